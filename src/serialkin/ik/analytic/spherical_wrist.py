"""Closed-form IK of 6-joint arms with a spherical wrist (Pieper's method): up to 8 solutions.

When the last three revolute axes meet in one point, the wrist centre ``c`` (that point
at q = 0) is moved by the first three joints only (joints 4-6 rotate about it), so the
problem splits (D. L. Pieper, PhD thesis, Stanford 1968). The first three joints are
R R R, or R R P (the Stanford arm class: the third joint slides; ``prismatic3`` in the
functions below, which serve both):

1. **Position.** The target puts the wrist centre at ``p_w = T·M⁻¹·c``; find q1..q3 with
   ``exp(ξ1 q1)·exp(ξ2 q2)·exp(ξ3 q3)·c = p_w``:

   * ``puma`` — axes 2 and 3 parallel (direction ``w``): rotations about them keep the
     component of ``c`` along ``w``, so ``(R1(q1)·w)·(p_w − r1) = w·(c − r1)`` gives q1
     (two solutions: shoulder left / right); then q2, q3 place ``exp(−ξ1 q1)·p_w`` by the
     two-link formula of eqs 23-27 (corrected) in the plane ⟂ w (elbow up / down).
     Shoulder and elbow offsets of any size are covered (Puma 560, KUKA, ABB, Fanuc...).
   * ``pieper_intersecting`` — axes 1 and 2 meet at ``o``: rotations about them keep
     the distance to ``o``, so ``|exp(ξ3 q3)·c − o| = |p_w − o|`` gives q3 (subproblem 3),
     then q1, q2 by subproblem 2 (:func:`intersecting_candidates`).
   * ``stanford`` — the same with a slide: ``|c − o + d·w3|² = |p_w − o|²``, i.e.
     ``d² + 2 (w3·h) d + |h|² − |p_w − o|² = 0`` with ``h = c − o``, gives up to two
     strokes d (:func:`~serialkin.ik.analytic.subproblems.sp3_slide`); up to 8
     candidates, usually 4 with a positive stroke.
   * ``pieper_general`` — any other R R R arm (axes 1 and 2 skew, or parallel while
     axes 2 and 3 are not): the invariants of joint 1 give a quartic in q3 (Pieper),
     solved as a degree-2 trigonometric polynomial (:func:`general_candidates`), then
     q2 and q1 in closed form.
   * ``stanford_general`` — R R P whose axes 1 and 2 do not meet (a shoulder offset):
     the same invariants give a polynomial quartic in the stroke
     (:func:`general_candidates` with a prismatic joint 3).
2. **Orientation.** ``R4·R5·R6 = (R1 R2 R3)ᵀ·R_T·R_Mᵀ =: X``; ``R4 R5 w6 = X w6`` gives
   q4, q5 (subproblem 2, two solutions: wrist flip) and q6 follows by subproblem 1.

At a wrist singularity (axes 4 and 6 aligned) only q4 + q6 is determined: one
representative with q4 = 0 is returned.
"""

from __future__ import annotations

import math

import numpy as np

from serialkin.ik.analytic.subproblems import (
    CLAMP,
    SEED_GAP,
    WRIST_SEED,
    add3,
    dot3,
    finalize,
    mv,
    mv3,
    planar2r_frame,
    planar2r_solve,
    polish_real_root,
    poly_roots,
    rot3,
    rotate_point,
    rotation,
    row3,
    sp1_dir,
    sp2_dir,
    sp3,
    sp3_slide,
    sp4,
    sub3,
    target_rotation,
    tup3,
)

from ..._jit import njit

#: Most candidate solutions of a 6-joint arm.
MAX_SOLUTIONS = 8
#: Largest move [rad, or m per m of stroke] of a Pieper quartic's root by its Newton
#: polish; beyond it the polish is undone (it was heading for another root).
POLISH_MOVE = 1e-4


