"""The blocked batch FK kernel and its vectorised sin/cos agree with libm and the single path."""

from __future__ import annotations

import re

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from numba import njit

import serialkin as sk
from serialkin.errors import InputError
from serialkin.kinematics import kernels as K
from serialkin.kinematics import parallel
from serialkin.model.chain import z_alignment
from serialkin.model.dh import link_transform, parse_dh_rows
from tests.kinematics._fd import dh_rows, random_transform


@njit(cache=True)
def _sincos_array(x, s, c):
    for i in range(x.shape[0]):
        s[i], c[i] = K._sincos(x[i])


def test_sincos_matches_libm():
    """The polynomial sin/cos is within 2e-16 of numpy's on [-1e5, 1e5], quadrant edges included."""
    rng = np.random.default_rng(0)
    edges = np.pi / 4 * np.arange(-400, 401)
    x = np.concatenate([rng.uniform(-60, 60, 200_000), rng.uniform(-1e5, 1e5, 50_000), edges,
                        np.nextafter(edges, np.inf), [0.0, -0.0, 1e-300]])
    s, c = np.empty_like(x), np.empty_like(x)
    _sincos_array(x, s, c)
    assert np.abs(s - np.sin(x)).max() < 2e-16
    assert np.abs(c - np.cos(x)).max() < 2e-16


@pytest.mark.parametrize("name", ["panda", "ur5", "stanford", "scara"])
def test_batch_equals_single(name):
    """Batch poses (blocked, vectorised) equal the single-configuration kernel to 1e-14."""
    robot = sk.models.get(name)
    Q = robot.random_q(1000, seed=3)  # >= the parallel threshold, not a multiple of the block
    batch = robot.fk(Q)
    single = np.stack([robot.fk(q) for q in Q])
    np.testing.assert_allclose(batch, single, atol=1e-14)


def test_huge_angles_fall_back_to_libm():
    """Joint values beyond 1e5 rad still give exact poses (libm fallback inside the block)."""
    robot = sk.models.get("ur5")
    Q = robot.random_q(600, seed=1)
    Q[5, 2] = 3e7
    Q[400, 0] = -1e9
    np.testing.assert_allclose(robot.fk(Q), np.stack([robot.fk(q) for q in Q]), atol=1e-12)


@settings(max_examples=60, deadline=None)
@given(st.lists(st.floats(-1, 1), min_size=3, max_size=3).filter(
    lambda v: np.linalg.norm(v) > 1e-3))
def test_z_alignment_is_a_rotation_onto_the_axis(v):
    """z_alignment(k) is a proper rotation with R·e_z = k, for any direction (±z included)."""
    k = np.asarray(v) / np.linalg.norm(v)
    R = z_alignment(k)
    np.testing.assert_allclose(R @ [0, 0, 1], k, atol=1e-15)
    np.testing.assert_allclose(R.T @ R, np.eye(3), atol=1e-15)
    assert abs(np.linalg.det(R) - 1) < 1e-14


def test_general_axes_compile_to_z():
    """Robots with arbitrary joint axes compile to z axes and keep their FK and link frames."""
    rng = np.random.default_rng(4)
    joints = [sk.Joint(axis=a, type=t, origin=sk.spatial.transl(*rng.normal(size=3)),
                       post=sk.spatial.trotx(rng.normal()))
              for a, t in zip(rng.normal(size=(5, 3)), "RPRRR")]
    joints.append(sk.Joint(axis=[0, 0, -1.0]))
    robot = sk.Robot.from_joints(joints)
    assert np.all(robot.chain.meta[:, :3] == [0.0, 0.0, 1.0])
    q = robot.random_q(seed=2)
    T = np.eye(4)
    frames = [T]
    for j, qi in zip(joints, q):
        x = qi + j.offset
        if j.type == "R":
            from scipy.spatial.transform import Rotation

            M = sk.spatial.make_transform(Rotation.from_rotvec(j.axis * x).as_matrix())
        else:
            M = sk.spatial.make_transform(p=j.axis * x)
        T = T @ j.origin @ M @ j.post
        frames.append(T)
    np.testing.assert_allclose(robot.fk_all(q), np.stack(frames), atol=1e-12)
    np.testing.assert_allclose(robot.fk(q), frames[-1], atol=1e-12)


@settings(max_examples=25, deadline=None)
@given(rows=dh_rows(min_joints=1, max_joints=14), seed=st.integers(0, 2**32 - 1),
       huge=st.booleans())
def test_single_calls_match_link_products_on_long_chains(rows, seed, huge):
    """Single-call fk/jacobian on 1-14 joints (huge angles too) equal link products and batches."""
    rng = np.random.default_rng(seed)
    robot = sk.Robot.from_dh(rows, "standard", base=random_transform(rng),
                             tool=random_transform(rng))
    q = robot.random_q(seed=rng)
    if huge:
        q[int(rng.integers(robot.n))] = 3e6 * rng.choice([-1.0, 1.0])
    T = robot.base.copy()
    for i, row in enumerate(parse_dh_rows(rows)):
        T = T @ link_transform(row, q[i], "standard")
    T = T @ robot.tool
    np.testing.assert_allclose(robot.fk(q), T, atol=1e-9)
    Q = np.stack([q, q])
    np.testing.assert_allclose(robot.fk(q), robot.fk(Q)[1], atol=1e-12)
    np.testing.assert_allclose(robot.jacobian(q), robot.jacobian(Q)[1], atol=1e-12)


