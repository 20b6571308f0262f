"""All IK solutions of a general 6R arm: Raghavan–Roth elimination, then a 2-D search.

A 6R arm in no special class (no spherical wrist, no three parallel axes) has up to 16
solutions (Raghavan & Roth 1993; Manseur & Doty 1989). :func:`general_candidates`
first eliminates five joints (:mod:`serialkin.ik.analytic.raghavan_roth`: a
trigonometric eliminant of degree 8 in θ3, 17 determinants of a 12 × 12 pencil,
about 35 µs per pose). Why the elimination first: it is exact (one candidate per real
root, every one refined by Newton's method), 20-50 times faster than the search, and
it finds the solutions closer together than a search cell. When it does not apply (a
rank-deficient elimination near special geometry) or loses a root (a cluster of
solutions, a singular configuration), the search below takes over, as IK-Geo does for
every arm (A. J. Elias, J. T. Wen, *IK-Geo: unified robot inverse kinematics using
subproblem decomposition*, Mechanism and Machine Theory 2025; arXiv:2211.05737): the
unknowns that no subproblem can eliminate are searched, the rest are closed forms:

1. Fix (q5, q6) on an N × N grid of the torus. Then
   ``G = T·M⁻¹·exp(−ξ6 q6)·exp(−ξ5 q5) = exp(ξ1 q1)···exp(ξ4 q4)`` is known.
2. A point ``c`` on axis 4 is not moved by joint 4, so ``exp(ξ1 q1)exp(ξ2 q2)exp(ξ3 q3)·c
   = G·c``: the position problem of the 3R arm in front of it, solved in closed form
   by the same functions as Pieper's spherical-wrist arms
   (:func:`~serialkin.ik.analytic.spherical_wrist.arm_positions`: up to 4 solutions,
   the quartic of Pieper's general case, or the planar / intersecting-axes forms).
3. Joint 4 must then produce ``X = R123ᵀ R_G`` alone, a rotation about ``w4``; the
   residual of the node and branch is ``|X w4 − w4|`` (two independent components:
   2 equations in the 2 searched unknowns, isolated zeros). q4 follows by subproblem 1.
4. Every grid node and branch whose residual is a local minimum (against the nearest
   branch of each of its 8 neighbours) starts Newton's method on the full pose error
   (:func:`~serialkin.ik.analytic.refine.newton_refine`); converged, distinct solutions
   are kept (at most :data:`MAX_SOLUTIONS`).

The search costs the grid (``grid``² nodes × one quartic, milliseconds), and two
solutions closer together than about one grid cell can merge into one basin (an odd
count, impossible for real solutions of a 6R, triggers one more search on a grid twice
as fine). On 400 random arms (1426 solutions, found independently by Newton from 300
random starts each; ``benchmarks/bench_ik_all.py --miss-arms``) grids 20 and 24 missed
none, grid 16 missed 2 and grid 12 missed 4: the default is 24. ``grid`` can be raised.
"""

from __future__ import annotations

import math

import numpy as np

from serialkin.ik.analytic.raghavan_roth import NEAR_SPECIAL, rr_candidates_from
from serialkin.ik.analytic.refine import refine_new, wrapped_dist
from serialkin.ik.analytic.spherical_wrist import arm_positions
from serialkin.ik.analytic.subproblems import (
    TWO_PI,
    inv_rigid,
    mm,
    mtv,
    mv,
    rotation,
    row3,
    screw,
    sp1_dir,
    transform_point,
)

from ..._jit import njit

#: Most solutions of a 6R arm.
MAX_SOLUTIONS = 16
#: A Newton iterate this close to a solution already found (every joint, wrapped) [rad]
#: stops: it converges onto it.
KNOWN_RADIUS = 1e-4
#: Default number of grid nodes per searched joint.
DEFAULT_GRID = 24


