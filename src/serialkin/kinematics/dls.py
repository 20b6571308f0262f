"""The damped least-squares step: one compiled implementation (numba, ``cache=True``).

Kernel contract: trusts its input; validation happens at the public boundary (the Python
functions that call these kernels). Arrays are float64, C-contiguous, of the documented
shapes, buffers at least as large as stated.

The damped least-squares (DLS) step of eq 46, as corrected by the ERRATA, for a task
Jacobian ``J`` (m, n) and a task error ``e`` (m,)::

    (J Jᵀ + λ² I) y = e,        Δq = Jᵀ y          (Δq = Jᵀ (J Jᵀ + λ² I)⁻¹ e)

It minimises ``‖J Δq − e‖² + λ² ‖Δq‖²``; ``λ`` [task units per joint unit] trades
accuracy for a bounded step near singularities. ``J Jᵀ + λ² I`` is symmetric positive
definite for λ > 0 and is solved by a Cholesky factorisation (:func:`spd_solve_into`,
also the solver of the n×n normal equations ``(Jᵀ W J + D) Δq = Jᵀ W e``).

Variants (the caller prepares the rows):

* **weighted rows**: weights ``w_i`` on the task rows, ``min ‖diag(√w)(J Δq − e)‖² +
  λ²‖Δq‖²``, is the plain step on ``J_w = diag(√w) J`` and ``e_w = √w ⊙ e``;
  :func:`weigh_rows_into` builds them, selecting task rows of a (6, n) Jacobian.
* **λ = 0 at a singularity**: ``floor > 0`` retries once with ``λ² + floor·(1 + max_i
  (J Jᵀ)_ii)`` when ``J Jᵀ + λ² I`` is not positive definite.
* **several right-hand sides**: :func:`dls_inverse_into` returns the matrix
  ``J^# = Jᵀ (J Jᵀ + λ² I)⁻¹`` (n, m); :func:`dls_step_batch` steps N problems at once.
"""

from __future__ import annotations

import math

import numpy as np

from .._jit import njit

__all__ = [
    "chol_factor_into",
    "chol_solve_into",
    "dls_factor_into",
    "dls_inverse_into",
    "dls_step_batch",
    "dls_step_into",
    "gram_into",
    "manipulability_batch",
    "manipulability_of",
    "spd_solve_into",
    "weigh_rows_into",
]


@njit(cache=True)
def chol_factor_into(A, m):
    """Cholesky factor ``A = L Lᵀ`` of the leading m×m block of A, in place.

    The one storage of serialkin's Cholesky factors: the lower triangle of L with the
    reciprocals ``1/L_jj`` on the diagonal (:func:`chol_solve_into`,
    :func:`lower_solve_into` and :func:`lower_t_solve_into` read it; so does a solve
    again with the factor :func:`spd_solve_into` leaves in its ``A``). The substitutions
    then multiply where a plain solve divides, and the only divisions left, one per
    column, are off the dependency chain of the rows below (about 10-20 % faster for the
    6×6 and 7×7 systems of IK, measured on a loaded machine). The factorisation is
    latency-bound (one pivot waits for the previous one), so each pivot ``L_jj² = s`` is
    found from the previous one through a division only (``s' = u − t²/s``, with
    ``t = L_{j+1,j}·L_jj``) and ``1/L_jj = √s · (1/s)`` lets the square root and the
    division overlap: 126 → 98 ns for a 7×7 solve.

    Args:
        A: (≥m, ≥m) symmetric matrix (only the lower triangle is read; overwritten by L).
        m: size of the block.

    Returns:
        True, or False when the block is not positive definite (A partly overwritten).
    """
    s = A[0, 0] if m > 0 else 1.0  # the pivot L_jj², j = 0
    for j in range(m):
        if not s > 0.0:
            return False
        inv = 1.0 / s
        r = math.sqrt(s) * inv  # 1/L_jj: the square root and the division run side by side
        A[j, j] = r
        if j + 1 < m:
            # the next pivot from t = L_{j+1,j}·L_jj as s' = u − t²/s: the chain from one
            # pivot to the next is a division, not a square root and then a division
            i = j + 1
            t = A[i, j]
            u = A[i, i]
            for k in range(j):
                t -= A[i, k] * A[j, k]
                u -= A[i, k] * A[i, k]
            A[i, j] = t * r
            s = u - t * t * inv
        for i in range(j + 2, m):
            t = A[i, j]
            for k in range(j):
                t -= A[i, k] * A[j, k]
            A[i, j] = t * r
    return True


@njit(cache=True)
def lower_solve_into(L, b, x, m):
    """Forward substitution: solve ``L x = b`` (m,) with a factor of :func:`chol_factor_into`.

    L lower triangular with the reciprocals of its diagonal stored; x may alias b.
    """
    for i in range(m):
        t = b[i]
        for k in range(i):
            t -= L[i, k] * x[k]
        x[i] = t * L[i, i]


