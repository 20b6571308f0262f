"""Section 5.3, the numerical families measured side by side: tables, reading, trade-offs, box.

:func:`serialkin.ik.compare.compare` on a planar 3-link arm, the Puma 560 and the UR5
(seeded targets and starts). Each target is solved once per method, one method after the
other: the tables' times are single-run medians over the targets, not repeated timings
(the section's bench gives those, and the ratios between methods). A method whose median
iteration count exceeds :data:`CHAOTIC_ITERATIONS` is shown with only what reproduces
from build to build: its success rate, its iteration count as "> 1,000", the median
errors as the bound its successful solves meet, and its largest errors as "varies".
"""

from __future__ import annotations

import html
from collections.abc import Callable

from serialkin import models
from serialkin.chapter._context import (
    VARIES,
    ReportContext,
    Timing,
    format_number,
    format_ratio,
)
from serialkin.ik.compare import COLUMNS, CompareRow, CompareTable, compare

#: Tolerance of the comparison (the accuracy bar of the IK issue) [m, rad].
COMPARE_TOL = 1e-6
#: Targets per robot in the comparison (kept small: BFGS/Powell are slow).
N_PLANAR, N_SPATIAL = 20, 10
#: Median iterations beyond which a method's count, and where its failed solves stop,
#: depend on how the kernels were compiled (shown as "> 1,000", not checked by the box).
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


def measured_summary(tables: list[tuple[str, CompareTable]]) -> dict[str, str]:
    """Per family: success rate range and single-run median time range over all tables."""
    acc: dict[str, list[tuple[float, float]]] = {}
    for _, table in tables:
        for row in table.rows:
            acc.setdefault(_family_of(row.method), []).append(
                (row.success_rate, 1e3 * row.median_time))
    return {fam: f"{_pct([v[0] for v in vals])}, {_span([v[1] for v in vals])} ms"
            for fam, vals in acc.items()}


def is_chaotic(row: CompareRow) -> bool:
    """True when the row's iteration count is beyond :data:`CHAOTIC_ITERATIONS`."""
    return row.median_iterations > CHAOTIC_ITERATIONS


def row_cells(row: CompareRow, tol: float) -> tuple[object, ...]:
    """The cells of a table row: a chaotic row shows only what reproduces.

    Its median iterations become "> 1,000"; its median errors the bound "< tol" when more
    than half of its solves succeeded (the median is then a successful solve's error),
    else :data:`VARIES`; its largest errors (a failed solve's, where it stopped)
    :data:`VARIES`.
    """
    cells = list(row.cells())
    if is_chaotic(row):
        bound = f"< {tol:g}" if row.success_rate > 0.5 else VARIES
        for name, value in (("median iterations", f"> {CHAOTIC_ITERATIONS:,}"),
                            ("median pos. error [m]", bound), ("max pos. error [m]", VARIES),
                            ("median ori. error [rad]", bound),
                            ("max ori. error [rad]", VARIES)):
            cells[COLUMNS.index(name)] = value
    return tuple(cells)


def compare_html(ctx: ReportContext, table: CompareTable) -> str:
    """A comparison table through ``ctx.table`` (aligned columns), skipped methods below."""
    caption = (f"<caption>IK methods on {html.escape(table.robot)}: {table.n_targets} "
               f"{html.escape(table.target_kind)} targets, tol {table.tol:g}</caption>")
    body = ctx.table([row_cells(r, table.tol) for r in table.rows], list(COLUMNS),
                     fmt="{:.3g}")
    out = body.replace("<table>", "<table>" + caption, 1)
    chaotic = [r.method for r in table.rows if is_chaotic(r)]
    if chaotic:
        out += (f'<p class="note">{", ".join(chaotic)}: more than {CHAOTIC_ITERATIONS:,} '
                "iterations per solve (median). Over that many steps the last bits of each "
                "step, which depend on how the kernels were compiled, decide the exact "
                "count and where a failed solve stops, so these vary between builds: the "
                f"row gives the count as “&gt; {CHAOTIC_ITERATIONS:,}”, the median errors as "
                "the bound its successful solves meet and the largest errors (those of the "
                f"failed solves) as “{VARIES}”; its success rate reproduces.</p>")
    if table.skipped:
        items = "".join(f"<li><b>{html.escape(m)}</b>: {html.escape(r)}</li>"
                        for m, r in table.skipped)
        out += f'<ul class="skipped">{items}</ul>'
    return out


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


def _iterations(values: list[float]) -> str:
    """Median iteration counts as "a–b", counts beyond :data:`CHAOTIC_ITERATIONS` as a bound."""
    kept = [v for v in values if v <= CHAOTIC_ITERATIONS]
    if len(kept) == len(values):
        return _span(values)
    over = f"more than {CHAOTIC_ITERATIONS:,}"
    return f"{_span(kept)} to {over}" if kept else over


