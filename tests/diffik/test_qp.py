"""Differential IK as a QP: closed forms, distance Jacobians, hard limits, failures as results."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import serialkin as sk
from serialkin.diffik import (
    CollisionAvoidance,
    CustomTask,
    DiffIK,
    FrameTask,
    ManipulabilityTask,
    PositionLimit,
    PostureTask,
    StepBox,
    VelocityLimit,
    solve_step,
)
from serialkin.diffik.tasks import Workspace
from serialkin.errors import InputError, InputTypeError
from serialkin.model.geometry import Capsule, Cylinder, Sphere
from serialkin.tracking import planar_arm


@pytest.fixture(scope="module")
def panda():
    return sk.models.get("panda")


@pytest.fixture(scope="module")
def arm():
    return planar_arm(8, 0.1)


def test_posture_task_alone_closes_the_error_in_one_step(panda):
    """Without constraints a posture task gives Δq = gain (q_ref − q) (up to the damping)."""
    q = panda.random_q(seed=0)
    ref = panda.random_q(seed=1)
    res = solve_step(panda, q, [PostureTask(ref, gain=0.5)], damping=0.0)
    assert res.success
    np.testing.assert_allclose(res.dq, 0.5 * (ref - q), atol=1e-9)


def test_frame_task_step_is_the_damped_gauss_newton_step(panda):
    """Unconstrained frame + damping: Δq = (JᵀWJ + μI)⁻¹ JᵀW e, the DLS step (eq 46)."""
    q = panda.random_q(seed=3)
    T = panda.fk(panda.random_q(seed=4))
    mu = 1e-3
    res = solve_step(panda, q, [FrameTask(T)], damping=mu)
    J = panda.jacobian(q)
    Tq = panda.fk(q)
    e = sk.spatial.pose_error(Tq, T)
    expected = np.linalg.solve(J.T @ J + mu * np.eye(7), J.T @ e)
    np.testing.assert_allclose(res.dq, expected, atol=1e-8)


def test_position_limits_hold_after_the_step(panda):
    """A step towards a target beyond the limits ends exactly at the limits, never past them."""
    q = panda.random_q(seed=5)
    ref = panda.qlim[:, 1] + 1.0  # beyond every upper limit
    res = solve_step(panda, q, [PostureTask(ref)], [PositionLimit()])
    assert res.success
    np.testing.assert_allclose(q + res.dq, panda.qlim[:, 1], atol=1e-6)


@settings(max_examples=25, deadline=None)
@given(seed=st.integers(0, 10_000), dt=st.floats(0.01, 1.0), gain=st.floats(0.1, 1.0))
def test_every_step_respects_position_and_velocity_limits(seed, dt, gain):
    """For random q, targets, dt and limit gains: lb ≤ Δq ≤ ub of every box constraint."""
    robot = sk.models.get("panda")
    q = robot.random_q(seed=seed)
    T = robot.fk(robot.random_q(seed=seed + 1))
    vmax = np.linspace(0.5, 2.0, 7)
    res = solve_step(robot, q, [FrameTask(T), PostureTask(q, weight=1e-3)],
                     [PositionLimit(gain=gain), VelocityLimit(vmax, dt)])
    assert res.success
    tol = 1e-6
    assert np.all(np.abs(res.dq) <= vmax * dt + tol)
    assert np.all(q + res.dq <= robot.qlim[:, 1] + tol)
    assert np.all(q + res.dq >= robot.qlim[:, 0] - tol)
    assert np.all(res.dq <= gain * (robot.qlim[:, 1] - q) + tol)


def test_qpsolvers_backend_agrees_with_direct_daqp(panda):
    """The same QP through qpsolvers (daqp) gives the same step as the direct DAQP call."""
    q = panda.random_q(seed=7)
    T = panda.fk(panda.random_q(seed=8))
    tasks = [FrameTask(T), PostureTask(q, weight=1e-2)]
    cons = [PositionLimit(gain=0.5), VelocityLimit(1.0, 0.1)]
    a = solve_step(panda, q, tasks, cons)
    b = solve_step(panda, q, tasks, cons, solver="qpsolvers:daqp")
    assert a.success and b.success
    np.testing.assert_allclose(a.dq, b.dq, atol=1e-8)


def _fd_gradient(f, q, h=1e-6):
    g = np.zeros(q.size)
    for i in range(q.size):
        dq = np.zeros(q.size)
        dq[i] = h
        g[i] = (f(q + dq) - f(q - dq)) / (2 * h)
    return g


@pytest.mark.parametrize("obstacle", [
    Sphere(0.05, center=[0.3, 0.2, 0.5], influence=5.0),
    Capsule(0.03, a=[0.4, -0.3, 0.0], b=[0.4, 0.3, 0.8], influence=5.0),
])
def test_obstacle_rows_match_finite_differences(panda, obstacle):
    """Each collision row is −∇d: it matches central differences of the clearance."""
    q = panda.random_q(seed=11)
    con = CollisionAvoidance([obstacle], link_radius=0.04, safety=0.0, influence=10.0)
    ws = Workspace(panda)
    ws.update(q)
    G, h = con.rows(ws, q)
    C, _ = con.distances(panda, q)
    assert G.shape[0] == C.shape[0]  # every segment within the huge influence
    for i in range(C.shape[0]):
        fd = _fd_gradient(lambda x, i=i: con.distances(panda, x)[0][i, 0], q)
        np.testing.assert_allclose(-G[i], fd, atol=1e-6)
        assert h[i] == pytest.approx(0.5 * C[i, 0])


def test_self_collision_rows_match_finite_differences(panda):
    """A self-pair row is −nᵀ(J_p(a) − J_p(b)): central differences of the pair distance."""
    q = panda.random_q(seed=12)
    pairs = [(0, 4), (1, 6), (2, 5)]
    con = CollisionAvoidance([], link_radius=0.03, safety=0.0, influence=10.0, self_pairs=pairs)
    ws = Workspace(panda)
    ws.update(q)
    G, _ = con.rows(ws, q)
    _, D = con.distances(panda, q)
    assert G.shape[0] == len(pairs)
    for p in range(len(pairs)):
        fd = _fd_gradient(lambda x, p=p: con.distances(panda, x)[1][p], q)
        np.testing.assert_allclose(-G[p], fd, atol=1e-6)


def test_collision_damper_limits_the_approach(arm):
    """A step pulled into an obstacle loses at most gain·(d − d_s) of clearance (first order)."""
    q = np.full(arm.n, 0.2)
    obs = Cylinder(0.05, math.inf, center=[0.55, 0.45, 0.0], influence=0.1)
    con = CollisionAvoidance([obs], safety=0.01, gain=0.5)
    T = arm.fk(q)
    target = T.copy()
    target[:2, 3] = obs.center[:2]  # the tool is pulled into the obstacle's centre
    ik = DiffIK(arm, [FrameTask(target, task="planar")], [con, VelocityLimit(0.05)])
    for _ in range(60):
        C0, _ = con.distances(arm, q)
        res = ik.step(q)
        assert res.success
        q = q + res.dq
        C1, _ = con.distances(arm, q)
        assert C1.min() > 0.0  # never enters
        near = C0 < 0.01 + obs.influence  # the constrained pairs
        allowed = C0 - 0.5 * (C0 - 0.01)  # damper: lose at most half the excess over d_s
        assert np.all(C1[near] >= allowed[near] - 1e-3)  # up to second order (steps 0.05 rad)
    assert C1.min() == pytest.approx(0.01, abs=2e-3)  # settles at the safety distance


def test_conflicting_bounds_are_a_result_naming_the_joint(panda):
    """A joint beyond its limit by more than the velocity limit allows back: a named result."""
    q = panda.random_q(seed=2)
    q[3] = panda.qlim[3, 1] + 0.5
    res = solve_step(panda, q, [PostureTask(q)], [PositionLimit(), VelocityLimit(0.1)])
    assert not res.success and "q4" in res.reason and "conflicting" in res.reason
    assert np.all(res.dq == 0.0)


def test_infeasible_collision_rows_are_a_result(arm):
    """A link inside the safety distance that cannot move out (tiny velocity box): a reason."""
    q = np.zeros(arm.n)
    # 1 cm from the stretched arm
    obs = Cylinder(0.03, math.inf, center=[0.45, 0.04, 0.0], influence=0.05)
    con = CollisionAvoidance([obs], safety=0.05, influence=0.1, gain=1.0)  # wants 4 cm out
    res = solve_step(arm, q, [PostureTask(q)], [con, VelocityLimit(1e-4)])
    assert not res.success and "infeasible" in res.reason
    assert np.all(res.dq == 0.0)


def test_step_box_bounds_the_deviation_from_the_reference(panda):
    """StepBox keeps |q + Δq − q_ref| ≤ δ for every joint."""
    q = panda.random_q(seed=20)
    ref = q + 0.05
    res = solve_step(panda, q, [PostureTask(q + 1.0)], [StepBox(ref, 0.1)])
    assert res.success and np.all(np.abs(q + res.dq - ref) <= 0.1 + 1e-6)


def test_custom_task_equals_the_builtin_posture_task(panda):
    """A user's task (J = I, e = q_ref − q) gives the posture task's step."""
    q = panda.random_q(seed=21)
    ref = panda.random_q(seed=22)
    a = solve_step(panda, q, [CustomTask(lambda x: (np.eye(7), ref - x))], [PositionLimit()])
    b = solve_step(panda, q, [PostureTask(ref)], [PositionLimit()])
    np.testing.assert_allclose(a.dq, b.dq, atol=1e-9)


def test_manipulability_task_climbs_manipulability(panda):
    """A small step of the manipulability task alone raises w(q) (eq 43)."""
    q = panda.random_q(seed=23)
    res = solve_step(panda, q, [ManipulabilityTask(step=1e-3, weight=1.0)])
    assert panda.manipulability(q + res.dq) > panda.manipulability(q)


def test_bad_input_raises_library_errors(panda):
    """Bad tasks, constraints and settings raise InputError / InputTypeError naming the cause."""
    with pytest.raises(InputError, match="at least one task"):
        DiffIK(panda, [])
    with pytest.raises(InputTypeError, match="tasks\\[0\\]"):
        DiffIK(panda, ["pose"])
    with pytest.raises(InputError, match="solver"):
        DiffIK(panda, [PostureTask(np.zeros(7))], solver="quadprog!")
    with pytest.raises(InputError, match="influence"):
        CollisionAvoidance([Sphere(0.1, center=[1, 1, 1])], safety=0.1, influence=0.05)
    with pytest.raises(InputError, match="weight"):
        PostureTask(np.zeros(7), weight=-1.0)
    bad = CustomTask(lambda x: (np.eye(3), np.zeros(3)), name="mine")
    with pytest.raises(InputError, match="mine"):
        solve_step(panda, np.zeros(7), [bad])


@pytest.mark.parametrize("seed", [30, 31, 32])
def test_compiled_solver_agrees_with_daqp_with_collision_rows(arm, seed):
    """solver='compiled' gives DAQP's step on a QP with limits, a velocity box and distance rows."""
    rng = np.random.default_rng(seed)
    q = rng.uniform(-0.5, 0.5, arm.n)
    obs = [Cylinder(0.05, math.inf, center=[0.4, 0.3, 0.0], influence=0.3),
           Cylinder(0.04, math.inf, center=[0.2, -0.2, 0.0], influence=0.3)]
    target = arm.fk(q)
    target[:2, 3] = [0.3, 0.45]
    tasks = [FrameTask(target, task="planar"), PostureTask(q, weight=1e-3)]
    cons = [PositionLimit(np.tile([-1.0, 1.0], (arm.n, 1))), VelocityLimit(0.1),
            CollisionAvoidance(obs, safety=0.01, gain=0.5)]
    a = solve_step(arm, q, tasks, cons)
    b = solve_step(arm, q, tasks, cons, solver="compiled")
    assert a.success and b.success and a.active > 0
    np.testing.assert_allclose(b.dq, a.dq, atol=1e-7)


