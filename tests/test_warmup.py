"""Compiling ahead of time (serialkin.warmup), the first-compile notice and the cache stamps."""

from __future__ import annotations

import os
import subprocess
import sys
import textwrap

import pytest
from click.testing import CliRunner

from serialkin import _jit
from serialkin.cli.main import cli
from serialkin.errors import InputError
from serialkin.warmup import FEATURES, feature_of_module, warmup


def test_feature_of_module_takes_the_longest_prefix():
    """Each kernel module belongs to the feature whose prefix matches it most closely."""
    assert feature_of_module("serialkin.ik.analytic.dispatch").name == "ik-all"
    assert feature_of_module("serialkin.ik.analytic.arm_angle").name == "arm-angle"
    assert feature_of_module("serialkin.ik._kernels").name == "ik"
    assert feature_of_module("serialkin.kinematics.kernels").name == "kinematics"
    assert feature_of_module("serialkin.kinematics.dls").name == "ik"
    assert feature_of_module("serialkin.collision.queries").name == "collision"
    assert feature_of_module("serialkin.iksomething") is None
    assert feature_of_module("numpy.linalg") is None


def test_unknown_feature_is_refused_with_the_valid_names():
    """An unknown feature name raises InputError naming it and listing the features."""
    with pytest.raises(InputError, match=r"unknown feature 'kinematic'.*'kinematics'"):
        warmup(["kinematic"])
    with pytest.raises(InputError, match="at least one feature"):
        warmup([])


def test_cli_lists_every_feature():
    """`serialkin warmup --list` names every feature with its expected compile time."""
    out = CliRunner().invoke(cli, ["warmup", "--list"])
    assert out.exit_code == 0
    for name, f in FEATURES.items():
        assert name in out.output and f.summary in out.output
    bad = CliRunner().invoke(cli, ["warmup", "--all", "ik"])
    assert bad.exit_code == 2 and "not both" in bad.output


def test_warmup_runs_a_feature_in_a_process_of_its_own():
    """warmup() compiles (or loads) a feature in a fresh process and reports its time."""
    times = warmup(["kinematics"], jobs=1, progress=False)
    assert list(times) == ["kinematics"] and times["kinematics"] > 0


_NOTICE_SCRIPT = textwrap.dedent("""
    from serialkin.model.limits import turn_mod, wrap_into
    turn_mod(7.0)      # two kernels of the same feature: one notice
    wrap_into(7.0, -3.2, 3.2)
""")


def _run(env: dict[str, str]) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-c", _NOTICE_SCRIPT], env=env, capture_output=True,
                          text=True, timeout=600, check=True)


def test_a_first_compile_says_so_once_and_a_cached_kernel_says_nothing(tmp_path):
    """Compiling prints one line per feature and process; a cache hit or quiet prints none."""
    env = dict(os.environ, NUMBA_CACHE_DIR=str(tmp_path))
    env.pop("SERIALKIN_QUIET_COMPILE", None)
    first = _run(env).stderr
    assert first.count("serialkin: compiling the ik kernels once") == 1, first
    assert "serialkin warmup" in first
    assert "compiling" not in _run(env).stderr  # loaded from the cache now
    quiet = _run(dict(env, NUMBA_CACHE_DIR=str(tmp_path / "other"),
                      SERIALKIN_QUIET_COMPILE="1")).stderr
    assert "compiling" not in quiet


def test_kernels_are_cached_by_serialkins_locator():
    """Serialkin's kernels use the dependency-stamped locators, other code numba's own."""
    from serialkin.kinematics import kernels as K

    locator = K.fk_one._cache._impl.locator
    assert isinstance(locator, (_jit._InTreeLocator, _jit._UserDirLocator))
    assert locator.get_source_stamp() == _jit.dependency_stamp(K.__file__)


