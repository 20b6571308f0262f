"""Closed-form IK of planar arms: two or three revolute joints on parallel axes (section 4.1).

The two-link arm is solved by the chapter's eqs 23-27 as corrected in the ERRATA
(:func:`~serialkin.ik.analytic.subproblems.planar2r`): r = sqrt(x² + y²),
α = atan2(y, x), θ2 = ±arccos((x² + y² − L1² − L2²)/(2 L1 L2)),
β = arccos((L1² − L2² + r²)/(2 L1 r)), θ1 = α − β with θ2 = +arccos(..) and
θ1 = α + β with θ2 = −arccos(..): both elbow solutions.

The three-link arm with end-effector orientation: the tool's rotation about the common
axis fixes s = θ1 + θ2 + θ3; the point of the third axis (the "wrist" of the planar arm)
is then known, ``c3 = T·M⁻¹·c3(0)``, and the first two joints place it by the two-link
formula; θ3 = s − θ1 − θ2.

Everything is computed in the plane perpendicular to the common axis direction ``w``,
so the arm may sit anywhere and point anywhere (base and tool transforms, DH offsets,
axes flipped by α = π: joint i turns by ``(w_i·w) q_i`` about ``w``).
"""

from __future__ import annotations

import math

import numpy as np

from serialkin.ik.analytic.subproblems import (
    cross3t,
    dot3,
    finalize,
    mv3,
    planar2r,
    row3,
    target_point,
)

from ..._jit import njit

#: Most candidate solutions of the parallel-axis family.
MAX_SOLUTIONS = 2


@njit(cache=True)
def planar_candidates(T, W, P, M, order, w, e1, out):
    """Candidate joint values of the revolute joints of a parallel-axis arm.

    Args:
        T: (4, 4) target pose (world), with any prismatic motion along ``w`` removed.
        W: (n, 3) unit joint directions at q = 0.
        P: (n, 3) a point of each joint line at q = 0 [m].
        M: (4, 4) tool pose at q = 0.
        order: revolute joint indices (2 or 3 of them) followed by the prismatic joint's
            index or -1.
        w: (3,) common unit axis direction.
        e1: (3,) unit vector ⟂ w.
        out: (2, n) candidates; only the revolute columns are written.

    Returns:
        number of candidates (0, 1 or 2).
    """
    nr = order.shape[0] - 1
    i0 = order[0]
    i1 = order[1]
    sol = np.empty((2, 2))
    wt = (w[0], w[1], w[2])  # vectors as tuples, the subproblems' type
    e1t = (e1[0], e1[1], e1[2])
    if nr == 3:
        c3 = P[order[2]].copy()
        t, Rg = target_point(T, M, c3)
        v = mv3(Rg, e1t)
        s = math.atan2(dot3(wt, cross3t(e1t, v)), dot3(e1t, v))
        k = planar2r(wt, e1t, row3(P, i0), row3(P, i1), (c3[0], c3[1], c3[2]),
                     (t[0], t[1], t[2]), sol)
    else:
        s = 0.0
        k = planar2r(wt, e1t, row3(P, i0), row3(P, i1), (M[0, 3], M[1, 3], M[2, 3]),
                     (T[0, 3], T[1, 3], T[2, 3]), sol)
    for r in range(k):
        out[r, i0] = dot3(row3(W, i0), wt) * sol[r, 0]
        out[r, i1] = dot3(row3(W, i1), wt) * sol[r, 1]
        if nr == 3:
            out[r, order[2]] = dot3(row3(W, order[2]), wt) * (s - sol[r, 0] - sol[r, 1])
    return k


@njit(cache=True)
def solve_planar(T, W, P, M, order, w, e1, revolute, qlim, mid, F, meta, check_rot, tol_p,
                 tol_r, out):
    """Every solution of a planar 2R / 3R arm inside the limits, sorted, into ``out`` (2, n).

    ``check_rot`` False verifies the position only (planar (x, y) targets). Returns the
    number of solutions (see :func:`~serialkin.ik.analytic.subproblems.finalize`).
    """
    cand = np.zeros((MAX_SOLUTIONS, W.shape[0]))
    k = planar_candidates(T, W, P, M, order, w, e1, cand)
    return finalize(cand, k, revolute, qlim, mid, F, meta, T, check_rot, tol_p, tol_r, out)
