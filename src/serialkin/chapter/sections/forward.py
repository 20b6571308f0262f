"""Report section 3, forward kinematics (eqs 10-18), recomputed by serialkin.

Contents: the SCARA of Table 1 (:func:`serialkin.models.scara`), its link matrices
(eqs 13-16) and end-effector transform (eqs 17-18, with the ERRATA's correction of eq 17)
derived symbolically by :mod:`serialkin.kinematics.symbolic` and evaluated numerically at
a sample configuration, checked against the compiled kernels and against the product of
the individual matrices; RᵀR = I and det R = 1 (eq 7) on the result; the same robot
rewritten in modified DH; the chapter's Figure 3 drawn on a PUMA 560 link pair and the
PUMA's DH frames (:mod:`.dh_drawings`); figures of the mechanism in 3D with its DH frames;
and the table of built-in models with their sources.
"""

from __future__ import annotations

import numpy as np
import sympy as sp

from serialkin import models
from serialkin.chapter._context import Html, ReportContext, Section, format_number
from serialkin.chapter.sections.dh_drawings import dh_pair_figure, puma_frames_figure
from serialkin.kinematics.symbolic import SymbolicKinematics, derive
from serialkin.model.dh import link_transform, standard_to_modified
from serialkin.model.robot import Robot

DEG = np.pi / 180.0

#: Parameters and sample configuration of the SCARA example (the chapter gives none).
SCARA_PARAMS = {"d1": 0.4, "d2": 0.1, "l1": 0.35, "l2": 0.30}
SCARA_Q = np.array([30 * DEG, -45 * DEG, -0.05, 60 * DEG])
#: The joint value of the PUMA 560's joint 3 in the drawing of Figure 3 [rad].
DH_PAIR_Q3 = 40 * DEG


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
    """Figure 4: the SCARA drawn as built (column, two horizontal arms, vertical quill)."""
    import matplotlib.pyplot as plt
    from matplotlib.ticker import MaxNLocator

    from serialkin.viz.plot import plot_robot

    fig = plt.figure(figsize=(10, 4.8))
    ax1 = fig.add_subplot(1, 2, 1, projection="3d")
    plot_robot(robot, q, ax=ax1, frames=True, mechanism=True, linewidth=4)
    ax1.set_title("SCARA at the sample q with its DH frames 0-4 and tool\n"
                  "(x red, y green, z blue)", fontsize=9)
    ax2 = fig.add_subplot(1, 2, 2, projection="3d")
    for i, qi in enumerate(robot.random_q(5, seed=3)):
        plot_robot(robot, qi, ax=ax2, color=f"C{i % 10}", alpha=0.85, markersize=3,
                   mechanism=True)
    ax2.set_title("five random configurations inside the joint limits (seed 3)", fontsize=9)
    for ax in (ax1, ax2):
        ax.set_xlim(-0.7, 0.7)
        ax.set_ylim(-0.7, 0.7)
        ax.set_zlim(0.0, 0.6)
        ax.set_box_aspect((1.4, 1.4, 0.75))
        ax.view_init(elev=22, azim=-60)
        for axis in (ax.xaxis, ax.yaxis, ax.zaxis):
            axis.set_major_locator(MaxNLocator(4))
        ax.tick_params(labelsize=7)
    return ctx.figure(fig, "forward_scara", "Figure 4 regenerated: the SCARA (RRPR) of Table 1 "
                      "drawn from its kinematic chain (eq 11): vertical column d1, horizontal "
                      "arms L1 and L2, vertical quill (prismatic q3 and offset d2).")


