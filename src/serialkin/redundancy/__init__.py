"""Redundancy resolution (chapter section 5.3, eqs 42-56, corrected by the ERRATA).

* :mod:`~serialkin.redundancy.objectives` — objectives H(q) with gradients: manipulability
  (eq 43), joint-limit distance (eq 44), obstacle distance (eq 45), user callables.
* :mod:`~serialkin.redundancy.nullspace` — eq 42, projected gradient, two-task priority.
* :mod:`~serialkin.redundancy.multitask` — weighted multi-task resolution (eqs 47-50).
* :mod:`~serialkin.redundancy.obstacles` — link-obstacle distances and obstacle Jacobians
  (eqs 51-56); the obstacles are shapes of :mod:`serialkin.model.geometry` (``Sphere``,
  ``Capsule``, the infinite ``Cylinder`` along z).
"""

from serialkin.redundancy.multitask import (
    MultiTaskResolver,
    joint_limit_repulsion,
    joint_limit_weights,
)
from serialkin.redundancy.nullspace import (
    dls_inverse,
    nullspace_projector,
    projected_gradient_velocity,
    pseudo_inverse,
    self_motion,
    task_priority_velocity,
)
from serialkin.redundancy.objectives import (
    Objective,
    custom_objective,
    jacobian_derivative,
    joint_limit_distance,
    manipulability,
    manipulability_gradient,
    obstacle_distance,
)
from serialkin.redundancy.obstacles import (
    check_obstacles,
    clearances,
    closest_pairs,
    obstacle_jacobian,
)

__all__ = [
    "MultiTaskResolver",
    "Objective",
    "check_obstacles",
    "clearances",
    "closest_pairs",
    "custom_objective",
    "dls_inverse",
    "jacobian_derivative",
    "joint_limit_distance",
    "joint_limit_repulsion",
    "joint_limit_weights",
    "manipulability",
    "manipulability_gradient",
    "nullspace_projector",
    "obstacle_distance",
    "obstacle_jacobian",
    "projected_gradient_velocity",
    "pseudo_inverse",
    "self_motion",
    "task_priority_velocity",
]


def __getattr__(name: str) -> object:
    """``Circle``, ``Cylinder``, ``Sphere``, ``Capsule``: old obstacle names (warn)."""
    from serialkin.model.geometry import renamed
    from serialkin.redundancy.obstacles import _DEPRECATED

    return renamed(__name__, name, _DEPRECATED)
