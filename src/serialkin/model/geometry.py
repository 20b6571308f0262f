"""Shapes: the one vocabulary of link geometry, collision scenes and obstacles (metres).

Every shape is described in one frame, *its frame*: a chain frame for link geometry (then
placed in that frame by :attr:`Shape.origin`), the world frame for a collision scene
(:mod:`serialkin.collision`) and for the obstacles of the obstacle-avoidance tasks
(:mod:`serialkin.redundancy`, :mod:`serialkin.diffik`). Sizes come first, positionally and
in URDF's order; the placement in the frame and the obstacle attributes are keywords:

* :class:`Sphere` ``(radius, *, center)`` — the points within ``radius`` of ``center``;
* :class:`Box` ``(size, *, center, rotation)`` — edge lengths ``size`` along the box axes;
* :class:`Cylinder` ``(radius, length, *, center, rotation)`` — axis along the third box
  axis, ``length`` its height (``math.inf``: an infinite cylinder);
* :class:`Capsule` ``(radius, length)`` or ``(radius, *, a, b)`` — the points within
  ``radius`` of the segment from ``a`` to ``b``; ``length`` puts the ends at
  ``z = ±length/2`` (the total extent is ``length + 2 radius``);
* :class:`HalfSpace` ``(normal, offset)`` — the solid ``{x : normalᵀ x ≤ offset}``;
* :class:`Mesh` ``(filename, scale)`` — a mesh file, named here and never loaded; link
  geometry only, placed by :attr:`Shape.origin`.

Placement: ``center`` (3,) [m] is a point of the frame; ``rotation`` (3, 3) holds the
shape's own axes as columns (a box's edges are along them, a cylinder's axis is the third
column); a capsule is placed by the ends ``a``, ``b`` (3,) [m] of its segment. The
defaults put a shape at the frame's origin along its axes (URDF's convention: centred, a
cylinder's and a capsule's axis along z). ``pose`` (4, 4) is the placement of a bounded
shape as one transform. The vertical cylinder through the point (x, y) of the xy plane (a
circle of a planar scene) is ``Cylinder(r, math.inf, center=[x, y, 0.0])``.

Every solid also carries ``name`` (a label) and ``influence`` [m]: the distance from its
surface within which an obstacle-avoidance task acts on it (read by the obstacle tasks of
:mod:`serialkin.redundancy` and :mod:`serialkin.diffik`, ignored by collision queries and
by link geometry).

Who accepts what: link geometry (:class:`Shape`) the bounded shapes at their frame's origin
and meshes; collision scenes spheres, capsules, boxes, half-spaces and infinite cylinders
along z; the obstacle tasks spheres, capsules and infinite cylinders along z. Collision and
redundancy pack them into their own kernel arrays
(:func:`serialkin.collision.shapes.encode_scene`,
:func:`serialkin.redundancy.obstacles.encode_obstacles`).

A :class:`LinkGeometry` holds the shapes of one named part (a URDF ``<link>``) fixed to
one *frame* of the compiled chain: index ``0..n`` of :meth:`Robot.fk_all` (0 = base,
i = after joint i). A URDF link merged into a chain frame through fixed joints (a hand on
the flange) keeps its own name and its frame index; its shapes' origins are then
expressed in that chain frame (the fixed transforms composed in). The world pose of a
shape at joint values ``q`` is therefore ``fk_all(q)[frame] @ shape.origin``.

Errors of every constructor: :class:`~serialkin.errors.RobotDefinitionError` (an
``InputError``) for a negative or non-finite size; ``InputError`` or ``InputTypeError``
for a point of the wrong shape or not finite, a matrix that is not a rotation, a negative
``influence`` or a name that is not a string. Each message names the field.
"""

from __future__ import annotations

import math
import warnings
from dataclasses import KW_ONLY, dataclass, field, fields
from typing import ClassVar

import numpy as np

from serialkin._checks import as_vector, check_positive, check_real, check_rotation, short_repr
from serialkin.errors import InputError, InputTypeError, NotSupportedError, RobotDefinitionError
from serialkin.model.joint import check_fixed_transform