def test_compiled_solver_reports_infeasibility(arm):
    """The compiled solver finds the infeasible collision QP infeasible too (a result)."""
    q = np.zeros(arm.n)
    obs = Cylinder(0.03, math.inf, center=[0.45, 0.04, 0.0], influence=0.05)
    con = CollisionAvoidance([obs], safety=0.05, influence=0.1, gain=1.0)
    res = solve_step(arm, q, [PostureTask(q)], [con, VelocityLimit(1e-4)], solver="compiled")
    assert not res.success and "infeasible" in res.reason


def test_resolver_and_tracker_reject_bad_settings(arm):
    """QPResolver and track(solver='qp') name the bad setting (library errors, nothing run)."""
    from serialkin.diffik import QPResolver
    from serialkin.tracking import Path, track

    for kwargs, word in (({"max_step": -1.0}, "max_step"), ({"obstacles": "abc"}, "obstacles"),
                         ({"solver": "cvx"}, "solver"), ({"collision_gain": 2.0}, "collision_gain"),
                         ({"max_joint_step": float("nan")}, "max_joint_step"),
                         ({"task": "sideways"}, "sideways"), ({"max_iter": 0}, "max_iter")):
        with pytest.raises((InputError, InputTypeError), match=word):
            QPResolver(**kwargs)
    path = Path.from_points([[0.3, 0.1]])
    with pytest.raises(InputError, match="max_joint_step"):
        track(arm, path, "qp", max_joint_step=float("inf"))
    with pytest.raises(InputError, match="task"):
        track(arm, path, QPResolver(task="position"))
    with pytest.raises(InputError, match="target"):
        FrameTask(np.eye(3))
    with pytest.raises(InputError, match="q must be"):
        DiffIK(arm, [PostureTask(np.zeros(arm.n))]).step(np.full(arm.n, np.nan))
