"""Compiled geometric subproblems shared by the closed-form solvers (numba, ``cache=True``).

The closed-form solvers work on the product-of-exponentials form of the chain at its
zero configuration (see :mod:`serialkin.ik.analytic.structure`): joint *i* is a line
with unit direction ``w_i`` through a point ``r_i`` (world frame, q = 0), and

``T(q) = exp(ξ_1 q_1) ··· exp(ξ_n q_n) · M``,  ``M = T(0)``.

So every DH variant (standard, modified) and every general joint description reduce to
the same few geometric subproblems (Paden–Kahan; R. M. Murray, Z. Li, S. S. Sastry,
*A Mathematical Introduction to Robotic Manipulation*, CRC 1994, section 3.3):

* :func:`sp1_dir` — the rotation about ``w`` that carries one vector onto another;
* :func:`sp2_dir` — two rotations about intersecting axes carrying ``u`` onto ``v``;
* :func:`sp3` — the rotation that puts a point at a given distance from another;
  :func:`sp3_slide` — the same for a translation along a line;
* :func:`sp4` — the rotation that gives a rotated vector a given projection, ``a·R b = c``;
* :func:`planar2r` — the two-link planar arm of the chapter (eqs 23-27, corrected per
  the ERRATA), on any pair of parallel axes.

Every function writes its (at most two) solutions into ``out`` and returns their
count; the count is 0 when the sub-target is out of reach. Arguments slightly outside
the domain of arccos (within :data:`CLAMP`) are clamped, so targets on the workspace
boundary keep their (double) solution. Angles in radians, lengths in metres. Kernels
trust their input.

Vectors: the subproblems and the small helpers of the section "3-vectors as tuples"
take 3-vectors as ``(x, y, z)`` tuples of floats, always (numba compiles a function
once per set of argument types, and a tuple and an array are two: issue 27); a solver
holding a vector in an array row passes :func:`row3` of its (read-only) structure
array, one in a (3,) array of its own :func:`tup3`. The helpers that return new arrays
(:func:`cross3`, :func:`mv`, :func:`rotation`, :func:`rotate_point`, ...) take (3,)
float64 arrays.
"""

from __future__ import annotations

import math

import numpy as np

from serialkin.kinematics.kernels import fk_range

from ..._jit import njit

#: arccos arguments within this distance of ±1 are clamped (workspace boundary).
CLAMP = 1e-9
#: arccos arguments within this distance of ±1 give exactly 0 / π (one merged branch).
SNAP = 1e-14
#: Two solutions closer than this in every joint (after wrapping) are one solution.
DUPLICATE_TOL = 1e-9
#: Elbow cosines this far beyond ±1 still seed a nearly ideal arm's two elbow branches
#: (:func:`planar2r_solve`); see docs/ik-analytic.md for the measurement.
ELBOW_SLACK = 0.25
#: Smallest half-angle [rad] between the two seeds a nearly ideal arm's subproblem gives at
#: or beyond a tangency (:func:`acos_seed`): Newton's method from either side of a fold
#: converges to the solution on that side, never from the fold itself.
SEED_GAP = 1e-3
#: A nearly ideal arm's seed within this angle [rad] of its wrist singularity (the axis
#: after the wrist parallel to the one before it) gets two more seeds along the ideal
#: wrist's continuum (``spherical_wrist.wrist_into``, ``ur.ur_candidates``).
WRIST_SEED = 0.05
#: Solutions within this distance outside a joint limit are clipped onto it.
LIMIT_TOL = 1e-10
TWO_PI = 2.0 * math.pi


@njit(cache=True)
def sort_prefix(x, n):
    """Sort ``x[:n]`` ascending in place (insertion sort, for the few values of a kernel).

    Not ``np.sort``, whose quicksort compiles for 1.6 s in every process that compiles a
    kernel calling it.
    """
    for i in range(1, n):
        v = x[i]
        j = i - 1
        while j >= 0 and x[j] > v:
            x[j + 1] = x[j]
            j -= 1
        x[j + 1] = v


@njit(cache=True)
def dot3(a, b):
    """Dot product of two 3-vectors."""
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]


@njit(cache=True)
def cross3(a, b):
    """Cross product of two 3-vectors, a new (3,) array."""
    out = np.empty(3)
    out[0] = a[1] * b[2] - a[2] * b[1]
    out[1] = a[2] * b[0] - a[0] * b[2]
    out[2] = a[0] * b[1] - a[1] * b[0]
    return out


