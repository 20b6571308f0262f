"""Hostile input to the public API (issue 10): a clear serialkin error or a correct result."""

from __future__ import annotations

import collections
import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import serialkin as sk
from serialkin._budget import memory_budget, parse_size, set_memory_budget
from serialkin._checks import MAX_ITERATIONS, MAX_JOINTS, short_repr
from serialkin.errors import (
    BudgetError,
    InputError,
    InputTypeError,
    RobotDefinitionError,
    SerialkinError,
)
from serialkin.formats.robotfile import load_robot_file
from serialkin.ik.solver import MAX_RESTARTS
from serialkin.model import limits as L
from serialkin.model.joint import Joint


def _alias_bomb(depth: int = 30, width: int = 9) -> list:
    """A list whose items are the same list, ``depth`` times: width**depth leaves if expanded."""
    a: list = ["lol"] * width
    for _ in range(depth):
        a = [a] * width
    return a


@pytest.mark.parametrize(
    "value",
    [
        _alias_bomb(),
        {str(i): i for i in range(200_000)},
        collections.OrderedDict((i, i) for i in range(200_000)),
        10**100_000,
        "x" * 1_000_000,
        np.zeros((2000, 2000)),
        range(10**12),
    ],
    ids=["alias-bomb", "big-dict", "ordered-dict", "huge-int", "long-str", "array", "range"],
)
def test_short_repr_bounded(value):
    """short_repr of a huge or alias-expanded value is at most `limit` characters."""
    for limit in (20, 80, 200):
        assert len(short_repr(value, limit)) <= limit


@given(st.recursive(st.none() | st.booleans() | st.integers() | st.floats() | st.text(),
                    lambda c: st.lists(c) | st.dictionaries(st.text(), c), max_leaves=30))
def test_short_repr_small_values_exact(value):
    """short_repr is at most 80 characters and, when nothing was cut, equals repr."""
    text = short_repr(value, 80)
    assert len(text) <= 80
    full = repr(value)
    if "..." not in text:
        assert text == full


# ---------------------------------------------------------------- limits as intervals
ROW = dict(a=0.5, alpha=0.0, d=0.0, theta=0.0)


def _one_sided_arm(qlim=(-np.inf, 1.0)):
    return sk.Robot.from_dh([dict(ROW, qlim=qlim), dict(ROW, qlim=qlim)])


@pytest.mark.parametrize("method", sorted(sk.ik.available_methods()))
def test_one_sided_limits_every_ik_method(method):
    """Every IK method: a success with qlim=(-inf, 1) has q <= 1 and reaches the target."""
    r = _one_sided_arm()
    for target, seed in (([0.6, 0.4], 0), ([0.6, 0.4], 3), ([0.2, -0.7], 1), ([-0.5, 0.5], 2)):
        res = r.ik(target, method=method, seed=seed)
        assert np.all(np.asarray(res.q) <= 1.0 + 1e-12), (method, res)
        if res.success:
            np.testing.assert_allclose(r.fk(res.q)[:2, 3], target, atol=1e-6)
            assert r.within_limits(res.q)


@pytest.mark.parametrize("qlim", [(-np.inf, 1.0), (-1.0, np.inf), (2.0, np.inf),
                                  (-np.inf, -2.5)])
def test_one_sided_limits_batch_and_python_paths(qlim):
    """Batch IK and q0-started IK keep every returned q inside a one-sided interval."""
    r = _one_sided_arm(qlim)
    targets = np.array([[0.6, 0.4], [0.9, 0.1], [-0.3, 0.6], [0.0, -0.8]])
    res = r.ik(targets, seed=4)
    lo, hi = qlim
    q = np.asarray(res.q)
    assert np.all((q >= lo - 1e-12) & (q <= hi + 1e-12))
    for k in np.flatnonzero(res.success):
        np.testing.assert_allclose(r.fk(q[k])[:2, 3], targets[k], atol=1e-6)


