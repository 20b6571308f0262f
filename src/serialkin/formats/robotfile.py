"""Robot files: a robot's DH table, limits, base and tool in YAML or JSON (section 3.2).

A robot file states its units once and describes the robot with a standard or modified
Denavit–Hartenberg table (the chapter's eqs 12-16 for ``standard``; Craig's form for
``modified``)::

    name: two-link                 # required
    convention: standard           # standard | modified
    units: {angle: deg, length: m} # required: angle rad|deg, length m|cm|mm
    source: "chapter Figure 5"     # optional, free text
    dh:                            # one row per joint, base to tool
      - {a: 1.0, alpha: 0, d: 0, theta: 0, type: R, qlim: [-170, 170]}
      - {a: 0.6, alpha: 0, d: 0, theta: 0, type: R, qlim: [-170, 170], name: elbow}
    base: {xyz: [0, 0, 0], rpy: [0, 0, 0]}   # optional: xyz + rpy, or a 4x4 matrix
    tool: [[1, 0, 0, 0.1], [0, 1, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1]]

Optional link geometry and collision capsules (lengths in the file's length unit, ``rpy``
in its angle unit; see docs/robot-files.md)::

    mesh_path: [meshes]            # optional: folders for relative mesh files
    geometry:                      # shapes per link, posed in chain frame 0..n
      - link: forearm
        frame: 2
        visual:
          - {mesh: {file: forearm.stl, scale: [1, 1, 1]}, rgba: [0.8, 0.8, 0.8, 1]}
        collision:
          - {cylinder: {radius: 0.05, length: 0.4}, origin: {xyz: [0.2, 0, 0], rpy: [0, 90, 0]}}
    collision:                     # the capsule model (serialkin.collision.CollisionModel)
      - {name: forearm, frame: 2,
         capsules: [{a: [0, 0, 0], b: [0.4, 0, 0], radius: 0.06}],
         spheres: [{center: [0.4, 0, 0], radius: 0.07}]}

A shape is one of ``box: {size: [x, y, z]}``, ``cylinder: {radius, length}``,
``sphere: {radius}``, ``capsule: {radius, length}`` (axis z, centred) or
``mesh: {file, scale}``, with optional ``origin`` (``{xyz, rpy}`` or a 4x4 matrix),
``name``, ``material`` and ``rgba``. A relative mesh file is looked up in the robot file's
folder, then in each ``mesh_path`` folder (relative to the file's folder); a
``package://NAME/rest`` path as ``FOLDER/NAME/rest``. Mesh files keep their own unit
(metres, or a COLLADA file's ``<unit>``), only ``scale`` applies.

Units apply to every field: ``alpha``, ``theta``, ``rpy`` and the limits of revolute
joints are angles; ``a``, ``d``, ``xyz``, the translation of a 4x4 matrix and the limits
of prismatic joints are lengths. ``qlim`` may be omitted (unlimited joint) or use
``null`` / ``.inf`` for an open side. ``rpy`` = (roll, pitch, yaw) about the fixed x, y,
z axes: ``R = Rz(yaw) · Ry(pitch) · Rx(roll)`` (the URDF convention).

Every error is a :class:`~serialkin.errors.RobotDefinitionError` whose message names the
file, the field (e.g. ``dh[2].alpha``) and what was expected.
"""

from __future__ import annotations

import json
import math
import os
from pathlib import Path
from typing import Any

import numpy as np

from serialkin._checks import MAX_JOINT_VALUE, MAX_JOINTS, MAX_LENGTH, beyond_a_turn, short_repr
from serialkin._files import Field, load_document
from serialkin.errors import InputTypeError, RobotDefinitionError
from serialkin.formats.urdf import MeshResolver
from serialkin.model.collision_model import CollisionModel
from serialkin.model.dh import CONVENTIONS, DHLink
from serialkin.model.geometry import Box, Capsule, Cylinder, LinkGeometry, Mesh, Shape, Sphere
from serialkin.model.joint import normalize_joint_type
from serialkin.model.robot import Robot
from serialkin.spatial import make_transform, rpy_to_matrix

