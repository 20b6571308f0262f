"""Report section 5.3 (first part): the numerical inverse-kinematics families (eqs 39-41).

Contents: the Jacobian control law (eqs 39-40) and one Newton-Raphson iteration (eq 41)
shown on the chapter's formulas; the numerical families of section 5.3 measured side by
side by :func:`serialkin.ik.compare.compare` on a planar 3-link arm, the Puma 560 and the
UR5 (:mod:`.comparison`: the tables, what they show, the trade-offs and the Reproduce
box); warm timings of the default solver (lm) and of BFGS and Powell on one target per
robot, with their ratios to lm taken per round (``ctx.bench``). The redundancy
resolution itself (eqs 42-56, the 6- and 20-link examples) follows in
:mod:`serialkin.chapter.sections.redundancy`.
"""

from __future__ import annotations

import html
from collections.abc import Callable, Sequence

import numpy as np

from serialkin import models
from serialkin.chapter._context import ReportContext, Section, TimingBench
from serialkin.chapter.sections.numerical.comparison import (
    CHAOTIC_ITERATIONS,
    COMPARE_TOL,
    N_PLANAR,
    N_SPATIAL,
    TRADE_OFFS,
    compare_box,
    compare_html,
    comparison_jobs,
    comparison_tables,
    measured_summary,
    reading_text,
)

__all__ = ["CHAOTIC_ITERATIONS", "COMPARE_TOL", "N_PLANAR", "N_SPATIAL", "TRADE_OFFS", "build",
           "comparison_jobs", "comparison_tables"]

#: Position error [m] below which the Newton demo's error is rounding, not convergence.
ROUNDING = 1e-13
#: The methods timed against lm on the section's bench (their ratios are in the prose).
AGAINST_LM = ("bfgs", "powell")


def _newton_demo(ctx: ReportContext) -> str:
    """Eq 41 on the UR5: position error after k Newton steps from a nearby start."""
    ur5 = models.ur5()
    q = np.array([0.4, -1.1, 1.3, -0.6, 0.9, 0.2])
    T = ur5.fk(q)
    q0 = q + 0.15
    rows = []
    for k in range(1, 7):
        res = ur5.ik(T, method="newton", q0=q0, max_iter=k, restarts=0, tol=1e-15)
        rows.append((k, res.position_error, res.orientation_error))
    # correct digits -log10(e) of the position error until it reaches rounding
    err = np.array([r[1] for r in rows])
    above = err > ROUNDING
    digits = -np.log10(err[above])
    growth = digits[1:] / digits[:-1]
    floor = int(np.argmin(above)) + 1 if not above.all() else None
    return (
        "<h3>Newton-Raphson (eq 41)</h3><p>For a scalar equation f(x) = 0 one step is</p>"
        + ctx.eq(r"x_1 = x_0 - \frac{f(x_0)}{f'(x_0)}", "41")
        + "<p>and for inverse kinematics, with the pose error e(q) between the target and "
        "f(q) and the Jacobian in place of f′, "
        + ctx.imath(r"\mathbf{q}_{k+1} = \mathbf{q}_k + \mathbf{J}^{\dagger}(\mathbf{q}_k)\,"
                    r"\mathbf{e}(\mathbf{q}_k)")
        + " (<code>method='newton'</code>). The UR5, target f(q) for q = (0.4, −1.1, 1.3, "
        "−0.6, 0.9, 0.2) rad, started at q + 0.15 rad in every joint, errors after k "
        "steps below. The correct digits of the position, "
        + ctx.imath(r"-\log_{10} e_k")
        + f" = {', '.join(f'{d:.1f}' for d in digits)} for k = 1 … {digits.size}, grow by "
        f"a factor {growth.min():.2f}–{growth.max():.2f} per step (2 is quadratic "
        "convergence)"
        + (f"; from step {floor} the error is rounding ({err[floor - 1]:.1e} m, below "
           f"{ROUNDING:g} m)" if floor is not None else "") + ".</p>"
        + ctx.table(rows, ["steps k", "position error [m]", "orientation error [rad]"],
                    fmt="{:.2e}")
    )


#: A solve timed on the section's bench: (robot name, target kind, method, solve).
Case = tuple[str, str, str, Callable[[], object]]


def _default_solver_cases(methods: Sequence[str] = ("lm",)) -> list[Case]:
    """The solves of ``methods`` on one target per robot (the default solver: 'lm')."""
    planar = models.planar(3, [1.0, 0.8, 0.5])
    cases = [(planar, planar.fk(planar.random_q(1, seed=42)[0])[:2, 3], "(x, y)")]
    for robot in (models.puma560(), models.ur5()):
        cases.append((robot, robot.fk(robot.random_q(1, seed=42)[0]), "6-D pose"))
    return [(robot.name, kind, method,
             lambda robot=robot, target=target, method=method: robot.ik(
                 target, method=method, seed=0))
            for robot, target, kind in cases for method in methods]


def _bench_name(case: Case) -> str:
    """The name of a case on the bench, e.g. "lm, UR5"."""
    return _name(case[2], case[0])


def _name(method: str, robot: str) -> str:
    """The bench name of ``method`` on ``robot`` (:func:`_bench_name`)."""
    return f"{method}, {robot}"


def _default_solver_timings(ctx: ReportContext, blocks: int = 7
                            ) -> list[tuple[str, str, str, str, str]]:
    """Warm median and spread of ``robot.ik(target)`` (method 'lm') on one target each.

    The three solves share one :class:`~serialkin.chapter._context.TimingBench`, timed in
    ``blocks`` blocks of three rounds taken back to back (the section's build takes its
    blocks between its other work instead).
    """
    bench = ctx.bench(rounds=3)
    cases = _default_solver_cases()
    for case in cases:
        bench.add(_bench_name(case), case[3])
    for _ in range(blocks):
        bench.block()
    return _solver_rows(bench, cases)


