"""Occupancy grids of sampled end-effector positions, and area/volume with a stated error.

The workspace (chapter section 1) is estimated from samples: every sampled position
marks the grid cell (2D) or voxel (3D) of edge ``h`` that contains it. The measure
(area in m², volume in m³) and its error come from two sources:

* **Resolution.** An *interior* cell is occupied and so are all of its 3^d − 1
  neighbours; it lies inside the workspace when the boundary is smooth at scale ``h``.
  The other occupied cells are *boundary* cells, which the boundary crosses: they are
  partly inside. With ``N_i`` interior and ``N_b`` boundary cells,
  ``A_low = h^d N_i`` and ``A_high = h^d (N_i + N_b)``; the estimate is the midpoint
  ``Â = h^d (N_i + N_b / 2)`` and the resolution error ``h^d N_b / 2``.
* **Monte-Carlo coverage.** A cell inside the workspace may receive no sample. The
  Chao1 estimator of unseen classes, ``f1² / (2 f2)`` (``f1``, ``f2``: cells hit exactly
  once and twice), estimates how many such cells were missed; they widen the upper bound.

The stated error is ``ε = h^d (N_b / 2 + f1² / (2 f2))``: ``|A − Â| ≤ ε`` when the
boundary is smooth at scale ``h`` and the sampling density is positive everywhere in
the workspace (true for uniform joint-space sampling of a robot with finite limits).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from itertools import product

import numpy as np

from serialkin._budget import check_allocation
from serialkin._checks import MAX_INT, as_float_array, check_int, check_positive, short_repr
from serialkin.errors import InputError


@dataclass(frozen=True)
class MeasureEstimate:
    """Area (2D) or volume (3D) of a sampled set with its error bound.

    Attributes:
        value: the estimate ``Â`` [m² or m³].
        error: the error bound ``ε`` (resolution + Monte-Carlo coverage) [m² or m³].
        lower: ``h^d N_i`` (interior cells only) [m² or m³].
        upper: ``h^d (N_i + N_b + unseen)`` [m² or m³].
        cell: grid cell edge ``h`` [m].
        n_interior: number of interior cells ``N_i``.
        n_boundary: number of boundary cells ``N_b``.
        unseen: Chao1 estimate of missed cells.
        dim: 2 (area) or 3 (volume).
    """

    value: float
    error: float
    lower: float
    upper: float
    cell: float
    n_interior: int
    n_boundary: int
    unseen: float
    dim: int

    @property
    def unit(self) -> str:
        """'m^2' for an area, 'm^3' for a volume."""
        return f"m^{self.dim}"

    @property
    def relative_error(self) -> float:
        """``ε / Â`` (inf when the estimate is 0)."""
        return self.error / self.value if self.value > 0 else float("inf")

    def __str__(self) -> str:
        what = "area" if self.dim == 2 else "volume"
        return (f"{what} {self.value:.6g} ± {self.error:.2g} {self.unit} "
                f"(cell {self.cell:.3g} m, {self.n_interior} interior + {self.n_boundary} "
                f"boundary cells)")

    def as_dict(self) -> dict[str, float | int | str]:
        """JSON-ready fields."""
        return {"value": self.value, "error": self.error, "lower": self.lower,
                "upper": self.upper, "cell": self.cell, "n_interior": self.n_interior,
                "n_boundary": self.n_boundary, "unseen": self.unseen, "unit": self.unit}


@dataclass(frozen=True, eq=False)
class OccupancyGrid:
    """Sample counts on a regular grid of cells with edge ``cell``.

    Cell ``idx`` (an integer d-vector) spans ``lower + cell·idx`` to ``lower + cell·(idx+1)``.

    Attributes:
        lower: (d,) corner of cell 0 [m].
        cell: cell edge ``h`` [m].
        counts: integer array of shape (n_1, ..., n_d): samples per cell.
    """

    lower: np.ndarray
    cell: float
    counts: np.ndarray

    @property
    def dim(self) -> int:
        """2 or 3."""
        return self.counts.ndim

    @property
    def shape(self) -> tuple[int, ...]:
        """Number of cells along each axis."""
        return self.counts.shape

    @property
    def occupied(self) -> np.ndarray:
        """Boolean array: cells holding at least one sample."""
        return self.counts > 0

    @property
    def upper(self) -> np.ndarray:
        """(d,) far corner of the last cell [m]."""
        return self.lower + self.cell * np.array(self.shape)

    def axes(self) -> list[np.ndarray]:
        """Cell-centre coordinates along each axis [m]."""
        return [self.lower[k] + self.cell * (np.arange(s) + 0.5) for k, s in enumerate(self.shape)]

    def index(self, points: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Integer cell indices (N, d) of ``points`` (N, d) and a mask of those inside the grid."""
        idx = np.floor((points - self.lower) / self.cell).astype(np.int64)
        inside = np.all((idx >= 0) & (idx < np.array(self.shape)), axis=1)
        return idx, inside

    def interior(self) -> np.ndarray:
        """Occupied cells whose 3^d − 1 neighbours are all occupied (boolean array)."""
        occ = self.occupied
        pad = np.pad(occ, 1, constant_values=False)
        inner = occ.copy()
        for shift in product((-1, 0, 1), repeat=self.dim):
            if not any(shift):
                continue
            sl = tuple(slice(1 + s, 1 + s + n) for s, n in zip(shift, self.shape))
            inner &= pad[sl]
        return inner

    def measure(self) -> MeasureEstimate:
        """Area/volume estimate with its error bound (see the module docstring)."""
        vol = self.cell ** self.dim
        n_occ = int(self.occupied.sum())
        n_int = int(self.interior().sum())
        n_b = n_occ - n_int
        f1 = int((self.counts == 1).sum())
        f2 = int((self.counts == 2).sum())
        unseen = f1 * f1 / (2.0 * f2) if f2 > 0 else f1 * (f1 - 1) / 2.0
        value = vol * (n_int + 0.5 * n_b)
        return MeasureEstimate(
            value=value, error=vol * (0.5 * n_b + unseen), lower=vol * n_int,
            upper=vol * (n_occ + unseen), cell=self.cell, n_interior=n_int, n_boundary=n_b,
            unseen=unseen, dim=self.dim,
        )

    def boundary(self, fill_gaps: bool = False) -> list[np.ndarray]:
        """Closed boundary polylines of the occupied region (2D grids only), each (k, 2) [m].

        The 0.5 level set of the occupancy indicator sampled at cell centres (marching
        squares, via ``contourpy``): it runs between occupied and empty cells. Outer
        boundaries and the rims of holes (e.g. the inner circle of an annulus) are all returned.

        Args:
            fill_gaps: first fill the enclosed empty regions that are plausibly cells no
                sample happened to hit (:func:`sampling_gaps`), so only true holes get a rim.
        """
        if self.dim != 2:
            raise InputError("boundary() needs a 2D grid; use a planar slice of a 3D workspace")
        import contourpy

        occ = self.occupied | sampling_gaps(self.counts) if fill_gaps else self.occupied
        occ = np.pad(occ.astype(float), 1)
        x = self.lower[0] + self.cell * (np.arange(occ.shape[0]) - 0.5)
        y = self.lower[1] + self.cell * (np.arange(occ.shape[1]) - 0.5)
        gen = contourpy.contour_generator(x, y, occ.T, line_type=contourpy.LineType.Separate)
        return [np.asarray(seg, dtype=float) for seg in gen.lines(0.5)]

    def values_max(self, points: np.ndarray, values: np.ndarray) -> np.ndarray:
        """Per-cell maximum of ``values`` (N,) at ``points`` (N, d); NaN in empty cells."""
        idx, inside = self.index(points)
        flat = np.ravel_multi_index(tuple(idx[inside].T), self.shape)
        out = np.full(int(np.prod(self.shape)), -np.inf)
        np.maximum.at(out, flat, values[inside])
        out[~np.isfinite(out)] = np.nan
        return out.reshape(self.shape)