def test_robot_file_null_limit(tmp_path):
    """A robot file with qlim: [null, 60] (degrees) never yields a success above 60°."""
    p = tmp_path / "arm.yaml"
    p.write_text("name: arm\nunits: {angle: deg}\ndh:\n"
                 "  - {a: 0.5, alpha: 0, d: 0, theta: 0, qlim: [null, 60]}\n"
                 "  - {a: 0.5, alpha: 0, d: 0, theta: 0, qlim: [null, 60]}\n")
    r = load_robot_file(p)
    assert r.qlim[0, 0] == -np.inf and r.qlim[0, 1] == pytest.approx(np.radians(60))
    for seed in range(4):
        res = r.ik([0.6, 0.4], seed=seed)
        assert np.all(res.q <= np.radians(60) + 1e-12)


@given(lo=st.one_of(st.just(-np.inf), st.floats(-20, 20)), width=st.floats(0, 30),
       open_hi=st.booleans(), x=st.floats(-1e3, 1e3))
def test_interval_helpers(lo, width, open_hi, x):
    """wrap/project/normalize land inside [lo, hi] and keep the angle modulo 2π."""
    hi = np.inf if open_hi else (lo + width if math.isfinite(lo) else 20.0 - width)
    if lo == -np.inf and hi == np.inf:
        hi = 5.0
    w = L.wrap_into(x, lo, hi)
    if not math.isnan(w):
        assert lo <= w <= hi
        assert math.isclose(math.cos(w), math.cos(x), abs_tol=1e-9)
        assert math.isclose(math.sin(w), math.sin(x), abs_tol=1e-9)
    elif math.isfinite(lo) and math.isfinite(hi):
        assert hi - lo < 2 * math.pi
    for rev in (True, False):
        p = L.project(x, lo, hi, rev)
        assert lo <= p <= hi
        if not rev:
            assert p == min(max(x, lo), hi)
    n = L.normalize(x, lo, hi, True)
    assert math.isclose(math.cos(n), math.cos(x), abs_tol=1e-9)
    if L.inside(x, lo, hi, 0.0):
        assert L.inside(n, lo, hi, 0.0)


@given(t=st.one_of(st.floats(allow_nan=True, allow_infinity=True),
                   st.floats(-2 * math.pi, 2 * math.pi),
                   st.sampled_from([0.0, -0.0, 2 * math.pi, -2 * math.pi, math.pi, -math.pi,
                                    np.nextafter(2 * math.pi, 0), np.nextafter(-2 * math.pi, 0),
                                    5e-324, -5e-324])))
def test_turn_mod_is_python_modulo_bit_for_bit(t):
    """turn_mod's fast paths give exactly t % 2π (Python's floor modulo), signed zeros too."""
    got, want = L.turn_mod(t), t % (2 * math.pi)
    if math.isnan(want):
        assert math.isnan(got)
    else:
        assert math.copysign(1.0, got) == math.copysign(1.0, want) and got == want
        assert 0.0 <= got <= 2 * math.pi  # a tiny negative t rounds up to 2π, as with %


def test_sampling_box_documented_ranges():
    """Open sides sample a documented finite range: [-π, π], [hi − 2π, hi], [lo, lo + 2π]."""
    box = L.sampling_box(np.array([-np.inf, -np.inf, 5.0, -np.inf, -np.inf]),
                         np.array([np.inf, 1.0, np.inf, 10.0, np.inf]),
                         np.array([np.pi, np.pi, np.pi, np.pi, 1.0]))
    np.testing.assert_allclose(box, [[-np.pi, np.pi], [1 - 2 * np.pi, 1.0],
                                     [5.0, 5 + 2 * np.pi], [-np.pi, 10.0], [-1.0, 1.0]])
    r = _one_sided_arm((2.0, np.inf))
    Q = r.random_q(1000, seed=0)
    assert np.all(Q >= 2.0) and np.all(Q <= 2.0 + 2 * np.pi)


