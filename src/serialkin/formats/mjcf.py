"""MJCF import: the serial chain, joint limits, sites and geometry of a MuJoCo model file.

Why a parser of our own (on :mod:`xml.etree.ElementTree`, as the URDF reader) and not the
``mujoco`` package: kinematics must work with ``pip install serialkin`` alone, and the
part of MJCF a kinematic chain needs (bodies, joints, sites, geoms, ``<default>``
classes, the ``<compiler>`` angle and Euler settings) is small and fully specified by
MuJoCo's XML reference. The ``mujoco`` package (a 20 MB binary, also needing a compile
of the whole physics model, meshes included) is only a test peer here: the tests check
this reader's poses against ``mujoco.mj_kinematics`` to 1e-10.

What is read (MuJoCo's semantics; everything else, e.g. ``<actuator>``, inertia,
physics options, is ignored):

* ``<compiler angle="degree|radian" eulerseq="xyz" autolimits meshdir assetdir>``:
  angles are in **degrees unless** ``angle="radian"`` (euler, axisangle, hinge ``range``
  and ``ref``); ``eulerseq`` letters are axes, lowercase = intrinsic (the rotated
  axes, ``R = R·R_i``), uppercase = extrinsic (the fixed axes, ``R = R_i·R``);
  ``coordinate="global"`` (removed from MuJoCo) is refused.
* ``<default>`` classes, nested (a class inherits its parent's values), for ``joint``,
  ``geom``, ``site``, ``mesh``, ``material``; an element takes the class of its
  ``class`` attribute, else the ``childclass`` of the nearest enclosing body or frame,
  else ``main``. An orientation given on the element replaces the class's orientation.
* Poses: ``pos`` and one of ``quat`` (w x y z, normalised), ``axisangle`` (axis, angle),
  ``euler``, ``xyaxes`` (x, then y made orthogonal to it), ``zaxis`` (the smallest
  rotation taking +z onto it); two of them on one element are refused, as MuJoCo does.
  ``<frame>`` elements compose their pose onto what they contain.
* ``<body>`` tree with ``hinge`` and ``slide`` joints: ``axis`` (default z, normalised),
  ``pos`` (the hinge axis passes through it: the body frame moves by
  ``Tr(p)·M(q − ref)·Tr(−p)``), ``ref`` (the body pose in the file is the pose at
  ``q = ref``), ``range`` with ``limited`` and the compiler's ``autolimits`` (default
  true: a range makes the joint limited; with ``autolimits="false"`` a range needs
  ``limited="true"``). Several joints in one body act one after the other, each about
  its own axis in the body frame. ``q`` is MuJoCo's ``qpos`` for these joints.
* ``<site>``: a site can be the tool frame (``tool_site=``).
* ``<geom>``: ``sphere``, ``capsule``, ``cylinder``, ``box`` (``size`` = radius,
  half-length, half-sizes, as MuJoCo) with ``fromto`` for the three elongated types, and
  ``mesh`` through ``<asset><mesh file scale>`` found in ``meshdir`` (relative to the
  model file's folder), else ``assetdir``, else the model's folder (a negative ``scale``,
  MuJoCo's mirroring, is kept as its magnitude: ``Mesh.scale`` is >= 0). A mesh geom is placed
  at its ``pos``/orientation with the file's vertices as written (MuJoCo re-centres a mesh
  on its inertia frame and moves the geom by the same amount, so what is drawn is the
  same). A geom's ``rgba`` other than MuJoCo's default grey overrides its material's
  colour. Planes, height fields, ellipsoids and SDFs are skipped. A geom with
  ``contype = conaffinity = 0`` is visual only; any other is a collision shape; a geom in
  the ``group`` 0, 1 or 2 (those MuJoCo shows by default) is also drawn.
* ``<include file>``: the children of the included ``<mujoco>`` are inserted in place
  (file relative to the main model's folder).

The chain: from ``base_body`` (default: the world) to ``end_body``. By default the end
is found by walking down from the base while exactly one child body carries moving
joints in its subtree, so a hand whose fingers branch off ends the arm (the fingers are
left out; choose one with ``end_body=``). Bodies without joints (welded) are merged into
the neighbouring transforms, as URDF fixed joints are. A body with a ``free`` joint
directly below the world (a floating robot) may start the chain: its free joint is
skipped and the base transform is that body's pose in the file. A ``ball`` joint, or a
free joint anywhere else, on the chain is refused (``NotSupportedError``); joints off
the chain are ignored.
"""

from __future__ import annotations

import difflib
import math
import os
import xml.etree.ElementTree as ET
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from serialkin._checks import short_repr
from serialkin._files import MAX_NUMBER, parse_xml, read_bytes
from serialkin.errors import (
    BudgetError,
    InputTypeError,
    NotSupportedError,
    RobotDefinitionError,
)
from serialkin.formats.xmlfile import parse_floats
from serialkin.model.geometry import Box, Capsule, Cylinder, LinkGeometry, Mesh, Shape, Sphere
from serialkin.model.joint import Joint
from serialkin.model.robot import Robot
from serialkin.spatial.rotations import axis_angle_to_matrix, quaternion_to_matrix

