"""Every angle the command line reads has a stated unit; radians beyond a turn are refused."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest
import yaml
from click.testing import CliRunner

from serialkin.cli.main import cli
from serialkin.tracking.scenario import ScenarioError, scenario_from_dict


def run(*args: str, code: int = 0):
    result = CliRunner().invoke(cli, [str(a) for a in args], catch_exceptions=False)
    assert result.exit_code == code, (result.exit_code, result.output, result.stderr)
    return result


@pytest.mark.parametrize(("args", "option"), [
    (["ik", "puma560", "--target", "0.5,0.2,0.3,180,0,0"], "--target"),
    (["ik", "three_link", "--target", "1.5,0.5,90"], "--target"),
    (["ik", "ur5", "--target", "0.4,0.1,0.3", "--q0", "0,-90,90,0,0,400"], "--q0"),
    (["workspace", "three_link", "--kind", "constant", "--orientation", "30"], "--orientation"),
    (["workspace", "ur5", "--kind", "dexterous", "--max-angle", "10"], "--max-angle"),
    (["view", "puma560", "--q", "0,45,300,0,0,0"], "--q"),
])
def test_radians_beyond_a_turn_are_refused_with_a_hint(args, option, tmp_path):
    """A value read as radians that only makes sense in degrees is exit 2 naming --degrees."""
    out = tmp_path / "x.html" if args[0] == "view" else tmp_path / "w"
    result = run(*args, "--out", out, code=2)
    assert option in result.stderr and "--degrees" in result.stderr, result.stderr


def test_ik_degrees_equals_radians():
    """The same target in degrees (--degrees) and in radians gives the same joint answer."""
    a = json.loads(run("ik", "puma560", "--target", "0.5,0.2,0.3,180,0,0", "--degrees",
                       "--json").stdout)
    b = json.loads(run("ik", "puma560", "--target", f"0.5,0.2,0.3,{math.pi},0,0",
                       "--json").stdout)
    np.testing.assert_allclose(a["results"][0]["T"], b["results"][0]["T"], atol=1e-8)


def test_compare_reads_target_file_in_degrees(tmp_path):
    """ik-compare --target-file takes --degrees and refuses degrees read as radians."""
    f = tmp_path / "t.csv"
    f.write_text("0.5,0.2,0.3,180,0,0\n", encoding="utf-8")
    res = run("ik-compare", "puma560", "--target-file", f, "--methods", "lm", code=2)
    assert "--degrees" in res.stderr
    run("ik-compare", "puma560", "--target-file", f, "--methods", "lm", "--degrees")


def test_base_placement_tasks_units(tmp_path):
    """base-placement reads task rpy in degrees with --degrees or units: {angle: deg}."""
    from serialkin.cli.io import CLIError
    from serialkin.cli.reach_cmd import read_tasks

    rows = [[0.4, 0.1, 0.3, 180.0, 0.0, 90.0]]
    plain = tmp_path / "plain.yaml"
    plain.write_text(yaml.safe_dump({"tasks": rows}), encoding="utf-8")
    with pytest.raises(CLIError, match="beyond a full turn.*--degrees"):
        read_tasks(str(plain))
    a = read_tasks(str(plain), degrees=True)
    marked = tmp_path / "marked.yaml"
    marked.write_text(yaml.safe_dump({"units": {"angle": "deg"}, "tasks": rows}),
                      encoding="utf-8")
    np.testing.assert_allclose(read_tasks(str(marked)), a, atol=1e-15)
    np.testing.assert_allclose(a[0, :3, :3], [[0, 1, 0], [1, 0, 0], [0, 0, -1]], atol=1e-12)
    res = run("base-placement", "ur5", "--tasks", plain, "--out", tmp_path / "b", code=2)
    assert "--degrees" in res.stderr
    assert "--degrees" in run("base-placement", "--help").stdout


def test_track_max_joint_step_units(tmp_path):
    """Track takes --max-joint-step-deg and refuses a radian step beyond a turn."""
    res = run("track", "six_link_circle", "--max-joint-step", "30", "--out", tmp_path, code=2)
    assert "--max-joint-step-deg" in res.stderr
    res = run("track", "six_link_circle", "--max-joint-step", "0.5", "--max-joint-step-deg",
              "30", "--out", tmp_path, code=2)
    assert "both given" in res.stderr


_LINE = {"robot": {"model": "ur5"}, "q0": [0, -1.2, 1.4, 0, 0.5, 0],
         "path": {"type": "line", "start": "q0",
                  "end": {"position": [0.3, 0.2, 0.4], "rpy": [180, 0, 0]}}}


def test_scenario_rpy_in_radians_beyond_a_turn_is_refused():
    """A scenario rpy of 180 read as radians is refused, naming the field and units: deg."""
    with pytest.raises(ScenarioError, match=r"path\.end\.rpy.*units: \{angle: deg\}"):
        scenario_from_dict(_LINE)


def test_scenario_units_deg_reads_every_angle_in_degrees():
    """units: {angle: deg} reads q0, rpy and max_angle in degrees, as their _deg forms do."""
    deg = dict(_LINE, units={"angle": "deg"}, q0=[0, -60, 80, 0, 30, 0])
    deg["path"] = dict(_LINE["path"], max_angle=2)
    explicit = dict(_LINE, q0_deg=[0, -60, 80, 0, 30, 0])
    del explicit["q0"]
    explicit["path"] = dict(_LINE["path"], max_angle_deg=2,
                            end={"position": [0.3, 0.2, 0.4], "rpy_deg": [180, 0, 0]})
    a, b = scenario_from_dict(deg), scenario_from_dict(explicit)
    np.testing.assert_allclose(a.q0, np.radians([0, -60, 80, 0, 30, 0]))
    np.testing.assert_allclose(a.path.targets, b.path.targets, atol=1e-12)


def test_scenario_units_field_is_checked():
    """Units must be {angle: rad|deg}; a max_angle beyond its radian range hints at degrees."""
    with pytest.raises(ScenarioError, match="units.angle"):
        scenario_from_dict(dict(_LINE, units={"angle": "grad"}))
    line = {"robot": {"planar": {"links": 3, "length": 0.3}},
            "path": {"type": "line", "start": {"position": [0.3, 0, 0]},
                     "end": {"position": [0.4, 0, 0]}, "max_angle": 5}}
    with pytest.raises(ScenarioError, match="max_angle.*are these degrees"):
        scenario_from_dict(line)


def test_scenario_circle_in_degrees():
    """A circle's start/stop/step in degrees gives the same path as in radians."""
    base = {"robot": {"planar": {"links": 3, "length": 0.3}},
            "path": {"type": "circle", "center": [0.4, 0], "radius": 0.1}}
    rad = dict(base, path=dict(base["path"], start=0, stop=math.pi, step=0.1))
    deg = dict(base, units={"angle": "deg"},
               path=dict(base["path"], start=0, stop=180, step=math.degrees(0.1)))
    np.testing.assert_allclose(scenario_from_dict(deg).path.points,
                               scenario_from_dict(rad).path.points, atol=1e-12)
