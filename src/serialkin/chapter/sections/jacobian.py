"""Report section 5, differential kinematics (eqs 28-38, 43), recomputed by serialkin.

Contents: the geometric Jacobian of the two-link arm (Figure 7, eqs 37-38) derived
symbolically and evaluated, compared with the compiled kernel and with central finite
differences of FK; the analytical Jacobian of the three-link arm (Figure 6, eqs 30-32)
derived symbolically and compared numerically with the position rows of the geometric
Jacobian; manipulability (eq 43) and condition number across configurations; figures of
both mechanisms with their velocity (manipulability) ellipses.
"""

from __future__ import annotations

import html

import numpy as np
import sympy as sp

from serialkin import models
from serialkin.chapter.report import ReportContext, Section
from serialkin.kinematics.symbolic import derive
from serialkin.model.robot import Robot

DEG = np.pi / 180.0

TWO_LINK = (1.0, 0.7)
TWO_LINK_Q = np.array([30 * DEG, 60 * DEG])
THREE_LINK = (1.0, 0.8, 0.5)
THREE_LINK_Q = np.array([20 * DEG, 40 * DEG, -30 * DEG])


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


def _figure_mechanisms(ctx: ReportContext, two: Robot, three: Robot) -> str:
    import matplotlib.pyplot as plt

    from serialkin.viz.plot import plot_robot

    fig, axes = plt.subplots(1, 2, figsize=(10, 4.4))
    for ax, robot, q, title in ((axes[0], two, TWO_LINK_Q, "Figure 7: two-link arm"),
                                (axes[1], three, THREE_LINK_Q, "Figure 6: three-link arm")):
        plot_robot(robot, q, ax=ax, frames=True, planar=True)
        p = robot.fk(q)[:2, 3]
        J = robot.jacobian_planar(q)
        _ellipse(ax, p, J, 0.25, color="C3", lw=1.2, label="velocity ellipse J q̇, |q̇| = 1 (×0.25)")
        w = robot.manipulability(q, task="planar")
        ax.set_title(f"{title}, w = {w:.3f} m² (eq 43)", fontsize=9)
        ax.legend(fontsize=7, loc="lower right")
    return ctx.figure(fig, "jacobian_mechanisms", "Figures 6 and 7 regenerated: the 3- and "
                      "2-link arms at the sample configurations with their link frames and "
                      "velocity ellipses (singular values of the planar Jacobian).")


def _figure_manipulability(ctx: ReportContext, two: Robot) -> str:
    import matplotlib.pyplot as plt

    q2 = np.linspace(-np.pi, np.pi, 721)
    Q = np.column_stack([np.full_like(q2, TWO_LINK_Q[0]), q2])
    w = two.manipulability(Q, task="planar")
    c = two.condition_number(Q, task="planar")
    fig, ax = plt.subplots(figsize=(7, 3.6))
    ax.plot(q2 / DEG, w, label="w = sqrt(det J Jᵀ) (eq 43)")
    ax.plot(q2[::24] / DEG, TWO_LINK[0] * TWO_LINK[1] * np.abs(np.sin(q2[::24])), "k.",
            label="L1 L2 |sin q2|")
    ax.set_xlabel("q2 [deg]")
    ax.set_ylabel("w [m²]")
    ax2 = ax.twinx()
    ax2.semilogy(q2 / DEG, np.where(np.isfinite(c), c, np.nan), "C1--", lw=1,
                 label="condition number")
    ax2.set_ylabel("condition number")
    ax.legend(loc="upper left", fontsize=8)
    ax2.legend(loc="upper right", fontsize=8)
    ax.set_title("Two-link arm: manipulability and condition number vs q2")
    return ctx.figure(fig, "jacobian_manipulability", "Manipulability (eq 43) of the two-link "
                      "arm vanishes at the stretched and folded singularities q2 = 0, ±180°.")


