"""Built-in robot models (the zoo), with a name lookup for the command line.

Functions build a fresh :class:`~serialkin.Robot` on each call::

    import serialkin as sk

    sk.models.puma560()
    sk.models.planar(20, 0.01675, qlim=(-1.745, 1.745))
    sk.models.get("ur5")          # by name, case-insensitive
    sk.models.get("planar6")      # planar<N>: an N-link planar arm of unit links

Every model names the published table it comes from in ``robot.source``.
"""

from __future__ import annotations

import difflib
import re
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

from serialkin._checks import MAX_JOINTS, short_repr
from serialkin.errors import InputError
from serialkin.model.robot import Robot
from serialkin.models.chapter import scara, three_link, two_link
from serialkin.models.industrial import iiwa7, panda, puma560, stanford, ur5
from serialkin.models.planar import planar


@dataclass(frozen=True)
class ModelInfo:
    """One entry of the model catalog.

    Attributes:
        name: lookup name (lower case).
        build: function returning the robot (keyword arguments are passed through).
        summary: one-line description.
        dof: number of joints, or None when it is a parameter (``planar``).
        convention: DH convention of the table.
    """

    name: str
    build: Callable[..., Robot]
    summary: str
    dof: int | None
    convention: str


_CATALOG: tuple[ModelInfo, ...] = (
    ModelInfo("planar", planar, "planar n-link arm (any n, any lengths)", None, "standard"),
    ModelInfo("two_link", two_link, "planar 2-link arm of Figures 5 and 7", 2, "standard"),
    ModelInfo("three_link", three_link, "planar 3-link arm of Figure 6", 3, "standard"),
    ModelInfo("scara", scara, "the chapter's SCARA (Table 1), RRPR", 4, "standard"),
    ModelInfo("puma560", puma560, "Unimation PUMA 560, 6R", 6, "standard"),
    ModelInfo("stanford", stanford, "Stanford arm, RRPRRR", 6, "standard"),
    ModelInfo("ur5", ur5, "Universal Robots UR5, 6R", 6, "standard"),
    ModelInfo("panda", panda, "Franka Emika Panda, 7R, with flange", 7, "modified"),
    ModelInfo("iiwa7", iiwa7, "KUKA LBR iiwa 7 R800, 7R", 7, "standard"),
)

_ALIASES = {"puma": "puma560", "franka": "panda", "iiwa": "iiwa7", "lbr_iiwa7": "iiwa7",
            "twolink": "two_link", "threelink": "three_link", "planar2": "two_link",
            "planar3": "three_link"}
_PLANAR_N = re.compile(r"^planar(\d+)$")


def catalog() -> tuple[ModelInfo, ...]:
    """Return every built-in model, in a fixed order."""
    return _CATALOG


def names() -> tuple[str, ...]:
    """Return the lookup names of the built-in models."""
    return tuple(m.name for m in _CATALOG)


def get(name: str, **kwargs: Any) -> Robot:
    """Build a built-in model by name.

    Names are case-insensitive, ``-`` and ``_`` are interchangeable, and ``planar<N>``
    (e.g. ``planar6``) gives an N-link planar arm (unit links unless ``lengths`` is given).

    Args:
        name: a name from :func:`names` (or an alias such as ``puma``, ``franka``).
        **kwargs: passed to the model function, e.g. ``get("scara", l1=0.4)``.

    Raises:
        InputError: unknown name (the message suggests close matches and lists all names).
        InputTypeError: ``name`` is not a string.
    """
    from serialkin.errors import InputTypeError

    if not isinstance(name, str):
        raise InputTypeError(f"model name must be a string, got {type(name).__name__}")
    key = name.strip().lower().replace("-", "_").replace(" ", "_")
    key = _ALIASES.get(key, key)
    m = _PLANAR_N.match(key)
    if m and key not in names():
        digits = m.group(1)  # no int() of a 10,000-digit string: bounded first
        if len(digits) > 12:
            raise InputError(f"robot model planar<N> with a {len(digits)}-digit N; a robot "
                             f"has at most {MAX_JOINTS} joints")
        return planar(int(digits), **kwargs)
    for info in _CATALOG:
        if info.name == key:
            return info.build(**kwargs)
    choices = list(names()) + list(_ALIASES)
    close = list(dict.fromkeys(
        _ALIASES.get(c, c) for c in difflib.get_close_matches(key, choices, n=3, cutoff=0.5)
    ))
    hint = f"; did you mean {' or '.join(repr(c) for c in close)}?" if close \
        else ""
    raise InputError(
        f"unknown robot model {short_repr(name)}{hint} Available: {', '.join(names())} "
        f"(and planar<N>, e.g. planar6)"
    )


__all__ = [
    "ModelInfo",
    "catalog",
    "get",
    "iiwa7",
    "names",
    "panda",
    "planar",
    "puma560",
    "scara",
    "stanford",
    "three_link",
    "two_link",
    "ur5",
]
