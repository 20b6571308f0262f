"""Path tracking: follow a task-space path with a redundant (or any) arm.

:func:`track` walks the path point by point ("CYCLE WHILE 1" of the chapter's algorithms)
and, at each point, iterates a solver from the previous configuration until the task
error is below ``tol`` or the iteration budget is spent ("CYCLE WHILE 2"). Solvers:

* ``'dls'`` (default) — damped least squares, eq 46 as corrected by the ERRATA:
  ``Δq = Jᵀ(J Jᵀ + λ²I)⁻¹ Δx; q ← q + Δq`` (the chapter's 6-link algorithm, steps 5-8,
  corrected). The whole path runs in one compiled loop over the kernel family.
* ``'multitask'`` or a :class:`~serialkin.redundancy.multitask.MultiTaskResolver` — the
  weighted multi-task resolution of eq 48 (obstacles, joint limits, singularities).
* ``'qp'`` or a :class:`~serialkin.diffik.resolver.QPResolver` — differential IK as a
  quadratic program with hard joint limits and collision constraints
  (:mod:`serialkin.diffik`).
* any other name — an IK method of :func:`serialkin.ik.solve` (``robot.ik``), warm
  started from the previous configuration.

A point whose final error exceeds ``tolerance`` is reported (:class:`PathFailure`: index,
error, target); tracking continues from the best configuration found or stops there, as
chosen with ``on_unreachable``; everything computed so far is kept in the trajectory.

Self-collision: a :class:`~serialkin.diffik.resolver.QPResolver` with
``self_collision=True`` keeps the robot's own bodies apart. On a robot with a collision
model (``robot.collision``) these are the body pairs that the model's allowed-collision
matrix checks, the same pairs as :meth:`Robot.in_collision <serialkin.Robot.in_collision>`,
``serialkin collide`` and the reach maps check: by default
:func:`~serialkin.collision.acm.default_acm` (same and adjacent frames, and the pairs of
:mod:`serialkin.collision.allowed_pairs`), or the matrix given to :func:`track` as
``acm``, or that default with an SRDF's ``<disable_collisions>`` pairs added (``srdf``,
``skip_links``, as in :func:`serialkin.collision.robot_acm`). On a robot without a model
(the scenarios' planar arms) the chain's link segments two or more apart are kept apart;
an SRDF cannot name those segments and is refused.

Joint jumps: with ``max_joint_step`` set, every pair of consecutive points where some joint
moved by more than that (a branch flip, a wrap) is reported in ``Trajectory.jumps``
(:class:`~serialkin.tracking.trajectory.JointJump`), never silently; the QP solver
additionally enforces the bound as a hard constraint, so it reports a point it cannot
reach within the bound as not reached instead of jumping.
"""

from __future__ import annotations

import os
import time
from collections.abc import Callable, Iterable, Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np

from serialkin._checks import (
    MAX_ITERATIONS,
    check_choice,
    check_int,
    check_positive,
    short_repr,
)
from serialkin.diffik.resolver import QPResolver
from serialkin.errors import InputError, InputTypeError, RobotDefinitionError
from serialkin.kinematics import kernels as K
from serialkin.kinematics.dls import dls_step_into, weigh_rows_into
from serialkin.model.limits import project as interval_project
from serialkin.model.tasks import get_task
from serialkin.redundancy.multitask import MultiTaskResolver
from serialkin.redundancy.objectives import task_rows
from serialkin.redundancy.obstacles import ObstacleGeometry, check_obstacles, encode_obstacles
from serialkin.spatial.kernels import pose_error_into
from serialkin.tracking.path import Path
from serialkin.tracking.trajectory import JointJump, PathFailure, Trajectory

from .._jit import njit_exact

__all__ = ["ON_UNREACHABLE", "dls_track", "joint_jumps", "limit_margins", "track"]

ON_UNREACHABLE = ("continue", "stop")


