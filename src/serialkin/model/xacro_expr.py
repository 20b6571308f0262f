"""Deprecated location of :mod:`serialkin.formats.xacro_expr` (removed in the next release).

The file formats left the model layer (the model knows no file format): import from
:mod:`serialkin.formats.xacro_expr` (or :mod:`serialkin.formats`). This alias re-exports that
module's names, private ones included, and warns once when imported.
"""

import warnings
from typing import Any

from serialkin.formats import xacro_expr as _moved

warnings.warn("serialkin.model.xacro_expr is deprecated: import from serialkin.formats.xacro_expr",
              DeprecationWarning, stacklevel=2)

__all__ = list(_moved.__all__)


def __getattr__(name: str) -> Any:
    """Every name of :mod:`serialkin.formats.xacro_expr`, read from there."""
    return getattr(_moved, name)
