"""Reading data files safely: one bounded parser and one typed field reader for every format.

Every description file serialkin reads (robot files, scenarios, trajectory headers, CSV
files of targets or joint values, URDF) goes through this module, in two steps:

1. **Parse safely** (:func:`read_bytes`, :func:`read_text`, :func:`load_document`): the
   path must be an existing regular file no larger than ``max_bytes``
   (:data:`MAX_FILE_BYTES` by default) and, for text, valid UTF-8. YAML is read with the
   safe loader (no tags that run code), duplicate keys in a mapping are refused, the
   nesting depth is at most :data:`MAX_DEPTH` and the document, with every alias
   expanded, has at most :data:`MAX_NODES` nodes — so a 545-byte "billion laughs" alias
   bomb fails at once instead of expanding into gigabytes. The bounds are checked on the
   parser's event stream, before any Python object is built. JSON refuses duplicate keys
   (``object_pairs_hook``) and the same depth.
2. **Read fields with types** (:class:`Field`): each getter checks the type and the
   range of a value *before* it is used and names the file and the field path in its
   message (``arm.yaml: field 'dh[2].a' must be a finite number with |x| <= 1e+09 [m],
   got 1e+308``). Values are shown with :func:`serialkin._checks.short_repr`, which never
   builds an unbounded repr.

Every failure is raised as the caller's error class (a subclass of
:class:`~serialkin.errors.SerialkinError`), e.g. ``RobotDefinitionError`` for robot files
and ``ScenarioError`` for scenarios.
"""

from __future__ import annotations

import difflib
import json
import math
import os
import stat
import xml.etree.ElementTree as ET
from collections.abc import Collection, Sequence
from pathlib import Path
from typing import Any

import numpy as np

from serialkin._checks import short_repr
from serialkin.errors import InputError, InputTypeError, SerialkinError

__all__ = [
    "MAX_DEPTH",
    "MAX_FILE_BYTES",
    "MAX_ITEMS",
    "MAX_NODES",
    "MAX_NUMBER",
    "MISSING",
    "Field",
    "load_document",
    "parse_json",
    "parse_yaml",
    "read_bytes",
    "read_text",
]

#: Largest description file read (robot file, scenario, URDF, trajectory header) [bytes].
MAX_FILE_BYTES = 16 * 1024 * 1024
#: Deepest nesting of lists and mappings accepted in a YAML or JSON document.
MAX_DEPTH = 64
#: Most nodes (scalars, lists, mappings) in a document once every YAML alias is expanded.
MAX_NODES = 4_000_000
#: Most items in one list of a document (rows, points, obstacles).
MAX_ITEMS = 1_000_000
#: Default bound on the magnitude of a number read from a file (in the file's units):
#: larger values are nonsense for kinematics and overflow products to inf.
MAX_NUMBER = 1e9

ErrorType = type[SerialkinError]


class _Missing:
    """The value of an absent field (distinct from an explicit ``null``)."""

    def __repr__(self) -> str:
        return "<missing>"

    def __bool__(self) -> bool:
        return False


#: Placeholder for an absent field; ``Field.present`` is False for it and for ``null``.
MISSING: Any = _Missing()


# ------------------------------------------------------------------------------ reading
def read_bytes(path: str | os.PathLike[str], *, what: str = "file",
               error: ErrorType = InputError, max_bytes: int = MAX_FILE_BYTES) -> bytes:
    """Read a whole regular file of at most ``max_bytes`` bytes.

    Args:
        path: the file.
        what: what the file is, for messages (``'robot file'``, ``'scenario'``).
        error: the exception class raised.
        max_bytes: size limit [bytes]; larger files are refused before being read.

    Raises:
        error: the file does not exist, is a folder or a device, is larger than
            ``max_bytes``, or cannot be read (the message names the path and the reason).
    """
    if not isinstance(path, (str, os.PathLike)):
        raise InputTypeError(f"the {what} path must be a str or os.PathLike, got "
                             f"{type(path).__name__} {short_repr(path)}")
    p = Path(path)
    try:
        st = p.stat()
    except FileNotFoundError:
        raise error(f"{p}: {what} not found") from None
    except OSError as exc:
        raise error(f"{p}: cannot read the {what} ({exc.strerror or exc})") from None
    if stat.S_ISDIR(st.st_mode):
        raise error(f"{p}: is a folder, not a {what}")
    if not stat.S_ISREG(st.st_mode):
        raise error(f"{p}: is not a regular file (a {what} must be one)")
    if st.st_size > max_bytes:
        raise error(f"{p}: the {what} has {st.st_size} bytes, more than the limit of "
                    f"{max_bytes} bytes")
    try:
        with p.open("rb") as f:
            data = f.read(max_bytes + 1)  # a file growing while read is still bounded
    except OSError as exc:
        raise error(f"{p}: cannot read the {what} ({exc.strerror or exc})") from None
    if len(data) > max_bytes:
        raise error(f"{p}: the {what} is larger than the limit of {max_bytes} bytes")
    return data


