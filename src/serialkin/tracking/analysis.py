"""Analyses of tracked scenarios: which secondary task matters, and eq 48 against the QP.

The chapter's report (section 5.3) shows these for its 20-link example; they are library
functions so that any scenario can be analysed the same way:

* :func:`ablation` — the scenario run with each secondary task of eq 48 switched off in
  turn (:data:`ABLATION`), with the outcome of each run (:class:`AblationRun`);
* :func:`task_activity` — each secondary task's weight or activity at every path point;
* :func:`limit_violation` — how far a joint trajectory leaves the joint limits;
* :func:`qp_resolver` and :func:`compare_row` — the same scenario solved by the
  differential-IK quadratic program (:mod:`serialkin.diffik`), and one summary row per
  resolver (:class:`ResolverRun`).
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np

from serialkin.redundancy import joint_limit_weights
from serialkin.redundancy.multitask import smoothstep

if TYPE_CHECKING:
    from serialkin.tracking.scenario import Scenario

__all__ = ["ABLATION", "AblationRun", "ResolverRun", "ablation", "compare_row",
           "limit_violation", "qp_resolver", "task_activity"]

#: Each secondary task of eq 48 and the solver setting that switches it off.
ABLATION: tuple[tuple[str, dict[str, float]], ...] = (
    ("all tasks", {}),
    ("without the obstacle task", {"obstacle_weight": 0.0}),
    ("without the joint-limit task", {"joint_limit_weight": 0.0}),
    ("without the singularity task", {"singularity_damping": 0.0}),
)



def limit_violation(robot: Any, q: np.ndarray) -> float:
    """Largest excursion of any joint beyond its limits over all rows of q [rad]; 0 inside."""
    lim = np.asarray(robot.qlim, dtype=float)
    with np.errstate(invalid="ignore"):
        over = np.maximum(q - lim[:, 1], lim[:, 0] - q)
    over = np.where(np.isnan(over), -np.inf, over)
    return float(max(over.max(), 0.0))


@dataclass(frozen=True)
class AblationRun:
    """One run of the ablation: the scenario with some secondary tasks of eq 48 switched off.

    Attributes:
        label: e.g. "without the joint-limit task".
        scenario: the scenario run (its resolver with the task's weight set to 0).
        trajectory: the tracked trajectory.
        max_joint_difference: largest |q − q_full| over steps and joints [rad].
        min_clearance: smallest link-obstacle clearance over the path [m] (< 0: collision).
        limit_violation: largest excursion beyond a joint limit [rad] (0: none).
        max_error: largest tracking error [m].
        unreached: path points missed by more than the tolerance.
    """

    label: str
    scenario: Any
    trajectory: Any
    max_joint_difference: float
    min_clearance: float
    limit_violation: float
    max_error: float
    unreached: int


def ablation(scenario: Scenario, full: Any = None) -> list[AblationRun]:
    """Run the scenario with all tasks and with each secondary task of eq 48 switched off.

    Args:
        scenario: a scenario whose solver is a ``MultiTaskResolver``.
        full: the trajectory of the unchanged scenario when already computed.

    Returns:
        One :class:`AblationRun` per entry of :data:`ABLATION`, the full run first.
    """
    out: list[AblationRun] = []
    ref = full
    for label, change in ABLATION:
        if not change and ref is not None:
            s, tr = scenario, ref
        else:
            s = dataclasses.replace(scenario, solver=scenario.solver.with_options(**change))
            tr = s.run()
        ref = tr if ref is None else ref
        out.append(AblationRun(
            label=label, scenario=s, trajectory=tr,
            max_joint_difference=float(np.abs(tr.q - ref.q).max()),
            min_clearance=tr.min_clearance, limit_violation=limit_violation(s.robot, tr.q),
            max_error=tr.max_error, unreached=int((~tr.reached).sum())))
    return out


def task_activity(scenario: Scenario, trajectory: Any) -> dict[str, np.ndarray]:
    """Weight or activity of each secondary task of eq 48 at every path point, (p,) each.

    * ``obstacle``: the largest obstacle weight ``W_c · σ((d_infl − c)/d_infl)``.
    * ``limit``: the largest eq 49 weight ``W_Li`` over the joints; ``limit_joint`` its joint
      (1-based, 0 when no weight).
    * ``manipulability``: w = √det(JJᵀ) of the task rows (eq 43).
    * ``singularity``: the added damping ``λ_s = λ_s,max (1 − w/w₀)`` when w < w₀ [m].
    """
    res = scenario.solver
    tr = trajectory
    infl = np.array([o.influence for o in scenario.obstacles], dtype=float)
    if tr.clearance.size:
        s = (infl[None, :] - tr.clearance) / np.where(infl > 0, infl, 1.0)[None, :]
        obst = (res.obstacle_weight * smoothstep(s)).max(axis=1)
    else:
        obst = np.zeros(len(tr))
    lim = np.asarray(scenario.robot.qlim, dtype=float)
    WL = np.array([joint_limit_weights(q, lim, buffer=res.limit_buffer,
                                       max_weight=res.joint_limit_weight) for q in tr.q])
    w = np.asarray(scenario.robot.manipulability(tr.q, res.task), dtype=float)
    w0 = res.manipulability_threshold
    sing = (res.singularity_damping * np.clip(1.0 - w / w0, 0.0, 1.0) if w0 > 0
            else np.zeros(len(tr)))
    return {"obstacle": obst, "limit": WL.max(axis=1),
            "limit_joint": np.where(WL.max(axis=1) > 0, WL.argmax(axis=1) + 1, 0),
            "manipulability": w, "singularity": sing}



@dataclass(frozen=True)
class ResolverRun:
    """One tracked run summarised for comparing resolvers on one scenario.

    Attributes:
        label: the run's name.
        trajectory: the tracked :class:`~serialkin.tracking.trajectory.Trajectory`.
        seconds: wall-clock time of the whole path [s] (None when not measured).
        max_error: largest tracking error [m].
        unreached: path points outside the tolerance.
        min_clearance: smallest link-obstacle clearance over the path [m] (< 0: collision).
        worst_margin: smallest distance of any joint to its nearer limit [rad] (< 0: out).
        per_point: ``seconds`` per path point [s] (None when not measured).
    """

    label: str
    trajectory: Any
    seconds: float | None
    max_error: float
    unreached: int
    min_clearance: float
    worst_margin: float
    per_point: float | None


def compare_row(label: str, trajectory: Any, seconds: float | None = None) -> ResolverRun:
    """The :class:`ResolverRun` of ``trajectory`` (timed ``seconds`` for the whole path)."""
    tr = trajectory
    return ResolverRun(label, tr, seconds, float(tr.max_error), int((~tr.reached).sum()),
                       float(tr.min_clearance), float(tr.min_limit_margin),
                       None if seconds is None else seconds / max(len(tr), 1))


def qp_resolver(scenario: Scenario):
    """The QP settings of the side-by-side run (a :class:`~serialkin.diffik.QPResolver`).

    The scenario's task and obstacles, safety distance 2 mm, damper gain 0.5, joint jumps
    between path points bounded by 0.2 rad.
    """
    from serialkin.diffik.resolver import QPResolver

    return QPResolver(task=scenario.path.task, obstacles=scenario.obstacles, safety=0.002,
                      collision_gain=0.5, max_joint_step=0.2)


