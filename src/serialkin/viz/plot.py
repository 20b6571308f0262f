"""matplotlib figures of a robot in a configuration, its target path and obstacles.

A robot is drawn as its *skeleton*: a polyline through the origins of the link frames
``world_T_i`` (i = 0..n, eq 11, from :meth:`~serialkin.Robot.fk_all`) and the tool point
(:meth:`~serialkin.Robot.fk`), with a marker on every joint axis and, optionally, the
link frames as RGB triads (x red, y green, z blue). Planar robots
(:attr:`~serialkin.Robot.is_planar`) are drawn in the world xy plane on ordinary 2D axes,
every other robot on 3D axes.

Obstacles are the shapes of :mod:`serialkin.model.geometry` (a sphere, a vertical
cylinder, a capsule), each drawn through an :class:`Obstacle` that holds it.
:func:`as_obstacle` is the boundary: it also reads plain dicts and duck-typed objects, where
anything with a ``center`` (or ``centre``) and a ``radius`` is a circle (2D) or a sphere
(3D); with a ``height`` too it is a vertical cylinder (the chapter's Figure 10 model, drawn
as a circle in 2D); with two end points (``a``/``b``, ``p0``/``p1`` or ``start``/``end``)
and a ``radius`` it is a capsule.

Lengths are in metres, angles in radians. matplotlib is imported lazily inside the
functions, so importing :mod:`serialkin` never requires it.
"""

from __future__ import annotations

import math
import warnings
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np

from serialkin._checks import as_float_array, check_positive
from serialkin.errors import InputError, InputTypeError
from serialkin.model.geometry import Capsule, Cylinder, Sphere
from serialkin.model.robot import robot_scale  # noqa: F401  (public here too)

if TYPE_CHECKING:
    from matplotlib.axes import Axes

    from serialkin.model.robot import Robot

__all__ = [
    "Obstacle",
    "as_obstacle",
    "is_3d_axes",
    "joint_positions",
    "plot_obstacles",
    "plot_path",
    "plot_robot",
    "robot_points",
    "robot_scale",
]

#: ``gid`` of the skeleton line drawn by :func:`plot_robot` (lets callers and tests find it).
LINKS_GID = "serialkin-links"
#: ``gid`` of the joint markers drawn by :func:`plot_robot`.
JOINTS_GID = "serialkin-joints"
#: ``gid`` prefix of the frame triads drawn by :func:`plot_robot`.
FRAMES_GID = "serialkin-frame"
#: ``gid`` of an obstacle artist drawn by :func:`plot_obstacles`.
OBSTACLE_GID = "serialkin-obstacle"
#: ``gid`` of the path drawn by :func:`plot_path`.
PATH_GID = "serialkin-path"


# ---------------------------------------------------------------------- geometry helpers
def robot_points(robot: Robot, q: object) -> np.ndarray:
    """Return the skeleton polyline: link-frame origins 0..n then the tool point.

    Args:
        robot: the robot.
        q: joint values, shape (n,) or (..., n) [rad / m].

    Returns:
        (n+2, 3) or (..., n+2, 3) points in the world frame [m]: rows 0..n are the origins
        of ``world_T_i`` (eq 11; row 0 is the base) and the last row is the tool point
        (translation of :meth:`Robot.fk`).
    """
    a = robot.check_q(q)
    frames = robot.fk_all(a)[..., :3, 3]
    tool = robot.fk(a)[..., None, :3, 3]
    return np.concatenate([frames, tool], axis=-2)


