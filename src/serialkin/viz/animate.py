"""Animations of a trajectory: GIF (Pillow, always available) and MP4 (needs ffmpeg).

Each frame draws the robot at one configuration (as :func:`serialkin.viz.plot.plot_robot`:
link-frame origins and the tool point, eq 11), the target path in green, the obstacles,
the end-effector trace so far in orange and a "step k / p" label. The axes limits are fixed
from the whole trajectory so the view does not jump. GIF frames are blitted (the static
scene is rendered once, each frame redraws only the moving robot, trace and label) and
encoded by Pillow; MP4 frames are rendered by matplotlib's ``FFMpegWriter`` (H.264).

:func:`animate_trajectory` returns the encoded bytes (e.g. for
:meth:`serialkin.chapter.report.ReportContext.file_figure`); :func:`save_animation`
writes them to a file atomically (temporary file + rename). Both take the frame rate,
frame count, size and what is drawn as one :class:`AnimationOptions`::

    save_animation(robot, Q, "arm.gif", AnimationOptions(fps=10, max_frames=40),
                   path_points=path)

These options given as keywords (``fps=10, max_frames=40``), the old form, still work for
one release and warn (:class:`DeprecationWarning`).
"""

from __future__ import annotations

import io
import shutil
import tempfile
import warnings
from collections.abc import Iterable, Sequence
from dataclasses import dataclass, fields
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from serialkin._checks import check_choice, check_int, check_positive, short_repr
from serialkin._io import write_bytes_atomic
from serialkin.errors import InputError, InputTypeError, NotSupportedError
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
from serialkin.viz.scene import _check_flag

if TYPE_CHECKING:
    from serialkin.model.robot import Robot

__all__ = [
    "FORMATS",
    "AnimationOptions",
    "animate_trajectory",
    "ffmpeg_available",
    "frame_indices",
    "save_animation",
]

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


@dataclass(frozen=True)
class AnimationOptions:
    """How :func:`animate_trajectory` draws and times an animation.

    Attributes:
        fps: frames per second (> 0).
        max_frames: at most this many frames, evenly spread over the trajectory (first and
            last included, see :func:`frame_indices`); None for all.
        planar: force 2D (True) or 3D (False) drawing; None: 2D for planar robots.
        frames: draw the link frames as RGB triads.
        trace: draw the end-effector trace up to the current frame.
        title: axes title (None for none).
        dpi: resolution of the frames (pixels per inch of ``figsize``, >= 10).
        figsize: figure size (width, height) [inch].
        progress: show a progress bar (tqdm) while rendering.

    Raises:
        InputTypeError: a flag that is not a bool, a title that is not a string, a
            non-integer ``dpi`` or ``max_frames``.
        InputError: non-positive ``fps`` or ``figsize``, ``dpi`` below 10, ``max_frames``
            below 1.
    """

    fps: float = 15.0
    max_frames: int | None = 300
    planar: bool | None = None
    frames: bool = False
    trace: bool = True
    title: str | None = None
    dpi: int = 80
    figsize: tuple[float, float] = (6.0, 5.0)
    progress: bool = False

    def __post_init__(self) -> None:
        def put(name: str, value: object) -> None:
            object.__setattr__(self, name, value)

        put("fps", check_positive(self.fps, "fps"))
        if self.max_frames is not None:
            put("max_frames", check_int(self.max_frames, "max_frames", minimum=1))
        if self.planar is not None:
            put("planar", _check_flag(self.planar, "planar", "True, False or None"))
        for name in ("frames", "trace", "progress"):
            put(name, _check_flag(getattr(self, name), name))
        if self.title is not None and not isinstance(self.title, str):
            raise InputTypeError(f"title must be a string or None, got "
                                 f"{type(self.title).__name__} {short_repr(self.title)}")
        put("dpi", check_int(self.dpi, "dpi", minimum=10))
        size = self.figsize
        if isinstance(size, (str, bytes)) or not isinstance(size, Sequence) or len(size) != 2:
            raise InputError(f"figsize must be (width, height) in inches, got "
                             f"{short_repr(size)}")
        put("figsize", (check_positive(size[0], "figsize[0]", maximum=1000.0),
                        check_positive(size[1], "figsize[1]", maximum=1000.0)))


