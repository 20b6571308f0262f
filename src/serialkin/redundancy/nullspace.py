"""Null-space redundancy resolution: eq 42 and two-task priority.

Eq 42, ``q̇ = J⁺ ẋ + (I − J⁺J) q̇_0``, adds to the minimum-norm primary solution a joint
velocity projected into the null space of the task Jacobian: self-motion, which leaves
the end-effector still. With the projected-gradient method ``q̇_0 = ±k ∇H(q)`` climbs (or
descends) an objective of :mod:`serialkin.redundancy.objectives`.

The primary inverse ``J⁺`` is either the Moore-Penrose pseudoinverse (eq 40) or the damped
least-squares inverse ``J^# = Jᵀ(J Jᵀ + λ² I)⁻¹`` (eq 46, corrected). With DLS the
projector ``I − J^# J`` is only approximately a null-space projector (its residual task
motion is ``λ² (J Jᵀ + λ²I)⁻¹ J q̇_0``); the exact projector ``I − J⁺J`` is used for the
secondary term in both cases, so self-motion never disturbs the task.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from serialkin._budget import check_allocation
from serialkin._checks import as_float_array, check_choice, check_int, check_positive
from serialkin.errors import InputError
from serialkin.kinematics.dls import dls_inverse_into
from serialkin.redundancy.objectives import Objective, task_rows

__all__ = [
    "dls_inverse",
    "nullspace_projector",
    "projected_gradient_velocity",
    "pseudo_inverse",
    "self_motion",
    "task_priority_velocity",
]

INVERSES = ("pinv", "dls")


def _matrix(J: object, name: str = "J") -> np.ndarray:
    a = as_float_array(J, name)
    if a.ndim != 2:
        raise InputError(f"{name} must be a 2-D (m, n) matrix, got shape {a.shape}")
    return a


def pseudo_inverse(J: object, rcond: float = 1e-10) -> np.ndarray:
    """Moore-Penrose pseudoinverse ``J⁺`` (eq 40) via the SVD, shape (n, m).

    ``J⁺ = Jᵀ(J Jᵀ)⁻¹`` for a full-row-rank redundant J; singular values below
    ``rcond·σ_max`` are treated as zero.
    """
    return np.linalg.pinv(_matrix(J), rcond=rcond)


def dls_inverse(J: object, damping: float) -> np.ndarray:
    """Damped least-squares inverse ``Jᵀ(J Jᵀ + λ² I)⁻¹`` (eq 46, ERRATA-corrected), (n, m).

    Args:
        J: (m, n) task Jacobian.
        damping: λ > 0 [task units/joint units].
    """
    a = _matrix(J)
    lam = check_positive(damping, "damping")
    m, n = a.shape
    out = np.empty((n, m))
    dls_inverse_into(np.ascontiguousarray(a), lam * lam, 0.0, np.empty((m, m)), np.empty(m),
                     out)
    return out


def nullspace_projector(J: object, rcond: float = 1e-10) -> np.ndarray:
    """Orthogonal projector onto the null space of J: ``I − J⁺J`` (eq 42), shape (n, n).

    Symmetric and idempotent; ``J (I − J⁺J) = 0``.
    """
    a = _matrix(J)
    return np.eye(a.shape[1]) - pseudo_inverse(a, rcond) @ a


def _primary(J: np.ndarray, method: str, damping: float) -> np.ndarray:
    check_choice(method, "method", INVERSES)
    return pseudo_inverse(J) if method == "pinv" else dls_inverse(J, damping)


def projected_gradient_velocity(
    robot,
    q: object,
    xdot: object,
    objective: Objective | None = None,
    *,
    gain: float = 1.0,
    task: str | Sequence[int] = "planar",
    method: str = "pinv",
    damping: float = 0.01,
) -> np.ndarray:
    """Joint velocity of eq 42 with the projected-gradient secondary term, shape (n,).

    ``q̇ = J_inv ẋ + (I − J⁺J) · k · (±∇H(q))``, with ``J_inv`` the pseudoinverse or the
    DLS inverse and the sign chosen by the objective (climb when maximising).

    Args:
        robot: the robot.
        q: joint values (n,).
        xdot: task velocity (m,) in the task's rows [m/s, rad/s].
        objective: secondary objective, or None for the primary task only (eq 40).
        gain: k ≥ 0, scale of the secondary velocity.
        task: task rows (see :func:`serialkin.redundancy.objectives.task_rows`).
        method: 'pinv' (eq 40) or 'dls' (eq 46) for the primary task.
        damping: λ for 'dls'.

    Raises:
        InputError: wrong sizes, negative gain, unknown method.
    """
    qv = robot.check_q(q)
    rows = task_rows(task)
    J = robot.jacobian(qv)[rows]
    xd = as_float_array(xdot, "xdot", ndim=1)
    if xd.shape[0] != rows.size:
        raise InputError(f"xdot must have {rows.size} values for task {task!r}, got {xd.shape[0]}")
    k = check_positive(gain, "gain", allow_zero=True)
    qdot = _primary(J, method, damping) @ xd
    if objective is not None and k > 0:
        qdot = qdot + nullspace_projector(J) @ (k * objective.ascent(qv))
    return qdot


def task_priority_velocity(
    J1: object, xdot1: object, J2: object, xdot2: object, *,
    method: str = "pinv", damping: float = 0.01, qdot0: object = None,
) -> np.ndarray:
    """Two tasks with strict priority (Nakamura; Maciejewski & Klein), shape (n,).

    ``q̇ = J1⁺ẋ1 + (J2 P1)⁺ (ẋ2 − J2 J1⁺ ẋ1) + P12 q̇_0`` with ``P1 = I − J1⁺J1`` and ``P12``
    the projector onto the null space of both tasks. Task 2 is met as well as it can be
    without disturbing task 1; ``J1 q̇ = ẋ1`` exactly when J1 has full row rank (pinv).

    Args:
        J1: primary Jacobian (m1, n).
        xdot1: primary task velocity (m1,).
        J2: secondary Jacobian (m2, n).
        xdot2: secondary task velocity (m2,).
        method: 'pinv' or 'dls' for both inverses.
        damping: λ for 'dls'.
        qdot0: optional (n,) velocity projected into the null space of both tasks.
    """
    A1 = _matrix(J1, "J1")
    A2 = _matrix(J2, "J2")
    n = A1.shape[1]
    if A2.shape[1] != n:
        raise InputError(
            f"J1 and J2 must have the same number of columns, got {n} and {A2.shape[1]}")
    x1 = as_float_array(xdot1, "xdot1", ndim=1)
    x2 = as_float_array(xdot2, "xdot2", ndim=1)
    if x1.shape[0] != A1.shape[0] or x2.shape[0] != A2.shape[0]:
        raise InputError("xdot1/xdot2 must have as many values as J1/J2 have rows")
    inv1 = _primary(A1, method, damping)
    P1 = np.eye(n) - pseudo_inverse(A1) @ A1
    A2P = A2 @ P1
    inv2 = _primary(A2P, method, damping)
    qdot = inv1 @ x1 + inv2 @ (x2 - A2 @ inv1 @ x1)
    if qdot0 is not None:
        q0 = as_float_array(qdot0, "qdot0", ndim=1)
        if q0.shape[0] != n:
            raise InputError(f"qdot0 must have {n} values, got {q0.shape[0]}")
        P12 = P1 - pseudo_inverse(A2P) @ A2P
        qdot = qdot + P12 @ q0
    return qdot


def self_motion(robot, q0: object, objective: Objective, *, steps: int = 50,
                gain: float = 0.1, task: str | Sequence[int] = "planar",
                max_step: float = 0.05) -> np.ndarray:
    """Integrate pure self-motion (ẋ = 0 in eq 42) along an objective, shape (steps+1, n).

    Each step is ``Δq = (I − J⁺J) k (±∇H)``, its norm clipped to ``max_step`` [rad]. The
    end-effector drifts only by the second-order effect of the finite step.
    """
    q = robot.check_q(q0, "q0").astype(float).copy()
    s = check_int(steps, "steps", minimum=1)
    check_allocation("the self-motion path", (s + 1, robot.n), 8, setting="steps")
    k = check_positive(gain, "gain", allow_zero=True)
    cap = check_positive(max_step, "max_step")
    rows = task_rows(task)
    out = np.empty((s + 1, robot.n))
    out[0] = q
    for i in range(s):
        J = robot.jacobian(q)[rows]
        dq = nullspace_projector(J) @ (k * objective.ascent(q))
        nrm = np.linalg.norm(dq)
        if nrm > cap:
            dq *= cap / nrm
        q = q + dq
        out[i + 1] = q
    return out
