"""Workspace boundaries outline true holes only; dexterous ⊆ total-orientation by construction."""

from __future__ import annotations

import numpy as np
import pytest

from serialkin import models
from serialkin.workspace import dexterous_workspace, total_orientation_workspace
from serialkin.workspace.grid import OccupancyGrid, sampling_gaps
from serialkin.workspace.kinds import total_and_dexterous_workspaces


def _annulus_counts(density: int, size: int = 41) -> np.ndarray:
    """Counts of a square grid: an annulus of radii 5..18 cells, ``density`` samples a cell."""
    i, j = np.indices((size, size)) - size // 2
    r = np.hypot(i, j)
    return np.where((r >= 5) & (r <= 18), density, 0).astype(np.int64)


def test_single_missed_cell_where_sparse_is_a_gap():
    """One empty cell among cells of 3 samples is a sampling gap (e^-3 is likely)."""
    c = _annulus_counts(3)
    c[20, 30] = 0
    gaps = sampling_gaps(c)
    assert gaps[20, 30] and gaps.sum() == 1


def test_true_hole_among_dense_cells_is_kept():
    """The annulus' inner disc (81 cells, 30 samples around) and a 3-cell hole stay holes."""
    c = _annulus_counts(30)
    c[20, 29:32] = 0
    gaps = sampling_gaps(c)
    assert not gaps.any()


def test_empty_region_touching_the_border_is_never_a_gap():
    """The outside of the workspace (connected to the border) is not filled."""
    c = _annulus_counts(1)
    assert not sampling_gaps(c)[0, 0]


def test_boundary_outlines_true_holes_only():
    """An annulus with scattered missed cells: one outer and one inner rim, no more."""
    c = _annulus_counts(4)
    rng = np.random.default_rng(1)
    ring = np.argwhere(c > 0)
    for i, j in ring[rng.choice(len(ring), 6, replace=False)]:
        c[i, j] = 0
    g = OccupancyGrid(lower=np.zeros(2), cell=0.1, counts=c)
    assert len(g.boundary()) > 2  # raw: every missed cell gets a rim
    assert len(g.boundary(fill_gaps=True)) == 2


@pytest.fixture(scope="module")
def pair():
    arm = models.three_link(1.0, 0.8, 0.3)
    return arm, total_and_dexterous_workspaces(arm, 6, 4000, seed=5, singularity_margin=0.1)


def test_dexterous_is_a_subset_of_total_orientation(pair):
    """One sampling, one grid: every dexterous cell is a total-orientation cell, area ≤."""
    _, (tot, dex) = pair
    assert tot.kind == "total" and dex.kind == "dexterous"
    assert dex.grid.counts.shape == tot.grid.counts.shape
    np.testing.assert_array_equal(dex.grid.lower, tot.grid.lower)
    assert dex.grid.cell == tot.grid.cell
    assert not (dex.grid.occupied & ~tot.grid.occupied).any()
    assert dex.estimate.value <= tot.estimate.value
    assert dex.estimate.lower <= tot.estimate.lower


def test_pair_matches_the_single_functions(pair):
    """The pair's total set is total_orientation_workspace's; the dexterous one on its grid."""
    arm, (tot, dex) = pair
    alone = total_orientation_workspace(arm, 6, 4000, seed=5)
    np.testing.assert_array_equal(alone.grid.counts, tot.grid.counts)
    assert alone.estimate.value == tot.estimate.value
    on_grid = dexterous_workspace(arm, 6, 4000, seed=5, singularity_margin=0.1, grid=tot.grid)
    np.testing.assert_array_equal(on_grid.grid.counts, dex.grid.counts)
