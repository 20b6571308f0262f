"""The result of path tracking: a :class:`Trajectory`, saved to and loaded from CSV or NPZ.

Per path point (step) ``k`` a trajectory holds the joint values ``q[k]`` (n,), the reached
end-effector pose ``poses[k]`` (4, 4), the target ``targets[k]`` (4, 4), the tracking error
``errors[k]`` (norm of the task error; position and orientation errors apart by
:attr:`Trajectory.position_errors` [m] and :attr:`Trajectory.orientation_errors` [rad]),
the iterations used, whether the point was
reached within the tolerance, the minimum clearance to every obstacle ``clearance[k]``
(k_obs,) [m] and the margin of every joint to its nearer limit ``limit_margin[k]`` (n,)
[rad or m; +inf when unlimited].

Files are written atomically (temporary file + rename), so an interrupted save never
leaves a truncated file.
"""

from __future__ import annotations

import csv
import io
import json
import os
from dataclasses import dataclass, field
from pathlib import Path as FsPath

import numpy as np

from serialkin._io import write_bytes_atomic
from serialkin.errors import InputError
from serialkin.spatial.lie import so3_log

__all__ = ["JointJump", "PathFailure", "Trajectory", "format_duration"]


def format_duration(seconds: float) -> str:
    """A duration with a unit that suits it: '12.3 µs', '4.56 ms', '7.8 s', '3 min 20 s'."""
    if not np.isfinite(seconds):
        return str(seconds)
    if seconds < 1e-3:
        return f"{seconds * 1e6:.3g} µs"
    if seconds < 1.0:
        return f"{seconds * 1e3:.3g} ms"
    if seconds < 120.0:
        return f"{seconds:.3g} s"
    minutes, rest = divmod(round(seconds), 60)
    return f"{minutes} min {rest} s"


@dataclass(frozen=True)
class PathFailure:
    """A path point that was not reached: index, final error [m], target, and the solver's reason.

    ``reason`` is empty unless the solver says why it stopped (the QP tracker does: blocked
    by constraints, infeasible QP, ...).
    """

    index: int
    error: float
    target: tuple[float, ...]
    reason: str = ""

    def __str__(self) -> str:
        t = ", ".join(f"{v:.4g}" for v in self.target)
        why = f" ({self.reason})" if self.reason else ""
        return f"path point {self.index} ({t}) not reached: error {self.error:.4g} m{why}"


@dataclass(frozen=True)
class JointJump:
    """A joint that moved by more than the allowed step between path points k − 1 and k.

    Attributes:
        index: path point k (point 0 is compared with the start configuration).
        joint: index of the joint that moved most (0-based).
        size: its signed change [rad or m].
    """

    index: int
    joint: int
    size: float

    def __str__(self) -> str:
        return (f"joint {self.joint + 1} jumped by {self.size:.4g} between path points "
                f"{self.index - 1} and {self.index} (a branch flip or wrap)")