@njit(cache=True)
def mm(A, B):
    """Matrix product of small matrices (loops, no BLAS), a new array.

    ``Aᵀ·B`` is ``mm(A.T, B)`` (a transposed view, same summation order).
    """
    n, k = A.shape
    m = B.shape[1]
    C = np.zeros((n, m))
    for i in range(n):
        for j in range(m):
            acc = 0.0
            for t in range(k):
                acc += A[i, t] * B[t, j]
            C[i, j] = acc
    return C


@njit(cache=True)
def mv(A, v):
    """``A[:3, :3]·v`` for a (3, 3) or (4, 4) matrix and a 3-vector."""
    out = np.empty(3)
    for i in range(3):
        out[i] = A[i, 0] * v[0] + A[i, 1] * v[1] + A[i, 2] * v[2]
    return out


@njit(cache=True)
def mtv(A, v):
    """``A[:3, :3]ᵀ·v`` for a (3, 3) or (4, 4) matrix and a 3-vector."""
    out = np.empty(3)
    for i in range(3):
        out[i] = A[0, i] * v[0] + A[1, i] * v[1] + A[2, i] * v[2]
    return out


# --- 3-vectors as tuples ------------------------------------------------------------------
#
# A numba function that returns a new (3,) array pays for a heap allocation (30-50 ns),
# which dominated the closed forms (about 100 per pose). The closed forms instead carry
# vectors as (x, y, z) tuples, which live in registers. The functions below take their
# vectors as tuples only (never array rows: each kind of argument compiles a function
# once more); :func:`row3` reads a row of the solvers' read-only (m, 3) arrays as one,
# :func:`tup3` a (3,) array the array-based solvers computed.


@njit(cache=True)
def row3(a, i):
    """Row i of a read-only (m, 3) array (or the first three entries of row i) as a tuple."""
    return (a[i, 0], a[i, 1], a[i, 2])


@njit(cache=True)
def tup3(a):
    """A (3,) array as a tuple (the array-based solvers' own fresh, writeable arrays)."""
    return (a[0], a[1], a[2])


@njit(cache=True)
def add3(a, b):
    """``a + b`` of two 3-vectors, a tuple."""
    return (a[0] + b[0], a[1] + b[1], a[2] + b[2])


@njit(cache=True)
def sub3(a, b):
    """``a − b`` of two 3-vectors, a tuple."""
    return (a[0] - b[0], a[1] - b[1], a[2] - b[2])


@njit(cache=True)
def cross3t(a, b):
    """Cross product of two 3-vectors, a tuple (see :func:`cross3` for an array)."""
    return (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])


@njit(cache=True)
def mv3(A, v):
    """``A[:3, :3]·v`` as a tuple (A a (3, 3) or (4, 4) array)."""
    return (A[0, 0] * v[0] + A[0, 1] * v[1] + A[0, 2] * v[2],
            A[1, 0] * v[0] + A[1, 1] * v[1] + A[1, 2] * v[2],
            A[2, 0] * v[0] + A[2, 1] * v[1] + A[2, 2] * v[2])


@njit(cache=True)
def mtv3(A, v):
    """``A[:3, :3]ᵀ·v`` as a tuple (A a (3, 3) or (4, 4) array)."""
    return (A[0, 0] * v[0] + A[1, 0] * v[1] + A[2, 0] * v[2],
            A[0, 1] * v[0] + A[1, 1] * v[1] + A[2, 1] * v[2],
            A[0, 2] * v[0] + A[1, 2] * v[1] + A[2, 2] * v[2])


@njit(cache=True)
def rot3(w, c, s, v):
    """``Rot(w, θ)·v`` as a tuple from ``c = cos θ``, ``s = sin θ`` (Rodrigues).

    ``Rot(w, θ)ᵀ·v = Rot(w, −θ)·v`` is ``rot3(w, c, -s, v)``: one sin/cos per joint.
    """
    k = (w[0] * v[0] + w[1] * v[1] + w[2] * v[2]) * (1.0 - c)
    return (v[0] * c + (w[1] * v[2] - w[2] * v[1]) * s + w[0] * k,
            v[1] * c + (w[2] * v[0] - w[0] * v[2]) * s + w[1] * k,
            v[2] * c + (w[0] * v[1] - w[1] * v[0]) * s + w[2] * k)


@njit(cache=True)
def target_rotation(T, M):
    """``R_T·R_Mᵀ`` (3, 3): the rotation the joints must produce, from poses T and M (4, 4)."""
    R = np.empty((3, 3))
    for i in range(3):
        for j in range(3):
            R[i, j] = T[i, 0] * M[j, 0] + T[i, 1] * M[j, 1] + T[i, 2] * M[j, 2]
    return R


