"""How serialkin compiles a kernel: numba's ``njit`` with floating-point contraction.

Every compiled module imports ``njit`` from here instead of from numba, so that one
setting holds everywhere: ``fastmath={"contract"}`` lets LLVM fuse a multiplication and
the addition that consumes it into one fused multiply-add (``fma(a, b, c) = a·b + c``
rounded once). It is the only fast-math flag used: it never reorders a sum, never assumes
finite values (NaN and ±inf still propagate and are still detected) and each fused
operation is at least as accurate as the two it replaces (one rounding instead of two).
Measured on the kernels (x86-64 with FMA3): batch FK 42 → 33 ns per UR5 pose on one
thread; an IK ``lm`` iteration 10–20 % faster, a Panda solve 10.7–11.3 → 9.3–10.1 µs
(``benchmarks/bench_ik.py``, old and new trees interleaved). Results
may differ from an uncontracted build in the last bits; every path through the same
kernel still gives the same bits (batch and single FK, fast and ordinary IK paths).

A module's own options pass through (``cache``, ``nogil``, ``inline``, ...).

**The on-disk cache notices every edit that matters.** numba keys a cached kernel on
its own source file only, so an edit to a kernel it calls in another module would leave
a stale (wrong) kernel in the cache. serialkin's kernels are therefore cached by a
locator of their own (:class:`_InTreeLocator`, :class:`_UserDirLocator`, inserted
before numba's) whose source stamp is :func:`dependency_stamp`: a hash of the kernel's
file and of every serialkin module it imports, directly or through others. An edit
invalidates exactly the kernels of the edited module and of the modules that import
it; nothing else is recompiled and nothing has to be deleted.

Exceptions, compiled by :func:`njit_exact` (no contraction): the path trackers of
:mod:`serialkin.tracking` and the resolvers of :mod:`serialkin.redundancy`. They iterate
step after step along a path, so a last-bit difference at one step is carried on to all
later ones, and the chapter's hardest scenario (Figure 12: twenty links between four
obstacles, 5 mm tolerance) turns a sharp corner at 4.1 mm: contracted, that corner's
error came out at 6.5 mm. They keep the rounding their figures were made with.
"""

from __future__ import annotations

import functools
import hashlib
import os
import re
import sys
import threading
from collections.abc import Callable
from types import FunctionType

from serialkin import _background

#: The fast-math flags of every serialkin kernel (see the module docstring).
FASTMATH = frozenset({"contract"})

# ------------------------------------------------------------- kernels before numba loads
# Importing numba takes about 0.3 s, more than the rest of ``import serialkin``; a
# command that answers with the kernels' Python (serialkin fk, a first call while
# compiling) does not need it. So a decorated kernel is first a :class:`Kernel`, which
# holds its Python function and options; numba is imported, and every kernel made a
# numba dispatcher, the first time any kernel is needed compiled (:func:`load_numba`).
_LOCK = threading.RLock()
_KERNELS: list[Kernel] = []          # made before numba was loaded
_BOUND: list[dict] = []              # globals of :func:`bind` copies made before
_ON_LOAD: list[Callable[[], None]] = []
_NUMBA: list[object] = []            # [numba] once loaded
_Dispatcher: type = object           # numba's dispatcher class, ours (see load_numba)


class Kernel:
    """A compiled kernel before numba is imported: its Python function and options.

    Behaves as the numba dispatcher it becomes (:attr:`dispatcher`, made by
    :func:`load_numba` on first need): calling it, or any attribute numba's dispatchers
    have, loads numba first, except a call that :func:`serialkin._background.prefers_python`
    answers with the kernel's Python. ``py_func`` is available without numba.
    """

    is_kernel_proxy = True

    def __init__(self, py_func: FunctionType, options: dict) -> None:
        self._real = None
        self.py_func = py_func
        self.options = options
        functools.update_wrapper(self, py_func)

    @property
    def dispatcher(self):
        """The numba dispatcher of this kernel (imports numba the first time)."""
        if self._real is None:
            load_numba()
        return self._real

    def __call__(self, *args, **kws):
        if self._real is None and not kws and _background.prefers_python(args):
            return _background.quietly(self)(*args)
        return self.dispatcher(*args, **kws)

    def __getattr__(self, name: str):
        if name.startswith("__") or name in ("_real", "py_func", "options"):
            raise AttributeError(name)
        return getattr(self.dispatcher, name)

    def __reduce__(self):
        return self.dispatcher.__reduce__()

    def __repr__(self) -> str:
        return f"<serialkin kernel {self.__qualname__} ({'loaded' if self._real else 'lazy'})>"


