"""The calibration fit: nonlinear least squares over the minimal identifiable set.

``calibrate`` minimises ``½ Σ_i ρ(‖L_i⁻¹ e_i(p)‖²)`` (``ρ`` the identity or a robust loss)
over the parameters the identifiability analysis keeps, with the others fixed at their
nominal values, by ``scipy.optimize.least_squares`` (trust-region reflective, the
analytic identification Jacobian of :mod:`serialkin.calibration.jacobian`), in rounds:

1. the set identifiable at the nominal geometry, fitted to convergence (the step, cost and
   gradient tolerances ``tol``);
2. the analysis redone at the solution, the current set first in the priority: a marker
   on the last joint axis at the nominal geometry hides that axis' tilts, off the axis
   where the fit found it they are seen. When the set changed the fit continues from
   there (at most :data:`MAX_ROUNDS` fits). A parameter identifiable only at the fitted
   geometry must also be determined to :data:`PRECISION_ANGLE` (or
   :data:`PRECISION_LENGTH` × the robot's size): a marker a few micrometres off the axis
   (the noise of its estimate) does not make the tilts measurable. A round whose new
   parameters make the fit fail (no convergence, implausible values) is abandoned for the
   last converged one, those parameters fixed.

(Fitting the base and the marker alone first was tried and dropped: the same results on
every arm measured, in more evaluations.) With ``frame='unknown'`` (the measuring
device's frame anywhere) the fit starts from a base pose estimated first: the rigid
transform that best maps the nominal model's tool positions onto the measured ones
(Kabsch / Horn, by the SVD of their cross-covariance), the base translation then free of
the plausibility bound on lengths.

Standard errors and the covariance come from the Gauss–Newton approximation at the
solution, ``Cov(p̂) = s² (JᵀJ)⁻¹`` over the fitted set, with ``s² = Σ r² / (m·k − r)`` the
residual variance of the whitened residuals (``s ≈ 1`` when the stated sigmas are right),
r the number of fitted parameters.

Success needs a converged solver, plausible parameters (:func:`implausible`) and a
residual consistent with the stated noise: ``χ² = Σ r²`` against the chi-square
distribution with ``m·k − r`` degrees of freedom (:class:`ChiSquare`). A fit that does not
converge, or whose residuals are not finite or too large, is a result with
``success=False`` and a ``reason``, never an exception.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
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


#: Default significance level of the chi-square test of the residual: a fit whose
#: residual is this improbable under the stated measurement noise is not a success.
SIGNIFICANCE = 1e-3
_SUSPECT = ("suspect the units (positions in metres, joint values in radians or metres), "
            "the wrong robot or robot file, the joint order of the columns q1..qn, an effect "
            "the model does not have (joint encoder scale, compliance, backlash, thermal "
            "drift), outliers (try loss='soft_l1'), or a stated noise (sigma_position, "
            "sigma_rotation) smaller than the instrument's")


@dataclass(frozen=True)
class ChiSquare:
    """The chi-square test of a fit's whitened residual against the stated noise.

    Under the model, with the stated measurement covariances right, ``χ² = Σ r²`` over the
    whitened residual rows follows the chi-square distribution with ``dof`` = rows − fitted
    parameters degrees of freedom. With a robust loss the rows of measurements flagged as
    outliers (``‖r_i‖²`` above the chi-square 1 − :data:`SIGNIFICANCE` quantile of their k
    rows) are left out (the test is then conservative).

    Attributes:
        chi2: Σ r² over the rows tested (dimensionless).
        dof: degrees of freedom (rows tested − fitted parameters); ≤ 0 means no test.
        p_value: probability of a χ² this large or larger under the stated noise (NaN
            without degrees of freedom).
        noise_ratio: ``sqrt(χ²/dof)``, the residual in units of the stated noise (≈ 1 when
            the model fits and the sigmas are right).
        outliers: measurements left out as outliers (robust losses only).
        measurements: measurements in the fit.
    """

    chi2: float
    dof: int
    p_value: float
    noise_ratio: float
    outliers: int = 0
    measurements: int = 0

    @property
    def variance(self) -> float:
        """``s² = χ²/dof`` (NaN without degrees of freedom)."""
        return self.chi2 / self.dof if self.dof > 0 else float("nan")

    def verdict(self, significance: float = SIGNIFICANCE) -> str:
        """'' when the residual is consistent with the noise, else why not (what to suspect)."""
        if self.outliers > self.measurements // 2:
            return (f"{self.outliers} of {self.measurements} measurements are far off the "
                    f"fitted model (more than half): {_SUSPECT}")
        if self.dof <= 0 or not math.isfinite(self.p_value) or self.p_value >= significance:
            return ""
        return (f"the residual is {self.noise_ratio:.3g} times the stated measurement noise "
                f"(chi-square {self.chi2:.4g} for {self.dof} degrees of freedom, p = "
                f"{self.p_value:.2g} < {significance:g}): the model does not explain the "
                f"measurements to their accuracy; {_SUSPECT}")


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
        iterations: function evaluations used (all rounds).
        chi_square: the :class:`ChiSquare` test of the residual against the stated noise.
        covariance: (p, p) covariance of the parameters [m², m·rad, rad²],
            ``s² (JᵀJ)⁻¹`` over the fitted set, NaN in the rows and columns of the
            parameters not fitted.
        stages: one line per solver run (what was fitted, evaluations, RMS before/after).
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
    chi_square: ChiSquare = field(default_factory=lambda: ChiSquare(
        float("nan"), 0, float("nan"), float("nan")))
    covariance: np.ndarray = field(default_factory=lambda: np.zeros((0, 0)))
    stages: tuple[str, ...] = ()

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
        chi = self.chi_square
        noise = (f"\nresidual {chi.noise_ratio:.3g} × the stated noise (chi-square "
                 f"{chi.chi2:.4g}, {chi.dof} degrees of freedom, p = {chi.p_value:.3g})"
                 if chi.dof > 0 else "")
        return (f"{head}: {len(self.errors_before)} {self.identifiability.kind} measurements, "
                f"{self.identifiability.rank} parameters fitted; position "
                f"{pb * 1e3:.4g} mm → {pa * 1e3:.4g} mm RMS{rot}{noise}\n"
                + self.identifiability.summary())

    @property
    def encoder_scale(self) -> np.ndarray:
        """(n,) identified factors ``1 + s_i`` (1 where no scale is modelled or fitted)."""
        return self.model.encoder_scale(self.params)

    @property
    def marker_offsets(self) -> np.ndarray:
        """(K, 3) identified marker offsets [m] in the tool frame (marker 1 at the origin)."""
        return self.model.marker_offsets(self.params)

    def joint_values(self, q: object) -> np.ndarray:
        """The calibrated :attr:`robot`'s joint values (…, n) for recorded ones: ``q · scale``.

        ``robot.fk(result.joint_values(q))`` is the calibrated pose of the tool at recorded
        (encoder) values q; without encoder scales in the model it is q itself.
        """
        qa = self.model.robot.check_q(q)
        return qa * self.encoder_scale

    def predicted_error(self, q: object = None, *, count: int = 1000,
                        seed: None | int | np.random.Generator = 0) -> float:
        """Expected RMS position error [m] of the calibrated robot at configurations.

        ``sqrt(mean_i trace(J_i Cov J_iᵀ))`` with J_i the (3, r) position rows of the
        identification Jacobian at configuration i over the fitted parameters and Cov
        their :attr:`covariance`: what the parameters' uncertainty leaves at the tool
        point (the measured one), against the real robot (not counting the noise of
        future measurements, nor what the model does not have).

        Args:
            q: (N, n) configurations, or None for ``count`` random ones within the limits.
            count: how many random configurations when ``q`` is None.
            seed: for the random configurations.

        Returns:
            the RMS [m] (NaN when the fit gave no covariance).
        """
        from serialkin.calibration.jacobian import errors

        fit = np.flatnonzero(self.identifiability.identifiable)
        if self.covariance.shape != (self.model.size, self.model.size) or fit.size == 0:
            return float("nan")
        C = self.covariance[np.ix_(fit, fit)]
        if not np.isfinite(C).all():
            return float("nan")
        robot = self.model.robot
        if q is None:
            qa = robot.random_q(check_int(count, "count", minimum=1), seed=seed)
        else:
            qa = robot.check_q(q).reshape(-1, robot.n)
        meas = _generic_measurements(self.model, qa, "position")
        _, J = errors(self.model, meas, self.params, jacobian=True)
        Jf = J[:, :3, fit]
        var = np.einsum("mip,pq,miq->m", Jf, C, Jf)
        return float(np.sqrt(max(float(np.mean(var)), 0.0)))


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
              tol: float = 1e-12, rank_tol: float | None = None,
              significance: float = SIGNIFICANCE, frame: str = "nominal") -> CalibrationResult:
    """Identify the robot's geometry from measurements (see the module docstring).

    Args:
        robot: the nominal robot (its default :func:`~serialkin.calibration.error_model`)
            or an :class:`ErrorModel`.
        measurements: from :func:`~serialkin.calibration.make_measurements` or
            :func:`~serialkin.calibration.read_measurements`.
        loss: 'linear' (least squares) or a robust loss: 'huber', 'soft_l1', 'cauchy',
            'arctan' (scipy's), applied per whitened residual row.
        loss_scale: residual size (in sigmas) where a robust loss starts to bend.
        max_evaluations: most residual evaluations over all rounds (non-convergence is a
            result).
        tol: the solver's ftol, xtol and gtol (relative cost change, relative step, and
            scaled gradient at which a fit has converged).
        rank_tol: tolerance of the identifiability analysis (default
            :data:`~serialkin.calibration.identifiability.RANK_TOL`).
        significance: level of the chi-square test of the residual against the stated
            noise (:class:`ChiSquare`); 0 turns the test off.
        frame: the measuring device's frame: 'nominal' (the robot's base pose in it is
            known roughly; the fit starts there) or 'unknown' (anywhere: the base pose is
            first estimated by a rigid registration of the nominal tool positions to the
            measured ones, then identified with the rest; needs the six base errors).

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
    if len(measurements) and int(measurements.markers.max()) >= model.markers:
        raise InputError(f"the measurements name marker {int(measurements.markers.max()) + 1} "
                         f"but the error model has {model.markers} marker(s) (expected "
                         f"error_model(..., markers={int(measurements.markers.max()) + 1}))")
    check_choice(frame, "frame", FRAMES)
    if frame == "unknown" and sum(p.group == "base" for p in model.parameters) != 6:
        raise InputError("frame='unknown' identifies the base pose: the error model needs "
                         "its six base errors (error_model(..., base=True))")
    check_choice(loss, "loss", LOSSES)
    loss_scale = check_positive(loss_scale, "loss_scale")
    max_evaluations = check_int(max_evaluations, "max_evaluations", minimum=1)
    tol = check_positive(tol, "tol")
    rank_tol = RANK_TOL if rank_tol is None else check_positive(rank_tol, "rank_tol")
    significance = check_positive(significance, "significance", allow_zero=True)
    if significance >= 1:
        raise InputError(f"significance must be below 1, got {significance}")
    # small dense problems: a multi-threaded BLAS next to numba's thread pool costs 10-40x
    with single_threaded_blas():
        return _calibrate(model, measurements, loss, loss_scale, max_evaluations, tol,
                          rank_tol, significance, frame)


