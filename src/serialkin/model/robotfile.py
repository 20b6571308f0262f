"""Deprecated location of :mod:`serialkin.formats.robotfile` (removed in the next release).

The file formats left the model layer (the model knows no file format): import from
:mod:`serialkin.formats.robotfile` (or :mod:`serialkin.formats`). This alias re-exports that
module's names, private ones included, and warns once when imported.
"""

import warnings
from typing import Any

from serialkin.formats import robotfile as _moved

warnings.warn("serialkin.model.robotfile is deprecated: import from serialkin.formats.robotfile",
              DeprecationWarning, stacklevel=2)

__all__ = list(_moved.__all__)


def __getattr__(name: str) -> Any:
    """Every name of :mod:`serialkin.formats.robotfile`, read from there."""
    return getattr(_moved, name)
