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

Beyond these exact classes (see ``docs/ik-analytic.md``): a 6-joint arm within
``near_tol`` of a class (a calibrated robot) is solved on the idealised class and every
branch refined by Newton's method on the true model (:mod:`~serialkin.ik.analytic.refine`);
any other 6R arm by :mod:`~serialkin.ik.analytic.general` (Raghavan–Roth elimination,
a 2-D search as its fallback; up to 16 solutions); ``free={index: value}`` locks
joints (7R arms); a batch of targets (..., 4, 4) returns an :class:`AllSolutions`.
Other robots raise :class:`~serialkin.errors.NoClosedFormError`, whose message says which
structural test failed and points to the numerical solvers (``robot.ik(target, method="lm")``).

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
  then takes about 4-6 µs for a 6R arm of an exact class, all solutions included,
  and about 0.1 ms for a general 6R arm (milliseconds when the elimination declines and
  the search answers; ``benchmarks/bench_ik_all.py``).
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Mapping
from dataclasses import dataclass, replace
from typing import Any

import numpy as np

from serialkin._checks import (
    ROTATION_TOL,
    as_float_array,
    check_positive,
    check_transform,
    short_repr,
)
from serialkin._memo import PerObject
from serialkin.errors import InputError, NoClosedFormError
from serialkin.ik.analytic.dispatch import (
    GENERAL,
    MAX_ROWS,
    PLANAR,
    SCARA,
    UR,
    WRIST,
)
from serialkin.ik.analytic.singular import continuous_family
from serialkin.ik.analytic.structure import (
    CLASSES,
    NUMERICAL_HINT,
    Structure,
    analyse,
    general_structure,
)
from serialkin.ik.analytic.subproblems import rigid_error
from serialkin.ik.turns import nearest_turn
from serialkin.model.robot import Robot, check_robot
from serialkin.spatial.rotations import wrap_angle

#: Spherical-wrist classes: (arm code, joint 3 prismatic) for ``solve_spherical_wrist``.
_WRIST_ARMS = {"puma": (0, False), "pieper_intersecting": (1, False), "stanford": (1, True),
               "pieper_general": (2, False), "stanford_general": (2, True)}

__all__ = ["CLASSES", "AllSolutions", "classify", "ik_all", "sort_by_reference",
           "structure_of"]

_STRUCTURES: PerObject[Structure | NoClosedFormError] = PerObject()


class _Prepared:
    """A robot's structure plus the contiguous arrays its kernel takes (cached per robot)."""

    def __init__(self, robot: Robot, s: Structure, mode: str = "exact") -> None:
        self.s = s
        self.mode = mode  # "exact", "near" (idealised, refined) or "general" (search)
        kind = s.kind
        if kind in ("planar_2r", "planar_3r"):
            self.code, self.arm, self.prismatic3 = PLANAR, 0, False
        elif kind in ("scara", "scara_rrp"):
            self.code, self.arm, self.prismatic3 = SCARA, 0, False
        elif kind in _WRIST_ARMS:
            self.code = WRIST
            self.arm, self.prismatic3 = _WRIST_ARMS[kind]
        elif kind == "ur":
            self.code, self.arm, self.prismatic3 = UR, 0, False
        else:  # general_6r
            self.code, self.arm, self.prismatic3 = GENERAL, int(s.order[0]), False
        self.refine = mode == "near"
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
        self.limited = bool(np.isfinite(self.qlim).any())
        # a nearly ideal arm is solved without its limits (the rows still wrapped about
        # ``mid``), so that the parity test of _near_rows counts every solution; the
        # limits are applied after it (_inside_limits)
        self.solve_qlim = self.qlim
        self.packed: dict[tuple, tuple] = {}  # dispatch.pack's arrays per options (_pack)
        if mode == "near":
            self.solve_qlim = np.ascontiguousarray(np.tile([-np.inf, np.inf], (robot.n, 1)))
        self.F = robot.chain.F
        self.meta = robot.chain.meta
        self.n = robot.n
        self.wrist = _wrist_coefficients(robot) if mode == "near" else None
        R0 = s.M[:3, :3]
        if math.hypot(R0[0, 0], R0[1, 0]) > 0.5:
            self.phi0 = math.atan2(R0[1, 0], R0[0, 0])
        else:  # tool x axis out of the plane: use the y axis, heading φ + π/2
            self.phi0 = math.atan2(R0[1, 1], R0[0, 1]) - 0.5 * math.pi
        for a in (self.W, self.P, self.M, self.aux, self.order, self.revolute, self.qlim,
                  self.solve_qlim, self.mid):
            a.setflags(write=False)


_PREPARED: PerObject[dict[float, _Prepared]] = PerObject()


def structure_of(robot: Robot) -> Structure:
    """The robot's recognised closed-form structure (cached per robot object).

    Raises:
        NoClosedFormError: the robot is of no class in :data:`CLASSES`.
    """
    check_robot(robot)
    s = _STRUCTURES.get(robot)
    if s is None:
        try:
            s = analyse(robot)
        except NoClosedFormError as exc:
            s = exc
        _STRUCTURES.set(robot, s)
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


def _prepared(robot: Robot, near_tol: float = 0.0) -> _Prepared:
    """The robot's solver data, cached per robot and ``near_tol``.

    Its exact class; else (6 joints) the class it is within ``near_tol`` of (solved on
    the idealised axes, refined on the true chain); else (6R) the general solver. When
    no class fits at ``near_tol`` itself, tolerances 10, 100 and 1000 times smaller are
    tried: an arm can be near a class only at a finer tolerance, where a short length
    of its own no longer looks like zero (a Stanford-like arm with a 2 cm offset
    between parallel axes 3 and 4, its parameters 1e-5 off: at 0.05 × size the axes
    looked coaxial, a degenerate arm, and the general solver lost solutions on one pose
    in eight).
    """
    check_robot(robot)
    cache = _PREPARED.setdefault(robot, dict)
    p = cache.get(near_tol)
    if p is not None:
        return p
    try:
        p = _Prepared(robot, structure_of(robot))
    except NoClosedFormError as exact_error:
        if robot.n != 6:
            raise
        p = _near_structure(robot, near_tol)
        if p is None:
            try:
                p = _Prepared(robot, general_structure(robot), "general")
            except NoClosedFormError as general_error:
                why = str(general_error).split("): ", 1)[-1].split(". Closed forms")[0]
                raise NoClosedFormError(f"{exact_error} The general 6R search does not apply "
                                        f"either: {why}.") from None
    cache[near_tol] = p
    return p


