"""The voxel grid of a reachability map and its cutting into chunks.

A grid of ``shape = (nx, ny, nz)`` cubic voxels of edge ``resolution`` [m] whose lower
corner is ``lower`` (3,) [m]; voxel ``(i, j, k)`` has its centre at
``lower + (i + ½, j + ½, k + ½)·resolution`` and flat index ``(i·ny + j)·nz + k``
(C order). A planar arm's grid has one layer (nz = 1) in the plane of the arm.

The map is computed in *chunks* of ``chunk_voxels`` consecutive flat indices: chunk c
covers voxels ``c·chunk_voxels .. min((c+1)·chunk_voxels, V) − 1``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from serialkin._budget import check_allocation
from serialkin._checks import as_float_array, check_positive
from serialkin.errors import InputError

#: Bytes per voxel of an assembled map (reached, solutions: int32; four float64 maps).
MAP_VOXEL_BYTES = 40

#: Configurations drawn to estimate a robot's reach when no bounds are given.
REACH_SAMPLES = 20_000


@dataclass(frozen=True)
class VoxelGrid:
    """A box of cubic voxels.

    Attributes:
        lower: (3,) lower corner [m].
        resolution: voxel edge [m].
        shape: (nx, ny, nz).
    """

    lower: tuple[float, float, float]
    resolution: float
    shape: tuple[int, int, int]

    @property
    def size(self) -> int:
        """Number of voxels V."""
        return int(np.prod(self.shape, dtype=object))

    def centres(self, start: int = 0, stop: int | None = None) -> np.ndarray:
        """Centres of the voxels with flat indices ``start..stop−1``, (stop − start, 3) [m]."""
        stop = self.size if stop is None else stop
        ijk = np.stack(np.unravel_index(np.arange(start, stop), self.shape), axis=-1)
        return np.asarray(self.lower) + (ijk + 0.5) * self.resolution

    def axes(self) -> list[np.ndarray]:
        """Voxel-centre coordinates along x, y, z [m]."""
        return [self.lower[a] + (np.arange(self.shape[a]) + 0.5) * self.resolution
                for a in range(3)]

    def as_dict(self) -> dict[str, object]:
        """JSON-ready description."""
        return {"lower": [float(v) for v in self.lower], "resolution": float(self.resolution),
                "shape": [int(v) for v in self.shape]}


def check_map_size(shape: tuple[int, ...], orientations: int) -> None:
    """Refuse a map whose assembled arrays exceed the memory budget.

    Raises:
        BudgetError: the message gives the size and says how to make it smaller.
    """
    voxels = 1
    for d in shape:
        voxels *= int(d)
    check_allocation(
        f"the reachability map ({voxels:,} voxels × {orientations} orientations = "
        f"{voxels * orientations:,} IK targets)", shape, MAP_VOXEL_BYTES,
        setting="the map: choose a coarser resolution or smaller --bounds (every chunk is "
                "written to disk as it finishes, so only the assembled map must fit; "
                "--chunk-voxels bounds the memory of one chunk)")


def robot_reach_box(robot: object, seed: int = 0) -> tuple[np.ndarray, np.ndarray]:
    """The box of tool positions of ``REACH_SAMPLES`` random configurations [m], (3,), (3,)."""
    Q = robot.random_q(REACH_SAMPLES, seed=seed)  # type: ignore[attr-defined]
    P = robot.fk(Q)[:, :3, 3]  # type: ignore[attr-defined]
    return P.min(axis=0), P.max(axis=0)


def make_grid(robot: object, resolution: float, bounds: object = None, *,
              planar: bool = False) -> VoxelGrid:
    """The grid of a map: ``bounds`` ((3, 2) [m]) or the robot's reach box, snapped.

    Without bounds the box of sampled tool positions is widened by 5 % of its largest
    extent plus one voxel on every side (sampling misses the outermost rim). The lower
    corner is a multiple of the resolution, so maps of one robot line up. A planar arm's
    grid has one layer centred on its plane (whatever the z bounds).

    Raises:
        InputError: resolution <= 0 or not finite; bounds not (3, 2) with lower < upper.
        BudgetError: the grid does not fit the memory budget (see :func:`check_map_size`).
    """
    res = check_positive(resolution, "resolution")
    if bounds is None:
        lo, hi = robot_reach_box(robot)
        pad = 0.05 * float(np.max(hi - lo)) + res
        lo, hi = lo - pad, hi + pad
    else:
        b = as_float_array(bounds, "bounds")
        if b.shape != (3, 2) or not np.all(b[:, 0] < b[:, 1]):
            raise InputError(f"bounds must be (3, 2) rows (lower, upper) with lower < upper "
                             f"[m], got {b.tolist() if b.size <= 12 else b.shape}")
        lo, hi = b[:, 0].copy(), b[:, 1].copy()
    lower = np.floor(lo / res) * res
    with np.errstate(over="ignore"):
        counts = np.ceil((hi - lower) / res - 1e-9)
    if not np.all(np.isfinite(counts)) or np.any(counts > 2**40):
        raise InputError(f"resolution {res!r} m is too fine for the box {lo.tolist()} .. "
                         f"{hi.tolist()} m")
    shape = [max(1, int(c)) for c in counts]
    if planar:  # one layer centred on the plane of the arm (the z bounds do not matter)
        z = float(robot.fk(robot.random_q(seed=0))[2, 3])  # type: ignore[attr-defined]
        lower[2] = z - 0.5 * res
        shape[2] = 1
    return VoxelGrid(tuple(float(v) for v in lower), float(res), tuple(shape))  # type: ignore


def chunk_count(grid: VoxelGrid, chunk_voxels: int) -> int:
    """Number of chunks of ``chunk_voxels`` voxels covering the grid."""
    return max(1, math.ceil(grid.size / chunk_voxels))
