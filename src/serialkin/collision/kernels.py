"""Compiled signed-distance kernels between primitive shapes, with witness points.

Shapes (all lengths in metres, every point a 3-vector in one common frame):

* **sphere** — centre ``c``, radius ``r``: the points within ``r`` of ``c``;
* **capsule** — segment ``a b`` and radius ``r``: the points within ``r`` of the segment
  (a sphere is the capsule with ``a = b``);
* **box** — centre ``c``, rotation ``R`` (3, 3) whose columns are the box axes, half
  extents ``h`` (3,): the points ``c + R u`` with ``|u_k| ≤ h_k``;
* **half-space** — unit normal ``n`` and offset ``o``: the solid ``{x : nᵀx ≤ o}`` (a
  table top is ``n = (0, 0, 1)``, ``o`` its height: the solid lies below the plane).

Every kernel returns ``(d, w1, w2)``: ``d`` the signed distance [m] and the witness points
``w1`` on (or in) the first shape and ``w2`` on (or in) the second.

* Separated shapes: ``d = ‖w1 − w2‖ > 0``, the distance between the closest points.
* Touching shapes: ``d = 0``.
* Overlapping shapes: ``d < 0`` and ``−d`` is a penetration depth:

  - sphere/capsule pairs: ``d = ‖s1 − s2‖ − r1 − r2`` with ``s1, s2`` the closest points of
    the two centre segments; ``−d`` is the exact penetration depth (the length of the
    shortest translation that separates the shapes) as long as the centre segments do not
    cross. When they cross (``s1 = s2``) the kernel returns ``d = −(r1 + r2)``, a lower
    bound on the depth, with the separating direction taken normal to both segments;
  - sphere/capsule against a half-space: ``d = min over the segment of (nᵀs − o) − r``,
    the exact penetration depth;
  - sphere against a box: ``d = sd_box(c) − r`` with ``sd_box`` the exact signed distance of
    a point to the box (negative inside: minus the distance to the nearest face); ``−d`` is
    the exact penetration depth;
  - capsule against a box: ``d = min over the segment of sd_box(s) − r``; ``−d`` is the
    depth of the deepest point of the capsule, a lower bound on the penetration depth
    (exact when the capsule pokes into the box by one end).

  When overlapping, ``w1`` is the deepest point of shape 1 and ``w2`` the point of shape 2's
  surface it must reach, so that ``‖w1 − w2‖ = −d`` wherever the depth is exact.

Closest points of two segments come from
:func:`serialkin.spatial.segments.closest_segment_segment` (Ericson's clamped
solution, robust for parallel and zero-length segments), the one implementation of that
idea in the package. The capsule–box distance minimises the convex function
``t ↦ sd_box(a + t (b − a))`` over ``t ∈ [0, 1]`` by golden-section search
(:data:`GOLDEN_STEPS` steps: the bracket shrinks below the floating-point resolution of t).

All kernels are ``@njit(cache=True, nogil=True)`` and trust their input (validation is done
by :mod:`serialkin.collision.shapes`).
"""

from __future__ import annotations

import math

import numpy as np

from serialkin.spatial.segments import closest_segment_segment

from .._jit import njit

__all__ = [
    "GOLDEN_STEPS",
    "box_point",
    "capsule_box",
    "capsule_capsule",
    "capsule_halfspace",
    "capsule_sphere",
    "segment_distance",
    "sphere_box",
    "sphere_halfspace",
    "sphere_sphere",
]

#: Golden-section steps of the capsule–box search: 0.618**90 ≈ 1e-19 of the segment.
GOLDEN_STEPS = 90
_INVPHI = (math.sqrt(5.0) - 1.0) / 2.0


@njit(cache=True, nogil=True)
def segment_distance(a0, a1, b0, b1):
    """Distance [m] between segments ``a0 a1`` and ``b0 b1`` (each point a 3-tuple).

    ``min_{s,t ∈ [0,1]} ‖a0 + s (a1 − a0) − b0 − t (b1 − b0)‖``; no allocation (used by the
    batch kernels, which pass the points as tuples).
    """
    s, t = closest_segment_segment(a0, a1, b0, b1)
    dx = a0[0] + s * (a1[0] - a0[0]) - b0[0] - t * (b1[0] - b0[0])
    dy = a0[1] + s * (a1[1] - a0[1]) - b0[1] - t * (b1[1] - b0[1])
    dz = a0[2] + s * (a1[2] - a0[2]) - b0[2] - t * (b1[2] - b0[2])
    return math.sqrt(dx * dx + dy * dy + dz * dz)


