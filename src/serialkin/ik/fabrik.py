"""FABRIK, Forward And Backward Reaching Inverse Kinematics (Aristidou & Lasenby 2011).

Chapter section 5.3 cites FABRIK as a heuristic that works on joint *positions* instead
of joint angles: it moves the chain's points along straight lines so that every segment
keeps its length, alternately from the end-effector (forward reaching: the tip is put on
the target) and from the base (backward reaching: the root is put back on the base).

Domain (decided here, checked by :func:`fabrik_domain`):

* **Chains of revolute joints whose axes are all parallel** (planar arms such as the
  chapter's 2-, 3-, 6- and 20-link arms, in any plane). For them the points of the chain
  are the joint axes' intersections with the plane of motion, the segments between
  consecutive points are rigid, and each joint angle is exactly the change of direction
  between consecutive segments, so positions map to angles without loss.
* **Targets**: a position in the plane of motion ((x, y) planar targets, or a 3-D
  position/pose whose point lies in that plane). Orientation is supported only as a
  final-link constraint: when any orientation coordinate is selected, the heading of the
  last link about the common axis is fixed by the target first, the wrist point is put at
  ``p_target − (last segment)``, and FABRIK solves the rest of the chain for the wrist.
  Target rotations that are not reachable by such a chain (not a rotation about the
  common axis times the current rotation) simply leave an orientation error, and the
  solve reports failure.
* **Not supported**: prismatic joints and spatial chains (non-parallel axes). Those raise
  :class:`~serialkin.errors.NotSupportedError` naming the reason; use 'ccd', 'lm' or
  'bfgs' there. Spatial FABRIK with hinge constraints (re-projecting every point onto
  each hinge's plane) does not recover exact joint angles for general DH geometry
  (offsets between consecutive axes), so it is left out rather than approximated.

Joint limits are treated by clamping in the angle recovery: after each forward/backward
pass the new joint angles are read from the segment directions (relative to the current
ones, so no zero-configuration bookkeeping is needed), each step is clamped to the limits
(the admissible angle nearest on the circle), and the points are recomputed from the
clamped angles with the forward kinematics kernel before the next pass. Without active
limits this is exactly the original algorithm (angles and points stay consistent);
with active limits it is the usual "FABRIK with constraints" resynchronisation.

Unreachable targets: when the target lies farther from the base than the total chain
length, the chain is stretched straight towards it (the least-squares point), and the
attempt ends with ``success=False``.

Documented tolerance: position error below the requested tolerance (e.g. 1e-6 m);
FABRIK converges linearly, typically in 5-50 passes for reachable targets away from the
workspace boundary. Near the boundary (an almost stretched or almost folded arm, e.g. a
two-link arm within ~0.1 rad of θ2 = 0 or π) the passes shrink the error slowly and
restarts do not help (the difficulty is the target's); the stagnation test then ends
the attempt at ~1e-5-1e-4 m and the solve reports failure with its best configuration.
Segments of zero length (coincident axes) are handled: their joint keeps its angle and
the next joint takes the turn.
"""

from __future__ import annotations

import math

import numpy as np

from serialkin.errors import NotSupportedError
from serialkin.ik._kernels import MAX_ITER, RUNNING, stopping_test
from serialkin.ik.ccd import _axis_point, _clamp_angle_step
from serialkin.kinematics.kernels import fk_into, jacobian_into
from serialkin.spatial.kernels import wrap_pi

from .._jit import njit

#: Axis alignment tolerance (|z_i × z_0|) for "parallel joint axes".
PARALLEL_TOL = 1e-9
#: Segments shorter than this [m] are treated as zero length (coincident axes).
ZERO_LENGTH = 1e-12


