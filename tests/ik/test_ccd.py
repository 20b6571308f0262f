"""Cyclic coordinate descent (serialkin.ik.ccd, method 'ccd')."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import serialkin as sk
from serialkin import models
from serialkin._checks import readonly
from serialkin.ik import ccd
from serialkin.ik.heuristic_methods import characteristic_length
from serialkin.spatial.pose import pose_error

from ._numerical_helpers import (
    assert_bounded_work,
    assert_fails_only_outside_limits,
    assert_solution,
    well_conditioned_q,
)

TOL = 1e-6
POSITION = np.array([1.0, 1.0, 1.0, 0.0, 0.0, 0.0])
PLANAR = np.array([1.0, 1.0, 0.0, 0.0, 0.0, 0.0])
PLANAR_POSE = np.array([1.0, 1.0, 0.0, 0.0, 0.0, 1.0])


def _limit(robot, side: int) -> np.ndarray:
    """Lower (0) or upper (1) joint limits as the solver passes them: read-only, contiguous."""
    return readonly(np.ascontiguousarray(robot.qlim[:, side]))


@pytest.mark.parametrize("name", ["puma560", "ur5", "panda", "stanford", "iiwa7", "scara"])
def test_position_targets_spatial(name):
    """FK of the CCD answer reaches 3-D position targets within 1e-6 m, q inside limits."""
    robot = models.get(name)
    for k, q in enumerate(well_conditioned_q(robot, 3, seed=1, task="position")):
        T = robot.fk(q)
        res = robot.ik(T[:3, 3], method="ccd", tol=TOL, seed=k)
        assert_solution(robot, res, T, POSITION, TOL)


@pytest.mark.parametrize("robot", [models.planar(3), models.planar(6, 0.1), models.two_link()],
                         ids=["planar3", "planar6", "two_link"])
def test_planar_targets(robot):
    """Planar (x, y) targets are reached within 1e-6 m."""
    for k, q in enumerate(well_conditioned_q(robot, 4, seed=2, task="planar")):
        T = robot.fk(q)
        res = robot.ik(T[:2, 3], method="ccd", tol=TOL, seed=k)
        assert_solution(robot, res, T, PLANAR, TOL)


def test_planar_pose_targets():
    """(x, y, φ) targets on the chapter's 3-link arm: position and heading within 1e-6."""
    robot = models.three_link()
    for k, q in enumerate(well_conditioned_q(robot, 3, seed=3, task="planar_pose")):
        T = robot.fk(q)
        phi = math.atan2(T[1, 0], T[0, 0])
        res = robot.ik([T[0, 3], T[1, 3], phi], method="ccd", tol=TOL, seed=k)
        assert_solution(robot, res, T, PLANAR_POSE, TOL)


@pytest.mark.slow
@pytest.mark.parametrize("name", ["ur5", "panda"])
def test_full_pose_targets_with_restarts(name):
    """Full 6-D poses are reached within 1e-6 m / 1e-6 rad (CCD may need restarts)."""
    robot = models.get(name)
    for k, q in enumerate(well_conditioned_q(robot, 2, seed=4)):
        T = robot.fk(q)
        res = robot.ik(T, method="ccd", tol=TOL, seed=k, restarts=60)
        assert_solution(robot, res, T, np.ones(6), TOL)


def _one_joint_robot(a, alpha, d, joint_type="R", qlim=(-np.inf, np.inf)):
    return sk.Robot.from_dh([{"a": a, "alpha": alpha, "d": d, "theta": 0.3, "type": joint_type,
                             "qlim": qlim}],
                            tool=sk.spatial.transl([0.1, -0.2, 0.15]) @ sk.spatial.trotx(0.4))


def _cost(robot, q, T_target, w_orient):
    T = robot.fk(np.array([q]))
    c = float(np.sum((T_target[:3, 3] - T[:3, 3]) ** 2))
    return c + w_orient * float(np.sum((T_target[:3, :3] - T[:3, :3]) ** 2))


