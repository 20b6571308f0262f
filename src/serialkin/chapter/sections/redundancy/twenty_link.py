"""Section 5.3: the 20-link example (Figures 11-12), task activity and the ablation of eq 48.

The ablation's prose, table and figure are in
:mod:`serialkin.chapter.sections.redundancy.twenty_link_ablation`; this module assembles
the part.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from serialkin.chapter._context import (
    ReportContext,
    Section,
    Timing,
    format_number,
    format_ratio,
)
from serialkin.chapter.sections.redundancy._common import (
    DEG,
    _gif,
    _mm,
    _phases,
    _shade,
    _where,
)
from serialkin.chapter.sections.redundancy.step_cap import (
    StepCap,
    cap_note,
    cap_paragraph,
)
from serialkin.chapter.sections.redundancy.twenty_link_ablation import (
    ablation_cells,
    ablation_figure,
    ablation_table,
)
from serialkin.tracking.analysis import (
    AblationRun,
    task_activity,
)
from serialkin.tracking.scenario import Scenario


def _q0_text(q0: np.ndarray) -> str:
    """q0 in degrees: "(75°, −2°, …, −2°)" when the joints after the first are all equal."""
    deg = [format_number(v, "{:.3g}").replace("-", "−") + "°" for v in np.degrees(q0)]
    if len(deg) > 3 and len(set(deg[1:])) == 1:
        return f"({deg[0]}, {deg[1]}, …, {deg[-1]})"
    return "(" + ", ".join(deg) + ")"


def _design_text(ctx: ReportContext, sb: Scenario, sc: Scenario, tb: Any, tc: Any,
                 act: dict[str, np.ndarray]) -> str:
    """The designed path, obstacles and weights of cases (b) and (c), in prose.

    Args:
        ctx: the report context.
        sb: scenario (b), ``twenty_link_free``.
        sc: scenario (c), ``twenty_link_obstacles``.
        tb: the trajectory of (b).
        tc: the trajectory of (c).
        act: :func:`serialkin.tracking.analysis.task_activity` of (c).
    """
    res = sc.solver
    robot = sc.robot
    L = float(robot.dh[0].a)
    R = float(sum(row.a for row in robot.dh))
    P = sc.path.points[:, :2]
    gaps = np.linalg.norm(np.diff(P, axis=0), axis=1) * 1e3
    radius = np.linalg.norm(P, axis=1)
    wp = np.asarray(sc.data["path"]["waypoints"], dtype=float)
    step = float(sc.data["path"]["step"])
    phases = _phases(sc)
    (a1, b1, _), (a2, b2, _), _ = phases
    far = int(np.argmax(radius[a1:b1 + 1])) + a1
    beyond = (radius.max() - R) * 1e3
    ring = np.linalg.norm(wp[2:10], axis=1) / R  # the boundary waypoints of phase 2
    ang = np.degrees(np.arctan2(wp[[2, 9], 1], wp[[2, 9], 0]))
    lim = np.degrees(np.asarray(robot.qlim, dtype=float)[0])
    buffer_from = lim[1] - res.limit_buffer * (lim[1] - lim[0])
    q1_c = float(np.degrees(tc.q[a2:b2 + 1, 0]).max())
    q1_b = float(np.degrees(tb.q[a2:b2 + 1, 0]).max())
    w_far = float(act["manipulability"][far])
    names = [o.name for o in sc.obstacles]
    lims = sorted({f"±{hi:g}°" if lo == -hi else f"[{lo:g}°, {hi:g}°]"
                   for lo, hi in np.degrees(np.asarray(robot.qlim, dtype=float))})
    return (
        f"<p>{robot.n} links of L = {L * 1e3:g} mm (reach "
        + ctx.imath(rf"R = {robot.n}L = {R:.4g}\ \mathrm{{m}}")
        + "). The chapter gives neither the path, nor q0, nor the obstacles (ERRATA); our "
        "design has one phase per secondary task of eq 48, so that each of them acts "
        f"somewhere: from q0 = {_q0_text(np.asarray(sc.q0, dtype=float))} (1) straight out to "
        f"{radius[far] / R:.3g}R, {beyond:.1f} mm beyond the reach: the arm stretches into "
        f"the singular configuration (w of eq 43 down to {w_far:.2g} at path point {far} "
        f"in (c)); (2) along the boundary at {np.median(ring):.3g}R from {ang[0]:.0f}° to "
        f"{ang[1]:.0f}°: the nearly straight arm points where joint 1 points, so joint 1 "
        f"would pass its {lim[1]:+g}° limit (the free case (b) turns it to {q1_b:.1f}° "
        f"there); in (c) the eq 49 weight holds it at {q1_c:.1f}° at most, inside the "
        f"buffer that starts at {buffer_from:g}°, and the next joints bend instead; (3) back "
        f"over the top and along a wave between {len(names)} obstacles "
        f"{names[0]}-{names[-1]}. The polyline is resampled at spacing ≤ {step * 1e3:g} mm; "
        f"the measured spacing of consecutive path points is {gaps.min():.2f}–"
        f"{gaps.max():.2f} mm (each straight piece is divided evenly, so pieces whose length "
        f"is not a multiple of {step * 1e3:g} mm get shorter steps; {len(sc.path)} points). "
        "Both cases use eq 48 with "
        + ctx.imath(r"\mathbf{W} = \mathbf{I}") + "; (b) adds only a constant damping "
        + ctx.imath(r"\mathbf{W}_s = \lambda^2\mathbf{I}") + f", λ = {sb.solver.damping:g} m; "
        f"(c) has the joint limits {', '.join(lims)} (eq 49, "
        + ctx.imath(r"W_{L,\max} = " + f"{res.joint_limit_weight:g}")
        + f", buffer {res.limit_buffer:.0%} of the range), the obstacle task (weight up to "
        + ctx.imath(r"W_{c,\max} = " + f"{res.obstacle_weight:g}") + " at contact, "
        "distances of influence "
        + ", ".join(f"{o.name} {o.influence * 1e3:.0f} mm" for o in sc.obstacles)
        + ") and the singularity task "
        + ctx.imath(r"\mathbf{W}_s = (\lambda_{\min}^2 + \lambda_s^2)\,\mathbf{I}")
        + " with " + ctx.imath(r"\lambda_{\min} = " + f"{res.damping:g}" + r"\ \mathrm{m}")
        + " and " + ctx.imath(r"\lambda_s = " + f"{res.singularity_damping:g}"
                              + r"\,(1 - w/w_0)")
        + " when " + ctx.imath(r"w < w_0 = " + f"{res.manipulability_threshold:g}")
        + " (w of eq 43), in the chapter's faithful mode "
        + ctx.imath(r"\mathbf{x}_c = \mathbf{x}_L = \mathbf{0}")
        + f"; at most {res.max_iter} iterations per point.</p>"
    )


def _results_table(ctx: ReportContext, sb: Scenario, sc: Scenario, tb: Any, tc: Any) -> str:
    """Points reached, errors, clearance per obstacle, joint range and iterations of (b), (c)."""
    from serialkin.redundancy import clearances

    names = [o.name for o in sc.obstacles]
    rows = []
    for label, s, tr in (("(b) free, Figure 11", sb, tb),
                         ("(c) obstacles, limits, singularities, Figure 12", sc, tc)):
        clear = (tr.clearance.min(axis=0) if tr.clearance.size else np.array(
            [clearances(sc.robot, q, sc.obstacles).min(axis=0) for q in tr.q]).min(axis=0))
        rows.append((label, f"{int(tr.reached.sum())}/{len(s.path)}", _mm(tr.max_error),
                     ", ".join(f"{n}: {c * 1e3:.1f}" for n, c in zip(names, clear)),
                     f"{np.abs(tr.q).max() * DEG:.1f}", f"{int(tr.iterations.sum())}"))
    return ctx.table(rows, ["case", "reached (±5 mm)", "max error [mm]",
                            "min clearance per obstacle [mm] (negative: collision)",
                            "max |q| [°]", "iterations"])


def _timings_text(ctx: ReportContext, sb: Scenario, sc: Scenario, tb: Any, tc: Any,
                  time_b: Timing, time_c: Timing, ratio: Timing | None = None) -> str:
    """Warm timings of (b) and (c), per path and per iteration, and the self-motion.

    Args:
        ctx: the report context.
        sb: scenario (b), ``twenty_link_free``.
        sc: scenario (c), ``twenty_link_obstacles``.
        tb: the trajectory of (b).
        tc: the trajectory of (c).
        time_b: the timing of the whole path of (b) [s].
        time_c: the timing of the whole path of (c) [s].
        ratio: their ratio (c)/(b) per round of runs in one process (None: the ratio of
            the medians).

    The per-iteration ratio is taken per round too: every run of a case makes the same
    iterations (the trajectories are deterministic), so each round's path ratio times
    it_b/it_c is that round's per-iteration ratio, and its median and percentiles scale
    by the same factor (added to ``ctx.timings``). Without ``ratio`` both ratios are ratios
    of medians, and say so.
    """
    it_b, it_c = int(tb.iterations.sum()), int(tc.iterations.sum())
    per_it_b = time_b.median / max(it_b, 1)
    per_it_c = time_c.median / max(it_c, 1)
    path_ratio = ratio.median if ratio is not None else time_c.median / time_b.median
    scale = max(it_b, 1) / max(it_c, 1)
    per_it = None if ratio is None else ratio.scaled(scale, f"{ratio.label} per iteration")
    if per_it is not None:
        ctx.timings.append(per_it)  # printed, so written to timings.json with its rounds
    per_it_ratio = per_it.median if per_it is not None else per_it_c / per_it_b
    of_medians = "" if ratio is not None else " (ratios of the medians)"
    how = ("each the median of the per-round ratios in the table" if ratio is not None
           else "ratios of the medians")
    dq = np.abs(tb.q - tc.q).max() * DEG
    dx = np.linalg.norm(tb.positions - tc.positions, axis=1).max()
    budget = sc.solver.max_iter
    full_c = tc.iterations >= budget
    full_b = int((tb.iterations >= sb.solver.max_iter).sum())
    blocks = ("an untimed warm-up run of each first, then the runs in blocks spread over "
              "this section's build, each block a few rounds that run every timed function "
              "of the section once" if time_b.blocks > 1 else
              "an untimed warm-up run of each first, then the two cases run in alternation")
    costs = "costs more" if path_ratio > 1 else "costs less here, unlike in the chapter"
    return (
        f"<p>Timings (whole path, compiled eq 48 loop; {blocks}):</p>"
        + ctx.table([
            ("(b) free", time_b.text, f"{per_it_b * 1e6:.3g} µs"),
            ("(c) constrained", time_c.text, f"{per_it_c * 1e6:.3g} µs"),
            ("ratio (c)/(b)" + of_medians,
             ratio.text if ratio is not None else f"{format_ratio(path_ratio)}×",
             per_it.text if per_it is not None else f"{format_ratio(per_it_ratio)}×"),
        ], ["case", "time for the whole path", "per iteration"])
        + f"<p>As the chapter says, the constrained case {costs}: "
        f"{format_ratio(path_ratio)}× the time of (b) for the whole path, "
        f"{format_ratio(per_it_ratio)}× per iteration ({how}; every "
        "iteration adds the link-obstacle distances and obstacle rows, the eq 49 weights and "
        f"the manipulability to the normal equations) and {it_c / max(it_b, 1):.2g}× the "
        f"iterations ({it_c} against {it_b}): in (c) {_where(sc, full_c)} use the whole "
        f"budget of {budget} iterations (points that cannot be reached exactly, beyond the "
        f"reach or held by a limit), in (b) {full_b} point{'' if full_b == 1 else 's'}.</p>"
        f"<p>Self-motion: the joint trajectories of (b) and (c) differ by up to "
        f"{dq:.1f}°, while their end-effector paths agree within {dx * 1e3:.3g} mm.</p>"
    )


def _motion_figures(ctx: ReportContext, sb: Scenario, sc: Scenario, tb: Any, tc: Any) -> str:
    """Figures 11 and 12 (the motions of (b) and (c)) and the animation of (c)."""
    import matplotlib.pyplot as plt

    from serialkin.viz import plot_motion, plot_obstacles

    parts = []
    for s, tr, fig_no, name in ((sb, tb, 11, "fig11_twenty_link_free"),
                                (sc, tc, 12, "fig12_twenty_link_obstacles")):
        free = s is sb
        fig, ax = plt.subplots(figsize=(7.2, 5.6))
        title = f"Figure {fig_no}: 20-link arm, " + (
            "free environment" if free else "four obstacles, limits ±100°")
        plot_motion(s.robot, tr.q, ax, path_points=s.path.points, every=8, q0=s.q0,
                    obstacles=None if free else s.obstacles, influence=not free,
                    labels=not free, title=title)
        if free:  # where the obstacles of (c) are: the free arm never needs to avoid them
            plot_obstacles(ax, sc.obstacles, alpha=0.12, labels=True)
        ax.set_xlabel("x [m]")
        ax.set_ylabel("y [m]")
        cap = f"eq 48 steps capped at ‖q̇‖ ≤ {s.solver.max_step:g} rad per iteration"
        caption = (f"Figure {fig_no} — " + (
            f"free motion (the obstacles of (c) drawn faintly); start pose q0 dashed; {cap} "
            "(a cap that never binds here)"
            if free else "motion between the obstacles A-D (influence zones dashed) with "
            f"joint limits ±100°; start pose q0 dashed; {cap}, which decides this outcome "
            "(see the step cap)"))
        parts.append(ctx.figure(fig, name, caption))
        if not free:  # one animation (GIFs are the costly part of the report)
            parts.append(_gif(ctx, s.robot, tr, name, title, obstacles=s.obstacles))
    return "".join(parts)


def _activity_figure(ctx: ReportContext, sc: Scenario, tc: Any) -> str:
    """The activity of each secondary task of eq 48 per path point of (c)."""
    import matplotlib.pyplot as plt

    res = sc.solver
    act = task_activity(sc, tc)
    steps = np.arange(len(tc))
    fig, axes = plt.subplots(3, 1, figsize=(9.0, 6.6), sharex=True)
    axes[0].plot(steps, act["obstacle"], color="tab:green")
    axes[0].set_ylabel("max W_c")
    axes[0].set_title("obstacle task: largest weight of an obstacle row (eq 48)", fontsize=10)
    axes[1].plot(steps, act["limit"], color="tab:orange")
    axes[1].set_ylabel("max W_Li")
    joints = sorted({int(v) for v in act["limit_joint"] if v > 0})
    axes[1].set_title("joint-limit task: largest eq 49 weight (joints "
                      + ", ".join(str(v) for v in joints) + ")", fontsize=10)
    axes[2].plot(steps, act["singularity"] * 1e3, color="tab:purple")
    axes[2].set_ylabel("λ_s [mm]")
    axes[2].set_title(f"singularity task: added damping (w < w₀ = {res.manipulability_threshold:g}"
                      ")", fontsize=10)
    axes[2].set_xlabel("path point")
    phases = _phases(sc)
    for i, a in enumerate(axes):
        _shade(a, phases, label=i == 0)
        a.grid(True, alpha=0.3)
    fig.subplots_adjust(hspace=0.45)
    n_act = {k: int((act[k] > 0).sum()) for k in ("obstacle", "limit", "singularity")}
    return ctx.figure(fig, "twenty_link_task_activity",
                      "Each secondary task of eq 48 along the path of (c): "
                      f"obstacle task active at {n_act['obstacle']}, joint-limit task at "
                      f"{n_act['limit']}, singularity task at {n_act['singularity']} of "
                      f"{len(tc)} path points (shaded: the three phases).")


def _joints_figure(ctx: ReportContext, sb: Scenario, sc: Scenario, tb: Any, tc: Any) -> str:
    """The joint angles of (b) and (c) side by side."""
    import matplotlib.pyplot as plt

    from serialkin.viz import plot_joint_trajectories

    fig, axes = plt.subplots(1, 2, figsize=(11.0, 3.8), sharey=True)
    plot_joint_trajectories(tb.q, ax=axes[0], robot=sb.robot, title="(b) joint angles")
    plot_joint_trajectories(tc.q, ax=axes[1], robot=sc.robot, title="(c) joint angles")
    lo, hi = np.degrees(np.asarray(sc.robot.qlim, dtype=float)[0])
    return ctx.figure(fig, "twenty_link_joints",
                      "Joint angles of the 20-link arm, free (b) and constrained (c); "
                      f"dashed: the limits [{lo:g}°, {hi:g}°] of (c).")


def twenty_link_figures(ctx: ReportContext, sb: Scenario, sc: Scenario, tb: Any, tc: Any,
                        runs: list[AblationRun]) -> dict[str, str]:
    """The figures of the 20-link part (no timing needed), HTML by name.

    Args:
        ctx: the report context (the figures are saved through it).
        sb: scenario (b), ``twenty_link_free``.
        sc: scenario (c), ``twenty_link_obstacles``.
        tb: the trajectory of (b).
        tc: the trajectory of (c).
        runs: :func:`serialkin.tracking.analysis.ablation` of (c).

    Returns:
        {"motion", "activity", "ablation", "joints"}: Figures 11-12 with the GIF, the task
        activity, the ablation and the joint angles.
    """
    return {"motion": _motion_figures(ctx, sb, sc, tb, tc),
            "activity": _activity_figure(ctx, sc, tc),
            "ablation": ablation_figure(ctx, sc, tc, runs),
            "joints": _joints_figure(ctx, sb, sc, tb, tc)}


def _twenty_link_part(ctx: ReportContext, sb: Scenario, sc: Scenario, tb: Any, tc: Any,
                      time_b: Timing, time_c: Timing, runs: list[AblationRun],
                      ratio: Timing | None, figures: dict[str, str], cap: StepCap) -> Section:
    """The 20-link example: free (b, Figure 11) and constrained (c, Figure 12), ablation.

    Args:
        ctx: the report context.
        sb: scenario (b), ``twenty_link_free``.
        sc: scenario (c), ``twenty_link_obstacles``.
        tb: the trajectory of (b).
        tc: the trajectory of (c).
        time_b: the timing of the whole path of (b) [s].
        time_c: the timing of the whole path of (c) [s].
        runs: :func:`serialkin.tracking.analysis.ablation` of (c).
        ratio: the ratio (c)/(b) per round of runs in one process (None: of the medians).
        figures: :func:`twenty_link_figures` of the same runs.
        cap: :func:`~serialkin.chapter.sections.redundancy.step_cap.step_cap_study` of the
            same runs.
    """
    from serialkin.tracking.analysis import task_activity

    track_numbers = [v for s, tr in ((sb, tb), (sc, tc))
                     for v in (str(int(tr.reached.sum())), str(len(s.path)), _mm(tr.max_error),
                               str(int(tr.iterations.sum())))] + [
        f"{tc.clearance.min() * 1e3:.1f}"]
    ablation_numbers = [v for r in runs for v in ablation_cells(r)[1:]]
    parts = [
        ctx.algorithm("Inverse kinematic model for 20-link manipulator (step 6 corrected)", [
            (0, "CYCLE WHILE 1"),
            (1, "Determine the next required x<sub>d</sub> from the planned path P"),
            (1, "CYCLE WHILE 2"),
            (2, "Compute the Jacobian J (damped least squares)"),
            (2, "Determine the end-effector position x for the current q"),
            (2, "Compute " + ctx.imath(r"\dot{\mathbf{q}}") + " by eq 48 (corrected: "
                + ctx.imath(r"\mathbf{J}^{T}") + " where the chapter prints "
                + ctx.imath(r"\mathbf{J}^{-1}") + ")"),
            (2, ctx.imath(r"\mathbf{q} = \mathbf{q}_{previous} + \dot{\mathbf{q}}\,dt")
                + f" (serialkin caps ‖q̇‖ at {cap.cap:g} rad, see the step cap below)"),
            (2, ctx.imath(r"\mathbf{q}_{previous} = \mathbf{q}")),
            (2, f"IF x<sub>d</sub> = x (here: within {sc.solver.tol * 1e3:g} mm, or "
                f"{sc.solver.max_iter} iterations spent) THEN end CYCLE WHILE 2, ELSE "
                "continue it"),
            (1, "END CYCLE WHILE 2"),
            (0, "END CYCLE WHILE 1"),
        ]),
        _design_text(ctx, sb, sc, tb, tc, task_activity(sc, tc)),
        _results_table(ctx, sb, sc, tb, tc),
        cap_paragraph(ctx, sc, cap),
        _timings_text(ctx, sb, sc, tb, tc, time_b, time_c, ratio),
        figures["motion"],
        figures["activity"],
        ablation_table(ctx, sc, runs, "All runs of the ablation are made " + cap_note(cap)),
        figures["ablation"],
        figures["joints"],
        ctx.reproduce("serialkin track twenty_link_free --out out/track\n"
                      "serialkin track twenty_link_obstacles --out out/track", shell=True,
                      expect=track_numbers),
        ctx.reproduce(
            "import numpy as np\n"
            "from serialkin.tracking import load_scenario\n"
            "from serialkin.tracking.analysis import ablation\n"
            "for r in ablation(load_scenario('twenty_link_obstacles')):\n"
            "    print(f'{r.label}: max |q - q_all| {np.degrees(r.max_joint_difference):.1f} deg,"
            " min clearance {r.min_clearance * 1e3:.3g} mm, worst limit violation '\n"
            "          f'{np.degrees(r.limit_violation):.1f} deg, max tracking error '\n"
            "          f'{r.max_error * 1e3:.3g} mm, {r.unreached} points outside the tolerance')",
            expect=ablation_numbers),
    ]
    return Section(title="5.3 Kinematically redundant manipulators",
                   part="Example: the 20-link arm (Figures 11 and 12)",
                   equations="eqs 47-56 at work, Figures 11-12, ablation of eq 48's tasks",
                   html="".join(parts))
