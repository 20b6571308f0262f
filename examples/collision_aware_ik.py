"""Collision-aware inverse kinematics: a Panda reaching over a table between two obstacles.

The zoo's Panda carries a capsule model (``robot.collision``, 11 bodies fitted to its
meshes). The scene is a table (``HalfSpace``: the solid below z = −0.10 m), a ball
(``Sphere``) and a crate (``Box``). The targets are the tool poses of random
configurations that are themselves free of collision, so every target has at least one
collision-free solution.

1. Plain ``lm`` reaches every target, but some of its solutions go through the table,
   the obstacles or the robot itself: it knows nothing of them.
2. ``robot.ik(T, scene=..., self_collision=True, margin=...)`` counts a solution as a
   success only when it also keeps ``margin`` metres from every scene shape and between
   the robot's own bodies. Every success's clearance is recomputed here with
   ``scene_clearance`` and ``self_clearance`` (independently of the solver).
3. A figure of one target solved both ways: capsules, obstacles, table.

Writes ``panda_collision_ik.png`` into ``$SERIALKIN_EXAMPLE_OUT`` (default: a new
temporary folder). Run: ``python examples/collision_aware_ik.py`` (a few seconds).
"""

import os
import tempfile
from pathlib import Path

import matplotlib

matplotlib.use("Agg")  # files only, no window

import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from mpl_toolkits.mplot3d.art3d import Poly3DCollection  # noqa: E402

import serialkin as sk  # noqa: E402
from serialkin.collision import in_collision, scene_clearance, self_clearance  # noqa: E402
from serialkin.model.geometry import Box, Capsule, HalfSpace, Sphere  # noqa: E402
from serialkin.viz import plot_obstacles, plot_robot  # noqa: E402

out = Path(os.environ.get("SERIALKIN_EXAMPLE_OUT") or tempfile.mkdtemp(prefix="serialkin_"))
out.mkdir(parents=True, exist_ok=True)

panda = sk.models.panda()
model = panda.collision                               # capsules per body
scene = [HalfSpace([0, 0, 1], -0.10, name="table"),  # table top 10 cm below the base frame
         Sphere(0.10, center=[0.45, 0.25, 0.45], name="ball"),
         Box((0.12, 0.12, 0.12), center=[0.40, -0.35, 0.25], name="crate")]
print(f"{panda.name}: {len(model.body_names)} collision bodies; scene: "
      + ", ".join(s.name for s in scene))


def clearance(q):
    """Smallest signed distance [m] of configurations q (..., 7) to the scene and itself."""
    return np.minimum(scene_clearance(panda, model, q, scene).distance,
                      self_clearance(panda, model, q).distance)


# --- targets: tool poses of collision-free configurations ----------------------------------
Q = panda.random_q(600, seed=1)
free = ~in_collision(panda, model, Q, scene=scene)     # scene and self, default ACM
Q = Q[free][:200]
targets = panda.fk(Q)
print(f"{free.mean():.0%} of random configurations are collision-free; "
      f"{len(targets)} of their tool poses are the targets")

# --- 1. plain lm ---------------------------------------------------------------------------
plain = panda.ik(targets, seed=0)
d_plain = clearance(plain.q)
print(f"\n{'solver':<42}{'success':>9}{'colliding':>11}{'min clearance':>15}")
print(f"{'lm (no collision model)':<42}{plain.success.mean():>9.0%}"
      f"{(d_plain < 0).mean():>11.0%}{d_plain.min() * 1e3:>12.1f} mm")

# --- 2. collision-aware lm, two margins ----------------------------------------------------
results = {}
for margin in (0.0, 0.005):
    r = panda.ik(targets, scene=scene, self_collision=True, margin=margin, seed=0)
    d = clearance(r.q)
    ok = r.success
    # a success keeps the margin, recomputed here (the solver's own value agrees)
    assert np.all(d[ok] >= margin - 1e-9) and np.allclose(r.clearance[ok], d[ok], atol=1e-9)
    assert np.all(np.isfinite(r.q)) and np.all(panda.within_limits(r.q))
    label = f"lm, scene + self, margin {margin * 1e3:.0f} mm"
    print(f"{label:<42}{ok.mean():>9.0%}{(d[ok] < 0).mean():>11.0%}"
          f"{d[ok].min() * 1e3:>12.1f} mm   (over successes)")
    results[margin] = r
failed = np.flatnonzero(~results[0.005].success)
if len(failed):
    print("  a failure is a result with its best attempt, e.g.:",
          results[0.005][failed[0]].reason)

# --- 3. figure: one target, plain vs collision-aware (margin 5 mm) ---------------------
aware = results[0.005]
k = int(np.flatnonzero((d_plain < 0) & aware.success)[0])
q_plain, q_aware = plain.q[k], aware.q[k]
print(f"\ntarget {k}: plain lm clearance {d_plain[k] * 1e3:.1f} mm (colliding), "
      f"collision-aware {clearance(q_aware) * 1e3:.1f} mm; same tool pose: "
      f"{np.abs(panda.fk(q_plain) - panda.fk(q_aware)).max():.1e}")


def capsules(q):
    """The robot's capsules at q as world-frame Capsule objects (for plot_obstacles)."""
    frames = panda.fk_all(q)
    caps = []
    for s, f in enumerate(model.shape_frame):
        a = frames[f] @ np.append(model.a[s], 1.0)
        b = frames[f] @ np.append(model.b[s], 1.0)
        caps.append(Capsule(float(model.radius[s]), a=a[:3], b=b[:3]))
    return caps


def draw_box(ax, box):
    """Draw a Box's six faces."""
    corners = np.array([[x, y, z] for x in (-1, 1) for y in (-1, 1) for z in (-1, 1)])
    p = box.center + (corners * box.half_extents) @ box.rotation.T
    faces = [[0, 1, 3, 2], [4, 5, 7, 6], [0, 1, 5, 4], [2, 3, 7, 6], [0, 2, 6, 4], [1, 3, 7, 5]]
    ax.add_collection3d(Poly3DCollection([p[f] for f in faces], color="tab:brown", alpha=0.5))


fig = plt.figure(figsize=(11, 5))
for i, (q, title) in enumerate([(q_plain, "plain lm"), (q_aware, "scene=, self_collision=True")]):
    ax = fig.add_subplot(1, 2, i + 1, projection="3d")
    d = clearance(q)
    caps = capsules(q)
    plot_obstacles(ax, caps, color="tab:red" if d < 0 else "tab:green", alpha=0.25)
    plot_robot(panda, q, ax=ax, color="k", linewidth=1.5)
    plot_obstacles(ax, [scene[1]], color="tab:blue", alpha=0.4)
    draw_box(ax, scene[2])
    xx, yy = np.meshgrid([-0.6, 0.8], [-0.7, 0.7])
    ax.plot_surface(xx, yy, np.full_like(xx, -0.10), color="0.6", alpha=0.3)
    ax.scatter(*targets[k][:3, 3], color="red", s=30)
    ax.set_xlim(-0.6, 0.8), ax.set_ylim(-0.7, 0.7), ax.set_zlim(-0.2, 1.2)
    ax.set_title(f"{title}: clearance {d * 1e3:.0f} mm", fontsize=10)
fig.suptitle("Panda, one target (red dot): capsules red when colliding, green when free")
fig.tight_layout()
fig.savefig(out / "panda_collision_ik.png", dpi=80)
plt.close(fig)
print("\nwrote", ", ".join(sorted(p.name for p in out.iterdir())), "to", out)
