"""A hang guard for calls that must return: a generous bound on the wait, not a timing claim."""

from __future__ import annotations

import threading
from collections.abc import Callable

#: Seconds to wait before calling a call hung: far beyond any promised timeout in these
#: tests, so that a loaded machine never trips it; only a call that never returns does.
HANG_GUARD = 300.0


def outcome(fn: Callable[[], object], guard: float = HANG_GUARD) -> BaseException | None:
    """Run ``fn()`` in a daemon thread; the exception it raised (None if none).

    Fails the test when ``fn`` has not returned after ``guard`` seconds (it hangs).
    """
    box: dict[str, BaseException | None] = {"error": None}

    def target() -> None:
        try:
            fn()
        except BaseException as exc:  # noqa: BLE001 - handed to the test
            box["error"] = exc

    worker = threading.Thread(target=target, name="hang-guard", daemon=True)
    worker.start()
    worker.join(guard)
    assert not worker.is_alive(), f"the call did not return within {guard:g} s: it hangs"
    return box["error"]
