"""A small URDF robot with every kind of visual shape, for the viewer tests.

base (box) -R z- link1 (cylinder, mesh file) -R y- link2 (capsule, sphere with a colour)
-fixed- tcp. The mesh is an icosphere STL written with trimesh (the ``mesh`` extra).
"""

from __future__ import annotations

from pathlib import Path
from xml.sax.saxutils import escape

import pytest

from serialkin import Robot

URDF = """<?xml version="1.0"?>
<robot name="body3">
  <link name="base">
    <visual><origin xyz="0 0 0.05"/><geometry><box size="0.3 0.2 0.1"/></geometry></visual>
  </link>
  <link name="LINK1">
    <visual><origin xyz="0 0 0.15"/><geometry><cylinder radius="0.05" length="0.3"/></geometry>
    </visual>
    <visual name="ball"><origin xyz="0.02 0 0.3" rpy="0.3 -0.2 0.5"/>
      <geometry><mesh filename="package://bodypkg/meshes/ball.stl" scale="0.08 0.08 0.1"/>
      </geometry></visual>
  </link>
  <link name="link2">
    <visual><origin xyz="0.2 0 0" rpy="0 1.5707963267948966 0"/>
      <geometry><capsule radius="0.04" length="0.3"/></geometry></visual>
    <visual><origin xyz="0.4 0 0"/><geometry><sphere radius="0.05"/></geometry>
      <material name="red"><color rgba="0.9 0.1 0.1 0.8"/></material></visual>
  </link>
  <link name="tcp"/>
  <joint name="j1" type="revolute"><parent link="base"/><child link="LINK1"/>
    <origin xyz="0 0 0.1"/><axis xyz="0 0 1"/>
    <limit lower="-3" upper="3" effort="1" velocity="1"/></joint>
  <joint name="j2" type="revolute"><parent link="LINK1"/><child link="link2"/>
    <origin xyz="0 0 0.35" rpy="0.2 0 0"/><axis xyz="0 1 0"/>
    <limit lower="-2" upper="2" effort="1" velocity="1"/></joint>
  <joint name="tool" type="fixed"><parent link="link2"/><child link="tcp"/>
    <origin xyz="0.45 0 0"/></joint>
</robot>
"""

#: Visual shapes of the robot in file order: (link, kind).
SHAPES = [("base", "box"), ("LINK1", "cylinder"), ("LINK1", "mesh"), ("link2", "capsule"),
          ("link2", "sphere")]


def write_package(folder: Path, link1: str = "LINK1", *, inside: bool = True) -> Path:
    """Write the URDF and its mesh package ``folder/bodypkg``; return the URDF path.

    ``inside``: the URDF in the package folder (its ``package://bodypkg/`` URIs then
    resolve by themselves, from the file's ancestor of that name), else in
    ``folder/elsewhere`` (they resolve only when told where the package is).
    """
    trimesh = pytest.importorskip("trimesh", reason='needs the mesh extra (serialkin[mesh])')
    pkg = folder / "bodypkg"
    (pkg / "meshes").mkdir(parents=True, exist_ok=True)
    trimesh.creation.icosphere(subdivisions=2).export(str(pkg / "meshes" / "ball.stl"))
    home = pkg if inside else folder / "elsewhere"
    home.mkdir(parents=True, exist_ok=True)
    urdf = home / "body3.urdf"
    name = escape(link1, {'"': "&quot;"})
    urdf.write_text(URDF.replace('"LINK1"', f'"{name}"'), encoding="utf-8")
    return urdf


def body_robot(folder: Path, link1: str = "LINK1") -> Robot:
    """The robot, its package resolved through ``package_map``."""
    urdf = write_package(folder, link1)
    return Robot.from_urdf(str(urdf), tip_link="tcp",
                           package_map={"bodypkg": urdf.parent}, resolve_meshes=True)
