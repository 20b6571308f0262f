"""Figures of a tracked path: joint trajectories, tracking error, clearance and motion.

- :func:`plot_joint_trajectories` — every joint over the path (the chapter's Figure 9,
  "variations of joint angles"), with the joint limits dashed.
- :func:`plot_tracking_error` — the task-error norm ``‖x_d − x‖`` per path point against the
  tolerance (the chapter's ±5 mm).
- :func:`plot_clearance` — the clearance of the arm to every obstacle per path point
  (eqs 51-53: distance from the closest link point to the obstacle surface), zero marked.
- :func:`plot_motion` — a stroboscopic picture of the arm along the path with the target
  path and obstacles (Figures 8, 11 and 12).
- :func:`tracking_figure` — the first three (and the motion) in one figure.

Every function takes plain arrays or a :class:`serialkin.tracking.Trajectory`-like object
(duck-typed: ``q``, ``errors``, ``tolerance``, ``clearance``, ``obstacle_names``,
``joint_names``, ``positions``, ``targets``). matplotlib is imported lazily.
"""

from __future__ import annotations

from collections.abc import Iterable, Sequence
from typing import TYPE_CHECKING, Any

import numpy as np

from serialkin._checks import as_float_array, check_choice, check_int
from serialkin.errors import InputError
from serialkin.viz.plot import (
    is_3d_axes,
    plot_obstacles,
    plot_path,
    plot_robot,
    robot_points,
)

if TYPE_CHECKING:
    from matplotlib.axes import Axes
    from matplotlib.figure import Figure

    from serialkin.model.robot import Robot

__all__ = [
    "clearance_along",
    "plot_clearance",
    "plot_joint_trajectories",
    "plot_motion",
    "plot_tracking_error",
    "tracking_figure",
]

_UNITS = {"m": 1.0, "mm": 1e3, "cm": 1e2}


def _new_axes(figsize: tuple[float, float] = (7.0, 4.0)) -> Axes:
    import matplotlib.pyplot as plt

    return plt.figure(figsize=figsize).add_subplot()


def _x_axis(t: object, p: int) -> tuple[np.ndarray, str]:
    """The x values (p,) and their label: ``t`` when given, else the path-point index."""
    if t is None:
        return np.arange(p, dtype=float), "path point"
    x = as_float_array(t, "t", ndim=1)
    if x.shape[0] != p:
        raise InputError(f"t must have {p} values (one per path point), got {x.shape[0]}")
    return x, "t"


def _colours(k: int) -> list[Any]:
    import matplotlib as mpl

    if k <= 10:
        return [f"C{i}" for i in range(k)]
    cmap = mpl.colormaps["viridis"]
    return [cmap(i / max(k - 1, 1)) for i in range(k)]


# ---------------------------------------------------------------------- joints (Figure 9)
def plot_joint_trajectories(
    q: object,
    t: object = None,
    ax: Any = None,
    *,
    robot: Robot | None = None,
    joint_names: Sequence[str] | None = None,
    degrees: bool = True,
    limits: bool = True,
    xlabel: str | None = None,
    title: str | None = "Joint variables along the path",
) -> Axes:
    """Plot every joint variable over the path (Figure 9, "variations of joint angles").

    Args:
        q: (p, n) joint values [rad / m], or a trajectory object with ``q``.
        t: (p,) x values (e.g. time [s] or path parameter); default the path-point index.
        ax: axes to draw into (new figure when None).
        robot: gives joint types (only revolute joints are converted to degrees), names
            and limits.
        joint_names: legend labels (default the robot's or the trajectory's, else q1..qn).
        degrees: show revolute joints in degrees.
        limits: draw the finite joint limits as dashed lines (needs ``robot``).
        xlabel: x-axis label (default "path point" or "t").
        title: axes title (None for none).

    Returns:
        The axes; joint i's line has ``gid='serialkin-joint-<i>'`` and holds the values
        as plotted (degrees for revolute joints when ``degrees``). More than 10 joints get
        a colour bar (viridis, joint index) instead of a legend.
    """
    Q, names = _joint_values(q, robot, joint_names)
    p, n = Q.shape
    types = robot.joint_types if robot is not None else ("R",) * n
    x, default_xlabel = _x_axis(t, p)
    ax = ax if ax is not None else _new_axes()
    colours = _colours(n)
    scale = np.array([np.degrees(1.0) if (degrees and k == "R") else 1.0 for k in types])
    for i in range(n):
        ax.plot(x, Q[:, i] * scale[i], color=colours[i], lw=1.4, label=names[i],
                gid=f"serialkin-joint-{i}")
    if limits and robot is not None:
        _draw_joint_limits(ax, robot.qlim, scale, colours)
    ax.set_xlabel(xlabel or default_xlabel)
    ax.set_ylabel(_joint_ylabel(types, degrees))
    if title:
        ax.set_title(title)
    ax.grid(True, alpha=0.3)
    if p > 1:
        ax.set_xlim(x[0], x[-1])
    _joint_key(ax, n)
    return ax


