"""Jacobian-based IK methods (chapter section 5.3), registered by name.

Each method is a small step kernel written here and compiled into the shared loop of
:mod:`serialkin.ik._kernels`: the default ``lm`` in a loop of its own
(:func:`~serialkin.ik._kernels.compile_method`), the others in one loop shared by
all of them (:func:`~serialkin.ik._kernels.compile_family`: :data:`MEMBERS`), so that
they compile once for all. Adding a built-in method means adding its step, its line in
:data:`MEMBERS` and its branch in :func:`step_member`, and its :func:`_register` call,
all in this file; a user's method is one step kernel and one
:func:`register_method` call (its own loop).
They share the skeleton of :mod:`serialkin.ik.solver`: the same
targets, mask, tolerance, restarts and seeding. Joint limits are respected by
projection after every step (2π shift or nearer limit for revolute joints, clamping for
prismatic ones).

=================  =====================================================================
name               step
=================  =====================================================================
``transpose``      Jacobian transpose, ``Δq = α Jᵀe``, Buss/Wolovich step length
``pinv``           Moore-Penrose pseudoinverse, ``Δq = J⁺e`` (eq 40), step capped
``dls``            damped least squares, ``Δq = Jᵀ(JJᵀ + λ²I)⁻¹e`` (eq 46, corrected)
``lm``             Levenberg-Marquardt, damping λE adapted to the error, limit-aware (default)
``lm_wampler``     ``(JᵀJ + λI)Δq = Jᵀe`` (Wampler 1986)
``lm_chan``        ``(JᵀJ + λE·I)Δq = Jᵀe`` (Chan & Lawrence 1988)
``lm_sugihara``    ``(JᵀJ + (E + λ)I)Δq = Jᵀe`` (Sugihara 2011)
``sdls``           selectively damped least squares by SVD (Buss & Kim 2005)
``newton``         Newton-Raphson (eq 41): full ``J⁺e`` step with backtracking
``gauss_newton``   Gauss-Newton on the normal equations, ``(JᵀJ)⁺Jᵀe``
=================  =====================================================================

(``J`` and ``e`` are weighted by the task mask; ``E = ½ eᵀWe``.)

Trade-offs measured by ``benchmarks/bench_ik.py`` (1,000 random full-pose targets on
Panda, UR5 and Puma 560): ``lm`` solves all of them in about 10 iterations (median);
the methods with a constant damping floor (``dls``, ``lm_wampler``, ``lm_sugihara``)
converge only linearly near singular solutions, where they may run out of patience
(about 1 % of targets); the SVD-based ``pinv``, ``newton``, ``gauss_newton`` and
``sdls`` are robust but cost more per iteration; ``transpose`` needs thousands of
iterations and solves only about 3 in 4 full-pose targets within its budget.

Options (keyword arguments of ``robot.ik``; defaults in ``METHODS[name].options``):
``damping`` (λ), ``stall_window`` (iterations within which the cost must halve before
a restart), ``stall_ratio`` (``lm``: an attempt also restarts when two iterations in a
row each leave the cost above this fraction of its previous value), ``max_step``
(``pinv``: cap on max |Δq_i|; ``sdls``: γ_max), ``rcond`` (relative singular-value
cut-off) and, for ``lm``, ``polish``: when every attempt
failed, refine the best one with a monotone Levenberg-Marquardt down to a local
least-squares minimum, so that an unreachable target returns the closest pose found.
"""

from __future__ import annotations

import math

from serialkin.ik._kernels import (
    W_A,
    W_EN,
    W_FREE,
    W_G,
    W_IDX,
    W_JW,
    W_M6,
    W_QN,
    W_R,
    W_S,
    W_SS,
    W_SU,
    W_SV,
    W_SX,
    W_SY,
    W_TN,
    W_U,
    W_Y6,
    W_Z,
    _jacobi_svd,
    _limit_step,
    _normal,
    _pinv_step,
    _transpose_times,
    compile_family,
    compile_method,
    project_into,
    task_cost,
)
from serialkin.ik.registry import MethodSpec, register_method
from serialkin.kinematics.dls import chol_solve_into, dls_step_into, spd_solve_into
from serialkin.kinematics.kernels import fk_into
from serialkin.model.limits import wrap_into
from serialkin.spatial.kernels import pose_error_into

from .._jit import njit

