"""Robot file formats: readers that build a :class:`~serialkin.Robot`, and writers.

One module per format, above the model layer (the model knows no file format):

* URDF import and export (``urdf.py``), MJCF import (``mjcf.py``), xacro expansion and
  import (``xacro.py``, its safe expression evaluator ``xacro_expr.py``);
* serialkin's own robot and collision files in YAML or JSON (``robotfile.py``);
* triangle meshes of link geometry (``mesh.py``; loading needs the ``mesh`` extra);
* the safe XML reading URDF, MJCF and SRDF share (``xmlfile.py``).

A reader parses its file into the parts of a robot (joints in general form, base, tool,
names, link geometry, collision model) and passes them to one
:class:`~serialkin.Robot` constructor call; the robot is never changed afterwards.
``Robot.from_urdf``, ``from_mjcf``, ``from_xacro`` and ``to_urdf`` call the functions this
package registers with :func:`serialkin.model.robot.provide` when it is imported.
"""

from serialkin.formats.mesh import TriangleMesh, decimate, link_meshes, load_mesh, welded
from serialkin.formats.mjcf import robot_from_mjcf
from serialkin.formats.robotfile import (
    load_collision_file,
    load_robot_file,
    save_collision_file,
    save_robot_file,
)
from serialkin.formats.urdf import robot_from_urdf, robot_to_urdf
from serialkin.formats.xacro import expand_xacro, robot_from_xacro
from serialkin.formats.xmlfile import read_robot_xml
from serialkin.model.robot import provide

# Robot.from_urdf, from_mjcf, from_xacro and to_urdf call these (the model imports no format)
provide("from_urdf", robot_from_urdf)
provide("from_mjcf", robot_from_mjcf)
provide("from_xacro", robot_from_xacro)
provide("to_urdf", robot_to_urdf)

__all__ = [
    "TriangleMesh",
    "decimate",
    "expand_xacro",
    "link_meshes",
    "load_collision_file",
    "load_mesh",
    "load_robot_file",
    "read_robot_xml",
    "robot_from_mjcf",
    "robot_from_urdf",
    "robot_from_xacro",
    "robot_to_urdf",
    "save_collision_file",
    "save_robot_file",
    "welded",
]