@dataclass
class Trajectory:
    """Joint and task-space record of a tracked path (see module docstring for shapes).

    Attributes:
        q: (p, n) joint values.
        poses: (p, 4, 4) end-effector poses reached.
        targets: (p, 4, 4) path targets.
        errors: (p,) task-error norms (for a 'pose' task the norm of [position error m,
            rotation vector rad]; :attr:`position_errors` [m] and
            :attr:`orientation_errors` [rad] give them apart).
        iterations: (p,) solver iterations per point.
        reached: (p,) error ≤ tolerance.
        clearance: (p, k) minimum clearance per obstacle [m] (k = 0 without obstacles).
        limit_margin: (p, n) distance of each joint to its nearer limit (+inf unlimited).
        times: (p,) wall time per point [s].
        task: path task ('planar', 'position', ...).
        tolerance: acceptance tolerance [m].
        joint_names, obstacle_names: labels.
        failures: points not reached (index, error, target).
        stopped: True when tracking stopped at the first failure (``on_unreachable='stop'``);
            the arrays then hold the points computed so far, the failing one included.
        path_length: number of points of the full path.
        solver: description of the solver used.
        jumps: points where a joint moved by more than the tracker's ``max_joint_step``.
        notes: solver failures at points that were nevertheless reached (e.g. an infeasible
            QP: a safety margin larger than the free space), one line per distinct reason.
    """

    q: np.ndarray
    poses: np.ndarray
    targets: np.ndarray
    errors: np.ndarray
    iterations: np.ndarray
    reached: np.ndarray
    clearance: np.ndarray
    limit_margin: np.ndarray
    times: np.ndarray
    task: str = "planar"
    tolerance: float = 5e-3
    joint_names: tuple[str, ...] = ()
    obstacle_names: tuple[str, ...] = ()
    failures: list[PathFailure] = field(default_factory=list)
    stopped: bool = False
    path_length: int = 0
    solver: str = ""
    jumps: list[JointJump] = field(default_factory=list)
    notes: list[str] = field(default_factory=list)

    # ------------------------------------------------------------------ summaries
    def __len__(self) -> int:
        return self.q.shape[0]

    @property
    def positions(self) -> np.ndarray:
        """(p, 3) end-effector positions [m]."""
        return self.poses[:, :3, 3]

    @property
    def max_error(self) -> float:
        """Largest tracking error over the computed points [m]."""
        return float(self.errors.max()) if len(self) else float("nan")

    @property
    def min_clearance(self) -> float:
        """Smallest clearance over all steps, links and obstacles [m] (+inf without obstacles)."""
        return float(self.clearance.min()) if self.clearance.size else float("inf")

    @property
    def min_limit_margin(self) -> float:
        """Smallest joint-limit margin over all steps and joints (+inf when unlimited)."""
        return float(self.limit_margin.min()) if self.limit_margin.size else float("inf")

    @property
    def complete(self) -> bool:
        """Every path point was computed and reached."""
        return not self.stopped and len(self) == self.path_length and not self.failures

    @property
    def position_errors(self) -> np.ndarray:
        """(p,) distance of each reached position from its target [m] (planar tasks: in x, y)."""
        d = self.poses[:, :3, 3] - self.targets[:, :3, 3]
        if self.task in ("planar", "planar_pose"):
            d = d[:, :2]
        return np.linalg.norm(d, axis=1)

    @property
    def orientation_errors(self) -> np.ndarray | None:
        """(p,) rotation angle between reached and target orientation [rad], or None.

        None for tasks that do not constrain the orientation ('planar', 'position');
        for 'planar_pose' the angle about z, for 'pose' the full rotation angle.
        """
        if self.task not in ("pose", "planar_pose"):
            return None
        R = np.swapaxes(self.targets[:, :3, :3], -1, -2) @ self.poses[:, :3, :3]
        if self.task == "planar_pose":
            return np.abs(np.arctan2(R[:, 1, 0], R[:, 0, 0]))
        return np.linalg.norm(so3_log(R, check=False), axis=-1)  # accurate near 0, unlike acos

    def summary(self, verbose: bool = False) -> str:
        """A short report (at most 15 lines), or every failure and jump with ``verbose``.

        Says how many path points were reached (not merely computed), the largest and
        median position error [mm] and, for orientation tasks, orientation error [deg],
        separately; the time with a unit that suits it; clearances and joint-limit
        margins; then the failures, jumps and notes (the first few, and how many more).
        """
        reached = int(np.sum(self.reached))
        head = f"reached {reached} of {self.path_length} path points with {self.solver}"
        if self.stopped:
            head += f" (stopped after point {len(self) - 1}: the next could not be reached)"
        lines = [head]
        if len(self):
            pos = self.position_errors * 1e3
            lines.append(f"position error: max {pos.max():.4g} mm, median "
                         f"{np.median(pos):.4g} mm (tolerance {self.tolerance * 1e3:.4g} mm)")
            rot = self.orientation_errors
            if rot is not None:
                lines.append(f"orientation error: max {np.degrees(rot.max()):.4g} deg, "
                             f"median {np.degrees(np.median(rot)):.4g} deg")
            lines.append(f"time: {format_duration(float(self.times.sum()))} in all, "
                         f"{format_duration(float(np.median(self.times)))} per point "
                         f"(median); {int(self.iterations.sum())} iterations")
        if self.clearance.size:
            lines.append(f"min clearance {self.min_clearance * 1e3:.4g} mm")
        if np.isfinite(self.min_limit_margin):
            lines.append(f"min joint-limit margin {np.degrees(self.min_limit_margin):.4g} deg")
        for items, what in ((self.failures, "failures"), (self.jumps, "jumps"),
                            (self.notes, "notes")):
            shown = items if verbose else items[:3]
            lines.extend(str(x) for x in shown)
            if len(items) > len(shown):
                lines.append(f"... and {len(items) - len(shown)} more {what} "
                             "(summary(verbose=True), or --verbose, lists them all)")
        return "\n".join(lines)

    # ------------------------------------------------------------------ files
    def _meta(self) -> dict:
        return {"task": self.task, "tolerance": self.tolerance,
                "joint_names": list(self.joint_names),
                "obstacle_names": list(self.obstacle_names),
                "failures": [[f.index, f.error, list(f.target), f.reason]
                             for f in self.failures],
                "stopped": self.stopped, "path_length": self.path_length,
                "solver": self.solver,
                "jumps": [[j.index, j.joint, j.size] for j in self.jumps],
                "notes": list(self.notes)}

    def save(self, path: str | os.PathLike[str]) -> FsPath:
        """Write to ``.csv`` or ``.npz`` (chosen by the extension), atomically."""
        p = FsPath(path)
        suffix = p.suffix.lower()
        if suffix == ".npz":
            buf = io.BytesIO()
            np.savez_compressed(
                buf, q=self.q, poses=self.poses, targets=self.targets, errors=self.errors,
                iterations=self.iterations, reached=self.reached, clearance=self.clearance,
                limit_margin=self.limit_margin, times=self.times,
                meta=np.array(json.dumps(self._meta())))
            write_bytes_atomic(p, buf.getvalue())
        elif suffix == ".csv":
            write_bytes_atomic(p, self._csv().encode("utf-8"))
        else:
            raise InputError(f"trajectory file must end in .csv or .npz, got {p.name!r}")
        return p

    def _columns(self) -> list[str]:
        n = self.q.shape[1]
        names = list(self.joint_names) or [f"joint{i + 1}" for i in range(n)]
        cols = ["step", "reached", "iterations", "error", "time"]
        cols += [f"target_T{r}{c}" for r in range(3) for c in range(4)]
        cols += [f"pose_T{r}{c}" for r in range(3) for c in range(4)]
        cols += [f"q:{j}" for j in names]
        obs = list(self.obstacle_names) or [f"obstacle{i + 1}"
                                            for i in range(self.clearance.shape[1])]
        cols += [f"clearance:{o}" for o in obs]
        cols += [f"margin:{j}" for j in names]
        return cols

    def _csv(self) -> str:
        out = io.StringIO()
        out.write("# serialkin trajectory " + json.dumps(self._meta()) + "\n")
        w = csv.writer(out, lineterminator="\n")
        w.writerow(self._columns())
        for k in range(len(self)):
            row = [k, int(self.reached[k]), int(self.iterations[k]), repr(float(self.errors[k])),
                   repr(float(self.times[k]))]
            row += [repr(float(v)) for v in self.targets[k, :3, :].ravel()]
            row += [repr(float(v)) for v in self.poses[k, :3, :].ravel()]
            row += [repr(float(v)) for v in self.q[k]]
            row += [repr(float(v)) for v in self.clearance[k]]
            row += [repr(float(v)) for v in self.limit_margin[k]]
            w.writerow(row)
        return out.getvalue()

    @classmethod
    def load(cls, path: str | os.PathLike[str]) -> Trajectory:
        """Read a trajectory written by :meth:`save` (``.csv`` or ``.npz``).

        The file is read through :mod:`serialkin._files` (at most
        :data:`MAX_TRAJECTORY_BYTES`, regular file, UTF-8 for CSV; ``.npz`` arrays are
        loaded without pickle and their unpacked size is bounded too); the header is
        checked field by field and the arrays for type and consistent shapes.

        Raises:
            InputError: unknown extension, a missing or unreadable file, or a file that is
                not a valid serialkin trajectory (the message names the file and what is
                wrong).
        """
        from serialkin._files import read_bytes

        p = FsPath(path)
        suffix = p.suffix.lower()
        if suffix not in (".npz", ".csv"):
            raise InputError(f"trajectory file must end in .csv or .npz, got {p.name!r}")
        data = read_bytes(p, what="trajectory file", max_bytes=MAX_TRAJECTORY_BYTES)
        if suffix == ".npz":
            arrays, meta = _read_npz(p, data)
        else:
            arrays, meta = _read_csv(p, data)
        return cls._from(p, arrays, meta)

    @classmethod
    def _from(cls, p: FsPath, a: dict, meta_data: object) -> Trajectory:
        from serialkin._files import Field

        meta = Field(meta_data, "", f"{p}: trajectory header", InputError)
        meta.mapping(None, ("task", "tolerance", "joint_names", "obstacle_names", "failures",
                            "stopped", "path_length", "solver"))
        arrays = _check_arrays(p, a)
        n, k = arrays["q"].shape[1], arrays["clearance"].shape[1]
        joint_names = tuple(f.string(nonempty=False, max_len=1000)
                            for f in meta["joint_names"].items(max_len=n))
        obstacle_names = tuple(f.string(nonempty=False, max_len=1000)
                               for f in meta["obstacle_names"].items(max_len=k))
        failures = []
        for f in meta["failures"].items(max_len=arrays["q"].shape[0]):
            parts = f.items(min_len=3, max_len=4, what="[index, error, target, reason?]")
            idx, err, tgt = parts[:3]
            why = parts[3].string(nonempty=False, max_len=10_000) if len(parts) == 4 else ""
            failures.append(PathFailure(idx.integer(hi=2**62), err.number(allow_inf=True),
                                        tuple(tgt.array(what="a list of numbers", ndim=1,
                                                        max_items=16)), why))
        notes = []
        if meta["notes"].present:
            notes = [f.string(nonempty=False, max_len=10_000)
                     for f in meta["notes"].items(max_len=1000)]
        jumps = []
        if meta["jumps"].present:  # files before the jump report have none
            for f in meta["jumps"].items(max_len=arrays["q"].shape[0]):
                idx, joint, size = f.items(min_len=3, max_len=3, what="[index, joint, size]")
                jumps.append(JointJump(idx.integer(hi=2**62), joint.integer(hi=n - 1),
                                       size.number()))
        stopped = meta["stopped"].value
        if not isinstance(stopped, bool):
            raise meta["stopped"].expected("true or false")
        return cls(
            q=arrays["q"], poses=arrays["poses"], targets=arrays["targets"],
            errors=arrays["errors"], iterations=arrays["iterations"].astype(int),
            reached=arrays["reached"].astype(bool), clearance=arrays["clearance"],
            limit_margin=arrays["limit_margin"], times=arrays["times"],
            task=meta["task"].string(max_len=100),
            tolerance=meta["tolerance"].number(lo=0.0, lo_open=True),
            joint_names=joint_names, obstacle_names=obstacle_names, failures=failures,
            stopped=stopped, path_length=meta["path_length"].integer(hi=2**62),
            solver=meta["solver"].string(nonempty=False, max_len=10_000), jumps=jumps,
            notes=notes)


