"""The one shape vocabulary: sizes, placement in a frame, equality, and link-geometry rules."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import example, given, settings
from hypothesis import strategies as st
from scipy.spatial.transform import Rotation

from serialkin.errors import InputError, InputTypeError, RobotDefinitionError
from serialkin.model.geometry import (
    DEFAULT_INFLUENCE,
    Box,
    Capsule,
    Cylinder,
    HalfSpace,
    Mesh,
    Shape,
    Sphere,
)

POINTS = st.lists(st.floats(-2.0, 2.0), min_size=3, max_size=3)


def _rotation(seed: int) -> np.ndarray:
    return Rotation.random(random_state=seed).as_matrix()


def test_sizes_alone_put_a_shape_at_its_frame_origin():
    """Sphere(r), Box(size), Cylinder(r, L), Capsule(r, L) sit at the origin along z (URDF)."""
    for g in (Sphere(0.1), Box((0.1, 0.2, 0.3)), Cylinder(0.1, 0.4), Capsule(0.1, 0.4)):
        np.testing.assert_array_equal(g.pose, np.eye(4))
        np.testing.assert_array_equal(g.center, np.zeros(3))
        assert g.influence == DEFAULT_INFLUENCE and g.name == ""
    cap = Capsule(0.05, 0.3)
    np.testing.assert_array_equal(cap.a, [0.0, 0.0, -0.15])
    np.testing.assert_array_equal(cap.b, [0.0, 0.0, 0.15])
    assert cap.length == 0.3  # exactly: URDF readers and writers round-trip it


@settings(max_examples=50, deadline=None)
@given(a=POINTS, b=POINTS, seed=st.integers(0, 2**31 - 1))
@example(a=[0.0, 0.0, 1.0], b=[1e-9, 0.0, 0.0], seed=0)  # an axis close to −z
@example(a=[0.0, 0.0, 1.0], b=[0.0, 0.0, 0.0], seed=0)  # exactly −z
def test_pose_maps_the_local_shape_onto_its_placement(a, b, seed):
    """The pose (4, 4) is a rigid transform moving the shape at the origin to its placement."""
    cap = Capsule(0.02, a=a, b=b)
    T = cap.pose
    np.testing.assert_allclose(T[:3, :3].T @ T[:3, :3], np.eye(3), atol=1e-12)
    assert np.linalg.det(T[:3, :3]) == pytest.approx(1.0)
    half = cap.length / 2.0
    np.testing.assert_allclose(T @ [0.0, 0.0, -half, 1.0], [*a, 1.0], atol=1e-12)
    np.testing.assert_allclose(T @ [0.0, 0.0, half, 1.0], [*b, 1.0], atol=1e-12)
    R = _rotation(seed)
    box = Box((0.2, 0.4, 0.6), center=a, rotation=R)
    corner = np.array([0.1, 0.2, 0.3, 1.0])
    np.testing.assert_allclose(box.pose @ corner, [*(np.asarray(a) + R @ corner[:3]), 1.0],
                               atol=1e-12)
    np.testing.assert_array_equal(box.half_extents, [0.1, 0.2, 0.3])
    cyl = Cylinder(0.1, 0.5, center=b, rotation=R)
    np.testing.assert_array_equal(cyl.axis, R[:, 2])
    np.testing.assert_allclose(cyl.pose[:3, 3], b)


def test_equality_and_hash_are_by_value_and_inputs_are_copied():
    """Equal fields: equal shapes with equal hashes; changing an input array later changes none."""
    c = np.array([0.1, 0.2, 0.3])
    s = Sphere(0.05, center=c, name="ball")
    c[0] = 9.0
    assert s == Sphere(0.05, center=[0.1, 0.2, 0.3], name="ball")
    assert hash(s) == hash(Sphere(0.05, center=(0.1, 0.2, 0.3), name="ball"))
    assert s != Sphere(0.05, center=[0.1, 0.2, 0.3], name="other")
    assert s != Sphere(0.05, center=[0.1, 0.2, 0.3], influence=0.5, name="ball")
    assert Capsule(0.1, 0.4) == Capsule(0.1, a=[0, 0, -0.2], b=[0, 0, 0.2])
    assert Box((1, 2, 3)) != Cylinder(1, 2)
    assert {Box((1, 2, 3)), Box((1.0, 2.0, 3.0))} == {Box((1, 2, 3))}


def test_infinite_cylinder_along_z():
    """A z-cylinder is infinite with its axis along z (turned about z is the same line)."""
    z_turn = Rotation.from_euler("z", 0.7).as_matrix()
    assert Cylinder(0.1, math.inf, center=[0.3, 0.2, 0.0]).infinite_along_z
    assert Cylinder(0.1, math.inf, rotation=z_turn).infinite_along_z
    assert not Cylinder(0.1, 2.0).infinite_along_z
    assert not Cylinder(0.1, math.inf, rotation=Rotation.from_euler("x", 0.2).as_matrix()
                        ).infinite_along_z


def test_half_space_normal_is_normalised():
    """HalfSpace keeps the unit normal and its offset along it."""
    h = HalfSpace([0.0, 0.0, 2.0], -0.1, name="table")
    np.testing.assert_array_equal(h.normal, [0.0, 0.0, 1.0])
    assert h.offset == -0.1 and h.name == "table"


def test_link_geometry_is_placed_by_the_shape_origin_only():
    """A Shape refuses a placed or unbounded geometry and names what to do instead."""
    T = np.eye(4)
    T[:3, 3] = [0.0, 0.0, 0.1]
    assert Shape(Sphere(0.05), T).origin[2, 3] == 0.1
    with pytest.raises(RobotDefinitionError, match="placed by the Shape's origin"):
        Shape(Sphere(0.05, center=[0.0, 0.0, 0.1]))
    with pytest.raises(RobotDefinitionError, match="placed by the Shape's origin"):
        Shape(Capsule(0.05, a=[0, 0, 0], b=[0.1, 0, 0]))
    with pytest.raises(RobotDefinitionError, match="cylinder length"):
        Shape(Cylinder(0.05, math.inf))
    with pytest.raises(RobotDefinitionError, match="expected a Box, Cylinder"):
        Shape(HalfSpace([0, 0, 1]))


def test_bad_fields_name_the_field():
    """Sizes raise RobotDefinitionError, placement and labels InputError, naming the field."""
    with pytest.raises(RobotDefinitionError, match="sphere radius"):
        Sphere(-0.1)
    with pytest.raises(RobotDefinitionError, match="cylinder length"):
        Cylinder(0.1, float("nan"))
    with pytest.raises(InputError, match="center must be a vector of 3"):
        Sphere(0.1, center=[0.0, 0.0])
    with pytest.raises(InputError, match="rotation"):
        Box((1, 1, 1), rotation=2 * np.eye(3))
    with pytest.raises(InputError, match="influence"):
        Capsule(0.1, 0.2, influence=-1.0)
    with pytest.raises(InputTypeError, match="name must be a string"):
        Cylinder(0.1, 0.2, name=3)
    with pytest.raises(InputError, match="not both"):
        Capsule(0.1, 0.2, a=[0, 0, 0], b=[1, 0, 0])
    with pytest.raises(InputError, match="both ends"):
        Capsule(0.1, a=[0, 0, 0])
    with pytest.raises(TypeError):
        Box([0.4, -0.35, 0.25], [0.06, 0.06, 0.06])  # the old (center, half_extents) order


def test_primitive_mesh_is_placed_like_its_shape():
    """primitive_mesh of a placed shape is the mesh at the origin moved by the shape's pose."""
    pytest.importorskip("trimesh")
    from serialkin.formats.mesh import primitive_mesh

    R = _rotation(3)
    for placed, local in (
            (Box((0.1, 0.2, 0.3), center=[1, 2, 3], rotation=R), Box((0.1, 0.2, 0.3))),
            (Capsule(0.05, a=[0, 0, 0], b=[0.3, 0.1, 0.2]),
             Capsule(0.05, float(np.linalg.norm([0.3, 0.1, 0.2])))),
            (Sphere(0.2, center=[0.5, 0, 0]), Sphere(0.2))):
        m, m0 = primitive_mesh(placed), primitive_mesh(local)
        T = placed.pose
        np.testing.assert_allclose(m.vertices, m0.vertices @ T[:3, :3].T + T[:3, 3],
                                   atol=1e-12)
    assert isinstance(Mesh("x.stl").scale, tuple)
