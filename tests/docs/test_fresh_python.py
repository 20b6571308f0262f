"""docs/_build/fresh_python.py runs code as a new ``python`` would, from a preloaded server."""

from __future__ import annotations

import os
from pathlib import Path

from fresh_python import PRELOAD, run_python  # docs/_build (on sys.path: tests/conftest.py)


def _run(tmp_path: Path, **kw) -> tuple[int, str, str]:
    out, err = tmp_path / "out.txt", tmp_path / "err.txt"
    kw.setdefault("env", dict(os.environ, FRESH_PYTHON_TEST="42"))
    status = run_python(cwd=tmp_path, stdout=out, stderr=err, timeout=kw.pop("timeout", 120),
                        **kw)
    return status, out.read_text(encoding="utf-8"), err.read_text(encoding="utf-8")


def test_code_runs_as_python_c_in_its_folder_and_environment(tmp_path):
    """``python -c``: argv ['-c'], sys.path[0] '', __main__, the given cwd and environment."""
    code = ("import os, sys\nprint(sys.argv, repr(sys.path[0]), __name__)\n"
            "print(os.getcwd())\nprint(os.environ['FRESH_PYTHON_TEST'])")
    status, out, _ = _run(tmp_path, code=code)
    assert status == 0
    assert out.splitlines() == ["['-c'] '' __main__", str(tmp_path), "42"]


def test_script_runs_as_python_script(tmp_path):
    """``python script``: argv [script], sys.path[0] its folder, __file__ and __main__."""
    script = tmp_path / "s.py"
    script.write_text("import sys\nprint(sys.argv == [__file__], sys.path[0], __name__)\n")
    status, out, _ = _run(tmp_path, script=script)
    assert (status, out.split()) == (0, ["True", str(tmp_path), "__main__"])


def test_exit_status_as_the_interpreter_gives_it(tmp_path):
    """sys.exit(n) gives n; an uncaught exception prints its traceback and gives 1."""
    assert _run(tmp_path, code="import sys; sys.exit(3)")[0] == 3
    assert _run(tmp_path, code="import sys; sys.exit()")[0] == 0
    status, _, err = _run(tmp_path, code="raise ValueError('no good')")
    assert status == 1 and "Traceback" in err and "ValueError: no good" in err
    status, _, err = _run(tmp_path, code="import sys; sys.exit('bye')")
    assert status == 1 and "bye" in err


def test_a_run_past_its_timeout_is_killed(tmp_path):
    """A run still going at its timeout is killed (status -9), not waited for."""
    assert _run(tmp_path, code="import time; time.sleep(60)", timeout=0.5)[0] == -9


def test_the_server_preloaded_but_called_nothing(tmp_path):
    """A run finds the preload imported and no serialkin kernel compiled or loaded yet."""
    code = ("import gc, sys\nfrom numba.core.dispatcher import Dispatcher\n"
            f"print({PRELOAD!r} in sys.modules, 'serialkin' in sys.modules)\n"
            "used = [o.py_func.__module__ for o in gc.get_objects()\n"
            "        if isinstance(o, Dispatcher) and o.signatures\n"
            "        and o.py_func.__module__.startswith('serialkin')]\n"
            "print(len(used))")
    status, out, err = _run(tmp_path, code=code)
    assert status == 0, err
    assert out.split() == ["True", "True", "0"]
