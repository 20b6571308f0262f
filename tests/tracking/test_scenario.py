"""Scenario files: the shipped ones load; malformed ones fail naming the field and the file."""

from __future__ import annotations

import json

import numpy as np
import pytest
import yaml

from serialkin.errors import InputError
from serialkin.tracking import ScenarioError, list_scenarios, load_scenario, scenario_from_dict

BASE = {
    "robot": {"planar": {"links": 4, "length": 0.1}},
    "path": {"type": "points", "points": [[0.2, 0.1], [0.2, 0.15]]},
}


def _write(tmp_path, data, name="s.yaml"):
    p = tmp_path / name
    p.write_text(json.dumps(data) if name.endswith(".json") else yaml.safe_dump(data))
    return p


def test_shipped_scenarios_listed_and_loadable():
    """The three chapter scenarios ship and validate."""
    names = list_scenarios()
    assert {"six_link_circle", "twenty_link_free", "twenty_link_obstacles"} <= set(names)
    for n in names:
        s = load_scenario(n)
        assert s.robot.n in (6, 20) and len(s.path) > 10


def test_yaml_and_json_agree(tmp_path):
    """The same scenario as YAML and as JSON gives the same robot, path and start."""
    a = load_scenario(_write(tmp_path, BASE, "a.yaml"))
    b = load_scenario(_write(tmp_path, BASE, "b.json"))
    np.testing.assert_allclose(a.path.targets, b.path.targets)
    assert a.robot.n == b.robot.n == 4
    assert a.run().complete


@pytest.mark.parametrize("mutate, field", [
    (lambda d: d.pop("robot"), "'robot' is missing"),
    (lambda d: d["robot"]["planar"].pop("length"), "'robot.planar.length' is missing"),
    (lambda d: d["robot"]["planar"].update(length="long"), "'robot.planar.length' must be"),
    (lambda d: d["path"].pop("type"), "'path.type' is missing"),
    (lambda d: d["path"].update(type="spiral"), "'path.type' must be one of"),
    (lambda d: d["path"].update(points=[[0.1, "x"]]), "'path.points'"),
    (lambda d: d["path"].update(points=[[0.1, float("nan")]]), "'path.points' must be finite"),
    (lambda d: d.update(tolerance=-0.1), "'tolerance' must be a number > 0"),
    (lambda d: d.update(q0=[0.0, 0.1]), "'q0' must have 4 values"),
    (lambda d: d.update(on_unreachable="skip"), "'on_unreachable'"),
    (lambda d: d.update(solver={"method": "multitask", "obstacle_weight": -5}),
     "'solver.obstacle_weight' must be a number >= 0"),
    (lambda d: d.update(solver={"method": "dls", "damping": "big"}), "'solver.damping'"),
    (lambda d: d.update(obstacles=[{"type": "circle", "center": [0.2, 0.0]}]),
     "'obstacles[0].radius' is missing"),
    (lambda d: d.update(obstacles=[{"type": "circle", "center": [0.0, 0.0], "radius": 0.05}]),
     "overlaps the robot base"),
])
def test_bad_scenarios_name_field_and_file(tmp_path, mutate, field):
    """Each malformed scenario raises ScenarioError naming the file and the field."""
    data = json.loads(json.dumps(BASE))
    mutate(data)
    p = _write(tmp_path, data, "broken.yaml")
    with pytest.raises(ScenarioError) as info:
        load_scenario(p)
    msg = str(info.value)
    assert "broken.yaml" in msg
    assert field in msg


def test_unknown_field_suggests_the_right_name(tmp_path):
    """A misspelt field is reported with a suggestion."""
    data = dict(BASE, tolerence=0.01)
    with pytest.raises(ScenarioError, match="did you mean 'tolerance'"):
        load_scenario(_write(tmp_path, data, "typo.yaml"))


def test_unparsable_and_missing_files(tmp_path):
    """A file that is not YAML and a name that is neither file nor shipped scenario fail clearly."""
    p = tmp_path / "bad.yaml"
    p.write_text("robot: [unclosed\n")
    with pytest.raises(ScenarioError, match="bad.yaml"):
        load_scenario(p)
    with pytest.raises(InputError, match="shipped scenarios"):
        load_scenario("no_such_scenario")
    with pytest.raises(ScenarioError, match="mapping"):
        scenario_from_dict([1, 2], source="list.yaml")
