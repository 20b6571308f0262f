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

**Collisions** (:class:`CollisionOptions`, and a ``scene=``): a target counts as
reached only with a collision-free solution, one whose clearance (smallest signed
distance of the robot's collision model to itself, over the pairs the allowed-collision
matrix checks, and to the scene) is at least ``clearance`` [m]. The closed-form path
keeps, of every solution, those that are free (:func:`collision_free`, exact: a target
with no free closed-form solution has none); the numerical path asks ``robot.ik`` for a
collision-free solution (``scene=``, ``self_collision=``, ``acm=``, ``margin=``), which
can miss one. The robot needs a collision model (``robot.collision``).

The manipulability of a reached target is the largest ``sqrt(det(J Jᵀ))`` (eq 43, the
task rows of J) over its (collision-free) solutions; 0 when not reached.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from serialkin._checks import check_choice, check_real, short_repr
from serialkin.errors import InputError, InputTypeError, NoClosedFormError

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

    ``scene`` is accepted for compatibility and does not change the choice: both paths
    honour collisions (the closed form by filtering its solutions).

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
        return solver
    return "closed_form" if ok else "numerical"


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


@dataclass(frozen=True)
class CollisionOptions:
    """Which collisions make a solution unusable (besides a scene's obstacles).

    Attributes:
        self_collision: check the robot's own body pairs (those ``acm`` does not allow).
        acm: :class:`~serialkin.collision.acm.AllowedCollisionMatrix` of the robot's model,
            or None for the model's default (:func:`~serialkin.collision.acm.default_acm`).
        clearance: smallest signed distance a solution must keep [m], >= 0 (0: touching
            is allowed, overlapping is not).
    """

    self_collision: bool = False
    acm: Any = None
    clearance: float = 0.0

    @property
    def active(self) -> bool:
        """True when anything beyond a scene is checked or a clearance is asked for."""
        return self.self_collision or self.clearance != 0.0

    def settings(self, robot: Any) -> dict[str, Any] | None:
        """JSON-ready record (None when inactive): flag, ACM hash and clearance [m]."""
        if not self.active:
            return None
        return {"self_collision": self.self_collision, "clearance": self.clearance,
                "acm_hash": acm_digest(self.effective_acm(robot))
                if self.self_collision else None}

    def effective_acm(self, robot: Any) -> Any:
        """The matrix checked: ``acm``, or the default of ``robot.collision``."""
        if self.acm is not None:
            return self.acm
        from serialkin.collision.acm import default_acm

        return default_acm(robot.collision)


def acm_digest(acm: Any) -> str:
    """SHA-256 (16 hex digits) of an allowed-collision matrix: its body names and pairs."""
    import hashlib

    h = hashlib.sha256("\n".join(acm.body_names).encode("utf-8"))
    h.update(np.packbits(np.asarray(acm.allowed, dtype=bool)).tobytes())
    return h.hexdigest()[:16]


def check_collision_options(robot: Any, self_collision: object, acm: object,
                            clearance: object, scene: object = None) -> CollisionOptions:
    """Validate collision settings at the boundary; the :class:`CollisionOptions`.

    Raises:
        InputTypeError: ``self_collision`` not a bool; ``acm`` not an
            AllowedCollisionMatrix.
        InputError: a negative or non-finite clearance; ``acm`` without self-collision; an
            ACM of other bodies; a collision check on a robot without a collision model.
    """
    from serialkin.collision.acm import check_acm

    if not isinstance(self_collision, (bool, np.bool_)):
        raise InputTypeError(f"self_collision must be True or False, got "
                             f"{short_repr(self_collision)}")
    clearance = check_real(clearance, "clearance", unit="m")
    if clearance < 0.0:
        raise InputError(f"clearance must be >= 0 m (the distance a solution keeps from "
                         f"collisions), got {clearance!r}")
    if check_acm(acm) is not None:
        if not self_collision:
            raise InputError("acm lists the body pairs a self-collision check skips; it "
                             "needs self_collision=True")
    opts = CollisionOptions(bool(self_collision), acm, float(clearance))
    if (opts.self_collision or scene is not None) and getattr(robot, "collision", None) is None:
        raise InputError(f"robot {short_repr(robot.name)} has no collision model, so "
                         "self_collision / scene cannot be checked; attach one with "
                         "robot.with_collision(model) or robot.fit_collision()")
    if acm is not None and tuple(acm.body_names) != tuple(robot.collision.body_names):
        raise InputError(f"acm is over the bodies {list(acm.body_names)[:6]}..., expected "
                         f"those of robot {short_repr(robot.name)}'s collision model "
                         f"{list(robot.collision.body_names)[:6]}...")
    return opts


