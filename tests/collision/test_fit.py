"""Capsule fitting (serialkin.collision.fit): containment, tightness, gap, robot models."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from serialkin import Robot
from serialkin.collision import acm_from_srdf, read_srdf, self_clearance
from serialkin.collision.fit import (
    bounding_capsule,
    capsule_volume,
    collision_model_from_geometry,
    fit_points,
    fit_shape,
    max_gap,
)
from serialkin.errors import InputError, RobotDefinitionError
from serialkin.model.geometry import Box, Capsule, Cylinder, Shape, Sphere
from tests.erd import robots_dir, urdf


def _segment_distance(P: np.ndarray, a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Distance of each point of P (k, 3) to the segment ab."""
    d = b - a
    dd = float(d @ d)
    t = np.zeros(len(P)) if dd == 0 else np.clip((P - a) @ d / dd, 0.0, 1.0)
    return np.linalg.norm(P - (a + t[:, None] * d), axis=1)


def _inside_union(P: np.ndarray, capsules) -> np.ndarray:
    """True for points of P inside at least one capsule (1e-9 m tolerance)."""
    return np.any([_segment_distance(P, a, b) <= r + 1e-9 for a, b, r in capsules], axis=0)


@settings(max_examples=40, deadline=None)
@given(seed=st.integers(0, 2**31), k=st.integers(1, 60),
       stretch=st.tuples(*[st.floats(0.01, 2.0)] * 3))
def test_bounding_capsule_contains_every_point(seed: int, k: int, stretch) -> None:
    """Every point of a random (stretched, rotated) cloud is inside its bounding capsule."""
    rng = np.random.default_rng(seed)
    Q, _ = np.linalg.qr(rng.normal(size=(3, 3)))
    P = rng.normal(size=(k, 3)) * np.asarray(stretch) @ Q.T + rng.normal(size=3)
    a, b, r = bounding_capsule(P)
    assert np.all(_segment_distance(P, a, b) <= r + 1e-12)


def test_bounding_capsule_of_a_capsule_cloud_is_that_capsule() -> None:
    """Points on a capsule's surface give back (nearly) that capsule: tight fit."""
    rng = np.random.default_rng(3)
    u = rng.normal(size=(4000, 3))
    u /= np.linalg.norm(u, axis=1, keepdims=True)
    P = u * 0.1
    P[:, 2] += np.where(P[:, 2] > 0, 0.25, -0.25)  # segment (0,0,±0.25), radius 0.1
    a, b, r = bounding_capsule(P)
    assert r == pytest.approx(0.1, abs=2e-3)
    assert np.linalg.norm(b - a) == pytest.approx(0.5, abs=5e-3)
    assert max_gap((a, b, r), P) < 5e-3


def test_max_gap_is_the_hausdorff_distance_to_an_inner_sphere() -> None:
    """A capsule around a concentric sphere ρ: the gap is L/2 + r − ρ (the tip's distance)."""
    rng = np.random.default_rng(0)
    u = rng.normal(size=(5000, 3))
    S = 0.05 * u / np.linalg.norm(u, axis=1, keepdims=True)
    cap = (np.array([0, 0, -0.2]), np.array([0, 0, 0.2]), 0.08)
    assert max_gap(cap, S) == pytest.approx(0.2 + 0.08 - 0.05, abs=1e-3)


def test_l_shape_is_split_into_tighter_capsules_that_cover_it() -> None:
    """An L-shaped bar gets several capsules, smaller than one, still covering every point."""
    rng = np.random.default_rng(1)
    bar1 = rng.uniform([0, 0, 0], [1.0, 0.1, 0.1], (400, 3))
    bar2 = rng.uniform([0, 0, 0], [0.1, 1.0, 0.1], (400, 3))
    P = np.vstack([bar1, bar2])
    one = bounding_capsule(P)
    caps, pieces, hull_volume = fit_points(P, max_capsules=4)
    assert len(caps) >= 2 and len(pieces) == len(caps)
    assert sum(capsule_volume(*c) for c in caps) < 0.8 * capsule_volume(*one)
    assert np.all(_inside_union(P, caps))
    assert 0 < hull_volume < capsule_volume(*one)
    assert len(fit_points(P, max_capsules=1)[0]) == 1