def _resolve_options(func: str, options: object, old_keywords: dict[str, Any],
                     ) -> AnimationOptions:
    """The options of a call: given, or built from the deprecated keywords (with a warning)."""
    if old_keywords:
        names = [f.name for f in fields(AnimationOptions)]
        unknown = sorted(set(old_keywords) - set(names))
        if unknown:
            raise InputTypeError(f"{func}() got unknown argument(s) {', '.join(unknown)}; "
                                 f"expected AnimationOptions fields ({', '.join(names)})")
        if options is not None:
            raise InputTypeError(f"{func}() got options and also {', '.join(sorted(old_keywords))}"
                                 "; put them in the AnimationOptions")
        warnings.warn(f"{func}(robot, q, {', '.join(f'{k}=...' for k in old_keywords)}) is "
                      "deprecated and will be removed in the next release; call "
                      f"{func}(robot, q, AnimationOptions(...), path_points=..., "
                      "obstacles=...)", DeprecationWarning, stacklevel=3)
        return AnimationOptions(**old_keywords)
    if options is None:
        return AnimationOptions()
    if not isinstance(options, AnimationOptions):
        raise InputTypeError(f"options must be an AnimationOptions or None, got "
                             f"{type(options).__name__} {short_repr(options)}")
    return options


def animate_trajectory(
    robot: Robot,
    q: object,
    options: AnimationOptions | None = None,
    *,
    fmt: str = "gif",
    path_points: object = None,
    obstacles: Iterable[object] | None = None,
    **old_keywords: Any,
) -> bytes:
    """Render the robot moving along ``q`` and encode it as GIF or MP4 bytes.

    Example::

        gif = animate_trajectory(robot, Q, AnimationOptions(fps=10, max_frames=40),
                                 path_points=path)

    Args:
        robot: the robot.
        q: (p, n) configurations [rad / m], or a trajectory object with ``q`` (its
            ``targets`` then give the path when ``path_points`` is None).
        options: frame rate, frame count, size and what is drawn (None: the defaults).
        fmt: 'gif' (Pillow) or 'mp4' (ffmpeg, H.264).
        path_points: (k, 2|3) target path [m], drawn in green.
        obstacles: obstacles (see :func:`serialkin.viz.plot.as_obstacle`).
        **old_keywords: deprecated: the fields of :class:`AnimationOptions` as keywords
            (``fps=``, ``dpi=``...); they build the options and a
            :class:`DeprecationWarning` names the new form. Removed in the next release.

    Returns:
        The encoded animation; a GIF starts with ``b"GIF89a"``. It has one frame per shown
        configuration (see :func:`frame_indices`).

    Raises:
        InputError: bad configurations, unknown ``fmt``; in the old form, what
            :class:`AnimationOptions` raises.
        InputTypeError: ``options`` is not an AnimationOptions, unknown old keywords.
        NotSupportedError: ``fmt='mp4'`` but ffmpeg is not installed.
    """
    options = _resolve_options("animate_trajectory", options, old_keywords)
    return _render(robot, q, options, fmt, path_points, obstacles)


def _configurations(robot: Robot, q: object, path_points: object,
                    ) -> tuple[np.ndarray, object]:
    """The (p, n) configurations and the path: a trajectory object's targets by default."""
    if hasattr(q, "q"):
        if path_points is None and getattr(q, "targets", None) is not None:
            path_points = np.asarray(q.targets)[:, :3, 3]
        q = q.q
    Q = robot.check_q(q, "q")
    if Q.ndim != 2 or Q.shape[0] == 0:
        raise InputError(f"q must have shape (p, {robot.n}) with p >= 1, got {Q.shape}")
    return Q, path_points


