"""Every solution of a 7R arm along a sweep of one joint, with the branches connected.

For a 7R arm without a spherical shoulder and wrist (Panda, xArm7, Gen3 with offsets)
there is no closed-form arm angle (:mod:`~serialkin.ik.analytic.arm_angle`); the
one-parameter family of configurations reaching a pose T is followed instead by locking
one joint j at a value v and solving the remaining 6R arm for every solution
(``ik_all(T, free={j: v})``, the locked-joint solver), for v on a grid. Rows at
neighbouring values are connected into *branches* by minimum-cost matching (the
assignment problem, scipy's ``linear_sum_assignment``) on the largest joint change,
as ssik's 7R sweep and Descartes' planning graph connect samples; a branch ends where
its row disappears (a limit, a singularity, out of reach) or would have to jump.

Units: radians (revolute joints), metres (prismatic).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy.optimize import linear_sum_assignment

from serialkin._checks import check_transform
from serialkin.errors import InputError
from serialkin.ik.analytic import ik_all
from serialkin.model.robot import Robot
from serialkin.spatial.rotations import wrap_angle
from serialkin.spatial.transforms import inv_transform

__all__ = ["JointSweep", "joint_sweep"]


@dataclass(frozen=True, eq=False)
class JointSweep:
    """The solutions of one pose along a sweep of one joint (what :func:`joint_sweep` returns).

    Attributes:
        joint: the swept joint's index (0-based).
        values: (m,) the swept joint's values [rad or m], increasing.
        q: (m, b, n) joint values of branch k at value i, where ``valid[i, k]``; zeros
            elsewhere (never NaN).
        valid: (m, b) bool, branch k has a configuration at value i. Each branch is one
            contiguous run of values along which its joints change continuously (at most
            ``max_jump`` between neighbouring values).
        feasible: [(v_lo, v_hi), ...] the closed intervals of values at which some
            configuration reaches the pose inside the limits, ends refined by bisection
            to 1e-9 (their width is exact to the refinement; a stretch narrower than the
            grid step can be missed).
        max_jump: the largest joint change [rad or m] allowed between neighbours.
    """

    joint: int
    values: np.ndarray
    q: np.ndarray
    valid: np.ndarray
    feasible: list[tuple[float, float]]
    max_jump: float

    @property
    def branches(self) -> int:
        """The number of branches b."""
        return self.valid.shape[1]

    def branch(self, k: int) -> tuple[np.ndarray, np.ndarray]:
        """Branch k as (values (r,), configurations (r, n)) over its run of values."""
        rows = np.flatnonzero(self.valid[:, k])
        return self.values[rows], self.q[rows, k]


def joint_sweep(robot: Robot, T: object, joint: int, values: object = None, *,
                resolution: float = math.radians(1.0), max_jump: float = 0.5) -> JointSweep:
    """Every configuration reaching pose T as joint ``joint`` sweeps its range, as branches.

    Args:
        robot: a 7-joint arm whose other six joints have a closed form or the general 6R
            solver (:func:`serialkin.ik.analytic.ik_all` with ``free``).
        T: (4, 4) target pose of the tool in the base frame.
        joint: index of the swept joint (0-based).
        values: (m,) increasing values to sweep [rad or m]; default the joint's limits
            (−π..π when unlimited) at steps of ``resolution``.
        resolution: the default grid's step [rad or m].
        max_jump: the largest change of any joint between neighbouring values for two
            rows to be one branch [rad or m].

    Returns:
        :class:`JointSweep`.

    Raises:
        InputError: T is not one rigid transform, the joint index is out of range, the
            values are not finite and increasing, or a step or jump is not positive.
        NoClosedFormError: the arm with the joint locked has no all-solutions solver.
    """
    Tt = check_transform(T, "T")
    if Tt.shape != (4, 4):
        raise InputError(f"T must be one (4, 4) pose, got shape {Tt.shape}")
    n = robot.n
    if isinstance(joint, bool) or not isinstance(joint, (int, np.integer)) \
            or not 0 <= int(joint) < n:
        raise InputError(f"joint must be a joint index in 0..{n - 1}, got {joint!r}")
    j = int(joint)
    if not (max_jump > 0.0 and math.isfinite(max_jump)):
        raise InputError(f"max_jump must be a positive length or angle, got {max_jump!r}")
    v = _values(robot, j, values, resolution)
    rows = _rows(robot, Tt, j, v)
    q, valid = _connect(rows, n, max_jump)

    def exists(x: np.ndarray) -> np.ndarray:
        return np.array([len(r) > 0 for r in _rows(robot, Tt, j, x)], dtype=bool)

    ways = _BATCH_WAYS if j in (0, n - 1) else 2  # a batch solve costs about one solve
    return JointSweep(joint=j, values=v, q=q, valid=valid,
                      feasible=_intervals(v, [len(r) > 0 for r in rows], exists, ways),
                      max_jump=float(max_jump))


def _rows(robot: Robot, T: np.ndarray, j: int, v: np.ndarray) -> list[np.ndarray]:
    """``ik_all(robot, T, free={j: x}).q`` for every value x of v (m,): m arrays (k, n).

    The first or the last joint moves the base or the tool end of the others rigidly:
    ``fk(q) = fk(q with q_j = 0)·D(q_j)`` for the last joint, with ``D(x) =
    fk(0)⁻¹·fk(x·e_j)``, and ``fk(q) = G(q_j)·fk(q with q_j = 0)`` for the first, with
    ``G(x) = fk(x·e_j)·fk(0)⁻¹``. Locking it at 0 then leaves one reduced arm for every
    value, whose targets ``T·D(x)⁻¹`` (or ``G(x)⁻¹·T``) are solved as one batch (one
    reduced robot, one compiled call); the locked column is then set to x. A joint in
    between changes the reduced arm's geometry: one locked solve per value.
    """
    n = robot.n
    if j not in (0, n - 1):
        return [np.asarray(ik_all(robot, T, free={j: float(x)}).q) for x in v]
    Q = np.zeros((len(v), n))
    Q[:, j] = v
    F = robot.fk(Q)                                       # (m, 4, 4)
    inv0 = inv_transform(robot.fk(np.zeros(n)), check=False)
    moved = inv_transform(inv0 @ F if j == n - 1 else F @ inv0, check=False)
    targets = T @ moved if j == n - 1 else moved @ T
    res = ik_all(robot, targets, free={j: 0.0})
    out = []
    for i, k in enumerate(np.asarray(res.count).tolist()):
        r = res.q[i, :k].copy()
        r[:, j] = v[i]
        out.append(r)
    return out


def _values(robot: Robot, j: int, values: object, resolution: float) -> np.ndarray:
    if values is not None:
        v = np.asarray(values, dtype=float).reshape(-1)
        if v.size == 0 or not np.all(np.isfinite(v)) or np.any(np.diff(v) <= 0.0):
            raise InputError("values must be a non-empty increasing sequence of finite joint "
                             f"values, got {np.asarray(values).tolist()!r}")
        return v
    if not (resolution > 0.0 and math.isfinite(resolution)):
        raise InputError(f"resolution must be a positive step, got {resolution!r}")
    lo, hi = robot.qlim[j]
    if not (np.isfinite(lo) and np.isfinite(hi)):
        lo, hi = -math.pi, math.pi
    m = max(2, int(math.ceil((hi - lo) / resolution)) + 1)
    return np.linspace(lo, hi, m)


def _distance(A: np.ndarray, B: np.ndarray) -> np.ndarray:
    """(a, b) the largest change of any joint between rows of A and B (angles wrapped)."""
    return np.abs(wrap_angle(A[:, None, :] - B[None, :, :])).max(axis=2)


def _connect(rows: list[np.ndarray], n: int, max_jump: float) -> tuple[np.ndarray, np.ndarray]:
    """Branches through the rows of each value: (m, b, n) and (m, b) valid."""
    track_of: list[np.ndarray] = []   # per value: the branch index of each row
    count = 0
    prev = np.zeros((0, n))
    for cur in rows:
        ids = np.full(len(cur), -1)
        if len(prev) and len(cur):
            cost = _distance(prev, cur)
            a, b = linear_sum_assignment(cost)
            ok = cost[a, b] <= max_jump
            ids[b[ok]] = track_of[-1][a[ok]]
        for i in np.flatnonzero(ids < 0):
            ids[i] = count
            count += 1
        track_of.append(ids)
        prev = cur
    m = len(rows)
    q = np.zeros((m, count, n))
    valid = np.zeros((m, count), dtype=bool)
    for i, (cur, ids) in enumerate(zip(rows, track_of)):
        q[i, ids] = cur
        valid[i, ids] = True
    return q, valid


#: Parts each bracket of an interval end is cut into per round when the values are solved
#: as one batch (the first or last joint swept): 16 parts, 4 bits a round instead of 1.
_BATCH_WAYS = 16


def _intervals(v: np.ndarray, some: list[bool], exists, ways: int) -> list[tuple[float, float]]:
    """Closed runs of values with a solution; inner ends refined to 1e-9 (:func:`_refine`).

    ``exists(x)`` says for each value of x (k,) whether a solution exists there.
    """
    runs, ends = [], []
    i, m = 0, len(v)
    while i < m:
        if not some[i]:
            i += 1
            continue
        k = i
        while k + 1 < m and some[k + 1]:
            k += 1
        runs.append((i, k))
        if i > 0:
            ends.append((v[i - 1], v[i]))
        if k < m - 1:
            ends.append((v[k + 1], v[k]))
        i = k + 1
    refined = iter(_refine(ends, exists, ways))
    return [(float(v[i] if i == 0 else next(refined)),
             float(v[k] if k == m - 1 else next(refined))) for i, k in runs]


def _refine(ends: list[tuple[float, float]], exists, ways: int) -> list[float]:
    """The feasible end of each (infeasible value, feasible value) bracket, to 1e-9.

    Every round cuts each bracket wider than 1e-9 into ``ways`` equal parts and keeps the
    part where, walking from the infeasible end, the first feasible point is met; all
    brackets' points are solved in one ``exists`` call. With ``ways = 2``: bisection.
    """
    if not ends:
        return []
    bad = np.array([e[0] for e in ends], dtype=float)
    good = np.array([e[1] for e in ends], dtype=float)
    t = np.arange(1, ways) / ways
    while True:
        open_ = np.flatnonzero(np.abs(good - bad) > 1e-9)
        if not len(open_):
            return good.tolist()
        b, g = bad[open_], good[open_]
        pts = b[:, None] + (g - b)[:, None] * t                  # (e, ways − 1)
        if ways == 2:
            pts = 0.5 * (b + g)[:, None]                         # bisection's midpoint
        ok = exists(pts.reshape(-1)).reshape(pts.shape)
        first = np.where(ok.any(axis=1), ok.argmax(axis=1), pts.shape[1])
        rows = np.arange(len(open_))
        new_bad = np.where(first > 0, pts[rows, np.maximum(first - 1, 0)], b)
        new_good = np.where(first < pts.shape[1], pts[rows, np.minimum(first, pts.shape[1] - 1)],
                            g)
        bad[open_], good[open_] = new_bad, new_good
