"""The ``reach`` and ``base-placement`` commands: outputs, resume and refused input."""

from __future__ import annotations

import json

import numpy as np
from click.testing import CliRunner

from serialkin import models
from serialkin.cli.main import cli
from serialkin.reach import load_map, reachability_map


def _run(*args: str):
    return CliRunner().invoke(cli, list(args), catch_exceptions=False)


def test_reach_command_writes_the_map_and_resumes(tmp_path):
    """`reach` writes the map the API computes; --resume recomputes no chunk."""
    out = tmp_path / "m"
    res = _run("reach", "three_link", "-r", "0.2", "-n", "6", "--out", str(out),
               "--chunk-voxels", "100", "--json")
    assert res.exit_code == 0, res.output
    summary = json.loads(res.stdout)
    assert summary["solver"] == "closed_form" and summary["reachable_voxels"] > 0
    assert (out / "reach_slice.png").read_bytes().startswith(b"\x89PNG")
    api = reachability_map(models.get("three_link"), 0.2, 6, chunk_voxels=100, progress=False)
    assert np.array_equal(load_map(out / "map.npz").reached, api.reached)
    res = _run("reach", "three_link", "-r", "0.2", "-n", "6", "--out", str(out),
               "--chunk-voxels", "100", "--resume", "-q")
    assert res.exit_code == 0, res.output
    assert json.loads((out / "metadata.json").read_text())["recomputed_chunks"] == 0


def test_reach_command_refuses_bad_input(tmp_path):
    """Zero resolution, other settings on --resume, a bad --cluster: one Error line each."""
    out = tmp_path / "m"
    res = _run("reach", "two_link", "-r", "0", "--out", str(out))
    assert res.exit_code != 0 and "resolution" in res.output
    assert _run("reach", "two_link", "-r", "0.2", "--out", str(out), "-q").exit_code == 0
    res = _run("reach", "two_link", "-r", "0.3", "--out", str(out), "--resume")
    assert res.exit_code != 0 and "resolution: 0.2 in the folder, 0.3 now" in res.output
    res = _run("reach", "two_link", "-r", "0.2", "--out", str(tmp_path / "n"),
               "--cluster", "remote:2")
    assert res.exit_code != 0 and "local:N" in res.output


def test_base_placement_command(tmp_path):
    """`base-placement` reads task poses (x, y, z, r, p, y) and names a base reaching all."""
    tasks = tmp_path / "tasks.yaml"
    tasks.write_text("tasks:\n  - [0.4, 0.2, 0.3, 3.14159, 0, 0]\n"
                     "  - [0.3, -0.3, 0.2, 3.14159, 0, 0]\n")
    out = tmp_path / "b"
    res = _run("base-placement", "ur5", "--tasks", str(tasks), "-r", "0.3", "--yaws", "2",
               "--out", str(out), "--json")
    assert res.exit_code == 0, res.output
    s = json.loads(res.stdout)
    assert s["best"]["reached"] == 2 and s["feasible_candidates"] > 0
    assert (out / "base_placement.png").exists() and (out / "base_placement.npz").exists()
    tasks.write_text("tasks:\n  - [1, 2, 3]\n")
    res = _run("base-placement", "ur5", "--tasks", str(tasks), "--out", str(out))
    assert res.exit_code != 0 and "tasks[0] has 3 numbers" in res.output


def test_help_has_examples():
    """Both commands have --help with example invocations."""
    for name in ("reach", "base-placement"):
        out = _run(name, "--help").output
        assert "Usage: " in out and f"serialkin {name} ur5" in out.split("Example")[1]


def _tasks_file(tmp_path):
    tasks = tmp_path / "tasks.yaml"
    tasks.write_text("tasks:\n  - [0.4, 0.2, 0.3, 3.14159, 0, 0]\n"
                     "  - [0.3, -0.3, 0.2, 3.14159, 0, 0]\n")
    return str(tasks)


def test_base_placement_saves_its_map_and_reuses_it_with_map(tmp_path):
    """The computed map is saved; --map with it gives the same best base and margins."""
    args = ["base-placement", "ur5", "--tasks", _tasks_file(tmp_path), "-r", "0.3",
            "--yaws", "2", "--no-plot", "--json"]
    res = _run(*args, "--out", str(tmp_path / "a"))
    assert res.exit_code == 0, res.output
    first = json.loads(res.stdout)
    assert first["self_collision"] is True and first["best"]["margin_min"] > 0
    saved = first["files"]["reach_map"]
    res = _run(*args, "--out", str(tmp_path / "b"), "--map", saved)
    assert res.exit_code == 0, res.output
    again = json.loads(res.stdout)
    assert again["best"] == first["best"] and "reach_map" not in again["files"]
    with np.load(tmp_path / "b" / "base_placement.npz") as z:
        assert z["margin"].shape == z["reached"].shape + (2,)


def test_base_placement_refuses_a_map_of_other_collision_settings(tmp_path):
    """A `reach` map without --self-collision is refused naming the difference; with it: used."""
    tasks = _tasks_file(tmp_path)
    for flag, name in (((), "plain"), (("--self-collision",), "sc")):
        res = _run("reach", "ur5", "-r", "0.4", "-n", "2", "--no-plot", "-q",
                   "--out", str(tmp_path / name), *flag)
        assert res.exit_code == 0, res.output
    args = ["base-placement", "ur5", "--tasks", tasks, "-r", "0.4", "--yaws", "1",
            "--no-plot", "-q", "--out", str(tmp_path / "b")]
    res = _run(*args, "--map", str(tmp_path / "plain"))
    assert res.exit_code != 0 and "collision: null in the map" in res.output
    assert _run(*args, "--map", str(tmp_path / "plain"), "--no-self-collision").exit_code == 0
    assert _run(*args, "--map", str(tmp_path / "sc")).exit_code == 0


def test_srdf_options_on_reach_and_base_placement(tmp_path):
    """--srdf joins the self-collision check; it is refused where self-collision is off."""
    srdf = tmp_path / "ur5.srdf"
    srdf.write_text('<robot name="ur5"><disable_collisions link1="base_link" '
                    'link2="wrist_3_link" reason="Never"/></robot>')
    res = _run("reach", "ur5", "-r", "0.4", "-n", "2", "--no-plot", "-q", "--srdf", str(srdf),
               "--out", str(tmp_path / "m"))
    assert res.exit_code != 0 and "--self-collision" in res.output
    res = _run("reach", "ur5", "-r", "0.4", "-n", "2", "--no-plot", "-q", "--srdf", str(srdf),
               "--self-collision", "--out", str(tmp_path / "m"))
    assert res.exit_code == 0, res.output
    acm_hash = load_map(tmp_path / "m").settings["collision"]["acm_hash"]
    base = ["base-placement", "ur5", "--tasks", _tasks_file(tmp_path), "-r", "0.4",
            "--yaws", "1", "--no-plot", "-q", "--out", str(tmp_path / "b")]
    res = _run(*base, "--srdf", str(srdf), "--no-self-collision")
    assert res.exit_code != 0 and "--no-self-collision" in res.output
    res = _run(*base, "--map", str(tmp_path / "m"))  # the map's SRDF pairs differ
    assert res.exit_code != 0 and acm_hash in res.output
    assert _run(*base, "--map", str(tmp_path / "m"), "--srdf", str(srdf)).exit_code == 0