__all__ = ["robot_from_mjcf"]

_ORIENTATIONS = ("quat", "axisangle", "euler", "xyaxes", "zaxis")
_DEFAULTED = ("joint", "geom", "site", "mesh", "material")
_UNSUPPORTED_ELEMENTS = {"replicate", "attach", "composite", "flexcomp"}
_DEFAULT_RGBA = (0.5, 0.5, 0.5, 1.0)
#: Deepest nesting of ``<include>`` files.
MAX_INCLUDE_DEPTH = 16
#: Most ``<include>`` elements expanded in one model (4 files each including the next 4
#: times would expand 4¹² times).
MAX_INCLUDES = 1_000
#: Most elements of a model once its includes are expanded.
MAX_ELEMENTS = 2_000_000
#: Deepest nesting of elements (bodies in bodies): the reader walks bodies recursively.
MAX_ELEMENT_DEPTH = 300


# ------------------------------------------------------------------------------ maths
def _rot(axis: np.ndarray, angle: float) -> np.ndarray:
    """Rotation by ``angle`` [rad] about ``axis`` (normalised)."""
    return axis_angle_to_matrix(axis, angle, normalize=True)


def euler_to_matrix(angles: np.ndarray, seq: str) -> np.ndarray:
    """MJCF ``euler`` rotation: ``angles`` [rad] about the axes named by ``seq``.

    Each letter of ``seq`` (3 of ``xyzXYZ``) is an elementary rotation ``R_i``; a lowercase
    letter rotates about the current (moving) axis, ``R ← R·R_i``, an uppercase letter about
    the fixed axis, ``R ← R_i·R`` (MuJoCo's ``eulerseq``).
    """
    R = np.eye(3)
    for a, c in zip(angles, seq):
        Ri = _rot(np.eye(3)["xyz".index(c.lower())], float(a))
        R = R @ Ri if c.islower() else Ri @ R
    return R


def zaxis_to_matrix(z: np.ndarray) -> np.ndarray:
    """The smallest rotation taking +z onto the direction ``z`` (a half turn about x if −z)."""
    z = z / np.linalg.norm(z)
    axis = np.cross([0.0, 0.0, 1.0], z)
    s = float(np.linalg.norm(axis))
    if s < 1e-10:
        axis = np.array([1.0, 0.0, 0.0])
    return _rot(axis, math.atan2(s, float(z[2])))


def _transform(R: np.ndarray | None = None, p: np.ndarray | None = None) -> np.ndarray:
    T = np.eye(4)
    if R is not None:
        T[:3, :3] = R
    if p is not None:
        T[:3, 3] = p
    return T


# --------------------------------------------------------------------------- the model
@dataclass
class _MJoint:
    name: str
    type: str  # hinge, slide, ball, free
    pos: np.ndarray
    axis: np.ndarray
    qlim: tuple[float, float]
    ref: float


@dataclass
class _Body:
    name: str
    index: int
    parent: int
    T: np.ndarray  # pose in the parent body frame (at q = ref)
    joints: list[_MJoint] = field(default_factory=list)
    visual: list[Shape] = field(default_factory=list)
    collision: list[Shape] = field(default_factory=list)
    sites: dict[str, np.ndarray] = field(default_factory=dict)
    children: list[int] = field(default_factory=list)

    @property
    def moving(self) -> bool:
        return bool(self.joints)


