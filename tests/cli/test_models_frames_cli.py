"""`serialkin models` shows every zoo robot's base and flange frames against the vendor's."""

from __future__ import annotations

import json

import numpy as np
from click.testing import CliRunner

from serialkin import models
from serialkin.cli.main import cli


def run(*args: str) -> str:
    result = CliRunner().invoke(cli, list(args), catch_exceptions=False)
    assert result.exit_code == 0, result.output
    return result.stdout


def test_listing_shows_frames_of_every_model():
    """The listing has a frames block naming each model, and the vendor variants."""
    out = run("models")
    block = out.split("Frames (")[1]
    for name in models.names():
        assert f"  {name}:\n    base frame: " in block
    assert "ur5_vendor, panda_vendor" in out
    assert "Rz(π)" in block and "Rz(-45°)" in block


def test_json_carries_the_vendor_transforms():
    """--json gives T_vbase_base and T_flange_vtip as 4x4 matrices, for a name or an alias."""
    data = json.loads(run("models", "franka", "--json"))
    v = data["frames"]["vendor"]
    assert v["tip_link"] == "panda_hand_tcp" and v["variant"] == "panda_vendor"
    np.testing.assert_allclose(v["T_flange_vtip"], models.frames.FRAMES["panda"].vendor
                               .T_flange_vtip)
    listing = json.loads(run("models", "--json"))["models"]
    assert all(e["frames"]["base"] for e in listing)


def test_vendor_variant_runs_in_fk():
    """`serialkin fk ur5-vendor` is the UR5 turned by Rz(π): x and y change sign."""
    a = json.loads(run("fk", "ur5", "--q", "0.1,-1,1,0,0.5,0", "--json"))
    b = json.loads(run("fk", "ur5-vendor", "--q", "0.1,-1,1,0,0.5,0", "--json"))
    pa, pb = (np.array(d["results"][0]["position"]) for d in (a, b))
    np.testing.assert_allclose(pb, [-pa[0], -pa[1], pa[2]], atol=1e-12)
