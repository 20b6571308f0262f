"""IK answers on joints wider than a turn are the 2π-representative nearest q0 (or zero)."""

from __future__ import annotations

import math

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

import serialkin as sk
from serialkin.ik.turns import TOL, nearest_turn, wide_joints

TWO_PI = 2 * math.pi
angles = st.floats(-20.0, 20.0, allow_nan=False)


@settings(max_examples=300, deadline=None)
@given(q=angles, ref=angles, lo=st.floats(-15.0, 0.0), width=st.floats(0.0, 30.0))
def test_nearest_turn_is_the_nearest_equivalent_inside_the_limits(q, ref, lo, width):
    """The result is q + 2πk inside the limits, and no other such value is nearer ref."""
    hi = lo + width
    if not lo - TOL <= q <= hi + TOL:  # the solver's answers respect the limits
        q = min(max(q, lo), hi)
    wide = wide_joints(np.array([lo]), np.array([hi]), np.array([True]))
    out = float(nearest_turn(np.array([q]), np.array([lo]), np.array([hi]), wide,
                             np.array([ref]))[0])
    k = (out - q) / TWO_PI
    assert abs(k - round(k)) < 1e-9
    assert lo - 1e-9 <= out <= hi + 1e-9
    if width <= TWO_PI:
        assert out == q, "a joint of at most one turn never moves"
    for j in range(-8, 9):  # every other equivalent inside the limits is farther
        c = q + TWO_PI * j
        if lo - TOL <= c <= hi + TOL:
            assert abs(out - ref) <= abs(c - ref) + 1e-9


def test_unlimited_and_prismatic_joints():
    """An unlimited revolute joint lands within π of the reference; prismatic joints stay."""
    lo, hi = np.array([-np.inf, -10.0]), np.array([np.inf, 10.0])
    wide = wide_joints(lo, hi, np.array([True, False]))
    out = nearest_turn(np.array([[7.0, 7.0], [-9.5, -9.5]]), lo, hi, wide)
    np.testing.assert_allclose(out, [[7.0 - TWO_PI, 7.0], [-9.5 + 2 * TWO_PI, -9.5]])


def test_ur5_ik_without_q0_is_nearest_zero():
    """UR5 (±2π joints) IK without q0 gives every joint in [-π, π], reaching the target."""
    r = sk.models.ur5()
    Q = r.random_q(12, seed=7)
    for k, q in enumerate(Q):
        T = r.fk(q)
        res = r.ik(T, seed=k)
        assert res.success
        assert np.all(np.abs(res.q) <= math.pi + 1e-9), res.q
        np.testing.assert_allclose(r.fk(res.q), T, atol=1e-8)


def test_ur5_ik_with_q0_is_nearest_q0():
    """With q0 a turn away on joints 1 and 6, the answer follows q0 (within π of it)."""
    r = sk.models.ur5()
    q = np.array([-2.0, -1.2, 1.3, -0.6, 1.1, 2.5])
    q0 = q + np.array([TWO_PI, 0, 0, 0, 0, -TWO_PI]) + 0.05
    res = r.ik(r.fk(q), q0=q0)
    assert res.success
    assert np.all(np.abs(res.q - q0) <= math.pi + 1e-9), res.q - q0
    batch = r.ik(np.stack([r.fk(q)] * 3), q0=q0)
    assert np.all(np.abs(batch.q - q0) <= math.pi + 1e-9)


def test_ordinary_and_fast_paths_agree():
    """The fast path and the ordinary path (an explicit tol) give the same representative."""
    r = sk.models.ur5()
    T = r.fk(np.array([2.5, -2.0, 2.2, 1.0, -2.0, 3.0]))
    a = r.ik(T, seed=3)
    b = sk.ik.solve(r, T, seed=3, tol=sk.ik.DEFAULT_TOL)
    np.testing.assert_allclose(a.q, b.q, atol=1e-9)
    assert np.all(np.abs(a.q) <= math.pi + 1e-9)


def test_far_values_keep_their_turns():
    """A value over MAX_TURNS turns from its representative is kept (rounding moves the pose)."""
    from serialkin.ik.turns import MAX_TURNS, nearest_turn

    lower, upper, wide = np.array([-np.inf]), np.array([np.inf]), np.array([True])
    near = 3.0 + 2 * np.pi * MAX_TURNS
    assert abs(nearest_turn(np.array([near]), lower, upper, wide)[0] - 3.0) < 1e-12
    far = np.array([8.9e9])
    assert nearest_turn(far, lower, upper, wide)[0] == far[0]


edge_angles = st.one_of(angles, st.sampled_from([0.0, -0.0, math.pi, -math.pi, TWO_PI, -TWO_PI,
                                                 3 * math.pi, 1e6, -1e6]))
bounds = st.sampled_from([math.inf, TWO_PI, math.pi, 10.0, 3.0, 0.0, 1e-13, 4 * math.pi])


@settings(max_examples=400, deadline=None)
@given(q=st.lists(edge_angles, min_size=1, max_size=7), data=st.data())
def test_one_configuration_equals_the_array_rule(q, data):
    """One configuration (joint by joint) gets the array rule's values, zero signs included."""
    n = len(q)
    lo = -np.array(data.draw(st.lists(bounds, min_size=n, max_size=n)))
    hi = np.array(data.draw(st.lists(bounds, min_size=n, max_size=n)))
    wide = np.array(data.draw(st.lists(st.booleans(), min_size=n, max_size=n)))
    refs = [None, np.array(data.draw(st.lists(edge_angles, min_size=n, max_size=n)))]
    for ref in refs:
        one = nearest_turn(np.array(q), lo, hi, wide, ref)
        rows = nearest_turn(np.array([q]), lo, hi, wide, None if ref is None else ref[None])[0]
        assert one.shape == (n,)
        assert np.array_equal(one, rows)
        assert np.array_equal(np.signbit(one), np.signbit(rows))
