"""Forward kinematics and Jacobian speed: serialkin beside Pinocchio and Robotics Toolbox.

Run by hand: ``.venv/bin/python benchmarks/bench_fk.py [--batch 100000] [--quick]``.

For the Panda, the UR5 and a planar 20-link arm it measures, in one run:

* single-call latency of ``robot.fk(q)`` and ``robot.jacobian(q)`` (one float64 q),
* batch FK throughput over 100,000 random configurations (``robot.fk(Q)``),

and the same for the peers when the ``bench`` extra is installed:

* Pinocchio (``pin``): a model built from the *same* DH table (one revolute/prismatic
  z joint per row, the fixed transforms as joint placements, the tool as a frame), so
  both libraries compute exactly the same kinematics (checked before timing).
  FK = ``forwardKinematics`` + ``updateFramePlacement``; Jacobian =
  ``computeFrameJacobian(..., LOCAL_WORLD_ALIGNED)``; batch = a Python loop of FK calls.
* Robotics Toolbox for Python: a ``DHRobot`` built from the same table, timed through its
  ETS (``ets.eval(q)``, ``ets.jacob0(q)``; batch ``ets.eval(Q)`` with Q (k, n)).

Ratios are serialkin / peer: below 1 is faster for latencies, above 1 is faster for
throughput. Latencies are the best of 5 repeats (microseconds per call).
"""

from __future__ import annotations

import argparse
import os
import platform
import sys
import time
import timeit

import numpy as np

import serialkin as sk
from serialkin import models


def best_us(fn, number: int, repeat: int = 5) -> float:
    """Best-of-``repeat`` time per call [µs]."""
    return min(timeit.repeat(fn, number=number, repeat=repeat)) / number * 1e6


def best_rate(fn, count: int, repeat: int = 3) -> float:
    """Best-of-``repeat`` throughput [configurations per second] of ``fn()`` over ``count``."""
    best = np.inf
    for _ in range(repeat):
        t0 = time.perf_counter()
        fn()
        best = min(best, time.perf_counter() - t0)
    return count / best


# ---------------------------------------------------------------------------- peers
def pin_model(robot: sk.Robot):
    """A Pinocchio model with the same kinematics as ``robot`` (z joints only), or None."""
    try:
        import pinocchio as pin
    except ImportError:
        return None
    F, meta = robot.chain.F, robot.chain.meta
    if not np.allclose(meta[:, :3], [0.0, 0.0, 1.0]):
        return None  # DH robots always move about / along z
    model = pin.Model()
    parent = 0
    for i in range(robot.n):
        off = meta[i, 4]
        P = F[i].copy()
        if meta[i, 3] == 0:  # revolute: Rz(q + off) = Rz(off) Rz(q)
            c, s = np.cos(off), np.sin(off)
            P = P @ np.array([[c, -s, 0, 0], [s, c, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1.0]])
            joint = pin.JointModelRZ()
        else:  # prismatic: Tz(q + off) = Tz(off) Tz(q)
            P = P @ np.array([[1, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, off], [0, 0, 0, 1.0]])
            joint = pin.JointModelPZ()
        parent = model.addJoint(parent, joint, pin.SE3(P[:3, :3], P[:3, 3]), f"j{i + 1}")
    fid = model.addFrame(pin.Frame("tool", parent, 0, pin.SE3(F[robot.n][:3, :3],
                                                              F[robot.n][:3, 3]),
                                   pin.FrameType.OP_FRAME))
    return pin, model, model.createData(), fid


def rtb_ets(robot: sk.Robot):
    """The Robotics Toolbox ETS of a DHRobot built from the same table, or None."""
    try:
        import roboticstoolbox as rtb
    except ImportError:
        return None
    links = []
    for r in robot.dh:
        if robot.convention == "standard":
            cls = rtb.RevoluteDH if r.type == "R" else rtb.PrismaticDH
        else:
            cls = rtb.RevoluteMDH if r.type == "R" else rtb.PrismaticMDH
        if r.type == "R":
            links.append(cls(a=r.a, alpha=r.alpha, d=r.d, offset=r.theta))
        else:
            links.append(cls(a=r.a, alpha=r.alpha, theta=r.theta, offset=r.d))
    dh = rtb.DHRobot(links, base=robot.base, tool=robot.tool, name=robot.name)
    return dh.ets()


