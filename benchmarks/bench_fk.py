"""Forward kinematics and Jacobian speed: serialkin beside Pinocchio and Robotics Toolbox.

Run by hand: ``.venv/bin/python benchmarks/bench_fk.py [--batch 100000] [--quick]``.

For the Panda, the UR5 and a planar 20-link arm it measures, in one run:

* single-call latency of ``robot.fk(q)``, ``robot.jacobian(q)`` (one float64 q, a new
  array returned), the same with ``out=`` buffers, ``robot.jacobian_dot(q, qd)`` and
  ``robot.hessian(q)``;
* batch FK throughput over 100,000 random configurations (``robot.fk(Q)``),

and the same for the peers when the ``bench`` extra is installed:

* Pinocchio (``pin``): a model built from the *same* DH table (one revolute/prismatic
  z joint per row, the fixed transforms as joint placements, the tool as a frame), so
  both libraries compute exactly the same kinematics (checked before timing).
  FK = ``forwardKinematics`` + ``updateFramePlacement`` (Pinocchio's update alone: no
  array is returned; one row adds ``data.oMf[fid].homogeneous``, the 4×4 array that
  ``robot.fk`` returns); Jacobian = ``computeFrameJacobian(..., LOCAL_WORLD_ALIGNED)``;
  J̇ = ``computeJointJacobiansTimeVariation`` + ``getFrameJacobianTimeVariation``;
  Hessian = ``computeJointJacobians`` + ``computeJointKinematicHessians`` +
  ``getJointKinematicHessian``; batch = a Python loop of FK calls.
* Robotics Toolbox for Python: a ``DHRobot`` built from the same table, timed through its
  ETS (``ets.eval(q)``, ``ets.jacob0(q)``, ``ets.hessian0(q)``; batch ``ets.eval(Q)``).

Each latency is the **median over 15 runs** of ``number`` calls, serialkin's and the
peers' runs interleaved (so that they see the same machine load), with the 10–90 %
spread of the runs; throughputs are the median of 20 runs (serialkin) and of 3 (the
peers' Python loops). Ratios are serialkin / peer
medians: below 1 is faster for latencies, above 1 is faster for throughput.
"""

from __future__ import annotations

import argparse
import sys

import numpy as np
from _common import Stat, header, interleaved_us, record, wall_s

