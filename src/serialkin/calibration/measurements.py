"""Calibration measurements: configurations with measured tool poses or positions.

A measurement is a configuration ``q`` (n,) and what an external instrument saw of the
tool in the world (instrument) frame:

* ``'pose'`` — the full pose: position p (3,) [m] and rotation R (3, 3);
* ``'position'`` — the position p (3,) [m] of a point on the tool (laser tracker, a
  marker). The point is the tool frame's origin; when its offset on the last link is
  unknown the tool translation of the error model is identified with it (the default);
  when it is known, put it in the robot's tool and leave the tool out of the model.

Each measurement has a residual ``e = [p_model − p; log(R_model · Rᵀ)^∨]`` (positions:
the first three rows) whitened by its covariance ``C = L·Lᵀ`` (rows ``L⁻¹ e``), so that
the least-squares cost is ``½ Σ eᵀ C⁻¹ e``. Without covariances, C is diagonal with
``sigma_position²`` [m²] and ``sigma_rotation²`` [rad²], divided by the measurement's
weight.

Several markers on the tool (a position set): ``markers`` (m,) says which marker
(0-based; marker 0 is the tool origin) each row measured; the error model has their
offsets (``error_model(..., markers=K)``).

CSV files (:func:`read_measurements`, :func:`write_measurements`) have a header line
naming the columns ``q1 … qn, x, y, z`` [rad or m; m] and, for poses, the scalar-first
unit quaternion ``quat_w, quat_x, quat_y, quat_z``; an optional ``marker`` column (the
marker number, 1..K) and an optional ``weight`` column last.
``#`` comments and blank lines are skipped; a bad row is reported by its line number.
"""

from __future__ import annotations

import math
import os
import re
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from serialkin._checks import (
    as_float_array,
    beyond_a_turn,
    check_choice,
    check_positive,
    short_repr,
)
from serialkin.errors import InputError
from serialkin.model.robot import Robot

#: Measurement kinds and their residual rows.
KINDS = {"position": 3, "pose": 6}
#: Default standard deviation of a measured coordinate [m].
SIGMA_POSITION = 1e-4
#: Default standard deviation of a measured rotation about each axis [rad].
SIGMA_ROTATION = 1e-3
_QUAT = ("quat_w", "quat_x", "quat_y", "quat_z")
#: Largest measurement file read [bytes].
MAX_MEASUREMENT_BYTES = 64 * 1024 * 1024  # about 500,000 rows of a 7-joint arm


@dataclass(frozen=True, eq=False)
class Measurements:
    """Measured tool positions or poses at known configurations (see the module docstring).

    Attributes:
        kind: 'position' or 'pose'.
        q: (m, n) configurations [rad or m].
        positions: (m, 3) measured tool positions in the world frame [m].
        rotations: (m, 3, 3) measured tool rotations, or None for positions.
        whitening: (m, k, k) ``L⁻¹`` per measurement (k = 3 or 6), ``C = L·Lᵀ``.
        lines: (m,) source line of each measurement (0 when not read from a file).
        source: where the measurements come from (a file name), for messages.
        markers: (m,) 0-based index of the marker each row measured (all 0: one marker).
    """

    kind: str
    q: np.ndarray
    positions: np.ndarray
    rotations: np.ndarray | None
    whitening: np.ndarray
    lines: np.ndarray
    source: str = ""
    markers: np.ndarray = None  # type: ignore[assignment]

    def __post_init__(self) -> None:
        if self.markers is None:
            z = np.zeros(self.q.shape[0], dtype=int)
            z.setflags(write=False)
            object.__setattr__(self, "markers", z)

    def __len__(self) -> int:
        """Number of measurements m."""
        return self.q.shape[0]

    @property
    def rows(self) -> int:
        """Residual rows per measurement k: 3 (position) or 6 (pose)."""
        return KINDS[self.kind]

    def subset(self, index: object) -> Measurements:
        """The measurements at ``index`` (an integer array or a boolean mask)."""
        i = np.asarray(index)
        return Measurements(self.kind, self.q[i], self.positions[i],
                            None if self.rotations is None else self.rotations[i],
                            self.whitening[i], self.lines[i], self.source, self.markers[i])

    def poses(self) -> np.ndarray:
        """(m, 4, 4) measured poses (rotation identity for positions)."""
        T = np.tile(np.eye(4), (len(self), 1, 1))
        T[:, :3, 3] = self.positions
        if self.rotations is not None:
            T[:, :3, :3] = self.rotations
        return T

    def where(self, i: int) -> str:
        """'measurement i (file, line l)' for messages."""
        line = int(self.lines[i])
        at = f" ({self.source}, line {line})" if line else ""
        return f"measurement {i}{at}"


