"""Planar serial arms with revolute joints about parallel z axes (chapter sections 4-5).

Every link of a planar arm lies in the xy plane; in standard DH each row is
``a = L_i, alpha = 0, d = 0, theta = q_i``, so the tool position is
``x = Σ L_i cos(q_1 + … + q_i)``, ``y = Σ L_i sin(q_1 + … + q_i)`` (eqs 21-22, 30-31).
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from serialkin._checks import MAX_JOINTS, as_float_array, check_int, short_repr
from serialkin.errors import InputError
from serialkin.model.dh import DHLink
from serialkin.model.limits import limits_table
from serialkin.model.robot import Robot

PLANAR_SOURCE = "chapter sections 4-5 (eqs 21-22, 30-31): standard DH rows (L_i, 0, 0, q_i)"


def _lengths(n: int, lengths: float | Sequence[float]) -> np.ndarray:
    arr = as_float_array(lengths, "lengths")
    if arr.ndim == 0:
        arr = np.full(n, float(arr))
    if arr.shape != (n,):
        raise InputError(f"lengths must be one number or {n} numbers, got shape {arr.shape}")
    if np.any(arr < 0):
        raise InputError(f"lengths must be non-negative [m], got {arr.tolist()}")
    return arr


def _limits(n: int, qlim: object) -> np.ndarray:
    if qlim is None:
        return np.tile([-np.inf, np.inf], (n, 1))
    return limits_table(qlim, n)


def planar(
    n: int,
    lengths: float | Sequence[float] = 1.0,
    qlim: object = None,
    *,
    name: str | None = None,
) -> Robot:
    """Build a planar arm of ``n`` revolute joints (any n, any link lengths).

    Args:
        n: number of links/joints, 1 to :data:`~serialkin._checks.MAX_JOINTS` (10 000).
        lengths: one link length for all links, or ``n`` lengths [m].
        qlim: None (unlimited), one (lower, upper) pair for every joint, or (n, 2) [rad].
        name: robot name (default ``planar<n>``).

    Returns:
        A standard-DH :class:`~serialkin.model.robot.Robot` whose tool sits at the tip of
        link ``n``, with one collision capsule per link (radius 5 % of its length,
        :func:`~serialkin.collision.robots.planar_collision_model`).

    Raises:
        InputError: n < 1 or above MAX_JOINTS, wrong number of lengths, negative or
            too large lengths, bad ``qlim`` shape.
        RobotDefinitionError: a joint limit with lower > upper.

    Example:
        >>> robot = planar(3, [1.0, 0.8, 0.5])
        >>> robot.fk([0.0, 0.0, 0.0])[:3, 3].tolist()
        [2.3, 0.0, 0.0]
    """
    n = check_int(n, "n", minimum=1, maximum=None)
    if n > MAX_JOINTS:
        raise InputError(f"n = {short_repr(n)}: a robot has at most {MAX_JOINTS} joints")
    L = _lengths(n, lengths)
    lim = _limits(n, qlim)
    rows = [
        DHLink(a=float(L[i]), alpha=0.0, d=0.0, theta=0.0, type="R",
               qlim=(float(lim[i, 0]), float(lim[i, 1])), name=f"q{i + 1}")
        for i in range(n)
    ]
    from serialkin.collision.robots import planar_collision_model

    robot = Robot.from_dh(rows, "standard", name=name or f"planar{n}", source=PLANAR_SOURCE)
    return robot.with_collision(planar_collision_model(L))
