"""The chapter report's section 4 (serialkin.chapter.sections.inverse)."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from serialkin import models
from serialkin.chapter.report import ReportContext
from serialkin.chapter.sections import inverse


@settings(max_examples=40, deadline=None)
@given(l1=st.floats(0.2, 2.0), l2=st.floats(0.2, 2.0), q1=st.floats(-3.1, 3.1),
       q2=st.floats(0.05, 3.0))
def test_corrected_eqs_23_27_give_both_elbows(l1, l2, q1, q2):
    """The corrected closed form returns (q1, q2) and its mirror, both reproducing the point."""
    robot = models.two_link(l1, l2)
    for sign in (1.0, -1.0):
        q = np.array([q1, sign * q2])
        x, y = robot.fk(q)[:2, 3]
        cf = inverse.two_link_closed_form(x, y, l1, l2)
        sols = np.array([[cf["theta1_a"], cf["theta2_plus"]],
                         [cf["theta1_b"], cf["theta2_minus"]]])
        for s in sols:
            np.testing.assert_allclose(robot.fk(s)[:2, 3], [x, y], atol=1e-9)
        d = np.angle(np.exp(1j * (sols - q)))
        assert np.min(np.linalg.norm(d, axis=1)) < 1e-6


def test_misprinted_eq_26_fails_on_the_worked_example():
    """As printed, eq 26's arccos argument leaves [-1, 1] for the section's reachable target."""
    x, y = inverse.TARGET
    assert abs(inverse._misprinted_cos_beta(x, y, inverse.L1, inverse.L2)) > 1
    assert math.isfinite(inverse.two_link_closed_form(x, y, inverse.L1, inverse.L2)["beta"])


@pytest.mark.slow
def test_section_builds_with_figure(tmp_path):
    """build() returns sections 4 and 4.1 with Figure 5 saved."""
    ctx = ReportContext(outdir=tmp_path, quiet=True)
    secs = inverse.build(ctx)
    assert [sec.number for sec in secs] == ["4", "4.1"]
    assert (tmp_path / "figures" / "inverse_two_link.png").stat().st_size > 1000


@pytest.mark.slow
def test_numerical_families_have_one_table_per_robot(report_section):
    """Section 5.3's comparison has one table per robot, FABRIK skipped on spatial arms."""
    html = report_section("numerical")
    assert "<h2>5.3 " in html
    assert html.count("<caption>IK methods on") == 3
    assert "skipped" in html and "fabrik" in html
    assert "Trade-offs" in html
