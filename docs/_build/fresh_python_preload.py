"""Imported once by fresh_python's fork server, before it forks a child per run.

What a new interpreter would otherwise spend its first 0.85 s on: the imports of the
examples and Reproduce boxes, and numba's compiler set-up (its typing and target
contexts, built at the first kernel call). No serialkin function is called: no kernel
is compiled or loaded, no cache of the library is filled.
"""

import os

os.environ.setdefault("MPLBACKEND", "Agg")  # as the runs set it (read at import)

import matplotlib.pyplot  # noqa: E402,F401
import numpy  # noqa: E402,F401
from numba.core.registry import cpu_target  # noqa: E402

import serialkin  # noqa: E402,F401

cpu_target.typing_context.refresh()
cpu_target.target_context.refresh()