@njit_exact(cache=True)
def dls_track(q0, targets, rows, F, meta, lam, tol, max_iter, max_step, accept, stop_on_fail,
              kick, lo, hi, revolute, Q, ITER, ERR):
    """Compiled DLS path tracking (eq 46 corrected, the 6-link algorithm).

    After every step each joint is projected onto its limits
    (:func:`serialkin.model.limits.project`: whole turns first for revolute joints, then
    the nearer limit), so every recorded q is inside the limits; unlimited joints are
    untouched (the chapter's 6-link arm).

    Args:
        q0: (n,) start configuration.
        targets: (p, 4, 4) target poses.
        rows: (m,) task rows of the pose error / Jacobian ([0, 1] for planar points).
        F: chain fixed transforms ``robot.chain.F``.
        meta: chain joint data ``robot.chain.meta``.
        lam: damping λ [m].
        tol: convergence tolerance on ‖e‖ [m].
        max_iter: iteration budget per point.
        max_step: cap on ‖Δq‖ per iteration [rad].
        accept: acceptance tolerance [m] (a point is reached when ‖e‖ ≤ accept).
        stop_on_fail: stop after the first point not reached.
        kick: joint offset [rad] added to every joint when the step vanishes while the
            error does not (an exact singularity), to leave it.
        lo: (n,) lower joint limits (-inf allowed).
        hi: (n,) upper joint limits (+inf allowed).
        revolute: (n,) 1.0 for revolute joints, 0.0 for prismatic ones.
        Q: out (p, n) joint values per point.
        ITER: out (p,) iterations per point.
        ERR: out (p,) final error norm per point [m].

    Returns:
        number of points computed.
    """
    n = q0.shape[0]
    m = rows.shape[0]
    p = targets.shape[0]
    q = q0.copy()
    for j in range(n):
        q[j] = interval_project(q[j], lo[j], hi[j], revolute[j] != 0.0)
    J = np.empty((6, n))
    T = np.empty((4, 4))
    e6 = np.empty(6)
    e = np.empty(m)
    Jt = np.empty((m, n))
    A = np.empty((m, m))
    y = np.empty(m)
    dq = np.empty(n)
    ones = np.ones(m)
    for k in range(p):
        it = 0
        while True:
            K.jacobian_into(q, F, meta, J, T)
            pose_error_into(T, targets[k], e6)
            err = np.sqrt(weigh_rows_into(J, e6, rows, ones, Jt, e))
            if err < tol or it >= max_iter:
                break
            dls_step_into(Jt, e, lam * lam, 0.0, A, y, dq)
            nrm = np.sqrt(np.sum(dq * dq))
            if nrm > max_step:
                dq *= max_step / nrm
            for j in range(n):
                q[j] += dq[j]
            it += 1
            if nrm < 1e-12 * (1.0 + err):
                # exactly singular with the error in the lost direction (e.g. the stretched
                # q0 = 0 of the 6-link example and a target behind the arm): the DLS step
                # vanishes; bend every joint by a small fixed angle to leave the singularity
                for j in range(n):
                    q[j] += kick
            for j in range(n):
                q[j] = interval_project(q[j], lo[j], hi[j], revolute[j] != 0.0)
        for j in range(n):
            Q[k, j] = q[j]
        ITER[k] = it
        ERR[k] = err
        if stop_on_fail and err > accept:
            return k + 1
    return p


def limit_margins(q: np.ndarray, qlim: np.ndarray) -> np.ndarray:
    """Distance of each joint to its nearer limit, (..., n) [rad or m]; negative when outside."""
    with np.errstate(invalid="ignore"):
        m = np.minimum(q - qlim[:, 0], qlim[:, 1] - q)
    return np.where(np.isnan(m), np.inf, m)


def _ik_target(path: Path, k: int) -> np.ndarray:
    if get_task(path.task).point_size <= 3:  # point tasks: IK takes the coordinates
        return np.array(path.points[k])
    return np.array(path.targets[k])


