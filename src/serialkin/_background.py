"""First calls answer at once: a kernel not yet compiled runs as Python while it compiles.

A numba kernel compiles at its first call (seconds to tens of seconds, see
docs/compile-time.md). In the default mode, ``background``, a first call does not wait
for that: the kernel is queued for compilation on a worker thread (one, since numba
compiles one kernel at a time) and the call runs the kernel's own Python source
instead (:func:`interpreted`: the same function with every kernel it calls replaced by
its Python source too). Once the worker has compiled it, the next call runs the compiled
code; a kernel already in numba's on-disk cache is loaded at once, as before. So there
is still one implementation of each kernel, and its first answer comes in milliseconds
to seconds instead of after the compile; a process that ends while kernels are still
compiling finishes them first (saying so on stderr), so that the next process finds
them in the cache.

What differs while a kernel runs as Python: speed (a UR5 ``fk`` takes about 0.2 ms
instead of 1 µs; a call whose array arguments hold more than :data:`BIG_ARGUMENTS`
numbers waits for the compiled kernel instead), and the last bits of floating-point
results (compiled kernels let LLVM fuse ``a·b + c`` into one rounding, see
:mod:`serialkin._jit`; Python rounds each operation, and :func:`fma_exact` rounds the
explicit fused operations exactly as the compiled ones do). Results agree to rounding
error; a process that needs the compiled results bit for bit from its first call (the
test suite, a benchmark) sets ``SERIALKIN_COMPILE=wait``, which compiles in the
foreground as numba does.

Environment: ``SERIALKIN_COMPILE`` = ``background`` (default), ``wait`` or ``python``
(:func:`mode`).

A first call that must compile says so on stderr, once per feature and process
(:func:`install_notice`, installed by :func:`serialkin._jit.load_numba` when numba is
loaded), unless ``SERIALKIN_QUIET_COMPILE`` is set to a non-empty value other than
``0``. The features, the kernel modules each covers and their measured compile times
are :data:`serialkin._features.COMPILE_FEATURES`; ``serialkin warmup``
(:mod:`serialkin.warmup`) compiles them ahead of time.
"""

from __future__ import annotations

import math
import os
import sys
import threading
import time
from collections.abc import Iterator
from concurrent.futures import Future, ThreadPoolExecutor
from contextlib import contextmanager
from types import CellType, FunctionType
from typing import Any

#: A first call whose array arguments hold more numbers than this waits for the compiled
#: kernel instead of running as Python (about 0.2-2 µs per number as Python, so a call
#: this large would take longer than most compiles).
BIG_ARGUMENTS = 50_000

#: Python functions standing for compiled-only objects (numba intrinsics) in
#: :func:`interpreted`: ``{intrinsic: python function}``, filled by the modules that
#: define them.
PYTHON_EQUIVALENTS: dict[int, Any] = {}


MODES = ("background", "wait", "python")


def mode() -> str:
    """How a call treats a kernel not yet compiled: one of :data:`MODES`.

    ``background`` (default): compile on the worker thread, run as Python meanwhile;
    ``wait``: compile now, as numba does; ``python``: never compile, always run as
    Python (for debugging and for testing the Python path). Read from
    ``SERIALKIN_COMPILE`` at every decision; an unknown value means ``background``.
    """
    value = os.environ.get("SERIALKIN_COMPILE", "").strip().lower()
    return value if value in MODES else "background"


def fma_exact(a: float, b: float, c: float) -> float:
    """``a·b + c`` rounded once, in Python (the compiled ``fma`` intrinsic's twin).

    The product is split exactly into ``p + e`` (Dekker's two-product with Veltkamp's
    splitting, ``p = fl(a·b)``), and ``math.fsum`` rounds ``p + e + c`` correctly, so the
    result equals IEEE-754 ``fusedMultiplyAdd(a, b, c)`` when ``1e-290 < |a·b| < 1e300``,
    ``|a|, |b| < 1e290`` and ``c`` is finite; otherwise (products near underflow or
    overflow, NaN, ±inf) ``a·b + c``. Python 3.13's ``math.fma`` is used when present.
    """
    a, b, c = float(a), float(b), float(c)
    p = a * b
    if not (1e-290 < abs(p) < 1e300 and abs(a) < 1e290 and abs(b) < 1e290
            and abs(c) < 1.7e308):
        return p + c
    t = 134217729.0 * a  # 2**27 + 1
    ah = t - (t - a)
    al = a - ah
    t = 134217729.0 * b
    bh = t - (t - b)
    bl = b - bh
    return _fsum((p, ((ah * bh - p) + ah * bl + al * bh) + al * bl, c))


