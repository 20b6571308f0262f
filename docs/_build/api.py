"""The public API as the docs see it: packages with ``__all__``, and where each name is documented.

Shared by ``gen_pages.py`` (which writes the API reference) and ``tests/docs`` (which checks
that every public name is in it, with a docstring).
"""

from __future__ import annotations

import importlib
import inspect
import pkgutil
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
#: packages that are not part of the library's API (the CLI has its own page)
NOT_API = {"serialkin.cli", "serialkin.chapter", "serialkin.chapter.sections"}

Packages = list[tuple[str, list[str]]]


def public_packages() -> list[tuple[str, list[str]]]:
    """``(dotted name, __all__)`` of serialkin and each subpackage declaring ``__all__``."""
    if str(ROOT / "src") not in sys.path:
        sys.path.insert(0, str(ROOT / "src"))
    import serialkin

    found = [("serialkin", list(serialkin.__all__))]
    todo = [serialkin]
    while todo:  # not pkgutil.walk_packages: it hides a package that fails to import
        package = todo.pop()
        for info in pkgutil.iter_modules(package.__path__, package.__name__ + "."):
            name = info.name
            if not info.ispkg or name in NOT_API or name.rsplit(".", 1)[1].startswith("_"):
                continue
            mod = importlib.import_module(name)
            todo.append(mod)
            if getattr(mod, "__all__", None):
                found.append((name, list(mod.__all__)))
    return sorted(found)


def _home(packages: Packages, obj: object, member: str) -> str | None:
    """The deepest public package whose tree defines ``obj`` and exports it (None: none)."""
    where = getattr(obj, "__name__", None) if inspect.ismodule(obj) else getattr(
        obj, "__module__", None) if (inspect.isclass(obj) or inspect.isfunction(obj)) else None
    if not where:
        return None
    if inspect.ismodule(obj) and any(n == where for n, _ in packages):
        return where  # a public package: it has its own page
    homes = [n for n, names in packages
             if (where == n or where.startswith(n + ".")) and member in names]
    return max(homes, key=len) if homes else None


def documented_at(packages: Packages, package: str, member: str) -> tuple[str, str | None]:
    """``(page package, anchor id)`` where ``package.member`` is documented.

    The anchor is None when the page links to another package's page instead.
    """
    obj = getattr(importlib.import_module(package), member)
    home = _home(packages, obj, member)
    if home is not None and home != package:
        return home, None
    if inspect.ismodule(obj):
        return package, obj.__name__
    if (inspect.isclass(obj) or inspect.isfunction(obj)) and getattr(obj, "__module__", None):
        return package, f"{obj.__module__}.{obj.__qualname__}"
    return package, f"{package}.{member}"


def member_block(packages: Packages, package: str, member: str) -> str:
    """The mkdocstrings block of one public name, documented once, in its home package.

    A name re-exported by a higher package (``serialkin.Robot``) is documented on the page
    of the package that defines it (``serialkin.model``) and linked from the others.
    Functions and classes are read from their defining module (griffe reads sources
    statically and cannot follow lazy ``__getattr__`` exports); constants through the
    package.
    """
    obj = getattr(importlib.import_module(package), member)
    home = _home(packages, obj, member)
    if home is not None and home != package:
        target = obj.__name__ if inspect.ismodule(obj) else f"{obj.__module__}.{obj.__qualname__}"
        anchor = "" if inspect.ismodule(obj) else f"#{target}"
        return (f"## `{member}`\n\n`{package}.{member}` is "
                f"[`{target}`]({home}.md{anchor}), documented with `{home}`.")
    _, path = documented_at(packages, package, member)
    if inspect.ismodule(obj):
        return f"::: {path}\n    options:\n      heading_level: 2"
    return f"::: {path}\n    options:\n      heading_level: 2\n      show_root_heading: true"