@dataclass(frozen=True, eq=False)
class _TrackSettings:
    """The checked settings of one :func:`track` call, shared by its helpers.

    Attributes:
        q_start: (n,) start configuration [rad or m].
        rows: task rows of the path's task.
        obstacles: the obstacles (a resolver's own when none were given).
        link_radius: link capsule radius [m].
        accept: acceptance tolerance [m] (``tolerance``).
        conv: convergence tolerance of the iterations [m] (``tol``).
        lam: DLS damping λ [m] (``damping``).
        budget: iteration budget per point (``max_iter``).
        cap: cap on the joint step per DLS iteration [rad] (``max_step``).
        jump: ``max_joint_step`` [rad or m], or None.
        stop: stop after the first point not reached (``on_unreachable='stop'``).
        acm: the allowed-collision matrix of the QP's self-collision check (from
            ``acm`` or ``srdf``), or None: the resolver's own.
    """

    q_start: np.ndarray
    rows: np.ndarray
    obstacles: tuple
    link_radius: float
    accept: float
    conv: float
    lam: float
    budget: int
    cap: float
    jump: float | None
    stop: bool
    acm: Any = None


@dataclass(frozen=True, eq=False)
class _Record:
    """What :func:`track` records per path point, filled in place by the solver loops.

    Attributes:
        Q: (p, n) joint values.
        ITER: (p,) iterations.
        ERR: (p,) final task errors [m].
        TIMES: (p,) wall time [s].
        reasons: why a solver stopped early at a point (QP), by point index.
    """

    Q: np.ndarray
    ITER: np.ndarray
    ERR: np.ndarray
    TIMES: np.ndarray
    reasons: dict[int, str]

    @classmethod
    def empty(cls, p: int, n: int) -> _Record:
        """Zeroed buffers for ``p`` points of an ``n``-joint robot."""
        return cls(np.zeros((p, n)), np.zeros(p, dtype=np.int64), np.zeros(p), np.zeros(p), {})

    def first(self, count: int) -> _Record:
        """The record of the first ``count`` points (views, same reasons)."""
        return _Record(self.Q[:count], self.ITER[:count], self.ERR[:count],
                       self.TIMES[:count], self.reasons)


def track(
    robot,
    path: Path,
    solver: str | MultiTaskResolver | QPResolver = "dls",
    *,
    q0: object = None,
    obstacles: tuple = (),
    link_radius: float = 0.0,
    tolerance: float = 5e-3,
    on_unreachable: str = "continue",
    damping: float = 0.02,
    tol: float = 1e-6,
    max_iter: int = 500,
    max_step: float = 0.5,
    ik_options: Mapping[str, Any] | None = None,
    max_joint_step: float | None = None,
    acm: object = None,
    srdf: object = None,
    skip_links: Iterable[str] = (),
) -> Trajectory:
    """Track a path and record the trajectory.

    Args:
        robot: the robot.
        path: a :class:`~serialkin.tracking.path.Path`.
        solver: 'dls' (eq 46 corrected, compiled; joints projected onto their limits
            after every step), 'multitask' (eq 48 with default
            weights and the given obstacles), a ``MultiTaskResolver``, 'qp' (the
            differential-IK QP with hard limits and collision constraints, default
            settings, the given obstacles), a ``QPResolver``, or an IK method name of
            :func:`serialkin.ik.solve`.
        q0: start configuration (n,); default zeros (the chapter's q0 = 0).
        obstacles: obstacles for clearance reporting (and for ``'multitask'``); a
            resolver's own obstacles are used when this is empty.
        link_radius: link capsule radius for clearances [m].
        tolerance: acceptance tolerance: a point is reached when its error ≤ this [m].
        on_unreachable: 'continue' (report and go on from the best configuration) or
            'stop' (report and stop; the trajectory keeps what was computed).
        damping: λ of DLS [m].
        tol: convergence tolerance of the iterations [m] (below ``tolerance``).
        max_iter: iteration budget per point (DLS and IK; a resolver keeps its own).
        max_step: cap on the joint step per DLS iteration [rad].
        ik_options: extra keyword arguments for ``robot.ik`` (IK methods only).
        max_joint_step: report every point where a joint moved by more than this since
            the previous point [rad or m] (``Trajectory.jumps``); with ``'qp'`` it is also
            a hard bound of the QP. None: no check.
        acm: :class:`~serialkin.collision.acm.AllowedCollisionMatrix` over the bodies of
            ``robot.collision``: the pairs the solver's self-collision check skips (a
            ``QPResolver`` with ``self_collision=True``; see the module docstring).
            None: the resolver's own (by default the model's
            :func:`~serialkin.collision.acm.default_acm`).
        srdf: an SRDF (file path, XML text or :class:`~serialkin.collision.srdf.Srdf`)
            whose ``<disable_collisions>`` pairs are added to the model's default matrix
            (:func:`serialkin.collision.robot_acm`); not together with ``acm``.
        skip_links: links of the SRDF without a body in the collision model (fingers off
            the chain, a TCP frame): pairs naming them are skipped. Needs ``srdf``.

    Returns:
        :class:`~serialkin.tracking.trajectory.Trajectory`.

    Raises:
        InputError: bad q0, negative tolerances, unknown ``on_unreachable``, obstacles
            overlapping the base; ``acm`` or ``srdf`` with a solver that checks no
            self-collision, on a robot without a collision model, or both given;
            ``skip_links`` without ``srdf``; an ``srdf`` file that does not exist.
        RobotDefinitionError: an unreadable SRDF, or one naming a link that is neither a
            body of the model nor in ``skip_links`` (the message starts with ``srdf``).
        InputTypeError: path is not a Path; ``acm`` is not an AllowedCollisionMatrix;
            ``srdf`` is not a path, text or Srdf.
    """
    s = _track_settings(robot, path, solver, q0=q0, obstacles=obstacles,
                        link_radius=link_radius, tolerance=tolerance,
                        on_unreachable=on_unreachable, damping=damping, tol=tol,
                        max_iter=max_iter, max_step=max_step, max_joint_step=max_joint_step,
                        acm=acm, srdf=srdf, skip_links=skip_links)
    rec = _Record.empty(len(path), robot.n)
    targets = np.ascontiguousarray(path.targets)
    if isinstance(solver, str) and solver == "dls":
        label, count = _run_dls(robot, targets, s, rec)
    else:
        label, step = _solver_step(robot, path, solver, targets, s, ik_options)
        count = _run_steps(step, len(path), s, rec)
    stopped = s.stop and count > 0 and rec.ERR[count - 1] > s.accept
    return _assemble(robot, path, s, rec.first(count), label, stopped)


