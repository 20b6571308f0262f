"""Collision checks of a robot by its own collision model, with the pairs named.

The conveniences behind :meth:`Robot.clearance <serialkin.Robot.clearance>`,
:meth:`Robot.in_collision <serialkin.Robot.in_collision>` and ``serialkin collide``:
they take the robot's :attr:`~serialkin.Robot.collision` model, an allowed-collision
matrix made from an SRDF when one is given (:func:`robot_acm`), and report every pair by
name — body names of the model (``panda_link5``, ``panda_hand``), and for an obstacle its
``name`` or ``obstacle <i>`` (its index in the scene). Distances in metres, negative when
the shapes overlap (see :mod:`serialkin.collision.queries`).
"""

from __future__ import annotations

import os
from collections.abc import Iterable
from dataclasses import dataclass

import numpy as np

from serialkin._checks import check_int, check_real, short_repr
from serialkin.collision.acm import AllowedCollisionMatrix, acm_from_srdf, default_acm
from serialkin.collision.queries import body_pair_distances, scene_clearance, self_clearance
from serialkin.errors import InputError

__all__ = ["NamedClearance", "PairDistance", "clearance", "closest_pairs", "in_collision_of",
           "robot_acm"]


def _model(robot):
    model = getattr(robot, "collision", None)
    if model is None:
        raise InputError(f"robot {short_repr(getattr(robot, 'name', ''))} has no collision "
                         "model: give it one with robot.with_collision(model) or "
                         "robot.fit_collision() (capsules fitted to its link geometry)")
    return model


def robot_acm(robot, acm: AllowedCollisionMatrix | None = None,
              srdf: str | os.PathLike[str] | None = None,
              skip_links: Iterable[str] = ()) -> AllowedCollisionMatrix:
    """The allowed-collision matrix of ``robot``'s collision model.

    ``acm`` when given; else the model's default (:func:`default_acm`: same and adjacent
    frames, and the pairs the model ships as allowed) with an SRDF's
    ``<disable_collisions>`` added when ``srdf`` is given; ``skip_links`` names SRDF links
    without a body in the model (pairs naming them are skipped).

    Raises:
        InputError: the robot has no collision model; ``acm`` and ``srdf`` both given.
        RobotDefinitionError: the SRDF names a link that is neither a body nor skipped.
    """
    model = _model(robot)
    if acm is not None:
        if srdf is not None:
            raise InputError("give acm or srdf, not both (acm_from_srdf(model, srdf, acm) "
                             "combines them)")
        return acm
    if srdf is not None:
        return acm_from_srdf(model, srdf, skip_links=skip_links)
    if tuple(skip_links):
        raise InputError("skip_links applies to the links of an SRDF: give srdf too")
    return default_acm(model)


def _scene_label(scene, index: int) -> str:
    shapes = scene if isinstance(scene, (list, tuple)) else [scene]
    name = getattr(shapes[index], "name", "") if 0 <= index < len(shapes) else ""
    return name or f"obstacle {index}"


@dataclass(frozen=True)
class NamedClearance:
    """Smallest signed distance and the pair that realises it, by name.

    Attributes:
        distance: (...,) signed distance [m]; +inf when nothing is checked.
        first: (...,) str, the robot body of the closest pair ('' when none).
        second: (...,) str, the other body, or the obstacle's name (``obstacle <i>``
            when it has none).
        with_scene: (...,) bool, True when ``second`` is an obstacle.
    """

    distance: np.ndarray
    first: np.ndarray
    second: np.ndarray
    with_scene: np.ndarray

    def pair(self) -> tuple[str, str]:
        """``(first, second)`` of a single configuration (InputError for a batch)."""
        if self.distance.ndim:
            raise InputError(f"pair() is for one configuration; this result has shape "
                             f"{self.distance.shape}: index first, e.g. result.first[k]")
        return str(self.first), str(self.second)


