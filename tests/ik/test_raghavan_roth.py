"""Raghavan–Roth elimination for general 6R arms (ik/analytic/raghavan_roth.py)."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from serialkin import Robot, models
from serialkin.ik.analytic import ik_all
from serialkin.ik.analytic.general import search_candidates
from serialkin.ik.analytic.raghavan_roth import (
    _ANGLES,
    DEGREE,
    N_GRID,
    _apply_q,
    _apply_qt,
    _equations,
    _grid_values,
    _qr,
    _to_coefficients,
    _trig,
    eliminant_roots,
    rr_candidates_from,
)
from serialkin.ik.analytic.structure import general_structure, joint_lines
from serialkin.ik.analytic.subproblems import screw
from serialkin.model.dh import DHLink
from tests.ik.test_analytic_general import _newton_set, _perturbed, _random_arm, _wrapped


def _quantities(l: np.ndarray, p: np.ndarray) -> np.ndarray:
    """The 14 Raghavan–Roth quantities, written out independently of the kernel."""
    return np.concatenate([l, p, [l @ p, p @ p], np.cross(l, p), (p @ p) * l - 2 * (l @ p) * p])


def _basis(t: float) -> np.ndarray:
    """(1, cos t, sin t)."""
    return np.array([1.0, math.cos(t), math.sin(t)])


def _solve(robot: Robot, T: np.ndarray, kernel=rr_candidates_from) -> tuple[int, np.ndarray]:
    """Count and rows of a general-6R kernel for target T."""
    s = general_structure(robot)
    out = np.zeros((16, 6))
    rev = bool(s.order[1] == 1)
    F, meta = robot.chain.F, robot.chain.meta
    if kernel is rr_candidates_from:  # the types ik_all passes (one compiled entry)
        k = kernel(T, s.W, s.P, s.M, rev, False, F, meta, 1e-12, 1e-12, out)
    else:
        k = kernel(T, s.W, s.P, s.M, s.aux, int(s.order[0]), rev, 48, F, meta, 1e-12, 1e-12, out)
    return k, out[:max(k, 0)]


def _assert_complete(robot: Robot, T: np.ndarray, q: np.ndarray, rows: np.ndarray) -> None:
    """Rows meet FK to 1e-10, include q and every row of the 2-D search (grid 48)."""
    assert _wrapped(rows, q).min() < 1e-8
    assert np.abs(robot.fk(rows) - T).max() < 1e-10
    _, searched = _solve(robot, T, search_candidates)
    for r in searched:
        assert _wrapped(rows, r).min() < 1e-8


@settings(max_examples=15, deadline=None)
@given(st.lists(st.tuples(st.floats(-1.0, 1.0), st.floats(-3.1, 3.1), st.floats(-1.0, 1.0)),
                min_size=6, max_size=6), st.integers(0, 2**32 - 1))
def test_both_sides_are_products_of_one_cosine_and_sine_per_joint(rows, seed):
    """The 14 quantities are exact in the 27 (θ3..θ5) and 9 (θ1, θ2) products of (1, c, s)."""
    robot = Robot.from_dh([DHLink(a=a, alpha=al, d=d) for a, al, d in rows])
    W, P, M = joint_lines(robot)
    rng = np.random.default_rng(seed)
    G = robot.fk(rng.uniform(-np.pi, np.pi, 6)) @ np.linalg.inv(M)

    def left(t3, t4, t5):
        E = screw(W[2], P[2], t3, False) @ screw(W[3], P[3], t4, False) @ \
            screw(W[4], P[4], t5, False)
        return _quantities(E[:3, :3] @ W[5], E[:3, :3] @ P[5] + E[:3, 3] - P[2])

    def right(t1, t2):
        E = screw(W[1], P[1], -t2, False) @ screw(W[0], P[0], -t1, False) @ G
        return _quantities(E[:3, :3] @ W[5], E[:3, :3] @ P[5] + E[:3, 3] - P[2])

    V = np.array([left(*_ANGLES[[r // 9, r // 3 % 3, r % 3]]) for r in range(27)])
    Cl = _to_coefficients(V, 3)
    V2 = np.array([right(*_ANGLES[[r // 3, r % 3]]) for r in range(9)])
    Cr = _to_coefficients(V2, 2)
    for t in rng.uniform(-np.pi, np.pi, (5, 5)):
        b = np.kron(np.kron(_basis(t[2]), _basis(t[3])), _basis(t[4]))
        size = 1.0 + np.abs(left(*t[2:])).max()
        assert np.abs(b @ Cl - left(*t[2:])).max() < 1e-11 * size
        b2 = np.kron(_basis(t[0]), _basis(t[1]))
        size = 1.0 + np.abs(right(*t[:2])).max()
        assert np.abs(b2 @ Cr - right(*t[:2])).max() < 1e-11 * size


def test_equations_kernel_matches_the_definition():
    """The compiled 14 quantities equal l, p, l·p, p·p, l×p, (p·p)l − 2(l·p)p."""
    rng = np.random.default_rng(3)
    l, p = rng.normal(size=3), rng.normal(size=3)
    out = np.empty((1, 14))
    _equations(l, p, out, 0)
    np.testing.assert_allclose(out[0], _quantities(l, p), rtol=1e-14, atol=1e-14)


def _trig_from_roots(roots: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Coefficients (a, b) of f(θ) = Π sin((θ − r_i)/2) (16 roots → degree 8)."""
    n = 2 * DEGREE + 1
    t = 2 * np.pi * np.arange(n) / n
    f = np.prod(np.sin((t[:, None] - roots[None]) / 2), axis=1)
    a = np.array([(1 if k == 0 else 2) * np.mean(f * np.cos(k * t)) for k in range(DEGREE + 1)])
    b = np.array([2 * np.mean(f * np.sin(k * t)) for k in range(DEGREE + 1)])
    return a, b


