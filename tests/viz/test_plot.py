"""Tests for serialkin.viz.plot: the drawn artists carry the kinematics' numbers."""

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from serialkin.errors import InputError, InputTypeError
from serialkin.model.geometry import Capsule, Cylinder, Sphere
from serialkin.viz.plot import (
    Obstacle,
    as_obstacle,
    is_3d_axes,
    joint_positions,
    plot_obstacles,
    plot_path,
    plot_robot,
    robot_points,
)


def _line(ax, gid):
    lines = [ln for ln in ax.get_lines() if ln.get_gid() == gid]
    assert len(lines) == 1, f"expected one line with gid {gid}, found {len(lines)}"
    return lines[0]


def test_planar_robot_drawn_in_2d(planar3):
    """A planar arm gets 2D axes whose link line is fk_all origins then the tool point."""
    q = np.array([0.3, -0.7, 1.1])
    ax = plot_robot(planar3, q)
    assert not is_3d_axes(ax)
    line = _line(ax, "serialkin-links")
    want = np.vstack([planar3.fk_all(q)[:, :2, 3], planar3.fk(q)[:2, 3]])
    np.testing.assert_allclose(np.c_[line.get_xdata(), line.get_ydata()], want, atol=1e-12)


@settings(max_examples=25, deadline=None)
@given(st.lists(st.floats(-3.0, 3.0), min_size=4, max_size=4))
def test_spatial_line_data_equals_fk_all(spatial4, qs):
    """For any q, the 3D link line's vertices are fk_all origins and the fk tool point."""
    import matplotlib.pyplot as plt

    q = np.array(qs)
    ax = plot_robot(spatial4, q)
    assert is_3d_axes(ax)
    x, y, z = _line(ax, "serialkin-links").get_data_3d()
    want = np.vstack([spatial4.fk_all(q)[:, :3, 3], spatial4.fk(q)[:3, 3]])
    np.testing.assert_allclose(np.c_[x, y, z], want, atol=1e-12)
    plt.close(ax.figure)


def test_joint_markers_on_joint_axes(spatial4):
    """Joint markers sit on the joint axes: for standard DH, at DH frame origins 0..n-1."""
    q = np.array([0.2, 0.4, 0.1, -0.5])
    ax = plot_robot(spatial4, q)
    x, y, z = _line(ax, "serialkin-joints").get_data_3d()
    drawn = np.c_[x, y, z]
    T = spatial4.fk_all(q)
    for i, kind in enumerate(spatial4.joint_types):
        if kind == "R":  # revolute joint i turns about z_{i-1} through DH origin i-1
            np.testing.assert_allclose(drawn[i], T[i, :3, 3], atol=1e-12)
        else:  # prismatic: the slider's end, on the axis z_{i-1}
            along = drawn[i] - T[i, :3, 3]
            np.testing.assert_allclose(np.cross(along, T[i, :3, 2]), 0.0, atol=1e-12)
    np.testing.assert_allclose(joint_positions(spatial4, q), drawn, atol=1e-12)


def test_frames_drawn_as_triads(spatial4):
    """frames=True draws one RGB triad (3 segments) per link frame plus the tool frame."""
    q = np.zeros(4)
    ax = plot_robot(spatial4, q, frames=True, frame_scale=0.1)
    for i in range(spatial4.n + 2):
        segs = [ln for ln in ax.get_lines() if ln.get_gid() == f"serialkin-frame-{i}"]
        assert len(segs) == 3
    # the tool triad's x axis points along the tool's x axis, 0.1 m long
    T = spatial4.fk(q)
    x, y, z = [ln for ln in ax.get_lines() if ln.get_gid() == f"serialkin-frame-{spatial4.n + 1}"][
        0
    ].get_data_3d()
    np.testing.assert_allclose([x[1] - x[0], y[1] - y[0], z[1] - z[0]], 0.1 * T[:3, 0], atol=1e-12)


def test_existing_axes_reused_and_planar_conflict(planar3):
    """Drawing twice into the same axes adds to it; planar=False on 2D axes is an error."""
    ax = plot_robot(planar3, np.zeros(3), label="a")
    ax2 = plot_robot(planar3, np.ones(3), ax=ax, color="C1", alpha=0.5, label="b")
    assert ax2 is ax
    assert sum(ln.get_gid() == "serialkin-links" for ln in ax.get_lines()) == 2
    with pytest.raises(InputError, match="planar"):
        plot_robot(planar3, np.zeros(3), ax=ax, planar=False)


