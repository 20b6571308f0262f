"""serialkin's FK and Jacobians agree with Pinocchio on real URDFs from example-robot-data."""

from __future__ import annotations

import numpy as np
import pytest

import serialkin as sk
from tests.erd import urdf

pin = pytest.importorskip("pinocchio", reason="pinocchio (pip package 'pin') is in the bench extra")

pytestmark = pytest.mark.peer

CHAINS = [
    ("panda_description/urdf/panda.urdf", "panda_link0", "panda_hand"),
    ("ur_description/urdf/ur5_robot.urdf", None, "tool0"),
    ("ur_description/urdf/ur3_robot.urdf", None, "tool0"),
    ("ur_description/urdf/ur10_robot.urdf", None, "tool0"),
    ("z1_description/urdf/z1.urdf", None, "gripperStator"),
    ("so_arm_description/urdf/so100.urdf", None, "gripper"),
    ("kinova_description/robots/kinova.urdf", None, "j2s6s200_end_effector"),
    ("xarm_description/urdf/xarm7.urdf", None, "link7"),
]


def _load(rel, base, tip):
    path = urdf(rel)
    if path is None:
        pytest.skip(f"{rel} is not shipped by the installed example-robot-data")
    try:
        robot = sk.Robot.from_urdf(str(path), base_link=base, tip_link=tip)
    except sk.errors.RobotDefinitionError as exc:  # a link name changed between versions
        pytest.skip(f"{rel}: {exc}")
    model = pin.buildModelFromUrdf(str(path))
    return robot, model


@pytest.mark.parametrize(("rel", "base", "tip"), CHAINS)
def test_fk_and_jacobian_match_pinocchio(rel, base, tip):
    """On random configurations, tool pose and frame Jacobian equal Pinocchio's to 1e-10."""
    robot, model = _load(rel, base, tip)
    data = model.createData()
    fid = model.getFrameId(tip, pin.BODY)
    idx = [model.getJointId(name) for name in robot.joint_names]
    assert all(i < model.njoints for i in idx), "every chain joint exists in the pin model"
    joints = [model.joints[i] for i in idx]
    vidx = [jm.idx_v for jm in joints]
    Q = robot.random_q(25, seed=11)
    T_all = robot.fk(Q)
    J_all = robot.jacobian(Q)
    for q, T, J in zip(Q, T_all, J_all):
        qp = pin.neutral(model)
        for jm, qi in zip(joints, q):
            if jm.nq == 2:  # continuous joints are (cos, sin) in pinocchio
                qp[jm.idx_q : jm.idx_q + 2] = np.cos(qi), np.sin(qi)
            else:
                qp[jm.idx_q] = qi
        pin.framesForwardKinematics(model, data, qp)
        T_pin = data.oMf[fid].homogeneous
        base_T = data.oMf[model.getFrameId(robot.link_names[0], pin.BODY)].homogeneous
        np.testing.assert_allclose(np.linalg.inv(base_T) @ T_pin, T, atol=1e-10)
        pin.computeJointJacobians(model, data, qp)
        Jp = pin.getFrameJacobian(model, data, fid, pin.LOCAL_WORLD_ALIGNED)[:, vidx]
        R0 = base_T[:3, :3].T
        Jp = np.vstack([R0 @ Jp[:3], R0 @ Jp[3:]])
        np.testing.assert_allclose(Jp, J, atol=1e-10)


@pytest.mark.parametrize(("rel", "base", "tip"), CHAINS[:2])
def test_urdf_export_agrees_with_pinocchio(rel, base, tip, tmp_path):
    """Pinocchio reads serialkin's exported URDF and finds the same tool pose."""
    robot, _ = _load(rel, base, tip)
    out = tmp_path / "exported.urdf"
    out.write_text(robot.to_urdf())
    model = pin.buildModelFromUrdf(str(out))
    data = model.createData()
    fid = model.getFrameId("tool")
    for q in robot.random_q(10, seed=4):
        pin.framesForwardKinematics(model, data, q)
        np.testing.assert_allclose(data.oMf[fid].homogeneous, robot.fk(q), atol=1e-10)
