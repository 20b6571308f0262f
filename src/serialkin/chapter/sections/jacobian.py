"""Report section 5, differential kinematics (eqs 28-38, 43), recomputed by serialkin.

Contents: the geometric Jacobian of the two-link arm (Figure 7, eqs 37-38) derived
symbolically and evaluated, compared with the compiled kernel and with central finite
differences of FK; the analytical Jacobian of the three-link arm (Figure 6, eqs 30-32)
derived symbolically and compared numerically with the position rows of the geometric
Jacobian; manipulability (eq 43) and condition number across configurations; the
chapter's Figures 6 and 7 regenerated with the velocity (manipulability) ellipses, each in
the part where the chapter first cites it (Figure 6 in 5.1, Figure 7 in 5.2).
"""

from __future__ import annotations

import numpy as np
import sympy as sp

from serialkin import models
from serialkin.chapter._context import ReportContext, Section, format_number
from serialkin.kinematics.symbolic import derive
from serialkin.model.robot import Robot

DEG = np.pi / 180.0

TWO_LINK = (1.0, 0.7)
TWO_LINK_Q = np.array([30 * DEG, 60 * DEG])
THREE_LINK = (1.0, 0.8, 0.5)
THREE_LINK_Q = np.array([20 * DEG, 40 * DEG, -30 * DEG])
PUMA_Q = np.array([0.3, -0.6, 0.9, 0.4, -0.7, 1.1])


def _renamed(robot: Robot, simplify: bool = True):
    """Symbolic kinematics with the lengths named L_1, L_2, ... as in the chapter."""
    kin = derive(robot, params="lengths", simplify=simplify)
    return kin.subs({sp.Symbol(f"a_{i}", real=True): sp.Symbol(f"L_{i}", real=True)
                     for i in range(1, robot.n + 1)})


def _fd_planar(robot: Robot, q: np.ndarray, h: float = 1e-6) -> np.ndarray:
    """Central finite differences of the tool (x, y) position, (2, n)."""
    J = np.empty((2, robot.n))
    for i in range(robot.n):
        e = np.zeros(robot.n)
        e[i] = h
        J[:, i] = (robot.fk(q + e)[:2, 3] - robot.fk(q - e)[:2, 3]) / (2 * h)
    return J


def _ellipse(ax: object, center: np.ndarray, J2: np.ndarray, scale: float, **kw: object) -> None:
    """Draw the velocity ellipse {J q̇ : |q̇| = 1} (semi-axes σ_i along u_i) at ``center``."""
    U, s, _ = np.linalg.svd(J2)
    t = np.linspace(0, 2 * np.pi, 100)
    pts = center[:, None] + scale * (U @ (s[:, None] * np.vstack([np.cos(t), np.sin(t)])))
    ax.plot(pts[0], pts[1], **kw)  # type: ignore[attr-defined]


def _figure_mechanism(ctx: ReportContext, robot: Robot, q: np.ndarray, number: int) -> str:
    """The chapter's Figure ``number`` regenerated: ``robot`` at ``q``, its velocity ellipse."""
    import matplotlib.pyplot as plt

    from serialkin.viz.plot import plot_robot

    fig, ax = plt.subplots(figsize=(5.6, 4.4))
    plot_robot(robot, q, ax=ax, frames=True, planar=True)
    J = robot.jacobian_planar(q)
    _ellipse(ax, robot.fk(q)[:2, 3], J, 0.25, color="C3", lw=1.2,
             label="velocity ellipse J q̇, |q̇| = 1 (×0.25)")
    w = robot.manipulability(q, task="planar")
    ax.set_title(f"Figure {number}: {robot.n}-link arm, w = {w:.3f} m² (eq 43)", fontsize=9)
    ax.legend(fontsize=7, loc="lower right")
    angles = ", ".join(f"{v / DEG:.0f}°" for v in q)
    return ctx.figure(fig, f"jacobian_fig{number}_{robot.n}_link",
                      f"Figure {number} regenerated: the {robot.n}-link arm at q = ({angles}) "
                      "with its link frames and velocity ellipse (singular values of the "
                      "planar Jacobian).")


