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

from collections.abc import Sequence
from dataclasses import dataclass, field, replace

import numpy as np

from serialkin._checks import as_float_array, check_int, check_positive
from serialkin.errors import InputError
from serialkin.kinematics import _kernels as K
from serialkin.redundancy.objectives import task_rows
from serialkin.redundancy.obstacles import (
    Capsule,
    Circle,
    Sphere,
    _Geometry,
    accumulate_obstacle_task,
    check_obstacles,
)
from serialkin.spatial._kernels import pose_error_into

__all__ = [
    "MultiTaskResolver",
    "SolveStats",
    "joint_limit_repulsion",
    "joint_limit_weights",
    "smoothstep",
]


def smoothstep(s: np.ndarray | float) -> np.ndarray:
    """C¹ ramp ``3s² − 2s³`` of s clipped to [0, 1]: 0 at s ≤ 0, 1 at s ≥ 1."""
    x = np.clip(s, 0.0, 1.0)
    return x * x * (3.0 - 2.0 * x)


def joint_limit_weights(q: object, qlim: object, *, buffer: float = 0.1,
                        max_weight: float = 1.0) -> np.ndarray:
    """The joint-limit weight function of eq 49 (designed per the ERRATA), shape (n,).

    With range ``r_i = q_M,i − q_m,i`` and buffer width ``b_i = buffer · r_i``:

    * ``W_Li = 0`` for ``q_m + b ≤ q ≤ q_M − b`` (well inside the range),
    * ``W_Li = max_weight · smoothstep((q_m + b − q)/b)`` in the lower buffer (and
      symmetrically in the upper one): continuous, growing towards the limit,
    * ``W_Li = max_weight`` at and beyond the limit.

    Joints with an infinite limit get 0.

    Args:
        q: joint values (n,).
        qlim: limits (n, 2).
        buffer: buffer width as a fraction of the range, in (0, 0.5].
        max_weight: weight at and beyond the limit (≥ 0).
    """
    qv = np.asarray(q, dtype=float)
    lim = np.asarray(qlim, dtype=float)
    b = float(buffer)
    if not 0.0 < b <= 0.5:
        raise InputError(f"buffer must be in (0, 0.5], got {buffer!r}")
    wmax = check_positive(max_weight, "max_weight", allow_zero=True)
    finite = np.isfinite(lim).all(axis=-1)
    lo = np.where(finite, lim[..., 0], 0.0)
    hi = np.where(finite, lim[..., 1], 1.0)
    width = b * (hi - lo)
    s_lo = (lo + width - qv) / width
    s_hi = (qv - (hi - width)) / width
    w = wmax * smoothstep(np.maximum(s_lo, s_hi))
    return np.where(finite, w, 0.0)


def joint_limit_repulsion(q: object, qlim: object, *, buffer: float = 0.1) -> np.ndarray:
    """Signed depth of each joint inside its limit buffer, towards mid-range, (n,) [rad/m].

    ``+(q_m + b − q)`` in the lower buffer (or beyond), ``−(q − (q_M − b))`` in the upper one,
    0 elsewhere; the optional repulsive target ``x_L`` is this times a gain.
    """
    qv = np.asarray(q, dtype=float)
    lim = np.asarray(qlim, dtype=float)
    finite = np.isfinite(lim).all(axis=-1)
    lo = np.where(finite, lim[..., 0], -np.inf)
    hi = np.where(finite, lim[..., 1], np.inf)
    width = np.where(finite, buffer * (hi - lo), 0.0)
    up = np.maximum(lo + width - qv, 0.0)
    down = np.maximum(qv - (hi - width), 0.0)
    return np.where(finite, up - down, 0.0)


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
        obstacles: obstacles (:class:`~serialkin.redundancy.obstacles.Circle`, ``Sphere``,
            ``Capsule``); each carries its influence distance.
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
        if not 0.0 < float(self.limit_buffer) <= 0.5:
            raise InputError(f"limit_buffer must be in (0, 0.5], got {self.limit_buffer!r}")
        check_int(self.max_iter, "max_iter", minimum=1)
        obs = tuple(self.obstacles)
        for i, o in enumerate(obs):
            if not isinstance(o, (Circle, Sphere, Capsule)):
                raise InputError(
                    f"obstacles[{i}] must be a Circle, Sphere or Capsule, got {type(o).__name__}")
        object.__setattr__(self, "obstacles", obs)

    def with_options(self, **changes: object) -> MultiTaskResolver:
        """A copy with some settings changed (validated again)."""
        return replace(self, **changes)

    # ------------------------------------------------------------------ set-up
    def _limits(self, robot) -> np.ndarray:
        if self.joint_limits is None:
            return np.asarray(robot.qlim, dtype=float)
        lim = np.asarray(self.joint_limits, dtype=float)
        if lim.shape != (robot.n, 2):
            raise InputError(f"joint_limits must have shape ({robot.n}, 2), got {lim.shape}")
        return lim

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
        K.jacobian_into(qv, robot._F, robot._meta, st.J, st.T)
        return st.qdot(qv, xd)

    def solve(self, robot, target: np.ndarray, q0: object, *, state: _State | None = None
              ) -> SolveStats:
        """Iterate eq 48 towards one target pose (4, 4) from q0 ("CYCLE WHILE 2").

        Each iteration: ẋ = gain·(x_d − x) (norm capped), q ← q + q̇ (dt = 1). Stops when the
        task error is below ``tol``, after ``max_iter`` iterations, or when the step
        becomes negligible (a compromise between the tasks).
        """
        st = state if state is not None else self.prepare(robot)
        return st.solve(np.ascontiguousarray(target, dtype=float),
                        np.ascontiguousarray(q0, dtype=float).copy())


