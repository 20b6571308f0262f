"""The ``serialkin`` command line, end to end in temporary folders (click's CliRunner)."""

from __future__ import annotations

import json
import math
import os
from pathlib import Path

import numpy as np
import pytest
import yaml
from click.testing import CliRunner

from serialkin import Robot, models
from serialkin.cli.io import CLIError, read_csv_rows, write_text_atomic
from serialkin.cli.main import cli

SUBCOMMANDS = ("chapter", "models", "fk", "jacobian", "ik", "ik-compare", "track", "path",
               "workspace", "view")
EXAMPLES = Path(__file__).resolve().parents[2] / "examples" / "robots"


def run(*args: str, code: int | None = 0):
    result = CliRunner().invoke(cli, [str(a) for a in args], catch_exceptions=False)
    if code is not None:
        assert result.exit_code == code, (result.exit_code, result.output, result.stderr)
    return result


def as_json(result) -> dict:
    return json.loads(result.stdout)


@pytest.mark.parametrize("name", SUBCOMMANDS)
def test_help_has_example(name):
    """Every subcommand has --help with an example invocation."""
    out = run(name, "--help").stdout
    assert "Usage: " in out
    assert f"serialkin {name}" in out.split("Examples:" if "Examples:" in out else "Example:")[1]


def test_models_lists_catalog():
    """'models' lists every built-in model with DOF and joint types (table and JSON)."""
    text = run("models").stdout
    for n in models.names():
        assert n in text
    data = as_json(run("models", "--json"))
    by_name = {m["name"]: m for m in data["models"]}
    assert set(by_name) == set(models.names())
    assert by_name["stanford"]["joint_types"] == "RRPRRR"
    assert by_name["panda"]["dof"] == 7 and by_name["panda"]["convention"] == "modified"


def test_fk_json_matches_library():
    """'fk --json' returns robot.fk(q) for a built-in robot."""
    q = [0.1, -0.4, 0.3, 0.2, 0.5, -0.6]
    data = as_json(run("fk", "puma560", "--q", ",".join(map(str, q)), "--json"))
    T = models.get("puma560").fk(np.array(q))
    np.testing.assert_allclose(data["results"][0]["T"], T, atol=1e-12)
    np.testing.assert_allclose(data["results"][0]["position"], T[:3, 3], atol=1e-12)
    assert data["units"] == {"length": "m", "angle": "rad"}


def test_fk_degrees_table_and_frames():
    """--degrees reads joint angles in degrees; --frames gives n+1 link frames."""
    data = as_json(run("fk", "two_link", "--q", "90 -90", "--degrees", "--frames", "--json"))
    rec = data["results"][0]
    np.testing.assert_allclose(rec["q"], [math.pi / 2, -math.pi / 2])
    np.testing.assert_allclose(rec["position"], [1.0, 1.0, 0.0], atol=1e-12)
    assert len(rec["frames"]) == 3
    text = run("fk", "two_link", "--q", "90,-90", "-d").stdout
    assert "position [m]" in text and "rpy [deg]" in text


def test_fk_csv_in_and_out(tmp_path):
    """Reads q from a CSV (header, comments); a CSV of poses out, atomically, matching FK."""
    r = models.get("ur5")
    Q = r.random_q(4, seed=1)
    src = tmp_path / "q.csv"
    src.write_text("# test\n" + ",".join(f"q{i}" for i in range(6)) + "\n"
                   + "\n".join(",".join(repr(float(v)) for v in q) for q in Q) + "\n")
    out = tmp_path / "sub" / "poses.csv"
    res = run("fk", "ur5", "--q-file", src, "--out", out)
    assert "wrote" in res.stdout
    rows = np.loadtxt(out, delimiter=",", skiprows=1)
    header = out.read_text().splitlines()[0].split(",")
    assert rows.shape == (4, len(header))
    np.testing.assert_allclose(rows[:, 6:9], r.fk(Q)[:, :3, 3], atol=1e-12)
    assert sorted(p.name for p in out.parent.iterdir()) == ["poses.csv"]