def make_measurements(robot: Robot, q: object, *, positions: object = None,
                      poses: object = None, weights: object = None,
                      sigma_position: float = SIGMA_POSITION,
                      sigma_rotation: float = SIGMA_ROTATION, covariance: object = None,
                      lines: object = None, source: str = "",
                      markers: object = None) -> Measurements:
    """Validated :class:`Measurements` from arrays.

    Args:
        robot: the robot measured (its joint count is checked).
        q: (m, n) configurations.
        positions: (m, 3) measured positions [m] (a 'position' set), or None.
        poses: (m, 4, 4) measured poses (a 'pose' set), or None. Exactly one of
            positions and poses.
        weights: (m,) positive weights (default 1), dividing the covariance.
        sigma_position: standard deviation of a coordinate [m].
        sigma_rotation: standard deviation of a rotation angle [rad] (poses).
        covariance: (m, k, k) or (k, k) symmetric positive definite covariances instead
            of the sigmas (k = 3 positions, 6 poses: [position; rotation]).
        lines: (m,) source line numbers (for messages), default 0.
        source: the file name (for messages).
        markers: (m,) 0-based marker index of each row (default all 0: one marker).

    Raises:
        InputError: wrong joint count, shapes that disagree, non-finite values (naming the
            measurement), non-rotations, non-positive weights or sigmas, a covariance that
            is not symmetric positive definite.
    """
    from serialkin._checks import check_transform

    if (positions is None) == (poses is None):
        raise InputError("give exactly one of positions (m, 3) and poses (m, 4, 4)")
    kind = "position" if positions is not None else "pose"
    qa = as_float_array(q, "q", ndim=2)
    if qa.shape[1] != robot.n:
        raise InputError(f"q has {qa.shape[1]} joint values per measurement but robot "
                         f"{robot.name!r} has {robot.n} joints (expected shape (m, {robot.n}), "
                         f"got {qa.shape})")
    m = qa.shape[0]
    ln = np.zeros(m, dtype=int) if lines is None else np.asarray(lines, dtype=int)
    rot = None
    if kind == "position":
        pos = as_float_array(positions, "positions", ndim=2)
        if pos.shape != (m, 3):
            raise InputError(f"positions must have shape ({m}, 3) like q, got {pos.shape}")
    else:
        T = as_float_array(poses, "poses", ndim=3)
        if T.shape != (m, 4, 4):
            raise InputError(f"poses must have shape ({m}, 4, 4) like q, got {T.shape}")
        T = check_transform(T, "poses")
        pos, rot = T[:, :3, 3].copy(), T[:, :3, :3].copy()
    k = KINDS[kind]
    if covariance is not None:
        L = _covariance_factor(covariance, m, k)
    else:
        sp = check_positive(sigma_position, "sigma_position")
        sr = check_positive(sigma_rotation, "sigma_rotation")
        L = np.broadcast_to(np.diag([sp] * 3 + [sr] * 3)[:k, :k], (m, k, k))
    if weights is not None:
        L = L / np.sqrt(_checked_weights(weights, m))[:, None, None]
    W = np.linalg.inv(L)
    mk = np.zeros(m, dtype=int) if markers is None else _checked_markers(markers, m)
    out = Measurements(kind, qa.copy(), np.ascontiguousarray(pos), rot, np.ascontiguousarray(W),
                       ln, source, mk)
    for a in (out.q, out.positions, out.whitening, out.lines, out.markers):
        a.setflags(write=False)
    return out


def _covariance_factor(covariance: object, m: int, k: int) -> np.ndarray:
    """The Cholesky factors L (m, k, k) of ``covariance`` (k, k) or (m, k, k), ``C = L·Lᵀ``.

    Raises InputError for another shape or a covariance that is not symmetric positive
    definite.
    """
    C = as_float_array(covariance, "covariance")
    if C.shape == (k, k):
        C = np.broadcast_to(C, (m, k, k))
    if C.shape != (m, k, k):
        raise InputError(f"covariance must have shape ({k}, {k}) or ({m}, {k}, {k}), "
                         f"got {C.shape}")
    if not np.allclose(C, np.swapaxes(C, -1, -2), rtol=1e-9, atol=0.0):
        raise InputError("covariance must be symmetric")
    try:
        return np.linalg.cholesky(C)
    except np.linalg.LinAlgError:
        raise InputError("covariance must be positive definite") from None


def _checked_markers(markers: object, m: int) -> np.ndarray:
    """``markers`` as (m,) non-negative ints; InputError naming the first bad one."""
    a = as_float_array(markers, "markers", ndim=1)
    if a.shape != (m,):
        raise InputError(f"markers must have shape ({m},) like q, got {a.shape}")
    bad = ~np.isfinite(a) | (a < 0) | (a != np.round(a))
    if bad.any():
        i = int(np.argmax(bad))
        raise InputError(f"markers must be integers >= 0 (0-based marker indices), got "
                         f"{a[i]!r} for measurement {i}")
    return a.astype(int)