def _near_structure(robot: Robot, near_tol: float) -> _Prepared | None:
    """Near-mode data of the 6-joint arm at the widest tolerance that fits, or None.

    Tried: ``near_tol``, then 10, 100 and 1000 times finer (see :func:`_prepared`).
    """
    for tol in (near_tol, 0.1 * near_tol, 0.01 * near_tol, 0.001 * near_tol):
        if tol <= 0.0:
            break
        try:
            return _Prepared(robot, analyse(robot, tol, tol), "near")
        except NoClosedFormError:
            continue
    return None


def _near_companion(robot: Robot) -> _Prepared | None:
    """The default mode's near-class data of an arm the general solver answers, or None.

    An arm within :data:`NEAR_TOL` of a class is near a special class, where the general
    6R search's basins narrow (its elimination declines): the refined closed form's
    rows are merged into the search's (:func:`_limited_rows`), so that asking for the
    exact mode (``near_tol=0``) never returns fewer solutions than the default mode.
    Never raises: the general structure the caller solves with also serves
    ``_prepared(robot, NEAR_TOL)`` when no class is near.
    """
    p = _prepared(robot, NEAR_TOL)
    return p if p.mode == "near" else None


def _merged(sols: np.ndarray, extra: np.ndarray) -> np.ndarray:
    """Rows ``sols`` (k, n) with the rows of ``extra`` not within 1e-7 (wrapped) of one.

    Sorted lexicographically, as the kernels sort; ``sols`` itself when nothing is new.
    """
    rows = [r for r in sols]
    for r in extra:
        if not rows or np.abs(wrap_angle(np.array(rows) - r)).max(axis=1).min() > 1e-7:
            rows.append(r)
    if len(rows) == len(sols):
        return sols
    merged = np.array(rows, dtype=float)
    return merged[np.lexsort(merged.T[::-1])]


def _limited_rows(p: _Prepared, rows: np.ndarray) -> np.ndarray:
    """Rows (k, n) solved without ``p``'s joint limits, kept inside them (all if none)."""
    return _inside_limits(p, rows) if p.limited else rows


def _put_rows(out: np.ndarray, counts: np.ndarray, i: int, rows: np.ndarray) -> None:
    """Target ``i`` of a batch (``out`` (N, 16, n), ``counts`` (N,)) holds ``rows`` (k, n).

    ``rows`` may be a view of ``out[i]`` (a merge that found nothing new returns its
    input): copied before ``out[i]`` is cleared.
    """
    rows = np.array(rows[:MAX_ROWS], dtype=float)
    counts[i] = len(rows)
    out[i] = 0.0
    out[i, :counts[i]] = rows


def _with_near(robot: Robot, T: np.ndarray, sols: np.ndarray, tol: float,
               grid: int) -> np.ndarray:
    """The general solver's ``sols`` merged with the refined closed form's rows.

    Those of :func:`_near_companion`, inside the limits; ``sols`` when the arm is near
    no class.
    """
    pn = _near_companion(robot)
    if pn is None:
        return sols
    out, k, _ = _solve_one(pn, pn.solve_qlim, T, True, True, tol, grid)
    return _merged(sols, _limited_rows(pn, out[:k]))


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
                                    "stanford_general", "ur", "scara", "general_6r"):
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



#: Default tolerance [rad, and × robot size in m] within which a 6-joint arm counts as
#: nearly of a special class (solved on the ideal axes, every branch refined).
NEAR_TOL = 0.05
#: Newton refinement tolerance: position [m] per metre of robot size, rotation [rad].
REFINE_TOL = 1e-12


_NEW = object.__new__
_PUT = object.__setattr__


