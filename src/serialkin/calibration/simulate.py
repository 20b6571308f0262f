"""Simulated calibrations: a perturbed "real" robot and noisy measurements of it.

``perturb`` draws every parameter of an error model uniformly in ``nominal ± length``
(translations) or ``± angle`` (rotations); ``perturb_joints`` makes a "real" robot without
any error model: every joint origin moved and tilted in all six directions, and a marker
offset on the flange; ``simulate_measurements`` measures a robot
at configurations with Gaussian noise of standard deviation ``noise_position`` [m] per
coordinate and ``noise_rotation`` [rad] about each axis (a rotation ``exp(n)·R`` with
``n ~ N(0, σ² I)``).
"""

from __future__ import annotations

import numpy as np

from serialkin._checks import as_generator, as_vector, check_choice, check_int, check_positive
from serialkin.calibration.measurements import (
    KINDS,
    SIGMA_POSITION,
    SIGMA_ROTATION,
    Measurements,
    make_measurements,
)
from serialkin.calibration.models import ErrorModel
from serialkin.errors import InputError
from serialkin.model.robot import Robot


def perturb(model: ErrorModel, *, length: float = 1e-3, angle: float = np.radians(0.5),
            scale: float = 1e-3,
            seed: None | int | np.random.Generator = None) -> np.ndarray:
    """Parameters (p,) drawn uniformly in ``nominal ± length / angle / scale``.

    ``length`` [m] for translations, ``angle`` [rad] for rotations, ``scale``
    (dimensionless) for encoder scale errors.
    """
    length = check_positive(length, "length", allow_zero=True)
    angle = check_positive(angle, "angle", allow_zero=True)
    scale = check_positive(scale, "scale", allow_zero=True)
    rng = as_generator(seed)
    half = np.array([length if p.unit == "m" else angle if p.unit == "rad" else scale
                     for p in model.parameters])
    return model.nominal + rng.uniform(-1.0, 1.0, model.size) * half


def perturb_joints(robot: Robot, *, length: float = 1e-3, angle: float = np.radians(0.3),
                   marker: float = 0.0, seed: None | int | np.random.Generator = None) -> Robot:
    """A "real" robot: ``robot`` with every joint origin moved and tilted, and a marker.

    Independent of the error models: joint i's origin becomes ``origin · Txyz(t) · R(r)``
    with each component of t uniform in ``± length`` [m] and of the rotation vector r
    uniform in ``± angle`` [rad] (so position, axis direction and zero of every joint
    change), and the tool becomes ``tool · Txyz(v)``: a marker offset v in a random
    direction, its length uniform in ``[marker/2, marker]`` [m] (0: the flange itself).

    Args:
        robot: the nominal robot.
        length: largest origin translation per axis [m].
        angle: largest origin rotation about each axis [rad].
        marker: largest marker offset [m].
        seed: None, int or numpy Generator.

    Returns:
        the perturbed :class:`~serialkin.Robot` (general joints, no DH table).
    """
    from serialkin.model.joint import Joint
    from serialkin.spatial.lie import so3_exp
    from serialkin.spatial.transforms import make_transform

    length = check_positive(length, "length", allow_zero=True)
    angle = check_positive(angle, "angle", allow_zero=True)
    marker = check_positive(marker, "marker", allow_zero=True)
    rng = as_generator(seed)
    joints = []
    for j in robot.joints:
        d = make_transform(so3_exp(rng.uniform(-angle, angle, 3)),
                           rng.uniform(-length, length, 3))
        joints.append(Joint(axis=j.axis, type=j.type, origin=j.origin @ d, post=j.post,
                            offset=j.offset, qlim=j.qlim, name=j.name))
    v = rng.normal(size=3)
    v *= marker * rng.uniform(0.5, 1.0) / np.linalg.norm(v)
    return Robot.from_joints(joints, base=robot.base, tool=robot.tool @ make_transform(p=v),
                             name=f"{robot.name} (perturbed)",
                             source=f"perturbed from {robot.name}")


def simulate_measurements(robot: Robot, q: object, *, kind: str = "position",
                          noise_position: float = 5e-5, noise_rotation: float = 0.0,
                          sigma_position: float | None = None,
                          sigma_rotation: float | None = None,
                          joint_scale: object = None, markers: object = None,
                          seed: None | int | np.random.Generator = None) -> Measurements:
    """Noisy measurements of ``robot``'s tool at configurations ``q``.

    The robot is at ``q``; the joint values recorded are ``q / joint_scale`` (what
    encoders with those scale factors read). With ``markers`` (K, 3) the measured point of
    row i is marker ``i mod K`` at ``T(q) · markers[k]`` (offsets [m] in the tool frame;
    give marker 0 as zeros for the tool origin), and the measurements say which.

    Args:
        robot: the "real" robot (e.g. ``model.calibrated_robot(perturb(model))``).
        q: (m, n) configurations, or an int m for m random ones inside the limits.
        kind: 'position' or 'pose'.
        noise_position: standard deviation of each coordinate [m] (0 for exact).
        noise_rotation: standard deviation of the rotation about each axis [rad].
        sigma_position: the sigma stated in the measurements (default the noise, or
            :data:`~serialkin.calibration.measurements.SIGMA_POSITION` when 0).
        sigma_rotation: likewise for rotations.
        joint_scale: (n,) factors ``1 + s_i`` of the real joint values over the recorded
            ones (default 1).
        markers: (K, 3) marker offsets [m] in the tool frame, or None (the tool origin).
        seed: None, int or numpy Generator.

    Returns:
        :class:`~serialkin.calibration.measurements.Measurements`.
    """
    from serialkin.spatial.lie import so3_exp

    check_choice(kind, "kind", KINDS)
    rng = as_generator(seed)
    npos = check_positive(noise_position, "noise_position", allow_zero=True)
    nrot = check_positive(noise_rotation, "noise_rotation", allow_zero=True)
    if isinstance(q, (int, np.integer)) and not isinstance(q, bool):
        qa = robot.random_q(check_int(q, "q", minimum=1), seed=rng)
    else:
        qa = robot.check_q(q).reshape(-1, robot.n)
    T = robot.fk(qa)
    which = None
    if markers is not None:
        from serialkin._checks import as_float_array

        w = as_float_array(markers, "markers", ndim=2)
        if w.shape[1] != 3 or w.shape[0] < 1:
            raise InputError(f"markers must have shape (K, 3), got {w.shape}")
        which = np.arange(len(qa)) % w.shape[0]
        T[:, :3, 3] += np.einsum("mij,mj->mi", T[:, :3, :3], w[which])
    recorded = qa
    if joint_scale is not None:
        recorded = qa / as_vector(joint_scale, "joint_scale", robot.n)
    sp = sigma_position or (npos if npos > 0 else SIGMA_POSITION)
    sr = sigma_rotation or (nrot if nrot > 0 else SIGMA_ROTATION)
    pos = T[:, :3, 3] + rng.normal(0.0, 1.0, (len(qa), 3)) * npos
    if kind == "position":
        return make_measurements(robot, recorded, positions=pos, sigma_position=sp,
                                 markers=which)
    T[:, :3, 3] = pos
    T[:, :3, :3] = so3_exp(rng.normal(0.0, 1.0, (len(qa), 3)) * nrot) @ T[:, :3, :3]
    return make_measurements(robot, recorded, poses=T, sigma_position=sp, sigma_rotation=sr,
                             markers=which)
