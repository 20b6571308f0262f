"""Issue 33, deliver 2: success only when the residual is consistent with the stated noise."""

from __future__ import annotations

import numpy as np
import pytest

import serialkin as sk
from serialkin.calibration import (
    ChiSquare,
    calibrate,
    make_measurements,
    perturb_joints,
    simulate_measurements,
)
from serialkin.errors import InputError

NOISE = 5e-5


@pytest.fixture(scope="module")
def ur5_truth():
    """The UR5 with joint-origin errors and a 5 cm marker, and 80 configurations."""
    robot = sk.models.ur5()
    truth = perturb_joints(robot, marker=0.05, seed=1)
    return robot, truth, robot.random_q(80, seed=3)


def _noisy(robot, q, positions, seed=0, sigma=NOISE):
    pos = positions + np.random.default_rng(seed).normal(0.0, NOISE, positions.shape)
    return make_measurements(robot, q, positions=pos, sigma_position=sigma)


def test_chi_square_has_the_right_degrees_of_freedom(ur5_truth):
    """Degrees of freedom 3 × measurements − fitted parameters; χ²/dof ≈ 1 when right."""
    robot, truth, q = ur5_truth
    res = calibrate(robot, _noisy(robot, q, truth.fk(q)[:, :3, 3]))
    assert res.success, res.reason
    chi = res.chi_square
    assert chi.dof == 80 * 3 - res.identifiability.rank == 213
    assert 0.8 < chi.noise_ratio < 1.2 and chi.p_value > 1e-3
    assert chi.chi2 == pytest.approx(np.sum((res.errors_after / NOISE) ** 2))
    assert "times the stated noise" not in res.summary()
    assert "× the stated noise" in res.summary()


def test_correct_fits_rarely_fail_the_test(ur5_truth):
    """Over 30 noise draws with the stated sigma right, at most one false alarm (α = 1e-3)."""
    robot, truth, q = ur5_truth
    p = [calibrate(robot, _noisy(robot, q, truth.fk(q)[:, :3, 3], seed=s)).chi_square.p_value
         for s in range(30)]
    assert sum(v < 1e-3 for v in p) <= 1
    assert 0.2 < np.median(p) < 0.8  # roughly uniform under the hypothesis


def test_unmodelled_encoder_scale_fails_with_the_hint(ur5_truth):
    """A 1e-4 scale error of joint 2's encoder (not in the model): success=False, 2.5σ."""
    robot, truth, q = ur5_truth
    qs = q.copy()
    qs[:, 1] *= 1 + 1e-4
    res = calibrate(robot, _noisy(robot, q, truth.fk(qs)[:, :3, 3]))
    assert not res.success
    assert res.chi_square.noise_ratio > 2
    assert "times the stated measurement noise" in res.reason
    for hint in ("units", "wrong robot", "joint order", "encoder scale"):
        assert hint in res.reason
    # the geometry is still returned, the test can be turned off
    assert calibrate(robot, _noisy(robot, q, truth.fk(qs)[:, :3, 3]), significance=0).success


def test_understated_noise_fails(ur5_truth):
    """The same good data stated as 10 µm instead of 50 µm: the test catches it."""
    robot, truth, q = ur5_truth
    res = calibrate(robot, _noisy(robot, q, truth.fk(q)[:, :3, 3], sigma=1e-5))
    assert not res.success and "sigma_position" in res.reason


@pytest.mark.parametrize("case", ["millimetres", "swapped joints", "another robot"])
def test_wrong_units_order_or_robot_fail_with_the_hint(ur5_truth, case):
    """Positions in mm, columns q5/q6 swapped, Puma 560 data: success=False, naming causes."""
    robot, truth, q = ur5_truth
    pos = truth.fk(q)[:, :3, 3]
    if case == "millimetres":
        meas = _noisy(robot, q, pos * 1000.0)
    elif case == "swapped joints":
        meas = _noisy(robot, q[:, [0, 1, 2, 3, 5, 4]], pos)
    else:
        robot = sk.models.puma560()
        meas = _noisy(robot, q, pos)
    res = calibrate(robot, meas)
    assert not res.success
    assert "joint order" in res.reason and "millimetres" in res.reason


def test_robust_loss_tests_the_inliers(ur5_truth):
    """5 blunders of 1 cm among 80: least squares fails the test, soft-L1 passes it."""
    robot, truth, q = ur5_truth
    meas = _noisy(robot, q, truth.fk(q)[:, :3, 3])
    pos = np.array(meas.positions)
    pos[:5] += 0.01
    bad = make_measurements(robot, q, positions=pos, sigma_position=NOISE)
    plain = calibrate(robot, bad)
    assert not plain.success and "outliers" in plain.reason
    robust = calibrate(robot, bad, loss="soft_l1", loss_scale=3.0)
    assert robust.success, robust.reason
    assert robust.chi_square.outliers == 5 and robust.chi_square.dof == 75 * 3 - 27


def test_chi_square_verdict_and_bad_significance():
    """Verdicts: '' when consistent or without dof; more than half outliers is a failure."""
    assert ChiSquare(100.0, 100, 0.48, 1.0).verdict() == ""
    assert ChiSquare(1.0, 0, float("nan"), float("nan")).verdict() == ""
    assert "more than half" in ChiSquare(1.0, 10, 0.9, 0.3, outliers=6, measurements=10).verdict()
    robot = sk.models.ur5()
    meas = simulate_measurements(robot, 20, seed=1)
    with pytest.raises(InputError, match="significance"):
        calibrate(robot, meas, significance=1.5)