_fsum = math.fsum
if hasattr(math, "fma"):  # pragma: no cover - Python >= 3.13
    def fma_exact(a: float, b: float, c: float, _fma=math.fma) -> float:  # noqa: F811
        """``a·b + c`` rounded once (Python's ``math.fma``; see the fallback above)."""
        return _fma(float(a), float(b), float(c))


_PYTHON: dict[int, tuple[object, FunctionType]] = {}


def interpreted(fn: Any) -> Any:
    """The Python function of the kernel ``fn``, calling the Python of its callees.

    A copy of the dispatcher's ``py_func`` whose globals and closure cells hold, in place
    of every numba dispatcher, that dispatcher's :func:`interpreted` function (and in
    place of an intrinsic, its :data:`PYTHON_EQUIVALENTS` entry), so that running it
    compiles nothing. Anything else is returned unchanged. Built once per kernel and
    process (under a lock: threads of a batch may ask at once).
    """
    found = _PYTHON.get(id(fn))
    if found is not None:
        return found[1]
    if not _compiled_object(fn):
        return fn
    with _BUILDING:
        partial: dict[int, tuple[object, Any]] = {}
        copy = _build(fn, partial)
        for key, value in partial.items():  # published once every copy is complete
            _PYTHON.setdefault(key, value)
        return copy


_BUILDING = threading.Lock()


def _build(fn: Any, partial: dict[int, tuple[object, Any]]) -> Any:
    """:func:`interpreted` of ``fn``; copies made in this call are kept in ``partial``."""
    key = id(fn)
    if key in PYTHON_EQUIVALENTS:
        return PYTHON_EQUIVALENTS[key]
    found = _PYTHON.get(key) or partial.get(key)
    if found is not None:
        return found[1]
    py = fn.py_func
    names: dict[str, Any] = {}
    cells = None
    if py.__closure__ is not None:
        cells = tuple(CellType() for _ in py.__closure__)
    copy = FunctionType(py.__code__, names, py.__name__, py.__defaults__, cells)
    copy.__qualname__, copy.__doc__ = py.__qualname__, py.__doc__
    copy.__kwdefaults__ = py.__kwdefaults__
    partial[key] = (fn, copy)  # before the callees: recursion terminates
    for name, value in py.__globals__.items():
        names[name] = _build(value, partial) if _compiled_object(value) else value
    if cells is not None:
        for mine, theirs in zip(cells, py.__closure__):
            value = theirs.cell_contents
            mine.cell_contents = _build(value, partial) if _compiled_object(value) else value
    return copy


def quietly(fn: Any) -> Any:
    """:func:`interpreted` ``fn`` run without NumPy's floating-point and overflow warnings.

    As Python, a kernel's scalars are NumPy scalars, which warn where compiled code is
    silent (the random stream's uint64 products wrap by design); the results are the same.
    Python ``int`` arguments are passed as ``numpy.int64``, the type numba gives them.
    """
    found = _QUIET.get(id(fn))
    if found is not None:
        return found[1]
    import numpy as np

    python = interpreted(fn)

    int64 = np.int64
    clock = time.perf_counter

    def call(*args: Any) -> Any:
        # a Python int is an int64 to a kernel (numba's typing): wraps, casts as in C
        args = tuple(int64(a) if type(a) is int else a for a in args)
        t0 = clock()
        try:
            with np.errstate(all="ignore"):
                return python(*args)
        finally:
            _PYTHON_SECONDS[0] += clock() - t0

    call.__name__ = call.__qualname__ = python.__name__
    call.__doc__ = python.__doc__
    _QUIET[id(fn)] = (fn, call)
    return call


_QUIET: dict[int, tuple[object, Any]] = {}


def _compiled_object(value: object) -> bool:
    """A kernel (lazy or a numba dispatcher) or an object with a Python equivalent."""
    if id(value) in PYTHON_EQUIVALENTS or getattr(type(value), "is_kernel_proxy", False):
        return True
    dispatcher = sys.modules.get("numba.core.dispatcher")
    return dispatcher is not None and isinstance(value, dispatcher.Dispatcher)


