"""Report section 3, forward kinematics (eqs 10-18), recomputed by serialkin.

Contents: the SCARA of Table 1 (:func:`serialkin.models.scara`), its link matrices
(eqs 13-16) and end-effector transform (eqs 17-18, with the ERRATA's correction of eq 17)
derived symbolically by :mod:`serialkin.kinematics.symbolic` and evaluated numerically at
a sample configuration, checked against the compiled kernels and against the product of
the individual matrices; RᵀR = I and det R = 1 (eq 7) on the result; the same robot
rewritten in modified DH; figures of the mechanism in 3D with its DH frames; and the
table of built-in models with their sources.
"""

from __future__ import annotations

import html

import numpy as np
import sympy as sp

from serialkin import models
from serialkin.chapter.report import ReportContext, Section
from serialkin.kinematics.symbolic import derive
from serialkin.model.dh import link_transform, standard_to_modified
from serialkin.model.robot import Robot

DEG = np.pi / 180.0

#: Parameters and sample configuration of the SCARA example (the chapter gives none).
SCARA_PARAMS = {"d1": 0.4, "d2": 0.1, "l1": 0.35, "l2": 0.30}
SCARA_Q = np.array([30 * DEG, -45 * DEG, -0.05, 60 * DEG])


def _symbols() -> dict[str, sp.Symbol]:
    return {k: sp.Symbol(k, real=True) for k in ("L_1", "L_2", "d_1", "d_2")}


def scara_symbolic(robot: Robot):
    """Symbolic SCARA with the chapter's names: a_1→L_1, a_2→L_2, d_1, d_3→d_2 (Table 1)."""
    kin = derive(robot, params="lengths", simplify=True)
    s = _symbols()
    rename = {sp.Symbol("a_1", real=True): s["L_1"], sp.Symbol("a_2", real=True): s["L_2"],
              sp.Symbol("d_3", real=True): s["d_2"]}
    return kin.subs(rename)


def _figure_scara(ctx: ReportContext, robot: Robot, q: np.ndarray) -> str:
    import matplotlib.pyplot as plt

    from serialkin.viz.plot import plot_robot

    fig = plt.figure(figsize=(10, 4.6))
    ax1 = fig.add_subplot(1, 2, 1, projection="3d")
    plot_robot(robot, q, ax=ax1, frames=True, label="q sample")
    ax1.set_title("SCARA at the sample q, DH frames 0-4 and tool (x red, y green, z blue)",
                  fontsize=8)
    ax2 = fig.add_subplot(1, 2, 2, projection="3d")
    rng = np.random.default_rng(3)
    for i, qi in enumerate(robot.random_q(6, seed=rng)):
        plot_robot(robot, qi, ax=ax2, color=f"C{i % 10}", alpha=0.8, markersize=3)
    ax2.set_title("six random configurations inside the joint limits (seed 3)", fontsize=8)
    return ctx.figure(fig, "forward_scara", "Figure 4 regenerated: the SCARA (RRPR) of "
                      "Table 1 drawn from fk_all (eq 11).")


def _figure_frames(ctx: ReportContext, robot: Robot, q: np.ndarray) -> str:
    """Top view of the SCARA's frame origins and x axes, from the computed matrices."""
    import matplotlib.pyplot as plt

    frames = robot.fk_all(q)
    fig, ax = plt.subplots(figsize=(5, 4.6))
    pts = frames[:, :3, 3]
    ax.plot(pts[:, 0], pts[:, 1], "-o", color="0.4", lw=2, mfc="white")
    L = 0.08
    labels: dict[tuple[float, float], list[str]] = {}
    for i, T in enumerate(frames):
        o = T[:3, 3]
        for k, c in ((0, "r"), (1, "g")):
            d = T[:3, k] * L
            ax.annotate("", xy=(o[0] + d[0], o[1] + d[1]), xytext=(o[0], o[1]),
                        arrowprops={"arrowstyle": "->", "color": c, "lw": 1.4})
        zsign = "up" if T[2, 2] > 0 else "down"
        key = (round(float(o[0]), 6), round(float(o[1]), 6))
        labels.setdefault(key, []).append(f"{{{i}}} z {zsign}, h = {o[2]:.2f} m")
    for (x, y), text in labels.items():
        ax.text(x + 0.012, y - 0.02, "\n".join(text), fontsize=8, va="top")
    ax.set_aspect("equal", adjustable="datalim")
    ax.set_xlabel("x [m]")
    ax.set_ylabel("y [m]")
    ax.set_title("Top view: frame origins, x (red) and y (green) axes")
    return ctx.figure(fig, "forward_scara_frames", "SCARA DH frames 0-4 seen from above; "
                      "frame 3 flips z downwards (α3 = π).")


