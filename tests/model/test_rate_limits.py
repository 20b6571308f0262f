"""Joint velocity and acceleration limits: URDF reading and export, the zoo, copies."""

from __future__ import annotations

import pickle

import numpy as np
import pytest

import serialkin as sk
from serialkin import models
from serialkin.errors import RobotDefinitionError

THREE = """<?xml version="1.0"?>
<robot name="three">
  <link name="base"/><link name="l1"/><link name="l2"/><link name="l3"/>
  <joint name="j1" type="revolute"><parent link="base"/><child link="l1"/>
    <axis xyz="0 0 1"/><limit lower="-1" upper="1" effort="1" velocity="1.5"/></joint>
  <joint name="j2" type="continuous"><parent link="l1"/><child link="l2"/>
    <origin xyz="0.3 0 0"/><axis xyz="0 1 0"/><limit effort="1" velocity="%s"/></joint>
  <joint name="j3" type="prismatic"><parent link="l2"/><child link="l3"/>
    <origin xyz="0.2 0 0"/><axis xyz="1 0 0"/>
    <limit lower="0" upper="0.4" effort="1" velocity="0.25"/></joint>
</robot>"""


def test_urdf_velocity_limits_are_read_per_joint():
    """<limit velocity> gives velocity_limits [rad/s, m/s]; 0 (URDF's placeholder) is inf."""
    r = sk.Robot.from_urdf(THREE % "2.5")
    assert np.array_equal(r.velocity_limits, [1.5, 2.5, 0.25])
    assert r.acceleration_limits is None   # URDF has no acceleration limits
    assert not r.velocity_limits.flags.writeable
    r0 = sk.Robot.from_urdf(THREE % "0")
    assert np.array_equal(r0.velocity_limits, [1.5, np.inf, 0.25])


def test_urdf_without_velocities_states_none():
    """A URDF whose every velocity is 0 or missing has velocity_limits None."""
    text = (THREE % "0").replace('velocity="1.5"', 'velocity="0"').replace(
        ' velocity="0.25"', "")
    assert sk.Robot.from_urdf(text).velocity_limits is None


@pytest.mark.parametrize("speed", ["2.5", "0"])
def test_velocity_limits_survive_a_urdf_round_trip(speed):
    """to_urdf writes the velocity limits (0 where none) and reading it back gives them."""
    r = sk.Robot.from_urdf(THREE % speed)
    back = sk.Robot.from_urdf(r.to_urdf())
    assert np.array_equal(back.velocity_limits, r.velocity_limits)
    panda = models.get("panda")
    assert np.array_equal(sk.Robot.from_urdf(panda.to_urdf()).velocity_limits,
                          panda.velocity_limits)


def test_bad_urdf_velocity_is_named():
    """A velocity that is not a number is refused, naming the joint and attribute."""
    with pytest.raises(RobotDefinitionError, match=r"j2.*<limit velocity>"):
        sk.Robot.from_urdf(THREE % "fast")


def test_zoo_robots_carry_their_vendor_limits():
    """UR5: 180°/s every joint, no acceleration; Panda: Franka's velocity and acceleration."""
    ur5 = models.get("ur5")
    assert np.allclose(ur5.velocity_limits, np.pi) and ur5.acceleration_limits is None
    panda = models.get("panda")
    assert np.array_equal(panda.velocity_limits, [2.175] * 4 + [2.61] * 3)
    assert np.array_equal(panda.acceleration_limits, [15, 7.5, 10, 12.5, 15, 20, 20])
    for name in ("ur5_vendor", "panda_vendor"):   # the vendor-frame variants keep them
        v = models.get(name)
        assert np.array_equal(v.velocity_limits, models.get(name[:-7]).velocity_limits)


def test_with_rate_limits_copies_and_checks():
    """with_rate_limits returns a new robot (the old one unchanged); other copies keep them."""
    ur5 = models.get("ur5")
    r = ur5.with_rate_limits(velocity=[1, 2, 3, 4, 5, 6], acceleration=10.0)
    assert np.array_equal(r.velocity_limits, [1, 2, 3, 4, 5, 6])
    assert np.array_equal(r.acceleration_limits, [10.0] * 6)
    assert ur5.acceleration_limits is None
    for copy in (r.with_tool(np.eye(4)), r.with_limits((-3.0, 3.0)), pickle.loads(
            pickle.dumps(r))):
        assert np.array_equal(copy.acceleration_limits, r.acceleration_limits)
        assert not copy.acceleration_limits.flags.writeable
    assert r.with_rate_limits().velocity_limits is None
    with pytest.raises(AttributeError):
        r.velocity_limits = None
    for bad in (0.0, -1.0, [1.0] * 5, "fast", np.nan):
        with pytest.raises(RobotDefinitionError, match="velocity_limits"):
            ur5.with_rate_limits(velocity=bad)
