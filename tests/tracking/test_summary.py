"""Tracking output that tells the truth: errors apart with their units, short summaries."""

from __future__ import annotations

import math

import numpy as np

from serialkin.spatial.lie import so3_exp
from serialkin.tracking.trajectory import PathFailure, Trajectory, format_duration


def _trajectory(task: str, p: int = 40, failed: int = 0) -> Trajectory:
    """A pose trajectory whose every point misses by 2 mm and 0.5 degrees, known exactly."""
    targets = np.tile(np.eye(4), (p, 1, 1))
    targets[:, :3, 3] = np.linspace([0.3, 0, 0.2], [0.5, 0.1, 0.2], p)
    poses = targets.copy()
    poses[:, :3, 3] += [0.002, 0.0, 0.0]
    poses[:, :3, :3] = so3_exp(np.array([0.0, 0.0, math.radians(0.5)]))
    fails = [PathFailure(i, 0.01, (0.0, 0.0, 0.0)) for i in range(failed)]
    reached = np.ones(p, dtype=bool)
    reached[:failed] = False
    return Trajectory(q=np.zeros((p, 6)), poses=poses, targets=targets, errors=np.zeros(p),
                      iterations=np.ones(p, dtype=int), reached=reached,
                      clearance=np.zeros((p, 0)), limit_margin=np.full((p, 6), np.inf),
                      times=np.full(p, 2e-4), task=task, tolerance=5e-3, failures=fails,
                      path_length=p, solver="test")


def test_position_and_orientation_errors_are_apart_in_their_units():
    """2 mm and 0.5° misses come out as 0.002 m and 0.5° (never their hypot in 'm')."""
    tr = _trajectory("pose")
    assert np.allclose(tr.position_errors, 0.002, atol=1e-15)
    assert np.allclose(np.degrees(tr.orientation_errors), 0.5, atol=1e-9)
    text = tr.summary()
    assert "position error: max 2 mm" in text and "orientation error: max 0.5 deg" in text
    assert _trajectory("position").orientation_errors is None
    assert "orientation" not in _trajectory("position").summary()


def test_summary_counts_reached_points_and_stays_short():
    """'reached K of N' counts successes; 24 failures give at most 15 lines unless verbose."""
    tr = _trajectory("pose", p=65, failed=24)
    lines = tr.summary().splitlines()
    assert lines[0].startswith("reached 41 of 65 path points")
    assert len(lines) <= 15 and "21 more failures" in lines[-1]
    assert len(tr.summary(verbose=True).splitlines()) == len(lines) - 1 + 21


def test_durations_read_with_a_unit_that_suits_them():
    """Microseconds, milliseconds, seconds and minutes, never '1.83e+05 ms'."""
    assert format_duration(2.5e-5) == "25 µs"
    assert format_duration(0.0123) == "12.3 ms"
    assert format_duration(7.8) == "7.8 s"
    assert format_duration(183.0) == "3 min 3 s"
    assert "time: 8 ms in all, 200 µs per point" in _trajectory("pose").summary()
