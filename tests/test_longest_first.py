"""The suite's scheduling list names files that exist."""

from __future__ import annotations

from pathlib import Path

from tests.conftest import LONGEST_FIRST

ROOT = Path(__file__).resolve().parents[1]


def test_every_file_listed_longest_first_exists():
    """Each entry of conftest.LONGEST_FIRST is a test file of the suite, listed once."""
    missing = [f for f in LONGEST_FIRST if not (ROOT / f).is_file()]
    assert not missing, missing
    assert len(set(LONGEST_FIRST)) == len(LONGEST_FIRST)
