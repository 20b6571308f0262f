"""Mesh loading (serialkin.formats.mesh): units, scenes, scale, cache, decimation, bad files."""

from __future__ import annotations

import os
import sys
from pathlib import Path

import numpy as np
import pytest

from serialkin import Robot
from serialkin.errors import NotSupportedError, RobotDefinitionError
from serialkin.formats import mesh as mesh_mod
from serialkin.formats.mesh import (
    TriangleMesh,
    decimate,
    link_meshes,
    load_mesh,
    primitive_mesh,
)
from serialkin.model.geometry import Box, Capsule, Cylinder, Sphere
from tests.erd import robots_dir, urdf

trimesh = pytest.importorskip("trimesh")


def _box_file(tmp_path: Path, suffix: str, extents=(0.1, 0.2, 0.3)) -> Path:
    p = tmp_path / f"box{suffix}"
    trimesh.creation.box(extents=extents).export(str(p))
    return p


@pytest.mark.parametrize("suffix", [".stl", ".obj", ".glb", ".ply"])
def test_box_files_load_with_their_volume_and_bounds(tmp_path: Path, suffix: str) -> None:
    """A 0.1 × 0.2 × 0.3 m box written as STL/OBJ/GLB/PLY loads with volume 6e-3 m³."""
    m = load_mesh(_box_file(tmp_path, suffix))
    assert m.vertices.dtype == np.float64 and m.faces.shape[1] == 3
    assert m.volume == pytest.approx(0.006, rel=1e-6)
    np.testing.assert_allclose(m.bounds, [[-0.05, -0.1, -0.15], [0.05, 0.1, 0.15]], atol=1e-7)


def test_scale_multiplies_each_axis(tmp_path: Path) -> None:
    """A scale (sx, sy, sz) multiplies the coordinates: the volume by sx·sy·sz."""
    m = load_mesh(_box_file(tmp_path, ".stl"), scale=(2.0, 1.0, 0.5))
    np.testing.assert_allclose(m.bounds[1], [0.1, 0.1, 0.075], atol=1e-7)
    assert m.volume == pytest.approx(0.006, rel=1e-6)


def test_dae_unit_is_honoured(tmp_path: Path) -> None:
    """A COLLADA file with <unit meter="0.001"> (millimetres) is scaled to metres."""
    text = trimesh.exchange.dae.export_collada(trimesh.creation.box(extents=(100, 200, 300)))
    text = text.decode() if isinstance(text, bytes) else text
    mm = tmp_path / "mm.dae"
    mm.write_text(text.replace("<asset>", '<asset><unit meter="0.001" name="millimeter"/>', 1))
    m = load_mesh(mm)
    np.testing.assert_allclose(m.bounds[1] - m.bounds[0], [0.1, 0.2, 0.3], atol=1e-7)


def test_scene_nodes_are_flattened_with_their_transforms(tmp_path: Path) -> None:
    """A GLB scene of two unit cubes, one moved 5 m along x, spans x ∈ [−0.5, 5.5]."""
    scene = trimesh.Scene()
    cube = trimesh.creation.box(extents=(1, 1, 1))
    scene.add_geometry(cube, node_name="a")
    scene.add_geometry(cube, node_name="b",
                       transform=trimesh.transformations.translation_matrix([5, 0, 0]))
    p = tmp_path / "two.glb"
    p.write_bytes(scene.export(file_type="glb"))
    m = load_mesh(p)
    assert m.faces.shape[0] == 24
    np.testing.assert_allclose(m.bounds, [[-0.5, -0.5, -0.5], [5.5, 0.5, 0.5]], atol=1e-7)


def test_cache_returns_the_same_mesh_until_the_file_changes(tmp_path: Path) -> None:
    """A second load of an unchanged file is the cached object; a rewritten file reloads."""
    p = _box_file(tmp_path, ".stl")
    a = load_mesh(p)
    assert load_mesh(str(p)) is a
    assert load_mesh(p, scale=2.0) is not a
    trimesh.creation.box(extents=(1, 1, 1)).export(str(p))
    st = p.stat()
    os.utime(p, ns=(st.st_atime_ns, st.st_mtime_ns + 10**9))
    assert load_mesh(p).volume == pytest.approx(1.0)


