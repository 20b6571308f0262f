"""Scene shapes and their flat encoding for the compiled clearance kernels.

A *scene* is a sequence of shapes fixed in the world frame (metres):

* :class:`serialkin.redundancy.obstacles.Sphere` and
  :class:`~serialkin.redundancy.obstacles.Capsule` — the obstacles the redundancy tasks
  already use (one definition of each; their ``influence`` is ignored here);
* :class:`~serialkin.redundancy.obstacles.Circle` (``Cylinder``) — an infinite cylinder
  along the world z axis: its distance is measured in the xy plane;
* :class:`Box` — an oriented box;
* :class:`HalfSpace` — the solid ``{x : nᵀx ≤ offset}`` (a table, a wall, the floor).

:func:`encode_scene` packs a scene into a (k, 16) float array, one row per shape:
``kind`` in column 0, then the parameters (see :data:`KIND_NAMES`).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from serialkin._checks import as_float_array, as_vector, check_real, check_rotation
from serialkin.errors import InputError, InputTypeError
from serialkin.redundancy.obstacles import Capsule, Circle, Sphere

__all__ = ["KIND_NAMES", "Box", "HalfSpace", "encode_scene"]

KIND_SPHERE, KIND_CAPSULE, KIND_BOX, KIND_HALFSPACE, KIND_CIRCLE = 0, 1, 2, 3, 4
#: Row layout of :func:`encode_scene` by kind (column 0 holds the kind).
KIND_NAMES = {
    KIND_SPHERE: "sphere: centre (1:4), radius (4)",
    KIND_CAPSULE: "capsule: a (1:4), b (4:7), radius (7)",
    KIND_BOX: "box: centre (1:4), rotation row-major (4:13), half extents (13:16)",
    KIND_HALFSPACE: "half-space: unit normal (1:4), offset (4)",
    KIND_CIRCLE: "z-cylinder: centre x, y (1:3), radius (3)",
}
ROW = 16


@dataclass(frozen=True)
class Box:
    """An oriented box: the points ``center + rotation @ u`` with ``|u_k| ≤ half_extents[k]``.

    Attributes:
        center: (3,) centre in the world frame [m].
        half_extents: (3,) half side lengths along the box axes [m], each ≥ 0.
        rotation: (3, 3) rotation whose columns are the box axes in the world frame
            (identity by default).
        name: label.
    """

    center: np.ndarray
    half_extents: np.ndarray
    rotation: np.ndarray = None  # type: ignore[assignment]
    name: str = ""

    def __post_init__(self) -> None:
        object.__setattr__(self, "center", as_vector(self.center, "center", 3).copy())
        h = as_vector(self.half_extents, "half_extents", 3).copy()
        if (h < 0).any():
            raise InputError(f"half_extents must be >= 0, got {h.tolist()}")
        object.__setattr__(self, "half_extents", h)
        R = np.eye(3) if self.rotation is None else check_rotation(self.rotation, "rotation")
        if R.shape != (3, 3):
            raise InputError(f"rotation must have shape (3, 3), got {R.shape}")
        object.__setattr__(self, "rotation", np.array(R, dtype=float))


@dataclass(frozen=True)
class HalfSpace:
    """The solid ``{x : normalᵀ x ≤ offset}`` below a plane (a table top: normal +z).

    Attributes:
        normal: (3,) outward normal of the solid, normalised on construction.
        offset: signed height of the plane along ``normal`` [m].
        name: label.
    """

    normal: np.ndarray
    offset: float = 0.0
    name: str = ""

    def __post_init__(self) -> None:
        n = as_vector(self.normal, "normal", 3)
        norm = float(np.linalg.norm(n))
        if norm < 1e-12:
            raise InputError(f"normal must be a non-zero vector, got {n.tolist()}")
        object.__setattr__(self, "normal", n / norm)
        object.__setattr__(self, "offset", check_real(self.offset, "offset"))


def encode_scene(scene: Sequence[object]) -> np.ndarray:
    """Pack scene shapes into a (k, 16) float array (layout in :data:`KIND_NAMES`).

    Raises:
        InputTypeError: an item is not a Sphere, Capsule, Circle, Box or HalfSpace.
    """
    if isinstance(scene, (Sphere, Capsule, Circle, Box, HalfSpace)):
        scene = [scene]
    rows = np.zeros((len(scene), ROW))
    for i, s in enumerate(scene):
        r = rows[i]
        if isinstance(s, Sphere):
            r[0], r[1:4], r[4] = KIND_SPHERE, s.center, s.radius
        elif isinstance(s, Capsule):
            r[0], r[1:4], r[4:7], r[7] = KIND_CAPSULE, s.a, s.b, s.radius
        elif isinstance(s, Circle):
            r[0], r[1:3], r[3] = KIND_CIRCLE, s.center, s.radius
        elif isinstance(s, Box):
            r[0], r[1:4], r[4:13], r[13:16] = (KIND_BOX, s.center, s.rotation.ravel(),
                                               s.half_extents)
        elif isinstance(s, HalfSpace):
            r[0], r[1:4], r[4] = KIND_HALFSPACE, s.normal, s.offset
        else:
            raise InputTypeError(
                f"scene[{i}] must be a Sphere, Capsule, Circle, Box or HalfSpace, "
                f"got {type(s).__name__}")
    return np.ascontiguousarray(as_float_array(rows, "scene"))