class _Reader:
    """Reads one MJCF document (includes expanded) into a list of :class:`_Body`."""

    def __init__(self, root: ET.Element, source: str, folder: Path | None,
                 resolve_meshes: bool) -> None:
        self.source = source
        self.folder = folder
        self.resolve_meshes = resolve_meshes
        self.angle = math.pi / 180.0  # radians per unit of angle in the file (degree default)
        self.eulerseq = "xyz"
        self.autolimits = True
        self.meshdir: str | None = None
        self.assetdir: str | None = None
        for el in root.iter("compiler"):
            self._compiler(el)
        self.classes: dict[str, dict[str, dict[str, str]]] = {
            "main": {tag: {} for tag in _DEFAULTED}}
        for el in root.findall("default"):
            self._default(el, self.classes["main"], top=True)
        self.meshes: dict[str, tuple[str, np.ndarray] | None] = {}
        self.materials: dict[str, tuple[float, ...] | None] = {}
        for asset in root.findall("asset"):
            self._assets(asset)
        self.bodies: list[_Body] = [_Body("world", 0, -1, np.eye(4))]
        self.sites: dict[str, int] = {}
        for wb in root.findall("worldbody"):
            self._contents(wb, self.bodies[0], np.eye(4), "main")

    # ------------------------------------------------------------------ small readers
    def where(self, el: ET.Element, what: str | None = None) -> str:
        """``file: <tag name='x'>`` for messages."""
        name = el.get("name") or el.get("class")
        label = f"<{el.tag}" + (f" {short_repr(name)}" if name else "") + ">"
        return f"{self.source}: {label}" + (f" attribute {what!r}" if what else "")

    def numbers(self, text: str, count: int, el: ET.Element, attr: str) -> np.ndarray:
        return parse_floats(text, count, (), self.where(el, attr), MAX_NUMBER)

    def _compiler(self, el: ET.Element) -> None:
        angle = el.get("angle")
        if angle is not None:
            if angle not in ("degree", "radian"):
                raise RobotDefinitionError(
                    f"{self.where(el, 'angle')}: expected 'degree' or 'radian', got "
                    f"{short_repr(angle)}")
            self.angle = 1.0 if angle == "radian" else math.pi / 180.0
        seq = el.get("eulerseq")
        if seq is not None:
            if len(seq) != 3 or any(c not in "xyzXYZ" for c in seq):
                raise RobotDefinitionError(
                    f"{self.where(el, 'eulerseq')}: expected 3 letters of xyzXYZ, got "
                    f"{short_repr(seq)}")
            self.eulerseq = seq
        auto = el.get("autolimits")
        if auto is not None:
            self.autolimits = self._bool(auto, el, "autolimits")
        if el.get("coordinate") not in (None, "local"):
            raise NotSupportedError(
                f"{self.where(el, 'coordinate')}: only 'local' coordinates are supported "
                f"(MuJoCo itself removed 'global'), got {short_repr(el.get('coordinate'))}")
        self.meshdir = el.get("meshdir", self.meshdir)
        self.assetdir = el.get("assetdir", self.assetdir)

    def _bool(self, text: str, el: ET.Element, attr: str) -> bool:
        if text not in ("true", "false"):
            raise RobotDefinitionError(
                f"{self.where(el, attr)}: expected 'true' or 'false', got {short_repr(text)}")
        return text == "true"

    def _default(self, el: ET.Element, parent: dict[str, dict[str, str]], top: bool) -> None:
        """Read a ``<default>`` class (nested ones inherit) into :attr:`classes`."""
        if top and el.get("class") in (None, "main"):
            values = parent
        else:
            name = el.get("class")
            if not name:
                raise RobotDefinitionError(f"{self.source}: a nested <default> has no class")
            if name in self.classes:
                raise RobotDefinitionError(
                    f"{self.source}: <default class={name!r}> is defined twice")
            values = {tag: dict(attrs) for tag, attrs in parent.items()}
            self.classes[name] = values
        for sub in el:
            if sub.tag == "default":
                self._default(sub, values, top=False)
            elif sub.tag in values:
                attrs = dict(sub.attrib)
                if any(k in attrs for k in _ORIENTATIONS):
                    values[sub.tag] = {k: v for k, v in values[sub.tag].items()
                                       if k not in _ORIENTATIONS}
                values[sub.tag].update(attrs)

    def attrs(self, el: ET.Element, cls: str) -> dict[str, str]:
        """The element's attributes over those of its default class."""
        name = el.get("class") or cls
        if name not in self.classes:
            near = difflib.get_close_matches(name, list(self.classes), n=3)
            raise RobotDefinitionError(
                f"{self.where(el, 'class')}: unknown default class {short_repr(name)}"
                + (f"; did you mean {', '.join(map(repr, near))}?" if near else
                   f"; the file defines {', '.join(sorted(self.classes))}"))
        values = dict(self.classes[name].get(el.tag, {}))
        if any(k in el.attrib for k in _ORIENTATIONS) or "fromto" in el.attrib:
            values = {k: v for k, v in values.items() if k not in _ORIENTATIONS}
        values.update(el.attrib)
        return values

    def pose(self, el: ET.Element, a: dict[str, str]) -> np.ndarray:
        """The element's ``pos`` and orientation as a (4, 4) transform."""
        given = [k for k in _ORIENTATIONS if k in a]
        if len(given) > 1:
            raise RobotDefinitionError(
                f"{self.where(el)}: has {' and '.join(given)}; give at most one orientation")
        p = self.numbers(a["pos"], 3, el, "pos") if "pos" in a else None
        R = None
        if given:
            kind = given[0]
            text = a[kind]
            if kind == "quat":
                q = self.numbers(text, 4, el, kind)
                if np.linalg.norm(q) < 1e-12:
                    raise RobotDefinitionError(f"{self.where(el, kind)}: the quaternion is zero")
                R = quaternion_to_matrix(q, normalize=True)
            elif kind == "axisangle":
                v = self.numbers(text, 4, el, kind)
                if np.linalg.norm(v[:3]) < 1e-12:
                    raise RobotDefinitionError(f"{self.where(el, kind)}: the axis is zero")
                R = _rot(v[:3], v[3] * self.angle)
            elif kind == "euler":
                R = euler_to_matrix(self.numbers(text, 3, el, kind) * self.angle, self.eulerseq)
            elif kind == "xyaxes":
                v = self.numbers(text, 6, el, kind)
                x = v[:3]
                nx = np.linalg.norm(x)
                y = v[3:] - x * (x @ v[3:]) / (nx * nx if nx > 0 else 1.0)
                ny = np.linalg.norm(y)
                if nx < 1e-12 or ny < 1e-12:
                    raise RobotDefinitionError(
                        f"{self.where(el, kind)}: x is zero or y is parallel to x")
                x, y = x / nx, y / ny
                R = np.column_stack([x, y, np.cross(x, y)])
            else:
                z = self.numbers(text, 3, el, kind)
                if np.linalg.norm(z) < 1e-12:
                    raise RobotDefinitionError(f"{self.where(el, kind)}: the axis is zero")
                R = zaxis_to_matrix(z)
        return _transform(R, p)

    # ------------------------------------------------------------------ assets
    def _assets(self, asset: ET.Element) -> None:
        for el in asset:
            if el.tag == "mesh":
                a = self.attrs(el, "main")
                file = a.get("file")
                name = a.get("name") or (Path(file).stem if file else None)
                if not name:
                    raise RobotDefinitionError(f"{self.where(el)}: a mesh needs a name or a file")
                if name in self.meshes:
                    raise RobotDefinitionError(
                        f"{self.where(el)}: mesh {short_repr(name)} is defined twice")
                scale = self.numbers(a["scale"], 3, el, "scale") if "scale" in a else \
                    np.ones(3)
                self.meshes[name] = (file, np.abs(scale)) if file else None
            elif el.tag == "material":
                a = self.attrs(el, "main")
                if a.get("name"):
                    self.materials[a["name"]] = self._rgba(a, el)

    def _mesh_path(self, file: str) -> str:
        """``meshdir``/``assetdir``/model folder joined with ``file`` (absolute when found)."""
        folder = self.meshdir if self.meshdir is not None else self.assetdir or ""
        path = Path(file) if Path(file).is_absolute() else \
            (self.folder or Path.cwd()) / folder / file
        try:
            if path.is_file():
                return str(path.resolve())
        except (OSError, ValueError):  # a name too long: not a file
            pass
        if self.resolve_meshes:
            raise RobotDefinitionError(
                f"mesh file {short_repr(file, 120)} does not resolve to "
                f"a file; looked for {short_repr(str(path), 160)}")
        return str(path)

    def _rgba(self, a: dict[str, str], el: ET.Element) -> tuple[float, ...] | None:
        if "rgba" not in a:
            return None
        rgba = self.numbers(a["rgba"], 4, el, "rgba")
        if not all(0.0 <= c <= 1.0 for c in rgba):
            raise RobotDefinitionError(
                f"{self.where(el, 'rgba')}: expected 4 numbers in [0, 1], got "
                f"{short_repr(a['rgba'])}")
        return tuple(float(c) for c in rgba)

    # ------------------------------------------------------------------ bodies
    def _contents(self, parent_el: ET.Element, body: _Body, T: np.ndarray, cls: str) -> None:
        """Read the joints, geoms, sites, frames and child bodies of one body (or frame).

        ``T`` is the pose of ``parent_el``'s frame in ``body``'s frame (frames compose).
        """
        for el in parent_el:
            tag = el.tag
            if tag in _UNSUPPORTED_ELEMENTS:
                raise NotSupportedError(f"{self.where(el)}: <{tag}> is not supported")
            if tag == "body":
                self._check_class(el, el.get("childclass"))
                child = _Body(el.get("name") or f"body{len(self.bodies)}", len(self.bodies),
                              body.index, T @ self.pose(el, el.attrib))
                self.bodies.append(child)
                body.children.append(child.index)
                self._contents(el, child, np.eye(4), el.get("childclass") or cls)
            elif tag == "frame":
                self._check_class(el, el.get("childclass"))
                self._contents(el, body, T @ self.pose(el, el.attrib),
                               el.get("childclass") or cls)
            elif tag in ("joint", "freejoint"):
                body.joints.append(self._joint(el, T, cls))
            elif tag == "geom":
                self._geom(el, body, T, cls)
            elif tag == "site":
                a = self.attrs(el, cls)
                name = a.get("name")
                if name:
                    if name in self.sites:
                        raise RobotDefinitionError(
                            f"{self.where(el)}: site {short_repr(name)} is defined twice")
                    self.sites[name] = body.index
                    body.sites[name] = T @ self.pose(el, a)

    def _check_class(self, el: ET.Element, name: str | None) -> None:
        if name is not None and name not in self.classes:
            near = difflib.get_close_matches(name, list(self.classes), n=3)
            raise RobotDefinitionError(
                f"{self.where(el, 'childclass')}: unknown default class {short_repr(name)}"
                + (f"; did you mean {', '.join(map(repr, near))}?" if near else ""))

    def _joint(self, el: ET.Element, T: np.ndarray, cls: str) -> _MJoint:
        if el.tag == "freejoint":
            return _MJoint(el.get("name") or "", "free", np.zeros(3), np.array([0.0, 0, 1]),
                           (-np.inf, np.inf), 0.0)
        a = self.attrs(el, cls)
        jtype = a.get("type", "hinge")
        if jtype not in ("hinge", "slide", "ball", "free"):
            raise RobotDefinitionError(
                f"{self.where(el, 'type')}: unknown joint type {short_repr(jtype)}; expected "
                "hinge, slide, ball or free")
        pos = self.numbers(a["pos"], 3, el, "pos") if "pos" in a else np.zeros(3)
        axis = self.numbers(a["axis"], 3, el, "axis") if "axis" in a else np.array([0.0, 0, 1])
        if jtype in ("hinge", "slide") and np.linalg.norm(axis) < 1e-12:
            raise RobotDefinitionError(f"{self.where(el, 'axis')}: the axis is zero")
        unit = self.angle if jtype == "hinge" else 1.0
        ref = float(self.numbers(a["ref"], 1, el, "ref")[0]) * unit if "ref" in a else 0.0
        qlim = (-np.inf, np.inf)
        limited = a.get("limited", "auto")
        if limited not in ("true", "false", "auto"):
            raise RobotDefinitionError(
                f"{self.where(el, 'limited')}: expected true, false or auto, got "
                f"{short_repr(limited)}")
        if limited == "auto" and "range" in a and not self.autolimits:
            raise RobotDefinitionError(
                f"{self.where(el, 'range')}: a range without limited=\"true\" while the "
                "compiler has autolimits=\"false\"")
        if limited == "true" or (limited == "auto" and "range" in a):
            rng = self.numbers(a.get("range", "0 0"), 2, el, "range") * unit
            if jtype in ("hinge", "slide") and not rng[0] < rng[1]:
                raise RobotDefinitionError(
                    f"{self.where(el, 'range')}: a limited joint needs range lower < upper, "
                    f"got {short_repr(a.get('range', '0 0 (default)'))}")
            qlim = (float(rng[0]), float(rng[1]))
        return _MJoint(a.get("name") or "", jtype, T[:3, :3] @ pos + T[:3, 3],
                       T[:3, :3] @ axis, qlim, ref)

    def _geom(self, el: ET.Element, body: _Body, T: np.ndarray, cls: str) -> None:
        a = self.attrs(el, cls)
        gtype = a.get("type", "sphere")
        where = self.where(el)
        known = ("plane", "hfield", "sphere", "capsule", "ellipsoid", "cylinder", "box", "mesh",
                 "sdf")
        if gtype not in known:
            raise RobotDefinitionError(
                f"{self.where(el, 'type')}: unknown geom type {short_repr(gtype)}; expected one "
                f"of {', '.join(known)}")
        size = np.zeros(3)
        if "size" in a:
            parts = a["size"].split()
            n = min(max(len(parts), 1), 3)
            size[:n] = self.numbers(a["size"], n, el, "size")
        pose = self.pose(el, a)
        half = size[1]
        if "fromto" in a and gtype in ("capsule", "cylinder", "box", "ellipsoid"):
            ft = self.numbers(a["fromto"], 6, el, "fromto")
            d = ft[3:] - ft[:3]
            half = float(np.linalg.norm(d)) / 2.0
            if half < 1e-12:
                raise RobotDefinitionError(f"{self.where(el, 'fromto')}: the two ends coincide")
            # MuJoCo turns +z onto from − to (the shape is symmetric about its centre)
            pose = _transform(zaxis_to_matrix(-d), (ft[:3] + ft[3:]) / 2.0)
        try:
            if gtype == "sphere":
                geometry = Sphere(size[0])
            elif gtype == "capsule":
                geometry = Capsule(size[0], 2.0 * half)
            elif gtype == "cylinder":
                geometry = Cylinder(size[0], 2.0 * half)
            elif gtype == "box":
                geometry = Box(tuple(2.0 * np.array(
                    [size[0], size[1], half if "fromto" in a else size[2]])))
            elif gtype == "mesh":
                mesh = a.get("mesh")
                if mesh not in self.meshes:
                    raise RobotDefinitionError(
                        f"mesh {short_repr(mesh)} is not an <asset><mesh>"
                        + (f" (known: {', '.join(sorted(self.meshes)[:10])})" if self.meshes
                           else ""))
                if self.meshes[mesh] is None:
                    return  # a mesh given by its vertices in the file: not a file to name
                file, scale = self.meshes[mesh]
                geometry = Mesh(self._mesh_path(file), tuple(scale))
            else:
                return  # plane, hfield, ellipsoid, sdf: not represented
        except RobotDefinitionError as exc:
            raise RobotDefinitionError(f"{where}: {exc}") from None
        rgba = self._rgba(a, el)
        material = a.get("material")
        if material is not None and rgba in (None, _DEFAULT_RGBA):
            rgba = self.materials.get(material)  # MuJoCo: a non-default rgba overrides it
        contype = self.numbers(a.get("contype", "1"), 1, el, "contype")[0]
        conaffinity = self.numbers(a.get("conaffinity", "1"), 1, el, "conaffinity")[0]
        group = self.numbers(a.get("group", "0"), 1, el, "group")[0]
        shape = Shape(geometry, T @ pose, name=a.get("name") or "", material=material,
                      rgba=rgba)
        if contype != 0 or conaffinity != 0:
            body.collision.append(shape)
        if group in (0, 1, 2):
            body.visual.append(shape)