def joint_positions(robot: Robot, q: object) -> np.ndarray:
    """Points on the joint axes: the origin of the frame right after each joint motion.

    Link frame i is ``(pose after M_i) · L[i]`` (see :mod:`serialkin.kinematics.kernels`),
    so the joint frame is ``world_T_i · L[i]⁻¹``. For a standard-DH robot this is the
    origin of DH frame i-1, where joint i's axis z_{i-1} passes.

    Args:
        robot: the robot.
        q: joint values, shape (n,) or (..., n).

    Returns:
        (n, 3) or (..., n, 3) joint positions in the world frame [m].
    """
    a = robot.check_q(q)
    T = robot.fk_all(a)[..., 1:, :, :]
    Linv = np.linalg.inv(robot.chain.L[1:])
    return (T @ Linv)[..., :3, 3]


def is_3d_axes(ax: Any) -> bool:
    """Return True when ``ax`` is a mplot3d ``Axes3D``."""
    return getattr(ax, "name", "") == "3d"


def _new_axes(three_d: bool) -> Axes:
    import matplotlib.pyplot as plt

    fig = plt.figure(figsize=(6.0, 5.0))
    if three_d:
        return fig.add_subplot(projection="3d")
    return fig.add_subplot()


def _resolve_axes(robot: Robot, ax: Any, planar: bool | None) -> tuple[Any, bool]:
    """Pick or create the axes; return (axes, draw in 2D)."""
    if ax is None:
        two_d = robot.is_planar if planar is None else bool(planar)
        return _new_axes(not two_d), two_d
    three_d = is_3d_axes(ax)
    if planar is not None and bool(planar) == three_d:
        want = "2D" if planar else "3D"
        got = "3D" if three_d else "2D"
        raise InputError(f"planar={planar} asks for {want} drawing but ax is a {got} axes")
    return ax, not three_d


def _set_equal_3d(ax: Any, pts: np.ndarray, margin: float) -> None:
    """Equal-scale 3D limits around ``pts`` (k, 3), merged with what is already drawn."""
    lo = pts.min(axis=0) - margin
    hi = pts.max(axis=0) + margin
    if getattr(ax, "_serialkin_box", None) is not None:
        olo, ohi = ax._serialkin_box
        lo, hi = np.minimum(lo, olo), np.maximum(hi, ohi)
    ax._serialkin_box = (lo, hi)
    centre = (lo + hi) / 2
    half = float((hi - lo).max()) / 2
    ax.set_xlim(centre[0] - half, centre[0] + half)
    ax.set_ylim(centre[1] - half, centre[1] + half)
    ax.set_zlim(centre[2] - half, centre[2] + half)
    ax.set_box_aspect((1.0, 1.0, 1.0))


# ---------------------------------------------------------------------- the robot
def _mechanism_points(robot: Robot, q: np.ndarray) -> np.ndarray:
    """Skeleton that follows the mechanism: along each joint axis first, then across.

    Walks ``T = F[0]·M_1(q_1)·F[1]···M_n(q_n)·F[n]`` (eq 11). After each joint motion
    ``M_i`` the pose's z axis is joint i's axis; the fixed offset ``F[i]`` is drawn as two
    segments, its component along that axis (the DH offset d, e.g. a SCARA's column) and
    then the rest (the DH length a). Returns (k, 3) points [m], consecutive duplicates
    removed, ending at the tool point.
    """
    from serialkin.kinematics.kernels import PRISMATIC

    F, meta = robot.chain.F, robot.chain.meta
    W = F[0].copy()
    pts = [robot.chain.L[0][:3, 3].copy(), W[:3, 3].copy()]
    for i in range(robot.n):
        x = float(q[i]) + float(meta[i, 4])
        M = np.eye(4)
        if int(meta[i, 3]) == PRISMATIC:
            M[2, 3] = x
        else:
            c, s_ = np.cos(x), np.sin(x)
            M[:2, :2] = [[c, -s_], [s_, c]]
        W = W @ M
        pts.append(W[:3, 3].copy())
        along = float(F[i + 1][2, 3])
        pts.append(W[:3, 3] + along * W[:3, 2])
        W = W @ F[i + 1]
        pts.append(W[:3, 3].copy())
    out = [pts[0]]
    for p_ in pts[1:]:
        if np.linalg.norm(p_ - out[-1]) > 1e-12:
            out.append(p_)
    return np.array(out)


