"""Closed-form IK of SCARA arms: revolute and prismatic joints on parallel axes.

The chapter's SCARA (Table 1, eqs 13-18: R R P R, α3 = π) and its 3-joint variant
(R R P). Every joint axis is parallel to one direction ``w`` (α = π only flips a
direction), and a translation along ``w`` commutes with rotations about axes parallel
to ``w``. So the prismatic joint is read off the height along ``w``,

``d = w·(p_target − p(0)) / (w·w_P)``,

the target is lowered by ``d·w_P``, and the revolute joints are those of a planar arm
(:mod:`serialkin.ik.analytic.planar`): the two-link formula of eqs 23-27 (corrected) for
the elbow, and the tool's rotation about ``w`` for the last revolute joint. Up to two
solutions (elbow left / right).
"""

from __future__ import annotations

import numpy as np

from serialkin.ik.analytic.planar import MAX_SOLUTIONS, planar_candidates
from serialkin.ik.analytic.subproblems import dot3, finalize, row3, sub3

from ..._jit import njit


@njit(cache=True)
def solve_scara(T, W, P, M, order, w, e1, revolute, qlim, mid, F, meta, check_rot, tol_p,
                tol_r, out):
    """Every solution of a SCARA (RRPR / RRP, parallel axes) inside the limits into ``out``.

    Args:
        T: (4, 4) target pose (world).
        W: (n, 3) unit joint directions at q = 0.
        P: (n, 3) a point of each joint line at q = 0 [m].
        M: (4, 4) tool pose at q = 0.
        order: revolute joint indices then the prismatic joint's index.
        w: (3,) common unit axis direction.
        e1: (3,) unit vector ⟂ w.
        revolute: (n,) booleans, True for revolute joints.
        qlim: (n, 2) joint limits.
        mid: (n,) wrapping centres of the revolute joints.
        F: (n+1, 4, 4) chain transforms (for the verification by forward kinematics).
        meta: (n, 5) chain joint data.
        check_rot: also verify the rotation (False for position targets).
        tol_p: position tolerance [m].
        tol_r: rotation-entry tolerance.
        out: (2, n) output.

    Returns:
        number of solutions.
    """
    n = W.shape[0]
    ip = order[order.shape[0] - 1]
    wp = row3(W, ip)
    wt = (w[0], w[1], w[2])  # vectors as tuples, the subproblems' type
    d = dot3(wt, sub3((T[0, 3], T[1, 3], T[2, 3]), (M[0, 3], M[1, 3], M[2, 3]))) / dot3(wt, wp)
    Tl = T.copy()
    for i in range(3):
        Tl[i, 3] -= d * wp[i]
    cand = np.zeros((MAX_SOLUTIONS, n))
    k = planar_candidates(Tl, W, P, M, order, w, e1, cand)
    for r in range(k):
        cand[r, ip] = d
    return finalize(cand, k, revolute, qlim, mid, F, meta, T, check_rot, tol_p, tol_r, out)