# ------------------------------------------------------------------------------ files
def _depth_checked(root: ET.Element, source: str) -> ET.Element:
    """``root``, or BudgetError when its elements nest deeper than :data:`MAX_ELEMENT_DEPTH`."""
    todo = [(root, 1)]
    while todo:
        el, depth = todo.pop()
        if depth > MAX_ELEMENT_DEPTH:
            raise BudgetError(f"{source}: elements nest more than {MAX_ELEMENT_DEPTH} levels "
                              "deep (bodies in bodies); serialkin reads at most that")
        todo.extend((child, depth + 1) for child in el)
    return root


def _read_file(path: Path) -> ET.Element:
    try:
        exists = path.exists()
    except OSError as exc:  # a name longer than the system allows, a loop of links
        raise RobotDefinitionError(f"MJCF file {short_repr(str(path), 120)}: "
                                   f"{exc.strerror or exc}") from None
    if not exists:
        raise RobotDefinitionError(f"MJCF file {short_repr(str(path), 120)} does not exist")
    data = read_bytes(path, what="MJCF file", error=RobotDefinitionError)
    return parse_xml(data, str(path), error=RobotDefinitionError)


class _Includes:
    """The budget of one model's include expansion: includes and elements so far."""

    def __init__(self, folder: Path) -> None:
        self.folder = folder.resolve()
        self.includes = 0
        self.elements = 0

    def inside(self, path: Path, source: str, file: str) -> None:
        """Raise unless ``path`` (links followed) lies inside the model's folder."""
        if path != self.folder and self.folder not in path.parents:
            raise RobotDefinitionError(
                f"{source}: <include file={short_repr(file, 120)}> leaves the model's folder "
                f"{short_repr(str(self.folder), 120)}; includes are read only inside it")

    def count(self, sub: ET.Element, source: str) -> None:
        self.includes += 1
        if self.includes > MAX_INCLUDES:
            raise BudgetError(f"{source}: more than {MAX_INCLUDES} <include> expansions (files "
                              "that include each other many times)")
        self.elements += sum(1 for _ in sub.iter())
        if self.elements > MAX_ELEMENTS:
            raise BudgetError(f"{source}: the includes expand to more than {MAX_ELEMENTS} "
                              "elements")


