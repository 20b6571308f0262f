"""Every inverse-kinematics solution of a pose: ``ik_all`` on ideal, general and calibrated arms.

1. The UR5: its 8 closed-form branches (shoulder left/right × elbow up/down × wrist
   flip) for one pose, all drawn, each meeting the target through FK.
2. A general 6R arm from a random DH table (no closed form): the 2-D subproblem search
   finds every solution (an even number, up to 16).
3. A "calibrated" UR5 whose DH twists and offsets are off by up to 0.01 rad and lengths
   by 1 mm: the ideal closed form gives one candidate per branch, Newton polishes each
   on the true arm (mode ``near``).
4. A Panda (7 joints) with joint 3 locked (``free={2: value}``): a 6R problem per value;
   sweeping the value samples the self-motion of the tool pose.
5. A batch of 500 UR5 targets in one call (an ``AllSolutions`` of counts and rows).

Writes ``ur5_eight_solutions.png`` and ``panda_self_motion.png`` into
``$SERIALKIN_EXAMPLE_OUT`` (default: a new temporary folder).
Run: ``python examples/all_ik_solutions.py`` (a few seconds).
"""

import os
import tempfile
import time
from pathlib import Path

import matplotlib

matplotlib.use("Agg")  # files only, no window

import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

import serialkin as sk  # noqa: E402
from serialkin.ik.analytic import ik_all  # noqa: E402
from serialkin.viz import plot_robot  # noqa: E402

out = Path(os.environ.get("SERIALKIN_EXAMPLE_OUT") or tempfile.mkdtemp(prefix="serialkin_"))
out.mkdir(parents=True, exist_ok=True)


def worst_fk_error(robot, rows, T):
    """Largest |FK(q) − T| entry over the solution rows (0 for no rows)."""
    return float(np.abs(robot.fk(rows) - T).max()) if len(rows) else 0.0


def contains(rows, q):
    """Whether q is among the rows, revolute angles compared modulo 2π."""
    d = (rows - q + np.pi) % (2 * np.pi) - np.pi
    return bool(np.abs(d).max(axis=1).min() < 1e-6)


# --- 1. UR5: the eight branches ------------------------------------------------------------
ur5 = sk.models.ur5()
q_true = np.array([0.3, -1.0, 1.2, -0.5, 0.8, 0.2])
T = ur5.fk(q_true)
res = ur5.ik_all(T, report=True)                      # AllSolutions: rows and how they came
sols = res.q
print(f"UR5 ({res.kind}, mode {res.mode}): {len(sols)} solutions, "
      f"worst FK error {worst_fk_error(ur5, sols, T):.1e}")
assert len(sols) == 8 and worst_fk_error(ur5, sols, T) < 1e-9 and contains(sols, q_true)
for q in sols:
    print("   ", np.round(q, 3))
near = ur5.ik_all(T, reference=np.zeros(6))           # the same rows, nearest q = 0 first
print("  nearest to q = 0:", np.round(near[0], 3))

fig = plt.figure(figsize=(12, 6))
for k, q in enumerate(sols):
    ax = fig.add_subplot(2, 4, k + 1, projection="3d")
    plot_robot(ur5, q, ax=ax, color=f"C{k}")
    ax.scatter(*T[:3, 3], color="red", s=30)          # the target position
    ax.set_title(f"solution {k + 1}", fontsize=9)
    ax.set_xlim(-0.6, 0.6), ax.set_ylim(-0.6, 0.6), ax.set_zlim(-0.2, 1.0)
    ax.tick_params(labelsize=6)
fig.suptitle("UR5: the 8 closed-form solutions of one pose (red dot: the tool position)")
fig.tight_layout()
fig.savefig(out / "ur5_eight_solutions.png", dpi=80)
plt.close(fig)

# --- 2. A general 6R arm: no closed form, the 2-D search ---------------------------------
rng = np.random.default_rng(5)
general = sk.Robot.from_dh([sk.DHLink(a=rng.uniform(0.05, 0.5), alpha=rng.uniform(-3.0, 3.0),
                                      d=rng.uniform(-0.3, 0.3)) for _ in range(6)],
                           name="random 6R")
q_true = rng.uniform(-np.pi, np.pi, 6)
T = general.fk(q_true)
t0 = time.perf_counter()
res = ik_all(general, T, report=True)
ms = (time.perf_counter() - t0) * 1e3
print(f"\n{general.name} ({res.kind}, mode {res.mode}): {len(res.q)} solutions in {ms:.0f} ms, "
      f"worst FK error {worst_fk_error(general, res.q, T):.1e}")
assert len(res.q) % 2 == 0 and contains(res.q, q_true)
assert worst_fk_error(general, res.q, T) < 1e-9

