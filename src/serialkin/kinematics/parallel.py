"""Batches across cores: the one scheduler of every batch kernel.

Every batch in serialkin — forward kinematics, Jacobians, Hessians, IK, workspace
sampling (which calls the FK and Jacobian batches) — is a compiled *range kernel*
``kernel(*args, start, stop)`` that processes items ``start..stop-1`` with the GIL
released (``@njit(nogil=True)``), and :func:`run` hands the range out to the cores.

Why not numba's ``prange``: its OpenMP and workqueue back ends cut the range into one
static share per thread and the caller waits for every share. When another process
keeps a core busy (a laptop, CI, a shared VM), the thread that shares that core gets
half of it, and the whole batch waits for its share: measured 1.7–2.2× *slower* than
one thread on the free core. :func:`run` instead

* hands the range out in chunks that the participants claim one at a time from a
  shared counter (dynamic scheduling), so a slowed-down thread simply takes fewer
  chunks. The chunks are *guided*: a claim takes ``max(grain, remaining // (2·P))``
  items (P participants), so a batch starts with large chunks — few returns to Python
  between chunks, each a GIL hand-off of a few µs — and ends with ``grain``-sized
  ones, so that the participants finish together. A 100,000-pose FK batch on two
  threads takes 13 chunks instead of 49 of a fixed 2,048 poses. A thread descheduled
  while it holds a chunk delays the batch by at most that chunk (at most a quarter of
  the batch on two threads, the first; late chunks are one grain);
* makes the calling thread a participant, so that the batch never waits for a worker
  thread that has not been scheduled yet: the caller waits only for chunks already
  claimed and still running;
* runs small batches (fewer than two grains, or fewer than the caller's
  ``min_items``) on the calling thread alone. Waking a worker and waiting for its last
  chunk cost 50–300 µs on a 2-vCPU VM (``pool.submit`` about 50 µs, the caller's own
  wake-up at the end up to 140 µs): an IK batch, whose targets vary in cost, of 16 and
  40 targets took 2.2× and 1.5× *longer* on two threads than on one, and of 100
  targets as long; so IK batches pass ``min_items`` (see
  :data:`serialkin.ik.solver.PARALLEL_MIN_TARGETS`);
* uses only the cores other processes leave free (as OpenMP's ``OMP_DYNAMIC`` does): on
  Linux it reads the number of runnable tasks from ``/proc/loadavg`` (at most every
  20 ms) and counts as free the usable CPUs minus the other runnable tasks. On a 2-core
  machine with one core kept busy, two threads would share the free core while the
  busy process keeps the other (measured 0.88–0.95× one thread), so the batch runs on
  the calling thread alone there.

The number of threads is at most ``numba.get_num_threads()`` (``NUMBA_NUM_THREADS``,
``numba.set_num_threads``); the worker threads live in one pool, created on first use.
"""

from __future__ import annotations

import os
import threading
import time
from collections.abc import Callable
from concurrent.futures import ThreadPoolExecutor
from typing import Any

#: Worker pools by number of workers, created on first use (never at import).
_POOLS: dict[int, ThreadPoolExecutor] = {}
_POOL_LOCK = threading.Lock()
if hasattr(os, "register_at_fork"):  # a forked child starts without the parent's threads
    os.register_at_fork(after_in_child=_POOLS.clear)


def threads() -> int:
    """Number of threads a batch may use: ``numba.get_num_threads()`` (at least 1)."""
    import numba

    return max(1, int(numba.get_num_threads()))


_CPUS = len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else os.cpu_count()
#: [time of the last reading, free cores then]
_FREE = [-1.0, 1 << 30]
#: Guided schedule: a claim takes 1 / (_SPLIT · participants) of the remaining items.
_SPLIT = 2


def free_cores() -> int:
    """CPUs this process may use minus the other runnable tasks (Linux; else all CPUs).

    The 4th field of ``/proc/loadavg`` counts the runnable tasks system-wide at the time
    of reading, the calling thread included. Read at most every 20 ms.
    """
    now = time.monotonic()
    if now - _FREE[0] < 0.02:
        return _FREE[1]
    free = _CPUS or 1
    try:
        with open("/proc/loadavg", "rb") as f:
            running = int(f.read().split()[3].split(b"/")[0])
        free = max(1, free - (running - 1))
    except (OSError, ValueError, IndexError):
        pass
    _FREE[0], _FREE[1] = now, free
    return free


