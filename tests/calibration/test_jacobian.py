"""The identification Jacobian equals finite differences of the residuals."""

from __future__ import annotations

import numpy as np
import pytest

import serialkin as sk
from serialkin.calibration import error_model, make_measurements, perturb
from serialkin.calibration.jacobian import errors, whitened


def _fd(model, meas, p, h=1e-7):
    J = np.empty((len(meas) * meas.rows, model.size))
    for k in range(model.size):
        dp = np.zeros(model.size)
        dp[k] = h
        J[:, k] = (whitened(model, meas, p + dp)[0] - whitened(model, meas, p - dp)[0]) / (2 * h)
    return J


@pytest.mark.parametrize("name,kind", [("ur5", "dh"), ("panda", "dh"), ("stanford", "dh"),
                                       ("ur5", "joints")])
@pytest.mark.parametrize("measure", ["position", "pose"])
def test_identification_jacobian_matches_finite_differences(name, kind, measure):
    """∂r/∂p from the kernels equals central differences, away from the nominal values too."""
    robot = sk.models.get(name)
    model = error_model(robot, kind)
    rng = np.random.default_rng(5)
    q = robot.random_q(6, seed=rng)
    real = model.calibrated_robot(perturb(model, length=0.01, angle=0.05, seed=rng))
    T = real.fk(q)
    meas = (make_measurements(robot, q, positions=T[:, :3, 3]) if measure == "position"
            else make_measurements(robot, q, poses=T))
    p = perturb(model, length=0.005, angle=0.03, seed=rng)
    _, J = whitened(model, meas, p, jacobian=True)
    scale = np.abs(J).max()
    np.testing.assert_allclose(J / scale, _fd(model, meas, p) / scale, atol=1e-6)


def test_errors_vanish_for_the_true_parameters():
    """The residual of measurements of model(p) is zero at p."""
    model = error_model(sk.models.puma560())
    p = perturb(model, seed=3)
    q = model.robot.random_q(5, seed=4)
    meas = make_measurements(model.robot, q, poses=model.fk(q, p))
    e, _ = errors(model, meas, p)
    assert np.abs(e).max() < 1e-12
