"""The S-R-S closed form in numpy: the reference the compiled kernel is checked against.

The arm-angle solutions were computed with numpy before the compiled kernel
(``serialkin.ik.analytic.arm_angle._srs_one``) replaced them; this is that computation,
kept here (never imported by the library) so that a test can show the kernel gives the
same rows. Likewise :func:`intervals`, the grid search and bisection the closed-form
feasible intervals replaced. Steps and symbols as in the module docstring of
:mod:`serialkin.ik.analytic.arm_angle`.
"""

from __future__ import annotations

import math

import numpy as np

from serialkin.ik.analytic.arm_angle import SRSArm
from serialkin.spatial.rotations import perpendicular

LIMIT_TOL = 1e-9


def _cross(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    return np.cross(a, b)


def _rot(h: np.ndarray, t: np.ndarray) -> np.ndarray:
    K = np.array([[0.0, -h[2], h[1]], [h[2], 0.0, -h[0]], [-h[1], h[0], 0.0]])
    s, c = np.sin(t)[..., None, None], np.cos(t)[..., None, None]
    return np.eye(3) + s * K + (1.0 - c) * (K @ K)


def _sp1(w: np.ndarray, u: np.ndarray, v: np.ndarray) -> np.ndarray:
    up = u - (u @ w)[..., None] * w
    vp = v - (v @ w)[..., None] * w
    return np.arctan2(_cross(up, vp) @ w, np.sum(up * vp, axis=-1))


def _sp2(w1, w2, u, v):
    c12 = float(w1 @ w2)
    den = c12 * c12 - 1.0
    a2u = float(w2 @ u)
    a1v = v @ w1
    alpha = (c12 * a2u - a1v) / den
    beta = (c12 * a1v - a2u) / den
    x = _cross(w1, w2)
    g2 = (1.0 - alpha**2 - beta**2 - 2.0 * alpha * beta * c12) / float(x @ x)
    g = np.sqrt(np.maximum(g2, 0.0))
    sign = np.array([1.0, -1.0])
    z = (alpha[..., None, None] * w1 + beta[..., None, None] * w2
         + (g[..., None] * sign)[..., None] * x)
    t2 = _sp1(w2, np.broadcast_to(u, z.shape), z)
    t1 = _sp1(w1, z, np.broadcast_to(v[..., None, :], z.shape))
    return t1, t2, g2 > -1e-9


def _elbow(arm: SRSArm, L: np.ndarray):
    h4, p4 = arm.H[3], arm.P[3]
    u, v = arm.W0 - p4, arm.S - p4
    u_par = (u @ h4) * h4
    u_perp = u - u_par
    A, B = float(v @ u_perp), float(v @ np.cross(h4, u_perp))
    k = 0.5 * (float(u @ u + v @ v) - L**2) - float(v @ u_par)
    rho = math.hypot(A, B)
    ratio = k / rho if rho > 0.0 else np.full(np.shape(L), np.inf)
    phi = np.arccos(np.clip(ratio, -1.0, 1.0))
    base = math.atan2(B, A)
    return np.stack([base + phi, base - phi], axis=-1), np.abs(ratio) <= 1.0 + 1e-12


def solve(arm: SRSArm, T: np.ndarray, psi: np.ndarray, r: np.ndarray, limits: bool = True):
    """Every branch at each (pose T (4, 4), ψ (N,)): (N, 8, 7) wrapped angles, (N, 8) inside.

    With ``limits`` False the flags say only that the branch exists (its subproblems
    have solutions), inside the limits or not.
    """
    H, P, S = arm.H, arm.P, arm.S
    N = len(psi)
    T = np.broadcast_to(T, (N, 4, 4))
    Q = np.zeros((N, 8, 7))
    ok = np.zeros((N, 8), dtype=bool)
    tiny = 1e-12 * arm.scale
    local = arm.M[:3, :3].T @ (arm.W0 - arm.M[:3, 3])
    d = T[:, :3, 3] + np.einsum("...ij,j->...i", T[:, :3, :3], local) - S
    L = np.linalg.norm(d, axis=1)
    e = d / np.maximum(L, tiny)[:, None]
    rp = r - (e @ r)[:, None] * e
    nr = np.linalg.norm(rp, axis=1)
    er = np.where((nr > 0.0)[:, None], rp / np.maximum(nr, 1e-300)[:, None], perpendicular(e))
    c_dir = np.cos(psi)[:, None] * er + np.sin(psi)[:, None] * _cross(e, er)
    Rw = T[:, :3, :3] @ arm.M[:3, :3].T
    q4s, ok4 = _elbow(arm, L)
    ok4 &= L > tiny
    u, b = arm.W0 - P[3], arm.E0 - S
    x3, x7 = perpendicular(H[2]), perpendicular(H[6])
    for i4 in range(2):
        R4 = _rot(H[3], q4s[:, i4])
        a = P[3] + R4 @ u - S
        a_hat = a / np.maximum(L, tiny)[:, None]
        b_perp = b - (a_hat @ b)[:, None] * a_hat
        nb = np.linalg.norm(b_perp, axis=1)
        line = nb < tiny
        cd = np.where(line[:, None], er, c_dir)
        bp = np.where(line[:, None], perpendicular(a_hat),
                      b_perp / np.maximum(nb, 1e-300)[:, None])
        F1 = np.stack([a_hat, bp, _cross(a_hat, bp)], axis=2)
        F2 = np.stack([e, cd, _cross(e, cd)], axis=2)
        R123 = F2 @ np.swapaxes(F1, -1, -2)
        t1, t2, ok_s = _sp2(H[0], H[1], H[2], R123 @ H[2])
        X = np.swapaxes(R123 @ R4, -1, -2) @ Rw
        t5, t6, ok_w = _sp2(H[4], H[5], H[6], X @ H[6])
        for i_s in range(2):
            R3 = np.swapaxes(_rot(H[0], t1[:, i_s]) @ _rot(H[1], t2[:, i_s]), -1, -2) @ R123
            q3 = _sp1(H[2], np.broadcast_to(x3, (N, 3)), R3 @ x3)
            for i_w in range(2):
                R7 = np.swapaxes(_rot(H[4], t5[:, i_w]) @ _rot(H[5], t6[:, i_w]), -1, -2) @ X
                q7 = _sp1(H[6], np.broadcast_to(x7, (N, 3)), R7 @ x7)
                j = 4 * i4 + 2 * i_s + i_w
                Q[:, j] = np.stack([t1[:, i_s], t2[:, i_s], q3, q4s[:, i4],
                                    t5[:, i_w], t6[:, i_w], q7], axis=1)
                ok[:, j] = ok4 & ok_s & ok_w
    Qw = Q - 2 * np.pi * np.round((Q - arm.mid) / (2 * np.pi))
    inside = np.all((Qw >= arm.lo - LIMIT_TOL) & (Qw <= arm.hi + LIMIT_TOL), axis=-1)
    return Qw, (ok & inside) if limits else ok


def intervals(arm: SRSArm, T: np.ndarray, r: np.ndarray, step: float = math.radians(0.5),
              steps: int = 40) -> dict[int, list[tuple[float, float]]]:
    """The feasible ψ of each branch by a grid and bisection (the search the closed form replaced).

    Every branch is evaluated by the compiled closed form (``_solve``) on a grid of ψ over
    [−π, π] of the given step [rad]; each change between neighbours is bisected ``steps``
    times onto its feasible side. Stretches narrower than the step can be missed.
    """
    from serialkin.ik.analytic.arm_angle import _solve

    n = int(math.ceil(2 * math.pi / step))
    grid = -math.pi + 2 * math.pi * np.arange(n + 1) / n
    ok = _solve(arm, T, grid, r)[1]
    out: dict[int, list[tuple[float, float]]] = {}
    for j in range(8):
        f = ok[:, j]
        edges = np.flatnonzero(f[1:] != f[:-1])
        bad = np.where(f[edges], grid[edges + 1], grid[edges])
        good = np.where(f[edges], grid[edges], grid[edges + 1])
        for _ in range(steps):
            mid = 0.5 * (bad + good)
            inside = _solve(arm, T, mid, r)[1][:, j] if len(mid) else np.zeros(0, bool)
            good = np.where(inside, mid, good)
            bad = np.where(inside, bad, mid)
        ends = dict(zip(edges.tolist(), good.tolist()))
        starts = ([-math.pi] if f[0] else []) + [ends[i] for i in edges if not f[i]]
        stops = [ends[i] for i in edges if f[i]] + ([math.pi] if f[-1] else [])
        if starts:
            out[j] = list(zip(starts, stops))
    return out