#: Largest trajectory file read, and largest total size of the arrays it unpacks to [bytes].
MAX_TRAJECTORY_BYTES = 1024 * 1024 * 1024
_ARRAYS = ("q", "poses", "targets", "errors", "iterations", "reached", "clearance",
           "limit_margin", "times")


def _bad(p: FsPath, why: str) -> InputError:
    return InputError(f"{p}: not a serialkin trajectory: {why}")


def _read_npz(p: FsPath, data: bytes) -> tuple[dict, object]:
    """Arrays and header of a ``.npz`` trajectory (no pickle, bounded unpacked size)."""
    import zipfile

    from serialkin._files import parse_json

    try:
        with zipfile.ZipFile(io.BytesIO(data)) as zf:
            unpacked = sum(info.file_size for info in zf.infolist())
        if unpacked > MAX_TRAJECTORY_BYTES:
            raise _bad(p, f"its arrays unpack to {unpacked} bytes, more than the limit "
                          f"of {MAX_TRAJECTORY_BYTES}")
        with np.load(io.BytesIO(data), allow_pickle=False) as z:
            missing = [k for k in (*_ARRAYS, "meta") if k not in z.files]
            if missing:
                raise _bad(p, f"missing array(s) {', '.join(missing)}")
            arrays = {k: z[k] for k in _ARRAYS}
            meta = z["meta"]
    except InputError:
        raise
    except zipfile.BadZipFile:
        raise _bad(p, "not an .npz (zip) archive") from None
    except (ValueError, OSError, EOFError, KeyError, RuntimeError, NotImplementedError,
            zipfile.LargeZipFile) as exc:  # pickled arrays, corrupt members, bad headers
        raise _bad(p, f"cannot read its arrays ({str(exc)[:120]})") from None
    if meta.dtype.kind != "U" or meta.shape != ():
        raise _bad(p, "its 'meta' entry is not a text header")
    return arrays, parse_json(str(meta), f"{p}: header")