def decode_text(data: bytes, origin: str, *, what: str = "file",
                error: ErrorType = InputError) -> str:
    """Decode UTF-8 bytes (a leading byte-order mark is dropped); raise naming the offset."""
    try:
        return data.decode("utf-8-sig")
    except UnicodeDecodeError as exc:
        raise error(f"{origin}: the {what} is not UTF-8 text (invalid byte "
                    f"0x{data[exc.start]:02x} at offset {exc.start})") from None


def read_text(path: str | os.PathLike[str], *, what: str = "file",
              error: ErrorType = InputError, max_bytes: int = MAX_FILE_BYTES) -> str:
    """Read a UTF-8 text file of at most ``max_bytes`` bytes (see :func:`read_bytes`).

    Raises:
        error: as :func:`read_bytes`, or the bytes are not UTF-8.
    """
    return decode_text(read_bytes(path, what=what, error=error, max_bytes=max_bytes),
                       str(path), what=what, error=error)


def load_document(path: str | os.PathLike[str], *, what: str = "file",
                  error: ErrorType = InputError, max_bytes: int = MAX_FILE_BYTES) -> object:
    """Read and parse a YAML or JSON file (JSON for a ``.json`` suffix, else YAML).

    Raises:
        error: unreadable file, invalid syntax (with line and column), a duplicate key,
            too deep nesting or too many nodes once aliases are expanded.
    """
    text = read_text(path, what=what, error=error, max_bytes=max_bytes)
    if Path(path).suffix.lower() == ".json":
        return parse_json(text, str(path), error=error)
    return parse_yaml(text, str(path), error=error)


def _yaml_module() -> Any:
    import yaml

    return yaml


def _at(mark: Any) -> str:
    return f" at line {mark.line + 1}, column {mark.column + 1}" if mark is not None else ""


def _check_yaml_events(text: str, origin: str, error: ErrorType) -> None:
    """Walk the YAML event stream once: bound the depth and the alias-expanded size.

    Each anchored node's expanded size is recorded when it closes; an alias adds that
    size. An alias to a node that is still open (a recursive structure) is refused.
    """
    yaml = _yaml_module()
    loader = getattr(yaml, "CSafeLoader", yaml.SafeLoader)
    start = (yaml.MappingStartEvent, yaml.SequenceStartEvent)
    end = (yaml.MappingEndEvent, yaml.SequenceEndEvent)
    sizes: dict[str, int] = {}
    open_nodes: list[tuple[str | None, int]] = []  # (anchor, total when it opened)
    total = 0
    for ev in yaml.parse(text, Loader=loader):
        if isinstance(ev, yaml.ScalarEvent):
            total += 1
            if ev.anchor is not None:
                sizes[ev.anchor] = 1
        elif isinstance(ev, start):
            if len(open_nodes) >= MAX_DEPTH:
                raise error(f"{origin}: nesting deeper than {MAX_DEPTH} levels"
                            f"{_at(ev.start_mark)}")
            open_nodes.append((ev.anchor, total))
            total += 1
        elif isinstance(ev, end):
            anchor, before = open_nodes.pop()
            if anchor is not None:
                sizes[anchor] = total - before
        elif isinstance(ev, yaml.AliasEvent):
            if ev.anchor not in sizes:
                raise error(f"{origin}: alias *{short_repr(ev.anchor, 40)[1:-1]}"
                            f"{_at(ev.start_mark)} refers to an undefined or enclosing anchor "
                            "(recursive structures are not allowed)")
            total += sizes[ev.anchor]
        if total > MAX_NODES:
            raise error(f"{origin}: the document has more than {MAX_NODES} values once its "
                        f"aliases are expanded{_at(ev.start_mark)} (an alias bomb?)")


