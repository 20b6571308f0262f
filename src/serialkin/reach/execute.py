"""Running a map: embedded (in-process, all cores) by default, or on a Dask cluster.

* **Embedded** (``client=None``): the chunks run one after the other in this process;
  each chunk's IK batch uses every free core through the library's one batch scheduler
  (``robot.ik`` → :func:`serialkin.kinematics.parallel.run`). No Dask import.
* **Dask** (``client=`` a ``dask.distributed.Client``): one task per chunk
  (:func:`serialkin.reach.chunk.compute_chunk`), results collected as they finish and
  written by this process (the workers need no shared disk). Dask is the optional extra
  ``serialkin[dist]``; :func:`connect` opens a client to a scheduler address with a
  timeout, :func:`local_cluster` starts N worker processes on this machine.

Either way a chunk's file is written as soon as it is finished (with ``out=``), the
progress bar advances by chunks, and each chunk's wall time is kept in the map
(``chunk_seconds``) and in ``metadata.json``. Seeds depend on the voxel only (see
:mod:`serialkin.reach.chunk`), so both paths give the same map, bit for bit.
"""

from __future__ import annotations

import json
import os
from pathlib import Path
from typing import Any

import numpy as np

from serialkin._budget import check_allocation
from serialkin._checks import check_choice, check_int, check_positive
from serialkin._io import write_text_atomic
from serialkin.errors import InputError, InputTypeError
from serialkin.model.robot import Robot, check_robot
from serialkin.reach import store
from serialkin.reach.chunk import FIELDS, ReachJob, compute_chunk
from serialkin.reach.grid import check_map_size, make_grid
from serialkin.reach.orientations import SAMPLINGS, orientation_set, planar_headings
from serialkin.reach.reachmap import ReachMap
from serialkin.reach.solve import (
    TASKS,
    NumericalOptions,
    check_collision_options,
    default_task,
    resolve_solver,
)

#: Default voxels per chunk (about a second of UR5 closed-form IK at 50 orientations).
CHUNK_VOXELS = 512

#: Seconds to wait for a Dask scheduler to answer.
CONNECT_TIMEOUT = 5.0
#: Most worker processes of a local cluster per core of this machine (more only share
#: the same cores and multiply the memory; a larger cluster runs on other machines).
LOCAL_WORKERS_PER_CORE = 4

_DIST_HINT = 'the Dask executor needs the extra: pip install "serialkin[dist]"'


def _distributed() -> Any:
    try:
        import dask.distributed as dd
    except ImportError as exc:  # pragma: no cover - the extra is installed in CI
        raise InputError(f"{_DIST_HINT} ({exc})") from exc
    return dd


def connect(address: str, timeout: float = CONNECT_TIMEOUT) -> Any:
    """A ``dask.distributed.Client`` connected to the scheduler at ``address``.

    Args:
        address: e.g. ``'tcp://10.0.0.5:8786'``.
        timeout: seconds to wait for the scheduler to answer.

    Raises:
        InputError: no answer within ``timeout`` (the address and the time are named),
            or Dask is not installed (the extra to install is named).
    """
    import threading

    timeout = check_positive(timeout, "timeout")
    dd = _distributed()
    # Dask's own timeout covers opening the connection, not a peer that accepts it and
    # never answers the handshake: the whole connection runs in a daemon thread that is
    # abandoned when the time is up, so the promised timeout holds for every stage.
    box: dict[str, Any] = {}

    def attempt() -> None:
        try:
            box["client"] = dd.Client(address, timeout=timeout)
        except BaseException as exc:  # noqa: BLE001 - handed to the caller below
            box["error"] = exc

    worker = threading.Thread(target=attempt, name="serialkin-dask-connect", daemon=True)
    worker.start()
    worker.join(timeout + 1.0)
    try:
        if worker.is_alive():
            raise TimeoutError(f"no complete answer in {timeout:g} s")
        if "error" in box:
            raise box["error"]
        return box["client"]
    except (OSError, TimeoutError, ValueError) as exc:
        raise InputError(f"the Dask scheduler {address!r} did not answer within "
                         f"{timeout:g} s ({type(exc).__name__}: {exc}); check the address "
                         "and that the scheduler runs") from exc
    except Exception as exc:  # noqa: BLE001 - something answered, not in Dask's protocol
        # (e.g. another service on that port: Dask then reads garbage frame lengths and
        # fails with MemoryError or a deserialisation error)
        raise InputError(f"{address!r} answered but not as a Dask scheduler "
                         f"({type(exc).__name__}: {str(exc)[:120]}); check the address and "
                         "the port") from exc


