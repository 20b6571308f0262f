"""Section 1 (workspace): every workspace kind of section 1 on the 3-link arm."""

from __future__ import annotations

import math

from serialkin import models
from serialkin.chapter._context import ReportContext
from serialkin.chapter.sections.workspace._common import SEED
from serialkin.chapter.sections.workspace.closed_forms import (
    annulus_area,
    three_link_reachable_area,
    three_link_total_area,
)
from serialkin.model.robot import Robot
from serialkin.workspace import (
    Workspace,
    constant_orientation_workspace,
    inclusive_orientation_workspace,
    reachable_workspace,
)
from serialkin.workspace.kinds import total_and_dexterous_workspaces

#: (label, workspace, closed-form area [m²] or None) of one workspace kind.
_Kind = tuple[str, Workspace, float | None]


def _three_link_kinds(three: Robot, L: tuple[float, float, float],
                      progress: bool | None) -> list[_Kind]:
    """(label, workspace, closed-form area or None) of every workspace kind of section 1.

    The total-orientation and dexterous workspaces come from one sampling on one grid, so
    the dexterous cells are a subset of the total-orientation cells.
    """
    phi = 0.0
    total, dexterous = total_and_dexterous_workspaces(three, 12, 20_000, seed=SEED,
                                                      singularity_margin=0.05,
                                                      progress=progress)
    return [
        ("maximal (reachable)", reachable_workspace(three, 200_000, seed=SEED,
                                                    progress=progress),
         three_link_reachable_area(L)),
        ("constant orientation φ = 0", constant_orientation_workspace(
            three, phi, 60_000, seed=SEED, progress=progress), annulus_area(L[0], L[1])),
        ("inclusive orientation |φ| ≤ 30°", inclusive_orientation_workspace(
            three, phi, math.radians(30), 60_000, seed=SEED, progress=progress), None),
        ("total orientation (12 headings)", total, three_link_total_area(L)),
        ("dexterous (12 headings, w ≥ 5 % of max)", dexterous, None),
    ]


def _three_link_intro(ctx: ReportContext, L: tuple[float, float, float]) -> str:
    """How the orientation workspaces of the 3-link arm are computed, with the closed forms."""
    return (
        f"<h3>Workspace kinds of the 3-link arm (L = {L} m)</h3>"
        "<p>Constant- and inclusive-orientation samples are moved onto the orientation "
        "constraint by damped least-squares steps on the angular rows of the Jacobian; the "
        "total-orientation and dexterous workspaces intersect the constant-orientation "
        "occupancy grids of 12 evenly spaced headings, the dexterous one keeping only "
        "samples whose manipulability (planar pose task) is at least 5 % of the largest. "
        "The dexterous workspace is computed from the same samples as the total-orientation "
        "one and counted on the same grid (<code>total_and_dexterous_workspaces</code>), so "
        "its cells are a subset of the total-orientation cells by construction and its area "
        "cannot exceed it (computed on "
        "separate grids sized for their own samples, the two estimates differ by their "
        "sampling errors and a subset could print larger than its superset). "
        "Closed forms, with " + ctx.imath(r"d = |L_1 - L_2|") + ": maximal, the annulus "
        + ctx.imath(r"\max(0, 2\max_i L_i - \textstyle\sum_i L_i) \le |\mathbf{p}| \le"
                    r" L_1 + L_2 + L_3") + "; constant orientation, the 2-link annulus "
        + ctx.imath(r"d \le |\mathbf{p} - L_3\mathbf{e}_\varphi| \le L_1 + L_2")
        + " about the wrist; total orientation, "
        + ctx.imath(r"d + L_3 \le |\mathbf{p}| \le L_1 + L_2 - L_3")
        + " plus the disc " + ctx.imath(r"|\mathbf{p}| \le L_3 - d") + " when "
        + ctx.imath(r"L_3 > d") + ".</p>"
    )


def _three_link_areas(ctx: ReportContext, kinds: list[_Kind]) -> str:
    """Table of the kinds' areas against their closed forms, and the inclusion check."""
    rows = []
    for label, ws, exact in kinds:
        e = ws.estimate
        ok = "" if exact is None else ("yes" if abs(e.value - exact) <= e.error else "NO")
        rows.append((label, e.value, e.error, "—" if exact is None else exact, ok,
                     ws.points.shape[0]))
    total, dexterous = kinds[3][1], kinds[4][1]
    extra = int((dexterous.grid.occupied & ~total.grid.occupied).sum())
    te, de = total.estimate, dexterous.estimate
    return (
        ctx.table(rows, ["kind", "area Â [m²]", "error ε [m²]", "closed form [m²]",
                         "within ε", "samples kept"])
        + "<p>Inclusion check on the common grid (cell "
        f"{te.cell * 1e3:.3g} mm): {int(dexterous.grid.occupied.sum())} dexterous cells, "
        f"{int(total.grid.occupied.sum())} total-orientation cells, {extra} dexterous cells "
        f"outside the total-orientation set; areas {de.value:.4f} ± {de.error:.2g} m² ≤ "
        f"{te.value:.4f} ± {te.error:.2g} m². Each ± is the sampling error bound: half the "
        "boundary cells plus the Chao1 estimate of cells no sample hit.</p>"
    )


def _three_link_figure(ctx: ReportContext, kinds: list[_Kind]) -> str:
    """One panel per workspace kind of the 3-link arm plus an overlay, and its reproduction."""
    import matplotlib.pyplot as plt

    from serialkin.workspace.plot import plot_workspace, plot_workspace_kinds

    fig, axes = plt.subplots(2, 3, figsize=(13, 8.4))
    for ax, (label, ws, _) in zip(axes.ravel(), kinds):
        plot_workspace(ws, ax, color_by_manipulability=False, max_points=5_000,
                       title=f"{label}\n{ws.estimate.value:.3f} ± {ws.estimate.error:.2g} m²")
    plot_workspace_kinds([kinds[0][1], kinds[1][1], kinds[4][1]], axes.ravel()[5],
                         labels=["maximal", "constant φ = 0", "dexterous"],
                         title="overlay")
    fig.tight_layout()
    return (
        ctx.figure(fig, "workspace_three_link_kinds",
                   "3-link arm: the workspace kinds of section 1 with their "
                   "boundaries and areas; bottom right, three of them overlaid. "
                   "Enclosed gaps of a few cells that no sample hit are not outlined "
                   "(only true holes are).")
        + ctx.reproduce(
            "from serialkin import models\n"
            "from serialkin.workspace.kinds import total_and_dexterous_workspaces\n"
            "arm = models.three_link(1.0, 0.8, 0.3)\n"
            "tot, dex = total_and_dexterous_workspaces(arm, 12, 20_000, seed=2024,"
            " singularity_margin=0.05)\n"
            "print(f'total {tot.estimate.value:.4f} ± {tot.estimate.error:.2g} m², '\n"
            "      f'dexterous {dex.estimate.value:.4f} ± {dex.estimate.error:.2g} m²')",
            expect=[f"{kinds[3][1].estimate.value:.4f}", f"{kinds[3][1].estimate.error:.2g}",
                    f"{kinds[4][1].estimate.value:.4f}", f"{kinds[4][1].estimate.error:.2g}"])
    )


def three_link_part(ctx: ReportContext, progress: bool | None) -> str:
    """Every workspace kind of section 1 on the 3-link arm: prose, table, figure."""
    L = (1.0, 0.8, 0.3)
    kinds = _three_link_kinds(models.three_link(*L), L, progress)
    return _three_link_intro(ctx, L) + _three_link_areas(ctx, kinds) + _three_link_figure(
        ctx, kinds)
