"""Which of a joint's 2π-equivalent angles an IK answer gives: the one nearest a reference.

A revolute joint whose range is wider than a full turn (the UR arms' ±2π, an unlimited
joint) reaches the same pose at ``q_j`` and ``q_j ± 2π``; a numerical solver may end on
any of them. :func:`robot.ik <serialkin.ik.solve>` returns, per such joint, the
representative nearest ``q0`` (nearest zero without ``q0``) among those inside the
limits:

    q_j ← q_j + 2π·k,  k = clip(round((r_j − q_j) / 2π), k_min, k_max)

where ``round`` rounds half to even (``np.rint``: a value exactly half a turn from the
reference keeps the even number of turns, so ``q_j = 0`` stays 0 for ``r_j = π``) and
``[k_min, k_max]`` are the turns that keep ``q_j`` inside ``[lower_j, upper_j]``
(tolerance :data:`TOL` rad). Joints whose range is at most 2π, prismatic joints, a
value no turn brings inside its limits, and a value more than :data:`MAX_TURNS` turns
from its representative (e.g. 9e9 rad after a hostile start) are left as they are: ``2π``
is not a float, so moving by ``k`` turns also moves the angle by ``k·(2π − fl(2π))``
(2.4e-16 rad per turn) plus the rounding of ``q`` itself, which for a few turns leaves
the pose unchanged to ~1e-14 m and for a billion turns would not.

One implementation of the rule, :func:`turn_toward` (one joint, compiled), serves every
caller: the compiled IK loop (:func:`serialkin.ik._kernels.nearest_into`), the closed-form
method's choice among its solutions (:mod:`serialkin.ik.analytic.method`) and, through
:func:`nearest_turn`, any array from Python. Its arithmetic is rounded operation by
operation (no fused multiply-add), so every caller gets the same bits.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from serialkin._jit import entry_point, njit_exact

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


@njit_exact(cache=True)
def turn_toward(x, r, lower, upper):
    """The rule of the module docstring for one joint that may move: ``x + 2π·k`` or ``x``.

    Args:
        x: the joint's value [rad], finite.
        r: its reference [rad].
        lower: its lower limit [rad], −inf when open (or when limits are not kept).
        upper: its upper limit [rad], +inf when open.

    Returns:
        float: the representative; ``x`` itself (same bits) when no turn applies.
    """
    k = np.rint((r - x) / _TWO_PI)  # half to even
    k_min = np.ceil((lower - TOL - x) / _TWO_PI)  # ±inf for an open end
    k_max = np.floor((upper + TOL - x) / _TWO_PI)
    k = k if k > k_min else k_min  # clip(k, k_min, k_max), the bound on ties
    k = k if k < k_max else k_max
    if k_min <= k_max and abs(k) <= MAX_TURNS:
        return x + _TWO_PI * k
    return x


@njit_exact(cache=True)
def nearest_turn_rows(Q, R, lower, upper, wide, out):
    """:func:`turn_toward` on every ``wide`` joint of the rows ``Q``, into ``out``.

    Args:
        Q: (m, n) configurations [rad / m], finite.
        R: (m, n) or (1, n) references (one for all rows), or no rows for zeros.
        lower: (n,) lower limits, −inf when open.
        upper: (n,) upper limits, +inf when open.
        wide: (n,) bool, the joints that may move.
        out: (m, n) output.

    Returns:
        int: the first row nearest its reference, ``sqrt(Σ_j (out_ij − r_ij)²)`` summed
        left to right (numpy's sum for fewer than 8 joints); −1 without rows. What a
        caller choosing one of several solutions needs, for the cost of ``n`` products
        per row.
    """
    m, n = Q.shape
    best, index = np.inf, -1
    for i in range(m):
        s = 0.0
        for j in range(n):
            r = 0.0 if R.shape[0] == 0 else R[i if R.shape[0] > 1 else 0, j]
            x = Q[i, j]
            if wide[j]:
                x = turn_toward(x, r, lower[j], upper[j])
            out[i, j] = x
            d = x - r
            s = d * d if j == 0 else s + d * d
        dist = math.sqrt(s)
        if dist < best or index < 0:
            best, index = dist, i
    return index


def _rows_signature() -> tuple:
    """The numba types of :func:`nearest_turn_rows` as :func:`nearest_turn` calls it."""
    import numba

    Array, f64 = numba.types.Array, numba.float64
    rows = Array(f64, 2, "A", readonly=True)
    joints = Array(f64, 1, "A", readonly=True)
    return (rows, rows, joints, joints, Array(numba.boolean, 1, "A", readonly=True),
            Array(f64, 2, "C"))


#: [entry point of nearest_turn_rows] once compiled (see :func:`rows_entry`).
_ROWS: list[Any] = []
#: The reference "zeros" of :func:`nearest_turn_rows` (no rows).
NO_REFERENCE = np.zeros((0, 0))
NO_REFERENCE.setflags(write=False)


def rows_entry() -> Any:
    """The compiled entry point of :func:`nearest_turn_rows` (its Python while it compiles).

    Compiled for one set of types, whatever layout or writeability the caller's arrays
    have: float64 rows and limits of any strides (read only), a bool mask, a fresh
    C-contiguous output. Calling it skips numba's type dispatch and checks nothing: the
    caller passes exactly those dtypes and dimensions (:func:`nearest_turn` does).
    """
    if _ROWS:
        return _ROWS[0]
    function, final = entry_point(nearest_turn_rows, _rows_signature)
    if final:
        _ROWS.append(function)
    return function


def nearest_turn(q: np.ndarray, lower: np.ndarray, upper: np.ndarray, wide: np.ndarray,
                 reference: np.ndarray | None = None) -> np.ndarray:
    """``q`` with each ``wide`` joint moved by the whole turns that bring it nearest ``reference``.

    Pure: a new array, the inputs untouched. See the module docstring for the rule
    (:func:`turn_toward`, applied by the compiled :func:`nearest_turn_rows`).

    Args:
        q: (..., n) configurations [rad / m], finite.
        lower: (n,) lower limits, −inf when open.
        upper: (n,) upper limits, +inf when open.
        wide: (n,) bool, the joints that may move (:func:`wide_joints`).
        reference: (..., n) or (n,) configurations broadcastable against ``q``; None for
            zeros.

    Returns:
        (..., n) float64 array.

    Raises:
        ValueError: ``reference``, ``lower``, ``upper`` or ``wide`` does not broadcast
            to ``q``'s shape (its last dimension, for the last three).
    """
    q = np.asarray(q, dtype=np.float64)
    shape = q.shape
    out = np.empty(shape)
    if q.size == 0:
        return out
    n = shape[-1]
    lower = np.asarray(lower, dtype=np.float64)
    upper = np.asarray(upper, dtype=np.float64)
    wide = np.asarray(wide, dtype=np.bool_)
    if lower.shape != (n,) or upper.shape != (n,) or wide.shape != (n,):
        lower, upper, wide = (np.broadcast_to(a, (n,)) for a in (lower, upper, wide))
    if reference is None:
        R = NO_REFERENCE
    else:
        R = np.asarray(reference, dtype=np.float64)
        if R.shape != shape and R.shape != (n,):
            R = np.broadcast_to(R, shape)
        R = R.reshape(-1, n)
    rows_entry()(q.reshape(-1, n), R, lower, upper, wide, out.reshape(-1, n))
    return out