class AllSolutions(np.lib.mixins.NDArrayOperatorsMixin):
    """Every IK solution of one target or of a batch of targets (what ``ik_all`` returns).

    It is also an array: its solutions ``q``. For one target that is the (k, n) array of
    rows, so ``len(sols)``, ``sols[0]``, ``for row in sols``, ``np.asarray(sols)``,
    arithmetic (``sols - q``), comparisons and the array's attributes and methods
    (``sols.shape``, ``sols.tolist()``) work as on the rows; for a batch the same applies
    to the padded ``q`` (..., k_max, n). Immutable.

    Attributes:
        q: (k, n) joint values [rad / m] of one target's solutions (k >= 0: 0 means
            unreachable, or reachable only outside the joint limits); for a batch
            (..., k_max, n): row j of target i is a solution for j < ``count[i]``, zero
            padding after it (never NaN).
        count: k for one target (int); for a batch (...,) int, the number of solutions
            of each target.
        branches: candidate branches the solver produced (before the limit filter and
            de-duplication): an int, or (...,) for a batch.
        converged: (16,) bool, or (..., 16) for a batch: per candidate branch whether its
            Newton refinement on the true model converged to 1e-12 (always True for
            exact classes, where no refinement is needed; False beyond ``branches``).
        kind: the structure class solved (a key of :data:`CLASSES`, or
            ``'general_6r'``).
        mode: ``'exact'`` (closed form of the exact class), ``'near'`` (the arm is within
            the tolerance of ``kind``: solved for the idealised axes, every branch refined
            on the true model) or ``'general'`` (Raghavan–Roth elimination or the 2-D
            search of :mod:`serialkin.ik.analytic.general`).
        continuous: with ``report=True``: (k,) bool, or (..., k_max) for a batch,
            solution j lies on a continuous family of solutions (a singular target: the
            row is one representative,
            :func:`~serialkin.ik.analytic.singular.continuous_family`); None when not
            computed.
    """

    __slots__ = ("q", "count", "_conv", "kind", "mode", "continuous")

    def __init__(self, q: np.ndarray, count: object, branches: object, converged: object,
                 kind: str, mode: str, continuous: np.ndarray | None = None) -> None:
        # (..., 17) as the kernels fill it: branches, then a flag per branch
        conv = np.concatenate([np.asarray(branches, dtype=np.int64)[..., None],
                               np.asarray(converged).astype(np.int64)], axis=-1)
        for name, value in zip(self.__slots__, (q, count, conv, kind, mode, continuous),
                               strict=True):
            _PUT(self, name, value)

    @staticmethod
    def _of(q: np.ndarray, count: object, conv: np.ndarray, kind: str, mode: str,
            continuous: np.ndarray | None = None) -> AllSolutions:
        """From the kernels' (..., 17) convergence record (no conversion: the fast path)."""
        self = _NEW(AllSolutions)
        _PUT(self, "q", q)
        _PUT(self, "count", count)
        _PUT(self, "_conv", conv)
        _PUT(self, "kind", kind)
        _PUT(self, "mode", mode)
        _PUT(self, "continuous", continuous)
        return self

    def replaced(self, **changes: object) -> AllSolutions:
        """A copy with some of ``q``, ``count``, ``continuous`` replaced."""
        values = {"q": self.q, "count": self.count, "continuous": self.continuous}
        values.update(changes)
        return AllSolutions._of(values["q"], values["count"], self._conv, self.kind,
                                self.mode, values["continuous"])

    @property
    def branches(self) -> object:
        """Candidate branches the solver produced: an int, or (...,) for a batch."""
        b = self._conv[..., 0]
        return int(b) if b.ndim == 0 else b

    @property
    def converged(self) -> np.ndarray:
        """(16,) or (..., 16) bool: per candidate branch whether its refinement converged."""
        return self._conv[..., 1:] != 0

    def solutions(self, index: int | tuple[int, ...] = ()) -> np.ndarray:
        """The (count, n) solutions of one target (an index into the batch dimensions)."""
        if np.ndim(self.count) == 0:
            return self.q
        return self.q[index][: int(self.count[index])]

    # ------------------------------------------------------------ the array it also is
    def __setattr__(self, name: str, value: object) -> None:
        raise AttributeError(f"AllSolutions is immutable (cannot set {name!r}); use "
                             ".replaced(...)")

    def __array__(self, dtype: object = None, copy: object = None) -> np.ndarray:
        if copy:
            return np.array(self.q, dtype=dtype, copy=True)
        return self.q if dtype is None else self.q.astype(dtype, copy=False)

    def __array_ufunc__(self, ufunc: np.ufunc, method: str, *inputs: object,
                        **kwargs: object) -> object:
        inputs = tuple(x.q if isinstance(x, AllSolutions) else x for x in inputs)
        if "out" in kwargs:
            kwargs["out"] = tuple(x.q if isinstance(x, AllSolutions) else x
                                  for x in kwargs["out"])
        return getattr(ufunc, method)(*inputs, **kwargs)

    def __len__(self) -> int:
        return len(self.q)

    def __getitem__(self, index: object) -> object:
        return self.q[index]

    def __iter__(self):
        return iter(self.q)

    def __getattr__(self, name: str) -> object:
        if name.startswith("_") or name == "q":  # not an array attribute (or unpickling)
            raise AttributeError(name)
        return getattr(self.q, name)

    def __reduce__(self) -> tuple:
        return (AllSolutions._of, (self.q, self.count, self._conv, self.kind, self.mode,
                                   self.continuous))

    def __str__(self) -> str:
        return str(self.q)

    def __repr__(self) -> str:
        q = np.array2string(self.q, separator=", ", prefix="    q=")
        return (f"AllSolutions(kind={self.kind!r}, mode={self.mode!r}, count="
                f"{self.count if np.ndim(self.count) == 0 else self.count.tolist()},\n"
                f"    q={q})")


def _locked(robot: Robot, free: object) -> tuple[Robot, np.ndarray, np.ndarray]:
    """The robot with the joints of ``free`` = {index: value} locked at those values.

    Returns the reduced robot, the locked indices and their values. A locked joint's
    motion is folded into the next joint's ``origin`` (or into the tool for the last).
    Reduced robots are cached per robot and lock; one left with a self-motion is
    refused (:func:`_check_no_self_motion`) and not cached.
    """
    if not isinstance(free, Mapping) or not free:
        raise InputError("free must be a non-empty mapping {joint index: value}, got "
                         f"{free!r}")
    idx, vals = [], []
    for key, value in free.items():
        if isinstance(key, bool) or not isinstance(key, (int, np.integer)) \
                or not 0 <= int(key) < robot.n:
            shown = short_repr(int(key) if isinstance(key, np.integer) else key, 40)
            raise InputError(f"free: joint index must be an int in 0..{robot.n - 1}, got "
                             f"{shown}")
        try:
            v = float(np.asarray(value, dtype=float))
        except (TypeError, ValueError):
            v = math.nan
        if not math.isfinite(v):
            raise InputError(f"free[{int(key)}] must be a finite joint value [rad or m], got "
                             f"{short_repr(value, 40)}")
        idx.append(int(key))
        vals.append(v)
    order = np.argsort(idx)
    idx_a = np.array(idx, dtype=np.int64)[order]
    vals_a = np.array(vals)[order]
    key = (tuple(idx_a.tolist()), tuple(vals_a.tolist()))
    cache = _LOCKED.setdefault(robot, dict)
    if key in cache:
        return cache[key], idx_a, vals_a
    joints = list(robot.joints)
    tool = robot.tool
    for i, v in sorted(zip(idx_a, vals_a), reverse=True):
        j = joints[i]
        m = np.eye(4)
        if j.type == "R":
            from serialkin.spatial.rotations import axis_angle_to_matrix

            m[:3, :3] = axis_angle_to_matrix(j.axis, v + j.offset)
        else:
            m[:3, 3] = (v + j.offset) * j.axis
        A = j.origin @ m @ j.post
        if i + 1 < len(joints):
            nxt = joints[i + 1]
            joints[i + 1] = replace(nxt, origin=A @ nxt.origin)
        else:
            tool = A @ tool
        del joints[i]
    reduced = Robot.from_joints(joints, base=robot.base, tool=tool,
                                name=f"{robot.name} (joint(s) {(idx_a + 1).tolist()} locked)")
    _check_no_self_motion(robot, reduced, idx_a, vals_a)  # only arms that pass are cached
    if len(cache) > 64:
        cache.clear()
    cache[key] = reduced
    return reduced, idx_a, vals_a


#: Relative smallest singular value below which the locked arm has lost a direction.
_RANK_TOL = 1e-9


