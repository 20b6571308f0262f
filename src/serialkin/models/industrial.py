"""Industrial and research arms from published DH tables.

Each model names its source in ``robot.source``. Lengths in metres, angles in radians,
joint limits from the manufacturer's data sheet or the cited paper. Every model carries a
capsule collision model (``robot.collision``, :mod:`serialkin.collision.robots`).
"""

from __future__ import annotations

import math

import numpy as np

from serialkin.model.dh import DHLink
from serialkin.model.robot import Robot
from serialkin.spatial.transforms import make_transform

_DEG = math.pi / 180.0
_INCH = 0.0254

# Unimation PUMA 560, standard DH. Kinematic parameters: P. Corke and B. Armstrong-Hélouvry,
# "A search for consensus among model parameters reported for the PUMA 560 robot",
# ICRA 1994; d1 = 26.45 in (mounting surface to shoulder axis) and joint limits (Wang &
# Chen, IEEE Trans. RA 7(4), 1991) as in P. Corke's Robotics Toolbox model.
PUMA560_SOURCE = (
    "Corke & Armstrong-Helouvry, ICRA 1994 (consensus PUMA 560 parameters); d1 = 26.45 in "
    "pedestal and limits per Wang & Chen 1991, as in Corke's Robotics Toolbox"
)

# Stanford arm (Scheinman), standard DH with a prismatic third joint: R. P. Paul,
# "Robot Manipulators: Mathematics, Programming and Control", MIT Press 1981, as in
# P. Corke's Robotics Toolbox ``Stanford`` model (stroke 12-50 in); d6 = 0.263 m as in the
# MATLAB toolbox's stanford.m (the Python toolbox sets d6 = 0, ending at the wrist centre).
STANFORD_SOURCE = (
    "R. P. Paul, Robot Manipulators (MIT Press 1981), Stanford arm; values as in "
    "Corke's Robotics Toolbox for MATLAB (stanford.m, d6 = 0.263 m to the flange)"
)

# Universal Robots UR5 (CB3), standard DH: Universal Robots support article "DH
# parameters for calculations of kinematics and dynamics"; limits ±360° (UR5 data sheet).
UR5_SOURCE = "Universal Robots, 'DH parameters for calculations of kinematics and dynamics' (UR5)"

# UR5 (CB3) joint speed limit: 180°/s on every joint, UR5 User Manual (CB3, version 3.13),
# as in ros-industrial/universal_robot ur_description/config/ur5/joint_limits.yaml
# (`max_velocity: !degrees 180.0`; older ur5.urdf.xacro files wrote 3.15 rad/s). Universal
# Robots publish no acceleration limits ("not publicly available", same file).
UR5_VELOCITY = math.pi

# Franka Emika Panda joint limits, Franka Control Interface docs, "Robot and interface
# specifications" (limits in the joint space): q̇max [rad/s], q̈max [rad/s²]; the jerk
# limits there (7500, 3750, 5000, 6250, 7500, 10000, 10000 rad/s³) are not kept on the
# Robot (serialkin.paths.jerk_limited takes them as an argument).
PANDA_VELOCITY = (2.1750, 2.1750, 2.1750, 2.1750, 2.6100, 2.6100, 2.6100)
PANDA_ACCELERATION = (15.0, 7.5, 10.0, 12.5, 15.0, 20.0, 20.0)

# Franka Emika Panda, modified (Craig) DH exactly as published by Franka in the FCI
# documentation ("Robot and interface specifications": DH table and joint limits); the
# flange row (a = 0, d = 0.107, α = 0, θ = 0) is the tool transform.
PANDA_SOURCE = "Franka Control Interface docs, 'Robot and interface specifications' (modified DH)"

