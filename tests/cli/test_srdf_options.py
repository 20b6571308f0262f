"""Every command that checks self-collision takes ``--srdf`` and ``--skip-links`` alike.

The commands that check collision (``collide``, ``reach``, ``base-placement``, ``view``,
``track``) declare the two options through one helper (``collide_cmd.srdf_options``),
refuse ``--skip-links`` without ``--srdf`` in the same words, and hand the SRDF's allowed
pairs to the library call that checks.
"""

from __future__ import annotations

import json
import re

import click
import numpy as np
import pytest
from click.testing import CliRunner

from serialkin.cli.main import cli
from serialkin.collision import AllowedCollisionMatrix
from serialkin.errors import SerialkinError

#: The commands that check collision, and the minimal arguments of each (tmp: a folder).
CHECKING = {
    "collide": lambda tmp: ["collide", "ur5"],
    "reach": lambda tmp: ["reach", "ur5", "-r", "0.4", "-n", "2", "--no-plot", "-q",
                          "--self-collision", "--out", str(tmp / "map")],
    "base-placement": lambda tmp: ["base-placement", "ur5", "--tasks", str(_tasks(tmp)),
                                   "--no-plot", "-q", "--out", str(tmp / "bp")],
    "view": lambda tmp: ["view", "ur5", "--out", str(tmp / "p.html")],
    "track": lambda tmp: ["track", str(_ur5_scenario(tmp)), "--no-figures", "--no-animation",
                          "-q", "--out", str(tmp / "track")],
}
#: Options by which a command checks collision.
COLLISION_OPTIONS = {"--scene", "--self-collision", "--collision", "--clearance"}
#: A pair of the UR5's collision bodies, never adjacent.
PAIR = ("base_link", "wrist_3_link")


def _tasks(tmp):
    path = tmp / "tasks.yaml"
    path.write_text("tasks:\n  - [0.4, 0.1, 0.3, 3.14159, 0, 0]\n", encoding="utf-8")
    return path


def _ur5_scenario(tmp):
    """A UR5 scenario tracked by the QP with self-collision (its solver checks it)."""
    path = tmp / "ur5_path.yaml"
    path.write_text("robot: {model: ur5}\nq0: [0, -1.2, 1.4, 0, 0.5, 0]\n"
                    "path: {type: points, points: [[0.4, 0.1, 0.3], [0.4, 0.15, 0.3]]}\n"
                    "solver: {method: qp, self_collision: true}\n", encoding="utf-8")
    return path


def _srdf(tmp):
    path = tmp / "ur5.srdf"
    path.write_text(f'<robot name="ur5"><disable_collisions link1="{PAIR[0]}" '
                    f'link2="{PAIR[1]}" reason="test"/></robot>', encoding="utf-8")
    return path


def _commands(group: click.Group, prefix: str = "") -> dict[str, click.Command]:
    """Every command under ``group`` by its full name (subgroups walked)."""
    found = {}
    for name, cmd in group.commands.items():
        if isinstance(cmd, click.Group):
            found.update(_commands(cmd, f"{prefix}{name} "))
        else:
            found[f"{prefix}{name}"] = cmd
    return found


def _options(cmd: click.Command) -> set[str]:
    return {o for p in cmd.params for o in getattr(p, "opts", [])}


def test_every_collision_checking_command_takes_srdf_and_skip_links():
    """A command with a collision option (or collide itself) has --srdf and --skip-links.

    The checking set is stated: a command that starts to check collision (``ik`` with a
    scene, say) fails here until it takes the SRDF options too.
    """
    commands = _commands(cli)
    checking = {name for name, cmd in commands.items()
                if _options(cmd) & COLLISION_OPTIONS or name == "collide"}
    assert checking == set(CHECKING)
    for name in checking:
        assert {"--srdf", "--skip-links"} <= _options(commands[name]), name
        srdf = next(p for p in commands[name].params if "--srdf" in p.opts)
        assert "disable_collisions" in (srdf.help or ""), name  # the one shared declaration


