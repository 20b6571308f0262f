"""Kinematic calibration: identify a robot's real geometry from measurements.

* :mod:`~serialkin.calibration.models` — error models (DH with Hayati's β, joint origin
  and axis errors, base and tool) as an extended chain;
* :mod:`~serialkin.calibration.measurements` — pose / position measurements, CSV files;
* :mod:`~serialkin.calibration.jacobian` — residuals and the identification Jacobian;
* :mod:`~serialkin.calibration.identifiability` — SVD, condition number, minimal set;
* :mod:`~serialkin.calibration.fit` — :func:`calibrate` (scipy least squares, staged,
  chi-square test, covariance);
* :mod:`~serialkin.calibration.crossval` — k-fold cross-validation of a calibration;
* :mod:`~serialkin.calibration.selection` — choosing poses by observability indices;
* :mod:`~serialkin.calibration.simulate` — perturbed robots and noisy measurements;
* :mod:`~serialkin.calibration.export` — the calibrated robot: the user's URDF patched, a
  URDF, or a robot file (refused when its DH table would not be physical).

See ``docs/calibration.md``.
"""

from serialkin.calibration.crossval import CrossValidation, cross_validate, holdout_errors
from serialkin.calibration.export import UrdfPatch, patch_urdf, save_robot
from serialkin.calibration.fit import CalibrationResult, ChiSquare, calibrate
from serialkin.calibration.identifiability import Identifiability, identifiability
from serialkin.calibration.measurements import (
    Measurements,
    make_measurements,
    read_measurements,
    write_measurements,
)
from serialkin.calibration.models import ErrorModel, Parameter, error_model
from serialkin.calibration.selection import observability, select_poses
from serialkin.calibration.simulate import perturb, perturb_joints, simulate_measurements

__all__ = [
    "CalibrationResult",
    "ChiSquare",
    "CrossValidation",
    "ErrorModel",
    "Identifiability",
    "Measurements",
    "Parameter",
    "UrdfPatch",
    "calibrate",
    "cross_validate",
    "error_model",
    "holdout_errors",
    "identifiability",
    "make_measurements",
    "observability",
    "patch_urdf",
    "perturb",
    "perturb_joints",
    "read_measurements",
    "save_robot",
    "select_poses",
    "simulate_measurements",
    "write_measurements",
]
