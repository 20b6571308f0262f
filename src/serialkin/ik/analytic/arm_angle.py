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

Units: angles in radians, lengths in metres. Steps 1–4 run compiled, one pose at one ψ
per call of :func:`_srs_one` (3-vectors as tuples: nothing allocated per ψ), batched over
poses and ψ by :func:`_srs_solve` and over interval ends by :func:`_srs_bisect`; the
arm's constants are packed once per robot. One pose at one ψ with the defaults takes one
compiled call (the rigidity check, the solve, a forward-kinematics check of each row).
The kernels belong to the ``ik-all`` compile feature (``serialkin warmup``).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from serialkin._checks import as_float_array, check_transform, readonly
from serialkin._jit import entry_point, njit
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


def _unit(v: np.ndarray) -> np.ndarray:
    n = np.linalg.norm(v, axis=-1, keepdims=True)
    return v / np.where(n > 0.0, n, 1.0)


_Z_REF = readonly(np.array([0.0, 0.0, 1.0]))


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


# ------------------------------------------------------------------- the compiled form
# One pose at one ψ in compiled code (:func:`_srs_one`, the same steps as the module
# docstring), called by :func:`_srs_solve` (poses × ψ) and :func:`_srs_bisect` (the
# interval ends). 3-vectors are tuples and rotations tuples of three rows, so nothing is
# allocated per ψ. The arm's constants are packed once per robot (:func:`_packed`):
#
# * ``H``, ``P``: (7, 3) joint directions and points, ``M``: (4, 4) the pose at q = 0;
# * ``V``: (_NV,) S (0:3), W0 (3:6), E0 (6:9), lo (9:16), hi (16:23), mid (23:30), then
#   scale, the wrist point in the tool frame (31:34), x3 = perpendicular(h3) (34:37),
#   x7 = perpendicular(h7) (37:40) and the elbow's constants A, B, atan2(B, A), |(A, B)|,
#   |u|² + |v|², v·u∥ (40:46) of :func:`_elbow_angles`.
_NV = 46


@njit(cache=True)
def _dot(a, b):
    """The dot product a · b of two 3-tuples."""
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]


@njit(cache=True)
def _crs(a, b):
    """The cross product a × b of two 3-tuples."""
    return (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])


@njit(cache=True)
def _lin(s, a, t, b):
    """s·a + t·b of two 3-tuples."""
    return (s * a[0] + t * b[0], s * a[1] + t * b[1], s * a[2] + t * b[2])


@njit(cache=True)
def _perp(e):
    """:func:`~serialkin.spatial.rotations.perpendicular` of one unit 3-tuple."""
    k = 0
    if abs(e[1]) < abs(e[0]):
        k = 1
    if abs(e[2]) < abs(e[k]):
        k = 2
    t = (1.0 if k == 0 else 0.0, 1.0 if k == 1 else 0.0, 1.0 if k == 2 else 0.0)
    v = _lin(1.0, t, -e[k], e)
    n = math.sqrt(_dot(v, v))
    return (v[0] / n, v[1] / n, v[2] / n)


@njit(cache=True)
def _rot3(h, t):
    """Rodrigues: the rotation (three row 3-tuples) by angle t about the unit 3-tuple h."""
    s, c = math.sin(t), math.cos(t)
    k = 1.0 - c
    return ((1.0 + k * (h[0] * h[0] - 1.0), k * h[0] * h[1] - s * h[2],
             k * h[0] * h[2] + s * h[1]),
            (k * h[1] * h[0] + s * h[2], 1.0 + k * (h[1] * h[1] - 1.0),
             k * h[1] * h[2] - s * h[0]),
            (k * h[2] * h[0] - s * h[1], k * h[2] * h[1] + s * h[0],
             1.0 + k * (h[2] * h[2] - 1.0)))


@njit(cache=True)
def _mv(R, v):
    """R·v."""
    return (_dot(R[0], v), _dot(R[1], v), _dot(R[2], v))


@njit(cache=True)
def _mtv(R, v):
    """Rᵀ·v."""
    return (R[0][0] * v[0] + R[1][0] * v[1] + R[2][0] * v[2],
            R[0][1] * v[0] + R[1][1] * v[1] + R[2][1] * v[2],
            R[0][2] * v[0] + R[1][2] * v[1] + R[2][2] * v[2])


