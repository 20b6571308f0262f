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
import subprocess
import sys
from collections.abc import Iterable
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
EXAMPLES = sorted((ROOT / "examples").glob("*.py"))
#: Longest an example may take [s].
TIMEOUT = 900


def run_example(script: Path, folder: Path) -> None:
    """Run ``script`` in ``folder`` (created): outputs in ``out/``, its streams and status."""
    out = folder / "out"
    out.mkdir(parents=True, exist_ok=True)
    env = dict(os.environ, MPLBACKEND="Agg", SERIALKIN_EXAMPLE_OUT=str(out))
    try:
        proc = subprocess.run([sys.executable, str(script)], cwd=out, env=env,
                              capture_output=True, text=True, timeout=TIMEOUT)
        code, stdout, stderr = proc.returncode, proc.stdout, proc.stderr
    except subprocess.TimeoutExpired as exc:
        code, stdout, stderr = -1, str(exc.stdout or ""), f"timed out after {TIMEOUT} s"
    (folder / "stdout.txt").write_text(stdout, encoding="utf-8")
    (folder / "stderr.txt").write_text(stderr, encoding="utf-8")
    (folder / "returncode").write_text(str(code))


def run_all(root: Path, scripts: Iterable[Path] = EXAMPLES, jobs: int | None = None) -> None:
    """Run every script into ``root/<stem>``, ``jobs`` at a time (default: the CPUs)."""
    scripts = list(scripts)
    cpus = len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else os.cpu_count()
    with ThreadPoolExecutor(max_workers=max(1, jobs or cpus or 1)) as pool:
        list(pool.map(lambda s: run_example(s, root / s.stem), scripts))
