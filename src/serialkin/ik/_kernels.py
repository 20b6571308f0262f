"""The compiled IK loop every Jacobian-family method shares (numba, ``cache=True``).

A compiled IK method is a small **step kernel** (written and registered in its family's
file, e.g. :mod:`serialkin.ik.jacobian_methods`); everything else — restarts, the
iteration budget, the tolerance test, joint-limit projection, stagnation detection, the
final polish and the result — is this module's one loop. :func:`compile_method` builds,
from a step kernel, the method's :class:`CompiledMethod`: a ``solve_chunk`` (targets
``start..stop-1``, each with restarts, with the GIL released, so the batch driver solves
across all cores; one target from Python is a chunk of one) and a ``solve_fast`` (one
target behind packed arguments, the default options' path). It is built on the only
FK/Jacobian implementation (``serialkin.kinematics.kernels.jacobian_into`` and
``fk_into``), the only pose-error implementation
(:func:`serialkin.spatial.kernels.pose_error_into`) and the one Cholesky solve
(:func:`serialkin.kinematics.dls.spd_solve_into`). The helpers every
compiled IK method shares live here too: the cost and error norms (:func:`task_cost`,
:func:`task_errors`), joint-limit projection, the random starts, small dense algebra
(normal equations, a Jacobi SVD, the pseudoinverse step) and the stopping test of the
heuristic attempts (:func:`stopping_test`, used by CCD and FABRIK).

Kernel contract: these functions trust their input; validation happens at the public
boundary (:func:`serialkin.ik.solver.solve`).

Notation (shapes): n joints; ``e`` (6,) the pose error ``[p_t − p; log(R_t Rᵀ)^∨]``
(world frame); ``w`` (6,) the task weights (0 drops a coordinate); ``r = √w ⊙ e`` and
``Jw = diag(√w) J`` the weighted residual and Jacobian, so the cost is
``E = ½ Σ w_i e_i² = ½ rᵀr`` and a step ``Δq`` solves ``Jw Δq ≈ r`` (eq 39 read as
``Δx = J Δq``).

**The step kernel** is an ``@njit`` function ``step(q, J, e, cost, p, ctx, ws, dq) -> bool``:
from the configuration ``q`` (n,) with its Jacobian ``J`` (6, n), pose error ``e`` (6,) and
cost ``E``, with the weighted ``Jw`` and ``r`` already in the workspace, it writes the
step ``Δq`` into ``dq`` (n,) and returns True (False: no step possible, the attempt
ends). A step only reads ``Jw`` and ``r``: with unit weights (every full-pose target)
they are ``J`` and ``e`` themselves, not copies (3-4 % of a solve). It is called from
the attempt loop (a direct call that LLVM may inline), which is compiled without numba's
reference counting (NRT: an incref/decref of every array it touches, every iteration)
unless it is built with ``compile_method(..., allocates=True)``: a step that allocates or
copies arrays, itself or in a helper it calls, needs it (the built-in steps allocate nothing:
the SVD-based ones take their scratch from ``ws``). numba's
IR-level inlining of the step and the loop's helpers (``inline="always"``) saved 8 % of
the instructions of a Puma 560 solve (cachegrind, 20,000 solves) but doubled the cold
compile of a first ``robot.ik`` (18.8 → 33.5 s): dropped. ``p`` holds the method's
parameters (the option values named by
``CompiledMethod.params``, in that order); ``ctx`` is the tuple
``(F, meta, Tt, w, sw, lo, hi, revolute, respect)`` (chain, target, weights and
``√w``, limits, whether to respect them) and ``ws`` the scratch tuple indexed by the
``W_*`` constants (``Jw`` (6, n), ``r`` (6,), ``A`` (n, n), ``g`` (n,), ``M6`` (6, 6),
``y6`` (6,), ``free`` (n,), ``qn`` (n,), ``Tn`` (4, 4), ``en`` (6,), for ``lm``'s
active set ``Z`` (n, n), ``S`` (n, n), ``idx`` (n,), ``u`` (n,), and for the SVD-based
steps (:func:`_pinv_step`) ``SU`` (max(n, 6), n), ``SV`` (n, n), ``SS`` (n,) and two
vectors ``SX``, ``SY`` (n,)). The loop then moves to ``q + Δq`` projected onto the joint
ranges.

Why the loop is compiled with its step bound (rather than a step passed as a
first-class function): numba specialises a function on the dispatcher of a function
argument but cannot cache that specialisation across processes (every import would
recompile the loop, seconds per method). :func:`compile_method` instead copies the
loop's Python functions with the step bound as a global, under a name that carries the
method's name and a hash of the sources, so each loop is cached on disk like any kernel
and the step is a direct call that LLVM inlines. A loop compiled per method costs its
compile per method (7-10 s cold each, about 2 s more for each further entry), so the
built-in methods other than the default share one loop: :func:`compile_family` binds a
step that dispatches on a member number (``p[0]``) to the members' steps, and the loop
and its entries compile once for the whole family. A method registered later (a user's
step) gets a loop of its own, and the default ``lm`` keeps its own, the smallest one,
so that a first ``robot.ik`` compiles nothing else.

Joint limits (``respect`` true) are intervals whose ends may be infinite
(:mod:`serialkin.model.limits`): after every step each joint is projected onto its
range — a revolute joint is first shifted by a multiple of 2π if that brings it inside
(same pose), else set to the nearer limit on the circle; a prismatic joint is clamped.
A step that leaves the range is therefore replaced by its projection (projected
iteration). At the end, unlimited revolute joints are wrapped into [-π, π) and joints
open on one side are tidied without leaving their range (:func:`limits.normalize`).

Stagnation: an attempt ends when the cost has not halved within ``window``
iterations (or becomes non-finite), or — with a stall ratio ρ > 0 (``cfg[C_STALL_RATIO]``,
the option ``stall_ratio``) — when two iterations in a row each leave the cost above ρ
times its previous value: an attempt caught at a joint-limit local minimum creeps
(typically 0.9-0.999 per iteration) where a converging one gains orders of magnitude
(measured on Panda and Puma 560 from random starts: 10-18 % fewer iterations in all,
the same success). The solver then restarts from a configuration drawn
uniformly inside the (sampling) limits by a per-target splitmix64 stream. The returned
q is that of the best attempt (lowest cost), so it is always finite. With the polish
flag (method ``lm``), when every attempt failed the best one is refined by a monotone
Levenberg-Marquardt (:func:`_polish`) down to a local least-squares minimum, so an
unreachable target returns the closest pose found.
"""