@pytest.mark.parametrize("name", sorted(CHECKING))
def test_skip_links_without_srdf_is_refused_alike(name, tmp_path):
    """--skip-links alone is refused with the same message by every checking command."""
    res = CliRunner().invoke(cli, [*CHECKING[name](tmp_path), "--skip-links", "tool0"])
    assert res.exit_code == 2, res.output
    assert "--skip-links names links of an SRDF: give --srdf too" in res.output


@pytest.mark.parametrize("name", sorted(CHECKING))
def test_unknown_srdf_file_is_refused(name, tmp_path):
    """A missing SRDF file is an error naming it, before anything is computed."""
    missing = tmp_path / "none.srdf"
    res = CliRunner().invoke(cli, [*CHECKING[name](tmp_path), "--srdf", str(missing)])
    assert res.exit_code != 0
    assert "none.srdf" in res.output


@pytest.mark.parametrize(("name", "target"), [
    ("collide", "serialkin.collision.closest_pairs"),
    ("reach", "serialkin.reach.execute.make_job"),
    ("base-placement", "serialkin.reach.base_placement"),
    ("view", "serialkin.viz.scene.Scene"),
    ("track", "serialkin.tracking.scenario.track"),
])
def test_srdf_pairs_reach_the_library_call(name, target, tmp_path, monkeypatch):
    """The SRDF's disabled pair arrives as ``acm`` in the call that checks collision."""
    seen = {}

    class Captured(SerialkinError):
        pass

    def capture(*args, **kwargs):
        seen.update(kwargs)
        raise Captured("captured")

    monkeypatch.setattr(target, capture)
    res = CliRunner().invoke(cli, [*CHECKING[name](tmp_path), "--srdf", str(_srdf(tmp_path))])
    assert "captured" in res.output, res.output
    acm = seen["acm"]
    assert isinstance(acm, AllowedCollisionMatrix)
    assert acm.is_allowed(*PAIR) and not acm.is_allowed("base_link", "forearm_link")


def test_collide_srdf_drops_the_disabled_pair(tmp_path):
    """`collide --srdf` no longer lists the pair the SRDF disables; the others stay."""
    q = np.zeros(6)
    args = ["collide", "ur5", "--q", ",".join(map(str, q)), "--count", "100", "--json"]
    runner = CliRunner()
    before = json.loads(runner.invoke(cli, args).stdout)["pairs"]
    after = json.loads(runner.invoke(cli, [*args, "--srdf", str(_srdf(tmp_path))]).stdout)
    names = {(p["first"], p["second"]) for p in after["pairs"]}
    assert PAIR not in names and PAIR[::-1] not in names
    assert len(after["pairs"]) == len(before) - 1


def test_view_srdf_drops_the_disabled_pair_from_the_page(tmp_path):
    """`view --srdf` writes a page whose in-page check skips exactly the disabled pair."""
    def pairs(*extra):
        out = tmp_path / "p.html"
        res = CliRunner().invoke(cli, ["view", "ur5", "--out", str(out), *extra])
        assert res.exit_code == 0, res.output
        page = out.read_text(encoding="utf-8")
        data = re.search(r'<script type="application/json" id="serialkin-data">(.*?)</script>',
                         page, re.S)
        col = json.loads(data.group(1))["collision"]
        body = [col["bodies"][k] for k in col["body"]]  # of each shape
        return {tuple(sorted((body[a], body[b]))) for a, b in col["pairs"]}

    full = pairs()
    skipped = pairs("--srdf", str(_srdf(tmp_path)))
    assert full - skipped == {tuple(sorted(PAIR))}