@njit(cache=True)
def lower_t_solve_into(L, b, x, m):
    """Back substitution: solve ``Lᵀ x = b`` (m,) with a factor of :func:`chol_factor_into`.

    L lower triangular with the reciprocals of its diagonal stored; x may alias b.
    """
    for i in range(m - 1, -1, -1):
        t = b[i]
        for k in range(i + 1, m):
            t -= L[k, i] * x[k]
        x[i] = t * L[i, i]


@njit(cache=True)
def chol_solve_into(L, b, x, m):
    """Solve ``L Lᵀ x = b`` (m,) with the factor L of :func:`chol_factor_into`; x may alias b."""
    lower_solve_into(L, b, x, m)
    lower_t_solve_into(L, x, x, m)


@njit(cache=True)
def spd_solve_into(A, b, x, m):
    """Solve ``A x = b`` for the leading m×m block of the SPD matrix A (destroyed).

    :func:`chol_factor_into` (``A = L Lᵀ``, L left in A), then ``L y = b`` and
    ``Lᵀ x = y``; the result agrees with numpy's solve to rounding.

    Args:
        A: (≥m, ≥m) symmetric positive definite matrix (only the lower triangle is read);
            overwritten by its factor.
        b: (≥m,) right-hand side.
        x: (≥m,) output (may alias b).
        m: size of the system.

    Returns:
        True, or False when A is not positive definite (x not written).
    """
    if not chol_factor_into(A, m):
        return False
    chol_solve_into(A, b, x, m)
    return True


@njit(cache=True)
def gram_into(J, M, columns=False):
    """``M = J Jᵀ`` (m, m) of J (m, n); returns ``max_i M_ii`` (0 for m = 0).

    With ``columns``, ``Jᵀ J`` (n, n) into ``M[:n, :n]`` (:func:`dls_factor_into`), by the
    same sums as ``J Jᵀ`` of the transposed view ``J.T`` (which would compile this
    kernel a second time, for a Fortran-ordered array).
    """
    m, n = J.shape
    d = 0.0
    if columns:
        for i in range(n):
            for k in range(i, n):
                s = 0.0
                for j in range(m):
                    s += J[j, i] * J[j, k]
                M[i, k] = s
                M[k, i] = s
            d = max(d, M[i, i])
        return d
    for i in range(m):
        for k in range(i, m):
            s = 0.0
            for j in range(n):
                s += J[i, j] * J[k, j]
            M[i, k] = s
            M[k, i] = s
        d = max(d, M[i, i])
    return d


@njit(cache=True)
def dls_factor_into(J, lam2, floor, M, columns=False):
    """Cholesky factor of ``J Jᵀ + λ² I`` (m, m) into M; J (m, n), ``lam2`` = λ².

    With ``columns``, of ``Jᵀ J + λ² I`` (n, n) into ``M[:n, :n]`` instead. When the
    matrix is not positive definite (λ = 0 at a singularity) and ``floor > 0``, retries
    once with ``λ² + floor·(1 + max_i G_ii)``, G the Gram matrix.

    Returns:
        True, or False when no factor was found.
    """
    k = J.shape[1] if columns else J.shape[0]
    l2 = lam2
    for _ in range(2):
        d = gram_into(J, M, columns)
        for i in range(k):
            M[i, i] += l2
        if chol_factor_into(M, k):
            return True
        if not floor > 0.0:
            return False
        l2 = lam2 + floor * (1.0 + d)
    return False


@njit(cache=True)
def dls_step_into(J, e, lam2, floor, M, y, dq):
    """DLS step ``Δq = Jᵀ (J Jᵀ + λ² I)⁻¹ e`` (eq 46, corrected) into ``dq``.

    With more task rows than joints (m > n) the same step is solved as
    ``(Jᵀ J + λ² I) Δq = Jᵀ e`` (the two are equal: ``Jᵀ(JJᵀ + λ²I) = (JᵀJ + λ²I)Jᵀ``):
    the n×n system is smaller, and it is as well conditioned as J itself, where
    ``J Jᵀ`` has rank at most n < m and its m×m system is as ill-conditioned as
    ``1/λ²`` (with λ = 0.002 and a random 4×2 J the m×m route kept about nine
    correct digits, the n×n one all but one, against 50-digit arithmetic).

    Args:
        J: (m, n) task Jacobian (weighted rows: pass ``diag(√w) J``).
        e: (m,) task error (weighted rows: ``√w ⊙ e``) [task units].
        lam2: λ² ≥ 0 [task units² per joint unit²].
        floor: relative damping floor for a retry when the system is singular
            (0: no retry); see :func:`dls_factor_into`.
        M: (m, m) buffer (overwritten by a Cholesky factor).
        y: (m,) buffer (overwritten).
        dq: (n,) output [joint units].

    Returns:
        True, or False when the system is singular (dq not written).
    """
    m, n = J.shape
    if m > n:
        if not dls_factor_into(J, lam2, floor, M, True):
            return False
        for j in range(n):
            s = 0.0
            for i in range(m):
                s += J[i, j] * e[i]
            y[j] = s
        chol_solve_into(M, y, dq, n)
        return True
    if not dls_factor_into(J, lam2, floor, M, False):
        return False
    chol_solve_into(M, e, y, m)
    for j in range(n):
        s = 0.0
        for i in range(m):
            s += J[i, j] * y[i]
        dq[j] = s
    return True


