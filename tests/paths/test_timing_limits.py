"""Timing with the robot's own joint limits, and the jerk-limited timing (ruckig)."""

from __future__ import annotations

import numpy as np
import pytest

from serialkin import models
from serialkin.errors import InputError
from serialkin.paths import jerk_limited, joint_path, line, time_optimal
from serialkin.spatial.lie import so3_exp

Q0 = {"ur5": [0.3, -1.2, 1.4, -1.0, -1.5, 0.4],
      "panda": [0.2, -0.3, 0.1, -2.0, 0.1, 1.8, 0.6]}


def _path(name, offset=(0.15, 0.1, -0.1), step=0.003):
    robot = models.get(name)
    q0 = np.array(Q0[name])
    A = robot.fk(q0)
    B = A.copy()
    B[:3, 3] += offset
    B[:3, :3] = A[:3, :3] @ so3_exp(np.array([0.2, -0.3, 0.4]))
    P = line(A, B, max_step=step)
    jp = joint_path(robot, P, q0=q0, max_joint_step=0.2)
    assert jp.success, jp.reason
    return robot, P, jp


def _within(tp, jerk=None, rel=1e-6):
    """q̇, q̈ of the output and finite differences of q (and of q̈ for the jerk) within limits."""
    assert np.all(np.abs(tp.qd) <= tp.velocity * (1 + rel))
    assert np.all(np.abs(tp.qdd) <= tp.acceleration * (1 + rel))
    dt = np.diff(tp.t)
    fd_v = np.diff(tp.q, axis=0) / dt[:, None]
    assert np.all(np.abs(fd_v) <= tp.velocity * 1.001)
    assert np.all(np.abs(np.diff(fd_v, axis=0)[:-1] / dt[:-2, None]) <= tp.acceleration * 1.02)
    if jerk is not None:
        fd_j = np.diff(tp.qdd, axis=0)[:-1] / dt[:-1, None]
        assert np.all(np.abs(fd_j) <= jerk * 1.001)


def test_time_optimal_takes_the_robots_own_limits():
    """Panda with no limits given: the same timing as with its data-sheet limits passed."""
    robot, _, jp = _path("panda")
    own = time_optimal(jp.q, robot=robot)
    given = time_optimal(jp.q, robot.velocity_limits, robot.acceleration_limits)
    assert own.duration == given.duration
    assert np.array_equal(own.velocity, robot.velocity_limits)
    _within(own)
    # one of them given, the other the robot's
    half = time_optimal(jp.q, acceleration=robot.acceleration_limits / 2, robot=robot)
    assert np.array_equal(half.velocity, robot.velocity_limits)
    assert half.duration > own.duration


def test_missing_limits_are_named():
    """No limit given and none stated: the error names the kind, the robot and the joints."""
    robot, _, jp = _path("ur5")
    with pytest.raises(InputError, match="acceleration limits.*'UR5' states none"):
        time_optimal(jp.q, robot=robot)
    with pytest.raises(InputError, match="velocity limits.*robot="):
        time_optimal(jp.q, acceleration=2.0)
    partial = robot.with_rate_limits(velocity=[1, 1, np.inf, 1, 1, np.inf])
    with pytest.raises(InputError, match="for joint\\(s\\) q3, q6"):
        time_optimal(jp.q, acceleration=2.0, robot=partial)
    with pytest.raises(InputError, match="acceleration limits"):
        jerk_limited(jp.q, 50.0, robot=robot)


@pytest.mark.parametrize("name,jerk", [("ur5", 30.0), ("panda", [7500, 3750, 5000, 6250,
                                                                 7500, 10000, 10000])])
def test_jerk_limited_timing_respects_every_limit(name, jerk):
    """Velocity, acceleration and jerk within their limits by finite differences; at rest."""
    robot, _, jp = _path(name)
    acc = 4.0 if name == "ur5" else None
    tp = jerk_limited(jp.q, jerk, acceleration=acc, robot=robot, dt=0.002)
    assert tp.method == "ruckig" and np.array_equal(tp.jerk, np.broadcast_to(jerk, (robot.n,)))
    _within(tp, np.asarray(jerk, dtype=float))
    assert tp.t[0] == 0.0 and tp.t[-1] == pytest.approx(tp.duration)
    assert np.allclose(tp.q[0], jp.q[0], atol=1e-12) and np.allclose(tp.q[-1], jp.q[-1],
                                                                         atol=1e-9)
    assert np.abs(tp.qd[[0, -1]]).max() < 1e-9 and np.abs(tp.qdd[[0, -1]]).max() < 1e-6


def test_jerk_limited_follows_the_path_and_is_no_faster_than_time_optimal():
    """The tool stays on the line (spline error only); the duration is at least toppra's."""
    robot, P, jp = _path("ur5")
    tp = jerk_limited(jp.q, 30.0, acceleration=4.0, robot=robot, dt=0.005)
    a, b = P.targets[0, :3, 3], P.targets[-1, :3, 3]
    u = (b - a) / np.linalg.norm(b - a)
    p = robot.fk(tp.q)[:, :3, 3] - a
    off = np.linalg.norm(p - (p @ u)[:, None] * u, axis=1)
    assert off.max() < 1e-5
    assert tp.duration >= time_optimal(jp.q, acceleration=4.0, robot=robot).duration * 0.99
    # a lower jerk limit takes longer
    assert jerk_limited(jp.q, 5.0, acceleration=4.0, robot=robot).duration > tp.duration


def test_jerk_limited_bad_input_is_named():
    """A bad jerk limit and a path that does not move are refused, naming them."""
    q = np.array([[0.0] * 6, [0.1] * 6])
    with pytest.raises(InputError, match="jerk"):
        jerk_limited(q, -1.0, 1.0, 1.0)
    with pytest.raises(InputError, match="does not move"):
        jerk_limited(np.zeros((3, 6)), 1.0, 1.0, 1.0)
