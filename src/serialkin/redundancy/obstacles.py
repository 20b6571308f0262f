"""Obstacles, link-obstacle distances and obstacle Jacobians (eqs 45, 51-56, corrected).

The links of the robot are modelled as segments (capsules of radius ``link_radius``):
link i (i = 1..n) runs from the origin of link frame i−1 to the origin of link frame i
and moves with link frame i; when the tool transform has a translation, one more
segment runs from the origin of frame n to the tool point. For a standard-DH arm these
are the physical links (the joint axis z_{i−1} passes through frame i−1's origin, so it is
a point of link i); a prismatic joint makes its segment stretch.

Obstacles are shapes of :mod:`serialkin.model.geometry` in the world frame, each with
its ``influence`` distance [m] beyond which the obstacle task of
:mod:`serialkin.redundancy.multitask` ignores it:

* :class:`~serialkin.model.geometry.Cylinder` infinite along z
  (``Cylinder(r, math.inf, center=[x, y, 0.0])``): a circle of the world xy plane; the
  distance is measured in that plane;
* :class:`~serialkin.model.geometry.Sphere` — a ball in 3-D;
* :class:`~serialkin.model.geometry.Capsule` — a segment with a radius in 3-D.

:func:`encode_obstacles` packs them into the (k, 8) rows of the compiled kernel;
:func:`obstacle_from_field` / :func:`obstacle_from_dict` read the form of scenario files
(``{type: circle|cylinder|sphere|capsule, ...}``) and :func:`obstacle_to_dict` writes it.
The old names ``Circle``, ``Cylinder``, ``Sphere`` and ``Capsule`` of this module (and of
:mod:`serialkin.redundancy`) still build the shared classes for one release, with a
``DeprecationWarning``.

Closest point (eqs 51-52, corrected by the ERRATA): the projection ``p_i = e_iᵀ(s_0 − s_i)``
of the obstacle centre on link i is clamped to ``[0, ℓ_i]`` so that the closest point
``s_ci = s_i + p_i e_i`` lies on the link *segment*, not on its infinite line. Eq 53 gives
``d_ci = ‖s_ci − s_0‖``, eq 54 (corrected: ``s_ci``, not ``s_ai``) the unit vector
``u_i = (s_ci − s_0)/d_ci`` from obstacle to link, and eqs 55-56 the obstacle-Jacobian row
``J_ci = −u_iᵀ J_sci`` with ``J_sci = ∂s_ci/∂q = (1 − t) J_{o_{i−1}} + t J_{o_i}``, the
blend of the point Jacobians of the segment's ends at the closest parameter t (from the
compiled kernel family; for a revolute joint this is the Jacobian of s_ci held fixed on
link i). ``J_ci q̇`` is the rate at which link i
approaches the obstacle; ``−J_ci`` is the gradient of its clearance.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from serialkin._checks import as_vector, check_positive
from serialkin.errors import InputError, InputTypeError
from serialkin.kinematics import kernels as K
from serialkin.model import geometry  # not its names: Sphere, Capsule here are the old ones
from serialkin.spatial.segments import closest_segment_segment

from .._jit import njit_exact

__all__ = [
    "ClosestPair",
    "Obstacle",
    "ObstacleGeometry",
    "check_obstacles",
    "clearances",
    "closest_pairs",
    "encode_obstacles",
    "obstacle_from_dict",
    "obstacle_from_field",
    "obstacle_jacobian",
    "obstacle_to_dict",
    "robot_segments",
]

KIND_CIRCLE = 0
KIND_SPHERE = 1
KIND_CAPSULE = 2

#: The shapes an obstacle task accepts (a Cylinder only when infinite along z).
Obstacle = geometry.Cylinder | geometry.Sphere | geometry.Capsule


def obstacle_from_field(f: Any) -> Obstacle:
    """Build an obstacle from a file field ``{type: circle|cylinder|sphere|capsule, ...}``.

    ``f`` is a :class:`serialkin._files.Field` (the reader every file format shares):
    the type, the fields of that type and their values are checked before use. A
    ``circle`` (or ``cylinder``) has a ``center`` [x, y] and is the vertical infinite
    :class:`~serialkin.model.geometry.Cylinder` through it; a ``sphere`` has a ``center``
    [x, y, z], a ``capsule`` its ends ``a`` and ``b``; all have a ``radius`` > 0 and
    optionally ``influence`` and ``name`` (lengths in metres).

    Raises:
        f.error: unknown type or a missing/invalid field; the message names the field.
    """
    kinds = ("circle", "cylinder", "sphere", "capsule")
    f.mapping(what="a mapping {type: circle|cylinder|sphere|capsule, ...}")
    t = f["type"].string(choices=kinds)
    points = {"circle": {"center": 2}, "cylinder": {"center": 2}, "sphere": {"center": 3},
              "capsule": {"a": 3, "b": 3}}[t]
    f.mapping({*points, "radius", "type", "influence", "name"}, (*points, "radius"))
    p = {k: f[k].vector(size, unit="m") for k, size in points.items()}
    radius = f["radius"].number(lo=0.0, lo_open=True, unit="m")
    label: dict[str, Any] = {"name": f["name"].string(default="", nonempty=False,
                                                       max_len=1000)}
    if f["influence"].present:
        label["influence"] = f["influence"].number(lo=0.0, unit="m")
    try:
        if t == "sphere":
            return geometry.Sphere(radius, center=p["center"], **label)
        if t == "capsule":
            return geometry.Capsule(radius, a=p["a"], b=p["b"], **label)
        return geometry.Cylinder(radius, math.inf, center=[*p["center"], 0.0], **label)
    except (InputError, InputTypeError) as exc:  # pragma: no cover - fields checked above
        raise f.fail(f"is invalid: {exc}") from exc


def obstacle_from_dict(d: dict, where: str = "obstacle") -> Obstacle:
    """Build an obstacle from a mapping ``{type: circle|cylinder|sphere|capsule, ...}``.

    Raises:
        InputError: unknown type or missing/invalid field; the message names ``where``.
    """
    from serialkin._files import Field

    return obstacle_from_field(Field(d, where, "", InputError))


def obstacle_to_dict(obstacle: Obstacle) -> dict:
    """The plain-data form of an obstacle that :func:`obstacle_from_dict` reads back.

    A vertical infinite cylinder is written as ``{type: circle, center: [x, y], ...}``
    (the height of its centre is not kept: it does not change the shape).

    Raises:
        InputTypeError: not a Cylinder, Sphere or Capsule.
        NotSupportedError: a cylinder that is finite or whose axis is not along z.
    """
    _row(obstacle, "obstacle")
    o = obstacle
    label = {"influence": o.influence, "name": o.name}
    if isinstance(o, geometry.Cylinder):
        return {"type": "circle", "center": o.center[:2].tolist(), "radius": o.radius,
                **label}
    if isinstance(o, geometry.Sphere):
        return {"type": "sphere", "center": o.center.tolist(), "radius": o.radius, **label}
    return {"type": "capsule", "a": o.a.tolist(), "b": o.b.tolist(), "radius": o.radius,
            **label}


def _row(o: object, where: str) -> np.ndarray:
    """The kernel row (kind, a(3), b(3), radius) of one obstacle.

    Raises:
        InputTypeError: not a Cylinder, Sphere or Capsule.
        NotSupportedError: a cylinder that is finite or whose axis is not along z.
    """
    if isinstance(o, geometry.Cylinder):
        o.require_infinite_along_z(where, "obstacle")
        x, y = o.center[0], o.center[1]
        return np.array([KIND_CIRCLE, x, y, 0.0, x, y, 0.0, o.radius])
    if isinstance(o, geometry.Sphere):
        return np.array([KIND_SPHERE, *o.center, *o.center, o.radius])
    if isinstance(o, geometry.Capsule):
        return np.array([KIND_CAPSULE, *o.a, *o.b, o.radius])
    raise InputTypeError(
        f"{where} must be a Cylinder, Sphere or Capsule, got {type(o).__name__}")


def encode_obstacles(obstacles: Sequence[Obstacle]) -> np.ndarray:
    """Obstacles as a (k, 8) float array for :func:`segment_obstacle_kernel`.

    Row j is (kind, a(3), b(3), radius): a sphere's centre twice, a capsule's ends, a
    vertical cylinder's (x, y, 0) twice.

    Raises:
        InputTypeError: an item that is not a Cylinder, Sphere or Capsule.
        NotSupportedError: a cylinder that is finite or whose axis is not along z.
    """
    rows = [_row(o, f"obstacles[{i}]") for i, o in enumerate(obstacles)]
    if not rows:
        return np.zeros((0, 8))
    return np.ascontiguousarray(np.stack(rows))


# --------------------------------------------------------------------- compiled geometry
@njit_exact(cache=True)
def segment_obstacle_kernel(P0, P1, obs, link_radius, T, SC, B, D, C):
    """Closest points between every segment and every obstacle (eqs 51-53, corrected).

    Args:
        P0: (s, 3) first ends of the segments [m].
        P1: (s, 3) second ends [m].
        obs: (k, 8) encoded obstacles (kind, a(3), b(3), radius).
        link_radius: link capsule radius [m].
        T: out (s, k) segment parameter of the closest point in [0, 1] (clamped: eq 51
            corrected).
        SC: out (s, k, 3) closest point on the segment s_c (eq 52).
        B: out (s, k, 3) closest point of the obstacle's core (centre, axis or segment).
        D: out (s, k) core distance ``‖s_c − b‖`` (eq 53).
        C: out (s, k) clearance ``D − radius − link_radius`` (negative when penetrating).
    """
    pa = np.empty(3)
    pb = np.empty(3)
    q0 = np.empty(3)
    q1 = np.empty(3)
    for i in range(P0.shape[0]):
        for j in range(obs.shape[0]):
            kind = int(obs[j, 0])
            if kind == KIND_CIRCLE:
                # work in the xy plane: the obstacle is a vertical line through (cx, cy)
                dx = P1[i, 0] - P0[i, 0]
                dy = P1[i, 1] - P0[i, 1]
                l2 = dx * dx + dy * dy
                t = 0.0
                if l2 > 1e-24:
                    t = ((obs[j, 1] - P0[i, 0]) * dx + (obs[j, 2] - P0[i, 1]) * dy) / l2
                    t = min(max(t, 0.0), 1.0)
                for r in range(3):
                    SC[i, j, r] = P0[i, r] + t * (P1[i, r] - P0[i, r])
                B[i, j, 0] = obs[j, 1]
                B[i, j, 1] = obs[j, 2]
                B[i, j, 2] = SC[i, j, 2]
            else:
                for r in range(3):
                    q0[r] = P0[i, r]
                    q1[r] = P1[i, r]
                    pa[r] = obs[j, 1 + r]
                    pb[r] = obs[j, 4 + r]
                s, u = closest_segment_segment((q0[0], q0[1], q0[2]), (q1[0], q1[1], q1[2]),
                                               (pa[0], pa[1], pa[2]), (pb[0], pb[1], pb[2]))
                t = s
                for r in range(3):
                    SC[i, j, r] = q0[r] + s * (q1[r] - q0[r])
                    B[i, j, r] = pa[r] + u * (pb[r] - pa[r])
            T[i, j] = t
            dd = 0.0
            for r in range(3):
                e = SC[i, j, r] - B[i, j, r]
                dd += e * e
            D[i, j] = math.sqrt(dd)
            C[i, j] = D[i, j] - obs[j, 7] - link_radius


# --------------------------------------------------------------------- python layer
def robot_segments(robot, q: object) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """The link segments of the robot at q.

    Returns:
        (P0, P1, link, frames): segment ends (s, 3) [m]; ``link`` (s,) the link frame each
        segment moves with (1..n); ``frames`` (n+1, 4, 4) the link frames (``fk_all``).
    """
    qv = robot.check_q(q)
    if qv.ndim != 1:
        raise InputError(f"q must have shape ({robot.n},), got {qv.shape}")
    g = ObstacleGeometry(robot, (), 0.0)
    g.update(np.ascontiguousarray(qv))
    return g.P0.copy(), g.P1.copy(), g.link.copy(), g.frames.copy()


@dataclass(frozen=True)
class ClosestPair:
    """The closest points of one link segment and one obstacle.

    Attributes:
        segment: segment index (0-based; segment i moves with link frame ``link``).
        obstacle: obstacle index.
        link: link frame index (1..n) the segment moves with.
        t: parameter of the closest point on the segment, in [0, 1].
        point: s_c (3,), the closest point on the link [m] (eq 52).
        obstacle_point: closest point of the obstacle's core (3,) [m].
        distance: d_c, distance from the core (eq 53) [m].
        clearance: d_c − obstacle radius − link radius [m] (negative when penetrating).
        u: unit vector from obstacle to link (eq 54, corrected) (3,).
        gradient: ∂clearance/∂q = uᵀ J_sc (n,), or None when not requested.
    """

    segment: int
    obstacle: int
    link: int
    t: float
    point: np.ndarray
    obstacle_point: np.ndarray
    distance: float
    clearance: float
    u: np.ndarray
    gradient: np.ndarray | None

    @property
    def jacobian_row(self) -> np.ndarray | None:
        """Eq 55: ``J_ci = −uᵀ J_sci`` (n,), the approach rate per unit joint velocity."""
        return None if self.gradient is None else -self.gradient


class ObstacleGeometry:
    """Link-obstacle distances of one robot and obstacle set, in pre-allocated buffers.

    Built once per robot, obstacle set and link radius (by the queries of this module,
    the obstacle task of :mod:`serialkin.redundancy.multitask`, the tracker and the
    obstacle constraint of :mod:`serialkin.diffik`); each :meth:`update` recomputes every
    buffer at a new configuration without allocating.

    Attributes (after :meth:`update`; ``s`` segments, ``k`` obstacles):
        frames: (n+1, 4, 4) link frames.
        P0, P1: (s, 3) segment ends [m]; ``link`` (s,) the link frame each moves with.
        T: (s, k) closest-point parameter along each segment (0..1).
        SC, B: (s, k, 3) closest points on the segment and on the obstacle [m].
        D: (s, k) distance between them [m]; ``C`` (s, k) clearance (``D`` minus the
            link radius) [m].
        enc: the obstacles encoded for the kernels (:func:`encode_obstacles`).
    """

    def __init__(self, robot, obstacles: Sequence[Obstacle], link_radius: float) -> None:
        self.robot = robot
        self.obstacles = tuple(obstacles)
        self.enc = encode_obstacles(self.obstacles)
        self.link_radius = float(link_radius)
        n = robot.n
        self.frames = np.empty((n + 1, 4, 4))
        self.has_tool = bool(np.linalg.norm(robot.tool[:3, 3]) > 1e-12)
        s = n + (1 if self.has_tool else 0)
        k = len(self.obstacles)
        self.link = np.arange(1, n + 1, dtype=np.int64)
        if self.has_tool:
            self.link = np.append(self.link, n)
        self.P0 = np.empty((s, 3))
        self.P1 = np.empty((s, 3))
        self.T = np.empty((s, k))
        self.SC = np.empty((s, k, 3))
        self.B = np.empty((s, k, 3))
        self.D = np.empty((s, k))
        self.C = np.empty((s, k))
        self.Jbuf = np.empty((6, n))
        self.pbuf = np.empty(3)
        self.Tee = np.empty((4, 4))

    def update(self, q: np.ndarray) -> None:
        """Recompute frames, segments and every closest pair at ``q`` (n,), contiguous."""
        r = self.robot
        c = r.chain
        update_geometry_into(q, c.F, c.L, c.meta, self.has_tool, self.enc, self.link_radius,
                             self.frames, self.P0, self.P1, self.Tee, self.T, self.SC, self.B,
                             self.D, self.C)

    def gradient(self, q: np.ndarray, i: int, j: int) -> tuple[np.ndarray, np.ndarray]:
        """(u (3,), ∂clearance/∂q (n,)) of segment i and obstacle j (after update).

        See :func:`pair_gradient_into`.
        """
        r = self.robot
        u = np.empty(3)
        g = np.empty(r.n)
        c = r.chain
        pair_gradient_into(q, c.F, c.L, c.meta, self.frames, self.P0, self.P1, self.link,
                           self.T, self.SC, self.B, self.D, i, j, self.Jbuf, self.pbuf, u, g)
        return u, g


@njit_exact(cache=True)
def update_geometry_into(q, F, L, meta, has_tool, enc, link_radius, frames, P0, P1, Tee, T, SC,
                         B, D, C):
    """Link frames, link segments and every segment-obstacle closest pair at q.

    Segment i < n runs from the origin of link frame i to that of frame i+1 (0-based);
    with ``has_tool`` one more runs from frame n's origin to the tool point. Writes
    ``frames`` (n+1, 4, 4), ``P0``/``P1`` (s, 3), ``Tee`` (4, 4) and the outputs of
    :func:`segment_obstacle_kernel`.
    """
    n = q.shape[0]
    K.fk_all_into(q, F, L, meta, frames)
    for i in range(n):
        for r in range(3):
            P0[i, r] = frames[i, r, 3]
            P1[i, r] = frames[i + 1, r, 3]
    if has_tool:
        K.fk_into(q, F, meta, Tee)
        for r in range(3):
            P0[n, r] = frames[n, r, 3]
            P1[n, r] = Tee[r, 3]
    if enc.shape[0] > 0:
        segment_obstacle_kernel(P0, P1, enc, link_radius, T, SC, B, D, C)


@njit_exact(cache=True)
def pair_gradient_into(q, F, L, meta, frames, P0, P1, link, T, SC, B, D, i, j, Jbuf, pbuf,
                       u, g):
    """Unit vector u (eq 54, corrected) and clearance gradient ``g = uᵀ J_sc`` of one pair.

    ``J_sc = ∂s_c/∂q`` (eq 56) for ``s_c = (1 − t) P0 + t P1`` at fixed t is
    ``(1 − t) J_P0 + t J_P1``, with the point Jacobians of the segment's ends (the origins
    of link frames k−1 and k, or frame n's origin and the tool point for the tool
    segment). Holding t fixed is exact for the distance's gradient (t is optimal: envelope
    theorem). Writes ``u`` (3,) and ``g`` (n,); eq 55's row is ``−g``.
    """
    n = q.shape[0]
    k = link[i]
    t = T[i, j]
    d = D[i, j]
    if d > 1e-12:
        for r in range(3):
            u[r] = (SC[i, j, r] - B[i, j, r]) / d
    else:  # on the core: any direction; the segment's normal in xy
        sx = -(P1[i, 1] - P0[i, 1])
        sy = P1[i, 0] - P0[i, 0]
        nu = math.sqrt(sx * sx + sy * sy)
        if nu > 1e-12:
            u[0] = sx / nu
            u[1] = sy / nu
        else:
            u[0] = 1.0
            u[1] = 0.0
        u[2] = 0.0
    for c in range(n):
        g[c] = 0.0
    local = np.zeros(3)
    if i >= n:  # tool segment: both ends on link n, s_c fixed in frame k
        W = frames[k]
        for a in range(3):
            s = 0.0
            for r in range(3):
                s += W[r, a] * (SC[i, j, r] - W[r, 3])
            local[a] = s
        K.point_jacobian_into(q, F, L, meta, k, local, Jbuf, pbuf)
        for c in range(n):
            g[c] = u[0] * Jbuf[0, c] + u[1] * Jbuf[1, c] + u[2] * Jbuf[2, c]
        return
    K.point_jacobian_into(q, F, L, meta, k - 1, local, Jbuf, pbuf)
    for c in range(n):
        g[c] = (1.0 - t) * (u[0] * Jbuf[0, c] + u[1] * Jbuf[1, c] + u[2] * Jbuf[2, c])
    K.point_jacobian_into(q, F, L, meta, k, local, Jbuf, pbuf)
    for c in range(n):
        g[c] += t * (u[0] * Jbuf[0, c] + u[1] * Jbuf[1, c] + u[2] * Jbuf[2, c])


@njit_exact(cache=True)
def accumulate_obstacle_task(q, F, L, meta, frames, P0, P1, link, T, SC, B, D, C, influence,
                             max_weight, repulsive_gain, A, rhs, Jbuf, pbuf):
    """Add the obstacle task of eq 48 to the normal equations ``A q̇ = rhs`` in place.

    For every pair (segment i, obstacle j) with clearance ``c < d_infl,j``: row
    ``J_ci = −g`` (eq 55), weight ``w = max_weight · smoothstep((d_infl − c)/d_infl)``
    (1 at contact and beyond); ``A += w J_ciᵀJ_ci`` and, with a repulsive gain k,
    ``rhs += w J_ciᵀ x_c`` with ``x_c = −k (d_infl − c)``. Returns the number of active pairs.
    """
    n = q.shape[0]
    u = np.empty(3)
    g = np.empty(n)
    count = 0
    for i in range(C.shape[0]):
        for j in range(C.shape[1]):
            c = C[i, j]
            dinf = influence[j]
            if c >= dinf:
                continue
            s = 1.0 if dinf <= 0.0 else (dinf - c) / dinf
            s = min(max(s, 0.0), 1.0)
            w = max_weight * s * s * (3.0 - 2.0 * s)
            if w <= 0.0:
                continue
            count += 1
            pair_gradient_into(q, F, L, meta, frames, P0, P1, link, T, SC, B, D, i, j, Jbuf,
                               pbuf, u, g)
            for a in range(n):
                for b in range(n):
                    A[a, b] += w * g[a] * g[b]
            if repulsive_gain > 0.0:
                xc = -repulsive_gain * (dinf - c)
                for a in range(n):
                    rhs[a] -= w * g[a] * xc
    return count


def clearances(robot, q: object, obstacles: Sequence[Obstacle], *,
               link_radius: float = 0.0) -> np.ndarray:
    """Signed clearance of every link segment to every obstacle, shape (s, k) [m].

    ``s`` is the number of segments (n, plus one for a tool offset), ``k`` the number of
    obstacles. Use ``.min(axis=0)`` for the clearance of each obstacle.
    """
    qv = robot.check_q(q)
    if qv.ndim != 1:
        raise InputError(f"q must have shape ({robot.n},), got {qv.shape}")
    check_positive(link_radius, "link_radius", allow_zero=True)
    g = ObstacleGeometry(robot, obstacles, link_radius)
    g.update(np.ascontiguousarray(qv))
    return g.C.copy()


def closest_pairs(robot, q: object, obstacles: Sequence[Obstacle], *,
                  link_radius: float = 0.0, with_jacobian: bool = False) -> list[ClosestPair]:
    """Closest points of every link segment and every obstacle (eqs 51-56, corrected).

    Args:
        robot: the robot.
        q: joint values, shape (n,).
        obstacles: obstacles.
        link_radius: link capsule radius [m].
        with_jacobian: also compute ``∂clearance/∂q`` (eq 55 with the opposite sign).

    Returns:
        list of :class:`ClosestPair`, segment-major.
    """
    qv = np.ascontiguousarray(robot.check_q(q))
    if qv.ndim != 1:
        raise InputError(f"q must have shape ({robot.n},), got {qv.shape}")
    check_positive(link_radius, "link_radius", allow_zero=True)
    g = ObstacleGeometry(robot, obstacles, link_radius)
    g.update(qv)
    out = []
    for i in range(g.C.shape[0]):
        for j in range(g.C.shape[1]):
            u, grad = g.gradient(qv, i, j) if with_jacobian else (None, None)
            if u is None:
                d = g.D[i, j]
                u = (g.SC[i, j] - g.B[i, j]) / d if d > 1e-12 else np.zeros(3)
            out.append(ClosestPair(i, j, int(g.link[i]), float(g.T[i, j]), g.SC[i, j].copy(),
                                   g.B[i, j].copy(), float(g.D[i, j]), float(g.C[i, j]),
                                   u, None if grad is None else grad.copy()))
    return out


def obstacle_jacobian(robot, q: object, obstacles: Sequence[Obstacle], *,
                      link_radius: float = 0.0, within_influence: bool = True
                      ) -> tuple[np.ndarray, np.ndarray, list[tuple[int, int]]]:
    """Obstacle-avoidance Jacobian J_c (eqs 55-56): one row per (link, obstacle) pair.

    Args:
        robot: the robot.
        q: joint values, shape (n,).
        obstacles: obstacles.
        link_radius: link capsule radius [m].
        within_influence: keep only pairs closer than the obstacle's influence distance
            (the chapter's "links that could collide"); else every pair.

    Returns:
        (J_c (r, n), clearance (r,), pairs [(segment, obstacle)]), rows ``−u_iᵀ J_sci``.
    """
    pairs = closest_pairs(robot, q, obstacles, link_radius=link_radius, with_jacobian=True)
    obs = tuple(obstacles)
    keep = [p for p in pairs if not within_influence or p.clearance < obs[p.obstacle].influence]
    if not keep:
        return np.zeros((0, robot.n)), np.zeros(0), []
    return (np.array([p.jacobian_row for p in keep]), np.array([p.clearance for p in keep]),
            [(p.segment, p.obstacle) for p in keep])


def check_obstacles(robot, obstacles: Sequence[Obstacle], *, link_radius: float = 0.0) -> None:
    """Raise when an obstacle overlaps the robot's base (the first joint's origin).

    Raises:
        InputError: naming the obstacle and its distance to the base.
        InputTypeError: an entry that is not an obstacle.
        NotSupportedError: a cylinder that is finite or whose axis is not along z.
    """
    encode_obstacles(tuple(obstacles))
    base = np.array(robot.base[:3, 3], dtype=float)
    frames0 = robot.fk_all(np.zeros(robot.n))
    base = frames0[0, :3, 3] if frames0.shape[0] else base
    P = np.ascontiguousarray(base[None, :])
    enc = encode_obstacles(tuple(obstacles))
    if not enc.shape[0]:
        return
    k = enc.shape[0]
    T = np.empty((1, k))
    SC = np.empty((1, k, 3))
    B = np.empty((1, k, 3))
    D = np.empty((1, k))
    C = np.empty((1, k))
    segment_obstacle_kernel(P, P, enc, float(link_radius), T, SC, B, D, C)
    for j, o in enumerate(obstacles):
        if C[0, j] <= 0.0:
            label = f" {o.name!r}" if o.name else ""
            raise InputError(
                f"obstacles[{j}]{label} overlaps the robot base at {base.round(4).tolist()}: "
                f"clearance {C[0, j]:.4g} m (radius {o.radius} m); move it or shrink it")


# ------------------------------------------------------------------ deprecated names
_INFLUENCE = geometry.DEFAULT_INFLUENCE


def _old_circle(center: object, radius: float, influence: float = _INFLUENCE,
                name: str = "") -> geometry.Cylinder:
    """The old ``Circle(center (2,), radius, influence, name)``: a vertical infinite cylinder."""
    c = as_vector(center, "center", 2)
    return geometry.Cylinder(check_positive(radius, "radius"), math.inf,
                             center=[c[0], c[1], 0.0], influence=influence, name=name)


def _old_sphere(center: object, radius: float, influence: float = _INFLUENCE,
                name: str = "") -> geometry.Sphere:
    """The old ``Sphere(center (3,), radius, influence, name)``."""
    return geometry.Sphere(check_positive(radius, "radius"), center=center,
                           influence=influence, name=name)


def _old_capsule(a: object, b: object, radius: float, influence: float = _INFLUENCE,
                 name: str = "") -> geometry.Capsule:
    """The old ``Capsule(a (3,), b (3,), radius, influence, name)``."""
    return geometry.Capsule(check_positive(radius, "radius"), a=a, b=b, influence=influence,
                            name=name)


_CYLINDER = "Cylinder(radius, math.inf, center=[x, y, 0.0], influence=..., name=...)"
#: Old name -> (thin constructor, the call in the shared vocabulary).
_DEPRECATED: dict[str, tuple[Callable[..., Any], str, str]] = {
    "Circle": (_old_circle, "Cylinder", _CYLINDER),
    "Cylinder": (_old_circle, "Cylinder", _CYLINDER),
    "Sphere": (_old_sphere, "Sphere", "Sphere(radius, center=..., influence=..., name=...)"),
    "Capsule": (_old_capsule, "Capsule",
                "Capsule(radius, a=..., b=..., influence=..., name=...)"),
}
_old_circle.__name__ = _old_circle.__qualname__ = "Circle"
_old_sphere.__name__ = _old_sphere.__qualname__ = "Sphere"
_old_capsule.__name__ = _old_capsule.__qualname__ = "Capsule"


def __getattr__(name: str) -> Callable[..., Any]:
    """``Circle``, ``Cylinder``, ``Sphere``, ``Capsule``: the old names (warn)."""
    return geometry.renamed(__name__, name, _DEPRECATED)
