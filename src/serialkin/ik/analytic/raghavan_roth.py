"""All IK solutions of a general 6R arm by Raghavan–Roth elimination (numba, ``cache=True``).

A 6R arm that no subproblem decomposes has up to 16 solutions, the real roots of one
univariate polynomial (M. Raghavan, B. Roth, *Inverse kinematics of the general 6R
manipulator and related linkages*, ASME J. Mech. Des. 115, 1993; the matrix form of
D. Manocha, J. F. Canny, *Efficient inverse kinematics for general 6R manipulators*,
IEEE T-RA 10(5), 1994). Here it is written on the product of exponentials of the
robot's own joint lines (so any joint description, base and tool), and every
coefficient is obtained numerically from the chain instead of from symbolic algebra:

1. **Split.** With ``G = T·M⁻¹ = e1·e2·e3·e4·e5·e6`` (``e_i = exp(ξ_i θ_i)``), the
   direction ``w6`` and a point ``c6`` of axis 6 are fixed by ``e6``, so
   ``e3 e4 e5 (w6, c6) = e2⁻¹ e1⁻¹ G (w6, c6)``. With ``o3`` a point of axis 3, set
   ``l = R·w6`` and ``p = (·)c6 − o3`` on each side (positions divided by the arm's size).
   Below, this split is described; when it degenerates exactly, joint 5 or
   4 is eliminated instead (``e2 e3 e4 x = e1⁻¹ G e6⁻¹ x``, ``e1 e2 e3 x = G e6⁻¹ e5⁻¹ x``),
   then the same three on the reversed chain (:func:`_rr_split`).
2. **Fourteen equations** (Raghavan–Roth): ``l``, ``p``, ``l·p``, ``p·p``, ``l × p`` and
   ``(p·p) l − 2 (l·p) p`` (3+3+1+1+3+3). Each left side is a combination of the 27
   products of ``(1, c_j, s_j)`` for j = 3, 4, 5 (at most linear in each joint's cosine
   and sine); each right side of the 9 products for j = 1, 2. The coefficients are
   exact interpolations on 3 angles per joint (27 and 9 chain evaluations): no symbolic
   derivation, and the claim is checked by the tests on random arms.
3. **Eliminate θ1, θ2.** Moving the constant term left, ``P(θ3, θ4, θ5) = Q·m12`` with
   ``Q`` (14, 8) the coefficients of the 8 non-constant products of θ1, θ2. Rows
   ``N`` (6, 14) spanning the left null space of ``Q`` (its QR) give six equations in
   θ3, θ4, θ5 alone.
4. **A 12 × 12 pencil.** The half-angle tangents x4, x5 turn each equation (times
   ``(1+x4²)(1+x5²)``) into a polynomial in the 9 monomials ``x4^i x5^j`` (i, j ≤ 2);
   the six equations and their products by x4 are 12 equations, linear in the 12
   monomials ``x4^i x5^j`` (i ≤ 3, j ≤ 2): ``K(θ3)·v = 0`` with
   ``K(θ3) = K0 + cos θ3 K1 + sin θ3 K2``.
5. **The univariate equation.** ``det K(θ3)`` is a trigonometric polynomial of degree 8
   (the eliminant of degree 16 in ``tan(θ3/2)``; the degree-24 determinant in the
   half-angle carries the spurious factor ``(1 + x3²)⁴``). Its 17 coefficients are the
   discrete Fourier transform of 17 determinants (LU). Its real roots are isolated by
   its derivatives: the zeros of its second derivative are bracketed on a grid, its
   first derivative is monotone between them, so it has at most one extremum between
   two of those, and each root is bracketed alone (:func:`eliminant_roots`). Roots
   closer together than a cell are so separated (the published 16-solution arm has four
   within 3.3°: Manocha & Canny 1994, Table III). An extremum at zero (a double root)
   is a root; an extremum that comes within a small imaginary part of zero (a complex
   pair t ± iη, η ≤ :data:`NEAR_REAL`: a near-double root that rounding may have moved
   off the real line) is a candidate as well.
6. **Back substitution.** For each root, the null vector of ``K(θ3)`` (Gaussian
   elimination with complete pivoting) gives x4, x5 as ratios of its entries (a root
   where that null space has two or more dimensions is shared by several solutions:
   the search answers instead, :data:`MULTIPLE_TOL`); the
   least-squares solution of ``Q·m12 = P`` (the same QR) gives ``(cos θ1, sin θ1)`` and
   ``(cos θ2, sin θ2)``; θ6 follows by subproblem 1 on ``w6``.
7. **Refinement.** Every candidate is polished by Newton's method on the robot's own
   chain (:func:`~serialkin.ik.analytic.refine.refine_new`) to the solver's
   tolerance; duplicates are dropped in joint space after polishing, never before (no
   early stop near a solution already found). A near-real candidate that converges to
   nothing new was a complex pair and is dropped; a real root that gives nothing new
   makes the caller search instead (below).

:func:`rr_candidates_from` reports failure (:data:`NEAR_SPECIAL`) when the elimination does not
apply: ``Q`` of rank below 8 or a pencil singular to rounding for all six splits (an exact special
pair, e.g. axes 1 and 2 intersecting, degenerates a split: the next one is tried), or a
pencil nearly singular for every θ3 (an arm near a special class: no split is trusted);
the 2-D search then takes over. Kernels trust their input.
"""

from __future__ import annotations

import math

import numpy as np

from serialkin.ik.analytic.refine import refine_new
from serialkin.ik.analytic.subproblems import (
    TWO_PI,
    inv_rigid,
    mm,
    screw_into,
    sort_prefix,
    sp1_dir,
)

from ..._jit import njit

#: Interpolation angles of each joint: 0, 2π/3, 4π/3 [rad].
_ANGLES = np.array([0.0, TWO_PI / 3.0, 2.0 * TWO_PI / 3.0])
#: Coefficients of (1, cos θ, sin θ) from values at :data:`_ANGLES`: ``c = _B_INV @ f``.
_B_INV = np.linalg.inv(np.column_stack([np.ones(3), np.cos(_ANGLES), np.sin(_ANGLES)]))
#: (1, cos θ, sin θ)·(1 + x²) as polynomials in x = tan(θ/2): row a, power p.
_HALF = np.array([[1.0, 0.0, 1.0], [1.0, 0.0, -1.0], [0.0, 2.0, 0.0]])
#: Degree of the trigonometric eliminant det K(θ3).
DEGREE = 8
#: Determinants sampled for its coefficients (2·DEGREE + 1).
_N_DET = 2 * DEGREE + 1
#: cos and sin of 2π k m / _N_DET (k ≤ DEGREE, m < _N_DET): the discrete Fourier transform
#: of the sampled determinants, a table instead of 306 calls per pose.
_DFT_COS = np.array([[math.cos(TWO_PI * k * m / _N_DET) for m in range(_N_DET)]
                     for k in range(DEGREE + 1)])