def _joint_values(q: object, robot: Robot | None,
                  joint_names: Sequence[str] | None) -> tuple[np.ndarray, list[str]]:
    """The (p, n) joint values and the n names: given, the trajectory's, the robot's or q1..qn."""
    names = joint_names
    if hasattr(q, "q"):
        names = names or tuple(getattr(q, "joint_names", ()) or ()) or None
        q = q.q
    Q = as_float_array(q, "q", ndim=2)
    n = Q.shape[1]
    if robot is not None and robot.n != n:
        raise InputError(f"q has {n} columns but robot {robot.name!r} has {robot.n} joints")
    names = list(names or (robot.joint_names if robot is not None else
                           [f"q{i + 1}" for i in range(n)]))
    if len(names) != n:
        raise InputError(f"joint_names must have {n} names, got {len(names)}")
    return Q, names


def _draw_joint_limits(ax: Any, qlim: np.ndarray, scale: np.ndarray,
                       colours: list[Any]) -> None:
    """Dashed lines at the finite limits (n, 2) × ``scale``, each value (and colour) once.

    Up to 10 joints the lines take their joint's colour; beyond, one grey.
    """
    n = len(colours)
    seen: set[tuple[float, Any]] = set()
    for i in range(n):
        for v in qlim[i]:
            if not np.isfinite(v):
                continue
            key = (round(float(v * scale[i]), 12), colours[i] if n <= 10 else None)
            if key in seen:
                continue
            seen.add(key)
            ax.axhline(v * scale[i], color=colours[i] if n <= 10 else "0.4", ls="--",
                       lw=0.9, alpha=0.8, gid="serialkin-limit")


def _joint_ylabel(types: Sequence[str], degrees: bool) -> str:
    """The y-axis label naming the units of the joint types drawn."""
    has_p = "P" in types
    if degrees and not has_p:
        return "joint angle [deg]"
    if degrees:
        return "joint value [deg (R), m (P)]"
    return "joint value [rad (R), m (P)]" if has_p else "joint angle [rad]"


def _joint_key(ax: Any, n: int) -> None:
    """A legend right of the axes for up to 10 joints, else a colour bar of the joint index."""
    import matplotlib as mpl

    if n <= 10:
        outside_legend(ax, ncol=2 if n > 5 else 1)
        return
    norm = mpl.colors.Normalize(vmin=1, vmax=n)
    sm = mpl.cm.ScalarMappable(norm=norm, cmap="viridis")
    bar = ax.figure.colorbar(sm, ax=ax, label="joint index")
    bar.set_ticks(joint_index_ticks(n))


def joint_index_ticks(n: int) -> list[int]:
    """Integer colour-bar ticks for joints 1..n: 1, the multiples of a round step, n."""
    step = 1 if n <= 10 else 5 if n <= 50 else 10 * int(np.ceil(n / 100))
    ticks = sorted({1, n, *range(step, n + 1, step)})
    return [t for t in ticks if t == n or n - t >= step / 2 or t == 1]


def outside_legend(ax: Any, **options: Any) -> Any:
    """Put the legend to the right of the axes, so it never covers data; returns it."""
    handles, _ = ax.get_legend_handles_labels()
    if not handles:
        return None
    kw = {"loc": "upper left", "bbox_to_anchor": (1.02, 1.0), "fontsize": "small",
          "borderaxespad": 0.0}
    kw.update(options)
    return ax.legend(**kw)