def plot_robot(
    robot: Robot,
    q: object,
    ax: Any = None,
    *,
    frames: bool = False,
    color: Any = "C0",
    alpha: float = 1.0,
    label: str | None = None,
    planar: bool | None = None,
    linewidth: float = 2.5,
    frame_scale: float | None = None,
    markersize: float = 6.0,
    mechanism: bool = False,
) -> Axes:
    """Draw the robot in configuration ``q``.

    The links are one polyline through the link-frame origins ``world_T_i``, i = 0..n
    (eq 11), and the tool point ``world_T_ee`` (eqs 10-11), in that order; the joints are
    round markers on their axes (:func:`joint_positions`), the base a square marker.

    Args:
        robot: the robot.
        q: joint values, shape (n,) [rad / m].
        ax: matplotlib axes to draw into; a new figure is made when None (2D for a planar
            robot, 3D otherwise).
        frames: also draw every link frame and the tool frame as an RGB triad.
        color: matplotlib colour of links and joint markers.
        alpha: opacity in [0, 1].
        label: legend label for the links.
        planar: force 2D (True, world xy plane) or 3D (False) drawing; None follows
            ``ax`` when given, else :attr:`Robot.is_planar`.
        linewidth: link line width [points].
        frame_scale: triad axis length [m] (default 8 % of :func:`robot_scale`).
        markersize: joint marker size [points] (0 hides joint, base and tool markers).
        mechanism: draw the links as the mechanism is built instead of straight between
            frame origins: each link runs along its joint axis first (the DH offset d, e.g.
            a SCARA's vertical column) and then across (the DH length a).

    Returns:
        The axes drawn into. The link line has ``gid='serialkin-links'``, the joint
        markers ``'serialkin-joints'``, the triads ``'serialkin-frame-<i>'``.

    Raises:
        InputError: wrong number of joint values, non-finite values, ``planar``
            contradicting ``ax``, ``alpha`` outside [0, 1].
    """
    qv = robot.check_q(q)
    if qv.ndim != 1:
        raise InputError(f"q must be one configuration of shape ({robot.n},), got {qv.shape}")
    alpha = float(alpha)
    if not 0.0 <= alpha <= 1.0:
        raise InputError(f"alpha must be in [0, 1], got {alpha}")
    ax, two_d = _resolve_axes(robot, ax, planar)
    pts = robot_points(robot, qv)
    joints = joint_positions(robot, qv)
    scale = robot_scale(robot)
    tri = 0.08 * scale if frame_scale is None else check_positive(frame_scale, "frame_scale")
    dims = 2 if two_d else 3

    line = _mechanism_points(robot, qv) if mechanism else pts
    ax.plot(*line[:, :dims].T, "-", color=color, alpha=alpha, lw=linewidth, label=label,
            gid=LINKS_GID, solid_capstyle="round")
    _draw_markers(ax, pts[:, :dims], joints[:, :dims], color, alpha, float(markersize))
    if frames:
        Ts = list(robot.fk_all(qv)) + [robot.fk(qv)]
        for i, T in enumerate(Ts):
            _draw_triad(ax, T, tri, two_d, alpha, f"{FRAMES_GID}-{i}")
    _finish_robot_axes(ax, two_d, pts, 0.1 * scale)
    return ax


def _draw_markers(ax: Any, pts: np.ndarray, joints: np.ndarray, color: Any, alpha: float,
                  ms: float) -> None:
    """Joint markers on their axes, the base square and the tool dot (none when ``ms`` = 0).

    ``pts`` is the skeleton (n+2, d) and ``joints`` the joint positions (n, d), d = 2 or 3.
    """
    if not ms > 0:
        return
    ax.plot(*joints.T, "o", color=color, alpha=alpha, ms=ms, mfc="white", mew=0.3 * ms,
            gid=JOINTS_GID)
    ax.plot(*pts[:1].T, "s", color="0.2", alpha=alpha, ms=1.33 * ms, gid="serialkin-base")
    ax.plot(*pts[-1:].T, "o", color=color, alpha=alpha, ms=0.67 * ms, gid="serialkin-tool")


