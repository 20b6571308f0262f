"""LLVM optimisation levels per kernel: ``-O3`` for the hot kernels, ``-O2`` for the rest.

serialkin/_jit.py sets numba's ``config.OPT`` while a kernel compiles: the kernels the
warm-speed goals name (FK, Jacobians, the default IK method's loop) at ``-O3``, all
others at ``-O2``, which compiles about a third faster (docs/compile-time.md).
"""

from __future__ import annotations

import numpy as np
import pytest

import serialkin as sk
from serialkin import _jit
from serialkin.ik import METHODS
from serialkin.kinematics import kernels as K


def _plain():
    return 1


def _hot():
    return 2


_jit._mark_hot(_hot)


@pytest.fixture
def config(monkeypatch):
    """Numba's config, with ``NUMBA_OPT`` unset (it turns the levels off)."""
    from numba.core import config

    monkeypatch.delenv("NUMBA_OPT", raising=False)
    return config


def test_a_kernel_compiled_from_python_gets_its_own_level(config):
    """A plain kernel compiles at -O2, a hot one at -O3; numba's level is restored after."""
    before = int(config.OPT)
    seen = []
    _jit._at_opt_level(_plain, lambda sig: seen.append(int(config.OPT)), ())
    _jit._at_opt_level(_hot, lambda sig: seen.append(int(config.OPT)), ())
    assert seen == [_jit.OPT, _jit.HOT_OPT] == [2, 3]
    assert int(config.OPT) == before


def test_callees_take_their_callers_level_but_hot_ones_stay_o3(config):
    """Nested compiles inherit the outer level, except a hot kernel, which is always -O3."""
    seen = {}

    def outer(sig):
        seen["outer"] = int(config.OPT)
        _jit._at_opt_level(_plain, lambda s: seen.setdefault("plain", int(config.OPT)), ())
        _jit._at_opt_level(_hot, lambda s: seen.setdefault("hot", int(config.OPT)), ())
        seen["after"] = int(config.OPT)

    _jit._at_opt_level(_plain, outer, ())
    assert seen == {"outer": 2, "plain": 2, "hot": 3, "after": 2}
    seen.clear()
    _jit._at_opt_level(_hot, outer, ())
    assert seen == {"outer": 3, "plain": 3, "hot": 3, "after": 3}


def test_the_level_is_reset_when_a_compile_fails(config):
    """An exception in the compile leaves numba's level and serialkin's state as before."""
    before = int(config.OPT)

    def fail(sig):
        raise RuntimeError("typing failed")

    with pytest.raises(RuntimeError, match="typing failed"):
        _jit._at_opt_level(_hot, fail, ())
    assert int(config.OPT) == before
    seen = []
    _jit._at_opt_level(_plain, lambda sig: seen.append(int(config.OPT)), ())
    assert seen == [2]


def test_numba_opt_in_the_environment_wins(config, monkeypatch):
    """With NUMBA_OPT set, serialkin leaves numba's level alone."""
    monkeypatch.setenv("NUMBA_OPT", "1")
    before = int(config.OPT)
    seen = []
    _jit._at_opt_level(_hot, lambda sig: seen.append(int(config.OPT)), ())
    assert seen == [before]


def test_the_kernels_of_the_speed_goals_are_hot():
    """FK, Jacobian and the default IK loop's entries are -O3; the other methods -O2."""
    for kernel in (K.fk_one, K.jacobian_one):
        assert _jit.opt_level(kernel.py_func) == 3, kernel
    lm = METHODS["lm"].kernel
    for entry in (lm.solve_fast, lm.solve_chunk):
        assert _jit.opt_level(entry.py_func) == 3
    other = METHODS["dls"].kernel
    assert _jit.opt_level(other.solve_fast.py_func) == 2


def test_a_hot_kernel_compiled_at_its_level_gives_the_same_answers():
    """A user kernel marked hot compiles and runs (the option never reaches numba)."""
    @_jit.njit(hot=True)
    def twice(x):
        return 2.0 * x

    @_jit.njit
    def plus_twice(x):
        return x + twice(x)

    assert plus_twice(np.float64(1.5)) == 4.5
    r = sk.models.get("ur5")
    q = r.random_q(1, seed=0)[0]
    np.testing.assert_allclose(r.fk(q), r.fk(q[None])[0], atol=1e-15)
