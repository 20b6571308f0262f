"""Closed-form inverse kinematics, all solutions (chapter section 4.1).

:func:`ik_all` returns **every** solution inside the joint limits for the robot classes
that have a closed form, recognised from the geometry of the joint axes (never from the
robot's name, see :mod:`serialkin.ik.analytic.structure`):

==========================  ====================================================  =====
class                       structure                                             max
==========================  ====================================================  =====
``planar_2r``               two revolute joints, parallel axes (eqs 21-27)        2
``planar_3r``               three revolute joints, parallel axes, with φ          2
``scara``                   R R P R, all axes parallel (Table 1)                  2
``scara_rrp``               R R P, all axes parallel                              2
``puma``                    6R, spherical wrist, axes 2 ∥ 3 (Pieper)              8
``pieper_intersecting``     6R, spherical wrist, axes 1 and 2 intersect           8
``pieper_general``          6R, spherical wrist, other R R R arms (Pieper)         8
``stanford``                R R P + spherical wrist, axes 1 and 2 intersect       8
``stanford_general``        R R P + spherical wrist, other arms                   8
``ur``                      6R, axes 2 ∥ 3 ∥ 4, axes 5 and 6 intersect            8
==========================  ====================================================  =====

Other robots raise :class:`~serialkin.errors.NoClosedFormError`, whose message says
which structural test failed and points to the numerical solvers
(``robot.ik(target, method="lm")``).

Semantics:

* An unreachable target (beyond the reach, or reachable only outside the joint limits)
  gives an **empty** (0, n) array, not an exception.
* Revolute angles are wrapped by a multiple of 2π to the value nearest the middle of
  their limits (0 for unlimited joints); with ``all_turns=True`` every 2π-equivalent
  value inside the limits is listed as well.
* Every returned row reproduces the target through forward kinematics (position within
  ``tol``·max(1, size) m, rotation entries within ``tol``); rows are unique and sorted
  lexicographically, so the output is deterministic.
* At singular configurations (aligned wrist axes, wrist centre on axis 1) the solution
  set is a continuum; one representative per branch is returned (the free angle set
  to 0). At a stretched elbow the two elbow branches merge into one solution.
* The kernels are compiled by numba on first use (cached on disk afterwards); a call
  then takes about 10-15 µs for a 6R arm, all solutions included
  (``benchmarks/bench_ik_all.py``).
"""

from __future__ import annotations

import itertools
import math
import weakref
from typing import Any

import numpy as np

from serialkin._checks import ROTATION_TOL, as_float_array, check_positive, check_transform
from serialkin.errors import InputError, NoClosedFormError
from serialkin.ik.analytic.structure import CLASSES, NUMERICAL_HINT, Structure, analyse
from serialkin.ik.analytic.subproblems import rigid_error
from serialkin.model.robot import Robot

__all__ = ["CLASSES", "classify", "ik_all", "structure_of"]

_STRUCTURES: weakref.WeakKeyDictionary[Robot, Structure | NoClosedFormError] = \
    weakref.WeakKeyDictionary()


class _Prepared:
    """A robot's structure plus the contiguous arrays its kernel takes (cached per robot)."""

    def __init__(self, robot: Robot, s: Structure) -> None:
        self.s = s
        self.W = np.ascontiguousarray(s.W)
        self.P = np.ascontiguousarray(s.P)
        self.M = np.ascontiguousarray(s.M)
        self.aux = np.ascontiguousarray(s.aux)
        self.order = np.ascontiguousarray(s.order)
        self.revolute = np.ascontiguousarray(s.revolute)
        self.qlim = np.ascontiguousarray(robot.qlim, dtype=float)
        self.mid = np.zeros(robot.n)  # wrapping centre: mid-range, or π inside a half-limit
        for j, (lo, hi) in enumerate(self.qlim):
            if math.isfinite(lo) and math.isfinite(hi):
                self.mid[j] = 0.5 * (lo + hi)
            elif math.isfinite(lo):
                self.mid[j] = lo + math.pi
            elif math.isfinite(hi):
                self.mid[j] = hi - math.pi
        self.F = robot.chain.F
        self.meta = robot.chain.meta
        self.n = robot.n
        R0 = s.M[:3, :3]
        if math.hypot(R0[0, 0], R0[1, 0]) > 0.5:
            self.phi0 = math.atan2(R0[1, 0], R0[0, 0])
        else:  # tool x axis out of the plane: use the y axis, heading φ + π/2
            self.phi0 = math.atan2(R0[1, 1], R0[0, 1]) - 0.5 * math.pi
        for a in (self.W, self.P, self.M, self.aux, self.order, self.revolute, self.qlim,
                  self.mid):
            a.setflags(write=False)


_PREPARED: weakref.WeakKeyDictionary[Robot, _Prepared] = weakref.WeakKeyDictionary()

#: Spherical-wrist classes: (arm code, joint 3 prismatic) for ``solve_spherical_wrist``.
_WRIST_ARMS = {"puma": (0, False), "pieper_intersecting": (1, False), "stanford": (1, True),
               "pieper_general": (2, False), "stanford_general": (2, True)}