_PROJECTION = (
    "projection after every step: a revolute joint is shifted by 2π when that brings it "
    "inside its range, else set to the nearer limit; a prismatic joint is clamped"
)
_LIMIT_AWARE = (
    "limit-aware step: joints at a limit whose step points outward are frozen and "
    "the step recomputed for the others; then " + _PROJECTION
)

#: Largest robot of the methods whose iteration costs O(n³) (an n×n system, or an SVD
#: over the n columns of J): about a minute for a failing solve at 1000 joints.
MAX_JOINTS_CUBIC = 1000

# Step kernels: step(q, J, e, cost, p, ctx, ws, dq) -> bool, see serialkin.ik._kernels.
# ctx = (F, meta, Tt, w, sw, lo, hi, revolute, respect); Jw = ws[W_JW], r = ws[W_R] are
# the weighted Jacobian and residual at q.


@njit(cache=True)
def step_transpose(q, J, e, cost, p, ctx, ws, dq):
    """``Δq = α Jwᵀ r`` with ``α = ⟨r, Jw Jwᵀ r⟩ / |Jw Jwᵀ r|²`` (Buss 2004; Wolovich & Elliott).

    The exact minimiser of the linearised residual along the gradient.
    """
    Jw = ws[W_JW]
    r = ws[W_R]
    g = ws[W_G]
    n = q.shape[0]
    _transpose_times(Jw, r, g)
    num = 0.0
    den = 0.0
    for i in range(6):
        v = 0.0
        for j in range(n):
            v += Jw[i, j] * g[j]
        num += r[i] * v
        den += v * v
    alpha = num / den if den > 0.0 else 0.0
    for j in range(n):
        dq[j] = alpha * g[j]
    return True


@njit(cache=True)
def step_pinv(q, J, e, cost, p, ctx, ws, dq):
    """``Δq = Jw⁺ r`` (eq 40; σ below ``rcond·σ_max`` dropped), scaled to max |Δq_i| ≤ max_step.

    ``p = (max_step, rcond)``.
    """
    _pinv_step(ws[W_JW], ws[W_R], dq, p[1], ws[W_SU], ws[W_SV], ws[W_SS])
    _limit_step(dq, p[0])
    return True


@njit(cache=True)
def step_dls(q, J, e, cost, p, ctx, ws, dq):
    """``Δq = Jwᵀ (Jw Jwᵀ + λ² I)⁻¹ r`` (eq 46 as corrected in the errata), fixed λ = ``p[0]``.

    A singular ``Jw Jwᵀ`` with λ = 0 is retried with a 1e-12 relative floor.
    """
    return dls_step_into(ws[W_JW], ws[W_R], p[0] * p[0], 1e-12, ws[W_M6], ws[W_Y6], dq)


