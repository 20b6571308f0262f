"""What the interactive viewer shows (:class:`Scene`) and how it draws it (:class:`ViewerOptions`).

:func:`~serialkin.viz.viewer.write_viewer`, :func:`~serialkin.viz.viewer.viewer_html` and
:func:`~serialkin.viz.viewer.viewer_data` take one :class:`Scene`: the robot, the
configuration or trajectory to show, the target path, the obstacles, the collision model
checked in the page and a point layer. :class:`ViewerOptions` holds the drawing options
(visual meshes, their triangle budget, capsules shown at first). Both are frozen and check
their values when made, so a scene that exists can be drawn: a wrong shape, a non-finite
value or a wrong type raises :class:`~serialkin.errors.InputError` or
:class:`~serialkin.errors.InputTypeError` naming the field, what it expects and what came.

Lengths are in metres, angles in radians.
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping
from dataclasses import KW_ONLY, dataclass
from typing import TYPE_CHECKING

import numpy as np

from serialkin._checks import as_float_array, check_int, short_repr
from serialkin.errors import InputError, InputTypeError
from serialkin.model.robot import Robot, check_robot
from serialkin.viz.plot import Obstacle, as_obstacle

if TYPE_CHECKING:
    from serialkin.collision.acm import AllowedCollisionMatrix
    from serialkin.model.collision_model import CollisionModel

__all__ = ["MESH_BUDGET", "Scene", "ViewerOptions"]

#: Default largest number of triangles of all visual meshes embedded in a page together
#: (about 12 bytes each in the file: the Panda's ten meshes in about 0.8 MB).
MESH_BUDGET = 60_000


def _set(obj: object, name: str, value: object) -> None:
    """Store a checked value on a frozen dataclass while it is made."""
    object.__setattr__(obj, name, value)


def _check_flag(value: object, name: str, expected: str = "True or False") -> bool:
    """``value`` as a bool; anything but a Python or numpy bool raises, naming ``name``."""
    if not isinstance(value, (bool, np.bool_)):
        raise InputTypeError(f"{name} must be {expected}, got {short_repr(value)}")
    return bool(value)


def _check_text(value: object, name: str, *, optional: bool) -> str | None:
    if value is None and optional:
        return None
    if not isinstance(value, str):
        want = "a string or None" if optional else "a string"
        raise InputTypeError(f"{name} must be {want}, got {type(value).__name__} "
                             f"{short_repr(value)}")
    return value


def _check_trajectory(robot: Robot, trajectory: object) -> np.ndarray | None:
    if trajectory is None:
        return None
    Q = robot.check_q(trajectory, "trajectory")
    if Q.ndim != 2 or Q.shape[0] == 0:
        raise InputError(
            f"trajectory must have shape (k, {robot.n}) with k >= 1, got {Q.shape}"
        )
    return np.array(Q)


def _check_q(robot: Robot, q: object) -> np.ndarray | None:
    if q is None:
        return None
    qv = robot.check_q(q)
    if qv.ndim != 1:
        raise InputError(f"q must be one configuration of shape ({robot.n},), got {qv.shape}")
    return np.array(qv)


def _check_path_points(path_points: object) -> np.ndarray | None:
    if path_points is None:
        return None
    P = as_float_array(path_points, "path_points", ndim=2)
    if P.shape[1] not in (2, 3):
        raise InputError(f"path_points must have shape (k, 2) or (k, 3), got {P.shape}")
    return np.array(P)


def _check_obstacles(obstacles: object) -> tuple[Obstacle, ...]:
    if obstacles is None:
        return ()
    if isinstance(obstacles, (str, bytes, Mapping)) or not isinstance(obstacles, Iterable):
        raise InputTypeError(f"obstacles must be a list of obstacles (objects or dicts), got "
                             f"{type(obstacles).__name__} {short_repr(obstacles)}")
    return tuple(as_obstacle(o, f"obstacles[{i}]") for i, o in enumerate(obstacles))


def _check_points(points: object, point_colors: object,
                  ) -> tuple[np.ndarray | None, np.ndarray | None]:
    """Positions (N, 3) [m] and RGB colours (N, 3) in [0, 1] (or None) of the point layer."""
    if points is None:
        if point_colors is not None:
            raise InputError("point_colors given without points")
        return None, None
    P = as_float_array(points, "points", ndim=2)
    if P.shape[1] != 3:
        raise InputError(f"points must have shape (N, 3), got {P.shape}")
    if point_colors is None:
        return np.array(P), None
    C = as_float_array(point_colors, "point_colors", ndim=2)
    if C.shape != P.shape:
        raise InputError(f"point_colors must have shape {P.shape} (RGB per point), "
                         f"got {C.shape}")
    if C.size and (C.min() < 0.0 or C.max() > 1.0):
        raise InputError(f"point_colors must be in [0, 1], got values in "
                         f"[{C.min():.3g}, {C.max():.3g}]")
    return np.array(P), np.array(C)


def _resolve_collision(robot: Robot, collision: object) -> CollisionModel | None:
    """The collision model drawn: the robot's (None), none (False) or the one given."""
    if collision is False:
        return None
    if collision is None or collision is True:
        model = robot.collision
        if model is None and collision is True:
            raise InputError(f"robot {short_repr(robot.name)} has no collision model "
                             "(Robot.collision is None); pass collision=CollisionModel(...)")
    else:
        model = collision
    if model is None:
        return None
    from serialkin.model.collision_model import CollisionModel

    if not isinstance(model, CollisionModel):
        raise InputTypeError(f"collision must be None, a bool or a CollisionModel, got "
                             f"{type(model).__name__}")
    if len(model.body_frames) and int(model.body_frames.max()) > robot.n:
        i = int(np.argmax(model.body_frames > robot.n))
        raise InputError(f"collision body {short_repr(model.body_names[i])} is fixed to frame "
                         f"{int(model.body_frames[i])}, but robot {short_repr(robot.name)} "
                         f"has frames 0..{robot.n}")
    return model