def structure_of(robot: Robot) -> Structure:
    """The robot's recognised closed-form structure (cached per robot object).

    Raises:
        NoClosedFormError: the robot is of no class in :data:`CLASSES`.
    """
    if not isinstance(robot, Robot):
        raise InputError(f"robot must be a serialkin Robot, got {type(robot).__name__}")
    s = _STRUCTURES.get(robot)
    if s is None:
        try:
            s = analyse(robot)
        except NoClosedFormError as exc:
            s = exc
        _STRUCTURES[robot] = s
    if isinstance(s, NoClosedFormError):
        raise NoClosedFormError(str(s))
    return s


def classify(robot: Robot) -> str:
    """Name of the robot's closed-form IK class, a key of :data:`CLASSES`.

    Raises:
        NoClosedFormError: no closed form is known for this structure (the message says
            why and points to ``robot.ik(target, method="lm")``).
    """
    return structure_of(robot).kind


def _prepared(robot: Robot) -> _Prepared:
    if not isinstance(robot, Robot):
        raise InputError(f"robot must be a serialkin Robot, got {type(robot).__name__}")
    p = _PREPARED.get(robot)
    if p is None:
        p = _Prepared(robot, structure_of(robot))
        _PREPARED[robot] = p
    return p


def _as_pose(a: np.ndarray) -> np.ndarray:
    """A (4, 4) float array as an exactly rigid target: checked, rotation projected on SO(3)."""
    T = np.ascontiguousarray(a, dtype=float)
    if not T.flags.writeable:  # one array type for the kernels (no extra compilation)
        T = T.copy()
    err = rigid_error(T)
    if err > ROTATION_TOL:
        check_transform(T, "target")  # raises with a message naming what is wrong
    if err > 1e-13:  # nearest rotation (polar decomposition), exact last row
        U, _, Vt = np.linalg.svd(T[:3, :3])
        T = T.copy()
        T[:3, :3] = U @ Vt
        T[3] = (0.0, 0.0, 0.0, 1.0)
    return T


def _heading(p: _Prepared, phi: float) -> np.ndarray:
    """Rotation with heading φ: ``Rz(φ − φ0)·R0`` (R0, φ0 of the zero configuration)."""
    c, s = math.cos(phi - p.phi0), math.sin(phi - p.phi0)
    return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]]) @ p.M[:3, :3]


def _parse_target(p: _Prepared, robot: Robot, target: object) -> tuple[np.ndarray, bool]:
    """Turn the target into a (4, 4) world pose and whether its rotation counts."""
    if type(target) is np.ndarray and target.shape == (4, 4) and target.dtype == np.float64:
        return _as_pose(target), True
    a = as_float_array(target, "target")
    kind = p.s.kind
    if a.shape == (4, 4):
        return _as_pose(a), True
    if a.ndim == 3 and a.shape[1:] == (4, 4):
        raise InputError(f"ik_all takes one target, got a batch of shape {a.shape}; call it "
                         "once per target (each may have a different number of solutions)")
    planar = kind in ("planar_2r", "planar_3r")
    if a.shape in ((2,), (3,)) and planar and p.s.planar_z:
        T = p.M.copy()
        T[0, 3], T[1, 3] = a[0], a[1]
        if a.shape == (2,):
            if kind == "planar_3r":
                raise NoClosedFormError(
                    f"robot {robot.name!r} (planar_3r) has infinitely many solutions for a "
                    "position target (x, y): the orientation is free. Give (x, y, phi) or a "
                    f"4x4 pose to ik_all, or {NUMERICAL_HINT}")
            return T, False
        T[:3, :3] = _heading(p, a[2])
        return T, True
    if a.shape == (4,) and kind == "scara" and p.s.planar_z:
        T = np.eye(4)
        T[:3, 3] = a[:3]
        T[:3, :3] = _heading(p, a[3])
        return T, True
    if a.shape == (3,) and kind == "scara_rrp":
        T = p.M.copy()
        T[:3, 3] = a
        return T, False
    if a.shape == (3,) and kind in ("puma", "pieper_intersecting", "pieper_general", "stanford",
                                    "stanford_general", "ur", "scara"):
        raise NoClosedFormError(
            f"robot {robot.name!r} ({kind}) has infinitely many solutions for a position-only "
            f"target: the orientation is free. Give ik_all a 4x4 pose, or {NUMERICAL_HINT}")
    if planar and p.s.planar_z:
        want = "a 4x4 pose, (x, y) or (x, y, phi)"
    elif kind == "scara" and p.s.planar_z:
        want = "a 4x4 pose or (x, y, z, phi)"
    elif kind == "scara_rrp":
        want = "a 4x4 pose or a position (x, y, z)"
    elif kind in ("planar_2r", "planar_3r"):
        want = ("a 4x4 pose (planar (x, y[, phi]) targets need joint axes along the world "
                "z axis)")
    else:
        want = "a 4x4 pose"
    raise InputError(f"target for ik_all on robot {robot.name!r} ({kind}) must be {want}, "
                     f"got shape {a.shape}")