@pytest.mark.parametrize("roots", [
    np.linspace(-3.0, 3.0, 16),                                   # spread out
    np.r_[np.linspace(-3.0, 1.0, 13), 2.0, 2.0015, 2.003],         # a cluster of three
    np.r_[np.linspace(-3.0, 0.5, 14), 1.2, 1.2 + 2e-4],            # a close pair
    # four within 3.3° across a cell boundary, as θ3 of the Manseur–Doty arm (the
    # bracketing before derivatives were isolated first found two of them)
    np.r_[np.linspace(-2.5, 2.5, 12), np.radians([-180.04, -179.07, -177.74, -176.72])],
    np.r_[np.linspace(-2.0, 1.5, 11), 2.5, 2.51, 2.52, 2.53, 2.54],  # five within 0.04
])
def test_eliminant_roots_separates_close_roots(roots):
    """Every real root of a degree-8 trigonometric polynomial, clusters included, to 1e-8 rad."""
    a, b = _trig_from_roots(roots)
    out = np.empty(16)
    near = np.empty(16)
    k, kn = eliminant_roots(a, b, out, near)
    assert k == 16
    found = np.sort(out[:k])
    expected = np.sort((roots + np.pi) % (2 * np.pi) - np.pi)
    np.testing.assert_allclose(found, expected, atol=1e-8)


def test_eliminant_roots_none_and_identically_zero():
    """A positive polynomial has no real root; the zero polynomial is reported (−1)."""
    a = np.zeros(DEGREE + 1)
    b = np.zeros(DEGREE + 1)
    out = np.empty(16)
    near = np.empty(16)
    assert eliminant_roots(a, b, out, near) == (-1, 0)
    a[0], a[3] = 2.0, 1.0  # 2 + cos 3θ > 0
    assert eliminant_roots(a, b, out, near) == (0, 0)


@pytest.mark.parametrize("eta, where", [(1e-4, "near"), (1e-7, "root"), (0.1, None)])
def test_eliminant_roots_lists_near_real_pairs(eta, where):
    """A complex root pair t0 ± iη with η ≤ NEAR_REAL gives the candidate t0.

    Listed as near-real, or as a double root where |f(t0)| is rounding (η ≲ 1e-5);
    beyond NEAR_REAL the pair is dropped.
    """
    t0 = 0.7
    real = np.r_[np.linspace(-3.0, -0.5, 7), np.linspace(1.5, 3.0, 7)]
    n = 2 * DEGREE + 1
    t = 2 * np.pi * np.arange(n) / n
    f = np.prod(np.sin((t[:, None] - real[None]) / 2), axis=1) * (np.cosh(eta) - np.cos(t - t0))
    a = np.array([(1 if k == 0 else 2) * np.mean(f * np.cos(k * t)) for k in range(DEGREE + 1)])
    b = np.array([2 * np.mean(f * np.sin(k * t)) for k in range(DEGREE + 1)])
    out = np.empty(16)
    near = np.empty(16)
    k, kn = eliminant_roots(a, b, out, near)
    assert k == 14 + (where == "root")
    expected = np.sort(np.r_[real, [t0] if where == "root" else []])
    np.testing.assert_allclose(np.sort(out[:k]), expected, atol=1e-6)
    assert kn == (where == "near")
    if kn:
        assert abs(near[0] - t0) < 1e-6


