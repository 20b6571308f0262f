"""Issue 33, item 6: the calibrated model written by patching the user's URDF; physical exports."""

from __future__ import annotations

import json
import xml.etree.ElementTree as ET

import numpy as np
import pytest
from click.testing import CliRunner

import serialkin as sk
from serialkin.calibration import (
    calibrate,
    patch_urdf,
    perturb_joints,
    save_robot,
    simulate_measurements,
    write_measurements,
)
from serialkin.cli.main import cli
from serialkin.errors import InputError

COMMENT = "<!-- calibrated cell 4: keep this comment -->"


def _user_urdf(tmp_path, tool_joint=True):
    """The Panda's URDF with a comment, an inertial and (optionally) a fixed tool joint."""
    text = sk.models.panda().to_urdf()
    text = text.replace("<robot", COMMENT + "\n<robot", 1)
    root = ET.fromstring(text)
    link = root.find("link")
    inertial = ET.SubElement(link, "inertial")
    ET.SubElement(inertial, "mass", value="4.97")
    if tool_joint:
        tip = [el.get("name") for el in root.findall("link")][-1]
        ET.SubElement(root, "link", name="tool0")
        j = ET.SubElement(root, "joint", name="flange_tool0", type="fixed")
        ET.SubElement(j, "parent", link=tip)
        ET.SubElement(j, "child", link="tool0")
        ET.SubElement(j, "origin", xyz="0 0 0.1034", rpy="0 0 -0.785398")
    body = ET.tostring(root, encoding="unicode")
    path = tmp_path / "panda.urdf"
    path.write_text(COMMENT + "\n" + body)
    return path


def _elements(path):
    """(tag, attributes, text) of every element, in document order."""
    return [(el.tag, dict(el.attrib), (el.text or "").strip())
            for el in ET.parse(path).getroot().iter()]


def _calibrated(src, kind="position"):
    robot = sk.Robot.from_urdf(str(src))
    truth = perturb_joints(robot, marker=0.08, seed=1)
    meas = simulate_measurements(truth, 200, kind=kind, noise_position=0.0, seed=2)
    res = calibrate(robot, meas)
    assert res.success, res.reason
    return robot, truth, res


def test_patched_urdf_differs_only_in_the_changed_joint_origins(tmp_path):
    """Parsing both files: every element equal except the origins of the joints changed."""
    src = _user_urdf(tmp_path)
    robot, truth, res = _calibrated(src)
    patch = patch_urdf(src, res, tmp_path / "cal.urdf")
    assert len(patch.changed) >= 5 and not patch.tool_written
    a, b = _elements(src), _elements(patch.path)
    assert len(a) == len(b)
    changed_origins = set()
    joint = None
    for (tag, attrs, text), (tag2, attrs2, text2) in zip(a, b):
        assert (tag, text) == (tag2, text2)
        if tag == "joint":
            joint = attrs["name"]
        if attrs != attrs2:
            assert tag == "origin" and joint in patch.changed, (tag, attrs, attrs2)
            assert set(attrs) == set(attrs2) == {"xyz", "rpy"}
            changed_origins.add(joint)
    assert changed_origins == set(patch.changed)
    text = patch.path.read_text()
    assert text.startswith(COMMENT) and "<inertial>" in text and 'value="4.97"' in text
    # the patched file has the calibrated kinematics (in its base frame, to its own tool)
    back = sk.Robot.from_urdf(str(patch.path))
    q = robot.random_q(100, seed=4)
    want = (np.linalg.inv(res.robot.base) @ res.robot.fk(q) @ np.linalg.inv(res.robot.tool)
            @ robot.tool)
    np.testing.assert_allclose(back.fk(q), want, atol=1e-12)


def test_tool_change_is_written_when_poses_identify_it(tmp_path):
    """Full poses identify the tool: the fixed tool joint takes it, the flange follows."""
    src = _user_urdf(tmp_path)
    robot, truth, res = _calibrated(src, kind="pose")
    patch = patch_urdf(src, res, tmp_path / "cal.urdf")
    assert patch.tool_written and "flange_tool0" in patch.changed
    back = sk.Robot.from_urdf(str(patch.path))
    q = robot.random_q(100, seed=4)
    want = np.linalg.inv(res.robot.base) @ res.robot.fk(q)
    np.testing.assert_allclose(back.fk(q), want, atol=1e-12)


def test_patch_never_replaces_the_original(tmp_path):
    """Writing the patched file over the URDF it patches is refused; the file is intact."""
    src = _user_urdf(tmp_path)
    before = src.read_bytes()
    _, _, res = _calibrated(src)
    with pytest.raises(InputError, match="original"):
        patch_urdf(src, res, src)
    assert src.read_bytes() == before


def test_dh_file_of_a_calibrated_ur5_is_refused_not_unphysical(tmp_path):
    """Nearly parallel UR5 axes: no robot file with ±30-170 m offsets; the message says why."""
    robot = sk.models.ur5()
    truth = perturb_joints(robot, marker=0.08, seed=1)
    res = calibrate(robot, simulate_measurements(truth, 200, noise_position=0.0, seed=2))
    with pytest.raises(InputError, match="nearly parallel.*urdf"):
        save_robot(res.robot, tmp_path / "cal.yaml")
    assert not (tmp_path / "cal.yaml").exists()
    back = sk.Robot.from_urdf(str(save_robot(res.robot, tmp_path / "cal.urdf")))
    q = robot.random_q(50, seed=3)
    np.testing.assert_allclose(back.fk(q), res.robot.fk(q), atol=1e-12)
    offsets = [abs(float(v)) for el in ET.parse(tmp_path / "cal.urdf").getroot().iter("origin")
               for v in el.get("xyz").split()]
    assert max(offsets) < 1.0  # per-joint origins stay bounded


def test_cli_patches_a_urdf_robot_and_reports_the_chi_square(tmp_path):
    """`serialkin calibrate arm.urdf --out cal.urdf --json`: patched file, chi-square in JSON."""
    src = _user_urdf(tmp_path)
    robot = sk.Robot.from_urdf(str(src))
    truth = perturb_joints(robot, marker=0.08, seed=1)
    meas = write_measurements(tmp_path / "m.csv",
                              simulate_measurements(truth, 80, noise_position=5e-5, seed=2))
    out = tmp_path / "cal.urdf"
    r = CliRunner().invoke(cli, ["calibrate", str(src), "--measurements", str(meas),
                                 "--sigma-position", "5e-5", "--out", str(out), "--json"],
                           catch_exceptions=False)
    assert r.exit_code == 0, r.output
    data = json.loads(r.stdout)
    chi = data["chi_square"]
    assert data["success"] and chi["consistent_with_noise"] and chi["dof"] > 0
    assert 0.5 < chi["noise_ratio"] < 1.5 and chi["significance"] == 1e-3
    assert any("base pose" in n for n in data["notes"])
    assert [e[0] for e in _elements(out)] == [e[0] for e in _elements(src)]
    assert out.read_text().startswith(COMMENT)
