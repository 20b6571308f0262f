"""Robot geometry: an MJCF arm written inline, capsule fitting of URDF meshes, self-clearance.

1. A three-joint arm written as MJCF (MuJoCo's format) in this script: its capsule geoms
   become the link geometry, ``fit_collision`` turns them into the collision model
   (a capsule is its own bounding capsule: gap 0), and ``self_clearance`` follows the
   smallest distance between non-adjacent links while the elbow folds. When the
   ``mujoco`` package is installed, its forward kinematics of the tool site is compared.
2. The UR5 of example-robot-data (when installed: ``pip install example-robot-data``,
   meshes read with ``pip install "serialkin[mesh]"``): its collision meshes fitted with
   bounding capsules (volume ratio and largest gap per link), the pairs that touch in
   every configuration found by sampling (``sampled_acm``), the share of random
   configurations in self-collision, and the interactive viewer with the meshes and the
   capsules.

Writes ``mjcf_arm_clearance.png`` and, with example-robot-data, ``ur5_capsules.png`` and
``ur5_meshes_viewer.html`` into ``$SERIALKIN_EXAMPLE_OUT`` (default: a new temporary
folder). Run: ``python examples/robot_geometry.py`` (a few seconds).
"""

import importlib.util
import os
import sys
import tempfile
from pathlib import Path

import matplotlib

matplotlib.use("Agg")  # files only, no window

import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

import serialkin as sk  # noqa: E402
from serialkin.collision import default_acm, sampled_acm, self_clearance  # noqa: E402
from serialkin.viz import Scene, ViewerOptions, write_viewer  # noqa: E402

out = Path(os.environ.get("SERIALKIN_EXAMPLE_OUT") or tempfile.mkdtemp(prefix="serialkin_"))
out.mkdir(parents=True, exist_ok=True)

# --- 1. An MJCF arm, written inline ----------------------------------------------------------
MJCF = """<mujoco model="folding_arm"><compiler angle="radian"/><worldbody>
  <body name="column"><geom type="capsule" fromto="0 0 0 0 0 0.4" size="0.06"/>
    <body name="upper" pos="0 0 0.4"><joint name="shoulder" axis="0 0 1" range="-3 3"/>
      <geom type="capsule" fromto="0 0 0 0.35 0 0" size="0.05"/>
      <body name="fore" pos="0.35 0 0"><joint name="elbow" axis="0 1 0" range="-2.8 2.8"/>
        <geom type="capsule" fromto="0 0 0 0.3 0 0" size="0.04"/>
        <body name="hand" pos="0.3 0 0"><joint name="wrist" axis="0 1 0" range="-2.5 2.5"/>
          <geom type="capsule" fromto="0 0 0 0.15 0 0" size="0.03"/>
          <site name="tcp" pos="0.15 0 0"/>
        </body>
      </body>
    </body>
  </body>
</worldbody></mujoco>"""
arm = sk.Robot.from_mjcf(MJCF, tool_site="tcp")
print(f"MJCF arm: joints {arm.joint_names}, tool at q = 0: {arm.fk(np.zeros(3))[:3, 3]}")
assert np.allclose(arm.fk(np.zeros(3))[:3, 3], [0.8, 0.0, 0.4])
arm, report = arm.fit_collision()                     # capsule geoms -> capsules, exactly
print(f"  {report.capsule_count} capsules, largest gap {report.max_gap * 1e3:.1f} mm")
assert report.max_gap < 1e-9

# fold the elbow and the wrist back: the hand comes down onto the upper arm
fold = np.linspace(0.0, 1.0, 60)[:, None] * np.array([0.0, 2.6, 2.4])   # (60, 3)
clear = self_clearance(arm, arm.collision, fold)
names = arm.collision.body_names
first_hit = np.flatnonzero(clear.distance < 0)
print(f"  folding: clearance {clear.distance[0] * 1e3:.0f} mm -> "
      f"{clear.distance.min() * 1e3:.0f} mm;"
      + (f" first contact at elbow {fold[first_hit[0], 1]:.2f} rad between "
         f"{names[clear.pair[first_hit[0], 0]]} and {names[clear.pair[first_hit[0], 1]]}"
         if len(first_hit) else " no contact"))
