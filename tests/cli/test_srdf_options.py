"""Every command that checks self-collision takes ``--srdf`` and ``--skip-links`` alike.

The commands that check collision (``collide``, ``reach``, ``base-placement``, ``view``)
declare the two options through one helper (``collide_cmd.srdf_options``), refuse
``--skip-links`` without ``--srdf`` in the same words, and hand the SRDF's allowed pairs
to the library call that checks.
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
}
#: Options by which a command checks collision.
COLLISION_OPTIONS = {"--scene", "--self-collision", "--collision", "--clearance"}
#: A pair of the UR5's collision bodies, never adjacent.
PAIR = ("base_link", "wrist_3_link")


def _tasks(tmp):
    path = tmp / "tasks.yaml"
    path.write_text("tasks:\n  - [0.4, 0.1, 0.3, 3.14159, 0, 0]\n", encoding="utf-8")
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

    The checking set is stated: a command that starts to check collision (``ik`` or
    ``track`` with a scene, say) fails here until it takes the SRDF options too.
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
