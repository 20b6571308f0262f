"""Report section 5.3 (first part): the numerical inverse-kinematics families (eqs 39-41).

Contents: the Jacobian control law (eqs 39-40) and one Newton-Raphson iteration (eq 41)
shown on the chapter's formulas; the numerical families of section 5.3 measured side by
side by :func:`serialkin.ik.compare.compare` on a planar 3-link arm, the Puma 560 and the
UR5 (every number in those tables is measured when the report is built), the default
solver's warm timing per robot (median and block spread, ``ctx.bench``), a table of the
trade-offs. The redundancy resolution itself (eqs 42-56, the 6- and 20-link examples) follows in
:mod:`serialkin.chapter.sections.redundancy`.
"""

from __future__ import annotations

import html
from collections.abc import Callable

import numpy as np

from serialkin import models
from serialkin.chapter._context import ReportContext, Section, TimingBench, format_number
from serialkin.ik.compare import COLUMNS, CompareTable, compare

#: Tolerance of the comparison (the accuracy bar of the IK issue) [m, rad].
COMPARE_TOL = 1e-6
#: Targets per robot in the comparison (kept small: BFGS/Powell are slow).
N_PLANAR, N_SPATIAL = 20, 10
#: Position error [m] below which the Newton demo's error is rounding, not convergence.
ROUNDING = 1e-13
#: Median iterations beyond which a method's row of the compare box is not checked.
CHAOTIC_ITERATIONS = 1000


def comparison_jobs() -> list[tuple[str, Callable[[], CompareTable]]]:
    """(title, run) of :func:`compare` on each robot of the section (seeded, reproducible)."""
    planar = models.planar(3, [1.0, 0.8, 0.5])
    jobs: list[tuple[str, Callable[[], CompareTable]]] = [(
        "Planar 3-link arm (L = 1.0, 0.8, 0.5 m, unlimited), (x, y) targets",
        lambda: compare(planar, planar.fk(planar.random_q(N_PLANAR, seed=42))[:, :2, 3],
                        tol=COMPARE_TOL, seed=0))]
    for robot in (models.puma560(), models.ur5()):
        jobs.append((f"{robot.name}, full 6-D pose targets",
                     lambda robot=robot: compare(robot, robot.fk(robot.random_q(
                         N_SPATIAL, seed=42)), tol=COMPARE_TOL, seed=0)))
    return jobs


def comparison_tables() -> list[tuple[str, CompareTable]]:
    """Run :func:`compare` on the three robots of the section (seeded, reproducible)."""
    return [(title, run()) for title, run in comparison_jobs()]


#: Trade-offs of the families (general properties; the measured columns come from the
#: tables above when the report is built).
TRADE_OFFS = (
    ("Jacobian transpose (transpose)", "one J, no solve", "linear, slow near the solution",
     "no inversion, so no blow-up; crawls", "projection"),
    ("Pseudoinverse / Newton / Gauss-Newton (pinv, newton, gauss_newton)",
     "J and an SVD / normal equations", "quadratic near a regular solution",
     "steps explode without a cut-off or damping", "projection"),
    ("Damped least squares / Levenberg-Marquardt (dls, lm, lm_*, sdls)",
     "J and one small solve", "fast; adaptive damping keeps it quadratic",
     "robust: damping bounds the step", "projection"),
    ("Minimisation (bfgs, powell)", "scipy iteration in Python: cost (+ gradient)",
     "superlinear (BFGS) / slow (Powell)", "unaffected (no inversion)", "bounds"),
    ("Cyclic coordinate descent (ccd)", "one J per sweep + O(n) closed forms",
     "linear; slow for full poses", "robust far from the target", "clamping"),
    ("FABRIK (fabrik)", "2 passes over the points + one FK", "linear",
     "robust; planar revolute chains only", "clamping in angle recovery"),
)


def _family_of(method: str) -> str:
    if method == "transpose":
        return TRADE_OFFS[0][0]
    if method in ("pinv", "newton", "gauss_newton"):
        return TRADE_OFFS[1][0]
    if method in ("bfgs", "powell"):
        return TRADE_OFFS[3][0]
    if method == "ccd":
        return TRADE_OFFS[4][0]
    if method == "fabrik":
        return TRADE_OFFS[5][0]
    return TRADE_OFFS[2][0]


def _measured_summary(tables: list[tuple[str, CompareTable]]) -> dict[str, str]:
    """Per family: measured success rate range and median time range over all tables."""
    acc: dict[str, list[tuple[float, float]]] = {}
    for _, table in tables:
        for row in table.rows:
            acc.setdefault(_family_of(row.method), []).append(
                (row.success_rate, 1e3 * row.median_time))
    out = {}
    for fam, vals in acc.items():
        rates = [v[0] for v in vals]
        times = [v[1] for v in vals]
        rate = (f"{100 * min(rates):.0f} %" if min(rates) == max(rates)
                else f"{100 * min(rates):.0f}-{100 * max(rates):.0f} %")
        time_ = (f"{min(times):.3g} ms" if len(times) == 1
                 else f"{min(times):.3g}-{max(times):.3g} ms")
        out[fam] = f"{rate}, {time_}"
    return out


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


