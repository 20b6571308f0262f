"""Robot models: joints, DH tables, the compiled chain, link geometry and the file formats.

* :class:`Robot` (``robot.py``), built from :class:`DHLink` tables (``dh.py``), general
  :class:`Joint` s (``joint.py``), URDF (``urdf.py``), MJCF (``mjcf.py``), xacro
  (``xacro.py``) or robot files (``robotfile.py``);
* shapes (``geometry.py``: link visual/collision geometry, collision scenes and
  obstacles share them) and triangle meshes (``mesh.py``; loading
  needs the ``mesh`` extra);
* the built-in zoo is :mod:`serialkin.models`.
"""

from serialkin.model.dh import DHLink
from serialkin.model.geometry import (
    Box,
    Capsule,
    Cylinder,
    HalfSpace,
    LinkGeometry,
    Mesh,
    Shape,
    Sphere,
)
from serialkin.model.joint import Joint
from serialkin.model.mesh import TriangleMesh, decimate, link_meshes, load_mesh, welded
from serialkin.model.robot import Robot
from serialkin.model.robotfile import (
    load_collision_file,
    load_robot_file,
    save_collision_file,
    save_robot_file,
)

__all__ = [
    "Box",
    "Capsule",
    "Cylinder",
    "DHLink",
    "HalfSpace",
    "Joint",
    "LinkGeometry",
    "Mesh",
    "Robot",
    "Shape",
    "Sphere",
    "TriangleMesh",
    "decimate",
    "link_meshes",
    "load_collision_file",
    "load_mesh",
    "load_robot_file",
    "save_collision_file",
    "save_robot_file",
    "welded",
]
