"""Cartesian paths: pose paths, branch-consistent joint paths and time-optimal timing."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from serialkin import models
from serialkin.errors import InputError
from serialkin.paths import arc, joint_path, line, slerp, time_optimal, waypoints
from serialkin.spatial.lie import so3_exp, so3_log


def _angle(R: np.ndarray) -> np.ndarray:
    return np.linalg.norm(so3_log(R, check=False), axis=-1)


def _steps(T: np.ndarray) -> tuple[float, float]:
    """Largest position step [m] and rotation step [rad] between neighbouring poses."""
    dp = np.linalg.norm(np.diff(T[:, :3, 3], axis=0), axis=1).max()
    dr = _angle(np.swapaxes(T[:-1, :3, :3], -1, -2) @ T[1:, :3, :3]).max()
    return float(dp), float(dr)


def _pose(p, w) -> np.ndarray:
    T = np.eye(4)
    T[:3, :3] = so3_exp(np.asarray(w, dtype=float))
    T[:3, 3] = p
    return T


# ------------------------------------------------------------------- pose paths

@settings(max_examples=30, deadline=None)
@given(w0=st.lists(st.floats(-3, 3), min_size=3, max_size=3),
       w1=st.lists(st.floats(-3, 3), min_size=3, max_size=3),
       s=st.floats(0, 1))
def test_slerp_is_the_geodesic_at_constant_speed(w0, w1, s):
    """SLERP: R(0) = R0, R(1) = R1, and angle(R0ᵀR(s)) = s·angle(R0ᵀR1) (a geodesic)."""
    R0, R1 = so3_exp(np.array(w0)), so3_exp(np.array(w1))
    R = slerp(R0, R1, [0.0, s, 1.0])
    assert np.allclose(R[0], R0, atol=1e-12) and np.allclose(R[2], R1, atol=1e-9)
    total = _angle(R0.T @ R1)
    assert abs(_angle(R0.T @ R[1]) - s * total) < 1e-9
    assert abs(_angle(R[1].T @ R1) - (1 - s) * total) < 1e-9


def test_line_respects_its_steps_and_ends_exactly():
    """A line's samples are evenly spaced within max_step and max_angle; ends are the poses."""
    A, B = _pose([0.4, 0.1, 0.3], [0.1, 0.2, 0.3]), _pose([0.2, -0.3, 0.5], [1.0, -0.5, 0.2])
    P = line(A, B, max_step=0.004, max_angle=math.radians(0.5))
    T = P.targets
    assert np.array_equal(T[0], A) and np.array_equal(T[-1], B)
    dp, dr = _steps(T)
    assert dp <= 0.004 + 1e-12 and dr <= math.radians(0.5) + 1e-12
    # positions on the segment, evenly spaced
    d = np.linalg.norm(np.diff(T[:, :3, 3], axis=0), axis=1)
    assert np.ptp(d) < 1e-12
    F = line(A, B, orientation="fixed").targets
    assert np.allclose(F[:, :3, :3], A[:3, :3], atol=1e-15)
    assert P.parameter[0] == 0.0 and P.parameter[-1] == 1.0


def test_arc_stays_on_its_circle_and_turns_the_tool_with_it():
    """Arc samples are at the radius, in the plane ⟂ axis; 'follow' turns R by Rot(u, s·φ)."""
    A = _pose([0.5, 0.0, 0.4], [0.0, math.pi, 0.0])
    c, u = np.array([0.4, 0.0, 0.4]), np.array([0.0, 0.0, 1.0])
    P = arc(A, c, u, math.radians(120), max_step=0.003)
    p = P.targets[:, :3, 3] - c
    assert np.allclose(np.linalg.norm(p[:, :2], axis=1), 0.1, atol=1e-12)
    assert np.allclose(p[:, 2], 0.0, atol=1e-12)
    assert _steps(P.targets)[0] <= 0.003 + 1e-12
    s = P.parameter
    expect = so3_exp((s * math.radians(120))[:, None] * u) @ A[:3, :3]
    assert np.allclose(P.targets[:, :3, :3], expect, atol=1e-12)
    fixed = arc(A, c, u, -1.0, orientation="fixed").targets
    assert np.allclose(fixed[:, :3, :3], A[:3, :3], atol=1e-15)
    assert np.allclose(fixed[-1, :3, 3] - c, [0.1 * math.cos(-1.0), 0.1 * math.sin(-1.0), 0],
                       atol=1e-12)