def _expand_includes(el: ET.Element, budget: _Includes, source: str,
                     stack: tuple[str, ...]) -> None:
    """Replace every ``<include file>`` below ``el`` by the children of that file's root.

    The elements are walked with a stack (any depth); only the include files recurse,
    at most :data:`MAX_INCLUDE_DEPTH` deep.
    """
    todo = [el]
    while todo:
        node = todo.pop()
        k = 0
        while k < len(node):
            child = node[k]
            if child.tag != "include":
                todo.append(child)
                k += 1
                continue
            file = child.get("file")
            if not file:
                raise RobotDefinitionError(f"{source}: an <include> has no file attribute")
            try:
                path = (budget.folder / file).resolve()
            except (OSError, RuntimeError) as exc:
                raise RobotDefinitionError(f"{source}: <include file={short_repr(file, 120)}>"
                                           f": {exc}") from None
            budget.inside(path, source, file)
            if str(path) in stack or len(stack) >= MAX_INCLUDE_DEPTH:
                raise RobotDefinitionError(
                    f"{source}: <include file={short_repr(file, 120)}> includes itself or "
                    f"nests more than {MAX_INCLUDE_DEPTH} files deep")
            sub = _read_file(path)
            if sub.tag != "mujoco":
                raise RobotDefinitionError(
                    f"{path}: an included file's root must be <mujoco>, got <{sub.tag}>")
            budget.count(sub, source)
            _expand_includes(sub, budget, str(path), (*stack, str(path)))
            node.remove(child)
            for j, item in enumerate(list(sub)):
                node.insert(k + j, item)
            k += len(sub)


