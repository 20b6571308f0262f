"""Cyclic coordinate descent (CCD), chapter section 5.3 (Wang & Chen 1991).

CCD sweeps the joints from the last one to the first and, for each joint in turn, moves
it to the value that best brings the end-effector onto the target *with every other
joint held fixed*. Each one-joint problem has a closed-form optimum, so an iteration
(one sweep) costs one Jacobian evaluation plus O(n) arithmetic: cheap, robust far from
the target, slow (linear) close to it.

One-joint optimum. A revolute joint i turns everything after it by an angle φ about its
world axis ``z`` through a point ``a`` on the axis. Writing ``v = p − a`` (end-effector
from the axis), ``d = p_target − a``, ``u_j`` / ``u_j*`` the columns of the current and
target end-effector rotations, the weighted cost

    C(φ) = w_p |d − R(φ) v|² + w_o Σ_j |u_j* − R(φ) u_j|²

is, with Rodrigues' formula ``R(φ) x = x cos φ + (z × x) sin φ + (z·x) z (1 − cos φ)``,
``C = const − 2 [k1 (1 − cos φ) + k2 cos φ + k3 sin φ]`` where

    k1 = w_p (d·z)(v·z) + w_o Σ_j (u_j*·z)(u_j·z)
    k2 = w_p  d·v       + w_o Σ_j  u_j*·u_j
    k3 = w_p z·(v × d)  + w_o Σ_j z·(u_j × u_j*)

so the minimiser is ``φ* = atan2(k3, k2 − k1)`` and C is a pure sinusoid of φ around it.
A prismatic joint slides the end-effector by δ along its axis ``z``; the optimum is
``δ* = z·d_p / (z·z)`` over the selected position coordinates (orientation does not
depend on δ).

Implementation notes:

* One call of :func:`serialkin.kinematics.kernels.jacobian_into` per sweep gives every
  joint axis (``z_i`` in the Jacobian's angular rows, or its linear rows for prismatic
  joints) and, through ``v_i × z_i = (p − o_i)⊥``, a point on each axis. Going from the
  last joint to the first, the axes still to be visited do not move, so the end-effector
  pose is updated in closed form (a rotation about / translation along the axis) and no
  second forward kinematics is needed.
* Joint limits: the new value is clamped to ``[q_min, q_max]``. Because C is a sinusoid
  in φ, the best admissible angle is φ* itself (or φ* ± 2π) when it lies in the range,
  otherwise the nearer end of the range on the circle: the clamped step is still the
  exact one-joint optimum under the limits.
* Masks: position coordinates that are not selected are replaced, at every joint step,
  by the current end-effector coordinates (so they exert no pull). This is exact when all
  three or none are selected and for planar arms with an (x, y) target; for other partial
  position masks it is a heuristic whose fixed points still have zero selected error.
  Orientation: when any orientation coordinate is selected, the whole target orientation
  is matched with weight ``w_o`` (exact for planar arms with (x, y, φ) targets, where the
  unselected rows vanish identically).
* Units: ``w_p`` is dimensionless, ``w_o`` is in m² (it trades metres against the
  dimensionless axis mismatch); the default is ``(0.1 · L)²`` with L the robot's
  characteristic length (sum of its link offsets), so that both terms have comparable
  scales.

Documented tolerance: CCD converges linearly, so it reaches position tolerances of
1e-6 m on position targets in tens to a few hundred sweeps; on full 6-D pose targets it
is slow and may stop on stagnation before 1e-6 (then ``success`` is False and the shared
loop restarts it from a random configuration). Near singular configurations (a target at
the boundary of the workspace, which only the stretched arm reaches) convergence becomes
sublinear and the stagnation test typically stops at millimetre accuracy; the attempt
then reports failure with its best configuration.
"""

from __future__ import annotations

import math

import numpy as np

from serialkin.ik._kernels import MAX_ITER, RUNNING, TWO_PI, stopping_test
from serialkin.kinematics.kernels import PRISMATIC, jacobian_into

from .._jit import njit