# KUKA LBR iiwa 7 R800, standard DH: link offsets 340/400/400/126 mm from the KUKA data
# sheet, frame assignment as in Faria, Ferreira, Erlhagen, Monteiro, Bicho, "Position-based
# kinematics for 7-DoF serial manipulators with global configuration control, joint limit
# and singularity avoidance", Mechanism and Machine Theory 121 (2018); limits ±170/120/175°
# from the KUKA LBR iiwa 7 R800 data sheet.
IIWA7_SOURCE = (
    "KUKA LBR iiwa 7 R800 data sheet (lengths, limits); DH frames per Faria et al., "
    "Mech. Mach. Theory 121 (2018)"
)


def _rows(a, alpha, d, theta, qlim_deg, types=None) -> list[DHLink]:
    n = len(a)
    types = types or ["R"] * n
    return [
        DHLink(a=a[i], alpha=alpha[i], d=d[i], theta=theta[i], type=types[i],
               qlim=tuple(qlim_deg[i]), name=f"q{i + 1}")
        for i in range(n)
    ]


def puma560() -> Robot:
    """Build the Unimation PUMA 560, 6R, standard DH (source in ``robot.source``).

    ====  =======  ======  ========  ==============
    Link  a [m]    α       d [m]     limits [deg]
    ====  =======  ======  ========  ==============
    1     0        π/2     0.6718    ±160
    2     0.4318   0       0         -45 .. 225
    3     0.0203   -π/2    0.15005   -225 .. 45
    4     0        π/2     0.4318    -110 .. 170
    5     0        -π/2    0         ±100
    6     0        0       0         ±266
    ====  =======  ======  ========  ==============
    """
    h = math.pi / 2
    lim = np.array([[-160, 160], [-45, 225], [-225, 45], [-110, 170], [-100, 100],
                    [-266, 266]]) * _DEG
    rows = _rows(a=[0.0, 0.4318, 0.0203, 0.0, 0.0, 0.0],
                 alpha=[h, 0.0, -h, h, -h, 0.0],
                 d=[26.45 * _INCH, 0.0, 0.15005, 0.4318, 0.0, 0.0],
                 theta=[0.0] * 6, qlim_deg=lim)
    from serialkin.collision.robots import puma560_collision_model

    robot = Robot.from_dh(rows, "standard", name="puma560", source=PUMA560_SOURCE)
    return robot.with_collision(puma560_collision_model())


def stanford() -> Robot:
    """Build the Stanford arm, RRPRRR (joint 3 prismatic, q3 in metres), standard DH.

    ====  =======  ======  ==============  ==============
    Link  a [m]    α       d [m]           θ
    ====  =======  ======  ==============  ==============
    1     0        -π/2    0.412           q1
    2     0        π/2     0.154           q2
    3     0.0203   0       q3 (0.30-1.27)  -π/2
    4     0        -π/2    0               q4
    5     0        π/2     0               q5
    6     0        0       0.263           q6
    ====  =======  ======  ==============  ==============
    """
    h = math.pi / 2
    lim = [(-170 * _DEG, 170 * _DEG), (-170 * _DEG, 170 * _DEG), (12 * _INCH, 50 * _INCH),
           (-170 * _DEG, 170 * _DEG), (-90 * _DEG, 90 * _DEG), (-170 * _DEG, 170 * _DEG)]
    rows = _rows(a=[0.0, 0.0, 0.0203, 0.0, 0.0, 0.0],
                 alpha=[-h, h, 0.0, -h, h, 0.0],
                 d=[0.412, 0.154, 0.0, 0.0, 0.0, 0.263],
                 theta=[0.0, 0.0, -h, 0.0, 0.0, 0.0],
                 qlim_deg=lim, types=["R", "R", "P", "R", "R", "R"])
    from serialkin.collision.robots import stanford_collision_model

    robot = Robot.from_dh(rows, "standard", name="stanford", source=STANFORD_SOURCE)
    return robot.with_collision(stanford_collision_model())