def _figure_frames(ctx: ReportContext, robot: Robot, q: np.ndarray) -> str:
    """Top view of the SCARA's frame origins and x axes, from the computed matrices."""
    import matplotlib.pyplot as plt

    frames = robot.fk_all(q)
    fig, ax = plt.subplots(figsize=(6, 4.2))
    pts = frames[:, :3, 3]
    ax.plot(pts[:, 0], pts[:, 1], "-o", color="0.4", lw=2, mfc="white")
    L = 0.08
    groups: dict[tuple[float, float], list[int]] = {}
    lines = []
    for i, T in enumerate(frames):
        o = T[:3, 3]
        for k, c in ((0, "r"), (1, "g")):
            d = T[:3, k] * L
            ax.annotate("", xy=(o[0] + d[0], o[1] + d[1]), xytext=(o[0], o[1]),
                        arrowprops={"arrowstyle": "->", "color": c, "lw": 1.4})
        groups.setdefault((round(float(o[0]), 6), round(float(o[1]), 6)), []).append(i)
        lines.append(f"frame {i}: z {'up' if T[2, 2] > 0 else 'down'}, height {o[2]:.2f} m")
    for (x, y), idx in groups.items():
        ax.annotate(", ".join(map(str, idx)), (x, y), xytext=(-6, -14),
                    textcoords="offset points", fontsize=9, ha="right", color="0.2")
    ax.text(0.02, 0.98, "\n".join(lines), transform=ax.transAxes, fontsize=8, va="top",
            bbox={"boxstyle": "round", "fc": "white", "ec": "0.7"})
    ax.set_xlim(-0.08, 0.72)
    ax.set_ylim(-0.12, 0.42)
    ax.set_aspect("equal", adjustable="box")
    ax.set_xlabel("x [m]")
    ax.set_ylabel("y [m]")
    ax.set_title("Top view: frame origins, x (red) and y (green) axes")
    flips = [i + 1 for i, row in enumerate(robot.dh) if np.isclose(abs(row.alpha), np.pi)]
    flip = "".join(f"; frame {i} flips z downwards (α{i} = π)" for i in flips)
    return ctx.figure(fig, "forward_scara_frames", f"SCARA DH frames 0-{robot.n} seen from "
                      f"above{flip}.")


def _section_3_1(ctx: ReportContext) -> Section:
    """Section 3.1: eqs 10-12 on the PUMA 560."""
    puma = models.puma560()
    q = np.array([0.3, -0.6, 0.9, 0.4, -0.7, 1.1])
    A = [link_transform(r, qi, "standard") for r, qi in zip(puma.dh, q, strict=True)]
    H = puma.base.copy()
    for Ai in A:
        H = H @ Ai
    H = H @ puma.tool
    T_fk = puma.fk(q)
    frames = puma.fk_all(q)
    rows = []
    for i, Ai in enumerate(A):
        R = Ai[:3, :3]
        rows.append((f"A{i + 1}", float(np.abs(R.T @ R - np.eye(3)).max()),
                     float(np.abs(Ai[3] - [0, 0, 0, 1]).max()),
                     float(np.abs(frames[i] @ Ai - frames[i + 1]).max())))
    qtxt = ", ".join(f"{v:g}" for v in q)
    html_ = (
        "<p>The links are connected by revolute or prismatic joints, each with one joint "
        "variable q<sub>i</sub>; a frame is attached to every link. The pose of the end "
        "effector in the base frame is a homogeneous matrix "
        "(eq 10), the product of the link matrices along the open chain (eq 11), each of "
        "which holds the pose of link frame i in frame i−1 (eq 12):</p>"
        + ctx.eq(r"\mathbf{H} = \begin{bmatrix}{}^{0}\mathbf{R}_{n} & {}^{0}\mathbf{o}_{n}"
                 r"\\ \mathbf{0}^T & 1\end{bmatrix}", "10")
        + ctx.eq(r"\mathbf{H} = {}^{0}\mathbf{T}_{n} = \prod_{i=1}^{N}\mathbf{A}_{i}", "11")
        + ctx.eq(r"\mathbf{A}_{i} = \begin{bmatrix}{}^{i-1}\mathbf{R}_{i} & "
                 r"{}^{i-1}\mathbf{o}_{i}\\ \mathbf{0}^T & 1\end{bmatrix}", "12")
        + "<h3>Eqs 10-12 on the PUMA 560</h3>"
        f"<p>At q = ({qtxt}) rad, the six link matrices "
        "<code>link_transform(row, q_i)</code> multiplied in order (eq 11) give</p>"
        + ctx.matrix(H)
        + "<p>and the compiled kernel <code>robot.fk(q)</code> agrees to "
        f"{np.abs(H - T_fk).max():.1e}. Its blocks are the rotation "
        + ctx.imath(r"{}^{0}\mathbf{R}_{6}")
        + f" (max |RᵀR − I| = {np.abs(H[:3, :3].T @ H[:3, :3] - np.eye(3)).max():.1e}) and "
        "the tool position " + ctx.imath(r"{}^{0}\mathbf{o}_{6}")
        + f" = ({H[0, 3]:.4f}, {H[1, 3]:.4f}, {H[2, 3]:.4f}) m (eq 10). Each "
        + ctx.imath(r"\mathbf{A}_i") + " has the form of eq 12 and maps frame i−1 onto "
        "frame i (the partial products are <code>robot.fk_all(q)</code>):</p>"
        + ctx.table(rows, ["link", "max |RᵀR − I| of its rotation block",
                           "max |last row − [0 0 0 1]|",
                           "max |0T(i−1) · A_i − 0T_i|"], fmt="{:.1e}")
        + ctx.reproduce(
            "import numpy as np, serialkin as sk\n"
            "robot = sk.models.puma560()\n"
            f"print(np.round(robot.fk(np.array([{qtxt}])), 4))   # eq 11",
            expect=[format_number(v, "{:.4f}") for v in H[:3].ravel()])
    )
    return Section(title="3.1 Open kinematic chain", equations="eqs 10-12", html=html_)