def local_cluster(workers: int, threads_per_worker: int = 1,
                  cores_per_worker: int | None = None) -> Any:
    """A client of a new ``LocalCluster`` of ``workers`` processes (close it when done).

    The machine's cores are shared out: each worker process runs its compiled batch
    kernels on ``cores_per_worker`` threads (``NUMBA_NUM_THREADS`` in the workers'
    environment; default ``max(1, cores // workers)``), so that N workers on one machine
    do not each start a thread per core and fight over them.

    Raises:
        InputError: workers or cores_per_worker < 1, more workers than
            :data:`LOCAL_WORKERS_PER_CORE` per core of this machine (at least 4), or Dask
            is not installed.
    """
    cores = (len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity")
             else os.cpu_count()) or 1
    most = max(4, LOCAL_WORKERS_PER_CORE * cores)
    workers = check_int(workers, "workers", minimum=1)
    if workers > most:
        raise InputError(f"workers={workers}: a local cluster runs at most {most} worker "
                         f"processes on this machine's {cores} core(s) "
                         f"({LOCAL_WORKERS_PER_CORE} per core); more would only share the "
                         "same cores. A larger cluster runs on other machines: connect to "
                         "its scheduler (--scheduler ADDRESS)")
    if cores_per_worker is None:
        cores_per_worker = max(1, cores // workers)
    share = str(check_int(cores_per_worker, "cores_per_worker", minimum=1))
    dd = _distributed()
    cluster = dd.LocalCluster(n_workers=workers, threads_per_worker=threads_per_worker,
                              processes=True, dashboard_address=":0",
                              env={"NUMBA_NUM_THREADS": share},
                              scheduler_kwargs={"dashboard": False})  # HTTP on a free port
    return dd.Client(cluster)


def make_job(robot: Robot, resolution: float, orientations: int = 50, *,
             sampling: str = "uniform", rolls: int = 1, bounds: object = None,
             task: str | None = None, solver: str = "auto", restarts: int = 5,
             tol: float = 1e-6, max_iter: int | None = None, seed: int = 0,
             scene: Any = None, chunk_voxels: int = CHUNK_VOXELS,
             self_collision: bool = False, acm: Any = None,
             clearance: float = 0.0) -> ReachJob:
    """Validate a map's settings and build its :class:`ReachJob` (see :func:`reachability_map`)."""
    check_robot(robot)
    task = default_task(robot) if task is None else check_choice(task, "task", TASKS)
    if task.startswith("planar") and not robot.is_planar:
        raise InputError(f"task {task!r} needs a planar robot; {robot.name!r} is spatial")
    orientations = check_int(orientations, "orientations", minimum=1)
    sampling = check_choice(sampling, "sampling", SAMPLINGS)
    seed = check_int(seed, "seed", minimum=0, maximum=2**63 - 1)
    chunk_voxels = check_int(chunk_voxels, "chunk_voxels", minimum=1)
    numerical = NumericalOptions(check_int(restarts, "restarts", minimum=0),
                                 check_positive(tol, "tol"),
                                 None if max_iter is None else check_int(max_iter, "max_iter",
                                                                         minimum=1))
    rolls = check_int(rolls, "rolls", minimum=1)
    count = orientations * rolls if sampling == "approach" and task == "pose" else orientations
    check_allocation("the orientation set", (count, 3, 3), 8, setting="orientations")
    rotations = headings = None
    if task == "pose":
        rotations = orientation_set(orientations, sampling, rolls=rolls)
    elif task == "planar_pose":
        headings = planar_headings(orientations)
        sampling = "headings"
    else:
        sampling = "none"
    grid = make_grid(robot, resolution, bounds, planar=task.startswith("planar"))
    n_ori = 1 if rotations is None and headings is None else \
        (len(rotations) if rotations is not None else len(headings))  # type: ignore[arg-type]
    check_map_size(grid.shape, n_ori)
    check_allocation("one chunk's IK targets", (min(chunk_voxels, grid.size), n_ori, 16), 8,
                     setting="chunk_voxels (--chunk-voxels)")
    solver = resolve_solver(robot, task, solver, scene)
    collision = check_collision_options(robot, self_collision, acm, clearance, scene)
    if scene is not None:  # refuse a scene the IK does not take before anything is written
        robot.ik(robot.fk(np.zeros(robot.n)), method="lm", scene=scene, max_iter=1,
                 restarts=0, seed=0)
    return ReachJob(robot, grid, task, solver, rotations, headings, sampling, seed, numerical,
                    chunk_voxels, scene, collision)


def _progress(total: int, progress: bool | None) -> Any:
    from tqdm import tqdm

    return tqdm(total=total, desc="reach", unit="chunk",
                disable=None if progress is None else not progress, leave=False)


def run_job(job: ReachJob, *, out: str | Path | None = None, resume: bool = False,
            client: Any = None, progress: bool | None = None) -> ReachMap:
    """Compute every chunk of ``job`` (embedded or on ``client``) and assemble the map.

    With ``out`` every chunk is written as soon as it finishes and, with ``resume``,
    chunks already in the folder are read instead of recomputed; the assembled map is
    written to ``out/map.npz`` and a summary with per-chunk timings to
    ``out/metadata.json``.
    """
    settings = job.settings()
    folder = store.open_folder(out, settings, resume) if out is not None else None
    C = job.chunks
    results: dict[int, dict[str, Any]] = {}
    if folder is not None and resume:
        for c in sorted(store.done_chunks(folder, C)):
            r = store.read_chunk(folder, c, *job.chunk_range(c), job.orientations)
            if r is not None:
                results[c] = r
    pending = [c for c in range(C) if c not in results]
    fresh: set[int] = set()

    def sink(r: dict[str, Any]) -> None:
        if folder is not None:
            store.write_chunk(folder, r)
        results[int(r["chunk"])] = r
        fresh.add(int(r["chunk"]))
        bar.update(1)

    with _progress(C, progress) as bar:
        bar.update(C - len(pending))
        if client is None:
            for c in pending:
                sink(compute_chunk(job, c))
        elif pending:
            dd = _distributed()
            [job_future] = client.scatter([job], broadcast=True, hash=False)
            futures = [client.submit(compute_chunk, job_future, c, pure=False) for c in pending]
            for fut in dd.as_completed(futures):
                sink(fut.result())
                fut.release()
    shape = job.grid.shape
    arrays = {k: np.empty(job.grid.size, dtype=t) for k, t in FIELDS.items()}
    seconds = np.full(C, np.nan)
    for c, r in results.items():
        start, stop = job.chunk_range(c)
        for k in FIELDS:
            arrays[k][start:stop] = r[k]
        seconds[c] = r["seconds"]
    m = ReachMap(job.grid, job.orientations, chunk_seconds=seconds, settings=settings,
                 **{k: v.reshape(shape) for k, v in arrays.items()})
    if folder is not None:
        m.save(folder / "map.npz")
        meta = {"summary": m.summary(), "settings": settings,
                "chunk_seconds": [None if not np.isfinite(s) else float(s) for s in seconds],
                "recomputed_chunks": len(fresh), "resumed_chunks": C - len(fresh),
                "executor": "embedded" if client is None else "dask"}
        write_text_atomic(folder / "metadata.json", json.dumps(meta, indent=1))
    return m


def reachability_map(robot: Robot, resolution: float, orientations: int = 50, *,
                     sampling: str = "uniform", rolls: int = 1, bounds: object = None,
                     task: str | None = None, solver: str = "auto", restarts: int = 5,
                     tol: float = 1e-6, max_iter: int | None = None, seed: int = 0,
                     scene: Any = None, chunk_voxels: int = CHUNK_VOXELS,
                     out: str | Path | None = None, resume: bool = False, client: Any = None,
                     progress: bool | None = None, self_collision: bool = False,
                     acm: Any = None, clearance: float = 0.0) -> ReachMap:
    """Reachability map: per voxel, the fraction of N tool orientations the robot reaches.

    For every voxel centre p and orientation R_k the target ``T = [R_k p; 0 1]`` is
    solved (:mod:`serialkin.reach.solve`); the voxel's reachability index is
    ``#{k : T reached} / N``, with the number of solutions and manipulability
    statistics (:mod:`serialkin.reach.chunk`).

    Args:
        robot: the robot.
        resolution: voxel edge [m], > 0.
        orientations: N for 'uniform' sampling; the number of approach directions for
            'approach'; the number of headings for planar arms.
        sampling: 'uniform' (super-Fibonacci over SO(3)) or 'approach' (directions ×
            ``rolls``); see :mod:`serialkin.reach.orientations`.
        rolls: rolls per approach direction.
        bounds: (3, 2) box [m] (lower, upper per axis); default the robot's reach box.
        task: 'pose', 'position', 'planar_pose' or 'planar' (default: 'pose' for spatial
            robots with ≥ 6 joints, 'position' below; 'planar_pose' for planar arms with
            ≥ 3 joints, 'planar' below). Position tasks have one "orientation".
        solver: 'auto', 'closed_form' or 'numerical' (:mod:`serialkin.reach.solve`).
        restarts: restarts of the numerical solver (``robot.ik(method='lm')``).
        tol: its position [m] / orientation [rad] tolerance.
        max_iter: its iterations per attempt (None: the method's default).
        seed: root seed, an int >= 0 (see :mod:`serialkin.reach.chunk`).
        scene: collision scene (the robot's world frame): a target counts only with a
            solution clear of it (:mod:`serialkin.reach.solve`).
        chunk_voxels: voxels per chunk (the unit of work, of streaming and of resuming).
        out: folder to stream chunks to (see :mod:`serialkin.reach.store`); None keeps
            everything in memory.
        resume: continue the run in ``out``, recomputing only missing chunks.
        client: a ``dask.distributed.Client`` to run the chunks on; None runs embedded.
        progress: tqdm bar over chunks (None: only on a terminal).
        self_collision: a target counts only with a solution free of self-collision
            (the robot's collision model, pairs not allowed by ``acm``).
        acm: :class:`~serialkin.collision.acm.AllowedCollisionMatrix` (e.g. from a vendor
            SRDF, :func:`~serialkin.collision.acm_from_srdf`); None: the model's default.
        clearance: smallest signed distance a solution keeps from collisions [m], >= 0.

    Returns:
        :class:`ReachMap`.

    Raises:
        InputError: resolution <= 0, unknown names, a folder of another map (the
            differences named), a planar task on a spatial robot.
        BudgetError: the grid does not fit the memory budget (its size and how to shrink
            it are named).
    """
    job = make_job(robot, resolution, orientations, sampling=sampling, rolls=rolls,
                   bounds=bounds, task=task, solver=solver, restarts=restarts, tol=tol,
                   max_iter=max_iter, seed=seed, scene=scene, chunk_voxels=chunk_voxels,
                   self_collision=self_collision, acm=acm, clearance=clearance)
    if client is not None and not callable(getattr(client, "submit", None)):
        raise InputTypeError(f"client must be a dask.distributed.Client, got "
                             f"{type(client).__name__}")
    return run_job(job, out=out, resume=resume, client=client, progress=progress)
