"""Issue 33, item 4: joint offset and encoder scale as identifiable parameters."""

from __future__ import annotations

import numpy as np
import pytest

import serialkin as sk
from serialkin.calibration import (
    calibrate,
    error_model,
    perturb,
    perturb_joints,
    simulate_measurements,
)
from serialkin.calibration.jacobian import errors


@pytest.mark.parametrize("arm", ["ur5", "stanford"])
def test_encoder_scale_error_of_0_2_percent_is_recovered(arm):
    """Joint 2 reading 0.2 % short: the scale comes back to 1e-9, validation ≤ 1 µm."""
    robot = sk.models.get(arm)
    truth = perturb_joints(robot, marker=0.08, seed=1)
    scale = np.ones(robot.n)
    scale[1] = 1.002
    meas = simulate_measurements(truth, 300, noise_position=0.0, joint_scale=scale, seed=2)
    res = calibrate(error_model(robot, scale=True), meas)
    assert res.success, res.reason
    np.testing.assert_allclose(res.encoder_scale, scale, atol=1e-9)
    q_true = robot.random_q(1000, seed=3)
    recorded = q_true / scale
    err = np.linalg.norm(res.robot.fk(res.joint_values(recorded))[:, :3, 3]
                         - truth.fk(q_true)[:, :3, 3], axis=1)
    assert np.sqrt(np.mean(err**2)) <= 1e-6


def test_scale_error_unmodelled_fails_the_chi_square_test():
    """Without scale parameters the same data (50 µm noise) fail honestly; with them pass."""
    robot = sk.models.ur5()
    truth = perturb_joints(robot, marker=0.08, seed=1)
    scale = np.ones(robot.n)
    scale[1] = 1.002
    meas = simulate_measurements(truth, 80, noise_position=5e-5, joint_scale=scale, seed=2)
    assert not calibrate(robot, meas).success
    res = calibrate(error_model(robot, scale=True), meas)
    assert res.success, res.reason
    assert abs(res.encoder_scale[1] - 1.002) < 5 * res.std_errors[res.model.names.index(
        "scale2")]


@pytest.mark.parametrize("kind", ["dh", "joints"])
def test_scale_columns_match_finite_differences(kind):
    """∂e/∂s = q · (the virtual joint's column), checked by central differences."""
    robot = sk.models.ur5()
    model = error_model(robot, kind, scale=True)
    p = perturb(model, seed=1)
    meas = simulate_measurements(model.calibrated_robot(p), 5, kind="pose",
                                 noise_position=0.0, seed=2)
    _, J = errors(model, meas, p, jacobian=True)
    for k, par in enumerate(model.parameters):
        if par.unit != "1":
            continue
        h = 1e-6
        dp = np.zeros(model.size)
        dp[k] = h
        fd = (errors(model, meas, p + dp)[0] - errors(model, meas, p - dp)[0]) / (2 * h)
        np.testing.assert_allclose(J[:, :, k], fd, atol=1e-7)


def test_regressors_are_one_except_for_scales():
    """The extension point: g_k(q) is 1 for geometric parameters and q_i for scale i."""
    robot = sk.models.puma560()
    model = error_model(robot, scale=True)
    q = robot.random_q(7, seed=1)
    g = model.regressors(q)
    for k, par in enumerate(model.parameters[:model.chain_size]):
        want = q[:, par.regressor] if par.regressor >= 0 else np.ones(7)
        np.testing.assert_array_equal(g[:, k], want)
    assert sum(p.unit == "1" for p in model.parameters) == robot.n
