"""xacro import: expand a ROS xacro file with the ``xacro`` processor, then read the URDF.

xacro (XML macros: ``<xacro:macro>``, ``<xacro:property>``, ``${expressions}``,
``<xacro:arg>`` with ``$(arg name)``, ``<xacro:include>``, ``$(find pkg)``) is a
language of its own with many corner cases; the well-kept ROS processor, published on
the package index as ``xacro``, expands it. It is an optional extra
(``pip install "serialkin[xacro]"``) imported only when a xacro file is read.

``$(find pkg)`` (and ``${find('pkg')}``) resolve to the folder of ``pkg`` given in
``package_map``, else ``FOLDER/pkg`` for the first folder of ``search_path`` that holds
it, else ROS's own lookup (``ament_index_python``) when it is installed — the same
package map and search path that :func:`~serialkin.formats.urdf.robot_from_urdf` uses for
``package://`` mesh paths, which are passed on to it. Relative mesh paths are looked up
next to the xacro file first. The xacro processor keeps its state in module globals, so
expansions are serialised by a lock.

A xacro file is data, never code. While a file expands, the processor's expression
evaluation (``${...}``, ``$(eval ...)``, units in YAML) is replaced by
:func:`serialkin.formats.xacro_expr.evaluate`, which accepts numbers, names, arithmetic,
comparisons, conditionals and a fixed table of math functions, and nothing that reaches
Python objects. Files are read only inside the folders the user named: the xacro
file's own folder (the working folder for XML text), ``package_map`` and
``search_path`` folders and the packages ``$(find)`` resolved; an include or a
``load_yaml`` that leaves them (``..``, an absolute path, a link pointing out) is an
error, never a read. A file may call at most :data:`MAX_MACRO_CALLS` macros and expand
to at most :data:`MAX_OUTPUT` characters (:class:`~serialkin.errors.BudgetError`).
"""

from __future__ import annotations

import contextlib
import os
import re
import threading
from collections.abc import Iterator, Mapping, Sequence
from pathlib import Path

from serialkin._checks import short_repr
from serialkin.errors import (
    BudgetError,
    NotSupportedError,
    RobotDefinitionError,
    SerialkinError,
)
from serialkin.formats.urdf import robot_from_urdf
from serialkin.formats.xacro_expr import FUNCTIONS, evaluate
from serialkin.model.robot import Robot

__all__ = ["MAX_MACRO_CALLS", "MAX_OUTPUT", "expand_xacro", "robot_from_xacro"]

_LOCK = threading.Lock()
_EXTRA = 'xacro files need the xacro processor: pip install "serialkin[xacro]"'
#: Most macro calls one expansion may make (a macro calling itself twice, 40 levels
#: deep, would make 2⁴⁰).
MAX_MACRO_CALLS = 50_000
#: Longest expanded document [characters].
MAX_OUTPUT = 50_000_000
#: A ROS package name: letters, digits, ``_ . -``, no path separators.
_PACKAGE = re.compile(r"^[A-Za-z0-9_][A-Za-z0-9_.-]{0,199}$")


def _xacro_module():
    """The ``xacro`` package, or a clear error naming the extra to install."""
    try:
        import xacro
        import xacro.substitution_args  # noqa: F401  (where $(find) is evaluated)
    except ImportError:
        raise NotSupportedError(_EXTRA) from None
    return xacro


def _package_finder(package_map: Mapping[str, object], search_path: Sequence[object],
                    fallback):
    """A ``find(pkg)`` for xacro: package map, then search path, then ROS's own lookup."""
    folders = {str(k): Path(os.fspath(v)).resolve() for k, v in package_map.items()}
    search = [Path(os.fspath(p)).resolve() for p in search_path]

    def find(pkg: str) -> str:
        if not isinstance(pkg, str) or not _PACKAGE.match(pkg) or ".." in pkg:
            raise RobotDefinitionError(
                f"$(find ...): {short_repr(pkg, 80)} is not a package name (letters, digits, "
                "'_', '.', '-'; no path)")
        if pkg in folders:
            return str(folders[pkg])
        for d in search:
            if (d / pkg).is_dir():
                return str(d / pkg)
        try:
            return str(fallback(pkg))
        except Exception:  # ament_index_python missing, or the package unknown to ROS
            pass
        looked = ", ".join(short_repr(str(d / pkg), 120) for d in search) or "nowhere"
        raise RobotDefinitionError(
            f"$(find {pkg}): package {short_repr(pkg)} not found (looked in package_map, "
            f"then {looked}); give package_map={{{pkg!r}: FOLDER}} or search_path=")

    return find