def _section_3_2(ctx: ReportContext) -> Section:
    """Section 3.2: the DH link matrix, standard vs modified, and the built-in models."""
    puma = models.puma560()
    m_rows, m_base, m_tool = standard_to_modified(puma.dh, puma.base, puma.tool)
    puma_m = Robot.from_dh(m_rows, "modified", base=m_base, tool=m_tool, name="puma560-mdh")
    Q = puma.random_q(1000, seed=7)
    diff = float(np.abs(puma_m.fk(Q) - puma.fk(Q)).max())
    parts = [
        "<p>The frame of link i is placed by the chapter's rules (Figure 3): z<sub>i−1</sub>"
        " on the axis of joint i, O<sub>i</sub> where the common normal of z<sub>i−1</sub> "
        "and z<sub>i</sub> meets z<sub>i</sub> (it meets z<sub>i−1</sub> at O<sub>i</sub>′),"
        " x<sub>i</sub> along that normal. Then a<sub>i</sub> = |O<sub>i</sub>′O<sub>i</sub>|"
        ", d<sub>i</sub> is the distance from O<sub>i−1</sub> to O<sub>i</sub>′ along "
        "z<sub>i−1</sub>, ϑ<sub>i</sub> the angle from x<sub>i−1</sub> to x<sub>i</sub> "
        "about z<sub>i−1</sub> and α<sub>i</sub> the angle from z<sub>i−1</sub> to "
        "z<sub>i</sub> about x<sub>i</sub>. Drawn from link 3 of the PUMA 560 (the link "
        "whose a and d are both nonzero) and measured back from the drawn frames:</p>",
        dh_pair_figure(ctx, puma, 3, DH_PAIR_Q3),
        "<p>With the four DH parameters (a<sub>i</sub>, α<sub>i</sub>, d<sub>i</sub>, "
        "ϑ<sub>i</sub>) the link matrix of eq 12 is a product of elementary motions "
        "(eqs 4, 6 and translations):</p>",
        ctx.eq(r"\mathbf{A}_i = \mathbf{R}_z(\vartheta_i)\,\mathbf{T}_z(d_i)\,"
               r"\mathbf{T}_x(a_i)\,\mathbf{R}_x(\alpha_i) = \begin{bmatrix}"
               r"\cos\vartheta_i & -\sin\vartheta_i\cos\alpha_i & \sin\vartheta_i\sin\alpha_i"
               r" & a_i\cos\vartheta_i\\ \sin\vartheta_i & \cos\vartheta_i\cos\alpha_i & "
               r"-\cos\vartheta_i\sin\alpha_i & a_i\sin\vartheta_i\\ 0 & \sin\alpha_i & "
               r"\cos\alpha_i & d_i\\ 0 & 0 & 0 & 1\end{bmatrix}"),
        "<p>ϑ<sub>i</sub> is the joint variable of a revolute joint, d<sub>i</sub> that of a "
        "prismatic one. <b>Standard and modified DH.</b> The PUMA 560 (standard DH) "
        "rewritten in modified (Craig) DH by <code>serialkin.model.dh.standard_to_modified"
        "</code> (row i takes a<sub>i−1</sub>, α<sub>i−1</sub>; the last row's "
        "Tx(a)Rx(α) moves into the tool) gives the same tool pose: max difference over "
        f"1,000 random configurations (seed 7) = {diff:.1e}.</p>",
    ]
    rows_m = []
    p_zero: dict[str, list[str]] = {}
    for info in models.catalog():
        r = info.build(6) if info.name == "planar" else info.build()
        pz = r.fk(np.zeros(r.n))[:3, 3]
        p_zero[info.name] = [format_number(v, "{:.4f}") for v in pz]
        rows_m.append((info.name, r.n, "".join(r.joint_types), r.convention or "joints",
                       f"({format_number(pz[0], '{:.4f}')}, {format_number(pz[1], '{:.4f}')},"
                       f" {format_number(pz[2], '{:.4f}')})", r.source))
    parts.append(puma_frames_figure(ctx, puma, np.zeros(puma.n)))
    parts.append(ctx.table([(i + 1, r.a, r.alpha, r.d, r.theta, r.type)
                            for i, r in enumerate(puma.dh)],
                           ["link", "a [m]", "α [rad]", "d [m]", "θ offset [rad]", "type"]))
    parts.append("<h3>Built-in models</h3><p><code>serialkin.models</code>; tool position at "
                 "q = 0 (planar shown with 6 unit links).</p>" + ctx.table(
                     rows_m, ["name", "n", "joints", "DH", "p(q = 0) [m]", "source"]))
    parts.append(ctx.reproduce(
        'serialkin fk puma560 --q "0, 0, 0, 0, 0, 0"     # p(q = 0) of the table\n'
        "serialkin models                               # the list of built-in models",
        shell=True, expect=p_zero["puma560"]))
    return Section(title="3.2 Denavit-Hartenberg convention",
                   equations="eq 12 in DH form, eqs 4 and 6", html="".join(parts))