@njit(cache=True)
def dls_inverse_into(J, lam2, floor, M, y, out):
    """DLS inverse ``J^# = Jᵀ (J Jᵀ + λ² I)⁻¹`` (n, m) of J (m, n) into ``out``.

    For a tall J (m > n) computed as ``(JᵀJ + λ² I)⁻¹ Jᵀ``, the same matrix from the
    better conditioned n×n system (see :func:`dls_step_into`), so that ``J^# e`` is
    the step for every shape. Buffers: M (m, m), y (m,). Returns False when the system
    is singular.
    """
    m, n = J.shape
    if m > n:
        if not dls_factor_into(J, lam2, floor, M, True):
            return False
        for c in range(m):
            for j in range(n):
                y[j] = J[c, j]
            chol_solve_into(M, y, y, n)
            for j in range(n):
                out[j, c] = y[j]
        return True
    if not dls_factor_into(J, lam2, floor, M, False):
        return False
    for c in range(m):
        for i in range(m):
            y[i] = 0.0
        y[c] = 1.0
        chol_solve_into(M, y, y, m)
        for j in range(n):
            s = 0.0
            for i in range(m):
                s += J[i, j] * y[i]
            out[j, c] = s
    return True


@njit(cache=True)
def dls_step_batch(J, e, lam2, floor, dq):
    """DLS steps of N problems: ``dq[k] = J[k]ᵀ (J[k] J[k]ᵀ + λ² I)⁻¹ e[k]``.

    Args:
        J: (N, m, n) task Jacobians.
        e: (N, m) task errors.
        lam2: λ².
        floor: see :func:`dls_factor_into`.
        dq: (N, n) output; a problem with a singular system gets NaN.

    Returns:
        number of singular problems.
    """
    N, m, n = J.shape
    M = np.empty((m, m))
    y = np.empty(m)
    bad = 0
    for k in range(N):
        if not dls_step_into(J[k], e[k], lam2, floor, M, y, dq[k]):
            dq[k, :] = np.nan
            bad += 1
    return bad


@njit(cache=True)
def weigh_rows_into(J, e, rows, sw, Jw, ew):
    """Select and weigh task rows: ``Jw[i] = sw[i]·J[rows[i]]``, ``ew[i] = sw[i]·e[rows[i]]``.

    Args:
        J: (6, n) Jacobian (or any (r, n)).
        e: (6,) error.
        rows: (m,) int row indices.
        sw: (m,) square roots of the row weights (ones for unweighted rows).
        Jw: (m, n) output.
        ew: (m,) output.

    Returns:
        ``‖ew‖²``.
    """
    n = J.shape[1]
    s2 = 0.0
    for i in range(rows.shape[0]):
        r = rows[i]
        ew[i] = sw[i] * e[r]
        s2 += ew[i] * ew[i]
        for j in range(n):
            Jw[i, j] = sw[i] * J[r, j]
    return s2


@njit(cache=True)
def manipulability_of(J):
    """Yoshikawa manipulability ``w = sqrt(det(J Jᵀ))`` (eq 43) of a task Jacobian J (m, n).

    Computed without forming ``J Jᵀ``: with the Householder QR factorisation
    ``Jᵀ = Q R`` (R upper triangular, m × m), ``J Jᵀ = Rᵀ R`` and ``w = Π |R_kk|`` (the
    product of J's singular values), so w keeps full relative accuracy near
    singularities and is 0 when a column of the reduction vanishes; 0 when m > n (J Jᵀ has
    rank ≤ n < m). The one implementation of eq 43: :meth:`serialkin.Robot.manipulability`,
    the manipulability objective, the multi-task resolver and the CLI call it.
    """
    m, n = J.shape
    if m > n:
        return 0.0
    A = np.empty((n, m))
    for i in range(m):
        for j in range(n):
            A[j, i] = J[i, j]
    w = 1.0
    for k in range(m):
        s = 0.0
        for j in range(k, n):
            s += A[j, k] * A[j, k]
        nrm = math.sqrt(s)
        if nrm == 0.0:
            return 0.0
        w *= nrm  # |R_kk|
        alpha = -nrm if A[k, k] >= 0.0 else nrm
        # Householder vector v = a - alpha e_k (in place), vᵀv = 2 nrm (nrm + |a_k|)
        A[k, k] -= alpha
        vv = 2.0 * nrm * (nrm + abs(A[k, k] + alpha))
        for c in range(k + 1, m):
            d = 0.0
            for j in range(k, n):
                d += A[j, k] * A[j, c]
            f = 2.0 * d / vv
            for j in range(k, n):
                A[j, c] -= f * A[j, k]
    return w


@njit(cache=True)
def manipulability_batch(J, out):
    """:func:`manipulability_of` of each J[k] (N, m, n) into ``out`` (N,)."""
    for k in range(J.shape[0]):
        out[k] = manipulability_of(J[k])
