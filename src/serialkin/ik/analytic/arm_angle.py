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
configurations, so a branch can be followed along ψ. At a fixed pose the shoulder
rotation is linear in (cos ψ, sin ψ), so the ψ at which a joint meets a limit are roots
of ``k₀ + k_c cos ψ + k_s sin ψ = const``: the feasible intervals of ψ follow in closed
form (:func:`arm_angle_intervals`, eqs 2 and 3 below).

Units: angles in radians, lengths in metres. Steps 1–4 run compiled, one pose at one ψ
per call of :func:`_srs_one` (3-vectors as tuples: nothing allocated per ψ), batched over
poses and ψ by :func:`_srs_solve`; the feasible intervals of one pose take one call of
:func:`_srs_spans`; the arm's constants are packed once per robot. One pose at one ψ
with the defaults takes one compiled call (the rigidity check, the solve, a
forward-kinematics check of each row). The kernels belong to the ``ik-all`` compile
feature (``serialkin warmup``).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from serialkin._checks import as_float_array, check_transform, readonly
from serialkin._jit import entry_point, njit
from serialkin._memo import PerObject
from serialkin.errors import InputError, NoClosedFormError
from serialkin.ik.analytic.subproblems import sort_prefix
from serialkin.model.robot import Robot, robot_scale
from serialkin.spatial.pose import pose_error
from serialkin.spatial.rotations import perpendicular, wrap_angle

__all__ = ["ArmAngleIntervals", "ArmAngleSolutions", "SRSArm", "arm_angle",
           "arm_angle_intervals", "ik_arm_angle", "ik_arm_angle_path", "srs_structure"]

#: Lines closer than this (relative to the robot's size) meet.
MEET_TOL = 1e-9
#: Feasibility tolerance on joint limits [rad].
LIMIT_TOL = 1e-9


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
        singular: the pose leaves ψ undefined (the line S–W parallel to the reference,
            or the elbow on that line): every configuration reaching it has the same
            shoulder-elbow-wrist plane up to rotation; ``branches`` then describes ψ = 0.
    """

    branches: dict[int, list[tuple[float, float]]]
    feasible: list[tuple[float, float]]
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
# docstring), called by :func:`_srs_solve` (poses × ψ); its steps are shared with
# :func:`_srs_spans` (the feasible intervals). 3-vectors are tuples and rotations tuples
# of three rows, so nothing is allocated per ψ. The arm's constants are packed once per
# robot (:func:`_packed`):
#
# * ``H``, ``P``: (7, 3) joint directions and points, ``M``: (4, 4) the pose at q = 0;
# * ``V``: (_NV,) S (0:3), W0 (3:6), E0 (6:9), lo (9:16), hi (16:23), mid (23:30), then
#   scale, the wrist point in the tool frame (31:34), x3 = perpendicular(h3) (34:37),
#   x7 = perpendicular(h7) (37:40) and the elbow's constants A, B, atan2(B, A), |(A, B)|,
#   |u|² + |v|², v·u∥ (40:46). The elbow is subproblem 3: with u = W₀ − p₄ split along
#   and across h₄ (u∥, u⊥) and v = S − p₄, ``|p₄ + Rot(h₄, q₄)·u − S| = L`` reads
#   ``A cos q₄ + B sin q₄ = k`` (A = v·u⊥, B = v·(h₄ × u⊥), k = (|u|² + |v|² − L²)/2 −
#   v·u∥): q₄ = atan2(B, A) ± acos(k/|(A, B)|). Then, for :func:`_srs_spans`, each
#   joint's arc of limits (46:67, :func:`_arcs`) and the equations of the cuts, eq (3)
#   (67:147, :func:`_cut_table`).
_NV = 147


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
def _sp2_terms(w1, w2, u, v):
    """Subproblem 2's intermediate ``z = α w1 + β w2 + γ (w1 × w2)`` for unit u, v (tuples).

    Returns ``(α, β, w1 × w2, γ²)``: ``w2·z = w2·u``, ``w1·z = w1·v``, ``|z| = 1``; a
    solution exists when γ² ≥ 0 (:func:`_sp2_3`, :func:`_group_ok`).
    """
    c12 = _dot(w1, w2)
    den = c12 * c12 - 1.0
    a2u = _dot(w2, u)
    a1v = _dot(v, w1)
    alpha = (c12 * a2u - a1v) / den
    beta = (c12 * a1v - a2u) / den
    x = _crs(w1, w2)
    return alpha, beta, x, (1.0 - alpha * alpha - beta * beta
                            - 2.0 * alpha * beta * c12) / _dot(x, x)


@njit(cache=True)
def _sp2_3(w1, w2, u, v, sign):
    """Subproblem 2 (:func:`_sp2`) on 3-tuples for one sign of γ: (θ1, θ2, exists)."""
    alpha, beta, x, g2 = _sp2_terms(w1, w2, u, v)
    g = sign * math.sqrt(max(g2, 0.0))
    z = (alpha * w1[0] + beta * w2[0] + g * x[0], alpha * w1[1] + beta * w2[1] + g * x[1],
         alpha * w1[2] + beta * w2[2] + g * x[2])
    return _sp1_3(w1, z, v), _sp1_3(w2, u, z), g2 > -1e-9


@njit(cache=True)
def _row(A, i):
    """Row i of a (k, 3) array as a 3-tuple."""
    return (A[i, 0], A[i, 1], A[i, 2])


@njit(cache=True)
def _inside(V, c, x):
    """Joint c's angle x [rad] moved by whole turns nearest its ``mid``; whether in its limits."""
    two_pi = 2.0 * math.pi
    y = x - two_pi * np.rint((x - V[23 + c]) / two_pi)
    return y, V[9 + c] - LIMIT_TOL <= y <= V[16 + c] + LIMIT_TOL


