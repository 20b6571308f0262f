"""Collision-aware IK on the Panda: time per target (single call and batched) and success.

Run by hand: ``.venv/bin/python benchmarks/bench_ik_collision.py [--targets N]
[--single M] [--margin m]``.

The zoo Panda with its fitted capsules (``robot.collision``), the default allowed-collision
matrix, and the scene of ``tests/ik/test_collision_ik.py``: a table (half-space, top 10 cm
below the base frame), a sphere (r = 10 cm) and a box (12 cm cube) in the workspace. N
full-pose targets are the FK of seeded random configurations inside the limits that are
collision-free with the margin (self and scene); the solver starts from random
configurations (no q0), ``robot.ik(T, scene=..., self_collision=True, margin=m,
seed=...)``. A success is what the solver reports (the test suite checks it independently
with coal); the clearance of every success is checked here against the margin.

Rows: the batch (all N targets in one call on every core, median and spread of 5 runs),
the single call (M targets one call each, median and 10–90 % spread over the targets),
and the same targets without collision checking (plain ``lm``) for the cost ratio. No
peer library offers collision-aware IK on a numerical solver in one call (mink and pink
solve a differential QP per step); the plain solve is the reference.
"""

from __future__ import annotations

import argparse
import os
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "src"))

from _common import Stat, header, record, wall_s  # noqa: E402

from serialkin import models  # noqa: E402
from serialkin.collision import scene_clearance, self_clearance  # noqa: E402
from serialkin.model.geometry import Box, HalfSpace, Sphere  # noqa: E402

SCENE = [HalfSpace([0.0, 0.0, 1.0], -0.10, name="table"),
         Sphere(0.10, center=[0.45, 0.25, 0.45], name="ball"),
         Box((0.12, 0.12, 0.12), center=[0.40, -0.35, 0.25], name="crate")]


def free_targets(robot, count: int, margin: float, seed: int) -> np.ndarray:
    """FK of ``count`` seeded configurations inside the limits, collision-free with margin."""
    rng = np.random.default_rng(seed)
    lim = robot.sampling_limits()
    kept: list[np.ndarray] = []
    while sum(len(k) for k in kept) < count:
        Q = rng.uniform(lim[:, 0], lim[:, 1], (4 * count, robot.n))
        ok = self_clearance(robot, robot.collision, Q).distance >= margin
        ok &= scene_clearance(robot, robot.collision, Q, SCENE).distance >= margin
        kept.append(Q[ok])
    return np.ascontiguousarray(robot.fk(np.concatenate(kept)[:count]))


def numba_threads() -> int:
    """Threads the batch may use."""
    import numba

    return numba.get_num_threads()


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--targets", type=int, default=10_000)
    parser.add_argument("--single", type=int, default=1000)
    parser.add_argument("--margin", type=float, default=0.0)
    args = parser.parse_args()
    robot = models.panda()
    targets = free_targets(robot, args.targets, args.margin, seed=1)
    kw = dict(scene=SCENE, self_collision=True, margin=args.margin)
    print(f"Collision-aware IK, Panda, table + sphere + box, margin {args.margin:g} m, "
          f"{args.targets} targets from collision-free configurations, random starts")
    print(header())

    res = robot.ik(targets, seed=0, **kw)
    ok = res.success
    assert (res.clearance[ok] >= args.margin).all()
    batch = Stat(wall_s(lambda: robot.ik(targets, seed=0, **kw), repeat=5).values
                 / args.targets * 1e6)
    plain = Stat(wall_s(lambda: robot.ik(targets, seed=0), repeat=5).values
                 / args.targets * 1e6)
    plain_ok = robot.ik(targets, seed=0).success.mean()
    free_plain = None
    if plain_ok:
        r0 = robot.ik(targets, seed=0)
        d = np.minimum(self_clearance(robot, robot.collision, r0.q).distance,
                       scene_clearance(robot, robot.collision, r0.q, SCENE).distance)
        free_plain = float(np.mean(r0.success & (d >= args.margin)))

    M = min(args.single, args.targets)
    for k in range(min(M, 20)):  # warm-up (compilation, caches)
        robot.ik(targets[k], seed=k, **kw)
    times = []
    single_ok = []
    for k in range(M):
        t0 = time.perf_counter()
        r = robot.ik(targets[k], seed=k, **kw)
        times.append((time.perf_counter() - t0) * 1e6)
        single_ok.append(r.success)
    single = Stat(times)

    threads = numba_threads()
    print(f"\n  {'row':58s} {'median us':>10s} {'spread us':>18s} {'success':>8s}")
    print(f"  {'batch, collision-aware (' + str(threads) + ' threads), per target':58s} "
          f"{batch.median:10.1f} {f'{batch.lo:.1f}-{batch.hi:.1f}':>18s} {ok.mean():8.1%}")
    print(f"  {'single call, collision-aware':58s} {single.median:10.1f} "
          f"{f'{single.lo:.1f}-{single.hi:.1f}':>18s} {np.mean(single_ok):8.1%}")
    print(f"  {'batch, plain lm (no collision check), per target':58s} {plain.median:10.1f} "
          f"{f'{plain.lo:.1f}-{plain.hi:.1f}':>18s} {plain_ok:8.1%}")
    if free_plain is not None:
        print(f"  plain lm solutions that also happen to be collision-free: {free_plain:.1%}")
    print(f"  cost of the collision check: batch {batch / plain:.2f}x the plain solve; mean "
          f"restarts {np.mean(res.restarts):.2f}, mean iterations {np.mean(res.iterations):.1f}")
    load = os.getloadavg()[0] if hasattr(os, "getloadavg") else float("nan")
    print(f"  load average at the end {load:.2f} on {os.cpu_count()} CPUs")
    record("13.1", f"collision-aware IK Panda batched ({threads} threads): us per target at "
           f"{ok.mean():.1%} success", batch.median, "us", "<= 100 at >= 95 %",
           batch.median <= 100.0 and ok.mean() >= 0.95)
    record("13.1", f"collision-aware IK Panda single call: median us at "
           f"{np.mean(single_ok):.1%} success", single.median, "us", "(reported)", True)


if __name__ == "__main__":
    main()
