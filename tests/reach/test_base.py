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
    """Task poses the robot reaches free of self-collision when its base stands at B0."""
    Q = robot.random_q(20 * count, seed=seed)
    return B0 @ robot.fk(Q[~robot.in_collision(Q)][:count])


def test_base_placement_finds_a_base_that_reaches_every_task():
    """Tasks made by FK from a base B0: B0 is feasible; the best base reaches all of them."""
    r = models.get("ur5")
    B0 = base_pose(0.4, -0.2, math.pi / 2)
    T = _tasks(r, B0, 3, seed=4)
    bp = base_placement(r, T, resolution=0.2, yaws=4)
    i, j, k = (int(np.argmin(np.abs(bp.xs - 0.4))), int(np.argmin(np.abs(bp.ys + 0.2))), 1)
    assert bp.feasible[i, j, k]
    assert bp.reached[bp.best_index] == 3
    # the best base has the largest smallest margin among the feasible candidates, and
    # the highest worst-case dexterity among those that tie with it on both margins
    assert bp.margin_min[bp.best_index] == bp.margin_min[bp.feasible].max() > 0
    tie = bp.feasible & (bp.margin_min == bp.margin_min[bp.best_index]) & \
        (bp.margin_median == bp.margin_median[bp.best_index])
    assert bp.dexterity[bp.best_index] == bp.dexterity[tie].max() > 0
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


# ---------------------------------------------------------------- margin, collisions, maps
def _box_map(shape=(20, 20, 20), h=0.1, inner=(2, 17)):
    """A synthetic map whose reachable set is the box of voxels inner[0]..inner[1] per axis."""
    from serialkin.reach import ReachMap, VoxelGrid

    reached = np.zeros(shape, dtype=np.int32)
    lo, hi = inner
    reached[lo:hi + 1, lo:hi + 1, lo:hi + 1] = 3
    z = np.zeros(shape)
    return ReachMap(VoxelGrid((0.0, 0.0, 0.0), h, shape), 4, reached, reached, z, z, z,
                    np.zeros(1))


@pytest.mark.parametrize(("point", "expected"), [
    ((0.55, 1.05, 1.05), 0.35),   # voxel 5: its centre is 3.5 voxels from the face at x = 0.2
    ((1.05, 1.05, 1.05), 0.75),   # the middle: 7.5 voxels to the nearest face (x, y or z)
    ((0.25, 0.25, 0.25), 0.05),   # a corner voxel of the box: half a voxel from its faces
    ((0.15, 1.0, 1.0), 0.0),      # an unreachable voxel
    ((-0.5, 1.0, 1.0), 0.0),      # outside the grid
])
def test_edge_margin_is_the_distance_to_the_edge_of_the_reachable_box(point, expected):
    """On a box-shaped reachable set a voxel centre's margin is its distance to the faces."""
    from serialkin.reach.base import edge_margin

    assert edge_margin(_box_map(), np.array([point]))[0] == pytest.approx(expected, abs=1e-12)


def test_edge_margin_shrinks_towards_the_edge():
    """Along a line from the middle of the box to its face the margin never increases."""
    from serialkin.reach.base import edge_margin

    x = np.linspace(1.05, 0.25, 9)
    m = edge_margin(_box_map(), np.stack([x, np.full(9, 1.05), np.full(9, 1.05)], axis=-1))
    assert np.all(np.diff(m) <= 0) and m[0] > m[-1] > 0


def test_margin_ranks_a_base_with_room_above_one_on_the_edge():
    """Among bases reaching every task the best has the largest smallest margin."""
    r = models.get("ur5")
    T = _tasks(r, base_pose(0.0, 0.0, 0.0), 3, seed=2)
    bp = base_placement(r, T, resolution=0.3, yaws=2)
    assert bp.margin.shape == bp.reached.shape + (3,)
    assert np.all(bp.margin[~bp.feasible].min(axis=-1) == 0)  # a task not reached: 0
    best = bp.margin_min[bp.best_index]
    assert best == bp.margin_min[bp.feasible].max()
    edge = bp.feasible & (bp.margin_min < best)
    assert edge.any()  # some feasible bases have their tasks nearer the edge, and rank lower
    s = bp.summary()["best"]
    assert s["margin_min"] == min(s["margins"]) and s["margin_median"] == np.median(s["margins"])


