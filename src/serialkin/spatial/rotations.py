"""Orientation representations and their conversions to and from rotation matrices.

Conventions (chapter section 2; elementary rotations Rx, Ry, Rz are eqs 4-6):

* **Roll-pitch-yaw** ``rpy = (roll, pitch, yaw)`` [rad]:
  ``R = Rz(yaw) · Ry(pitch) · Rx(roll)`` (rotations about the fixed world axes x, then y,
  then z; equivalently intrinsic z-y'-x''). :func:`matrix_to_rpy` returns
  ``pitch ∈ [−π/2, π/2]``, ``roll, yaw ∈ (−π, π]``. At the gimbal lock (``cos pitch = 0``)
  only ``roll − yaw`` (pitch = +π/2) or ``roll + yaw`` (pitch = −π/2) is defined; yaw is
  set to 0 there.
* **ZYZ Euler angles** ``zyz = (phi, theta, psi)`` [rad]:
  ``R = Rz(phi) · Ry(theta) · Rz(psi)``. :func:`matrix_to_zyz` returns
  ``theta ∈ [0, π]``, ``phi, psi ∈ (−π, π]``; at ``sin theta = 0`` only ``phi ± psi`` is
  defined and phi is set to 0.
* **Axis-angle** ``(axis, angle)``: unit axis (3,) and angle [rad],
  ``R = exp(angle · [axis]^)`` (Rodrigues). :func:`matrix_to_axis_angle` returns
  ``angle ∈ [0, π]`` and, for the identity, the axis (0, 0, 1).
* **Unit quaternion** ``q = (w, x, y, z)`` (scalar first), ``w = cos(angle/2)``,
  ``(x, y, z) = sin(angle/2) · axis``. :func:`matrix_to_quaternion` returns ``w ≥ 0``
  (q and −q are the same rotation).

Non-unit input policy: :func:`axis_angle_to_matrix` and :func:`quaternion_to_matrix`
reject an axis / quaternion whose norm differs from 1 by more than ``UNIT_TOL`` with an
:class:`~serialkin.errors.InputError`, unless ``normalize=True`` is passed, in which case
any non-zero vector is scaled to unit norm (a zero vector is always an error).

Every conversion from a matrix is robust near its representation's singularity: the
angles are read with ``atan2`` after removing the first angle's rotation, so the round
trip ``R → angles → R`` is exact to rounding for every rotation, gimbal lock included.
All functions accept batches through leading dimensions.
"""

from __future__ import annotations

import numpy as np

from serialkin._checks import as_float_array, check_last_dims, check_rotation
from serialkin.errors import InputError
from serialkin.spatial.lie import so3_exp, so3_log
from serialkin.spatial.transforms import rotx, roty, rotz

#: Accepted deviation of an axis or quaternion norm from 1 (without ``normalize=True``).
UNIT_TOL = 1e-6
#: Below this value of |cos pitch| (rpy) or |sin theta| (ZYZ) the first angle is set to 0.
GIMBAL_TOL = 1e-14


def wrap_angle(angle: object) -> np.ndarray:
    """Wrap angle(s) [rad] to the interval (−π, π]. Shape preserved.

    ``((a + π) mod 2π) − π``, with −π sent to π; the compiled scalar form is
    :func:`serialkin.spatial.kernels.wrap_pi`. (Moving an angle by whole turns into a
    joint's limits is another idea: :func:`serialkin.model.limits.wrap_into`.)
    """
    a = as_float_array(angle, "angle")
    w = np.remainder(a + np.pi, 2.0 * np.pi) - np.pi
    return np.where(w == -np.pi, np.pi, w)


def perpendicular(e: np.ndarray) -> np.ndarray:
    """A unit vector perpendicular to each unit vector ``e`` (..., 3); deterministic.

    ``v = t − (t·e) e``, normalised, with ``t`` the world axis along which ``e`` has its
    smallest absolute component (so ``|v| ≥ √(2/3)``: never ill-conditioned). Trusted
    input: finite unit vectors. Returns (..., 3).
    """
    t = np.eye(3)[np.argmin(np.abs(e), axis=-1)]
    v = t - np.sum(t * e, axis=-1, keepdims=True) * e
    return v / np.linalg.norm(v, axis=-1, keepdims=True)