def _pool(workers: int) -> ThreadPoolExecutor:
    pool = _POOLS.get(workers)
    if pool is None:
        with _POOL_LOCK:
            pool = _POOLS.get(workers)
            if pool is None:
                pool = _POOLS[workers] = ThreadPoolExecutor(
                    max_workers=workers, thread_name_prefix="serialkin-batch")
    return pool


class _Job:
    """One batch: the next unclaimed item, the count of claimed unfinished chunks, an error slot."""

    __slots__ = ("kernel", "args", "N", "grain", "split", "next", "lock", "running",
                 "idle", "error")

    def __init__(self, kernel: Callable[..., Any], args: tuple, N: int, grain: int,
                 participants: int) -> None:
        self.kernel, self.args, self.N, self.grain = kernel, args, N, grain
        self.split = _SPLIT * participants
        self.next = 0
        self.lock = threading.Lock()
        self.running = 0
        self.idle = threading.Event()
        self.error: BaseException | None = None

    def work(self) -> None:
        """Claim and run chunks until none is left (called by every participant).

        A claim takes ``max(grain, remaining // split)`` items (guided schedule).
        """
        kernel, args, N, grain, split, lock = (self.kernel, self.args, self.N, self.grain,
                                               self.split, self.lock)
        while True:
            with lock:
                start = self.next
                if start >= N or self.error is not None:
                    return
                stop = min(N, start + max(grain, (N - start) // split))
                self.next = stop
                self.running += 1
            try:
                kernel(*args, start, stop)
            except BaseException as exc:  # re-raised by the caller
                self.error = exc
            with lock:
                self.running -= 1
                if self.running == 0:
                    self.idle.set()


def run(kernel: Callable[..., Any], args: tuple, N: int, grain: int,
        min_items: int = 0) -> None:
    """Run ``kernel(*args, start, stop)`` over items 0..N-1 on every thread, chunk by chunk.

    Args:
        kernel: a compiled range kernel that releases the GIL and writes disjoint outputs
            for disjoint ranges.
        args: its arguments before ``start, stop``.
        N: number of items.
        grain: the smallest chunk (and the last chunks' size, see the guided schedule in
            the module docstring); pick ~50-100 µs of work, so that a chunk costs far
            more than claiming it (~2 µs) and a late chunk delays the batch little.
        min_items: the smallest batch worth waking a worker for (for kernels whose
            items vary in cost, where two grains are not enough; see above).

    Batches of fewer than two grains or ``min_items`` items, and every batch when one
    thread is configured, run on the calling thread. Exceptions raised by the kernel
    are re-raised here.
    """
    grain = max(1, int(grain))
    if N < 2 * grain or N < min_items:
        kernel(*args, 0, N)
        return
    nthreads = min(threads(), free_cores())
    if nthreads == 1:
        kernel(*args, 0, N)
        return
    participants = min(nthreads, N // grain)
    job = _Job(kernel, args, N, grain, participants)
    pool = _pool(nthreads - 1)
    for _ in range(participants - 1):
        pool.submit(job.work)
    job.work()
    with job.lock:
        wait = job.running > 0
        if wait:
            job.idle.clear()
    if wait:
        job.idle.wait()
    if job.error is not None:
        raise job.error


_BLAS_CONTROLLER: list[Any] = []


def single_threaded_blas() -> Any:
    """Context manager limiting BLAS (numpy/scipy linear algebra) to one thread inside it.

    Small dense problems (scipy's L-BFGS-B on n-vectors, the SVDs and least squares of a
    calibration) pay for waking a BLAS thread pool on every call, and that pool competes
    with numba's threads: measured 225 ms vs 9 ms per planar 3-link minimisation, and
    10-40× slower calibration SVDs, on 2 shared cores. ``with single_threaded_blas(): ...``
    """
    if not _BLAS_CONTROLLER:
        from threadpoolctl import ThreadpoolController

        _BLAS_CONTROLLER.append(ThreadpoolController())
    return _BLAS_CONTROLLER[0].limit(limits=1, user_api="blas")
