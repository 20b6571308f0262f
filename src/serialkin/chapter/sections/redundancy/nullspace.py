"""Section 5.3: the null-space methods of eqs 42-45 and the 6-link example (Figures 8-9)."""

from __future__ import annotations

from typing import Any

import numpy as np

from serialkin.chapter._context import Html, ReportContext, Section, format_vector
from serialkin.chapter.sections.redundancy._common import (
    DEG,
    EQ,
    _gif,
)
from serialkin.redundancy import (
    joint_limit_distance,
    manipulability,
    nullspace_projector,
    self_motion,
)
from serialkin.tracking.scenario import planar_arm


def _obstacle_objective(ctx: ReportContext) -> str:
    """Eq 45 on a planar 3-link arm and a circular obstacle, checked by brute force."""
    from serialkin import models
    from serialkin.model.geometry import Cylinder
    from serialkin.redundancy import obstacle_distance
    from serialkin.redundancy.objectives import finite_difference_gradient

    arm = models.three_link(1.0, 0.8, 0.5)
    obstacle = Cylinder(0.25, np.inf, center=[1.2, 1.3, 0.0])  # the circle, extruded along z
    H = obstacle_distance(arm, [obstacle])
    rows = []
    for q in (np.array([0.3, 0.6, -0.4]), np.array([0.0, 0.3, 0.9]),
              np.array([-0.2, 1.0, 1.0])):
        pts = arm.fk_all(q)[:, :2, 3]
        t = np.linspace(0.0, 1.0, 1001)[:, None]
        a = np.vstack([p0 + t * (p1 - p0) for p0, p1 in zip(pts[:-1], pts[1:])])
        ang = np.linspace(0.0, 2 * np.pi, 721)
        b = obstacle.center[:2] + obstacle.radius * np.c_[np.cos(ang), np.sin(ang)]
        d2 = min(float(np.min(np.sum((a[:, None, :] - bj) ** 2, axis=-1))) for bj in b)
        d_exact = np.min(np.linalg.norm(a - obstacle.center[:2], axis=1)) - obstacle.radius
        g = H.gradient(q)
        g_fd = finite_difference_gradient(H.value, q)
        rows.append((", ".join(f"{v:g}" for v in q), H.value(q), d_exact * abs(d_exact),
                     d2, float(np.abs(g - g_fd).max())))
    return (
        "<h3>Obstacle-avoidance objective (eq 45)</h3>"
        + ctx.eq(r"H(\mathbf{q}) = \min_{\mathbf{a}\in\text{robot},\ \mathbf{b}\in"
                 r"\text{obstacle}}\left\|\mathbf{a}(\mathbf{q}) - \mathbf{b}\right\|^2", "45")
        + "<p>On the planar three-link arm (L = 1.0, 0.8, 0.5 m) and a circle of radius "
        "0.25 m at (1.2, 1.3) m: <code>redundancy.obstacle_distance(arm, [circle])</code> "
        "computes H from the closest points of the link segments (eqs 51-56, corrected); "
        "it is compared with a brute-force minimum over 3,000 points on the links and 720 "
        "on the circle, and with the point-to-centre distance minus the radius. Its "
        "gradient (used as " + ctx.imath(r"\dot{\mathbf{q}}_0") + " in eq 42) is checked "
        "against central finite differences.</p>"
        + "<p>(serialkin keeps the sign of the clearance, H = c·|c|, so that H still grows "
        "when a link has entered the obstacle.)</p>"
        + ctx.table(rows, ["q [rad]", "H(q) [m²]", "(min |a − centre| − r)² [m²]",
                           "brute force [m²]", "|∇H − finite differences|"], fmt="{:.6g}")
    )