__all__ = [
    "ANGLE_UNITS",
    "LENGTH_UNITS",
    "MAX_DH_ROWS",
    "MAX_SHAPES",
    "ROBOT_FILE_SUFFIXES",
    "collision_from_dict",
    "dh_rows_from_field",
    "load_collision_file",
    "load_robot_file",
    "read_robot_data",
    "robot_from_dict",
    "robot_to_dict",
    "save_collision_file",
    "save_robot_file",
]

#: Accepted angle units and their factor to radians.
ANGLE_UNITS: dict[str, float] = {"rad": 1.0, "deg": math.pi / 180.0}
#: Accepted length units and their factor to metres.
LENGTH_UNITS: dict[str, float] = {"m": 1.0, "cm": 0.01, "mm": 0.001}
#: Suffixes read as robot files (``.urdf`` is read by :mod:`serialkin.formats.urdf`).
ROBOT_FILE_SUFFIXES = (".yaml", ".yml", ".json")
#: Most rows of a DH table in a robot file or a scenario.
MAX_DH_ROWS = MAX_JOINTS

_TOP_FIELDS = ("name", "convention", "units", "source", "dh", "base", "tool", "mesh_path",
               "geometry", "collision")
_SHAPE_KINDS = ("box", "cylinder", "sphere", "capsule", "mesh")
_SHAPE_FIELDS = (*_SHAPE_KINDS, "origin", "name", "material", "rgba")
#: Most shapes per link and kind, links with geometry, and capsules per body.
MAX_SHAPES = 10_000
_ROW_FIELDS = ("a", "alpha", "d", "theta", "type", "qlim", "name")


def _transform(f: Field, ang: float, lin: float, angle_unit: str, length_unit: str
               ) -> np.ndarray:
    """Parse ``{xyz, rpy}`` (either optional) or a 4x4 nested list into a rigid transform."""
    if isinstance(f.value, dict):
        f.mapping({"xyz", "rpy"})
        xyz = (_lengths(f["xyz"], 3, length_unit) if f["xyz"].present else np.zeros(3))
        rpy = (_angles(f["rpy"], 3, angle_unit) if f["rpy"].present else np.zeros(3))
        return make_transform(rpy_to_matrix(rpy), xyz)
    if isinstance(f.value, list) and len(f.value) == 4:
        T = np.array([r.vector(4, unit="matrix row") for r in f.items()])
        T[:3, 3] *= lin
        if np.abs(T[3] - [0, 0, 0, 1]).max() > 1e-9:
            raise f.fail(f"must be a homogeneous transform whose last row is [0, 0, 0, 1], "
                         f"got {T[3].tolist()}")
        R = T[:3, :3]
        err = float(np.abs(R.T @ R - np.eye(3)).max())
        if err > 1e-6 or np.linalg.det(R) < 0:
            raise f.fail("must have a rotation block that is orthonormal with det +1 "
                         f"(max |RᵀR − I| = {err:.3g}, det = {np.linalg.det(R):.4g})")
        return T
    raise f.expected("{xyz: [x, y, z], rpy: [roll, pitch, yaw]} or a 4x4 matrix")


def _bound(limit: float, factor: float) -> float:
    """A bound in SI units (``limit``) expressed in the file's units (``factor`` to SI)."""
    return limit / factor


def _lengths(f: Field, size: int, unit: str) -> np.ndarray:
    """``size`` lengths in ``unit`` as metres, each within ±:data:`MAX_LENGTH` m."""
    b = _bound(MAX_LENGTH, LENGTH_UNITS[unit])
    return f.vector(size, lo=-b, hi=b, unit=unit) * LENGTH_UNITS[unit]


def _angles(f: Field, size: int, unit: str) -> np.ndarray:
    """``size`` angles in ``unit`` as radians, each within ±:data:`MAX_JOINT_VALUE` rad."""
    b = _bound(MAX_JOINT_VALUE, ANGLE_UNITS[unit])
    return f.vector(size, lo=-b, hi=b, unit=unit) * ANGLE_UNITS[unit]