def _check_no_self_motion(robot: Robot, reduced: Robot, idx: np.ndarray,
                          vals: np.ndarray) -> None:
    """Refuse a lock that leaves a 6-joint arm moving in fewer than six directions.

    When the reduced arm's Jacobian (6, 6) is singular at every configuration (three
    seeded random ones, σ_min < 1e-9 σ_max at each), each pose it reaches has infinitely
    many solutions (a self-motion) and every other pose none: e.g. a 7R arm with a
    spherical shoulder and wrist (iiwa) with its elbow locked keeps rotating about the
    shoulder–wrist line. Raises NoClosedFormError with the singular values.
    """
    if reduced.n != 6:
        return
    Q = reduced.random_q(3, seed=0)
    sv = np.linalg.svd(reduced.jacobian(Q), compute_uv=False)  # (3, 6)
    ratio = sv[:, -1] / np.maximum(sv[:, 0], 1e-300)
    if np.all(ratio < _RANK_TOL):
        locked = ", ".join(f"joint {i + 1} at {v:.6g}" for i, v in zip(idx, vals, strict=True))
        raise NoClosedFormError(
            f"locking {locked} of robot {robot.name!r} leaves an arm that cannot move in "
            f"every direction: its Jacobian's smallest singular value is "
            f"{float(sv[:, -1].max()):.1e} against a largest of {float(sv[:, 0].min()):.3g} at "
            "each of three random configurations, so every pose it reaches has infinitely "
            "many solutions (a self-motion) and every other pose none. Lock a different "
            f"joint, or {NUMERICAL_HINT}")


_LOCKED: PerObject[dict] = PerObject()  # per robot: {locked joints: reduced robot}


def _insert_locked(sols: np.ndarray, idx: np.ndarray, vals: np.ndarray, n: int) -> np.ndarray:
    """Put the locked joints' values back into rows of the reduced robot (..., n - len(idx))."""
    out = np.zeros(sols.shape[:-1] + (n,))
    keep = np.setdiff1d(np.arange(n), idx)
    out[..., keep] = sols
    out[..., idx] = vals
    return out


def _toward(robot: Robot, q: np.ndarray, reference: np.ndarray) -> np.ndarray:
    """``q`` (..., n), revolute joints moved by whole turns nearest ``reference``.

    Inside the limits; ``reference`` broadcasts against ``q``
    (:func:`~serialkin.ik.turns.nearest_turn`).
    """
    return nearest_turn(q, robot.qlim[:, 0], robot.qlim[:, 1], robot.revolute, reference)


def _distance_args(robot: Robot, reference: object, weights: object,
                   norm: str) -> tuple[np.ndarray, np.ndarray]:
    """The checked ``reference`` (n,) and ``weights`` (n,) of :func:`sort_by_reference`."""
    from serialkin._checks import check_choice

    check_choice(norm, "norm", ("l2", "linf"))
    ref = robot.check_q(reference).reshape(robot.n)
    w = np.ones(robot.n) if weights is None else as_float_array(weights, "weights")
    if w.shape != (robot.n,) or not np.all(np.isfinite(w)) or np.any(w < 0):
        raise InputError(f"weights must be {robot.n} finite non-negative numbers, got "
                         f"{np.asarray(weights)!r}")
    return ref, w


def reference_distance(d: np.ndarray, w: np.ndarray, norm: str) -> np.ndarray:
    """Distances ``sqrt(Σ_j w_j d_j²)`` (``'l2'``) or ``max_j w_j |d_j|`` (``'linf'``).

    ``d`` (..., n) joint differences, ``w`` (n,) weights; returns (...,).
    """
    return np.sqrt((w * d * d).sum(axis=-1)) if norm == "l2" else (w * np.abs(d)).max(axis=-1)


def sort_by_reference(robot: Robot, sols: np.ndarray, reference: object, *,
                      weights: object = None, norm: str = "l2",
                      return_order: bool = False) -> Any:
    """Solutions ordered by distance to a reference configuration, nearest first.

    Each revolute joint of each row is first moved by the multiple of 2π that brings it
    nearest the reference while staying inside its limits
    (:func:`serialkin.ik.turns.nearest_turn`). The
    distance is ``sqrt(Σ w_j d_j²)`` (``norm='l2'``) or ``max_j w_j |d_j|``
    (``norm='linf'``), ``d = q − reference`` after that shift.

    Args:
        robot: the robot (joint kinds and limits).
        sols: (k, n) solutions, e.g. from :func:`ik_all`.
        reference: (n,) reference configuration [rad / m].
        weights: (n,) non-negative weights (default ones).
        norm: 'l2' or 'linf'.
        return_order: also return the permutation applied to ``sols``.

    Returns:
        (k, n) the shifted rows, nearest first (stable for ties); with ``return_order``
        also the (k,) indices of ``sols`` in that order.
    """
    ref, w = _distance_args(robot, reference, weights, norm)
    q = np.array(sols, dtype=float).reshape(-1, robot.n)
    if q.shape[0] == 0:
        return (q, np.zeros(0, dtype=np.int64)) if return_order else q
    q = _toward(robot, q, ref)
    order = np.argsort(reference_distance(q - ref, w, norm), kind="stable")
    if return_order:
        return q[order], order
    return q[order]


def _near_rows(robot: Robot, p: _Prepared, T: np.ndarray, rows: np.ndarray,
               conv: np.ndarray, tol: float, grid: int) -> np.ndarray:
    """A nearly ideal arm's rows: the refined branches ``rows`` (k, n), completed, then limited.

    ``rows`` come from a solve without the joint limits (``p.solve_qlim``), so they are
    every distinct solution the refined branches reached; ``conv`` (17,) is the kernel's
    record of them. When they are doubtful (:func:`_doubtful`) the general solver's rows
    are merged in (:func:`_with_general`). Then the limits are applied.
    """
    if _doubtful(p, rows[None], conv[None], np.array([len(rows)]))[0]:
        rows = _with_general(robot, T, rows, tol, grid)
    return _limited_rows(p, rows)


def _doubtful(p: _Prepared, rows: np.ndarray, conv: np.ndarray,
              counts: np.ndarray) -> np.ndarray:
    """(N,) whether a nearly ideal arm's refined branches may have missed a solution.

    ``rows`` (N, K, n) with ``counts`` (N,) valid rows each: the distinct solutions of a
    solve without limits; ``conv`` (N, 17) the kernels' records (branches, then a flag per
    branch). Doubtful when

    * no branch, or an odd number of branches, converged on the true chain (the
      idealised arm may have no solution where the true arm has some: measured on random
      arms with twists 0.04 rad from parallel; an odd count lost one of a pair);
    * the number of distinct solutions is odd: real solutions of a 6-joint arm come in
      pairs, so one was lost;
    * more branches converged than there are distinct solutions: two seeds met on one
      solution, so its neighbour (the pair of a fold, a member of a cluster) may have
      none (measured on a UR5 whose parameters deviate by 1e-5, at a folded elbow near
      the shoulder's tangency: 8 branches on 6 solutions, 2 of the 8 missing);
    * a row is near the wrist singularity (:func:`_wrist_singular`), where the true
      arm's solutions cluster along the ideal wrist's continuum, more than its seeds
      may reach.
    """
    branches = conv[:, 0]
    good = (conv[:, 1:] * (np.arange(conv.shape[1] - 1) < branches[:, None])).sum(axis=1)
    out = (good % 2 == 1) | (good == 0) | (counts % 2 == 1) | (good > counts)
    for i in np.flatnonzero(~out):
        out[i] = _wrist_singular(p, rows[i, :counts[i]])
    return out


