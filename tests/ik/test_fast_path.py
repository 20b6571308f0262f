"""The fast path of ``robot.ik`` for one (4, 4) pose gives the ordinary path's answer."""

from __future__ import annotations

import numpy as np
import pytest

from serialkin import models
from serialkin.errors import InputError
from serialkin.ik import solver


def _same(a, b):
    """True when two single results agree field by field (q bit for bit)."""
    return (np.array_equal(a.q, b.q) and a.success == b.success
            and a.iterations == b.iterations and a.restarts == b.restarts
            and a.position_error == b.position_error
            and a.orientation_error == b.orientation_error and a.reason == b.reason
            and a.method == b.method)


@pytest.mark.parametrize("name", ["ur5", "panda"])
def test_fast_equals_ordinary(name):
    """A writeable pose (fast path) and a read-only copy (ordinary path) give one answer."""
    robot = models.get(name)
    Q = robot.random_q(6, seed=4)
    Q0 = robot.random_q(6, seed=5)
    for k in range(6):
        T = np.ascontiguousarray(robot.fk(Q[k]))
        frozen = T.copy()
        frozen.setflags(write=False)
        for q0 in (None, Q0[k]):
            fast = robot.ik(T, q0=q0, seed=k)
            slow = robot.ik(frozen, q0=q0, seed=k)
            assert _same(fast, slow)
            assert solver._fast(robot, T, "lm", q0, k) is not None


def test_fast_path_declines_what_it_does_not_check():
    """Bad poses and q0 outside the limits fall back to the ordinary path's errors."""
    ur5 = models.ur5()
    T = ur5.fk(np.zeros(6))
    bad = T.copy()
    bad[0, 0] = 2.0
    assert solver._fast(ur5, bad, "lm", None, 0) is None
    with pytest.raises(InputError, match="target"):
        ur5.ik(bad)
    q0 = np.full(6, 7.0)
    assert solver._fast(ur5, T, "lm", q0, 0) is None
    with pytest.raises(InputError, match="q0 is outside the joint limits"):
        ur5.ik(T, q0=q0)
    assert solver._fast(ur5, T, "ccd", None, 0) is None
    assert solver._fast(ur5, T, "lm", None, np.random.default_rng(0)) is None


def test_fast_path_seed_above_int64():
    """A seed ≥ 2⁶³ reaches the kernel as the same 64 bits on the fast and ordinary paths."""
    ur5 = models.ur5()
    T = np.ascontiguousarray(ur5.fk(ur5.random_q(seed=8)))
    frozen = T.copy()
    frozen.setflags(write=False)
    for seed in (2**63, 2**64 - 1, -1):
        fast = ur5.ik(T, seed=seed)
        assert solver._fast(ur5, T, "lm", None, seed) is not None
        assert _same(fast, ur5.ik(frozen, seed=seed))


def test_fast_path_failure_equals_ordinary():
    """An unreachable pose fails on the fast path with the ordinary path's result and reason."""
    ur5 = models.ur5()
    T = np.eye(4)
    T[:3, 3] = (3.0, 0.0, 0.5)  # far beyond the UR5's reach
    frozen = T.copy()
    frozen.setflags(write=False)
    fast = ur5.ik(T, seed=1)
    slow = ur5.ik(frozen, seed=1)
    assert not fast.success
    assert "out of reach" in fast.reason
    assert _same(fast, slow)


def test_fast_path_declines_other_types_and_shapes():
    """Poses of other layouts are copied into the fast path, strided q0 goes the other way.

    Read-only arrays take the fast path. Either way the answer is the same.
    """
    ur5 = models.ur5()
    T = np.ascontiguousarray(ur5.fk(ur5.random_q(seed=3)))
    q0 = ur5.random_q(seed=6)
    ref = ur5.ik(T, q0=q0, seed=2)
    frozen_q0 = q0.copy()
    frozen_q0.setflags(write=False)
    frozen_T = T.copy()
    frozen_T.setflags(write=False)
    strided_q0 = np.ascontiguousarray(np.stack([q0, q0]).T)[:, 0]
    assert solver._fast(ur5, T, "lm", strided_q0, 2) is None
    assert _same(ur5.ik(T, q0=strided_q0, seed=2), ref)
    copied = [np.asfortranarray(T),  # F layout, as the Robotics Toolbox returns poses
              np.ascontiguousarray(np.stack([T, T], axis=-1))[..., 0]]  # strided
    for Tv in copied:
        assert _same(solver._fast(ur5, Tv, "lm", q0, 2), ref)
        assert _same(ur5.ik(Tv, q0=q0, seed=2), ref)
    for Tv, qv in ((T, frozen_q0), (frozen_T, q0)):  # read-only: only read
        assert _same(solver._fast(ur5, Tv, "lm", qv, 2), ref)
    T32 = T.astype(np.float32)
    assert _same(solver._fast(ur5, T32, "lm", q0, 2), ur5.ik(T32.astype(float), q0=q0, seed=2))
    assert solver._fast(ur5, T, "lm", q0.astype(np.int64), 2) is None
    assert solver._fast(ur5, T, "lm", q0[:5].copy(), 2) is None
    assert solver._fast(ur5, T[:3].copy(), "lm", None, 2) is None
    with pytest.raises(InputError, match="q0"):
        ur5.ik(T, q0=q0[:5].copy())
    with pytest.raises(InputError, match="target"):
        ur5.ik(T[:3].copy())