@njit(cache=True)
def _mtm(A, B):
    """Aᵀ·B, by rows."""
    return (_mtv(B, (A[0][0], A[1][0], A[2][0])), _mtv(B, (A[0][1], A[1][1], A[2][1])),
            _mtv(B, (A[0][2], A[1][2], A[2][2])))


@njit(cache=True)
def _mm(A, B):
    """A·B, by rows."""
    return (_mtv(B, A[0]), _mtv(B, A[1]), _mtv(B, A[2]))


@njit(cache=True)
def _sp1_3(w, u, v):
    """Subproblem 1 (:func:`_sp1`) on 3-tuples."""
    up = _lin(1.0, u, -_dot(u, w), w)
    vp = _lin(1.0, v, -_dot(v, w), w)
    return math.atan2(_dot(_crs(up, vp), w), _dot(up, vp))


@njit(cache=True)
def _sp2_3(w1, w2, u, v, sign):
    """Subproblem 2 (:func:`_sp2`) on 3-tuples for one sign of γ: (θ1, θ2, exists)."""
    c12 = _dot(w1, w2)
    den = c12 * c12 - 1.0
    a2u = _dot(w2, u)
    a1v = _dot(v, w1)
    alpha = (c12 * a2u - a1v) / den
    beta = (c12 * a1v - a2u) / den
    x = _crs(w1, w2)
    g2 = (1.0 - alpha * alpha - beta * beta - 2.0 * alpha * beta * c12) / _dot(x, x)
    g = sign * math.sqrt(max(g2, 0.0))
    z = (alpha * w1[0] + beta * w2[0] + g * x[0], alpha * w1[1] + beta * w2[1] + g * x[1],
         alpha * w1[2] + beta * w2[2] + g * x[2])
    return _sp1_3(w1, z, v), _sp1_3(w2, u, z), g2 > -1e-9


@njit(cache=True)
def _row(A, i):
    """Row i of a (k, 3) array as a 3-tuple."""
    return (A[i, 0], A[i, 1], A[i, 2])


