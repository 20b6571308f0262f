"""Tests for serialkin.viz.viewer: the page embeds the robot's chain data and three.js."""

import dataclasses
import json
import re
import warnings

import numpy as np
import pytest

from serialkin import Joint, Robot, models
from serialkin.collision import default_acm
from serialkin.errors import InputError, InputTypeError, OutputError
from serialkin.viz.viewer import (
    THREE_REVISION,
    Scene,
    ViewerOptions,
    viewer_data,
    viewer_html,
    write_viewer,
)


def _page_data(page: str) -> dict:
    m = re.search(r'<script type="application/json" id="serialkin-data">(.*?)</script>', page,
                  re.S)
    assert m is not None
    return json.loads(m.group(1))


def test_page_embeds_chain_data_exactly(spatial4):
    """The JSON in the page holds F, L, meta bit-for-bit and the initial q."""
    q = np.array([0.1, -0.2, 0.15, 0.3])
    data = _page_data(viewer_html(Scene(spatial4, q=q)))
    np.testing.assert_array_equal(np.array(data["F"]), spatial4.chain.F)
    np.testing.assert_array_equal(np.array(data["L"]), spatial4.chain.L)
    np.testing.assert_array_equal(np.array(data["meta"]), spatial4.chain.meta)
    assert data["q"] == q.tolist()
    assert data["n"] == 4 and data["joint_types"] == ["R", "R", "P", "R"]
    assert data["qlim"][2] == [0.0, 0.3] and data["qlim"][0] == [None, None]


def test_page_embeds_three_js_and_viewer_code(planar3):
    """The page is self-contained: three.js module text inline, no external src/href."""
    from importlib import resources

    page = viewer_html(Scene(planar3))
    lib = resources.files("serialkin.viz").joinpath("assets", "three.module.min.js").read_text()
    assert lib in page
    assert f'const t="{THREE_REVISION}"' in lib  # the revision we document
    assert "window.serialkin" in page
    assert not re.search(r'<script[^>]+src=', page)
    assert not re.search(r'href="(?!data:)', page)


def test_licence_file_shipped():
    """three.js's MIT licence is vendored next to the library."""
    from importlib import resources

    text = resources.files("serialkin.viz").joinpath("assets", "three.LICENSE").read_text()
    assert "MIT License" in text and "three.js authors" in text


def test_trajectory_path_obstacles_in_data(planar3):
    """Trajectory rows, 2D path points (z = 0) and obstacles reach the page data."""
    Q = planar3.random_q(6, seed=3)
    path = np.c_[np.linspace(0, 1, 5), np.linspace(0, 0.5, 5)]
    obs = [dict(center=[0.5, 0.5, 0.0], radius=0.1), dict(center=[0, 1], radius=0.2, height=0.5)]
    data = viewer_data(Scene(planar3, trajectory=Q, path_points=path, obstacles=obs))
    np.testing.assert_array_equal(np.array(data["trajectory"]), Q)
    assert data["q"] == Q[0].tolist()
    np.testing.assert_array_equal(np.array(data["path_points"]), np.c_[path, np.zeros(5)])
    assert [o["kind"] for o in data["obstacles"]] == ["sphere", "cylinder"]
    assert data["obstacles"][1]["height"] == 0.5
    lo, hi = np.array(data["slider_limits"]).T
    assert np.all(lo <= Q.min(axis=0)) and np.all(hi >= Q.max(axis=0))
    assert data["planar"] is True


def test_default_q_respects_limits():
    """Without q or trajectory the page starts at zeros clipped into the joint limits."""
    r = Robot.from_dh([dict(a=0.3, alpha=0.0, d=0.0, theta=0.0, qlim=(0.2, 1.0)),
                       dict(a=0.2, alpha=0.0, d=0.0, theta=0.0)])
    assert viewer_data(Scene(r))["q"] == [0.2, 0.0]


def test_markup_cannot_break_out_of_script():
    """A robot name with '</script>' is escaped in the title and in the JSON."""
    evil = "</script><script>alert(1)</script>"
    r = Robot.from_joints([Joint(name="j1")], name=evil)
    page = viewer_html(Scene(r, title=evil))
    assert evil not in page
    assert _page_data(page)["name"] == evil


