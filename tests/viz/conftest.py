"""Shared fixtures for the viz tests: a headless matplotlib backend and small robots."""

import matplotlib
import numpy as np
import pytest

matplotlib.use("Agg")

import matplotlib.pyplot as plt  # noqa: E402

from serialkin import Robot  # noqa: E402


@pytest.fixture(autouse=True)
def _close_figures():
    """Close every figure a test opened."""
    yield
    plt.close("all")


@pytest.fixture(scope="session")
def planar3():
    """A planar RRR arm with a tool offset."""
    rows = [dict(a=0.5, alpha=0.0, d=0.0, theta=0.0), dict(a=0.4, alpha=0.0, d=0.0, theta=0.0),
            dict(a=0.3, alpha=0.0, d=0.0, theta=0.0)]
    tool = np.eye(4)
    tool[0, 3] = 0.05
    return Robot.from_dh(rows, tool=tool, name="planar3")


@pytest.fixture(scope="session")
def spatial4():
    """A spatial RRPR arm (standard DH) with a base offset and a prismatic joint."""
    rows = [
        dict(a=0.0, alpha=np.pi / 2, d=0.4, theta=0.0),
        dict(a=0.5, alpha=0.0, d=0.0, theta=0.0),
        dict(a=0.0, alpha=np.pi / 2, d=0.1, theta=0.0, type="P", qlim=(0.0, 0.3)),
        dict(a=0.2, alpha=0.0, d=0.05, theta=0.0),
    ]
    base = np.eye(4)
    base[:3, 3] = [0.1, -0.2, 0.05]
    return Robot.from_dh(rows, base=base, name="spatial4")
