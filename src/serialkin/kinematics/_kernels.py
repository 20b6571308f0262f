"""Compiled kernels over the chain representation (numba, ``cache=True``).

Every robot, whatever convention it was described in (standard DH, modified DH,
general joint axes, URDF), is compiled by :mod:`serialkin.model.chain` into the same
arrays, and these kernels are the only implementation of forward kinematics and
Jacobians in serialkin. IK solvers, redundancy resolution and workspace sampling call
them too.

The chain arrays, for a robot with ``n`` joints:

``F`` (n+1, 4, 4)
    Fixed transforms between joint motions: the end-effector pose is
    ``T = F[0] · M_1(q_1) · F[1] · M_2(q_2) · ... · M_n(q_n) · F[n]`` (eq 11), where
    ``F[0]`` includes the base transform and ``F[n]`` the tool transform.
``L`` (n+1, 4, 4)
    Link-frame offsets: frame 0 is ``L[0]`` (the base), link frame *i* is the pose right
    after ``M_i`` times ``L[i]``. For a standard-DH robot these are the DH frames.
``meta`` (n, 5)
    Per joint: unit axis (x, y, z) in the joint frame — always (0, 0, 1), because
    :func:`~serialkin.model.chain.compile_chain` turns every axis onto z —, type
    (0 revolute, 1 prismatic), offset added to the joint variable.

``M_i(q)`` is a rotation by ``q + offset`` about z (revolute) or a translation by
``q + offset`` along z (prismatic). Kernels trust their input: validation happens in
the Python wrappers. All arrays are float64, C-contiguous.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit, prange

REVOLUTE = 0
PRISMATIC = 1


@njit(cache=True, inline="always")
def _post_multiply(T, A):
    """T ← T · A for rigid transforms (last rows [0 0 0 1]), in place, no allocation."""
    for r in range(3):
        t0 = T[r, 0]
        t1 = T[r, 1]
        t2 = T[r, 2]
        T[r, 0] = t0 * A[0, 0] + t1 * A[1, 0] + t2 * A[2, 0]
        T[r, 1] = t0 * A[0, 1] + t1 * A[1, 1] + t2 * A[2, 1]
        T[r, 2] = t0 * A[0, 2] + t1 * A[1, 2] + t2 * A[2, 2]
        T[r, 3] += t0 * A[0, 3] + t1 * A[1, 3] + t2 * A[2, 3]


@njit(cache=True, inline="always")
def _apply_joint(T, meta_i, qi):
    """T ← T · M(q): rotation about / translation along the (compiled) z axis."""
    x = qi + meta_i[4]
    if meta_i[3] == PRISMATIC:
        for r in range(3):
            T[r, 3] += x * T[r, 2]
        return
    s, c = _sincos_scalar(x)
    for r in range(3):
        t0 = T[r, 0]
        t1 = T[r, 1]
        T[r, 0] = t0 * c + t1 * s
        T[r, 1] = t1 * c - t0 * s


@njit(cache=True, inline="always")
def _row_times(t0, t1, t2, t3, A):
    """One row [t0 t1 t2 t3] of a rigid transform times the rigid transform A."""
    return (t0 * A[0, 0] + t1 * A[1, 0] + t2 * A[2, 0],
            t0 * A[0, 1] + t1 * A[1, 1] + t2 * A[2, 1],
            t0 * A[0, 2] + t1 * A[1, 2] + t2 * A[2, 2],
            t0 * A[0, 3] + t1 * A[1, 3] + t2 * A[2, 3] + t3)


@njit(cache=True, inline="always")
def _chain_walk(q, F, meta, J, record):
    """Walk the chain holding the pose's 12 entries in registers; return them as a tuple.

    The joints' sin/cos are computed first (independent of the pose, so they pipeline).
    With ``record``, each joint's world axis z_i and origin o_i (its frame just before its
    motion) are stored in ``J[3:, i]`` and ``J[:3, i]`` (J (6, n)) on the way.
    """
    n = meta.shape[0]
    sc = np.empty((2, n))
    for i in range(n):
        sc[0, i], sc[1, i] = _sincos_scalar(q[i] + meta[i, 4])
    A = F[0]
    a0, a1, a2, a3 = A[0, 0], A[0, 1], A[0, 2], A[0, 3]
    b0, b1, b2, b3 = A[1, 0], A[1, 1], A[1, 2], A[1, 3]
    c0, c1, c2, c3 = A[2, 0], A[2, 1], A[2, 2], A[2, 3]
    for i in range(n):
        if record:
            J[0, i], J[1, i], J[2, i] = a3, b3, c3
            J[3, i], J[4, i], J[5, i] = a2, b2, c2
        if meta[i, 3] == PRISMATIC:
            x = q[i] + meta[i, 4]
            a3 += x * a2
            b3 += x * b2
            c3 += x * c2
        else:
            s = sc[0, i]
            c = sc[1, i]
            a0, a1 = a0 * c + a1 * s, a1 * c - a0 * s
            b0, b1 = b0 * c + b1 * s, b1 * c - b0 * s
            c0, c1 = c0 * c + c1 * s, c1 * c - c0 * s
        A = F[i + 1]
        a0, a1, a2, a3 = _row_times(a0, a1, a2, a3, A)
        b0, b1, b2, b3 = _row_times(b0, b1, b2, b3, A)
        c0, c1, c2, c3 = _row_times(c0, c1, c2, c3, A)
    return a0, a1, a2, a3, b0, b1, b2, b3, c0, c1, c2, c3


@njit(cache=True, inline="always")
def _store_pose(t, T):
    for k in range(12):
        T[k // 4, k % 4] = t[k]
    T[3, 0] = 0.0
    T[3, 1] = 0.0
    T[3, 2] = 0.0
    T[3, 3] = 1.0


@njit(cache=True)
def fk_into(q, F, meta, T):
    """End-effector pose (eq 11) into ``T`` (4, 4) for one configuration ``q`` (n,)."""
    _store_pose(_chain_walk(q, F, meta, T, False), T)


# --- sin/cos, and batches: blocks of configurations in structure-of-arrays form -----------
#
# libm's sin/cos are scalar calls (about 10 ns each) and dominate FK. Every kernel here
# evaluates them with a branch-free Taylor polynomial after Cody–Waite reduction by π/2
# (about 3x cheaper), which LLVM also vectorises across a block of configurations. π/2 is
# split into three parts (P1, P2 with 32 significant bits, so k·P1 and k·P2 are exact for
# |k| < 2^20); on |r| ≤ π/4 the truncated series (sin to r^15, cos to r^16) is accurate to
# a few 1e-17; the result agrees with libm to about 2 ulp (tested). Angles beyond
# |x| > 1e5 rad fall back to libm.

_BLOCK = 64
_TWO_OVER_PI = 0.6366197723675814
_P1 = 1.5707963267341256
_P2 = 6.077100506303966e-11
_P3 = 2.0222662487959506e-21


@njit(cache=True, inline="always")
def _sincos(x):
    """(sin x, cos x) for |x| ≤ 1e5, branch-free so loops over it vectorise (see above)."""
    kf = math.floor(x * _TWO_OVER_PI + 0.5)
    r = ((x - kf * _P1) - kf * _P2) - kf * _P3
    z = r * r
    sr = r + r * z * (-1.0 / 6.0 + z * (1.0 / 120.0 + z * (-1.0 / 5040.0 + z * (
        1.0 / 362880.0 + z * (-2.505210838544172e-08 + z * (
            1.6059043836821613e-10 + z * -7.647163731819816e-13))))))
    cr = 1.0 + z * (-0.5 + z * (1.0 / 24.0 + z * (-1.0 / 720.0 + z * (
        2.48015873015873e-05 + z * (-2.755731922398589e-07 + z * (
            2.08767569878681e-09 + z * (-1.1470745597729725e-11
                                        + z * 4.779477332387385e-14)))))))
    quadrant = kf - 4.0 * math.floor(kf * 0.25)  # 0, 1, 2, 3
    odd = quadrant == 1.0 or quadrant == 3.0
    sv = cr if odd else sr
    cv = sr if odd else cr
    sv = -sv if quadrant >= 2.0 else sv
    cv = -cv if (quadrant == 1.0 or quadrant == 2.0) else cv
    return sv, cv


@njit(cache=True, inline="always")
def _sincos_scalar(x):
    """(sin x, cos x): :func:`_sincos`, or libm beyond |x| > 1e5 rad."""
    if abs(x) > 1e5:
        return math.sin(x), math.cos(x)
    return _sincos(x)


@njit(cache=True)
def _fk_block(Q, F, meta, out, k0, B, T, X, c, s):
    """Poses of configurations ``Q[k0:k0+B]`` into ``out``.

    Scratch: T (12, _BLOCK) the poses' top rows, X (n, _BLOCK) the block's joint values
    joint-major (so every per-joint loop reads contiguous memory), c, s (_BLOCK,).
    """
    n = meta.shape[0]
    for b in range(B):
        for i in range(n):
            X[i, b] = Q[k0 + b, i] + meta[i, 4]
    for j in range(12):
        v = F[0, j // 4, j % 4]
        for b in range(B):
            T[j, b] = v
    for i in range(n):
        x = X[i]
        if meta[i, 3] == PRISMATIC:
            for r in range(3):
                for b in range(B):
                    T[4 * r + 3, b] += x[b] * T[4 * r + 2, b]
        else:
            big = False
            for b in range(B):
                s[b], c[b] = _sincos(x[b])
                big |= abs(x[b]) > 1e5
            if big:
                for b in range(B):
                    s[b] = math.sin(x[b])
                    c[b] = math.cos(x[b])
            for r in range(3):
                for b in range(B):
                    t0 = T[4 * r, b]
                    t1 = T[4 * r + 1, b]
                    T[4 * r, b] = t0 * c[b] + t1 * s[b]
                    T[4 * r + 1, b] = t1 * c[b] - t0 * s[b]
        A = F[i + 1]
        a00, a01, a02, a03 = A[0, 0], A[0, 1], A[0, 2], A[0, 3]
        a10, a11, a12, a13 = A[1, 0], A[1, 1], A[1, 2], A[1, 3]
        a20, a21, a22, a23 = A[2, 0], A[2, 1], A[2, 2], A[2, 3]
        for r in range(3):
            for b in range(B):
                t0 = T[4 * r, b]
                t1 = T[4 * r + 1, b]
                t2 = T[4 * r + 2, b]
                T[4 * r, b] = t0 * a00 + t1 * a10 + t2 * a20
                T[4 * r + 1, b] = t0 * a01 + t1 * a11 + t2 * a21
                T[4 * r + 2, b] = t0 * a02 + t1 * a12 + t2 * a22
                T[4 * r + 3, b] += t0 * a03 + t1 * a13 + t2 * a23
    for b in range(B):
        o = out[k0 + b]
        for j in range(12):
            o[j // 4, j % 4] = T[j, b]
        o[3, 0] = 0.0
        o[3, 1] = 0.0
        o[3, 2] = 0.0
        o[3, 3] = 1.0


@njit(cache=True, parallel=True)
def fk_batch(Q, F, meta, out):
    """End-effector poses for a batch ``Q`` (N, n) into ``out`` (N, 4, 4), across cores.

    Each thread takes a contiguous chunk and walks it in blocks of ``_BLOCK``
    configurations (structure of arrays, see :func:`_sincos`).
    """
    N = Q.shape[0]
    chunks = 32  # enough to balance any thread count numba uses here
    per = (N + chunks - 1) // chunks
    for ch in prange(chunks):
        T = np.empty((12, _BLOCK))
        X = np.empty((meta.shape[0], _BLOCK))
        c = np.empty(_BLOCK)
        s = np.empty(_BLOCK)
        k0 = ch * per
        end = min(N, k0 + per)
        while k0 < end:
            B = min(_BLOCK, end - k0)
            _fk_block(Q, F, meta, out, k0, B, T, X, c, s)
            k0 += B


@njit(cache=True)
def fk_batch_serial(Q, F, meta, out):
    """:func:`fk_batch` on one core: small batches, where starting threads costs more."""
    for k in range(Q.shape[0]):
        fk_into(Q[k], F, meta, out[k])


@njit(cache=True)
def fk_all_into(q, F, L, meta, out):
    """Every link frame 0..n (base to last link, without the tool) into ``out`` (n+1, 4, 4)."""
    n = meta.shape[0]
    T = F[0].copy()
    out[0, :, :] = L[0]
    for i in range(n):
        _apply_joint(T, meta[i], q[i])
        out[i + 1, :, :] = T
        _post_multiply(out[i + 1], L[i + 1])
        _post_multiply(T, F[i + 1])


@njit(cache=True, parallel=True)
def fk_all_batch(Q, F, L, meta, out):
    """Link frames for a batch ``Q`` (N, n) into ``out`` (N, n+1, 4, 4), across cores."""
    for k in prange(Q.shape[0]):
        fk_all_into(Q[k], F, L, meta, out[k])


@njit(cache=True, inline="always")
def _record_joint(J, j, T, meta_j):
    """Store joint j's world axis z_j in J[3:, j] and origin o_j in J[:3, j] (T: its frame)."""
    for r in range(3):
        J[3 + r, j] = T[r, 2]  # the joint axis is the frame's z axis
        J[r, j] = T[r, 3]