@njit(cache=True)
def _clamp_angle_step(phi, qi, lo, hi):
    """Best admissible rotation step for a joint at ``qi`` with limits [lo, hi].

    ``phi`` ∈ (−π, π] is the unconstrained optimum of a cost that is a sinusoid in the
    step, so the constrained optimum is φ (shifted by a multiple of 2π) when that lies in
    [lo − qi, hi − qi], else the end of that interval nearer to φ on the circle.
    """
    a = lo - qi
    b = hi - qi
    if a <= phi <= b:
        return phi
    if a <= phi - TWO_PI <= b:
        return phi - TWO_PI
    if a <= phi + TWO_PI <= b:
        return phi + TWO_PI
    # outside: pick the end with the larger cos(step - phi) (the nearer one on the circle)
    if math.cos(a - phi) >= math.cos(b - phi):
        return a
    return b


@njit(cache=True)
def _axis_point(J, i, px, py, pz):
    """A point on the axis of revolute joint ``i``, from the Jacobian ``J`` (6, n) at ``p``.

    With ``z = J[3:, i]`` (unit) and ``v = J[:3, i] = z × (p − o)`` for any point o of the
    axis, ``v × z`` is the component of ``p − o`` normal to the axis, so
    ``p − v × z`` (returned as three floats) is the foot of the perpendicular from ``p``,
    the end-effector point at which J was evaluated, onto the axis.
    """
    vx = J[0, i]
    vy = J[1, i]
    vz = J[2, i]
    zx = J[3, i]
    zy = J[4, i]
    zz = J[5, i]
    return (px - (vy * zz - vz * zy), py - (vz * zx - vx * zz), pz - (vx * zy - vy * zx))


@njit(cache=True)
def _pair_terms(w, zx, zy, zz, vx, vy, vz, dx, dy, dz):
    """One vector pair's weighted share of (k1, k2, k3) in the one-joint cost (module doc).

    ``v`` is a vector the joint turns about the unit axis ``z`` and ``d`` where it should
    go: returns ``(w (d·z)(v·z), w d·v, w z·(v × d))``.
    """
    return (w * (dx * zx + dy * zy + dz * zz) * (vx * zx + vy * zy + vz * zz),
            w * (dx * vx + dy * vy + dz * vz),
            w * (zx * (vy * dz - vz * dy) + zy * (vz * dx - vx * dz) + zz * (vx * dy - vy * dx)))


@njit(cache=True)
def ccd_sweep(q, F, meta, T_target, pos_sel, w_pos, w_orient, lo, hi, J, T):
    """One CCD sweep (last joint to first), in place on ``q`` (n,) and the pose ``T`` (4, 4).

    Args:
        q: joint values (n,), updated in place.
        F: (n+1, 4, 4) chain fixed transforms (see :mod:`serialkin.kinematics.kernels`).
        meta: (n, 5) chain joint data.
        T_target: target pose (4, 4).
        pos_sel: (3,) 1.0 where the position coordinate is selected, else 0.0.
        w_pos: weight of the position term (0 when no position coordinate is selected).
        w_orient: weight of the orientation term [m²] (0: position only).
        lo: (n,) lower joint limits (-inf allowed).
        hi: (n,) upper joint limits (inf allowed).
        J: (6, n) work array.
        T: (4, 4) receives the end-effector pose after the sweep.
    """
    # One piece over 80 lines: each joint's exact update reads the pose the previous joint's
    # update wrote; split into compiled calls it would add levels that each re-link and
    # re-optimise their callees (docs/compile-time.md).
    n = q.shape[0]
    jacobian_into(q, F, meta, J, T)
    p0x = T[0, 3]
    p0y = T[1, 3]
    p0z = T[2, 3]
    for i in range(n - 1, -1, -1):
        px = T[0, 3]
        py = T[1, 3]
        pz = T[2, 3]
        # effective target: unselected coordinates follow the end-effector
        tx = T_target[0, 3] if pos_sel[0] > 0.0 else px
        ty = T_target[1, 3] if pos_sel[1] > 0.0 else py
        tz = T_target[2, 3] if pos_sel[2] > 0.0 else pz
        if meta[i, 3] == PRISMATIC:
            zx = J[0, i]
            zy = J[1, i]
            zz = J[2, i]
            den = zx * zx * pos_sel[0] + zy * zy * pos_sel[1] + zz * zz * pos_sel[2]
            if den < 1e-12 or w_pos == 0.0:
                continue
            step = ((tx - px) * zx + (ty - py) * zy + (tz - pz) * zz) / den
            new = min(max(q[i] + step, lo[i]), hi[i])
            step = new - q[i]
            q[i] = new
            T[0, 3] += step * zx
            T[1, 3] += step * zy
            T[2, 3] += step * zz
            continue
        zx = J[3, i]
        zy = J[4, i]
        zz = J[5, i]
        # point a on the axis, from the Jacobian at the start of the sweep (pose p0)
        ax, ay, az = _axis_point(J, i, p0x, p0y, p0z)
        k1 = 0.0
        k2 = 0.0
        k3 = 0.0
        if w_pos > 0.0:  # v = p − a moves to d = p_target − a
            a1, a2, a3 = _pair_terms(w_pos, zx, zy, zz, px - ax, py - ay, pz - az,
                                     tx - ax, ty - ay, tz - az)
            k1 += a1
            k2 += a2
            k3 += a3
        if w_orient > 0.0:  # each column u_j of R moves to that of R_target
            for j in range(3):
                a1, a2, a3 = _pair_terms(w_orient, zx, zy, zz, T[0, j], T[1, j], T[2, j],
                                         T_target[0, j], T_target[1, j], T_target[2, j])
                k1 += a1
                k2 += a2
                k3 += a3
        c0 = k2 - k1
        if c0 == 0.0 and k3 == 0.0:
            continue
        phi = math.atan2(k3, c0)
        phi = _clamp_angle_step(phi, q[i], lo[i], hi[i])
        if phi == 0.0:
            continue
        q[i] += phi
        # rotate the end-effector pose about the axis (z through a) by phi (Rodrigues)
        c = math.cos(phi)
        s = math.sin(phi)
        v1 = 1.0 - c
        for col in range(4):
            if col < 3:
                x = T[0, col]
                y = T[1, col]
                w = T[2, col]
            else:
                x = T[0, 3] - ax
                y = T[1, 3] - ay
                w = T[2, 3] - az
            dot = (x * zx + y * zy + w * zz) * v1
            rx = x * c + (zy * w - zz * y) * s + dot * zx
            ry = y * c + (zz * x - zx * w) * s + dot * zy
            rw = w * c + (zx * y - zy * x) * s + dot * zz
            if col < 3:
                T[0, col] = rx
                T[1, col] = ry
                T[2, col] = rw
            else:
                T[0, 3] = ax + rx
                T[1, 3] = ay + ry
                T[2, 3] = az + rw