def clearance(robot, q: object, scene=None, *, acm: AllowedCollisionMatrix | None = None,
              srdf: str | os.PathLike[str] | None = None, skip_links: Iterable[str] = (),
              self_collision: bool = True) -> NamedClearance:
    """Smallest signed distance of ``robot`` at ``q`` to itself and to ``scene``, named.

    Args:
        robot: a robot with a collision model.
        q: joint values (..., n) [rad or m].
        scene: None, or a shape / sequence of shapes of :mod:`serialkin.model.geometry`
            in the world frame.
        acm: allowed-collision matrix (default :func:`robot_acm`).
        srdf: an SRDF whose disabled pairs are added to the default matrix.
        skip_links: SRDF links without a body (see :func:`robot_acm`).
        self_collision: check the robot's own pairs (False: the scene only).

    Returns:
        :class:`NamedClearance` of shape (...,).
    """
    model = _model(robot)
    full = robot_acm(robot, acm, srdf, skip_links)
    shape = np.shape(robot.check_q(q))[:-1]
    d = np.full(shape, np.inf)
    first = np.full(shape, "", dtype=object)
    second = np.full(shape, "", dtype=object)
    with_scene = np.zeros(shape, dtype=bool)
    if self_collision:
        c = self_clearance(robot, model, q, full)
        d = c.distance.copy()
        for idx in np.ndindex(shape):
            i, j = c.pair[idx]
            if i >= 0:
                first[idx], second[idx] = model.body_names[i], model.body_names[j]
    if scene is not None:
        c = scene_clearance(robot, model, q, scene)
        closer = c.distance < d
        for idx in zip(*np.nonzero(closer), strict=True) if shape else [()] * int(closer):
            i, o = c.pair[idx]
            first[idx], second[idx] = model.body_names[i], _scene_label(scene, int(o))
        d = np.where(closer, c.distance, d)
        with_scene = np.asarray(closer, dtype=bool)
    return NamedClearance(np.asarray(d, dtype=float), first.astype(str), second.astype(str),
                          with_scene)


def in_collision_of(robot, q: object, scene=None, *, margin: float = 0.0,
                    acm: AllowedCollisionMatrix | None = None,
                    srdf: str | os.PathLike[str] | None = None,
                    skip_links: Iterable[str] = (), self_collision: bool = True) -> np.ndarray:
    """(...,) bool: the :func:`clearance` is below ``margin`` [m] (0: shapes overlap)."""
    margin = check_real(margin, "margin", unit="m")
    return clearance(robot, q, scene, acm=acm, srdf=srdf, skip_links=skip_links,
                     self_collision=self_collision).distance < margin


@dataclass(frozen=True)
class PairDistance:
    """The signed distance [m] of one pair in one configuration.

    Attributes:
        first: robot body name.
        second: other body name, or the obstacle's name.
        distance: signed distance [m] (negative: overlap).
        with_scene: True when ``second`` is an obstacle.
    """

    first: str
    second: str
    distance: float
    with_scene: bool = False


def closest_pairs(robot, q: object, scene=None, *, count: int = 5,
                  acm: AllowedCollisionMatrix | None = None,
                  srdf: str | os.PathLike[str] | None = None, skip_links: Iterable[str] = (),
                  self_collision: bool = True) -> list[PairDistance]:
    """The ``count`` closest checked pairs of one configuration, closest first.

    Every checked body pair (the allowed ones are skipped) and, for each obstacle of
    ``scene``, its closest robot body.

    Args:
        robot: a robot with a collision model.
        q: one configuration (n,) [rad or m].
        scene: None, or shapes in the world frame.
        count: most pairs returned (>= 1).
        acm: allowed-collision matrix (default :func:`robot_acm`).
        srdf: an SRDF whose disabled pairs are added to the default matrix.
        skip_links: SRDF links without a body (see :func:`robot_acm`).
        self_collision: list the robot's own pairs (False: the obstacles only).
    """
    model = _model(robot)
    count = check_int(count, "count", minimum=1)
    qa = robot.check_q(q)
    if qa.ndim != 1:
        raise InputError(f"q must be one configuration (n,), got shape {qa.shape}")
    out: list[PairDistance] = []
    if self_collision:
        full = robot_acm(robot, acm, srdf, skip_links)
        pairs, d = body_pair_distances(robot, model, qa[None], full)
        out += [PairDistance(model.body_names[i], model.body_names[j], float(d[0, k]))
                for k, (i, j) in enumerate(pairs)]
    if scene is not None:
        shapes = list(scene) if isinstance(scene, (list, tuple)) else [scene]
        for o, shape in enumerate(shapes):
            c = scene_clearance(robot, model, qa, [shape])
            out.append(PairDistance(model.body_names[int(c.pair[0])], _scene_label(shapes, o),
                                    float(c.distance), True))
    out.sort(key=lambda p: p.distance)
    return out[:count]
