"""BFGS and Powell on the pose-error cost (serialkin.ik.optimize, methods 'bfgs', 'powell')."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from serialkin import models
from serialkin._checks import readonly
from serialkin.ik import optimize

from ._numerical_helpers import (
    assert_fails_only_outside_limits,
    assert_solution,
    well_conditioned_q,
)

TOL = 1e-6


@settings(max_examples=30, deadline=None)
@given(seed=st.integers(0, 100_000), name=st.sampled_from(["puma560", "ur5", "panda", "stanford"]),
       weights=st.sampled_from([(1, 1, 1, 1, 1, 1), (1, 1, 1, 0, 0, 0), (2, 0.5, 1, 3, 3, 3)]))
def test_gradient_matches_finite_differences(seed, name, weights):
    """The analytic gradient −JᵀWe equals central differences of E (equal orientation weights)."""
    robot = models.get(name)
    rng = np.random.default_rng(seed)
    q = robot.random_q(seed=rng)
    Tt = robot.fk(robot.random_q(seed=rng))
    # keep the orientation error away from π, where log() switches branch
    Tt[:3, :3] = robot.fk(q + 0.3 * rng.uniform(-1, 1, robot.n))[:3, :3]
    w = readonly(np.array(weights, dtype=float))  # read-only, as the solver passes its inputs
    n = robot.n
    g = np.empty(n)
    F, meta = robot.chain.F, robot.chain.meta
    optimize.cost_and_gradient(q, F, meta, readonly(Tt), w, np.empty((6, n)), np.empty((4, 4)),
                               np.empty(6), g)
    h = 1e-6
    fd = np.empty(n)
    for j in range(n):
        dq = np.zeros(n)
        dq[j] = h
        cp = optimize.cost_only(q + dq, F, meta, readonly(Tt), w, np.empty((4, 4)), np.empty(6))
        cm = optimize.cost_only(q - dq, F, meta, readonly(Tt), w, np.empty((4, 4)), np.empty(6))
        fd[j] = (cp - cm) / (2 * h)
    np.testing.assert_allclose(g, fd, rtol=1e-5, atol=1e-7)


@pytest.mark.parametrize("method", ["bfgs", "powell"])
@pytest.mark.parametrize("name", ["ur5", "puma560"])
def test_full_pose_round_trip(method, name):
    """FK of the answer matches full-pose targets within 1e-6 m / 1e-6 rad, inside limits."""
    robot = models.get(name)
    count = 2 if method == "bfgs" else 1
    for k, q in enumerate(well_conditioned_q(robot, count, seed=10)):
        T = robot.fk(q)
        res = robot.ik(T, method=method, tol=TOL, seed=k, restarts=30)
        assert_solution(robot, res, T, np.ones(6), TOL)


@pytest.mark.slow
def test_bfgs_redundant_panda():
    """BFGS solves full poses of the 7-DOF Panda (bounds keep q inside the limits)."""
    robot = models.panda()
    for k, q in enumerate(well_conditioned_q(robot, 2, seed=11)):
        T = robot.fk(q)
        res = robot.ik(T, method="bfgs", tol=TOL, seed=k, restarts=30)
        assert_solution(robot, res, T, np.ones(6), TOL)


@pytest.mark.parametrize("method", ["bfgs", "powell"])
def test_planar_pose_and_default_tolerance(method):
    """(x, y, φ) targets on the 3-link arm, at the library's default tolerance (1e-9)."""
    robot = models.three_link()
    q = np.array([0.4, -0.9, 0.6])
    T = robot.fk(q)
    res = robot.ik([T[0, 3], T[1, 3], math.atan2(T[1, 0], T[0, 0])], method=method, seed=0)
    assert_solution(robot, res, T, [1, 1, 0, 0, 0, 1], 1e-9)


def test_position_target_bfgs():
    """3-D position targets on a 6R arm (redundant task) within 1e-6 m."""
    robot = models.puma560()
    for k, q in enumerate(well_conditioned_q(robot, 2, seed=12, task="position")):
        T = robot.fk(q)
        res = robot.ik(T[:3, 3], method="bfgs", tol=TOL, seed=k)
        assert_solution(robot, res, T, [1, 1, 1, 0, 0, 0], TOL)


@pytest.mark.parametrize("method", ["bfgs", "powell"])
def test_unreachable_target_fails_cleanly(method):
    """Out of reach: success False with a reason, finite q inside limits, bounded time."""
    robot = models.planar(3, qlim=(-2.0, 2.0))
    res = robot.ik([4.0, 2.0], method=method, tol=TOL, seed=0, restarts=2, max_iter=50)
    assert res.restarts <= 2  # a scipy attempt counts function evaluations, not iterations
    assert not res.success and "no configuration" in res.reason
    assert np.isfinite(res.q).all() and robot.within_limits(res.q)
    assert res.position_error == pytest.approx(math.hypot(4.0, 2.0) - 3.0, abs=1e-4)


@pytest.mark.parametrize("method", ["bfgs", "powell"])
def test_bounds_keep_q_inside_limits(method):
    """A target reachable only outside the limits fails; every returned q is inside them."""
    assert_fails_only_outside_limits(method, tol=TOL, restarts=2, max_iter=50)


@pytest.mark.parametrize("method", ["bfgs", "powell"])
def test_same_seed_same_answer(method):
    """The same seed gives the same q, and a batch returns what single solves return."""
    robot = models.ur5()
    T = robot.fk(well_conditioned_q(robot, 1, seed=13)[0])
    a = robot.ik(T, method=method, seed=5, tol=1e-4, restarts=3)
    b = robot.ik(T, method=method, seed=5, tol=1e-4, restarts=3)
    np.testing.assert_array_equal(a.q, b.q)
    assert a.iterations == b.iterations
    batch = robot.ik(np.stack([T, T]), method=method, seed=5, tol=1e-4, restarts=3)
    np.testing.assert_array_equal(batch.q[1], a.q)


def test_powell_xtol_option_is_validated():
    """Powell's xtol option is accepted and a negative value is rejected by name."""
    robot = models.planar(2)
    res = robot.ik([1.2, 0.5], method="powell", tol=TOL, seed=0, xtol=1e-4)
    assert res.success
    with pytest.raises(ValueError, match="xtol"):
        robot.ik([1.2, 0.5], method="powell", xtol=-1.0)


def test_respect_limits_false_uses_no_bounds():
    """With respect_limits=False the solver may leave the limits to reach the target."""
    robot = models.planar(2, qlim=(0.0, 0.5))
    T = robot.fk(np.array([-1.0, -1.0]))
    res = robot.ik(T[:2, 3], method="bfgs", tol=TOL, seed=0, respect_limits=False)
    assert res.success
    assert np.linalg.norm(robot.fk(res.q)[:2, 3] - T[:2, 3]) <= TOL


@pytest.mark.parametrize("method", ["bfgs", "powell"])
def test_singular_targets(method):
    """Stretched-arm and aligned-wrist targets end finite, inside limits, without error."""
    planar = models.planar(3)
    res = planar.ik([3.0, 0.0], method=method, tol=TOL, seed=1, restarts=2, max_iter=100)
    assert np.isfinite(res.q).all() and res.position_error < 1e-3
    puma = models.puma560()
    T = puma.fk(np.array([0.3, -0.6, 0.4, 0.7, 0.0, -0.5]))
    res = puma.ik(T, method=method, tol=TOL, seed=0, restarts=30 if method == "bfgs" else 3)
    assert np.isfinite(res.q).all() and puma.within_limits(res.q)
    if method == "bfgs":
        assert_solution(puma, res, T, np.ones(6), TOL)
