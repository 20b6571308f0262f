"""A compiled dual active-set QP solver (Goldfarb & Idnani 1983) for small dense problems.

Solves

    minimise ½ xᵀ H x + cᵀ x   subject to   A x ≥ b

with H (n, n) symmetric positive definite and A (m, n). It is the compiled alternative to
DAQP measured in ``benchmarks/bench_diffik.py``: being a numba function, it can run inside
a compiled loop (no Python between iterations).

The dual method starts from the unconstrained minimum ``x = −H⁻¹c`` and adds the most
violated constraint at a time; each addition takes a step along the primal direction
``z = (H⁻¹ − J₁J₁ᵀ) n⁺`` (which keeps the active constraints active) and the dual
direction ``r = R⁻¹ J₁ᵀ n⁺``, dropping an active constraint whose multiplier would turn
negative. ``J₁ = L⁻ᵀ Q₁`` and ``R`` come from the QR factorisation of ``L⁻¹ N`` (L the
Cholesky factor of H, N the active normals), recomputed from scratch after every change
of the active set (O(n²q) for q active constraints — cheap for the n ≲ 30 of a robot,
and free of the update bookkeeping of the original paper). A new constraint dependent on
the active ones (z = 0) with no constraint to drop proves the problem infeasible.

Kernel contract: trusts its input; validation happens at the public boundary
(:class:`serialkin.diffik.qp.DiffIK`).
"""

from __future__ import annotations

import math

import numpy as np

from serialkin.kinematics.dls import chol_factor_into, lower_solve_into, lower_t_solve_into

from .._jit import njit

__all__ = ["INFEASIBLE", "ITERATION_LIMIT", "NOT_CONVEX", "OPTIMAL", "dual_active_set",
           "solve_bounded"]

#: Exit codes (DAQP's numbering, so that one table of reasons serves both).
OPTIMAL = 1
INFEASIBLE = -1
ITERATION_LIMIT = -4
NOT_CONVEX = -5


@njit(cache=True)
def _factor_active(L, A, active, q, J1, R):
    """J₁ (n, q) = L⁻ᵀ Q₁ and R (q, q) from the QR of L⁻¹ N, N = A[active[:q]]ᵀ."""
    n = L.shape[0]
    M = np.empty((n, q))
    col = np.empty(n)
    tmp = np.empty(n)
    for j in range(q):
        for i in range(n):
            tmp[i] = A[active[j], i]
        lower_solve_into(L, tmp, col, n)
        for i in range(n):
            M[i, j] = col[i]
    Q1, R1 = np.linalg.qr(M)
    for j in range(q):
        for i in range(n):
            tmp[i] = Q1[i, j]
        lower_t_solve_into(L, tmp, col, n)
        for i in range(n):
            J1[i, j] = col[i]
        for i in range(q):
            R[i, j] = R1[i, j]