__all__ = ["DEFAULT_INFLUENCE", "Box", "Capsule", "Cylinder", "Geometry", "HalfSpace",
           "LinkGeometry", "Mesh", "Shape", "Solid", "Sphere"]

#: Default ``influence`` of a solid [m]: the obstacle tasks act within 2 cm of its surface.
DEFAULT_INFLUENCE = 0.02


def _check_sizes(kind: str, **fields: float | tuple[float, ...]) -> None:
    """Refuse a negative or non-finite size, naming the geometry and the field."""
    for name, value in fields.items():
        vals = value if isinstance(value, tuple) else (value,)
        for v in vals:
            if not (isinstance(v, float) and math.isfinite(v) and v >= 0.0):
                raise RobotDefinitionError(
                    f"{kind} {name}: expected finite numbers >= 0 [m], got {short_repr(value)}")


def _floats(value: object, count: int, kind: str, name: str) -> tuple[float, ...]:
    try:
        vals = tuple(float(v) for v in np.asarray(value, dtype=float).reshape(-1))
    except (TypeError, ValueError):
        raise RobotDefinitionError(
            f"{kind} {name}: expected {count} numbers, got {short_repr(value)}") from None
    if len(vals) != count:
        raise RobotDefinitionError(
            f"{kind} {name}: expected {count} numbers, got {short_repr(value)}")
    return vals


def _float(value: object, kind: str, name: str) -> float:
    return _floats(value, 1, kind, name)[0]


def _size(value: object, kind: str, name: str) -> float:
    """One finite size >= 0 [m]."""
    v = _float(value, kind, name)
    _check_sizes(kind, **{name: v})
    return v


def _point(value: object, name: str) -> np.ndarray:
    """A finite point (3,) [m], copied (float64, C order)."""
    return as_vector(value, name, 3).copy()


def _rotation(value: object) -> np.ndarray:
    """A (3, 3) rotation matrix, copied (float64, C order)."""
    R = check_rotation(value, "rotation")
    if R.shape != (3, 3):
        raise InputError(f"rotation must have shape (3, 3), got {R.shape}")
    return np.array(R, dtype=float)


def _pose(R: np.ndarray | None, p: np.ndarray) -> np.ndarray:
    T = np.eye(4)
    if R is not None:
        T[:3, :3] = R
    T[:3, 3] = p
    return T


def _same(x: object, y: object) -> bool:
    if isinstance(x, np.ndarray) or isinstance(y, np.ndarray):
        return bool(np.array_equal(x, y))
    return x == y


def _key(x: object) -> object:
    return tuple(np.ravel(x).tolist()) if isinstance(x, np.ndarray) else x


class _Solid:
    """Shared by the solids: equality and hash by value (arrays compared elementwise).

    The arrays of a solid are its own copies; do not modify them in place (the solid is
    frozen and hashed by value).
    """

    kind: ClassVar[str]

    def __eq__(self, other: object) -> bool:
        """The same shape class with equal fields (arrays equal element by element)."""
        if type(other) is not type(self):
            return NotImplemented
        return all(_same(getattr(self, f.name), getattr(other, f.name)) for f in fields(self))

    def __hash__(self) -> int:
        """A hash of the class and the field values."""
        return hash((type(self).__name__,
                     *(_key(getattr(self, f.name)) for f in fields(self))))

    def _check_label(self) -> None:
        """Validate ``influence`` (a number >= 0 [m]) and ``name`` (a string)."""
        object.__setattr__(self, "influence",
                           check_positive(self.influence, "influence", allow_zero=True))
        if not isinstance(self.name, str):
            raise InputTypeError(f"name must be a string, got {short_repr(self.name)}")


def _origin() -> np.ndarray:
    return np.zeros(3)


def _identity() -> np.ndarray:
    return np.eye(3)


