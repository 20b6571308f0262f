"""Report section 5.3 (second part): redundancy resolution, eqs 42-56, recomputed.

Contents, in the chapter's order: the null-space methods of eqs 42-44 (the projector
checked numerically, self-motion along the manipulability gradient and away from the
joint limits, eq 44 corrected; the obstacle objective of eq 45 checked by brute force and
finite differences); the chapter's 6-link example (Figures 8 and 9, eq 46
corrected) run from the shipped scenario ``six_link_circle``; the weighted multi-task
resolution of eqs 47-50 (eq 48 corrected, eq 49 designed and plotted, eq 48 assembled
by hand from eqs 49-50 and compared with the library); Figure 10, the link-obstacle
geometry of eqs 51-56 (corrected) with a finite-difference check of the obstacle
Jacobian row; the 20-link example in free space (Figure 11, ``twenty_link_free``) and
between four obstacles with joint limits ±100° (Figure 12, ``twenty_link_obstacles``):
warm timings, each secondary task's activity per path point and an ablation that
switches each task off in turn; and the same constrained scenario solved side by side by
eq 48 (soft, weighted tasks) and by the differential-IK quadratic program with hard
joint limits and collision constraints (:mod:`serialkin.diffik`).
"""

from __future__ import annotations

from serialkin.chapter._context import ReportContext, Section
from serialkin.chapter.sections.redundancy._common import eq48_by_hand, timed_run
from serialkin.chapter.sections.redundancy.nullspace import _nullspace_part, _six_link_part
from serialkin.chapter.sections.redundancy.qp import _qp_part, side_by_side
from serialkin.chapter.sections.redundancy.twenty_link import _twenty_link_part
from serialkin.chapter.sections.redundancy.weights import _figure10_part, _weights_part
from serialkin.tracking import load_scenario
from serialkin.tracking.analysis import ablation

__all__ = ["build", "eq48_by_hand", "side_by_side", "timed_run"]


def build(ctx: ReportContext) -> list[Section]:
    """Run the redundancy examples of section 5.3 and return the report's parts."""
    sb = load_scenario("twenty_link_free")
    sc = load_scenario("twenty_link_obstacles")
    tb, tc = sb.run(), sc.run()  # the trajectories (every run gives the same)
    time_b, time_c, ratio = ctx.interleaved(sb.run, sc.run, warmup=1, repeat=15)
    runs = ablation(sc, tc)
    return [
        _nullspace_part(ctx),
        _six_link_part(ctx),
        _weights_part(ctx, sc, tc),
        _figure10_part(ctx, sc, tc),
        _twenty_link_part(ctx, sb, sc, tb, tc, time_b, time_c, runs, ratio),
        _qp_part(ctx, sc, side_by_side(ctx, sc, tc)),
    ]
