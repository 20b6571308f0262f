"""A fit that cannot describe the robot fails and says why: units, wrong robot, degrees."""

from __future__ import annotations

import numpy as np
import pytest

from serialkin import models
from serialkin.calibration import calibrate, make_measurements, read_measurements
from serialkin.errors import InputError


def _positions(robot, count=60, seed=0):
    q = robot.random_q(count, seed=seed)
    return q, robot.fk(q)[:, :3, 3]


def test_positions_in_millimetres_fail_with_the_likely_cause():
    """Marker positions in mm (metres read): success=False naming the units."""
    ur5 = models.get("ur5")
    q, pos = _positions(ur5)
    res = calibrate(ur5, make_measurements(ur5, q, positions=pos * 1000.0))
    assert not res.success
    assert "millimetres" in res.reason


def test_measurements_of_another_robot_fail():
    """UR5 positions fitted to a Puma 560 (same joint count): success=False."""
    ur5, puma = models.get("ur5"), models.get("puma560")
    q, pos = _positions(ur5, seed=1)
    res = calibrate(puma, make_measurements(puma, q, positions=pos))
    assert not res.success
    assert "do not fit this robot" in res.reason


def test_good_measurements_still_succeed():
    """The robot's own noiseless positions fit (the guard does not reject real fits)."""
    ur5 = models.get("ur5")
    q, pos = _positions(ur5, seed=2)
    res = calibrate(ur5, make_measurements(ur5, q, positions=pos))
    assert res.success, res.reason
    assert res.rms_after[0] < 1e-9


def test_joint_values_in_degrees_are_refused(tmp_path):
    """A measurement file whose revolute joint values exceed a turn is refused, naming the cell."""
    ur5 = models.get("ur5")
    q, pos = _positions(ur5, count=10, seed=3)
    lines = ["q1,q2,q3,q4,q5,q6,x,y,z"]
    lines += [",".join(f"{v:.6f}" for v in (*np.degrees(qi), *p)) for qi, p in zip(q, pos)]
    f = tmp_path / "m.csv"
    f.write_text("\n".join(lines) + "\n")
    with pytest.raises(InputError, match=r"line \d+, column 'q\d'.*degrees"):
        read_measurements(f, ur5)
