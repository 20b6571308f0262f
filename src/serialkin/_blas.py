"""One BLAS thread for small products: a context manager (threadpoolctl).

numpy's BLAS (OpenBLAS) wakes its thread pool for each matrix product; for the small
products of mesh loading and capsule fitting that costs more than the product on a busy
machine (measured on 2 shared cores: the Panda's visual meshes load in 0.97 s instead of
1.37 s, a capsule's gap evaluation takes 1.9 ms instead of 14 ms). Code that runs many
small products holds BLAS to one thread while it does.
"""

from __future__ import annotations

import contextlib
from collections.abc import Iterator

__all__ = ["single_threaded_blas"]

_CONTROLLER: list = []


@contextlib.contextmanager
def single_threaded_blas() -> Iterator[None]:
    """Limit BLAS to one thread inside the block (the controller is made once)."""
    from threadpoolctl import ThreadpoolController

    if not _CONTROLLER:
        _CONTROLLER.append(ThreadpoolController())
    with _CONTROLLER[0].limit(limits=1, user_api="blas"):
        yield
