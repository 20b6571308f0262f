"""Tests of the analytical Jacobian (eqs 28-29) and the representations' rate matrices."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import assume, given, settings
from hypothesis import strategies as st

from serialkin import Robot
from serialkin.errors import InputError, SingularityError
from serialkin.kinematics.analytic import (
    jacobian_analytic,
    rate_matrix,
    rotation_coordinates,
)
from serialkin.spatial import make_transform, roty, rpy_to_matrix, unskew, wrap_angle, zyz_to_matrix
from serialkin.spatial.lie import so3_exp

SETTINGS = settings(max_examples=30, deadline=None)
REPS = ("rpy", "zyz", "exp")
TO_MATRIX = {"rpy": rpy_to_matrix, "zyz": zyz_to_matrix, "exp": so3_exp}


def puma560() -> Robot:
    """Puma 560, standard DH (Corke, Robotics Toolbox 'Puma560'; a, d in m)."""
    a = [0.0, 0.4318, 0.0203, 0.0, 0.0, 0.0]
    d = [0.67183, 0.0, 0.15005, 0.4318, 0.0, 0.0]
    alpha = [np.pi / 2, 0.0, -np.pi / 2, np.pi / 2, -np.pi / 2, 0.0]
    rows = [{"a": a[i], "alpha": alpha[i], "d": d[i], "theta": 0.0} for i in range(6)]
    return Robot.from_dh(rows, name="puma560_test")


PUMA = puma560()
q_strategy = st.lists(st.floats(-np.pi, np.pi), min_size=6, max_size=6).map(np.array)


def task_coordinates(robot: Robot, q: np.ndarray, rep: str) -> np.ndarray:
    """x(q) = [p; φ(R)] evaluated through FK (the quantity J_A differentiates)."""
    T = robot.fk(q)
    return np.concatenate([T[:3, 3], rotation_coordinates(T[:3, :3], rep)])


def fd_jacobian(robot: Robot, q: np.ndarray, rep: str, h: float = 1e-6) -> np.ndarray:
    """Central finite difference of the task coordinates, angle differences wrapped."""
    J = np.empty((6, robot.n))
    for i in range(robot.n):
        dq = np.zeros(robot.n)
        dq[i] = h
        d = task_coordinates(robot, q + dq, rep) - task_coordinates(robot, q - dq, rep)
        if rep != "exp":
            d[3:] = wrap_angle(d[3:])
        J[:, i] = d / (2 * h)
    return J


def away_from_singularity(robot: Robot, q: np.ndarray, rep: str) -> bool:
    """True when φ(q) is well inside its chart (no gimbal lock, no log branch cut)."""
    phi = rotation_coordinates(robot.fk(q)[:3, :3], rep)
    if rep == "rpy":
        return abs(np.cos(phi[1])) > 0.05 and abs(abs(phi[0]) - np.pi) > 0.05 \
            and abs(abs(phi[2]) - np.pi) > 0.05
    if rep == "zyz":
        return abs(np.sin(phi[1])) > 0.05
    return np.linalg.norm(phi) < np.pi - 0.05


@SETTINGS
@given(q_strategy, st.sampled_from(REPS))
def test_analytic_jacobian_matches_finite_difference_of_fk(q: np.ndarray, rep: str) -> None:
    """J_A(q) equals the central difference of [p; φ(R(q))] on a Puma 560 built from DH."""
    assume(away_from_singularity(PUMA, q, rep))
    JA = jacobian_analytic(PUMA, q, rep)
    JF = fd_jacobian(PUMA, q, rep)
    scale = max(1.0, np.abs(JA).max())
    assert np.abs(JA - JF).max() < 1e-6 * scale
    assert np.allclose(JA[:3], PUMA.jacobian(q)[:3])


@SETTINGS
@given(st.lists(st.floats(-3.0, 3.0), min_size=3, max_size=3).map(np.array),
       st.lists(st.floats(-1.0, 1.0), min_size=3, max_size=3).map(np.array),
       st.sampled_from(REPS))
def test_rate_matrix_maps_coordinate_rates_to_angular_velocity(
    phi: np.ndarray, phidot: np.ndarray, rep: str
) -> None:
    """Ṙ Rᵀ = [E(φ) φ̇]^ for the representation's own φ → R map (central difference)."""
    to_R = TO_MATRIX[rep]
    h = 1e-6
    dR = (to_R(phi + h * phidot) - to_R(phi - h * phidot)) / (2 * h)
    omega = unskew(dR @ to_R(phi).T, tol=1e-6)
    assert np.allclose(rate_matrix(phi, rep) @ phidot, omega, atol=1e-8)


def test_rate_matrix_determinants() -> None:
    """Det E = cos pitch (rpy), −sin theta (zyz) and 2(1 − cos θ)/θ² (exp)."""
    phi = np.array([0.3, 0.7, -1.1])
    assert np.linalg.det(rate_matrix(phi, "rpy")) == pytest.approx(np.cos(0.7))
    assert np.linalg.det(rate_matrix(phi, "zyz")) == pytest.approx(-np.sin(0.7))
    th = np.linalg.norm(phi)
    assert np.linalg.det(rate_matrix(phi, "exp")) == pytest.approx(2 * (1 - np.cos(th)) / th**2)
    assert rate_matrix(np.zeros((4, 2, 3)), "exp").shape == (4, 2, 3, 3)


