"""The viewer's page data for the robot's body: shapes, embedded meshes, capsules, points."""

from __future__ import annotations

import base64
import json
import re
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from hypothesis.extra.numpy import arrays

from serialkin import models
from serialkin.collision import acm_from_srdf, default_acm, self_clearance
from serialkin.collision.queries import checked_shape_pairs
from serialkin.errors import InputError, RobotDefinitionError
from serialkin.viz.viewer import (
    MESH_BUDGET,
    Scene,
    ViewerOptions,
    _encode_mesh,
    viewer_data,
    viewer_html,
)
from tests.erd import urdf as erd_urdf
from tests.viz._body import SHAPES, body_robot

FOLDED = np.array([0.0, 0.0, 0.0, -3.0, 0.0, 0.5, 0.0])  # the Panda's elbow folded


def _decode(m: dict) -> tuple[np.ndarray, np.ndarray]:
    """Vertices (V, 3) and faces (F, 3) of an embedded mesh, decoded as the page does."""
    u = np.frombuffer(base64.b64decode(m["positions"]), dtype="<u2").reshape(-1, 3)
    idx = np.frombuffer(base64.b64decode(m["indices"]),
                        dtype="<u4" if m["index_bytes"] == 4 else "<u2").reshape(-1, 3)
    return np.asarray(m["lo"]) + np.asarray(m["step"]) * u, idx.astype(np.int64)


def _page_data(page: str) -> dict:
    m = re.search(r'<script type="application/json" id="serialkin-data">(.*?)</script>', page,
                  re.S)
    assert m is not None
    return json.loads(m.group(1))


@pytest.fixture(scope="module")
def body(tmp_path_factory):
    """The URDF robot with a box, cylinder, mesh, capsule and sphere."""
    return body_robot(tmp_path_factory.mktemp("body"))


@settings(max_examples=40, deadline=None)
@given(arrays(np.float64, st.tuples(st.integers(1, 40), st.just(3)),
              elements=st.floats(-2.0, 2.0)))
def test_quantised_positions_within_half_a_step(v):
    """Decoded positions are within step/2 (+ rounding) of the originals, per coordinate."""
    faces = np.zeros((1, 3), dtype=np.int64)
    m = _encode_mesh(v, faces)
    got, f = _decode(m)
    step = np.asarray(m["step"])
    assert np.all(np.abs(got - v) <= step / 2 + 1e-12)
    span = np.ptp(v, axis=0)
    np.testing.assert_allclose(step[span > 0], span[span > 0] / 65535, rtol=1e-12)
    np.testing.assert_array_equal(f, faces)


def test_wide_meshes_use_32_bit_indices():
    """More than 65536 vertices switch the indices to uint32 and they decode exactly."""
    v = np.random.default_rng(0).uniform(size=(70000, 3))
    faces = np.array([[0, 65540, 69999], [1, 2, 3]])
    m = _encode_mesh(v, faces)
    assert m["index_bytes"] == 4
    np.testing.assert_array_equal(_decode(m)[1], faces)


def test_shapes_posed_in_their_frames(body):
    """Every visual shape reaches the page with its link, kind, frame and origin exactly."""
    data = viewer_data(Scene(body))
    assert [(s["link"], s["kind"]) for s in data["shapes"]] == SHAPES
    expected = [(lg.frame, s) for lg in body.geometry for s in lg.visual]
    for sh, (frame, shape) in zip(data["shapes"], expected, strict=True):
        assert sh["frame"] == frame
        np.testing.assert_array_equal(np.reshape(sh["origin"], (4, 4)), shape.origin)
    sizes = {s["kind"]: s for s in data["shapes"]}
    assert sizes["box"]["size"] == [0.3, 0.2, 0.1]
    assert (sizes["cylinder"]["radius"], sizes["cylinder"]["length"]) == (0.05, 0.3)
    assert (sizes["capsule"]["radius"], sizes["capsule"]["length"]) == (0.04, 0.3)
    assert sizes["sphere"]["rgba"] == [0.9, 0.1, 0.1, 0.8]


def test_mesh_embedded_with_scale_and_all_triangles(body):
    """A mesh under the budget keeps its triangles; decoded vertices are the scaled file's."""
    from serialkin.formats.mesh import load_mesh

    data = viewer_data(Scene(body))
    (m,) = data["meshes"]
    shape = next(s for lg in body.geometry for s in lg.visual if s.name == "ball")
    ref = load_mesh(shape.geometry.filename, shape.geometry.scale)
    v, f = _decode(m)
    assert f.shape == ref.faces.shape
    step = np.asarray(m["step"])
    # each decoded triangle is a file triangle to within half a quantisation step
    tri, ref_tri = v[f], ref.vertices[ref.faces]
    assert np.abs(np.sort(tri.reshape(-1, 3), axis=0)
                  - np.sort(ref_tri.reshape(-1, 3), axis=0)).max() <= step.max() / 2 + 1e-12
    assert np.ptp(v, axis=0) == pytest.approx([0.16, 0.16, 0.2], rel=1e-3)  # radius 1 · scale


def test_budget_decimates_all_meshes_together(body):
    """With a small budget the embedded meshes hold at most that many triangles in all."""
    data = viewer_data(Scene(body), ViewerOptions(mesh_budget=100))
    assert 0 < sum(m["faces"] for m in data["meshes"]) <= 100
    with pytest.raises(InputError, match="mesh_budget"):
        ViewerOptions(mesh_budget=2)


