"""Cartesian pose paths: straight lines, circular arcs and blended waypoint polylines.

Every path is a sequence of tool poses ``T_base_tool`` (p, 4, 4), returned as a
:class:`~serialkin.tracking.path.Path` of task 'pose' whose ``parameter`` is each
sample's fraction of the path, from 0 to 1 (of the position's length; of the turn for a
path that only turns). Orientation is interpolated by SLERP (the geodesic of SO(3),
``R(s) = R₀·exp(s·log(R₀ᵀR₁))``, Shoemake 1985), or kept fixed, or for arcs turned with
the arc. Samples are spaced evenly along each piece so that no step moves the position by
more than ``max_step`` [m] nor turns the tool by more than ``max_angle`` [rad].

Units: metres and radians throughout; the command line and scenario files say which
unit each angle is in (``deg`` / ``rad``), never guess.
"""

from __future__ import annotations

import math

import numpy as np

from serialkin._checks import as_float_array, check_positive, check_transform
from serialkin.errors import InputError
from serialkin.spatial.lie import so3_exp, so3_log
from serialkin.tracking.path import Path, check_path_size

__all__ = ["arc", "line", "slerp", "waypoints"]

ORIENTATIONS = ("slerp", "fixed", "follow")


def slerp(R0: object, R1: object, s: object) -> np.ndarray:
    """Spherical linear interpolation of rotations: ``R(s) = R₀·exp(s·log(R₀ᵀR₁))``.

    Args:
        R0: (3, 3) the rotation at s = 0 (checked).
        R1: (3, 3) the rotation at s = 1 (checked).
        s: fractions (m,) in [0, 1] (any real works: outside it extrapolates).

    Returns:
        (m, 3, 3) rotations on the shortest geodesic from R0 (s = 0) to R1 (s = 1); the
        angle from R0 grows linearly in s. At a half turn (R0ᵀR1 a rotation by π) the
        geodesic is not unique and one of the two is returned.
    """
    A = _rotation(R0, "R0")
    B = _rotation(R1, "R1")
    w = so3_log(A.T @ B, check=False)
    t = np.atleast_1d(as_float_array(s, "s"))
    return A @ so3_exp(t[:, None] * w)


def _rotation(R: object, name: str) -> np.ndarray:
    T = np.eye(4)
    T[:3, :3] = as_float_array(R, name)
    return check_transform(T, name)[:3, :3]


def _pose(T: object, name: str) -> np.ndarray:
    A = check_transform(T, name)
    if A.shape != (4, 4):
        raise InputError(f"{name} must be one (4, 4) pose, got shape {A.shape}")
    return A


def _count(length: float, angle: float, max_step: float, max_angle: float) -> int:
    """Segments so that each moves at most max_step [m] and turns at most max_angle [rad]."""
    k = max(1, math.ceil(length / max_step - 1e-9), math.ceil(angle / max_angle - 1e-9))
    check_path_size(k + 1, "max_step")
    return k


def _steps(max_step: float, max_angle: float) -> tuple[float, float]:
    return check_positive(max_step, "max_step"), check_positive(max_angle, "max_angle")


def _orientation(orientation: str) -> str:
    if orientation not in ORIENTATIONS:
        raise InputError(f"orientation must be one of {', '.join(map(repr, ORIENTATIONS))}, "
                         f"got {orientation!r}")
    return orientation


def _poses(p: np.ndarray, R: np.ndarray) -> np.ndarray:
    T = np.zeros((len(p), 4, 4))
    T[:, :3, :3] = R
    T[:, :3, 3] = p
    T[:, 3, 3] = 1.0
    return T