@njit(cache=True)
def _srs_one(T, psi, r, H, P, M, V, Q, ok):
    """Every branch at one pose T (4, 4) and arm angle ψ: Q (8, 7) [rad], ok (8,) bool.

    :func:`_solve` for one (pose, ψ), in the same steps; the angles are moved by whole
    turns nearest ``mid`` (:func:`_into_limits`) and ``ok[j]`` is True when branch j
    exists and lies inside the limits. ``r`` (3,) is the unit reference direction.
    """
    two_pi = 2.0 * math.pi
    S, W0, E0 = (V[0], V[1], V[2]), (V[3], V[4], V[5]), (V[6], V[7], V[8])
    tiny = 1e-12 * V[30]
    rr = (r[0], r[1], r[2])
    loc = (V[31], V[32], V[33])
    Wt = (T[0, 3] + T[0, 0] * loc[0] + T[0, 1] * loc[1] + T[0, 2] * loc[2],
          T[1, 3] + T[1, 0] * loc[0] + T[1, 1] * loc[1] + T[1, 2] * loc[2],
          T[2, 3] + T[2, 0] * loc[0] + T[2, 1] * loc[1] + T[2, 2] * loc[2])
    d = _lin(1.0, Wt, -1.0, S)
    L = math.sqrt(_dot(d, d))
    Lm = max(L, tiny)
    e = (d[0] / Lm, d[1] / Lm, d[2] / Lm)
    rp = _lin(1.0, rr, -_dot(e, rr), e)
    nr = math.sqrt(_dot(rp, rp))
    er = (rp[0] / nr, rp[1] / nr, rp[2] / nr) if nr > 0.0 else _perp(e)
    c_dir = _lin(math.cos(psi), er, math.sin(psi), _crs(e, er))
    # Rw = R_T · R_Mᵀ
    RT = ((T[0, 0], T[0, 1], T[0, 2]), (T[1, 0], T[1, 1], T[1, 2]),
          (T[2, 0], T[2, 1], T[2, 2]))
    RMt = ((M[0, 0], M[1, 0], M[2, 0]), (M[0, 1], M[1, 1], M[2, 1]),
           (M[0, 2], M[1, 2], M[2, 2]))
    Rw = _mm(RT, RMt)
    # 1. the elbow (subproblem 3, :func:`_elbow_angles`)
    k = 0.5 * (V[44] - L * L) - V[45]
    rho = V[43]
    ratio = k / rho if rho > 0.0 else math.inf
    ok4 = abs(ratio) <= 1.0 + 1e-12 and L > tiny
    phi = math.acos(min(max(ratio, -1.0), 1.0))
    h = (_row(H, 0), _row(H, 1), _row(H, 2), _row(H, 3), _row(H, 4), _row(H, 5), _row(H, 6))
    p4 = _row(P, 3)
    u = _lin(1.0, W0, -1.0, p4)
    b = _lin(1.0, E0, -1.0, S)
    x3 = (V[34], V[35], V[36])
    x7 = (V[37], V[38], V[39])
    for i4 in range(2):
        q4 = V[42] + phi if i4 == 0 else V[42] - phi
        R4 = _rot3(h[3], q4)
        a = _lin(1.0, _lin(1.0, p4, 1.0, _mv(R4, u)), -1.0, S)
        a_hat = (a[0] / Lm, a[1] / Lm, a[2] / Lm)
        b_perp = _lin(1.0, b, -_dot(a_hat, b), a_hat)
        nb = math.sqrt(_dot(b_perp, b_perp))
        if nb < tiny:  # the elbow on the line S–W: ψ undefined, any plane
            cd = er
            bp = _perp(a_hat)
        else:
            cd = c_dir
            nbm = max(nb, 1e-300)
            bp = (b_perp[0] / nbm, b_perp[1] / nbm, b_perp[2] / nbm)
        # R123 = F2·F1ᵀ with F1 = [a, b⊥, a × b⊥], F2 = [e, c⊥, e × c⊥] (columns)
        ab = _crs(a_hat, bp)
        ec = _crs(e, cd)
        R123 = (_lin(1.0, _lin(e[0], a_hat, cd[0], bp), ec[0], ab),
                _lin(1.0, _lin(e[1], a_hat, cd[1], bp), ec[1], ab),
                _lin(1.0, _lin(e[2], a_hat, cd[2], bp), ec[2], ab))
        X = _mtm(_mm(R123, R4), Rw)                      # (R123·R4)ᵀ·R_T·R_Mᵀ
        v3 = _mv(R123, h[2])
        v7 = _mv(X, h[6])
        for i_s in range(2):
            t1, t2, ok_s = _sp2_3(h[0], h[1], h[2], v3, 1.0 if i_s == 0 else -1.0)
            R3 = _mtm(_mm(_rot3(h[0], t1), _rot3(h[1], t2)), R123)
            q3 = _sp1_3(h[2], x3, _mv(R3, x3))
            for i_w in range(2):
                t5, t6, ok_w = _sp2_3(h[4], h[5], h[6], v7, 1.0 if i_w == 0 else -1.0)
                R7 = _mtm(_mm(_rot3(h[4], t5), _rot3(h[5], t6)), X)
                q7 = _sp1_3(h[6], x7, _mv(R7, x7))
                j = 4 * i4 + 2 * i_s + i_w
                Q[j, 0], Q[j, 1], Q[j, 2], Q[j, 3] = t1, t2, q3, q4
                Q[j, 4], Q[j, 5], Q[j, 6] = t5, t6, q7
                inside = ok4 and ok_s and ok_w
                for c in range(7):
                    x = Q[j, c] - two_pi * np.rint((Q[j, c] - V[23 + c]) / two_pi)
                    Q[j, c] = x
                    if not (V[9 + c] - LIMIT_TOL <= x <= V[16 + c] + LIMIT_TOL):
                        inside = False
                ok[j] = inside


