"""Validation helpers used at the public boundary.

Each ``check_*`` function coerces its argument to ``float64`` where that is natural,
checks shape and finiteness, and raises :class:`~serialkin.errors.InputError` (a
``ValueError``) or :class:`~serialkin.errors.InputTypeError` (a ``TypeError``) with a
message that names the argument, what was expected and what came. Kernels never
validate: they trust what these functions let through.
"""

from __future__ import annotations

import difflib
import itertools
import math
import reprlib
from collections.abc import Iterable, Mapping, Sequence
from typing import Any

import numpy as np

from serialkin.errors import InputError, InputTypeError, NotSupportedError

#: Tolerance used to decide whether a matrix is a rotation (max |RᵀR − I| and |det R − 1|).
ROTATION_TOL = 1e-6


class _BoundedRepr(reprlib.Repr):
    """A :class:`reprlib.Repr` that never builds the full repr of a large value.

    Containers are shown to ``maxlevel`` levels and ``maxlist``/``maxdict`` items, so a
    YAML alias bomb (a list whose items are the same list, nested) costs at most
    ``maxlist ** maxlevel`` item reprs. Mapping and sequence subclasses go through the same
    bounded path, huge integers are described by their size, arrays by shape and dtype.
    """

    def __init__(self) -> None:
        super().__init__()
        self.maxlevel = 3
        self.maxlist = self.maxtuple = self.maxset = self.maxfrozenset = 6
        self.maxdeque = self.maxarray = 6
        self.maxdict = 4
        self.maxstring = 40
        self.maxlong = 40
        self.maxother = 40

    def repr1(self, x: object, level: int) -> str:
        if isinstance(x, np.ndarray):
            return f"<array of shape {x.shape} and dtype {x.dtype}>"
        if isinstance(x, bool) or x is None:
            return repr(x)
        if isinstance(x, int) and x.bit_length() > 128:
            return f"<integer of about {int(x.bit_length() * 0.30103) + 1} digits>"
        if isinstance(x, str):
            return self.repr_str(x, level)
        if type(x) in (list, tuple, dict, set, frozenset, int, float):
            return super().repr1(x, level)
        if isinstance(x, Mapping):  # subclasses too: never their own full repr
            return self.repr_dict(dict(_first_items(x, self.maxdict + 1)), level)
        if isinstance(x, (Sequence, set, frozenset)) and not isinstance(x, (bytes, bytearray)):
            return self.repr_list(list(itertools.islice(x, self.maxlist + 1)), level)
        return super().repr1(x, level)

    def repr_dict(self, x: dict, level: int) -> str:  # no sort of a huge dict: first items
        if not x:
            return "{}"
        if level <= 0:
            return "{...}"
        items = [f"{self.repr1(k, level - 1)}: {self.repr1(v, level - 1)}"
                 for k, v in _first_items(x, self.maxdict)]
        more = ", ..." if len(x) > self.maxdict else ""
        return "{" + ", ".join(items) + more + "}"


def _first_items(m: Mapping, count: int) -> list[tuple[object, object]]:
    out = []
    for k in m:
        if len(out) >= count:
            break
        out.append((k, m[k]))
    return out


_BOUNDED = _BoundedRepr()


def short_repr(value: object, limit: int = 80) -> str:
    """Return a repr of ``value`` of at most ``limit`` characters, built in bounded time.

    Unlike ``repr(value)[:limit]`` it never builds the full repr: nested containers are
    cut at 3 levels and 6 items (4 for mappings), strings at 40 characters, integers of
    more than 128 bits are described by their number of digits, arrays by their shape.
    Use it for every user-supplied value formatted into an error message.

    Args:
        value: any object (typically a value read from a user's file or argument).
        limit: maximum length of the result, in characters (>= 5).

    Returns:
        A string of at most ``limit`` characters; ``...`` marks a cut.
    """
    try:
        text = _BOUNDED.repr(value)
    except Exception:  # a user object whose __repr__ fails
        text = f"<{type(value).__name__} object>"
    limit = max(int(limit), 5)
    if len(text) > limit:
        text = text[: limit - 3] + "..."
    return text


