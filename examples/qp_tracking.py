"""Differential IK as a quadratic program: hard joint limits and obstacles vs weighted tasks.

``serialkin.diffik`` computes each joint step Δq as the solution of a small QP:

    minimise ½ Σ w (J Δq − gain·e)² + ½ μ ‖Δq‖²   subject to   lb ≤ Δq ≤ ub,  G Δq ≤ h

where the bounds are the joint and velocity limits and the rows ``G Δq ≤ h`` keep every
link at least ``safety`` metres from the obstacles (velocity damper). In the chapter's
weighted multi-task resolution (eq 48) limits and obstacles are only heavy weights.

1. One target 20 cm from a Panda, past a ball: ``DiffIK`` steps reach it; with joint 4's
   range cut short the target is out of reach, and the QP stops on the limit and at the
   safety distance from the ball instead of trading them for the task.
2. The chapter's 20-link arm between four obstacles with ±100° limits (Figure 12),
   tracked by eq 48 (the scenario's own solver) and by the QP (``QPResolver``):
   both follow the path, the QP goes right up to the limits and the safety distance but
   never past them; eq 48 keeps a wider berth through its buffers.

Writes ``qp_vs_eq48.png`` (clearance and joint-limit margin along the path) into
``$SERIALKIN_EXAMPLE_OUT`` (default: a new temporary folder).
Run: ``python examples/qp_tracking.py`` (a few seconds).
"""

import os
import tempfile
from pathlib import Path

import matplotlib

matplotlib.use("Agg")  # files only, no window

import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

import serialkin as sk  # noqa: E402
from serialkin.diffik import (  # noqa: E402
    CollisionAvoidance,
    DiffIK,
    FrameTask,
    PositionLimit,
    PostureTask,
    QPResolver,
    VelocityLimit,
)
from serialkin.model.geometry import Sphere  # noqa: E402
from serialkin.redundancy import clearances  # noqa: E402
from serialkin.tracking import load_scenario, track  # noqa: E402

out = Path(os.environ.get("SERIALKIN_EXAMPLE_OUT") or tempfile.mkdtemp(prefix="serialkin_"))
out.mkdir(parents=True, exist_ok=True)

# --- 1. One QP step at a time: Panda, joint 4's range and a sphere -------------------------
# The target is 20 cm away, past a ball. With joint 4's range cut short at -1.9 rad the
# target is out of reach: the QP stops with joint 4 exactly on its limit and the links at
# the safety distance from the ball (the task gives way, the constraints never do).
panda = sk.models.panda()
q_start = np.array([0.0, -0.4, 0.0, -2.0, 0.0, 1.6, 0.8])
target = panda.fk(q_start)
target[:3, 3] += [0.15, 0.10, -0.10]
ball = Sphere(0.05, center=[0.50, 0.05, 0.45], name="ball")
safety = 0.01                                         # d_s [m], links as capsules of 5 cm
print(f"{'joint 4 range [rad]':<22}{'QP steps':>9}{'final error':>14}{'max q4':>9}"
      f"{'min clearance':>15}")
for upper in (-1.5, -1.9):
    qlim = panda.qlim.copy()
    qlim[3] = (-2.6, upper)
    arm = panda.with_limits(qlim)
    ik = DiffIK(arm,
                tasks=[FrameTask(target, task="pose"), PostureTask(q_start, weight=1e-6)],
                constraints=[PositionLimit(), VelocityLimit(vmax=1.0, dt=0.05),
                             CollisionAvoidance([ball], link_radius=0.05, safety=safety)])
    q = q_start
    history = [q]
    for _ in range(100):
        step = ik.step(q)
        assert step.success, step.reason              # a failure is a result, never NaN
        q = q + step.dq
        history.append(q)
        if np.linalg.norm(step.dq) < 1e-9:
            break
    history = np.array(history)
    d = np.array([clearances(arm, qk, [ball], link_radius=0.05).min() for qk in history])
    err = np.linalg.norm(arm.fk(q)[:3, 3] - target[:3, 3])
    print(f"{f'[-2.6, {upper}]':<22}{len(history) - 1:>9}{err * 1e3:>11.3f} mm"
          f"{history[:, 3].max():>9.4f}{d.min() * 1e3:>12.2f} mm")
    assert np.all(history[:, 3] <= upper + 1e-6)      # hard: never past the limit
    assert d.min() > 0.9 * safety                     # linearised: d_s up to 2nd-order terms
print(f"  (safety distance {safety * 1e3:.0f} mm; the velocity damper holds it to first order)")

# --- 2. The 20-link arm: eq 48 against the QP ----------------------------------------------
sc = load_scenario("twenty_link_obstacles")
weighted = sc.run()                                   # the scenario's solver: eq 48
qp = track(sc.robot, sc.path,
           QPResolver(task=sc.path.task, obstacles=sc.obstacles, safety=0.002,
                      max_joint_step=0.2),
           q0=sc.q0)
print(f"\n{sc.name}: {sc.description}")
print(f"  {'solver':<28}{'max error':>11}{'iterations':>12}{'min clearance':>15}"
      f"{'min limit margin':>18}")
for name, tr in (("eq 48 (weighted tasks)", weighted), ("QP (hard constraints)", qp)):
    print(f"  {name:<28}{tr.max_error * 1e3:>8.2f} mm{int(tr.iterations.sum()):>12}"
          f"{tr.min_clearance * 1e3:>12.2f} mm{np.degrees(tr.min_limit_margin):>15.2f} °")
    assert tr.complete and tr.max_error <= tr.tolerance
assert qp.min_limit_margin >= 0.0 and qp.min_clearance > 0.0     # never past a limit
limit = np.radians(100)
assert np.abs(qp.q).max() <= limit + 1e-12

fig, axes = plt.subplots(1, 2, figsize=(11, 3.8))
s = np.arange(len(qp.q))
for name, tr, style in (("eq 48", weighted, "C0"), ("QP", qp, "C3")):
    axes[0].plot(s, tr.clearance.min(axis=1) * 1e3, style, label=name)
    axes[1].plot(s, np.degrees(tr.limit_margin.min(axis=1)), style, label=name)
axes[0].axhline(2.0, color="k", ls="--", lw=0.8, label="QP safety 2 mm")
axes[0].set_ylabel("smallest clearance [mm]")
axes[1].set_ylabel("smallest joint-limit margin [deg]")
for ax in axes:
    ax.set_xlabel("path point")
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8)
fig.suptitle("20-link arm between four obstacles, limits ±100°: eq 48 vs the QP")
fig.tight_layout()
fig.savefig(out / "qp_vs_eq48.png", dpi=80)
plt.close(fig)
print("\nwrote", ", ".join(sorted(p.name for p in out.iterdir())), "to", out)