@njit(cache=True)
def target_point(T, M, p):
    """Where the target pose puts a point p fixed to the tool, and the rotation to produce.

    Returns ``(T·M⁻¹·p, R_T·R_Mᵀ)``: the point (3,) [m] for p (3,) given at q = 0, e.g. a
    spherical wrist's centre, and the (3, 3) rotation the joints must produce.
    """
    Rg = target_rotation(T, M)
    return mv(Rg, p - M[:3, 3]) + T[:3, 3], Rg


@njit(cache=True)
def rotation(w, theta):
    """Rotation matrix (3, 3) by ``theta`` [rad] about the unit axis ``w`` (Rodrigues)."""
    R = np.empty((3, 3))
    rotation_into(w, theta, R)
    return R


@njit(cache=True, inline="always")
def rotation_into(w, theta, R):
    """``R[:3, :3] ← Rot(w, θ)`` (Rodrigues) for the unit axis ``w``; R (3, 3) or (4, 4)."""
    c = math.cos(theta)
    s = math.sin(theta)
    v = 1.0 - c
    x = w[0]
    y = w[1]
    z = w[2]
    R[0, 0] = c + x * x * v
    R[0, 1] = x * y * v - z * s
    R[0, 2] = x * z * v + y * s
    R[1, 0] = y * x * v + z * s
    R[1, 1] = c + y * y * v
    R[1, 2] = y * z * v - x * s
    R[2, 0] = z * x * v - y * s
    R[2, 1] = z * y * v + x * s
    R[2, 2] = c + z * z * v


@njit(cache=True)
def rotate(w, theta, v):
    """``Rot(w, θ)·v`` (3,) by Rodrigues' formula, w a unit axis, v a vector."""
    c = math.cos(theta)
    s = math.sin(theta)
    wv = w[0] * v[0] + w[1] * v[1] + w[2] * v[2]
    out = np.empty(3)
    out[0] = v[0] * c + (w[1] * v[2] - w[2] * v[1]) * s + w[0] * wv * (1.0 - c)
    out[1] = v[1] * c + (w[2] * v[0] - w[0] * v[2]) * s + w[1] * wv * (1.0 - c)
    out[2] = v[2] * c + (w[0] * v[1] - w[1] * v[0]) * s + w[2] * wv * (1.0 - c)
    return out


@njit(cache=True)
def rotate_point(w, r, theta, p):
    """``exp(ξ θ)·p`` (3,): the point p turned by θ about the line (w, r) (Rodrigues)."""
    c = math.cos(theta)
    s = math.sin(theta)
    v0 = p[0] - r[0]
    v1 = p[1] - r[1]
    v2 = p[2] - r[2]
    wv = w[0] * v0 + w[1] * v1 + w[2] * v2
    out = np.empty(3)
    out[0] = v0 * c + (w[1] * v2 - w[2] * v1) * s + w[0] * wv * (1.0 - c) + r[0]
    out[1] = v1 * c + (w[2] * v0 - w[0] * v2) * s + w[1] * wv * (1.0 - c) + r[1]
    out[2] = v2 * c + (w[0] * v1 - w[1] * v0) * s + w[2] * wv * (1.0 - c) + r[2]
    return out


@njit(cache=True)
def screw(w, r, theta, prismatic):
    """``exp(ξ θ)`` (4, 4): rotation by θ about the line (w, r), or translation θ·w."""
    E = np.eye(4)
    if prismatic:
        for i in range(3):
            E[i, 3] = theta * w[i]
        return E
    screw_into(w, r, theta, E)
    return E


@njit(cache=True)
def screw_into(w, r, theta, E):
    """``E ← exp(ξ θ)`` (4, 4) of the revolute line (w, r), without allocation.

    Rodrigues' rotation (:func:`rotation_into`), then the translation ``r − R r``.
    """
    rotation_into(w, theta, E)
    for i in range(3):
        E[i, 3] = r[i] - (E[i, 0] * r[0] + E[i, 1] * r[1] + E[i, 2] * r[2])
        E[3, i] = 0.0
    E[3, 3] = 1.0


@njit(cache=True)
def inv_rigid(T):
    """Inverse of a rigid transform (4, 4)."""
    out = np.eye(4)
    for i in range(3):
        for j in range(3):
            out[i, j] = T[j, i]
    for i in range(3):
        out[i, 3] = -(out[i, 0] * T[0, 3] + out[i, 1] * T[1, 3] + out[i, 2] * T[2, 3])
    return out


@njit(cache=True)
def transform_point(T, p):
    """``T·p`` for a rigid transform T (4, 4) and a point p (3,)."""
    out = np.empty(3)
    for i in range(3):
        out[i] = T[i, 0] * p[0] + T[i, 1] * p[1] + T[i, 2] * p[2] + T[i, 3]
    return out


