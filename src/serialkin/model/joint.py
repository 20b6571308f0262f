"""One joint of a serial chain in the general form every convention compiles to.

A joint contributes the link transform ``A_i(q) = P_i · M_i(q_i + offset_i) · Q_i``
where ``P_i`` (``origin``) and ``Q_i`` (``post``) are fixed rigid transforms and ``M_i``
rotates about (revolute) or translates along (prismatic) the unit ``axis`` expressed in
the frame reached by ``P_i``. Standard DH puts the constant part in ``post``
(A = Rz(θ)·Tz(d)·Tx(a)·Rx(α)), modified DH and URDF put it in ``origin``.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from serialkin._checks import (
    MAX_JOINT_VALUE,
    MAX_LENGTH,
    as_vector,
    check_real,
    check_transform,
    short_repr,
)
from serialkin.errors import InputError, InputTypeError, RobotDefinitionError
from serialkin.model.limits import check_interval

JOINT_TYPES = {"R": 0, "P": 1}
_TYPE_ALIASES = {
    "r": "R",
    "revolute": "R",
    "continuous": "R",
    "rot": "R",
    "p": "P",
    "prismatic": "P",
    "slide": "P",
    "linear": "P",
}


def normalize_joint_type(value: object, where: str) -> str:
    """Map 'R'/'revolute'/'continuous' to 'R' and 'P'/'prismatic' to 'P', or raise."""
    key = str(value).strip().lower() if isinstance(value, str) else None
    if key not in _TYPE_ALIASES:
        raise RobotDefinitionError(
            f"{where}: unknown joint type {short_repr(value)}; expected 'R' (revolute) or 'P' "
            "(prismatic)"
        )
    return _TYPE_ALIASES[key]


def definition_real(value: object, where: str, field: str, max_abs: float, unit: str) -> float:
    """A finite real number of a robot description with ``|value| <= max_abs``.

    Raises:
        RobotDefinitionError: not a real number, NaN/inf, or too large (naming ``where``
            and ``field``).
    """
    try:
        return check_real(value, f"{where}: {field}", max_abs=max_abs, unit=unit)
    except (InputError, InputTypeError) as exc:
        raise RobotDefinitionError(str(exc)) from None


def check_fixed_transform(T: object, where: str) -> np.ndarray:
    """A copy of the rigid transform ``T`` (4, 4) of a robot description.

    Its translation must be at most :data:`~serialkin._checks.MAX_LENGTH` metres long.
    """
    a = check_transform(T, where).copy()
    length = float(np.linalg.norm(a[:3, 3]))
    if length > MAX_LENGTH:
        raise RobotDefinitionError(
            f"{where}: translation of {length:g} m exceeds the {MAX_LENGTH:g} m bound on "
            "lengths in a robot description"
        )
    return a


@dataclass(frozen=True)
class Joint:
    """A joint in general form: ``A(q) = origin · M(q + offset) · post``.

    Attributes:
        axis: unit joint axis (3,) in the frame reached by ``origin``.
        type: 'R' revolute (q in rad) or 'P' prismatic (q in m).
        origin: fixed transform (4, 4) before the motion.
        post: fixed transform (4, 4) after the motion.
        offset: constant added to the joint variable [rad or m].
        qlim: (lower, upper) limits on q [rad or m]; ±inf for none.
        name: joint name.
    """

    axis: np.ndarray = field(default_factory=lambda: np.array([0.0, 0.0, 1.0]))
    type: str = "R"
    origin: np.ndarray = field(default_factory=lambda: np.eye(4))
    post: np.ndarray = field(default_factory=lambda: np.eye(4))
    offset: float = 0.0
    qlim: tuple[float, float] = (-np.inf, np.inf)
    name: str = ""

    def __post_init__(self) -> None:
        if not isinstance(self.name, str):
            raise RobotDefinitionError(
                f"joint name must be a string, got {type(self.name).__name__} "
                f"{short_repr(self.name)}"
            )
        where = f"joint {short_repr(self.name)}" if self.name else "joint"
        jt = normalize_joint_type(self.type, where)
        try:
            axis = as_vector(self.axis, f"{where} axis", 3)
            origin = check_fixed_transform(self.origin, f"{where} origin")
            post = check_fixed_transform(self.post, f"{where} post")
        except (InputError, InputTypeError) as exc:
            if isinstance(exc, RobotDefinitionError):
                raise
            raise RobotDefinitionError(str(exc)) from None
        norm = float(np.linalg.norm(axis))
        if norm < 1e-12:
            raise RobotDefinitionError(
                f"{where}: the joint axis is zero; expected a nonzero 3-vector"
            )
        object.__setattr__(self, "type", jt)
        object.__setattr__(self, "axis", axis / norm)
        object.__setattr__(self, "origin", origin)
        object.__setattr__(self, "post", post)
        object.__setattr__(self, "offset", definition_real(
            self.offset, where, "offset", MAX_JOINT_VALUE, "rad or m"))
        object.__setattr__(self, "qlim", check_interval(self.qlim, where))
