"""Section 5.3: the weighted multi-task resolution of eqs 47-50 and Figure 10 (eqs 51-56)."""

from __future__ import annotations

import html
from dataclasses import dataclass
from typing import Any

import numpy as np

from serialkin.chapter._context import Html, ReportContext, Section
from serialkin.chapter.sections.redundancy._common import (
    DEG,
    EQ,
    eq48_by_hand,
)
from serialkin.redundancy import (
    closest_pairs,
    joint_limit_weights,
)
from serialkin.redundancy.obstacles import ClosestPair, robot_segments
from serialkin.tracking.analysis import (
    task_activity,
)
from serialkin.tracking.scenario import Scenario


def _eq47_50_text(ctx: ReportContext, sc: Scenario) -> str:
    """Eqs 47-48 (step 6 corrected) and the designed eqs 49-50, in prose."""
    res = sc.solver
    return (
        "<p>The 20-link algorithm minimises the weighted cost of eq 47 (written here with the "
        "weights that eq 48 carries; " + ctx.imath(r"\mathbf{W}_s")
        + " stands for the chapter's " + ctx.imath(r"\rho^2") + ") in every iteration:</p>"
        + ctx.eq(EQ["47"], "47")
        + "<p>Its minimiser with the chapter's " + ctx.imath(r"\mathbf{x}_c = \mathbf{x}_L"
                                                             r" = \mathbf{0}")
        + " (motion towards an obstacle or a limit is damped, never reversed) is eq 48. "
        "<b>Step 6 of the algorithm is corrected</b> (ERRATA): it prints "
        + ctx.imath(r"\mathbf{J}^{-1}") + " where eq 48 has " + ctx.imath(r"\mathbf{J}^{T}")
        + ".</p>" + ctx.eq(EQ["48"], "48")
        + "<p><b>Eq 49 is missing from the chapter</b>; the text asks for a weight that is 0 "
        "inside the range, grows near a limit and is largest at and beyond it. Our design "
        "(<code>joint_limit_weights</code>): a buffer " + ctx.imath(r"b_i") + " of "
        f"{res.limit_buffer:.0%} of the range next to each limit and the C¹ smoothstep "
        + ctx.imath(r"\sigma(s) = 3s^2 - 2s^3") + " (s clipped to [0, 1]):</p>"
        + ctx.eq(EQ["49"], "49") + ctx.eq(EQ["50"], "50")
    )


def _eq49_figure(ctx: ReportContext, sc: Scenario) -> str:
    """The designed joint-limit weight of eq 49 against the joint angle (limits ±100°)."""
    import matplotlib.pyplot as plt

    res = sc.solver
    lim = np.radians([-100.0, 100.0])
    qs = np.radians(np.linspace(-110.0, 110.0, 881))
    W = joint_limit_weights(qs, np.tile(lim, (qs.size, 1)), buffer=res.limit_buffer,
                            max_weight=res.joint_limit_weight)
    fig, ax = plt.subplots(figsize=(7.0, 3.2))
    ax.plot(np.degrees(qs), W, color="tab:red", lw=2)
    b = res.limit_buffer * 200.0
    for v, ls in ((-100, "-"), (100, "-"), (-100 + b, ":"), (100 - b, ":")):
        ax.axvline(v, color="0.3", ls=ls, lw=1)
    ax.text(-100 + b / 2, res.joint_limit_weight * 0.55, "buffer", ha="center",
            fontsize="small", rotation=90)
    ax.text(100 - b / 2, res.joint_limit_weight * 0.55, "buffer", ha="center",
            fontsize="small", rotation=90)
    ax.set_xlabel("q_i [deg] (limits ±100°)")
    ax.set_ylabel("W_Li")
    ax.set_title(f"Eq 49 (designed): buffer {res.limit_buffer:.0%} of the range, "
                 f"W_L,max = {res.joint_limit_weight:g}")
    ax.grid(True, alpha=0.3)
    return ctx.figure(fig, "eq49_joint_limit_weight",
                      "Eq 49 — the joint-limit weight as a function of the joint "
                      "angle: 0 inside, smoothstep across the buffer, maximal at and "
                      "beyond the limit.")


