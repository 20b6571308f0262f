"""Weighted multi-task resolution (eqs 47-50, corrected) and the joint-limit weight eq 49."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from serialkin.errors import InputError
from serialkin.model.geometry import Cylinder
from serialkin.redundancy import (
    MultiTaskResolver,
    joint_limit_repulsion,
    joint_limit_weights,
    obstacle_jacobian,
)

from ._robots import six_link, twenty_link

LIM = np.array([[-1.0, 1.0]])


def test_joint_limit_weight_shape_of_eq_49():
    """Eq 49 (designed): 0 inside, continuous growth in the buffer, maximum at and beyond."""
    q = np.linspace(-1.5, 1.5, 3001)
    w = np.array([joint_limit_weights([x], LIM, buffer=0.1, max_weight=50.0)[0] for x in q])
    inside = np.abs(q) <= 0.8
    assert np.all(w[inside] == 0.0)
    assert np.all(w[np.abs(q) >= 1.0] == 50.0)
    assert np.max(np.abs(np.diff(w))) < 50.0 * 0.02  # continuous: no jump
    buf = (q > 0.8) & (q < 1.0)
    assert np.all(np.diff(w[buf]) > 0)  # grows towards the upper limit
    assert joint_limit_weights([0.9], [[-np.inf, np.inf]])[0] == 0.0


def test_joint_limit_repulsion_points_to_mid_range():
    """The repulsive target is positive near the lower limit and negative near the upper one."""
    r = joint_limit_repulsion([-0.95, 0.0, 0.95], np.tile(LIM, (3, 1)), buffer=0.1)
    assert r[0] > 0 and r[1] == 0 and r[2] < 0


@settings(max_examples=25, deadline=None)
@given(seed=st.integers(0, 2**31 - 1))
def test_eq48_without_secondary_tasks_is_dls(seed):
    """With W = I, W_c = W_L = 0 and W_s = λ²I, eq 48 equals Jᵀ(JJᵀ + λ²I)⁻¹ẋ (eq 46)."""
    robot = six_link()
    rng = np.random.default_rng(seed)
    q = robot.random_q(seed=rng)
    xdot = rng.normal(size=2) * 0.01
    lam = 0.05
    res = MultiTaskResolver(task="planar", damping=lam, joint_limit_weight=0.0)
    J = robot.jacobian(q)[:2]
    expected = J.T @ np.linalg.solve(J @ J.T + lam**2 * np.eye(2), xdot)
    np.testing.assert_allclose(res.velocity(robot, q, xdot), expected, atol=1e-12)


def test_obstacle_task_damps_the_approach():
    """Eq 48 with the obstacle task: the approach rate J_c q̇ is smaller than without it."""
    robot = twenty_link()
    q = np.full(20, np.radians(6.0))
    obs = Cylinder(0.02, math.inf, center=[0.1, 0.07, 0.0], influence=0.05)
    Jc, c, _ = obstacle_jacobian(robot, q, [obs])
    assert Jc.shape[0] > 0
    xdot = np.array([-0.005, 0.005])
    free = MultiTaskResolver(task="planar", damping=0.01).velocity(robot, q, xdot)
    guarded = MultiTaskResolver(task="planar", damping=0.01, obstacles=(obs,),
                                obstacle_weight=1000.0).velocity(robot, q, xdot)
    assert np.max(Jc @ guarded) < np.max(Jc @ free)
    J = robot.jacobian(q)[:2]
    np.testing.assert_allclose(J @ guarded, xdot, atol=2e-3)  # primary task still served


def test_repulsive_mode_retreats():
    """With a repulsive gain the closest link moves away (negative approach rate) at ẋ = 0."""
    robot = twenty_link()
    q = np.full(20, np.radians(6.0))
    obs = Cylinder(0.02, math.inf, center=[0.1, 0.07, 0.0], influence=0.05)
    Jc, c, _ = obstacle_jacobian(robot, q, [obs])
    res = MultiTaskResolver(task="planar", obstacles=(obs,), repulsive_gain=1.0,
                            damping=0.01)
    qd = res.velocity(robot, q, np.zeros(2))
    assert (Jc @ qd)[np.argmin(c)] < 0


def test_joint_limit_task_damps_motion_beyond_buffer():
    """A joint deep in its buffer moves less with the joint-limit task than without it."""
    robot = six_link().with_limits(np.tile(np.radians([-100.0, 100.0]), (6, 1)))
    q = np.radians([10.0, 98.0, 20.0, 10.0, 5.0, 0.0])
    xdot = np.array([0.0, 0.02])
    off = MultiTaskResolver(task="planar", joint_limit_weight=0.0, damping=0.01)
    on = MultiTaskResolver(task="planar", joint_limit_weight=100.0, damping=0.01)
    assert abs(on.velocity(robot, q, xdot)[1]) < 0.2 * abs(off.velocity(robot, q, xdot)[1])


@pytest.mark.parametrize("field", ["weight", "obstacle_weight", "joint_limit_weight",
                                   "singularity_damping", "repulsive_gain"])
def test_negative_weights_rejected(field):
    """Negative weights raise InputError naming the weight."""
    with pytest.raises(InputError, match=field):
        MultiTaskResolver(**{field: -1.0})


def test_resolver_rejects_bad_settings():
    """Bad buffer, task, obstacles and xdot size raise InputError."""
    with pytest.raises(InputError, match="limit_buffer"):
        MultiTaskResolver(limit_buffer=0.9)
    with pytest.raises(InputError, match="task"):
        MultiTaskResolver(task="planer")
    with pytest.raises(InputError, match="obstacles"):
        MultiTaskResolver(obstacles=("x",))
    with pytest.raises(InputError, match="xdot"):
        MultiTaskResolver().velocity(six_link(), np.zeros(6), [0.0, 0.0, 0.0])
    with pytest.raises(InputError, match="overlaps"):
        post = Cylinder(0.05, math.inf, center=[0, 0, 0.0])
        MultiTaskResolver(obstacles=(post,)).prepare(six_link())