@njit(cache=True)
def wrist_into(gw, gv, W, v, q1, q2, q3, prismatic3, slack, sol, out, k):
    """Append the wrist solutions (q4, q5, q6) for arm joints (q1, q2, q3) to ``out``.

    The arm's rotation is ``R123 = Rot(w1, q1)·Rot(w2, q2)·Rot(w3, q3)`` (without the
    last factor when joint 3 is prismatic), and ``X = R123ᵀ·R_g = R4·R5·R6``.

    ``slack`` > 0 (a nearly ideal arm's seeds): the wrist's subproblem 2 gives its two
    seeds also where the true axes (not quite a spherical wrist) miss the tangency, and
    near the wrist singularity (axis 6 turned by joint 5 within :data:`WRIST_SEED` rad
    of axis 4, ``R5 w6 ≈ s·w4``), where the ideal wrist has the continuum
    ``(q4 + t, q5, q6 − s·t)`` and the true arm isolated solutions anywhere along it,
    two more seeds at t = ±π/2 (the two rows are t = 0 and, flipped, t ≈ π), while
    ``out`` has room: more than :data:`MAX_SOLUTIONS` candidates say that a seed lay
    there.

    Args:
        gw: ``R_g·w6`` (3,), ``R_g = R_T·R_Mᵀ`` the rotation the six joints must produce.
        gv: ``R_g·v`` (3,).
        W: (6, 3) joint directions at q = 0.
        v: (3,) unit vector ⟂ w6.
        q1: arm joint 1 value [rad].
        q2: arm joint 2 value [rad].
        q3: arm joint 3 value [rad, or m when prismatic].
        prismatic3: True when joint 3 slides (Stanford class).
        slack: 0 for an exact solve, > 0 for a nearly ideal arm's seeds.
        sol: (2, 6) scratch array (see :func:`~serialkin.ik.analytic.subproblems.sp2_dir`).
        out: (K, 6) candidate rows; rows k, k+1 (and two more near the singularity) are
            written.
        k: number of rows already in ``out``.

    Returns:
        the new number of rows.
    """
    w4 = row3(W, 3)
    w5 = row3(W, 4)
    w6 = row3(W, 5)
    # X·w6 and X·v with X = R123ᵀ·R_g, by Rodrigues' formula (Rot(w, −θ) = Rot(w, θ)ᵀ):
    # tuples and one sin/cos per joint, no 3 × 3 products and no allocation
    w1 = row3(W, 0)
    w2 = row3(W, 1)
    c1 = math.cos(q1)
    sn1 = -math.sin(q1)
    c2 = math.cos(q2)
    sn2 = -math.sin(q2)
    xw = rot3(w2, c2, sn2, rot3(w1, c1, sn1, gw))
    xv = rot3(w2, c2, sn2, rot3(w1, c1, sn1, gv))
    if not prismatic3:
        w3 = row3(W, 2)
        c3 = math.cos(q3)
        sn3 = -math.sin(q3)
        xw = rot3(w3, c3, sn3, xw)
        xv = rot3(w3, c3, sn3, xv)
    m = sp2_dir(w4, w5, w6, xw, slack, sol)  # (q4, q5) with their cosines and sines
    for r in range(m):
        q6 = sp1_dir(w6, v, rot3(w5, sol[r, 4], -sol[r, 5], rot3(w4, sol[r, 2], -sol[r, 3], xv)))
        if k == out.shape[0]:
            return k
        out[k, 0] = q1
        out[k, 1] = q2
        out[k, 2] = q3
        out[k, 3] = sol[r, 0]
        out[k, 4] = sol[r, 1]
        out[k, 5] = q6
        k += 1
        if slack > 0.0 and r == 0:
            a = rot3(w5, sol[r, 4], sol[r, 5], w6)  # R5·w6
            s = dot3(a, w4)
            if 1.0 - s * s < WRIST_SEED * WRIST_SEED:
                for t in (0.5 * math.pi, -0.5 * math.pi):
                    if k == out.shape[0]:
                        return k
                    out[k, 0] = q1
                    out[k, 1] = q2
                    out[k, 2] = q3
                    out[k, 3] = sol[r, 0] + t
                    out[k, 4] = sol[r, 1]
                    out[k, 5] = q6 - t if s > 0.0 else q6 + t
                    k += 1
    return k


