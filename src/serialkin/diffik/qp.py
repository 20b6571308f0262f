"""One step of differential IK as a quadratic program, and its solution.

At a configuration q the step ``Δq`` (n,) solves

    minimise    ½ Δqᵀ H Δq + cᵀ Δq,     H = Σ_t J_tᵀ W_t J_t + μ I,   c = −Σ_t gain_t J_tᵀ W_t e_t
    subject to  lb ≤ Δq ≤ ub            (position limits, velocity limits, step boxes: the
                                          tightest of each side)
                G Δq ≤ h                (collision rows)

(tasks: :mod:`serialkin.diffik.tasks`; constraints: :mod:`serialkin.diffik.constraints`;
μ the Tikhonov damping). The QP is solved by DAQP (a dual active-set solver in C,
Arnström et al. 2022) called directly (``solver='daqp'``, the default), by the compiled
dual active-set solver of :mod:`serialkin.diffik.active_set` (``solver='compiled'``), or
by any solver of qpsolvers (``solver='qpsolvers:<name>'``, e.g. 'qpsolvers:osqp').

Failure is a result, never an exception from the solver: a lower bound above an upper
bound (e.g. a joint outside its limits further than its velocity limit lets it come back)
is found before the solve and named; an infeasible or failed solve gives
``success=False`` with the solver's reason and ``dq = 0`` (the robot stays where it is,
which keeps every hard constraint that held before).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from serialkin._checks import check_positive
from serialkin.diffik.constraints import Constraint
from serialkin.diffik.tasks import Task, Workspace
from serialkin.errors import InputError, InputTypeError

__all__ = ["DAQP_EXIT", "DiffIK", "StepResult", "check_solver", "solve_step"]

#: DAQP exit flags (https://darnstrom.github.io/daqp/parameters) and their meaning.
DAQP_EXIT = {
    1: "optimal", 2: "optimal (soft constraints violated)", -1: "infeasible",
    -2: "cycling detected", -3: "unbounded", -4: "iteration limit reached",
    -5: "non-convex problem", -6: "initial working set overdetermined",
}

_BIG = 1e20  # solvers take no infinity: an open side becomes this


@dataclass(frozen=True)
class StepResult:
    """The solution of one QP step.

    Attributes:
        dq: (n,) joint step [rad or m] (zeros when not successful).
        success: the QP was solved to optimality.
        reason: why not ('' on success).
        cost: optimal value of ½ Δqᵀ H Δq + cᵀ Δq.
        active: number of collision rows in the QP.
    """

    dq: np.ndarray
    success: bool
    reason: str = ""
    cost: float = 0.0
    active: int = 0


def _solve_daqp(H, c, G, h, lb, ub):
    daqp = _daqp()
    if h.size:
        bu = np.concatenate([ub, h])
        bl = np.concatenate([lb, np.full(h.size, -_BIG)])
    else:
        bu, bl = ub, lb
    x, fval, flag, _ = daqp.solve(H, c, G, bu, bl)
    return x, fval, flag


_DAQP = []


def _daqp():
    """The daqp module, imported once (lazily: ``import serialkin`` does not load it)."""
    if not _DAQP:
        import daqp

        _DAQP.append(daqp)
    return _DAQP[0]


def _solve_compiled(H, c, G, h, lb, ub):
    from serialkin.diffik.active_set import solve_bounded

    x = np.empty(lb.size)
    flag, _ = solve_bounded(H, c, G, h, lb, ub, x, 50 * (lb.size + h.size) + 100)
    return x, float(0.5 * x @ H @ x + c @ x), int(flag)


def _solve_qpsolvers(name, H, c, G, h, lb, ub):
    import qpsolvers

    x = qpsolvers.solve_qp(H, c, G if G.shape[0] else None, h if h.size else None,
                           lb=lb, ub=ub, solver=name)
    if x is None:
        return None, 0.0, -1
    x = np.asarray(x, dtype=float)
    return x, float(0.5 * x @ H @ x + c @ x), 1


def check_solver(solver: object) -> str:
    """Validate a solver name: 'daqp', 'compiled' or 'qpsolvers:<name>' (an installed one).

    Raises:
        InputError: anything else (the message lists the installed qpsolvers solvers).
    """
    if not isinstance(solver, str) or not (solver in ("daqp", "compiled")
                                           or solver.startswith("qpsolvers:")):
        raise InputError(f"solver must be 'daqp', 'compiled' or 'qpsolvers:<name>', got "
                         f"{solver!r}")
    if solver.startswith("qpsolvers:"):
        import qpsolvers

        name = solver.split(":", 1)[1]
        if name not in qpsolvers.available_solvers:
            raise InputError(f"qpsolvers has no solver {name!r} installed; available: "
                             f"{', '.join(qpsolvers.available_solvers)}")
    return solver


class DiffIK:
    """Tasks, constraints and solver settings of the differential-IK QP for one robot.

    Args:
        robot: the robot.
        tasks: sequence of :class:`~serialkin.diffik.tasks.Task`.
        constraints: sequence of :class:`~serialkin.diffik.constraints.Constraint`.
        damping: μ ≥ 0, Tikhonov damping added to H [cost/rad²] (makes H positive definite
            when the tasks leave joints free).
        solver: 'daqp' (direct call), 'compiled' or 'qpsolvers:<name>'.

    Raises:
        InputError: no task, negative damping, unknown solver.
        InputTypeError: a task or constraint of the wrong type.
    """

    def __init__(self, robot, tasks: Sequence[Task], constraints: Sequence[Constraint] = (), *,
                 damping: float = 1e-9, solver: str = "daqp") -> None:
        self.robot = robot
        self.tasks = tuple(tasks)
        self.constraints = tuple(constraints)
        if not self.tasks:
            raise InputError("DiffIK needs at least one task")
        for i, t in enumerate(self.tasks):
            if not isinstance(t, Task):
                raise InputTypeError(f"tasks[{i}] must be a serialkin.diffik task, got "
                                     f"{type(t).__name__}")
        for i, k in enumerate(self.constraints):
            if not isinstance(k, Constraint):
                raise InputTypeError(f"constraints[{i}] must be a serialkin.diffik constraint, "
                                     f"got {type(k).__name__}")
        self.damping = check_positive(damping, "damping", allow_zero=True)
        self.solver = check_solver(solver)
        self.ws = Workspace(robot)
        self._eye = np.eye(robot.n)
        self._lb = np.empty(robot.n)
        self._ub = np.empty(robot.n)
        self._H = np.empty((robot.n, robot.n))
        self._c = np.empty(robot.n)
        self._no_rows = (np.zeros((0, robot.n)), np.zeros(0))

    def problem(self, q: np.ndarray) -> tuple[np.ndarray, ...]:
        """The QP at q: ``(H (n, n), c (n,), G (r, n), h (r,), lb (n,), ub (n,))``.

        The arrays are this object's buffers, overwritten by the next call: copy what you
        keep.
        """
        self.ws.update(q)
        H = np.multiply(self._eye, self.damping, out=self._H)
        c = self._c
        c.fill(0.0)
        for t in self.tasks:
            t.accumulate(self.ws, q, H, c)
        lb = self._lb
        ub = self._ub
        lb.fill(-np.inf)
        ub.fill(np.inf)
        Gs, hs = [], []
        for k in self.constraints:
            if k.is_box:
                lo, hi = k.box(self.ws, q)
                np.maximum(lb, lo, out=lb)
                np.minimum(ub, hi, out=ub)
            else:
                G, h = k.rows(self.ws, q)
                if h.size:
                    Gs.append(G)
                    hs.append(h)
        if not Gs:
            return H, c, *self._no_rows, lb, ub
        G = Gs[0] if len(Gs) == 1 else np.vstack(Gs)
        h = hs[0] if len(hs) == 1 else np.concatenate(hs)
        return H, c, G, h, lb, ub

    def step(self, q: object) -> StepResult:
        """Solve the QP at q (n,); see the module docstring for failures."""
        qv = np.ascontiguousarray(q, dtype=float)
        if qv.shape != (self.robot.n,) or not math.isfinite(float(qv @ qv)):
            raise InputError(f"q must be {self.robot.n} finite values, got shape {qv.shape}")
        H, c, G, h, lb, ub = self.problem(qv)
        n = qv.size
        if np.any(lb > ub + 1e-12):
            j = int(np.flatnonzero(lb > ub + 1e-12)[0])
            name = self.robot.joint_names[j] if self.robot.joint_names else f"joint {j + 1}"
            return StepResult(np.zeros(n), False,
                              f"conflicting bounds on {name}: the constraints need "
                              f"Δq ≥ {lb[j]:.4g} and Δq ≤ {ub[j]:.4g}", 0.0, h.size)
        lb = np.maximum(np.minimum(lb, ub), -_BIG)  # bounds within 1e-12 of each other
        ub = np.minimum(ub, _BIG)
        try:
            if self.solver == "daqp":
                x, fval, flag = _solve_daqp(H, c, G, h, lb, ub)
            elif self.solver == "compiled":
                x, fval, flag = _solve_compiled(H, c, G, h, lb, ub)
            else:
                x, fval, flag = _solve_qpsolvers(self.solver.split(":", 1)[1], H, c, G, h,
                                                 lb, ub)
        except Exception as exc:  # noqa: BLE001 - a solver's internal error becomes a result
            return StepResult(np.zeros(n), False, f"QP solver failed: {exc}", 0.0, h.size)
        if flag not in (1, 2) or x is None or not math.isfinite(float(x @ x)):
            what = DAQP_EXIT.get(flag, f"exit flag {flag}")
            hint = (" (the constraints conflict: e.g. a link already closer to an obstacle "
                    "than the safety distance with no way out within the limits)"
                    if flag == -1 and h.size else "")
            return StepResult(np.zeros(n), False, f"QP {what}{hint}", 0.0, h.size)
        return StepResult(np.array(x, dtype=float), True, "", float(fval), h.size)


def solve_step(robot, q: object, tasks: Sequence[Task], constraints: Sequence[Constraint] = (),
               *, damping: float = 1e-9, solver: str = "daqp") -> StepResult:
    """One differential-IK step at q: build a :class:`DiffIK` and call its ``step``.

    For repeated steps keep the :class:`DiffIK` (it holds the buffers).
    """
    return DiffIK(robot, tasks, constraints, damping=damping, solver=solver).step(q)