def _track_settings(robot, path: Path, solver: object, *, q0: object, obstacles: tuple,
                    link_radius: float, tolerance: float, on_unreachable: str, damping: float,
                    tol: float, max_iter: int, max_step: float,
                    max_joint_step: float | None, acm: object = None, srdf: object = None,
                    skip_links: Iterable[str] = ()) -> _TrackSettings:
    """Check the arguments of :func:`track` (same names) and gather them; raises as it does."""
    if not isinstance(path, Path):
        raise InputTypeError(f"path must be a serialkin.tracking.Path, got {type(path).__name__}")
    check_choice(on_unreachable, "on_unreachable", ON_UNREACHABLE)
    accept = check_positive(tolerance, "tolerance")
    conv = check_positive(tol, "tol")
    lam = check_positive(damping, "damping")
    budget = check_int(max_iter, "max_iter", minimum=1, maximum=MAX_ITERATIONS)
    cap = check_positive(max_step, "max_step")
    check_positive(link_radius, "link_radius", allow_zero=True)
    q_start = (np.zeros(robot.n) if q0 is None
               else np.array(robot.check_q(q0, "q0"), dtype=float))
    if q_start.shape != (robot.n,):
        raise InputError(f"q0 must have shape ({robot.n},), got {q_start.shape}")
    rows = task_rows(path.task)
    jump = None if max_joint_step is None else check_positive(max_joint_step, "max_joint_step")
    if isinstance(solver, (MultiTaskResolver, QPResolver)) and not obstacles:
        obstacles = solver.obstacles
    obstacles = tuple(obstacles)
    encode_obstacles(obstacles)
    check_obstacles(robot, obstacles, link_radius=link_radius)
    allowed = _self_collision_acm(robot, solver, acm, srdf, skip_links)
    return _TrackSettings(q_start, rows, obstacles, link_radius, accept, conv, lam, budget, cap,
                          jump, on_unreachable == "stop", allowed)


