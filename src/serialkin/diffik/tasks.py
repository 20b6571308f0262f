"""Tasks of the differential-IK quadratic program: rows ``J Δq ≈ gain · e`` with weights.

A task contributes ``½ Σ_i w_i (J_i Δq − gain · e_i)²`` to the QP cost, where ``Δq`` (n,)
is the joint displacement of one step, ``J`` (k, n) the task Jacobian, ``e`` (k,) the
task error (what the task wants to change, in the task's units) and ``w`` (k,) the row
weights ([cost]/[task unit]²; pink's and mink's cost vector ``c`` is ``w = c²``). With
``gain = 1`` a lone task asks to close its error in one step (dead beat); smaller gains
filter. Priorities are expressed by weights (a soft hierarchy: a task weighted 10³ above
another wins every conflict up to a relative 10⁻³); hard requirements belong in the
constraints (:mod:`serialkin.diffik.constraints`).

=====================  ==========================  ===================================
task                   J (k × n)                   e (k,)
=====================  ==========================  ===================================
:class:`FrameTask`     rows of the geometric       rows of ``[p_t − p; log(R_t Rᵀ)^∨]``
                       Jacobian (world frame)      (the library's pose error)
:class:`PostureTask`   I                           ``q_ref − q``
:class:`ManipulabilityTask`  I                     ``∇w(q)`` of eq 43 (ascent)
:class:`CustomTask`    the user's                  the user's
=====================  ==========================  ===================================
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass, field

import numpy as np

from serialkin._checks import as_float_array, check_positive, check_transform, readonly
from serialkin.errors import InputError, InputTypeError
from serialkin.kinematics import kernels as K
from serialkin.model.tasks import task_rows
from serialkin.spatial.kernels import pose_error_into

__all__ = ["CustomTask", "FrameTask", "ManipulabilityTask", "PostureTask", "Task"]


def _weights(weight: object, size: int, name: str = "weight") -> np.ndarray:
    """A scalar or (size,) non-negative weight as a (size,) array."""
    w = as_float_array(weight, name)
    if w.ndim == 0:
        w = np.full(size, float(w))
    if w.shape != (size,) or not np.all(np.isfinite(w)) or np.any(w < 0.0):
        raise InputError(f"{name} must be a non-negative number or {size} non-negative "
                         f"numbers, got {np.asarray(weight).tolist()}")
    return np.ascontiguousarray(w)


class Workspace:
    """Per-step buffers shared by the tasks of one QP: the tool pose and Jacobian at q."""

    def __init__(self, robot) -> None:
        self.robot = robot
        self.J = np.empty((6, robot.n))
        self.T = np.empty((4, 4))
        self.e6 = np.empty(6)
        self.q = np.full(robot.n, np.nan)

    def update(self, q: np.ndarray) -> None:
        """Tool Jacobian (6, n) and pose (4, 4) at q (once per step)."""
        c = self.robot.chain
        K.jacobian_into(q, c.F, c.meta, self.J, self.T)
        self.q[:] = q


class Task:
    """Base class: a task returns ``(J (k, n), e (k,), w (k,))`` at a configuration."""

    gain: float = 1.0

    def rows(self, ws: Workspace, q: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Task Jacobian, error and row weights at q (``ws`` holds the tool J and pose)."""
        raise NotImplementedError  # pragma: no cover

    def accumulate(self, ws: Workspace, q: np.ndarray, H: np.ndarray, c: np.ndarray) -> None:
        """Add the task to the QP: ``H += Jᵀ W J``, ``c −= gain Jᵀ W e`` (in place)."""
        J, e, w = self.rows(ws, q)
        WJ = J * w[:, None]
        H += J.T @ WJ
        c -= self.gain * (WJ.T @ e)

    def error_norm(self, ws: Workspace, q: np.ndarray) -> float:
        """‖e‖ of the task at q (after ``ws.update(q)``)."""
        return float(np.linalg.norm(self.rows(ws, q)[1]))


