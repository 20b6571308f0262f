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

from serialkin.chapter._context import ReportContext, Section
from serialkin.chapter.sections.workspace.dof import dof_part
from serialkin.chapter.sections.workspace.puma import puma_part
from serialkin.chapter.sections.workspace.three_link import three_link_part
from serialkin.chapter.sections.workspace.two_link import two_link_area_part, two_link_map_part

__all__ = ["build"]


def build(ctx: ReportContext) -> Section:
    """Compute section 1's workspace examples and return the report section."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    progress = False if ctx.quiet else None
    areas, rel2d = two_link_area_part(ctx, progress)
    parts = [
        dof_part(ctx),
        areas,
        two_link_map_part(ctx, progress),
        three_link_part(ctx, progress),
        puma_part(ctx, progress, rel2d),
    ]
    plt.close("all")
    return Section(
        title="1. Degrees of freedom, joint space and workspace",
        equations="section 1 definitions (DOF, joint space, maximal / inclusive / constant / "
                  "total-orientation / dexterous workspace, task space); eq 43 "
                  "(manipulability map); eqs 10-11 (batched FK)",
        html="".join(parts),
    )
