"""Report sections 2-5.3 built one by one: structure, and numbers of the kind they claim."""

from __future__ import annotations

import numpy as np
import pytest

from serialkin.chapter.report import ReportContext


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
        assert row[-1] == t.text and "warm runs in 7 blocks, 5th–95th percentile" in t.text


@pytest.mark.slow
def test_sections_in_chapter_numbering(ctx):
    """Sections 3, 4 and 5 build their numbered parts in the chapter's order."""
    from serialkin.chapter.sections import forward, inverse, jacobian

    numbers = [s.number for mod in (forward, inverse, jacobian) for s in mod.build(ctx)]
    assert numbers == ["3", "3.1", "3.2", "3.2.1", "4", "4.1", "5", "5.1", "5.2"]


@pytest.mark.slow
def test_worker_processes_build_the_same_report(tmp_path):
    """jobs=2 (spawned workers) gives the same sections as jobs=1, in the chapter's order."""
    import re

    from serialkin.chapter.report import build_report

    pages = []
    for jobs in (1, 2):
        path = build_report(tmp_path / f"j{jobs}", quiet=True, jobs=jobs,
                            sections=["inverse", "rigid_motion"])
        pages.append(path.read_text(encoding="utf-8"))
    heads = [re.findall(r"<h2>([^<]*)</h2>", p) for p in pages]
    assert heads[0] == heads[1] == ["2 Rigid body motion", "4 Inverse kinematics",
                                    "4.1 Closed-form solution of inverse kinematics"]
    assert "2 worker processes" in pages[1] and "one process" in pages[0]
    assert (tmp_path / "j2" / "figures" / "inverse_two_link.png").stat().st_size > 1000


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
