"""J̇ and the Jacobian Hessian agree with Pinocchio's on the same kinematics, to 1e-9."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import serialkin as sk
from tests.kinematics._fd import MODEL_IDS, all_models, dh_rows, random_transform
from tests.peers._pin_chain import pin_model

pin = pytest.importorskip("pinocchio", reason="pinocchio (pip package 'pin') is in the bench extra")

pytestmark = pytest.mark.peer

MODELS = all_models()


def _pin_hessian(model, data, joint: int, rf, n: int) -> np.ndarray:
    """Pinocchio's kinematic Hessian as H[:, j, k] = ∂J[:, j]/∂q_k.

    Its Python binding hands the (column-major) tensor's memory over as a C-ordered
    array, so the entries are read back in Fortran order.
    """
    H = pin.getJointKinematicHessian(model, data, joint, rf)
    return np.ascontiguousarray(H).ravel().reshape((6, n, n), order="F")


def _check_robot(robot: sk.Robot, q: np.ndarray, qd: np.ndarray) -> None:
    model, data, fid = pin_model(pin, robot)
    n = robot.n
    # J̇ of the tool frame: LOCAL_WORLD_ALIGNED is 'base', LOCAL is 'ee'.
    pin.computeJointJacobiansTimeVariation(model, data, q, qd)
    pin.updateFramePlacements(model, data)
    for rf, frame in ((pin.LOCAL_WORLD_ALIGNED, "base"), (pin.LOCAL, "ee")):
        dJ = np.reshape(pin.getFrameJacobianTimeVariation(model, data, fid, rf), (6, n))
        np.testing.assert_allclose(robot.jacobian_dot(q, qd, frame), dJ, atol=1e-9)
    # Hessian of the last joint's frame = serialkin's link frame n times L[n]⁻¹.
    Ln = robot.chain.L[n]
    origin = -(Ln[:3, :3].T @ Ln[:3, 3])  # that frame's origin in link-n coordinates
    pin.computeJointJacobians(model, data, q)
    pin.computeJointKinematicHessians(model, data, q)
    H_lwa = _pin_hessian(model, data, n, pin.LOCAL_WORLD_ALIGNED, n)
    np.testing.assert_allclose(robot.hessian(q, link=n, point=origin), H_lwa, atol=1e-9)
    H_loc = _pin_hessian(model, data, n, pin.LOCAL, n)
    B = np.kron(np.eye(2), Ln[:3, :3])  # Pinocchio's LOCAL axes = link frame n's · L[n]⁻¹
    H_ee = np.einsum("ab,bjk->ajk", B, robot.hessian(q, "ee", link=n, point=origin))
    np.testing.assert_allclose(H_ee, H_loc, atol=1e-9)


@pytest.mark.parametrize("robot", MODELS, ids=MODEL_IDS)
def test_second_order_matches_pinocchio_on_models(robot):
    """Every built-in model: J̇ (both frames) and ∂J/∂q (both frames) equal Pinocchio's."""
    rng = np.random.default_rng(5)
    for q in robot.random_q(3, seed=rng):
        _check_robot(robot, q, rng.normal(size=robot.n))


@settings(max_examples=25, deadline=None)
@given(rows=dh_rows(), convention=st.sampled_from(["standard", "modified"]),
       seed=st.integers(0, 2**32 - 1))
def test_second_order_matches_pinocchio_on_random_dh(rows, convention, seed):
    """Random DH tables (R and P joints, base and tool): J̇ and ∂J/∂q equal Pinocchio's."""
    rng = np.random.default_rng(seed)
    robot = sk.Robot.from_dh(rows, convention, base=random_transform(rng),
                             tool=random_transform(rng))
    _check_robot(robot, robot.random_q(seed=rng), rng.normal(size=robot.n))
