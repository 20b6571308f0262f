"""Reading the XML robot descriptions safely: the document and its number attributes.

Shared by the URDF and MJCF readers and by SRDF (:mod:`serialkin.collision.srdf`).
Documents are parsed by :func:`serialkin._files.parse_xml` (the standard library's
:mod:`xml.etree.ElementTree`, bounded in size); errors are
:class:`~serialkin.errors.RobotDefinitionError` naming the file and the element.
"""

from __future__ import annotations

import math
import os
import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np

from serialkin._checks import short_repr
from serialkin._files import parse_xml, read_bytes
from serialkin.errors import RobotDefinitionError

__all__ = ["parse_floats", "read_robot_xml"]


def read_robot_xml(path_or_string: str | os.PathLike[str], what: str = "URDF"
                   ) -> tuple[ET.Element, str]:
    """Parse a URDF or SRDF file or string; ``(root element, source)``.

    ``path_or_string`` is XML text when it starts with ``<`` (after blanks), else a file
    path; ``what`` ("URDF", "SRDF") names the kind of file in the messages. A file is
    read as bytes (at most :data:`serialkin._files.MAX_FILE_BYTES`) so that ``<?xml ...
    encoding="ISO-8859-1"?>`` is decoded as declared (UTF-8 by default). ``source`` is
    the file path, or ``"<string>"`` for text.

    Raises:
        RobotDefinitionError: a missing or oversized file, malformed XML (with line and
            column), or a root element other than ``<robot>``.
    """
    text = str(path_or_string)
    data: str | bytes
    if text.lstrip().startswith("<"):
        source, data = "<string>", text
    else:
        path = Path(text)
        if not path.exists():
            raise RobotDefinitionError(f"{what} file {short_repr(text)} does not exist")
        source = str(path)
        data = read_bytes(path, what=f"{what} file", error=RobotDefinitionError)
    root = parse_xml(data, source, error=RobotDefinitionError)
    if root.tag != "robot":
        raise RobotDefinitionError(f"{source}: the root element must be <robot>, got <{root.tag}>")
    return root, source


def parse_floats(text: str | None, count: int, default: tuple[float, ...], where: str,
                 bound: float = math.inf) -> np.ndarray:
    """``count`` finite numbers from an attribute, each with magnitude at most ``bound``.

    Args:
        text: the attribute's value (numbers separated by blanks), or None when absent.
        count: how many numbers it must hold.
        default: the values when the attribute is absent.
        where: the file and element, for the error message.
        bound: the largest magnitude accepted.

    Raises:
        RobotDefinitionError: not exactly ``count`` finite numbers within ``bound``.
    """
    if text is None:
        return np.array(default, dtype=float)
    parts = text.split()
    want = f"{count} finite numbers" + (f" with |x| <= {bound:g}" if bound < math.inf else "")
    try:
        vals = np.array([float(p) for p in parts[: count + 1]])
    except ValueError:
        raise RobotDefinitionError(f"{where}: expected {want}, got {short_repr(text)}") from None
    if len(parts) != count or not np.isfinite(vals).all() or np.abs(vals).max() > bound:
        raise RobotDefinitionError(f"{where}: expected {want}, got {short_repr(text)}")
    return vals
