"""Shared by the benchmark scripts: repeated timings, a busy core, the goals file.

Every figure is the **median over repeated runs** with its spread (the 10th–90th
percentile range of the runs, or min–max when fewer than 10), never the best run alone.
Scripts record the figures that the goals of issue 11 are judged on with :func:`record`;
``run_all.py`` collects them into one summary table (``SERIALKIN_BENCH_RESULTS`` names a
JSON-lines file; without it nothing is written).
"""

from __future__ import annotations

import contextlib
import json
import os
import subprocess
import sys
import time
import timeit
from collections.abc import Callable, Iterator
from pathlib import Path

import numpy as np
from threadpoolctl import threadpool_limits

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "src"))

# One BLAS thread in every benchmark process. OpenBLAS's worker threads keep spinning
# for a while after a call, so a peer that calls BLAS (the Pinocchio CLIK loop through
# numpy, ikpy through scipy) took a core away from the batch measured next: Panda's IK
# batch measured 5.62 [4.74-8.42] us per target after the CLIK rows against 4.40
# [4.33-4.53] with one BLAS thread (the kernels measured here use no BLAS; the peers'
# 6x7 matrices gain nothing from BLAS threads). The variable covers libraries loaded
# later (scipy's own OpenBLAS), threadpoolctl those already loaded (numpy's).
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
os.environ.setdefault("MKL_NUM_THREADS", "1")
threadpool_limits(limits=1, user_api="blas")


class Stat:
    """Median and spread of repeated measurements (any unit)."""

    def __init__(self, values: object) -> None:
        v = np.sort(np.asarray(values, dtype=float))
        self.values = v
        self.median = float(np.median(v))
        if v.size >= 10:
            self.lo, self.hi = (float(x) for x in np.percentile(v, [10, 90]))
        else:
            self.lo, self.hi = float(v[0]), float(v[-1])

    def fmt(self, digits: int = 3) -> str:
        """'median [lo–hi]'."""
        return f"{self.median:.{digits}f} [{self.lo:.{digits}f}–{self.hi:.{digits}f}]"

    def __truediv__(self, other: Stat) -> float:
        return self.median / other.median


def latency_us(fn: Callable[[], object], number: int, repeat: int = 15) -> Stat:
    """Time per call [µs] of ``fn()``: ``repeat`` runs of ``number`` calls each."""
    fn()
    return Stat(np.array(timeit.repeat(fn, number=number, repeat=repeat)) / number * 1e6)


def interleaved_us(fns: dict[str, Callable[[], object]], number: int,
                   repeat: int = 15) -> dict[str, Stat]:
    """:func:`latency_us` of several functions, their runs interleaved (same machine load)."""
    for f in fns.values():
        f()
    runs: dict[str, list[float]] = {k: [] for k in fns}
    for _ in range(repeat):
        for k, f in fns.items():
            runs[k].append(timeit.timeit(f, number=number) / number * 1e6)
    return {k: Stat(v) for k, v in runs.items()}


def wall_s(fn: Callable[[], object], repeat: int = 20) -> Stat:
    """Wall-clock seconds of ``fn()`` over ``repeat`` runs (after one untimed run)."""
    fn()
    out = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        fn()
        out.append(time.perf_counter() - t0)
    return Stat(out)


@contextlib.contextmanager
def busy_core() -> Iterator[None]:
    """Another process spinning on one core (a laptop, CI, a shared VM) while inside."""
    p = subprocess.Popen([sys.executable, "-c", "while True: pass"])
    try:
        time.sleep(0.3)
        yield
    finally:
        p.kill()
        p.wait()


def record(goal: str, measure: str, value: float, unit: str, target: str, met: bool) -> None:
    """Append one goal's measured figure to ``$SERIALKIN_BENCH_RESULTS`` (JSON lines)."""
    path = os.environ.get("SERIALKIN_BENCH_RESULTS")
    if not path:
        return
    with open(path, "a", encoding="utf-8") as f:
        f.write(json.dumps({"goal": goal, "measure": measure, "value": value, "unit": unit,
                            "target": target, "met": bool(met)}) + "\n")


def header() -> str:
    """One line: versions, CPUs, numba threads, load average."""
    import platform

    import numba

    import serialkin as sk

    load = os.getloadavg()[0] if hasattr(os, "getloadavg") else float("nan")
    return (f"serialkin {sk.__version__}, numpy {np.__version__}, numba {numba.__version__}, "
            f"Python {platform.python_version()}, {os.cpu_count()} CPUs, numba threads "
            f"{numba.get_num_threads()}, load average {load:.2f}")