def _figure_manipulability(ctx: ReportContext, two: Robot) -> str:
    import matplotlib.pyplot as plt

    q2 = np.linspace(-np.pi, np.pi, 721)
    Q = np.column_stack([np.full_like(q2, TWO_LINK_Q[0]), q2])
    w = two.manipulability(Q, task="planar")
    c = two.condition_number(Q, task="planar")
    fig, ax = plt.subplots(figsize=(7, 3.6))
    ax.plot(q2 / DEG, w, label=r"$w = \sqrt{\det(J J^T)}$ (eq 43)")
    ax.plot(q2[::24] / DEG, TWO_LINK[0] * TWO_LINK[1] * np.abs(np.sin(q2[::24])), "k.",
            label=r"$L_1 L_2 |\sin q_2|$")
    ax.set_xlabel("q2 [deg]")
    ax.set_ylabel("w [m²]")
    ax2 = ax.twinx()
    ax2.semilogy(q2 / DEG, np.where(np.isfinite(c), c, np.nan), "C1--", lw=1,
                 label="condition number")
    ax2.set_ylabel("condition number")
    handles = ax.get_legend_handles_labels()[0] + ax2.get_legend_handles_labels()[0]
    ax.legend(handles, [h.get_label() for h in handles], loc="upper center",
              bbox_to_anchor=(0.5, -0.16), ncol=3, fontsize=8, frameon=False)
    ax.set_title("Two-link arm: manipulability and condition number vs q2")
    return ctx.figure(fig, "jacobian_manipulability", "Manipulability (eq 43) of the two-link "
                      "arm vanishes at the stretched and folded singularities q2 = 0, ±180°.")


def _matrix_tokens(M: object) -> list[str]:
    """The entries of a matrix as :meth:`ReportContext.matrix` prints them, row by row."""
    return [format_number(0.0 if abs(v) < 5e-13 else float(v), "{:.4f}")
            for v in np.asarray(M, dtype=float).ravel()]


def _fd_columns(f, q: np.ndarray, h: float = 1e-6) -> np.ndarray:
    """Central finite differences of a vector function f(q), (m, n)."""
    cols = []
    for i in range(len(q)):
        e = np.zeros(len(q))
        e[i] = h
        cols.append((f(q + e) - f(q - e)) / (2 * h))
    return np.column_stack(cols)


def _section_5(ctx: ReportContext) -> Section:
    html_ = (
        "<p>Differential kinematics relates joint velocities to end-effector velocities "
        "through a Jacobian: the analytical Jacobian differentiates the task coordinates "
        "x = f(q) of eq 19 (section 5.1); the geometric Jacobian is built from the joint "
        "axes and gives the linear and angular velocity (section 5.2). Both are computed by "
        "the same compiled kernels that do forward kinematics, and checked here against "
        "sympy's derivatives and against finite differences.</p>"
    )
    return Section(title="5. Differential kinematics", equations="eqs 28-38", html=html_)


def _eq32(ctx: ReportContext, Ja: sp.Matrix) -> str:
    """Eq 32 as the chapter sets it: the matrix of partials, then its entries line by line.

    The entries come from symbolic differentiation (``.jacobian('planar')``); one line
    each, aligned on "=", so that the equation fits the text column.
    """
    names = [rf"\dfrac{{\partial {x}}}{{\partial q_{j}}}" for x in ("x_E", "y_E")
             for j in range(1, Ja.shape[1] + 1)]
    matrix = (r"\mathbf{J}(\mathbf{q}) = \begin{bmatrix}"
              + r"\\ ".join(" & ".join(names[i * Ja.shape[1]:(i + 1) * Ja.shape[1]])
                             for i in range(Ja.shape[0])) + r"\end{bmatrix}")
    lines = r"\\ ".join(f"{name} & = & {sp.latex(entry)}"
                         for name, entry in zip(names, Ja))
    return (ctx.eq(matrix, "32")
            + "<p>whose entries, by symbolic differentiation "
            "(<code>.jacobian('planar')</code>), are the ones the chapter lists under "
            "eq 32:</p>"
            + ctx.eq(r"\begin{array}{rcl}" + lines + r"\end{array}"))


