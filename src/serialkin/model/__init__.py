"""Robot models: joints, DH tables, the compiled chain and link geometry.

* :class:`Robot` (``robot.py``), built from :class:`DHLink` tables (``dh.py``) or general
  :class:`Joint` s (``joint.py``); the file formats (URDF, MJCF, xacro, robot files,
  meshes) are read and written by :mod:`serialkin.formats`, above this layer;
* shapes (``geometry.py``: link visual/collision geometry, collision scenes and
  obstacles share them) and the robot's capsule model (``collision_model.py``);
* the built-in zoo is :mod:`serialkin.models`.

The names this package re-exported from its former format modules
(``load_robot_file``, ``load_mesh``, ...) still work for one release, with a
DeprecationWarning: import them from :mod:`serialkin.formats`.
"""

from typing import Any

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
from serialkin.model.robot import Robot

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
]

#: Names re-exported here before the file formats left the model layer: their module in
#: serialkin.formats (deprecated here; removed in the next release).
_MOVED = {
    "TriangleMesh": "mesh",
    "decimate": "mesh",
    "link_meshes": "mesh",
    "load_mesh": "mesh",
    "welded": "mesh",
    "load_collision_file": "robotfile",
    "load_robot_file": "robotfile",
    "save_collision_file": "robotfile",
    "save_robot_file": "robotfile",
}


def __getattr__(name: str) -> Any:
    """The deprecated names of :data:`_MOVED`, from :mod:`serialkin.formats` with a warning."""
    module = _MOVED.get(name)
    if module is None:
        raise AttributeError(f"module 'serialkin.model' has no attribute {name!r}")
    import warnings

    from serialkin import formats  # deprecated alias: an upward import, removed with it

    warnings.warn(f"serialkin.model.{name} is deprecated: import {name} from "
                  f"serialkin.formats (module serialkin.formats.{module})",
                  DeprecationWarning, stacklevel=2)
    return getattr(formats, name)