def test_eliminant_roots_agree_with_a_high_precision_solve():
    """The real roots of 60 random degree-8 polynomials are mpmath's, to 1e-8 rad.

    The independent count: 40-digit ``polyroots`` of z⁸·f (z = e^{iθ}; a real root lies
    on |z| = 1); a third of the polynomials have a planted cluster of 2-4 roots within
    0.05 rad, their coefficients then perturbed so that some pairs turn complex.
    """
    mpmath = pytest.importorskip("mpmath")
    mpmath.mp.dps = 40
    rng = np.random.default_rng(11)
    out = np.empty(16)
    near = np.empty(16)
    for i in range(60):
        if i % 3 == 0:  # a planted cluster of 2-4 roots within 0.05 rad, the rest random
            c = rng.uniform(-np.pi, np.pi)
            m = int(rng.integers(2, 5))
            roots = np.r_[c + rng.uniform(0, 0.05, m), rng.uniform(-np.pi, np.pi, 16 - m)]
            a, b = _trig_from_roots(roots)
            a = a + rng.normal(0, 1e-3, a.shape) * np.abs(a).max()  # some pairs go complex
        else:
            a, b = rng.normal(size=DEGREE + 1), rng.normal(size=DEGREE + 1)
        b[0] = 0.0
        p = [mpmath.mpf(float(a[0]))] * (2 * DEGREE + 1)
        for kk in range(1, DEGREE + 1):
            p[DEGREE + kk] = mpmath.mpc(float(a[kk]), -float(b[kk])) / 2
            p[DEGREE - kk] = mpmath.mpc(float(a[kk]), float(b[kk])) / 2
        z = np.array([complex(r) for r in mpmath.polyroots(p[::-1], maxsteps=400,
                                                            extraprec=200)])
        expected = np.sort(np.angle(z[np.abs(np.log(np.abs(z))) < 1e-7]))
        k, _ = eliminant_roots(a, b, out, near)
        assert k == len(expected)
        np.testing.assert_allclose(np.sort(out[:k]), expected, atol=1e-8)


def test_elimination_agrees_with_the_search_on_random_arms():
    """40 random arms: the same solution set as the 2-D search (grid 48), FK to 1e-10."""
    rng = np.random.default_rng(21)
    for _ in range(40):
        robot = _random_arm(rng)
        q = rng.uniform(-np.pi, np.pi, 6)
        T = robot.fk(q)
        k, rows = _solve(robot, T)
        if k < 0:  # declined: the search answers (rare; checked below that it is rare)
            continue
        assert k % 2 == 0 and k >= 2
        _assert_complete(robot, T, q, rows)


def test_elimination_misses_nothing_newton_finds():
    """5 random arms: no solution Newton reaches from 200 random starts is missing."""
    rng = np.random.default_rng(5)
    for _ in range(5):
        robot = _random_arm(rng)
        T = robot.fk(rng.uniform(-np.pi, np.pi, 6))
        k, rows = _solve(robot, T)
        assert k >= 2
        for f in _newton_set(robot, T, 200, rng):
            assert _wrapped(rows, f).min() < 1e-6


def test_elimination_applies_to_almost_every_random_arm():
    """Of 60 random arms, at most 2 fall back to the search (a degenerate or lost root)."""
    rng = np.random.default_rng(8)
    declined = 0
    for _ in range(60):
        robot = _random_arm(rng)
        k, _ = _solve(robot, robot.fk(rng.uniform(-np.pi, np.pi, 6)))
        declined += k < 0
    assert declined <= 2