@njit(cache=True)
def puma_positions(pw, W, P, aux, slack, out):
    """Arm joints (q1, q2, q3) of a ``puma``-class arm putting c on ``pw``.

    aux = (c, w, e1 ⟂ w, ...); ``slack``: 0 for an exact solve, > 0 for a nearly ideal
    arm's seeds: shoulder and elbow give two seeds on both sides of their tangencies, also
    just beyond the ideal arm's reach (:func:`~serialkin.ik.analytic.subproblems.acos_seed`).

    Writes rows into ``out`` (4, 3) and returns their count.
    """
    c = row3(aux, 0)
    w = row3(aux, 1)
    e1 = row3(aux, 2)
    w1 = row3(W, 0)
    r1 = row3(P, 0)
    c2 = row3(P, 1)
    c3 = row3(P, 2)
    buf = np.empty(10)
    q1s = buf[0:6]  # angles, then the cosine and sine of each (sp4)
    sol = buf[6:10].reshape((2, 2))
    frame = planar2r_frame(w, e1, c2, c3, c)  # joints 2, 3 carrying c, once, not per branch
    d = sub3((pw[0], pw[1], pw[2]), r1)
    n1 = sp4(w1, w, d, dot3(w, sub3(c, r1)), slack, q1s)
    k = 0
    s2 = dot3(row3(W, 1), w)
    s3 = dot3(row3(W, 2), w)
    for i in range(n1):
        q1 = q1s[i]
        x = add3(rot3(w1, q1s[2 + 2 * i], -q1s[3 + 2 * i], d), r1)  # exp(−ξ1 q1)·pw
        m = planar2r_solve(frame, x, sol, slack)
        for j in range(m):
            out[k, 0] = q1
            out[k, 1] = s2 * sol[j, 0]
            out[k, 2] = s3 * sol[j, 1]
            k += 1
    return k


@njit(cache=True)
def intersecting_positions(pw, W, P, aux, prismatic3, slack, out):
    """Arm joints when axes 1 and 2 meet at o; aux = (c, o, ...). Rows into ``out`` (4, 3).

    Rotations about axes 1 and 2 keep the distance to ``o``, so joint 3 alone must give
    the wrist centre its target distance ``|p_w − o|``: subproblem 3 for a revolute
    joint 3 (``pieper_intersecting``), :func:`~serialkin.ik.analytic.subproblems.sp3_slide`
    for a prismatic one (``prismatic3``, ``stanford``). Up to two values of q3; q1, q2
    then carry the moved centre onto ``p_w`` (subproblem 2, two solutions each).
    Returns the count. The subproblems take their vectors as tuples (:func:`row3`,
    :func:`tup3`). ``slack``: 0 for an exact solve, > 0 for a nearly ideal arm's seeds
    (both sides of the tangencies of q3 and of q1, q2; not for a slide).
    """
    c = aux[0].copy()
    o = aux[1].copy()
    w3 = W[2].copy()
    r3 = P[2].copy()
    h = c - o
    g = pw - o
    gt = tup3(g)
    q3s = np.empty(2)
    if prismatic3:
        n3 = sp3_slide(tup3(w3), tup3(h), dot3(gt, gt), q3s)
    else:
        n3 = sp3(tup3(w3), tup3(r3), tup3(c), tup3(o), np.sqrt(dot3(gt, gt)), slack, q3s)
    sol = np.empty((2, 2))
    k = 0
    for i in range(n3):
        q3 = q3s[i]
        if prismatic3:
            x = h + q3 * w3
        else:
            x = rotate_point(w3, r3, q3, c) - o
        m = sp2_dir(row3(W, 0), row3(W, 1), tup3(x), gt, slack, sol)
        for j in range(m):
            out[k, 0] = sol[j, 0]
            out[k, 1] = sol[j, 1]
            out[k, 2] = q3
            k += 1
    return k


