"""Report section 5.3 (second part): redundancy resolution, eqs 42-56, recomputed.

Contents, in the chapter's order: the null-space methods of eqs 42-44 (the projector
checked numerically, self-motion along the manipulability gradient and away from the
joint limits, eq 44 corrected; the obstacle objective of eq 45 checked by brute force and
finite differences); the chapter's 6-link example (Figures 8 and 9, eq 46 corrected) run
from the shipped scenario ``six_link_circle``; the weighted multi-task resolution of eqs
47-50 (step 6 of the algorithm corrected to eq 48, eq 49 designed and plotted, eq 48
assembled by hand from eqs 49-50 and compared with the library); Figure 10, the
link-obstacle geometry of eqs 51-56 (51, 52 and 54 corrected) with a finite-difference
check of the obstacle Jacobian row; the 20-link example in free space (Figure 11,
``twenty_link_free``) and between four obstacles with joint limits ±100° (Figure 12,
``twenty_link_obstacles``): warm timings, the step cap that decides its outcome, each
secondary task's activity per path point and an ablation that switches each task off in
turn; and the same constrained scenario solved side by side by eq 48 (soft, weighted
tasks) and by the differential-IK quadratic program with hard joint limits and collision
constraints (:mod:`serialkin.diffik`).
"""

from __future__ import annotations

from serialkin.chapter._context import ReportContext, Section
from serialkin.chapter.sections.redundancy._common import eq48_by_hand, timed_run
from serialkin.chapter.sections.redundancy.nullspace import (
    _nullspace_part,
    _six_link_part,
    six_link_prepare,
)
from serialkin.chapter.sections.redundancy.qp import (
    _qp_part,
    qp_figures,
    qp_scenario,
    side_by_side,
    side_by_side_rows,
)
from serialkin.chapter.sections.redundancy.step_cap import step_cap_study
from serialkin.chapter.sections.redundancy.twenty_link import (
    _twenty_link_part,
    twenty_link_figures,
)
from serialkin.chapter.sections.redundancy.weights import _figure10_part, _weights_part
from serialkin.tracking import load_scenario
from serialkin.tracking.analysis import ablation, compare_row

__all__ = ["build", "eq48_by_hand", "side_by_side", "timed_run"]

#: Names of the timed whole-path runs on the section's bench.
SIX, FREE, CONSTRAINED, QP = ("six-link circle", "(b) free", "(c) constrained",
                              "(c) by the QP")


def build(ctx: ReportContext) -> list[Section]:
    """Run the redundancy examples of section 5.3 and return the report's parts.

    The four whole-path runs the section times (six-link circle, 20-link (b) and (c), and
    (c) by the QP) are registered on one :class:`~serialkin.chapter._context.TimingBench`
    and timed in seven blocks of three rounds, taken between the section's other work
    (null space, ablation, the step-cap runs, eqs 48-56, the figures); the parts that
    print a time are assembled at the end.
    """
    sa = load_scenario("six_link_circle")
    sb = load_scenario("twenty_link_free")
    sc = load_scenario("twenty_link_obstacles")
    qp = qp_scenario(sc)
    bench = ctx.bench(rounds=3)
    ta = bench.add(SIX, sa.run)  # each warm-up run's trajectory (every run gives the same)
    tb = bench.add(FREE, sb.run)
    tc = bench.add(CONSTRAINED, sc.run)
    tq = bench.add(QP, qp.run)
    bench.block()
    nullspace = _nullspace_part(ctx)
    bench.block()
    runs = ablation(sc, tc)
    cap = step_cap_study(sb, sc, tb, tc)
    six = six_link_prepare(ctx, sa, ta)
    bench.block()
    weights = _weights_part(ctx, sc, tc)
    figure10 = _figure10_part(ctx, sc, tc)
    bench.block()
    twenty = twenty_link_figures(ctx, sb, sc, tb, tc, runs)
    bench.block()
    qp_figs = qp_figures(ctx, sc, [compare_row("weighted tasks, eq 48 (soft)", tc),
                                   compare_row("QP with hard constraints", tq)])
    bench.block()
    bench.block()
    time_c = bench.timing(CONSTRAINED)
    rows = side_by_side_rows(tc, time_c, tq, bench.timing(QP), bench.ratio(QP, CONSTRAINED))
    return [
        nullspace,
        _six_link_part(ctx, sa, ta, bench.timing(SIX), six),
        weights,
        figure10,
        _twenty_link_part(ctx, sb, sc, tb, tc, bench.timing(FREE), time_c, runs,
                          bench.ratio(CONSTRAINED, FREE), twenty, cap),
        _qp_part(ctx, sc, rows, qp_figs, cap),
    ]
