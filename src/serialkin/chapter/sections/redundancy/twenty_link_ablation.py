"""Section 5.3, the 20-link example: the ablation of eq 48's secondary tasks.

The constrained scenario (c) run again with each secondary task switched off in turn
(:func:`serialkin.tracking.analysis.ablation`): what goes wrong, measured (prose), the
table of the runs and the figure comparing each with the run with all tasks.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from serialkin.chapter._context import ReportContext
from serialkin.chapter.sections.redundancy._common import DEG, _mm, _phases, _shade, _where
from serialkin.tracking.analysis import AblationRun
from serialkin.tracking.scenario import Scenario


def ablation_cells(r: AblationRun) -> tuple[str, str, str, str, str, str]:
    """One row of the ablation table: label, degrees and millimetres as printed."""
    return (r.label, f"{r.max_joint_difference * DEG:.1f}", _mm(r.min_clearance),
            f"{r.limit_violation * DEG:.1f}", _mm(r.max_error), f"{r.unreached}")


def _ablation_prose(sc: Scenario, runs: list[AblationRun]) -> str:
    """What goes wrong in each ablated run, measured: where, which obstacle or joint, how much."""
    by = {r.label: r for r in runs}
    full = by["all tasks"].trajectory
    names = [o.name for o in sc.obstacles]
    out = []
    r = by["without the obstacle task"]
    tr = r.trajectory
    hit = tr.clearance.min(axis=1) < 0
    depth = tr.clearance.min(axis=0)
    hit_obs = [f"{n} (down to {c * 1e3:.1f} mm)" for n, c in zip(names, depth) if c < 0]
    out.append("without the obstacle task links enter "
               + (", ".join(hit_obs) if hit_obs else "no obstacle")
               + f" at {_where(sc, hit)}")
    r = by["without the joint-limit task"]
    lim = np.asarray(sc.robot.qlim, dtype=float)
    over = np.maximum(r.trajectory.q - lim[:, 1], lim[:, 0] - r.trajectory.q)
    out_mask = (over > 0).any(axis=1)
    joints = sorted({int(j) + 1 for j in np.flatnonzero((over > 0).any(axis=0))})
    out.append("without the joint-limit task joint" + ("s " if len(joints) > 1 else " ")
               + ", ".join(map(str, joints)) + f" leave{'' if len(joints) > 1 else 's'} its "
               f"range by up to {r.limit_violation * DEG:.1f}° at {_where(sc, out_mask)}"
               if joints else "without the joint-limit task no joint leaves its range")
    r = by["without the singularity task"]
    bad = r.trajectory.errors > sc.tolerance
    out.append(f"without the singularity task the tracking error exceeds the ±"
               f"{sc.tolerance * 1e3:g} mm tolerance at {_where(sc, bad)}, up to "
               f"{_mm(r.max_error)} mm (with all tasks at most "
               f"{_mm(float(full.errors[bad].max()) if bad.any() else full.max_error)} mm "
               "there)")
    return "; ".join(out)


def ablation_table(ctx: ReportContext, sc: Scenario, runs: list[AblationRun],
                   cap: str = "") -> str:
    """What each secondary task of eq 48 contributes: one run with each switched off.

    Args:
        ctx: the report context.
        sc: scenario (c), ``twenty_link_obstacles``.
        runs: :func:`serialkin.tracking.analysis.ablation` of (c).
        cap: a clause stating the step cap of the runs
            (:func:`~serialkin.chapter.sections.redundancy.step_cap.cap_note`), or "".
    """
    arows = [ablation_cells(r) for r in runs]
    R = float(sum(row.a for row in sc.robot.dh))
    beyond = float(np.linalg.norm(sc.path.points, axis=1).max()) - R
    return (
        "<h4>Ablation: each secondary task switched off in turn</h4>"
        "<p>The scenario of (c) run again with one weight of eq 48 set to zero (the obstacle "
        "weight, the eq 49 maximum, or the singularity damping, leaving λ_min = "
        f"{sc.solver.damping:g} m). Measured: " + _ablation_prose(sc, runs) + ". The farthest "
        f"path point lies {beyond * 1e3:.1f} mm beyond the reach R, so no configuration "
        "reaches it exactly." + (f" {cap}." if cap else "")
        + "</p><p><b>This ablation is circular by design.</b> The path and "
        "the obstacles were designed (the chapter gives neither) with one phase per "
        "secondary task, so that each task has something to do; that switching a task off "
        "then breaks its phase confirms the design and the implementation, not that the "
        "tasks are needed on an arbitrary path.</p>"
        + ctx.table(arows, ["run", "max |q − q_all| [°]", "min clearance [mm]",
                            "worst limit violation [°]", "max tracking error [mm]",
                            "points outside ±5 mm"])
    )


def ablation_figure(ctx: ReportContext, sc: Scenario, tc: Any, runs: list[AblationRun]) -> str:
    """Clearance, joint 1 and tracking error with all tasks and with one switched off."""
    import matplotlib.pyplot as plt

    full = runs[0]
    by = {r.label: r for r in runs}
    steps = np.arange(len(tc))
    lo, hi = np.degrees(np.asarray(sc.robot.qlim, dtype=float)[0])
    buffer_from = hi - sc.solver.limit_buffer * (hi - lo)
    tol = sc.tolerance * 1e3
    fig, axes = plt.subplots(1, 3, figsize=(12.5, 3.8))
    no_obs = by["without the obstacle task"].trajectory
    axes[0].plot(steps, full.trajectory.clearance.min(axis=1) * 1e3, label="all tasks")
    axes[0].plot(steps, no_obs.clearance.min(axis=1) * 1e3, label="without obstacle task")
    axes[0].axhline(0, color="k", lw=1)
    axes[0].set_ylabel("smallest clearance [mm]")
    axes[0].set_title("without the obstacle task: clearance down to "
                      f"{no_obs.clearance.min() * 1e3:.1f} mm", fontsize=10)
    no_lim = by["without the joint-limit task"].trajectory
    axes[1].plot(steps, full.trajectory.q[:, 0] * DEG, label="all tasks")
    axes[1].plot(steps, no_lim.q[:, 0] * DEG, label="without joint-limit task")
    axes[1].axhline(hi, color="k", lw=1)
    axes[1].axhline(buffer_from, color="k", lw=0.8, ls=":")
    axes[1].set_ylabel(f"q1 [°] (limit {hi:g}°, buffer from {buffer_from:g}°)")
    axes[1].set_title(f"without the limit task: q1 up to {no_lim.q[:, 0].max() * DEG:.1f}°",
                      fontsize=10)
    no_sing = by["without the singularity task"].trajectory
    axes[2].plot(steps, full.trajectory.errors * 1e3, label="all tasks")
    axes[2].plot(steps, no_sing.errors * 1e3, label="without singularity task")
    axes[2].axhline(tol, color="k", lw=1)
    axes[2].set_ylabel(f"tracking error [mm] (tolerance {tol:g} mm)")
    axes[2].set_title(f"without the singularity task: {int((no_sing.errors > sc.tolerance).sum())}"
                      f" points beyond {tol:g} mm", fontsize=10)
    phases = _phases(sc)
    for a in axes:
        _shade(a, phases)
        a.set_xlabel("path point")
        a.grid(True, alpha=0.3)
        a.legend(loc="upper center", bbox_to_anchor=(0.5, -0.2), fontsize="small", ncol=1)
    fig.subplots_adjust(wspace=0.35)
    return ctx.figure(fig, "twenty_link_ablation",
                      "What goes wrong when one task is switched off (shaded: the three "
                      "phases).")
