"""The shared damped least-squares kernel against the closed-form NumPy expressions."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import example, given, settings
from hypothesis import strategies as st

from serialkin.kinematics import dls


def _reference(J, e, lam):
    """Jᵀ(JJᵀ+λ²I)⁻¹e as the least-squares solution of [J; λI] Δq ≈ [e; 0] (QR, stable).

    The same vector as the closed form, computed without forming JJᵀ: for m > n that
    matrix has rank n and its m×m solve loses about 2·log10(1/λ) digits, enough for
    the reference itself to miss a 1e-9 tolerance at λ = 1e-3.
    """
    n = J.shape[1]
    return np.linalg.lstsq(np.vstack([J, lam * np.eye(n)]), np.concatenate([e, np.zeros(n)]),
                           rcond=None)[0]


@settings(max_examples=40, deadline=None)
@given(st.integers(1, 6), st.integers(1, 8), st.floats(1e-3, 1.0), st.integers(0, 2**32 - 1))
@example(m=4, n=2, lam=0.001953125, seed=0)  # tall J, small λ: failed with the m×m route
def test_step_matches_closed_form(m, n, lam, seed):
    """Δq = Jᵀ(JJᵀ+λ²I)⁻¹e and it satisfies the normal equations (JᵀJ+λ²I)Δq = Jᵀe."""
    rng = np.random.default_rng(seed)
    J = rng.standard_normal((m, n))
    e = rng.standard_normal(m)
    dq = np.empty(n)
    assert dls.dls_step_into(J, e, lam * lam, 0.0, np.empty((m, m)), np.empty(m), dq)
    np.testing.assert_allclose(dq, _reference(J, e, lam), rtol=1e-9, atol=1e-12)
    np.testing.assert_allclose((J.T @ J + lam * lam * np.eye(n)) @ dq, J.T @ e,
                               rtol=1e-8, atol=1e-10)


def test_singular_without_floor_fails_and_floor_recovers():
    """λ = 0 on a rank-deficient J: False without a floor, a finite least-squares step with one."""
    J = np.array([[1.0, 0.0], [1.0, 0.0]])
    e = np.array([1.0, 1.0])
    dq = np.full(2, 7.0)
    assert not dls.dls_step_into(J, e, 0.0, 0.0, np.empty((2, 2)), np.empty(2), dq)
    assert dls.dls_step_into(J, e, 0.0, 1e-12, np.empty((2, 2)), np.empty(2), dq)
    np.testing.assert_allclose(dq, [1.0, 0.0], atol=1e-6)


def test_inverse_and_batch_agree_with_the_step():
    """J^# e equals the step, and the batch equals the single steps."""
    rng = np.random.default_rng(3)
    J = rng.standard_normal((5, 3, 7))
    e = rng.standard_normal((5, 3))
    out = np.empty((5, 7))
    assert dls.dls_step_batch(J, e, 0.04, 0.0, out) == 0
    inv = np.empty((7, 3))
    for k in range(5):
        assert dls.dls_inverse_into(J[k], 0.04, 0.0, np.empty((3, 3)), np.empty(3), inv)
        np.testing.assert_allclose(inv @ e[k], out[k], rtol=1e-12, atol=1e-14)
        np.testing.assert_allclose(out[k], _reference(J[k], e[k], 0.2), rtol=1e-9, atol=1e-12)


def test_spd_solve_and_weighted_rows():
    """Cholesky solve of an SPD system; weighted rows scale the selected rows by √w."""
    rng = np.random.default_rng(4)
    B = rng.standard_normal((4, 4))
    A = B @ B.T + 4 * np.eye(4)
    b = rng.standard_normal(4)
    x = np.empty(4)
    assert dls.spd_solve_into(A.copy(), b, x, 4)
    np.testing.assert_allclose(A @ x, b, atol=1e-12)
    assert not dls.spd_solve_into(-A.copy(), b, x, 4)
    J = rng.standard_normal((6, 3))
    e = rng.standard_normal(6)
    rows = np.array([0, 1, 5])
    sw = np.array([1.0, 2.0, 0.5])
    Jw, ew = np.empty((3, 3)), np.empty(3)
    s2 = dls.weigh_rows_into(J, e, rows, sw, Jw, ew)
    np.testing.assert_allclose(Jw, sw[:, None] * J[rows])
    np.testing.assert_allclose(ew, sw * e[rows])
    assert abs(s2 - float(ew @ ew)) < 1e-12


