"""Input and output for the command line: vectors, CSV files, tables, JSON, atomic writes.

* Numbers on the command line are comma- or space-separated (``--q "0, 0.5, 1"``).
* CSV input files have one row per item, an optional header line, ``#`` comments and
  blank lines allowed; a row with the wrong number of columns or a cell that is not a
  number is an error that names the file and the line number.
* Every output file is written atomically (a temporary file in the same folder, then a
  rename): an interrupted run never leaves a truncated CSV, JSON or HTML file behind.
"""

from __future__ import annotations

import json
import math
import os
import sys
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import click
import numpy as np

from serialkin._checks import short_repr
from serialkin._io import written_through

#: Exit code of a run whose inputs were wrong (bad file, robot, option): also click's
#: exit code for usage errors.
EXIT_INPUT = 2
#: Exit code of a run that completed but did not reach a goal (an IK target out of
#: reach, a path point not tracked).
EXIT_NOT_REACHED = 1
#: Largest CSV file of targets or joint values read [bytes].
MAX_CSV_BYTES = 512 * 1024 * 1024


class CLIError(click.ClickException):
    """An input error shown as one line ``Error: ...`` with exit code 2."""

    exit_code = EXIT_INPUT


def command_help(text: str, examples: list[str]) -> str:
    """Help text of a subcommand: ``text`` then an unwrapped block of example lines.

    click keeps a paragraph that starts with its no-rewrap marker (a backspace
    character) as written, so the examples are not re-flowed.
    """
    block = "\n".join(f"  {e}" for e in examples)
    return f"{text}\n\n\b\nExamples:\n{block}"


def parse_numbers(text: str, name: str, size: int | Sequence[int] | None = None) -> np.ndarray:
    """Parse comma/space-separated numbers; check the count when ``size`` is given.

    Raises:
        CLIError: a token is not a number, or the count is wrong (names ``name``).
    """
    tokens = [t for t in text.replace(",", " ").replace(";", " ").split() if t]
    values = []
    for t in tokens:
        try:
            v = float(t)
        except ValueError:
            raise CLIError(f"{name}: {short_repr(t)} is not a number (in {short_repr(text)})"
                           ) from None
        if not math.isfinite(v):
            raise CLIError(f"{name}: {short_repr(t)} is not a finite number")
        values.append(v)
    if size is not None:
        sizes = (size,) if isinstance(size, int) else tuple(size)
        if len(values) not in sizes:
            want = " or ".join(str(s) for s in sizes)
            raise CLIError(f"{name}: expected {want} numbers, got {len(values)} "
                           f"({short_repr(text)})")
    return np.array(values, dtype=float)


def read_csv_rows(path: str | os.PathLike[str], name: str,
                  columns: int | Sequence[int]) -> np.ndarray:
    """Read a numeric CSV file into an (N, k) array.

    The first non-comment line is a header when none of its cells is a number.

    Args:
        path: the file; ``-`` reads standard input.
        name: what the rows are (for messages), e.g. 'q'.
        columns: the accepted number(s) of columns; every row must have the same count.

    Raises:
        CLIError: unreadable, non-UTF-8 or too large (:data:`MAX_CSV_BYTES`) file, a
            folder, no rows, a row with a wrong number of columns or a non-numeric or
            non-finite cell; the message gives the file and the line number.
    """
    from serialkin._files import read_text

    accepted = (columns,) if isinstance(columns, int) else tuple(columns)
    label = "<stdin>" if str(path) == "-" else str(path)
    if str(path) == "-":
        try:
            text = sys.stdin.read(MAX_CSV_BYTES + 1)
        except (OSError, UnicodeDecodeError) as exc:
            raise CLIError(f"{label}: cannot read the {name} rows ({exc})") from exc
        if len(text) > MAX_CSV_BYTES:
            raise CLIError(f"{label}: more than {MAX_CSV_BYTES} characters of {name} rows")
    else:
        text = read_text(path, what=f"{name} file", error=CLIError, max_bytes=MAX_CSV_BYTES)
    rows: list[list[float]] = []
    width: int | None = None
    first_data = True
    for lineno, line in enumerate(text.splitlines(), start=1):
        s = line.strip()
        if not s or s.startswith("#"):
            continue
        cells = [c.strip() for c in s.split(",")] if "," in s else s.split()
        try:
            vals = [float(c) for c in cells]
        except ValueError:
            if first_data and not any(_is_number(c) for c in cells):
                first_data = False  # a header line: no cell is a number
                continue
            bad = next(c for c in cells if not _is_number(c))
            raise CLIError(f"{label}, line {lineno}: {short_repr(bad)} is not a number"
                           ) from None
        first_data = False
        if not all(math.isfinite(v) for v in vals):
            raise CLIError(f"{label}, line {lineno}: values must be finite, got "
                           f"{short_repr(s)}")
        want = " or ".join(str(c) for c in accepted)
        if len(vals) not in accepted:
            raise CLIError(
                f"{label}, line {lineno}: expected {want} columns for {name}, got {len(vals)}"
            )
        if width is not None and len(vals) != width:
            raise CLIError(
                f"{label}, line {lineno}: expected {width} columns like the rows above, "
                f"got {len(vals)}"
            )
        width = len(vals)
        rows.append(vals)
    if not rows:
        raise CLIError(f"{label}: no {name} rows found")
    return np.array(rows, dtype=float)


