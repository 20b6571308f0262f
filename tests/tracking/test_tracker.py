"""Path tracking: unreachable points, bad input, solvers, and trajectory files."""

from __future__ import annotations

import math

import numpy as np
import pytest

from serialkin.errors import InputError, InputTypeError
from serialkin.model.geometry import Cylinder
from serialkin.redundancy import MultiTaskResolver
from serialkin.tracking import Path, Trajectory, planar_arm, track


@pytest.fixture(scope="module")
def arm():
    return planar_arm(6, 0.1)


def _path_with_unreachable():
    pts = [[0.3, 0.1], [0.3, 0.15], [1.0, 0.0], [0.3, 0.2], [0.25, 0.2]]
    return Path.from_points(pts)


def test_unreachable_point_reported_and_tracking_continues(arm):
    """An out-of-reach point is reported (index, error) and later points are still tracked."""
    tr = track(arm, _path_with_unreachable(), q0=np.full(6, 0.3), on_unreachable="continue")
    assert len(tr) == 5 and not tr.stopped and not tr.complete
    assert [f.index for f in tr.failures] == [2]
    assert 0.4 - 1e-9 <= tr.failures[0].error < 0.42  # reach 0.6 m, target at 1 m
    assert "path point 2" in str(tr.failures[0])
    assert tr.reached.tolist() == [True, True, False, True, True]
    assert np.all(tr.errors[[0, 1, 3, 4]] < 1e-5)


def test_unreachable_point_stop_keeps_computed_points(arm):
    """With on_unreachable='stop' tracking stops at the failing point and keeps what came before."""
    path = _path_with_unreachable()
    full = track(arm, path, q0=np.full(6, 0.3))
    tr = track(arm, path, q0=np.full(6, 0.3), on_unreachable="stop")
    assert tr.stopped and len(tr) == 3 and tr.path_length == 5
    assert [f.index for f in tr.failures] == [2]
    np.testing.assert_allclose(tr.q, full.q[:3])
    assert "stopped" in tr.summary()


def test_multitask_unreachable_point_reported(arm):
    """The multi-task resolver reports an unreachable point the same way."""
    res = MultiTaskResolver(task="planar", max_iter=100)
    tr = track(arm, _path_with_unreachable(), res, q0=np.full(6, 0.3))
    assert [f.index for f in tr.failures] == [2]
    assert tr.reached[[0, 1, 3, 4]].all()


def test_path_with_nan_rejected():
    """A path with NaN raises InputError naming the offending index."""
    with pytest.raises(InputError, match=r"finite.*index \(1, 0\)"):
        Path.from_points([[0.1, 0.2], [np.nan, 0.1]])
    with pytest.raises(InputError, match="finite"):
        Path.from_function(lambda s: [s, np.nan], 0, 1, 0.5)


def test_bad_tracking_arguments(arm):
    """Bad path type, q0 size, tolerance, on_unreachable and solver raise clear errors."""
    path = Path.circle([-0.25, 0.0], 0.1)
    with pytest.raises(InputTypeError, match="Path"):
        track(arm, [[0.1, 0.2]])
    with pytest.raises(InputError, match="q0"):
        track(arm, path, q0=np.zeros(5))
    with pytest.raises(InputError, match="tolerance"):
        track(arm, path, tolerance=-1.0)
    with pytest.raises(InputError, match="on_unreachable"):
        track(arm, path, on_unreachable="skip")
    with pytest.raises(InputTypeError, match="solver"):
        track(arm, path, solver=3)
    with pytest.raises(InputError, match="overlaps"):
        track(arm, path, obstacles=[Cylinder(0.02, math.inf, center=[0.0, 0.0, 0.0])])
    with pytest.raises(InputError, match="task"):
        track(arm, path, MultiTaskResolver(task="position"))


def test_path_constructors():
    """Circle sampling matches the chapter (32 points), polylines keep their spacing."""
    c = Path.circle([-0.25, 0.0], 0.1, step=0.2)
    assert len(c) == 32 and c.task == "planar"
    pl = Path.polyline([[0, 0], [0.1, 0]], step=0.03)
    assert len(pl) == 5 and np.max(np.diff(pl.points[:, 0])) <= 0.03 + 1e-12
    pos = Path.from_points([[0.1, 0.2, 0.3]])
    assert pos.task == "position"
    with pytest.raises(InputError, match="columns"):
        Path.from_points([[0.1, 0.2, 0.3, 0.4]])


