"""Values computed once per object (a robot) and dropped with it: the one cache mechanism.

Solvers keep per-robot data (packed arrays, prepared entry points, characteristic
lengths) here rather than on the robot: a :class:`~serialkin.model.robot.Robot` is
immutable, so what is computed from it stays valid for its lifetime, and the model layer
need not know who caches what.
"""

from __future__ import annotations

import weakref
from collections.abc import Callable
from typing import Any, Generic, TypeVar

V = TypeVar("V")


class PerObject(Generic[V]):
    """A mapping from live objects to values, keyed by identity.

    ``get`` is one dictionary lookup (about 50 ns: the IK fast path reads it on every
    call); an entry is removed when its object is garbage-collected
    (:func:`weakref.finalize`), so an identity is never reused while its entry exists.
    An object that cannot be weakly referenced is not cached (``set`` returns the value
    without keeping it).
    """

    def __init__(self) -> None:
        self._values: dict[int, V] = {}

    def get(self, obj: object, default: Any = None) -> V | Any:
        """The value kept for ``obj``, or ``default``."""
        return self._values.get(id(obj), default)

    def set(self, obj: object, value: V) -> V:
        """Keep ``value`` for ``obj`` (replacing any); returns ``value``."""
        key = id(obj)
        if key not in self._values:
            try:
                weakref.finalize(obj, self._values.pop, key, None)
            except TypeError:  # not weak-referenceable: nothing is kept
                return value
        self._values[key] = value
        return value

    def setdefault(self, obj: object, make: Callable[[], V]) -> V:
        """The value kept for ``obj``, made by ``make()`` and kept the first time."""
        found = self._values.get(id(obj), _MISSING)
        return self.set(obj, make()) if found is _MISSING else found

    def __len__(self) -> int:
        return len(self._values)


_MISSING: Any = object()