def _render(robot: Robot, q: object, options: AnimationOptions, fmt: str,
            path_points: object, obstacles: Iterable[object] | None) -> bytes:
    """Draw the frames of :func:`animate_trajectory` and encode them."""
    import matplotlib.pyplot as plt

    check_choice(fmt, "fmt", FORMATS)
    if fmt == "mp4" and not ffmpeg_available():
        raise NotSupportedError(
            "MP4 animations need ffmpeg on PATH (e.g. apt-get install ffmpeg); "
            "fmt='gif' works without it"
        )
    Q, path_points = _configurations(robot, q, path_points)
    obs = [as_obstacle(o, f"obstacles[{i}]") for i, o in enumerate(obstacles or ())]
    idx = frame_indices(Q.shape[0], options.max_frames)
    fig = plt.figure(figsize=options.figsize, dpi=options.dpi)
    try:
        film = _Film(fig, robot, Q, idx, options, path_points, obs)
        return _encode(fig, film, fmt, options)
    finally:
        plt.close(fig)


class _Film:
    """The animation's axes: the static scene drawn once, the moving artists set per frame.

    Frame k shows configuration ``Q[idx[k]]``: the skeleton ``P[k]`` (n+2, 3) [m], the
    joint markers ``J[k]`` (n, 3), the trace of the tool point up to k, the frame triads
    (with ``frames``) and the "step i / p" label.
    """

    def __init__(self, fig: Any, robot: Robot, Q: np.ndarray, idx: np.ndarray,
                 options: AnimationOptions, path_points: object, obs: list[Any]) -> None:
        Qs = Q[idx]
        self.robot, self.idx, self.total = robot, idx, Q.shape[0]
        self.P = robot_points(robot, Qs)  # (m, n+2, 3)
        self.J = joint_positions(robot, Qs)  # (m, n, 3)
        self.T_all = robot.fk_all(Qs) if options.frames else None
        self.T_tool = robot.fk(Qs) if options.frames else None
        two_d = robot.is_planar if options.planar is None else options.planar
        self.two_d = two_d
        self.ax = ax = fig.add_subplot(projection=None if two_d else "3d")
        if obs:
            plot_obstacles(ax, obs)
        if path_points is not None:
            plot_path(ax, path_points, linewidth=2.5)
        plot_robot(robot, Qs[0], ax, frames=options.frames, planar=two_d)
        self.tip = self.P[:, -1, :]
        self.trace_line = None
        if options.trace:
            (self.trace_line,) = ax.plot(*self.tip[:1, : 2 if two_d else 3].T, "-",
                                         color="tab:orange", lw=1.2, gid="serialkin-trace")
        _fix_limits(ax, robot, self.P, path_points, obs)
        if options.title:
            ax.set_title(options.title)
        if two_d:
            fig.tight_layout()
        text = ax.text if two_d else ax.text2D
        self.label = text(0.02, 0.97, "", transform=ax.transAxes, va="top", fontsize=9)
        self.lines = {ln.get_gid(): ln for ln in ax.get_lines()}
        self.triads = [[ln for ln in ax.get_lines() if ln.get_gid() == f"{FRAMES_GID}-{i}"]
                       for i in range(robot.n + 2)] if options.frames else []
        self.size = 0.08 * robot_scale(robot)

    def moving(self) -> list[Any]:
        """The artists :meth:`draw` changes (redrawn per frame when blitting)."""
        out = [self.lines[LINKS_GID], self.lines[JOINTS_GID], self.lines["serialkin-tool"],
               self.label]
        out += [self.trace_line] if self.trace_line is not None else []
        return out + [seg for segs in self.triads for seg in segs]

    def _set(self, line: Any, pts: np.ndarray) -> None:
        if self.two_d:
            line.set_data(pts[:, 0], pts[:, 1])
        else:
            line.set_data_3d(pts[:, 0], pts[:, 1], pts[:, 2])

    def draw(self, k: int) -> list[Any]:
        """Pose the moving artists for frame ``k``."""
        self._set(self.lines[LINKS_GID], self.P[k])
        self._set(self.lines[JOINTS_GID], self.J[k])
        self._set(self.lines["serialkin-tool"], self.P[k, -1:])
        if self.trace_line is not None:
            self._set(self.trace_line, self.tip[: k + 1])
        n = self.robot.n
        for i, segs in enumerate(self.triads):
            T = self.T_all[k, i] if i <= n else self.T_tool[k]  # type: ignore[index]
            axes_k = [c for c in range(3) if not (self.two_d and c == 2)]
            for seg, c in zip(segs, axes_k):
                o = T[:3, 3]
                self._set(seg, np.vstack([o, o + self.size * T[:3, c]]))
        self.label.set_text(f"step {self.idx[k] + 1} / {self.total}")
        return []


