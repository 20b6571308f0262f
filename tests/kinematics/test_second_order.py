"""Hessian ∂J/∂q and time derivative J̇ of the geometric Jacobian: differences and identities."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import serialkin as sk
from serialkin import models
from serialkin.errors import InputError
from tests.kinematics._fd import dh_rows, random_transform

H_FD = 1e-6


def _fd_hessian(jac, q: np.ndarray) -> np.ndarray:
    """Central differences of a Jacobian function: [:, j, k] = ∂J[:, j]/∂q_k."""
    cols = [(jac(q + H_FD * e) - jac(q - H_FD * e)) / (2 * H_FD) for e in np.eye(q.size)]
    return np.stack(cols, axis=-1)


def _random_case(rows, convention, seed):
    rng = np.random.default_rng(seed)
    robot = sk.Robot.from_dh(rows, convention, base=random_transform(rng),
                             tool=random_transform(rng))
    q = robot.random_q(seed=rng)
    qd = rng.normal(size=robot.n)
    kwargs = {}
    if rng.random() < 0.5:
        kwargs = {"link": int(rng.integers(0, robot.n + 1)), "point": rng.uniform(-0.5, 0.5, 3)}
    return robot, q, qd, kwargs


@settings(max_examples=40, deadline=None)
@given(rows=dh_rows(), convention=st.sampled_from(["standard", "modified"]),
       frame=st.sampled_from(["base", "ee"]), seed=st.integers(0, 2**32 - 1))
def test_hessian_matches_finite_differences(rows, convention, frame, seed):
    """On random DH tables (R and P joints, tool or any link point, both frames) H = FD of J."""
    robot, q, _, kw = _random_case(rows, convention, seed)
    H = robot.hessian(q, frame, **kw)
    assert H.shape == (6, robot.n, robot.n)
    np.testing.assert_allclose(H, _fd_hessian(lambda x: robot.jacobian(x, frame, **kw), q),
                               atol=1e-7)


@settings(max_examples=40, deadline=None)
@given(rows=dh_rows(), convention=st.sampled_from(["standard", "modified"]),
       frame=st.sampled_from(["base", "ee"]), seed=st.integers(0, 2**32 - 1))
def test_jacobian_dot_matches_finite_differences_and_hessian(rows, convention, frame, seed):
    """J̇ equals the FD of J along q̇ and the contraction Σ_k H[:, :, k] q̇_k."""
    robot, q, qd, kw = _random_case(rows, convention, seed)
    Jd = robot.jacobian_dot(q, qd, frame, **kw)
    fd = (robot.jacobian(q + H_FD * qd, frame, **kw)
          - robot.jacobian(q - H_FD * qd, frame, **kw)) / (2 * H_FD)
    np.testing.assert_allclose(Jd, fd, atol=1e-7 * max(1.0, np.abs(qd).max()))
    np.testing.assert_allclose(Jd, robot.hessian(q, frame, **kw) @ qd, atol=1e-12)


@settings(max_examples=30, deadline=None)
@given(rows=dh_rows(), convention=st.sampled_from(["standard", "modified"]),
       seed=st.integers(0, 2**32 - 1))
def test_task_acceleration_is_j_qdd_plus_jdot_qd(rows, convention, seed):
    """Along q(t) = q + q̇t + ½q̈t², the tool's p̈ (second difference) is (J q̈ + J̇ q̇)[:3]."""
    robot, q, qd, _ = _random_case(rows, convention, seed)
    qdd = np.random.default_rng(seed + 1).normal(size=robot.n)
    h = 1e-4

    def p(t):
        return robot.fk(q + qd * t + 0.5 * qdd * t * t)[:3, 3]

    pdd = (p(h) - 2 * p(0.0) + p(-h)) / (h * h)
    acc = robot.jacobian(q) @ qdd + robot.jacobian_dot(q, qd) @ qd
    np.testing.assert_allclose(pdd, acc[:3], atol=1e-5 * max(1.0, np.abs(acc).max()))


@pytest.mark.parametrize("name", ["panda", "ur5", "stanford", "scara"])
def test_linear_block_is_symmetric_and_angular_block_triangular(name):
    """∂v_j/∂q_k = ∂v_k/∂q_j (Hessian of a position); ∂w_j/∂q_k = 0 for k ≥ j (base frame)."""
    robot = models.get(name)
    for q in robot.random_q(3, seed=4):
        H = robot.hessian(q)
        np.testing.assert_allclose(H[:3], np.swapaxes(H[:3], 1, 2), atol=1e-14)
        assert np.all(np.triu(np.ones((robot.n, robot.n), bool)) <= (H[3:] == 0.0).all(axis=0))


@pytest.mark.parametrize("name", ["panda", "ur5", "scara"])
def test_batches_equal_single_calls(name):
    """Hessians and J̇ over leading dimensions (qd broadcast) equal the single calls."""
    robot = models.get(name)
    Q = robot.random_q((2, 3), seed=6)
    qd = np.random.default_rng(7).normal(size=robot.n)
    for kw in ({}, {"frame": "ee"}, {"link": robot.n - 1, "point": [0.1, 0.0, -0.2]}):
        H = robot.hessian(Q, **kw)
        Jd = robot.jacobian_dot(Q, qd, **kw)
        assert H.shape == (2, 3, 6, robot.n, robot.n)
        assert Jd.shape == (2, 3, 6, robot.n)
        for idx in np.ndindex(2, 3):
            np.testing.assert_allclose(H[idx], robot.hessian(Q[idx], **kw), atol=1e-15)
            np.testing.assert_allclose(Jd[idx], robot.jacobian_dot(Q[idx], qd, **kw),
                                       atol=1e-15)


def test_jacobian_dot_vanishes_at_rest_and_is_linear_in_qd():
    """J̇(q, 0) = 0 and J̇(q, a·q̇₁ + q̇₂) = a·J̇(q, q̇₁) + J̇(q, q̇₂)."""
    robot = models.panda()
    q = robot.random_q(seed=8)
    rng = np.random.default_rng(9)
    v1, v2 = rng.normal(size=(2, robot.n))
    assert np.all(robot.jacobian_dot(q, np.zeros(robot.n)) == 0.0)
    np.testing.assert_allclose(robot.jacobian_dot(q, 2.5 * v1 + v2),
                               2.5 * robot.jacobian_dot(q, v1) + robot.jacobian_dot(q, v2),
                               atol=1e-13)


def test_bad_input_is_named():
    """Wrong qd shape, non-finite qd, unknown frame: InputError naming the argument."""
    robot = models.ur5()
    q = robot.random_q(seed=1)
    with pytest.raises(InputError, match="qd"):
        robot.jacobian_dot(q, np.zeros(5))
    with pytest.raises(InputError, match="qd"):
        robot.jacobian_dot(q, [0, 0, np.nan, 0, 0, 0])
    with pytest.raises(InputError, match="qd"):
        robot.jacobian_dot(q, np.zeros((3, 6)))
    with pytest.raises(InputError, match="qd"):
        robot.jacobian_dot(q, np.array([0, 0, np.inf, 0, 0, 0.0]))
    bad = q.copy()
    bad[1] = np.nan
    with pytest.raises(InputError, match="q must be finite"):
        robot.jacobian_dot(bad, np.zeros(6))
    with pytest.raises(InputError, match="q must be finite"):
        robot.hessian(bad)
    with pytest.raises(InputError, match="frame"):
        robot.hessian(q, "tool")
    with pytest.raises(InputError, match="frame"):
        robot.jacobian_dot(q, np.zeros(6), "world")