def _read_csv(p: FsPath, data: bytes) -> tuple[dict, object]:
    """Arrays and header of a ``.csv`` trajectory (header line, column names, numbers)."""
    from serialkin._files import decode_text, parse_json

    text = decode_text(data, str(p), what="trajectory file")
    first, _, rest = text.partition("\n")
    prefix = "# serialkin trajectory "
    if not first.startswith(prefix):
        raise _bad(p, f"the first line must start with {prefix.strip()!r}")
    meta = parse_json(first[len(prefix):], f"{p}: header line")
    try:
        rows = list(csv.reader(io.StringIO(rest)))
    except csv.Error as exc:
        raise _bad(p, f"malformed CSV ({exc})") from None
    if not rows:
        raise _bad(p, "no column names after the header line")
    header, body = rows[0], [r for r in rows[1:] if r]
    col = {h: i for i, h in enumerate(header)}
    needed = ("step", "reached", "iterations", "error", "time")
    missing = [h for h in needed if h not in col]
    if missing or len(col) != len(header):
        raise _bad(p, f"missing column(s) {', '.join(missing)}" if missing
                   else "duplicate column names")
    values = np.empty((len(body), len(header)))
    for i, r in enumerate(body):
        if len(r) != len(header):
            raise _bad(p, f"line {i + 3} has {len(r)} values, the header names {len(header)}")
        for j, v in enumerate(r):
            try:
                values[i, j] = float(v)
            except ValueError:
                raise _bad(p, f"line {i + 3}, column {header[j][:40]!r}: "
                              f"{v[:40]!r} is not a number") from None
    steps = len(body)

    def block(prefix: str) -> np.ndarray:
        return values[:, [i for h, i in col.items() if h.startswith(prefix)]]

    def poses(prefix: str) -> np.ndarray:
        b = block(prefix)
        if b.shape[1] != 12:
            raise _bad(p, f"expected 12 columns {prefix}RC, got {b.shape[1]}")
        T = np.tile(np.eye(4), (steps, 1, 1))
        T[:, :3, :] = b.reshape(steps, 3, 4)
        return T

    arrays = {"q": block("q:"), "poses": poses("pose_T"), "targets": poses("target_T"),
              "errors": values[:, col["error"]], "iterations": values[:, col["iterations"]],
              "reached": values[:, col["reached"]], "clearance": block("clearance:"),
              "limit_margin": block("margin:"), "times": values[:, col["time"]]}
    return arrays, meta


