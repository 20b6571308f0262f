"""Section 5.3, the 20-link example: the step cap of eq 48's iterations and what it decides.

:class:`~serialkin.redundancy.multitask.MultiTaskResolver` caps each iteration's joint
step at ‖q̇‖ ≤ ``max_step`` (0.2 rad by default; the chapter has no cap). On the
constrained scenario (c) that cap decides the outcome: with a larger one the arm with
every task on takes another branch and collides. :func:`step_cap_study` runs (c) again
with the cap doubled and with no effective cap (100 rad), and (b) with no effective cap,
in the same build; the texts below state the cap and those outcomes where Figures 11-12,
the ablation and the QP comparison are shown (docs/chapter-report.md: limits and caps
that change an outcome are stated where the outcome is shown).
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass
from typing import Any

import numpy as np

from serialkin.chapter._context import ReportContext
from serialkin.chapter.sections.redundancy._common import DEG, _where
from serialkin.tracking.scenario import Scenario

#: The cap with no effect on these paths [rad] (a step never comes near it).
NO_CAP = 100.0


@dataclass(frozen=True)
class CapRun:
    """Scenario (c) run with another step cap.

    Attributes:
        cap: the cap ``max_step`` of the run [rad].
        trajectory: the tracked trajectory.
        min_clearance: smallest link-obstacle clearance [m] (< 0: collision).
        iterations: iterations over the whole path.
        depth: {obstacle name: smallest clearance [m]} of the obstacles entered.
        hit: (p,) True at the path points where a link is inside an obstacle.
        max_joint_difference: largest |q − q_shown| over steps and joints [rad].
    """

    cap: float
    trajectory: Any
    min_clearance: float
    iterations: int
    depth: dict[str, float]
    hit: np.ndarray
    max_joint_difference: float


@dataclass(frozen=True)
class StepCap:
    """The step cap of the runs shown and the runs with larger caps.

    Attributes:
        cap: ``max_step`` of the scenarios shown [rad].
        shown: the trajectory of (c) shown (cap ``cap``).
        runs: (c) with the cap doubled, then with :data:`NO_CAP`.
        free_difference: largest |q − q_shown| of (b) run with :data:`NO_CAP` [rad].
    """

    cap: float
    shown: Any
    runs: list[CapRun]
    free_difference: float

    @property
    def doubled(self) -> CapRun:
        """(c) with the cap doubled."""
        return self.runs[0]


def _with_cap(scenario: Scenario, cap: float) -> Scenario:
    return dataclasses.replace(scenario, solver=scenario.solver.with_options(max_step=cap))


def step_cap_study(sb: Scenario, sc: Scenario, tb: Any, tc: Any) -> StepCap:
    """Run (c) with the cap doubled and with no effective cap, (b) with no effective cap.

    Args:
        sb: scenario (b), ``twenty_link_free``.
        sc: scenario (c), ``twenty_link_obstacles``.
        tb: the trajectory of (b) shown.
        tc: the trajectory of (c) shown.
    """
    cap = float(sc.solver.max_step)
    names = [o.name for o in sc.obstacles]
    runs = []
    for other in (2 * cap, NO_CAP):
        tr = _with_cap(sc, other).run()
        per_obstacle = tr.clearance.min(axis=0)
        runs.append(CapRun(
            cap=other, trajectory=tr, min_clearance=tr.min_clearance,
            iterations=int(tr.iterations.sum()),
            depth={n: float(c) for n, c in zip(names, per_obstacle) if c < 0},
            hit=tr.clearance.min(axis=1) < 0,
            max_joint_difference=float(np.abs(tr.q - tc.q).max())))
    free = _with_cap(sb, NO_CAP).run()
    return StepCap(cap=cap, shown=tc, runs=runs,
                   free_difference=float(np.abs(free.q - tb.q).max()))


def _clearance(value: float) -> str:
    """A clearance [m] as printed in millimetres, one decimal, Unicode minus."""
    return f"{value * 1e3:.1f}".replace("-", "−")


def _outcome(sc: Scenario, run: CapRun) -> str:
    """What (c) does with the cap of ``run``, e.g. "collides: links enter A (…) … ."."""
    if not run.depth:
        return (f"stays clear (minimum clearance {_clearance(run.min_clearance)} mm, "
                f"{run.iterations} iterations)")
    each = [f"{n} (down to {_clearance(d)} mm)" for n, d in run.depth.items()]
    entered = ", ".join(each[:-1]) + " and " + each[-1] if len(each) > 1 else each[0]
    return (f"collides: links enter {entered} at {_where(sc, run.hit)}, in "
            f"{run.iterations} iterations")


def cap_paragraph(ctx: ReportContext, sc: Scenario, study: StepCap) -> str:
    """The step cap, stated where Figures 11-12 are shown, with its Reproduce box."""
    doubled, uncapped = study.runs
    tc = study.shown
    free = ("its joint trajectory is the same" if study.free_difference == 0.0 else
            f"its joint trajectory differs by up to {study.free_difference * DEG:.2g}°")
    shown = [f"{study.cap:g}", _clearance(tc.min_clearance), str(int(tc.iterations.sum()))]
    expect = shown + [v for r in study.runs
                      for v in (f"{r.cap:g}", _clearance(r.min_clearance), str(r.iterations))]
    return (
        f"<p><b>Step cap.</b> Each eq 48 iteration's joint step is capped at ‖q̇‖ ≤ "
        f"{study.cap:g} rad (<code>MultiTaskResolver.max_step</code>, the resolver's "
        "default; the chapter has no cap), in (b) and (c) alike. In (c) the cap decides the "
        f"outcome. Run again with the cap at {doubled.cap:g} rad, the arm with every task on "
        f"takes another branch (joint angles up to {doubled.max_joint_difference * DEG:.0f}° "
        f"from the run shown) and {_outcome(sc, doubled)}; without an effective cap "
        f"({uncapped.cap:g} rad) it {_outcome(sc, uncapped)}. The run shown keeps "
        f"{_clearance(tc.min_clearance)} mm of clearance in {int(tc.iterations.sum())} "
        f"iterations. In (b) the cap never binds: with {uncapped.cap:g} rad {free}. "
        f"Figures 11 and 12, the ablation and the QP comparison below are all run with "
        f"{study.cap:g} rad.</p>"
        + ctx.reproduce(
            "import dataclasses\n"
            "from serialkin.tracking import load_scenario\n"
            "sc = load_scenario('twenty_link_obstacles')\n"
            f"for cap in ({study.cap:g}, {doubled.cap:g}, {uncapped.cap:g}):\n"
            "    tr = dataclasses.replace(sc, solver=sc.solver.with_options(max_step=cap)).run()\n"
            "    print(f'max_step {cap:g} rad: min clearance {tr.min_clearance * 1e3:.1f} mm, '\n"
            "          f'{int(tr.iterations.sum())} iterations')",
            expect=expect))


def cap_note(study: StepCap) -> str:
    """A clause "with a step cap of … rad per eq 48 iteration …", what a doubled cap does.

    Args:
        study: :func:`step_cap_study` of the same build.
    """
    doubled = study.doubled
    head = (f"with a step cap of {study.cap:g} rad per eq 48 iteration (see the step cap "
            "above)")
    if not doubled.depth:
        return f"{head}; with {doubled.cap:g} rad the run with all tasks stays clear too"
    return (f"{head}, which keeps the run with all tasks clear: with {doubled.cap:g} rad that "
            f"run itself collides (minimum clearance {_clearance(doubled.min_clearance)} mm, "
            f"{doubled.iterations} iterations instead of {int(study.shown.iterations.sum())})")
