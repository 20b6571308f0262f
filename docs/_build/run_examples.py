"""Run the example scripts: one function shared by the docs gallery and the test suite.

Each script runs in a folder of its own (its working directory and
``SERIALKIN_EXAMPLE_OUT``, matplotlib's Agg backend); what it wrote stays in
``<folder>/out`` and what it printed in ``stdout.txt`` / ``stderr.txt`` beside its exit
status in ``returncode``. The docs build (gen_pages.py) runs them itself, several at a
time, unless ``SERIALKIN_EXAMPLES_RAN`` names a folder where they already ran (the test
suite runs them once per test run and hands that folder to the docs build it tests).
"""

from __future__ import annotations

import os
from collections.abc import Iterable
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

from fresh_python import run_python

ROOT = Path(__file__).resolve().parents[2]
EXAMPLES = sorted((ROOT / "examples").glob("*.py"))
#: Longest an example may take [s].
TIMEOUT = 900


def run_example(script: Path, folder: Path) -> None:
    """Run ``script`` in ``folder`` (created): outputs in ``out/``, its streams and status.

    As ``python script`` in a process of its own (:func:`fresh_python.run_python`: a
    child of a fork server that has done the imports and numba's set-up already).
    """
    out = folder / "out"
    out.mkdir(parents=True, exist_ok=True)
    env = dict(os.environ, MPLBACKEND="Agg", SERIALKIN_EXAMPLE_OUT=str(out))
    stderr = folder / "stderr.txt"
    code = run_python(script=script, cwd=out, env=env, stdout=folder / "stdout.txt",
                      stderr=stderr, timeout=TIMEOUT)
    if code == -9:
        with stderr.open("a", encoding="utf-8") as f:
            f.write(f"\ntimed out after {TIMEOUT} s\n")
    (folder / "returncode").write_text(str(code))


def run_all(root: Path, scripts: Iterable[Path] = EXAMPLES, jobs: int | None = None) -> None:
    """Run every script into ``root/<stem>``, ``jobs`` at a time (default: the CPUs)."""
    scripts = list(scripts)
    cpus = len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else os.cpu_count()
    with ThreadPoolExecutor(max_workers=max(1, jobs or cpus or 1)) as pool:
        list(pool.map(lambda s: run_example(s, root / s.stem), scripts))