def _nullspace_part(ctx: ReportContext) -> Section:
    rng = np.random.default_rng(42)
    robot = planar_arm(6, 0.1)
    worst = 0.0
    for _ in range(200):
        q = robot.random_q(seed=rng)
        J = robot.jacobian(q)[:2]
        v = rng.normal(size=6)
        worst = max(worst, float(np.linalg.norm(J @ nullspace_projector(J) @ v)))
    q0 = np.array([0.3, 0.2, 0.1, 0.1, 0.05, 0.02])
    obj = manipulability(robot, "planar")
    traj = self_motion(robot, q0, obj, steps=60, gain=20.0, max_step=0.02)
    drift = np.linalg.norm(robot.fk(traj[-1])[:2, 3] - robot.fk(q0)[:2, 3])
    # the same self-motion in half-size steps (twice as many): the drift of finer steps
    fine = self_motion(robot, q0, obj, steps=120, gain=20.0, max_step=0.01)
    drift_fine = np.linalg.norm(robot.fk(fine[-1])[:2, 3] - robot.fk(q0)[:2, 3])
    lim_robot = robot.with_limits(np.tile(np.radians([-100.0, 100.0]), (6, 1)))
    q1 = np.radians([80.0, -70.0, 60.0, 20.0, -85.0, 40.0])
    jl = joint_limit_distance(lim_robot)
    traj2 = self_motion(lim_robot, q1, jl, steps=80, gain=2.0, max_step=0.02)
    drift2 = np.linalg.norm(robot.fk(traj2[-1])[:2, 3] - robot.fk(q1)[:2, 3])
    rows = [
        (Html("max " + ctx.imath(r"\|\mathbf{J}(\mathbf{I} - \mathbf{J}^{\dagger}\mathbf{J})"
                                 r"\mathbf{v}\|") + " over 200 random (q, v)"),
         f"{worst:.2e}", "m/s per unit v"),
        (Html("self-motion along " + ctx.imath(r"+\nabla H") + " (eq 43): H before → after"),
         f"{obj.value(q0):.4f} → {obj.value(traj[-1]):.4f}", f"EE drift {drift * 1e3:.3f} mm"),
        (Html("self-motion along " + ctx.imath(r"-\nabla H") + " (eq 44): H before → after"),
         f"{jl.value(q1):.4f} → {jl.value(traj2[-1]):.4f}",
         f"max |q| {np.abs(q1).max() * DEG:.1f}° → {np.abs(traj2[-1]).max() * DEG:.1f}°, "
         f"EE drift {drift2 * 1e3:.3f} mm"),
    ]
    body = (
        "<p>The null-space methods add to the minimum-norm solution of eq 40 a joint velocity "
        "projected onto the null space of J, which moves the joints without moving the end "
        "effector (self-motion):</p>" + ctx.eq(EQ["42"], "42")
        + "<p>With the projected gradient " + ctx.imath(r"\dot{\mathbf{q}}_0 = \pm k\nabla H")
        + " the self-motion climbs the manipulability of eq 43 or descends the distance from "
        "mid-range of eq 44. <b>Eq 44 is corrected</b> (ERRATA): the chapter prints the "
        "mid-range as the half-range " + ctx.imath(r"(q_{M,i} - q_{m,i})/2") + ".</p>"
        + ctx.eq(EQ["43"], "43") + ctx.eq(EQ["44"], "44, corrected")
        + "<p>Checks on a 6-link planar arm, L = 0.1 m, task (x, y). The self-motion "
        "integrates " + ctx.imath(r"\Delta\mathbf{q} = (\mathbf{I} - \mathbf{J}^{\dagger}"
                                  r"\mathbf{J})\,k\,(\pm\nabla H)")
        + " in steps of at most 0.02 rad; the end-effector drift comes from the finite "
        "steps: the climb of H in 120 steps of at most 0.01 rad drifts "
        f"{drift_fine * 1e3:.3f} mm (H → {obj.value(fine[-1]):.4f}) against "
        f"{drift * 1e3:.3f} mm in 60 steps of 0.02 rad.</p>"
        + ctx.table(rows, ["check", "value", "note"])
        + _obstacle_objective(ctx)
        + ctx.reproduce(
            "import numpy as np\n"
            "from serialkin.redundancy import manipulability, self_motion\n"
            "from serialkin.tracking.scenario import planar_arm\n"
            "robot = planar_arm(6, 0.1); q0 = np.array([0.3, 0.2, 0.1, 0.1, 0.05, 0.02])\n"
            "H = manipulability(robot, 'planar')\n"
            "q = self_motion(robot, q0, H, steps=60, gain=20.0, max_step=0.02)\n"
            "drift = np.linalg.norm(robot.fk(q[-1])[:2, 3] - robot.fk(q0)[:2, 3])\n"
            "print(f'H {H.value(q0):.4f} -> {H.value(q[-1]):.4f}, EE drift {drift * 1e3:.3f} mm')",
            expect=[f"{obj.value(q0):.4f}", f"{obj.value(traj[-1]):.4f}",
                    f"{drift * 1e3:.3f}"]))
    return Section(title="5.3 Kinematically redundant manipulators",
                   part="Null-space methods", equations="eqs 42-45 (44 corrected)", html=body)