def _eq48_by_hand_column(sc: Scenario, tc: Any, k: int) -> tuple[str, str, str, str]:
    """Eq 48 by hand against the library at path point ``k``: one column of the table."""
    res = sc.solver
    q = tc.q[k]
    x = sc.robot.fk(q)[:2, 3]
    dx = sc.path.points[min(k + 1, len(sc.path) - 1)] - x
    xdot = dx * min(1.0, res.max_task_step / max(np.linalg.norm(dx), 1e-12))
    hand = eq48_by_hand(sc, q, xdot)
    lib = res.velocity(sc.robot, q, xdot)
    nz = np.flatnonzero(hand["W_L"] > 0)
    return (
        ", ".join(f"W_L{i + 1} = {hand['W_L'][i]:.3g} (q{i + 1} = {q[i] * DEG:.1f}°)"
                  for i in nz) or "all 0",
        f"{hand['J_c'].shape[0]} (weights up to {hand['W_c'].max():.3g})"
        if hand["W_c"].size else "0",
        f"w = {hand['w']:.4g}, λ_s = {hand['lambda_s'] * 1e3:.3g} mm",
        f"{np.linalg.norm(hand['qdot'] - lib) / np.linalg.norm(lib):.1e}")


def _eq48_by_hand_part(ctx: ReportContext, sc: Scenario, tc: Any) -> str:
    """Eqs 48-50 assembled by hand at two path points of (c), against the library."""
    # two path points: limits + singularity (phase 2), limits + obstacles
    act = task_activity(sc, tc)
    picks = []
    for other in ("singularity", "obstacle"):
        both = (act["limit"] > 0) & (act[other] > 0)
        if both.any():
            picks.append(int(np.flatnonzero(both)[np.argmax(act[other][both])]))
    cols = [_eq48_by_hand_column(sc, tc, k) for k in picks]
    labels = ["non-zero W_Li of eq 50 (the others are 0)",
              "obstacle rows J_ci within the distance of influence",
              Html("manipulability w (eq 43), singularity damping " + ctx.imath(r"\lambda_s")),
              "‖q̇ by hand − q̇ library‖ / ‖q̇‖"]
    return (
        "<p>Eqs 48-50 at path points " + " and ".join(str(k) for k in picks)
        + " of the constrained run (Figure 12; the joint-limit task acts at both, with the "
        "singularity task at the first and the obstacle task at the second), with ẋ towards "
        "the next path point. Eq 48 is assembled here by hand: plain numpy on the chapter's "
        "formulas, calling no serialkin kinematics or weight function "
        "(<code>eq48_by_hand</code> in this report's source): the joint positions from the "
        "link lengths, the Jacobian columns of eq 35, the weights of eq 49 (eq 50's "
        "diagonal), eqs 51-56 for every link and obstacle within the distance of influence, "
        "and " + ctx.imath(r"\mathbf{W}_s") + " from the resolver's damping settings; only "
        "the settings and the obstacles' centres and radii are read from the library's "
        "objects. It is compared with the library's compiled "
        "<code>MultiTaskResolver.velocity</code>:</p>"
        + ctx.table([(lab, *[c[i] for c in cols]) for i, lab in enumerate(labels)],
                    ["quantity", *[f"path point {k}" for k in picks]]))


def _weights_part(ctx: ReportContext, sc: Scenario, tc: Any) -> Section:
    """Weighted multi-task resolution: eqs 47-50, the eq 49 figure, eq 48 by hand."""
    res = sc.solver
    q_deg = (0.0, 85.0, 95.0, 101.0)
    W = joint_limit_weights(np.radians(q_deg), np.radians([[-100.0, 100.0]] * len(q_deg)),
                            buffer=res.limit_buffer, max_weight=res.joint_limit_weight)
    w_txt = [f"{v:.4g}" for v in W]
    parts = [
        _eq47_50_text(ctx, sc),
        _eq49_figure(ctx, sc),
        "<p>For example, with limits ±100°: W<sub>L</sub> = "
        + ", ".join(f"{w} at {q:g}°" for w, q in zip(w_txt, q_deg)) + ".</p>",
        _eq48_by_hand_part(ctx, sc, tc),
        ctx.reproduce(
            "import numpy as np\n"
            "from serialkin.redundancy import joint_limit_weights\n"
            f"lim = np.radians([[-100.0, 100.0]] * {len(q_deg)})\n"
            f"W = joint_limit_weights(np.radians({list(q_deg)}), lim, "
            f"buffer={res.limit_buffer:g}, max_weight={res.joint_limit_weight:g})\n"
            "print(', '.join(f'{w:.4g}' for w in W))   # eq 49",
            expect=w_txt),
    ]
    return Section(title="5.3 Kinematically redundant manipulators",
                   part="Weighted multi-task resolution (eqs 47-50)",
                   equations="eqs 47-50 (step 6 corrected to eq 48, 49 designed)",
                   html="".join(parts))


