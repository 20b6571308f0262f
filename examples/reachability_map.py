"""Reachability map of a UR5 and where to put its base for a set of task poses.

1. A coarse reachability map (``serialkin.reach.reachability_map``): the UR5's space cut
   into 15 cm voxels; at every voxel centre 12 tool orientations (a super-Fibonacci set
   on SO(3)) are tried with the closed-form ``ik_all``. The *reachability index* of a
   voxel is the fraction of orientations reached. The map is written chunk by chunk
   into an output folder (and could be resumed after an interruption).
2. Base placement (inverse reachability): four pick poses on a table, tool pointing
   down; every base pose on a floor grid (10 cm, 8 headings) is tried, each task solved
   exactly. The best base reaches all four with the largest worst-case manipulability;
   the example checks it by solving the tasks again from that base.
3. The map as a point layer of the interactive viewer.

Writes ``ur5_reach_slice.png``, ``ur5_base_placement.png``, ``ur5_reach_viewer.html``
and the map folder ``ur5_map/`` into ``$SERIALKIN_EXAMPLE_OUT`` (default: a new
temporary folder). Run: ``python examples/reachability_map.py`` (a few seconds).
"""

import os
import tempfile
from pathlib import Path

import matplotlib

matplotlib.use("Agg")  # files only, no window

import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from serialkin import models  # noqa: E402
from serialkin.reach import base_placement, load_map, reachability_map  # noqa: E402
from serialkin.reach.plot import plot_base_placement, plot_map_slice, point_layer  # noqa: E402
from serialkin.spatial import make_transform  # noqa: E402
from serialkin.viz import Scene, write_viewer  # noqa: E402

out = Path(os.environ.get("SERIALKIN_EXAMPLE_OUT") or tempfile.mkdtemp(prefix="serialkin_"))
out.mkdir(parents=True, exist_ok=True)

# --- 1. The map ------------------------------------------------------------------------------
ur5 = models.get("ur5")
m = reachability_map(ur5, resolution=0.15, orientations=12, out=out / "ur5_map", progress=False)
n_vox = m.index.size
print(f"{ur5.name}: {m.index.shape} voxels of 15 cm, 12 orientations each "
      f"({n_vox * 12} closed-form IK calls in {sum(m.chunk_seconds):.2f} s)")
print(f"  reachable from at least one orientation: {int(m.reachable.sum())} voxels; "
      f"from all 12: {int(m.fully_reachable.sum())}")
print(f"  mean manipulability over reached orientations: "
      f"{np.nanmax(m.manipulability_mean):.3f} at best")
assert (m.index[m.fully_reachable] == 1).all() and (m.index[~m.reachable] == 0).all()
# every reached voxel centre is within the arm's reach (0.85 m from the shoulder, plus the wrist)
shoulder = ur5.fk_all(np.zeros(6))[1][:3, 3]
reach = np.linalg.norm(m.centres(m.reachable) - shoulder, axis=-1).max()
print(f"  farthest reached voxel centre: {reach:.2f} m from the shoulder")
assert reach < 1.05
again = load_map(out / "ur5_map" / "map.npz")         # the same map, read back
assert np.array_equal(again.index, m.index)

fig, axes = plt.subplots(1, 2, figsize=(10, 4.2))
plot_map_slice(m, "z", 0.3, ax=axes[0], title="UR5 reachability index, z = 0.3 m")
plot_map_slice(m, "y", 0.0, ax=axes[1], title="UR5 reachability index, y = 0")
fig.tight_layout()
fig.savefig(out / "ur5_reach_slice.png", dpi=80)
plt.close(fig)

# --- 2. Base placement -----------------------------------------------------------------------
down = np.diag([1.0, -1.0, -1.0])                    # tool z pointing down
tasks = np.array([make_transform(R=down, p=p) for p in
                  ([1.2, 0.3, 0.75], [1.4, 0.3, 0.75], [1.2, 0.6, 0.80], [1.4, 0.6, 0.85])])
bp = base_placement(ur5, tasks, resolution=0.1, yaws=8, floor_z=0.6)
summary = bp.summary()
print(f"\nbase placement for {len(tasks)} pick poses: {summary['feasible_candidates']} of "
      f"{summary['candidates']} candidate bases (floor cell × heading) reach all of them")
best = bp.best
print(f"  best base at x = {best[0, 3]:.2f} m, y = {best[1, 3]:.2f} m, "
      f"heading {np.degrees(np.arctan2(best[1, 0], best[0, 0])):.0f}°, worst-case "
      f"manipulability {summary['best']['dexterity']:.3f}")
placed = ur5.with_base(best)
for T in tasks:                                       # check: solve again from the best base
    sols = placed.ik_all(T)
    assert len(sols) > 0 and np.abs(placed.fk(sols) - T).max() < 1e-8
fig, ax = plt.subplots(figsize=(5.5, 4.5))
plot_base_placement(bp, ax=ax, tasks=tasks, title="UR5 bases reaching all four pick poses")
fig.tight_layout()
fig.savefig(out / "ur5_base_placement.png", dpi=80)
plt.close(fig)

# --- 3. The viewer's point layer ---------------------------------------------------------------
points, colours = point_layer(m, min_index=0.25)
write_viewer(Scene(ur5, points=points, point_colors=colours,
                   points_label="reachability index ≥ 0.25"), out / "ur5_reach_viewer.html")
print(f"\nviewer: {len(points)} voxel centres coloured by index (open ur5_reach_viewer.html)")
print("wrote", ", ".join(sorted(p.name for p in out.iterdir())), "to", out)
