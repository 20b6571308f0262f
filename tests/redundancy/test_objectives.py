"""Objectives of eqs 43-45 and their gradients, checked against finite differences."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from serialkin.errors import InputError, InputTypeError
from serialkin.model.geometry import Cylinder
from serialkin.redundancy import (
    custom_objective,
    jacobian_derivative,
    joint_limit_distance,
    manipulability,
    manipulability_gradient,
    obstacle_distance,
)
from serialkin.redundancy.objectives import finite_difference_gradient, task_rows

from ._robots import six_link, spatial_rp

SEEDS = st.integers(0, 2**31 - 1)


@settings(max_examples=25, deadline=None)
@given(seed=SEEDS)
def test_jacobian_derivative_matches_finite_differences(seed):
    """∂J/∂q_k from the cross-product formulas equals central differences of J (R and P joints)."""
    robot = spatial_rp()
    q = robot.random_q(seed=seed)
    H = jacobian_derivative(robot, q)
    h = 1e-6
    for k in range(robot.n):
        d = np.zeros(robot.n)
        d[k] = h
        fd = (robot.jacobian(q + d) - robot.jacobian(q - d)) / (2 * h)
        np.testing.assert_allclose(H[k], fd, atol=1e-7)


@settings(max_examples=25, deadline=None)
@given(seed=SEEDS, task=st.sampled_from(["full", "position"]))
def test_manipulability_gradient_spatial(seed, task):
    """The analytic gradient of w = sqrt(det(J Jᵀ)) (eq 43) matches finite differences."""
    robot = spatial_rp()
    q = robot.random_q(seed=seed)
    w, g = manipulability_gradient(robot, q, task)
    assert w == pytest.approx(robot.manipulability(q, task), rel=1e-12)
    fd = finite_difference_gradient(lambda x: manipulability_gradient(robot, x, task)[0], q)
    np.testing.assert_allclose(g, fd, atol=1e-7 * max(1.0, abs(w)))


@settings(max_examples=25, deadline=None)
@given(seed=SEEDS)
def test_manipulability_gradient_planar(seed):
    """Planar (vx, vy) manipulability gradient of the 6-link arm matches finite differences."""
    robot = six_link()
    q = robot.random_q(seed=seed)
    obj = manipulability(robot, "planar")
    fd = finite_difference_gradient(obj.value, q)
    np.testing.assert_allclose(obj.gradient(q), fd, atol=1e-8)
    assert obj.maximize


def test_manipulability_gradient_zero_at_singularity():
    """At the stretched (singular) planar arm w = 0 and the gradient returned is 0."""
    robot = six_link()
    w, g = manipulability_gradient(robot, np.zeros(6), "planar")
    assert w == pytest.approx(0.0, abs=1e-12)
    assert np.all(g == 0.0)


def test_joint_limit_objective_uses_corrected_mid_range():
    """Eq 44 corrected: H and ∇H vanish at q̄ = (q_M + q_m)/2, not at (q_M − q_m)/2."""
    robot = six_link().with_limits(np.tile([0.2, 1.4], (6, 1)))
    obj = joint_limit_distance(robot)
    mid = np.full(6, 0.8)
    assert obj.value(mid) == pytest.approx(0.0)
    assert np.allclose(obj.gradient(mid), 0.0)
    assert obj.value(np.full(6, 0.6)) > 0  # the printed (q_M - q_m)/2 = 0.6 is not optimal
    assert not obj.maximize


@settings(max_examples=25, deadline=None)
@given(seed=SEEDS)
def test_joint_limit_gradient_matches_finite_differences(seed):
    """∂H/∂q_i = (q_i − q̄_i)/(q_M − q_m)² matches finite differences (unlimited joints: 0)."""
    lim = np.tile([-1.5, 2.0], (6, 1))
    lim[2] = [-np.inf, np.inf]
    robot = six_link().with_limits(lim)
    obj = joint_limit_distance(robot)
    q = robot.random_q(seed=seed)
    np.testing.assert_allclose(obj.gradient(q), finite_difference_gradient(obj.value, q),
                               atol=1e-8)
    assert obj.gradient(q)[2] == 0.0


def test_joint_limit_objective_rejects_bad_limits():
    """Limits of the wrong shape or with lower >= upper raise InputError."""
    robot = six_link()
    with pytest.raises(InputError, match="shape"):
        joint_limit_distance(robot, np.zeros((5, 2)))
    with pytest.raises(InputError, match="lower"):
        joint_limit_distance(robot, np.tile([1.0, -1.0], (6, 1)))


@settings(max_examples=25, deadline=None)
@given(seed=SEEDS, squared=st.booleans())
def test_obstacle_distance_gradient_matches_finite_differences(seed, squared):
    """Eq 45's gradient (closest pair, eqs 51-56) matches finite differences away from ties."""
    robot = six_link()
    obs = [Cylinder(0.05, math.inf, center=[0.25, 0.2, 0.0]),
           Cylinder(0.04, math.inf, center=[-0.2, -0.25, 0.0])]
    rng = np.random.default_rng(seed)
    q = rng.uniform(-1.2, 1.2, 6)
    obj = obstacle_distance(robot, obs, squared=squared)
    fd = finite_difference_gradient(obj.value, q, step=1e-7)
    g = obj.gradient(q)
    # the min over pairs has kinks where two pairs tie: skip those rare points
    if np.linalg.norm(g - fd) > 1e-5:
        fd2 = finite_difference_gradient(obj.value, q, step=1e-8)
        if np.linalg.norm(fd - fd2) > 1e-5:
            return
    np.testing.assert_allclose(g, fd, atol=1e-5)


def test_custom_objective_with_and_without_gradient():
    """A user callable works with its own gradient and with the finite-difference fallback."""
    f = lambda q: float(np.sum(np.sin(q)))  # noqa: E731
    g = lambda q: np.cos(q)  # noqa: E731
    q = np.linspace(-1, 1, 6)
    a = custom_objective(f, g, maximize=False)
    b = custom_objective(f)
    np.testing.assert_allclose(a.gradient(q), np.cos(q))
    np.testing.assert_allclose(b.gradient(q), np.cos(q), atol=1e-8)
    np.testing.assert_allclose(a.ascent(q), -np.cos(q))
    with pytest.raises(InputTypeError):
        custom_objective(3.0)
    with pytest.raises(InputTypeError):
        custom_objective(f, gradient="no")


def test_task_rows_validation():
    """Unknown task names and rows outside 0..5 raise InputError."""
    assert task_rows("planar").tolist() == [0, 1]
    with pytest.raises(InputError, match="unknown task"):
        task_rows("planer")
    with pytest.raises(InputError):
        task_rows([0, 7])
