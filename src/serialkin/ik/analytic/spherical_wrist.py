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
   * ``pieper_general`` — any other R R R arm (axes 1 and 2 skew, or parallel while
     axes 2 and 3 are not): the invariants of joint 1 give a quartic in q3 (Pieper),
     solved as a degree-2 trigonometric polynomial (:func:`general_candidates`), then
     q2 and q1 in closed form.
2. **Orientation.** ``R4·R5·R6 = (R1 R2 R3)ᵀ·R_T·R_Mᵀ =: X``; ``R4 R5 w6 = X w6`` gives
   q4, q5 (subproblem 2, two solutions: wrist flip) and q6 follows by subproblem 1.

The Stanford arm (prismatic third joint) is in :mod:`serialkin.ik.analytic.stanford`.
At a wrist singularity (axes 4 and 6 aligned) only q4 + q6 is determined: one
representative with q4 = 0 is returned.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from serialkin.ik.analytic.subproblems import (
    CLAMP,
    dot3,
    finalize,
    mm,
    mtm,
    mtv,
    mv,
    planar2r,
    poly_roots,
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
def _general_residual(theta, c, w3, r3, r2, w2, a1, ca, sa, rho2, h):
    """E(θ3) = g1² + g2² − (|u|² − (w2·u)²) of the general arm (see general_candidates)."""
    u = mv(rotation(w3, theta), c - r3) + r3 - r2
    uu = dot3(u, u)
    wu = dot3(w2, u)
    g1 = (rho2 - uu - a1 * a1) / (2.0 * a1)
    g2 = (h - ca * wu) / sa
    return g1 * g1 + g2 * g2 - (uu - wu * wu)


@njit(cache=True)
def general_candidates(T, W, P, M, aux, out):
    """Candidates for a ``pieper_general`` arm; aux = (c, r1, r2, n, m, v). Returns the count.

    Axes 1 and 2 do not meet: r1, r2 are the feet of their common perpendicular, a1 = |r2 − r1|,
    n = (r2 − r1)/a1, m = w2 × n, and w1 = cα·w2 + sα·m. With u = exp(ξ3 θ3)·c − r2 and
    x = exp(ξ2 θ2)·(r2 + u) the point that joint 1 must turn onto p_w, the invariants of
    joint 1 (distance to r1 and height along w1) give (Pieper; Craig, *Introduction to
    Robotics*, section 4.6)

    * n·R2 u = g1 = (|p_w − r1|² − |u|² − a1²)/(2 a1),
    * m·R2 u = g2 = (w1·(p_w − r1) − cα w2·u)/sα,

    and since R2 turns the (n, m) components of u rigidly, g1² + g2² = |u|² − (w2·u)²:
    a trigonometric polynomial E(θ3) of degree 2 (a quartic). Its Fourier coefficients
    come exactly from 5 samples; the roots of ``z²·E`` (z = e^{iθ3}) on the unit circle,
    polished by Newton's method, give up to 4 values of θ3; then
    θ2 = atan2(g2, g1) − atan2(m·u, n·u) and θ1 by subproblem 1.

    When axes 1 and 2 are parallel (sα = 0) the second invariant reads w2·u = cα·w1·(p_w − r1)
    instead: θ3 by :func:`~serialkin.ik.analytic.subproblems.sp4` (two values) and
    g2 = ±sqrt(|u|² − (w2·u)² − g1²) (two values of θ2 each).
    """
    c = aux[0].copy()
    r1 = aux[1].copy()
    r2 = aux[2].copy()
    n = aux[3].copy()
    m = aux[4].copy()
    v = aux[5].copy()
    w1 = W[0].copy()
    w2 = W[1].copy()
    w3 = W[2].copy()
    r3 = P[2].copy()
    pw, Rg = _wrist_centre(T, M, c)
    a1 = dot3(r2 - r1, n)
    ca = dot3(w1, w2)
    sa = dot3(w1, m)
    rho2 = dot3(pw - r1, pw - r1)
    h = dot3(w1, pw - r1)
    thetas = np.empty(4)
    if abs(sa) < 1e-9:  # axes 1 ∥ 2: w2·u(θ3) = cα·h fixes θ3 (two values), g2 = ±sqrt(..)
        nt = sp4(w3, c - r3, w2, ca * h - dot3(w2, r3 - r2), thetas)
    else:
        nt = _quartic_theta3(c, w3, r3, r2, w2, a1, ca, sa, rho2, h, thetas)
    k = 0
    for i in range(nt):
        th = thetas[i]
        u = mv(rotation(w3, th), c - r3) + r3 - r2
        uu = dot3(u, u)
        wu = dot3(w2, u)
        g1 = (rho2 - uu - a1 * a1) / (2.0 * a1)
        if abs(sa) < 1e-9:
            g2sq = uu - wu * wu - g1 * g1
            if g2sq < -CLAMP * max(uu, 1e-300):
                continue
            g2 = math.sqrt(max(g2sq, 0.0))
            ng = 1 if g2 == 0.0 else 2
        else:
            g2 = (h - ca * wu) / sa
            ng = 1
        for j in range(ng):
            gj = g2 if j == 0 else -g2
            th2 = math.atan2(gj, g1) - math.atan2(dot3(m, u), dot3(n, u))
            x = mv(rotation(w2, th2), u) + r2
            th1 = sp1_dir(w1, x - r1, pw - r1)
            R123 = mm(mm(rotation(w1, th1), rotation(w2, th2)), rotation(w3, th))
            if k + 2 > out.shape[0]:
                return k
            k = wrist_into(Rg, R123, W, v, th1, th2, th, out, k)
    return k


@njit(cache=True)
def _quartic_theta3(c, w3, r3, r2, w2, a1, ca, sa, rho2, h, thetas):
    """Real roots θ3 of E(θ3) (degree-2 trigonometric polynomial) into ``thetas``; the count.

    The Fourier coefficients c0, c1, c2 of E come exactly from 5 equally spaced samples;
    the roots of ``z²·E(z)`` (z = e^{iθ}) near the unit circle
    (:func:`~serialkin.ik.analytic.subproblems.poly_roots`) are polished by Newton's
    method on E and kept when E vanishes there.
    """
    coef = np.zeros(3, dtype=np.complex128)
    scale = 0.0
    for j in range(5):
        th = 2.0 * np.pi * j / 5.0
        e = _general_residual(th, c, w3, r3, r2, w2, a1, ca, sa, rho2, h)
        scale = max(scale, abs(e))
        for k in range(3):
            coef[k] += e * np.exp(-1j * k * th) / 5.0
    poly = np.empty(5, dtype=np.complex128)  # z²·E(z) = c2 z⁴ + c1 z³ + c0 z² + c̄1 z + c̄2
    poly[0] = coef[2]
    poly[1] = coef[1]
    poly[2] = coef[0]
    poly[3] = np.conj(coef[1])
    poly[4] = np.conj(coef[2])
    big = max(abs(poly[0]), abs(poly[1]), abs(poly[2]))
    if big <= 1e-12 * max(scale, 1e-300):
        return 0  # E(θ3) ≡ 0: a continuum of solutions (excluded by the structure test)
    # when c2 vanishes both ends of z²·E do: drop the z factor (no spurious root z = 0)
    roots = np.empty(4, dtype=np.complex128)
    nr = poly_roots(poly if abs(poly[0]) > 1e-13 * big else poly[1:4], roots)
    count = 0
    for z in roots[:nr]:
        if abs(abs(z) - 1.0) > 1e-3 or count == thetas.shape[0]:
            continue
        th = math.atan2(z.imag, z.real)
        for _ in range(8):  # Newton on E(θ) = c0 + 2 Re(c1 e^{iθ} + c2 e^{2iθ})
            e1 = np.exp(1j * th)
            e2 = e1 * e1
            f = coef[0].real + 2.0 * (coef[1] * e1 + coef[2] * e2).real
            df = 2.0 * (1j * coef[1] * e1 + 2j * coef[2] * e2).real
            if df == 0.0:
                break
            step = f / df
            th -= step
            if abs(step) < 1e-15:
                break
        if abs(_general_residual(th, c, w3, r3, r2, w2, a1, ca, sa, rho2, h)) \
                <= 1e-8 * max(scale, 1e-300):
            thetas[count] = th
            count += 1
    return count


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
        arm: 0 for ``puma``, 1 for ``pieper_intersecting``, 2 for ``pieper_general``.
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
    elif arm == 1:
        k = intersecting_candidates(T, W, P, M, aux, cand)
    else:
        k = general_candidates(T, W, P, M, aux, cand)
    return finalize(cand, k, revolute, qlim, mid, F, meta, T, True, tol_p, tol_r, out)