@njit(cache=True)
def dual_active_set(H, c, A, b, x, max_iter):
    """Solve ``min ½xᵀHx + cᵀx  s.t.  A x ≥ b``; writes x (n,), returns (status, iterations).

    Args:
        H: (n, n) symmetric positive definite.
        c: (n,).
        A: (m, n) constraint rows.
        b: (m,) lower bounds of ``A x``.
        x: out (n,) the solution (the last iterate when not optimal).
        max_iter: budget of active-set changes.

    Returns:
        (status, iterations): status OPTIMAL (1), INFEASIBLE (−1), ITERATION_LIMIT (−4) or
        NOT_CONVEX (−5, H not positive definite).
    """
    # One piece over 80 lines: the dual active-set iteration (Goldfarb-Idnani) updates one
    # factorisation and one active set in a single loop; split into compiled calls it would add
    # levels that each re-link and re-optimise their callees (docs/compile-time.md).
    n = H.shape[0]
    m = A.shape[0]
    L = np.zeros((n, n))
    for i in range(n):
        for j in range(i + 1):
            L[i, j] = H[i, j]
    if not chol_factor_into(L, n):  # H = L Lᵀ, lower triangle; the upper stays zero
        return NOT_CONVEX, 0
    y = np.empty(n)
    tmp = np.empty(n)
    for i in range(n):
        tmp[i] = -c[i]
    lower_solve_into(L, tmp, y, n)
    lower_t_solve_into(L, y, x, n)  # unconstrained minimum
    norms = np.empty(m)
    for i in range(m):
        s = 0.0
        for k in range(n):
            s += A[i, k] * A[i, k]
        norms[i] = math.sqrt(s) if s > 0.0 else 1.0
    cap = min(n, m)
    active = np.empty(max(cap, 1), dtype=np.int64)
    is_active = np.zeros(m, dtype=np.bool_)
    u = np.zeros(max(cap, 1))
    J1 = np.zeros((n, max(cap, 1)))
    R = np.zeros((max(cap, 1), max(cap, 1)))
    q = 0
    np_ = np.empty(n)
    hinv_n = np.empty(n)
    z = np.empty(n)
    d1 = np.empty(max(cap, 1))
    r = np.empty(max(cap, 1))
    it = 0
    tol = 1e-10
    while True:
        # step 1: the most violated constraint (scaled by its row norm)
        p = -1
        worst = -tol
        for i in range(m):
            if is_active[i]:
                continue
            s = -b[i]
            for k in range(n):
                s += A[i, k] * x[k]
            s /= norms[i]
            if s < worst:
                worst = s
                p = i
        if p < 0:
            return OPTIMAL, it
        u_plus = 0.0
        for k in range(n):
            np_[k] = A[p, k]
        lower_solve_into(L, np_, y, n)
        lower_t_solve_into(L, y, hinv_n, n)  # H⁻¹ n⁺
        while True:  # step 2: add p (possibly after dropping others)
            it += 1
            if it > max_iter:
                return ITERATION_LIMIT, it
            for j in range(q):
                s = 0.0
                for k in range(n):
                    s += J1[k, j] * np_[k]
                d1[j] = s
            for k in range(n):
                s = hinv_n[k]
                for j in range(q):
                    s -= J1[k, j] * d1[j]
                z[k] = s
            for j in range(q - 1, -1, -1):  # r = R⁻¹ d1
                s = d1[j]
                for k in range(j + 1, q):
                    s -= R[j, k] * r[k]
                r[j] = s / R[j, j]
            t1 = np.inf
            drop = -1
            for j in range(q):
                if r[j] > 1e-14 and u[j] / r[j] < t1:
                    t1 = u[j] / r[j]
                    drop = j
            zn = 0.0
            hn = 0.0
            for k in range(n):
                zn += z[k] * np_[k]
                hn += hinv_n[k] * np_[k]
            s_p = -b[p]
            for k in range(n):
                s_p += A[p, k] * x[k]
            t2 = np.inf
            if zn > 1e-12 * hn:
                t2 = -s_p / zn
            if t1 == np.inf and t2 == np.inf:
                return INFEASIBLE, it
            if t2 == np.inf or t1 < t2:
                t = t1
            else:
                t = t2
            if t2 != np.inf:
                for k in range(n):
                    x[k] += t * z[k]
            for j in range(q):
                u[j] -= t * r[j]
            u_plus += t
            if t == t2:  # full step: p joins the active set
                if q >= cap:  # cannot happen for independent normals; guard anyway
                    return INFEASIBLE, it
                active[q] = p
                u[q] = u_plus
                is_active[p] = True
                q += 1
                _factor_active(L, A, active, q, J1, R)
                break
            # partial step: drop the blocking constraint, then try p again
            is_active[active[drop]] = False
            for j in range(drop, q - 1):
                active[j] = active[j + 1]
                u[j] = u[j + 1]
            q -= 1
            if q > 0:
                _factor_active(L, A, active, q, J1, R)


@njit(cache=True)
def solve_bounded(H, c, G, h, lb, ub, x, max_iter):
    """Solve ``min ½xᵀHx + cᵀx  s.t.  lb ≤ x ≤ ub,  G x ≤ h`` with :func:`dual_active_set`.

    Bounds beyond ±1e19 count as absent. Returns (status, iterations); writes x (n,).
    """
    n = H.shape[0]
    count = G.shape[0]
    for j in range(n):
        if lb[j] > -1e19:
            count += 1
        if ub[j] < 1e19:
            count += 1
    A = np.zeros((count, n))
    b = np.empty(count)
    r = 0
    for j in range(n):
        if lb[j] > -1e19:
            A[r, j] = 1.0
            b[r] = lb[j]
            r += 1
        if ub[j] < 1e19:
            A[r, j] = -1.0
            b[r] = -ub[j]
            r += 1
    for i in range(G.shape[0]):
        for k in range(n):
            A[r, k] = -G[i, k]
        b[r] = -h[i]
        r += 1
    return dual_active_set(H, c, A, b, x, max_iter)
