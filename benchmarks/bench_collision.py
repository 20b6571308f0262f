"""Self-clearance of the Panda: serialkin's batch kernel against coal on the same capsules.

Run by hand: ``.venv/bin/python benchmarks/bench_collision.py [--runs 15] [--quick]``.

The Panda of :func:`serialkin.models.panda` with :func:`panda_collision_model` (11 capsules)
and the allowed-collision matrix of example-robot-data's ``panda.srdf`` (20 checked body
pairs, 20 capsule pairs; the default matrix when example-robot-data is missing). Timed,
``--runs`` times each, median and 10–90 % spread:

* one call of ``self_clearance`` for one configuration (µs per call: Python front end,
  ``fk_all`` and the kernel);
* one call for a batch of 10,000 configurations on **one** numba thread, in µs per
  configuration; then the two parts of it (``robot.fk_all`` and the compiled kernel);
* coal (hpp-fcl) on the same capsules: for each configuration the capsule poses from the
  same link frames and ``coal.distance`` on every checked pair, from Python (µs per
  configuration; most of it is the Python loop over pairs, so the row also gives coal's
  time per pair). The largest difference of the two clearances is printed.

Goal (issue 12): at most 2 µs per configuration batched on one core.
"""

from __future__ import annotations

import argparse
import sys
import timeit
from pathlib import Path

import numba
import numpy as np
from _common import Stat, header, latency_us, record

from serialkin import models
from serialkin.collision import acm_from_srdf, default_acm, panda_collision_model, self_clearance
from serialkin.collision import queries as Q

SRDF = (Path(sys.prefix) / "lib" / f"python{sys.version_info.major}.{sys.version_info.minor}"
        / "site-packages" / "cmeel.prefix" / "share" / "example-robot-data" / "robots"
        / "panda_description" / "srdf" / "panda.srdf")


def coal_setup(model, pa, pb):
    import coal

    geoms = []
    for s in range(len(model.radius)):
        L = float(np.linalg.norm(model.b[s] - model.a[s]))
        geoms.append((coal.Capsule(float(model.radius[s]), L) if L > 0
                      else coal.Sphere(float(model.radius[s])), L))
    req = coal.DistanceRequest()
    res = coal.DistanceResult()

    def poses(F):
        out = []
        for s in range(len(model.radius)):
            T = F[model.shape_frame[s]]
            a = T[:3, :3] @ model.a[s] + T[:3, 3]
            b = T[:3, :3] @ model.b[s] + T[:3, 3]
            z = b - a
            L = np.linalg.norm(z)
            z = z / L if L > 0 else np.array([0.0, 0.0, 1.0])
            x = np.cross(z, [1.0, 0, 0] if abs(z[0]) < 0.9 else [0, 1.0, 0])
            x /= np.linalg.norm(x)
            M = coal.Transform3s()
            M.setRotation(np.column_stack([x, np.cross(z, x), z]))
            M.setTranslation((a + b) / 2)
            out.append(M)
        return out

    def clearance(F):
        P = poses(F)
        best = np.inf
        for i, j in zip(pa, pb, strict=True):
            res.clear()
            best = min(best, coal.distance(geoms[i][0], P[i], geoms[j][0], P[j], req, res))
        return best

    return clearance


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--runs", type=int, default=15)
    ap.add_argument("--quick", action="store_true")
    args = ap.parse_args()
    print(header())
    robot, model = models.panda(), panda_collision_model()
    acm = acm_from_srdf(model, SRDF) if SRDF.exists() else default_acm(model)
    pa, pb = Q.checked_shape_pairs(model, acm)
    print(f"Panda: {len(model.radius)} capsules, {len(pa)} checked capsule pairs "
          f"({'panda.srdf' if SRDF.exists() else 'default matrix'})")
    N = 1000 if args.quick else 10_000
    Qs = robot.random_q(N, seed=0)
    q1 = Qs[0]
    numba.set_num_threads(1)
    single = latency_us(lambda: self_clearance(robot, model, q1, acm), 200, args.runs)
    batch = Stat(np.array(timeit.repeat(lambda: self_clearance(robot, model, Qs, acm),
                                        number=1, repeat=args.runs)) / N * 1e6)
    fk = Stat(np.array(timeit.repeat(lambda: robot.fk_all(Qs), number=1,
                                     repeat=args.runs)) / N * 1e6)
    F = robot.fk_all(Qs)
    d, p = np.empty(N), np.empty(N, dtype=np.int64)
    sf = np.ascontiguousarray(model.shape_frame)

    def kernel():
        Q.self_clearance_range(F, sf, model.a, model.b, model.radius, pa, pb, d, p, 0, N)

    kern = Stat(np.array(timeit.repeat(kernel, number=1, repeat=args.runs)) / N * 1e6)
    print(f"self_clearance, one configuration per call [µs/call]   {single.fmt(2)}")
    print(f"self_clearance, batch of {N}, 1 thread [µs/config]    {batch.fmt(3)}")
    print(f"   of which robot.fk_all [µs/config]                   {fk.fmt(3)}")
    print(f"   of which the clearance kernel [µs/config]           {kern.fmt(3)}")
    record("12.1", "Panda self_clearance batched, 1 thread (median)", batch.median, "µs/config",
           "<= 2", batch.median <= 2.0)
    try:
        clearance = coal_setup(model, pa, pb)
    except ImportError:
        print("coal is not installed (pip install coal): no comparison")
        return
    M = 50 if args.quick else 200
    ours = self_clearance(robot, model, Qs[:M], acm).distance
    theirs = np.array([clearance(F[k]) for k in range(M)])
    print(f"largest |serialkin − coal| over {M} configurations: "
          f"{np.abs(ours - theirs).max():.2e} m")
    co = Stat(np.array(timeit.repeat(lambda: [clearance(F[k]) for k in range(M)], number=1,
                                     repeat=max(3, args.runs // 3))) / M * 1e6)
    print(f"coal, same capsules and pairs, from Python [µs/config] {co.fmt(1)} "
          f"({co.median / len(pa):.2f} µs per pair incl. the Python loop)")
    print(f"serialkin batch is {co.median / batch.median:.0f}x faster per configuration")


if __name__ == "__main__":
    main()
