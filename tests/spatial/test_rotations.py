"""Tests of the orientation representations (rpy, ZYZ, axis-angle, quaternion)."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import assume, given, settings
from hypothesis import strategies as st
from scipy.spatial.transform import Rotation

from serialkin.errors import InputError, InputTypeError
from serialkin.spatial import (
    axis_angle_to_matrix,
    matrix_to_axis_angle,
    matrix_to_quaternion,
    matrix_to_rpy,
    matrix_to_zyz,
    quaternion_multiply,
    quaternion_to_matrix,
    rotx,
    roty,
    rotz,
    rpy_to_matrix,
    wrap_angle,
    zyz_to_matrix,
)

SETTINGS = settings(max_examples=40, deadline=None)
angle = st.floats(-np.pi, np.pi, allow_nan=False)
tiny = st.floats(-1e-6, 1e-6, allow_nan=False)


@st.composite
def unit_quaternions(draw: st.DrawFn) -> np.ndarray:
    """Random unit quaternions (normalised 4-vectors away from zero)."""
    v = np.array(draw(st.lists(st.floats(-1, 1), min_size=4, max_size=4)))
    if np.linalg.norm(v) < 1e-3:
        v = np.array([1.0, 0.0, 0.0, 0.0])
    return v / np.linalg.norm(v)


def rotations(n: int, seed: int = 0) -> np.ndarray:
    """Uniform random rotations from scipy (an independent generator)."""
    return Rotation.random(n, random_state=seed).as_matrix()


def angle_diff(a: np.ndarray, b: np.ndarray) -> float:
    """Largest wrapped difference between two angle arrays."""
    return float(np.abs(wrap_angle(np.asarray(a) - np.asarray(b))).max())


# ----------------------------------------------------------------------------- chapter eqs 4-7
def test_elementary_rotations_match_chapter_eqs_4_to_6() -> None:
    """rotx/roty/rotz equal the matrices printed as eqs 4, 5 and 6."""
    a = 0.7
    c, s = np.cos(a), np.sin(a)
    assert np.allclose(rotx(a), [[1, 0, 0], [0, c, -s], [0, s, c]])
    assert np.allclose(roty(a), [[c, 0, s], [0, 1, 0], [-s, 0, c]])
    assert np.allclose(rotz(a), [[c, -s, 0], [s, c, 0], [0, 0, 1]])


@SETTINGS
@given(angle, angle, angle)
def test_composed_rotations_are_orthonormal_eq_7(r: float, p: float, y: float) -> None:
    """Every rpy/ZYZ composition satisfies RᵀR = I (eq 7) and det R = +1."""
    for R in (rpy_to_matrix([r, p, y]), zyz_to_matrix([r, p, y])):
        assert np.allclose(R.T @ R, np.eye(3), atol=1e-14)
        assert np.linalg.det(R) == pytest.approx(1.0, abs=1e-14)


# ----------------------------------------------------------------------------- roll-pitch-yaw
@SETTINGS
@given(angle, st.floats(-np.pi / 2 + 1e-6, np.pi / 2 - 1e-6), angle)
def test_rpy_matches_scipy_and_round_trips(r: float, p: float, y: float) -> None:
    """rpy_to_matrix is Rz(yaw)Ry(pitch)Rx(roll) (scipy extrinsic 'xyz') and inverts exactly."""
    R = rpy_to_matrix([r, p, y])
    assert np.allclose(R, Rotation.from_euler("xyz", [r, p, y]).as_matrix(), atol=1e-14)
    assert np.allclose(R, rotz(y) @ roty(p) @ rotx(r), atol=1e-15)
    assert angle_diff(matrix_to_rpy(R), [r, p, y]) < 1e-8


@SETTINGS
@given(angle, st.sampled_from([-1.0, 1.0]), tiny, angle)
def test_rpy_round_trip_at_gimbal_lock(r: float, sign: float, eps: float, y: float) -> None:
    """R → rpy → R is exact to rounding at and next to pitch = ±π/2."""
    R = rpy_to_matrix([r, sign * np.pi / 2 + eps, y])
    rpy = matrix_to_rpy(R)
    assert abs(rpy[1]) <= np.pi / 2
    assert np.abs(rpy_to_matrix(rpy) - R).max() < 1e-13


def test_rpy_gimbal_lock_convention() -> None:
    """At pitch = ±π/2 yaw is set to 0 and roll carries roll ∓ yaw."""
    up = matrix_to_rpy(rpy_to_matrix([0.5, np.pi / 2, 0.2]))
    down = matrix_to_rpy(rpy_to_matrix([0.5, -np.pi / 2, 0.2]))
    assert np.allclose(up, [0.3, np.pi / 2, 0.0])
    assert np.allclose(down, [0.7, -np.pi / 2, 0.0])


def test_rpy_random_rotations_round_trip_batched() -> None:
    """A (10, 20, 3, 3) batch converts with shape (10, 20, 3) and reconstructs R."""
    R = rotations(200, seed=1).reshape(10, 20, 3, 3)
    rpy = matrix_to_rpy(R)
    assert rpy.shape == (10, 20, 3)
    assert np.abs(rpy_to_matrix(rpy) - R).max() < 1e-14
    ref = Rotation.from_matrix(R.reshape(-1, 3, 3)).as_euler("xyz").reshape(10, 20, 3)
    assert angle_diff(rpy, ref) < 1e-12


# ----------------------------------------------------------------------------- ZYZ
@SETTINGS
@given(angle, st.floats(1e-6, np.pi - 1e-6), angle)
def test_zyz_matches_scipy_and_round_trips(f: float, t: float, s: float) -> None:
    """zyz_to_matrix is Rz(phi)Ry(theta)Rz(psi) (scipy intrinsic 'ZYZ') and inverts exactly."""
    R = zyz_to_matrix([f, t, s])
    assert np.allclose(R, Rotation.from_euler("ZYZ", [f, t, s]).as_matrix(), atol=1e-14)
    assert angle_diff(matrix_to_zyz(R), [f, t, s]) < 1e-8


@SETTINGS
@given(angle, st.sampled_from([0.0, np.pi]), tiny, angle)
def test_zyz_round_trip_near_theta_0_and_pi(f: float, t0: float, eps: float, s: float) -> None:
    """R → ZYZ → R is exact to rounding at and next to theta = 0 and theta = π."""
    R = zyz_to_matrix([f, t0 + eps, s])
    zyz = matrix_to_zyz(R)
    assert 0.0 <= zyz[1] <= np.pi
    assert np.abs(zyz_to_matrix(zyz) - R).max() < 1e-13


def test_zyz_singular_convention() -> None:
    """At theta = 0 phi is 0 and psi carries phi + psi."""
    zyz = matrix_to_zyz(zyz_to_matrix([0.4, 0.0, 0.5]))
    assert np.allclose(zyz, [0.0, 0.0, 0.9])


# ----------------------------------------------------------------------------- axis-angle
@SETTINGS
@given(unit_quaternions(), st.floats(0.0, np.pi))
def test_axis_angle_matches_scipy_and_round_trips(qv: np.ndarray, th: float) -> None:
    """axis_angle_to_matrix equals scipy's rotvec, and the inverse recovers (axis, angle)."""
    axis = qv[1:] / np.linalg.norm(qv[1:]) if np.linalg.norm(qv[1:]) > 1e-3 else np.eye(3)[0]
    R = axis_angle_to_matrix(axis, th)
    assert np.allclose(R, Rotation.from_rotvec(axis * th).as_matrix(), atol=1e-14)
    ax2, th2 = matrix_to_axis_angle(R)
    assert th2 == pytest.approx(th, abs=1e-9)
    if 1e-6 < th < np.pi - 1e-6:
        assert np.allclose(ax2, axis, atol=1e-9)
    assert np.abs(axis_angle_to_matrix(ax2, th2) - R).max() < 1e-14


