"""Compiled IK loop for the Jacobian family (numba, ``cache=True``).

One general kernel, :func:`solve_one`, runs every Jacobian-based method (chapter section
5.3) selected by a method code, including restarts, the iteration budget, stagnation
detection and joint-limit projection; :func:`solve_chunk` runs it over a range of N
targets with the GIL released, so that the batch driver solves across all cores (one
thread per core). It is built on the only FK/Jacobian implementation
(``serialkin.kinematics._kernels.jacobian_into`` and ``fk_into``) and the only
pose-error implementation
(:func:`serialkin.spatial._kernels.pose_error_into`). The helpers every compiled IK
method shares live here too: the cost and error norms (:func:`task_cost`,
:func:`task_errors`), joint-limit projection, the random starts, and the stopping test
of the heuristic attempts (:func:`stopping_test`, used by CCD and FABRIK).

Notation (shapes): n joints; ``e`` (6,) the pose error ``[p_t − p; log(R_t Rᵀ)^∨]``
(world frame); ``w`` (6,) the task weights (0 drops a coordinate); ``r = √w ⊙ e`` and
``Jw = diag(√w) J`` the weighted residual and Jacobian, so the cost is
``E = ½ Σ w_i e_i² = ½ rᵀr`` and a step ``Δq`` solves ``Jw Δq ≈ r`` (eq 39 read as
``Δx = J Δq``).

Method codes and steps:

* ``TRANSPOSE`` — ``Δq = α Jwᵀ r`` with the step length of Buss (2004) / Wolovich & Elliott
  (1984), ``α = ⟨r, Jw Jwᵀ r⟩ / |Jw Jwᵀ r|²`` (the exact minimiser of the linearised
  residual along the gradient).
* ``PINV`` — ``Δq = Jw⁺ r`` (eq 40; Moore-Penrose pseudoinverse by a one-sided Jacobi
  SVD, :func:`_jacobi_svd`, singular values below ``rcond·σ_max`` dropped), then scaled
  so that ``max |Δq_i| ≤ max_step``.
* ``DLS`` — ``Δq = Jwᵀ (Jw Jwᵀ + λ² I)⁻¹ r`` (eq 46 as corrected in the errata), fixed λ.
* ``LM`` — Levenberg-Marquardt with error-adaptive damping,
  ``(JwᵀJw + μI) Δq = Jwᵀ r`` with ``μ = λE`` (Chan & Lawrence's rule with a small λ,
  so the step is strongly damped far from the target and becomes the Gauss-Newton
  step — quadratic convergence — at it), every step taken (non-monotone: it escapes
  shallow local minima that a monotone trust-region LM falls into), and a
  **limit-aware step**: a joint at a limit whose step points outward is frozen (its
  column removed) and the step recomputed for the others before projection.
* ``LM_WAMPLER`` / ``LM_CHAN`` / ``LM_SUGIHARA`` — ``(JwᵀJw + W_N) Δq = Jwᵀ r`` with
  ``W_N = λ I`` (Wampler 1986), ``W_N = λ E I`` (Chan & Lawrence 1988) and
  ``W_N = E I + λ I`` (Sugihara 2011); every step is taken.
* ``SDLS`` — selectively damped least squares (Buss & Kim 2005): each singular
  direction's contribution is clamped by ``γ_i = min(1, N_i/M_i)·γ_max`` and the total
  by ``γ_max``, with the position and orientation rows as the two "end effectors".
* ``NEWTON`` — Newton-Raphson (eq 41 in n dimensions): the full step ``Δq = Jw⁺ r``,
  then backtracking (halving) until the cost decreases.
* ``GAUSS_NEWTON`` — ``Δq = (JwᵀJw)⁺ Jwᵀ r`` from the normal equations, full step.

Joint limits (``respect`` true) are intervals whose ends may be infinite
(:mod:`serialkin.model.limits`): after every step each joint is projected onto its
range — a revolute joint is first shifted by a multiple of 2π if that brings it inside
(same pose), else set to the nearer limit on the circle; a prismatic joint is clamped.
A step that leaves the range is therefore replaced by its projection (projected
iteration). At the end, unlimited revolute joints are wrapped into [-π, π) and joints
open on one side are tidied without leaving their range (:func:`limits.normalize`).

Stagnation: an attempt ends when the cost has not halved within ``window``
iterations (or becomes non-finite); the solver then restarts from a configuration drawn
uniformly inside the (sampling) limits by a per-target splitmix64 stream. The returned
q is that of the best attempt (lowest cost), so it is always finite. With the polish
flag (method ``lm``), when every attempt failed the best one is refined by a monotone
Levenberg-Marquardt (:func:`_polish`) down to a local least-squares minimum, so an
unreachable target returns the closest pose found.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from serialkin.kinematics._kernels import fk_into, jacobian_into
from serialkin.model.limits import inside as interval_inside
from serialkin.model.limits import normalize as interval_normalize
from serialkin.model.limits import project as interval_project
from serialkin.model.limits import wrap_angle as interval_wrap
from serialkin.spatial._kernels import pose_error_into

TRANSPOSE = 0
PINV = 1
DLS = 2
LM = 3
LM_WAMPLER = 4
LM_CHAN = 5
LM_SUGIHARA = 6
SDLS = 7
NEWTON = 8
GAUSS_NEWTON = 9

#: Layout of the configuration vector ``cfg`` (float64, length N_CFG).
C_WEIGHTS = 0  # 6 task weights w, indices 0..5
C_METHOD = 6  # method code
C_TOL = 7  # tolerance on position [m] and orientation [rad] errors
C_MAX_ITER = 8  # iterations per attempt
C_RESTARTS = 9  # restarts allowed
C_RESPECT = 10  # 1: project onto the joint limits after every step
C_USE_Q0 = 11  # 1: the first attempt starts from q0
P_DAMPING = 12  # λ (DLS, LM, Wampler, Chan, Sugihara)
P_WINDOW = 13  # stagnation window [iterations]
P_MAX_STEP = 14  # max |Δq_i| (PINV) or γ_max (SDLS) [rad / m]
P_RCOND = 15  # relative cut-off for singular values (PINV, NEWTON, GAUSS_NEWTON)
C_POLISH = 16  # 1: after failed attempts, polish the best one with a monotone LM
N_CFG = 17

#: Rows of the per-robot ``box`` array (5, n).
B_LO = 0  # lower joint limits (-inf allowed)
B_HI = 1  # upper joint limits (+inf allowed)
B_SLO = 2  # finite sampling box for random starts, lower
B_SHI = 3  # finite sampling box, upper
B_REVOLUTE = 4  # 1.0 for revolute joints, 0.0 for prismatic

#: Layout of the ``info`` output (float64, length N_INFO).
I_SUCCESS = 0
I_ITERATIONS = 1
I_POS_ERR = 2
I_ORI_ERR = 3
I_RESTARTS = 4
I_COST = 5
N_INFO = 6

#: Status codes of the heuristic attempts (:func:`stopping_test`; CCD and FABRIK).
RUNNING = -1
CONVERGED = 0
MAX_ITER = 1
STAGNATED = 2

TWO_PI = 2.0 * math.pi


# ---------------------------------------------------------------- random stream
@njit(cache=True, inline="always")
def _next_u64(state):
    """splitmix64: advance ``state`` (uint64[1]) and return the next 64-bit output."""
    state[0] = state[0] + np.uint64(0x9E3779B97F4A7C15)
    z = state[0]
    z = (z ^ (z >> np.uint64(30))) * np.uint64(0xBF58476D1CE4E5B9)
    z = (z ^ (z >> np.uint64(27))) * np.uint64(0x94D049BB133111EB)
    return z ^ (z >> np.uint64(31))


@njit(cache=True)
def random_q_into(state, slo, shi, q):
    """Uniform configuration in the box [slo, shi] (n,) into ``q``, from the stream ``state``."""
    for i in range(q.shape[0]):
        u = float(_next_u64(state) >> np.uint64(11)) * (1.0 / 9007199254740992.0)
        q[i] = slo[i] + (shi[i] - slo[i]) * u


# ---------------------------------------------------------------- joint limits
# The interval logic (open ends included) lives in serialkin.model.limits; these loops
# apply it joint by joint.
@njit(cache=True)
def inside_limits(q, lo, hi, tol):
    """True when every q_i (finite) lies in [lo_i − tol, hi_i + tol] (ends may be infinite)."""
    for i in range(q.shape[0]):
        if not interval_inside(q[i], lo[i], hi[i], tol):
            return False
    return True


@njit(cache=True)
def project_into(q, lo, hi, revolute):
    """Project ``q`` (n,) onto the joint ranges [lo, hi], in place (:func:`limits.project`)."""
    for i in range(q.shape[0]):
        q[i] = interval_project(q[i], lo[i], hi[i], revolute[i] != 0)


@njit(cache=True)
def normalize_into(q, lo, hi, revolute):
    """Tidy a final q in place without changing the pose (:func:`limits.normalize`).

    Unlimited revolute joints are wrapped into [-π, π); a revolute joint outside its
    range is shifted by a multiple of 2π when that brings it inside; a joint open on one
    side stays inside its range.
    """
    for i in range(q.shape[0]):
        q[i] = interval_normalize(q[i], lo[i], hi[i], revolute[i] != 0)


# ---------------------------------------------------------------- small dense algebra
@njit(cache=True)
def _chol_solve(A, b, x, m):
    """Solve A x = b for the leading m×m block of the SPD matrix A (destroyed); False if not PD."""
    for j in range(m):
        s = A[j, j]
        for k in range(j):
            s -= A[j, k] * A[j, k]
        if not s > 0.0:
            return False
        d = math.sqrt(s)
        A[j, j] = d
        for i in range(j + 1, m):
            t = A[i, j]
            for k in range(j):
                t -= A[i, k] * A[j, k]
            A[i, j] = t / d
    for i in range(m):
        t = b[i]
        for k in range(i):
            t -= A[i, k] * x[k]
        x[i] = t / A[i, i]
    for i in range(m - 1, -1, -1):
        t = x[i]
        for k in range(i + 1, m):
            t -= A[k, i] * x[k]
        x[i] = t / A[i, i]
    return True


@njit(cache=True, inline="always")
def task_cost(e, w):
    """The weighted cost ``E = ½ Σ w_i e_i²`` of the pose error ``e`` (6,), weights ``w`` (6,)."""
    c = 0.0
    for i in range(6):
        c += w[i] * e[i] * e[i]
    return 0.5 * c


@njit(cache=True, inline="always")
def task_errors(e, w):
    """(position error [m], orientation error [rad]): the norms of ``e`` (6,) over w_i > 0."""
    p = 0.0
    o = 0.0
    for i in range(3):
        if w[i] > 0.0:
            p += e[i] * e[i]
        if w[i + 3] > 0.0:
            o += e[i + 3] * e[i + 3]
    return math.sqrt(p), math.sqrt(o)


@njit(cache=True)
def stopping_test(T, T_target, w, tol_pos, tol_orient, it, window, min_progress, ref, e):
    """Stopping test of a heuristic attempt (CCD, FABRIK) after its iteration ``it`` ≥ 1.

    The pose error of ``T`` (4, 4) against ``T_target`` (4, 4) goes into ``e`` (6,), and
    its norms ``e_p`` [m], ``e_o`` [rad] over the coordinates with ``w_i > 0`` (6,) are
    tested: **converged** when ``e_p ≤ tol_pos`` and ``e_o ≤ tol_orient``; else the scaled
    error ``s = e_p/tol_pos + e_o/tol_orient`` is compared every ``window`` iterations with
    the reference ``ref`` (``s`` at the previous check, at iteration 1 first):
    **stagnated** when ``s > (1 − min_progress)·ref``.

    Returns:
        ``(status, ref)``: CONVERGED, STAGNATED or RUNNING, and the reference to pass to
        the next call (any value before iteration 1).
    """
    pose_error_into(T, T_target, e)
    ep, eo = task_errors(e, w)
    if ep <= tol_pos and eo <= tol_orient:
        return CONVERGED, ref
    score = ep / tol_pos + eo / tol_orient
    if it == 1:
        return RUNNING, score
    if it % window == 0:
        if score > (1.0 - min_progress) * ref:
            return STAGNATED, ref
        return RUNNING, score
    return RUNNING, ref


@njit(cache=True, inline="always")
def _weigh(J, e, sw, Jw, r):
    """Jw = diag(√w) J and r = √w ⊙ e."""
    n = J.shape[1]
    for i in range(6):
        r[i] = sw[i] * e[i]
        for j in range(n):
            Jw[i, j] = sw[i] * J[i, j]


@njit(cache=True, inline="always")
def _transpose_times(Jw, r, g):
    """The product g = Jwᵀ r (n,) of Jw (6, n) and r (6,), in place in ``g``."""
    for i in range(Jw.shape[1]):
        s = 0.0
        for k in range(6):
            s += Jw[k, i] * r[k]
        g[i] = s


@njit(cache=True, inline="always")
def _normal(Jw, r, A, g):
    """A = Jwᵀ Jw (n×n) and g = Jwᵀ r (n,)."""
    n = Jw.shape[1]
    _transpose_times(Jw, r, g)
    for i in range(n):
        for j in range(i, n):
            s = 0.0
            for k in range(6):
                s += Jw[k, i] * Jw[k, j]
            A[i, j] = s
            A[j, i] = s


@njit(cache=True)
def _jacobi_svd(M, W, V, s):
    """Singular value decomposition of a small matrix by one-sided Jacobi (Hestenes).

    ``M`` (m, k) is copied into ``W`` (m, k), whose columns are orthogonalised by plane
    rotations accumulated in ``V`` (k, k), so that ``M = W Vᵀ`` with orthogonal columns:
    ``σ_j = |W[:, j]|`` into ``s`` (k,) (unsorted; k − rank of them are 0) and
    ``u_j = W[:, j] / σ_j``. Accurate to working precision for every singular value and
    allocation free — much cheaper than a LAPACK call for the 6×n matrices of IK.
    """
    m = M.shape[0]
    k = M.shape[1]
    for i in range(m):
        for j in range(k):
            W[i, j] = M[i, j]
    for i in range(k):
        for j in range(k):
            V[i, j] = 1.0 if i == j else 0.0
    frob = 0.0
    for i in range(m):
        for j in range(k):
            frob += M[i, j] * M[i, j]
    tiny = 1e-30 * frob  # columns below this squared norm count as zero (rank deficiency)
    for _sweep in range(60):
        rotated = False
        for p in range(k - 1):
            for q in range(p + 1, k):
                alpha = 0.0
                beta = 0.0
                gamma = 0.0
                for i in range(m):
                    alpha += W[i, p] * W[i, p]
                    beta += W[i, q] * W[i, q]
                    gamma += W[i, p] * W[i, q]
                if alpha <= tiny or beta <= tiny or abs(gamma) <= 1e-15 * math.sqrt(alpha * beta):
                    continue
                rotated = True
                zeta = (beta - alpha) / (2.0 * gamma)
                t = (1.0 if zeta >= 0.0 else -1.0) / (abs(zeta) + math.sqrt(1.0 + zeta * zeta))
                c = 1.0 / math.sqrt(1.0 + t * t)
                sn = c * t
                for i in range(m):
                    wp = W[i, p]
                    wq = W[i, q]
                    W[i, p] = c * wp - sn * wq
                    W[i, q] = sn * wp + c * wq
                for i in range(k):
                    vp = V[i, p]
                    vq = V[i, q]
                    V[i, p] = c * vp - sn * vq
                    V[i, q] = sn * vp + c * vq
        if not rotated:
            break
    for j in range(k):
        t = 0.0
        for i in range(m):
            t += W[i, j] * W[i, j]
        s[j] = math.sqrt(t)


@njit(cache=True)
def _pinv_step(M, rhs, dq, rcond):
    """Pseudoinverse step ``dq = M⁺ rhs`` for a small (m, n) M (σ below rcond·σ_max dropped)."""
    m = M.shape[0]
    n = M.shape[1]
    W = np.empty((m, n))
    V = np.empty((n, n))
    s = np.empty(n)
    _jacobi_svd(M, W, V, s)
    smax = 0.0
    for j in range(n):
        smax = max(smax, s[j])
        dq[j] = 0.0
    if not smax > 0.0:
        return
    cut = rcond * smax
    for k in range(n):
        if s[k] <= cut:
            continue
        a = 0.0
        for i in range(m):
            a += W[i, k] * rhs[i]
        a /= s[k] * s[k]  # u_kᵀ rhs / σ_k with u_k = W[:, k] / σ_k
        for j in range(n):
            dq[j] += a * V[j, k]


@njit(cache=True)
def _sdls_step(Jw, r, dq, gamma_max):
    """Selectively damped least squares step (Buss & Kim 2005), two 3-row blocks."""
    n = Jw.shape[1]
    W = np.empty((6, n))
    V = np.empty((n, n))
    s = np.empty(n)
    _jacobi_svd(Jw, W, V, s)
    rho = np.empty(n)
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
    phi = np.empty(n)
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


@njit(cache=True, inline="always")
def _limit_step(dq, max_step):
    """Scale dq so that max |dq_i| ≤ max_step (direction kept)."""
    big = 0.0
    for j in range(dq.shape[0]):
        big = max(big, abs(dq[j]))
    if big > max_step:
        for j in range(dq.shape[0]):
            dq[j] *= max_step / big


# ---------------------------------------------------------------- one attempt
@njit(cache=True)
def _attempt(F, meta, Tt, w, sw, lo, hi, revolute, respect, method, params, tol, max_iter,
             q, J, T, e, Jw, r, A, g, dq, qn, Jn, Tn, en, M6, y6, free):
    """Iterate ``method`` from q (n,) in place; return (iterations, converged, cost).

    On return q, J, T, e describe the final (last accepted) configuration.
    """
    n = q.shape[0]
    window = int(params[P_WINDOW])
    jacobian_into(q, F, meta, J, T)
    pose_error_into(T, Tt, e)
    cost = task_cost(e, w)
    ref_cost = cost
    ref_it = 0
    for it in range(max_iter):
        pe, oe = task_errors(e, w)
        if pe <= tol and oe <= tol:
            return it, True, cost
        if not math.isfinite(cost):
            return it, False, cost
        if cost < 0.5 * ref_cost:
            ref_cost = cost
            ref_it = it
        elif it - ref_it > window:
            return it, False, cost
        _weigh(J, e, sw, Jw, r)
        if method == LM:
            # error-damped LM, μ = λE, with an active set for the joint limits: a joint
            # that sits at a limit and whose step points outward is frozen (its column
            # removed) and the step recomputed, at most n times.
            for j in range(n):
                free[j] = 1.0
            lam = params[P_DAMPING]
            for _pass in range(n + 1):
                for i in range(6):
                    for j in range(n):
                        Jw[i, j] = sw[i] * J[i, j] * free[j]
                _normal(Jw, r, A, g)
                d = 0.0
                for i in range(n):
                    d = max(d, A[i, i])
                mu = lam * cost + 1e-12 * (1.0 + d)
                for i in range(n):
                    A[i, i] += mu + (1.0 - free[i])
                if not _chol_solve(A, g, dq, n):
                    return it, False, cost
                if not respect:
                    break
                changed = False
                for i in range(n):
                    x = q[i] + dq[i]
                    if free[i] == 0.0 or (x >= lo[i] and x <= hi[i]):
                        continue
                    if revolute[i] != 0 and not math.isnan(interval_wrap(x, lo[i], hi[i])):
                        continue  # a 2π shift brings it inside: not blocked
                    if (x < lo[i] and q[i] <= lo[i] + 1e-12) \
                            or (x > hi[i] and q[i] >= hi[i] - 1e-12):
                        free[i] = 0.0
                        changed = True
                if not changed:
                    break
        elif method == TRANSPOSE:
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
        elif method == DLS:
            lam2 = params[P_DAMPING] * params[P_DAMPING]
            for _retry in range(2):
                d = 0.0
                for i in range(6):
                    for k in range(i, 6):
                        s = 0.0
                        for j in range(n):
                            s += Jw[i, j] * Jw[k, j]
                        M6[i, k] = s
                        M6[k, i] = s
                    d = max(d, M6[i, i])
                for i in range(6):
                    M6[i, i] += lam2
                if _chol_solve(M6, r, y6, 6):
                    break
                lam2 += 1e-12 * (1.0 + d)  # singular JJᵀ with λ = 0: retry with a floor
            else:
                return it, False, cost
            for j in range(n):
                s = 0.0
                for i in range(6):
                    s += Jw[i, j] * y6[i]
                dq[j] = s
        elif method == LM_WAMPLER or method == LM_CHAN or method == LM_SUGIHARA:
            _normal(Jw, r, A, g)
            lam = params[P_DAMPING]
            if method == LM_WAMPLER:
                wn = lam
            elif method == LM_CHAN:
                wn = lam * cost
            else:
                wn = cost + lam
            d = 0.0
            for i in range(n):
                d = max(d, A[i, i])
                A[i, i] += wn
            if not _chol_solve(A, g, dq, n):
                # singular normal matrix with a vanishing damping (e.g. a redundant arm
                # at convergence): retry with a 1e-12 relative floor
                _normal(Jw, r, A, g)
                for i in range(n):
                    A[i, i] += wn + 1e-12 * (1.0 + d)
                if not _chol_solve(A, g, dq, n):
                    return it, False, cost
        elif method == PINV or method == NEWTON:
            _pinv_step(Jw, r, dq, params[P_RCOND])
            if method == PINV:
                _limit_step(dq, params[P_MAX_STEP])
        elif method == GAUSS_NEWTON:
            _normal(Jw, r, A, g)
            _pinv_step(A, g, dq, params[P_RCOND])
        elif method == SDLS:
            _sdls_step(Jw, r, dq, params[P_MAX_STEP])
        step = 1.0
        for _ls in range(12 if method == NEWTON else 1):
            for j in range(n):
                qn[j] = q[j] + step * dq[j]
            if respect:
                project_into(qn, lo, hi, revolute)
            if method != NEWTON:
                break
            fk_into(qn, F, meta, Tn)
            pose_error_into(Tn, Tt, en)
            if task_cost(en, w) < cost:
                break
            step *= 0.5
        q[:] = qn
        jacobian_into(q, F, meta, J, T)
        pose_error_into(T, Tt, e)
        cost = task_cost(e, w)
    pe, oe = task_errors(e, w)
    return max_iter, (pe <= tol and oe <= tol), cost


@njit(cache=True)
def _polish(F, meta, Tt, w, sw, lo, hi, revolute, respect, tol, max_iter,
            q, J, T, e, Jw, r, A, g, dq, qn, Jn, Tn, en):
    """Monotone Levenberg-Marquardt from q (in place) to the nearest least-squares minimum.

    Gain-ratio damping update of Madsen, Nielsen & Tingleff (2004, §3.2): a step is
    accepted only when it lowers the cost (ρ > 0), then ``μ ← μ·max(1/3, 1 − (2ρ − 1)³)``,
    else ``μ ← μ·ν, ν ← 2ν``. Used after every attempt failed, so the best attempt
    reported for an unreachable target is a local minimum of the cost (the closest pose
    the arm can take from there), not wherever a non-monotone iteration stopped.
    Returns (iterations, converged, cost); q, J, T, e describe the final point.
    """
    n = q.shape[0]
    jacobian_into(q, F, meta, J, T)
    pose_error_into(T, Tt, e)
    cost = task_cost(e, w)
    mu = -1.0
    nu = 2.0
    quiet = 0
    for it in range(max_iter):
        pe, oe = task_errors(e, w)
        if pe <= tol and oe <= tol:
            return it, True, cost
        _weigh(J, e, sw, Jw, r)
        _normal(Jw, r, A, g)
        d = 0.0
        for i in range(n):
            d = max(d, A[i, i])
        if mu < 0.0:
            mu = 1e-3 * max(d, 1e-12)
        for i in range(n):
            A[i, i] += mu
        if not _chol_solve(A, g, dq, n):
            return it, False, cost
        for i in range(n):
            qn[i] = q[i] + dq[i]
        if respect:
            project_into(qn, lo, hi, revolute)
        jacobian_into(qn, F, meta, Jn, Tn)
        pose_error_into(Tn, Tt, en)
        cost_n = task_cost(en, w)
        lin = 0.0
        for i in range(6):
            s = 0.0
            for j in range(n):
                s += Jw[i, j] * (qn[j] - q[j])
            lin += (r[i] - s) * (r[i] - s)
        pred = cost - 0.5 * lin
        rho = (cost - cost_n) / pred if pred > 0.0 else -1.0
        if rho > 0.0 and math.isfinite(cost_n):
            quiet = quiet + 1 if cost - cost_n <= 1e-12 * cost else 0
            q[:] = qn
            J[:, :] = Jn
            T[:, :] = Tn
            e[:] = en
            cost = cost_n
            t = 2.0 * rho - 1.0
            mu *= max(1.0 / 3.0, 1.0 - t * t * t)
            nu = 2.0
        else:
            quiet += 1
            mu *= nu
            nu *= 2.0
        if quiet > 10 or mu > 1e16 * (1.0 + d):
            return it + 1, False, cost
    pe, oe = task_errors(e, w)
    return max_iter, (pe <= tol and oe <= tol), cost


@njit(cache=True)
def solve_one(F, meta, Tt, box, q0, cfg, seed, q_out, info):
    """Solve one target with restarts; write the best q into ``q_out`` (n,) and ``info``.

    Args:
        F: (n+1, 4, 4) chain fixed transforms (see :mod:`serialkin.kinematics._kernels`).
        meta: (n, 5) chain joint data.
        Tt: (4, 4) target pose.
        box: (5, n) joint limits, sampling box and joint types (rows ``B_*``).
        q0: (n,) first start configuration, read when ``cfg[C_USE_Q0]`` is 1.
        cfg: (N_CFG,) weights, method code, tolerance, budget and method parameters
            (indices ``C_*`` and ``P_*``).
        seed: uint64 seed of this target's random stream.
        q_out: (n,) output, the best configuration found.
        info: (N_INFO,) output, see ``I_*``.
    """
    n = meta.shape[0]
    w = cfg[C_WEIGHTS:C_WEIGHTS + 6]
    lo = box[B_LO]
    hi = box[B_HI]
    slo = box[B_SLO]
    shi = box[B_SHI]
    revolute = box[B_REVOLUTE]
    method = int(cfg[C_METHOD])
    tol = cfg[C_TOL]
    max_iter = int(cfg[C_MAX_ITER])
    restarts = int(cfg[C_RESTARTS])
    respect = cfg[C_RESPECT] > 0.5
    use_q0 = cfg[C_USE_Q0] > 0.5
    J = np.empty((6, n))
    T = np.empty((4, 4))
    e = np.empty(6)
    Jw = np.empty((6, n))
    r = np.empty(6)
    A = np.empty((n, n))
    g = np.empty(n)
    dq = np.empty(n)
    qn = np.empty(n)
    Jn = np.empty((6, n))
    Tn = np.empty((4, 4))
    en = np.empty(6)
    M6 = np.empty((6, 6))
    y6 = np.empty(6)
    free = np.empty(n)
    q = np.empty(n)
    be = np.empty(6)
    sw = np.empty(6)
    for i in range(6):
        sw[i] = math.sqrt(w[i])
    state = np.empty(1, dtype=np.uint64)
    state[0] = seed
    total = 0
    success = False
    used = 0
    # fallback best: the first start configuration (finite, inside the limits)
    if use_q0:
        q_out[:] = q0
    else:
        state_copy = np.empty(1, dtype=np.uint64)
        state_copy[0] = seed
        random_q_into(state_copy, slo, shi, q_out)
    if respect:
        project_into(q_out, lo, hi, revolute)
    fk_into(q_out, F, meta, T)
    pose_error_into(T, Tt, be)
    best_cost = task_cost(be, w)
    for attempt in range(restarts + 1):
        used = attempt
        if attempt == 0 and use_q0:
            q[:] = q0
        else:
            random_q_into(state, slo, shi, q)
        if respect:
            project_into(q, lo, hi, revolute)
        its, ok, cost = _attempt(F, meta, Tt, w, sw, lo, hi, revolute, respect, method, cfg,
                                 tol, max_iter, q, J, T, e, Jw, r, A, g, dq, qn, Jn, Tn, en,
                                 M6, y6, free)
        total += its
        finite = math.isfinite(cost)
        for i in range(n):
            if not math.isfinite(q[i]):
                finite = False
        if finite and (ok or cost < best_cost):
            best_cost = cost
            q_out[:] = q
            be[:] = e
        if ok:
            success = True
            break
    if not success and cfg[C_POLISH] > 0.5:
        q[:] = q_out
        its, ok, cost = _polish(F, meta, Tt, w, sw, lo, hi, revolute, respect, tol, max_iter,
                                q, J, T, e, Jw, r, A, g, dq, qn, Jn, Tn, en)
        total += its
        if ok or cost < best_cost:
            best_cost = cost
            q_out[:] = q
            be[:] = e
            success = ok
    normalize_into(q_out, lo, hi, revolute)
    pe, oe = task_errors(be, w)
    info[I_SUCCESS] = 1.0 if success else 0.0
    info[I_ITERATIONS] = total
    info[I_POS_ERR] = pe
    info[I_ORI_ERR] = oe
    info[I_RESTARTS] = used
    info[I_COST] = best_cost


@njit(cache=True, nogil=True)
def solve_chunk(F, meta, Tt, box, Q0, cfg, seed, Q_out, info, start, stop):
    """:func:`solve_one` for targets ``start..stop-1`` of ``Tt`` (N, 4, 4), GIL released.

    ``Q0`` (N, n) start configurations (read when ``cfg[C_USE_Q0]`` is 1), ``Q_out``
    (N, n) and ``info`` (N, N_INFO) outputs. The batch driver
    (:func:`serialkin.ik.solver.solve`) hands chunks to every core through
    :func:`serialkin.kinematics.parallel.run`, the scheduler of every batch kernel. Every
    target uses the same random stream ``seed``, so a batch solve returns exactly what
    the single solves with that seed return, whatever the chunking.
    """
    for k in range(start, stop):
        solve_one(F, meta, Tt[k], box, Q0[k], cfg, seed, Q_out[k], info[k])