@njit(cache=True)
def _general_residual(theta, c, w3, r3, r2, w2, a1, ca, sa, rho2, h):
    """E(θ3) = g1² + g2² − (|u|² − (w2·u)²) of the general arm (see general_candidates)."""
    x = rotate_point(w3, r3, theta, c)  # u = Rot(w3, θ)·(c − r3) + r3 − r2, scalar
    u0 = x[0] - r2[0]
    u1 = x[1] - r2[1]
    u2 = x[2] - r2[2]
    uu = u0 * u0 + u1 * u1 + u2 * u2
    wu = w2[0] * u0 + w2[1] * u1 + w2[2] * u2
    g1 = (rho2 - uu - a1 * a1) / (2.0 * a1)
    g2 = (h - ca * wu) / sa
    return g1 * g1 + g2 * g2 - (uu - wu * wu)


@njit(cache=True)
def general_positions(pw, W, P, aux, prismatic3, slack, out):
    """Arm joints of a ``pieper_general`` / ``stanford_general`` arm; aux = (c, r1, r2, n, m, ...).

    Writes rows (q1, q2, q3) putting c on ``pw`` into ``out`` (4, 3); returns the count.

    Axes 1 and 2 do not meet: r1, r2 are the feet of their common perpendicular, a1 = |r2 − r1|,
    n = (r2 − r1)/a1, m = w2 × n, and w1 = cα·w2 + sα·m. With u = exp(ξ3 q3)·c − r2 and
    x = exp(ξ2 θ2)·(r2 + u) the point that joint 1 must turn onto p_w, the invariants of
    joint 1 (distance to r1 and height along w1) give (Pieper; Craig, *Introduction to
    Robotics*, section 4.6)

    * n·R2 u = g1 = (|p_w − r1|² − |u|² − a1²)/(2 a1),
    * m·R2 u = g2 = (w1·(p_w − r1) − cα w2·u)/sα,

    and since R2 turns the (n, m) components of u rigidly, E(q3) = g1² + g2² − (|u|² − (w2·u)²)
    must vanish. Revolute joint 3 (``pieper_general``): u = Rot(w3, θ3)·(c − r3) + r3 − r2 and
    E is a trigonometric polynomial of degree 2 (:func:`_quartic_theta3`). Prismatic joint 3
    (``prismatic3``, ``stanford_general``): u = c + d·w3 − r2 is linear in the stroke d and
    E(d) a polynomial quartic (:func:`_quartic_stroke`). Up to 4 values of q3; then
    θ2 = atan2(g2, g1) − atan2(m·u, n·u) and θ1 by subproblem 1.

    When axes 1 and 2 are parallel (sα = 0) the second invariant reads w2·u = cα·w1·(p_w − r1)
    instead: θ3 by :func:`~serialkin.ik.analytic.subproblems.sp4` (two values) or d directly
    (one), and g2 = ±sqrt(|u|² − (w2·u)² − g1²) (two values of θ2 each).

    ``slack``: 0 for an exact solve; > 0 for a nearly ideal arm's seeds: a pair of roots
    just off the real axis (a near-double root the ideal arm lacks) gives two seeds
    mirrored onto it, and tangencies give two seeds on both sides
    (:func:`~serialkin.ik.analytic.subproblems.acos_seed`).

    The subproblems take their vectors as tuples (:func:`row3`, :func:`tup3`); the
    intermediate vectors stay in arrays, so that no rounding changes (fused operations
    across the tuples would).
    """
    # One piece over 80 lines: the quartic's coefficients, its roots and their polish
    # share the arm's lines and the target's terms; split into compiled calls it would
    # add levels that each re-link and re-optimise their callees (docs/compile-time.md).
    c = aux[0].copy()
    r1 = aux[1].copy()
    r2 = aux[2].copy()
    n = row3(aux, 3)
    m = row3(aux, 4)
    w1 = row3(W, 0)
    w2 = W[1].copy()
    w2t = row3(W, 1)
    w3 = W[2].copy()
    w3t = row3(W, 2)
    r3 = P[2].copy()
    d = tup3(pw - r1)
    a1 = dot3(tup3(r2 - r1), n)
    ca = dot3(w1, w2t)
    sa = dot3(w1, m)
    rho2 = dot3(d, d)
    h = dot3(w1, d)
    h0 = c - r2
    parallel = abs(sa) < 1e-9
    thetas = np.empty(4)
    if prismatic3:
        nt = _quartic_stroke(tup3(h0), w3t, w2t, a1, ca, sa, rho2, h, parallel, slack, thetas)
    elif parallel:  # axes 1 ∥ 2: w2·u(θ3) = cα·h fixes θ3 (two values), g2 = ±sqrt(..)
        nt = sp4(w3t, tup3(c - r3), w2t, ca * h - dot3(w2t, tup3(r3 - r2)), slack, thetas)
    else:
        nt = _quartic_theta3(c, w3, r3, r2, w2, a1, ca, sa, rho2, h, slack, thetas)
    k = 0
    for i in range(nt):
        th = thetas[i]
        if prismatic3:
            u = h0 + th * w3
        else:
            u = mv(rotation(w3, th), c - r3) + r3 - r2
        ut = tup3(u)
        uu = dot3(ut, ut)
        wu = dot3(w2t, ut)
        g1 = (rho2 - uu - a1 * a1) / (2.0 * a1)
        if parallel:
            g2sq = uu - wu * wu - g1 * g1
            if slack > 0.0:  # seeds on both sides of the tangency (as acos_seed)
                perp = max(uu - wu * wu, 1e-300)
                if g2sq < -slack * perp:
                    continue
                g2sq = max(abs(g2sq), SEED_GAP * SEED_GAP * perp)
            elif g2sq < -CLAMP * max(uu, 1e-300):
                continue
            g2 = math.sqrt(max(g2sq, 0.0))
            ng = 1 if g2 == 0.0 else 2
        else:
            g2 = (h - ca * wu) / sa
            ng = 1
        for j in range(ng):
            gj = g2 if j == 0 else -g2
            th2 = math.atan2(gj, g1) - math.atan2(dot3(m, ut), dot3(n, ut))
            x = mv(rotation(w2, th2), u) + r2
            th1 = sp1_dir(w1, tup3(x - r1), d)
            if k == out.shape[0]:
                return k
            out[k, 0] = th1
            out[k, 1] = th2
            out[k, 2] = th
            k += 1
    return k


