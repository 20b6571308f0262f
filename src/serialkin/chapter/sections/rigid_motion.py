"""Report section 2, rigid-body motion (eqs 1-9), recomputed by :mod:`serialkin.spatial`.

Contents: the elementary rotations (eqs 4-6) evaluated and compared with their printed
form; a composition example with the change of coordinates of a point (eq 3) and the
homogeneous transform (eqs 8-9) and its inverse; the orthonormality checks RᵀR = I and
det R = 1 (eq 7); a table converting one orientation between every representation
serialkin supports (with the round-trip error, also at the gimbal lock); the pose error
used by the IK solvers; the chapter's Figure 1 (a rigid body moved by a twist, two of its
points keeping their distance) and a figure of the rotated frames (the chapter's Figure 2
and a rotated and translated frame), drawn from the computed matrices.
"""

from __future__ import annotations

import numpy as np

from serialkin.chapter._context import ReportContext, Section, format_number, format_vector
from serialkin.spatial import (
    inv_transform,
    make_transform,
    matrix_to_axis_angle,
    matrix_to_quaternion,
    matrix_to_rpy,
    matrix_to_zyz,
    pose_distance,
    pose_error,
    quaternion_to_matrix,
    rotx,
    roty,
    rotz,
    rpy_to_matrix,
    se3_exp,
    se3_log,
    so3_exp,
    so3_log,
    trotz,
    zyz_to_matrix,
)
from serialkin.spatial.rotations import axis_angle_to_matrix

DEG = np.pi / 180.0

#: Figure 1's body: a pentagon in body coordinates [m], points p and q on it [m], its pose
#: at t = 0 and the twist ξ = [v; ω] [m/s; rad/s] it moves by, T(t) = exp(ξ t) · T(0).
BODY = np.array([[0.0, 0.0], [0.5, 0.0], [0.6, 0.25], [0.3, 0.45], [0.0, 0.3]])
BODY_P, BODY_Q = np.array([0.1, 0.1, 0.0]), np.array([0.5, 0.15, 0.0])
BODY_T0 = make_transform(rotz(10 * DEG), np.array([0.2, 0.1, 0.0]))
BODY_TWIST = np.array([0.9, 0.35, 0.0, 0.0, 0.0, 0.8])
BODY_T = 1.5  # the later time t [s]


def _printed_elementary(axis: str, t: float) -> np.ndarray:
    """The matrices exactly as printed in eqs 4-6, typed from the chapter."""
    c, s = np.cos(t), np.sin(t)
    if axis == "x":
        return np.array([[1, 0, 0], [0, c, -s], [0, s, c]])
    if axis == "y":
        return np.array([[c, 0, s], [0, 1, 0], [-s, 0, c]])
    return np.array([[c, -s, 0], [s, c, 0], [0, 0, 1]])


def _orthonormality(R: np.ndarray) -> tuple[float, float]:
    """(max |RᵀR − I|, max |det R − 1|) over a (batch of) rotation(s)."""
    err = np.abs(np.swapaxes(R, -1, -2) @ R - np.eye(3)).max()
    det = np.abs(np.linalg.det(R) - 1.0).max()
    return float(err), float(det)


def _draw_frame(ax: object, T: np.ndarray, label: str, color: str, length: float = 1.0,
                text_shift: float = 0.0) -> None:
    """Three quiver arrows (x, y, z axes of T) labelled ``x_label`` etc."""
    o = T[:3, 3]
    for k, name in enumerate("xyz"):
        d = T[:3, k] * length
        ax.quiver(o[0], o[1], o[2], d[0], d[1], d[2], color=color,  # type: ignore[attr-defined]
                  arrow_length_ratio=0.12, linewidth=2 if k == 2 else 1.5)
        tip = o + 1.1 * d + np.array([text_shift, 0.0, 0.0])
        ax.text(tip[0], tip[1], tip[2], f"${name}_{{{label}}}$", color=color)  # type: ignore[attr-defined]


