"""Run Python code as a new interpreter would, without paying its start-up every time.

The example scripts (docs gallery, tests/test_examples.py) and the chapter report's
Reproduce boxes (tests/chapter/test_reproduce.py) each run in a process of their own, as a
reader runs them. On this project's machines a new ``python`` spends about 0.85 s before
such code does anything of its own: importing NumPy, matplotlib, numba and serialkin
(0.5 s) and setting up numba's compiler at the first kernel call (0.3 s). Run one by
one, 27 of them cost the test suite 23 s of CPU.

:func:`run_python` pays that once per run of the suite: the runs are children of
:mod:`multiprocessing`'s fork server, which imports those modules and sets up numba's
compiler once (``fresh_python_preload``) and then forks a child per run. A child
sets what ``python script.py`` / ``python -c code`` would (working directory,
environment, ``sys.argv``, ``sys.path[0]``, a new ``__main__``), sends file descriptors
1 and 2 to files and runs the code, then exits with the status ``python`` would give
(an uncaught exception prints its traceback and gives 1; ``sys.exit(n)`` gives ``n``).
Nothing of serialkin has been called in the server (setting up numba's compiler
compiles no kernel), so a child meets the library exactly as a new interpreter that has
just imported it does; a module the code imports that the server did not is imported by
the child, as usual.
"""

from __future__ import annotations

import atexit
import multiprocessing
import os
import runpy
import sys
import threading
import traceback
import types
from multiprocessing import forkserver
from pathlib import Path

#: The module the fork server imports before it forks (imports and numba's set-up).
PRELOAD = "fresh_python_preload"

_CONTEXT: list[multiprocessing.context.BaseContext] = []
_LOCK = threading.Lock()


def _context() -> multiprocessing.context.BaseContext:
    """The fork-server context, its server running with :data:`PRELOAD` imported."""
    with _LOCK:
        if not _CONTEXT:
            ctx = multiprocessing.get_context("forkserver")
            ctx.set_forkserver_preload([PRELOAD])
            # The server finds the preload module by PYTHONPATH: Python 3.11's fork server
            # ignores the sys.path it is handed, and skips a module it cannot import.
            here = str(Path(__file__).resolve().parent)
            saved = os.environ.get("PYTHONPATH")
            os.environ["PYTHONPATH"] = os.pathsep.join(p for p in (here, saved) if p)
            try:
                forkserver.ensure_running()
            finally:
                if saved is None:
                    del os.environ["PYTHONPATH"]
                else:
                    os.environ["PYTHONPATH"] = saved
            _CONTEXT.append(ctx)
        return _CONTEXT[0]


def _child(code: str | None, script: str | None, cwd: str, env: dict[str, str],
           stdout: str, stderr: str) -> None:
    """In the forked child: set up as ``python`` would, run, exit with its status."""
    for fd, path in ((1, stdout), (2, stderr)):
        handle = os.open(path, os.O_WRONLY | os.O_CREAT | os.O_TRUNC, 0o644)
        os.dup2(handle, fd)
        os.close(handle)
    sys.stdout = open(1, "w", encoding="utf-8", closefd=False)  # noqa: SIM115
    sys.stderr = open(2, "w", encoding="utf-8", closefd=False)  # noqa: SIM115
    os.environ.clear()
    os.environ.update(env)
    os.chdir(cwd)
    status = 0
    try:
        if script is not None:
            sys.argv = [script]
            sys.path[0] = str(Path(script).resolve().parent)
            runpy.run_path(script, run_name="__main__")
        else:
            sys.argv = ["-c"]
            sys.path[0] = ""
            main = types.ModuleType("__main__")
            sys.modules["__main__"] = main
            exec(compile(code, "<string>", "exec"), main.__dict__)  # noqa: S102
    except SystemExit as exc:
        code_ = exc.code
        status = code_ if isinstance(code_, int) else (0 if code_ is None else 1)
        if not isinstance(code_, int | None):
            print(code_, file=sys.stderr)
    except BaseException:  # noqa: BLE001 - as the interpreter: traceback, status 1
        traceback.print_exc()
        status = 1
    atexit._run_exitfuncs()  # what the interpreter runs at exit (the fork skips it)
    sys.stdout.flush()
    sys.stderr.flush()
    sys.exit(status)


def run_python(*, code: str | None = None, script: str | os.PathLike[str] | None = None,
               cwd: str | os.PathLike[str], env: dict[str, str],
               stdout: str | os.PathLike[str], stderr: str | os.PathLike[str],
               timeout: float) -> int:
    """Run ``code`` (as ``python -c``) or ``script`` (as ``python script``); its status.

    Its standard output and error go to the files ``stdout`` and ``stderr``; ``env`` is
    its whole environment. A run still going after ``timeout`` seconds is killed and
    gives -9. Safe to call from several threads at once (each run is its own child).
    """
    if (code is None) == (script is None):
        raise ValueError("run_python: pass exactly one of code= and script=")
    ctx = _context()
    proc = ctx.Process(target=_child, args=(code, None if script is None else str(script),
                                            str(cwd), dict(env), str(stdout), str(stderr)))
    proc.start()
    proc.join(timeout)
    if proc.exitcode is None:
        proc.kill()
        proc.join()
    return proc.exitcode
