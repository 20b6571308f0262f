"""Link geometry: the visual and collision shapes of a robot, posed in its link frames.

A :class:`LinkGeometry` holds the shapes of one named part (a URDF ``<link>``) fixed to
one *frame* of the compiled chain: index ``0..n`` of :meth:`Robot.fk_all` (0 = base,
i = after joint i). A URDF link merged into a chain frame through fixed joints (a hand on
the flange) keeps its own name and its frame index; its shapes' origins are then
expressed in that chain frame (the fixed transforms composed in). The world pose of a
shape at joint values ``q`` is therefore ``fk_all(q)[frame] @ shape.origin``.

Primitives follow URDF/ROS: a :class:`Box` is centred on its origin with edge lengths
``size`` (x, y, z); a :class:`Cylinder` and a :class:`Capsule` are centred with their
axis along z (``length`` is the cylinder's height, the capsule's segment between the
centres of its end spheres); a :class:`Mesh` file is scaled per axis by ``scale``.
Meshes are only named here, never loaded. Lengths in metres.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from serialkin._checks import short_repr
from serialkin.errors import RobotDefinitionError
from serialkin.model.joint import check_fixed_transform

__all__ = ["Box", "Capsule", "Cylinder", "Geometry", "LinkGeometry", "Mesh", "Shape",
           "Sphere"]


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


@dataclass(frozen=True)
class Box:
    """A box centred on its origin; ``size`` = edge lengths (x, y, z) [m]."""

    size: tuple[float, float, float]

    def __post_init__(self) -> None:
        """Validate: three finite sizes >= 0."""
        object.__setattr__(self, "size", _floats(self.size, 3, "box", "size"))
        _check_sizes("box", size=self.size)


@dataclass(frozen=True)
class Cylinder:
    """A cylinder centred on its origin, axis z; ``radius``, ``length`` (height) [m]."""

    radius: float
    length: float

    def __post_init__(self) -> None:
        """Validate: finite radius and length >= 0."""
        object.__setattr__(self, "radius", _float(self.radius, "cylinder", "radius"))
        object.__setattr__(self, "length", _float(self.length, "cylinder", "length"))
        _check_sizes("cylinder", radius=self.radius, length=self.length)


@dataclass(frozen=True)
class Sphere:
    """A sphere centred on its origin; ``radius`` [m]."""

    radius: float

    def __post_init__(self) -> None:
        """Validate: a finite radius >= 0."""
        object.__setattr__(self, "radius", _float(self.radius, "sphere", "radius"))
        _check_sizes("sphere", radius=self.radius)


@dataclass(frozen=True)
class Capsule:
    """A capsule centred on its origin, axis z: segment ``length`` [m] swept by ``radius``.

    The end-sphere centres are at ``z = ±length/2``; the total extent is ``length + 2 radius``.
    """

    radius: float
    length: float

    def __post_init__(self) -> None:
        """Validate: finite radius and length >= 0."""
        object.__setattr__(self, "radius", _float(self.radius, "capsule", "radius"))
        object.__setattr__(self, "length", _float(self.length, "capsule", "length"))
        _check_sizes("capsule", radius=self.radius, length=self.length)


@dataclass(frozen=True)
class Mesh:
    """A mesh file (not loaded), scaled per axis by ``scale``.

    ``filename`` is the resolved absolute path when the importer found the file, else the
    path as written (``package://...`` or relative).
    """

    filename: str
    scale: tuple[float, float, float] = (1.0, 1.0, 1.0)

    def __post_init__(self) -> None:
        """Validate: a non-empty file name and three finite scale factors >= 0."""
        if not isinstance(self.filename, str) or not self.filename:
            raise RobotDefinitionError(
                f"mesh filename: expected a non-empty path, got {short_repr(self.filename)}")
        object.__setattr__(self, "scale", _floats(self.scale, 3, "mesh", "scale"))
        _check_sizes("mesh", scale=self.scale)


Geometry = Box | Cylinder | Sphere | Capsule | Mesh


@dataclass(frozen=True, eq=False)
class Shape:
    """One posed geometry: ``origin`` (4, 4) is its pose in the owning chain frame.

    ``name`` is the URDF ``<visual name>``/``<collision name>`` (may be empty);
    ``material`` and ``rgba`` (4 numbers in [0, 1]) are optional appearance.
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
