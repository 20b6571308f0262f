"""The chapter report, built once per test run and shared by the tests that read it."""

from __future__ import annotations

import pytest


@pytest.fixture(scope="session")
def built_report(shared_once):
    """(output folder, report.html text) of one full build of the chapter report.

    Built once per run, also when pytest-xdist sends the files that read it to different
    workers (``shared_once`` in tests/conftest.py).
    """
    from serialkin.chapter.report import build_report

    out = shared_once("chapter-report", lambda folder: build_report(folder, quiet=True))
    return out, (out / "report.html").read_text(encoding="utf-8")