def _limits(f: Field, factor: float, unit: str) -> tuple[float, float]:
    """A joint range ``[lower, upper]`` (null or ±.inf for an open side), times ``factor``."""
    if not isinstance(f.value, list) or len(f.value) != 2:
        raise f.expected(f"a pair [lower, upper] [{unit}] (null or .inf for an open side)")
    lo_f, hi_f = f.items()
    b = _bound(MAX_JOINT_VALUE, factor)
    lo = lo_f.number(lo=-b, hi=b, unit=unit, allow_inf=True, default=-math.inf)
    hi = hi_f.number(lo=-b, hi=b, unit=unit, allow_inf=True, default=math.inf)
    if lo == math.inf:
        raise lo_f.fail("must be a number or null (an open lower side), got +inf")
    if hi == -math.inf:
        raise hi_f.fail("must be a number or null (an open upper side), got -inf")
    if lo > hi:
        raise f.fail(f"must have lower <= upper, got [{lo:g}, {hi:g}]")
    return (lo * factor if math.isfinite(lo) else lo, hi * factor if math.isfinite(hi) else hi)


def dh_rows_from_field(f: Field, *, angle_unit: str = "rad", length_unit: str = "m",
                       allow_names: bool = True) -> list[DHLink]:
    """Read a DH table (a list of ``{a, alpha, d, theta, type, qlim, name}`` rows).

    Shared by robot files and scenarios. ``a``, ``d`` and the limits of prismatic
    joints are lengths in ``length_unit``; ``alpha``, ``theta`` and the limits of
    revolute joints are angles in ``angle_unit``; the result is in metres and radians.

    Raises:
        f.error: a malformed table; the message names the file and the field
            (``dh[2].alpha``).
    """
    ang, lin = ANGLE_UNITS[angle_unit], LENGTH_UNITS[length_unit]
    allowed = _ROW_FIELDS if allow_names else tuple(x for x in _ROW_FIELDS if x != "name")
    rows: list[DHLink] = []
    items = f.items(min_len=1, max_len=MAX_DH_ROWS,
                    what="a non-empty list of rows {a, alpha, d, theta, type, qlim}")
    for i, row in enumerate(items):
        row.mapping(allowed, ("a", "alpha", "d", "theta"),
                    what="a mapping {a, alpha, d, theta, type, qlim}")
        tf = row["type"]
        try:
            jtype = normalize_joint_type(tf.value if tf.present else "R", tf.path)
        except RobotDefinitionError:
            raise tf.expected("'R' (revolute) or 'P' (prismatic)") from None
        bl, ba = _bound(MAX_LENGTH, lin), _bound(MAX_JOINT_VALUE, ang)
        a = row["a"].number(lo=-bl, hi=bl, unit=length_unit) * lin
        d = row["d"].number(lo=-bl, hi=bl, unit=length_unit) * lin
        alpha = row["alpha"].number(lo=-ba, hi=ba, unit=angle_unit) * ang
        theta = row["theta"].number(lo=-ba, hi=ba, unit=angle_unit) * ang
        for key, value in (("alpha", alpha), ("theta", theta)):
            if beyond_a_turn(value):  # a fixed angle beyond a turn: degrees?
                raise row[key].expected(
                    f"an angle of at most one turn (2π) in {angle_unit} (are these degrees? "
                    "declare them with units: {angle: deg})")
        qunit, qfac = (angle_unit, ang) if jtype == "R" else (length_unit, lin)
        qlim = (_limits(row["qlim"], qfac, qunit) if row["qlim"].present
                else (-math.inf, math.inf))
        jname = row["name"].string(default=f"joint{i + 1}", max_len=1000)
        rows.append(DHLink(a=a, alpha=alpha, d=d, theta=theta, type=jtype, qlim=qlim,
                           name=jname))
    names = [r.name for r in rows]
    if len(set(names)) != len(names):
        dup = sorted({x for x in names if names.count(x) > 1})
        raise f.fail(f"must have unique joint names, got duplicates {dup[:5]}")
    return rows


def _size(f: Field, unit: str, lin: float) -> float:
    """A length >= 0 in ``unit``, as metres."""
    return f.number(lo=0.0, hi=_bound(MAX_LENGTH, lin), unit=unit) * lin


