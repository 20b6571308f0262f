"""Whether a solution is a member of a continuous family (a singular target).

At a wrist singularity (axes 4 and 6 aligned) or a shoulder singularity (the wrist
centre on axis 1) the solutions form a one-parameter family; ``ik_all`` returns one
representative per branch. This module tells such a family from an isolated solution
where the Jacobian is merely singular (a stretched elbow on the workspace boundary,
where two branches merge):

1. the Jacobian J(q) (6, n) is singular: ``σ_min < tol · σ_max``; v is the right
   singular vector of σ_min (J v ≈ 0);
2. step to ``q ± ε v`` and return to the target by Newton's method with minimum-norm
   steps (:func:`~serialkin.ik.analytic.refine.newton_refine`, whose steps lie in the
   row space of J, orthogonal to v): on a family the pose error is O(ε²) and the
   correction stays orthogonal to the family, so the refined point is a *different*
   solution about ε away; at an isolated (double) solution Newton returns to q or
   fails.
"""

from __future__ import annotations

import numpy as np

from serialkin.ik.analytic.refine import newton_refine
from serialkin.model.robot import Robot

#: Relative singular-value threshold for "J is singular" [-].
SINGULAR_TOL = 1e-6
#: Probe step along the null direction [rad / m].
PROBE_STEP = 1e-3


def continuous_family(robot: Robot, T: np.ndarray, q: np.ndarray, *,
                      tol: float = SINGULAR_TOL, step: float = PROBE_STEP) -> bool:
    """True when ``q`` (n,) solving ``T`` (4, 4) lies on a continuum of solutions.

    Args:
        robot: the robot.
        T: (4, 4) target pose (world).
        q: (n,) a solution of T [rad / m].
        tol: relative threshold on the smallest singular value of the Jacobian.
        step: probe step ε along its null direction [rad / m].

    Returns:
        False when J(q) is regular (an isolated solution) or when the probe returns to q
        or fails; True when it reaches another solution about ε away.
    """
    q = np.asarray(q, dtype=float)
    J = robot.jacobian(q)
    _, sv, Vt = np.linalg.svd(J)
    if robot.n > 6 or sv[-1] >= tol * max(sv[0], 1e-300):
        return False
    v = Vt[-1]
    T = np.ascontiguousarray(T, dtype=float)
    scale = max(1.0, float(np.linalg.norm(T[:3, 3])))
    for sign in (1.0, -1.0):
        probe = q + sign * step * v
        if newton_refine(probe, T, robot.chain.F, robot.chain.meta, 1e-12 * scale, 1e-12, 30) \
                and np.abs(probe - q).max() > 0.5 * step / np.sqrt(robot.n):
            return True
    return False