def _figure(R_q: np.ndarray, q: float, T1: np.ndarray, p1: np.ndarray) -> object:
    """Two 3D panels: (a) frame 0 rotated by q about z_r (Figure 2); (b) frame 1 = T1 and p."""
    from matplotlib.figure import Figure
    from matplotlib.ticker import MaxNLocator

    fig = Figure(figsize=(11, 5))
    ax = fig.add_subplot(1, 2, 1, projection="3d")
    _draw_frame(ax, np.eye(4), "r", "0.35")
    _draw_frame(ax, make_transform(R_q), "0", "tab:blue", text_shift=0.25)
    arc = np.linspace(0.0, q, 30)
    ax.plot(0.6 * np.cos(arc), 0.6 * np.sin(arc), 0 * arc, color="tab:red")
    ax.text(0.65 * np.cos(q / 2), 0.65 * np.sin(q / 2), 0.0, f"q = {q / DEG:.0f}°", color="tab:red")
    ax.set_title("(a) frame 0 = Rz(q) · frame r (eq 6, Figure 2)")
    ax2 = fig.add_subplot(1, 2, 2, projection="3d")
    _draw_frame(ax2, np.eye(4), "r", "0.35")
    _draw_frame(ax2, T1, "1", "tab:green", length=0.8)
    o = T1[:3, 3]
    pr = T1[:3, :3] @ p1 + o
    ax2.plot([0, o[0]], [0, o[1]], [0, o[2]], "k--", linewidth=1)
    ax2.quiver(o[0], o[1], o[2], *(pr - o), color="tab:purple", arrow_length_ratio=0.1)
    ax2.quiver(0, 0, 0, *pr, color="tab:orange", arrow_length_ratio=0.06)
    ax2.scatter(*pr, color="k", s=20)
    ax2.text(*(pr + 0.05), "p", color="k")
    ax2.set_title("(b) frame 1 = T (eq 9) and a point p = R p₁ + o (eq 8)")
    ax.view_init(elev=28, azim=-30)
    ax2.view_init(elev=22, azim=-65)
    for a in (ax, ax2):
        lim = (-0.1, 1.5) if a is ax2 else (-1.0, 1.2)
        a.set_xlim(lim)
        a.set_ylim(lim)
        a.set_zlim((-0.1, 1.5) if a is ax2 else (0.0, 1.2))
        a.set_xlabel("x")
        a.set_ylabel("y")
        a.set_zlabel("z")
        a.set_box_aspect((1, 1, 1) if a is ax2 else (2.2, 2.2, 1.2))
        for axis in (a.xaxis, a.yaxis, a.zaxis):
            axis.set_major_locator(MaxNLocator(4))
        a.tick_params(labelsize=8)
    return fig


def _rigid_body_part(ctx: ReportContext) -> str:
    """The chapter's Figure 1: a body at t = 0 and t, ‖p(t) − q(t)‖ = ‖p(0) − q(0)‖."""
    from matplotlib.figure import Figure

    times = np.linspace(0.0, BODY_T, 31)
    poses = se3_exp(BODY_TWIST * times[:, None]) @ BODY_T0  # f(t) of the chapter, (31, 4, 4)
    corners = np.column_stack([BODY, np.zeros(len(BODY)), np.ones(len(BODY))])
    points = np.array([np.append(BODY_P, 1.0), np.append(BODY_Q, 1.0)])
    world = poses @ points.T  # (31, 4, 2): p and q at every time
    dist = np.linalg.norm(world[:, :3, 0] - world[:, :3, 1], axis=1)
    fig = Figure(figsize=(7.0, 4.6))
    ax = fig.add_subplot(1, 1, 1)
    for k in (10, 20):  # two poses in between, faint
        xy = (poses[k] @ corners.T)[:2].T
        ax.fill(xy[:, 0], xy[:, 1], fill=False, ec="0.75", lw=0.8, ls="--")
    for k, color, when in ((0, "0.55", "0"), (-1, "tab:blue", "t")):
        xy = (poses[k] @ corners.T)[:2].T
        ax.fill(xy[:, 0], xy[:, 1], color=color, alpha=0.25, ec=color, lw=1.5,
                label=f"body at t = {times[k]:g} s")
        pq = world[k, :2]
        ax.plot(pq[0], pq[1], "-o", color="k", ms=4, lw=1)
        for j, name in enumerate("pq"):
            ax.annotate(f"{name}({when})", pq[:, j], xytext=(4, 5), textcoords="offset points")
    for j in range(2):
        ax.plot(world[:, 0, j], world[:, 1, j], ":", color="tab:red", lw=1)
    ax.text(0.98, 0.03, f"‖p(0) − q(0)‖ = {dist[0]:.4f} m\n‖p(t) − q(t)‖ = {dist[-1]:.4f} m",
            transform=ax.transAxes, ha="right", va="bottom", fontsize=9,
            bbox={"boxstyle": "round", "fc": "white", "ec": "0.7"})
    ax.set_aspect("equal", adjustable="datalim")
    ax.set_xlabel("x_r [m]")
    ax.set_ylabel("y_r [m]")
    ax.legend(loc="upper left", fontsize=8)
    ax.set_title("Rigid body moved by T(t) = exp(ξt)·T(0); dotted: the paths of p and q",
                 fontsize=10)
    caption = (f"Figure 1 — rigid body: a pentagon moved by the twist ξ = "
               f"{format_vector(BODY_TWIST)} (se3_exp) from t = 0 to t = {BODY_T:g} s; "
               f"‖p(0) − q(0)‖ = {dist[0]:.4f} m, ‖p(t) − q(t)‖ = {dist[-1]:.4f} m, "
               f"largest change over the {len(times)} poses drawn {np.ptp(dist):.1e} m.")
    return (
        "<h3>Rigid body (Figure 1)</h3><p>A motion of a body O is a map f(t): O → ℝ³ that "
        "keeps the distance of any two of its points p and q,</p>"
        + ctx.eq(r"\|\mathbf{p}(t) - \mathbf{q}(t)\| = \|\mathbf{p}(0) - \mathbf{q}(0)\|"
                 r" = \text{constant}")
        + "<p>Here f(t) is the transform T(t) = exp(ξt)·T(0) of a constant twist "
        "(<code>se3_exp</code>, eq 9's matrix for every t), applied to the body's corners "
        "and to p and q; the distances below are computed from the moved points.</p>"
        + ctx.figure(fig, "rigid_body_fig1", caption)
    )


