"""Hard constraints of the differential-IK quadratic program, as inequalities on ``Δq``.

* :class:`PositionLimit` — ``gain · (lo − q) ≤ Δq ≤ gain · (hi − q)``: the joint limits as
  bounds on one step (with ``gain = 1`` the step may go exactly to the limit, never
  beyond; a smaller gain slows the approach, as pink's ``ConfigurationLimit``).
* :class:`VelocityLimit` — ``|Δq_j| ≤ v_max,j · dt``.
* :class:`StepBox` — ``|q + Δq − q_ref| ≤ δ``: the joints stay within δ of a reference
  (the tracker's bound on the joint jump between path points).
* :class:`CollisionAvoidance` — linearised distance constraints with a velocity damper
  (Faverjon & Tournassoud 1987; Kanoun et al. 2011; the form in mink and pink): for every
  pair (link capsule, obstacle) whose clearance ``d`` is below the influence distance
  ``d_i``, ``∇d · Δq ≥ −ξ (d − d_s)/(d_i − d_s)``, with ``d_s`` the safety distance and
  ``ξ = gain · (d_i − d_s)`` [m per step]: the clearance may shrink by at most the
  fraction ``gain`` of its excess over ``d_s`` per step, so (to first order) it never
  falls below ``d_s``, and it is pushed back up when it already has.
  ``∇d = uᵀ J_p(s_c)`` (eqs 54-56, corrected) with ``u`` the unit vector from the
  obstacle to the closest link point ``s_c`` and ``J_p`` its point Jacobian from the
  compiled kernel family (:func:`serialkin.redundancy.obstacles.pair_gradient_into`).
  For two capsules a and b of the robot (self-collision) ``∇d = nᵀ(J_p(a) − J_p(b))``.

Box constraints are returned as ``(lb, ub)`` (n,), the others as rows ``G Δq ≤ h``.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np

from serialkin._checks import as_float_array, check_positive
from serialkin._memo import PerObject
from serialkin.errors import InputError
from serialkin.kinematics import kernels as K
from serialkin.redundancy.obstacles import (
    Obstacle,
    ObstacleGeometry,
    encode_obstacles,
    pair_gradient_into,
)
from serialkin.spatial.segments import closest_segment_segment

from .._jit import njit

__all__ = ["CollisionAvoidance", "Constraint", "PositionLimit", "StepBox", "VelocityLimit"]


class Constraint:
    """Base class: ``box(ws, q) -> (lb, ub)`` or ``rows(ws, q) -> (G, h)``."""

    is_box: bool = True

    def box(self, ws, q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Bounds (n,) on Δq."""
        raise NotImplementedError  # pragma: no cover

    def rows(self, ws, q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Rows ``G (r, n)`` and ``h (r,)`` of ``G Δq ≤ h``."""
        raise NotImplementedError  # pragma: no cover


@dataclass
class PositionLimit(Constraint):
    """Joint position limits as bounds on the step: ``gain (lo − q) ≤ Δq ≤ gain (hi − q)``.

    Attributes:
        limits: (n, 2) limits [rad or m]; None uses the robot's ``qlim`` (infinite ends
            give no bound).
        gain: fraction of the distance to a limit one step may cover, (0, 1].
    """

    limits: object = None
    gain: float = 1.0

    def __post_init__(self) -> None:
        self.gain = check_positive(self.gain, "gain", maximum=1.0)
        if self.limits is not None:
            lim = as_float_array(self.limits, "limits", ndim=2)
            if lim.shape[1] != 2 or np.any(np.isnan(lim)) or np.any(lim[:, 0] > lim[:, 1]):
                raise InputError(f"limits must be (n, 2) with lower <= upper, got "
                                 f"shape {lim.shape}")
            self.limits = lim

    def box(self, ws, q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """``gain (lo − q)``, ``gain (hi − q)``."""
        lim = ws.robot.qlim if self.limits is None else self.limits
        if lim.shape[0] != q.size:
            raise InputError(f"PositionLimit has {lim.shape[0]} limits but the robot has "
                             f"{q.size} joints")
        return self.gain * (lim[:, 0] - q), self.gain * (lim[:, 1] - q)


@dataclass
class VelocityLimit(Constraint):
    """Joint velocity limits over one step: ``|Δq_j| ≤ v_max,j · dt``.

    Attributes:
        vmax: (n,) or scalar maximum joint speed [rad/s or m/s] (inf for none).
        dt: step duration [s] (1 makes ``vmax`` a maximum step per iteration).
    """

    vmax: object
    dt: float = 1.0

    def __post_init__(self) -> None:
        v = as_float_array(self.vmax, "vmax")
        if np.any(np.isnan(v)) or np.any(v <= 0.0):
            raise InputError(f"vmax must be > 0 (inf for no limit), got {v.tolist()}")
        self.vmax = v
        self.dt = check_positive(self.dt, "dt")

    def box(self, ws, q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """``∓ vmax · dt``."""
        b = getattr(self, "_b", None)
        if b is None or b.shape != q.shape:
            if self.vmax.ndim and self.vmax.shape != q.shape:
                raise InputError(f"vmax has {self.vmax.size} values but the robot has "
                                 f"{q.size} joints")
            b = np.ascontiguousarray(np.broadcast_to(self.vmax * self.dt, q.shape))
            self._b, self._mb = b, -b
        return self._mb, b


@dataclass
class StepBox(Constraint):
    """Keep every joint within ``delta`` of a reference: ``|q + Δq − q_ref| ≤ δ``.

    Attributes:
        reference: (n,) reference configuration (the previous path point's).
        delta: largest allowed deviation per joint [rad or m].
    """

    reference: object
    delta: float

    def __post_init__(self) -> None:
        self.reference = as_float_array(self.reference, "reference", ndim=1)
        self.delta = check_positive(self.delta, "delta")

    def box(self, ws, q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """``q_ref − q ∓ δ``."""
        d = self.reference - q
        return d - self.delta, d + self.delta


@njit(cache=True)
def obstacle_rows_into(q, F, L, meta, frames, P0, P1, link, T, SC, B, D, C, influence, safety,
                       gain, Jbuf, pbuf, G, h, PAIRS):
    """Velocity-damper rows of every (segment, obstacle) pair closer than its influence.

    Row r: ``G[r] = −∇d``, ``h[r] = gain · (d − d_s)`` (i.e. ``∇d·Δq ≥ −gain (d − d_s)``),
    with ``∇d = uᵀ J_sc`` from :func:`pair_gradient_into`. Writes ``PAIRS[r] = (i, j)``.
    Returns the number of rows written (G, h, PAIRS must hold s·k rows).
    """
    n = q.shape[0]
    u = np.empty(3)
    g = np.empty(n)
    r = 0
    for i in range(C.shape[0]):
        for j in range(C.shape[1]):
            d = C[i, j]
            if d >= influence[j]:
                continue
            pair_gradient_into(q, F, L, meta, frames, P0, P1, link, T, SC, B, D, i, j, Jbuf,
                               pbuf, u, g)
            for c in range(n):
                G[r, c] = -g[c]
            h[r] = gain * (d - safety)
            PAIRS[r, 0] = i
            PAIRS[r, 1] = j
            r += 1
    return r


@njit(cache=True)
def self_rows_into(q, F, L, meta, frames, P0, P1, link, pairs, radius, influence, safety, gain,
                   Jbuf, pbuf, G, h, DIST):
    """Velocity-damper rows of pairs of robot segments (self-collision).

    For the pair (a, b) with closest points ``s_a``, ``s_b`` and unit normal
    ``n = (s_a − s_b)/‖s_a − s_b‖``, ``d = ‖s_a − s_b‖ − 2 radius`` and
    ``∇d = nᵀ (J_p(s_a) − J_p(s_b))``; row ``G = −∇d``, ``h = gain (d − d_s)`` when
    ``d < influence``. Writes ``DIST[p]`` for every pair; returns the number of rows.
    """
    n = q.shape[0]
    la = np.empty(3)
    g = np.empty(n)
    nv = np.empty(3)
    r = 0
    for p in range(pairs.shape[0]):
        a = pairs[p, 0]
        b = pairs[p, 1]
        s, t = closest_segment_segment((P0[a, 0], P0[a, 1], P0[a, 2]),
                                       (P1[a, 0], P1[a, 1], P1[a, 2]),
                                       (P0[b, 0], P0[b, 1], P0[b, 2]),
                                       (P1[b, 0], P1[b, 1], P1[b, 2]))
        dist2 = 0.0
        for c in range(3):
            nv[c] = (P0[a, c] + s * (P1[a, c] - P0[a, c])) - (P0[b, c] + t * (P1[b, c] - P0[b, c]))
            dist2 += nv[c] * nv[c]
        dist = math.sqrt(dist2)
        d = dist - 2.0 * radius
        DIST[p] = d
        if d >= influence:
            continue
        if dist < 1e-12:
            continue  # coincident cores: no direction to push along
        for c in range(3):
            nv[c] /= dist
        for c in range(n):
            g[c] = 0.0
        for side in range(2):
            seg = a if side == 0 else b
            par = s if side == 0 else t
            sign = 1.0 if side == 0 else -1.0
            k = link[seg]
            for end in range(2):
                wt = (1.0 - par) if end == 0 else par
                if wt == 0.0:
                    continue
                for c in range(3):
                    la[c] = 0.0
                K.point_jacobian_into(q, F, L, meta, k - 1 + end, la, Jbuf, pbuf)
                for c in range(n):
                    g[c] += sign * wt * (nv[0] * Jbuf[0, c] + nv[1] * Jbuf[1, c]
                                         + nv[2] * Jbuf[2, c])
        for c in range(n):
            G[r, c] = -g[c]
        h[r] = gain * (d - safety)
        r += 1
    return r


@dataclass
class CollisionAvoidance(Constraint):
    """Link capsules kept off obstacles (and off each other) by velocity-damper rows.

    The links are the segments of :mod:`serialkin.redundancy.obstacles` (link i from the
    origin of link frame i−1 to that of frame i, capsules of ``link_radius``; a tool
    offset adds one segment, which is not checked against itself here).

    Attributes:
        obstacles: :class:`~serialkin.model.geometry.Cylinder` (infinite along z),
            ``Sphere``, ``Capsule``.
        link_radius: capsule radius of the links [m].
        safety: d_s, the clearance kept [m] (≥ 0).
        influence: d_i, the clearance below which a pair is constrained [m]; None uses
            ``safety`` + each obstacle's own ``influence``.
        gain: fraction of ``d − d_s`` the clearance may lose per step, (0, 1]
            (ξ = gain · (d_i − d_s) in the velocity-damper form).
        self_pairs: pairs of segment indices (0-based) checked against each other, or
            'auto' for every pair at least two segments apart; () for none.
    """

    obstacles: Sequence[Obstacle] = ()
    link_radius: float = 0.0
    safety: float = 0.002
    influence: float | None = None
    gain: float = 0.5
    self_pairs: object = ()
    _geo: PerObject = field(default_factory=PerObject, init=False, repr=False)

    is_box = False

    def __post_init__(self) -> None:
        self.obstacles = tuple(self.obstacles)
        self._enc = encode_obstacles(self.obstacles)
        self.link_radius = check_positive(self.link_radius, "link_radius", allow_zero=True)
        self.safety = check_positive(self.safety, "safety", allow_zero=True)
        self.gain = check_positive(self.gain, "gain", maximum=1.0)
        if self.influence is None:
            infl = np.array([self.safety + o.influence for o in self.obstacles])
        else:
            infl = np.full(len(self.obstacles), check_positive(self.influence, "influence"))
        if np.any(infl <= self.safety):
            raise InputError(f"the influence distance must exceed the safety distance "
                             f"{self.safety:g} m, got {infl.min():g} m")
        self._influence = infl
        self._self_influence = (self.safety + 0.02 if self.influence is None
                                else float(self.influence))

    def _state(self, robot):
        st = self._geo.get(robot)
        if st is None:
            g = ObstacleGeometry(robot, self.obstacles, self.link_radius)
            s = g.P0.shape[0]
            k = len(self.obstacles)
            if isinstance(self.self_pairs, str):
                if self.self_pairs != "auto":
                    raise InputError(f"self_pairs must be 'auto' or pairs of segment "
                                     f"indices, got {self.self_pairs!r}")
                pairs = [(a, b) for a in range(robot.n) for b in range(a + 2, robot.n)]
            else:
                pairs = [tuple(int(v) for v in p) for p in self.self_pairs]
                for p in pairs:
                    if len(p) != 2 or min(p) < 0 or max(p) >= robot.n or p[0] == p[1]:
                        raise InputError(f"self_pairs entries must be two distinct segment "
                                         f"indices in 0..{robot.n - 1}, got {p}")
            pa = np.array(pairs, dtype=np.int64).reshape(-1, 2)
            rows = s * k + pa.shape[0]
            st = (robot, g, pa, np.empty((rows, robot.n)), np.empty(rows),
                  np.empty((s * k, 2), dtype=np.int64), np.empty(pa.shape[0]))
            self._geo = PerObject()  # the latest robot's state only
            self._geo.set(robot, st)
        return st

    def distances(self, robot, q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Clearances at q: (s, k) segment-obstacle [m] and (pairs,) self pairs [m]."""
        _, g, pa, G, h, _, DIST = self._state(robot)
        q = np.ascontiguousarray(q, dtype=float)
        g.update(q)
        c = robot.chain
        if pa.shape[0]:
            self_rows_into(q, c.F, c.L, c.meta, g.frames, g.P0, g.P1, g.link, pa,
                           self.link_radius, -np.inf, self.safety, self.gain, g.Jbuf, g.pbuf,
                           G, h, DIST)
        return g.C.copy(), DIST.copy()

    def rows(self, ws, q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Rows of the active pairs (clearance below the influence distance)."""
        robot = ws.robot
        _, g, pa, G, h, PAIRS, DIST = self._state(robot)
        g.update(q)
        c = robot.chain
        r = 0
        if self._enc.shape[0]:
            r = obstacle_rows_into(q, c.F, c.L, c.meta, g.frames, g.P0, g.P1, g.link, g.T,
                                   g.SC, g.B, g.D, g.C, self._influence, self.safety,
                                   self.gain, g.Jbuf, g.pbuf, G, h, PAIRS)
        if pa.shape[0]:
            r += self_rows_into(q, c.F, c.L, c.meta, g.frames, g.P0, g.P1, g.link, pa,
                                self.link_radius, self._self_influence, self.safety,
                                self.gain, g.Jbuf, g.pbuf, G[r:], h[r:], DIST)
        return G[:r], h[:r]