@njit(cache=True, inline="always")
def general_candidates(T, W, P, M, aux, arm, reverse, rr_other, grid, F, meta, tol_p, tol_r,
                       out):
    """Every solution of a general 6R arm into ``out`` (16, 6).

    By :func:`~serialkin.ik.analytic.raghavan_roth.rr_candidates_from` (starting on the
    reversal of the searched chain's splits when ``rr_other``: ``order[2]`` of
    :func:`~serialkin.ik.analytic.structure.general_structure`) when it applies and
    accounts for every root of its eliminant with an even count, else by
    :func:`search_candidates`. When the elimination declines the arm as a whole
    (:data:`~serialkin.ik.analytic.raghavan_roth.NEAR_SPECIAL`: near a special class,
    two axes 1° apart and 1e-6 m away say, where a solution's basin of the search can
    be narrower than a cell), a search that finds nothing is repeated on a grid twice as
    fine (four times the nodes: on 96 random poses of arms with two axes 0.5–1° apart
    and 0–1e-6 m away, 18 solutions a multi-start Newton search found were missing
    before, 7 after; an unreachable pose on such an arm takes about 17 ms instead of
    3.4). The solutions the elimination did converge to before it declined are kept
    beside the search's (the union, duplicates dropped in joint space): a search that
    misses one cannot lose it. Arguments and result as for :func:`search_candidates`.
    """
    k = rr_candidates_from(T, W, P, M, reverse, rr_other, F, meta, tol_p, tol_r, out)
    if k >= 0 and k % 2 == 0:
        return k
    near_special = k == NEAR_SPECIAL
    kept = 0 if near_special else (k if k >= 0 else -1 - k)  # converged rows in out
    found = out[:kept].copy()
    k = search_candidates(T, W, P, M, aux, arm, reverse, grid, F, meta, tol_p, tol_r, out)
    if near_special and k == 0:  # basins narrower than a cell?
        k = search_candidates(T, W, P, M, aux, arm, reverse, 2 * grid, F, meta, tol_p, tol_r,
                              out)
    for i in range(kept):  # the elimination's converged solutions are kept: the union
        new = k < out.shape[0]
        for j in range(k):
            if wrapped_dist(found[i], out[j], 6) < 1e-7:
                new = False
                break
        if new:
            for j in range(out.shape[1]):  # a loop: see subproblems.finalize
                out[k, j] = found[i, j]
            k += 1
    return k