def test_robot_pickles_after_fast_solves():
    """A robot that has used the fast path pickles and solves alike; its entries die with it.

    The solver keeps its prepared entries per robot (``solver._FAST_ENTRIES``), never on
    the robot (issue 28): a pickled copy carries none, and a dropped robot leaves none.
    """
    import gc
    import pickle

    from serialkin.ik import solver

    ur5 = models.ur5()
    T = np.ascontiguousarray(ur5.fk(ur5.random_q(seed=3)))
    ref = ur5.ik(T, seed=4)
    assert solver._FAST_ENTRIES.get(ur5)  # the fast path prepared its entry
    assert "_ik_fast" not in vars(ur5)
    copy = pickle.loads(pickle.dumps(ur5))
    assert solver._FAST_ENTRIES.get(copy) is None
    assert _same(copy.ik(T, seed=4), ref)
    gc.collect()  # robots of earlier tests that are already garbage go first
    before = len(solver._FAST_ENTRIES)
    del copy
    gc.collect()
    assert len(solver._FAST_ENTRIES) == before - 1


def _ordinary(robot, target, method, q0, seed):
    """The ordinary path of ``robot.ik`` (every argument parsed), skipping the fast one."""
    return solver._solve_checked(robot, target, method, solver._Request(
        q0=q0, mask=None, tol=None, max_iter=None, restarts=None, seed=seed,
        respect_limits=True, scene=None, self_collision=False, margin=0.0, acm=None,
        options={}))


def _identical(a, b):
    """Two single results agree in every field and type, q bit for bit (zero signs too)."""
    return (_same(a, b) and np.array_equal(np.signbit(a.q), np.signbit(b.q))
            and a.q.shape == b.q.shape and a.q.dtype == b.q.dtype
            and all(type(getattr(a, f)) is type(getattr(b, f))
                    for f in ("success", "iterations", "position_error", "reason", "restarts"))
            and a.clearance == b.clearance and a.closest_pair == b.closest_pair)


def _analytic_robots():
    """Arms with a closed form: UR5 (±2π), PUMA 560, UR5 with joint 1 in [-3π, π], Stanford.

    The third one's middle of the ranges is not zero; the Stanford arm's third joint
    slides (never moved by a turn).
    """
    ur5 = models.ur5()
    lim = ur5.qlim.copy()
    lim[0] = (-3 * np.pi, np.pi)
    return [ur5, models.puma560(), ur5.with_limits(lim), models.get("stanford")]


@pytest.mark.parametrize("k", range(4))
def test_analytic_fast_path_equals_ordinary(k):
    """method='analytic' on one pose: the fast path answers exactly as the ordinary path.

    Over random reachable poses, poses out of reach and poses reachable only outside the
    limits, with q0 None, q0 inside the limits and q0 a whole turn away (the 2π
    representatives of with_nearest_turns), seeds None and int.
    """
    robot = _analytic_robots()[k]
    rng = np.random.default_rng(10 + k)
    Q = robot.random_q(40, seed=11 + k)
    poses = [np.ascontiguousarray(robot.fk(q)) for q in Q]
    far = np.eye(4)
    far[:3, 3] = (3.0, 0.2, 0.4)
    poses.append(far)
    wide = solver._wide(robot)
    taken = 0
    for i, T in enumerate(poses):
        q0s = [None, robot.random_q(seed=100 + i)]
        if wide is not False:  # a q0 a turn off where that stays inside the limits
            q, lo, hi = Q[i % len(Q)], robot.qlim[:, 0], robot.qlim[:, 1]
            up, down = q + 2 * np.pi, q - 2 * np.pi
            q0s.append(np.where(wide & (up <= hi), up,
                                np.where(wide & (down >= lo), down, q)))
        for q0 in q0s:
            for seed in (None, int(rng.integers(1 << 40))):
                fast = robot.ik(T, method="analytic", q0=q0, seed=seed)
                assert solver._fast(robot, T, "analytic", q0, seed) is not None
                taken += 1
                assert _identical(fast, _ordinary(robot, T, "analytic", q0, seed)), (i, q0)
    assert taken > 100


