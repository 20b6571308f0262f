"""Parsing and validation of IK targets, task masks, tolerances and initial guesses.

Every IK method sees its target as a (4, 4) world pose ``T_target`` plus a weight for
each of the six task coordinates ``[vx, vy, vz, wx, wy, wz]`` of the pose error
``e = [p_target − p; log(R_target Rᵀ)^∨]`` (world frame). A weight of 0 drops the
coordinate: the task space then has dimension m < 6 (the chapter's m, section 5.3).

Accepted targets:

* a (4, 4) rigid transform: full pose, all six coordinates;
* a 3-vector ``(x, y, z)`` [m]: position only (weights ``[1, 1, 1, 0, 0, 0]``);
* on a planar robot (one whose tool moves in the world xy plane), a 2-vector
  ``(x, y)`` [m] (weights ``[1, 1, 0, 0, 0, 0]``) or a 3-vector ``(x, y, φ)`` [m, m, rad]
  (weights ``[1, 1, 0, 0, 0, 1]``), where φ is the heading of the tool x axis in the
  world xy plane, ``atan2(R[1, 0], R[0, 0])``. On a planar robot a 3-vector is always
  read as ``(x, y, φ)``;
* a batch: (N, 4, 4) poses, (N, 3) positions, or (N, 2) / (N, 3) planar targets.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from serialkin._checks import (
    ROTATION_TOL,
    as_float_array,
    check_positive,
    check_transform,
    readonly,
)
from serialkin._memo import PerObject
from serialkin.errors import InputError
from serialkin.ik._kernels import (  # noqa: F401 (re-export)
    inside_limits,
    pose_and_q0_valid,
    rows_inside_limits,
)
from serialkin.model.robot import Robot
from serialkin.model.tasks import TARGET_TASKS, TASK_COORDINATES, task_weights
from serialkin.spatial.kernels import transforms_valid

#: Default weights per target kind: 1 on the task's rows (the target kinds of
#: :data:`serialkin.model.tasks.TASKS`, the one task table).
KIND_WEIGHTS = {kind: task_weights(kind) for kind in TARGET_TASKS}


def _frozen(values: object) -> np.ndarray:
    """A read-only float64 copy of ``values``: the kernels are compiled for read-only weights."""
    a = np.array(values, dtype=np.float64)
    a.setflags(write=False)
    return a


#: The default weights per target kind, as read-only arrays.
DEFAULT_WEIGHTS = {kind: _frozen(w) for kind, w in KIND_WEIGHTS.items()}


@dataclass(frozen=True, eq=False)
class RobotArrays:
    """Contiguous per-robot arrays the solvers use (cached; robots are immutable).

    All read-only (the kernels only read them, and take read-only arrays: issue 27).

    Attributes:
        lo, hi: (n,) joint limits (±inf where unlimited).
        slo, shi: (n,) finite sampling box for random starts (:meth:`Robot.sampling_limits`).
        revolute: (n,) bool.
        box: (5, n) rows lo, hi, slo, shi, revolute (1.0 / 0.0), the kernels' layout.
    """

    lo: np.ndarray
    hi: np.ndarray
    slo: np.ndarray
    shi: np.ndarray
    revolute: np.ndarray
    box: np.ndarray


_ARRAYS: PerObject[RobotArrays] = PerObject()


def robot_arrays(robot: Robot) -> RobotArrays:
    """The cached :class:`RobotArrays` of ``robot``."""
    a = _ARRAYS.get(robot)
    if a is None:
        samp = robot.sampling_limits()
        revolute = robot.revolute
        box = np.ascontiguousarray(
            np.stack([robot.qlim[:, 0], robot.qlim[:, 1], samp[:, 0], samp[:, 1],
                      revolute.astype(np.float64)]), dtype=np.float64)
        box.setflags(write=False)  # before the row views are taken: they are read-only too
        a = RobotArrays(lo=box[0], hi=box[1], slo=box[2], shi=box[3], revolute=revolute, box=box)
        a.revolute.setflags(write=False)
        _ARRAYS.set(robot, a)
    return a


@dataclass(frozen=True, eq=False)
class Target:
    """A parsed IK target.

    Attributes:
        T: (4, 4) target pose, or (N, 4, 4) for a batch; C-contiguous float64. For
            position and planar targets the unconstrained parts (rotation, z) are filled
            in but carry zero weight.
        weights: (6,) non-negative weights of ``[vx, vy, vz, wx, wy, wz]``; the cost that
            the solvers minimise is ``E = ½ Σ w_i e_i²``.
        kind: 'pose', 'position', 'planar' or 'planar_pose'.
    """

    T: np.ndarray
    weights: np.ndarray
    kind: str

    @property
    def batch(self) -> bool:
        """True for a batch of targets (``T`` has shape (N, 4, 4))."""
        return self.T.ndim == 3

    @property
    def selected(self) -> np.ndarray:
        """(6,) booleans: the task coordinates that count (weight > 0)."""
        return self.weights > 0.0


def _planar_frame(robot: Robot) -> tuple[np.ndarray, float, float]:
    """Reference rotation R0, its heading φ0 and the constant height z0 of a planar robot."""
    T0 = robot.fk(np.zeros(robot.n))
    R0 = T0[:3, :3]
    if math.hypot(R0[0, 0], R0[1, 0]) > 0.5:
        phi0 = math.atan2(R0[1, 0], R0[0, 0])
    else:  # tool x axis out of the plane: use the y axis, whose heading is φ + π/2
        phi0 = math.atan2(R0[1, 1], R0[0, 1]) - 0.5 * math.pi
    return R0, phi0, float(T0[2, 3])


def _planar_targets(robot: Robot, xy: np.ndarray, with_phi: bool) -> np.ndarray:
    """(N, 4, 4) poses for planar targets (N, 2) or (N, 3): R = Rz(φ − φ0)·R0, z = z0.

    For a planar robot every reachable rotation is ``Rz(θ)·R0``, so the orientation
    error of this pose is exactly ``[0, 0, wrap(φ − φ(q))]``.
    """
    R0, phi0, z0 = _planar_frame(robot)
    N = xy.shape[0]
    T = np.zeros((N, 4, 4))
    T[:, 3, 3] = 1.0
    T[:, 0, 3] = xy[:, 0]
    T[:, 1, 3] = xy[:, 1]
    T[:, 2, 3] = z0
    dphi = xy[:, 2] - phi0 if with_phi else np.full(N, -0.0)
    c, s = np.cos(dphi), np.sin(dphi)
    Rz = np.zeros((N, 3, 3))
    Rz[:, 0, 0], Rz[:, 0, 1], Rz[:, 1, 0], Rz[:, 1, 1], Rz[:, 2, 2] = c, -s, s, c, 1.0
    T[:, :3, :3] = Rz @ R0
    return T


def parse_mask(mask: object, kind: str) -> np.ndarray:
    """Task-coordinate weights (6,) from a user mask and the target kind.

    Args:
        mask: None (the kind's default), or 6 booleans / non-negative weights for
            ``[vx, vy, vz, wx, wy, wz]``.
        kind: the target kind (see :data:`KIND_WEIGHTS`).

    Raises:
        InputError: wrong size, negative or non-finite weights, nothing selected, or a
            coordinate selected that the target does not define (e.g. an orientation
            coordinate for a position target).
    """
    default = DEFAULT_WEIGHTS[kind]
    if mask is None:
        return default
    w = as_float_array(mask, "mask")
    if w.shape != (6,):
        raise InputError(
            f"mask must have 6 entries, one per task coordinate {list(TASK_COORDINATES)}, "
            f"got shape {w.shape}"
        )
    if np.any(w < 0):
        raise InputError(f"mask weights must be >= 0, got {w.tolist()}")
    if not np.any(w > 0):
        raise InputError(
            f"mask selects no task coordinate (all of {list(TASK_COORDINATES)} are 0); "
            "select at least one"
        )
    extra = (w > 0) & (default == 0)
    if np.any(extra):
        names = [TASK_COORDINATES[i] for i in np.flatnonzero(extra)]
        raise InputError(
            f"mask selects {names} but a {kind} target does not define them; "
            f"a {kind} target defines {[c for c, d in zip(TASK_COORDINATES, default) if d]}"
        )
    return _frozen(w)


def parse_target(robot: Robot, target: object, mask: object = None) -> Target:
    """Validate ``target`` (and ``mask``) for ``robot`` and return a :class:`Target`.

    Raises:
        InputError: NaN/inf, a pose that is not a rigid transform (non-orthonormal
            rotation block, last row not [0, 0, 0, 1]), a shape that is none of the
            accepted ones, a planar target on a non-planar robot, or a bad mask.
    """
    if (isinstance(target, np.ndarray) and target.ndim in (2, 3)
            and target.shape[-2:] == (4, 4) and target.dtype == np.float64):
        # one pose or a batch: the compiled check (check_transform's criteria, no
        # temporaries); only a failing target takes the numpy path, which names the fault
        T = np.ascontiguousarray(target)
        if transforms_valid(readonly(T.reshape(-1, 4, 4)), ROTATION_TOL):
            return Target(T, parse_mask(mask, "pose"), "pose")
    a = as_float_array(target, "target")
    if a.ndim >= 2 and a.shape[-2:] == (4, 4):
        if a.ndim > 3:
            raise InputError(
                f"target must be one (4, 4) pose or a batch (N, 4, 4), got shape {a.shape}"
            )
        T = check_transform(a, "target")
        return Target(np.ascontiguousarray(T), parse_mask(mask, "pose"), "pose")
    if a.ndim not in (1, 2) or a.shape[-1] not in (2, 3):
        raise InputError(
            "target must be a (4, 4) pose, a 3-vector position, a planar (x, y) or "
            f"(x, y, phi) target, or a batch of one of these; got shape {a.shape}"
        )
    single = a.ndim == 1
    rows = a.reshape(-1, a.shape[-1])
    if robot.is_planar:
        kind = "planar" if a.shape[-1] == 2 else "planar_pose"
        T = _planar_targets(robot, rows, kind == "planar_pose")
    else:
        if a.shape[-1] == 2:
            raise InputError(
                f"target (x, y) is a planar target but robot {robot.name!r} is not planar "
                "(its tool does not move in the world xy plane); give a 3-vector position "
                "or a (4, 4) pose"
            )
        kind = "position"
        T = np.zeros((rows.shape[0], 4, 4))
        T[:, :3, :3] = np.eye(3)
        T[:, :3, 3] = rows
        T[:, 3, 3] = 1.0
    T = T[0] if single else T
    return Target(np.ascontiguousarray(T), parse_mask(mask, kind), kind)


def check_tol(tol: object) -> float:
    """Check the convergence tolerance: a finite number > 0 [m / rad].

    Raises:
        InputError / InputTypeError: tol <= 0, non-finite or not a number.
    """
    return check_positive(tol, "tol")


def check_q0(robot: Robot, q0: object, n_targets: int | None, respect_limits: bool) -> np.ndarray:
    """Validate an initial guess: (n,), or for a batch of N targets (n,) or (N, n).

    Returns a C-contiguous (N, n) array for a batch (a single (n,) guess is repeated),
    else (n,).

    Raises:
        InputError: wrong size, NaN/inf, or (with ``respect_limits``) outside the limits.
    """
    if isinstance(q0, np.ndarray) and q0.dtype == np.float64 and q0.flags.c_contiguous \
            and q0.shape == ((robot.n,) if n_targets is None else (n_targets, robot.n)):
        # the common call, checked in one compiled pass (finite, inside the limits)
        arr = robot_arrays(robot)
        tol = 1e-12 if respect_limits else np.inf
        q = readonly(q0)  # a user's read-only q0 compiles nothing more
        if (inside_limits(q, arr.lo, arr.hi, tol) if n_targets is None
                else rows_inside_limits(q, arr.lo, arr.hi, tol)):
            return q0
    q = robot.check_q(q0, "q0")
    if n_targets is None:
        if q.ndim != 1:
            raise InputError(f"q0 must have shape ({robot.n},) for one target, got {q.shape}")
    else:
        if q.ndim == 1:
            q = np.broadcast_to(q, (n_targets, robot.n))
        elif q.shape != (n_targets, robot.n):
            raise InputError(
                f"q0 must have shape ({robot.n},) or ({n_targets}, {robot.n}) for "
                f"{n_targets} targets, got {q.shape}"
            )
    if respect_limits:
        lo, hi = robot.qlim[:, 0], robot.qlim[:, 1]
        bad = (q < lo - 1e-12) | (q > hi + 1e-12)
        if np.any(bad):
            idx = np.argwhere(bad)[0]
            j = int(idx[-1])
            where = f"q0[{', '.join(str(int(i)) for i in idx)}]"
            raise InputError(
                f"q0 is outside the joint limits: {where} = {q[tuple(idx)]:.6g} but joint "
                f"{robot.joint_names[j]!r} allows [{lo[j]:.6g}, {hi[j]:.6g}]; give a q0 inside "
                "the limits or pass respect_limits=False"
            )
    return np.ascontiguousarray(q, dtype=np.float64)