def test_csv_wrong_columns_names_line(tmp_path):
    """A CSV row with the wrong column count is an error naming the file and line."""
    src = tmp_path / "q.csv"
    src.write_text("q1,q2\n0.1,0.2\n\n0.3,0.4,0.5\n")
    res = run("fk", "two_link", "--q-file", src, code=2)
    assert f"{src}, line 4: expected 2 columns" in res.stderr
    src.write_text("0.1,abc\n")
    res = run("fk", "two_link", "--q-file", src, code=2)
    assert "line 1" in res.stderr and "'abc' is not a number" in res.stderr


def test_wrong_q_count_is_clear():
    """--q with the wrong number of values is a one-line error, exit code 2."""
    res = run("fk", "puma560", "--q", "0,1", code=2)
    assert "--q: expected 6 numbers, got 2" in res.stderr
    assert "Traceback" not in res.output


def test_jacobian_json_matches_library():
    """'jacobian --json' returns robot.jacobian(q, frame) and the manipulability."""
    r = models.get("ur5")
    q = r.random_q(seed=2)
    qs = ",".join(repr(float(v)) for v in q)
    for frame in ("base", "ee"):
        data = as_json(run("jacobian", "ur5", "--q", qs, "--frame", frame, "--json"))
        np.testing.assert_allclose(data["results"][0]["J"], r.jacobian(q, frame=frame),
                                   atol=1e-12)
    assert data["task"] == "full"
    assert data["results"][0]["manipulability"] == pytest.approx(r.manipulability(q))
    data = as_json(run("jacobian", "ur5", "--q", qs, "--link", "3", "--point", "0,0,0.1",
                       "--json"))
    np.testing.assert_allclose(data["results"][0]["J"],
                               r.jacobian(q, link=3, point=[0, 0, 0.1]), atol=1e-12)


def test_jacobian_planar_task():
    """A planar arm's manipulability uses its planar rows (eq 43: L1 L2 |sin q2|)."""
    data = as_json(run("jacobian", "two_link", "--q", "0.3,0.9", "--planar", "--json"))
    assert data["rows"] == ["vx", "vy", "wz"] and data["task"] == "planar"
    assert data["results"][0]["manipulability"] == pytest.approx(abs(math.sin(0.9)))


def test_ik_reachable_pose():
    """A reachable full pose is solved: exit 0, success true, FK(q) equals the target."""
    r = models.get("puma560")
    T = r.fk(r.random_q(seed=4))
    from serialkin.spatial import matrix_to_rpy

    t = np.concatenate([T[:3, 3], matrix_to_rpy(T[:3, :3])])
    data = as_json(run("ik", "puma560", "--target", ",".join(repr(float(v)) for v in t), "--json"))
    assert data["success"] is True and data["method"] == "lm"
    q = np.array(data["results"][0]["q"])
    np.testing.assert_allclose(r.fk(q), T, atol=1e-8)
    assert r.within_limits(q)


def test_ik_out_of_reach_json_and_exit_code():
    """Out of reach: exit 1, a clear stderr line, and well-formed JSON with success false."""
    res = run("ik", "two_link", "--target", "5,0", "--json", code=1)
    data = as_json(res)
    assert data["success"] is False and data["results"][0]["success"] is False
    assert data["results"][0]["reason"]
    assert data["results"][0]["position_error"] >= 3.0 - 1e-9  # reach is 2 m, target at 5 m
    assert "target 1 not reached" in res.stderr
    res = run("ik", "two_link", "--target", "5,0", code=1)
    assert "NO" in res.stdout


def test_ik_batch_file_methods_and_options(tmp_path):
    """Targets from a CSV, --method/--option/--tol/--seed honoured, results written out."""
    r = models.get("three_link")
    Q = r.random_q(5, seed=3)
    T = r.fk(Q)
    phi = np.arctan2(T[:, 1, 0], T[:, 0, 0])
    src = tmp_path / "t.csv"
    src.write_text("x,y,phi\n" + "".join(f"{float(a)!r},{float(b)!r},{float(c)!r}\n"
                                         for a, b, c in zip(T[:, 0, 3], T[:, 1, 3], phi)))
    out = tmp_path / "sol.json"
    data = as_json(run("ik", "three_link", "--target-file", src, "--method", "dls",
                       "--option", "damping=0.05", "--tol", "1e-8", "--seed", "3",
                       "--out", out, "--json"))
    assert data["success"] and data["count"] == 5 and data["method"] == "dls"
    q = np.array([rec["q"] for rec in data["results"]])
    np.testing.assert_allclose(r.fk(q)[:, :2, 3], T[:, :2, 3], atol=1e-7)
    assert json.loads(out.read_text())["results"][0]["q"] == data["results"][0]["q"]
    res = run("ik", "three_link", "--target", "1,1", "--option", "no_such=1", code=2)
    assert "no_such" in res.stderr