class _LazyIntrinsic:
    """``fma`` before numba is loaded: calling it from Python gives :func:`fma_exact`."""

    is_kernel_proxy = False

    def __call__(self, a, b, c):
        return _background.fma_exact(a, b, c)


fma = _LazyIntrinsic()
_LAZY_FMA = fma  # ``fma`` itself is replaced by the intrinsic when numba loads
fma.__doc__ = """``a·b + c`` rounded once (LLVM's ``llvm.fma.f64``; one instruction with FMA3).

For kernels whose results must not depend on what LLVM chooses to contract: two code
paths that must agree bit for bit (one pose and a batch of poses) spell their fused
operations out with this and compile with ``fastmath=False``. Arguments are cast to
float64. A numba intrinsic once numba is loaded; in Python, :func:`fma_exact`.
"""
_background.PYTHON_EQUIVALENTS[id(_LAZY_FMA)] = _background.fma_exact


def _readonly_view(a):
    """A read-only view of the array ``a`` (no copy): :data:`as_readonly` in Python."""
    v = a.view()
    v.flags.writeable = False
    return v


class _LazyReadonly:
    """``as_readonly`` before numba is loaded: calling it from Python gives a read-only view."""

    is_kernel_proxy = False

    def __call__(self, a):
        return _readonly_view(a)


as_readonly = _LazyReadonly()
_LAZY_READONLY = as_readonly  # replaced by the intrinsic when numba loads, as ``fma`` is
as_readonly.__doc__ = """The array ``a`` typed read-only, inside a kernel: no copy, no instruction.

numba compiles a kernel once per set of argument types, and a read-only and a writeable
array are two types. Data a kernel only reads is passed read-only
(:func:`serialkin._checks.readonly` at the Python boundary); a kernel that holds such
data in a writeable array (a user's target that a fast path passes as it came, a
scratch array it has just filled) passes ``as_readonly(a)`` to a kernel that only reads
it, so that the callee compiles once (issue 27). The view shares ``a``'s memory, so it
sees later writes to ``a``. A numba intrinsic once numba is loaded; in Python, a
read-only view.
"""
_background.PYTHON_EQUIVALENTS[id(_LAZY_READONLY)] = _readonly_view


def numba_loaded() -> bool:
    """Whether numba has been imported and the kernels made dispatchers."""
    return bool(_NUMBA)


def on_numba_load(callback: Callable[[], None]) -> None:
    """Call ``callback()`` once numba is loaded (now, if it is)."""
    with _LOCK:
        if not _NUMBA:
            _ON_LOAD.append(callback)
            return
    callback()


def load_numba() -> None:
    """Import numba and make every :class:`Kernel` its dispatcher (once per process).

    Defines what needs numba (the dispatcher class, the ``fma`` and ``as_readonly``
    intrinsics, the cache locators), then replaces every :class:`Kernel` and the lazy
    intrinsics in the globals of serialkin's modules and of :func:`bind` copies by the
    real objects, so that numba,
    compiling a kernel, finds dispatchers and intrinsics among its globals; a
    :class:`Kernel` kept elsewhere (in a container) forwards to its dispatcher. Last, it
    installs the first-compile notice (:func:`serialkin._background.install_notice`) and
    runs the :func:`on_numba_load` callbacks.
    """
    with _LOCK:
        if _NUMBA:
            return
        import numba

        real_fma, real_readonly = _define_numba_objects()
        for k in _KERNELS:
            k._real = _compiled(numba.njit(**k.options)(k.py_func))
        namespaces = [vars(m) for name, m in list(sys.modules.items())
                      if (name == "serialkin" or name.startswith("serialkin."))
                      and m is not None]
        lazy_fma = _LAZY_FMA  # locals: this module's own names are replaced too
        lazy_readonly = _LAZY_READONLY
        for names in namespaces + _BOUND:
            for key, value in list(names.items()):
                if type(value) is Kernel:
                    names[key] = value._real
                elif value is lazy_fma and key != "_LAZY_FMA":
                    names[key] = real_fma
                elif value is lazy_readonly and key != "_LAZY_READONLY":
                    names[key] = real_readonly
        _KERNELS.clear()
        _BOUND.clear()
        _NUMBA.append(numba)
        # the first-compile notice listens from now on (numba's events need numba)
        callbacks = [_background.install_notice, *_ON_LOAD]
        _ON_LOAD.clear()
    for callback in callbacks:
        callback()


