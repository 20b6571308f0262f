"""Reachability maps and base placement (the 6-D workspace), embedded or on Dask.

* :func:`reachability_map` — per voxel of a grid, the fraction of N tool orientations the
  robot reaches (reachability index), the number of IK solutions and manipulability
  statistics; chunked, streamed to disk, resumable, bit-identical on any number of
  workers (:mod:`~serialkin.reach.chunk`, :mod:`~serialkin.reach.store`,
  :mod:`~serialkin.reach.execute`);
* :func:`base_placement` — inverse reachability: which base poses on a floor plane reach
  every task pose, and the best one (:mod:`~serialkin.reach.base`);
* plots and the viewer's point layer in :mod:`serialkin.reach.plot` (matplotlib on demand).
"""

from serialkin.reach.base import BasePlacement, base_placement
from serialkin.reach.execute import connect, local_cluster, reachability_map
from serialkin.reach.grid import VoxelGrid
from serialkin.reach.orientations import approach_orientations, orientation_set, super_fibonacci
from serialkin.reach.reachmap import ReachMap, load_map

__all__ = [
    "BasePlacement",
    "ReachMap",
    "VoxelGrid",
    "approach_orientations",
    "base_placement",
    "connect",
    "load_map",
    "local_cluster",
    "orientation_set",
    "reachability_map",
    "super_fibonacci",
]
