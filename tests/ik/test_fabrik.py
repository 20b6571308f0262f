"""FABRIK (serialkin.ik.fabrik, method 'fabrik'): planar revolute chains."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import serialkin as sk
from serialkin import models
from serialkin._checks import readonly
from serialkin.errors import NotSupportedError
from serialkin.ik import fabrik

from ._numerical_helpers import (
    assert_bounded_work,
    assert_fails_only_outside_limits,
    assert_solution,
    well_conditioned_q,
)

TOL = 1e-6
PLANAR = np.array([1.0, 1.0, 0.0, 0.0, 0.0, 0.0])
PLANAR_POSE = np.array([1.0, 1.0, 0.0, 0.0, 0.0, 1.0])
CHAINS = {
    "planar3": lambda: models.planar(3),
    "planar6": lambda: models.planar(6, 0.1),
    "two_link": models.two_link,
    "three_link": models.three_link,
    "planar20_limited": lambda: models.planar(20, 0.01675, qlim=(-1.745, 1.745)),
    "uneven_limited": lambda: models.planar(4, [0.5, 0.3, 0.4, 0.2], qlim=(-2.0, 2.0)),
}


def _limit(robot, side: int) -> np.ndarray:
    """Lower (0) or upper (1) joint limits as the solver passes them: read-only, contiguous."""
    return readonly(np.ascontiguousarray(robot.qlim[:, side]))


@pytest.mark.parametrize("name", sorted(CHAINS))
def test_planar_position_targets(name):
    """(x, y) targets are reached within 1e-6 m and q stays inside the joint limits."""
    robot = CHAINS[name]()
    for k, q in enumerate(well_conditioned_q(robot, 4, seed=1, task="planar")):
        T = robot.fk(q)
        res = robot.ik(T[:2, 3], method="fabrik", tol=TOL, seed=k)
        assert_solution(robot, res, T, PLANAR, TOL)


@pytest.mark.parametrize("name", ["planar3", "three_link", "planar6", "uneven_limited"])
def test_planar_pose_targets_final_link_constraint(name):
    """(x, y, φ) targets: the last link's heading is fixed first, position and heading met."""
    robot = CHAINS[name]()
    for k, q in enumerate(well_conditioned_q(robot, 3, seed=2, task="planar_pose")):
        T = robot.fk(q)
        phi = math.atan2(T[1, 0], T[0, 0])
        res = robot.ik([T[0, 3], T[1, 3], phi], method="fabrik", tol=TOL, seed=k)
        assert_solution(robot, res, T, PLANAR_POSE, TOL)


def test_chain_in_a_tilted_plane():
    """A planar chain in a tilted plane solves in-plane positions and reachable full poses."""
    flat = models.planar(3, [0.4, 0.3, 0.2])
    robot = flat.with_base(
        sk.spatial.trotx(0.7) @ sk.spatial.troty(-0.4) @ sk.spatial.transl([0.1, 0.2, 0.3]))
    assert not robot.is_planar
    # the base transform does not change conditioning: sample on the flat twin
    for k, q in enumerate(well_conditioned_q(flat, 3, seed=3, task="planar")):
        T = robot.fk(q)
        res = robot.ik(T[:3, 3], method="fabrik", tol=TOL, seed=k)
        assert_solution(robot, res, T, [1, 1, 1, 0, 0, 0], TOL)
        res = robot.ik(T, method="fabrik", tol=TOL, seed=k)
        assert_solution(robot, res, T, np.ones(6), TOL)


def _reference_fabrik_tip(points, lengths, target):
    """One textbook FABRIK iteration (forward then backward reaching) on 2-D points."""
    p = points.copy()
    base = p[0].copy()
    p[-1] = target
    for i in range(len(lengths) - 1, -1, -1):
        lam = lengths[i] / np.linalg.norm(p[i + 1] - p[i])
        p[i] = (1 - lam) * p[i + 1] + lam * p[i]
    p[0] = base
    for i in range(len(lengths)):
        lam = lengths[i] / np.linalg.norm(p[i + 1] - p[i])
        p[i + 1] = (1 - lam) * p[i] + lam * p[i + 1]
    return p