class _Worker:
    """The compile queue: one thread, one job per (dispatcher, signature)."""

    def __init__(self) -> None:
        self._pool: ThreadPoolExecutor | None = None
        self._jobs: dict[tuple[int, tuple], Future] = {}
        self._lock = threading.Lock()

    def submit(self, dispatcher: Any, sig: tuple) -> Future:
        """The job compiling (or loading) ``dispatcher`` for ``sig``, queued if new."""
        key = (id(dispatcher), sig)
        with self._lock:
            job = self._jobs.get(key)
            if job is None:
                if self._pool is None:
                    self._pool = ThreadPoolExecutor(1, thread_name_prefix="serialkin-compile")
                    _at_exit(self)
                job = self._jobs[key] = self._pool.submit(dispatcher.compile, sig)
        return job

    def pending(self) -> list[Future]:
        """The jobs not finished yet."""
        with self._lock:
            return [j for j in self._jobs.values() if not j.done()]


_WORKER = _Worker()


def _at_exit(worker: _Worker) -> None:
    """At interpreter exit, finish the queued compiles (they fill the on-disk cache)."""

    def finish() -> None:
        jobs = worker.pending()
        if not jobs:
            return
        if os.environ.get("SERIALKIN_QUIET_COMPILE", "") in ("", "0"):
            print("serialkin: finishing the kernels' compile before exit, so that the next "
                  "run starts compiled (Ctrl-C skips)", file=sys.stderr, flush=True)
        try:
            for job in jobs:
                job.exception()  # waits; an error shows at the next run's call instead
        except KeyboardInterrupt:
            for job in jobs:
                job.cancel()

    register = getattr(threading, "_register_atexit", None)
    if register is None:  # pragma: no cover - CPython has it since 3.9
        import atexit

        register = atexit.register
    register(finish)


def on_disk(dispatcher: Any, sig: tuple) -> bool:
    """Whether numba's on-disk cache holds ``dispatcher`` compiled for ``sig`` (fresh).

    Reads the cache's index only (no LLVM work, so it is safe while the worker compiles).
    """
    cache = getattr(dispatcher, "_cache", None)
    if cache is None or not getattr(cache, "_enabled", False):
        return False
    try:
        key = cache._index_key(sig, dispatcher.targetctx.codegen())
        return key in cache._cache_file._load_index()
    except Exception:  # noqa: BLE001 - an unreadable cache is an empty cache
        return False


#: In :func:`answer_first`: the time [s] a process may spend running kernels as Python
#: before it loads or compiles them (about what loading the first kernels costs).
LOAD_SECONDS = 0.5
_PYTHON_SECONDS = [0.0]  # time spent so far running kernels as Python, this process
_ANSWER_FIRST = [0]


@contextmanager
def answer_first() -> Iterator[None]:
    """Inside: small calls of kernels not yet loaded run as Python, nothing is queued.

    For one-shot commands (``serialkin fk``, ``ik``): loading the first compiled kernels
    costs a process about half a second (numba sets up its compiler), more than a few
    calls take as Python. Inside this context a call with at most
    :data:`BIG_ARGUMENTS` numbers of a kernel not loaded in this process runs as Python
    (even one in the on-disk cache) and queues no compile, until the process has spent
    :data:`LOAD_SECONDS` running kernels as Python; after that, and for larger calls,
    kernels load or compile as usual. Applies in ``background`` mode only.
    """
    _ANSWER_FIRST[0] += 1
    try:
        yield
    finally:
        _ANSWER_FIRST[0] -= 1


def _size(args: tuple) -> int:
    return sum(getattr(a, "size", 0) for a in args if hasattr(a, "dtype"))


def prefers_python(args: tuple) -> bool:
    """Whether a call with arguments ``args`` of a kernel not loaded runs as Python.

    In ``python`` mode always; inside :func:`answer_first`, for at most
    :data:`BIG_ARGUMENTS` numbers while the process has spent less than
    :data:`LOAD_SECONDS` running kernels as Python (``background`` mode).
    """
    how = mode()
    return how == "python" or (how == "background" and _ANSWER_FIRST[0] > 0
                               and _PYTHON_SECONDS[0] < LOAD_SECONDS
                               and _size(args) <= BIG_ARGUMENTS)