def _finish_robot_axes(ax: Any, two_d: bool, pts: np.ndarray, margin: float) -> None:
    """Equal scale around the skeleton ``pts`` (n+2, 3) [m] and axis labels in metres."""
    ax.set_xlabel("x [m]")
    ax.set_ylabel("y [m]")
    if two_d:
        ax.set_aspect("equal", adjustable="datalim")
        ax.autoscale_view()
    else:
        _set_equal_3d(ax, pts, margin)
        ax.set_zlabel("z [m]")


def _draw_triad(ax: Any, T: np.ndarray, size: float, two_d: bool, alpha: float, gid: str) -> None:
    """Draw frame T's x, y, z axes (red, green, blue) of length ``size``."""
    o = T[:3, 3]
    for k, c in enumerate(("tab:red", "tab:green", "tab:blue")):
        e = o + size * T[:3, k]
        if two_d:
            if k == 2:
                continue
            ax.plot([o[0], e[0]], [o[1], e[1]], "-", color=c, alpha=alpha, lw=1.5, gid=gid)
        else:
            ax.plot([o[0], e[0]], [o[1], e[1]], [o[2], e[2]], "-", color=c, alpha=alpha,
                    lw=1.5, gid=gid)


# ---------------------------------------------------------------------- obstacles and paths
#: The shapes of :mod:`serialkin.model.geometry` the figures and the viewer draw.
Drawable = Sphere | Cylinder | Capsule


@dataclass(frozen=True, init=False)
class Obstacle:
    """A shape of :mod:`serialkin.model.geometry` as the figures and the viewer draw it.

    It holds the shape and describes nothing again: every attribute below is read from
    ``shape``. A cylinder is drawn vertical (its axis along the world z) about its
    ``center``.

    ``Obstacle(shape)`` wraps a :class:`~serialkin.model.geometry.Sphere`,
    :class:`~serialkin.model.geometry.Cylinder` or :class:`~serialkin.model.geometry.Capsule`;
    :func:`as_obstacle` builds one from any accepted form. The old form
    ``Obstacle(kind, center, radius, height, a, b, influence, name)`` still builds the
    shape for one release, with a ``DeprecationWarning``.

    Attributes:
        shape: the geometry shape drawn.

    Raises:
        InputTypeError: ``shape`` is not a Sphere, Cylinder or Capsule.
    """

    shape: Drawable

    def __init__(self, shape: Drawable | str, *old: Any, **old_keywords: Any) -> None:
        """Wrap ``shape`` (or build it from the deprecated field-by-field form)."""
        if isinstance(shape, str):
            warnings.warn("Obstacle(kind, center, radius, ...) is deprecated: pass the shape, "
                          "Obstacle(Sphere(radius, center=...)), or call as_obstacle(...)",
                          DeprecationWarning, stacklevel=2)
            shape = _old_shape(shape, *old, **old_keywords)
        elif old or old_keywords:
            raise InputTypeError("Obstacle takes one geometry shape, got more arguments")
        if not isinstance(shape, Sphere | Cylinder | Capsule):
            raise InputTypeError(f"Obstacle: expected a Sphere, Cylinder or Capsule of "
                                 f"serialkin.model.geometry, got {type(shape).__name__}")
        object.__setattr__(self, "shape", shape)

    @property
    def kind(self) -> str:
        """'sphere', 'cylinder' (vertical; a circle in 2D) or 'capsule'."""
        return self.shape.kind

    @property
    def center(self) -> np.ndarray:
        """(3,) centre [m] (a capsule: the midpoint of a-b)."""
        return self.shape.center

    @property
    def radius(self) -> float:
        """Radius [m]."""
        return self.shape.radius

    @property
    def height(self) -> float | None:
        """A cylinder's height [m]; None when infinite (drawn as tall as the scene needs)."""
        if isinstance(self.shape, Cylinder) and math.isfinite(self.shape.length):
            return self.shape.length
        return None

    @property
    def a(self) -> np.ndarray | None:
        """(3,) a capsule's start point [m], else None."""
        return self.shape.a if isinstance(self.shape, Capsule) else None

    @property
    def b(self) -> np.ndarray | None:
        """(3,) a capsule's end point [m], else None."""
        return self.shape.b if isinstance(self.shape, Capsule) else None

    @property
    def influence(self) -> float:
        """Distance of influence beyond the surface [m] (Figure 10)."""
        return self.shape.influence

    @property
    def name(self) -> str:
        """Label."""
        return self.shape.name

    def extent_points(self) -> np.ndarray:
        """Points whose bounding box holds the obstacle's cross-section, for axis limits.

        The centre (a capsule: both end points) moved by ± ``radius`` along x, y and z:
        (6, 3) or (12, 3) [m]. A cylinder's height is not included.
        """
        ends = [self.center] if self.a is None else [self.a, self.b]
        offsets = self.radius * np.vstack([np.eye(3), -np.eye(3)])
        return np.vstack([c[None] + offsets for c in ends])