@njit(cache=True, inline="always")
def _finish_columns(J, meta, m, px, py, pz):
    """Turn the recorded (o_j, z_j) of the first m joints into Jacobian columns (eqs 35-36).

    Revolute: ``[z × (p − o); z]``; prismatic: ``[z; 0]``.
    """
    for j in range(m):
        zx = J[3, j]
        zy = J[4, j]
        zz = J[5, j]
        if meta[j, 3] == PRISMATIC:
            J[0, j] = zx
            J[1, j] = zy
            J[2, j] = zz
            J[3, j] = 0.0
            J[4, j] = 0.0
            J[5, j] = 0.0
        else:
            dx = px - J[0, j]
            dy = py - J[1, j]
            dz = pz - J[2, j]
            J[0, j] = zy * dz - zz * dy
            J[1, j] = zz * dx - zx * dz
            J[2, j] = zx * dy - zy * dx


@njit(cache=True)
def jacobian_into(q, F, meta, J, T):
    """Geometric Jacobian at the end-effector, base frame (eqs 33-36).

    Writes ``J`` (6, n), rows (vx, vy, vz, wx, wy, wz), and the end-effector pose ``T``
    (4, 4). Joint *i*'s axis and origin are those of its frame just before its motion
    (for standard DH, frame i-1: the chapter's z_{i-1}, p_{i-1}).
    """
    t = _chain_walk(q, F, meta, J, True)
    _store_pose(t, T)
    _finish_columns(J, meta, meta.shape[0], t[3], t[7], t[11])


