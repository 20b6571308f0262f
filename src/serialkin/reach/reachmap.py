"""The result of a reachability map: per-voxel arrays over a :class:`VoxelGrid`."""

from __future__ import annotations

import io
import json
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from serialkin._io import write_bytes_atomic
from serialkin.errors import InputError
from serialkin.reach.chunk import FIELDS
from serialkin.reach.grid import VoxelGrid


@dataclass(frozen=True, eq=False)
class ReachMap:
    """A reachability map.

    Attributes:
        grid: the voxel grid.
        orientations: N, orientations tried per voxel (1 for position tasks).
        reached: grid.shape int32, orientations reached per voxel.
        solutions: grid.shape int32, IK solutions summed over the orientations.
        manipulability_mean, manipulability_min, manipulability_max: grid.shape, over the
            reached orientations of each one's best manipulability (eq 43); 0 elsewhere.
        chunk_seconds: (chunks,) wall time of each chunk [s] (NaN for chunks computed by
            an earlier run whose timing is unknown).
        settings: the settings that decided the values (see ``ReachJob.settings``).
    """

    grid: VoxelGrid
    orientations: int
    reached: np.ndarray
    solutions: np.ndarray
    manipulability_mean: np.ndarray
    manipulability_min: np.ndarray
    manipulability_max: np.ndarray
    chunk_seconds: np.ndarray
    settings: dict[str, Any] = field(default_factory=dict)

    @property
    def index(self) -> np.ndarray:
        """Reachability index per voxel: the fraction of orientations reached, in [0, 1]."""
        return self.reached / float(self.orientations)

    @property
    def reachable(self) -> np.ndarray:
        """Voxels reached with at least one orientation (bool, grid.shape)."""
        return self.reached > 0

    @property
    def fully_reachable(self) -> np.ndarray:
        """Voxels reached with every sampled orientation (bool, grid.shape)."""
        return self.reached == self.orientations

    def centres(self, mask: np.ndarray | None = None) -> np.ndarray:
        """Voxel centres (V, 3) [m], C order; only those where ``mask`` is True if given."""
        P = self.grid.centres()
        return P if mask is None else P[np.asarray(mask).reshape(-1)]

    def summary(self) -> dict[str, Any]:
        """Counts and timings, JSON-ready."""
        t = self.chunk_seconds[np.isfinite(self.chunk_seconds)]
        return {"voxels": int(self.grid.size), "orientations": self.orientations,
                "reachable_voxels": int(self.reachable.sum()),
                "fully_reachable_voxels": int(self.fully_reachable.sum()),
                "mean_index": float(self.index.mean()),
                "chunks": int(self.chunk_seconds.size),
                "chunk_seconds_total": float(t.sum()) if t.size else None,
                "grid": self.grid.as_dict()}

    def arrays(self) -> dict[str, np.ndarray]:
        """The per-voxel arrays by name (those of ``FIELDS``)."""
        return {k: getattr(self, k) for k in FIELDS}

    def save(self, path: str | Path) -> Path:
        """Write the map to one ``.npz`` file, atomically (see :func:`load_map`)."""
        buf = io.BytesIO()
        meta = {"grid": self.grid.as_dict(), "orientations": self.orientations,
                "settings": self.settings}
        np.savez_compressed(buf, meta=np.array(json.dumps(meta)),
                            chunk_seconds=self.chunk_seconds, **self.arrays())
        return write_bytes_atomic(path, buf.getvalue())


def load_map(path: str | Path) -> ReachMap:
    """Read a map written by :meth:`ReachMap.save` (no pickles are loaded).

    Args:
        path: the ``.npz`` file, or the output folder of a run (its ``map.npz`` is read).

    Raises:
        InputError: not such a file.
    """
    if Path(path).is_dir():
        path = Path(path) / "map.npz"
    try:
        with np.load(path, allow_pickle=False) as z:
            meta = json.loads(str(z["meta"]))
            arrays = {k: np.asarray(z[k]) for k in FIELDS}
            seconds = np.asarray(z["chunk_seconds"])
    except (OSError, KeyError, ValueError) as exc:
        raise InputError(f"{str(path)!r} is not a reachability map file: {exc}") from exc
    g = meta["grid"]
    grid = VoxelGrid(tuple(g["lower"]), float(g["resolution"]), tuple(g["shape"]))
    return ReachMap(grid, int(meta["orientations"]), chunk_seconds=seconds,
                    settings=meta.get("settings", {}), **arrays)
