"""Report section 1: degrees of freedom, joint space, workspace kinds and task space.

Computed by :mod:`serialkin.workspace` (sampling on the batched FK kernels):

* a table of the built-in robots: DOF n, the joint space Q (product of joint ranges),
  the task space dimension m and the degree of redundancy n − m;
* the 2-link arm: sampled area of the maximal workspace against the closed form
  π((L1+L2)² − (L1−L2)²), with the sampling error bound, for several link lengths; the
  workspace with its boundary and the manipulability map (eq 43);
* the 3-link arm: every workspace kind of section 1 (maximal, constant-orientation,
  inclusive-orientation, total-orientation, dexterous), with areas, the closed forms
  where they are known, and one figure each plus an overlay;
* a spatial robot (PUMA 560): the maximal workspace as a 3D point cloud with its volume,
  planar slices, and the constant-orientation workspace with the tool pointing down.
"""

from __future__ import annotations

import math

import numpy as np

from serialkin import models
from serialkin.chapter._context import ReportContext, Section
from serialkin.model.robot import Robot
from serialkin.spatial import rpy_to_matrix
from serialkin.workspace import (
    Workspace,
    WorkspaceSlice,
    constant_orientation_workspace,
    inclusive_orientation_workspace,
    reachable_workspace,
    workspace_slice,
)
from serialkin.workspace.kinds import total_and_dexterous_workspaces

SEED = 2024
#: Samples of each 2-link area in the table of section 1.
AREA_SAMPLES = 100_000

#: (label, workspace, closed-form area [m²] or None) of one workspace kind.
_Kind = tuple[str, Workspace, float | None]


def _annulus(L1: float, L2: float) -> float:
    """π((L1+L2)² − (L1−L2)²) = 4π L1 L2: the area of the 2-link workspace."""
    return math.pi * ((L1 + L2) ** 2 - (L1 - L2) ** 2)


def _three_link_reachable(L: tuple[float, float, float]) -> float:
    """Maximal workspace of a planar 3R arm: the annulus r_min ≤ |p| ≤ L1+L2+L3."""
    r_max = sum(L)
    r_min = max(0.0, 2 * max(L) - r_max)
    return math.pi * (r_max**2 - r_min**2)


def _three_link_total(L: tuple[float, float, float]) -> float:
    """Total-orientation workspace of a planar 3R arm (unlimited joints).

    Every heading φ is reachable at p when the wrist p − L3 e_φ is in the 2-link annulus
    [d, L1+L2], d = |L1−L2|, for every φ: |p| ∈ [d + L3, L1 + L2 − L3], plus the disc
    |p| ≤ L3 − d when L3 > d.
    """
    L1, L2, L3 = L
    d = abs(L1 - L2)
    outer = max(L1 + L2 - L3, 0.0)
    ring = math.pi * max(outer**2 - (d + L3) ** 2, 0.0) if outer > d + L3 else 0.0
    return ring + math.pi * max(L3 - d, 0.0) ** 2


def _limits_text(robot: object) -> str:
    parts = []
    for (lo, hi), t in zip(robot.qlim, robot.joint_types):  # type: ignore[attr-defined]
        if not (np.isfinite(lo) and np.isfinite(hi)):
            parts.append("ℝ" if t == "P" else "S¹")
        elif t == "R":
            parts.append(f"[{math.degrees(lo):.0f}°, {math.degrees(hi):.0f}°]")
        else:
            parts.append(f"[{lo:.3g}, {hi:.3g}] m")
    return " × ".join(parts)


def _dof_table(ctx: ReportContext) -> tuple[str, dict[str, tuple[int, int]]]:
    """The table of every built-in robot, and {name: (n, m)}."""
    rows = []
    for info in models.catalog():
        r = info.build() if info.dof is not None else info.build(6, 0.1)
        planar = bool(r.is_planar)
        # generic rank of J: the dimension of the task space the tool can move in
        J = r.jacobian(r.random_q(8, seed=SEED))
        m = int(max(np.linalg.matrix_rank(Jk, tol=1e-9) for Jk in J))
        rows.append((r.name, r.n, "".join(r.joint_types), _limits_text(r),
                     "planar (x, y, φ)" if planar else "spatial (x, y, z, 3 rotations)", m,
                     r.n - m))
    return ctx.table(rows, ["robot", "DOF n", "joints", "joint space Q",
                            "task space", "m = rank J", "redundancy n − m"]), {
        row[0]: (row[1], row[5]) for row in rows}


def _dof_part(ctx: ReportContext) -> str:
    """DOF, joint space and task space of every built-in robot (table and reproduction)."""
    table, nm = _dof_table(ctx)
    return (
        "<h3>Degrees of freedom, joint space and task space</h3>"
        "<p>The number of DOF is the dimension of the joint space Q (one coordinate per "
        "joint); the task space of a planar arm has m = 3 coordinates (x, y, φ), that of a "
        "spatial arm m = 6; the table gives the generic rank of the Jacobian, the number "
        f"of task coordinates the tool can actually move in ({nm['two_link'][1]} for the "
        f"2-link arm, {nm['scara'][1]} for the SCARA: x, y, z and the yaw). A robot with "
        "n &gt; m is kinematically redundant "
        "(section 5.3). S¹ is an unlimited revolute joint.</p>" + table
        + ctx.reproduce(
            "import numpy as np\n"
            "from serialkin import models\n"
            "r = models.scara(); J = r.jacobian(r.random_q(8, seed=2024))\n"
            "print(r.n, max(np.linalg.matrix_rank(Jk, tol=1e-9) for Jk in J))  # n, m",
            expect=[str(v) for v in nm["scara"]])
    )