def _inside_limits(p: _Prepared, rows: np.ndarray) -> np.ndarray:
    """The rows (k, n) inside the limits ``p.qlim``, those within LIMIT_TOL outside clipped.

    What :func:`~serialkin.ik.analytic.subproblems.finalize` does with the limits, for the
    rows of a solve without them (the rows are already wrapped about ``p.mid``); the
    order is kept.
    """
    from serialkin.ik.analytic.subproblems import LIMIT_TOL

    lo, hi = p.qlim[:, 0], p.qlim[:, 1]
    keep = np.all((rows >= lo - LIMIT_TOL) & (rows <= hi + LIMIT_TOL), axis=1)
    return np.clip(rows[keep], lo, hi)


def _with_general(robot: Robot, T: np.ndarray, sols: np.ndarray, tol: float,
                  grid: int) -> np.ndarray:
    """``sols`` of a nearly ideal arm merged with the general search's (when it applies).

    Called when an odd number of refined branches converged: real solutions of a 6R come
    in pairs, so one was lost (e.g. near a singularity of the true arm). Branches that
    fail in pairs are usually solutions the idealised arm has and the true arm has not
    (a target near the workspace boundary), and trigger nothing.
    """
    cache = _PREPARED.setdefault(robot, dict)
    g = cache.get(-1.0)
    if g is None:
        try:
            g = _Prepared(robot, general_structure(robot), "general")
        except NoClosedFormError:
            return sols
        cache[-1.0] = g
    out, k, _ = _solve_one(g, g.qlim, T, True, False, tol, grid)
    return _merged(np.asarray(sols, dtype=float).reshape(-1, robot.n), out[:k])


#: |w_i × w_(i+2)| below which a nearly ideal arm's row is near its wrist singularity.
WRIST_SINGULAR = 0.05


def _wrist_coefficients(robot: Robot) -> np.ndarray:
    """The coefficients of the angle between axes i and i + 2, a function of q_(i+1) alone.

    Returns (2, 4): per triple (i, j, k) = (4, 5, 6), (1, 2, 3) (1-based) the A, B, C of
    ``w_i·Rot(w_j, q_j)·w_k = A + B cos q_j + C sin q_j`` (zero-configuration directions),
    then j (0-based). Joint i's rotation keeps w_i and earlier joints turn both axes
    alike, so the angle between axes i and k of any configuration depends on q_j alone:
    ``A = (w_i·w_j)(w_j·w_k)``, ``B = w_i·w_k − A``, ``C = w_i·(w_j × w_k)``.
    """
    W = robot.joint_axes(np.zeros(robot.n))[1]
    W = W / np.linalg.norm(W, axis=1, keepdims=True)
    out = np.zeros((2, 4))
    for row, (i, j, k) in enumerate(((3, 4, 5), (0, 1, 2))):
        a = (W[i] @ W[j]) * (W[j] @ W[k])
        out[row] = (a, W[i] @ W[k] - a, W[i] @ np.cross(W[j], W[k]), j)
    return out


def _wrist_singular(p: _Prepared, rows: np.ndarray) -> bool:
    """Whether a row of ``rows`` (k, 6) has axes 4, 6 (or 1, 3) within 0.05 rad of parallel.

    There (q5 ≈ 0 on a Puma 560 or a UR5) a nearly ideal arm's true solutions split and
    merge within O(√deviation) of the idealised ones, along the ideal wrist's continuum:
    the kernels' extra seeds there (``WRIST_SEED``) find some, the general solver's rows
    the others (:func:`_near_rows`). Measured before those seeds, on UR5 and Puma 560 arms
    whose DH parameters deviate by 1e-5 to 1e-3: 21 of 48 poses with q5 in
    {0, 1e-6, 1e-3} lost 1 to 6 solutions the general solver finds, and none of 72 random
    poses did; about 3 % of random poses are this close to the singularity. The angle
    of axes i and i + 2 depends on q_(i+1) alone (:func:`_wrist_coefficients`).
    """
    if not len(rows) or p.wrist is None:
        return False
    c = p.wrist
    dots = np.abs(c[:, :1] + c[:, 1:2] * np.cos(rows[:, [4, 1]].T)
                  + c[:, 2:3] * np.sin(rows[:, [4, 1]].T))
    return bool(dots.max() > _WRIST_COS)


#: cos of WRIST_SINGULAR: |w_i · w_(i+2)| above it is within WRIST_SINGULAR of parallel.
_WRIST_COS = math.sqrt(1.0 - WRIST_SINGULAR ** 2)


def _near_wrist_singular(robot: Robot, sols: np.ndarray) -> bool:
    """Whether a row of ``sols`` (k, 6) has axes 4, 6 (or 1, 3) within 0.05 rad of parallel.

    :func:`_wrist_singular` for any 6-joint robot (False for others), from its axes.
    """
    if robot.n != 6 or not len(sols):
        return False
    c = _wrist_coefficients(robot)
    q = np.asarray(sols, dtype=float)[:, [4, 1]].T
    return bool(np.abs(c[:, :1] + c[:, 1:2] * np.cos(q) + c[:, 2:3] * np.sin(q)).max()
                > _WRIST_COS)


def _sort_batch(robot: Robot, res: AllSolutions, reference: object, weights: object,
                norm: str) -> AllSolutions:
    """``res`` with each target's rows sorted by :func:`sort_by_reference` (flags too).

    All targets at once: padding rows (beyond each ``count``) stay zero and last.
    """
    ref, w = _distance_args(robot, reference, weights, norm)
    k_max, n = res.q.shape[-2], res.q.shape[-1]
    q = res.q.reshape(-1, k_max, n)
    valid = np.arange(k_max) < np.asarray(res.count).reshape(-1, 1)  # (N, k_max)
    shifted = np.where(valid[..., None], _toward(robot, q, ref), 0.0)
    dist = np.where(valid, reference_distance(shifted - ref, w, norm), np.inf)
    order = np.argsort(dist, axis=1, kind="stable")
    q = np.take_along_axis(shifted, order[..., None], axis=1)
    cont = None
    if res.continuous is not None:
        cont = np.take_along_axis(res.continuous.reshape(-1, k_max), order, axis=1)
    return res.replaced(q=q.reshape(res.q.shape),
                        continuous=None if cont is None else cont.reshape(res.continuous.shape))