# ---------------------------------------------------------------- nonsense refused
@pytest.mark.parametrize("qlim", ["12", None, 5, (np.inf, np.inf), (-np.inf, -np.inf),
                                  (2.0, 1.0), (0.0, 1e300), (0, 10**400), (np.nan, 1.0),
                                  (1, 2, 3), ("a", "b"), {"lo": 1}, np.zeros((2, 2))])
def test_nonsense_limits_refused(qlim):
    """Strings, scalars, None, empty or reversed intervals, huge ends are refused clearly."""
    with pytest.raises(RobotDefinitionError, match="joint limit"):
        sk.Robot.from_dh([dict(ROW, qlim=qlim)])
    with pytest.raises(RobotDefinitionError, match="joint limit"):
        Joint(qlim=qlim)


def test_sigma_and_contradictory_types():
    """sigma=1 means prismatic (Robotics Toolbox); type/joint/sigma that disagree are refused."""
    assert sk.Robot.from_dh([dict(ROW, sigma=1)]).joint_types == ("P",)
    assert sk.Robot.from_dh([dict(ROW, sigma=0, type="R")]).joint_types == ("R",)
    with pytest.raises(RobotDefinitionError, match="contradictory joint type"):
        sk.Robot.from_dh([dict(ROW, type="R", joint="P")])
    with pytest.raises(RobotDefinitionError, match="contradictory joint type"):
        sk.Robot.from_dh([dict(ROW, type="R", sigma=1)])
    with pytest.raises(RobotDefinitionError, match="sigma"):
        sk.Robot.from_dh([dict(ROW, sigma=2)])
    with pytest.raises(RobotDefinitionError, match="unknown field.*allowed: a, alpha"):
        sk.Robot.from_dh([dict(ROW, offset=1)])


@pytest.mark.parametrize("field, value, match", [
    ("a", 1e308, "at most 1e\\+06 m"), ("d", -1e7, "at most"), ("a", 10**400, "at most"),
    ("alpha", 1e300, "at most"), ("a", "x", "must be a number"), ("theta", None, "number"),
    ("a", True, "number"), ("d", np.nan, "finite"),
])
def test_dh_values_refused(field, value, match):
    """Lengths that would overflow FK, huge angles and non-numbers are refused at the row."""
    with pytest.raises(RobotDefinitionError, match=match):
        sk.Robot.from_dh([dict(ROW, **{field: value})])


def test_joint_and_robot_fields_refused():
    """Joint(offset='x'), non-string names, huge translations and too many joints are refused."""
    with pytest.raises(RobotDefinitionError, match="offset must be a number"):
        Joint(offset="x")
    with pytest.raises(RobotDefinitionError, match="name must be a string"):
        Joint(name=3)
    with pytest.raises(RobotDefinitionError, match="exceeds"):
        Joint(origin=np.array([[1, 0, 0, 1e9], [0, 1, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1.0]]))
    far = np.eye(4)
    far[0, 3] = 1e12
    with pytest.raises(InputError, match="base"):
        sk.Robot.from_dh([ROW], base=far)
    with pytest.raises(RobotDefinitionError, match="name must be a string"):
        sk.Robot.from_dh([ROW], name=["x"])
    with pytest.raises(InputError, match=f"at most {MAX_JOINTS}"):
        sk.models.planar(10**8)
    with pytest.raises(RobotDefinitionError, match=f"at most {MAX_JOINTS}"):
        sk.Robot.from_dh([ROW] * (MAX_JOINTS + 1))


def test_fk_never_infinite_for_accepted_robots():
    """The largest accepted lengths and joint values still give a finite FK."""
    r = sk.Robot.from_dh([dict(ROW, a=1e6, d=-1e6, type="P", qlim=(-1e9, 1e9))] * 50)
    T = r.fk(np.full(50, 1e9))
    assert np.isfinite(T).all()


