"""The chapter report, built once per test run and shared by the tests that read it."""

from __future__ import annotations

import json
import os
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

from serialkin.chapter.report import SECTION_MODULES, build_provenance

ROOT = Path(__file__).resolve().parents[2]


@pytest.fixture(scope="session")
def built_report(shared_once):
    """(output folder, report.html text) of one full build of the chapter report.

    Built once per run, also when pytest-xdist sends the files that read it to different
    workers (``shared_once`` in tests/conftest.py), by ``serialkin chapter`` in a fresh
    process, as ``make run`` builds it: a build inside a test worker sees what earlier
    tests left in that process (an IK method registered by a test, such as the "gradient"
    of docs/architecture.md's example, adds a row to the numerical section's comparison
    table that its Reproduce box, run in a fresh interpreter, does not print).

    When ``make run`` has built ``out/chapter`` from these very sources with these
    library versions (its ``build.json`` equals :func:`build_provenance` of every
    section), that build is the one tested (copied): the same command on the same inputs.
    """

    def build(folder: Path) -> None:
        made = ROOT / "out" / "chapter"
        try:
            recorded = json.loads((made / "build.json").read_text(encoding="utf-8"))
        except (OSError, ValueError):
            recorded = None
        if recorded == build_provenance(SECTION_MODULES):
            shutil.copytree(made, folder, dirs_exist_ok=True)
            return
        env = {**os.environ, "SERIALKIN_COMPILE": "wait"}
        cli = Path(sys.executable).parent / "serialkin"
        res = subprocess.run([str(cli), "chapter", "--out", str(folder), "-q"], env=env,
                             capture_output=True, text=True, timeout=1800, check=False)
        assert res.returncode == 0, res.stderr[-4000:]

    out = shared_once("chapter-report", build)
    return out, (out / "report.html").read_text(encoding="utf-8")