def _elementary_part(ctx: ReportContext, elem: dict[str, np.ndarray],
                     angles: tuple[float, float, float]) -> str:
    """Eqs 4-6 as printed, and ``rotx``/``roty``/``rotz`` against the printed matrices."""
    rows = []
    for (axis, R), t in zip(elem.items(), angles, strict=True):
        dev = np.abs(R - _printed_elementary(axis, t)).max()
        rows.append((f"R{axis}({t / DEG:.0f}°)", ctx.matrix(R), f"{dev:.1e}"))
    return (
        "<h3>Elementary rotations (eqs 4-6)</h3><p>The chapter's rotations about x, y and z:</p>"
        + ctx.eq(r"\mathbf{R}_x = \begin{bmatrix}1 & 0 & 0\\ 0 & \cos\alpha & -\sin\alpha"
                 r"\\ 0 & \sin\alpha & \cos\alpha\end{bmatrix}", "4")
        + ctx.eq(r"\mathbf{R}_y = \begin{bmatrix}\cos\beta & 0 & \sin\beta\\ 0 & 1 & 0"
                 r"\\ -\sin\beta & 0 & \cos\beta\end{bmatrix}", "5")
        + ctx.eq(r"\mathbf{R}_z = \begin{bmatrix}\cos\gamma & -\sin\gamma & 0\\ "
                 r"\sin\gamma & \cos\gamma & 0\\ 0 & 0 & 1\end{bmatrix}", "6")
        + "<p>Evaluated at " + ctx.imath(r"\alpha = 30^\circ,\ \beta = 45^\circ,\ "
                                         r"\gamma = 60^\circ")
        + " by <code>rotx</code>, <code>roty</code>, <code>rotz</code>; the last column is "
        "the largest deviation from the matrix typed from the chapter.</p>"
        + ctx.table(rows, ["rotation", "matrix", "|R − printed|"])
    )


