"""Fixtures for the IK tests: built-in robots and reachable targets."""

from __future__ import annotations

import numpy as np
import pytest

from serialkin import models
from serialkin.spatial.pose import pose_error

#: Accuracy every full-pose success must reach (the benchmark's definition).
ACCURACY = 1e-6


@pytest.fixture(scope="session")
def ur5():
    """Universal Robots UR5 (standard DH)."""
    return models.ur5()


@pytest.fixture(scope="session")
def puma():
    """Puma 560 (standard DH)."""
    return models.puma560()


@pytest.fixture(scope="session")
def panda():
    """Franka Panda (7 joints, modified DH)."""
    return models.panda()


@pytest.fixture(scope="session")
def two_link():
    """The chapter's 2-link planar arm (unit links)."""
    return models.two_link()


@pytest.fixture(scope="session")
def planar6():
    """The chapter's 6-link planar arm, L = 0.1 m."""
    return models.planar(6, 0.1)


def reachable(robot, count, seed):
    """``count`` configurations inside the limits and their FK poses (targets)."""
    q = robot.random_q(count, seed=seed)
    return q, robot.fk(q)


def task_errors(robot, q, T_target, weights=None):
    """(position error [m], orientation error [rad]) of FK(q) over the selected rows."""
    e = pose_error(robot.fk(q), T_target)
    sel = np.ones(6, bool) if weights is None else np.asarray(weights) > 0
    return float(np.linalg.norm(e[:3][sel[:3]])), float(np.linalg.norm(e[3:][sel[3:]]))


def assert_reaches(robot, res, T_target, weights=None, accuracy=ACCURACY, limits=True):
    """The result is a success whose q reproduces the target and lies inside the limits."""
    assert res.success, res.reason
    assert res.reason == ""
    pe, oe = task_errors(robot, res.q, T_target, weights)
    assert pe < accuracy, pe
    assert oe < accuracy, oe
    assert np.isfinite(res.q).all()
    if limits:
        assert robot.within_limits(res.q, 1e-12)