@settings(max_examples=30, deadline=None)
@given(a=st.floats(0.0, 1.0), alpha=st.floats(-3.0, 3.0), d=st.floats(-0.5, 0.5),
       qt=st.floats(-3.0, 3.0), q0=st.floats(-3.0, 3.0), w_orient=st.sampled_from([0.0, 0.3]),
       lo=st.floats(-3.0, 0.0), width=st.floats(0.1, 7.0))
def test_one_joint_step_is_the_exact_optimum(a, alpha, d, qt, q0, w_orient, lo, width):
    """A CCD step of a revolute joint minimises the weighted cost over its (limited) range."""
    hi = lo + width
    robot = _one_joint_robot(a, alpha, d, qlim=(lo, hi))
    Tt = robot.fk(np.array([qt]))
    Tt[:3, 3] += np.array([0.05, -0.02, 0.03])  # not exactly reachable
    q = np.array([min(max(q0, lo), hi)])
    ccd.ccd_sweep(q, robot.chain.F, robot.chain.meta, readonly(Tt), np.ones(3), 1.0, w_orient,
                  _limit(robot, 0), _limit(robot, 1), np.empty((6, 1)), np.empty((4, 4)))
    assert lo - 1e-12 <= q[0] <= hi + 1e-12
    grid = np.linspace(lo, hi, 4001)
    best = min(_cost(robot, g, Tt, w_orient) for g in grid)
    assert _cost(robot, q[0], Tt, w_orient) <= best + 1e-9


@settings(max_examples=25, deadline=None)
@given(d=st.floats(-1.0, 1.0), target=st.floats(-2.0, 2.0), lo=st.floats(-1.0, 0.0),
       width=st.floats(0.0, 2.0))
def test_prismatic_step_is_the_clamped_projection(d, target, lo, width):
    """A prismatic CCD step slides to the projection of the target on its axis, clamped."""
    robot = sk.Robot.from_dh([{"a": 0.2, "alpha": 0.5, "d": 0.0, "theta": 0.1, "type": "P",
                               "qlim": (lo, lo + width)}])
    axis_T = robot.fk(np.array([0.0]))
    z = robot.jacobian(np.array([0.0]))[:3, 0]
    Tt = axis_T.copy()
    Tt[:3, 3] += target * z
    q = np.array([min(max(d, lo), lo + width)])
    ccd.ccd_sweep(q, robot.chain.F, robot.chain.meta, readonly(Tt), np.ones(3), 1.0, 0.0,
                  _limit(robot, 0), _limit(robot, 1), np.empty((6, 1)), np.empty((4, 4)))
    assert q[0] == pytest.approx(min(max(target, lo), lo + width), abs=1e-12)


@settings(max_examples=25, deadline=None)
@given(seed=st.integers(0, 10_000), w_orient=st.sampled_from([0.0, 0.05, 1.0]),
       name=st.sampled_from(["puma560", "ur5", "stanford", "panda"]))
def test_sweep_never_increases_the_cost(seed, w_orient, name):
    """A sweep never increases the cost and its analytically tracked pose equals FK(q)."""
    robot = models.get(name)
    rng = np.random.default_rng(seed)
    q = robot.random_q(seed=rng)
    Tt = robot.fk(robot.random_q(seed=rng))
    lo, hi = _limit(robot, 0), _limit(robot, 1)

    def cost(qq):
        T = robot.fk(qq)
        return float(np.sum((Tt[:3, 3] - T[:3, 3]) ** 2)
                     + w_orient * np.sum((Tt[:3, :3] - T[:3, :3]) ** 2))

    before = cost(q)
    T = np.empty((4, 4))
    ccd.ccd_sweep(q, robot.chain.F, robot.chain.meta, readonly(Tt), np.ones(3), 1.0, w_orient,
                  lo, hi, np.empty((6, robot.n)), T)
    assert cost(q) <= before + 1e-12
    assert robot.within_limits(q, 1e-12)
    np.testing.assert_allclose(T, robot.fk(q), atol=1e-12)


