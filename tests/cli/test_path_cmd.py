"""``serialkin path``: a scenario's pose path as a timed joint trajectory, or a clear refusal."""

from __future__ import annotations

import json
import math

import numpy as np
from click.testing import CliRunner

from serialkin import models
from serialkin.cli.main import cli

LINE = """name: seam
robot: {model: ur5}
q0: [0.3, -1.2, 1.4, -1.0, -1.5, 0.4]
path:
  type: line
  start: q0
  end: {position: [%s], rpy_deg: [180, 0, 45]}
  max_step: 0.005
  max_angle_deg: 1
"""


def run(*args, code: int = 0):
    result = CliRunner().invoke(cli, [str(a) for a in args], catch_exceptions=False)
    assert result.exit_code == code, (result.exit_code, result.stdout, result.stderr)
    return result


def test_path_writes_joints_timing_and_summary(tmp_path):
    """A line: every sample met, steps within the degree bound, a timing within its limits."""
    sc = tmp_path / "seam.yaml"
    sc.write_text(LINE % "0.2, 0.3, 0.3")
    res = run("path", sc, "--out", tmp_path / "o", "--max-joint-step-deg", 10,
              "--velocity-deg", 90, "--acceleration-deg", 180, "--json")
    data = json.loads(res.stdout)
    assert data["success"] and data["followed"] == data["samples"] > 10
    assert data["largest_step_rad"] <= math.radians(10)
    assert data["max_position_error_m"] < 1e-9
    q = np.loadtxt(data["files"]["joints"], delimiter=",", skiprows=1)[:, 1:7]
    T = models.get("ur5").fk(q)
    assert np.allclose(T[-1, :3, 3], [0.2, 0.3, 0.3], atol=1e-9)
    traj = json.loads((tmp_path / "o" / "seam_trajectory.json").read_text())
    assert abs(np.array(traj["qd"])).max() <= math.radians(90) * (1 + 1e-6)
    assert abs(np.array(traj["qdd"])).max() <= math.radians(180) * (1 + 1e-6)
    assert (tmp_path / "o" / "seam_timing.png").stat().st_size > 10_000


def test_unreachable_path_exits_1_saying_where(tmp_path):
    """A line beyond the reach: exit 1, stderr names the sample; the joint file keeps the rest."""
    sc = tmp_path / "far.yaml"
    sc.write_text(LINE % "1.5, 0.3, 0.3")
    res = run("path", sc, "--out", tmp_path / "o", code=1)
    assert "cannot follow the path: sample " in res.stderr and "out of reach" in res.stderr
    data = json.loads((tmp_path / "o" / "far_path.json").read_text())
    assert data["success"] is False and data["failed_at"] == data["followed"] > 0
    rows = np.loadtxt(tmp_path / "o" / "far_joints.csv", delimiter=",", skiprows=1)
    assert len(rows) == data["followed"]


def test_angle_options_say_their_unit(tmp_path):
    """Radians and degrees of one option together, half a timing, or a point path: refused."""
    sc = tmp_path / "seam.yaml"
    sc.write_text(LINE % "0.2, 0.3, 0.3")
    res = run("path", sc, "--max-joint-step", 0.1, "--max-joint-step-deg", 5, code=2)
    assert "radians or degrees" in res.stderr
    res = run("path", sc, "--velocity", 1.0, code=2)
    assert "acceleration" in res.stderr
    points = tmp_path / "pts.yaml"
    points.write_text("robot: {planar: {links: 3, length: 0.1}}\n"
                      "path: {type: circle, center: [0.1, 0], radius: 0.05}\n")
    res = run("path", points, code=2)
    assert "pose paths" in res.stderr


def test_scenario_pose_path_units_are_explicit(tmp_path):
    """A scenario line with both max_angle and max_angle_deg, or rpy and rpy_deg: refused."""
    from serialkin.tracking import load_scenario
    from serialkin.tracking.scenario import ScenarioError

    sc = tmp_path / "both.yaml"
    sc.write_text((LINE % "0.2, 0.3, 0.3").replace("max_angle_deg: 1",
                                                   "max_angle_deg: 1\n  max_angle: 0.1"))
    try:
        load_scenario(sc)
    except ScenarioError as exc:
        assert "radians or degrees" in str(exc)
    else:
        raise AssertionError("both units accepted")
    arc = tmp_path / "arc.yaml"
    arc.write_text("robot: {model: ur5}\nq0: [0.3, -1.2, 1.4, -1.0, -1.5, 0.4]\n"
                   "path: {type: arc, start: q0, center: [0.3, 0.1, 0.4], axis: [0, 0, 1], "
                   "angle_deg: 60}\n")
    path = load_scenario(arc).path
    assert path.task == "pose" and len(path) > 10


def test_timing_takes_the_robots_own_limits_and_a_jerk_limit(tmp_path):
    """--timing on a Panda: its data-sheet limits hold; --jerk gives the ruckig timing."""
    sc = tmp_path / "panda.yaml"
    sc.write_text("robot: {model: panda}\nq0: [0.2, -0.3, 0.1, -2.0, 0.1, 1.8, 0.6]\n"
                  "path:\n  type: line\n  start: q0\n  end: {position: [0.45, 0.1, 0.45], "
                  "rpy_deg: [180, 0, 0]}\n  max_step: 0.005\n")
    panda = models.get("panda")
    data = json.loads(run("path", sc, "--out", tmp_path / "o", "--timing", "--no-figures",
                          "--json").stdout)
    assert data["success"] and data["timing"] == "toppra"
    traj = json.loads((tmp_path / "o" / "panda_trajectory.json").read_text())
    assert traj["velocity_limits"] == panda.velocity_limits.tolist()
    assert np.all(np.abs(traj["qd"]) <= panda.velocity_limits * (1 + 1e-6))
    data = json.loads(run("path", sc, "--out", tmp_path / "j", "--jerk", 500, "--no-figures",
                          "--json").stdout)
    assert data["timing"] == "ruckig" and data["duration_s"] > 0
    traj = json.loads((tmp_path / "j" / "panda_trajectory.json").read_text())
    assert traj["jerk_limits"] == [500.0] * 7
    ur5 = tmp_path / "seam.yaml"
    ur5.write_text(LINE % "0.2, 0.3, 0.3")
    res = run("path", ur5, "--out", tmp_path / "u", "--timing", code=2)
    assert "acceleration limits" in res.stderr and "--acceleration" in res.stderr
