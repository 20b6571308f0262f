"""Redundancy resolution and path tracking: the chapter's 6-link and 20-link examples.

1. Null space (eq 42): self-motion of a redundant arm leaves the end-effector still while
   it climbs the manipulability objective (eq 43).
2. The 6-link arm tracking a circle with damped least squares (eq 46 corrected; Figures
   8-9), from the shipped scenario ``six_link_circle``.
3. The 20-link arm following the same path in free space (Figure 11) and between four
   obstacles with joint limits of ±100° (Figure 12), weighted multi-task resolution
   (eq 48) from the shipped scenarios ``twenty_link_free`` / ``twenty_link_obstacles``.

Writes ``twenty_link_tracking.png`` and ``six_link_circle.csv`` into
``$SERIALKIN_EXAMPLE_OUT`` (default: a new temporary folder).
Run: ``python examples/redundancy_tracking.py`` (a few seconds).
"""

import os
import tempfile
from pathlib import Path

import matplotlib

matplotlib.use("Agg")  # files only, no window

import numpy as np  # noqa: E402

from serialkin.redundancy import (  # noqa: E402
    clearances,
    manipulability,
    nullspace_projector,
    self_motion,
)
from serialkin.tracking import load_scenario  # noqa: E402
from serialkin.viz import tracking_figure  # noqa: E402

out = Path(os.environ.get("SERIALKIN_EXAMPLE_OUT") or tempfile.mkdtemp(prefix="serialkin_"))
out.mkdir(parents=True, exist_ok=True)

# --- 1. Null space of the 6-link arm (task: the planar position, m = 2 < n = 6) ----------
six = load_scenario("six_link_circle")
arm = six.robot
q = np.radians([20, 30, -40, 50, -30, 20])
J = arm.jacobian(q)[:2]                               # rows vx, vy
P = nullspace_projector(J)                            # I − J⁺J
v = np.random.default_rng(0).normal(size=arm.n)
print(f"6-link arm: |J (I − J⁺J) v| = {np.linalg.norm(J @ P @ v):.1e} for a random v")
w = manipulability(arm, task="planar")                # eq 43 on the planar task
# 200 steps of at most 0.01 rad: the drift is the integration error of the finite steps
# (it shrinks with max_step); the projection itself is exact, as printed above
Q = self_motion(arm, q, w, steps=200, gain=1.0, task="planar", max_step=0.01)
drift = np.linalg.norm(arm.fk(Q)[:, :2, 3] - arm.fk(q)[:2, 3], axis=1).max()
print(f"  self-motion along ∇w: manipulability {w.value(Q[0]):.4f} -> {w.value(Q[-1]):.4f}, "
      f"end-effector drift {drift * 1e3:.2f} mm over 200 steps")

# --- 2. The 6-link circle (Figures 8-9) --------------------------------------------------
traj6 = six.run()
print(f"\n{six.name}: {six.description}")
print(f"  {len(traj6)} path points, max tracking error {traj6.max_error * 1e3:.4f} mm "
      f"(tolerance {traj6.tolerance * 1e3:.0f} mm), {traj6.iterations.sum()} DLS iterations")
print(f"  joint ranges over the circle [deg]: "
      f"{np.round(np.degrees(np.ptp(traj6.q, axis=0)), 1).tolist()}")
traj6.save(out / "six_link_circle.csv")                # also .npz; Trajectory.load reads both

# --- 3. The 20-link arm: free (Figure 11) vs four obstacles and ±100° limits (Figure 12) --
free = load_scenario("twenty_link_free")
constrained = load_scenario("twenty_link_obstacles")
traj_free = free.run()
traj_obs = constrained.run()
obstacles = constrained.obstacles
print(f"\n{free.name}: max error {traj_free.max_error * 1e3:.4f} mm, "
      f"max |q| {np.degrees(np.abs(traj_free.q).max()):.1f} deg")
print(f"{constrained.name}: max error {traj_obs.max_error * 1e3:.4f} mm, "
      f"max |q| {np.degrees(np.abs(traj_obs.q).max()):.1f} deg (limit 100), "
      f"min joint-limit margin {np.degrees(traj_obs.min_limit_margin):.1f} deg")
# clearance of every obstacle along each motion (the free arm ignores the obstacles)
free_clear = np.array([clearances(free.robot, qk, obstacles).min(axis=0) for qk in traj_free.q])
for j, ob in enumerate(obstacles):
    print(f"  obstacle {ob.name}: min clearance {traj_obs.clearance[:, j].min() * 1e3:7.2f} mm "
          f"with the obstacle task, {free_clear[:, j].min() * 1e3:7.2f} mm for the free motion")
same_path = np.abs(traj_obs.positions[:, :2] - traj_free.positions[:, :2]).max()
diff_q = np.degrees(np.abs(traj_obs.q - traj_free.q).max())
print(f"  same task-space path (max end-effector difference {same_path * 1e3:.3f} mm), "
      f"different self-motion (max joint difference {diff_q:.0f} deg)")

fig = tracking_figure(traj_obs, constrained.robot, obstacles=obstacles,
                      title="20-link arm between four obstacles (eq 48)")
fig.savefig(out / "twenty_link_tracking.png", dpi=80)
print("\nwrote", ", ".join(sorted(p.name for p in out.iterdir())), "to", out)