def _describe(x: object) -> str:
    if isinstance(x, np.ndarray):
        return f"an array of shape {x.shape} and dtype {x.dtype}"
    return f"{type(x).__name__} {short_repr(x, 100)}"


def readonly(a: np.ndarray) -> np.ndarray:
    """A read-only view of ``a`` (no copy): the one array type a kernel input compiles for.

    numba compiles a kernel once per set of argument types, and a read-only and a
    writeable array are two types. Inputs a kernel only reads pass through this, so
    that a user's read-only array, a broadcast view and a fresh array share one
    compiled specialization (issue 27).
    """
    v = a.view()
    v.flags.writeable = False
    return v


def as_float_array(x: object, name: str, *, ndim: int | None = None,
                   finite: bool = True) -> np.ndarray:
    """Return ``x`` as a finite float64 array, or raise naming ``name``.

    Args:
        x: array-like of real numbers.
        name: the argument's name, used in error messages.
        ndim: required number of dimensions, or None for any.
        finite: check that every entry is finite (False: the caller's compiled kernel
            checks while it reads, and calls this again to raise the same error).

    Raises:
        InputTypeError: ``x`` is not numeric (strings, objects, complex numbers).
        InputError: wrong number of dimensions, or NaN/inf entries.
    """
    if isinstance(x, np.ndarray) and x.dtype == np.float64:
        a = x
    else:
        try:
            a = np.asarray(x)
        except (TypeError, ValueError) as exc:  # ragged lists
            raise InputTypeError(
                f"{name} must be an array of real numbers, got {_describe(x)}"
            ) from exc
        if a.dtype.kind not in "biuf":
            raise InputTypeError(
                f"{name} must be an array of real numbers, got {_describe(x)}"
            )
        a = a.astype(np.float64)
    if ndim is not None and a.ndim != ndim:
        raise InputError(f"{name} must have {ndim} dimension(s), got shape {a.shape}")
    if finite and not np.isfinite(a).all():
        bad = np.argwhere(~np.isfinite(a))[0]
        raise InputError(
            f"{name} must be finite, got {a[tuple(bad)]} at index {tuple(int(i) for i in bad)}"
        )
    return a


def as_vector(x: object, name: str, size: int | Sequence[int]) -> np.ndarray:
    """Return ``x`` as a finite float64 vector of the given size (or one of several sizes)."""
    a = as_float_array(x, name)
    sizes = (size,) if isinstance(size, int) else tuple(size)
    if a.ndim != 1 or a.shape[0] not in sizes:
        want = " or ".join(str(s) for s in sizes)
        raise InputError(f"{name} must be a vector of {want} values, got shape {a.shape}")
    return a


def check_last_dims(a: np.ndarray, name: str, shape: tuple[int, ...]) -> np.ndarray:
    """Check that the trailing dimensions of ``a`` equal ``shape`` (leading ones are a batch)."""
    k = len(shape)
    if a.ndim < k or a.shape[a.ndim - k :] != shape:
        dims = "x".join(str(s) for s in shape)
        raise InputError(
            f"{name} must have shape (..., {', '.join(map(str, shape))}) ({dims} matrices or "
            f"a batch of them), got shape {a.shape}"
        )
    return a


def check_rotation(R: object, name: str = "R", tol: float = ROTATION_TOL) -> np.ndarray:
    """Check that ``R`` is a rotation (batch): shape (..., 3, 3), RᵀR = I (eq 7), det R = 1."""
    a = check_last_dims(as_float_array(R, name), name, (3, 3))
    err = np.abs(np.swapaxes(a, -1, -2) @ a - np.eye(3)).max(initial=0.0)
    if err > tol:
        raise InputError(
            f"{name} is not orthonormal: max |RᵀR − I| = {err:.3g} exceeds {tol:g}"
        )
    det = np.linalg.det(a) if a.size else np.ones(0)
    if np.any(np.abs(det - 1.0) > tol):
        raise InputError(f"{name} is not a proper rotation: det R = {np.min(det):.6g}, expected +1")
    return a