def _define_numba_objects():
    """The numba-side definitions (see :func:`load_numba`); returns the two intrinsics.

    ``(fma, as_readonly)``: the dispatcher class (:func:`_define_dispatcher`), the
    intrinsics (:func:`_define_intrinsics`), the type of a :class:`Kernel` met as a value
    and the cache locators.
    """
    from numba.extending import typeof_impl

    _define_dispatcher()
    real_fma, real_readonly = _define_intrinsics()

    @typeof_impl.register(Kernel)
    def _typeof_kernel(val, c):  # a Kernel numba meets as a value: its dispatcher's type
        return typeof_impl(val.dispatcher, c)

    globals()["_UserDirLocator"], globals()["_InTreeLocator"] = _install_locators()
    return real_fma, real_readonly


def _define_dispatcher() -> None:
    """Define ``_Dispatcher`` (a module global, so that it pickles by reference)."""
    import numba
    from numba.core import types
    from numba.core.dispatcher import OmittedArg

    class _Dispatcher(numba.core.registry.CPUDispatcher):
        """numba's dispatcher, but a call from another kernel never specialises on a literal.

        numba types a constant argument in a kernel (``f(x, 0)``) as a literal
        (``Literal[int](0)``) and compiles the callee once for that literal and once more
        for an ``int64`` passed elsewhere: measured, ``_sincos_banks`` compiled four times
        and ``fk_range`` twice in one process. Calls are resolved with the arguments'
        ordinary types instead, so each kernel compiles once (a kernel that needs a
        compile-time constant reads a module global, never an argument).
        """

        def get_call_template(self, args, kws):
            """The call template of numba for the non-literal types of ``args`` and ``kws``."""
            args = tuple(types.unliteral(a) for a in args)
            kws = {k: types.unliteral(v) for k, v in kws.items()}
            return super().get_call_template(args, kws)

        def compile(self, sig):
            """Compile ``sig`` at this kernel's optimisation level (:func:`opt_level`)."""
            return _at_opt_level(self.py_func, super().compile, sig)

        def _compile_for_args(self, *args, **kws):
            """A call from Python found no compiled version: compile, or run as Python.

            In ``background`` mode (:mod:`serialkin._background`) the kernel is queued for
            compilation and this call runs its Python source; in ``wait`` mode, or for
            arguments numba passes specially (keywords, omitted defaults), numba compiles
            it here as usual.
            """
            if kws or _background.mode() == "wait" or \
                    any(isinstance(a, OmittedArg) for a in args):
                return super()._compile_for_args(*args, **kws)
            self._compilation_chain_init_hook()
            sig = tuple(self.typeof_pyval(a) for a in args)
            return _background.entry(self, sig, args)[0]

    _Dispatcher.__module__ = __name__
    _Dispatcher.__qualname__ = "_Dispatcher"
    globals()["_Dispatcher"] = _Dispatcher  # pickled by reference


def _define_intrinsics() -> tuple:
    """``(fma, as_readonly)``: numba intrinsics, each with its Python equivalent registered.

    ``fma(a, b, c)`` is LLVM's fused ``a·b + c`` (one rounding); ``as_readonly(a)`` the
    same array typed read-only (a new reference to the same memory, no copy).
    """
    from llvmlite import ir
    from numba.core import cgutils, types
    from numba.core.imputils import impl_ret_borrowed
    from numba.extending import intrinsic

    def fma_intrinsic(typingctx, a, b, c):
        f64 = types.float64
        sig = f64(a, b, c)

        def codegen(context, builder, signature, args):
            xs = [context.cast(builder, v, t, f64) for v, t in zip(args, signature.args)]
            d = ir.DoubleType()
            fn = cgutils.get_or_insert_function(builder.module,
                                                ir.FunctionType(d, [d, d, d]), "llvm.fma.f64")
            return builder.call(fn, xs)

        return sig, codegen

    fma_intrinsic.__name__ = fma_intrinsic.__qualname__ = "fma"
    real_fma = intrinsic(fma_intrinsic)
    _background.PYTHON_EQUIVALENTS[id(real_fma)] = _background.fma_exact

    def readonly_intrinsic(typingctx, a):
        if not isinstance(a, types.Array):
            return None
        sig = a.copy(readonly=True)(a)

        def codegen(context, builder, signature, args):
            # the same array structure (the two types share numba's data model): a new
            # reference to the same memory
            return impl_ret_borrowed(context, builder, signature.return_type, args[0])

        return sig, codegen

    readonly_intrinsic.__name__ = readonly_intrinsic.__qualname__ = "as_readonly"
    real_readonly = intrinsic(readonly_intrinsic)
    _background.PYTHON_EQUIVALENTS[id(real_readonly)] = _readonly_view
    return real_fma, real_readonly


