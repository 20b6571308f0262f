"""Inverse reachability: where on the floor must the base stand to reach every task pose.

Candidate base poses ``B(x, y, ψ) = Trans(x, y, z_floor) · Rz(ψ)`` place the robot's
world frame (its mounting frame: ``robot.fk`` is expressed in it) on a grid of the floor
plane with ``yaws`` headings ψ_j = 2πj/yaws. For each candidate and each task pose
``T_m`` (world frame) the robot must reach ``B⁻¹ T_m``; this is solved directly, with the
same solver as the maps (:func:`serialkin.reach.solve.solve_targets`: every closed-form
solution where one exists, else the numerical batch IK), so the result is exact at the
candidates, not looked up in a discretised map.

**Collisions.** A task pose counts as reached only with a collision-free solution: free
of self-collision (the robot's collision model ``robot.collision``, the pairs its
allowed-collision matrix checks: the model's default or one from a vendor SRDF) — on by
default when the robot has a collision model — and clear of the ``scene`` (obstacles in
the world frame, moved into the robot's frame of each candidate: ``B⁻¹`` applied to
them), keeping ``clearance`` [m]. Closed-form solutions are filtered one by one (exact);
the numerical IK is asked for a free solution.

**Margin.** How far a task pose lies inside the reachable set, on a reachability map of
the same robot and self-collision settings (:func:`serialkin.reach.reachability_map`,
computed here at ``map_resolution`` with ``map_orientations`` orientations, or a saved
one passed as ``reach_map``). With ``h`` the map's voxel edge, ``R`` the voxels reached
with at least one orientation (``ReachMap.reachable``; everything outside the map's grid
counts as unreachable) and ``p`` the task position in the candidate's robot frame::

    margin(p) = max(0, min over voxels u ∉ R of ‖c(v) − c(u)‖ − h/2)   if v(p) ∈ R, else 0

where ``v(p)`` is the voxel holding ``p`` and ``c(·)`` a voxel centre: the distance [m]
from the task to the edge of the reachable set, the edge taken midway between a reachable
and an unreachable voxel centre (a Euclidean distance transform of the map), accurate to
about ``h·√3/2``. It is a *position* margin: the reachable set is that of the map's
sampled orientations, not of the task's own orientation, and the scene is not in it
(the map is computed without one: obstacles stand still while the base moves). A task
that is not reached has margin 0.

**Score.** A candidate's score is lexicographic: first the number of task poses it
reaches, then the smallest margin over its task poses (a base whose tasks are all
reached but on the edge ranks below one with room), then the median margin, then the
*worst-case dexterity*: the smallest, over the task poses, of the largest manipulability
(eq 43) among each pose's free solutions. The candidates that reach every task pose form
the *base-placement distribution* (``BasePlacement.feasible``).

The floor region searched is by default the box of the task positions widened by the
robot's reach (the largest distance from its world origin of sampled tool positions).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path
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
from serialkin.errors import InputError, NotSupportedError
from serialkin.model.robot import Robot, check_robot
from serialkin.reach.chunk import restart_seed, robot_digest, voxel_starts
from serialkin.reach.grid import robot_reach_box
from serialkin.reach.reachmap import ReachMap, load_map
from serialkin.reach.solve import (
    CollisionOptions,
    NumericalOptions,
    check_collision_options,
    resolve_solver,
    solve_targets,
)
from serialkin.reach.store import differences

#: Orientations per voxel of the map computed for the margin when none is given.
MAP_ORIENTATIONS = 12


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
        margin: (nx, ny, nyaw, M) each task's distance from the edge of the reachable
            set [m] (module docstring; 0 where it is not reached).
        map_resolution: voxel edge of the map the margins were read on [m].
        self_collision: whether solutions had to be free of self-collision.
        clearance: the distance [m] a solution kept from collisions.
        reach_map: the :class:`ReachMap` the margins were read on (given or computed).
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
    margin: np.ndarray
    map_resolution: float
    self_collision: bool = False
    clearance: float = 0.0
    reach_map: ReachMap | None = None

    @property
    def margin_min(self) -> np.ndarray:
        """Smallest margin over the task poses per candidate [m], (nx, ny, nyaw)."""
        return self.margin.min(axis=-1)

    @property
    def margin_median(self) -> np.ndarray:
        """Median margin over the task poses per candidate [m], (nx, ny, nyaw)."""
        return np.median(self.margin, axis=-1)

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
                "self_collision": self.self_collision, "clearance": self.clearance,
                "map_resolution": self.map_resolution,
                "best": {"x": float(self.xs[i]), "y": float(self.ys[j]),
                         "yaw": float(self.yaws[k]), "z": self.floor_z,
                         "reached": int(self.reached[i, j, k]),
                         "margin_min": float(self.margin_min[i, j, k]),
                         "margin_median": float(self.margin_median[i, j, k]),
                         "margins": [float(v) for v in self.margin[i, j, k]],
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


def _check_spatial(robot: Robot) -> None:
    """Refuse what is not a spatial robot (base placement is on a floor plane).

    Raises:
        InputTypeError: not a Robot.
        InputError: a planar robot.
    """
    check_robot(robot)
    if robot.is_planar:
        raise InputError("base_placement places a spatial robot on a floor plane; "
                         f"{robot.name!r} is planar")


def _candidate_grid(robot: Robot, T: np.ndarray, region: object, res: float, yaws: int,
                    ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The candidates' floor coordinates xs (nx,), ys (ny,) [m] and headings (yaws,) [rad].

    The grid of spacing ``res`` covering the floor box (:func:`_floor_box`), headings
    ``2πj/yaws``.

    Raises:
        BudgetError: too many candidates × tasks for the memory budget.
    """
    box = _floor_box(robot, T, region)
    ix = (math.floor(box[0, 0] / res), math.ceil(box[0, 1] / res) + 1)
    iy = (math.floor(box[1, 0] / res), math.ceil(box[1, 1] / res) + 1)
    K = (ix[1] - ix[0]) * (iy[1] - iy[0]) * yaws
    check_allocation("the base-placement targets", (K, T.shape[0], 16), 8,
                     setting="resolution / region")
    return np.arange(*ix) * res, np.arange(*iy) * res, 2.0 * math.pi * np.arange(yaws) / yaws