# --------------------------------------------------------------------------- the chain
def _pick_end(bodies: list[_Body], base: int, source: str) -> int:
    """Walk down from ``base`` while exactly one child's subtree has joints.

    Raises when the walk stops at a branch before any hinge or slide joint (nothing to
    choose the arm by).
    """
    def moves(i: int) -> bool:
        return bodies[i].moving or any(moves(c) for c in bodies[i].children)

    b, seen_joint = base, False
    while True:
        going = [c for c in bodies[b].children if moves(c)]
        if len(going) != 1:
            if len(going) > 1 and not seen_joint:
                raise RobotDefinitionError(
                    f"{source}: the tree below {short_repr(bodies[b].name)} branches into "
                    f"{', '.join(bodies[c].name for c in going[:10])}; pass end_body= (or "
                    "tool_site=) to choose the chain")
            return b
        b = going[0]
        seen_joint = seen_joint or any(j.type in ("hinge", "slide") for j in bodies[b].joints)


def _find_body(bodies: list[_Body], name: str, role: str, source: str) -> int:
    for b in bodies:
        if b.name == name:
            return b.index
    near = difflib.get_close_matches(name, [b.name for b in bodies], n=3)
    raise RobotDefinitionError(
        f"{source}: {role} {short_repr(name)} is not a body of the model"
        + (f"; did you mean {', '.join(map(repr, near))}?" if near else ""))


