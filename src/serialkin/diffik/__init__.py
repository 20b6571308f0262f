"""Differential inverse kinematics as a quadratic program (tasks, hard constraints, solve).

Each step solves ``min ½ Σ_t ‖J_t Δq − gain_t e_t‖²_{W_t} + ½ μ ‖Δq‖²`` subject to joint
position and velocity limits and linearised collision constraints with a velocity damper
(:mod:`~serialkin.diffik.qp`). Tasks: :mod:`~serialkin.diffik.tasks`; constraints:
:mod:`~serialkin.diffik.constraints`; the path-tracking resolver:
:mod:`~serialkin.diffik.resolver` (``track(..., solver='qp')``). See docs/diffik.md.
"""

from serialkin.diffik.constraints import (
    CollisionAvoidance,
    Constraint,
    PositionLimit,
    StepBox,
    VelocityLimit,
)
from serialkin.diffik.model_collision import ModelCollisionAvoidance
from serialkin.diffik.qp import DiffIK, StepResult, solve_step
from serialkin.diffik.resolver import QPResolver, QPSolveStats
from serialkin.diffik.tasks import CustomTask, FrameTask, ManipulabilityTask, PostureTask, Task

__all__ = [
    "CollisionAvoidance",
    "Constraint",
    "CustomTask",
    "DiffIK",
    "FrameTask",
    "ManipulabilityTask",
    "ModelCollisionAvoidance",
    "PositionLimit",
    "PostureTask",
    "QPResolver",
    "QPSolveStats",
    "StepBox",
    "StepResult",
    "Task",
    "VelocityLimit",
    "solve_step",
]