def _compiled(decorated):
    """``decorated`` (a dispatcher or a decorator making one) as a ``_Dispatcher``."""
    import numba

    if isinstance(decorated, numba.core.registry.CPUDispatcher):
        decorated.__class__ = _Dispatcher
        return decorated

    def decorate(fn):
        return _compiled(decorated(fn))

    return decorate


def _decorator(args: tuple, options: dict):
    """``numba.njit(*args, **options)``, as a :class:`Kernel` while numba is not loaded.

    ``options["hot"]`` (serialkin's own option, not numba's) marks the kernel for
    LLVM's ``-O3`` (see :func:`opt_level`).
    """
    hot = options.pop("hot", False)
    given = bool(args) and isinstance(args[0], FunctionType)
    if hot and given:
        _mark_hot(args[0])
    if _NUMBA:
        import numba

        made = numba.njit(*args, **options)
        if hot and not given:
            return _compiled(lambda fn: made(_mark_hot(fn)))
        return _compiled(made)

    def make(fn):
        if hot:
            _mark_hot(fn)
        with _LOCK:
            if _NUMBA:  # loaded meanwhile (by another thread)
                return _decorator((), options)(fn)
            kernel = Kernel(fn, options)
            _KERNELS.append(kernel)
            return kernel

    if len(args) == 1 and isinstance(args[0], FunctionType):
        return make(args[0])
    if args:  # an explicit signature compiles at once: numba is needed now
        load_numba()
        return _decorator(args, dict(options, hot=hot))
    return make


# ------------------------------------------------------------------ optimisation levels
#: LLVM's optimisation level of the kernels marked ``hot`` (the ones the warm-speed goals
#: name: forward kinematics, Jacobians, the default IK method's loop) and of all others.
HOT_OPT, OPT = 3, 2
_COMPILING = threading.local()


def _mark_hot(fn: FunctionType) -> FunctionType:
    """Mark the Python function ``fn`` of a kernel for :data:`HOT_OPT`; return it."""
    fn._serialkin_hot = True
    return fn


def opt_level(py_func: FunctionType) -> int:
    """The LLVM optimisation level a kernel is compiled at (``-O2`` or ``-O3``).

    ``-O3`` (:data:`HOT_OPT`) for kernels declared ``njit(..., hot=True)``; ``-O2``
    (:data:`OPT`) for every other. Measured on a quiet 2-core machine (the ``ik-all``
    feature's kernels, fresh cache): 71 s to compile at ``-O3``, 48 s at ``-O2``, the same
    warm speed within the machine's noise for ``ik_all`` (UR5 5.5–7.8 µs at ``-O3``,
    5.7–8.2 µs at ``-O2``); FK and the ``lm`` IK loop lose 15–40 % at ``-O2``, so they
    stay at ``-O3`` (docs/compile-time.md). ``NUMBA_OPT`` set in the environment wins.
    """
    return HOT_OPT if getattr(py_func, "_serialkin_hot", False) else OPT


