"""Figures, animations and the interactive viewer.

- :mod:`serialkin.viz.plot` — a robot in a configuration (2D for planar arms, 3D
  otherwise), obstacles and target paths (matplotlib).
- :mod:`serialkin.viz.trajectory` — joint trajectories (the chapter's Figure 9), tracking
  error and obstacle clearance along a path.
- :mod:`serialkin.viz.animate` — a trajectory as a GIF (Pillow) or MP4 (ffmpeg), drawn as
  :class:`~serialkin.viz.animate.AnimationOptions` say.
- :mod:`serialkin.viz.viewer` — a self-contained HTML page with the robot in 3D (three.js,
  embedded), joint sliders and forward kinematics computed in the page.
- :mod:`serialkin.viz.scene` — what the page shows (:class:`~serialkin.viz.scene.Scene`)
  and how it draws the robot's body (:class:`~serialkin.viz.scene.ViewerOptions`).

The submodules import matplotlib lazily; ``import serialkin.viz`` itself is cheap.
"""

from __future__ import annotations

import importlib
from typing import Any

_EXPORTS = {
    "plot_robot": "plot",
    "plot_obstacles": "plot",
    "plot_path": "plot",
    "robot_points": "plot",
    "joint_positions": "plot",
    "as_obstacle": "plot",
    "plot_joint_trajectories": "trajectory",
    "plot_tracking_error": "trajectory",
    "plot_clearance": "trajectory",
    "plot_motion": "trajectory",
    "clearance_along": "trajectory",
    "tracking_figure": "trajectory",
    "AnimationOptions": "animate",
    "animate_trajectory": "animate",
    "save_animation": "animate",
    "ffmpeg_available": "animate",
    "Scene": "scene",
    "ViewerOptions": "scene",
    "viewer_html": "viewer",
    "viewer_data": "viewer",
    "write_viewer": "viewer",
}

__all__ = sorted(_EXPORTS)


def __getattr__(name: str) -> Any:
    """Import the public functions of the submodules on first use."""
    if name in _EXPORTS:
        module = importlib.import_module(f"serialkin.viz.{_EXPORTS[name]}")
        return getattr(module, name)
    raise AttributeError(f"module 'serialkin.viz' has no attribute {name!r}")
