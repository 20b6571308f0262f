"""Workspace figures: each plot draws its content and renders to PNG."""

from __future__ import annotations

import io

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
import pytest  # noqa: E402

from serialkin import Robot, models  # noqa: E402
from serialkin.errors import InputError  # noqa: E402
from serialkin.workspace import constant_orientation_workspace, reachable_workspace  # noqa: E402
from serialkin.workspace.plot import (  # noqa: E402
    plot_manipulability_map,
    plot_slice,
    plot_workspace,
    plot_workspace_kinds,
)


def _png(ax) -> bytes:
    buf = io.BytesIO()
    ax.figure.savefig(buf, format="png", dpi=50)
    plt.close(ax.figure)
    return buf.getvalue()


@pytest.fixture(scope="module")
def planar_ws():
    r = Robot.from_dh([dict(a=1, alpha=0, d=0, theta=0), dict(a=0.6, alpha=0, d=0, theta=0)])
    return r, reachable_workspace(r, 40_000, seed=0, manipulability=True, progress=False)


def test_plot_planar_workspace(planar_ws):
    """The planar plot has samples, the two boundary rims and the area in the title."""
    r, ws = planar_ws
    ax = plot_workspace(ws, robot=r, q=[0.3, 0.5])
    assert len(ax.collections) >= 1
    assert sum(1 for ln in ax.lines if ln.get_label() == "boundary") == 1
    assert "area" in ax.get_title() and "±" in ax.get_title()
    assert _png(ax).startswith(b"\x89PNG")


def test_plot_manipulability_map(planar_ws):
    """The manipulability map image holds the per-cell maxima."""
    _, ws = planar_ws
    ax = plot_manipulability_map(ws)
    img = ax.images[0].get_array()
    assert np.nanmax(img) == pytest.approx(np.nanmax(ws.manipulability_map()))
    assert _png(ax).startswith(b"\x89PNG")


def test_plot_spatial_and_slice():
    """A spatial workspace plots as a 3D cloud, and a slice as 2D with its area."""
    ws = reachable_workspace(models.get("puma560"), 30_000, seed=0, progress=False)
    ax = plot_workspace(ws)
    assert ax.name == "3d"
    assert _png(ax).startswith(b"\x89PNG")
    ax = plot_slice(ws, "z", 0.6)
    assert "slice z = 0.6" in ax.get_title()
    assert _png(ax).startswith(b"\x89PNG")


def test_plot_kinds_overlay(planar_ws):
    """Overlaying kinds labels each with its measure; spatial input is refused."""
    r3 = models.get("three_link")
    a = reachable_workspace(r3, 20_000, seed=0, progress=False)
    b = constant_orientation_workspace(r3, 0.0, 20_000, seed=0, progress=False)
    ax = plot_workspace_kinds([a, b])
    labels = [t.get_text() for t in ax.get_legend().get_texts()]
    assert len(labels) == 2 and all("area" in t for t in labels)
    _png(ax)
    ws3 = reachable_workspace(models.get("puma560"), 2000, seed=0, progress=False)
    with pytest.raises(InputError, match="planar"):
        plot_workspace_kinds([ws3])