# ---------------------------------------------------------------------------- run
def bench_robot(robot: sk.Robot, batch: int, number: int) -> list[tuple]:
    """Measure one robot; return table rows (measure, serialkin, pin, rtb, unit)."""
    rng = np.random.default_rng(0)
    q = robot.random_q(seed=rng)
    Q = robot.random_q(batch, seed=rng)
    robot.fk(q), robot.jacobian(q), robot.fk(Q[:10])  # compile / warm up

    sk_fk = best_us(lambda: robot.fk(q), number)
    sk_jac = best_us(lambda: robot.jacobian(q), number)
    sk_batch = best_rate(lambda: robot.fk(Q), batch)

    pin_fk = pin_jac = pin_batch = np.nan
    peer = pin_model(robot)
    if peer is not None:
        pin, model, data, fid = peer
        pin.forwardKinematics(model, data, q)
        pin.updateFramePlacement(model, data, fid)
        err = np.abs(data.oMf[fid].homogeneous - robot.fk(q)).max()
        J = pin.computeFrameJacobian(model, data, q, fid, pin.LOCAL_WORLD_ALIGNED)
        err = max(err, np.abs(J - robot.jacobian(q)).max())
        if err > 1e-9:
            print(f"  ! pinocchio disagrees with serialkin on {robot.name}: {err:.2e}")

        def pin_fk_call():
            pin.forwardKinematics(model, data, q)
            pin.updateFramePlacement(model, data, fid)

        pin_fk = best_us(pin_fk_call, number)
        pin_jac = best_us(
            lambda: pin.computeFrameJacobian(model, data, q, fid, pin.LOCAL_WORLD_ALIGNED),
            number)
        k = min(batch, 20000)

        def pin_loop():
            for qi in Q[:k]:
                pin.forwardKinematics(model, data, qi)
                pin.updateFramePlacement(model, data, fid)

        pin_batch = best_rate(pin_loop, k)

    rtb_fk = rtb_jac = rtb_batch = np.nan
    ets = rtb_ets(robot)
    if ets is not None:
        err = max(np.abs(ets.eval(q) - robot.fk(q)).max(),
                  np.abs(ets.jacob0(q) - robot.jacobian(q)).max())
        if err > 1e-9:
            print(f"  ! robotics toolbox disagrees with serialkin on {robot.name}: {err:.2e}")
        n_rtb = max(number // 20, 200)
        rtb_fk = best_us(lambda: ets.eval(q), n_rtb)
        rtb_jac = best_us(lambda: ets.jacob0(q), n_rtb)
        rtb_batch = best_rate(lambda: ets.eval(Q), batch, repeat=2)

    return [
        ("fk(q) latency [µs]", sk_fk, pin_fk, rtb_fk, "lat"),
        ("jacobian(q) latency [µs]", sk_jac, pin_jac, rtb_jac, "lat"),
        (f"batch fk, {batch:,} q [M q/s]", sk_batch / 1e6, pin_batch / 1e6, rtb_batch / 1e6,
         "rate"),
    ]


def ratio(a: float, b: float) -> str:
    """Format a/b, or '-' when the peer is missing."""
    return "-" if not np.isfinite(b) or b == 0 else f"{a / b:.2f}"


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--batch", type=int, default=100_000, help="batch size (default 100000)")
    ap.add_argument("--quick", action="store_true", help="fewer repetitions")
    args = ap.parse_args(argv)
    number = 2000 if args.quick else 20000
    robots = [models.panda(), models.ur5(), models.planar(20, 0.01675, name="planar20")]

    try:
        import numba

        threads = numba.get_num_threads()
    except Exception:  # pragma: no cover
        threads = "?"
    print(f"serialkin {sk.__version__}, numpy {np.__version__}, Python "
          f"{platform.python_version()}, {os.cpu_count()} CPUs, numba threads {threads}")
    print("pin: same-DH Pinocchio model; rtb: Robotics Toolbox ETS of the same DH table.")
    print("Ratios serialkin/peer: < 1 faster for latency rows, > 1 faster for throughput.\n")
    head = (f"{'robot':9s} {'measure':28s} {'serialkin':>10s} {'pin':>10s} {'rtb':>10s} "
            f"{'sk/pin':>7s} {'sk/rtb':>7s}")
    print(head)
    print("-" * len(head))
    for robot in robots:
        for name, a, b, c, _ in bench_robot(robot, args.batch, number):
            print(f"{robot.name:9s} {name:28s} {a:10.3f} {b:10.3f} {c:10.3f} "
                  f"{ratio(a, b):>7s} {ratio(a, c):>7s}", flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
