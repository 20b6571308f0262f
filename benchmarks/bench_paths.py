"""Cartesian paths and 7-DOF arm angles: joint paths over all solutions, timing, ψ.

Rows (median and spread of repeated runs; goals of issues 30 and 31):

* joint path of a 1,000-sample line by dynamic programming over all solutions: UR5
  (``ik_all``), iiwa (arm angle), Panda (locked joint 7);
* time-optimal timing of a 1,000-sample joint path (toppra), and toppra called directly
  on the same spline for the ratio;
* the arm angle: all solutions at one ψ (iiwa), the feasible ψ intervals, a Panda sweep
  of joint 7 at 1° and, beside it, its floor: the one batch of locked solves on its grid.

Usage: ``python benchmarks/bench_paths.py`` (``make bench`` runs it).
"""

from __future__ import annotations

import math
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _common import Stat, header, latency_us, record, wall_s  # noqa: E402

from serialkin import models  # noqa: E402
from serialkin.ik import ik_all  # noqa: E402
from serialkin.ik.analytic import _locked  # noqa: E402
from serialkin.ik.analytic.arm_angle import arm_angle_intervals, ik_arm_angle  # noqa: E402
from serialkin.ik.sweep import _targets as _sweep_targets  # noqa: E402
from serialkin.ik.sweep import _values as _sweep_values  # noqa: E402
from serialkin.ik.sweep import joint_sweep  # noqa: E402
from serialkin.paths import joint_path, line, time_optimal  # noqa: E402

ARMS = {"ur5": [0.3, -1.2, 1.4, -1.0, -1.5, 0.4],
        "iiwa7": [0.3, 0.6, -0.2, -1.2, 0.4, 0.8, 0.1],
        "panda": [0.2, -0.3, 0.1, -2.0, 0.1, 1.8, 0.6]}
GOALS_MS = {"ur5": 20.0, "panda": 50.0}


def _line(name: str, samples: int = 1000):
    robot = models.get(name)
    q0 = np.array(ARMS[name])
    A = robot.fk(q0)
    B = A.copy()
    B[:3, 3] += [0.1, -0.08, 0.05]
    length = float(np.linalg.norm(B[:3, 3] - A[:3, 3]))
    return robot, q0, line(A, B, max_step=length / (samples - 1) * (1 + 1e-9), max_angle=1.0)


def main() -> None:
    """Print the table and record the goals' rows."""
    print(header())
    print(f"{'row':58s} {'median [spread] ms':>28s}")
    jp_ur5 = None
    for name in ARMS:
        robot, q0, path = _line(name)
        st = wall_s(lambda r=robot, p=path, q=q0: joint_path(r, p, q0=q), repeat=7)
        jp = joint_path(robot, path, q0=q0)
        ms = Stat(st.values * 1e3)
        row = f"joint path, {len(path)} samples, {name} ({jp.method})"
        print(f"{row:58s} {ms.fmt(1):>28s}")
        if name in GOALS_MS:
            record("31.b", f"joint path of 1,000 samples, {name}", ms.median, "ms",
                   f"<= {GOALS_MS[name]:g} ms", ms.median <= GOALS_MS[name])
        if name == "ur5":
            jp_ur5 = jp
    t = Stat(wall_s(lambda: time_optimal(jp_ur5.q, 1.0, 2.0), repeat=7).values * 1e3)
    print(f"{'time-optimal timing of the UR5 path (toppra)':58s} {t.fmt(1):>28s}")
    record("31.b", "timing of a 1,000-sample path", t.median, "ms", "<= 50 ms", t.median <= 50)

    iiwa = models.get("iiwa7")
    T = iiwa.fk(np.array(ARMS["iiwa7"]))
    one = Stat(wall_s(lambda: ik_arm_angle(iiwa, T, 0.3), repeat=50).values * 1e6)
    print(f"{'iiwa: every solution at one arm angle [µs]':58s} {one.fmt(1):>28s}")
    record("30.6", "S-R-S all solutions at one arm angle", one.median, "us", "<= 10 us",
           one.median <= 10)
    iv = Stat(wall_s(lambda: arm_angle_intervals(iiwa, T), repeat=7).values * 1e3)
    print(f"{'iiwa: feasible arm-angle intervals':58s} {iv.fmt(1):>28s}")
    record("30.6", "feasible arm-angle intervals", iv.median * 1e3, "us", "<= 50 us",
           iv.median * 1e3 <= 50)
    panda = models.get("panda")
    Tp = panda.fk(np.array(ARMS["panda"]))
    sw = Stat(latency_us(lambda: joint_sweep(panda, Tp, 6, resolution=math.radians(1.0)),
                         number=10, repeat=15).values / 1e3)
    print(f"{'Panda: sweep of joint 7 at 1° (goal <= 1 ms)':58s} {sw.fmt(2):>28s}")
    # ssik does not build here (C++, no package): its figures as issue 30 quotes them
    print(f"{'  ssik 7R sweep, all solutions (quoted in issue 30, not run)':58s} "
          f"{'Panda 3.0 / iiwa14 4.8':>28s}")
    record("30.6", "Panda sweep of joint 7 at 1 degree", sw.median, "ms", "<= 1 ms",
           sw.median <= 1)
    ends = Stat(latency_us(lambda: joint_sweep(panda, Tp, 6,
                                               resolution=math.radians(1.0)).feasible,
                           number=10, repeat=15).values / 1e3)
    print(f"{'  with its feasible intervals refined to 1e-9 (.feasible)':58s} "
          f"{ends.fmt(2):>28s}")
    # its floor: the one batch of locked solves on the grid (the branches ~0.05 ms; the
    # refinement of the feasible ends, a few rounds of small batches, at first read)
    grid = _sweep_values(panda, 6, None, math.radians(1.0))
    reduced, targets = _locked(panda, {6: 0.0})[0], _sweep_targets(panda, Tp, 6, grid)
    floor = Stat(latency_us(lambda: ik_all(reduced, targets), number=10,
                            repeat=15).values / 1e3)
    print(f"{f'  of which the grid: one batch ik_all of {len(grid)} targets':58s} "
          f"{floor.fmt(2):>28s}")


if __name__ == "__main__":
    main()