def _change_of_frame_part(ctx: ReportContext, R: np.ndarray, R_other: np.ndarray,
                          p1: np.ndarray) -> str:
    """Eqs 1-3: R's entries as scalar products of unit vectors, checked one by one."""
    # eqs 1-3: unit vectors of frame 1 expressed in r are R's columns; R_jk = e_j · u_k
    units = [R[:, k] for k in range(3)]
    dots = np.array([[np.eye(3)[j] @ units[k] for k in range(3)] for j in range(3)])
    p_eq1 = sum(p1[k] * units[k] for k in range(3))
    return (
        "<h3>Change of frame (eqs 1-3)</h3><p>A vector written in the unit vectors of the "
        "reference frame and of frame 1,</p>"
        + ctx.eq(r"\mathbf{p} = p_{xr}\mathbf{i}_r + p_{yr}\mathbf{j}_r + p_{zr}\mathbf{k}_r"
                 r" = p_{x1}\mathbf{i}_1 + p_{y1}\mathbf{j}_1 + p_{z1}\mathbf{k}_1", "1")
        + "<p>has reference coordinates given by the scalar products of the unit vectors</p>"
        + ctx.eq(r"\begin{array}{rcl}"
                 r"p_{xr} & = & \mathbf{i}_r\cdot\mathbf{p} = \mathbf{i}_r\cdot p_{x1}"
                 r"\mathbf{i}_1 + \mathbf{i}_r\cdot p_{y1}\mathbf{j}_1 + \mathbf{i}_r\cdot"
                 r" p_{z1}\mathbf{k}_1\\ "
                 r"p_{yr} & = & \mathbf{j}_r\cdot\mathbf{p} = \mathbf{j}_r\cdot p_{x1}"
                 r"\mathbf{i}_1 + \mathbf{j}_r\cdot p_{y1}\mathbf{j}_1 + \mathbf{j}_r\cdot"
                 r" p_{z1}\mathbf{k}_1\\ "
                 r"p_{zr} & = & \mathbf{k}_r\cdot\mathbf{p} = \mathbf{k}_r\cdot p_{x1}"
                 r"\mathbf{i}_1 + \mathbf{k}_r\cdot p_{y1}\mathbf{j}_1 + \mathbf{k}_r\cdot"
                 r" p_{z1}\mathbf{k}_1\end{array}", "2")
        + "<p>in matrix form</p>"
        + ctx.eq(r"\begin{bmatrix}p_{xr}\\ p_{yr}\\ p_{zr}\end{bmatrix} = \begin{bmatrix}"
                 r"\mathbf{i}_r\cdot\mathbf{i}_1 & \mathbf{i}_r\cdot\mathbf{j}_1 & "
                 r"\mathbf{i}_r\cdot\mathbf{k}_1\\ \mathbf{j}_r\cdot\mathbf{i}_1 & "
                 r"\mathbf{j}_r\cdot\mathbf{j}_1 & \mathbf{j}_r\cdot\mathbf{k}_1\\ "
                 r"\mathbf{k}_r\cdot\mathbf{i}_1 & \mathbf{k}_r\cdot\mathbf{j}_1 & "
                 r"\mathbf{k}_r\cdot\mathbf{k}_1\end{bmatrix}\begin{bmatrix}p_{x1}\\ p_{y1}"
                 r"\\ p_{z1}\end{bmatrix} = \mathbf{R}_{r1}\,\mathbf{p}_1", "3")
        + "<p>Take frame 1 turned by "
        + ctx.imath(r"\mathbf{R}_{r1} = \mathbf{R}_z(60^\circ)\,\mathbf{R}_y(45^\circ)\,"
                    r"\mathbf{R}_x(30^\circ)")
        + " (rotations about the fixed axes x, then y, then z: the roll-pitch-yaw convention "
        "used throughout serialkin):</p>"
        + ctx.matrix(R)
        + "<p>Computing the nine scalar products of eq 3 one by one reproduces "
        + ctx.imath(r"\mathbf{R}_{r1}") + f" to {np.abs(dots - R).max():.1e}, and eq 1 "
        "(the sum of frame 1's unit vectors weighted by "
        + ctx.imath(r"\mathbf{p}_1") + ") equals " + ctx.imath(r"\mathbf{R}_{r1}\mathbf{p}_1")
        + f" to {np.abs(p_eq1 - R @ p1).max():.1e}. Rotations do not commute: "
        + ctx.imath(r"\max|\mathbf{R}_z\mathbf{R}_y\mathbf{R}_x - "
                    r"\mathbf{R}_x\mathbf{R}_y\mathbf{R}_z|")
        + f" = {np.abs(R - R_other).max():.4f}.</p>"
    )


