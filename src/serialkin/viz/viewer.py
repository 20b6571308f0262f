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
and matrix), ``linkOrigins()``, ``fk(q)``, ``setFrame(k)``, ``play()``, ``pause()``,
``drawn()`` (what is on screen: shapes, triangles, capsules, points) and ``clearance()``
(the in-page self-collision check) for scripting and tests.

**The robot's body.** A robot with link geometry (:attr:`Robot.geometry`, e.g. from a URDF)
is drawn with its visual shapes, each fixed to its chain frame ``f`` at its origin, so a
vertex ``p`` of a shape is drawn at ``fk_all(q)[f] · origin · p``. Boxes, cylinders,
spheres and capsules become three.js geometries; mesh files are loaded with
:func:`serialkin.formats.mesh.load_mesh` (the ``mesh`` extra), decimated
(:func:`serialkin.formats.mesh.decimate`) so that all meshes together hold at most
``ViewerOptions.mesh_budget`` triangles (each mesh gets a share proportional to its own
triangle count; a mesh used by several links counts once), and embedded compactly: vertex
positions quantised to 16 bits per coordinate over the mesh's bounding box (error at most
half a step, ``extent / 131070``, about 2 µm for a 0.3 m link) and triangle indices as 16-
or 32-bit integers, both base64 of little-endian arrays; normals are computed in the page.
A robot without geometry keeps the skeleton of cylinders.

**Self-collision in the page.** With a collision model (:attr:`Robot.collision`, capsules
and spheres per body, :mod:`serialkin.collision`) the page can draw the capsules (a toggle)
and checks, after every slider move, the shape pairs that
:func:`~serialkin.collision.queries.checked_shape_pairs` lists for the allowed-collision
matrix: shape ``s`` with axis ends
``a_s, b_s`` in frame ``f_s`` has world ends ``A_s = T_f a_s``, ``B_s = T_f b_s``, and a pair
collides when ``dist(A_s B_s, A_t B_t) − r_s − r_t < 0`` (segment–segment distance, as
:func:`serialkin.collision.self_clearance` computes it). The bodies of a colliding pair are
drawn red (their capsules and the visual shapes of the links of the same name).

**Point layer.** A scene's ``points`` (N, 3) [m] with RGB ``point_colors`` (N, 3) in [0, 1]
are drawn as a point cloud with a toggle named by ``points_label`` (e.g. a reachability
map): positions as float32, colours as 8-bit, base64.

**Calling it.** What the page shows is one :class:`~serialkin.viz.scene.Scene`, how the
body is drawn one :class:`~serialkin.viz.scene.ViewerOptions`::

    write_viewer(Scene(robot, trajectory=Q, obstacles=obstacles), "robot.html",
                 ViewerOptions(meshes=False))

The old form, the robot first and the fields as keywords
(``write_viewer(robot, "robot.html", trajectory=Q, meshes=False)``), still works for one
release and warns (:class:`DeprecationWarning`).

Lengths are in metres, angles in radians.
"""

from __future__ import annotations

import base64
import html
import json
import re
import warnings
from dataclasses import fields
from functools import cache
from importlib import resources
from pathlib import Path
from typing import Any

import numpy as np

from serialkin._checks import as_float_array, short_repr
from serialkin._io import write_text_atomic
from serialkin.errors import InputError, InputTypeError
from serialkin.model.robot import Robot
from serialkin.viz.plot import Obstacle, robot_points, robot_scale
from serialkin.viz.scene import MESH_BUDGET, Scene, ViewerOptions

__all__ = [
    "MESH_BUDGET",
    "THREE_REVISION",
    "Scene",
    "ViewerOptions",
    "viewer_data",
    "viewer_html",
    "write_viewer",
]

#: three.js release embedded in the page (``viz/assets/three.module.min.js``).
THREE_REVISION = "170"
#: Fewest triangles a decimated mesh keeps.
_MIN_MESH_FACES = 16
#: Colour of a visual shape without its own (RGBA in [0, 1]).
_DEFAULT_RGBA = (0.86, 0.87, 0.89, 1.0)
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


def _path3(P: np.ndarray | None) -> np.ndarray | None:
    """The target path (k, 3) [m]: 2D points get z = 0."""
    if P is None or P.shape[1] == 3:
        return P
    return np.hstack([P, np.zeros((P.shape[0], 1))])


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


# ---------------------------------------------------------------------- geometry, collision, points
def _b64(a: np.ndarray) -> str:
    """Base64 text of an array's bytes (the caller chooses a little-endian dtype)."""
    return base64.b64encode(np.ascontiguousarray(a).tobytes()).decode("ascii")