#: The measuring device's frame (:func:`calibrate`'s ``frame``).
FRAMES = ("nominal", "unknown")


def registered_base(model: ErrorModel, measurements: Measurements) -> np.ndarray:
    """Parameters (p,): nominal, the base errors set to the best rigid registration.

    The rotation R and translation t minimising ``Σ ‖R x_i + t − y_i‖²`` between the
    nominal model's tool positions x_i and the measured y_i (Kabsch 1976 / Horn 1987:
    ``R = U diag(1, 1, det UVᵀ) Vᵀ`` from the SVD ``U S Vᵀ`` of the centred
    cross-covariance ``Σ (y_i − ȳ)(x_i − x̄)ᵀ``, ``t = ȳ − R x̄``); with the nominal base
    B0 the base error is ``E = B0⁻¹ · [R t] · B0``, written as ``Txyz · Rz · Ry · Rx``.
    An unknown marker only blurs it by its length: the fit refines it.
    """
    from serialkin.spatial import matrix_to_rpy

    p = model.nominal.copy()
    x = model.fk(np.asarray(measurements.q), p)[:, :3, 3]
    y = np.asarray(measurements.positions)
    xc, yc = x - x.mean(axis=0), y - y.mean(axis=0)
    U, _, Vt = np.linalg.svd(yc.T @ xc)
    D = np.diag([1.0, 1.0, np.sign(np.linalg.det(U @ Vt)) or 1.0])
    G = np.eye(4)
    G[:3, :3] = U @ D @ Vt
    G[:3, 3] = y.mean(axis=0) - G[:3, :3] @ x.mean(axis=0)
    B0 = model.robot.base
    E = np.linalg.inv(B0) @ G @ B0
    roll, pitch, yaw = matrix_to_rpy(E[:3, :3], check=False)
    values = {"base x": E[0, 3], "base y": E[1, 3], "base z": E[2, 3], "base rz": yaw,
              "base ry": pitch, "base rx": roll}
    for k, name in enumerate(model.names):
        if name in values:
            p[k] = values[name]
    return p