def _old_shape(kind: str, center: object, radius: float, height: float | None = None,
               a: object = None, b: object = None, influence: float = 0.0,
               name: str = "") -> Drawable:
    """The shape of the deprecated ``Obstacle(kind, center, radius, ...)`` fields."""
    label = {"influence": influence, "name": name}
    if kind == "capsule":
        return Capsule(radius, a=a, b=b, **label)
    if kind == "cylinder":
        return Cylinder(radius, math.inf if height is None else height, center=center,
                        **label)
    if kind == "sphere":
        return Sphere(radius, center=center, **label)
    raise InputError(f"Obstacle kind must be one of sphere, cylinder, capsule, got {kind!r}")


_ENDPOINT_NAMES = (("a", "b"), ("p0", "p1"), ("start", "end"), ("p1", "p2"))
#: Integer ``kind`` codes of the obstacle encoding (cylinder along z, sphere, capsule).
_KIND_CODES = {0: "cylinder", 1: "sphere", 2: "capsule"}
_KIND_NAMES = {"circle": "cylinder", "cylinder": "cylinder", "sphere": "sphere",
               "ball": "sphere", "capsule": "capsule"}


def _field(obj: object, names: Sequence[str]) -> Any:
    for name in names:
        if isinstance(obj, Mapping):
            if name in obj:
                return obj[name]
        elif hasattr(obj, name):
            return getattr(obj, name)
    return None


def _point3(value: object, name: str) -> np.ndarray:
    p = as_float_array(value, name)
    if p.shape == (2,):
        p = np.append(p, 0.0)
    if p.shape != (3,):
        raise InputError(f"{name} must have 2 or 3 coordinates, got shape {p.shape}")
    return p


def _kind_of(obj: object, name: str) -> str | None:
    """Shape named by a ``kind``/``type``/``shape`` field (string or integer code)."""
    value = _field(obj, ("kind", "type", "shape"))
    if value is None or isinstance(value, bool):
        return None
    if isinstance(value, (int, np.integer)):
        kind = _KIND_CODES.get(int(value))
    elif isinstance(value, str):
        kind = _KIND_NAMES.get(value.strip().lower())
    else:
        return None
    if kind is None:
        raise InputError(
            f"{name}.kind must be one of {', '.join(_KIND_NAMES)} (or code 0, 1, 2), "
            f"got {value!r}"
        )
    return kind


