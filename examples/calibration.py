"""Kinematic calibration of a UR5 from noisy position measurements (a laser tracker).

1. The "real" robot: the data-sheet UR5 with a 50 mm tool bracket, every DH parameter,
   the base and the tool moved by up to 1 mm and 0.5° (``perturb``).
2. 60 measured tool positions with 0.05 mm noise at random configurations
   (``simulate_measurements``), written to a CSV and read back as a real file would be.
3. Identifiability: which of the error model's 36 parameters these measurements cannot
   see or cannot separate (they stay at their nominal values, never fitted to noise).
4. The fit (``calibrate``, trust-region least squares with the compiled identification
   Jacobian): residuals before and after, and a validation on 300 new configurations.
5. The calibrated robot exported as a URDF and read back (a DH robot file is refused for
   it: its nearly parallel axes would need common normals tens of metres away).

Writes ``calibration_residuals.png``, ``measurements.csv`` and ``ur5_calibrated.urdf``
into ``$SERIALKIN_EXAMPLE_OUT`` (default: a new temporary folder).
Run: ``python examples/calibration.py`` (a few seconds).
"""

import os
import tempfile
from pathlib import Path

import matplotlib

matplotlib.use("Agg")  # files only, no window

import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

import serialkin as sk  # noqa: E402
from serialkin.calibration import (  # noqa: E402
    calibrate,
    error_model,
    identifiability,
    perturb,
    read_measurements,
    save_robot,
    simulate_measurements,
    write_measurements,
)
from serialkin.errors import InputError  # noqa: E402

out = Path(os.environ.get("SERIALKIN_EXAMPLE_OUT") or tempfile.mkdtemp(prefix="serialkin_"))
out.mkdir(parents=True, exist_ok=True)

# --- 1. Nominal model, error model and the "real" robot -------------------------------------
nominal = sk.models.ur5().with_tool(sk.spatial.make_transform(p=[0.05, 0.02, 0.06]))
model = error_model(nominal)             # DH errors + Hayati's β on the parallel axes 2-4
print(f"error model of {nominal.name}: {len(model.parameters)} parameters "
      f"({model.kind}, Hayati's β on links {[i + 1 for i in model.hayati]})")
real = model.calibrated_robot(perturb(model, length=1e-3, angle=np.radians(0.5), seed=3))

# --- 2. Measurements, through a CSV file ----------------------------------------------------
sim = simulate_measurements(real, 60, noise_position=5e-5, seed=4)   # (60, 3) positions [m]
csv = write_measurements(out / "measurements.csv", sim)
meas = read_measurements(csv, nominal)
assert np.allclose(meas.positions, sim.positions) and np.allclose(meas.q, sim.q)

# --- 3. What these measurements can identify ------------------------------------------------
ident = identifiability(model, meas)
print(f"\n{int(ident.identifiable.sum())} of {len(model.parameters)} parameters identifiable "
      f"from {ident.kind} measurements, condition number {ident.condition_number:.1f}")
print("not identifiable (kept nominal):")
for reason in ident.reasons:
    print("  -", reason)
assert "d1 and base z cannot be separated from position measurements" in ident.reasons
assert not ident.identifiable[[model.names.index(f"tool r{a}") for a in "xyz"]].any()

# --- 4. Fit and validation ------------------------------------------------------------------
result = calibrate(model, meas)
print("\n" + result.summary().splitlines()[0])
assert result.success
before = np.linalg.norm(result.errors_before[:, :3], axis=1)
after = np.linalg.norm(result.errors_after[:, :3], axis=1)
# validation on configurations the fit never saw: the calibrated robot against the real one
Q = real.random_q(300, seed=5)
val_nominal = np.linalg.norm(nominal.fk(Q)[:, :3, 3] - real.fk(Q)[:, :3, 3], axis=1)
val_fit = np.linalg.norm(result.robot.fk(Q)[:, :3, 3] - real.fk(Q)[:, :3, 3], axis=1)
print(f"validation on 300 new configurations, tool position error: nominal "
      f"{np.sqrt(np.mean(val_nominal ** 2)) * 1e3:.2f} mm RMS, calibrated "
      f"{np.sqrt(np.mean(val_fit ** 2)) * 1e3:.3f} mm RMS (noise 0.05 mm per coordinate)")
assert np.sqrt(np.mean(val_fit ** 2)) < 0.2e-3 < np.sqrt(np.mean(val_nominal ** 2))

fig, axes = plt.subplots(1, 2, figsize=(10, 3.8))
idx = np.arange(len(before))
axes[0].bar(idx - 0.2, before * 1e3, 0.4, label="nominal model")
axes[0].bar(idx + 0.2, after * 1e3, 0.4, label="calibrated")
axes[0].set_yscale("log")
axes[0].set_xlabel("measurement")
axes[0].set_ylabel("position residual [mm]")
axes[0].set_title("the 60 fitted measurements", fontsize=10)
axes[0].legend(fontsize=8)
bins = np.logspace(-3, 1.3, 40)
axes[1].hist(val_nominal * 1e3, bins, alpha=0.7, label="nominal model")
axes[1].hist(val_fit * 1e3, bins, alpha=0.7, label="calibrated")
axes[1].set_xscale("log")
axes[1].set_xlabel("tool position error [mm]")
axes[1].set_ylabel("configurations")
axes[1].set_title("300 validation configurations", fontsize=10)
axes[1].legend(fontsize=8)
fig.suptitle("UR5 calibration from 60 noisy positions")
fig.tight_layout()
fig.savefig(out / "calibration_residuals.png", dpi=80)
plt.close(fig)

# --- 5. Export and read back ----------------------------------------------------------------
# The UR5's axes 2-4 are parallel: after calibration they are nearly so, and a DH table of
# the calibrated arm would place their common normals tens of metres away. A robot file
# (DH YAML) is refused for such an arm with the reason; the URDF keeps each joint's
# identified origin and axis, all of them bounded.
try:
    save_robot(result.robot, out / "ur5_calibrated.yaml")
except InputError as exc:
    print("robot file refused:", str(exc).split(": ", 2)[-1])
save_robot(result.robot, out / "ur5_calibrated.urdf")
from_urdf = sk.Robot.from_urdf(str(out / "ur5_calibrated.urdf"))
q = Q[:20]
diff = np.abs(from_urdf.fk(q) - result.robot.fk(q)).max()
print(f"URDF: FK of the file matches the calibrated robot to {diff:.1e}")
assert diff < 1e-6
print("\nwrote", ", ".join(sorted(p.name for p in out.iterdir())), "to", out)
