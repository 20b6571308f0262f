"""Section 5.3 (redundancy): the equations shown, timed runs, eq 48 by hand, plot helpers."""

from __future__ import annotations

from typing import Any

import numpy as np

from serialkin.chapter._context import ReportContext, Timing
from serialkin.redundancy import (
    joint_limit_weights,
    obstacle_jacobian,
)
from serialkin.redundancy.multitask import smoothstep
from serialkin.tracking.scenario import Scenario

DEG = 180.0 / np.pi

#: The chapter's equations of this part, as LaTeX (corrected per the ERRATA where marked).
EQ = {
    "42": r"\dot{\mathbf{q}} = \mathbf{J}^{\dagger}(\mathbf{q})\,\dot{\mathbf{x}}"
          r" + \left(\mathbf{I} - \mathbf{J}^{\dagger}\mathbf{J}\right)\dot{\mathbf{q}}_0",
    "43": r"H(\mathbf{q}) = \sqrt{\det\left(\mathbf{J}(\mathbf{q})\,\mathbf{J}^{T}(\mathbf{q})"
          r"\right)}",
    "44": r"H(\mathbf{q}) = \frac{1}{2}\sum_{i=1}^{n}\left(\frac{q_i - \bar{q}_i}"
          r"{q_{M,i} - q_{m,i}}\right)^2,\qquad \bar{q}_i = \frac{q_{M,i} + q_{m,i}}{2}",
    "46": r"\Delta\mathbf{q} = \mathbf{J}^{T}\left(\mathbf{J}\mathbf{J}^{T} + \lambda^{2}"
          r"\mathbf{I}\right)^{-1}\Delta\mathbf{x},\qquad \mathbf{q} \leftarrow \mathbf{q}"
          r" + \Delta\mathbf{q}",
    "47": r"H = \left\|\mathbf{J}\dot{\mathbf{q}} - \dot{\mathbf{x}}\right\|^2_{\mathbf{W}}"
          r" + \left\|\mathbf{J}_c\dot{\mathbf{q}} - \mathbf{x}_c\right\|^2_{\mathbf{W}_c}"
          r" + \left\|\mathbf{J}_L\dot{\mathbf{q}} - \mathbf{x}_L\right\|^2_{\mathbf{W}_L}"
          r" + \left\|\dot{\mathbf{q}}\right\|^2_{\mathbf{W}_s}",
    "48": r"\dot{\mathbf{q}} = \left(\mathbf{J}^{T}\mathbf{W}\mathbf{J} + \mathbf{J}_c^{T}"
          r"\mathbf{W}_c\mathbf{J}_c + \mathbf{J}_L^{T}\mathbf{W}_L\mathbf{J}_L + \mathbf{W}_s"
          r"\right)^{-1}\mathbf{J}^{T}\mathbf{W}\dot{\mathbf{x}}",
    "49": r"W_{Li} = W_{L,\max}\cdot\begin{cases} 0 & q_{m,i} + b_i \le q_i \le q_{M,i} - b_i"
          r" \\ \sigma\left(\frac{q_{m,i} + b_i - q_i}{b_i}\right) & q_i < q_{m,i} + b_i \\"
          r" \sigma\left(\frac{q_i - q_{M,i} + b_i}{b_i}\right) & q_i > q_{M,i} - b_i"
          r" \end{cases}",
    "50": r"\mathbf{W}_L = \begin{bmatrix} W_{L1} & & & \\ & W_{L2} & & \\ & & \ddots & \\"
          r" & & & W_{Ln} \end{bmatrix},\qquad \mathbf{J}_L = \mathbf{I}",
    "51": r"p_i = \min\left(\max\left(\mathbf{e}_i^{T}(\mathbf{s}_0 - \mathbf{s}_i),\ 0\right),"
          r"\ \ell_i\right)",
    "52": r"\mathbf{s}_{ci} = \mathbf{s}_i + p_i\,\mathbf{e}_i",
    "53": r"d_{ci} = \left\|\mathbf{s}_{ci} - \mathbf{s}_0\right\|",
    "54": r"\mathbf{u}_i = \frac{\mathbf{s}_{ci} - \mathbf{s}_0}{d_{ci}}",
    "55": r"\mathbf{J}_{ci} = -\mathbf{u}_i^{T}\,\mathbf{J}_{s_{ci}}",
    "56": r"\mathbf{J}_{s_{ci}} = \frac{\partial\mathbf{s}_{ci}}{\partial\mathbf{q}}",
}