@settings(max_examples=30, deadline=None)
@given(seed=st.integers(0, 100_000), n=st.integers(2, 7))
def test_one_pass_equals_textbook_fabrik(seed, n):
    """Without active limits one pass puts every joint where textbook FABRIK puts its point."""
    rng = np.random.default_rng(seed)
    lengths = rng.uniform(0.2, 1.0, n)
    robot = models.planar(n, lengths)
    q = rng.uniform(-np.pi, np.pi, n)
    target = rng.uniform(-0.6, 0.6, 2) * lengths.sum()
    Tt = np.eye(4)
    Tt[:2, 3] = target
    frames = robot.fk_all(q)
    points = np.vstack([frames[:n, :2, 3], robot.fk(q)[:2, 3]])
    expected = _reference_fabrik_tip(points, lengths, target)
    a, e1, e2, sign = fabrik.fabrik_domain(robot)
    qq = q.copy()
    inf = np.full(n, np.inf)
    fabrik.fabrik_pass(qq, robot.chain.F, robot.chain.meta, readonly(Tt),
                       np.array([1.0, 1.0, 0.0]), False, a, e1, e2, sign, readonly(-inf),
                       readonly(inf), np.empty((6, n)), np.empty((4, 4)), np.empty((n + 1, 2)),
                       np.empty(n), np.empty(n))
    frames = robot.fk_all(qq)
    got = np.vstack([frames[:n, :2, 3], robot.fk(qq)[:2, 3]])
    np.testing.assert_allclose(got, expected, atol=1e-9)


@settings(max_examples=25, deadline=None)
@given(seed=st.integers(0, 100_000))
def test_limits_are_clamped(seed):
    """With tight limits every pass keeps q inside them (clamping in the angle recovery)."""
    rng = np.random.default_rng(seed)
    robot = models.planar(5, 0.3, qlim=(-0.6, 0.9))
    q = robot.random_q(seed=rng)
    Tt = np.eye(4)
    Tt[:2, 3] = rng.uniform(-1.5, 1.5, 2)
    a, e1, e2, sign = fabrik.fabrik_domain(robot)
    lo, hi = _limit(robot, 0), _limit(robot, 1)
    w = readonly(np.array([1.0, 1, 0, 0, 0, 0]))  # read-only, as the solver passes its inputs
    fabrik.fabrik_attempt(q, robot.chain.F, robot.chain.meta, readonly(Tt), w,
                          a, e1, e2, sign, lo, hi, TOL, TOL, 50, 20, 0.05)
    assert robot.within_limits(q, 1e-12)


def test_unreachable_target_stretches_the_chain():
    """Beyond reach: success False, reason, best attempt is the straight chain at the target."""
    robot = models.planar(3, [0.5, 0.4, 0.3])
    res = robot.ik([2.0, -1.0], method="fabrik", tol=TOL, seed=0, restarts=3)
    assert_bounded_work(res, "fabrik", 3)
    assert not res.success and "no configuration" in res.reason
    assert np.isfinite(res.q).all()
    assert res.position_error == pytest.approx(math.hypot(2.0, -1.0) - 1.2, abs=1e-9)
    tip = robot.fk(res.q)[:2, 3]
    np.testing.assert_allclose(tip / np.linalg.norm(tip), np.array([2.0, -1.0]) / math.hypot(2, 1),
                               atol=1e-9)


def test_target_reachable_only_outside_limits():
    """A target reachable only outside the joint limits fails, q inside the limits."""
    assert_fails_only_outside_limits("fabrik", tol=TOL, restarts=3)


@pytest.mark.parametrize("name, match", [("puma560", "parallel"), ("ur5", "parallel"),
                                         ("scara", "prismatic"), ("panda", "parallel")])
def test_outside_the_domain_is_a_clear_error(name, match):
    """Spatial chains / prismatic joints raise NotSupportedError with reason and alternatives."""
    robot = models.get(name)
    with pytest.raises(NotSupportedError, match=match) as info:
        robot.ik(robot.fk(np.zeros(robot.n))[:3, 3] if name != "scara" else
                 robot.fk(np.zeros(robot.n)), method="fabrik")
    assert "ccd" in str(info.value)


def test_same_seed_same_answer():
    """The same seed gives the same q; a batch agrees with single solves."""
    robot = models.planar(6, 0.1)
    T = robot.fk(well_conditioned_q(robot, 3, seed=4, task="planar"))
    a = robot.ik(T[0, :2, 3], method="fabrik", seed=3, tol=TOL)
    b = robot.ik(T[0, :2, 3], method="fabrik", seed=3, tol=TOL)
    np.testing.assert_array_equal(a.q, b.q)
    batch = robot.ik(T[:, :2, 3], method="fabrik", seed=3, tol=TOL)
    np.testing.assert_array_equal(batch.q[0], a.q)
    assert batch.success.all()


@pytest.mark.parametrize("target", [[1.2, 0.0], [0.0, -1.2], [0.6, 0.0]])
def test_boundary_and_folded_targets(target):
    """Targets at full reach or needing a folded arm end without NaN, error or hang."""
    robot = models.planar(3, [0.5, 0.4, 0.3])
    res = robot.ik(target, method="fabrik", tol=TOL, seed=1, restarts=2)
    assert_bounded_work(res, "fabrik", 2)
    assert np.isfinite(res.q).all()
    assert res.position_error < 1e-3