def test_imports_are_found_statically():
    """The import scan finds absolute, relative and parenthesised serialkin imports."""
    pkg = _jit._PACKAGE_DIR

    def deps(rel):
        return {os.path.relpath(p, pkg) for p in _jit._imports(os.path.join(pkg, rel))}

    assert "_jit.py" in deps("kinematics/kernels.py")  # from .._jit import ...
    ik = deps("ik/_kernels.py")
    assert {"kinematics/kernels.py", "kinematics/dls.py", "spatial/kernels.py",
            "collision/queries.py", "model/limits.py", "_jit.py"} <= ik
    assert "ik/analytic/ur.py" in deps("ik/analytic/dispatch.py")


def test_a_submodule_import_does_not_stamp_the_package():
    """``from serialkin import _background`` depends on _background, not serialkin/__init__.

    The package's __init__ imports nearly everything; counting it would make every
    kernel's cache stale after any edit anywhere. A kernel's whole closure stays inside
    what it imports: the IK kernels' stamps do not include the CLI or the report.
    """
    pkg = _jit._PACKAGE_DIR

    def deps(rel):
        return {os.path.relpath(p, pkg) for p in _jit._imports(os.path.join(pkg, rel))}

    assert "_background.py" in deps("_jit.py") and "__init__.py" not in deps("_jit.py")
    closure = {os.path.relpath(p, pkg) for p in _closure(os.path.join(pkg, "ik/_kernels.py"))}
    assert not any(p.startswith(("cli/", "chapter/", "viz/", "reach/")) for p in closure)
    assert "ik/solver.py" not in _closure(os.path.join(pkg, "kinematics/kernels.py"))


def test_the_feature_table_is_outside_every_kernel_stamp():
    """Editing the warm-up features' timings or summaries recompiles no kernel.

    Every kernel module imports serialkin._jit, which imports _background (the notice
    reads the table, through importlib); the table's own module is in no kernel's import
    closure.
    """
    pkg = _jit._PACKAGE_DIR
    table = os.path.join(pkg, "_features.py")
    for rel in ("_jit.py", "_background.py", "kinematics/kernels.py", "ik/_kernels.py",
                "ik/analytic/dispatch.py"):
        assert table not in _closure(os.path.join(pkg, rel)), rel
    assert os.path.join(pkg, "_background.py") in _closure(os.path.join(pkg, "_jit.py"))


def _closure(path):
    """Every file in the import closure of ``path`` (as the stamp walks it)."""
    seen, todo = {path}, [path]
    while todo:
        for dep in _jit._imports_of(todo.pop()):
            if dep not in seen:
                seen.add(dep)
                todo.append(dep)
    return seen


def test_an_edit_changes_the_stamps_of_its_importers_only(tmp_path, monkeypatch):
    """Editing a module changes its own stamp and its importers', never the others'."""
    pkg = tmp_path / "serialkin"
    (pkg / "sub").mkdir(parents=True)
    (pkg / "__init__.py").write_text("")
    (pkg / "sub" / "__init__.py").write_text("")
    (pkg / "base.py").write_text("X = 1\n")
    (pkg / "sub" / "mid.py").write_text("from ..base import X\n")
    (pkg / "top.py").write_text("from serialkin.sub import mid\n")
    (pkg / "other.py").write_text("Y = 2\n")
    monkeypatch.setattr(_jit, "_PACKAGE_DIR", str(pkg))

    def stamps():
        for memo in ("_STAMPS", "_IMPORTED", "_DIGESTS"):  # a new process each time
            monkeypatch.setattr(_jit, memo, {})
        return {n: _jit.dependency_stamp(str(pkg / n))
                for n in ("base.py", "sub/mid.py", "top.py", "other.py")}

    before = stamps()
    (pkg / "base.py").write_text("X = 2\n")
    after = stamps()
    assert {n for n in before if before[n] != after[n]} == {"base.py", "sub/mid.py", "top.py"}
    (pkg / "top.py").write_text("from serialkin.sub import mid  # edited\n")
    again = stamps()
    assert {n for n in after if after[n] != again[n]} == {"top.py"}