def _latex_q(q: np.ndarray) -> str:
    """The SCARA configuration as LaTeX; each value braced so a minus sign is unary."""
    return (rf"\mathbf{{q}} = ({{{q[0] / DEG:.0f}}}^\circ,\ {{{q[1] / DEG:.0f}}}^\circ,\ "
            rf"{{{q[2]:.2f}}}\,\text{{m}},\ {{{q[3] / DEG:.0f}}}^\circ)")


def _table1_part(ctx: ReportContext, robot: Robot) -> str:
    """Table 1 as printed (symbols) and as built (numbers, joint types, limits)."""
    table1 = [("L_1", "0", "d_1", "q_1"), ("L_2", "0", "0", "q_2"),
              ("0", r"\pi", "d_2 + q_3", "0"), ("0", "0", "0", "q_4")]
    return (
        "<h3>Table 1</h3><p>The chapter's SCARA (RRPR) in standard DH, built by "
        "<code>serialkin.models.scara()</code>. The chapter gives no numbers; this report "
        "uses d1 = {d1} m, d2 = {d2} m, L1 = {l1} m, L2 = {l2} m.</p>".format(**SCARA_PARAMS)
        + ctx.table(
            [(str(i + 1), *(Html(ctx.imath(c)) for c in row)) for i, row in enumerate(table1)],
            ["link", *(Html(ctx.imath(h)) for h in ("a_i", r"\alpha_i", "d_i", r"\vartheta_i"))])
        + "<p>As built (numbers, joint type and limits):</p>" + ctx.table(
            [(i + 1, r.a, r.alpha, r.d, r.theta, r.type, f"[{r.qlim[0]:.4g}, {r.qlim[1]:.4g}]")
             for i, r in enumerate(robot.dh)],
            ["link", "a [m]", "α [rad]", "d [m]", "θ [rad]", "type", "limits"])
    )


