"""Compiled rotation-log and pose-error kernels (numba, ``cache=True``).

Kernel contract: trusts its input; validation happens at the public boundary. Other
subpackages call these kernels directly from their compiled code.

These are scalar kernels meant to be called from other njit code (IK iterations,
trajectory tracking loops) and, through the thin batch loops below, from the numpy
wrappers in :mod:`serialkin.spatial.pose` and :mod:`serialkin.spatial.lie`. They are the
only implementation of the SO(3) logarithm and of the pose error in serialkin.

Kernels trust their input: arrays are float64, of the documented shapes, finite, and
rotation blocks are (close to) orthonormal. Validation happens in the Python wrappers.

The pose error (used by every IK solver) is the 6-vector, world frame, order [v; ω]::

    e = [p_target − p ;  ω],   ω = log(R_target · Rᵀ)^∨

so that for a small displacement ``T_target ≈ (I + [dω]^, dv) · T`` the error is the
small twist ``[dv; dω]`` and ``e ≈ J(q) dq`` with the geometric Jacobian (eqs 33-36).
"""

from __future__ import annotations

import math

from .._jit import as_readonly, njit

#: Below this rotation angle [rad] θ/sin θ is replaced by its series 1 + θ²/6 + 7θ⁴/360.
SMALL_ANGLE = 1e-3
#: Below this value of cos θ (θ > ~2.69 rad) the rotation axis is read from the symmetric
#: part of R, which stays well conditioned up to and at θ = π (the antisymmetric part
#: vanishes there).
NEAR_PI_COS = -0.9


@njit(cache=True)
def wrap_pi(x):
    """The angle ``x`` [rad] wrapped to (−π, π]: ``((x + π) mod 2π) − π``, −π sent to π.

    The compiled scalar form of :func:`serialkin.spatial.wrap_angle` (same formula, same
    results).
    """
    w = (x + math.pi) % (2.0 * math.pi) - math.pi
    return math.pi if w == -math.pi else w


@njit(cache=True)
def _so3_log_parts(r00, r01, r02, r10, r11, r12, r20, r21, r22):
    """Rotation vector ω = θ·a of a rotation matrix given by its 9 entries (row major).

    θ = atan2(|vee(R − Rᵀ)|/2, (tr R − 1)/2) ∈ [0, π] is accurate at both ends (unlike
    acos). Away from π, ω = θ / (2 sin θ) · vee(R − Rᵀ) (series near 0). Near π the axis
    comes from the symmetric part (R + Rᵀ)/2 = cos θ I + (1 − cos θ) a aᵀ, using the
    largest diagonal entry, with the sign that agrees with vee(R − Rᵀ) = 2 sin θ a.
    """
    vx = r21 - r12
    vy = r02 - r20
    vz = r10 - r01
    c = 0.5 * (r00 + r11 + r22 - 1.0)
    s = 0.5 * math.sqrt(vx * vx + vy * vy + vz * vz)
    theta = math.atan2(s, c)
    if c > NEAR_PI_COS:
        if theta < SMALL_ANGLE:
            t2 = theta * theta
            k = 0.5 * (1.0 + t2 / 6.0 + 7.0 * t2 * t2 / 360.0)
        else:
            k = 0.5 * theta / s
        return k * vx, k * vy, k * vz
    # near π: a_i² = (R_ii − c) / (1 − c), a_i a_j = (R_ij + R_ji) / (2 (1 − c))
    omc = 1.0 - c
    if r00 >= r11 and r00 >= r22:
        ax = math.sqrt(max(0.0, (r00 - c) / omc))
        ay = (r01 + r10) / (2.0 * omc * ax)
        az = (r02 + r20) / (2.0 * omc * ax)
    elif r11 >= r22:
        ay = math.sqrt(max(0.0, (r11 - c) / omc))
        ax = (r01 + r10) / (2.0 * omc * ay)
        az = (r12 + r21) / (2.0 * omc * ay)
    else:
        az = math.sqrt(max(0.0, (r22 - c) / omc))
        ax = (r02 + r20) / (2.0 * omc * az)
        ay = (r12 + r21) / (2.0 * omc * az)
    norm = math.sqrt(ax * ax + ay * ay + az * az)
    if ax * vx + ay * vy + az * vz < 0.0:
        norm = -norm
    k = theta / norm
    return k * ax, k * ay, k * az


@njit(cache=True)
def so3_log_into(R, w):
    """SO(3) logarithm: rotation vector ``w`` (3,) [rad] of the rotation ``R`` (3, 3).

    ``R = exp([w]^)`` with ``|w| = θ ∈ [0, π]``; at θ = π either of the two opposite
    vectors may be returned. Accurate (to ~1e-15 relative) over the whole range,
    including θ → 0 and θ → π.
    """
    wx, wy, wz = _so3_log_parts(
        R[0, 0], R[0, 1], R[0, 2], R[1, 0], R[1, 1], R[1, 2], R[2, 0], R[2, 1], R[2, 2]
    )
    w[0] = wx
    w[1] = wy
    w[2] = wz


