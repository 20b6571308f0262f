"""Rigid-body motion (section 2): rotations, transforms, orientation representations."""

from serialkin._checks import check_rotation, check_transform
from serialkin.spatial.pose import pose_distance, pose_error
from serialkin.spatial.transforms import (
    inv_transform,
    make_transform,
    rotx,
    roty,
    rotz,
    transl,
    trotx,
    troty,
    trotz,
)

__all__ = [
    "check_rotation",
    "check_transform",
    "inv_transform",
    "make_transform",
    "pose_distance",
    "pose_error",
    "rotx",
    "roty",
    "rotz",
    "transl",
    "trotx",
    "troty",
    "trotz",
]
