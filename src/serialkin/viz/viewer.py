"""The interactive viewer: one self-contained HTML page with the robot in 3D.

The page needs no server and no network: it embeds the robot's data as JSON, the
three.js library (r170, MIT licence, vendored unmodified under ``viz/assets/`` with its
licence file) and the viewer's own script. It shows the robot in 3D (drag to rotate,
wheel to zoom, shift-drag to pan), a slider and a number box per joint that move the arm
live, a play button and a frame slider for a trajectory, the target path, the trace of the
end effector along the trajectory and the obstacles.

Forward kinematics runs **in the page**, from the robot's compiled chain arrays
(:attr:`Robot.chain`: ``F``, ``L``, ``meta``), with the same product as serialkin's kernels
(eq 11)::

    T = F[0] · M_1(q_1) · F[1] · M_2(q_2) ··· M_n(q_n) · F[n]

so any robot (standard or modified DH, general joints, URDF) is drawn exactly as
:meth:`Robot.fk` computes it. The page exposes ``window.serialkin`` with ``setJoint(i, v)``,
``setJoints(q)``, ``getJoints()``, ``endEffector()`` (the drawn tool frame's world position
and matrix), ``linkOrigins()``, ``fk(q)``, ``setFrame(k)``, ``play()``, ``pause()`` for
scripting and tests.

Lengths are in metres, angles in radians.
"""

from __future__ import annotations

import html
import json
import re
from collections.abc import Iterable
from functools import cache
from importlib import resources
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from serialkin._checks import as_float_array
from serialkin._io import write_text_atomic
from serialkin.errors import InputError
from serialkin.viz.plot import as_obstacle, robot_points, robot_scale

if TYPE_CHECKING:
    from serialkin.model.robot import Robot

__all__ = ["THREE_REVISION", "viewer_data", "viewer_html", "write_viewer"]

#: three.js release embedded in the page (``viz/assets/three.module.min.js``).
THREE_REVISION = "170"
_ASSETS = ("three.module.min.js", "three.LICENSE", "viewer.js", "viewer.css", "viewer.html")


@cache
def _asset(name: str) -> str:
    """Text of a file in ``serialkin/viz/assets``."""
    return resources.files("serialkin.viz").joinpath("assets", name).read_text(encoding="utf-8")


def _library() -> str:
    """The embedded three.js module source, checked to be safe inside a <script> element."""
    text = _asset("three.module.min.js")
    low = text.lower()
    if "</script" in low or "<!--" in low:  # would end the raw-text element early
        raise RuntimeError("the vendored three.js contains '</script' or '<!--'")
    return text


def _trajectory(robot: Robot, trajectory: object) -> np.ndarray | None:
    if trajectory is None:
        return None
    Q = robot.check_q(trajectory, "trajectory")
    if Q.ndim != 2 or Q.shape[0] == 0:
        raise InputError(
            f"trajectory must have shape (k, {robot.n}) with k >= 1, got {Q.shape}"
        )
    return Q


def _path_points(path_points: object) -> np.ndarray | None:
    if path_points is None:
        return None
    P = as_float_array(path_points, "path_points", ndim=2)
    if P.shape[1] not in (2, 3):
        raise InputError(f"path_points must have shape (k, 2) or (k, 3), got {P.shape}")
    if P.shape[1] == 2:
        P = np.hstack([P, np.zeros((P.shape[0], 1))])
    return P


def _initial_q(robot: Robot, q: object, Q: np.ndarray | None) -> np.ndarray:
    if q is not None:
        qv = robot.check_q(q)
        if qv.ndim != 1:
            raise InputError(f"q must be one configuration of shape ({robot.n},), got {qv.shape}")
        return qv
    if Q is not None:
        return Q[0].copy()
    return np.clip(np.zeros(robot.n), robot.qlim[:, 0], robot.qlim[:, 1])


def _slider_limits(robot: Robot, scale: float, qs: np.ndarray) -> list[list[float]]:
    """Slider range per joint: finite limits, else ±π rad or ±scale m, widened to fit ``qs``."""
    out = []
    for i, revolute in enumerate(robot.revolute):
        lo, hi = (float(v) for v in robot.qlim[i])
        default = np.pi if revolute else scale
        lo = lo if np.isfinite(lo) else -default
        hi = hi if np.isfinite(hi) else default
        lo = min(lo, float(qs[:, i].min()))
        hi = max(hi, float(qs[:, i].max()))
        out.append([lo, hi])
    return out


def _view(points: np.ndarray, planar: bool, scale: float) -> dict[str, Any]:
    """Camera framing all ``points`` (k, 3): orbit target, distance and angles [rad]."""
    lo, hi = points.min(axis=0), points.max(axis=0)
    target = (lo + hi) / 2
    radius = max(float(np.linalg.norm(hi - lo)) / 2, 0.25 * scale)
    distance = radius / np.sin(np.radians(20.0)) * 1.3  # 40° vertical field, some margin
    if planar:
        return {"target": target.tolist(), "radius": distance, "azimuth": -np.pi / 2,
                "elevation": np.radians(70.0)}
    return {"target": target.tolist(), "radius": distance, "azimuth": np.radians(-55.0),
            "elevation": np.radians(22.0)}


