"""Link geometry and collision capsules in robot files: reading, writing, round trips, errors."""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pytest
import yaml

from serialkin import models
from serialkin.errors import RobotDefinitionError
from serialkin.formats.robotfile import (
    load_robot_file,
    robot_from_dict,
    robot_to_dict,
    save_robot_file,
)
from serialkin.model.geometry import Box, Capsule, Cylinder, Mesh, Sphere

DOC = """
name: arm
units: {angle: deg, length: mm}
dh:
  - {a: 300, alpha: 0, d: 0, theta: 0}
  - {a: 200, alpha: 0, d: 0, theta: 0}
mesh_path: [meshes]
geometry:
  - link: base
    frame: 0
    collision:
      - {box: {size: [200, 200, 100]}, origin: {xyz: [0, 0, -50]}}
  - link: upper
    frame: 1
    visual:
      - mesh: {file: upper.stl, scale: [0.5, 1, 1]}
        origin: {xyz: [-150, 0, 0], rpy: [0, 0, 90]}
        rgba: [0.8, 0.1, 0.1, 1.0]
        material: red
        name: shell
    collision:
      - {cylinder: {radius: 40, length: 300}, origin: {xyz: [-150, 0, 0], rpy: [0, 90, 0]}}
  - link: fore
    frame: 2
    collision:
      - {capsule: {radius: 30, length: 200}, origin: {xyz: [-100, 0, 0], rpy: [0, 90, 0]}}
      - {sphere: {radius: 35}}
collision:
  - name: upper
    frame: 1
    capsules: [{a: [-300, 0, 0], b: [0, 0, 0], radius: 45}]
  - name: fore
    frame: 2
    capsules: [{a: [-200, 0, 0], b: [0, 0, 0], radius: 35}]
    spheres: [{center: [0, 0, 0], radius: 40}]
"""


@pytest.fixture
def folder(tmp_path: Path) -> Path:
    (tmp_path / "meshes").mkdir()
    (tmp_path / "meshes" / "upper.stl").write_bytes(b"\0" * 84)  # never loaded here
    (tmp_path / "arm.yaml").write_text(DOC)
    return tmp_path


def test_geometry_is_read_in_si_units_and_meshes_resolved(folder: Path) -> None:
    """Sizes in mm and rpy in degrees become metres and radians; the mesh path resolves."""
    robot = load_robot_file(folder / "arm.yaml")
    by = {lg.link_name: lg for lg in robot.geometry}
    assert [lg.frame for lg in robot.geometry] == [0, 1, 2]
    assert by["base"].collision[0].geometry == Box((0.2, 0.2, 0.1))
    np.testing.assert_allclose(by["base"].collision[0].origin[:3, 3], [0, 0, -0.05])
    shell = by["upper"].visual[0]
    assert shell.geometry == Mesh(str((folder / "meshes" / "upper.stl").resolve()),
                                  (0.5, 1.0, 1.0))
    assert shell.rgba == (0.8, 0.1, 0.1, 1.0) and shell.material == "red"
    assert shell.name == "shell"
    np.testing.assert_allclose(shell.origin[:3, :2], [[0, -1], [1, 0], [0, 0]], atol=1e-12)
    assert by["upper"].collision[0].geometry == Cylinder(0.04, 0.3)
    assert by["fore"].collision[0].geometry == Capsule(0.03, 0.2)
    assert by["fore"].collision[1].geometry == Sphere(0.035)
    model = robot.collision
    assert model.body_names == ("upper", "fore")
    np.testing.assert_allclose(model.radius, [0.045, 0.035, 0.04])
    np.testing.assert_allclose(model.a[0], [-0.3, 0, 0])


@pytest.mark.parametrize("suffix", [".yaml", ".json"])
def test_round_trip_keeps_geometry_and_capsules(folder: Path, suffix: str) -> None:
    """Save and reload (YAML and JSON, another folder): same shapes, poses and capsules."""
    robot = load_robot_file(folder / "arm.yaml")
    out = folder / "saved" / f"arm{suffix}"
    out.parent.mkdir()
    save_robot_file(robot, out)
    text = out.read_text()
    assert "../meshes/upper.stl" in text  # written relative to the new file
    again = load_robot_file(out)
    assert len(again.geometry) == len(robot.geometry)
    for g1, g2 in zip(robot.geometry, again.geometry, strict=True):
        assert (g1.link_name, g1.frame) == (g2.link_name, g2.frame)
        for kind in ("visual", "collision"):
            for s1, s2 in zip(getattr(g1, kind), getattr(g2, kind), strict=True):
                assert s1.geometry == s2.geometry
                assert (s1.name, s1.material, s1.rgba) == (s2.name, s2.material, s2.rgba)
                np.testing.assert_allclose(s1.origin, s2.origin, atol=1e-12)
    for field in ("a", "b", "radius"):
        np.testing.assert_allclose(getattr(again.collision, field),
                                   getattr(robot.collision, field), atol=1e-12)
    assert again.collision.body_names == robot.collision.body_names


