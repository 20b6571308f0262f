"""The layer contract (issue 28): a module imports only from its layer and the layers below.

The layers are listed in pyproject.toml (``[tool.importlinter]``) and drawn in
docs/architecture.md; import-linter checks every import, deferred ones inside functions
included. Every package and module of serialkin must be placed in a layer, so that a new
one cannot sit outside the contract.

Within a layer, modules may import each other, so the contract alone allows a circle of
two modules of one package. :func:`test_no_import_cycles` forbids any: over every module
of serialkin, with every import (at the top, inside functions, and
``importlib.import_module`` of a literal name or of a literal package prefix), no module
may reach itself again. Imports under ``if TYPE_CHECKING:`` are annotations only and do
not count, as for the contract.
"""

from __future__ import annotations

import ast
import os
import subprocess
import sys
import tomllib
from collections import deque
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
SRC = ROOT / "src"


def _layers() -> list[str]:
    config = tomllib.loads((ROOT / "pyproject.toml").read_text())["tool"]["importlinter"]
    (contract,) = config["contracts"]
    return [name.strip() for layer in contract["layers"] for name in layer.split("|")]


def test_every_package_and_module_has_a_layer():
    here = SRC / "serialkin"
    found = {f"serialkin.{p.stem}" for p in here.iterdir()
             if (p.suffix == ".py" and p.stem != "__init__")
             or (p.is_dir() and (p / "__init__.py").exists())}
    assert found - set(_layers()) == set(), "place these in a layer of pyproject.toml"
    assert set(_layers()) - found == set(), "layers name modules that do not exist"


def test_the_layer_contract_is_kept():
    linter = Path(sys.executable).parent / "lint-imports"
    if not linter.exists():
        message = "import-linter is not installed (the dev extra installs it)"
        if os.environ.get("CI"):  # in CI the contract must be checked, not skipped
            pytest.fail(message)
        pytest.skip(message)
    p = subprocess.run([str(linter), str(ROOT / "pyproject.toml")], cwd=ROOT,
                       capture_output=True, text=True, check=False)
    assert p.returncode == 0, p.stdout[-4000:] + p.stderr[-2000:]
    assert "1 kept, 0 broken" in p.stdout


# ---------------------------------------------------------------- no import cycles
def _modules() -> dict[str, Path]:
    """Every module of serialkin, by dotted name (a package by its ``__init__.py``)."""
    out = {}
    for path in (SRC / "serialkin").rglob("*.py"):
        if "__pycache__" in path.parts:
            continue
        parts = list(path.relative_to(SRC).with_suffix("").parts)
        if parts[-1] == "__init__":
            parts.pop()
        out[".".join(parts)] = path
    return out


def _is_type_checking(test: ast.expr) -> bool:
    return (isinstance(test, ast.Name) and test.id == "TYPE_CHECKING") or (
        isinstance(test, ast.Attribute) and test.attr == "TYPE_CHECKING")


class _Imports(ast.NodeVisitor):
    """The (imported name, line) pairs of one module: every import statement anywhere."""

    def __init__(self, module: str, is_package: bool, modules: set[str]) -> None:
        self.package = module.split(".") if is_package else module.split(".")[:-1]
        self.modules = modules
        self.found: list[tuple[str, int]] = []

    def visit_If(self, node: ast.If) -> None:
        if _is_type_checking(node.test):  # annotations only: the else branch still runs
            for child in node.orelse:
                self.visit(child)
            return
        self.generic_visit(node)

    def visit_Import(self, node: ast.Import) -> None:
        self.found += [(alias.name, node.lineno) for alias in node.names]

    def visit_ImportFrom(self, node: ast.ImportFrom) -> None:
        if node.level:
            base = self.package[:len(self.package) - (node.level - 1)]
            source = ".".join(base + ([node.module] if node.module else []))
        else:
            source = node.module or ""
        for alias in node.names:  # `from a import b`: the module a.b if it is one, else a
            sub = f"{source}.{alias.name}"
            self.found.append((sub if sub in self.modules else source, node.lineno))

    def visit_Call(self, node: ast.Call) -> None:
        f = node.func
        name = f.attr if isinstance(f, ast.Attribute) else getattr(f, "id", None)
        if name in ("import_module", "__import__") and node.args:
            arg = node.args[0]
            if isinstance(arg, ast.Constant) and isinstance(arg.value, str):
                self.found.append((arg.value, node.lineno))
            elif (isinstance(arg, ast.JoinedStr) and arg.values
                  and isinstance(arg.values[0], ast.Constant)
                  and str(arg.values[0].value).endswith(".")):
                # f"pkg.{name}": any module directly below pkg may be the one imported
                prefix = str(arg.values[0].value)
                self.found += [(m, node.lineno) for m in sorted(self.modules)
                               if m.startswith(prefix) and "." not in m[len(prefix):]]
        self.generic_visit(node)