def test_ik_all_closed_form():
    """--all lists both elbow solutions of the 2-link arm, each reproducing the target."""
    r = models.get("two_link")
    data = as_json(run("ik", "two_link", "--target", "1.2,0.4", "--all", "--json"))
    sols = np.array(data["results"][0]["solutions"])
    assert sols.shape == (2, 2)
    np.testing.assert_allclose(r.fk(sols)[:, :2, 3], [[1.2, 0.4]] * 2, atol=1e-9)


def test_ik_unknown_method_and_listing():
    """An unknown method lists the available ones; --list-methods prints them."""
    res = run("ik", "two_link", "--target", "1,1", "--method", "levenberg", code=2)
    assert "lm" in res.stderr and "dls" in res.stderr
    out = run("ik", "--list-methods").stdout
    for m in ("lm", "dls", "pinv", "ccd", "fabrik", "analytic"):
        assert m in out


def test_unknown_robot_suggests_nearest():
    """An unknown robot name suggests the nearest built-in names (exit 2)."""
    res = run("fk", "puma650", code=2)
    assert "puma560" in res.stderr and "did you mean" in res.stderr.lower()
    res = run("fk", "two_lnk", code=2)
    assert "two_link" in res.stderr


def test_robot_file_and_malformed_file(tmp_path):
    """A robot file works like a model; a malformed one names the file and the field."""
    r = models.get("puma560")
    q = "0.1,0.2,0.3,0.4,0.5,0.6"
    a = as_json(run("fk", EXAMPLES / "puma560.yaml", "--q", q, "--json"))
    np.testing.assert_allclose(a["results"][0]["T"], r.fk(np.array([0.1, 0.2, 0.3, 0.4, 0.5,
                                                                   0.6])), atol=1e-12)
    doc = yaml.safe_load((EXAMPLES / "puma560.yaml").read_text())
    doc["dh"][3]["alpha"] = "ninety"
    bad = tmp_path / "bad.yaml"
    bad.write_text(yaml.safe_dump(doc))
    res = run("fk", bad, code=2)
    assert str(bad) in res.stderr and "dh[3].alpha" in res.stderr
    res = run("fk", tmp_path / "missing.json", code=2)
    assert "not found" in res.stderr


def test_urdf_robot(tmp_path):
    """A .urdf ROBOT is read with Robot.from_urdf and gives the same FK."""
    r = models.get("ur5")
    p = tmp_path / "ur5.urdf"
    p.write_text(r.to_urdf())
    q = r.random_q(seed=5)
    data = as_json(run("fk", p, "--q", ",".join(repr(float(v)) for v in q), "--json"))
    np.testing.assert_allclose(data["results"][0]["T"], r.fk(q), atol=1e-9)


def test_model_params():
    """--param passes keyword arguments to a built-in model."""
    data = as_json(run("fk", "planar", "--param", "n=3", "--param", "lengths=[1, 2, 3]",
                       "--json"))
    np.testing.assert_allclose(data["results"][0]["position"], [6, 0, 0], atol=1e-12)


def test_unwritable_output_folder(tmp_path):
    """An output folder that cannot be created gives a clear error (exit 2)."""
    blocker = tmp_path / "file.txt"
    blocker.write_text("x")
    res = run("workspace", "two_link", "--samples", "1000", "--out", blocker / "ws", code=2)
    assert "cannot create output folder" in res.stderr and "Traceback" not in res.output
    res = run("fk", "two_link", "--out", blocker / "sub" / "p.json", code=2)
    assert "output folder" in res.stderr


def test_atomic_write_never_truncates(tmp_path, monkeypatch):
    """A write interrupted before the rename leaves the old file whole and no temp file."""
    p = tmp_path / "r.csv"
    write_text_atomic(p, "old\n")

    def boom(*_a, **_k):
        raise OSError(28, "No space left on device")

    monkeypatch.setattr(os, "replace", boom)
    with pytest.raises(CLIError, match="No space left"):
        write_text_atomic(p, "new content\n" * 1000)
    assert p.read_text() == "old\n"
    assert [x.name for x in tmp_path.iterdir()] == ["r.csv"]