def fabrik_domain(robot: object) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Check that FABRIK can model ``robot`` and return its plane of motion.

    Args:
        robot: a :class:`~serialkin.model.robot.Robot`.

    Returns:
        ``(a, e1, e2, sign)``: the common axis direction ``a`` (3,) (that of the first
        joint), an orthonormal basis ``e1, e2`` (3,) of the plane of motion with
        ``e1 × e2 = a``, and per joint the sign (+1/−1) of its axis along ``a``, (n,).

    Raises:
        NotSupportedError: a prismatic joint, or joint axes that are not all parallel.
    """
    types = tuple(robot.joint_types)  # type: ignore[attr-defined]
    if "P" in types:
        j = types.index("P")
        raise NotSupportedError(
            f"FABRIK needs a chain of revolute joints, but joint {j + 1} "
            f"({robot.joint_names[j]!r}) of robot {robot.name!r} is prismatic; "  # type: ignore[attr-defined]
            "use method 'ccd', 'lm' or 'bfgs'"
        )
    qs = robot.random_q(2, seed=0)  # type: ignore[attr-defined]
    J = robot.jacobian(qs)  # type: ignore[attr-defined]
    z = J[0, 3:, :].T  # (n, 3) world axes at the first sample
    a = z[0] / np.linalg.norm(z[0])
    for Jk in J:
        zk = Jk[3:, :].T
        cross = np.linalg.norm(np.cross(zk, a), axis=1)
        if np.any(cross > PARALLEL_TOL):
            j = int(np.argmax(cross > PARALLEL_TOL))
            raise NotSupportedError(
                f"FABRIK is implemented for chains of revolute joints with parallel axes "
                f"(planar arms); joint {j + 1} ({robot.joint_names[j]!r}) of robot "  # type: ignore[attr-defined]
                f"{robot.name!r} is not parallel to joint 1 (|z_{j + 1} × z_1| = "
                f"{cross[j]:.3g}); use method 'ccd', 'lm' or 'bfgs' for spatial chains"
            )
    sign = np.where(z @ a >= 0.0, 1.0, -1.0)
    helper = np.array([1.0, 0.0, 0.0]) if abs(a[0]) < 0.9 else np.array([0.0, 1.0, 0.0])
    e1 = helper - a * (helper @ a)
    e1 /= np.linalg.norm(e1)
    e2 = np.cross(a, e1)
    return a, e1, e2, sign


@njit(cache=True)
def _reach(P, a, b, x, y, length):
    """Place point ``b`` of ``P`` (m, 2) at ``length`` from point ``a`` towards ``(x, y)``.

    The FABRIK step ``P_b = (1 − λ) P_a + λ (x, y)`` with ``λ = length / |(x, y) − P_a|``;
    ``P_b = P_a`` when ``(x, y)`` is within ZERO_LENGTH of ``P_a`` (no direction).
    """
    r = math.sqrt((x - P[a, 0]) ** 2 + (y - P[a, 1]) ** 2)
    if r < ZERO_LENGTH:
        P[b, 0] = P[a, 0]
        P[b, 1] = P[a, 1]
        return
    lam = length / r
    P[b, 0] = (1.0 - lam) * P[a, 0] + lam * x
    P[b, 1] = (1.0 - lam) * P[a, 1] + lam * y


@njit(cache=True)
def fabrik_pass(q, F, meta, T_target, pos_sel, use_orient, a, e1, e2, sign, lo, hi,
                J, T, P, lengths, theta):
    """One FABRIK iteration (forward + backward reaching + angle recovery), in place on q.

    Args:
        q: (n,) joint angles, updated in place (clamped to [lo, hi]).
        F: (n+1, 4, 4) chain fixed transforms.
        meta: (n, 5) chain joint data.
        T_target: (4, 4) target pose.
        pos_sel: (3,) 1.0 for selected position coordinates (others follow the tool).
        use_orient: match the heading of the last link to the target's (final-link
            constraint).
        a: (3,) common joint axis direction.
        e1: (3,) first basis vector of the plane of motion.
        e2: (3,) second basis vector, ``e1 × e2 = a``.
        sign: (n,) +1/−1, each joint axis's sense along ``a``.
        lo: (n,) lower joint limits.
        hi: (n,) upper joint limits.
        J: (6, n) work array (Jacobian).
        T: (4, 4) work array (end-effector pose before the pass).
        P: (n+1, 2) work array (chain points in plane coordinates).
        lengths: (n,) work array (segment lengths).
        theta: (n,) work array (segment directions).

    Returns:
        True when the target was beyond the chain's reach (the chain was stretched).
    """
    # One piece over 80 lines: the forward and backward reaching and the angle recovery work on
    # the same point buffers in one pass; split into compiled calls it would add levels that
    # each re-link and re-optimise their callees (docs/compile-time.md).
    n = q.shape[0]
    jacobian_into(q, F, meta, J, T)
    px = T[0, 3]
    py = T[1, 3]
    pz = T[2, 3]
    # joint points in the plane: o_i = p − (v_i × z_i), v_i = z_i × (p − o_i)
    for i in range(n):
        ox, oy, oz = _axis_point(J, i, px, py, pz)
        P[i, 0] = ox * e1[0] + oy * e1[1] + oz * e1[2]
        P[i, 1] = ox * e2[0] + oy * e2[1] + oz * e2[2]
    P[n, 0] = px * e1[0] + py * e1[1] + pz * e1[2]
    P[n, 1] = px * e2[0] + py * e2[1] + pz * e2[2]
    total = 0.0
    for i in range(n):
        dx = P[i + 1, 0] - P[i, 0]
        dy = P[i + 1, 1] - P[i, 1]
        lengths[i] = math.sqrt(dx * dx + dy * dy)
        theta[i] = math.atan2(dy, dx)
        total += lengths[i]
    # target point (unselected coordinates follow the tool), in plane coordinates
    gx = T_target[0, 3] if pos_sel[0] > 0.0 else px
    gy = T_target[1, 3] if pos_sel[1] > 0.0 else py
    gz = T_target[2, 3] if pos_sel[2] > 0.0 else pz
    tx = gx * e1[0] + gy * e1[1] + gz * e1[2]
    ty = gx * e2[0] + gy * e2[1] + gz * e2[2]
    end = n  # index of the point FABRIK must put on its target
    last_dir = 0.0
    if use_orient:
        # heading change about a that best aligns R with R_target: R_rel = R_t Rᵀ,
        # sin part a·vee(R_rel − R_relᵀ)/2, cos part (tr R_rel − aᵀ R_rel a)/2
        tr = 0.0
        ara = 0.0
        vee0 = 0.0
        vee1 = 0.0
        vee2 = 0.0
        Rr = np.empty((3, 3))
        for r in range(3):
            for c in range(3):
                s = 0.0
                for k in range(3):
                    s += T_target[r, k] * T[c, k]
                Rr[r, c] = s
        for r in range(3):
            tr += Rr[r, r]
            for c in range(3):
                ara += a[r] * Rr[r, c] * a[c]
        vee0 = 0.5 * (Rr[2, 1] - Rr[1, 2])
        vee1 = 0.5 * (Rr[0, 2] - Rr[2, 0])
        vee2 = 0.5 * (Rr[1, 0] - Rr[0, 1])
        dpsi = math.atan2(a[0] * vee0 + a[1] * vee1 + a[2] * vee2, 0.5 * (tr - ara))
        last_dir = theta[n - 1] + dpsi
        # the wrist point is the target for the rest of the chain
        tx -= lengths[n - 1] * math.cos(last_dir)
        ty -= lengths[n - 1] * math.sin(last_dir)
        end = n - 1
        total -= lengths[n - 1]
    bx = P[0, 0]
    by = P[0, 1]
    dist = math.sqrt((tx - bx) ** 2 + (ty - by) ** 2)
    stretched = dist > total
    if end > 0:
        if stretched:
            # out of reach: stretch the chain straight towards the target
            for i in range(end):
                _reach(P, i, i + 1, tx, ty, lengths[i])
        else:
            # forward reaching: tip on the target, then towards the base
            P[end, 0] = tx
            P[end, 1] = ty
            for i in range(end - 1, -1, -1):
                _reach(P, i + 1, i, P[i, 0], P[i, 1], lengths[i])
            # backward reaching: root back on the base, then towards the tip
            P[0, 0] = bx
            P[0, 1] = by
            for i in range(end):
                _reach(P, i, i + 1, P[i + 1, 0], P[i + 1, 1], lengths[i])
    # angle recovery: q_i changes by sign_i · Δ(θ_i − θ_{i−1}) (θ_{−1} fixed)
    prev_old = 0.0
    prev_new = 0.0
    for i in range(n):
        old = theta[i]
        if use_orient and i == n - 1:
            new = last_dir
        elif i < end and lengths[i] > ZERO_LENGTH:
            new = math.atan2(P[i + 1, 1] - P[i, 1], P[i + 1, 0] - P[i, 0])
        else:
            new = prev_new + (old - prev_old)  # zero-length segment: keep its joint angle
        rel = wrap_pi((new - prev_new) - (old - prev_old))
        step = _clamp_angle_step(sign[i] * rel, q[i], lo[i], hi[i])
        q[i] += step
        # the clamped joint fixes this segment's actual direction for the next one
        prev_new = prev_new + (old - prev_old) + sign[i] * step
        prev_old = old
    return stretched


@njit(cache=True)
def fabrik_attempt(q, F, meta, T_target, mask, a, e1, e2, sign, lo, hi, tol_pos,
                   tol_orient, max_iter, window, min_progress):
    """One FABRIK attempt from ``q`` (updated in place), passes until converged or stopped.

    Args:
        q: (n,) start angles inside the limits; overwritten with the result.
        F: (n+1, 4, 4) chain fixed transforms.
        meta: (n, 5) chain joint data.
        T_target: (4, 4) target pose.
        mask: (6,) weights of [vx vy vz wx wy wz]; > 0 means selected.
        a: (3,) common axis, from :func:`fabrik_domain`.
        e1: (3,) plane basis vector, from :func:`fabrik_domain`.
        e2: (3,) plane basis vector, from :func:`fabrik_domain`.
        sign: (n,) axis senses, from :func:`fabrik_domain`.
        lo: (n,) lower joint limits.
        hi: (n,) upper joint limits.
        tol_pos: tolerance on the selected position error norm [m].
        tol_orient: tolerance on the selected orientation error norm [rad].
        max_iter: pass budget.
        window: stagnation window in passes.
        min_progress: minimal relative drop of the scaled error per window (see
            :func:`serialkin.ik.ccd.ccd_attempt`).

    Returns:
        (passes used, status) with status CONVERGED, MAX_ITER or STAGNATED (codes of
        :mod:`serialkin.ik._kernels`).
    """
    n = q.shape[0]
    J = np.empty((6, n))
    T = np.empty((4, 4))
    P = np.empty((n + 1, 2))
    lengths = np.empty(n)
    theta = np.empty(n)
    e = np.empty(6)
    sel = np.empty(6)
    for k in range(6):
        sel[k] = 1.0 if mask[k] > 0.0 else 0.0
    pos_sel = sel[:3].copy()
    use_orient = sel[3] + sel[4] + sel[5] > 0.0
    ref = np.inf
    for it in range(1, max_iter + 1):
        fabrik_pass(q, F, meta, T_target, pos_sel, use_orient, a, e1, e2, sign, lo, hi,
                    J, T, P, lengths, theta)
        fk_into(q, F, meta, T)
        status, ref = stopping_test(T, T_target, mask, tol_pos, tol_orient, it, window,
                                    min_progress, ref, e)
        if status != RUNNING:
            return it, status
    return max_iter, MAX_ITER
