"""7-DOF arms with a spherical shoulder and a spherical wrist (S-R-S): IK by the arm angle.

A 7R arm whose axes 1, 2, 3 meet at the shoulder point **S** and whose axes 5, 6, 7 meet
at the wrist point **W** (KUKA iiwa, Kinova Gen3, the SRS arms of Shimizu et al. 2008)
reaches a pose T with a one-parameter family of configurations: the elbow point **E**
swings on a circle around the line S–W. The *arm angle* ψ says where on that circle
(the conventional SEW angle of Elias & Wen, "IK-Geo", 2024)::

    e = (W − S) / |W − S|,     e_r = unit part of the reference r perpendicular to e,
    ψ = atan2(e · (e_r × (E − S)), e_r · (E − S))                                   (1)

with r a fixed direction in the base frame (the base z axis unless another is given;
ψ is undefined when W − S is parallel to r, and when E lies on the line S–W, the arm
stretched or folded). At a given ψ the configurations follow in closed form, up to 8:

1. the wrist point at the target, ``W_t = T·M⁻¹·W₀`` (M the pose at q = 0, W₀ the wrist
   point at q = 0), fixes ``|W − S|``, which depends on the elbow joint only: q₄ by
   subproblem 3 (two values);
2. the shoulder rotation ``R₁₂₃`` maps the arm's upper-arm and shoulder-to-wrist vectors
   at q = 0, ``b = E₀ − S`` and ``a = W₀(q₄) − S``, onto ``E − S`` (from ψ and (1)) and
   ``W_t − S``: a rotation fixed by two vector pairs;
3. ``Rot(h₁, q₁)·Rot(h₂, q₂)·Rot(h₃, q₃) = R₁₂₃``: subproblem 2 for (q₁, q₂) (two
   solutions), subproblem 1 for q₃;
4. the wrist, ``Rot(h₅, q₅)·Rot(h₆, q₆)·Rot(h₇, q₇) = (R₁…R₄)ᵀ·R_T·R_Mᵀ``: the same.

A solution's *branch* ``4·i₄ + 2·i_s + i_w`` (i₄ the elbow's, i_s the shoulder's and
i_w the wrist's choice of sign, 0 or 1) is continuous in ψ away from singular
configurations, so a branch can be followed along ψ (:func:`arm_angle_intervals`).

Units: angles in radians, lengths in metres. Everything is computed with numpy on
batches of arm angles (no compiled kernel: nothing to compile at a first call).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from serialkin._checks import as_float_array, check_transform
from serialkin._memo import PerObject
from serialkin.errors import InputError, NoClosedFormError
from serialkin.model.robot import Robot, robot_scale
from serialkin.spatial.pose import pose_error
from serialkin.spatial.rotations import perpendicular, wrap_angle

__all__ = ["ArmAngleIntervals", "ArmAngleSolutions", "SRSArm", "arm_angle",
           "arm_angle_intervals", "ik_arm_angle", "ik_arm_angle_path", "srs_structure"]

#: Lines closer than this (relative to the robot's size) meet.
MEET_TOL = 1e-9
#: Feasibility tolerance on joint limits [rad].
LIMIT_TOL = 1e-9
_TWO_PI = 2.0 * math.pi


@dataclass(frozen=True, eq=False)
class SRSArm:
    """An S-R-S arm's geometry at q = 0 (world frame, base and tool included).

    Attributes:
        H: (7, 3) unit joint directions.
        P: (7, 3) a point on each joint line [m].
        M: (4, 4) tool pose at q = 0.
        S: (3,) shoulder point: axes 1, 2, 3 meet there [m].
        W0: (3,) wrist point at q = 0: axes 5, 6, 7 meet there [m].
        E0: (3,) elbow point at q = 0: the point of axis 4 nearest S [m].
        lo, hi: (7,) joint limits [rad] (±inf where unlimited).
        mid: (7,) the angle each solution is wrapped nearest to (by whole turns): the
            middle of the limits, 0 for an unlimited joint.
        scale: the robot's size [m] (for tolerances).
    """

    H: np.ndarray
    P: np.ndarray
    M: np.ndarray
    S: np.ndarray
    W0: np.ndarray
    E0: np.ndarray
    lo: np.ndarray
    hi: np.ndarray
    mid: np.ndarray
    scale: float


@dataclass(frozen=True, eq=False)
class ArmAngleSolutions:
    """The configurations reaching one pose at one arm angle (what :func:`ik_arm_angle` returns).

    Attributes:
        q: (k, 7) joint values [rad], k ≤ 8, inside the joint limits, each reaching the
            target; (0, 7) when the pose is out of reach or every branch violates a limit.
        branch: (k,) int, each row's branch (0–7, see the module docstring).
        psi: the arm angle [rad].
    """

    q: np.ndarray
    branch: np.ndarray
    psi: float

    def __len__(self) -> int:
        """The number of solutions k."""
        return len(self.q)


@dataclass(frozen=True, eq=False)
class ArmAngleIntervals:
    """The arm angles at which each branch reaches a pose inside the joint limits.

    Attributes:
        branches: ``{branch: [(ψ_lo, ψ_hi), ...]}`` closed intervals [rad] inside
            [−π, π] for every branch (0–7) that reaches the pose somewhere; an interval
            touching both −π and π is one interval across ±π, listed as its two parts.
        feasible: the union over branches, the same form: every ψ at which some
            configuration reaches the pose inside the limits.
        resolution: the grid step [rad] of the search; interval ends are refined by
            bisection to ``1e-10`` rad.
        singular: the pose leaves ψ undefined (the line S–W parallel to the reference,
            or the elbow on that line): every configuration reaching it has the same
            shoulder-elbow-wrist plane up to rotation; ``branches`` then describes ψ = 0.
    """

    branches: dict[int, list[tuple[float, float]]]
    feasible: list[tuple[float, float]]
    resolution: float
    singular: bool

    def contains(self, psi: float, branch: int | None = None) -> bool:
        """Whether ψ [rad] (wrapped to (−π, π]) is feasible, on ``branch`` or on any."""
        x = float(wrap_angle(float(psi)))
        spans = self.feasible if branch is None else self.branches.get(int(branch), [])
        return any(lo - 1e-12 <= x <= hi + 1e-12 for lo, hi in spans)


# ----------------------------------------------------------------------- structure

def _meeting_point(H: np.ndarray, P: np.ndarray) -> tuple[np.ndarray, float]:
    """The least-squares point nearest to every line (P[i], H[i]) and its largest distance."""
    A = np.zeros((3, 3))
    rhs = np.zeros(3)
    for h, p in zip(H, P):
        N = np.eye(3) - np.outer(h, h)
        A += N
        rhs += N @ p
    x = np.linalg.lstsq(A, rhs, rcond=None)[0]
    gap = max(float(np.linalg.norm((np.eye(3) - np.outer(h, h)) @ (x - p)))
              for h, p in zip(H, P))
    return x, gap


def _pairwise_independent(H: np.ndarray) -> bool:
    return all(np.linalg.norm(_cross(H[i], H[i + 1])) > 1e-6 for i in range(len(H) - 1))


_SRS: PerObject[SRSArm | NoClosedFormError] = PerObject()


def srs_structure(robot: Robot) -> SRSArm:
    """The robot's S-R-S geometry, or :class:`~serialkin.errors.NoClosedFormError` saying why not.

    Requires 7 revolute joints; axes 1–3 meeting in one point S and axes 5–7 in one
    point W (within ``MEET_TOL`` times the robot's size), consecutive axes of each
    triple not parallel, and neither S nor W on axis 4 (otherwise the elbow cannot
    change the distance |W − S|). Cached per robot.
    """
    got = _SRS.get(robot)
    if got is None:
        got = _SRS.set(robot, _analyse(robot))
    if isinstance(got, NoClosedFormError):
        raise got
    return got


def _analyse(robot: Robot) -> SRSArm | NoClosedFormError:
    def fail(why: str) -> NoClosedFormError:
        return NoClosedFormError(
            f"robot {robot.name!r} is not a 7R arm with a spherical shoulder and wrist "
            f"(S-R-S), so its arm angle has no closed form: {why}. For other 7R arms "
            "sweep a joint instead: robot.ik_all(T, free={joint: value}).")

    if robot.n != 7 or not bool(np.all(robot.revolute)):
        return fail(f"it has {robot.n} joints of types {''.join(robot.joint_types)}")
    P, H = robot.joint_axes()
    H = H / np.linalg.norm(H, axis=1, keepdims=True)
    M = robot.fk(np.zeros(7))
    scale = robot_scale(robot)
    S, gap_s = _meeting_point(H[:3], P[:3])
    W0, gap_w = _meeting_point(H[4:], P[4:])
    if gap_s > MEET_TOL * scale:
        return fail(f"axes 1, 2, 3 do not meet in one point (they miss by {gap_s:.3g} m)")
    if gap_w > MEET_TOL * scale:
        return fail(f"axes 5, 6, 7 do not meet in one point (they miss by {gap_w:.3g} m)")
    if not (_pairwise_independent(H[:3]) and _pairwise_independent(H[4:])):
        return fail("two consecutive axes of the shoulder or of the wrist are parallel")
    h4, p4 = H[3], P[3]
    E0 = p4 + np.dot(S - p4, h4) * h4
    for name, x in (("shoulder", S), ("wrist", W0)):
        d = x - p4
        if np.linalg.norm(d - np.dot(d, h4) * h4) <= MEET_TOL * scale:
            return fail(f"the {name} point lies on axis 4 (the elbow cannot move it)")
    lo, hi = robot.qlim[:, 0].copy(), robot.qlim[:, 1].copy()
    mid = np.zeros(7)  # the value each angle is wrapped nearest to: 0 when unlimited
    for i in range(7):
        if np.isfinite(lo[i]):
            mid[i] = 0.5 * (lo[i] + hi[i]) if np.isfinite(hi[i]) else lo[i] + math.pi
        elif np.isfinite(hi[i]):
            mid[i] = hi[i] - math.pi
    return SRSArm(H=H, P=P, M=M, S=S, W0=W0, E0=E0, lo=lo, hi=hi, mid=mid, scale=scale)


# ----------------------------------------------------------------- vector helpers

def _cross(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """The cross product a × b over the last axis (..., 3), cheaper than numpy's if small."""
    a0, a1, a2 = a[..., 0], a[..., 1], a[..., 2]
    b0, b1, b2 = b[..., 0], b[..., 1], b[..., 2]
    return np.stack([a1 * b2 - a2 * b1, a2 * b0 - a0 * b2, a0 * b1 - a1 * b0], axis=-1)


def _rot(h: np.ndarray, t: np.ndarray) -> np.ndarray:
    """Rodrigues: (..., 3, 3) rotations by angles t (...,) about the unit axis h (3,)."""
    K = np.array([[0.0, -h[2], h[1]], [h[2], 0.0, -h[0]], [-h[1], h[0], 0.0]])
    s, c = np.sin(t)[..., None, None], np.cos(t)[..., None, None]
    return np.eye(3) + s * K + (1.0 - c) * (K @ K)


def _sp1(w: np.ndarray, u: np.ndarray, v: np.ndarray) -> np.ndarray:
    """Subproblem 1 on directions: θ (...,) with Rot(w, θ)·u pointing like v in the plane ⟂ w."""
    up = u - (u @ w)[..., None] * w
    vp = v - (v @ w)[..., None] * w
    return np.arctan2(_cross(up, vp) @ w, np.sum(up * vp, axis=-1))


def _sp2(w1: np.ndarray, w2: np.ndarray, u: np.ndarray, v: np.ndarray):
    """Subproblem 2: (θ1, θ2) with Rot(w1, θ1)·Rot(w2, θ2)·u = v, both signs of the root.

    u (3,) and v (..., 3) are unit vectors from the axes' common point; returns θ1, θ2
    of shape (..., 2) (second index: the sign of γ in z = α w1 + β w2 ± γ (w1 × w2)) and
    ``ok`` (...,): False where no solution exists beyond rounding (then γ = 0 is used).
    """
    c12 = float(w1 @ w2)
    den = c12 * c12 - 1.0
    a2u = float(w2 @ u)
    a1v = v @ w1
    alpha = (c12 * a2u - a1v) / den
    beta = (c12 * a1v - a2u) / den
    x = _cross(w1, w2)
    g2 = (1.0 - alpha**2 - beta**2 - 2.0 * alpha * beta * c12) / float(x @ x)
    ok = g2 > -1e-9
    g = np.sqrt(np.maximum(g2, 0.0))
    sign = np.array([1.0, -1.0])
    z = (alpha[..., None, None] * w1 + beta[..., None, None] * w2
         + (g[..., None] * sign)[..., None] * x)                       # (..., 2, 3)
    t2 = _sp1(w2, np.broadcast_to(u, z.shape), z)
    t1 = _sp1(w1, z, np.broadcast_to(v[..., None, :], z.shape))
    return t1, t2, ok


def _unit(v: np.ndarray) -> np.ndarray:
    n = np.linalg.norm(v, axis=-1, keepdims=True)
    return v / np.where(n > 0.0, n, 1.0)


def _reference(reference: object) -> np.ndarray:
    r = np.array([0.0, 0.0, 1.0]) if reference is None else as_float_array(reference,
                                                                             "reference")
    if r.shape != (3,) or not np.all(np.isfinite(r)) or np.linalg.norm(r) == 0.0:
        raise InputError(f"reference must be a non-zero finite 3-vector (a direction in the "
                         f"base frame), got {np.asarray(reference).tolist()!r}")
    return r / np.linalg.norm(r)


# ------------------------------------------------------------------ arm angle of q

def arm_angle(robot: Robot, q: object, reference: object = None) -> np.ndarray:
    """The arm angle ψ [rad] of configurations q (..., 7) of an S-R-S arm (eq 1 above).

    ``reference`` is the direction r of eq (1) in the base frame (default the base z
    axis). Returns (...,) angles in (−π, π]; 0 where ψ is undefined (the line S–W
    parallel to r, or the elbow on it).
    """
    arm = srs_structure(robot)
    r = _reference(reference)
    Q = robot.check_q(q)
    T = robot.fk(Q)
    # the shoulder rotation R123 and the wrist point, from the joint values
    R = _rot(arm.H[0], Q[..., 0]) @ _rot(arm.H[1], Q[..., 1]) @ _rot(arm.H[2], Q[..., 2])
    E = arm.S + np.einsum("...ij,j->...i", R, arm.E0 - arm.S)
    Wt = _wrist_target(arm, T)
    return _psi_of(arm, E, Wt, r)


def _wrist_target(arm: SRSArm, T: np.ndarray) -> np.ndarray:
    """W_t = T·M⁻¹·W₀: where the wrist point must be for the tool pose T (..., 4, 4)."""
    local = arm.M[:3, :3].T @ (arm.W0 - arm.M[:3, 3])
    return T[..., :3, 3] + np.einsum("...ij,j->...i", T[..., :3, :3], local)


def _psi_of(arm: SRSArm, E: np.ndarray, Wt: np.ndarray, r: np.ndarray) -> np.ndarray:
    e = _unit(Wt - arm.S)
    rp = r - np.sum(r * e, axis=-1, keepdims=True) * e
    er = _unit(rp)
    c = E - arm.S
    y = np.sum(e * _cross(er, c), axis=-1)
    x = np.sum(er * c, axis=-1)
    tiny = 1e-12 * arm.scale
    undefined = (np.linalg.norm(rp, axis=-1) < 1e-12) | (np.hypot(x, y) < tiny)
    return np.where(undefined, 0.0, np.arctan2(y, x))


# ------------------------------------------------------------- solving at given ψ

def _solve(arm: SRSArm, T: np.ndarray, psi: np.ndarray, r: np.ndarray):
    """Every branch for every (pose, ψ): (N, 8, 7) joint values and (N, 8) 'exists' flags.

    T is one (4, 4) pose or (N, 4, 4) poses, ψ (N,). Branch ``4·i4 + 2·is + iw``; rows
    whose subproblem has no solution (beyond rounding) are flagged False. No limits here.
    """
    H, P, S = arm.H, arm.P, arm.S
    N = len(psi)
    T = np.broadcast_to(T, (N, 4, 4))
    Q = np.zeros((N, 8, 7))
    ok = np.zeros((N, 8), dtype=bool)
    tiny = 1e-12 * arm.scale
    d = _wrist_target(arm, T) - S                                       # (N, 3)
    L = np.linalg.norm(d, axis=1)
    e = d / np.maximum(L, tiny)[:, None]
    rp = r - (e @ r)[:, None] * e
    nr = np.linalg.norm(rp, axis=1)
    er = np.where((nr > 0.0)[:, None], rp / np.maximum(nr, 1e-300)[:, None],
                  perpendicular(e))
    # 2. E − S at ψ: its part along e is b's along a (a rotation keeps a·b); its part
    # across e points at ψ in the plane (e_r, e × e_r) of eq (1)
    c_dir = np.cos(psi)[:, None] * er + np.sin(psi)[:, None] * _cross(e, er)
    Rw = T[:, :3, :3] @ arm.M[:3, :3].T
    # 1. the elbow joint: two q4 (subproblem 3) put the wrist at distance L from S
    q4s, ok4 = _elbow_angles(arm, L)                                    # (N, 2), (N,)
    ok4 &= L > tiny
    h4, p4 = H[3], P[3]
    u = arm.W0 - p4
    b = arm.E0 - S
    x3, x7 = perpendicular(H[2]), perpendicular(H[6])
    for i4 in range(2):
        R4 = _rot(h4, q4s[:, i4])                                       # (N, 3, 3)
        a = p4 + R4 @ u - S                                             # W0(q4) − S, |a| = L
        a_hat = a / np.maximum(L, tiny)[:, None]
        b_perp = b - (a_hat @ b)[:, None] * a_hat
        nb = np.linalg.norm(b_perp, axis=1)
        line = nb < tiny          # the elbow on the line S–W: ψ undefined, any plane
        cd = np.where(line[:, None], er, c_dir)
        bp = np.where(line[:, None], perpendicular(a_hat),
                      b_perp / np.maximum(nb, 1e-300)[:, None])
        # the shoulder rotation maps the frame (a, b⊥) onto (e, c⊥): R123 = F2·F1ᵀ
        F1 = np.stack([a_hat, bp, _cross(a_hat, bp)], axis=2)           # (N, 3, 3)
        F2 = np.stack([e, cd, _cross(e, cd)], axis=2)
        R123 = F2 @ np.swapaxes(F1, -1, -2)
        # 3. the shoulder: Rot(h1,q1) Rot(h2,q2) h3 = R123 h3, then q3
        t1, t2, ok_s = _sp2(H[0], H[1], H[2], R123 @ H[2])
        # 4. the wrist: Rot(h5) Rot(h6) Rot(h7) = (R123 R4)ᵀ R_T R_Mᵀ
        X = np.swapaxes(R123 @ R4, -1, -2) @ Rw
        t5, t6, ok_w = _sp2(H[4], H[5], H[6], X @ H[6])
        for i_s in range(2):
            R3 = np.swapaxes(_rot(H[0], t1[:, i_s]) @ _rot(H[1], t2[:, i_s]), -1, -2) @ R123
            q3 = _sp1(H[2], np.broadcast_to(x3, (N, 3)), R3 @ x3)
            for i_w in range(2):
                R7 = np.swapaxes(_rot(H[4], t5[:, i_w]) @ _rot(H[5], t6[:, i_w]), -1, -2) @ X
                q7 = _sp1(H[6], np.broadcast_to(x7, (N, 3)), R7 @ x7)
                j = 4 * i4 + 2 * i_s + i_w
                Q[:, j] = np.stack([t1[:, i_s], t2[:, i_s], q3, q4s[:, i4],
                                    t5[:, i_w], t6[:, i_w], q7], axis=1)
                ok[:, j] = ok4 & ok_s & ok_w
    return Q, ok


def _elbow_angles(arm: SRSArm, L: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Subproblem 3: the two q4 with ``|p4 + Rot(h4, q4)·(W0 − p4) − S| = L`` for each L (N,).

    With u = W0 − p4 split along and across h4 and v = S − p4, the distance condition is
    ``A cos q4 + B sin q4 = k`` (A = v·u⊥, B = v·(h4 × u⊥), k = (|u|² + |v|² − L²)/2 −
    v·u∥): q4 = atan2(B, A) ± acos(k / hypot(A, B)). Returns (N, 2) angles and (N,)
    flags, False beyond reach (beyond rounding).
    """
    h4, p4 = arm.H[3], arm.P[3]
    u = arm.W0 - p4
    v = arm.S - p4
    u_par = (u @ h4) * h4
    u_perp = u - u_par
    A = float(v @ u_perp)
    B = float(v @ np.cross(h4, u_perp))
    k = 0.5 * (float(u @ u + v @ v) - np.asarray(L) ** 2) - float(v @ u_par)
    rho = math.hypot(A, B)
    ratio = k / rho if rho > 0.0 else np.full(np.shape(L), np.inf)
    ok = np.abs(ratio) <= 1.0 + 1e-12
    phi = np.arccos(np.clip(ratio, -1.0, 1.0))
    base = math.atan2(B, A)
    return np.stack([base + phi, base - phi], axis=-1), ok


def _into_limits(arm: SRSArm, Q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Angles moved by whole turns nearest the middle of their limits; the inside mask (...,)."""
    lo, hi = arm.lo, arm.hi
    Qw = Q - _TWO_PI * np.round((Q - arm.mid) / _TWO_PI)
    inside = np.all((Qw >= lo - LIMIT_TOL) & (Qw <= hi + LIMIT_TOL), axis=-1)
    return Qw, inside


def ik_arm_angle(robot: Robot, T: object, psi: float, reference: object = None, *,
                 tol: float = 1e-9) -> ArmAngleSolutions:
    """Every configuration of an S-R-S arm reaching pose T at arm angle ψ (closed form).

    Args:
        robot: a 7R arm with a spherical shoulder and wrist (:func:`srs_structure`).
        T: (4, 4) target pose of the tool in the base frame.
        psi: the arm angle [rad] (eq 1 of the module docstring).
        reference: the direction r of eq (1) (default the base z axis).
        tol: each returned row reproduces T within ``tol``·max(1, size) m and ``tol`` on
            the rotation entries.

    Returns:
        :class:`ArmAngleSolutions`: up to 8 rows, inside the joint limits (angles moved
        by whole turns nearest the middle of their limits), sorted by branch; empty when
        the pose is out of reach at this ψ.

    Raises:
        NoClosedFormError: the robot is not an S-R-S arm (the message says why).
        InputError: T is not a rigid transform, ψ not finite, r not a direction.
    """
    Tt = check_transform(T, "T")
    if Tt.shape != (4, 4):
        raise InputError(f"T must be one (4, 4) pose, got shape {Tt.shape}")
    return ik_arm_angle_path(robot, Tt[None], psi, reference, tol=tol)[0]


def ik_arm_angle_path(robot: Robot, T: object, psi: float, reference: object = None, *,
                      tol: float = 1e-9) -> list[ArmAngleSolutions]:
    """:func:`ik_arm_angle` for every pose of a path (p, 4, 4) at one arm angle ψ [rad].

    The same closed form, computed for all poses at once (a path of 1,000 poses in a few
    milliseconds). Returns one :class:`ArmAngleSolutions` per pose.
    """
    arm = srs_structure(robot)
    Tt = check_transform(T, "T")
    if Tt.ndim != 3:
        raise InputError(f"T must be (p, 4, 4) poses, got shape {Tt.shape}")
    psi_f = float(psi)
    if not math.isfinite(psi_f):
        raise InputError(f"psi must be a finite angle in radians, got {psi!r}")
    p = len(Tt)
    Q, ok = _solve(arm, Tt, np.full(p, psi_f), _reference(reference))
    Qw, inside = _into_limits(arm, Q)
    which, branch = np.nonzero(ok & inside)                     # (pose, branch) pairs
    rows = Qw[which, branch]
    if len(rows):
        rows = _polish(robot, rows, Tt[which])
        good = _reaches(robot, rows, Tt[which], tol, arm.scale)
        which, branch, rows = which[good], branch[good], rows[good]
    starts = np.searchsorted(which, np.arange(p + 1))
    return [ArmAngleSolutions(q=rows[a:b], branch=branch[a:b].astype(np.int64), psi=psi_f)
            for a, b in zip(starts[:-1], starts[1:])]


def _polish(robot: Robot, Q: np.ndarray, T: np.ndarray, steps: int = 3) -> np.ndarray:
    """Minimum-norm Newton steps ``Δq = J⁺ e`` on rows that miss T by rounding-amplified error.

    Next to a stretched or folded elbow the elbow angle is an ``acos`` of a number within
    rounding of ±1, so its error is about √ε (1e-8 rad) and the pose misses by as much.
    Rows whose pose error e = [Δp; log(R_T Rᵀ)] is above 1e-13 and below 1e-5 take up to
    three steps with the geometric Jacobian (they then meet T to rounding; ψ moves by as
    little as the step, ~1e-8 rad). Other rows are returned unchanged.
    """
    Q = Q.copy()
    for _ in range(steps):
        e = pose_error(robot.fk(Q), T, check=False)
        size = np.abs(e).max(axis=1)
        fix = (size > 1e-13) & (size < 1e-5)
        if not fix.any():
            break
        J = robot.jacobian(Q[fix])
        Q[fix] += np.einsum("kij,kj->ki", np.linalg.pinv(J), e[fix])
    return Q


def _reaches(robot: Robot, Q: np.ndarray, T: np.ndarray, tol: float, scale: float) -> np.ndarray:
    """(k,) rows Q (k, n) reaching their targets T (k, 4, 4) within tol (position scaled)."""
    F = robot.fk(Q)
    pos = np.linalg.norm(F[..., :3, 3] - T[..., :3, 3], axis=-1) <= tol * max(1.0, scale)
    rot = np.abs(F[..., :3, :3] - T[..., :3, :3]).max(axis=(-2, -1)) <= tol
    return pos & rot


# ------------------------------------------------------------- feasible intervals

def arm_angle_intervals(robot: Robot, T: object, reference: object = None, *,
                        resolution: float = math.radians(0.5)) -> ArmAngleIntervals:
    """The arm angles ψ at which each branch reaches pose T inside the joint limits.

    Every branch is evaluated in closed form on a grid of ψ over [−π, π] with step
    ``resolution`` [rad]; each change from feasible to infeasible is then refined by
    bisection (all ends at once) to 1e-10 rad. A feasible stretch narrower than the grid
    step can be missed (a branch grazing a limit): lower ``resolution`` to find those.

    Returns:
        :class:`ArmAngleIntervals`.

    Raises:
        NoClosedFormError: the robot is not an S-R-S arm.
        InputError: T is not one rigid transform, or ``resolution`` not in (0, π/8].
    """
    arm = srs_structure(robot)
    Tt = check_transform(T, "T")
    if Tt.shape != (4, 4):
        raise InputError(f"T must be one (4, 4) pose, got shape {Tt.shape}")
    if not (0.0 < float(resolution) <= math.pi / 8):
        raise InputError(f"resolution must be in (0, π/8] rad, got {resolution!r}")
    r = _reference(reference)
    n = int(math.ceil(_TWO_PI / float(resolution)))
    grid = -math.pi + _TWO_PI * np.arange(n + 1) / n          # both ends: −π and π
    ok = _feasible(arm, Tt, grid, r)                           # (n + 1, 8)
    # runs of feasible grid points per branch; each inner end lies between two points
    runs = []
    for j in range(8):
        edges = np.flatnonzero(np.diff(ok[:, j].astype(np.int8)))
        starts = ([0] if ok[0, j] else []) + [int(i) + 1 for i in edges if not ok[i, j]]
        stops = [int(i) for i in edges if ok[i, j]] + ([n] if ok[n, j] else [])
        runs += [(j, a, b) for a, b in zip(starts, stops)]
    # the inner ends: (branch, infeasible ψ, feasible ψ), bisected together
    ends = [(j, grid[a - 1], grid[a]) for j, a, _ in runs if a > 0]
    ends += [(j, grid[b + 1], grid[b]) for j, _, b in runs if b < n]
    refined = _bisect(arm, Tt, r, ends)
    at = dict(zip([(j, g) for j, _, g in ends], refined))
    branches: dict[int, list[tuple[float, float]]] = {}
    for j, a, b in runs:
        lo = grid[a] if a == 0 else at[(j, grid[a])]
        hi = grid[b] if b == n else at[(j, grid[b])]
        branches.setdefault(j, []).append((float(lo), float(hi)))
    feasible = _union([s for spans in branches.values() for s in spans])
    return ArmAngleIntervals(branches=branches, feasible=feasible,
                             resolution=_TWO_PI / n, singular=_undefined(arm, Tt, r))


def _feasible(arm: SRSArm, T: np.ndarray, psi: np.ndarray, r: np.ndarray) -> np.ndarray:
    """(N, 8): branch j reaches T at ψ[i] inside the joint limits."""
    Q, ok = _solve(arm, T, psi, r)
    return ok & _into_limits(arm, Q)[1]


def _bisect(arm, T, r, ends, steps: int = 36) -> list[float]:
    """Bisect every (branch, infeasible ψ, feasible ψ) at once: the feasible ends."""
    if not ends:
        return []
    j = np.array([e[0] for e in ends])
    bad = np.array([e[1] for e in ends], dtype=float)
    good = np.array([e[2] for e in ends], dtype=float)
    rows = np.arange(len(ends))
    for _ in range(steps):  # the grid step halves 36 times: below 1e-10 rad
        mid = 0.5 * (bad + good)
        f = _feasible(arm, T, mid, r)[rows, j]
        good = np.where(f, mid, good)
        bad = np.where(f, bad, mid)
    return good.tolist()


def _undefined(arm: SRSArm, T: np.ndarray, r: np.ndarray) -> bool:
    """ψ is undefined at pose T: the line S–W parallel to r, or the elbow on that line."""
    d = _wrist_target(arm, T) - arm.S
    L = float(np.linalg.norm(d))
    if L < 1e-12 * arm.scale:
        return True
    e = d / L
    if np.linalg.norm(r - (r @ e) * e) < 1e-12:
        return True
    b = arm.E0 - arm.S
    q4s, ok = _elbow_angles(arm, np.array([L]))
    for q4 in q4s[0] if ok[0] else ():
        a = arm.P[3] + _rot(arm.H[3], np.array(q4)) @ (arm.W0 - arm.P[3]) - arm.S
        if np.linalg.norm(_cross(a, b)) < 1e-12 * arm.scale * max(L, 1e-300):
            return True
    return False


def _union(spans: list[tuple[float, float]]) -> list[tuple[float, float]]:
    out: list[list[float]] = []
    for lo, hi in sorted(spans):
        if out and lo <= out[-1][1] + 1e-12:
            out[-1][1] = max(out[-1][1], hi)
        else:
            out.append([lo, hi])
    return [(a, b) for a, b in out]