def test_missing_corrupt_and_unsupported_files_are_named(tmp_path: Path) -> None:
    """A missing, corrupt, empty or unknown-suffix mesh file raises naming the file."""
    with pytest.raises(RobotDefinitionError, match=r"nope\.stl: mesh file not found"):
        load_mesh(tmp_path / "nope.stl")
    bad = tmp_path / "bad.dae"
    bad.write_text("<COLLADA><this is not xml")
    with pytest.raises(RobotDefinitionError, match=r"bad\.dae: cannot read the mesh file"):
        load_mesh(bad)
    glb = tmp_path / "bad.glb"
    glb.write_bytes(b"glTF\x02\x00\x00\x00garbage")
    with pytest.raises(RobotDefinitionError, match=r"bad\.glb"):
        load_mesh(glb)
    empty = tmp_path / "empty.obj"
    empty.write_text("# nothing\n")
    with pytest.raises(RobotDefinitionError, match=r"empty\.obj.*no triangles"):
        load_mesh(empty)
    other = tmp_path / "x.fbx"
    other.write_text("x")
    with pytest.raises(RobotDefinitionError, match=r"unsupported mesh file type '\.fbx'"):
        load_mesh(other)
    with pytest.raises(RobotDefinitionError, match="scale"):
        load_mesh(_box_file(tmp_path, ".stl"), scale=(1, -1, 1))