def _calibrate(model: ErrorModel, measurements: Measurements, loss: str, loss_scale: float,
               max_evaluations: int, tol: float, rank_tol: float,
               significance: float, frame: str) -> CalibrationResult:
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
    p0 = model.nominal
    e0, _ = errors(model, measurements, p0)
    start = registered_base(model, measurements) if frame == "unknown" else p0
    free_base = frame == "unknown"
    solver = _Solver(model, measurements, loss, loss_scale, tol, max_evaluations)
    ident = identifiability(model, measurements, start, tol=rank_tol)
    success, reason = False, ""
    params = p0.copy()
    std = np.full(model.size, np.nan)
    cov = np.full((model.size, model.size), np.nan)
    if not np.isfinite(e0).all():
        reason = "the nominal model gives non-finite errors"
    else:
        try:
            with np.errstate(all="ignore"):
                params, ident, success, reason = _fit_rounds(solver, ident, rank_tol, start,
                                                             free_base)
        except (ValueError, np.linalg.LinAlgError, FloatingPointError) as exc:
            reason = f"the solver failed: {exc}"
            params = solver.best
    if not np.isfinite(params).all():
        params, success = p0.copy(), False
    fit = np.flatnonzero(ident.identifiable)
    r1, J1 = whitened(model, measurements, params, jacobian=True)
    test, inlier = _chi_square(r1, measurements.rows, fit.size, loss)
    if fit.size and np.isfinite(r1).all() and np.isfinite(J1).all():
        rows = np.repeat(inlier, measurements.rows)
        block = _parameter_covariance(J1[np.ix_(rows, fit)], test.variance)
        cov[np.ix_(fit, fit)] = block
        std[fit] = np.sqrt(np.maximum(np.diag(block), 0.0))
    e1, _ = errors(model, measurements, params)
    doubt = implausible(model, params, e1, free_base=free_base) if np.isfinite(e1).all() \
        else ""
    if success:
        if not doubt and significance > 0:
            doubt = test.verdict(significance)
        if doubt:
            success, reason = False, doubt
    elif doubt:  # e.g. a fit that wanders off because the data are of another robot
        reason = f"{reason}; {doubt}"
    return CalibrationResult(success=success, reason=reason, model=model, params=params,
                             std_errors=std, identifiability=ident,
                             robot=model.calibrated_robot(params), errors_before=e0,
                             errors_after=e1, iterations=solver.nfev, chi_square=test,
                             covariance=cov, stages=tuple(solver.log))