def _homogeneous_part(ctx: ReportContext, T: np.ndarray, p1: np.ndarray) -> str:
    """Eqs 8-9: one point mapped by R p₁ + o and by T, and T⁻¹ mapping it back."""
    o = T[:3, 3]
    pr_eq8 = T[:3, :3] @ p1 + o
    pr_eq9 = (T @ np.append(p1, 1.0))[:3]
    Tinv = inv_transform(T)
    return (
        "<h3>Rotation and translation (eqs 8-9)</h3>"
        + ctx.eq(r"\begin{bmatrix}x_r\\ y_r\\ z_r\end{bmatrix} = \mathbf{R}\begin{bmatrix}"
                 r"x_1\\ y_1\\ z_1\end{bmatrix} + \begin{bmatrix}p_x\\ p_y\\ p_z\end{bmatrix}",
                 "8")
        + ctx.eq(r"\begin{bmatrix}x_r\\ y_r\\ z_r\\ 1\end{bmatrix} = \begin{bmatrix}"
                 r"\mathbf{R} & \mathbf{p}\\ \mathbf{0}^T & 1\end{bmatrix}\begin{bmatrix}"
                 r"x_1\\ y_1\\ z_1\\ 1\end{bmatrix}", "9")
        + f"<p>With the rotation R of eq 3 above and origin p = {format_vector(o)} m, the "
        "homogeneous transform of eq 9 (<code>make_transform(R, p)</code>) is</p>"
        + ctx.matrix(T)
        + f"<p>The point with frame-1 coordinates {format_vector(p1)} m has reference coordinates "
        f"{format_vector(pr_eq8)} by eq 8 and {format_vector(pr_eq9)} by eq 9; "
        f"difference {np.abs(pr_eq8 - pr_eq9).max():.1e}. The inverse "
        + ctx.imath(r"\mathbf{T}^{-1} = \begin{bmatrix}\mathbf{R}^T & -\mathbf{R}^T\mathbf{p}"
                    r"\\ \mathbf{0}^T & 1\end{bmatrix}")
        + " satisfies " + ctx.imath(r"\max|\mathbf{T}^{-1}\mathbf{T} - \mathbf{I}_4|")
        + f" = {np.abs(Tinv @ T - np.eye(4)).max():.1e} and maps the point back with error "
        f"{np.abs((Tinv @ np.append(pr_eq9, 1.0))[:3] - p1).max():.1e}.</p>"
    )


def _orthonormality_part(ctx: ReportContext, elem: dict[str, np.ndarray], R: np.ndarray,
                         T: np.ndarray) -> str:
    """Eq 7 checked on every matrix of the section and on 10,000 random compositions."""
    rng = np.random.default_rng(2024)
    many = rpy_to_matrix(rng.uniform(-np.pi, np.pi, size=(10000, 3)))
    checks = [("Rx(30°)", elem["x"]), ("Ry(45°)", elem["y"]), ("Rz(60°)", elem["z"]),
              ("Rz Ry Rx", R), ("rotation block of T (eq 9 below)", T[:3, :3]),
              ("10,000 random rpy compositions (seed 2024)", many)]
    return (
        "<h3>Orthonormality (eq 7)</h3>"
        + ctx.eq(r"\mathbf{R}^T\mathbf{R} = \mathbf{I}_3,\qquad \det\mathbf{R} = 1", "7")
        + ctx.table([(name, *_orthonormality(M)) for name, M in checks],
                    ["matrix", "max |RᵀR − I₃|", "max |det R − 1|"], fmt="{:.1e}"))


def _representations_part(ctx: ReportContext, R: np.ndarray) -> str:
    """R in every orientation representation, converted back, and two singular points."""
    rpy = matrix_to_rpy(R)
    zyz = matrix_to_zyz(R)
    axis, angle = matrix_to_axis_angle(R)
    quat = matrix_to_quaternion(R)
    rotvec = so3_log(R)
    conv = [
        ("roll-pitch-yaw (rad), R = Rz(y)Ry(p)Rx(r)", rpy, rpy_to_matrix(rpy)),
        ("ZYZ Euler (rad), R = Rz(φ)Ry(θ)Rz(ψ)", zyz, zyz_to_matrix(zyz)),
        ("axis, angle (rad)", np.append(axis, angle), axis_angle_to_matrix(axis, angle)),
        ("unit quaternion (w, x, y, z)", quat, quaternion_to_matrix(quat)),
        ("rotation vector log(R) (rad)", rotvec, so3_exp(rotvec)),
    ]
    locked = rpy_to_matrix([0.5, np.pi / 2, 0.2])
    rpy_l = matrix_to_rpy(locked)
    half = axis_angle_to_matrix([0.0, 0.6, 0.8], np.pi)
    q_half = matrix_to_quaternion(half)
    conv_rows = [(n, format_vector(v),
                  f"{np.abs(back - R).max():.1e}") for n, v, back in conv]
    conv_rows.append(("rpy at the gimbal lock: (0.5, π/2, 0.2) → (roll − yaw, π/2, 0)",
                      format_vector(rpy_l),
                      f"{np.abs(rpy_to_matrix(rpy_l) - locked).max():.1e}"))
    conv_rows.append(("quaternion of a half turn about (0, 0.6, 0.8): w = 0, angle π",
                      format_vector(q_half),
                      f"{np.abs(quaternion_to_matrix(q_half) - half).max():.1e}"))
    return (
        "<h3>Orientation representations</h3><p>The rotation R above in every representation "
        "(serialkin.spatial), and the error of converting back to a matrix. The last two rows "
        "are at singular points of a representation.</p>"
        + ctx.table(conv_rows, ["representation", "value", "max |R(value) − R|"])
    )