# ------------------------------------------------------------------------- track
#: A unit-link 6-link planar arm with its capsule model, folded towards its base: links 1
#: and 6 cross unless the QP keeps them apart (tests/tracking/test_self_collision_pairs.py).
FOLD = ("robot: {model: planar6}\nq0: 0.1\n"
        "path: {type: polyline, waypoints: [[5.0, 1.0], [0.5, 0.0], [0.0, 0.0]], step: 0.2}\n"
        "solver: {method: qp, self_collision: true, safety: 0.05}\n")


def _fold(tmp, text=FOLD):
    path = tmp / "fold.yaml"
    path.write_text(text, encoding="utf-8")
    return path


def _fold_srdf(tmp, a="link1", b="link6"):
    path = tmp / f"{a}_{b}.srdf"
    path.write_text(f'<robot name="planar6"><disable_collisions link1="{a}" link2="{b}"/>'
                    "</robot>", encoding="utf-8")
    return path


def _track_q(tmp, scenario, *extra):
    """Joint trajectory (p, n) that `serialkin track` writes for ``scenario``."""
    from serialkin.tracking import Trajectory

    out = tmp / "out"
    res = CliRunner().invoke(cli, ["track", str(scenario), "--out", str(out), "--format", "npz",
                                   "--no-figures", "--no-animation", "-q", *extra])
    assert res.exit_code in (0, 1), res.output  # 1: a point not reached
    return Trajectory.load(out / f"{scenario.stem}.npz").q


@pytest.mark.parametrize("extra", [(), ("link1", "link6"), ("link2", "link5")])
def test_track_cli_and_python_api_agree(extra, tmp_path):
    """`track --srdf` writes the trajectory of ``track(..., srdf=...)``, bit for bit."""
    from serialkin.tracking import load_scenario, track

    scenario = _fold(tmp_path)
    srdf = {"srdf": _fold_srdf(tmp_path, *extra)} if extra else {}
    cli_q = _track_q(tmp_path, scenario, *(("--srdf", str(srdf["srdf"])) if srdf else ()))
    sc = load_scenario(scenario)
    api = track(sc.robot, sc.path, sc.solver, q0=sc.q0, **srdf)
    np.testing.assert_array_equal(cli_q, api.q)


@pytest.fixture(scope="module")
def fold_runs(tmp_path_factory):
    """The fold scenario tracked by `serialkin track` without and with an SRDF, once.

    ``(folder, SRDF disabling link1–link6, trajectory without it, trajectory with it)``:
    two QP runs, shared by the tests below.
    """
    tmp = tmp_path_factory.mktemp("fold")
    srdf = _fold_srdf(tmp)
    kept = _track_q(tmp, _fold(tmp))
    return tmp, srdf, kept, _track_q(tmp, _fold(tmp), "--srdf", str(srdf))


def test_scenario_srdf_key_is_the_srdf_option(tmp_path, fold_runs):
    """A scenario's ``srdf:`` (relative to its file) tracks as ``--srdf``; --srdf replaces it."""
    from serialkin.tracking import ScenarioError, load_scenario

    _, srdf, kept, by_flag = fold_runs
    keyed = tmp_path / "keyed"
    keyed.mkdir()
    (keyed / "pairs.srdf").write_bytes(srdf.read_bytes())
    scenario = _fold(keyed, FOLD + "srdf: pairs.srdf\n")
    assert load_scenario(scenario).options["srdf"] == str(keyed / "pairs.srdf")
    np.testing.assert_array_equal(_track_q(keyed, scenario), by_flag)
    assert not np.array_equal(kept, by_flag)  # no pair skipped: differs
    other = _fold_srdf(tmp_path, "link2", "link5")  # the flag wins over the file's key
    np.testing.assert_array_equal(_track_q(keyed, scenario, "--srdf", str(other)),
                                  _track_q(tmp_path, _fold(tmp_path), "--srdf", str(other)))
    with pytest.raises(ScenarioError, match="field 'srdf' must name an SRDF file"):
        load_scenario(_fold(keyed, FOLD + "srdf: missing.srdf\n"))
    with pytest.raises(ScenarioError, match="field 'skip_links' names links of an SRDF"):
        load_scenario(_fold(keyed, FOLD + "skip_links: [hand]\n"))


