"""Figures, an animation and the interactive viewer for the chapter's 20-link example.

Runs the shipped scenario ``twenty_link_obstacles`` (a planar 20-link arm tracking a path
between four obstacles, eq 48), then writes into ``$SERIALKIN_EXAMPLE_OUT`` (default
``out/examples``):

- ``twenty_link_tracking.png`` — motion, joint angles (Figure 9 style), tracking error and
  clearance to every obstacle;
- ``twenty_link.gif`` — the motion as an animation (and ``.mp4`` when ffmpeg is present);
- ``twenty_link_viewer.html`` — the interactive 3D viewer (open it in a browser).
"""

import os
from pathlib import Path

import matplotlib

matplotlib.use("Agg")

from serialkin.tracking import load_scenario  # noqa: E402
from serialkin.viz import (  # noqa: E402
    AnimationOptions,
    Scene,
    ffmpeg_available,
    save_animation,
    tracking_figure,
    write_viewer,
)

out = Path(os.environ.get("SERIALKIN_EXAMPLE_OUT", "out/examples"))
out.mkdir(parents=True, exist_ok=True)

scenario = load_scenario("twenty_link_obstacles")
trajectory = scenario.run()
print(trajectory.summary())

fig = tracking_figure(trajectory, scenario.robot, obstacles=scenario.obstacles,
                      title="20-link arm between four obstacles")
fig.savefig(out / "twenty_link_tracking.png", dpi=90)

path_xy = trajectory.targets[:, :2, 3]
animation = AnimationOptions(max_frames=40, dpi=60)
save_animation(scenario.robot, trajectory.q, out / "twenty_link.gif", animation,
               path_points=path_xy, obstacles=scenario.obstacles)
if ffmpeg_available():
    save_animation(scenario.robot, trajectory.q, out / "twenty_link.mp4", animation,
                   path_points=path_xy, obstacles=scenario.obstacles)

scene = Scene(scenario.robot, trajectory=trajectory.q, path_points=path_xy,
              obstacles=scenario.obstacles, title="serialkin: 20-link arm between four obstacles")
page = write_viewer(scene, out / "twenty_link_viewer.html")
print("wrote", *sorted(p.name for p in out.iterdir()))
print("open", page.resolve().as_uri())
