"""Base and flange frames of the zoo robots, written against the vendors' descriptions.

A zoo model follows its published DH table, whose base and flange frames need not be the
root and tip links of the vendor's URDF. Every catalog entry states here, in words, where
its base frame (``robot.fk`` is expressed in it) and its flange frame (``robot.fk`` is the
pose of it) sit, and, when a vendor description exists, the two fixed transforms between
them::

    T_vbase_vtip(q) = T_vbase_base · T_base_flange(q) · T_flange_vtip

where ``vbase``/``vtip`` are the vendor's root and tip links, ``T_base_flange(q)`` is
``robot.fk(q)`` of the zoo model, and the joint values ``q`` are the same numbers in both
(same zero, same sign). The transforms are tested against the files of
example-robot-data (``tests/model/test_model_frames.py``).

Where the two differ, both are offered by name: ``ur5`` has the frames of the Universal
Robots DH table (the controller's base frame), ``ur5_vendor`` (also ``ur5-vendor``) the
same arm with the frames of the vendor URDF (``base_link`` to ``tool0``); likewise
``panda`` (flange ``panda_link8``) and ``panda_vendor`` (``panda_link0`` to
``panda_hand_tcp``, the SRDF's end effector).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from serialkin.spatial.transforms import make_transform, trotz

#: Suffix of the variant with the vendor's frames: ``ur5`` → ``ur5_vendor``.
VENDOR_SUFFIX = "_vendor"


def _frozen(T: np.ndarray) -> np.ndarray:
    T = np.array(T, dtype=float)
    T.setflags(write=False)
    return T


@dataclass(frozen=True)
class VendorFrames:
    """How a zoo model's frames sit in a vendor description of the same robot.

    Attributes:
        description: the vendor file and where it is published.
        file: path of the file under example-robot-data's ``robots`` folder (for the test),
            or None when it is not distributed there.
        base_link: the vendor's link the zoo base frame is expressed in (its root).
        tip_link: the vendor's tip link compared with the zoo flange.
        T_vbase_base: (4, 4) pose of the zoo base frame in ``base_link`` [m].
        T_flange_vtip: (4, 4) pose of ``tip_link`` in the zoo flange frame [m].
        note: the transforms in words.
    """

    description: str
    file: str | None
    base_link: str
    tip_link: str
    T_vbase_base: np.ndarray = field(repr=False)
    T_flange_vtip: np.ndarray = field(repr=False)
    note: str

    def __post_init__(self) -> None:  # noqa: D105
        object.__setattr__(self, "T_vbase_base", _frozen(self.T_vbase_base))
        object.__setattr__(self, "T_flange_vtip", _frozen(self.T_flange_vtip))


@dataclass(frozen=True)
class ModelFrames:
    """Where a zoo model's base and flange frames are, and how they relate to the vendor's.

    Attributes:
        base: the base frame in words (origin, axes).
        flange: the flange (tool) frame in words.
        vendor: the relation to the vendor description, or None.
        no_vendor: why there is no vendor comparison (when ``vendor`` is None).
    """

    base: str
    flange: str
    vendor: VendorFrames | None = None
    no_vendor: str = ""

    @property
    def variant(self) -> bool:
        """Whether the vendor frames differ from the model's (a ``*_vendor`` variant exists)."""
        v = self.vendor
        return v is not None and not (np.allclose(v.T_vbase_base, np.eye(4), atol=1e-15)
                                      and np.allclose(v.T_flange_vtip, np.eye(4), atol=1e-15))


