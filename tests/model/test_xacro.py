"""xacro import: expansion by the ROS processor, args, $(find) resolution, bad input."""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
import pytest

from serialkin import Robot
from serialkin.errors import NotSupportedError, RobotDefinitionError

DATA = Path(__file__).parent / "data"
PKGS = DATA / "xacro_pkgs"
PKG = PKGS / "demo_arm_description"
XACRO = PKG / "urdf" / "demo_arm.urdf.xacro"
EXPANDED = DATA / "xacro_demo_arm_expanded.urdf"


@pytest.fixture(autouse=True)
def _needs_xacro(request):
    if request.node.name != "test_missing_extra_is_named":
        pytest.importorskip("xacro")


def test_expands_to_the_plain_urdf():
    """Macros, properties, an include and default args expand to the hand-written URDF."""
    robot = Robot.from_xacro(XACRO, search_path=[PKGS])
    plain = Robot.from_urdf(str(EXPANDED), package_map={"demo_arm_description": PKG})
    Q = plain.random_q(50, seed=0)
    np.testing.assert_allclose(robot.fk_all(Q), plain.fk_all(Q), atol=1e-15)
    np.testing.assert_allclose(robot.fk(Q), plain.fk(Q), atol=1e-15)
    np.testing.assert_array_equal(robot.qlim, plain.qlim)
    assert robot.joint_names == plain.joint_names == ("j1", "j2", "j3")
    assert robot.link_names == plain.link_names
    assert robot.geometry == plain.geometry
    assert robot.geometry[0].visual[0].geometry.filename == str((PKG / "meshes" / "link.stl")
                                                                .resolve())
    assert robot.source.startswith(f"xacro {XACRO}")


def test_args_change_the_robot():
    """<xacro:arg> values from mappings: the prefix renames joints, reach sets two lengths."""
    robot = Robot.from_xacro(XACRO, mappings={"prefix": "left_", "reach": 0.55},
                             package_map={"demo_arm_description": PKG})
    assert robot.joint_names == ("left_j1", "left_j2", "left_j3")
    frames = robot.fk_all(np.zeros(3))
    assert np.linalg.norm(frames[3][:3, 3] - frames[2][:3, 3]) == pytest.approx(0.55)
    tool = robot.fk(np.zeros(3))
    assert np.linalg.norm(tool[:3, 3] - frames[3][:3, 3]) == pytest.approx(0.75 * 0.55)


def test_text_input_and_find_through_package_map():
    """Text input works, $(find pkg) comes from package_map, and xacro's own lookup is restored."""
    import xacro.substitution_args as sa

    before, before_eval = sa._eval_find, sa._eval_dict.get("find")  # (another library
    # may have patched either one already: each must come back as it was)
    text = XACRO.read_text().replace("<xacro:arg name=\"reach\" default=\"0.4\"/>",
                                     "<xacro:arg name=\"reach\" default=\"0.3\"/>")
    robot = Robot.from_xacro(text, package_map={"demo_arm_description": str(PKG)})
    frames = robot.fk_all(np.zeros(3))
    assert np.linalg.norm(frames[3][:3, 3] - frames[2][:3, 3]) == pytest.approx(0.3)
    assert sa._eval_find is before and sa._eval_dict.get("find") is before_eval


def test_unknown_package_is_named():
    """$(find pkg) for a package found nowhere names it and how to give it."""
    with pytest.raises(RobotDefinitionError,
                       match=r"demo_arm_description.*not found.*package_map="):
        Robot.from_xacro(XACRO, search_path=[DATA])


@pytest.mark.parametrize("body, pattern", [
    ("<link name='${undefined_thing}'/>", "expression 'undefined_thing': unknown name"),
    ("<xacro:bogus_macro/>", "xacro failed.*bogus_macro"),
    ("<link name='a'>", "xacro failed"),
    ("<link name='$(arg missing)'/>", "xacro failed.*missing"),
])
def test_bad_xacro_is_named(body, pattern):
    """Undefined names, macros, args and malformed XML raise naming the source."""
    text = f"<robot name='r' xmlns:xacro='http://www.ros.org/wiki/xacro'>{body}</robot>"
    with pytest.raises(RobotDefinitionError, match=f"<string>: {pattern}"):
        Robot.from_xacro(text)


def test_bad_file_and_mappings_are_named(tmp_path):
    """A missing file, non-string mappings and URDF errors after expansion name the xacro file."""
    with pytest.raises(RobotDefinitionError, match="xacro file .*nope.xacro.* does not exist"):
        Robot.from_xacro(tmp_path / "nope.xacro")
    with pytest.raises(RobotDefinitionError, match="mappings"):
        Robot.from_xacro(XACRO, mappings={"reach": [1, 2]}, search_path=[PKGS])
    bad = tmp_path / "bad.urdf.xacro"
    bad.write_text("<robot name='r' xmlns:xacro='http://www.ros.org/wiki/xacro'>"
                   "<xacro:property name='n' value='l1'/><link name='${n}'/></robot>")
    with pytest.raises(RobotDefinitionError, match=r"bad.urdf.xacro \(expanded by xacro\): "):
        Robot.from_xacro(bad)


def test_missing_extra_is_named(monkeypatch):
    """Without the xacro package the error names the extra to install."""
    monkeypatch.setitem(sys.modules, "xacro", None)
    with pytest.raises(NotSupportedError, match=r'pip install "serialkin\[xacro\]"'):
        Robot.from_xacro(XACRO)
