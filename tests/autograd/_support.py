"""Shared helpers of the autograd tests: the extras' import rule and the robots tested."""

from __future__ import annotations

import importlib
import os
from types import ModuleType

import numpy as np
import pytest

import serialkin as sk
from serialkin import models
from tests.kinematics._fd import random_transform

#: Set by `make test-autograd`: there a missing extra fails the run instead of skipping it.
REQUIRED = "SERIALKIN_AUTOGRAD_REQUIRED"


def require(name: str) -> ModuleType:
    """Import ``name``; when missing, skip the module (fail it under ``make test-autograd``)."""
    try:
        return importlib.import_module(name)
    except ImportError as exc:
        message = (f"{name} is not installed ({exc}); `make test-autograd` installs the "
                   "torch and jax extras and runs tests/autograd")
        if os.environ.get(REQUIRED):
            pytest.fail(message, pytrace=False)
        pytest.skip(message, allow_module_level=True)


def random_arm(seed: int, types: str) -> sk.Robot:
    """A random standard-DH arm with the given joint types ('R'/'P'), random base and tool."""
    rng = np.random.default_rng(seed)
    rows = [{"a": rng.uniform(-0.6, 0.6), "alpha": rng.uniform(-np.pi, np.pi),
             "d": rng.uniform(-0.6, 0.6), "theta": rng.uniform(-np.pi, np.pi), "type": t}
            for t in types]
    return sk.Robot.from_dh(rows, "standard", base=random_transform(rng),
                            tool=random_transform(rng), name=f"random-{types}-{seed}")


def gradient_robots() -> list[tuple[str, sk.Robot]]:
    """UR5, Panda and random DH arms with revolute and prismatic joints."""
    return [("ur5", models.get("ur5")), ("panda", models.get("panda")),
            ("rprp", random_arm(1, "RPRP")), ("rrprrr", random_arm(2, "RRPRRR")),
            ("prrrrrr", random_arm(3, "PRRRRRR"))]


def well_conditioned_q(robot: sk.Robot, count: int, seed: int, sigma_min: float = 0.08
                       ) -> np.ndarray:
    """``count`` configurations whose Jacobian's smallest singular value exceeds sigma_min."""
    rng = np.random.default_rng(seed)
    out = []
    while len(out) < count:
        q = robot.random_q(seed=rng)
        if np.linalg.svd(robot.jacobian(q), compute_uv=False).min() > sigma_min:
            out.append(q)
    return np.array(out)


