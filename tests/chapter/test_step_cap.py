"""The 20-link example's step cap decides its outcome, and the page says so where it shows it.

The constrained scenario (c) is run with eq 48's step cap doubled: the clearances are
recomputed here from the joint trajectories (``clearances``), not read from the run or the
page; then the built page is checked to state the cap, and what the doubled cap does, in
the 20-link part (Figures 11-12), in the ablation and in the QP comparison.
"""

from __future__ import annotations

import html
import re

import numpy as np
import pytest

from serialkin.chapter.sections.redundancy.step_cap import NO_CAP, step_cap_study
from serialkin.redundancy import clearances
from serialkin.tracking import load_scenario


@pytest.fixture(scope="module")
def study():
    sb, sc = load_scenario("twenty_link_free"), load_scenario("twenty_link_obstacles")
    return sc, step_cap_study(sb, sc, sb.run(), sc.run())


def _worst(sc, q):
    return min(float(clearances(sc.robot, qk, sc.obstacles).min()) for qk in q)


def test_the_cap_shown_is_clear_and_a_doubled_cap_collides(study):
    """With the default cap (c) keeps clear of every obstacle; doubled, a link enters one."""
    sc, s = study
    assert s.cap == sc.solver.max_step == 0.2
    assert _worst(sc, s.shown.q) > 0
    doubled, uncapped = s.runs
    assert doubled.cap == 2 * s.cap and uncapped.cap == NO_CAP
    for run in s.runs:
        worst = _worst(sc, run.trajectory.q)
        assert worst < 0 and worst == pytest.approx(run.min_clearance, abs=1e-9)
        assert run.depth and all(d < 0 for d in run.depth.values())
        assert run.iterations > int(s.shown.iterations.sum())
        assert run.max_joint_difference == float(np.abs(run.trajectory.q - s.shown.q).max())


def test_the_cap_never_binds_in_the_free_case(study):
    """(b) with no effective cap follows the same joint trajectory as with the default cap."""
    _, s = study
    assert s.free_difference == 0.0


def _visible(fragment: str) -> str:
    """The text a reader sees (the spans that keep numbers on one line add no space)."""
    text = re.sub(r'<span class="nowrap">([^<]*)</span>', r"\1", fragment)
    text = re.sub(r"<math.*?</math>", " ", text, flags=re.S)
    text = re.sub(r'src="data:[^"]+"', "", text)
    return re.sub(r"\s+", " ", html.unescape(re.sub(r"<[^>]+>", " ", text)))


def _part(page: str, heading: str) -> str:
    for body in re.findall(r'<section id="redundancy[^"]*">(.*?)</section>', page, re.S):
        if f'<h3 class="part">{heading}' in body:
            return body
    raise AssertionError(f"no part {heading!r}")


@pytest.mark.slow
def test_the_page_states_the_cap_where_the_outcome_is_shown(built_report, study):
    """Figures 11-12, the ablation and the QP comparison state the cap and its outcome."""
    _, page = built_report
    _, s = study
    doubled = s.doubled
    collides = f"{doubled.min_clearance * 1e3:.1f}".replace("-", "−")
    twenty = _part(page, "Example: the 20-link arm")
    ablation = _visible(twenty[twenty.index("<h4>Ablation"):])
    qp = _visible(_part(page, "Weighted tasks (eq 48) against a QP"))
    for where, text in (("20-link part", _visible(twenty)), ("ablation", ablation),
                        ("QP comparison", qp)):
        assert f"step cap of {s.cap:g} rad" in text or f"‖q̇‖ ≤ {s.cap:g} rad" in text, where
        assert f"with {doubled.cap:g} rad" in text, where
        assert f"{collides} mm" in text and str(doubled.iterations) in text, where
    figures = [_visible(f) for f in re.findall(r"<figcaption>(Figure 1[12] .*?)</figcaption>",
                                               twenty, re.S)]
    assert len(figures) == 2 and all(f"≤ {s.cap:g} rad" in f for f in figures), figures
    uncapped = f"{s.runs[1].min_clearance * 1e3:.1f}".replace("-", "−")
    assert f"({NO_CAP:g} rad)" in _visible(twenty) and f"{uncapped} mm" in _visible(twenty)