def _link_names(skip_links: object) -> tuple[str, ...]:
    """``skip_links`` as a tuple of link names; InputTypeError for anything else."""
    if isinstance(skip_links, str | bytes) or not isinstance(skip_links, Iterable):
        raise InputTypeError(f"skip_links must be a list of link names, got "
                             f"{type(skip_links).__name__} {short_repr(skip_links)}")
    names = tuple(skip_links)
    for i, x in enumerate(names):
        if not isinstance(x, str):
            raise InputTypeError(f"skip_links[{i}] must be a link name (str), got "
                                 f"{type(x).__name__} {short_repr(x)}")
    return names


def _check_srdf_source(srdf: object) -> None:
    """Refuse an ``srdf`` that is not an Srdf, XML text or an existing file, naming it."""
    from serialkin.collision.srdf import Srdf

    if isinstance(srdf, Srdf):
        return
    if not isinstance(srdf, str | os.PathLike):
        raise InputTypeError(f"srdf must be an SRDF file path, SRDF XML text or a "
                             f"serialkin.collision.Srdf, got {type(srdf).__name__} "
                             f"{short_repr(srdf)}")
    text = os.fsdecode(srdf)
    if not text.lstrip().startswith("<") and not os.path.isfile(text):
        raise InputError(f"srdf must be an SRDF file or SRDF XML text, got "
                         f"{short_repr(text)}: no such file")


def _self_collision_acm(robot, solver: object, acm: object, srdf: object,
                        skip_links: object) -> Any:
    """The allowed-collision matrix of :func:`track`'s ``acm`` / ``srdf`` / ``skip_links``.

    None when neither ``acm`` nor ``srdf`` is given (the resolver keeps its own matrix);
    else ``acm``, or :func:`serialkin.collision.robot_acm` of the SRDF (the model's
    default matrix with the SRDF's disabled pairs added). Raises as :func:`track` says.
    """
    from serialkin.collision.acm import check_acm
    from serialkin.collision.checks import robot_acm

    skip = _link_names(skip_links)
    if skip and srdf is None:
        raise InputError("skip_links names links of an SRDF: give srdf too")
    if acm is None and srdf is None:
        return None
    if acm is not None and srdf is not None:
        raise InputError("give acm or srdf, not both (serialkin.collision.acm_from_srdf("
                         "model, srdf, acm) combines them)")
    name = "acm" if acm is not None else "srdf"
    if not (isinstance(solver, QPResolver) and solver.self_collision):
        what = (f"solver {solver!r}" if isinstance(solver, str)
                else f"this {type(solver).__name__}")
        raise InputError(f"{name} lists the body pairs a self-collision check skips, but "
                         f"{what} checks no self-collision: use "
                         "solver=QPResolver(task=..., self_collision=True)")
    if solver.acm is not None:
        raise InputError(f"{name} is given to track and the QPResolver has its own acm: "
                         "give the allowed pairs once")
    model = getattr(robot, "collision", None)
    if model is None:
        raise InputError(f"{name} names bodies of a collision model, but robot "
                         f"{short_repr(robot.name)} has none (its self-collision check keeps "
                         "the chain's link segments apart, which an SRDF cannot name); give "
                         "it one with robot.with_collision(model) or robot.fit_collision()")
    if check_acm(acm) is not None:
        if tuple(acm.body_names) != tuple(model.body_names):
            raise InputError(f"acm must be over the bodies of robot {short_repr(robot.name)}'s "
                             f"collision model {short_repr(list(model.body_names))}, got "
                             f"{short_repr(list(acm.body_names))}")
        return acm
    _check_srdf_source(srdf)
    try:
        return robot_acm(robot, srdf=srdf, skip_links=skip)
    except RobotDefinitionError as exc:  # unreadable XML, or a link that is not a body
        raise RobotDefinitionError(f"srdf: {exc}") from exc


