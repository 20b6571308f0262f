"""Reversed closed-form arms: the wrist (or the parallel axes) at the base, solved on T⁻¹.

An arm whose first three axes meet in a point is a spherical-wrist arm read from the tool
end: ``fk(q)⁻¹`` is the pose of the reversed chain (joints 6 to 1) at ``q[::-1]``
(``structure.reversed_lines``). ik_all recognises it and solves it in closed form; its
solutions must be exactly the forward arm's solutions of the inverted target, reversed.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import serialkin as sk
from serialkin import Joint, Robot
from serialkin.errors import NoClosedFormError
from serialkin.ik.analytic import classify, ik_all, structure_of
from serialkin.ik.analytic.structure import joint_lines, reversed_lines
from serialkin.model.dh import DHLink
from tests.ik._arms import WRIST_ARM, wrist_arm_rows

H = 0.5 * math.pi


def reversed_robot(robot: Robot) -> Robot:
    """The robot read from its tool end: ``reversed(q[::-1]).fk == robot.fk(q)⁻¹``.

    Joint j of the result is joint n + 1 − j of ``robot``, on the line of
    :func:`reversed_lines`, with its kind and limits; every joint frame is world-aligned
    at q = 0, so the chain is the product of exponentials of those lines.
    """
    W, P, M = joint_lines(robot)
    Wr, Pr, Mr = reversed_lines(W, P, M)
    joints, previous = [], np.zeros(3)
    for j in range(robot.n):
        origin = np.eye(4)
        origin[:3, 3] = Pr[j] - previous
        previous = Pr[j]
        k = robot.n - 1 - j
        joints.append(Joint(axis=Wr[j], type=robot.joint_types[k], origin=origin,
                            qlim=tuple(robot.qlim[k])))
    tool = np.eye(4)
    tool[:3, 3] = -previous
    return Robot.from_joints(joints, tool=tool @ Mr, name=f"{robot.name}-reversed")


def _wrapped_distance(robot: Robot, S: np.ndarray, q: np.ndarray) -> np.ndarray:
    """Distance of each row of S (k, n) to q (n,), revolute joints wrapped [rad or m]."""
    d = S - q
    rev = robot.revolute
    d[:, rev] = np.angle(np.exp(1j * d[:, rev]))
    return np.abs(d).max(axis=1) if len(S) else np.zeros(0)


def _same_sets(robot: Robot, A: np.ndarray, B: np.ndarray, tol: float = 1e-9) -> bool:
    """A and B (k, n) hold the same configurations (to tol, revolute joints wrapped)."""
    if len(A) != len(B):
        return False
    return all(_wrapped_distance(robot, B, a).min() < tol for a in A)


def _check(forward: Robot, count: int, seed: int) -> Robot:
    """Round trips on the reversed arm, and its solutions equal the forward arm's, reversed."""
    backward = reversed_robot(forward)
    rng = np.random.default_rng(seed)
    for q in forward.random_q(count, seed=rng):
        np.testing.assert_allclose(backward.fk(q[::-1]), np.linalg.inv(forward.fk(q)),
                                   atol=1e-12)
        T = backward.fk(q[::-1])
        S = np.asarray(ik_all(backward, T))
        assert len(S) and _wrapped_distance(backward, S, q[::-1]).min() < 1e-9
        for row in S:
            F = backward.fk(row)
            assert np.abs(F - T).max() < 1e-10
        expected = np.asarray(ik_all(forward, np.linalg.inv(T)))[:, ::-1]
        assert _same_sets(backward, S, expected)
    return backward


@pytest.mark.parametrize("name", ["puma560", "ur5", "stanford"])
def test_zoo_arms_read_from_the_tool_end(name):
    """Puma, UR5 and Stanford arms reversed: same class, reversed, every solution found."""
    forward = sk.models.get(name)
    backward = _check(forward, 20, seed=3)
    s = structure_of(backward)
    assert s.reversed and s.kind == structure_of(forward).kind
    assert classify(backward) == classify(forward)


@settings(max_examples=30, deadline=None)
@given(**WRIST_ARM, seed=st.integers(0, 2**31 - 1))
def test_any_reversed_pieper_arm(a, alpha, d, seed):
    """Any R R R arm behind a spherical wrist, read from the tool end, is solved completely."""
    rows = wrist_arm_rows(a, alpha, d)
    forward = Robot.from_dh(rows)
    try:
        classify(forward)
    except NoClosedFormError:  # degenerate draws (parallel or coinciding axes)
        return
    _check(forward, 4, seed=seed)


def test_a_wrist_first_dh_arm_is_closed_form():
    """A DH arm whose first three axes meet at one point is solved in closed form."""
    rows = [DHLink(a=0.0, alpha=-H, d=0.35), DHLink(a=0.0, alpha=H, d=0.0),
            DHLink(a=0.0, alpha=-H, d=0.3), DHLink(a=0.4, alpha=0.0, d=0.05),
            DHLink(a=0.05, alpha=H, d=0.1), DHLink(a=0.3, alpha=-0.4, d=0.08)]
    robot = Robot.from_dh(rows)
    s = structure_of(robot)
    assert s.reversed and s.kind in ("puma", "pieper_intersecting", "pieper_general")
    rng = np.random.default_rng(5)
    for q in robot.random_q(20, seed=rng):
        S = np.asarray(ik_all(robot, robot.fk(q)))
        assert _wrapped_distance(robot, S, q).min() < 1e-9
        assert len(S) % 2 == 0 and len(S) <= 8


def test_neither_end_gives_the_reason_of_the_forward_chain():
    """An arm with no closed form at either end says why, and that the reverse was tried."""
    rng = np.random.default_rng(0)
    robot = Robot.from_dh([DHLink(a=rng.uniform(0.1, 0.4), alpha=rng.uniform(0.3, 1.2),
                                  d=rng.uniform(0.05, 0.3)) for _ in range(6)])
    with pytest.raises(NoClosedFormError, match="reversed chain"):
        classify(robot)