class _Sandbox:
    """What one expansion may read and do: its folders, and counters of its work."""

    def __init__(self, xacro, find, roots: list[Path]) -> None:
        self.xacro = xacro
        self.roots = roots
        self.macro_calls = 0
        self.texts: dict[str, str] = {}

        def found(pkg: str) -> str:
            folder = find(pkg)
            self.roots.append(Path(folder).resolve())  # a package the file asked for
            return folder

        self.find = found

    def allowed(self, path: str) -> str:
        """``path`` if it resolves (links followed) inside a root; else RobotDefinitionError."""
        real = Path(os.path.realpath(path))
        if any(real == r or r in real.parents for r in self.roots):
            return path
        shown = ", ".join(short_repr(str(r), 100) for r in self.roots[:4]) or "none"
        raise RobotDefinitionError(
            f"{short_repr(path, 160)} is outside the folders this file may read (the file's "
            f"own folder, package_map, search_path: {shown}); a xacro file reads only "
            "there")

    def line_of(self, expression: str) -> str:
        """``'FILE, line N: '`` of the file being expanded where ``expression`` first occurs.

        ``''`` while XML text expands (the caller names it).
        """
        stack = self.xacro.filestack or [None]
        name = stack[-1]
        if not name:
            return ""
        shown = "" if name == stack[0] else f"{name}, "  # the caller names the top file
        if name not in self.texts:
            try:
                self.texts[name] = Path(name).read_text(encoding="utf-8", errors="replace")
            except OSError:
                self.texts[name] = ""
        at = self.texts[name].find(expression.strip())
        line = "" if at < 0 else f"line {self.texts[name].count(chr(10), 0, at) + 1}"
        return f"{shown}{line}: " if shown or line else ""

    def functions(self, extra: Mapping[str, object]) -> dict[str, object]:
        table = dict(FUNCTIONS)
        table["find"] = self.find
        table["load_yaml"] = self.xacro.load_yaml  # reads through allowed() only
        table.update(extra)
        return table

    def evaluate(self, expression: str, lookup, extra: Mapping[str, object]) -> object:
        try:
            return evaluate(expression, lookup, functions=self.functions(extra))
        except SerialkinError as exc:
            raise type(exc)(f"{self.line_of(expression)}expression "
                            f"{short_repr(expression.strip(), 120)}: {exc}") from None


