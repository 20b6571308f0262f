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
    Per joint: unit axis (x, y, z) in the joint frame, type (0 revolute, 1 prismatic),
    offset added to the joint variable.

``M_i(q)`` is a rotation by ``q + offset`` about the axis (revolute) or a translation by
``q + offset`` along it (prismatic). Kernels trust their input: validation happens in
the Python wrappers. All arrays are float64, C-contiguous.
"""

from __future__ import annotations

import math

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
    """T ← T · M(q): rotation about / translation along the joint axis (Rodrigues)."""
    ax = meta_i[0]
    ay = meta_i[1]
    az = meta_i[2]
    x = qi + meta_i[4]
    if meta_i[3] == PRISMATIC:
        for r in range(3):
            T[r, 3] += x * (T[r, 0] * ax + T[r, 1] * ay + T[r, 2] * az)
        return
    c = math.cos(x)
    s = math.sin(x)
    if ax == 0.0 and ay == 0.0 and az == 1.0:  # z axis (every DH joint): only 2 columns change
        for r in range(3):
            t0 = T[r, 0]
            t1 = T[r, 1]
            T[r, 0] = t0 * c + t1 * s
            T[r, 1] = t1 * c - t0 * s
        return
    v = 1.0 - c
    r00 = c + ax * ax * v
    r01 = ax * ay * v - az * s
    r02 = ax * az * v + ay * s
    r10 = ay * ax * v + az * s
    r11 = c + ay * ay * v
    r12 = ay * az * v - ax * s
    r20 = az * ax * v - ay * s
    r21 = az * ay * v + ax * s
    r22 = c + az * az * v
    for r in range(3):
        t0 = T[r, 0]
        t1 = T[r, 1]
        t2 = T[r, 2]
        T[r, 0] = t0 * r00 + t1 * r10 + t2 * r20
        T[r, 1] = t0 * r01 + t1 * r11 + t2 * r21
        T[r, 2] = t0 * r02 + t1 * r12 + t2 * r22


@njit(cache=True)
def fk_into(q, F, meta, T):
    """End-effector pose (eq 11) into ``T`` (4, 4) for one configuration ``q`` (n,)."""
    n = meta.shape[0]
    T[:, :] = F[0]
    for i in range(n):
        _apply_joint(T, meta[i], q[i])
        _post_multiply(T, F[i + 1])


@njit(cache=True, parallel=True)
def fk_batch(Q, F, meta, out):
    """End-effector poses for a batch ``Q`` (N, n) into ``out`` (N, 4, 4), across cores."""
    for k in prange(Q.shape[0]):
        fk_into(Q[k], F, meta, out[k])


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
    ax = meta_j[0]
    ay = meta_j[1]
    az = meta_j[2]
    for r in range(3):
        J[3 + r, j] = T[r, 0] * ax + T[r, 1] * ay + T[r, 2] * az
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
    n = meta.shape[0]
    T[:, :] = F[0]
    for i in range(n):
        _record_joint(J, i, T, meta[i])
        _apply_joint(T, meta[i], q[i])
        _post_multiply(T, F[i + 1])
    _finish_columns(J, meta, n, T[0, 3], T[1, 3], T[2, 3])


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
