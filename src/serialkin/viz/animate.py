"""Animations of a trajectory: GIF (Pillow, always available) and MP4 (needs ffmpeg).

Each frame draws the robot at one configuration (as :func:`serialkin.viz.plot.plot_robot`:
link-frame origins and the tool point, eq 11), the target path in green, the obstacles,
the end-effector trace so far in orange and a "step k / p" label. The axes limits are fixed
from the whole trajectory so the view does not jump. GIF frames are blitted (the static
scene is rendered once, each frame redraws only the moving robot, trace and label) and
encoded by Pillow; MP4 frames are rendered by matplotlib's ``FFMpegWriter`` (H.264).

:func:`animate_trajectory` returns the encoded bytes (e.g. for
:meth:`serialkin.chapter.report.ReportContext.file_figure`); :func:`save_animation`
writes them to a file atomically (temporary file + rename).
"""

from __future__ import annotations

import io
import shutil
import tempfile
from collections.abc import Iterable
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from serialkin._checks import check_choice, check_int, check_positive
from serialkin._io import write_bytes_atomic
from serialkin.errors import InputError, NotSupportedError
from serialkin.viz.plot import (
    FRAMES_GID,
    JOINTS_GID,
    LINKS_GID,
    as_obstacle,
    is_3d_axes,
    joint_positions,
    plot_obstacles,
    plot_path,
    plot_robot,
    robot_points,
    robot_scale,
)

if TYPE_CHECKING:
    from serialkin.model.robot import Robot

__all__ = ["FORMATS", "animate_trajectory", "ffmpeg_available", "frame_indices", "save_animation"]

#: Output formats: file suffix -> matplotlib writer name.
FORMATS = {"gif": "pillow", "mp4": "ffmpeg"}


def ffmpeg_available() -> bool:
    """Return True when matplotlib can find ffmpeg (``animation.ffmpeg_path``, PATH)."""
    import matplotlib as mpl
    from matplotlib import animation

    exe = mpl.rcParams["animation.ffmpeg_path"]
    return shutil.which(exe) is not None and animation.writers.is_available("ffmpeg")


def frame_indices(p: int, max_frames: int | None) -> np.ndarray:
    """Return the indices of the configurations shown, at most ``max_frames`` of ``p``.

    All of them when ``p <= max_frames`` (or None), else ``max_frames`` evenly spread from
    the first to the last (both included when ``max_frames >= 2``).
    """
    if max_frames is None or p <= max_frames:
        return np.arange(p)
    return np.unique(np.round(np.linspace(0, p - 1, max_frames)).astype(int))


