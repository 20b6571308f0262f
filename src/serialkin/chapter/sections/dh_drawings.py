"""Drawings of Denavit-Hartenberg frames for report section 3.2, computed from a model.

Two figures: the chapter's Figure 3 (one link pair: the axes z_{i−1} and z_i, their common
normal from O_i′ to O_i, the x axes and the four parameters a_i, d_i, ϑ_i, α_i) drawn from
a DH row of a built-in model and measured back from the drawn frames; and every DH frame
of the PUMA 560, its coinciding origins labelled once ("O4 = O5 = O6").
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from serialkin.chapter._context import ReportContext, format_number
from serialkin.model.dh import link_transform
from serialkin.model.dh_extract import common_normal
from serialkin.model.robot import Robot

DEG = np.pi / 180.0


@dataclass(frozen=True)
class LinkPair:
    """Frame i in frame i−1 and its DH parameters measured back from the drawn geometry.

    Attributes:
        i: the link number (1-based), frames i−1 and i.
        T: frame i in frame i−1, ``link_transform(row, q_i)``, shape (4, 4).
        o_prime: O_i′, foot of the common normal on z_{i−1} [m], shape (3,).
        a: (O_i − O_i′) · x_i [m].
        d: (O_i′ − O_{i−1}) · z_{i−1} [m].
        theta: angle from x_{i−1} to x_i about z_{i−1} [rad].
        alpha: angle from z_{i−1} to z_i about x_i [rad].
    """

    i: int
    T: np.ndarray
    o_prime: np.ndarray
    a: float
    d: float
    theta: float
    alpha: float


def link_pair(robot: Robot, i: int, q_i: float) -> LinkPair:
    """Frames i−1 and i of ``robot`` (standard DH) at joint value ``q_i``, measured.

    O_i′ is the point of z_{i−1} closest to the line z_i (the projection of O_i onto z_{i−1}
    when the axes are parallel); the parameters are read from the frames, not the row.
    """
    T = link_transform(robot.dh[i - 1], q_i, "standard")
    o, x, z = T[:3, 3], T[:3, 0], T[:3, 2]
    ez = np.array([0.0, 0.0, 1.0])
    b = float(ez @ z)
    o_prime = common_normal(np.zeros(3), ez, o, z, prefer=o)[0]  # its foot on z_{i−1}
    return LinkPair(i=i, T=T, o_prime=o_prime, a=float((o - o_prime) @ x),
                    d=float(o_prime[2]),
                    theta=float(np.arctan2(x[1], x[0])),
                    alpha=float(np.arctan2(np.cross(ez, z) @ x, b)))


def _arc(ax: object, center: np.ndarray, u: np.ndarray, w: np.ndarray, angle: float,
         radius: float, label: str, color: str, shift: np.ndarray) -> None:
    """An arc center + r(u cos s + w sin s), s from 0 to ``angle``, labelled by its middle."""
    s = np.linspace(0.0, angle, 30)
    pts = center + radius * (np.outer(np.cos(s), u) + np.outer(np.sin(s), w))
    ax.plot(pts[:, 0], pts[:, 1], pts[:, 2], color=color, lw=1.6)  # type: ignore[attr-defined]
    m = center + radius * (np.cos(angle / 2) * u + np.sin(angle / 2) * w) + shift
    ax.text(m[0], m[1], m[2], label, color=color, fontsize=9)  # type: ignore[attr-defined]


def _line(ax: object, a: np.ndarray, b: np.ndarray, **kw: object) -> None:
    ax.plot(*np.transpose([a, b]), **kw)  # type: ignore[attr-defined]


def _draw_pair(ax: object, p: LinkPair, half: float, zoom: bool) -> None:
    """Link pair ``p`` in a cube of half-width ``half`` [m] (around O_i′ when ``zoom``)."""
    from matplotlib.ticker import MaxNLocator

    i = p.i
    o, x, z = p.T[:3, 3], p.T[:3, 0], p.T[:3, 2]
    ex, ey, ez = np.eye(3)
    L, r = 0.45 * half, 0.3 * half
    c = p.o_prime if zoom else np.array([0.0, 0.0, p.d / 2 + 0.02])
    z_lo, z_hi = (c[2] - 0.9 * half, c[2] + 0.9 * half) if zoom else (-0.04, p.d + 0.09)
    _line(ax, z_lo * ez, z_hi * ez, color="tab:blue", lw=1.5)
    _line(ax, o - 0.8 * half * z, o + 0.8 * half * z, color="tab:blue", lw=1.5)
    _line(ax, o, o + L * x, color="tab:red", lw=2)
    _line(ax, p.o_prime, o, color="k", lw=2.5)  # the common normal, length a_i
    _line(ax, max(z_lo, 0.0) * ez, p.o_prime, color="tab:orange", lw=4, alpha=0.6)  # d_i
    _line(ax, p.o_prime, p.o_prime + L * ex, color="tab:red", lw=1, ls="--")
    _line(ax, o, o + L * ez, color="tab:blue", lw=1, ls="--")
    named = [(p.o_prime, f"$O'_{{{i}}}$", (-0.3, -0.3)), (o, f"$O_{{{i}}}$", (0.08, -0.3))]
    tips = [(z_hi * ez, f"$z_{{{i - 1}}}$"), (o + 0.85 * half * z, f"$z_{{{i}}}$"),
            (o + 1.15 * L * x, f"$x_{{{i}}}$")]
    if zoom:
        _arc(ax, p.o_prime, ex, ey, p.theta, r, f"ϑ{i} = {p.theta / DEG:.0f}°", "tab:purple",
             -0.45 * half * ez)
        _arc(ax, o, ez, np.cross(x, ez), p.alpha, r, f"α{i} = {p.alpha / DEG:.0f}°",
             "tab:green", 0.15 * half * (ex + ez))
        m = (p.o_prime + o) / 2 + 0.12 * half * ez
        ax.text(m[0], m[1], m[2], f"a{i} = {p.a:.5g} m", fontsize=9,  # type: ignore[attr-defined]
                ha="right")
        tips.append((p.o_prime + 1.15 * L * ex, f"$x_{{{i - 1}}}$"))
    else:
        _line(ax, np.zeros(3), L * ex, color="tab:red", lw=2)
        named = [(np.zeros(3), f"$O_{{{i - 1}}}$", (-0.15, -0.2))]
        tips.append((1.15 * L * ex, f"$x_{{{i - 1}}}$"))
        ax.text(-0.08 * half, 0.0, p.d / 2, f"d{i} = {p.d:.5g} m",  # type: ignore[attr-defined]
                fontsize=9, color="tab:orange", ha="right")
    for pt, name, (dx, dz) in named:
        ax.scatter(*pt, color="k", s=18)  # type: ignore[attr-defined]
        ax.text(pt[0] + dx * half, pt[1], pt[2] + dz * half, name,  # type: ignore[attr-defined]
                fontsize=11)
    for pt, name in tips:
        color = "tab:blue" if name.startswith("$z") else "tab:red"
        ax.text(*pt, name, color=color, fontsize=11)  # type: ignore[attr-defined]
    ax.set_xlim(c[0] - half, c[0] + half)  # type: ignore[attr-defined]
    ax.set_ylim(c[1] - half, c[1] + half)  # type: ignore[attr-defined]
    ax.set_zlim(c[2] - half, c[2] + half)  # type: ignore[attr-defined]
    ax.set_box_aspect((1, 1, 1))  # type: ignore[attr-defined]
    ax.view_init(elev=30, azim=-100)  # type: ignore[attr-defined]
    for name in "xyz":
        getattr(ax, f"set_{name}label")(f"{name}{i - 1} [m]", fontsize=8)
        getattr(ax, f"{name}axis").set_major_locator(MaxNLocator(3))
    ax.tick_params(labelsize=7)  # type: ignore[attr-defined]


def dh_pair_figure(ctx: ReportContext, robot: Robot, i: int, q_i: float) -> str:
    """The chapter's Figure 3 on link ``i`` of ``robot``: both frames and a_i, d_i, ϑ_i, α_i.

    Two panels of one figure: (a) the pair to scale, with d_i; (b) around O_i′, four times
    closer, with a_i, ϑ_i and α_i. The numbers printed are measured by :func:`link_pair`
    from the drawn frames; the table beside them gives the model's DH row.
    """
    from matplotlib.figure import Figure

    p = link_pair(robot, i, q_i)
    fig = Figure(figsize=(10.5, 5.2))
    halves = (0.15, 0.0375)  # half-widths of the two panels' cubes [m]
    for k, half in enumerate(halves):
        ax = fig.add_subplot(1, 2, k + 1, projection="3d")
        _draw_pair(ax, p, half, zoom=k == 1)
        ax.set_title("(a) to scale" if k == 0 else
                     f"(b) around O′, {halves[0] / half:g} times closer", fontsize=9)
    row = robot.dh[i - 1]
    caption = (f"Figure 3 — the Denavit-Hartenberg approach on link {i} of the {robot.name} "
               f"(DH row {i}), drawn in frame {i - 1} at q{i} = {q_i / DEG:.0f}°: z{i - 1} "
               f"and z{i} (blue), their common normal from O{i}′ to O{i} along x{i}, and "
               f"the parameters measured on the drawn frames: a{i} = {p.a:.5g} m, "
               f"d{i} = {p.d:.5g} m, α{i} = {p.alpha / DEG:.0f}°, ϑ{i} = "
               f"{p.theta / DEG:.0f}° (= q{i} + offset {row.theta / DEG:.0f}°); dashed: "
               f"x{i - 1} carried to O{i}′ and z{i - 1} carried to O{i}.")
    rows = [(f"a{i} [m]", format_number(p.a, "{:.5g}"), format_number(row.a, "{:.5g}")),
            (f"d{i} [m]", format_number(p.d, "{:.5g}"), format_number(row.d, "{:.5g}")),
            (f"α{i} [°]", format_number(p.alpha / DEG, "{:.1f}"),
             format_number(row.alpha / DEG, "{:.1f}")),
            (f"ϑ{i} [°]", format_number(p.theta / DEG, "{:.1f}"),
             format_number((row.theta + q_i) / DEG, "{:.1f}"))]
    return (ctx.figure(fig, f"fig3_dh_pair_{robot.name}", caption)
            + ctx.table(rows, ["parameter", "measured on the drawing",
                               f"DH row {i} of {robot.name} (ϑ: offset + q{i})"]))


def origin_labels(frames: np.ndarray, near: float = 0.25
                  ) -> list[tuple[str, np.ndarray, np.ndarray]]:
    """One label per distinct frame origin: (text, origin, where the text goes) [m].

    Origins equal to 0.1 mm share one label ("O4 = O5 = O6"). A label goes above its
    origin, or below and aside when an origin already labelled lies within ``near`` [m]
    (on the PUMA 560, O2 and O3 are 0.15 m apart and their labels overlapped).

    Args:
        frames: link frames, ``robot.fk_all(q)``, shape (n + 1, 4, 4).
        near: distance [m] under which two origins' labels go on opposite sides.
    """
    seen: dict[tuple[float, float, float], list[int]] = {}
    for i, T in enumerate(frames):
        seen.setdefault(tuple(float(v) for v in np.round(T[:3, 3], 4)), []).append(i)
    labels: list[tuple[str, np.ndarray, np.ndarray]] = []
    for key, idx in seen.items():
        o = np.array(key)
        close = any(np.linalg.norm(o - other) < near for _, other, _ in labels)
        shift = np.array([0.05, 0.0, -0.12]) if close else np.array([-0.02, 0.0, 0.05])
        labels.append((" = ".join(f"O{i}" for i in idx), o, o + shift))
    return labels


def puma_frames_figure(ctx: ReportContext, robot: Robot, q: np.ndarray) -> str:
    """Every DH frame of ``robot`` at ``q``; coinciding origins share one label."""
    import matplotlib.pyplot as plt

    from serialkin.viz.plot import plot_robot

    frames = robot.fk_all(q)
    fig = plt.figure(figsize=(10, 5.2))
    ax = fig.add_subplot(1, 1, 1, projection="3d")
    plot_robot(robot, q, ax=ax, frames=True, mechanism=True, linewidth=3, frame_scale=0.12)
    for text, o, at in origin_labels(frames):
        ax.text(at[0], at[1], at[2], text, fontsize=9, color="0.1")
        if at[2] < o[2]:  # a label moved below its point: a leader line to it
            _line(ax, o, at + np.array([0.0, 0.0, 0.03]), color="0.5", lw=0.7)
    ax.set_title(f"DH frames 0-{robot.n} of the PUMA 560 at q = 0, drawn from its DH table: "
                 "z_i on joint axis i+1,\nx_i along the common normal of z_(i-1) and z_i "
                 "(x red, y green, z blue)", fontsize=9)
    ax.view_init(elev=20, azim=-50)
    ax.set_box_aspect((1, 1, 1))
    return ctx.figure(fig, "forward_dh_frames_puma560",
                      "The chapter's Figure 3 applied to a whole arm, the PUMA 560: every link "
                      "frame computed by robot.fk_all(q) from the DH table below, origins O_i "
                      "labelled (coinciding origins once, as O4 = O5 = O6).")
