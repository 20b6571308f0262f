"""Figures of sampled workspaces (matplotlib, imported on use).

* :func:`plot_workspace` — a planar workspace in 2D (occupied cells, samples coloured by
  manipulability, the boundary, the area ± its error) or a spatial one as a 3D point cloud;
* :func:`plot_manipulability_map` — per-cell maximum manipulability (eq 43);
* :func:`plot_slice` — a planar slice of a 3D workspace with its boundary and area;
* :func:`plot_workspace_kinds` — the boundaries of several workspaces of one robot
  overlaid (e.g. maximal vs constant-orientation vs dexterous).
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np

from serialkin.errors import InputError
from serialkin.workspace.kinds import Workspace, WorkspaceSlice, workspace_slice

_TITLES = {
    "reachable": "maximal (reachable) workspace",
    "constant": "constant-orientation workspace",
    "inclusive": "inclusive-orientation workspace",
    "total": "total-orientation workspace",
    "dexterous": "dexterous workspace",
}


def _subsample(n: int, max_points: int, seed: int) -> np.ndarray:
    if n <= max_points:
        return np.arange(n)
    return np.sort(np.random.default_rng(seed).choice(n, max_points, replace=False))


def _measure_label(est: Any) -> str:
    what = "area" if est.dim == 2 else "volume"
    return f"{what} = {est.value:.4g} ± {est.error:.2g} {est.unit}"


def plot_workspace(ws: Workspace, ax: Any = None, *, color_by_manipulability: bool = True,
                   show_cells: bool = True, show_boundary: bool = True,
                   max_points: int = 30_000, seed: int = 0, title: str | None = None,
                   robot: Any = None, q: object = None) -> Any:
    """Draw a workspace: 2D for planar robots, a 3D point cloud otherwise.

    Args:
        ws: the workspace.
        ax: axes to draw into (a new figure when None; 3D axes for a spatial workspace).
        color_by_manipulability: colour samples by manipulability when it was computed.
        show_cells: shade the occupied grid cells (planar).
        show_boundary: draw the boundary polylines (planar).
        max_points: at most this many samples are drawn (seeded subsample).
        seed: seed of the subsample.
        title: axes title (default: the kind, robot and measure).
        robot: optionally draw this robot (in configuration ``q``, default zeros) on top.
        q: the robot's configuration.

    Returns:
        The axes.
    """
    import matplotlib.pyplot as plt

    if ax is None:
        fig = plt.figure(figsize=(6.4, 5.6))
        ax = fig.add_subplot(111, projection=None if ws.planar else "3d")
    idx = _subsample(ws.points.shape[0], max_points, seed)
    P = ws.points[idx]
    w = ws.manipulability[idx] if (color_by_manipulability and ws.manipulability is not None) \
        else None
    if ws.planar:
        if show_cells and ws.grid.counts.size > 1:
            g = ws.grid
            ext = (g.lower[0], g.upper[0], g.lower[1], g.upper[1])
            ax.imshow(np.where(g.occupied.T, 1.0, np.nan), origin="lower", extent=ext,
                      cmap="Greys", vmin=0, vmax=4, interpolation="nearest", zorder=0)
        if len(P):
            colour = {"c": w, "cmap": "viridis"} if w is not None else {"color": "C0"}
            sc = ax.scatter(P[:, 0], P[:, 1], s=0.6, alpha=0.6, linewidths=0, zorder=1,
                            rasterized=True, **colour)
            if w is not None:
                plt.colorbar(sc, ax=ax, label="manipulability", shrink=0.8)
        if show_boundary and len(P):
            for k, line in enumerate(ws.boundary()):
                ax.plot(line[:, 0], line[:, 1], color="C3", lw=1.2, zorder=2,
                        label="boundary" if k == 0 else None)
        ax.set_aspect("equal")
        ax.set_xlabel("x [m]")
        ax.set_ylabel("y [m]")
    else:
        if len(P):
            # colour by manipulability, or by height for depth
            colour = w if w is not None else P[:, 2]
            sc = ax.scatter(P[:, 0], P[:, 1], P[:, 2], s=2.0, alpha=0.5, linewidths=0,
                            c=colour, cmap="viridis", rasterized=True)
            plt.colorbar(sc, ax=ax, label="manipulability" if w is not None else "z [m]",
                         shrink=0.6, pad=0.12)
            lo, hi = P.min(axis=0), P.max(axis=0)
            c, r = (lo + hi) / 2, (hi - lo).max() / 2
            ax.set_xlim(c[0] - r, c[0] + r)
            ax.set_ylim(c[1] - r, c[1] + r)
            ax.set_zlim(c[2] - r, c[2] + r)
            ax.set_box_aspect((1, 1, 1))
        ax.set_xlabel("x [m]")
        ax.set_ylabel("y [m]")
        ax.set_zlabel("z [m]")
    if robot is not None:
        from serialkin.viz.plot import plot_robot

        plot_robot(robot, np.zeros(robot.n) if q is None else q, ax=ax, color="k")
    ax.set_title(title if title is not None else
                 f"{ws.robot_name}: {_TITLES.get(ws.kind, ws.kind)}\n"
                 f"{_measure_label(ws.estimate)}", fontsize=10)
    return ax


def plot_manipulability_map(ws: Workspace, ax: Any = None, *, title: str | None = None) -> Any:
    """Per-cell maximum manipulability over the workspace (eq 43), as an image.

    Planar: the xy grid. Spatial: the maximum over z of each (x, y) column (top view).
    Requires a workspace computed with ``manipulability=True`` (or a dexterous one).
    """
    import matplotlib.pyplot as plt

    W = ws.manipulability_map()
    g = ws.grid
    if not ws.planar:
        with np.errstate(all="ignore"):
            W = np.where(np.all(np.isnan(W), axis=2), np.nan,
                         np.nanmax(np.where(np.isnan(W), -np.inf, W), axis=2))
    if ax is None:
        _, ax = plt.subplots(figsize=(6.4, 5.2))
    ext = (g.lower[0], g.upper[0], g.lower[1], g.upper[1])
    im = ax.imshow(W.T, origin="lower", extent=ext, cmap="magma", interpolation="nearest")
    plt.colorbar(im, ax=ax, label="manipulability w = sqrt(det J Jᵀ)", shrink=0.8)
    ax.set_aspect("equal")
    ax.set_xlabel("x [m]")
    ax.set_ylabel("y [m]")
    task = ws.params.get("manipulability_task") or ""
    view = "" if ws.planar else ", max over z"
    ax.set_title(title if title is not None else
                 f"{ws.robot_name}: manipulability map ({task} task{view})", fontsize=10)
    return ax


def plot_slice(ws: Workspace | WorkspaceSlice, axis: str = "z", value: float = 0.0,
               ax: Any = None, *, thickness: float | None = None, max_points: int = 30_000,
               title: str | None = None) -> Any:
    """A planar slice of a 3D workspace: samples in the slab, boundary and area ± error."""
    import matplotlib.pyplot as plt

    sl = ws if isinstance(ws, WorkspaceSlice) else workspace_slice(ws, axis, value, thickness)
    if ax is None:
        _, ax = plt.subplots(figsize=(6.0, 5.2))
    idx = _subsample(sl.points.shape[0], max_points, 0)
    P = sl.points[idx]
    if len(P):
        ax.scatter(P[:, 0], P[:, 1], s=1.0, color="C0", alpha=0.5, linewidths=0,
                   rasterized=True)
        for k, line in enumerate(sl.boundary()):
            ax.plot(line[:, 0], line[:, 1], color="C3", lw=1.2,
                    label="boundary" if k == 0 else None)
    ax.set_aspect("equal")
    ax.set_xlabel(f"{sl.axes[0]} [m]")
    ax.set_ylabel(f"{sl.axes[1]} [m]")
    name = ws.robot_name if isinstance(ws, Workspace) else ""
    ax.set_title(title if title is not None else
                 f"{name} slice {sl.axis} = {sl.value:.3g} m (±{sl.thickness / 2:.2g} m)\n"
                 f"{_measure_label(sl.estimate)}", fontsize=10)
    return ax


def plot_workspace_kinds(workspaces: Sequence[Workspace], ax: Any = None, *,
                         labels: Sequence[str] | None = None, title: str | None = None) -> Any:
    """Overlay the boundaries of several planar workspaces (e.g. the kinds of one robot)."""
    import matplotlib.pyplot as plt

    if any(not w.planar for w in workspaces):
        raise InputError("plot_workspace_kinds draws planar workspaces; slice 3D ones first")
    if ax is None:
        _, ax = plt.subplots(figsize=(6.4, 5.6))
    for i, ws in enumerate(workspaces):
        lab = labels[i] if labels is not None else _TITLES.get(ws.kind, ws.kind)
        g = ws.grid
        if ws.points.shape[0]:
            ext = (g.lower[0], g.upper[0], g.lower[1], g.upper[1])
            ax.imshow(np.where(g.occupied.T, 1.0, np.nan), origin="lower", extent=ext,
                      cmap="Blues" if i % 2 == 0 else "Oranges", vmin=0, vmax=3 + i,
                      alpha=0.45, interpolation="nearest")
            for k, line in enumerate(ws.boundary()):
                ax.plot(line[:, 0], line[:, 1], color=f"C{i}", lw=1.3,
                        label=f"{lab}: {_measure_label(ws.estimate)}" if k == 0 else None)
        else:
            ax.plot([], [], color=f"C{i}", label=f"{lab}: empty")
    ax.set_aspect("equal")
    ax.set_xlabel("x [m]")
    ax.set_ylabel("y [m]")
    # below the axes: a legend must never cover the workspaces it describes
    ax.legend(fontsize=8, loc="upper center", bbox_to_anchor=(0.5, -0.16), ncol=1)
    if title:
        ax.set_title(title, fontsize=10)
    return ax
