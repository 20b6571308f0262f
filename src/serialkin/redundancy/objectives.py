"""Secondary objectives H(q) for redundancy resolution, with their gradients (eqs 43-45).

The projected-gradient method (eq 42) moves a redundant arm in the null space of its task
Jacobian along ``±∇H``. Each objective here is an :class:`Objective`: a value ``H(q)``
[its own unit], a gradient ``∇H(q)`` of shape (n,) [unit/rad or unit/m], and whether it is
to be maximised or minimised. Users can wrap their own function with
:func:`custom_objective` (the gradient is optional: central finite differences are used
when it is missing).

Objectives:
    * :func:`manipulability` — eq 43, ``w(q) = sqrt(det(J Jᵀ))`` (maximise). Its gradient is
      analytic: ``∂w/∂q_k = w · tr((J Jᵀ)⁻¹ (∂J/∂q_k) Jᵀ)`` with ``∂J/∂q_k`` from
      :func:`jacobian_derivative`.
    * :func:`joint_limit_distance` — eq 44, corrected by the ERRATA: the mid-range is
      ``q̄ = (q_M + q_m)/2`` (the chapter prints ``(q_M − q_m)/2``). Minimise.
    * :func:`obstacle_distance` — eq 45, the squared minimum distance between the links
      and the obstacles (maximise); see :mod:`serialkin.redundancy.obstacles`.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from serialkin._checks import check_positive
from serialkin.errors import InputError, InputTypeError
from serialkin.kinematics.dls import manipulability_of
from serialkin.model.tasks import TASKS, task_rows

if TYPE_CHECKING:
    from serialkin.model.robot import Robot
    from serialkin.redundancy.obstacles import Obstacle

__all__ = [
    "TASKS",  # re-exported from serialkin.model.tasks, the one task table
    "Objective",
    "custom_objective",
    "finite_difference_gradient",
    "jacobian_derivative",
    "joint_limit_distance",
    "manipulability",
    "manipulability_gradient",
    "obstacle_distance",
    "task_rows",
]

@dataclass(frozen=True)
class Objective:
    """A scalar objective H(q) with its gradient, for the projected-gradient method.

    Attributes:
        name: short label.
        value: ``H(q)`` for q of shape (n,).
        gradient: ``∇H(q)``, shape (n,).
        maximize: True when the arm should climb H (manipulability, obstacle distance),
            False when it should descend (joint-limit distance).
    """

    name: str
    value: Callable[[np.ndarray], float]
    gradient: Callable[[np.ndarray], np.ndarray]
    maximize: bool

    def ascent(self, q: np.ndarray) -> np.ndarray:
        """The improving direction: ``+∇H`` when maximising, ``−∇H`` when minimising, (n,)."""
        g = np.asarray(self.gradient(q), dtype=float)
        return g if self.maximize else -g


# --------------------------------------------------------------------- Jacobian derivative
def jacobian_derivative(robot: Robot, q: object) -> np.ndarray:
    """Derivative of the geometric base-frame Jacobian, ``H[k] = ∂J/∂q_k``, shape (n, 6, n).

    With ``Jv_i``, ``Jω_i`` the linear and angular parts of column i and ``z_k`` the axis of
    revolute joint k (all in the world frame):

    * k ≤ i, joint k revolute: ``∂J_i/∂q_k = [z_k × Jv_i; z_k × Jω_i]``;
    * k > i, joint i revolute: ``∂J_i/∂q_k = [z_i × Jv_k; 0]``;
    * otherwise (a prismatic joint k before i, or a prismatic column i with k > i): 0.

    These follow from ``∂z_i/∂q_k = z_k × z_i`` and ``∂p/∂q_k = Jv_k`` and the Jacobi
    identity; they are checked against finite differences in the tests.

    Args:
        robot: the robot.
        q: joint values, shape (n,).
    """
    qv = robot.check_q(q)
    if qv.ndim != 1:
        raise InputError(f"q must have shape ({robot.n},), got {qv.shape}")
    J = robot.jacobian(qv)
    return _jacobian_derivative_from(J, robot.revolute)


def _jacobian_derivative_from(J: np.ndarray, revolute: np.ndarray) -> np.ndarray:
    n = J.shape[1]
    Jv = J[:3].T  # (n, 3)
    Jw = J[3:].T
    Z = Jw  # axis of revolute joints (zero for prismatic, unused there)
    H = np.zeros((n, 6, n))
    k_idx, i_idx = np.meshgrid(np.arange(n), np.arange(n), indexing="ij")
    lower = (k_idx <= i_idx) & revolute[:, None]          # k ≤ i, k revolute
    upper = (k_idx > i_idx) & revolute[None, :]           # k > i, i revolute
    zk = Z[k_idx]  # (n, n, 3) indexed [k, i]
    cv_low = np.cross(zk, Jv[i_idx])
    cw_low = np.cross(zk, Jw[i_idx])
    cv_up = np.cross(Z[i_idx], Jv[k_idx])
    dv = np.where(lower[..., None], cv_low, 0.0) + np.where(upper[..., None], cv_up, 0.0)
    dw = np.where(lower[..., None], cw_low, 0.0)
    H[:, :3, :] = np.transpose(dv, (0, 2, 1))
    H[:, 3:, :] = np.transpose(dw, (0, 2, 1))
    return H


# --------------------------------------------------------------------- eq 43
def manipulability_gradient(robot: Robot, q: object, task: str | Sequence[int] = "full"
                            ) -> tuple[float, np.ndarray]:
    """Manipulability ``w = sqrt(det(J_t J_tᵀ))`` (eq 43) and its analytic gradient (n,).

    ``∂w/∂q_k = w · Σ ((J_t J_tᵀ)⁻¹ J_t) ∘ (∂J_t/∂q_k)`` (trace identity), with ``J_t`` the
    task rows of the geometric Jacobian. At a singular configuration (w = 0) the
    gradient returned is 0 (w is not differentiable there).

    Args:
        robot: the robot.
        q: joint values, shape (n,).
        task: task rows, see :func:`task_rows`.

    Returns:
        (w, grad): w [m^m-ish, task units], grad shape (n,).
    """
    rows = task_rows(task)
    qv = robot.check_q(q)
    J = robot.jacobian(qv)
    Jt = J[rows]
    A = Jt @ Jt.T
    w = float(manipulability_of(np.ascontiguousarray(Jt)))
    if w <= 1e-300 or Jt.shape[0] > Jt.shape[1]:
        return w, np.zeros(robot.n)
    H = _jacobian_derivative_from(J, robot.revolute)[:, rows, :]
    B = np.linalg.solve(A, Jt)  # (m, n)
    grad = w * np.einsum("mn,kmn->k", B, H)
    return w, grad


def manipulability(robot: Robot, task: str | Sequence[int] = "full") -> Objective:
    """Objective of eq 43: maximise ``w(q) = sqrt(det(J Jᵀ))`` of the task rows.

    Args:
        robot: the robot.
        task: task rows ('planar', 'position', 'pose', ... or row indices).
    """
    task_rows(task)
    return Objective(
        name="manipulability",
        value=lambda q: manipulability_gradient(robot, q, task)[0],
        gradient=lambda q: manipulability_gradient(robot, q, task)[1],
        maximize=True,
    )


# --------------------------------------------------------------------- eq 44
def joint_limit_distance(robot: Robot, qlim: object = None) -> Objective:
    """Objective of eq 44 (ERRATA-corrected): minimise the distance from mid-range.

    ``H(q) = ½ Σ_i ((q_i − q̄_i)/(q_M,i − q_m,i))²`` with ``q̄_i = (q_M,i + q_m,i)/2``
    (the chapter prints ``(q_M − q_m)/2``, the half-range, which is wrong). Gradient:
    ``∂H/∂q_i = (q_i − q̄_i)/(q_M,i − q_m,i)²``. Joints without finite limits do not
    contribute.

    Args:
        robot: the robot.
        qlim: (n, 2) limits [rad or m]; default ``robot.qlim``.

    Raises:
        InputError: qlim of the wrong shape or with lower >= upper.
    """
    lim = robot.qlim if qlim is None else np.asarray(qlim, dtype=float)
    if lim.shape != (robot.n, 2):
        raise InputError(f"qlim must have shape ({robot.n}, 2), got {lim.shape}")
    finite = np.isfinite(lim).all(axis=1)
    if np.any(lim[finite, 0] >= lim[finite, 1]):
        raise InputError("qlim: every lower limit must be below its upper limit")
    lo = np.where(finite, lim[:, 0], 0.0)
    hi = np.where(finite, lim[:, 1], 1.0)
    mid = np.where(finite, 0.5 * (lo + hi), 0.0)
    span = hi - lo
    mask = finite.astype(float)

    def value(q: np.ndarray) -> float:
        x = (np.asarray(q, float) - mid) / span * mask
        return float(0.5 * x @ x)

    def gradient(q: np.ndarray) -> np.ndarray:
        return (np.asarray(q, float) - mid) / span**2 * mask

    return Objective("joint_limit_distance", value, gradient, maximize=False)


# --------------------------------------------------------------------- eq 45
def obstacle_distance(robot: Robot, obstacles: Sequence[Obstacle], *,
                      link_radius: float = 0.0, squared: bool = True) -> Objective:
    """Objective of eq 45: maximise the minimum distance between the links and obstacles.

    With ``c(q)`` the smallest signed clearance over every link segment and obstacle
    (:func:`serialkin.redundancy.obstacles.clearances`), ``H = c·|c|`` (eq 45's squared
    distance, sign kept so that H still increases when a link is inside an obstacle), or
    ``H = c`` with ``squared=False``. Gradient: ``∂c/∂q = uᵀ J_sc`` of the closest pair
    (eqs 51-56, corrected), times ``2|c|`` when squared.

    Args:
        robot: the robot.
        obstacles: obstacles (at least one).
        link_radius: radius of the links modelled as capsules [m].
        squared: eq 45's squared form (default) or the plain distance.
    """
    from serialkin.redundancy.obstacles import closest_pairs

    obs = tuple(obstacles)
    if not obs:
        raise InputError("obstacle_distance needs at least one obstacle")
    check_positive(link_radius, "link_radius", allow_zero=True)

    def both(q: np.ndarray) -> tuple[float, np.ndarray]:
        pairs = closest_pairs(robot, q, obs, link_radius=link_radius, with_jacobian=True)
        best = min(pairs, key=lambda p: p.clearance)
        c, g = best.clearance, best.gradient
        if squared:
            return c * abs(c), 2.0 * abs(c) * g
        return c, g

    return Objective("obstacle_distance", lambda q: both(q)[0], lambda q: both(q)[1],
                     maximize=True)


# --------------------------------------------------------------------- user objectives
def finite_difference_gradient(f: Callable[[np.ndarray], float], q: object,
                               step: float = 1e-6) -> np.ndarray:
    """Central finite-difference gradient of a scalar function, shape (n,)."""
    qv = np.asarray(q, dtype=float)
    g = np.empty(qv.shape[0])
    for i in range(qv.shape[0]):
        d = np.zeros_like(qv)
        d[i] = step
        g[i] = (float(f(qv + d)) - float(f(qv - d))) / (2 * step)
    return g


def custom_objective(value: Callable[[np.ndarray], float],
                     gradient: Callable[[np.ndarray], np.ndarray] | None = None, *,
                     maximize: bool = True, name: str = "custom",
                     step: float = 1e-6) -> Objective:
    """Wrap a user function as an :class:`Objective`.

    Args:
        value: ``H(q)`` for q of shape (n,), returning a real number.
        gradient: ``∇H(q)`` (n,); when None, central finite differences with ``step``.
        maximize: climb H (True) or descend it (False).
        name: label.
        step: finite-difference step [rad or m].

    Raises:
        InputTypeError: value or gradient not callable.
    """
    if not callable(value):
        raise InputTypeError(f"value must be callable, got {type(value).__name__}")
    if gradient is not None and not callable(gradient):
        raise InputTypeError(f"gradient must be callable or None, got {type(gradient).__name__}")
    check_positive(step, "step")
    grad = gradient if gradient is not None else (
        lambda q: finite_difference_gradient(value, q, step))
    return Objective(name, lambda q: float(value(q)), grad, maximize=bool(maximize))
