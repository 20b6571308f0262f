"""Robot files: a robot's DH table, limits, base and tool in YAML or JSON (section 3.2).

A robot file states its units once and describes the robot with a standard or modified
Denavit–Hartenberg table (the chapter's eqs 12-16 for ``standard``; Craig's form for
``modified``)::

    name: two-link                 # required
    convention: standard           # standard | modified
    units: {angle: deg, length: m} # required: angle rad|deg, length m|cm|mm
    source: "chapter Figure 5"     # optional, free text
    dh:                            # one row per joint, base to tool
      - {a: 1.0, alpha: 0, d: 0, theta: 0, type: R, qlim: [-170, 170]}
      - {a: 0.6, alpha: 0, d: 0, theta: 0, type: R, qlim: [-170, 170], name: elbow}
    base: {xyz: [0, 0, 0], rpy: [0, 0, 0]}   # optional: xyz + rpy, or a 4x4 matrix
    tool: [[1, 0, 0, 0.1], [0, 1, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1]]

Units apply to every field: ``alpha``, ``theta``, ``rpy`` and the limits of revolute
joints are angles; ``a``, ``d``, ``xyz``, the translation of a 4x4 matrix and the limits
of prismatic joints are lengths. ``qlim`` may be omitted (unlimited joint) or use
``null`` / ``.inf`` for an open side. ``rpy`` = (roll, pitch, yaw) about the fixed x, y,
z axes: ``R = Rz(yaw) · Ry(pitch) · Rx(roll)`` (the URDF convention).

Every error is a :class:`~serialkin.errors.RobotDefinitionError` whose message names the
file, the field (e.g. ``dh[2].alpha``) and what was expected.
"""

from __future__ import annotations

import json
import math
import os
from collections.abc import Mapping
from pathlib import Path
from typing import Any

import numpy as np

from serialkin.errors import RobotDefinitionError
from serialkin.model.dh import CONVENTIONS, DHLink
from serialkin.model.joint import normalize_joint_type
from serialkin.spatial import make_transform, rpy_to_matrix

#: Accepted angle units and their factor to radians.
ANGLE_UNITS: dict[str, float] = {"rad": 1.0, "deg": math.pi / 180.0}
#: Accepted length units and their factor to metres.
LENGTH_UNITS: dict[str, float] = {"m": 1.0, "cm": 0.01, "mm": 0.001}
#: Suffixes read as robot files (``.urdf`` is read by :mod:`serialkin.model.urdf`).
ROBOT_FILE_SUFFIXES = (".yaml", ".yml", ".json")

_TOP_FIELDS = ("name", "convention", "units", "source", "dh", "base", "tool")
_ROW_FIELDS = ("a", "alpha", "d", "theta", "type", "qlim", "name")


class _Where:
    """Formats error messages that name the file and the field."""

    def __init__(self, origin: str) -> None:
        self.origin = origin

    def error(self, field: str, expected: str, got: object = None, *, show_got: bool = True
              ) -> RobotDefinitionError:
        tail = f", got {got!r}" if show_got else ""
        return RobotDefinitionError(f"{self.origin}: field '{field}': expected {expected}{tail}")


def _number(value: object, field: str, where: _Where, unit: str) -> float:
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        raise where.error(field, f"a number [{unit}]", value)
    v = float(value)
    if not math.isfinite(v):
        raise where.error(field, f"a finite number [{unit}]", value)
    return v


def _vector(value: object, field: str, where: _Where, size: int, unit: str) -> np.ndarray:
    if not isinstance(value, (list, tuple)) or len(value) != size:
        raise where.error(field, f"a list of {size} numbers [{unit}]", value)
    return np.array([_number(v, f"{field}[{i}]", where, unit) for i, v in enumerate(value)])