def _strict_loader() -> type:
    """A safe YAML loader class whose mappings refuse duplicate keys (built once)."""
    global _STRICT_LOADER
    if _STRICT_LOADER is not None:
        return _STRICT_LOADER
    yaml = _yaml_module()
    base = getattr(yaml, "CSafeLoader", yaml.SafeLoader)

    class StrictSafeLoader(base):  # type: ignore[misc, valid-type]
        def construct_mapping(self, node: Any, deep: bool = False) -> Any:
            if isinstance(node, yaml.MappingNode):
                seen: set[Any] = set()
                for key_node, _ in node.value:
                    if key_node.tag == "tag:yaml.org,2002:merge":
                        continue  # `<<: *base` then explicit keys: overriding is the point
                    key = self.construct_object(key_node, deep=True)
                    try:
                        dup = key in seen
                    except TypeError:
                        raise yaml.constructor.ConstructorError(
                            "while constructing a mapping", node.start_mark,
                            f"found an unhashable key ({type(key).__name__})",
                            key_node.start_mark) from None
                    if dup:
                        raise yaml.constructor.ConstructorError(
                            "while constructing a mapping", node.start_mark,
                            f"found duplicate key {short_repr(key, 60)}", key_node.start_mark)
                    seen.add(key)
            return super().construct_mapping(node, deep=deep)

    _STRICT_LOADER = StrictSafeLoader
    return StrictSafeLoader


_STRICT_LOADER: type | None = None


def parse_yaml(text: str, origin: str, *, error: ErrorType = InputError) -> object:
    """Parse one YAML document with the safe loader, within the module's bounds.

    Args:
        text: the document.
        origin: what to call it in messages (the file path).
        error: the exception class raised.

    Raises:
        error: a syntax error (line and column), a tag that is not plain data, a
            duplicate or unhashable key, nesting deeper than :data:`MAX_DEPTH`, more than
            :data:`MAX_NODES` values after alias expansion, or several documents.
    """
    yaml = _yaml_module()
    try:
        _check_yaml_events(text, origin, error)
        loader = _strict_loader()(text)
        try:
            return loader.get_single_data()
        finally:
            loader.dispose()
    except SerialkinError:
        raise
    except yaml.YAMLError as exc:
        mark = getattr(exc, "problem_mark", None)
        problem = getattr(exc, "problem", None) or str(exc).splitlines()[0]
        raise error(f"{origin}: invalid YAML{_at(mark)}: {problem}") from None
    except RecursionError:  # pragma: no cover - depth is bounded by the event check
        raise error(f"{origin}: nesting too deep (more than {MAX_DEPTH} levels)") from None
    except (ValueError, TypeError, OverflowError) as exc:  # a scalar no type can hold
        raise error(f"{origin}: invalid YAML: {str(exc).split(':')[0][:120]}") from None


class _DuplicateKey(Exception):
    def __init__(self, key: str) -> None:
        super().__init__(key)
        self.key = key


def _unique_pairs(pairs: list[tuple[str, Any]]) -> dict[str, Any]:
    out: dict[str, Any] = {}
    for k, v in pairs:
        if k in out:
            raise _DuplicateKey(k)
        out[k] = v
    return out


def _depth_exceeds(data: object, limit: int) -> bool:
    """True when lists/mappings in ``data`` nest deeper than ``limit`` (iterative walk)."""
    stack: list[tuple[object, int]] = [(data, 0)]
    while stack:
        value, depth = stack.pop()
        if isinstance(value, (dict, list)):
            if depth >= limit:
                return True
            items = value.values() if isinstance(value, dict) else value
            stack.extend((v, depth + 1) for v in items)
    return False