_DFT_SIN = np.array([[math.sin(TWO_PI * k * m / _N_DET) for m in range(_N_DET)]
                     for k in range(DEGREE + 1)])
#: Grid on which the zeros of the eliminant's second derivative are bracketed.
N_GRID = 128
#: cos and sin of k·t_m at the grid's ends t_m = −π + 2π m / N_GRID (k ≤ DEGREE,
#: m ≤ N_GRID), rows k: the grid values of :func:`_scan` as table products.
_GRID_COS = np.array([[math.cos(k * (-math.pi + TWO_PI / N_GRID * m)) for m in range(N_GRID + 1)]
                      for k in range(DEGREE + 1)])
_GRID_SIN = np.array([[math.sin(k * (-math.pi + TWO_PI / N_GRID * m)) for m in range(N_GRID + 1)]
                      for k in range(DEGREE + 1)])
#: Bracket or Newton step [rad] at which a zero of the eliminant or of a derivative is
#: accepted (each root is then polished on the determinant and the pose anyway).
ZERO_TOL = 1e-13
#: Largest imaginary part [rad] of a pair of complex roots of the eliminant whose real
#: part is tried as a candidate θ3 (:func:`eliminant_roots`): a near-double real root
#: that rounding turned into a complex pair survives; refinement on the pose decides.
NEAR_REAL = 1e-3
#: Smallest ratio |R[7, 7]| / |R[0, 0]| of Q's pivoted QR (:func:`_qr`; at least its smallest
#: singular value over its largest) for the elimination to apply.
RANK_TOL = 1e-9
#: Smallest pivot ratio (≈ 1/cond) of the best-conditioned sample of K(θ3): below it the
#: pencil is nearly singular for every θ3 (an arm close to a special class, where the
#: eliminant degenerates) and the search takes over. Random arms give 1e-2 to 0.3,
#: arms within 0.01 rad of the UR5 or the Puma 560 1e-7 to 4e-4.
PIVOT_TOL = 1e-3
#: Below this pivot ratio the pencil is singular to rounding for every θ3: the split
#: degenerates exactly (e.g. axes 1 and 2 intersecting or parallel give 1e-16 to 1e-11)
#: and the next split is tried.
EXACT_TOL = 1e-10
#: Below this ratio of K(θ3)'s second-smallest pivot to its largest (complete pivoting),
#: the pencil at a root has a null space of two or more dimensions: several solutions share
#: that θ3 (e.g. the two elbows of three parallel axes 4, 5, 6 behind it; 1e-16 to 1e-13
#: there) and back substitution, which takes one null vector, would find one of them, so
#: the search answers instead. Random arms give 7e-5 and above (550 roots of 150 arms).
MULTIPLE_TOL = 1e-8
#: :func:`_rr_split` codes: Q of rank < 8 or a pencil singular to rounding for this split
#: (an exact special pair: the next split is tried), and a nearly degenerate eliminant
#: (pivot ratio in [EXACT_TOL, PIVOT_TOL): an arm close to a special class, where another
#: split can be well conditioned and still find an incomplete set of roots — seen on
#: tilted Puma 560s — so the search answers instead).
RANK_DEFICIENT = -1000
NEAR_SPECIAL = -1001


@njit(cache=True)
def _equations(l, p, out, row):
    """The 14 Raghavan–Roth quantities of ``l``, ``p`` (3,) into ``out[row]``.

    ``[l, p, l·p, p·p, l × p, (p·p) l − 2 (l·p) p]``.
    """
    lp = l[0] * p[0] + l[1] * p[1] + l[2] * p[2]
    pp = p[0] * p[0] + p[1] * p[1] + p[2] * p[2]
    for i in range(3):
        out[row, i] = l[i]
        out[row, 3 + i] = p[i]
        out[row, 11 + i] = pp * l[i] - 2.0 * lp * p[i]
    out[row, 6] = lp
    out[row, 7] = pp
    out[row, 8] = l[1] * p[2] - l[2] * p[1]
    out[row, 9] = l[2] * p[0] - l[0] * p[2]
    out[row, 10] = l[0] * p[1] - l[1] * p[0]


@njit(cache=True)
def _move(E, x, y):
    """``y = (R·x[:3], E·x[3:])`` (6,) for a rigid E (4, 4): a direction and a point moved."""
    for i in range(3):
        y[i] = E[i, 0] * x[0] + E[i, 1] * x[1] + E[i, 2] * x[2]
        y[3 + i] = E[i, 0] * x[3] + E[i, 1] * x[4] + E[i, 2] * x[5] + E[i, 3]


@njit(cache=True)
def _qr(A, beta, rdiag, perm):
    """Householder QR with column pivoting of A (m, n), m > n, in place: ``A Π = Q R``.

    Column j of A becomes the reflector ``v_j`` in rows j..m−1 (``H_j = I − β_j v_j v_jᵀ``,
    ``Q = H_0···H_{n−1}``), its rows above the diagonal R's, ``rdiag`` R's diagonal;
    ``perm[j]`` is the column of the original A in position j (the largest remaining
    column first). Returns ``|R[n−1, n−1]| / |R[0, 0]|`` (0 for A = 0), a rank test
    (at least σ_min / σ_max); a few hundred flops against LAPACK's SVD with its copies
    and workspace queries (10 µs from a kernel).
    """
    m, n = A.shape
    for j in range(n):
        perm[j] = j
    for j in range(n):
        pc = j
        big = -1.0
        for c in range(j, n):
            t = 0.0
            for i in range(j, m):
                t += A[i, c] * A[i, c]
            if t > big:
                big = t
                pc = c
        if pc != j:
            for i in range(m):
                A[i, j], A[i, pc] = A[i, pc], A[i, j]
            perm[j], perm[pc] = perm[pc], perm[j]
        norm = math.sqrt(big)
        alpha = -norm if A[j, j] >= 0.0 else norm
        A[j, j] -= alpha
        vv = 0.0
        for i in range(j, m):
            vv += A[i, j] * A[i, j]
        b = 2.0 / vv if vv > 0.0 else 0.0
        beta[j] = b
        rdiag[j] = alpha
        for c in range(j + 1, n):
            t = 0.0
            for i in range(j, m):
                t += A[i, j] * A[i, c]
            t *= b
            for i in range(j, m):
                A[i, c] -= t * A[i, j]
    if rdiag[0] == 0.0:
        return 0.0
    return abs(rdiag[n - 1]) / abs(rdiag[0])


