"""Rigid-body motion: rotations, homogeneous transforms and orientation representations (section 2)."""

from serialkin._checks import check_rotation, check_transform
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
    "rotx",
    "roty",
    "rotz",
    "transl",
    "trotx",
    "troty",
    "trotz",
]