@njit(cache=True)
def _pose_frame(T, r, M, V):
    """What a pose T (4, 4) fixes for every ψ: ``(e, er, L, Lm, nr, Rw, ratio)``.

    ``e`` the unit direction from S to the wrist target ``W_t = T·M⁻¹·W₀``, ``L = |W_t −
    S|`` [m] and ``Lm = max(L, 1e-12·size)``; ``er`` the unit part of the reference r (3,)
    perpendicular to e, of length ``nr`` before normalising (a fixed perpendicular of e
    when nr = 0); ``Rw = R_T·R_Mᵀ``; ``ratio = k/ρ`` of the elbow's subproblem 3
    (:func:`_elbow_angles`): the elbow reaches L iff |ratio| ≤ 1.
    """
    S = (V[0], V[1], V[2])
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
    RT = ((T[0, 0], T[0, 1], T[0, 2]), (T[1, 0], T[1, 1], T[1, 2]),
          (T[2, 0], T[2, 1], T[2, 2]))
    RMt = ((M[0, 0], M[1, 0], M[2, 0]), (M[0, 1], M[1, 1], M[2, 1]),
           (M[0, 2], M[1, 2], M[2, 2]))
    Rw = _mm(RT, RMt)
    k = 0.5 * (V[44] - L * L) - V[45]
    rho = V[43]
    ratio = k / rho if rho > 0.0 else math.inf
    return e, er, L, Lm, nr, Rw, ratio


@njit(cache=True)
def _elbow_frame(H, P, V, q4, Lm):
    """At elbow angle q4: ``(R4, â, b⊥, |b⊥|)``, what the shoulder rotation maps.

    ``â = (p4 + R4·(W₀ − p4) − S)/Lm`` the unit shoulder-to-wrist direction at q = 0 but
    q4 (length L when the elbow solves subproblem 3) and ``b⊥`` the part of the upper
    arm ``b = E₀ − S`` across â; R₁₂₃ maps â to e and b⊥/|b⊥| to the elbow's direction.
    """
    S, W0, E0 = (V[0], V[1], V[2]), (V[3], V[4], V[5]), (V[6], V[7], V[8])
    p4 = _row(P, 3)
    R4 = _rot3(_row(H, 3), q4)
    a = _lin(1.0, _lin(1.0, p4, 1.0, _mv(R4, _lin(1.0, W0, -1.0, p4))), -1.0, S)
    a_hat = (a[0] / Lm, a[1] / Lm, a[2] / Lm)
    b = _lin(1.0, E0, -1.0, S)
    b_perp = _lin(1.0, b, -_dot(a_hat, b), a_hat)
    return R4, a_hat, b_perp, math.sqrt(_dot(b_perp, b_perp))


@njit(cache=True)
def _shoulder_rotation(e, cd, a_hat, bp):
    """``R₁₂₃ = F2·F1ᵀ``, F1 = [â, b̂⊥, â × b̂⊥], F2 = [e, c, e × c] (columns; rows returned)."""
    ab = _crs(a_hat, bp)
    ec = _crs(e, cd)
    return (_lin(1.0, _lin(e[0], a_hat, cd[0], bp), ec[0], ab),
            _lin(1.0, _lin(e[1], a_hat, cd[1], bp), ec[1], ab),
            _lin(1.0, _lin(e[2], a_hat, cd[2], bp), ec[2], ab))


@njit(cache=True)
def _spherical(h1, h2, h3, x3, R, v, sign):
    """One solution of ``Rot(h1, t1)·Rot(h2, t2)·Rot(h3, t3) = R``: ``(t1, t2, t3, exists)``.

    Subproblem 2 for (t1, t2) with ``v = R·h3`` and the sign of γ (the branch),
    subproblem 1 for t3 on ``x3 ⊥ h3``. Angles in (−π, π] [rad].
    """
    t1, t2, ok = _sp2_3(h1, h2, h3, v, sign)
    R3 = _mtm(_mm(_rot3(h1, t1), _rot3(h2, t2)), R)
    return t1, t2, _sp1_3(h3, x3, _mv(R3, x3)), ok


