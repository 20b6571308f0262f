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

Exceptions, compiled by :func:`njit_exact` (no contraction): the path trackers of
:mod:`serialkin.tracking` and the resolvers of :mod:`serialkin.redundancy`. They iterate
step after step along a path, so a last-bit difference at one step is carried on to all
later ones, and the chapter's hardest scenario (Figure 12: twenty links between four
obstacles, 5 mm tolerance) turns a sharp corner at 4.1 mm: contracted, that corner's
error came out at 6.5 mm. They keep the rounding their figures were made with.
"""

from __future__ import annotations

import numba
from llvmlite import ir
from numba.core import cgutils, types
from numba.extending import intrinsic

#: The fast-math flags of every serialkin kernel (see the module docstring).
FASTMATH = frozenset({"contract"})


def njit(*args, **options):
    """``numba.njit`` with ``fastmath=FASTMATH`` unless the caller sets ``fastmath``.

    Used exactly like ``numba.njit``: ``@njit``, ``@njit(cache=True, ...)`` or
    ``njit(signature, ...)``.
    """
    options.setdefault("fastmath", set(FASTMATH))
    return numba.njit(*args, **options)


def njit_exact(*args, **options):
    """``numba.njit`` without fast-math flags: every product and sum rounded on its own."""
    options["fastmath"] = False
    return numba.njit(*args, **options)


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
