"""Recognise which closed-form inverse kinematics a robot admits, from its joint axes.

The test never looks at the robot's name or at its DH table: it walks the compiled
chain (:mod:`serialkin.model.chain`) at q = 0 and reads every joint as a line in the
world frame, unit direction ``w_i`` through a point ``r_i`` (product-of-exponentials
form, ``T(q) = exp(ξ_1 q_1)···exp(ξ_n q_n)·M``). Standard DH, modified DH, general
joints and URDF therefore give the same answer for the same mechanism, and base and
tool transforms are part of the lines and of ``M`` (solving on ``M`` is the same as
solving for the flange on ``base⁻¹·T·tool⁻¹``).

Recognised classes (:data:`CLASSES`):

``planar_2r``, ``planar_3r``
    two / three revolute joints on parallel axes (the chapter's arms, eqs 21-27).
``scara``, ``scara_rrp``
    three / two revolute joints and one prismatic joint, all parallel (chapter Table 1).
``puma``
    6R with a spherical wrist (axes 4, 5, 6 meet in one point) and parallel axes 2, 3
    (axis 1 not parallel to them): Pieper's case, up to 8 solutions.
``pieper_intersecting``
    6R with a spherical wrist whose first two axes intersect: up to 8 solutions.
``pieper_general``
    any other 6R with a spherical wrist (axes 1 and 2 skew: Pieper's quartic; or
    parallel with axes 2, 3 not): up to 8.
``stanford``
    R R P with intersecting axes 1, 2 followed by a spherical wrist: up to 8.
``stanford_general``
    R R P with a spherical wrist whose axes 1 and 2 do not meet (quartic in the stroke).
``ur``
    6R with three consecutive parallel axes 2, 3, 4 (axis 1 not parallel to them) and
    intersecting axes 5, 6 (Universal Robots class): up to 8 solutions.

The geometric tests use :data:`ANGLE_TOL` [rad] and :data:`LENGTH_TOL` (relative to the
robot's size): a closed form is exact only for the exact structure, so a robot whose
axes are merely close to parallel (e.g. a URDF with angles rounded to 4 digits) is
reported as not recognised, with the measured deviation in the message.
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace

import numpy as np

from serialkin.errors import NoClosedFormError
from serialkin.model.robot import Robot
from serialkin.spatial.rotations import perpendicular

#: Two axes are parallel when |w_i × w_j| is below this [rad].
ANGLE_TOL = 1e-9
#: Two lines meet / a point is on a line within this distance, times the robot's size [m].
LENGTH_TOL = 1e-9

#: Recognised class names and what they mean.
CLASSES: dict[str, str] = {
    "planar_2r": "planar arm, two revolute joints on parallel axes",
    "planar_3r": "planar arm, three revolute joints on parallel axes",
    "scara": "SCARA: three revolute and one prismatic joint, all axes parallel",
    "scara_rrp": "two revolute and one prismatic joint, all axes parallel",
    "puma": "6R, spherical wrist, parallel axes 2 and 3 (Pieper; Puma 560 class)",
    "pieper_intersecting": "6R, spherical wrist, intersecting axes 1 and 2 (Pieper)",
    "pieper_general": "any other 6R with a spherical wrist (Pieper's quartic)",
    "stanford": "RRP arm with intersecting axes 1 and 2 and a spherical wrist (Stanford arm)",
    "stanford_general": "any other RRP arm with a spherical wrist",
    "ur": "6R, three parallel axes 2, 3, 4 and intersecting axes 5, 6 (UR class)",
}

NUMERICAL_HINT = (
    "use a numerical method instead, e.g. robot.ik(target, method='lm') "
    "(or serialkin.ik.solve(robot, target, method=...))"
)


@dataclass(frozen=True, eq=False)
class Structure:
    """A robot's joint lines at q = 0 and its recognised closed-form class.

    Attributes:
        kind: class name, a key of :data:`CLASSES`.
        W: (n, 3) unit joint directions in the world frame at q = 0.
        P: (n, 3) a point on each joint line (the joint frame's origin) [m].
        M: (4, 4) tool pose at q = 0 (base and tool transforms included).
        revolute: (n,) booleans.
        aux: (k, 3) class-specific points and vectors (see each solver).
        order: (k,) class-specific joint indices.
        planar_z: every joint axis is parallel to the world z axis, so planar targets
            (x, y), (x, y, φ) and SCARA targets (x, y, z, φ) are meaningful.
        scale: characteristic length of the robot [m] (for tolerances).
        reversed: the class was recognised on the reversed chain (:func:`reversed_lines`:
            the wrist or the parallel axes at the base); ``W``, ``P``, ``M`` are that
            chain's, whose joint j is joint n + 1 − j, and the solver solves ``T⁻¹``.
    """

    kind: str
    W: np.ndarray
    P: np.ndarray
    M: np.ndarray
    revolute: np.ndarray
    aux: np.ndarray = field(default_factory=lambda: np.zeros((0, 3)))
    order: np.ndarray = field(default_factory=lambda: np.zeros(0, dtype=np.int64))
    planar_z: bool = False
    scale: float = 1.0
    reversed: bool = False

    def __post_init__(self) -> None:
        """Own read-only C copies of the arrays: every solver kernel is compiled once.

        The kernels take ``W``, ``P``, ``M`` and ``aux`` as read-only arrays (the packed
        data of :mod:`~serialkin.ik.analytic.dispatch` is read-only); a writeable array
        passed instead would compile each of them a second time (issue 27).
        """
        for name, dtype in (("W", np.float64), ("P", np.float64), ("M", np.float64),
                            ("revolute", np.bool_), ("aux", np.float64), ("order", np.int64)):
            a = np.array(getattr(self, name), dtype=dtype, order="C")
            a.setflags(write=False)
            object.__setattr__(self, name, a)


def joint_lines(robot: Robot) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Joint lines at q = 0 in the world frame, from the compiled chain.

    These are :meth:`serialkin.Robot.joint_axes` (joint i's frame just before its motion,
    from the compiled chain) at q = 0.

    Returns:
        W (n, 3) unit directions, P (n, 3) points [m], M (4, 4) the pose ``T(0)``.
    """
    P, W = robot.joint_axes()
    T = robot.fk(np.zeros(robot.n))
    W /= np.linalg.norm(W, axis=1, keepdims=True)
    return W, P, T


def _sin_angle(w1: np.ndarray, w2: np.ndarray) -> float:
    return float(np.linalg.norm(np.cross(w1, w2)))


def _line_distance(p1, w1, p2, w2, atol: float = ANGLE_TOL) -> float:
    """Shortest distance between two lines [m]."""
    x = np.cross(w1, w2)
    nx = np.linalg.norm(x)
    d = p2 - p1
    if nx <= atol:  # parallel (also exactly, when atol is 0)
        return float(np.linalg.norm(np.cross(d, w1)))
    return float(abs(d @ x) / nx)


def _closest_point(p1, w1, p2, w2) -> np.ndarray:
    """Midpoint of the common perpendicular of two non-parallel lines.

    Lines parallel to rounding (``1 − (w1·w2)² = 0``: the callers' angle test has let a
    nearly parallel pair through, e.g. with ``near_tol=0``) have no such perpendicular:
    the midpoint of ``p1`` and its foot on line 2 is returned (a point between the lines;
    the callers then measure the lines' distance, which decides).
    """
    c = w1 @ w2
    if 1.0 - c * c <= 0.0:
        return 0.5 * (p1 + p2 + ((p1 - p2) @ w2) * w2)
    return 0.5 * (_closest_point_on_first(p1, w1, p2, w2)
                  + _closest_point_on_first(p2, w2, p1, w1))


def _closest_point_on_first(p1, w1, p2, w2) -> np.ndarray:
    """The point of line 1 closest to line 2 (lines not parallel)."""
    d = p2 - p1
    c = w1 @ w2
    t1 = (d @ w1 - c * (d @ w2)) / (1.0 - c * c)
    return p1 + t1 * w1


def _point_line_distance(x, p, w) -> float:
    return float(np.linalg.norm(np.cross(x - p, w)))


def _fail(robot: Robot, why: str) -> NoClosedFormError:
    types = "".join(robot.joint_types)
    return NoClosedFormError(
        f"no closed-form inverse kinematics for robot {robot.name!r} ({robot.n} joints, "
        f"{types}): {why}. Closed forms are known here for: "
        + "; ".join(CLASSES.values())
        + f". For this robot, {NUMERICAL_HINT}."
    )


def analyse(robot: Robot, angle_tol: float = ANGLE_TOL,
            length_tol: float = LENGTH_TOL) -> Structure:
    """Recognise the robot's closed-form class from its joint lines.

    Args:
        robot: the robot.
        angle_tol: two axes are parallel when the sine of their angle is below this.
        length_tol: lines meet when closer than this times the robot's size [m/m].

    Returns:
        the :class:`Structure` with the class-specific data the solvers need.

    Raises:
        NoClosedFormError: the structure is none of :data:`CLASSES`; the message says
            which test failed and points to the numerical methods.
    """
    W, P, M = joint_lines(robot)
    n = robot.n
    rev = robot.revolute
    scale = max(1.0, float(np.max(np.linalg.norm(np.vstack([P, M[:3, 3]]) - P[0], axis=1))))
    ltol = length_tol * scale
    atol = angle_tol

    def para(i: int, j: int) -> bool:
        return _sin_angle(W[i], W[j]) < atol

    # ---------------------------------------------------------------- parallel family
    if all(para(0, j) for j in range(1, n)):
        return _parallel_family(robot, W, P, M, rev, scale, ltol, atol)
    if n == 6:
        return _six_dof(robot, W, P, M, rev, scale, ltol, atol)
    if n > 6:
        raise _fail(robot, f"it has {n} joints, more than the 6 a pose needs: it is redundant "
                           "and has infinitely many solutions per target")
    raise _fail(robot, f"its {n} joints are not all parallel and it is not a 6-joint arm")


def _parallel_family(robot, W, P, M, rev, scale, ltol, atol) -> Structure:
    n = robot.n
    ir = [i for i in range(n) if rev[i]]
    ip = [i for i in range(n) if not rev[i]]
    nr, np_ = len(ir), len(ip)
    if np_ > 1:
        raise _fail(robot, f"{np_} prismatic joints along one direction are redundant")
    if nr not in (2, 3):
        raise _fail(robot, f"all its axes are parallel but it has {nr} revolute joint(s); "
                           "closed forms need two or three (more are redundant)")
    w = W[ir[0]]
    if _point_line_distance(P[ir[1]], P[ir[0]], w) < ltol:
        raise _fail(robot, f"the axes of joints {ir[0] + 1} and {ir[1] + 1} coincide")
    last = P[ir[2]] if nr == 3 else M[:3, 3]
    if _point_line_distance(last, P[ir[1]], w) < ltol:
        what = f"the axis of joint {ir[2] + 1}" if nr == 3 else "the tool point"
        raise _fail(robot, f"{what} lies on the axis of joint {ir[1] + 1}")
    kind = {(2, 0): "planar_2r", (3, 0): "planar_3r", (3, 1): "scara", (2, 1): "scara_rrp"}[
        (nr, np_)]
    e1 = perpendicular(w)
    aux = np.array([w, e1])
    order = np.array(ir + [ip[0] if ip else -1], dtype=np.int64)
    planar_z = abs(abs(w[2]) - 1.0) < atol
    return Structure(kind, W, P, M, rev, aux, order, planar_z, scale)


def _wrist_arm(W, P, M, rev, scale, ltol, types, wrist, reasons,
               atol=ANGLE_TOL) -> Structure | None:
    """The arm class in front of a spherical wrist, or None (a reason is appended)."""
    v = perpendicular(W[5])
    none = np.zeros(0, np.int64)
    if types[:3] not in ("RRR", "RRP"):
        reasons.append(f"the arm joints are {types[:3]}; closed forms need RRR or RRP")
        return None
    p12 = _sin_angle(W[0], W[1]) < atol
    if types[:3] == "RRP":  # the wrist centre slides on the line (wrist, W[2])
        for k in (0, 1):
            if _sin_angle(W[k], W[2]) < atol and \
                    _point_line_distance(wrist, P[k], W[k]) < ltol:
                reasons.append(f"the wrist centre slides along axis {k + 1}, which then "
                               "cannot move it")
                return None
    if types[:3] == "RRR":
        if _sin_angle(W[0], W[2]) < atol and _point_line_distance(P[2], P[0], W[0]) < ltol:
            reasons.append("axes 1 and 3 coincide")
            return None
        if _point_line_distance(wrist, P[2], W[2]) < ltol:
            reasons.append("the wrist centre lies on axis 3")
            return None
        if _sin_angle(W[1], W[2]) < atol:  # Puma class, or degenerate
            if p12:
                reasons.append("axes 1, 2, 3 are all parallel: the wrist centre cannot leave "
                               "a plane")
            elif _point_line_distance(P[2], P[1], W[1]) < ltol:
                reasons.append("axes 2 and 3 coincide")
            else:
                aux = np.array([wrist, W[1], perpendicular(W[1]), v])
                return Structure("puma", W, P, M, rev, aux, none, False, scale)
            return None
    d12 = _line_distance(P[0], W[0], P[1], W[1], atol)
    if p12 and d12 < ltol:
        reasons.append("axes 1 and 2 coincide")
        return None
    if p12 and types[:3] == "RRP" and abs(W[1] @ W[2]) < atol:
        reasons.append("the arm is R R P with parallel axes 1 and 2 and a slide perpendicular "
                       "to them: the wrist centre cannot leave a plane")
        return None
    if d12 < ltol:
        o = _closest_point(P[0], W[0], P[1], W[1])
        if types[:3] == "RRP":
            return Structure("stanford", W, P, M, rev, np.array([wrist, o, v]), none, False,
                             scale)
        if _point_line_distance(o, P[2], W[2]) < ltol:
            reasons.append("axis 3 passes through the intersection of axes 1 and 2")
            return None
        return Structure("pieper_intersecting", W, P, M, rev, np.array([wrist, o, v]), none,
                         False, scale)
    if p12:  # parallel axes 1, 2: any common perpendicular
        r1 = P[0]
        r2 = P[1] + ((P[0] - P[1]) @ W[1]) * W[1]
    else:
        r1 = _closest_point_on_first(P[0], W[0], P[1], W[1])
        r2 = _closest_point_on_first(P[1], W[1], P[0], W[0])
    nvec = (r2 - r1) / np.linalg.norm(r2 - r1)
    aux = np.array([wrist, r1, r2, nvec, np.cross(W[1], nvec), v])
    kind = "stanford_general" if types[:3] == "RRP" else "pieper_general"
    return Structure(kind, W, P, M, rev, aux, none, False, scale)


def reversed_lines(W: np.ndarray, P: np.ndarray, M: np.ndarray) -> tuple:
    """The joint lines ``(W', P', M')`` of the reversed chain of ``(W, P, M)``.

    ``T⁻¹ = M⁻¹·e_n⁻¹···e_1⁻¹`` (PoE, ``e_i = exp([S_i] q_i)``) is the chain whose joint j
    is joint n + 1 − j about the line ``(−R_Mᵀ w, M⁻¹ p)``, with the same angle, and
    whose tool pose at q = 0 is ``M⁻¹``: ``fk'(q[::-1]) = fk(q)⁻¹``. W, P (n, 3), M (4, 4).
    """
    Minv = np.linalg.inv(M)
    Wr = np.ascontiguousarray(-(W[::-1] @ M[:3, :3]))
    Pr = np.ascontiguousarray(P[::-1] @ Minv[:3, :3].T + Minv[:3, 3])
    return Wr, Pr, Minv


def _six_dof(robot, W, P, M, rev, scale, ltol, atol) -> Structure:
    """The closed-form class of a 6-joint arm, found forward or on its reversed chain.

    A reversed arm (three intersecting axes at the base, or parallel axes 3, 4, 5 with
    intersecting axes 1, 2) is solved in closed form on ``T⁻¹`` (:func:`reversed_lines`).
    """
    types = "".join(robot.joint_types)
    reasons: list[str] = []
    found = _six_dof_lines(W, P, M, rev, types, scale, ltol, atol, reasons)
    if found is not None:
        return found
    Wr, Pr, Mr = reversed_lines(W, P, M)
    found = _six_dof_lines(Wr, Pr, Mr, rev, types[::-1], scale, ltol, atol, [])
    if found is not None:
        return replace(found, reversed=True, order=np.ones(1, dtype=np.int64))
    raise _fail(robot, "; ".join(reasons) + "; nor does the reversed chain (joints 6 to 1)")


def _six_dof_lines(W, P, M, rev, types, scale, ltol, atol, reasons) -> Structure | None:
    """The class of the 6-joint chain of lines W, P, M (joint kinds ``types``), or None.

    None when no class fits; the reasons are appended to ``reasons``.
    """
    # ------------------------------------------------ spherical wrist (axes 4, 5, 6)
    wrist = None
    if types[3:] != "RRR":
        reasons.append("joints 4-6 are not all revolute, so there is no spherical wrist")
    elif _sin_angle(W[3], W[4]) < atol or _sin_angle(W[4], W[5]) < atol:
        reasons.append("wrist axes 4/5 or 5/6 are parallel, so they do not form a spherical wrist")
    else:
        d45 = _line_distance(P[3], W[3], P[4], W[4], atol)
        c = _closest_point(P[3], W[3], P[4], W[4])
        d6 = _point_line_distance(c, P[5], W[5])
        if d45 < ltol and d6 < ltol:
            wrist = c
        else:
            reasons.append(f"axes 4, 5, 6 do not meet in one point (axes 4-5 {d45:.3g} m "
                           f"apart, axis 6 {d6:.3g} m from their meeting point)")
    if wrist is not None:
        found = _wrist_arm(W, P, M, rev, scale, ltol, types, wrist, reasons, atol)
        if found is not None:
            return found
    # ------------------------------------------------ three parallel axes (2, 3, 4)
    if types == "RRRRRR":
        if _sin_angle(W[1], W[2]) < atol and _sin_angle(W[1], W[3]) < atol:
            w = W[1]
            d56 = _line_distance(P[4], W[4], P[5], W[5], atol)
            if _sin_angle(W[0], w) < atol:
                reasons.append("axis 1 is parallel to the parallel axes 2, 3, 4")
            elif _sin_angle(W[4], w) < atol:
                reasons.append("axis 5 is parallel to the parallel axes 2, 3, 4")
            elif _sin_angle(W[4], W[5]) < atol or d56 >= ltol:
                reasons.append(f"axes 2, 3, 4 are parallel but axes 5 and 6 do not intersect "
                               f"({d56:.3g} m apart)")
            elif _point_line_distance(P[2], P[1], w) < ltol or \
                    _point_line_distance(P[3], P[2], w) < ltol:
                reasons.append("two of the parallel axes 2, 3, 4 coincide")
            else:
                p56 = _closest_point(P[4], W[4], P[5], W[5])
                aux = np.array([p56, w, perpendicular(w)])
                return Structure("ur", W, P, M, rev, aux, np.zeros(0, np.int64), False, scale)
        else:
            reasons.append("axes 2, 3, 4 are not parallel")
    return None


#: Arm codes of the 3R arm in front of axis 4 (as ``spherical_wrist.arm_positions``).
ARM_CODES = {"puma": 0, "pieper_intersecting": 1, "pieper_general": 2}


#: Largest sine of the angle between two of axes 1, 2, 3 [-] below which the general
#: search's 3R arm counts as nearly planar (:func:`planar_score` below 0.5). Measured on
#: two tables whose axis 1 is tilted by s from parallel axes 2, 3 (DH α1 = s; 8 random
#: poses each, 30-42 solutions found by Newton's method from 200 random starts): the
#: search on grid 24 of the forward chain found 6-20 of 40 at s = 1e-3..1e-2, 36 of 42 at
#: 0.02, 41 of 42 at 0.05 and all at 0.1 and beyond.
PLANAR_SPREAD = 0.1


def quartic_score(kind: str, aux: np.ndarray, scale: float) -> float:
    """``min(1, 10·a1/size)`` for Pieper's quartic (``pieper_general``), else 1.

    The quartic of the 3R arm of joints 1-3 divides by the common normal a1 of axes 1
    and 2 (``aux[1]``, ``aux[2]`` its feet, from :func:`_wrist_arm`; ``scale`` the
    robot's size [m]). Below 0.5 it is badly conditioned.
    """
    if kind != "pieper_general":
        return 1.0
    return min(1.0, 10.0 * float(np.linalg.norm(aux[2] - aux[1])) / scale)


def planar_score(W: np.ndarray) -> float:
    """``min(1, s / (2·PLANAR_SPREAD))``, ``s = max_{i<j≤3} |w_i × w_j|`` of W (6, 3).

    With axes 1, 2, 3 within s of parallel, joints 1-3 move the searched point c only
    inside a slab about s·reach thick (a plane at s = 0). The (q5, q6) nodes whose target
    ``G·c`` lies inside it form a band about s rad wide, which a grid of 24 nodes
    (0.26 rad cells) misses, and the search finds nothing: below 0.5
    (s < :data:`PLANAR_SPREAD`) the chain is unfit for the search.
    """
    s = max(float(np.linalg.norm(np.cross(W[i], W[j]))) for i, j in ((0, 1), (0, 2), (1, 2)))
    return min(1.0, s / (2.0 * PLANAR_SPREAD))


def _eliminated_end(found: list[tuple]) -> tuple:
    """The entry of ``found`` whose splits the elimination tries first.

    ``found``: an entry ``(planar_score, quartic_score, reversed, ...)`` per end whose
    joints 1-3 can place a point, forward first. The forward one, unless its
    :func:`quartic_score` is below 0.5 and the reversed one's is not.
    """
    if len(found) == 2 and found[0][1] < 0.5 <= found[1][1]:
        return found[1]
    return found[0]


def _searched_end(found: list[tuple]) -> tuple:
    """The entry of ``found`` (as for :func:`_eliminated_end`) whose chain is searched.

    When exactly one end is nearly planar (:func:`planar_score` below 0.5: the search
    there finds nothing), the other; else as :func:`_eliminated_end`. The planar test
    comes first, and the quartic test keeps its threshold: a small common normal a1 only
    degrades the quartic (a Puma 560 tilted by 0.01 rad, a1 at most 1e-3 m at both ends:
    the forward search finds its 8 solutions, the reversed one 5; test_raghavan_roth).
    """
    if len(found) == 2 and (found[0][0] < 0.5) != (found[1][0] < 0.5):
        return found[1] if found[0][0] < 0.5 else found[0]
    return _eliminated_end(found)


def general_structure(robot: Robot) -> Structure:
    """The data of the general 6R search (:mod:`serialkin.ik.analytic.general`).

    The 3R arm of joints 1-3 must place a point ``c`` of axis 4 in closed form; ``c`` is
    taken on axis 4 as far from axis 3 as the candidates ``P4 + t·w4`` (t = 0, ±size/2)
    allow, and the arm is classified like the arm of a spherical-wrist robot. When joints
    1-3 cannot (e.g. axes 1, 2, 3 parallel), the chain is reversed:
    ``T⁻¹ = M⁻¹·e6⁻¹···e1⁻¹`` is a chain whose joint j is joint 7 − j about the line
    ``(−R_Mᵀ w, M⁻¹ p)`` with tool pose ``M⁻¹``, and joints 6-4 place a point of axis 3.
    When both ends can, the reversed chain is searched when only the forward one has
    axes 1, 2, 3 within :data:`PLANAR_SPREAD` of parallel (:func:`planar_score`), or,
    neither or both being so, when it is clearly better conditioned
    (:func:`quartic_score` below 0.5 forward, at least 0.5 reversed). ``order`` holds the
    arm code (:data:`ARM_CODES`), 1 when the searched chain is reversed, and 1 when the
    elimination starts on the reversed chain's splits; ``aux`` ends with a unit vector
    ⟂ w4 (of the chain searched); W, P, M are that chain's.

    The elimination keeps the order of its splits from the quartic score alone
    (:func:`quartic_score`, the rule before nearly planar ends were scored): on an arm
    whose axes 1, 2, 3 are 3e-6 to 1e-5 rad from parallel (DH α1, 4 poses) the first
    forward split is nearly singular and declines (the search answers), while the first
    reversed split is well conditioned yet lost roots on one pose (7 of 8 rows, or 6
    without the generating q); on an arm 3e-3 rad from parallel (4 poses) the forward
    split solves and the reversed one declines (a search, 5 ms instead of 0.1).

    Raises:
        NoClosedFormError: not a 6R arm, or neither end's three joints can place a point
            in closed form (e.g. coaxial joints: infinitely many solutions).
    """
    W, P, M = joint_lines(robot)
    rev = robot.revolute
    types = "".join(robot.joint_types)
    if robot.n != 6 or types != "RRRRRR":
        raise _fail(robot, f"the general solver needs six revolute joints, got {types}")
    scale = max(1.0, float(np.max(np.linalg.norm(np.vstack([P, M[:3, 3]]) - P[0], axis=1))))
    ltol = 1e-6 * scale
    for i in range(5):  # coaxial neighbours turn as one joint: a continuum of solutions
        if _sin_angle(W[i], W[i + 1]) < 1e-9 and \
                _point_line_distance(P[i + 1], P[i], W[i]) < 1e-9 * scale:
            raise _fail(robot, f"axes {i + 1} and {i + 2} coincide: the arm is redundant "
                               "(infinitely many solutions)")
    reasons: list[str] = []
    Wr, Pr, Minv = reversed_lines(W, P, M)
    found = []
    for reversed_, (Wc, Pc, Mc) in ((0, (W, P, M)), (1, (Wr, Pr, Minv))):
        options = sorted(((_point_line_distance(Pc[3] + t * Wc[3], Pc[2], Wc[2]), t)
                          for t in (0.0, 0.5 * scale, -0.5 * scale)), reverse=True)
        for _, t in options:
            c = Pc[3] + t * Wc[3]
            arm = _wrist_arm(Wc, Pc, Mc, rev, scale, ltol, types, c, reasons, 1e-6)
            if arm is not None:
                aux = np.vstack([arm.aux[:-1], perpendicular(Wc[3])])
                found.append((planar_score(Wc), quartic_score(arm.kind, arm.aux, scale),
                              reversed_, ARM_CODES[arm.kind], (Wc, Pc, Mc, aux)))
                break
    if found:  # the reversed chain only when clearly better conditioned
        best = _searched_end(found)
        Wc, Pc, Mc, aux = best[4]
        order = np.array([best[3], best[2], _eliminated_end(found)[2]], dtype=np.int64)
        return Structure("general_6r", np.ascontiguousarray(Wc), np.ascontiguousarray(Pc),
                         np.ascontiguousarray(Mc), rev, aux, order, False, scale)
    raise _fail(robot, "no closed form for the 3R arm of joints 1-3 placing a point of axis "
                       "4, nor for joints 6-4 placing a point of axis 3: "
                       + "; ".join(dict.fromkeys(reasons)))