def _shape(f: Field, link: str, units: tuple[str, str], resolve: Any) -> Any:
    """One shape mapping (module doc) as a :class:`~serialkin.model.geometry.Shape`."""
    angle_unit, length_unit = units
    ang, lin = ANGLE_UNITS[angle_unit], LENGTH_UNITS[length_unit]
    f.mapping(_SHAPE_FIELDS, what="a shape mapping with one of " + ", ".join(_SHAPE_KINDS))
    kinds = [k for k in _SHAPE_KINDS if k in f]
    if len(kinds) != 1:
        raise f.fail(f"must have exactly one geometry ({', '.join(_SHAPE_KINDS)}), got "
                     f"{', '.join(kinds) or 'none'}")
    kind = kinds[0]
    g = f[kind]
    if kind == "box":
        g.mapping({"size"}, ("size",), what="{size: [x, y, z]}")
        b = _bound(MAX_LENGTH, lin)
        geometry: Any = Box(tuple(g["size"].vector(3, lo=0.0, hi=b, unit=length_unit) * lin))
    elif kind == "sphere":
        g.mapping({"radius"}, ("radius",), what="{radius}")
        geometry = Sphere(_size(g["radius"], length_unit, lin))
    elif kind in ("cylinder", "capsule"):
        g.mapping({"radius", "length"}, ("radius", "length"), what="{radius, length}")
        cls = Cylinder if kind == "cylinder" else Capsule
        geometry = cls(_size(g["radius"], length_unit, lin), _size(g["length"], length_unit, lin))
    else:
        g.mapping({"file", "scale"}, ("file",), what="{file, scale}")
        name = g["file"].string(max_len=4096)
        scale = (tuple(g["scale"].vector(3, lo=0.0, hi=1e6)) if g["scale"].present
                 else (1.0, 1.0, 1.0))
        if min(scale) <= 0.0:
            raise g["scale"].expected("3 numbers > 0")
        where = f"{f.origin}: field '{g['file'].path}' (link {short_repr(link)})"
        geometry = Mesh(resolve(name, where), scale)
    T = (_transform(f["origin"], ang, lin, angle_unit, length_unit) if f["origin"].present
         else np.eye(4))
    rgba = None
    if f["rgba"].present:
        rgba = tuple(f["rgba"].vector(4, lo=0.0, hi=1.0))
    material = f["material"].string(max_len=1000) if f["material"].present else None
    return Shape(geometry, T, name=f["name"].string(default="", nonempty=False, max_len=1000),
                 material=material, rgba=rgba)


def _geometry_field(f: Field, n: int, units: tuple[str, str], resolve: Any) -> tuple:
    """The ``geometry`` list as :class:`~serialkin.model.geometry.LinkGeometry` entries."""
    out, seen = [], set()
    for item in f.items(max_len=MAX_SHAPES, what="a list of {link, frame, visual, collision}"):
        item.mapping({"link", "frame", "visual", "collision"}, ("link", "frame"),
                     what="a mapping {link, frame, visual, collision}")
        link = item["link"].string(max_len=1000)
        if link in seen:
            raise item["link"].fail(f"must name each link once, got {short_repr(link)} twice")
        seen.add(link)
        frame = item["frame"].integer(lo=0, hi=n)
        shapes = {}
        for kind in ("visual", "collision"):
            k = item[kind]
            shapes[kind] = tuple(
                _shape(s, link, units, resolve)
                for s in (k.items(max_len=MAX_SHAPES, what="a list of shapes")
                          if k.present else []))
        out.append(LinkGeometry(link, frame, shapes["visual"], shapes["collision"]))
    return tuple(out)


