"""Issue 33, item 5: every measurement kind recovers the truth without noise (≤ 1 µm).

Truths from ``perturb_joints`` (joint origins moved ≤ 1 mm and tilted ≤ 0.3° in all six
directions, an 8 cm marker); validation RMS position error at 1,000 other configurations.
"""

from __future__ import annotations

import numpy as np
import pytest

import serialkin as sk
from serialkin.calibration import (
    calibrate,
    error_model,
    make_measurements,
    perturb_joints,
    read_measurements,
    simulate_measurements,
    write_measurements,
)
from serialkin.errors import InputError
from serialkin.spatial import make_transform
from serialkin.spatial.lie import so3_exp

ARMS = ["ur5", "panda"]
MARKERS = np.array([[0.0, 0.0, 0.0], [0.05, -0.03, 0.02], [-0.04, 0.06, 0.01]])


def _validation_rms(robot, calibrated, truth):
    q = robot.random_q(1000, seed=3)
    err = np.linalg.norm(calibrated.fk(q)[:, :3, 3] - truth.fk(q)[:, :3, 3], axis=1)
    return float(np.sqrt(np.mean(err**2)))


@pytest.mark.parametrize("arm", ARMS)
def test_positions(arm):
    """Marker positions: validation RMS ≤ 1 µm."""
    robot = sk.models.get(arm)
    truth = perturb_joints(robot, marker=0.08, seed=1)
    res = calibrate(robot, simulate_measurements(truth, 200, noise_position=0.0, seed=2))
    assert res.success, res.reason
    assert _validation_rms(robot, res.robot, truth) <= 1e-6


@pytest.mark.parametrize("arm", ARMS)
def test_full_poses(arm):
    """Full poses: validation RMS ≤ 1 µm, and the tool rotation is identified too."""
    robot = sk.models.get(arm)
    truth = perturb_joints(robot, marker=0.08, seed=1)
    meas = simulate_measurements(truth, 100, kind="pose", noise_position=0.0, seed=2)
    res = calibrate(robot, meas)
    assert res.success, res.reason
    assert _validation_rms(robot, res.robot, truth) <= 1e-6
    q = robot.random_q(50, seed=4)
    R = res.robot.fk(q)[:, :3, :3] @ np.swapaxes(truth.fk(q)[:, :3, :3], 1, 2)
    assert np.abs(R - np.eye(3)).max() < 1e-9


@pytest.mark.parametrize("arm", ARMS)
def test_several_markers(arm):
    """Three markers measured in turn: robot and marker offsets recovered (≤ 1 µm)."""
    robot = sk.models.get(arm)
    truth = perturb_joints(robot, marker=0.08, seed=1)
    meas = simulate_measurements(truth, 240, noise_position=0.0, markers=MARKERS, seed=2)
    assert set(meas.markers.tolist()) == {0, 1, 2}
    res = calibrate(error_model(robot, markers=3), meas)
    assert res.success, res.reason
    assert _validation_rms(robot, res.robot, truth) <= 1e-6
    # each marker's point, calibrated against true, at other configurations
    q = robot.random_q(200, seed=5)
    Tc, Tt = res.robot.fk(q), truth.fk(q)
    for k in range(3):
        pc = Tc[:, :3, 3] + Tc[:, :3, :3] @ res.marker_offsets[k]
        pt = Tt[:, :3, 3] + Tt[:, :3, :3] @ MARKERS[k]
        assert np.abs(pc - pt).max() < 1e-6


def test_marker_column_round_trips_and_is_checked(tmp_path):
    """The CSV 'marker' column (1-based) round-trips; a model with too few markers refuses."""
    robot = sk.models.ur5()
    meas = simulate_measurements(robot, 9, noise_position=0.0, markers=MARKERS, seed=2)
    back = read_measurements(write_measurements(tmp_path / "m.csv", meas), robot)
    np.testing.assert_array_equal(back.markers, meas.markers)
    with pytest.raises(InputError, match="markers=3"):
        calibrate(robot, back)
    with pytest.raises(InputError, match="markers must be integers"):
        make_measurements(robot, meas.q, positions=meas.positions, markers=[0.5] * 9)


@pytest.mark.parametrize("arm", ARMS)
def test_unknown_device_frame(arm):
    """A tracker 3 m away and turned by 130°: frame='unknown' registers it first (≤ 1 µm)."""
    robot = sk.models.get(arm)
    truth = perturb_joints(robot, marker=0.08, seed=1)
    device = make_transform(so3_exp(np.array([0.3, -1.2, 1.9])), [1.5, -2.0, 0.7])
    seen = truth.with_base(device @ truth.base)
    meas = simulate_measurements(seen, 200, noise_position=0.0, seed=2)
    res = calibrate(robot, meas, frame="unknown")
    assert res.success, res.reason
    assert _validation_rms(robot, res.robot, seen) <= 1e-6
    # the base found is the device's frame, up to the joint errors it absorbs (d1, θ1: ≤ 1°)
    R = res.robot.base[:3, :3].T @ seen.base[:3, :3]
    assert np.arccos(np.clip((np.trace(R) - 1) / 2, -1, 1)) < np.radians(1.0)
    assert np.linalg.norm(res.robot.base[:3, 3] - seen.base[:3, 3]) < 0.01


def test_unknown_frame_needs_the_base_errors():
    """frame='unknown' with a model without base errors is an input error."""
    robot = sk.models.ur5()
    meas = simulate_measurements(robot, 20, noise_position=0.0, seed=2)
    with pytest.raises(InputError, match="base"):
        calibrate(error_model(robot, base=False), meas, frame="unknown")