def test_a_target_counts_only_with_a_collision_free_solution():
    """Closed-form solutions are filtered by the collision model: the same as robot.in_collision."""
    from serialkin.reach.solve import CollisionOptions, solve_targets

    r = models.get("ur5")
    T = r.fk(r.random_q(40, seed=3))
    ok, count, _ = solve_targets(r, "pose", T, "closed_form",
                                 collision=CollisionOptions(self_collision=True))
    free = [int((~r.in_collision(np.asarray(r.ik_all(t)).reshape(-1, 6))).sum()) for t in T]
    assert count.tolist() == free and ok.tolist() == [c > 0 for c in free]
    assert 0 < sum(free) < sum(len(r.ik_all(t)) for t in T)  # some solutions were in collision


def test_self_collision_is_on_by_default_and_only_removes():
    """With the robot's collision model no candidate reaches more tasks than without it."""
    r = models.get("ur5")
    T = _tasks(r, base_pose(0.2, 0.1, 0.0), 3, seed=5)
    on = base_placement(r, T, resolution=0.3, yaws=2)
    off = base_placement(r, T, resolution=0.3, yaws=2, self_collision=False)
    assert on.self_collision and not off.self_collision
    assert np.all(on.reached <= off.reached)
    Binv = np.linalg.inv(on.best)  # every task has a free closed-form solution from the best
    assert all((~r.in_collision(np.asarray(r.ik_all(Binv @ t)))).any() for t in T)


def test_a_world_scene_stands_still_while_the_base_moves():
    """An obstacle at a task's tool blocks it from every base; one far away, nothing."""
    from serialkin.model.geometry import Sphere

    r = models.get("ur5")
    T = _tasks(r, base_pose(0.0, 0.0, 0.0), 2, seed=6)
    opts = {"resolution": 0.3, "yaws": 2}
    free = base_placement(r, T, **opts)
    far = base_placement(r, T, scene=[Sphere(0.1, center=[20.0, 0.0, 0.0])], **opts)
    assert np.array_equal(far.reached, free.reached)
    blocked = base_placement(r, T, scene=[Sphere(0.05, center=T[0, :3, 3])], **opts)
    assert blocked.reached.max() <= 1 and free.reached.max() == 2


def test_scene_in_frame_moves_every_point_rigidly():
    """A point inside a shape, moved by T, is inside the moved shape; T⁻¹ undoes T."""
    from serialkin.model.geometry import Box, Capsule, HalfSpace, Sphere
    from serialkin.reach.base import scene_in_frame

    shapes = [Sphere(0.1, center=[1.0, 0.0, 0.5]), Box((0.2, 0.4, 0.1), center=[0.0, 1.0, 0.2]),
              Capsule(0.05, a=[0.0, 0.0, 0.0], b=[0.3, 0.0, 0.0]),
              HalfSpace([0.0, 0.0, 1.0], 0.1)]
    T = base_pose(0.7, -0.3, 1.1, 0.2)
    moved = scene_in_frame(shapes, T)
    back = scene_in_frame(moved, np.linalg.inv(T))
    for a, b in zip(shapes, back, strict=True):
        for name in ("center", "a", "b", "normal", "rotation"):
            if hasattr(a, name):
                assert np.allclose(getattr(a, name), getattr(b, name), atol=1e-12)
    h = moved[3]
    p = T[:3, :3] @ np.array([5.0, -2.0, 0.05]) + T[:3, 3]  # below the plane z = 0.1
    assert h.normal @ p <= h.offset