def _transform(value: object, field: str, where: _Where, ang: float, lin: float,
               angle_unit: str, length_unit: str) -> np.ndarray:
    """Parse ``{xyz, rpy}`` (either optional) or a 4x4 nested list into a rigid transform."""
    if isinstance(value, Mapping):
        unknown = sorted(set(value) - {"xyz", "rpy"})
        if unknown:
            raise where.error(field, "a mapping with keys 'xyz' and/or 'rpy', or a 4x4 matrix",
                              f"unknown key(s) {', '.join(map(str, unknown))}", show_got=True)
        xyz = (_vector(value["xyz"], f"{field}.xyz", where, 3, length_unit) * lin
               if "xyz" in value else np.zeros(3))
        rpy = (_vector(value["rpy"], f"{field}.rpy", where, 3, angle_unit) * ang
               if "rpy" in value else np.zeros(3))
        return make_transform(rpy_to_matrix(rpy), xyz)
    if isinstance(value, (list, tuple)) and len(value) == 4:
        rows = [_vector(r, f"{field}[{i}]", where, 4, "matrix row") for i, r in enumerate(value)]
        T = np.array(rows)
        T[:3, 3] *= lin
        if np.abs(T[3] - [0, 0, 0, 1]).max() > 1e-9:
            raise where.error(field, "a homogeneous transform whose last row is [0, 0, 0, 1]",
                              T[3].tolist())
        R = T[:3, :3]
        err = float(np.abs(R.T @ R - np.eye(3)).max())
        if err > 1e-6 or np.linalg.det(R) < 0:
            raise where.error(field, "a rotation block that is orthonormal with det +1 "
                              f"(max |RᵀR − I| = {err:.3g}, det = {np.linalg.det(R):.4g})",
                              show_got=False)
        return T
    raise where.error(field, "{xyz: [x, y, z], rpy: [roll, pitch, yaw]} or a 4x4 matrix", value)


def _limits(value: object, field: str, where: _Where, factor: float, unit: str
            ) -> tuple[float, float]:
    if not isinstance(value, (list, tuple)) or len(value) != 2:
        raise where.error(field, f"a pair [lower, upper] [{unit}] (null or .inf for none)", value)
    out = []
    for i, (v, default) in enumerate(zip(value, (-math.inf, math.inf))):
        if v is None:
            out.append(default)
            continue
        if isinstance(v, bool) or not isinstance(v, (int, float)) or math.isnan(v):
            raise where.error(f"{field}[{i}]", f"a number [{unit}] or null", v)
        out.append(float(v) * factor if math.isfinite(v) else float(v))
    if out[0] > out[1]:
        raise where.error(field, "lower <= upper", list(value))
    return out[0], out[1]


