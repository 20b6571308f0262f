"""Figures of reachability maps and base placements (matplotlib, imported on use).

* :func:`point_layer` — positions (N, 3) and RGB colours (N, 3) of the reached voxels,
  coloured by reachability index: the data of a point-cloud layer for the HTML viewer
  (or any other renderer);
* :func:`plot_map_slice` — the index on a slice of the grid (x, y or z = value);
* :func:`plot_map_points` — a 3-D point cloud of the reached voxels coloured by index;
* :func:`plot_base_placement` — per floor cell, the fraction of headings from which the
  base reaches every task pose, with the best base pose marked.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from serialkin._checks import check_choice
from serialkin.reach.base import BasePlacement
from serialkin.reach.reachmap import ReachMap

_AXES = ("x", "y", "z")


def index_colours(index: np.ndarray, colormap: str = "viridis") -> np.ndarray:
    """RGB colours in [0, 1] of reachability indices in [0, 1], (..., 3)."""
    import matplotlib

    cmap = matplotlib.colormaps[colormap]
    return np.asarray(cmap(np.clip(np.asarray(index, dtype=float), 0.0, 1.0)))[..., :3]


def point_layer(reach_map: ReachMap, *, min_index: float = 0.0,
                colormap: str = "viridis") -> tuple[np.ndarray, np.ndarray]:
    """Reached voxel centres and their colours by index, for a point-cloud layer.

    Args:
        reach_map: the map.
        min_index: keep voxels whose index is > this (0: every reached voxel).
        colormap: a matplotlib colormap name.

    Returns:
        positions (N, 3) [m], colours (N, 3) RGB in [0, 1].
    """
    mask = reach_map.index > float(min_index)
    return reach_map.centres(mask), index_colours(reach_map.index[mask], colormap)


def plot_map_slice(reach_map: ReachMap, axis: str = "z", value: float = 0.0, ax: Any = None,
                   *, title: str | None = None) -> Any:
    """The reachability index on the grid layer nearest ``axis = value`` [m].

    Returns:
        The axes (a new figure when ``ax`` is None).
    """
    import matplotlib.pyplot as plt

    axis = check_choice(axis, "axis", _AXES)
    a = _AXES.index(axis)
    g = reach_map.grid
    centres = g.axes()[a]
    k = int(np.argmin(np.abs(centres - float(value))))
    layer = np.take(reach_map.index, k, axis=a)
    u, v = [b for b in range(3) if b != a]
    if ax is None:
        _, ax = plt.subplots(figsize=(6.0, 5.0))
    lo = np.asarray(g.lower)
    ext = [lo[u], lo[u] + g.shape[u] * g.resolution, lo[v], lo[v] + g.shape[v] * g.resolution]
    im = ax.imshow(layer.T, origin="lower", extent=ext, vmin=0.0, vmax=1.0, cmap="viridis",
                   interpolation="nearest")
    ax.figure.colorbar(im, ax=ax, label="reachability index")
    ax.set_xlabel(f"{_AXES[u]} [m]")
    ax.set_ylabel(f"{_AXES[v]} [m]")
    ax.set_aspect("equal")
    name = reach_map.settings.get("robot", "")
    ax.set_title(title if title is not None else
                 f"{name} reachability, {axis} = {centres[k]:.3g} m "
                 f"({reach_map.orientations} orientations)", fontsize=10)
    return ax


def plot_map_points(reach_map: ReachMap, ax: Any = None, *, min_index: float = 0.0,
                    title: str | None = None) -> Any:
    """3-D point cloud of the reached voxels coloured by reachability index.

    Returns:
        The 3-D axes (a new figure when ``ax`` is None).
    """
    import matplotlib.pyplot as plt

    P, C = point_layer(reach_map, min_index=min_index)
    if ax is None:
        fig = plt.figure(figsize=(6.5, 5.5))
        ax = fig.add_subplot(projection="3d")
    ax.scatter(P[:, 0], P[:, 1], P[:, 2], c=C, s=4.0, depthshade=False, linewidths=0)
    for lab, f in zip(("x", "y", "z"), (ax.set_xlabel, ax.set_ylabel, ax.set_zlabel)):
        f(f"{lab} [m]")
    sm = plt.cm.ScalarMappable(cmap="viridis", norm=plt.Normalize(0.0, 1.0))
    ax.figure.colorbar(sm, ax=ax, label="reachability index", shrink=0.7)
    name = reach_map.settings.get("robot", "")
    ax.set_title(title if title is not None else
                 f"{name}: {P.shape[0]} reached voxels of {reach_map.grid.size}", fontsize=10)
    return ax


def plot_base_placement(placement: BasePlacement, ax: Any = None, *,
                        tasks: object = None, title: str | None = None) -> Any:
    """Floor map of the fraction of headings that reach every task, best base marked.

    Args:
        placement: the result of :func:`serialkin.reach.base_placement`.
        ax: axes (a new figure when None).
        tasks: optionally the (M, 4, 4) task poses, drawn as crosses.
        title: axes title.

    Returns:
        The axes.
    """
    import matplotlib.pyplot as plt

    if ax is None:
        _, ax = plt.subplots(figsize=(6.0, 5.0))
    xs, ys = placement.xs, placement.ys
    h = float(xs[1] - xs[0]) if xs.size > 1 else 1.0
    k = float(ys[1] - ys[0]) if ys.size > 1 else 1.0
    im = ax.imshow(placement.feasible_fraction.T, origin="lower", vmin=0.0, vmax=1.0,
                   extent=[xs[0] - h / 2, xs[-1] + h / 2, ys[0] - k / 2, ys[-1] + k / 2],
                   cmap="viridis", interpolation="nearest")
    ax.figure.colorbar(im, ax=ax, label="fraction of headings reaching every task")
    B = placement.best
    ax.plot(B[0, 3], B[1, 3], "r*", ms=14, label="best base")
    ax.arrow(B[0, 3], B[1, 3], 0.2 * B[0, 0], 0.2 * B[1, 0], color="r", width=0.005)
    if tasks is not None:
        T = np.asarray(tasks, dtype=float).reshape(-1, 4, 4)
        ax.plot(T[:, 0, 3], T[:, 1, 3], "wx", ms=8, label="task poses")
    ax.legend(loc="upper right", fontsize=8)
    ax.set_xlabel("x [m]")
    ax.set_ylabel("y [m]")
    ax.set_aspect("equal")
    ax.set_title(title if title is not None else
                 f"base placement: {int(placement.feasible.sum())} feasible of "
                 f"{placement.reached.size} candidates", fontsize=10)
    return ax
