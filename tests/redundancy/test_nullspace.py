"""Null-space projection (eq 42), self-motion and task priority."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from serialkin.errors import InputError
from serialkin.redundancy import (
    dls_inverse,
    joint_limit_distance,
    manipulability,
    nullspace_projector,
    projected_gradient_velocity,
    pseudo_inverse,
    self_motion,
    task_priority_velocity,
)

from ._robots import six_link, spatial_rp, twenty_link

SEEDS = st.integers(0, 2**31 - 1)


@settings(max_examples=40, deadline=None)
@given(seed=SEEDS, which=st.sampled_from(["six", "twenty", "rp7"]))
def test_nullspace_motion_leaves_end_effector_still(seed, which):
    """‖J (I − J⁺J) v‖ ≈ 0 for random q and v; the projector is symmetric and idempotent."""
    robot = {"six": six_link, "twenty": twenty_link, "rp7": spatial_rp}[which]()
    rng = np.random.default_rng(seed)
    q = robot.random_q(seed=rng)
    J = robot.jacobian(q)
    J = J[[0, 1]] if which != "rp7" else J[[0, 1, 2]]
    v = rng.normal(size=robot.n)
    P = nullspace_projector(J)
    assert np.linalg.norm(J @ P @ v) <= 1e-9 * max(1.0, np.linalg.norm(v))
    np.testing.assert_allclose(P, P.T, atol=1e-12)
    np.testing.assert_allclose(P @ P, P, atol=1e-10)


def test_projected_gradient_primary_task_exact():
    """Eq 42 with the pseudoinverse: J q̇ = ẋ whatever the secondary objective."""
    robot = six_link()
    q = robot.random_q(seed=3)
    xdot = np.array([0.05, -0.02])
    qd = projected_gradient_velocity(robot, q, xdot, manipulability(robot, "planar"), gain=5.0)
    np.testing.assert_allclose(robot.jacobian(q)[:2] @ qd, xdot, atol=1e-12)


def test_dls_inverse_forms_agree():
    """Jᵀ(J Jᵀ + λ²I)⁻¹ (eq 46 corrected) equals (JᵀJ + λ²I)⁻¹Jᵀ and tends to J⁺ as λ → 0."""
    J = np.random.default_rng(1).normal(size=(2, 6))
    lam = 0.3
    np.testing.assert_allclose(dls_inverse(J, lam),
                               np.linalg.solve(J.T @ J + lam**2 * np.eye(6), J.T), atol=1e-12)
    np.testing.assert_allclose(dls_inverse(J, 1e-7), pseudo_inverse(J), atol=1e-6)
    with pytest.raises(InputError):
        dls_inverse(J, -1.0)


def test_self_motion_increases_manipulability():
    """Self-motion along the manipulability gradient increases w while the end-effector stays."""
    robot = six_link()
    q0 = np.array([0.3, 0.2, 0.1, 0.1, 0.05, 0.02])  # nearly stretched: low manipulability
    obj = manipulability(robot, "planar")
    traj = self_motion(robot, q0, obj, steps=60, gain=20.0, max_step=0.02)
    w = np.array([obj.value(q) for q in traj])
    assert w[-1] > 1.15 * w[0]
    assert np.all(np.diff(w) > -1e-9)
    drift = np.linalg.norm(robot.fk(traj[-1])[:2, 3] - robot.fk(q0)[:2, 3])
    assert drift < 2e-3


def test_self_motion_moves_toward_mid_range():
    """Self-motion along −∇H of eq 44 moves the joints towards mid-range (H decreases)."""
    lim = np.tile(np.radians([-100.0, 100.0]), (6, 1))
    robot = six_link().with_limits(lim)
    q0 = np.radians([80.0, -70.0, 60.0, 20.0, -85.0, 40.0])
    obj = joint_limit_distance(robot)
    traj = self_motion(robot, q0, obj, steps=80, gain=2.0, max_step=0.02)
    H = np.array([obj.value(q) for q in traj])
    assert H[-1] < 0.5 * H[0]
    assert np.all(np.diff(H) < 1e-12)
    assert np.abs(traj[-1]).max() < np.abs(q0).max()
    drift = np.linalg.norm(robot.fk(traj[-1])[:2, 3] - robot.fk(q0)[:2, 3])
    assert drift < 2e-3


def test_task_priority_keeps_primary_and_meets_compatible_secondary():
    """Two-task priority: task 1 exact; a compatible task 2 is met too."""
    robot = twenty_link()
    q = robot.random_q(seed=5)
    J1 = robot.jacobian(q)[:2]
    J2 = robot.jacobian(q, link=10)[:2]  # the middle of the arm
    x1 = np.array([0.01, 0.02])
    x2 = np.array([-0.01, 0.0])
    qd = task_priority_velocity(J1, x1, J2, x2)
    np.testing.assert_allclose(J1 @ qd, x1, atol=1e-10)
    np.testing.assert_allclose(J2 @ qd, x2, atol=1e-8)
    with pytest.raises(InputError, match="columns"):
        task_priority_velocity(J1, x1, J2[:, :5], x2)


def test_projected_gradient_bad_input():
    """Wrong xdot size, negative gain and an unknown inverse raise InputError."""
    robot = six_link()
    q = np.zeros(6)
    with pytest.raises(InputError, match="xdot"):
        projected_gradient_velocity(robot, q, [0.1, 0.2, 0.3])
    with pytest.raises(InputError, match="gain"):
        projected_gradient_velocity(robot, q, [0.1, 0.2], manipulability(robot, "planar"),
                                    gain=-1.0)
    with pytest.raises(InputError, match="method"):
        projected_gradient_velocity(robot, q, [0.1, 0.2], method="svd")