def _reach_candidates(robot: Robot, task: str, rel: np.ndarray, sol: str,
                      q0: np.ndarray | None, opts: dict[str, Any], shapes: Any,
                      binv: np.ndarray | None) -> tuple[np.ndarray, np.ndarray]:
    """Which relative targets are reached (K·M,) bool, and the manipulability there (K·M,).

    ``rel`` (K·M, 4, 4) holds the task poses in each candidate's frame (candidates
    slowest); ``opts`` the keywords of :func:`solve_targets`. With a scene (``shapes``
    not None), ``binv`` (K, 4, 4) holds each candidate's ``B⁻¹``.
    """
    targets = rel if task == "pose" else np.ascontiguousarray(rel[:, :3, 3])
    ok, _, w = solve_targets(robot, task, targets, sol, q0=q0, **opts)
    if shapes is not None:
        # The scene stands still in the world: moved into each candidate's frame, it is
        # checked candidate by candidate, on the targets reached without it (a scene only
        # removes solutions of the closed form; the numerical IK solves them again).
        K = binv.shape[0]
        M = ok.size // K
        for c in np.flatnonzero(ok.reshape(K, M).any(axis=1)):
            rows = c * M + np.flatnonzero(ok[c * M:(c + 1) * M])
            ok[rows], _, w[rows] = solve_targets(
                robot, task, targets[rows], sol, q0=None if q0 is None else q0[rows],
                scene=scene_in_frame(shapes, binv[c]), **opts)
    return ok, w


