"""URDF import/export: chain extraction, fixed-joint merging, round trips and bad input."""

from __future__ import annotations

import numpy as np
import pytest

import serialkin as sk
from serialkin.errors import NotSupportedError, RobotDefinitionError

TWO_LINK = """<?xml version="1.0"?>
<robot name="two">
  <link name="base"/><link name="l1"/><link name="l2"/><link name="tip"/>
  <joint name="j1" type="revolute"><parent link="base"/><child link="l1"/>
    <origin xyz="0 0 0.5" rpy="0 0 0"/><axis xyz="0 0 1"/>
    <limit lower="-1" upper="1" effort="1" velocity="1"/></joint>
  <joint name="j2" type="prismatic"><parent link="l1"/><child link="l2"/>
    <origin xyz="0.3 0 0" rpy="0.1 0.2 0.3"/><axis xyz="1 1 0"/>
    <limit lower="0" upper="0.4" effort="1" velocity="1"/></joint>
  <joint name="fixed_tip" type="fixed"><parent link="l2"/><child link="tip"/>
    <origin xyz="0 0 0.1" rpy="0 1.5707963 0"/></joint>
</robot>"""


def _rz(t):
    return sk.spatial.make_transform(sk.spatial.rotz(t))


def test_two_link_fk_matches_hand_computation():
    """FK of a small URDF equals the product origin·motion by hand, fixed tip merged in the tool."""
    r = sk.Robot.from_urdf(TWO_LINK)
    assert r.n == 2 and r.joint_types == ("R", "P")
    assert r.joint_names == ("j1", "j2")
    assert r.link_names == ("base", "l1", "l2", "tip")
    np.testing.assert_allclose(r.qlim, [[-1, 1], [0, 0.4]])
    from serialkin.formats.urdf import rpy_to_matrix

    q = np.array([0.3, 0.2])
    O1 = sk.spatial.make_transform(p=[0, 0, 0.5])
    O2 = sk.spatial.make_transform(rpy_to_matrix(np.array([0.1, 0.2, 0.3])), [0.3, 0, 0])
    axis = np.array([1, 1, 0]) / np.sqrt(2)
    M2 = sk.spatial.make_transform(p=axis * 0.2)
    Ot = sk.spatial.make_transform(rpy_to_matrix(np.array([0, 1.5707963, 0])), [0, 0, 0.1])
    expected = O1 @ _rz(0.3) @ O2 @ M2 @ Ot
    np.testing.assert_allclose(r.fk(q), expected, atol=1e-14)


def test_export_round_trip():
    """Exporting any robot to URDF and importing it back gives the same FK and limits."""
    rows = [dict(a=0.1, alpha=np.pi / 2, d=0.2, theta=0.3, qlim=(-2, 2)),
            dict(a=0.4, alpha=0.1, d=0.05, theta=0.0, type="P", qlim=(0.0, 0.5)),
            dict(a=0.0, alpha=-np.pi / 2, d=0.1, theta=-0.2)]
    for conv in ("standard", "modified"):
        r = sk.Robot.from_dh(rows, conv, base=sk.spatial.transl(1, 2, 3),
                             tool=sk.spatial.trotx(0.4), name="rt")
        r2 = sk.Robot.from_urdf(r.to_urdf())
        Q = r.random_q(20, seed=3)
        np.testing.assert_allclose(r2.fk(Q), r.fk(Q), atol=1e-12)
        np.testing.assert_allclose(r2.jacobian(Q), r.jacobian(Q), atol=1e-12)
        assert r2.qlim[0, 0] == -2 and r2.qlim[1, 1] == 0.5
        assert np.isinf(r2.qlim[2]).all()  # unlimited revolute exported as continuous


def test_file_path_and_tip_link(tmp_path):
    """A URDF file path works, and tip_link selects a shorter chain."""
    p = tmp_path / "two.urdf"
    p.write_text(TWO_LINK)
    assert sk.Robot.from_urdf(str(p)).n == 2
    r = sk.Robot.from_urdf(str(p), tip_link="l1")
    assert r.n == 1


BRANCH = """<robot name="b"><link name="a"/><link name="b"/><link name="c"/>
<joint name="ja" type="revolute"><parent link="a"/><child link="b"/><axis xyz="0 0 1"/>
<limit lower="-1" upper="1"/></joint>
<joint name="jb" type="continuous"><parent link="a"/><child link="c"/><axis xyz="0 0 1"/></joint>
</robot>"""


@pytest.mark.parametrize(
    ("text", "error", "words"),
    [
        ("<robot name='x'><link name='a'/>", RobotDefinitionError, ["malformed XML", "line"]),
        ("<robot name='x'><link name='a'/><joint name='j' type='revolute'><parent link='a'/>"
         "<child link='zz'/><axis xyz='0 0 1'/></joint></robot>", RobotDefinitionError,
         ["'j'", "zz", "does not exist"]),
        (BRANCH, RobotDefinitionError, ["branches", "b", "c", "tip_link"]),
        ("<robot name='x'><link name='a'/><link name='b'/><joint name='j0' type='revolute'>"
         "<parent link='a'/><child link='b'/><axis xyz='0 0 0'/></joint></robot>",
         RobotDefinitionError, ["'j0'", "zero"]),
        ("<robot name='x'><link name='a'/><link name='b'/><joint name='jl' type='revolute'>"
         "<parent link='a'/><child link='b'/><limit lower='1' upper='-1'/></joint></robot>",
         RobotDefinitionError, ["'jl'", "lower", "greater"]),
        ("<robot name='x'><link name='a'/><link name='b'/><joint name='jf' type='floating'>"
         "<parent link='a'/><child link='b'/></joint></robot>", NotSupportedError,
         ["'jf'", "floating", "not supported"]),
        ("<robot name='x'><link name='a'/><link name='b'/><joint name='jm' type='revolute'>"
         "<parent link='a'/><child link='b'/><mimic joint='x'/></joint></robot>",
         NotSupportedError, ["'jm'", "mimic"]),
        ("<robot name='x'><link name='a'/><link name='b'/>"
         "<joint name='j1' type='revolute'><parent link='a'/><child link='b'/></joint>"
         "<joint name='j2' type='revolute'><parent link='b'/><child link='a'/></joint></robot>",
         RobotDefinitionError, ["loop"]),
        ("<robot name='x'><link name='a'/><link name='b'/><joint name='jo' type='revolute'>"
         "<parent link='a'/><child link='b'/><origin xyz='1 2'/></joint></robot>",
         RobotDefinitionError, ["'jo'", "origin xyz", "3"]),
    ],
)
def test_bad_urdf_names_the_element(text, error, words):
    """Each malformed URDF raises a clear error that names the offending element."""
    with pytest.raises(error) as info:
        sk.Robot.from_urdf(text)
    for w in words:
        assert w in str(info.value), (w, str(info.value))


def test_unsupported_joint_off_the_chain_is_ignored():
    """A mimic joint on another branch does not prevent extracting the chain to tip_link."""
    text = BRANCH.replace('type="continuous"', 'type="revolute"').replace(
        '<axis xyz="0 0 1"/></joint>\n</robot>', '<mimic joint="ja"/></joint></robot>')
    r = sk.Robot.from_urdf(text, tip_link="b")
    assert r.n == 1 and r.joint_names == ("ja",)


def test_missing_file():
    """A path that does not exist is reported as such."""
    with pytest.raises(RobotDefinitionError, match="does not exist"):
        sk.Robot.from_urdf("/nonexistent/robot.urdf")