def test_axis_angle_of_a_tiny_rotation_has_a_unit_axis() -> None:
    """Angles whose squared components underflow (< 1e-154) still give a unit axis."""
    for th in (8.134142396155163e-162, 1e-300, 5e-324):
        R = axis_angle_to_matrix(np.array([0.6, 0.0, 0.8]), th)
        ax, th2 = matrix_to_axis_angle(R)
        assert abs(np.linalg.norm(ax) - 1.0) < 1e-15
        assert np.abs(axis_angle_to_matrix(ax, th2) - R).max() < 1e-14


@pytest.mark.parametrize("th", [0.0, 1e-14, 1e-9, 1e-4, np.pi - 1e-4, np.pi - 1e-9, np.pi])
def test_axis_angle_near_0_and_pi(th: float) -> None:
    """Angles near 0 and π come back accurately (the axis up to sign at exactly π)."""
    axis = np.array([2.0, -1.0, 2.0]) / 3.0
    ax2, th2 = matrix_to_axis_angle(axis_angle_to_matrix(axis, th))
    assert th2 == pytest.approx(th, abs=1e-15 + 1e-12 * th)
    if th == 0.0:
        assert np.allclose(ax2, [0, 0, 1])
    elif th > 1e-6:
        assert min(np.abs(ax2 - axis).max(), np.abs(ax2 + axis).max()) < 1e-8
        if th < np.pi - 1e-6:
            assert np.allclose(ax2, axis, atol=1e-8)


