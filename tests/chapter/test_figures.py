"""The chapter's Figures 1, 3, 6 and 7 on the page, and the numbers the drawings print."""

from __future__ import annotations

import html
import re
from types import SimpleNamespace

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from serialkin import models
from serialkin.chapter._context import ReportContext, Timing, format_number, format_ratio
from serialkin.model.dh import DHLink
from serialkin.model.robot import Robot

_CAPTION = re.compile(r"<figcaption>(.*?)</figcaption>", re.S)


@pytest.fixture
def ctx(tmp_path):
    return ReportContext(outdir=tmp_path, quiet=True)


def _text(fragment: str) -> str:
    """Visible text of an HTML fragment (tags dropped, entities decoded)."""
    return html.unescape(re.sub(r"<[^>]+>", "", fragment))


def _captions(page: str) -> list[str]:
    return [_text(c) for c in _CAPTION.findall(page)]


def test_figure_1_prints_equal_distances_of_the_moved_points(ctx):
    """Figure 1 prints ‖p(0) − q(0)‖ = ‖p(t) − q(t)‖, both equal to |p − q| on the body."""
    from serialkin.chapter.sections import rigid_motion

    page = rigid_motion.build(ctx).html
    (cap,) = [c for c in _captions(page) if c.startswith("Figure 1 ")]
    d0, dt = (float(v) for v in re.findall(r"‖p\((?:0|t)\) − q\((?:0|t)\)‖ = ([\d.]+) m", cap))
    assert d0 == dt
    body = np.linalg.norm(rigid_motion.BODY_P - rigid_motion.BODY_Q)  # distance in the body
    assert f"{d0:.4f}" == f"{body:.4f}"
    change = float(re.search(r"largest change over the \d+ poses drawn ([\d.e+-]+) m", cap)[1])
    assert change < 1e-12
    assert page.index("Rigid body (Figure 1)") < page.index("Change of frame (eqs 1-3)")


def test_figure_3_prints_the_dh_row_of_the_model(ctx):
    """Figure 3's a3, d3 and α3, measured on the drawing, are the PUMA 560's DH row 3."""
    from serialkin.chapter.sections import forward

    page = forward._section_3_2(ctx).html
    (cap,) = [c for c in _captions(page) if c.startswith("Figure 3 ")]
    row = models.puma560().dh[2]
    assert f"a3 = {row.a:.5g} m" in cap and f"d3 = {row.d:.5g} m" in cap
    assert f"α3 = {np.degrees(row.alpha):.0f}°" in cap
    assert f"ϑ3 = {np.degrees(row.theta + forward.DH_PAIR_Q3):.0f}°" in cap
    table = page[page.index("measured on the drawing"):]
    cells = [_text(c) for c in re.findall(r"<td[^>]*>(.*?)</td>", table)[:12]]
    want = {"a3 [m]": format_number(row.a, "{:.5g}"), "d3 [m]": format_number(row.d, "{:.5g}"),
            "α3 [°]": format_number(np.degrees(row.alpha), "{:.1f}")}
    for name, value in want.items():
        k = cells.index(name)
        assert cells[k + 1] == cells[k + 2] == value, (name, cells[k:k + 3])


@settings(max_examples=60, deadline=None)
@given(a=st.floats(-1.0, 1.0), d=st.floats(-1.0, 1.0), alpha=st.floats(-3.1, 3.1),
       theta=st.floats(-1.5, 1.5), q=st.floats(-1.5, 1.5))
def test_link_pair_measures_back_the_dh_row(a, d, alpha, theta, q):
    """link_pair reads a, d, ϑ + q and α of any standard-DH row back from its two frames."""
    from serialkin.chapter.sections.dh_drawings import link_pair

    robot = Robot.from_dh([DHLink(a=a, alpha=alpha, d=d, theta=theta)], "standard")
    p = link_pair(robot, 1, q)
    wrap = np.angle(np.exp(1j * (p.theta - theta - q)))
    if abs(np.sin(alpha)) > 1e-3:  # skew axes: the common normal is unique
        assert p.a == pytest.approx(a, abs=1e-9) and p.d == pytest.approx(d, abs=1e-9)
    assert p.alpha == pytest.approx(alpha, abs=1e-9) and abs(wrap) < 1e-9
    o_i = p.T[:3, 3]
    assert np.linalg.norm(o_i - p.o_prime) == pytest.approx(abs(p.a), abs=1e-9)


