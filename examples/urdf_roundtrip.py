"""URDF in and out: export a robot, import it back, extract its DH table, read a real URDF.

1. Build a 5-joint arm (revolute and prismatic joints, base and tool) from a DH table,
   export it to URDF and import it back: the forward kinematics must not change.
2. Extract the standard and the modified DH table from the imported (general-form) robot
   and save it as a robot file.
3. If the ``example-robot-data`` package is installed (``pip install example-robot-data``),
   load the real Franka Panda and UR5 URDFs, extract their DH tables and solve the UR5's
   inverse kinematics in closed form on the URDF model. Skipped with a message otherwise.

Files go to ``$SERIALKIN_EXAMPLE_OUT`` (default: a new temporary folder).
Run: ``python examples/urdf_roundtrip.py`` (a few seconds).
"""

import importlib.metadata
import os
import tempfile
import time
from pathlib import Path

import numpy as np

import serialkin as sk
from serialkin.formats.robotfile import save_robot_file
from serialkin.model.dh_extract import extract_dh, to_dh_robot

out = Path(os.environ.get("SERIALKIN_EXAMPLE_OUT") or tempfile.mkdtemp(prefix="serialkin_"))
out.mkdir(parents=True, exist_ok=True)

# --- 1. DH robot -> URDF -> robot ------------------------------------------------------------
arm = sk.Robot.from_dh(
    [dict(a=0.0, alpha=np.pi / 2, d=0.30, theta=0.0, qlim=(-2.9, 2.9), name="waist"),
     dict(a=0.35, alpha=0.0, d=0.0, theta=0.2, qlim=(-1.8, 1.8), name="shoulder"),
     dict(a=0.0, alpha=np.pi / 2, d=0.0, theta=0.0, type="P", qlim=(0.0, 0.25),
          name="slide"),
     dict(a=0.0, alpha=-np.pi / 2, d=0.10, theta=0.0, qlim=(-3.0, 3.0), name="wrist_roll"),
     dict(a=0.05, alpha=0.0, d=0.0, theta=0.0, name="wrist_pitch")],   # no limits
    base=sk.spatial.transl(0.1, 0.0, 0.05),
    tool=sk.spatial.transl(0.0, 0.0, 0.08),
    name="demo_arm",
)
urdf_text = arm.to_urdf()                      # kinematics only: links, joints, limits
urdf_file = out / "demo_arm.urdf"
urdf_file.write_text(urdf_text)
back = sk.Robot.from_urdf(str(urdf_file))      # a path or the XML text itself

Q = arm.random_q(1000, seed=0)
print(f"wrote {urdf_file.name}: {len(urdf_text.splitlines())} lines")
print("imported:", back, "joints", back.joint_names, "types", "".join(back.joint_types))
print("  limits kept:", np.allclose(back.qlim, arm.qlim),
      "(unlimited 'wrist_pitch' became a continuous joint)")
print(f"  max |T_original − T_imported| over 1000 random q: "
      f"{np.abs(arm.fk(Q) - back.fk(Q)).max():.1e}")
print(f"  max |J_original − J_imported|: {np.abs(arm.jacobian(Q) - back.jacobian(Q)).max():.1e}")

# --- 2. DH extraction from the general (URDF) representation -------------------------------
print("\nDH tables extracted from the imported robot (base and tool absorb the rest):")
for convention in ("standard", "modified"):
    rows, base, tool = extract_dh(back, convention)
    print(f"  {convention}:  {'a [m]':>8}{'alpha':>9}{'d [m]':>9}{'theta':>9}  type")
    for r in rows:
        print(f"  {r.name:<12}{r.a:>8.4f}{r.alpha:>9.4f}{r.d:>9.4f}{r.theta:>9.4f}  {r.type}")
    dh_robot = to_dh_robot(back, convention)
    print(f"  -> max FK difference {np.abs(dh_robot.fk(Q) - back.fk(Q)).max():.1e}")
saved = save_robot_file(to_dh_robot(back, "standard"), out / "demo_arm_dh.yaml")
print("saved the standard DH table as a robot file:", Path(saved).name)


# --- 3. Real URDFs from example-robot-data (optional) --------------------------------------
def example_robot_data_urdf(relative):
    """Path of a URDF shipped by example-robot-data, or None when it is not installed."""
    try:
        dist = importlib.metadata.distribution("example-robot-data")
    except importlib.metadata.PackageNotFoundError:
        return None
    for f in dist.files or []:
        if str(f).replace("\\", "/").endswith("robots/" + relative):
            return Path(str(dist.locate_file(f)))
    return None


panda_urdf = example_robot_data_urdf("panda_description/urdf/panda.urdf")
ur5_urdf = example_robot_data_urdf("ur_description/urdf/ur5_robot.urdf")
if panda_urdf is None or ur5_urdf is None:
    print("\nexample-robot-data is not installed: skipping the real Panda and UR5 URDFs "
          "(pip install example-robot-data)")
else:
    t0 = time.perf_counter()
    panda = sk.Robot.from_urdf(str(panda_urdf), base_link="panda_link0", tip_link="panda_hand")
    ms = (time.perf_counter() - t0) * 1e3
    print(f"\nreal Panda URDF: {panda} imported in {ms:.1f} ms (meshes are never loaded)")
    print("  joint limits [rad]:", np.round(panda.qlim, 4).tolist())
    Qp = panda.random_q(500, seed=1)
    dh = to_dh_robot(panda, "modified")
    print(f"  extracted modified DH reproduces the URDF FK to "
          f"{np.abs(dh.fk(Qp) - panda.fk(Qp)).max():.1e}")
    r = panda.ik(panda.fk(Qp[0]), seed=0)          # numerical IK on the URDF model
    print(f"  ik on the URDF model: success={r.success}, "
          f"position error {r.position_error:.1e} m")

    ur5 = sk.Robot.from_urdf(str(ur5_urdf), tip_link="tool0")
    q = ur5.random_q(seed=2)
    sols = ur5.ik_all(ur5.fk(q))                   # class recognised from the joint axes
    errs = [np.abs(ur5.fk(s) - ur5.fk(q)).max() for s in sols]
    print(f"real UR5 URDF: {len(sols)} closed-form solutions, worst FK error {max(errs):.1e}")