# ---------------------------------------------------------------------- tracking error
def plot_tracking_error(
    errors: object = None,
    t: object = None,
    ax: Any = None,
    *,
    target: object = None,
    actual: object = None,
    tolerance: float | None = None,
    unit: str = "mm",
    log: bool | None = None,
    label: str | None = None,
    title: str | None = "Tracking error",
) -> Axes:
    """Plot the tracking-error norm ``e_k = ‖x_d,k − x_k‖`` per path point.

    Give either ``errors`` ((p,) norms [m], or a trajectory object with ``errors`` and
    ``tolerance``) or both ``target`` and ``actual`` ((p, m) task coordinates [m]).

    Args:
        errors: (p,) error norms [m] or a trajectory object.
        t: (p,) x values; default the path-point index.
        ax: axes (new figure when None).
        target: (p, m) desired task coordinates [m].
        actual: (p, m) reached task coordinates [m].
        tolerance: acceptance tolerance [m], drawn as a dashed line; points above it are
            marked with red crosses. Default the trajectory's tolerance, if any.
        unit: 'mm', 'cm' or 'm' for the y axis.
        log: logarithmic y axis; None chooses it when every error is below 1/20 of the
            tolerance (a linear axis would show a flat line at zero).
        label: legend label of the error line.
        title: axes title.

    Returns:
        The axes; the error line has ``gid='serialkin-error'`` (values in ``unit``).
    """
    check_choice(unit, "unit", _UNITS)
    k = _UNITS[unit]
    if errors is not None and hasattr(errors, "errors"):
        if tolerance is None:
            tolerance = getattr(errors, "tolerance", None)
        errors = errors.errors
    if errors is None:
        if target is None or actual is None:
            raise InputError("give errors, or both target and actual")
        A = as_float_array(target, "target")
        B = as_float_array(actual, "actual")
        if A.shape != B.shape or A.ndim != 2:
            raise InputError(f"target and actual must both have shape (p, m), got {A.shape} "
                             f"and {B.shape}")
        e = np.linalg.norm(B - A, axis=1)
    else:
        if target is not None or actual is not None:
            raise InputError("give errors or target/actual, not both")
        e = as_float_array(errors, "errors", ndim=1)
    x, default_xlabel = _x_axis(t, e.shape[0])
    ax = ax if ax is not None else _new_axes()
    ax.plot(x, e * k, "-", color="C0", lw=1.4, marker="." if e.shape[0] <= 200 else None,
            label=label or "‖x_d − x‖", gid="serialkin-error")
    if tolerance is not None:
        tol = float(tolerance)
        ax.axhline(tol * k, color="C3", ls="--", lw=1.0, label=f"tolerance {tol * k:g} {unit}",
                   gid="serialkin-tolerance")
        bad = e > tol
        if bad.any():
            ax.plot(x[bad], e[bad] * k, "x", color="C3", ms=6, label="not reached",
                    gid="serialkin-unreached")
    if log is None:
        log = bool(tolerance is not None and e.size and e.max() < float(tolerance) / 20
                   and e.max() > 0)
    if log:
        ax.set_yscale("log")
    else:
        ax.set_ylim(bottom=0.0)
    ax.set_xlabel(default_xlabel)
    ax.set_ylabel(f"tracking error [{unit}]")
    if title:
        ax.set_title(title)
    ax.grid(True, alpha=0.3)
    ax.legend(loc="best", fontsize="small")
    return ax


# ---------------------------------------------------------------------- clearance
def clearance_along(robot: Robot, q: object, obstacles: Sequence[object], *,
                    link_radius: float = 0.0) -> np.ndarray:
    """Clearance of the arm to every obstacle at every configuration, shape (p, k) [m].

    The minimum over the link segments of the signed distance from the link (a capsule of
    ``link_radius``) to the obstacle surface (eqs 51-53 with the ERRATA's clamped
    projection), from :func:`serialkin.redundancy.obstacles.clearances`.

    Args:
        robot: the robot.
        q: (p, n) configurations.
        obstacles: obstacles of :mod:`serialkin.redundancy.obstacles` (or their dicts).
        link_radius: link thickness [m].
    """
    from serialkin.redundancy import obstacles as obs_mod

    obs = [o if not isinstance(o, dict) else obs_mod.obstacle_from_dict(o, f"obstacles[{i}]")
           for i, o in enumerate(obstacles)]
    Q = robot.check_q(q)
    if Q.ndim != 2:
        raise InputError(f"q must have shape (p, {robot.n}), got {Q.shape}")
    out = np.empty((Q.shape[0], len(obs)))
    for j, qj in enumerate(Q):
        out[j] = obs_mod.clearances(robot, qj, obs, link_radius=link_radius).min(axis=0)
    return out