class _Solver:
    """``least_squares`` over a subset of the parameters, with one evaluation budget."""

    def __init__(self, model: ErrorModel, measurements: Measurements, loss: str,
                 loss_scale: float, tol: float, budget: int) -> None:
        self.model, self.meas = model, measurements
        self.loss, self.loss_scale, self.tol = loss, loss_scale, tol
        self.budget, self.nfev = budget, 0
        self.best = model.nominal
        self.log: list[str] = []

    def solve(self, p: np.ndarray, fit: np.ndarray, label: str) -> tuple[np.ndarray, Any]:
        """Minimise over ``fit`` (indices) from ``p``.

        Returns:
            (params (p,), scipy's result).
        """
        from scipy.optimize import least_squares

        model, meas, tol = self.model, self.meas, self.tol

        def fun(x: np.ndarray) -> np.ndarray:
            q = p.copy()
            q[fit] = x
            return whitened(model, meas, q)[0]

        def jac(x: np.ndarray) -> np.ndarray:
            q = p.copy()
            q[fit] = x
            return whitened(model, meas, q, jacobian=True)[1][:, fit]

        before = _position_rms(model, meas, p)
        sol = least_squares(fun, p[fit], jac=jac, method="trf", loss=self.loss,
                            f_scale=self.loss_scale, x_scale="jac", ftol=tol, xtol=tol,
                            gtol=tol, max_nfev=max(self.budget - self.nfev, 1))
        self.nfev += int(sol.nfev)
        out = p.copy()
        out[fit] = sol.x
        if np.isfinite(out).all():
            self.best = out
        after = _position_rms(model, meas, out)
        self.log.append(f"{label}: {fit.size} parameters, {int(sol.nfev)} evaluations, "
                        f"position {before * 1e3:.4g} mm -> {after * 1e3:.4g} mm RMS "
                        f"(status {sol.status})")
        return out, sol


