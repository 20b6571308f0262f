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

from serialkin.ik.analytic.subproblems import (
    WRIST_SEED,
    add3,
    cross3t,
    dot3,
    finalize,
    mtv3,
    mv3,
    planar2r_frame,
    planar2r_solve,
    rot3,
    row3,
    sp1_dir_cs,
    sp4,
    sub3,
    target_rotation,
)

from ..._jit import njit

#: Most candidate solutions.
MAX_SOLUTIONS = 8


@njit(cache=True)
def ur_candidates(T, W, P, M, aux, slack, out):
    """Candidates for a ``ur``-class arm; aux = (p56, w, e ⟂ w). Returns the count.

    ``slack``: 0 for an exact solve; > 0 for the seeds of a nearly ideal arm: the
    shoulder (q1), the wrist (q5) and the elbow give two seeds on both sides of their
    tangencies, also just beyond the ideal arm's reach
    (:func:`~serialkin.ik.analytic.subproblems.acos_seed`), and near the wrist
    singularity (axis 6 turned by joint 5 within
    :data:`~serialkin.ik.analytic.subproblems.WRIST_SEED` rad of ``w``: the ideal arm
    has a continuum, q6 free and joints 2-4 following) the first q5 also gets the seeds
    q6 ± π/2, while ``out`` has room: more than :data:`MAX_SOLUTIONS` candidates say
    that a seed lay there.

    Vectors are tuples (no allocation per branch) and every rotation is applied by
    Rodrigues' formula from one sin/cos per joint value (``Rot(w, −θ) = Rot(w, θ)ᵀ``).
    """
    # One piece over 80 lines: the nested branches (q1, then q5, q6, then the elbow) share
    # the rotated vectors of the levels above; split into compiled calls it would pass
    # them as arguments and add levels that each re-link and re-optimise their callees
    # (docs/compile-time.md).
    p56 = row3(aux, 0)
    w = row3(aux, 1)
    e = row3(aux, 2)
    w1 = row3(W, 0)
    r1 = row3(P, 0)
    w5 = row3(W, 4)
    r5 = row3(P, 4)
    w6 = row3(W, 5)
    r6 = row3(P, 5)
    c2 = row3(P, 1)
    c3 = row3(P, 2)
    x4 = row3(P, 3)
    Rg = target_rotation(T, M)
    # T·M⁻¹ = [R_g, t_g] with t_g = t_T − R_g·t_M
    mt = mv3(Rg, (M[0, 3], M[1, 3], M[2, 3]))
    tg = (T[0, 3] - mt[0], T[1, 3] - mt[1], T[2, 3] - mt[2])
    p5 = add3(mv3(Rg, p56), tg)
    w6t = mv3(Rg, w6)
    s2 = dot3(row3(W, 1), w)
    s3 = dot3(row3(W, 2), w)
    s4 = dot3(row3(W, 3), w)
    frame = planar2r_frame(w, e, c2, c3, x4)  # joints 2, 3 carrying x4, once, not per branch
    x4r5 = sub3(x4, r5)
    r5r6 = sub3(r5, r6)
    tgr1 = sub3(tg, r1)
    buf = np.empty(16)
    q1s = buf[0:6]  # angles, then the cosine and sine of each (sp4)
    q5s = buf[6:12]
    sol = buf[12:16].reshape((2, 2))
    n1 = sp4(w1, w, sub3(p5, r1), dot3(w, sub3(p56, r1)), slack, q1s)
    k = 0
    for i in range(n1):
        q1 = q1s[i]
        c1 = q1s[2 + 2 * i]
        sn1 = q1s[3 + 2 * i]
        R1w = rot3(w1, c1, sn1, w)
        Xtw = mtv3(Rg, R1w)  # Xᵀ·w with X = R1ᵀ·R_g
        n5 = sp4(w5, w6, w, dot3(R1w, w6t), slack, q5s)
        for j in range(n5):
            q5 = q5s[j]
            c5 = q5s[2 + 2 * j]
            sn5 = q5s[3 + 2 * j]
            q6, c6, sn6 = sp1_dir_cs(w6, Xtw, rot3(w5, c5, -sn5, w))
            seeds = 1
            if slack > 0.0 and j == 0:  # near the wrist singularity: along its continuum
                aw = dot3(rot3(w5, c5, sn5, w6), w)  # w·R5·w6
                if 1.0 - aw * aw < WRIST_SEED * WRIST_SEED:
                    seeds = 3
            for t in range(seeds):
                if t == 1:  # q6 + π/2
                    q6, c6, sn6 = q6 + 0.5 * math.pi, -sn6, c6
                elif t == 2:  # q6 − π/2 (from q6 + π/2)
                    q6, c6, sn6 = q6 - math.pi, -c6, -sn6
                # G = e1⁻¹·T·M⁻¹·e6⁻¹·e5⁻¹ applied to e and x4 by rotations (no 4 × 4 products)
                ve = rot3(w1, c1, -sn1, mv3(Rg, rot3(w6, c6, -sn6, rot3(w5, c5, -sn5, e))))
                s = math.atan2(dot3(w, cross3t(e, ve)), dot3(e, ve))
                a = add3(rot3(w5, c5, -sn5, x4r5), r5r6)
                b = add3(mv3(Rg, add3(rot3(w6, c6, -sn6, a), r6)), tgr1)
                y = add3(rot3(w1, c1, -sn1, b), r1)
                m = planar2r_solve(frame, y, sol, slack)
                for r in range(m):
                    if k == out.shape[0]:
                        return k
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
    k = ur_candidates(T, W, P, M, aux, 0.0, cand)
    return finalize(cand, k, revolute, qlim, mid, F, meta, T, True, tol_p, tol_r, out)