@pytest.mark.parametrize("task", [[0, 0], [], [6], [-1], ["a"], "nope", [0.5], [0] * 7, 3])
def test_manipulability_bad_task(task):
    """manipulability(task=[0, 0]) and other malformed tasks raise, never return ≈0."""
    r = sk.models.ur5()
    with pytest.raises((InputError, InputTypeError)):
        r.manipulability(np.zeros(6), task=task)


@pytest.mark.parametrize("size", [-1, "a", 1.5, (2, -1), True, 2**70])
def test_random_q_bad_size(size):
    """random_q(-1) / ('a') / 2**70 raise library errors (the last one a BudgetError)."""
    with pytest.raises(SerialkinError):
        sk.models.ur5().random_q(size, seed=0)


def test_random_q_budget():
    """A random_q batch beyond the budget is refused before allocation, naming the setting."""
    with pytest.raises(BudgetError, match="size"):
        sk.models.ur5().random_q(10**11, seed=0)


@pytest.mark.parametrize("target", [np.full((4, 4), np.nan), np.eye(3), np.zeros(6),
                                    np.eye(4) * 2, "x"])
def test_multitask_solve_bad_target(target):
    """MultiTaskResolver.solve with a NaN, wrong-size or non-rigid target raises InputError."""
    from serialkin.redundancy import MultiTaskResolver

    r = sk.models.planar(4)
    with pytest.raises((InputError, InputTypeError)):
        MultiTaskResolver(task="planar").solve(r, target, np.zeros(4))
    with pytest.raises(InputError):
        MultiTaskResolver(task="planar").solve(r, np.eye(4), np.zeros(3))


# ---------------------------------------------------------------- integers and budgets
_INT_OPTIONS = [("max_iter", 2**63), ("restarts", 2**64), ("max_iter", MAX_ITERATIONS + 1),
                ("restarts", MAX_RESTARTS + 1), ("max_iter", 0), ("restarts", -1),
                ("stall_window", 2**63)]


@pytest.mark.parametrize("method, option, value", [
    (m, o, v) for m in ("lm", "ccd", "bfgs") for o, v in _INT_OPTIONS
    if not (o == "stall_window" and m == "bfgs")])  # bfgs has no stall_window
def test_integer_options_bounded(option, value, method):
    """Integer options beyond their documented maximum raise (never 0 iterations / 1 attempt)."""
    r = sk.models.planar(3)
    with pytest.raises(InputError, match=option):
        r.ik([1.0, 1.0], method=method, **{option: value})


def test_large_max_iter_still_solves():
    """max_iter at its maximum runs normally (a reachable pose is reached)."""
    r = sk.models.ur5()
    q = r.random_q(seed=2)
    res = r.ik(r.fk(q), max_iter=MAX_ITERATIONS, restarts=MAX_RESTARTS, seed=0)
    assert res.success


def test_path_circle_tiny_step_budget():
    """Path.circle(step=1e-9) and a tiny polyline step are refused before allocation."""
    from serialkin.tracking.path import Path

    with pytest.raises(BudgetError, match="step"):
        Path.circle([0, 0], 1.0, step=1e-9)
    with pytest.raises(BudgetError, match="step"):
        Path.circle([0, 0], 1.0, step=5e-324)
    with pytest.raises(BudgetError, match="step"):
        Path.polyline([[0, 0], [1e6, 0]], 1e-9)
    assert len(Path.polyline([[0, 0], [1, 0], [1, 1]], 0.1)) == 21


def test_workspace_budget():
    """Workspace grids and sample counts beyond the budget raise BudgetError naming them."""
    from serialkin.workspace import compute_workspace

    r = sk.models.two_link()
    with pytest.raises(BudgetError, match="cell"):
        compute_workspace(r, "reachable", samples=200, cell=1e-7, progress=False)
    with pytest.raises(BudgetError, match="samples"):
        compute_workspace(r, "reachable", samples=10**12, progress=False)