def _angles3(x: object, name: str) -> np.ndarray:
    return check_last_dims(as_float_array(x, name), name, (3,))


# ----------------------------------------------------------------------------- roll-pitch-yaw
def rpy_to_matrix(rpy: object) -> np.ndarray:
    """Rotation ``R = Rz(yaw) · Ry(pitch) · Rx(roll)`` from roll-pitch-yaw angles (eqs 4-6).

    Args:
        rpy: (..., 3) angles ``(roll, pitch, yaw)`` [rad].

    Returns:
        (..., 3, 3) rotation matrices.
    """
    a = _angles3(rpy, "rpy")
    return rotz(a[..., 2]) @ roty(a[..., 1]) @ rotx(a[..., 0])


def matrix_to_rpy(R: object, *, check: bool = True) -> np.ndarray:
    """Roll-pitch-yaw angles of a rotation, inverse of :func:`rpy_to_matrix`.

    ``yaw = atan2(r10, r00)``; then with ``R' = Rz(yaw)ᵀ R = Ry(pitch) Rx(roll)``:
    ``pitch = atan2(−r20, r'00)`` and ``roll = atan2(−r'12, r'11)``.
    Reading roll from ``R'`` keeps it exact near the gimbal lock (cos pitch → 0), where
    yaw is set to 0 and roll carries ``roll ∓ yaw``.

    Args:
        R: (..., 3, 3) rotation matrices.
        check: validate R (orthonormal, det +1, finite).

    Returns:
        (..., 3) ``(roll, pitch, yaw)`` [rad], pitch in [−π/2, π/2].
    """
    a = check_rotation(R, "R") if check else np.asarray(R, dtype=np.float64)
    r00, r10, r20 = a[..., 0, 0], a[..., 1, 0], a[..., 2, 0]
    cp = np.hypot(r00, r10)  # = r'00 = |cos pitch| (≥ 0 keeps pitch in [−π/2, π/2])
    yaw = np.where(cp > GIMBAL_TOL, np.arctan2(r10, r00), 0.0)
    cy, sy = np.cos(yaw), np.sin(yaw)
    pitch = np.arctan2(-r20, cp)
    roll = np.arctan2(
        sy * a[..., 0, 2] - cy * a[..., 1, 2], cy * a[..., 1, 1] - sy * a[..., 0, 1]
    )
    return np.stack([roll, pitch, yaw], axis=-1)


# ----------------------------------------------------------------------------- ZYZ Euler
def zyz_to_matrix(zyz: object) -> np.ndarray:
    """Rotation ``R = Rz(phi) · Ry(theta) · Rz(psi)`` from ZYZ Euler angles (eqs 5-6).

    Args:
        zyz: (..., 3) angles ``(phi, theta, psi)`` [rad].

    Returns:
        (..., 3, 3) rotation matrices.
    """
    a = _angles3(zyz, "zyz")
    return rotz(a[..., 0]) @ roty(a[..., 1]) @ rotz(a[..., 2])


def matrix_to_zyz(R: object, *, check: bool = True) -> np.ndarray:
    """ZYZ Euler angles of a rotation, inverse of :func:`zyz_to_matrix`.

    ``phi = atan2(r12, r02)``; then with ``R' = Rz(phi)ᵀ R = Ry(theta) Rz(psi)``:
    ``theta = atan2(r'02, r22) ∈ [0, π]`` and ``psi = atan2(r'10, r'11)``. At
    ``sin theta = 0`` phi is set to 0 and psi carries ``phi ± psi``.

    Args:
        R: (..., 3, 3) rotation matrices.
        check: validate R (orthonormal, det +1, finite).

    Returns:
        (..., 3) ``(phi, theta, psi)`` [rad].
    """
    a = check_rotation(R, "R") if check else np.asarray(R, dtype=np.float64)
    r02, r12 = a[..., 0, 2], a[..., 1, 2]
    st = np.hypot(r02, r12)  # = r'02 = |sin theta| (≥ 0 keeps theta in [0, π])
    phi = np.where(st > GIMBAL_TOL, np.arctan2(r12, r02), 0.0)
    cf, sf = np.cos(phi), np.sin(phi)
    theta = np.arctan2(st, a[..., 2, 2])
    psi = np.arctan2(cf * a[..., 1, 0] - sf * a[..., 0, 0], cf * a[..., 1, 1] - sf * a[..., 0, 1])
    return np.stack([phi, theta, psi], axis=-1)


