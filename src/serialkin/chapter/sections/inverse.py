"""Report section 4, inverse kinematics (eqs 19-27), recomputed by serialkin.

Contents:

* the two-link closed form, eqs 23-27 **as corrected in the ERRATA** (r = sqrt(x² + y²)
  in eq 26, and the sign pairing θ1 = α ∓ β with θ2 = ±arccos(..)), evaluated step by
  step for a worked example, both elbow solutions checked by forward kinematics and
  against :func:`serialkin.ik.analytic.ik_all` (``robot.ik_all``); the misprinted eq 26
  evaluated too, to show why it is wrong;
* Figure 5 regenerated: both elbow configurations reaching the same point, with α and β;
* a round-trip check of the closed form on random configurations.

The numerical families (section 5.3) are in :mod:`serialkin.chapter.sections.numerical`.
"""

from __future__ import annotations

import html
import math
import re

import numpy as np

from serialkin import models
from serialkin.chapter._context import Html, ReportContext, Section, format_number
from serialkin.spatial import wrap_angle

#: A general 6R arm (standard DH: a [m], α [rad], d [m]) and a configuration whose pose
#: has 16 real solutions, the most a 6R arm can have (Raghavan & Roth 1993); found by a
#: random walk, checked against Newton's method from 300 starts (tests).
ARM16 = ([0.9783, 0.2463, 0.5547, 0.0997, 1.2249, 0.3515],
         [-0.8372, 1.3472, -1.7796, 1.2287, -1.5585, 2.7402],
         [-0.0017, 0.2408, 0.7272, -0.169, -0.0999, 0.4972])
Q16 = (-2.3429, 1.801, 3.0488, 0.3575, 1.1886, -0.1766)

#: Worked example of eqs 23-27 (the chapter gives no numbers): link lengths and target.
L1, L2 = 1.0, 0.7
TARGET = (1.2, 0.6)


def two_link_closed_form(x: float, y: float, l1: float, l2: float) -> dict[str, float]:
    """Eqs 23-27 as corrected in the ERRATA, step by step (angles in rad).

    Returns r (eq 23 corrected), α (eq 24), θ2± (eq 25), β (eq 26 corrected),
    θ1 = α − β paired with θ2+, and θ1 = α + β paired with θ2− (eq 27 and its twin).
    NaN where the target is out of reach (|cos| > 1).
    """
    r = math.hypot(x, y)
    alpha = math.atan2(y, x)
    c2 = (x * x + y * y - l1 * l1 - l2 * l2) / (2 * l1 * l2)
    cb = (l1 * l1 - l2 * l2 + r * r) / (2 * l1 * r) if r > 0 else math.nan
    t2 = math.acos(c2) if abs(c2) <= 1 else math.nan
    beta = math.acos(cb) if abs(cb) <= 1 else math.nan
    return {"r": r, "alpha": alpha, "cos_theta2": c2, "theta2_plus": t2, "theta2_minus": -t2,
            "cos_beta": cb, "beta": beta, "theta1_a": alpha - beta, "theta1_b": alpha + beta}


def _misprinted_cos_beta(x: float, y: float, l1: float, l2: float) -> float:
    """The argument of arccos in eq 26 as printed: c = x² + y² and c² in the numerator."""
    c = x * x + y * y
    return (l1 * l1 - l2 * l2 + c * c) / (2 * l1 * c)


def _figure5(ctx: ReportContext, robot, sols: np.ndarray, cf: dict[str, float]) -> str:
    import matplotlib.pyplot as plt
    from matplotlib.patches import Arc

    fig, ax = plt.subplots(figsize=(6.2, 4.8))
    styles = [("C0", "elbow down: θ1 = α − β, θ2 = +arccos(..)"),
              ("C3", "elbow up: θ1 = α + β, θ2 = −arccos(..)")]
    for q, (color, label) in zip(sols, styles):
        pts = robot.fk_all(q)[:, :2, 3]
        ax.plot(pts[:, 0], pts[:, 1], "-o", color=color, lw=3, mfc="white", ms=8,
                label=f"{label}: q = ({q[0]:.3f}, {q[1]:.3f}) rad")
    x, y = TARGET
    ax.plot([0, x], [0, y], "--", color="0.5", lw=1)
    ax.plot([x], [y], "*", color="k", ms=14, label=f"target x_E = ({x}, {y}) m")
    ax.plot([0, 0.6], [0, 0], color="0.6", lw=0.8)
    a, b = math.degrees(cf["alpha"]), math.degrees(cf["beta"])
    ax.add_patch(Arc((0, 0), 0.9, 0.9, theta1=0, theta2=a, color="k", lw=1))
    ax.text(0.47 * math.cos(cf["alpha"] / 2), 0.47 * math.sin(cf["alpha"] / 2), " α",
            fontsize=12, va="center")
    ax.add_patch(Arc((0, 0), 0.6, 0.6, theta1=a, theta2=a + b, color="C3", lw=1.2))
    ax.add_patch(Arc((0, 0), 0.6, 0.6, theta1=a - b, theta2=a, color="C0", lw=1.2))
    for sgn, color in ((1, "C3"), (-1, "C0")):
        ang = cf["alpha"] + sgn * cf["beta"] / 2
        ax.text(0.36 * math.cos(ang), 0.36 * math.sin(ang), "β", color=color, fontsize=12,
                ha="center", va="center")
    ax.plot([0], [0], "ks", ms=9)
    ax.set_aspect("equal", adjustable="datalim")
    ax.set_xlabel("x [m]")
    ax.set_ylabel("y [m]")
    ax.grid(alpha=0.3)
    ax.legend(fontsize=7, loc="upper center", bbox_to_anchor=(0.5, -0.13))
    ax.set_title(f"Two-link arm, L1 = {L1} m, L2 = {L2} m: both solutions of eqs 23-27")
    return ctx.figure(fig, "inverse_two_link", "Figure 5 regenerated: the two inverse "
                      "kinematics solutions of the two-link mechanism, from robot.ik_all "
                      "(corrected eqs 23-27).")


