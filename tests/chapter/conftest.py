"""The chapter report, built once per test session and shared by the tests that read it."""

from __future__ import annotations

import pytest


@pytest.fixture(scope="session")
def built_report(tmp_path_factory):
    """(output folder, report.html text) of one full build of the chapter report."""
    from serialkin.chapter.report import build_report

    out = tmp_path_factory.mktemp("chapter")
    path = build_report(out, quiet=True)
    return out, path.read_text(encoding="utf-8")