def test_axis_angle_broadcasts() -> None:
    """One axis with five angles gives five rotations."""
    R = axis_angle_to_matrix([0, 0, 1], np.linspace(0, 1, 5))
    assert R.shape == (5, 3, 3)
    assert np.allclose(R[-1], rotz(1.0))


# ----------------------------------------------------------------------------- quaternion
@SETTINGS
@given(unit_quaternions())
def test_quaternion_matches_scipy_and_round_trips(q: np.ndarray) -> None:
    """quaternion_to_matrix agrees with scipy (scalar first); R → q gives back ±q with w ≥ 0."""
    R = quaternion_to_matrix(q)
    assert np.allclose(R, Rotation.from_quat(q, scalar_first=True).as_matrix(), atol=1e-14)
    q2 = matrix_to_quaternion(R)
    assert q2[0] >= 0.0
    assert np.linalg.norm(q2) == pytest.approx(1.0, abs=1e-15)
    assert min(np.abs(q2 - q).max(), np.abs(q2 + q).max()) < 1e-12


@pytest.mark.parametrize("th", [0.0, 1e-12, np.pi - 1e-12, np.pi])
@pytest.mark.parametrize("axis", [[1, 0, 0], [0, 1, 0], [0, 0, 1], [0.6, 0, -0.8]])
def test_quaternion_at_angle_0_and_pi(th: float, axis: list[float]) -> None:
    """Shepperd's branch choice keeps R → q → R exact at angle 0 and π for every axis."""
    R = axis_angle_to_matrix(axis, th)
    q = matrix_to_quaternion(R)
    assert np.abs(quaternion_to_matrix(q) - R).max() < 1e-14
    assert abs(q[0] - np.cos(th / 2)) < 1e-12


def test_quaternion_batch_and_multiply() -> None:
    """Batched conversion matches scipy, and R(q1 ⊗ q2) = R(q1) R(q2)."""
    R = rotations(100, seed=3).reshape(4, 25, 3, 3)
    q = matrix_to_quaternion(R)
    assert q.shape == (4, 25, 4)
    ref = Rotation.from_matrix(R.reshape(-1, 3, 3)).as_quat(scalar_first=True)
    ref *= np.sign(ref[:, :1])
    assert np.allclose(q.reshape(-1, 4), ref, atol=1e-14)
    q1, q2 = q[0], q[1]
    assert np.allclose(quaternion_to_matrix(quaternion_multiply(q1, q2)), R[0] @ R[1], atol=1e-14)


