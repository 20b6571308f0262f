"""Section 5.3: eq 48 (soft, weighted tasks) and the differential-IK QP side by side."""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

import numpy as np

from serialkin.chapter._context import ReportContext, Section, Timing
from serialkin.chapter.sections.redundancy._common import (
    DEG,
    _mm,
    _phases,
    _shade,
)
from serialkin.chapter.sections.redundancy.step_cap import StepCap, cap_note
from serialkin.tracking.analysis import (
    ResolverRun,
    compare_row,
    qp_resolver,
)
from serialkin.tracking.scenario import Scenario

if TYPE_CHECKING:
    from serialkin.diffik.resolver import QPResolver


class SideBySide(list):
    """The rows of :func:`side_by_side` (a list of (ResolverRun, Timing)) and their ratio.

    Attributes:
        ratio: QP / eq 48 time of the whole path, per interleaved pair of runs, as a
            :class:`Timing` whose numbers are ratios.
    """

    ratio: Timing | None = None


def qp_scenario(scenario: Scenario) -> Scenario:
    """``scenario`` with the QP resolver of :func:`serialkin.tracking.analysis.qp_resolver`."""
    from dataclasses import replace

    return replace(scenario, solver=qp_resolver(scenario), options={})


def side_by_side_rows(weighted: Any, weighted_time: Timing, qp: Any, qp_time: Timing,
                      ratio: Timing | None) -> SideBySide:
    """The rows of the side-by-side table from runs timed elsewhere.

    Args:
        weighted: the eq 48 trajectory of the scenario.
        weighted_time: its timing (whole path) [s].
        qp: the QP trajectory of the same scenario.
        qp_time: its timing (whole path) [s].
        ratio: QP / eq 48 time per round of runs in one process, or None.

    Returns:
        :class:`SideBySide` with each run's :func:`compare_row` (per-point time from the
        median) and its timing.
    """
    rows = SideBySide([
        (compare_row("weighted tasks, eq 48 (soft)", weighted, weighted_time.median),
         weighted_time),
        (compare_row("QP with hard constraints", qp, qp_time.median), qp_time)])
    rows.ratio = ratio
    return rows


def side_by_side(ctx: ReportContext, scenario: Scenario, weighted: Any,
                 weighted_time: Timing | None = None, repeat: int = 7) -> SideBySide:
    """Eq 48 (the given run) and the QP on one scenario, timed in alternation in this process.

    Both whole-path runs are warmed up, then timed ``repeat`` times each in alternating
    order (:meth:`ReportContext.interleaved`), so their ratio is measured under the same
    machine state. ``weighted_time`` is accepted for callers of the earlier signature and
    not used (eq 48 is timed again, interleaved with the QP). The report itself times both
    on its section's :class:`~serialkin.chapter._context.TimingBench` and calls
    :func:`side_by_side_rows`.

    Returns:
        :class:`SideBySide`: rows of :func:`serialkin.tracking.analysis.compare_row`, each
        with its timing, and the ratio QP / eq 48.
    """
    del weighted_time
    qp = qp_scenario(scenario)
    tq = qp.run()
    tw_t, tq_t, ratio = ctx.interleaved(scenario.run, qp.run, warmup=1, repeat=repeat)
    return side_by_side_rows(weighted, tw_t, tq, tq_t, ratio)


def _qp_intro(ctx: ReportContext, res: QPResolver) -> str:
    """Soft weights against hard constraints: the QP solved in each iteration, in prose."""
    return (
        "<p>The weighted tasks of eq 48 make obstacles and joint limits <em>soft</em>: a "
        "large weight near contact, but nothing forbids a violation when the primary task "
        "pulls hard enough (the ablation above shows what happens when a weight is zero). "
        "The same scenario (c) solved by differential IK as a quadratic program "
        "(<code>serialkin.diffik</code>, docs/diffik.md): each iteration minimises "
        + ctx.imath(r"\tfrac12\|\mathbf{J}\Delta\mathbf{q} - \mathbf{e}\|^2 + "
                    r"\tfrac12 w_p\|\Delta\mathbf{q} - \Delta\mathbf{q}_0\|^2 + "
                    r"\tfrac12\mu\|\Delta\mathbf{q}\|^2")
        + " subject to hard inequalities: the joint limits "
        + ctx.imath(r"\mathbf{q}_m - \mathbf{q} \le \Delta\mathbf{q} \le "
                    r"\mathbf{q}_M - \mathbf{q}")
        + f", a step cap of {res.max_step:g} rad per iteration and {res.max_joint_step:g} rad "
        "between path points, and one linearised distance row per link-obstacle pair within "
        "the distance of influence (velocity damper, "
        + ctx.imath(r"\nabla d\,\Delta\mathbf{q} \ge -\xi\,\frac{d - d_s}{d_i - d_s}")
        + f", safety distance d_s = {res.safety * 1e3:g} mm, "
        + ctx.imath(r"\xi = " + f"{res.collision_gain:g}" + r"\,(d_i - d_s)")
        + "), solved by a dual active-set method (Goldfarb–Idnani) compiled into the "
        "tracking loop.</p>"
    )