def _at_opt_level(py_func: FunctionType, compile_: Callable, sig):
    """``compile_(sig)`` with numba's optimisation level set for the kernel ``py_func``.

    A kernel compiled for its own sake (called from Python) gets ``opt_level(py_func)``; a
    callee compiled while another kernel compiles gets its caller's level (the caller
    optimises it again, with that level, when it links it), except a ``hot`` kernel,
    always ``-O3``: what a user calls directly stays as fast whichever feature compiled
    it first. Set only while numba's compiler lock is held, so no other compile (a user's
    own kernels, another thread's) sees it. ``NUMBA_OPT`` in the environment turns this
    off.
    """
    if "NUMBA_OPT" in os.environ:
        return compile_(sig)
    outer = getattr(_COMPILING, "level", None)
    level = opt_level(py_func) if outer is None or getattr(py_func, "_serialkin_hot", False) \
        else outer
    if level == outer:
        return compile_(sig)
    from numba.core import config
    from numba.core.compiler_lock import global_compiler_lock

    with global_compiler_lock:
        saved = config.OPT
        config.OPT = type(saved)(level)
        _COMPILING.level = level
        try:
            return compile_(sig)
        finally:
            _COMPILING.level = outer
            config.OPT = saved


def njit(*args, **options):
    """``numba.njit`` with ``fastmath=FASTMATH`` unless the caller sets ``fastmath``.

    Used exactly like ``numba.njit``: ``@njit``, ``@njit(cache=True, ...)`` or
    ``njit(signature, ...)``; the dispatcher resolves calls from other kernels without
    literal types. Returns a :class:`Kernel` until numba is loaded.
    """
    options.setdefault("fastmath", set(FASTMATH))
    return _decorator(args, options)


def njit_exact(*args, **options):
    """``numba.njit`` without fast-math flags: every product and sum rounded on its own."""
    options["fastmath"] = False
    return _decorator(args, options)


def entry_point(dispatcher, sig):
    """``(function, final)``: the entry point of ``dispatcher`` for exactly the types ``sig``.

    The compiled function itself (loaded from numba's on-disk cache, or compiled), with
    ``final`` True: calling it skips numba's per-call type dispatch (0.2-2 µs) but checks
    nothing, so callers pass exactly those types. While the kernel compiles in the
    background (:func:`serialkin._background.entry`) it is the kernel's Python function,
    with ``final`` False: callers keep only a final entry point and ask again next time.
    ``sig`` may be a function returning the types (called only when numba is needed).
    """
    return _background.entry(dispatcher, sig)


def bind(template, qualname: str, **bound):
    """A copy of the Python function ``template`` with ``bound`` added to its globals.

    For kernels assembled from parts: the copy calls the functions bound here directly
    (numba treats a global function as a constant, so LLVM can inline it), and its
    ``qualname`` names the on-disk cache entry, one per combination of parts.
    """
    g = dict(template.__globals__)
    g.update(bound)
    with _LOCK:
        if not _NUMBA:
            _BOUND.append(g)  # its kernels become dispatchers when numba loads
        else:  # a kernel kept in a container before numba loaded, bound now
            for key, value in list(g.items()):
                if type(value) is Kernel:
                    g[key] = value.dispatcher
    fn = FunctionType(template.__code__, g, qualname)
    fn.__qualname__ = qualname
    fn.__doc__ = template.__doc__
    return fn


# ---------------------------------------------------------------- the cache's source stamp
_PACKAGE_DIR = os.path.dirname(os.path.abspath(__file__))
_IMPORT = re.compile(r"^[ \t]*(?:from[ \t]+(\.*)([\w.]*)[ \t]+import[ \t]+"
                     r"(?:\(([^)]*)\)|([\w \t,]+))|import[ \t]+(serialkin[\w.]*))",
                     re.MULTILINE)
_STAMPS: dict[str, str] = {}


def _module_file(module: str) -> str | None:
    """The file of serialkin module ``module`` (dotted, from the package), or None."""
    parts = module.split(".")
    if not parts or parts[0] != "serialkin":
        return None
    base = os.path.join(_PACKAGE_DIR, *parts[1:])
    for path in (base + ".py", os.path.join(base, "__init__.py")):
        if os.path.isfile(path):
            return path
    return None