def entry(dispatcher: Any, sig: Any, args: tuple = ()) -> tuple[Any, bool]:
    """What to call for ``dispatcher`` with argument types ``sig``: ``(function, final)``.

    ``dispatcher`` is a numba dispatcher or a :class:`serialkin._jit.Kernel` (numba is
    loaded only when the answer is not the Python function); ``sig`` a tuple of numba
    types or a function returning one.

    ``final`` is True for the compiled entry point (compiled here, loaded from the
    on-disk cache, or finished by the worker) and False for the :func:`interpreted`
    function returned while the worker compiles it; the caller keeps only a final one.
    Compiles in the foreground when the mode is ``wait``; in ``python`` mode always
    returns the Python function; in ``background`` mode waits for the worker when the
    kernel is on disk and the worker is idle (loading takes milliseconds), or when
    ``args`` (the call's arguments, if known) hold more than :data:`BIG_ARGUMENTS`
    numbers. A compile error is raised here, by the first call after the worker met it.
    """
    if getattr(type(dispatcher), "is_kernel_proxy", False):  # numba not loaded yet
        if dispatcher._real is None and prefers_python(args):
            return quietly(dispatcher), False
        dispatcher = dispatcher.dispatcher
    sig = tuple(sig() if callable(sig) else sig)
    done = dispatcher.overloads.get(sig)
    if done is not None:
        return done.entry_point, True
    how = mode()
    if how == "wait":
        return dispatcher.compile(sig), True
    if prefers_python(args):
        return quietly(dispatcher), False
    job = _WORKER.submit(dispatcher, sig)
    if not job.done() and _size(args) <= BIG_ARGUMENTS \
            and (len(_WORKER.pending()) > 1 or not on_disk(dispatcher, sig)):
        return quietly(dispatcher), False
    job.result()
    return dispatcher.overloads[sig].entry_point, True


# ---------------------------------------------------------------- the first-compile notice
def _quiet() -> bool:
    return os.environ.get("SERIALKIN_QUIET_COMPILE", "") not in ("", "0")


_NOTICE: list[object] = []


def install_notice() -> None:
    """Print one line to stderr when a serialkin kernel starts compiling (once per feature).

    A numba event listener (``numba:compile``, which fires only when a kernel is really
    compiled, not when it is loaded from the cache): at the outermost compile of a kernel
    of a feature not yet announced in this process it writes, for example::

        serialkin: compiling the ik kernels once (about 27 s); `serialkin warmup` does
        this ahead of time

    :func:`serialkin._jit.load_numba` installs it when it loads numba (``import
    serialkin`` does not load numba); called earlier, it imports numba. Silenced by
    ``SERIALKIN_QUIET_COMPILE=1``. Installing twice is harmless.
    """
    with _NOTICE_LOCK:
        if _NOTICE:
            return
        _NOTICE.append(_listener())


_NOTICE_LOCK = threading.Lock()


def _listener() -> object:
    """Register the notice's numba event listener and return it."""
    import importlib

    from numba.core import event

    # the feature table by name, not by an import statement: serialkin._jit's dependency
    # stamps follow import statements, and every kernel's stamp includes this module's
    # (through _jit); the table's timings and summaries change no compiled code
    features = importlib.import_module("serialkin._features")
    announced: set[str] = set()

    class _Notice(event.Listener):
        depth = 0

        def on_start(self, ev: event.Event) -> None:
            self.depth += 1
            if self.depth != 1 or _quiet():
                return
            module = getattr(ev.data["dispatcher"].py_func, "__module__", "") or ""
            if not module.startswith("serialkin."):
                return
            f = features.feature_of_module(module)
            name = f.name if f else module.removeprefix("serialkin.").split(".")[0]
            if name in announced:
                return
            announced.add(name)
            about = f"about {f.seconds:.0f} s" if f else ""
            if mode() == "background":
                about = f" ({about}; until then they run uncompiled, slower)" if about else \
                    " (until then they run uncompiled, slower)"
                print(f"serialkin: compiling the {name} kernels in the background{about}; "
                      f"`serialkin warmup` does this ahead of time", file=sys.stderr,
                      flush=True)
                return
            about = f" ({about})" if about else ""
            print(f"serialkin: compiling the {name} kernels once{about}; "
                  f"`serialkin warmup` does this ahead of time", file=sys.stderr, flush=True)

        def on_end(self, ev: event.Event) -> None:
            self.depth -= 1

    listener = _Notice()
    event.register("numba:compile", listener)
    return listener