def _encode_mesh(vertices: object, faces: object) -> dict[str, Any]:
    """The compact page form of a triangle mesh (see the module docstring).

    Positions are quantised over the bounding box ``[lo, lo + 65535 step]``:
    ``p ≈ lo + step · u`` with ``u`` 16-bit integers, so the error per coordinate is at
    most ``step / 2``; indices are uint16 when there are at most 65536 vertices, else uint32.

    Args:
        vertices: (V, 3) positions [m].
        faces: (F, 3) vertex indices.

    Returns:
        ``{"lo": [3], "step": [3], "positions": base64 of (V, 3) <u2, "indices": base64 of
        (F, 3) <u2 or <u4, "index_bytes": 2 or 4, "vertices": V, "faces": F}``.
    """
    v = as_float_array(vertices, "vertices", ndim=2)
    f = np.asarray(faces)
    if v.shape[1] != 3 or f.ndim != 2 or f.shape[1] != 3 or f.dtype.kind not in "iu":
        raise InputError(f"expected vertices (V, 3) and integer faces (F, 3), got {v.shape} "
                         f"and {f.shape}")
    if f.size and (f.min() < 0 or f.max() >= v.shape[0]):
        raise InputError(f"faces index vertices outside 0..{v.shape[0] - 1}")
    lo = v.min(axis=0) if v.size else np.zeros(3)
    span = (v.max(axis=0) - lo) if v.size else np.zeros(3)
    step = np.where(span > 0, span / 65535.0, 1.0)
    u = np.clip(np.rint((v - lo) / step), 0, 65535).astype("<u2")
    wide = v.shape[0] > 65536
    idx = f.astype("<u4" if wide else "<u2")
    return {"lo": lo.tolist(), "step": step.tolist(), "positions": _b64(u),
            "indices": _b64(idx), "index_bytes": 4 if wide else 2,
            "vertices": int(v.shape[0]), "faces": int(f.shape[0])}


def _face_shares(counts: list[int], budget: int) -> list[int]:
    """Triangles each mesh keeps: all when they fit, else shares proportional to the counts."""
    total = sum(counts)
    if total <= budget:
        return list(counts)
    return [min(c, max(_MIN_MESH_FACES, int(c * budget / total))) for c in counts]


def _primitive(g: object) -> dict[str, Any]:
    """Kind and sizes of a box, cylinder, sphere or capsule for the page [m]."""
    from serialkin.model.geometry import Box, Capsule, Cylinder, Sphere

    if isinstance(g, Box):
        return {"kind": "box", "size": list(g.size)}
    if isinstance(g, Cylinder):
        return {"kind": "cylinder", "radius": g.radius, "length": g.length}
    if isinstance(g, Sphere):
        return {"kind": "sphere", "radius": g.radius}
    if isinstance(g, Capsule):
        return {"kind": "capsule", "radius": g.radius, "length": g.length}
    raise InputTypeError(f"unknown geometry {type(g).__name__}")