def test_read_csv_rows_stdin_and_empty(tmp_path):
    """CSV reader: empty file error, whitespace-separated rows accepted."""
    p = tmp_path / "e.csv"
    p.write_text("# nothing\n")
    with pytest.raises(CLIError, match="no q rows"):
        read_csv_rows(p, "q", 2)
    p.write_text("1 2\n3 4\n")
    np.testing.assert_array_equal(read_csv_rows(p, "q", 2), [[1, 2], [3, 4]])


def test_workspace_two_link(tmp_path):
    """'workspace' writes figure, points and summary; the area matches within its error."""
    out = tmp_path / "ws"
    data = as_json(run("workspace", "two_link", "--samples", "150000", "--out", out, "-w",
                       "--save-q", "--json"))
    area = data["area"]
    assert abs(area["value"] - 4 * math.pi) <= area["error"]
    for key in ("figure", "manipulability", "points", "summary"):
        assert Path(data["files"][key]).is_file()
    assert json.loads((out / "workspace_reachable.json").read_text())["area"] == area
    with np.load(out / "workspace_reachable.npz") as z:
        assert z["points"].shape == (150000, 2)
        np.testing.assert_allclose(z["points"], models.get("two_link").fk(z["q"])[:, :2, 3],
                                   atol=1e-12)


def test_workspace_kinds_and_errors(tmp_path):
    """Orientation kinds take --orientation (degrees with -d); missing ones are errors."""
    data = as_json(run("workspace", "three_link", "--kind", "constant", "--orientation", "30",
                       "-d", "--samples", "30000", "--out", tmp_path, "--no-plot", "--json"))
    assert data["kind"] == "constant"
    assert data["params"]["phi"] == pytest.approx(math.radians(30))
    res = run("workspace", "three_link", "--kind", "inclusive", "--orientation", "0",
              "--out", tmp_path, code=2)
    assert "--max-angle" in res.stderr
    res = run("workspace", "three_link", "--kind", "constant", "--out", tmp_path, code=2)
    assert "--orientation" in res.stderr


def test_workspace_spatial_slice(tmp_path):
    """A spatial workspace gives a volume and a slice figure."""
    data = as_json(run("workspace", "puma560", "--samples", "40000", "--slice", "z=0.6",
                       "--out", tmp_path, "--json"))
    assert data["volume"]["unit"] == "m^3" and data["volume"]["value"] > 0
    assert data["slices"][0]["axis"] == "z"
    assert (tmp_path / "slice_z_0.6.png").is_file()
    res = run("workspace", "two_link", "--slice", "z=0", "--samples", "1000", "--out",
              tmp_path, code=2)
    assert "spatial" in res.stderr


def test_quiet_prints_nothing(tmp_path):
    """--quiet prints nothing on stdout or stderr (no progress bar, no summary)."""
    res = run("workspace", "two_link", "--samples", "20000", "--out", tmp_path, "--quiet",
              "--no-plot")
    assert res.stdout == "" and res.stderr == ""
    res = run("fk", "two_link", "--quiet")
    assert res.stdout == ""


@pytest.mark.slow
def test_track_scenario(tmp_path):
    """'track' writes the trajectory (CSV+NPZ), figure, GIF, viewer and a JSON summary."""
    from serialkin.tracking import Trajectory, load_scenario

    data = as_json(run("track", "six_link_circle", "--out", tmp_path, "--max-frames", "4",
                       "--viewer", "--json"))
    assert data["success"] is True and data["computed"] == data["path_points"] > 0
    assert data["max_error"] < 0.005
    traj = Trajectory.load(tmp_path / "six_link_circle.csv")
    traj2 = Trajectory.load(tmp_path / "six_link_circle.npz")
    np.testing.assert_allclose(traj.q, traj2.q)
    ref = load_scenario("six_link_circle").run()
    np.testing.assert_allclose(traj.q, ref.q, atol=1e-12)
    assert (tmp_path / "six_link_circle.gif").read_bytes().startswith(b"GIF8")
    for name in ("", "_motion", "_joints", "_error"):
        assert (tmp_path / f"six_link_circle{name}.png").read_bytes().startswith(b"\x89PNG")
    assert not (tmp_path / "six_link_circle_clearance.png").exists()  # no obstacles
    assert "<html" in (tmp_path / "six_link_circle.html").read_text().lower()
    assert run("track", "--list").stdout.split() == sorted(run("track", "--list").stdout.split())