def test_planar_robot_forced_3d(planar3):
    """planar=False draws even a planar arm in 3D, z = 0 everywhere."""
    ax = plot_robot(planar3, np.array([0.1, 0.2, 0.3]), planar=False)
    assert is_3d_axes(ax)
    _, _, z = _line(ax, "serialkin-links").get_data_3d()
    np.testing.assert_allclose(z, 0.0, atol=1e-12)


def test_bad_q_rejected(planar3):
    """Wrong length, batches and NaN are rejected with the argument named."""
    with pytest.raises(InputError, match="q"):
        plot_robot(planar3, [0.0, 1.0])
    with pytest.raises(InputError, match="one configuration"):
        plot_robot(planar3, np.zeros((2, 3)))
    with pytest.raises(InputError, match="finite"):
        plot_robot(planar3, [0.0, np.nan, 0.0])


def test_robot_points_batch(spatial4):
    """robot_points works over a batch and matches the per-configuration call."""
    Q = spatial4.random_q(5, seed=1)
    P = robot_points(spatial4, Q)
    assert P.shape == (5, spatial4.n + 2, 3)
    np.testing.assert_allclose(P[3], robot_points(spatial4, Q[3]), atol=1e-12)


class _Cyl:
    """Duck-typed obstacle like serialkin.redundancy.obstacles' cylinder."""

    def __init__(self, center, radius, height=None):
        self.center = np.asarray(center, float)
        self.radius = radius
        if height is not None:
            self.height = height


def test_obstacles_2d(planar3):
    """Circles, cylinders and capsules become patches of the right centre and radius."""
    ax = plot_robot(planar3, np.zeros(3))
    plot_obstacles(ax, [dict(center=[0.5, 0.5], radius=0.1), _Cyl([1.0, -0.5], 0.2, 1.0),
                        dict(a=[0, 1], b=[1, 1], radius=0.05)])
    patches = [p for p in ax.patches if p.get_gid() == "serialkin-obstacle"]
    assert len(patches) == 3
    assert patches[0].center == pytest.approx((0.5, 0.5))
    assert patches[0].radius == pytest.approx(0.1)
    assert patches[1].radius == pytest.approx(0.2)
    xy = patches[2].get_xy()
    d = np.abs(xy[:, 1] - 1.0)
    assert d.max() == pytest.approx(0.05, abs=1e-9)  # outline at distance r from segment


def test_obstacles_3d(spatial4):
    """In 3D each obstacle becomes one surface whose points lie at its radius."""
    ax = plot_robot(spatial4, np.zeros(4))
    plot_obstacles(ax, [dict(center=[0.3, 0.0, 0.5], radius=0.1), _Cyl([0, 0.5, 0], 0.2, 1.0),
                        dict(p0=[0, 0, 0], p1=[0, 0, 1], radius=0.1)])
    surfs = [c for c in ax.collections if c.get_gid() == "serialkin-obstacle"]
    assert len(surfs) == 3
    ob = as_obstacle(dict(p0=[0, 0, 0], p1=[0, 0, 1], radius=0.1))
    assert ob.kind == "capsule"
    np.testing.assert_allclose(ob.center, [0, 0, 0.5])


def test_obstacle_errors():
    """Obstacles without a radius, with a bad radius or bad coordinates are rejected."""
    with pytest.raises(InputTypeError, match="radius"):
        as_obstacle(dict(center=[0, 0]))
    with pytest.raises(InputError, match="radius"):
        as_obstacle(dict(center=[0, 0], radius=-1))
    with pytest.raises(InputError, match="center"):
        as_obstacle(dict(center=[0, 0, 0, 0], radius=1))


def test_plot_path_2d_and_3d(planar3, spatial4):
    """The path line holds the given points (2D points get z = 0 in 3D)."""
    P = np.c_[np.linspace(0, 1, 7), np.linspace(1, 0, 7)]
    ax = plot_path(plot_robot(planar3, np.zeros(3)), P)
    line = _line(ax, "serialkin-path")
    np.testing.assert_allclose(np.c_[line.get_xdata(), line.get_ydata()], P)
    ax3 = plot_path(plot_robot(spatial4, np.zeros(4)), P)
    x, y, z = _line(ax3, "serialkin-path").get_data_3d()
    np.testing.assert_allclose(np.c_[x, y, z], np.c_[P, np.zeros(7)])
    with pytest.raises(InputError, match="points"):
        plot_path(ax, np.zeros((3, 4)))


