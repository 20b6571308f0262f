"""The calibration fit: the issue's acceptance cases and bad input."""

from __future__ import annotations

import numpy as np
import pytest

import serialkin as sk
from serialkin.calibration import (
    calibrate,
    error_model,
    identifiability,
    make_measurements,
    perturb,
    simulate_measurements,
)
from serialkin.errors import InputError

MARKER = sk.spatial.make_transform(p=[0.05, 0.02, 0.06])  # a tracker target on a bracket


@pytest.fixture(scope="module", params=["bracket", "flange"])
def ur5_case(request):
    """UR5, every parameter perturbed (±1 mm, ±0.5°), 60 positions with 0.05 mm noise.

    The target sits on a bracket (off joint 6's axis) or on the flange centre (on it).
    """
    robot = sk.models.ur5()
    if request.param == "bracket":
        robot = robot.with_tool(MARKER)
    model = error_model(robot)
    real = model.calibrated_robot(perturb(model, length=1e-3, angle=np.radians(0.5), seed=3))
    meas = simulate_measurements(real, 60, noise_position=5e-5, seed=4)
    return model, real, meas, calibrate(model, meas)


def test_ur5_positions_residual_at_noise_level(ur5_case):
    """The residual RMS per coordinate after the fit is the 0.05 mm noise (± 25 %)."""
    _, _, _, res = ur5_case
    assert res.success, res.reason
    per_coordinate = res.rms_after[0] / np.sqrt(3)
    assert 0.75 * 5e-5 < per_coordinate < 1.25 * 5e-5
    assert res.rms_before[0] > 1e-3  # the nominal model is millimetres off


def test_ur5_validation_error_below_a_tenth_of_a_millimetre(ur5_case):
    """Over 1,000 validation configurations the calibrated position error is ≤ 0.1 mm RMS."""
    model, real, _, res = ur5_case
    q = model.robot.random_q(1000, seed=99)
    err = np.linalg.norm(res.robot.fk(q)[:, :3, 3] - real.fk(q)[:, :3, 3], axis=1)
    assert np.sqrt(np.mean(err**2)) <= 1e-4


def test_ur5_unidentifiable_parameters_are_flagged_not_fitted(ur5_case):
    """Tool rotations and the redundant link parameters keep their nominal values."""
    model, _, _, res = ur5_case
    ident = res.identifiability
    for name in ("tool rx", "tool ry", "tool rz", "d1", "theta1"):
        i = model.names.index(name)
        assert not ident.identifiable[i]
        assert res.params[i] == model.nominal[i]
        assert np.isnan(res.std_errors[i])
    if model.robot.tool[0, 3]:
        assert ident.rank == 27
    else:
        # on the nominal flange centre the target cannot see joint 6's axis (2 fewer); the
        # fitted target sits about 0.9 mm off it (the perturbed tool), where the analysis
        # redone at the solution finds a5 determined to 0.6 mm and alpha5 too weakly
        _, _, meas, _ = ur5_case
        assert identifiability(model, meas).rank == 25
        assert ident.rank == 26 and ident.identifiable[model.names.index("a5")]
        assert any(r.startswith("alpha5 is too weakly determined") for r in ident.reasons)


def test_standard_errors_cover_the_fitted_changes(ur5_case):
    """The fitted position parameters' standard errors are of the order σ-propagated values."""
    _, _, _, res = ur5_case
    fitted = res.identifiability.identifiable
    se = res.std_errors[fitted]
    assert np.all(np.isfinite(se)) and np.all(se > 0)
    lengths = np.array([p.unit == "m" for p in res.model.parameters])[fitted]
    assert np.median(se[lengths]) < 2e-4  # well below the 1 mm perturbations


@pytest.mark.parametrize("name", ["ur5", "panda", "stanford"])
def test_noise_free_poses_recover_the_parameters(name):
    """With exact full-pose measurements the perturbed identifiable parameters come back to 1e-8."""
    robot = sk.models.get(name)
    model = error_model(robot)
    q = robot.random_q(30, seed=1)
    ident = calibrate(model, make_measurements(robot, q, poses=robot.fk(q))).identifiability
    truth = model.nominal.copy()
    keep = ident.identifiable
    truth[keep] = perturb(model, seed=2)[keep]
    meas = make_measurements(robot, q, poses=model.fk(q, truth))
    res = calibrate(model, meas)
    assert res.success, res.reason
    np.testing.assert_allclose(res.params, truth, atol=1e-8, rtol=0)


