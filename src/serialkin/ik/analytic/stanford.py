"""Closed-form IK of the Stanford arm class: R R P with intersecting axes 1, 2, spherical wrist.

The first two axes meet at ``o`` and the third joint slides the wrist centre along a
line, ``c + d·w3``. Rotations about axes 1 and 2 keep the distance to ``o``, so

``|c − o + d·w3|² = |p_w − o|²``,  i.e.  ``d² + 2 (w3·h) d + |h|² − |p_w − o|² = 0``,
``h = c − o``,

gives up to two strokes d; for each, q1 and q2 carry ``c + d·w3`` onto ``p_w`` about the
intersecting axes (subproblem 2, two solutions), and the spherical wrist gives two more
(see :mod:`serialkin.ik.analytic.spherical_wrist`): up to 8 candidates, usually 4 with
a positive stroke.

``stanford_general``: when axes 1 and 2 do not meet (a shoulder offset), the invariants
of joint 1 give a quartic in the stroke instead (:func:`general_stanford_candidates`).
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from serialkin.ik.analytic.spherical_wrist import MAX_SOLUTIONS, wrist_into
from serialkin.ik.analytic.subproblems import (
    CLAMP,
    dot3,
    finalize,
    mm,
    mv,
    poly_roots,
    rotation,
    sp1_dir,
    sp2_dir,
    target_rotation,
)


@njit(cache=True)
def stanford_candidates(T, W, P, M, aux, out):
    """Candidates for a ``stanford``-class arm; aux = (c, o, v ⟂ w6). Returns the count."""
    c = aux[0].copy()
    o = aux[1].copy()
    v = aux[2].copy()
    w1 = W[0].copy()
    w2 = W[1].copy()
    w3 = W[2].copy()
    Rg = target_rotation(T, M)
    pw = mv(Rg, c - M[:3, 3]) + T[:3, 3]
    h = c - o
    g = pw - o
    b = dot3(w3, h)
    hh = dot3(h, h)
    disc = b * b - hh + dot3(g, g)
    if disc < 0.0:
        if disc < -CLAMP * max(hh, 1.0):
            return 0
        disc = 0.0
    root = math.sqrt(disc)
    nd = 1 if root == 0.0 else 2
    sol = np.empty((2, 2))
    k = 0
    for i in range(nd):
        d = -b + root if i == 0 else -b - root
        x = h + d * w3
        m = sp2_dir(w1, w2, x, g, sol)
        for j in range(m):
            R12 = mm(rotation(w1, sol[j, 0]), rotation(w2, sol[j, 1]))
            k = wrist_into(Rg, R12, W, v, sol[j, 0], sol[j, 1], d, out, k)
    return k


@njit(cache=True)
def _polish(coefs, x):
    """Newton steps on the real polynomial ``coefs`` (highest degree first) from x."""
    for _ in range(8):
        f = 0.0
        df = 0.0
        for c in coefs:
            df = df * x + f
            f = f * x + c
        if df == 0.0:
            break
        step = f / df
        x -= step
        if abs(step) <= 1e-15 * max(1.0, abs(x)):
            break
    return x


@njit(cache=True)
def general_stanford_candidates(T, W, P, M, aux, out):
    """Candidates for a ``stanford_general`` arm; aux = (c, r1, r2, n, m, v). Returns the count.

    As in :func:`~serialkin.ik.analytic.spherical_wrist.general_candidates` with the
    slide in place of joint 3: u(d) = c + d·w3 − r2 is linear in the stroke d, so
    g1 = (|p_w − r1|² − |u|² − a1²)/(2 a1) is quadratic, g2 = (w1·(p_w − r1) − cα w2·u)/sα
    linear, and E(d) = g1² + g2² − (|u|² − (w2·u)²) is a quartic in d, solved by
    :func:`~serialkin.ik.analytic.subproblems.poly_roots` and polished by Newton's
    method; then q2 = atan2(g2, g1) − atan2(m·u, n·u) and q1 by subproblem 1. With
    parallel axes 1, 2 (sα = 0) the height w2·u(d) = cα·w1·(p_w − r1) gives d directly
    and g2 = ±sqrt(..).
    """
    c = aux[0].copy()
    r1 = aux[1].copy()
    r2 = aux[2].copy()
    n = aux[3].copy()
    m = aux[4].copy()
    v = aux[5].copy()
    w1 = W[0].copy()
    w2 = W[1].copy()
    b = W[2].copy()
    Rg = target_rotation(T, M)
    pw = mv(Rg, c - M[:3, 3]) + T[:3, 3]
    a1 = dot3(r2 - r1, n)
    ca = dot3(w1, w2)
    sa = dot3(w1, m)
    rho2 = dot3(pw - r1, pw - r1)
    h = dot3(w1, pw - r1)
    h0 = c - r2
    wb = dot3(w2, b)
    wh = dot3(w2, h0)
    strokes = np.empty(4)
    ns = 0
    parallel = abs(sa) < 1e-9
    if parallel:
        if abs(wb) > 1e-12:
            strokes[0] = (ca * h - wh) / wb
            ns = 1
    else:
        K2 = -1.0 / (2.0 * a1)
        K1 = -dot3(b, h0) / a1
        K0 = (rho2 - dot3(h0, h0) - a1 * a1) / (2.0 * a1)
        L1 = -ca * wb / sa
        L0 = (h - ca * wh) / sa
        N2 = 1.0 - wb * wb
        N1 = 2.0 * (dot3(b, h0) - wh * wb)
        N0 = dot3(h0, h0) - wh * wh
        coefs = np.array([K2 * K2, 2.0 * K1 * K2, K1 * K1 + 2.0 * K0 * K2 + L1 * L1 - N2,
                          2.0 * K0 * K1 + 2.0 * L0 * L1 - N1, K0 * K0 + L0 * L0 - N0])
        roots = np.empty(4, dtype=np.complex128)
        roots = roots[:poly_roots(coefs.astype(np.complex128), roots)]
        big = 0.0
        for cf in coefs:
            big = max(big, abs(cf))
        for z in roots:
            if abs(z.imag) > 1e-4 * max(1.0, abs(z.real)) or ns == 4:
                continue
            d = _polish(coefs, z.real)
            f = 0.0
            for cf in coefs:
                f = f * d + cf
            if abs(f) <= 1e-9 * big * max(1.0, d * d * d * d):
                strokes[ns] = d
                ns += 1
    sol_k = 0
    for i in range(ns):
        d = strokes[i]
        u = h0 + d * b
        uu = dot3(u, u)
        wu = dot3(w2, u)
        g1 = (rho2 - uu - a1 * a1) / (2.0 * a1)
        if parallel:
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
            R12 = mm(rotation(w1, th1), rotation(w2, th2))
            if sol_k + 2 > out.shape[0]:
                return sol_k
            sol_k = wrist_into(Rg, R12, W, v, th1, th2, d, out, sol_k)
    return sol_k


@njit(cache=True)
def solve_stanford(T, W, P, M, aux, general, revolute, qlim, mid, F, meta, tol_p, tol_r,
                   out):
    """Every solution of a Stanford-class arm inside the limits, sorted, into ``out`` (8, 6).

    ``general`` selects :func:`general_stanford_candidates` (axes 1, 2 do not meet);
    other arguments as in
    :func:`~serialkin.ik.analytic.spherical_wrist.solve_spherical_wrist`.
    Returns the number of solutions (0-8).
    """
    cand = np.zeros((MAX_SOLUTIONS, 6))
    if general:
        k = general_stanford_candidates(T, W, P, M, aux, cand)
    else:
        k = stanford_candidates(T, W, P, M, aux, cand)
    return finalize(cand, k, revolute, qlim, mid, F, meta, T, True, tol_p, tol_r, out)