@njit(cache=True)
def joint_axes_into(q, F, meta, P, W):
    """World origin ``P[i]`` (3,) and unit axis ``W[i]`` (3,) of every joint i at ``q``.

    These are the lines the joints turn about / slide along (the o_i, z_i of eqs 35-36),
    used by DH extraction and by closed-form structure recognition.
    """
    T = F[0].copy()
    for i in range(meta.shape[0]):
        for r in range(3):
            P[i, r] = T[r, 3]
            W[i, r] = T[r, 2]
        _apply_joint(T, meta[i], q[i])
        _post_multiply(T, F[i + 1])


@njit(cache=True, parallel=True)
def jacobian_batch(Q, F, meta, J, T):
    """Geometric Jacobians (N, 6, n) and poses (N, 4, 4) for a batch ``Q`` (N, n)."""
    for k in prange(Q.shape[0]):
        jacobian_into(Q[k], F, meta, J[k], T[k])


@njit(cache=True)
def jacobian_batch_serial(Q, F, meta, J, T):
    """:func:`jacobian_batch` on one core, for small batches."""
    for k in range(Q.shape[0]):
        jacobian_into(Q[k], F, meta, J[k], T[k])


@njit(cache=True)
def point_jacobian_into(q, F, L, meta, link, point, J, p_out):
    """Jacobian of a point fixed to link frame ``link`` (0..n), base frame.

    ``point`` (3,) is given in the link frame's coordinates. Columns of joints beyond
    ``link`` are zero (they do not move the point). Writes ``J`` (6, n) and the point's
    position in the base frame into ``p_out`` (3,). This is eq 56, J_s = ∂s/∂q, with the
    angular rows of the link.
    """
    J[:, :] = 0.0
    T = F[0].copy()
    W = L[0].copy()
    for i in range(link):
        _record_joint(J, i, T, meta[i])
        _apply_joint(T, meta[i], q[i])
        if i == link - 1:
            W[:, :] = T
            _post_multiply(W, L[i + 1])
        _post_multiply(T, F[i + 1])
    for r in range(3):
        p_out[r] = W[r, 0] * point[0] + W[r, 1] * point[1] + W[r, 2] * point[2] + W[r, 3]
    _finish_columns(J, meta, link, p_out[0], p_out[1], p_out[2])


@njit(cache=True, parallel=True)
def point_jacobian_batch(Q, F, L, meta, link, point, J, P):
    """Point Jacobians (N, 6, n) and point positions (N, 3) for a batch ``Q`` (N, n)."""
    for k in prange(Q.shape[0]):
        point_jacobian_into(Q[k], F, L, meta, link, point, J[k], P[k])


@njit(cache=True)
def all_finite(x):
    """True when every entry of the 1-D array ``x`` is finite (cheap check for the fast path)."""
    for i in range(x.shape[0]):
        if not math.isfinite(x[i]):
            return False
    return True


@njit(cache=True)
def fk_checked(q, F, meta, T):
    """Run :func:`fk_into` after a finiteness check of q; False (T untouched) on NaN/inf."""
    if not all_finite(q):
        return False
    fk_into(q, F, meta, T)
    return True


@njit(cache=True)
def jacobian_checked(q, F, meta, J, T):
    """:func:`jacobian_into` preceded by a finiteness check of q; returns False on NaN/inf."""
    if not all_finite(q):
        return False
    jacobian_into(q, F, meta, J, T)
    return True
