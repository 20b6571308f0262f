"""The batch scheduler: every item exactly once, results independent of threads and chunks."""

from __future__ import annotations

import threading

import numba
import numpy as np
import pytest
from numba import njit

from serialkin import models
from serialkin.errors import InputError
from serialkin.kinematics import parallel


@njit(nogil=True, cache=True)
def _count_range(hits, start, stop):
    for k in range(start, stop):
        hits[k] += 1


_FREE_CORES = parallel.free_cores  # the real one (the fixture below replaces it)


@pytest.fixture(autouse=True)
def _all_cores_free(monkeypatch):
    """Exercise the threaded path whatever else runs on the machine."""
    monkeypatch.setattr(parallel, "free_cores", lambda: 64)


def test_free_cores_is_a_positive_count():
    """free_cores() (the /proc/loadavg reading, cached 20 ms) is at least 1."""
    n = _FREE_CORES()
    assert isinstance(n, int) and 1 <= n <= 1 << 30


def test_no_free_core_runs_on_the_calling_thread(monkeypatch):
    """With no core free, a batch runs as one call on the calling thread."""
    monkeypatch.setattr(parallel, "free_cores", lambda: 1)
    calls = []
    parallel.run(lambda start, stop: calls.append((start, stop)), (), 10_000, 10)
    assert calls == [(0, 10_000)]


@pytest.mark.parametrize(("N", "grain"), [(0, 4), (1, 4), (7, 4), (8, 4), (1001, 16),
                                          (4096, 1)])
def test_every_item_is_processed_exactly_once(N, grain):
    """run() hands out [0, N) in chunks: each item once, serial and parallel sizes alike."""
    hits = np.zeros(N, dtype=np.int64)
    parallel.run(_count_range, (hits,), N, grain)
    assert np.all(hits == 1)


def test_kernel_errors_reach_the_caller():
    """An exception raised in any chunk, on any thread, is re-raised by run()."""
    def kernel(start, stop):
        if start <= 500 < stop:
            raise ValueError("chunk with item 500")

    with pytest.raises(ValueError, match="item 500"):
        parallel.run(kernel, (), 1000, 10)


@pytest.mark.parametrize("name", ["ur5", "panda", "scara"])
def test_parallel_batches_equal_single_calls_and_one_thread(name):
    """Split batches (FK, Jacobians, frames, point Jacobians, J̇) equal single and 1-thread runs."""
    robot = models.get(name)
    Q = robot.random_q(5000, seed=2)  # more than two FK chunks for n ≥ 3
    idx = [0, 1, 2047, 2048, 4095, 4999]
    calls = {
        "fk": lambda x: robot.fk(x),
        "jacobian": lambda x: robot.jacobian(x),
        "jacobian_ee": lambda x: robot.jacobian(x, "ee"),
        "point": lambda x: robot.jacobian(x, link=robot.n - 1, point=[0.1, 0.2, 0.0]),
        "fk_all": lambda x: robot.fk_all(x),
        "jdot": lambda x: robot.jacobian_dot(x, np.ones(robot.n)),
    }
    before = numba.get_num_threads()
    for f in calls.values():
        many = f(Q)
        np.testing.assert_allclose(many[idx], np.stack([f(Q[i]) for i in idx]), atol=1e-14)
        numba.set_num_threads(1)
        try:
            one_thread = f(Q)
        finally:
            numba.set_num_threads(before)
        assert np.array_equal(many, one_thread)


def test_out_buffers_are_filled_and_returned():
    """fk/jacobian with out= write into the caller's array (single and batch) and return it."""
    robot = models.panda()
    q = robot.random_q(seed=3)
    Q = robot.random_q((4, 5), seed=3)
    T, J = np.empty((4, 4)), np.empty((6, robot.n))
    assert robot.fk(q, out=T) is T and np.array_equal(T, robot.fk(q))
    assert robot.jacobian(q, out=J) is J and np.array_equal(J, robot.jacobian(q))
    TB, JB = np.empty((4, 5, 4, 4)), np.empty((4, 5, 6, robot.n))
    assert robot.fk(Q, out=TB) is TB and np.array_equal(TB, robot.fk(Q))
    assert robot.jacobian(Q, "ee", out=JB) is JB
    assert np.array_equal(JB, robot.jacobian(Q, "ee"))