def _symbolic_part(ctx: ReportContext, kin: SymbolicKinematics) -> str:
    """Eqs 13-16 (the link matrices) and eqs 17-18 (their product), derived by sympy."""
    # the chapter's numbers: 13 is 0A1, 14 the factors of 1A2 (garbled in print), 15 is
    # 1A2, 16 is 2A3; 3A4 is printed with 16 but carries no number of its own
    labels = ("13", "15", "16", None)
    return (
        "<h3>Link matrices, symbolic (eqs 13-16)</h3><p>Derived by "
        "<code>serialkin.kinematics.symbolic.derive(scara, params='lengths')</code> from the "
        "DH matrix of section 3.2 and simplified (the chapter's eq 14, the factors of "
        "1A2, is garbled in print and not repeated; 3A4 has no number there):</p>"
        + "".join(ctx.eq(rf"{{}}^{{{i}}}\mathbf{{A}}_{{{i + 1}}} = {sp.latex(M)}", labels[i])
                  for i, M in enumerate(kin.A))
        + "<h3>End-effector transform (eqs 17-18)</h3><p>Eq 17 is printed as "
        + ctx.imath(r"{}^{0}\mathbf{T}_4 = {}^{0}\mathbf{A}_2\,{}^{1}\mathbf{A}_2\,"
                    r"{}^{2}\mathbf{A}_3\,{}^{3}\mathbf{A}_4")
        + "; the ERRATA corrects the first factor:</p>"
        + ctx.eq(r"{}^{0}\mathbf{T}_4 = {}^{0}\mathbf{A}_1\,{}^{1}\mathbf{A}_2\,"
                 r"{}^{2}\mathbf{A}_3\,{}^{3}\mathbf{A}_4", "17, corrected")
        + "<p>which gives (simplified)</p>"
        + ctx.eq(rf"{{}}^{{0}}\mathbf{{T}}_4 = {sp.latex(kin.T)}", "18")
        + "<p>so the end-effector position is "
        + ctx.imath(r"{}^{0}\mathbf{o}_4 = \left("
                    + r",\ ".join(sp.latex(v) for v in kin.T[:3, 3]) + r"\right)")
        + " and the tool z axis (column 3 of the rotation) is "
        + ctx.imath(r"\left(" + r",\ ".join(sp.latex(v) for v in kin.T[:3, 2]) + r"\right)")
        + (": it points down whatever q" if list(kin.T[:3, 2]) == [0, 0, -1] else "")
        + ".</p>"
    )


