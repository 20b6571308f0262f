"""The ``serialkin calibrate`` command: simulate, calibrate, write files, exit codes."""

from __future__ import annotations

import json

import numpy as np
from click.testing import CliRunner

import serialkin as sk
from serialkin.cli.main import cli


def _run(*args):
    return CliRunner().invoke(cli, ["calibrate", *args], catch_exceptions=False)


def test_simulate_then_calibrate(tmp_path):
    """Simulated UR5 measurements calibrate to a robot within 0.1 mm of the simulated truth."""
    meas, truth = tmp_path / "meas.csv", tmp_path / "real.urdf"
    r = _run("ur5", "--simulate", "40", "--measurements", str(meas), "--truth", str(truth),
             "--select", "200", "--seed", "1")
    assert r.exit_code == 0, r.output
    assert meas.exists() and truth.exists()
    out, urdf, report = tmp_path / "cal.yaml", tmp_path / "cal.urdf", tmp_path / "res.csv"
    r = _run("ur5", "--measurements", str(meas), "--out", str(out), "--urdf", str(urdf),
             "--report", str(report))
    assert r.exit_code == 0, r.output
    assert "d1 and base z cannot be separated" in r.output
    # Hayati's β on the UR5: a DH table would need tens of metres; the URDF is written
    assert f"note: {out} not written" in r.output and "nearly parallel" in r.output
    assert not out.exists()
    real = sk.Robot.from_urdf(str(truth))
    q = real.random_q(200, seed=5)
    for robot in (sk.Robot.from_urdf(str(urdf)),):
        err = np.linalg.norm(robot.fk(q)[:, :3, 3] - real.fk(q)[:, :3, 3], axis=1)
        assert np.sqrt(np.mean(err**2)) < 1e-4
    rows = report.read_text().splitlines()
    assert rows[0] == "measurement,position_before_m,position_after_m" and len(rows) == 41


def test_json_report_and_non_convergence(tmp_path):
    """--json prints the report; a one-evaluation budget exits 1 with the reason."""
    meas = tmp_path / "meas.csv"
    assert _run("ur5", "--simulate", "30", "--kind", "pose", "--measurements", str(meas)
                ).exit_code == 0
    r = _run("ur5", "--measurements", str(meas), "--json", "--sigma-rotation", "1e-4")
    assert r.exit_code == 0, r.output
    data = json.loads(r.stdout)
    assert data["success"] and data["kind"] == "pose" and len(data["residuals"]["rows"]) == 30
    assert data["rms_position_after"] < data["rms_position_before"]
    report = tmp_path / "report.json"
    r = _run("ur5", "--measurements", str(meas), "--max-evaluations", "1", "--report",
             str(report))
    assert r.exit_code == 1 and "NOT converged" in r.output
    saved = json.loads(report.read_text())
    assert saved["success"] is False and "not converged" in saved["reason"]


def test_bad_measurement_file_is_an_input_error(tmp_path):
    """A NaN row exits 2 with the file and line named."""
    meas = tmp_path / "m.csv"
    meas.write_text("q1,q2,q3,q4,q5,q6,x,y,z\n0,0,0,0,0,0,0.1,nan,0.3\n")
    r = _run("ur5", "--measurements", str(meas))
    assert r.exit_code == 2 and "line 2" in r.output and "finite" in r.output
    meas.write_text("q1,q2,q3,q4,q5,q6,x,y,z\n" + "0,0,0,0,0,0,0.1,0.2,0.3\n" * 3)
    r = _run("ur5", "--measurements", str(meas))
    assert r.exit_code == 2 and "at least 9 are needed" in r.output
    r = _run("ur5", "--measurements", str(meas), "--report", str(tmp_path / "r.txt"))
    assert r.exit_code == 2 and "--report" in r.output and ".csv, .json" in r.output


def test_options_of_the_other_mode_are_refused(tmp_path):
    """--out with --simulate, and --truth without it, are input errors rather than ignored."""
    meas = str(tmp_path / "m.csv")
    r = _run("ur5", "--simulate", "20", "--measurements", meas, "--out", "x.yaml")
    assert r.exit_code == 2 and "with --simulate nothing is calibrated" in r.output
    r = _run("ur5", "--measurements", meas, "--truth", "t.urdf")
    assert r.exit_code == 2 and "--truth only apply with --simulate" in r.output