def animate_trajectory(
    robot: Robot,
    q: object,
    *,
    fmt: str = "gif",
    fps: float = 15.0,
    path_points: object = None,
    obstacles: Iterable[object] | None = None,
    planar: bool | None = None,
    frames: bool = False,
    trace: bool = True,
    max_frames: int | None = 300,
    title: str | None = None,
    dpi: int = 80,
    figsize: tuple[float, float] = (6.0, 5.0),
    progress: bool = False,
) -> bytes:
    """Render the robot moving along ``q`` and encode it as GIF or MP4 bytes.

    Args:
        robot: the robot.
        q: (p, n) configurations [rad / m], or a trajectory object with ``q`` (its
            ``targets`` then give the path when ``path_points`` is None).
        fmt: 'gif' (Pillow) or 'mp4' (ffmpeg, H.264).
        fps: frames per second.
        path_points: (k, 2|3) target path [m], drawn in green.
        obstacles: obstacles (see :func:`serialkin.viz.plot.as_obstacle`).
        planar: force 2D/3D drawing (default: 2D for planar robots).
        frames: draw the link frames as RGB triads.
        trace: draw the end-effector trace up to the current frame.
        max_frames: at most this many frames, evenly spread over the trajectory (first and
            last included); None for all.
        title: axes title.
        dpi: resolution of the frames (pixels per inch of ``figsize``).
        figsize: figure size [inch].
        progress: show a progress bar (tqdm) while rendering.

    Returns:
        The encoded animation; a GIF starts with ``b"GIF89a"``. It has one frame per shown
        configuration (see :func:`frame_indices`).

    Raises:
        InputError: bad configurations, unknown ``fmt``, non-positive ``fps``.
        NotSupportedError: ``fmt='mp4'`` but ffmpeg is not installed.
    """
    import matplotlib.pyplot as plt
    from matplotlib import animation

    check_choice(fmt, "fmt", FORMATS)
    fps = check_positive(fps, "fps")
    dpi = check_int(dpi, "dpi", minimum=10)
    if max_frames is not None:
        max_frames = check_int(max_frames, "max_frames", minimum=1)
    if fmt == "mp4" and not ffmpeg_available():
        raise NotSupportedError(
            "MP4 animations need ffmpeg on PATH (e.g. apt-get install ffmpeg); "
            "fmt='gif' works without it"
        )
    if hasattr(q, "q"):
        if path_points is None and getattr(q, "targets", None) is not None:
            path_points = np.asarray(q.targets)[:, :3, 3]
        q = q.q
    Q = robot.check_q(q, "q")
    if Q.ndim != 2 or Q.shape[0] == 0:
        raise InputError(f"q must have shape (p, {robot.n}) with p >= 1, got {Q.shape}")
    obs = [as_obstacle(o, f"obstacles[{i}]") for i, o in enumerate(obstacles or ())]
    idx = frame_indices(Q.shape[0], max_frames)
    Qs = Q[idx]
    P = robot_points(robot, Qs)  # (m, n+2, 3)
    J = joint_positions(robot, Qs)  # (m, n, 3)
    T_all = robot.fk_all(Qs) if frames else None
    T_tool = robot.fk(Qs) if frames else None

    fig = plt.figure(figsize=figsize, dpi=dpi)
    try:
        two_d = robot.is_planar if planar is None else bool(planar)
        ax = fig.add_subplot(projection=None if two_d else "3d")
        if obs:
            plot_obstacles(ax, obs)
        if path_points is not None:
            plot_path(ax, path_points, linewidth=2.5)
        plot_robot(robot, Qs[0], ax, frames=frames, planar=two_d)
        dims = 2 if two_d else 3
        tip = P[:, -1, :]
        trace_line = None
        if trace:
            (trace_line,) = ax.plot(*tip[:1, :dims].T, "-", color="tab:orange", lw=1.2,
                                    gid="serialkin-trace")
        _fix_limits(ax, robot, P, path_points, obs)
        if title:
            ax.set_title(title)
        if two_d:
            fig.tight_layout()
        label = (ax.text(0.02, 0.97, "", transform=ax.transAxes, va="top", fontsize=9)
                 if two_d else ax.text2D(0.02, 0.97, "", transform=ax.transAxes, va="top",
                                         fontsize=9))
        lines = {ln.get_gid(): ln for ln in ax.get_lines()}
        triads = [[ln for ln in ax.get_lines() if ln.get_gid() == f"{FRAMES_GID}-{i}"]
                  for i in range(robot.n + 2)] if frames else []
        size = 0.08 * robot_scale(robot)

        def _set(line: Any, pts: np.ndarray) -> None:
            if two_d:
                line.set_data(pts[:, 0], pts[:, 1])
            else:
                line.set_data_3d(pts[:, 0], pts[:, 1], pts[:, 2])

        def draw(k: int) -> list[Any]:
            _set(lines[LINKS_GID], P[k])
            _set(lines[JOINTS_GID], J[k])
            _set(lines["serialkin-tool"], P[k, -1:])
            if trace_line is not None:
                _set(trace_line, tip[: k + 1])
            for i, segs in enumerate(triads):
                T = T_all[k, i] if i <= robot.n else T_tool[k]  # type: ignore[index]
                axes_k = [c for c in range(3) if not (two_d and c == 2)]
                for seg, c in zip(segs, axes_k):
                    o = T[:3, 3]
                    _set(seg, np.vstack([o, o + size * T[:3, c]]))
            label.set_text(f"step {idx[k] + 1} / {Q.shape[0]}")
            return []

        bar = None
        callback = None
        if progress:
            from tqdm.auto import tqdm

            bar = tqdm(total=len(idx), desc=f"animation ({fmt})", unit="frame")

            def callback(i: int, n: int) -> None:
                bar.update(1)

        if fmt == "gif":
            moving = [lines[LINKS_GID], lines[JOINTS_GID], lines["serialkin-tool"], label]
            moving += ([trace_line] if trace_line is not None else [])
            moving += [seg for segs in triads for seg in segs]
            data = _gif_blitted(fig, ax, moving, draw, len(idx), fps, callback)
        else:
            anim = animation.FuncAnimation(fig, draw, frames=len(idx), blit=False,
                                           repeat=False, cache_frame_data=False)
            writer = animation.FFMpegWriter(fps=fps, codec="libx264",
                                            extra_args=["-pix_fmt", "yuv420p"])
            with tempfile.TemporaryDirectory(prefix="serialkin-anim-") as tmp:
                out = Path(tmp) / f"animation.{fmt}"
                anim.save(str(out), writer=writer, dpi=dpi, progress_callback=callback)
                data = out.read_bytes()
        if bar is not None:
            bar.close()
        return data
    finally:
        plt.close(fig)