def _imports(path: str) -> set[str]:
    """The files of the serialkin modules that the source file ``path`` imports.

    A static scan of its ``import`` and ``from ... import`` lines (also inside functions:
    more than needed rather than less), relative imports resolved. ``from A import b``
    counts the module ``A.b`` when it exists, else ``A`` (``b`` is then defined in A).
    """
    rel = os.path.relpath(path, _PACKAGE_DIR)[:-3].split(os.sep)
    package = ["serialkin", *rel[:-1]]
    with open(path, encoding="utf-8") as f:
        text = f.read()
    found = set()
    for dots, name, group, names, plain in _IMPORT.findall(text):
        names = group or names
        if plain:
            candidates = [plain]
        else:
            if dots:
                up = len(dots) - 1
                base = package[:len(package) - up] if up else package
                module = ".".join(base + ([name] if name else []))
            else:
                module = name
            # ``from A import b``: the module A.b when there is one, else A itself (b is
            # a name defined in A). Not A's __init__ for a submodule: the package
            # serialkin's own __init__ imports nearly everything, and would make every
            # kernel's stamp change with any edit anywhere.
            subs = [f"{module}.{n.split()[0]}" for n in names.split(",") if n.split()]
            candidates = [m for m in subs if _module_file(m) is not None]
            if len(candidates) < len(subs) or not subs:
                candidates.append(module)
        for m in candidates:
            file = _module_file(m)
            if file is not None and file != path:
                found.add(file)
    return found


_IMPORTED: dict[str, frozenset[str]] = {}
_DIGESTS: dict[str, bytes] = {}


def _imports_of(path: str) -> frozenset[str]:
    """:func:`_imports` of ``path``, read once per process."""
    found = _IMPORTED.get(path)
    if found is None:
        found = _IMPORTED[path] = frozenset(_imports(path))
    return found


def _digest(path: str) -> bytes:
    """The sha256 of the file ``path``'s package-relative name and bytes, once per process."""
    found = _DIGESTS.get(path)
    if found is None:
        with open(path, "rb") as f:
            rel = os.path.relpath(path, _PACKAGE_DIR).encode()
            found = _DIGESTS[path] = hashlib.sha256(rel + b"\0" + f.read()).digest()
    return found


def dependency_stamp(path: str) -> str:
    """A hash of the source file ``path`` and of every serialkin module it imports.

    The closure over imports (see :func:`_imports`), each file's digest hashed in a
    fixed order. Each file is read and scanned once per process (numba asks for the stamp
    of every kernel when the module defining it is imported: about 200 kernels in 60
    files), and each stamp is computed once. Files outside the package give the hash of
    their own bytes.
    """
    path = os.path.abspath(path)
    if path in _STAMPS:
        return _STAMPS[path]
    seen, todo = {path}, [path]
    inside = path.startswith(_PACKAGE_DIR + os.sep)
    while todo and inside:
        for dep in _imports_of(todo.pop()):
            if dep not in seen:
                seen.add(dep)
                todo.append(dep)
    h = hashlib.sha256()
    for file in sorted(seen):
        if inside:
            h.update(_digest(file))
        else:
            with open(file, "rb") as f:
                h.update(os.path.relpath(file, _PACKAGE_DIR).encode() + b"\0" + f.read())
    _STAMPS[path] = stamp = h.hexdigest()
    return stamp


def _locator(base: type) -> type:
    """A numba cache locator like ``base`` for serialkin's files, stamped by dependencies."""

    class Locator(base):
        def get_source_stamp(self):
            return dependency_stamp(self._py_file)

        @classmethod
        def from_function(cls, py_func, py_file):
            if not os.path.abspath(py_file).startswith(_PACKAGE_DIR + os.sep):
                return None
            return super().from_function(py_func, py_file)

    Locator.__name__ = Locator.__qualname__ = f"Serialkin{base.__name__.lstrip('_')}"
    return Locator


def _install_locators() -> tuple[type, type]:
    """Put serialkin's two locators first in numba's list (once); return them.

    Returns ``(user-directory locator, in-tree locator)``: ``$NUMBA_CACHE_DIR`` when set,
    else ``__pycache__`` beside the sources, as numba's own two.
    """
    from numba.core import caching

    user = getattr(caching, "UserProvidedCacheLocator", None) or \
        caching._UserProvidedCacheLocator
    tree = getattr(caching, "InTreeCacheLocator", None) or caching._InTreeCacheLocator
    classes = (getattr(caching, "CacheImpl", None) or caching._CacheImpl)._locator_classes
    if not getattr(classes[0], "_serialkin", False):  # not yet installed in this process
        mine = [_locator(user), _locator(tree)]
        for c in mine:
            c._serialkin = True
        classes[:0] = mine
    return classes[0], classes[1]