def _compare_html(ctx: ReportContext, table: CompareTable) -> str:
    """A comparison table through ``ctx.table`` (aligned columns), skipped methods below."""
    caption = (f"<caption>IK methods on {html.escape(table.robot)}: {table.n_targets} "
               f"{html.escape(table.target_kind)} targets, tol {table.tol:g}</caption>")
    body = ctx.table([r.cells() for r in table.rows], list(COLUMNS), fmt="{:.3g}")
    out = body.replace("<table>", "<table>" + caption, 1)
    if table.skipped:
        items = "".join(f"<li><b>{html.escape(m)}</b>: {html.escape(r)}</li>"
                        for m, r in table.skipped)
        out += f'<ul class="skipped">{items}</ul>'
    return out


def _default_solver_cases() -> list[tuple[str, str, Callable[[], object]]]:
    """(robot name, target kind, solve) of the default solver on one target per robot."""
    planar = models.planar(3, [1.0, 0.8, 0.5])
    cases = [(planar, planar.fk(planar.random_q(1, seed=42)[0])[:2, 3], "(x, y)")]
    for robot in (models.puma560(), models.ur5()):
        cases.append((robot, robot.fk(robot.random_q(1, seed=42)[0]), "6-D pose"))
    return [(robot.name, kind, lambda robot=robot, target=target: robot.ik(target, seed=0))
            for robot, target, kind in cases]


def _default_solver_timings(ctx: ReportContext, blocks: int = 7
                            ) -> list[tuple[str, str, str, str]]:
    """Warm median and spread of ``robot.ik(target)`` (method 'lm') on one target each.

    The three solves share one :class:`~serialkin.chapter._context.TimingBench`, timed in
    ``blocks`` blocks of three rounds taken back to back (the section's build takes its
    blocks between its other work instead).
    """
    bench = ctx.bench(rounds=3)
    cases = _default_solver_cases()
    for name, _, solve in cases:
        bench.add(name, solve)
    for _ in range(blocks):
        bench.block()
    return _solver_rows(bench, cases)


def _solver_rows(bench: TimingBench, cases: list[tuple[str, str, Callable[[], object]]]
                 ) -> list[tuple[str, str, str, str]]:
    """The rows (robot, target, method, timing) of the default solver's timings."""
    return [(name, kind, "lm", bench.timing(name).text) for name, kind, _ in cases]


def _pct(rates: list[float]) -> str:
    """Success rates as "100 %" or "70–100 %"."""
    lo, hi = 100 * min(rates), 100 * max(rates)
    return f"{lo:.0f} %" if f"{lo:.0f}" == f"{hi:.0f}" else f"{lo:.0f}–{hi:.0f} %"


def _num(value: float, digits: int = 3) -> str:
    """A number with ``digits`` significant digits, from 100 up as a whole number ("4,900")."""
    return f"{value:,.0f}" if abs(value) >= 100 else f"{value:.{digits}g}"


def _span(values: list[float], digits: int = 3) -> str:
    """Values as "a" or "a–b" (:func:`_num`)."""
    lo, hi = _num(min(values), digits), _num(max(values), digits)
    return lo if lo == hi else f"{lo}–{hi}"