# ---------------------------------------------------------------------------------- helpers
def timed_run(ctx: ReportContext, scenario: Any, repeat: int = 5) -> tuple[Any, Timing]:
    """Run ``scenario.run()`` once untimed (warm-up: compilation, caches), then time it.

    Returns:
        (the trajectory of the warm-up run, the :class:`Timing` of ``repeat`` warm runs).
    """
    runs: list[Any] = []

    def run() -> None:
        runs.append(scenario.run())

    timing = ctx.timing(run, warmup=1, repeat=repeat)
    del runs[1:]  # every run gives the same trajectory; keep the warm-up's
    return runs[0], timing


def eq48_by_hand(scenario: Scenario, q: np.ndarray, xdot: np.ndarray) -> dict[str, Any]:
    """Assemble eq 48 from its parts (eqs 49-50, 55, the W_s of the resolver) with numpy.

    Returns:
        dict with ``qdot`` (n,), ``W_L`` (n,) diagonal of eq 50, ``J_c`` (r, n), ``W_c``
        (r,), ``lambda_s`` and ``w``.
    """
    res = scenario.solver
    robot = scenario.robot
    J = robot.jacobian(q)[:2]
    lim = np.asarray(robot.qlim, dtype=float)
    WL = joint_limit_weights(q, lim, buffer=res.limit_buffer, max_weight=res.joint_limit_weight)
    Jc, clear, pairs = obstacle_jacobian(robot, q, scenario.obstacles)
    infl = np.array([scenario.obstacles[j].influence for _, j in pairs])
    Wc = (res.obstacle_weight * smoothstep((infl - clear) / infl) if len(pairs)
          else np.zeros(0))
    w = float(np.sqrt(max(np.linalg.det(J @ J.T), 0.0)))
    w0 = res.manipulability_threshold
    lam_s = res.singularity_damping * max(0.0, 1.0 - w / w0) if w0 > 0 else 0.0
    A = (res.weight * J.T @ J + Jc.T @ (Wc[:, None] * Jc) + np.diag(WL)
         + (res.damping ** 2 + lam_s ** 2) * np.eye(robot.n))
    qdot = np.linalg.solve(A, res.weight * J.T @ xdot)
    return {"qdot": qdot, "W_L": WL, "J_c": Jc, "W_c": Wc, "lambda_s": lam_s, "w": w}


def _phase_marks(scenario: Scenario) -> list[int]:
    """Path indices of the designed scenario's waypoints (phase boundaries), if any."""
    wp = (scenario.data.get("path") or {}).get("waypoints")
    if not wp:
        return []
    P = scenario.path.points[:, :2]
    return [int(np.argmin(np.linalg.norm(P - np.asarray(w, dtype=float)[:2], axis=1)))
            for w in wp]


def _phases(scenario: Scenario) -> list[tuple[int, int, str]]:
    """(first, last, label) of the three phases of ``twenty_link_*`` (empty otherwise)."""
    m = _phase_marks(scenario)
    if len(m) < 14:
        return []
    return [(0, m[2], "1"), (m[2], m[9], "2"), (m[13], len(scenario.path) - 1, "3")]


def _shade(ax: Any, phases: list[tuple[int, int, str]], label: bool = False) -> None:
    for k, (a, b, name) in enumerate(phases):
        ax.axvspan(a, b, color=("tab:purple", "tab:orange", "tab:green")[k], alpha=0.13, lw=0,
                   zorder=0)
        if label:
            ax.text((a + b) / 2, 0.93, f"phase {name}", transform=ax.get_xaxis_transform(),
                    ha="center", va="top", fontsize="small")


def _gif(ctx: ReportContext, robot: Any, tr: Any, name: str, caption: str,
         obstacles: Any = None, frames: int = 40) -> str:
    from serialkin.viz import AnimationOptions, animate_trajectory

    options = AnimationOptions(max_frames=frames, fps=8, dpi=60, figsize=(5.0, 4.5),
                               title=caption)
    data = animate_trajectory(robot, tr.q, options, path_points=tr.targets[:, :2, 3],
                              obstacles=obstacles)
    return ctx.file_figure(data, f"{name}.gif", caption)


def _mm(v: float) -> str:
    return f"{v * 1e3:.3g}"