#: e^{−ikθ_j}/5 at the 5 samples θ_j = 2πj/5 (k = 0, 1, 2): their discrete Fourier weights.
_FIVE = np.array([[np.exp(-1j * k * 2.0 * np.pi * j / 5.0) / 5.0 for k in range(3)]
                  for j in range(5)])


@njit(cache=True)
def _quartic_theta3(c, w3, r3, r2, w2, a1, ca, sa, rho2, h, slack, thetas):
    """Real roots θ3 of E(θ3) (degree-2 trigonometric polynomial) into ``thetas``; the count.

    The Fourier coefficients c0, c1, c2 of E come exactly from 5 equally spaced samples;
    the roots of ``z²·E(z)`` (z = e^{iθ}) near the unit circle
    (:func:`~serialkin.ik.analytic.subproblems.poly_roots`) are polished by Newton's
    method on E and kept when E vanishes there. The polish keeps the root it started
    from: near a double root E' nearly vanishes and a Newton step can jump to another
    root (two solutions 1e-3 rad apart then came back as one, the other pair lost), so
    a polish that moves more than :data:`POLISH_MOVE` is undone.

    ``slack`` > 0 (a nearly ideal arm's seeds): a root z = e^{i(θ0 + iτ)} off the circle
    (|τ| > 1e-7) with |τ| <= ``slack`` (a real pair of the true arm that the ideal one
    has as a complex pair, or a double root) gives the seed θ0 + τ, so the pair z, 1/z̄
    gives θ0 ± τ, at least :data:`~serialkin.ik.analytic.subproblems.SEED_GAP` apart
    (:func:`_spread`); seeds are not required to make E vanish. Measured on a Pieper arm
    perturbed by 1e-8: at a pose 1e-3 rad from its elbow singularity the ideal arm's pair
    was complex (τ = 6e-4) where the true arm's solutions lie 1.4e-3 apart.
    """
    coef = np.zeros(3, dtype=np.complex128)
    scale = 0.0
    for j in range(5):
        e = _general_residual(2.0 * np.pi * j / 5.0, c, w3, r3, r2, w2, a1, ca, sa, rho2, h)
        scale = max(scale, abs(e))
        for k in range(3):
            coef[k] += e * _FIVE[j, k]
    poly = np.empty(5, dtype=np.complex128)  # z²·E(z) = c2 z⁴ + c1 z³ + c0 z² + c̄1 z + c̄2
    poly[0] = coef[2]
    poly[1] = coef[1]
    poly[2] = coef[0]
    poly[3] = np.conj(coef[1])
    poly[4] = np.conj(coef[2])
    big = max(abs(poly[0]), abs(poly[1]), abs(poly[2]))
    if big <= 1e-12 * max(scale, 1e-300):
        return 0  # E(θ3) ≡ 0: a continuum of solutions (excluded by the structure test)
    # when c2 vanishes both ends of z²·E do: drop the z factor (no spurious root z = 0)
    roots = np.empty(4, dtype=np.complex128)
    nr = poly_roots(poly if abs(poly[0]) > 1e-13 * big else poly[1:4], roots)
    c0r = coef[0].real
    c1r = coef[1].real
    c1i = coef[1].imag
    c2r = coef[2].real
    c2i = coef[2].imag
    count = 0
    for z in roots[:nr]:
        if count == thetas.shape[0]:
            continue
        th = math.atan2(z.imag, z.real)
        tau = -math.log(max(abs(z), 1e-300))  # z = e^{i(θ0 + iτ)}
        if slack > 0.0 and abs(tau) > 1e-7:  # complex, or a double root: both sides
            if abs(tau) <= slack:
                thetas[count] = th + math.copysign(max(abs(tau), SEED_GAP), tau)
                count += 1
            continue
        if abs(abs(z) - 1.0) > 1e-3:
            continue
        start = th
        for _ in range(8):  # Newton on E(θ) = c0 + 2 Re(c1 e^{iθ} + c2 e^{2iθ}), real form
            cs = math.cos(th)
            sn = math.sin(th)
            cs2 = cs * cs - sn * sn
            sn2 = 2.0 * sn * cs
            f = c0r + 2.0 * (c1r * cs - c1i * sn + c2r * cs2 - c2i * sn2)
            df = -2.0 * (c1r * sn + c1i * cs + 2.0 * (c2r * sn2 + c2i * cs2))
            if df == 0.0:
                break
            step = f / df
            th -= step
            if abs(step) < 1e-15:
                break
        if not abs(th - start) <= POLISH_MOVE:
            th = start  # jumped towards another root: keep the one it started from
        if slack > 0.0 or abs(_general_residual(th, c, w3, r3, r2, w2, a1, ca, sa, rho2, h)) \
                <= 1e-8 * max(scale, 1e-300):
            thetas[count] = th
            count += 1
    if slack > 0.0:
        _spread(thetas, count)
    return count