def _expand_turns(sols: np.ndarray, revolute: np.ndarray, qlim: np.ndarray) -> np.ndarray:
    """Every 2π-equivalent of every row inside the limits, unique and sorted.

    Joints without a finite range (or with more than 8 turns of range) keep their
    representative only: their equivalents are unbounded in number.
    """
    rows = []
    for q in sols:
        options = []
        for j, v in enumerate(q):
            lo, hi = qlim[j]
            if not revolute[j] or not (math.isfinite(lo) and math.isfinite(hi)) \
                    or hi - lo > 16 * math.pi:
                options.append([v])
                continue
            lo_k = math.ceil((lo - v) / (2 * math.pi) - 1e-12)
            hi_k = math.floor((hi - v) / (2 * math.pi) + 1e-12)
            vals = [v + 2 * math.pi * k for k in range(lo_k, hi_k + 1)]
            options.append([min(max(x, lo), hi) for x in vals] or [v])
        rows.extend(itertools.product(*options))
    out = np.unique(np.array(rows, dtype=float).reshape(-1, sols.shape[1]), axis=0)
    return out


def ik_all(robot: Robot, target: object, *, tol: float = 1e-8, all_turns: bool = False,
           **options: Any) -> np.ndarray:
    """Every closed-form inverse-kinematics solution inside the joint limits (section 4.1).

    Args:
        robot: a robot of a class in :data:`CLASSES` (recognised from its joint axes).
        target: (4, 4) tool pose in the world frame (base and tool transforms included);
            on a planar arm whose axes are along the world z axis also ``(x, y)`` [m]
            (2R) or ``(x, y, φ)`` [m, m, rad], φ the heading ``atan2(R[1, 0], R[0, 0])`` of
            the tool x axis; on such a SCARA ``(x, y, z, φ)``; on an R R P arm a position
            ``(x, y, z)`` [m]. A pose's rotation may deviate from orthonormal by up to
            1e-6 (``check_transform``); it is replaced by the nearest rotation first.
        tol: verification tolerance: each returned row reproduces the target within
            ``tol``·max(1, robot size) metres and ``tol`` in every rotation entry.
        all_turns: also list every 2π-equivalent of each revolute angle inside the limits
            (e.g. joints with ±2π limits; joints without finite limits keep one value);
            by default one representative, nearest the middle of the limits.
        **options: none other are accepted (an unknown name raises InputError).

    Returns:
        (k, n) array of joint values [rad / m], k >= 0 (k = 0: unreachable, or reachable
        only outside the joint limits), rows unique and sorted lexicographically.

    Raises:
        NoClosedFormError: the robot has no closed form here, or the target leaves
            infinitely many solutions (e.g. a position-only target for a 6R arm).
        InputError: a target that is not a rigid transform / of an accepted shape, a
            non-positive ``tol`` or an unknown option.
    """
    if options:
        raise InputError(f"unknown option(s) for ik_all: {', '.join(sorted(options))}; "
                         "accepted: tol, all_turns")
    p = _prepared(robot)
    tol = check_positive(tol, "tol")
    T, check_rot = _parse_target(p, robot, target)
    tol_p = tol * p.s.scale
    kind = p.s.kind
    if kind in ("planar_2r", "planar_3r"):
        from serialkin.ik.analytic.planar import solve_planar

        out = np.empty((2, p.n))
        k = solve_planar(T, p.W, p.P, p.M, p.order, p.aux[0], p.aux[1], p.revolute, p.qlim,
                         p.mid, p.F, p.meta, check_rot, tol_p, tol, out)
    elif kind in ("scara", "scara_rrp"):
        from serialkin.ik.analytic.scara import solve_scara

        out = np.empty((2, p.n))
        k = solve_scara(T, p.W, p.P, p.M, p.order, p.aux[0], p.aux[1], p.revolute, p.qlim,
                        p.mid, p.F, p.meta, check_rot, tol_p, tol, out)
    elif kind in _WRIST_ARMS:
        from serialkin.ik.analytic.spherical_wrist import solve_spherical_wrist

        out = np.empty((8, 6))
        arm, prismatic3 = _WRIST_ARMS[kind]
        k = solve_spherical_wrist(T, p.W, p.P, p.M, p.aux, arm, prismatic3,
                                  p.revolute, p.qlim, p.mid, p.F, p.meta, tol_p, tol, out)
    else:  # "ur"
        from serialkin.ik.analytic.ur import solve_ur

        out = np.empty((8, 6))
        k = solve_ur(T, p.W, p.P, p.M, p.aux, p.revolute, p.qlim, p.mid, p.F, p.meta, tol_p,
                     tol, out)
    sols = out[:k]
    if all_turns and k:
        sols = _expand_turns(sols, p.revolute, p.qlim)
    return sols
