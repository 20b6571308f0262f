"""The QP tracker's iterations for one path target in one compiled loop.

:func:`qp_point_into` runs what :meth:`serialkin.diffik.resolver.QPResolver` does per
target with ``solver='compiled'`` — frame task of the path's rows, posture task, joint
limits, per-iteration step cap, step box around the previous point, collision rows with
the velocity damper, the dual active-set solver of :mod:`serialkin.diffik.active_set` —
without returning to Python between iterations. Same maths, same stopping rules as the
Python loop (the tests compare the two).

Kernel contract: trusts its input; validation happens at the public boundary.
"""

from __future__ import annotations

import math

import numpy as np

from serialkin.diffik.active_set import OPTIMAL, solve_bounded
from serialkin.diffik.constraints import obstacle_rows_into, self_rows_into
from serialkin.kinematics import kernels as K
from serialkin.kinematics.dls import weigh_rows_into
from serialkin.redundancy.obstacles import update_geometry_into
from serialkin.spatial.kernels import pose_error_into

from .._jit import njit

__all__ = ["CONFLICT", "CONVERGED", "NO_PROGRESS", "qp_point_into"]

#: Outcome codes of :func:`qp_point_into` (a QP failure returns the solver's negative code).
CONVERGED = 0
NO_PROGRESS = 1
CONFLICT = 2
BUDGET = 3


@njit(cache=True)
def _task_error(q, F, meta, target, rows, J, T, e6, Jt, e, ones):
    K.jacobian_into(q, F, meta, J, T)
    pose_error_into(T, target, e6)
    return math.sqrt(weigh_rows_into(J, e6, rows, ones, Jt, e))


