"""Weighted multi-task redundancy resolution (eqs 47-50, corrected by the ERRATA).

The joint velocity minimises the weighted cost of eq 47,

``H = ‖J q̇ − ẋ‖²_W + ‖J_c q̇ − x_c‖²_Wc + ‖J_L q̇ − x_L‖²_WL + ‖q̇‖²_Ws``,

whose minimiser is eq 48 (the 20-link algorithm's step 6 prints ``J⁻¹`` where ``Jᵀ`` is
meant; the ERRATA restores eq 48):

``q̇ = (JᵀWJ + J_cᵀW_cJ_c + J_LᵀW_LJ_L + W_s)⁻¹ (JᵀWẋ + J_cᵀW_c x_c + J_LᵀW_L x_L)``.

* Primary task: ``J`` the task rows of the geometric Jacobian, ``W = weight·I``.
* Obstacle task: one row ``J_ci = −u_iᵀ J_sci`` (eqs 51-56) per link/obstacle pair closer
  than the obstacle's influence distance, weighted by ``obstacle_weight · g(c)`` with
  ``g`` the smoothstep from 0 at the influence distance to 1 at contact (and 1 beyond).
* Joint-limit task: ``J_L = I`` on limited joints (eq 50: ``W_L = diag(W_Li)``) with the
  weight function of eq 49, which the chapter describes but does not print. Designed per
  the ERRATA (:func:`joint_limit_weights`): 0 inside the range, a C¹ smoothstep growth
  across a buffer of ``limit_buffer`` × range next to each limit, and the maximum
  ``joint_limit_weight`` at and beyond the limit.
* Singularity task: ``W_s = (λ_min² + λ_s²) I`` with the variable damping of Nakamura &
  Hanafusa, ``λ_s = singularity_damping · (1 − w/w₀)`` when the task manipulability
  ``w < w₀ = manipulability_threshold``, else 0. ``λ_min = damping`` keeps the matrix
  invertible (JᵀWJ has rank m < n).

Faithful mode (the chapter's eq 48): ``x_c = x_L = 0``, so motion towards an obstacle or
a limit is damped, never reversed. With ``repulsive_gain > 0`` the targets become
``x_c,i = −k (d_infl − c_i)`` (retreat at a rate growing with the intrusion into the
influence zone) and ``x_L,i = k · (distance into the buffer, signed towards mid-range)``.
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass, field, replace

import numpy as np

from serialkin._checks import (
    MAX_ITERATIONS,
    as_float_array,
    check_int,
    check_positive,
    check_transform,
    readonly,
    short_repr,
)
from serialkin.errors import InputError
from serialkin.kinematics import kernels as K
from serialkin.kinematics.dls import manipulability_of, spd_solve_into
from serialkin.model.geometry import Capsule, Cylinder, Sphere
from serialkin.model.limits import check_interval
from serialkin.redundancy.objectives import task_rows
from serialkin.redundancy.obstacles import (
    ObstacleGeometry,
    accumulate_obstacle_task,
    check_obstacles,
    encode_obstacles,
    update_geometry_into,
)
from serialkin.spatial.kernels import pose_error_into

from .._jit import njit_exact

__all__ = [
    "MultiTaskResolver",
    "SolveStats",
    "eq48_into",
    "joint_limit_repulsion",
    "joint_limit_weights",
    "multitask_solve_into",
    "smoothstep",
]


def smoothstep(s: np.ndarray | float) -> np.ndarray:
    """C¹ ramp ``3s² − 2s³`` of s clipped to [0, 1]: 0 at s ≤ 0, 1 at s ≥ 1."""
    x = np.clip(s, 0.0, 1.0)
    return x * x * (3.0 - 2.0 * x)


#: Range [rad or m] whose buffer a joint open on one side gets at its finite end (eq 49).
ONE_SIDED_RANGE = 2.0 * math.pi


@njit_exact(cache=True)
def _limit_weight_and_push(q, lo, hi, buffer, max_weight):
    """Eq 49 weight of one joint and its signed depth into the buffer (towards mid-range).

    Limits are intervals whose ends may be infinite (:mod:`serialkin.model.limits`):
    an unlimited joint gets (0, 0); a joint open on one side gets, at its finite end, the
    buffer of a range :data:`ONE_SIDED_RANGE` wide.
    """
    lo_f = math.isfinite(lo)
    hi_f = math.isfinite(hi)
    if not (lo_f or hi_f):
        return 0.0, 0.0
    width = buffer * ((hi - lo) if lo_f and hi_f else ONE_SIDED_RANGE)
    if width <= 0.0:  # a fixed joint (lo == hi): always at its limit, nothing to push
        return max_weight, 0.0
    s = 0.0
    push = 0.0
    if lo_f:
        s = max(s, (lo + width - q) / width)
        push += max(lo + width - q, 0.0)
    if hi_f:
        s = max(s, (q - (hi - width)) / width)
        push -= max(q - (hi - width), 0.0)
    s = 1.0 if q <= lo or q >= hi else min(max(s, 0.0), 1.0)  # exactly the max at the limit
    w = max_weight * s * s * (3.0 - 2.0 * s)
    return w, push


def _check_buffer(buffer: float) -> float:
    b = float(buffer)
    if not 0.0 < b <= 0.5:
        raise InputError(f"buffer must be in (0, 0.5], got {buffer!r}")
    return b


def joint_limit_weights(q: object, qlim: object, *, buffer: float = 0.1,
                        max_weight: float = 1.0) -> np.ndarray:
    """The joint-limit weight function of eq 49 (designed per the ERRATA), shape (n,).

    With range ``r_i = q_M,i − q_m,i`` and buffer width ``b_i = buffer · r_i``:

    * ``W_Li = 0`` for ``q_m + b ≤ q ≤ q_M − b`` (well inside the range),
    * ``W_Li = max_weight · smoothstep((q_m + b − q)/b)`` in the lower buffer (and
      symmetrically in the upper one), ``smoothstep(s) = 3s² − 2s³``: continuous (C¹),
      growing towards the limit,
    * ``W_Li = max_weight`` at and beyond the limit.

    Unlimited joints get 0; a joint open on one side gets the buffer of a 2π-wide range
    at its finite end.

    Args:
        q: joint values (n,).
        qlim: limits (n, 2).
        buffer: buffer width as a fraction of the range, in (0, 0.5].
        max_weight: weight at and beyond the limit (≥ 0).
    """
    qv = np.asarray(q, dtype=float).reshape(-1)
    lim = np.asarray(qlim, dtype=float).reshape(-1, 2)
    b = _check_buffer(buffer)
    wmax = check_positive(max_weight, "max_weight", allow_zero=True)
    return np.array([_limit_weight_and_push(qv[i], lim[i, 0], lim[i, 1], b, wmax)[0]
                     for i in range(qv.shape[0])])


def joint_limit_repulsion(q: object, qlim: object, *, buffer: float = 0.1) -> np.ndarray:
    """Signed depth of each joint inside its limit buffer, towards mid-range, (n,) [rad/m].

    ``+(q_m + b − q)`` in the lower buffer (or beyond), ``−(q − (q_M − b))`` in the upper one,
    0 elsewhere; the optional repulsive target ``x_L`` is this times a gain.
    """
    qv = np.asarray(q, dtype=float).reshape(-1)
    lim = np.asarray(qlim, dtype=float).reshape(-1, 2)
    b = _check_buffer(buffer)
    return np.array([_limit_weight_and_push(qv[i], lim[i, 0], lim[i, 1], b, 1.0)[1]
                     for i in range(qv.shape[0])])


# settings vector of the compiled kernels
_W, _DAMP, _SING, _W0, _WL, _BUF, _WC, _KREP, _GAIN, _MAXX, _MAXQ, _TOL, _ITER = range(13)
_LINKR, _USE_LIM, _USE_OBS, _HAS_TOOL = 13, 14, 15, 16


@njit_exact(cache=True)
def eq48_into(q, xdot, J, rows, F, L, meta, cfg, qlim, enc, influence, link, frames, P0, P1, Tee,
              T, SC, B, D, C, Jbuf, pbuf, A, rhs, qdot):
    """Eq 48 (corrected): ``q̇ = (JᵀWJ + J_cᵀW_cJ_c + J_LᵀW_LJ_L + W_s)⁻¹(JᵀWẋ + …)``.

    Args:
        q: (n,) joint values.
        xdot: (m,) primary task velocity.
        J: (6, n) geometric Jacobian at q (only ``rows`` are used).
        rows: (m,) task rows.
        F: chain fixed transforms.
        L: chain link-frame offsets.
        meta: chain joint data.
        cfg: settings vector (see :class:`MultiTaskResolver`).
        qlim: (n, 2) joint limits of the joint-limit task.
        enc: (k, 8) encoded obstacles.
        influence: (k,) influence distances [m].
        link: (s,) link frame of each segment.
        frames: (n+1, 4, 4) buffer.
        P0: (s, 3) buffer.
        P1: (s, 3) buffer.
        Tee: (4, 4) buffer.
        T: (s, k) buffer.
        SC: (s, k, 3) buffer.
        B: (s, k, 3) buffer.
        D: (s, k) buffer.
        C: (s, k) buffer (clearances at q on return).
        Jbuf: (6, n) buffer.
        pbuf: (3,) buffer.
        A: (n, n) buffer.
        rhs: (n,) buffer.
        qdot: (n,) output.
    """
    n = q.shape[0]
    m = rows.shape[0]
    w = cfg[_W]
    for a in range(n):
        s = 0.0
        for r in range(m):
            s += J[rows[r], a] * xdot[r]
        rhs[a] = w * s
        for b in range(n):
            s = 0.0
            for r in range(m):
                s += J[rows[r], a] * J[rows[r], b]
            A[a, b] = w * s
    lam2 = cfg[_DAMP] * cfg[_DAMP]
    if cfg[_SING] > 0.0 and cfg[_W0] > 0.0:
        Jt = np.empty((m, n))
        for r in range(m):
            for a in range(n):
                Jt[r, a] = J[rows[r], a]
        wm = manipulability_of(Jt)
        if wm < cfg[_W0]:
            ls = cfg[_SING] * (1.0 - wm / cfg[_W0])
            lam2 += ls * ls
    for a in range(n):
        A[a, a] += lam2
    if cfg[_USE_LIM] > 0.0:
        for a in range(n):
            wl, push = _limit_weight_and_push(q[a], qlim[a, 0], qlim[a, 1], cfg[_BUF], cfg[_WL])
            A[a, a] += wl
            if cfg[_KREP] > 0.0:
                rhs[a] += wl * cfg[_KREP] * push
    if cfg[_USE_OBS] > 0.0:
        update_geometry_into(q, F, L, meta, cfg[_HAS_TOOL] > 0.0, enc, cfg[_LINKR], frames, P0,
                             P1, Tee, T, SC, B, D, C)
        accumulate_obstacle_task(q, F, L, meta, frames, P0, P1, link, T, SC, B, D, C, influence,
                                 cfg[_WC], cfg[_KREP], A, rhs, Jbuf, pbuf)
    # SPD: damping > 0 is validated by MultiTaskResolver, the other terms are PSD
    spd_solve_into(A, rhs, qdot, n)


@njit_exact(cache=True)
def multitask_solve_into(q, target, rows, F, L, meta, cfg, qlim, enc, influence, link, frames,
                         P0, P1, Tee, T, SC, B, D, C, Jbuf, pbuf, A, rhs, qdot, J, Tpose, e6):
    """Iterate eq 48 towards ``target`` (4, 4) from ``q`` (updated in place).

    Each iteration: ẋ = gain·(x_d − x) with ‖ẋ‖ capped, q̇ from :func:`eq48_into` with
    ‖q̇‖ capped, q ← q + q̇ (dt = 1). Stops when ‖x_d − x‖ < tol, after max_iter
    iterations or when the step vanishes (a compromise between the tasks). Buffers as in
    :func:`eq48_into`; ``J`` (6, n), ``Tpose`` (4, 4), ``e6`` (6,).

    Returns:
        (iterations, final error norm).
    """
    n = q.shape[0]
    m = rows.shape[0]
    xdot = np.empty(m)
    it = 0
    max_iter = int(cfg[_ITER])
    while True:
        K.jacobian_into(q, F, meta, J, Tpose)
        pose_error_into(Tpose, target, e6)
        err2 = 0.0
        for r in range(m):
            err2 += e6[rows[r]] * e6[rows[r]]
        err = math.sqrt(err2)
        if err < cfg[_TOL] or it >= max_iter:
            return it, err
        scale = cfg[_GAIN]
        if scale * err > cfg[_MAXX]:
            scale = cfg[_MAXX] / err
        for r in range(m):
            xdot[r] = scale * e6[rows[r]]
        eq48_into(q, xdot, J, rows, F, L, meta, cfg, qlim, enc, influence, link, frames, P0, P1,
                  Tee, T, SC, B, D, C, Jbuf, pbuf, A, rhs, qdot)
        nq = 0.0
        for a in range(n):
            nq += qdot[a] * qdot[a]
        nq = math.sqrt(nq)
        f = 1.0 if nq <= cfg[_MAXQ] else cfg[_MAXQ] / nq
        for a in range(n):
            q[a] += f * qdot[a]
        it += 1
        if nq < 1e-12:
            K.jacobian_into(q, F, meta, J, Tpose)
            pose_error_into(Tpose, target, e6)
            err2 = 0.0
            for r in range(m):
                err2 += e6[rows[r]] * e6[rows[r]]
            return it, math.sqrt(err2)


@dataclass(frozen=True)
class SolveStats:
    """Outcome of :meth:`MultiTaskResolver.solve` for one target.

    Attributes:
        q: final joint values (n,).
        iterations: iterations used.
        error: final task error norm [m or mixed].
        converged: error below the tolerance.
    """

    q: np.ndarray
    iterations: int
    error: float
    converged: bool


def _weight(value: object, name: str) -> float:
    return check_positive(value, name, allow_zero=True)


@dataclass(frozen=True)
class MultiTaskResolver:
    """Weighted multi-task inverse kinematics (eq 48, corrected) with settings.

    Attributes:
        task: primary task rows ('planar', 'position', 'planar_pose', 'pose' or indices).
        weight: W, primary-task weight (scalar, ≥ 0) [1].
        obstacles: obstacles (:class:`~serialkin.model.geometry.Cylinder` infinite along
            z, ``Sphere``, ``Capsule``); each carries its influence distance.
        obstacle_weight: maximum W_c (at contact) [1].
        link_radius: links modelled as capsules of this radius [m].
        joint_limit_weight: maximum W_L of eq 49 [1]; 0 disables the joint-limit task.
        limit_buffer: buffer of eq 49 as a fraction of each joint's range.
        joint_limits: (n, 2) limits for the task; None uses the robot's ``qlim``.
        damping: λ_min, constant part of W_s [task units].
        singularity_damping: λ_s at a singularity (0 disables the singularity task).
        manipulability_threshold: w₀ below which the singularity damping grows.
        repulsive_gain: k of the optional repulsive targets; 0 = the chapter's x_c = x_L = 0.
        gain: ẋ = gain · (x_d − x) per iteration (dt = 1).
        max_task_step: cap on ‖ẋ‖ per iteration [m] (keeps each step in the linear regime).
        max_step: cap on ‖q̇‖ per iteration [rad].
        tol: convergence tolerance on the task error [m].
        max_iter: iteration budget per target.
    """

    task: str | Sequence[int] = "planar"
    weight: float = 1.0
    obstacles: tuple = field(default_factory=tuple)
    obstacle_weight: float = 100.0
    link_radius: float = 0.0
    joint_limit_weight: float = 100.0
    limit_buffer: float = 0.1
    joint_limits: object = None
    damping: float = 1e-3
    singularity_damping: float = 0.0
    manipulability_threshold: float = 0.0
    repulsive_gain: float = 0.0
    gain: float = 1.0
    max_task_step: float = 0.01
    max_step: float = 0.2
    tol: float = 1e-5
    max_iter: int = 500

    def __post_init__(self) -> None:
        task_rows(self.task)
        for name in ("weight", "obstacle_weight", "link_radius", "joint_limit_weight",
                     "singularity_damping", "manipulability_threshold", "repulsive_gain"):
            object.__setattr__(self, name, _weight(getattr(self, name), name))
        for name in ("damping", "gain", "max_task_step", "max_step", "tol"):
            object.__setattr__(self, name, check_positive(getattr(self, name), name))
        buffer = check_positive(self.limit_buffer, "limit_buffer")
        if buffer > 0.5:
            raise InputError(f"limit_buffer must be in (0, 0.5], got {buffer:g}")
        object.__setattr__(self, "limit_buffer", buffer)
        check_int(self.max_iter, "max_iter", minimum=1, maximum=MAX_ITERATIONS)
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

    def with_options(self, **changes: object) -> MultiTaskResolver:
        """A copy with some settings changed (validated again)."""
        return replace(self, **changes)

    # ------------------------------------------------------------------ set-up
    def _limits(self, robot) -> np.ndarray:
        if self.joint_limits is None:
            return np.asarray(robot.qlim, dtype=float)
        if isinstance(self.joint_limits, (str, bytes)):
            raise InputError(f"joint_limits must be ({robot.n}, 2) numbers, got "
                             f"{short_repr(self.joint_limits)}")
        try:
            lim = np.asarray(self.joint_limits, dtype=float)
        except (TypeError, ValueError, OverflowError) as exc:
            raise InputError(f"joint_limits must be ({robot.n}, 2) numbers, got "
                             f"{short_repr(self.joint_limits)}") from exc
        if lim.shape != (robot.n, 2):
            raise InputError(f"joint_limits must have shape ({robot.n}, 2), got {lim.shape}")
        return np.array([check_interval(row, f"joint_limits[{i}]") for i, row in enumerate(lim)])

    def prepare(self, robot) -> _State:
        """Buffers and checks for one robot (obstacles overlapping the base raise)."""
        check_obstacles(robot, self.obstacles, link_radius=self.link_radius)
        return _State(self, robot)

    def velocity(self, robot, q: object, xdot: object) -> np.ndarray:
        """One evaluation of eq 48: the joint velocity (n,) for a task velocity ẋ (m,)."""
        st = self.prepare(robot)
        qv = np.ascontiguousarray(robot.check_q(q), dtype=float)
        xd = as_float_array(xdot, "xdot", ndim=1)
        if xd.shape[0] != st.rows.size:
            raise InputError(f"xdot must have {st.rows.size} values, got {xd.shape[0]}")
        return st.qdot(qv, xd)

    def solve(self, robot, target: np.ndarray, q0: object, *, state: _State | None = None
              ) -> SolveStats:
        """Iterate eq 48 towards one target pose (4, 4) from q0 ("CYCLE WHILE 2").

        Each iteration: ẋ = gain·(x_d − x) (norm capped), q ← q + q̇ (dt = 1). Stops when the
        task error is below ``tol``, after ``max_iter`` iterations, or when the step
        becomes negligible (a compromise between the tasks).

        Raises:
            InputError: ``target`` not a finite (4, 4) rigid transform, ``q0`` not (n,)
                finite values.
        """
        T = check_transform(target, "target")
        if T.shape != (4, 4):
            raise InputError(f"target must be one (4, 4) pose, got shape {T.shape}")
        q = robot.check_q(q0, "q0")
        if q.ndim != 1:
            raise InputError(f"q0 must have shape ({robot.n},), got {q.shape}")
        st = state if state is not None else self.prepare(robot)
        # the target read-only, as tracking passes its path's: the kernels compile once
        return st.solve(readonly(np.ascontiguousarray(T, dtype=float)),
                        np.array(q, dtype=float, order="C"))


class _State:
    """Per-robot buffers of a :class:`MultiTaskResolver` for the compiled kernels."""

    def __init__(self, res: MultiTaskResolver, robot) -> None:
        self.res = res
        self.robot = robot
        self.rows = task_rows(res.task)
        n = robot.n
        self.lim = np.ascontiguousarray(res._limits(robot), dtype=float)
        use_limits = res.joint_limit_weight > 0 and bool(np.isfinite(self.lim).any())
        self.geom = ObstacleGeometry(robot, res.obstacles, res.link_radius)
        self.infl = np.array([o.influence for o in res.obstacles], dtype=float)
        cfg = np.zeros(17)
        cfg[[_W, _DAMP, _SING, _W0, _WL, _BUF, _WC, _KREP, _GAIN, _MAXX, _MAXQ, _TOL, _ITER,
             _LINKR]] = [res.weight, res.damping, res.singularity_damping,
                         res.manipulability_threshold, res.joint_limit_weight,
                         float(res.limit_buffer), res.obstacle_weight, res.repulsive_gain,
                         res.gain, res.max_task_step, res.max_step, res.tol, res.max_iter,
                         res.link_radius]
        cfg[_USE_LIM] = float(use_limits)
        cfg[_USE_OBS] = float(len(res.obstacles) > 0)
        cfg[_HAS_TOOL] = float(self.geom.has_tool)
        self.cfg = cfg
        self.A = np.empty((n, n))
        self.rhs = np.empty(n)
        self.qdot_buf = np.empty(n)
        self.J = np.empty((6, n))
        self.T = np.empty((4, 4))
        self.e6 = np.empty(6)

    def _args(self):
        g = self.geom
        rb = self.robot
        return (rb.chain.F, rb.chain.L, rb.chain.meta, self.cfg, self.lim, g.enc, self.infl, g.link,
                g.frames, g.P0, g.P1, g.Tee, g.T, g.SC, g.B, g.D, g.C, g.Jbuf, g.pbuf, self.A,
                self.rhs, self.qdot_buf)

    def qdot(self, q: np.ndarray, xdot: np.ndarray) -> np.ndarray:
        """Eq 48 at q (n,) for the task velocity ẋ (m,)."""
        rb = self.robot
        K.jacobian_into(q, rb.chain.F, rb.chain.meta, self.J, self.T)
        eq48_into(q, np.ascontiguousarray(xdot, dtype=float), self.J, self.rows, *self._args())
        return self.qdot_buf.copy()

    def solve(self, target: np.ndarray, q: np.ndarray) -> SolveStats:
        it, err = multitask_solve_into(q, target, self.rows, *self._args(), self.J, self.T,
                                       self.e6)
        return SolveStats(q, int(it), float(err), bool(err < self.res.tol))
