"""First calls while kernels compile (serialkin._background; issue 27).

A kernel that is not compiled yet runs as its own Python source while a worker thread
compiles it. Tested here: the Python twin of the fused multiply-add is exact, every
feature's kernels give the compiled answers as Python, the background mode answers
before the compile and uses the compiled kernel after it, a process that ends early
finishes the compile for the next one, large calls and compile errors are handled.
The rest of the suite runs with ``SERIALKIN_COMPILE=wait`` (tests/conftest.py).
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
import textwrap
from fractions import Fraction

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

import serialkin as sk
from serialkin import _background
from serialkin._jit import njit
from serialkin.kinematics import kernels as K

_FINITE = st.floats(min_value=-1e30, max_value=1e30, allow_nan=False, allow_infinity=False)


@given(_FINITE, _FINITE, _FINITE)
def test_fma_exact_is_the_correctly_rounded_fused_multiply_add(a, b, c):
    # reference: exact rational arithmetic, rounded once by float(Fraction)
    exact = Fraction(a) * Fraction(b) + Fraction(c)
    assert _background.fma_exact(a, b, c) == float(exact)


def test_fma_exact_special_values():
    assert np.isnan(_background.fma_exact(np.inf, 0.0, 1.0))
    assert _background.fma_exact(np.inf, 2.0, 1.0) == np.inf
    assert _background.fma_exact(1e300, 1e10, 0.0) == np.inf
    # a case where two roundings differ from one: (1 + 2^-30)^2 - (1 + 2^-29)
    x = 1.0 + 2.0**-30
    assert _background.fma_exact(x, x, -(1.0 + 2.0**-29)) == 2.0**-60
    assert x * x - (1.0 + 2.0**-29) == 0.0


@pytest.mark.parametrize("name", ["ur5", "panda", "puma560"])
def test_kernels_as_python_give_the_compiled_results(name):
    r = sk.models.get(name)
    q = r.random_q(seed=3)
    T, J = np.empty((4, 4)), np.empty((6, r.n))
    H = np.empty((6, r.n, r.n))
    assert _background.quietly(K.fk_one)(q, r._P, T) == 0
    assert _background.quietly(K.jacobian_one)(q, r._P, J) == 0
    _background.quietly(K.hessian_one)(q, r._P, False, H)
    np.testing.assert_allclose(T, r.fk(q), rtol=0, atol=1e-14)
    np.testing.assert_allclose(J, r.jacobian(q), rtol=0, atol=1e-13)
    np.testing.assert_allclose(H, r.hessian(q), rtol=0, atol=1e-12)


def test_interpreted_calls_the_python_of_its_callees_and_compiles_nothing():
    @njit
    def inner(x):
        return x * 2.0

    @njit
    def outer(x, k):
        return inner(x) + k

    assert _background.quietly(outer)(1.5, 2) == 5.0
    assert not inner.overloads and not outer.overloads
    # a Python int reaches the kernel as numpy.int64, as numba types it
    assert type(_background.quietly(lambda_kernel)(3)) is np.int64


@njit
def lambda_kernel(k):
    return k + 1


def _run(script: str, env: dict, timeout: float = 600) -> subprocess.CompletedProcess:
    full = {k: v for k, v in os.environ.items() if k not in ("SERIALKIN_COMPILE",)}
    full.update(env)
    full.pop("SERIALKIN_QUIET_COMPILE", None)
    return subprocess.run([sys.executable, "-c", textwrap.dedent(script)], env=full,
                          capture_output=True, text=True, timeout=timeout, check=False)


_FEATURES = """
    import json, numpy as np, serialkin as sk
    out = {}
    for name in ("ur5", "panda"):
        r = sk.models.get(name)
        q = r.random_q(seed=5)
        out[name + " fk"] = r.fk(q).tolist()
        out[name + " jacobian"] = r.jacobian(q).tolist()
        T = r.fk(r.random_q(seed=6))
        res = r.ik(T, seed=1)
        out[name + " ik"] = [bool(res.success), r.fk(res.q).tolist()]
        out[name + " ik batch"] = r.ik(r.fk(r.random_q(3, seed=7)), seed=1).success.tolist()
    for name in ("ur5", "puma560"):
        r = sk.models.get(name)
        out[name + " ik_all"] = [s.tolist() for s in r.ik_all(r.fk(r.random_q(seed=8)))]
    r = sk.models.get("panda")
    res = r.ik(r.fk(r.random_q(seed=9)), self_collision=True, seed=2)
    out["panda collision ik"] = [bool(res.success), r.fk(res.q).tolist()]
    print(json.dumps(out))