@dataclass(frozen=True, eq=False)
class Sphere(_Solid):
    """A ball: the points within ``radius`` of ``center``.

    Attributes:
        radius: radius [m], finite and >= 0.
        center: (3,) centre in the shape's frame [m] (default: the frame's origin).
        influence: distance from the surface within which an obstacle task acts [m].
        name: label.
    """

    kind: ClassVar[str] = "sphere"
    radius: float
    _: KW_ONLY
    center: np.ndarray = field(default_factory=_origin)
    influence: float = DEFAULT_INFLUENCE
    name: str = ""

    def __post_init__(self) -> None:
        """Validate: a finite radius >= 0, a finite centre (3,), the label."""
        object.__setattr__(self, "radius", _size(self.radius, "sphere", "radius"))
        object.__setattr__(self, "center", _point(self.center, "center"))
        self._check_label()

    @property
    def pose(self) -> np.ndarray:
        """(4, 4) placement in the shape's frame: the translation to ``center``."""
        return _pose(None, self.center)


@dataclass(frozen=True, eq=False)
class Box(_Solid):
    """A box: the points ``center + rotation @ u`` with ``|u_k| <= size[k] / 2``.

    Attributes:
        size: edge lengths (x, y, z) along the box axes [m], each finite and >= 0.
        center: (3,) centre in the shape's frame [m] (default: the frame's origin).
        rotation: (3, 3) rotation whose columns are the box axes in the shape's frame
            (default: identity).
        influence: distance from the surface within which an obstacle task acts [m].
        name: label.
    """

    kind: ClassVar[str] = "box"
    size: tuple[float, float, float]
    _: KW_ONLY
    center: np.ndarray = field(default_factory=_origin)
    rotation: np.ndarray = field(default_factory=_identity)
    influence: float = DEFAULT_INFLUENCE
    name: str = ""

    def __post_init__(self) -> None:
        """Validate: three finite sizes >= 0, a finite centre, a rotation, the label."""
        object.__setattr__(self, "size", _floats(self.size, 3, "box", "size"))
        _check_sizes("box", size=self.size)
        object.__setattr__(self, "center", _point(self.center, "center"))
        object.__setattr__(self, "rotation", _rotation(self.rotation))
        self._check_label()

    @property
    def half_extents(self) -> np.ndarray:
        """(3,) half edge lengths ``size / 2`` [m]."""
        return np.array(self.size) / 2.0

    @property
    def pose(self) -> np.ndarray:
        """(4, 4) placement in the shape's frame: ``rotation`` and ``center``."""
        return _pose(self.rotation, self.center)


@dataclass(frozen=True, eq=False)
class Cylinder(_Solid):
    """A cylinder: the points within ``radius`` of its axis, over ``length`` along it.

    Attributes:
        radius: radius [m], finite and >= 0.
        length: height along the axis [m], >= 0; ``math.inf`` for an infinite cylinder.
        center: (3,) centre in the shape's frame [m] (default: the frame's origin); for
            an infinite cylinder any point of its axis.
        rotation: (3, 3) rotation whose third column is the axis (default: identity, the
            axis along the frame's z).
        influence: distance from the surface within which an obstacle task acts [m].
        name: label.
    """

    kind: ClassVar[str] = "cylinder"
    radius: float
    length: float
    _: KW_ONLY
    center: np.ndarray = field(default_factory=_origin)
    rotation: np.ndarray = field(default_factory=_identity)
    influence: float = DEFAULT_INFLUENCE
    name: str = ""

    def __post_init__(self) -> None:
        """Validate: a finite radius >= 0, a length >= 0 (inf allowed), the placement."""
        object.__setattr__(self, "radius", _size(self.radius, "cylinder", "radius"))
        length = _float(self.length, "cylinder", "length")
        if not (length >= 0.0):  # NaN fails too
            raise RobotDefinitionError(
                f"cylinder length: expected a number >= 0 [m] (math.inf: an infinite "
                f"cylinder), got {short_repr(self.length)}")
        object.__setattr__(self, "length", length)
        object.__setattr__(self, "center", _point(self.center, "center"))
        object.__setattr__(self, "rotation", _rotation(self.rotation))
        self._check_label()

    @property
    def axis(self) -> np.ndarray:
        """(3,) unit direction of the axis in the shape's frame (``rotation[:, 2]``)."""
        return self.rotation[:, 2].copy()

    @property
    def infinite_along_z(self) -> bool:
        """True for an infinite cylinder whose axis is the frame's z direction.

        Its distances are measured in the xy plane, to the circle of radius ``radius``
        about ``center[:2]``: the only cylinder that collision scenes and the obstacle
        tasks accept.
        """
        return math.isinf(self.length) and abs(float(self.rotation[2, 2])) >= 1.0 - 1e-12

    def require_infinite_along_z(self, where: str, role: str) -> None:
        """Raise NotSupportedError unless :attr:`infinite_along_z` (``role``: who refuses).

        ``where`` names the argument (``scene[2]``), ``role`` what it is used as ("in a
        scene", "obstacle"): collision scenes and the obstacle tasks take no other cylinder.
        """
        if not self.infinite_along_z:
            raise NotSupportedError(
                f"{where}: a Cylinder {role} must be infinite along z (length=math.inf, axis "
                f"along the world z), got length {self.length:g} m and axis "
                f"{self.axis.round(6).tolist()}")

    @property
    def pose(self) -> np.ndarray:
        """(4, 4) placement in the shape's frame: ``rotation`` and ``center``."""
        return _pose(self.rotation, self.center)


