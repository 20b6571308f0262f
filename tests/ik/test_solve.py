"""The shared IK interface: robot.ik / serialkin.ik.solve with the default method."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import serialkin.ik as ik
from serialkin import models
from serialkin.ik import IKResult
from serialkin.spatial import transl

from .conftest import ACCURACY, assert_reaches, reachable, task_errors

JACOBIAN_METHODS = ("transpose", "pinv", "dls", "lm", "lm_wampler", "lm_chan", "lm_sugihara",
                    "sdls", "newton", "gauss_newton")


def test_registry_lists_jacobian_methods():
    """Every Jacobian-family method is registered under its documented name."""
    names = ik.available_methods()
    for m in JACOBIAN_METHODS:
        assert m in names
        assert ik.METHODS[m].family == "jacobian"
        assert ik.METHODS[m].limits
    assert names == tuple(sorted(names))


@pytest.mark.parametrize("name", ["ur5", "puma560", "panda", "iiwa7", "stanford"])
def test_default_method_full_pose(name):
    """Default 'lm' reaches FK targets of random in-limit q to 1e-6 m / rad, q in limits."""
    robot = models.get(name)
    q_true, targets = reachable(robot, 25, seed=11)
    for k, T in enumerate(targets):
        res = robot.ik(T, seed=k)
        assert isinstance(res, IKResult) and res.method == "lm"
        assert_reaches(robot, res, T)


@settings(max_examples=30, deadline=None)
@given(seed=st.integers(0, 2**31 - 1))
def test_round_trip_property_puma(seed):
    """For any in-limit q, IK of FK(q) returns a q' with FK(q') = FK(q) inside the limits."""
    robot = models.puma560()
    q = robot.random_q(seed=seed)
    T = robot.fk(q)
    res = robot.ik(T, seed=seed)
    assert_reaches(robot, res, T)


def test_solution_at_q0_takes_no_iteration(ur5):
    """Starting at an exact solution returns it after 0 iterations and no restart."""
    q = ur5.random_q(seed=4)
    res = ur5.ik(ur5.fk(q), q0=q, seed=0)
    assert res.success and res.iterations == 0 and res.restarts == 0
    assert np.allclose(res.q, q)


def test_position_only_target(puma):
    """A 3-vector target is position-only: the position matches, orientation is free."""
    for k, q in enumerate(puma.random_q(10, seed=2)):
        p = puma.fk(q)[:3, 3]
        res = puma.ik(p, seed=k)
        assert_reaches(puma, res, transl(*p), weights=[1, 1, 1, 0, 0, 0])
        assert res.orientation_error == 0.0


def test_planar_targets(two_link, planar6):
    """Planar (x, y) and (x, y, φ) targets are reached on planar arms, φ = heading of x_tool."""
    res = two_link.ik(np.array([1.2, 0.7]), seed=0)
    T = two_link.fk(res.q)
    assert res.success and np.allclose(T[:2, 3], [1.2, 0.7], atol=ACCURACY)
    res = planar6.ik(np.array([-0.25, 0.1, 2.0]), seed=1)
    T = planar6.fk(res.q)
    assert res.success
    assert np.allclose(T[:2, 3], [-0.25, 0.1], atol=ACCURACY)
    assert abs(np.arctan2(T[1, 0], T[0, 0]) - 2.0) < ACCURACY


def test_mask_selects_task_coordinates(panda):
    """With a mask only the selected coordinates are matched (m < 6 task space)."""
    mask = [1, 1, 1, 0, 0, 1]
    for k, q in enumerate(panda.random_q(5, seed=3)):
        T = panda.fk(q)
        res = panda.ik(T, mask=mask, seed=k)
        assert_reaches(panda, res, T, weights=mask)
    # weights other than 0/1 are accepted and scale the cost
    T = panda.fk(panda.random_q(seed=9))
    res = panda.ik(T, mask=[2.0, 2.0, 2.0, 0.5, 0.5, 0.5], seed=0)
    assert_reaches(panda, res, T)


def test_tolerance_controls_accuracy(ur5):
    """A looser tol stops earlier with errors within it; the default reaches 1e-9."""
    T = ur5.fk(ur5.random_q(seed=5))
    q0 = ur5.random_q(seed=6)
    loose = ur5.ik(T, q0=q0, tol=1e-3, seed=0)
    tight = ur5.ik(T, q0=q0, seed=0)
    assert loose.success and tight.success
    assert loose.position_error <= 1e-3 and loose.orientation_error <= 1e-3
    assert tight.position_error <= ik.DEFAULT_TOL and tight.orientation_error <= ik.DEFAULT_TOL
    assert loose.iterations <= tight.iterations


def test_reported_errors_match_fk(ur5):
    """position_error and orientation_error are those of FK(q) against the target."""
    T = ur5.fk(ur5.random_q(seed=7))
    res = ur5.ik(T, tol=1e-4, seed=3)
    pe, oe = task_errors(ur5, res.q, T)
    assert res.position_error == pytest.approx(pe, abs=1e-12)
    assert res.orientation_error == pytest.approx(oe, abs=1e-12)


def test_same_seed_same_answer(panda):
    """The same seed gives the same q; the answer does not depend on earlier calls."""
    T = panda.fk(panda.random_q(seed=8))
    a = panda.ik(T, seed=123)
    panda.ik(T, seed=5)
    b = panda.ik(T, seed=123)
    c = panda.ik(T, seed=np.random.default_rng(0))
    assert np.array_equal(a.q, b.q) and a.iterations == b.iterations
    assert c.success


def test_unreachable_target_fails_cleanly(puma):
    """A target beyond the reach: success False, a reason, finite in-limit best q, bounded."""
    T = transl(3.0, 0.0, 0.5)
    res = puma.ik(T, seed=0, restarts=20, max_iter=50)
    assert not res.success
    assert "no configuration within" in res.reason
    assert "the target is out of reach: it is 3.04 m from joint 1" in res.reason
    assert np.isfinite(res.q).all() and puma.within_limits(res.q)
    assert res.iterations <= 21 * 50 + 50  # attempts, then the lm polish
    assert res.restarts == 20
    # the best attempt is a genuine attempt: closer than the reach allows is impossible
    assert res.position_error > 3.0 - 1.0


def test_target_only_outside_limits_fails(ur5):
    """A pose reachable only with a joint outside its (narrowed) limits is reported as failed."""
    q = np.array([0.0, -1.0, 1.0, 0.0, 1.0, 0.0])
    T = ur5.fk(q)
    narrow = ur5.with_limits(np.column_stack([np.full(6, -0.5), np.full(6, 0.5)]))
    res = narrow.ik(T, seed=0, restarts=10)
    assert not res.success and res.reason
    assert "at a limit" in res.reason and "only outside the joint limits" in res.reason
    assert narrow.within_limits(res.q)
    free = narrow.ik(T, seed=0, respect_limits=False)
    assert free.success
    assert task_errors(narrow, free.q, T)[0] < ACCURACY


def test_singular_starts(ur5, puma):
    """Singular initial guesses (stretched arm, aligned wrist axes) do not break the solver."""
    q_str = np.zeros(6)  # UR5 at zero: arm stretched, wrist axes aligned
    for k, q in enumerate(ur5.random_q(5, seed=12)):
        T = ur5.fk(q)
        assert_reaches(ur5, ur5.ik(T, q0=q_str, seed=k), T)
    q_wrist = np.array([0.3, -0.5, 0.4, 0.7, 0.0, -0.2])  # Puma q5 = 0: wrist singular
    for k, q in enumerate(puma.random_q(5, seed=13)):
        T = puma.fk(q)
        for method in ("lm", "dls", "sdls", "lm_chan"):
            assert_reaches(puma, puma.ik(T, method=method, q0=q_wrist, seed=k), T)


def test_singular_targets(ur5, two_link):
    """Targets at singular configurations and on the workspace boundary are handled."""
    q = np.array([0.4, -1.2, 0.9, 0.1, 0.0, 0.3])  # wrist singular target
    T = ur5.fk(q)
    res = ur5.ik(T, seed=0)
    assert_reaches(ur5, res, T)
    # two-link arm stretched (boundary of the workspace): position within 1e-6
    for method in JACOBIAN_METHODS:
        res = two_link.ik(np.array([2.0, 0.0]), method=method, seed=1, tol=1e-7)
        assert np.isfinite(res.q).all()
        assert task_errors(two_link, res.q, two_link.fk(np.zeros(2)), [1, 1, 0, 0, 0, 0])[0] \
            < 1e-3, method


def test_unlimited_revolute_joints_are_wrapped(two_link):
    """Joints without limits come back wrapped into [-π, π)."""
    for seed in range(10):
        res = two_link.ik(np.array([0.3, -1.1]), seed=seed)
        assert res.success
        assert np.all(res.q >= -np.pi) and np.all(res.q < np.pi)


def test_respect_limits_false_still_finite(puma):
    """With respect_limits=False the solve succeeds and q is finite (limits may be left)."""
    q, Ts = reachable(puma, 5, seed=14)
    for k, T in enumerate(Ts):
        res = puma.ik(T, seed=k, respect_limits=False)
        assert_reaches(puma, res, T, limits=False)


def test_method_options_are_passed(ur5):
    """Method-specific options reach the kernel (a huge damping slows DLS down)."""
    T = ur5.fk(ur5.random_q(seed=15))
    q0 = ur5.random_q(seed=16)
    fast = ur5.ik(T, method="dls", q0=q0, seed=0, restarts=0, max_iter=500)
    slow = ur5.ik(T, method="dls", q0=q0, seed=0, restarts=0, max_iter=500, damping=2.0,
                  stall_window=500)
    assert slow.iterations > fast.iterations


def test_result_repr_and_fields(ur5):
    """IKResult is frozen, typed and prints its key facts."""
    res = ur5.ik(ur5.fk(ur5.random_q(seed=1)), seed=0)
    assert isinstance(res.success, bool) and isinstance(res.iterations, int)
    assert isinstance(res.position_error, float) and isinstance(res.restarts, int)
    assert res.q.shape == (6,)
    text = repr(res)
    assert "success=True" in text and "lm" in text
    with pytest.raises(AttributeError):
        res.success = False  # type: ignore[misc]
    with pytest.raises(TypeError):
        res[0]


def test_polish_returns_closest_pose(two_link):
    """For an unreachable target, 'lm' polishes its best attempt to the closest pose."""
    res = two_link.ik(np.array([3.0, 1.0]), seed=0, restarts=3)
    assert not res.success
    # closest point of the reach circle (radius 2) to (3, 1): distance sqrt(10) − 2
    assert res.position_error == pytest.approx(np.sqrt(10.0) - 2.0, abs=1e-6)
    rough = two_link.ik(np.array([3.0, 1.0]), seed=0, restarts=3, polish=False)
    assert rough.position_error >= res.position_error - 1e-12


@pytest.mark.parametrize("name", ["ur5", "puma560", "stanford"])
def test_analytic_method_nearest_to_q0(name):
    """Method 'analytic' returns the closed-form solution nearest q0 (q0 itself for FK(q0))."""
    pytest.importorskip("serialkin.ik.analytic")
    robot = models.get(name)
    for q in robot.random_q(5, seed=90):
        T = robot.fk(q)
        res = robot.ik(T, method="analytic", q0=q)
        assert_reaches(robot, res, T)
        assert np.allclose(res.q, q, atol=1e-6)
        assert res.iterations == 1 and res.restarts == 0


@pytest.mark.parametrize("name", ["ur5", "puma560", "two_link"])
def test_analytic_batch_is_the_single_answers(name):
    """Method 'analytic' on a batch (one ik_all batch) answers each target as a single call."""
    pytest.importorskip("serialkin.ik.analytic")
    robot = models.get(name)
    rng = np.random.default_rng(7)
    Q = robot.random_q(12, seed=91)
    targets = robot.fk(Q)
    # per-target references near each truth, inside the limits
    q0 = np.clip(Q + rng.normal(scale=0.3, size=Q.shape), robot.qlim[:, 0], robot.qlim[:, 1])
    if robot.n == 2:  # planar 2R: (x, y) targets, plus one out of reach
        targets = np.vstack([targets[:, :2, 3], [[5.0, 0.0]]])
        q0 = np.vstack([q0, np.zeros(2)])
    batch = robot.ik(targets, method="analytic", q0=q0)
    for k in range(len(targets)):
        one = robot.ik(targets[k], method="analytic", q0=q0[k])
        assert batch.success[k] == one.success
        assert np.array_equal(batch.q[k], one.q)
        assert batch.reason[k] == one.reason
        assert batch.position_error[k] == one.position_error
    assert batch.success[:12].all() and np.allclose(batch.q[:12], Q, atol=1e-6)
    if robot.n == 2:
        assert not batch.success[-1] and "no closed-form solution" in batch.reason[-1]


def test_analytic_method_errors(panda, two_link):
    """'analytic' on a robot without closed form raises; an unreachable target fails cleanly."""
    pytest.importorskip("serialkin.ik.analytic")
    from serialkin.errors import NoClosedFormError

    with pytest.raises(NoClosedFormError):
        panda.ik(panda.fk(np.zeros(7)), method="analytic")
    res = two_link.ik(np.array([3.0, 0.0]), method="analytic")
    assert not res.success and "no closed-form solution" in res.reason
    assert np.isfinite(res.q).all()


@settings(max_examples=25, deadline=None)
@given(
    seed=st.integers(0, 2**31 - 1),
    n=st.integers(6, 7),
    convention=st.sampled_from(["standard", "modified"]),
)
def test_users_own_random_robot(seed, n, convention):
    """Any random DH arm (R and P joints): IK of FK(q) for in-limit q succeeds in the limits."""
    from serialkin import Robot
    from serialkin.model.dh import DHLink

    rng = np.random.default_rng(seed)
    rows = []
    for i in range(n):
        prismatic = i == 2 and rng.random() < 0.3
        rows.append(DHLink(
            a=float(rng.uniform(0, 0.5)), alpha=float(rng.choice([0, np.pi / 2, -np.pi / 2,
                                                                  rng.uniform(-np.pi, np.pi)])),
            d=float(rng.uniform(0, 0.4)), theta=0.0, type="P" if prismatic else "R",
            qlim=(0.1, 0.6) if prismatic else (-np.pi, np.pi)))
    robot = Robot.from_dh(rows, convention)
    q = robot.random_q(seed=seed)
    T = robot.fk(q)
    res = robot.ik(T, seed=seed)
    assert_reaches(robot, res, T)


@pytest.mark.parametrize("name", ["puma560", "ur5", "panda", "stanford", "scara"])
def test_reach_bound_is_an_upper_bound(name):
    """No sampled configuration puts the tool farther from joint 1 than reach_bound."""
    from serialkin.ik.solver import reach_bound

    robot = models.get(name)
    P = robot.fk(robot.random_q(5000, seed=1))[:, :3, 3]
    dist = np.linalg.norm(P - robot.chain.F[0][:3, 3], axis=1)
    assert dist.max() <= reach_bound(robot) + 1e-12


def test_singular_best_attempt_hint(two_link):
    """A target just beyond a planar arm's reach ends stretched: the hint names the singularity."""
    res = two_link.ik(np.array([1.5, 1.5]), seed=0, restarts=3)
    assert not res.success
    assert "singular configuration" in res.reason and "out of reach" in res.reason