def test_waypoints_pass_through_every_waypoint_without_blend_and_round_corners_with_it():
    """No blend: every waypoint is a sample; blend: no kink, corners cut within the blend."""
    W = np.stack([_pose([0.4, 0.0, 0.3], [0, 3.0, 0]), _pose([0.4, 0.2, 0.3], [0, 3.0, 0.3]),
                  _pose([0.2, 0.2, 0.4], [0.2, 2.8, 0.3]), _pose([0.2, 0.0, 0.4], [0, 3.1, 0])])
    sharp = waypoints(W, max_step=0.005).targets
    for w in W:
        assert np.min(np.abs(sharp - w).max(axis=(1, 2))) < 1e-12
    P = waypoints(W, blend=0.03, max_step=0.002)
    T = P.targets
    assert np.array_equal(T[0], W[0]) and np.array_equal(T[-1], W[-1])
    dp, dr = _steps(T)
    assert dp <= 0.002 + 1e-12 and dr <= math.radians(1) + 1e-12
    d = np.diff(T[:, :3, 3], axis=0)
    d /= np.linalg.norm(d, axis=1, keepdims=True)
    turn = np.degrees(np.arccos(np.clip(np.sum(d[1:] * d[:-1], axis=1), -1, 1)))
    assert turn.max() < 10.0  # sharp corners turn by 90°: blended, each step turns a little
    for w in W[1:-1]:  # corners are cut, by at most the blend
        gap = np.linalg.norm(T[:, :3, 3] - w[:3, 3], axis=1).min()
        assert 0.005 < gap < 0.03
    assert np.all(np.diff(P.parameter) > 0)


def test_pose_path_bad_input_is_named():
    """Bad steps, orientation modes, arcs and waypoint lists say what is wrong."""
    A = _pose([0.4, 0.0, 0.3], [0, 0, 0])
    with pytest.raises(InputError, match="max_step"):
        line(A, A, max_step=0.0)
    with pytest.raises(InputError, match="orientation"):
        line(A, A, orientation="spin")
    with pytest.raises(InputError, match="radius 0"):
        arc(A, A[:3, 3], [0, 0, 1], 1.0)
    with pytest.raises(InputError, match="end_rotation"):
        arc(A, [0, 0, 0.3], [0, 0, 1], 1.0, orientation="slerp")
    with pytest.raises(InputError, match="angle"):
        arc(A, [0, 0, 0.3], [0, 0, 1], 0.0)
    with pytest.raises(InputError, match="k >= 2"):
        waypoints(A[None])
    with pytest.raises(InputError, match="blend"):
        waypoints(np.stack([A, A]), blend=-1.0)


# ------------------------------------------------------------------ joint paths

def _ur5_line(offset, q0, step=0.003):
    robot = models.get("ur5")
    A = robot.fk(q0)
    B = A.copy()
    B[:3, 3] += offset
    B[:3, :3] = A[:3, :3] @ so3_exp(np.array([0.2, -0.3, 0.4]))
    return robot, line(A, B, max_step=step)


def _configuration(robot, Q):
    """The configuration's sign: sign(det J), which changes exactly at a singularity.

    det J of a 6R arm is the product of its shoulder, elbow and wrist factors, so a
    change of configuration (elbow up/down, wrist flip, shoulder left/right) changes its
    sign; along a path that avoids singularities it must stay constant.
    """
    return np.sign(np.linalg.det(robot.jacobian(Q)))


