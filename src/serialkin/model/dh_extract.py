"""Denavit–Hartenberg parameters extracted from a chain in general form.

A robot from a URDF (or from general joint axes) is a list of joint axes in space. At the
zero configuration each joint *i* is the directed line (o_i, z_i); DH frames are placed
on these lines by the rules of section 3.2: frame axes z along joint axes, x along the
common normal of consecutive axes, origins where that normal meets an axis. Where the
rules leave a choice (parallel axes, the first and last frames) the choice that zeroes
d (parallel axes) or the offsets is taken; the ``base`` and ``tool`` transforms absorb
what DH cannot express (the pose of frame 0 in the world and of the tool in frame n).

The result is verified: the DH robot must reproduce the original forward kinematics at
random configurations, or :class:`~serialkin.errors.RobotDefinitionError` is raised.
"""

from __future__ import annotations

import numpy as np

from serialkin._checks import check_choice
from serialkin.errors import RobotDefinitionError
from serialkin.model.dh import CONVENTIONS, DHLink

_EPS = 1e-9


def _unit(v: np.ndarray) -> np.ndarray:
    return v / np.linalg.norm(v)


def _perpendicular(z: np.ndarray, hint: np.ndarray) -> np.ndarray:
    """A unit vector ⟂ z, as close as possible to ``hint`` (falls back to world x, then y)."""
    for h in (hint, np.array([1.0, 0.0, 0.0]), np.array([0.0, 1.0, 0.0])):
        v = h - (h @ z) * z
        if np.linalg.norm(v) > 1e-6:
            return _unit(v)
    raise AssertionError("unreachable: x and y cannot both be parallel to z")  # pragma: no cover


def common_normal(p1: np.ndarray, z1: np.ndarray, p2: np.ndarray, z2: np.ndarray,
                  prefer: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray | None]:
    """Feet c1 (on line 1) and c2 (on line 2) of the common normal, and its direction.

    Lines are ``p + t z`` with unit z. For skew lines the normal is unique; for
    intersecting lines c1 = c2 is the intersection and the direction is z1 × z2; for
    parallel lines the normal through the projection of ``prefer`` on line 1 is used.
    The direction (unit, from line 1 to line 2) is None when the lines coincide.
    """
    cross = np.cross(z1, z2)
    s = np.linalg.norm(cross)
    if s > _EPS:
        # feet from cross products: well conditioned even for nearly parallel axes
        n = cross / s
        dp = p2 - p1
        t1 = np.cross(dp, z2) @ n / s
        t2 = np.cross(dp, z1) @ n / s
        c1, c2 = p1 + t1 * z1, p2 + t2 * z2
        gap = c2 - c1
        if np.linalg.norm(gap) > _EPS:
            return c1, c2, _unit(gap)
        return c1, c1, cross / s
    c1 = p1 + ((prefer - p1) @ z1) * z1
    c2 = p2 + ((c1 - p2) @ z2) * z2
    gap = c2 - c1
    if np.linalg.norm(gap) > _EPS:
        return c1, c2, _unit(gap)
    return c1, c2, None


def _frame(origin: np.ndarray, z: np.ndarray, x: np.ndarray) -> np.ndarray:
    T = np.eye(4)
    T[:3, 0], T[:3, 2] = x, z
    T[:3, 1] = np.cross(z, x)
    T[:3, 3] = origin
    return T


def _std_params(A: np.ndarray) -> tuple[float, float, float, float]:
    """(a, alpha, d, theta) from A = Rz(θ)Tz(d)Tx(a)Rx(α)."""
    theta = np.arctan2(A[1, 0], A[0, 0])
    alpha = np.arctan2(A[2, 1], A[2, 2])
    a = A[0, 3] * np.cos(theta) + A[1, 3] * np.sin(theta)
    return float(a), float(alpha), float(A[2, 3]), float(theta)


def _mod_params(A: np.ndarray) -> tuple[float, float, float, float]:
    """(a, alpha, d, theta) from A = Rx(α)Tx(a)Rz(θ)Tz(d)."""
    theta = np.arctan2(-A[0, 1], A[0, 0])
    alpha = np.arctan2(-A[1, 2], A[2, 2])
    d = -A[1, 3] * np.sin(alpha) + A[2, 3] * np.cos(alpha)
    return float(A[0, 3]), float(alpha), float(d), float(theta)


