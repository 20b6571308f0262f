"""``ik_all`` (all solutions): time per pose, single and batched; UR5, Puma 560, general arms.

Per pose, single call and batched (all cores), for decomposable arms (UR5, Puma 560:
goals <= 10 us single, <= 3 us batched), a UR5 with every axis perturbed by up to
0.01 rad (nearly ideal: the idealised closed form refined by Newton) and random
general 6R arms (Raghavan-Roth elimination, the 2-D search as its fallback: goal
<= 200 us, against Robotics Toolbox's Raghavan-Roth ``analytic_ik`` in the same run;
one arm in detail, then the median over 50 random arms). IK-Geo's published native
figures are printed beside them. Then ``robot.ik(T, method="analytic")`` (the
nearest solution, judged as every IK answer) against ``ik_all`` on the same poses, calls
interleaved (goal: within 2x, issue 32). Beside wall time, "CPU" columns give the calling
thread's CPU time per single call and the process's CPU time (all threads) per pose of
a batch: the work done, whatever share of the cores the run got on a shared machine.

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

from _common import Stat, header, interleaved_us, latency_us, record  # noqa: E402

from serialkin import Robot, models  # noqa: E402
from serialkin.ik.analytic import classify, ik_all  # noqa: E402
from serialkin.model.dh import DHLink  # noqa: E402

#: IK-Geo's published native figures as quoted in issue 14 (Elias & Wen, IK-Geo,
#: arXiv:2211.05737; C++, their machine): all solutions per pose, decomposable arms.
IKGEO_US = {"decomposable arms, fastest": 1.7, "decomposable arms, slowest": 2.7}


def _wrap(x: np.ndarray) -> np.ndarray:
    return (x + np.pi) % (2 * np.pi) - np.pi


def _times_us(fn, args) -> np.ndarray:
    out = np.empty(len(args))
    for i, a in enumerate(args):
        t0 = time.perf_counter()
        fn(a)
        out[i] = time.perf_counter() - t0
    return out * 1e6


def _cpu_us(fn, number: int, repeat: int) -> tuple[float, float, float]:
    """Median, min and max over ``repeat`` runs of the calling thread's CPU time per call
    [us] (``time.thread_time``: less disturbed than wall time by other processes)."""
    fn()
    out = []
    for _ in range(repeat):
        t0 = time.thread_time()
        for _ in range(number):
            fn()
        out.append((time.thread_time() - t0) / number * 1e6)
    return float(np.median(out)), min(out), max(out)


def _process_cpu_us(fn, repeat: int) -> float:
    """Median over ``repeat`` runs of the process's CPU time of ``fn()`` [us], all threads
    (``time.process_time``: the work done, whatever share of the cores it got)."""
    fn()
    out = []
    for _ in range(repeat):
        t0 = time.process_time()
        fn()
        out.append((time.process_time() - t0) * 1e6)
    return float(np.median(out))


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
    out = {"derive_s": derive, "rtb": Stat(t_rtb), "ours": Stat(t_ours),
           "agree": agree / n_targets, "class": classify(ours)}
    if hasattr(rtb_robot, "ikine_a"):
        confs = ["lun", "lud", "lfn", "lfd", "run", "rud", "rfn", "rfd"]
        t_a = _times_us(lambda T: [rtb_robot.ikine_a(T, config=c) for c in confs], Ts[:50])
        out["ikine_a_x8_median"] = np.median(t_a)
    return out


def _perturbed(robot: Robot, rng: np.random.Generator, angle: float = 0.01) -> Robot:
    """Every DH twist and offset moved by up to ``angle`` rad, lengths by up to 1 mm."""
    rows = [DHLink(a=r.a + rng.uniform(-1e-3, 1e-3), alpha=r.alpha + rng.uniform(-angle, angle),
                   d=r.d + rng.uniform(-1e-3, 1e-3), theta=r.theta + rng.uniform(-angle, angle))
            for r in robot.dh]
    return Robot.from_dh(rows, robot.convention, name=f"{robot.name} perturbed")


def _general_arm(seed: int) -> Robot:
    rng = np.random.default_rng(seed)
    return Robot.from_dh([DHLink(a=rng.uniform(0.05, 0.5), alpha=rng.uniform(-3.0, 3.0),
                                 d=rng.uniform(-0.3, 0.3)) for _ in range(6)], name="general")


def _wrist_first_arm() -> Robot:
    """A Pieper arm read from the tool end: axes 1, 2, 3 meet in one point (issue 30.4)."""
    h = 0.5 * np.pi
    return Robot.from_dh([DHLink(a=0.0, alpha=-h, d=0.35), DHLink(a=0.0, alpha=h, d=0.0),
                          DHLink(a=0.0, alpha=-h, d=0.3), DHLink(a=0.4, alpha=0.0, d=0.05),
                          DHLink(a=0.05, alpha=h, d=0.1), DHLink(a=0.3, alpha=-0.4, d=0.08)],
                         name="wrist first")


def bench_per_pose(n_batch: int, repeat: int) -> None:
    """Per pose, single call and batched, for exact, nearly ideal and general arms (14.1)."""
    print(f"\nper pose, single call and batched ({n_batch} targets, all cores via "
          "parallel.run); median [spread] over repeated runs")
    print(f"{'arm':18s} {'mode':8s} {'single us':>22s} {'single CPU us':>24s} "
          f"{'batched us/pose':>16s} {'batched CPU us/pose':>20s} {'#sol':>5s}")
    rng = np.random.default_rng(0)
    arms = [(models.ur5(), 10.0, 3.0, "14.1"), (models.puma560(), 10.0, 3.0, "14.1"),
            (_perturbed(models.ur5(), rng), None, None, "14.1"),
            (_general_arm(3), 200.0, None, "14.1"), (_wrist_first_arm(), 20.0, None, "30.4")]
    for robot, goal_single, goal_batch, goal_id in arms:
        Q = robot.random_q(n_batch, seed=1)
        T = np.ascontiguousarray(robot.fk(Q))
        res = ik_all(robot, T)
        T0 = np.ascontiguousarray(T[0])
        few = 20 if res.mode == "general" else 2000
        single = latency_us(lambda r=robot, t=T0: ik_all(r, t), few, repeat)
        cpu = _cpu_us(lambda r=robot, t=T0: ik_all(r, t), few, repeat)
        Tb = T[: max(8, n_batch // (50 if res.mode == "general" else 1))]
        batched = latency_us(lambda r=robot, t=Tb: ik_all(r, t), 1, repeat)
        per = batched.median / len(Tb)
        per_cpu = _process_cpu_us(lambda r=robot, t=Tb: ik_all(r, t), repeat) / len(Tb)
        cpu_s = f"{cpu[0]:.1f} [{cpu[1]:.1f}-{cpu[2]:.1f}]"
        print(f"{robot.name:18s} {res.mode:8s} {single.fmt(1):>22s} {cpu_s:>24s} "
              f"{per:16.2f} {per_cpu:20.2f} {res.count.mean():5.1f}")
        if goal_single is not None:
            record(goal_id, f"ik_all single, {robot.name} ({res.mode}), all solutions",
                   single.median, "us", f"<= {goal_single:g}", single.median <= goal_single)
        if goal_batch is not None:
            record("14.1", f"ik_all batched per pose, {robot.name} ({res.mode})", per, "us",
                   f"<= {goal_batch:g}", per <= goal_batch)
    print("IK-Geo published (native C++, their machine): "
          + ", ".join(f"{k} {v:g} us" for k, v in IKGEO_US.items()))


def bench_analytic_method(n_targets: int, passes: int) -> None:
    """``robot.ik(T, method="analytic")`` on one pose against ``ik_all`` on it (issue 32).

    The method solves by ``ik_all`` and returns the row nearest q0 (or the middle of the
    ranges), judged as every solver's answer is (errors, limits, the 2π representative):
    goal within 2x of ``ik_all``. Each call timed on its own, the two (and the call with
    a q0) interleaved target by target, ``passes`` passes over ``n_targets`` poses.
    """
    print(f"\nrobot.ik(T, method='analytic') against ik_all(T), one pose per call, "
          f"{n_targets} targets x {passes} passes interleaved; median [10-90 %] us")
    print(f"{'arm':12s} {'ik analytic':>20s} {'with q0':>20s} {'ik_all':>18s} {'ratio':>6s}")
    clock = time.perf_counter
    for robot in (models.ur5(), models.puma560(), models.get("stanford"), _wrist_first_arm()):
        Ts = [np.ascontiguousarray(T) for T in robot.fk(robot.random_q(n_targets, seed=1))]
        Q0 = robot.random_q(n_targets, seed=2)
        for T, q0 in zip(Ts[:5], Q0):  # compile / load the kernels
            robot.ik(T, method="analytic")
            robot.ik(T, method="analytic", q0=q0)
            ik_all(robot, T)
        one, with_q0, alone = [], [], []
        for _ in range(passes):
            for T, q0 in zip(Ts, Q0):
                t0 = clock()
                robot.ik(T, method="analytic")
                t1 = clock()
                robot.ik(T, method="analytic", q0=q0)
                t2 = clock()
                ik_all(robot, T)
                t3 = clock()
                one.append(t1 - t0)
                with_q0.append(t2 - t1)
                alone.append(t3 - t2)
        a, b, c = (Stat(np.array(v) * 1e6) for v in (one, with_q0, alone))
        ratio = a / c
        print(f"{robot.name:12s} {a.fmt(1):>20s} {b.fmt(1):>20s} {c.fmt(1):>18s} {ratio:6.2f}")
        record("32", f"robot.ik(method='analytic') / ik_all, one pose, {robot.name}", ratio,
               "x", "<= 2", ratio <= 2.0)


def bench_general_vs_rtb(repeat: int) -> None:
    """General 6R: ours against Robotics Toolbox's Raghavan–Roth solver, same DH table."""
    try:
        import roboticstoolbox as rtb
    except ImportError:
        print("roboticstoolbox not installed: general-arm peer skipped")
        return
    ours = _general_arm(3)
    links = [rtb.RevoluteDH(a=r.a, alpha=r.alpha, d=r.d) for r in ours.dh]
    peer = rtb.DHRobot(links, name="general")
    T = np.ascontiguousarray(ours.fk(ours.random_q(1, seed=2)[0]))
    t0 = time.perf_counter()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        try:
            solver = peer.analytic_ik()
            solver.solve(T, joint_limits=False)
        except Exception as exc:  # noqa: BLE001 - a peer's failure is reported, not raised
            print(f"Robotics Toolbox analytic_ik on the general arm failed: {exc}")
            return
    derive = time.perf_counter() - t0
    times = interleaved_us({"ours": lambda: ik_all(ours, T),
                            "rtb": lambda: solver.solve(T, joint_limits=False)}, 5, repeat)
    cpu_ours = _cpu_us(lambda: ik_all(ours, T), 5, repeat)
    cpu_rtb = _cpu_us(lambda: solver.solve(T, joint_limits=False), 5, repeat)
    b = np.atleast_2d(np.asarray(solver.solve(T, joint_limits=False).q, dtype=float))
    a = ik_all(ours, T)
    print(f"\ngeneral 6R vs Robotics Toolbox analytic_ik (Raghavan-Roth; derived in "
          f"{derive:.1f} s): ours {times['ours'].fmt(0)} us ({len(a)} solutions), "
          f"rtb {times['rtb'].fmt(0)} us ({len(b)} solutions), ratio rtb/ours "
          f"{times['rtb'] / times['ours']:.2f}; CPU time per call: ours {cpu_ours[0]:.0f} "
          f"[{cpu_ours[1]:.0f}-{cpu_ours[2]:.0f}] us, rtb {cpu_rtb[0]:.0f} "
          f"[{cpu_rtb[1]:.0f}-{cpu_rtb[2]:.0f}] us, ratio {cpu_rtb[0] / cpu_ours[0]:.2f}")
    record("14.1", "ik_all general 6R, all solutions, single call", times["ours"].median, "us",
           "<= 200", times["ours"].median <= 200.0)