def build(ctx: ReportContext) -> Section:
    """Compute section 5's examples and return the report section."""
    parts: list[str] = []

    # --- two-link geometric Jacobian, eqs 37-38 -------------------------------------------
    two = models.two_link(*TWO_LINK)
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
    parts.append(
        "<h3>Geometric Jacobian of the two-link arm (eqs 37-38)</h3>"
        "<p>Column i is [z<sub>i−1</sub> × (p<sub>2</sub> − p<sub>i−1</sub>); "
        "z<sub>i−1</sub>] (eq 35). Derived symbolically by "
        "<code>derive(two_link, params='lengths').geometric_jacobian()</code>:</p>"
        + ctx.code(kin2.pretty(Jg)) + ctx.code(sp.latex(Jg))
        + f"<p>Evaluated with L1 = {L1} m, L2 = {L2} m at q = ({q1 / DEG:.0f}°, "
        f"{q2 / DEG:.0f}°) by <code>robot.jacobian(q)</code> (rows vx, vy, vz, ωx, ωy, ωz):</p>"
        + ctx.matrix(J2)
        + ctx.table([
            ("|J − eq 38|", float(np.abs(J2 - eq38).max())),
            ("|J − symbolic J evaluated|", float(np.abs(J2 - f_sym(TWO_LINK_Q)).max())),
            ("|J[:2] − finite differences of fk|",
             float(np.abs(J2[:2] - _fd_planar(two, TWO_LINK_Q)).max())),
        ], ["check", "max abs difference"], fmt="{:.2e}")
        + "<p>Rank 2: only two of the six velocity components can be assigned; for a "
        "position task only the first two rows are kept "
        "(<code>robot.jacobian_planar(q)</code>).</p>"
    )

    # --- three-link analytical Jacobian, eqs 30-32 ----------------------------------------
    three = models.three_link(*THREE_LINK)
    kin3 = _renamed(three)
    x3 = kin3.task("planar")
    Ja = kin3.jacobian("planar")
    Jpose = kin3.jacobian("planar_pose")
    f_a = kin3.lambdify(Ja)
    Jnum = three.jacobian_planar(THREE_LINK_Q)
    rng = np.random.default_rng(5)
    Q = three.random_q(1000, seed=rng)
    err_many = max(float(np.abs(f_a(q) - three.jacobian_planar(q)).max()) for q in Q[:200])
    parts.append(
        "<h3>Analytical Jacobian of the three-link arm (eqs 30-32)</h3>"
        "<p>Position of E (eqs 30-31), from the symbolic forward kinematics:</p>"
        + ctx.code(kin3.pretty(x3))
        + "<p>J = ∂(x<sub>E</sub>, y<sub>E</sub>)/∂q (eqs 29, 32):</p>"
        + ctx.code(kin3.pretty(Ja)) + ctx.code(sp.latex(Ja))
        + "<p>With the heading φ = q1 + q2 + q3 as a third task coordinate the extra row is "
        f"{html.escape(str(list(Jpose[2, :])))}.</p>"
        + f"<p>Evaluated with L = {THREE_LINK} m at q = "
        f"({', '.join(f'{v / DEG:.0f}°' for v in THREE_LINK_Q)}), the analytical Jacobian "
        "and the position rows of the geometric Jacobian (eqs 33-35) agree:</p>"
        + ctx.matrix(f_a(THREE_LINK_Q))
        + ctx.table([
            ("|J_analytic − J_geometric[vx, vy]| at the sample q",
             float(np.abs(f_a(THREE_LINK_Q) - Jnum).max())),
            ("same, max over 200 random q (seed 5)", err_many),
            ("|J_geometric[vx, vy] − finite differences|",
             float(np.abs(Jnum - _fd_planar(three, THREE_LINK_Q)).max())),
        ], ["check", "max abs difference"], fmt="{:.2e}")
        + "<p>For a planar arm the analytical and geometric Jacobians coincide: the heading "
        "rate is ω<sub>z</sub>. In 3D they differ in the rotational part (section 5.2), "
        "see <code>robot.jacobian_analytic(q, rep)</code>.</p>"
    )

    # --- manipulability, eq 43 --------------------------------------------------------------
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
    parts.append(
        "<h3>Manipulability (eq 43) and condition number</h3><p>w = sqrt(det(J Jᵀ)) of the "
        "task Jacobian and σ<sub>max</sub>/σ<sub>min</sub>; for the two-link arm "
        f"w = L1 L2 |sin q2| = {L1 * L2 * abs(np.sin(q2)):.4g} m² at the sample q.</p>"
        + ctx.table(rows, ["robot, configuration", "task rows", "w", "condition number"])
    )

    parts.append(_figure_mechanisms(ctx, two, three))
    parts.append(_figure_manipulability(ctx, two))
    return Section(title="5. Differential kinematics: Jacobians",
                   equations="eqs 28-38, 43", html="".join(parts))
