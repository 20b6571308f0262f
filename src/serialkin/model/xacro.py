"""xacro import: expand a ROS xacro file with the ``xacro`` processor, then read the URDF.

xacro (XML macros: ``<xacro:macro>``, ``<xacro:property>``, ``${expressions}``,
``<xacro:arg>`` with ``$(arg name)``, ``<xacro:include>``, ``$(find pkg)``) is a
language of its own with many corner cases; the well-kept ROS processor, published on
the package index as ``xacro``, expands it. It is an optional extra
(``pip install "serialkin[xacro]"``) imported only when a xacro file is read.

``$(find pkg)`` (and ``${find('pkg')}``) resolve to the folder of ``pkg`` given in
``package_map``, else ``FOLDER/pkg`` for the first folder of ``search_path`` that holds
it, else ROS's own lookup (``ament_index_python``) when it is installed — the same
package map and search path that :func:`~serialkin.model.urdf.robot_from_urdf` uses for
``package://`` mesh paths, which are passed on to it. Relative mesh paths are looked up
next to the xacro file first. The xacro processor keeps its state in module globals, so
expansions are serialised by a lock.
"""

from __future__ import annotations

import contextlib
import os
import threading
from collections.abc import Iterator, Mapping, Sequence
from pathlib import Path

from serialkin._checks import short_repr
from serialkin.errors import NotSupportedError, RobotDefinitionError, SerialkinError

__all__ = ["expand_xacro", "robot_from_xacro"]

_LOCK = threading.Lock()
_EXTRA = 'xacro files need the xacro processor: pip install "serialkin[xacro]"'


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


@contextlib.contextmanager
def _patched_find(xacro, find) -> Iterator[None]:
    """Route xacro's ``$(find)`` and ``find()`` through ``find`` while expanding."""
    sa = xacro.substitution_args
    old = sa._eval_find
    old_eval = sa._eval_dict.get("find")
    sa._eval_find = find
    sa._eval_dict["find"] = find
    try:
        yield
    finally:
        sa._eval_find = old
        sa._eval_dict["find"] = old_eval


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
            or argument undefined, a package not found (the message names the file).
    """
    xacro = _xacro_module()
    args = _check_mappings(mappings)
    if isinstance(search_path, str | os.PathLike):
        search_path = [search_path]
    text = os.fspath(path_or_string)
    is_text = text.lstrip().startswith("<")
    source = "<string>" if is_text else text
    if not is_text and not Path(text).is_file():
        raise RobotDefinitionError(f"xacro file {short_repr(text)} does not exist")
    find = _package_finder(package_map or {}, search_path, xacro.substitution_args._eval_find)
    with _LOCK, _patched_find(xacro, find):
        try:
            if is_text:
                xacro.init_stacks(None)
                doc = xacro.parse(text)
                xacro.process_doc(doc, mappings=args)
            else:
                doc = xacro.process_file(str(Path(text).resolve()), mappings=args)
            return doc.toxml()
        except SerialkinError as exc:
            raise type(exc)(f"{source}: {exc}") from None
        except Exception as exc:  # the processor's own errors: XacroException, XML, names
            msg = str(exc) or type(exc).__name__
            raise RobotDefinitionError(f"{source}: xacro failed: {msg}") from exc


def robot_from_xacro(path_or_string: str | os.PathLike[str], base_link: str | None = None,
                     tip_link: str | None = None, *,
                     mappings: Mapping[str, object] | None = None,
                     package_map: Mapping[str, str | os.PathLike[str]] | None = None,
                     search_path: Sequence[str | os.PathLike[str]] = (),
                     resolve_meshes: bool = False):
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
    from serialkin.model.urdf import robot_from_urdf

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