@dataclass
class FrameTask(Task):
    """Bring the tool frame (or some of its rows) to a target pose.

    ``J`` is the rows ``task`` of the geometric Jacobian ``[v; ω]`` in the world frame and
    ``e`` the same rows of the pose error ``[p_t − p; log(R_t Rᵀ)^∨]`` [m; rad], so a step
    with ``gain = 1`` is the Gauss-Newton step of the pose error.

    Attributes:
        target: (4, 4) target pose ``T_world_tool``; for point tasks only the position
            (and, for 'planar_pose', the rotation about z) matters.
        task: rows: 'pose' (6), 'position' (3), 'orientation' (3), 'planar' (2),
            'planar_pose' (3) or explicit row indices (see :mod:`serialkin.model.tasks`).
        weight: w per row or one for all [cost/m² or cost/rad²].
        gain: fraction of the error closed per step (0, 1].
    """

    target: object
    task: str | Sequence[int] = "pose"
    weight: object = 1.0
    gain: float = 1.0
    _rows: np.ndarray = field(init=False, repr=False)
    _w: np.ndarray = field(init=False, repr=False)

    def __post_init__(self) -> None:
        self._rows = task_rows(self.task)
        self._all = self._rows.tolist() == [0, 1, 2, 3, 4, 5]
        self._w = _weights(self.weight, self._rows.size)
        self._unit = bool(np.all(self._w == 1.0))
        self.gain = check_positive(self.gain, "gain", maximum=1.0)
        self.set_target(self.target)

    def set_target(self, target: object) -> None:
        """Change the target pose (4, 4) (tracking moves it along the path)."""
        # read-only: the kernels take targets read-only (one compiled specialization)
        self.target = readonly(np.ascontiguousarray(check_transform(target, "target")))

    def rows(self, ws: Workspace, q: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Rows of the geometric Jacobian and of the pose error (see the class docstring)."""
        pose_error_into(ws.T, self.target, ws.e6)
        if self._all:
            return ws.J, ws.e6, self._w
        return ws.J[self._rows], ws.e6[self._rows], self._w

    def accumulate(self, ws: Workspace, q: np.ndarray, H: np.ndarray, c: np.ndarray) -> None:
        """``H += Jᵀ W J``, ``c −= gain Jᵀ W e`` (unit weights: no weighting pass)."""
        J, e, w = self.rows(ws, q)
        if self._unit:
            H += J.T @ J
            c -= self.gain * (e @ J)
        else:
            WJ = J * w[:, None]
            H += J.T @ WJ
            c -= self.gain * (e @ WJ)


@dataclass
class PostureTask(Task):
    """Pull every joint towards a reference configuration: ``J = I``, ``e = q_ref − q``.

    Attributes:
        reference: (n,) reference configuration [rad or m].
        weight: w per joint or one for all [cost/rad²].
        gain: fraction of the error closed per step (0, 1].
    """

    reference: object
    weight: object = 1.0
    gain: float = 1.0
    _ref: np.ndarray = field(init=False, repr=False)
    _w: np.ndarray = field(init=False, repr=False)
    _eye: np.ndarray = field(init=False, repr=False)

    def __post_init__(self) -> None:
        ref = as_float_array(self.reference, "reference", ndim=1)
        if not np.all(np.isfinite(ref)):
            raise InputError(f"reference must be finite, got {ref.tolist()}")
        self._ref = np.ascontiguousarray(ref)
        self._w = _weights(self.weight, ref.size)
        self._eye = np.eye(ref.size)
        self.gain = check_positive(self.gain, "gain", maximum=1.0)

    def accumulate(self, ws: Workspace, q: np.ndarray, H: np.ndarray, c: np.ndarray) -> None:
        """``H += diag(w)``, ``c −= gain · w (q_ref − q)`` (J = I, without forming it)."""
        if self._ref.size != q.size:
            raise InputError(f"PostureTask reference has {self._ref.size} values but the "
                             f"robot has {q.size} joints")
        H.flat[::q.size + 1] += self._w
        c -= self.gain * self._w * (self._ref - q)

    def rows(self, ws: Workspace, q: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Identity rows and ``q_ref − q``."""
        if self._ref.size != q.size:
            raise InputError(f"PostureTask reference has {self._ref.size} values but the "
                             f"robot has {q.size} joints")
        return self._eye, self._ref - q, self._w


@dataclass
class ManipulabilityTask(Task):
    """Climb the manipulability ``w(q) = sqrt(det(J_t J_tᵀ))`` of eq 43.

    ``J = I`` and ``e = step · ∇w / max(‖∇w‖, ε)``: each step asks for a joint move of
    length ``step`` [rad] along the gradient (the null-space objective of eq 42 as a soft
    task); the analytic gradient is
    :func:`serialkin.redundancy.objectives.manipulability_gradient`.

    Attributes:
        task: rows whose manipulability is climbed (default 'pose').
        step: joint move asked per step along the gradient [rad].
        weight: w [cost/rad²] (keep it small against the frame task).
    """

    task: str | Sequence[int] = "pose"
    step: float = 0.05
    weight: float = 1e-3
    gain: float = 1.0

    def __post_init__(self) -> None:
        task_rows(self.task)
        self.step = check_positive(self.step, "step")
        self.weight = check_positive(self.weight, "weight", allow_zero=True)

    def rows(self, ws: Workspace, q: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Identity rows and the scaled gradient of w."""
        from serialkin.redundancy.objectives import manipulability_gradient

        _, grad = manipulability_gradient(ws.robot, q, self.task)
        norm = float(np.linalg.norm(grad))
        e = grad * (self.step / norm) if norm > 1e-12 else np.zeros(q.size)
        return np.eye(q.size), e, np.full(q.size, self.weight)


@dataclass
class CustomTask(Task):
    """A user's task: ``function(q) -> (J (k, n), e (k,))`` with ``J Δq ≈ gain · e`` wanted.

    Attributes:
        function: called with q (n,) once per step; returns the Jacobian and the error
            (the change of the task quantity the task asks for, in its own units).
        weight: w per row or one for all.
        gain: fraction of the error closed per step (0, 1].
        name: label used in error messages.
    """

    function: Callable[[np.ndarray], tuple[object, object]]
    weight: object = 1.0
    gain: float = 1.0
    name: str = "custom task"

    def __post_init__(self) -> None:
        if not callable(self.function):
            raise InputTypeError(f"CustomTask function must be callable, got "
                                 f"{type(self.function).__name__}")
        self.gain = check_positive(self.gain, "gain", maximum=1.0)

    def rows(self, ws: Workspace, q: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """The user's rows, checked for shape and finiteness."""
        out = self.function(q.copy())
        if not isinstance(out, tuple) or len(out) != 2:
            raise InputTypeError(f"{self.name}: function must return (J, e), got "
                                 f"{type(out).__name__}")
        J = as_float_array(out[0], f"{self.name} J")
        e = as_float_array(out[1], f"{self.name} e")
        if J.ndim == 1:
            J = J[None, :]
        e = np.atleast_1d(e)
        if J.ndim != 2 or J.shape[1] != q.size or e.shape != (J.shape[0],):
            raise InputError(f"{self.name}: expected J of shape (k, {q.size}) and e of shape "
                             f"(k,), got {J.shape} and {e.shape}")
        if not (np.all(np.isfinite(J)) and np.all(np.isfinite(e))):
            raise InputError(f"{self.name}: J and e must be finite")
        return J, e, _weights(self.weight, e.size, f"{self.name} weight")