import serialkin as sk
from serialkin import models


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
    """Measure one robot; return rows (measure, serialkin Stat, pin Stat|None, rtb Stat|None)."""
    rng = np.random.default_rng(0)
    q = robot.random_q(seed=rng)
    qd = rng.normal(size=robot.n)
    Q = robot.random_q(batch, seed=rng)
    T, J = np.empty((4, 4)), np.empty((6, robot.n))
    sk_calls = {
        "fk": lambda: robot.fk(q),
        "fk_out": lambda: robot.fk(q, out=T),
        "jac": lambda: robot.jacobian(q),
        "jac_out": lambda: robot.jacobian(q, out=J),
        "jdot": lambda: robot.jacobian_dot(q, qd),
        "hess": lambda: robot.hessian(q),
    }
    peer_calls: dict[str, object] = {}
    peer = pin_model(robot)
    if peer is not None:
        pin, model, data, fid = peer
        pin.forwardKinematics(model, data, q)
        pin.updateFramePlacement(model, data, fid)
        err = np.abs(data.oMf[fid].homogeneous - robot.fk(q)).max()
        Jp = pin.computeFrameJacobian(model, data, q, fid, pin.LOCAL_WORLD_ALIGNED)
        err = max(err, np.abs(Jp - robot.jacobian(q)).max())
        pin.computeJointJacobiansTimeVariation(model, data, q, qd)
        dJ = pin.getFrameJacobianTimeVariation(model, data, fid, pin.LOCAL_WORLD_ALIGNED)
        err = max(err, np.abs(dJ - robot.jacobian_dot(q, qd)).max())
        if err > 1e-9:
            print(f"  ! pinocchio disagrees with serialkin on {robot.name}: {err:.2e}")

        def pin_fk():
            pin.forwardKinematics(model, data, q)
            pin.updateFramePlacement(model, data, fid)

        def pin_jdot():
            pin.computeJointJacobiansTimeVariation(model, data, q, qd)
            return pin.getFrameJacobianTimeVariation(model, data, fid, pin.LOCAL_WORLD_ALIGNED)

        def pin_hess():
            pin.computeJointJacobians(model, data, q)
            pin.computeJointKinematicHessians(model, data, q)
            return pin.getJointKinematicHessian(model, data, robot.n, pin.LOCAL_WORLD_ALIGNED)

        def pin_fk_array():
            pin.forwardKinematics(model, data, q)
            pin.updateFramePlacement(model, data, fid)
            return data.oMf[fid].homogeneous

        peer_calls.update({
            "pin_fk": pin_fk,
            "pin_fk_array": pin_fk_array,
            "pin_jac": lambda: pin.computeFrameJacobian(model, data, q, fid,
                                                        pin.LOCAL_WORLD_ALIGNED),
            "pin_jdot": pin_jdot,
            "pin_hess": pin_hess,
        })
    ets = rtb_ets(robot)
    if ets is not None:
        err = max(np.abs(ets.eval(q) - robot.fk(q)).max(),
                  np.abs(ets.jacob0(q) - robot.jacobian(q)).max())
        if err > 1e-9:
            print(f"  ! robotics toolbox disagrees with serialkin on {robot.name}: {err:.2e}")
        peer_calls.update({"rtb_fk": lambda: ets.eval(q), "rtb_jac": lambda: ets.jacob0(q),
                           "rtb_hess": lambda: ets.hessian0(q)})
    t = interleaved_us({**sk_calls, **peer_calls}, number)
    robot.fk(Q[:10])
    sk_batch = Stat(batch / wall_s(lambda: robot.fk(Q), repeat=20).values / 1e6)
    pin_batch = rtb_batch = None
    if peer is not None:
        k = min(batch, 20000)

        def pin_loop():
            for qi in Q[:k]:
                pin.forwardKinematics(model, data, qi)
                pin.updateFramePlacement(model, data, fid)

        pin_batch = Stat(k / wall_s(pin_loop, repeat=3).values / 1e6)
    if ets is not None:
        rtb_batch = Stat(batch / wall_s(lambda: ets.eval(Q), repeat=3).values / 1e6)
    g = t.get
    return [
        ("fk(q) [µs]", t["fk"], g("pin_fk"), g("rtb_fk")),
        ("fk(q), pin + 4x4 array [µs]", t["fk"], g("pin_fk_array"), g("rtb_fk")),
        ("fk(q, out=T) [µs]", t["fk_out"], g("pin_fk"), g("rtb_fk")),
        ("jacobian(q) [µs]", t["jac"], g("pin_jac"), g("rtb_jac")),
        ("jacobian(q, out=J) [µs]", t["jac_out"], g("pin_jac"), g("rtb_jac")),
        ("jacobian_dot(q, qd) [µs]", t["jdot"], g("pin_jdot"), None),
        ("hessian(q) [µs]", t["hess"], g("pin_hess"), g("rtb_hess")),
        (f"batch fk, {batch:,} q [M q/s]", sk_batch, pin_batch, rtb_batch),
    ]


def ratio(a: Stat, b: Stat | None) -> str:
    """Format a/b of the medians, or '-' when the peer is missing."""
    return "-" if b is None or b.median == 0 else f"{a / b:.2f}"


def cell(s: Stat | None) -> str:
    """'median [10-90 %]' or '-'."""
    return "-" if s is None else s.fmt(3 if s.median < 10 else 1)


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--batch", type=int, default=100_000, help="batch size (default 100000)")
    ap.add_argument("--quick", action="store_true", help="fewer repetitions")
    args = ap.parse_args(argv)
    number = 1000 if args.quick else 10000
    robots = [models.panda(), models.ur5(), models.planar(20, 0.01675, name="planar20")]
    print(header())
    print("pin: same-DH Pinocchio model; rtb: Robotics Toolbox ETS of the same DH table.")
    print("median [10-90 %] of 15 interleaved runs; ratios serialkin/peer medians: < 1 faster "
          "for latency rows, > 1 faster for throughput.\n")
    head = (f"{'robot':9s} {'measure':28s} {'serialkin':>22s} {'pin':>22s} {'rtb':>22s} "
            f"{'sk/pin':>7s} {'sk/rtb':>7s}")
    print(head)
    print("-" * len(head))
    for robot in robots:
        for name, a, b, c in bench_robot(robot, args.batch, number):
            print(f"{robot.name:9s} {name:28s} {cell(a):>22s} {cell(b):>22s} {cell(c):>22s} "
                  f"{ratio(a, b):>7s} {ratio(a, c):>7s}", flush=True)
            if robot.name in ("UR5", "Panda", "ur5", "panda") and b is not None and (
                    name.startswith("fk(q) ") or name.startswith("jacobian(q) ")):
                r = a / b
                record("11.1", f"{robot.name} {name.split(' [')[0]} / Pinocchio "
                       f"{'FK update' if name.startswith('fk') else 'computeFrameJacobian'}",
                       r, "x (median ratio)", "<= 1", r <= 1.0)
    return 0


if __name__ == "__main__":
    sys.exit(main())