def test_built_in_capsules_survive_a_robot_file() -> None:
    """The Panda's capsules written to a dict and read back are the same numbers."""
    panda = models.panda()
    data = json.loads(json.dumps(robot_to_dict(panda, "rad", "m")))
    back = robot_from_dict(data, "panda.json")
    for field in ("a", "b", "radius", "body_frames", "shape_body"):
        np.testing.assert_array_equal(getattr(back.collision, field),
                                      getattr(panda.collision, field))


def test_a_fitted_model_can_be_saved_and_edited(folder: Path) -> None:
    """Capsules fitted to primitives are saved; an edited radius is read back."""
    robot, _ = load_robot_file(folder / "arm.yaml").fit_collision()
    path = save_robot_file(robot, folder / "fitted.yaml")
    data = yaml.safe_load(path.read_text())
    data["collision"][0]["capsules"][0]["radius"] = 0.123  # the file is in metres
    path.write_text(yaml.safe_dump(data))
    edited = load_robot_file(path)
    assert edited.collision.radius[0] == pytest.approx(0.123)
    assert edited.collision.body_names == robot.collision.body_names


def _doc(**changes: object) -> dict:
    data = yaml.safe_load(DOC)
    data.pop("mesh_path")
    data["geometry"] = [g for g in data["geometry"] if g["link"] != "upper"]
    data.update(changes)
    return data


@pytest.mark.parametrize(("geometry", "match"), [
    ([{"link": "x", "frame": 0, "collision": [{"sphere": {"radius": -1}}]}],
     r"arm\.yaml: field 'geometry\[0\]\.collision\[0\]\.sphere\.radius' must be a number >= 0"),
    ([{"link": "x", "frame": 0, "collision": [{"box": {"size": [1, -2, 3]}}]}],
     r"'geometry\[0\]\.collision\[0\]\.box\.size\[1\]' must be a number >= 0"),
    ([{"link": "x", "frame": 0, "visual": [{"cone": {"radius": 1}}]}],
     r"unknown field\(s\) 'geometry\[0\]\.visual\[0\]\.cone'.*allowed: box, capsule"),
    ([{"link": "x", "frame": 0, "visual": [{"sphere": {"radius": 1}, "box": {"size": [1, 1, 1]}}]}],
     r"exactly one geometry.*got box, sphere"),
    ([{"link": "x", "frame": 0, "visual": [{"origin": {"xyz": [0, 0, 0]}}]}],
     r"exactly one geometry.*got none"),
    ([{"link": "x", "frame": 3}], r"'geometry\[0\]\.frame' must be an integer in \[0, 2\]"),
    ([{"link": "x", "frame": 0}, {"link": "x", "frame": 1}], r"each link once.*'x'"),
    ([{"link": "x", "frame": 0, "visual": [{"sphere": {"radius": 1}, "rgba": [2, 0, 0, 1]}]}],
     r"rgba\[0\]' must be a number >= 0 \(at most 1\)"),
])
def test_bad_geometry_names_file_and_field(geometry: list, match: str) -> None:
    """Negative sizes, unknown or several kinds, bad frames, duplicates: clear errors."""
    with pytest.raises(RobotDefinitionError, match=match):
        robot_from_dict(_doc(geometry=geometry), "arm.yaml")


@pytest.mark.parametrize(("collision", "match"), [
    ([{"name": "b", "frame": 0, "capsules": [{"a": [0, 0, 0], "b": [1, 0, 0], "radius": -1}]}],
     r"'collision\[0\]\.capsules\[0\]\.radius' must be a number >= 0"),
    ([{"name": "b", "frame": 9}], r"'collision\[0\]\.frame' must be an integer in \[0, 2\]"),
    ([{"name": "b", "frame": 0, "spheres": [{"centre": [0, 0, 0], "radius": 1}]}],
     r"unknown field\(s\) 'collision\[0\]\.spheres\[0\]\.centre' \(did you mean 'center'\?\)"),
    ([{"name": "b", "frame": 0}, {"name": "b", "frame": 1}], r"each body once"),
])
def test_bad_collision_names_file_and_field(collision: list, match: str) -> None:
    """Negative radius, bad frame, misspelt key, duplicate body: clear errors."""
    with pytest.raises(RobotDefinitionError, match=match):
        robot_from_dict(_doc(collision=collision), "arm.yaml")


def test_unresolved_mesh_names_link_path_and_where_it_looked(folder: Path) -> None:
    """A mesh file that is nowhere: the message names the link, the path and the folders."""
    (folder / "meshes" / "upper.stl").unlink()
    with pytest.raises(RobotDefinitionError,
                       match=r"arm\.yaml: field 'geometry\[1\]\.visual\[0\]\.mesh\.file' "
                             r"\(link 'upper'\): mesh 'upper\.stl' does not resolve to a file; "
                             r"looked in .*upper\.stl.*meshes/upper\.stl"):
        load_robot_file(folder / "arm.yaml")