def _frame_with_z(z: np.ndarray) -> np.ndarray:
    """A rotation whose third column is the unit vector ``z`` (identity for z = +e_z).

    The branchless orthonormal basis of Duff et al., "Building an orthonormal basis,
    revisited" (JCGT 6(1), 2017): with ``s = sign(z_z)`` and ``k = −1/(s + z_z)``,
    ``x = (1 + s z_x² k, s z_x z_y k, −s z_x)``, ``y = (z_x z_y k, s + z_y² k, −z_y)``;
    accurate for every direction (``|s + z_z| >= 1``).
    """
    s = math.copysign(1.0, float(z[2]))
    k = -1.0 / (s + z[2])
    xy = z[0] * z[1] * k
    x = [1.0 + s * z[0] * z[0] * k, s * xy, -s * z[0]]
    y = [xy, s + z[1] * z[1] * k, -z[1]]
    return np.column_stack([x, y, z])


@dataclass(frozen=True, eq=False, init=False)
class Capsule(_Solid):
    """A capsule: the points within ``radius`` of the segment from ``a`` to ``b``.

    Built from its size, ``Capsule(radius, length)``, it is centred on the frame's origin
    with its axis along z (URDF: the segment's ends at ``z = ±length/2``); built from its
    ends, ``Capsule(radius, a=..., b=...)``, it lies where they are.

    Attributes:
        radius: radius [m], finite and >= 0.
        a: (3,) first end of the segment in the shape's frame [m].
        b: (3,) second end [m] (``a = b``: a sphere).
        influence: distance from the surface within which an obstacle task acts [m].
        name: label.
    """

    kind: ClassVar[str] = "capsule"
    radius: float
    a: np.ndarray
    b: np.ndarray
    influence: float = DEFAULT_INFLUENCE
    name: str = ""

    def __init__(self, radius: float, length: float | None = None, *,
                 a: object = None, b: object = None, influence: float = DEFAULT_INFLUENCE,
                 name: str = "") -> None:
        """Build from ``radius`` and either ``length`` or both ends ``a`` and ``b``.

        Raises:
            InputError: both a length and ends, or neither (and the errors of the module).
        """
        r = _size(radius, "capsule", "radius")
        if length is not None:
            if a is not None or b is not None:
                raise InputError("capsule: give either its length (the segment centred on "
                                 "the frame's origin along z) or its ends a and b, not both")
            half = _size(length, "capsule", "length") / 2.0
            a, b = np.array([0.0, 0.0, -half]), np.array([0.0, 0.0, half])
        elif a is None or b is None:
            raise InputError("capsule: give its length (the segment centred on the frame's "
                             "origin along z) or both ends a and b")
        object.__setattr__(self, "radius", r)
        object.__setattr__(self, "a", _point(a, "a"))
        object.__setattr__(self, "b", _point(b, "b"))
        object.__setattr__(self, "influence", influence)
        object.__setattr__(self, "name", name)
        self._check_label()

    @property
    def length(self) -> float:
        """Length of the segment ``‖b − a‖`` [m] (between the end-sphere centres)."""
        return float(np.linalg.norm(self.b - self.a))

    @property
    def center(self) -> np.ndarray:
        """(3,) midpoint of the segment [m]."""
        return (self.a + self.b) / 2.0

    @property
    def pose(self) -> np.ndarray:
        """(4, 4) placement: at the midpoint, z along ``b − a`` (identity for ``a = b``).

        A capsule is symmetric about its axis: the other two axes are a fixed choice
        (the identity for an axis along +z, as ``Capsule(radius, length)`` has).
        """
        d = self.b - self.a
        n = float(np.linalg.norm(d))
        return _pose(np.eye(3) if n == 0.0 else _frame_with_z(d / n), self.center)


