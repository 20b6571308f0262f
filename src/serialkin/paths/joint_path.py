"""Joint paths that follow a pose path without branch flips or 2π jumps.

For every sample of a pose path the arm's configurations are listed (all of them:
:func:`serialkin.ik.analytic.ik_all`), and one per sample is chosen by dynamic
programming over the layered graph of samples (Descartes' planning graph for ROS): an
edge joins configurations of neighbouring samples whose joints all differ by at most
``max_joint_step`` (wrapped differences for revolute joints), its cost the joint motion
``Σ_j |Δq_j|`` [rad or m]; the path of least total motion is kept (Bellman's recursion,
``C_i(b) = min_a C_{i−1}(a) + |q_b − q_a|₁`` over allowed edges). A configuration flip
(elbow up to down, wrist flip) needs a large step, so it is never chosen while a
continuous branch exists. Angles are then unwrapped along the path (no 2π jumps).

Redundant arms keep their redundancy fixed along the path: the arm angle ψ for a 7R arm
with a spherical shoulder and wrist (:mod:`~serialkin.ik.analytic.arm_angle`), a locked
joint for other 7R arms (``ik_all(..., free=...)``), each at its starting value. Arms with
no all-solutions solver follow the path by numerical IK warm-started at the previous
sample, with the same step check.

Where no continuous joint path exists (an unreachable sample, a singularity or a joint
limit that forces a change of branch, a step beyond the bound), the result says at which
sample and why, and holds the best path up to the sample before.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from serialkin._checks import check_positive, check_transform
from serialkin.errors import InputError, NoClosedFormError
from serialkin.ik.analytic import ik_all
from serialkin.ik.analytic.arm_angle import arm_angle, ik_arm_angle_path, srs_structure
from serialkin.model.robot import Robot
from serialkin.spatial.pose import pose_error
from serialkin.spatial.rotations import wrap_angle
from serialkin.tracking.path import Path

__all__ = ["JointPath", "joint_path"]

_TWO_PI = 2.0 * math.pi


@dataclass(frozen=True, eq=False)
class JointPath:
    """A joint path along a pose path (what :func:`joint_path` returns).

    Attributes:
        q: (m, n) joint values [rad or m], unwrapped (no 2π jumps); m is the path's length
            on success, else the samples before ``failed_at`` (the best path up to there).
        success: every sample reached, every step within ``max_joint_step``.
        failed_at: the first sample that cannot be reached continuously (None on success).
        reason: why (empty on success).
        max_joint_step: the bound on any joint's change between neighbours [rad or m].
        largest_step: the largest joint change between neighbouring samples of ``q``.
        position_error: (m,) distance of each reached position from its target [m].
        orientation_error: (m,) rotation angle between reached and target orientation [rad].
        method: how the configurations were listed: 'all-solutions', 'arm-angle',
            'locked-joint' or 'numerical'.
        redundancy: the arm angle [rad] or locked joint's value kept along the path for a
            redundant arm (None otherwise).
        reference: the arm angle's reference direction (3,) for an S-R-S arm (chosen far
            from every sample's shoulder-to-wrist line), else None.
    """

    q: np.ndarray
    success: bool
    failed_at: int | None
    reason: str
    max_joint_step: float
    largest_step: float
    position_error: np.ndarray
    orientation_error: np.ndarray
    method: str
    redundancy: float | None = None
    reference: np.ndarray | None = None

    def __len__(self) -> int:
        """The number of samples in ``q``."""
        return len(self.q)


def joint_path(robot: Robot, path: Path | object, *, q0: object = None,
               max_joint_step: float = 0.5, locked_joint: int | None = None,
               redundancy: float | None = None, seed: object = 0) -> JointPath:
    """A branch-consistent joint path through every pose of ``path`` (module docstring).

    Args:
        robot: the arm.
        path: a pose :class:`~serialkin.tracking.path.Path` (:mod:`serialkin.paths`
            builds lines, arcs and waypoint paths) or (p, 4, 4) poses.
        q0: (n,) the configuration the path starts from: the first sample's choice
            prefers the configuration nearest it, and a redundant arm keeps q0's arm angle
            (or locked joint's value). Default: least total motion from any start.
        max_joint_step: the largest change of any joint between neighbouring samples
            [rad or m] (MoveIt's jump threshold, absolute).
        locked_joint: for a 7R arm without a spherical shoulder and wrist, the joint kept
            fixed (default the last).
        redundancy: the arm angle [rad] (S-R-S arms) or the locked joint's value to keep;
            default from q0, else 0 (arm angle) or the middle of the joint's limits.
        seed: the numerical solver's seed (arms with no all-solutions solver).

    Returns:
        :class:`JointPath`.

    Raises:
        InputError: the path is not a pose path, q0 has the wrong size, a bound is not
            positive.
    """
    T = _poses(path)
    bound = check_positive(max_joint_step, "max_joint_step")
    start = None if q0 is None else robot.check_q(q0, "q0")
    if start is not None and start.ndim != 1:
        raise InputError(f"q0 must be one configuration ({robot.n},), got shape {start.shape}")
    lists = _configurations(robot, T, start, locked_joint, redundancy)
    if lists is None:
        return _numerical(robot, T, start, bound, seed)
    rows, method, kept = lists
    chosen, failed_at, reason = _dynamic_programme(robot, rows, start, bound)
    return _finish(robot, T, chosen, failed_at, reason, bound, method, kept, start)


def _poses(path: Path | object) -> np.ndarray:
    if isinstance(path, Path):
        if path.task != "pose":
            raise InputError(f"path must be a pose path (task 'pose'), got task {path.task!r}: "
                             "build one with serialkin.paths.line, arc or waypoints")
        return path.targets
    T = check_transform(path, "path")
    if T.ndim != 3:
        raise InputError(f"path poses must have shape (p, 4, 4), got {T.shape}")
    return T


# --------------------------------------------------------------- configurations

def _configurations(robot: Robot, T: np.ndarray, start, locked_joint, redundancy):
    """([rows (k_i, n) per sample], method, (kept value, reference)), or None (no solver)."""
    if robot.n == 7 and locked_joint is None:
        try:
            srs_structure(robot)
        except NoClosedFormError:
            pass
        else:
            r = _reference(robot, T)
            psi = float(redundancy if redundancy is not None else
                        (arm_angle(robot, start, r) if start is not None else 0.0))
            return [s.q for s in ik_arm_angle_path(robot, T, psi, r)], "arm-angle", (psi, r)
    if robot.n == 7:
        j = robot.n - 1 if locked_joint is None else int(locked_joint)
        if not 0 <= j < robot.n:
            raise InputError(f"locked_joint must be a joint index in 0..{robot.n - 1}, "
                             f"got {locked_joint!r}")
        lo, hi = robot.qlim[j]
        value = float(redundancy if redundancy is not None else start[j] if start is not None
                      else (0.5 * (lo + hi) if np.isfinite(lo) and np.isfinite(hi) else 0.0))
        try:
            sols = ik_all(robot, T, free={j: value})   # one batch: 15 times a loop's speed
        except NoClosedFormError:
            return None
        return _rows(sols), "locked-joint", (value, None)
    try:
        sols = ik_all(robot, T)
    except NoClosedFormError:
        return None
    return _rows(sols), "all-solutions", (None, None)


def _rows(sols) -> list[np.ndarray]:
    """The configurations (k_i, n) of each sample of a batch of all solutions."""
    return [sols.q[i, :c] for i, c in enumerate(np.atleast_1d(sols.count))]


def _reference(robot: Robot, T: np.ndarray) -> np.ndarray:
    """The arm angle's reference direction for a path: the one farthest from every S–W line.

    ψ is undefined where the shoulder-to-wrist line is parallel to the reference and
    changes fast near there; of the base axes and the directions perpendicular to the
    path's mean S–W line, the one whose smallest angle to any sample's S–W line is the
    largest is used.
    """
    arm = srs_structure(robot)
    local = arm.M[:3, :3].T @ (arm.W0 - arm.M[:3, 3])
    e = T[:, :3, 3] + T[:, :3, :3] @ local - arm.S
    e /= np.maximum(np.linalg.norm(e, axis=1, keepdims=True), 1e-300)
    mean = e.mean(axis=0)
    cands = [np.eye(3)[k] for k in range(3)]
    for k in range(3):
        c = np.cross(mean, np.eye(3)[k])
        if np.linalg.norm(c) > 1e-6:
            cands.append(c / np.linalg.norm(c))
    score = [float(np.min(np.linalg.norm(np.cross(e, c), axis=1))) for c in cands]
    return cands[int(np.argmax(score))]


# ---------------------------------------------------------- dynamic programming

def _joint_change(robot: Robot, d: np.ndarray) -> np.ndarray:
    """Joint changes (..., n) with the revolute ones wrapped to (−π, π] (the shortest turn)."""
    d = np.array(d, dtype=float)
    d[..., robot.revolute] = wrap_angle(d[..., robot.revolute])
    return d


def _dynamic_programme(robot: Robot, rows: list[np.ndarray], start, bound: float):
    """(chosen rows (m, n), failed_at, reason) by Bellman's recursion over allowed edges.

    The rows are padded to one (p, K, n) array so that every edge's joint changes are
    computed in a few passes (:func:`_edges`); the recursion is then three numpy operations
    on a (K, K) table per sample, and a sample where no configuration is reachable any
    more (every cost infinite, which stays so) is found after the loop.
    """
    p, n = len(rows), robot.n
    K = max(1, max(len(r) for r in rows))
    R = np.zeros((p, K, n))
    valid = np.zeros((p, K), dtype=bool)
    for i, r in enumerate(rows):
        R[i, :len(r)] = r
        valid[i, :len(r)] = True
    if not valid[0].any():
        return np.zeros((0, n)), 0, _unreachable(0)
    motion, step = _edges(robot, R)
    allowed = (step <= bound) & valid[:-1, :, None] & valid[1:, None, :]
    edge = np.where(allowed, motion, np.inf)
    cost = np.where(valid[0], 0.0, np.inf)
    if start is not None:
        cost = np.where(valid[0], np.abs(_joint_change(robot, R[0] - start)).sum(axis=1),
                        np.inf)
    reach = valid.any(axis=1)
    stop = p if reach.all() else int(np.argmin(reach))   # the first unreachable sample
    back = np.zeros((p, K), dtype=np.int64)
    costs = np.empty((stop, K))
    costs[0] = cost
    cols = np.arange(K)
    total = np.empty((K, K))
    for i in range(1, stop):
        np.add(costs[i - 1][:, None], edge[i - 1], out=total)
        arg = total.argmin(axis=0)
        back[i] = arg
        costs[i] = total[arg, cols]
    dead = ~np.isfinite(costs).any(axis=1)
    if dead.any():
        i = int(np.argmax(dead))
        live = np.isfinite(costs[i - 1])[:, None] & valid[i][None, :]
        a, b = np.unravel_index(np.argmin(np.where(live, step[i - 1], np.inf)), (K, K))
        j = int(np.argmax(_edge_change(robot, R, i - 1, int(a), int(b))))
        return _back(R, back, costs[i - 1], i - 1), i, (
            f"sample {i}: every configuration is more than max_joint_step ({bound:.4g}) "
            f"from those that reach sample {i - 1} (the closest differ by "
            f"{step[i - 1, a, b]:.4g} in joint {j + 1}): a singularity or a joint limit "
            "forces a change of branch here; sample the path more finely near it or "
            "allow a larger step")
    if stop < p:
        return _back(R, back, costs[stop - 1], stop - 1), stop, _unreachable(stop)
    return _back(R, back, costs[p - 1], p - 1), None, ""


def _edges(robot: Robot, R: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Σ_j |Δq_j| and max_j |Δq_j| (p − 1, K, K) of every edge, revolute changes wrapped.

    ``Δq[i, a, b] = q_{i+1, b} − q_{i, a}`` with a revolute change ``d`` taken as
    ``d − 2π·round(d / 2π)`` (the shortest turn, |·| ≤ π). One joint at a time, in place
    on (p − 1, K, K) arrays: the (p − 1, K, K, n) array of every change would not fit in
    the cache (3 MB for a UR5 path of 1,000 samples) and took 16 times longer.
    """
    p, K, n = R.shape
    total = np.zeros((p - 1, K, K))
    step = np.zeros((p - 1, K, K))
    d = np.empty((p - 1, K, K))
    turns = np.empty((p - 1, K, K))
    for j in range(n):
        np.subtract(R[1:, None, :, j], R[:-1, :, None, j], out=d)
        if robot.revolute[j]:
            np.multiply(d, 1.0 / _TWO_PI, out=turns)
            np.rint(turns, out=turns)
            turns *= _TWO_PI
            d -= turns
        np.abs(d, out=d)
        total += d
        np.maximum(step, d, out=step)
    return total, step


def _edge_change(robot: Robot, R: np.ndarray, i: int, a: int, b: int) -> np.ndarray:
    """|Δq| (n,) of the edge from configuration a of sample i to b of sample i + 1."""
    d = R[i + 1, b] - R[i, a]
    d = np.where(robot.revolute, d - _TWO_PI * np.rint(d / _TWO_PI), d)
    return np.abs(d)


def _back(R: np.ndarray, back: np.ndarray, cost: np.ndarray, last: int) -> np.ndarray:
    """The least-cost path to layer ``last`` by the stored predecessors: (last + 1, n)."""
    k = int(np.argmin(cost))
    out = np.empty((last + 1, R.shape[2]))
    for i in range(last, -1, -1):
        out[i] = R[i, k]
        k = int(back[i, k])
    return out


def _unreachable(i: int) -> str:
    return (f"sample {i} is out of reach: no configuration inside the joint limits reaches "
            "it")


# ------------------------------------------------------------------- finishing

def _unwrap(robot: Robot, Q: np.ndarray, start) -> np.ndarray:
    """Revolute angles made continuous along the path (no 2π jumps), from the start nearest q0."""
    if len(Q) == 0:
        return Q
    out = Q.copy()
    rev = robot.revolute
    if start is not None:
        shift = np.round((start[rev] - out[0, rev]) / _TWO_PI) * _TWO_PI
        moved = out[0, rev] + shift
        lo, hi = robot.qlim[rev, 0], robot.qlim[rev, 1]
        ok = (moved >= lo) & (moved <= hi)
        out[0, rev] = np.where(ok, moved, out[0, rev])
    out[1:] = out[0] + np.cumsum(_joint_change(robot, np.diff(out, axis=0)), axis=0)
    return out


def _finish(robot, T, Q, failed_at, reason, bound, method, kept, start) -> JointPath:
    """Unwrap, check the limits along the unwrapped path, measure the errors."""
    Q = _unwrap(robot, Q, start)
    if failed_at is None and len(Q):
        lo, hi = robot.qlim[:, 0], robot.qlim[:, 1]
        out = (Q < lo - 1e-9) | (Q > hi + 1e-9)
        if out.any():
            i, j = np.argwhere(out)[0]
            failed_at, Q = int(i), Q[:i]
            reason = (f"sample {i}: joint {j + 1} would leave its limits (the continuous "
                      "path needs more than the joint's range)")
    return _result(robot, T, Q, failed_at, reason, bound, method, kept)


def _result(robot, T, Q, failed_at, reason, bound, method, kept) -> JointPath:
    m = len(Q)
    if m:
        e = pose_error(robot.fk(Q), T[:m], check=False)
        pos, rot = np.linalg.norm(e[:, :3], axis=1), np.linalg.norm(e[:, 3:], axis=1)
    else:
        pos = rot = np.zeros(0)
    largest = float(np.abs(np.diff(Q, axis=0)).max()) if m > 1 else 0.0
    for a in (Q, pos, rot):
        a.setflags(write=False)
    return JointPath(q=Q, success=failed_at is None, failed_at=failed_at, reason=reason,
                     max_joint_step=bound, largest_step=largest, position_error=pos,
                     orientation_error=rot, method=method, redundancy=kept[0],
                     reference=kept[1])


def _numerical(robot: Robot, T: np.ndarray, start, bound: float, seed) -> JointPath:
    """Warm-started numerical IK sample by sample, each step checked against the bound."""
    out = []
    prev = start
    for i, t in enumerate(T):
        res = robot.ik(t, q0=prev, seed=seed)
        if not bool(res.success):
            return _result(robot, T, np.array(out).reshape(-1, robot.n), i,
                           f"sample {i}: the numerical IK did not converge ({res.reason})",
                           bound, "numerical", (None, None))
        q = np.asarray(res.q, dtype=float)
        if prev is not None:
            d = _joint_change(robot, q - prev)
            if i > 0 and np.abs(d).max() > bound:
                j = int(np.argmax(np.abs(d)))
                return _result(robot, T, np.array(out).reshape(-1, robot.n), i,
                               f"sample {i}: joint {j + 1} would move by {d[j]:.4g} (more "
                               f"than max_joint_step {bound:.4g}): the warm-started solver "
                               "changed branch", bound, "numerical", (None, None))
            q = prev + d if i > 0 else q
        out.append(q)
        prev = q
    return _finish(robot, T, np.array(out), None, "", bound, "numerical", (None, None), start)
