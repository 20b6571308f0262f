"""Robots shared by the redundancy and tracking tests."""

from __future__ import annotations

import numpy as np

from serialkin import Robot
from serialkin.tracking.scenario import planar_arm


def six_link() -> Robot:
    """The chapter's 6-link planar arm, L = 0.1 m."""
    return planar_arm(6, 0.1)


def twenty_link() -> Robot:
    """The chapter's 20-link planar arm, L = 16.75 mm."""
    return planar_arm(20, 0.01675)


def spatial_rp() -> Robot:
    """A 7-joint spatial arm with one prismatic joint and a tool offset (general test case)."""
    rows = [
        {"a": 0.0, "alpha": np.pi / 2, "d": 0.3, "theta": 0.0},
        {"a": 0.25, "alpha": 0.0, "d": 0.0, "theta": 0.3},
        {"a": 0.0, "alpha": -np.pi / 2, "d": 0.05, "theta": 0.0, "type": "P",
         "qlim": (0.0, 0.4)},
        {"a": 0.05, "alpha": np.pi / 2, "d": 0.2, "theta": 0.0},
        {"a": 0.0, "alpha": -np.pi / 2, "d": 0.0, "theta": 0.1},
        {"a": 0.1, "alpha": np.pi / 2, "d": 0.1, "theta": 0.0},
        {"a": 0.0, "alpha": 0.0, "d": 0.08, "theta": 0.0},
    ]
    tool = np.eye(4)
    tool[:3, 3] = [0.02, 0.0, 0.05]
    return Robot.from_dh(rows, tool=tool, name="rp7")