# --- 3. A calibrated UR5: nearly, not exactly, of the UR class ---------------------------
rows = [sk.DHLink(a=r.a + rng.uniform(-1e-3, 1e-3), alpha=r.alpha + rng.uniform(-0.01, 0.01),
                  d=r.d + rng.uniform(-1e-3, 1e-3), theta=r.theta + rng.uniform(-0.01, 0.01),
                  qlim=r.qlim)
        for r in ur5.dh]
calibrated = sk.Robot.from_dh(rows, ur5.convention, base=ur5.base, tool=ur5.tool,
                              name="UR5 (calibrated)")
q_true = np.array([0.3, -1.0, 1.2, -0.5, 0.8, 0.2])
T = calibrated.fk(q_true)
res = ik_all(calibrated, T, report=True)
print(f"\n{calibrated.name}: mode {res.mode} (idealised class {res.kind}), "
      f"{len(res.q)} solutions, worst FK error {worst_fk_error(calibrated, res.q, T):.1e}")
ideal = ur5.ik_all(T)                                 # the data-sheet model for the same pose
err_ideal = np.linalg.norm(calibrated.fk(ideal)[:, :3, 3] - T[:3, 3], axis=1).max()
print(f"  the data-sheet closed form would miss this pose by up to {err_ideal * 1e3:.1f} mm")
assert len(res.q) == 8 and worst_fk_error(calibrated, res.q, T) < 1e-9

# --- 4. Panda with a locked joint: sampling the self-motion ------------------------------
panda = sk.models.panda()
q_true = np.array([0.2, -0.3, 0.4, -2.0, 0.1, 1.8, 0.6])
T = panda.fk(q_true)
locked = np.linspace(q_true[2] - 0.9, q_true[2] + 0.9, 13)   # values of joint 3 [rad]
sweep = []                                            # (value, row nearest q_true) per value
for v in locked:
    rows = panda.ik_all(T, free={2: v}, reference=q_true)
    assert worst_fk_error(panda, rows, T) < 1e-9 and np.all(rows[:, 2] == v)
    if len(rows):
        sweep.append(rows[0])
sweep = np.array(sweep)
print(f"\nPanda, joint 3 locked at {len(locked)} values in "
      f"[{locked[0]:.2f}, {locked[-1]:.2f}] rad: {len(sweep)} with a solution inside the limits")
print(f"  along the sweep joint 1 moves over "
      f"[{sweep[:, 0].min():.2f}, {sweep[:, 0].max():.2f}] rad "
      f"with the tool pose fixed (the elbow, joint 4, stays near {sweep[:, 3].mean():.2f} rad)")

fig = plt.figure(figsize=(11, 4.5))
ax = fig.add_subplot(1, 2, 1, projection="3d")
for k, q in enumerate(sweep):
    plot_robot(panda, q, ax=ax, color=plt.cm.viridis(k / max(len(sweep) - 1, 1)), alpha=0.7,
               linewidth=1.5)
ax.set_title("Panda: one tool pose, joint 3 swept (self-motion)", fontsize=9)
ax2 = fig.add_subplot(1, 2, 2)
for j in range(7):
    ax2.plot(sweep[:, 2], sweep[:, j], "o-", ms=3, label=f"q{j + 1}")
ax2.set_xlabel("locked joint 3 [rad]")
ax2.set_ylabel("joint angle [rad]")
ax2.legend(fontsize=7, ncol=2)
ax2.grid(alpha=0.3)
fig.tight_layout()
fig.savefig(out / "panda_self_motion.png", dpi=80)
plt.close(fig)

# --- 5. A batch: one call, many targets --------------------------------------------------
Q = ur5.random_q(500, seed=2)
targets = ur5.fk(Q)                                   # (500, 4, 4)
ur5.ik_all(targets[:2])                               # warm-up (kernel loading)
t0 = time.perf_counter()
batch = ur5.ik_all(targets)                           # AllSolutions: q (500, 8, 6), count (500,)
dt = time.perf_counter() - t0
counts = np.bincount(batch.count, minlength=9)
print(f"\nUR5 batch of {len(targets)} poses in {dt * 1e3:.1f} ms "
      f"({dt / len(targets) * 1e6:.1f} µs per pose); solutions per pose: "
      + ", ".join(f"{k}: {c}" for k, c in enumerate(counts) if c))
for i in (0, 17, 499):
    rows = batch.solutions(i)
    assert contains(rows, Q[i]) and worst_fk_error(ur5, rows, targets[i]) < 1e-9
print("\nwrote", ", ".join(sorted(p.name for p in out.iterdir())), "to", out)