def robot_from_dict(data: object, origin: str = "<robot description>") -> Any:
    """Build a :class:`~serialkin.Robot` from a parsed robot-file mapping (see module doc).

    Args:
        data: the mapping read from a YAML/JSON robot file.
        origin: what to call the description in errors (the file path).

    Returns:
        The robot, with lengths in metres and angles in radians.

    Raises:
        RobotDefinitionError: a missing, unknown or malformed field; the message names
            ``origin``, the field and what was expected.
    """
    from serialkin.model.robot import Robot

    where = _Where(origin)
    if not isinstance(data, Mapping):
        raise RobotDefinitionError(
            f"{origin}: expected a mapping with fields {', '.join(_TOP_FIELDS)}, "
            f"got {type(data).__name__}"
        )
    unknown = sorted(set(map(str, data)) - set(_TOP_FIELDS))
    if unknown:
        raise RobotDefinitionError(
            f"{origin}: unknown field(s) {', '.join(repr(u) for u in unknown)}; "
            f"allowed: {', '.join(_TOP_FIELDS)}"
        )
    for req in ("name", "units", "dh"):
        if req not in data:
            hint = {"units": " (e.g. units: {angle: deg, length: m})",
                    "dh": " (a list of rows {a, alpha, d, theta, type, qlim})",
                    "name": " (a string)"}[req]
            raise RobotDefinitionError(f"{origin}: missing required field '{req}'{hint}")
    name = data["name"]
    if not isinstance(name, str) or not name.strip():
        raise where.error("name", "a non-empty string", name)
    convention = data.get("convention", "standard")
    if convention not in CONVENTIONS:
        raise where.error("convention", " or ".join(repr(c) for c in CONVENTIONS), convention)
    source = data.get("source", "")
    if not isinstance(source, str):
        raise where.error("source", "a string", source)

    units = data["units"]
    if not isinstance(units, Mapping):
        raise where.error("units", "a mapping {angle: rad|deg, length: m|cm|mm}", units)
    bad = sorted(set(map(str, units)) - {"angle", "length"})
    if bad:
        raise where.error("units", "only the keys 'angle' and 'length'", f"key(s) {bad}")
    if "angle" not in units:
        raise where.error("units.angle", "'rad' or 'deg' (the angle unit must be stated)",
                          show_got=False)
    angle_unit = units["angle"]
    if angle_unit not in ANGLE_UNITS:
        raise where.error("units.angle", "'rad' or 'deg'", angle_unit)
    length_unit = units.get("length", "m")
    if length_unit not in LENGTH_UNITS:
        raise where.error("units.length", "'m', 'cm' or 'mm'", length_unit)
    ang, lin = ANGLE_UNITS[angle_unit], LENGTH_UNITS[length_unit]

    rows_in = data["dh"]
    if not isinstance(rows_in, list) or not rows_in:
        raise where.error("dh", "a non-empty list of rows {a, alpha, d, theta, type, qlim}",
                          rows_in)
    rows: list[DHLink] = []
    for i, row in enumerate(rows_in):
        f = f"dh[{i}]"
        if not isinstance(row, Mapping):
            raise where.error(f, "a mapping {a, alpha, d, theta, type, qlim}", row)
        extra = sorted(set(map(str, row)) - set(_ROW_FIELDS))
        if extra:
            raise where.error(f, f"only the fields {', '.join(_ROW_FIELDS)}",
                              f"unknown field(s) {', '.join(extra)}")
        for req in ("a", "alpha", "d", "theta"):
            if req not in row:
                raise where.error(f"{f}.{req}", "a number (a, alpha, d and theta are required)",
                                  show_got=False)
        try:
            jtype = normalize_joint_type(row.get("type", "R"), f"{origin}: field '{f}.type'")
        except RobotDefinitionError as exc:
            raise where.error(f"{f}.type", "'R' (revolute) or 'P' (prismatic)",
                              row.get("type")) from exc
        a = _number(row["a"], f"{f}.a", where, length_unit) * lin
        d = _number(row["d"], f"{f}.d", where, length_unit) * lin
        alpha = _number(row["alpha"], f"{f}.alpha", where, angle_unit) * ang
        theta = _number(row["theta"], f"{f}.theta", where, angle_unit) * ang
        qunit, qfac = (angle_unit, ang) if jtype == "R" else (length_unit, lin)
        qlim = (_limits(row["qlim"], f"{f}.qlim", where, qfac, qunit)
                if row.get("qlim") is not None else (-math.inf, math.inf))
        jname = row.get("name", f"joint{i + 1}")
        if not isinstance(jname, str) or not jname:
            raise where.error(f"{f}.name", "a non-empty string", jname)
        rows.append(DHLink(a=a, alpha=alpha, d=d, theta=theta, type=jtype, qlim=qlim,
                           name=jname))
    names = [r.name for r in rows]
    dup = sorted({x for x in names if names.count(x) > 1})
    if dup:
        raise where.error("dh[*].name", "unique joint names", f"duplicates {dup}")

    base = tool = None
    if data.get("base") is not None:
        base = _transform(data["base"], "base", where, ang, lin, angle_unit, length_unit)
    if data.get("tool") is not None:
        tool = _transform(data["tool"], "tool", where, ang, lin, angle_unit, length_unit)
    try:
        return Robot.from_dh(rows, convention, base=base, tool=tool, name=name.strip(),
                             source=source)
    except RobotDefinitionError as exc:  # pragma: no cover - fields are validated above
        raise RobotDefinitionError(f"{origin}: {exc}") from exc


def read_robot_data(path: str | os.PathLike[str]) -> object:
    """Parse a robot file (YAML or JSON by suffix) into Python data, naming the file on error."""
    p = Path(path)
    if p.suffix.lower() not in ROBOT_FILE_SUFFIXES:
        raise RobotDefinitionError(
            f"{p}: unknown robot file type {p.suffix!r}; expected one of "
            f"{', '.join(ROBOT_FILE_SUFFIXES)} (or .urdf)"
        )
    try:
        text = p.read_text(encoding="utf-8")
    except FileNotFoundError as exc:
        raise RobotDefinitionError(f"{p}: robot file not found") from exc
    except (OSError, UnicodeDecodeError) as exc:
        raise RobotDefinitionError(f"{p}: cannot read the robot file ({exc})") from exc
    if p.suffix.lower() == ".json":
        try:
            return json.loads(text)
        except json.JSONDecodeError as exc:
            raise RobotDefinitionError(
                f"{p}: invalid JSON at line {exc.lineno}, column {exc.colno}: {exc.msg}"
            ) from exc
    import yaml

    try:
        return yaml.safe_load(text)
    except yaml.YAMLError as exc:
        mark = getattr(exc, "problem_mark", None)
        at = f" at line {mark.line + 1}, column {mark.column + 1}" if mark is not None else ""
        problem = getattr(exc, "problem", None) or str(exc)
        raise RobotDefinitionError(f"{p}: invalid YAML{at}: {problem}") from exc