def test_trajectory_roundtrip_csv_and_npz(arm, tmp_path):
    """Saving to CSV and NPZ and loading back gives the same trajectory."""
    obs = [Cylinder(0.05, math.inf, center=[0.0, 0.3, 0.0], name="post")]
    tr = track(arm.with_limits(np.tile([-2.5, 2.5], (6, 1))), _path_with_unreachable(),
               q0=np.full(6, 0.3), obstacles=obs)
    assert tr.clearance.shape == (5, 1)
    for ext in ("csv", "npz"):
        p = tr.save(tmp_path / f"traj.{ext}")
        back = Trajectory.load(p)
        for name in ("q", "poses", "targets", "errors", "clearance", "limit_margin", "times"):
            np.testing.assert_allclose(getattr(back, name), getattr(tr, name), rtol=0, atol=0)
        assert back.reached.tolist() == tr.reached.tolist()
        assert back.iterations.tolist() == tr.iterations.tolist()
        assert back.failures == tr.failures and back.obstacle_names == ("post",)
        assert back.path_length == tr.path_length and back.solver == tr.solver
    assert not list(tmp_path.glob(".*tmp"))
    with pytest.raises(InputError, match=".csv or .npz"):
        tr.save(tmp_path / "traj.txt")
    (tmp_path / "bad.csv").write_text("a,b\n1,2\n")
    with pytest.raises(InputError, match="not a serialkin trajectory"):
        Trajectory.load(tmp_path / "bad.csv")


def test_track_with_ik_method(arm):
    """Any IK method of robot.ik can track the path (warm-started), when serialkin.ik is there."""
    ik = pytest.importorskip("serialkin.ik")
    if not hasattr(ik, "solve"):
        pytest.skip("serialkin.ik.solve not available yet")
    path = Path.circle([-0.25, 0.0], 0.1, step=0.4)
    tr = track(arm, path, "lm", q0=np.full(6, 0.3))
    assert tr.max_error <= 0.005


@pytest.mark.parametrize("task", ["pose", "position"])
def test_spatial_arm_tracks_pose_and_position_paths(task):
    """DLS and the multi-task resolver track 6-D pose / 3-D position paths of a spatial arm."""
    from ..redundancy._robots import spatial_rp

    robot = spatial_rp()
    qa = robot.random_q(seed=11)
    qs = qa + np.linspace(0, 1, 15)[:, None] * np.linspace(0.2, -0.2, robot.n)
    qs[:, 2] = np.clip(qs[:, 2], 0.05, 0.35)
    T = robot.fk(qs)
    path = Path.from_poses(T) if task == "pose" else Path.from_points(T[:, :3, 3])
    for solver in ("dls", MultiTaskResolver(task=task, tol=1e-7, joint_limit_weight=0.0,
                                            max_task_step=0.05)):
        tr = track(robot, path, solver, q0=qa, damping=0.01, tol=1e-8)
        assert tr.complete, tr.summary()
        assert tr.max_error < 1e-6
        if task == "pose":
            R_err = np.einsum("kij,kij->k", tr.poses[:, :3, :3], T[:, :3, :3])
            assert np.all(R_err > 3 - 1e-9)  # trace(RᵀR_d) = 3: same orientation
        np.testing.assert_allclose(tr.positions, T[:, :3, 3], atol=2e-6)


@pytest.mark.parametrize("repulsive_gain", [0.0, 1.0])
def test_joint_limit_task_keeps_joints_inside_limits(repulsive_gain):
    """With limits ±80° the joint-limit task (faithful or repulsive) keeps q inside, path reached.

    Without the task the joints of the same circle-tracking run leave the range.
    """
    path = Path.circle([-0.25, 0.0], 0.1, step=0.2)
    robot = planar_arm(6, 0.1, joint_limits_deg=[-80, 80])
    q0 = np.radians([-60.0, 20, 20, 20, 20, 20])
    free = track(robot, path, MultiTaskResolver(joint_limit_weight=0.0, damping=0.01), q0=q0)
    assert np.abs(free.q).max() > np.radians(80.0)
    tr = track(robot, path, MultiTaskResolver(joint_limit_weight=100.0, damping=0.01,
                                              repulsive_gain=repulsive_gain), q0=q0)
    assert tr.complete and tr.max_error <= 0.005
    assert np.abs(tr.q).max() < np.radians(80.0)
    assert tr.min_limit_margin > 0