def robot_from_mjcf(path_or_string: str | os.PathLike[str], base_body: str | None = None,
                    end_body: str | None = None, *, tool_site: str | None = None,
                    resolve_meshes: bool = False) -> Robot:
    """Build a :class:`~serialkin.Robot` from the serial chain of an MJCF (MuJoCo) model.

    The body frames of MuJoCo are the link frames: ``robot.fk_all(q)[i]`` is the pose of
    the body moved by joint *i* (MuJoCo's ``xpos``/``xmat`` at ``qpos = q``), and
    ``robot.fk(q)`` the end body's pose, or the pose of ``tool_site`` (``site_xpos``,
    ``site_xmat``). Joint *i* moves the body frame by ``Tr(p)·M(q − ref)·Tr(−p)`` with
    ``M`` a rotation about (hinge) or a translation along (slide) the joint axis ``a``
    through the joint position ``p``, both in the body frame.

    Args:
        path_or_string: an MJCF file path, or the XML text itself.
        base_body: body whose frame is the robot's base (default: the world; a floating
            robot's free joint below the world is skipped, see the module docstring).
        end_body: last body of the chain (default: the tip of the unbranched chain, or the
            body of ``tool_site``).
        tool_site: a site on the end body (or a body welded to it) used as the tool frame.
        resolve_meshes: if true, a mesh file that does not exist is an error; otherwise its
            path is kept as written (joined with ``meshdir``).

    Returns:
        Robot with one joint per hinge/slide joint of the chain (names kept, ``range`` as
        limits, ``q = qpos``), ``link_names`` set to the body names, and ``geometry``: one
        :class:`~serialkin.model.geometry.LinkGeometry` per body of the chain or welded
        to it.

    Raises:
        RobotDefinitionError: malformed XML or number (naming the element and attribute),
            an unknown default class, a missing end body or site, an end body not below the
            base, no moving joint on the chain, two orientations on one element, an
            unresolved mesh with ``resolve_meshes``.
        NotSupportedError: a ball joint or a free joint (other than a floating base's) on
            the chain; ``<replicate>``, ``<attach>``, ``<composite>``, ``<flexcomp>``.
    """
    _check_names(base_body=base_body, end_body=end_body, tool_site=tool_site)
    root, source, reader = _read_model(path_or_string, resolve_meshes)
    bodies = reader.bodies
    base = 0 if base_body is None else _find_body(bodies, base_body, "base_body", source)
    end = _end_body(reader, base, end_body, tool_site, source)
    path_ids, base_T = _chain_path(bodies, base, end, source)
    joints, link_names, places = _chain_joints(bodies, path_ids, source)
    if not joints:
        raise RobotDefinitionError(
            f"{source}: no hinge or slide joint between {short_repr(bodies[path_ids[0]].name)} "
            f"and {short_repr(bodies[end].name)}")
    _weld(bodies, places)
    tool = _tool_pose(reader, places, end, len(joints), tool_site, source)
    name = root.get("model") or "mjcf_robot"
    geometry = tuple(
        LinkGeometry(bodies[b].name, frame,
                     tuple(_posed(s, T) for s in bodies[b].visual),
                     tuple(_posed(s, T) for s in bodies[b].collision))
        for b, (frame, T) in sorted(places.items()))
    return Robot(joints, base=base_T, tool=tool, name=name,
                 source=f"MJCF {source} ({bodies[path_ids[0]].name} -> {bodies[end].name}"
                        + (f", site {tool_site}" if tool_site else "") + ")",
                 link_names=tuple(link_names), geometry=geometry)


def _check_names(**names: object) -> None:
    """Raise InputTypeError for a body or site name (keyword: its argument) not a str or None."""
    for name, value in names.items():
        if value is not None and not isinstance(value, str):
            raise InputTypeError(f"{name} must be a body or site name (str) or None, got "
                                 f"{type(value).__name__} {short_repr(value)}")


def _read_model(path_or_string: str | os.PathLike[str],
                resolve_meshes: bool) -> tuple[ET.Element, str, _Reader]:
    """The ``<mujoco>`` root (includes expanded), the source label and its bodies' reader."""
    text = os.fspath(path_or_string)
    if isinstance(text, bytes):
        text = text.decode()
    if text.lstrip().startswith("<"):
        source, folder = "<string>", None
        root = parse_xml(text, source, error=RobotDefinitionError)
    else:
        path = Path(text)
        source, folder = str(path), path.resolve().parent
        root = _read_file(path)
    if root.tag != "mujoco":
        raise RobotDefinitionError(
            f"{source}: the root element must be <mujoco>, got <{root.tag}>")
    # the expansion walks elements without recursion; the reader then recurses into
    # bodies, so the depth is checked once, on the whole expanded model
    _expand_includes(root, _Includes(folder or Path.cwd()), source, (source,))
    _depth_checked(root, source)
    return root, source, _Reader(root, source, folder, resolve_meshes)