def _qp_table(ctx: ReportContext, sc: Scenario,
              timed: list[tuple[ResolverRun, Timing]]) -> str:
    """Reach, errors, clearance, limit margin, iterations and time of both runs."""
    table = [(r.label, f"{len(r.trajectory) - r.unreached}/{len(sc.path)}", _mm(r.max_error),
              _mm(r.min_clearance), f"{r.worst_margin * DEG:.2f}",
              f"{int(r.trajectory.iterations.sum())}", f"{r.per_point * 1e3:.3g} ms",
              t.text) for r, t in timed]
    return ctx.table(table, ["run", f"reached (±{sc.tolerance * 1e3:g} mm)",
                             "max tracking error [mm]",
                             "min clearance [mm] (negative: collision)",
                             "worst joint-limit margin [°] (negative: outside)",
                             "iterations", "time per path point", "whole path"])


def _qp_discussion(w: ResolverRun, q: ResolverRun, safety: float, buffer: float,
                   ratio: Timing | None, cap: str = "") -> str:
    """What the two runs show: berth, limit margin, guarantees and cost, in prose.

    Args:
        w: the eq 48 run (timed: ``per_point`` set).
        q: the QP run (timed).
        safety: the QP's safety distance d_s [m].
        buffer: eq 49's buffer of the eq 48 run, a fraction of each joint's range.
        ratio: QP / eq 48 time of the whole path per round of runs in one process.
        cap: a clause stating eq 48's step cap and what a larger one does, or "".
    """
    per_point = q.trajectory.clearance.min(axis=1)
    below = int((per_point < safety).sum())
    if below:
        qp_berth = (f"the QP's linearised distance rows let links come to the safety "
                    f"distance d_s = {safety * 1e3:g} mm and, between linearisation points, "
                    f"below it: at {below} of {len(per_point)} path points, down to "
                    f"{_mm(q.min_clearance)} mm")
    else:
        qp_berth = (f"the QP lets links come to the safety distance d_s = "
                    f"{safety * 1e3:g} mm (measured minimum {_mm(q.min_clearance)} mm)")
    reach = ("both runs reach every point" if w.unreached == 0 and q.unreached == 0 else
             f"eq 48 misses {w.unreached} and the QP {q.unreached} points")
    hit = ("neither collides" if min(w.min_clearance, q.min_clearance) > 0 else
           "a link enters an obstacle in " + " and ".join(
               r.label for r in (w, q) if r.min_clearance <= 0))
    berth = "a wider" if w.min_clearance > q.min_clearance else "a narrower"
    qp_at_limit = int((q.trajectory.limit_margin.min(axis=1) < 1e-6).sum())
    faster = ("the QP is faster" if q.per_point < w.per_point else "eq 48 is faster")
    return (
        f"<p>Here {reach} and {hit}"
        + (f". {cap}: eq 48's clearance and iteration count here are those of the capped "
           "run" if cap else "")
        + f". Eq 48 keeps {berth} berth ({_mm(w.min_clearance)} mm "
        f"against the QP's {_mm(q.min_clearance)} mm: its obstacle weight starts acting at "
        f"the distance of influence and pushes away, while {qp_berth}) and stays "
        f"{w.worst_margin * DEG:.1f}° inside every limit, where its {buffer:.0%} buffer "
        f"raises the eq 49 weight; the QP's worst margin is {q.worst_margin * DEG:.2f}° "
        f"(a joint at its limit, within 1 µrad, at {qp_at_limit} of "
        f"{len(q.trajectory)} path points: margin 0° is allowed, beyond is impossible). "
        "The guarantee is the difference: the QP's limits hold by "
        "construction for any path and any weights, eq 48's only as long as its weights "
        f"win. Time per path point: {q.per_point * 1e3:.2g} ms for the QP against "
        f"{w.per_point * 1e3:.2g} ms for eq 48 ({faster} here)"
        + (f"; the ratio QP / eq 48 of the whole path is {ratio.text}, each round timing "
           "both in one process" if ratio is not None else "")
        + ". Both run their iterations in compiled "
        "loops, the QP with a dual active-set solver compiled with numba; the QP needs "
        f"{int(q.trajectory.iterations.sum())} iterations against eq 48's "
        f"{int(w.trajectory.iterations.sum())}.</p>"
    )