def test_geometry_survives_units_of_the_written_file(folder: Path) -> None:
    """Writing in cm and radians and reading back gives the same metres."""
    robot = load_robot_file(folder / "arm.yaml")
    data = robot_to_dict(robot, "rad", "cm", mesh_base=folder)
    assert data["geometry"][0]["collision"][0]["box"]["size"] == [20.0, 20.0, 10.0]
    assert data["geometry"][1]["visual"][0]["mesh"]["file"] == "meshes/upper.stl"
    rpy = data["geometry"][1]["collision"][0]["origin"]["rpy"]
    assert rpy[1] == pytest.approx(math.pi / 2)
    back = robot_from_dict(data, "x.yaml", folder=folder)
    np.testing.assert_allclose(back.collision.radius, robot.collision.radius)


_FUZZ_DIR = None


def _fuzz_doc() -> dict:
    """DOC with its mesh in a temporary folder (made once), as a plain mapping."""
    global _FUZZ_DIR
    import tempfile

    if _FUZZ_DIR is None:
        _FUZZ_DIR = Path(tempfile.mkdtemp())
        (_FUZZ_DIR / "meshes").mkdir()
        (_FUZZ_DIR / "meshes" / "upper.stl").write_bytes(b"\0" * 84)
    return yaml.safe_load(DOC)


def test_fuzz_geometry_and_collision_fields() -> None:
    """Any geometry or collision field replaced by junk: a robot or a RobotDefinitionError."""
    from hypothesis import HealthCheck, given, settings
    from hypothesis import strategies as st

    from serialkin.errors import SerialkinError
    from tests.test_hostile_files import _json, _paths, _replace, guard

    doc = _fuzz_doc()
    paths = [p for p in _paths(doc) if p and p[0] in ("geometry", "collision", "mesh_path")]

    @settings(max_examples=150, deadline=None, suppress_health_check=[HealthCheck.too_slow])
    @given(path=st.sampled_from(paths), junk=_json)
    def run(path: tuple, junk: object) -> None:
        with guard():
            try:
                robot = robot_from_dict(_replace(doc, path, junk), "fuzz.yaml",
                                        folder=_FUZZ_DIR)
            except RobotDefinitionError as exc:
                assert "fuzz.yaml" in str(exc)
                return
            except SerialkinError as exc:  # pragma: no cover - a wrong error type
                raise AssertionError(f"{type(exc).__name__}: {exc}") from exc
        assert np.isfinite(robot.fk(np.zeros(robot.n))).all()

    run()


def test_relative_mesh_without_a_folder_says_where_to_look() -> None:
    """A relative mesh in a mapping with no file folder and no mesh_path: the fix is named."""
    data = _doc(geometry=[{"link": "x", "frame": 0, "visual": [{"mesh": {"file": "a.stl"}}]}])
    with pytest.raises(RobotDefinitionError, match=r"link 'x'.*'a\.stl'.*nowhere: give mesh_path"):
        robot_from_dict(data, "arm.yaml")


@pytest.mark.parametrize("suffix", [".yaml", ".json"])
def test_capsule_file_round_trip(tmp_path: Path, suffix: str) -> None:
    """A collision model saved to a capsule file (mm) loads back the same in metres."""
    from serialkin.formats.robotfile import load_collision_file, save_collision_file

    puma = models.puma560()
    path = save_collision_file(puma.collision, tmp_path / f"caps{suffix}", length_unit="mm")
    back = load_collision_file(path, puma)
    for field in ("a", "b", "radius"):
        np.testing.assert_allclose(getattr(back, field), getattr(puma.collision, field),
                                   atol=1e-12)
    assert back.body_names == puma.collision.body_names
    np.testing.assert_array_equal(back.body_frames, puma.collision.body_frames)
    assert puma.with_collision(back).collision is back


def test_capsule_file_errors_name_the_file(tmp_path: Path) -> None:
    """A frame beyond the robot, a missing section or a bad unit: errors naming the file."""
    from serialkin.formats.robotfile import collision_from_dict, load_collision_file

    p = tmp_path / "caps.yaml"
    p.write_text("collision:\n  - {name: a, frame: 7, spheres: [{center: [0, 0, 0], "
                 "radius: 0.1}]}\n")
    with pytest.raises(RobotDefinitionError, match=r"caps\.yaml: field 'collision\[0\]\.frame'"
                                                   r" must be an integer in \[0, 6\]"):
        load_collision_file(p, models.puma560())
    assert load_collision_file(p).body_frames.tolist() == [7]
    with pytest.raises(RobotDefinitionError, match=r"x\.yaml: field 'collision' is missing"):
        collision_from_dict({"units": {"length": "m"}}, "x.yaml")
    with pytest.raises(RobotDefinitionError, match=r"'units\.length' must be one of m, cm, mm"):
        collision_from_dict({"units": {"length": "ft"}, "collision": []}, "x.yaml")