# ----------------------------------------------------------------------------- axis-angle
def _unit(v: np.ndarray, name: str, normalize: bool) -> np.ndarray:
    norm = np.linalg.norm(v, axis=-1, keepdims=True)
    if normalize:
        if np.any(norm < 1e-12):
            raise InputError(f"{name} must be non-zero to be normalized, got norm {norm.min():.3g}")
        return v / norm
    dev = np.abs(norm - 1.0).max(initial=0.0)
    if dev > UNIT_TOL:
        worst = norm.reshape(-1)[np.argmax(np.abs(norm - 1.0).reshape(-1))]
        raise InputError(
            f"{name} must have unit norm (1 ± {UNIT_TOL:g}), got norm {worst:.6g}; "
            "pass normalize=True to scale it"
        )
    return v


def axis_angle_to_matrix(axis: object, angle: object, *, normalize: bool = False) -> np.ndarray:
    """Rotation by ``angle`` [rad] about the unit ``axis`` (Rodrigues' formula).

    Args:
        axis: (..., 3) unit axis (see the module's non-unit policy).
        angle: (...) angle [rad]; broadcasts with axis' batch shape.
        normalize: scale a non-unit axis to unit norm instead of raising.

    Returns:
        (..., 3, 3) rotation matrices.

    Raises:
        InputError: wrong shape, NaN/inf, a non-unit axis (without ``normalize``) or a zero
            axis.
    """
    ax = _unit(_angles3(axis, "axis"), "axis", normalize)
    th = as_float_array(angle, "angle")
    return so3_exp(ax * th[..., None])


def matrix_to_axis_angle(R: object, *, check: bool = True) -> tuple[np.ndarray, np.ndarray]:
    """Unit axis and angle ∈ [0, π] of a rotation (the SO(3) logarithm, split).

    Args:
        R: (..., 3, 3) rotation matrices.
        check: validate R.

    Returns:
        ``(axis, angle)`` with shapes (..., 3) and (...); the identity gives axis (0, 0, 1).
    """
    w = so3_log(R, check=check)
    # scaled by the largest component first: the squares of a tiny angle's components
    # (below 1e-154) underflow, and ‖w‖ computed directly would not make a unit axis
    big = np.abs(w).max(axis=-1, keepdims=True)
    scaled = w / np.where(big > 0.0, big, 1.0)
    norm = np.linalg.norm(scaled, axis=-1)
    angle = big[..., 0] * norm
    safe = np.where(norm > 0.0, norm, 1.0)[..., None]
    axis = np.where(big > 0.0, scaled / safe, np.array([0.0, 0.0, 1.0]))
    return axis, angle


# ----------------------------------------------------------------------------- quaternion
def quaternion_to_matrix(q: object, *, normalize: bool = False) -> np.ndarray:
    """Rotation matrix of a unit quaternion ``q = (w, x, y, z)``.

    ``R = [[1 − 2(y² + z²), 2(xy − wz), 2(xz + wy)],
           [2(xy + wz), 1 − 2(x² + z²), 2(yz − wx)],
           [2(xz − wy), 2(yz + wx), 1 − 2(x² + y²)]]``.

    Args:
        q: (..., 4) quaternions, scalar first.
        normalize: scale a non-unit quaternion to unit norm instead of raising.

    Returns:
        (..., 3, 3) rotation matrices.

    Raises:
        InputError: wrong shape, NaN/inf, a non-unit quaternion (without ``normalize``) or a
            zero quaternion.
    """
    a = _unit(check_last_dims(as_float_array(q, "q"), "q", (4,)), "q", normalize)
    w, x, y, z = a[..., 0], a[..., 1], a[..., 2], a[..., 3]
    R = np.empty(a.shape[:-1] + (3, 3))
    R[..., 0, 0] = 1 - 2 * (y * y + z * z)
    R[..., 0, 1] = 2 * (x * y - w * z)
    R[..., 0, 2] = 2 * (x * z + w * y)
    R[..., 1, 0] = 2 * (x * y + w * z)
    R[..., 1, 1] = 1 - 2 * (x * x + z * z)
    R[..., 1, 2] = 2 * (y * z - w * x)
    R[..., 2, 0] = 2 * (x * z - w * y)
    R[..., 2, 1] = 2 * (y * z + w * x)
    R[..., 2, 2] = 1 - 2 * (x * x + y * y)
    return R


