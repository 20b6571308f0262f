"""Tests of the pose error (compiled kernel and numpy wrapper) and pose distance."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.spatial.transform import Rotation

from serialkin import Robot
from serialkin._checks import readonly
from serialkin.errors import InputError
from serialkin.spatial import kernels as K
from serialkin.spatial import (
    make_transform,
    pose_distance,
    pose_error,
    so3_exp,
    transl,
    trotz,
)

SETTINGS = settings(max_examples=40, deadline=None)
seeds = st.integers(0, 2**32 - 1)


def random_poses(n: int, seed: int) -> np.ndarray:
    """Random rigid transforms, n of them (uniform rotations, positions in a 2 m cube)."""
    rng = np.random.default_rng(seed)
    R = Rotation.random(n, random_state=seed).as_matrix()
    return make_transform(R, rng.uniform(-1, 1, size=(n, 3)))


@SETTINGS
@given(seeds)
def test_pose_error_is_zero_at_target(seed: int) -> None:
    """e(T, T) = 0 for every pose (batch of 20)."""
    T = random_poses(20, seed)
    assert np.abs(pose_error(T, T)).max() < 1e-15


@SETTINGS
@given(seeds, st.floats(1e-8, 1e-3))
def test_pose_error_equals_small_twist(seed: int, scale: float) -> None:
    """For T_target = (exp(dω) R, p + dv) the error is [dv; dω] up to O(|d|²)."""
    rng = np.random.default_rng(seed)
    T = random_poses(1, seed)[0]
    d = rng.normal(size=6) * scale
    Tt = make_transform(so3_exp(d[3:]) @ T[:3, :3], T[:3, 3] + d[:3])
    e = pose_error(T, Tt)
    assert np.abs(e - d).max() <= 1e-12 + 1e-9 * scale
    # exact for the rotation part, whatever the size (it is the log)
    assert np.allclose(e[3:], d[3:], atol=1e-15, rtol=1e-9)


@SETTINGS
@given(seeds)
def test_pose_error_is_antisymmetric_and_frame_consistent(seed: int) -> None:
    """Swapping the poses negates the error; its angle equals the relative rotation angle."""
    A, B = random_poses(2, seed)
    e1, e2 = pose_error(A, B), pose_error(B, A)
    if np.linalg.norm(e1[3:]) < np.pi - 1e-6:
        assert np.allclose(e1, -e2, atol=1e-13)
    rel = Rotation.from_matrix(A[:3, :3].T @ B[:3, :3]).magnitude()
    assert np.linalg.norm(e1[3:]) == pytest.approx(rel, abs=1e-12)


@pytest.mark.parametrize("eps", [0.0, 1e-12, 1e-8, 1e-4])
def test_pose_error_near_half_turn(eps: float) -> None:
    """Near a relative rotation of π the error keeps its length π − eps and its axis."""
    axis = np.array([1.0, 2.0, 2.0]) / 3.0
    T = random_poses(1, 11)[0]
    Tt = make_transform(so3_exp(axis * (np.pi - eps)) @ T[:3, :3], T[:3, 3])
    w = pose_error(T, Tt)[3:]
    assert np.linalg.norm(w) == pytest.approx(np.pi - eps, abs=1e-13)
    assert min(np.abs(w / np.linalg.norm(w) - axis).max(),
               np.abs(w / np.linalg.norm(w) + axis).max()) < 1e-8
    if eps > 1e-7:
        assert np.allclose(w / np.linalg.norm(w), axis, atol=1e-8)


def test_kernel_direct_call_matches_wrapper() -> None:
    """pose_error_into (the IK kernel) writes the same 6-vector as pose_error."""
    A, B = random_poses(2, 4)
    e = np.empty(6)
    K.pose_error_into(A, readonly(B), e)  # the target read-only, as the library passes it
    assert np.array_equal(e, pose_error(A, B))


def test_pose_error_linearises_with_the_geometric_jacobian() -> None:
    """e(fk(q), fk(q + dq)) ≈ J(q) dq for a 3-D DH arm (world frame, order [v; ω])."""
    robot = Robot.from_dh(
        [
            {"a": 0.0, "alpha": np.pi / 2, "d": 0.3, "theta": 0.0},
            {"a": 0.4, "alpha": 0.0, "d": 0.0, "theta": 0.0},
            {"a": 0.05, "alpha": -np.pi / 2, "d": 0.1, "theta": 0.0},
            {"a": 0.0, "alpha": np.pi / 2, "d": 0.35, "theta": 0.0},
        ],
        name="test_arm",
    )
    rng = np.random.default_rng(7)
    for _ in range(5):
        q = rng.uniform(-np.pi, np.pi, 4)
        dq = rng.normal(size=4) * 1e-6
        e = pose_error(robot.fk(q), robot.fk(q + dq))
        assert np.allclose(e, robot.jacobian(q) @ dq, atol=1e-11)


def test_pose_distance_and_broadcasting() -> None:
    """pose_distance gives |Δp| and the angle; one target broadcasts against a batch."""
    T = np.stack([np.eye(4), transl(0.3, 0.4, 0.0), trotz(0.25)])
    d, th = pose_distance(T, np.eye(4))
    assert d.shape == th.shape == (3,)
    assert np.allclose(d, [0.0, 0.5, 0.0])
    assert np.allclose(th, [0.0, 0.0, 0.25])
    e = pose_error(np.eye(4), transl(0.1, 0, 0) @ trotz(0.2))
    assert np.allclose(e, [0.1, 0, 0, 0, 0, 0.2])
    assert pose_error(T.reshape(3, 1, 4, 4), random_poses(5, 1)).shape == (3, 5, 6)


def test_pose_error_bad_input_messages() -> None:
    """Wrong shapes, non-rigid matrices, NaN and non-broadcasting batches raise clearly."""
    with pytest.raises(InputError, match=r"T must have shape \(\.\.\., 4, 4\).*got shape \(3, 3\)"):
        pose_error(np.eye(3), np.eye(4))
    bad = np.eye(4)
    bad[3, 0] = 1.0
    with pytest.raises(InputError, match="T_target is not a homogeneous transform"):
        pose_error(np.eye(4), bad)
    with pytest.raises(InputError, match="the rotation block of T is not orthonormal"):
        pose_error(np.diag([2.0, 1.0, 1.0, 1.0]), np.eye(4))
    nan = np.eye(4)
    nan[0, 3] = np.nan
    with pytest.raises(InputError, match="T must be finite"):
        pose_error(nan, np.eye(4))
    with pytest.raises(InputError, match="do not broadcast"):
        pose_error(random_poses(2, 0), random_poses(3, 0))


@SETTINGS
@given(seeds, st.integers(0, 15), st.sampled_from([0.0, 1e-8, 1e-5, 1e-3]))
def test_compiled_validity_check_agrees_with_check_transform(seed: int, entry: int,
                                                             delta: float) -> None:
    """transforms_valid accepts exactly what check_transform accepts (perturbed entries)."""
    from serialkin._checks import ROTATION_TOL, check_transform

    T = random_poses(3, seed)
    T[1].flat[entry] += delta
    try:
        check_transform(T)
        ok = True
    except InputError:
        ok = False
    assert K.transforms_valid(readonly(T), ROTATION_TOL) == ok  # read-only, as the library
    assert ok == (delta < ROTATION_TOL or entry in (3, 7, 11))


def test_pose_error_accepts_lists_and_unchecked_arrays() -> None:
    """Nested lists are coerced; check=False skips validation but computes the same error."""
    A = random_poses(1, 9)[0]
    e_list = pose_error(A.tolist(), np.eye(4).tolist())
    assert np.allclose(e_list, pose_error(A, np.eye(4)))
    assert np.array_equal(pose_error(A, np.eye(4), check=False), pose_error(A, np.eye(4)))