@pytest.mark.parametrize("name,q0", [
    ("ur5", [0.3, -1.2, 1.4, -1.0, -1.5, 0.4]),
    ("ur5", [2.0, -2.0, -1.3, 0.4, 1.2, -2.0]),
    ("puma560", [0.2, -0.6, 0.4, 0.5, 0.8, -0.3]),
    ("puma560", [-1.0, -0.4, 0.3, -1.2, -1.4, 2.0]),
])
def test_lines_arcs_and_waypoints_keep_one_branch(name, q0):
    """6R arms: every sample met to 1e-9, steps within the bound, no configuration flip."""
    robot = models.get(name)
    q0 = np.array(q0)
    A = robot.fk(q0)
    B = A.copy()
    B[:3, 3] += [0.08, -0.06, 0.05]
    B[:3, :3] = A[:3, :3] @ so3_exp(np.array([0.3, 0.1, -0.2]))
    C = B.copy()
    C[:3, 3] += [-0.05, -0.05, 0.0]
    for path in (line(A, B, max_step=0.004),
                 arc(A, A[:3, 3] + [0.05, 0.0, 0.0], [0, 0, 1], 1.5, max_step=0.004),
                 waypoints(np.stack([A, B, C]), blend=0.02, max_step=0.004)):
        jp = joint_path(robot, path, q0=q0, max_joint_step=0.2)
        assert jp.success, jp.reason
        assert len(jp) == len(path)
        assert jp.position_error.max() < 1e-9 and jp.orientation_error.max() < 1e-9
        assert jp.largest_step <= 0.2
        assert np.abs(jp.q[0] - q0).max() < 1e-9  # starts at q0 itself
        signs = _configuration(robot, jp.q)
        assert np.all(signs == signs[0]), "a configuration flip"


@pytest.mark.parametrize("joint,q_near,dq_a,dq_b", [
    (4, [0.4, -1.3, 1.5, -1.2, 0.02, 0.5], [0, -0.05, 0.05, 0, 0.02, 0],
     [0, 0.05, -0.05, 0, 0.016, 0]),                      # wrist: q5 within 2.1° of 0
    (2, [0.4, -1.0, 0.01, -1.2, -1.2, 0.5], [0, -0.05, 0.03, 0, 0, 0],
     [0, 0.05, 0.02, 0, 0, 0]),                           # elbow: q3 within 1.7° of 0
])
def test_paths_close_to_a_singularity_keep_their_branch(joint, q_near, dq_a, dq_b):
    """UR5 lines passing within 2° of the wrist or elbow singularity: no flip, bounded steps."""
    robot = models.get("ur5")
    qa = np.array(q_near) + dq_a
    qb = np.array(q_near) + dq_b
    P = line(robot.fk(qa), robot.fk(qb), max_step=0.001, max_angle=math.radians(0.2))
    jp = joint_path(robot, P, q0=qa, max_joint_step=0.3)
    assert jp.success, jp.reason
    assert jp.position_error.max() < 1e-9 and jp.orientation_error.max() < 1e-9
    assert jp.largest_step <= 0.3
    assert np.abs(jp.q[:, joint]).min() < math.radians(2.2)  # the path does come close
    signs = _configuration(robot, jp.q)
    assert np.all(signs == signs[0]), "a configuration flip"


def test_unreachable_sample_stops_with_the_best_partial_path():
    """A line leaving the workspace: refused at the first unreachable sample, prefix kept."""
    robot = models.get("ur5")
    q0 = np.array([0.0, -1.0, 1.0, -1.0, -1.5, 0.0])
    A = robot.fk(q0)
    B = A.copy()
    B[:3, 3] = A[:3, 3] / np.linalg.norm(A[:3, 3]) * 1.5   # beyond the UR5's ~0.95 m reach
    jp = joint_path(robot, line(A, B, max_step=0.01), q0=q0)
    assert not jp.success and "out of reach" in jp.reason
    assert jp.failed_at == len(jp) and jp.failed_at > 0
    reach = robot.fk(jp.q)[:, :3, 3]
    assert np.allclose(reach, line(A, B, max_step=0.01).targets[:len(jp), :3, 3], atol=1e-9)