@njit(cache=True)
def step_lm(q, J, e, cost, p, ctx, ws, dq):
    """Error-damped Levenberg-Marquardt with a limit-aware active set, λ = ``p[0]``.

    ``(JwᵀJw + μI) Δq = Jwᵀ r`` with ``μ = λE`` (Chan & Lawrence's rule with a small λ,
    plus a 1e-12 relative floor): strongly damped far from the target, the Gauss-Newton
    step (quadratic convergence) at it; every step is taken (non-monotone: it escapes
    shallow local minima that a monotone trust-region LM falls into). With the limits
    respected, a joint at a limit whose step points outward is frozen and the step
    recomputed for the others, at most n times: the minimiser of the same quadratic
    ``½ΔqᵀAΔq − gᵀΔq`` (``A = JwᵀJw + μI``, ``g = Jwᵀr``) with ``Δq_i = 0`` for the
    frozen set S, ``Δq = Δq₀ − A⁻¹E_S λ`` with ``(A⁻¹)_SS λ = (Δq₀)_S`` (Δq₀ the free
    step, E_S the columns of I in S). A's factor is reused: each frozen joint costs two
    triangular substitutions (its column of A⁻¹) and S's small system, not a new normal
    matrix and factorisation.
    """
    # One piece over 80 lines: the active set re-solves the same damped system with the joints
    # at a limit removed; split into compiled calls it would add levels that each re-link and
    # re-optimise their callees (docs/compile-time.md).
    lo = ctx[5]
    hi = ctx[6]
    revolute = ctx[7]
    respect = ctx[8]
    Jw = ws[W_JW]
    r = ws[W_R]
    A = ws[W_A]
    g = ws[W_G]
    n = q.shape[0]
    lam = p[0]
    _normal(Jw, r, A, g)
    d = 0.0
    for i in range(n):
        d = max(d, A[i, i])
    mu = lam * cost + 1e-12 * (1.0 + d)
    for i in range(n):
        A[i, i] += mu
    if not spd_solve_into(A, g, dq, n):
        return False
    if not respect:
        return True
    free = ws[W_FREE]
    Z = ws[W_Z]
    S = ws[W_S]
    idx = ws[W_IDX]
    u = ws[W_U]
    for j in range(n):
        free[j] = 1.0
        g[j] = dq[j]  # g now keeps the free step Δq₀ (A holds the factor)
    k = 0
    for _pass in range(n):
        changed = False
        for i in range(n):
            x = q[i] + dq[i]
            if free[i] == 0.0 or (x >= lo[i] and x <= hi[i]):
                continue
            if revolute[i] != 0 and not math.isnan(wrap_into(x, lo[i], hi[i])):
                continue  # a 2π shift brings it inside: not blocked
            if (x < lo[i] and q[i] <= lo[i] + 1e-12) or (x > hi[i] and q[i] >= hi[i] - 1e-12):
                free[i] = 0.0
                idx[k] = i
                z = Z[k]
                for j in range(n):
                    z[j] = 0.0
                z[i] = 1.0
                chol_solve_into(A, z, z, n)  # A⁻¹ e_i
                k += 1
                changed = True
        if not changed:
            return True
        if k == n:  # every joint frozen
            for j in range(n):
                dq[j] = 0.0
            return True
        for a in range(k):
            ia = int(idx[a])
            u[a] = g[ia]
            for b in range(k):
                S[a, b] = Z[b, ia]
        if not spd_solve_into(S, u, u, k):
            return False
        for j in range(n):
            t = g[j]
            for a in range(k):
                t -= Z[a, j] * u[a]
            dq[j] = t * free[j]  # exactly 0 for the frozen joints
    return True


@njit(cache=True)
def _damped_normal_step(ws, wn, dq):
    """``(JwᵀJw + wn I) Δq = Jwᵀ r``; a singular matrix is retried with a 1e-12 relative floor."""
    Jw = ws[W_JW]
    r = ws[W_R]
    A = ws[W_A]
    g = ws[W_G]
    n = dq.shape[0]
    _normal(Jw, r, A, g)
    d = 0.0
    for i in range(n):
        d = max(d, A[i, i])
        A[i, i] += wn
    if spd_solve_into(A, g, dq, n):
        return True
    # singular normal matrix with a vanishing damping (e.g. a redundant arm at
    # convergence): retry with a 1e-12 relative floor
    _normal(Jw, r, A, g)
    for i in range(n):
        A[i, i] += wn + 1e-12 * (1.0 + d)
    return spd_solve_into(A, g, dq, n)


@njit(cache=True)
def step_lm_wampler(q, J, e, cost, p, ctx, ws, dq):
    """``(JwᵀJw + λI) Δq = Jwᵀ r`` (Wampler 1986), λ = ``p[0]``; every step taken."""
    return _damped_normal_step(ws, p[0], dq)


@njit(cache=True)
def step_lm_chan(q, J, e, cost, p, ctx, ws, dq):
    """``(JwᵀJw + λE I) Δq = Jwᵀ r`` (Chan & Lawrence 1988), λ = ``p[0]``; every step taken."""
    return _damped_normal_step(ws, p[0] * cost, dq)


@njit(cache=True)
def step_lm_sugihara(q, J, e, cost, p, ctx, ws, dq):
    """``(JwᵀJw + (E + λ) I) Δq = Jwᵀ r`` (Sugihara 2011), λ = ``p[0]``; every step taken."""
    return _damped_normal_step(ws, cost + p[0], dq)


