"""The flat encoding of a collision scene for the compiled clearance kernels.

A *scene* is a sequence of shapes of :mod:`serialkin.model.geometry` fixed in the world
frame (metres): :class:`~serialkin.model.geometry.Sphere`,
:class:`~serialkin.model.geometry.Capsule`, :class:`~serialkin.model.geometry.Box`,
:class:`~serialkin.model.geometry.HalfSpace` and the infinite
:class:`~serialkin.model.geometry.Cylinder` along z (its distance is measured in the xy
plane). Their ``influence`` is not used here.

:func:`encode_scene` packs a scene into a (k, 16) float array, one row per shape:
``kind`` in column 0, then the parameters (see :data:`KIND_NAMES`).

``Box`` and ``HalfSpace`` were defined here before the shapes had one vocabulary; the
old names still build the shared classes for one release, with a ``DeprecationWarning``.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from typing import Any

import numpy as np

from serialkin._checks import as_float_array, as_vector
from serialkin.errors import InputError, InputTypeError
from serialkin.model import geometry  # not its names: Box and HalfSpace here are the old ones

__all__ = ["KIND_NAMES", "encode_scene"]

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

_SCENE_TYPES = (geometry.Sphere, geometry.Capsule, geometry.Cylinder, geometry.Box,
                geometry.HalfSpace)


def encode_scene(scene: Sequence[object]) -> np.ndarray:
    """Pack scene shapes into a (k, 16) float array (layout in :data:`KIND_NAMES`).

    Args:
        scene: one shape or a sequence of shapes, in the world frame.

    Raises:
        InputTypeError: an item is not a Sphere, Capsule, Cylinder, Box or HalfSpace.
        NotSupportedError: a cylinder that is finite or whose axis is not along z.
    """
    if isinstance(scene, _SCENE_TYPES):
        scene = [scene]
    rows = np.zeros((len(scene), ROW))
    for i, s in enumerate(scene):
        r = rows[i]
        if isinstance(s, geometry.Sphere):
            r[0], r[1:4], r[4] = KIND_SPHERE, s.center, s.radius
        elif isinstance(s, geometry.Capsule):
            r[0], r[1:4], r[4:7], r[7] = KIND_CAPSULE, s.a, s.b, s.radius
        elif isinstance(s, geometry.Cylinder):
            s.require_infinite_along_z(f"scene[{i}]", "in a scene")
            r[0], r[1:3], r[3] = KIND_CIRCLE, s.center[:2], s.radius
        elif isinstance(s, geometry.Box):
            r[0], r[1:4], r[4:13], r[13:16] = (KIND_BOX, s.center, s.rotation.ravel(),
                                               s.half_extents)
        elif isinstance(s, geometry.HalfSpace):
            r[0], r[1:4], r[4] = KIND_HALFSPACE, s.normal, s.offset
        else:
            raise InputTypeError(
                f"scene[{i}] must be a Sphere, Capsule, Cylinder, Box or HalfSpace, "
                f"got {type(s).__name__}")
    return np.ascontiguousarray(as_float_array(rows, "scene"))


# ------------------------------------------------------------------ deprecated names
def _old_box(center: object, half_extents: object, rotation: object = None,
             name: str = "") -> geometry.Box:
    """The old ``Box(center, half_extents, rotation=None, name='')``: a Box of size 2·h."""
    h = as_vector(half_extents, "half_extents", 3)
    if (h < 0).any():
        raise InputError(f"half_extents must be >= 0, got {h.tolist()}")
    placement: dict[str, Any] = {} if rotation is None else {"rotation": rotation}
    return geometry.Box(tuple(2.0 * h), center=center, name=name, **placement)


def _old_halfspace(normal: object, offset: float = 0.0, name: str = "") -> geometry.HalfSpace:
    """The old ``HalfSpace(normal, offset=0.0, name='')``."""
    return geometry.HalfSpace(normal, offset, name=name)


_old_box.__name__ = _old_box.__qualname__ = "Box"
_old_halfspace.__name__ = _old_halfspace.__qualname__ = "HalfSpace"

#: Old name -> (thin constructor, the class it builds, the call in the shared vocabulary).
_DEPRECATED: dict[str, tuple[Callable[..., Any], str, str]] = {
    "Box": (_old_box, "Box", "Box(size=2 * half_extents, center=..., rotation=..., name=...)"),
    "HalfSpace": (_old_halfspace, "HalfSpace", "HalfSpace(normal, offset, name=...)"),
}


def __getattr__(name: str) -> Callable[..., Any]:
    """``Box``, ``HalfSpace``: the old names, building the shared classes (warns)."""
    return geometry.renamed(__name__, name, _DEPRECATED)