def _rank_candidates(ok: np.ndarray, w: np.ndarray, margin: np.ndarray,
                     ) -> tuple[np.ndarray, np.ndarray, int]:
    """Reached counts (K,), dexterity (K,) and the index of the best candidate.

    ``ok``, ``w`` and ``margin`` are (K, M). The best reaches the most task poses, then
    has the largest smallest margin, then the largest median margin, then the largest
    dexterity (the smallest manipulability over the reached poses).
    """
    reached = ok.sum(axis=1)
    dex = np.where(ok, w, 0.0).min(axis=1)
    best = int(np.lexsort((-dex, -np.median(margin, axis=1), -margin.min(axis=1),
                           -reached))[0])
    return reached, dex, best


def base_placement(robot: Robot, tasks: object, *, resolution: float = 0.1, yaws: int = 8,
                   region: object = None, floor_z: float = 0.0, solver: str = "auto",
                   restarts: int = 5, tol: float = 1e-6, seed: int = 0,
                   scene: Any = None, self_collision: bool | None = None, acm: Any = None,
                   clearance: float = 0.0, reach_map: ReachMap | str | Path | None = None,
                   map_resolution: float | None = None,
                   map_orientations: int = MAP_ORIENTATIONS,
                   progress: bool | None = False) -> BasePlacement:
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
        scene: obstacles (a shape or a list of shapes of :mod:`serialkin.model.geometry`)
            in the world frame of the tasks; a solution must keep ``clearance`` from them.
        self_collision: solutions must be free of self-collision; None: when the robot
            has a collision model.
        acm: :class:`~serialkin.collision.acm.AllowedCollisionMatrix` of the self-collision
            check (e.g. ``acm_from_srdf(robot.collision, "panda.srdf")``); None: the
            model's default.
        clearance: smallest signed distance a solution keeps from collisions [m], >= 0.
        reach_map: the reachability map the margins are read on: a :class:`ReachMap`, or
            a map's output folder or ``.npz`` file; it must be of this robot (same chain
            hash), with the same self-collision settings and no scene, else it is refused
            naming each difference. None: one is computed.
        map_resolution: voxel edge [m] of the computed map (None: ``resolution``).
        map_orientations: orientations per voxel of the computed map.
        progress: progress bar of the computed map (None: only on a terminal).

    Returns:
        :class:`BasePlacement`.

    Raises:
        InputError: malformed tasks or region, resolution <= 0, yaws < 1, a planar robot,
            a collision check on a robot without a collision model, an incompatible
            ``reach_map`` (each difference named).
        BudgetError: too many candidates × tasks for the memory budget.
    """
    _check_spatial(robot)
    T = _task_poses(tasks)
    floor_z = check_real(floor_z, "floor_z", max_abs=1e6, unit="m")
    res = check_positive(resolution, "resolution")
    yaws = check_int(yaws, "yaws", minimum=1)
    seed = check_int(seed, "seed", minimum=0, maximum=2**63 - 1)
    if self_collision is None:
        self_collision = getattr(robot, "collision", None) is not None
    shapes = _scene_list(scene)
    collision = check_collision_options(robot, self_collision, acm, clearance, shapes)
    task = "pose" if robot.n >= 6 else "position"
    xs, ys, psi = _candidate_grid(robot, T, region, res, yaws)
    M, K = T.shape[0], xs.size * ys.size * yaws
    sol = resolve_solver(robot, task, solver)
    numerical = NumericalOptions(check_int(restarts, "restarts", minimum=0),
                                 check_positive(tol, "tol"))
    rmap = _margin_map(robot, task, collision, reach_map, map_resolution or res,
                       map_orientations, sol, numerical, seed, progress)
    rel = _relative_targets(T, xs, ys, psi, float(floor_z))
    q0 = voxel_starts(robot, seed, 0, K, M) if sol == "numerical" else None
    opts = {"seed": restart_seed(seed), "numerical": numerical, "collision": collision}
    binv = None if shapes is None else _base_inverses(xs, ys, psi, float(floor_z))
    ok, w = _reach_candidates(robot, task, rel, sol, q0, opts, shapes, binv)
    ok, w = ok.reshape(K, M), w.reshape(K, M)
    margin = np.where(ok, edge_margin(rmap, rel[:, :3, 3]).reshape(K, M), 0.0)
    reached, dex, best = _rank_candidates(ok, w, margin)
    shape = (xs.size, ys.size, yaws)
    i, j, k = (int(v) for v in np.unravel_index(best, shape))
    return BasePlacement(xs, ys, psi, float(floor_z), reached.reshape(shape),
                         dex.reshape(shape), M, base_pose(xs[i], ys[j], psi[k], float(floor_z)),
                         (i, j, k), margin.reshape(shape + (M,)), float(rmap.grid.resolution),
                         collision.self_collision, collision.clearance, rmap)


def edge_margin(rmap: ReachMap, points: np.ndarray) -> np.ndarray:
    """Distance [m] of points (P, 3) (the map's frame) from the edge of its reachable set.

    ``max(0, d(v) − h/2)`` for a point in a reachable voxel v, where d(v) is the distance
    from v's centre to the nearest centre of a voxel not reached with any orientation
    (the grid is surrounded by unreachable voxels) and h the voxel edge; 0 for a point in
    an unreachable voxel or outside the grid. Returns (P,).
    """
    from scipy.ndimage import distance_transform_edt

    h = float(rmap.grid.resolution)
    inside = np.pad(np.asarray(rmap.reachable, dtype=bool), 1, constant_values=False)
    d = distance_transform_edt(inside, sampling=h)[1:-1, 1:-1, 1:-1]
    field = np.where(rmap.reachable, np.maximum(d - 0.5 * h, 0.0), 0.0)
    P = np.asarray(points, dtype=float).reshape(-1, 3)
    idx = np.floor((P - np.asarray(rmap.grid.lower)) / h).astype(np.int64)
    shape = np.asarray(rmap.grid.shape)
    within = np.all((idx >= 0) & (idx < shape), axis=1)
    out = np.zeros(P.shape[0])
    out[within] = field[tuple(idx[within].T)]
    return out


def _margin_map(robot: Robot, task: str, collision: CollisionOptions, reach_map: object,
                resolution: float, orientations: int, solver: str,
                numerical: NumericalOptions, seed: int, progress: bool | None) -> ReachMap:
    """The map the margins are read on: ``reach_map`` checked, or one computed."""
    if reach_map is None:
        from serialkin.reach.execute import reachability_map

        return reachability_map(robot, resolution, orientations, task=task, solver=solver,
                                restarts=numerical.restarts, tol=numerical.tol, seed=seed,
                                self_collision=collision.self_collision, acm=collision.acm,
                                clearance=collision.clearance, progress=progress)
    if isinstance(reach_map, ReachMap):
        rmap, label = reach_map, "(a ReachMap)"
    elif isinstance(reach_map, (str, Path)):
        label = repr(str(reach_map))
        if Path(reach_map).is_dir() and not (Path(reach_map) / "map.npz").is_file():
            raise InputError(f"reach_map {label} holds no assembled map (map.npz): finish "
                             "the run with `serialkin reach ... --resume` first")
        rmap = load_map(reach_map)
    else:
        raise InputError(f"reach_map must be a ReachMap, a map folder or a .npz file, or "
                         f"None, got {type(reach_map).__name__}")
    check_map_fits(rmap, robot, collision, label)
    return rmap


def check_map_fits(rmap: ReachMap, robot: Robot, collision: CollisionOptions,
                   label: str = "(a ReachMap)") -> None:
    """Refuse a map the margins of this base placement cannot be read on.

    It must be of ``robot`` (the same chain hash), a spatial task ('pose' or
    'position'), computed with the same self-collision settings (flag, allowed-collision
    matrix, clearance) and without a scene (obstacles fixed to one base pose).

    Raises:
        InputError: naming each difference (``key: <value> in the map, <value> now``).
    """
    s = rmap.settings
    if not s or "robot_hash" not in s:
        raise InputError(f"reach_map {label} records no settings (robot, collision), so it "
                         "cannot be checked: use a map written by reachability_map / "
                         "`serialkin reach`")
    want = {"robot_hash": robot_digest(robot), "collision": collision.settings(robot),
            "scene_hash": None}
    have = {k: s.get(k) for k in want}
    if have["robot_hash"] != want["robot_hash"]:
        have["robot"], want["robot"] = s.get("robot"), robot.name
    diff = differences(have, want, "in the map")
    if s.get("task") not in ("pose", "position"):
        diff.append(f"task: {s.get('task')!r} in the map, 'pose' or 'position' now")
    if diff:
        raise InputError(f"reach_map {label} does not fit this base placement ("
                         + "; ".join(diff) + "); compute one for this robot with the same "
                         "self-collision settings (serialkin reach ... --self-collision, "
                         "--srdf, --clearance) and no scene, or let base placement compute it")


def _scene_list(scene: Any) -> list[Any] | None:
    """The scene as a list of shapes (None: no scene), validated by the scene encoder."""
    if scene is None:
        return None
    shapes = list(scene) if isinstance(scene, (list, tuple)) else [scene]
    from serialkin.collision.shapes import encode_scene

    encode_scene(shapes)
    return shapes


def scene_in_frame(shapes: list[Any], T: np.ndarray) -> list[Any]:
    """The shapes moved by the rigid transform T (4, 4): ``x' = R x + t`` for every point.

    Spheres, boxes, capsules, half-spaces and cylinders (an infinite cylinder along z
    stays one under a rotation about z, as base placement's are).

    Raises:
        NotSupportedError: another kind of shape.
    """
    import dataclasses

    from serialkin.model.geometry import Box, Capsule, Cylinder, HalfSpace, Sphere

    R, t = T[:3, :3], T[:3, 3]
    out = []
    for i, s in enumerate(shapes):
        if isinstance(s, Sphere):
            out.append(dataclasses.replace(s, center=R @ s.center + t))
        elif isinstance(s, (Box, Cylinder)):
            out.append(dataclasses.replace(s, center=R @ s.center + t, rotation=R @ s.rotation))
        elif isinstance(s, Capsule):
            out.append(Capsule(s.radius, a=R @ s.a + t, b=R @ s.b + t, influence=s.influence,
                               name=s.name))
        elif isinstance(s, HalfSpace):
            n = R @ s.normal
            out.append(dataclasses.replace(s, normal=n, offset=s.offset + float(n @ t)))
        else:
            raise NotSupportedError(f"scene[{i}]: a {type(s).__name__} cannot be moved with "
                                    "the base; use spheres, boxes, capsules, half-spaces or "
                                    "cylinders")
    return out


def _base_inverses(xs: np.ndarray, ys: np.ndarray, psi: np.ndarray,
                   floor_z: float) -> np.ndarray:
    """``B⁻¹`` of every candidate, (K, 4, 4), in (x, y, ψ) C order."""
    X, Y, P = np.meshgrid(xs, ys, psi, indexing="ij")
    K = X.size
    c, s = np.cos(P.ravel()), np.sin(P.ravel())
    # B⁻¹ = [Rzᵀ, −Rzᵀ t]
    Binv = np.zeros((K, 4, 4))
    Binv[:, 0, 0], Binv[:, 0, 1], Binv[:, 1, 0], Binv[:, 1, 1] = c, s, -s, c
    Binv[:, 2, 2] = Binv[:, 3, 3] = 1.0
    t = np.stack([X.ravel(), Y.ravel(), np.full(K, floor_z)], axis=-1)
    Binv[:, :3, 3] = -np.einsum("kij,kj->ki", Binv[:, :3, :3], t)
    return Binv


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
    Binv = _base_inverses(xs, ys, psi, floor_z)
    return np.einsum("kab,mbc->kmac", Binv, T).reshape(Binv.shape[0] * T.shape[0], 4, 4)
