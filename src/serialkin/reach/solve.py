"""IK of a batch of map targets: reached or not, number of solutions, manipulability.

One function, :func:`solve_targets`, serves the reachability map and base placement,
so the solver can be switched in one place:

* ``"closed_form"`` — every closed-form solution inside the limits
  (:func:`serialkin.ik.analytic.ik_all`: one batched call for pose targets, one call
  per target for planar ones); a target is
  reached when there is at least one, and its number of solutions is their count;
* ``"numerical"`` — the batch IK ``robot.ik(targets, method="lm", q0=…, seed=…,
  restarts=…)`` (compiled, all cores); a target is reached when it converges, and it
  counts one solution (a numerical solver finds one per start);
* ``"auto"`` — closed form when the robot has one for the task, else numerical.

A collision scene (``scene=``) is passed to ``robot.ik`` only when given (the
constraint-aware IK); the closed-form path cannot honour it, so a scene selects the
numerical solver under ``"auto"``.

The manipulability of a reached target is the largest ``sqrt(det(J Jᵀ))`` (eq 43, the
task rows of J) over its solutions; 0 when not reached.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from serialkin._checks import check_choice
from serialkin.errors import InputError, NoClosedFormError

#: Solver names of :func:`solve_targets`.
SOLVERS = ("auto", "closed_form", "numerical")

#: Map tasks: what a target fixes (rows of the twist, :mod:`serialkin.model.tasks`).
TASKS = ("pose", "position", "planar_pose", "planar")


def default_task(robot: Any) -> str:
    """'planar_pose' (n ≥ 3) / 'planar' for a planar arm; 'pose' (n ≥ 6) / 'position'."""
    if robot.is_planar:
        return "planar_pose" if robot.n >= 3 else "planar"
    return "pose" if robot.n >= 6 else "position"


def oriented(task: str) -> bool:
    """True when the task's targets carry an orientation."""
    return task in ("pose", "planar_pose")


def make_targets(task: str, positions: np.ndarray, rotations: np.ndarray | None,
                 headings: np.ndarray | None) -> np.ndarray:
    """Targets for every (position, orientation) pair, position-major.

    Args:
        task: a name of :data:`TASKS`.
        positions: (P, 3) [m].
        rotations: (N, 3, 3) for 'pose'.
        headings: (N,) [rad] for 'planar_pose'.

    Returns:
        (P·N, 4, 4) poses ('pose'), (P·N, 3) (x, y, φ) ('planar_pose'), (P, 3) positions
        ('position') or (P, 2) ('planar').
    """
    P = positions.shape[0]
    if task == "pose":
        N = rotations.shape[0]  # type: ignore[union-attr]
        T = np.zeros((P, N, 4, 4))
        T[:, :, :3, :3] = rotations[None]  # type: ignore[index]
        T[:, :, :3, 3] = positions[:, None, :]
        T[:, :, 3, 3] = 1.0
        return T.reshape(P * N, 4, 4)
    if task == "planar_pose":
        N = headings.shape[0]  # type: ignore[union-attr]
        X = np.empty((P, N, 3))
        X[:, :, :2] = positions[:, None, :2]
        X[:, :, 2] = headings[None, :]  # type: ignore[index]
        return X.reshape(P * N, 3)
    if task == "planar":
        return np.ascontiguousarray(positions[:, :2])
    return np.ascontiguousarray(positions)


def resolve_solver(robot: Any, task: str, solver: str, scene: Any = None) -> str:
    """'closed_form' or 'numerical' for ``solver`` ('auto' picks; see the module docstring).

    Raises:
        InputError: an unknown solver; 'closed_form' for a robot or task without one.
    """
    solver = check_choice(solver, "solver", SOLVERS)
    if solver == "numerical":
        return solver
    from serialkin.ik.analytic import classify

    try:
        kind = classify(robot)
        ok = task in ("pose", "planar_pose") or (task == "planar" and kind == "planar_2r") \
            or (task == "position" and kind == "scara_rrp")
        why = f"the {kind} closed form needs a full target, not a {task} task"
    except NoClosedFormError as exc:
        ok, why = False, str(exc)
    if solver == "closed_form":
        if not ok:
            raise InputError(f"solver 'closed_form' is not available for robot "
                             f"{robot.name!r}: {why}")
        if scene is not None:
            raise InputError("solver 'closed_form' cannot take a collision scene; use "
                             "'numerical' (or 'auto')")
        return solver
    return "closed_form" if ok and scene is None else "numerical"


@dataclass(frozen=True)
class NumericalOptions:
    """Options of the numerical solver (``robot.ik(method='lm')``).

    Attributes:
        restarts: random restarts after the first attempt.
        tol: position [m] / orientation [rad] tolerance.
        max_iter: iterations per attempt (None: the method's default).
    """

    restarts: int = 5
    tol: float = 1e-6
    max_iter: int | None = None


def _manipulability_task(task: str) -> str:
    return {"pose": "full", "position": "position", "planar": "planar",
            "planar_pose": "planar_pose"}[task]


def solve_targets(robot: Any, task: str, targets: np.ndarray, solver: str, *,
                  q0: np.ndarray | None = None, seed: int = 0,
                  numerical: NumericalOptions = NumericalOptions(),
                  scene: Any = None) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Solve every target; (reached (M,) bool, solutions (M,) int32, manipulability (M,)).

    Args:
        robot: the robot.
        task: a name of :data:`TASKS` (the form of ``targets``, see :func:`make_targets`).
        targets: (M, 4, 4), (M, 3) or (M, 2).
        solver: 'closed_form' or 'numerical' (resolved by :func:`resolve_solver`).
        q0: (M, n) first guesses of the numerical solver.
        seed: stream seed of its restarts (the same for every target).
        numerical: its options.
        scene: collision scene passed to ``robot.ik`` when not None.
    """
    M = targets.shape[0]
    reached = np.zeros(M, dtype=bool)
    count = np.zeros(M, dtype=np.int32)
    manip = np.zeros(M)
    if M == 0:
        return reached, count, manip
    mtask = _manipulability_task(task)
    if solver == "closed_form":
        from serialkin.ik.analytic import ik_all

        if task == "pose":  # one batched call, on every core
            res = ik_all(robot, targets)
            count[:] = res.count
            sols = [res.q[i, : count[i]] for i in range(M)]
        else:  # planar targets: one call per target (ik_all batches poses only)
            sols = [ik_all(robot, t) for t in targets]
            count[:] = [len(s) for s in sols]
        reached[:] = count > 0
        if reached.any():
            Q = np.concatenate([s for s in sols if len(s)], axis=0)
            w = np.asarray(robot.manipulability(Q, task=mtask), dtype=float).reshape(-1)
            starts = np.concatenate([[0], np.cumsum(count[reached])[:-1]])
            manip[reached] = np.maximum.reduceat(w, starts)
        return reached, count, manip
    opts: dict[str, Any] = {"q0": q0, "seed": int(seed), "restarts": numerical.restarts,
                            "tol": numerical.tol}
    if numerical.max_iter is not None:
        opts["max_iter"] = numerical.max_iter
    if scene is not None:
        opts["scene"] = scene
    res = robot.ik(targets, method="lm", **opts)
    reached[:] = np.asarray(res.success, dtype=bool).reshape(-1)
    count[:] = reached
    if reached.any():
        Q = np.asarray(res.q).reshape(M, robot.n)[reached]
        manip[reached] = np.asarray(robot.manipulability(Q, task=mtask)).reshape(-1)
    return reached, count, manip
