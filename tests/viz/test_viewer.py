"""Tests for serialkin.viz.viewer: the page embeds the robot's chain data and three.js."""

import json
import re

import numpy as np
import pytest

from serialkin import Joint, Robot
from serialkin.errors import InputError, OutputError
from serialkin.viz.viewer import THREE_REVISION, viewer_data, viewer_html, write_viewer


def _page_data(page: str) -> dict:
    m = re.search(r'<script type="application/json" id="serialkin-data">(.*?)</script>', page,
                  re.S)
    assert m is not None
    return json.loads(m.group(1))


def test_page_embeds_chain_data_exactly(spatial4):
    """The JSON in the page holds F, L, meta bit-for-bit and the initial q."""
    q = np.array([0.1, -0.2, 0.15, 0.3])
    data = _page_data(viewer_html(spatial4, q=q))
    np.testing.assert_array_equal(np.array(data["F"]), spatial4.chain.F)
    np.testing.assert_array_equal(np.array(data["L"]), spatial4.chain.L)
    np.testing.assert_array_equal(np.array(data["meta"]), spatial4.chain.meta)
    assert data["q"] == q.tolist()
    assert data["n"] == 4 and data["joint_types"] == ["R", "R", "P", "R"]
    assert data["qlim"][2] == [0.0, 0.3] and data["qlim"][0] == [None, None]


def test_page_embeds_three_js_and_viewer_code(planar3):
    """The page is self-contained: three.js module text inline, no external src/href."""
    from importlib import resources

    page = viewer_html(planar3)
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
    data = viewer_data(planar3, trajectory=Q, path_points=path, obstacles=obs)
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
    assert viewer_data(r)["q"] == [0.2, 0.0]


def test_markup_cannot_break_out_of_script():
    """A robot name with '</script>' is escaped in the title and in the JSON."""
    evil = "</script><script>alert(1)</script>"
    r = Robot.from_joints([Joint(name="j1")], name=evil)
    page = viewer_html(r, title=evil)
    assert evil not in page
    assert _page_data(page)["name"] == evil


def test_bad_inputs_named(spatial4):
    """Wrong trajectory/q/path shapes raise InputError naming the argument."""
    with pytest.raises(InputError, match="trajectory"):
        viewer_html(spatial4, trajectory=np.zeros((3, 2)))
    with pytest.raises(InputError, match="trajectory"):
        viewer_html(spatial4, trajectory=np.zeros(4))
    with pytest.raises(InputError, match="q"):
        viewer_html(spatial4, q=np.zeros((2, 4)))
    with pytest.raises(InputError, match="path_points"):
        viewer_html(spatial4, path_points=np.zeros((3, 5)))
    with pytest.raises(InputError, match="finite"):
        viewer_html(spatial4, q=[0, np.inf, 0, 0])


def test_write_viewer_atomic(tmp_path, planar3):
    """write_viewer creates folders, writes the page and leaves no temporary file."""
    out = write_viewer(planar3, tmp_path / "a" / "b" / "view.html", q=[0.1, 0.2, 0.3])
    assert out.read_text(encoding="utf-8").startswith("<!doctype html>")
    assert [p.name for p in out.parent.iterdir()] == ["view.html"]


def test_write_viewer_unwritable(tmp_path, planar3):
    """An output folder that cannot be created gives an OutputError naming the path."""
    blocker = tmp_path / "file"
    blocker.write_text("x")
    with pytest.raises(OutputError, match="cannot write"):
        write_viewer(planar3, blocker / "sub" / "view.html")
