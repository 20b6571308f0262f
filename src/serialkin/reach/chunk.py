"""One chunk of a reachability map: the job description and the per-chunk computation.

A :class:`ReachJob` holds everything a worker needs (robot, grid, orientations, solver
settings, seed); :func:`compute_chunk` turns chunk ``c`` into per-voxel statistics. It
is a plain function of ``(job, c)``, so the embedded loop and Dask workers run the same
code and chunks can be computed in any order, on any machine.

**Seeds.** The numerical solver's first guesses for voxel v come from the generator of
``numpy.random.SeedSequence(seed, spawn_key=(v,))`` — the v-th child that
``SeedSequence(seed).spawn`` hands out — and its restarts from one stream seeded by
``SeedSequence(seed)``, the same for every target (``robot.ik`` gives a target the same
answer alone or in any batch). Every number of a voxel therefore depends on the voxel
and the seed only: the map is bit-identical whatever the chunk size, the order of the
chunks and the number of workers. The closed-form solver draws nothing.

**Per voxel** (over the map's N orientations; one "orientation" for position tasks):

* ``reached`` — the number of orientations with at least one IK solution; the
  reachability index is ``reached / N``;
* ``solutions`` — the total number of solutions over the orientations;
* ``manipulability_mean``, ``_min``, ``_max`` — statistics over the reached orientations
  of each orientation's best manipulability (eq 43); 0 where nothing is reached.
"""

from __future__ import annotations

import hashlib
import pickle
import time
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from serialkin.reach.grid import VoxelGrid
from serialkin.reach.solve import (
    CollisionOptions,
    NumericalOptions,
    make_targets,
    oriented,
    solve_targets,
)

#: Per-voxel arrays of a chunk and of a map, with their dtypes.
FIELDS = {"reached": np.int32, "solutions": np.int32, "manipulability_mean": np.float64,
          "manipulability_min": np.float64, "manipulability_max": np.float64}


def _digest(*arrays: np.ndarray) -> str:
    h = hashlib.sha256()
    for a in arrays:
        a = np.ascontiguousarray(a)
        h.update(str(a.dtype).encode() + str(a.shape).encode())
        h.update(a.tobytes())
    return h.hexdigest()[:16]


def robot_digest(robot: Any) -> str:
    """Hash of what decides a robot's kinematics: chain arrays, joint kinds and limits."""
    c = robot.chain
    return _digest(np.asarray(c.F), np.asarray(c.meta), np.asarray(robot.qlim, dtype=float),
                   np.asarray(robot.revolute))


def scene_digest(scene: Any) -> str | None:
    """Hash of a collision scene (its pickle; its repr if it does not pickle), or None."""
    if scene is None:
        return None
    try:
        data = pickle.dumps(scene, protocol=4)
    except Exception:  # noqa: BLE001 - any object: fall back to its text
        data = repr(scene).encode("utf-8", "replace")
    return hashlib.sha256(data).hexdigest()[:16]


