"""Tests of SO(3)/SE(3) hat/vee, exponential, logarithm and left Jacobian."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.linalg import expm
from scipy.spatial.transform import Rotation

from serialkin._checks import readonly
from serialkin.errors import InputError
from serialkin.spatial import kernels as K
from serialkin.spatial import (
    se3_exp,
    se3_log,
    skew,
    so3_exp,
    so3_left_jacobian,
    so3_left_jacobian_inv,
    so3_log,
    unskew,
)

SETTINGS = settings(max_examples=40, deadline=None)
unit3 = st.lists(st.floats(-1, 1), min_size=3, max_size=3).map(np.array).filter(
    lambda v: np.linalg.norm(v) > 1e-2
).map(lambda v: v / np.linalg.norm(v))
# angles that stress both ends of the domain
angles = st.one_of(
    st.floats(0.0, np.pi),
    st.floats(0.0, 1e-3),
    st.floats(np.pi - 1e-3, np.pi),
    st.sampled_from([0.0, 1e-15, 1e-8, 0.05, np.pi - 1e-12, np.pi]),
)
vec3 = st.lists(st.floats(-2, 2), min_size=3, max_size=3).map(np.array)


def test_skew_is_the_cross_product_and_unskew_inverts() -> None:
    """[w]^ v = w × v and unskew(skew(w)) = w, batched."""
    rng = np.random.default_rng(0)
    w, v = rng.normal(size=(2, 7, 3))
    S = skew(w)
    assert S.shape == (7, 3, 3)
    assert np.allclose(np.einsum("...ij,...j->...i", S, v), np.cross(w, v))
    assert np.allclose(S, -np.swapaxes(S, -1, -2))
    assert np.allclose(unskew(S), w)


@SETTINGS
@given(unit3, angles)
def test_so3_exp_matches_matrix_exponential(axis: np.ndarray, th: float) -> None:
    """Rodrigues' closed form (series near 0) equals scipy's expm of [w]^."""
    w = axis * th
    assert np.abs(so3_exp(w) - expm(skew(w))).max() < 1e-14


@SETTINGS
@given(unit3, angles)
def test_so3_log_inverts_exp_including_near_pi(axis: np.ndarray, th: float) -> None:
    """log(exp(w)) = w for |w| ≤ π (±w at exactly π), and exp(log(R)) = R."""
    w = axis * th
    R = so3_exp(w)
    w2 = so3_log(R)
    tol = 1e-12
    if th < np.pi - 1e-7:
        assert np.abs(w2 - w).max() < tol
    else:
        assert min(np.abs(w2 - w).max(), np.abs(w2 + w).max()) < 1e-7
    assert np.linalg.norm(w2) <= np.pi + 1e-15
    assert np.abs(so3_exp(w2) - R).max() < 1e-14


def test_so3_log_matches_scipy_on_random_rotations() -> None:
    """so3_log agrees with scipy's as_rotvec on 500 uniform rotations (batched)."""
    rot = Rotation.random(500, random_state=2)
    W = so3_log(rot.as_matrix().reshape(5, 100, 3, 3))
    assert W.shape == (5, 100, 3)
    assert np.allclose(W.reshape(-1, 3), rot.as_rotvec(), atol=1e-13)


@pytest.mark.parametrize("diag", [[1, -1, -1], [-1, 1, -1], [-1, -1, 1]])
def test_so3_log_of_half_turns(diag: list[int]) -> None:
    """A rotation by exactly π about a coordinate axis has log of norm π along that axis."""
    w = so3_log(np.diag(np.array(diag, dtype=float)))
    assert np.linalg.norm(w) == pytest.approx(np.pi, abs=1e-15)
    assert abs(w[int(np.argmax(diag))]) == pytest.approx(np.pi, abs=1e-15)


def test_so3_log_kernel_direct_call() -> None:
    """The njit kernels so3_log_into and rotation_error_into agree with the wrapper."""
    rot = Rotation.random(2, random_state=5).as_matrix()
    w = np.empty(3)
    K.so3_log_into(rot[0], w)
    assert np.allclose(w, so3_log(rot[0]), atol=1e-15)
    K.rotation_error_into(readonly(rot[0]), readonly(rot[1]), w)  # only read: read-only
    assert np.allclose(w, so3_log(rot[1] @ rot[0].T), atol=1e-14)


@SETTINGS
@given(unit3, angles, vec3)
def test_se3_exp_matches_matrix_exponential_and_log_inverts(
    axis: np.ndarray, th: float, v: np.ndarray
) -> None:
    """The exponential of the twist [v; ω] equals expm of its 4x4 matrix, and se3_log inverts it."""
    xi = np.concatenate([v, axis * th])
    X = np.zeros((4, 4))
    X[:3, :3] = skew(xi[3:])
    X[:3, 3] = v
    T = se3_exp(xi)
    assert np.abs(T - expm(X)).max() < 1e-13
    xi2 = se3_log(T)
    if th < np.pi - 1e-7:
        assert np.abs(xi2 - xi).max() < 1e-11
    assert np.abs(se3_exp(xi2) - T).max() < 1e-12


@SETTINGS
@given(unit3, st.floats(0.0, 3.0), vec3)
def test_left_jacobian_maps_rotation_vector_rate_to_angular_velocity(
    axis: np.ndarray, th: float, wdot: np.ndarray
) -> None:
    """d/dt exp(w) · exp(w)ᵀ = [J_l(w) ẇ]^ (central difference), and J_l · J_l⁻¹ = I."""
    w = axis * th
    h = 1e-6
    dR = (so3_exp(w + h * wdot) - so3_exp(w - h * wdot)) / (2 * h)
    omega = unskew(dR @ so3_exp(w).T, tol=1e-6)
    assert np.allclose(so3_left_jacobian(w) @ wdot, omega, atol=1e-8)
    assert np.allclose(so3_left_jacobian(w) @ so3_left_jacobian_inv(w), np.eye(3), atol=1e-12)


@pytest.mark.parametrize("th", [0.0, 1e-6, 0.049, 0.051, 1.0])
def test_series_and_closed_form_agree_at_the_switch(th: float) -> None:
    """J_l⁻¹ from its series (θ < 0.05) and closed form match the numerical inverse of J_l."""
    w = th * np.array([0.0, 0.6, 0.8])
    assert np.allclose(so3_left_jacobian_inv(w), np.linalg.inv(so3_left_jacobian(w)), atol=1e-14)


def test_lie_bad_input_messages() -> None:
    """Non-skew matrices, wrong twist shapes, non-rotations and |w| ≥ 2π raise clear errors."""
    with pytest.raises(InputError, match="S must be skew-symmetric"):
        unskew(np.eye(3))
    with pytest.raises(InputError, match=r"xi must have shape \(\.\.\., 6\)"):
        se3_exp(np.zeros(3))
    with pytest.raises(InputError, match="R is not orthonormal"):
        so3_log(2 * np.eye(3))
    with pytest.raises(InputError, match="T is not a homogeneous transform"):
        se3_log(np.ones((4, 4)))
    with pytest.raises(InputError, match="norm < 2π"):
        so3_left_jacobian_inv([2 * np.pi, 0, 0])
    with pytest.raises(InputError, match="w must be finite"):
        so3_exp([np.inf, 0, 0])
