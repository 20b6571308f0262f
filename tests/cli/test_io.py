"""Command-line input/output helpers: number parsing, CSV reading, strict JSON."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from serialkin.cli.io import CLIError, dumps_json, parse_numbers, read_csv_rows

finite = st.floats(allow_nan=False, allow_infinity=False, width=64)


@settings(max_examples=40, deadline=None)
@given(st.lists(finite, min_size=1, max_size=12), st.sampled_from([",", " ", ", ", ";"]))
def test_parse_numbers_round_trip(values, sep):
    """Numbers written with repr and any separator parse back exactly."""
    out = parse_numbers(sep.join(repr(v) for v in values), "--q", len(values))
    assert out.tolist() == values


@settings(max_examples=25, deadline=None)
@given(cols=st.integers(1, 6), rows=st.integers(1, 8), header=st.booleans(),
       seed=st.integers(0, 2**31 - 1))
def test_csv_round_trip(tmp_path_factory, cols, rows, header, seed):
    """A CSV of random numbers (with or without a header) reads back exactly."""
    a = np.random.default_rng(seed).normal(size=(rows, cols)) * 10.0**np.arange(cols)
    p = tmp_path_factory.mktemp("csv") / "a.csv"
    text = (",".join(f"c{i}" for i in range(cols)) + "\n" if header else "")
    text += "\n".join(",".join(repr(float(v)) for v in r) for r in a) + "\n"
    p.write_text(text)
    np.testing.assert_array_equal(read_csv_rows(p, "rows", cols), a)


def test_parse_numbers_errors():
    """Wrong counts, words and infinities are named errors."""
    with pytest.raises(CLIError, match="expected 3 numbers, got 2"):
        parse_numbers("1,2", "--target", 3)
    with pytest.raises(CLIError, match="'x' is not a number"):
        parse_numbers("1,x", "--q")
    with pytest.raises(CLIError, match="finite"):
        parse_numbers("1,inf", "--q")
    with pytest.raises(CLIError, match="2 or 3"):
        parse_numbers("1", "--target", (2, 3))


def test_csv_inconsistent_rows(tmp_path):
    """Rows must agree in width even when several widths are accepted."""
    p = tmp_path / "t.csv"
    p.write_text("1,2\n1,2,3\n")
    with pytest.raises(CLIError, match="line 2: expected 2 columns like the rows above"):
        read_csv_rows(p, "targets", (2, 3))


def test_json_is_strict():
    """Infinities and NaN become null; numpy values become plain JSON."""
    text = dumps_json({"a": np.array([1.0, np.inf]), "b": np.float64(math.nan),
                       "c": np.int64(3), "d": np.bool_(True)})
    assert json.loads(text) == {"a": [1.0, None], "b": None, "c": 3, "d": True}
