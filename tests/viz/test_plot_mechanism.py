"""plot_robot(mechanism=True): links drawn along the joint axes, then across."""

from __future__ import annotations

import matplotlib

matplotlib.use("Agg")

import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from hypothesis import given, settings  # noqa: E402
from hypothesis import strategies as st  # noqa: E402

from serialkin import models  # noqa: E402
from serialkin.viz.plot import plot_robot  # noqa: E402


def _links(ax):
    (line,) = [ln for ln in ax.get_lines() if ln.get_gid() == "serialkin-links"]
    return np.c_[line.get_data_3d()]


def test_scara_has_a_vertical_column_and_horizontal_arms():
    """SCARA: base → (0, 0, d1) straight up, then both arms at height d1, ending at the tool."""
    robot = models.scara(d1=0.4, d2=0.1, l1=0.35, l2=0.30)
    q = np.array([0.5, -0.8, -0.05, 1.0])
    ax = plot_robot(robot, q, mechanism=True)
    P = _links(ax)
    np.testing.assert_allclose(P[0], [0, 0, 0], atol=1e-12)
    np.testing.assert_allclose(P[1], [0, 0, 0.4], atol=1e-12)
    np.testing.assert_allclose(P[2:4, 2], 0.4, atol=1e-12)  # the two arms are horizontal
    np.testing.assert_allclose(np.linalg.norm(P[2] - P[1]), 0.35, atol=1e-12)
    np.testing.assert_allclose(np.linalg.norm(P[3] - P[2]), 0.30, atol=1e-12)
    np.testing.assert_allclose(P[-1], robot.fk(q)[:3, 3], atol=1e-12)
    plt.close(ax.figure)


@settings(max_examples=15, deadline=None)
@given(st.lists(st.floats(-3.0, 3.0), min_size=6, max_size=6))
def test_mechanism_line_ends_at_tool_and_passes_link_frames(qs):
    """PUMA 560: the mechanism line ends at the tool and passes through every link origin."""
    robot = models.puma560()
    q = np.array(qs)
    ax = plot_robot(robot, q, mechanism=True)
    P = _links(ax)
    np.testing.assert_allclose(P[-1], robot.fk(q)[:3, 3], atol=1e-9)
    for o in robot.fk_all(q)[:, :3, 3]:
        assert np.min(np.linalg.norm(P - o, axis=1)) < 1e-9
    plt.close(ax.figure)