def _collision_field(f: Field, n: int, length_unit: str, source: str) -> Any:
    """The ``collision`` list as a :class:`~serialkin.model.collision_model.CollisionModel`."""
    lin = LENGTH_UNITS[length_unit]
    b = _bound(MAX_LENGTH, lin)
    names, frames, owner, A, B, R = [], [], [], [], [], []
    allowed: list[tuple[Field, str, str]] = []
    for i, body in enumerate(f.items(max_len=MAX_SHAPES,
                                     what="a list of {name, frame, capsules, spheres}")):
        body.mapping({"name", "frame", "capsules", "spheres", "allowed"}, ("name", "frame"),
                     what="a mapping {name, frame, capsules, spheres, allowed}")
        name = body["name"].string(max_len=1000)
        if body["allowed"].present:
            allowed += [(item, name, item.string(max_len=1000)) for item in
                        body["allowed"].items(max_len=MAX_SHAPES, what="a list of body names")]
        if name in names:
            raise body["name"].fail(f"must name each body once, got {short_repr(name)} twice")
        names.append(name)
        frames.append(body["frame"].integer(lo=0, hi=n))
        for kind, keys in (("capsules", ("a", "b")), ("spheres", ("center",))):
            k = body[kind]
            for s in (k.items(max_len=MAX_SHAPES, what=f"a list of {kind}")
                      if k.present else []):
                s.mapping({*keys, "radius"}, (*keys, "radius"),
                          what="a mapping {" + ", ".join((*keys, "radius")) + "}")
                pts = [s[key].vector(3, lo=-b, hi=b, unit=length_unit) * lin for key in keys]
                owner.append(i)
                A.append(pts[0])
                B.append(pts[-1])
                R.append(_size(s["radius"], length_unit, lin))
    for item, _, other in allowed:
        if other not in names:
            raise item.fail(f"must name a body of this list ({', '.join(names)}), got "
                            f"{short_repr(other)}")
    return CollisionModel(tuple(names), np.array(frames, dtype=np.int64),
                          np.array(owner, dtype=np.int64), np.reshape(np.array(A), (-1, 3)),
                          np.reshape(np.array(B), (-1, 3)), np.array(R, dtype=float),
                          source=source, allowed=tuple((a, b) for _, a, b in allowed))


def robot_from_dict(data: object, origin: str = "<robot description>",
                    folder: str | os.PathLike[str] | None = None) -> Robot:
    """Build a :class:`~serialkin.Robot` from a parsed robot-file mapping (see module doc).

    Args:
        data: the mapping read from a YAML/JSON robot file.
        origin: what to call the description in errors (the file path).
        folder: where relative mesh files and ``mesh_path`` folders are looked up (the
            robot file's folder); None: only absolute paths and ``mesh_path`` as given.

    Returns:
        The robot, with lengths in metres and angles in radians.

    Raises:
        RobotDefinitionError: a missing, unknown or malformed field (a negative size, an
            unknown shape kind, a frame beyond the robot's), or a mesh file that does not
            resolve; the message names ``origin``, the field (and link) and what was
            expected, or where the mesh was looked for.
    """
    doc = Field(data, "", origin, RobotDefinitionError)
    doc.mapping(_TOP_FIELDS, ("name", "units", "dh"),
                what=f"a mapping with fields {', '.join(_TOP_FIELDS)}")
    name = doc["name"].string(max_len=1000)
    convention = doc["convention"].string(choices=CONVENTIONS, default="standard")
    source = doc["source"].string(default="", nonempty=False)
    units = doc["units"].mapping({"angle", "length"}, ("angle",),
                                 what="a mapping {angle: rad|deg, length: m|cm|mm}")
    angle_unit = units["angle"].string(choices=ANGLE_UNITS)
    length_unit = units["length"].string(choices=LENGTH_UNITS, default="m")
    ang, lin = ANGLE_UNITS[angle_unit], LENGTH_UNITS[length_unit]
    rows = dh_rows_from_field(doc["dh"], angle_unit=angle_unit, length_unit=length_unit)
    base = tool = None
    if doc["base"].present:
        base = _transform(doc["base"], ang, lin, angle_unit, length_unit)
    if doc["tool"].present:
        tool = _transform(doc["tool"], ang, lin, angle_unit, length_unit)
    try:
        robot = Robot.from_dh(rows, convention, base=base, tool=tool, name=name,
                              source=source)
    except RobotDefinitionError as exc:  # pragma: no cover - fields are validated above
        raise RobotDefinitionError(f"{origin}: {exc}") from exc
    if doc["geometry"].present:
        base_dir = Path(folder) if folder is not None else None
        search = []
        if doc["mesh_path"].present:
            for item in doc["mesh_path"].items(max_len=1000, what="a list of folders"):
                d = Path(item.string(max_len=4096))
                search.append(base_dir / d if base_dir is not None and not d.is_absolute()
                              else d)
        resolve = MeshResolver(base_dir, {}, search, strict=True,
                               nowhere="nowhere: give mesh_path, or load the robot file "
                                       "from its folder")
        robot = robot._copy(geometry=_geometry_field(doc["geometry"], robot.n,
                                                     (angle_unit, length_unit), resolve))
    elif doc["mesh_path"].present:
        doc["mesh_path"].items(max_len=1000, what="a list of folders")
    if doc["collision"].present:
        model = _collision_field(doc["collision"], robot.n, length_unit,
                                 f"robot file {origin}")
        robot = robot.with_collision(model)
    return robot