def test_joint_model_calibrates_a_urdf_robot():
    """The joint-origin model fits a robot of general joints to the noise level."""
    robot = sk.Robot.from_urdf(sk.models.ur5().to_urdf()).with_tool(MARKER)
    model = error_model(robot)
    assert model.kind == "joints"
    dh_model = error_model(sk.models.ur5().with_tool(MARKER))
    real = dh_model.calibrated_robot(perturb(dh_model, seed=5))
    meas = simulate_measurements(real, 60, noise_position=5e-5, seed=6)
    res = calibrate(model, meas)
    assert res.success and res.identifiability.rank == 27
    q = robot.random_q(300, seed=7)
    err = np.linalg.norm(res.robot.fk(q)[:, :3, 3] - real.fk(q)[:, :3, 3], axis=1)
    assert np.sqrt(np.mean(err**2)) <= 1e-4


def test_robust_loss_resists_outliers():
    """With 5 gross outliers, a soft-L1 loss fits the clean robot far better than least squares."""
    robot = sk.models.ur5().with_tool(MARKER)
    model = error_model(robot)
    real = model.calibrated_robot(perturb(model, seed=8))
    meas = simulate_measurements(real, 60, noise_position=5e-5, seed=9)
    pos = np.array(meas.positions)
    pos[:5] += 0.01  # 1 cm blunders
    bad = make_measurements(robot, meas.q, positions=pos, sigma_position=5e-5)
    q = robot.random_q(300, seed=10)

    def rms(res):
        e = np.linalg.norm(res.robot.fk(q)[:, :3, 3] - real.fk(q)[:, :3, 3], axis=1)
        return np.sqrt(np.mean(e**2))

    plain, robust = calibrate(model, bad), calibrate(model, bad, loss="soft_l1", loss_scale=3.0)
    assert rms(robust) < 1e-4 < rms(plain)
    assert rms(robust) * 5 < rms(plain)


def test_non_convergence_is_a_result():
    """A budget of one evaluation gives success=False with the reason, not an exception."""
    robot = sk.models.ur5().with_tool(MARKER)
    model = error_model(robot)
    real = model.calibrated_robot(perturb(model, seed=11))
    res = calibrate(model, simulate_measurements(real, 30, seed=12), max_evaluations=1)
    assert not res.success
    assert "not converged within 1 evaluations" in res.reason
    assert np.isfinite(res.params).all()
    assert "NOT converged" in res.summary()


def test_too_few_measurements_says_how_many():
    """Five position measurements for 27 identifiable parameters: the message asks for 9."""
    robot = sk.models.ur5().with_tool(MARKER)
    meas = simulate_measurements(robot, 5, seed=13)
    with pytest.raises(InputError, match=r"27 parameters .* at least 9 are needed"):
        calibrate(robot, meas)


def test_measurements_of_another_robot_are_refused():
    """Measurements with 7 joint values for a 6-joint robot raise, naming both counts."""
    panda = sk.models.panda()
    meas = simulate_measurements(panda, 40, seed=14)
    with pytest.raises(InputError, match="7 joint values each but robot 'UR5' has 6 joints"):
        calibrate(sk.models.ur5(), meas)
    with pytest.raises(InputError, match="6 joints"):
        make_measurements(sk.models.ur5(), meas.q, positions=meas.positions)


def test_residual_and_parameter_tables():
    """The report has one row per measurement and one per parameter, before ≥ after overall."""
    robot = sk.models.ur5().with_tool(MARKER)
    model = error_model(robot)
    real = model.calibrated_robot(perturb(model, seed=15))
    res = calibrate(model, simulate_measurements(real, 40, kind="pose", noise_rotation=1e-4,
                                                 seed=16))
    header, rows = res.residual_table()
    assert header[-1] == "rotation_after_rad" and rows.shape == (40, 5)
    assert rows[:, 1].mean() > rows[:, 2].mean() and rows[:, 3].mean() > rows[:, 4].mean()
    table = res.parameter_table()
    assert len(table) == model.size and sum(r["fitted"] for r in table) == 30


def test_standard_errors_match_the_spread_over_noise_draws():
    """Over 40 noise draws the fitted parameters scatter as their standard errors predict."""
    robot = sk.models.ur5().with_tool(MARKER)
    model = error_model(robot)
    real = model.calibrated_robot(perturb(model, seed=20))
    q = robot.random_q(40, seed=21)
    fits, ses = [], []
    for seed in range(40):
        res = calibrate(model, simulate_measurements(real, q, noise_position=5e-5, seed=seed))
        fits.append(res.params)
        ses.append(res.std_errors)
    keep = res.identifiability.identifiable
    spread = np.std(np.array(fits)[:, keep], axis=0, ddof=1)
    predicted = np.median(np.array(ses)[:, keep], axis=0)
    ratio = spread / predicted
    # 40 draws: the sample std is within ±25 % of the truth with high probability
    assert 0.75 < np.median(ratio) < 1.25
    assert np.all((ratio > 0.5) & (ratio < 1.6))