def bench_general_arms(n_arms: int, repeat: int) -> None:
    """General 6R: median single-call time over random arms (one pose each), and how often
    the elimination declines (the 2-D search answers instead)."""
    from serialkin.ik.analytic import _prepared
    from serialkin.ik.analytic.raghavan_roth import rr_candidates_from

    medians, counts, declined = [], [], 0
    for i in range(n_arms):
        robot = _general_arm(1000 + i)
        try:
            p = _prepared(robot, 0.05)
        except Exception:  # noqa: BLE001 - coaxial / no closed form at either end: skipped
            continue
        if p.mode != "general":
            continue
        T = np.ascontiguousarray(robot.fk(robot.random_q(1, seed=i)[0]))
        out = np.zeros((16, 6))
        reverse = bool(p.order[1] == 1)  # as ik_all calls it (dispatch._general)
        other = len(p.order) > 2 and bool(p.order[2] == 1) != reverse
        k = rr_candidates_from(T, p.W, p.P, p.M, reverse, other, p.F, p.meta, 1e-12, 1e-12,
                               out)
        declined += k < 0
        medians.append(latency_us(lambda r=robot, t=T: ik_all(r, t), 5, repeat).median)
        counts.append(len(ik_all(robot, T)))
    m = np.asarray(medians)
    med = float(np.median(m))
    print(f"\ngeneral 6R over {len(m)} random arms (one pose each): median single call "
          f"{med:.0f} us [p10-p90 {np.percentile(m, 10):.0f}-{np.percentile(m, 90):.0f}, "
          f"max {m.max():.0f}]; mean {np.mean(counts):.1f} solutions; elimination declined "
          f"(2-D search) on {declined}")
    record("14.1", f"ik_all general 6R, median over {len(m)} random arms", med, "us", "<= 200",
           med <= 200.0)


