"""Denavit–Hartenberg tables (chapter section 3.2), standard and modified (Craig).

Standard DH (the chapter's convention, eqs 13-16)::

    A_i = Rz(θ_i) · Tz(d_i) · Tx(a_i) · Rx(α_i)

Modified DH (Craig): row *i* holds a_{i-1}, α_{i-1}, d_i, θ_i and::

    A_i = Rx(α_{i-1}) · Tx(a_{i-1}) · Rz(θ_i) · Tz(d_i)

For a revolute joint θ_i = q_i + theta (``theta`` is the constant offset); for a
prismatic joint d_i = q_i + d. Lengths in metres, angles in radians.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from serialkin._checks import MAX_JOINT_VALUE, MAX_JOINTS, MAX_LENGTH, short_repr
from serialkin.errors import RobotDefinitionError
from serialkin.model.joint import Joint, definition_real, normalize_joint_type
from serialkin.model.limits import check_interval
from serialkin.spatial.transforms import make_transform, rotx, rotz

CONVENTIONS = ("standard", "modified")
_FIELDS = ("a", "alpha", "d", "theta")


@dataclass(frozen=True)
class DHLink:
    """One row of a DH table.

    Attributes:
        a: link length [m] (a_i standard; a_{i-1} modified).
        alpha: link twist [rad] (α_i standard; α_{i-1} modified).
        d: link offset [m]; the constant part of d_i for a prismatic joint.
        theta: joint angle offset [rad]; the constant θ_i for a prismatic joint.
        type: 'R' revolute or 'P' prismatic.
        qlim: (lower, upper) joint limits [rad or m].
        name: joint name.
    """

    a: float = 0.0
    alpha: float = 0.0
    d: float = 0.0
    theta: float = 0.0
    type: str = "R"
    qlim: tuple[float, float] = (-np.inf, np.inf)
    name: str = ""

    def __post_init__(self) -> None:
        if not isinstance(self.name, str):
            raise RobotDefinitionError(
                f"DH row name must be a string, got {type(self.name).__name__} "
                f"{short_repr(self.name)}"
            )
        where = f"DH row {short_repr(self.name)}" if self.name else "DH row"
        for f in _FIELDS:
            bound, unit = (MAX_LENGTH, "m") if f in ("a", "d") else (MAX_JOINT_VALUE, "rad")
            object.__setattr__(self, f, definition_real(getattr(self, f), where, f"field {f!r}",
                                                        bound, unit))
        object.__setattr__(self, "type", normalize_joint_type(self.type, where))
        object.__setattr__(self, "qlim", check_interval(self.qlim, where))


def link_transform(link: DHLink, q: float, convention: str = "standard") -> np.ndarray:
    """The DH link matrix A_i(q) (eq 12) evaluated directly from the DH formula, (4, 4).

    Used as an independent reference in tests and in the symbolic derivation; the fast
    path is the compiled kernel.
    """
    theta = link.theta + (q if link.type == "R" else 0.0)
    d = link.d + (q if link.type == "P" else 0.0)
    Rz, Rx = make_transform(rotz(theta)), make_transform(rotx(link.alpha))
    Tz, Tx = make_transform(p=[0, 0, d]), make_transform(p=[link.a, 0, 0])
    if convention == "standard":
        return Rz @ Tz @ Tx @ Rx
    return Rx @ Tx @ Rz @ Tz


def parse_dh_rows(links: Sequence[object], where: str = "links") -> list[DHLink]:
    """Turn DHLink objects or mappings {a, alpha, d, theta, type, qlim, name} into DHLinks.

    Raises:
        RobotDefinitionError: a row is not a mapping, misses a field or has an unknown one.
    """
    if isinstance(links, (str, bytes)) or not isinstance(links, Sequence):
        raise RobotDefinitionError(
            f"{where} must be a list of DH rows, got {type(links).__name__} {short_repr(links)}")
    if len(links) == 0:
        raise RobotDefinitionError(f"{where} is empty; a robot needs at least one joint")
    if len(links) > MAX_JOINTS:
        raise RobotDefinitionError(
            f"{where} has {len(links)} rows; a robot has at most {MAX_JOINTS} joints")
    rows: list[DHLink] = []
    for i, row in enumerate(links):
        if isinstance(row, DHLink):
            rows.append(row)
            continue
        if not isinstance(row, Mapping):
            raise RobotDefinitionError(
                f"{where}[{i}] must be a mapping with fields a, alpha, d, theta, got "
                f"{type(row).__name__} {short_repr(row)}"
            )
        unknown = sorted((k for k in row if k not in ROW_KEYS), key=_key_text)
        if unknown:
            raise RobotDefinitionError(
                f"{where}[{i}] has unknown field(s) "
                f"{', '.join(_key_text(k) for k in unknown[:5])}"
                f"; allowed: {', '.join(ROW_KEYS)}"
            )
        missing = [f for f in _FIELDS if f not in row]
        if missing:
            raise RobotDefinitionError(f"{where}[{i}] is missing field(s) {', '.join(missing)}")
        name = row.get("name", f"joint{i + 1}")
        rows.append(
            DHLink(
                a=row["a"],
                alpha=row["alpha"],
                d=row["d"],
                theta=row["theta"],
                type=row_joint_type(row, f"{where}[{i}]"),
                qlim=row.get("qlim", (-np.inf, np.inf)),
                name=name,
            )
        )
    return rows


def _key_text(key: object) -> str:
    """A mapping key for an error message: identifiers as they are, anything else quoted."""
    return key if isinstance(key, str) and key.isidentifier() else short_repr(key, 40)


#: Keys a DH row mapping may have. ``joint`` is an alias of ``type``; ``sigma`` is the
#: Robotics Toolbox's joint flag (0 revolute, 1 prismatic) and is honoured.
ROW_KEYS = ("a", "alpha", "d", "joint", "name", "qlim", "sigma", "theta", "type")


def row_joint_type(row: Mapping[str, Any], where: str) -> str:
    """The joint type of a DH row mapping from ``type``, ``joint`` and/or ``sigma``.

    ``type`` and ``joint`` take 'R'/'P' (or 'revolute'/'prismatic'...), ``sigma`` takes
    0 (revolute) or 1 (prismatic) as in the Robotics Toolbox. Absent: 'R'.

    Raises:
        RobotDefinitionError: an unknown value, or keys that contradict each other
            (e.g. ``type='R', joint='P'``).
    """
    given: dict[str, str] = {}
    for key in ("type", "joint"):
        if key in row:
            given[key] = normalize_joint_type(row[key], f"{where}: field {key!r}")
    if "sigma" in row:
        sigma = row["sigma"]
        if isinstance(sigma, bool) or not isinstance(
                sigma, (int, float, np.integer, np.floating)) or sigma not in (0, 1):
            raise RobotDefinitionError(
                f"{where}: field 'sigma' must be 0 (revolute) or 1 (prismatic), got "
                f"{short_repr(sigma)}"
            )
        given["sigma"] = "P" if sigma == 1 else "R"
    kinds = set(given.values())
    if len(kinds) > 1:
        said = ", ".join(f"{k}={short_repr(row[k], 20)}" for k in given)
        raise RobotDefinitionError(f"{where}: contradictory joint type ({said}); give one")
    return kinds.pop() if kinds else "R"


def dh_to_joints(rows: Sequence[DHLink], convention: str) -> list[Joint]:
    """Express DH rows as general joints ``A = origin · M(q + offset) · post``."""
    joints = []
    for i, r in enumerate(rows):
        name = r.name or f"joint{i + 1}"
        Tz = make_transform(p=[0.0, 0.0, r.d])
        Tx = make_transform(p=[r.a, 0.0, 0.0])
        Rx = make_transform(rotx(r.alpha))
        Rz = make_transform(rotz(r.theta))
        if convention == "standard":
            if r.type == "R":
                origin, post, offset = np.eye(4), Tz @ Tx @ Rx, r.theta
            else:
                origin, post, offset = Rz, Tx @ Rx, r.d
        else:
            if r.type == "R":
                origin, post, offset = Rx @ Tx @ Tz, np.eye(4), r.theta
            else:
                origin, post, offset = Rx @ Tx @ Rz, np.eye(4), r.d
        joints.append(
            Joint(axis=np.array([0.0, 0.0, 1.0]), type=r.type, origin=origin, post=post,
                  offset=offset, qlim=r.qlim, name=name)
        )
    return joints


def standard_to_modified(
    rows: Sequence[DHLink], base: object = None, tool: object = None
) -> tuple[list[DHLink], np.ndarray, np.ndarray]:
    """Rewrite a standard DH table as a modified (Craig) one with the same tool pose.

    The standard product ``Π Rz(θ_i)Tz(d_i)Tx(a_i)Rx(α_i)`` regroups, because Tx(a)
    and Rx(α) commute, as ``Π Rx(α_{i-1})Tx(a_{i-1})Rz(θ_i)Tz(d_i) · Tx(a_n)Rx(α_n)``
    with a_0 = α_0 = 0: modified row i takes (a_{i-1}, α_{i-1}) from standard row i-1
    and keeps (d_i, θ_i, type, qlim, name); the last row's Tx(a_n)Rx(α_n) moves into
    the tool. Intermediate link frames differ (each modified frame i sits at joint
    axis i), the end-effector pose does not.

    Args:
        rows: standard DH rows.
        base: (4, 4) world-from-base transform (kept), default identity.
        tool: (4, 4) tool transform of the standard robot, default identity.

    Returns:
        (modified rows, base (4, 4), tool (4, 4)) for ``Robot.from_dh(rows, "modified",
        base=base, tool=tool)``.
    """
    rows = parse_dh_rows(rows, "rows")
    B = np.eye(4) if base is None else np.asarray(base, dtype=float).copy()
    T = np.eye(4) if tool is None else np.asarray(tool, dtype=float)
    out = []
    prev_a, prev_alpha = 0.0, 0.0
    for r in rows:
        out.append(DHLink(a=prev_a, alpha=prev_alpha, d=r.d, theta=r.theta, type=r.type,
                          qlim=r.qlim, name=r.name))
        prev_a, prev_alpha = r.a, r.alpha
    last = make_transform(rotx(prev_alpha), [prev_a, 0.0, 0.0])
    return out, B, last @ T


def modified_to_standard(
    rows: Sequence[DHLink], base: object = None, tool: object = None
) -> tuple[list[DHLink], np.ndarray, np.ndarray]:
    """Rewrite a modified (Craig) DH table as a standard one with the same tool pose.

    The inverse regrouping of :func:`standard_to_modified`: the first row's
    Rx(α_0)Tx(a_0) moves into the base, standard row i takes (a, α) from modified row
    i+1, and the last standard row has a = α = 0.

    Args:
        rows: modified DH rows.
        base: (4, 4) world-from-base transform of the modified robot, default identity.
        tool: (4, 4) tool transform (kept), default identity.

    Returns:
        (standard rows, base (4, 4), tool (4, 4)).
    """
    rows = parse_dh_rows(rows, "rows")
    B = np.eye(4) if base is None else np.asarray(base, dtype=float)
    T = np.eye(4) if tool is None else np.asarray(tool, dtype=float).copy()
    first = make_transform(rotx(rows[0].alpha), [rows[0].a, 0.0, 0.0])
    out = []
    for i, r in enumerate(rows):
        nxt = rows[i + 1] if i + 1 < len(rows) else None
        out.append(DHLink(a=nxt.a if nxt else 0.0, alpha=nxt.alpha if nxt else 0.0, d=r.d,
                          theta=r.theta, type=r.type, qlim=r.qlim, name=r.name))
    return out, B @ first, T
