"""serialkin's version, in a module of its own so that any layer can read it.

(The package's ``__init__`` imports every feature; a module importing ``serialkin`` for
its version would import upwards through it.)
"""

__version__ = "0.1.0"