@njit(cache=True)
def _miss(T, q, H, P, M):
    """How far the configuration q (7,) misses T: max |e| of ``pose_error`` (e = [Δp; ω]).

    Forward kinematics as the product of exponentials of the joint lines at q = 0 (H, P)
    times M; ω from the angle-axis of ``R_T·Rᵀ`` (its angle by atan2, exact near 0 and π).
    """
    R = ((1.0, 0.0, 0.0), (0.0, 1.0, 0.0), (0.0, 0.0, 1.0))
    t = (0.0, 0.0, 0.0)
    for i in range(7):
        p = _row(P, i)
        Ri = _rot3(_row(H, i), q[i])
        t = _lin(1.0, t, 1.0, _mv(R, _lin(1.0, p, -1.0, _mv(Ri, p))))
        R = _mm(R, Ri)
    t = _lin(1.0, t, 1.0, _mv(R, (M[0, 3], M[1, 3], M[2, 3])))
    R = _mm(R, ((M[0, 0], M[0, 1], M[0, 2]), (M[1, 0], M[1, 1], M[1, 2]),
                (M[2, 0], M[2, 1], M[2, 2])))
    size = max(abs(T[0, 3] - t[0]), abs(T[1, 3] - t[1]), abs(T[2, 3] - t[2]))
    E = (_mv(R, (T[0, 0], T[0, 1], T[0, 2])), _mv(R, (T[1, 0], T[1, 1], T[1, 2])),
         _mv(R, (T[2, 0], T[2, 1], T[2, 2])))                     # R_T·Rᵀ, by rows
    w = (0.5 * (E[2][1] - E[1][2]), 0.5 * (E[0][2] - E[2][0]), 0.5 * (E[1][0] - E[0][1]))
    s = math.sqrt(_dot(w, w))
    angle = math.atan2(s, 0.5 * (E[0][0] + E[1][1] + E[2][2] - 1.0))
    if s > 0.0:
        f = angle / s
        size = max(size, abs(w[0]) * f, abs(w[1]) * f, abs(w[2]) * f)
    elif angle > 1.0:  # a half turn
        size = max(size, angle)
    return size


@njit(cache=True)
def _rigid(T):
    """T (4, 4) is rigid to 1e-13: RᵀR = I, det R = 1, last row [0, 0, 0, 1], finite."""
    tol = 1e-13
    good = (abs(T[3, 0]) <= tol and abs(T[3, 1]) <= tol and abs(T[3, 2]) <= tol
            and abs(T[3, 3] - 1.0) <= tol)
    for i in range(3):
        good = good and math.isfinite(T[i, 3])
        for j in range(3):
            g = T[0, i] * T[0, j] + T[1, i] * T[1, j] + T[2, i] * T[2, j]
            good = good and abs(g - 1.0 if i == j else g) <= tol
    det = _dot((T[0, 0], T[1, 0], T[2, 0]),
               _crs((T[0, 1], T[1, 1], T[2, 1]), (T[0, 2], T[1, 2], T[2, 2])))
    return good and abs(det - 1.0) <= tol


@njit(cache=True)
def _srs_solve(T, psi, r, H, P, M, V, check, Q, found):
    """Every branch at each (pose, ψ): T (1 or N, 4, 4), ψ (N,) → Q (N, 8, 7), found (N, 8).

    Without ``check``: ``found[i, j]`` is 1 where branch j exists inside the limits at
    pose i and ψ[i] (:func:`_srs_one`), else 0; returns 0.

    With ``check`` (the fast path of :func:`ik_arm_angle`): the rows of each pose that
    meet it to 1e-13 (:func:`_miss`) are moved to the front of ``Q[i]``, ``found[i, :k]``
    their branches, −1 after them; rows missing by more than 1e-5 are dropped. Returns
    the number of rows; −1 (nothing solved) when a pose is not rigid to 1e-13 (a
    rotation block not orthonormal, a last row not [0, 0, 0, 1], NaN); −2 when a row
    misses by 1e-13 to 1e-5 (:func:`_polish` would move it).
    """
    n_t = T.shape[0]
    if check:
        for i in range(n_t):
            if not _rigid(T[i]):
                return -1
    ok = np.zeros(8, dtype=np.bool_)
    total = 0
    for i in range(psi.shape[0]):
        Ti = T[i if n_t > 1 else 0]
        Qi = Q[i]
        _srs_one(Ti, psi[i], r, H, P, M, V, Qi, ok)
        if not check:
            for j in range(8):
                found[i, j] = 1 if ok[j] else 0
            continue
        k = 0
        for j in range(8):
            found[i, j] = -1
            if ok[j]:
                size = _miss(Ti, Qi[j], H, P, M)
                if size <= 1e-13:
                    for c in range(7):
                        Qi[k, c] = Qi[j, c]
                    found[i, k] = j
                    k += 1
                elif size < 1e-5:
                    return -2
        total += k
    return total