class _State:
    """Per-robot buffers of a :class:`MultiTaskResolver`."""

    def __init__(self, res: MultiTaskResolver, robot) -> None:
        self.res = res
        self.robot = robot
        self.rows = task_rows(res.task)
        n = robot.n
        self.J = np.empty((6, n))
        self.T = np.empty((4, 4))
        self.e6 = np.empty(6)
        self.lim = res._limits(robot)
        self.use_limits = res.joint_limit_weight > 0 and bool(np.isfinite(self.lim).any())
        self.geom = _Geometry(robot, res.obstacles, res.link_radius) if res.obstacles else None
        self.infl = np.array([o.influence for o in res.obstacles])
        self.di = np.arange(n)

    def qdot(self, q: np.ndarray, xdot: np.ndarray) -> np.ndarray:
        """Eq 48 at q, with J and T already evaluated into the buffers."""
        r = self.res
        Jt = self.J[self.rows]
        A = r.weight * (Jt.T @ Jt)
        rhs = r.weight * (Jt.T @ xdot)
        lam2 = r.damping ** 2
        if r.singularity_damping > 0 and r.manipulability_threshold > 0:
            w = float(np.sqrt(max(np.linalg.det(Jt @ Jt.T), 0.0)))
            if w < r.manipulability_threshold:
                lam2 += (r.singularity_damping * (1.0 - w / r.manipulability_threshold)) ** 2
        A[self.di, self.di] += lam2
        if self.use_limits:
            wl = joint_limit_weights(q, self.lim, buffer=r.limit_buffer,
                                     max_weight=r.joint_limit_weight)
            A[self.di, self.di] += wl
            if r.repulsive_gain > 0:
                rhs += wl * r.repulsive_gain * joint_limit_repulsion(q, self.lim,
                                                                     buffer=r.limit_buffer)
        if self.geom is not None:
            g = self.geom
            g.update(q)
            rb = self.robot
            accumulate_obstacle_task(q, rb._F, rb._L, rb._meta, g.frames, g.P0, g.P1, g.link,
                                     g.T, g.SC, g.B, g.D, g.C, self.infl, r.obstacle_weight,
                                     r.repulsive_gain, A, rhs, g.Jbuf, g.pbuf)
        return np.linalg.solve(A, rhs)

    def error(self, q: np.ndarray, target: np.ndarray) -> np.ndarray:
        robot = self.robot
        K.jacobian_into(q, robot._F, robot._meta, self.J, self.T)
        pose_error_into(self.T, target, self.e6)
        return self.e6[self.rows]

    def solve(self, target: np.ndarray, q: np.ndarray) -> SolveStats:
        r = self.res
        it = 0
        e = self.error(q, target)
        err = float(np.linalg.norm(e))
        while err >= r.tol and it < r.max_iter:
            xdot = r.gain * e
            nx = np.linalg.norm(xdot)
            if nx > r.max_task_step:
                xdot *= r.max_task_step / nx
            dq = self.qdot(q, xdot)
            nq = np.linalg.norm(dq)
            if nq > r.max_step:
                dq *= r.max_step / nq
            q += dq
            it += 1
            e = self.error(q, target)
            err = float(np.linalg.norm(e))
            if nq < 1e-12:
                break
        return SolveStats(q, it, err, err < r.tol)