def test_budget_configuration(monkeypatch):
    """The budget follows set_memory_budget, then SERIALKIN_MEMORY_BUDGET, then memory."""
    assert parse_size("8G") == 8 * 1024**3 and parse_size("500m") == 500 * 1024**2
    assert parse_size("unlimited") == math.inf and parse_size("1.5K") == 1536
    for bad in ("", "-1G", "abc", "1X", "0"):
        with pytest.raises(InputError):
            parse_size(bad)
    monkeypatch.setenv("SERIALKIN_MEMORY_BUDGET", "1G")
    assert memory_budget() == 1024**3
    set_memory_budget("2G")
    try:
        assert memory_budget() == 2 * 1024**3
        with pytest.raises(BudgetError, match="2 GiB"):
            sk.models.ur5().random_q(10**8, seed=0)
    finally:
        set_memory_budget(None)
    monkeypatch.delenv("SERIALKIN_MEMORY_BUDGET")
    assert 0 < memory_budget() < math.inf


def test_eq49_weights_one_sided_limits():
    """Eq 49 weights: a one-sided joint is weighted near its finite end only, like a 2π range."""
    from serialkin.redundancy.multitask import joint_limit_repulsion, joint_limit_weights

    lim = np.array([[-np.inf, 1.0], [-1.0, np.inf], [-np.inf, np.inf], [-1.0, -1.0 + 2 * np.pi]])
    near = np.array([0.99, -0.99, 0.0, -0.99])
    far = np.array([-3.0, 3.0, 100.0, 2.0])
    w_near = joint_limit_weights(near, lim)
    assert w_near[0] > 0 and w_near[1] > 0 and w_near[2] == 0
    assert w_near[0] == pytest.approx(w_near[3]) and w_near[1] == pytest.approx(w_near[3])
    np.testing.assert_array_equal(joint_limit_weights(far, lim), 0.0)
    push = joint_limit_repulsion(near, lim)
    assert push[0] < 0 < push[1] and push[2] == 0


# ---------------------------------------------------------------- fuzzing the API
_WEIRD = st.one_of(
    st.none(), st.booleans(), st.integers(-(2**70), 2**70), st.floats(), st.text(max_size=8),
    st.binary(max_size=4), st.lists(st.floats(), max_size=4),
    st.lists(st.one_of(st.none(), st.floats(), st.text(max_size=2)), min_size=2, max_size=2),
    st.sampled_from([(np.inf, np.inf), {"a": 1}, np.zeros((2, 2)), np.array([1, 2]), 10**400,
                     object(), complex(1, 2)]),
)


def _library_error_or_result(call):
    """Run ``call``: it returns, or raises a SerialkinError (never another exception)."""
    try:
        return call()
    except SerialkinError:
        return None


@settings(max_examples=150, deadline=None)
@given(field=st.sampled_from(["a", "alpha", "d", "theta", "type", "qlim", "name", "sigma",
                              "joint"]), value=_WEIRD)
def test_fuzz_dh_rows(field, value):
    """Any value in any DH field: a robot whose FK is finite, or a library error."""
    r = _library_error_or_result(lambda: sk.Robot.from_dh([dict(ROW, **{field: value})]))
    if r is not None:
        assert np.isfinite(r.fk(r.random_q(seed=0))).all()
        assert np.all(r.qlim[:, 0] <= r.qlim[:, 1])


@settings(max_examples=150, deadline=None)
@given(option=st.sampled_from(["max_iter", "restarts", "tol", "seed", "q0", "mask",
                               "respect_limits", "damping", "stall_window", "max_step",
                               "polish", "method"]), value=_WEIRD)