def test_unreachable_target_fails_cleanly():
    """Out-of-reach targets: success False with a reason, finite q inside the limits, fast."""
    robot = models.planar(3, qlim=(-2.0, 2.0))
    res = robot.ik([5.0, 1.0], method="ccd", tol=TOL, seed=0, restarts=3)
    assert_bounded_work(res, "ccd", 3)
    assert not res.success
    assert "no configuration" in res.reason
    assert np.isfinite(res.q).all() and robot.within_limits(res.q)
    # the best attempt is the stretched arm pointing at the target
    assert res.position_error == pytest.approx(math.hypot(5.0, 1.0) - 3.0, abs=1e-6)


def test_target_reachable_only_outside_limits():
    """A target reachable only outside the joint limits fails, q stays inside them."""
    assert_fails_only_outside_limits("ccd", tol=TOL, restarts=3)


def test_same_seed_same_answer():
    """The same seed gives the same q; batch solves agree with single solves."""
    robot = models.ur5()
    T = robot.fk(well_conditioned_q(robot, 2, seed=5))
    a = robot.ik(T[0], method="ccd", seed=11, tol=TOL)
    b = robot.ik(T[0], method="ccd", seed=11, tol=TOL)
    np.testing.assert_array_equal(a.q, b.q)
    batch = robot.ik(T, method="ccd", seed=11, tol=TOL)
    np.testing.assert_array_equal(batch.q[0], a.q)
    assert batch.success.shape == (2,)


def test_orientation_weight_option():
    """An explicit orientation weight [m²] is used; a non-positive one is rejected by name."""
    robot = models.three_link()
    T = robot.fk(np.array([0.3, 0.4, -0.5]))
    phi = math.atan2(T[1, 0], T[0, 0])
    target = [T[0, 3], T[1, 3], phi]
    default = robot.ik(target, method="ccd", tol=1e-5, seed=0)
    res = robot.ik(target, method="ccd", tol=1e-5, seed=0, orientation_weight=0.3)
    assert res.success and default.success
    assert res.iterations != default.iterations
    with pytest.raises(ValueError, match="orientation_weight"):
        robot.ik([T[0, 3], T[1, 3], phi], method="ccd", orientation_weight=-1.0)
    assert characteristic_length(robot) > 0


def test_partial_position_mask():
    """With only x and y selected, CCD matches them and ignores z."""
    robot = models.puma560()
    q = well_conditioned_q(robot, 1, seed=6, task="position")[0]
    T = robot.fk(q)
    target = T[:3, 3] + np.array([0.0, 0.0, 0.05])
    res = robot.ik(target, method="ccd", tol=TOL, seed=0, mask=[1, 1, 0, 0, 0, 0])
    assert res.success
    e = pose_error(robot.fk(res.q), T)
    assert np.hypot(e[0], e[1]) <= TOL


@pytest.mark.parametrize("target", [[3.0, 0.0], [0.0, -3.0]])
def test_workspace_boundary_target(target):
    """A target at full reach (stretched, singular arm) is approached without NaN or error."""
    robot = models.planar(3)
    res = robot.ik(target, method="ccd", tol=TOL, seed=1, restarts=2)
    assert_bounded_work(res, "ccd", 2)
    assert np.isfinite(res.q).all()
    # convergence is sublinear at the boundary (documented): millimetres, not micrometres
    assert res.position_error < 1e-2


def test_aligned_wrist_axes_target():
    """A Puma 560 pose with aligned wrist axes (q5 = 0) is solved to position 1e-6."""
    robot = models.puma560()
    q = np.array([0.3, -0.6, 0.4, 0.7, 0.0, -0.5])
    T = robot.fk(q)
    res = robot.ik(T[:3, 3], method="ccd", tol=TOL, seed=0)
    assert_solution(robot, res, T, POSITION, TOL)
    full = robot.ik(T, method="ccd", tol=TOL, seed=0, restarts=3)
    assert np.isfinite(full.q).all() and robot.within_limits(full.q)