def _checked_weights(weights: object, m: int) -> np.ndarray:
    """``weights`` as (m,) finite positive floats; InputError naming the first bad one."""
    w = as_float_array(weights, "weights", ndim=1)
    if w.shape != (m,):
        raise InputError(f"weights must have shape ({m},) like q, got {w.shape}")
    if not (np.isfinite(w).all() and (w > 0).all()):
        i = int(np.argmax(~(np.isfinite(w) & (w > 0))))
        raise InputError(f"weights must be finite and > 0, got {w[i]!r} for measurement {i}")
    return w


def read_measurements(path: str | os.PathLike[str], robot: Robot, *,
                      sigma_position: float = SIGMA_POSITION,
                      sigma_rotation: float = SIGMA_ROTATION) -> Measurements:
    """Read a measurement CSV file (see the module docstring for its columns).

    Args:
        path: the file.
        robot: the robot measured; the file must have one ``q`` column per joint.
        sigma_position: standard deviation of a coordinate [m].
        sigma_rotation: standard deviation of a rotation angle [rad].

    Raises:
        InputError: unreadable file, no header, missing or unknown columns, a joint count
            that is not the robot's, a row with a wrong number of cells, a cell that is
            not a number or not finite (named by its line), a quaternion that is not unit.
    """
    from serialkin._files import read_text

    label = str(path)
    text = read_text(path, what="measurement file", error=InputError,
                     max_bytes=MAX_MEASUREMENT_BYTES)
    header, rows, lines = _read_table(text, robot, label)
    a = np.array(rows)
    col = {h: i for i, h in enumerate(header)}
    q = a[:, [col[f"q{i + 1}"] for i in range(robot.n)]]
    _check_radians(q, robot, label, lines)
    pos = a[:, [col["x"], col["y"], col["z"]]]
    w = a[:, col["weight"]] if "weight" in col else None
    if w is not None and not (w > 0).all():
        i = int(np.argmax(w <= 0))
        raise InputError(f"{label}, line {lines[i]}: weight must be > 0, got {w[i]!r}")
    mk = None
    if "marker" in col:
        mk = a[:, col["marker"]]
        bad = (mk < 1) | (mk != np.round(mk))
        if bad.any():
            i = int(np.argmax(bad))
            raise InputError(f"{label}, line {lines[i]}, column 'marker': expected a marker "
                             f"number 1, 2, ..., got {mk[i]!r}")
        mk = mk - 1
    common = dict(weights=w, sigma_position=sigma_position, sigma_rotation=sigma_rotation,
                  lines=lines, source=label, markers=mk)
    if "quat_w" not in col:
        return make_measurements(robot, q, positions=pos, **common)
    T = _poses(a[:, [col[c] for c in _QUAT]], pos, label, lines)
    return make_measurements(robot, q, poses=T, **common)


def _read_table(text: str, robot: Robot,
                label: str) -> tuple[list[str], list[list[float]], list[int]]:
    """The header (lower case), the rows of numbers and their line numbers of a CSV text.

    ``#`` comments and blank lines are skipped; the header is checked against ``robot``
    (:func:`_check_header`), every row has one finite number per column. ``label`` names
    the file in messages; raises InputError naming the line (and column) at fault.
    """
    header: list[str] | None = None
    rows: list[list[float]] = []
    lines: list[int] = []
    for lineno, line in enumerate(text.splitlines(), start=1):
        s = line.strip()
        if not s or s.startswith("#"):
            continue
        cells = [c.strip() for c in s.split(",")]
        if header is None:
            header = [c.lower() for c in cells]
            _check_header(header, robot, label, lineno)
            continue
        if len(cells) != len(header):
            raise InputError(f"{label}, line {lineno}: {len(cells)} values but the header "
                             f"names {len(header)} columns")
        rows.append([_number(c, name, label, lineno) for name, c in zip(header, cells)])
        lines.append(lineno)
    if header is None or not rows:
        raise InputError(f"{label}: no measurements found (expected a header line and rows)")
    return header, rows, lines


def _number(cell: str, name: str, label: str, lineno: int) -> float:
    """The finite float in ``cell`` (column ``name`` of line ``lineno``); else InputError."""
    try:
        v = float(cell)
    except ValueError:
        raise InputError(f"{label}, line {lineno}, column {name!r}: "
                         f"{short_repr(cell, 40)} is not a number") from None
    if not math.isfinite(v):
        raise InputError(f"{label}, line {lineno}, column {name!r}: values must be "
                         f"finite, got {short_repr(cell, 40)}")
    return v