def _visual_data(robot: Robot, meshes: bool, mesh_budget: int,
                 body_index: dict[str, int]) -> tuple[list[dict], list[dict]]:
    """The visual shapes (posed in their chain frames) and the encoded meshes they use.

    Mesh files are loaded once per (file, scale); ``meshes=False`` leaves mesh shapes out
    (primitives stay). Raises what :func:`serialkin.formats.mesh.load_mesh` raises, with the
    link named.
    """
    from serialkin.model.geometry import Mesh

    shapes: list[dict] = []
    files: dict[tuple, int] = {}
    loaded: list[Any] = []
    for lg in robot.geometry:
        if lg.frame > robot.n:
            raise InputError(f"link {short_repr(lg.link_name)} is fixed to frame {lg.frame}, "
                             f"but robot {short_repr(robot.name)} has frames 0..{robot.n}")
        for shape in lg.visual:
            g = shape.geometry
            entry: dict[str, Any] = {
                "link": lg.link_name, "name": shape.name, "frame": lg.frame,
                "origin": shape.origin.reshape(-1).tolist(),
                "rgba": list(shape.rgba if shape.rgba is not None else _DEFAULT_RGBA),
                "body": body_index.get(lg.link_name, -1),
            }
            if isinstance(g, Mesh):
                if not meshes:
                    continue
                key = (g.filename, g.scale)
                if key not in files:
                    files[key] = len(loaded)
                    loaded.append(_load_visual_mesh(lg.link_name, g))
                entry.update(kind="mesh", mesh=files[key])
            else:
                entry.update(_primitive(g))
            shapes.append(entry)
    encoded = []
    if loaded:
        from serialkin.formats.mesh import TriangleMesh, decimate, welded

        shares = _face_shares([m.faces.shape[0] for m in loaded], mesh_budget)
        for m, share in zip(loaded, shares, strict=True):
            if m.faces.shape[0] > share:
                m = decimate(TriangleMesh(m.vertices, m.faces, m.source), max(4, share))
            m = welded(TriangleMesh(m.vertices, m.faces, m.source))
            encoded.append(_encode_mesh(m.vertices, m.faces))
    return shapes, encoded


def _load_visual_mesh(link: str, g: Any) -> Any:
    """Load one visual mesh file (scale applied), its vertices welded for decimation."""
    from serialkin.errors import RobotDefinitionError
    from serialkin.formats.mesh import load_mesh, welded

    try:
        m = load_mesh(g.filename, g.scale)
    except RobotDefinitionError as exc:
        hint = ""
        if g.filename.startswith("package://") or not Path(g.filename).is_absolute():
            hint = (" (the path was never resolved: load the URDF with package_map= or "
                    "search_path=, or pass meshes=False)")
        raise RobotDefinitionError(f"link {short_repr(link)} visual mesh: {exc}{hint}") from None
    return welded(m)


def _collision_data(model: Any, acm: object) -> dict[str, Any]:
    """Capsules (frame, body, ends, radius) and the checked shape pairs for the page."""
    from serialkin.collision.queries import checked_shape_pairs

    pa, pb = checked_shape_pairs(model, acm)  # type: ignore[arg-type]
    return {
        "bodies": list(model.body_names),
        "body_frames": model.body_frames.tolist(),
        "frame": model.shape_frame.tolist(),
        "body": model.shape_body.tolist(),
        "a": model.a.tolist(),
        "b": model.b.tolist(),
        "radius": model.radius.tolist(),
        "pairs": np.stack([pa, pb], axis=1).tolist() if len(pa) else [],
        "source": model.source,
    }


def _collision_page(scene: Scene, show: bool) -> dict[str, Any] | None:
    """The page's collision block (capsules, checked pairs, shown at first?) or None."""
    model = scene.collision_model
    if model is None:
        if show:
            raise InputError(f"show_collision=True but robot {short_repr(scene.robot.name)} "
                             "has no collision model (Robot.collision is None)")
        return None
    data = _collision_data(model, scene.acm)
    data["show"] = bool(show)
    return data


def _points_data(scene: Scene) -> dict[str, Any] | None:
    """The point layer: positions float32 and colours uint8, base64; None without points."""
    P = scene.points
    if P is None:
        return None
    C = np.tile([0.1, 0.45, 0.85], (P.shape[0], 1)) if scene.point_colors is None \
        else scene.point_colors
    return {"count": int(P.shape[0]), "label": scene.points_label,
            "positions": _b64(P.astype("<f4")), "colors": _b64(np.rint(C * 255).astype("u1"))}


# ---------------------------------------------------------------------- the page's data
def _chain_data(robot: Robot) -> dict[str, Any]:
    """The robot's chain arrays, joint names, types and limits (None where unlimited)."""
    return {
        "n": robot.n,
        "F": robot.chain.F.tolist(),
        "L": robot.chain.L.tolist(),
        "meta": robot.chain.meta.tolist(),
        "joint_names": list(robot.joint_names),
        "joint_types": list(robot.joint_types),
        "qlim": [[float(v) if np.isfinite(v) else None for v in row] for row in robot.qlim],
    }


