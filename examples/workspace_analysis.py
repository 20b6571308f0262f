"""Workspace analysis (chapter section 1): areas with their sampling error, and figures.

Writes its figures to $SERIALKIN_EXAMPLE_OUT (default out/examples).
"""

import math
import os
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

import serialkin as sk  # noqa: E402
from serialkin.formats.robotfile import load_robot_file  # noqa: E402
from serialkin.workspace import (  # noqa: E402
    constant_orientation_workspace,
    reachable_workspace,
    workspace_slice,
)
from serialkin.workspace.plot import plot_slice, plot_workspace, plot_workspace_kinds  # noqa: E402

out = Path(os.environ.get("SERIALKIN_EXAMPLE_OUT", "out/examples"))
out.mkdir(parents=True, exist_ok=True)

# 2-link arm: sampled area against π((L1+L2)² − (L1−L2)²)
L1, L2 = 1.0, 0.6
ws = reachable_workspace(sk.models.two_link(L1, L2), 200_000, seed=0, manipulability=True)
exact = math.pi * ((L1 + L2) ** 2 - (L1 - L2) ** 2)
print(ws.estimate, "| closed form", round(exact, 4),
      "| within the bound:", abs(ws.estimate.value - exact) <= ws.estimate.error)
ax = plot_workspace(ws)
ax.figure.savefig(out / "two_link_workspace.png", dpi=90)

# 3-link arm: maximal vs constant-orientation workspace
three = sk.models.three_link(1.0, 0.8, 0.3)
a = reachable_workspace(three, 100_000, seed=0)
b = constant_orientation_workspace(three, math.radians(45), 100_000, seed=0)
ax = plot_workspace_kinds([a, b], labels=["maximal", "constant φ = 45°"])
ax.figure.savefig(out / "three_link_kinds.png", dpi=90)

# a spatial robot from a robot file (mm and degrees): volume and a slice
puma = load_robot_file(Path(__file__).parent / "robots" / "puma560.yaml")
ws3 = reachable_workspace(puma, 150_000, seed=0)
print(puma.name, ws3.estimate)
sl = workspace_slice(ws3, "z", 0.67)
ax = plot_slice(sl)
ax.figure.savefig(out / "puma560_slice.png", dpi=90)
plt.close("all")
print("figures in", out)
