"""Bad input to the core API: each error names the argument, the expectation and the value."""

from __future__ import annotations

import numpy as np
import pytest

import serialkin as sk
from serialkin import models
from serialkin.errors import InputError, InputTypeError, RobotDefinitionError, SerialkinError

ROW = {"a": 0.1, "alpha": 0.0, "d": 0.2, "theta": 0.0}


@pytest.fixture(scope="module")
def ur5():
    return models.ur5()


@pytest.mark.parametrize("call", ["fk", "fk_all", "jacobian", "within_limits"])
@pytest.mark.parametrize("q", [np.zeros(5), [0.0] * 5, np.zeros((3, 5))],
                         ids=["array", "list", "batch"])
def test_wrong_q_size_names_robot_and_counts(ur5, call, q):
    """A q with 5 values for the 6-joint UR5 is refused with both counts and the robot name."""
    with pytest.raises(InputError, match=r"q has 5 values but robot 'UR5' has 6 joints"):
        getattr(ur5, call)(q)


def test_scalar_q(ur5):
    """A scalar q is refused as a scalar, not broadcast."""
    with pytest.raises(InputError, match=r"q has a scalar but robot 'UR5' has 6 joints"):
        ur5.fk(0.0)


@pytest.mark.parametrize("bad", [np.nan, np.inf, -np.inf])
@pytest.mark.parametrize("call", ["fk", "fk_all", "jacobian"])
def test_nonfinite_q(ur5, call, bad):
    """NaN or inf in q raises 'q must be finite' (never a NaN pose)."""
    for q in (np.array([0, 0, bad, 0, 0, 0.0]), np.array([[0.0] * 6, [bad] * 6])):
        with pytest.raises(InputError, match="q must be finite"):
            getattr(ur5, call)(q)
    with pytest.raises(InputError, match="q must be finite"):
        ur5.jacobian(np.array([0, 0, bad, 0, 0, 0.0]), frame="ee")


@pytest.mark.parametrize("q", ["abc", np.zeros(6, dtype=complex), [None] * 6, {"q": 1}])
def test_non_numeric_q(ur5, q):
    """Strings, complex numbers, None and mappings are a type error naming q."""
    with pytest.raises(InputTypeError, match="q must be"):
        ur5.fk(q)


def test_dh_row_missing_field():
    """A DH row without theta is refused naming the row and the field."""
    with pytest.raises(RobotDefinitionError, match=r"links\[1\] is missing field\(s\) theta"):
        sk.Robot.from_dh([ROW, {"a": 0.0, "alpha": 0.0, "d": 0.0}])


def test_dh_row_unknown_field():
    """A misspelt DH field is refused and the allowed ones listed."""
    with pytest.raises(RobotDefinitionError, match=r"unknown field\(s\) lenght; allowed: a,"):
        sk.Robot.from_dh([dict(ROW, lenght=1.0)])


@pytest.mark.parametrize("value", ["x", None, np.nan, np.inf])
def test_dh_field_not_a_finite_number(value):
    """A DH field that is not a finite number is refused naming the field."""
    with pytest.raises(RobotDefinitionError, match=r"field 'a' must be (a number|finite)"):
        sk.Robot.from_dh([dict(ROW, a=value)])


def test_unknown_joint_type():
    """An unknown joint type names the value and the accepted types."""
    with pytest.raises(RobotDefinitionError,
                       match=r"unknown joint type 'spherical'; expected 'R' .* or 'P'"):
        sk.Robot.from_dh([dict(ROW, type="spherical")])


def test_joint_limit_lower_above_upper():
    """A joint limit pair with lower > upper is refused with both numbers."""
    with pytest.raises(RobotDefinitionError, match="joint limit lower 1 is greater than upper -1"):
        sk.Robot.from_dh([dict(ROW, qlim=(1.0, -1.0))])
    with pytest.raises(RobotDefinitionError, match="joint limits must be a pair"):
        sk.Robot.from_dh([dict(ROW, qlim=(1.0,))])


def test_non_orthonormal_base_and_tool():
    """A base or tool whose rotation is not orthonormal, or of the wrong shape, is refused."""
    with pytest.raises(InputError, match="rotation block of base is not orthonormal"):
        sk.Robot.from_dh([ROW], base=np.diag([2.0, 1.0, 1.0, 1.0]))
    with pytest.raises(InputError, match=r"tool must have shape \(\.\.\., 4, 4\)"):
        sk.Robot.from_dh([ROW], tool=np.eye(3))
    reflect = np.diag([1.0, 1.0, -1.0, 1.0])
    with pytest.raises(InputError, match="base"):
        sk.Robot.from_dh([ROW], base=reflect)


def test_unknown_convention():
    """An unknown convention lists the valid ones."""
    with pytest.raises(InputError, match="unknown convention 'craig'; expected one of: "
                                         "'standard', 'modified'"):
        sk.Robot.from_dh([ROW], convention="craig")


def test_empty_or_malformed_tables():
    """Empty tables, strings and non-mapping rows are refused."""
    with pytest.raises(RobotDefinitionError, match="links is empty"):
        sk.Robot.from_dh([])
    with pytest.raises(RobotDefinitionError, match="links must be a list of DH rows"):
        sk.Robot.from_dh("a alpha d theta")
    with pytest.raises(RobotDefinitionError, match=r"links\[0\] must be a mapping"):
        sk.Robot.from_dh([5])


def test_jacobian_options(ur5):
    """Unknown frame, out-of-range link, bad point and point-without-link are refused."""
    q = np.zeros(6)
    with pytest.raises(InputError, match="unknown frame 'tool'; expected one of: 'base', 'ee'"):
        ur5.jacobian(q, frame="tool")
    with pytest.raises(InputError, match="link must be in 0..6, got 9"):
        ur5.jacobian(q, link=9)
    with pytest.raises(InputError, match=r"point must have 3 values, got shape \(2,\)"):
        ur5.jacobian(q, link=2, point=[1.0, 2.0])
    with pytest.raises(InputError, match="point is given without link"):
        ur5.jacobian(q, point=[1.0, 2.0, 3.0])
    with pytest.raises(InputError, match="unknown task 'foo'"):
        ur5.manipulability(q, task="foo")


def test_limits_and_seed(ur5):
    """with_limits checks its shape and order; random_q checks the seed type."""
    with pytest.raises(InputError, match=r"qlim must be a pair \(lower, upper\) or have "
                                         r"shape \(6, 2\), got shape \(5, 2\)"):
        ur5.with_limits(np.zeros((5, 2)))
    with pytest.raises(RobotDefinitionError, match="lower 1 is greater than upper -1"):
        ur5.with_limits([[1.0, -1.0]] * 6)
    with pytest.raises(InputTypeError, match="seed must be None, an int or a numpy Generator"):
        ur5.random_q(seed="x")


def test_errors_share_one_root_and_builtin_bases():
    """Library errors derive from SerialkinError and from ValueError/TypeError where natural."""
    assert issubclass(InputError, SerialkinError) and issubclass(InputError, ValueError)
    assert issubclass(InputTypeError, SerialkinError) and issubclass(InputTypeError, TypeError)
    assert issubclass(RobotDefinitionError, SerialkinError)


def test_models_bad_arguments():
    """Model builders reject bad lengths, counts and unknown names with named messages."""
    with pytest.raises(InputError, match="lengths must be one number or 2 numbers"):
        models.planar(2, [1.0, 1.0, 1.0])
    with pytest.raises(InputTypeError, match="n must be an integer"):
        models.planar(2.5)
    with pytest.raises(InputError, match="did you mean 'ur5'"):
        models.get("ur6")