@njit(cache=True)
def qp_point_into(q, target, rows, F, L, meta, lo, hi, cfg, has_tool, enc, influence,
                  link, pairs, frames, P0, P1, Tee, Tc, SC, B, D, C, Jbuf, pbuf, G, h, PAIRS,
                  DIST, out_q):
    """Iterate QP steps from q (n,) towards ``target`` (4, 4); best q written to ``out_q``.

    Args:
        q: (n,) start configuration (not modified).
        target: (4, 4) target pose.
        rows: (m,) task rows of the pose error.
        F: chain fixed transforms ``robot.chain.F``.
        L: chain link-frame offsets ``robot.chain.L``.
        meta: chain joint data ``robot.chain.meta``.
        lo: (n,) lower joint limits (−inf allowed).
        hi: (n,) upper joint limits (+inf allowed).
        cfg: (10,) settings: posture weight, damping μ, max step per iteration, max joint
            step between points (≤ 0: none), tol, max_iter, link radius, safety d_s,
            collision gain, self-collision influence.
        has_tool: the robot has a tool segment.
        enc: (k, 8) encoded obstacles (0 rows: none).
        influence: (k,) influence distance per obstacle [m].
        link: (s,) link frame of each segment.
        pairs: (p, 2) self-collision segment pairs (0 rows: none).
        frames: buffer (n+1, 4, 4).
        P0: buffer (s, 3).
        P1: buffer (s, 3).
        Tee: buffer (4, 4).
        Tc: buffer (s, k).
        SC: buffer (s, k, 3).
        B: buffer (s, k, 3).
        D: buffer (s, k).
        C: buffer (s, k).
        Jbuf: buffer (6, n).
        pbuf: buffer (3,).
        G: buffer (s·k + p, n) collision rows.
        h: buffer (s·k + p,).
        PAIRS: buffer (s·k, 2).
        DIST: buffer (p,).
        out_q: out (n,) the best configuration found.

    Returns:
        (iterations, best error [m], code): code CONVERGED, NO_PROGRESS, CONFLICT, BUDGET
        or the QP solver's negative status.
    """
    # One piece over 80 lines: the QP iterations share their buffers, Cholesky factor and active
    # set from step to step; split into compiled calls it would add levels that each re-link and
    # re-optimise their callees (docs/compile-time.md).
    n = q.shape[0]
    m = rows.shape[0]
    w_post = cfg[0]
    mu = cfg[1]
    max_step = cfg[2]
    jump = cfg[3]
    tol = cfg[4]
    max_iter = int(cfg[5])
    link_radius = cfg[6]
    safety = cfg[7]
    gain = cfg[8]
    self_infl = cfg[9]
    J = np.empty((6, n))
    T = np.empty((4, 4))
    e6 = np.empty(6)
    Jt = np.empty((m, n))
    e = np.empty(m)
    ones = np.ones(m)
    H = np.empty((n, n))
    c = np.empty(n)
    lb = np.empty(n)
    ub = np.empty(n)
    x = np.empty(n)
    qlo = np.empty(n)
    qhi = np.empty(n)
    ref = q.copy()
    cur = q.copy()
    for j in range(n):
        qlo[j] = lo[j]
        qhi[j] = hi[j]
        if jump > 0.0:
            qlo[j] = max(qlo[j], ref[j] - jump)
            qhi[j] = min(qhi[j], ref[j] + jump)
    err = _task_error(cur, F, meta, target, rows, J, T, e6, Jt, e, ones)
    best = err
    for j in range(n):
        out_q[j] = cur[j]
    it = 0
    since = 0
    kicks = 0
    code = BUDGET
    qp_budget = 50 * (n + G.shape[0]) + 100
    while True:
        if best < tol:
            code = CONVERGED
            break
        if it >= max_iter:
            code = BUDGET
            break
        if since >= 10:
            code = NO_PROGRESS
            break
        # J and e are those of cur (from _task_error)
        for a in range(n):
            for b in range(n):
                s = 0.0
                for r in range(m):
                    s += Jt[r, a] * Jt[r, b]
                H[a, b] = s
            H[a, a] += w_post + mu
            s = 0.0
            for r in range(m):
                s += Jt[r, a] * e[r]
            c[a] = -s - w_post * (ref[a] - cur[a])
            lb[a] = max(qlo[a] - cur[a], -max_step)
            ub[a] = min(qhi[a] - cur[a], max_step)
            if lb[a] > ub[a] + 1e-12:
                return it, best, CONFLICT
            if lb[a] > ub[a]:
                lb[a] = ub[a]
            lb[a] = max(lb[a], -1e20)
            ub[a] = min(ub[a], 1e20)
        rcount = 0
        if enc.shape[0] > 0 or pairs.shape[0] > 0:
            update_geometry_into(cur, F, L, meta, has_tool, enc, link_radius, frames, P0, P1,
                                 Tee, Tc, SC, B, D, C)
            if enc.shape[0] > 0:
                rcount = obstacle_rows_into(cur, F, L, meta, frames, P0, P1, link, Tc, SC, B,
                                            D, C, influence, safety, gain, Jbuf, pbuf, G, h,
                                            PAIRS)
            if pairs.shape[0] > 0:
                rcount += self_rows_into(cur, F, L, meta, frames, P0, P1, link, pairs,
                                         link_radius, self_infl, safety, gain, Jbuf, pbuf,
                                         G[rcount:], h[rcount:], DIST)
        status, _ = solve_bounded(H, c, G[:rcount], h[:rcount], lb, ub, x, qp_budget)
        it += 1
        if status != OPTIMAL:
            return it, best, status
        big = 0.0
        for a in range(n):
            v = cur[a] + x[a]
            cur[a] = min(max(v, qlo[a]), qhi[a])
            big = max(big, abs(x[a]))
        err = _task_error(cur, F, meta, target, rows, J, T, e6, Jt, e, ones)
        if err < best * (1.0 - 1e-9):
            best = err
            since = 0
            for a in range(n):
                out_q[a] = cur[a]
        else:
            since += 1
        if big < 1e-12:
            # singular with the error in the lost direction (Jᵀe = 0): kick, as in Python
            g2 = 0.0
            jn = 0.0
            for a in range(n):
                s = 0.0
                for r in range(m):
                    s += Jt[r, a] * e[r]
                    jn += Jt[r, a] * Jt[r, a]
                g2 += s * s
            if kicks >= 3 or math.sqrt(g2) >= 1e-9 * math.sqrt(jn) * err + 1e-300:
                code = NO_PROGRESS
                break
            kicks += 1
            since = 0
            for a in range(n):
                cur[a] = min(max(cur[a] + 1e-3, qlo[a]), qhi[a])
            err = _task_error(cur, F, meta, target, rows, J, T, e6, Jt, e, ones)
    return it, best, code
