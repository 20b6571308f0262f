"""The IK method ``'analytic'``: every closed-form solution, then the one nearest q0.

The closed-form family registers and implements its own method here, at import
(:mod:`serialkin.ik` imports this module): ``robot.ik(target,
method="analytic", q0=...)`` solves with :func:`serialkin.ik.analytic.ik_all` and
returns the solution nearest ``q0`` (:func:`serialkin.ik.analytic.sort_by_reference`:
revolute joints moved by 2π towards ``q0`` inside their limits, weighted L2 or L∞
distance), or the middle of the joint ranges without ``q0``.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

import numpy as np

from serialkin.ik.analytic import NEAR_TOL
from serialkin.ik.registry import MethodSpec, register_method
from serialkin.model.robot import Robot

#: Options of the method, with their defaults (passed on to ``ik_all``).
OPTIONS: dict[str, Any] = {"weights": None, "norm": "l2", "near_tol": NEAR_TOL, "grid": None}


def analytic_solve(robot: Robot, problem: Any, q0: np.ndarray | None,
                   options: Mapping[str, Any]) -> tuple[np.ndarray, bool, int, str]:
    """Solve ``problem`` (an :class:`~serialkin.ik.solver.IKProblem`) by ``ik_all``.

    Returns ``(q, success, iterations, reason)``: the solution nearest ``q0`` (or the
    middle of the ranges); without any solution inside the limits, ``q0`` (or the
    middle) with success False and a reason.
    """
    from serialkin.ik.analytic import ik_all, sort_by_reference

    T = problem.T_target
    if problem.kind == "pose":
        target: object = T
    elif problem.kind == "position":
        target = T[:3, 3].copy()
    elif problem.kind == "planar":
        target = T[:2, 3].copy()
    else:
        target = np.array([T[0, 3], T[1, 3], np.arctan2(T[1, 0], T[0, 0])])
    sols = np.asarray(ik_all(robot, target, near_tol=options["near_tol"],
                             grid=options["grid"]), dtype=np.float64).reshape(-1, robot.n)
    ref = q0 if q0 is not None else robot.sampling_limits().mean(axis=1)
    if sols.shape[0] == 0:
        return ref.copy(), False, 0, (
            "no closed-form solution inside the joint limits: the target is out of reach or "
            "reachable only outside the limits")
    best = sort_by_reference(robot, sols, ref, weights=options["weights"],
                             norm=options["norm"])[0]
    ok = problem.converged(best) and (not problem.respect_limits
                                      or bool(robot.within_limits(best, 1e-12)))
    reason = "" if ok else "the closed-form solution does not reproduce the target within tol"
    return best, ok, 1, reason


def register_analytic() -> None:
    """Register the method ``'analytic'`` (done once, when this module is imported)."""
    register_method(MethodSpec(
        name="analytic", family="analytic",
        summary="all closed-form solutions (section 4.1; general 6R by search), the one "
                "nearest q0",
        limits="only solutions inside the limits are returned by ik_all",
        max_iter=1, restarts=0, options=dict(OPTIONS), solve=analytic_solve,
    ))


register_analytic()
