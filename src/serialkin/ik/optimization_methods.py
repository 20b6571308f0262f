"""Minimisation IK methods of chapter section 5.3, registered by name: BFGS and Powell.

==========  ===========================================================================
name        solver (scipy.optimize.minimize) on E = ½ eᵀWe
==========  ===========================================================================
``bfgs``    L-BFGS-B with the analytic gradient −JᵀWe, joint limits as bounds
``powell``  Powell's derivative-free conjugate directions, joint limits as bounds
==========  ===========================================================================

See :mod:`serialkin.ik.optimize`. One attempt per call; the shared loop
(:func:`serialkin.ik.solver.run_attempts`) owns restarts, seeding and the result.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

import numpy as np

from serialkin._checks import check_positive
from serialkin.ik.optimize import minimize_attempt
from serialkin.ik.registry import AttemptFn, MethodSpec, register_method
from serialkin.ik.solver import IKProblem

_BOUNDS = (
    "bounds: scipy keeps every iterate inside the joint ranges (projected quasi-Newton "
    "steps for L-BFGS-B, box-confined line searches for Powell)"
)


def _attempt(method: str) -> AttemptFn:
    """The attempt function of ``method`` ('bfgs' or 'powell') for the shared loop."""

    def attempt(problem: IKProblem, q_start: np.ndarray, max_iter: int,
                options: Mapping[str, Any]) -> tuple[np.ndarray, int]:
        robot = problem.robot
        xtol = check_positive(options.get("xtol", 1e-6), "xtol")
        return minimize_attempt(
            method, robot.chain.F, robot.chain.meta, problem.T_target, problem.weights,
            np.asarray(q_start, dtype=np.float64), problem.lower, problem.upper,
            tol=problem.tol, max_iter=max_iter, bounded=problem.respect_limits,
            project=problem.project, xtol=xtol,
        )

    attempt.__doc__ = f"One {method} attempt (see :func:`serialkin.ik.optimize.minimize_attempt`)."
    return attempt


register_method(MethodSpec(
    name="bfgs", family="optimization",
    summary="L-BFGS-B on the pose-error cost with the analytic gradient −JᵀWe (scipy)",
    limits=_BOUNDS, max_iter=200, restarts=20, attempt=_attempt("bfgs"),
))
register_method(MethodSpec(
    name="powell", family="optimization",
    summary="Powell's derivative-free method on the pose-error cost (scipy)",
    limits=_BOUNDS, max_iter=100, restarts=20, options={"xtol": 1e-6},
    attempt=_attempt("powell"), max_joints=200,  # n line searches of O(n) FK per iteration
))