def _section_5_1(ctx: ReportContext, three: Robot) -> Section:
    parts: list[str] = [
        ctx.eq(r"\dot{\mathbf{x}} = \frac{\partial\mathbf{f}(\mathbf{q})}{\partial\mathbf{q}}"
               r"\frac{d\mathbf{q}}{dt} = \mathbf{J}(\mathbf{q})\,\dot{\mathbf{q}}", "28"),
        ctx.eq(r"\mathbf{J}(\mathbf{q}) = \begin{bmatrix}\frac{\partial x_1}{\partial q_1} & "
               r"\cdots & \frac{\partial x_1}{\partial q_n}\\ \vdots & \ddots & \vdots\\ "
               r"\frac{\partial x_m}{\partial q_1} & \cdots & \frac{\partial x_m}"
               r"{\partial q_n}\end{bmatrix}", "29"),
    ]
    kin3 = _renamed(three)
    x3 = kin3.task("planar")
    Ja = kin3.jacobian("planar")
    Jpose = kin3.jacobian("planar_pose")
    f_a = kin3.lambdify(Ja)
    Jnum = three.jacobian_planar(THREE_LINK_Q)
    Q = three.random_q(200, seed=5)
    err_many = max(float(np.abs(f_a(q) - three.jacobian_planar(q)).max()) for q in Q)
    parts.append(
        "<h3>The three-link arm (Figure 6, eqs 30-32)</h3>"
        + _figure_mechanism(ctx, three, THREE_LINK_Q, 6)
        + "<p>Position of E from the symbolic forward kinematics "
        "(<code>derive(three_link, params='lengths').task('planar')</code>):</p>"
        + ctx.eq("x_E = " + sp.latex(x3[0]), "30") + ctx.eq("y_E = " + sp.latex(x3[1]), "31")
        + "<p>and its Jacobian, the matrix of eq 29 for these two coordinates,</p>"
        + _eq32(ctx, Ja)
        + "<p>With the heading φ = q1 + q2 + q3 as a third task coordinate the extra row is "
        + ctx.imath(sp.latex(Jpose[2, :])) + ".</p>"
        + f"<p>Evaluated with L = {THREE_LINK} m at q = "
        f"({', '.join(f'{v / DEG:.0f}°' for v in THREE_LINK_Q)}):</p>"
        + ctx.matrix(f_a(THREE_LINK_Q))
        + ctx.table([
            ("|J_symbolic − J_geometric[vx, vy]| at the sample q",
             float(np.abs(f_a(THREE_LINK_Q) - Jnum).max())),
            ("same, max over 200 random q (seed 5)", err_many),
            ("|J_geometric[vx, vy] − finite differences of fk|",
             float(np.abs(Jnum - _fd_planar(three, THREE_LINK_Q)).max())),
        ], ["check", "max abs difference"], fmt="{:.2e}")
        + "<p>For a planar arm the analytical and geometric Jacobians coincide (the heading "
        "rate is ω<sub>z</sub>); for a spatial arm they differ in the rotational rows "
        "(section 5.2).</p>"
        + ctx.reproduce(
            "import numpy as np, serialkin as sk\n"
            "from serialkin.kinematics.symbolic import derive\n"
            "arm = sk.models.three_link(1.0, 0.8, 0.5)\n"
            "print(derive(arm, params='lengths').jacobian('planar'))      # eq 32\n"
            "print(arm.jacobian_planar(np.radians([20, 40, -30])))",
            expect=_matrix_tokens(f_a(THREE_LINK_Q)))
    )
    return Section(title="5.1 Analytical Jacobian", equations="eqs 28-32, Figure 6",
                   html="".join(parts))


