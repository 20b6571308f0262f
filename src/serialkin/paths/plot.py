"""Figures of a timed joint trajectory: positions, velocities and accelerations against limits."""

from __future__ import annotations

from typing import Any

import numpy as np

from serialkin.paths.timing import TimedPath

__all__ = ["plot_timing"]


def plot_timing(timed: TimedPath, qlim: np.ndarray | None = None) -> Any:
    """Three panels against time [s]: q, q̇ and q̈ of every joint, their limits dashed.

    Args:
        timed: the trajectory (:func:`serialkin.paths.time_optimal`).
        qlim: (n, 2) joint position limits to draw (finite ones only), or None.

    Returns:
        The matplotlib Figure (the caller saves or shows it).
    """
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(3, 1, figsize=(8, 8), sharex=True, layout="constrained")
    names = timed.names()
    colors = plt.rcParams["axes.prop_cycle"].by_key()["color"]
    panels = ((timed.q, "position [rad]", qlim),
              (timed.qd, "velocity [rad/s]", np.column_stack([-timed.velocity,
                                                               timed.velocity])),
              (timed.qdd, "acceleration [rad/s²]", np.column_stack([-timed.acceleration,
                                                                    timed.acceleration])))
    for ax, (values, label, limits) in zip(axes, panels):
        for j in range(values.shape[1]):
            c = colors[j % len(colors)]
            ax.plot(timed.t, values[:, j], color=c, label=names[j])
            if limits is not None:
                for v in limits[j]:
                    if np.isfinite(v):
                        ax.axhline(v, color=c, linestyle="--", linewidth=0.7)
        ax.set_ylabel(label)
        ax.grid(True, alpha=0.3)
    axes[0].legend(ncol=min(7, len(names)), fontsize="small", loc="upper right")
    axes[-1].set_xlabel("time [s]")
    axes[0].set_title(f"time-optimal trajectory: {timed.duration:.3g} s (limits dashed)")
    return fig