def test_no_meshes_keeps_primitives(body):
    """meshes=False leaves the mesh out but keeps the primitive shapes."""
    data = viewer_data(Scene(body), ViewerOptions(meshes=False))
    assert data["meshes"] == []
    assert [s["kind"] for s in data["shapes"]] == [k for _, k in SHAPES if k != "mesh"]


def test_unresolved_mesh_names_link_and_path(tmp_path):
    """A URDF loaded without its package map: the error names the link, the path and the fix."""
    from serialkin import Robot
    from tests.viz._body import write_package

    urdf = write_package(tmp_path, inside=False)
    robot = Robot.from_urdf(str(urdf), tip_link="tcp")
    with pytest.raises(RobotDefinitionError,
                       match=r"link 'LINK1' visual mesh: package://bodypkg/meshes/ball\.stl"
                             r".*package_map="):
        viewer_data(Scene(robot))
    data = viewer_data(Scene(robot), ViewerOptions(meshes=False))
    assert [s["kind"] for s in data["shapes"]] == ["box", "cylinder", "capsule", "sphere"]


def test_link_and_label_markup_escaped(tmp_path):
    """A link name and a points label with markup stay inert in the page and round-trip."""
    evil = "</script><script>alert(1)</script>"
    robot = body_robot(tmp_path, link1=evil)
    page = viewer_html(Scene(robot, points=np.zeros((2, 3)), points_label=evil))
    assert evil not in page
    data = _page_data(page)
    assert data["shapes"][1]["link"] == evil and data["points"]["label"] == evil


def test_collision_pairs_are_the_checked_pairs():
    """The page checks exactly the shape pairs self_clearance checks (default and SRDF ACM)."""
    panda = models.panda()
    model = panda.collision
    col = viewer_data(Scene(panda))["collision"]
    pa, pb = checked_shape_pairs(model, default_acm(model))
    assert col["pairs"] == np.stack([pa, pb], axis=1).tolist()
    np.testing.assert_array_equal(col["frame"], model.shape_frame)
    np.testing.assert_array_equal(col["a"], model.a)
    assert col["bodies"] == list(model.body_names) and col["show"] is False
    srdf = erd_urdf("panda_description/srdf/panda.srdf")
    if srdf is not None:
        acm = acm_from_srdf(model, srdf)
        fewer = viewer_data(Scene(panda, acm=acm),
                            ViewerOptions(show_collision=True))["collision"]
        pa2, _ = checked_shape_pairs(model, acm)
        assert len(fewer["pairs"]) == len(pa2) <= len(pa) and fewer["show"] is True
    assert self_clearance(panda, model, FOLDED).distance < 0  # the browser test's premise


def test_collision_options_refused_when_meaningless(spatial4):
    """show_collision or acm without a model, or a model on missing frames, raise InputError."""
    assert viewer_data(Scene(spatial4))["collision"] is None
    assert viewer_data(Scene(models.panda(), collision=False))["collision"] is None
    with pytest.raises(InputError, match="no collision model"):
        viewer_data(Scene(spatial4), ViewerOptions(show_collision=True))
    with pytest.raises(InputError, match="no collision model"):
        Scene(spatial4, collision=True)
    with pytest.raises(InputError, match="acm"):
        Scene(spatial4, acm=default_acm(models.panda().collision))
    with pytest.raises(InputError, match="frames 0..4"):
        Scene(spatial4, collision=models.panda().collision)


def test_points_layer_encoded():
    """Points decode to float32 positions and 8-bit colours; bad shapes and ranges raise."""
    P = np.random.default_rng(1).normal(size=(50, 3))
    C = np.random.default_rng(2).uniform(size=(50, 3))
    scene = Scene(models.planar(3), points=P, point_colors=C, points_label="reach")
    pts = viewer_data(scene)["points"]
    got = np.frombuffer(base64.b64decode(pts["positions"]), dtype="<f4").reshape(-1, 3)
    np.testing.assert_array_equal(got, P.astype(np.float32))
    rgb = np.frombuffer(base64.b64decode(pts["colors"]), dtype="u1").reshape(-1, 3)
    assert np.abs(rgb / 255 - C).max() <= 0.5 / 255 + 1e-12
    assert pts["count"] == 50 and pts["label"] == "reach"
    with pytest.raises(InputError, match="points"):
        Scene(models.planar(3), points=np.zeros((4, 2)))
    with pytest.raises(InputError, match="point_colors"):
        Scene(models.planar(3), points=P, point_colors=C[:5])
    with pytest.raises(InputError, match=r"point_colors must be in \[0, 1\]"):
        Scene(models.planar(3), points=P, point_colors=2 * C)
    with pytest.raises(InputError, match="without points"):
        Scene(models.planar(3), point_colors=C)


def test_panda_with_meshes_within_five_megabytes():
    """The Panda of example-robot-data with its nine visual meshes: a page of at most 5 MB."""
    pytest.importorskip("trimesh", reason='needs the mesh extra (serialkin[mesh])')
    path = erd_urdf("panda_description/urdf/panda.urdf")
    if path is None:
        pytest.skip("example-robot-data (bench extra) is not installed")
    from serialkin import Robot

    robot = Robot.from_urdf(str(path), "panda_link0", "panda_hand",
                            package_map={"example-robot-data": Path(path).parents[3]},
                            resolve_meshes=True)
    page = viewer_html(Scene(robot))
    data = _page_data(page)
    assert sum(s["kind"] == "mesh" for s in data["shapes"]) == 9
    assert sum(m["faces"] for m in data["meshes"]) <= MESH_BUDGET
    assert len(page.encode("utf-8")) <= 5_000_000