@pytest.mark.parametrize("name", ["ur5", "scara"])
@pytest.mark.parametrize("where", [0, 63, 64, 2047, 4999])
@pytest.mark.parametrize("value", [np.nan, np.inf, -np.inf])
def test_batch_nonfinite_q_raises_the_checked_error(name, where, value, monkeypatch):
    """A NaN/inf anywhere in a batch (any block, chunk, joint kind) raises check_q's InputError."""
    monkeypatch.setattr(parallel, "free_cores", lambda: 64)  # the threaded path too
    robot = sk.models.get(name)
    Q = robot.random_q(5000, seed=5)
    Q[where, where % robot.n] = value
    for shaped in (Q, Q.reshape(50, 100, robot.n)):
        with pytest.raises(InputError, match="q must be finite") as expected:
            robot.check_q(shaped)
        with pytest.raises(InputError) as got:
            robot.fk(shaped, out=np.empty(shaped.shape[:-1] + (4, 4)))
        assert str(got.value) == str(expected.value)
    with pytest.raises(InputError, match=re.escape(f"got {value} at index ({where}, ")):
        robot.fk(Q)


def test_checked_range_flags_only_nonfinite_values():
    """fk_checked_range sets its flag for NaN/inf, not for huge finite q, and equals fk_range."""
    robot = sk.models.get("scara")  # revolute and prismatic joints
    Q = robot.random_q(300, seed=6)
    Q[7, 0], Q[8, 2] = 1e300, -1e300
    c = robot.chain
    T1, T2, bad = np.empty((300, 4, 4)), np.empty((300, 4, 4)), np.zeros(1, dtype=np.int64)
    K.fk_range(Q, c.F, c.meta, T1, 0, 300)
    K.fk_checked_range(Q, c.F, c.meta, T2, bad, 0, 300)
    assert bad[0] == 0 and np.array_equal(T1, T2, equal_nan=True)
    Q[299, 3] = np.nan
    K.fk_checked_range(Q, c.F, c.meta, T2, bad, 0, 299)
    assert bad[0] == 0  # outside the range
    K.fk_checked_range(Q, c.F, c.meta, T2, bad, 299, 300)
    assert bad[0] == 1


@pytest.mark.parametrize("where", [0, 1999])
@pytest.mark.parametrize("value", [np.nan, np.inf])
def test_jacobian_and_link_frame_batches_raise_the_checked_error(where, value, monkeypatch):
    """A NaN/inf in a jacobian, fk_all or hessian batch raises check_q's error."""
    monkeypatch.setattr(parallel, "free_cores", lambda: 64)  # the threaded path too
    robot = sk.models.get("scara")  # revolute and prismatic joints
    Q = robot.random_q(2000, seed=7)
    Q[where, where % robot.n] = value
    with pytest.raises(InputError, match="q must be finite") as expected:
        robot.check_q(Q)
    calls = [lambda: robot.jacobian(Q), lambda: robot.jacobian(Q, "ee"),
             lambda: robot.jacobian(Q, link=2, point=[0.1, 0.0, 0.0]),
             lambda: robot.jacobian(Q, out=np.empty((2000, 6, robot.n))),
             lambda: robot.fk_all(Q), lambda: robot.hessian(Q)]
    for call in calls:
        with pytest.raises(InputError) as got:
            call()
        assert str(got.value) == str(expected.value)


def test_range_kernels_flag_only_nonfinite_rows():
    """jacobian/point_jacobian/fk_all ranges flag NaN rows (NaN output), not huge finite q."""
    robot = sk.models.get("scara")
    c = robot.chain
    n = robot.n
    Q = robot.random_q(40, seed=8)
    Q[3, 0], Q[4, 2] = 1e300, -1e300
    J, T, P = np.empty((40, 6, n)), np.empty((40, 4, 4)), np.empty((40, 3))
    A = np.empty((40, n + 1, 4, 4))
    pt = np.array([0.1, 0.0, 0.0])
    for k in range(2):
        bad = np.zeros(1, dtype=np.int64)
        K.jacobian_range(Q, c.F, c.meta, J, T, bad, 0, 40)
        K.point_jacobian_range(Q, c.F, c.L, c.meta, 2, pt, J, P, bad, 0, 40)
        K.fk_all_range(Q, c.F, c.L, c.meta, A, bad, 0, 40)
        if k == 0:
            assert bad[0] == 0
            Q[39, 1] = np.nan
        else:
            assert bad[0] == 1
            assert np.isnan(J[39]).all() and np.isnan(P[39]).all() and np.isnan(A[39]).all()
            assert np.isfinite(J[:39]).all() and np.isfinite(A[:3]).all()


def test_batch_jacobian_out_is_written_in_place():
    """jacobian(Q, out=J) in the base frame fills the caller's buffer itself (views too)."""
    robot = sk.models.get("ur5")
    Q = robot.random_q((3, 5), seed=9)
    expected = robot.jacobian(Q)
    big = np.zeros((2, 3, 5, 6, robot.n))
    view = big[1]  # a C-contiguous view: its base is big
    assert robot.jacobian(Q, out=view) is view
    assert np.array_equal(big[1], expected) and not big[0].any()
    E = np.empty((3, 5, 6, robot.n))
    assert robot.jacobian(Q, "ee", out=E) is E
    np.testing.assert_array_equal(E, robot.jacobian(Q, "ee"))