@dataclass(frozen=True)
class _LinkObstacle:
    """The closest link-obstacle pair of a run, with eqs 51-54 evaluated on it in the plane.

    Attributes:
        k: the path point.
        q: the configuration at ``k``, shape (n,) [rad].
        obs: the obstacle.
        pair: the library's closest pair (with the obstacle row of eq 55).
        P0: start point of every link segment, shape (segments, 3) [m].
        P1: end point of every link segment, shape (segments, 3) [m].
        seg: the index of the link's segment.
        link: the link's number.
        s_i: start of the link, shape (2,) [m].
        e_i: unit vector along the link, shape (2,).
        ell: length of the link [m].
        s0: centre of the obstacle, shape (2,) [m].
        p_i: the clamped projection of eq 51 [m].
        s_ci: the closest point of the link, eq 52, shape (2,) [m].
        d_ci: the distance of eq 53 [m].
        u_i: the unit vector of eq 54, shape (2,).
    """

    k: int
    q: np.ndarray
    obs: Any
    pair: ClosestPair
    P0: np.ndarray
    P1: np.ndarray
    seg: int
    link: int
    s_i: np.ndarray
    e_i: np.ndarray
    ell: float
    s0: np.ndarray
    p_i: float
    s_ci: np.ndarray
    d_ci: float
    u_i: np.ndarray


def _closest_link_obstacle(sc: Scenario, tc: Any) -> _LinkObstacle:
    """Eqs 51-54 by hand on the path point and link closest to an obstacle in run ``tc``."""
    robot = sc.robot
    k = int(np.argmin(tc.clearance.min(axis=1)))
    j = int(np.argmin(tc.clearance[k]))
    q = np.ascontiguousarray(tc.q[k])
    obs = sc.obstacles[j]
    pairs = closest_pairs(robot, q, [obs], with_jacobian=True)
    pair = min(pairs, key=lambda p: p.clearance)
    P0, P1, links, frames = robot_segments(robot, q)
    seg = pair.segment
    s_i = P0[seg][:2]
    ell = float(np.linalg.norm(P1[seg] - P0[seg]))
    e_i = (P1[seg][:2] - s_i) / ell
    s0 = np.asarray(obs.center, dtype=float)[:2]
    p_i = float(np.clip(e_i @ (s0 - s_i), 0.0, ell))
    s_ci = s_i + p_i * e_i
    d_ci = float(np.linalg.norm(s_ci - s0))
    return _LinkObstacle(k=k, q=q, obs=obs, pair=pair, P0=P0, P1=P1, seg=seg,
                         link=int(pair.link), s_i=s_i, e_i=e_i, ell=ell, s0=s0, p_i=p_i,
                         s_ci=s_ci, d_ci=d_ci, u_i=(s_ci - s0) / d_ci)


def _clearance_gradient(sc: Scenario, g: _LinkObstacle, h: float) -> np.ndarray:
    """Minus the central finite difference of the link's clearance per joint, shape (n,)."""
    robot = sc.robot
    fd = np.empty(robot.n)
    for a in range(robot.n):
        dq = np.zeros(robot.n)
        dq[a] = h
        cp = closest_pairs(robot, g.q + dq, [g.obs])[g.seg].clearance
        cm = closest_pairs(robot, g.q - dq, [g.obs])[g.seg].clearance
        fd[a] = -(cp - cm) / (2 * h)
    return fd