def test_fuzz_ik_options(option, value):
    """Any value for any IK option: an honest result, or a library error."""
    r = sk.models.planar(3, qlim=(-2.0, np.inf))
    kw = {option: value} if option == "max_iter" else {option: value, "max_iter": 50}
    res = _library_error_or_result(lambda: r.ik([1.0, 1.0], **kw))
    if res is not None and res.success:
        tol = float(value) if option == "tol" and value is not None else 1e-6
        assert np.linalg.norm(r.fk(res.q)[:2, 3] - [1.0, 1.0]) <= tol * (1 + 1e-9) + 1e-12
        if option != "respect_limits":
            assert r.within_limits(res.q)


@pytest.mark.parametrize("method", ["lm", "ccd"])
def test_huge_start_angle_keeps_the_reported_error(method):
    """A q0 of 8.9e9 rad on an unbounded joint: the returned q has the error reported.

    Moving such an angle by whole turns rounds it by ~1e-6 rad (found by the fuzzer
    above: a success whose returned q missed the 1e-6 tolerance).
    """
    r = sk.models.planar(3, qlim=(-2.0, np.inf))
    res = r.ik([1.0, 1.0], q0=[0.0, 0.0, 8916041057.0], max_iter=50, method=method)
    err = np.linalg.norm(r.fk(res.q)[:2, 3] - [1.0, 1.0])
    assert abs(err - res.position_error) <= 1e-12
    assert not res.success or err <= 1e-6


@settings(max_examples=100, deadline=None)
@given(call=st.sampled_from(["random_q", "manipulability", "jacobian_link", "with_limits",
                             "within_limits", "circle_step", "planar_n"]), value=_WEIRD)
def test_fuzz_robot_and_path_calls(call, value):
    """Any argument to sizes, tasks, links, limits, steps: a result or a library error."""
    from serialkin.tracking.path import Path

    r = sk.models.planar(3)
    calls = {
        "random_q": lambda: r.random_q(value, seed=0),
        "manipulability": lambda: r.manipulability(np.zeros(3), task=value),
        "jacobian_link": lambda: r.jacobian(np.zeros(3), link=value),
        "with_limits": lambda: r.with_limits(value),
        "within_limits": lambda: r.within_limits(np.zeros(3), tol=value),
        "circle_step": lambda: Path.circle([0, 0], 1.0, step=value),
        "planar_n": lambda: sk.models.planar(value),
    }
    _library_error_or_result(calls[call])


@pytest.mark.parametrize("qlim", [(-np.inf, 0.3), (-0.2, 0.4), (0.1, np.inf)])
def test_dls_tracking_stays_inside_limits(qlim):
    """DLS tracking projects every step onto the limits: no recorded q leaves them."""
    from serialkin.tracking import track
    from serialkin.tracking.path import Path

    r = sk.models.planar(4, 0.3, qlim=qlim)
    traj = track(r, Path.circle([0.6, 0.3], 0.3, step=0.3), "dls", q0=np.full(4, 0.2))
    assert r.within_limits(traj.q).all()
    assert np.all(traj.min_limit_margin >= 0)
    for k in np.flatnonzero(traj.reached):
        assert np.linalg.norm(r.fk(traj.q[k])[:2, 3] - traj.targets[k, :2, 3]) <= 5e-3 + 1e-9


def test_superlinear_methods_refuse_the_longest_chains():
    """Methods whose iteration is O(n³) refuse >1000 joints, naming the scalable methods."""
    r = sk.models.planar(1500, 1.0 / 1500)
    with pytest.raises(InputError, match="at most 1000 joints.*dls"):
        r.ik([0.5, 0.5])
    with pytest.raises(InputError, match="at most 200 joints"):
        sk.models.planar(300).ik([1.0, 1.0], method="powell")
    res = r.ik([0.5, 0.5], method="dls", max_iter=5, restarts=0, seed=0)
    assert res.q.shape == (1500,)


def test_the_old_interval_wrap_name_warns():
    from serialkin.model import limits

    with pytest.warns(DeprecationWarning, match="wrap_into"):
        old = limits.wrap_angle
    assert old is limits.wrap_into