def _optimisers_text(rows: list[dict[str, CompareRow]],
                     ratios: dict[str, list[Timing]]) -> str:
    """BFGS and Powell against lm: success rates, and their time ratios from the bench."""
    rates = {m: _pct([r[m].success_rate for r in rows if m in r]) for m in ("bfgs", "powell")}
    lm = _pct([r["lm"].success_rate for r in rows if "lm" in r])
    text = ("BFGS and Powell (scipy's optimisers, iterating in Python) solved "
            + (f"{rates['bfgs']} each" if rates["bfgs"] == rates["powell"]
               else " and ".join(rates.values())) + f" of the targets (lm {lm})")
    if not ratios:
        return text
    spans = {}
    for m, ts in ratios.items():
        lo, hi = (format_ratio(f([t.median for t in ts])) for f in (min, max))
        spans[m] = lo if lo == hi else f"{lo}–{hi}"
    return (text + f"; on the default solver's target of each robot they took "
            f"{spans['bfgs']}× and {spans['powell']}× lm's time per solve (per robot the "
            "median of the per-round ratios, both timed in the same rounds of one process; "
            "each ratio with its 5th–95th percentile in the table above)")


def reading_text(tables: list[tuple[str, CompareTable]],
                 ratios: dict[str, list[Timing]] | None = None) -> str:
    """What the comparison tables show, each statement computed from their rows.

    Args:
        tables: the comparison tables (title, table).
        ratios: {"bfgs": [...], "powell": [...]}: per robot, the method's time over lm's
            per round on the section's bench (:meth:`TimingBench.ratio`); None: no ratio.
    """
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
            f" of the targets in a median {_iterations(of('lm', 'median_iterations'))} "
            f"iterations and {_span([1e3 * t for t in of('lm', 'median_time')])} ms per solve "
            "(single-run medians over the targets)")
    jac = [m for r in rows for m, row in r.items()
           if row.family == "jacobian" and m != "transpose"]
    if of("transpose", "median_iterations") and jac:
        others = [float(r[m].median_iterations) for r in rows for m in set(jac) if m in r]
        out.append(
            "the Jacobian transpose converges linearly: a median "
            f"{_iterations(of('transpose', 'median_iterations'))} iterations per solve "
            f"against {_iterations(others)} for the other Jacobian methods, and it solved "
            f"{_pct(of('transpose', 'success_rate'))} of the targets")
    if of("bfgs", "success_rate") and of("powell", "success_rate"):
        out.append(_optimisers_text(rows, ratios or {}))
    planar = [r for (_, t), r in zip(tables, rows) if t.target_kind.startswith("planar")]
    poses = [r for (_, t), r in zip(tables, rows) if t.target_kind == "pose"]
    if of("ccd", "success_rate", planar) and of("ccd", "success_rate", poses):
        out.append(
            "CCD solved the planar arm's position targets "
            f"({_pct(of('ccd', 'success_rate', planar))}) in a median "
            f"{_iterations(of('ccd', 'median_iterations', planar))} sweeps, but on full "
            "poses, where it trades position against orientation joint by joint, it needed "
            f"{_iterations(of('ccd', 'median_iterations', poses))} "
            f"({_pct(of('ccd', 'success_rate', poses))} solved)")
    skipped = [t.robot for _, t in tables if any(m == "fabrik" for m, _ in t.skipped)]
    if of("fabrik", "success_rate"):
        out.append(
            f"FABRIK solved {_pct(of('fabrik', 'success_rate'))} of the planar targets in "
            f"{_span([1e3 * t for t in of('fabrik', 'median_time')])} ms per solve (single-run "
            "median)"
            + (f" and is skipped, with the reason shown, on {' and '.join(skipped)}"
               if skipped else ""))
    return "<p>Reading the tables (ranges over the robots where a method ran): " + "; ".join(
        out) + ".</p>"


def compare_box(ctx: ReportContext, table: CompareTable) -> str:
    """The Reproduce box of the Puma 560 comparison ``table``.

    It checks every row's success rate, median iterations and median and largest position
    errors, except a chaotic row's (:func:`is_chaotic`), of which it checks the success
    rate only: the other numbers of that row are not shown (:func:`row_cells`).
    """
    expect = []
    for r in table.rows:
        values = ((r.success_rate,) if is_chaotic(r) else
                  (r.success_rate, r.median_iterations, r.median_position_error,
                   r.max_position_error))
        expect += [format_number(v, "{:.3g}") for v in values]
    return ctx.reproduce(
        "import serialkin as sk\n"
        "from serialkin.ik.compare import compare\n"
        "robot = sk.models.puma560()\n"
        f"print(compare(robot, robot.fk(robot.random_q({N_SPATIAL}, seed=42)), "
        f"tol={COMPARE_TOL:g}, seed=0))",
        expect=expect)