@njit(cache=True)
def _spread(seeds, count):
    """Move seeds closer than :data:`~serialkin.ik.analytic.subproblems.SEED_GAP` apart.

    Two seeds of a nearly ideal arm at (nearly) one double root become their midpoint
    ± SEED_GAP / 2, one on each side of the tangency (Newton's method converges to the
    solution on its side); ``seeds[:count]`` in place.
    """
    for i in range(count):
        for j in range(i + 1, count):
            if abs(seeds[i] - seeds[j]) < SEED_GAP:
                mid = 0.5 * (seeds[i] + seeds[j])
                lo = seeds[i] <= seeds[j]
                seeds[i] = mid - 0.5 * SEED_GAP if lo else mid + 0.5 * SEED_GAP
                seeds[j] = mid + 0.5 * SEED_GAP if lo else mid - 0.5 * SEED_GAP


@njit(cache=True)
def _quartic_stroke(h0, b, w2, a1, ca, sa, rho2, h, parallel, slack, strokes):
    """Real roots d of E(d), joint 3 prismatic (see :func:`general_candidates`); the count.

    With u = h0 + d·b (h0 = c − r2, b = w3): g1 = K2 d² + K1 d + K0, g2 = L1 d + L0 and
    |u|² − (w2·u)² = N2 d² + N1 d + N0, so E(d) = g1² + g2² − (N2 d² + N1 d + N0) is a
    quartic, solved by :func:`~serialkin.ik.analytic.subproblems.poly_roots`; the real
    roots are polished by Newton's method and kept when E vanishes there. With ``parallel``
    axes 1, 2 the height w2·u(d) = cα·h gives the one stroke d directly. ``h0``, ``b``,
    ``w2`` tuples. A polish that moves a root more than :data:`POLISH_MOVE`·max(1, |d|) is
    undone (as in :func:`_quartic_theta3`); ``slack`` > 0 (a nearly ideal arm's seeds): a
    root d0 + iτ with |τ| <= ``slack``·max(1, |d0|) gives the seed d0 + τ (the conjugate
    pair gives d0 ± τ), not required to make E vanish.
    """
    wb = dot3(w2, b)
    wh = dot3(w2, h0)
    ns = 0
    if parallel:
        if abs(wb) > 1e-12:
            strokes[0] = (ca * h - wh) / wb
            ns = 1
        return ns
    K2 = -1.0 / (2.0 * a1)
    K1 = -dot3(b, h0) / a1
    K0 = (rho2 - dot3(h0, h0) - a1 * a1) / (2.0 * a1)
    L1 = -ca * wb / sa
    L0 = (h - ca * wh) / sa
    N2 = 1.0 - wb * wb
    N1 = 2.0 * (dot3(b, h0) - wh * wb)
    N0 = dot3(h0, h0) - wh * wh
    coefs = np.array([K2 * K2, 2.0 * K1 * K2, K1 * K1 + 2.0 * K0 * K2 + L1 * L1 - N2,
                      2.0 * K0 * K1 + 2.0 * L0 * L1 - N1, K0 * K0 + L0 * L0 - N0])
    roots = np.empty(4, dtype=np.complex128)
    roots = roots[:poly_roots(coefs.astype(np.complex128), roots)]
    big = 0.0
    for cf in coefs:
        big = max(big, abs(cf))
    for z in roots:
        if ns == strokes.shape[0]:
            continue
        size = max(1.0, abs(z.real))
        if abs(z.imag) > 1e-4 * size:
            if slack > 0.0 and abs(z.imag) <= slack * size:
                strokes[ns] = z.real + math.copysign(max(abs(z.imag), SEED_GAP * size),
                                                     z.imag)
                ns += 1
            continue
        d = polish_real_root(coefs, z.real)
        if not abs(d - z.real) <= POLISH_MOVE * size:
            d = z.real
        f = 0.0
        for cf in coefs:
            f = f * d + cf
        if slack > 0.0 or abs(f) <= 1e-9 * big * max(1.0, d * d * d * d):
            strokes[ns] = d
            ns += 1
    return ns


