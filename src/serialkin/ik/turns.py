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
    q = np.asarray(q, dtype=np.float64)
    wide = np.asarray(wide, dtype=bool)
    if not wide.any():
        return q.copy()
    ref = 0.0 if reference is None else np.asarray(reference, dtype=np.float64)
    n = q.shape[-1] if q.ndim else -1
    if (q.ndim == 1 and (np.ndim(ref) == 0 or np.shape(ref) == (n,)) and wide.shape == (n,)
            and isinstance(lower, np.ndarray) and isinstance(upper, np.ndarray)
            and lower.shape == upper.shape == (n,)):
        # one configuration: joint by joint, cheaper than a dozen numpy calls on n values
        return _nearest_turn_row(q, lower, upper, wide, ref)
    with np.errstate(invalid="ignore"):  # ±inf limits give ±inf bounds on k: fine
        k = np.rint((ref - q) / _TWO_PI)  # np.round to 0 decimals, half to even
        k_min = np.ceil((lower - TOL - q) / _TWO_PI)
        k_max = np.floor((upper + TOL - q) / _TWO_PI)
    k = k.clip(k_min, k_max)  # np.clip, without its wrapper
    # a value outside its limits with no turn inside, or too many turns away: kept
    ok = wide & (k_min <= k_max) & (np.abs(k) <= MAX_TURNS)
    return np.where(ok, q + _TWO_PI * np.where(ok, k, 0.0), q)


def _nearest_turn_row(q: np.ndarray, lower: np.ndarray, upper: np.ndarray, wide: np.ndarray,
                      ref: np.ndarray | float) -> np.ndarray:
    """:func:`nearest_turn` of one configuration ``q`` (n,), joint by joint in Python floats.

    The same rule and the same IEEE operations in the same order as the array version
    (whose dozen numpy calls cost more than the arithmetic on a few values), down to the
    sign of a zero: Python's ``round`` rounds half to even as ``np.rint`` does, a zero
    takes the sign ``np.rint``, ``np.ceil`` and ``np.floor`` give it (``copysign``), and
    on a tie ``np.clip`` returns the bound, as here. An infinite bound stays infinite.
    ``tests/ik/test_turns.py`` checks both versions against each other. ``ref`` is
    (n,) or a scalar.
    """
    out = q.tolist()
    refs = ref.tolist() if np.ndim(ref) == 1 else None
    r = float(ref) if refs is None else 0.0  # a scalar reference (zero without q0)
    lows, highs = lower.tolist(), upper.tolist()
    for j, moves in enumerate(wide.tolist()):
        if not moves:
            continue
        x = out[j]
        t = ((r if refs is None else refs[j]) - x) / _TWO_PI
        low, high = lows[j] - TOL, highs[j] + TOL
        if -0.5 < t < 0.5 and low <= x <= high and x != 0.0:
            continue  # k = ±0 inside [k_min <= 0, k_max >= 0]: x + 2π·(±0) is x
        k = round(t) or math.copysign(0.0, t)  # np.rint: -0.0 for t in [-0.5, 0)
        a = (low - x) / _TWO_PI
        b = (high - x) / _TWO_PI
        k_min = (math.ceil(a) or math.copysign(0.0, a)) if math.isfinite(a) else a
        k_max = (math.floor(b) or math.copysign(0.0, b)) if math.isfinite(b) else b
        k = k if k > k_min else k_min  # np.clip(k, k_min, k_max), the bound on ties
        k = k if k < k_max else k_max
        if k_min <= k_max and abs(k) <= MAX_TURNS:
            out[j] = x + _TWO_PI * k
    return np.array(out)