def test_missing_extra_names_the_extra(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """Without trimesh, loading says to install serialkin[mesh]."""
    p = _box_file(tmp_path, ".ply")
    mesh_mod.clear_mesh_cache()
    monkeypatch.setitem(sys.modules, "trimesh", None)
    with pytest.raises(NotSupportedError, match=r'pip install "serialkin\[mesh\]"'):
        load_mesh(p)


def test_decimate_keeps_at_most_max_faces_and_the_shape() -> None:
    """Decimating a 1280-face sphere to 200 faces keeps it within 5 % of the radius."""
    tm = trimesh.creation.icosphere(subdivisions=3, radius=0.1)
    m = TriangleMesh(tm.vertices, tm.faces)
    d = decimate(m, 200)
    assert 0 < d.faces.shape[0] <= 200
    r = np.linalg.norm(d.vertices, axis=1)
    assert np.all(np.abs(r - 0.1) < 0.005)
    assert decimate(d, 10_000) is d


def test_primitives_triangulate_to_their_volume() -> None:
    """Box, cylinder, sphere and capsule meshes enclose their volume (to the tessellation)."""
    cases = [(Box((0.1, 0.2, 0.3)), 0.006, 1e-9),
             (Cylinder(0.1, 0.4), np.pi * 0.01 * 0.4, 0.02),
             (Sphere(0.1), 4 / 3 * np.pi * 1e-3, 0.03),
             (Capsule(0.1, 0.4), np.pi * 0.01 * (0.4 + 4 / 3 * 0.1), 0.03)]
    for g, vol, rel in cases:
        assert primitive_mesh(g, sections=48).volume == pytest.approx(vol, rel=rel), g


def test_link_meshes_are_posed_in_their_chain_frame(tmp_path: Path) -> None:
    """A mesh with origin T and scale s is yielded as T · diag(s) · p in its frame."""
    stl = _box_file(tmp_path, ".stl", extents=(1, 1, 1))
    text = f"""<robot name="r">
      <link name="base"/>
      <link name="l1"><visual><origin xyz="0 0 0.5" rpy="0 0 1.5707963267948966"/>
        <geometry><mesh filename="{stl}" scale="0.1 0.2 0.3"/></geometry></visual>
        <visual><geometry><sphere radius="0.05"/></geometry></visual></link>
      <joint name="j1" type="revolute"><parent link="base"/><child link="l1"/>
        <axis xyz="0 0 1"/><limit lower="-1" upper="1" effort="1" velocity="1"/></joint>
    </robot>"""
    robot = Robot.from_urdf(text, tip_link="l1")
    (lm,) = list(link_meshes(robot, "visual"))
    assert lm.link_name == "l1" and lm.frame == 1
    np.testing.assert_allclose(lm.mesh.bounds, [[-0.1, -0.05, 0.35], [0.1, 0.05, 0.65]],
                               atol=1e-7)
    both = list(link_meshes(robot, "visual", primitives=True))
    assert len(both) == 2 and both[1].mesh.volume == pytest.approx(5.2e-4, rel=0.05)
    assert list(link_meshes(robot, "collision")) == []


def test_unresolved_mesh_in_link_meshes_names_the_link() -> None:
    """A package:// path never resolved fails in link_meshes naming link, path and the fix."""
    text = """<robot name="r"><link name="base"/>
      <link name="l1"><visual><geometry><mesh filename="package://p/m.stl"/></geometry>
      </visual></link>
      <joint name="j1" type="revolute"><parent link="base"/><child link="l1"/>
        <axis xyz="0 0 1"/><limit lower="-1" upper="1" effort="1" velocity="1"/></joint>
    </robot>"""
    robot = Robot.from_urdf(text, tip_link="l1")
    with pytest.raises(RobotDefinitionError, match=r"link 'l1' visual mesh.*package://p/m\.stl"
                                                   r".*package_map"):
        list(link_meshes(robot))


ERD_ROBOTS = [
    ("panda_description/urdf/panda.urdf", "panda_hand", 9),
    ("ur_description/urdf/ur5_robot.urdf", "tool0", 7),
    ("kinova_description/robots/kinova.urdf", "j2s6s200_end_effector", 11),
    ("talos_data/robots/talos_left_arm.urdf", "arm_left_7_link", 14),
]


@pytest.mark.parametrize(("rel", "tip", "n_collision"), ERD_ROBOTS)
def test_example_robot_data_meshes_load(rel: str, tip: str, n_collision: int) -> None:
    """Panda, UR5, Kinova and TALOS arm: every visual and collision mesh loads, in metres."""
    path = urdf(rel)
    if path is None:
        pytest.skip("example-robot-data (bench extra) is not installed")
    robot = Robot.from_urdf(str(path), tip_link=tip, resolve_meshes=True,
                            package_map={"example-robot-data": robots_dir().parent})
    for kind in ("visual", "collision"):
        meshes = list(link_meshes(robot, kind))
        if kind == "collision":
            assert len(meshes) == n_collision
        assert meshes and all(m.mesh.faces.shape[0] > 0 for m in meshes)
        # link-sized: every vertex within 0.6 m of its link frame (a mm file would be ×1000)
        assert max(float(np.abs(m.mesh.bounds).max()) for m in meshes) < 0.6
        assert all(m.mesh.volume < 0.02 for m in meshes)


def test_import_serialkin_does_not_import_trimesh() -> None:
    """The mesh extra stays optional: importing serialkin (and its mesh module) loads no trimesh."""
    import subprocess

    code = ("import sys, serialkin, serialkin.formats.mesh, serialkin.collision; "
            "print('trimesh' in sys.modules)")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         check=True, env={**os.environ, "PYTHONPATH": os.pathsep.join(sys.path)})
    assert out.stdout.strip() == "False"


def test_decimate_keeps_the_surface_of_a_mesh_with_repeated_vertices():
    """Decimating a per-corner (STL-like) sphere keeps its area within 10 % (welded first)."""
    pytest.importorskip("trimesh")
    pytest.importorskip("fast_simplification")
    from serialkin.formats.mesh import TriangleMesh, decimate, primitive_mesh
    from serialkin.model.geometry import Sphere

    sphere = primitive_mesh(Sphere(0.1), sections=48)
    corners = sphere.vertices[sphere.faces.reshape(-1)]  # every corner its own vertex
    soup = TriangleMesh(corners, np.arange(corners.shape[0]).reshape(-1, 3), "soup")

    def area(m):
        a, b, c = (m.vertices[m.faces[:, k]] for k in range(3))
        return 0.5 * np.linalg.norm(np.cross(b - a, c - a), axis=1).sum()

    small = decimate(soup, 400)
    assert small.faces.shape[0] <= 400
    assert abs(area(small) / area(sphere) - 1) < 0.1
