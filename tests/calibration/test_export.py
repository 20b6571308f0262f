"""Writing calibrated robots as robot files and URDF."""

from __future__ import annotations

import numpy as np
import pytest

import serialkin as sk
from serialkin.calibration import error_model, perturb, save_robot
from serialkin.errors import InputError
from serialkin.formats.robotfile import load_robot_file


@pytest.mark.parametrize("name", ["ur5", "panda"])
@pytest.mark.parametrize("suffix", [".yaml", ".json", ".urdf"])
def test_saved_robot_has_the_calibrated_kinematics(tmp_path, name, suffix):
    """Reading the written file back gives the calibrated kinematics (UR5 DH: refused)."""
    model = error_model(sk.models.get(name))
    robot = model.calibrated_robot(perturb(model, seed=1))
    if name == "ur5" and suffix != ".urdf":  # β links: DH would need tens of metres
        with pytest.raises(InputError, match="nearly parallel"):
            save_robot(robot, tmp_path / f"cal{suffix}")
        return
    path = save_robot(robot, tmp_path / f"cal{suffix}")
    back = sk.Robot.from_urdf(str(path)) if suffix == ".urdf" else load_robot_file(path)
    q = robot.random_q(20, seed=2)
    np.testing.assert_allclose(back.fk(q), robot.fk(q), atol=1e-9)


def test_unknown_suffix(tmp_path):
    """A .txt target raises InputError naming the accepted suffixes."""
    with pytest.raises(InputError, match=".urdf"):
        save_robot(sk.models.ur5(), tmp_path / "x.txt")
