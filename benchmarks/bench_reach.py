"""Reachability maps (issue 15): IK calls per second, Dask scaling, projected map time.

Run by hand: ``.venv/bin/python benchmarks/bench_reach.py [--chunks K] [--repeat R]
[--full] [--no-dask] [--no-peers]``.

The job is the issue's: UR5 at 5 cm voxels with 50 uniform orientations per voxel
(closed-form ``ik_all`` for every target, the library's choice for this robot). Timing
the whole map takes minutes, so by default K chunks of 512 voxels spread evenly over the
grid (every C/K-th chunk: inside, rim and outside of the workspace alike) are computed
R times:

* **embedded** — ``compute_chunk`` in this process (what ``reachability_map`` runs
  without a client), its runs interleaved with the Dask runs below;
* **Dask, 1 and 2 worker processes** — ``LocalCluster``s with one thread and one core per worker,
  the same chunks as tasks (after an untimed warm-up that loads the compiled kernels in
  every worker), the runs of the two clusters interleaved; scaling efficiency =
  rate(2) / (2 · rate(1));
* the **numerical** solver (batch LM, 5 restarts) on one chunk, for robots without a
  closed form;
* peer, same run: Robotics Toolbox for Python's compiled ``ik_LM`` (one call per target,
  its C++ Levenberg–Marquardt) on the same targets, IK calls per second.

The projected time of the 2.5 cm × 50-orientation map is 6.5·10⁷ IK calls divided by the
best measured 2-core rate (``record("15.1", ...)``; goal < 1 h), and the Dask scaling
efficiency is recorded against its goal ≥ 0.85. Other processes on the machine disturb
every figure; the header prints the load average.
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path
from typing import Any

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "src"))

from _common import Stat, header, record  # noqa: E402

from serialkin import models  # noqa: E402
from serialkin.reach.chunk import compute_chunk  # noqa: E402
from serialkin.reach.execute import local_cluster, make_job  # noqa: E402

BIG_MAP_CALLS = 6.5e7


def _chunks(job, k: int) -> list[int]:
    C = job.chunks
    return sorted({int(c) for c in np.linspace(0, C - 1, min(k, C))})


def _targets(job, chunks: list[int]) -> int:
    return sum(np.subtract(*job.chunk_range(c)[::-1]) for c in chunks) * job.orientations


def _embedded(job, chunks: list[int], repeat: int) -> Stat:
    calls = _targets(job, chunks)
    compute_chunk(job, chunks[0])  # compile / load the kernels
    rates = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        for c in chunks:
            compute_chunk(job, c)
        rates.append(calls / (time.perf_counter() - t0))
    return Stat(rates)


def _interleaved(job, chunks: list[int], workers: tuple[int, ...], repeat: int
                 ) -> dict[str, Stat]:
    """IK calls/s embedded and on LocalClusters of each size in ``workers``, interleaved.

    All clusters stay up during the measurement and the runs alternate (embedded, 1
    worker, 2 workers, embedded, ...), so a change in the machine's load hits them alike.
    """
    calls = _targets(job, chunks)
    # one core per worker process, so that 1 -> 2 workers measures scaling, not sharing
    clients = {w: local_cluster(w, cores_per_worker=1) for w in workers}
    try:
        jobs = {}
        for w, client in clients.items():
            from dask.distributed import wait

            [jobs[w]] = client.scatter([job], broadcast=True, hash=False)
            wait([client.submit(compute_chunk, jobs[w], c, pure=False)
                  for c in chunks[:2 * w]])  # load the compiled kernels in every worker
        compute_chunk(job, chunks[0])

        def embedded() -> None:
            for c in chunks:
                compute_chunk(job, c)

        runs: dict[str, Any] = {"embedded (this process)": embedded}
        for w, client in clients.items():
            runs[f"Dask LocalCluster, {w} worker process(es)"] = (
                lambda cl=client, jf=jobs[w]: cl.gather(
                    [cl.submit(compute_chunk, jf, c, pure=False) for c in chunks]))
        rates: dict[str, list[float]] = {k: [] for k in runs}
        busy: dict[str, list[float]] = {k: [] for k in runs if k.startswith("Dask")}
        chunk_s: dict[str, list[float]] = {k: [] for k in busy}
        for _ in range(repeat):
            for name, fn in runs.items():
                t0 = time.perf_counter()
                out = fn()
                wall = time.perf_counter() - t0
                rates[name].append(calls / wall)
                if name in busy:  # Σ chunk wall times / (workers · wall): Dask's overhead
                    w = int(name.split(", ")[1].split()[0])
                    busy[name].append(sum(r["seconds"] for r in out) / (w * wall))
                    chunk_s[name] += [r["seconds"] for r in out]
    finally:
        for client in clients.values():
            client.close()
            client.cluster.close()
    for k, v in busy.items():  # low busy: Dask overhead or imbalance; long chunks: no free CPU
        print(f"{k}: workers busy {Stat(v).fmt(2)} of the wall time, one chunk takes "
              f"{Stat(chunk_s[k]).fmt(2)} s")
        record("15.1", f"{k}: workers busy / wall (Dask overhead, imbalance)",
               Stat(v).median, "", "(info)", True)
    return {k: Stat(v) for k, v in rates.items()}


def _rtb_rate(job, chunk: int, limit: int) -> Stat | None:
    try:
        import roboticstoolbox as rtb
    except ImportError:
        return None
    from serialkin.reach.solve import make_targets

    start, stop = job.chunk_range(chunk)
    T = make_targets("pose", job.grid.centres(start, stop), job.rotations, None)[:limit]
    ur = rtb.models.DH.UR5()
    ur.ik_LM(T[0])
    rates = []
    for _ in range(3):
        t0 = time.perf_counter()
        for t in T:
            ur.ik_LM(t, slimit=6)
        rates.append(len(T) / (time.perf_counter() - t0))
    return Stat(rates)


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--chunks", type=int, default=8, help="chunks timed (of 512 voxels)")
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--full", action="store_true", help="time the whole 5 cm map embedded")
    ap.add_argument("--no-dask", action="store_true")
    ap.add_argument("--no-peers", action="store_true")
    args = ap.parse_args(argv)
    print(header())
    ur5 = models.get("ur5")
    job = make_job(ur5, 0.05, 50)
    chunks = list(range(job.chunks)) if args.full else _chunks(job, args.chunks)
    calls = _targets(job, chunks)
    print(f"UR5 map: grid {job.grid.shape} = {job.grid.size} voxels x 50 orientations = "
          f"{job.grid.size * 50:.3g} IK calls, {job.chunks} chunks; timing {len(chunks)} "
          f"chunks = {calls} IK calls ({job.solver}), {args.repeat} repeats")
    rows: dict[str, Stat] = {}
    if args.no_dask:
        rows["embedded (this process)"] = _embedded(job, chunks, args.repeat)
    else:
        rows.update(_interleaved(job, chunks, (1, 2), args.repeat))
    num = make_job(ur5, 0.05, 50, solver="numerical", restarts=5)
    rows["embedded, numerical LM (5 restarts), 1 chunk"] = _embedded(num, chunks[len(chunks) // 2:
                                                                         len(chunks) // 2 + 1], 1)
    if not args.no_peers:
        peer = _rtb_rate(job, chunks[len(chunks) // 2], 2000)
        if peer is not None:
            rows["peer: Robotics Toolbox ik_LM, one call per target (2000 targets)"] = peer
    base = rows["embedded (this process)"]
    print(f"\n{'executor':66s} {'IK calls/s median [spread]':>30s} {'ratio':>7s}")
    for name, s in rows.items():
        print(f"{name:66s} {s.fmt(0):>30s} {s / base:7.2f}")
    two_core = [s.median for k, s in rows.items() if "numerical" not in k and "peer" not in k]
    best = max(two_core)
    hours = BIG_MAP_CALLS / best / 3600
    print(f"\nprojected 2.5 cm x 50-orientation map (6.5e7 IK calls) on this machine: "
          f"{hours * 60:.1f} min at the best 2-core rate {best:.0f} calls/s")
    record("15.1", "UR5 reach map 5 cm x 50 orientations: IK calls/s embedded",
           base.median, "calls/s", "(info)", True)
    record("15.1", "projected 2.5 cm x 50-orientation UR5 map on 2 cores [h]", hours, "h",
           "< 1", hours < 1.0)
    if not args.no_dask:
        one = rows["Dask LocalCluster, 1 worker process(es)"]
        two = rows["Dask LocalCluster, 2 worker process(es)"]
        eff = two.median / (2 * one.median)
        print(f"Dask scaling 1 -> 2 worker processes: efficiency {eff:.2f} (goal >= 0.85)")
        record("15.1", "Dask scaling efficiency 1 -> 2 worker processes", eff, "",
               ">= 0.85", eff >= 0.85)
    return 0


if __name__ == "__main__":
    sys.exit(main())
