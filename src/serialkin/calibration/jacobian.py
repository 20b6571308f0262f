"""Calibration residuals and the identification Jacobian ∂ residual / ∂ parameter.

With the extended chain of :mod:`serialkin.calibration.models`, parameter k is the value
of a virtual joint, so ``∂T/∂p_k`` is that joint's geometric-Jacobian column
``[z_k × (p − o_k); z_k]`` (rotation) or ``[z_k; 0]`` (translation) in the world frame
(eqs 33-36), computed by the compiled batch kernels through ``robot.jacobian``, times the
parameter's regressor ``g_k(q)`` (1, or ``q_i`` for an encoder scale; see
:meth:`~serialkin.calibration.models.ErrorModel.regressors`). For a
measurement with pose error ``e = [p_model − p; φ]``, ``φ = log(R_model · Rᵀ)^∨``::

    ∂e/∂p_k = [v_k; J_l(φ)⁻¹ · ω_k]

(the left Jacobian of SO(3) turns a world angular velocity into the rate of φ; it is the
identity at φ = 0). Whitened residuals ``r = L⁻¹ e`` and their Jacobian ``L⁻¹ ∂e/∂p``
are what the fit minimises. With several markers, marker j is at ``T · w_j``: the chain's
columns become ``v + ω × R w_j`` and ``∂e/∂w_j = [R; 0]`` on marker j's rows.
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
    q = np.asarray(measurements.q)
    Q = model.extended_q(q, p)
    T = model.extended.fk(Q)
    k = measurements.rows
    e = np.empty((len(measurements), k))
    point = T[:, :3, 3]
    Rw = None
    if model.markers > 1:  # marker j at T · w_j (w_1 = 0)
        w = model.marker_offsets(p)[measurements.markers]
        Rw = np.einsum("mij,mj->mi", T[:, :3, :3], w)
        point = point + Rw
    e[:, :3] = point - measurements.positions
    phi = None
    if k == 6:
        Rerr = T[:, :3, :3] @ np.swapaxes(measurements.rotations, -1, -2)
        phi = so3_log(Rerr, check=False)
        e[:, 3:] = phi
    if not jacobian:
        return e, None
    J = model.extended.jacobian(Q)[:, :, model.param_index]
    if model.has_regressors:  # ∂Q_k/∂p_k = g_k(q)
        J *= model.regressors(q)[:, None, :]
    if Rw is not None:
        # the chain's columns at the marker point (v + ω × R w), and ∂point/∂w_j = R
        J[:, :3] += np.cross(J[:, 3:], Rw[:, :, None], axisa=1, axisb=1, axisc=1)
        Jm = np.zeros((len(measurements), 6, 3 * (model.markers - 1)))
        for j in range(1, model.markers):
            rows = measurements.markers == j
            Jm[rows, :3, 3 * (j - 1):3 * j] = T[rows, :3, :3]
        J = np.concatenate([J, Jm], axis=2)
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