def _round_trip(robot, count: int = 500) -> tuple[float, float]:
    """Round trip of the closed form on random configurations.

    Returns the worst distance of q to the ik_all(FK(q)) solution set (mod 2π) [rad] and
    the worst position error of any returned solution [m].
    """
    Q = robot.random_q(count, seed=7)
    T = robot.fk(Q)
    worst_q = 0.0
    worst_p = 0.0
    for q, Tq in zip(Q, T):
        sols = robot.ik_all(Tq[:2, 3])
        d = np.angle(np.exp(1j * (sols - q)))  # wrap differences to (-π, π]
        worst_q = max(worst_q, float(np.min(np.linalg.norm(d, axis=1))))
        P = robot.fk(sols)[:, :2, 3]
        worst_p = max(worst_p, float(np.max(np.linalg.norm(P - Tq[:2, 3], axis=1))))
    return worst_q, worst_p


def _section_4(ctx: ReportContext) -> Section:
    """Section 4: x = f(q) and q = f⁻¹(x) (eqs 19-20): several, infinitely many or no q."""
    ur5 = models.ur5()
    q_ur = np.array([0.4, -1.1, 1.3, -0.6, 0.9, 0.2])
    T = ur5.fk(q_ur)
    sols = ur5.ik_all(T)
    sols_deg = [[format_number(v, "{:.1f}") for v in np.degrees(wrap_angle(qk))]
                for qk in sols]
    rows_ur = [(k + 1, *sols_deg[k], f"{np.abs(ur5.fk(qk) - T).max():.3g}")
               for k, qk in enumerate(sols)]
    three = models.three_link(1.0, 0.8, 0.5)
    target = three.fk(np.array([0.3, 0.6, -0.4]))[:2, 3]
    rows_3 = []
    found = []
    for seed in range(4):
        res = three.ik(target, seed=seed, q0=three.random_q(seed=seed))
        found.append(np.round(np.degrees(wrap_angle(res.q)), 2))
        rows_3.append((seed, *(format_number(v, "{:.2f}")
                               for v in np.degrees(wrap_angle(res.q))),
                       float(np.linalg.norm(three.fk(res.q)[:2, 3] - target)),
                       "yes" if res.success else "no"))
    from serialkin.model.dh import DHLink
    from serialkin.model.robot import Robot

    arm = Robot.from_dh([DHLink(a=a, alpha=al, d=d) for a, al, d in zip(*ARM16)],
                        name="general 6R")
    T16 = arm.fk(np.array(Q16))
    sols16 = arm.ik_all(T16)
    err16 = float(np.abs(arm.fk(sols16) - T16).max()) if len(sols16) else math.nan
    two = models.two_link(L1, L2)
    far = np.array([2.0, 0.5])
    res_far = two.ik(far, seed=0)
    html_ = (
        "<p>Forward kinematics is a function of the joint variables; inverse kinematics "
        "asks for its inverse:</p>"
        + ctx.eq(r"\mathbf{x} = \mathbf{f}(\mathbf{q})", "19")
        + ctx.eq(r"\mathbf{q} = \mathbf{f}^{-1}(\mathbf{x})", "20")
        + "<p>Unlike f, f⁻¹ is not a function: a target can have several solutions, "
        "infinitely many (a redundant arm) or none (outside the workspace). All three, "
        "computed:</p>"
        f"<p><b>Several.</b> The UR5 at q = ({', '.join(f'{v:g}' for v in q_ur)}) rad; "
        f"its closed-form solver <code>robot.ik_all(T)</code> returns {len(sols)} "
        "configurations with the same tool pose (angles in degrees, in (−180°, 180°]):</p>"
        + ctx.table(rows_ur, ["#", "q1", "q2", "q3", "q4", "q5", "q6", "max |f(q) − T|"],
                    fmt="{:.3g}")
        + "<p>How many can there be? For a 6R arm, eliminating five joint angles leaves "
        "one polynomial of degree 16 (Raghavan &amp; Roth 1993): at most 16 solutions. "
        "The UR5 has at most 8 because its parallel and intersecting axes factor that "
        "polynomial. An arm with no such structure (DH a = "
        f"({', '.join(f'{v:g}' for v in ARM16[0])}) m, α = "
        f"({', '.join(f'{v:g}' for v in ARM16[1])}) rad, d = "
        f"({', '.join(f'{v:g}' for v in ARM16[2])}) m) reaches the pose of q = "
        f"({', '.join(f'{v:g}' for v in Q16)}) rad in <b>{len(sols16)}</b> ways: "
        "<code>ik_all</code> finds them as the real roots of that polynomial "
        f"(worst max |f(q) − T| = {err16:.1e}).</p>"
        + "<p><b>Infinitely many.</b> The planar three-link arm (L = 1.0, 0.8, 0.5 m) and a "
        f"position target ({target[0]:.4f}, {target[1]:.4f}) m: n = 3 joints for m = 2 task "
        "coordinates, so the solutions form a curve; <code>robot.ik</code> started from "
        f"{len(found)} seeded random configurations lands on "
        f"{len({tuple(f) for f in found})} different points of it:</p>"
        + ctx.table(rows_3, ["seed", "q1 [°]", "q2 [°]", "q3 [°]", "|f(q) − x| [m]",
                             "success"], fmt="{:.3g}")
        + f"<p><b>None.</b> The two-link arm (L1 = {L1} m, L2 = {L2} m) cannot reach "
        f"x = ({far[0]}, {far[1]}) m (|x| = {np.linalg.norm(far):.3f} m &gt; L1 + L2): "
        f"<code>ik_all</code> returns {len(two.ik_all(far))} solutions and "
        "<code>robot.ik(x, seed=0)</code> (random restarts drawn from seed 0) reports "
        f"success = {res_far.success}, reason: "
        f"“{html.escape(res_far.reason)}”.</p>"
        + ctx.reproduce(
            "import numpy as np, serialkin as sk\n"
            "ur5 = sk.models.ur5()\n"
            f"T = ur5.fk(np.array([{', '.join(f'{v:g}' for v in q_ur)}]))\n"
            "print(np.round(np.degrees(sk.spatial.wrap_angle(ur5.ik_all(T))), 1))  # eq 20, in °\n"
            f"print(sk.models.two_link({L1}, {L2}).ik([{far[0]}, {far[1]}], seed=0).reason)"
            "  # none",
            expect=[v for row in sols_deg for v in row]
            + re.findall(r"\d+(?:\.\d+)?(?:e-?\d+)?", res_far.reason))
    )
    return Section(title="4. Inverse kinematics", equations="eqs 19-20", html=html_)


