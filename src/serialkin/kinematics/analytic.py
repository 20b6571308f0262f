"""The analytical Jacobian (chapter section 5.1, eqs 28-29) of an orientation representation.

The analytical Jacobian differentiates the task coordinates ``x = [p; φ(R)]``, where
``φ`` is a minimal (or exponential) description of the end-effector orientation:
``ẋ = J_A(q) q̇`` (eq 28) with ``J_A = ∂x/∂q`` (eq 29). It relates to the geometric
Jacobian ``J`` (eqs 33-36, rows [v; ω], world frame) through the representation's rate
matrix ``E(φ)``, defined by ``ω = E(φ) φ̇``::

    J_A(q) = blockdiag(I₃, E(φ)⁻¹) · J(q)

Representations (see :mod:`serialkin.spatial.rotations` for the angle conventions):

``"rpy"``  φ = (roll, pitch, yaw), R = Rz(yaw) Ry(pitch) Rx(roll)::

    E = [[cos y cos p, −sin y, 0], [sin y cos p, cos y, 0], [−sin p, 0, 1]],  det E = cos p

``"zyz"``  φ = (phi, theta, psi), R = Rz(phi) Ry(theta) Rz(psi)::

    E = [[0, −sin phi, cos phi sin theta], [0, cos phi, sin phi sin theta], [1, 0, cos theta]],
    det E = −sin theta

``"exp"``  φ = log(R)^∨ (rotation vector, |φ| ≤ π), E = J_l(φ), the left Jacobian of SO(3)
(:func:`serialkin.spatial.lie.so3_left_jacobian`), singular only at |φ| = 2π k.

Where ``|det E|`` falls below ``tol`` the representation is singular (gimbal lock for rpy
at pitch = ±π/2, for ZYZ at theta = 0 or π) and :class:`~serialkin.errors.SingularityError`
is raised: φ̇ is not defined there although the geometric Jacobian still is.
"""

from __future__ import annotations

import numpy as np

from serialkin._checks import as_float_array, check_choice, check_last_dims, check_positive
from serialkin.errors import SingularityError
from serialkin.spatial.lie import so3_left_jacobian, so3_log
from serialkin.spatial.rotations import matrix_to_rpy, matrix_to_zyz

#: Names accepted by ``rep``.
REPRESENTATIONS: tuple[str, ...] = ("rpy", "zyz", "exp")
#: Default threshold on |det E(φ)| below which the representation is declared singular.
SINGULAR_TOL = 1e-8

_SINGULARITY_TEXT = {
    "rpy": "roll-pitch-yaw angles are singular at pitch = ±π/2 (gimbal lock), |cos pitch|",
    "zyz": "ZYZ Euler angles are singular at theta = 0 or π, |sin theta|",
    "exp": "the rotation vector's rate matrix is singular at |φ| = 2πk, |det J_l(φ)|",
}


def rotation_coordinates(R: object, rep: str, *, check: bool = True) -> np.ndarray:
    """Orientation coordinates φ of rotation(s) in representation ``rep``.

    Args:
        R: (..., 3, 3) rotation matrices.
        rep: 'rpy' (roll, pitch, yaw), 'zyz' (phi, theta, psi) or 'exp' (rotation vector).
        check: validate R.

    Returns:
        (..., 3) coordinates [rad].
    """
    check_choice(rep, "rep", REPRESENTATIONS)
    if rep == "rpy":
        return matrix_to_rpy(R, check=check)
    if rep == "zyz":
        return matrix_to_zyz(R, check=check)
    return so3_log(R, check=check)


