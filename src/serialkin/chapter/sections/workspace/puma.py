"""Section 1 (workspace): a spatial robot, the PUMA 560 (volumes, slices, figures)."""

from __future__ import annotations

import math

from serialkin import models
from serialkin.chapter._context import ReportContext
from serialkin.chapter.sections.workspace._common import AREA_SAMPLES, SEED
from serialkin.spatial import rpy_to_matrix
from serialkin.workspace import (
    Workspace,
    WorkspaceSlice,
    constant_orientation_workspace,
    inclusive_orientation_workspace,
    reachable_workspace,
    workspace_slice,
)


def _puma_table(ctx: ReportContext, ws3: Workspace, wsc: Workspace, wsi: Workspace,
                slices: list[WorkspaceSlice], rel2d: list[float]) -> str:
    """The PUMA 560's workspace volumes and slice areas with their error bounds.

    Args:
        ctx: the report context.
        ws3: the maximal workspace.
        wsc: the constant-orientation workspace (tool down).
        wsi: the inclusive-orientation workspace (tool within 30° of down).
        slices: horizontal slices of ``ws3``.
        rel2d: relative error bounds ε/Â of the 2-link areas above (for comparison).
    """
    rel3 = ws3.estimate.error / ws3.estimate.value
    return (
        "<h3>A spatial robot: PUMA 560</h3>"
        "<p>Spatial workspaces are 3D point clouds measured on a voxel grid; planar slices "
        "(samples within half a voxel of the plane) show the cross-sections. A voxel grid "
        "has far fewer samples per cell than a 2D grid for the same number of samples, so "
        f"the relative error bounds are larger: ε/V = {rel3:.1%} for the maximal volume "
        f"from {ws3.samples:,} samples, against ε/Â = {min(rel2d):.1%}–{max(rel2d):.1%} for "
        f"the 2-link areas above from {AREA_SAMPLES:,} (a 6R arm's dexterous workspace: "
        "<code>serialkin workspace puma560 --kind dexterous --samples ...</code>).</p>"
        + ctx.table(
            [("maximal", ws3.estimate.value, f"{ws3.estimate.error:.2g}", ws3.samples,
              ws3.points.shape[0]),
             ("constant orientation (tool down)", wsc.estimate.value,
              f"{wsc.estimate.error:.2g}", wsc.samples, wsc.points.shape[0]),
             ("inclusive orientation (tool within 30° of down)", wsi.estimate.value,
              f"{wsi.estimate.error:.2g}", wsi.samples, wsi.points.shape[0])]
            + [(f"slice z = {s.value:.2f} m of the maximal (area, m²)", s.estimate.value,
                f"{s.estimate.error:.2g}", "", s.points.shape[0]) for s in slices],
            ["set", "volume [m³] / area [m²]", "error bound", "samples (seed 2024)",
             "points kept"])
    )


def _puma_figures(ctx: ReportContext, ws3: Workspace, wsc: Workspace,
                  slices: list[WorkspaceSlice]) -> str:
    """The PUMA 560's workspaces in 3D and its horizontal slices: two figures."""
    import matplotlib.pyplot as plt

    from serialkin.workspace.plot import plot_slice, plot_workspace

    fig = plt.figure(figsize=(13, 4.6))
    ax = fig.add_subplot(1, 3, 1, projection="3d")
    plot_workspace(ws3, ax, max_points=5_000)
    ax = fig.add_subplot(1, 3, 2, projection="3d")
    plot_workspace(wsc, ax, max_points=5_000)
    plot_slice(slices[1], ax=fig.add_subplot(1, 3, 3), title=(
        f"slice z = {slices[1].value:.2f} m: "
        f"{slices[1].estimate.value:.3f} ± {slices[1].estimate.error:.2g} m²"))
    fig.tight_layout()
    html = ctx.figure(fig, "workspace_puma560",
                      "PUMA 560: maximal workspace (left), constant-orientation "
                      "workspace with the tool pointing down (middle) and the maximal "
                      "workspace's slice at shoulder height (right).")
    fig, axes = plt.subplots(1, 3, figsize=(13, 4.2))
    for ax, s in zip(axes, slices):
        plot_slice(s, ax=ax)
    fig.tight_layout()
    return html + ctx.figure(fig, "workspace_puma560_slices",
                             "PUMA 560 maximal workspace: horizontal slices with their "
                             "boundaries and cross-section areas.")


def puma_part(ctx: ReportContext, progress: bool | None, rel2d: list[float]) -> str:
    """A spatial robot (PUMA 560): maximal, constant- and inclusive-orientation, slices.

    Args:
        ctx: the report context.
        progress: progress bars (None: automatic, False: none).
        rel2d: relative error bounds of the 2-link areas (compared in the prose).
    """
    puma = models.puma560()
    ws3 = reachable_workspace(puma, 300_000, seed=SEED, progress=progress)
    down = rpy_to_matrix([math.pi, 0.0, 0.0])  # tool z axis pointing down
    wsc = constant_orientation_workspace(puma, down, 25_000, seed=SEED, progress=progress)
    wsi = inclusive_orientation_workspace(puma, down, math.radians(30), 25_000, seed=SEED,
                                          progress=progress)
    slices = [workspace_slice(ws3, "z", z) for z in (0.2, 0.67, 1.1)]
    return (_puma_table(ctx, ws3, wsc, wsi, slices, rel2d)
            + _puma_figures(ctx, ws3, wsc, slices)
            + ctx.reproduce(f"serialkin workspace puma560 --samples {ws3.samples} --seed {SEED} "
                            "--slice z=0.67 --out out/ws", shell=True,
                            expect=[f"{ws3.estimate.value:.6g}", f"{ws3.estimate.error:.2g}",
                                    f"{slices[1].estimate.value:.6g}",
                                    f"{slices[1].estimate.error:.2g}"]))
