"""``serialkin view`` options for the robot's body: meshes, packages, collision, points."""

from __future__ import annotations

import json
import re

import numpy as np
import pytest
from click.testing import CliRunner

from serialkin.cli import view_cmd
from serialkin.cli.main import cli
from serialkin.viz.viewer import MESH_BUDGET
from tests.erd import urdf as erd_urdf
from tests.viz._body import write_package


def run(*args: object, code: int = 0):
    result = CliRunner().invoke(cli, [str(a) for a in args], catch_exceptions=False)
    assert result.exit_code == code, (result.exit_code, result.output)
    return result


def _page_data(path) -> dict:
    page = path.read_text(encoding="utf-8")
    m = re.search(r'<script type="application/json" id="serialkin-data">(.*?)</script>', page,
                  re.S)
    assert m is not None
    return json.loads(m.group(1))


def test_help_default_budget_is_the_viewers():
    """The command line's copy of the mesh budget equals the viewer's constant."""
    assert view_cmd._MESH_BUDGET == MESH_BUDGET
    assert str(MESH_BUDGET) in run("view", "--help").stdout


def test_urdf_meshes_through_package_and_budget(tmp_path):
    """--package resolves package:// meshes, --mesh-budget bounds them, --no-meshes drops them."""
    urdf = write_package(tmp_path, inside=False)
    out = tmp_path / "v.html"
    res = run("view", urdf, "--param", "tip_link=tcp", code=2)
    assert "LINK1" in res.output and "--package NAME=FOLDER" in res.output
    run("view", urdf, "--param", "tip_link=tcp", "--package", f"bodypkg={tmp_path / 'bodypkg'}",
        "--mesh-budget", 50, "--out", out)
    data = _page_data(out)
    assert [s["kind"] for s in data["shapes"]].count("mesh") == 1
    assert 0 < data["meshes"][0]["faces"] <= 50
    run("view", urdf, "--param", "tip_link=tcp", "--mesh-path", tmp_path, "--out", out)
    assert _page_data(out)["meshes"][0]["faces"] == 320
    run("view", urdf, "--param", "tip_link=tcp", "--no-meshes", "--out", out)
    assert _page_data(out)["meshes"] == []


def test_bad_package_options_named(tmp_path):
    """Malformed --package, a missing folder, or --package on a built-in model: exit 2."""
    urdf = write_package(tmp_path)
    assert "NAME=FOLDER" in run("view", urdf, "--package", "nofolder", code=2).output
    assert "not found" in run("view", urdf, "--package", f"p={tmp_path / 'x'}", code=2).output
    assert "not found" in run("view", urdf, "--mesh-path", tmp_path / "x", code=2).output
    assert "URDF" in run("view", "ur5", "--package", f"p={tmp_path}", code=2).output


def test_collision_and_srdf(tmp_path):
    """--collision shows the Panda's capsules or fits a URDF's; --srdf skips pairs."""
    out = tmp_path / "p.html"
    info = json.loads(run("view", "panda", "--collision", "--out", out, "--json").stdout)
    assert info["collision"] is True
    col = _page_data(out)["collision"]
    assert col["show"] is True and col["pairs"]
    urdf = write_package(tmp_path)  # a URDF robot carries no capsules unless fitted
    assert "no collision model" in run("view", urdf, "--param", "tip_link=tcp", "--no-meshes",
                                       "--collision", "--out", out, code=2).output
    text = urdf.read_text(encoding="utf-8")
    for link in ("base", "link2"):
        text = text.replace(f'<link name="{link}">', f'<link name="{link}"><collision>'
                            '<geometry><sphere radius="0.05"/></geometry></collision>')
    urdf.write_text(text, encoding="utf-8")
    info = json.loads(run("view", urdf, "--param", "tip_link=tcp", "--no-meshes", "--collision",
                          "--out", out, "--json").stdout)
    assert info["capsules_fitted"] is True
    assert _page_data(out)["collision"]["bodies"] == ["base", "link2"]
    srdf = erd_urdf("panda_description/srdf/panda.srdf")
    if srdf is None:
        pytest.skip("example-robot-data (bench extra) is not installed")
    run("view", "panda", "--srdf", srdf, "--out", out)
    assert len(_page_data(out)["collision"]["pairs"]) <= len(col["pairs"])


def test_points_csv(tmp_path):
    """--points reads x,y,z[,r,g,b] rows; the label defaults to the file name."""
    pts = np.random.default_rng(0).uniform(size=(7, 6))
    f = tmp_path / "reach.csv"
    f.write_text("x,y,z,r,g,b\n" + "\n".join(",".join(map(str, r)) for r in pts) + "\n")
    out = tmp_path / "v.html"
    run("view", "two_link", "--points", f, "--out", out)
    p = _page_data(out)["points"]
    assert p["count"] == 7 and p["label"] == "reach.csv"
    run("view", "two_link", "--points", f, "--points-label", "reachable", "--out", out)
    assert _page_data(out)["points"]["label"] == "reachable"
    assert "--points" in run("view", "two_link", "--points-label", "x", "--out", out,
                             code=2).output