def test_redundancy_obstacle_classes():
    """The obstacle shapes (Cylinder/Sphere/Capsule) and their plain-data forms are drawn."""
    obstacles = pytest.importorskip("serialkin.redundancy.obstacles")
    circle = Cylinder(0.05, math.inf, center=[0.4, 0.1, 0.0], influence=0.03)
    sphere = Sphere(0.07, center=[0.1, 0.2, 0.3])
    capsule = Capsule(0.02, a=[0, 0, 0], b=[0.2, 0, 0.1])
    to_dict = obstacles.obstacle_to_dict
    for src in (circle, to_dict(circle)):
        ob = as_obstacle(src)
        assert ob.kind == "cylinder" and ob.height is None and ob.influence == 0.03
        np.testing.assert_allclose(ob.center, [0.4, 0.1, 0.0])
    for src in (sphere, to_dict(sphere)):
        assert as_obstacle(src).kind == "sphere"
    for src in (capsule, to_dict(capsule)):
        ob = as_obstacle(src)
        assert ob.kind == "capsule"
        np.testing.assert_allclose(ob.b, [0.2, 0, 0.1])


def test_obstacle_holds_the_geometry_shape():
    """as_obstacle turns every accepted form into an Obstacle holding the geometry shape."""
    cases = [
        (dict(center=[0.5, 0.5], radius=0.1, name="A"),
         Cylinder(0.1, math.inf, center=[0.5, 0.5, 0.0], influence=0.0, name="A")),
        (dict(center=[0, 0, 1], radius=0.2, height=0.5, influence=0.03),
         Cylinder(0.2, 0.5, center=[0, 0, 1], influence=0.03)),
        (dict(p0=[0, 0, 0], p1=[0, 0, 1], radius=0.1),
         Capsule(0.1, a=[0, 0, 0], b=[0, 0, 1], influence=0.0)),
        (dict(a=[1, 0, 0], b=[1, 0, 0], radius=0.1), Sphere(0.1, center=[1, 0, 0], influence=0.0)),
        (Sphere(0.07, center=[0.1, 0.2, 0.3]), Sphere(0.07, center=[0.1, 0.2, 0.3])),
        (Cylinder(0.1, 0.4, center=[0, 0, 0.2]), Cylinder(0.1, 0.4, center=[0, 0, 0.2])),
    ]
    for src, shape in cases:
        ob = as_obstacle(src)
        assert ob.shape == shape, src
        assert ob.radius == shape.radius and ob.name == shape.name
        assert ob.influence == shape.influence
    assert as_obstacle(cases[1][1]).height == 0.5  # a finite Cylinder keeps its length


def test_old_obstacle_constructor_warns():
    """The field-by-field Obstacle(kind, center, radius, ...) builds the shape and warns."""
    with pytest.warns(DeprecationWarning, match="Obstacle"):
        ob = Obstacle("capsule", np.zeros(3), 0.1, None, [0, 0, 0], [0, 0, 1], 0.02, "c")
    assert ob.shape == Capsule(0.1, a=[0, 0, 0], b=[0, 0, 1], influence=0.02, name="c")
    with pytest.raises(InputTypeError, match="Sphere, Cylinder or Capsule"):
        Obstacle(dict(center=[0, 0, 0], radius=0.1))


def test_influence_rings(planar3):
    """influence=True adds a dashed ring at radius + the obstacle's own influence."""
    ax = plot_robot(planar3, np.zeros(3))
    plot_obstacles(ax, [dict(center=[0.5, 0.5], radius=0.1, influence=0.04),
                        dict(center=[0.0, 0.5], radius=0.1)], influence=True)
    rings = [p for p in ax.patches if p.get_gid() == "serialkin-obstacle-influence"]
    assert len(rings) == 1 and rings[0].radius == pytest.approx(0.14)


def test_unknown_kind_rejected():
    """An unknown obstacle kind names the field and the valid kinds."""
    with pytest.raises(InputError, match="kind must be one of"):
        as_obstacle(dict(center=[0, 0, 0], radius=1.0, kind="cube"))


def test_package_exports_resolve():
    """Every name in serialkin.viz.__all__ resolves to a callable of its submodule."""
    import serialkin.viz as viz

    for name in viz.__all__:
        assert callable(getattr(viz, name)), name
    with pytest.raises(AttributeError):
        viz.no_such_function  # noqa: B018