@njit(cache=True)
def _sdls_into(Jw, r, dq, gamma_max, W, V, s, rho, phi):
    """Selectively damped least squares step (Buss & Kim 2005), two 3-row blocks.

    ``W`` (≥ 6, n), ``V`` (n, n), ``s`` (n,): the SVD's scratch (``_jacobi_svd``);
    ``rho``, ``phi`` (n,) scratch.
    """
    n = Jw.shape[1]
    _jacobi_svd(Jw, W, V, s)
    smax = 0.0
    for j in range(n):
        a = 0.0
        b = 0.0
        for i in range(3):
            a += Jw[i, j] * Jw[i, j]
            b += Jw[i + 3, j] * Jw[i + 3, j]
        rho[j] = math.sqrt(a) + math.sqrt(b)
        dq[j] = 0.0
        smax = max(smax, s[j])
    if not smax > 0.0:
        return
    for k in range(n):
        if s[k] <= 1e-12 * smax:
            continue
        alpha = 0.0
        a = 0.0
        b = 0.0
        for i in range(3):
            a += W[i, k] * W[i, k]
            b += W[i + 3, k] * W[i + 3, k]
        for i in range(6):
            alpha += W[i, k] * r[i]
        alpha /= s[k]  # α = u_kᵀ r
        N = (math.sqrt(a) + math.sqrt(b)) / s[k]  # |u_k| over the two blocks
        M = 0.0
        for j in range(n):
            M += abs(V[j, k]) * rho[j]
        M /= s[k]
        gamma = gamma_max * min(1.0, N / M) if M > 0.0 else gamma_max
        big = 0.0
        for j in range(n):
            phi[j] = alpha / s[k] * V[j, k]
            big = max(big, abs(phi[j]))
        scale = gamma / big if big > gamma else 1.0
        for j in range(n):
            dq[j] += scale * phi[j]
    _limit_step(dq, gamma_max)



@njit(cache=True)
def step_sdls(q, J, e, cost, p, ctx, ws, dq):
    """Selectively damped least squares (Buss & Kim 2005), γ_max = ``p[0]``.

    Each singular direction's contribution is clamped by ``γ_i = min(1, N_i/M_i)·γ_max``
    and the total by ``γ_max``, with the position and orientation rows as the two "end
    effectors".
    """
    _sdls_into(ws[W_JW], ws[W_R], dq, p[0], ws[W_SU], ws[W_SV], ws[W_SS], ws[W_SX],
               ws[W_SY])
    return True


@njit(cache=True)
def step_newton(q, J, e, cost, p, ctx, ws, dq):
    """Newton-Raphson (eq 41 in n dimensions): ``Δq = Jw⁺ r`` (rcond = ``p[0]``), backtracking.

    The step is halved (at most 11 times) until the projected ``q + Δq`` lowers the cost.
    """
    F = ctx[0]
    meta = ctx[1]
    Tt = ctx[2]
    w = ctx[3]
    lo = ctx[5]
    hi = ctx[6]
    revolute = ctx[7]
    respect = ctx[8]
    qn = ws[W_QN]
    Tn = ws[W_TN]
    en = ws[W_EN]
    n = q.shape[0]
    _pinv_step(ws[W_JW], ws[W_R], dq, p[0], ws[W_SU], ws[W_SV], ws[W_SS])
    s = 1.0
    for _ls in range(12):
        for j in range(n):
            qn[j] = q[j] + s * dq[j]
        if respect:
            project_into(qn, lo, hi, revolute)
        fk_into(qn, F, meta, Tn)
        pose_error_into(Tn, Tt, en)
        if task_cost(en, w) < cost or _ls == 11:
            break
        s *= 0.5
    if s != 1.0:
        for j in range(n):
            dq[j] *= s
    return True


@njit(cache=True)
def step_gauss_newton(q, J, e, cost, p, ctx, ws, dq):
    """Gauss-Newton on the normal equations, ``Δq = (JwᵀJw)⁺ Jwᵀ r`` (rcond ``p[0]``), full step."""
    A = ws[W_A]
    g = ws[W_G]
    _normal(ws[W_JW], ws[W_R], A, g)
    for i in range(dq.shape[0]):  # the upper triangle, which the SVD reads too
        for j in range(i + 1, dq.shape[0]):
            A[i, j] = A[j, i]
    _pinv_step(A, g, dq, p[0], ws[W_SU], ws[W_SV], ws[W_SS])
    return True


# ---------------------------------------------------------------- the shared loop
# The built-in methods other than the default share one compiled loop
# (serialkin.ik._kernels.compile_family), without reference counting: no step allocates
# (the SVD-based ones take their scratch from the workspace). Its step runs member number
# p[0] with that member's parameters p[1:]; the numbers are the members' places in MEMBERS.