@njit(cache=True)
def search_candidates(T, W, P, M, aux, arm, reverse, grid, F, meta, tol_p, tol_r, out):
    """Every solution of a general 6R arm found by the (q5, q6) search, into ``out`` (16, 6).

    Args:
        T: (4, 4) target pose (world).
        W: (6, 3) unit joint directions at q = 0.
        P: (6, 3) a point of each joint line at q = 0 [m].
        M: (4, 4) tool pose at q = 0.
        aux: class data of the 3R arm of joints 1-3 (``aux[0]`` = c, a point of axis 4,
            then as for :func:`~serialkin.ik.analytic.spherical_wrist.arm_positions`),
            and ``aux[-1]`` a unit vector ⟂ w4.
        arm: arm code for ``arm_positions`` (0 planar 2 ∥ 3, 1 axes 1, 2 meet, 2 other).
        reverse: W, P, M describe the reversed chain (joint j is joint 7 − j, tool pose
            M⁻¹), searched for ``T⁻¹``; rows are returned in the robot's joint order.
        grid: nodes per searched joint (N; N² nodes).
        F: (7, 4, 4) chain transforms.
        meta: (6, 5) chain joint data.
        tol_p: Newton position tolerance [m].
        tol_r: Newton rotation tolerance [rad].
        out: (16, 6) output rows (refined, not wrapped).

    Returns:
        the number of distinct converged solutions.
    """
    # One piece over 80 lines: the grid scan and the Newton refinement of its sign changes share
    # their buffers; split into compiled calls it would add levels that each re-link and
    # re-optimise their callees (docs/compile-time.md).
    N = grid
    c = aux[0].copy()
    u4 = aux[aux.shape[0] - 1].copy()
    w4 = W[3].copy()
    w5 = W[4].copy()
    r5 = P[4].copy()
    w6 = W[5].copy()
    r6 = P[5].copy()
    Ts = inv_rigid(T) if reverse else T
    TMinv = mm(Ts, inv_rigid(M.copy()))  # a writeable copy, as T is: inv_rigid compiles once
    nb = np.zeros((N, N), dtype=np.int64)
    res = np.full((N, N, 4), np.inf)
    Q = np.zeros((N, N, 4, 4))
    arm3 = np.empty((4, 3))
    h = TWO_PI / N
    E5 = np.empty((N, 4, 4))  # exp(−ξ5 q5) and T·M⁻¹·exp(−ξ6 q6) on the grid
    A6 = np.empty((N, 4, 4))
    for i in range(N):
        E = screw(w5, r5, -(-math.pi + h * i), False)
        A = mm(TMinv, screw(w6, r6, -(-math.pi + h * i), False))
        for i4 in range(4):  # loops: see subproblems.finalize
            for j4 in range(4):
                E5[i, i4, j4] = E[i4, j4]
                A6[i, i4, j4] = A[i4, j4]
    w1 = W[0].copy()
    w2 = W[1].copy()
    w3 = W[2].copy()
    w4t = row3(W, 3)  # w4, u4 as tuples for sp1_dir (the subproblems' vector type)
    u4t = row3(aux, aux.shape[0] - 1)
    for i5 in range(N):
        # G = A6·E5 is applied to c, w4, u4 only: E5's part once per row, no 4 × 4 product
        e5c = transform_point(E5[i5], c)
        e5w = mv(E5[i5], w4)
        e5u = mv(E5[i5], u4)
        for i6 in range(N):
            pw = transform_point(A6[i6], e5c)
            m = arm_positions(pw, W, P, aux, arm, False, 0.0, arm3)
            nb[i5, i6] = m
            gw = mv(A6[i6], e5w)  # R_G w4 and R_G u4, then turned back by joints 1-3
            gu = mv(A6[i6], e5u)
            for b in range(m):
                R1 = rotation(w1, arm3[b, 0])  # Rot(w, −θ)·v = Rot(w, θ)ᵀ·v, one sin/cos each
                R2 = rotation(w2, arm3[b, 1])
                R3 = rotation(w3, arm3[b, 2])
                xw = mtv(R3, mtv(R2, mtv(R1, gw)))
                xu = mtv(R3, mtv(R2, mtv(R1, gu)))
                res[i5, i6, b] = math.sqrt((xw[0] - w4[0]) ** 2 + (xw[1] - w4[1]) ** 2
                                           + (xw[2] - w4[2]) ** 2)
                Q[i5, i6, b, 0] = arm3[b, 0]
                Q[i5, i6, b, 1] = arm3[b, 1]
                Q[i5, i6, b, 2] = arm3[b, 2]
                Q[i5, i6, b, 3] = sp1_dir(w4t, u4t, (xu[0], xu[1], xu[2]))
    local = np.zeros((N, N, 4), dtype=np.bool_)  # residual below every neighbour's
    for i5 in range(N):
        for i6 in range(N):
            for b in range(nb[i5, i6]):
                local[i5, i6, b] = _is_local_min(res, Q, nb, i5, i6, b, N)
    k = 0
    q = np.empty(6)
    qs = np.empty(6)
    accept = 2.0 * h  # residuals this small start Newton even when not a local minimum
    # Local minima first, then the other nodes with a residual below ``accept``; a start
    # inside 0.5 h of a solution already found is skipped, and Newton's method stops as
    # soon as it comes within KNOWN_RADIUS of one (it would converge onto it)
    for phase in range(2):
        for i5 in range(N):
            for i6 in range(N):
                for b in range(nb[i5, i6]):
                    if local[i5, i6, b] != (phase == 0):
                        continue
                    if phase == 1 and res[i5, i6, b] > accept:
                        continue
                    for j in range(4):
                        qs[j] = Q[i5, i6, b, j]
                    qs[4] = -math.pi + h * i5
                    qs[5] = -math.pi + h * i6
                    for j in range(6):
                        q[j] = qs[5 - j] if reverse else qs[j]
                    near = False  # inside the basin of a solution already found: skip
                    for s in range(k):
                        if wrapped_dist(q, out[s], 6) < 0.5 * h:
                            near = True
                            break
                    if near:
                        continue
                    k = refine_new(q, T, F, meta, tol_p, tol_r, out, k, KNOWN_RADIUS)
    return k


@njit(cache=True)
def _is_local_min(res, Q, nb, i5, i6, b, N):
    """Whether node (i5, i6) branch b is a local minimum of the residual.

    Its residual must be no larger than that of each of its 8 neighbours' nearest branch
    (nearest in the wrapped arm joints q1-q3).
    """
    r = res[i5, i6, b]
    for d5 in range(-1, 2):
        for d6 in range(-1, 2):
            if d5 == 0 and d6 == 0:
                continue
            j5 = (i5 + d5) % N
            j6 = (i6 + d6) % N
            best = -1
            bd = math.inf
            for bb in range(nb[j5, j6]):  # the neighbour's nearest branch
                dd = wrapped_dist(Q[i5, i6, b], Q[j5, j6, bb], 3)
                if dd < bd:
                    bd = dd
                    best = bb
            if best >= 0 and res[j5, j6, best] < r:
                return False
    return True
