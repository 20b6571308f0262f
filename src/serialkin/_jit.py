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

import hashlib
import os
import re
from types import FunctionType

import numba
from llvmlite import ir
from numba.core import cgutils, types
from numba.core.dispatcher import OmittedArg
from numba.extending import intrinsic

from serialkin import _background

#: The fast-math flags of every serialkin kernel (see the module docstring).
FASTMATH = frozenset({"contract"})


class _Dispatcher(numba.core.registry.CPUDispatcher):
    """numba's dispatcher, but a call from another kernel never specialises on a literal.

    numba types a constant argument in a kernel (``f(x, 0)``) as a literal
    (``Literal[int](0)``) and compiles the callee once for that literal and once more for
    an ``int64`` passed elsewhere: measured, ``_sincos_banks`` compiled four times and
    ``fk_range`` twice in one process. Calls are resolved with the arguments' ordinary
    types instead, so each kernel compiles once (a kernel that needs a compile-time
    constant reads a module global, never an argument).
    """

    def get_call_template(self, args, kws):
        """The call template of numba for the non-literal types of ``args`` and ``kws``."""
        args = tuple(types.unliteral(a) for a in args)
        kws = {k: types.unliteral(v) for k, v in kws.items()}
        return super().get_call_template(args, kws)

    def _compile_for_args(self, *args, **kws):
        """A call from Python found no compiled version: compile, or run as Python meanwhile.

        In ``background`` mode (:mod:`serialkin._background`) the kernel is queued for
        compilation and this call runs its Python source; in ``wait`` mode, or for
        arguments numba passes specially (keywords, omitted defaults), numba compiles it
        here as usual.
        """
        if kws or _background.mode() == "wait" or \
                any(isinstance(a, OmittedArg) for a in args):
            return super()._compile_for_args(*args, **kws)
        self._compilation_chain_init_hook()
        sig = tuple(self.typeof_pyval(a) for a in args)
        return _background.entry(self, sig, args)[0]


def _compiled(decorated):
    """``decorated`` (a dispatcher or a decorator making one) as a :class:`_Dispatcher`."""
    if isinstance(decorated, numba.core.registry.CPUDispatcher):
        decorated.__class__ = _Dispatcher
        return decorated

    def decorate(fn):
        return _compiled(decorated(fn))

    return decorate


def njit(*args, **options):
    """``numba.njit`` with ``fastmath=FASTMATH`` unless the caller sets ``fastmath``.

    Used exactly like ``numba.njit``: ``@njit``, ``@njit(cache=True, ...)`` or
    ``njit(signature, ...)``; the dispatcher resolves calls from other kernels without
    literal types (:class:`_Dispatcher`).
    """
    options.setdefault("fastmath", set(FASTMATH))
    return _compiled(numba.njit(*args, **options))


def entry_point(dispatcher, sig):
    """``(function, final)``: the entry point of ``dispatcher`` for exactly the types ``sig``.

    The compiled function itself (loaded from numba's on-disk cache, or compiled), with
    ``final`` True: calling it skips numba's per-call type dispatch (0.2-2 µs) but checks
    nothing, so callers pass exactly those types. While the kernel compiles in the
    background (:func:`serialkin._background.entry`) it is the kernel's Python function,
    with ``final`` False: callers keep only a final entry point and ask again next time.
    """
    return _background.entry(dispatcher, tuple(sig))


def bind(template, qualname: str, **bound):
    """A copy of the Python function ``template`` with ``bound`` added to its globals.

    For kernels assembled from parts: the copy calls the functions bound here directly
    (numba treats a global function as a constant, so LLVM can inline it), and its
    ``qualname`` names the on-disk cache entry, one per combination of parts.
    """
    g = dict(template.__globals__)
    g.update(bound)
    fn = FunctionType(template.__code__, g, qualname)
    fn.__qualname__ = qualname
    fn.__doc__ = template.__doc__
    return fn


def njit_exact(*args, **options):
    """``numba.njit`` without fast-math flags: every product and sum rounded on its own."""
    options["fastmath"] = False
    return _compiled(numba.njit(*args, **options))


@intrinsic
def fma(typingctx, a, b, c):
    """``a·b + c`` rounded once (LLVM's ``llvm.fma.f64``; one instruction with FMA3).

    For kernels whose results must not depend on what LLVM chooses to contract: two code
    paths that must agree bit for bit (one pose and a batch of poses) spell their fused
    operations out with this and compile with ``fastmath=False``. Arguments are cast to
    float64.
    """
    f64 = types.float64
    sig = f64(a, b, c)

    def codegen(context, builder, signature, args):
        xs = [context.cast(builder, v, t, f64) for v, t in zip(args, signature.args)]
        d = ir.DoubleType()
        fn = cgutils.get_or_insert_function(builder.module, ir.FunctionType(d, [d, d, d]),
                                            "llvm.fma.f64")
        return builder.call(fn, xs)

    return sig, codegen


_background.PYTHON_EQUIVALENTS[id(fma)] = _background.fma_exact

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
    more than needed rather than less), relative imports resolved.
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
            candidates = [module] + [f"{module}.{n.split()[0]}" for n in names.split(",")
                                     if n.split()]
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


#: The cache locators of serialkin's kernels.
_UserDirLocator, _InTreeLocator = _install_locators()