def viewer_data(
    robot: Robot,
    q: object = None,
    trajectory: object = None,
    path_points: object = None,
    obstacles: Iterable[object] | None = None,
    title: str | None = None,
) -> dict[str, Any]:
    """The JSON document the page is built from (see :func:`viewer_html` for arguments).

    Keys: ``n``, ``name``, ``F``/``L`` ((n+1) row-major 4x4 lists), ``meta`` (n rows
    [ax, ay, az, type (0 R, 1 P), offset]), ``joint_names``, ``joint_types``, ``qlim``
    (None where unlimited), ``slider_limits``, ``q``, ``trajectory`` (list of q or None),
    ``path_points`` (k, 3), ``obstacles`` (kind, center, radius, height, a, b),
    ``scale`` [m], ``sizes`` (link and joint radii drawn [m]), ``ground_z`` [m], ``view``
    (camera), ``title``, ``version``.
    """
    from serialkin import __version__

    Q = _trajectory(robot, trajectory)
    P = _path_points(path_points)
    q0 = _initial_q(robot, q, Q)
    obs = [as_obstacle(o, f"obstacles[{i}]") for i, o in enumerate(obstacles or ())]
    scale = robot_scale(robot)
    qs = q0[None] if Q is None else np.vstack([q0[None], Q])
    pts = robot_points(robot, qs).reshape(-1, 3)
    planar = robot.is_planar
    frame_pts = [pts]
    if P is not None:
        frame_pts.append(P)
    frame_pts.extend(o.extent_points() for o in obs)
    allpts = np.vstack(frame_pts)
    ground_z = float(allpts[:, 2].min()) - (0.002 * scale if planar else 0.0)
    qlim = [[float(v) if np.isfinite(v) else None for v in row] for row in robot.qlim]
    seg = np.linalg.norm(np.diff(robot_points(robot, q0), axis=0), axis=1)
    seg = seg[seg > 1e-9]
    typical = float(np.median(seg)) if seg.size else scale
    sizes = {"link_radius": min(0.018 * scale, 0.1 * typical),
             "joint_radius": min(0.032 * scale, 0.2 * typical)}
    return {
        "version": __version__,
        "name": robot.name,
        "title": title if title is not None else f"serialkin viewer: {robot.name}",
        "n": robot.n,
        "F": robot.chain.F.tolist(),
        "L": robot.chain.L.tolist(),
        "meta": robot.chain.meta.tolist(),
        "joint_names": list(robot.joint_names),
        "joint_types": list(robot.joint_types),
        "qlim": qlim,
        "slider_limits": _slider_limits(robot, scale, qs),
        "q": q0.tolist(),
        "trajectory": None if Q is None else Q.tolist(),
        "path_points": None if P is None else P.tolist(),
        "obstacles": [
            {
                "kind": o.kind,
                "center": o.center.tolist(),
                "radius": o.radius,
                "height": o.height,
                "a": None if o.a is None else o.a.tolist(),
                "b": None if o.b is None else o.b.tolist(),
            }
            for o in obs
        ],
        "planar": planar,
        "scale": scale,
        "sizes": sizes,
        "ground_z": ground_z,
        "view": _view(allpts, planar, scale),
    }


def _json_for_script(data: dict[str, Any]) -> str:
    """JSON safe to embed in a raw-text <script> element (no '<' characters at all)."""
    return json.dumps(data, allow_nan=False, separators=(",", ":")).replace("<", "\\u003c")


def viewer_html(
    robot: Robot,
    q: object = None,
    trajectory: object = None,
    path_points: object = None,
    obstacles: Iterable[object] | None = None,
    title: str | None = None,
) -> str:
    """The interactive viewer page as an HTML string (self-contained, works offline).

    Args:
        robot: the robot to show.
        q: initial configuration (n,) [rad / m]; default the trajectory's first row, else
            zeros clipped into the joint limits.
        trajectory: (k, n) configurations to play back (play button and frame slider); the
            end effector's trace along it is drawn.
        path_points: (k, 2) or (k, 3) target path [m], drawn as a green polyline
            (2D points get z = 0).
        obstacles: obstacle objects or dicts (see :func:`serialkin.viz.plot.as_obstacle`):
            spheres, vertical cylinders, capsules.
        title: page title (default "serialkin viewer: <robot name>").

    Returns:
        The HTML text (about 0.7 MB, most of it three.js).

    Raises:
        InputError: a configuration with the wrong number of joints or non-finite values,
            a path of the wrong shape, a malformed obstacle.
    """
    data = viewer_data(robot, q=q, trajectory=trajectory, path_points=path_points,
                       obstacles=obstacles, title=title)
    kinds = "".join(robot.joint_types)
    subtitle = f"{robot.n} joints ({kinds})"
    if robot.convention:
        subtitle += f", {robot.convention} DH"
    if data["trajectory"] is not None:
        subtitle += f", trajectory of {len(data['trajectory'])} configurations"
    viewer_js = _asset("viewer.js")
    if "</script" in viewer_js.lower():
        raise RuntimeError("viewer.js must not contain '</script'")
    values = {
        "TITLE": html.escape(data["title"]),
        "SUBTITLE": html.escape(subtitle),
        "VERSION": html.escape(data["version"]),
        "CSS": _asset("viewer.css"),
        "DATA": _json_for_script(data),
        "THREE": _library(),
        "THREE_REVISION": THREE_REVISION,
        "VIEWER_JS": viewer_js,
    }
    # one pass: substituted text is never scanned again for placeholders
    return re.sub(r"\{\{([A-Z_]+)\}\}", lambda m: values[m.group(1)], _asset("viewer.html"))


def write_viewer(
    robot: Robot,
    path: str | Path,
    q: object = None,
    trajectory: object = None,
    path_points: object = None,
    obstacles: Iterable[object] | None = None,
    title: str | None = None,
) -> Path:
    """Write the viewer page (see :func:`viewer_html`) to ``path``, atomically.

    The file is written to a temporary file in the same folder and renamed, so an
    interrupted run never leaves a truncated page. Parent folders are created.

    Returns:
        The path written.
    """
    text = viewer_html(robot, q=q, trajectory=trajectory, path_points=path_points,
                       obstacles=obstacles, title=title)
    out = Path(path)
    write_text_atomic(out, text)
    return out
