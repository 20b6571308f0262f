"""The exceptions serialkin raises.

Every error derives from :class:`SerialkinError`. Input errors also derive from the
built-in :class:`ValueError` or :class:`TypeError`, so ``except ValueError`` keeps working.
A failed inverse-kinematics solve is *not* an exception: it is a result with
``success=False`` and a ``reason``.
"""

from __future__ import annotations


class SerialkinError(Exception):
    """Root of every exception raised by serialkin."""


class InputError(SerialkinError, ValueError):
    """An argument has the wrong shape, a non-finite value or a value out of its domain."""


class InputTypeError(SerialkinError, TypeError):
    """An argument has the wrong type (e.g. a string where numbers were expected)."""


class RobotDefinitionError(InputError):
    """A robot description (DH table, joint list, robot or URDF file) is malformed.

    The message names the file (when there is one), the field or element and what was
    expected.
    """


class BudgetError(InputError):
    """A size derived from the input would need more memory than the budget allows.

    Sizes are those of samples, grid cells, path points, links (see
    :mod:`serialkin._budget`). The message names the setting, the estimated size and
    the budget, and how to raise it.
    """


class OutputError(SerialkinError, OSError):
    """An output file or folder cannot be written (the message names the path)."""


class SingularityError(SerialkinError, ValueError):
    """A quantity is undefined at this configuration (e.g. a representation singularity)."""


class NoClosedFormError(SerialkinError, ValueError):
    """No closed-form inverse kinematics is known for the robot's structure."""


class NotSupportedError(SerialkinError, ValueError):
    """A feature of the input is understood but not supported (e.g. a mimic joint)."""
