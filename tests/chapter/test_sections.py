"""Report sections 2-5.3 built one by one: structure, and numbers of the kind they claim."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from serialkin.chapter.report import ReportContext

#: The folder of the section modules, and the most lines one of them may have.
SECTIONS = Path(__file__).resolve().parents[2] / "src" / "serialkin" / "chapter" / "sections"
MAX_SECTION_LINES = 400


@pytest.fixture
def ctx(tmp_path):
    return ReportContext(outdir=tmp_path, quiet=True)


def test_default_solver_timings_are_warm(ctx):
    """Section 5.3's solver timings: a bench, warm-up first, 21 runs each in 7 blocks."""
    from serialkin.chapter.sections import numerical

    rows = numerical._default_solver_timings(ctx)
    assert len(rows) == len(ctx.timings) == 3
    for row, t in zip(rows, ctx.timings):
        assert t.warm and t.n == len(t.runs) == 21 and t.blocks == 7
        assert 0 < t.low <= t.median <= t.high
        assert (t.low, t.high) == tuple(np.percentile(t.runs, [5, 95]))
        assert row[2] == "lm" and row[3] == t.text and row[4] == ""  # no ratio to itself
        assert "warm runs in 7 blocks, 5th–95th percentile" in t.text


@pytest.mark.slow
def test_sections_in_chapter_numbering(built_report):
    """The report's numbered sections come in the chapter's order, 1 to 5.3."""
    import re

    _, page = built_report
    numbers = [h.split()[0] for h in re.findall(r"<h2>([^<]*)</h2>", page)]
    assert numbers == ["1", "2", "3", "3.1", "3.2", "3.2.1", "4", "4.1", "5", "5.1", "5.2",
                       "5.3"]


@pytest.mark.slow
def test_worker_processes_build_the_same_report(built_report, tmp_path):
    """Worker processes (the report as built) give the same sections as one process, in order."""
    import re

    from serialkin.chapter.report import build_report

    out, page = built_report
    if "2 worker processes" not in page:  # a one-core machine built it in one process
        out = tmp_path / "j2"
        page = build_report(out, quiet=True, jobs=2,
                            sections=["inverse", "rigid_motion"]).read_text(encoding="utf-8")
    one = build_report(tmp_path / "j1", quiet=True, jobs=1,
                       sections=["inverse", "rigid_motion"]).read_text(encoding="utf-8")
    heads = [[h for h in re.findall(r"<h2>([^<]*)</h2>", p) if h[0] in "24"]
             for p in (page, one)]
    assert heads[0] == heads[1] == ["2 Rigid body motion", "4 Inverse kinematics",
                                    "4.1 Closed-form solution of inverse kinematics"]
    assert "2 worker processes" in page and "one process" in one
    assert (out / "figures" / "inverse_two_link.png").stat().st_size > 1000


def test_jobs_must_be_positive(tmp_path):
    """jobs=0 is refused with the library's input error naming the argument."""
    from serialkin.chapter.report import build_report
    from serialkin.errors import InputError

    with pytest.raises(InputError, match="jobs"):
        build_report(tmp_path, quiet=True, jobs=0, sections=["rigid_motion"])


def test_section_4_shows_sixteen_solutions(ctx):
    """Section 4 shows the 16-solution general 6R arm, every solution meeting FK to 1e-10."""
    from serialkin.chapter.sections import inverse

    html = inverse._section_4(ctx).html
    assert "in <b>16</b> ways" in html
    err = float(html.split("worst max |f(q) − T| = ")[1].split(")")[0])
    assert err < 1e-10


def test_no_section_module_is_longer_than_400_lines():
    """Every file under chapter/sections/ has at most 400 lines (a longer one is split)."""
    files = sorted(SECTIONS.rglob("*.py"))
    assert len(files) > 10  # the folder was found, with its subpackages
    lengths = {str(f.relative_to(SECTIONS)): len(f.read_text(encoding="utf-8").splitlines())
               for f in files}
    too_long = {name: n for name, n in lengths.items() if n > MAX_SECTION_LINES}
    assert not too_long, f"split these along a seam (at most {MAX_SECTION_LINES} lines): {too_long}"


def _radial_area(L: tuple[float, float, float], every_heading: bool) -> float:
    """Area of the tool positions p of a planar 3R arm whose wrist p − L3·e_φ is reachable.

    For every heading φ (total orientation) or for some φ (maximal workspace): the wrist
    must lie in the 2-link annulus |L1 − L2| ≤ |w| ≤ L1 + L2. The set is a union of rings,
    so it is tested on radii r (p = (r, 0)) and integrated as ∫ 2πr dr.
    """
    L1, L2, L3 = L
    r = np.linspace(0.0, sum(L), 20_001)
    phi = np.linspace(0.0, 2 * np.pi, 721)  # holds 0 and π, where |w| is extreme
    wrist = np.hypot(r[:, None] - L3 * np.cos(phi), L3 * np.sin(phi))
    ok = (wrist >= abs(L1 - L2)) & (wrist <= L1 + L2)
    inside = ok.all(axis=1) if every_heading else ok.any(axis=1)
    return float(np.sum(2 * np.pi * r * inside) * (r[1] - r[0]))


_ARMS = [(1.0, 0.8, 0.3), (1.0, 1.0, 0.5), (1.0, 0.6, 0.2), (0.7, 0.4, 0.5), (2.0, 0.5, 0.3)]


@pytest.mark.parametrize("L", _ARMS + [(0.5, 0.4, 2.0), (1.0, 1.0, 1.5)])
def test_closed_form_reachable_areas_match_a_radial_integration(L):
    """Section 1's 2R annulus and 3R maximal-workspace areas equal ∫ 2πr dr over the rings."""
    from serialkin.chapter.sections.workspace.closed_forms import (
        annulus_area,
        three_link_reachable_area,
    )

    assert three_link_reachable_area(L) == pytest.approx(_radial_area(L, False), rel=1e-3)
    assert annulus_area(L[0], L[1]) == pytest.approx(
        _radial_area((L[0], L[1], 0.0), False), rel=1e-3)


@pytest.mark.parametrize("L", _ARMS + [(1.0, 1.0, 1.5), (0.5, 0.4, 2.0)])
def test_closed_form_total_orientation_area_matches_a_radial_integration(L):
    """Section 1's 3R total-orientation area equals ∫ 2πr dr over radii every heading reaches."""
    from serialkin.chapter.sections.workspace.closed_forms import three_link_total_area

    assert three_link_total_area(L) == pytest.approx(_radial_area(L, True), rel=1e-3)