@njit(cache=True)
def arm_positions(pw, W, P, aux, arm, prismatic3, slack, out):
    """Joints (q1, q2, q3) that put the point ``aux[0]`` (at q = 0) on ``pw`` (3,) [m].

    ``arm`` 0: axes 2 ∥ 3 (:func:`puma_positions`); 1: axes 1, 2 meet
    (:func:`intersecting_positions`); 2: otherwise (:func:`general_positions`). Rows into
    ``out`` (4, 3); returns their count (0-4). ``slack``: 0 for an exact solve, > 0 for
    the seeds of a nearly ideal arm (two on both sides of every tangency, also just
    beyond the ideal arm's reach; :func:`~serialkin.ik.analytic.subproblems.acos_seed`).
    """
    if arm == 0:
        return puma_positions(pw, W, P, aux, slack, out)
    if arm == 1:
        return intersecting_positions(pw, W, P, aux, prismatic3, slack, out)
    return general_positions(pw, W, P, aux, prismatic3, slack, out)


@njit(cache=True)
def wrist_candidates(T, W, P, M, aux, arm, prismatic3, slack, out):
    """Candidate rows (8, 6) of a spherical-wrist arm: the arm joints, then the wrist.

    ``aux[0]`` is the wrist centre c and ``aux[-1]`` a unit vector ⟂ w6; returns the count.
    ``slack``: 0 for an exact solve, > 0 for a nearly ideal arm's seeds (:func:`arm_positions`).
    """
    Rg = target_rotation(T, M)
    scratch = np.empty(27)  # wrist centre, arm rows, wrist scratch: one allocation
    pw = scratch[0:3]
    pw[0], pw[1], pw[2] = add3(mv3(Rg, sub3(row3(aux, 0), (M[0, 3], M[1, 3], M[2, 3]))),
                               (T[0, 3], T[1, 3], T[2, 3]))  # T·M⁻¹·c
    arm3 = scratch[3:15].reshape((4, 3))
    sol = scratch[15:27].reshape((2, 6))
    m = arm_positions(pw, W, P, aux, arm, prismatic3, slack, arm3)
    v = row3(aux, aux.shape[0] - 1)
    gw = mv3(Rg, row3(W, 5))
    gv = mv3(Rg, v)
    k = 0
    for i in range(m):
        k = wrist_into(gw, gv, W, v, arm3[i, 0], arm3[i, 1], arm3[i, 2], prismatic3, slack,
                       sol, out, k)
    return k