def test_track_srdf_lets_the_disabled_pair_cross(fold_runs):
    """With link1–link6 disabled by --srdf the fold completes through them; not without."""
    from serialkin import models

    arm = models.get("planar6")
    _, _, kept, crossed = fold_runs
    assert arm.clearance(kept).distance.min() > 0.0
    worst = arm.clearance(crossed)
    k = int(np.argmin(worst.distance))
    assert worst.distance[k] < 0.0 and (worst.first[k], worst.second[k]) == ("link1", "link6")


def test_track_self_collision_flag_turns_the_qp_check_on(tmp_path):
    """--self-collision on a QP scenario without it keeps the bodies apart; needs the QP."""
    from serialkin import models

    arm = models.get("planar6")
    scenario = _fold(tmp_path, FOLD.replace("self_collision: true", "self_collision: false"))
    assert arm.clearance(_track_q(tmp_path, scenario)).distance.min() < 0.0
    kept = _track_q(tmp_path, scenario, "--self-collision")
    np.testing.assert_array_equal(kept, _track_q(tmp_path, _fold(tmp_path)))
    dls = _fold(tmp_path, FOLD.replace("{method: qp, self_collision: true, safety: 0.05}",
                                       "{method: dls}"))
    res = CliRunner().invoke(cli, ["track", str(dls), "--self-collision", "-q",
                                   "--out", str(tmp_path / "o")])
    assert res.exit_code == 2
    assert "--self-collision needs the QP solver" in res.output and "'dls'" in res.output


@pytest.mark.parametrize(("solver", "hint"), [
    ("{method: dls}", "add --self-collision and --solver qp"),
    ("{method: qp}", "add --self-collision"),
])
def test_track_srdf_without_a_self_collision_check_is_refused(solver, hint, tmp_path):
    """--srdf where nothing checks self-collision says what to add."""
    scenario = _fold(tmp_path, FOLD.replace("{method: qp, self_collision: true, safety: 0.05}",
                                            solver))
    res = CliRunner().invoke(cli, ["track", str(scenario), "--srdf",
                                   str(_fold_srdf(tmp_path)), "-q", "--out", str(tmp_path / "o")])
    assert res.exit_code == 2
    assert "--srdf lists the pairs a self-collision check skips" in res.output
    assert hint in res.output


@pytest.mark.parametrize(("content", "match"), [
    ("<robot><disable_collisions link1='link1'", "malformed XML"),
    ("<robot><disable_collisions link1='link1' link2='nope'/></robot>", "'nope'"),
])
def test_track_bad_srdf_content_names_the_option(content, match, tmp_path):
    """An SRDF that cannot be read, or names a link without a body: 'Error: --srdf: ...'."""
    bad = tmp_path / "bad.srdf"
    bad.write_text(content, encoding="utf-8")
    res = CliRunner().invoke(cli, ["track", str(_fold(tmp_path)), "--srdf", str(bad), "-q",
                                   "--out", str(tmp_path / "o")])
    assert res.exit_code == 2
    assert "Error: --srdf: " in res.output and match in res.output
    assert not (tmp_path / "o").exists()  # refused before anything is written


def test_track_srdf_on_a_robot_without_a_collision_model_is_refused(tmp_path):
    """A scenario's planar arm has no collision model: --srdf says so."""
    scenario = _fold(tmp_path, FOLD.replace("{model: planar6}",
                                            "{planar: {links: 6, length: 1.0}}"))
    res = CliRunner().invoke(cli, ["track", str(scenario), "--srdf", str(_fold_srdf(tmp_path)),
                                   "-q", "--out", str(tmp_path / "o")])
    assert res.exit_code == 2
    assert "--srdf: robot" in res.output and "has no collision model" in res.output
