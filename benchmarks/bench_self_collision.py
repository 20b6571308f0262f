"""Self-collision of the zoo robots against Pinocchio + coal on the vendor meshes (issue 32).

For every zoo robot with vendor meshes in example-robot-data (Panda, UR5; Puma 560,
Stanford arm and iiwa 7 have none and are listed as skipped), 10,000 configurations
uniform within the joint limits (Panda fingers at a random opening), same joint values
in both models (:mod:`serialkin.collision.reference`):

* false positives at 5 mm and at the stated 30 mm margin, false negatives (no margin),
  our and coal's collision rates;
* time per configuration of our batch check and of coal's ``computeCollisions`` (first
  hit), median [spread] of 5 repeats over 2,000 configurations.

    PYTHONPATH=src python benchmarks/bench_self_collision.py
"""

from __future__ import annotations

import time

import numpy as np
from _common import Stat, header, record

from serialkin import models
from serialkin.collision.queries import self_clearance
from serialkin.collision.reference import (
    NO_VENDOR_MESHES,
    VENDOR,
    CoalReference,
    _limits,
    compare_with_coal,
    vendor_files,
)

SAMPLES, MARGIN, MAX_FP = 10_000, 0.03, 0.01


def speed(name: str, repeats: int = 5, count: int = 2000) -> tuple[Stat, Stat]:
    """(ours, coal) time per configuration [µs]."""
    robot, ref = models.get(name), CoalReference(name)
    rng = np.random.default_rng(3)
    lo, hi = _limits(robot)
    q = lo + (hi - lo) * rng.random((count, robot.n))
    qv = ref.vendor_q(q, ref.sample_extra(count, rng))
    self_clearance(robot, robot.collision, q)
    ours, theirs = [], []
    for _ in range(repeats):
        t = time.perf_counter()
        self_clearance(robot, robot.collision, q)
        ours.append((time.perf_counter() - t) / count * 1e6)
        t = time.perf_counter()
        for x in qv:
            ref.collide(x)
        theirs.append((time.perf_counter() - t) / count * 1e6)
    return Stat(ours), Stat(theirs)


def main() -> None:
    print(header())
    print(f"# self-collision vs coal, {SAMPLES} configurations; FP margin {MARGIN * 1e3:g} mm")
    for name in NO_VENDOR_MESHES:
        print(f"{name:8s} skipped: no vendor meshes in example-robot-data (allowed pairs by "
              "never/always sampling)")
    for name in sorted(VENDOR):
        files = vendor_files(name)
        if isinstance(files, str):
            print(f"{name:8s} skipped: {files}")
            continue
        robot = models.get(name)
        a5 = compare_with_coal(robot, name, SAMPLES, seed=0, margin=0.005)
        a = compare_with_coal(robot, name, SAMPLES, seed=0, margin=MARGIN)
        ours, theirs = speed(name)
        print(f"{name:8s} ours {a.ours:6.2%}  coal {a.coal:6.2%}  FP@5mm {a5.false_positive:6.2%}"
              f"  FP@{MARGIN * 1e3:g}mm {a.false_positive:6.2%}  FN {a.false_negative:.2%}  "
              f"ours {ours.fmt(1)} us  coal {theirs.fmt(1)} us per q (x{theirs / ours:.1f})")
        top = sorted(a5.fp_pairs.items(), key=lambda kv: -kv[1])[:3]
        print(f"         FP@5mm pairs: {top}")
        record(f"self-collision {name} vs coal", f"false positives beyond {MARGIN * 1e3:g} mm",
               100 * a.false_positive, "%", f"<= {MAX_FP:.0%}, 0 false negatives",
               a.false_positive <= MAX_FP and a.false_negative == 0.0)


if __name__ == "__main__":
    main()