@njit(cache=True)
def _srs_bisect(T, r, H, P, M, V, branch, bad, good, steps):
    """Bisect each (branch, infeasible ψ, feasible ψ) ``steps`` times; ``good`` (m,) updated.

    The feasible end of each of the m stretches: ``good[k]`` ends feasible on branch
    ``branch[k]`` (:func:`_srs_one`), ``bad[k]`` infeasible, |bad − good| halved per step.
    """
    Q = np.empty((8, 7))
    ok = np.zeros(8, dtype=np.bool_)
    for k in range(branch.shape[0]):
        lo, hi = bad[k], good[k]
        for _ in range(steps):
            mid = 0.5 * (lo + hi)
            _srs_one(T, mid, r, H, P, M, V, Q, ok)
            if ok[branch[k]]:
                hi = mid
            else:
                lo = mid
        good[k] = hi


# ------------------------------------------------------------- solving at given ψ

_PACKED: PerObject[tuple] = PerObject()
_ENTRIES: dict[str, object] = {}


def _packed(arm: SRSArm) -> tuple:
    """``(H, P, M, V)``: the arm's constants for the kernels, read-only (cached per arm).

    ``V`` is laid out as described above :data:`_NV`.
    """
    got = _PACKED.get(arm)
    if got is None:
        h4, p4 = arm.H[3], arm.P[3]
        u, v = arm.W0 - p4, arm.S - p4
        u_par = (u @ h4) * h4
        u_perp = u - u_par
        A, B = float(v @ u_perp), float(v @ np.cross(h4, u_perp))
        V = np.concatenate([
            arm.S, arm.W0, arm.E0, arm.lo, arm.hi, arm.mid, [arm.scale],
            arm.M[:3, :3].T @ (arm.W0 - arm.M[:3, 3]), perpendicular(arm.H[2]),
            perpendicular(arm.H[6]),
            [A, B, math.atan2(B, A), math.hypot(A, B), float(u @ u + v @ v),
             float(v @ u_par)]])
        got = _PACKED.set(arm, tuple(readonly(np.ascontiguousarray(x, dtype=np.float64))
                                     for x in (arm.H, arm.P, arm.M, V)))
    return got


def _entry(name: str):
    """The compiled entry point of ``_srs_solve`` or ``_srs_bisect`` (no type dispatch).

    Compiled for exactly the types the callers pass: read-only C-contiguous float64
    inputs (T (N, 4, 4), ψ (N,), r (3,), H, P, M, V), a bool, and fresh outputs
    (Q float64 (N, 8, 7), found int64 (N, 8)); for the bisection T (4, 4), the branches
    read-only int64, the ends float64 and an int64 step count.
    """
    found = _ENTRIES.get(name)
    if found is not None:
        return found

    def sig() -> tuple:  # numba's types, imported only when the kernel is loaded
        import numba

        Array, f64 = numba.types.Array, numba.float64

        def ro(ndim: int, dtype=f64):
            return Array(dtype, ndim, "C", readonly=True)

        if name == "solve":
            return (ro(3), ro(1), ro(1), ro(2), ro(2), ro(2), ro(1), numba.boolean,
                    Array(f64, 3, "C"), Array(numba.int64, 2, "C"))
        return (ro(2), ro(1), ro(2), ro(2), ro(2), ro(1), ro(1, numba.int64), ro(1),
                Array(f64, 1, "C"), numba.int64)

    found, final = entry_point(_srs_solve if name == "solve" else _srs_bisect, sig)
    if final:  # else the Python function while it compiles: ask again next call
        _ENTRIES[name] = found
    return found


