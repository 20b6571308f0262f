"""Built-in robot models (the zoo), with a name lookup for the command line.

Functions build a fresh :class:`~serialkin.Robot` on each call::

    import serialkin as sk

    sk.models.puma560()
    sk.models.planar(20, 0.01675, qlim=(-1.745, 1.745))
    sk.models.get("ur5")          # by name, case-insensitive
    sk.models.get("planar6")      # planar<N>: an N-link planar arm of unit links
    sk.models.get("ur5-vendor")   # the UR5 in the frames of the vendor URDF

Every model names the published table it comes from in ``robot.source``, and its base and
flange frames against the vendor's description in ``ModelInfo.frames``
(:mod:`serialkin.models.frames`). Where the vendor's frames differ from the table's, the
variant ``<name>_vendor`` (``ur5_vendor``, ``panda_vendor``; ``-vendor`` works too) is the
same arm with the vendor's base and tip frames: its FK equals the vendor URDF's.
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
from serialkin.models.frames import FRAMES, VENDOR_SUFFIX, ModelFrames, vendor_variants
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
        frames: base and flange frames, and their relation to the vendor description.
    """

    name: str
    build: Callable[..., Robot]
    summary: str
    dof: int | None
    convention: str

    @property
    def frames(self) -> ModelFrames:
        """Base and flange frames of this model (:mod:`serialkin.models.frames`)."""
        return FRAMES[self.name]


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


def canonical_name(name: str) -> str | None:
    """The catalog name ``name`` stands for (``Franka-Vendor`` → ``panda_vendor``), or None.

    Case, ``-``/``_`` and aliases are forgiven as in :func:`get`; ``planar<N>`` maps to
    ``planar``.
    """
    key = name.strip().lower().replace("-", "_").replace(" ", "_")
    stem = key.removesuffix(VENDOR_SUFFIX)
    stem = _ALIASES.get(stem, stem)
    if _PLANAR_N.match(stem):
        stem = "planar"
    if stem not in FRAMES:
        return None
    return stem + key[len(key.removesuffix(VENDOR_SUFFIX)):]


def vendor(name: str, **kwargs: Any) -> Robot:
    """Build catalog model ``name`` in the frames of its vendor description.

    The joints, limits and collision capsules are those of ``get(name)``; the base becomes
    ``T_vbase_base`` and the tool ``tool · T_flange_vtip``
    (:class:`~serialkin.models.frames.VendorFrames`), so that ``fk`` gives the pose of the
    vendor's tip link in the vendor's root link, e.g. ``tool0`` in ``base_link`` for the
    UR5. Also reachable as ``get("<name>_vendor")``.

    Raises:
        InputError: ``name`` has no vendor frames that differ (the message lists those
            that do).
    """
    key = name.strip().lower().replace("-", "_").removesuffix(VENDOR_SUFFIX)
    key = _ALIASES.get(key, key)
    info = FRAMES.get(key)
    if info is None or not info.variant or info.vendor is None:
        raise InputError(
            f"no vendor-frame variant of robot model {short_repr(name)}; variants: "
            f"{', '.join(vendor_variants())}")
    robot = get(key, **kwargs)
    v = info.vendor
    out = Robot.from_dh(robot.dh, robot.convention, base=v.T_vbase_base @ robot.base,
                        tool=robot.tool @ v.T_flange_vtip, name=key + VENDOR_SUFFIX,
                        source=f"{robot.source}; in the frames {v.base_link} -> "
                               f"{v.tip_link} of {v.description}")
    return out.with_collision(robot.collision).with_rate_limits(
        robot.velocity_limits, robot.acceleration_limits)


def get(name: str, **kwargs: Any) -> Robot:
    """Build a built-in model by name.

    Names are case-insensitive, ``-`` and ``_`` are interchangeable, and ``planar<N>``
    (e.g. ``planar6``) gives an N-link planar arm (unit links unless ``lengths`` is given);
    ``<name>_vendor`` (:func:`vendor_variants`) gives the model in its vendor's frames.

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
    if key.endswith(VENDOR_SUFFIX) and key != VENDOR_SUFFIX:
        return vendor(key, **kwargs)
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
    choices = list(names()) + list(_ALIASES) + list(vendor_variants())
    close = list(dict.fromkeys(
        _ALIASES.get(c, c) for c in difflib.get_close_matches(key, choices, n=3, cutoff=0.5)
    ))
    hint = f"; did you mean {' or '.join(repr(c) for c in close)}?" if close \
        else ""
    raise InputError(
        f"unknown robot model {short_repr(name)}{hint} Available: {', '.join(names())} "
        f"(and planar<N>, e.g. planar6; in vendor frames: {', '.join(vendor_variants())})"
    )


__all__ = [
    "ModelFrames",
    "ModelInfo",
    "canonical_name",
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
    "vendor",
    "vendor_variants",
]