def _prismatic_column(ctx: ReportContext) -> str:
    """Eq 36 on the SCARA: the prismatic joint's column is [z_2; 0]."""
    from serialkin.chapter.sections.forward import SCARA_PARAMS, SCARA_Q

    scara = models.scara(**SCARA_PARAMS)
    J = scara.jacobian(SCARA_Q)
    z2 = scara.fk_all(SCARA_Q)[2, :3, 2]
    col = J[:, 2]
    fd = _fd_columns(lambda q: scara.fk(q)[:3, 3], SCARA_Q)[:, 2]
    return (
        "<h3>Prismatic joint (eq 36) on the SCARA</h3>"
        + ctx.eq(r"\begin{bmatrix}\mathbf{J}_{vi}\\ \mathbf{J}_{\omega i}\end{bmatrix} = "
                 r"\begin{bmatrix}{}^{0}\mathbf{z}_{i-1}\\ \mathbf{0}\end{bmatrix}", "36")
        + "<p>The SCARA of section 3.2.1 at the same q; its third joint (the quill) is "
        "prismatic. Column 3 of <code>robot.jacobian(q)</code> (rows "
        + ctx.imath(r"v_x, v_y, v_z, \omega_x, \omega_y, \omega_z") + ") and the axis "
        + ctx.imath(r"{}^{0}\mathbf{z}_2") + " of DH frame 2 (<code>fk_all(q)[2]</code>):</p>"
        + ctx.table([("J[:, 3]", *col), ("[z2; 0]", *z2, 0.0, 0.0, 0.0),
                     ("finite differences ∂p/∂q3", *fd, "", "", "")],
                    ["", "v_x", "v_y", "v_z", "ω_x", "ω_y", "ω_z"], fmt="{:.6f}")
        + f"<p>|J[:, 3] − [z2; 0]| = {np.abs(col - np.r_[z2, 0, 0, 0]).max():.1e}: sliding "
        "the quill moves the tool along the vertical axis and turns nothing.</p>"
    )


def _analytic_vs_geometric(ctx: ReportContext) -> str:
    """On the PUMA 560: J_A = blockdiag(I, E⁻¹) J, checked by finite differences."""
    from serialkin.kinematics.analytic import rate_matrix, rotation_coordinates

    puma = models.puma560()
    q = PUMA_Q
    J = puma.jacobian(q)
    JA = puma.jacobian_analytic(q, "rpy")
    phi = rotation_coordinates(puma.fk(q)[:3, :3], "rpy")
    E = rate_matrix(phi, "rpy")

    def x_of(qq: np.ndarray) -> np.ndarray:
        T = puma.fk(qq)
        return np.r_[T[:3, 3], rotation_coordinates(T[:3, :3], "rpy")]

    fd = _fd_columns(x_of, q)
    return (
        "<h3>Analytical vs geometric Jacobian on a spatial arm</h3>"
        "<p>Eq 34 notes that the two Jacobians differ in the rotational part. For the "
        "PUMA 560 at q = (" + ", ".join(f"{v:g}" for v in q) + ") rad with roll-pitch-yaw "
        "angles " + ctx.imath(r"\boldsymbol{\phi}") + " as orientation coordinates, "
        + ctx.imath(r"\boldsymbol{\omega} = \mathbf{E}(\boldsymbol{\phi})\,"
                    r"\dot{\boldsymbol{\phi}}") + " and</p>"
        + ctx.eq(r"\mathbf{J}_A(\mathbf{q}) = \begin{bmatrix}\mathbf{I}_3 & \mathbf{0}\\ "
                 r"\mathbf{0} & \mathbf{E}(\boldsymbol{\phi})^{-1}\end{bmatrix}"
                 r"\mathbf{J}(\mathbf{q})")
        + "<p>Geometric Jacobian <code>robot.jacobian(q)</code> (rows v, ω):</p>"
        + ctx.matrix(J)
        + "<p>Analytical Jacobian <code>robot.jacobian_analytic(q, 'rpy')</code> (rows p, "
        "roll, pitch, yaw):</p>" + ctx.matrix(JA)
        + ctx.table([
            ("position rows: |J_A[:3] − J[:3]|", float(np.abs(JA[:3] - J[:3]).max())),
            ("rotation rows: |J_A[3:] − J[3:]| (they differ)",
             float(np.abs(JA[3:] - J[3:]).max())),
            ("|E(φ) J_A[3:] − J[3:]|", float(np.abs(E @ JA[3:] - J[3:]).max())),
            ("|J_A − finite differences of (p, rpy(R))|", float(np.abs(JA - fd).max())),
        ], ["check", "max abs difference"], fmt="{:.2e}")
    )