from __future__ import annotations

import functools
import hashlib
import math
from dataclasses import dataclass, replace

import numpy as np

from serialkin.collision.queries import PAIR_NONE, clearance_at, pair_distance_at
from serialkin.ik.turns import turn_toward
from serialkin.kinematics.dls import dls_step_into, spd_solve_into
from serialkin.kinematics.kernels import fk_all_into, jacobian_into
from serialkin.model.limits import inside as interval_inside
from serialkin.model.limits import normalize as interval_normalize
from serialkin.model.limits import project as interval_project
from serialkin.spatial.kernels import pose_error_into, transforms_valid

from .._jit import as_readonly, bind, dependency_stamp, njit

#: Layout of the configuration vector ``cfg`` (float64): the loop's slots, then the
#: method's parameters ``cfg[N_LOOP:]`` (``CompiledMethod.params``, in order).
C_WEIGHTS = 0  # 6 task weights w, indices 0..5
C_TOL = 6  # tolerance on position [m] and orientation [rad] errors
C_MAX_ITER = 7  # iterations per attempt
C_RESTARTS = 8  # restarts allowed
C_RESPECT = 9  # 1: project onto the joint limits after every step
C_USE_Q0 = 10  # 1: the first attempt starts from q0
C_WINDOW = 11  # stagnation window [iterations]
C_POLISH = 12  # 1: after failed attempts, polish the best one with a monotone LM
C_STALL_RATIO = 13  # ρ in [0, 1): two iterations in a row with cost > ρ · previous end it
N_LOOP = 14

#: Indices of the step kernels' workspace tuple ``ws``.
W_JW = 0  # (6, n) weighted Jacobian diag(√w) J
W_R = 1  # (6,) weighted residual √w ⊙ e
W_A = 2  # (n, n)
W_G = 3  # (n,)
W_M6 = 4  # (6, 6)
W_Y6 = 5  # (6,)
W_FREE = 6  # (n,)
W_QN = 7  # (n,)
W_TN = 8  # (4, 4)
W_EN = 9  # (6,)
W_Z = 10  # (n, n) lm's active set: rows A⁻¹e_j of the frozen joints j
W_S = 11  # (n, n) lm's active set: the frozen block of A⁻¹, then its factor
W_IDX = 12  # (n,) lm's active set: the frozen joints' indices (as floats)
W_U = 13  # (n,) lm's active set: right-hand side, then the multipliers
W_SU = 14  # (max(n, 6), n) SVD of an (m, n) matrix, m <= max(n, 6): its columns, rotated
W_SV = 15  # (n, n) SVD: the accumulated rotations
W_SS = 16  # (n,) SVD: the singular values
W_SX = 17  # (n,) scratch of the SVD-based steps
W_SY = 18  # (n,) scratch of the SVD-based steps

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
I_INSIDE = 6  # 1: the returned q lies inside the joint limits (within LIMIT_TOL)
I_CLEARANCE = 7  # clearance of the returned q [m] (+inf when nothing is checked)
I_PAIR = 8  # 5 slots: the closest pair (collision.queries.clearance_at's ``pair``)
N_INFO = 13

#: Layout of the collision options ``ccfg`` (float64) of the collision-aware solves.
K_MARGIN = 0  # required clearance [m], >= 0
K_PUSHES = 1  # push-out steps allowed per attempt that reaches the target in collision
N_CCFG = 2

#: Push-out step: clearance asked beyond the margin [m], cap on max |Δq_i| [rad or m],
#: forward-difference step of the clearance gradient [rad or m].
PUSH_EXTRA = 0.01
PUSH_MAX = 0.5
PUSH_H = 1e-6

#: Tolerance of the final "q inside the joint limits" test of a success [rad or m].
LIMIT_TOL = 1e-12

#: Status codes of the heuristic attempts (:func:`stopping_test`; CCD and FABRIK).
RUNNING = -1
CONVERGED = 0
MAX_ITER = 1
STAGNATED = 2

TWO_PI = 2.0 * math.pi


# ---------------------------------------------------------------- random stream
@njit(cache=True)
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
def rows_inside_limits(Q, lo, hi, tol):
    """True when every row of ``Q`` (N, n) passes :func:`inside_limits`."""
    for k in range(Q.shape[0]):
        if not inside_limits(Q[k], lo, hi, tol):
            return False
    return True


@njit(cache=True)
def project_into(q, lo, hi, revolute):
    """Project ``q`` (n,) onto the joint ranges [lo, hi], in place (:func:`limits.project`)."""
    for i in range(q.shape[0]):
        x = q[i]
        if not (x >= lo[i] and x <= hi[i]):  # inside: unchanged, without the call
            q[i] = interval_project(x, lo[i], hi[i], revolute[i] != 0)


@njit(cache=True)
def normalize_into(q, lo, hi, revolute):
    """Tidy a final q in place without changing the pose (:func:`limits.normalize`).

    Unlimited revolute joints are wrapped into [-π, π); a revolute joint outside its
    range is shifted by a multiple of 2π when that brings it inside; a joint open on one
    side stays inside its range.
    """
    for i in range(q.shape[0]):
        q[i] = interval_normalize(q[i], lo[i], hi[i], revolute[i] != 0)


@njit(cache=True)
def nearest_into(q, ref, lo, hi, revolute, bounded):
    """Move each revolute q_i (in place) to its 2π-representative nearest ``ref_i``.

    The rule of :mod:`serialkin.ik.turns`, by its one implementation
    (:func:`~serialkin.ik.turns.turn_toward`: half-turn ties to the even number of turns,
    at most :data:`~serialkin.ik.turns.MAX_TURNS` turns), on every revolute joint whose
    range [lo_i, hi_i] is wider than 2π; with ``bounded`` False (limits not kept) on
    every revolute joint, as if unlimited. Prismatic joints are untouched; ``ref`` (n,)
    is the initial guess q0.
    """
    for i in range(q.shape[0]):
        if revolute[i] == 0:
            continue
        if not bounded:
            q[i] = turn_toward(q[i], ref[i], -np.inf, np.inf)
        elif hi[i] - lo[i] > TWO_PI:
            q[i] = turn_toward(q[i], ref[i], lo[i], hi[i])


