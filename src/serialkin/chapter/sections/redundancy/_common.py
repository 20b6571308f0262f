"""Section 5.3 (redundancy): the equations shown, timed runs, eq 48 by hand, plot helpers."""

from __future__ import annotations

from typing import Any

import numpy as np

from serialkin.chapter._context import ReportContext, Timing
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


def _smoothstep(s: np.ndarray) -> np.ndarray:
    """σ(s) = 3s² − 2s³ with s clipped to [0, 1] (the designed eq 49's ramp)."""
    s = np.clip(s, 0.0, 1.0)
    return 3.0 * s**2 - 2.0 * s**3


def _planar_joint_points(robot: Any, q: np.ndarray) -> np.ndarray:
    """Joint positions s_0 … s_n of a planar revolute chain, (n + 1, 2), by eq 21's pattern.

    s_k = s_(k−1) + L_k (cos θ_k, sin θ_k), θ_k = q_1 + … + q_k, from the DH lengths a_k
    and the base's origin (no library kinematics).
    """
    L = np.array([row.a for row in robot.dh], dtype=float)
    theta = np.cumsum(q + np.array([row.theta for row in robot.dh], dtype=float))
    steps = L[:, None] * np.c_[np.cos(theta), np.sin(theta)]
    return np.vstack([np.zeros((1, 2)), np.cumsum(steps, axis=0)]) + robot.base[:2, 3]


def _cross_z(points: np.ndarray, about: np.ndarray) -> np.ndarray:
    """Columns ẑ × (p − s_j) of a planar revolute chain: shape (2, len(about))."""
    d = points[None, :] - about
    return np.vstack([-d[:, 1], d[:, 0]])


def eq48_by_hand(scenario: Scenario, q: np.ndarray, xdot: np.ndarray) -> dict[str, Any]:
    """Eq 48 assembled with numpy from the chapter's formulas, without serialkin's kinematics.

    For a planar revolute chain between circular obstacles: joint positions from the link
    lengths (eq 21's pattern), the task Jacobian by eq 35 (ẑ × (p_E − s_j)), eq 49's
    weights with σ(s) = 3s² − 2s³ (eq 50's diagonal), per link and obstacle eqs 51-54
    (clamped projection, closest point, distance, unit vector) and eq 55's row
    −u_iᵀ J_sci with eq 56's J_sci by eq 35 again, kept within the distance of influence
    and weighted W_c σ((d_infl − c)/d_infl); W_s = (λ² + λ_s²) I with the singularity
    damping of the resolver. Only the resolver's settings (weights, buffer, damping) and
    the obstacles' geometry are read from the library's objects.

    Returns:
        dict with ``qdot`` (n,), ``W_L`` (n,) diagonal of eq 50, ``J_c`` (r, n), ``W_c``
        (r,), ``clearance`` (r,), ``lambda_s``, ``w`` and ``points`` (n + 1, 2).
    """
    res = scenario.solver
    robot = scenario.robot
    q = np.asarray(q, dtype=float)
    n = q.shape[0]
    S = _planar_joint_points(robot, q)
    J = _cross_z(S[-1], S[:-1])  # eq 35, (2, n)
    lim = np.asarray(robot.qlim, dtype=float)
    b = res.limit_buffer * (lim[:, 1] - lim[:, 0])
    low = _smoothstep((lim[:, 0] + b - q) / b)
    high = _smoothstep((q - lim[:, 1] + b) / b)
    WL = res.joint_limit_weight * np.maximum(low, high)  # eq 49
    rows, clear, weights = [], [], []
    for obs in scenario.obstacles:
        s0 = np.asarray(obs.center, dtype=float)[:2]
        for i in range(n):  # link i + 1 runs from S[i] to S[i + 1]
            ell = float(np.linalg.norm(S[i + 1] - S[i]))
            if ell == 0.0:
                continue
            e = (S[i + 1] - S[i]) / ell
            p = min(max(float(e @ (s0 - S[i])), 0.0), ell)  # eq 51 (clamped)
            s_c = S[i] + p * e  # eq 52
            d = float(np.linalg.norm(s_c - s0))  # eq 53
            c = d - obs.radius - res.link_radius
            if c >= obs.influence:
                continue
            u = (s_c - s0) / d  # eq 54
            J_sc = np.zeros((2, n))
            J_sc[:, :i + 1] = _cross_z(s_c, S[:i + 1])  # eq 56: joints 1 … i + 1 move it
            rows.append(-u @ J_sc)  # eq 55
            clear.append(c)
            weights.append(res.obstacle_weight
                           * float(_smoothstep((obs.influence - c) / obs.influence)))
    Jc = np.array(rows).reshape(-1, n)
    Wc = np.array(weights)
    w = float(np.sqrt(max(np.linalg.det(J @ J.T), 0.0)))  # eq 43
    w0 = res.manipulability_threshold
    lam_s = res.singularity_damping * max(0.0, 1.0 - w / w0) if w0 > 0 else 0.0
    A = (res.weight * J.T @ J + Jc.T @ (Wc[:, None] * Jc) + np.diag(WL)
         + (res.damping ** 2 + lam_s ** 2) * np.eye(n))
    qdot = np.linalg.solve(A, res.weight * J.T @ xdot)  # eq 48
    return {"qdot": qdot, "W_L": WL, "J_c": Jc, "W_c": Wc, "clearance": np.array(clear),
            "lambda_s": lam_s, "w": w, "points": S}


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


def _where(sc: Scenario, mask: np.ndarray) -> str:
    """The path points of ``mask`` as "path points a–b (phase k)", phases by their ranges."""
    idx = np.flatnonzero(mask)
    if not idx.size:
        return "no path point"
    phases = _phases(sc)
    names = []
    for a, b, name in phases:
        if ((idx >= a) & (idx <= b)).any():
            names.append(f"phase {name}")
    if any(not any(a <= k <= b for a, b, _ in phases) for k in idx):
        names.append("the return between phases 2 and 3" if phases else "")
    where = " and ".join(n for n in names if n)
    return (f"{idx.size} path point{'s' if idx.size > 1 else ''} between {idx[0]} and "
            f"{idx[-1]}" + (f" ({where})" if where else ""))


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
