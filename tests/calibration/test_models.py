"""Error models: the extended chain reproduces the robot, and calibrated robots match it."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import serialkin as sk
from serialkin.calibration import error_model, perturb
from serialkin.errors import InputError
from tests.kinematics._fd import dh_rows, random_transform


@pytest.mark.parametrize("name", ["ur5", "puma560", "panda", "stanford"])
@pytest.mark.parametrize("kind", ["dh", "joints"])
def test_nominal_model_reproduces_the_robot(name, kind):
    """At nominal parameters the extended chain and the calibrated robot equal robot.fk."""
    robot = sk.models.get(name)
    model = error_model(robot, kind)
    q = robot.random_q(8, seed=1)
    np.testing.assert_allclose(model.fk(q), robot.fk(q), atol=1e-12)
    np.testing.assert_allclose(model.calibrated_robot(model.nominal).fk(q), robot.fk(q),
                               atol=1e-12)


@settings(max_examples=25, deadline=None)
@given(rows=dh_rows(), convention=st.sampled_from(["standard", "modified"]),
       kind=st.sampled_from(["dh", "joints"]), seed=st.integers(0, 2**32 - 1))
def test_calibrated_robot_matches_the_extended_chain(rows, convention, kind, seed):
    """For random DH tables and parameters, calibrated_robot(p).fk == model.fk(·, p)."""
    rng = np.random.default_rng(seed)
    robot = sk.Robot.from_dh(rows, convention, base=random_transform(rng),
                             tool=random_transform(rng))
    model = error_model(robot, kind, hayati=[1])
    p = perturb(model, length=0.05, angle=0.1, seed=rng)
    q = robot.random_q(5, seed=rng)
    np.testing.assert_allclose(model.calibrated_robot(p).fk(q), model.fk(q, p), atol=1e-10)


def test_hayati_links_are_the_parallel_axes():
    """'auto' puts β on links with parallel consecutive axes and leaves their d out."""
    ur5 = error_model(sk.models.ur5())
    assert ur5.hayati == (1, 2)
    assert "beta2" in ur5.names and "beta3" in ur5.names
    assert "d2" not in ur5.names and "d3" not in ur5.names and "d4" in ur5.names
    puma = error_model(sk.models.puma560())
    assert puma.hayati == (1,) and "beta2" in puma.names and "d2" not in puma.names
    assert error_model(sk.models.puma560(), hayati="none").hayati == ()


def test_plain_dh_model_gives_a_dh_robot():
    """Without β the calibrated robot keeps a DH table with the fitted values."""
    model = error_model(sk.models.panda())
    p = perturb(model, seed=2)
    robot = model.calibrated_robot(p)
    assert robot.dh is not None and robot.convention == "modified"
    values = dict(zip(model.names, p))
    assert robot.dh[3].a == pytest.approx(values["a4"])
    assert robot.dh[2].d == pytest.approx(values["d3"])


def test_parameter_counts():
    """DH: 4 per link + β per Hayati link − the d it replaces + 12; joints: 7 per joint + 12."""
    assert error_model(sk.models.panda()).size == 4 * 7 + 12
    assert error_model(sk.models.ur5()).size == 4 * 6 + 12
    assert error_model(sk.models.ur5(), "joints").size == 7 * 6 + 12
    assert error_model(sk.models.ur5(), base=False, tool=False, hayati="none").size == 24


def test_bad_model_arguments():
    """Unknown kind, 'dh' without a table and a bad Hayati list raise InputError."""
    robot = sk.models.ur5()
    with pytest.raises(InputError, match="kind"):
        error_model(robot, "poe")
    general = sk.Robot.from_joints(list(robot.joints))
    with pytest.raises(InputError, match="DH table"):
        error_model(general, "dh")
    with pytest.raises(InputError, match="outside 1..6"):
        error_model(robot, hayati=[7])


def test_dh_calibration_keeps_the_collision_model():
    """A calibrated plain-DH robot carries the nominal capsules; a general-joint one none."""
    robot = sk.models.ur5()
    plain = error_model(robot, hayati="none")
    assert plain.calibrated_robot(perturb(plain, seed=0)).collision is robot.collision
    hayati = error_model(robot)
    assert hayati.calibrated_robot(perturb(hayati, seed=0)).collision is None
