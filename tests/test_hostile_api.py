"""Hostile input to the public API (issue 10): a clear serialkin error or a correct result."""

from __future__ import annotations

import collections

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from serialkin._checks import short_repr


def _alias_bomb(depth: int = 30, width: int = 9) -> list:
    """A list whose items are the same list, ``depth`` times: width**depth leaves if expanded."""
    a: list = ["lol"] * width
    for _ in range(depth):
        a = [a] * width
    return a


@pytest.mark.parametrize(
    "value",
    [
        _alias_bomb(),
        {str(i): i for i in range(200_000)},
        collections.OrderedDict((i, i) for i in range(200_000)),
        10**100_000,
        "x" * 1_000_000,
        np.zeros((2000, 2000)),
        range(10**12),
    ],
    ids=["alias-bomb", "big-dict", "ordered-dict", "huge-int", "long-str", "array", "range"],
)
def test_short_repr_bounded(value):
    """short_repr of a huge or alias-expanded value is at most `limit` characters."""
    for limit in (20, 80, 200):
        assert len(short_repr(value, limit)) <= limit


@given(st.recursive(st.none() | st.booleans() | st.integers() | st.floats() | st.text(),
                    lambda c: st.lists(c) | st.dictionaries(st.text(), c), max_leaves=30))
def test_short_repr_small_values_exact(value):
    """A small value's short_repr is its repr when that fits, else a prefix ending in '...'."""
    text = short_repr(value, 80)
    assert len(text) <= 80
    full = repr(value)
    if "..." not in text:
        assert text == full