def ur5() -> Robot:
    """Build the Universal Robots UR5, 6R, standard DH as published by Universal Robots.

    a = (0, -0.425, -0.39225, 0, 0, 0) m, d = (0.089159, 0, 0, 0.10915, 0.09465, 0.0823) m,
    α = (π/2, 0, 0, π/2, -π/2, 0); every joint ±360°, at most 180°/s (π rad/s; no
    acceleration limits are published).
    """
    h = math.pi / 2
    lim = [(-2 * math.pi, 2 * math.pi)] * 6
    rows = _rows(a=[0.0, -0.425, -0.39225, 0.0, 0.0, 0.0],
                 alpha=[h, 0.0, 0.0, h, -h, 0.0],
                 d=[0.089159, 0.0, 0.0, 0.10915, 0.09465, 0.0823],
                 theta=[0.0] * 6, qlim_deg=lim)
    from serialkin.collision.robots import ur5_collision_model

    robot = Robot.from_dh(rows, "standard", name="UR5", source=UR5_SOURCE)
    return robot.with_collision(ur5_collision_model()).with_rate_limits(velocity=UR5_VELOCITY)


def panda() -> Robot:
    """Build the Franka Emika Panda, 7R, modified (Craig) DH with the flange as tool.

    ======  =========  =====  ======  =================
    Joint   a [m]      d [m]  α       limits [rad]
    ======  =========  =====  ======  =================
    1       0          0.333  0       ±2.8973
    2       0          0      -π/2    ±1.7628
    3       0          0.316  π/2     ±2.8973
    4       0.0825     0      π/2     -3.0718 .. -0.0698
    5       -0.0825    0.384  -π/2    ±2.8973
    6       0          0      π/2     -0.0175 .. 3.7525
    7       0.088      0      π/2     ±2.8973
    flange  0          0.107  0       (tool transform)
    ======  =========  =====  ======  =================

    Velocity limits 2.175 rad/s (joints 1-4) and 2.61 rad/s (5-7); acceleration limits
    15, 7.5, 10, 12.5, 15, 20, 20 rad/s² (Franka's specifications).
    """
    h = math.pi / 2
    lim = [(-2.8973, 2.8973), (-1.7628, 1.7628), (-2.8973, 2.8973), (-3.0718, -0.0698),
           (-2.8973, 2.8973), (-0.0175, 3.7525), (-2.8973, 2.8973)]
    rows = _rows(a=[0.0, 0.0, 0.0, 0.0825, -0.0825, 0.0, 0.088],
                 alpha=[0.0, -h, h, h, -h, h, h],
                 d=[0.333, 0.0, 0.316, 0.0, 0.384, 0.0, 0.0],
                 theta=[0.0] * 7, qlim_deg=lim)
    flange = make_transform(p=[0.0, 0.0, 0.107])
    from serialkin.collision.robots import panda_collision_model

    robot = Robot.from_dh(rows, "modified", tool=flange, name="panda", source=PANDA_SOURCE)
    return robot.with_collision(panda_collision_model()).with_rate_limits(
        velocity=PANDA_VELOCITY, acceleration=PANDA_ACCELERATION)


def iiwa7() -> Robot:
    """Build the KUKA LBR iiwa 7 R800, 7R, standard DH; the tool is the media flange (d7 = 0.126 m).

    d = (0.340, 0, 0.400, 0, 0.400, 0, 0.126) m, a = 0,
    α = (-π/2, π/2, π/2, -π/2, -π/2, π/2, 0); limits ±170, ±120, ±170, ±120, ±170, ±120,
    ±175 degrees.
    """
    h = math.pi / 2
    lim = np.array([[-170, 170], [-120, 120], [-170, 170], [-120, 120], [-170, 170],
                    [-120, 120], [-175, 175]]) * _DEG
    rows = _rows(a=[0.0] * 7,
                 alpha=[-h, h, h, -h, -h, h, 0.0],
                 d=[0.340, 0.0, 0.400, 0.0, 0.400, 0.0, 0.126],
                 theta=[0.0] * 7, qlim_deg=lim)
    from serialkin.collision.robots import iiwa7_collision_model

    robot = Robot.from_dh(rows, "standard", name="iiwa7", source=IIWA7_SOURCE)
    return robot.with_collision(iiwa7_collision_model())