def _two_link_area_part(ctx: ReportContext, progress: bool | None) -> tuple[str, list[float]]:
    """Sampled area of the 2-link workspace against its closed form, for four arms.

    Returns:
        (HTML, the relative error bounds ε/Â of the four areas).
    """
    rows = []
    for L1, L2 in ((1.0, 1.0), (1.0, 0.6), (0.7, 0.4), (0.5, 0.9)):
        ws = reachable_workspace(models.two_link(L1, L2), AREA_SAMPLES, seed=SEED,
                                 progress=progress)
        exact = _annulus(L1, L2)
        e = ws.estimate
        rows.append((L1, L2, exact, e.value, e.error, abs(e.value - exact),
                     "yes" if abs(e.value - exact) <= e.error else "NO", e.cell))
    return ((
        "<h3>Maximal workspace of the 2-link arm</h3>"
        "<p>Joint space sampled uniformly (seeded), every sample's tool position computed "
        "by the batched FK kernel and binned on an occupancy grid. The area estimate Â "
        "counts interior cells fully and boundary cells by half; the error bound ε adds "
        "half the boundary cells and the Chao1 estimate of cells no sample hit "
        "(see <code>serialkin.workspace.grid</code>). The closed form is</p>"
        + ctx.eq(r"A = \pi\left((L_1 + L_2)^2 - (L_1 - L_2)^2\right) = 4\pi L_1 L_2")
        + ctx.table(rows, ["L1 [m]", "L2 [m]", "closed form A [m²]", "sampled Â [m²]",
                           "error bound ε [m²]", "|Â − A|", "within ε", "cell [m]"])
    ), [row[4] / row[3] for row in rows])


def _two_link_map_part(ctx: ReportContext, progress: bool | None) -> str:
    """The 2-link workspace with its boundary and manipulability map (eq 43), one figure."""
    import matplotlib.pyplot as plt

    from serialkin.workspace.plot import plot_manipulability_map, plot_workspace

    two = models.two_link(1.0, 0.6)
    ws2 = reachable_workspace(two, 200_000, seed=SEED, manipulability=True, progress=progress)
    fig, axes = plt.subplots(1, 2, figsize=(12, 5.2))
    plot_workspace(ws2, axes[0], robot=two, q=[0.6, 1.1])
    plot_manipulability_map(ws2, axes[1])
    fig.tight_layout()
    e = ws2.estimate
    area, err = f"{e.value:.6g}", f"{e.error:.2g}"
    return (
        f"<p>The figure's workspace, {ws2.samples:,} samples (seed {SEED}): Â = {area} ± "
        f"{err} m² (closed form {_annulus(1.0, 0.6):.6g} m²). "
        "The manipulability of eq 43 of the 2-link arm is "
        + ctx.imath(r"w = \sqrt{\det\left(\mathbf{J}\mathbf{J}^T\right)}"
                    r" = L_1 L_2 \left|\sin q_2\right|")
        + ": zero on both boundary circles, the singular configurations "
        + ctx.imath(r"q_2 = 0, \pi") + ".</p>"
        + ctx.figure(fig, "workspace_two_link",
                     "2-link arm (L1 = 1 m, L2 = 0.6 m): maximal workspace with its "
                     "boundary (left) and the manipulability per cell (right, eq 43).")
        + ctx.reproduce(f"serialkin workspace two_link --param l1=1.0 --param l2=0.6 "
                        f"--samples {ws2.samples} --seed {SEED} -w --out out/ws", shell=True,
                        expect=[area, err])
    )


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
         _three_link_reachable(L)),
        ("constant orientation φ = 0", constant_orientation_workspace(
            three, phi, 60_000, seed=SEED, progress=progress), _annulus(L[0], L[1])),
        ("inclusive orientation |φ| ≤ 30°", inclusive_orientation_workspace(
            three, phi, math.radians(30), 60_000, seed=SEED, progress=progress), None),
        ("total orientation (12 headings)", total, _three_link_total(L)),
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


def _three_link_part(ctx: ReportContext, progress: bool | None) -> str:
    """Every workspace kind of section 1 on the 3-link arm: prose, table, figure."""
    L = (1.0, 0.8, 0.3)
    kinds = _three_link_kinds(models.three_link(*L), L, progress)
    return _three_link_intro(ctx, L) + _three_link_areas(ctx, kinds) + _three_link_figure(
        ctx, kinds)


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


def _puma_part(ctx: ReportContext, progress: bool | None, rel2d: list[float]) -> str:
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


def build(ctx: ReportContext) -> Section:
    """Compute section 1's workspace examples and return the report section."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    progress = False if ctx.quiet else None
    areas, rel2d = _two_link_area_part(ctx, progress)
    parts = [
        _dof_part(ctx),
        areas,
        _two_link_map_part(ctx, progress),
        _three_link_part(ctx, progress),
        _puma_part(ctx, progress, rel2d),
    ]
    plt.close("all")
    return Section(
        title="1. Degrees of freedom, joint space and workspace",
        equations="section 1 definitions (DOF, joint space, maximal / inclusive / constant / "
                  "total-orientation / dexterous workspace, task space); eq 43 "
                  "(manipulability map); eqs 10-11 (batched FK)",
        html="".join(parts),
    )