@dataclass(frozen=True, eq=False)
class HalfSpace(_Solid):
    """The solid ``{x : normalᵀ x <= offset}`` below a plane (a table top: normal +z).

    Unbounded: a collision scene accepts it, link geometry does not.

    Attributes:
        normal: (3,) outward unit normal of the solid (normalised on construction).
        offset: signed height of the plane along ``normal`` [m].
        influence: distance from the surface within which an obstacle task acts [m].
        name: label.
    """

    kind: ClassVar[str] = "halfspace"
    normal: np.ndarray
    offset: float = 0.0
    _: KW_ONLY
    influence: float = DEFAULT_INFLUENCE
    name: str = ""

    def __post_init__(self) -> None:
        """Validate: a finite non-zero normal (normalised), a finite offset, the label."""
        n = as_vector(self.normal, "normal", 3)
        norm = float(np.linalg.norm(n))
        if norm < 1e-12:
            raise InputError(f"normal must be a non-zero vector, got {n.tolist()}")
        object.__setattr__(self, "normal", n / norm)
        object.__setattr__(self, "offset", check_real(self.offset, "offset"))
        self._check_label()


@dataclass(frozen=True)
class Mesh:
    """A mesh file (not loaded), scaled per axis by ``scale``.

    ``filename`` is the resolved absolute path when the importer found the file, else the
    path as written (``package://...`` or relative). Link geometry only: a mesh has no
    placement of its own (its :class:`Shape`'s ``origin`` places it).
    """

    kind: ClassVar[str] = "mesh"
    filename: str
    scale: tuple[float, float, float] = (1.0, 1.0, 1.0)

    def __post_init__(self) -> None:
        """Validate: a non-empty file name and three finite scale factors >= 0."""
        if not isinstance(self.filename, str) or not self.filename:
            raise RobotDefinitionError(
                f"mesh filename: expected a non-empty path, got {short_repr(self.filename)}")
        object.__setattr__(self, "scale", _floats(self.scale, 3, "mesh", "scale"))
        _check_sizes("mesh", scale=self.scale)


#: The shapes of link geometry.
Geometry = Box | Cylinder | Sphere | Capsule | Mesh
#: The solids: what a collision scene or an obstacle list is made of.
Solid = Sphere | Capsule | Cylinder | Box | HalfSpace


def _check_link_geometry(g: Geometry) -> None:
    """Refuse an unbounded shape, or one placed off its frame's origin, as link geometry."""
    if isinstance(g, Mesh):
        return
    if isinstance(g, Cylinder) and math.isinf(g.length):
        raise RobotDefinitionError(
            "cylinder length: link geometry is bounded, expected a finite length [m], got inf")
    if not np.array_equal(g.pose, np.eye(4)):
        raise RobotDefinitionError(
            f"shape geometry: a {g.kind} of link geometry sits at its frame's origin along "
            f"its axes and is placed by the Shape's origin; got one placed by the pose "
            f"{short_repr(np.round(g.pose[:3], 9).tolist())} (build it at the origin and "
            f"pass that pose as origin=...)")