def _figure10_text(ctx: ReportContext, g: _LinkObstacle) -> list[str]:
    """Eqs 51-56 (51, 52, 54 corrected) and the table of their values on the closest pair."""
    s_i, e_i, s0, s_ci, u_i = g.s_i, g.e_i, g.s0, g.s_ci, g.u_i
    p_i, ell, obs = g.p_i, g.ell, g.obs
    return [
        "<p>The obstacle is a cylinder (a circle in the plane) of centre "
        + ctx.imath(r"\mathbf{s}_0") + " whose distance of influence is drawn dashed; link i "
        "runs from joint position " + ctx.imath(r"\mathbf{s}_i") + " along the unit vector "
        + ctx.imath(r"\mathbf{e}_i") + " over its length " + ctx.imath(r"\ell_i")
        + ". <b>Eqs 51, 52 and 54 are corrected</b> (ERRATA): the projection is clamped to "
        "the link segment (the chapter projects onto the infinite line), so that eq 52's "
        "closest point lies on the link and eq 53's distance is to the segment, and eq 54 "
        "divides "
        + ctx.imath(r"\mathbf{s}_{ci} - \mathbf{s}_0") + " (the chapter prints "
        + ctx.imath(r"\mathbf{s}_{ai}") + ").</p>",
        ctx.eq(EQ["51"], "51, corrected") + ctx.eq(EQ["52"], "52, corrected")
        + ctx.eq(EQ["53"], "53") + ctx.eq(EQ["54"], "54, corrected") + ctx.eq(EQ["55"], "55")
        + ctx.eq(EQ["56"], "56"),
        f"<p>Computed by <code>closest_pairs</code> at path point {g.k} of the constrained run, "
        f"link {g.link} and obstacle {html.escape(obs.name)} (the closest pair of the whole "
        "run):</p>",
        ctx.table([
            (Html(ctx.imath(r"\mathbf{s}_i")), f"({s_i[0]:.4f}, {s_i[1]:.4f}) m"),
            (Html(ctx.imath(r"\mathbf{e}_i")), f"({e_i[0]:.4f}, {e_i[1]:.4f})"),
            (Html(ctx.imath(r"\mathbf{s}_0") + ", radius"),
             f"({s0[0]:.4f}, {s0[1]:.4f}) m, {obs.radius * 1e3:.3g} mm"),
            (Html(ctx.imath(r"p_i") + " (eq 51)"), f"{p_i * 1e3:.3f} mm of {ell * 1e3:.2f} mm"
             + (" (clamped: the closest point is an end of the link)"
                if min(p_i, ell - p_i) < 1e-9 else "")),
            (Html(ctx.imath(r"\mathbf{s}_{ci}") + " (eq 52)"),
             f"({s_ci[0]:.4f}, {s_ci[1]:.4f}) m"),
            (Html(ctx.imath(r"d_{ci}") + " (eq 53)"),
             f"{g.d_ci * 1e3:.3f} mm (clearance {g.pair.clearance * 1e3:.3f} mm, influence "
             f"{obs.influence * 1e3:.3g} mm)"),
            (Html(ctx.imath(r"\mathbf{u}_i") + " (eq 54)"), f"({u_i[0]:.4f}, {u_i[1]:.4f})"),
            ("library vs these formulas: |Δs_ci|, |Δd_ci|",
             f"{np.linalg.norm(g.pair.point[:2] - s_ci):.1e} m, "
             f"{abs(g.pair.distance - g.d_ci):.1e} m"),
        ], ["quantity", "value"]),
    ]


def _eq55_check(ctx: ReportContext, g: _LinkObstacle, fd: np.ndarray, h: float) -> list[str]:
    """The obstacle row of eq 55 against the finite difference of the clearance."""
    row = g.pair.jacobian_row
    return [
        "<p>The row " + ctx.imath(r"\mathbf{J}_{ci}") + " of eq 55 (the approach speed of "
        + ctx.imath(r"\mathbf{s}_{ci}") + " towards the obstacle per unit joint velocity) "
        "against a central finite difference of the clearance, "
        + ctx.imath(r"-\left(c(\mathbf{q} + h\mathbf{e}_k) - c(\mathbf{q} - h\mathbf{e}_k)"
                    r"\right)/2h") + f", h = {h:g} rad; joints after {g.link} do not move the "
        "link and give 0:</p>",
        ctx.table([(f"{a + 1}", f"{row[a]:.6f}", f"{fd[a]:.6f}", f"{abs(row[a] - fd[a]):.1e}")
                   for a in range(g.link)],
                  ["joint", "J_ci (eq 55) [m/rad]", "finite difference [m/rad]", "|difference|"]),
        f"<p>Largest difference over all {fd.size} joints: "
        f"{np.abs(row - fd).max():.1e} m/rad.</p>",
    ]