@njit(cache=True)
def _srs_one(T, psi, r, H, P, M, V, Q, ok):
    """Every branch at one pose T (4, 4) and arm angle ψ: Q (8, 7) [rad], ok (8,) bool.

    :func:`_solve` for one (pose, ψ), in the same steps; the angles are moved by whole
    turns nearest ``mid`` (:func:`_inside`) and ``ok[j]`` is True when branch j exists
    and lies inside the limits. ``r`` (3,) is the unit reference direction.
    """
    e, er, L, Lm, _, Rw, ratio = _pose_frame(T, r, M, V)
    tiny = 1e-12 * V[30]
    c_dir = _lin(math.cos(psi), er, math.sin(psi), _crs(e, er))
    # 1. the elbow (subproblem 3, see :data:`_NV`)
    ok4 = abs(ratio) <= 1.0 + 1e-12 and L > tiny
    phi = math.acos(min(max(ratio, -1.0), 1.0))
    h = (_row(H, 0), _row(H, 1), _row(H, 2), _row(H, 3), _row(H, 4), _row(H, 5), _row(H, 6))
    x3 = (V[34], V[35], V[36])
    x7 = (V[37], V[38], V[39])
    for i4 in range(2):
        q4 = V[42] + phi if i4 == 0 else V[42] - phi
        R4, a_hat, b_perp, nb = _elbow_frame(H, P, V, q4, Lm)
        if nb < tiny:  # the elbow on the line S–W: ψ undefined, any plane
            cd = er
            bp = _perp(a_hat)
        else:
            cd = c_dir
            bp = (b_perp[0] / nb, b_perp[1] / nb, b_perp[2] / nb)
        # 2. the shoulder rotation; 3., 4. the shoulder's and the wrist's angles
        R123 = _shoulder_rotation(e, cd, a_hat, bp)
        X = _mtm(_mm(R123, R4), Rw)                      # (R123·R4)ᵀ·R_T·R_Mᵀ
        v3 = _mv(R123, h[2])
        v7 = _mv(X, h[6])
        wrists = (_spherical(h[4], h[5], h[6], x7, X, v7, 1.0),
                  _spherical(h[4], h[5], h[6], x7, X, v7, -1.0))
        for i_s in range(2):
            t1, t2, q3, ok_s = _spherical(h[0], h[1], h[2], x3, R123, v3,
                                          1.0 if i_s == 0 else -1.0)
            for i_w in range(2):
                t5, t6, q7, ok_w = wrists[i_w]
                j = 4 * i4 + 2 * i_s + i_w
                Q[j, 0], Q[j, 1], Q[j, 2], Q[j, 3] = t1, t2, q3, q4
                Q[j, 4], Q[j, 5], Q[j, 6] = t5, t6, q7
                inside = ok4 and ok_s and ok_w
                for c in range(7):
                    Q[j, c], good = _inside(V, c, Q[j, c])
                    inside = inside and good
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


# ------------------------------------------------------- feasible ψ in closed form
# At a fixed pose and elbow angle the shoulder rotation built by :func:`_srs_one` is
#
#     R₁₂₃(ψ) = e·âᵀ + cos ψ·(e_r·b̂ᵀ + f·ĉᵀ) + sin ψ·(f·b̂ᵀ − e_r·ĉᵀ)                (2)
#
# with f = e × e_r, b̂ = b⊥/|b⊥| and ĉ = â × b̂: linear in (cos ψ, sin ψ) (Shimizu et al.
# 2008, sec. III), and so is the wrist's X = R₄ᵀ·R₁₂₃ᵀ·R_w. For a spherical group
# Rot(h₁, t₁)·Rot(h₂, t₂)·Rot(h₃, t₃) = R (R₁₂₃ or X) the two vectors
#
#     v(ψ) = R·h₃ = v₀ + v_c cos ψ + v_s sin ψ,    u(ψ) = Rᵀ·h₁ = u₀ + u_c cos ψ + u_s sin ψ
#
# decide everything (:func:`_sinusoid` gives the coefficients):
#
#     t₁ = λ  ⇔  (Rot(h₁, λ)·h₂)·v(ψ) = h₂·h₃          (h₂ is fixed by Rot(h₂, t₂))
#     t₂ = λ  ⇔  h₁·v(ψ) = h₁·Rot(h₂, λ)·h₃            (h₁ is fixed by Rot(h₁, t₁))
#     t₃ = λ  ⇔  u(ψ)·(Rot(h₃, −λ)·h₂) = h₁·h₂         (h₂ is fixed by Rot(h₂, t₂))   (3)
#
# (each "⇔": one of the group's two solutions has that angle, modulo 2π); the group has
# solutions where subproblem 2's γ² ≥ 0, a quadratic in w = h₁·v(ψ). So every ψ at which
# a joint meets a limit, or a group's solutions appear or vanish, is a root of
# ``k₀ + k_c cos ψ + k_s sin ψ = const``: at most two each, in closed form
# (:func:`_roots`). The pivot angles t₁, t₃ jump where h₁ ∥ v (w = ±1, an extremum of
# w(ψ)): those ψ are cuts too. Between consecutive cuts no angle meets a limit or jumps,
# so one evaluation of the group at the middle decides the whole stretch
# (:func:`_group_feasible`: the same subproblems as :func:`_srs_one`, but each angle kept
# as its (cos, sin) and tested against its arc of limits, without atan2).

