"""Elementary rotations and homogeneous transforms (chapter section 2, eqs 4-9).

Conventions (used everywhere in serialkin):

* A rotation matrix ``R_a_b`` (shape (3, 3)) maps coordinates in frame *b* to frame *a*:
  ``p_a = R_a_b @ p_b`` (eq 3).
* A homogeneous transform ``T_a_b`` (shape (4, 4)) is ``[[R_a_b, p_a_b], [0, 0, 0, 1]]``
  where ``p_a_b`` is the origin of *b* expressed in *a* (eqs 8-9).
* Angles are in radians, lengths in metres unless a function says otherwise.
* Functions accept a batch through leading dimensions: an angle array of shape (...)
  gives rotations of shape (..., 3, 3).
"""

from __future__ import annotations

import numpy as np

from serialkin._checks import as_float_array, check_last_dims, check_transform


def _axis_rotation(angle: object, i: int, j: int, name: str) -> np.ndarray:
    a = as_float_array(angle, name)
    c, s = np.cos(a), np.sin(a)
    R = np.zeros(a.shape + (3, 3))
    k = 3 - i - j
    R[..., k, k] = 1.0
    R[..., i, i] = c
    R[..., j, j] = c
    R[..., i, j] = -s
    R[..., j, i] = s
    return R


def rotx(alpha: object) -> np.ndarray:
    """Rotation about the x axis by ``alpha`` [rad] (eq 4). Shape (..., 3, 3) for alpha (...)."""
    return _axis_rotation(alpha, 1, 2, "alpha")


def roty(beta: object) -> np.ndarray:
    """Rotation about the y axis by ``beta`` [rad] (eq 5). Shape (..., 3, 3) for beta (...)."""
    return _axis_rotation(beta, 2, 0, "beta")


def rotz(gamma: object) -> np.ndarray:
    """Rotation about the z axis by ``gamma`` [rad] (eq 6). Shape (..., 3, 3) for gamma (...)."""
    return _axis_rotation(gamma, 0, 1, "gamma")


def make_transform(R: object = None, p: object = None) -> np.ndarray:
    """Homogeneous transform ``[[R, p], [0, 1]]`` (eq 9), shape (..., 4, 4).

    Args:
        R: rotation, shape (..., 3, 3); identity when None. Not checked for orthonormality
            here: use :func:`serialkin.spatial.check_rotation` on untrusted input.
        p: translation [m], shape (..., 3); zero when None.
    """
    Ra = np.eye(3) if R is None else check_last_dims(as_float_array(R, "R"), "R", (3, 3))
    pa = np.zeros(3) if p is None else check_last_dims(as_float_array(p, "p"), "p", (3,))
    batch = np.broadcast_shapes(Ra.shape[:-2], pa.shape[:-1])
    T = np.zeros(batch + (4, 4))
    T[..., :3, :3] = Ra
    T[..., :3, 3] = pa
    T[..., 3, 3] = 1.0
    return T


def transl(x: object, y: object = None, z: object = None) -> np.ndarray:
    """Pure translation transform, shape (4, 4): ``transl(x, y, z)`` or ``transl([x, y, z])``."""
    p = np.asarray(x, dtype=float) if y is None and z is None else np.array([x, y, z], dtype=float)
    return make_transform(None, p)


def trotx(alpha: float) -> np.ndarray:
    """Homogeneous rotation about x by ``alpha`` [rad] (eq 4 embedded in eq 9)."""
    return make_transform(rotx(alpha))


def troty(beta: float) -> np.ndarray:
    """Homogeneous rotation about y by ``beta`` [rad] (eq 5 embedded in eq 9)."""
    return make_transform(roty(beta))


def trotz(gamma: float) -> np.ndarray:
    """Homogeneous rotation about z by ``gamma`` [rad] (eq 6 embedded in eq 9)."""
    return make_transform(rotz(gamma))


def inv_transform(T: object, *, check: bool = True) -> np.ndarray:
    """Inverse of a rigid transform, ``[[Rᵀ, −Rᵀp], [0, 1]]``, shape (..., 4, 4).

    Args:
        T: rigid transform(s), shape (..., 4, 4).
        check: verify that ``T`` is a rigid transform first (raises InputError otherwise).
    """
    a = check_transform(T, "T") if check else np.asarray(T, dtype=float)
    Rt = np.swapaxes(a[..., :3, :3], -1, -2)
    out = np.zeros_like(a)
    out[..., :3, :3] = Rt
    out[..., :3, 3] = -np.einsum("...ij,...j->...i", Rt, a[..., :3, 3])
    out[..., 3, 3] = 1.0
    return out