@njit(cache=True)
def pose_and_q0_valid(T, q0, lo, hi, rot_tol, has_q0):
    """True when ``T`` (4, 4) is a rigid transform and ``q0`` (n,) is inside [lo, hi].

    ``T`` must pass :func:`~serialkin.spatial.kernels.transforms_valid` (finite,
    orthonormal within ``rot_tol``) and, when ``has_q0``, ``q0`` be finite and inside the
    limits within 1e-12. The solvers' fast path asks this one question inside its
    compiled call; when the answer is False the ordinary checks
    (:func:`~serialkin.ik.target.parse_target`, :func:`~serialkin.ik.target.check_q0`)
    run and raise the precise error.
    """
    # T and q0 are the caller's (writeable) arrays, only read: typed read-only, as the
    # ordinary path passes them, so that the checks compile once
    if not transforms_valid(as_readonly(T).reshape((1, 4, 4)), rot_tol):
        return False
    return not has_q0 or inside_limits(as_readonly(q0), lo, hi, 1e-12)


# ---------------------------------------------------------------- small dense algebra
@njit(cache=True)
def task_cost(e, w):
    """The weighted cost ``E = ½ Σ w_i e_i²`` of the pose error ``e`` (6,), weights ``w`` (6,)."""
    c = 0.0
    for i in range(6):
        c += w[i] * e[i] * e[i]
    return 0.5 * c