def _run_dls(robot, targets: np.ndarray, s: _TrackSettings, rec: _Record) -> tuple[str, int]:
    """Track ``targets`` (p, 4, 4) with the compiled DLS loop; (solver label, points computed)."""
    label = f"DLS (eq 46), λ = {s.lam:g} m"
    t0 = time.perf_counter()
    revolute = robot.revolute.astype(float)
    count = dls_track(s.q_start, targets, s.rows, robot.chain.F, robot.chain.meta, s.lam, s.conv,
                      s.budget, s.cap, s.accept, s.stop, 1e-3,
                      np.ascontiguousarray(robot.qlim[:, 0]),
                      np.ascontiguousarray(robot.qlim[:, 1]), revolute, rec.Q, rec.ITER, rec.ERR)
    elapsed = time.perf_counter() - t0
    # per-point time: shared in proportion to the iterations used
    its = rec.ITER[:count].astype(float) + 1.0
    rec.TIMES[:count] = elapsed * its / its.sum()
    return label, count


def _check_resolver_task(solver: MultiTaskResolver | QPResolver, path: Path,
                         rows: np.ndarray) -> None:
    """Raise InputError when the resolver's task rows are not the path's."""
    if list(task_rows(solver.task)) != list(rows):
        raise InputError(f"the resolver's task {solver.task!r} does not match the "
                         f"path's task {path.task!r}")


def _solver_step(robot, path: Path, solver: object, targets: np.ndarray, s: _TrackSettings,
                 ik_options: Mapping[str, Any] | None) -> tuple[str, Callable]:
    """The label and the per-point step ``step(k, q) -> result`` of a solver other than 'dls'.

    The result has ``q``, ``iterations``, ``error`` and, optionally, ``reason``.
    """
    if isinstance(solver, str) and solver == "multitask":
        solver = MultiTaskResolver(task=path.task, obstacles=s.obstacles,
                                   link_radius=s.link_radius, max_iter=s.budget, tol=s.conv)
    if isinstance(solver, str) and solver == "qp":
        solver = QPResolver(task=path.task, obstacles=s.obstacles, link_radius=s.link_radius,
                            max_iter=s.budget, tol=s.conv, max_joint_step=s.jump)
    if isinstance(solver, QPResolver):
        _check_resolver_task(solver, path, s.rows)
        if s.jump is not None and solver.max_joint_step is None:
            solver = solver.with_options(max_joint_step=s.jump)
        if s.acm is not None:
            solver = solver.with_options(acm=s.acm)
        qstate = solver.prepare(robot)
        return ("differential-IK QP (hard limits and collision constraints)",
                lambda k, q: qstate.solve(targets[k], q))
    if isinstance(solver, MultiTaskResolver):
        _check_resolver_task(solver, path, s.rows)
        state = solver.prepare(robot)
        return "multi-task resolution (eq 48)", lambda k, q: state.solve(targets[k], q)
    if isinstance(solver, str):
        if ik_options is not None and (not isinstance(ik_options, Mapping) or not all(
                isinstance(k, str) for k in ik_options)):
            raise InputTypeError("ik_options must be a mapping of robot.ik option names "
                                 f"(str) to values, got {short_repr(ik_options, 80)}")
        opts = dict(ik_options or {})
        opts.setdefault("max_iter", s.budget)
        opts.setdefault("tol", s.conv)
        return f"IK method {solver!r}", _ik_step(robot, path, solver, opts)
    raise InputTypeError("solver must be 'dls', 'multitask', 'qp', an IK method name, "
                         f"a MultiTaskResolver or a QPResolver, got "
                         f"{type(solver).__name__}")


def _run_steps(step: Callable, p: int, s: _TrackSettings, rec: _Record) -> int:
    """Run ``step`` point by point from ``s.q_start``, timing each; the points computed."""
    q = s.q_start.copy()
    count = 0
    for k in range(p):
        t0 = time.perf_counter()
        res = step(k, q)
        rec.TIMES[k] = time.perf_counter() - t0
        q = np.array(res.q, dtype=float)
        rec.Q[k] = q
        rec.ITER[k] = res.iterations
        rec.ERR[k] = res.error
        reason = getattr(res, "reason", "")
        if reason:
            rec.reasons[k] = reason
        count = k + 1
        if s.stop and res.error > s.accept:
            break
    return count


class _IKStats:
    def __init__(self, q: np.ndarray, iterations: int, error: float) -> None:
        self.q, self.iterations, self.error = q, iterations, error