#: Cuts of ψ per spherical group: 3 joints × 2 limits × 2 roots, 2 × 2 existence roots,
#: 2 extrema, and the ends −π, π.
_MAX_CUTS = 20
#: Feasible stretches per branch: ≤ 9 per group; an intersection of 9 and 9 has ≤ 17.
_MAX_SPANS = 18
#: Limits are met at ``limit ∓ (LIMIT_TOL − _MARGIN)``: just inside the kernels' test.
_MARGIN = 1e-12


@njit(cache=True)
def _sinusoid(y, e, er, f, a, b, c, line, transposed):
    """R·y (or Rᵀ·y) as ``v₀ + v_c cos ψ + v_s sin ψ``: the three 3-tuples (v₀, v_c, v_s).

    ``R = e·aᵀ + cos ψ (er·bᵀ + f·cᵀ) + sin ψ (f·bᵀ − er·cᵀ)``: eq (2) with (a, b, c) =
    (â, b̂, ĉ). ``transposed``: Rᵀ·y, whose coefficients are
    those of R·y with the triples swapped and v_s negated. ``line``: the elbow on the line
    S–W, where :func:`_srs_one` takes ψ = 0 whatever ψ (v_c, v_s = 0).
    """
    if transposed:
        e, er, f, a, b, c = a, b, c, e, er, f
    ay, by, cy = _dot(a, y), _dot(b, y), _dot(c, y)
    v0 = (e[0] * ay, e[1] * ay, e[2] * ay)
    vc = _lin(by, er, cy, f)
    vs = _lin(-by, f, cy, er) if transposed else _lin(by, f, -cy, er)
    if line:
        return _lin(1.0, v0, 1.0, vc), (0.0, 0.0, 0.0), (0.0, 0.0, 0.0)
    return v0, vc, vs


@njit(cache=True)
def _wrap_pi(x):
    """The angle x [rad] moved by whole turns into [−π, π]."""
    return x - 2.0 * math.pi * np.rint(x / (2.0 * math.pi))


@njit(cache=True)
def _roots(k0, kc, ks, rhs, cuts, n):
    """Append the ψ in [−π, π] with ``k0 + kc cos ψ + ks sin ψ = rhs`` to cuts; the new n.

    ``kc cos ψ + ks sin ψ = ρ cos(ψ − φ)``, ρ = |(kc, ks)|, φ = atan2(ks, kc): ψ = φ ±
    acos((rhs − k0)/ρ), both kept (clamped) when the ratio is within 1e-12 of ±1.
    """
    rho = math.hypot(kc, ks)
    if not rho > 0.0:
        return n
    t = (rhs - k0) / rho
    if abs(t) > 1.0 + 1e-12:
        return n
    phi = math.atan2(ks, kc)
    d = math.acos(min(max(t, -1.0), 1.0))
    cuts[n] = _wrap_pi(phi + d)
    cuts[n + 1] = _wrap_pi(phi - d)
    return n + 2


@njit(cache=True)
def _in_arc(V, c, x, y):
    """Joint c's angle atan2(y, x) lies in its limits (± LIMIT_TOL), modulo 2π.

    The arc's middle (cos, sin) and the cosine of its half width are ``V[46 + 3c:49 + 3c]``
    (cosine −2, middle (1, 0): no limit).
    """
    return x * V[46 + 3 * c] + y * V[47 + 3 * c] >= V[48 + 3 * c] * math.hypot(x, y)


