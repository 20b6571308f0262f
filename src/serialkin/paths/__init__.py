"""Cartesian paths a robot can follow: pose paths, branch-consistent joint paths, timing.

* pose paths (:mod:`~serialkin.tracking.poses`, re-exported here: scenario files use
  them too) — straight lines, circular arcs and blended waypoint paths of tool poses,
  orientation by SLERP, sampled by a largest step in metres and radians;
* :mod:`~serialkin.paths.joint_path` — one configuration per sample chosen over all
  solutions by dynamic programming (no branch flips, no 2π jumps, a bounded joint step),
  or a clear refusal saying where and why;
* :mod:`~serialkin.paths.timing` — the time-optimal timing under joint velocity and
  acceleration limits (and a Cartesian speed limit) by toppra, and a jerk-limited timing
  by ruckig (both the ``paths`` extra).
"""

from serialkin.paths.joint_path import JointPath, joint_path
from serialkin.paths.timing import TimedPath, jerk_limited, time_optimal
from serialkin.tracking.poses import arc, line, slerp, waypoints

__all__ = ["JointPath", "TimedPath", "arc", "jerk_limited", "joint_path", "line", "slerp",
           "time_optimal", "waypoints"]
