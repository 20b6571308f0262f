"""Deprecated location of :mod:`serialkin.formats.mjcf` (removed in the next release).

The file formats left the model layer (the model knows no file format): import from
:mod:`serialkin.formats.mjcf` (or :mod:`serialkin.formats`). This alias re-exports that
module's names, private ones included, and warns once when imported.
"""

import warnings
from typing import Any

from serialkin.formats import mjcf as _moved

warnings.warn("serialkin.model.mjcf is deprecated: import from serialkin.formats.mjcf",
              DeprecationWarning, stacklevel=2)

__all__ = list(_moved.__all__)


def __getattr__(name: str) -> Any:
    """Every name of :mod:`serialkin.formats.mjcf`, read from there."""
    return getattr(_moved, name)
