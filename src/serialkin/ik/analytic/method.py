"""The IK method ``'analytic'``: every closed-form solution, then the one nearest q0.

The closed-form family registers and implements its own method here, at import
(:mod:`serialkin.ik` imports this module): ``robot.ik(target,
method="analytic", q0=...)`` solves with :func:`serialkin.ik.analytic.ik_all` and
returns the solution nearest ``q0`` (revolute joints moved by 2π towards ``q0`` inside
their limits, :func:`serialkin.ik.turns.nearest_turn`; weighted L2 or L∞ distance),
or nearest the middle of the joint ranges without ``q0``; a batch of targets is one
``ik_all`` batch. The common single call (one pose, default options) takes
:func:`analytic_solve_pose`: the same answer without the batch's array bookkeeping.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

import numpy as np

from serialkin._memo import PerObject
from serialkin.ik.analytic import (
    NEAR_TOL,
    _distance_args,
    _toward,
    ik_all,
    reference_distance,
)
from serialkin.ik.registry import MethodSpec, register_method
from serialkin.ik.turns import rows_entry
from serialkin.model.robot import Robot

#: Options of the method, with their defaults (passed on to ``ik_all``).
OPTIONS: dict[str, Any] = {"weights": None, "norm": "l2", "near_tol": NEAR_TOL, "grid": None}


#: Why a target has no answer.
NOT_FOUND = ("no closed-form solution inside the joint limits: the target is out of reach or "
             "reachable only outside the joint limits")


def _every_solution(robot: Robot, T: np.ndarray, kind: str,
                    options: Mapping[str, Any]) -> tuple[np.ndarray, np.ndarray]:
    """Every solution of each target: rows (N, k_max, n), zero padded, and counts (N,).

    Several pose targets go to ``ik_all`` as one batch (every core); one pose, and the
    other kinds, whose target is a vector, one by one (``ik_all``'s single-target path).
    """
    opts = {"near_tol": options["near_tol"], "grid": options["grid"]}
    if kind == "pose" and T.shape[0] > 1:
        res = ik_all(robot, T, **opts)
        return np.asarray(res.q, dtype=np.float64), np.asarray(res.count).reshape(-1)
    rows = []
    for Tk in T:
        if kind == "pose":
            target: object = Tk
        elif kind == "position":
            target = Tk[:3, 3].copy()
        elif kind == "planar":
            target = Tk[:2, 3].copy()
        else:
            target = np.array([Tk[0, 3], Tk[1, 3], np.arctan2(Tk[1, 0], Tk[0, 0])])
        rows.append(np.asarray(ik_all(robot, target, **opts), dtype=np.float64)
                    .reshape(-1, robot.n))
    counts = np.array([len(r) for r in rows], dtype=np.int64)
    Q = np.zeros((len(rows), max(1, int(counts.max(initial=0))), robot.n))
    for i, r in enumerate(rows):
        Q[i, :len(r)] = r
    return Q, counts


#: Per robot: (middle of the joint ranges, lower limits, upper limits, revolute), read-only.
_LIMITS: PerObject[tuple] = PerObject()


def _limits(robot: Robot) -> tuple:
    """``(middle, lower, upper, revolute)`` of ``robot``, each (n,), computed once per robot.

    ``middle`` is the middle of the sampling box (the reference without q0).
    """
    lim = _LIMITS.get(robot)
    if lim is None:
        mid = robot.sampling_limits().mean(axis=1)
        mid.setflags(write=False)
        lim = _LIMITS.set(robot, (mid, robot.qlim[:, 0], robot.qlim[:, 1], robot.revolute))
    return lim


def _middle(robot: Robot) -> np.ndarray:
    """The (n,) middle of ``robot``'s sampling box (computed once per robot)."""
    return _limits(robot)[0]


def analytic_solve(robot: Robot, T: np.ndarray, kind: str, q0: np.ndarray | None,
                   options: Mapping[str, Any]) -> tuple[np.ndarray, np.ndarray, str]:
    """Solve the targets ``T`` (N, 4, 4) by ``ik_all``, each answer the nearest ``q0``.

    The reference ``r`` is ``q0`` (N, n) or the middle of the joint ranges; each target's
    solutions are shifted by 2π towards it (:func:`~serialkin.ik.turns.nearest_turn`)
    and the nearest in the ``weights``/``norm`` distance
    (:func:`~serialkin.ik.analytic.reference_distance`) is returned. All targets at once:
    one ``ik_all`` batch and array operations, no loop per target for pose targets.

    Returns:
        ``(q (N, n), found (N,) bool, reason)``: a target without any solution inside
        the limits answers its reference, ``found`` False and ``reason`` says why.
    """
    mid = _middle(robot)
    ref = np.broadcast_to(mid, (T.shape[0], robot.n)) if q0 is None else q0
    _, w = _distance_args(robot, mid, options["weights"], options["norm"])
    Q, counts = _every_solution(robot, T, kind, options)
    valid = np.arange(Q.shape[1]) < counts[:, None]  # (N, k_max)
    shifted = _toward(robot, Q, ref[:, None, :])
    dist = np.where(valid, reference_distance(shifted - ref[:, None, :], w, options["norm"]),
                    np.inf)
    best = np.take_along_axis(shifted, dist.argmin(axis=1)[:, None, None], axis=1)[:, 0]
    found = counts > 0
    return np.where(found[:, None], best, ref), found, NOT_FOUND


def analytic_solve_pose(robot: Robot, T: np.ndarray,
                        q0: np.ndarray | None) -> tuple[np.ndarray, bool, str]:
    """:func:`analytic_solve` of one pose ``T`` (4, 4) with the default options.

    The rows of ``ik_all``, then one compiled call
    (:func:`~serialkin.ik.turns.nearest_turn_rows`) that moves each revolute joint of
    each row by the turns nearest the reference (``q0`` (n,) or the middle of the
    ranges) and returns the first row of least L2 distance: the same operations on the
    same values as :func:`analytic_solve`, so the same answer bit for bit (unit weights
    multiply by 1.0, which changes no value; the closed-form classes have at most 6
    joints, whose sum numpy takes left to right as the kernel does).

    Returns:
        ``(q (n,), found, reason)``: without any solution, a copy of the reference.
    """
    mid, lower, upper, revolute = _limits(robot)
    ref = mid if q0 is None else q0
    rows = np.asarray(ik_all(robot, T).q, dtype=np.float64)
    if rows.shape[0] == 0:
        return ref.copy(), False, NOT_FOUND
    shifted = np.empty(rows.shape)
    best = rows_entry()(rows, ref.reshape(1, -1), lower, upper, revolute, shifted)
    return shifted[best].copy(), True, NOT_FOUND


def register_analytic() -> None:
    """Register the method ``'analytic'`` (done once, when this module is imported)."""
    register_method(MethodSpec(
        name="analytic", family="analytic",
        summary="all closed-form solutions (section 4.1; general 6R by search), the one "
                "nearest q0",
        limits="only solutions inside the limits are returned by ik_all",
        max_iter=1, restarts=0, options=dict(OPTIONS), solve=analytic_solve,
        solve_pose=analytic_solve_pose,
    ))


register_analytic()