def collision_free(robot: Any, Q: np.ndarray, scene: Any = None,
                   collision: CollisionOptions = CollisionOptions()) -> np.ndarray:
    """(K,) bool: configurations Q (K, n) whose clearance is >= ``collision.clearance``.

    The clearance is the smallest signed distance [m] of the robot's collision model to
    itself (pairs not allowed by the ACM; only with ``collision.self_collision``) and to
    ``scene`` (world frame of the robot; only when given). Nothing to check: all True.
    """
    free = np.ones(Q.shape[0], dtype=bool)
    if Q.shape[0] == 0 or not (collision.self_collision or scene is not None):
        return free
    from serialkin.collision.queries import scene_clearance, self_clearance

    model = robot.collision
    if collision.self_collision:
        free &= self_clearance(robot, model, Q, collision.acm).distance >= collision.clearance
    if scene is not None and free.any():
        d = scene_clearance(robot, model, Q[free], scene).distance
        free[np.flatnonzero(free)] = d >= collision.clearance
    return free


def _manipulability_task(task: str) -> str:
    return {"pose": "full", "position": "position", "planar": "planar",
            "planar_pose": "planar_pose"}[task]


def solve_targets(robot: Any, task: str, targets: np.ndarray, solver: str, *,
                  q0: np.ndarray | None = None, seed: int = 0,
                  numerical: NumericalOptions = NumericalOptions(),
                  scene: Any = None, collision: CollisionOptions = CollisionOptions()
                  ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Solve every target; (reached (M,) bool, solutions (M,) int32, manipulability (M,)).

    Args:
        robot: the robot.
        task: a name of :data:`TASKS` (the form of ``targets``, see :func:`make_targets`).
        targets: (M, 4, 4), (M, 3) or (M, 2).
        solver: 'closed_form' or 'numerical' (resolved by :func:`resolve_solver`).
        q0: (M, n) first guesses of the numerical solver.
        seed: stream seed of its restarts (the same for every target).
        numerical: its options.
        scene: collision scene (the robot's world frame) when not None.
        collision: self-collision and clearance (see the module docstring).

    A solution in collision does not count: ``solutions`` counts the free ones, and a
    target with none is not reached.
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
            sols = [np.asarray(ik_all(robot, t)).reshape(-1, robot.n) for t in targets]
            count[:] = [len(s) for s in sols]
        if scene is not None or collision.self_collision:  # keep the free solutions
            flat = np.concatenate(sols, axis=0) if count.sum() else np.zeros((0, robot.n))
            keep = np.split(collision_free(robot, flat, scene, collision), np.cumsum(count)[:-1])
            sols = [s[k] for s, k in zip(sols, keep, strict=True)]
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
    if collision.self_collision:
        opts["self_collision"] = True
        if collision.acm is not None:
            opts["acm"] = collision.acm
    if collision.clearance and (scene is not None or collision.self_collision):
        opts["margin"] = collision.clearance
    res = robot.ik(targets, method="lm", **opts)
    reached[:] = np.asarray(res.success, dtype=bool).reshape(-1)
    count[:] = reached
    if reached.any():
        Q = np.asarray(res.q).reshape(M, robot.n)[reached]
        manip[reached] = np.asarray(robot.manipulability(Q, task=mtask)).reshape(-1)
    return reached, count, manip
