"""Section 1 (workspace): the 2-link arm's sampled areas and its workspace figure."""

from __future__ import annotations

from serialkin import models
from serialkin.chapter._context import ReportContext
from serialkin.chapter.sections.workspace._common import AREA_SAMPLES, SEED
from serialkin.chapter.sections.workspace.closed_forms import annulus_area
from serialkin.workspace import reachable_workspace


def two_link_area_part(ctx: ReportContext, progress: bool | None) -> tuple[str, list[float]]:
    """Sampled area of the 2-link workspace against its closed form, for four arms.

    Returns:
        (HTML, the relative error bounds ε/Â of the four areas).
    """
    rows = []
    for L1, L2 in ((1.0, 1.0), (1.0, 0.6), (0.7, 0.4), (0.5, 0.9)):
        ws = reachable_workspace(models.two_link(L1, L2), AREA_SAMPLES, seed=SEED,
                                 progress=progress)
        exact = annulus_area(L1, L2)
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


def two_link_map_part(ctx: ReportContext, progress: bool | None) -> str:
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
        f"{err} m² (closed form {annulus_area(1.0, 0.6):.6g} m²). "
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