def test_bad_inputs_named(spatial4):
    """Wrong trajectory/q/path shapes raise InputError naming the argument."""
    with pytest.raises(InputError, match="trajectory"):
        Scene(spatial4, trajectory=np.zeros((3, 2)))
    with pytest.raises(InputError, match="trajectory"):
        Scene(spatial4, trajectory=np.zeros(4))
    with pytest.raises(InputError, match="q"):
        Scene(spatial4, q=np.zeros((2, 4)))
    with pytest.raises(InputError, match="path_points"):
        Scene(spatial4, path_points=np.zeros((3, 5)))
    with pytest.raises(InputError, match="finite"):
        Scene(spatial4, q=[0, np.inf, 0, 0])


def test_write_viewer_atomic(tmp_path, planar3):
    """write_viewer creates folders, writes the page and leaves no temporary file."""
    out = write_viewer(Scene(planar3, q=[0.1, 0.2, 0.3]), tmp_path / "a" / "b" / "view.html")
    assert out.read_text(encoding="utf-8").startswith("<!doctype html>")
    assert [p.name for p in out.parent.iterdir()] == ["view.html"]


def test_write_viewer_unwritable(tmp_path, planar3):
    """An output folder that cannot be created gives an OutputError naming the path."""
    blocker = tmp_path / "file"
    blocker.write_text("x")
    with pytest.raises(OutputError, match="cannot write"):
        write_viewer(Scene(planar3), blocker / "sub" / "view.html")


def _old_and_new_pages(robot, old_keywords, scene, options):
    """The page of the deprecated keyword form (and its warnings) and of the Scene form."""
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        old = viewer_html(robot, **old_keywords)
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # the new form does not warn
        new = viewer_html(scene, options)
    return old, new, caught


def test_old_keyword_form_warns_and_gives_the_same_page():
    """The robot-first keyword form warns, naming the Scene form, and writes the same bytes."""
    panda = models.panda()
    Q = panda.random_q(5, seed=4)
    P = np.random.default_rng(3).uniform(-0.5, 0.5, (20, 3))
    obstacles = [dict(center=[0.4, 0.0, 0.3], radius=0.1)]
    acm = default_acm(panda.collision)
    old, new, caught = _old_and_new_pages(
        panda,
        dict(trajectory=Q, path_points=panda.fk(Q)[:, :3, 3], obstacles=obstacles,
             title="pick", acm=acm, points=P, points_label="cloud", show_collision=True,
             meshes=False, mesh_budget=1000),
        Scene(panda, trajectory=Q, path_points=panda.fk(Q)[:, :3, 3], obstacles=obstacles,
              title="pick", acm=acm, points=P, points_label="cloud"),
        ViewerOptions(show_collision=True, meshes=False, mesh_budget=1000))
    assert old == new
    assert [w.category for w in caught] == [DeprecationWarning]
    message = str(caught[0].message)
    assert "viewer_html(Scene(robot, ...), ViewerOptions(...))" in message
    assert caught[0].filename == __file__  # points at the caller, not into serialkin


def test_old_positional_form_and_every_function_warn(tmp_path, spatial4):
    """viewer_data, viewer_html and write_viewer accept the old positional order, warning."""
    q = [0.1, -0.2, 0.15, 0.3]
    scene = Scene(spatial4, q=q, title="t")
    with pytest.warns(DeprecationWarning, match=r"viewer_data\(Scene\(robot"):
        data = viewer_data(spatial4, q, None, None, None, "t")
    assert data == viewer_data(scene)
    with pytest.warns(DeprecationWarning, match=r"write_viewer\(Scene\(robot, \.\.\.\), path"):
        old = write_viewer(spatial4, tmp_path / "old.html", q, title="t")
    new = write_viewer(scene, tmp_path / "new.html")
    assert old.read_bytes() == new.read_bytes()
    with pytest.warns(DeprecationWarning, match="viewer_html"):
        assert viewer_html(spatial4, q=q, title="t") == viewer_html(scene)