@njit(cache=True)
def _acos_clamped(x):
    """arccos(x) for |x| <= 1 + CLAMP (clamped), else NaN (out of reach).

    Within :data:`SNAP` of ±1 the result snaps to 0 / π, so the two branches of a
    boundary configuration (stretched elbow) merge into one solution instead of two
    copies ~1e-8 rad apart; the pose error this causes is second order (< 1e-14 m).
    """
    if x >= 1.0 - SNAP:
        return 0.0 if x <= 1.0 + CLAMP else math.nan
    if x <= -1.0 + SNAP:
        return math.pi if x >= -1.0 - CLAMP else math.nan
    return math.acos(x)


@njit(cache=True)
def acos_seed(x, slack):
    """arccos(x) for an exact solve (``slack`` 0), or the seed angle of a nearly ideal arm.

    ``slack`` 0: :func:`_acos_clamped` (clamped within :data:`CLAMP`, snapped within
    :data:`SNAP`, NaN beyond). ``slack`` > 0, the candidates of an idealised arm that
    Newton's method refines on the true one: every |x| <= 1 + slack gives an angle,
    arccos of x or, beyond ±1, of the mirrored ``sign(x)·(2 − |x|)`` (as far inside as x
    is outside: the true arm may reach what the ideal one just misses), kept at least
    :data:`SEED_GAP` from 0 and π, so that the two seeds ``±angle`` lie on both sides of
    the tangency; NaN beyond.
    """
    if slack <= 0.0:
        return _acos_clamped(x)
    ax = abs(x)
    if not ax <= 1.0 + slack:
        return math.nan
    if ax > 1.0:
        x = math.copysign(2.0 - ax, x)
    a = math.acos(max(-1.0, min(1.0, x)))
    return min(max(a, SEED_GAP), math.pi - SEED_GAP)


@njit(cache=True)
def sp1_dir_cs(w, u, v):
    """Subproblem 1 on directions with the cosine and sine of the angle: ``(θ, cos θ, sin θ)``.

    θ = ``atan2(w·(u' × v'), u'·v')`` with ``u'``, ``v'`` the projections of u, v on the
    plane ⟂ w (so ``Rot(w, θ)·u`` points like ``v`` there); cos θ and sin θ come from the
    same two numbers (no trigonometric call). ``(0, 1, 0)`` when either projection
    vanishes to rounding level (< 1e-12 of |u|, |v|): the angle is then arbitrary (a
    singular configuration) and 0 is its representative. Scalar code, no allocation.
    """
    wu = w[0] * u[0] + w[1] * u[1] + w[2] * u[2]
    wv = w[0] * v[0] + w[1] * v[1] + w[2] * v[2]
    u0 = u[0] - wu * w[0]
    u1 = u[1] - wu * w[1]
    u2 = u[2] - wu * w[2]
    v0 = v[0] - wv * w[0]
    v1 = v[1] - wv * w[1]
    v2 = v[2] - wv * w[2]
    if (u0 * u0 + u1 * u1 + u2 * u2 <= 1e-24 * (u[0] * u[0] + u[1] * u[1] + u[2] * u[2])
            or v0 * v0 + v1 * v1 + v2 * v2 <= 1e-24 * (v[0] * v[0] + v[1] * v[1]
                                                        + v[2] * v[2])):
        return 0.0, 1.0, 0.0
    c0 = u1 * v2 - u2 * v1
    c1 = u2 * v0 - u0 * v2
    c2 = u0 * v1 - u1 * v0
    y = w[0] * c0 + w[1] * c1 + w[2] * c2
    x = u0 * v0 + u1 * v1 + u2 * v2
    r = math.sqrt(x * x + y * y)
    if r == 0.0:
        return 0.0, 1.0, 0.0
    return math.atan2(y, x), x / r, y / r


@njit(cache=True)
def sp1_dir(w, u, v):
    """Subproblem 1 on directions: θ such that ``Rot(w, θ)·u`` points like ``v`` in the plane ⟂ w.

    The angle of :func:`sp1_dir_cs`: ``atan2(w·(u' × v'), u'·v')``, 0 when either
    projection vanishes (a singular configuration). A hot path of every solver.
    """
    return sp1_dir_cs(w, u, v)[0]


