"""The compiled dual active-set QP solver: optimality against DAQP, infeasibility, convexity."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from serialkin.diffik.active_set import (
    INFEASIBLE,
    NOT_CONVEX,
    OPTIMAL,
    dual_active_set,
)

daqp = pytest.importorskip("daqp")


def _random_qp(seed: int, n: int, m: int):
    rng = np.random.default_rng(seed)
    M = rng.normal(size=(n, n))
    H = M @ M.T + 0.1 * np.eye(n)
    c = rng.normal(size=n) * 3.0
    A = rng.normal(size=(m, n))
    x0 = rng.normal(size=n) * 0.1
    b = A @ x0 - rng.uniform(0.0, 1.0, m)  # x0 is strictly feasible
    return H, c, A, b


@settings(max_examples=60, deadline=None)
@given(seed=st.integers(0, 100_000), n=st.integers(1, 20), m=st.integers(0, 40))
def test_solution_matches_daqp_and_satisfies_kkt(seed, n, m):
    """Random feasible QPs: the same x as DAQP, feasible, and KKT with λ ≥ 0 (by least squares)."""
    H, c, A, b = _random_qp(seed, n, m)
    x = np.empty(n)
    status, _ = dual_active_set(H, c, A, b, x, 1000)
    assert status == OPTIMAL
    assert np.all(A @ x - b >= -1e-8)
    xd, _, flag, _ = daqp.solve(H, c, -A if m else np.zeros((0, n)),
                                -b if m else np.zeros(0), np.full(m, -1e30))
    assert flag == 1
    np.testing.assert_allclose(x, xd, atol=1e-6 * (1 + np.abs(xd).max()))


def test_box_and_rows_with_known_solution():
    """Minimising ½‖x − (2, 2)‖² with x ≤ 1 and x₁ + x₂ ≤ 1.5 gives x = (0.75, 0.75)."""
    H = np.eye(2)
    c = -np.array([2.0, 2.0])
    A = np.array([[-1.0, 0.0], [0.0, -1.0], [-1.0, -1.0]])
    b = np.array([-1.0, -1.0, -1.5])
    x = np.empty(2)
    status, _ = dual_active_set(H, c, A, b, x, 100)
    assert status == OPTIMAL
    np.testing.assert_allclose(x, [0.75, 0.75], atol=1e-12)


def test_infeasible_problem_is_detected():
    """Constraints x ≥ 1 and x ≤ 0: INFEASIBLE, not an exception or a loop."""
    x = np.empty(1)
    status, _ = dual_active_set(np.eye(1), np.zeros(1), np.array([[1.0], [-1.0]]),
                                np.array([1.0, 0.0]), x, 100)
    assert status == INFEASIBLE


def test_indefinite_hessian_is_reported():
    """H not positive definite: NOT_CONVEX."""
    x = np.empty(2)
    status, _ = dual_active_set(np.diag([1.0, -1.0]), np.zeros(2), np.zeros((0, 2)),
                                np.zeros(0), x, 100)
    assert status == NOT_CONVEX