def test_puma_frame_labels_are_distinct_and_apart():
    """Every PUMA 560 frame is labelled once; coinciding origins share one label, set apart."""
    from serialkin.chapter.sections.dh_drawings import origin_labels

    frames = models.puma560().fk_all(np.zeros(6))
    labels = origin_labels(frames)
    texts = [t for t, _, _ in labels]
    assert "O4 = O5 = O6" in texts
    assert sorted(int(n) for t in texts for n in re.findall(r"O(\d+)", t)) == list(range(7))
    anchors = np.array([at for _, _, at in labels])
    gaps = np.linalg.norm(anchors[:, None] - anchors[None], axis=-1)
    assert gaps[np.triu_indices(len(labels), 1)].min() > 0.2


def _ratio(values: list[float]) -> Timing:
    low, high = np.percentile(values, [5, 95])
    return Timing(median=float(np.median(values)), low=float(low), high=float(high),
                  n=len(values), blocks=3, unit="×", label="c / b", runs=tuple(values))


def test_twenty_link_per_iteration_ratio_is_taken_per_round(ctx):
    """The 20-link per-iteration ratio is each round's ratio × it_b/it_c, with its spread."""
    from serialkin.chapter.sections.redundancy.twenty_link import _timings_text

    sb = SimpleNamespace(solver=SimpleNamespace(max_iter=100))
    sc = SimpleNamespace(solver=SimpleNamespace(max_iter=100), path=[0, 1, 2])
    q, x = np.zeros((3, 2)), np.zeros((3, 3))
    tb = SimpleNamespace(iterations=np.array([10, 10, 10]), q=q, positions=x)
    tc = SimpleNamespace(iterations=np.array([20, 20, 20]), q=q, positions=x)
    t_b = Timing(median=1e-3, low=0.9e-3, high=1.1e-3, n=9, blocks=3)
    t_c = Timing(median=5e-3, low=4e-3, high=6e-3, n=9, blocks=3)
    rounds = [4.0, 4.4, 4.2, 3.8, 4.6, 4.1, 4.3, 3.9, 4.5]
    text = _text(_timings_text(ctx, sb, sc, tb, tc, t_b, t_c, _ratio(rounds)))
    per_round = _ratio([r * 30 / 60 for r in rounds])  # it_b / it_c = 30 / 60
    assert per_round.text in text
    assert f"{format_ratio(per_round.median)}× per iteration (each the median" in text
    medians = _text(_timings_text(ctx, sb, sc, tb, tc, t_b, t_c, None))
    assert f"{format_ratio(5 * 30 / 60)}× per iteration (ratios of the medians" in medians


@pytest.mark.slow
def test_chapter_figures_sit_where_the_chapter_cites_them(built_report):
    """Figures 1, 3, 6, 7 are captioned with their numbers, in sections 2, 3.2, 5.1, 5.2."""
    _, page = built_report
    heads: dict[str, int] = {}
    for m in re.finditer(r"<h2>([\d.]+) [^<]*</h2>", page):
        heads.setdefault(m[1], m.start())
    where = {}
    for m in _CAPTION.finditer(page):
        n = re.match(r"Figure (\d+)\b", _text(m[1]))
        if n:
            where.setdefault(int(n[1]), m.start())
    for fig, (start, end) in {1: ("2", "3"), 3: ("3.2", "3.2.1"), 6: ("5.1", "5.2"),
                              7: ("5.2", "5.3")}.items():
        assert heads[start] < where[fig] < heads[end], fig
    assert list(where) == sorted(where)  # in the chapter's order