def build(ctx: ReportContext) -> list[Section]:
    """Compute section 4's examples: sections 4 (eqs 19-20) and 4.1 (eqs 21-27)."""
    return [_section_4(ctx), _section_4_1(ctx)]


def _section_4_1(ctx: ReportContext) -> Section:
    """Section 4.1: the two-link closed form, eqs 21-27 as corrected in the ERRATA."""
    parts: list[str] = []
    robot = models.two_link(L1, L2)
    x, y = TARGET
    cf = two_link_closed_form(x, y, L1, L2)

    parts.append(
        "<p>The two-link arm of Figure 5 has the forward kinematics</p>"
        + ctx.eq(r"x = L_1\cos\vartheta_1 + L_2\cos(\vartheta_1 + \vartheta_2)", "21")
        + ctx.eq(r"y = L_1\sin\vartheta_1 + L_2\sin(\vartheta_1 + \vartheta_2)", "22")
        + "<p>and the inverse below. The chapter's eqs 23 and 26 carry misprints (ERRATA: "
        "as printed, " + ctx.imath(r"c = x^2 + y^2") + " and "
        + ctx.imath(r"\beta = \arccos\frac{L_1^2 - L_2^2 + c^2}{2L_1c}")
        + "), and eq 27 gives only " + ctx.imath(r"\vartheta_1 = \alpha - \beta")
        + " (the ERRATA pairs it with the + sign of eq 25 and adds "
        + ctx.imath(r"\vartheta_1 = \alpha + \beta") + " for the − sign); the corrected "
        "forms, with the two solutions paired by sign, are</p>"
        + ctx.eq(r"r = \sqrt{x^2 + y^2}", "23, corrected")
        + ctx.eq(r"\alpha = \mathrm{atan2}(y, x)", "24")
        + ctx.eq(r"\vartheta_2 = \pm\arccos\left(\frac{x^2 + y^2 - L_1^2 - L_2^2}"
                 r"{2L_1L_2}\right)", "25")
        + ctx.eq(r"\beta = \arccos\left(\frac{L_1^2 - L_2^2 + r^2}{2L_1r}\right)",
                 "26, corrected")
        + ctx.eq(r"\vartheta_1 = \alpha \mp \beta\quad(\text{upper signs together: }"
                 r"\vartheta_1 = \alpha - \beta \text{ with } \vartheta_2 = +\arccos(\cdot))",
                 "27, corrected")
        + f"<p>Worked example (the chapter gives no numbers): L1 = {L1} m, L2 = {L2} m, "
        f"target x<sub>E</sub> = ({x}, {y}) m, step by step:</p>"
    )
    parts.append(ctx.table(
        [("23 (corrected)", Html(ctx.imath(r"r")), cf["r"]),
         ("24", Html(ctx.imath(r"\alpha")), cf["alpha"]),
         ("25", Html(ctx.imath(r"\cos\vartheta_2")), cf["cos_theta2"]),
         ("25", Html(ctx.imath(r"\vartheta_2 = +\arccos(\cdot)")), cf["theta2_plus"]),
         ("26 (corrected)", Html(ctx.imath(r"\cos\beta")), cf["cos_beta"]),
         ("26 (corrected)", Html(ctx.imath(r"\beta")), cf["beta"]),
         ("27", Html(ctx.imath(r"\vartheta_1 = \alpha - \beta")), cf["theta1_a"]),
         ("27 (corrected), twin", Html(ctx.imath(r"\vartheta_1 = \alpha + \beta")),
          cf["theta1_b"])],
        ["eq", "quantity", "value [m or rad]"]))
    bad = _misprinted_cos_beta(x, y, L1, L2)
    inside = abs(L1 - L2) <= cf["r"] <= L1 + L2
    parts.append(
        f"<p>As printed, eq 26 uses c = x² + y² and c² in the numerator: its arccos argument "
        f"is {bad:.4f}{' &gt; 1, so no real β exists' if abs(bad) > 1 else ''}, although the "
        f"target, at r = {cf['r']:.4f} m, lies {'inside' if inside else 'outside'} the "
        f"workspace |L1 − L2| = {abs(L1 - L2):.4g} m ≤ r ≤ L1 + L2 = {L1 + L2:.4g} m"
        + (" — the corrected form is needed" if inside and abs(bad) > 1 else "") + ".</p>"
    )

    mine = np.array([[cf["theta1_a"], cf["theta2_plus"]], [cf["theta1_b"], cf["theta2_minus"]]])
    lib = robot.ik_all([x, y])
    rows = []
    for label, q in zip(("α − β, +arccos", "α + β, −arccos"), mine):
        p = robot.fk(q)[:2, 3]
        d = np.angle(np.exp(1j * (lib - q)))
        match = float(np.min(np.linalg.norm(d, axis=1))) if len(lib) else math.nan
        rows.append((label, q[0], q[1], p[0], p[1], float(np.hypot(*(p - TARGET))), match))
    parts.append(
        "<p>Both solutions, checked by forward kinematics (eqs 21-22, compiled kernel) and "
        "against <code>robot.ik_all</code> (the library's closed-form solver, which "
        f"returned {len(lib)} solutions):</p>" + ctx.table(
            rows, ["pairing", "θ1 [rad]", "θ2 [rad]", "x [m]", "y [m]",
                   "|x_E − f(q)| [m]", "distance to ik_all [rad]"], fmt="{:.6g}"))
    # draw the library's solutions, ordered like the pairings above
    drawn = np.array([lib[int(np.argmin(np.linalg.norm(np.angle(np.exp(1j * (lib - q))), axis=1)))]
                      for q in mine]) if len(lib) == 2 else mine
    parts.append(_figure5(ctx, robot, drawn, cf))
    worst_q, worst_p = _round_trip(robot)
    parts.append(
        "<p>Round trip on 500 random configurations (seed 7): FK(q) fed to "
        "<code>ik_all</code> returns a set containing q (up to 2π) with worst distance "
        f"{worst_q:.2e} rad, and every returned solution reproduces the target within "
        f"{worst_p:.2e} m.</p>"
    )

    parts.append(ctx.reproduce(
        "import serialkin as sk\n"
        f"print(sk.models.two_link({L1}, {L2}).ik_all([{x}, {y}]))   # both elbows, eqs 23-27",
        expect=[format_number(v) for v in mine.ravel()]))
    return Section(title="4.1 Closed-form solution of inverse kinematics",
                   equations="eqs 21-27 (23, 26, 27 corrected), Figure 5", html="".join(parts))
