"""Which of a joint's 2π-equivalent angles an IK answer gives: the one nearest a reference.

A revolute joint whose range is wider than a full turn (the UR arms' ±2π, an unlimited
joint) reaches the same pose at ``q_j`` and ``q_j ± 2π``; a numerical solver may end on
any of them. :func:`robot.ik <serialkin.ik.solve>` returns, per such joint, the
representative nearest ``q0`` (nearest zero without ``q0``) among those inside the
limits:

    q_j ← q_j + 2π·k,  k = clip(round((r_j − q_j) / 2π), k_min, k_max)

where ``[k_min, k_max]`` are the turns that keep ``q_j`` inside ``[lower_j, upper_j]``
(tolerance :data:`TOL` rad). Joints whose range is at most 2π, prismatic joints, a
value no turn brings inside its limits, and a value more than :data:`MAX_TURNS` turns
from its representative (e.g. 9e9 rad after a hostile start) are left as they are: ``2π``
is not a float, so moving by ``k`` turns also moves the angle by ``k·(2π − fl(2π))``
(2.4e-16 rad per turn) plus the rounding of ``q`` itself, which for a few turns leaves
the pose unchanged to ~1e-14 m and for a billion turns would not.
"""

from __future__ import annotations

import math

import numpy as np

#: Tolerance on the limits when choosing a turn [rad]: a solver's answer may sit on a
#: limit to rounding.
TOL = 1e-12
#: Most whole turns a value is moved by (see the module docstring).
MAX_TURNS = 16
_TWO_PI = 2.0 * math.pi


def wide_joints(lower: np.ndarray, upper: np.ndarray, revolute: np.ndarray) -> np.ndarray:
    """(n,) bool: revolute joints whose range ``upper − lower`` exceeds 2π (or is unbounded).

    Args:
        lower: (n,) lower limits [rad / m], −inf when open.
        upper: (n,) upper limits [rad / m], +inf when open.
        revolute: (n,) bool, True for revolute joints.
    """
    return np.asarray(revolute, dtype=bool) & (np.asarray(upper) - np.asarray(lower) > _TWO_PI)


def nearest_turn(q: np.ndarray, lower: np.ndarray, upper: np.ndarray, wide: np.ndarray,
                 reference: np.ndarray | None = None) -> np.ndarray:
    """``q`` with each ``wide`` joint moved by the whole turns that bring it nearest ``reference``.

    Pure: a new array, the inputs untouched. See the module docstring for the rule.

    Args:
        q: (..., n) configurations [rad / m], finite.
        lower: (n,) lower limits, −inf when open.
        upper: (n,) upper limits, +inf when open.
        wide: (n,) bool, the joints that may move (:func:`wide_joints`).
        reference: (..., n) or (n,) configurations broadcastable against ``q``; None for
            zeros.

    Returns:
        (..., n) float64 array.
    """
    q = np.array(q, dtype=np.float64)
    if not np.any(wide):
        return q
    ref = 0.0 if reference is None else np.asarray(reference, dtype=np.float64)
    with np.errstate(invalid="ignore"):  # ±inf limits give ±inf bounds on k: fine
        k = np.round((ref - q) / _TWO_PI)
        k_min = np.ceil((lower - TOL - q) / _TWO_PI)
        k_max = np.floor((upper + TOL - q) / _TWO_PI)
    k = np.clip(k, k_min, k_max)
    # a value outside its limits with no turn inside, or too many turns away: kept
    ok = wide & (k_min <= k_max) & (np.abs(k) <= MAX_TURNS)
    return np.where(ok, q + _TWO_PI * np.where(ok, k, 0.0), q)