@njit(cache=True)
def _solution_ok(V, base, h1, h2, h3, z, v, u):
    """One solution of a spherical group, given subproblem 2's z = Rot(h2, t2)·h3, in limits.

    The angles as (cos, sin) pairs, unnormalised: ``t2`` takes h3 to z about h2, ``t1``
    takes z to v = R·h3 about h1, ``t3`` takes u = Rᵀ·h1 to Rot(h2, −t2)·h1 about h3
    (R = Rot(h1, t1)·Rot(h2, t2)·Rot(h3, t3) gives Rᵀ·h1 = Rot(h3, −t3)·Rot(h2, −t2)·h1).
    """
    h3p = _lin(1.0, h3, -_dot(h3, h2), h2)
    zp = _lin(1.0, z, -_dot(z, h2), h2)
    c2, s2 = _dot(h3p, zp), _dot(h2, _crs(h3p, zp))
    if not _in_arc(V, base + 1, c2, s2):
        return False
    zq = _lin(1.0, z, -_dot(z, h1), h1)
    vq = _lin(1.0, v, -_dot(v, h1), h1)
    if not _in_arc(V, base, _dot(zq, vq), _dot(h1, _crs(zq, vq))):
        return False
    n2 = math.hypot(c2, s2)
    if n2 > 0.0:
        c2, s2 = c2 / n2, s2 / n2
    c12 = _dot(h1, h2)
    target = _lin(1.0, _lin(c2, _lin(1.0, h1, -c12, h2), -s2, _crs(h2, h1)), c12, h2)
    up = _lin(1.0, u, -_dot(u, h3), h3)
    tp = _lin(1.0, target, -_dot(target, h3), h3)
    return _in_arc(V, base + 2, _dot(up, tp), _dot(h3, _crs(up, tp)))


@njit(cache=True)
def _group_feasible(psi, base, gv, gu, h, V):
    """Whether each solution of a spherical group exists inside its limits at ψ [rad].

    Joints base..base + 2 with axes h1, h2, h3; ``gv``, ``gu`` the sinusoids of v = R·h3
    and u = Rᵀ·h1 (eq 3). Subproblem 2 as in :func:`_sp2_3` (exists iff γ² > −1e-9),
    the angles tested by :func:`_solution_ok`. Returns (γ ≥ 0 solution ok, γ ≤ 0 ok).
    """
    h1, h2, h3 = h[base], h[base + 1], h[base + 2]
    cs, sn = math.cos(psi), math.sin(psi)
    v = _lin(1.0, gv[0], 1.0, _lin(cs, gv[1], sn, gv[2]))
    u = _lin(1.0, gu[0], 1.0, _lin(cs, gu[1], sn, gu[2]))
    alpha, beta, x, g2 = _sp2_terms(h1, h2, h3, v)
    if not g2 > -1e-9:
        return False, False
    g = math.sqrt(max(g2, 0.0))
    z = _lin(1.0, _lin(alpha, h1, beta, h2), g, x)
    first = _solution_ok(V, base, h1, h2, h3, z, v, u)
    z = _lin(1.0, _lin(alpha, h1, beta, h2), -g, x)
    return first, _solution_ok(V, base, h1, h2, h3, z, v, u)


@njit(cache=True)
def _group_cuts(base, gv, gu, h, V, cuts):
    """The sorted ψ where one group's feasibility can change (eq 3); returns how many.

    Each of the group's eight equations ``d·v(ψ) = rhs`` or ``d·u(ψ) = rhs`` (its row of
    ``V[67:147]``, :func:`_cut_table`: the limits of its three joints and the two
    bounds of existence), the extrema of w(ψ) = h1·v(ψ) within 1e-9 of ±1, and −π, π.
    """
    cuts[0], cuts[1] = -math.pi, math.pi
    n = 2
    o = 67 + 10 * base  # 40 numbers per group: base 0 or 4
    for row in range(8):
        i = o + 5 * row
        if V[i + 3] < 0.0:
            continue  # no limit (or no bound)
        g = gu if V[i + 3] > 0.0 else gv
        d = (V[i], V[i + 1], V[i + 2])
        n = _roots(_dot(d, g[0]), _dot(d, g[1]), _dot(d, g[2]), V[i + 4], cuts, n)
    h1 = h[base]
    k0, kc, ks = _dot(h1, gv[0]), _dot(h1, gv[1]), _dot(h1, gv[2])
    rho = math.hypot(kc, ks)
    if rho > 0.0:  # h1 ∥ v at an extremum of w(ψ): the pivots t1, t3 jump
        phi = math.atan2(ks, kc)
        if k0 + rho >= 1.0 - 1e-9:
            cuts[n] = _wrap_pi(phi)
            n += 1
        if k0 - rho <= -1.0 + 1e-9:
            cuts[n] = _wrap_pi(phi + math.pi)
            n += 1
    sort_prefix(cuts, n)  # n ≤ 20
    return n


@njit(cache=True)
def _nudge(x, toward, s, base, gv, gu, h, V):
    """x, or the point nearest x towards ``toward`` where solution s of the group is feasible.

    A cut is a root computed in floating point, with the limits moved inwards by
    ``_MARGIN``: should rounding still leave it outside, steps of 1e-15 rad, doubling, at
    most to ``toward`` (the middle of the feasible stretch). The seam ±π is kept.
    """
    if abs(x) >= math.pi:
        return x
    step = 1e-15 if toward > x else -1e-15
    y = x
    for _ in range(64):
        if _group_feasible(y, base, gv, gu, h, V)[s]:
            return y
        y = x + step
        if (toward - y) * step <= 0.0:
            return toward
        step *= 2.0
    return toward


