"""Heuristic IK methods of chapter section 5.3, registered by name: CCD and FABRIK.

=========  ============================================================================
name       what one iteration does
=========  ============================================================================
``ccd``    cyclic coordinate descent: each joint, last to first, to its closed-form
           one-joint optimum (:mod:`serialkin.ik.ccd`); any serial chain, any target
``fabrik`` forward and backward reaching on the joint positions, then angle recovery
           (:mod:`serialkin.ik.fabrik`); revolute chains with parallel axes only
=========  ============================================================================

Both run one attempt in a compiled kernel and leave restarts, seeding, the success test
and the result to the shared loop (:func:`serialkin.ik.solver.run_attempts`). Both
respect joint limits by clamping each joint update to its range.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

import numpy as np

from serialkin._checks import MAX_ITERATIONS, check_int, check_positive
from serialkin._memo import PerObject
from serialkin.ik import ccd as _ccd
from serialkin.ik import fabrik as _fabrik
from serialkin.ik.registry import MethodSpec, register_method
from serialkin.ik.solver import IKProblem

_CLAMP = (
    "clamping: each joint update is the best value inside its range (for a revolute "
    "joint the admissible angle nearest the one-joint optimum on the circle)"
)

#: Per robot: characteristic length [m] (CCD orientation weight) and FABRIK plane data.
_ROBOT_CACHE: PerObject[dict[str, Any]] = PerObject()


def _cache(robot: Any) -> dict[str, Any]:
    return _ROBOT_CACHE.setdefault(robot, dict)


def characteristic_length(robot: Any) -> float:
    """Sum of the fixed link translations |F_i[:3, 3]| (i = 1..n) [m], at least 1e-3.

    An upper bound of the reach (prismatic strokes aside) used to scale the orientation
    term of CCD's cost against its position term.
    """
    c = _cache(robot)
    if "length" not in c:
        F = robot.chain.F
        c["length"] = max(float(np.linalg.norm(F[1:, :3, 3], axis=1).sum()), 1e-3)
    return c["length"]


def _stall(options: Mapping[str, Any]) -> tuple[int, float]:
    window = check_int(options["stall_window"], "stall_window", minimum=1,
                       maximum=MAX_ITERATIONS)
    progress = check_positive(options["min_progress"], "min_progress")
    return window, progress


def _ccd_attempt(problem: IKProblem, q_start: np.ndarray, max_iter: int,
                 options: Mapping[str, Any]) -> tuple[np.ndarray, int]:
    """One CCD attempt (see :func:`serialkin.ik.ccd.ccd_attempt`).

    Options: ``orientation_weight`` w_o [m²] (default ``(orientation_scale · L)²`` with L
    the :func:`characteristic_length`; scale 0.1 solved the most Puma 560 / UR5 / Panda
    full-pose targets among 0.05, 0.1, 0.2, 0.3), ``stall_window`` [sweeps] and
    ``min_progress`` (stagnation test).
    """
    robot = problem.robot
    w_o = options["orientation_weight"]
    if w_o is None:
        w_o = (options["orientation_scale"] * characteristic_length(robot)) ** 2
    w_o = check_positive(w_o, "orientation_weight")
    window, progress = _stall(options)
    q = np.array(q_start, dtype=np.float64)
    its, _status = _ccd.ccd_attempt(
        q, robot.chain.F, robot.chain.meta, problem.T_target, problem.weights, w_o,
        problem.lower, problem.upper, problem.tol, problem.tol, int(max_iter), window,
        progress,
    )
    return q, int(its)


def fabrik_plane(robot: Any) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Cached :func:`serialkin.ik.fabrik.fabrik_domain` (raises NotSupportedError)."""
    c = _cache(robot)
    if "fabrik" not in c:
        try:
            c["fabrik"] = _fabrik.fabrik_domain(robot)
        except Exception as exc:
            c["fabrik"] = exc
    got = c["fabrik"]
    if isinstance(got, Exception):
        raise got
    return got


def _fabrik_attempt(problem: IKProblem, q_start: np.ndarray, max_iter: int,
                    options: Mapping[str, Any]) -> tuple[np.ndarray, int]:
    """One FABRIK attempt (see :func:`serialkin.ik.fabrik.fabrik_attempt`)."""
    robot = problem.robot
    a, e1, e2, sign = fabrik_plane(robot)
    window, progress = _stall(options)
    q = np.array(q_start, dtype=np.float64)
    its, _status = _fabrik.fabrik_attempt(
        q, robot.chain.F, robot.chain.meta, problem.T_target, problem.weights, a, e1, e2,
        sign, problem.lower, problem.upper, problem.tol, problem.tol, int(max_iter), window,
        progress,
    )
    return q, int(its)


register_method(MethodSpec(
    name="ccd", family="heuristic",
    summary="cyclic coordinate descent: closed-form one-joint optima, last joint to first",
    limits=_CLAMP, max_iter=3000, restarts=20,
    options={"orientation_weight": None, "orientation_scale": 0.1, "stall_window": 50,
             "min_progress": 0.05},
    attempt=_ccd_attempt,
))
register_method(MethodSpec(
    name="fabrik", family="heuristic",
    summary="FABRIK on joint positions + angle recovery (revolute chains, parallel axes)",
    limits=_CLAMP + ", in the angle recovery after each forward/backward pass",
    max_iter=500, restarts=20,
    options={"stall_window": 20, "min_progress": 0.05},
    attempt=_fabrik_attempt,
))