@njit(cache=True)
def solve_spherical_wrist(T, W, P, M, aux, arm, prismatic3, revolute, qlim, mid, F, meta,
                          tol_p, tol_r, out):
    """Every solution of a spherical-wrist 6R / R R P arm inside the limits, sorted, into ``out``.

    Args:
        T: (4, 4) target pose (world).
        W: (6, 3) unit joint directions at q = 0.
        P: (6, 3) a point of each joint line at q = 0 [m].
        M: (4, 4) tool pose at q = 0.
        aux: class data (see the candidate functions).
        arm: 0 for ``puma``, 1 when axes 1 and 2 meet (``pieper_intersecting``,
            ``stanford``), 2 otherwise (``pieper_general``, ``stanford_general``).
        prismatic3: True when joint 3 slides (``stanford``, ``stanford_general``).
        revolute: (6,) booleans, True for revolute joints.
        qlim: (6, 2) joint limits.
        mid: (6,) wrapping centres of the revolute joints.
        F: (7, 4, 4) chain transforms (for the verification by forward kinematics).
        meta: (6, 5) chain joint data.
        tol_p: position tolerance [m].
        tol_r: rotation-entry tolerance.
        out: (8, 6) output.

    Returns:
        number of solutions (0-8).
    """
    cand = np.zeros((MAX_SOLUTIONS, 6))
    k = wrist_candidates(T, W, P, M, aux, arm, prismatic3, 0.0, cand)
    return finalize(cand, k, revolute, qlim, mid, F, meta, T, True, tol_p, tol_r, out)