def _columns_part(ctx: ReportContext) -> str:
    """Eqs 33-35: the Jacobian by columns and the column of a revolute joint."""
    return (
        ctx.eq(r"\mathbf{J} = \begin{bmatrix}\mathbf{J}_v\\ \mathbf{J}_\omega\end{bmatrix} = "
               r"\begin{bmatrix}\mathbf{J}_{v1} & \cdots & \mathbf{J}_{vn}\\ "
               r"\mathbf{J}_{\omega 1} & \cdots & \mathbf{J}_{\omega n}\end{bmatrix}", "33")
        + ctx.eq(r"\mathbf{v} = \mathbf{J}_{v1}\dot{q}_1 + \ldots + \mathbf{J}_{vn}\dot{q}_n,"
                 r"\qquad \boldsymbol{\omega} = \mathbf{J}_{\omega 1}\dot{q}_1 + \ldots + "
                 r"\mathbf{J}_{\omega n}\dot{q}_n", "34")
        + "<p>Column i for a revolute joint:</p>"
        + ctx.eq(r"\begin{bmatrix}\mathbf{J}_{vi}\\ \mathbf{J}_{\omega i}\end{bmatrix} = "
                 r"\begin{bmatrix}{}^{0}\mathbf{z}_{i-1}\times({}^{0}\mathbf{p}_n - "
                 r"{}^{0}\mathbf{p}_{i-1})\\ {}^{0}\mathbf{z}_{i-1}\end{bmatrix}", "35")
    )


def _two_link_part(ctx: ReportContext, two: Robot) -> str:
    """Eqs 37-38: the two-link Jacobian derived by sympy, against the kernel and FK."""
    kin2 = _renamed(two)
    Jg = kin2.geometric_jacobian()
    L1, L2 = TWO_LINK
    q1, q2 = TWO_LINK_Q
    eq38 = np.array([
        [-L1 * np.sin(q1) - L2 * np.sin(q1 + q2), -L2 * np.sin(q1 + q2)],
        [L1 * np.cos(q1) + L2 * np.cos(q1 + q2), L2 * np.cos(q1 + q2)],
        [0, 0], [0, 0], [0, 0], [1, 1],
    ])
    J2 = two.jacobian(TWO_LINK_Q)
    f_sym = kin2.lambdify(Jg)
    return (
        "<h3>The two-link arm (Figure 7, eqs 37-38)</h3>"
        + ctx.eq(r"\mathbf{J}(\mathbf{q}) = \begin{bmatrix}\mathbf{z}_0\times(\mathbf{p}_2 - "
                 r"\mathbf{p}_0) & \mathbf{z}_1\times(\mathbf{p}_2 - \mathbf{p}_1)\\ "
                 r"\mathbf{z}_0 & \mathbf{z}_1\end{bmatrix}", "37")
        + "<p>derived symbolically by "
        "<code>derive(two_link, params='lengths').geometric_jacobian()</code>:</p>"
        + ctx.eq(r"\mathbf{J}(\mathbf{q}) = " + sp.latex(Jg), "38")
        + f"<p>Evaluated with L1 = {L1} m, L2 = {L2} m at q = ({q1 / DEG:.0f}°, "
        f"{q2 / DEG:.0f}°) by <code>robot.jacobian(q)</code> (rows v<sub>x</sub>, "
        "v<sub>y</sub>, v<sub>z</sub>, ω<sub>x</sub>, ω<sub>y</sub>, ω<sub>z</sub>):</p>"
        + ctx.matrix(J2)
        + ctx.table([
            ("|J − eq 38|", float(np.abs(J2 - eq38).max())),
            ("|J − symbolic J evaluated|", float(np.abs(J2 - f_sym(TWO_LINK_Q)).max())),
            ("|J[:2] − finite differences of fk|",
             float(np.abs(J2[:2] - _fd_planar(two, TWO_LINK_Q)).max())),
        ], ["check", "max abs difference"], fmt="{:.2e}")
        + f"<p>Rank {np.linalg.matrix_rank(J2)} (<code>numpy.linalg.matrix_rank</code>): "
        f"only {np.linalg.matrix_rank(J2)} of the {J2.shape[0]} velocity components can be "
        "assigned; for a position task only the first two rows are kept "
        "(<code>robot.jacobian_planar(q)</code>).</p>"
    )