def plot_clearance(
    clearance: object,
    t: object = None,
    ax: Any = None,
    *,
    names: Sequence[str] | None = None,
    influence: float | Sequence[float] | None = None,
    unit: str = "mm",
    title: str | None = "Clearance to obstacles",
) -> Axes:
    """Plot the clearance to every obstacle per path point; below zero is a collision.

    Args:
        clearance: (p, k) clearance [m] per obstacle (e.g. :func:`clearance_along`), (p,)
            for one obstacle, or a trajectory object with ``clearance`` and
            ``obstacle_names``.
        t: (p,) x values; default the path-point index.
        ax: axes (new figure when None).
        names: obstacle labels (default "obstacle 1".. or the trajectory's names).
        influence: distance(s) of influence [m], drawn dotted (Figure 10).
        unit: 'mm', 'cm' or 'm'.
        title: axes title.

    Returns:
        The axes; obstacle j's line has ``gid='serialkin-clearance-<j>'``, the zero line
        ``'serialkin-contact'``.
    """
    check_choice(unit, "unit", _UNITS)
    k = _UNITS[unit]
    if hasattr(clearance, "clearance"):
        names = names or tuple(getattr(clearance, "obstacle_names", ()) or ()) or None
        clearance = clearance.clearance
    C = as_float_array(clearance, "clearance")
    if C.ndim == 1:
        C = C[:, None]
    if C.ndim != 2:
        raise InputError(f"clearance must have shape (p,) or (p, k), got {C.shape}")
    p, m = C.shape
    if m == 0:
        raise InputError("clearance has no obstacle columns (the path had no obstacles)")
    labels = list(names) if names else [f"obstacle {j + 1}" for j in range(m)]
    labels = [s or f"obstacle {j + 1}" for j, s in enumerate(labels)]
    if len(labels) != m:
        raise InputError(f"names must have {m} labels, got {len(labels)}")
    x, default_xlabel = _x_axis(t, p)
    ax = ax if ax is not None else _new_axes()
    colours = _colours(m)
    for j in range(m):
        ax.plot(x, C[:, j] * k, color=colours[j], lw=1.4, label=labels[j],
                gid=f"serialkin-clearance-{j}")
    ax.axhline(0.0, color="k", lw=1.2, label="contact", gid="serialkin-contact")
    lo = min(float(C.min()) * k, 0.0)
    ax.axhspan(lo - abs(lo) * 0.1 - 1e-12, 0.0, color="k", alpha=0.06)
    if influence is not None:
        dists = np.broadcast_to(np.asarray(influence, dtype=float), (m,))
        for j, d in enumerate(np.unique(dists)):
            ax.axhline(d * k, color="0.4", ls=":", lw=1.0,
                       label="influence distance" if j == 0 else None,
                       gid="serialkin-influence")
    ax.set_xlabel(default_xlabel)
    ax.set_ylabel(f"clearance [{unit}]")
    if title:
        ax.set_title(title)
    ax.grid(True, alpha=0.3)
    outside_legend(ax)
    return ax


# ---------------------------------------------------------------------- motion (Figs 8, 11, 12)
def plot_motion(
    robot: Robot,
    q: object,
    ax: Any = None,
    *,
    every: int | None = None,
    path_points: object = None,
    obstacles: Iterable[object] | None = None,
    trace: bool = True,
    planar: bool | None = None,
    cmap: str = "Blues",
    title: str | None = None,
    q0: object = None,
    influence: bool | float = False,
    labels: bool = False,
) -> Axes:
    """Draw the arm at configurations along the path, fading from light to dark.

    The chapter's Figures 8, 11 and 12: the robot at every ``every``-th configuration (and
    the last), the target path in green, the end-effector trace and the obstacles.

    Args:
        robot: the robot.
        q: (p, n) configurations, or a trajectory object with ``q``.
        ax: axes (new figure when None; 2D for planar robots).
        every: draw every ``every``-th configuration (default: about 12 poses).
        path_points: (k, 2|3) target path [m].
        obstacles: obstacles (see :func:`serialkin.viz.plot.as_obstacle`).
        trace: draw the end-effector trace (orange).
        planar: force 2D/3D (see :func:`serialkin.viz.plot.plot_robot`).
        cmap: colormap for the arm poses (first light, last dark).
        title: axes title.
        q0: start configuration (n,) before the first path point, drawn dashed in
            orange-red and labelled "start pose q0" (None: not drawn).
        influence: draw the obstacles' influence zones (see
            :func:`~serialkin.viz.plot.plot_obstacles`).
        labels: write the obstacles' names at their centres.

    Returns:
        The axes; the legend (path, trace, start pose) sits right of the axes.
    """
    import matplotlib as mpl

    if hasattr(q, "q"):
        if path_points is None and hasattr(q, "targets"):
            path_points = np.asarray(q.targets)[:, :3, 3]
        q = q.q
    Q = robot.check_q(q, "q")
    if Q.ndim != 2 or Q.shape[0] == 0:
        raise InputError(f"q must have shape (p, {robot.n}) with p >= 1, got {Q.shape}")
    idx = _pose_indices(Q.shape[0], every)
    colours = mpl.colormaps[cmap](np.linspace(0.35, 1.0, len(idx)))
    for j, k in enumerate(idx):
        last = j == len(idx) - 1
        ax = plot_robot(robot, Q[k], ax, planar=planar, color=colours[j],
                        linewidth=2.2 if last else 1.1, markersize=5.0 if last else 2.5,
                        alpha=0.9)
    if q0 is not None:
        start = robot_points(robot, robot.check_q(q0, "q0"))
        _plot_points(ax, start, "--o", color="tab:red", lw=1.4, ms=2.5,
                     label="start pose q0", gid="serialkin-start")
    if obstacles is not None:
        plot_obstacles(ax, obstacles, influence=influence, labels=labels)
    if path_points is not None:
        plot_path(ax, path_points, linewidth=3.0)
    if trace:
        _plot_points(ax, robot_points(robot, Q)[:, -1, :], "-", color="tab:orange", lw=1.0,
                     label="end-effector trace", gid="serialkin-trace")
    if title:
        ax.set_title(title)
    if path_points is not None or trace or q0 is not None:
        outside_legend(ax)
    return ax


