"""Newton refinement of closed-form candidates on the true chain (numba, ``cache=True``).

Every candidate that comes from an idealised model (a nearly ideal arm solved as the
ideal one) or from a search (the general 6R solver) is polished by Newton's method on
the pose error of the robot's own compiled chain (:mod:`serialkin.kinematics.kernels`):

``J(q) Δq = e(q)``,  ``e = [p_T − p(q); log(R_T R(q)ᵀ)^∨]`` (6,) [m; rad],

solved by the one damped least-squares kernel (:func:`serialkin.kinematics.dls.dls_step_into`)
with λ = 0 (a tiny damping floor only when ``J Jᵀ`` is singular), steps limited to
:data:`MAX_STEP` rad. For a 6-joint arm away from singularities this is Newton's
method: the error falls quadratically (1e-2 → 1e-4 → 1e-8 → 1e-16). Kernels trust
their input.
"""

from __future__ import annotations

import math

import numpy as np

from serialkin.kinematics.dls import dls_step_into
from serialkin.kinematics.kernels import jacobian_into
from serialkin.spatial.kernels import pose_error_into

from ..._jit import as_readonly, njit

#: Largest Newton step, any joint [rad or m]; larger steps are scaled down.
MAX_STEP = 0.5
#: Newton iterations at most.
MAX_NEWTON = 30
TWO_PI = 2.0 * math.pi


@njit(cache=True)
def wrapped_dist(a, b, n):
    """Largest |a_j − b_j| over the first n joints, each difference wrapped to [−π, π)."""
    d = 0.0
    for j in range(n):
        x = a[j] - b[j]
        x -= TWO_PI * math.floor(x / TWO_PI + 0.5)
        d = max(d, abs(x))
    return d


@njit(cache=True)
def newton_refine(q, T, F, meta, tol_p, tol_r, max_iter):
    """Polish ``q`` (n,) in place until ``robot.fk(q)`` reproduces ``T`` (4, 4).

    Args:
        q: (n,) start, overwritten by the refined configuration [rad / m].
        T: (4, 4) target pose (world).
        F: (n+1, 4, 4) chain transforms.
        meta: (n, 5) chain joint data.
        tol_p: position tolerance [m] (e.g. 1e-12 · robot size).
        tol_r: rotation tolerance [rad].
        max_iter: iterations at most.

    Returns:
        True when both errors fell within their tolerances.
    """
    return newton_refine_known(q, T, F, meta, tol_p, tol_r, max_iter, q.reshape(1, -1), 0,
                               0.0) == 1


@njit(cache=True)
def newton_refine_known(q, T, F, meta, tol_p, tol_r, max_iter, known, k, radius):
    """:func:`newton_refine` that stops early on reaching a solution already known.

    Before each step, when ``q`` is within ``radius`` (wrapped, every joint) of one of
    the rows ``known[:k]`` (k, n) the iteration stops: Newton's method there converges
    quadratically onto that row, so the start adds nothing (the general search's
    duplicate starts). Returns 1 converged, 0 failed, −1 stopped at a known row.
    """
    n = q.shape[0]
    J = np.empty((6, n))
    Tq = np.empty((4, 4))
    e = np.empty(6)
    Mb = np.empty((6, 6))
    y = np.empty(6)
    dq = np.empty(n)
    for _ in range(max_iter + 1):
        jacobian_into(q, F, meta, J, Tq)
        pose_error_into(Tq, as_readonly(T), e)  # the target only read (read-only, as for all)
        ep = math.sqrt(e[0] * e[0] + e[1] * e[1] + e[2] * e[2])
        er = math.sqrt(e[3] * e[3] + e[4] * e[4] + e[5] * e[5])
        if not (math.isfinite(ep) and math.isfinite(er)):
            return 0
        if ep <= tol_p and er <= tol_r:
            return 1
        for s in range(k):
            if wrapped_dist(q, known[s], n) < radius:
                return -1
        if not dls_step_into(J, e, 0.0, 1e-14, Mb, y, dq):
            return 0
        big = 0.0
        for j in range(n):
            big = max(big, abs(dq[j]))
        scale = 1.0 if big <= MAX_STEP else MAX_STEP / big
        for j in range(n):
            q[j] += scale * dq[j]
    return 0


@njit(cache=True)
def refine_rows(cand, k, T, F, meta, tol_p, tol_r, converged):
    """Refine rows ``cand[:k]`` (K, n) in place; ``converged[i]`` says whether row i converged.

    A row that does not converge keeps its refined value; :func:`~serialkin.ik.analytic.
    subproblems.finalize` then drops it (it does not reproduce the target).
    """
    for i in range(k):  # each row refined where it is (a C row: newton_refine's one type)
        converged[i] = newton_refine(cand[i], T, F, meta, tol_p, tol_r, MAX_NEWTON)


@njit(cache=True)
def refine_new(q, T, F, meta, tol_p, tol_r, out, k, radius):
    """Refine the start ``q`` (n,) and append it to ``out[k]`` when it is a new solution.

    Newton's method (:func:`newton_refine_known`, stopping within ``radius`` of a row of
    ``out[:k]``); a converged ``q`` within 1e-7 rad (every joint, wrapped) of a row
    already there, or beyond the capacity of ``out`` (K, n), is not added.

    Returns:
        the new number of rows (k or k + 1).
    """
    if newton_refine_known(q, T, F, meta, tol_p, tol_r, MAX_NEWTON, out, k, radius) != 1:
        return k
    for s in range(k):
        if wrapped_dist(q, out[s], q.shape[0]) < 1e-7:
            return k
    if k < out.shape[0]:
        for j in range(q.shape[0]):
            out[k, j] = q[j]
        return k + 1
    return k
