"""Link geometry read from URDF: shapes posed in chain frames, mesh paths, round trip."""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from serialkin import Robot
from serialkin.errors import RobotDefinitionError
from serialkin.formats.urdf import rpy_to_matrix
from serialkin.model.geometry import Box, Capsule, Cylinder, LinkGeometry, Mesh, Shape, Sphere

_ERD = (Path(sys.prefix) / "lib" / f"python{sys.version_info.major}.{sys.version_info.minor}"
        / "site-packages" / "cmeel.prefix" / "share" / "example-robot-data")
PANDA = _ERD / "robots" / "panda_description" / "urdf" / "panda.urdf"

# base_link -(fixed)-> plate -(R, axis y)-> link1 -(P, axis x)-> link2 -(fixed)-> hand
#   -(fixed)-> tcp; link1 -(fixed)-> sensor (off the chain)
URDF = """<?xml version="1.0"?>
<robot name="geo">
  <link name="base_link">
    <visual><origin xyz="0 0 0.05"/><geometry><box size="0.3 0.2 0.1"/></geometry>
      <material name="grey"><color rgba="0.5 0.5 0.5 1"/></material></visual>
  </link>
  <link name="plate">
    <collision name="plate_c"><origin xyz="0.01 0 0.02" rpy="0.1 0 0"/>
      <geometry><cylinder radius="0.1" length="0.04"/></geometry></collision>
  </link>
  <link name="link1">
    <visual><origin xyz="0 0 0.2" rpy="0.3 -0.2 0.5"/>
      <geometry><mesh filename="meshes/l1.stl" scale="0.001 0.001 0.001"/></geometry></visual>
    <collision><origin xyz="0 0.05 0.2"/><geometry><sphere radius="0.07"/></geometry></collision>
  </link>
  <link name="link2">
    <collision><origin xyz="0.1 0 0" rpy="0 1.5707963267948966 0"/>
      <geometry><capsule radius="0.04" length="0.2"/></geometry></collision>
  </link>
  <link name="hand">
    <visual><origin xyz="0 0 0.03" rpy="0 0 0.7"/>
      <geometry><mesh filename="package://mypkg/hand.stl"/></geometry></visual>
    <collision><origin xyz="0 0 0.03"/><geometry><box size="0.05 0.2 0.06"/></geometry>
    </collision>
  </link>
  <link name="tcp"/>
  <link name="sensor">
    <visual><origin xyz="0.02 0 0"/><geometry><sphere radius="0.02"/></geometry></visual>
  </link>
  <joint name="mount" type="fixed"><parent link="base_link"/><child link="plate"/>
    <origin xyz="0.1 0.2 0.3" rpy="0 0 0.4"/></joint>
  <joint name="j1" type="revolute"><parent link="plate"/><child link="link1"/>
    <origin xyz="0 0 0.1" rpy="0.2 0 0"/><axis xyz="0 1 0"/>
    <limit lower="-3" upper="3" effort="1" velocity="1"/></joint>
  <joint name="j2" type="prismatic"><parent link="link1"/><child link="link2"/>
    <origin xyz="0 0 0.4" rpy="0 0.3 0"/><axis xyz="1 0 0"/>
    <limit lower="-0.2" upper="0.2" effort="1" velocity="1"/></joint>
  <joint name="flange" type="fixed"><parent link="link2"/><child link="hand"/>
    <origin xyz="0.2 0 0" rpy="0 0 -0.7853981633974483"/></joint>
  <joint name="tcp_joint" type="fixed"><parent link="hand"/><child link="tcp"/>
    <origin xyz="0 0 0.1"/></joint>
  <joint name="sensor_joint" type="fixed"><parent link="link1"/><child link="sensor"/>
    <origin xyz="0.05 0.05 0.1" rpy="0.5 0 0"/></joint>
</robot>
"""