def test_three_link_planar_analytic_jacobian_eqs_30_to_32() -> None:
    """For the chapter's 3-link arm, rows x, y are eq 32 and the yaw row is [1, 1, 1]."""
    L = (1.0, 0.8, 0.5)
    robot = Robot.from_dh([{"a": li, "alpha": 0.0, "d": 0.0, "theta": 0.0} for li in L])
    q = np.array([0.3, -0.5, 0.9])
    s1, s12, s123 = np.sin(q[0]), np.sin(q[:2].sum()), np.sin(q.sum())
    c1, c12, c123 = np.cos(q[0]), np.cos(q[:2].sum()), np.cos(q.sum())
    eq32 = np.array([
        [-L[0] * s1 - L[1] * s12 - L[2] * s123, -L[1] * s12 - L[2] * s123, -L[2] * s123],
        [L[0] * c1 + L[1] * c12 + L[2] * c123, L[1] * c12 + L[2] * c123, L[2] * c123],
    ])
    JA = jacobian_analytic(robot, q, "rpy")
    assert np.allclose(JA[:2], eq32)
    assert np.allclose(JA[5], [1.0, 1.0, 1.0])
    assert np.allclose(JA[[2, 3, 4]], 0.0)


def test_batched_equals_single_calls_and_robot_method() -> None:
    """A (2, 3, 6) batch gives (2, 3, 6, 6) equal to per-configuration calls and robot method."""
    Q = np.random.default_rng(3).uniform(-1, 1, size=(2, 3, 6)) + 0.3
    for rep in REPS:
        JA = jacobian_analytic(PUMA, Q, rep)
        assert JA.shape == (2, 3, 6, 6)
        for idx in np.ndindex(2, 3):
            assert np.allclose(JA[idx], jacobian_analytic(PUMA, Q[idx], rep))
        assert np.allclose(PUMA.jacobian_analytic(Q, rep), JA)


def test_singular_representation_raises_with_clear_message() -> None:
    """At pitch = π/2 (rpy) and theta = 0 (zyz) a SingularityError names rep, q and index."""
    R0 = PUMA.fk(np.zeros(6))[:3, :3]
    locked = PUMA.with_tool(make_transform(R0.T @ roty(np.pi / 2)))
    assert np.allclose(locked.fk(np.zeros(6))[:3, :3], roty(np.pi / 2))
    with pytest.raises(SingularityError, match=r"rep='rpy'.*gimbal lock.*q = \[0\.0"):
        jacobian_analytic(locked, np.zeros(6), "rpy")
    Q = np.stack([np.full(6, 0.4), np.zeros(6)])
    with pytest.raises(SingularityError, match=r"at batch index \(1,\).*theta = 0 or π"):
        jacobian_analytic(PUMA, Q, "zyz")
    # the exponential coordinates are fine there
    assert np.all(np.isfinite(jacobian_analytic(PUMA, Q, "exp")))
    # SingularityError is a ValueError, catchable as such
    with pytest.raises(ValueError):
        PUMA.jacobian_analytic(np.zeros(6), "zyz")


def test_bad_input_messages() -> None:
    """Unknown rep (with a suggestion), wrong q size, NaN and bad phi shape raise clearly."""
    with pytest.raises(InputError, match=r"unknown rep 'rp'.*Did you mean 'rpy'"):
        jacobian_analytic(PUMA, np.zeros(6), "rp")
    with pytest.raises(InputError, match="q has 5 values but robot 'puma560_test' has 6 joints"):
        jacobian_analytic(PUMA, np.zeros(5), "rpy")
    with pytest.raises(InputError, match="q must be finite"):
        jacobian_analytic(PUMA, np.full(6, np.nan), "exp")
    with pytest.raises(InputError, match=r"phi must have shape \(\.\.\., 3\)"):
        rate_matrix(np.zeros(4), "rpy")
    with pytest.raises(InputError, match="tol must be a finite number > 0"):
        jacobian_analytic(PUMA, np.ones(6), "rpy", tol=-1.0)


@pytest.mark.peer
@pytest.mark.parametrize(("rep", "peer_rep"), [("rpy", "rpy/zyx"), ("zyz", "eul"), ("exp", "exp")])
def test_agrees_with_robotics_toolbox(rep: str, peer_rep: str) -> None:
    """J_A equals Robotics Toolbox's jacob0_analytical for the same Puma 560 DH table."""
    rtb = pytest.importorskip("roboticstoolbox")
    peer = rtb.models.DH.Puma560()
    rng = np.random.default_rng(8)
    for _ in range(5):
        q = rng.uniform(-2.5, 2.5, 6)
        if not away_from_singularity(PUMA, q, rep):
            continue
        assert np.allclose(peer.fkine(q).A, PUMA.fk(q), atol=1e-12)
        ref = peer.jacob0_analytical(q, representation=peer_rep)
        assert np.allclose(jacobian_analytic(PUMA, q, rep), ref, atol=1e-10)