def _qp_margins_figure(ctx: ReportContext, sc: Scenario, res: QPResolver,
                       rows: list[ResolverRun]) -> str:
    """Clearance, joint-limit margin and tracking error per path point of both runs."""
    import matplotlib.pyplot as plt

    phases = _phases(sc)
    steps = np.arange(len(rows[0].trajectory))
    fig, axes = plt.subplots(1, 3, figsize=(12.5, 3.8))
    for r, color in zip(rows, ("tab:blue", "tab:red")):
        tr = r.trajectory
        axes[0].plot(steps, tr.clearance.min(axis=1) * 1e3, color=color, label=r.label)
        axes[1].plot(steps, tr.limit_margin.min(axis=1) * DEG, color=color, label=r.label)
        axes[2].plot(steps, tr.errors * 1e3, color=color, label=r.label)
    axes[0].axhline(res.safety * 1e3, color="k", lw=0.8, ls=":")
    axes[0].set_ylabel("smallest clearance [mm] (dotted: d_s)")
    axes[1].set_ylabel("worst joint-limit margin [°]")
    axes[2].axhline(sc.tolerance * 1e3, color="k", lw=1)
    axes[2].set_ylabel("tracking error [mm]")
    for a in axes:
        a.axhline(0, color="k", lw=1)
        _shade(a, phases)
        a.set_xlabel("path point")
        a.grid(True, alpha=0.3)
    axes[0].legend(loc="upper center", bbox_to_anchor=(0.5, -0.2), fontsize="small")
    fig.subplots_adjust(wspace=0.35)
    return ctx.figure(fig, "twenty_link_qp_vs_eq48",
                      "Eq 48 (soft, weighted) and the QP (hard constraints) on scenario "
                      "(c): clearance, limit margin and tracking error per path point.")


def _qp_motion_figure(ctx: ReportContext, sc: Scenario, q: ResolverRun) -> str:
    """The QP's motion of the 20-link arm between the obstacles."""
    import matplotlib.pyplot as plt

    from serialkin.viz import plot_motion

    fig, ax = plt.subplots(figsize=(7.2, 5.6))
    plot_motion(sc.robot, q.trajectory.q, ax, path_points=sc.path.points, every=8, q0=sc.q0,
                obstacles=sc.obstacles, influence=True, labels=True,
                title="20-link arm tracked by the QP (hard limits and obstacles)")
    ax.set_xlabel("x [m]")
    ax.set_ylabel("y [m]")
    return ctx.figure(fig, "twenty_link_qp_motion",
                      "The QP's motion between the obstacles A-D (compare Figure 12).")


def qp_figures(ctx: ReportContext, sc: Scenario, rows: list[ResolverRun]) -> str:
    """The figures of the side-by-side part (no timing needed), HTML.

    Args:
        ctx: the report context (the figures are saved through it).
        sc: scenario (c), ``twenty_link_obstacles``.
        rows: the eq 48 run and the QP run, in that order (``compare_row``; untimed will do).
    """
    res = qp_resolver(sc)
    return _qp_margins_figure(ctx, sc, res, rows) + _qp_motion_figure(ctx, sc, rows[1])


def _qp_part(ctx: ReportContext, sc: Scenario, timed: list[tuple[ResolverRun, Timing]],
             figures: str | None = None, cap: StepCap | None = None) -> Section:
    """Eq 48 (soft weights) against the differential-IK QP (hard constraints) on (c).

    Args:
        ctx: the report context.
        sc: scenario (c), ``twenty_link_obstacles``.
        timed: (eq 48 run, its timing) and (QP run, its timing), e.g. a
            :class:`SideBySide` (whose ``ratio`` is shown when set).
        figures: :func:`qp_figures` of the same runs (made here when None).
        cap: :func:`~serialkin.chapter.sections.redundancy.step_cap.step_cap_study` of
            the eq 48 run, whose step cap is then stated (nothing said when None).
    """
    ratio = getattr(timed, "ratio", None)
    res = qp_resolver(sc)
    rows = [r for r, _ in timed]
    w, q = rows
    parts = [
        _qp_intro(ctx, res),
        _qp_table(ctx, sc, timed),
        _qp_discussion(w, q, res.safety, sc.solver.limit_buffer, ratio,
                       "Eq 48 runs " + cap_note(cap) if cap is not None else ""),
        figures if figures is not None else qp_figures(ctx, sc, rows),
        ctx.reproduce(
            "import dataclasses\n"
            "from serialkin.tracking import load_scenario\n"
            "from serialkin.tracking.analysis import qp_resolver\n"
            "sc = load_scenario('twenty_link_obstacles')\n"
            "qp = dataclasses.replace(sc, solver=qp_resolver(sc), options={})\n"
            "print(qp.run().summary())",
            expect=[str(len(q.trajectory) - q.unreached), str(len(sc.path)),
                    _mm(q.max_error), str(int(q.trajectory.iterations.sum())),
                    _mm(q.min_clearance)]),
    ]
    return Section(title="5.3 Kinematically redundant manipulators",
                   part="Weighted tasks (eq 48) against a QP with hard constraints",
                   equations="eq 48 against the differential-IK QP",
                   html="".join(parts))