JOINTS = {  # child: (parent, type, xyz, rpy, axis)
    "plate": ("base_link", "fixed", (0.1, 0.2, 0.3), (0, 0, 0.4), None),
    "link1": ("plate", "R", (0, 0, 0.1), (0.2, 0, 0), (0, 1, 0)),
    "link2": ("link1", "P", (0, 0, 0.4), (0, 0.3, 0), (1, 0, 0)),
    "hand": ("link2", "fixed", (0.2, 0, 0), (0, 0, -np.pi / 4), None),
    "tcp": ("hand", "fixed", (0, 0, 0.1), (0, 0, 0), None),
    "sensor": ("link1", "fixed", (0.05, 0.05, 0.1), (0.5, 0, 0), None),
}


def _tf(xyz, rpy) -> np.ndarray:
    T = np.eye(4)
    T[:3, :3] = rpy_to_matrix(np.asarray(rpy, dtype=float))
    T[:3, 3] = xyz
    return T


def _world_links(q: np.ndarray) -> dict[str, np.ndarray]:
    """World pose of every URDF link, by walking the joints as the URDF spec reads."""
    values = {"link1": q[0], "link2": q[1]}
    out = {"base_link": np.eye(4)}
    for child, (parent, kind, xyz, rpy, axis) in JOINTS.items():
        M = np.eye(4)
        if kind == "R":
            M[:3, :3] = Rotation.from_rotvec(np.asarray(axis, float) * values[child]).as_matrix()
        elif kind == "P":
            M[:3, 3] = np.asarray(axis, float) * values[child]
        out[child] = out[parent] @ _tf(xyz, rpy) @ M
    return out


@pytest.fixture()
def urdf_dir(tmp_path: Path) -> Path:
    """A URDF file with a relative mesh and a package mesh, both present on disk."""
    (tmp_path / "urdf" / "meshes").mkdir(parents=True)
    (tmp_path / "urdf" / "meshes" / "l1.stl").write_bytes(b"solid x\nendsolid x\n")
    (tmp_path / "pkgs" / "mypkg").mkdir(parents=True)
    (tmp_path / "pkgs" / "mypkg" / "hand.stl").write_bytes(b"solid y\nendsolid y\n")
    (tmp_path / "urdf" / "geo.urdf").write_text(URDF)
    return tmp_path


def _load(urdf_dir: Path, **kw) -> Robot:
    return Robot.from_urdf(str(urdf_dir / "urdf" / "geo.urdf"), tip_link="tcp",
                           package_map={"mypkg": urdf_dir / "pkgs" / "mypkg"}, **kw)


def _world_shapes(robot: Robot, q: np.ndarray) -> dict[tuple[int, str], list]:
    """(frame, kind) -> [(geometry, world pose)] in order."""
    frames = robot.fk_all(q)
    out: dict[tuple[int, str], list] = {}
    for lg in robot.geometry:
        for kind in ("visual", "collision"):
            for s in getattr(lg, kind):
                pose = frames[lg.frame] @ s.origin
                out.setdefault((lg.frame, kind), []).append((s.geometry, pose))
    return out


def test_shape_world_poses_match_the_urdf_joint_chain(urdf_dir: Path) -> None:
    """fk_all[frame] @ origin equals the link pose walked by hand times the URDF origin."""
    robot = _load(urdf_dir)
    by_link = {lg.link_name: lg for lg in robot.geometry}
    assert {n: lg.frame for n, lg in by_link.items()} == {
        "base_link": 0, "plate": 0, "link1": 1, "link2": 2, "hand": 2, "tcp": 2, "sensor": 1}
    local = {  # link: [(kind, xyz, rpy)] as written in the URDF
        "base_link": [("visual", (0, 0, 0.05), (0, 0, 0))],
        "plate": [("collision", (0.01, 0, 0.02), (0.1, 0, 0))],
        "link1": [("visual", (0, 0, 0.2), (0.3, -0.2, 0.5)),
                  ("collision", (0, 0.05, 0.2), (0, 0, 0))],
        "link2": [("collision", (0.1, 0, 0), (0, np.pi / 2, 0))],
        "hand": [("visual", (0, 0, 0.03), (0, 0, 0.7)), ("collision", (0, 0, 0.03), (0, 0, 0))],
        "sensor": [("visual", (0.02, 0, 0), (0, 0, 0))],
    }
    rng = np.random.default_rng(12)
    for q in rng.uniform([-3, -0.2], [3, 0.2], size=(5, 2)):
        frames = robot.fk_all(q)
        world = _world_links(q)
        for link, shapes in local.items():
            lg = by_link[link]
            for kind, xyz, rpy in shapes:
                (s,) = getattr(lg, kind)
                np.testing.assert_allclose(frames[lg.frame] @ s.origin,
                                           world[link] @ _tf(xyz, rpy), atol=1e-12)


