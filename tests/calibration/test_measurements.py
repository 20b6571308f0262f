"""Measurement files and arrays: round trips and bad input named by line."""

from __future__ import annotations

import numpy as np
import pytest

import serialkin as sk
from serialkin.calibration import (
    make_measurements,
    read_measurements,
    simulate_measurements,
    write_measurements,
)
from serialkin.errors import InputError


@pytest.mark.parametrize("kind", ["position", "pose"])
def test_csv_round_trip(tmp_path, kind):
    """write_measurements then read_measurements gives the same q, positions and rotations."""
    robot = sk.models.ur5()
    meas = simulate_measurements(robot, 7, kind=kind, noise_rotation=1e-3, seed=0)
    path = write_measurements(tmp_path / "m.csv", meas, weights=np.arange(1, 8))
    back = read_measurements(path, robot)
    assert back.kind == kind and len(back) == 7
    np.testing.assert_allclose(back.q, meas.q, atol=0)
    np.testing.assert_allclose(back.positions, meas.positions, atol=0)
    if kind == "pose":
        np.testing.assert_allclose(back.rotations, meas.rotations, atol=1e-15)
    assert back.lines.tolist() == list(range(2, 9))
    part = back.subset([1, 4])
    assert len(part) == 2 and part.lines.tolist() == [3, 6] and part.kind == kind
    assert "m.csv, line 6" in part.where(1)
    # weight w divides the covariance: the whitening grows with sqrt(w)
    np.testing.assert_allclose(back.whitening[3, 0, 0] / back.whitening[0, 0, 0], 2.0)


def _write(tmp_path, text):
    p = tmp_path / "m.csv"
    p.write_text(text)
    return p


def test_nan_row_is_named_by_line(tmp_path):
    """A NaN cell is reported with its line number and column."""
    p = _write(tmp_path, "# tracker export\nq1,q2,q3,q4,q5,q6,x,y,z\n"
                         "0,0,0,0,0,0,0.1,0.2,0.3\n\n0,0,0,0,0,0,nan,0.2,0.3\n")
    with pytest.raises(InputError, match=r"m.csv, line 5, column 'x': values must be finite"):
        read_measurements(p, sk.models.ur5())


def test_wrong_joint_count_is_refused(tmp_path):
    """A file with 7 joint columns for a 6-joint robot names both counts."""
    p = _write(tmp_path, "q1,q2,q3,q4,q5,q6,q7,x,y,z\n0,0,0,0,0,0,0,1,2,3\n")
    with pytest.raises(InputError, match="7 joint columns .* robot 'UR5' has 6 joints"):
        read_measurements(p, sk.models.ur5())


@pytest.mark.parametrize("text,match", [
    ("0,0,0,0,0,0,1,2,3\n", "expected a header line"),
    ("q1,q2,q3,q4,q5,q6,x,y\n0,0,0,0,0,0,1,2\n", "missing column"),
    ("q1,q2,q3,q4,q5,q6,x,y,z,foo\n0,0,0,0,0,0,1,2,3,4\n", "unknown column"),
    ("q1,q2,q3,q4,q5,q6,x,y,z\n0,0,0,0,0,0,1,2\n", "line 2: 8 values"),
    ("q1,q2,q3,q4,q5,q6,x,y,z\n0,0,0,0,0,0,1,2,abc\n", "'abc' is not a number"),
    ("q1,q2,q3,q4,q5,q6,x,y,z,weight\n0,0,0,0,0,0,1,2,3,0\n", "weight must be > 0"),
    ("q1,q2,q3,q4,q5,q6,x,y,z,quat_w,quat_x,quat_y,quat_z\n0,0,0,0,0,0,1,2,3,1,1,0,0\n",
     "unit norm"),
    ("q1,q2,q3,q4,q5,q6,x,y,z\n", "no measurements"),
])
def test_malformed_files(tmp_path, text, match):
    """Header, columns, cells, weights and quaternions are checked with clear messages."""
    with pytest.raises(InputError, match=match):
        read_measurements(_write(tmp_path, text), sk.models.ur5())


def test_array_input_checks():
    """Arrays: one of positions/poses, matching shapes, finite values, SPD covariance."""
    robot = sk.models.ur5()
    q = robot.random_q(4, seed=0)
    pos = robot.fk(q)[:, :3, 3]
    with pytest.raises(InputError, match="exactly one"):
        make_measurements(robot, q)
    with pytest.raises(InputError, match=r"shape \(4, 3\)"):
        make_measurements(robot, q, positions=pos[:3])
    bad = pos.copy()
    bad[2, 1] = np.nan
    with pytest.raises(InputError, match=r"positions must be finite, got nan at index \(2, 1\)"):
        make_measurements(robot, q, positions=bad)
    with pytest.raises(InputError, match="positive definite"):
        make_measurements(robot, q, positions=pos, covariance=-np.eye(3))
    m = make_measurements(robot, q, positions=pos, covariance=np.diag([1e-8, 4e-8, 1e-8]))
    np.testing.assert_allclose(m.whitening[0], np.diag([1e4, 5e3, 1e4]))