# ----------------------------------------------------------------------------- bad input
def test_non_unit_quaternion_policy() -> None:
    """A non-unit quaternion is rejected naming its norm, accepted with normalize=True."""
    with pytest.raises(InputError, match=r"q must have unit norm.*got norm 2.*normalize=True"):
        quaternion_to_matrix([2.0, 0, 0, 0])
    assert np.allclose(quaternion_to_matrix([2.0, 0, 0, 0], normalize=True), np.eye(3))
    with pytest.raises(InputError, match="q must be non-zero"):
        quaternion_to_matrix([0.0, 0, 0, 0], normalize=True)
    with pytest.raises(InputError, match="axis must have unit norm"):
        axis_angle_to_matrix([1.0, 1.0, 0.0], 0.3)
    assert np.allclose(axis_angle_to_matrix([0, 0, 5.0], 0.3, normalize=True), rotz(0.3))


def test_bad_rotation_matrix_messages() -> None:
    """Non-orthonormal, reflected, wrongly shaped and NaN matrices raise naming R."""
    with pytest.raises(InputError, match="R is not orthonormal"):
        matrix_to_rpy(np.diag([1.0, 2.0, 1.0]))
    with pytest.raises(InputError, match="det R = -1"):
        matrix_to_quaternion(np.diag([1.0, 1.0, -1.0]))
    with pytest.raises(InputError, match=r"R must have shape \(\.\.\., 3, 3\).*got shape \(4, 4\)"):
        matrix_to_zyz(np.eye(4))
    bad = np.eye(3)
    bad[0, 1] = np.nan
    with pytest.raises(InputError, match="R must be finite"):
        matrix_to_axis_angle(bad)


def test_bad_angle_input_messages() -> None:
    """Angle vectors of the wrong length, strings and NaN raise naming the argument."""
    with pytest.raises(InputError, match=r"rpy must have shape \(\.\.\., 3\).*got shape \(2,\)"):
        rpy_to_matrix([0.1, 0.2])
    with pytest.raises(InputTypeError, match="zyz must be an array of real numbers"):
        zyz_to_matrix(["a", "b", "c"])
    with pytest.raises(InputError, match="angle must be finite"):
        axis_angle_to_matrix([0, 0, 1], np.nan)
    with pytest.raises(InputError, match=r"q must have shape \(\.\.\., 4\)"):
        quaternion_to_matrix([1.0, 0, 0])


def test_wrap_angle_interval() -> None:
    """wrap_angle maps to (−π, π] and keeps values already inside."""
    w = wrap_angle([-np.pi, np.pi, 3 * np.pi, 0.5, -7.0])
    assert np.allclose(w, [np.pi, np.pi, np.pi, 0.5, -7.0 + 2 * np.pi])
    assert np.all((w > -np.pi) & (w <= np.pi))


@settings(max_examples=60, deadline=None)
@given(v=st.lists(st.floats(-1.0, 1.0), min_size=3, max_size=3))
def test_perpendicular_is_a_unit_normal(v):
    """perpendicular(e) is a unit vector with e · v = 0, for one vector and for a batch."""
    from serialkin.spatial import perpendicular

    e = np.array(v)
    assume(np.linalg.norm(e) > 1e-3)
    e = e / np.linalg.norm(e)
    p = perpendicular(e)
    assert p.shape == (3,)
    assert abs(np.linalg.norm(p) - 1.0) < 1e-14 and abs(p @ e) < 1e-14
    batch = perpendicular(np.stack([e, -e, np.eye(3)[1]]))
    assert batch.shape == (3, 3) and np.allclose(batch[0], p, rtol=0, atol=0)
    assert np.allclose(np.einsum("ij,ij->i", batch, [e, -e, np.eye(3)[1]]), 0.0, atol=1e-14)