def test_geometry_values_and_mesh_resolution(urdf_dir: Path) -> None:
    """Primitives keep their sizes; relative and package:// meshes resolve to the files."""
    by_link = {lg.link_name: lg for lg in _load(urdf_dir).geometry}
    assert by_link["base_link"].visual[0].geometry == Box((0.3, 0.2, 0.1))
    assert by_link["base_link"].visual[0].rgba == (0.5, 0.5, 0.5, 1.0)
    assert by_link["base_link"].visual[0].material == "grey"
    assert by_link["plate"].collision[0].geometry == Cylinder(0.1, 0.04)
    assert by_link["plate"].collision[0].name == "plate_c"
    assert by_link["link1"].collision[0].geometry == Sphere(0.07)
    assert by_link["link2"].collision[0].geometry == Capsule(0.04, 0.2)
    l1 = by_link["link1"].visual[0].geometry
    assert l1 == Mesh(str((urdf_dir / "urdf" / "meshes" / "l1.stl").resolve()), (1e-3,) * 3)
    assert by_link["hand"].visual[0].geometry.filename == str(
        (urdf_dir / "pkgs" / "mypkg" / "hand.stl").resolve())
    # the same package found through a search path instead of the map
    robot = Robot.from_urdf(str(urdf_dir / "urdf" / "geo.urdf"), tip_link="tcp",
                            search_path=[urdf_dir / "pkgs"], resolve_meshes=True)
    hand = {lg.link_name: lg for lg in robot.geometry}["hand"]
    assert Path(hand.visual[0].geometry.filename).is_file()


def test_round_trip_through_to_urdf_keeps_shapes_and_world_poses(urdf_dir: Path) -> None:
    """Import -> to_urdf -> import: same geometries at the same world poses, per frame."""
    robot = _load(urdf_dir)
    again = Robot.from_urdf(robot.to_urdf(), resolve_meshes=True)
    rng = np.random.default_rng(3)
    for q in rng.uniform([-3, -0.2], [3, 0.2], size=(4, 2)):
        a, b = _world_shapes(robot, q), _world_shapes(again, q)
        assert a.keys() == b.keys()
        for key in a:
            assert [g for g, _ in a[key]] == [g for g, _ in b[key]]
            for (_, Ta), (_, Tb) in zip(a[key], b[key], strict=True):
                np.testing.assert_allclose(Ta, Tb, atol=1e-12)
    colours = [s.rgba for lg in again.geometry for s in lg.visual if s.rgba is not None]
    assert colours == [(0.5, 0.5, 0.5, 1.0)]


def test_copies_keep_the_geometry(urdf_dir: Path) -> None:
    """with_tool, with_base and with_limits carry the same geometry tuple."""
    robot = _load(urdf_dir)
    assert robot.geometry
    for other in (robot.with_tool(np.eye(4)), robot.with_base(np.eye(4)),
                  robot.with_limits([(-1, 1), (-0.1, 0.1)])):
        assert other.geometry is robot.geometry
    assert Robot.from_dh([{"a": 0, "alpha": 0, "d": 1, "theta": 0}]).geometry == ()


