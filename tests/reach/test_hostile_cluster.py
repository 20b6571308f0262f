"""Clusters and batches within their budgets: local workers capped, a silent scheduler times out."""

from __future__ import annotations

import re
import socket
import threading

import numpy as np
import pytest

from serialkin import models
from serialkin.errors import BudgetError, InputError
from tests.reach._guard import outcome


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
    try:
        # a hang guard, not a timing claim: connect must return, with the error that
        # names the timeout it was given
        err = outcome(lambda: connect(f"tcp://127.0.0.1:{server.getsockname()[1]}",
                                      timeout=1.0))
        assert isinstance(err, InputError), repr(err)
        assert re.search("did not answer within 1 s|answered but not", str(err)), str(err)
    finally:
        stop.set()
        for c in held:
            c.close()
        server.close()


def test_a_connection_that_never_completes_is_abandoned_at_the_timeout(monkeypatch):
    """A Dask client that never returns is given up after the timeout: InputError, no hang.

    The stand-in client blocks until the test ends, so only connect's own bound can end
    the call; its message names the timeout and the abandoned attempt.
    """
    from serialkin.reach import execute

    release = threading.Event()
    seen = {}

    class _NeverAnswers:
        def Client(self, address, timeout):  # noqa: N802 - dask.distributed's name
            seen["timeout"] = timeout
            release.wait()

    monkeypatch.setattr(execute, "_distributed", _NeverAnswers)
    try:
        err = outcome(lambda: execute.connect("tcp://192.0.2.1:8786", timeout=0.2))
    finally:
        release.set()
    assert isinstance(err, InputError), repr(err)
    assert "did not answer within 0.2 s" in str(err) and "no complete answer" in str(err)
    assert seen["timeout"] == 0.2  # dask's own timeout is the same one


def test_an_ik_batch_beyond_the_memory_budget_is_refused(monkeypatch):
    """10⁸ targets (a broadcast view, no memory yet) raise BudgetError before any allocation."""
    monkeypatch.setenv("SERIALKIN_MEMORY_BUDGET", "1G")
    ur5 = models.get("ur5")
    T = np.broadcast_to(ur5.fk(np.zeros(6)), (10**8, 4, 4))
    with pytest.raises(BudgetError, match="target"):
        ur5.ik(T)