def _figure10(ctx: ReportContext, g: _LinkObstacle) -> str:
    """Figure 10 drawn from the computed geometry: link, obstacle, s_ci, d_ci, u_i, e_i."""
    import matplotlib.pyplot as plt

    from serialkin.viz import plot_obstacles
    from serialkin.viz.trajectory import outside_legend

    s_i, e_i, s0, s_ci, u_i, obs = g.s_i, g.e_i, g.s0, g.s_ci, g.u_i, g.obs
    fig, ax = plt.subplots(figsize=(6.4, 5.2))
    pts = np.vstack([g.P0[:, :2], g.P1[-1:, :2]])
    ax.plot(pts[:, 0], pts[:, 1], "-o", color="0.6", lw=1.2, ms=2.5, label="arm")
    ax.plot([s_i[0], g.P1[g.seg][0]], [s_i[1], g.P1[g.seg][1]], "-", color="tab:blue", lw=3,
            label=f"link {g.link}")
    plot_obstacles(ax, [obs], influence=True, labels=True)
    ax.plot([s_i[0], s0[0]], [s_i[1], s0[1]], "--", color="0.4", lw=1)
    ax.plot(*s_ci, "o", color="tab:red", ms=6, label="s_ci (eq 52)")
    ax.plot([s0[0], s_ci[0]], [s0[1], s_ci[1]], "-", color="tab:red", lw=1.5,
            label=f"d_ci = {g.d_ci * 1e3:.1f} mm (eq 53)")
    span = 0.6 * (obs.radius + obs.influence)
    ax.annotate("", xy=s_ci + span * u_i, xytext=s_ci,
                arrowprops={"arrowstyle": "->", "color": "tab:green", "lw": 2})
    ax.annotate("", xy=s_i + span * e_i, xytext=s_i,
                arrowprops={"arrowstyle": "->", "color": "tab:blue", "lw": 1.5})
    ax.text(*(s_ci + span * u_i), "  u_i", color="tab:green", va="center")
    ax.text(*(s_i + span * e_i), "  e_i", color="tab:blue", va="center")
    ax.text(*s_i, "s_i  ", ha="right", va="top")
    ax.text(*s0, "\n\ns_0", ha="center", va="top", fontsize="small")
    c = (s_i + s0) / 2
    r = 2.6 * (obs.radius + obs.influence)
    ax.set_xlim(c[0] - r, c[0] + r)
    ax.set_ylim(c[1] - r, c[1] + r)
    ax.set_aspect("equal", adjustable="box")
    ax.set_xlabel("x [m]")
    ax.set_ylabel("y [m]")
    ax.set_title(f"Figure 10: link {g.link} and obstacle {obs.name} (path point {g.k})")
    ax.grid(True, alpha=0.3)
    outside_legend(ax)
    return ctx.figure(fig, "fig10_link_obstacle",
                      "Figure 10 — relation between a link and an obstacle: "
                      "projection, closest point, distance and unit vector, "
                      "computed by serialkin.")


def _figure10_part(ctx: ReportContext, sc: Scenario, tc: Any) -> Section:
    """Figure 10: eqs 51-56 on the closest link-obstacle pair of (c), eq 55 checked."""
    g = _closest_link_obstacle(sc, tc)
    h = 1e-6
    fd = _clearance_gradient(sc, g, h)
    text = _figure10_text(ctx, g)
    parts = [
        *text[:2],
        _figure10(ctx, g),
        *text[2:],
        *_eq55_check(ctx, g, fd, h),
        ctx.reproduce(
            "from serialkin.redundancy import closest_pairs\n"
            "from serialkin.tracking import load_scenario\n"
            "sc = load_scenario('twenty_link_obstacles'); tr = sc.run()\n"
            f"p = min(closest_pairs(sc.robot, tr.q[{g.k}], sc.obstacles, with_jacobian=True),"
            " key=lambda p: p.clearance)\n"
            "print('s_ci', p.point[:2], 'd_ci [mm]', p.distance * 1e3, 'u_i', p.u[:2])\n"
            f"print('J_ci', p.jacobian_row[:{g.link}])",
            expect=[f"{v:.4f}" for v in g.s_ci] + [f"{g.d_ci * 1e3:.3f}"]
            + [f"{v:.4f}" for v in g.u_i]
            + [f"{g.pair.jacobian_row[a]:.6f}" for a in range(g.link)]),
    ]
    return Section(title="5.3 Kinematically redundant manipulators",
                   part="Figure 10: a link and an obstacle (eqs 51-56)",
                   equations="eqs 51-56 (51, 52, 54 corrected)", html="".join(parts))