@njit(cache=True)
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
    its norms ``e_p`` [m], ``e_o`` [rad] over the coordinates with ``w_i > 0`` (``w`` (6,),
    the attempt's read-only weights: the type the IK loop passes to :func:`task_errors`)
    are tested: **converged** when ``e_p ≤ tol_pos`` and ``e_o ≤ tol_orient``; else the scaled
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


@njit(cache=True)
def _weigh(J, e, sw, Jw, r):
    """Jw = diag(√w) J and r = √w ⊙ e."""
    n = J.shape[1]
    for i in range(6):
        r[i] = sw[i] * e[i]
        for j in range(n):
            Jw[i, j] = sw[i] * J[i, j]


@njit(cache=True)
def _transpose_times(Jw, r, g):
    """The product g = Jwᵀ r (n,) of Jw (6, n) and r (6,), in place in ``g``."""
    for i in range(Jw.shape[1]):
        s = 0.0
        for k in range(6):
            s += Jw[k, i] * r[k]
        g[i] = s


@njit(cache=True)
def _normal(Jw, r, A, g):
    """The lower triangle of A = Jwᵀ Jw (n×n, diagonal included) and g = Jwᵀ r (n,).

    The lower triangle is all :func:`~serialkin.kinematics.dls.spd_solve_into` reads (a
    caller that needs all of A mirrors it). Each entry is a sum of six products added
    pairwise, ``((a₀ + a₁) + (a₂ + a₃)) + (a₄ + a₅)``: three dependent additions instead
    of six, which lets the processor overlap the entries (about 30 % faster for the 6×6
    and 7×7 systems of IK than a running sum, to rounding the same). Row i is computed
    along the contiguous rows of Jw, which LLVM vectorises (7×7: 55 → 38 ns against the
    column order, the same bits).
    """
    n = Jw.shape[1]
    J0, J1, J2, J3, J4, J5 = Jw[0], Jw[1], Jw[2], Jw[3], Jw[4], Jw[5]
    for j in range(n):
        g[j] = (J0[j] * r[0] + J1[j] * r[1]) + (J2[j] * r[2] + J3[j] * r[3]) \
            + (J4[j] * r[4] + J5[j] * r[5])
    for i in range(n):
        a0, a1, a2, a3, a4, a5 = J0[i], J1[i], J2[i], J3[i], J4[i], J5[i]
        Ai = A[i]
        for j in range(i + 1):
            Ai[j] = (a0 * J0[j] + a1 * J1[j]) + (a2 * J2[j] + a3 * J3[j]) \
                + (a4 * J4[j] + a5 * J5[j])


@njit(cache=True)
def _jacobi_svd(M, W, V, s):
    """Singular value decomposition of a small matrix by one-sided Jacobi (Hestenes).

    ``M`` (m, k) is copied into the first m rows of ``W`` (≥ m, k), whose columns are
    orthogonalised by plane rotations accumulated in ``V`` (k, k), so that ``M = W Vᵀ``
    with orthogonal columns (W's first m rows): ``σ_j = |W[:, j]|`` into ``s`` (k,)
    (unsorted; k − rank of them are 0) and ``u_j = W[:, j] / σ_j``. Accurate to working
    precision for every singular value and allocation free — much cheaper than a LAPACK
    call for the 6×n matrices of IK.
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
def _pinv_step(M, rhs, dq, rcond, W, V, s):
    """Pseudoinverse step ``dq = M⁺ rhs`` for a small (m, n) M (σ below rcond·σ_max dropped).

    ``W`` (≥ m, n), ``V`` (n, n), ``s`` (n,): the SVD's scratch (:func:`_jacobi_svd`).
    """
    m = M.shape[0]
    n = M.shape[1]
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
def _limit_step(dq, max_step):
    """Scale dq so that max |dq_i| ≤ max_step (direction kept)."""
    big = 0.0
    for j in range(dq.shape[0]):
        big = max(big, abs(dq[j]))
    if big > max_step:
        for j in range(dq.shape[0]):
            dq[j] *= max_step / big


@njit(cache=True, inline="always")
def _workspace(n):
    """The loop's four buffers for n joints, ``(B, C, T2, state)``; :func:`_carve` cuts them.

    ``B`` (4n + 29 + max(n, 6), n), ``C`` (13, 6), ``T2`` (2, 4, 4) float64 and ``state``
    (1,) uint64.
    Four allocations rather than one per array; the views are cut where they are used
    (:func:`_carve`), in a function without reference counting when it can be: with it,
    each view costs an atomic increment and decrement of its buffer's count.
    """
    return (np.empty((4 * n + 29 + max(n, 6), n)), np.empty((13, 6)), np.empty((2, 4, 4)),
            np.empty(1, dtype=np.uint64))


@njit(cache=True, inline="always")
def _carve(buffers):
    """The loop's arrays, C-contiguous views of :func:`_workspace`'s buffers.

    Returns ``(J (6, n), T (4, 4), e (6,), dq (n,), q (n,), be (6,), sw (6,), ws, Jn (6, n),
    state (1,) uint64, hit_q (n,), hit_e (6,))`` with ``ws`` the step kernels' scratch
    tuple (``W_*``), ``Jn`` the polish's trial Jacobian, ``state`` the random stream and
    ``hit_q``, ``hit_e`` the best target-reaching configuration a guard refused and its
    error (:func:`_restarts`). Arrays of one width share a buffer as its rows or blocks of
    rows: such a view costs a few ns, where a reshaped slice of one flat buffer costs
    tens (numba's reshape helper).
    """
    B, C, T2, state = buffers
    n = B.shape[1]
    J, Jw, Jn = B[3 * n:3 * n + 6], B[3 * n + 6:3 * n + 12], B[3 * n + 12:3 * n + 18]
    V = B[3 * n + 18:3 * n + 29]  # dq, q, g, free, qn, idx, u, hit_q, SS, SX, SY
    return (J, T2[0], C[0], V[0], V[1], C[1], C[2],
            (Jw, C[3], B[:n], V[2], C[6:12], C[4], V[3], V[4], T2[1], C[5], B[n:2 * n],
             B[2 * n:3 * n], V[5], V[6], B[4 * n + 29:], B[3 * n + 29:4 * n + 29], V[8], V[9],
             V[10]), Jn, state, V[7], C[12])


@njit(cache=True, inline="always")
def _settings(cfg, box):
    """The loop's settings from ``cfg`` (indices ``C_*``) and ``box`` (rows ``B_*``).

    Returns ``(w, p, lo, hi, slo, shi, revolute, tol, max_iter, restarts, respect,
    use_q0, window, ratio)``: the task weights (6,), the method's parameters, the joint
    limits and sampling box (n,) each, the joint types, the tolerance, the iteration
    budget per attempt, the restarts, whether limits are respected, whether q0 is the
    first start, the stagnation window and stall ratio.
    """
    return (cfg[C_WEIGHTS:C_WEIGHTS + 6], cfg[N_LOOP:], box[B_LO], box[B_HI], box[B_SLO],
            box[B_SHI], box[B_REVOLUTE], cfg[C_TOL], int(cfg[C_MAX_ITER]),
            int(cfg[C_RESTARTS]), cfg[C_RESPECT] > 0.5, cfg[C_USE_Q0] > 0.5,
            int(cfg[C_WINDOW]), cfg[C_STALL_RATIO])


@njit(cache=True)
def _finite_attempt(cost, q):
    """Whether an attempt ended with a finite cost and a finite q (n,)."""
    if not math.isfinite(cost):
        return False
    for i in range(q.shape[0]):
        if not math.isfinite(q[i]):
            return False
    return True


@njit(cache=True)
def _tidy(q_out, q0, use_q0, lo, hi, revolute, respect):
    """Tidy the returned q (n,) in place: wrapped, then turned nearest to q0, or to zero.

    :func:`normalize_into`, then :func:`nearest_into` toward q0 when given, else (limits
    respected) toward zero, which ``q0`` then holds: the representative the result
    promises (:mod:`serialkin.ik.turns`), given here rather than by a Python pass after
    the call (:func:`serialkin.ik.solver.with_nearest_turns`, 4 µs of a 10 µs solve).
    """
    normalize_into(q_out, lo, hi, revolute)
    if use_q0 or respect:
        nearest_into(q_out, q0, lo, hi, revolute, respect)


# ---------------------------------------------------------------- the shared loop
# The three functions below are templates: compile_method copies them with the method's
# step kernel (and the copies that call it) bound as globals, then compiles the copies.
def _attempt(F, meta, Tt, w, sw, lo, hi, revolute, respect, p, window, ratio, tol, max_iter,
             q, J, T, e, dq, ws, fresh):
    """Iterate the step kernel from q (n,) in place; return (iterations, converged, cost).

    Stagnation (module docstring): the cost has not halved within ``window`` iterations,
    or, with ``ratio`` > 0, two iterations in a row each left it above ``ratio`` times
    its previous value. With ``fresh`` False, J, T, e already hold the Jacobian, pose and
    error at q (the caller evaluated them). On return q, J, T, e describe the final
    configuration.
    """
    n = q.shape[0]
    Jw = ws[W_JW]
    r = ws[W_R]
    qn = ws[W_QN]
    unit = True
    for i in range(6):
        unit &= sw[i] == 1.0
    if unit:  # Jw = J and r = e: the step reads them in place (steps never write them)
        ws = (J, e) + ws[2:]
    ctx = (F, meta, Tt, w, sw, lo, hi, revolute, respect)
    if fresh:
        jacobian_into(q, F, meta, J, T)
        pose_error_into(T, Tt, e)
    cost = task_cost(e, w)
    ref_cost = cost
    ref_it = 0
    prev = math.inf
    slow = 0
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
        if ratio > 0.0 and cost > ratio * prev:
            slow += 1
            if slow == 2:
                return it, False, cost
        else:
            slow = 0
        prev = cost
        if not unit:
            _weigh(J, e, sw, Jw, r)
        if not step(q, J, e, cost, p, ctx, ws, dq):  # noqa: F821 (bound by compile_method)
            return it, False, cost
        for j in range(n):
            qn[j] = q[j] + dq[j]
        if respect:
            project_into(qn, lo, hi, revolute)
        for j in range(n):
            q[j] = qn[j]
        jacobian_into(q, F, meta, J, T)
        pose_error_into(T, Tt, e)
        cost = task_cost(e, w)
    pe, oe = task_errors(e, w)
    return max_iter, (pe <= tol and oe <= tol), cost


@njit(cache=True)
def _copy(src, dst):
    """``dst[:] = src`` for two distinct C-contiguous 1-D arrays of one length.

    A 2-D array is passed as its flat view ``a.reshape(a.size)`` (one compiled type).
    A loop, not numba's slice assignment, which may allocate a temporary (it guards
    against overlap): the per-target loop runs without reference counting and may not.
    """
    for i in range(src.shape[0]):
        dst[i] = src[i]


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
        if not spd_solve_into(A, g, dq, n):
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
            _copy(qn, q)
            _copy(Jn.reshape(Jn.size), J.reshape(J.size))
            _copy(Tn.reshape(16), T.reshape(16))
            _copy(en, e)
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
def _polish_best(F, meta, Tt, w, sw, lo, hi, revolute, respect, tol, max_iter, q, q_out,
                 J, T, e, be, dq, ws, Jn, best_cost):
    """The final polish (:func:`_polish`) from the best attempt ``q_out``, kept when better.

    Returns (success, best cost, iterations): ``q_out`` and its error ``be`` are replaced
    when the polish converges or lowers the cost.
    """
    _copy(q_out, q)
    its, ok, cost = _polish(F, meta, Tt, w, sw, lo, hi, revolute, respect, tol, max_iter,
                            q, J, T, e, ws[W_JW], ws[W_R], ws[W_A], ws[W_G], dq,
                            ws[W_QN], Jn, ws[W_TN], ws[W_EN])
    if ok or cost < best_cost:
        _copy(q, q_out)
        _copy(e, be)
        return ok, cost, its
    return False, best_cost, its


@njit(cache=True)
def _write_info(info, success, total, be, w, used, best_cost, q_out, lo, hi, clearance):
    """Fill ``info`` (N_INFO,) but the closest pair: see the ``I_*`` indices."""
    pe, oe = task_errors(be, w)
    info[I_SUCCESS] = 1.0 if success else 0.0
    info[I_ITERATIONS] = total
    info[I_POS_ERR] = pe
    info[I_ORI_ERR] = oe
    info[I_RESTARTS] = used
    info[I_COST] = best_cost
    info[I_INSIDE] = 1.0 if inside_limits(as_readonly(q_out), lo, hi, LIMIT_TOL) else 0.0
    info[I_CLEARANCE] = clearance


def _restarts(F, meta, Tt, box, q0, cfg, seed, q_out, info, wsp, guard):
    """Solve one target with restarts in the workspace ``wsp`` (:func:`_workspace`).

    The one restart loop of every compiled method, plain and collision-aware: a template
    that :func:`compile_method` binds twice, to the method's ``attempt_loop`` and to one
    of two guards, ``accept`` and ``final``, that decide whether a configuration reaching
    the target is a solution:

    * plain (:func:`_accept_all`, :func:`_no_clearance`; ``guard`` the empty tuple):
      every one is;
    * collision-aware (:func:`_push_accept`, :func:`_final_clearance`; ``guard`` from
      :func:`_solve_one_collision`): one whose clearance is at least the margin, after up
      to a number of push-out steps, each followed by the attempt loop again.

    The first start (q0, else the stream's first draw) is evaluated once: it is the
    fallback best (finite, inside the limits) and the first attempt starts there; each
    later attempt starts from the stream's next draw. A finite attempt that does not
    reach the target becomes the best when its cost is lower, until a guard has refused
    a target-reaching one; the first accepted attempt ends the loop. Without one, the
    refused attempt of largest clearance is returned (``hit_q``); else the best attempt
    is polished (``cfg[C_POLISH]``, :func:`_polish_best`). q is then tidied
    (:func:`_tidy`) and ``info`` written (``final`` gives the clearance and the pair).

    Args:
        F: (n+1, 4, 4) chain fixed transforms (see :mod:`serialkin.kinematics.kernels`).
        meta: (n, 5) chain joint data.
        Tt: (4, 4) target pose.
        box: (5, n) joint limits, sampling box and joint types (rows ``B_*``).
        q0: (n,) first start configuration, read when ``cfg[C_USE_Q0]`` is 1; zeros
            otherwise (the reference of the final 2π turns, :func:`_tidy`).
        cfg: weights, tolerance, budget (indices ``C_*``), then the method's parameters
            ``cfg[N_LOOP:]``.
        seed: uint64 seed of this target's random stream.
        q_out: (n,) output, the best configuration found.
        info: (N_INFO,) output, see ``I_*``.
        wsp: the loop's buffers (:func:`_workspace` of n), overwritten.
        guard: the guard's data (see above).
    """
    (w, p, lo, hi, slo, shi, revolute, tol, max_iter, restarts, respect, use_q0, window,
     ratio) = _settings(cfg, box)
    Tt = as_readonly(Tt)  # only read: the loop's kernels see read-only targets, as all do
    J, T, e, dq, q, be, sw, ws, Jn, state, hit_q, hit_e = _carve(wsp)
    for i in range(6):
        sw[i] = math.sqrt(w[i])
    state[0] = seed
    total = 0
    success = False
    used = 0
    hit_d = -math.inf  # clearance of hit_q; -inf: no target-reaching attempt refused yet
    if use_q0:
        _copy(q0, q)
    else:
        random_q_into(state, slo, shi, q)
    if respect:
        project_into(q, lo, hi, revolute)
    _copy(q, q_out)
    jacobian_into(q, F, meta, J, T)
    pose_error_into(T, Tt, e)
    _copy(e, be)
    best_cost = task_cost(e, w)
    for attempt in range(restarts + 1):
        used = attempt
        if attempt > 0:
            random_q_into(state, slo, shi, q)
            if respect:
                project_into(q, lo, hi, revolute)
        its, ok, cost = attempt_loop(F, meta, Tt, w, sw, lo, hi, revolute,  # noqa: F821
                                     respect, p, window, ratio, tol, max_iter, q, J, T, e,
                                     dq, ws, attempt > 0)
        total += its
        if not _finite_attempt(cost, q):
            continue
        if not ok:
            if hit_d == -math.inf and cost < best_cost:
                best_cost = cost
                _copy(q, q_out)
                _copy(e, be)
            continue
        ok, cost, its, hit_d = accept(F, meta, Tt, w, sw, lo, hi, revolute,  # noqa: F821
                                      respect, p, window, ratio, tol, max_iter, q, J, T, e,
                                      dq, ws, cost, guard, hit_q, hit_e, hit_d)
        total += its
        if ok:
            success = True
            best_cost = cost
            _copy(q, q_out)
            _copy(e, be)
            break
    if not success and hit_d > -math.inf:
        _copy(hit_q, q_out)
        _copy(hit_e, be)
        best_cost = task_cost(be, w)
    elif not success and cfg[C_POLISH] > 0.5:
        success, best_cost, its = _polish_best(F, meta, Tt, w, sw, lo, hi, revolute, respect,
                                               tol, max_iter, q, q_out, J, T, e, be, dq, ws,
                                               Jn, best_cost)
        total += its
    _tidy(q_out, q0, use_q0, lo, hi, revolute, respect)
    d, clear = final(q_out, guard, info)  # noqa: F821
    _write_info(info, success and clear, total, be, w, used, best_cost, q_out, lo, hi, d)


@njit(cache=True, inline="always")
def _accept_all(F, meta, Tt, w, sw, lo, hi, revolute, respect, p, window, ratio, tol,
                max_iter, q, J, T, e, dq, ws, cost, guard, hit_q, hit_e, hit_d):
    """The plain guard of :func:`_restarts`: every configuration reaching the target is one.

    Returns ``(accepted, cost, iterations, hit_d)``: True and the arguments, unchanged.
    """
    return True, cost, 0, hit_d


@njit(cache=True, inline="always")
def _no_clearance(q, guard, info):
    """The plain guard's report: clearance +inf (nothing checked), no closest pair."""
    for k in range(5):
        info[I_PAIR + k] = -1.0
    info[I_PAIR] = PAIR_NONE
    return math.inf, True


def _solve_chunk(F, meta, Tt, box, Q0, cfg, seed, Q_out, info, start, stop):
    """The restart loop (:func:`_restarts`) for targets ``start..stop-1`` of ``Tt`` (N, 4, 4).

    GIL released.

    ``Q0`` (N, n) start configurations (read when ``cfg[C_USE_Q0]`` is 1, zeros
    otherwise), ``Q_out`` (N, n) and ``info`` (N, N_INFO) outputs. The batch driver
    (:func:`serialkin.ik.solver.solve`) hands chunks to every core through
    :func:`serialkin.kinematics.parallel.run`, the scheduler of every batch kernel. Every
    target uses the same random stream ``seed``, so a batch solve returns exactly what
    the single solves with that seed return, whatever the chunking. One workspace serves
    the whole chunk.
    """
    wsp = _workspace(meta.shape[0])
    for k in range(start, stop):
        solve_one_in(F, meta, Tt[k], box, Q0[k], cfg, seed, Q_out[k], info[k], wsp,  # noqa: F821
                     ())


# ---------------------------------------------------------------- the single call from Python
# A call from Python pays for every argument numba unboxes (about 60 ns per array) and for
# every array it allocates: the fast entry takes the robot's and method's constant arrays
# packed in one vector (:func:`pack_fast`), checks its input itself and returns its
# answer as a tuple of scalars.


def pack_fast(F, meta, box, cfg_random, cfg_q0, rot_tol):
    """The constant input of ``solve_fast``: one float64 vector (read-only).

    Layout: ``rot_tol``, then ``F`` (n+1, 4, 4), ``meta`` (n, 5), ``box`` (5, n), and the
    two configuration vectors (same length) without and with ``C_USE_Q0``, each raveled.
    """
    parts = [np.array([rot_tol], dtype=np.float64), np.ravel(F), np.ravel(meta), np.ravel(box),
             np.ravel(cfg_random), np.ravel(cfg_q0)]
    S = np.ascontiguousarray(np.concatenate(parts), dtype=np.float64)
    S.setflags(write=False)
    return S


def _solve_fast(S, Tt, q0, seed, use_q0, q_out):
    """The restart loop behind the input checks of the ordinary path, for a call from Python.

    ``S`` from :func:`pack_fast`; ``Tt`` (4, 4) target; ``q0`` (n,) read when ``use_q0``;
    ``seed`` the stream seed as an int64 (its bits are the uint64 seed); ``q_out`` (n,).
    Returns ``(status, iterations, position error, orientation error, restarts)``:
    status -1 when ``Tt`` is not a rigid transform (within ``rot_tol``) or q0 is not
    finite and inside the limits (nothing solved: the caller's checks raise the precise
    error), 1 for a success with q inside the limits, 0 for a failure.
    """
    n = q_out.shape[0]
    o = 1
    F = S[o:o + 16 * (n + 1)].reshape((n + 1, 4, 4))
    o += 16 * (n + 1)
    meta = S[o:o + 5 * n].reshape((n, 5))
    o += 5 * n
    box = S[o:o + 5 * n].reshape((5, n))
    o += 5 * n
    m = (S.shape[0] - o) // 2
    cfg = S[o + m:o + 2 * m] if use_q0 else S[o:o + m]
    if not pose_and_q0_valid(Tt, q0, box[B_LO], box[B_HI], S[0], use_q0):
        return -1, 0, 0.0, 0.0, 0
    info = np.empty(N_INFO)
    # solve_one_in directly, not through solve_chunk: one level less of compiled calls (each
    # level re-optimises everything below it at its first compile: 2 s of a first ik)
    solve_one_in(F, meta, Tt, box, q0, cfg, np.uint64(seed), q_out, info,  # noqa: F821
                 _workspace(n), ())
    ok = info[I_SUCCESS] > 0.5 and info[I_INSIDE] > 0.5
    return (1 if ok else 0), int(info[I_ITERATIONS]), info[I_POS_ERR], info[I_ORI_ERR], \
        int(info[I_RESTARTS])


# ---------------------------------------------------------------- collision-aware solves
@njit(cache=True)
def _clearance(q, chain, model, near):
    """Clearance [m] of configuration q and its closest pair.

    ``chain = (F, L, meta, frames)``: the chain's arrays and the (n+1, 4, 4) frames it
    fills; ``model = (sf, A, B, rad, sb, pa, pb, scene)``: the collision model's flat
    arrays, the checked pairs and the encoded scene (k, 16); ``near = (W0, W1, pair)``:
    two (m, 3) work arrays and ``pair`` (5,), written as
    :func:`serialkin.collision.queries.clearance_at` writes it.
    """
    F, L, meta, frames = chain
    sf, A, B, rad, sb, pa, pb, scene = model
    W0, W1, pair = near
    fk_all_into(q, F, L, meta, frames)
    return clearance_at(frames, sf, A, B, rad, sb, pa, pb, scene, W0, W1, pair)


@njit(cache=True)
def _push_out(q, d, margin, J, sw, joints, chain, model, near, work):
    """One push-out step from q (n,), which reaches the target with clearance ``d < margin``.

    q is moved in place. Returns False when the clearance does not depend on q (nothing
    to push). ``J`` (6, n) is the task Jacobian at q, ``sw`` (6,) the square roots of the
    task weights; ``joints = (lo, hi, revolute, respect)``; ``chain``, ``model`` and
    ``near`` as for :func:`_clearance`; ``work = (g, qn, Jw, M6, y6, v6, dq)``: work arrays
    of shapes (n,), (n,), (6, n), (6, 6), (6,), (6,), (n,).

    The gradient ``g = ∂d/∂q`` of the closest pair's distance (``pair``, as left by the
    last :func:`_clearance`; forward differences, step :data:`PUSH_H`) is
    projected onto the null space of the weighted task Jacobian ``Jw = diag(√w) J``:
    ``u = g − Jwᵀ (Jw Jwᵀ + λ² I)⁻¹ Jw g`` (the DLS step of :mod:`serialkin.kinematics.dls`,
    λ² = 1e-8), so that a redundant arm moves its body away without moving the tool; when
    the null space carries less than 5 % of the gradient (a 6-axis arm) the plain
    gradient is used and the loop re-converges to the target afterwards. The step
    ``Δq = s u`` asks the linearised clearance ``d + s gᵀu`` to reach
    ``margin + PUSH_EXTRA``, with max |Δq_i| ≤ :data:`PUSH_MAX`; q is then projected onto
    the joint ranges when ``respect``.
    """
    lo, hi, revolute, respect = joints
    F, L, meta, frames = chain
    sf, A, B, rad, sb, pa, pb, scene = model
    W0, W1, pair = near
    g, qn, Jw, M6, y6, v6, dq = work
    n = q.shape[0]
    gg = 0.0
    for j in range(n):
        for k in range(n):
            qn[k] = q[k]
        qn[j] += PUSH_H
        fk_all_into(qn, F, L, meta, frames)
        g[j] = (pair_distance_at(frames, sf, A, B, rad, scene, pair, W0, W1) - d) / PUSH_H
        gg += g[j] * g[j]
    if not gg > 1e-12 or not math.isfinite(gg):
        return False
    for i in range(6):
        s = 0.0
        for j in range(n):
            Jw[i, j] = sw[i] * J[i, j]
            s += Jw[i, j] * g[j]
        v6[i] = s
    gain = 0.0
    if dls_step_into(Jw, v6, 1e-8, 1e-9, M6, y6, dq):
        for j in range(n):
            dq[j] = g[j] - dq[j]
            gain += dq[j] * g[j]
    if not gain > 1e-3 * gg:
        for j in range(n):
            dq[j] = g[j]
        gain = gg
    s = (margin - d + PUSH_EXTRA) / gain
    big = 0.0
    for j in range(n):
        dq[j] *= s
        big = max(big, abs(dq[j]))
    if big > PUSH_MAX:
        for j in range(n):
            dq[j] *= PUSH_MAX / big
    for j in range(n):
        q[j] += dq[j]
    if respect:
        project_into(q, lo, hi, revolute)
    return True


def _push_accept(F, meta, Tt, w, sw, lo, hi, revolute, respect, p, window, ratio, tol,
                 max_iter, q, J, T, e, dq, ws, cost, guard, hit_q, hit_e, hit_d):
    """The collision guard of :func:`_restarts`: accept q (reaching the target) when clear.

    ``guard = (chain, model, near, work, margin, pushes)`` (:func:`_solve_one_collision`).
    While the clearance of q (:func:`_clearance`) is below ``margin``, up to ``pushes``
    push-out steps (:func:`_push_out`), each followed by the attempt loop again (which
    brings the tool back onto the target); the refused configuration of largest clearance
    so far is kept in ``hit_q``, ``hit_e`` (clearance ``hit_d``). Returns ``(accepted,
    cost, iterations, hit_d)``; q, J, T, e describe the last configuration.
    """
    chain, model, near, work, margin, pushes = guard
    joints = (lo, hi, revolute, respect)
    total = 0
    ok = True
    d = _clearance(q, chain, model, near)
    for push in range(pushes + 1):
        if d >= margin:
            break
        if d > hit_d:
            hit_d = d
            _copy(q, hit_q)
            _copy(e, hit_e)
        if push == pushes or not _push_out(q, d, margin, J, sw, joints, chain, model, near,
                                           work):
            break
        its, ok, cost = attempt_loop(F, meta, Tt, w, sw, lo, hi, revolute,  # noqa: F821
                                     respect, p, window, ratio, tol, max_iter, q, J, T, e,
                                     dq, ws, True)
        total += its
        if not ok or not math.isfinite(cost):
            ok = False
            break
        d = _clearance(q, chain, model, near)
    return ok and d >= margin, cost, total, hit_d


@njit(cache=True)
def _final_clearance(q, guard, info):
    """The collision guard's report: the clearance of the returned q and its closest pair.

    Writes the pair into ``info[I_PAIR:I_PAIR + 5]``; returns ``(clearance, clearance >=
    margin)``.
    """
    chain, model, near, work, margin, pushes = guard
    d = _clearance(q, chain, model, near)
    pair = near[2]
    for k in range(5):
        info[I_PAIR + k] = pair[k]
    return d, d >= margin


def _solve_one_collision(F, L, meta, Tt, box, q0, cfg, seed, sf, A, B, rad, sb, pa, pb, scene,
                         ccfg, q_out, info):
    """The restart loop whose success also asks for a clearance ≥ ``ccfg[K_MARGIN]``.

    :func:`_restarts` with the collision guard (:func:`_push_accept`): every attempt that
    reaches the target is checked (:func:`_clearance`: the checked self pairs ``pa, pb``
    and the encoded ``scene``); while it collides, up to ``ccfg[K_PUSHES]`` push-out steps
    (:func:`_push_out`) each followed by the attempt loop again; then the next restart.
    The returned q is the first collision-free solution; else the solution with the
    largest clearance; else (no attempt reached the target) the lowest-cost attempt,
    polished as in a plain solve. ``info[I_CLEARANCE]`` and ``info[I_PAIR:I_PAIR + 3]``
    describe the returned q; ``info[I_SUCCESS]`` is 1 only when it reaches the target and
    its clearance is ≥ the margin. Arguments as :func:`_restarts` (but the workspace and
    guard) plus the collision model's flat arrays (``sf`` shape frames, ``A``, ``B``,
    ``rad``, ``sb`` shape bodies), the checked pairs, the scene (k, 16) and ``ccfg``
    (:data:`N_CCFG`,). Allocates the loop's workspace and the guard's work arrays.
    """
    n = meta.shape[0]
    m = A.shape[0]
    chain = (F, L, meta, np.empty((n + 1, 4, 4)))
    model = (sf, A, B, rad, sb, pa, pb, scene)
    near = (np.empty((m, 3)), np.empty((m, 3)), np.empty(5))
    work = (np.empty(n), np.empty(n), np.empty((6, n)), np.empty((6, 6)), np.empty(6),
            np.empty(6), np.empty(n))
    guard = (chain, model, near, work, ccfg[K_MARGIN], int(ccfg[K_PUSHES]))
    restarts_collision(F, meta, Tt, box, q0, cfg, seed, q_out, info,  # noqa: F821
                       _workspace(n), guard)


def _solve_chunk_collision(F, L, meta, Tt, box, Q0, cfg, seed, sf, A, B, rad, sb, pa, pb, scene,
                           ccfg, Q_out, info, start, stop):
    """:func:`_solve_one_collision` (inlined) for targets ``start..stop-1``, GIL released.

    As ``solve_chunk``; one target from Python is a chunk of one.
    """
    for k in range(start, stop):
        solve_one_collision(F, L, meta, Tt[k], box, Q0[k], cfg, seed, sf, A, B,  # noqa: F821
                            rad, sb, pa, pb, scene, ccfg, Q_out[k], info[k])


@dataclass(frozen=True, eq=False)
class CompiledMethod:
    """A compiled IK method: its step kernel inside the shared loop.

    Attributes:
        step: the step kernel (see the module docstring).
        params: ``(option name, zero allowed)`` of the values the step reads from ``p``,
            in order (``cfg[N_LOOP + i]``); each is a finite number > 0 (or ≥ 0).
        solve_chunk: ``solve_chunk(F, meta, Tt, box, Q0, cfg, seed, Q_out, info, start,
            stop)``, GIL released (one target from Python: a chunk of one).
        solve_chunk_collision: the same with the collision check
            (:func:`_solve_one_collision`), compiled at its first call.
        solve_fast: ``solve_fast(S, Tt, q0, seed, use_q0, q_out) -> (status, iterations,
            position error, orientation error, restarts)``, the single call from Python
            (:func:`_solve_fast`).
        code: None for a method compiled alone; for a member of a family
            (:func:`compile_family`) its number, which the caller puts first in ``p``
            (``cfg[N_LOOP]``, the parameters after it).
    """

    step: object
    params: tuple[tuple[str, bool], ...]
    solve_chunk: object
    solve_chunk_collision: object = None
    solve_fast: object = None
    code: int | None = None


def _bind(template, name: str, tag: str, **bound):
    """:func:`serialkin._jit.bind` under a name carrying the method's name and ``tag``.

    So that numba's on-disk cache (keyed by name and source file) keeps one entry per
    method and per version of the sources.
    """
    return bind(template, f"{template.__name__.lstrip('_')}_{name}_{tag}", **bound)


def compile_method(name: str, step, params: tuple[tuple[str, bool], ...] = (), *,
                   allocates: bool = False, hot: bool = False) -> CompiledMethod:
    """The shared loop around the step kernel ``step`` (an ``@njit`` function), for ``name``.

    ``params`` names the options the step reads (see :class:`CompiledMethod`);
    ``allocates`` must be True when the step, or a helper it calls, allocates arrays (the
    attempt loop and the per-target loop around it are then compiled with reference
    counting, about 0.1 µs slower per iteration and 0.35 µs per target); ``hot`` compiles
    the loop at ``-O3`` (:func:`serialkin._jit.opt_level`: the default method). Compilation is
    lazy (at the first call) and cached on disk; the cache entry's name holds a hash of
    this module's and the step's module's sources and of everything they import
    (:func:`serialkin._jit.dependency_stamp`), so editing any of them recompiles.
    """
    import inspect

    stamps = dependency_stamp(__file__) + dependency_stamp(inspect.getfile(step.py_func))
    tag = hashlib.sha1(stamps.encode()).hexdigest()[:10]
    # the attempt loop itself allocates nothing: without reference counting (NRT), which
    # would incref/decref every array the loop touches, each iteration (about
    # 0.1 µs per iteration, a fifth of an lm solve), unless the step allocates
    compiled = functools.partial(njit, cache=True, hot=hot)
    attempt = compiled(_nrt=allocates)(_bind(_attempt, name, tag + str(int(allocates)),
                                             step=step))
    # a function of its own, without reference counting unless the step allocates: it
    # allocates nothing (the workspace comes from its callers), and with NRT the views it
    # unpacks from the workspace and slices from cfg and box cost an atomic increment
    # and decrement each, per target (about 0.35 µs of a Panda target's 0.7 µs outside
    # its iterations)
    one_in = compiled(_nrt=allocates)(_bind(_restarts, name, tag + str(int(allocates)),
                                            attempt_loop=attempt, accept=_accept_all,
                                            final=_no_clearance))
    # one target from Python is a chunk of one: each compiled entry links and re-optimises
    # the whole loop below it (about 2 s of a first ik per entry)
    chunk = compiled(nogil=True)(_bind(_solve_chunk, name, tag, solve_one_in=one_in))
    # the same restart loop with the collision guard (with reference counting: the
    # guard's tuples hold arrays the wrapper allocates)
    # (the guard and this restart loop have one call site each: inlined in numba's IR,
    # not compiled levels of their own, each of which would re-optimise the tree below)
    push = compiled(inline="always")(_bind(_push_accept, name, tag, attempt_loop=attempt))
    restarts_c = compiled(inline="always")(_bind(_restarts, name, tag + "c",
                                                 attempt_loop=attempt, accept=push,
                                                 final=_final_clearance))
    one_c = compiled(inline="always")(_bind(_solve_one_collision, name, tag,
                                            restarts_collision=restarts_c))
    chunk_c = compiled(nogil=True)(_bind(_solve_chunk_collision, name, tag,
                                         solve_one_collision=one_c))
    fast = compiled()(_bind(_solve_fast, name, tag, solve_one_in=one_in))
    return CompiledMethod(step=step, params=tuple(params), solve_chunk=chunk,
                          solve_chunk_collision=chunk_c, solve_fast=fast)


def compile_family(family: str, dispatch, members) -> dict[str, CompiledMethod]:
    """Several methods in one compiled loop: the loop around ``dispatch``, shared.

    ``dispatch`` is a step kernel that runs the step of member ``int(p[0])`` with that
    member's parameters ``p[1:]``; ``members`` lists ``(name, step, params)`` in the
    order of those numbers. Each member gets a :class:`CompiledMethod` with its ``code``
    and the family's compiled entries, so the loop, its entries and everything they call
    compile once for all members instead of once per member (each copy of the loop takes
    7-10 s to compile cold on a quiet 2-core machine, its entries about 2 s more each;
    docs/compile-time.md). The members' steps allocate nothing (the loop is compiled
    without reference counting).
    """
    base = compile_method(family, dispatch, ())
    return {name: replace(base, step=step, params=tuple(params), code=i)
            for i, (name, step, params) in enumerate(members)}