def build(ctx: ReportContext) -> Section:
    """Compute section 3's examples and return the report section."""
    parts: list[str] = []
    robot = models.scara(**SCARA_PARAMS)
    q = SCARA_Q
    s = _symbols()

    # --- Table 1 -------------------------------------------------------------------------
    parts.append(
        "<h3>SCARA: Table 1</h3><p>The chapter's SCARA (RRPR) in standard DH "
        "(A<sub>i</sub> = Rz(θ<sub>i</sub>)·Tz(d<sub>i</sub>)·Tx(a<sub>i</sub>)·"
        "Rx(α<sub>i</sub>)), built by <code>serialkin.models.scara()</code>. The chapter gives "
        "no numbers; this report uses d1 = {d1} m, d2 = {d2} m, L1 = {l1} m, L2 = {l2} m."
        "</p>".format(**SCARA_PARAMS)
    )
    parts.append(ctx.table(
        [("1", "L1", "0", "d1", "q1"), ("2", "L2", "0", "0", "q2"),
         ("3", "0", "π", "d2 + q3", "0"), ("4", "0", "0", "0", "q4")],
        ["link", "a_i", "α_i", "d_i", "θ_i"]))
    parts.append("<p>As built (numbers, joint type and limits):</p>" + ctx.table(
        [(i + 1, r.a, r.alpha, r.d, r.theta, r.type, f"[{r.qlim[0]:.4g}, {r.qlim[1]:.4g}]")
         for i, r in enumerate(robot.dh)],
        ["link", "a [m]", "α [rad]", "d [m]", "θ [rad]", "type", "limits"]))

    # --- symbolic eqs 13-18 ----------------------------------------------------------------
    kin = scara_symbolic(robot)
    A = kin.A
    tex_A = "\n\n".join(
        rf"{{}}^{{{i}}}\mathbf{{A}}_{{{i + 1}}} = {sp.latex(M)}" for i, M in enumerate(A)
    )
    parts.append(
        "<h3>Link matrices, symbolic (eqs 13-16)</h3><p>Derived by "
        "<code>serialkin.kinematics.symbolic.derive(scara, params='lengths')</code> from the DH "
        "formula and simplified (LaTeX):</p>" + ctx.code(tex_A)
    )
    parts.append(
        "<h3>End-effector transform (eqs 17-18)</h3><p>Eq 17 is printed as "
        "0T4 = 0A2 · 1A2 · 2A3 · 3A4; the ERRATA corrects it to "
        "<b>0T4 = 0A1 · 1A2 · 2A3 · 3A4</b>, which gives (simplified):</p>"
        + ctx.code(kin.pretty()) + ctx.code(sp.latex(kin.T))
        + "<p>so the end-effector position (eq 18) is p = (L1 cos q1 + L2 cos(q1+q2), "
        "L1 sin q1 + L2 sin(q1+q2), d1 + d2 + q3) and the tool z axis points down.</p>"
    )

    # --- numeric ----------------------------------------------------------------------------
    A_num = [link_transform(r, qi, "standard") for r, qi in zip(robot.dh, q, strict=True)]
    T_prod = A_num[0] @ A_num[1] @ A_num[2] @ A_num[3]
    T_fk = robot.fk(q)
    subs = {s["L_1"]: SCARA_PARAMS["l1"], s["L_2"]: SCARA_PARAMS["l2"],
            s["d_1"]: SCARA_PARAMS["d1"], s["d_2"]: SCARA_PARAMS["d2"]}
    T_sym = np.array(kin.T.subs(subs).subs(dict(zip(kin.q, q, strict=True))).evalf(),
                     dtype=float)
    misprint = (A_num[0] @ A_num[1]) @ A_num[1] @ A_num[2] @ A_num[3]
    qtxt = (f"q = ({q[0] / DEG:.0f}°, {q[1] / DEG:.0f}°, {q[2]:.2f} m, {q[3] / DEG:.0f}°)")
    rows = "".join(
        f"<tr><td>{i}A{i + 1}</td><td>{ctx.matrix(M)}</td></tr>" for i, M in enumerate(A_num)
    )
    parts.append(
        f"<h3>Evaluated at {html.escape(qtxt)}</h3><table>{rows}</table>"
        "<p>0T4 by the compiled kernel (<code>robot.fk(q)</code>):</p>" + ctx.matrix(T_fk)
        + ctx.table([
            ("|fk − 0A1·1A2·2A3·3A4| (corrected eq 17)", float(np.abs(T_fk - T_prod).max())),
            ("|fk − symbolic 0T4 evaluated|", float(np.abs(T_fk - T_sym).max())),
            ("|fk − printed eq 17 (0A2·1A2·2A3·3A4)|", float(np.abs(T_fk - misprint).max())),
            ("max |RᵀR − I| (eq 7)",
             float(np.abs(T_fk[:3, :3].T @ T_fk[:3, :3] - np.eye(3)).max())),
            ("|det R − 1| (eq 7)", float(abs(np.linalg.det(T_fk[:3, :3]) - 1.0))),
        ], ["check", "max abs difference"], fmt="{:.2e}")
        + "<p>The printed eq 17 (with 0A2 in place of 0A1) gives a different pose; the "
        "corrected product agrees with the kernel to rounding.</p>"
    )

    # --- same robot in modified DH --------------------------------------------------------
    puma = models.puma560()
    m_rows, m_base, m_tool = standard_to_modified(puma.dh, puma.base, puma.tool)
    puma_m = Robot.from_dh(m_rows, "modified", base=m_base, tool=m_tool, name="puma560-mdh")
    Q = puma.random_q(1000, seed=7)
    diff = float(np.abs(puma_m.fk(Q) - puma.fk(Q)).max())
    parts.append(
        "<h3>Standard and modified DH</h3><p>The PUMA 560 (standard DH) rewritten in "
        "modified (Craig) DH by <code>serialkin.model.dh.standard_to_modified</code> "
        "(row i takes a<sub>i−1</sub>, α<sub>i−1</sub>; the last row's Tx(a)Rx(α) moves "
        f"into the tool) gives the same tool pose: max difference over 1,000 random "
        f"configurations (seed 7) = {diff:.1e}.</p>"
    )

    # --- figures ------------------------------------------------------------------------------
    parts.append(_figure_scara(ctx, robot, q))
    parts.append(_figure_frames(ctx, robot, q))

    # --- built-in models ------------------------------------------------------------------------
    rows_m = []
    for info in models.catalog():
        r = info.build(6) if info.name == "planar" else info.build()
        p = r.fk(np.zeros(r.n))[:3, 3]
        rows_m.append((info.name, r.n, "".join(r.joint_types), r.convention,
                       f"({p[0]:.4f}, {p[1]:.4f}, {p[2]:.4f})", r.source))
    parts.append("<h3>Built-in models</h3><p><code>serialkin.models</code>; tool position at "
                 "q = 0 (planar shown with 6 unit links).</p>" + ctx.table(
                     rows_m, ["name", "n", "joints", "DH", "p(q=0) [m]", "source"]))

    return Section(title="3. Forward kinematics", equations="eqs 7, 10-18, Table 1",
                   html="".join(parts))