def _encode(fig: Any, film: _Film, fmt: str, options: AnimationOptions) -> bytes:
    """Encode every frame of ``film``: blitted GIF (Pillow) or MP4 (ffmpeg)."""
    from matplotlib import animation

    count = len(film.idx)
    bar = None
    callback = None
    if options.progress:
        from tqdm.auto import tqdm

        bar = tqdm(total=count, desc=f"animation ({fmt})", unit="frame")

        def callback(i: int, n: int) -> None:
            bar.update(1)

    if fmt == "gif":
        data = _gif_blitted(fig, film.ax, film.moving(), film.draw, count, options.fps,
                            callback)
    else:
        anim = animation.FuncAnimation(fig, film.draw, frames=count, blit=False,
                                       repeat=False, cache_frame_data=False)
        writer = animation.FFMpegWriter(fps=options.fps, codec="libx264",
                                        extra_args=["-pix_fmt", "yuv420p"])
        with tempfile.TemporaryDirectory(prefix="serialkin-anim-") as tmp:
            out = Path(tmp) / f"animation.{fmt}"
            anim.save(str(out), writer=writer, dpi=options.dpi, progress_callback=callback)
            data = out.read_bytes()
    if bar is not None:
        bar.close()
    return data


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


def save_animation(
    robot: Robot,
    q: object,
    path: str | Path,
    options: AnimationOptions | None = None,
    *,
    path_points: object = None,
    obstacles: Iterable[object] | None = None,
    fmt: str | None = None,
    **old_keywords: Any,
) -> Path:
    """Render an animation (see :func:`animate_trajectory`) and write it atomically.

    Args:
        robot: the robot.
        q: (p, n) configurations [rad / m] or a trajectory object (see
            :func:`animate_trajectory`).
        path: the file to write; its suffix ('.gif' or '.mp4') gives the format.
        options: frame rate, frame count, size and what is drawn (None: the defaults).
        path_points: (k, 2|3) target path [m], drawn in green.
        obstacles: obstacles (see :func:`serialkin.viz.plot.as_obstacle`).
        fmt: 'gif' or 'mp4'; when given it must agree with the suffix.
        **old_keywords: deprecated: the fields of :class:`AnimationOptions` as keywords
            (warns; removed in the next release).

    Returns:
        The path written.

    Raises:
        InputError: unknown suffix, ``fmt`` contradicting it, or the folder cannot be
            written.
        NotSupportedError: '.mp4' without ffmpeg.
    """
    options = _resolve_options("save_animation", options, old_keywords)
    out = Path(path)
    suffix = out.suffix.lower().lstrip(".")
    if suffix not in FORMATS:
        raise InputError(f"path must end in .gif or .mp4, got {str(out)!r}")
    if fmt is not None and fmt != suffix:
        raise InputError(f"fmt contradicts the suffix of {str(out)!r}")
    data = _render(robot, q, options, suffix, path_points, obstacles)
    return write_bytes_atomic(out, data)
