"""Closed-form IK of 6-joint arms with a spherical wrist (Pieper's method): up to 8 solutions.

When the last three revolute axes meet in one point, the wrist centre ``c`` (that point
at q = 0) is moved by the first three joints only (joints 4-6 rotate about it), so the
problem splits (D. L. Pieper, PhD thesis, Stanford 1968):

1. **Position.** The target puts the wrist centre at ``p_w = T·M⁻¹·c``; find q1..q3 with
   ``exp(ξ1 q1)·exp(ξ2 q2)·exp(ξ3 q3)·c = p_w``:

   * ``puma`` — axes 2 and 3 parallel (direction ``w``): rotations about them keep the
     component of ``c`` along ``w``, so ``(R1(q1)·w)·(p_w − r1) = w·(c − r1)`` gives q1
     (two solutions: shoulder left / right); then q2, q3 place ``exp(−ξ1 q1)·p_w`` by the
     two-link formula of eqs 23-27 (corrected) in the plane ⟂ w (elbow up / down).
     Shoulder and elbow offsets of any size are covered (Puma 560, KUKA, ABB, Fanuc...).
   * ``pieper_intersecting`` — axes 1 and 2 meet at ``o``: rotations about them keep
     the distance to ``o``, so ``|exp(ξ3 q3)·c − o| = |p_w − o|`` gives q3 (subproblem 3),
     then q1, q2 by subproblem 2.
2. **Orientation.** ``R4·R5·R6 = (R1 R2 R3)ᵀ·R_T·R_Mᵀ =: X``; ``R4 R5 w6 = X w6`` gives
   q4, q5 (subproblem 2, two solutions: wrist flip) and q6 follows by subproblem 1.

The Stanford arm (prismatic third joint) is in :mod:`serialkin.ik.analytic.stanford`.
At a wrist singularity (axes 4 and 6 aligned) only q4 + q6 is determined: one
representative with q4 = 0 is returned.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from serialkin.ik.analytic.subproblems import (
    dot3,
    finalize,
    mm,
    mtm,
    mtv,
    mv,
    planar2r,
    rotation,
    screw,
    sp1_dir,
    sp2_dir,
    sp3,
    sp4,
    target_rotation,
    transform_point,
)

#: Most candidate solutions of a 6-joint arm.
MAX_SOLUTIONS = 8


@njit(cache=True)
def wrist_into(Rg, R123, W, v, q1, q2, q3, out, k):
    """Append the wrist solutions (q4, q5, q6) for arm joints (q1, q2, q3) to ``out``.

    Args:
        Rg: (3, 3) ``R_T·R_Mᵀ``, the rotation the six joints must produce.
        R123: (3, 3) rotation of the first three joints.
        W: (6, 3) joint directions at q = 0.
        v: (3,) unit vector ⟂ w6.
        q1: arm joint 1 value.
        q2: arm joint 2 value.
        q3: arm joint 3 value [rad or m].
        out: (8, 6) candidate rows; rows k, k+1 are written.
        k: number of rows already in ``out``.

    Returns:
        the new number of rows.
    """
    X = mtm(R123, Rg)
    w4 = W[3].copy()
    w5 = W[4].copy()
    w6 = W[5].copy()
    sol = np.empty((2, 2))
    m = sp2_dir(w4, w5, w6, mv(X, w6), sol)
    for r in range(m):
        R45 = mm(rotation(w4, sol[r, 0]), rotation(w5, sol[r, 1]))
        q6 = sp1_dir(w6, v, mtv(R45, mv(X, v)))
        out[k, 0] = q1
        out[k, 1] = q2
        out[k, 2] = q3
        out[k, 3] = sol[r, 0]
        out[k, 4] = sol[r, 1]
        out[k, 5] = q6
        k += 1
    return k


@njit(cache=True)
def _wrist_centre(T, M, c):
    """Target position of the wrist centre, ``T·M⁻¹·c``, and ``R_T·R_Mᵀ``."""
    Rg = target_rotation(T, M)
    pw = mv(Rg, c - M[:3, 3]) + T[:3, 3]
    return pw, Rg


@njit(cache=True)
def puma_candidates(T, W, P, M, aux, out):
    """Candidates for a ``puma``-class arm; aux = (c, w, e1 ⟂ w, v ⟂ w6). Returns the count."""
    c = aux[0].copy()
    w = aux[1].copy()
    e1 = aux[2].copy()
    v = aux[3].copy()
    w1 = W[0].copy()
    r1 = P[0].copy()
    pw, Rg = _wrist_centre(T, M, c)
    q1s = np.empty(2)
    n1 = sp4(w1, w, pw - r1, dot3(w, c - r1), q1s)
    sol = np.empty((2, 2))
    k = 0
    s2 = dot3(W[1], w)
    s3 = dot3(W[2], w)
    for i in range(n1):
        q1 = q1s[i]
        x = transform_point(screw(w1, r1, -q1, False), pw)
        m = planar2r(w, e1, P[1].copy(), P[2].copy(), c, x, sol)
        for j in range(m):
            q2 = s2 * sol[j, 0]
            q3 = s3 * sol[j, 1]
            R123 = mm(mm(rotation(w1, q1), rotation(W[1].copy(), q2)),
                      rotation(W[2].copy(), q3))
            k = wrist_into(Rg, R123, W, v, q1, q2, q3, out, k)
    return k


@njit(cache=True)
def intersecting_candidates(T, W, P, M, aux, out):
    """Candidates for a ``pieper_intersecting`` arm; aux = (c, o, v). Returns the count."""
    c = aux[0].copy()
    o = aux[1].copy()
    v = aux[2].copy()
    w1 = W[0].copy()
    w2 = W[1].copy()
    w3 = W[2].copy()
    r3 = P[2].copy()
    pw, Rg = _wrist_centre(T, M, c)
    delta = np.sqrt(dot3(pw - o, pw - o))
    q3s = np.empty(2)
    n3 = sp3(w3, r3, c, o, delta, q3s)
    sol = np.empty((2, 2))
    k = 0
    for i in range(n3):
        q3 = q3s[i]
        x = transform_point(screw(w3, r3, q3, False), c)
        m = sp2_dir(w1, w2, x - o, pw - o, sol)
        for j in range(m):
            R123 = mm(mm(rotation(w1, sol[j, 0]), rotation(w2, sol[j, 1])), rotation(w3, q3))
            k = wrist_into(Rg, R123, W, v, sol[j, 0], sol[j, 1], q3, out, k)
    return k


@njit(cache=True)
def solve_spherical_wrist(T, W, P, M, aux, arm, revolute, qlim, mid, F, meta, tol_p, tol_r,
                          out):
    """Every solution of a spherical-wrist 6R arm inside the limits, sorted, into ``out``.

    Args:
        T: (4, 4) target pose (world).
        W: (6, 3) unit joint directions at q = 0.
        P: (6, 3) a point of each joint line at q = 0 [m].
        M: (4, 4) tool pose at q = 0.
        aux: class data (see the candidate functions).
        arm: 0 for ``puma``, 1 for ``pieper_intersecting``.
        revolute: (6,) booleans, True for revolute joints.
        qlim: (6, 2) joint limits.
        mid: (6,) wrapping centres of the revolute joints.
        F: (7, 4, 4) chain transforms (for the verification by forward kinematics).
        meta: (6, 5) chain joint data.
        tol_p: position tolerance [m].
        tol_r: rotation-entry tolerance.
        out: (8, 6) output.

    Returns:
        number of solutions (0-8).
    """
    cand = np.zeros((MAX_SOLUTIONS, 6))
    if arm == 0:
        k = puma_candidates(T, W, P, M, aux, cand)
    else:
        k = intersecting_candidates(T, W, P, M, aux, cand)
    return finalize(cand, k, revolute, qlim, mid, F, meta, T, True, tol_p, tol_r, out)
