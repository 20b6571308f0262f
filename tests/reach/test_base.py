"""Base placement (inverse reachability) and the map figures / point layer."""

from __future__ import annotations

import io
import math

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
import pytest  # noqa: E402

from serialkin import models  # noqa: E402
from serialkin.errors import InputError  # noqa: E402
from serialkin.models.planar import planar  # noqa: E402
from serialkin.reach import base_placement, reachability_map  # noqa: E402
from serialkin.reach.base import base_pose  # noqa: E402
from serialkin.reach.plot import (  # noqa: E402
    plot_base_placement,
    plot_map_points,
    plot_map_slice,
    point_layer,
)


def _tasks(robot, B0: np.ndarray, count: int, seed: int) -> np.ndarray:
    """Task poses the robot reaches when its base stands at B0."""
    return B0 @ robot.fk(robot.random_q(count, seed=seed))


def test_base_placement_finds_a_base_that_reaches_every_task():
    """Tasks made by FK from a base B0: B0 is feasible; the best base reaches all of them."""
    r = models.get("ur5")
    B0 = base_pose(0.4, -0.2, math.pi / 2)
    T = _tasks(r, B0, 3, seed=4)
    bp = base_placement(r, T, resolution=0.2, yaws=4)
    i, j, k = (int(np.argmin(np.abs(bp.xs - 0.4))), int(np.argmin(np.abs(bp.ys + 0.2))), 1)
    assert bp.feasible[i, j, k]
    assert bp.reached[bp.best_index] == 3
    # the best base has the highest worst-case dexterity among the feasible candidates
    assert bp.dexterity[bp.best_index] == bp.dexterity[bp.feasible].max() > 0
    # an independent check of the best pose: every task has a closed-form solution from it
    Binv = np.linalg.inv(bp.best)
    assert all(len(r.ik_all(Binv @ t)) > 0 for t in T)
    # and a candidate far away from every task reaches none
    assert bp.reached[0, 0, 0] == 0


def test_base_placement_bad_input():
    """Malformed tasks, region or a planar robot are refused with the argument named."""
    r = models.get("ur5")
    with pytest.raises(InputError, match="tasks"):
        base_placement(r, np.zeros((2, 3, 3)))
    with pytest.raises(InputError, match="region"):
        base_placement(r, np.eye(4), region=[[1, 0], [0, 1]])
    with pytest.raises(InputError, match="resolution"):
        base_placement(r, np.eye(4), resolution=0)
    with pytest.raises(InputError, match="planar"):
        base_placement(planar(3, 1.0), np.eye(4))


def _png(ax) -> bytes:
    buf = io.BytesIO()
    ax.figure.savefig(buf, format="png", dpi=40)
    plt.close(ax.figure)
    return buf.getvalue()


def test_point_layer_and_figures():
    """The point layer holds the reached voxels coloured by index; the figures render."""
    m = reachability_map(models.get("ur5"), 0.3, 4, progress=False)
    P, C = point_layer(m)
    assert P.shape == (int(m.reachable.sum()), 3) and C.shape == P.shape
    assert np.all((C >= 0) & (C <= 1))
    # voxels of equal index get equal colours, higher index another colour
    idx = m.index[m.reachable]
    lo, hi = idx.min(), idx.max()
    assert lo < hi and not np.allclose(C[idx == lo][0], C[idx == hi][0])
    full = point_layer(m, min_index=0.99)[0]
    assert len(full) == int(m.fully_reachable.sum())
    for ax in (plot_map_slice(m, "z", 0.1), plot_map_points(m), plot_map_slice(m, "x", 0.0)):
        assert _png(ax).startswith(b"\x89PNG")
    r = models.get("ur5")
    T = _tasks(r, base_pose(0.0, 0.0, 0.0), 2, seed=1)
    ax = plot_base_placement(base_placement(r, T, resolution=0.3, yaws=2), tasks=T)
    assert _png(ax).startswith(b"\x89PNG")


def test_base_placement_too_fine_grid_is_refused():
    """A floor grid beyond the memory budget is refused before any allocation."""
    from serialkin.errors import BudgetError

    with pytest.raises(BudgetError, match="resolution"):
        base_placement(models.get("ur5"), np.eye(4), resolution=1e-7)