def _ik_step(robot, path: Path, method: str, opts: dict):
    rows = task_rows(path.task)
    J = np.empty((6, robot.n))
    T = np.empty((4, 4))
    e6 = np.empty(6)

    def step(k: int, q: np.ndarray) -> _IKStats:
        res = robot.ik(_ik_target(path, k), method=method, q0=q, **opts)
        qn = np.ascontiguousarray(res.q, dtype=float)
        K.jacobian_into(qn, robot.chain.F, robot.chain.meta, J, T)
        pose_error_into(T, path.targets[k], e6)
        return _IKStats(qn, int(getattr(res, "iterations", 0)),
                        float(np.linalg.norm(e6[rows])))

    return step


def joint_jumps(q_start: np.ndarray, Q: np.ndarray, threshold: float) -> list[JointJump]:
    """Every point k where some joint moved by more than ``threshold`` since point k − 1.

    Point 0 is compared with the start configuration. Returns one
    :class:`~serialkin.tracking.trajectory.JointJump` per such point (its largest move).
    """
    if not Q.shape[0]:
        return []
    prev = np.vstack([q_start[None, :], Q[:-1]])
    d = np.abs(Q - prev)
    out = []
    for k in np.flatnonzero(d.max(axis=1) > threshold * (1.0 + 1e-9) + 1e-12):  # float noise
        j = int(np.argmax(d[k]))
        out.append(JointJump(int(k), j, float(Q[k, j] - prev[k, j])))
    return out


def _assemble(robot, path: Path, s: _TrackSettings, rec: _Record, label: str,
              stopped: bool) -> Trajectory:
    """The :class:`Trajectory` of the points recorded in ``rec`` under the settings ``s``.

    Poses by FK, clearances to ``s.obstacles`` (minimum over the links, [m]), joint-limit
    margins, failures with their reasons, and the joint jumps beyond ``s.jump``.
    """
    Q, ITER, ERR, TIMES = rec.Q, rec.ITER, rec.ERR, rec.TIMES
    obstacles, accept = s.obstacles, s.accept
    count = Q.shape[0]
    poses = np.empty((count, 4, 4))
    for k in range(count):  # serial: the parallel batch kernel costs ms of thread start-up
        K.fk_into(np.ascontiguousarray(Q[k]), robot.chain.F, robot.chain.meta, poses[k])
    if obstacles and count:
        g = ObstacleGeometry(robot, obstacles, s.link_radius)
        clear = np.empty((count, len(obstacles)))
        for k in range(count):
            g.update(np.ascontiguousarray(Q[k]))
            clear[k] = g.C.min(axis=0)
    else:
        clear = np.zeros((count, len(obstacles)))
    margin = limit_margins(Q, np.asarray(robot.qlim, dtype=float))
    reached = ERR <= accept
    reasons = rec.reasons
    failures = [PathFailure(int(k), float(ERR[k]), tuple(float(v) for v in path.points[k]),
                            reasons.get(int(k), ""))
                for k in np.flatnonzero(~reached)]
    # solver failures at points that were still reached (e.g. an infeasible QP at a point
    # the robot already sat on): one note per distinct reason, never silent
    notes: dict[str, list[int]] = {}
    for k, why in sorted(reasons.items()):
        if reached[k] and not why.startswith("no progress"):
            notes.setdefault(why, []).append(k)
    note_text = [f"{why} at {len(ks)} reached path point(s), first at point {ks[0]}"
                 for why, ks in notes.items()]
    return Trajectory(
        q=Q, poses=poses, targets=np.array(path.targets[:count]), errors=ERR,
        iterations=ITER, reached=reached, clearance=clear, limit_margin=margin, times=TIMES,
        task=path.task, tolerance=accept, joint_names=tuple(robot.joint_names),
        obstacle_names=tuple(o.name or f"obstacle{i + 1}" for i, o in enumerate(obstacles)),
        failures=failures, stopped=bool(stopped), path_length=len(path), solver=label,
        jumps=[] if s.jump is None else joint_jumps(s.q_start, Q, s.jump), notes=note_text)