def line(start: object, end: object, *, max_step: float = 0.005,
         max_angle: float = math.radians(1.0), orientation: str = "slerp") -> Path:
    """A straight line from pose ``start`` to pose ``end``, orientation by SLERP.

    Position ``p(s) = p₀ + s·(p₁ − p₀)``, rotation ``slerp(R₀, R₁, s)`` (or R₀ throughout
    with ``orientation='fixed'``), s evenly spaced in [0, 1].

    Args:
        start: (4, 4) first tool pose in the base frame.
        end: (4, 4) last tool pose.
        max_step: largest position step between samples [m].
        max_angle: largest rotation step between samples [rad].
        orientation: 'slerp' or 'fixed'.

    Returns:
        A pose :class:`~serialkin.tracking.path.Path`, first and last samples exactly
        ``start`` and ``end`` (with 'fixed', ``end``'s position with ``start``'s
        rotation).
    """
    A, B = _pose(start, "start"), _pose(end, "end")
    h, a = _steps(max_step, max_angle)
    mode = _orientation(orientation)
    if mode == "follow":
        raise InputError("orientation 'follow' is for arcs; a line takes 'slerp' or 'fixed'")
    length = float(np.linalg.norm(B[:3, 3] - A[:3, 3]))
    turn = 0.0 if mode == "fixed" else float(np.linalg.norm(so3_log(A[:3, :3].T @ B[:3, :3],
                                                                   check=False)))
    k = _count(length, turn, h, a)
    s = np.arange(k + 1) / k
    p = A[:3, 3] + s[:, None] * (B[:3, 3] - A[:3, 3])
    R = np.broadcast_to(A[:3, :3], (k + 1, 3, 3)) if mode == "fixed" else slerp(
        A[:3, :3], B[:3, :3], s)
    T = _poses(p, R)
    T[0] = A
    if mode == "slerp":
        T[-1] = B
    return Path.from_poses(T, parameter=s)


def arc(start: object, center: object, axis: object, angle: float, *,
        end_rotation: object = None, max_step: float = 0.005,
        max_angle: float = math.radians(1.0), orientation: str = "follow") -> Path:
    """A circular arc: ``start``'s position turned about the line (center, axis) by ``angle``.

    Position ``p(s) = c + Rot(u, s·φ)·(p₀ − c)`` (u the unit axis, φ = ``angle``, right
    hand), s evenly spaced in [0, 1]. Orientation: 'follow' turns the tool with the arc
    (``Rot(u, s·φ)·R₀``, the tool keeps its attitude to the arc, as a weld torch does),
    'fixed' keeps R₀, 'slerp' interpolates from R₀ to ``end_rotation``.

    Args:
        start: (4, 4) first pose.
        center: (3,) a point on the arc's axis [m].
        axis: (3,) the axis direction (normalised here).
        angle: the arc's angle φ [rad], non-zero, at most 2π in size.
        end_rotation: (3, 3) last rotation, for 'slerp'.
        max_step: largest position step between samples [m].
        max_angle: largest rotation step between samples [rad].
        orientation: 'follow', 'fixed' or 'slerp'.
    """
    A = _pose(start, "start")
    c = as_float_array(center, "center")
    u = as_float_array(axis, "axis")
    if c.shape != (3,) or u.shape != (3,) or np.linalg.norm(u) == 0.0:
        raise InputError(f"center and axis must be 3-vectors, the axis non-zero; got center "
                         f"{c.tolist()!r}, axis {u.tolist()!r}")
    u = u / np.linalg.norm(u)
    phi = float(angle)
    if not (math.isfinite(phi) and 0.0 < abs(phi) <= 2 * math.pi + 1e-12):
        raise InputError(f"angle must be a non-zero arc angle in radians, at most 2π in size, "
                         f"got {angle!r}")
    h, a = _steps(max_step, max_angle)
    mode = _orientation(orientation)
    r0 = A[:3, 3] - c
    radius = float(np.linalg.norm(r0 - (r0 @ u) * u))
    if radius < 1e-9:
        raise InputError("the arc's start lies on its axis (radius 0): move the center or "
                         "the axis")
    if mode == "slerp":
        if end_rotation is None:
            raise InputError("orientation 'slerp' needs end_rotation, a (3, 3) rotation")
        R1 = _rotation(end_rotation, "end_rotation")
        turn = float(np.linalg.norm(so3_log(A[:3, :3].T @ R1, check=False)))
    else:
        turn = abs(phi) if mode == "follow" else 0.0
    k = _count(radius * abs(phi), turn, h, a)
    s = np.arange(k + 1) / k
    Rarc = so3_exp((s * phi)[:, None] * u)                       # (k + 1, 3, 3)
    p = c + Rarc @ r0
    if mode == "follow":
        R = Rarc @ A[:3, :3]
    elif mode == "fixed":
        R = np.broadcast_to(A[:3, :3], (k + 1, 3, 3))
    else:
        R = slerp(A[:3, :3], R1, s)
    T = _poses(p, R)
    T[0] = A
    return Path.from_poses(T, parameter=s)