#: An enclosed empty region is a sampling gap (not a hole) when, at the density of the
#: samples around it, all its cells would be empty with at least this probability.
GAP_PROBABILITY = 1e-9


def sampling_gaps(counts: np.ndarray, p_min: float = GAP_PROBABILITY) -> np.ndarray:
    """Cells of enclosed empty regions that are plausibly sampling gaps, boolean (2D or 3D).

    An empty region (face-connected, ``scipy.ndimage.label``) not touching the grid's
    border is a gap when ``exp(−λ k) ≥ p_min``: k its cells, λ the mean sample count of
    the occupied cells next to it (Poisson: the chance that k cells of that density all
    stay empty). A cell or two no sample hit where samples are sparse is a gap; a hole of a
    few cells among densely hit cells (a true hole of the workspace) is not.
    """
    from scipy import ndimage

    c = np.asarray(counts)
    occ = c > 0
    labels, count = ndimage.label(~occ)
    if count == 0:
        return np.zeros_like(occ)
    border = np.zeros(count + 1, dtype=bool)
    for axis in range(occ.ndim):
        for end in (0, -1):
            border[np.unique(np.take(labels, end, axis=axis))] = True
    nsum = np.zeros(c.shape, dtype=float)  # counts of the face neighbours of every cell
    nocc = np.zeros(c.shape, dtype=float)  # number of occupied face neighbours
    for axis in range(occ.ndim):
        for shift in (1, -1):
            nsum += np.roll(np.where(occ, c, 0), shift, axis=axis)
            nocc += np.roll(occ, shift, axis=axis)
    idx = np.arange(count + 1)
    size = ndimage.sum(np.ones(c.shape), labels, idx)
    lam = ndimage.sum(nsum, labels, idx) / np.maximum(ndimage.sum(nocc, labels, idx), 1.0)
    gap = (np.exp(-lam * size) >= p_min) & ~border
    gap[0] = False
    return gap[labels]