def check_transform(T: object, name: str = "T", tol: float = ROTATION_TOL) -> np.ndarray:
    """Check that ``T`` is a (batch of) homogeneous rigid transform, shape (..., 4, 4) (eq 9).

    The last row must be ``[0, 0, 0, 1]`` and the upper-left 3x3 block a rotation.
    """
    a = check_last_dims(as_float_array(T, name), name, (4, 4))
    if np.abs(a[..., 3, :] - np.array([0.0, 0.0, 0.0, 1.0])).max(initial=0.0) > tol:
        raise InputError(
            f"{name} is not a homogeneous transform: its last row must be [0, 0, 0, 1]"
        )
    check_rotation(a[..., :3, :3], f"the rotation block of {name}", tol)
    return a


def check_choice(value: object, name: str, choices: Iterable[str]) -> str:
    """Check that ``value`` is one of ``choices``; the error lists them and the nearest match."""
    options = list(choices)
    if not isinstance(value, str) or value not in options:
        near = (difflib.get_close_matches(value[:200], options, n=1)
                if isinstance(value, str) else [])
        hint = f" Did you mean {near[0]!r}?" if near else ""
        raise InputError(
            f"unknown {name} {short_repr(value)}; expected one of: "
            f"{', '.join(map(repr, options))}.{hint}"
        )
    return value


#: Largest value of any positive real setting (tolerances, dampings, gains, weights, steps,
#: radii, cell sizes...): beyond it squares and products of settings approach overflow.
MAX_REAL = 1e9


def check_positive(value: object, name: str, *, allow_zero: bool = False,
                   maximum: float = MAX_REAL) -> float:
    """Check that ``value`` is a real number > 0 (or >= 0 with ``allow_zero``), <= ``maximum``.

    Args:
        value: the value (bool is refused; Python/numpy ints and floats are accepted).
        name: the argument's name, used in error messages.
        allow_zero: accept 0.
        maximum: largest accepted value (default :data:`MAX_REAL`, 1e9).
    """
    if isinstance(value, bool) or not isinstance(value, (int, float, np.integer, np.floating)):
        raise InputTypeError(f"{name} must be a real number, got {_describe(value)}")
    try:
        v = float(value)
    except OverflowError:  # an integer beyond the float range
        v = float("inf")
    if not np.isfinite(v) or v < 0 or (v == 0 and not allow_zero):
        want = ">= 0" if allow_zero else "> 0"
        raise InputError(f"{name} must be a finite number {want}, got {short_repr(value)}")
    if v > maximum:
        raise InputError(f"{name} must be at most {maximum:g}, got {v:g}")
    return v


#: Largest magnitude of a length [m] in a robot description (DH a and d, the translations
#: of joint, base and tool transforms): far beyond any robot, far below float overflow in
#: FK over thousands of links.
MAX_LENGTH = 1e6

#: Largest magnitude of an angle, joint offset or finite joint limit [rad or m].
MAX_JOINT_VALUE = 1e9


#: Largest integer any option accepts unless it has a tighter bound: exactly representable
#: in float64 and far inside int64, so nothing that reaches a compiled kernel overflows.
MAX_INT = 2**53

#: Largest number of joints of a robot: a chain this long already takes seconds to build
#: and its IK is O(n³) per iteration.
MAX_JOINTS = 10_000

#: Largest iteration budget (``max_iter``) of any iterative solver, per attempt / point.
MAX_ITERATIONS = 1_000_000