@pytest.mark.skipif(not PANDA.exists(), reason="example-robot-data (bench extra) is not installed")
def test_panda_links_have_visual_and_collision_meshes_that_resolve() -> None:
    """Every Panda link with a body (link0..7, hand) has a visual and a collision mesh file."""
    robot = Robot.from_urdf(str(PANDA), "panda_link0", "panda_hand",
                            package_map={"example-robot-data": _ERD}, resolve_meshes=True)
    with_shapes = {lg.link_name: lg for lg in robot.geometry if lg.visual or lg.collision}
    assert set(with_shapes) == {f"panda_link{i}" for i in range(8)} | {"panda_hand"}
    assert with_shapes["panda_hand"].frame == 7
    for lg in with_shapes.values():
        assert len(lg.visual) == len(lg.collision) == 1
        for s in (*lg.visual, *lg.collision):
            assert isinstance(s.geometry, Mesh) and Path(s.geometry.filename).is_file()


def test_negative_or_nonfinite_size_names_link_geometry_and_field() -> None:
    """A negative radius or a NaN box size is refused, naming link, geometry and field."""
    bad = URDF.replace('<sphere radius="0.07"/>', '<sphere radius="-0.07"/>')
    with pytest.raises(RobotDefinitionError, match=r"link 'link1'.*sphere radius"):
        Robot.from_urdf(bad, tip_link="tcp")
    bad = URDF.replace('<box size="0.05 0.2 0.06"/>', '<box size="0.05 nan 0.06"/>')
    with pytest.raises(RobotDefinitionError, match=r"link 'hand'.*box size"):
        Robot.from_urdf(bad, tip_link="tcp")
    with pytest.raises(RobotDefinitionError, match=r"capsule length"):
        Capsule(0.1, -1.0)
    with pytest.raises(RobotDefinitionError, match=r"box size"):
        Box((1.0, float("inf"), 1.0))
    with pytest.raises(RobotDefinitionError, match=r"frame"):
        LinkGeometry("x", -1)
    with pytest.raises(RobotDefinitionError, match=r"rgba"):
        Shape(Sphere(1.0), rgba=(2, 0, 0, 1))


def test_unresolved_mesh_is_kept_or_refused_with_where_it_looked(urdf_dir: Path) -> None:
    """Without a package map the mesh keeps its path; resolve_meshes=True names link and places."""
    path = str(urdf_dir / "urdf" / "geo.urdf")
    robot = Robot.from_urdf(path, tip_link="tcp", search_path=[urdf_dir])
    hand = {lg.link_name: lg for lg in robot.geometry}["hand"]
    assert hand.visual[0].geometry.filename == "package://mypkg/hand.stl"
    with pytest.raises(RobotDefinitionError,
                       match=r"link 'hand'.*package://mypkg/hand\.stl.*looked in.*mypkg"):
        Robot.from_urdf(path, tip_link="tcp", search_path=[urdf_dir], resolve_meshes=True)
    with pytest.raises(RobotDefinitionError, match=r"link 'link1'.*meshes/l1\.stl.*nowhere"):
        Robot.from_urdf(URDF, tip_link="tcp", resolve_meshes=True)


def test_hostile_mesh_paths_are_unresolved_not_crashes() -> None:
    """A mesh name too long for the file system is kept, or refused with the library's error."""
    urdf = URDF.replace("meshes/l1.stl", "x" * 5000)
    robot = Robot.from_urdf(urdf, tip_link="tcp", search_path=["/tmp"])
    l1 = {lg.link_name: lg for lg in robot.geometry}["link1"]
    assert l1.visual[0].geometry.filename == "x" * 5000
    with pytest.raises(RobotDefinitionError, match=r"link 'link1'.*does not resolve"):
        Robot.from_urdf(urdf, tip_link="tcp", search_path=["/tmp"], resolve_meshes=True)