def read_robot_data(path: str | os.PathLike[str]) -> object:
    """Parse a robot file (YAML or JSON by suffix) into Python data, naming the file on error.

    The file is read by :func:`serialkin._files.load_document`: at most
    :data:`~serialkin._files.MAX_FILE_BYTES`, UTF-8, no duplicate keys, bounded nesting
    and alias expansion.
    """
    if not isinstance(path, (str, os.PathLike)):
        raise InputTypeError(f"path must be a str or os.PathLike, got {type(path).__name__} "
                             f"{short_repr(path)}")
    p = Path(path)
    if p.suffix.lower() not in ROBOT_FILE_SUFFIXES:
        raise RobotDefinitionError(
            f"{p}: unknown robot file type {p.suffix!r}; expected one of "
            f"{', '.join(ROBOT_FILE_SUFFIXES)} (or .urdf)"
        )
    return load_document(p, what="robot file", error=RobotDefinitionError)


def load_robot_file(path: str | os.PathLike[str]) -> Robot:
    """Read a robot file (``.yaml``, ``.yml`` or ``.json``) and build the robot.

    Args:
        path: the file.

    Returns:
        :class:`~serialkin.Robot` (lengths in m, angles in rad).

    Raises:
        RobotDefinitionError: unreadable file, syntax error (with line number) or a
            malformed field (named, with what was expected).
    """
    return robot_from_dict(read_robot_data(path), origin=str(path),
                           folder=Path(path).resolve().parent)


def robot_to_dict(robot: Any, angle_unit: str = "deg", length_unit: str = "m", *,
                  mesh_base: str | os.PathLike[str] | None = None) -> dict[str, Any]:
    """The robot-file mapping of a DH robot in the given units (inverse of robot_from_dict).

    Base and tool are written as ``{xyz, rpy}`` in the file's units (rpy from
    :func:`serialkin.spatial.matrix_to_rpy`, 12 significant decimals) and omitted when
    they are the identity. The robot's ``geometry`` and ``collision`` model are written
    when it has them; absolute mesh paths are written relative to ``mesh_base`` when it
    is given (the folder of the file being written).

    Raises:
        RobotDefinitionError: the robot has no DH table (e.g. it came from a URDF).
        InputError: unknown unit.
    """
    from serialkin._checks import check_choice

    check_choice(angle_unit, "angle_unit", ANGLE_UNITS)
    check_choice(length_unit, "length_unit", LENGTH_UNITS)
    if robot.dh is None:
        raise RobotDefinitionError(
            f"robot {short_repr(robot.name)} has no DH table; a robot file needs one "
            "(save a URDF with robot.to_urdf() instead)"
        )
    ang, lin = ANGLE_UNITS[angle_unit], LENGTH_UNITS[length_unit]

    def num(x: float) -> float | None:
        return None if not math.isfinite(x) else float(round(x, 12)) + 0.0  # no -0.0

    rows = []
    for r in robot.dh:
        fac = ang if r.type == "R" else lin
        row: dict[str, Any] = {"a": num(r.a / lin), "alpha": num(r.alpha / ang),
                               "d": num(r.d / lin), "theta": num(r.theta / ang), "type": r.type}
        if np.isfinite(r.qlim).any():
            row["qlim"] = [num(r.qlim[0] / fac), num(r.qlim[1] / fac)]
        row["name"] = r.name
        rows.append(row)
    out: dict[str, Any] = {"name": robot.name, "convention": robot.convention,
                           "units": {"angle": angle_unit, "length": length_unit}}
    if robot.source:
        out["source"] = robot.source
    out["dh"] = rows
    from serialkin.spatial import matrix_to_rpy

    for key in ("base", "tool"):
        T = np.array(getattr(robot, key), dtype=float)
        if not np.allclose(T, np.eye(4), atol=1e-15):
            rpy = matrix_to_rpy(T[:3, :3], check=False) / ang
            out[key] = {"xyz": [num(v / lin) for v in T[:3, 3]], "rpy": [num(v) for v in rpy]}
    if getattr(robot, "geometry", ()):
        out["geometry"] = [_link_geometry_dict(lg, ang, lin, mesh_base, num)
                           for lg in robot.geometry]
    if getattr(robot, "collision", None) is not None:
        out["collision"] = _collision_list(robot.collision, lin)
    return out