#: Estimated memory per grid cell [bytes]: the int64 count plus the boolean and float
#: arrays derived from it (occupancy, interior, boundary, per-cell maps).
GRID_CELL_BYTES = 32


def check_grid_size(shape: tuple[int, ...], setting: str = "the cell size (--cell / --resolution)"
                    ) -> None:
    """Refuse a grid of ``shape`` cells beyond the memory budget (:mod:`serialkin._budget`).

    Raises:
        BudgetError: naming ``setting`` and the estimated size.
    """
    check_allocation("the workspace grid", shape, GRID_CELL_BYTES, setting=setting)


def grid_bounds(points: np.ndarray, cell: float) -> tuple[np.ndarray, tuple[int, ...]]:
    """Lower corner and shape of a grid of edge ``cell`` covering ``points`` with one free cell.

    Raises:
        BudgetError: the grid would exceed the memory budget (checked before allocating).
    """
    lo = points.min(axis=0) - cell
    hi = points.max(axis=0) + cell
    with np.errstate(over="ignore"):  # an overflowing extent counts as too many cells
        ratios = [float(r) for r in (hi - lo) / cell]
    shape = tuple(max(math.ceil(r), 1) if math.isfinite(r) and r < MAX_INT else MAX_INT
                  for r in ratios)
    check_grid_size(shape)
    return lo, shape


def occupancy_grid(points: object, cell: float, *, lower: object = None,
                   shape: tuple[int, ...] | None = None) -> OccupancyGrid:
    """Count the points (N, d) per cell of edge ``cell`` [m] (d = 2 or 3).

    Args:
        points: (N, d) positions [m].
        cell: cell edge [m].
        lower: (d,) corner of cell 0; with ``shape``, fixes the grid (to compare several
            sets on one grid). Default: the points' bounding box plus one empty cell.
        shape: number of cells per axis (with ``lower``).

    Points outside a fixed grid are ignored.
    """
    P = as_float_array(points, "points", ndim=2)
    if P.shape[1] not in (2, 3):
        raise InputError(f"points must have shape (N, 2) or (N, 3), got {P.shape}")
    h = check_positive(cell, "cell")
    if lower is None:
        if P.shape[0] == 0:
            raise InputError("points is empty and no grid (lower, shape) was given")
        lo, shp = grid_bounds(P, h)
    else:
        if shape is None:
            raise InputError("shape must be given together with lower")
        lo = as_float_array(lower, "lower", ndim=1)
        if isinstance(shape, (str, bytes)) or not hasattr(shape, "__len__") \
                or len(shape) != lo.shape[0]:
            raise InputError(f"shape must have {lo.shape[0]} cell counts, got "
                             f"{short_repr(shape)}")
        shp = tuple(check_int(s, "shape", minimum=1) for s in shape)
        check_grid_size(shp, "shape")
    grid = OccupancyGrid(lower=lo, cell=h, counts=np.zeros(shp, dtype=np.int64))
    if P.shape[0]:
        idx, inside = grid.index(P)
        flat = np.ravel_multi_index(tuple(idx[inside].T), shp)
        counts = np.bincount(flat, minlength=int(np.prod(shp))).reshape(shp)
        grid = OccupancyGrid(lower=lo, cell=h, counts=counts)
    return grid
