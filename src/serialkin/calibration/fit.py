"""The calibration fit: nonlinear least squares over the minimal identifiable set.

``calibrate`` minimises ``½ Σ_i ρ(‖L_i⁻¹ e_i(p)‖²)`` (``ρ`` the identity or a robust loss)
over the parameters the identifiability analysis keeps, with the others fixed at their
nominal values, by ``scipy.optimize.least_squares`` (trust-region reflective, the
analytic identification Jacobian of :mod:`serialkin.calibration.jacobian`).

Standard errors come from the Gauss–Newton covariance at the solution,
``Cov(p̂) = s² (JᵀJ)⁻¹`` with ``s² = Σ r² / (m·k − r)`` the residual variance of the
whitened residuals (``s ≈ 1`` when the stated sigmas are right), r the number of fitted
parameters.

A fit that does not converge, or whose residuals are not finite, is a result with
``success=False`` and a ``reason``, never an exception.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from serialkin._checks import check_choice, check_int, check_positive
from serialkin.calibration.identifiability import Identifiability, identifiability
from serialkin.calibration.jacobian import errors, whitened
from serialkin.calibration.measurements import Measurements
from serialkin.calibration.models import ErrorModel, error_model
from serialkin.errors import InputError, InputTypeError
from serialkin.model.robot import Robot, robot_scale

#: Loss functions of ``scipy.optimize.least_squares`` accepted by :func:`calibrate`.
LOSSES = ("linear", "huber", "soft_l1", "cauchy", "arctan")


@dataclass(frozen=True, eq=False)
class CalibrationResult:
    """The outcome of :func:`calibrate`.

    Attributes:
        success: True when the solver met its tolerances with finite residuals.
        reason: why it stopped (the solver's message, or what went wrong).
        model: the error model fitted.
        params: (p,) parameter values [m or rad] (nominal for those not fitted).
        std_errors: (p,) standard errors [m or rad], NaN for parameters not fitted.
        identifiability: the analysis that chose the fitted set.
        robot: the calibrated :class:`~serialkin.Robot`.
        errors_before: (m, k) errors of the nominal model [m; rad].
        errors_after: (m, k) errors of the calibrated model [m; rad].
        iterations: function evaluations used.
    """

    success: bool
    reason: str
    model: ErrorModel
    params: np.ndarray
    std_errors: np.ndarray
    identifiability: Identifiability
    robot: Robot
    errors_before: np.ndarray
    errors_after: np.ndarray
    iterations: int

    @staticmethod
    def _rms(e: np.ndarray, rows: slice) -> float:
        return float(np.sqrt(np.mean(np.sum(e[:, rows] ** 2, axis=1)))) if e.shape[1] > \
            rows.start else float("nan")

    @property
    def rms_before(self) -> tuple[float, float]:
        """RMS position error [m] and RMS rotation error [rad] (NaN for positions) before."""
        return self._rms(self.errors_before, slice(0, 3)), self._rms(self.errors_before,
                                                                      slice(3, 6))

    @property
    def rms_after(self) -> tuple[float, float]:
        """RMS position error [m] and RMS rotation error [rad] (NaN for positions) after."""
        return self._rms(self.errors_after, slice(0, 3)), self._rms(self.errors_after,
                                                                     slice(3, 6))

    def residual_table(self) -> tuple[list[str], np.ndarray]:
        """Per-measurement error norms before and after: (header, rows).

        Rows (m, 3 or 5): measurement index, position error [m] before and after, and for
        poses the rotation error [rad] before and after.
        """
        m = self.errors_before.shape[0]
        cols = [np.arange(m), np.linalg.norm(self.errors_before[:, :3], axis=1),
                np.linalg.norm(self.errors_after[:, :3], axis=1)]
        header = ["measurement", "position_before_m", "position_after_m"]
        if self.errors_before.shape[1] == 6:
            cols += [np.linalg.norm(self.errors_before[:, 3:], axis=1),
                     np.linalg.norm(self.errors_after[:, 3:], axis=1)]
            header += ["rotation_before_rad", "rotation_after_rad"]
        return header, np.column_stack(cols)

    def parameter_table(self) -> list[dict[str, Any]]:
        """One row per parameter: name, unit, nominal, value, change, std error, fitted."""
        rows = []
        for i, prm in enumerate(self.model.parameters):
            rows.append({"name": prm.name, "unit": prm.unit, "nominal": prm.nominal,
                         "value": float(self.params[i]),
                         "change": float(self.params[i] - prm.nominal),
                         "std_error": float(self.std_errors[i]),
                         "fitted": bool(self.identifiability.identifiable[i])})
        return rows

    def summary(self) -> str:
        """A few lines for people: success, RMS before/after, what was not identifiable."""
        pb, rb = self.rms_before
        pa, ra = self.rms_after
        rot = (f"; rotation {math.degrees(rb):.4g}° → {math.degrees(ra):.4g}° RMS"
               if math.isfinite(rb) else "")
        head = "calibrated" if self.success else f"NOT converged ({self.reason})"
        return (f"{head}: {len(self.errors_before)} {self.identifiability.kind} measurements, "
                f"{self.identifiability.rank} parameters fitted; position "
                f"{pb * 1e3:.4g} mm → {pa * 1e3:.4g} mm RMS{rot}\n"
                + self.identifiability.summary())


def _as_model(robot: object) -> ErrorModel:
    if isinstance(robot, ErrorModel):
        return robot
    if isinstance(robot, Robot):
        return error_model(robot)
    raise InputTypeError(f"robot must be a Robot or an ErrorModel, got {type(robot).__name__}")


def minimum_measurements(rank: int, kind: str) -> int:
    """Fewest measurements of ``kind`` whose equations (3 or 6 each) cover ``rank`` unknowns."""
    return -(-rank // (3 if kind == "position" else 6))


def calibrate(robot: Robot | ErrorModel, measurements: Measurements, *,
              loss: str = "linear", loss_scale: float = 1.0, max_evaluations: int = 200,
              tol: float = 1e-12, rank_tol: float | None = None) -> CalibrationResult:
    """Identify the robot's geometry from measurements (see the module docstring).

    Args:
        robot: the nominal robot (its default :func:`~serialkin.calibration.error_model`)
            or an :class:`ErrorModel`.
        measurements: from :func:`~serialkin.calibration.make_measurements` or
            :func:`~serialkin.calibration.read_measurements`.
        loss: 'linear' (least squares) or a robust loss: 'huber', 'soft_l1', 'cauchy',
            'arctan' (scipy's), applied per whitened residual row.
        loss_scale: residual size (in sigmas) where a robust loss starts to bend.
        max_evaluations: most residual evaluations (non-convergence is a result).
        tol: the solver's ftol, xtol and gtol.
        rank_tol: tolerance of the identifiability analysis (default
            :data:`~serialkin.calibration.identifiability.RANK_TOL`).

    Returns:
        :class:`CalibrationResult`.

    Raises:
        InputError: measurements of another robot (joint count), too few measurements for
            the identifiable set (the message says how many are needed), a bad option.
    """
    from serialkin.calibration.identifiability import RANK_TOL
    from serialkin.kinematics.parallel import single_threaded_blas

    model = _as_model(robot)
    if not isinstance(measurements, Measurements):
        raise InputTypeError(f"measurements must be Measurements, got "
                             f"{type(measurements).__name__}")
    if measurements.q.shape[1] != model.robot.n:
        raise InputError(f"the measurements have {measurements.q.shape[1]} joint values each "
                         f"but robot {model.robot.name!r} has {model.robot.n} joints")
    check_choice(loss, "loss", LOSSES)
    loss_scale = check_positive(loss_scale, "loss_scale")
    max_evaluations = check_int(max_evaluations, "max_evaluations", minimum=1)
    tol = check_positive(tol, "tol")
    rank_tol = RANK_TOL if rank_tol is None else check_positive(rank_tol, "rank_tol")
    # small dense problems: a multi-threaded BLAS next to numba's thread pool costs 10-40x
    with single_threaded_blas():
        return _calibrate(model, measurements, loss, loss_scale, max_evaluations, tol,
                          rank_tol)


def _calibrate(model: ErrorModel, measurements: Measurements, loss: str, loss_scale: float,
               max_evaluations: int, tol: float, rank_tol: float) -> CalibrationResult:
    from scipy.optimize import least_squares

    kind = measurements.kind
    # the identifiable set at generic configurations, to say how many measurements it needs
    generic_q = model.robot.random_q(max(60, model.size), seed=0)
    generic = _generic_measurements(model, generic_q, kind)
    needed = identifiability(model, generic, tol=rank_tol).rank
    m = len(measurements)
    if m * measurements.rows < needed:
        raise InputError(
            f"too few measurements: {m} {kind} measurements give {m * measurements.rows} "
            f"equations but {needed} parameters of {model!r} are identifiable from {kind} "
            f"measurements; at least {minimum_measurements(needed, kind)} are needed "
            f"(several times more for accuracy)")
    ident = identifiability(model, measurements, tol=rank_tol)
    fit = np.flatnonzero(ident.identifiable)
    p0 = model.nominal
    e0, _ = errors(model, measurements, p0)

    def fun(x: np.ndarray) -> np.ndarray:
        p = p0.copy()
        p[fit] = x
        return whitened(model, measurements, p)[0]

    def jac(x: np.ndarray) -> np.ndarray:
        p = p0.copy()
        p[fit] = x
        return whitened(model, measurements, p, jacobian=True)[1][:, fit]

    success, reason, nfev = False, "", 0
    params = p0.copy()
    std = np.full(model.size, np.nan)
    if not np.isfinite(e0).all():
        reason = "the nominal model gives non-finite errors"
    else:
        try:
            with np.errstate(all="ignore"):
                sol = least_squares(fun, p0[fit], jac=jac, method="trf", loss=loss,
                                    f_scale=loss_scale, x_scale="jac", ftol=tol, xtol=tol,
                                    gtol=tol, max_nfev=max_evaluations)
        except (ValueError, np.linalg.LinAlgError, FloatingPointError) as exc:
            reason = f"the solver failed: {exc}"
        else:
            nfev = int(sol.nfev)
            params[fit] = sol.x
            finite = bool(np.isfinite(sol.fun).all() and np.isfinite(sol.x).all())
            success = bool(sol.status > 0 and finite)
            reason = sol.message if finite else "non-finite residuals or parameters"
            if sol.status == 0:
                reason = (f"not converged within {max_evaluations} evaluations "
                          f"(the budget max_evaluations); the last iterate is returned")
            if finite:
                std[fit] = _standard_errors(sol.jac, sol.fun)
    if not np.isfinite(params).all():
        params = p0.copy()
    e1, _ = errors(model, measurements, params)
    if success:
        doubt = implausible(model, params, e1)
        if doubt:
            success, reason = False, doubt
    return CalibrationResult(success=success, reason=reason, model=model, params=params,
                             std_errors=std, identifiability=ident,
                             robot=model.calibrated_robot(params), errors_before=e0,
                             errors_after=e1, iterations=nfev)


#: A fitted length may move by at most this fraction of the robot's size.
MOVE_LIMIT = 1.0
#: A fitted joint-axis angle may move by at most this much [rad] (base and tool rotations
#: are free: the measurement frame and the marker may sit at any angle).
ANGLE_LIMIT = math.pi / 4
#: The RMS position residual after the fit may be at most this fraction of the robot's
#: size (1 cm on a 1 m arm: far above any real measurement noise).
RESIDUAL_LIMIT = 0.01
_CAUSES = ("are the positions in metres (not millimetres), is it the right robot, and are "
           "the joint columns q1..qn in the robot's joint order and in radians?")


def implausible(model: ErrorModel, params: np.ndarray, errors_after: np.ndarray) -> str:
    """Why a converged fit cannot describe this robot ('' when it can).

    A length moved by more than :data:`MOVE_LIMIT` × the robot's size, a joint axis turned
    by more than :data:`ANGLE_LIMIT`, or an RMS position residual after the fit above
    :data:`RESIDUAL_LIMIT` × the size: the measurements then belong to other units, another
    robot or another joint order (the message says so).
    """
    size = robot_scale(model.robot)
    moved = params - model.nominal
    for k, par in enumerate(model.parameters):
        if par.unit == "m" and abs(moved[k]) > MOVE_LIMIT * size:
            return (f"the fit moved {par.name!r} by {moved[k]:.4g} m, more than the robot's "
                    f"size ({size:.3g} m): the measurements do not fit this robot; " + _CAUSES)
        if par.unit == "rad" and par.group not in ("base", "tool") \
                and abs(moved[k]) > ANGLE_LIMIT:
            return (f"the fit turned {par.name!r} by {math.degrees(moved[k]):.3g}°: the "
                    "measurements do not fit this robot; " + _CAUSES)
    if errors_after.shape[1] >= 3:
        rms = float(np.sqrt(np.mean(np.sum(errors_after[:, :3] ** 2, axis=1))))
        if rms > RESIDUAL_LIMIT * size:
            return (f"the RMS position error after the fit is {rms * 1e3:.4g} mm, large "
                    f"against the robot's size ({size:.3g} m): the measurements do not fit "
                    "this robot; " + _CAUSES)
    return ""


def _standard_errors(J: np.ndarray, r: np.ndarray) -> np.ndarray:
    """sqrt(diag(s² (JᵀJ)⁻¹)), s² = Σr²/(rows − cols) (NaN when rows == cols)."""
    rows, cols = J.shape
    dof = rows - cols
    s2 = float(r @ r) / dof if dof > 0 else float("nan")
    _, s, Vt = np.linalg.svd(J, full_matrices=False)
    keep = s > s[0] * 1e-12 if s.size else s > 0
    inv = (Vt[keep].T / s[keep] ** 2) @ Vt[keep]
    return np.sqrt(np.maximum(np.diag(inv), 0.0) * s2)


def _generic_measurements(model: ErrorModel, q: np.ndarray, kind: str) -> Measurements:
    from serialkin.calibration.measurements import make_measurements

    T = model.fk(q)
    if kind == "position":
        return make_measurements(model.robot, q, positions=T[:, :3, 3])
    return make_measurements(model.robot, q, poses=T)
