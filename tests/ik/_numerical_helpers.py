"""Shared helpers for the CCD / FABRIK / BFGS / Powell / compare tests."""

from __future__ import annotations

import numpy as np

from serialkin import models
from serialkin.spatial.pose import pose_error


def well_conditioned_q(robot, count, seed, task="full", max_cond=15.0, margin=0.05):
    """``count`` configurations inside the shrunk limits with task condition number < max_cond.

    Targets away from singularities and workspace boundaries, where every method's
    documented tolerance applies.
    """
    rng = np.random.default_rng(seed)
    lo, hi = robot.sampling_limits().T
    span = hi - lo
    out = []
    for _ in range(1000 * count):
        q = lo + margin * span + (1 - 2 * margin) * span * rng.random(robot.n)
        if robot.condition_number(q, task) < max_cond:
            out.append(q)
            if len(out) == count:
                return np.array(out)
    raise RuntimeError(f"no configuration with condition number < {max_cond} for {task!r}")


def selected_errors(robot, q, T_target, weights):
    """(position error [m], orientation error [rad]) of FK(q) over the selected rows."""
    e = pose_error(robot.fk(q), T_target)
    sel = np.asarray(weights) > 0
    return float(np.linalg.norm(e[:3][sel[:3]])), float(np.linalg.norm(e[3:][sel[3:]]))


def assert_solution(robot, res, T_target, weights, tol):
    """The returned q reproduces the target within tol and lies inside the limits."""
    assert res.success, res.reason
    pe, oe = selected_errors(robot, res.q, T_target, weights)
    assert pe <= tol * 1.0000001, pe
    assert oe <= tol * 1.0000001, oe
    assert robot.within_limits(res.q, 1e-12)


def assert_fails_only_outside_limits(method, **options):
    """A planar 2-link target reachable only outside the limits fails; q stays inside them.

    The limits [0, 0.5] rad exclude the configuration (-1, -1) that reaches the target;
    ``options`` go to ``robot.ik`` (seed 0).
    """
    robot = models.planar(2, qlim=(0.0, 0.5))
    T = robot.fk(np.array([-1.0, -1.0]))
    res = robot.ik(T[:2, 3], method=method, seed=0, **options)
    assert not res.success and res.reason
    assert robot.within_limits(res.q)


def assert_bounded_work(res, method, restarts, max_iter=None):
    """The solve stopped within its budget (restarts, iterations).

    At most ``restarts`` restarts and ``(restarts + 1) · max_iter`` iterations plus one
    polishing attempt: what a wall-clock bound stood for (no hang, no runaway loop),
    checked without a clock (timings live in ``benchmarks/``).
    """
    from serialkin.ik.registry import get_method

    budget = max_iter if max_iter is not None else get_method(method).max_iter
    assert res.restarts <= restarts
    assert res.iterations <= (restarts + 2) * budget