def _pack(p: _Prepared, qlim: np.ndarray, check_rot: bool, refine: bool, tol: float,
          grid: int) -> tuple:
    """:func:`~serialkin.ik.analytic.dispatch.pack` of ``p`` with these limits and options.

    Kept on ``p`` per set of options (packing takes about 10 µs, as long as a solve).
    """
    from serialkin.ik.analytic.dispatch import pack

    key = (qlim is p.solve_qlim, check_rot, refine, tol, grid)
    found = p.packed.get(key)
    if found is None:
        if len(p.packed) > 64:  # a caller sweeping tol or grid
            p.packed.clear()
        found = p.packed[key] = pack(
            p.code, p.arm, p.prismatic3, p.W, p.P, p.M, p.aux, p.order, p.revolute, qlim,
            p.mid, p.F, p.meta, check_rot, refine, grid, tol * p.s.scale, tol,
            REFINE_TOL * p.s.scale, REFINE_TOL)
    return found


def _solve_one(p: _Prepared, qlim: np.ndarray, T: np.ndarray, check_rot: bool, refine: bool,
               tol: float, grid: int) -> tuple[np.ndarray, int, np.ndarray]:
    """One target T (4, 4), already a rigid transform: (rows (16, n), count, conv (17,))."""
    from serialkin.ik.analytic.dispatch import solve

    T = T if T.flags.carray and T.dtype == np.float64 else np.array(T, dtype=float, order="C")
    # one target is the kernel's batch of one (its one specialisation)
    out, counts, conv = solve(p.code, T[None], _pack(p, qlim, check_rot, refine, tol, grid))
    return out[0], int(counts[0]), conv[0]