@njit(cache=True, nogil=True)
def _crossing_direction(a0, a1, b0, b1):
    """A unit vector normal to both segments (any unit vector when they are parallel)."""
    u = a1 - a0
    v = b1 - b0
    w = np.cross(u, v)
    nw = math.sqrt(w[0] * w[0] + w[1] * w[1] + w[2] * w[2])
    if nw > 1e-12 * (1.0 + np.dot(u, u) + np.dot(v, v)):
        return w / nw
    # parallel or degenerate: any unit vector normal to the longer one
    d = u if np.dot(u, u) >= np.dot(v, v) else v
    k = 0 if abs(d[0]) <= abs(d[1]) and abs(d[0]) <= abs(d[2]) else (
        1 if abs(d[1]) <= abs(d[2]) else 2)
    e = np.zeros(3)
    e[k] = 1.0
    w = np.cross(d, e)
    nw = math.sqrt(np.dot(w, w))
    if nw == 0.0:
        return e
    return w / nw


@njit(cache=True, nogil=True)
def capsule_capsule(a0, a1, ra, b0, b1, rb):
    """Signed distance of capsule (a0 a1, ra) to capsule (b0 b1, rb) and witness points.

    ``d = ‖sa − sb‖ − ra − rb`` with ``sa, sb`` the closest points of the two segments;
    ``w1 = sa − ra u``, ``w2 = sb + rb u``, ``u = (sa − sb)/‖sa − sb‖`` (see the module
    docstring for crossing segments). Points shape (3,), radii [m]; returns (float, (3,), (3,)).
    """
    # the points as tuples, as the batch kernels pass them: closest_segment_segment
    # compiles once
    s, t = closest_segment_segment((a0[0], a0[1], a0[2]), (a1[0], a1[1], a1[2]),
                                   (b0[0], b0[1], b0[2]), (b1[0], b1[1], b1[2]))
    sa = a0 + s * (a1 - a0)
    sb = b0 + t * (b1 - b0)
    diff = sa - sb
    dist = math.sqrt(diff[0] * diff[0] + diff[1] * diff[1] + diff[2] * diff[2])
    if dist > 0.0:
        u = diff / dist
    else:
        u = _crossing_direction(a0, a1, b0, b1)
    return dist - ra - rb, sa - ra * u, sb + rb * u


@njit(cache=True, nogil=True)
def capsule_sphere(a0, a1, ra, c, rc):
    """Signed distance of capsule (a0 a1, ra) to sphere (c, rc) and witness points."""
    return capsule_capsule(a0, a1, ra, c, c, rc)


@njit(cache=True, nogil=True)
def sphere_sphere(c1, r1, c2, r2):
    """Signed distance ``‖c1 − c2‖ − r1 − r2`` of two spheres and witness points."""
    return capsule_capsule(c1, c1, r1, c2, c2, r2)


@njit(cache=True, nogil=True)
def box_point(c, R, h, p):
    """Signed distance of point ``p`` to the box (c, R, h) and the closest boundary point.

    In box coordinates ``u = Rᵀ(p − c)``, ``e = |u| − h``: outside,
    ``sd = ‖max(e, 0)‖`` and the closest point clamps ``u`` to the box; inside,
    ``sd = max_k e_k ≤ 0`` and the closest point moves ``u`` onto that nearest face.
    Returns (sd [m], point (3,) in the common frame).
    """
    u = R.T @ (p - c)
    q = np.empty(3)
    out2 = 0.0
    inside = True
    kmax = 0
    emax = -np.inf
    for k in range(3):
        e = abs(u[k]) - h[k]
        if e > 0.0:
            inside = False
            out2 += e * e
        if e > emax:
            emax = e
            kmax = k
        q[k] = min(max(u[k], -h[k]), h[k])
    if inside:
        q[kmax] = h[kmax] if u[kmax] >= 0.0 else -h[kmax]
        return emax, c + R @ q
    return math.sqrt(out2), c + R @ q


@njit(cache=True, nogil=True)
def _box_sd(c, Rf, h, x, y, z):
    """Signed distance of point (x, y, z) to the box; ``Rf[3 r + k] = R[r, k]`` (no allocation).

    ``c``, ``h`` (3-)tuples and ``Rf`` a 9-tuple, as :func:`_segment_box_t` passes them.
    """
    px = x - c[0]
    py = y - c[1]
    pz = z - c[2]
    out2 = 0.0
    emax = -np.inf
    for k in range(3):
        u = Rf[k] * px + Rf[3 + k] * py + Rf[6 + k] * pz
        e = abs(u) - h[k]
        if e > 0.0:
            out2 += e * e
        if e > emax:
            emax = e
    if out2 > 0.0:
        return math.sqrt(out2)
    return emax


