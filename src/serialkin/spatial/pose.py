"""Pose error and pose distance between homogeneous transforms (used by every IK solver).

The pose error is the world-frame 6-vector, order [v; ω] (the geometric Jacobian's row
order, eqs 33-36)::

    e = [p_target − p ;  ω],   ω = log(R_target · Rᵀ)^∨,   |ω| ∈ [0, π]

It is zero exactly when the poses coincide, and for a small displacement it equals the
small twist ``[dv; dω]`` with ``p_target = p + dv`` and ``R_target = exp([dω]^) R``, so
that ``e ≈ J(q) dq``. It is computed by the compiled kernel
:func:`serialkin.spatial.kernels.pose_error_into`, which IK kernels call directly.
"""

from __future__ import annotations

import numpy as np

from serialkin._checks import ROTATION_TOL, check_transform, readonly
from serialkin.errors import InputError
from serialkin.spatial import kernels as K


def _validated(x: object, name: str, check: bool) -> np.ndarray:
    """``x`` as a float64 array of shape (..., 4, 4), checked when ``check``."""
    if (
        type(x) is np.ndarray
        and x.dtype == np.float64
        and x.ndim >= 2
        and x.shape[-2:] == (4, 4)
    ):
        if not check or K.transforms_valid(
            readonly(np.ascontiguousarray(x).reshape(-1, 4, 4)), ROTATION_TOL
        ):
            return x
        return check_transform(x, name)
    if check:
        return check_transform(x, name)
    return np.asarray(x, dtype=np.float64)


def _pair(
    T: object, T_target: object, check: bool
) -> tuple[np.ndarray, np.ndarray, tuple[int, ...]]:
    """Validate two (batches of) transforms and broadcast them to read-only (N, 4, 4) C arrays.

    Float64 arrays of shape (..., 4, 4) are validated by a compiled kernel; only when it
    reports a problem (or for other input types) does ``check_transform`` run, to coerce
    the input or to raise its detailed message.
    """
    a = _validated(T, "T", check)
    b = _validated(T_target, "T_target", check)
    try:
        batch = np.broadcast_shapes(a.shape[:-2], b.shape[:-2])
    except ValueError as exc:
        raise InputError(
            f"T and T_target batch shapes do not broadcast: T has shape {a.shape}, "
            f"T_target has shape {b.shape}"
        ) from exc
    a = readonly(np.ascontiguousarray(np.broadcast_to(a, batch + (4, 4)).reshape(-1, 4, 4)))
    b = readonly(np.ascontiguousarray(np.broadcast_to(b, batch + (4, 4)).reshape(-1, 4, 4)))
    return a, b, batch


def pose_error(T: object, T_target: object, *, check: bool = True) -> np.ndarray:
    """World-frame pose error ``e = [p_target − p; log(R_target Rᵀ)^∨]`` [m; rad].

    Args:
        T: current pose(s), shape (..., 4, 4).
        T_target: desired pose(s), shape (..., 4, 4); batch dimensions broadcast with T's.
        check: validate both arguments as rigid transforms (eq 9: orthonormal rotation
            block with det +1, last row [0, 0, 0, 1], finite). Pass False only for
            arrays that are known to be valid.

    Returns:
        (..., 6) errors, order [vx, vy, vz, wx, wy, wz]; the rotation part has norm in
        [0, π] (at exactly π either of the two opposite vectors is returned).

    Raises:
        InputError: a shape other than (..., 4, 4), NaN/inf, a non-rigid transform, or
            batch shapes that do not broadcast.

    Example:
        >>> import numpy as np
        >>> from serialkin.spatial import pose_error, trotz, transl
        >>> pose_error(np.eye(4), transl(0.1, 0, 0) @ trotz(0.2)).round(3)
        array([0.1, 0. , 0. , 0. , 0. , 0.2])
    """
    a, b, batch = _pair(T, T_target, check)
    E = np.empty((a.shape[0], 6))
    K.pose_error_batch(a, b, E)
    return E.reshape(batch + (6,))


def pose_distance(
    T: object, T_target: object, *, check: bool = True
) -> tuple[np.ndarray, np.ndarray]:
    """Position distance [m] and rotation angle [rad] between poses.

    ``d = |p_target − p|`` and ``θ = |log(R_target Rᵀ)^∨| ∈ [0, π]`` (the geodesic angle
    on SO(3), independent of the frame it is measured in).

    Args:
        T: pose(s), shape (..., 4, 4).
        T_target: pose(s), shape (..., 4, 4); batch dimensions broadcast with T's.
        check: validate both arguments as rigid transforms.

    Returns:
        ``(d, theta)``: two arrays of the broadcast batch shape (0-d arrays for single poses).
    """
    e = pose_error(T, T_target, check=check)
    return np.linalg.norm(e[..., :3], axis=-1), np.linalg.norm(e[..., 3:], axis=-1)
