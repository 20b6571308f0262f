"""Clusters and batches within their budgets: local workers capped, a silent scheduler times out."""

from __future__ import annotations

import socket
import threading
import time

import numpy as np
import pytest

from serialkin import models
from serialkin.errors import BudgetError, InputError


def test_local_cluster_workers_are_capped():
    """local:9999 is refused before any process starts, naming the cap and the cores."""
    pytest.importorskip("dask.distributed")
    from serialkin.reach import local_cluster

    with pytest.raises(InputError, match=r"workers=9999.*at most \d+ worker processes"):
        local_cluster(9999)


def test_a_scheduler_that_never_answers_times_out_as_promised():
    """A port that accepts the connection and stays silent gives InputError within the timeout."""
    pytest.importorskip("dask.distributed")
    from serialkin.reach import connect

    server = socket.socket()
    server.bind(("127.0.0.1", 0))
    server.listen(8)
    held = []
    stop = threading.Event()

    def accept():
        server.settimeout(0.2)
        while not stop.is_set():
            try:
                held.append(server.accept()[0])  # accept and never answer
            except OSError:
                continue

    threading.Thread(target=accept, daemon=True).start()
    t0 = time.monotonic()
    try:
        with pytest.raises(InputError, match="did not answer|answered but not"):
            connect(f"tcp://127.0.0.1:{server.getsockname()[1]}", timeout=1.0)
        assert time.monotonic() - t0 < 10.0  # the promised bound (1 s + slack), not a timing target
    finally:
        stop.set()
        for c in held:
            c.close()
        server.close()


def test_an_ik_batch_beyond_the_memory_budget_is_refused(monkeypatch):
    """10⁸ targets (a broadcast view, no memory yet) raise BudgetError before any allocation."""
    monkeypatch.setenv("SERIALKIN_MEMORY_BUDGET", "1G")
    ur5 = models.get("ur5")
    T = np.broadcast_to(ur5.fk(np.zeros(6)), (10**8, 4, 4))
    with pytest.raises(BudgetError, match="target"):
        ur5.ik(T)
