"""Closed-form ``ik_all`` (all solutions): time per call on UR5 and Puma 560.

Run by hand: ``.venv/bin/python benchmarks/bench_ik_all.py [--targets N] [--no-peers]``.

For each arm, N reachable targets (FK of seeded random q inside the limits) are solved
one call at a time; the table gives the median and mean time per call, the mean number
of solutions, the share of calls whose solution set contains the sampled q, and the
worst pose error of any returned solution.

Beside it, in the same run when the ``bench`` extra is installed, Robotics Toolbox for
Python's closed-form solver for all solutions, ``robot.analytic_ik().solve(T)``, on the
same DH table (our robot is built from the toolbox's links) and the same poses, with
joint limits off on both sides so the sets can be compared; its one-time symbolic
derivation is timed separately. For the Puma 560 its classic ``ikine_a`` (one
configuration per call) is timed too.
"""

from __future__ import annotations

import argparse
import sys
import time
import warnings
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "src"))

from serialkin import Robot, models  # noqa: E402
from serialkin.ik.analytic import classify, ik_all  # noqa: E402
from serialkin.model.dh import DHLink  # noqa: E402


def _wrap(x: np.ndarray) -> np.ndarray:
    return (x + np.pi) % (2 * np.pi) - np.pi


def _times_us(fn, args) -> np.ndarray:
    out = np.empty(len(args))
    for i, a in enumerate(args):
        t0 = time.perf_counter()
        fn(a)
        out[i] = time.perf_counter() - t0
    return out * 1e6


def bench_serialkin(robot: Robot, n_targets: int, seed: int = 0) -> dict:
    """Time ik_all over n_targets reachable poses; check contents and accuracy."""
    Q = robot.random_q(n_targets, seed=seed)
    Ts = [np.ascontiguousarray(T) for T in robot.fk(Q)]
    ik_all(robot, Ts[0])  # compile / load the cached kernels
    times = _times_us(lambda T: ik_all(robot, T), Ts)
    counts, found, worst = [], 0, 0.0
    for q, T in zip(Q, Ts):
        S = ik_all(robot, T)
        counts.append(len(S))
        if len(S):
            found += np.abs(_wrap(S - q)).max(axis=1).min() < 1e-6
            worst = max(worst, float(np.abs(robot.fk(S) - T).max()))
    return {"median": np.median(times), "mean": times.mean(),
            "p10": np.percentile(times, 10), "p90": np.percentile(times, 90),
            "solutions": np.mean(counts),
            "found": found / n_targets, "worst": worst}


def _robot_from_rtb(rtb_robot, name: str) -> Robot:
    rows = [DHLink(a=float(L.a), alpha=float(L.alpha), d=float(L.d), theta=float(L.offset))
            for L in rtb_robot.links]
    return Robot.from_dh(rows, "standard", base=np.asarray(rtb_robot.base.A),
                         tool=np.asarray(rtb_robot.tool.A), name=name)


def bench_rtb(rtb_robot, name: str, n_targets: int, seed: int = 1) -> dict:
    """Robotics Toolbox all-solution closed form vs ours on the toolbox's own table."""
    ours = _robot_from_rtb(rtb_robot, name)
    Q = ours.random_q(n_targets, seed=seed)
    Ts = [np.ascontiguousarray(T) for T in ours.fk(Q)]
    t0 = time.perf_counter()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        solver = rtb_robot.analytic_ik()
        solver.solve(Ts[0], joint_limits=False)
    derive = time.perf_counter() - t0
    ik_all(ours, Ts[0])
    t_rtb = _times_us(lambda T: solver.solve(T, joint_limits=False), Ts)
    t_ours = _times_us(lambda T: ik_all(ours, T), Ts)
    agree = 0
    for T in Ts:
        a = ik_all(ours, T)
        b = np.atleast_2d(np.asarray(solver.solve(T, joint_limits=False).q, dtype=float))
        b = b[np.all(np.isfinite(b), axis=1)] if b.size else b.reshape(0, 6)
        same = len(a) == len(b) and all(
            np.abs(_wrap(a - row)).max(axis=1).min() < 1e-6 for row in b)
        agree += same
    out = {"derive_s": derive, "rtb_median": np.median(t_rtb), "ours_median": np.median(t_ours),
           "agree": agree / n_targets, "class": classify(ours)}
    if hasattr(rtb_robot, "ikine_a"):
        confs = ["lun", "lud", "lfn", "lfd", "run", "rud", "rfn", "rfd"]
        t_a = _times_us(lambda T: [rtb_robot.ikine_a(T, config=c) for c in confs], Ts[:50])
        out["ikine_a_x8_median"] = np.median(t_a)
    return out


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--targets", type=int, default=1000)
    parser.add_argument("--peer-targets", type=int, default=100)
    parser.add_argument("--no-peers", action="store_true")
    args = parser.parse_args()

    print(f"serialkin ik_all, {args.targets} reachable targets per arm (limits on)")
    print(f"{'robot':10s} {'class':6s} {'median us':>10s} {'p10-p90 us':>12s} {'mean us':>9s} "
          f"{'mean #sol':>10s} {'q found':>8s} {'worst err':>10s}")
    for robot in (models.ur5(), models.puma560()):
        r = bench_serialkin(robot, args.targets)
        spread = f"{r['p10']:.1f}-{r['p90']:.1f}"
        print(f"{robot.name:10s} {classify(robot):6s} {r['median']:10.1f} {spread:>12s} "
              f"{r['mean']:9.1f} {r['solutions']:10.2f} {r['found']:8.1%} {r['worst']:10.1e}")
    if args.no_peers:
        return
    try:
        import roboticstoolbox as rtb
    except ImportError:
        print("\nroboticstoolbox not installed (pip install -e '.[bench]'): peers skipped")
        return
    print(f"\nvs Robotics Toolbox analytic_ik().solve (all solutions), {args.peer_targets} "
          "targets, limits off, same DH table")
    print(f"{'robot':10s} {'derive s':>9s} {'rtb med us':>11s} {'ours med us':>12s} "
          f"{'ratio':>7s} {'same set':>9s}  extra")
    for rtb_robot, name in ((rtb.models.DH.UR5(), "UR5"), (rtb.models.DH.Puma560(), "Puma560")):
        r = bench_rtb(rtb_robot, name, args.peer_targets)
        extra = (f"ikine_a x 8 configs: {r['ikine_a_x8_median']:.0f} us"
                 if "ikine_a_x8_median" in r else "")
        print(f"{name:10s} {r['derive_s']:9.1f} {r['rtb_median']:11.1f} {r['ours_median']:12.1f} "
              f"{r['rtb_median'] / r['ours_median']:7.0f} {r['agree']:9.1%}  {extra}")
    print("\n(times per call on this machine, one thread)")


if __name__ == "__main__":
    main()
