"""Writing a calibrated robot: a robot file (YAML/JSON) or a URDF, atomically.

A robot file holds a DH table. A calibrated DH model without Hayati's β is one already;
otherwise (β, or the joint model) the DH table is extracted from the calibrated joint
axes (:func:`serialkin.model.dh_extract.to_dh_robot`, which checks that the extracted
table reproduces the forward kinematics). For nearly parallel axes that table has long
offsets d (about a / tan(tilt)): it is exact but a URDF, which keeps each joint's origin
as identified, is the better file for such a robot.
"""

from __future__ import annotations

import os
from pathlib import Path

from serialkin.errors import InputError
from serialkin.model.robot import Robot


def save_robot(robot: Robot, path: str | os.PathLike[str]) -> Path:
    """Write ``robot`` to ``path`` by its suffix: ``.urdf``, or ``.yaml``/``.yml``/``.json``.

    Raises:
        InputError: another suffix.
        RobotDefinitionError: the DH table cannot be extracted.
    """
    from serialkin._io import write_text_atomic
    from serialkin.formats.robotfile import ROBOT_FILE_SUFFIXES, save_robot_file

    p = Path(path)
    suffix = p.suffix.lower()
    if suffix == ".urdf":
        return write_text_atomic(p, robot.to_urdf())
    if suffix not in ROBOT_FILE_SUFFIXES:
        raise InputError(f"{p}: unknown robot file type {p.suffix!r}; expected .urdf or one "
                         f"of {', '.join(ROBOT_FILE_SUFFIXES)}")
    if robot.dh is None:
        from serialkin.model.dh_extract import to_dh_robot

        robot = to_dh_robot(robot, "standard")
    return save_robot_file(robot, p)