assert clear.distance[0] > 0 and len(first_hit) > 0

if importlib.util.find_spec("mujoco") is not None:   # an independent peer, when installed
    import mujoco

    m = mujoco.MjModel.from_xml_string(MJCF)
    d = mujoco.MjData(m)
    worst = 0.0
    for q in fold[::10]:
        d.qpos[:] = q
        mujoco.mj_kinematics(m, d)
        worst = max(worst, np.abs(d.site("tcp").xpos - arm.fk(q)[:3, 3]).max())
    print(f"  MuJoCo's forward kinematics of the tool site agrees to {worst:.1e} m")
    assert worst < 1e-10

fig, ax = plt.subplots(figsize=(6, 3.5))
ax.plot(fold[:, 1], clear.distance * 1e3)
ax.axhline(0.0, color="k", lw=0.8)
ax.set_xlabel("elbow angle [rad] (wrist folding with it)")
ax.set_ylabel("smallest self-clearance [mm]")
ax.set_title("MJCF arm folding onto itself (capsule model)", fontsize=10)
ax.grid(alpha=0.3)
fig.tight_layout()
fig.savefig(out / "mjcf_arm_clearance.png", dpi=80)
plt.close(fig)

# --- 2. UR5 meshes from example-robot-data ---------------------------------------------------
share = Path(sys.prefix, "lib", f"python{sys.version_info.major}.{sys.version_info.minor}",
             "site-packages", "cmeel.prefix", "share", "example-robot-data")
urdf = share / "robots/ur_description/urdf/ur5_robot.urdf"
if not urdf.is_file() or importlib.util.find_spec("trimesh") is None:
    print("\nexample-robot-data or trimesh not installed: the UR5 mesh part is skipped")
    sys.exit(0)

ur5 = sk.Robot.from_urdf(str(urdf), "base_link", "tool0", resolve_meshes=True,
                         package_map={"example-robot-data": share})
ur5, report = ur5.fit_collision()                     # one bounding capsule per mesh here
print(f"\nUR5 from {urdf.name}: {report.capsule_count} capsules fitted to its collision meshes")
print(report.table())
model = ur5.collision
Q = ur5.random_q(1000, seed=0)
naive = self_clearance(ur5, model, Q)                 # default matrix: adjacent links skipped
acm = sampled_acm(ur5, model, samples=500, seed=1)    # + pairs touching in every sample
checked = self_clearance(ur5, model, Q, acm)
newly = sorted(set(default_acm(model).checked_pairs()) - set(acm.checked_pairs()))
print("pairs in contact in every sample (now allowed):", ", ".join(f"{a}–{b}" for a, b in newly))
print(f"self-collision in 1000 random configurations: {np.mean(naive.distance < 0):.0%} with the "
      f"default matrix, {np.mean(checked.distance < 0):.0%} once the pairs that touch in every "
      f"sample are allowed")
assert np.mean(checked.distance < 0) < np.mean(naive.distance < 0)

fig, ax = plt.subplots(figsize=(7, 3.5))
ax.bar(range(len(report.fits)), [f.volume_ratio for f in report.fits])
ax.set_xticks(range(len(report.fits)), [f.link_name for f in report.fits], rotation=30,
              ha="right", fontsize=8)
ax.set_ylabel("capsule volume / mesh volume")
ax.set_title("UR5: bounding capsules of the collision meshes", fontsize=10)
fig.tight_layout()
fig.savefig(out / "ur5_capsules.png", dpi=80)
plt.close(fig)

write_viewer(Scene(ur5, q=[0.0, -1.2, 1.5, -0.3, 1.2, 0.0], acm=acm),
             out / "ur5_meshes_viewer.html", ViewerOptions(mesh_budget=20000, show_collision=True))
size = (out / "ur5_meshes_viewer.html").stat().st_size
print(f"viewer with meshes (at most 20,000 triangles) and capsules: {size / 1e6:.1f} MB")
print("\nwrote", ", ".join(sorted(p.name for p in out.iterdir())), "to", out)
