"""Inverse reachability: where on the floor must the base stand to reach every task pose.

Candidate base poses ``B(x, y, ψ) = Trans(x, y, z_floor) · Rz(ψ)`` place the robot's
world frame (its mounting frame: ``robot.fk`` is expressed in it) on a grid of the floor
plane with ``yaws`` headings ψ_j = 2πj/yaws. For each candidate and each task pose
``T_m`` (world frame) the robot must reach ``B⁻¹ T_m``; this is solved directly, with the
same solver as the maps (:func:`serialkin.reach.solve.solve_targets`: every closed-form
solution where one exists, else the numerical batch IK), so the result is exact at the
candidates, not looked up in a discretised map.

**Score.** A candidate's score is lexicographic: first the number of task poses it
reaches, then the *worst-case dexterity*: the smallest, over the task poses, of the
largest manipulability (eq 43) among each pose's solutions. The best base pose reaches
the most task poses and, among those that reach as many, stays farthest from
singularities on its hardest pose. The candidates that reach every task pose form the
*base-placement distribution* (``BasePlacement.feasible``).

The floor region searched is by default the box of the task positions widened by the
robot's reach (the largest distance from its world origin of sampled tool positions).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from serialkin._budget import check_allocation
from serialkin._checks import (
    as_float_array,
    check_int,
    check_positive,
    check_real,
    check_transform,
)
from serialkin.errors import InputError
from serialkin.model.robot import Robot, check_robot
from serialkin.reach.chunk import restart_seed, voxel_starts
from serialkin.reach.grid import robot_reach_box
from serialkin.reach.solve import NumericalOptions, resolve_solver, solve_targets


@dataclass(frozen=True, eq=False)
class BasePlacement:
    """Result of :func:`base_placement`.

    Attributes:
        xs, ys: (nx,), (ny,) candidate base positions on the floor [m].
        yaws: (nyaw,) candidate headings [rad].
        floor_z: height of the floor plane [m].
        reached: (nx, ny, nyaw) int, task poses reached from each candidate.
        dexterity: (nx, ny, nyaw), the worst task's best manipulability (0 if one fails).
        tasks: M, the number of task poses.
        best: (4, 4) the best base pose (world from robot base).
        best_index: (i, j, k) of the best candidate.
    """

    xs: np.ndarray
    ys: np.ndarray
    yaws: np.ndarray
    floor_z: float
    reached: np.ndarray
    dexterity: np.ndarray
    tasks: int
    best: np.ndarray
    best_index: tuple[int, int, int]

    @property
    def feasible(self) -> np.ndarray:
        """Candidates that reach every task pose, (nx, ny, nyaw) bool."""
        return self.reached == self.tasks

    @property
    def feasible_fraction(self) -> np.ndarray:
        """Per floor cell, the fraction of headings that reach every task pose, (nx, ny)."""
        return self.feasible.mean(axis=2)

    def summary(self) -> dict[str, Any]:
        """JSON-ready summary."""
        i, j, k = self.best_index
        return {"tasks": self.tasks, "candidates": int(self.reached.size),
                "feasible_candidates": int(self.feasible.sum()),
                "best": {"x": float(self.xs[i]), "y": float(self.ys[j]),
                         "yaw": float(self.yaws[k]), "z": self.floor_z,
                         "reached": int(self.reached[i, j, k]),
                         "dexterity": float(self.dexterity[i, j, k])}}


def base_pose(x: float, y: float, yaw: float, z: float = 0.0) -> np.ndarray:
    """``Trans(x, y, z)·Rz(yaw)``, (4, 4)."""
    c, s = math.cos(yaw), math.sin(yaw)
    return np.array([[c, -s, 0.0, x], [s, c, 0.0, y], [0.0, 0.0, 1.0, z], [0, 0, 0, 1.0]])


def _task_poses(tasks: object) -> np.ndarray:
    a = as_float_array(tasks, "tasks")
    if a.ndim == 2 and a.shape == (4, 4):
        a = a[None]
    if a.ndim != 3 or a.shape[1:] != (4, 4) or a.shape[0] == 0:
        raise InputError(f"tasks must be (M, 4, 4) poses with M >= 1, got shape {a.shape}")
    for m in range(a.shape[0]):
        check_transform(a[m], f"tasks[{m}]")
    return a


def base_placement(robot: Robot, tasks: object, *, resolution: float = 0.1, yaws: int = 8,
                   region: object = None, floor_z: float = 0.0, solver: str = "auto",
                   restarts: int = 5, tol: float = 1e-6, seed: int = 0,
                   scene: Any = None) -> BasePlacement:
    """Base poses on the floor that reach the task poses, and the best one (module docstring).

    Args:
        robot: a spatial robot (its world frame is the mounting frame placed at B).
        tasks: (M, 4, 4) task poses in the world frame [m].
        resolution: spacing of the floor grid [m], > 0.
        yaws: number of headings ψ_j = 2πj/yaws (1: no yaw, the robot keeps ψ = 0).
        region: ((xmin, xmax), (ymin, ymax)) [m]; default the task box widened by the reach.
        floor_z: height of the floor plane [m].
        solver: 'auto', 'closed_form' or 'numerical', as for the maps.
        restarts: restarts of the numerical solver.
        tol: its position [m] / orientation [rad] tolerance.
        seed: root seed of the numerical solver's starts (candidate c uses
            ``SeedSequence(seed, spawn_key=(c,))``).
        scene: collision scene (world frame of the robot) passed to the numerical IK.

    Returns:
        :class:`BasePlacement`.

    Raises:
        InputError: malformed tasks or region, resolution <= 0, yaws < 1, a planar robot.
        BudgetError: too many candidates × tasks for the memory budget.
    """
    check_robot(robot)
    if robot.is_planar:
        raise InputError("base_placement places a spatial robot on a floor plane; "
                         f"{robot.name!r} is planar")
    T = _task_poses(tasks)
    floor_z = check_real(floor_z, "floor_z", max_abs=1e6, unit="m")
    res = check_positive(resolution, "resolution")
    yaws = check_int(yaws, "yaws", minimum=1)
    seed = check_int(seed, "seed", minimum=0, maximum=2**63 - 1)
    task = "pose" if robot.n >= 6 else "position"
    box = _floor_box(robot, T, region)
    ix = (math.floor(box[0, 0] / res), math.ceil(box[0, 1] / res) + 1)
    iy = (math.floor(box[1, 0] / res), math.ceil(box[1, 1] / res) + 1)
    M = T.shape[0]
    K = (ix[1] - ix[0]) * (iy[1] - iy[0]) * yaws
    check_allocation("the base-placement targets", (K, M, 16), 8, setting="resolution / region")
    xs = np.arange(*ix) * res
    ys = np.arange(*iy) * res
    psi = 2.0 * math.pi * np.arange(yaws) / yaws
    sol = resolve_solver(robot, task, solver, scene)
    rel = _relative_targets(T, xs, ys, psi, float(floor_z))
    targets = rel if task == "pose" else np.ascontiguousarray(rel[:, :3, 3])
    q0 = voxel_starts(robot, seed, 0, K, M) if sol == "numerical" else None
    ok, _, w = solve_targets(robot, task, targets, sol, q0=q0, seed=restart_seed(seed),
                             numerical=NumericalOptions(check_int(restarts, "restarts"),
                                                        check_positive(tol, "tol")),
                             scene=scene)
    ok, w = ok.reshape(K, M), w.reshape(K, M)
    reached = ok.sum(axis=1)
    dex = np.where(ok, w, 0.0).min(axis=1)
    best = int(np.lexsort((-dex, -reached))[0])
    shape = (xs.size, ys.size, yaws)
    i, j, k = (int(v) for v in np.unravel_index(best, shape))
    return BasePlacement(xs, ys, psi, float(floor_z), reached.reshape(shape),
                         dex.reshape(shape), M, base_pose(xs[i], ys[j], psi[k], float(floor_z)),
                         (i, j, k))


def _floor_box(robot: Robot, T: np.ndarray, region: object) -> np.ndarray:
    """((xmin, xmax), (ymin, ymax)) [m] searched: ``region``, or the task box widened by the reach.

    ``T`` is (M, 4, 4), the task poses; raises InputError for a malformed ``region``.
    """
    if region is None:
        lo, hi = robot_reach_box(robot)
        reach = float(np.max(np.abs(np.concatenate([lo, hi]))))
        return np.array([[T[:, 0, 3].min() - reach, T[:, 0, 3].max() + reach],
                         [T[:, 1, 3].min() - reach, T[:, 1, 3].max() + reach]])
    box = as_float_array(region, "region")
    if box.shape != (2, 2) or not np.all(box[:, 0] <= box[:, 1]):
        raise InputError("region must be ((xmin, xmax), (ymin, ymax)) with min <= max "
                         f"[m], got {box.tolist() if box.size <= 8 else box.shape}")
    return box


def _relative_targets(T: np.ndarray, xs: np.ndarray, ys: np.ndarray, psi: np.ndarray,
                      floor_z: float) -> np.ndarray:
    """Every task pose in the robot's frame for every candidate base: ``B⁻¹ T_m``.

    Args:
        T: (M, 4, 4) task poses in the world frame [m].
        xs: (nx,) candidate x [m].
        ys: (ny,) candidate y [m].
        psi: (nyaw,) candidate headings [rad].
        floor_z: height of the floor plane [m].

    Returns:
        (K·M, 4, 4), K = nx·ny·nyaw candidates in (x, y, ψ) C order, tasks fastest.
    """
    X, Y, P = np.meshgrid(xs, ys, psi, indexing="ij")
    K = X.size
    M = T.shape[0]
    c, s = np.cos(P.ravel()), np.sin(P.ravel())
    # B⁻¹ = [Rzᵀ, −Rzᵀ t]: targets in the robot's frame for every candidate and task
    Binv = np.zeros((K, 4, 4))
    Binv[:, 0, 0], Binv[:, 0, 1], Binv[:, 1, 0], Binv[:, 1, 1] = c, s, -s, c
    Binv[:, 2, 2] = Binv[:, 3, 3] = 1.0
    t = np.stack([X.ravel(), Y.ravel(), np.full(K, floor_z)], axis=-1)
    Binv[:, :3, 3] = -np.einsum("kij,kj->ki", Binv[:, :3, :3], t)
    return np.einsum("kab,mbc->kmac", Binv, T).reshape(K * M, 4, 4)
