"""Workspace analysis (chapter section 1), by sampling, with area/volume and error.

Maximal, constant-, inclusive- and total-orientation and dexterous workspaces.

Plots live in :mod:`serialkin.workspace.plot` (matplotlib, imported on demand).
"""

from serialkin.workspace.grid import MeasureEstimate, OccupancyGrid, occupancy_grid
from serialkin.workspace.kinds import (
    KINDS,
    Workspace,
    WorkspaceSlice,
    compute_workspace,
    constant_orientation_workspace,
    dexterous_workspace,
    inclusive_orientation_workspace,
    reachable_workspace,
    total_orientation_workspace,
    workspace_slice,
)

__all__ = [
    "KINDS",
    "MeasureEstimate",
    "OccupancyGrid",
    "Workspace",
    "WorkspaceSlice",
    "compute_workspace",
    "constant_orientation_workspace",
    "dexterous_workspace",
    "inclusive_orientation_workspace",
    "occupancy_grid",
    "reachable_workspace",
    "total_orientation_workspace",
    "workspace_slice",
]
