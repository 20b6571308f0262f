"""A Pinocchio model with exactly a serialkin robot's kinematics, built from its chain."""

from __future__ import annotations

import numpy as np

import serialkin as sk


def pin_model(pin, robot: sk.Robot):
    """(model, data, tool frame id): one RZ/PZ joint per compiled joint, F[i] as placements.

    Every compiled joint moves about / along z (see :mod:`serialkin.model.chain`), so
    joint i is placed at ``F[i-1]·M(offset_i)`` and the tool is an operational frame at
    ``F[n]`` on the last joint. Pinocchio's joint i frame is then serialkin's frame just
    after joint i's motion, i.e. link frame i times ``L[i]⁻¹``.
    """
    F, meta = robot.chain.F, robot.chain.meta
    model = pin.Model()
    parent = 0
    for i in range(robot.n):
        off = meta[i, 4]
        M = np.eye(4)
        if meta[i, 3] == 0:
            c, s = np.cos(off), np.sin(off)
            M[:2, :2] = [[c, -s], [s, c]]
            joint = pin.JointModelRZ()
        else:
            M[2, 3] = off
            joint = pin.JointModelPZ()
        P = F[i] @ M
        parent = model.addJoint(parent, joint, pin.SE3(P[:3, :3], P[:3, 3]), f"j{i + 1}")
    tool = F[robot.n]
    fid = model.addFrame(pin.Frame("tool", parent, 0, pin.SE3(tool[:3, :3], tool[:3, 3]),
                                   pin.FrameType.OP_FRAME))
    return model, model.createData(), fid
