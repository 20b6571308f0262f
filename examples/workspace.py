"""Workspace of the planar 2-link arm by sampling, against the closed form (chapter section 1).

With unlimited joints the reachable workspace of a 2-link arm is the annulus between the
radii |L1 − L2| and L1 + L2, of area π((L1 + L2)² − (L1 − L2)²) = 4π·L1·L2.
``reachable_workspace`` samples joint space uniformly, counts occupied cells of a grid
and states an error bound ε (grid resolution + cells that the sampling may have missed);
the closed form must lie within Â ± ε, and ε shrinks as the number of samples grows.

Writes ``two_link_workspace.png`` into ``$SERIALKIN_EXAMPLE_OUT`` (default: a new
temporary folder). Run: ``python examples/workspace.py`` (a few seconds).
"""

import math
import os
import tempfile
from pathlib import Path

import matplotlib

matplotlib.use("Agg")  # files only, no window

import matplotlib.pyplot as plt  # noqa: E402

import serialkin as sk  # noqa: E402
from serialkin.workspace import reachable_workspace  # noqa: E402
from serialkin.workspace.plot import plot_manipulability_map, plot_workspace  # noqa: E402

out = Path(os.environ.get("SERIALKIN_EXAMPLE_OUT") or tempfile.mkdtemp(prefix="serialkin_"))
out.mkdir(parents=True, exist_ok=True)

print(f"{'L1':>5}{'L2':>5}{'samples':>9}{'estimate Â [m²]':>17}{'± ε':>8}"
      f"{'closed form':>13}{'|Â − A|':>9}  within ε")
for L1, L2 in [(1.0, 0.6), (0.5, 0.5), (0.3, 0.7)]:
    arm = sk.models.two_link(L1, L2)
    exact = math.pi * ((L1 + L2) ** 2 - (L1 - L2) ** 2)
    for samples in (20_000, 100_000, 400_000):
        ws = reachable_workspace(arm, samples, seed=0, progress=False)
        est = ws.estimate                              # MeasureEstimate: value, error, cell, ...
        ok = abs(est.value - exact) <= est.error
        print(f"{L1:>5}{L2:>5}{samples:>9}{est.value:>17.4f}{est.error:>8.3f}"
              f"{exact:>13.4f}{abs(est.value - exact):>9.4f}  {ok}")
        assert ok, "the closed form must lie within the stated error"

# The 1.0 / 0.6 arm once more with its manipulability (eq 43, here L1·L2·|sin q2|) per sample
arm = sk.models.two_link(1.0, 0.6)
ws = reachable_workspace(arm, 200_000, seed=1, manipulability=True, progress=False)
print(f"\ntwo_link(1.0, 0.6): {ws.estimate}")
print(f"  largest sampled manipulability {ws.manipulability.max():.4f} "
      f"(closed-form maximum L1·L2 = {1.0 * 0.6:.4f}, at q2 = ±90°)")

fig, axes = plt.subplots(1, 2, figsize=(11, 5))
plot_workspace(ws, axes[0], robot=arm, q=[0.6, 1.2])
plot_manipulability_map(ws, axes[1])
fig.tight_layout()
fig.savefig(out / "two_link_workspace.png", dpi=80)
print("wrote", out / "two_link_workspace.png")
