"""The QP step agrees with pink's on the same tasks and limits (test-only peer pin-pink)."""

from __future__ import annotations

import numpy as np
import pytest

import serialkin as sk
from serialkin.diffik import DiffIK, FrameTask, PositionLimit, PostureTask, VelocityLimit

pin = pytest.importorskip("pinocchio")
pink = pytest.importorskip("pink")
pytest.importorskip("daqp")


def _world_pose_task(frame: str, target):
    """A pink task whose error and Jacobian come from Pinocchio in the world-aligned frame.

    pink's own FrameTask uses the body-frame log6 (with its Jacobian of the log), a
    different but equivalent first-order model; this task states serialkin's convention
    ``e = [p_t − p; log(R_t Rᵀ)]`` with Pinocchio's kinematics, so the comparison checks
    our Jacobian, the QP assembly, the limits and the solve against pink's.
    """
    from pink.tasks import Task

    class WorldPoseTask(Task):
        def compute_error(self, configuration):
            T = configuration.get_transform_frame_to_world(frame)
            e = np.concatenate([target.translation - T.translation,
                                pin.log3(target.rotation @ T.rotation.T)])
            return -e  # pink's error is what the step removes

        def compute_jacobian(self, configuration):
            fid = configuration.model.getFrameId(frame)
            return pin.getFrameJacobian(configuration.model, configuration.data, fid,
                                        pin.LOCAL_WORLD_ALIGNED)

        def __repr__(self):
            return "WorldPoseTask"

    return WorldPoseTask(cost=1.0, gain=1.0)


@pytest.mark.parametrize("seed", [0, 1, 2, 3])
def test_qp_step_agrees_with_pink(seed):
    """Frame + posture tasks, configuration and velocity limits: the same Δq as pink's."""
    from pink.limits import ConfigurationLimit
    from pink.limits import VelocityLimit as PinkVelocityLimit
    from pink.tasks import PostureTask as PinkPostureTask

    robot = sk.models.get("panda")
    model = pin.buildModelFromXML(robot.to_urdf())
    data = model.createData()
    vmax = np.linspace(0.8, 2.0, robot.n)
    model.velocityLimit[:] = vmax
    dt = 0.05
    q = robot.random_q(seed=seed)
    ref = robot.random_q(seed=seed + 100)
    T = robot.fk(robot.random_q(seed=seed + 200))
    posture = PinkPostureTask(cost=0.1)  # pink's cost c is our weight c²
    posture.set_target(ref)
    tasks = [_world_pose_task("tool", pin.SE3(T[:3, :3], T[:3, 3])), posture]
    limits = [ConfigurationLimit(model, config_limit_gain=0.5), PinkVelocityLimit(model)]
    v = pink.solve_ik(pink.Configuration(model, data, q), tasks, dt, solver="daqp",
                      damping=1e-12, limits=limits)
    ours = DiffIK(robot, [FrameTask(T), PostureTask(ref, weight=0.01)],
                  [PositionLimit(gain=0.5), VelocityLimit(vmax, dt)], damping=1e-12).step(q)
    assert ours.success
    np.testing.assert_allclose(ours.dq, v * dt, atol=1e-8)
    assert np.any(np.abs(np.abs(ours.dq) - vmax * dt) < 1e-9)  # some limit is active
