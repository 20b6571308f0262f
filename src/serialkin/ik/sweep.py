"""Every solution of a 7R arm along a sweep of one joint, with the branches connected.

For a 7R arm without a spherical shoulder and wrist (Panda, xArm7, Gen3 with offsets)
there is no closed-form arm angle (:mod:`~serialkin.ik.analytic.arm_angle`); the
one-parameter family of configurations reaching a pose T is followed instead by locking
one joint j at a value v and solving the remaining 6R arm for every solution
(``ik_all(T, free={j: v})``, the locked-joint solver), for v on a grid. Rows at
neighbouring values are connected into *branches* by minimum-cost matching (the
assignment problem, as ssik's 7R sweep and Descartes' planning graph connect samples)
on the largest joint change; a branch ends where its row disappears (a limit, a
singularity, out of reach) or would have to jump.

The first or the last joint moves the base or the tool end of the others rigidly, so
the arm with it locked at 0 is one 6R arm for every value, and the whole grid is one
batch of targets (:func:`_targets`). Matching rows is an assignment problem per value;
when each row's nearest row at the next value is strictly nearest and no two rows share
it, that choice is the unique optimum and no assignment is solved (:func:`_connect`).
The ends of the feasible intervals are found by safeguarded interpolation
(:func:`_refine`): a joint crossing its limit is a root of a smooth margin, a pair of
solutions meeting at the edge of reach closes like √(v* − v).

Units: radians (revolute joints), metres (prismatic).
"""

from __future__ import annotations

import functools
import math
from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np
from scipy.optimize import linear_sum_assignment

from serialkin._checks import check_transform, readonly
from serialkin._jit import entry_point, njit
from serialkin._memo import PerObject
from serialkin.errors import InputError
from serialkin.ik.analytic import _locked, ik_all
from serialkin.model.robot import Robot
from serialkin.spatial.kernels import wrap_pi

__all__ = ["JointSweep", "joint_sweep"]

