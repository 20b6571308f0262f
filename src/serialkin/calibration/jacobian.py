"""Calibration residuals and the identification Jacobian ∂ residual / ∂ parameter.

With the extended chain of :mod:`serialkin.calibration.models`, parameter k is the value
of a virtual joint, so ``∂T/∂p_k`` is that joint's geometric-Jacobian column
``[z_k × (p − o_k); z_k]`` (rotation) or ``[z_k; 0]`` (translation) in the world frame
(eqs 33-36), computed by the compiled batch kernels through ``robot.jacobian``. For a
measurement with pose error ``e = [p_model − p; φ]``, ``φ = log(R_model · Rᵀ)^∨``::

    ∂e/∂p_k = [v_k; J_l(φ)⁻¹ · ω_k]

(the left Jacobian of SO(3) turns a world angular velocity into the rate of φ; it is the
identity at φ = 0). Whitened residuals ``r = L⁻¹ e`` and their Jacobian ``L⁻¹ ∂e/∂p``
are what the fit minimises.
"""

from __future__ import annotations

import numpy as np

from serialkin.calibration.measurements import Measurements
from serialkin.calibration.models import ErrorModel
from serialkin.spatial.lie import so3_left_jacobian_inv, so3_log


def errors(model: ErrorModel, measurements: Measurements, params: object = None,
           *, jacobian: bool = False) -> tuple[np.ndarray, np.ndarray | None]:
    """Raw errors ``e`` (m, k) [m; rad] of the model at ``params`` and, optionally, ∂e/∂p.

    Args:
        model: the error model.
        measurements: m measurements of k = 3 (position) or 6 (pose) rows.
        params: (p,) parameter values; None for the nominal ones.
        jacobian: also return the (m, k, p) identification Jacobian.

    Returns:
        (e (m, k), J (m, k, p) or None).
    """
    p = model.nominal if params is None else model.check_params(params)
    Q = model.extended_q(np.asarray(measurements.q), p)
    T = model.extended.fk(Q)
    k = measurements.rows
    e = np.empty((len(measurements), k))
    e[:, :3] = T[:, :3, 3] - measurements.positions
    phi = None
    if k == 6:
        Rerr = T[:, :3, :3] @ np.swapaxes(measurements.rotations, -1, -2)
        phi = so3_log(Rerr, check=False)
        e[:, 3:] = phi
    if not jacobian:
        return e, None
    J = model.extended.jacobian(Q)[:, :, model.param_index]
    if k == 3:
        return e, np.ascontiguousarray(J[:, :3])
    J[:, 3:] = so3_left_jacobian_inv(phi) @ J[:, 3:]
    return e, J


def whitened(model: ErrorModel, measurements: Measurements, params: object = None,
             *, jacobian: bool = False) -> tuple[np.ndarray, np.ndarray | None]:
    """Whitened residuals ``r = L⁻¹ e`` (m·k,) and their Jacobian (m·k, p) (or None)."""
    e, J = errors(model, measurements, params, jacobian=jacobian)
    W = measurements.whitening
    r = np.einsum("mij,mj->mi", W, e).reshape(-1)
    if J is None:
        return r, None
    return r, np.einsum("mij,mjp->mip", W, J).reshape(r.size, -1)


def identification_jacobian(model: ErrorModel, measurements: Measurements,
                            params: object = None) -> np.ndarray:
    """The whitened identification Jacobian (m·k, p) at ``params`` (nominal by default)."""
    return whitened(model, measurements, params, jacobian=True)[1]