def _six_link_algorithm(ctx: ReportContext, sa: Any) -> str:
    """The DLS step (eq 46, corrected) and the chapter's 6-link algorithm, steps corrected."""
    return (
        "<p>Damped least squares (the Levenberg-Marquardt step); <b>eq 46 and the 6-link "
        "algorithm are corrected</b> (ERRATA): the chapter prints "
        + ctx.imath(r"\mathbf{J}^{T}(\mathbf{J}^{T} + \lambda^2\mathbf{I})^{-1}")
        + " and the update " + ctx.imath(r"\Delta\mathbf{q} = \mathbf{q} + \ldots;\ "
                                         r"\mathbf{q} = \Delta\mathbf{q}") + ".</p>"
        + ctx.eq(EQ["46"], "46, corrected")
        + ctx.algorithm("Inverse kinematic model for 6-link manipulator (steps 7-8 corrected)", [
            (0, "Set the desired path of the end effector, the matrix X<sub>path</sub>, and "
                "the parameters L, λ."),
            (0, "FOR step = 1 → p"),
            (1, "Set the desired position of the end effector from X<sub>path</sub>: "
                "e<sub>p</sub> = [x<sub>p</sub> y<sub>p</sub>]ᵀ"),
            (1, "WHILE x<sub>actual</sub> ≠ e<sub>p</sub> (here: until ‖Δx‖ &lt; "
                f"{sa.options.get('tol', 1e-6) * 1e6:g} µm)"),
            (2, "Compute the Jacobian J"),
            (2, "Compute x<sub>actual</sub> = [x<sub>act</sub> y<sub>act</sub>]ᵀ"),
            (2, "Compute " + ctx.imath(r"\Delta\mathbf{q} = \mathbf{J}^{T}(\mathbf{J}"
                                       r"\mathbf{J}^{T} + \lambda^2\mathbf{I})^{-1}"
                                       r"\Delta\mathbf{x}") + " (corrected)"),
            (2, ctx.imath(r"\mathbf{q} \leftarrow \mathbf{q} + \Delta\mathbf{q}")
                + " (corrected; serialkin also caps ‖Δq‖, see below)"),
            (1, "END WHILE"),
            (0, "END FOR"),
        ], "<p>The chapter prints step 7 as Δq = q + Jᵀ(JJᵀ + λ²I)⁻¹Δx and step 8 as "
           "q = Δq (ERRATA).</p>"))


def _times_l(k: float) -> str:
    """A multiple k of the link length as the chapter writes it: "0", "L", "−2.5L"."""
    if k == 0:
        return "0"
    text = "L" if abs(k) == 1 else f"{abs(k):g}L"
    return ("−" if k < 0 else "") + text