def _pose_indices(p: int, every: int | None) -> list[int]:
    """Indices of the poses drawn: every ``every``-th of ``p`` (default about 12), and the last."""
    step = max(1, p // 12) if every is None else check_int(every, "every", minimum=1)
    idx = list(range(0, p, step))
    if idx[-1] != p - 1:
        idx.append(p - 1)
    return idx


def _plot_points(ax: Any, P: np.ndarray, fmt: str, **style: Any) -> None:
    """Draw the points ``P`` (k, 3) [m] as a line: x, y, z on 3D axes, x, y on 2D axes."""
    if is_3d_axes(ax):
        ax.plot(P[:, 0], P[:, 1], P[:, 2], fmt, **style)
    else:
        ax.plot(P[:, 0], P[:, 1], fmt, **style)


# ---------------------------------------------------------------------- all together
def tracking_figure(
    trajectory: Any,
    robot: Robot | None = None,
    *,
    obstacles: Iterable[object] | None = None,
    title: str | None = None,
) -> Figure:
    """One figure summarising a tracked path.

    Panels: the motion (:func:`plot_motion`, when ``robot`` is given), the joint variables
    (:func:`plot_joint_trajectories`), the tracking error (:func:`plot_tracking_error`)
    and, when the trajectory has obstacle clearances, :func:`plot_clearance`.

    Args:
        trajectory: a trajectory object (``q``, ``errors``, ``tolerance``, ``clearance``,
            ``targets``...).
        robot: the robot (for the motion panel, joint types and limits).
        obstacles: obstacles to draw in the motion panel.
        title: figure title.

    Returns:
        The matplotlib figure.
    """
    import matplotlib.pyplot as plt

    clearance = np.asarray(getattr(trajectory, "clearance", np.empty((0, 0))))
    has_clear = clearance.ndim == 2 and clearance.shape[1] > 0 and clearance.shape[0] > 0
    panels = ["joints", "error"] + (["clearance"] if has_clear else [])
    motion = robot is not None
    ncols = 2
    nrows = (len(panels) + int(motion) + 1) // 2
    fig = plt.figure(figsize=(12.0, 4.2 * nrows))
    slot = 1
    if motion:
        three_d = not robot.is_planar
        ax = fig.add_subplot(nrows, ncols, slot, projection="3d" if three_d else None)
        plot_motion(robot, trajectory, ax, obstacles=obstacles, title="Motion along the path")
        slot += 1
    ax = fig.add_subplot(nrows, ncols, slot)
    plot_joint_trajectories(trajectory, ax=ax, robot=robot)
    slot += 1
    ax = fig.add_subplot(nrows, ncols, slot)
    plot_tracking_error(trajectory, ax=ax)
    slot += 1
    if has_clear:
        ax = fig.add_subplot(nrows, ncols, slot)
        plot_clearance(trajectory, ax=ax)
    if title:
        fig.suptitle(title)
    fig.tight_layout()
    return fig
