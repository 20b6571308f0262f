"""Vendor URDFs open as they are: a stated tip rule, the whole tree, package:// found."""

from __future__ import annotations

import shutil
from pathlib import Path

import numpy as np
import pytest
from click.testing import CliRunner

from serialkin.cli.main import cli
from serialkin.errors import RobotDefinitionError
from serialkin.formats.urdf import choose_chain, package_folders, robot_from_urdf
from tests.erd import robots_dir, urdf


def _link(name: str) -> str:
    return f'<link name="{name}"/>'


def _joint(name: str, parent: str, child: str, kind: str = "revolute") -> str:
    lim = '<limit lower="-1" upper="1"/>' if kind != "fixed" else ""
    return (f'<joint name="{name}" type="{kind}"><parent link="{parent}"/>'
            f'<child link="{child}"/><origin xyz="0 0 0.1"/><axis xyz="0 0 1"/>{lim}</joint>')


def _tree(*branches: list[tuple[str, str]]) -> str:
    """A URDF: base -> a -> b, then the branches (lists of (link, kind)) from b."""
    links, joints = ["base", "a", "b"], [_joint("j1", "base", "a"), _joint("j2", "a", "b")]
    for i, branch in enumerate(branches):
        parent = "b"
        for k, (link, kind) in enumerate(branch):
            links.append(link)
            joints.append(_joint(f"br{i}_{k}", parent, link, kind))
            parent = link
    return f'<robot name="t">{"".join(map(_link, links))}{"".join(joints)}</robot>'


def test_tip_named_like_a_tcp_beats_fingers():
    """With fingers beside it, a link named like a TCP is the tip, and the rule is stated."""
    text = _tree([("hand", "fixed"), ("hand_tcp", "fixed")], [("finger_l", "prismatic")],
                 [("finger_r", "prismatic")])
    c = choose_chain(text)
    assert (c.tip, c.rule) == ("hand_tcp", "named")
    assert set(c.others) == {"finger_l", "finger_r"}
    r = robot_from_urdf(text)
    assert "a link named like a TCP" in r.source and r.n == 2


def test_name_kinds_in_order_and_deepest_fallback():
    """Names rank TCP > tool > flange > ee; else the deepest chain wins; a tie is refused."""
    assert choose_chain(_tree([("ee_link", "fixed")], [("tool0", "fixed")])).tip == "tool0"
    assert choose_chain(_tree([("flange", "fixed")], [("x_eef", "fixed")])).tip == "flange"
    deep = choose_chain(_tree([("c", "revolute"), ("d", "revolute")], [("e", "revolute")]))
    assert (deep.tip, deep.rule) == ("d", "deepest")
    with pytest.raises(RobotDefinitionError, match="equally deep.*pass tip_link="):
        choose_chain(_tree([("c", "revolute")], [("e", "revolute")]))


def test_given_tip_and_srdf_end_effector(tmp_path):
    """tip_link= wins over every rule; an SRDF's end effector wins over the names."""
    text = _tree([("hand_tcp", "fixed")], [("c", "revolute"), ("d", "revolute")])
    assert choose_chain(text, tip_link="d").rule == "given"
    srdf = tmp_path / "r.srdf"
    srdf.write_text('<robot name="t"><end_effector name="e" parent_link="d" group="g"/>'
                    "</robot>", encoding="utf-8")
    c = choose_chain(text, srdf=srdf)
    assert (c.tip, c.rule) == ("d", "srdf")


def test_whole_tree_places_fingers_at_rest():
    """whole_tree gives the off-chain links' geometry, their joints at 0 (clamped to limits)."""
    box = '<visual><geometry><box size="0.1 0.1 0.1"/></geometry></visual>'
    text = _tree([("tcp", "fixed")], [("finger", "prismatic")]).replace(
        '<link name="finger"/>', f'<link name="finger">{box}</link>')
    assert "finger" not in [g.link_name for g in robot_from_urdf(text).geometry]
    whole = robot_from_urdf(text, whole_tree=True)
    g = {g.link_name: g for g in whole.geometry}["finger"]
    assert g.frame == 2  # on link b, the chain's last moving frame
    np.testing.assert_allclose(g.visual[0].origin[:3, 3], [0, 0, 0.1])


def _erd_panda() -> Path:
    p = urdf("panda_description/urdf/panda.urdf")
    if p is None:
        pytest.skip("example-robot-data is not installed")
    return p


def test_vendor_panda_loads_with_meshes_as_it_is():
    """The example-robot-data Panda loads with no tip and no package map; meshes resolve."""
    r = robot_from_urdf(str(_erd_panda()), resolve_meshes=True, whole_tree=True)
    assert r.link_names[-1] == "panda_hand_tcp"
    meshes = [s.geometry.filename for g in r.geometry for s in g.visual + g.collision
              if hasattr(s.geometry, "filename")]
    assert meshes and all(Path(m).is_file() for m in meshes)
    assert {"panda_leftfinger", "panda_rightfinger"} <= {g.link_name for g in r.geometry}


def test_package_found_by_package_xml_and_ros_paths(tmp_path, monkeypatch):
    """package:// resolves via an ancestor's package.xml, ROS_PACKAGE_PATH and AMENT_PREFIX_PATH."""
    pkg = tmp_path / "some_folder"
    (pkg / "urdf").mkdir(parents=True)
    (pkg / "package.xml").write_text("<package><name>my_robot</name></package>",
                                     encoding="utf-8")
    assert pkg in package_folders("my_robot", pkg / "urdf")
    monkeypatch.setenv("ROS_PACKAGE_PATH", str(tmp_path))
    assert pkg in package_folders("my_robot", None)
    monkeypatch.setenv("AMENT_PREFIX_PATH", str(tmp_path / "install"))
    assert tmp_path / "install" / "share" / "other" in package_folders("other", None)


def test_cli_view_and_fk_open_the_vendor_panda(tmp_path):
    """`serialkin view` and `fk` open a copied vendor Panda tree as it is and name the tip."""
    root = robots_dir()
    if root is None:
        pytest.skip("example-robot-data is not installed")
    dest = tmp_path / "example-robot-data" / "robots" / "panda_description"
    shutil.copytree(root / "panda_description", dest)  # found as an ancestor named like it
    f = dest / "urdf" / "panda.urdf"
    res = CliRunner().invoke(cli, ["view", str(f), "--out", str(tmp_path / "p.html")])
    assert res.exit_code == 0, res.output
    assert "panda_hand_tcp" in res.stderr and "named like a TCP" in res.stderr
    assert "leftfinger" in (tmp_path / "p.html").read_text(encoding="utf-8")
    res = CliRunner().invoke(cli, ["fk", str(f), "--json"])
    assert res.exit_code == 0, res.output
    assert "tip_link=NAME" in res.stderr