@njit(cache=True)
def sp2_dir(w1, w2, u, v, slack, out):
    """Subproblem 2: θ1, θ2 with ``Rot(w1, θ1)·Rot(w2, θ2)·u = v`` (axes meet; w1 ∦ w2).

    ``u`` and ``v`` are vectors from the common point (or directions). The intermediate
    vector is ``z = α w1 + β w2 ± γ (w1 × w2)`` with ``w2·z = w2·u``, ``w1·z = w1·v`` and
    ``|z| = |u|``. Writes rows (θ1, θ2) into ``out`` (2, 2), or (θ1, θ2, cos θ1, sin θ1,
    cos θ2, sin θ2) when ``out`` has 6 columns (:func:`sp1_dir_cs`: no trigonometric
    call); returns 0, 1 or 2. ``slack`` > 0 (a nearly ideal arm's seeds): γ² down to
    −slack·|u|²/|w1 × w2|² gives the two mirrored seeds ±sqrt(|γ²|), and γ is kept at
    least :data:`SEED_GAP`·|u|/|w1 × w2| (as :func:`acos_seed`); 0 for an exact solve.
    """
    c12 = dot3(w1, w2)
    den = c12 * c12 - 1.0
    a2u = dot3(w2, u)
    a1v = dot3(w1, v)
    alpha = (c12 * a2u - a1v) / den
    beta = (c12 * a1v - a2u) / den
    x = cross3t(w1, w2)
    nx2 = dot3(x, x)
    uu = dot3(u, u)
    g2 = (uu - alpha * alpha - beta * beta - 2.0 * alpha * beta * c12) / nx2
    if slack > 0.0:
        if g2 < -slack * uu / nx2:
            return 0
        g2 = max(abs(g2), SEED_GAP * SEED_GAP * uu / nx2)
    elif g2 < 0.0:
        if g2 < -CLAMP * max(uu, 1e-300) / nx2:
            return 0
        g2 = 0.0
    g = math.sqrt(g2)
    count = 1 if g == 0.0 else 2
    for k in range(count):
        sg = g if k == 0 else -g
        z = (alpha * w1[0] + beta * w2[0] + sg * x[0], alpha * w1[1] + beta * w2[1] + sg * x[1],
             alpha * w1[2] + beta * w2[2] + sg * x[2])
        t2, cs2, sn2 = sp1_dir_cs(w2, u, z)
        t1, cs1, sn1 = sp1_dir_cs(w1, z, v)
        out[k, 0] = t1
        out[k, 1] = t2
        if out.shape[1] >= 6:
            out[k, 2] = cs1
            out[k, 3] = sn1
            out[k, 4] = cs2
            out[k, 5] = sn2
    return count


@njit(cache=True)
def sp3(w, r, p, q, delta, slack, out):
    """Subproblem 3: θ with ``|Rot(w, θ; r)·p − q| = δ`` (rotation about the line (w, r)).

    Projected on the plane ⟂ w: ``|u'|² + |v'|² − 2|u'||v'| cos(θ − θ0) = δ'²`` with
    ``u = p − r``, ``v = q − r``, ``δ'² = δ² − (w·(p − q))²``. Writes θ into ``out``
    (2,), returns 0, 1 or 2 (0 also when p or q lies on the axis). Vectors as tuples.
    ``slack``: 0 for an exact solve, > 0 for a nearly ideal arm's seeds (:func:`acos_seed`).
    """
    u = sub3(p, r)
    v = sub3(q, r)
    wu = dot3(w, u)
    up = (u[0] - wu * w[0], u[1] - wu * w[1], u[2] - wu * w[2])
    wv = dot3(w, v)
    vp = (v[0] - wv * w[0], v[1] - wv * w[1], v[2] - wv * w[2])
    nu = math.sqrt(dot3(up, up))
    nv = math.sqrt(dot3(vp, vp))
    if nu < 1e-12 or nv < 1e-12:
        return 0
    h = dot3(w, sub3(p, q))
    d2 = delta * delta - h * h
    theta0 = math.atan2(dot3(w, cross3t(up, vp)), dot3(up, vp))
    c = acos_seed((nu * nu + nv * nv - d2) / (2.0 * nu * nv), slack)
    if math.isnan(c):
        return 0
    out[0] = theta0 - c
    if c == 0.0:
        return 1
    out[1] = theta0 + c
    return 2


@njit(cache=True)
def sp3_slide(w, h, delta2, out):
    """Subproblem 3 for a slide: strokes d with ``|h + d·w|² = δ²`` (w a unit direction).

    ``d² + 2 (w·h) d + |h|² − δ² = 0``, so d = −w·h ± sqrt((w·h)² − |h|² + δ²); a
    discriminant slightly negative (within :data:`CLAMP`·max(|h|², 1)) counts as zero.
    Takes ``delta2`` = δ² [m²]; writes d [m] into ``out`` (2,) (the + root first),
    returns 0, 1 or 2. ``w``, ``h`` tuples.
    """
    b = dot3(w, h)
    hh = dot3(h, h)
    disc = b * b - hh + delta2
    if disc < 0.0:
        if disc < -CLAMP * max(hh, 1.0):
            return 0
        disc = 0.0
    root = math.sqrt(disc)
    out[0] = -b + root
    if root == 0.0:
        return 1
    out[1] = -b - root
    return 2