#: Most fits of the whole identifiable set (each after an identifiability analysis at the
#: point the previous one reached).
MAX_ROUNDS = 6


def _fit_rounds(solver: _Solver, nominal_ident: Identifiability, rank_tol: float,
                start: np.ndarray, free_base: bool = False
                ) -> tuple[np.ndarray, Identifiability, bool, str]:
    """The identifiable set, fitted and re-analysed where each fit ends (module docstring).

    ``start`` (p,) is where the first round starts (nominal, or with a registered base).

    Returns:
        (params (p,), the final analysis, converged, reason).
    """
    model, meas = solver.model, solver.meas
    p = start.copy()
    # the set identifiable at the nominal geometry; then, until the set no longer changes,
    # the set identifiable where the last fit ended (a marker off the last axis there
    # shows that axis' tilts)
    ident = nominal_ident
    good: tuple[np.ndarray, np.ndarray, Any, float] | None = None  # last converged round
    for rnd in range(MAX_ROUNDS):
        fit = np.flatnonzero(ident.identifiable)
        p, sol = solver.solve(p, fit, f"round {rnd + 1}")
        failed = ""
        if sol.status == 0:
            failed = _not_converged(solver, sol)
        elif not (np.isfinite(sol.fun).all() and np.isfinite(p).all()):
            failed = "non-finite residuals or parameters"
        elif good is not None:
            failed = implausible(model, p, errors(model, meas, p)[0], free_base=free_base)
        if failed and good is None:
            return p, ident, False, failed
        if failed:
            # parameters seen only at the fitted geometry that make the fit fail (e.g. a
            # wrist axis seen through a millimetre lever): back to the last converged fit
            p0, keep0, sol0, noise0 = good
            added = {int(k): f"{model.names[k]} is identifiable at the fitted geometry but "
                             f"the fit with it failed ({failed.split(';')[0]}); it is fixed"
                     for k in np.flatnonzero(ident.identifiable & ~keep0)}
            names = ", ".join(model.names[k] for k in added)
            solver.log.append(f"round {rnd + 1} abandoned: {names} stay fixed")
            final = _practical(model, meas, p0, keep0, nominal_ident, rank_tol, noise0,
                               exclude=added)
            if np.array_equal(final.identifiable, keep0):
                return p0, final, True, str(sol0.message)
            return p0, final, False, failed
        dof = sol.fun.size - fit.size
        ratio = math.sqrt(float(sol.fun @ sol.fun) / dof) if dof > 0 else 1.0
        noise = min(max(ratio, NOISE_FLOOR), 1.0)
        again = _practical(model, meas, p, ident.identifiable, nominal_ident, rank_tol, noise)
        if np.array_equal(again.identifiable, ident.identifiable):
            return p, again, True, str(sol.message)
        good = (p.copy(), ident.identifiable.copy(), sol, noise)
        # parameters that became redundant go back to their start (data-sheet) values
        dropped = ident.identifiable & ~again.identifiable
        p[dropped] = start[dropped]
        ident = again
    return p, ident, False, (f"the identifiable set kept changing over {MAX_ROUNDS} fits "
                             "(parameters at the edge of identifiability); the last "
                             "iterate is returned")


