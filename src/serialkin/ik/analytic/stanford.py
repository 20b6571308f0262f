"""Closed-form IK of the Stanford arm class: R R P with intersecting axes 1, 2, spherical wrist.

The first two axes meet at ``o`` and the third joint slides the wrist centre along a
line, ``c + d·w3``. Rotations about axes 1 and 2 keep the distance to ``o``, so

``|c − o + d·w3|² = |p_w − o|²``,  i.e.  ``d² + 2 (w3·h) d + |h|² − |p_w − o|² = 0``,
``h = c − o``,

gives up to two strokes d; for each, q1 and q2 carry ``c + d·w3`` onto ``p_w`` about the
intersecting axes (subproblem 2, two solutions), and the spherical wrist gives two more
(see :mod:`serialkin.ik.analytic.spherical_wrist`): up to 8 candidates, usually 4 with
a positive stroke.
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
    rotation,
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
def solve_stanford(T, W, P, M, aux, revolute, qlim, mid, F, meta, tol_p, tol_r, out):
    """Every solution of a Stanford-class arm inside the limits, sorted, into ``out`` (8, 6).

    Arguments as in :func:`~serialkin.ik.analytic.spherical_wrist.solve_spherical_wrist`.
    Returns the number of solutions (0-8).
    """
    cand = np.zeros((MAX_SOLUTIONS, 6))
    k = stanford_candidates(T, W, P, M, aux, cand)
    return finalize(cand, k, revolute, qlim, mid, F, meta, T, True, tol_p, tol_r, out)