@njit(cache=True)
def sp4(w, b, a, c, slack, out):
    """θ with ``a·Rot(w, θ)·b = c``: ``A cos θ + B sin θ = c − (a·w)(w·b)``.

    ``A = a·b'``, ``B = a·(w × b')``, ``b'`` the part of b ⟂ w, so θ = atan2(B, A) ±
    arccos(D / sqrt(A² + B²)). When A = B = 0 any θ solves a consistent equation:
    θ = 0 is returned as the representative. Writes θ into ``out`` (2,), returns 0, 1 or
    2. With ``out`` of 6 entries also ``cos θ, sin θ`` of each solution into
    ``out[2:4]`` and ``out[4:6]``, by the angle-sum formulas from A, B, D (no
    trigonometric call; ``sin(arccos x) = sqrt((1 − x)(1 + x))``). ``slack``: 0 for an
    exact solve, > 0 for a nearly ideal arm's seeds (:func:`acos_seed`: two seeds on both
    sides of a tangency, also just beyond it).
    """
    wb = w[0] * b[0] + w[1] * b[1] + w[2] * b[2]
    b0 = b[0] - wb * w[0]
    b1 = b[1] - wb * w[1]
    b2 = b[2] - wb * w[2]
    A = a[0] * b0 + a[1] * b1 + a[2] * b2
    B = (a[0] * (w[1] * b2 - w[2] * b1) + a[1] * (w[2] * b0 - w[0] * b2)
         + a[2] * (w[0] * b1 - w[1] * b0))
    D = c - (a[0] * w[0] + a[1] * w[1] + a[2] * w[2]) * wb
    Rn = math.hypot(A, B)
    scale = math.sqrt((a[0] * a[0] + a[1] * a[1] + a[2] * a[2])
                      * (b[0] * b[0] + b[1] * b[1] + b[2] * b[2]))
    cs = out.shape[0] >= 6
    if Rn <= 1e-12 * max(scale, 1e-300):
        if abs(D) <= 1e-9 * max(scale, 1.0):
            out[0] = 0.0
            if cs:
                out[2] = 1.0
                out[3] = 0.0
            return 1
        return 0
    phi = math.atan2(B, A)
    cx = D / Rn
    x = acos_seed(cx, slack)
    if math.isnan(x):
        return 0
    out[0] = phi + x
    if cs:
        cp = A / Rn
        sp = B / Rn
        if slack > 0.0:
            cx, sx = math.cos(x), math.sin(x)
        elif x == 0.0:
            cx, sx = 1.0, 0.0
        elif x == math.pi:
            cx, sx = -1.0, 0.0
        else:
            sx = math.sqrt((1.0 - cx) * (1.0 + cx))
        out[2] = cp * cx - sp * sx
        out[3] = sp * cx + cp * sx
        out[4] = cp * cx + sp * sx
        out[5] = sp * cx - cp * sx
    if x == 0.0:
        return 1
    out[1] = phi - x
    return 2


@njit(cache=True)
def planar2r(w, e1, c1, c2, p, t, out):
    """Two revolute joints on parallel axes (w; through c1, c2) carrying point p to t.

    The chapter's closed form (eqs 23-27, corrected per the ERRATA) in the plane ⟂ w
    with basis (e1, e2 = w × e1), origin c1, link lengths L1 = |c2 − c1|' and
    L2 = |p − c2|' (' = projected):

    * r = sqrt(x² + y²), α = atan2(y, x)  (eqs 23-24, corrected)
    * θ2 = ±arccos((x² + y² − L1² − L2²) / (2 L1 L2))  (eq 25)
    * β = arccos((L1² − L2² + r²) / (2 L1 r))  (eq 26, corrected), evaluated in the
      equivalent form β = atan2(L2 sin|θ2|, L1 + L2 cos θ2), which stays accurate near
      the workspace boundary;
    * θ1 = α − β with θ2 = +arccos(..), θ1 = α + β with θ2 = −arccos(..)  (eq 27).

    The link angles are then measured from the zero configuration. Writes rows
    (θ1, θ2) [rad, about +w] into ``out`` (2, 2); returns 0, 1 or 2. When the target is
    on the first axis with L1 = L2, θ1 is arbitrary and θ1 = α = 0 is returned.
    """
    return planar2r_solve(planar2r_frame(w, e1, c1, c2, p), t, out, 0.0)