def _check_acm(acm: object, model: CollisionModel | None) -> None:
    """The allowed-collision matrix must be one over the bodies of the model checked."""
    if acm is None:
        return
    if model is None:
        raise InputError("acm given but there is no collision model to check")
    from serialkin.collision.acm import check_acm

    check_acm(acm)
    if tuple(acm.body_names) != tuple(model.body_names):
        raise InputError(f"acm must cover the collision model's bodies "
                         f"{short_repr(tuple(model.body_names))}, got "
                         f"{short_repr(tuple(acm.body_names))}")


@dataclass(frozen=True, eq=False)
class Scene:
    """What the viewer page shows: a robot, its motion, the path, obstacles and points.

    Every field but ``robot`` is keyword-only. Arrays are checked and stored as float64
    copies; obstacles are stored normalised (:func:`~serialkin.viz.plot.as_obstacle`).

    Attributes:
        robot: the robot to show.
        q: initial configuration (n,) [rad / m]; None: the trajectory's first row, else
            zeros clipped into the joint limits.
        trajectory: (k, n) configurations to play back (play button and frame slider);
            the end effector's trace along it is drawn. None for none.
        path_points: (k, 2) or (k, 3) target path [m], drawn as a green polyline (2D
            points get z = 0 in the page).
        obstacles: obstacle objects or dicts (see :func:`serialkin.viz.plot.as_obstacle`):
            spheres, vertical cylinders, capsules; stored as a tuple of
            :class:`~serialkin.viz.plot.Obstacle`, each holding its
            :mod:`~serialkin.model.geometry` shape (``.shape``).
        collision: the capsule model checked and drawn: None = :attr:`Robot.collision`
            (if any), a :class:`~serialkin.model.collision_model.CollisionModel`, or False
            for none (True requires the robot's own).
        acm: the :class:`~serialkin.collision.acm.AllowedCollisionMatrix` whose pairs are
            skipped (None: :func:`~serialkin.collision.acm.default_acm`); needs a
            collision model and must cover its bodies.
        points: (N, 3) positions [m] drawn as a toggled point cloud, or None.
        point_colors: (N, 3) RGB in [0, 1] per point (None: one blue); needs ``points``.
        points_label: the point layer's name in the page.
        title: page title (None: "serialkin viewer: <robot name>").

    Raises:
        InputTypeError: ``robot`` is not a :class:`~serialkin.Robot`; ``obstacles`` is not
            a list; ``collision`` is not None, a bool or a collision model; ``acm`` is not
            an allowed-collision matrix; a label or title is not a string.
        InputError: a configuration with the wrong number of joints or non-finite values,
            a path or points of the wrong shape, colours outside [0, 1], a malformed
            obstacle, ``collision=True`` for a robot without a model, a collision model on
            frames the robot does not have, an ``acm`` over other bodies, ``acm`` or
            ``point_colors`` given without what they apply to.
    """

    robot: Robot
    _: KW_ONLY
    q: np.ndarray | None = None
    trajectory: np.ndarray | None = None
    path_points: np.ndarray | None = None
    obstacles: tuple[Obstacle, ...] = ()
    collision: CollisionModel | bool | None = None
    acm: AllowedCollisionMatrix | None = None
    points: np.ndarray | None = None
    point_colors: np.ndarray | None = None
    points_label: str = "points"
    title: str | None = None

    def __post_init__(self) -> None:
        robot = self.robot
        check_robot(robot)
        _set(self, "trajectory", _check_trajectory(robot, self.trajectory))
        _set(self, "path_points", _check_path_points(self.path_points))
        _set(self, "q", _check_q(robot, self.q))
        _set(self, "obstacles", _check_obstacles(self.obstacles))
        _check_acm(self.acm, self.collision_model)
        points, colors = _check_points(self.points, self.point_colors)
        _set(self, "points", points)
        _set(self, "point_colors", colors)
        _check_text(self.points_label, "points_label", optional=False)
        _check_text(self.title, "title", optional=True)

    @property
    def collision_model(self) -> CollisionModel | None:
        """The collision model the page checks and draws (None: none), from ``collision``."""
        return _resolve_collision(self.robot, self.collision)

    @property
    def initial_q(self) -> np.ndarray:
        """The configuration (n,) shown when the page opens [rad / m] (see ``q``)."""
        if self.q is not None:
            return self.q.copy()
        if self.trajectory is not None:
            return self.trajectory[0].copy()
        return np.clip(np.zeros(self.robot.n), self.robot.qlim[:, 0], self.robot.qlim[:, 1])


@dataclass(frozen=True)
class ViewerOptions:
    """How the viewer page draws the robot's body.

    Attributes:
        meshes: draw the visual mesh files of :attr:`Robot.geometry` (needs the ``mesh``
            extra when there are any); False draws only the primitive shapes, or the
            skeleton of cylinders when there are none.
        mesh_budget: most triangles of all embedded meshes together (>= 4); larger meshes
            are decimated (about 12 bytes of page per triangle).
        show_collision: collision capsules visible when the page opens (a toggle in the
            page); needs a collision model in the scene.

    Raises:
        InputTypeError: a flag that is not a bool, a budget that is not an integer.
        InputError: ``mesh_budget`` below 4.
    """

    meshes: bool = True
    mesh_budget: int = MESH_BUDGET
    show_collision: bool = False

    def __post_init__(self) -> None:
        _set(self, "meshes", _check_flag(self.meshes, "meshes"))
        _set(self, "mesh_budget", check_int(self.mesh_budget, "mesh_budget", minimum=4))
        _set(self, "show_collision", _check_flag(self.show_collision, "show_collision"))

