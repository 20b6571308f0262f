"""The chapter report, built once per test run and shared by the tests that read it."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest


@pytest.fixture(scope="session")
def built_report(shared_once):
    """(output folder, report.html text) of one full build of the chapter report.

    Built once per run, also when pytest-xdist sends the files that read it to different
    workers (``shared_once`` in tests/conftest.py), by ``serialkin chapter`` in a fresh
    process, as ``make run`` builds it: a build inside a test worker sees what earlier
    tests left in that process (an IK method registered by a test, such as the "gradient"
    of docs/architecture.md's example, adds a row to the numerical section's comparison
    table that its Reproduce box, run in a fresh interpreter, does not print).
    """

    def build(folder: Path) -> None:
        env = {**os.environ, "SERIALKIN_COMPILE": "wait"}
        cli = Path(sys.executable).parent / "serialkin"
        res = subprocess.run([str(cli), "chapter", "--out", str(folder), "-q"], env=env,
                             capture_output=True, text=True, timeout=1800, check=False)
        assert res.returncode == 0, res.stderr[-4000:]

    out = shared_once("chapter-report", build)
    return out, (out / "report.html").read_text(encoding="utf-8")