def _reading_text(tables: list[tuple[str, CompareTable]]) -> str:
    """What the comparison tables show, each statement computed from their rows."""
    rows = [{r.method: r for r in t.rows} for _, t in tables]

    def of(method: str, field: str, where: list[dict] | None = None) -> list[float]:
        return [float(getattr(r[method], field)) for r in (rows if where is None else where)
                if method in r]

    out = []
    if of("lm", "success_rate"):
        out.append(
            "the damped (Levenberg-Marquardt) family combines the Jacobian methods' "
            "quadratic convergence with bounded steps near singularities, which is why it "
            f"is the default (<code>method='lm'</code>): lm solved {_pct(of('lm', 'success_rate'))}"
            f" of the targets in a median {_span(of('lm', 'median_iterations'))} iterations "
            f"and {_span([1e3 * t for t in of('lm', 'median_time')])} ms per solve")
    jac = [m for r in rows for m, row in r.items()
           if row.family == "jacobian" and m != "transpose"]
    if of("transpose", "median_iterations") and jac:
        others = [float(r[m].median_iterations) for r in rows for m in set(jac) if m in r]
        out.append(
            "the Jacobian transpose converges linearly: a median "
            f"{_span(of('transpose', 'median_iterations'))} iterations per solve against "
            f"{_span(others)} for the other Jacobian methods, and it solved "
            f"{_pct(of('transpose', 'success_rate'))} of the targets")
    if of("bfgs", "success_rate") and of("powell", "success_rate"):
        lm_time = [r["lm"].median_time for r in rows if "lm" in r]
        ratio = {m: [r[m].median_time / r["lm"].median_time for r in rows
                     if m in r and "lm" in r] for m in ("bfgs", "powell")}
        rates = (_pct(of("bfgs", "success_rate")), _pct(of("powell", "success_rate")))
        out.append(
            "BFGS and Powell (scipy's optimisers, iterating in Python) solved "
            + (f"{rates[0]} each" if rates[0] == rates[1] else " and ".join(rates))
            + f" of the targets (lm {_pct(of('lm', 'success_rate'))}) at "
            f"{_span(ratio['bfgs'], 2)}× and {_span(ratio['powell'], 2)}× lm's median time "
            f"per solve ({_span([1e3 * t for t in lm_time])} ms)")
    planar = [r for (_, t), r in zip(tables, rows) if t.target_kind.startswith("planar")]
    poses = [r for (_, t), r in zip(tables, rows) if t.target_kind == "pose"]
    if of("ccd", "success_rate", planar) and of("ccd", "success_rate", poses):
        out.append(
            "CCD solved the planar arm's position targets "
            f"({_pct(of('ccd', 'success_rate', planar))}) in a median "
            f"{_span(of('ccd', 'median_iterations', planar))} sweeps, but on full poses, "
            "where it trades position against orientation joint by joint, it needed "
            f"{_span(of('ccd', 'median_iterations', poses))} "
            f"({_pct(of('ccd', 'success_rate', poses))} solved)")
    skipped = [t.robot for _, t in tables if any(m == "fabrik" for m, _ in t.skipped)]
    if of("fabrik", "success_rate"):
        out.append(
            f"FABRIK solved {_pct(of('fabrik', 'success_rate'))} of the planar targets in "
            f"{_span([1e3 * t for t in of('fabrik', 'median_time')])} ms per solve"
            + (f" and is skipped, with the reason shown, on {' and '.join(skipped)}"
               if skipped else ""))
    return "<p>Reading the tables (ranges over the robots where a method ran): " + "; ".join(
        out) + ".</p>"


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


def _compare_box(ctx: ReportContext, table: object) -> str:
    """The Reproduce box of the Puma 560 comparison ``table``, with its unchecked rows.

    A method that runs thousands of iterations amplifies the last bits of each step,
    which differ between a kernel's optimisation levels: its row is named and not checked.
    """
    chaotic = [r.method for r in table.rows if r.median_iterations > CHAOTIC_ITERATIONS]
    note = ""
    if chaotic:
        note = (f"<p>{', '.join(chaotic)} ran more than {CHAOTIC_ITERATIONS:,} iterations "
                "per solve: over that many steps the last bits of each step (which depend "
                "on how the kernels were compiled) decide the exact count, so a rerun of "
                "the box below may differ in that row; every other row reproduces to the "
                "digits shown.</p>")
    return note + ctx.reproduce(
        "import serialkin as sk\n"
        "from serialkin.ik.compare import compare\n"
        "robot = sk.models.puma560()\n"
        f"print(compare(robot, robot.fk(robot.random_q({N_SPATIAL}, seed=42)), "
        f"tol={COMPARE_TOL:g}, seed=0))",
        expect=[format_number(v, "{:.3g}") for r in table.rows
                if r.method not in chaotic
                for v in (r.success_rate, r.median_iterations, r.median_position_error,
                          r.max_position_error)])


def build(ctx: ReportContext) -> Section:
    """Measure the numerical IK families of section 5.3 and return the section's first part.

    The default solver's timings share one :class:`~serialkin.chapter._context.TimingBench`
    whose seven blocks of three rounds are taken between the section's other work (the
    Newton demonstration and the three comparisons).
    """
    bench = ctx.bench(rounds=3)
    cases = _default_solver_cases()
    for name, _, solve in cases:
        bench.add(name, solve)
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
        parts.append(f"<h4>{html.escape(title)}</h4>" + _compare_html(ctx, table))
    measured = _measured_summary(tables)
    reading = _reading_text(tables)
    bench.block()
    bench.block()
    parts.append(
        "<p>The comparison times are warm too: each method solves the first target once, "
        "untimed, before the timed solves; the median and mean are over the targets (one "
        "solve each, so they carry no spread of repeated runs). For that spread, the "
        "default solver on one target per robot, each solve timed "
        f"{bench.timing(cases[0][0]).n} times in {bench.blocks} blocks taken between the "
        "comparisons above:</p>"
        + ctx.table(_solver_rows(bench, cases), ["robot", "target", "method", "time"]))
    parts.append(
        "<h4>Trade-offs</h4><p>The first four columns are properties of the algorithms; the "
        "last is measured in the tables above (range over the robots where the family ran: "
        "success rate, median time per solve).</p>" + ctx.table(
            [row + (measured.get(row[0], "not run"),) for row in TRADE_OFFS],
            ["family (methods)", "cost per iteration", "convergence", "near singularities",
             "joint limits", "measured here"]))
    parts.append(reading)
    parts.append(_compare_box(ctx, tables[1][1]))
    return Section(title="5.3 Kinematically redundant manipulators",
                   part="Numerical inverse kinematics, measured",
                   equations="eqs 39-41", html="".join(parts))
