"""Closed-form inverse kinematics, all solutions (chapter section 4.1, serialkin.ik.analytic).

Round trips FK(q) -> ik_all -> {q_k}: the set contains q (up to 2π) and every q_k
reproduces the target; on the built-in models, on the same mechanisms in modified DH, as
general joints (URDF) and on users' own robots of each class (scaled lengths, offsets,
base and tool transforms, generated with a seed).
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import serialkin as sk
from serialkin import Robot, models
from serialkin.errors import InputError, InputTypeError, NoClosedFormError
from serialkin.ik.analytic import CLASSES, AllSolutions, classify, ik_all
from serialkin.model.dh import DHLink, standard_to_modified
from serialkin.spatial import make_transform, rotx, roty, rotz
from tests.ik._arms import WRIST_ARM, wrist_arm_rows

H = math.pi / 2


# ----------------------------------------------------------------------------- helpers
def _random_transform(rng: np.random.Generator, size: float = 0.3) -> np.ndarray:
    R = rotz(rng.uniform(-np.pi, np.pi)) @ roty(rng.uniform(-np.pi, np.pi)) \
        @ rotx(rng.uniform(-np.pi, np.pi))
    return make_transform(R, rng.uniform(-size, size, 3))


def _joint_distance(robot: Robot, S: np.ndarray, q: np.ndarray) -> np.ndarray:
    """Max joint difference of each row of S to q, revolute joints modulo 2π."""
    d = S - q
    rev = np.array([t == "R" for t in robot.joint_types])
    d[:, rev] = (d[:, rev] + np.pi) % (2 * np.pi) - np.pi
    return np.abs(d).max(axis=1)


def _check_round_trips(robot: Robot, count: int, seed: int, *, expect_all: bool = True,
                       tol: float = 1e-9) -> list[int]:
    """FK(q) -> ik_all contains q and every solution reproduces the pose; returns the counts."""
    rng = np.random.default_rng(seed)
    counts = []
    for _ in range(count):
        q = robot.random_q(seed=rng)
        T = robot.fk(q)
        S = ik_all(robot, T)
        assert S.ndim == 2 and S.shape[1] == robot.n
        counts.append(len(S))
        if expect_all:
            assert len(S) and _joint_distance(robot, S, q).min() < 1e-6, (q, S)
        if len(S):
            err = np.abs(robot.fk(S) - T).max(axis=(1, 2))
            assert err.max() < tol, err
            assert np.all(robot.within_limits(S))
    return counts


def _scara_rows(l1=0.35, l2=0.30, d1=0.4, d2=0.1, theta=(0.0, 0.0, 0.0, 0.0)):
    return [
        DHLink(a=l1, alpha=0.0, d=d1, theta=theta[0], qlim=(-2.6, 2.6)),
        DHLink(a=l2, alpha=0.0, d=0.0, theta=theta[1], qlim=(-2.5, 2.5)),
        DHLink(a=0.0, alpha=math.pi, d=d2, theta=theta[2], type="P", qlim=(-0.3, 0.0)),
        DHLink(a=0.0, alpha=0.0, d=0.0, theta=theta[3], qlim=(-2 * np.pi, 2 * np.pi)),
    ]


def _pieper_rows():
    """A 6R arm with intersecting axes 1, 2 and a spherical wrist (not a Puma: 2 ∦ 3)."""
    lim = (-np.pi, np.pi)
    return [
        DHLink(a=0.0, alpha=-H, d=0.4, qlim=lim),
        DHLink(a=0.0, alpha=H, d=0.1, qlim=lim),
        DHLink(a=0.3, alpha=H, d=0.2, qlim=lim),
        DHLink(a=0.0, alpha=-H, d=0.35, qlim=lim),
        DHLink(a=0.0, alpha=H, d=0.0, qlim=lim),
        DHLink(a=0.0, alpha=0.0, d=0.1, qlim=lim),
    ]


def _skew_rows():
    """A 6R arm with a spherical wrist and skew axes 1-2 and 2-3 (Pieper's general case)."""
    lim = (-np.pi, np.pi)
    return [
        DHLink(a=0.15, alpha=math.pi / 3, d=0.4, qlim=lim),
        DHLink(a=0.5, alpha=math.pi / 4, d=0.1, qlim=lim),
        DHLink(a=0.1, alpha=H, d=0.2, qlim=lim),
        DHLink(a=0.0, alpha=-H, d=0.4, qlim=lim),
        DHLink(a=0.0, alpha=H, d=0.0, qlim=lim),
        DHLink(a=0.0, alpha=0.0, d=0.1, qlim=lim),
    ]


def _parallel12_rows():
    """A 6R arm with a spherical wrist, parallel axes 1-2 and skew axes 2-3."""
    rows = _skew_rows()
    rows[0] = DHLink(a=0.3, alpha=0.0, d=0.4, qlim=(-np.pi, np.pi))
    return rows


def _stanford_offset_rows():
    """The Stanford arm with a shoulder offset a1 = 0.1 m (axes 1 and 2 no longer meet)."""
    rows = list(models.stanford().dh)
    r = rows[0]
    rows[0] = DHLink(a=0.1, alpha=r.alpha, d=r.d, theta=r.theta, type=r.type, qlim=r.qlim)
    return rows


def _variant(robot: Robot, rng: np.random.Generator, keep_zero: tuple[str, ...] = ()) -> Robot:
    """A user's own robot of the same class: scaled a/d, joint offsets, base and tool."""
    rows = []
    for i, r in enumerate(robot.dh):
        a = 0.0 if f"a{i + 1}" in keep_zero else r.a * rng.uniform(0.5, 2.0) \
            + rng.uniform(-0.1, 0.1)
        d = 0.0 if f"d{i + 1}" in keep_zero else r.d * rng.uniform(0.5, 2.0) \
            + rng.uniform(-0.1, 0.1)
        theta = r.theta + (rng.uniform(-np.pi, np.pi) if r.type == "R" else 0.0)
        rows.append(DHLink(a=a, alpha=r.alpha, d=d, theta=theta, type=r.type, qlim=r.qlim,
                           name=r.name))
    return Robot.from_dh(rows, robot.convention, base=_random_transform(rng),
                         tool=_random_transform(rng, 0.1), name="users_own")


ROBOTS = {
    "two_link": (models.two_link, "planar_2r"),
    "three_link": (models.three_link, "planar_3r"),
    "scara": (models.scara, "scara"),
    "puma560": (models.puma560, "puma"),
    "stanford": (models.stanford, "stanford"),
    "ur5": (models.ur5, "ur"),
    "pieper": (lambda: Robot.from_dh(_pieper_rows(), name="pieper"), "pieper_intersecting"),
    "skew": (lambda: Robot.from_dh(_skew_rows(), name="skew"), "pieper_general"),
    "par12": (lambda: Robot.from_dh(_parallel12_rows(), name="par12"), "pieper_general"),
    "stanford_offset": (lambda: Robot.from_dh(_stanford_offset_rows(), name="stanford_offset"),
                        "stanford_general"),
}


# ----------------------------------------------------------------------------- round trips
@pytest.mark.parametrize("name", list(ROBOTS))
def test_round_trip_builtin(name):
    """For random q inside the limits, ik_all(FK(q)) contains q and every row reproduces FK(q)."""
    build, kind = ROBOTS[name]
    robot = build()
    assert classify(robot) == kind
    counts = _check_round_trips(robot, 150, seed=1)
    assert max(counts) >= (1 if kind == "planar_2r" else 2)  # 2R + pose: one orientation


@pytest.mark.parametrize("name", ["scara", "puma560", "stanford", "ur5", "pieper", "skew"])
def test_round_trip_modified_dh(name):
    """The same mechanism written in modified (Craig) DH is recognised and solved identically."""
    build, kind = ROBOTS[name]
    std = build()
    rows, base, tool = standard_to_modified(std.dh, std.base, std.tool)
    mod = Robot.from_dh(rows, "modified", base=base, tool=tool, name="modified")
    assert classify(mod) == kind
    _check_round_trips(mod, 60, seed=2)
    T = std.fk(std.random_q(seed=3))
    np.testing.assert_allclose(ik_all(mod, T), ik_all(std, T), atol=1e-9)


@pytest.mark.parametrize("name", ["puma560", "ur5", "stanford"])
def test_round_trip_general_joints_from_urdf(name):
    """Recognition works on general joints (URDF round trip), not only on DH tables."""
    build, kind = ROBOTS[name]
    std = build()
    urdf = Robot.from_urdf(std.to_urdf())
    assert urdf.dh is None or urdf.convention is not None
    general = Robot.from_joints(urdf.joints, base=urdf.base, tool=urdf.tool, name="g")
    assert classify(general) == kind
    T = std.fk(std.random_q(seed=4))
    np.testing.assert_allclose(ik_all(general, T), ik_all(std, T), atol=1e-8)


@pytest.mark.parametrize("relative, tip", [
    ("ur_description/urdf/ur5_robot.urdf", "tool0"),
    ("ur_description/urdf/ur10_robot.urdf", "ee_link"),
    ("ur_description/urdf/ur3_robot.urdf", "tool0"),
    ("z1_description/urdf/z1.urdf", "link06"),
])
def test_published_urdf_arms(relative, tip):
    """Published URDFs (example-robot-data: UR3/5/10, Unitree Z1) are recognised and solved."""
    from tests.erd import urdf

    path = urdf(relative)
    if path is None:
        pytest.skip("example-robot-data is not installed (pip install -e '.[bench]')")
    robot = Robot.from_urdf(str(path), tip_link=tip)
    assert classify(robot) == "ur"
    _check_round_trips(robot, 30, seed=18)


VARIANT_ZEROS = {
    # DH entries that must stay 0 for the class; every other a, d is scaled and shifted
    "two_link": (),
    "three_link": (),
    "scara": (),
    "puma560": ("a4", "a5", "d5"),          # spherical wrist
    "ur5": ("a5",),                         # axes 5 and 6 intersect
    "stanford": ("a1", "a4", "a5", "d5"),   # axes 1, 2 intersect; spherical wrist
    "pieper": ("a1", "a4", "a5", "d5"),
    "skew": ("a4", "a5", "d5"),
    "par12": ("a4", "a5", "d5"),
    "stanford_offset": ("a4", "a5", "d5"),
}


@pytest.mark.parametrize("name", list(VARIANT_ZEROS))
@pytest.mark.parametrize("seed", [11, 12, 13])
def test_round_trip_users_own_robot(name, seed):
    """A user's robot of the same class (other lengths, offsets, base, tool) is fully solved."""
    build, kind = ROBOTS[name]
    rng = np.random.default_rng(seed)
    robot = _variant(build(), rng, VARIANT_ZEROS[name])
    assert classify(robot) == kind
    _check_round_trips(robot, 40, seed=seed)


@settings(max_examples=25, deadline=None)
@given(l1=st.floats(0.1, 2.0), l2=st.floats(0.1, 2.0), d1=st.floats(-1.0, 1.0),
       d2=st.floats(-0.5, 0.5), seed=st.integers(0, 2**31 - 1))
def test_scara_any_dimensions(l1, l2, d1, d2, seed):
    """Any SCARA of Table 1's structure is recognised and its round trips close."""
    robot = Robot.from_dh(_scara_rows(l1, l2, d1, d2), base=_random_transform(
        np.random.default_rng(seed)), name="my_scara")
    assert classify(robot) == "scara"
    _check_round_trips(robot, 5, seed=seed)


@settings(max_examples=25, deadline=None)
@given(a2=st.floats(0.1, 1.0), a3=st.floats(-0.2, 0.2), d3=st.floats(-0.3, 0.3),
       d4=st.floats(0.1, 1.0), a1=st.floats(-0.3, 0.3), seed=st.integers(0, 2**31 - 1))
def test_puma_class_any_dimensions(a2, a3, d3, d4, a1, seed):
    """Puma-class arms with any shoulder/elbow offsets (a1 ≠ 0: KUKA-like) close round trips."""
    rows = [DHLink(a=a1, alpha=H, d=0.5), DHLink(a=a2, alpha=0.0, d=0.0),
            DHLink(a=a3, alpha=-H, d=d3), DHLink(a=0.0, alpha=H, d=d4),
            DHLink(a=0.0, alpha=-H, d=0.0), DHLink(a=0.0, alpha=0.0, d=0.08)]
    robot = Robot.from_dh(rows, tool=_random_transform(np.random.default_rng(seed), 0.1))
    assert classify(robot) == "puma"
    counts = _check_round_trips(robot, 5, seed=seed)
    assert max(counts) <= 8


@settings(max_examples=25, deadline=None)
@given(d1=st.floats(0.05, 0.5), a2=st.floats(-0.8, -0.1), a3=st.floats(-0.8, -0.1),
       d4=st.floats(-0.3, 0.3), d5=st.floats(0.02, 0.3), d6=st.floats(0.0, 0.3),
       a1=st.floats(-0.2, 0.2), seed=st.integers(0, 2**31 - 1))
def test_ur_class_any_dimensions(d1, a2, a3, d4, d5, d6, a1, seed):
    """UR-class arms of any dimensions (and a1 ≠ 0), base and tool close all round trips."""
    rng = np.random.default_rng(seed)
    rows = [DHLink(a=a1, alpha=H, d=d1), DHLink(a=a2, alpha=0.0, d=0.0),
            DHLink(a=a3, alpha=0.0, d=0.0), DHLink(a=0.0, alpha=H, d=d4),
            DHLink(a=0.0, alpha=-H, d=d5), DHLink(a=0.0, alpha=0.0, d=d6)]
    robot = Robot.from_dh(rows, base=_random_transform(rng), tool=_random_transform(rng, 0.1))
    assert classify(robot) == "ur"
    counts = _check_round_trips(robot, 5, seed=seed)
    assert max(counts) <= 8


def test_wrist_singular_representative():
    """At an aligned wrist (q5 = 0) only q4 + q6 is fixed: the representative has q4 = 0."""
    robot = models.puma560()
    q = np.array([0.3, 0.5, -0.7, 0.2, 0.0, 0.4])
    S = ik_all(robot, robot.fk(q))
    on_branch = S[np.abs(S[:, 4]) < 1e-9]
    assert len(on_branch) >= 1
    np.testing.assert_allclose(on_branch[:, 3], 0.0, atol=1e-12)
    np.testing.assert_allclose(on_branch[:, 5], np.full(len(on_branch), q[3] + q[5]),
                               atol=1e-9)


@settings(max_examples=30, deadline=None)
@given(**WRIST_ARM, seed=st.integers(0, 2**31 - 1))
def test_any_arm_with_spherical_wrist(a, alpha, d, seed):
    """Any well-conditioned R R R arm followed by a spherical wrist is solved (Pieper)."""
    robot = Robot.from_dh(wrist_arm_rows(a, alpha, d),
                          base=_random_transform(np.random.default_rng(seed)))
    try:
        kind = classify(robot)
    except NoClosedFormError as exc:  # degenerate draws: the message says which test failed
        assert "parallel" in str(exc) or "axis 3" in str(exc) or "coincide" in str(exc)
        return
    assert kind in ("puma", "pieper_intersecting", "pieper_general")
    counts = _check_round_trips(robot, 5, seed=seed, tol=1e-8)
    assert max(counts) <= 8


@settings(max_examples=25, deadline=None)
@given(name=st.sampled_from(["puma560", "ur5", "stanford", "scara", "skew"]),
       seed=st.integers(0, 2**31 - 1))
def test_base_and_tool_invariance(name, seed):
    """ik_all(robot with base B and tool E, B·T·E) equals ik_all(robot, T): same joint values."""
    rng = np.random.default_rng(seed)
    robot = ROBOTS[name][0]()
    B, E = _random_transform(rng, 1.0), _random_transform(rng, 0.2)
    moved = Robot.from_dh(robot.dh, robot.convention, base=B @ robot.base,
                          tool=robot.tool @ E)
    T = robot.fk(robot.random_q(seed=rng))
    np.testing.assert_allclose(ik_all(moved, B @ T @ E), ik_all(robot, T), atol=1e-8)


@settings(max_examples=30, deadline=None)
@given(**WRIST_ARM, theta3=st.floats(-3.0, 3.0), seed=st.integers(0, 2**31 - 1))
def test_any_rrp_arm_with_spherical_wrist(a, alpha, d, theta3, seed):
    """Any well-conditioned R R P arm followed by a spherical wrist is solved (Stanford class)."""
    rows = [DHLink(a=a[0], alpha=alpha[0], d=d[0]), DHLink(a=a[1], alpha=alpha[1], d=d[1]),
            DHLink(a=a[2], alpha=alpha[2], d=d[2], theta=theta3, type="P", qlim=(-1.0, 1.0)),
            DHLink(a=0.0, alpha=-H, d=d[3]), DHLink(a=0.0, alpha=H, d=0.0),
            DHLink(a=0.0, alpha=0.0, d=0.1)]
    robot = Robot.from_dh(rows, base=_random_transform(np.random.default_rng(seed)))
    try:
        kind = classify(robot)
    except NoClosedFormError as exc:  # degenerate draws: the message says which test failed
        assert "coincide" in str(exc) or "cannot" in str(exc)
        return
    assert kind in ("stanford", "stanford_general")
    counts = _check_round_trips(robot, 5, seed=seed, tol=1e-8)
    assert max(counts) <= 8


def test_eight_solutions_without_limits():
    """Unlimited Puma 560 and Pieper arm: 8 solutions per pose; UR5: 8 for most, never more."""
    for robot in (models.puma560(), Robot.from_dh(_pieper_rows())):
        free = robot.with_limits(np.tile([-np.inf, np.inf], (6, 1)))
        assert _check_round_trips(free, 20, seed=5) == [8] * 20
    free = models.ur5().with_limits(np.tile([-np.inf, np.inf], (6, 1)))
    counts = _check_round_trips(free, 40, seed=5)
    assert max(counts) == 8 and counts.count(8) >= 20, counts


@pytest.mark.parametrize("name", ["ur5", "puma560", "pieper", "skew", "par12",
                                  "stanford_offset"])
def test_solution_set_is_complete(name):
    """Least squares from 30 random starts finds no solution missing from ik_all's set."""
    optimize = pytest.importorskip("scipy.optimize")
    robot = ROBOTS[name][0]().with_limits(np.tile([-np.inf, np.inf], (6, 1)))
    rng = np.random.default_rng(14)

    def residual(q, T):
        F = robot.fk(q)
        return np.concatenate([F[:3, 3] - T[:3, 3], (F[:3, :3] - T[:3, :3]).ravel()])

    for _ in range(3):
        T = robot.fk(robot.random_q(seed=rng))
        S = ik_all(robot, T)
        for _ in range(30):
            sol = optimize.least_squares(residual, rng.uniform(-np.pi, np.pi, 6), args=(T,),
                                         xtol=1e-15, ftol=1e-15, gtol=1e-15)
            if np.abs(sol.fun).max() < 1e-9:
                assert _joint_distance(robot, S, sol.x).min() < 1e-5


def test_stanford_negative_stroke_gives_eight():
    """Without stroke limits the Stanford arm has 8 solutions (4 with the slide reversed)."""
    free = models.stanford().with_limits(np.tile([-np.inf, np.inf], (6, 1)))
    counts = _check_round_trips(free, 20, seed=6)
    assert counts.count(8) >= 15, counts


@settings(max_examples=30, deadline=None)
@given(seed=st.integers(0, 2**32 - 1), delta=st.floats(0.0, 2.0))
def test_sp3_slide_strokes_reach_the_distance(seed, delta):
    """sp3_slide's strokes d give |h + d·w| = δ, and none exist only when δ < dist(line, 0)."""
    from serialkin.ik.analytic.subproblems import sp3_slide

    rng = np.random.default_rng(seed)
    w = rng.normal(size=3)
    w /= np.linalg.norm(w)
    h = rng.uniform(-1.0, 1.0, 3)
    out = np.empty(2)
    count = sp3_slide(tuple(w), tuple(h), delta * delta, out)  # vectors as tuples, as always
    gap = np.linalg.norm(h - (w @ h) * w)  # distance from the origin to the line h + d·w
    if count == 0:
        assert delta < gap
    else:
        assert delta >= gap - 1e-6
        for d in out[:count]:
            assert abs(np.linalg.norm(h + d * w) - delta) < 1e-9
        assert count == 1 or out[0] > out[1]


def test_puma_agrees_with_robotics_toolbox_ikine_a():
    """Every solution of Robotics Toolbox's Puma 560 ikine_a (8 configurations) is in our set."""
    rtb = pytest.importorskip("roboticstoolbox")
    puma = rtb.models.DH.Puma560()
    rows = [DHLink(a=float(L.a), alpha=float(L.alpha), d=float(L.d), theta=float(L.offset))
            for L in puma.links]
    ours = Robot.from_dh(rows, base=np.asarray(puma.base.A), tool=np.asarray(puma.tool.A))
    assert classify(ours) == "puma"
    rng = np.random.default_rng(15)
    for _ in range(8):
        q = rng.uniform(-np.pi, np.pi, 6)
        T = ours.fk(q)
        np.testing.assert_allclose(np.asarray(puma.fkine(q).A), T, atol=1e-12)
        S = ik_all(ours, T)
        assert len(S) == 8
        for config in ("lun", "lud", "lfn", "lfd", "run", "rud", "rfn", "rfd"):
            sol = puma.ikine_a(T, config=config)
            if sol.success:
                assert _joint_distance(ours, S, np.asarray(sol.q, float)).min() < 1e-6


# ----------------------------------------------------------------------------- chapter
def test_two_link_matches_chapter_equations():
    """Planar 2-link: both elbow solutions equal eqs 23-27 as corrected by the ERRATA."""
    l1, l2 = 0.7, 0.45
    robot = models.two_link(l1, l2)
    rng = np.random.default_rng(7)
    for _ in range(50):
        x, y = robot.fk(robot.random_q(seed=rng))[:2, 3]
        r = math.hypot(x, y)                                         # eq 23, corrected
        alpha = math.atan2(y, x)                                     # eq 24
        th2 = math.acos((x * x + y * y - l1 * l1 - l2 * l2) / (2 * l1 * l2))  # eq 25
        beta = math.acos((l1 * l1 - l2 * l2 + r * r) / (2 * l1 * r))          # eq 26, corrected
        expected = np.array([[alpha - beta, th2], [alpha + beta, -th2]])      # eq 27 pairing
        expected = (expected + np.pi) % (2 * np.pi) - np.pi
        S = ik_all(robot, [x, y])
        assert S.shape == (2, 2)
        np.testing.assert_allclose(S[np.lexsort(S.T[::-1])],
                                   expected[np.lexsort(expected.T[::-1])], atol=1e-7)


def test_planar_targets():
    """(x, y) on the 2-link arm and (x, y, φ) on the 3-link arm: positions and heading match."""
    two, three = models.two_link(), models.three_link(1.0, 0.8, 0.3)
    S = ik_all(two, (1.2, 0.5))
    assert len(S) == 2
    np.testing.assert_allclose(two.fk(S)[:, :2, 3], [[1.2, 0.5]] * 2, atol=1e-12)
    S = ik_all(three, (1.0, 0.6, 0.4))
    assert len(S) == 2
    T = three.fk(S)
    np.testing.assert_allclose(T[:, :2, 3], [[1.0, 0.6]] * 2, atol=1e-12)
    np.testing.assert_allclose(np.arctan2(T[:, 1, 0], T[:, 0, 0]), [0.4, 0.4], atol=1e-12)
    np.testing.assert_allclose(S.sum(axis=1), [0.4, 0.4], atol=1e-12)


@pytest.mark.parametrize("flip", [False, True])
def test_planar_targets_with_base_and_tool(flip):
    """(x, y, φ) targets on a 3-link arm moved in the plane (or flipped upside down) with a tool."""
    base = make_transform(rotz(0.7) @ (rotx(np.pi) if flip else np.eye(3)), [0.3, -0.2, 0.5])
    tool = make_transform(rotz(-0.4), [0.1, 0.05, 0.0])
    robot = Robot.from_dh(models.three_link(1.0, 0.8, 0.3).dh, base=base, tool=tool)
    assert classify(robot) == "planar_3r"
    rng = np.random.default_rng(16)
    for _ in range(20):
        q = robot.random_q(seed=rng)
        T = robot.fk(q)
        phi = math.atan2(T[1, 0], T[0, 0])
        S = ik_all(robot, [T[0, 3], T[1, 3], phi])
        assert _joint_distance(robot, S, q).min() < 1e-9
        np.testing.assert_allclose(robot.fk(S), np.broadcast_to(T, (len(S), 4, 4)), atol=1e-9)


@pytest.mark.parametrize("order", ["RRRP", "PRRR", "RPRR"])
def test_scara_joint_orders(order):
    """SCARAs with the vertical slide anywhere in the chain (e.g. R R R P, P R R R) are solved."""
    rows, links = [], iter([0.4, 0.3, 0.0])
    for t in order:
        if t == "P":
            rows.append(DHLink(a=0.0, alpha=0.0, d=0.2, type="P", qlim=(-0.3, 0.3)))
        else:
            rows.append(DHLink(a=next(links), alpha=0.0, d=0.05, qlim=(-2.8, 2.8)))
    robot = Robot.from_dh(rows, tool=make_transform(p=[0.02, 0.0, -0.1]))
    assert classify(robot) == "scara"
    counts = _check_round_trips(robot, 30, seed=17)
    assert max(counts) == 2


def test_scara_position_and_heading_target():
    """The chapter's SCARA takes (x, y, z, φ): both elbow solutions reach it with heading φ."""
    robot = models.scara()
    T0 = robot.fk(np.array([0.4, -0.9, -0.12, 1.3]))
    phi = math.atan2(T0[1, 0], T0[0, 0])
    S = ik_all(robot, [*T0[:3, 3], phi])
    assert len(S) == 2
    np.testing.assert_allclose(robot.fk(S), [T0, T0], atol=1e-12)


def test_slightly_non_orthonormal_target_is_projected():
    """A pose rounded to 7 decimals (rotation off SO(3) by ~1e-7) still gives every solution."""
    robot = models.puma560()
    q = np.array([0.3, 0.5, -0.7, 0.2, 0.6, 0.4])
    T = np.round(robot.fk(q), 7)
    S = ik_all(robot, T)
    assert len(S) >= 2 and _joint_distance(robot, S, q).min() < 1e-6
    assert np.abs(robot.fk(S) - T).max() < 1e-6


def test_two_link_pose_target_filters_orientation():
    """A 4x4 pose on a 2-link arm keeps only the elbow solution with the right orientation."""
    robot = models.two_link()
    q = np.array([0.3, 1.1])
    S = ik_all(robot, robot.fk(q))
    np.testing.assert_allclose(S, [q], atol=1e-9)


def test_scara_chapter_table():
    """The chapter's SCARA (Table 1): both elbow solutions, stroke and q4 recovered."""
    robot = models.scara()
    q = np.array([0.4, -0.9, -0.12, 1.3])
    S = ik_all(robot, robot.fk(q))
    assert len(S) == 2
    assert _joint_distance(robot, S, q).min() < 1e-9
    np.testing.assert_allclose(S[:, 2], [-0.12, -0.12], atol=1e-12)


# ----------------------------------------------------------------------------- edge cases
@pytest.mark.parametrize("name", ["two_link", "scara", "puma560", "stanford", "ur5"])
def test_unreachable_target_gives_empty_array(name):
    """A target beyond the reach gives an empty (0, n) array, not an exception."""
    robot = ROBOTS[name][0]()
    T = robot.fk(robot.random_q(seed=8))
    T[:3, 3] += 50.0
    S = ik_all(robot, T)
    assert S.shape == (0, robot.n)


def test_reachable_only_outside_limits_gives_empty_array():
    """A pose reachable only with joints outside their limits gives no solution."""
    robot = models.two_link().with_limits([[-np.pi, np.pi], [0.5, 1.0]])
    T = models.two_link().fk([0.2, 2.0])
    assert ik_all(robot, T).shape == (0, 2)
    assert ik_all(robot, T[:2, 3]).shape == (0, 2)


def test_rotation_the_robot_cannot_make_gives_empty_array():
    """A SCARA pose whose tool axis is tilted is unreachable: empty, no exception."""
    robot = models.scara()
    T = robot.fk(np.array([0.4, -0.9, -0.12, 1.3])) @ make_transform(rotx(0.2))
    assert ik_all(robot, T).shape == (0, 4)


def _puma_stretched_q3() -> float:
    """q3 that aligns the Puma 560's forearm (axis 3 → wrist centre) with link 2."""
    robot = models.puma560()
    frames = robot.fk_all(np.zeros(6))
    v = np.linalg.inv(frames[2]) @ frames[4][:, 3]  # wrist centre in frame 2 at q3 = 0
    return -math.atan2(v[1], v[0])


@pytest.mark.parametrize("robot, q", [
    (models.ur5(), [0.3, -1.0, 0.7, 0.2, 0.0, 0.4]),              # wrist singular
    (models.ur5(), [0.3, -1.0, 0.0, 0.2, 0.9, 0.4]),              # elbow stretched
    (models.puma560(), [0.3, 0.5, -0.7, 0.2, 0.0, 0.4]),          # wrist singular
    (models.puma560(), [0.3, 0.5, _puma_stretched_q3(), 0.2, 0.9, 0.4]),  # elbow stretched
])
def test_singular_configurations(robot, q):
    """At singular configurations: finite solutions, q among them, all reproducing the target."""
    q = np.array(q)
    T = robot.fk(q)
    S = ik_all(robot, T)
    assert len(S) >= 1 and np.isfinite(S).all()
    assert np.abs(robot.fk(S) - T).max() < 1e-9
    if q[4] != 0.0:  # wrist not singular: q itself is found (else only q4 + q6 is fixed)
        assert _joint_distance(robot, S, q).min() < 1e-6


def test_two_link_stretched_has_one_solution():
    """At the workspace boundary (arm stretched) both elbow branches merge into one solution."""
    robot = models.two_link()
    S = ik_all(robot, (2.0, 0.0))
    np.testing.assert_allclose(S, [[0.0, 0.0]], atol=1e-12)


def test_all_turns_lists_every_equivalent():
    """all_turns adds every 2π-equivalent angle inside the limits (UR5: ±2π, so 2⁶ per solution)."""
    robot = models.ur5()
    T = robot.fk(robot.random_q(seed=9))
    base = ik_all(robot, T)
    full = ik_all(robot, T, all_turns=True)
    assert len(full) == 64 * len(base)
    assert np.all(robot.within_limits(full))
    assert np.all(_joint_distance(robot, base, full[0]).min() < 1e-9)
    assert np.abs(robot.fk(full) - T).max() < 1e-9
    free = models.two_link()  # unlimited joints: one value each, not infinitely many
    np.testing.assert_array_equal(ik_all(free, (1.2, 0.5), all_turns=True),
                                  ik_all(free, (1.2, 0.5)))


def test_deterministic_and_sorted():
    """Same input, same output; rows sorted lexicographically and unique."""
    robot = models.puma560().with_limits(np.tile([-np.pi, np.pi], (6, 1)))
    T = robot.fk(robot.random_q(seed=10))
    S1, S2 = ik_all(robot, T), robot.ik_all(T)
    np.testing.assert_array_equal(S1, S2)
    assert np.array_equal(S1, S1[np.lexsort(S1.T[::-1])])
    assert len(np.unique(np.round(S1, 9), axis=0)) == len(S1)


def test_wrapping_into_limits():
    """Angles are returned inside the limits even when those are offset by 2π (e.g. [2π, 4π])."""
    robot = models.three_link().with_limits([[2 * np.pi, 4 * np.pi], [-np.pi, np.pi],
                                             [-3 * np.pi, -np.pi]])
    q = np.array([2 * np.pi + 0.5, 0.7, -2 * np.pi - 0.3])
    S = ik_all(robot, robot.fk(q))
    assert np.all(robot.within_limits(S))
    assert np.abs(S - q).max(axis=1).min() < 1e-9


# ----------------------------------------------------------------------------- recognition
def test_recognition_ignores_the_name():
    """A Puma table named 'ur5' is a puma, a UR5 named 'my_arm' is a UR."""
    assert classify(Robot.from_dh(models.puma560().dh, name="ur5")) == "puma"
    assert classify(Robot.from_dh(models.ur5().dh, name="my_arm")) == "ur"
    assert set(CLASSES) >= {"planar_2r", "planar_3r", "scara", "puma", "stanford", "ur"}


@pytest.mark.parametrize("robot, words", [
    (models.panda(), ["redundant", "robot.ik(target, method='lm')"]),
    (models.iiwa7(), ["redundant"]),
    (models.planar(4), ["redundant", "4 revolute"]),
    (models.planar(6), ["redundant", "6 revolute"]),
])
def test_unsupported_robot_raises_with_reason(robot, words):
    """Robots without a closed form raise NoClosedFormError saying why and pointing to robot.ik."""
    with pytest.raises(NoClosedFormError) as info:
        robot.ik_all(np.eye(4))
    for w in words:
        assert w in str(info.value)
    with pytest.raises(NoClosedFormError):
        classify(robot)


def test_near_structure_is_not_recognised():
    """Axes parallel only to 1e-5 rad are not taken for a UR (the closed form would be wrong)."""
    rows = list(models.ur5().dh)
    rows[2] = DHLink(a=rows[2].a, alpha=1e-5, d=rows[2].d, qlim=rows[2].qlim)
    with pytest.raises(NoClosedFormError, match="axes 2, 3, 4 are not parallel"):
        classify(Robot.from_dh(rows))


# ----------------------------------------------------------------------------- bad input
def test_infinite_solution_targets_raise():
    """Targets with infinitely many solutions (position on 6R, (x, y) on 3R) raise NoClosedForm."""
    with pytest.raises(NoClosedFormError, match="orientation is free"):
        ik_all(models.ur5(), [0.3, 0.1, 0.4])
    with pytest.raises(NoClosedFormError, match="orientation is free"):
        ik_all(models.three_link(), [1.0, 0.5])


@pytest.mark.parametrize("target, match", [
    (np.diag([1.0, 1.0, 2.0, 1.0]), "target"),
    (np.full((4, 4), np.nan), "target"),
    (np.zeros((3, 4, 4)), "target"),
    (np.zeros(5), "must be a 4x4 pose"),
    ("pose", "target"),
])
def test_bad_target(target, match):
    """Non-rigid, NaN, misshaped or non-numeric targets (one or a batch) raise naming 'target'."""
    with pytest.raises((InputError, sk.errors.InputTypeError), match=match):
        ik_all(models.ur5(), target)


def test_bad_options():
    """Bad tol or option: InputError naming it; a non-robot: InputTypeError with a hint."""
    robot = models.ur5()
    T = robot.fk(np.zeros(6))
    with pytest.raises(InputError, match="tol"):
        ik_all(robot, T, tol=-1.0)
    with pytest.raises(InputError, match="unknown option"):
        ik_all(robot, T, q0=np.zeros(6))
    with pytest.raises(InputTypeError, match=r"Robot.*models\.get"):
        ik_all("ur5", T)


@pytest.mark.parametrize("name", ["ur5", "puma560", "stanford", "scara", "three_link",
                                  "perturbed", "general"])
def test_fast_path_equals_ordinary_path(name):
    """One C-contiguous float64 pose (fast path) gives the ordinary path's rows bit for bit."""
    rng = np.random.default_rng(5)
    if name == "perturbed":
        robot = Robot.from_dh([DHLink(a=r.a + rng.uniform(-1e-3, 1e-3),
                                      alpha=r.alpha + rng.uniform(-0.01, 0.01),
                                      d=r.d, theta=r.theta + rng.uniform(-0.01, 0.01))
                               for r in models.ur5().dh], "standard")
    elif name == "general":
        robot = Robot.from_dh([DHLink(a=rng.uniform(0.05, 0.5), alpha=rng.uniform(-3.0, 3.0),
                                      d=rng.uniform(-0.3, 0.3)) for _ in range(6)])
    else:
        robot = getattr(models, name)()
    for q in robot.random_q(3, seed=2):
        T = np.ascontiguousarray(robot.fk(q))
        fast = ik_all(robot, T)
        slow = ik_all(robot, np.asfortranarray(T))  # not C-contiguous: the ordinary path
        ro = T.copy()
        ro.setflags(write=False)
        assert fast.shape[0] >= 1 and np.array_equal(fast, slow)
        assert np.array_equal(fast, ik_all(robot, ro))
        assert np.abs(robot.fk(fast) - T).max() < 1e-8


def test_tuple_vector_helpers_match_matrices():
    """rot3, mv3, mtv3, cross3t, add3, sub3 and row3 equal the matrix/array operations.

    Vectors as tuples and row3 of a read-only array: what the solvers pass.
    """
    from serialkin._checks import readonly
    from serialkin.ik.analytic.subproblems import (
        add3,
        cross3t,
        mtv3,
        mv3,
        rot3,
        rotation,
        row3,
        sub3,
    )

    rng = np.random.default_rng(3)
    for _ in range(20):
        w = rng.normal(size=3)
        w /= np.linalg.norm(w)
        v, u = rng.normal(size=3), rng.normal(size=3)
        th = rng.uniform(-4.0, 4.0)
        R = rotation(w, th)
        A = rng.normal(size=(4, 4))
        c, s = math.cos(th), math.sin(th)
        wt, vt, ut = tuple(w), tuple(v), tuple(u)
        assert np.allclose(rot3(wt, c, s, vt), R @ v, atol=1e-14)
        assert np.allclose(rot3(wt, c, -s, vt), R.T @ v, atol=1e-14)
        assert np.allclose(mv3(A, vt), A[:3, :3] @ v, atol=1e-14)
        assert np.allclose(mtv3(A, vt), A[:3, :3].T @ v, atol=1e-14)
        assert np.allclose(cross3t(ut, vt), np.cross(u, v), atol=1e-14)
        assert np.allclose(add3(ut, vt), u + v) and np.allclose(sub3(ut, vt), u - v)
        assert row3(readonly(A), 2) == tuple(A[2, :3])


def test_one_kernel_per_class_single_equals_batch():
    """The class kernel gives a target the same rows alone, in a batch and on the fast path.

    ``dispatch.solve`` over 4 targets at once, one at a time, and ``ik_all``'s fast path
    (one C-order pose) return the same rows bit for bit and the same convergence
    records; a target that is not rigid to 1e-13 gives −1 without solving.
    """
    from serialkin.ik.analytic import _pack, _prepared
    from serialkin.ik.analytic.dispatch import solve

    rng = np.random.default_rng(8)
    perturbed = Robot.from_dh([DHLink(a=r.a + rng.uniform(-1e-3, 1e-3),
                                      alpha=r.alpha + rng.uniform(-0.01, 0.01), d=r.d,
                                      theta=r.theta + rng.uniform(-0.01, 0.01))
                               for r in models.ur5().dh], "standard")
    for robot in (models.ur5(), models.puma560(), models.stanford(), models.scara(),
                  perturbed):
        p = _prepared(robot, 0.05)
        packed = _pack(p, p.solve_qlim, True, p.refine, 1e-8, 24)
        T = np.ascontiguousarray(robot.fk(robot.random_q(4, seed=1)))
        out, counts, conv = solve(p.code, T, packed)
        assert (counts >= 1).all()
        for i in range(4):
            o1, c1, v1 = solve(p.code, T[i:i + 1].copy(), packed)
            assert c1[0] == counts[i]
            np.testing.assert_array_equal(v1[0], conv[i])
            assert np.array_equal(o1[0], out[i])
            if p.mode != "near":  # the fast path's rows are the kernel's, unsorted
                assert np.array_equal(np.asarray(robot.ik_all(T[i])), out[i, :counts[i]])
        bad = T.copy()
        bad[1, 0, 0] += 1e-9
        assert solve(p.code, bad, packed)[1][1] == -1


def test_subproblem_cosines_match_angles():
    """sp1_dir_cs and the 6-column sp2_dir give cos/sin of their angles, which solve them."""
    from serialkin.ik.analytic.subproblems import rotation, sp1_dir, sp1_dir_cs, sp2_dir

    rng = np.random.default_rng(4)
    for _ in range(20):
        w1, w2, u = (x / np.linalg.norm(x) for x in rng.normal(size=(3, 3)))
        # vectors as tuples, as the solvers pass them
        ru = tuple(rotation(w1, 0.7) @ u)
        th, c, s = sp1_dir_cs(tuple(w1), tuple(u), ru)
        assert th == sp1_dir(tuple(w1), tuple(u), ru)
        assert abs(th - 0.7) < 1e-12 and abs(c - math.cos(th)) < 1e-15 \
            and abs(s - math.sin(th)) < 1e-15
        v = rotation(w1, rng.uniform(-3, 3)) @ rotation(w2, rng.uniform(-3, 3)) @ u
        out2, out6 = np.zeros((2, 2)), np.zeros((2, 6))
        vecs = (tuple(w1), tuple(w2), tuple(u), tuple(v))
        m = sp2_dir(*vecs, 0.0, out2)
        assert m == sp2_dir(*vecs, 0.0, out6) >= 1
        assert np.array_equal(out2[:m], out6[:m, :2])
        for t1, t2, c1, s1, c2, s2 in out6[:m]:
            assert np.allclose([c1, s1, c2, s2], [math.cos(t1), math.sin(t1), math.cos(t2),
                                                  math.sin(t2)], atol=1e-14)
            assert np.allclose(rotation(w1, t1) @ rotation(w2, t2) @ u, v, atol=1e-12)
    assert sp1_dir_cs((0.0, 0.0, 1.0), (0.0, 0.0, 2.0), (1.0, 0.0, 0.0)) == (0.0, 1.0, 0.0)


def test_sp4_cosines_match_angles():
    """sp4 with 6 output entries gives the cosine and sine of each angle, which solve it."""
    from serialkin.ik.analytic.subproblems import rotation, sp4

    rng = np.random.default_rng(6)
    for _ in range(40):
        w, b, a = rng.normal(size=(3, 3))
        w /= np.linalg.norm(w)
        c = a @ rotation(w, rng.uniform(-3, 3)) @ b
        out2, out6 = np.zeros(2), np.zeros(6)
        vecs = (tuple(w), tuple(b), tuple(a))  # as tuples, as the solvers pass them
        m = sp4(*vecs, c, 0.0, out2)
        assert m == sp4(*vecs, c, 0.0, out6) >= 1 and np.array_equal(out2[:m], out6[:m])
        for i in range(m):
            th, cs, sn = out6[i], out6[2 + 2 * i], out6[3 + 2 * i]
            assert abs(cs - math.cos(th)) < 1e-14 and abs(sn - math.sin(th)) < 1e-14
            assert abs(a @ rotation(w, th) @ b - c) < 1e-12


def test_ik_all_returns_one_type_for_one_target_and_a_batch():
    """ik_all gives an AllSolutions for one pose and for a batch; one pose's acts as its rows."""
    import pickle

    ur5 = models.ur5()
    Q = ur5.random_q(3, seed=4)
    T = ur5.fk(Q)
    one, many = ur5.ik_all(T[0]), ur5.ik_all(T)
    assert isinstance(one, AllSolutions) and isinstance(many, AllSolutions)
    rows = np.asarray(one)
    assert rows.shape == (one.count, 6) == one.shape and len(one) == one.count >= 1
    np.testing.assert_array_equal(one[0], rows[0])
    assert [r.tolist() for r in one] == rows.tolist() == one.tolist()
    np.testing.assert_array_equal(one - Q[0], rows - Q[0])
    turns = (one - Q[0] + np.pi) % (2 * np.pi) - np.pi  # arithmetic on the rows
    assert np.min(np.abs(turns).max(axis=1)) < 1e-9  # the generating q is a row (mod 2π)
    np.testing.assert_array_equal(many.solutions(0), rows)
    assert one.branches == many.branches[0]
    np.testing.assert_array_equal(one.converged, many.converged[0])
    slow = ur5.ik_all(np.asfortranarray(T[0]))  # the ordinary path: same record
    assert slow.branches == one.branches and slow.kind == one.kind == "ur"
    np.testing.assert_array_equal(slow.converged, one.converged)
    with pytest.raises(AttributeError, match="immutable"):
        one.q = rows
    np.testing.assert_array_equal(pickle.loads(pickle.dumps(one)), rows)
    assert str(one) == str(rows) and "AllSolutions(kind='ur'" in repr(one)


@pytest.mark.parametrize("name", ["ur5", "puma560", "stanford"])
def test_analytic_method_picks_the_nearest_representative(name):
    """robot.ik(method='analytic') on one pose is the nearest 2π-shift of an ik_all row."""
    robot = models.get(name)
    lo, hi = robot.qlim[:, 0], robot.qlim[:, 1]
    turns = np.arange(-3, 4) * 2 * np.pi
    for i, q in enumerate(robot.random_q(25, seed=40)):
        T = np.ascontiguousarray(robot.fk(q))
        rows = np.asarray(ik_all(robot, T))
        for q0 in (None, robot.random_q(seed=41 + i)):
            ref = robot.sampling_limits().mean(axis=1) if q0 is None else q0
            best = np.inf  # every row, every revolute joint at every turn inside the limits
            for row in rows:
                c = row[None, :] + np.where(robot.revolute, 1.0, 0.0) * turns[:, None]
                c = np.where((c >= lo - 1e-12) & (c <= hi + 1e-12), c, np.inf)
                nearest = np.take_along_axis(c, np.abs(c - ref).argmin(axis=0)[None], 0)[0]
                best = min(best, float(np.linalg.norm(nearest - ref)))
            res = robot.ik(T, method="analytic", q0=q0)
            assert res.success
            np.testing.assert_allclose(robot.fk(res.q), T, atol=1e-9)
            # without q0 the solver then moves joints wider than a turn nearest zero
            if q0 is not None or not np.any(hi - lo > 2 * np.pi):
                assert abs(np.linalg.norm(res.q - ref) - best) < 1e-9