def bench_published_arm(repeat: int) -> None:
    """General 6R: the published 16-solution arm at its published pose (issue 30.1).

    D. Manocha, J. F. Canny, IEEE T-RA 10(5), 1994: Table I (standard DH; twists 90° and
    1°), the pose ``A_hand`` of p. 655 (its rotation made orthonormal) and 16 solutions
    (Table III); the test tests/ik/test_published_6r.py matches them one-to-one.
    """
    a, d, alpha = (0.3, 1.0, 0.0, 1.5, 0.0, 0.0), (0.0, 0.0, 0.2, 0.0, 0.0, 0.0), (90, 1) * 3
    robot = Robot.from_dh([DHLink(a=ai, alpha=np.radians(al), d=di)
                           for ai, di, al in zip(a, d, alpha, strict=True)], name="published")
    A = np.array([[-0.7601, -0.6416, 0.1022, -1.1401], [0.1333, 0.0, 0.9910, 0.0],
                  [-0.6359, 0.7669, 0.0855, 0.0], [0.0, 0.0, 0.0, 1.0]])
    U, _, Vt = np.linalg.svd(A[:3, :3])
    A[:3, :3] = U @ Vt
    T = np.ascontiguousarray(A)
    single = latency_us(lambda: ik_all(robot, T), 20, repeat)
    n = len(ik_all(robot, T))
    print(f"\npublished 16-solution arm (Manocha & Canny 1994) at its pose: single call "
          f"{single.fmt(0)} us, {n} solutions")
    record("14.1", f"ik_all general 6R, published 16-solution arm ({n} solutions)",
           single.median, "us", "<= 200", single.median <= 200.0 and n == 16)