def test_too_small_a_step_bound_is_refused_with_the_joint_named():
    """A bound below what the path needs: refused at a sample, naming the joint and sizes."""
    robot, P = _ur5_line([0.1, 0.1, -0.1], np.array([0.3, -1.2, 1.4, -1.0, -1.5, 0.4]))
    jp = joint_path(robot, P, max_joint_step=1e-4)
    assert not jp.success and jp.failed_at == 1
    assert "joint" in jp.reason and "max_joint_step" in jp.reason


@settings(max_examples=8, deadline=None)
@given(dx=st.floats(-0.1, 0.1), dy=st.floats(-0.1, 0.1), dz=st.floats(-0.1, 0.1))
def test_reversing_a_path_reverses_the_joint_path(dx, dy, dz):
    """joint_path(reversed poses) is the joint path reversed (the least motion is symmetric)."""
    robot, P = _ur5_line([dx, dy, dz], np.array([0.3, -1.2, 1.4, -1.0, -1.5, 0.4]), step=0.01)
    fwd = joint_path(robot, P.targets)
    back = joint_path(robot, P.targets[::-1].copy())
    assert fwd.success and back.success
    d = (fwd.q - back.q[::-1] + math.pi) % (2 * math.pi) - math.pi
    assert np.abs(d).max() < 1e-9


def test_redundant_arms_keep_their_redundancy():
    """The iiwa keeps its arm angle (S-R-S), the Panda its last joint; both meet every pose."""
    from serialkin.ik.analytic.arm_angle import arm_angle

    for name, q0 in (("iiwa7", [0.3, 0.6, -0.2, -1.2, 0.4, 0.8, 0.1]),
                     ("panda", [0.2, -0.3, 0.1, -2.0, 0.1, 1.8, 0.6])):
        robot = models.get(name)
        q0 = np.array(q0)
        A = robot.fk(q0)
        B = A.copy()
        B[:3, 3] += [0.06, -0.04, 0.05]
        jp = joint_path(robot, line(A, B, max_step=0.004), q0=q0, max_joint_step=0.2)
        assert jp.success, jp.reason
        assert jp.position_error.max() < 1e-9 and jp.orientation_error.max() < 1e-9
        assert np.abs(jp.q[0] - q0).max() < 1e-9
        if jp.method == "arm-angle":
            psi = arm_angle(robot, jp.q, jp.reference)
            assert np.abs(psi - jp.redundancy).max() < 1e-9
        else:
            assert jp.method == "locked-joint" and np.all(jp.q[:, 6] == q0[6])


def test_joint_path_bad_input_is_named():
    """A point path, a bad bound and a wrong q0 are refused, naming the argument."""
    from serialkin.tracking import Path

    robot = models.get("ur5")
    with pytest.raises(InputError, match="pose path"):
        joint_path(robot, Path.from_points(np.zeros((3, 3))))
    with pytest.raises(InputError, match="max_joint_step"):
        joint_path(robot, np.stack([np.eye(4)] * 2), max_joint_step=0.0)
    with pytest.raises(InputError, match="q0"):
        joint_path(robot, np.stack([np.eye(4)] * 2), q0=np.zeros(5))


# ------------------------------------------------------------------------ timing

def _ur5_joint_path():
    robot, P = _ur5_line([0.15, 0.1, -0.1], np.array([0.3, -1.2, 1.4, -1.0, -1.5, 0.4]))
    return robot, joint_path(robot, P, q0=np.array([0.3, -1.2, 1.4, -1.0, -1.5, 0.4]))