def test_track_bad_scenario(tmp_path):
    """A malformed scenario file is an error naming the field; a missing one lists names."""
    bad = tmp_path / "s.yaml"
    bad.write_text("name: x\nrobot: {planar: {links: 3, length: -1}}\npath: {type: circle}\n")
    res = run("track", bad, "--out", tmp_path, code=2)
    assert "s.yaml" in res.stderr
    res = run("track", "no_such_scenario", "--out", tmp_path, code=2)
    assert "six_link_circle" in res.stderr


def test_view_writes_page(tmp_path):
    """'view' writes a self-contained page for a configuration or a trajectory file."""
    out = tmp_path / "v.html"
    data = as_json(run("view", "ur5", "--q", "0,-1.2,1.4,0,0.5,0", "--out", out, "--json"))
    assert Path(data["file"]) == out and data["frames"] == 0
    page = out.read_text()
    assert "UR5" in page and "<script" in page
    q = tmp_path / "q.csv"
    q.write_text("0,0\n0.1,0.2\n0.2,0.4\n")
    data = as_json(run("view", "two_link", "--trajectory", q, "--out", out, "--json"))
    assert data["frames"] == 3
    res = run("view", "two_link", "--trajectory", tmp_path / "none.csv", code=2)
    assert "not found" in res.stderr


def test_view_scenario(tmp_path):
    """'view --scenario' takes robot, path and obstacles from the scenario."""
    data = as_json(run("view", "--scenario", "six_link_circle", "--out", tmp_path / "s.html",
                       "--json"))
    assert data["n"] == 6 and data["frames"] > 0


def test_robotfile_yaml_equivalent_to_from_dh(tmp_path):
    """A robot file written by save_robot_file works as ROBOT for fk."""
    from serialkin.formats.robotfile import save_robot_file

    r = Robot.from_dh([dict(a=0.3, alpha=0.2, d=0.1, theta=0.0)] * 2, name="tiny")
    p = save_robot_file(r, tmp_path / "tiny.json")
    data = as_json(run("fk", p, "--q", "0.5,0.5", "--json"))
    np.testing.assert_allclose(data["results"][0]["T"], r.fk(np.array([0.5, 0.5])),
                               atol=1e-12)


def test_ik_compare_matches_library(tmp_path, monkeypatch):
    """'ik-compare --json' gives the rows of serialkin.ik.compare on the same seeded targets."""
    from serialkin.cli.compare_cmd import random_targets
    from serialkin.ik.compare import compare

    monkeypatch.chdir(tmp_path)

    data = as_json(run("ik-compare", "three_link", "--targets", "6", "--methods", "lm,dls",
                       "--seed", "2", "--option", "dls:damping=0.05", "--json"))
    r = models.get("three_link")
    ref = compare(r, random_targets(r, 6, "planar_pose", 2), methods=["lm", "dls"], seed=2,
                  tol=1e-9, method_options={"dls": {"damping": 0.05}})
    assert data["target_kind"] == "planar_pose" and data["targets"] == 6
    for row, ref_row in zip(data["rows"], ref.to_dicts()):
        assert row["method"] == ref_row["method"]
        assert row["success_rate"] == ref_row["success_rate"]
        assert row["median_iterations"] == ref_row["median_iterations"]
    run("ik-compare", "two_link", "--targets", "3", "--methods", "lm", "--out",
        "cmp.csv", "--quiet")
    lines = Path("cmp.csv").read_text().splitlines()
    assert lines[0].startswith("method,family,") and lines[1].startswith("lm,jacobian,")
    res = run("ik-compare", "ur5", "--kind", "planar", code=2)
    assert "planar robot" in res.stderr
    res = run("ik-compare", "ur5", "--option", "damping=0.1", code=2)
    assert "METHOD:KEY=VALUE" in res.stderr