@njit(cache=True)
def _group_runs(base, gv, gu, h, V, cuts, feasible, runs, found):
    """The closed stretches of ψ in [−π, π] where each solution of one group is feasible.

    Each stretch between consecutive cuts (:func:`_group_cuts`) is decided at its middle
    (:func:`_group_feasible`, into the scratch ``feasible`` (2, _MAX_CUTS)); feasible
    neighbours join; ends are moved onto feasible ψ (:func:`_nudge`). Writes
    ``runs[s, :found[s]]`` (ψ_lo, ψ_hi) for the solution with γ ≥ 0 (s = 0) and γ ≤ 0
    (s = 1).
    """
    n = _group_cuts(base, gv, gu, h, V, cuts)
    for i in range(n - 1):
        if cuts[i + 1] > cuts[i]:
            feasible[0, i], feasible[1, i] = _group_feasible(0.5 * (cuts[i] + cuts[i + 1]),
                                                             base, gv, gu, h, V)
    for s in range(2):
        k = 0
        inside = False
        start = middle = 0.0  # the run's start, the middle of its last stretch
        for i in range(n - 1):
            a, b = cuts[i], cuts[i + 1]
            if not b > a:
                continue
            if feasible[s, i] and not inside:
                start = _nudge(a, 0.5 * (a + b), s, base, gv, gu, h, V)
            elif inside and not feasible[s, i]:
                runs[s, k, 0] = start
                runs[s, k, 1] = _nudge(a, middle, s, base, gv, gu, h, V)
                k += 1
            if feasible[s, i]:
                middle = 0.5 * (a + b)
            inside = feasible[s, i]
        if inside:
            runs[s, k, 0] = start
            runs[s, k, 1] = math.pi
            k += 1
        found[s] = k


@njit(cache=True)
def _intersect(A, na, B, nb, out):
    """The intersection of two sorted lists of disjoint closed stretches: out[:k], k returned.

    A (na, 2) and B (nb, 2); stretches that only touch (no width) are left out.
    """
    i = j = k = 0
    while i < na and j < nb:
        lo = max(A[i, 0], B[j, 0])
        hi = min(A[i, 1], B[j, 1])
        if lo < hi:
            out[k, 0] = lo
            out[k, 1] = hi
            k += 1
        if A[i, 1] < B[j, 1]:
            i += 1
        else:
            j += 1
    return k


@njit(cache=True)
def _srs_spans(T, r, H, P, M, V, check, out, counts):
    """The feasible ψ of every branch at pose T (4, 4): ``out[j, :counts[j]]`` (ψ_lo, ψ_hi).

    For each elbow angle inside its limits, the shoulder's and the wrist's feasible
    stretches (:func:`_group_runs`) on the sinusoids v(ψ), u(ψ) of eq (3): for the
    shoulder v = R₁₂₃·h3, u = R₁₂₃ᵀ·h1; for the wrist v = X·h7 = R4ᵀ·(R₁₂₃ᵀ·R_w·h7),
    u = Xᵀ·h5 = R_wᵀ·(R₁₂₃·R4·h5). They are intersected per branch ``4·i4 + 2·is + iw``
    (:func:`_intersect`). ``out`` is (8, _MAX_SPANS, 2), ``counts`` (8,). Returns 1 when
    ψ is undefined at T (the line S–W along r or of no length, or the elbow on it), 0
    otherwise; with ``check``, −1 (nothing done) when T is not rigid to 1e-13
    (:func:`_rigid`).
    """
    for j in range(8):
        counts[j] = 0
    if check and not _rigid(T):
        return -1
    e, er, L, Lm, nr, Rw, ratio = _pose_frame(T, r, M, V)
    tiny = 1e-12 * V[30]
    singular = L < tiny or nr < 1e-12
    if not (abs(ratio) <= 1.0 + 1e-12 and L > tiny):
        return 1 if singular else 0
    phi = math.acos(min(max(ratio, -1.0), 1.0))
    f = _crs(e, er)
    h = (_row(H, 0), _row(H, 1), _row(H, 2), _row(H, 3), _row(H, 4), _row(H, 5), _row(H, 6))
    eye = ((1.0, 0.0, 0.0), (0.0, 1.0, 0.0), (0.0, 0.0, 1.0))
    cuts = np.empty(_MAX_CUTS)
    feasible = np.empty((2, _MAX_CUTS), dtype=np.bool_)
    runs = np.empty((2, 2, _MAX_SPANS, 2))   # group, solution, stretch, (lo, hi)
    found = np.empty((2, 2), dtype=np.int64)
    for i4 in range(2):
        q4 = V[42] + phi if i4 == 0 else V[42] - phi
        R4, a_hat, b_perp, nb = _elbow_frame(H, P, V, q4, Lm)
        line = nb < tiny
        singular = singular or line
        if not _inside(V, 3, q4)[1]:
            continue
        bp = _perp(a_hat) if line else (b_perp[0] / nb, b_perp[1] / nb, b_perp[2] / nb)
        ab = _crs(a_hat, bp)
        for g in range(2):
            if g == 0:
                yv, tv, Pv, yu, tu, Pu = h[2], False, eye, h[0], True, eye
            else:
                yv, tv, Pv, yu, tu, Pu = _mv(Rw, h[6]), True, R4, _mv(R4, h[4]), False, Rw
            sv = _sinusoid(yv, e, er, f, a_hat, bp, ab, line, tv)
            su = _sinusoid(yu, e, er, f, a_hat, bp, ab, line, tu)
            gv = (_mtv(Pv, sv[0]), _mtv(Pv, sv[1]), _mtv(Pv, sv[2]))
            gu = (_mtv(Pu, su[0]), _mtv(Pu, su[1]), _mtv(Pu, su[2]))
            _group_runs(4 * g, gv, gu, h, V, cuts, feasible, runs[g], found[g])
        for j in range(4 * i4, 4 * i4 + 4):
            i_s, i_w = (j >> 1) & 1, j & 1
            counts[j] = _intersect(runs[0, i_s], found[0, i_s], runs[1, i_w], found[1, i_w],
                                   out[j])
    return 1 if singular else 0


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
             float(v @ u_par)], _arcs(arm), _cut_table(arm)])
        got = _PACKED.set(arm, tuple(readonly(np.ascontiguousarray(x, dtype=np.float64))
                                     for x in (arm.H, arm.P, arm.M, V)))
    return got