def _capsule_of(obj: object, r: float, label: dict[str, Any], name: str) -> Drawable | None:
    """The capsule (a sphere when its ends meet) of an object with end points, else None."""
    for na, nb in _ENDPOINT_NAMES:
        pa, pb = _field(obj, (na,)), _field(obj, (nb,))
        if pa is not None and pb is not None and not isinstance(pa, (int, float, str)):
            a = _point3(pa, f"{name}.{na}")
            b = _point3(pb, f"{name}.{nb}")
            if np.allclose(a, b, rtol=0.0, atol=1e-12):
                return Sphere(r, center=a, **label)
            return Capsule(r, a=a, b=b, **label)
    return None


def _height_of(obj: object, name: str) -> float | None:
    """A vertical cylinder's height [m] (inf: infinite), None when ``obj`` names none.

    A :class:`~serialkin.model.geometry.Cylinder` gives its ``length``; other objects a
    ``height``/``h`` field (a non-finite one: infinite).
    """
    if isinstance(obj, Cylinder):
        return obj.length
    height = _field(obj, ("height", "h"))
    if height is None:
        return None
    h = float(height)
    if not np.isfinite(h):
        return math.inf
    return check_positive(h, f"{name}.height", allow_zero=True)


def as_obstacle(obj: object, name: str = "obstacle") -> Obstacle:
    """Normalise an obstacle object or dict to an :class:`Obstacle` (a geometry shape).

    Works with the shapes of :mod:`serialkin.model.geometry` (``Cylinder``: a vertical
    cylinder of its length, ``math.inf`` for an infinite one; ``Sphere``; ``Capsule``),
    their scenario-file form (:func:`serialkin.redundancy.obstacles.obstacle_to_dict`) and
    plain dicts.
    Accepted fields (attributes or mapping keys): ``center``/``centre``/``position`` (2 or 3
    coordinates; z = 0 when 2), ``radius`` (> 0), optional ``height`` (a vertical cylinder
    of that height), capsule end points ``a``/``b`` (or ``p0``/``p1``, ``start``/``end``),
    ``kind``/``type``/``shape`` ('circle' = 'cylinder', 'sphere', 'capsule', or the integer
    codes 0, 1, 2), ``influence`` [m] (default 0, a geometry shape's own) and ``name``.
    Without a kind, a 2-coordinate centre is a circle (infinite cylinder along z) and a
    3-coordinate centre a sphere.

    Raises:
        InputTypeError: ``obj`` has no radius or no centre.
        InputError: bad coordinates, a non-positive radius, a negative height or an
            unknown kind.
    """
    if isinstance(obj, Obstacle):
        return obj
    radius = _field(obj, ("radius", "r"))
    if radius is None:
        raise InputTypeError(
            f"{name} must have a 'radius' and a 'center' (or capsule end points 'a', 'b'), "
            f"got {type(obj).__name__} {obj!r}"[:200]
        )
    r = check_positive(radius, f"{name}.radius")
    kind = _kind_of(obj, name)
    infl = _field(obj, ("influence",))
    label = {"influence": 0.0 if infl is None else check_positive(
                 infl, f"{name}.influence", allow_zero=True),
             "name": str(_field(obj, ("name",)) or "")}
    capsule = _capsule_of(obj, r, label, name)
    if capsule is not None:
        return Obstacle(capsule)
    if kind == "capsule":
        raise InputTypeError(f"{name} is a capsule but has no end points 'a' and 'b'")
    centre = _field(obj, ("center", "centre", "position", "c"))
    if centre is None:
        raise InputTypeError(f"{name} has a radius but no 'center': {obj!r}"[:200])
    c_raw = as_float_array(centre, f"{name}.center")
    c = _point3(c_raw, f"{name}.center")
    height = _height_of(obj, name)
    if height is None and kind is None:
        kind = "cylinder" if c_raw.shape == (2,) else "sphere"
    if height is not None or kind == "cylinder":
        return Obstacle(Cylinder(r, math.inf if height is None else height, center=c,
                                 **label))
    return Obstacle(Sphere(r, center=c, **label))