@njit(cache=True)
def ccd_attempt(q, F, meta, T_target, mask, w_orient, lo, hi, tol_pos, tol_orient,
                max_iter, window, min_progress):
    """One CCD attempt from ``q`` (updated in place): sweeps until converged or stopped.

    Args:
        q: (n,) start configuration (inside the limits), overwritten with the result.
        F: (n+1, 4, 4) chain fixed transforms.
        meta: (n, 5) chain joint data.
        T_target: (4, 4) target pose.
        mask: (6,) weights of [vx vy vz wx wy wz]; > 0 means selected.
        w_orient: orientation weight [m²] (used only when an orientation row is selected).
        lo: (n,) lower joint limits.
        hi: (n,) upper joint limits.
        tol_pos: tolerance on the selected position error norm [m].
        tol_orient: tolerance on the selected orientation error norm [rad].
        max_iter: sweep budget.
        window: stagnation window in sweeps.
        min_progress: the attempt stops as stagnated when the scaled error
            ``e_p/tol_p + e_o/tol_o`` did not drop by this fraction over ``window`` sweeps
            (:func:`serialkin.ik._kernels.stopping_test`).

    Returns:
        (sweeps used, status) with status CONVERGED, MAX_ITER or STAGNATED (codes of
        :mod:`serialkin.ik._kernels`); ``q`` holds the final configuration.
    """
    n = q.shape[0]
    J = np.empty((6, n))
    T = np.empty((4, 4))
    e = np.empty(6)
    sel = np.empty(6)
    for k in range(6):
        sel[k] = 1.0 if mask[k] > 0.0 else 0.0
    pos_sel = sel[:3].copy()
    w_pos = 1.0 if pos_sel.sum() > 0.0 else 0.0
    w_o = w_orient if sel[3] + sel[4] + sel[5] > 0.0 else 0.0
    ref = np.inf
    for it in range(1, max_iter + 1):
        ccd_sweep(q, F, meta, T_target, pos_sel, w_pos, w_o, lo, hi, J, T)
        status, ref = stopping_test(T, T_target, mask, tol_pos, tol_orient, it, window,
                                    min_progress, ref, e)
        if status != RUNNING:
            return it, status
    return max_iter, MAX_ITER