@njit(cache=True)
def planar2r_frame(w, e1, c1, c2, p):
    """The target-independent part of :func:`planar2r`, computed once per arm.

    Returns the tuple ``(e1, e2 = w × e1, c1, L1, L2, φ10, φ20)``: the plane basis and
    origin, the projected link lengths and the link angles at the zero configuration
    (φ10 of link 1, φ20 of link 2 relative to link 1).
    """
    e2 = cross3t(w, e1)
    l1 = sub3(c2, c1)
    l2 = sub3(p, c2)
    x1 = dot3(e1, l1)
    y1 = dot3(e2, l1)
    x2 = dot3(e1, l2)
    y2 = dot3(e2, l2)
    phi10 = math.atan2(y1, x1)
    return ((e1[0], e1[1], e1[2]), e2, (c1[0], c1[1], c1[2]), math.hypot(x1, y1),
            math.hypot(x2, y2), phi10, math.atan2(y2, x2) - phi10)


@njit(cache=True)
def planar2r_solve(frame, t, out, slack):
    """:func:`planar2r` for the target point t, given its :func:`planar2r_frame`.

    ``slack`` ≥ 0: a target out of reach whose elbow cosine ``c`` lies within
    ``1 + slack`` of the boundary (|c| ≤ 1 + slack) still gives two rows, those of the
    mirrored cosine ``sign(c)·(2 − |c|)`` (as far inside the reach as c is outside), and
    a nearly stretched or folded elbow two rows at least :data:`SEED_GAP` apart
    (:func:`acos_seed`): the seeds of an idealised arm's refinement (:data:`ELBOW_SLACK`),
    where the true arm may reach what the ideal one does not. 0 for an exact solve.
    """
    e1, e2, c1, L1, L2, phi10, phi20 = frame
    d = sub3(t, c1)
    x = dot3(e1, d)
    y = dot3(e2, d)
    r2 = x * x + y * y
    c = (r2 - L1 * L1 - L2 * L2) / (2.0 * L1 * L2)
    th2 = acos_seed(c, slack)
    if math.isnan(th2):
        return 0
    alpha = math.atan2(y, x)
    beta = math.atan2(L2 * math.sin(th2), L1 + L2 * math.cos(th2))
    out[0, 0] = alpha - beta - phi10
    out[0, 1] = th2 - phi20
    if th2 == 0.0:
        return 1
    out[1, 0] = alpha + beta - phi10
    out[1, 1] = -th2 - phi20
    return 2


@njit(cache=True)
def rigid_error(T):
    """How far T (4, 4) is from a rigid transform (the quantities ``check_transform`` tests).

    The largest of |last row − [0, 0, 0, 1]|, |RᵀR − I| and |det R − 1|; inf when an
    entry is not finite.
    """
    for i in range(4):
        for j in range(4):
            if not math.isfinite(T[i, j]):
                return math.inf
    err = max(abs(T[3, 0]), abs(T[3, 1]), abs(T[3, 2]), abs(T[3, 3] - 1.0))
    for i in range(3):
        for j in range(3):
            g = T[0, i] * T[0, j] + T[1, i] * T[1, j] + T[2, i] * T[2, j]
            err = max(err, abs(g - (1.0 if i == j else 0.0)))
    det = (T[0, 0] * (T[1, 1] * T[2, 2] - T[1, 2] * T[2, 1])
           - T[0, 1] * (T[1, 0] * T[2, 2] - T[1, 2] * T[2, 0])
           + T[0, 2] * (T[1, 0] * T[2, 1] - T[1, 1] * T[2, 0]))
    return max(err, abs(det - 1.0))


@njit(cache=True)
def rigid_errors_into(Ts, err):
    """:func:`rigid_error` of every ``Ts[k]`` (N, 4, 4) into ``err`` (N,)."""
    for k in range(Ts.shape[0]):
        err[k] = rigid_error(Ts[k])