@njit(cache=True)
def _apply_q(A, beta, x):
    """``x ← Q x`` (m,) in place, Q the orthogonal factor of :func:`_qr` (reflectors in A)."""
    _reflect(A, beta, x, False)


@njit(cache=True)
def _apply_qt(A, beta, x):
    """``x ← Qᵀ x`` (m,) in place, Q the orthogonal factor of :func:`_qr` (reflectors in A)."""
    _reflect(A, beta, x, True)


@njit(cache=True, inline="always")
def _reflect(A, beta, x, transpose):
    """Apply the reflectors ``H_j = I − β_j v_j v_jᵀ`` of A (:func:`_qr`) to x in place.

    ``Q = H_0···H_(n−1)``, so Qᵀ x applies them first to last (``transpose``), Q x last
    to first.
    """
    m, n = A.shape
    for k in range(n):
        j = k if transpose else n - 1 - k
        t = 0.0
        for i in range(j, m):
            t += A[i, j] * x[i]
        t *= beta[j]
        for i in range(j, m):
            x[i] -= t * A[i, j]


@njit(cache=True)
def _to_coefficients(V, m):
    """Values at the interpolation angles → coefficients of (1, c, s), along ``m`` axes.

    ``V`` has shape (3^m, 14) with the joint indices in row-major order; returns the
    same shape with each joint index turned into a basis index (a, 0: 1, 1: cos, 2: sin).
    """
    C = V.copy()
    stride = 1
    for _ in range(m):
        stride *= 3
    tmp = np.empty_like(C)
    block = stride
    for _ in range(m):
        block //= 3
        for r in range(C.shape[0]):
            i = (r // block) % 3
            base = r - i * block
            for k in range(C.shape[1]):
                tmp[r, k] = (_B_INV[i, 0] * C[base, k] + _B_INV[i, 1] * C[base + block, k]
                             + _B_INV[i, 2] * C[base + 2 * block, k])
        for r in range(C.shape[0]):  # a loop: see subproblems.finalize
            for k in range(C.shape[1]):
                C[r, k] = tmp[r, k]
    return C


@njit(cache=True)
def _eliminate_below(A, c):
    """One Gaussian elimination step: rows below c minus multiples of row c (pivot A[c, c]).

    Only the columns right of c are updated (column c below the pivot is left as is:
    the caller does not read it again).
    """
    n = A.shape[0]
    inv = 1.0 / A[c, c]
    for r in range(c + 1, n):
        f = A[r, c] * inv
        if f != 0.0:
            for j in range(c + 1, n):
                A[r, j] -= f * A[c, j]


@njit(cache=True)
def _null_vector(A, v, y, perm):
    """A unit null vector ``v`` (n,) of the nearly singular ``A`` (n, n, overwritten).

    ``y`` (n,) and ``perm`` (n,) int are work space.

    Gaussian elimination with complete pivoting; the last pivot is the (near) zero one,
    the vector follows by back substitution with its last entry 1. Returns the
    second-smallest pivot relative to the largest, |u_{n−2,n−2}| / |u_00|: near zero
    when the null space has two or more dimensions, where ``v`` is one vector of it.
    """
    n = A.shape[0]
    for i in range(n):
        perm[i] = i
    for c in range(n - 1):
        pr, pc, big = c, c, -1.0
        for r in range(c, n):
            for j in range(c, n):
                if abs(A[r, j]) > big:
                    big = abs(A[r, j])
                    pr, pc = r, j
        if big == 0.0:
            break
        if pr != c:
            for j in range(n):
                A[c, j], A[pr, j] = A[pr, j], A[c, j]
        if pc != c:
            for r in range(n):
                A[r, c], A[r, pc] = A[r, pc], A[r, c]
            perm[c], perm[pc] = perm[pc], perm[c]
        _eliminate_below(A, c)
    y[n - 1] = 1.0
    for i in range(n - 2, -1, -1):
        s = 0.0
        for j in range(i + 1, n):
            s += A[i, j] * y[j]
        y[i] = -s / A[i, i] if A[i, i] != 0.0 else 0.0
    norm = 0.0
    for i in range(n):
        norm += y[i] * y[i]
    norm = math.sqrt(norm)
    for i in range(n):
        v[perm[i]] = y[i] / norm
    return abs(A[n - 2, n - 2]) / abs(A[0, 0]) if A[0, 0] != 0.0 else 0.0


@njit(cache=True, inline="always")
def _phase(u, v, m):
    """``u, v, −u, −v`` for m mod 4 = 0, 1, 2, 3: an m-th derivative (:func:`_trig3`)."""
    r = m % 4
    if r == 0:
        return u
    if r == 1:
        return v
    if r == 2:
        return -u
    return -v


@njit(cache=True)
def _trig3(a, b, c1, s1, order):
    """Derivatives ``order``, ``order + 1`` and ``order + 2`` of f where (cos t, sin t) = (c1, s1).

    ``f(t) = a0 + Σ_k a_k cos kt + b_k sin kt`` (k = 1..DEGREE). The m-th derivative of
    ``a cos kt + b sin kt`` is ``k^m`` times ``u, v, −u, −v`` for m mod 4 = 0, 1, 2, 3,
    with ``u = a cos kt + b sin kt`` and ``v = b cos kt − a sin kt``: exact, no
    differences.
    """
    ck, sk = 1.0, 0.0
    d0 = a[0] if order == 0 else 0.0
    d1 = 0.0
    d2 = 0.0
    u0, v0 = _phase(1.0, 0.0, order), _phase(0.0, 1.0, order)  # d0 = Σ w (u0 u + v0 v)
    u1, v1 = _phase(1.0, 0.0, order + 1), _phase(0.0, 1.0, order + 1)
    u2, v2 = _phase(1.0, 0.0, order + 2), _phase(0.0, 1.0, order + 2)
    for k in range(1, a.shape[0]):
        ck, sk = ck * c1 - sk * s1, sk * c1 + ck * s1
        u = a[k] * ck + b[k] * sk
        v = b[k] * ck - a[k] * sk
        w = 1.0
        for _ in range(order):
            w *= k
        d0 += w * (u0 * u + v0 * v)
        w *= k
        d1 += w * (u1 * u + v1 * v)
        w *= k
        d2 += w * (u2 * u + v2 * v)
    return d0, d1, d2


@njit(cache=True)
def _trig(a, b, t, order):
    """Derivative ``order`` (0, 1, 2, ...) of f at t (see :func:`_trig3`)."""
    return _trig3(a, b, math.cos(t), math.sin(t), order)[0]


@njit(cache=True)
def _zero(a, b, lo, hi, order, flo):
    """Zero in [lo, hi] of derivative ``order`` of f, which changes sign there.

    ``flo`` is that derivative's value at lo (nonzero; the caller's, which decided the
    bracket). Newton steps on the next derivative when they stay inside the bracket,
    else bisection; 60 iterations at most, or until the bracket or a Newton step is
    below :data:`ZERO_TOL` (a derivative's value near its zero is rounding noise:
    smaller steps only wander in it), or until a step converging quadratically (at
    most a tenth of the one before) predicts the next below it (``d³/d_prev²``): the
    step that would only confirm the zero is not taken (about a third of the
    evaluations of the eliminant's roots).
    """
    x = 0.5 * (lo + hi)
    dprev = math.inf  # the previous Newton step
    for _ in range(60):
        f, fp, _unused = _trig3(a, b, math.cos(x), math.sin(x), order)
        if f == 0.0:
            return x
        if (f > 0.0) == (flo > 0.0):
            lo = x
            flo = f
        else:
            hi = x
        if hi - lo < ZERO_TOL:
            break
        xn = x - f / fp if fp != 0.0 else 0.5 * (lo + hi)
        if lo < xn < hi:
            d = abs(xn - x)
            if d < ZERO_TOL or (d < 0.1 * dprev < 0.1 and d * d * d < ZERO_TOL * dprev * dprev):
                return xn
            dprev = d
            x = xn
        else:
            dprev = math.inf
            x = 0.5 * (lo + hi)
    return x


@njit(cache=True)
def _add_root(roots, k, x):
    """Append ``x`` wrapped to [−π, π) unless within 1e-10 rad of a root already listed."""
    x -= TWO_PI * math.floor((x + math.pi) / TWO_PI)
    for i in range(k):
        d = abs(x - roots[i])
        if min(d, TWO_PI - d) < 1e-10:
            return k
    if k < roots.shape[0]:
        roots[k] = x
        k += 1
    return k


@njit(cache=True)
def _changes(u, v):
    """Whether u and v are nonzero numbers of opposite signs."""
    return u != 0.0 and v != 0.0 and (u > 0.0) != (v > 0.0)


@njit(cache=True)
def _tiny(a, b, order):
    """1e-10 of the size of derivative ``order`` of f (``Σ k^order (|a_k| + |b_k|)``).

    Below it a value is zero to rounding: an extremum there is a double zero.
    """
    s = abs(a[0]) if order == 0 else 0.0
    for k in range(1, a.shape[0]):
        w = 1.0
        for _ in range(order):
            w *= k
        s += w * (abs(a[k]) + abs(b[k]))
    return 1e-10 * s


@njit(cache=True)
def _cell_pieces(a, b, lo, hi, f_lo, g_lo, s_lo, f_hi, g_hi, s_hi, tiny, order, roots, k):
    """Zeros of g = f^(order) in a cell [lo, hi] where g'' changes sign; the new count.

    The zero of g'' (one is looked for) splits the cell into two pieces where g' is
    monotone, so each holds at most one extremum of g (a zero of g'); those extrema cut
    the cell into pieces where g is monotone, each holding at most one zero. ``f_*``,
    ``g_*``, ``s_*`` are g, g', g'' at the ends.
    """
    cut = np.empty(4)  # lo, up to two extrema, hi
    fv = np.empty(4)
    cut[0] = lo
    fv[0] = f_lo
    nc = 1
    x = _zero(a, b, lo, hi, order + 2, s_lo)
    gx = _trig(a, b, x, order + 1)
    if _changes(g_lo, gx):
        cut[nc] = _zero(a, b, lo, x, order + 1, g_lo)
        nc += 1
    if _changes(gx, g_hi):
        cut[nc] = _zero(a, b, x, hi, order + 1, gx)
        nc += 1
    for i in range(1, nc):
        fv[i] = _trig(a, b, cut[i], order)
    cut[nc] = hi
    fv[nc] = f_hi
    for i in range(nc):
        if _changes(fv[i], fv[i + 1]):
            k = _add_root(roots, k, _zero(a, b, cut[i], cut[i + 1], order, fv[i]))
        elif i > 0 and fv[i] != 0.0 and abs(fv[i]) <= tiny and not _changes(fv[i - 1], fv[i]):
            k = _add_root(roots, k, cut[i])  # an extremum at zero to rounding: a double zero
    return k


@njit(cache=True)
def _grid_values(a, b, order):
    """Derivatives ``order``, ``order + 1``, ``order + 2`` of f at the N_GRID + 1 grid ends.

    (3, N_GRID + 1): the coefficients of each derivative (:func:`_trig3`'s ``k^m`` and
    phase) times the tables :data:`_GRID_COS`, :data:`_GRID_SIN`; independent products
    over the grid instead of 129 serial angle-addition recurrences (3 µs less per pose).
    """
    vals = np.zeros((3, N_GRID + 1))
    for j in range(3):
        o = order + j
        u0, v0 = _phase(1.0, 0.0, o), _phase(0.0, 1.0, o)
        if o == 0:
            for m in range(N_GRID + 1):
                vals[j, m] = a[0]
        for k in range(1, a.shape[0]):
            w = 1.0
            for _ in range(o):
                w *= k
            al = w * (u0 * a[k] + v0 * b[k])
            be = w * (u0 * b[k] - v0 * a[k])
            for m in range(N_GRID + 1):
                vals[j, m] += al * _GRID_COS[k, m] + be * _GRID_SIN[k, m]
    return vals


@njit(cache=True)
def _scan(a, b, order, roots):
    """Zeros in [−π, π) of g = f^(order) on a grid of :data:`N_GRID` cells; their count.

    Exact while g'' has at most one zero in every cell. Then g has at most one extremum
    in a cell unless g'' changes sign there while g' keeps its sign and first moves
    toward zero: such a cell is cut at the zero of g'' (:func:`_cell_pieces`). In the
    others, a cell where g changes sign holds exactly one zero (bisected with Newton
    steps); a cell where g keeps its sign and first moves toward zero holds two, a double
    one (an extremum where |g| is below :func:`_tiny`) or none, decided at its extremum;
    the rest hold none, settled from their end values alone.
    """
    tiny = _tiny(a, b, order)
    h = TWO_PI / N_GRID
    vals = _grid_values(a, b, order)
    k = 0
    lo = -math.pi
    f_lo, g_lo, s_lo = vals[0, 0], vals[1, 0], vals[2, 0]
    for m in range(N_GRID):
        hi = -math.pi + h * (m + 1)
        f_hi, g_hi, s_hi = vals[0, m + 1], vals[1, m + 1], vals[2, m + 1]
        if f_lo == 0.0:
            k = _add_root(roots, k, lo)
        if (_changes(s_lo, s_hi) and not _changes(g_lo, g_hi)
                and (g_lo > 0.0) == (s_lo < 0.0)):
            # g' turns in the cell and moves toward zero first: g may have two extrema
            k = _cell_pieces(a, b, lo, hi, f_lo, g_lo, s_lo, f_hi, g_hi, s_hi, tiny, order,
                             roots, k)
        elif _changes(f_lo, f_hi):  # at most one extremum: exactly one zero
            k = _add_root(roots, k, _zero(a, b, lo, hi, order, f_lo))
        elif _changes(g_lo, g_hi) and (f_lo > 0.0) == (g_lo < 0.0):
            # one extremum, and g moves toward zero first: two zeros, a double one, or none
            x = _zero(a, b, lo, hi, order + 1, g_lo)
            fx = _trig(a, b, x, order)
            if _changes(f_lo, fx):
                k = _add_root(roots, k, _zero(a, b, lo, x, order, f_lo))
                k = _add_root(roots, k, _zero(a, b, x, hi, order, fx))
            elif abs(fx) <= tiny:
                k = _add_root(roots, k, x)
        lo, f_lo, g_lo, s_lo = hi, f_hi, g_hi, s_hi
    return k


@njit(cache=True)
def eliminant_roots(a, b, roots, near):
    """Real roots in [−π, π) of the trigonometric polynomial (a, b), and near-real pairs.

    Root isolation by derivatives: the zeros of f'' are found on a grid of
    :data:`N_GRID` cells (:func:`_scan`: exact while f⁗ has at most one zero in a
    cell), and f' is monotone between consecutive ones, so f has at most one extremum
    on each such arc. An arc where f changes sign holds exactly one root; an arc where
    f keeps its sign and first moves toward zero holds two, a double one or none,
    decided at its extremum. Roots of f closer together than a grid cell are so
    separated (the 16-solution arm of Manseur & Doty has four within 3.3°); an extremum
    where |f| is below 1e-10 of the coefficients' size, between two ends of its sign,
    is a double root.

    An extremum of f that comes close to zero without reaching it,
    ``2|f| ≤ η² |f''|`` with η = :data:`NEAR_REAL` (near a pair of complex roots
    t0 ± iη, f ≈ f''·((t − t0)² + η²)/2), is written to ``near``: a pair with a small
    imaginary part, which rounding may have moved off the real line (a near-double real
    root), is a candidate too, and refinement on the pose decides.

    Args:
        a: (DEGREE + 1,) cosine coefficients.
        b: (DEGREE + 1,) sine coefficients (``b[0]`` unused).
        roots: (16,) output: the real roots.
        near: (16,) output: the centres t0 of near-real pairs.

    Returns:
        (number of real roots, number of near-real pairs); (−1, 0) when f vanishes
        identically.
    """
    size = abs(a[0])
    for k in range(1, a.shape[0]):
        size += abs(a[k]) + abs(b[k])
    if size == 0.0:
        return -1, 0
    tiny = _tiny(a, b, 0)
    z2 = np.empty(2 * DEGREE)
    n2 = _scan(a, b, 2, z2)
    k = 0
    kn = 0
    if n2 == 0:  # f' keeps its sign on the circle: f is constant (no root unless ≡ 0)
        return 0, 0
    sort_prefix(z2, n2)
    fz = np.empty(n2)  # f and f' at the zeros of f''
    gz = np.empty(n2)
    for i in range(n2):
        fz[i], gz[i], _unused = _trig3(a, b, math.cos(z2[i]), math.sin(z2[i]), 0)
    for i in range(n2):
        j = i + 1 if i + 1 < n2 else 0
        lo = z2[i]
        hi = z2[j] if j > 0 else z2[0] + TWO_PI
        f_lo, g_lo, f_hi, g_hi = fz[i], gz[i], fz[j], gz[j]
        if f_lo == 0.0:
            k = _add_root(roots, k, lo)
        if _changes(f_lo, f_hi):  # at most one extremum: exactly one root
            k = _add_root(roots, k, _zero(a, b, lo, hi, 0, f_lo))
        elif _changes(g_lo, g_hi) and (f_lo > 0.0) == (g_lo < 0.0):
            # one extremum, and f moves toward zero first: two roots, a double one, or none
            x = _zero(a, b, lo, hi, 1, g_lo)
            fx, _unused, f2 = _trig3(a, b, math.cos(x), math.sin(x), 0)
            if _changes(f_lo, fx):
                k = _add_root(roots, k, _zero(a, b, lo, x, 0, f_lo))
                k = _add_root(roots, k, _zero(a, b, x, hi, 0, fx))
            elif abs(fx) <= tiny:
                k = _add_root(roots, k, x)
            elif 2.0 * abs(fx) <= NEAR_REAL * NEAR_REAL * abs(f2) and kn < near.shape[0]:
                near[kn] = x - TWO_PI * math.floor((x + math.pi) / TWO_PI)
                kn += 1
    return k, kn


@njit(cache=True)
def _half_angle(v, stride, count):
    """θ with ``tan(θ/2) = v[(j+1)·stride] / v[j·stride]``, j the best-conditioned ratio.

    ``v[j·stride]`` for j < count are proportional to ``x^j``; the ratio with the
    largest denominator among the first ``count − 1`` is taken.
    """
    j = 0
    big = -1.0
    for i in range(count - 1):
        if abs(v[i * stride]) > big:
            big = abs(v[i * stride])
            j = i
    return 2.0 * math.atan2(v[(j + 1) * stride], v[j * stride])


@njit(cache=True)
def rr_candidates_from(T, W, P, M, reverse, other_first, F, meta, tol_p, tol_r, out):
    """Every solution of a 6R arm by Raghavan–Roth elimination into ``out`` (16, 6).

    Args:
        T: (4, 4) target pose (world).
        W: (6, 3) unit joint directions at q = 0.
        P: (6, 3) a point of each joint line at q = 0 [m].
        M: (4, 4) tool pose at q = 0.
        reverse: W, P, M describe the reversed chain (joint j is joint 7 − j, tool pose
            M⁻¹), solved for ``T⁻¹``; rows are returned in the robot's joint order.
        other_first: try the splits of the reversal of W, P, M before their own (the
            first split that does not degenerate exactly decides, so the order matters
            on arms near a special class; see
            :func:`~serialkin.ik.analytic.structure.general_structure`).
        F: (7, 4, 4) chain transforms (refinement).
        meta: (6, 5) chain joint data.
        tol_p: Newton position tolerance [m].
        tol_r: Newton rotation tolerance [rad].
        out: (16, 6) output rows (refined, not wrapped).

    Returns:
        the number of distinct converged solutions, one per real root of the eliminant
        (and per near-real pair that converged to a new solution);
        :data:`NEAR_SPECIAL` when no split applies (eliminating joint 6, 5 or 4 of the
        chain or of its reversal, tried in turn while one degenerates exactly,
        :data:`EXACT_TOL`) or the pencil is nearly singular for every θ3
        (:data:`PIVOT_TOL`), and −1 − k
        when a real root gave no new solution even after polishing (a cluster of solutions
        or a singular configuration) or belongs to several solutions
        (:data:`MULTIPLE_TOL`; the k solutions found so far are in ``out``): in both
        cases the caller searches instead.
    """
    # fresh C arrays, as Wr, Pr and Minv are: the caller's may be read-only views, and
    # _rr_split would compile twice (11 s cold each) for the two kinds of arrays
    Wf = W.copy()
    Pf = P.copy()
    Mf = M.copy()
    Minv = inv_rigid(Mf)
    Wr = np.empty((6, 3))  # the reversed chain: joint j is joint 7 − j about the line
    Pr = np.empty((6, 3))  # (−R_Mᵀ w, M⁻¹ p), tool pose M⁻¹, target T⁻¹
    for j in range(6):
        for i in range(3):
            Wr[j, i] = -(W[5 - j, 0] * M[0, i] + W[5 - j, 1] * M[1, i] + W[5 - j, 2] * M[2, i])
            Pr[j, i] = (Minv[i, 0] * P[5 - j, 0] + Minv[i, 1] * P[5 - j, 1]
                        + Minv[i, 2] * P[5 - j, 2] + Minv[i, 3])
    for attempt in range(6):  # eliminated joint 6, 5, 4 of the chain, then of its reversal
        e = 5 - attempt % 3
        if (attempt < 3) != other_first:
            k = _rr_split(T, Wf, Pf, Mf, reverse, e, F, meta, tol_p, tol_r, out)
        else:
            k = _rr_split(T, Wr, Pr, Minv, not reverse, e, F, meta, tol_p, tol_r, out)
        if k == NEAR_SPECIAL:  # near a special class: no split is trusted, search
            return NEAR_SPECIAL
        if k != RANK_DEFICIENT:
            return k
    return NEAR_SPECIAL


@njit(cache=True)
def _rr_split(T, W, P, M, reverse, e, F, meta, tol_p, tol_r, out):
    """:func:`rr_candidates_from` for the split that eliminates joint ``e`` (0-based 5, 4 or 3).

    With ``G = T·M⁻¹ = e1···e6`` and ``x`` the direction and a point of axis e:

    * e = 6: ``e3 e4 e5 x = e2⁻¹ · e1⁻¹ · G x`` (left joints 3, 4, 5; right 2, 1);
    * e = 5: ``e2 e3 e4 x = e1⁻¹ · G · e6⁻¹ x`` (left 2, 3, 4; right 1, 6);
    * e = 4: ``e1 e2 e3 x = G · e6⁻¹ · e5⁻¹ x`` (left 1, 2, 3; right 6, 5);

    in general ``U·exp(−ξ_D θ_D)·V·exp(−ξ_E θ_E)·W'·x`` on the right with U, V, W'
    each I or G; the point ``o`` is on the first left axis.
    """
    # One piece over 80 lines: one elimination (the equations, the matrix polynomial, its
    # eigenproblem and the back-substitution) shares its scratch arrays; split into compiled
    # calls it would add levels that each re-link and re-optimise their callees
    # (docs/compile-time.md).
    scale = 0.0
    for j in range(6):
        for i in range(3):
            scale = max(scale, abs(P[j, i] - P[0, i]))
    for i in range(3):
        scale = max(scale, abs(M[i, 3] - P[0, i]))
    inv_s = 1.0 / max(scale, 1e-300)
    Ts = inv_rigid(T) if reverse else T
    G = mm(Ts, inv_rigid(M))
    I4 = np.eye(4)
    ja, jb, jc = e - 3, e - 2, e - 1  # left joints
    if e == 5:
        jd, je_, Um, Vm, Wm = 1, 0, I4, I4, G  # right: outer D, inner E
    elif e == 4:
        jd, je_, Um, Vm, Wm = 0, 5, I4, G, I4
    else:
        jd, je_, Um, Vm, Wm = 5, 4, G, I4, I4
    w_e = W[e].copy()
    o = P[ja].copy()
    # 1-2. left side: the 14 quantities at 27 sample angles → coefficients (27, 14). The
    # screws of the left joints at the 3 angles move (w_e, c_e) from the inside out: 39
    # direction-and-point products, no 4 × 4 products and no allocation per sample
    S = np.empty((9, 4, 4))  # S[3·a + i]: left joint a (ja, jb, jc) at angle i
    for i in range(3):
        screw_into(W[ja], P[ja], _ANGLES[i], S[i])
        screw_into(W[jb], P[jb], _ANGLES[i], S[3 + i])
        screw_into(W[jc], P[jc], _ANGLES[i], S[6 + i])
    x0 = np.empty(6)
    for i in range(3):
        x0[i] = W[e, i]
        x0[3 + i] = P[e, i]
    X5 = np.empty((3, 6))
    X45 = np.empty((9, 6))
    x = np.empty(6)
    for i5 in range(3):
        _move(S[6 + i5], x0, X5[i5])
        for i4 in range(3):
            _move(S[3 + i4], X5[i5], X45[3 * i4 + i5])
    V = np.empty((27, 14))
    l = np.empty(3)
    p = np.empty(3)
    for i3 in range(3):
        for i4 in range(3):
            for i5 in range(3):
                _move(S[i3], X45[3 * i4 + i5], x)
                for i in range(3):
                    l[i] = x[i]
                    p[i] = (x[3 + i] - o[i]) * inv_s
                _equations(l, p, V, 9 * i3 + 3 * i4 + i5)
    Cl = _to_coefficients(V, 3)
    # right side: 9 samples of (θ_E, θ_D) → coefficients (9, 14)
    for i in range(3):  # S[i]: joint E at −angle i, S[3 + i]: joint D
        screw_into(W[je_], P[je_], -_ANGLES[i], S[i])
        screw_into(W[jd], P[jd], -_ANGLES[i], S[3 + i])
    xw = np.empty(6)
    _move(Wm, x0, xw)
    x1 = np.empty(6)
    V2 = np.empty((9, 14))
    for i1 in range(3):
        _move(S[i1], xw, x)
        _move(Vm, x, x1)
        for i2 in range(3):
            _move(S[3 + i2], x1, X5[0])
            _move(Um, X5[0], x)
            for i in range(3):
                l[i] = x[i]
                p[i] = (x[3 + i] - o[i]) * inv_s
            _equations(l, p, V2, 3 * i1 + i2)
    Cr = _to_coefficients(V2, 2)
    # 3. eliminate θ1, θ2: left null space of Q (14, 8), the last 6 columns of the
    # orthogonal factor of its QR decomposition (Householder, column pivoting)
    Q = np.empty((14, 8))
    for j in range(8):
        for k in range(14):
            Q[k, j] = Cr[j + 1, k]
    rdiag = np.empty(8)
    beta = np.empty(8)
    perm = np.empty(8, dtype=np.int64)
    if not _qr(Q, beta, rdiag, perm) > RANK_TOL:
        return RANK_DEFICIENT
    N = np.zeros((6, 14))  # rows: Q e_9 ... Q e_14
    for r in range(6):
        N[r, 8 + r] = 1.0
        _apply_q(Q, beta, N[r])
    E = np.zeros((6, 27))  # N·(left − constant), basis index 9·a3 + 3·a4 + a5
    for r in range(6):
        for idx in range(27):
            s = 0.0
            for k in range(14):
                s += N[r, k] * Cl[idx, k]
            E[r, idx] = s
        s = 0.0
        for k in range(14):
            s += N[r, k] * Cr[0, k]
        E[r, 0] -= s
    # 4. the pencil K(θ3) = K[0] + cos θ3 K[1] + sin θ3 K[2] on monomials x4^i x5^j
    K = np.zeros((3, 12, 12))
    for r in range(6):
        for a3 in range(3):
            for p4 in range(3):
                for p5 in range(3):
                    s = 0.0
                    for a4 in range(3):
                        h4 = _HALF[a4, p4]
                        if h4 != 0.0:
                            for a5 in range(3):
                                s += E[r, 9 * a3 + 3 * a4 + a5] * h4 * _HALF[a5, p5]
                    K[a3, r, 3 * p4 + p5] = s
                    K[a3, 6 + r, 3 * (p4 + 1) + p5] = s
    # 5. the eliminant det K(θ3): 17 samples → trigonometric coefficients
    A = np.empty((12, 12))
    d = np.empty(_N_DET)
    best = 0.0
    for m in range(_N_DET):
        d[m], ratio = _pencil_det_cs(K, _DFT_COS[1, m], _DFT_SIN[1, m], A)  # θ3 = 2π m / 17
        best = max(best, ratio)
    if best < EXACT_TOL:  # K(θ3) singular for every θ3: this split degenerates exactly
        return RANK_DEFICIENT
    if best < PIVOT_TOL:  # nearly singular for every θ3: an arm near a special class
        return NEAR_SPECIAL
    ca = np.zeros(DEGREE + 1)
    cb = np.zeros(DEGREE + 1)
    for k in range(DEGREE + 1):
        for m in range(_N_DET):
            ca[k] += d[m] * _DFT_COS[k, m]
            cb[k] += d[m] * _DFT_SIN[k, m]
        ca[k] *= (1.0 if k == 0 else 2.0) / _N_DET
        cb[k] *= 2.0 / _N_DET
    cb[0] = 0.0
    roots = np.empty(2 * DEGREE)
    near = np.empty(2 * DEGREE)
    nr, nn = eliminant_roots(ca, cb, roots, near)
    if nr < 0:
        return NEAR_SPECIAL
    # 6-7. back substitution and refinement of every candidate (the real roots, then the
    # near-real pairs); duplicates are dropped only after Newton's method has converged
    # (radius 0: no early stop near a solution already found). A real root whose candidate
    # does not converge to a new solution is polished on the determinant itself and tried
    # once more; a near-real pair that converges to nothing is complex, and dropped
    u6 = np.zeros(3)  # a unit vector ⟂ w_e
    ax = 0 if abs(w_e[0]) < 0.9 else 1
    u6[ax] = 1.0
    dw = w_e[ax]
    for i in range(3):
        u6[i] -= dw * w_e[i]
    nu = math.sqrt(u6[0] ** 2 + u6[1] ** 2 + u6[2] ** 2)
    for i in range(3):
        u6[i] /= nu
    q = np.empty(6)
    ws = np.empty(87)  # work space of _candidate
    iws = np.empty(12, dtype=np.int64)
    k = 0
    lost = False
    for ir in range(nr + nn):
        real = ir < nr
        t3 = roots[ir] if real else near[ir - nr]
        found = False
        for attempt in range(2 if real else 1):
            if attempt == 1:
                t3 = _polish_root(K, t3, A)
            second = _candidate(t3, K, Cl, Cr, Q, beta, rdiag, perm, W, G, e, u6, reverse,
                                A, q, ws, iws)
            if second < MULTIPLE_TOL:  # K(θ3) has a null space of 2+ dimensions: this θ3
                if not real:
                    break
                return -1 - k  # belongs to several solutions, one null vector gives one
            k_new = refine_new(q, T, F, meta, tol_p, tol_r, out, k, 0.0)
            if k_new > k:
                k = k_new
                found = True
                break
        lost = lost or (real and not found)
    if lost:  # a root that gave no new solution: a cluster or a singular configuration
        return -1 - k
    return k


@njit(cache=True)
def _pencil_det(K, t, A):
    """``det K(t)`` and its pivot ratio, ``K(t) = K[0] + cos t K[1] + sin t K[2]``.

    K (3, 12, 12); A (12, 12) is work space (:func:`_pencil_det_cs`).
    """
    return _pencil_det_cs(K, math.cos(t), math.sin(t), A)


@njit(cache=True)
def _pencil_det_cs(K, c, s, A):
    """:func:`_pencil_det` at the angle whose cosine and sine are c, s.

    LU with partial pivoting (17 of these per pose, their angles' cos and sin from a
    table); returns the determinant and min |pivot| / max |pivot|, a cheap lower bound on
    1/cond(K(t)): the determinant's relative accuracy is about machine epsilon over it.
    The loops run to ``A.shape[0]``, not to a constant 12: with constant trip counts the
    17 determinants took 7.4 µs per pose freshly compiled but 15 µs as loaded from
    numba's on-disk cache, which is what every later process runs (general 6R ``ik_all``
    40 µs median instead of 33 µs); with the size read from the array, 7.7 µs both ways.
    """
    n = A.shape[0]
    for i in range(n):
        for j in range(n):
            A[i, j] = K[0, i, j] + c * K[1, i, j] + s * K[2, i, j]
    d = 1.0
    pmin = math.inf
    pmax = 0.0
    for col in range(n):
        piv = col
        big = abs(A[col, col])
        for r in range(col + 1, n):
            if abs(A[r, col]) > big:
                big = abs(A[r, col])
                piv = r
        if big == 0.0:
            return 0.0, 0.0
        pmin = min(pmin, big)
        pmax = max(pmax, big)
        if piv != col:
            d = -d
            for j in range(col, n):
                A[col, j], A[piv, j] = A[piv, j], A[col, j]
        d *= A[col, col]
        inv = 1.0 / A[col, col]
        for r in range(col + 1, n):
            f = A[r, col] * inv
            if f != 0.0:
                for j in range(col + 1, n):
                    A[r, j] -= f * A[col, j]
    return d, pmin / pmax


@njit(cache=True)
def _polish_root(K, t, A):
    """A root of ``det K(θ3)`` near t, by secant steps on the determinant itself.

    The trigonometric interpolant loses relative accuracy where |det| is small compared
    with its largest values (two close roots); the LU determinant does not. Four steps
    at most, each kept only if it moves less than 0.01 rad.
    """
    h = 1e-7
    for _ in range(4):
        d0 = _pencil_det(K, t, A)[0]
        d1 = _pencil_det(K, t + h, A)[0]
        if d1 == d0:
            break
        step = d0 * h / (d1 - d0)
        if not abs(step) < 0.01:
            break
        t -= step
        if abs(step) < 1e-13:
            break
    return t


@njit(cache=True)
def _candidate(t3, K, Cl, Cr, H, beta, rdiag, perm, W, G, e, u, reverse, A, q, ws, iws):
    """The configuration (6,) of root θ3 into ``q`` (robot joint order), step 6.

    For the split eliminating joint ``e`` (see :func:`_rr_split`; "θ3, θ4, θ5" are its
    left joints, "θ1, θ2" its right ones): x4, x5 from the null vector of ``K(θ3)``,
    (cos, sin) of the right joints from ``Q⁺·P``, then joint e by subproblem 1 on its
    axis (``u`` (3,) a unit vector ⟂ it). ``ws`` (87,) and ``iws`` (12,) int are work
    space (no allocation per root).
    """
    v = ws[0:12]
    L = ws[12:26]
    m12 = ws[26:34]
    z = ws[34:42]
    qs = ws[42:48]
    c3, s3 = math.cos(t3), math.sin(t3)
    for i in range(12):
        for j in range(12):
            A[i, j] = K[0, i, j] + c3 * K[1, i, j] + s3 * K[2, i, j]
    second = _null_vector(A, v, ws[48:60], iws)
    big = -1.0
    ib = 0
    for i in range(12):
        if abs(v[i]) > big:
            big = abs(v[i])
            ib = i
    t5 = _half_angle(v[3 * (ib // 3):], 1, 3)
    t4 = _half_angle(v[ib % 3:], 3, 4)
    b3 = (1.0, c3, s3)
    b4 = (1.0, math.cos(t4), math.sin(t4))
    b5 = (1.0, math.cos(t5), math.sin(t5))
    bb = ws[60:87]  # the 27 products of (1, c, s) of the left joints
    for a3 in range(3):
        for a4 in range(3):
            b34 = b3[a3] * b4[a4]
            for a5 in range(3):
                bb[9 * a3 + 3 * a4 + a5] = b34 * b5[a5]
    for kk in range(14):
        s = -Cr[0, kk]
        for idx in range(27):
            s += Cl[idx, kk] * bb[idx]
        L[kk] = s
    # m12 = Q⁺ L: R z = (Qᵀ L)[:8] (the QR of :func:`_qr` in H, beta, rdiag, perm); entries
    # (j = 3·a1 + a2 − 1): c2 0, s2 1, c1 2, s1 5
    _apply_qt(H, beta, L)
    for i in range(7, -1, -1):
        s = L[i]
        for j in range(i + 1, 8):
            s -= H[i, j] * z[j]
        z[i] = s / rdiag[i]
        m12[perm[i]] = z[i]
    qs[e - 3], qs[e - 2], qs[e - 1] = t3, t4, t5
    inner, outer = (0, 1) if e == 5 else ((5, 0) if e == 4 else (4, 5))
    qs[inner] = math.atan2(m12[5], m12[2])
    qs[outer] = math.atan2(m12[1], m12[0])
    # joint e: R_e = (R_1···R_{e−1})ᵀ R_G (R_{e+1}···R_6)ᵀ, applied to u
    x = (u[0], u[1], u[2])
    for j in range(e + 1, 6):
        x = _turn_back(W[j], qs[j], x)
    x = (G[0, 0] * x[0] + G[0, 1] * x[1] + G[0, 2] * x[2],
         G[1, 0] * x[0] + G[1, 1] * x[1] + G[1, 2] * x[2],
         G[2, 0] * x[0] + G[2, 1] * x[1] + G[2, 2] * x[2])
    for j in range(e):
        x = _turn_back(W[j], qs[j], x)
    qs[e] = sp1_dir((W[e, 0], W[e, 1], W[e, 2]), (u[0], u[1], u[2]), x)
    for j in range(6):
        q[j] = qs[5 - j] if reverse else qs[j]
    return second


@njit(cache=True)
def _turn_back(w, theta, x):
    """``Rot(w, θ)ᵀ·x`` for a 3-tuple x, without allocation.

    The operations of ``mtv(rotation(w, θ), x)`` (so the same rounding).
    """
    c = math.cos(theta)
    s = math.sin(theta)
    v = 1.0 - c
    a, b, d = w[0], w[1], w[2]
    r00 = c + a * a * v
    r01 = a * b * v - d * s
    r02 = a * d * v + b * s
    r10 = b * a * v + d * s
    r11 = c + b * b * v
    r12 = b * d * v - a * s
    r20 = d * a * v - b * s
    r21 = d * b * v + a * s
    r22 = c + d * d * v
    return (r00 * x[0] + r10 * x[1] + r20 * x[2], r01 * x[0] + r11 * x[1] + r21 * x[2],
            r02 * x[0] + r12 * x[1] + r22 * x[2])