def _obstacle_data(o: Obstacle) -> dict[str, Any]:
    """One obstacle for the page: kind, centre, radius, height, capsule ends [m]."""
    return {
        "kind": o.kind,
        "center": o.center.tolist(),
        "radius": o.radius,
        "height": o.height,
        "a": None if o.a is None else o.a.tolist(),
        "b": None if o.b is None else o.b.tolist(),
    }


def _link_sizes(robot: Robot, q0: np.ndarray, scale: float) -> dict[str, float]:
    """Radii [m] of the skeleton's link and joint cylinders, from the typical link length."""
    seg = np.linalg.norm(np.diff(robot_points(robot, q0), axis=0), axis=1)
    seg = seg[seg > 1e-9]
    typical = float(np.median(seg)) if seg.size else scale
    return {"link_radius": min(0.018 * scale, 0.1 * typical),
            "joint_radius": min(0.032 * scale, 0.2 * typical)}


def _framing(scene: Scene, qs: np.ndarray, P: np.ndarray | None,
             scale: float) -> tuple[float, dict[str, Any]]:
    """The ground height [m] under the robot, path and obstacles, and the camera on all."""
    planar = scene.robot.is_planar
    frame_pts = [robot_points(scene.robot, qs).reshape(-1, 3)]
    if P is not None:
        frame_pts.append(P)
    frame_pts.extend(o.extent_points() for o in scene.obstacles)
    allpts = np.vstack(frame_pts)
    ground_z = float(allpts[:, 2].min()) - (0.002 * scale if planar else 0.0)
    if scene.points is not None and scene.points.shape[0]:  # framed, not under the grid
        allpts = np.vstack([allpts, scene.points])
    return ground_z, _view(allpts, planar, scale)


def _page_data(scene: Scene, options: ViewerOptions) -> dict[str, Any]:
    """The JSON document of :func:`viewer_data` for a checked scene and options."""
    from serialkin._version import __version__

    robot = scene.robot
    Q = scene.trajectory
    P = _path3(scene.path_points)
    q0 = scene.initial_q
    cdata = _collision_page(scene, options.show_collision)
    bodies = {} if cdata is None else {nm: i for i, nm in enumerate(cdata["bodies"])}
    shapes, mesh_data = _visual_data(robot, options.meshes, options.mesh_budget, bodies)
    scale = robot_scale(robot)
    qs = q0[None] if Q is None else np.vstack([q0[None], Q])
    ground_z, view = _framing(scene, qs, P, scale)
    return {
        "version": __version__,
        "name": robot.name,
        "title": scene.title if scene.title is not None else f"serialkin viewer: {robot.name}",
        **_chain_data(robot),
        "slider_limits": _slider_limits(robot, scale, qs),
        "q": q0.tolist(),
        "trajectory": None if Q is None else Q.tolist(),
        "path_points": None if P is None else P.tolist(),
        "obstacles": [_obstacle_data(o) for o in scene.obstacles],
        "planar": robot.is_planar,
        "scale": scale,
        "sizes": _link_sizes(robot, q0, scale),
        "ground_z": ground_z,
        "view": view,
        "shapes": shapes,
        "meshes": mesh_data,
        "collision": cdata,
        "points": _points_data(scene),
    }


def _json_for_script(data: dict[str, Any]) -> str:
    """JSON safe to embed in a raw-text <script> element (no '<' characters at all)."""
    return json.dumps(data, allow_nan=False, separators=(",", ":")).replace("<", "\\u003c")


def _subtitle(robot: Robot, data: dict[str, Any]) -> str:
    """The line under the page title: joints, their kinds, DH convention, trajectory size."""
    subtitle = f"{robot.n} joints ({''.join(robot.joint_types)})"
    if robot.convention:
        subtitle += f", {robot.convention} DH"
    if data["trajectory"] is not None:
        subtitle += f", trajectory of {len(data['trajectory'])} configurations"
    return subtitle