def import_graph() -> dict[str, dict[str, int]]:
    """``{module: {imported serialkin module: first line}}`` over all of serialkin."""
    files = _modules()
    names = set(files)
    graph: dict[str, dict[str, int]] = {}
    for module, path in files.items():
        visitor = _Imports(module, path.name == "__init__.py", names)
        visitor.visit(ast.parse(path.read_text(encoding="utf-8"), str(path)))
        edges: dict[str, int] = {}
        for target, line in visitor.found:
            while target and target not in names:  # `import a.b.X` of a name X in a.b
                target = target.rpartition(".")[0]
            if target and target != module:
                edges.setdefault(target, line)
        graph[module] = edges
    return graph


def strongly_connected(graph: dict[str, dict[str, int]]) -> list[list[str]]:
    """The strongly connected components of more than one module (Tarjan, iterative)."""
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    on_stack: set[str] = set()
    stack: list[str] = []
    found = []
    for root in sorted(graph):
        if root in index:
            continue
        work = [(root, iter(sorted(graph[root])))]
        index[root] = low[root] = len(index)
        stack.append(root)
        on_stack.add(root)
        while work:
            v, children = work[-1]
            child = next(children, None)
            if child is not None:
                if child not in index:
                    index[child] = low[child] = len(index)
                    stack.append(child)
                    on_stack.add(child)
                    work.append((child, iter(sorted(graph[child]))))
                elif child in on_stack:
                    low[v] = min(low[v], index[child])
                continue
            work.pop()
            if work:
                low[work[-1][0]] = min(low[work[-1][0]], low[v])
            if low[v] == index[v]:
                component = []
                while True:
                    w = stack.pop()
                    on_stack.discard(w)
                    component.append(w)
                    if w == v:
                        break
                if len(component) > 1:
                    found.append(sorted(component))
    return found


def _a_cycle(graph: dict[str, dict[str, int]], component: list[str]) -> str:
    """One shortest cycle through the component's first module, with each import's line."""
    inside = set(component)
    start = component[0]
    came_from: dict[str, str] = {}
    todo = deque([start])
    while todo:
        v = todo.popleft()
        for w in sorted(graph[v]):
            if w not in inside or w in came_from:
                continue
            came_from[w] = v
            if w == start:
                todo.clear()
                break
            todo.append(w)
    path = [start]
    while path[-1] != start or len(path) == 1:
        path.append(came_from[path[-1]])
    path.reverse()
    return " -> ".join(f"{a} (line {graph[a][b]})" for a, b in zip(path, path[1:])) + \
        f" -> {start}"


def test_the_cycle_finder_finds_deferred_and_dynamic_imports(tmp_path, monkeypatch):
    """The scan sees imports inside functions and import_module, and skips TYPE_CHECKING."""
    pkg = tmp_path / "serialkin"
    (pkg / "sub").mkdir(parents=True)
    (pkg / "__init__.py").write_text("")
    (pkg / "sub" / "__init__.py").write_text("")
    (pkg / "a.py").write_text("from serialkin import b\n")
    (pkg / "b.py").write_text("def f():\n    from .a import x\n")  # deferred: a <-> b
    (pkg / "c.py").write_text("import importlib\nimportlib.import_module('serialkin.d')\n")
    (pkg / "d.py").write_text("from typing import TYPE_CHECKING\nif TYPE_CHECKING:\n"
                              "    from serialkin import c\n")  # annotations only
    (pkg / "e.py").write_text("import importlib\n"
                              "def f(n):\n    importlib.import_module(f'serialkin.sub.{n}')\n")
    (pkg / "sub" / "g.py").write_text("from serialkin.e import f\n")  # dynamic: e <-> sub.g
    monkeypatch.setattr(sys.modules[__name__], "SRC", tmp_path)
    graph = import_graph()
    assert graph["serialkin.c"] == {"serialkin.d": 2} and graph["serialkin.d"] == {}
    assert strongly_connected(graph) == [["serialkin.a", "serialkin.b"],
                                         ["serialkin.e", "serialkin.sub.g"]]
    assert _a_cycle(graph, ["serialkin.a", "serialkin.b"]) == (
        "serialkin.a (line 1) -> serialkin.b (line 2) -> serialkin.a")


def test_no_import_cycles():
    """No module of serialkin imports itself again through others, deferred or not."""
    graph = import_graph()
    assert len(graph) > 100 and "serialkin.ik.registry" in graph  # the whole package seen
    cycles = [_a_cycle(graph, c) for c in strongly_connected(graph)]
    assert not cycles, "import cycles (module granularity):\n" + "\n".join(cycles)
