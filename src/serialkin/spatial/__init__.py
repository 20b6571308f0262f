"""Rigid-body motion (section 2): rotations, transforms, orientation representations.

Conventions: angles in rad, lengths in m; ``R_a_b`` maps frame-b coordinates to frame a;
twists and pose errors are ordered [v; ω]; quaternions are (w, x, y, z); roll-pitch-yaw is
``R = Rz(yaw) Ry(pitch) Rx(roll)``; ZYZ Euler is ``R = Rz(phi) Ry(theta) Rz(psi)``.
"""

from serialkin._checks import check_rotation, check_transform
from serialkin.spatial.lie import (
    se3_exp,
    se3_log,
    skew,
    so3_exp,
    so3_left_jacobian,
    so3_left_jacobian_inv,
    so3_log,
    unskew,
)
from serialkin.spatial.pose import pose_distance, pose_error
from serialkin.spatial.rotations import (
    axis_angle_to_matrix,
    matrix_to_axis_angle,
    matrix_to_quaternion,
    matrix_to_rpy,
    matrix_to_zyz,
    perpendicular,
    quaternion_multiply,
    quaternion_to_matrix,
    rpy_to_matrix,
    wrap_angle,
    zyz_to_matrix,
)
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
    "axis_angle_to_matrix",
    "check_rotation",
    "check_transform",
    "inv_transform",
    "make_transform",
    "matrix_to_axis_angle",
    "matrix_to_quaternion",
    "matrix_to_rpy",
    "matrix_to_zyz",
    "pose_distance",
    "pose_error",
    "quaternion_multiply",
    "quaternion_to_matrix",
    "rotx",
    "roty",
    "rotz",
    "rpy_to_matrix",
    "se3_exp",
    "se3_log",
    "skew",
    "so3_exp",
    "so3_left_jacobian",
    "so3_left_jacobian_inv",
    "so3_log",
    "transl",
    "trotx",
    "troty",
    "trotz",
    "unskew",
    "perpendicular",
    "wrap_angle",
    "zyz_to_matrix",
]