def test_nearly_special_arm_is_declined_and_searched():
    """A Puma 560 with axes tilted by 0.01 rad: the eliminant degenerates, the search gives 8."""
    rng = np.random.default_rng(1)
    robot = _perturbed(models.puma560().with_limits(np.tile([-np.inf, np.inf], (6, 1))), rng)
    q = np.array([0.3, 0.3, 0.2, 0.6, -1.5, -2.4])
    T = robot.fk(q)
    k, _ = _solve(robot, T)
    assert k < 0
    s = general_structure(robot)
    out = np.zeros((16, 6))
    # general_candidates is the elimination, declined above, then this search (the kernel is
    # inlined into the solver and never compiled on its own there)
    k = search_candidates(T, s.W, s.P, s.M, s.aux, int(s.order[0]), bool(s.order[1] == 1), 24,
                          robot.chain.F, robot.chain.meta, 1e-12, 1e-12, out)
    assert k == 8
    assert _wrapped(out[:k], q).min() < 1e-8
    assert len(ik_all(robot, T, near_tol=0.0)) == 8


def test_sixteen_real_solution_arm():
    """An arm and pose with 16 real solutions (the most a 6R has): all 16, Newton agrees.

    The DH table (``chapter.sections.inverse.ARM16``) was found by a random walk from the
    14-solution arm of test_analytic_general; 16 is confirmed independently by Newton's
    method from 300 random starts and by the 2-D search. The published 16-solution arm
    (Manocha & Canny 1994, after Manseur & Doty 1989), with its published solutions, is
    tests/ik/test_published_6r.py.
    """
    from serialkin.chapter.sections.inverse import ARM16, Q16  # the report shows it too

    robot = Robot.from_dh([DHLink(a=a, alpha=al, d=d) for a, al, d in zip(*ARM16)])
    T = robot.fk(np.array(Q16))
    k, rows = _solve(robot, T)
    assert k == 16
    assert np.abs(robot.fk(rows) - T).max() < 1e-10
    assert np.all(_wrapped(rows[:, None], rows[None]) + 10 * np.eye(16) > 1e-6)  # distinct
    newton = _newton_set(robot, T, 300, np.random.default_rng(0))
    assert len(newton) == 16
    for f in newton:
        assert _wrapped(rows, f).min() < 1e-6
    assert len(ik_all(robot, T)) == 16


@pytest.mark.parametrize("family", [
    {0: {"a": 0.0}},                    # axes 1 and 2 intersect: joint 5 or 4 is eliminated
    {0: {"a": 0.0}, 4: {"a": 0.0}},     # 1, 2 and 5, 6 intersect: neither end's θ1, θ2 split
    {1: {"alpha": 0.0}},                # axes 2 ∥ 3
    {3: {"alpha": 0.0}},                # axes 4 ∥ 5
    {2: {"a": 0.0}},                    # axes 3 and 4 intersect
])
def test_partly_special_arms_by_elimination(family):
    """Arms with one or two special pairs (no closed form): eliminated, same set as the search."""
    rng = np.random.default_rng(17)
    for _ in range(6):
        rows = [dict(a=rng.uniform(0.05, 0.5), alpha=rng.uniform(-3.0, 3.0),
                     d=rng.uniform(-0.3, 0.3)) for _ in range(6)]
        for j, change in family.items():
            rows[j].update(change)
        robot = Robot.from_dh([DHLink(**r) for r in rows])
        q = rng.uniform(-np.pi, np.pi, 6)
        T = robot.fk(q)
        k, found = _solve(robot, T)
        assert k >= 2
        _assert_complete(robot, T, q, found)


def test_tilted_arms_never_return_an_incomplete_even_set():
    """UR5 / Puma 560 tilted by 0.01 or 0.001 rad: the general solver's set equals the search's.

    (On tilted Puma 560s a later split can be well conditioned and still miss half the
    roots: the elimination must decline there rather than return an even, incomplete set.)
    """
    rng = np.random.default_rng(1)
    for make in (models.puma560, models.ur5):
        ideal = make()
        for angle in (0.01, 0.001):
            for _ in range(3):
                robot = _perturbed(ideal, rng, angle)
                T = robot.fk(rng.uniform(-2.5, 2.5, 6))
                k, rows_rr = _solve(robot, T)
                k2, rows_search = _solve(robot, T, search_candidates)
                if k >= 0 and k % 2 == 0:  # accepted by general_candidates: must be complete
                    assert k == k2
                    for r in rows_search:
                        assert _wrapped(rows_rr, r).min() < 1e-8


