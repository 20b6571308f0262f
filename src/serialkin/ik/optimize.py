"""IK as minimisation of the pose-error cost: BFGS and Powell (chapter section 5.3).

The chapter names Powell's method and BFGS as the minimisation family of numerical IK.
Both minimise the same cost as every other solver of :mod:`serialkin.ik`,

    E(q) = ½ e(q)ᵀ W e(q),   e = [p_target − p(q); log(R_target R(q)ᵀ)^∨],

with ``W = diag(w)`` the task weights of the target (a zero weight drops a coordinate,
:mod:`serialkin.ik.target`), using :func:`scipy.optimize.minimize`. The cost and its
gradient are evaluated by one compiled kernel call (:func:`cost_and_gradient`) over the
shared FK/Jacobian kernels.

* ``bfgs`` — quasi-Newton with the analytic gradient ``∇E = −Jᵀ W e`` (J the geometric
  Jacobian, eqs 33-36). The gradient is exact for the position rows and, for the
  orientation rows, whenever the three orientation weights are equal (then
  ``∇(½|ω|²) = −J_ωᵀ ω`` exactly, because ω is an eigenvector of the inverse right
  Jacobian of SO(3)); with unequal orientation weights it is the usual first-order
  approximation. The solver is scipy's **L-BFGS-B** (limited-memory BFGS with bound
  constraints) with a memory of ``max(10, n)`` pairs, so that **joint limits are
  respected by bounds** (projected quasi-Newton steps), never by rejection.
* ``powell`` — Powell's conjugate-direction method (derivative free: only E is
  evaluated) with scipy's bound handling (line searches confined to the box), so limits
  are respected the same way.

Unlimited joints are unbounded; an unlimited revolute joint is wrapped into [-π, π)
afterwards (same pose). Both methods stop as soon as the selected position and
orientation errors are within the tolerance (checked in a callback after every
iteration), else on scipy's own convergence tests (set far below the tolerance) or the
iteration budget; the shared loop then restarts from a random configuration. Their
documented tolerance is that of every method (``serialkin.ik.DEFAULT_TOL``: 1e-9 m and
1e-9 rad), reached on full-pose targets when they converge (use restarts).

They are much slower than the compiled Jacobian methods (a Python call per cost
evaluation): they are here to make the chapter's comparison measurable, not to be the
default.
"""

from __future__ import annotations

import math
from collections.abc import Callable

import numpy as np

from serialkin.ik._kernels import task_cost, task_errors
from serialkin.kinematics.kernels import fk_into, jacobian_into
from serialkin.kinematics.parallel import single_threaded_blas
from serialkin.spatial.kernels import pose_error_into

from .._jit import njit

#: Names of the methods implemented here (scipy method used for each).
SCIPY_METHODS = {"bfgs": "L-BFGS-B", "powell": "Powell"}



@njit(cache=True)
def cost_and_gradient(q, F, meta, T_target, w, J, T, e, g):
    """Cost ``E = ½ Σ w_i e_i²`` and gradient ``g = −Jᵀ (w ⊙ e)`` (n,) at ``q`` (n,).

    Args:
        q: (n,) joint values.
        F: (n+1, 4, 4) chain fixed transforms.
        meta: (n, 5) chain joint data.
        T_target: (4, 4) target pose.
        w: (6,) task weights.
        J: (6, n) work array (Jacobian).
        T: (4, 4) work array (pose).
        e: (6,) receives the pose error.
        g: (n,) receives the gradient.

    Returns:
        The cost E.
    """
    jacobian_into(q, F, meta, J, T)
    pose_error_into(T, T_target, e)
    cost = task_cost(e, w)
    n = q.shape[0]
    for j in range(n):
        s = 0.0
        for k in range(6):
            s -= J[k, j] * w[k] * e[k]
        g[j] = s
    return cost


@njit(cache=True)
def cost_only(q, F, meta, T_target, w, T, e):
    """Cost ``E = ½ Σ w_i e_i²`` at ``q`` (n,) (one FK, no Jacobian); ``e`` receives the error.

    Args:
        q: (n,) joint values.
        F: (n+1, 4, 4) chain fixed transforms.
        meta: (n, 5) chain joint data.
        T_target: (4, 4) target pose.
        w: (6,) task weights.
        T: (4, 4) work array (pose).
        e: (6,) receives the pose error.

    Returns:
        The cost E.
    """
    fk_into(q, F, meta, T)
    pose_error_into(T, T_target, e)
    return task_cost(e, w)


@njit(cache=True)
def selected_errors(q, F, meta, T_target, w, T, e):
    """Position and orientation error norms [m], [rad] over the coordinates with w > 0."""
    fk_into(q, F, meta, T)
    pose_error_into(T, T_target, e)
    return task_errors(e, w)


def _bounds(lo: np.ndarray, hi: np.ndarray) -> list[tuple[float | None, float | None]]:
    """Scipy bounds from limit arrays (±inf → None)."""
    return [(float(a) if np.isfinite(a) else None, float(b) if np.isfinite(b) else None)
            for a, b in zip(lo, hi)]


class _Converged(Exception):
    """Raised internally when the tolerance is met inside a cost evaluation."""