def _page(scene: Scene, options: ViewerOptions) -> str:
    """The HTML text of :func:`viewer_html` for a checked scene and options."""
    data = _page_data(scene, options)
    viewer_js = _asset("viewer.js")
    if "</script" in viewer_js.lower():
        raise RuntimeError("viewer.js must not contain '</script'")
    values = {
        "TITLE": html.escape(data["title"]),
        "SUBTITLE": html.escape(_subtitle(scene.robot, data)),
        "VERSION": html.escape(data["version"]),
        "CSS": _asset("viewer.css"),
        "DATA": _json_for_script(data),
        "THREE": _library(),
        "THREE_REVISION": THREE_REVISION,
        "VIEWER_JS": viewer_js,
    }
    # one pass: substituted text is never scanned again for placeholders
    return re.sub(r"\{\{([A-Z_]+)\}\}", lambda m: values[m.group(1)], _asset("viewer.html"))


# ---------------------------------------------------------------------- the call forms
#: The deprecated form's positional parameters after ``robot`` (after ``robot, path`` for
#: :func:`write_viewer`).
_OLD_POSITIONAL = ("q", "trajectory", "path_points", "obstacles", "title")
#: How each function is called now, for the deprecation message.
_NEW_FORM = {
    "viewer_data": "viewer_data(Scene(robot, ...), ViewerOptions(...))",
    "viewer_html": "viewer_html(Scene(robot, ...), ViewerOptions(...))",
    "write_viewer": "write_viewer(Scene(robot, ...), path, ViewerOptions(...))",
}


def _scene_and_options(func: str, scene: object, options: object, old_args: tuple,
                       old_keywords: dict[str, Any]) -> tuple[Scene, ViewerOptions]:
    """The scene and options of a call: given (new form) or built from the old arguments.

    The old form, a :class:`~serialkin.Robot` first and the scene's and options' fields
    as arguments, builds them and warns (:class:`DeprecationWarning`).
    """
    if isinstance(scene, Scene):
        if old_args or old_keywords:
            extra = (", ".join(f"{k}=" for k in sorted(old_keywords)) if old_keywords
                     else f"{len(old_args)} more positional argument(s)")
            raise InputTypeError(f"{func}() takes a Scene and a ViewerOptions, got a Scene "
                                 f"and also {extra}; put them in the Scene or the "
                                 "ViewerOptions")
        if options is None:
            return scene, ViewerOptions()
        if not isinstance(options, ViewerOptions):
            raise InputTypeError(f"options must be a ViewerOptions or None, got "
                                 f"{type(options).__name__} {short_repr(options)}")
        return scene, options
    if not isinstance(scene, Robot):
        raise InputTypeError(f"scene must be a Scene, got {type(scene).__name__} "
                             f"{short_repr(scene)}")
    positional = (options, *old_args) if old_args or options is not None else ()
    return _from_old_form(func, scene, positional, old_keywords)


def _from_old_form(func: str, robot: Robot, args: tuple,
                   keywords: dict[str, Any]) -> tuple[Scene, ViewerOptions]:
    """Build the scene and options from the deprecated arguments, with a warning."""
    if len(args) > len(_OLD_POSITIONAL):
        raise InputTypeError(f"{func}() takes at most {len(_OLD_POSITIONAL)} positional "
                             f"arguments after the robot ({', '.join(_OLD_POSITIONAL)}), got "
                             f"{len(args)}")
    given = dict(zip(_OLD_POSITIONAL, args, strict=False))
    twice = sorted(given.keys() & keywords.keys())
    if twice:
        raise InputTypeError(f"{func}() got {twice[0]!r} both by position and by name")
    given.update(keywords)
    scene_names = [f.name for f in fields(Scene) if f.name != "robot"]
    option_names = [f.name for f in fields(ViewerOptions)]
    unknown = sorted(set(given) - set(scene_names) - set(option_names))
    if unknown:
        raise InputTypeError(f"{func}() got unknown argument(s) {', '.join(unknown)}; "
                             f"expected Scene fields ({', '.join(scene_names)}) or "
                             f"ViewerOptions fields ({', '.join(option_names)})")
    warnings.warn(f"{func}(robot, ...) with the scene's and options' fields as arguments "
                  f"is deprecated and will be removed in the next release; call "
                  f"{_NEW_FORM[func]}", DeprecationWarning, stacklevel=4)
    scene = Scene(robot, **{k: v for k, v in given.items() if k in scene_names})
    return scene, ViewerOptions(**{k: v for k, v in given.items() if k in option_names})