def test_primitives_are_used_as_they_are_or_bounded() -> None:
    """Sphere and capsule: exact, gap 0; box and cylinder: bounding capsule holding them."""
    T = np.eye(4)
    T[:3, 3] = [0.1, 0.2, 0.3]
    f = fit_shape(Shape(Sphere(0.05), T), "l", 2)
    (a, b, r), = f.capsules
    assert np.array_equal(a, b) and np.allclose(a, [0.1, 0.2, 0.3]) and r == 0.05
    assert f.max_gap == 0.0 and f.volume_ratio == 1.0 and f.frame == 2
    f = fit_shape(Shape(Capsule(0.05, 0.4), T))
    (a, b, r), = f.capsules
    np.testing.assert_allclose(sorted([a[2], b[2]]), [0.1, 0.5])
    box = fit_shape(Shape(Box((0.1, 0.2, 0.6)), T))
    corners = np.array([[x, y, z] for x in (-.05, .05) for y in (-.1, .1) for z in (-.3, .3)])
    assert np.all(_inside_union(corners + T[:3, 3], box.capsules))
    assert box.volume_ratio > 1.0 and box.max_gap > 0.0
    cyl = fit_shape(Shape(Cylinder(0.1, 0.5)))
    ang = np.linspace(0, 2 * math.pi, 1000)
    rim = np.array([[0.1 * math.cos(t), 0.1 * math.sin(t), z] for t in ang
                    for z in (-0.25, 0.25)])
    assert np.all(_inside_union(rim, cyl.capsules))
    assert cyl.shape_volume == pytest.approx(math.pi * 0.01 * 0.5)


URDF = """<robot name="r">
  <link name="base"><collision><geometry><box size="0.3 0.3 0.1"/></geometry></collision></link>
  <link name="l1">
    <collision><origin xyz="0.25 0 0" rpy="0 1.5707963267948966 0"/>
      <geometry><cylinder radius="0.05" length="0.5"/></geometry></collision>
    <collision><origin xyz="0.5 0 0"/><geometry><sphere radius="0.06"/></geometry></collision>
  </link>
  <link name="l2"><visual><geometry><sphere radius="0.06"/></geometry></visual></link>
  <joint name="j1" type="revolute"><parent link="base"/><child link="l1"/>
    <origin xyz="0 0 0.1"/><axis xyz="0 0 1"/>
    <limit lower="-2" upper="2" effort="1" velocity="1"/></joint>
  <joint name="j2" type="revolute"><parent link="l1"/><child link="l2"/>
    <origin xyz="0.5 0 0"/><axis xyz="0 0 1"/>
    <limit lower="-2" upper="2" effort="1" velocity="1"/></joint>
</robot>"""


def test_model_from_urdf_primitives_has_a_body_per_link_with_shapes() -> None:
    """Bodies are the links with collision shapes, on their frames; spheres stay spheres."""
    robot = Robot.from_urdf(URDF, tip_link="l2")
    model, report = collision_model_from_geometry(robot)
    assert model.body_names == ("base", "l1")
    assert model.body_frames.tolist() == [0, 1]
    assert len(report.fits) == 3 and report.capsule_count == len(model.radius) >= 3
    sphere = int(np.flatnonzero(model.radius == 0.06)[0])
    np.testing.assert_allclose(model.a[sphere], [0.5, 0, 0], atol=1e-12)
    assert "ratio" in report.table() and "l1" in report.table()
    fitted, rep = robot.fit_collision()
    assert fitted.collision is not None and fitted.collision.body_names == model.body_names
    assert rep.max_gap == report.max_gap
    visual, _ = collision_model_from_geometry(robot, "visual")
    assert visual.body_names == ("l2",)


def test_no_geometry_or_bad_options_are_clear_errors() -> None:
    """A robot without geometry, an unknown link or bad options raise InputError."""
    bare = Robot.from_dh([{"a": 1, "alpha": 0, "d": 0, "theta": 0}])
    with pytest.raises(InputError, match="no collision geometry"):
        bare.fit_collision()
    robot = Robot.from_urdf(URDF, tip_link="l2")
    with pytest.raises(InputError, match="unknown link 'l9'"):
        collision_model_from_geometry(robot, links=["l9"])
    with pytest.raises(InputError, match="kind"):
        collision_model_from_geometry(robot, "visuals")
    with pytest.raises(InputError, match="loose"):
        collision_model_from_geometry(robot, loose=0.5)