def minimize_attempt(
    method: str,
    F: np.ndarray,
    meta: np.ndarray,
    T_target: np.ndarray,
    w: np.ndarray,
    q_start: np.ndarray,
    lo: np.ndarray,
    hi: np.ndarray,
    *,
    tol: float,
    max_iter: int,
    bounded: bool = True,
    project: Callable[[np.ndarray], np.ndarray] | None = None,
    xtol: float = 1e-6,
) -> tuple[np.ndarray, int]:
    """One BFGS or Powell attempt from ``q_start``; returns ``(q, iterations)``.

    Args:
        method: 'bfgs' (L-BFGS-B with the analytic gradient) or 'powell'.
        F: (n+1, 4, 4) chain fixed transforms.
        meta: (n, 5) chain joint data.
        T_target: (4, 4) target pose.
        w: (6,) task weights (cost ``½ Σ w_i e_i²``).
        q_start: (n,) start configuration (inside [lo, hi] when ``bounded``).
        lo: (n,) lower joint limits (-inf for none).
        hi: (n,) upper joint limits (inf for none).
        tol: tolerance on the selected position [m] and orientation [rad] error norms.
        max_iter: iteration budget (scipy's ``maxiter``; Powell's cost evaluations are
            also capped at ``200 · n · max_iter / 10``).
        bounded: pass the joint limits to scipy as bounds.
        project: optional map applied to the final q (e.g. wrapping / projection onto
            the limits); default: none.
        xtol: Powell's line-search tolerance (scipy ``xtol``; 1e-6 solved the most
            Puma 560 / Panda targets per attempt among 1e-3, 1e-4, 1e-6).

    Returns:
        The configuration that met the tolerance, else the best one seen (lowest cost,
        always finite), and the number of iterations scipy performed.
    """
    # imported here: scipy.optimize takes 0.1-0.3 s to import, and serialkin.ik imports
    # this family (to register it) at every `import serialkin`
    from scipy.optimize import minimize

    scipy_method = SCIPY_METHODS[method]
    run = _Attempt(F, meta, T_target, w, q_start, tol)
    bfgs = scipy_method == "L-BFGS-B"
    iterations = 0

    def callback(intermediate_result: object) -> None:
        nonlocal iterations
        iterations += 1
        run.check(np.ascontiguousarray(intermediate_result.x, dtype=np.float64))  # type: ignore[attr-defined]

    x0 = np.array(q_start, dtype=np.float64)
    try:
        run.check(x0)
        with single_threaded_blas():
            res = minimize(run.cost_and_gradient if bfgs else run.cost, x0,
                           method=scipy_method, jac=bfgs,
                           bounds=_bounds(lo, hi) if bounded else None,
                           options=_scipy_options(bfgs, q_start.shape[0], max_iter, xtol),
                           callback=callback)
        iterations = max(iterations, int(getattr(res, "nit", iterations)))
        run.remember(np.ascontiguousarray(res.x, dtype=np.float64), float(res.fun))
    except _Converged:
        pass
    q = run.best_q
    if project is not None:
        q = project(q)
    return q, iterations


def _scipy_options(bfgs: bool, n: int, max_iter: int, xtol: float) -> dict[str, object]:
    """The options scipy gets for L-BFGS-B (``bfgs``) or Powell.

    The budgets of :func:`minimize_attempt`, and tolerances that never stop it first
    (ours do: :meth:`_Attempt.check`).
    """
    if bfgs:
        return {"maxiter": int(max_iter), "maxfun": 20 * int(max_iter) + 20,
                "maxcor": max(10, n), "ftol": 1e-30, "gtol": 1e-30}
    return {"maxiter": int(max_iter), "maxfev": 20 * n * int(max_iter) + 20,
            "xtol": float(xtol), "ftol": 1e-30}


class _Attempt:
    """The cost functions scipy calls, the best configuration seen and the tolerance test.

    Holds the workspace of the compiled cost kernels (``J`` (6, n), ``T`` (4, 4), ``e``
    (6,), ``g`` (n,)) so that no evaluation allocates.
    """

    def __init__(self, F: np.ndarray, meta: np.ndarray, T_target: np.ndarray,
                 w: np.ndarray, q_start: np.ndarray, tol: float) -> None:
        n = q_start.shape[0]
        self.F, self.meta, self.tol = F, meta, tol
        self.Tt = np.ascontiguousarray(T_target, dtype=np.float64)
        self.w = np.ascontiguousarray(w, dtype=np.float64)
        self.J, self.T, self.e, self.g = np.empty((6, n)), np.empty((4, 4)), np.empty(6), \
            np.empty(n)
        self.best_cost = math.inf
        self.best_q = np.array(q_start, dtype=np.float64)

    def remember(self, x: np.ndarray, cost: float) -> None:
        """Keep ``x`` when its cost is the lowest (finite) so far."""
        if cost < self.best_cost and math.isfinite(cost):
            self.best_cost = cost
            self.best_q = x.copy()

    def check(self, x: np.ndarray) -> None:
        """Raise :class:`_Converged` (keeping ``x``) when ``x`` meets the tolerance."""
        ep, eo = selected_errors(x, self.F, self.meta, self.Tt, self.w, self.T, self.e)
        if ep <= self.tol and eo <= self.tol:
            self.best_q = x.copy()
            raise _Converged

    def cost_and_gradient(self, x: np.ndarray) -> tuple[float, np.ndarray]:
        """``(E, ∇E)`` at ``x`` for L-BFGS-B (``E = ½ Σ w_i e_i²``)."""
        x = np.ascontiguousarray(x, dtype=np.float64)
        c = cost_and_gradient(x, self.F, self.meta, self.Tt, self.w, self.J, self.T, self.e,
                              self.g)
        self.remember(x, c)
        return c, self.g.copy()

    def cost(self, x: np.ndarray) -> float:
        """``E`` at ``x`` for Powell."""
        x = np.ascontiguousarray(x, dtype=np.float64)
        c = cost_only(x, self.F, self.meta, self.Tt, self.w, self.T, self.e)
        self.remember(x, c)
        return c