def parse_json(text: str, origin: str, *, error: ErrorType = InputError) -> object:
    """Parse a JSON document, refusing duplicate keys and nesting deeper than :data:`MAX_DEPTH`.

    Raises:
        error: a syntax error (line and column), a duplicate key, an integer of more
            than 4300 digits, or too deep nesting.
    """
    try:
        data = json.loads(text, object_pairs_hook=_unique_pairs)
    except json.JSONDecodeError as exc:
        raise error(f"{origin}: invalid JSON at line {exc.lineno}, column {exc.colno}: "
                    f"{exc.msg}") from None
    except _DuplicateKey as exc:
        raise error(f"{origin}: invalid JSON: duplicate key {short_repr(exc.key, 60)} in an "
                    "object (each key may appear once)") from None
    except RecursionError:
        raise error(f"{origin}: nesting too deep (more than {MAX_DEPTH} levels)") from None
    except ValueError as exc:  # e.g. an integer of more than 4300 digits
        raise error(f"{origin}: invalid JSON: {str(exc).split(':')[0][:120]}") from None
    if _depth_exceeds(data, MAX_DEPTH):
        raise error(f"{origin}: nesting deeper than {MAX_DEPTH} levels")
    return data


def parse_xml(data: str | bytes, origin: str, *, error: ErrorType = InputError) -> ET.Element:
    """Parse an XML document (URDF, MJCF) with :mod:`xml.etree.ElementTree`; its root element.

    Raises:
        error: malformed XML (with line and column), or an encoding Python does not know.
    """
    try:
        return ET.fromstring(data)
    except ET.ParseError as exc:
        line, col = exc.position
        raise error(f"{origin}: malformed XML at line {line}, column {col}: {exc}") from exc
    except (ValueError, LookupError) as exc:  # e.g. an encoding Python does not know
        raise error(f"{origin}: cannot read the XML ({exc})") from exc


# ------------------------------------------------------------------------------ fields
def _fmt_bound(x: float) -> str:
    return f"{x:g}"


