"""Closed-form IK of 6R arms with three parallel axes (Universal Robots class): up to 8.

Axes 2, 3, 4 are parallel (direction ``w``), axis 1 is not, and axes 5 and 6 meet at a
point ``p56``. With ``T = exp(ξ1 q1)···exp(ξ6 q6)·M`` and ``R_g = R_T R_Mᵀ``:

1. ``p56`` is fixed by joints 5 and 6, so ``p5 = T·M⁻¹·p56 = e1 e2 e3 e4 · p56``; joints
   2-4 keep the component along ``w``: ``(R1 w)·(p5 − r1) = w·(p56 − r1)`` gives q1
   (two solutions: shoulder left / right).
2. The direction of axis 6 at the target is ``R_g w6``; joints 2-4 keep ``w``, so
   ``w·(R5 w6) = (R1 w)·(R_g w6)`` gives q5 (two solutions: wrist up / down).
3. ``X = R1ᵀ R_g = R234 R5 R6`` and ``R234ᵀ w = w`` give ``R6 (Xᵀ w) = R5ᵀ w``: q6 by
   subproblem 1 (at the wrist singularity, axis 6 ∥ w, q6 is free: 0 is returned).
4. ``G = e1⁻¹·T·M⁻¹·e6⁻¹·e5⁻¹ = e2 e3 e4``: its rotation about ``w`` is q2 + q3 + q4,
   and it carries a point ``x4`` of axis 4 to ``G·x4 = e2 e3·x4``: the two-link formula
   of eqs 23-27 (corrected) gives q2, q3 (elbow up / down) and q4 follows.

Any link lengths and offsets, either DH convention, base and tool transforms.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from serialkin.ik.analytic.subproblems import (
    cross3,
    dot3,
    finalize,
    inv_rigid,
    mm,
    mtv,
    mv,
    planar2r,
    rotation,
    sp1_dir,
    sp4,
    target_point,
    transform_point,
)

#: Most candidate solutions.
MAX_SOLUTIONS = 8


@njit(cache=True)
def ur_candidates(T, W, P, M, aux, out):
    """Candidates for a ``ur``-class arm; aux = (p56, w, e ⟂ w). Returns the count."""
    p56 = aux[0].copy()
    w = aux[1].copy()
    e = aux[2].copy()
    w1 = W[0].copy()
    r1 = P[0].copy()
    w5 = W[4].copy()
    r5 = P[4].copy()
    w6 = W[5].copy()
    r6 = P[5].copy()
    p5, Rg = target_point(T, M, p56)
    w6t = mv(Rg, w6)
    TMinv = mm(T, inv_rigid(M))
    x4 = P[3].copy()
    s2 = dot3(W[1], w)
    s3 = dot3(W[2], w)
    s4 = dot3(W[3], w)
    q1s = np.empty(2)
    q5s = np.empty(2)
    sol = np.empty((2, 2))
    n1 = sp4(w1, w, p5 - r1, dot3(w, p56 - r1), q1s)
    k = 0
    for i in range(n1):
        q1 = q1s[i]
        R1 = rotation(w1, q1)
        X = mm(R1.T, Rg)
        n5 = sp4(w5, w6, w, dot3(mv(R1, w), w6t), q5s)
        for j in range(n5):
            q5 = q5s[j]
            R5 = rotation(w5, q5)
            q6 = sp1_dir(w6, mtv(X, w), mtv(R5, w))
            # G = e1⁻¹·T·M⁻¹·e6⁻¹·e5⁻¹ applied to e and x4 by rotations (no 4 × 4 products)
            # (Rot(w, −θ) = Rot(w, θ)ᵀ: the rotations already built are reused)
            R6 = rotation(w6, q6)
            ve = mtv(R1, mv(TMinv, mtv(R6, mtv(R5, e))))
            s = math.atan2(dot3(w, cross3(e, ve)), dot3(e, ve))
            y = mtv(R1, transform_point(TMinv, mtv(R6, mtv(R5, x4 - r5) + r5 - r6) + r6)
                    - r1) + r1
            m = planar2r(w, e, P[1].copy(), P[2].copy(), x4, y, sol)
            for r in range(m):
                out[k, 0] = q1
                out[k, 1] = s2 * sol[r, 0]
                out[k, 2] = s3 * sol[r, 1]
                out[k, 3] = s4 * (s - sol[r, 0] - sol[r, 1])
                out[k, 4] = q5
                out[k, 5] = q6
                k += 1
    return k


@njit(cache=True)
def solve_ur(T, W, P, M, aux, revolute, qlim, mid, F, meta, tol_p, tol_r, out):
    """Every solution of a UR-class arm inside the limits, sorted, into ``out`` (8, 6).

    Arguments as in :func:`~serialkin.ik.analytic.spherical_wrist.solve_spherical_wrist`.
    Returns the number of solutions (0-8).
    """
    cand = np.zeros((MAX_SOLUTIONS, 6))
    k = ur_candidates(T, W, P, M, aux, cand)
    return finalize(cand, k, revolute, qlim, mid, F, meta, T, True, tol_p, tol_r, out)