@dataclass(frozen=True, eq=False)
class ReachJob:
    """Everything needed to compute any chunk of a map.

    Attributes:
        robot: the robot.
        grid: the voxel grid.
        task: 'pose', 'position', 'planar_pose' or 'planar'.
        solver: 'closed_form' or 'numerical' (resolved).
        rotations: (N, 3, 3) tool orientations ('pose'), else None.
        headings: (N,) headings [rad] ('planar_pose'), else None.
        sampling: how the orientations were made (for the record).
        seed: root seed (see the module docstring).
        numerical: options of the numerical solver.
        chunk_voxels: voxels per chunk.
        scene: collision scene (the robot's world frame), or None.
        collision: self-collision and clearance of a solution (see
            :mod:`serialkin.reach.solve`).
    """

    robot: Any
    grid: VoxelGrid
    task: str
    solver: str
    rotations: np.ndarray | None
    headings: np.ndarray | None
    sampling: str
    seed: int
    numerical: NumericalOptions
    chunk_voxels: int
    scene: Any = field(default=None)
    collision: CollisionOptions = field(default=CollisionOptions())

    @property
    def orientations(self) -> int:
        """Number N of orientations per voxel (1 for position tasks)."""
        if self.rotations is not None:
            return int(self.rotations.shape[0])
        if self.headings is not None:
            return int(self.headings.shape[0])
        return 1

    @property
    def chunks(self) -> int:
        """Number of chunks."""
        return max(1, -(-self.grid.size // self.chunk_voxels))

    def chunk_range(self, c: int) -> tuple[int, int]:
        """Flat voxel indices ``start, stop`` of chunk c."""
        start = c * self.chunk_voxels
        return start, min(start + self.chunk_voxels, self.grid.size)

    def settings(self) -> dict[str, Any]:
        """The settings that decide the map's values, JSON-ready (the manifest's record).

        ``collision`` (self-collision flag, ACM hash, clearance [m]) is recorded only when
        a self-collision check or a clearance is asked for, so that maps written before
        it existed still resume.
        """
        ori = self.rotations if self.rotations is not None else self.headings
        out = {
            "robot": self.robot.name,
            "robot_hash": robot_digest(self.robot),
            "resolution": self.grid.resolution,
            "grid_lower": list(self.grid.lower),
            "grid_shape": list(self.grid.shape),
            "task": self.task,
            "solver": self.solver,
            "orientations": self.orientations,
            "sampling": self.sampling,
            "orientations_hash": None if ori is None else _digest(ori),
            "seed": self.seed,
            "restarts": self.numerical.restarts,
            "tol": self.numerical.tol,
            "max_iter": self.numerical.max_iter,
            "scene_hash": scene_digest(self.scene),
            "chunk_voxels": self.chunk_voxels,
        }
        collision = self.collision.settings(self.robot)
        if collision is not None:
            out["collision"] = collision
        return out


def voxel_starts(robot: Any, seed: int, start: int, stop: int, count: int) -> np.ndarray:
    """First guesses of voxels ``start..stop−1``: ``count`` each, uniform in the limits.

    Voxel v's come from ``SeedSequence(seed, spawn_key=(v,))``. Returns
    ((stop − start)·count, n).
    """
    lo, hi = robot.sampling_limits().T
    U = np.empty((stop - start, count, robot.n))
    for i, v in enumerate(range(start, stop)):
        rng = np.random.Generator(np.random.PCG64(np.random.SeedSequence(seed, spawn_key=(v,))))
        U[i] = rng.random((count, robot.n))
    return (lo + (hi - lo) * U).reshape(-1, robot.n)


def restart_seed(seed: int) -> int:
    """The restart stream seed of a map (the same for every target)."""
    return int(np.random.SeedSequence(seed).generate_state(1, np.uint64)[0])


def compute_chunk(job: ReachJob, c: int) -> dict[str, Any]:
    """Per-voxel statistics of chunk ``c`` (see the module docstring).

    Returns:
        ``{"chunk": c, "start": ..., "stop": ..., "seconds": wall time [s],
        "reached": (B,) int32, "solutions": (B,) int32, "manipulability_*": (B,)}``.
    """
    t0 = time.perf_counter()
    start, stop = job.chunk_range(c)
    B = stop - start
    N = job.orientations if oriented(job.task) else 1
    P = job.grid.centres(start, stop)
    targets = make_targets(job.task, P, job.rotations, job.headings)
    q0 = voxel_starts(job.robot, job.seed, start, stop, N) if job.solver == "numerical" \
        else None
    ok, nsol, w = solve_targets(job.robot, job.task, targets, job.solver, q0=q0,
                                seed=restart_seed(job.seed), numerical=job.numerical,
                                scene=job.scene, collision=job.collision)
    ok, nsol, w = ok.reshape(B, N), nsol.reshape(B, N), w.reshape(B, N)
    reached = ok.sum(axis=1).astype(np.int32)
    out: dict[str, Any] = {"chunk": c, "start": start, "stop": stop,
                           "reached": reached,
                           "solutions": nsol.sum(axis=1).astype(np.int32)}
    with np.errstate(invalid="ignore", divide="ignore"):
        wsum = np.where(ok, w, 0.0).sum(axis=1)
        out["manipulability_mean"] = np.where(reached > 0, wsum / np.maximum(reached, 1), 0.0)
    out["manipulability_min"] = np.where(reached > 0, np.where(ok, w, np.inf).min(axis=1), 0.0)
    out["manipulability_max"] = np.where(reached > 0, np.where(ok, w, -np.inf).max(axis=1), 0.0)
    out["seconds"] = time.perf_counter() - t0
    return out