def _num(x: float) -> float | None:
    """A finite number rounded to 12 decimals (no -0.0); None for ±inf."""
    return None if not math.isfinite(x) else float(round(x, 12)) + 0.0


def _collision_list(model: Any, lin: float) -> list[dict]:
    """The ``collision`` section of a collision model, lengths divided by ``lin``."""
    bodies = model.to_dicts()
    for body in bodies:
        for c in body["capsules"]:
            c.update(a=[_num(v / lin) for v in c["a"]], b=[_num(v / lin) for v in c["b"]],
                     radius=_num(c["radius"] / lin))
        for c in body["spheres"]:
            c.update(center=[_num(v / lin) for v in c["center"]],
                     radius=_num(c["radius"] / lin))
        for kind in ("capsules", "spheres"):
            if not body[kind]:
                del body[kind]
    return bodies


def _link_geometry_dict(lg: Any, ang: float, lin: float, mesh_base: Any, num: Any) -> dict:
    """One :class:`~serialkin.model.geometry.LinkGeometry` in robot-file form."""
    from serialkin.spatial import matrix_to_rpy

    def shape(s: Any) -> dict:
        g = s.geometry
        if isinstance(g, Box):
            d: dict[str, Any] = {"box": {"size": [num(v / lin) for v in g.size]}}
        elif isinstance(g, Sphere):
            d = {"sphere": {"radius": num(g.radius / lin)}}
        elif isinstance(g, Cylinder | Capsule):
            d = {"cylinder" if isinstance(g, Cylinder) else "capsule":
                 {"radius": num(g.radius / lin), "length": num(g.length / lin)}}
        elif isinstance(g, Mesh):
            name = g.filename
            if mesh_base is not None and os.path.isabs(name):
                name = os.path.relpath(name, mesh_base)
            d = {"mesh": {"file": name}}
            if g.scale != (1.0, 1.0, 1.0):
                d["mesh"]["scale"] = [num(v) for v in g.scale]
        T = s.origin
        if not np.allclose(T, np.eye(4), atol=1e-15):
            rpy = matrix_to_rpy(T[:3, :3], check=False) / ang
            d["origin"] = {"xyz": [num(v / lin) for v in T[:3, 3]], "rpy": [num(v) for v in rpy]}
        if s.name:
            d["name"] = s.name
        if s.material is not None:
            d["material"] = s.material
        if s.rgba is not None:
            d["rgba"] = list(s.rgba)
        return d

    out: dict[str, Any] = {"link": lg.link_name, "frame": lg.frame}
    for kind in ("visual", "collision"):
        shapes = getattr(lg, kind)
        if shapes:
            out[kind] = [shape(s) for s in shapes]
    return out


def save_robot_file(robot: Any, path: str | os.PathLike[str], *, angle_unit: str = "deg",
                    length_unit: str = "m") -> Path:
    """Write a DH robot to a robot file (YAML or JSON by suffix), atomically.

    The file is written to a temporary file in the same folder and renamed, so an
    interrupted save never leaves a truncated file. ``load_robot_file`` of the result
    gives the same kinematics.

    Returns:
        The path written.
    """
    from serialkin._io import write_text_atomic

    p = Path(path)
    if p.suffix.lower() not in ROBOT_FILE_SUFFIXES:
        raise RobotDefinitionError(
            f"{p}: unknown robot file type {p.suffix!r}; expected one of "
            f"{', '.join(ROBOT_FILE_SUFFIXES)}"
        )
    data = robot_to_dict(robot, angle_unit=angle_unit, length_unit=length_unit,
                         mesh_base=p.resolve().parent)
    write_text_atomic(p, _dump(data, p, "serialkin robot file"))
    return p