#: Width [rad or m] to which the ends of the feasible intervals are refined.
END_TOL = 1e-9
#: Tolerance on the limits in a refinement probe [rad or m]: the closed-form solvers'.
_PROBE_LIMIT_TOL = 1e-10


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
            configuration reaches the pose inside the limits, ends refined to
            :data:`END_TOL` (a stretch narrower than the grid step can be missed).
            Computed at its first read (a few rounds of locked solves near each end:
            about 1 ms on a Panda, as long as the sweep itself), then kept.
        max_jump: the largest joint change [rad or m] allowed between neighbours.
    """

    joint: int
    values: np.ndarray
    q: np.ndarray
    valid: np.ndarray
    max_jump: float
    #: what :attr:`feasible` is computed from: () -> [(v_lo, v_hi), ...]
    _intervals: Callable[[], list[tuple[float, float]]] = field(repr=False, compare=False)

    @functools.cached_property
    def feasible(self) -> list[tuple[float, float]]:
        """The feasible intervals, ends refined to :data:`END_TOL` (see the class)."""
        return self._intervals()

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
    Q, count = _solve(robot, Tt, j, v, limited=True)
    q, valid = _connect(Q, count, float(max_jump))

    return JointSweep(joint=j, values=v, q=q, valid=valid, max_jump=float(max_jump),
                      _intervals=functools.partial(_feasible, robot, Tt, j, v, Q, count))


def _feasible(robot: Robot, T: np.ndarray, j: int, v: np.ndarray, Q: np.ndarray,
              count: np.ndarray) -> list[tuple[float, float]]:
    """:attr:`JointSweep.feasible` of the sweep of joint j at values v (rows Q, count).

    A module-level function bound by ``functools.partial``, so that a sweep pickles
    (to a Dask worker, say) before and after its intervals are read.
    """
    def probe(x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        return _solve(robot, T, j, x, limited=False)

    return _intervals(robot, v, Q, count, probe, j in (0, robot.n - 1))


# ------------------------------------------------------------------ the locked solves

def _solve(robot: Robot, T: np.ndarray, j: int, x: np.ndarray, *, limited: bool
           ) -> tuple[np.ndarray, np.ndarray]:
    """``ik_all(robot, T, free={j: x_i})`` for every value x_i of x (m,): (m, K, n), (m,).

    Row r of value i is a solution for r < count[i], zeros after. With ``limited``
    False the robot's limits are ignored (every solution, for :func:`_refine`); the
    angles are then those of the unlimited solve (:func:`_margin` wraps them).

    The first or the last joint moves the base or the tool end of the others rigidly
    (:func:`_targets`): one batch solve of the arm locked at 0. A joint in between
    changes the locked arm's geometry: one locked solve per value.
    """
    n = robot.n
    target = robot if limited else _unlimited(robot)
    if j not in (0, n - 1):
        sols = [np.asarray(ik_all(target, T, free={j: float(xi)}).q) for xi in x]
        K = max([len(s) for s in sols] + [1])
        Q = np.zeros((len(x), K, n))
        count = np.array([len(s) for s in sols], dtype=np.int64)
        for i, s in enumerate(sols):
            Q[i, :len(s)] = s
        return Q, count
    res = ik_all(_locked(target, {j: 0.0})[0], _targets(robot, T, j, x))  # cached
    count = np.asarray(res.count, dtype=np.int64).reshape(len(x))
    q = res.q.reshape(len(x), -1, n - 1)
    Q = np.empty((len(x), q.shape[1], n))
    Q[:, :, :j] = q[:, :, :j]
    Q[:, :, j + 1:] = q[:, :, j:]
    Q[:, :, j] = np.where(np.arange(q.shape[1])[None, :] < count[:, None], x[:, None], 0.0)
    return Q, count


def _targets(robot: Robot, T: np.ndarray, j: int, x: np.ndarray) -> np.ndarray:
    """Targets (m, 4, 4) of the arm with joint j (first or last) locked at 0, one per x.

    For the last joint ``fk(q) = fk(q with q_j = 0)·D(q_j)`` with ``D(x) =
    fk(0)⁻¹·fk(x·e_j)``, so the locked arm must reach ``T·D(x)⁻¹ = T·fk(x·e_j)⁻¹·fk(0)``;
    for the first ``fk(q) = G(q_j)·fk(q with q_j = 0)`` with ``G(x) =
    fk(x·e_j)·fk(0)⁻¹``, target ``G(x)⁻¹·T = fk(0)·fk(x·e_j)⁻¹·T``.
    """
    Q = np.zeros((len(x), robot.n))
    Q[:, j] = x
    F = robot.fk(Q)
    Rt = np.swapaxes(F[:, :3, :3], 1, 2)
    inv = np.zeros_like(F)
    inv[:, :3, :3] = Rt
    inv[:, :3, 3] = -(Rt @ F[:, :3, 3:])[:, :, 0]
    inv[:, 3, 3] = 1.0
    F0 = _home(robot)
    return T @ inv @ F0 if j == robot.n - 1 else F0 @ inv @ T


def _home(robot: Robot) -> np.ndarray:
    """fk(0) (4, 4), cached per robot."""
    got = _HOME.get(robot)
    if got is None:
        got = _HOME.set(robot, readonly(robot.fk(np.zeros(robot.n))))
    return got


_HOME: PerObject[np.ndarray] = PerObject()


def _unlimited(robot: Robot) -> Robot:
    """The robot without joint limits (cached per robot)."""
    got = _UNLIMITED.get(robot)
    if got is None:
        got = _UNLIMITED.set(robot, robot.with_limits(np.tile([-np.inf, np.inf], (robot.n, 1))))
    return got


_UNLIMITED: PerObject[Robot] = PerObject()


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


# ------------------------------------------------------------------------ branches

@njit(cache=True)
def _link(Q, count, max_jump, cost, nxt, unsure):
    """Match rows of neighbouring values where the minimum-cost matching is certain.

    Q (m, K, n) rows, count (m,) of them per value. For each step t → t + 1, ``cost[t,
    a, b]`` is the largest change of any joint (wrapped to (−π, π], as
    :func:`~serialkin.spatial.wrap_angle`) from row a to row b. On the smaller side each
    row (column) takes its smallest entry; when every such minimum is strict and no two
    share their partner, that matching is the unique optimum of the assignment problem
    (any other takes a larger entry in some row and nothing smaller elsewhere), and
    ``nxt[t, a]`` is a's partner (−1: none, or farther than ``max_jump``). Otherwise
    ``unsure[t]`` is set and ``nxt[t]`` left at −1 for the caller's assignment solver.
    """
    m, K, n = Q.shape
    for t in range(m - 1):
        ka, kb = count[t], count[t + 1]
        for a in range(K):
            nxt[t, a] = -1
        for a in range(ka):
            for b in range(kb):
                worst = 0.0
                for c in range(n):
                    d = abs(wrap_pi(Q[t, a, c] - Q[t + 1, b, c]))
                    if d > worst:
                        worst = d
                cost[t, a, b] = worst
        rows_first = ka <= kb
        small, big = min(ka, kb), max(ka, kb)
        used = 0
        sure = True
        for s in range(small):
            best, second, arg = math.inf, math.inf, -1
            for o in range(big):
                x = cost[t, s, o] if rows_first else cost[t, o, s]
                if x < best:
                    best, second, arg = x, best, o
                elif x < second:
                    second = x
            if arg < 0 or not second > best or (used >> arg) & 1:
                sure = False
                break
            used |= 1 << arg
            if best <= max_jump:
                if rows_first:
                    nxt[t, s] = arg
                else:
                    nxt[t, arg] = s
        unsure[t] = not sure
        if not sure:
            for a in range(K):
                nxt[t, a] = -1


@njit(cache=True)
def _label(nxt, count, ids):
    """Branch numbers ``ids[i, r]`` of the rows from the matches: returns how many branches.

    A row matched from the previous value continues its branch; any other row starts
    the next number, in the order of values and then rows.
    """
    m = count.shape[0]
    b = 0
    for r in range(count[0]):
        ids[0, r] = b
        b += 1
    for t in range(m - 1):
        for r in range(count[t + 1]):
            ids[t + 1, r] = -1
        for a in range(count[t]):
            if nxt[t, a] >= 0:
                ids[t + 1, nxt[t, a]] = ids[t, a]
        for r in range(count[t + 1]):
            if ids[t + 1, r] < 0:
                ids[t + 1, r] = b
                b += 1
    return b


def _connect(Q: np.ndarray, count: np.ndarray, max_jump: float
             ) -> tuple[np.ndarray, np.ndarray]:
    """Branches through the rows of each value: (m, b, n) and (m, b) valid.

    Q (m, K, n) rows (count[i] of them at value i). Consecutive rows are matched by
    minimum total cost, the cost the largest joint change (the assignment problem);
    a matched pair more than ``max_jump`` apart is not joined. :func:`_link` settles the
    steps whose optimum is certain; scipy's ``linear_sum_assignment`` the others.
    """
    m, K, n = Q.shape
    Q = np.ascontiguousarray(Q, dtype=np.float64)
    count = np.ascontiguousarray(count, dtype=np.int64)
    cost = np.zeros((max(m - 1, 0), K, K))
    nxt = np.full((max(m - 1, 0), K), -1, dtype=np.int64)
    unsure = np.zeros(max(m - 1, 0), dtype=np.bool_)
    _kernel("link")(readonly(Q), readonly(count), float(max_jump), cost, nxt, unsure)
    for t in np.flatnonzero(unsure):
        c = cost[t, :count[t], :count[t + 1]]
        a, b = linear_sum_assignment(c)
        ok = c[a, b] <= max_jump
        nxt[t, a[ok]] = b[ok]
    ids = np.full((m, K), -1, dtype=np.int64)
    b = int(_kernel("label")(readonly(nxt), readonly(count), ids))
    q = np.zeros((m, b, n))
    valid = np.zeros((m, b), dtype=bool)
    i, r = np.nonzero(ids >= 0)
    q[i, ids[i, r]] = Q[i, r]
    valid[i, ids[i, r]] = True
    return q, valid


_KERNELS: dict[str, object] = {}


def _kernel(name: str):
    """The compiled entry point of :func:`_link` or :func:`_label`, for the types passed.

    Read-only C-contiguous inputs (Q float64 (m, K, n), count int64 (m,); nxt int64
    (m − 1, K) for the labels), a float, and fresh outputs (cost float64 (m − 1, K, K),
    nxt int64 (m − 1, K), unsure bool (m − 1,); ids int64 (m, K)).
    """
    found = _KERNELS.get(name)
    if found is not None:
        return found

    def sig() -> tuple:  # numba's types, imported only when the kernel is loaded
        import numba

        Array, f64, i64 = numba.types.Array, numba.float64, numba.int64
        if name == "link":
            return (Array(f64, 3, "C", readonly=True), Array(i64, 1, "C", readonly=True), f64,
                    Array(f64, 3, "C"), Array(i64, 2, "C"), Array(numba.boolean, 1, "C"))
        return (Array(i64, 2, "C", readonly=True), Array(i64, 1, "C", readonly=True),
                Array(i64, 2, "C"))

    found, final = entry_point(_link if name == "link" else _label, sig)
    if final:  # else the Python function while it compiles: ask again next call
        _KERNELS[name] = found
    return found


# ---------------------------------------------------------------- feasible intervals

def _margin(robot: Robot, Q: np.ndarray, count: np.ndarray) -> np.ndarray:
    """(m,) how far inside its limits the best row of each value lies [rad or m]; −inf: none.

    A row's margin is ``min over joints of min(q − lower, upper − q)``, each revolute
    angle first moved by whole turns into the middle of its limits; joints whose limits
    leave out no angle (a range of 2π or more, or one side open) are left out.
    """
    lo, hi, mid, limited, rev = _limits(robot)
    x = Q[:, :, limited]
    turned = x - 2.0 * math.pi * np.floor((x - mid) / (2.0 * math.pi) + 0.5)
    x = turned if rev is True else np.where(rev, turned, x)
    d = np.minimum(x - lo, hi - x)
    if d.shape[0] * d.shape[1] <= 256:
        best = d.min(axis=-1, initial=np.inf)                         # (m, K)
    else:  # a loop over the joints: numpy's reduction of a short last axis is slow
        best = np.full(Q.shape[:2], np.inf)
        for k in range(d.shape[-1]):
            np.minimum(best, d[..., k], out=best)
    best[np.arange(Q.shape[1])[None, :] >= count[:, None]] = -np.inf
    return best.max(axis=-1, initial=-np.inf)


def _limits(robot: Robot) -> tuple:
    """``(lo, hi, mid, limited, revolute)`` of :func:`_margin`, for the limited joints.

    ``limited`` is a slice when every joint is, ``revolute`` True when every one is.
    """
    got = _LIMITS.get(robot)
    if got is None:
        lo, hi = robot.qlim[:, 0], robot.qlim[:, 1]
        rev = np.asarray(robot.revolute, dtype=bool)
        with np.errstate(invalid="ignore"):
            limited = ~rev | (np.isfinite(lo) & np.isfinite(hi) & (hi - lo < 2.0 * math.pi))
        limited &= np.isfinite(lo) | np.isfinite(hi)
        mid = np.where(np.isfinite(lo) & np.isfinite(hi), 0.5 * (lo + hi), 0.0)
        got = _LIMITS.set(robot, (lo[limited], hi[limited], mid[limited],
                                  slice(None) if limited.all() else np.flatnonzero(limited),
                                  True if rev[limited].all() else rev[limited]))
    return got


_LIMITS: PerObject[tuple] = PerObject()


def _closeness(Q: np.ndarray, count: np.ndarray) -> np.ndarray:
    """(m,) the smallest squared distance between two rows of each value (inf: < 2 rows).

    Two solutions meeting at the edge of reach (a fold) approach each other like
    √(v* − v), so this is linear in v near a fold.
    """
    d = Q[:, :, None, :] - Q[:, None, :, :]
    d = d - 2.0 * math.pi * np.floor(d / (2.0 * math.pi) + 0.5)
    d2 = (d * d).sum(axis=-1)
    K = Q.shape[1]
    pad = np.arange(K)[None, :] >= count[:, None]
    d2[pad[:, :, None] | pad[:, None, :] | np.eye(K, dtype=bool)[None]] = np.inf
    return d2.min(axis=(1, 2), initial=np.inf)


def _intervals(robot: Robot, v: np.ndarray, Q: np.ndarray, count: np.ndarray,
               probe: Callable[[np.ndarray], tuple[np.ndarray, np.ndarray]],
               batched: bool = False) -> list[tuple[float, float]]:
    """Closed runs of values with a solution; inner ends refined (:func:`_refine`).

    ``probe(x)`` solves the locked arm without limits at the values x (k,); ``batched``:
    in one batch, where a probe costs little beside a round (:func:`_refine`).
    """
    some = count > 0
    m = len(v)
    edges = np.flatnonzero(some[1:] != some[:-1])
    if not len(edges):
        return [(float(v[0]), float(v[-1]))] if some[0] else []
    good = np.where(some[edges], edges, edges + 1)
    step = np.where(some[edges], -1, 1)                      # from the end inwards
    near = good[:, None] + step[:, None] * np.arange(3)[None, :]   # (e, 3) grid samples
    inside = (near >= 0) & (near < m)
    near = np.clip(near, 0, m - 1)
    inside &= some[near]
    inside = np.cumprod(inside, axis=1).astype(bool)          # a run of feasible values
    sub = np.unique(near[inside])
    f = _margin(robot, Q[sub], count[sub]) + _PROBE_LIMIT_TOL
    c = _closeness(Q[sub], count[sub])
    where = np.minimum(np.searchsorted(sub, near), len(sub) - 1)   # outside runs: masked
    samples = np.stack([np.where(inside, v[near], np.nan), np.where(inside, f[where], np.nan),
                        np.where(inside, c[where], np.nan)], axis=-1)   # (e, 3, 3)
    ends = _refine(robot, v[np.where(some[edges], edges + 1, edges)], samples, probe, batched)
    starts = ([float(v[0])] if some[0] else []) + [float(x) for x, s in zip(ends, step)
                                                   if s > 0]
    stops = [float(x) for x, s in zip(ends, step) if s < 0] + ([float(v[-1])] if some[-1]
                                                                else [])
    return list(zip(starts, stops))


#: Probes around each estimate of an end, in units of its bracket's width.
_AROUND = np.array([-3e-3, -3e-5, 0.0, 3e-5, 3e-3])
#: The safeguard: probes at these fractions of every bracket, every round.
_SPLIT = np.array([0.25, 0.5, 0.75])
#: Batched probes (first or last joint swept): a round costs as much as ~40 probes, so
#: each estimate gets a ladder of probes at these distances [rad or m] on both sides,
#: from END_TOL / 2 up to the bracket's width, beside one probe at the bracket's middle;
#: a bracket without an estimate is cut in 8, every bracket in the first round in 16.
_LADDER = 0.5 * END_TOL * 100.0 ** np.arange(8)
_SPLIT_FINE = np.arange(1, 8) / 8.0
_HALF = np.array([0.5])
#: The first round's cut (the grid's samples give poor estimates): in 16.
_SPLIT_FIRST = np.arange(1, 16) / 16.0


def _estimates(b: float, fb: float, rows: list) -> list[float]:
    """Where an end between the infeasible value b and the feasible samples may lie.

    ``rows``: the (value, margin f, closeness c) of the feasible values nearest the end
    that were sampled (1 to 3 of them), nearest first. A limit is
    where f = 0: the root of the line or parabola through the samples' f and, when f is
    known at b too, of the inverse quadratic (or the secant) through b and the two
    nearest samples; an edge of reach is where c = 0, c linear near it: the same through
    the samples' c. Roots outside the bracket are dropped.
    """
    g = rows[0][0]
    lo, hi = min(b, g), max(b, g)
    out = []
    for k in (1, 2):
        pts = [(r[0], r[k]) for r in rows if math.isfinite(r[k])]
        if len(pts) >= 2:
            r = _root(pts, g)
            if r is not None and lo < r < hi:
                out.append(r)
    if math.isfinite(fb) and math.isfinite(rows[0][1]):
        pts = [(b, fb)] + [(r[0], r[1]) for r in rows[:2] if math.isfinite(r[1])]
        (x0, y0), (x1, y1) = pts[0], pts[1]
        r = x1 - y1 * (x1 - x0) / (y1 - y0) if y1 != y0 else None
        if len(pts) == 3 and len({y0, y1, pts[2][1]}) == 3:   # inverse quadratic
            x2, y2 = pts[2]
            r = (x0 * y1 * y2 / ((y0 - y1) * (y0 - y2)) + x1 * y0 * y2 / ((y1 - y0) * (y1 - y2))
                 + x2 * y0 * y1 / ((y2 - y0) * (y2 - y1)))
        if r is not None and lo < r < hi:
            out.append(r)
    return out


def _root(pts: list[tuple[float, float]], g: float) -> float | None:
    """The root nearest g of the line (2 points) or parabola (3 points) through pts."""
    (x0, y0), (x1, y1) = pts[0], pts[1]
    if x1 == x0:
        return None
    s01 = (y1 - y0) / (x1 - x0)
    if len(pts) == 2:
        return x0 - y0 / s01 if s01 != 0.0 else None
    x2, y2 = pts[2]
    if x2 == x1 or x2 == x0:
        return None
    a = ((y2 - y1) / (x2 - x1) - s01) / (x2 - x0)      # y = y0 + s·u + a·u·(u − (x1 − x0))
    s = s01 - a * (x1 - x0)                             # in u = x − x0: y0 + s·u + a·u²
    if a == 0.0:
        return x0 - y0 / s if s != 0.0 else None
    disc = s * s - 4.0 * a * y0
    if disc < 0.0:
        return None
    q = -0.5 * (s + math.copysign(math.sqrt(disc), s))
    roots = [q / a] + ([y0 / q] if q != 0.0 else [])
    return x0 + min(roots, key=lambda u: abs(x0 + u - g))


def _refine(robot: Robot, bad: np.ndarray, samples: np.ndarray,
            probe: Callable[[np.ndarray], tuple[np.ndarray, np.ndarray]],
            batched: bool = False) -> np.ndarray:
    """The feasible end next to each infeasible value ``bad`` (e,), to :data:`END_TOL`.

    ``samples`` (e, 3, 3): per end the (value, margin, closeness) of the nearest
    feasible values (:func:`_estimates`), the first one the bracket's feasible side.
    Every round solves, for all open brackets at once (one ``probe`` call, without
    limits), the points ``_AROUND`` each estimate and the safeguard points ``_SPLIT``
    (and, the first time, the infeasible value itself, whose margin the secant needs);
    the bracket becomes the stretch between the last infeasible and the first feasible
    point met walking from the infeasible side. A joint reaching a limit is a smooth
    root of the margin; two solutions meeting at the edge of reach close like √(v* − v),
    a smooth root of their squared distance: either way the estimates converge fast, and
    the safeguard shrinks every bracket at least fourfold per round.

    ``batched`` (the first or the last joint swept: ``probe`` is one batch solve, and a
    round's fixed cost, ~0.1 ms, is that of some 40 probes): fewer, wider rounds. The
    first round cuts every bracket in 16 (the grid's samples are a degree apart and
    their estimates poor); every round probes a ladder around each estimate, at
    ``_LADDER`` (END_TOL / 2 to the bracket's width, factors of 100) on either side, so
    that the bracket shrinks to about the estimate's error, and closes to END_TOL once
    that error is below END_TOL / 2; the safeguard is the bracket's middle, or a cut in 8
    when there is no estimate. Either way each end is a feasible value within END_TOL of
    an infeasible one, so the two agree to END_TOL; the bookkeeping is in Python floats,
    as a round has a few dozen probes.
    """
    e = len(bad)
    bad = [float(x) for x in bad]      # per end, as Python floats: a few probes each
    fb = [math.nan] * e
    near = [[tuple(r) for r in s.tolist() if r[0] == r[0]] for s in samples]
    first = True
    for _ in range(64):
        live = [i for i in range(e) if abs(near[i][0][0] - bad[i]) > END_TOL]
        if not live:
            break
        pts: list[float] = []
        sizes = []
        for i in live:
            b, w = bad[i], near[i][0][0] - bad[i]
            est = _estimates(b, fb[i], near[i])
            if batched:
                split = _SPLIT_FIRST if first else _HALF if est else _SPLIT_FINE
                rungs = [r for r in _LADDER if r < abs(w)]
                here = [b + w * u for u in split]
                for x in est:
                    here += [x - r for r in rungs] + [x] + [x + r for r in rungs]
                here = sorted({x for x in here if 0.0 < (x - b) / w < 1.0})
            else:
                here = [b + w * u for u in _SPLIT] + [x + w * u for x in est for u in _AROUND]
            if first:
                here.append(b)
            pts += here
            sizes.append(len(here))
        X = np.array(pts)
        Qp, cp = probe(X)
        f = (_margin(robot, Qp, cp) + _PROBE_LIMIT_TOL).tolist()
        start = 0
        kept = []      # per live end: the indices into X of its new feasible samples
        for i, k in zip(live, sizes):
            b, gi = bad[i], near[i][0][0]
            t = [((pts[a] - b) / (gi - b), a) for a in range(start, start + k)]  # 0: bad
            start += k
            if first:
                fb[i] = f[min(t, key=lambda ta: abs(ta[0]))[1]]
            inner = sorted([ta for ta in t if 0.0 < ta[0] < 1.0])
            h = next((m for m, (_, a) in enumerate(inner) if f[a] >= 0.0), None)
            if h is None:
                if inner:
                    bad[i], fb[i] = pts[inner[-1][1]], f[inner[-1][1]]
                kept.append([])
                continue
            if h > 0:
                bad[i], fb[i] = pts[inner[h - 1][1]], f[inner[h - 1][1]]
            kept.append([a for _, a in inner[h:] if f[a] >= 0.0][:3])  # the three nearest
        need = [a for at in kept for a in at]
        c = dict(zip(need, _closeness(Qp[need], cp[need]).tolist()))   # only those kept
        for i, at in zip(live, kept):
            if at:
                near[i] = ([(pts[a], f[a], c[a]) for a in at] + near[i])[:3]
        first = False
    return np.array([near[i][0][0] for i in range(e)])
