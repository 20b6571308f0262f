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

from serialkin._checks import as_vector, check_transform
from serialkin.errors import RobotDefinitionError

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
            f"{where}: unknown joint type {value!r}; expected 'R' (revolute) or 'P' (prismatic)"
        )
    return _TYPE_ALIASES[key]


def check_limits(qlim: object, where: str) -> tuple[float, float]:
    """Validate a (lower, upper) joint limit pair; infinities allowed, lower <= upper."""
    try:
        lo, hi = (float(v) for v in qlim)  # type: ignore[union-attr]
    except (TypeError, ValueError) as exc:
        raise RobotDefinitionError(
            f"{where}: joint limits must be a pair (lower, upper), got {qlim!r}"
        ) from exc
    if np.isnan(lo) or np.isnan(hi):
        raise RobotDefinitionError(f"{where}: joint limits must not be NaN, got {qlim!r}")
    if lo > hi:
        raise RobotDefinitionError(
            f"{where}: joint limit lower {lo:g} is greater than upper {hi:g}"
        )
    return lo, hi


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
        where = f"joint {self.name!r}" if self.name else "joint"
        jt = normalize_joint_type(self.type, where)
        axis = as_vector(self.axis, f"{where} axis", 3)
        norm = float(np.linalg.norm(axis))
        if norm < 1e-12:
            raise RobotDefinitionError(
                f"{where}: the joint axis is zero; expected a nonzero 3-vector"
            )
        object.__setattr__(self, "type", jt)
        object.__setattr__(self, "axis", axis / norm)
        object.__setattr__(self, "origin", check_transform(self.origin, f"{where} origin").copy())
        object.__setattr__(self, "post", check_transform(self.post, f"{where} post").copy())
        if not np.isfinite(self.offset):
            raise RobotDefinitionError(f"{where}: offset must be finite, got {self.offset!r}")
        object.__setattr__(self, "offset", float(self.offset))
        object.__setattr__(self, "qlim", check_limits(self.qlim, where))

    @property
    def is_revolute(self) -> bool:
        """True for a revolute joint."""
        return self.type == "R"