@njit(cache=True)
def poly_roots(coefs, out):
    """Complex roots of a polynomial of degree <= 4 (Aberth–Ehrlich iteration).

    Args:
        coefs: (m,) complex coefficients, highest degree first; leading coefficients
            below 1e-13 of the largest are dropped (the degree falls).
        out: (4,) complex output.

    Returns:
        the number of roots written (the degree). Simple roots converge cubically;
        callers polish the real roots they keep on their own equation.
    """
    big = 0.0
    for c in coefs:
        big = max(big, abs(c))
    start = 0
    while start < coefs.shape[0] and abs(coefs[start]) <= 1e-13 * big:
        start += 1
    deg = coefs.shape[0] - 1 - start
    if deg <= 0:
        return 0
    a = coefs[start:] / coefs[start]
    radius = 0.0
    for k in range(1, deg + 1):
        radius = max(radius, abs(a[k]) ** (1.0 / k))
    for k in range(deg):
        out[k] = radius * np.exp(1j * (2.0 * math.pi * k / deg + 0.4))
    for _ in range(100):
        moved = 0.0
        for k in range(deg):
            z = out[k]
            p = a[0]
            dp = 0.0 + 0.0j
            for j in range(1, deg + 1):
                dp = dp * z + p
                p = p * z + a[j]
            if p == 0.0:
                continue
            ratio = p / dp if dp != 0.0 else p
            s = 0.0 + 0.0j
            for j in range(deg):
                if j != k:
                    s += 1.0 / (z - out[j])
            step = ratio / (1.0 - ratio * s)
            out[k] = z - step
            moved = max(moved, abs(step) / max(1.0, abs(z)))
        if moved < 1e-12:  # the callers polish with Newton's method on their equation
            break
    return deg


@njit(cache=True)
def polish_real_root(coefs, x):
    """Newton steps on the real polynomial ``coefs`` (highest degree first) from x.

    At most 8 steps, stopping when a step falls below 1e-15·max(1, |x|) or the
    derivative vanishes; returns the polished root.
    """
    for _ in range(8):
        f = 0.0
        df = 0.0
        for c in coefs:
            df = df * x + f
            f = f * x + c
        if df == 0.0:
            break
        step = f / df
        x -= step
        if abs(step) <= 1e-15 * max(1.0, abs(x)):
            break
    return x


@njit(cache=True)
def _lex_less(a, b):
    for j in range(a.shape[0]):
        if a[j] < b[j]:
            return True
        if a[j] > b[j]:
            return False
    return False


@njit(cache=True)
def finalize(cand, k, revolute, qlim, mid, F, meta, T, check_rot, tol_p, tol_r, out):
    """Wrap, limit-check, verify, de-duplicate and sort candidate solutions.

    For each of the first ``k`` rows of ``cand`` (K, n): revolute angles are moved by a
    multiple of 2π to the value nearest the middle of their limits ``mid`` (n,); a row
    with any joint outside ``qlim`` (n, 2) (beyond :data:`LIMIT_TOL`) is dropped; the
    rest must reproduce ``T`` (4, 4) through forward kinematics (eq 11, the shared
    kernel): position within ``tol_p`` [m] and, when ``check_rot``, every rotation entry
    within ``tol_r``. Duplicates (within :data:`DUPLICATE_TOL`) are dropped and the
    accepted rows are sorted lexicographically into ``out`` (K, n). Returns their count.
    """
    n = cand.shape[1]
    Q = np.empty((max(k, 1), n))
    kq = 0
    for i in range(k):
        ok = True
        for j in range(n):
            v = cand[i, j]
            if not math.isfinite(v):
                ok = False
                break
            if revolute[j]:
                v = v - TWO_PI * math.floor((v - mid[j]) / TWO_PI + 0.5)
            lo = qlim[j, 0]
            hi = qlim[j, 1]
            if v < lo:
                if v < lo - LIMIT_TOL:
                    ok = False
                    break
                v = lo
            elif v > hi:
                if v > hi + LIMIT_TOL:
                    ok = False
                    break
                v = hi
            Q[kq, j] = v
        if ok:
            kq += 1
    Tq = np.empty((max(kq, 1), 4, 4))
    fk_range(Q, F, meta, Tq, 0, kq)  # the rows inside the limits, vectorised across rows
    m = 0
    for i in range(kq):
        q = Q[i]
        ep = 0.0
        for r in range(3):
            ep += (Tq[i, r, 3] - T[r, 3]) ** 2
        if math.sqrt(ep) > tol_p:
            continue
        if check_rot:
            er = 0.0
            for r in range(3):
                for c in range(3):
                    er = max(er, abs(Tq[i, r, c] - T[r, c]))
            if er > tol_r:
                continue
        dup = False
        for s in range(m):
            dmax = 0.0
            for j in range(n):
                dmax = max(dmax, abs(out[s, j] - q[j]))
            if dmax < DUPLICATE_TOL:
                dup = True
                break
        if dup:
            continue
        # insertion into the sorted prefix out[:m]
        pos = m
        # (rows copied by loops: numba's slice assignment from an array compiles its
        # shape-mismatch message, 2.5 s of string kernels, in every compiling process)
        while pos > 0 and _lex_less(q, out[pos - 1]):
            for j in range(n):
                out[pos, j] = out[pos - 1, j]
            pos -= 1
        for j in range(n):
            out[pos, j] = q[j]
        m += 1
    return m
