"""The Lie groups SO(3) and SE(3): hat/vee, exponential, logarithm, left Jacobian.

Conventions:

* ``skew(w)`` is the cross-product matrix ``[w]^`` with ``[w]^ v = w × v``.
* A rotation vector (exponential coordinates) ``w = θ a`` [rad] maps to
  ``R = exp([w]^) = I + sin θ/θ [w]^ + (1 − cos θ)/θ² [w]^²`` (Rodrigues). The logarithm
  returns ``|w| = θ ∈ [0, π]``.
* A twist is ordered ``ξ = [v; ω]`` (translation part first, like the geometric
  Jacobian's rows, eqs 33-36) and ``exp(ξ^) = [[exp(ω), J_l(ω) v], [0, 1]]``.
* ``J_l(w)`` is the left Jacobian of SO(3): ``d/dt exp(w) · exp(w)ᵀ = [J_l(w) ẇ]^``,
  i.e. the world-frame angular velocity of ``R = exp(w)`` is ``ω = J_l(w) ẇ``.

All functions accept batches through leading dimensions: ``w`` of shape (..., 3) gives
rotations of shape (..., 3, 3). Closed forms switch to Taylor series near θ = 0, and the
SO(3) logarithm (compiled kernel :func:`serialkin.spatial.kernels.so3_log_into`) reads
the rotation axis from the symmetric part of R near θ = π, so every function stays
accurate over its whole domain.
"""

from __future__ import annotations

import numpy as np

from serialkin._checks import as_float_array, check_last_dims, check_rotation, check_transform
from serialkin.errors import InputError
from serialkin.spatial import kernels as K

#: Below this angle [rad] the closed-form coefficients are replaced by Taylor series.
SERIES_ANGLE = 0.05
#: Tolerance for :func:`unskew`'s check that a matrix is skew-symmetric.
SKEW_TOL = 1e-6


def _vec3(w: object, name: str) -> np.ndarray:
    return check_last_dims(as_float_array(w, name), name, (3,))


def skew(w: object) -> np.ndarray:
    """Cross-product (hat) matrix ``[w]^`` of a 3-vector, so that ``[w]^ v = w × v``.

    Args:
        w: vector(s), shape (..., 3).

    Returns:
        (..., 3, 3) skew-symmetric matrices ``[[0, −w3, w2], [w3, 0, −w1], [−w2, w1, 0]]``.
    """
    a = _vec3(w, "w")
    S = np.zeros(a.shape + (3,))
    S[..., 0, 1] = -a[..., 2]
    S[..., 0, 2] = a[..., 1]
    S[..., 1, 0] = a[..., 2]
    S[..., 1, 2] = -a[..., 0]
    S[..., 2, 0] = -a[..., 1]
    S[..., 2, 1] = a[..., 0]
    return S


def unskew(S: object, tol: float = SKEW_TOL) -> np.ndarray:
    """Vee map, the inverse of :func:`skew`: ``[w]^ ↦ w``.

    Args:
        S: skew-symmetric matrices, shape (..., 3, 3).
        tol: largest accepted ``|S + Sᵀ|`` entry.

    Returns:
        (..., 3) vectors (read from the antisymmetric part ``(S − Sᵀ)/2``).

    Raises:
        InputError: wrong shape, NaN/inf, or ``S`` not skew-symmetric within ``tol``.
    """
    a = check_last_dims(as_float_array(S, "S"), "S", (3, 3))
    sym = np.abs(a + np.swapaxes(a, -1, -2)).max(initial=0.0)
    if sym > tol:
        raise InputError(f"S must be skew-symmetric: max |S + Sᵀ| = {sym:.3g} exceeds {tol:g}")
    return 0.5 * np.stack(
        [a[..., 2, 1] - a[..., 1, 2], a[..., 0, 2] - a[..., 2, 0], a[..., 1, 0] - a[..., 0, 1]],
        axis=-1,
    )


def _series(theta: np.ndarray, closed: np.ndarray, coeffs: tuple[float, ...]) -> np.ndarray:
    """Replace ``closed`` by the even series Σ c_k θ^{2k} where θ < SERIES_ANGLE."""
    t2 = theta * theta
    ser = np.zeros_like(theta)
    for c in reversed(coeffs):
        ser = ser * t2 + c
    return np.where(theta < SERIES_ANGLE, ser, closed)