def test_analytic_fast_path_failures_and_errors_equal_ordinary():
    """Unreachable poses fail with the ordinary reason; bad input raises the ordinary error."""
    ur5 = models.ur5()
    far = np.eye(4)
    far[:3, 3] = (3.0, 0.0, 0.5)
    res = ur5.ik(far, method="analytic")
    assert not res.success and res.reason
    assert _identical(res, _ordinary(ur5, far, "analytic", None, None))
    T = np.ascontiguousarray(ur5.fk(ur5.random_q(seed=2)))
    bad_pose = T.copy()
    bad_pose[0, 0] = 2.0
    assert solver._fast(ur5, bad_pose, "analytic", None, None) is None
    for target, q0 in ((bad_pose, None), (T, np.full(6, 7.0)), (T, np.zeros(5)),
                       (T, [0.0, 0.0, np.nan, 0.0, 0.0, 0.0]), (bad_pose, np.full(6, 7.0))):
        with pytest.raises(InputError) as fast:
            ur5.ik(target, method="analytic", q0=q0)
        with pytest.raises(InputError) as ordinary:
            _ordinary(ur5, target, "analytic", q0, None)
        assert str(fast.value) == str(ordinary.value)
    panda = models.panda()  # 7 joints: no closed form, the same error either way
    Tp = np.ascontiguousarray(panda.fk(panda.random_q(seed=1)))
    messages = []
    for call in (lambda: panda.ik(Tp, method="analytic"),
                 lambda: _ordinary(panda, Tp, "analytic", None, None)):
        with pytest.raises(Exception) as err:  # noqa: PT011 (compared below)
            call()
        messages.append((type(err.value), str(err.value)))
    assert messages[0] == messages[1]
    # a Generator seed is drawn from on the ordinary path: the fast path declines it
    assert solver._fast(ur5, T, "analytic", None, np.random.default_rng(0)) is None


def test_analytic_fast_path_other_layouts():
    """Fortran-ordered, float32 and read-only poses and list q0 give the ordinary answer."""
    ur5 = models.ur5()
    T = np.ascontiguousarray(ur5.fk(ur5.random_q(seed=5)))
    q0 = ur5.random_q(seed=6)
    frozen = T.copy()
    frozen.setflags(write=False)
    for Tv in (np.asfortranarray(T), T.astype(np.float32), frozen):
        for qv in (None, q0, list(q0)):
            assert _identical(ur5.ik(Tv, method="analytic", q0=qv, seed=1),
                              _ordinary(ur5, Tv, "analytic", qv, 1))


def test_solve_pose_needs_solve():
    """A method spec with ``solve_pose`` but no ``solve`` is refused (the batch path needs it)."""
    from serialkin.ik.registry import MethodSpec

    with pytest.raises(InputError, match="solve_pose goes with solve"):
        MethodSpec(name="_x", family="analytic", summary="", limits="",
                   attempt=lambda *a: None, solve_pose=lambda *a: None)


@pytest.mark.parametrize("robot", _analytic_robots(), ids=lambda r: r.name)
def test_lm_fast_path_turns_wide_joints_as_the_ordinary_path(robot):
    """The lm fast path's 2π choice on joints wider than a turn is the ordinary path's.

    The compiled loop turns each wide joint nearest q0, or nearest zero without one
    (``_kernels._tidy``); the ordinary path then applies ``with_nearest_turns``, the
    Python rule. Both answers must agree bit for bit, with and without q0 (q0 drawn
    anywhere inside the limits, so that joints must move by whole turns).
    """
    rng = np.random.default_rng(11)
    Q = robot.random_q(12, seed=5)
    T = robot.fk(Q)
    lo, hi = robot.qlim[:, 0], robot.qlim[:, 1]
    for k in range(Q.shape[0]):
        Tk = np.ascontiguousarray(T[k])
        for q0 in (None, rng.uniform(lo, hi)):
            fast = solver._fast(robot, Tk, "lm", q0, k)
            assert fast is not None
            assert _identical(fast, _ordinary(robot, Tk, "lm", q0, k))
