"""Cross-validation of a calibration: fit on part of the measurements, test on the rest.

``cross_validate`` splits the measurements into ``folds`` random parts; for each part it
calibrates on the others and measures the calibrated robot's position error on the part
left out. Each held-out error has two sources: the measurement noise of the held-out
measurements and the calibrated robot's own error (its parameters' uncertainty, and any
effect the model does not have). The fit predicts both — the residual variance ``s²``
times the stated covariance of a measurement, plus
:meth:`~serialkin.calibration.fit.CalibrationResult.predicted_error` at the held-out
configurations — so a held-out RMS well above the prediction says the model
extrapolates worse than its statistics claim (an unmodelled effect, or over-fitting).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from serialkin._checks import as_generator, check_int
from serialkin.calibration.fit import CalibrationResult, _as_model, calibrate
from serialkin.calibration.jacobian import errors
from serialkin.calibration.measurements import Measurements
from serialkin.calibration.models import ErrorModel
from serialkin.errors import InputError, InputTypeError
from serialkin.model.robot import Robot


@dataclass(frozen=True, eq=False)
class CrossValidation:
    """The outcome of :func:`cross_validate`.

    Attributes:
        folds: number of folds k.
        held_out_rms: (k,) RMS position error [m] of each fold's calibrated robot on the
            measurements left out of its fit (against the measured positions).
        predicted_rms: (k,) what each fold's fit predicts for that RMS [m]: its residual
            variance times the held-out measurements' stated noise, plus its
            :meth:`~serialkin.calibration.fit.CalibrationResult.predicted_error`.
        train_rms: (k,) RMS position error [m] of each fold's fit on its own measurements.
        success: (k,) each fold's ``success``.
        results: the k fold results.
    """

    folds: int
    held_out_rms: np.ndarray
    predicted_rms: np.ndarray
    train_rms: np.ndarray
    success: np.ndarray
    results: tuple[CalibrationResult, ...]

    @property
    def rms(self) -> float:
        """Held-out RMS position error over all measurements [m] (the folds pooled)."""
        return float(np.sqrt(np.mean(self.held_out_rms**2)))

    @property
    def predicted(self) -> float:
        """Predicted held-out RMS position error over all measurements [m]."""
        return float(np.sqrt(np.mean(self.predicted_rms**2)))

    @property
    def ratio(self) -> float:
        """Held-out over predicted RMS (≈ 1 when the fit's statistics hold)."""
        return self.rms / self.predicted if self.predicted > 0 else float("nan")

    def summary(self) -> str:
        """A few lines for people: held-out against predicted and training RMS per fold."""
        lines = [f"{self.folds}-fold cross-validation: held-out position error "
                 f"{self.rms * 1e3:.4g} mm RMS, predicted {self.predicted * 1e3:.4g} mm "
                 f"(ratio {self.ratio:.3g}); {int(self.success.sum())} of {self.folds} fits "
                 "succeeded"]
        for i in range(self.folds):
            lines.append(f"  fold {i + 1}: held out {self.held_out_rms[i] * 1e3:.4g} mm, "
                         f"predicted {self.predicted_rms[i] * 1e3:.4g} mm, training "
                         f"{self.train_rms[i] * 1e3:.4g} mm")
        return "\n".join(lines)


def holdout_errors(result: CalibrationResult, measurements: Measurements) -> np.ndarray:
    """Errors (m, k) [m; rad] of a calibration's robot on other measurements.

    The same residual as the fit's (``[p_model − p; log(R_model Rᵀ)^∨]``), at the fitted
    parameters.
    """
    if not isinstance(measurements, Measurements):
        raise InputTypeError(f"measurements must be Measurements, got "
                             f"{type(measurements).__name__}")
    return errors(result.model, measurements, result.params)[0]


def _noise_position_variance(measurements: Measurements) -> np.ndarray:
    """(m,) trace of the stated position covariance of each measurement [m²]."""
    W = measurements.whitening
    C = np.linalg.inv(np.swapaxes(W, 1, 2) @ W)  # W = L⁻¹: (WᵀW)⁻¹ = L Lᵀ
    return np.trace(C[:, :3, :3], axis1=1, axis2=2)


def cross_validate(robot: Robot | ErrorModel, measurements: Measurements, *, folds: int = 5,
                   seed: None | int | np.random.Generator = 0,
                   **options: Any) -> CrossValidation:
    """k-fold cross-validation of :func:`~serialkin.calibration.calibrate` (module docstring).

    Args:
        robot: the nominal robot or an :class:`~serialkin.calibration.ErrorModel`.
        measurements: all m measurements.
        folds: k ≥ 2; each fit leaves out about m/k measurements.
        seed: for the random split.
        **options: passed to :func:`~serialkin.calibration.calibrate` (loss, tol, ...).

    Returns:
        :class:`CrossValidation`.

    Raises:
        InputError: fewer measurements than folds, or too few per fit (from calibrate).
    """
    model = _as_model(robot)
    if not isinstance(measurements, Measurements):
        raise InputTypeError(f"measurements must be Measurements, got "
                             f"{type(measurements).__name__}")
    k = check_int(folds, "folds", minimum=2)
    m = len(measurements)
    if m < k:
        raise InputError(f"{k}-fold cross-validation needs at least {k} measurements, got {m}")
    order = as_generator(seed).permutation(m)
    parts = np.array_split(order, k)
    held, pred, train, ok, results = [], [], [], [], []
    for part in parts:
        rest = np.setdiff1d(order, part)
        res = calibrate(model, measurements.subset(np.sort(rest)), **options)
        test = measurements.subset(np.sort(part))
        e = holdout_errors(res, test)
        held.append(float(np.sqrt(np.mean(np.sum(e[:, :3] ** 2, axis=1)))))
        s2 = res.chi_square.variance
        noise = float(np.mean(_noise_position_variance(test))) * (s2 if np.isfinite(s2) else 1.0)
        own = res.predicted_error(np.asarray(test.q))
        pred.append(float(np.sqrt(noise + own**2)) if np.isfinite(own) else float("nan"))
        train.append(res.rms_after[0])
        ok.append(res.success)
        results.append(res)
    return CrossValidation(k, np.array(held), np.array(pred), np.array(train),
                           np.array(ok, dtype=bool), tuple(results))
