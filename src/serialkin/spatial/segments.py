"""Closest points of two line segments: the one compiled kernel of that idea.

Used by the link-obstacle geometry of the redundancy resolver (eqs 51-53) and by the
collision distance kernels (capsules are segments with a radius). Kernels trust their input;
validation happens at the public boundary.
"""

from __future__ import annotations

from .._jit import njit

#: sin²θ of two segments' directions below which their closest points are computed from
#: cross products (:func:`closest_segment_segment`).
NEAR_PARALLEL = 1e-4
#: sin²θ below which two segments are parallel (θ < 1e-14 rad: rounding of the directions).
PARALLEL = 1e-28


@njit(cache=True, nogil=True)
def closest_segment_segment(p0, p1, a, b):
    """Parameters (s, t) of the closest points of segments p0p1 and ab (Ericson).

    Minimises ``‖(p0 + s (p1 − p0)) − (a + t (b − a))‖`` over ``s, t ∈ [0, 1]``: the
    unconstrained minimiser of the two lines, clamped to the segments and re-projected
    (C. Ericson, *Real-Time Collision Detection*, 2005, §5.1.9), its determinant
    ``aa·ee − bb² = |d1 × d2|²`` taken from the cross product when the segments are
    nearly parallel (:data:`NEAR_PARALLEL`). Parallel segments (:data:`PARALLEL`) take
    s = 0; zero-length segments are points.

    Points are ``(x, y, z)`` tuples: every caller passes its points as tuples (registers,
    no array views), so that the kernel compiles once.

    Args:
        p0: first end of the first segment [m].
        p1: second end of the first segment [m].
        a: first end of the second segment [m].
        b: second end of the second segment [m].

    Returns:
        (s, t), each in [0, 1].
    """
    d1x = p1[0] - p0[0]
    d1y = p1[1] - p0[1]
    d1z = p1[2] - p0[2]
    d2x = b[0] - a[0]
    d2y = b[1] - a[1]
    d2z = b[2] - a[2]
    rx = p0[0] - a[0]
    ry = p0[1] - a[1]
    rz = p0[2] - a[2]
    aa = d1x * d1x + d1y * d1y + d1z * d1z
    ee = d2x * d2x + d2y * d2y + d2z * d2z
    ff = d2x * rx + d2y * ry + d2z * rz
    eps = 1e-18
    if aa <= eps and ee <= eps:
        return 0.0, 0.0
    if aa <= eps:
        return 0.0, min(max(ff / ee, 0.0), 1.0)
    cc = d1x * rx + d1y * ry + d1z * rz
    if ee <= eps:
        return min(max(-cc / aa, 0.0), 1.0), 0.0
    bb = d1x * d2x + d1y * d2y + d1z * d2z
    den = aa * ee - bb * bb
    num = bb * ff - cc * ee
    if den <= NEAR_PARALLEL * aa * ee:
        # nearly parallel: aa·ee − bb² = |d1 × d2|² cancels to a relative error of about
        # 1e-16/sin²θ (1 % at θ = 1e-7 rad, which put touching segments 4e-10 m apart);
        # by Lagrange's identity den = |d1 × d2|² and num = (d1 × d2)·(d2 × r), whose
        # cross products lose only 1e-16/sin θ
        cx = d1y * d2z - d1z * d2y
        cy = d1z * d2x - d1x * d2z
        cz = d1x * d2y - d1y * d2x
        den = cx * cx + cy * cy + cz * cz
        num = (cx * (d2y * rz - d2z * ry) + cy * (d2z * rx - d2x * rz)
               + cz * (d2x * ry - d2y * rx))
        if den <= PARALLEL * aa * ee:
            den = 0.0
    s = min(max(num / den, 0.0), 1.0) if den > eps else 0.0
    t = (bb * s + ff) / ee
    if t < 0.0:
        t = 0.0
        s = min(max(-cc / aa, 0.0), 1.0)
    elif t > 1.0:
        t = 1.0
        s = min(max((bb - cc) / aa, 0.0), 1.0)
    return s, t
