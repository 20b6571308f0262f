"""Path tracking (chapter section 5.3): paths, the tracker, trajectories and scenarios.

* :class:`~serialkin.tracking.path.Path` — points, poses or a sampled parametric curve.
* :func:`~serialkin.tracking.tracker.track` — follow a path with DLS, the multi-task
  resolver or any IK method; returns a :class:`~serialkin.tracking.trajectory.Trajectory`.
* :func:`~serialkin.tracking.scenario.load_scenario` — validated YAML/JSON scenarios; the
  chapter's examples ship as ``six_link_circle``, ``twenty_link_free``,
  ``twenty_link_obstacles``.
"""

from serialkin.tracking.path import Path
from serialkin.tracking.scenario import (
    Scenario,
    ScenarioError,
    list_scenarios,
    load_scenario,
    planar_arm,
    scenario_from_dict,
)
from serialkin.tracking.tracker import track
from serialkin.tracking.trajectory import JointJump, PathFailure, Trajectory

__all__ = [
    "Path",
    "JointJump",
    "PathFailure",
    "Scenario",
    "ScenarioError",
    "Trajectory",
    "list_scenarios",
    "load_scenario",
    "planar_arm",
    "scenario_from_dict",
    "track",
]