def _solver_rows(bench: TimingBench, cases: list[Case]
                 ) -> list[tuple[str, str, str, str, str]]:
    """The rows (robot, target, method, timing, ratio to lm's) of the bench's solves."""
    rows = []
    for case in cases:
        name, kind, method, _ = case
        ratio = ("" if method == "lm" else
                 bench.ratio(_bench_name(case), _bench_name((name, kind, "lm", case[3]))).text)
        rows.append((name, kind, method, bench.timing(_bench_name(case)).text, ratio))
    return rows


#: The opening of the numerical families' part (section 5.3).
_FAMILIES_INTRO = (
    "<h3>Numerical families (section 5.3), measured</h3>"
    "<p>Section 5.3 lists the numerical approaches: linearisation by the Jacobian "
    "(transpose, Moore-Penrose pseudoinverse eq 40, damped least squares / "
    "Levenberg-Marquardt eq 46 with the ERRATA's JJᵀ, selectively damped least squares "
    "by SVD), Newton methods (eq 41), minimisation (Powell, BFGS) and the heuristics CCD "
    "and FABRIK. serialkin implements each behind one interface "
    "(<code>robot.ik(target, method=...)</code>) with the same targets, tolerance, "
    "restarts from seeded random configurations and joint-limit handling, so "
    "<code>serialkin.ik.compare</code> can run them on the same targets from the same "
    f"starts. Success means FK of the answer within {COMPARE_TOL:g} m and "
    f"{COMPARE_TOL:g} rad of the target with q inside the joint limits. Times are wall "
    "times per solve on the machine that built this report (restarts included); "
    "targets are FK of seeded random configurations inside the limits.</p>")


def _timings_part(ctx: ReportContext, bench: TimingBench, cases: list[Case]) -> str:
    """The bench's timings: lm, BFGS and Powell on one target per robot, with ratios."""
    return (
        "<p>The comparison times are warm too: each method solves the first target once, "
        "untimed, before the timed solves; the median and mean are over the targets, each "
        "target solved once, one method after the other: single runs, which carry no "
        "spread of repeated runs and which a rebuild shifts. For repeated timings, the "
        f"default solver (lm) and the two optimisers {' and '.join(AGAINST_LM)} on one "
        f"target per robot, each solve timed {bench.timing(_bench_name(cases[0])).n} times "
        f"in {bench.blocks} blocks taken between the comparisons above; the ratio to lm is "
        "taken per round (both solves in the same round of one process):</p>"
        + ctx.table(_solver_rows(bench, cases),
                    ["robot", "target", "method", "time", "time / lm's time"]))


def build(ctx: ReportContext) -> Section:
    """Measure the numerical IK families of section 5.3 and return the section's first part.

    The timings of lm, BFGS and Powell on one target per robot share one
    :class:`~serialkin.chapter._context.TimingBench` whose seven blocks of three rounds are
    taken between the section's other work (the Newton demonstration and the three
    comparisons); the ratios BFGS / lm and Powell / lm are taken per round on it.
    """
    bench = ctx.bench(rounds=3)
    cases = _default_solver_cases(("lm", *AGAINST_LM))
    for case in cases:
        bench.add(_bench_name(case), case[3])
    bench.block()
    parts: list[str] = [
        "<p>A redundant arm has more joints n than task coordinates m; its inverse "
        "kinematics is solved numerically from the differential relation</p>",
        ctx.eq(r"\dot{\mathbf{x}} = \mathbf{J}(\mathbf{q})\,\dot{\mathbf{q}}", "39"),
        "<p>inverted with the Moore-Penrose pseudoinverse (minimum-norm joint velocity)</p>",
        ctx.eq(r"\dot{\mathbf{q}} = \mathbf{J}^{\dagger}(\mathbf{q})\,\dot{\mathbf{x}},"
               r"\qquad \mathbf{J}^{\dagger} = \mathbf{J}^T\left(\mathbf{J}\mathbf{J}^T"
               r"\right)^{-1}\ (m < n),\quad \mathbf{J}^{\dagger} = \left(\mathbf{J}^T"
               r"\mathbf{J}\right)^{-1}\mathbf{J}^T\ (m > n)", "40"),
        _newton_demo(ctx),
    ]
    bench.block()
    # --- section 5.3: the numerical families ------------------------------------------------
    parts.append(_FAMILIES_INTRO)
    tables = []
    for title, run in comparison_jobs():
        tables.append((title, run()))
        bench.block()
    for title, table in tables:
        parts.append(f"<h4>{html.escape(title)}</h4>" + compare_html(ctx, table))
    bench.block()
    bench.block()
    parts.append(_timings_part(ctx, bench, cases))
    robots = [c[0] for c in cases if c[2] == "lm"]
    ratios = {m: [bench.ratio(_name(m, r), _name("lm", r)) for r in robots] for m in AGAINST_LM}
    measured = measured_summary(tables)
    parts.append(
        "<h4>Trade-offs</h4><p>The first four columns are properties of the algorithms; the "
        "last is measured in the comparison tables above (range over the robots where the "
        "family ran: success rate, and the median time per solve over the targets, each "
        "solved once: single runs, not repeated timings).</p>" + ctx.table(
            [row + (measured.get(row[0], "not run"),) for row in TRADE_OFFS],
            ["family (methods)", "cost per iteration", "convergence", "near singularities",
             "joint limits", "measured here"]))
    parts.append(reading_text(tables, ratios))
    parts.append(compare_box(ctx, tables[1][1]))
    return Section(title="5.3 Kinematically redundant manipulators",
                   part="Numerical inverse kinematics, measured",
                   equations="eqs 39-41", html="".join(parts))
