"""The memory budget: sizes derived from user input are checked before allocation.

Every array whose size follows from a user's argument or file (random configuration
batches, workspace samples and grid cells, path points, frames, links) is estimated
with :func:`check_allocation` *before* it is allocated. An estimate beyond the budget
raises :class:`~serialkin.errors.BudgetError` naming the setting, the estimated size
and the budget, and how to raise it.

The budget, in bytes, is, in order of precedence:

1. the value set by :func:`set_memory_budget` (the CLI's ``--memory-budget`` sets it);
2. the environment variable ``SERIALKIN_MEMORY_BUDGET`` (e.g. ``8G``, ``500M``,
   ``2000000000``; suffixes K, M, G, T in powers of 1024; ``unlimited`` for none);
3. :data:`DEFAULT_FRACTION` of the memory available when the check runs
   (``MemAvailable`` of ``/proc/meminfo``; :data:`FALLBACK_BYTES` where that cannot be
   read).

Allocations below :data:`ALWAYS_ALLOWED` bytes are never refused (and cost no lookup).
"""

from __future__ import annotations

import math
import os
import re

from serialkin.errors import BudgetError, InputError

#: Environment variable that sets the budget (see the module docstring for the syntax).
ENV_VAR = "SERIALKIN_MEMORY_BUDGET"

#: Default budget: this fraction of the available memory.
DEFAULT_FRACTION = 0.5

#: Budget used when the available memory cannot be read [bytes].
FALLBACK_BYTES = 4 * 1024**3

#: Allocations smaller than this are always allowed [bytes].
ALWAYS_ALLOWED = 64 * 1024**2

_UNITS = {"": 1, "B": 1, "K": 1024, "M": 1024**2, "G": 1024**3, "T": 1024**4}
_override: float | None = None


def parse_size(text: str, name: str = ENV_VAR) -> float:
    """Parse a memory size: ``'8G'``, ``'500M'``, ``'1.5G'``, ``'2000000'``, ``'unlimited'``.

    Suffixes K, M, G, T (optionally followed by B or iB) are powers of 1024. Returns
    bytes, ``inf`` for ``unlimited``.

    Raises:
        InputError: anything else, or a size <= 0.
    """
    s = str(text).strip().upper()
    if s in ("UNLIMITED", "INF", "NONE"):
        return math.inf
    m = re.fullmatch(r"(\d+(?:\.\d*)?(?:E\d+)?)\s*([KMGT]?)(?:I?B)?", s)
    if m is None or len(s) > 40:
        raise InputError(
            f"{name}: {str(text)[:40]!r} is not a memory size; expected e.g. 8G, 500M, "
            "2000000000 or unlimited"
        )
    value = float(m.group(1)) * _UNITS[m.group(2)]
    if not value > 0 or not math.isfinite(value):
        raise InputError(f"{name}: the memory budget must be > 0, got {str(text)[:40]!r}")
    return value


def set_memory_budget(size: float | str | None) -> None:
    """Set the memory budget for this process.

    Args:
        size: bytes, a size string (see :func:`parse_size`), or None to go back to the
            environment variable / default.
    """
    global _override
    if size is None:
        _override = None
    elif isinstance(size, str):
        _override = parse_size(size, "memory budget")
    else:
        v = float(size)
        if not v > 0:
            raise InputError(f"memory budget must be > 0 bytes, got {size!r}")
        _override = v


def _available_bytes() -> float:
    try:
        with open("/proc/meminfo", encoding="ascii") as f:
            for line in f:
                if line.startswith("MemAvailable:"):
                    return float(line.split()[1]) * 1024
    except (OSError, ValueError, IndexError):
        pass
    try:
        return float(os.sysconf("SC_AVPHYS_PAGES") * os.sysconf("SC_PAGE_SIZE"))
    except (OSError, ValueError, AttributeError):
        return FALLBACK_BYTES / DEFAULT_FRACTION


def memory_budget() -> float:
    """The current budget in bytes (``inf`` when unlimited); see the module docstring."""
    if _override is not None:
        return _override
    env = os.environ.get(ENV_VAR)
    if env:
        return parse_size(env)
    return DEFAULT_FRACTION * _available_bytes()


def format_bytes(n: float) -> str:
    """``n`` bytes as a short human-readable string (powers of 1024)."""
    if not math.isfinite(n):
        return "unlimited"
    for unit in ("B", "KiB", "MiB", "GiB", "TiB", "PiB"):
        if abs(n) < 1024 or unit == "PiB":
            return f"{n:.3g} {unit}" if unit != "B" else f"{int(n)} B"
        n /= 1024
    return f"{n:.3g} PiB"  # pragma: no cover


def check_allocation(what: str, shape: int | tuple[int, ...], itemsize: int = 8, *,
                     setting: str) -> int:
    """Refuse an allocation of ``prod(shape) * itemsize`` bytes beyond the budget.

    Args:
        what: what would be allocated (e.g. "workspace grid").
        shape: the array's shape (or an element count); computed with Python integers,
            so huge products do not overflow.
        itemsize: bytes per element (8 for float64), or an estimate of bytes per item.
        setting: the user setting that drives the size (e.g. "--cell"), named in the error.

    Returns:
        The estimated size in bytes.

    Raises:
        BudgetError: the estimate exceeds :func:`memory_budget`.
    """
    dims = (shape,) if isinstance(shape, int) else tuple(shape)
    count = 1
    for d in dims:
        count *= max(int(d), 0)
    nbytes = count * int(itemsize)
    if nbytes < ALWAYS_ALLOWED:
        return nbytes
    budget = memory_budget()
    if nbytes > budget:
        size = f" ({'x'.join(str(int(d)) for d in dims)} items)" if len(dims) > 1 else ""
        raise BudgetError(
            f"{what} would need about {format_bytes(nbytes)}{size}, beyond the "
            f"memory budget of {format_bytes(budget)}; reduce {setting}, or raise the "
            f"budget with {ENV_VAR}=SIZE (e.g. 16G) or the CLI option --memory-budget"
        )
    return nbytes
