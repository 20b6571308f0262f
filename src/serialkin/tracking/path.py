"""Task-space paths for tracking: points, poses, or a sampled parametric curve.

A :class:`Path` holds ``p`` targets as 4x4 poses (``T_world_target``, shape (p, 4, 4)) and
the task it constrains:

* 'planar' — (x, y) points; only the rows vx, vy of the Jacobian count;
* 'planar_pose' — (x, y, φ) with φ the rotation about z [rad];
* 'position' — (x, y, z) points;
* 'pose' — full 4x4 poses.

Build one with :meth:`Path.from_points`, :meth:`Path.from_poses`,
:meth:`Path.from_function` (parametric curve sampled with a step),
:meth:`Path.circle` (the chapter's 6-link example) or :meth:`Path.polyline`.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence

import numpy as np

from serialkin._budget import check_allocation
from serialkin._checks import (
    MAX_INT,
    as_float_array,
    check_last_dims,
    check_positive,
    check_real,
    check_transform,
    short_repr,
)
from serialkin.errors import InputError
from serialkin.model.tasks import TARGET_TASKS, TASK_NAMES, get_task
from serialkin.spatial.lie import so3_log

__all__ = ["TASKS", "Path", "sample_parameter"]

#: Path tasks and the number of task coordinates of each point (the target kinds of
#: :data:`serialkin.model.tasks.TASKS`, the one task table).
TASKS: dict[str, int] = {name: get_task(name).point_size for name in TARGET_TASKS}


def sample_parameter(start: float, stop: float, step: float) -> np.ndarray:
    """Samples ``start, start + step, ...`` up to ``stop`` (included when it falls on the grid).

    The chapter's "φ ∈ {0, ..., 2π} with step 0.2" gives 0, 0.2, ..., 6.2 (32 values).
    """
    s0 = check_real(start, "start")
    s1 = check_real(stop, "stop")
    h = check_positive(step, "step")
    if s1 < s0:
        raise InputError(f"stop ({s1}) must not be below start ({s0})")
    ratio = (s1 - s0) / h
    count = int(np.floor(ratio + 1e-9)) + 1 if ratio < MAX_INT else MAX_INT
    check_path_size(count, "step")
    return s0 + h * np.arange(count)


#: Estimated memory per path point [bytes]: its 4x4 target, up to 6 task coordinates
#: and the parameter (float64), before any tracking result.
PATH_POINT_BYTES = 8 * (16 + 6 + 1)


def check_path_size(count: int, setting: str) -> None:
    """Refuse a path of ``count`` points beyond the memory budget (:mod:`serialkin._budget`).

    Raises:
        BudgetError: naming ``setting`` (e.g. 'step') and the estimated size.
    """
    check_allocation(f"a path of {count} points", count, PATH_POINT_BYTES, setting=setting)


class Path:
    """A sequence of task-space targets.

    Attributes:
        task: 'planar', 'planar_pose', 'position' or 'pose'.
        targets: (p, 4, 4) target poses (for point tasks only the position or planar
            angle is meaningful).
        points: (p, m) task coordinates: (x, y), (x, y, φ), (x, y, z), or for 'pose' the
            positions followed by the rotation vectors.
        parameter: (p,) curve parameter of each point (index when there is none).
    """

    def __init__(self, targets: np.ndarray, task: str, points: np.ndarray,
                 parameter: np.ndarray | None = None) -> None:
        task = get_task(task, targets_only=True, what="path task").name
        if targets.shape[0] == 0:
            raise InputError("a path needs at least one point")
        self.task = task
        self.targets = np.ascontiguousarray(targets, dtype=float)
        self.points = np.asarray(points, dtype=float)
        self.parameter = (np.arange(targets.shape[0], dtype=float) if parameter is None
                          else np.asarray(parameter, dtype=float))
        for a in (self.targets, self.points, self.parameter):
            a.setflags(write=False)

    def __len__(self) -> int:
        return self.targets.shape[0]

    def __repr__(self) -> str:
        return f"Path(task={self.task!r}, points={len(self)})"

    @property
    def positions(self) -> np.ndarray:
        """(p, 3) target positions [m]."""
        return self.targets[:, :3, 3]

    # ------------------------------------------------------------------ constructors
    @classmethod
    def from_points(cls, points: object, task: str | None = None,
                    parameter: object = None) -> Path:
        """A path through points.

        Args:
            points: (p, 2) planar points, (p, 3) positions or (x, y, φ) with
                ``task='planar_pose'`` [m, rad].
            task: default 'planar' for 2 columns, 'position' for 3.
            parameter: optional (p,) curve parameter.

        Raises:
            InputError: NaN/inf (the message gives the index), wrong shape, unknown task.
        """
        P = as_float_array(points, "path points", ndim=2)
        cols = P.shape[1]
        if task is None:
            task = {2: "planar", 3: "position"}.get(cols)
            if task is None:
                raise InputError(f"path points must have 2 or 3 columns, got shape {P.shape}")
        if isinstance(task, str) and task in TASK_NAMES:
            task = get_task(task).name
        if task not in TASKS or task == "pose":
            raise InputError(f"task for points must be 'planar', 'planar_pose' or 'position', "
                             f"got {short_repr(task)}")
        if cols != TASKS[task]:
            raise InputError(f"task {task!r} needs {TASKS[task]} columns, got shape {P.shape}")
        p = P.shape[0]
        T = np.tile(np.eye(4), (p, 1, 1))
        if task == "planar":
            T[:, :2, 3] = P
        elif task == "position":
            T[:, :3, 3] = P
        else:
            T[:, :2, 3] = P[:, :2]
            c, s = np.cos(P[:, 2]), np.sin(P[:, 2])
            T[:, 0, 0], T[:, 0, 1], T[:, 1, 0], T[:, 1, 1] = c, -s, s, c
        par = None if parameter is None else as_float_array(parameter, "parameter", ndim=1)
        if par is not None and par.shape[0] != p:
            raise InputError(f"parameter must have {p} values, got {par.shape[0]}")
        return cls(T, task, P, par)

    @classmethod
    def from_poses(cls, poses: object, parameter: object = None) -> Path:
        """A path of full poses, (p, 4, 4) rigid transforms (checked)."""
        T = check_last_dims(check_transform(poses, "path poses"), "path poses", (4, 4))
        if T.ndim != 3:
            raise InputError(f"path poses must have shape (p, 4, 4), got {T.shape}")
        W = so3_log(T[:, :3, :3], check=False)  # rotations checked with the poses
        par = None if parameter is None else as_float_array(parameter, "parameter", ndim=1)
        return cls(T, "pose", np.hstack([T[:, :3, 3], W]), par)

    @classmethod
    def from_function(cls, f: Callable[[float], object], start: float, stop: float,
                      step: float, task: str | None = None) -> Path:
        """Sample a parametric curve ``f(s)`` at ``s = start, start + step, ..., ≤ stop``.

        ``f`` returns a point (2 or 3 values) or a (4, 4) pose.
        """
        if not callable(f):
            raise InputError(f"f must be callable, got {type(f).__name__}")
        s = sample_parameter(start, stop, step)
        vals = [np.asarray(f(float(x)), dtype=float) for x in s]
        if vals[0].shape == (4, 4):
            return cls.from_poses(np.stack(vals), parameter=s)
        return cls.from_points(np.stack(vals), task=task, parameter=s)

    @classmethod
    def circle(cls, center: Sequence[float], radius: float, *, start: float = 0.0,
               stop: float = 2 * np.pi, step: float = 0.2) -> Path:
        """Planar circle ``x = c_x + r cos φ, y = c_y + r sin φ`` (the 6-link example).

        Args:
            center: (2,) centre [m].
            radius: radius [m] (> 0).
            start: first φ [rad].
            stop: last φ [rad] (included when on the grid, see :func:`sample_parameter`).
            step: φ step [rad].
        """
        c = as_float_array(center, "center", ndim=1)
        if c.shape != (2,):
            raise InputError(f"center must have 2 values, got {c.shape}")
        r = check_positive(radius, "radius")
        phi = sample_parameter(start, stop, step)
        pts = np.column_stack([c[0] + r * np.cos(phi), c[1] + r * np.sin(phi)])
        return cls.from_points(pts, "planar", parameter=phi)

    @classmethod
    def polyline(cls, waypoints: object, step: float, task: str | None = None) -> Path:
        """Straight segments between waypoints (k, 2|3), sampled at spacing ≤ ``step`` [m]."""
        W = as_float_array(waypoints, "waypoints", ndim=2)
        if W.shape[0] < 2:
            raise InputError(f"a polyline needs at least 2 waypoints, got {W.shape[0]}")
        h = check_positive(step, "step")
        seg = np.linalg.norm(W[1:, :3] - W[:-1, :3], axis=1) / h
        seg = np.where(np.isfinite(seg), seg, float(MAX_INT))
        ks = [max(1, int(np.ceil(x - 1e-9))) if x < MAX_INT else MAX_INT for x in seg]
        check_path_size(1 + sum(ks), "step")
        pts = [W[:1]]
        for a, b, k in zip(W[:-1], W[1:], ks):
            pts.append(a + (b - a) * (np.arange(1, k + 1)[:, None] / k))
        return cls.from_points(np.concatenate(pts), task=task)
