"""The result of path tracking: a :class:`Trajectory`, saved to and loaded from CSV or NPZ.

Per path point (step) ``k`` a trajectory holds the joint values ``q[k]`` (n,), the reached
end-effector pose ``poses[k]`` (4, 4), the target ``targets[k]`` (4, 4), the tracking error
``errors[k]`` (norm of the task error [m]), the iterations used, whether the point was
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

__all__ = ["PathFailure", "Trajectory"]


@dataclass(frozen=True)
class PathFailure:
    """A path point that was not reached: its index, its final error [m] and its target."""

    index: int
    error: float
    target: tuple[float, ...]

    def __str__(self) -> str:
        t = ", ".join(f"{v:.4g}" for v in self.target)
        return f"path point {self.index} ({t}) not reached: error {self.error:.4g} m"


@dataclass
class Trajectory:
    """Joint and task-space record of a tracked path (see module docstring for shapes).

    Attributes:
        q: (p, n) joint values.
        poses: (p, 4, 4) end-effector poses reached.
        targets: (p, 4, 4) path targets.
        errors: (p,) task-error norms [m].
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

    def summary(self) -> str:
        """A one-paragraph human-readable report."""
        lines = [
            f"{len(self)}/{self.path_length} path points computed with {self.solver}; "
            f"max tracking error {self.max_error * 1e3:.4g} mm "
            f"(tolerance {self.tolerance * 1e3:.4g} mm); "
            f"{int(self.iterations.sum())} iterations, {self.times.sum() * 1e3:.3g} ms"]
        if self.clearance.size:
            lines.append(f"min clearance {self.min_clearance * 1e3:.4g} mm")
        if np.isfinite(self.min_limit_margin):
            lines.append(f"min joint-limit margin {np.degrees(self.min_limit_margin):.4g} deg")
        for f in self.failures:
            lines.append(str(f))
        if self.stopped:
            lines.append("tracking stopped at the first unreachable point")
        return "; ".join(lines)

    # ------------------------------------------------------------------ files
    def _meta(self) -> dict:
        return {"task": self.task, "tolerance": self.tolerance,
                "joint_names": list(self.joint_names),
                "obstacle_names": list(self.obstacle_names),
                "failures": [[f.index, f.error, list(f.target)] for f in self.failures],
                "stopped": self.stopped, "path_length": self.path_length,
                "solver": self.solver}

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

        Raises:
            InputError: unknown extension or a file that is not a serialkin trajectory.
        """
        p = FsPath(path)
        suffix = p.suffix.lower()
        if suffix == ".npz":
            with np.load(p, allow_pickle=False) as z:
                try:
                    meta = json.loads(str(z["meta"]))
                    arrays = {k: z[k] for k in ("q", "poses", "targets", "errors", "iterations",
                                                "reached", "clearance", "limit_margin", "times")}
                except KeyError as exc:
                    raise InputError(f"{p}: not a serialkin trajectory (missing {exc})") from exc
            return cls._from(arrays, meta)
        if suffix == ".csv":
            return cls._read_csv(p)
        raise InputError(f"trajectory file must end in .csv or .npz, got {p.name!r}")

    @classmethod
    def _from(cls, a: dict, meta: dict) -> Trajectory:
        return cls(
            q=a["q"], poses=a["poses"], targets=a["targets"], errors=a["errors"],
            iterations=a["iterations"].astype(int), reached=a["reached"].astype(bool),
            clearance=a["clearance"], limit_margin=a["limit_margin"], times=a["times"],
            task=meta["task"], tolerance=float(meta["tolerance"]),
            joint_names=tuple(meta["joint_names"]), obstacle_names=tuple(meta["obstacle_names"]),
            failures=[PathFailure(int(i), float(e), tuple(t)) for i, e, t in meta["failures"]],
            stopped=bool(meta["stopped"]), path_length=int(meta["path_length"]),
            solver=str(meta["solver"]))

    @classmethod
    def _read_csv(cls, p: FsPath) -> Trajectory:
        text = p.read_text(encoding="utf-8")
        first, _, rest = text.partition("\n")
        prefix = "# serialkin trajectory "
        if not first.startswith(prefix):
            raise InputError(f"{p}: not a serialkin trajectory (first line must start with "
                             f"{prefix.strip()!r})")
        meta = json.loads(first[len(prefix):])
        rows = list(csv.reader(io.StringIO(rest)))
        header, body = rows[0], [r for r in rows[1:] if r]
        data = np.array([[float(v) for v in r] for r in body]).reshape(len(body), len(header))
        col = {h: i for i, h in enumerate(header)}

        def block(prefix: str) -> np.ndarray:
            idx = [i for h, i in col.items() if h.startswith(prefix)]
            return data[:, idx]

        p_ = data.shape[0]

        def poses(prefix: str) -> np.ndarray:
            T = np.tile(np.eye(4), (p_, 1, 1))
            T[:, :3, :] = block(prefix).reshape(p_, 3, 4)
            return T

        a = {"q": block("q:"), "poses": poses("pose_T"), "targets": poses("target_T"),
             "errors": data[:, col["error"]], "iterations": data[:, col["iterations"]],
             "reached": data[:, col["reached"]], "clearance": block("clearance:"),
             "limit_margin": block("margin:"), "times": data[:, col["time"]]}
        return cls._from(a, meta)
