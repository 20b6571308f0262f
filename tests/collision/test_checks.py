"""Robot.clearance / in_collision / closest_pairs and `serialkin collide`: pairs by name."""

import numpy as np
import pytest
from click.testing import CliRunner

from serialkin import models
from serialkin.cli.main import cli
from serialkin.collision import closest_pairs, self_clearance
from serialkin.errors import InputError
from serialkin.model.geometry import Sphere

FOLDED = [0.0, 0.0, 0.0, -3.0, 0.0, 0.5, 0.0]


def test_clearance_names_the_pair_of_self_clearance():
    """Robot.clearance equals self_clearance and names its pair with body names."""
    r = models.get("panda")
    q = np.random.default_rng(0).uniform(-1, 1, (4, 7))
    c = r.clearance(q)
    ref = self_clearance(r, r.collision, q)
    np.testing.assert_allclose(c.distance, ref.distance)
    assert list(zip(c.first, c.second, strict=True)) == ref.names(r.collision)


def test_in_collision_with_scene_names_the_obstacle():
    """An obstacle on the hand is the closest pair, by its name, and a collision."""
    r = models.get("ur5")
    q = np.zeros(6)
    p = r.fk(q)[:3, 3]
    c = r.clearance(q, scene=[Sphere(0.05, center=p, name="ball")])
    assert c.second == "ball" and c.with_scene and c.distance < 0
    assert r.in_collision(q, scene=[Sphere(0.05, center=p, name="ball")])
    assert not r.in_collision(q, scene=[Sphere(0.05, center=p + [3, 0, 0])])


def test_closest_pairs_sorted_and_srdf_pairs_skipped(tmp_path):
    """closest_pairs is sorted by distance and skips the pairs an SRDF disables."""
    r = models.get("panda")
    pairs = closest_pairs(r, FOLDED, count=50)
    d = [p.distance for p in pairs]
    assert d == sorted(d)
    a, b = pairs[0].first, pairs[0].second
    srdf = tmp_path / "x.srdf"
    srdf.write_text(f'<robot name="p"><disable_collisions link1="{a}" link2="{b}"/>'
                    '<disable_collisions link1="panda_hand_tcp" link2="panda_link0"/></robot>')
    again = closest_pairs(r, FOLDED, count=50, srdf=str(srdf), skip_links=["panda_hand_tcp"])
    assert (a, b) not in {(p.first, p.second) for p in again}


def test_robot_without_model_and_skip_links_without_srdf_are_refused():
    """No collision model, or skip_links without an SRDF: InputError that says what to do."""
    r = models.get("panda")
    with pytest.raises(InputError, match="with_collision"):
        r.with_collision(None).clearance(np.zeros(7))
    with pytest.raises(InputError, match="srdf"):
        r.clearance(np.zeros(7), skip_links=["x"])


def test_collide_command_prints_named_pairs(tmp_path):
    """`serialkin collide` prints the verdict and named pairs; --srdf with --skip-links."""
    runner = CliRunner()
    res = runner.invoke(cli, ["collide", "panda", "--q", ",".join(map(str, FOLDED)),
                              "--count", "3"])
    assert res.exit_code == 0, res.output
    lines = res.output.splitlines()
    assert lines[0].startswith("panda: ") and "panda_" in lines[2]
    assert len(lines) == 5
    srdf = tmp_path / "x.srdf"
    srdf.write_text('<robot name="p"><disable_collisions link1="panda_hand_tcp" '
                    'link2="panda_link0"/></robot>')
    res = runner.invoke(cli, ["collide", "panda", "--json", "--srdf", str(srdf),
                              "--skip-links", "panda_hand_tcp"])
    assert res.exit_code == 0, res.output
    assert '"pairs"' in res.output
    res = runner.invoke(cli, ["collide", "panda", "--skip-links", "panda_hand_tcp"])
    assert res.exit_code != 0 and "--srdf" in res.output