def plot_obstacles(
    ax: Any,
    obstacles: Iterable[object],
    *,
    color: Any = "tab:gray",
    alpha: float = 0.35,
    edgecolor: Any = "0.25",
    influence: bool | float = False,
    labels: bool = False,
) -> Any:
    """Draw obstacles: circles/capsule outlines on 2D axes, surfaces on 3D axes.

    Args:
        ax: 2D or 3D matplotlib axes.
        obstacles: iterable of obstacle objects or dicts (see :func:`as_obstacle`).
        color: face colour.
        alpha: face opacity.
        edgecolor: outline colour (2D).
        influence: in 2D, also draw a dashed circle of radius ``radius + influence`` (the
            distance of influence, Figure 10): True uses each obstacle's own
            ``influence``, a number [m] is used for all, False draws none.
        labels: in 2D, write each obstacle's ``name`` at its centre (the tables' A, B, ...).

    Returns:
        The axes. Every obstacle artist has ``gid='serialkin-obstacle'`` (labels
        ``'serialkin-obstacle-label'``).
    """
    from matplotlib.patches import Circle, Polygon

    obs = [as_obstacle(o, f"obstacles[{i}]") for i, o in enumerate(obstacles)]
    three_d = is_3d_axes(ax)
    for o in obs:
        if not three_d:
            if o.kind == "capsule":
                outline = _stadium(np.asarray(o.a)[:2], np.asarray(o.b)[:2], o.radius)
                ax.add_patch(Polygon(outline, closed=True, fc=color, ec=edgecolor, alpha=alpha,
                                     gid=OBSTACLE_GID))
            else:
                ax.add_patch(Circle(tuple(o.center[:2]), o.radius, fc=color, ec=edgecolor,
                                    alpha=alpha, gid=OBSTACLE_GID))
                extra = o.influence if influence is True else float(influence or 0.0)
                if extra > 0.0:
                    ax.add_patch(Circle(tuple(o.center[:2]), o.radius + extra,
                                        fill=False, ec=edgecolor, ls="--", lw=0.8,
                                        gid=OBSTACLE_GID + "-influence"))
            if labels and o.name:
                ax.text(float(o.center[0]), float(o.center[1]), o.name, ha="center",
                        va="center", fontsize="medium", fontweight="bold", color="0.1",
                        gid=OBSTACLE_GID + "-label")
            continue
        box = getattr(ax, "_serialkin_box", None)
        tall = float(box[1][2] - box[0][2]) if box is not None else 0.0
        X, Y, Z = _surface(o, default_height=max(4.0 * o.radius, tall))
        ax.plot_surface(X, Y, Z, color=color, alpha=alpha, linewidth=0, gid=OBSTACLE_GID)
        pts = np.stack([X.ravel(), Y.ravel(), Z.ravel()], axis=1)
        _set_equal_3d(ax, pts, 0.0)
    if not three_d:
        ax.set_aspect("equal", adjustable="datalim")
        ax.autoscale_view()
    return ax


def _stadium(a: np.ndarray, b: np.ndarray, r: float, k: int = 24) -> np.ndarray:
    """Outline (2k+2, 2) of the planar capsule around segment a-b."""
    d = b - a
    ang = float(np.arctan2(d[1], d[0])) if np.linalg.norm(d) > 0 else 0.0
    t1 = np.linspace(ang - np.pi / 2, ang + np.pi / 2, k + 1)
    t2 = t1 + np.pi
    arc_b = b + r * np.stack([np.cos(t1), np.sin(t1)], axis=1)
    arc_a = a + r * np.stack([np.cos(t2), np.sin(t2)], axis=1)
    return np.vstack([arc_b, arc_a])