@contextlib.contextmanager
def _sandboxed(xacro, find, roots: list[Path]) -> Iterator[_Sandbox]:
    """Route xacro's evaluation, file access and macro calls through a :class:`_Sandbox`."""
    sa = xacro.substitution_args
    box = _Sandbox(xacro, find, roots)
    abs_spec, parse, macro_call = xacro.abs_filename_spec, xacro.parse, xacro.handle_macro_call

    def safe_eval(expr, globals, locals=None):
        def lookup(name):
            for table in (locals, globals):
                if table is not None:
                    try:
                        return table[name]
                    except KeyError:
                        pass
            raise KeyError(name)

        arg = xacro.substitution_args_context.get("arg", {})
        return box.evaluate(expr, lookup, {"arg": lambda name: arg[name]})

    def eval_substitution(s, context):
        args = context.setdefault("arg", {})

        def lookup(name):
            return sa.convert_value(args[name], "auto")

        return str(box.evaluate(s, lookup, {
            "arg": lambda name: sa.convert_value(sa._eval_arg(name, args=args), "auto")}))

    def checked_spec(spec):
        return box.allowed(abs_spec(spec))

    def checked_parse(inp, filename=None):
        if inp is None and filename is not None:
            box.allowed(os.path.join(xacro.root_dir, filename))
        return parse(inp, filename)

    def counted_macro_call(node, macros, symbols):
        if node.tagName.startswith("xacro:"):
            box.macro_calls += 1
            if box.macro_calls > MAX_MACRO_CALLS:
                raise BudgetError(f"more than {MAX_MACRO_CALLS} macro calls (the file's "
                                  "macros expand without end, or exponentially)")
        return macro_call(node, macros, symbols)

    patches = [(xacro, "safe_eval", safe_eval), (xacro, "abs_filename_spec", checked_spec),
               (xacro, "parse", checked_parse), (xacro, "handle_macro_call", counted_macro_call),
               (sa, "_eval", eval_substitution), (sa, "_eval_find", box.find)]
    saved = [(mod, name, getattr(mod, name)) for mod, name, _ in patches]
    saved_find = sa._eval_dict.get("find")
    for mod, name, value in patches:
        setattr(mod, name, value)
    sa._eval_dict["find"] = box.find
    try:
        yield box
    finally:
        for mod, name, value in saved:
            setattr(mod, name, value)
        sa._eval_dict["find"] = saved_find


def _unwrapped(exc: BaseException) -> SerialkinError | None:
    """The serialkin error inside the processor's wrappers (``XacroException.exc``), if any."""
    seen = 0
    while exc is not None and seen < 50:
        if isinstance(exc, SerialkinError):
            return exc
        exc = getattr(exc, "exc", None) or exc.__cause__ or exc.__context__
        seen += 1
    return None


def _check_mappings(mappings: Mapping[str, object] | None) -> dict[str, str]:
    if mappings is None:
        return {}
    if not isinstance(mappings, Mapping):
        raise RobotDefinitionError(
            f"mappings must be a mapping of xacro argument names to values, got "
            f"{type(mappings).__name__} {short_repr(mappings)}")
    out = {}
    for k, v in mappings.items():
        if not isinstance(k, str) or not isinstance(v, str | int | float | bool):
            raise RobotDefinitionError(
                f"mappings: expected name -> string (or number) pairs, got {short_repr(k)}: "
                f"{short_repr(v)}")
        out[k] = str(v).lower() if isinstance(v, bool) else str(v)
    return out