def _not_converged(solver: _Solver, sol: Any) -> str:
    if sol.status == 0:
        return (f"not converged within {solver.budget} evaluations (the budget "
                f"max_evaluations); the last iterate is returned")
    return "non-finite residuals or parameters"


#: A parameter that becomes identifiable only through the fitted geometry (not at the
#: nominal one, e.g. the tilt of the last axis once the marker is off it) is fitted only
#: when its standard error (the other fitted parameters free; the residual's noise, at
#: most the stated one and at least :data:`NOISE_FLOOR` of it) is below this angle [rad]
#: (0.06°, a fraction of typical joint-axis errors) ...
PRECISION_ANGLE = 1e-3
#: ... or this fraction of the robot's size (a length).
PRECISION_LENGTH = 1e-3
#: The residual's noise used for those standard errors is at least this fraction of the
#: stated one: noiseless data would otherwise admit parameters seen only through a product
#: of two small errors (a marker a millimetre off a wrist axis), which then wander.
NOISE_FLOOR = 0.1


def _practical(model: ErrorModel, meas: Measurements, p: np.ndarray,
               current: np.ndarray, nominal_ident: Identifiability, rank_tol: float,
               noise: float, exclude: dict[int, str] | None = None) -> Identifiability:
    """The identifiability analysis at ``p``, the ``current`` set (p,) first in the priority.

    Parameters the analysis at ``p`` keeps but the nominal one did not are kept only while
    their standard error (``noise`` × the stated sigmas' one) is below
    :data:`PRECISION_ANGLE` or :data:`PRECISION_LENGTH` × the robot's size: a marker a
    few micrometres off the last axis (the noise of its estimate) makes that axis' tilts
    independent columns, but not determinable ones.
    """
    from serialkin.calibration.identifiability import analyse, priority_order
    from serialkin.calibration.jacobian import identification_jacobian

    J = identification_jacobian(model, meas, p)
    order = priority_order(model)
    order = [k for k in order if current[k]] + [k for k in order if not current[k]]
    size = robot_scale(model.robot)
    limit = np.array([PRECISION_LENGTH * size if par.unit == "m" else PRECISION_ANGLE
                      for par in model.parameters])  # 'rad', and '1' (a relative scale)
    weak: dict[int, str] = dict(exclude or {})
    while True:
        ident = analyse(J, model.names, kind=meas.kind, order=order, tol=rank_tol,
                        exclude=weak)
        keep = ident.identifiable
        new = np.flatnonzero(keep & ~nominal_ident.identifiable)
        if new.size == 0:
            return ident
        idx = np.flatnonzero(keep)
        se = noise * np.sqrt(np.maximum(np.diag(np.linalg.pinv(J[:, idx].T @ J[:, idx])),
                                        0.0))
        pos = np.searchsorted(idx, new)
        ratio = se[pos] / limit[new]
        worst = int(np.argmax(ratio))
        if ratio[worst] <= 1.0:
            return ident
        k = int(new[worst])
        weak[k] = (f"{model.names[k]} is too weakly determined by these measurements at "
                   f"the fitted geometry (standard error {se[pos[worst]]:.3g} "
                   f"{model.parameters[k].unit})")