def _solve_batch(p: _Prepared, robot: Robot, T: np.ndarray, tol: float,
                 grid: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Solve targets T (N, 4, 4) on every core; (out (N, 16, n), counts (N,), conv (N, 17))."""
    from serialkin.ik.analytic.dispatch import solve

    return solve(p.code, T, _pack(p, p.solve_qlim, True, p.refine, tol, grid),
                 grain=4 if p.code == GENERAL else 64)


def _as_poses(a: np.ndarray) -> np.ndarray:
    """(N, 4, 4) targets as exact rigid transforms (checked; rotations projected on SO(3)).

    The criteria of :func:`_as_pose` per target, in one compiled pass
    (:func:`~serialkin.ik.analytic.subproblems.rigid_errors_into`).
    """
    from serialkin.ik.analytic.subproblems import rigid_errors_into

    T = np.ascontiguousarray(a, dtype=float)
    if not T.flags.writeable:  # one array type for the kernels, as in _as_pose
        T = T.copy()
    err = np.empty(T.shape[0])
    rigid_errors_into(T, err)
    if T.shape[0] and err.max() > ROTATION_TOL:
        for k in np.flatnonzero(err > ROTATION_TOL):
            check_transform(T[k], f"target[{k}]")  # raises with a message naming the fault
    off = err > 1e-13
    if off.any():  # nearest rotations (polar decomposition) where needed, exact last rows
        T = T.copy()
        U, _, Vt = np.linalg.svd(T[off, :3, :3])
        T[off, :3, :3] = U @ Vt
        T[off, 3] = (0.0, 0.0, 0.0, 1.0)
    return T


#: Fast-path entries per robot (:func:`_fast_entry`).
_FAST: PerObject[tuple] = PerObject()
#: The compiled entry points of each class's kernel, by (class code, refine) (resolved on
#: first use by :func:`_packed_entry`).
_SOLVE_PACKED: dict[tuple[int, bool], Any] = {}


def _packed_entry(code: int, refine: bool) -> Any:
    """The compiled entry point of ``for_class(code, refine).solve`` (see dispatch).

    Calling it skips numba's type dispatch (about 1 µs with its arguments); it is
    compiled for exactly the types every caller passes (:func:`dispatch.solve
    <serialkin.ik.analytic.dispatch.solve>` too): C-contiguous, aligned, writeable
    float64 targets stacked (4N, 4) (the fast path's (4, 4) pose as it comes, checked by
    :func:`ik_all` before the call), the read-only packed arrays of
    :func:`~serialkin.ik.analytic.dispatch.pack`, flat outputs and the range.
    """
    if (code, refine) not in _SOLVE_PACKED:
        from serialkin._jit import entry_point
        from serialkin.ik.analytic.dispatch import for_class

        def sig() -> tuple:  # numba's types, imported only when the kernel is loaded
            import numba

            Array = numba.types.Array
            f64, i64 = numba.float64, numba.int64
            return (Array(f64, 2, "C"), Array(i64, 1, "C", readonly=True),
                    Array(f64, 1, "C", readonly=True),
                    Array(numba.boolean, 1, "C", readonly=True), Array(f64, 2, "C"),
                    Array(i64, 1, "C"), Array(i64, 1, "C"), i64, i64)

        found, final = entry_point(for_class(code, refine).solve, sig)
        if not final:  # its Python function while it compiles: ask again next call
            return found
        _SOLVE_PACKED[code, refine] = found
    return _SOLVE_PACKED[code, refine]


def _fast_entry(robot: object) -> tuple:
    """The fast path's cached data for ``robot`` (default ``tol``, ``near_tol``, grid).

    ``(counts, entry point, I, D, B, (16, n), kind, mode, prepared)``: a scratch
    ``counts`` (1,) (written, never read: the kernel returns the count, so concurrent
    calls may share it), the packed arguments of
    :func:`~serialkin.ik.analytic.dispatch.solve`'s kernel, the shape of its output, the
    class solved and its :class:`_Prepared` data.
    """
    from serialkin.ik.analytic.general import DEFAULT_GRID

    p = _prepared(robot, NEAR_TOL)  # raises the ordinary path's errors
    I, D, B = _pack(p, p.solve_qlim, True, p.refine, 1e-8, DEFAULT_GRID)
    entry = (np.empty(1, dtype=np.int64), _packed_entry(p.code, p.refine), I, D, B,
             (MAX_ROWS, p.n), p.s.kind, p.mode, p)
    if (p.code, p.refine) in _SOLVE_PACKED:  # compiled: kept (else its Python, asked again)
        _FAST.set(robot, entry)
    return entry


_EMPTY = np.empty
_ZEROS = np.zeros
_ALL = AllSolutions._of
_CONV = MAX_ROWS + 1  # the kernels' convergence record: branches, then one flag per branch
_I64 = np.int64
_NDARRAY = np.ndarray
_F64 = np.dtype(np.float64)
_SHAPE44 = (4, 4)
#: The default of ``ik_all``'s ``tol`` (the fast path tests identity: an explicit
#: ``tol=1e-8`` takes the ordinary path, which gives the same rows).
_TOL = 1e-8


def ik_all(robot: Robot, target: object, *, tol: float = _TOL, all_turns: bool = False,
           free: Mapping[int, float] | None = None, near_tol: float = NEAR_TOL,
           grid: int | None = None, reference: object = None, weights: object = None,
           norm: str = "l2", report: bool = False,
           **options: Any) -> AllSolutions:
    """Every inverse-kinematics solution inside the joint limits (section 4.1).

    Which solver runs is decided from the joint axes (never the name):

    * a robot of a class in :data:`CLASSES`: its closed form (exact);
    * a 6-joint arm within ``near_tol`` of such a class (axes parallel / meeting up to
      ``near_tol`` rad, ``near_tol``·size m; e.g. a calibrated robot): the closed form of
      the idealised arm gives one candidate per branch, each refined by Newton's method
      on the true model to 1e-12 (``report=True`` says per branch whether it converged);
    * any other 6R arm: Raghavan–Roth elimination, with a 2-D search as its fallback
      (:mod:`serialkin.ik.analytic.general`; up to 16 solutions, each refined to 1e-12).

    Args:
        robot: the robot.
        target: (4, 4) tool pose in the world frame (base and tool transforms included),
            or a batch (..., 4, 4); on a
            planar arm whose axes are along the world z axis also ``(x, y)`` [m] (2R) or
            ``(x, y, φ)`` [m, m, rad], φ the heading ``atan2(R[1, 0], R[0, 0])`` of the
            tool x axis; on such a SCARA ``(x, y, z, φ)``; on an R R P arm a position
            ``(x, y, z)`` [m]. A pose's rotation may deviate from orthonormal by up to
            1e-6 (``check_transform``); it is replaced by the nearest rotation first.
        tol: verification tolerance: each returned row reproduces the target within
            ``tol``·max(1, robot size) metres and ``tol`` in every rotation entry.
        all_turns: also list every 2π-equivalent of each revolute angle inside the limits
            (single targets; joints without finite limits keep one value).
        free: ``{joint index: value}`` locks joints (e.g. one joint of a 7R arm: Panda,
            iiwa); the rest is solved as above and the locked values are put back in
            the rows. Sweeping the value samples the self-motion manifold.
        near_tol: tolerance of the nearly-ideal test [rad; m per m of size]; 0 disables it.
        grid: nodes per searched joint of the general 6R search (default 24).
        reference: (n,) configuration: rows are shifted by 2π towards it (inside the
            limits) and sorted nearest first (per target in a batch; see
            :func:`sort_by_reference`); without it rows are sorted lexicographically.
        weights: (n,) weights of the distance to ``reference``.
        norm: 'l2' (weighted Euclidean) or 'linf' (weighted max) distance.
        report: also say, per solution, whether it lies on a continuous family (a
            singular target; ``AllSolutions.continuous``).
        **options: none other are accepted (an unknown name raises InputError).

    Returns:
        :class:`AllSolutions`, for one target or a batch. For one target it is also the
        (k, n) array of its rows [rad / m], k >= 0 (k = 0: unreachable, or reachable only
        outside the joint limits), rows unique: ``len``, indexing, iteration and
        ``np.asarray`` give the rows.

    Raises:
        NoClosedFormError: no solver applies (not 6 joints and of no class), or the target
            leaves infinitely many solutions (a position-only target for a 6R arm).
        InputError: a target that is not a rigid transform / of an accepted shape, a
            non-positive ``tol`` or an unknown option.
    """
    if (type(target) is _NDARRAY and tol is _TOL and near_tol is NEAR_TOL and free is None
            and grid is None and reference is None and report is False and all_turns is False
            and not options and target.shape == _SHAPE44 and target.dtype is _F64
            and target.flags.carray):
        res = _ik_all_fast(robot, target)
        if res is not None:
            return res
        # not rigid to 1e-13: the ordinary path checks, projects or raises
    return _ik_all_checked(robot, target, _AllOptions(
        tol=tol, all_turns=all_turns, free=free, near_tol=near_tol, grid=grid,
        reference=reference, weights=weights, norm=norm, report=report, unknown=options))


def _ik_all_fast(robot: Robot, target: np.ndarray) -> AllSolutions | None:
    """:func:`ik_all` with its defaults for one C-contiguous, aligned, writeable float64 pose.

    The fast path: the rigidity check and the solve are one compiled call
    (``dispatch.for_class(...).solve``) on the robot's cached packed data; the rows are the ordinary
    path's, bit for bit. None when the target is not rigid to 1e-13 (the ordinary path
    then checks, projects or raises).
    """
    entry = _FAST.get(robot)
    if entry is None:
        entry = _fast_entry(robot)
    out = _EMPTY(entry[5])
    conv = _ZEROS(_CONV, _I64)  # False beyond the branches
    k = entry[1](target, entry[2], entry[3], entry[4], out, entry[0], conv, 0, 1)
    if k == -1:
        return None
    if entry[7] != "near":
        return _ALL(out[:k], k, conv, entry[6], entry[7])
    from serialkin.ik.analytic.general import DEFAULT_GRID  # a nearly ideal arm

    rows = _near_rows(robot, entry[8], target, out[:k], conv, _TOL, DEFAULT_GRID)
    return _ALL(rows, rows.shape[0], conv, entry[6], entry[7])


@dataclass(frozen=True, eq=False)
class _AllOptions:
    """The keyword arguments of one :func:`ik_all` call, as given (same names, unchecked).

    ``unknown`` holds the ``**options`` (none are accepted).
    """

    tol: float
    all_turns: bool
    free: Mapping[int, float] | None
    near_tol: float
    grid: int | None
    reference: object
    weights: object
    norm: str
    report: bool
    unknown: Mapping[str, Any]


def _check_grid(grid: object) -> int:
    """``grid`` of :func:`ik_all` as an int in 4..2000 (None: the default); raises InputError."""
    if grid is None:
        from serialkin.ik.analytic.general import DEFAULT_GRID

        grid = DEFAULT_GRID
    if isinstance(grid, bool) or not isinstance(grid, (int, np.integer)) or not 4 <= grid <= 2000:
        raise InputError(f"grid must be an int in 4..2000, got {short_repr(grid, 40)}")
    return int(grid)


def _ik_all_checked(robot: Robot, target: object, o: _AllOptions) -> AllSolutions:
    """:func:`ik_all` past its fast path: check the options, then solve one target or a batch."""
    if o.unknown:
        raise InputError(f"unknown option(s) for ik_all: {', '.join(sorted(o.unknown))}; "
                         "accepted: tol, all_turns, free, near_tol, grid, reference, "
                         "weights, norm, report")
    if o.free is not None:
        solve = {"tol": o.tol, "all_turns": o.all_turns, "near_tol": o.near_tol,
                 "grid": o.grid, "report": o.report}
        return _ik_all_locked(robot, target, o.free, (o.reference, o.weights, o.norm), solve)
    near_tol = check_positive(o.near_tol, "near_tol", allow_zero=True)
    p = _prepared(robot, near_tol)
    tol = check_positive(o.tol, "tol")
    grid = _check_grid(o.grid)
    a = target if type(target) is np.ndarray else as_float_array(target, "target")
    if a.ndim >= 3 and a.shape[-2:] == (4, 4):
        if o.all_turns:
            raise InputError("all_turns applies to one target; for a batch, call ik_all per "
                             "target with all_turns=True")
        res = _ik_all_batch(p, robot, a, tol, grid, o.report)
        if o.reference is not None:
            res = _sort_batch(robot, res, o.reference, o.weights, o.norm)
        return res
    return _ik_all_one(p, robot, a, tol, grid, o.all_turns, o.reference, o.weights, o.norm,
                       o.report)


def _ik_all_locked(robot: Robot, target: object, free: object, order: tuple,
                   solve: dict[str, Any]) -> AllSolutions:
    """:func:`ik_all` with the joints of ``free`` locked: the reduced robot's rows, refilled.

    ``order`` is ``(reference, weights, norm)`` of the sorting, ``solve`` the options of
    the reduced robot's solve.
    """
    check_robot(robot)
    reference, weights, norm = order
    reduced, idx, vals = _locked(robot, free)
    res = ik_all(reduced, target, **solve)
    q = _insert_locked(res.q, idx, vals, robot.n)
    if np.ndim(res.count) == 0:  # one target
        if reference is not None:
            q = sort_by_reference(robot, q, reference, weights=weights, norm=norm)
        return res.replaced(q=q)
    q[np.arange(q.shape[-2]) >= np.asarray(res.count)[..., None]] = 0.0  # padding
    full = res.replaced(q=q)
    if reference is not None:
        full = _sort_batch(robot, full, reference, weights, norm)
    return full


def _ik_all_batch(p: Any, robot: Robot, a: np.ndarray, tol: float, grid: int,
                  report: bool) -> AllSolutions:
    """:func:`ik_all` of a batch of poses ``a`` (..., 4, 4) on the prepared structure ``p``."""
    lead = a.shape[:-2]
    T = _as_poses(a.reshape(-1, 4, 4))
    out, counts, conv = _solve_batch(p, robot, T, tol, grid)
    pn = _near_companion(robot) if p.mode == "general" else None
    if pn is not None:  # as _with_near, all targets in one batch
        near_out, near_counts, _ = _solve_batch(pn, robot, T, tol, grid)
        for i in range(T.shape[0]):
            rows = _merged(out[i, :counts[i]], _limited_rows(pn, near_out[i, :near_counts[i]]))
            if len(rows) != counts[i]:
                _put_rows(out, counts, i, rows)
    kmax = int(counts.max(initial=0))
    cont = None
    if report:
        cont = np.zeros((T.shape[0], kmax), dtype=bool)
        for i in range(T.shape[0]):
            for j in range(int(counts[i])):
                cont[i, j] = continuous_family(robot, T[i], out[i, j])
        cont = cont.reshape(lead + (kmax,))
    if p.mode == "near":  # doubtful refined branches: general search too; then limits
        for i in np.flatnonzero(_doubtful(p, out, conv, counts)):
            _put_rows(out, counts, i, _with_general(robot, T[i], out[i, :counts[i]], tol, grid))
        if p.limited:  # the limits, all targets at once: rows inside first, in order
            from serialkin.ik.analytic.subproblems import LIMIT_TOL

            lo, hi = p.qlim[:, 0], p.qlim[:, 1]
            keep = (np.arange(MAX_ROWS) < counts[:, None]) & np.all(
                (out >= lo - LIMIT_TOL) & (out <= hi + LIMIT_TOL), axis=2)
            order = np.argsort(~keep, axis=1, kind="stable")
            out = np.clip(np.take_along_axis(out, order[..., None], axis=1), lo, hi)
            counts = keep.sum(axis=1)
            out[np.arange(MAX_ROWS) >= counts[:, None]] = 0.0
        kmax = int(counts.max(initial=0))
    return _ALL(out[:, :kmax].reshape(lead + (kmax, p.n)), counts.reshape(lead),
                conv.reshape(lead + (MAX_ROWS + 1,)), p.s.kind, p.mode, cont)


def _ik_all_one(p: Any, robot: Robot, a: np.ndarray, tol: float, grid: int, all_turns: bool,
                reference: object, weights: object, norm: str, report: bool) -> AllSolutions:
    """:func:`ik_all` of one target ``a`` (a pose, or a planar / position target)."""
    T, check_rot = _parse_target(p, robot, a)
    out, k, conv = _solve_one(p, p.solve_qlim, T, check_rot, p.refine, tol, grid)
    sols = out[:k]
    if p.mode == "near":
        sols = _near_rows(robot, p, T, sols, conv, tol, grid)
    elif p.mode == "general" and check_rot:
        sols = _with_near(robot, T, sols, tol, grid)
    if all_turns and k:
        sols = _expand_turns(sols, p.revolute, p.qlim)
    if reference is not None:
        sols = sort_by_reference(robot, sols, reference, weights=weights, norm=norm)
    cont = None
    if report:
        cont = np.array([check_rot and p.n == 6 and continuous_family(robot, T, row)
                         for row in sols], dtype=bool)
    return _ALL(sols, sols.shape[0], conv, p.s.kind, p.mode, cont)