def matrix_to_quaternion(R: object, *, check: bool = True) -> np.ndarray:
    """Unit quaternion ``(w, x, y, z)`` with ``w ≥ 0`` of a rotation (Shepperd's method).

    Of the four expressions ``4w² = 1 + tr R``, ``4x² = 1 + 2 r00 − tr R``, ... the largest
    is used to take the square root and the others are found from off-diagonal sums and
    differences, so the result is accurate for every rotation (no division by a small
    number, also at angle π where w = 0).

    Args:
        R: (..., 3, 3) rotation matrices.
        check: validate R.

    Returns:
        (..., 4) unit quaternions, scalar first, w ≥ 0.
    """
    a = check_rotation(R, "R") if check else np.asarray(R, dtype=np.float64)
    r = a.reshape(-1, 3, 3)
    tr = r[:, 0, 0] + r[:, 1, 1] + r[:, 2, 2]
    d = np.stack([tr, r[:, 0, 0], r[:, 1, 1], r[:, 2, 2]], axis=-1)
    k = np.argmax(d, axis=-1)
    s21, s02, s10 = r[:, 2, 1] - r[:, 1, 2], r[:, 0, 2] - r[:, 2, 0], r[:, 1, 0] - r[:, 0, 1]
    p01, p02, p12 = r[:, 0, 1] + r[:, 1, 0], r[:, 0, 2] + r[:, 2, 0], r[:, 1, 2] + r[:, 2, 1]
    big = np.sqrt(np.maximum(1.0 + np.where(k == 0, tr, 2 * d[np.arange(len(k)), k] - tr), 0.0))
    cand = np.stack(
        [
            np.stack([big * big, s21, s02, s10], axis=-1),  # k = 0: 4w · (w, x, y, z)
            np.stack([s21, big * big, p01, p02], axis=-1),  # k = 1: 4x · (w, x, y, z)
            np.stack([s02, p01, big * big, p12], axis=-1),  # k = 2: 4y · ...
            np.stack([s10, p02, p12, big * big], axis=-1),  # k = 3: 4z · ...
        ],
        axis=1,
    )
    q = cand[np.arange(len(k)), k]
    q /= np.linalg.norm(q, axis=-1, keepdims=True)
    q *= np.where(q[:, :1] < 0.0, -1.0, 1.0)
    return q.reshape(a.shape[:-2] + (4,))


def quaternion_multiply(q1: object, q2: object) -> np.ndarray:
    """Hamilton product ``q1 ⊗ q2`` (scalar first); ``R(q1 ⊗ q2) = R(q1) · R(q2)``.

    Args:
        q1: (..., 4) quaternions.
        q2: (..., 4) quaternions; batch dimensions broadcast.

    Returns:
        (..., 4) quaternions (not re-normalized).
    """
    a = check_last_dims(as_float_array(q1, "q1"), "q1", (4,))
    b = check_last_dims(as_float_array(q2, "q2"), "q2", (4,))
    w1, x1, y1, z1 = np.moveaxis(a, -1, 0)
    w2, x2, y2, z2 = np.moveaxis(b, -1, 0)
    return np.stack(
        [
            w1 * w2 - x1 * x2 - y1 * y2 - z1 * z2,
            w1 * x2 + x1 * w2 + y1 * z2 - z1 * y2,
            w1 * y2 - x1 * z2 + y1 * w2 + z1 * x2,
            w1 * z2 + x1 * y2 - y1 * x2 + z1 * w2,
        ],
        axis=-1,
    )
