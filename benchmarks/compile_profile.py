"""Where the first call's time goes: numba compile time per kernel, largest first.

Runs a warm-up feature (``serialkin warmup --list``) or a step of ``bench_cold.py`` in a
fresh process with an empty numba cache and records, from numba's ``numba:compile``
events, each kernel's compile time: *self* (its own typing, lowering and LLVM work) and
*inclusive* (with the kernels it compiled as callees). Usage::

    python benchmarks/compile_profile.py ik            # one feature
    python benchmarks/compile_profile.py --all --top 15
    python benchmarks/compile_profile.py ik --markdown  # a table for docs/compile-time.md

Not a timed assertion: a measurement for docs/compile-time.md.
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile
import time

_CHILD = r"""
import collections, json, sys, time
from numba.core import event
stack, rows = [], []
pulled = collections.Counter()

class Listener(event.Listener):
    def on_start(self, ev):
        f = ev.data["dispatcher"].py_func
        stack.append([time.perf_counter(), 0.0, f"{f.__module__}.{f.__qualname__}"])

    def on_end(self, ev):
        t0, child, name = stack.pop()
        dt = time.perf_counter() - t0
        if stack:
            stack[-1][1] += dt
        rows.append((name, dt - child, dt))
        if name.startswith("numba."):  # numba's own code: which kernel of ours asked for it
            ours = next((s[2] for s in reversed(stack) if s[2].startswith("serialkin.")), "")
            pulled[name + " <- " + ours] += dt

event.register("numba:compile", Listener())
t0 = time.perf_counter()
from serialkin.warmup import FEATURES
FEATURES[sys.argv[1]].run()
total = time.perf_counter() - t0
agg = collections.defaultdict(lambda: [0, 0.0, 0.0])
for name, own, incl in rows:
    a = agg[name]
    a[0] += 1
    a[1] += own
    a[2] = max(a[2], incl)
print(json.dumps({"total": total, "kernels": agg, "numba": pulled}))
"""


def profile(feature: str) -> dict:
    """Compile ``feature`` in a fresh process with an empty cache; its per-kernel times."""
    with tempfile.TemporaryDirectory(prefix="serialkin-nbcache-") as cache:
        env = dict(os.environ, NUMBA_CACHE_DIR=cache, SERIALKIN_QUIET_COMPILE="1",
                   SERIALKIN_COMPILE="wait", OPENBLAS_NUM_THREADS="1")
        t0 = time.perf_counter()
        out = subprocess.run([sys.executable, "-c", _CHILD, feature], env=env, check=True,
                             capture_output=True, text=True).stdout
        result = json.loads(out.strip().splitlines()[-1])
        result["wall"] = time.perf_counter() - t0
    return result


def main() -> None:
    from serialkin.warmup import FEATURES

    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("features", nargs="*", help="features (serialkin warmup --list)")
    ap.add_argument("--all", action="store_true", help="every feature, one after the other")
    ap.add_argument("--top", type=int, default=12, help="kernels shown per feature")
    ap.add_argument("--markdown", action="store_true", help="markdown tables")
    args = ap.parse_args()
    names = list(FEATURES) if args.all or not args.features else args.features
    for name in names:
        r = profile(name)
        kernels = sorted(r["kernels"].items(), key=lambda kv: -kv[1][1])
        own = sum(v[1] for _, v in kernels)
        head = (f"{name}: {r['wall']:.1f} s in a fresh process (feature {r['total']:.1f} s), "
                f"{sum(v[0] for _, v in kernels)} compilations, {own:.1f} s compiling")
        if args.markdown:
            print(f"\n**{head}**\n\n| kernel | self [s] | with callees [s] | compiled |\n"
                  "|---|---:|---:|---:|")
            for k, (count, s, incl) in kernels[:args.top]:
                print(f"| `{k.removeprefix('serialkin.')}` | {s:.2f} | {incl:.2f} | {count} |")
        else:
            print(head)
            for k, (count, s, incl) in kernels[:args.top]:
                print(f"  {s:6.2f} s self {incl:7.2f} s incl  x{count}  {k}")
            # numba's own functions (not cached: compiled again in every compiling
            # process), by the kernel that called them: string formatting or sorting
            # here is a slice assignment's error path or np.sort, which a loop avoids
            big = sorted(((t, k) for k, t in r["numba"].items() if t >= 0.3), reverse=True)
            if big:
                print("  numba's own code (with callees: nested rows overlap, do not add "
                      "them), by the serialkin kernel calling it:")
                for t, k in big[:args.top]:
                    print(f"  {t:6.2f} s  {k}")


if __name__ == "__main__":
    main()
