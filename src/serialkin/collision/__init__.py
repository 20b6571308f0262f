"""Collision: primitive distance kernels, robot capsule models, the allowed-collision matrix.

* :mod:`~serialkin.collision.kernels` — compiled signed distances with witness points
  (sphere, capsule, box, half-space);
* :mod:`~serialkin.collision.shapes` — the flat encoding of a scene, whose shapes are
  those of :mod:`serialkin.model.geometry` (``Sphere``, ``Capsule``, ``Box``,
  ``HalfSpace``, the infinite ``Cylinder`` along z) in the world frame;
* :class:`CollisionModel` — capsules per body per frame (defined in
  :mod:`serialkin.model.collision_model`: a robot carries it);
* :mod:`~serialkin.collision.fit` — capsules fitted to link geometry (meshes, primitives),
  with the fitting error;
* :mod:`~serialkin.collision.robots` — fitted models of built-in robots;
* :mod:`~serialkin.collision.acm` — the allowed-collision matrix (default, SRDF; the
  sampled one is :func:`~serialkin.collision.queries.sampled_acm`);
* :mod:`~serialkin.collision.srdf` — reading an SRDF;
* :mod:`~serialkin.collision.queries` — self/scene clearance and collision checks, batched;
* :mod:`~serialkin.collision.checks` — the same for a robot's own model, pairs named
  (``Robot.clearance``, ``Robot.in_collision``, ``serialkin collide``);
* :mod:`~serialkin.collision.reference` — agreement with Pinocchio + coal on the vendor
  meshes (optional peers).
"""

from serialkin.collision.acm import AllowedCollisionMatrix, acm_from_srdf, default_acm
from serialkin.collision.checks import (
    NamedClearance,
    PairDistance,
    clearance,
    closest_pairs,
    in_collision_of,
    robot_acm,
)
from serialkin.collision.fit import FitReport, ShapeFit, collision_model_from_geometry
from serialkin.collision.queries import (
    Clearance,
    in_collision,
    sampled_acm,
    scene_clearance,
    self_clearance,
)
from serialkin.collision.robots import (
    iiwa7_collision_model,
    panda_collision_model,
    planar_collision_model,
    puma560_collision_model,
    scara_collision_model,
    stanford_collision_model,
    ur5_collision_model,
)
from serialkin.collision.srdf import Srdf, read_srdf
from serialkin.model.collision_model import CollisionModel
from serialkin.model.robot import provide

provide("fit_collision", collision_model_from_geometry)  # Robot.fit_collision calls it
provide("clearance", clearance)  # Robot.clearance
provide("in_collision", in_collision_of)  # Robot.in_collision

__all__ = [
    "AllowedCollisionMatrix",
    "Clearance",
    "CollisionModel",
    "FitReport",
    "NamedClearance",
    "PairDistance",
    "ShapeFit",
    "Srdf",
    "acm_from_srdf",
    "clearance",
    "closest_pairs",
    "collision_model_from_geometry",
    "default_acm",
    "iiwa7_collision_model",
    "in_collision",
    "in_collision_of",
    "panda_collision_model",
    "planar_collision_model",
    "puma560_collision_model",
    "read_srdf",
    "robot_acm",
    "sampled_acm",
    "scara_collision_model",
    "scene_clearance",
    "self_clearance",
    "stanford_collision_model",
    "ur5_collision_model",
]


def __getattr__(name: str) -> object:
    """``Box``, ``HalfSpace``: old names of :mod:`serialkin.model.geometry` classes (warn)."""
    from serialkin.collision.shapes import _DEPRECATED
    from serialkin.model.geometry import renamed

    return renamed(__name__, name, _DEPRECATED)
