"""Differential-IK QP benchmark: one QP step against pink and mink, and QP path tracking.

(1) One step on the Panda (7 joints) with the same task set for every library: a full
pose task on the tool frame, a posture task (cost 0.1, our weight 0.01), joint position
limits (gain 0.5) and joint velocity limits (dt = 0.05 s), solved by DAQP. A step starts
at a new configuration, so each timing includes the library's kinematics update
(serialkin: inside ``DiffIK.step``; pink: ``pink.Configuration(model, data, q)``; mink:
``configuration.update(q)``). pink and mink load the Panda from ``robot.to_urdf()``
(Pinocchio; MuJoCo with ``fusestatic="false"`` so that the tool frame stays a body, and
small bounded masses because the URDF has no inertias). Their frame tasks use the body-
frame SE(3) log with its Jacobian; ours the world-frame pose error with the geometric
Jacobian: the same task set, not the same maths to the last digit (tests/diffik checks
the agreement with pink on a task with identical maths). Rows: serialkin with DAQP called
directly (the default of ``DiffIK``), with the compiled dual active-set solver, through
qpsolvers (the same DAQP), pink, mink; goal 13.2: at most half of pink's and mink's time.

(2) QP path tracking of the 20-link scenario ``twenty_link_obstacles`` (obstacles,
limits ±100°): time per path point and per QP iteration, with the compiled loop and dual
active-set solver (the default) and with DAQP called from Python each iteration, against
the same scenario by eq 48 (the compiled weighted-task loop).

Timings are medians with the 10-90 % spread of interleaved runs; on a shared machine they
move with other processes' load (the header shows the load average).

Run: ``.venv/bin/python benchmarks/bench_diffik.py [--quick]``.
"""

from __future__ import annotations

import argparse

import numpy as np
from _common import Stat, header, interleaved_us, record, wall_s

import serialkin as sk
from serialkin.diffik import DiffIK, FrameTask, PositionLimit, PostureTask, VelocityLimit

DT = 0.05


def _configs(robot, q_star: np.ndarray, count: int) -> np.ndarray:
    """Configurations within ±0.15 rad of q_star (targets near: limits partly active)."""
    rng = np.random.default_rng(1)
    lim = robot.qlim
    return np.clip(q_star + rng.uniform(-0.15, 0.15, (count, robot.n)), lim[:, 0], lim[:, 1])


def _serialkin(robot, T, ref, vmax, solver):
    ik = DiffIK(robot, [FrameTask(T), PostureTask(ref, weight=0.01)],
                [PositionLimit(gain=0.5), VelocityLimit(vmax, DT)], damping=1e-12,
                solver=solver)
    return ik.step


def _pink(robot, T, ref, vmax):
    import pink
    import pinocchio as pin
    from pink.limits import ConfigurationLimit
    from pink.limits import VelocityLimit as PinkVelocityLimit
    from pink.tasks import FrameTask as PinkFrameTask
    from pink.tasks import PostureTask as PinkPostureTask

    model = pin.buildModelFromXML(robot.to_urdf())
    data = model.createData()
    model.velocityLimit[:] = vmax
    frame = PinkFrameTask("tool", position_cost=1.0, orientation_cost=1.0)
    frame.set_target(pin.SE3(T[:3, :3], T[:3, 3]))
    posture = PinkPostureTask(cost=0.1)
    posture.set_target(ref)
    limits = [ConfigurationLimit(model, config_limit_gain=0.5), PinkVelocityLimit(model)]

    def step(q):
        conf = pink.Configuration(model, data, q)
        return pink.solve_ik(conf, [frame, posture], DT, solver="daqp", damping=1e-12,
                             limits=limits) * DT

    return step


def mujoco_model(robot):
    """A MuJoCo model of the robot from its URDF (tool kept as a body, tiny masses)."""
    import mujoco

    urdf = robot.to_urdf()
    i = urdf.index(">", urdf.index("<robot")) + 1
    extra = ('<mujoco><compiler fusestatic="false" discardvisual="true" boundmass="0.01" '
             'boundinertia="0.0001"/></mujoco>')
    return mujoco.MjModel.from_xml_string(urdf[:i] + extra + urdf[i:])


def _mink(robot, T, ref, vmax):
    import mink

    model = mujoco_model(robot)
    conf = mink.Configuration(model)
    frame = mink.FrameTask("tool", "body", position_cost=1.0, orientation_cost=1.0)
    frame.set_target(mink.SE3.from_matrix(T))
    posture = mink.PostureTask(model, cost=0.1)
    posture.set_target(ref)
    names = [model.joint(j).name for j in range(model.njnt)]
    limits = [mink.ConfigurationLimit(model, gain=0.5),
              mink.VelocityLimit(model, dict(zip(names, vmax)))]

    def step(q):
        conf.update(q)
        return mink.solve_ik(conf, [frame, posture], DT, solver="daqp", damping=1e-12,
                             limits=limits) * DT

    return step