@pytest.mark.parametrize("bad", [np.empty((4, 3)), np.empty((4, 4), dtype=np.float32),
                                 np.empty((4, 8))[:, ::2], "T", None])
def test_bad_out_buffers_are_refused(bad):
    """A buffer of the wrong shape, dtype, layout or type: InputError naming out."""
    robot = models.ur5()
    if bad is None:
        bad = np.empty((4, 4))
        bad.setflags(write=False)
    with pytest.raises(InputError, match="out"):
        robot.fk(robot.random_q(seed=1), out=bad)
    with pytest.raises(InputError, match="out"):
        robot.jacobian(robot.random_q(seed=1), out=bad)


@pytest.mark.parametrize("make", [models.ur5, lambda: models.planar(2)])
def test_single_call_fast_path_converts_other_arrays(make):
    """Integer, float32, (n, 1) and strided q give the float64 answer (never bits reinterpreted)."""
    robot = make()
    n = robot.n
    q = np.arange(1, n + 1, dtype=float) / 4
    T, J = robot.fk(q), robot.jacobian(q)
    for other in (np.arange(1, n + 1), q.astype(np.float32), np.repeat(q, 2)[::2]):
        expect = (q if other.dtype.kind == "f" and other.dtype.itemsize == 8
                  else other.astype(float))
        np.testing.assert_allclose(robot.fk(other), robot.fk(expect.copy()), atol=1e-6)
        np.testing.assert_allclose(robot.jacobian(other), robot.jacobian(expect.copy()),
                                   atol=1e-6)
    np.testing.assert_allclose(robot.fk(np.arange(1, n + 1)), robot.fk(np.arange(1.0, n + 1)))
    column = q.reshape(n, 1)  # (n, 1) is a batch of n one-value rows: refused, not misread
    with pytest.raises(InputError):
        robot.fk(column)
    assert robot.fk(q[None]).shape == (1, 4, 4) and np.array_equal(robot.fk(q[None])[0], T)
    assert np.array_equal(robot.jacobian(q[None])[0], J)


@pytest.mark.parametrize(("N", "grain", "threads"), [(100_000, 2048, 2), (10_000, 16, 4),
                                                     (4097, 2048, 2), (9, 4, 8)])
def test_guided_chunks_shrink_to_the_grain(N, grain, threads, monkeypatch):
    """Chunks tile [0, N) in claim order, each max(grain, remaining/(2·participants)) items."""
    monkeypatch.setattr(parallel, "threads", lambda: threads)
    calls = []
    lock = threading.Lock()

    def kernel(start, stop):
        with lock:
            calls.append((start, stop))

    parallel.run(kernel, (), N, grain)
    calls.sort()
    assert calls[0][0] == 0 and calls[-1][1] == N
    assert all(a[1] == b[0] for a, b in zip(calls, calls[1:]))
    participants = min(threads, N // grain)
    for start, stop in calls:
        assert stop - start == min(N - start, max(grain, (N - start) // (2 * participants)))
    if N >= 8 * grain * participants:
        assert len(calls) < N / grain / 2  # far fewer hand-offs than fixed-grain chunks


def test_min_items_keeps_a_batch_on_the_calling_thread():
    """run(..., min_items=M) makes one call on the calling thread for fewer than M items."""
    calls = []
    parallel.run(lambda start, stop: calls.append((start, stop, threading.get_ident())), (),
                 1000, 10, min_items=1001)
    assert calls == [(0, 1000, threading.get_ident())]


def test_small_ik_batches_do_not_wake_a_worker(monkeypatch):
    """IK batches below PARALLEL_MIN_TARGETS never use the pool; larger ones do (2 threads)."""
    from serialkin.ik import solver

    monkeypatch.setattr(parallel, "threads", lambda: 2)
    used = []
    real_pool = parallel._pool
    monkeypatch.setattr(parallel, "_pool", lambda workers: used.append(workers) or
                        real_pool(workers))
    robot = models.ur5()
    for N, pooled in ((solver.PARALLEL_MIN_TARGETS - 1, False),
                      (solver.PARALLEL_MIN_TARGETS, True)):
        used.clear()
        Q = robot.random_q(N, seed=4)
        res = robot.ik(robot.fk(Q), q0=robot.random_q(N, seed=5), seed=0)
        assert bool(used) is pooled and res.success.all()