def _six_link_setup(sa: Any, cap: float, prepared: dict[str, Any]) -> str:
    """The scenario's parameters and what the step cap ``cap`` [rad] decides.

    Args:
        sa: the scenario ``six_link_circle``.
        cap: the DLS step cap [rad].
        prepared: :func:`six_link_prepare` of the run (branches, the step at q0).
    """
    branch = prepared["branch"]
    robot = sa.robot
    L = float(robot.dh[0].a)
    circle = sa.data["path"]
    c = np.asarray(circle["center"], dtype=float)
    p0 = sa.path.points[0][:2]
    q0 = np.asarray(sa.q0, dtype=float)
    q0_text = (f"{q0[0]:g}" if np.ptp(q0) == 0 else format_vector(q0, "{:.3g}") + " rad")
    stop = float(circle["stop"])
    stop_text = "2π" if abs(stop - 2 * np.pi) < 1e-9 else f"{stop:.4g}"
    stretched = "the stretched arm, " if not q0.any() else ""
    return (
        f"<p>Scenario <code>six_link_circle</code>: {robot.n} links of L = {L * 1e3:g} mm, "
        f"circle of centre ({_times_l(c[0] / L)}, {_times_l(c[1] / L)}) and radius "
        f"{_times_l(float(circle['radius']) / L)}, φ from {float(circle['start']):g} to "
        f"{stop_text} in steps of {float(circle['step']):g} "
        f"({len(sa.path)} points), q0 = {q0_text} ({stretched}drawn dashed in Figure 8), λ = "
        f"{sa.options.get('damping', 0.02):g} m (our choice; the chapter does not give it), "
        f"iterations until ‖Δx‖ &lt; {sa.options.get('tol', 1e-6) * 1e6:g} µm, acceptance "
        f"±{sa.tolerance * 1e3:g} mm. At q0 the Jacobian is singular (smallest singular value "
        f"{prepared['sigma_min']:.1e} m) and the error towards the first target "
        f"({p0[0]:g}, {p0[1]:g}) m lies along the direction it has lost (|cos| = "
        f"{prepared['along']:.4f}): the eq 46 step towards it has norm "
        f"{prepared['step0']:.1e} rad, so the tracker bends every joint by 1 mrad and "
        "continues.</p>"
        f"<p><b>Step cap.</b> Each DLS iteration's joint step is capped at ‖Δq‖ ≤ {cap:g} "
        "rad (<code>max_step</code>, the tracker's default; the chapter has no cap). From "
        "the singular start the cap decides which way the arm folds, and with it which "
        "branch the joint curves of Figure 9 follow: "
        f"with the cap at {2 * cap:g} rad the joint trajectory differs from the one shown by "
        f"up to {branch[2 * cap]:.1f}°, without an effective cap (100 rad) by up to "
        f"{branch[100.0]:.1f}°.</p>")


def _six_link_figures(ctx: ReportContext, sa: Any, ta: Any, cap: float) -> list[str]:
    """Figures 8 (the motion) and 9 (the joint angles) of the run ``ta``, and its GIF."""
    import matplotlib.pyplot as plt

    from serialkin.viz import plot_joint_trajectories, plot_motion

    fig, ax = plt.subplots(figsize=(7.5, 4.6))
    plot_motion(sa.robot, ta.q, ax, path_points=sa.path.points, every=2, q0=sa.q0,
                title="Figure 8: six-link arm tracking the circle (DLS)")
    parts = [ctx.figure(fig, "fig08_six_link_motion",
                        "Figure 8 — motion of the six-link arm from the stretched start "
                        "pose q0 = 0 (dashed); the circle in green.")]
    fig, ax = plt.subplots(figsize=(7.5, 4.0))
    plot_joint_trajectories(ta.q, sa.path.parameter, ax, robot=sa.robot, xlabel="φ [rad]",
                            title="Figure 9: variations of the joint angles")
    parts.append(ctx.figure(fig, "fig09_six_link_joints",
                            f"Figure 9 — joint angles along the circle (φ); DLS steps capped "
                            f"at ‖Δq‖ ≤ {cap:g} rad, which selects this branch from the "
                            "singular start (see the step cap above)."))
    parts.append(_gif(ctx, sa.robot, ta, "fig08_six_link", "Six-link arm tracking the circle",
                      frames=32))
    return parts


