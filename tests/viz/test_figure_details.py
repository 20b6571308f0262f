"""Figure details of the chapter report: start pose, obstacle labels, legends, colour bars."""

from __future__ import annotations

import io
import math

import matplotlib.pyplot as plt
import numpy as np
from PIL import Image

from serialkin.model.geometry import Cylinder
from serialkin.tracking.scenario import planar_arm
from serialkin.viz import (
    AnimationOptions,
    animate_trajectory,
    plot_joint_trajectories,
    plot_motion,
)
from serialkin.viz.trajectory import joint_index_ticks


def test_joint_index_ticks_are_integers_from_1_to_n():
    """Colour-bar ticks are integers, start at 1, end at n and increase."""
    for n in (2, 7, 10, 11, 20, 24, 50, 73, 150):
        t = joint_index_ticks(n)
        assert t[0] == 1 and t[-1] == n and t == sorted(set(t))
        assert all(isinstance(v, int) for v in t) and len(t) <= 12


def test_twenty_joint_colour_bar_has_integer_ticks():
    """With 20 joints the colour bar's ticks are 1, 5, 10, 15, 20."""
    q = np.zeros((5, 20))
    ax = plot_joint_trajectories(q)
    bar = ax.figure.axes[-1]
    assert [float(v) for v in bar.get_yticks()] == [1.0, 5.0, 10.0, 15.0, 20.0]


def test_motion_shows_start_pose_labels_and_legend_outside():
    """plot_motion(q0=..., labels=True): start pose drawn, names written, legend off the axes."""
    robot = planar_arm(4, 0.1)
    Q = np.linspace([0.2, 0.3, 0.2, 0.1], [0.8, 0.5, 0.4, 0.3], 10)
    obs = [Cylinder(0.03, math.inf, center=[0.1, 0.25, 0.0], influence=0.02, name="A")]
    ax = plot_motion(robot, Q, path_points=np.zeros((3, 2)) + 0.1, q0=np.zeros(4),
                     obstacles=obs, influence=True, labels=True)
    start = [ln for ln in ax.get_lines() if ln.get_gid() == "serialkin-start"]
    assert len(start) == 1
    np.testing.assert_allclose(start[0].get_xydata()[-1], [0.4, 0.0], atol=1e-12)
    assert [t.get_text() for t in ax.texts] == ["A"]
    assert any(p.get_gid() == "serialkin-obstacle-influence" for p in ax.patches)
    fig = ax.figure
    fig.canvas.draw()
    leg = ax.get_legend().get_window_extent()
    box = ax.get_window_extent()
    assert leg.x0 >= box.x1  # right of the axes: it covers no data
    plt.close(fig)


def test_blitted_gif_frames_follow_the_motion():
    """Each GIF frame shows the arm of its configuration: frames differ, first ≠ last."""
    robot = planar_arm(3, 0.1)
    Q = np.linspace([0.0, 0.0, 0.0], [1.5, 0.5, 0.5], 6)
    data = animate_trajectory(robot, Q, AnimationOptions(max_frames=6, dpi=40, figsize=(3.0, 3.0)))
    im = Image.open(io.BytesIO(data))
    frames = []
    for k in range(im.n_frames):
        im.seek(k)
        frames.append(np.asarray(im.convert("RGB"), dtype=int))
    assert len(frames) == 6
    assert all(np.abs(a - b).sum() > 0 for a, b in zip(frames[:-1], frames[1:]))
