"""Scene shapes are the shared classes: encoding, agreement with redundancy, the old names."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.spatial.transform import Rotation

import serialkin.collision
from serialkin.collision import CollisionModel, scene_clearance
from serialkin.collision import shapes as scene_shapes
from serialkin.errors import InputError, NotSupportedError
from serialkin.model.geometry import Box, Capsule, Cylinder, HalfSpace, Sphere
from serialkin.redundancy import clearances
from serialkin.redundancy.obstacles import robot_segments

from ..redundancy._robots import spatial_rp

LINK_RADIUS = 0.03


def _segment_model(robot, q):
    """The redundancy link segments at q as capsules on the (identity) base frame, one body each."""
    P0, P1, _, _ = robot_segments(robot, q)
    s = P0.shape[0]
    return CollisionModel(tuple(f"segment{i}" for i in range(s)), np.zeros(s, dtype=np.int64),
                          np.arange(s), P0, P1, np.full(s, LINK_RADIUS))


@settings(max_examples=20, deadline=None)
@given(seed=st.integers(0, 2**31 - 1))
def test_collision_and_redundancy_agree_on_one_obstacle(seed):
    """One Sphere, Capsule or z-Cylinder has the same clearance in collision and redundancy."""
    rng = np.random.default_rng(seed)
    robot = spatial_rp()
    assert np.array_equal(robot.base, np.eye(4))
    q = robot.random_q(seed=rng)
    model = _segment_model(robot, q)
    for o in (Sphere(0.05, center=rng.uniform(-0.5, 0.5, 3)),
              Capsule(0.02, a=rng.uniform(-0.5, 0.5, 3), b=rng.uniform(-0.5, 0.5, 3)),
              Cylinder(0.04, math.inf, center=[*rng.uniform(-0.5, 0.5, 2), 0.3])):
        per_segment = clearances(robot, q, [o], link_radius=LINK_RADIUS)[:, 0]
        c = scene_clearance(robot, model, q, [o])
        assert float(c.distance) == pytest.approx(per_segment.min(), abs=1e-12)
        assert c.pair[1] == 0
        assert per_segment[c.pair[0]] == pytest.approx(per_segment.min(), abs=1e-12)


def test_scene_encoding_reads_the_shared_classes():
    """Each shape's row holds its own fields: centre, ends, rotation, half extents, plane."""
    R = Rotation.from_euler("xyz", [0.1, 0.2, 0.3]).as_matrix()
    rows = scene_shapes.encode_scene([
        Sphere(0.1, center=[1, 2, 3]), Capsule(0.2, a=[0, 0, 0], b=[1, 0, 0]),
        Box((0.2, 0.4, 0.6), center=[1, 1, 1], rotation=R), HalfSpace([0, 0, 2], -0.5),
        Cylinder(0.3, math.inf, center=[0.4, 0.5, 7.0])])
    np.testing.assert_array_equal(rows[0, :5], [0, 1, 2, 3, 0.1])
    np.testing.assert_array_equal(rows[1, :8], [1, 0, 0, 0, 1, 0, 0, 0.2])
    np.testing.assert_array_equal(rows[2, 4:13], R.ravel())
    np.testing.assert_array_equal(rows[2, 13:16], [0.1, 0.2, 0.3])
    np.testing.assert_array_equal(rows[3, :5], [3, 0, 0, 1, -0.5])
    np.testing.assert_array_equal(rows[4, :4], [4, 0.4, 0.5, 0.3])


def test_finite_or_tilted_cylinder_is_not_a_scene_shape():
    """Only infinite cylinders along z are supported in a scene: others raise, naming the item."""
    with pytest.raises(NotSupportedError, match=r"scene\[0\].*infinite along z"):
        scene_shapes.encode_scene([Cylinder(0.1, 0.5)])
    tilted = Rotation.from_euler("x", 0.3).as_matrix()
    with pytest.raises(NotSupportedError, match=r"scene\[1\]"):
        scene_shapes.encode_scene([Sphere(0.1), Cylinder(0.1, math.inf, rotation=tilted)])


def test_old_scene_names_warn_and_build_the_shared_classes():
    """collision(.shapes).Box/HalfSpace warn, name the new import and build equal objects."""
    R = Rotation.from_euler("z", 0.4).as_matrix()
    for module in (scene_shapes, serialkin.collision):
        with pytest.warns(DeprecationWarning, match=r"import Box from serialkin\.model\.geometry"):
            old_box = module.Box
        with pytest.warns(DeprecationWarning, match=r"HalfSpace from serialkin\.model\.geometry"):
            old_half = module.HalfSpace
        assert old_box([0.4, -0.35, 0.25], [0.06, 0.07, 0.08], R, name="crate") == \
            Box((0.12, 0.14, 0.16), center=[0.4, -0.35, 0.25], rotation=R, name="crate")
        assert old_box(center=[0, 0, 1], half_extents=[1, 1, 1]) == Box((2, 2, 2), center=[0, 0, 1])
        assert old_half([0, 0, 1], -0.1, "table") == HalfSpace([0, 0, 1], -0.1, name="table")
        with pytest.raises(InputError, match="half_extents must be >= 0"):
            old_box([0, 0, 0], [0.1, -0.1, 0.1])
    with pytest.warns(DeprecationWarning, match=r"serialkin\.collision\.shapes\.Box"):
        from serialkin.collision.shapes import Box as OldBox  # noqa: F401
    with pytest.raises(AttributeError, match="no attribute 'Sphere'"):
        serialkin.collision.Sphere  # noqa: B018