def _solve(arm: SRSArm, T: np.ndarray, psi: np.ndarray, r: np.ndarray
           ) -> tuple[np.ndarray, np.ndarray]:
    """Every branch for every (pose, ψ): (N, 8, 7) joint values and (N, 8) 'inside' flags.

    T is one (4, 4) pose or (N, 4, 4) poses, ψ (N,), r (3,) the unit reference.
    Branch ``4·i4 + 2·is + iw``; angles moved by whole turns nearest the middle of their
    limits; a row is flagged True when its subproblems have a solution (beyond rounding)
    and it lies inside the limits. Compiled: :func:`_srs_solve`.
    """
    H, P, M, V = _packed(arm)
    T = readonly(np.ascontiguousarray(T, dtype=np.float64).reshape(-1, 4, 4))
    psi = readonly(np.ascontiguousarray(psi, dtype=np.float64).reshape(-1))
    Q = np.empty((len(psi), 8, 7))
    found = np.empty((len(psi), 8), dtype=np.int64)
    _entry("solve")(T, psi, readonly(r), H, P, M, V, False, Q, found)
    return Q, found == 1


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
    if (type(T) is np.ndarray and reference is None and tol == _TOL and T.shape == (4, 4)
            and T.dtype == np.float64 and T.flags.c_contiguous and isinstance(psi, (float, int))
            and math.isfinite(psi)):
        got = _ik_arm_angle_fast(robot, T, float(psi))
        if got is not None:
            return got
    Tt = check_transform(T, "T")
    if Tt.shape != (4, 4):
        raise InputError(f"T must be one (4, 4) pose, got shape {Tt.shape}")
    return ik_arm_angle_path(robot, Tt[None], psi, reference, tol=tol)[0]


#: The default ``tol`` of :func:`ik_arm_angle` (the fast path's).
_TOL = 1e-9
#: Per robot: its packed constants (:func:`_packed`) and the default reference z.
_FAST: PerObject[tuple] = PerObject()


def _ik_arm_angle_fast(robot: Robot, T: np.ndarray, psi: float) -> ArmAngleSolutions | None:
    """:func:`ik_arm_angle` with its defaults for one C-contiguous float64 pose T (4, 4).

    One compiled call (:func:`_srs_solve` with its checks) on the robot's cached constants:
    the rows of the ordinary path. None when T is not rigid to 1e-13 or a row would be
    polished (:func:`_polish`): the ordinary path then checks, polishes or raises.
    """
    packed = _FAST.get(robot)
    if packed is None:
        packed = _FAST.set(robot, _packed(srs_structure(robot)) + (_Z_REF,))
    H, P, M, V, r = packed
    Q = _EMPTY((1, 8, 7))
    found = _EMPTY((1, 8), _I64)
    k = _entry("solve")(T.reshape(1, 4, 4), _ARRAY((psi,)), r, H, P, M, V, True, Q, found)
    if k < 0:
        return None
    got = _NEW(ArmAngleSolutions)  # frozen: set as the dataclass's __init__ would
    _PUT(got, "q", Q[0, :k])
    _PUT(got, "branch", found[0, :k])
    _PUT(got, "psi", psi)
    return got


_EMPTY, _ARRAY, _I64 = np.empty, np.array, np.int64
_NEW, _PUT = object.__new__, object.__setattr__


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
    Q, inside = _solve(arm, Tt, np.full(p, psi_f), _reference(reference))
    which, branch = np.nonzero(inside)                          # (pose, branch) pairs
    rows = Q[which, branch]
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
    return _solve(arm, T, psi, r)[1]


def _bisect(arm: SRSArm, T: np.ndarray, r: np.ndarray, ends: list, steps: int = 36
            ) -> list[float]:
    """Bisect every (branch, infeasible ψ, feasible ψ) ``steps`` times: the feasible ends.

    36 halvings of the grid step: below 1e-10 rad. Compiled: :func:`_srs_bisect`.
    """
    if not ends:
        return []
    H, P, M, V = _packed(arm)
    j = readonly(np.array([e[0] for e in ends], dtype=np.int64))
    bad = readonly(np.array([e[1] for e in ends], dtype=np.float64))
    good = np.array([e[2] for e in ends], dtype=np.float64)
    T = readonly(np.ascontiguousarray(T, dtype=np.float64))
    _entry("bisect")(T, readonly(r), H, P, M, V, j, bad, good, steps)
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