def test_calls_mixing_or_misnaming_the_forms_are_refused(spatial4):
    """A Scene with old keywords, a wrong options type, unknown keywords raise InputTypeError."""
    scene = Scene(spatial4)
    with pytest.raises(InputTypeError, match="got a Scene and also q="):
        viewer_html(scene, q=[0, 0, 0, 0])
    with pytest.raises(InputTypeError, match="options must be a ViewerOptions or None, got dict"):
        viewer_html(scene, {"meshes": False})
    with pytest.raises(InputTypeError, match="scene must be a Scene, got str 'spatial4'"):
        viewer_html("spatial4")
    with pytest.raises(InputTypeError, match="unknown argument.*colour.*expected Scene fields"):
        viewer_html(spatial4, colour="red")
    with pytest.raises(InputTypeError, match="at most 5 positional arguments"):
        viewer_html(spatial4, None, None, None, None, None, "extra")


def test_scene_checks_its_fields(spatial4):
    """Scene names the field, what it expects and what came, with the library's error classes."""
    with pytest.raises(InputTypeError, match="robot must be a serialkin Robot, got str 'ur5'"):
        Scene("ur5")
    with pytest.raises(InputError, match=r"trajectory has 2 values .* 4 joints"):
        Scene(spatial4, trajectory=np.zeros((3, 2)))
    with pytest.raises(InputTypeError, match="obstacles must be a list .* got dict"):
        Scene(spatial4, obstacles={"center": [0, 0, 0], "radius": 0.1})
    with pytest.raises(InputError, match=r"obstacles\[1\]\.radius must be .* > 0, got -1"):
        Scene(spatial4, obstacles=[dict(center=[0, 0, 0], radius=0.1),
                                   dict(center=[1, 0, 0], radius=-1)])
    with pytest.raises(InputTypeError, match="title must be a string or None, got int 3"):
        Scene(spatial4, title=3)
    with pytest.raises(InputTypeError, match="points_label must be a string, got NoneType"):
        Scene(spatial4, points=np.zeros((2, 3)), points_label=None)
    with pytest.raises(InputTypeError, match="collision must be None, a bool or a CollisionModel"):
        Scene(spatial4, collision="capsules")
    panda = models.panda()
    with pytest.raises(InputTypeError, match="acm must be an AllowedCollisionMatrix or None"):
        Scene(panda, acm=[("panda_link1", "panda_link2")])
    other = models.ur5()
    with pytest.raises(InputError, match="acm must cover the collision model's bodies"):
        Scene(panda, acm=default_acm(other.collision))


def test_options_check_their_fields():
    """ViewerOptions refuses non-bool flags and budgets that are not integers >= 4."""
    assert ViewerOptions() == ViewerOptions(meshes=True, mesh_budget=60_000,
                                            show_collision=False)
    with pytest.raises(InputTypeError, match="meshes must be True or False, got 'no'"):
        ViewerOptions(meshes="no")
    with pytest.raises(InputTypeError, match="show_collision must be True or False, got 1"):
        ViewerOptions(show_collision=1)
    with pytest.raises(InputTypeError, match="mesh_budget must be an integer, got float"):
        ViewerOptions(mesh_budget=1e4)
    with pytest.raises(InputError, match="mesh_budget must be >= 4, got 2"):
        ViewerOptions(mesh_budget=2)


def test_scene_is_frozen_and_owns_its_arrays(planar3):
    """A Scene cannot be changed, and changing the caller's arrays afterwards leaves it alone."""
    Q = planar3.random_q(4, seed=1)
    scene = Scene(planar3, trajectory=Q, path_points=np.zeros((3, 2)))
    page = viewer_html(scene)
    Q[:] = 0.5
    assert viewer_html(scene) == page
    with pytest.raises(dataclasses.FrozenInstanceError):
        scene.title = "x"  # type: ignore[misc]
    assert scene.path_points.shape == (3, 2)  # stored as given; the page gets z = 0
    np.testing.assert_array_equal(scene.initial_q, scene.trajectory[0])