def _rodrigues_coeffs(theta: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """A = sin θ/θ, B = (1 − cos θ)/θ², C = (θ − sin θ)/θ³, each accurate near 0."""
    with np.errstate(divide="ignore", invalid="ignore"):
        s = np.sin(theta)
        h = np.sin(0.5 * theta)
        A = _series(theta, s / theta, (1.0, -1 / 6, 1 / 120, -1 / 5040, 1 / 362880))
        B = _series(theta, 2.0 * h * h / theta**2, (0.5, -1 / 24, 1 / 720, -1 / 40320, 1 / 3628800))
        C = _series(theta, (theta - s) / theta**3,
                    (1 / 6, -1 / 120, 1 / 5040, -1 / 362880, 1 / 39916800))
    return A, B, C


def so3_exp(w: object) -> np.ndarray:
    """SO(3) exponential (Rodrigues' formula): rotation vector ↦ rotation matrix.

    ``R = I + (sin θ/θ) [w]^ + ((1 − cos θ)/θ²) [w]^²`` with θ = |w| [rad]; the rotation
    is by θ about the unit axis w/θ. Exact orthonormality up to rounding for any θ.

    Args:
        w: rotation vector(s) [rad], shape (..., 3).

    Returns:
        (..., 3, 3) rotation matrices.
    """
    a = _vec3(w, "w")
    theta = np.linalg.norm(a, axis=-1)
    A, B, _ = _rodrigues_coeffs(theta)
    W = skew(a)
    return np.eye(3) + A[..., None, None] * W + B[..., None, None] * (W @ W)


def so3_log(R: object, *, check: bool = True) -> np.ndarray:
    """SO(3) logarithm: rotation matrix ↦ rotation vector ``w`` with ``|w| = θ ∈ [0, π]``.

    θ = atan2(|vee(R − Rᵀ)|/2, (tr R − 1)/2); away from π, ``w = θ/(2 sin θ) vee(R − Rᵀ)``;
    near π the axis is read from the symmetric part of R. At θ = π exactly, either of the
    two opposite vectors is a valid answer and one of them is returned.

    Args:
        R: rotation(s), shape (..., 3, 3).
        check: validate that R is a rotation (RᵀR = I, det R = 1, eq 7).

    Returns:
        (..., 3) rotation vectors [rad].

    Raises:
        InputError: wrong shape, NaN/inf or (with ``check``) a matrix that is not a rotation.
    """
    a = check_rotation(R, "R") if check else np.asarray(R, dtype=np.float64)
    flat = np.ascontiguousarray(a.reshape(-1, 3, 3))
    W = np.empty((flat.shape[0], 3))
    K.so3_log_batch(flat, W)
    return W.reshape(a.shape[:-2] + (3,))


def so3_left_jacobian(w: object) -> np.ndarray:
    """Left Jacobian of SO(3): ``J_l(w) = I + (1 − cos θ)/θ² [w]^ + (θ − sin θ)/θ³ [w]^²``.

    It maps the rate of the rotation vector to the world-frame angular velocity of
    ``R = exp(w)``: ``ω = J_l(w) ẇ``; it is also the ``V`` matrix of :func:`se3_exp`.
    Singular only at θ = 2π k, k ≥ 1.

    Args:
        w: rotation vector(s) [rad], shape (..., 3).

    Returns:
        (..., 3, 3).
    """
    a = _vec3(w, "w")
    theta = np.linalg.norm(a, axis=-1)
    _, B, C = _rodrigues_coeffs(theta)
    W = skew(a)
    return np.eye(3) + B[..., None, None] * W + C[..., None, None] * (W @ W)


def _left_jacobian_inv_coeff(theta: np.ndarray) -> np.ndarray:
    """D = 1/θ² − cot(θ/2)/(2θ) = 1/θ² − (1 + cos θ)/(2θ sin θ), series near 0."""
    with np.errstate(divide="ignore", invalid="ignore"):
        closed = 1.0 / theta**2 - np.cos(0.5 * theta) / (2.0 * theta * np.sin(0.5 * theta))
    return _series(theta, closed, (1 / 12, 1 / 720, 1 / 30240, 1 / 1209600))


def so3_left_jacobian_inv(w: object) -> np.ndarray:
    """Inverse left Jacobian ``J_l(w)⁻¹ = I − ½[w]^ + (1/θ² − cot(θ/2)/(2θ)) [w]^²``.

    Args:
        w: rotation vector(s) [rad], shape (..., 3) with |w| < 2π.

    Returns:
        (..., 3, 3).

    Raises:
        InputError: |w| ≥ 2π − 1e-6 (J_l is singular at 2π).
    """
    a = _vec3(w, "w")
    theta = np.linalg.norm(a, axis=-1)
    if np.any(theta >= 2 * np.pi - 1e-6):
        raise InputError(
            f"w must have norm < 2π for the inverse left Jacobian, got |w| = {theta.max():.6g}"
        )
    D = _left_jacobian_inv_coeff(theta)
    W = skew(a)
    return np.eye(3) - 0.5 * W + D[..., None, None] * (W @ W)


def se3_exp(xi: object) -> np.ndarray:
    """SE(3) exponential of a twist ``ξ = [v; ω]`` (order: translation part first).

    ``exp(ξ^) = [[exp([ω]^), J_l(ω) v], [0, 0, 0, 1]]``.

    Args:
        xi: twist(s), shape (..., 6): v [m] then ω [rad].

    Returns:
        (..., 4, 4) rigid transforms.
    """
    a = check_last_dims(as_float_array(xi, "xi"), "xi", (6,))
    v, w = a[..., :3], a[..., 3:]
    T = np.zeros(a.shape[:-1] + (4, 4))
    T[..., :3, :3] = so3_exp(w)
    T[..., :3, 3] = np.einsum("...ij,...j->...i", so3_left_jacobian(w), v)
    T[..., 3, 3] = 1.0
    return T


def se3_log(T: object, *, check: bool = True) -> np.ndarray:
    """SE(3) logarithm: rigid transform ↦ twist ``ξ = [v; ω]`` with |ω| ∈ [0, π].

    ``ω = log(R)``, ``v = J_l(ω)⁻¹ p``. Inverse of :func:`se3_exp` on that domain.

    Args:
        T: rigid transform(s), shape (..., 4, 4).
        check: validate T as a rigid transform (eq 9).

    Returns:
        (..., 6) twists.

    Raises:
        InputError: wrong shape, NaN/inf or (with ``check``) not a rigid transform.
    """
    a = check_transform(T, "T") if check else np.asarray(T, dtype=np.float64)
    w = so3_log(a[..., :3, :3], check=False)
    v = np.einsum("...ij,...j->...i", so3_left_jacobian_inv(w), a[..., :3, 3])
    return np.concatenate([v, w], axis=-1)