def extract_dh(robot, convention: str = "standard") -> tuple[list[DHLink], np.ndarray, np.ndarray]:
    """DH table of ``robot`` in the given convention, with base and tool transforms.

    Args:
        robot: any :class:`~serialkin.Robot` (e.g. from a URDF).
        convention: 'standard' (A = Rz Tz Tx Rx) or 'modified' (A = Rx Tx Rz Tz).

    Returns:
        ``(rows, base, tool)`` such that ``Robot.from_dh(rows, convention, base=base,
        tool=tool)`` has the same forward kinematics as ``robot`` for every q. The θ
        (revolute) or d (prismatic) of each row is its value at q = 0.

    Raises:
        RobotDefinitionError: when the result does not reproduce the robot (which would
            mean a chain DH cannot express), with the largest deviation found.
    """
    from serialkin.model.robot import Robot

    check_choice(convention, "convention", CONVENTIONS)
    n = robot.n
    o, z = robot.joint_axes()
    T_tool = robot.fk(np.zeros(n))
    world_x = robot.base[:3, 0]
    frames: list[np.ndarray] = []
    if convention == "standard":
        # frame 0 on joint 1's axis; frames i = 1..n-1 on joint i+1's axis; frame n = frame n-1
        # turned with joint n (a_n = alpha_n = d_n = 0).
        if n > 1:
            c1, _, x = common_normal(o[0], z[0], o[1], z[1], robot.base[:3, 3])
            x0 = x if x is not None else _perpendicular(z[0], world_x)
        else:
            c1 = o[0] + ((robot.base[:3, 3] - o[0]) @ z[0]) * z[0]
            x0 = _perpendicular(z[0], world_x)
        frames.append(_frame(c1, z[0], x0))
        for i in range(1, n):
            prev = frames[-1]
            c_prev, c_next, x = common_normal(prev[:3, 3], z[i - 1], o[i], z[i], prev[:3, 3])
            if x is None:
                x = prev[:3, 0]
            elif np.linalg.norm(c_next - c_prev) < _EPS and x @ prev[:3, 0] < 0:
                x = -x  # intersecting axes: pick the sign nearest the previous x
            frames.append(_frame(c_next, z[i], x))
        frames.append(frames[-1].copy())
    else:
        # frame i (i = 1..n) on joint i's axis, x along the normal to joint i+1's axis;
        # frame 0 = frame 1 at q = 0 (a_0 = alpha_0 = d_1 = theta_1 = 0).
        for i in range(n):
            if i + 1 < n:
                prefer = frames[-1][:3, 3] if frames else robot.base[:3, 3]
                c, _, x = common_normal(o[i], z[i], o[i + 1], z[i + 1], prefer)
                if x is None:
                    x = frames[-1][:3, 0] if frames else _perpendicular(z[i], world_x)
            else:
                prev = frames[-1] if frames else None
                c = o[i] if prev is None else o[i] + ((prev[:3, 3] - o[i]) @ z[i]) * z[i]
                x = _perpendicular(z[i], prev[:3, 0] if prev is not None else world_x)
            frames.append(_frame(c, z[i], x))
        frames.insert(0, frames[0].copy())
    params = _std_params if convention == "standard" else _mod_params
    rows = []
    for i, j in enumerate(robot.joints):
        A = np.linalg.inv(frames[i]) @ frames[i + 1]
        a, alpha, d, theta = params(A)
        rows.append(DHLink(a=a, alpha=alpha, d=d, theta=theta, type=j.type, qlim=j.qlim,
                           name=robot.joint_names[i]))
    base = frames[0]
    tool = np.linalg.inv(frames[n]) @ T_tool
    for T in (base, tool):
        T[3] = (0.0, 0.0, 0.0, 1.0)
        U, _, Vt = np.linalg.svd(T[:3, :3])
        T[:3, :3] = U @ Vt
    dh_robot = Robot.from_dh(rows, convention, base=base, tool=tool, name=robot.name)
    Q = robot.random_q(16, seed=0)
    err = float(np.abs(dh_robot.fk(Q) - robot.fk(Q)).max())
    if err > 1e-8:
        raise RobotDefinitionError(
            f"robot {robot.name!r} cannot be expressed in {convention} DH: the extracted table "
            f"deviates from the original forward kinematics by {err:.3g}"
        )
    return rows, base, tool


def to_dh_robot(robot, convention: str = "standard"):
    """The same robot rebuilt from its extracted DH table (see :func:`extract_dh`)."""
    from serialkin.model.robot import Robot

    rows, base, tool = extract_dh(robot, convention)
    dh_robot = Robot.from_dh(rows, convention, base=base, tool=tool, name=robot.name,
                             source=f"DH extracted from {robot.source or robot.name}")
    return dh_robot
