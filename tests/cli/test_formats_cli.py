"""The command line reads MJCF (.xml/.mjcf) and xacro (.xacro) robots, with their --param keys."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
from click.testing import CliRunner

import serialkin as sk
from serialkin.cli.main import cli

DATA = Path(__file__).parents[1] / "model" / "data"
ARM = DATA / "mjcf_arm_degree.xml"
XACRO = DATA / "xacro_pkgs" / "demo_arm_description" / "urdf" / "demo_arm.urdf.xacro"


def _fk(args):
    res = CliRunner().invoke(cli, ["fk", *args, "--json"])
    assert res.exit_code == 0, res.output
    return np.array(json.loads(res.stdout)["results"][0]["T"])


def test_mjcf_fk_matches_the_api():
    """An .xml robot with --param tool_site= gives the API's pose."""
    q = [0.1, -0.2, 0.05, 0.3, 0.4]
    T = _fk([str(ARM), "--param", "tool_site=tcp", "--q", ",".join(map(str, q))])
    np.testing.assert_allclose(T, sk.Robot.from_mjcf(ARM, tool_site="tcp").fk(q), atol=1e-12)


def test_mjcf_branch_hint_and_unknown_param(tmp_path):
    """A branching MJCF names --param end_body=; an unknown key lists the valid ones."""
    path = tmp_path / "fork.mjcf"
    path.write_text("<mujoco><worldbody><body name='a'><joint name='j'/></body>"
                    "<body name='b'><joint name='k'/></body></worldbody></mujoco>")
    res = CliRunner().invoke(cli, ["fk", str(path), "--q", "0"])
    assert res.exit_code == 2 and "--param end_body=NAME" in res.output
    T = _fk([str(path), "--param", "end_body=b", "--q", "0.3"])
    np.testing.assert_allclose(T, sk.Robot.from_mjcf(path, end_body="b").fk([0.3]))
    res = CliRunner().invoke(cli, ["fk", str(path), "--param", "tip_link=b", "--q", "0"])
    assert res.exit_code == 2 and "base_body=..., end_body=..., tool_site=..." in res.output


def test_xacro_args_and_packages():
    """A .xacro robot takes arg:NAME= and package:NAME= and gives the API's pose."""
    pytest.importorskip("xacro")
    pkg = XACRO.parents[1]
    T = _fk([str(XACRO), "--param", "arg:reach=0.5", "--param",
             f"package:demo_arm_description={pkg}", "--q", "0.1,0.2,0.3"])
    robot = sk.Robot.from_xacro(XACRO, mappings={"reach": "0.5"},
                                package_map={"demo_arm_description": pkg})
    np.testing.assert_allclose(T, robot.fk([0.1, 0.2, 0.3]), atol=1e-12)
    T = _fk([str(XACRO), "--param", f"search_path={pkg.parent}", "--q", "0.1,0.2,0.3"])
    np.testing.assert_allclose(T, sk.Robot.from_xacro(XACRO, search_path=[pkg.parent])
                               .fk([0.1, 0.2, 0.3]), atol=1e-12)


def test_urdf_saved_as_xml_gets_a_hint(tmp_path):
    """A URDF named .xml is read as MJCF; the error suggests naming it .urdf."""
    path = tmp_path / "arm.xml"
    path.write_text("<robot name='r'><link name='a'/></robot>")
    res = CliRunner().invoke(cli, ["fk", str(path), "--q", "0"])
    assert res.exit_code == 2 and "(a URDF? name it .urdf)" in res.output
