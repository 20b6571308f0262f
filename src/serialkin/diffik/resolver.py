"""Path tracking through the differential-IK QP: :class:`QPResolver`.

For each path target the resolver iterates QP steps (``q ← q + Δq``, dt = 1) from the
previous configuration until the task error is below ``tol``, the budget is spent, or
the step vanishes (the constraints block the task: the result says so). Every step keeps
the hard constraints:

* joint limits (:class:`~serialkin.diffik.constraints.PositionLimit`, gain 1: a step goes
  at most to the limit; the solver's feasibility tolerance, 1e-6, is removed by clipping
  q to its limits, and to the ``max_joint_step`` box, after the step);
* a per-iteration joint step ``max_step`` (a velocity limit with dt = 1);
* optionally a bound on how far any joint may move between consecutive path points
  (``max_joint_step``, a :class:`~serialkin.diffik.constraints.StepBox` around the
  previous point's q): the tracker then never jumps by more, and a target it cannot
  reach within that bound is reported as not reached;
* collision avoidance against the obstacles (velocity damper with safety distance
  ``safety`` and gain ``collision_gain``);
* optionally self-collision avoidance (``self_collision``): for a robot with a collision
  model (``robot.collision``) between the body pairs of that model that its
  allowed-collision matrix checks (``acm``; by default
  :func:`~serialkin.collision.acm.default_acm`: same and adjacent frames and the pairs
  the model ships as allowed), the same pairs ``robot.in_collision`` checks; for a robot
  without one between the chain's link segments two or more apart.

With ``solver='compiled'`` (the default) the iterations of one target run in one
compiled loop (:func:`serialkin.diffik.compiled.qp_point_into`); with 'daqp' or a
qpsolvers solver they run in Python around :class:`~serialkin.diffik.DiffIK`. Both give
the same iterates (to the solvers' tolerances; the tests compare them).

The frame task is the path's task (its rows of the pose error); a posture task of weight
``posture_weight`` pulls towards the configuration at the start of the point (the
minimum-motion regulariser), and ``damping`` is the Tikhonov term μ.
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass, field, replace

import numpy as np

from serialkin._checks import MAX_ITERATIONS, check_int, check_positive, readonly, short_repr
from serialkin.diffik.constraints import (
    CollisionAvoidance,
    PositionLimit,
    StepBox,
    VelocityLimit,
)
from serialkin.diffik.qp import DiffIK, check_solver
from serialkin.diffik.tasks import FrameTask, PostureTask
from serialkin.errors import InputError
from serialkin.model.geometry import Capsule, Cylinder, Sphere
from serialkin.redundancy.obstacles import check_obstacles, encode_obstacles

__all__ = ["QPResolver", "QPSolveStats"]


@dataclass(frozen=True)
class QPSolveStats:
    """Outcome of one target: final q (n,), iterations, task error [m], reason ('' if met)."""

    q: np.ndarray
    iterations: int
    error: float
    converged: bool
    reason: str = ""


@dataclass(frozen=True)
class QPResolver:
    """Settings of QP path tracking (see the module docstring).

    Attributes:
        task: the path's task rows ('planar', 'position', 'pose', ...).
        obstacles: obstacles of the obstacle task (:mod:`serialkin.redundancy.obstacles`:
            ``Sphere``, ``Capsule`` and the infinite ``Cylinder`` along z of
            :mod:`serialkin.model.geometry`).
        link_radius: link capsule radius [m].
        safety: d_s, clearance kept from obstacles [m].
        collision_gain: fraction of ``d − d_s`` the clearance may lose per step, (0, 1].
        self_collision: also keep the robot's own bodies apart: with a collision model
            (``robot.collision``) the body pairs of the capsule model that ``acm`` checks
            (:class:`~serialkin.diffik.model_collision.ModelCollisionAvoidance`); without
            one, the chain's link segments two or more apart (capsules of ``link_radius``).
        acm: :class:`~serialkin.collision.acm.AllowedCollisionMatrix` of the capsule
            model's body pairs never checked (e.g. an SRDF's
            ``<disable_collisions>``: :func:`~serialkin.collision.acm.acm_from_srdf`);
            None: the model's default (:func:`~serialkin.collision.acm.default_acm`).
            Needs ``self_collision`` and a robot with a collision model.
        scene: scene shapes for the robot's capsule model ``robot.collision``
            (:class:`~serialkin.diffik.model_collision.ModelCollisionAvoidance`): spheres,
            capsules, z-cylinders, boxes, half-spaces of :mod:`serialkin.collision`, in the
            world frame. Non-empty: the capsule model is used (the iterations then run in
            Python around :class:`~serialkin.diffik.DiffIK`, with the chosen solver).
        posture_weight: weight of the pull towards the point's start configuration.
        damping: μ, Tikhonov damping of the QP [cost/rad²].
        max_step: largest change of any joint per iteration [rad or m].
        max_joint_step: largest change of any joint between consecutive path points
            (None: unbounded; the tracker still reports jumps above its own threshold).
        tol: convergence tolerance on the task error [m].
        max_iter: iteration budget per target.
        solver: 'compiled' (default: every iteration of a target in one compiled loop
            with the dual active-set solver of :mod:`serialkin.diffik.active_set`;
            measured 5× faster than DAQP called from Python per iteration), 'daqp' or
            'qpsolvers:<name>' (the Python loop of :class:`~serialkin.diffik.DiffIK`).
    """

    task: str | Sequence[int] = "planar"
    obstacles: tuple = field(default_factory=tuple)
    scene: tuple = field(default_factory=tuple)
    link_radius: float = 0.0
    safety: float = 0.002
    collision_gain: float = 0.5
    self_collision: bool = False
    acm: object = None
    posture_weight: float = 1e-4
    damping: float = 1e-6
    max_step: float = 0.1
    max_joint_step: float | None = None
    tol: float = 1e-5
    max_iter: int = 200
    solver: str = "compiled"

    def __post_init__(self) -> None:
        from serialkin.model.tasks import task_rows

        task_rows(self.task)
        if isinstance(self.obstacles, (str, bytes, Mapping)) or not isinstance(
                self.obstacles, Iterable):
            raise InputError("obstacles must be a list of Cylinder, Sphere or Capsule, got "
                             f"{type(self.obstacles).__name__} {short_repr(self.obstacles)}")
        obs = tuple(self.obstacles)
        for i, o in enumerate(obs):
            if not isinstance(o, Cylinder | Sphere | Capsule):
                raise InputError(f"obstacles[{i}] must be a Cylinder, Sphere or Capsule, got "
                                 f"{type(o).__name__}")
        encode_obstacles(obs)  # a finite or tilted cylinder: NotSupportedError
        object.__setattr__(self, "obstacles", obs)
        from serialkin.collision.shapes import encode_scene

        if isinstance(self.scene, (str, bytes, Mapping)) or not isinstance(self.scene, Iterable):
            raise InputError(f"scene must be a list of scene shapes, got "
                             f"{type(self.scene).__name__}")
        object.__setattr__(self, "scene", tuple(self.scene))
        encode_scene(self.scene)
        for name in ("link_radius", "safety", "posture_weight", "damping"):
            object.__setattr__(self, name, check_positive(getattr(self, name), name,
                                                          allow_zero=True))
        for name in ("max_step", "tol"):
            object.__setattr__(self, name, check_positive(getattr(self, name), name))
        object.__setattr__(self, "collision_gain",
                           check_positive(self.collision_gain, "collision_gain", maximum=1.0))
        if self.max_joint_step is not None:
            object.__setattr__(self, "max_joint_step",
                               check_positive(self.max_joint_step, "max_joint_step"))
        check_int(self.max_iter, "max_iter", minimum=1, maximum=MAX_ITERATIONS)
        check_solver(self.solver)
        if not isinstance(self.self_collision, bool):
            raise InputError(f"self_collision must be true or false, got "
                             f"{short_repr(self.self_collision)}")
        from serialkin.collision.acm import check_acm

        if check_acm(self.acm) is not None:
            if not self.self_collision:
                raise InputError("acm lists the body pairs a self-collision check skips; it "
                                 "needs self_collision=True")

    def with_options(self, **changes: object) -> QPResolver:
        """A copy with some settings changed (validated again)."""
        return replace(self, **changes)

    def prepare(self, robot) -> _QPState:
        """Buffers and checks for one robot (obstacles overlapping the base raise)."""
        check_obstacles(robot, self.obstacles, link_radius=self.link_radius)
        return _QPState(self, robot)


_NO_PROGRESS = ("no progress towards the target: the constraints (limits, obstacles, "
                "max_joint_step) block the task or the target is out of reach")


class _QPState:
    """One robot's QP (tasks and constraints built once; targets and references move)."""

    def __init__(self, res: QPResolver, robot) -> None:
        from serialkin.model.tasks import task_rows

        self.res = res
        self.robot = robot
        self.rows = task_rows(res.task)
        n = robot.n
        self.frame = FrameTask(np.eye(4), task=res.task)
        self.posture = PostureTask(np.zeros(n), weight=res.posture_weight)
        cons: list = [PositionLimit(), VelocityLimit(res.max_step)]
        self.box = None
        if res.max_joint_step is not None:
            self.box = StepBox(np.zeros(n), res.max_joint_step)
            cons.append(self.box)
        self.collision = None
        self.model_collision = None
        has_model = getattr(robot, "collision", None) is not None
        if res.acm is not None and not has_model:
            raise InputError(f"acm names bodies of a collision model, but robot "
                             f"{short_repr(robot.name)} has none (its self-collision check "
                             "keeps link segments apart); give it one with "
                             "robot.with_collision(model)")
        if res.scene or (res.self_collision and has_model):
            from serialkin.diffik.model_collision import ModelCollisionAvoidance

            self.model_collision = ModelCollisionAvoidance(
                res.scene, acm=res.acm, self_collision=res.self_collision, safety=res.safety,
                influence=res.safety + 0.03, gain=res.collision_gain)
            self.model_collision._state(robot)  # no model, or the scene through the base
            cons.append(self.model_collision)
        segments = res.self_collision and self.model_collision is None  # no body model
        if res.obstacles or segments:
            self.collision = CollisionAvoidance(
                res.obstacles, link_radius=res.link_radius, safety=res.safety,
                gain=res.collision_gain, self_pairs="auto" if segments else ())
            cons.append(self.collision)
        tasks = [self.frame] + ([self.posture] if res.posture_weight > 0 else [])
        self.ik = DiffIK(robot, tasks, cons, damping=res.damping, solver=res.solver)
        self.lo = np.ascontiguousarray(robot.qlim[:, 0], dtype=float)
        self.hi = np.ascontiguousarray(robot.qlim[:, 1], dtype=float)
        self.in_kernel = res.solver == "compiled" and self.model_collision is None
        if self.in_kernel:
            self._prepare_compiled()

    def _prepare_compiled(self) -> None:
        """Arguments of :func:`serialkin.diffik.compiled.qp_point_into` for this robot."""
        res, robot = self.res, self.robot
        col = self.collision or CollisionAvoidance((), safety=res.safety,
                                                   gain=res.collision_gain)
        _, g, pairs, G, h, PAIRS, DIST = col._state(robot)
        cfg = np.array([res.posture_weight, res.damping, res.max_step,
                        -1.0 if res.max_joint_step is None else res.max_joint_step, res.tol,
                        float(res.max_iter), res.link_radius, res.safety, res.collision_gain,
                        col._self_influence])
        c = robot.chain
        self._kernel_args = (
            np.ascontiguousarray(self.rows), c.F, c.L, c.meta, self.lo, self.hi, cfg,
            g.has_tool, col._enc, np.ascontiguousarray(col._influence, dtype=float), g.link,
            pairs, g.frames, g.P0, g.P1, g.Tee, g.T, g.SC, g.B, g.D, g.C, g.Jbuf, g.pbuf, G, h,
            PAIRS, DIST)

    def _error(self, q: np.ndarray) -> float:
        self.ik.ws.update(q)
        _, e, _ = self.frame.rows(self.ik.ws, q)
        return float(np.sqrt(e @ e))

    def _singular(self, q: np.ndarray) -> bool:
        """The frame task sees no descent direction (Jᵀ W e ≈ 0) while its error remains."""
        self.ik.ws.update(q)
        J, e, w = self.frame.rows(self.ik.ws, q)
        g = J.T @ (w * e)
        scale = float(np.linalg.norm(J)) * float(np.linalg.norm(e)) + 1e-300
        return float(np.linalg.norm(g)) < 1e-9 * scale

    def _solve_compiled(self, target: np.ndarray, q: np.ndarray) -> QPSolveStats:
        from serialkin.diffik.compiled import CONFLICT, NO_PROGRESS, qp_point_into
        from serialkin.diffik.qp import DAQP_EXIT

        a = self._kernel_args
        out = np.empty(q.size)
        # the target only read: read-only, as tracking passes its path's (one compiled type)
        it, err, code = qp_point_into(np.ascontiguousarray(q, dtype=float),
                                      readonly(np.ascontiguousarray(target, dtype=float)), a[0],
                                      *a[1:], out)
        reason = ""
        if code == NO_PROGRESS:
            reason = _NO_PROGRESS
        elif code == CONFLICT:
            reason = "conflicting bounds: a joint outside its limits beyond max_step"
        elif code < 0:
            reason = f"QP {DAQP_EXIT.get(int(code), f'exit flag {code}')}"
        return QPSolveStats(out, int(it), float(err), err < self.res.tol, reason)

    def solve(self, target: np.ndarray, q: np.ndarray) -> QPSolveStats:
        """Iterate QP steps towards ``target`` (4, 4) from q (n,) (q is not modified)."""
        if self.in_kernel:
            return self._solve_compiled(target, q)
        res = self.res
        q = np.array(q, dtype=float)
        self.frame.set_target(target)
        self.posture._ref[:] = q
        lo, hi = self.lo, self.hi
        if self.box is not None:
            self.box.reference = q.copy()
            lo = np.maximum(lo, q - res.max_joint_step)
            hi = np.minimum(hi, q + res.max_joint_step)
        err = self._error(q)
        best_q, best = q, err
        it = since_best = kicks = 0
        reason = ""
        while best >= res.tol and it < res.max_iter and since_best < 10:
            step = self.ik.step(q)
            it += 1
            if not step.success:
                reason = step.reason
                break
            q = np.clip(q + step.dq, lo, hi)  # removes the solver's 1e-6 tolerance
            err = self._error(q)
            if err < best * (1.0 - 1e-9):
                best_q, best, since_best = q, err, 0
            else:
                since_best += 1
            if np.max(np.abs(step.dq)) < 1e-12:
                if kicks >= 3 or not self._singular(q):
                    break
                # exactly singular with the error in the lost direction (the stretched arm
                # and a target behind it): Jᵀe = 0, the step vanishes; bend every joint by
                # a small fixed angle (inside the limits and the step box) to leave it, as
                # the DLS tracker does
                kicks += 1
                q = np.clip(q + 1e-3, lo, hi)
                since_best = 0
        if best >= res.tol and not reason and it < res.max_iter:
            reason = _NO_PROGRESS
        q, err = best_q, best
        return QPSolveStats(q, it, err, err < res.tol, reason)