#: A fitted length may move by at most this fraction of the robot's size.
MOVE_LIMIT = 1.0
#: A fitted joint-axis angle may move by at most this much [rad] (base and tool rotations
#: are free: the measurement frame and the marker may sit at any angle).
ANGLE_LIMIT = math.pi / 4
#: A fitted encoder scale error may be at most this (10 %: a wrong gear ratio or units).
SCALE_LIMIT = 0.1
#: The RMS position residual after the fit may be at most this fraction of the robot's
#: size (1 cm on a 1 m arm: far above any real measurement noise).
RESIDUAL_LIMIT = 0.01
_CAUSES = ("are the positions in metres (not millimetres), is it the right robot, and are "
           "the joint columns q1..qn in the robot's joint order and in radians?")


def implausible(model: ErrorModel, params: np.ndarray, errors_after: np.ndarray, *,
                free_base: bool = False) -> str:
    """Why a converged fit cannot describe this robot ('' when it can).

    A length moved by more than :data:`MOVE_LIMIT` × the robot's size (the base
    translation excepted with ``free_base``: the device frame unknown), a joint axis
    turned by more than :data:`ANGLE_LIMIT`, an encoder scale off by more than
    :data:`SCALE_LIMIT`, or an RMS position residual after the fit above
    :data:`RESIDUAL_LIMIT` × the size: the measurements then belong to other units, another
    robot or another joint order (the message says so).
    """
    size = robot_scale(model.robot)
    moved = params - model.nominal
    for k, par in enumerate(model.parameters):
        if par.unit == "1" and abs(moved[k]) > SCALE_LIMIT:
            return (f"the fit changed the encoder scale {par.name!r} by {moved[k]:.3g} (more "
                    f"than {SCALE_LIMIT:g}): the measurements do not fit this robot; "
                    + _CAUSES)
        if free_base and par.group == "base":
            continue
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


def _parameter_covariance(J: np.ndarray, s2: float) -> np.ndarray:
    """``s² (JᵀJ)⁻¹`` (r, r) of a whitened Jacobian (rows, r), by the SVD (NaN if s² is)."""
    _, s, Vt = np.linalg.svd(J, full_matrices=False)
    keep = s > s[0] * 1e-12 if s.size else s > 0
    return (Vt[keep].T / s[keep] ** 2) @ Vt[keep] * s2


def _chi_square(r: np.ndarray, k: int, fitted: int, loss: str
                ) -> tuple[ChiSquare, np.ndarray]:
    """The chi-square test of whitened residuals r (m·k,) with ``fitted`` parameters.

    Returns:
        (the test, (m,) bool mask of the measurements tested: all but a robust loss'
        outliers).
    """
    from scipy.stats import chi2 as chi2_dist

    rows = r.reshape(-1, k)
    m = rows.shape[0]
    inlier = np.ones(m, dtype=bool)
    if not np.isfinite(rows).all():
        return ChiSquare(float("inf"), m * k - fitted, 0.0, float("inf"), 0, m), inlier
    norms = np.sum(rows**2, axis=1)
    if loss != "linear":
        inlier = norms <= chi2_dist.isf(SIGNIFICANCE, k)
    outliers = int(m - inlier.sum())
    chi2 = float(norms[inlier].sum())
    dof = int(inlier.sum()) * k - fitted
    if dof <= 0:
        return ChiSquare(chi2, dof, float("nan"), float("nan"), outliers, m), inlier
    return ChiSquare(chi2, dof, float(chi2_dist.sf(chi2, dof)), math.sqrt(chi2 / dof),
                     outliers, m), inlier


def _position_rms(model: ErrorModel, meas: Measurements, p: np.ndarray) -> float:
    """RMS position error [m] of the model at parameters p over the measurements."""
    e, _ = errors(model, meas, p)
    return float(np.sqrt(np.mean(np.sum(e[:, :3] ** 2, axis=1))))


def _generic_measurements(model: ErrorModel, q: np.ndarray, kind: str) -> Measurements:
    from serialkin.calibration.measurements import make_measurements

    T = model.fk(q)
    markers = np.arange(len(q)) % model.markers  # every marker seen (their offsets count)
    if kind == "position":
        return make_measurements(model.robot, q, positions=T[:, :3, 3], markers=markers)
    return make_measurements(model.robot, q, poses=T, markers=markers)