@settings(max_examples=25, deadline=None)
@given(
    seed=st.integers(0, 2**31 - 1),
    mask=st.lists(st.booleans(), min_size=6, max_size=6).filter(any),
)
def test_any_mask_property(seed, mask):
    """For any non-empty mask, IK of FK(q) matches exactly the selected coordinates."""
    robot = models.ur5()
    q = robot.random_q(seed=seed)
    T = robot.fk(q)
    res = robot.ik(T, mask=mask, seed=seed)
    assert_reaches(robot, res, T, weights=np.array(mask, float))
    if not any(mask[:3]):
        assert res.position_error == 0.0
    if not any(mask[3:]):
        assert res.orientation_error == 0.0


@pytest.mark.peer
@pytest.mark.parametrize("name", ["ur5", "panda"])
def test_solution_checked_by_pinocchio(name):
    """Pinocchio's FK of our IK answers (model from our URDF) reproduces the targets."""
    pin = pytest.importorskip("pinocchio")
    robot = models.get(name)
    model = pin.buildModelFromXML(robot.to_urdf())
    data = model.createData()
    fid = model.getFrameId("tool")
    _, targets = reachable(robot, 10, seed=95)
    res = robot.ik(targets, seed=0)
    assert res.success.all()
    for q, T in zip(res.q, targets):
        pin.framesForwardKinematics(model, data, q)
        M = data.oMf[fid]
        assert np.linalg.norm(M.translation - T[:3, 3]) < ACCURACY
        assert np.linalg.norm(pin.log3(M.rotation @ T[:3, :3].T)) < ACCURACY