def expand_xacro(path_or_string: str | os.PathLike[str], *,
                 mappings: Mapping[str, object] | None = None,
                 package_map: Mapping[str, str | os.PathLike[str]] | None = None,
                 search_path: Sequence[str | os.PathLike[str]] = ()) -> str:
    """Expand a xacro file (or xacro XML text) into URDF text with the ROS processor.

    Args:
        path_or_string: a ``.xacro`` / ``.urdf.xacro`` file, or the XML text itself
            (relative includes then resolve from the working folder).
        mappings: values of the file's ``<xacro:arg>`` arguments (``name -> value``).
        package_map: package name -> folder, for ``$(find pkg)``.
        search_path: folders where ``$(find pkg)`` looks for ``FOLDER/pkg``.

    Returns:
        The expanded document as an XML string.

    Raises:
        NotSupportedError: the ``xacro`` package is not installed (names the extra).
        RobotDefinitionError: the file is missing, the XML malformed, a macro, property
            or argument undefined, a package not found, an expression that is not data
            (:class:`~serialkin.formats.xacro_expr.XacroExpressionError`, naming the file,
            the line and the expression), an include or YAML file outside the allowed
            folders (the message names the file).
        BudgetError: more macro calls, a larger expanded document, or a larger number,
            string or expression than allowed.
    """
    xacro = _xacro_module()
    args = _check_mappings(mappings)
    if isinstance(search_path, str | os.PathLike):
        search_path = [search_path]
    text = os.fspath(path_or_string)
    is_text = text.lstrip().startswith("<")
    source = "<string>" if is_text else text
    if not is_text:
        try:
            is_file, is_dir = Path(text).is_file(), Path(text).is_dir()
        except OSError as exc:  # a name longer than the system allows, a loop of links
            raise RobotDefinitionError(f"xacro file {short_repr(text, 120)}: "
                                       f"{exc.strerror or exc}") from None
        if not is_file:
            what = "is a folder, not a xacro file" if is_dir else "does not exist"
            raise RobotDefinitionError(f"xacro file {short_repr(text, 120)} {what}")
    find = _package_finder(package_map or {}, search_path, xacro.substitution_args._eval_find)
    roots = [Path.cwd().resolve() if is_text else Path(text).resolve().parent]
    roots += [Path(os.fspath(v)).resolve() for v in (package_map or {}).values()]
    roots += [Path(os.fspath(v)).resolve() for v in search_path]
    with _LOCK, _sandboxed(xacro, find, roots):
        try:
            if is_text:
                xacro.init_stacks(None)
                doc = xacro.parse(text)
                xacro.process_doc(doc, mappings=args)
            else:
                doc = xacro.process_file(str(Path(text).resolve()), mappings=args)
            out = doc.toxml()
        except RecursionError:
            raise BudgetError(f"{source}: the xacro file nests macros or includes too "
                              "deeply") from None
        except Exception as exc:  # the processor's own errors: XacroException, XML, names
            inner = _unwrapped(exc)
            if inner is not None:
                raise type(inner)(f"{source}: {inner}") from None
            msg = short_repr(str(exc) or type(exc).__name__, 2000)
            raise RobotDefinitionError(f"{source}: xacro failed: {msg}") from exc
    if len(out) > MAX_OUTPUT:
        raise BudgetError(f"{source}: the expanded document has {len(out)} characters, more "
                          f"than the {MAX_OUTPUT} allowed")
    return out


def robot_from_xacro(path_or_string: str | os.PathLike[str], base_link: str | None = None,
                     tip_link: str | None = None, *,
                     mappings: Mapping[str, object] | None = None,
                     package_map: Mapping[str, str | os.PathLike[str]] | None = None,
                     search_path: Sequence[str | os.PathLike[str]] = (),
                     resolve_meshes: bool = False) -> Robot:
    """Build a :class:`~serialkin.Robot` from a xacro file: :func:`expand_xacro`, then URDF.

    Args:
        path_or_string: a xacro file, or its XML text.
        base_link: link whose frame is the robot's base (default: the tree's root).
        tip_link: link whose frame is the tool (default: the single leaf).
        mappings: values of the ``<xacro:arg>`` arguments.
        package_map: package name -> folder, for ``$(find pkg)`` and ``package://pkg``.
        search_path: folders holding packages (``FOLDER/pkg``) and relative mesh paths;
            relative mesh paths are looked up next to the xacro file first.
        resolve_meshes: if true, a mesh path that does not resolve is an error.

    Raises:
        NotSupportedError: the ``xacro`` package is not installed; or as ``robot_from_urdf``.
        RobotDefinitionError: as :func:`expand_xacro` and ``robot_from_urdf`` (messages name
            the xacro file).
    """
    text = expand_xacro(path_or_string, mappings=mappings, package_map=package_map,
                        search_path=search_path)
    is_text = os.fspath(path_or_string).lstrip().startswith("<")
    source = "<string>" if is_text else os.fspath(path_or_string)
    if isinstance(search_path, str | os.PathLike):
        search_path = [search_path]
    folders = ([] if is_text else [Path(source).resolve().parent]) + list(search_path)
    label = source if is_text else f"{source} (expanded by xacro)"
    try:
        robot = robot_from_urdf(text, base_link=base_link, tip_link=tip_link,
                                package_map=package_map, search_path=folders,
                                resolve_meshes=resolve_meshes)
    except SerialkinError as exc:
        msg = str(exc)
        raise type(exc)(msg.replace("<string>", label, 1) if msg.startswith("<string>")
                        else f"{label}: {msg}") from None
    return robot._copy(source=robot.source.replace("URDF <string>", f"xacro {source}", 1))