def _dump(data: dict, p: Path, title: str) -> str:
    """``data`` as JSON (``.json``) or YAML text with a ``# title`` line."""
    if p.suffix.lower() == ".json":
        return json.dumps(data, indent=2) + "\n"
    import yaml

    # The dumper quotes and escapes every name and free text: nothing a name holds
    # (newlines, ':', '#', quotes) can add a line or a key to the file. Non-ASCII is
    # escaped too (allow_unicode would write U+0085 raw, which reads back as a space).
    return f"# {title}\n" + yaml.safe_dump(data, sort_keys=False, default_flow_style=None)


# ------------------------------------------------------------------ capsule files
_CAPSULE_FIELDS = ("units", "source", "collision")


def collision_from_dict(data: object, origin: str = "<collision model>",
                        frames: int | None = None) -> Any:
    """A :class:`~serialkin.model.collision_model.CollisionModel` from a capsule-file mapping.

    A capsule file holds only a collision model, for robots that cannot be saved as robot
    files (a URDF robot) or to share capsules between files::

        units: {length: m}           # optional, m | cm | mm (default m)
        source: "fitted to ..."      # optional, free text
        collision:                   # as the collision section of a robot file
          - {name: link1, frame: 1, capsules: [{a: [0, 0, 0], b: [0, 0, 0.3], radius: 0.06}]}

    Args:
        data: the parsed mapping.
        origin: what to call it in errors (the file path).
        frames: the robot's joint count n; frames must lie in 0..n (default: not checked
            beyond >= 0, :meth:`Robot.with_collision` checks them).

    Raises:
        RobotDefinitionError: a missing, unknown or malformed field (named).
    """
    doc = Field(data, "", origin, RobotDefinitionError)
    doc.mapping(_CAPSULE_FIELDS, ("collision",),
                what=f"a mapping with fields {', '.join(_CAPSULE_FIELDS)}")
    unit = "m"
    if doc["units"].present:
        units = doc["units"].mapping({"length"}, what="a mapping {length: m|cm|mm}")
        unit = units["length"].string(choices=LENGTH_UNITS, default="m")
    source = doc["source"].string(default=f"capsule file {origin}", nonempty=False)
    n = MAX_JOINTS if frames is None else frames
    return _collision_field(doc["collision"], n, unit, source)


def load_collision_file(path: str | os.PathLike[str], robot: Any = None) -> Any:
    """Read a capsule file (YAML or JSON, :func:`collision_from_dict`).

    Args:
        path: the file.
        robot: if given, frames are checked against its frames 0..n.

    Returns:
        The :class:`~serialkin.model.collision_model.CollisionModel` (metres); attach it with
        ``robot.with_collision(model)``.

    Raises:
        RobotDefinitionError: unreadable file or a malformed field (named).
    """
    data = read_robot_data(path)
    return collision_from_dict(data, str(path), None if robot is None else robot.n)


def save_collision_file(model: Any, path: str | os.PathLike[str], *,
                        length_unit: str = "m") -> Path:
    """Write a collision model to a capsule file (YAML or JSON by suffix), atomically.

    Returns:
        The path written; :func:`load_collision_file` gives the same model.
    """
    from serialkin._checks import check_choice
    from serialkin._io import write_text_atomic

    if not isinstance(model, CollisionModel):
        raise InputTypeError(f"model must be a CollisionModel, got {type(model).__name__}")
    check_choice(length_unit, "length_unit", LENGTH_UNITS)
    p = Path(path)
    if p.suffix.lower() not in ROBOT_FILE_SUFFIXES:
        raise RobotDefinitionError(
            f"{p}: unknown capsule file type {p.suffix!r}; expected one of "
            f"{', '.join(ROBOT_FILE_SUFFIXES)}")
    data: dict[str, Any] = {"units": {"length": length_unit}}
    if model.source:
        data["source"] = model.source
    data["collision"] = _collision_list(model, LENGTH_UNITS[length_unit])
    write_text_atomic(p, _dump(data, p, "serialkin capsule file"))
    return p