def test_missing_mesh_in_fit_names_the_link(tmp_path) -> None:
    """Fitting a link whose mesh file is gone names the link and the file."""
    text = URDF.replace('<box size="0.3 0.3 0.1"/>',
                        f'<mesh filename="{tmp_path / "gone.stl"}"/>')
    robot = Robot.from_urdf(text, tip_link="l2")
    pytest.importorskip("trimesh")
    with pytest.raises(RobotDefinitionError, match=r"link 'base'.*gone\.stl"):
        collision_model_from_geometry(robot)


def _panda_from_urdf():
    path = urdf("panda_description/urdf/panda.urdf")
    if path is None:
        pytest.skip("example-robot-data (bench extra) is not installed")
    pytest.importorskip("trimesh")
    return Robot.from_urdf(str(path), tip_link="panda_hand", resolve_meshes=True,
                           package_map={"example-robot-data": robots_dir().parent})


def test_panda_meshes_are_contained_and_the_fit_reported() -> None:
    """Every Panda collision-mesh vertex lies in its link's capsules; ratio ≥ 1, gap > 0."""
    from serialkin.formats.mesh import link_meshes

    robot = _panda_from_urdf()
    model, report = collision_model_from_geometry(robot)
    assert len(model.body_names) == 9
    for lm in link_meshes(robot, "collision"):
        bi = model.body_index(lm.link_name)
        caps = [(model.a[s], model.b[s], model.radius[s])
                for s in np.flatnonzero(model.shape_body == bi)]
        assert np.all(_inside_union(lm.mesh.vertices, caps)), lm.link_name
    for f in report.fits:
        assert 1.0 < f.volume_ratio < 4.0 and 0.0 < f.max_gap < 0.1


def test_panda_fitted_from_urdf_is_free_at_default_and_collides_folded() -> None:
    """Capsules fitted from the URDF meshes: SRDF 'default' state free, folded arm collides."""
    robot = _panda_from_urdf()
    fitted, _ = robot.fit_collision()
    srdf = read_srdf(robots_dir() / "panda_description" / "srdf" / "panda.srdf")
    with pytest.raises(RobotDefinitionError, match="panda_leftfinger.*skip_links"):
        acm_from_srdf(fitted.collision, srdf)  # the fingers are off the chain: no bodies
    acm = acm_from_srdf(fitted.collision, srdf,
                        skip_links=["panda_leftfinger", "panda_rightfinger"])
    state = srdf.group_state("default")
    q = np.array([state[f"panda_joint{i}"] for i in range(1, 8)])
    assert self_clearance(fitted, fitted.collision, q, acm).distance > 0
    folded = np.array([0.0, 0.0, 0.0, -3.0, 0.0, 0.5, 0.0])
    assert self_clearance(fitted, fitted.collision, folded, acm).distance < 0


def test_refined_axis_is_never_larger_and_still_contains() -> None:
    """The direction search never gives a larger capsule than the principal axes; it holds P."""
    rng = np.random.default_rng(5)
    # an elbow: two bars at 120°, whose principal axis is not the best capsule axis
    t = rng.uniform(0, 1, (300, 1))
    bar1 = t * [0.3, 0, 0] + rng.normal(0, 0.01, (300, 3))
    bar2 = [0.3, 0, 0] + t * [-0.1, 0.17, 0] + rng.normal(0, 0.01, (300, 3))
    P = np.vstack([bar1, bar2])
    plain, refined = bounding_capsule(P, refine=False), bounding_capsule(P)
    assert capsule_volume(*refined) <= capsule_volume(*plain) * (1 + 1e-12)
    assert np.all(_segment_distance(P, refined[0], refined[1]) <= refined[2] + 1e-12)


def test_merge_fits_a_links_boxes_together() -> None:
    """merge=True: the three boxes of a link become one cloud; spheres stay spheres."""
    text = URDF.replace(
        '<collision><geometry><box size="0.3 0.3 0.1"/></geometry></collision>',
        "".join(f'<collision><origin xyz="0 0 {z}"/><geometry><box size="0.05 0.05 0.05"/>'
                "</geometry></collision>" for z in (0.0, 0.05, 0.1)))
    robot = Robot.from_urdf(text, tip_link="l2")
    apart, rep_apart = collision_model_from_geometry(robot)
    merged, rep_merged = collision_model_from_geometry(robot, merge=True)
    base = merged.body_index("base")
    assert int((apart.shape_body == base).sum()) == 3
    assert int((merged.shape_body == base).sum()) == 1
    assert [f.shape for f in rep_merged.fits if f.link_name == "base"] == ["3 shapes merged"]
    assert len(rep_merged.fits) == 3 and len(rep_apart.fits) == 5