def test_ik_mask_q0_degrees_and_no_limits():
    """--mask drops coordinates, --q0 (in degrees with -d) seeds the solve, --no-limits passes."""
    r = models.get("ur5")
    q = r.random_q(seed=7)
    p = r.fk(q)[:3, 3]
    target = ",".join(repr(float(v)) for v in [*p, 10.0, 20.0, 30.0])  # unreachable rpy
    q0 = ",".join(repr(float(v)) for v in np.degrees(q + 0.05))
    data = as_json(run("ik", "ur5", "-t", target, "-d", "--mask", "1,1,1,0,0,0", "--q0", q0,
                       "--max-iter", "200", "--restarts", "5", "--no-limits", "--json"))
    assert data["success"]
    np.testing.assert_allclose(r.fk(np.array(data["results"][0]["q"]))[:3, 3], p, atol=1e-8)
    res = run("ik", "ur5", "-t", target, "-d", "--mask", "0,0,0,0,0,0", code=2)
    assert "mask" in res.stderr


def test_track_unreachable_points_exit_1(tmp_path):
    """A path partly out of reach: exit 1, the failed points on stderr, JSON success false."""
    sc = tmp_path / "far.yaml"
    sc.write_text("name: far\nrobot: {planar: {links: 3, length: 0.1}}\n"
                  "path: {type: circle, center: [0.25, 0], radius: 0.1, step: 0.5}\n")
    res = run("track", sc, "--out", tmp_path / "o", "--no-animation", "--no-figures",
              "--json", code=1)
    data = as_json(res)
    assert data["success"] is False and data["computed"] == data["path_points"]
    assert data["failures"] and all(f["error"] > 0.005 for f in data["failures"])
    failed = [f["index"] for f in data["failures"]]
    assert data["failed_points"] == failed and data["reached"] == data["computed"] - len(failed)
    assert f"{len(failed)} path points not reached: " in res.stderr  # one line, indices
    assert res.stderr.count("not reached") == 1
    assert (tmp_path / "o" / "far.csv").is_file()  # nothing of the trajectory is lost


def test_track_summary_is_short_and_says_what_was_reached(tmp_path):
    """Text summary: 'reached K of N', errors in mm apart, at most 15 lines; --verbose all."""
    sc = tmp_path / "far.yaml"
    sc.write_text("name: far\nrobot: {planar: {links: 3, length: 0.1}}\n"
                  "path: {type: circle, center: [0.25, 0], radius: 0.1, step: 0.1}\n")
    res = run("track", sc, "--out", tmp_path / "o", "--no-animation", "--no-figures", code=1)
    summary = [ln for ln in res.stdout.splitlines() if not ln.startswith("  wrote ")]
    assert len(summary) <= 15
    reached = int(summary[0].split()[1])
    total = int(summary[0].split()[3])
    assert summary[0].startswith("reached ") and reached < total
    assert any(ln.startswith("position error: max ") and " mm" in ln for ln in summary)
    assert any("more failures" in ln for ln in summary)
    full = run("track", sc, "--out", tmp_path / "o2", "--no-animation", "--no-figures",
               "--verbose", code=1)
    listed = [ln for ln in full.stdout.splitlines() if ln.startswith("path point ")]
    assert len(listed) == total - reached


def test_models_show_and_save(tmp_path):
    """'models ROBOT' shows the DH table; --save writes a robot file or URDF that loads back."""
    text = run("models", "puma560").stdout
    assert "alpha [deg]" in text and "[-160.0, 160.0] deg" in text
    r = models.get("ur5")
    y = tmp_path / "ur5.yaml"
    run("models", "ur5", "--save", y, "--length-unit", "mm")
    assert "length: mm" in y.read_text()
    u = tmp_path / "ur5.urdf"
    run("models", "ur5", "--save", u)
    q = r.random_q(seed=3)
    qs = ",".join(repr(float(v)) for v in q)
    for f in (y, u):
        data = as_json(run("fk", f, "--q", qs, "--json"))
        np.testing.assert_allclose(data["results"][0]["T"], r.fk(q), atol=1e-9)
    detail = as_json(run("models", u, "--json"))
    assert "joints" in detail and len(detail["joints"]) == 6
    assert len(as_json(run("models", "ur5", "--json"))["dh"]) == 6
    res = run("models", "ur5", "--save", tmp_path / "x.txt", code=2)
    assert ".urdf" in res.stderr
    res = run("models", "--save", y, code=2)
    assert "needs ROBOT" in res.stderr