@dataclass(frozen=True, eq=False)
class Shape:
    """One posed geometry: ``origin`` (4, 4) is its pose in the owning chain frame.

    ``geometry`` is a bounded shape at its own frame's origin along its axes (the
    defaults of its placement: ``Sphere(r)``, ``Box(size)``, ``Cylinder(r, length)``,
    ``Capsule(r, length)``) or a :class:`Mesh`; ``origin`` places it, so its world pose at
    ``q`` is ``fk_all(q)[frame] @ origin``. Its ``name`` and ``influence`` are not used here.
    ``name`` is the URDF ``<visual name>``/``<collision name>`` (may be empty);
    ``material`` and ``rgba`` (4 numbers in [0, 1]) are optional appearance.

    Raises:
        RobotDefinitionError: another kind of geometry, one placed off its frame's origin
            or an infinite cylinder, an origin that is not a rigid transform, a bad colour.
    """

    geometry: Geometry
    origin: np.ndarray = field(default_factory=lambda: np.eye(4))
    name: str = ""
    material: str | None = None
    rgba: tuple[float, float, float, float] | None = None

    def __post_init__(self) -> None:
        """Validate the origin (a rigid transform) and the colour."""
        if not isinstance(self.geometry, Box | Cylinder | Sphere | Capsule | Mesh):
            raise RobotDefinitionError(
                f"shape geometry: expected a Box, Cylinder, Sphere, Capsule or Mesh, got "
                f"{type(self.geometry).__name__}")
        _check_link_geometry(self.geometry)
        T = np.array(check_fixed_transform(self.origin, "shape origin"), dtype=float)
        T.setflags(write=False)
        object.__setattr__(self, "origin", T)
        if self.rgba is not None:
            rgba = _floats(self.rgba, 4, "shape", "rgba")
            if not all(math.isfinite(c) and 0.0 <= c <= 1.0 for c in rgba):
                raise RobotDefinitionError(
                    f"shape rgba: expected 4 numbers in [0, 1], got {short_repr(self.rgba)}")
            object.__setattr__(self, "rgba", rgba)

    def __eq__(self, other: object) -> bool:
        """Equal geometry, name, appearance and origin (exactly)."""
        if not isinstance(other, Shape):
            return NotImplemented
        return (self.geometry == other.geometry and self.name == other.name
                and self.material == other.material and self.rgba == other.rgba
                and bool(np.array_equal(self.origin, other.origin)))

    __hash__ = None  # type: ignore[assignment]


@dataclass(frozen=True)
class LinkGeometry:
    """The visual and collision shapes of one named link, fixed to chain frame ``frame``.

    Attributes:
        link_name: the URDF link the shapes came from.
        frame: index 0..n of :meth:`Robot.fk_all` the link is fixed to.
        visual: shapes drawn; origins in frame ``frame``.
        collision: shapes for collision checking; origins in frame ``frame``.
    """

    link_name: str
    frame: int
    visual: tuple[Shape, ...] = ()
    collision: tuple[Shape, ...] = ()

    def __post_init__(self) -> None:
        """Validate the frame index (>= 0) and turn the shape lists into tuples."""
        if isinstance(self.frame, bool) or not isinstance(self.frame, int | np.integer) \
                or self.frame < 0:
            raise RobotDefinitionError(
                f"link {short_repr(self.link_name)} frame: expected an int >= 0, got "
                f"{short_repr(self.frame)}")
        object.__setattr__(self, "frame", int(self.frame))
        for kind in ("visual", "collision"):
            shapes = tuple(getattr(self, kind))
            for s in shapes:
                if not isinstance(s, Shape):
                    raise RobotDefinitionError(
                        f"link {short_repr(self.link_name)} {kind}: expected Shape objects, "
                        f"got {type(s).__name__}")
            object.__setattr__(self, kind, shapes)


def renamed(module: str, name: str, table: dict) -> object:
    """The old name ``name`` of ``module`` (a module ``__getattr__``), with a warning.

    ``table`` maps each old name to ``(build, new, call)``: the thin constructor keeping
    the old signature, the name of the class of this module it builds and an example of
    the new call. Emits a ``DeprecationWarning`` naming the new import and call.

    Raises:
        AttributeError: ``name`` is not an old name (``module`` has no such attribute).
    """
    if name not in table:
        raise AttributeError(f"module {module!r} has no attribute {name!r}")
    build, new, call = table[name]
    warnings.warn(f"{module}.{name} is deprecated: import {new} from serialkin.model.geometry "
                  f"(one class per shape), sizes first and placement by keyword: {call}",
                  DeprecationWarning, stacklevel=3)
    return build
