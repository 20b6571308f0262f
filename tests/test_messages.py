"""Bad arguments raise errors that name the argument and show its value shortened."""

from __future__ import annotations

import math

import numpy as np
import pytest

from serialkin import models
from serialkin.errors import InputError, InputTypeError, RobotDefinitionError, SerialkinError


def _raises(call, error, pattern):
    with pytest.raises(error, match=pattern) as info:
        call()
    assert len(str(info.value)) < 1000, "the message echoes the whole value"
    assert "np.int64" not in str(info.value)
    return info.value


def test_ik_all_free_names_the_joint_and_value():
    """free={2: 'a'}, a huge index and numpy keys: InputError naming free and the value."""
    ur5 = models.get("ur5")
    T = ur5.fk(np.zeros(6))
    _raises(lambda: ur5.ik_all(T, free={2: "a"}), InputError, r"free\[2\].*'a'")
    _raises(lambda: ur5.ik_all(T, free={2**1000: 0.0}), InputError, "joint index")
    _raises(lambda: ur5.ik_all(T, free={np.int64(9): 0.0}), InputError, "got 9")


def test_a_folder_is_not_a_xacro_file(tmp_path):
    """from_xacro on a folder says it is a folder."""
    pytest.importorskip("xacro")
    from serialkin import Robot

    _raises(lambda: Robot.from_xacro(str(tmp_path)), RobotDefinitionError, "is a folder")


def test_base_placement_floor_must_be_finite():
    """floor_z=nan is refused naming floor_z."""
    from serialkin.reach import base_placement

    ur5 = models.get("ur5")
    tasks = ur5.fk(np.zeros(6))[None]
    _raises(lambda: base_placement(ur5, tasks, floor_z=math.nan), SerialkinError, "floor_z")


def test_a_model_name_is_not_a_robot():
    """serialkin.ik.solve('puma560', T) says what a robot is and how to build one."""
    from serialkin.ik import solve

    T = models.get("puma560").fk(np.zeros(6))
    _raises(lambda: solve("puma560", T), InputTypeError, r"models\.get\('puma560'\)")


def test_ik_options_must_map_names():
    """track(..., ik_options={1: 2}) names ik_options."""
    from serialkin.tracking import load_scenario, track

    sc = load_scenario("six_link_circle")
    _raises(lambda: track(sc.robot, sc.path, "lm", ik_options={1: 2}), InputTypeError,
            "ik_options")


def test_a_huge_link_name_in_an_srdf_is_not_echoed():
    """A 10 MB link name of an SRDF gives a message of readable length."""
    from serialkin.collision.acm import acm_from_srdf

    panda = models.get("panda")
    name = "x" * 10_000_000
    srdf = f"<robot name='p'><disable_collisions link1='{name}' link2='panda_link1'/></robot>"
    _raises(lambda: acm_from_srdf(panda.collision, srdf), RobotDefinitionError, "xxx")


def test_dh_angles_beyond_a_turn_read_as_radians_are_refused(tmp_path):
    """A robot file with alpha: 90 in radians is refused, naming the field and the units."""
    from serialkin.formats.robotfile import load_robot_file

    rows = ("dh:\n  - {a: 0.5, alpha: 0, d: 0, theta: 0}\n"
            "  - {a: 0.3, alpha: 90, d: 0, theta: 0}\n")
    f = tmp_path / "arm.yaml"
    f.write_text("name: arm\nunits: {angle: rad, length: m}\n" + rows)
    _raises(lambda: load_robot_file(f), RobotDefinitionError, r"dh\[1\]\.alpha.*degrees")
    f.write_text("name: arm\nunits: {angle: deg, length: m}\n" + rows)
    assert load_robot_file(f).n == 2


def test_urdf_rpy_beyond_a_turn_is_refused():
    """A URDF origin rpy of 90 (degrees where radians are read) names the joint and the units."""
    from serialkin import Robot

    urdf = ("<robot name='r'><link name='a'/><link name='b'/>"
            "<joint name='j1' type='revolute'><parent link='a'/><child link='b'/>"
            "<origin xyz='0 0 0.1' rpy='0 90 0'/><axis xyz='0 0 1'/>"
            "<limit lower='-1' upper='1' effort='1' velocity='1'/></joint></robot>")
    _raises(lambda: Robot.from_urdf(urdf), RobotDefinitionError, r"j1.*rpy.*degrees")


def test_cli_q_beyond_a_turn_and_the_limits_suggests_degrees():
    """The CLI refuses --q 90,0,0,0,0,0 (radians read) on a UR5, with a hint to --degrees."""
    from click.testing import CliRunner

    from serialkin.cli.main import cli

    res = CliRunner().invoke(cli, ["fk", "ur5", "--q", "90,0,0,0,0,0"])
    assert res.exit_code == 2 and "--degrees" in res.output
    assert CliRunner().invoke(cli, ["fk", "ur5", "--q", "90,0,0,0,0,0", "--degrees"]
                              ).exit_code == 0


def test_scenario_q0_beyond_a_turn_suggests_q0_deg(tmp_path):
    """A scenario's q0 of 90 (radians read) is refused, naming q0 and q0_deg."""
    from serialkin.tracking import load_scenario
    from serialkin.tracking.scenario import ScenarioError

    f = tmp_path / "s.yaml"
    f.write_text("name: s\nrobot: {planar: {links: 2, length: 0.8}}\nq0: [90, 10]\n"
                 "path: {type: points, points: [[1.0, 0.2], [1.1, 0.3]]}\n")
    _raises(lambda: load_scenario(f), ScenarioError, r"q0.*q0_deg")