def _surface(o: Obstacle, k: int = 20, default_height: float = 1.0,
             ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Mesh grids (X, Y, Z) of a sphere, vertical cylinder or capsule.

    An infinite cylinder (``height`` None) is drawn ``default_height`` tall.
    """
    u = np.linspace(0, 2 * np.pi, k + 1)
    if o.kind == "sphere":
        v = np.linspace(0, np.pi, k // 2 + 1)
        X = o.center[0] + o.radius * np.outer(np.cos(u), np.sin(v))
        Y = o.center[1] + o.radius * np.outer(np.sin(u), np.sin(v))
        Z = o.center[2] + o.radius * np.outer(np.ones_like(u), np.cos(v))
        return X, Y, Z
    if o.kind == "cylinder":
        h = o.height if o.height is not None else default_height
        z = o.center[2] + np.array([-h / 2, h / 2])
        X = o.center[0] + o.radius * np.outer(np.cos(u), np.ones(2))
        Y = o.center[1] + o.radius * np.outer(np.sin(u), np.ones(2))
        Z = np.outer(np.ones_like(u), z)
        return X, Y, Z
    # capsule: a tube along a-b closed by two hemispheres, parametrised along the axis
    a, b = np.asarray(o.a, dtype=float), np.asarray(o.b, dtype=float)
    axis = b - a
    length = float(np.linalg.norm(axis))
    e = axis / length if length > 0 else np.array([0.0, 0.0, 1.0])
    helper = np.array([1.0, 0.0, 0.0]) if abs(e[0]) < 0.9 else np.array([0.0, 1.0, 0.0])
    n1 = np.cross(e, helper)
    n1 /= np.linalg.norm(n1)
    n2 = np.cross(e, n1)
    v = np.linspace(-np.pi / 2, np.pi / 2, k // 2 + 1)
    # along-axis offset: hemisphere at a (v<0), cylinder, hemisphere at b (v>0)
    s = np.concatenate([o.radius * np.sin(v[v < 0]), [0.0, length],
                        length + o.radius * np.sin(v[v > 0])])
    rad = np.concatenate([o.radius * np.cos(v[v < 0]), [o.radius, o.radius],
                          o.radius * np.cos(v[v > 0])])
    P = (a[None, None, :] + s[None, :, None] * e
         + rad[None, :, None] * (np.cos(u)[:, None, None] * n1 + np.sin(u)[:, None, None] * n2))
    return P[..., 0], P[..., 1], P[..., 2]


def plot_path(
    ax: Any,
    points: object,
    *,
    color: Any = "tab:green",
    label: str | None = "target path",
    linewidth: float = 1.5,
    linestyle: str = "-",
) -> Any:
    """Draw a target path (the chapter's green curve of Figures 8, 11, 12).

    Args:
        ax: 2D or 3D axes.
        points: (k, 2) or (k, 3) path points [m]; on 2D axes only x, y are used, on 3D
            axes 2D points get z = 0.
        color: line colour.
        label: legend label.
        linewidth: line width [points].
        linestyle: matplotlib line style.

    Returns:
        The axes; the line has ``gid='serialkin-path'``.
    """
    P = as_float_array(points, "points", ndim=2)
    if P.shape[1] not in (2, 3):
        raise InputError(f"points must have shape (k, 2) or (k, 3), got {P.shape}")
    if is_3d_axes(ax):
        if P.shape[1] == 2:
            P = np.hstack([P, np.zeros((P.shape[0], 1))])
        ax.plot(P[:, 0], P[:, 1], P[:, 2], linestyle, color=color, lw=linewidth, label=label,
                gid=PATH_GID)
        _set_equal_3d(ax, P, 0.0)
    else:
        ax.plot(P[:, 0], P[:, 1], linestyle, color=color, lw=linewidth, label=label,
                gid=PATH_GID)
        ax.set_aspect("equal", adjustable="datalim")
    return ax
