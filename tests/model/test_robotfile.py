"""Robot files (YAML/JSON): units, base/tool, round trips and error messages."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
import yaml
from hypothesis import given, settings
from hypothesis import strategies as st

from serialkin import Robot, models
from serialkin.errors import RobotDefinitionError
from serialkin.formats.robotfile import load_robot_file, robot_from_dict, save_robot_file
from serialkin.spatial import make_transform, rpy_to_matrix

EXAMPLES = Path(__file__).resolve().parents[2] / "examples" / "robots"


def _write(tmp_path: Path, data: object, name: str = "robot.yaml") -> Path:
    p = tmp_path / name
    p.write_text(json.dumps(data) if name.endswith(".json") else yaml.safe_dump(data))
    return p


def _base_doc() -> dict:
    return {
        "name": "arm",
        "convention": "standard",
        "units": {"angle": "deg", "length": "mm"},
        "dh": [
            {"a": 1000, "alpha": 0, "d": 0, "theta": 0, "type": "R", "qlim": [-90, 90]},
            {"a": 600, "alpha": 90, "d": 50, "theta": 10, "type": "R"},
            {"a": 0, "alpha": 0, "d": 100, "theta": 0, "type": "P", "qlim": [0, 300]},
        ],
        "base": {"xyz": [0, 0, 500], "rpy": [0, 0, 45]},
        "tool": [[1, 0, 0, 20], [0, 1, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1]],
    }


def test_units_are_converted_to_si(tmp_path):
    """Degrees and millimetres in the file become radians and metres in the robot."""
    r = load_robot_file(_write(tmp_path, _base_doc()))
    assert r.n == 3 and r.joint_types == ("R", "R", "P")
    assert r.dh[0].a == pytest.approx(1.0)
    assert r.dh[1].alpha == pytest.approx(np.pi / 2)
    assert r.dh[1].theta == pytest.approx(np.radians(10))
    assert r.dh[1].d == pytest.approx(0.05)
    np.testing.assert_allclose(r.qlim[0], np.radians([-90, 90]))
    np.testing.assert_allclose(r.qlim[2], [0.0, 0.3])
    assert np.isinf(r.qlim[1]).all()
    np.testing.assert_allclose(r.base, make_transform(rpy_to_matrix(np.radians([0, 0, 45])),
                                                      [0, 0, 0.5]), atol=1e-15)
    np.testing.assert_allclose(r.tool[:3, 3], [0.02, 0, 0])


def test_same_robot_as_from_dh(tmp_path):
    """A robot file gives the same FK as Robot.from_dh with the SI values."""
    r = load_robot_file(_write(tmp_path, _base_doc(), "robot.json"))
    ref = Robot.from_dh(
        [dict(a=1.0, alpha=0, d=0, theta=0), dict(a=0.6, alpha=np.pi / 2, d=0.05,
                                                   theta=np.radians(10)),
         dict(a=0, alpha=0, d=0.1, theta=0, type="P")],
        base=make_transform(rpy_to_matrix([0, 0, np.pi / 4]), [0, 0, 0.5]),
        tool=make_transform(p=[0.02, 0, 0]))
    Q = r.random_q(20, seed=1)
    np.testing.assert_allclose(r.fk(Q), ref.fk(Q), atol=1e-12)


@pytest.mark.parametrize("name", ["puma560", "panda", "stanford", "scara", "two_link"])
@pytest.mark.parametrize("suffix", [".yaml", ".json"])
@pytest.mark.parametrize("units", [("deg", "mm"), ("rad", "m")])
def test_save_load_round_trip(tmp_path, name, suffix, units):
    """save_robot_file then load_robot_file reproduces FK, limits and convention."""
    r = models.get(name)
    p = save_robot_file(r, tmp_path / f"r{suffix}", angle_unit=units[0], length_unit=units[1])
    r2 = load_robot_file(p)
    assert r2.convention == r.convention and r2.name == r.name and r2.n == r.n
    np.testing.assert_allclose(r2.qlim, r.qlim, atol=1e-9)
    Q = r.random_q(25, seed=3)
    np.testing.assert_allclose(r2.fk(Q), r.fk(Q), atol=1e-9)


@settings(max_examples=30, deadline=None)
@given(st.lists(st.tuples(st.floats(-2, 2), st.floats(-3.1, 3.1), st.floats(-2, 2),
                          st.floats(-3.1, 3.1), st.sampled_from("RP")), min_size=1, max_size=7),
       st.sampled_from(["standard", "modified"]))
def test_random_dh_round_trip(rows, convention):
    """Any DH table survives robot_to_dict / robot_from_dict (both conventions)."""
    from serialkin.formats.robotfile import robot_to_dict

    r = Robot.from_dh([dict(a=a, alpha=al, d=d, theta=th, type=t) for a, al, d, th, t in rows],
                      convention)
    r2 = robot_from_dict(yaml.safe_load(yaml.safe_dump(robot_to_dict(r))))
    Q = r.random_q(5, seed=0)
    np.testing.assert_allclose(r2.fk(Q), r.fk(Q), atol=1e-9)


def test_example_files_load():
    """Every shipped example robot file loads."""
    files = sorted(EXAMPLES.glob("*.y*ml")) + sorted(EXAMPLES.glob("*.json"))
    assert files
    for f in files:
        r = load_robot_file(f)
        assert r.n >= 1


@pytest.mark.parametrize(
    ("mutate", "needle"),
    [
        (lambda d: d["dh"][1].pop("alpha"), "dh[1].alpha"),
        (lambda d: d["dh"][2].__setitem__("a", "long"), "dh[2].a"),
        (lambda d: d["dh"][0].__setitem__("type", "spherical"), "dh[0].type"),
        (lambda d: d["dh"][0].__setitem__("qlim", [90, -90]), "dh[0].qlim"),
        (lambda d: d["dh"][0].__setitem__("qlim", [1]), "dh[0].qlim"),
        (lambda d: d["dh"][0].__setitem__("offset", 1), "dh[0]"),
        (lambda d: d.pop("units"), "'units'"),
        (lambda d: d["units"].pop("angle"), "units.angle"),
        (lambda d: d["units"].__setitem__("angle", "grad"), "units.angle"),
        (lambda d: d["units"].__setitem__("length", "inch"), "units.length"),
        (lambda d: d.__setitem__("convention", "craig"), "convention"),
        (lambda d: d.__setitem__("dh", []), "dh"),
        (lambda d: d.__setitem__("colour", "red"), "colour"),
        (lambda d: d["base"].__setitem__("rpy", [0, 0]), "base.rpy"),
        (lambda d: d.__setitem__("tool", [[1, 0, 0, 0], [0, 2, 0, 0], [0, 0, 1, 0],
                                          [0, 0, 0, 1]]), "tool"),
        (lambda d: d.__setitem__("name", ""), "name"),
    ],
)
def test_malformed_file_names_file_and_field(tmp_path, mutate, needle):
    """A malformed robot file raises RobotDefinitionError naming the file and the field."""
    doc = _base_doc()
    mutate(doc)
    p = _write(tmp_path, doc)
    with pytest.raises(RobotDefinitionError) as info:
        load_robot_file(p)
    msg = str(info.value)
    assert str(p) in msg
    assert needle in msg


def test_syntax_error_gives_line(tmp_path):
    """A YAML/JSON syntax error names the file and the line."""
    p = tmp_path / "bad.yaml"
    p.write_text("name: x\nunits: {angle: deg\ndh: [\n")
    with pytest.raises(RobotDefinitionError, match=r"bad\.yaml: invalid YAML at line \d+"):
        load_robot_file(p)
    j = tmp_path / "bad.json"
    j.write_text('{"name": "x",\n "dh": [}\n')
    with pytest.raises(RobotDefinitionError, match=r"bad\.json: invalid JSON at line 2"):
        load_robot_file(j)


def test_missing_and_unknown_suffix(tmp_path):
    """A missing file or an unknown suffix is a clear error."""
    with pytest.raises(RobotDefinitionError, match="not found"):
        load_robot_file(tmp_path / "nope.yaml")
    with pytest.raises(RobotDefinitionError, match="unknown robot file type"):
        load_robot_file(tmp_path / "robot.txt")


def test_save_is_atomic_and_rejects_urdf_robots(tmp_path):
    """Saving leaves no temporary file; a robot without DH table cannot be saved."""
    save_robot_file(models.get("ur5"), tmp_path / "ur5.yaml")
    assert [p.name for p in tmp_path.iterdir()] == ["ur5.yaml"]
    r = models.get("ur5")
    no_dh = Robot.from_joints(list(r.joints), name="joints-only")
    with pytest.raises(RobotDefinitionError, match="no DH table"):
        save_robot_file(no_dh, tmp_path / "x.yaml")


def test_puma_example_matches_builtin_model():
    """examples/robots/puma560.yaml (mm, deg) has the FK and limits of models.puma560."""
    a = load_robot_file(EXAMPLES / "puma560.yaml")
    b = models.puma560()
    Q = b.random_q(50, seed=2)
    np.testing.assert_allclose(a.fk(Q), b.fk(Q), atol=1e-12)
    np.testing.assert_allclose(a.qlim, b.qlim, atol=1e-12)


@pytest.mark.parametrize("pitch", [0.4, np.pi / 2, -np.pi / 2])
def test_base_tool_round_trip(tmp_path, pitch):
    """Base and tool survive save/load as xyz + rpy, also at the rpy gimbal lock."""
    r = models.get("ur5")
    r = r.with_base(make_transform(rpy_to_matrix([0.3, pitch, -1.0]), [1.0, 2.0, 3.0]))
    r = r.with_tool(make_transform(rpy_to_matrix([np.pi, 0.0, 0.2]), [0.0, 0.0, 0.1]))
    p = save_robot_file(r, tmp_path / "r.yaml", length_unit="mm")
    doc = yaml.safe_load(p.read_text())
    assert set(doc["base"]) == {"xyz", "rpy"} and doc["base"]["xyz"] == [1000.0, 2000.0, 3000.0]
    r2 = load_robot_file(p)
    np.testing.assert_allclose(r2.base, r.base, atol=1e-12)
    np.testing.assert_allclose(r2.tool, r.tool, atol=1e-12)