"""


def _features_compiled() -> dict:
    ns: dict = {}
    lines = textwrap.dedent(_FEATURES).replace("print(json.dumps(out))", "")
    exec(compile(lines, "<features>", "exec"), ns)  # noqa: S102 - the test's own snippet
    return ns["out"]


def _same_solutions(a, b) -> bool:
    if len(a) != len(b):
        return False
    a, b = (np.array(sorted(map(tuple, np.round(x, 9)))) for x in (a, b))
    return np.allclose(a, b, atol=1e-8)


def test_every_feature_as_python_gives_the_compiled_answers(tmp_path):
    p = _run(_FEATURES, {"SERIALKIN_COMPILE": "python", "NUMBA_CACHE_DIR": str(tmp_path)})
    assert p.returncode == 0, p.stderr[-2000:]
    python = json.loads(p.stdout.strip().splitlines()[-1])
    compiled = _features_compiled()
    assert python.keys() == compiled.keys()
    assert not list(tmp_path.rglob("*.nbi")), "python mode compiled something"
    for key, value in compiled.items():
        got = python[key]
        if key.endswith(("fk", "jacobian")):
            np.testing.assert_allclose(got, value, rtol=0, atol=1e-12, err_msg=key)
        elif key.endswith("ik batch"):
            assert got == value, key
        elif key.endswith("ik_all"):
            assert _same_solutions(got, value), key
        else:  # one solve: both succeed and reach the same pose
            assert got[0] and value[0], key
            np.testing.assert_allclose(got[1], value[1], rtol=0, atol=1e-8, err_msg=key)


def test_background_mode_answers_first_then_runs_compiled(tmp_path):
    script = """
        import json, time, numpy as np, serialkin as sk
        from serialkin import _background
        from serialkin.model import robot as robot_module
        r = sk.models.get("ur5")
        q = np.array([0.1, 0.2, 0.3, 0.4, 0.5, 0.6])
        T = r.fk(q)
        first_final = robot_module._FK1 is not None
        for job in _background._WORKER.pending():
            job.result()
        T2 = r.fk(q)
        print(json.dumps({"first_final": first_final,
                          "then_final": robot_module._FK1 is not None,
                          "diff": float(np.abs(T - T2).max())}))
    """
    p = _run(script, {"NUMBA_CACHE_DIR": str(tmp_path)})
    assert p.returncode == 0, p.stderr[-2000:]
    out = json.loads(p.stdout.strip().splitlines()[-1])
    assert out == {"first_final": False, "then_final": True, "diff": out["diff"]}
    assert out["diff"] < 1e-14
    assert "compiling the kinematics kernels in the background" in p.stderr


def test_a_process_that_ends_early_finishes_the_compile_for_the_next(tmp_path):
    script = """
        import numpy as np, serialkin as sk
        sk.models.get("ur5").jacobian(np.zeros(6))
    """
    p = _run(script, {"NUMBA_CACHE_DIR": str(tmp_path)})
    assert p.returncode == 0, p.stderr[-2000:]
    assert "finishing the kernels' compile before exit" in p.stderr
    check = """
        import numpy as np, serialkin as sk
        from serialkin.model import robot as robot_module
        sk.models.get("ur5").jacobian(np.zeros(6))
        assert robot_module._JAC1 is not None, "not loaded from the cache"
    """
    p = _run(check, {"NUMBA_CACHE_DIR": str(tmp_path)})
    assert p.returncode == 0, p.stderr[-2000:]
    assert "compiling" not in p.stderr and "finishing" not in p.stderr


def test_large_calls_wait_for_the_compiled_kernel(monkeypatch):
    @njit
    def total(a):
        s = 0.0
        for x in a:
            s += x
        return s

    monkeypatch.setenv("SERIALKIN_COMPILE", "background")
    big = np.ones(_background.BIG_ARGUMENTS + 1)
    fn, final = _background.entry(total, (total.typeof_pyval(big),), (big,))
    assert final and fn(big) == big.size
    small = np.ones(6)
    sig = (total.typeof_pyval(small),)
    fn, final = _background.entry(total, sig, (small,))
    if not final:  # the Python function while it compiles
        assert fn(small) == 6.0
    _background._WORKER.submit(total, sig).result()
    assert _background.entry(total, sig, (small,))[1]


def test_a_compile_error_reaches_the_caller(monkeypatch):
    @njit
    def bad(x):
        return float(Fraction(x) * 2)  # valid Python, not compilable (a Python class)

    monkeypatch.setenv("SERIALKIN_COMPILE", "background")
    assert bad(1.5) == 3.0  # answered as Python while the worker fails to compile
    for job in _background._WORKER.pending():
        job.exception()
    with pytest.raises(Exception, match="(?i)typing|Fraction"):
        bad(1.5)


def test_mode_reads_the_environment(monkeypatch):
    for value, expected in [("wait", "wait"), ("python", "python"), ("", "background"),
                            ("bogus", "background"), (" WAIT ", "wait")]:
        monkeypatch.setenv("SERIALKIN_COMPILE", value)
        assert _background.mode() == expected


def test_an_uncompiled_entry_point_is_never_kept(tmp_path):
    """The fast paths keep an entry point only once it is compiled (else: Python forever)."""
    script = """
        import numpy as np, serialkin as sk
        from serialkin.ik import analytic, solver
        from serialkin.model import robot as robot_module
        r = sk.models.get("ur5")
        T = r.fk(np.array([0.1, 0.2, 0.3, 0.4, 0.5, 0.6]))
        for _ in range(2):
            assert len(r.ik_all(T)) == 8 and r.ik(T, seed=0).success
        assert analytic._FAST.get(r) is None and solver._FAST_ENTRIES.get(r) is None
        assert robot_module._FK1 is None
        print("ok")
    """
    p = _run(script, {"SERIALKIN_COMPILE": "python", "NUMBA_CACHE_DIR": str(tmp_path)})
    assert p.returncode == 0 and p.stdout.strip().endswith("ok"), p.stderr[-2000:]
