"""Tests for serialkin.viz.trajectory: plotted lines hold the trajectory's numbers."""

import math
from types import SimpleNamespace

import numpy as np
import pytest

from serialkin.errors import InputError
from serialkin.model.geometry import Cylinder
from serialkin.viz.trajectory import (
    clearance_along,
    plot_clearance,
    plot_joint_trajectories,
    plot_motion,
    plot_tracking_error,
    tracking_figure,
)


def _by_gid(ax, gid):
    return [ln for ln in ax.get_lines() if ln.get_gid() == gid]


def test_joint_lines_in_degrees_for_revolute_only(spatial4):
    """Revolute joints are plotted in degrees, prismatic ones in metres, against the index."""
    Q = spatial4.random_q(9, seed=4)
    ax = plot_joint_trajectories(Q, robot=spatial4)
    for i, kind in enumerate(spatial4.joint_types):
        (line,) = _by_gid(ax, f"serialkin-joint-{i}")
        want = np.degrees(Q[:, i]) if kind == "R" else Q[:, i]
        np.testing.assert_allclose(line.get_ydata(), want, rtol=1e-12)
        np.testing.assert_array_equal(line.get_xdata(), np.arange(9))
    assert "deg (R), m (P)" in ax.get_ylabel()
    # joint 3's finite limits (0, 0.3) m are drawn
    limits = sorted(ln.get_ydata()[0] for ln in _by_gid(ax, "serialkin-limit"))
    assert limits == pytest.approx([0.0, 0.3])


def test_joint_trajectories_many_joints_and_time_axis():
    """With 20 joints a colour bar replaces the legend; t becomes the x data."""
    Q = np.linspace(np.zeros(20), np.ones(20), 5)
    t = np.linspace(0.0, 2.0, 5)
    ax = plot_joint_trajectories(Q, t, degrees=False)
    assert len([ln for ln in ax.get_lines() if ln.get_gid().startswith("serialkin-joint")]) == 20
    assert ax.get_legend() is None
    assert len(ax.figure.axes) == 2  # plus the colour bar
    np.testing.assert_array_equal(_by_gid(ax, "serialkin-joint-19")[0].get_xdata(), t)
    with pytest.raises(InputError, match="t must have 5"):
        plot_joint_trajectories(Q, t[:3])


def test_tracking_error_from_target_and_actual():
    """The error line is ‖actual − target‖ in mm; points above tolerance are marked."""
    target = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0]])
    actual = target + np.array([[0.001, 0.0], [0.0, 0.003], [0.004, 0.003]])
    ax = plot_tracking_error(target=target, actual=actual, tolerance=0.004)
    (line,) = _by_gid(ax, "serialkin-error")
    np.testing.assert_allclose(line.get_ydata(), [1.0, 3.0, 5.0])
    (bad,) = _by_gid(ax, "serialkin-unreached")
    np.testing.assert_array_equal(bad.get_xdata(), [2.0])
    with pytest.raises(InputError, match="both"):
        plot_tracking_error(target=target, actual=actual[:, :1])
    with pytest.raises(InputError, match="give errors"):
        plot_tracking_error()


def test_clearance_lines_and_contact():
    """Each obstacle gets a line in the chosen unit; the zero line marks contact."""
    C = np.array([[0.10, 0.02], [0.05, -0.01], [0.07, 0.0]])
    ax = plot_clearance(C, names=["a", "b"], unit="cm", influence=0.03)
    np.testing.assert_allclose(_by_gid(ax, "serialkin-clearance-1")[0].get_ydata(),
                               [2.0, -1.0, 0.0])
    assert _by_gid(ax, "serialkin-contact")[0].get_ydata()[0] == 0.0
    assert _by_gid(ax, "serialkin-influence")[0].get_ydata()[0] == pytest.approx(3.0)
    with pytest.raises(InputError, match="names"):
        plot_clearance(C, names=["a"])


def test_clearance_along_matches_redundancy(planar3):
    """clearance_along equals the redundancy module's per-configuration minimum."""
    ob = pytest.importorskip("serialkin.redundancy.obstacles")
    obstacles = [Cylinder(0.1, math.inf, center=[0.6, 0.6, 0.0]),
                 dict(type="sphere", center=[0.0, 0.8, 0.0], radius=0.05)]
    Q = planar3.random_q(4, seed=5)
    C = clearance_along(planar3, Q, obstacles)
    assert C.shape == (4, 2)
    objs = [obstacles[0], ob.obstacle_from_dict(obstacles[1])]
    for j, q in enumerate(Q):
        np.testing.assert_allclose(C[j], ob.clearances(planar3, q, objs).min(axis=0))


def test_motion_draws_selected_poses(planar3):
    """plot_motion draws every `every`-th pose plus the last, the path and the trace."""
    Q = np.linspace([0.0, 0.0, 0.0], [1.0, 0.5, -0.5], 10)
    path = planar3.fk(Q)[:, :2, 3]
    ax = plot_motion(planar3, Q, every=4, path_points=path,
                     obstacles=[dict(center=[0.2, 0.8], radius=0.1)])
    links = _by_gid(ax, "serialkin-links")
    assert len(links) == 4  # poses 0, 4, 8 and 9
    np.testing.assert_allclose(links[-1].get_xdata()[-1], planar3.fk(Q[9])[0, 3])
    (trace,) = _by_gid(ax, "serialkin-trace")
    np.testing.assert_allclose(trace.get_xydata(), path, atol=1e-12)
    assert len(_by_gid(ax, "serialkin-path")) == 1


def test_tracking_figure_from_real_track():
    """tracking_figure accepts a Trajectory from serialkin.tracking.track (4 panels)."""
    tracking = pytest.importorskip("serialkin.tracking")
    from serialkin import models

    robot = models.planar(6, 0.1)
    obstacles = [Cylinder(0.05, math.inf, center=[-0.1, 0.25, 0.0], name="post")]
    traj = tracking.track(robot, tracking.Path.circle([-0.25, 0.0], 0.1), obstacles=obstacles)
    fig = tracking_figure(traj, robot, obstacles=obstacles, title="six-link")
    assert len(fig.axes) == 4
    err_ax = fig.axes[2]
    np.testing.assert_allclose(_by_gid(err_ax, "serialkin-error")[0].get_ydata(),
                               traj.errors * 1e3)
    clr_ax = fig.axes[3]
    np.testing.assert_allclose(_by_gid(clr_ax, "serialkin-clearance-0")[0].get_ydata(),
                               traj.clearance[:, 0] * 1e3)
    assert clr_ax.get_legend().get_texts()[0].get_text() == "post"


def test_tracking_figure_duck_typed_without_robot():
    """A plain object with q/errors/tolerance gives a 2-panel figure (no clearance)."""
    traj = SimpleNamespace(q=np.zeros((3, 2)), errors=np.array([0.0, 0.001, 0.002]),
                           tolerance=0.005, clearance=np.empty((3, 0)))
    fig = tracking_figure(traj)
    assert len(fig.axes) == 2


def test_tracking_error_log_scale_when_far_below_tolerance():
    """Errors far below the tolerance switch to a log axis by default; log=False keeps linear."""
    e = np.array([1e-7, 2e-7, 5e-8])
    assert plot_tracking_error(e, tolerance=5e-3).get_yscale() == "log"
    assert plot_tracking_error(e, tolerance=5e-3, log=False).get_yscale() == "linear"
    assert plot_tracking_error(np.array([1e-3, 4e-3]), tolerance=5e-3).get_yscale() == "linear"