def check_int(value: object, name: str, *, minimum: int = 0, maximum: int | None = MAX_INT,
              hint: str = "") -> int:
    """Check that ``value`` is an integer with ``minimum <= value <= maximum``.

    Args:
        value: the value (bool is refused; Python and numpy integers are accepted).
        name: the argument's name, used in error messages.
        minimum: smallest accepted value.
        maximum: largest accepted value (default :data:`MAX_INT`), or None for no bound.
        hint: a sentence appended to the "too large" message (e.g. how to raise a bound).
    """
    if isinstance(value, bool) or not isinstance(value, (int, np.integer)):
        raise InputTypeError(f"{name} must be an integer, got {_describe(value)}")
    if value < minimum:
        raise InputError(f"{name} must be >= {minimum}, got {short_repr(value)}")
    if maximum is not None and value > maximum:
        tail = f" {hint}" if hint else ""
        raise InputError(f"{name} must be <= {maximum}, got {short_repr(value)}.{tail}")
    return int(value)


#: Largest angle read as radians before it looks like degrees: a full turn, plus rounding.
TURN_LIMIT = 2 * math.pi + 1e-6


def beyond_a_turn(values: object) -> np.ndarray:
    """Where ``|value|`` exceeds a full turn (:data:`TURN_LIMIT`) [rad], element-wise.

    A fixed angle or joint value read in radians that large is most likely in degrees:
    the readers refuse it and say so (the caller names the field and the unit to use).
    """
    return np.abs(np.asarray(values, dtype=float)) > TURN_LIMIT


def check_real(value: object, name: str, *, max_abs: float | None = None,
               unit: str = "") -> float:
    """Check that ``value`` is a finite real number with ``|value| <= max_abs``.

    Args:
        value: the value (bool and strings are refused; Python/numpy ints and floats pass).
        name: the argument's name, used in error messages.
        max_abs: largest accepted magnitude, or None for any finite value.
        unit: unit shown in the message (e.g. 'm').

    Raises:
        InputTypeError: not a real number.
        InputError: NaN, infinite, or larger than ``max_abs`` in magnitude.
    """
    if isinstance(value, bool) or not isinstance(value, (int, float, np.integer, np.floating)):
        raise InputTypeError(f"{name} must be a number, got {_describe(value)}")
    u = f" {unit}" if unit else ""
    try:
        v = float(value)
    except OverflowError:  # an integer beyond the float range
        bound = f"at most {max_abs:g}{u} in magnitude" if max_abs is not None else "finite"
        raise InputError(f"{name} must be {bound}, got {short_repr(value)}") from None
    if not np.isfinite(v):
        raise InputError(f"{name} must be finite, got {short_repr(value)}")
    if max_abs is not None and abs(v) > max_abs:
        raise InputError(f"{name} must be at most {max_abs:g}{u} in magnitude, got {v:g}{u}")
    return v


def as_generator(seed: None | int | np.random.Generator) -> np.random.Generator:
    """Return a numpy Generator for ``seed`` (None: fresh entropy; int: reproducible)."""
    if isinstance(seed, np.random.Generator):
        return seed
    if seed is None:
        return np.random.default_rng()
    if isinstance(seed, (int, np.integer)) and not isinstance(seed, bool):
        if seed < 0:
            raise InputError(f"seed must be >= 0, got {short_repr(seed)}")
        return np.random.default_rng(int(seed))
    raise InputTypeError(f"seed must be None, an int or a numpy Generator, got {_describe(seed)}")


def require(module: str, extra: str, needed_for: str) -> Any:
    """Import the optional dependency ``module`` (dotted name) or say which extra brings it.

    Raises:
        NotSupportedError: ``module`` is not installed; the message names what needs it
            and the command ``pip install "serialkin[<extra>]"``.
    """
    import importlib

    try:
        return importlib.import_module(module)
    except ImportError:
        raise NotSupportedError(f'{needed_for} needs {module.split(".")[0]}: '
                                f'pip install "serialkin[{extra}]"') from None
