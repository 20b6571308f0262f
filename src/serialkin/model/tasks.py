"""The task vocabulary: which rows of the twist a task uses, their names and aliases.

A *task* selects rows of the geometric Jacobian and of the pose error
``e = [p_target − p; log(R_target Rᵀ)^∨]``, in the order ``[vx, vy, vz, wx, wy, wz]``
(:data:`TASK_COORDINATES`); the task space has dimension ``m`` = the number of rows (the
chapter's m, section 5.3). This module is the one table of tasks: the robot's
manipulability and condition number, the redundancy resolvers, IK target kinds (their
default weights), paths, scenario files and the command line all read it.

===============  ===================  ===================  ===========================
name (aliases)   rows                 target point         used as
===============  ===================  ===================  ===========================
``planar``       vx, vy               (x, y) [m]           path, IK kind, task rows
``planar_pose``  vx, vy, wz           (x, y, φ) [m, rad]   path, IK kind, task rows
``position``     vx, vy, vz           (x, y, z) [m]        path, IK kind, task rows
``pose``         all six              4×4 pose             path, IK kind, task rows
(``full``)
``orientation``  wx, wy, wz           —                    task rows only
===============  ===================  ===================  ===========================
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from serialkin._checks import short_repr
from serialkin.errors import InputError

__all__ = [
    "TARGET_TASKS",
    "TASKS",
    "TASK_COORDINATES",
    "TASK_NAMES",
    "Task",
    "get_task",
    "task_rows",
    "task_weights",
]

#: Names of the six task coordinates, in the order of the pose error and Jacobian rows.
TASK_COORDINATES = ("vx", "vy", "vz", "wx", "wy", "wz")


@dataclass(frozen=True)
class Task:
    """One named task.

    Attributes:
        name: canonical name.
        rows: rows of the twist / Jacobian / pose error the task uses (0..5).
        aliases: other accepted names.
        point_size: number of coordinates of one target point of the task (2 for
            (x, y), 3 for (x, y, φ) or (x, y, z), 6 for a pose given as position and
            angles), or 0 when the task is not a target kind (only a row selection).
    """

    name: str
    rows: tuple[int, ...]
    aliases: tuple[str, ...] = ()
    point_size: int = 0

    @property
    def coordinates(self) -> tuple[str, ...]:
        """Names of the rows, e.g. ('vx', 'vy', 'wz')."""
        return tuple(TASK_COORDINATES[r] for r in self.rows)


_TABLE = (
    Task("planar", (0, 1), point_size=2),
    Task("planar_pose", (0, 1, 5), point_size=3),
    Task("position", (0, 1, 2), point_size=3),
    Task("pose", (0, 1, 2, 3, 4, 5), aliases=("full",), point_size=6),
    Task("orientation", (3, 4, 5)),
)

#: Every task by canonical name and by alias.
TASKS: dict[str, Task] = {**{t.name: t for t in _TABLE},
                          **{a: t for t in _TABLE for a in t.aliases}}

#: All accepted names (canonical names and aliases).
TASK_NAMES: tuple[str, ...] = tuple(TASKS)

#: The tasks that are target kinds (paths, IK targets): canonical names.
TARGET_TASKS: tuple[str, ...] = tuple(t.name for t in _TABLE if t.point_size)


def get_task(name: object, *, targets_only: bool = False, what: str = "task") -> Task:
    """The :class:`Task` named ``name`` (canonical name or alias).

    Args:
        name: the task's name.
        targets_only: accept only target kinds (:data:`TARGET_TASKS` and their aliases).
        what: how the error message calls the argument ('task', 'path task', ...).

    Raises:
        InputError: unknown name (the message lists the accepted ones).
    """
    task = TASKS.get(name) if isinstance(name, str) else None
    if task is None or (targets_only and not task.point_size):
        names = [k for k, t in TASKS.items() if t.point_size or not targets_only]
        raise InputError(f"unknown {what} {short_repr(name)}; expected one of: "
                         f"{', '.join(names)}")
    return task


def task_rows(task: str | Sequence[int]) -> np.ndarray:
    """Row indices (m,) int64 of the twist / geometric Jacobian that form a task.

    Args:
        task: a task name or alias (see :data:`TASKS`: 'planar' (vx, vy), 'planar_pose'
            (vx, vy, wz), 'position' (vx, vy, vz), 'orientation' (wx, wy, wz),
            'pose'/'full' (all six)) or an explicit sequence of distinct row indices in 0..5.

    Raises:
        InputError: unknown name or rows that are not distinct integers in 0..5.
    """
    if isinstance(task, str):
        return np.array(get_task(task).rows, dtype=np.int64)
    try:
        rows = np.asarray(task)
    except (TypeError, ValueError):
        rows = np.zeros(0)
    if rows.ndim != 1 or rows.size == 0 or rows.dtype.kind not in "iu" \
            or rows.min() < 0 or rows.max() > 5 or len(set(rows.tolist())) != rows.size:
        raise InputError(f"task rows must be distinct integers in 0..5, got {short_repr(task)}")
    return rows.astype(np.int64)


def task_weights(task: str) -> tuple[float, ...]:
    """Default weights (6,) of a task: 1.0 on its rows, 0.0 elsewhere."""
    rows = get_task(task).rows
    return tuple(1.0 if r in rows else 0.0 for r in range(6))
