"""Collision rows from the robot's capsule model (:mod:`serialkin.collision`) and a scene.

:class:`ModelCollisionAvoidance` is the velocity-damper constraint of
:class:`~serialkin.diffik.constraints.CollisionAvoidance` for a
:class:`~serialkin.model.collision_model.CollisionModel` (the fitted capsules and spheres per
link frame that ``robot.collision`` carries, e.g. the zoo's Panda and UR5) against scene
shapes (spheres, capsules, z-cylinders, boxes, half-spaces of
:mod:`serialkin.model.geometry`, encoded by :mod:`serialkin.collision.shapes`) and
between the robot's own bodies (pairs checked by the allowed-collision matrix).

For every pair the compiled kernels of :mod:`serialkin.collision.kernels` give the signed
distance ``d`` and the witness points ``w₁`` (on the robot shape) and ``w₂``; ``(w₁ − w₂)/d``
is the unit direction in which moving the robot's shape increases ``d`` (for separated and
for overlapping shapes alike), so ``∇d = uᵀ J_p(w₁)`` for a scene pair and
``∇d = uᵀ (J_p(w₁) − J_p(w₂))`` for a self pair, with ``J_p`` the point Jacobian of the
witness point held on its link frame (the compiled kernel family). Rows as in
:class:`~serialkin.diffik.constraints.CollisionAvoidance`:
``∇d · Δq ≥ −gain (d − d_s)`` when ``d < d_i``. A capsule against a scene shape also gets
the rows of its two end spheres: lying flat on a face it has a whole segment of closest
points, and a single row at one of them would let the other end sink as it tilts.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from serialkin._checks import check_positive, readonly
from serialkin._memo import PerObject
from serialkin.collision import kernels as CK
from serialkin.collision.queries import shapes_to_world
from serialkin.diffik.constraints import Constraint
from serialkin.errors import InputError
from serialkin.kinematics import kernels as K

from .._jit import njit

__all__ = ["ModelCollisionAvoidance", "model_rows_into"]


@njit(cache=True)
def _scene_pair(w0, w1, r, scene, o):
    """(d, w1, w2) of robot capsule (w0 w1, r) and scene shape o (layout of encode_scene)."""
    kind = int(scene[o, 0])
    if kind == 0:
        c = scene[o, 1:4].copy()
        return CK.capsule_sphere(w0, w1, r, c, scene[o, 4])
    if kind == 1:
        return CK.capsule_capsule(w0, w1, r, scene[o, 1:4].copy(), scene[o, 4:7].copy(),
                                  scene[o, 7])
    if kind == 2:
        R = scene[o, 4:13].copy().reshape(3, 3)
        return CK.capsule_box(w0, w1, r, scene[o, 1:4].copy(), R, scene[o, 13:16].copy())
    if kind == 3:
        return CK.capsule_halfspace(w0, w1, r, scene[o, 1:4].copy(), scene[o, 4])
    # vertical cylinder: the distance in the xy plane, the robot witness at its height
    a = w0.copy()
    b = w1.copy()
    a[2] = 0.0
    b[2] = 0.0
    c = np.array([scene[o, 1], scene[o, 2], 0.0])
    d, p1, p2 = CK.capsule_sphere(a, b, r, c, scene[o, 3])
    dx = b[0] - a[0]
    dy = b[1] - a[1]
    l2 = dx * dx + dy * dy
    t = 0.0
    if l2 > 1e-24:
        t = min(max(((c[0] - a[0]) * dx + (c[1] - a[1]) * dy) / l2, 0.0), 1.0)
    z = w0[2] + t * (w1[2] - w0[2])
    p1[2] = z
    p2[2] = z
    return d, p1, p2


@njit(cache=True)
def _add_gradient(q, F, L, meta, frames, f, w, u, sign, Jbuf, pbuf, g):
    """Add ``sign · uᵀ J_p(w)`` to g, the point w held on link frame f."""
    n = q.shape[0]
    local = np.empty(3)
    for a in range(3):
        s = 0.0
        for r in range(3):
            s += frames[f, r, a] * (w[r] - frames[f, r, 3])
        local[a] = s
    K.point_jacobian_into(q, F, L, meta, f, local, Jbuf, pbuf)
    for c in range(n):
        g[c] += sign * (u[0] * Jbuf[0, c] + u[1] * Jbuf[1, c] + u[2] * Jbuf[2, c])


@njit(cache=True)
def _negligible(g):
    for c in range(g.shape[0]):
        if abs(g[c]) > 1e-12:
            return False
    return True


@njit(cache=True)
def model_rows_into(q, F, L, meta, shape_frame, A, B, rad, scene, pa, pb, influence, safety,
                    gain, frames, G, h, DIST, WHO):
    """Velocity-damper rows of every robot-shape/scene-shape pair and checked self pair.

    ``DIST`` (m·k + P,) receives every pair's signed distance (scene pairs shape-major,
    then the self pairs); ``WHO[r]`` the pair index of row r (``−1 − index`` for the rows of
    a capsule's end spheres against the scene). G, h, WHO hold up to 3·m·k + P rows.
    Returns the number of rows.
    """
    n = q.shape[0]
    K.fk_all_into(q, F, L, meta, frames)
    m = A.shape[0]
    W0 = np.empty((m, 3))
    W1 = np.empty((m, 3))
    shapes_to_world(frames, shape_frame, A, B, W0, W1)
    Jbuf = np.empty((6, n))
    pbuf = np.empty(3)
    g = np.empty(n)
    u = np.empty(3)
    rows = 0
    idx = 0
    k = scene.shape[0]
    for s in range(m):
        for o in range(k):
            # the closest pair, then (for a capsule) each end as a sphere: a capsule lying
            # flat on a face has a whole segment of closest points, and one row at one of
            # them lets the other end sink when the capsule tilts
            for part in range(3):
                if part == 0:
                    d, w1, w2 = _scene_pair(W0[s].copy(), W1[s].copy(), rad[s], scene, o)
                    DIST[idx] = d
                else:
                    end = W0[s].copy() if part == 1 else W1[s].copy()
                    same = True
                    for r in range(3):
                        if W0[s, r] != W1[s, r]:
                            same = False
                    if same:
                        break
                    d, w1, w2 = _scene_pair(end, end.copy(), rad[s], scene, o)
                if d < influence and abs(d) > 1e-12:
                    for r in range(3):
                        u[r] = (w1[r] - w2[r]) / d
                    for c in range(n):
                        g[c] = 0.0
                    _add_gradient(q, F, L, meta, frames, shape_frame[s], w1, u, 1.0, Jbuf,
                                  pbuf, g)
                    if _negligible(g):  # a shape that does not move (on the base): no row
                        continue
                    for c in range(n):
                        G[rows, c] = -g[c]
                    h[rows] = gain * (d - safety)
                    WHO[rows] = idx if part == 0 else -1 - idx
                    rows += 1
            idx += 1
    for p in range(pa.shape[0]):
        i = pa[p]
        j = pb[p]
        d, w1, w2 = CK.capsule_capsule(W0[i].copy(), W1[i].copy(), rad[i], W0[j].copy(),
                                       W1[j].copy(), rad[j])
        DIST[idx] = d
        if d < influence and abs(d) > 1e-12:
            for r in range(3):
                u[r] = (w1[r] - w2[r]) / d
            for c in range(n):
                g[c] = 0.0
            _add_gradient(q, F, L, meta, frames, shape_frame[i], w1, u, 1.0, Jbuf, pbuf, g)
            _add_gradient(q, F, L, meta, frames, shape_frame[j], w2, u, -1.0, Jbuf, pbuf, g)
            if _negligible(g):
                idx += 1
                continue
            for c in range(n):
                G[rows, c] = -g[c]
            h[rows] = gain * (d - safety)
            WHO[rows] = idx
            rows += 1
        idx += 1
    return rows


@dataclass
class ModelCollisionAvoidance(Constraint):
    """Velocity-damper rows from a capsule collision model, a scene and self pairs.

    Attributes:
        scene: scene shapes in the world frame (``Sphere``, ``Capsule``, ``Box``,
            ``HalfSpace``, the infinite ``Cylinder`` along z), or ().
        model: the :class:`~serialkin.model.collision_model.CollisionModel`; None uses the
            robot's ``robot.collision``.
        acm: allowed-collision matrix for the self pairs (default: the model's default).
        self_collision: add rows for the checked self pairs.
        safety: d_s [m].
        influence: d_i [m] (> d_s).
        gain: fraction of ``d − d_s`` the distance may lose per step, (0, 1].

    Raises:
        InputError: influence ≤ safety, no model, a model whose frames do not fit the robot.
    """

    scene: object = ()
    model: object = None
    acm: object = None
    self_collision: bool = True
    safety: float = 0.01
    influence: float = 0.05
    gain: float = 0.5
    _cache: PerObject = field(default_factory=PerObject, init=False, repr=False)

    is_box = False

    def __post_init__(self) -> None:
        from serialkin.collision.shapes import encode_scene

        self._scene = encode_scene(self.scene if self.scene is not None else ())
        self.safety = check_positive(self.safety, "safety", allow_zero=True)
        self.influence = check_positive(self.influence, "influence")
        self.gain = check_positive(self.gain, "gain", maximum=1.0)
        if self.influence <= self.safety:
            raise InputError(f"the influence distance must exceed the safety distance "
                             f"{self.safety:g} m, got {self.influence:g} m")

    def _state(self, robot):
        st = self._cache.get(robot)
        if st is not None:
            return st
        from serialkin.collision.queries import check_model_fits, checked_shape_pairs

        model = self.model if self.model is not None else robot.collision
        if model is None:
            raise InputError(f"robot {robot.name!r} has no collision model: pass model= or "
                             "use robot.with_collision(...)")
        check_model_fits(robot, model)
        if self.self_collision:
            pa, pb = checked_shape_pairs(model, self.acm)
        else:  # read-only as the pairs are: one compiled specialization
            pa = pb = readonly(np.zeros(0, dtype=np.int64))
        total = model.a.shape[0] * self._scene.shape[0] + pa.size
        rows = 3 * model.a.shape[0] * self._scene.shape[0] + pa.size
        st = (robot, model, np.ascontiguousarray(model.shape_frame, dtype=np.int64),
              np.ascontiguousarray(pa, dtype=np.int64), np.ascontiguousarray(pb, dtype=np.int64),
              np.empty((robot.n + 1, 4, 4)), np.empty((rows, robot.n)), np.empty(rows),
              np.empty(total), np.empty(rows, dtype=np.int64))
        self._cache = PerObject()  # the latest robot's state only
        self._cache.set(robot, st)
        self._check_base(robot, model, st)
        return st

    def _check_base(self, robot, model, st) -> None:
        """Shapes on the base frame never move: one inside the scene is an input error."""
        _, _, sf, pa, pb, frames, G, h, DIST, WHO = st
        c = robot.chain
        model_rows_into(np.zeros(robot.n), c.F, c.L, c.meta, sf, model.a, model.b,
                        model.radius, self._scene, pa, pb, -math.inf, self.safety, self.gain,
                        frames, G, h, DIST, WHO)
        k = self._scene.shape[0]
        for s_ in np.flatnonzero(sf == 0):
            for o in range(k):
                d = DIST[s_ * k + o]
                if d < 0.0:
                    body = model.body_names[model.shape_body[s_]]
                    raise InputError(
                        f"scene shape {o} overlaps body {body!r}, which is fixed to the base "
                        f"and cannot move away (signed distance {d:.4g} m): is the scene in "
                        "the world frame of the robot, and its base placed as intended?")

    def distances(self, robot, q: np.ndarray) -> np.ndarray:
        """Signed distance of every pair at q [m]: scene pairs (shape-major), then self pairs."""
        _, model, sf, pa, pb, frames, G, h, DIST, WHO = self._state(robot)
        c = robot.chain
        model_rows_into(np.ascontiguousarray(q, dtype=float), c.F, c.L, c.meta, sf, model.a,
                        model.b, model.radius, self._scene, pa, pb, -math.inf, self.safety,
                        self.gain, frames, G, h, DIST, WHO)
        return DIST.copy()

    def rows(self, ws, q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Rows of the pairs closer than the influence distance."""
        robot = ws.robot
        _, model, sf, pa, pb, frames, G, h, DIST, WHO = self._state(robot)
        c = robot.chain
        r = model_rows_into(q, c.F, c.L, c.meta, sf, model.a, model.b, model.radius,
                            self._scene, pa, pb, self.influence, self.safety, self.gain, frames,
                            G, h, DIST, WHO)
        return G[:r], h[:r]