def _gif_blitted(fig: Any, ax: Any, moving: list[Any], draw: Any, count: int, fps: float,
                 callback: Any = None) -> bytes:
    """Encode ``count`` frames as a GIF, redrawing only the ``moving`` artists per frame.

    The static scene (obstacles, path, axes) is rendered once; each frame restores it, lets
    ``draw(k)`` update the moving artists and draws just those (blitting), then keeps the
    RGBA pixels. Pillow writes the GIF (looping, ``1/fps`` s per frame).
    """
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from PIL import Image

    canvas = FigureCanvasAgg(fig)
    for artist in moving:
        artist.set_animated(True)
    canvas.draw()
    background = canvas.copy_from_bbox(fig.bbox)
    frames = []
    for k in range(count):
        canvas.restore_region(background)
        draw(k)
        for artist in moving:
            ax.draw_artist(artist)
        frames.append(Image.fromarray(np.asarray(canvas.buffer_rgba()).copy(), "RGBA"))
        if callback is not None:
            callback(k, count)
    buf = io.BytesIO()
    frames[0].save(buf, format="GIF", save_all=True, append_images=frames[1:],
                   duration=max(1, int(round(1000.0 / fps))), loop=0)
    return buf.getvalue()


def _fix_limits(ax: Any, robot: Robot, P: np.ndarray, path_points: object,
                obs: list[Any]) -> None:
    """Axis limits covering every frame, the path and the obstacles (equal scale)."""
    pts = [P.reshape(-1, 3)]
    if path_points is not None:
        pp = np.asarray(path_points, dtype=float)
        if pp.shape[1] == 2:
            pp = np.hstack([pp, np.zeros((pp.shape[0], 1))])
        pts.append(pp)
    pts.extend(o.extent_points() for o in obs)
    allp = np.vstack(pts)
    margin = 0.08 * robot_scale(robot)
    lo, hi = allp.min(axis=0) - margin, allp.max(axis=0) + margin
    if is_3d_axes(ax):
        centre = (lo + hi) / 2
        half = float((hi - lo).max()) / 2
        ax.set_xlim(centre[0] - half, centre[0] + half)
        ax.set_ylim(centre[1] - half, centre[1] + half)
        ax.set_zlim(centre[2] - half, centre[2] + half)
    else:
        ax.set_xlim(lo[0], hi[0])
        ax.set_ylim(lo[1], hi[1])
        ax.set_aspect("equal", adjustable="box")


def save_animation(robot: Robot, q: object, path: str | Path, **options: Any) -> Path:
    """Render an animation (see :func:`animate_trajectory`) and write it atomically.

    The format comes from the suffix of ``path`` ('.gif' or '.mp4'); ``options`` are
    passed on to :func:`animate_trajectory`.

    Returns:
        The path written.

    Raises:
        InputError: unknown suffix, or the folder cannot be written.
        NotSupportedError: '.mp4' without ffmpeg.
    """
    out = Path(path)
    fmt = out.suffix.lower().lstrip(".")
    if fmt not in FORMATS:
        raise InputError(f"path must end in .gif or .mp4, got {str(out)!r}")
    if "fmt" in options and options.pop("fmt") != fmt:
        raise InputError(f"fmt contradicts the suffix of {str(out)!r}")
    return write_bytes_atomic(out, animate_trajectory(robot, q, fmt=fmt, **options))
