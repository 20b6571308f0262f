"""Standard ↔ modified DH conversion keeps the end-effector pose."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import serialkin as sk
from serialkin import models
from serialkin.model.dh import modified_to_standard, standard_to_modified
from tests.kinematics._fd import dh_rows, random_transform


@settings(max_examples=40, deadline=None)
@given(rows=dh_rows(), seed=st.integers(0, 2**32 - 1))
def test_standard_robot_equals_its_modified_conversion(rows, seed):
    """A random standard-DH robot and its modified-DH rewrite give the same pose and Jacobian."""
    rng = np.random.default_rng(seed)
    base, tool = random_transform(rng), random_transform(rng)
    std = sk.Robot.from_dh(rows, "standard", base=base, tool=tool)
    m_rows, m_base, m_tool = standard_to_modified(std.dh, std.base, std.tool)
    mod = sk.Robot.from_dh(m_rows, "modified", base=m_base, tool=m_tool)
    Q = std.random_q(5, seed=rng)
    np.testing.assert_allclose(mod.fk(Q), std.fk(Q), atol=1e-12)
    np.testing.assert_allclose(mod.jacobian(Q), std.jacobian(Q), atol=1e-12)
    np.testing.assert_array_equal(mod.qlim, std.qlim)
    assert mod.joint_types == std.joint_types


@settings(max_examples=40, deadline=None)
@given(rows=dh_rows(), seed=st.integers(0, 2**32 - 1))
def test_modified_robot_equals_its_standard_conversion(rows, seed):
    """A random modified-DH robot and its standard-DH rewrite give the same pose."""
    rng = np.random.default_rng(seed)
    mod = sk.Robot.from_dh(rows, "modified", base=random_transform(rng),
                           tool=random_transform(rng))
    s_rows, s_base, s_tool = modified_to_standard(mod.dh, mod.base, mod.tool)
    std = sk.Robot.from_dh(s_rows, "standard", base=s_base, tool=s_tool)
    Q = mod.random_q(5, seed=rng)
    np.testing.assert_allclose(std.fk(Q), mod.fk(Q), atol=1e-12)


@pytest.mark.parametrize("name", ["puma560", "stanford", "ur5", "iiwa7", "scara"])
def test_round_trip_restores_the_table(name):
    """Converting standard → modified → standard returns the original rows, base and tool."""
    robot = models.get(name)
    rows, base, tool = modified_to_standard(*standard_to_modified(robot.dh, robot.base,
                                                                  robot.tool))
    assert rows == list(robot.dh)
    np.testing.assert_allclose(base, robot.base, atol=1e-15)
    np.testing.assert_allclose(tool, robot.tool, atol=1e-15)


def test_panda_in_standard_dh():
    """The Panda (published in modified DH) rewritten in standard DH has the same poses."""
    panda = models.panda()
    rows, base, tool = modified_to_standard(panda.dh, panda.base, panda.tool)
    std = sk.Robot.from_dh(rows, "standard", base=base, tool=tool)
    Q = panda.random_q(10, seed=1)
    np.testing.assert_allclose(std.fk(Q), panda.fk(Q), atol=1e-12)