def _restricted(arm: SRSArm) -> np.ndarray:
    """(7,) bool: joints whose limits (± LIMIT_TOL) leave out part of the circle."""
    lo, hi = arm.lo - LIMIT_TOL, arm.hi + LIMIT_TOL
    with np.errstate(invalid="ignore"):
        return np.isfinite(lo) & np.isfinite(hi) & (hi - lo < 2.0 * math.pi)


def _arcs(arm: SRSArm) -> np.ndarray:
    """(21,) per joint: cos m, sin m, cos w of its arc of limits m ± w (± LIMIT_TOL).

    ``(cos t, sin t)·(cos m, sin m) ≥ cos w`` iff t lies in the arc, modulo 2π; −2 for
    cos w (and m = 0) where the limits leave out no angle (:func:`_in_arc`).
    """
    out = np.tile([1.0, 0.0, -2.0], (7, 1))
    for c in np.flatnonzero(_restricted(arm)):
        m = 0.5 * (arm.lo[c] + arm.hi[c])
        out[c] = [math.cos(m), math.sin(m), math.cos(0.5 * (arm.hi[c] - arm.lo[c]) + LIMIT_TOL)]
    return out.reshape(-1)


def _cut_table(arm: SRSArm) -> np.ndarray:
    """(80,) per group (shoulder, wrist) the eight equations of its cuts (eq 3), 5 numbers each.

    A row ``(d, which, rhs)`` is ``d·v(ψ) = rhs`` (which = 0) or ``d·u(ψ) = rhs``
    (which = 1), or nothing (which = −1): t1 at its lower and upper limit λ (moved out by
    ``LIMIT_TOL − _MARGIN``, joints without limits skipped), ``d = Rot(h1, λ)·h2``, rhs
    h2·h3; t2, ``d = h1``, rhs ``h1·Rot(h2, λ)·h3``; t3, ``d = Rot(h3, −λ)·h2`` on u, rhs
    h1·h2; and the two bounds of w = h1·v between which subproblem 2's γ² > −(1e-9 −
    _MARGIN) (γ² is a quadratic in w: α = (c12·h2·h3 − w)/(c12² − 1), β = (c12·w −
    h2·h3)/(c12² − 1), γ² = (1 − α² − β² − 2αβ c12)/|h1 × h2|²).
    """
    out = np.zeros((2, 8, 5))
    out[:, :, 3] = -1.0
    restricted = _restricted(arm)
    for g, base in enumerate((0, 4)):
        h1, h2, h3 = arm.H[base:base + 3]
        for side, (lim, sign) in enumerate(((arm.lo, -1.0), (arm.hi, 1.0))):
            lam = lim[base:base + 3] + sign * (LIMIT_TOL - _MARGIN)
            if restricted[base]:
                out[g, side] = [*(_rot(h1, np.array(lam[0])) @ h2), 0.0, h2 @ h3]
            if restricted[base + 1]:
                out[g, 2 + side] = [*h1, 0.0, h1 @ _rot(h2, np.array(lam[1])) @ h3]
            if restricted[base + 2]:
                out[g, 4 + side] = [*(_rot(h3, np.array(-lam[2])) @ h2), 1.0, h1 @ h2]
        c12, a2u = float(h1 @ h2), float(h2 @ h3)
        den = c12 * c12 - 1.0
        a0, a1, b0, b1 = c12 * a2u / den, -1.0 / den, -a2u / den, c12 / den
        qa = a1 * a1 + b1 * b1 + 2.0 * c12 * a1 * b1
        qb = 2.0 * (a0 * a1 + b0 * b1 + c12 * (a0 * b1 + a1 * b0))
        qc = (a0 * a0 + b0 * b0 + 2.0 * c12 * a0 * b0 - 1.0
              - (1e-9 - _MARGIN) * float(np.cross(h1, h2) @ np.cross(h1, h2)))
        disc = qb * qb - 4.0 * qa * qc
        if disc >= 0.0:
            for k, sign in enumerate((1.0, -1.0)):
                out[g, 6 + k] = [*h1, 0.0, (-qb + sign * math.sqrt(disc)) / (2.0 * qa)]
    return out.reshape(-1)


