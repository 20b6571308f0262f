"""Deprecated location of :mod:`serialkin.formats.urdf` (removed in the next release).

The file formats left the model layer (the model knows no file format): import from
:mod:`serialkin.formats.urdf` (or :mod:`serialkin.formats`). This alias re-exports that
module's names, private ones included, and warns once when imported.
"""

import warnings
from typing import Any

from serialkin.formats import urdf as _moved

warnings.warn("serialkin.model.urdf is deprecated: import from serialkin.formats.urdf",
              DeprecationWarning, stacklevel=2)

__all__ = list(_moved.__all__)

#: Private helpers that became public in serialkin.formats.xmlfile (other code used them).
_RENAMED = {"_read_xml": "read_robot_xml", "_floats": "parse_floats"}


def __getattr__(name: str) -> Any:
    """Every name of :mod:`serialkin.formats.urdf`, read from there."""
    return getattr(_moved, _RENAMED.get(name, name))