@njit(cache=True)
def _rotation_error_parts(A, B):
    """log(A · Bᵀ)^∨ for the upper-left 3x3 blocks of A and B (any 2-D arrays ≥ 3x3).

    Both read-only (C-contiguous float64): the one type every caller passes.
    """
    m00 = A[0, 0] * B[0, 0] + A[0, 1] * B[0, 1] + A[0, 2] * B[0, 2]
    m01 = A[0, 0] * B[1, 0] + A[0, 1] * B[1, 1] + A[0, 2] * B[1, 2]
    m02 = A[0, 0] * B[2, 0] + A[0, 1] * B[2, 1] + A[0, 2] * B[2, 2]
    m10 = A[1, 0] * B[0, 0] + A[1, 1] * B[0, 1] + A[1, 2] * B[0, 2]
    m11 = A[1, 0] * B[1, 0] + A[1, 1] * B[1, 1] + A[1, 2] * B[1, 2]
    m12 = A[1, 0] * B[2, 0] + A[1, 1] * B[2, 1] + A[1, 2] * B[2, 2]
    m20 = A[2, 0] * B[0, 0] + A[2, 1] * B[0, 1] + A[2, 2] * B[0, 2]
    m21 = A[2, 0] * B[1, 0] + A[2, 1] * B[1, 1] + A[2, 2] * B[1, 2]
    m22 = A[2, 0] * B[2, 0] + A[2, 1] * B[2, 1] + A[2, 2] * B[2, 2]
    return _so3_log_parts(m00, m01, m02, m10, m11, m12, m20, m21, m22)


@njit(cache=True)
def rotation_error_into(R, R_target, w):
    """Orientation error ``w = log(R_target · Rᵀ)^∨`` (3,) [rad], world frame.

    ``R`` and ``R_target`` may be (3, 3) rotations or (4, 4) transforms (only their
    rotation blocks are read), both read-only. No temporary arrays are allocated.
    """
    wx, wy, wz = _rotation_error_parts(R_target, R)
    w[0] = wx
    w[1] = wy
    w[2] = wz


@njit(cache=True)
def pose_error_into(T, T_target, e):
    """Pose error ``e = [p_target − p; log(R_target · Rᵀ)^∨]`` (6,), world frame, [m; rad].

    Args:
        T: current pose (4, 4), e.g. the end-effector from ``fk_into``.
        T_target: desired pose (4, 4).
        e: output (6,), order [v; ω] like the geometric Jacobian's rows.

    For a small displacement the error equals the small twist that moves ``T`` onto
    ``T_target`` (position part: the translation; rotation part: ``R_target = exp(ω) R``),
    so a Newton / Levenberg-Marquardt step solves ``J dq = e``. Allocation free.

    Argument types (one compiled specialization): ``T`` the writeable array the caller
    computed the pose into, ``T_target`` read-only (a caller holding a target in a
    writeable array passes ``as_readonly(T_target)``), ``e`` writeable.
    """
    e[0] = T_target[0, 3] - T[0, 3]
    e[1] = T_target[1, 3] - T[1, 3]
    e[2] = T_target[2, 3] - T[2, 3]
    wx, wy, wz = _rotation_error_parts(T_target, as_readonly(T))
    e[3] = wx
    e[4] = wy
    e[5] = wz


@njit(cache=True)
def so3_log_batch(R, W):
    """Rotation vectors ``W`` (N, 3) of the rotations ``R`` (N, 3, 3)."""
    for k in range(R.shape[0]):
        so3_log_into(R[k], W[k])


@njit(cache=True)
def pose_error_batch(T, T_target, E):
    """Pose errors ``E`` (N, 6) between ``T`` (N, 4, 4) and ``T_target`` (N, 4, 4).

    :func:`pose_error_into`'s formula, written out: here both poses are read-only input
    (:func:`serialkin.spatial.pose.pose_error`), where pose_error_into reads a pose its
    caller computed into a writeable array.
    """
    for k in range(T.shape[0]):
        A = T[k]
        B = T_target[k]
        E[k, 0] = B[0, 3] - A[0, 3]
        E[k, 1] = B[1, 3] - A[1, 3]
        E[k, 2] = B[2, 3] - A[2, 3]
        wx, wy, wz = _rotation_error_parts(B, A)
        E[k, 3] = wx
        E[k, 4] = wy
        E[k, 5] = wz


@njit(cache=True)
def transforms_valid(T, tol):
    """True when every ``T[k]`` of ``T`` (N, 4, 4) is a finite rigid transform.

    Same criteria as :func:`serialkin._checks.check_transform` (last row [0, 0, 0, 1],
    max |RᵀR − I| ≤ tol, |det R − 1| ≤ tol), without allocation; the Python wrapper
    calls ``check_transform`` only when this fails, to build the error message.
    """
    for k in range(T.shape[0]):
        A = T[k]
        for i in range(4):
            for j in range(4):
                if not math.isfinite(A[i, j]):
                    return False
        if (abs(A[3, 0]) > tol or abs(A[3, 1]) > tol or abs(A[3, 2]) > tol
                or abs(A[3, 3] - 1.0) > tol):
            return False
        for i in range(3):
            for j in range(3):
                s = A[0, i] * A[0, j] + A[1, i] * A[1, j] + A[2, i] * A[2, j]
                if abs(s - (1.0 if i == j else 0.0)) > tol:
                    return False
        det = (A[0, 0] * (A[1, 1] * A[2, 2] - A[1, 2] * A[2, 1])
               - A[0, 1] * (A[1, 0] * A[2, 2] - A[1, 2] * A[2, 0])
               + A[0, 2] * (A[1, 0] * A[2, 1] - A[1, 1] * A[2, 0]))
        if abs(det - 1.0) > tol:
            return False
    return True