def _entry(name: str):
    """The compiled entry point of ``_srs_solve`` or ``_srs_spans`` (no type dispatch).

    Compiled for exactly the types the callers pass: read-only C-contiguous float64
    inputs (T (N, 4, 4), ψ (N,), r (3,), H, P, M, V), a bool, and fresh outputs
    (Q float64 (N, 8, 7), found int64 (N, 8)); for the spans T (4, 4), r, H, P, M, V
    read-only, a bool and fresh outputs (float64 (8, _MAX_SPANS, 2), int64 (8,)).
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
        return (ro(2), ro(1), ro(2), ro(2), ro(2), ro(1), numba.boolean, Array(f64, 3, "C"),
                Array(numba.int64, 1, "C"))

    found, final = entry_point(_srs_solve if name == "solve" else _srs_spans, sig)
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

def arm_angle_intervals(robot: Robot, T: object, reference: object = None) -> ArmAngleIntervals:
    """The arm angles ψ at which each branch reaches pose T inside the joint limits.

    In closed form (eqs 2 and 3 above, after Shimizu et al. 2008): for each elbow angle,
    every ψ at which a shoulder or wrist angle meets a limit, at which a group's solutions
    appear or vanish, or at which a pivot angle jumps (h₁ ∥ R·h₃), is a root of
    ``k₀ + k_c cos ψ + k_s sin ψ = const``; between consecutive roots one evaluation of
    the closed form decides feasibility. Each inner end is feasible, with a joint at its
    limit (within ``LIMIT_TOL``), or at the edge of a group's existence or at a jump.
    Compiled: :func:`_srs_spans`, one call.

    Args:
        robot: a 7R arm with a spherical shoulder and wrist (:func:`srs_structure`).
        T: (4, 4) target pose of the tool in the base frame.
        reference: the direction r of eq (1) (default the base z axis).

    Returns:
        :class:`ArmAngleIntervals`.

    Raises:
        NoClosedFormError: the robot is not an S-R-S arm.
        InputError: T is not one rigid transform, r not a direction.
    """
    arm = srs_structure(robot)
    H, P, M, V = _packed(arm)
    out = np.empty((8, _MAX_SPANS, 2))
    counts = np.empty(8, dtype=np.int64)
    spans = _entry("spans")
    if (type(T) is np.ndarray and reference is None and T.shape == (4, 4)
            and T.dtype == np.float64 and T.flags.c_contiguous):
        singular = spans(readonly(T), _Z_REF, H, P, M, V, True, out, counts)  # −1: not rigid
    else:
        singular = -1
    if singular < 0:  # the ordinary checks (messages), then the kernel without its own
        Tt = check_transform(T, "T")
        if Tt.shape != (4, 4):
            raise InputError(f"T must be one (4, 4) pose, got shape {Tt.shape}")
        singular = spans(readonly(np.ascontiguousarray(Tt)), readonly(_reference(reference)),
                         H, P, M, V, False, out, counts)
    branches = {j: list(map(tuple, out[j, :k].tolist()))
                for j, k in enumerate(counts.tolist()) if k}
    return ArmAngleIntervals(branches=branches,
                             feasible=_union([s for spans in branches.values() for s in spans]),
                             singular=bool(singular))


def _union(spans: list[tuple[float, float]]) -> list[tuple[float, float]]:
    """The union of closed stretches (lo, hi), sorted; stretches within 1e-12 rad join."""
    out: list[list[float]] = []
    for lo, hi in sorted(spans):
        if out and lo <= out[-1][1] + 1e-12:
            out[-1][1] = max(out[-1][1], hi)
        else:
            out.append([lo, hi])
    return [(a, b) for a, b in out]