def test_nearly_coincident_axes_search_finer_when_nothing_is_found():
    """Axes 2, 3 0.5° apart and 1 mm away (elimination declined): every pose's q is found.

    The search's basins there can be narrower than a cell of the default grid, so a
    search that finds nothing is repeated on a grid twice as fine (general_candidates);
    before, one of these 24 poses returned no solution at all.
    """
    rng = np.random.default_rng(1)
    for _ in range(8):
        rows = [dict(a=rng.uniform(0.1, 1), alpha=rng.uniform(-3, 3), d=rng.uniform(-.5, .5))
                for _ in range(6)]
        rows[1].update(a=1e-3, alpha=math.radians(0.5))
        robot = Robot.from_dh([DHLink(**r) for r in rows])
        for q in rng.uniform(-np.pi, np.pi, (3, 6)):
            T = robot.fk(q)
            rows_found = ik_all(robot, T).q
            assert len(rows_found) % 2 == 0
            assert _wrapped(rows_found, q).min() < 1e-8
            assert np.abs(robot.fk(rows_found) - T).max() < 1e-10


def _qr_of(A: np.ndarray) -> tuple[float, np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    H = np.ascontiguousarray(A, dtype=float).copy()
    beta, rdiag = np.empty(A.shape[1]), np.empty(A.shape[1])
    perm = np.empty(A.shape[1], dtype=np.int64)
    ratio = _qr(H, beta, rdiag, perm)
    return ratio, H, beta, rdiag, perm


def test_pivoted_qr_gives_the_left_null_space_and_least_squares():
    """The pivoted QR of the elimination (it replaced an SVD) is right.

    The last 6 columns of its Q span the left null space of the (14, 8) matrix
    (orthonormal), the least-squares solution is numpy's, and the rank ratio is at least
    the singular values' (below 1e-14 for a rank-deficient matrix).
    """
    rng = np.random.default_rng(3)
    for _ in range(20):
        A = rng.normal(size=(14, 8)) * rng.uniform(0.1, 10.0, size=8)
        ratio, H, beta, rdiag, perm = _qr_of(A)
        sv = np.linalg.svd(A, compute_uv=False)
        assert sv[-1] / sv[0] <= ratio * (1 + 1e-12)
        N = np.zeros((6, 14))
        for r in range(6):
            N[r, 8 + r] = 1.0
            _apply_q(H, beta, N[r])
        assert np.allclose(N @ N.T, np.eye(6), atol=1e-13)
        assert np.abs(N @ A).max() < 1e-12 * np.abs(A).max()
        b = rng.normal(size=14)
        y = b.copy()
        _apply_qt(H, beta, y)
        z = np.empty(8)
        m = np.empty(8)
        for i in range(7, -1, -1):
            z[i] = (y[i] - H[i, i + 1:8] @ z[i + 1:]) / rdiag[i]
            m[perm[i]] = z[i]
        assert np.allclose(m, np.linalg.lstsq(A, b, rcond=None)[0], atol=1e-11)
    A = rng.normal(size=(14, 8))
    A[:, 5] = A[:, 1] - 2.0 * A[:, 3]  # rank 7
    assert _qr_of(A)[0] < 1e-14


def test_grid_values_are_the_derivatives_at_the_grid():
    """The scan's table products equal the derivatives evaluated one by one."""
    rng = np.random.default_rng(5)
    a, b = rng.normal(size=DEGREE + 1), rng.normal(size=DEGREE + 1)
    for order in (0, 2):
        vals = _grid_values(a, b, order)
        for m in range(N_GRID + 1):
            t = -math.pi + 2.0 * math.pi / N_GRID * m
            for j in range(3):
                size = sum(k ** (order + j) * (abs(a[k]) + abs(b[k])) for k in range(DEGREE + 1))
                assert abs(vals[j, m] - _trig(a, b, t, order + j)) <= 1e-13 * size

