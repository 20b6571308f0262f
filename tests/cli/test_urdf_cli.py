"""The command line reads branching URDFs with --param tip_link= / base_link=."""

from __future__ import annotations

import json

import numpy as np
from click.testing import CliRunner

import serialkin as sk
from serialkin.cli.main import cli

BRANCHED = """<robot name="fork">
  <link name="base"/><link name="l1"/><link name="a"/><link name="b"/>
  <joint name="j1" type="revolute"><parent link="base"/><child link="l1"/>
    <axis xyz="0 0 1"/><limit lower="-3" upper="3"/></joint>
  <joint name="ja" type="revolute"><parent link="l1"/><child link="a"/>
    <origin xyz="0.5 0 0"/><axis xyz="0 1 0"/><limit lower="-3" upper="3"/></joint>
  <joint name="jb" type="prismatic"><parent link="l1"/><child link="b"/>
    <origin xyz="0 0.2 0"/><axis xyz="1 0 0"/><limit lower="0" upper="1"/></joint>
</robot>"""


def test_branching_urdf_needs_tip_link(tmp_path):
    """Without tip_link the error lists the leaves and says how to pass it on the CLI."""
    path = tmp_path / "fork.urdf"
    path.write_text(BRANCHED)
    res = CliRunner().invoke(cli, ["fk", str(path), "--q", "0,0"])
    assert res.exit_code == 2
    assert "a, b" in res.output and "--param tip_link=NAME" in res.output


def test_tip_link_selects_the_chain(tmp_path):
    """--param tip_link=b gives the chain base→b, with the same FK as the Python API."""
    path = tmp_path / "fork.urdf"
    path.write_text(BRANCHED)
    res = CliRunner().invoke(cli, ["fk", str(path), "--param", "tip_link=b", "--q", "0.3,0.4",
                                   "--json"])
    assert res.exit_code == 0, res.output
    T = np.array(json.loads(res.stdout)["results"][0]["T"])
    robot = sk.Robot.from_urdf(BRANCHED, tip_link="b")
    np.testing.assert_allclose(T, robot.fk([0.3, 0.4]), atol=1e-12)


def test_unknown_urdf_param_is_refused(tmp_path):
    """A --param other than base_link/tip_link for a URDF is an error naming it."""
    path = tmp_path / "fork.urdf"
    path.write_text(BRANCHED)
    res = CliRunner().invoke(cli, ["fk", str(path), "--param", "tip=b", "--q", "0,0"])
    assert res.exit_code == 2 and "tip" in res.output and "tip_link" in res.output