def _check_radians(q: np.ndarray, robot: Robot, label: str, lines: list[int]) -> None:
    """Refuse a revolute joint value (q (m, n) [rad]) beyond a full turn: degrees read as rad."""
    revolute = robot.revolute
    wild = beyond_a_turn(q[:, revolute])
    if wild.any():  # radians are read: 90 means 90 rad, fourteen turns
        i, j = np.argwhere(wild)[0]
        joint = int(np.flatnonzero(revolute)[j])
        raise InputError(f"{label}, line {lines[i]}, column 'q{joint + 1}': "
                         f"{q[i, np.flatnonzero(revolute)[j]]:.6g} rad is more than a full turn; "
                         "joint values are read in radians (are these degrees?)")


def _poses(quat: np.ndarray, pos: np.ndarray, label: str, lines: list[int]) -> np.ndarray:
    """(m, 4, 4) poses from unit quaternions (m, 4), scalar first, and positions (m, 3) [m].

    Raises InputError naming the line of the first quaternion whose norm is not 1 (1e-6).
    """
    from serialkin.spatial.rotations import quaternion_to_matrix

    norm = np.linalg.norm(quat, axis=1)
    if (np.abs(norm - 1.0) > 1e-6).any():
        i = int(np.argmax(np.abs(norm - 1.0)))
        raise InputError(f"{label}, line {lines[i]}: the quaternion must have unit norm, got "
                         f"norm {norm[i]:.9g}")
    T = np.tile(np.eye(4), (quat.shape[0], 1, 1))
    T[:, :3, :3] = quaternion_to_matrix(quat, normalize=True)
    T[:, :3, 3] = pos
    return T


def _check_header(header: list[str], robot: Robot, label: str, lineno: int) -> None:
    if any(re.fullmatch(r"[-+.0-9eE]+", h) for h in header):
        raise InputError(f"{label}, line {lineno}: expected a header line naming the columns "
                         f"q1..q{robot.n}, x, y, z[, quat_w, quat_x, quat_y, quat_z][, weight], "
                         f"got numbers")
    if len(set(header)) != len(header):
        raise InputError(f"{label}, line {lineno}: duplicate column names in the header")
    joints = sorted(int(h[1:]) for h in header if re.fullmatch(r"q[0-9]+", h))
    if joints != list(range(1, len(joints) + 1)):
        raise InputError(f"{label}, line {lineno}: joint columns must be q1..qN in any order, "
                         f"got {', '.join(f'q{j}' for j in joints) or 'none'}")
    if len(joints) != robot.n:
        raise InputError(f"{label}: the measurements have {len(joints)} joint columns "
                         f"(q1..q{len(joints)}) but robot {robot.name!r} has {robot.n} joints")
    allowed = {f"q{i + 1}" for i in range(robot.n)} | {"x", "y", "z", "weight", "marker",
                                                        *_QUAT}
    unknown = [h for h in header if h not in allowed]
    if unknown:
        raise InputError(f"{label}, line {lineno}: unknown column(s) "
                         f"{', '.join(short_repr(u, 30) for u in unknown[:5])}; allowed: "
                         f"q1..q{robot.n}, x, y, z, {', '.join(_QUAT)}, marker, weight")
    missing = [h for h in ("x", "y", "z") if h not in header]
    quat = [h for h in _QUAT if h in header]
    if quat and len(quat) != 4:
        missing += [h for h in _QUAT if h not in header]
    if missing:
        raise InputError(f"{label}, line {lineno}: missing column(s) {', '.join(missing)}")


def write_measurements(path: str | os.PathLike[str], measurements: Measurements,
                       weights: object = None) -> Path:
    """Write measurements as a CSV file (atomically), readable by :func:`read_measurements`.

    Args:
        path: the file.
        measurements: what to write (sigmas and covariances are not written).
        weights: optional (m,) weights for a ``weight`` column.
    """
    from serialkin._io import write_text_atomic
    from serialkin.spatial.rotations import matrix_to_quaternion

    check_choice(measurements.kind, "kind", KINDS)
    n = measurements.q.shape[1]
    header = [f"q{i + 1}" for i in range(n)] + ["x", "y", "z"]
    cols = [measurements.q, measurements.positions]
    if measurements.rotations is not None:
        header += list(_QUAT)
        cols.append(matrix_to_quaternion(measurements.rotations, check=False))
    if measurements.markers.any():
        header.append("marker")
        cols.append(measurements.markers.reshape(-1, 1) + 1.0)
    if weights is not None:
        header.append("weight")
        cols.append(np.asarray(weights, dtype=float).reshape(-1, 1))
    data = np.hstack(cols)
    body = "\n".join(",".join(repr(float(v)) for v in row) for row in data)
    return write_text_atomic(path, ",".join(header) + "\n" + body + "\n")