def test_a_saved_map_is_reused_and_gives_the_same_result(tmp_path):
    """A map computed once, passed as an object or its folder, gives the margins of a fresh one."""
    from serialkin.reach import load_map

    r = models.get("ur5")
    T = _tasks(r, base_pose(0.0, 0.0, 0.0), 2, seed=7)
    opts = {"resolution": 0.3, "yaws": 2}
    fresh = base_placement(r, T, **opts)
    fresh.reach_map.save(tmp_path / "map.npz")
    for given in (fresh.reach_map, tmp_path, tmp_path / "map.npz"):
        again = base_placement(r, T, reach_map=given, **opts)
        assert np.array_equal(again.margin, fresh.margin)
        assert again.best_index == fresh.best_index
    assert load_map(tmp_path).settings["collision"]["self_collision"] is True


def test_an_incompatible_map_is_refused_naming_the_difference(tmp_path):
    """A map without self-collision, of another robot, with a scene or no settings: refused."""
    from serialkin.model.geometry import Sphere
    from serialkin.reach import ReachMap

    r = models.get("ur5")
    T = _tasks(r, base_pose(0.0, 0.0, 0.0), 1, seed=8)
    plain = reachability_map(r, 0.4, 2, progress=False)
    with pytest.raises(InputError, match=r"collision: null in the map, \{.*self_collision.*now"):
        base_placement(r, T, resolution=0.4, yaws=1, reach_map=plain)
    base_placement(r, T, resolution=0.4, yaws=1, reach_map=plain, self_collision=False)
    other = reachability_map(models.get("puma560"), 0.5, 2, progress=False)
    with pytest.raises(InputError, match='robot: "puma560" in the map, "UR5" now; robot_hash: '):
        base_placement(r, T, resolution=0.4, yaws=1, reach_map=other, self_collision=False)
    scened = reachability_map(r, 0.4, 2, scene=[Sphere(0.1, center=[2.0, 2.0, 2.0])],
                              progress=False)
    with pytest.raises(InputError, match="scene_hash: .* in the map, null now"):
        base_placement(r, T, resolution=0.4, yaws=1, reach_map=scened, self_collision=False)
    bare = ReachMap(plain.grid, plain.orientations, plain.reached, plain.solutions,
                    plain.manipulability_mean, plain.manipulability_min,
                    plain.manipulability_max, plain.chunk_seconds)
    with pytest.raises(InputError, match="records no settings"):
        base_placement(r, T, resolution=0.4, yaws=1, reach_map=bare, self_collision=False)
    with pytest.raises(InputError, match="no assembled map"):
        base_placement(r, T, resolution=0.4, yaws=1, reach_map=tmp_path)


def test_map_records_self_collision_and_only_loses_voxels():
    """A self-collision map records its settings (ACM hash) and drops the solutions in collision."""
    r = models.get("ur5")
    with_sc = reachability_map(r, 0.4, 4, self_collision=True, progress=False)
    plain = reachability_map(r, 0.4, 4, progress=False)
    assert "collision" not in plain.settings  # maps written before it still resume
    c = with_sc.settings["collision"]
    assert c["self_collision"] is True and len(c["acm_hash"]) == 16 and c["clearance"] == 0.0
    assert np.all(with_sc.reached <= plain.reached)
    assert np.all(with_sc.solutions <= plain.solutions)
    assert with_sc.solutions.sum() < plain.solutions.sum()  # solutions in collision dropped


def test_collision_settings_are_checked_at_the_boundary():
    """A negative clearance, an acm without self-collision, no collision model: named."""
    from serialkin.collision import default_acm

    r = models.get("ur5")
    T = r.fk(np.zeros(6))
    with pytest.raises(InputError, match="clearance"):
        base_placement(r, T, clearance=-0.01)
    with pytest.raises(InputError, match="self_collision"):
        base_placement(r, T, self_collision=False, acm=default_acm(r.collision))
    bare = r.with_collision(None) if hasattr(r, "with_collision") else None
    if bare is not None and bare.collision is None:
        with pytest.raises(InputError, match="collision model"):
            base_placement(bare, T, self_collision=True)