#: The members of the shared loop: (name, step, parameters).
MEMBERS = (
    ("transpose", step_transpose, ()),
    ("dls", step_dls, (("damping", True),)),
    ("lm_wampler", step_lm_wampler, (("damping", True),)),
    ("lm_chan", step_lm_chan, (("damping", True),)),
    ("lm_sugihara", step_lm_sugihara, (("damping", True),)),
    ("pinv", step_pinv, (("max_step", False), ("rcond", False))),
    ("sdls", step_sdls, (("max_step", False),)),
    ("newton", step_newton, (("rcond", False),)),
    ("gauss_newton", step_gauss_newton, (("rcond", False),)),
)


@njit(cache=True)
def step_member(q, J, e, cost, p, ctx, ws, dq):
    """The step of member ``p[0]`` of :data:`MEMBERS`, with its parameters ``p[1:]``."""
    code = p[0]
    r = p[1:]
    if code == 0.0:
        return step_transpose(q, J, e, cost, r, ctx, ws, dq)
    if code == 1.0:
        return step_dls(q, J, e, cost, r, ctx, ws, dq)
    if code == 2.0:
        return step_lm_wampler(q, J, e, cost, r, ctx, ws, dq)
    if code == 3.0:
        return step_lm_chan(q, J, e, cost, r, ctx, ws, dq)
    if code == 4.0:
        return step_lm_sugihara(q, J, e, cost, r, ctx, ws, dq)
    if code == 5.0:
        return step_pinv(q, J, e, cost, r, ctx, ws, dq)
    if code == 6.0:
        return step_sdls(q, J, e, cost, r, ctx, ws, dq)
    if code == 7.0:
        return step_newton(q, J, e, cost, r, ctx, ws, dq)
    return step_gauss_newton(q, J, e, cost, r, ctx, ws, dq)


_KERNELS = {
    **compile_family("methods", step_member, MEMBERS),
    "lm": compile_method("lm", step_lm, (("damping", True),), hot=True),
}


def _register(name, max_iter, restarts, options, summary, *, limits=_PROJECTION,
              linear=False):
    """Register the built-in method ``name`` with its compiled loop (``_KERNELS``)."""
    register_method(MethodSpec(
        name=name, family="jacobian", summary=summary, limits=limits,
        max_iter=max_iter, restarts=restarts, options=options, kernel=_KERNELS[name],
        max_joints=None if linear else MAX_JOINTS_CUBIC,
    ))


_register("transpose", 5000, 5, {"stall_window": 1000},
          "Jacobian transpose with the Buss/Wolovich step length (slow, linear convergence)",
          linear=True)
_register("pinv", 100, 50, {"max_step": 0.5, "rcond": 1e-10, "stall_window": 20},
          "Moore-Penrose pseudoinverse step J⁺e (eq 40), steps capped at max_step")
_register("dls", 200, 50, {"damping": 0.01, "stall_window": 30},
          "damped least squares Jᵀ(JJᵀ+λ²I)⁻¹e with fixed damping λ (eq 46)", linear=True)
_register("lm", 100, 100,
          {"damping": 0.03, "stall_window": 5, "stall_ratio": 0.6, "polish": True},
          "Levenberg-Marquardt, damping λE adapted to the error, limit-aware (default)",
          limits=_LIMIT_AWARE)
_register("lm_wampler", 200, 50, {"damping": 1e-4, "stall_window": 30},
          "Levenberg-Marquardt with constant damping λI (Wampler)")
_register("lm_chan", 200, 50, {"damping": 1.0, "stall_window": 30},
          "Levenberg-Marquardt with error-proportional damping λE (Chan-Lawrence)")
_register("lm_sugihara", 200, 50, {"damping": 1e-4, "stall_window": 30},
          "Levenberg-Marquardt with damping E + λ (Sugihara)")
_register("sdls", 500, 30, {"max_step": math.pi / 4, "stall_window": 60},
          "selectively damped least squares by SVD (Buss & Kim)")
_register("newton", 100, 50, {"rcond": 1e-10, "stall_window": 20},
          "Newton-Raphson (eq 41): full pseudoinverse step with backtracking line search")
_register("gauss_newton", 100, 50, {"rcond": 1e-12, "stall_window": 20},
          "Gauss-Newton on the normal equations (JᵀJ)⁺Jᵀe, full step")
