"""Jacobians (chapter section 5): finite differences, the chapter's examples and peers."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import serialkin as sk
from serialkin import models
from tests.kinematics._fd import MODEL_IDS, all_models, dh_rows, fd_jacobian, random_transform

MODELS = all_models()


@pytest.mark.parametrize("frame", ["base", "ee"])
@pytest.mark.parametrize("robot", MODELS, ids=MODEL_IDS)
def test_geometric_jacobian_matches_finite_differences(robot, frame):
    """J (eqs 33-36) equals central differences of fk: dp/dq and vee(Ṙ Rᵀ) (or Rᵀ Ṙ for 'ee')."""
    for q in robot.random_q(4, seed=10):
        J = robot.jacobian(q, frame=frame)
        np.testing.assert_allclose(J, fd_jacobian(robot.fk, q, frame), atol=1e-7)


@settings(max_examples=40, deadline=None)
@given(rows=dh_rows(), convention=st.sampled_from(["standard", "modified"]),
       frame=st.sampled_from(["base", "ee"]), seed=st.integers(0, 2**32 - 1))
def test_random_dh_jacobian_matches_finite_differences(rows, convention, frame, seed):
    """On random DH tables (both conventions, R and P joints, base and tool) J matches FD."""
    rng = np.random.default_rng(seed)
    robot = sk.Robot.from_dh(rows, convention, base=random_transform(rng),
                             tool=random_transform(rng))
    q = robot.random_q(seed=rng)
    np.testing.assert_allclose(robot.jacobian(q, frame=frame), fd_jacobian(robot.fk, q, frame),
                               atol=1e-7)


@settings(max_examples=30, deadline=None)
@given(rows=dh_rows(min_joints=2), convention=st.sampled_from(["standard", "modified"]),
       frame=st.sampled_from(["base", "ee"]), seed=st.integers(0, 2**32 - 1))
def test_point_jacobian_on_any_link_matches_finite_differences(rows, convention, frame, seed):
    """The Jacobian of a point fixed on link k equals FD of that point (and of frame k)."""
    rng = np.random.default_rng(seed)
    robot = sk.Robot.from_dh(rows, convention, base=random_transform(rng))
    q = robot.random_q(seed=rng)
    k = int(rng.integers(0, robot.n + 1))
    point = rng.uniform(-0.5, 0.5, 3)
    offset = np.eye(4)
    offset[:3, 3] = point

    def pose(qq):
        return robot.fk_all(qq)[k] @ offset

    J = robot.jacobian(q, frame=frame, link=k, point=point)
    np.testing.assert_allclose(J, fd_jacobian(pose, q, frame), atol=1e-7)
    assert np.all(J[:, k:] == 0.0)  # joints beyond link k do not move it


@pytest.mark.parametrize("robot", MODELS, ids=MODEL_IDS)
def test_link_n_origin_jacobian_is_tool_jacobian_without_tool(robot):
    """With link = n and point = 0 the Jacobian is the tool Jacobian of the tool-less robot."""
    bare = robot.with_tool(np.eye(4))
    q = robot.random_q(seed=11)
    np.testing.assert_allclose(robot.jacobian(q, link=robot.n), bare.jacobian(q), atol=1e-14)


@pytest.mark.parametrize("robot", MODELS, ids=MODEL_IDS)
def test_jacobian_batch_equals_single(robot):
    """Batched Jacobians (tool and link/point, both frames) equal single calls."""
    Q = robot.random_q((2, 3), seed=12)
    for kwargs in ({}, {"frame": "ee"}, {"link": robot.n - 1, "point": [0.1, 0.2, 0.3]},
                   {"link": robot.n, "frame": "ee"}):
        J = robot.jacobian(Q, **kwargs)
        assert J.shape == (2, 3, 6, robot.n)
        for idx in np.ndindex(2, 3):
            np.testing.assert_allclose(J[idx], robot.jacobian(Q[idx], **kwargs), atol=1e-14)


@settings(max_examples=40, deadline=None)
@given(L1=st.floats(0.01, 2.0), L2=st.floats(0.01, 2.0), q1=st.floats(-np.pi, np.pi),
       q2=st.floats(-np.pi, np.pi))
def test_two_link_jacobian_eq_38(L1, L2, q1, q2):
    """The two-link geometric Jacobian equals eq 38 entry by entry."""
    robot = models.two_link(L1, L2)
    s1, c1, s12, c12 = np.sin(q1), np.cos(q1), np.sin(q1 + q2), np.cos(q1 + q2)
    eq38 = np.array([
        [-L1 * s1 - L2 * s12, -L2 * s12],
        [L1 * c1 + L2 * c12, L2 * c12],
        [0, 0], [0, 0], [0, 0],
        [1, 1],
    ])
    np.testing.assert_allclose(robot.jacobian([q1, q2]), eq38, atol=1e-12)


@settings(max_examples=40, deadline=None)
@given(L=st.lists(st.floats(0.01, 2.0), min_size=3, max_size=3),
       q=st.lists(st.floats(-np.pi, np.pi), min_size=3, max_size=3))
def test_three_link_analytical_jacobian_eqs_30_32(L, q):
    """The 3-link planar task Jacobian equals the analytical derivatives of eqs 30-32."""
    robot = models.three_link(*L)
    L1, L2, L3 = L
    q1, q2, q3 = q
    s1, s12, s123 = np.sin(q1), np.sin(q1 + q2), np.sin(q1 + q2 + q3)
    c1, c12, c123 = np.cos(q1), np.cos(q1 + q2), np.cos(q1 + q2 + q3)
    eq32 = np.array([
        [-L1 * s1 - L2 * s12 - L3 * s123, -L2 * s12 - L3 * s123, -L3 * s123],
        [L1 * c1 + L2 * c12 + L3 * c123, L2 * c12 + L3 * c123, L3 * c123],
    ])
    np.testing.assert_allclose(robot.jacobian_planar(q), eq32, atol=1e-12)
    J3 = robot.jacobian_planar(q, orientation=True)
    np.testing.assert_allclose(J3[2], [1.0, 1.0, 1.0], atol=1e-15)


@settings(max_examples=40, deadline=None)
@given(L1=st.floats(0.1, 2.0), L2=st.floats(0.1, 2.0), q=st.lists(st.floats(-3, 3), min_size=2,
                                                                  max_size=2))
def test_two_link_manipulability_eq_43(L1, L2, q):
    """The planar manipulability sqrt(det(J Jᵀ)) (eq 43) of the 2-link arm is L1 L2 |sin q2|."""
    robot = models.two_link(L1, L2)
    w = robot.manipulability(q, task="planar")
    # compare w² = det(J Jᵀ): sqrt amplifies round-off near singularities (w ~ 1e-8 there)
    assert w**2 == pytest.approx((L1 * L2 * np.sin(q[1])) ** 2, abs=1e-12)
    J = robot.jacobian_planar(q)
    s = np.linalg.svd(J, compute_uv=False)
    if s[-1] > 1e-9:
        assert robot.condition_number(q, task="planar") == pytest.approx(s[0] / s[-1], rel=1e-9)


def test_two_link_singular_when_stretched():
    """At q2 = 0 the 2-link arm is singular: manipulability 0, condition number inf."""
    robot = models.two_link(1.0, 0.7)
    assert robot.manipulability([0.4, 0.0], task="planar") ** 2 == pytest.approx(0.0, abs=1e-14)
    assert robot.condition_number([0.4, 0.0], task="planar") == np.inf


@pytest.mark.parametrize("robot", MODELS, ids=MODEL_IDS)
def test_jacobian_is_consistent_with_fk_velocity(robot):
    """A small joint step moves the tool by J·dq to first order (eq 28)."""
    rng = np.random.default_rng(13)
    q = robot.random_q(seed=rng)
    dq = rng.normal(size=robot.n) * 1e-6
    dp = robot.fk(q + dq)[:3, 3] - robot.fk(q)[:3, 3]
    np.testing.assert_allclose(dp, robot.jacobian(q)[:3] @ dq, atol=1e-10)


# ---------------------------------------------------------------------------- peers
@pytest.mark.peer
@pytest.mark.parametrize("name", ["puma560", "panda", "ur5"])
def test_jacobian_matches_robotics_toolbox(name):
    """jacob0 / jacobe of Robotics Toolbox's DH models equal jacobian(frame='base'/'ee')."""
    from tests.kinematics.test_fk import _rtb_models

    peer = _rtb_models()[name]
    robot = models.get(name)
    for q in robot.random_q(10, seed=14):
        np.testing.assert_allclose(robot.jacobian(q), peer.jacob0(q), atol=1e-12)
        np.testing.assert_allclose(robot.jacobian(q, frame="ee"), peer.jacobe(q), atol=1e-12)