def six_link_prepare(ctx: ReportContext, sa: Any, ta: Any) -> dict[str, Any]:
    """What the six-link part shows besides its timing: step cap, branches, figures.

    Args:
        ctx: the report context (the figures are saved through it).
        sa: the scenario ``six_link_circle``.
        ta: its trajectory (``sa.run()``).

    Returns:
        dict with ``cap`` (the DLS step cap [rad]), ``branch`` ({other cap [rad]: largest
        joint difference from ``ta`` [deg]}), ``step0`` (norm of the eq 46 step at q0
        towards the first path point [rad]), ``sigma_min`` (smallest singular value of the
        (2, n) Jacobian at q0 [m]), ``along`` (|cos| of the angle between that error and
        the Jacobian's lost direction) and ``figures`` (Figures 8, 9 and the GIF, HTML).
    """
    import dataclasses
    import inspect

    from serialkin.tracking.tracker import track

    cap = float(sa.options.get("max_step", inspect.signature(track).parameters["max_step"]
                               .default))
    # the same run with the cap doubled and with no effective cap: does the branch change?
    other = {c: dataclasses.replace(sa, options={**sa.options, "max_step": c}).run()
             for c in (2 * cap, 100.0)}
    branch = {c: float(np.abs(tr.q - ta.q).max()) * DEG for c, tr in other.items()}
    # eq 46 at the stretched start towards the first path point
    q0 = np.asarray(sa.q0, dtype=float)
    J = sa.robot.jacobian(q0)[:2]
    dx = sa.path.points[0][:2] - sa.robot.fk(q0)[:2, 3]
    lam = float(sa.options.get("damping", 0.02))
    step0 = float(np.linalg.norm(J.T @ np.linalg.solve(J @ J.T + lam**2 * np.eye(2), dx)))
    U, sv, _ = np.linalg.svd(J)
    along = float(abs(U[:, -1] @ dx) / np.linalg.norm(dx))  # |cos| to the lost direction
    return {"cap": cap, "branch": branch, "step0": step0, "sigma_min": float(sv[-1]),
            "along": along, "figures": _six_link_figures(ctx, sa, ta, cap)}


def _six_link_part(ctx: ReportContext, sa: Any, ta: Any, t_a: Any,
                   prepared: dict[str, Any]) -> Section:
    """The six-link example: the DLS algorithm, the run, its table and Figures 8 and 9.

    Args:
        ctx: the report context.
        sa: the scenario ``six_link_circle``.
        ta: its trajectory.
        t_a: the :class:`Timing` of ``sa.run()`` (whole path).
        prepared: :func:`six_link_prepare` of the same run.
    """
    cap = prepared["cap"]
    reached = f"{int(ta.reached.sum())} / {len(sa.path)}"
    max_err = f"{ta.max_error * 1e3:.4g}"
    total_it = str(int(ta.iterations.sum()))
    parts = [
        _six_link_algorithm(ctx, sa),
        _six_link_setup(sa, cap, prepared),
        ctx.table([
            ("path points reached within ±5 mm", reached),
            ("largest tracking error", f"{max_err} mm"),
            ("iterations (first point / median of the others / in all)",
             f"{ta.iterations[0]} / {int(np.median(ta.iterations[1:]))} / {total_it}"),
            ("time for the whole path (compiled loop)", t_a.text),
        ], ["quantity", "value"]),
        *prepared["figures"],
    ]
    parts.append(ctx.reproduce("serialkin track six_link_circle --out out/track", shell=True,
                               expect=reached.split(" / ") + [max_err, total_it]))
    return Section(title="5.3 Kinematically redundant manipulators",
                   part="Example: the six-link arm (Figures 8 and 9)",
                   equations="eq 46 (corrected)", html="".join(parts))