def _twist_part(ctx: ReportContext, T: np.ndarray) -> str:
    """The twist coordinates of T (SE(3) log and exp) and the IK solvers' pose error."""
    xi = se3_log(T)
    T2 = trotz(0.1) @ T
    e = pose_error(T, T2)
    d, th = pose_distance(T, T2)
    return (
        "<h3>Twist coordinates and pose error</h3>"
        "<p>The twist " + ctx.imath(r"\boldsymbol{\xi} = [\mathbf{v}; \boldsymbol{\omega}]")
        + " with " + ctx.imath(r"\exp(\boldsymbol{\xi}) = \mathbf{T}") + " is ξ = "
        f"{format_vector(xi)} (max |exp(ξ) − T| = "
        f"{np.abs(se3_exp(xi) - T).max():.1e}). Turning T by 0.1 rad about the world z axis "
        "gives the pose error "
        + ctx.imath(r"\mathbf{e} = [\mathbf{p}_{target} - \mathbf{p};\ "
                    r"\log(\mathbf{R}_{target}\mathbf{R}^T)^\vee]")
        + f" = {format_vector(e)}: position distance {float(d):.4f} m,"
        f" angle {float(th):.4f} rad. Every IK solver drives this 6-vector to zero.</p>"
    )


def _frames_part(ctx: ReportContext, T: np.ndarray, p1: np.ndarray) -> str:
    """The figure of the rotated frames and the snippet that reproduces eqs 8-9."""
    q = 30 * DEG
    return (
        ctx.figure(_figure(rotz(q), q, T, p1), "rigid_motion_frames",
                   "Rotated frames computed by serialkin: (a) the chapter's Figure 2, a "
                   "frame rotated by q = 30° about z_r; (b) the frame T of eq 9 "
                   "(Rz(60°)Ry(45°)Rx(30°), origin o) and the point p.")
        + ctx.reproduce(
            "import numpy as np\n"
            "from serialkin.spatial import rotx, roty, rotz, make_transform, inv_transform\n"
            "R = rotz(np.radians(60)) @ roty(np.radians(45)) @ rotx(np.radians(30))\n"
            "T = make_transform(R, [0.5, 0.4, 0.3])                      # eq 9\n"
            "print(np.round(T, 4))\n"
            "print(T @ [0.3, 0.2, 0.1, 1.0])                             # eq 9 on a point\n"
            "print(np.round(inv_transform(T) @ T, 12))                   # T⁻¹T = I",
            expect=[format_number(0.0 if abs(v) < 5e-13 else v, "{:.4f}")
                    for v in T[:3].ravel()]
            + [format_number(v) for v in (T @ np.append(p1, 1.0))[:3]])
    )


def build(ctx: ReportContext) -> Section:
    """Compute section 2's examples and return the report section."""
    alpha, beta, gamma = 30 * DEG, 45 * DEG, 60 * DEG
    elem = {"x": rotx(alpha), "y": roty(beta), "z": rotz(gamma)}
    R = rotz(gamma) @ roty(beta) @ rotx(alpha)
    p1 = np.array([0.3, 0.2, 0.1])
    T = make_transform(R, np.array([0.5, 0.4, 0.3]))
    parts = [  # in the chapter's order: Figure 1, eqs 1-3, 4-6, 7, 8-9
        _rigid_body_part(ctx),
        _change_of_frame_part(ctx, R, rotx(alpha) @ roty(beta) @ rotz(gamma), p1),
        _elementary_part(ctx, elem, (alpha, beta, gamma)),
        _orthonormality_part(ctx, elem, R, T),
        _homogeneous_part(ctx, T, p1),
        _representations_part(ctx, R),
        _twist_part(ctx, T),
        _frames_part(ctx, T, p1),
    ]
    return Section(title="2. Rigid body motion", equations="eqs 1-9", html="".join(parts))