def _evaluated_part(ctx: ReportContext, robot: Robot, q: np.ndarray,
                    kin: SymbolicKinematics) -> str:
    """The link matrices at ``q``, and the kernel's pose against the products and sympy."""
    s = _symbols()
    A_num = [link_transform(r, qi, "standard") for r, qi in zip(robot.dh, q, strict=True)]
    T_prod = A_num[0] @ A_num[1] @ A_num[2] @ A_num[3]
    T_fk = robot.fk(q)
    subs = {s["L_1"]: SCARA_PARAMS["l1"], s["L_2"]: SCARA_PARAMS["l2"],
            s["d_1"]: SCARA_PARAMS["d1"], s["d_2"]: SCARA_PARAMS["d2"]}
    T_sym = np.array(kin.T.subs(subs).subs(dict(zip(kin.q, q, strict=True))).evalf(),
                     dtype=float)
    misprint = (A_num[0] @ A_num[1]) @ A_num[1] @ A_num[2] @ A_num[3]
    rows = [(Html(ctx.imath(rf"{{}}^{{{i}}}\mathbf{{A}}_{{{i + 1}}}")), ctx.matrix(M))
            for i, M in enumerate(A_num)]
    return (
        "<h3>Evaluated at " + ctx.imath(_latex_q(q)) + "</h3>"
        + ctx.table(rows, ["matrix", "value"])
        + "<p>" + ctx.imath(r"{}^{0}\mathbf{T}_4")
        + " by the compiled kernel (<code>robot.fk(q)</code>):</p>" + ctx.matrix(T_fk)
        + ctx.table([
            ("|fk − 0A1·1A2·2A3·3A4| (corrected eq 17)", float(np.abs(T_fk - T_prod).max())),
            ("|fk − symbolic 0T4 evaluated|", float(np.abs(T_fk - T_sym).max())),
            ("|fk − printed eq 17 (0A2·1A2·2A3·3A4)|", float(np.abs(T_fk - misprint).max())),
            ("max |RᵀR − I| (eq 7)",
             float(np.abs(T_fk[:3, :3].T @ T_fk[:3, :3] - np.eye(3)).max())),
            ("|det R − 1| (eq 7)", float(abs(np.linalg.det(T_fk[:3, :3]) - 1.0))),
        ], ["check", "max abs difference"], fmt="{:.2e}")
        + "<p>The printed eq 17 (with 0A2 in place of 0A1) gives a pose whose entries differ "
        f"from the kernel's by up to {np.abs(T_fk - misprint).max():.2g}; the corrected "
        f"product agrees with it to {np.abs(T_fk - T_prod).max():.1e}, rounding.</p>"
    )


def _section_3_2_1(ctx: ReportContext) -> Section:
    """Section 3.2.1: the SCARA example (Table 1, eqs 13-18)."""
    robot = models.scara(**SCARA_PARAMS)
    q = SCARA_Q
    parts = [_table1_part(ctx, robot)]
    kin = scara_symbolic(robot)
    parts.append(_symbolic_part(ctx, kin))
    parts.append(_evaluated_part(ctx, robot, q, kin))
    parts.append(_figure_scara(ctx, robot, q))
    parts.append(_figure_frames(ctx, robot, q))
    parts.append(ctx.reproduce(
        "import numpy as np, serialkin as sk\n"
        "from serialkin.kinematics.symbolic import derive\n"
        "robot = sk.models.scara(d1=0.4, d2=0.1, l1=0.35, l2=0.30)\n"
        "print(derive(robot, params='lengths').T)                        # eq 18\n"
        "print(np.round(robot.fk(np.array([np.radians(30), np.radians(-45), -0.05, "
        "np.radians(60)])), 4))",
        expect=[format_number(0.0 if abs(v) < 5e-13 else v, "{:.4f}")
                for v in robot.fk(q)[:3].ravel()]))
    return Section(title="3.2.1 Example: the SCARA", equations="Table 1, eqs 13-18 (17 "
                   "corrected), eq 7", html="".join(parts))


def build(ctx: ReportContext) -> list[Section]:
    """Compute section 3's examples: sections 3, 3.1, 3.2 and 3.2.1."""
    intro = Section(
        title="3. Forward kinematics", equations="eqs 10-18, Table 1",
        html="<p>The forward kinematic model gives the position and orientation of the end "
             "effector in the base frame from the joint variables: for an open chain, a "
             "product of one homogeneous matrix per link (3.1), each written with the four "
             "Denavit-Hartenberg parameters (3.2), worked out for the chapter's SCARA "
             "(3.2.1). Every matrix below is computed by serialkin's kernels and checked "
             "against the product of the individual matrices and against sympy.</p>")
    return [intro, _section_3_1(ctx), _section_3_2(ctx), _section_3_2_1(ctx)]