_TEXTBOOK = "a textbook mechanism: there is no vendor description"
_UR5_VENDOR = VendorFrames(
    description="ROS-Industrial ur_description ur5_robot.urdf (as in example-robot-data)",
    file="ur_description/urdf/ur5_robot.urdf",
    base_link="base_link", tip_link="tool0",
    T_vbase_base=trotz(math.pi), T_flange_vtip=np.eye(4),
    note="base: Rz(π) (the URDF's base_link is turned half a turn about z from the "
         "controller's base frame, which the URDF calls 'base'); flange: identity (tool0)",
)
_PANDA_VENDOR = VendorFrames(
    description="franka_description panda.urdf with hand (as in example-robot-data); tip "
                "panda_hand_tcp, the end effector of its SRDF",
    file="panda_description/urdf/panda.urdf",
    base_link="panda_link0", tip_link="panda_hand_tcp",
    T_vbase_base=np.eye(4),
    T_flange_vtip=trotz(-math.pi / 4) @ make_transform(p=[0.0, 0.0, 0.1034]),
    note="base: identity (panda_link0); flange = panda_link8; panda_hand = flange · "
         "Rz(-45°); panda_hand_tcp = flange · Rz(-45°) · Tz(0.1034 m)",
)

#: Frames of every catalog entry, by catalog name.
FRAMES: dict[str, ModelFrames] = {
    "planar": ModelFrames(
        base="joint 1 axis along z (out of the plane), x along link 1 at q = 0",
        flange="end of the last link, x along it, z out of the plane",
        no_vendor=_TEXTBOOK),
    "two_link": ModelFrames(
        base="joint 1 axis along z (out of the plane), x along link 1 at q = 0",
        flange="end of link 2, x along it", no_vendor=_TEXTBOOK),
    "three_link": ModelFrames(
        base="joint 1 axis along z (out of the plane), x along link 1 at q = 0",
        flange="end of link 3, x along it", no_vendor=_TEXTBOOK),
    "scara": ModelFrames(
        base="foot of the column on joint 1's axis, z up",
        flange="tip of the quill (frame 4), z pointing down (α3 = π)",
        no_vendor="the chapter's illustrative SCARA: there is no vendor description"),
    "puma560": ModelFrames(
        base="mounting surface, on joint 1's axis, z up (shoulder axis 26.45 in above)",
        flange="frame 6 at the wrist centre (d6 = 0), not the mounting flange: add the "
               "flange offset as a tool",
        no_vendor="Unimation published DH tables, no URDF; the reference is Corke's "
                  "Robotics Toolbox model, with the same frames"),
    "stanford": ModelFrames(
        base="on joint 1's axis at the foot of the column, z up",
        flange="frame 6, 0.263 m along z6 beyond the wrist centre (the flange)",
        no_vendor="a research arm of 1969: no vendor description"),
    "ur5": ModelFrames(
        base="the controller's base frame (the URDF's 'base' link), z up along joint 1; "
             "the URDF's root base_link is turned Rz(π) from it",
        flange="the tool flange, z out of the flange (the URDF's tool0)",
        vendor=_UR5_VENDOR),
    "panda": ModelFrames(
        base="panda_link0, z up along joint 1",
        flange="panda_link8, the flange 0.107 m beyond joint 7, same axes as link 7 (the "
               "hand sits at -45° about z)",
        vendor=_PANDA_VENDOR),
    "iiwa7": ModelFrames(
        base="the mounting base, on joint 1's axis, z up (joint 2 axis 0.340 m above)",
        flange="the media flange, 0.126 m beyond the joint 6 axis, z out of it",
        no_vendor="no KUKA description is installed for the tests (example-robot-data has "
                  "none; MuJoCo Menagerie's is the iiwa 14)"),
}


def frames(name: str) -> ModelFrames:
    """Return the documented frames of catalog model ``name`` (a ``*_vendor`` name too).

    Raises:
        KeyError: ``name`` is not a catalog name.
    """
    return FRAMES[name.removesuffix(VENDOR_SUFFIX)]


def vendor_variants() -> tuple[str, ...]:
    """Names of the ``*_vendor`` variants (models whose vendor frames differ)."""
    return tuple(k + VENDOR_SUFFIX for k, f in FRAMES.items() if f.variant)