def _is_number(text: str) -> bool:
    try:
        float(text)
    except ValueError:
        return False
    return True


def write_text_atomic(path: str | os.PathLike[str], text: str) -> Path:
    """Write UTF-8 text through a temporary file and a rename; return the path.

    Raises:
        CLIError: the folder cannot be created or written (the message says which).
    """
    return write_bytes_atomic(path, text.encode("utf-8"))


def write_bytes_atomic(path: str | os.PathLike[str], data: bytes) -> Path:
    """Write bytes atomically after checking the folder; errors become CLIError.

    Delegates to :func:`serialkin._io.write_bytes_atomic` (temporary file in the same
    folder + rename), the one atomic writer of serialkin.
    """
    from serialkin._io import write_bytes_atomic as _write
    from serialkin.errors import OutputError

    p = Path(path)
    ensure_dir(p.parent)
    try:
        return _write(p, data)
    except OutputError as exc:
        raise CLIError(str(exc)) from exc


def ensure_dir(folder: str | os.PathLike[str]) -> Path:
    """Create ``folder`` if needed and check it is writable; raise a clear CLIError if not."""
    d = Path(folder) if str(folder) else Path(".")
    try:
        d.mkdir(parents=True, exist_ok=True)
    except FileExistsError as exc:
        raise CLIError(f"output folder {d} exists and is not a folder") from exc
    except OSError as exc:
        raise CLIError(f"cannot create output folder {d} ({exc.strerror or exc})") from exc
    if not os.access(d, os.W_OK | os.X_OK):
        raise CLIError(f"output folder {d} is not writable")
    return d


def to_jsonable(obj: Any) -> Any:
    """Convert numpy values (arrays, scalars) and infinities into JSON-ready Python values.

    Non-finite floats become ``None`` (JSON has no inf/NaN), so the output is strict JSON.
    """
    if isinstance(obj, dict):
        return {str(k): to_jsonable(v) for k, v in obj.items()}
    if isinstance(obj, (list, tuple)):
        return [to_jsonable(v) for v in obj]
    if isinstance(obj, np.ndarray):
        return to_jsonable(obj.tolist())
    if isinstance(obj, (np.bool_, bool)):
        return bool(obj)
    if isinstance(obj, (np.integer,)):
        return int(obj)
    if isinstance(obj, (float, np.floating)):
        v = float(obj)
        return v if math.isfinite(v) else None
    if isinstance(obj, Path):
        return str(obj)
    return obj


def dumps_json(obj: Any) -> str:
    """Strict JSON text (indent 2) of ``obj`` after :func:`to_jsonable`."""
    return json.dumps(to_jsonable(obj), indent=2, allow_nan=False) + "\n"


def format_table(rows: Sequence[Sequence[Any]], header: Sequence[str], digits: int = 6) -> str:
    """A plain-text table with right-aligned numeric columns."""
    def cell(v: Any) -> str:
        if isinstance(v, (bool, np.bool_)):
            return "yes" if v else "no"
        if isinstance(v, (float, np.floating)):
            return f"{float(v) + 0.0:.{digits}g}" if math.isfinite(v) else str(float(v))
        return str(v)

    body = [[cell(v) for v in r] for r in rows]
    widths = [max(len(h), *(len(r[i]) for r in body)) if body else len(h)
              for i, h in enumerate(header)]
    lines = ["  ".join(h.rjust(w) for h, w in zip(header, widths)),
             "  ".join("-" * w for w in widths)]
    lines += ["  ".join(c.rjust(w) for c, w in zip(r, widths)) for r in body]
    return "\n".join(lines)


def format_matrix(M: np.ndarray, digits: int = 6, indent: str = "  ") -> str:
    """A matrix as aligned text rows."""
    a = np.atleast_2d(np.asarray(M, dtype=float))
    cells = [[f"{0.0 if abs(v) < 5e-16 else v: .{digits}f}" for v in r] for r in a]
    w = max(len(c) for r in cells for c in r)
    return "\n".join(indent + " ".join(c.rjust(w) for c in r) for r in cells)


def csv_text(header: Sequence[str], rows: np.ndarray | Sequence[Sequence[float]]) -> str:
    """CSV text with a header line and full-precision numbers."""
    lines = [",".join(header)]
    for r in rows:
        lines.append(",".join(repr(float(v)) for v in r))
    return "\n".join(lines) + "\n"


def write_output(path: str | os.PathLike[str], data: dict[str, Any],
                 csv: tuple[Sequence[str], np.ndarray] | None = None) -> Path:
    """Write results to ``path``: JSON for ``.json``, CSV for ``.csv`` (when ``csv`` given).

    Raises:
        CLIError: unsupported suffix or unwritable location.
    """
    p = Path(path)
    suffix = p.suffix.lower()
    if suffix == ".json" or written_through(p):  # a device or pipe (/dev/stdout): JSON
        return write_text_atomic(p, dumps_json(data))
    if suffix == ".csv" and csv is not None:
        return write_text_atomic(p, csv_text(*csv))
    allowed = ".json or .csv" if csv is not None else ".json"
    raise CLIError(f"--out {p}: unsupported file type {p.suffix!r}; use {allowed}")