def test_timing_respects_every_limit_by_finite_differences():
    """q̇ and q̈ of the output, and finite differences of q, stay within the limits."""
    robot, jp = _ur5_joint_path()
    v = np.array([1.0, 1.0, 1.2, 2.0, 2.0, 2.0])
    a = np.array([2.0, 2.0, 3.0, 4.0, 4.0, 4.0])
    tp = time_optimal(jp.q, v, a, robot=robot, dt=0.002)
    assert tp.t[0] == 0.0 and tp.t[-1] == pytest.approx(tp.duration)
    assert np.all(np.abs(tp.qd) <= v * (1 + 1e-6))
    assert np.all(np.abs(tp.qdd) <= a * (1 + 1e-6))
    dt = np.diff(tp.t)
    fd_v = np.diff(tp.q, axis=0) / dt[:, None]
    assert np.all(np.abs(fd_v) <= v * 1.001)
    assert np.all(np.abs(np.diff(fd_v, axis=0)[:-1] / dt[:-2, None]) <= a * 1.02)
    # the timed path follows the joint path: its start, end and every sample on the spline
    assert np.allclose(tp.q[0], jp.q[0], atol=1e-12) and np.allclose(tp.q[-1], jp.q[-1],
                                                                         atol=1e-9)
    # some limit is active (time-optimal: a velocity or acceleration bound is reached)
    assert max((np.abs(tp.qd) / v).max(), (np.abs(tp.qdd) / a).max()) > 0.99


def test_timing_matches_toppra_directly():
    """The duration equals toppra's own on the same spline and limits (within 1 %)."""
    import toppra as ta
    import toppra.algorithm
    import toppra.constraint

    robot, jp = _ur5_joint_path()
    v, a = 1.5, 3.0
    tp = time_optimal(jp.q, v, a)
    s = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(jp.q, axis=0), axis=1))])
    path = ta.SplineInterpolator(s, jp.q)
    n = jp.q.shape[1]
    cons = [ta.constraint.JointVelocityConstraint(np.tile([-v, v], (n, 1))),
            ta.constraint.JointAccelerationConstraint(np.tile([-a, a], (n, 1)))]
    ref = ta.algorithm.TOPPRA(cons, path, gridpoints=np.linspace(0, s[-1], 1000))
    assert tp.duration == pytest.approx(ref.compute_trajectory(0, 0).duration, rel=0.01)


def test_cartesian_speed_limit_caps_the_tool_speed():
    """With a Cartesian speed limit the tool position never moves faster than it."""
    robot, jp = _ur5_joint_path()
    tp = time_optimal(jp.q, 3.0, 10.0, robot=robot, cartesian_speed=0.05, dt=0.005)
    J = robot.jacobian(tp.q)[:, :3, :]
    speed = np.linalg.norm(np.einsum("kij,kj->ki", J, tp.qd), axis=1)
    assert speed.max() <= 0.05 * 1.01
    assert tp.duration >= 0.9 * np.linalg.norm(
        robot.fk(jp.q[-1])[:3, 3] - robot.fk(jp.q[0])[:3, 3]) / 0.05


def test_timed_path_files_round_trip(tmp_path):
    """CSV and JSON hold t, q, q̇, q̈ with units and the limits; they read back equal."""
    import json

    robot, jp = _ur5_joint_path()
    tp = time_optimal(jp.q, 1.0, 2.0, robot=robot)
    data = json.loads(tp.to_json(tmp_path / "traj.json").read_text())
    assert data["units"]["t"] == "s" and np.allclose(data["q"], tp.q)
    rows = np.loadtxt(tp.to_csv(tmp_path / "traj.csv"), delimiter=",", skiprows=1)
    head = (tmp_path / "traj.csv").read_text().splitlines()[0]
    assert head.startswith("t [s],") and "[rad/s]" in head
    assert np.array_equal(rows[:, 0], tp.t) and np.array_equal(rows[:, 1:7], tp.q)


def test_timing_bad_input_is_named():
    """Bad limits, a path that does not move and a bad step are refused, naming them."""
    q = np.array([[0.0] * 6, [0.1] * 6])
    with pytest.raises(InputError, match="velocity"):
        time_optimal(q, [1.0] * 5, 1.0)
    with pytest.raises(InputError, match="acceleration"):
        time_optimal(q, 1.0, -1.0)
    with pytest.raises(InputError, match="does not move"):
        time_optimal(np.zeros((3, 6)), 1.0, 1.0)
    with pytest.raises(InputError, match="dt"):
        time_optimal(q, 1.0, 1.0, dt=0.0)
    with pytest.raises(InputError, match="robot"):
        time_optimal(q, 1.0, 1.0, cartesian_speed=0.1)