def rate_matrix(phi: object, rep: str) -> np.ndarray:
    """Rate matrix ``E(φ)`` with ``ω = E(φ) φ̇`` (world-frame angular velocity).

    Args:
        phi: (..., 3) orientation coordinates [rad] in representation ``rep``.
        rep: 'rpy', 'zyz' or 'exp' (see the module docstring for the formulas).

    Returns:
        (..., 3, 3) rate matrices.

    Raises:
        InputError: unknown ``rep``, wrong shape or NaN/inf in ``phi``.
    """
    check_choice(rep, "rep", REPRESENTATIONS)
    a = check_last_dims(as_float_array(phi, "phi"), "phi", (3,))
    if rep == "exp":
        return so3_left_jacobian(a)
    E = np.zeros(a.shape[:-1] + (3, 3))
    if rep == "rpy":
        p, y = a[..., 1], a[..., 2]
        cp, sp, cy, sy = np.cos(p), np.sin(p), np.cos(y), np.sin(y)
        E[..., 0, 0] = cy * cp
        E[..., 1, 0] = sy * cp
        E[..., 2, 0] = -sp
        E[..., 0, 1] = -sy
        E[..., 1, 1] = cy
        E[..., 2, 2] = 1.0
    else:  # zyz
        f, t = a[..., 0], a[..., 1]
        cf, sf, ct, st = np.cos(f), np.sin(f), np.cos(t), np.sin(t)
        E[..., 2, 0] = 1.0
        E[..., 0, 1] = -sf
        E[..., 1, 1] = cf
        E[..., 0, 2] = cf * st
        E[..., 1, 2] = sf * st
        E[..., 2, 2] = ct
    return E


def _singular_measure(phi: np.ndarray, rep: str) -> np.ndarray:
    """|det E(φ)|: |cos pitch| (rpy), |sin theta| (zyz), |det J_l| (exp)."""
    if rep == "rpy":
        return np.abs(np.cos(phi[..., 1]))
    if rep == "zyz":
        return np.abs(np.sin(phi[..., 1]))
    theta = np.linalg.norm(phi, axis=-1)
    # det J_l(φ) = 2 (1 − cos θ) / θ² (→ 1 at θ = 0)
    with np.errstate(divide="ignore", invalid="ignore"):
        d = np.where(theta < 1e-4, 1.0, 2.0 * (1.0 - np.cos(theta)) / theta**2)
    return np.abs(d)


def jacobian_analytic(robot: object, q: object, rep: str = "rpy", *,
                      tol: float = SINGULAR_TOL) -> np.ndarray:
    """Analytical Jacobian ``J_A = blockdiag(I₃, E(φ)⁻¹) · J`` (eqs 28-29 via eqs 33-36).

    Rows are ``(ẋ, ẏ, ż, φ̇₁, φ̇₂, φ̇₃)``: the tool position rates [m/s per joint unit]
    followed by the rates of the orientation coordinates of ``rep`` [rad/s per joint
    unit], all in the world frame.

    Args:
        robot: a :class:`serialkin.Robot`.
        q: joint values, shape (n,) or (..., n) [rad / m].
        rep: 'rpy' (default), 'zyz' or 'exp'.
        tol: threshold on |det E(φ)| below which the representation is singular.

    Returns:
        (6, n) or (..., 6, n).

    Raises:
        InputError: unknown ``rep``, bad ``q`` (shape, NaN/inf) or bad ``tol``.
        SingularityError: the tool orientation is at (or within ``tol`` of) a singularity of
            the representation; the message names the configuration.
    """
    check_choice(rep, "rep", REPRESENTATIONS)
    tol = check_positive(tol, "tol")
    a = robot.check_q(q)  # type: ignore[attr-defined]
    J = robot.jacobian(a)  # type: ignore[attr-defined]
    T = robot.fk(a)  # type: ignore[attr-defined]
    phi = rotation_coordinates(T[..., :3, :3], rep, check=False)
    measure = _singular_measure(phi, rep)
    bad = measure < tol
    if np.any(bad):
        idx = tuple(int(i) for i in np.argwhere(bad)[0]) if bad.ndim else ()
        where = f" at batch index {idx}" if idx else ""
        qbad = np.round(a[idx], 6).tolist()
        raise SingularityError(
            f"the analytical Jacobian (rep={rep!r}) is undefined{where}: "
            f"{_SINGULARITY_TEXT[rep]} = {measure[idx]:.3g} < tol = {tol:g} "
            f"(φ = {np.round(phi[idx], 6).tolist()}, q = {qbad}); use another rep or the "
            "geometric Jacobian robot.jacobian(q)"
        )
    E = rate_matrix(phi, rep)
    JA = J.copy()
    JA[..., 3:, :] = np.linalg.solve(E, J[..., 3:, :])
    return JA