def qp_step_table(quick: bool) -> None:
    robot = sk.models.get("panda")
    q_star = robot.random_q(seed=2)
    Q = _configs(robot, q_star, 16)
    T = robot.fk(q_star)
    ref = robot.random_q(seed=3)
    vmax = np.linspace(0.8, 2.0, robot.n)
    makers = {
        "serialkin (DAQP direct)": lambda: _serialkin(robot, T, ref, vmax, "daqp"),
        "serialkin (compiled active set)": lambda: _serialkin(robot, T, ref, vmax,
                                                              "compiled"),
        "serialkin (qpsolvers: daqp)": lambda: _serialkin(robot, T, ref, vmax,
                                                          "qpsolvers:daqp"),
        "pink": lambda: _pink(robot, T, ref, vmax),
        "mink": lambda: _mink(robot, T, ref, vmax),
    }
    steps = {}
    for name, make in makers.items():
        try:
            steps[name] = make()
        except ImportError as exc:
            print(f"{name}: not installed ({exc.name}); pip install -e .[bench]")
    def runner(step):
        def run():
            for q in Q:
                step(q)
        return run

    stats = interleaved_us({k: runner(s) for k, s in steps.items()}, number=3 if quick else 10,
                           repeat=5 if quick else 15)
    stats = {k: Stat(v.values / len(Q)) for k, v in stats.items()}
    ours = stats["serialkin (DAQP direct)"]
    print("\n(1) one QP step, Panda, pose + posture tasks, position + velocity limits, DAQP")
    print(f"{'library':<30}{'µs per step, median [10-90 %]':>34}{'ratio to serialkin':>22}")
    for k, s in stats.items():
        print(f"{k:<30}{s.fmt(1):>34}{s / ours:>22.2f}")
    for peer in ("pink", "mink"):
        if peer in stats:
            ratio = ours / stats[peer]
            record("13.2", f"QP step Panda: serialkin / {peer} time", ratio, "x", "<= 0.5",
                   ratio <= 0.5)
    # agreement of the steps at one configuration (different frame-error maths: indicative)
    q = Q[0]
    d = {k: np.asarray(getattr(r, "dq", r)) for k, r in ((k, s(q)) for k, s in steps.items())}
    base = d["serialkin (DAQP direct)"]
    for k, v in d.items():
        print(f"  step at Q[0]: max |Δq − serialkin's| for {k}: {np.abs(v - base).max():.2e} rad")


def tracking_table(quick: bool) -> None:
    from serialkin.diffik.resolver import QPResolver
    from serialkin.tracking import load_scenario, track

    sc = load_scenario("twenty_link_obstacles")
    out = {}
    runs = {}
    for name, solver in (("QP, DAQP (hard constraints)", "daqp"),
                         ("QP, compiled active set", "compiled")):
        res = QPResolver(task=sc.path.task, obstacles=sc.obstacles, max_joint_step=0.2,
                         solver=solver)

        def qp(res=res, name=name):
            out[name] = track(sc.robot, sc.path, res, q0=sc.q0, tolerance=sc.tolerance)

        runs[name] = qp

    def eq48():
        out["eq 48 (weighted, compiled)"] = sc.run()

    runs["eq 48 (weighted, compiled)"] = eq48
    rep = 3 if quick else 7
    times = {k: wall_s(f, rep) for k, f in runs.items()}
    p = len(sc.path)
    print(f"\n(2) 20-link scenario twenty_link_obstacles ({p} points), whole path, "
          f"median [spread] of {rep} warm runs")
    print(f"{'solver':<34}{'ms per point':>22}{'µs per iteration':>20}{'min clearance':>16}"
          f"{'worst margin':>14}")
    for name, t in times.items():
        tr = out[name]
        its = int(tr.iterations.sum())
        per = Stat(t.values / p * 1e3)
        print(f"{name:<34}{per.fmt(3):>22}{t.median / its * 1e6:>20.1f}"
              f"{tr.min_clearance * 1e3:>13.2f} mm{np.degrees(tr.min_limit_margin):>12.2f} °")
    t_48 = times["eq 48 (weighted, compiled)"]
    for name in ("QP, compiled active set", "QP, DAQP (hard constraints)"):
        print(f"{name} / eq 48, time per point: {times[name].median / t_48.median:.1f}x")
    t_c = times["QP, compiled active set"]
    t_d = times["QP, DAQP (hard constraints)"]
    print(f"compiled loop against DAQP from Python: {t_d.median / t_c.median:.1f}x faster")
    record("13.3", "QP tracking 20-link (compiled loop): ms per path point",
           t_c.median / p * 1e3, "ms", "report", True)
    record("13.3", "QP tracking 20-link: DAQP-from-Python time / compiled-loop time",
           t_d.median / t_c.median, "x", "report", True)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="fewer repeats (a smoke run)")
    args = ap.parse_args()
    print(header())
    qp_step_table(args.quick)
    tracking_table(args.quick)


if __name__ == "__main__":
    main()
