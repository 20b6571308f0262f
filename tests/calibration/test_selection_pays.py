"""Issue 33 acceptance: observability-based pose selection pays against random poses."""

from __future__ import annotations

import numpy as np

import serialkin as sk
from serialkin.calibration import (
    calibrate,
    error_model,
    perturb_joints,
    select_poses,
    simulate_measurements,
)


def test_selected_poses_give_a_lower_median_validation_error_over_20_seeds():
    """UR5, 15 positions (50 µm noise): O1-selected beat random ones of the same candidates.

    Per seed: a truth with joint errors and an 8 cm marker, 150 random candidates, 15
    chosen by select_poses against 15 drawn at random; the median validation RMS over 20
    seeds is lower for the selected ones (measured 70 µm against 86 µm, 18 of 20 seeds).
    """
    robot = sk.models.ur5()
    model = error_model(robot)
    selected, random_ = [], []
    for seed in range(20):
        rng = np.random.default_rng(seed)
        truth = perturb_joints(robot, marker=0.08, seed=rng)
        cand = robot.random_q(150, seed=rng)
        chosen = select_poses(model, cand, 15, seed=rng)
        drawn = rng.choice(len(cand), 15, replace=False)
        qv = robot.random_q(300, seed=rng)
        for idx, out in ((chosen, selected), (drawn, random_)):
            meas = simulate_measurements(truth, cand[idx], noise_position=5e-5, seed=rng)
            res = calibrate(model, meas)
            err = np.linalg.norm(res.robot.fk(qv)[:, :3, 3] - truth.fk(qv)[:, :3, 3], axis=1)
            out.append(float(np.sqrt(np.mean(err**2))))
    assert np.median(selected) < np.median(random_)
    assert sum(a < b for a, b in zip(selected, random_)) >= 12
