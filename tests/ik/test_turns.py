"""IK answers on joints wider than a turn are the 2π-representative nearest q0 (or zero)."""

from __future__ import annotations

import math

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

import serialkin as sk
from serialkin.ik.turns import MAX_TURNS, TOL, nearest_turn, wide_joints

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


def _documented_rule(q, lower, upper, wide, reference):
    """The module docstring's formula with numpy's array operations (the reference)."""
    ref = 0.0 if reference is None else reference
    with np.errstate(invalid="ignore"):
        k = np.rint((ref - q) / TWO_PI)
        k_min = np.ceil((lower - TOL - q) / TWO_PI)
        k_max = np.floor((upper + TOL - q) / TWO_PI)
    k = np.clip(k, k_min, k_max)
    ok = wide & (k_min <= k_max) & (np.abs(k) <= MAX_TURNS)
    return np.where(ok, q + TWO_PI * np.where(ok, k, 0.0), q)


@settings(max_examples=400, deadline=None)
@given(q=st.lists(edge_angles, min_size=1, max_size=7), data=st.data())
def test_compiled_rule_equals_the_documented_formula(q, data):
    """nearest_turn of one row, rows or strided rows is the documented formula, bit for bit."""
    n = len(q)
    lo = -np.array(data.draw(st.lists(bounds, min_size=n, max_size=n)))
    hi = np.array(data.draw(st.lists(bounds, min_size=n, max_size=n)))
    wide = np.array(data.draw(st.lists(st.booleans(), min_size=n, max_size=n)))
    ref = np.array(data.draw(st.lists(edge_angles, min_size=n, max_size=n)))
    rows = np.array([q, ref[::-1], np.array(q)[::-1]])
    cases = [(np.array(q), None), (np.array(q), ref), (rows, None), (rows, ref),
             (rows, rows[::-1].copy()), (rows[:, ::-1], ref)]  # the last one strided
    for x, r in cases:
        got = nearest_turn(x, lo, hi, wide, r)
        want = _documented_rule(x, lo, hi, wide, r)
        assert got.shape == x.shape
        assert np.array_equal(got, want)
        assert np.array_equal(np.signbit(got), np.signbit(want))


def test_half_turn_ties_keep_the_even_turn():
    """Half a turn from the reference keeps the even turn, in nearest_turn and the IK loop."""
    from serialkin.ik import _kernels as K

    lo, hi = np.array([-np.inf, -4 * math.pi]), np.array([np.inf, 4 * math.pi])
    wide = np.array([True, True])
    for q, ref, want in ((0.0, math.pi, 0.0), (0.0, -math.pi, 0.0),
                         (0.0, 5 * math.pi, 4 * math.pi), (0.0, -5 * math.pi, -4 * math.pi)):
        assert (ref - q) / TWO_PI % 1.0 == 0.5  # an exact tie
        q2, r2 = np.array([q, q]), np.array([ref, ref])
        got = nearest_turn(q2, lo, hi, wide, r2)
        assert got[0] == want and got[1] == want
        loop = q2.copy()
        box = np.array([lo, hi, [1.0, 1.0]])  # read-only rows, as the solver's limit box
        box.setflags(write=False)
        K.nearest_into(loop, r2, box[0], box[1], box[2], True)
        assert np.array_equal(loop, got)


@settings(max_examples=300, deadline=None)
@given(q=angles, ref=st.floats(-200.0, 200.0), lo=st.floats(-15.0, 0.0),
       width=st.sampled_from([1.0, math.pi, TWO_PI, 7.0, 12.0, 30.0, math.inf]),
       bounded=st.booleans())
def test_ik_loop_applies_the_same_rule(q, ref, lo, width, bounded):
    """The IK loop's nearest_into is nearest_turn on its wide joints (all, if limits are off)."""
    from serialkin.ik import _kernels as K

    hi = lo + width
    q = min(max(q, lo), hi) if bounded else q
    lower, upper = np.array([lo, lo]), np.array([hi, hi])
    box = np.array([lower, upper, [1.0, 0.0]])  # read-only rows, as the solver's limit box
    box.setflags(write=False)
    loop = np.array([q, q])
    K.nearest_into(loop, np.array([ref, ref]), box[0], box[1], box[2], bounded)
    if bounded:
        wide = wide_joints(lower, upper, np.array([True, False]))
        want = nearest_turn(np.array([q, q]), lower, upper, wide, np.array([ref, ref]))
    else:
        want = nearest_turn(np.array([q, q]), np.full(2, -np.inf), np.full(2, np.inf),
                            np.array([True, False]), np.array([ref, ref]))
    assert np.array_equal(loop, want)
    assert loop[1] == q  # prismatic: never moved
