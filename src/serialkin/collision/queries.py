"""Self-clearance, scene clearance and collision checks, batch-evaluated.

For configurations ``q`` (shape (..., n)) the link frames come from the public
``robot.fk_all(q)`` (shape (..., n+1, 4, 4)); shape ``s`` of the collision model, fixed to
frame ``f``, has world axis ends ``Aʷ = R_f a_s + p_f`` and ``Bʷ = R_f b_s + p_f``.

* self-clearance: ``min over checked shape pairs (s, t) of ‖c_s − c_t‖ − r_s − r_t`` where
  ``c_s, c_t`` are the closest points of the two world axes; a pair is checked when its
  bodies differ and the allowed-collision matrix does not allow them;
* scene clearance: ``min over shapes s and scene shapes o`` of the signed distances of
  :mod:`serialkin.collision.kernels`;
* in collision: a clearance ``< margin``.

Distances are in metres, negative when shapes overlap (see
:mod:`serialkin.collision.kernels` for what the penetration value means). The batch
kernels are ``@njit(cache=True, nogil=True)`` range kernels run by
:func:`serialkin.kinematics.parallel.run`, over chunks of at most :data:`CHUNK`
configurations (the link frames of one chunk are held in memory).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from serialkin._checks import as_generator, check_int, check_real
from serialkin._memo import PerObject
from serialkin.collision.acm import AllowedCollisionMatrix, default_acm
from serialkin.collision.kernels import _box_sd, _segment_box_t, segment_distance
from serialkin.collision.shapes import encode_scene
from serialkin.errors import InputError
from serialkin.kinematics import parallel
from serialkin.model.collision_model import CollisionModel

from .._jit import njit

__all__ = ["CHUNK", "PAIR_NONE", "PAIR_SCENE", "PAIR_SELF", "Clearance", "body_pair_distances",
           "check_model_fits", "checked_shape_pairs", "clearance_at", "pair_distance_at",
           "scene_point_distance", "in_collision", "sampled_acm", "scene_clearance",
           "self_clearance", "shapes_to_world"]

#: Configurations whose link frames are computed at once (8 frames × 128 B each for a 7-axis arm).
CHUNK = 4096
_GRAIN = 128


@dataclass(frozen=True)
class Clearance:
    """Smallest signed distance and the pair that realises it.

    Attributes:
        distance: (...,) signed distance [m]; +inf when nothing is checked.
        pair: (..., 2) int. Self-clearance: the two body indices (into
            ``model.body_names``, first < second). Scene clearance: the body index and the
            scene index. −1 when nothing is checked.
    """

    distance: np.ndarray
    pair: np.ndarray

    def names(self, model: CollisionModel, scene: bool = False) -> list:
        """The pair(s) as names: ``(body, body)``, or ``(body, scene index)`` for a scene query."""
        flat = self.pair.reshape(-1, 2)
        out = [None if i < 0 else (model.body_names[i], int(j) if scene else model.body_names[j])
               for i, j in flat]
        return out


# ---------------------------------------------------------------- compiled kernels
@njit(cache=True, nogil=True)
def _shape_to_world(F, shape_frame, A, B, W0, W1, s):
    """World axis ends ``W0[s]``, ``W1[s]`` of shape s from the link frames F (n+1, 4, 4)."""
    f = shape_frame[s]
    for r in range(3):
        W0[s, r] = (F[f, r, 0] * A[s, 0] + F[f, r, 1] * A[s, 1] + F[f, r, 2] * A[s, 2]
                    + F[f, r, 3])
        W1[s, r] = (F[f, r, 0] * B[s, 0] + F[f, r, 1] * B[s, 1] + F[f, r, 2] * B[s, 2]
                    + F[f, r, 3])


@njit(cache=True, nogil=True)
def shapes_to_world(F, shape_frame, A, B, W0, W1):
    """World axis ends ``W0``, ``W1`` (m, 3) of every shape from the link frames F (n+1, 4, 4).

    ``W = F[shape_frame[s]] · [A_s; 1]`` (and B_s); shared by the queries here and the
    collision rows of :mod:`serialkin.diffik`. Trusts its input.
    """
    for s in range(A.shape[0]):
        _shape_to_world(F, shape_frame, A, B, W0, W1, s)


@njit(cache=True, nogil=True)
def _pair(W0, W1, i, j):
    """Distance of the world axes of shapes i and j (points passed as tuples: no views)."""
    return segment_distance((W0[i, 0], W0[i, 1], W0[i, 2]), (W1[i, 0], W1[i, 1], W1[i, 2]),
                            (W0[j, 0], W0[j, 1], W0[j, 2]), (W1[j, 0], W1[j, 1], W1[j, 2]))


@njit(cache=True, nogil=True)
def _self_min(W0, W1, rad, pa, pb):
    """(smallest ``dist(axis_i, axis_j) − r_i − r_j`` over the pairs (pa, pb), its index).

    (+inf, −1) when there is no pair; world axis ends in ``W0``, ``W1``.
    """
    best = np.inf
    bp = -1
    for p in range(pa.shape[0]):
        i = pa[p]
        j = pb[p]
        d = _pair(W0, W1, i, j) - rad[i] - rad[j]
        if d < best:
            best = d
            bp = p
    return best, bp


@njit(cache=True, nogil=True)
def self_clearance_range(frames, shape_frame, A, B, rad, pa, pb, out_d, out_p, start, stop):
    """For k in start..stop−1: smallest ``dist(axis_i, axis_j) − r_i − r_j`` over pairs (pa, pb)."""
    m = A.shape[0]
    W0 = np.empty((m, 3))
    W1 = np.empty((m, 3))
    for k in range(start, stop):
        shapes_to_world(frames[k], shape_frame, A, B, W0, W1)
        out_d[k], out_p[k] = _self_min(W0, W1, rad, pa, pb)


@njit(cache=True, nogil=True)
def pair_distances_range(frames, shape_frame, A, B, rad, pa, pb, out, start, stop):
    """For k in start..stop−1: ``out[k, p] = dist(axis_pa[p], axis_pb[p]) − radii``."""
    m = A.shape[0]
    W0 = np.empty((m, 3))
    W1 = np.empty((m, 3))
    for k in range(start, stop):
        shapes_to_world(frames[k], shape_frame, A, B, W0, W1)
        for p in range(pa.shape[0]):
            i = pa[p]
            j = pb[p]
            out[k, p] = _pair(W0, W1, i, j) - rad[i] - rad[j]


@njit(cache=True, nogil=True)
def _shape_scene(W0, W1, s, r, scene, o):
    """Signed distance of robot capsule s (world ends W0[s], W1[s], radius r) to scene shape o.

    Points are passed on as tuples (no array views in the inner loop).
    """
    a0 = (W0[s, 0], W0[s, 1], W0[s, 2])
    a1 = (W1[s, 0], W1[s, 1], W1[s, 2])
    kind = int(scene[o, 0])
    if kind == 0:
        c = (scene[o, 1], scene[o, 2], scene[o, 3])
        return segment_distance(a0, a1, c, c) - r - scene[o, 4]
    if kind == 1:
        return segment_distance(a0, a1, (scene[o, 1], scene[o, 2], scene[o, 3]),
                                (scene[o, 4], scene[o, 5], scene[o, 6])) - r - scene[o, 7]
    if kind == 2:
        c = (scene[o, 1], scene[o, 2], scene[o, 3])
        Rf = (scene[o, 4], scene[o, 5], scene[o, 6], scene[o, 7], scene[o, 8], scene[o, 9],
              scene[o, 10], scene[o, 11], scene[o, 12])
        h = (scene[o, 13], scene[o, 14], scene[o, 15])
        t = _segment_box_t(a0, a1, c, Rf, h)
        return _box_sd(c, Rf, h, a0[0] + t * (a1[0] - a0[0]), a0[1] + t * (a1[1] - a0[1]),
                       a0[2] + t * (a1[2] - a0[2])) - r
    if kind == 3:
        h0 = scene[o, 1] * a0[0] + scene[o, 2] * a0[1] + scene[o, 3] * a0[2]
        h1 = scene[o, 1] * a1[0] + scene[o, 2] * a1[1] + scene[o, 3] * a1[2]
        return min(h0, h1) - scene[o, 4] - r
    # kind 4: infinite cylinder along z: distances in the xy plane
    c = (scene[o, 1], scene[o, 2], 0.0)
    return segment_distance((a0[0], a0[1], 0.0), (a1[0], a1[1], 0.0), c, c) - r - scene[o, 3]


@njit(cache=True, nogil=True)
def _box_bound(W0, W1, s, r, scene, o):
    """A lower bound of the signed distance of capsule s to scene row o (−inf unless a box).

    For a box, ``dist(axis, centre) − r − |h|`` (the box lies inside the sphere of radius
    ``|h|`` about its centre): much cheaper than the exact golden-section distance, so
    that boxes farther than the best pair found so far are skipped.
    """
    if int(scene[o, 0]) != 2:
        return -np.inf
    c = (scene[o, 1], scene[o, 2], scene[o, 3])
    hr = math.sqrt(scene[o, 13] ** 2 + scene[o, 14] ** 2 + scene[o, 15] ** 2)
    return segment_distance((W0[s, 0], W0[s, 1], W0[s, 2]), (W1[s, 0], W1[s, 1], W1[s, 2]),
                            c, c) - r - hr


@njit(cache=True, nogil=True)
def _scene_min(W0, W1, rad, scene, below):
    """(smallest signed distance < ``below`` of a shape to a scene row, shape, row).

    (``below``, −1, −1) when none is smaller; rows whose bounding sphere is farther than
    the best so far are skipped (:func:`_box_bound`).
    """
    best = below
    bs = -1
    bo = -1
    for s in range(W0.shape[0]):
        for o in range(scene.shape[0]):
            if _box_bound(W0, W1, s, rad[s], scene, o) >= best:
                continue
            d = _shape_scene(W0, W1, s, rad[s], scene, o)
            if d < best:
                best = d
                bs = s
                bo = o
    return best, bs, bo


@njit(cache=True, nogil=True)
def scene_clearance_range(frames, shape_frame, A, B, rad, shape_body, scene, out_d, out_p,
                          start, stop):
    """For k in start..stop−1: smallest signed distance of a robot shape to a scene shape."""
    m = A.shape[0]
    W0 = np.empty((m, 3))
    W1 = np.empty((m, 3))
    for k in range(start, stop):
        shapes_to_world(frames[k], shape_frame, A, B, W0, W1)
        best, bs, bo = _scene_min(W0, W1, rad, scene, np.inf)
        out_d[k] = best
        out_p[k, 0] = shape_body[bs] if bs >= 0 else -1
        out_p[k, 1] = bo


@njit(cache=True, nogil=True)
def scene_point_distance(p, scene, o):
    """Signed distance [m] of the point ``p`` (3,) to scene row ``o`` (negative inside)."""
    W = p.reshape(1, 3)
    return _shape_scene(W, W, 0, 0.0, scene, o)


# ---------------------------------------------------------------- one configuration
#: Kinds of closest pair written by :func:`clearance_at` into ``pair[0]``.
PAIR_NONE = 0  # nothing checked (distance +inf)
PAIR_SELF = 1  # pair = (PAIR_SELF, body i, body j), i < j
PAIR_SCENE = 2  # pair = (PAIR_SCENE, body, scene index)


@njit(cache=True, nogil=True)
def clearance_at(frames, shape_frame, A, B, rad, shape_body, pa, pb, scene, W0, W1, pair):
    """Smallest signed distance [m] of one configuration, self pairs and scene together.

    For the link frames ``frames`` (n+1, 4, 4) of one configuration (``fk_all``):
    ``min(min over checked shape pairs (pa[p], pb[p]) of dist(axis_i, axis_j) − r_i − r_j,
    min over shapes s and scene rows o of sd(s, o))``, the per-pair distances of
    :func:`self_clearance_range` and :func:`scene_clearance_range`. The compiled IK loop
    calls it once per candidate solution (no allocation: ``W0``, ``W1`` are (m, 3)
    buffers).

    Args:
        frames: (n+1, 4, 4) link frames.
        shape_frame: (m,) int, the link frame of each shape of the collision model.
        A: (m, 3) first axis end of each shape in its frame [m].
        B: (m, 3) second axis end [m].
        rad: (m,) radii [m].
        shape_body: (m,) int, the body of each shape.
        pa: (P,) first shape of each checked pair (:func:`checked_shape_pairs`; empty: no
            self check).
        pb: (P,) second shape of each checked pair.
        scene: (k, 16) encoded scene (:func:`~serialkin.collision.shapes.encode_scene`;
            k = 0: no scene).
        W0: (m, 3) buffer (world first ends).
        W1: (m, 3) buffer (world second ends).
        pair: (5,) float output: kind (:data:`PAIR_NONE`, :data:`PAIR_SELF`,
            :data:`PAIR_SCENE`), the two indices (bodies, or body and scene row), then
            the shape indices (two shapes, or shape and scene row) for
            :func:`pair_distance_at`.

    Returns:
        The clearance [m]; +inf when nothing is checked.
    """
    shapes_to_world(frames, shape_frame, A, B, W0, W1)
    for k in range(5):
        pair[k] = -1.0
    pair[0] = PAIR_NONE
    best, p = _self_min(W0, W1, rad, pa, pb)
    if p >= 0:
        i = pa[p]
        j = pb[p]
        bi = shape_body[i]
        bj = shape_body[j]
        pair[0] = PAIR_SELF
        pair[1] = min(bi, bj)
        pair[2] = max(bi, bj)
        pair[3] = i
        pair[4] = j
    best, s, o = _scene_min(W0, W1, rad, scene, best)
    if s >= 0:
        pair[0] = PAIR_SCENE
        pair[1] = shape_body[s]
        pair[2] = o
        pair[3] = s
        pair[4] = o
    return best


@njit(cache=True, nogil=True)
def pair_distance_at(frames, shape_frame, A, B, rad, scene, pair, W0, W1):
    """Signed distance [m] of the one pair ``pair`` (as written by :func:`clearance_at`).

    Only the pair's shapes are placed in the world (``W0``, ``W1`` (m, 3) buffers), so a
    gradient by finite differences costs one ``fk_all`` and one distance per step.
    """
    s = int(pair[3])
    t = int(pair[4])
    _shape_to_world(frames, shape_frame, A, B, W0, W1, s)
    if pair[0] == PAIR_SELF:
        _shape_to_world(frames, shape_frame, A, B, W0, W1, t)
        return _pair(W0, W1, s, t) - rad[s] - rad[t]
    return _shape_scene(W0, W1, s, rad[s], scene, t)


# ---------------------------------------------------------------- Python front ends
def check_model_fits(robot, model: CollisionModel) -> None:
    """Check that ``model`` is a :class:`CollisionModel` whose bodies sit on frames of ``robot``.

    Every query of this module calls it first; other layers building on the queries (the
    collision constraint of :mod:`serialkin.diffik`) call it too, so that a model of
    another robot is refused with the same message.

    Raises:
        InputError: ``model`` is not a CollisionModel, or one of its bodies is fixed to a
            frame beyond ``robot``'s frames 0..n (the message names the body).
    """
    if not isinstance(model, CollisionModel):
        raise InputError(f"model must be a CollisionModel, got {type(model).__name__}")
    if len(model.body_frames) and model.body_frames.max() > robot.n:
        i = int(np.argmax(model.body_frames > robot.n))
        raise InputError(f"model body {model.body_names[i]!r} is fixed to frame "
                         f"{model.body_frames[i]}, but robot {robot.name!r} has frames "
                         f"0..{robot.n}")


#: Per model (immutable): the pairs of its default matrix (key None) and, per matrix
#: given (immutable too), that matrix's pairs.
_PAIRS: PerObject[tuple[dict, PerObject]] = PerObject()


def checked_shape_pairs(model: CollisionModel,
                        acm: AllowedCollisionMatrix | None = None) -> tuple[np.ndarray, np.ndarray]:
    """Shape index pairs (s < t) whose bodies differ and are not allowed by ``acm``.

    Returns:
        Two (P,) int arrays (read-only; cached per model and matrix, both immutable).
        ``acm`` defaults to :func:`default_acm`.
    """
    default, given = _PAIRS.setdefault(model, lambda: ({}, PerObject()))
    hit = default.get(None) if acm is None else given.get(acm)
    if hit is not None:
        return hit
    full = default_acm(model) if acm is None else acm
    if not isinstance(full, AllowedCollisionMatrix) or full.body_names != model.body_names:
        raise InputError("acm must be an AllowedCollisionMatrix over the model's bodies "
                         f"{model.body_names}")
    sb = model.shape_body
    s, t = np.triu_indices(len(sb), 1)
    keep = ~full.allowed[sb[s], sb[t]]
    pa, pb = np.ascontiguousarray(s[keep]), np.ascontiguousarray(t[keep])
    pa.setflags(write=False)
    pb.setflags(write=False)
    if acm is None:
        default[None] = (pa, pb)
    else:
        given.set(acm, (pa, pb))
    return pa, pb


def _batches(robot, q: object):
    """Yield (slice, frames) over chunks of the flattened batch; also the batch shape first."""
    qa = robot.check_q(q)
    flat = qa.reshape(-1, robot.n)
    yield qa.shape[:-1]
    for lo in range(0, flat.shape[0], CHUNK):
        sl = slice(lo, min(lo + CHUNK, flat.shape[0]))
        yield sl, np.ascontiguousarray(robot.fk_all(flat[sl]))


def self_clearance(robot, model: CollisionModel, q: object,
                   acm: AllowedCollisionMatrix | None = None) -> Clearance:
    """Smallest signed distance between checked body pairs, and which pair.

    Args:
        robot: the :class:`serialkin.Robot` whose ``fk_all`` places the frames.
        model: the collision model (bodies on frames 0..n).
        q: joint values, shape (..., n) [rad or m].
        acm: allowed-collision matrix (default :func:`default_acm`).

    Returns:
        :class:`Clearance` with ``distance`` (...,) [m] and ``pair`` (..., 2) body indices.
    """
    check_model_fits(robot, model)
    pa, pb = checked_shape_pairs(model, acm)
    it = _batches(robot, q)
    shape = next(it)
    N = int(np.prod(shape, dtype=np.int64))
    d = np.empty(N)
    p = np.empty(N, dtype=np.int64)
    sf = np.ascontiguousarray(model.shape_frame)
    for sl, frames in it:
        dv, pv = d[sl], p[sl]
        parallel.run(self_clearance_range, (frames, sf, model.a, model.b, model.radius, pa, pb,
                                            dv, pv), frames.shape[0], _GRAIN)
    pair = np.full((N, 2), -1, dtype=np.int64)
    ok = p >= 0
    sb = model.shape_body
    pair[ok, 0] = np.minimum(sb[pa[p[ok]]], sb[pb[p[ok]]])
    pair[ok, 1] = np.maximum(sb[pa[p[ok]]], sb[pb[p[ok]]])
    return Clearance(d.reshape(shape), pair.reshape(shape + (2,)))


def body_pair_distances(robot, model: CollisionModel, q: object,
                        acm: AllowedCollisionMatrix | None = None
                        ) -> tuple[list[tuple[int, int]], np.ndarray]:
    """Smallest signed distance of every checked body pair in every configuration.

    Args:
        robot: the robot.
        model: its collision model.
        q: joint values, shape (N, n).
        acm: pairs to skip; default: only bodies on the same frame are skipped.

    Returns:
        The body pairs ``[(i, j), ...]`` (i < j, P of them) and distances (N, P) [m].
    """
    check_model_fits(robot, model)
    if acm is None:
        f = model.body_frames
        acm = AllowedCollisionMatrix(model.body_names, f[:, None] == f[None, :])
    pa, pb = checked_shape_pairs(model, acm)
    sb = model.shape_body
    bi, bj = np.minimum(sb[pa], sb[pb]), np.maximum(sb[pa], sb[pb])
    pairs = sorted(set(zip(bi.tolist(), bj.tolist(), strict=True)))
    it = _batches(robot, q)
    shape = next(it)
    N = int(np.prod(shape, dtype=np.int64))
    ds = np.empty((N, len(pa)))
    sf = np.ascontiguousarray(model.shape_frame)
    for sl, frames in it:
        parallel.run(pair_distances_range, (frames, sf, model.a, model.b, model.radius, pa, pb,
                                            ds[sl]), frames.shape[0], _GRAIN)
    out = np.full((N, len(pairs)), np.inf)
    for c, (i, j) in enumerate(pairs):
        cols = (bi == i) & (bj == j)
        out[:, c] = ds[:, cols].min(axis=1)
    return pairs, out


def sampled_acm(robot, model: CollisionModel, acm: AllowedCollisionMatrix | None = None, *,
                samples: int = 1000, seed: object = 0,
                margin: float = 0.0, never: bool = False) -> AllowedCollisionMatrix:
    """Add to ``acm`` (default: :func:`default_acm`) the pairs in contact in every sample.

    ``samples`` configurations are drawn uniformly within ``robot.qlim`` (±π where a joint
    is unlimited) with the generator made from ``seed``; a body pair is in contact when
    the smallest signed distance between their shapes is ≤ ``margin`` [m]. With
    ``never=True`` the pairs in contact in *no* sample are allowed too (MoveIt's setup
    assistant's "never in collision": they cost checks and find nothing).

    Returns:
        The matrix with those pairs allowed (pairs without shapes are left as they are).
    """
    samples = check_int(samples, "samples", minimum=1, maximum=10**7)
    margin = check_real(margin, "margin", unit="m")
    rng = as_generator(seed)
    lo, hi = robot.qlim[:, 0].copy(), robot.qlim[:, 1].copy()
    lo[~np.isfinite(lo)] = -np.pi
    hi[~np.isfinite(hi)] = np.pi
    q = lo + (hi - lo) * rng.random((samples, robot.n))
    pairs, d = body_pair_distances(robot, model, q)
    contact = d <= margin
    always = contact.all(axis=0) | (~contact.any(axis=0) if never else False)
    base = default_acm(model) if acm is None else acm
    return base.allow((model.body_names[i], model.body_names[j])
                      for (i, j), yes in zip(pairs, always, strict=True) if yes)


def scene_clearance(robot, model: CollisionModel, q: object, scene) -> Clearance:
    """Smallest signed distance of any robot shape to any scene shape, and which pair.

    Args:
        robot: the robot.
        model: its collision model.
        q: joint values, shape (..., n).
        scene: a shape or a sequence of shapes of :mod:`serialkin.model.geometry` in
            the world frame: ``Sphere``, ``Capsule``, ``Box``, ``HalfSpace`` and the
            infinite ``Cylinder`` along z (see :func:`~serialkin.collision.shapes.encode_scene`).

    Returns:
        :class:`Clearance`: ``distance`` (...,) [m], ``pair`` (..., 2) = (body, scene index).
    """
    check_model_fits(robot, model)
    enc = encode_scene(scene)
    it = _batches(robot, q)
    shape = next(it)
    N = int(np.prod(shape, dtype=np.int64))
    d = np.empty(N)
    p = np.empty((N, 2), dtype=np.int64)
    sf = np.ascontiguousarray(model.shape_frame)
    for sl, frames in it:
        parallel.run(scene_clearance_range, (frames, sf, model.a, model.b, model.radius,
                                             model.shape_body, enc, d[sl], p[sl]),
                     frames.shape[0], max(8, _GRAIN // max(1, len(enc))))
    return Clearance(d.reshape(shape), p.reshape(shape + (2,)))


def in_collision(robot, model: CollisionModel, q: object,
                 acm: AllowedCollisionMatrix | None = None, scene=None, *,
                 margin: float = 0.0) -> np.ndarray:
    """True where the self-clearance or the scene clearance is below ``margin`` [m].

    ``margin = 0`` flags overlapping shapes (touching is not a collision); a positive margin
    also flags shapes closer than it. Returns a bool array of shape (...,).
    """
    margin = check_real(margin, "margin", unit="m")
    hit = self_clearance(robot, model, q, acm).distance < margin
    if scene is not None:
        hit |= scene_clearance(robot, model, q, scene).distance < margin
    return hit