def _end_body(reader: _Reader, base: int, end_body: str | None, tool_site: str | None,
              source: str) -> int:
    """The chain's last body: ``end_body``, else the body of ``tool_site``, else the tip."""
    if tool_site is not None and tool_site not in reader.sites:
        near = difflib.get_close_matches(tool_site, list(reader.sites), n=3)
        raise RobotDefinitionError(
            f"{source}: tool_site {short_repr(tool_site)} is not a named site of the model"
            + (f"; did you mean {', '.join(map(repr, near))}?" if near else ""))
    if end_body is not None:
        return _find_body(reader.bodies, end_body, "end_body", source)
    if tool_site is not None:
        return reader.sites[tool_site]
    return _pick_end(reader.bodies, base, source)


def _tool_pose(reader: _Reader, places: dict[int, tuple[int, np.ndarray]], end: int, n: int,
               tool_site: str | None, source: str) -> np.ndarray:
    """The tool (4, 4) in the last joint's frame: the end body's pose, or ``tool_site``'s.

    ``places`` holds every chain or welded body's (frame, pose in it); ``n`` is the number
    of joints (the last frame).
    """
    bodies = reader.bodies
    tool = places[end][1]
    if tool_site is not None:
        sb = reader.sites[tool_site]
        if sb not in places or places[sb][0] != n:
            raise RobotDefinitionError(
                f"{source}: tool_site {short_repr(tool_site)} is on body "
                f"{short_repr(bodies[sb].name)}, which is not fixed to the end body "
                f"{short_repr(bodies[end].name)}")
        tool = places[sb][1] @ bodies[sb].sites[tool_site]
    return tool


def _chain_path(bodies: list[_Body], base: int, end: int, source: str
                ) -> tuple[list[int], np.ndarray]:
    """The bodies from ``base`` to ``end`` and the base pose (a floating base's is skipped).

    A free joint on the body directly below the world is a floating base: that body's pose
    in the file becomes the robot's base, and the chain starts at it.
    """
    path_ids = [end]
    while path_ids[-1] != base:
        parent = bodies[path_ids[-1]].parent
        if parent < 0:
            raise RobotDefinitionError(
                f"{source}: end body {short_repr(bodies[end].name)} is not below base body "
                f"{short_repr(bodies[base].name)}")
        path_ids.append(parent)
    path_ids.reverse()
    base_T = np.eye(4)
    if base == 0 and len(path_ids) > 1 \
            and any(j.type == "free" for j in bodies[path_ids[1]].joints):
        first = bodies[path_ids[1]]
        if len(first.joints) != 1:
            raise RobotDefinitionError(
                f"{source}: body {short_repr(first.name)} has a free joint and other joints")
        base_T = first.T  # a floating base: its pose in the file
        path_ids = path_ids[1:]
    return path_ids, base_T


def _chain_joints(bodies: list[_Body], path_ids: list[int], source: str
                  ) -> tuple[list[Joint], list[str], dict[int, tuple[int, np.ndarray]]]:
    """The chain's joints, its link names, and each chain body's (frame, pose in it).

    Joint i moves the body frame by ``Tr(p)·M(q − ref)·Tr(−p)`` (module docstring): the
    body's pose and what is left of the previous body's go into the joint's origin.
    """
    joints: list[Joint] = []
    link_names = [bodies[path_ids[0]].name]
    places: dict[int, tuple[int, np.ndarray]] = {path_ids[0]: (0, np.eye(4))}
    pending = np.eye(4)
    for b in path_ids[1:]:
        body = bodies[b]
        pending = pending @ body.T
        for k, j in enumerate(body.joints):
            label = f"joint {short_repr(j.name)}" if j.name else f"a joint of body {body.name!r}"
            if j.type in ("ball", "free"):
                raise NotSupportedError(
                    f"{source}: {label} on the chain (body {short_repr(body.name)}) is a "
                    f"{j.type} joint; only hinge and slide joints are supported"
                    + (" (a free joint only on the floating base directly below the world)"
                       if j.type == "free" else ""))
            jtype = "R" if j.type == "hinge" else "P"
            joints.append(Joint(axis=j.axis, type=jtype, origin=pending @ _transform(p=j.pos),
                                post=_transform(p=-j.pos), offset=-j.ref, qlim=j.qlim,
                                name=j.name))
            pending = np.eye(4)
            last = k == len(body.joints) - 1
            link_names.append(body.name if last else f"{body.name}#{k + 1}")
        places[b] = (len(joints), pending)
    return joints, link_names, places


def _weld(bodies: list[_Body], places: dict[int, tuple[int, np.ndarray]]) -> None:
    """Add to ``places`` the bodies welded (no joints) to a chain body: they share its frame."""
    todo = list(places)
    while todo:
        b = todo.pop()
        frame, T = places[b]
        for c in bodies[b].children:
            if c not in places and not bodies[c].joints:
                places[c] = (frame, T @ bodies[c].T)
                todo.append(c)


def _posed(shape: Shape, T: np.ndarray) -> Shape:
    return Shape(shape.geometry, T @ shape.origin, name=shape.name, material=shape.material,
                 rgba=shape.rgba)