@njit(cache=True, nogil=True)
def _segment_box_t(a0, a1, c, Rf, h):
    """Parameter t ∈ [0, 1] minimising the convex signed distance of a0 + t(a1 − a0) to the box.

    Points, ``c`` and ``h`` are tuples; ``Rf`` is the box rotation flattened row-major,
    a tuple of 9 numbers.
    """
    dx = a1[0] - a0[0]
    dy = a1[1] - a0[1]
    dz = a1[2] - a0[2]
    if dx == 0.0 and dy == 0.0 and dz == 0.0:
        return 0.0
    lo = 0.0
    hi = 1.0
    m1 = hi - _INVPHI * (hi - lo)
    m2 = lo + _INVPHI * (hi - lo)
    f1 = _box_sd(c, Rf, h, a0[0] + m1 * dx, a0[1] + m1 * dy, a0[2] + m1 * dz)
    f2 = _box_sd(c, Rf, h, a0[0] + m2 * dx, a0[1] + m2 * dy, a0[2] + m2 * dz)
    for _ in range(GOLDEN_STEPS):
        if f1 <= f2:
            hi = m2
            m2 = m1
            f2 = f1
            m1 = hi - _INVPHI * (hi - lo)
            f1 = _box_sd(c, Rf, h, a0[0] + m1 * dx, a0[1] + m1 * dy, a0[2] + m1 * dz)
        else:
            lo = m1
            m1 = m2
            f1 = f2
            m2 = lo + _INVPHI * (hi - lo)
            f2 = _box_sd(c, Rf, h, a0[0] + m2 * dx, a0[1] + m2 * dy, a0[2] + m2 * dz)
    best = 0.5 * (lo + hi)
    fb = _box_sd(c, Rf, h, a0[0] + best * dx, a0[1] + best * dy, a0[2] + best * dz)
    # the minimum of a convex function on [0, 1] may sit at an end
    f0 = _box_sd(c, Rf, h, a0[0], a0[1], a0[2])
    if f0 < fb:
        best, fb = 0.0, f0
    fe = _box_sd(c, Rf, h, a1[0], a1[1], a1[2])
    if fe < fb:
        best = 1.0
    return best


@njit(cache=True, nogil=True)
def sphere_box(c, r, bc, R, h):
    """Signed distance ``sd_box(c) − r`` of sphere (c, r) to box (bc, R, h), witness points."""
    sd, q = box_point(bc, R, h, c)
    diff = c - q
    nd = math.sqrt(np.dot(diff, diff))
    if nd > 0.0:
        u = diff / nd if sd > 0.0 else -diff / nd
    else:  # the centre lies on the boundary: the outward normal of the face it lies on
        e = np.abs(R.T @ (c - bc)) - h
        k = int(np.argmax(e))
        axis = np.array([R[0, k], R[1, k], R[2, k]])
        u = axis if np.dot(axis, c - bc) >= 0.0 else -axis
    return sd - r, c - r * u, q


@njit(cache=True, nogil=True)
def capsule_box(a0, a1, r, bc, R, h):
    """Signed distance ``min_t sd_box(a0 + t(a1 − a0)) − r`` of a capsule to a box, witnesses."""
    # tuples, as the batch kernels pass them (:mod:`serialkin.collision.queries`):
    # _segment_box_t compiles once
    t = _segment_box_t((a0[0], a0[1], a0[2]), (a1[0], a1[1], a1[2]), (bc[0], bc[1], bc[2]),
                       (R[0, 0], R[0, 1], R[0, 2], R[1, 0], R[1, 1], R[1, 2], R[2, 0], R[2, 1],
                        R[2, 2]), (h[0], h[1], h[2]))
    return sphere_box(a0 + t * (a1 - a0), r, bc, R, h)


@njit(cache=True, nogil=True)
def capsule_halfspace(a0, a1, r, n, o):
    """Signed distance ``min(nᵀa0, nᵀa1) − o − r`` of a capsule to the half-space nᵀx ≤ o.

    ``n`` must be a unit vector. Witnesses: ``w1 = s − r n`` with ``s`` the lower end
    (``a0`` on a tie), ``w2 = w1 − d n`` its projection onto the plane.
    """
    h0 = np.dot(n, a0)
    h1 = np.dot(n, a1)
    s = a0 if h0 <= h1 else a1
    d = min(h0, h1) - o - r
    w1 = s - r * n
    return d, w1, w1 - d * n


@njit(cache=True, nogil=True)
def sphere_halfspace(c, r, n, o):
    """Signed distance ``nᵀc − o − r`` of a sphere to the half-space nᵀx ≤ o, witnesses."""
    return capsule_halfspace(c, c, r, n, o)