def _manipulability_part(ctx: ReportContext, two: Robot, three: Robot) -> str:
    """Eq 43 and the condition number on the planar arms, the PUMA 560 and the Panda."""
    rows = []
    for name, robot, q, task in (
        ("two-link", two, TWO_LINK_Q, "planar"),
        ("two-link, stretched q2 = 0", two, np.array([TWO_LINK_Q[0], 0.0]), "planar"),
        ("three-link", three, THREE_LINK_Q, "planar"),
        ("three-link, (x, y, φ)", three, THREE_LINK_Q, "planar_pose"),
        ("PUMA 560 at qn = (0, 45°, 180°, 0, 45°, 0)", models.puma560(),
         np.array([0, 45 * DEG, np.pi, 0, 45 * DEG, 0]), "full"),
        ("Panda at (0, −0.3, 0, −2.2, 0, 2.0, π/4)", models.panda(),
         np.array([0, -0.3, 0, -2.2, 0, 2.0, np.pi / 4]), "full"),
    ):
        w = robot.manipulability(q, task=task)
        c = robot.condition_number(q, task=task)
        rows.append((name, task, f"{w:.4g}", "∞" if not np.isfinite(c) else f"{c:.4g}"))
    L1, L2 = TWO_LINK
    q2 = TWO_LINK_Q[1]
    return (
        "<h3>Rank, singularities and manipulability</h3><p>Where J loses rank the arm is "
        "singular. The manipulability of section 5.3,</p>"
        + ctx.eq(r"H(\mathbf{q}) = \sqrt{\det\left(\mathbf{J}(\mathbf{q})\mathbf{J}^T"
                 r"(\mathbf{q})\right)}\qquad\text{(eq 43, numbered in section 5.3)}")
        + "<p>and the condition number σ<sub>max</sub>/σ<sub>min</sub> of the task "
        "Jacobian measure the distance from singularities; for the two-link arm "
        + ctx.imath(r"H = L_1L_2|\sin q_2|")
        + f" = {L1 * L2 * abs(np.sin(q2)):.4g} m² at the sample q.</p>"
        + ctx.table(rows, ["robot, configuration", "task rows", "w", "condition number"])
    )


def _section_5_2(ctx: ReportContext, two: Robot, three: Robot) -> Section:
    """Section 5.2: the geometric Jacobian (eqs 33-38), J_A against J, eq 43, two figures."""
    parts = [
        _columns_part(ctx),
        _prismatic_column(ctx),
        _two_link_part(ctx, two),
        _figure_mechanism(ctx, two, TWO_LINK_Q, 7),
        _analytic_vs_geometric(ctx),
        _manipulability_part(ctx, two, three),
        _figure_manipulability(ctx, two),
        ctx.reproduce(
            'serialkin jacobian two_link --q "30, 60" --degrees --param l1=1.0 --param l2=0.7\n'
            'serialkin jacobian scara --q "30, -45, -0.05, 60" --degrees '
            '--param d1=0.4 --param d2=0.1 --param l1=0.35 --param l2=0.30\n'
            f'serialkin jacobian puma560 --q "{", ".join(f"{v:g}" for v in PUMA_Q)}"',
            shell=True, expect=_matrix_tokens(two.jacobian(TWO_LINK_Q))
            + _matrix_tokens(models.puma560().jacobian(PUMA_Q))),
    ]
    return Section(title="5.2 Geometric Jacobian",
                   equations="eqs 33-38 (36 on the SCARA), J_A vs J on the PUMA 560, eq 43",
                   html="".join(parts))


def build(ctx: ReportContext) -> list[Section]:
    """Compute section 5's examples: sections 5, 5.1 and 5.2."""
    two = models.two_link(*TWO_LINK)
    three = models.three_link(*THREE_LINK)
    return [_section_5(ctx), _section_5_1(ctx, three), _section_5_2(ctx, two, three)]