@settings(max_examples=40, deadline=None)
@given(st.integers(1, 6), st.integers(1, 8), st.integers(0, 2**32 - 1))
def test_manipulability_is_the_product_of_singular_values(m, n, seed):
    """Manipulability = Π σ_i = sqrt(det(J Jᵀ)) for m ≤ n; 0 for m > n and a repeated row."""
    J = np.random.default_rng(seed).standard_normal((m, n))
    want = float(np.prod(np.linalg.svd(J, compute_uv=False))) if m <= n else 0.0
    assert abs(dls.manipulability_of(J) - want) <= 1e-12 * max(1.0, want)
    if m >= 2 and m <= n:
        J[1] = J[0]
        assert dls.manipulability_of(J) <= 1e-12 * np.linalg.norm(J) ** m


@pytest.mark.parametrize("m", [1, 2, 3, 6, 7, 9])
def test_spd_solve_matches_numpy(m):
    """spd_solve_into solves random SPD systems as numpy does, also with x aliasing b."""
    rng = np.random.default_rng(m)
    for _ in range(5):
        G = rng.normal(size=(m + 2, m))
        A = G.T @ G + 1e-3 * np.eye(m)
        b = rng.normal(size=m)
        ref = np.linalg.solve(A, b)
        x = np.empty(m)
        assert dls.spd_solve_into(A.copy(), b, x, m)
        np.testing.assert_allclose(x, ref, rtol=1e-10, atol=1e-12)
        y = b.copy()
        assert dls.spd_solve_into(A.copy(), y, y, m)
        np.testing.assert_allclose(y, ref, rtol=1e-10, atol=1e-12)


@settings(max_examples=60, deadline=None)
@given(st.integers(2, 6), st.integers(1, 5), st.floats(1e-4, 1e-2), st.integers(0, 2**32 - 1))
def test_tall_jacobian_step_is_accurate_for_small_damping(m, n, lam, seed):
    """A tall J (m > n) with small λ: the step equals the stacked least squares to 1e-12."""
    if n >= m:
        n = m - 1
    rng = np.random.default_rng(seed)
    J = rng.standard_normal((m, n))
    e = rng.standard_normal(m)
    dq = np.empty(n)
    assert dls.dls_step_into(J, e, lam * lam, 0.0, np.empty((m, m)), np.empty(m), dq)
    np.testing.assert_allclose(dq, _reference(J, e, lam), rtol=1e-12, atol=1e-14)


@pytest.mark.parametrize("shape", [(3, 7), (6, 6), (6, 3), (5, 1)])
def test_inverse_times_error_is_the_step_for_every_shape(shape):
    """J^# e equals dls_step_into's Δq for wide, square and tall J (tall: the n×n form)."""
    m, n = shape
    rng = np.random.default_rng(11)
    J = rng.standard_normal((m, n))
    e = rng.standard_normal(m)
    inv, dq = np.empty((n, m)), np.empty(n)
    for lam in (0.5, 1e-3):
        assert dls.dls_inverse_into(J, lam * lam, 0.0, np.empty((m, m)), np.empty(m), inv)
        assert dls.dls_step_into(J, e, lam * lam, 0.0, np.empty((m, m)), np.empty(m), dq)
        np.testing.assert_allclose(inv @ e, dq, rtol=1e-10, atol=1e-13)
        np.testing.assert_allclose(dq, _reference(J, e, lam), rtol=1e-9, atol=1e-12)