def miss_rate(n_arms: int, starts: int, grids: tuple[int, ...]) -> None:
    """Completeness of the general solver: solutions found by Newton from random starts
    (the compiled ``newton_refine`` on the robot's chain) that ``ik_all`` does not return.

    ``grid`` only matters where the elimination declines and the search answers."""
    from serialkin.ik.analytic import _prepared
    from serialkin.ik.analytic.refine import MAX_NEWTON, newton_refine

    rng = np.random.default_rng(7)
    totals = {g: [0, 0, 0.0] for g in grids}  # missed, reference solutions, seconds (CPU)
    arms = 0
    for i in range(n_arms):
        robot = _general_arm(100 + i)
        try:
            if _prepared(robot, 0.05).mode != "general":
                continue
        except Exception:  # noqa: BLE001 - coaxial / no closed form at either end: skipped
            continue
        arms += 1
        T = np.ascontiguousarray(robot.fk(robot.random_q(1, seed=i)[0]))
        ref: list[np.ndarray] = []
        F, meta = robot.chain.F, robot.chain.meta
        scale = _prepared(robot, 0.05).s.scale
        for q in rng.uniform(-np.pi, np.pi, (starts, 6)):
            if newton_refine(q, T, F, meta, 1e-12 * scale, 1e-12, MAX_NEWTON):
                q = _wrap(q)
                if all(np.abs(_wrap(q - r)).max() > 1e-6 for r in ref):
                    ref.append(q)
        for g in grids:
            t0 = time.thread_time()
            S = ik_all(robot, T, grid=g)
            totals[g][2] += time.thread_time() - t0
            for r in ref:
                totals[g][0] += len(S) == 0 or np.abs(_wrap(S - r)).max(axis=1).min() > 1e-6
            totals[g][1] += len(ref)
    print(f"\ngeneral search completeness on {arms} random general arms (of {n_arms} drawn), "
          f"reference = distinct solutions of Newton from {starts} random starts")
    for g, (missed, total, sec) in totals.items():
        print(f"  grid {g:3d}: missed {missed} of {total} reference solutions; "
              f"mean CPU time per call {1e3 * sec / max(arms, 1):.2f} ms")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--targets", type=int, default=1000)
    parser.add_argument("--peer-targets", type=int, default=100)
    parser.add_argument("--no-peers", action="store_true")
    parser.add_argument("--batch", type=int, default=2000)
    parser.add_argument("--repeat", type=int, default=7)
    parser.add_argument("--analytic-passes", type=int, default=5,
                        help="passes over the targets of the method='analytic' rows")
    parser.add_argument("--miss-arms", type=int, default=0,
                        help="random general arms for the completeness study (0: skip)")
    parser.add_argument("--miss-starts", type=int, default=200)
    parser.add_argument("--miss-grids", type=int, nargs="+", default=[16, 24, 32])
    args = parser.parse_args()
    print(header())
    if args.miss_arms:
        miss_rate(args.miss_arms, args.miss_starts, tuple(args.miss_grids))
        return
    bench_per_pose(args.batch, args.repeat)
    bench_analytic_method(200, args.analytic_passes)
    bench_general_arms(50, max(3, args.repeat // 2))
    bench_published_arm(max(3, args.repeat // 2))
    if not args.no_peers:
        bench_general_vs_rtb(args.repeat)

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
    print("(median [10th-90th percentile] over the targets, one call each)")
    print(f"{'robot':10s} {'derive s':>9s} {'rtb us':>20s} {'ours us':>18s} "
          f"{'ratio':>7s} {'same set':>9s}  extra")
    for rtb_robot, name in ((rtb.models.DH.UR5(), "UR5"), (rtb.models.DH.Puma560(), "Puma560")):
        r = bench_rtb(rtb_robot, name, args.peer_targets)
        extra = (f"ikine_a x 8 configs: {r['ikine_a_x8_median']:.0f} us"
                 if "ikine_a_x8_median" in r else "")
        print(f"{name:10s} {r['derive_s']:9.1f} {r['rtb'].fmt(1):>20s} {r['ours'].fmt(1):>18s} "
              f"{r['rtb'] / r['ours']:7.0f} {r['agree']:9.1%}  {extra}")
    print("\n(times per call on this machine, one thread)")


if __name__ == "__main__":
    main()