class Field:
    """A value read from a file, with its path in the document for error messages.

    ``Field(data, "", origin, error)`` is the document; ``field["robot"]["planar"]`` a
    field inside it (its value is :data:`MISSING` when absent), ``field.items()`` the
    fields of a list (paths ``dh[0]``, ``dh[1]`` ...). The typed getters (``number``,
    ``integer``, ``string``, ``vector``, ``array`` ...) check type and range before
    returning a plain Python or numpy value; failures raise ``error`` with the message
    ``"<origin>: field '<path>' must be <expected>, got <short repr>"``.

    Attributes:
        value: the raw value (or :data:`MISSING`).
        path: the field path, e.g. ``'robot.planar.links'`` ('' for the document).
        origin: the file (or other source) named in messages.
        error: the exception class raised.
    """

    __slots__ = ("error", "origin", "path", "value")

    def __init__(self, value: object, path: str = "", origin: str = "<data>",
                 error: ErrorType = InputError) -> None:
        self.value = value
        self.path = path
        self.origin = origin
        self.error = error

    # ---------------------------------------------------------------- messages
    def fail(self, problem: str) -> SerialkinError:
        """The error ``"<origin>: field '<path>' <problem>"`` (not raised)."""
        who = f"field {self.path!r}" if self.path else "the document"
        return self.error(f"{self.origin}: {who} {problem}" if self.origin else
                          f"{who} {problem}")

    def expected(self, what: str) -> SerialkinError:
        """The error ``... must be <what>, got <short repr of the value>`` (not raised)."""
        return self.fail(f"must be {what}, got {short_repr(self.value)}")

    @property
    def present(self) -> bool:
        """True unless the field is absent or ``null``."""
        return self.value is not MISSING and self.value is not None

    def _child(self, value: object, key: str | int) -> Field:
        if isinstance(key, int):
            path = f"{self.path}[{key}]"
        else:
            path = f"{self.path}.{key}" if self.path else key
        return Field(value, path, self.origin, self.error)

    # ---------------------------------------------------------------- structure
    def mapping(self, allowed: Collection[str] | None = None,
                required: Sequence[str] = (), *, what: str = "a mapping") -> Field:
        """Check the value is a mapping with text keys, allowed keys and required ones; return it.

        Only ``allowed`` keys (when given) may appear and every ``required`` key must be
        present and not null. Unknown keys are reported with the closest allowed name.
        """
        v = self.value
        if not isinstance(v, dict):
            raise self.expected(what)
        bad = [k for k in v if not isinstance(k, str)]
        if bad:
            raise self.fail(f"has a key that is not a text name: {short_repr(bad[0])} "
                            "(keys must be names)")
        if allowed is not None:
            extra = [k for k in v if k not in allowed]
            if extra:
                options = sorted(allowed)
                hints = []
                for e in extra[:5]:
                    near = difflib.get_close_matches(e, options, n=1)
                    label = f"{self.path}.{short_repr(e, 40)[1:-1]}" if self.path else \
                        short_repr(e, 40)[1:-1]
                    hints.append(f"{label!r}" + (f" (did you mean {near[0]!r}?)" if near
                                                 else ""))
                where = f"{self.origin}: " if self.origin else ""
                raise self.error(f"{where}unknown field(s) {', '.join(hints)}; allowed: "
                                 f"{', '.join(options)}")
        for key in required:
            if v.get(key) is None:
                raise self._child(MISSING, key).fail("is missing")
        return self

    def __getitem__(self, key: str) -> Field:
        """The field ``key`` of this mapping (call :meth:`mapping` first)."""
        v = self.value
        return self._child(v.get(key, MISSING) if isinstance(v, dict) else MISSING, key)

    def __contains__(self, key: str) -> bool:
        """True when this mapping has ``key`` (null included)."""
        return isinstance(self.value, dict) and key in self.value

    def keys(self) -> list[str]:
        """The keys of this mapping (call :meth:`mapping` first)."""
        return list(self.value) if isinstance(self.value, dict) else []

    def require(self) -> Field:
        """Check the field is present (not absent, not null); return ``self``."""
        if not self.present:
            raise self.fail("is missing")
        return self

    def items(self, *, min_len: int = 0, max_len: int = MAX_ITEMS,
              what: str = "a list") -> list[Field]:
        """The fields of a list value (paths ``<path>[i]``), its length checked."""
        v = self.value
        if not isinstance(v, list):
            raise self.expected(what)
        if not min_len <= len(v) <= max_len:
            span = f"at least {min_len}" if max_len >= MAX_ITEMS else f"{min_len} to {max_len}"
            raise self.fail(f"must have {span} items, got {len(v)}")
        return [self._child(x, i) for i, x in enumerate(v)]

    # ---------------------------------------------------------------- scalars
    def number(self, *, lo: float = -MAX_NUMBER, hi: float = MAX_NUMBER, unit: str = "",
               lo_open: bool = False, default: Any = MISSING, allow_inf: bool = False
               ) -> Any:
        """A real number in [lo, hi] (or (lo, hi] with ``lo_open``) as a float.

        Booleans, strings and containers are refused; integers of any size are compared
        exactly before conversion (no OverflowError). ``allow_inf`` also accepts ±inf
        (e.g. an open joint limit). An absent or null field gives ``default`` when one
        is given, else "is missing".
        """
        v = self.value
        if v is MISSING or v is None:
            if default is not MISSING:
                return default
            raise self.fail("is missing")
        what = self._number_text(lo, hi, lo_open, unit)
        if isinstance(v, bool) or not isinstance(v, (int, float)):
            raise self.expected(what)
        if isinstance(v, float) and math.isnan(v):
            raise self.expected(what)
        if allow_inf and isinstance(v, float) and math.isinf(v):
            return v
        if v < lo or v > hi or (lo_open and v == lo) or (isinstance(v, float)
                                                         and math.isinf(v)):
            raise self.expected(what)
        return float(v)

    @staticmethod
    def _number_text(lo: float, hi: float, lo_open: bool, unit: str) -> str:
        u = f" [{unit}]" if unit else ""
        if lo == 0:
            most = f" (at most {_fmt_bound(hi)})" if hi < math.inf else ""
            return f"a number {'>' if lo_open else '>='} 0{u}{most}"
        if lo == -MAX_NUMBER and hi == MAX_NUMBER:
            return f"a finite number with |x| <= {_fmt_bound(hi)}{u}"
        return f"a number in {'(' if lo_open else '['}{_fmt_bound(lo)}, {_fmt_bound(hi)}]{u}"

    def integer(self, *, lo: int = 0, hi: int = 2**31 - 1, default: Any = MISSING) -> Any:
        """An integer in [lo, hi] (floats such as ``1e8`` and booleans are refused)."""
        v = self.value
        if v is MISSING or v is None:
            if default is not MISSING:
                return default
            raise self.fail("is missing")
        if isinstance(v, bool) or not isinstance(v, int) or not lo <= v <= hi:
            raise self.expected(f"an integer in [{lo}, {hi}]")
        return int(v)

    def string(self, *, choices: Collection[str] | None = None, default: Any = MISSING,
               nonempty: bool = True, max_len: int = 10_000) -> Any:
        """A text value (one of ``choices`` when given; the message suggests the nearest)."""
        v = self.value
        if v is MISSING or v is None:
            if default is not MISSING:
                return default
            raise self.fail("is missing")
        if choices is not None:
            options = list(choices)
            if not isinstance(v, str) or v not in options:
                near = difflib.get_close_matches(v, options, n=1) if isinstance(v, str) else []
                hint = f" (did you mean {near[0]!r}?)" if near else ""
                raise self.fail(f"must be one of {', '.join(options)}, got "
                                f"{short_repr(v)}{hint}")
            return v
        if not isinstance(v, str) or (nonempty and not v.strip()) or len(v) > max_len:
            raise self.expected(f"a {'non-empty ' if nonempty else ''}text of at most "
                                f"{max_len} characters")
        return v

    # ---------------------------------------------------------------- arrays
    def vector(self, size: int, *, lo: float = -MAX_NUMBER, hi: float = MAX_NUMBER,
               unit: str = "") -> np.ndarray:
        """A list of exactly ``size`` numbers (each checked as :meth:`number`), float64."""
        v = self.value
        u = f" [{unit}]" if unit else ""
        if not isinstance(v, list) or len(v) != size:
            raise self.expected(f"a list of {size} numbers{u}")
        return np.array([self._child(x, i).number(lo=lo, hi=hi, unit=unit)
                         for i, x in enumerate(v)], dtype=float)

    def array(self, *, what: str, ndim: int | None = None,
              cols: Collection[int] | None = None, scalar_ok: bool = False,
              max_items: int = MAX_ITEMS, lo: float = -MAX_NUMBER,
              hi: float = MAX_NUMBER) -> np.ndarray:
        """A number, a list of numbers or a list of equal-length lists of numbers.

        Args:
            what: the expected form for messages (``'a list of [x, y] points'``).
            ndim: required dimensions (1 or 2), or None for either.
            cols: accepted row lengths of a 2-D value.
            scalar_ok: accept one number (a 0-d array).
            max_items: most numbers accepted.
            lo: lower bound of every entry.
            hi: upper bound of every entry.

        Raises:
            error: a value of another form (the message names the first bad entry),
                a NaN, an infinity or an entry outside [lo, hi].
        """
        v = self.value
        if not isinstance(v, list):
            if scalar_ok and isinstance(v, (int, float)) and not isinstance(v, bool):
                return np.array(self._entry(v, (), lo, hi, what))
            raise self.expected(what)
        if v and all(isinstance(r, list) for r in v):
            width = len(v[0])
            if len(v) * max(width, 1) > max_items:
                raise self.fail(f"has more than {max_items} numbers")
            for i, r in enumerate(v):
                if len(r) != width:
                    raise self.fail(f"must be {what}: row {i} has {len(r)} numbers, row 0 "
                                    f"has {width}")
            out = np.array([[self._entry(x, (i, j), lo, hi, what) for j, x in enumerate(r)]
                            for i, r in enumerate(v)], dtype=float).reshape(len(v), width)
        else:
            if len(v) > max_items:
                raise self.fail(f"has more than {max_items} numbers")
            out = np.array([self._entry(x, (i,), lo, hi, what) for i, x in enumerate(v)],
                           dtype=float)
        if ndim is not None and out.ndim != ndim or (cols is not None and out.ndim == 2
                                                     and out.shape[1] not in cols):
            raise self.fail(f"must be {what}, got shape {out.shape}")
        return out

    def _entry(self, x: object, index: tuple[int, ...], lo: float, hi: float,
               what: str) -> float:
        at = f"[{', '.join(map(str, index))}]" if index else ""
        if isinstance(x, bool) or not isinstance(x, (int, float)):
            raise self.fail(f"must be {what} of numbers; entry {at} is {short_repr(x)}")
        if isinstance(x, float) and not math.isfinite(x):
            raise self.fail(f"must be finite; entry {at} is {x}")
        if not lo <= x <= hi:
            raise self.fail(f"must have entries in [{_fmt_bound(lo)}, {_fmt_bound(hi)}]; "
                            f"entry {at} is {short_repr(x)}")
        return float(x)
