"""Issue 33, deliver 3: parameter covariance, predicted validation error, cross-validation."""

from __future__ import annotations

import numpy as np
import pytest

import serialkin as sk
from serialkin.calibration import (
    calibrate,
    cross_validate,
    holdout_errors,
    make_measurements,
    perturb_joints,
    simulate_measurements,
)
from serialkin.errors import InputError

NOISE = 5e-5


@pytest.fixture(scope="module")
def ur5_fit():
    """UR5 with joint-origin errors and a 5 cm marker; 80 positions with 50 µm noise."""
    robot = sk.models.ur5()
    truth = perturb_joints(robot, marker=0.05, seed=1)
    meas = simulate_measurements(truth, 80, noise_position=NOISE, seed=2)
    return robot, truth, meas, calibrate(robot, meas)


def test_covariance_is_the_fitted_block(ur5_fit):
    """Covariance (p, p): SPD over the fitted set, NaN elsewhere, diagonal = std errors²."""
    _, _, _, res = ur5_fit
    fit = res.identifiability.identifiable
    C = res.covariance
    assert C.shape == (res.model.size, res.model.size)
    block = C[np.ix_(fit, fit)]
    np.testing.assert_allclose(block, block.T, rtol=0, atol=1e-20)
    assert np.linalg.eigvalsh(block).min() > 0
    assert np.isnan(C[~fit]).all() and np.isnan(C[:, ~fit]).all()
    np.testing.assert_allclose(np.sqrt(np.diag(block)), res.std_errors[fit], rtol=1e-12)


def test_predicted_error_matches_the_validation_error():
    """The predicted RMS error at 1,000 configurations is the validation RMS vs the truth.

    Over 8 seeds: the median ratio within ±25 %, each within a factor 2.
    """
    robot = sk.models.ur5()
    ratios = []
    for seed in range(8):
        truth = perturb_joints(robot, marker=0.05, seed=seed)
        res = calibrate(robot, simulate_measurements(truth, 80, noise_position=NOISE,
                                                     seed=seed + 100))
        q = robot.random_q(1000, seed=seed + 200)
        err = np.linalg.norm(res.robot.fk(q)[:, :3, 3] - truth.fk(q)[:, :3, 3], axis=1)
        ratios.append(np.sqrt(np.mean(err**2)) / res.predicted_error(q))
    assert 0.75 < np.median(ratios) < 1.25
    assert all(0.5 < r < 2.0 for r in ratios)


def test_predicted_error_scales_with_the_measurements(ur5_fit):
    """Four times the measurements: about half the predicted error."""
    robot, truth, _, res = ur5_fit
    more = calibrate(robot, simulate_measurements(truth, 320, noise_position=NOISE, seed=3))
    assert 0.35 < more.predicted_error() / res.predicted_error() < 0.7
    assert res.predicted_error(count=50, seed=1) > 0


def test_cross_validation_agrees_with_the_prediction(ur5_fit):
    """5 folds: held-out RMS (noise included) within ±30 % of the prediction.

    It is above the training RMS; every fold succeeds; the summary has a line per fold.
    """
    robot, _, meas, _ = ur5_fit
    cv = cross_validate(robot, meas, folds=5, seed=0)
    assert cv.folds == 5 and cv.success.all() and len(cv.results) == 5
    assert 0.7 < cv.ratio < 1.3
    assert cv.rms > np.sqrt(np.mean(cv.train_rms**2))
    assert cv.summary().count("\n  fold ") == 5
    e = holdout_errors(cv.results[0], meas)
    assert e.shape == (80, 3)


def test_cross_validation_bad_input():
    """Fewer measurements than folds, and too few per fit, are input errors."""
    robot = sk.models.ur5()
    meas = simulate_measurements(robot, 12, seed=1)
    with pytest.raises(InputError, match="at least 20 measurements"):
        cross_validate(robot, meas, folds=20)
    with pytest.raises(InputError, match="too few measurements"):
        cross_validate(robot, meas, folds=2)  # 6 per fit, 9 needed
    good = make_measurements(robot, meas.q, positions=meas.positions)
    with pytest.raises(InputError, match="folds"):
        cross_validate(robot, good, folds=1)