def _check_arrays(p: FsPath, a: dict) -> dict:
    """Check dtypes and shapes: q (s, n), poses/targets (s, 4, 4), clearance (s, k) ..."""
    for k in _ARRAYS:
        if a[k].dtype.kind not in "biuf":
            raise _bad(p, f"array {k!r} holds {a[k].dtype} values, not numbers")
    q = a["q"]
    if q.ndim != 2 or q.shape[1] < 1:
        raise _bad(p, f"array 'q' must have shape (steps, joints), got {q.shape}")
    s, n = q.shape
    shapes = {"poses": (s, 4, 4), "targets": (s, 4, 4), "errors": (s,), "iterations": (s,),
              "reached": (s,), "limit_margin": (s, n), "times": (s,)}
    for k, shape in shapes.items():
        if a[k].shape != shape:
            raise _bad(p, f"array {k!r} must have shape {shape}, got {a[k].shape}")
    if a["clearance"].ndim != 2 or a["clearance"].shape[0] != s:
        raise _bad(p, f"array 'clearance' must have shape ({s}, obstacles), got "
                      f"{a['clearance'].shape}")
    for k in ("q", "poses", "targets"):
        if not np.isfinite(a[k]).all():
            raise _bad(p, f"array {k!r} has NaN or infinite values")
    return {k: a[k] if k in ("iterations", "reached") else np.asarray(a[k], dtype=float)
            for k in _ARRAYS}