def waypoints(poses: object, *, blend: float = 0.0, max_step: float = 0.005,
              max_angle: float = math.radians(1.0)) -> Path:
    """Straight segments through waypoint poses, corners rounded within ``blend`` [m].

    Positions: segment i runs from waypoint i to i + 1; with ``blend`` > 0 each inner
    corner is replaced by the quadratic Bézier curve from the point ``blend`` before the
    corner to the point ``blend`` after it (tangent to both segments; ``blend`` is cut
    to half of the shorter neighbouring segment), so the path has no kink. Rotations:
    SLERP from waypoint i's to waypoint i + 1's along segment i, by the fraction of its
    length travelled (the blend's samples take the rotation of the same fraction).

    Args:
        poses: (k, 4, 4) waypoint poses, k ≥ 2.
        blend: corner blend distance [m] (0: sharp corners through every waypoint).
        max_step: largest position step between samples [m].
        max_angle: largest rotation step between samples [rad].

    Returns:
        A pose :class:`~serialkin.tracking.path.Path` from the first to the last
        waypoint; without blending it passes through every waypoint exactly.
    """
    W = check_transform(poses, "poses")
    if W.ndim != 3 or W.shape[0] < 2:
        raise InputError(f"poses must be (k, 4, 4) with k >= 2 waypoints, got shape {W.shape}")
    h, a = _steps(max_step, max_angle)
    b = float(blend)
    if not (math.isfinite(b) and b >= 0.0):
        raise InputError(f"blend must be a distance >= 0 m, got {blend!r}")
    P = W[:, :3, 3]
    seg = np.linalg.norm(np.diff(P, axis=0), axis=1)
    cut = np.zeros(len(W))           # the blend distance at each inner waypoint
    for i in range(1, len(W) - 1):
        cut[i] = min(b, 0.5 * seg[i - 1], 0.5 * seg[i])
    out_p, out_R, out_s = [P[:1]], [W[:1, :3, :3]], [np.zeros(1)]
    travelled = 0.0
    for i in range(len(W) - 1):
        R0, R1 = W[i, :3, :3], W[i + 1, :3, :3]
        turn = float(np.linalg.norm(so3_log(R0.T @ R1, check=False)))
        L = float(seg[i])
        d = (P[i + 1] - P[i]) / L if L > 0.0 else np.zeros(3)
        # the straight part: from cut[i] after waypoint i to cut[i + 1] before i + 1
        s0, s1 = cut[i], L - cut[i + 1]
        frac_end = s1 / L if L > 0.0 else 1.0
        k = _count(s1 - s0, turn * (frac_end - (s0 / L if L > 0.0 else 0.0)), h, a)
        t = s0 + (s1 - s0) * np.arange(1, k + 1) / k
        f = t / L if L > 0.0 else np.arange(1, k + 1) / k
        out_p.append(P[i] + t[:, None] * d)
        out_R.append(slerp(R0, R1, f))
        out_s.append(travelled + t)
        if i + 1 < len(W) - 1 and cut[i + 1] > 0.0:  # the corner blend at waypoint i + 1
            e = (P[i + 2] - P[i + 1]) / seg[i + 1]
            c0, c1 = P[i + 1] - cut[i + 1] * d, P[i + 1] + cut[i + 1] * e
            R2 = W[i + 2, :3, :3]
            turn2 = float(np.linalg.norm(so3_log(R1.T @ R2, check=False)))
            chord = float(np.linalg.norm(c1 - c0))
            kb = _count(2.0 * cut[i + 1], turn * cut[i + 1] / L + turn2 * cut[i + 1]
                        / seg[i + 1], h, a)
            u = np.arange(1, kb + 1) / kb
            q = ((1 - u) ** 2)[:, None] * c0 + (2 * u * (1 - u))[:, None] * P[i + 1] \
                + (u**2)[:, None] * c1
            # rotation: the end of segment i's SLERP, then the start of segment i + 1's
            Rb = np.empty((kb, 3, 3))
            before = u < 0.5
            Rb[before] = slerp(R0, R1, 1.0 - cut[i + 1] / L * (1.0 - 2.0 * u[before]))
            Rb[~before] = slerp(R1, R2, cut[i + 1] / seg[i + 1] * (2.0 * u[~before] - 1.0))
            out_p.append(q)
            out_R.append(Rb)
            out_s.append(travelled + L - cut[i + 1] + u * max(chord, 1e-300))
        travelled += L
    T = _poses(np.concatenate(out_p), np.concatenate(out_R))
    T[0], T[-1] = W[0], W[-1]
    s = np.concatenate(out_s)
    s = s / s[-1] if s[-1] > 0.0 else np.linspace(0.0, 1.0, len(s))
    return Path.from_poses(T, parameter=s)
