"""Batch IK: (N, 4, 4) targets solved in the compiled batch kernel across the cores."""

from __future__ import annotations

import numpy as np
import pytest

from serialkin import models
from serialkin.ik import IKResult

from .conftest import assert_reaches, reachable


@pytest.mark.parametrize("method", ["lm", "dls", "sdls"])
def test_batch_equals_single(method, puma):
    """Each batch entry equals the single solve with the same seed (restarts included)."""
    q, targets = reachable(puma, 12, seed=71)
    batch = puma.ik(targets, method=method, seed=99)
    assert batch.batch and len(batch) == 12
    assert batch.q.shape == (12, 6)
    for k, T in enumerate(targets):
        single = puma.ik(T, method=method, seed=99)
        assert np.array_equal(batch.q[k], single.q)
        assert batch.success[k] == single.success
        assert batch.iterations[k] == single.iterations
        assert batch.restarts[k] == single.restarts
        assert batch.reason[k] == single.reason
        assert batch[k].position_error == single.position_error


def test_batch_with_initial_guesses(panda):
    """(N, n) and (n,) initial guesses are used per target; all targets are reached."""
    q, targets = reachable(panda, 20, seed=72)
    q0 = panda.random_q(20, seed=73)
    res = panda.ik(targets, q0=q0, seed=1)
    for k, T in enumerate(targets):
        assert_reaches(panda, res[k], T)
        assert np.array_equal(res.q[k], panda.ik(T, q0=q0[k], seed=1).q)
    shared = panda.ik(targets, q0=q0[0], seed=1)
    assert np.array_equal(shared.q[3], panda.ik(targets[3], q0=q0[0], seed=1).q)


def test_batch_result_types(ur5):
    """Batch results hold arrays of the documented dtypes and shapes."""
    _, targets = reachable(ur5, 5, seed=74)
    res = ur5.ik(targets, seed=2)
    assert isinstance(res, IKResult)
    assert res.success.dtype == bool and res.success.shape == (5,)
    assert res.iterations.dtype == np.int64 and res.restarts.dtype == np.int64
    assert res.position_error.shape == (5,) and res.orientation_error.shape == (5,)
    assert res.reason.shape == (5,) and all(r == "" for r in res.reason)
    assert "batch of 5" in repr(res)


def test_batch_same_seed_same_answer(ur5):
    """Two batch solves with the same seed are identical; the parallel order does not matter."""
    _, targets = reachable(ur5, 40, seed=75)
    a = ur5.ik(targets, seed=7)
    b = ur5.ik(targets, seed=7)
    assert np.array_equal(a.q, b.q)
    assert np.array_equal(a.iterations, b.iterations)


def test_batch_with_unreachable_entries(puma):
    """Unreachable entries fail with a reason while the others succeed."""
    _, targets = reachable(puma, 6, seed=76)
    targets = targets.copy()
    targets[2, :3, 3] = [4.0, 0.0, 0.0]
    res = puma.ik(targets, seed=3, restarts=10)
    assert not res.success[2] and "no configuration" in res.reason[2]
    assert res.success[[0, 1, 3, 4, 5]].all()
    assert np.isfinite(res.q).all() and puma.within_limits(res.q).all()


def test_batch_positions_and_planar(puma, planar6):
    """(N, 3) position targets and (N, 2) planar targets are batches too."""
    q, targets = reachable(puma, 8, seed=77)
    res = puma.ik(targets[:, :3, 3], seed=4)
    assert res.success.all()
    assert np.allclose(puma.fk(res.q)[:, :3, 3], targets[:, :3, 3], atol=1e-6)
    q, targets = reachable(planar6, 8, seed=78)
    res = planar6.ik(targets[:, :2, 3], seed=5)
    assert res.success.all()
    assert np.allclose(planar6.fk(res.q)[:, :2, 3], targets[:, :2, 3], atol=1e-6)


def test_batch_single_target_in_batch_form(ur5):
    """A (1, 4, 4) target gives a batch result of length 1."""
    _, targets = reachable(ur5, 1, seed=79)
    res = ur5.ik(targets, seed=6)
    assert res.batch and res.q.shape == (1, 6)
    assert np.array_equal(res.q[0], ur5.ik(targets[0], seed=6).q)


def test_batch_readonly_inputs(ur5):
    """Read-only target and q0 arrays are accepted (copied for the kernel)."""
    _, targets = reachable(ur5, 3, seed=80)
    targets.setflags(write=False)
    q0 = ur5.random_q(3, seed=81)
    q0.setflags(write=False)
    res = ur5.ik(targets, q0=q0, seed=0)
    assert res.success.all()
    single = ur5.ik(targets[1], q0=q0[1], seed=0)
    assert np.array_equal(single.q, res.q[1])


def test_large_batch_solves():
    """1,000 UR5 targets: at least 99.9 % solved, each within its budget.

    The speed of a large batch is measured by ``benchmarks/bench_ik.py``, not asserted.
    """
    robot = models.ur5()
    _, targets = reachable(robot, 1000, seed=82)
    res = robot.ik(targets, seed=0)
    assert res.success.mean() >= 0.999
    from serialkin.ik.registry import get_method

    assert (res.restarts <= get_method("lm").restarts).all() and np.isfinite(res.q).all()


def test_batch_result_indexing_takes_one_integer():
    """A batch IKResult indexes by an int; a mask or a single result gives InputTypeError."""
    from serialkin.errors import InputTypeError

    robot = models.get("ur5")
    res = robot.ik(robot.fk(robot.random_q(3, seed=0)), seed=0)
    assert res[1].success == bool(res.success[1])
    with pytest.raises(InputTypeError, match="result.q\\[result.success\\]"):
        res[res.success]
    with pytest.raises(InputTypeError, match="single"):
        res[0][0]