# ---------------------------------------------------------------------- public functions
def viewer_data(scene: Scene, options: ViewerOptions | None = None, *old_args: object,
                **old_keywords: object) -> dict[str, Any]:
    """The JSON document the page is built from (see :func:`viewer_html` for arguments).

    Keys: ``n``, ``name``, ``F``/``L`` ((n+1) row-major 4x4 lists), ``meta`` (n rows
    [ax, ay, az, type (0 R, 1 P), offset]), ``joint_names``, ``joint_types``, ``qlim``
    (None where unlimited), ``slider_limits``, ``q``, ``trajectory`` (list of q or None),
    ``path_points`` (k, 3), ``obstacles`` (kind, center, radius, height, a, b),
    ``scale`` [m], ``sizes`` (link and joint radii drawn [m]), ``ground_z`` [m], ``view``
    (camera), ``title``, ``version``; ``shapes`` (visual shapes: link, name, frame, origin
    as 16 row-major numbers, rgba, kind ``mesh|box|cylinder|sphere|capsule`` with its sizes
    or its index into ``meshes``, body index or −1), ``meshes`` (encoded triangle meshes,
    see the module docstring), ``collision`` (None, or bodies, body_frames, per shape
    frame/body/a/b/radius, the checked shape ``pairs``, ``show``), ``points`` (None, or
    count, label, base64 positions and colours).
    """
    scene, options = _scene_and_options("viewer_data", scene, options, old_args, old_keywords)
    return _page_data(scene, options)


def viewer_html(scene: Scene, options: ViewerOptions | None = None, *old_args: object,
                **old_keywords: object) -> str:
    """The interactive viewer page as an HTML string (self-contained, works offline).

    Example::

        page = viewer_html(Scene(robot, trajectory=Q, path_points=path),
                           ViewerOptions(meshes=False))

    Args:
        scene: what the page shows: the robot, its configuration or (k, n) trajectory
            [rad / m], the target path and obstacles [m], the collision model and the
            point layer (see :class:`~serialkin.viz.scene.Scene`).
        options: how the robot's body is drawn: visual meshes, their triangle budget,
            capsules shown at first (see :class:`~serialkin.viz.scene.ViewerOptions`;
            None: the defaults).
        *old_args: deprecated: the old form ``viewer_html(robot, q, trajectory,
            path_points, obstacles, title)`` (builds the scene; warns).
        **old_keywords: deprecated: the old keywords (the fields of ``Scene`` and
            ``ViewerOptions``) after a robot; they build the scene and options and a
            :class:`DeprecationWarning` names the new form. Removed in the next release.

    Returns:
        The HTML text (about 0.7 MB of three.js, plus about 12 bytes per mesh triangle
        and 20 per point).

    Raises:
        InputTypeError: ``scene`` is not a Scene (nor, in the old form, a Robot),
            ``options`` is not a ViewerOptions, unknown old keywords.
        InputError: ``show_collision`` without a collision model; in the old form, what
            :class:`~serialkin.viz.scene.Scene` raises.
        RobotDefinitionError: a visual mesh file that is missing or corrupt (the message
            names the link and the file).
        NotSupportedError: mesh files to draw but trimesh is not installed (the message
            names the extra).
    """
    scene, options = _scene_and_options("viewer_html", scene, options, old_args, old_keywords)
    return _page(scene, options)


def write_viewer(scene: Scene, path: str | Path, options: ViewerOptions | None = None,
                 *old_args: object, **old_keywords: object) -> Path:
    """Write the viewer page (see :func:`viewer_html`) to ``path``, atomically.

    The file is written to a temporary file in the same folder and renamed, so an
    interrupted run never leaves a truncated page. Parent folders are created.

    Args:
        scene: what the page shows (see :func:`viewer_html`).
        path: the HTML file to write.
        options: how the robot's body is drawn (None: the defaults).
        *old_args: deprecated: the old form ``write_viewer(robot, path, q, trajectory,
            path_points, obstacles, title)`` (warns).
        **old_keywords: deprecated: the old keywords after a robot (warns; see
            :func:`viewer_html`).

    Returns:
        The path written.

    Raises:
        OutputError: the folder cannot be created or the file cannot be written; and
            what :func:`viewer_html` raises.
    """
    scene, options = _scene_and_options("write_viewer", scene, options, old_args,
                                        old_keywords)
    out = Path(path)
    write_text_atomic(out, _page(scene, options))
    return out