def load_robot_file(path: str | os.PathLike[str]) -> Any:
    """Read a robot file (``.yaml``, ``.yml`` or ``.json``) and build the robot.

    Args:
        path: the file.

    Returns:
        :class:`~serialkin.Robot` (lengths in m, angles in rad).

    Raises:
        RobotDefinitionError: unreadable file, syntax error (with line number) or a
            malformed field (named, with what was expected).
    """
    return robot_from_dict(read_robot_data(path), origin=str(path))


def robot_to_dict(robot: Any, angle_unit: str = "deg", length_unit: str = "m") -> dict[str, Any]:
    """The robot-file mapping of a DH robot in the given units (inverse of robot_from_dict).

    Base and tool are written as ``{xyz, rpy}`` in the file's units (rpy from
    :func:`serialkin.spatial.matrix_to_rpy`, 12 significant decimals) and omitted when
    they are the identity.

    Raises:
        RobotDefinitionError: the robot has no DH table (e.g. it came from a URDF).
        InputError: unknown unit.
    """
    from serialkin._checks import check_choice

    check_choice(angle_unit, "angle_unit", ANGLE_UNITS)
    check_choice(length_unit, "length_unit", LENGTH_UNITS)
    if robot.dh is None:
        raise RobotDefinitionError(
            f"robot {robot.name!r} has no DH table; a robot file needs one "
            "(save a URDF with robot.to_urdf() instead)"
        )
    ang, lin = ANGLE_UNITS[angle_unit], LENGTH_UNITS[length_unit]

    def num(x: float) -> float | None:
        return None if not math.isfinite(x) else float(round(x, 12)) + 0.0  # no -0.0

    rows = []
    for r in robot.dh:
        fac = ang if r.type == "R" else lin
        row: dict[str, Any] = {"a": num(r.a / lin), "alpha": num(r.alpha / ang),
                               "d": num(r.d / lin), "theta": num(r.theta / ang), "type": r.type}
        if np.isfinite(r.qlim).any():
            row["qlim"] = [num(r.qlim[0] / fac), num(r.qlim[1] / fac)]
        row["name"] = r.name
        rows.append(row)
    out: dict[str, Any] = {"name": robot.name, "convention": robot.convention,
                           "units": {"angle": angle_unit, "length": length_unit}}
    if robot.source:
        out["source"] = robot.source
    out["dh"] = rows
    from serialkin.spatial import matrix_to_rpy

    for key in ("base", "tool"):
        T = np.array(getattr(robot, key), dtype=float)
        if not np.allclose(T, np.eye(4), atol=1e-15):
            rpy = matrix_to_rpy(T[:3, :3], check=False) / ang
            out[key] = {"xyz": [num(v / lin) for v in T[:3, 3]], "rpy": [num(v) for v in rpy]}
    return out


def save_robot_file(robot: Any, path: str | os.PathLike[str], *, angle_unit: str = "deg",
                    length_unit: str = "m") -> Path:
    """Write a DH robot to a robot file (YAML or JSON by suffix), atomically.

    The file is written to a temporary file in the same folder and renamed, so an
    interrupted save never leaves a truncated file. ``load_robot_file`` of the result
    gives the same kinematics.

    Returns:
        The path written.
    """
    from serialkin._io import write_text_atomic

    p = Path(path)
    if p.suffix.lower() not in ROBOT_FILE_SUFFIXES:
        raise RobotDefinitionError(
            f"{p}: unknown robot file type {p.suffix!r}; expected one of "
            f"{', '.join(ROBOT_FILE_SUFFIXES)}"
        )
    data = robot_to_dict(robot, angle_unit=angle_unit, length_unit=length_unit)
    if p.suffix.lower() == ".json":
        text = json.dumps(data, indent=2) + "\n"
    else:
        import yaml

        text = f"# serialkin robot file: {robot.name}\n" + yaml.safe_dump(
            data, sort_keys=False, default_flow_style=None)
    write_text_atomic(p, text)
    return p
