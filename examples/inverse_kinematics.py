"""Inverse kinematics with serialkin: numerical methods, batches, closed form, failures.

Chapter sections 4.1 (closed form) and 5.3 (numerical methods). Every method is called
through the one entry point ``robot.ik(target, method=...)`` and returns the same
``IKResult`` (q, success, iterations, restarts, position/orientation error, reason).

Run: ``python examples/inverse_kinematics.py`` (about 5 s, most of it numba loading its
cached kernels). Writes no files.
"""

import time

import numpy as np

import serialkin as sk
from serialkin.ik import available_methods
from serialkin.ik.analytic import classify


def pose_error(robot, q, T):
    """Position error [m] and largest rotation-entry error of FK(q) against T."""
    Tq = robot.fk(q)
    return np.linalg.norm(Tq[:3, 3] - T[:3, 3]), np.abs(Tq[:3, :3] - T[:3, :3]).max()


print("IK methods:", ", ".join(available_methods()))

# --- 1. Several methods on the same reachable full-pose target (UR5 and Panda) -------------
# The target is FK of a random configuration inside the joint limits, so it is reachable.
for robot in (sk.models.ur5(), sk.models.panda()):
    T_target = robot.fk(robot.random_q(seed=1))
    print(f"\n{robot.name}: one full-pose target, seed=0 for the random restarts")
    print(f"  {'method':<13}{'success':>8}{'iter':>7}{'restarts':>9}"
          f"{'pos err [m]':>13}{'ori err [rad]':>15}{'time [ms]':>11}")
    for method in ("lm", "dls", "pinv", "sdls", "newton", "lm_chan", "ccd", "bfgs"):
        robot.ik(T_target, method=method, seed=0)  # first call loads the compiled kernels
        t0 = time.perf_counter()
        r = robot.ik(T_target, method=method, seed=0)
        ms = (time.perf_counter() - t0) * 1e3
        print(f"  {method:<13}{r.success!s:>8}{r.iterations:>7}{r.restarts:>9}"
              f"{r.position_error:>13.1e}{r.orientation_error:>15.1e}{ms:>11.2f}")
        if r.success:  # a success always means FK(q) reproduces the target within tol
            assert robot.within_limits(r.q)
    # CCD converges linearly: at the default tol = 1e-9 it may spend its whole budget on a
    # full 6-D pose (success=False, with its best errors); a looser tolerance suits it
    r = robot.ik(T_target, method="ccd", tol=1e-6, seed=0)
    print(f"  ccd with tol=1e-6: success={r.success} after {r.iterations} sweeps")

# --- 2. Position-only targets and masks ----------------------------------------------------
panda = sk.models.panda()
p = np.array([0.4, 0.2, 0.5])                       # a 3-vector is a position target
r = panda.ik(p, seed=0)
print(f"\nPanda, position only {p}: success={r.success}, "
      f"reached {np.round(panda.fk(r.q)[:3, 3], 9)}")
# a mask selects task coordinates [vx, vy, vz, wx, wy, wz]: here x, y, z and the yaw rate
T = panda.fk(panda.random_q(seed=3))
r = panda.ik(T, mask=[1, 1, 1, 0, 0, 1], seed=0)
print(f"Panda, pose target with mask [1,1,1,0,0,1] (m = 4): success={r.success}, "
      f"position error {r.position_error:.1e} m")

# --- 3. A batch: 1,000 targets solved in the compiled loop on every core -------------------
Q_true = panda.random_q(1000, seed=7)
targets = panda.fk(Q_true)                           # (1000, 4, 4)
panda.ik(targets[:2], seed=0)                        # warm-up (kernel loading)
t0 = time.perf_counter()
batch = panda.ik(targets, seed=0)                    # arrays: q (1000, 7), success (1000,)
dt = time.perf_counter() - t0
pos = np.linalg.norm(panda.fk(batch.q)[:, :3, 3] - targets[:, :3, 3], axis=1)
print(f"\nPanda batch of {len(batch)}: {batch.success.mean():.1%} solved in {dt * 1e3:.0f} ms "
      f"({dt / len(batch) * 1e6:.0f} µs per target), median {np.median(batch.iterations):.0f} "
      f"iterations, max position error {pos.max():.1e} m")
print("  same answer as a single solve:", np.allclose(batch[5].q, panda.ik(targets[5], seed=0).q))

# --- 4. Closed form: every solution (section 4.1) -------------------------------------------
# The class is recognised from the joint axes, not from the robot's name.
for robot in (sk.models.puma560(), sk.models.ur5()):
    q_true = robot.random_q(seed=11)
    T = robot.fk(q_true)
    sols = robot.ik_all(T)                           # (k, 6), every solution inside the limits
    worst = max(pose_error(robot, q, T)[0] for q in sols)
    d = sols - q_true
    d = (d + np.pi) % (2 * np.pi) - np.pi            # compare angles modulo 2π
    found = np.abs(d).max(axis=1).min() < 1e-6
    print(f"\n{robot.name} ({classify(robot)}): {len(sols)} closed-form solutions, "
          f"worst FK position error {worst:.1e} m, contains the generating q: {found}")
    for q in sols[:3]:
        print("   ", np.round(q, 4))
    if len(sols) > 3:
        print(f"    ... and {len(sols) - 3} more")
two = sk.models.two_link(1.0, 0.6)
print("two-link arm, both elbow solutions of (1.2, 0.4):\n", np.round(two.ik_all([1.2, 0.4]), 6))

# --- 5. An unreachable target: a result with success=False, not an exception ---------------
ur5 = sk.models.ur5()
far = np.eye(4)
far[:3, 3] = [2.0, 0.0, 0.5]                         # the UR5 reaches about 0.95 m
r = ur5.ik(far, seed=0)
print(f"\nUR5, target 2 m away: success={r.success}, restarts={r.restarts}, "
      f"best position error {r.position_error:.3f} m")
print("  reason:", r.reason)
print("  closed form:", ur5.ik_all(far).shape, "(no solution: an empty array)")
assert not r.success and np.isfinite(r.q).all()
