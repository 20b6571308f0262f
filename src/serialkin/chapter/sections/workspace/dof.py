"""Section 1 (workspace): DOF, joint space and task space of every built-in robot."""

from __future__ import annotations

import math

import numpy as np

from serialkin import models
from serialkin.chapter._context import ReportContext
from serialkin.chapter.sections.workspace._common import SEED


def _limits_text(robot: object) -> str:
    parts = []
    for (lo, hi), t in zip(robot.qlim, robot.joint_types):  # type: ignore[attr-defined]
        if not (np.isfinite(lo) and np.isfinite(hi)):
            parts.append("ℝ" if t == "P" else "S¹")
        elif t == "R":
            parts.append(f"[{math.degrees(lo):.0f}°, {math.degrees(hi):.0f}°]")
        else:
            parts.append(f"[{lo:.3g}, {hi:.3g}] m")
    return " × ".join(parts)


def _dof_table(ctx: ReportContext) -> tuple[str, dict[str, tuple[int, int]]]:
    """The table of every built-in robot, and {name: (n, m)}."""
    rows = []
    for info in models.catalog():
        r = info.build() if info.dof is not None else info.build(6, 0.1)
        planar = bool(r.is_planar)
        # generic rank of J: the dimension of the task space the tool can move in
        J = r.jacobian(r.random_q(8, seed=SEED))
        m = int(max(np.linalg.matrix_rank(Jk, tol=1e-9) for Jk in J))
        rows.append((r.name, r.n, "".join(r.joint_types), _limits_text(r),
                     "planar (x, y, φ)" if planar else "spatial (x, y, z, 3 rotations)", m,
                     r.n - m))
    return ctx.table(rows, ["robot", "DOF n", "joints", "joint space Q",
                            "task space", "m = rank J", "redundancy n − m"]), {
        row[0]: (row[1], row[5]) for row in rows}


def dof_part(ctx: ReportContext) -> str:
    """DOF, joint space and task space of every built-in robot (table and reproduction)."""
    table, nm = _dof_table(ctx)
    return (
        "<h3>Degrees of freedom, joint space and task space</h3>"
        "<p>The number of DOF is the dimension of the joint space Q (one coordinate per "
        "joint); the task space of a planar arm has m = 3 coordinates (x, y, φ), that of a "
        "spatial arm m = 6; the table gives the generic rank of the Jacobian, the number "
        f"of task coordinates the tool can actually move in ({nm['two_link'][1]} for the "
        f"2-link arm, {nm['scara'][1]} for the SCARA: x, y, z and the yaw). A robot with "
        "n &gt; m is kinematically redundant "
        "(section 5.3). S¹ is an unlimited revolute joint.</p>" + table
        + ctx.reproduce(
            "import numpy as np\n"
            "from serialkin import models\n"
            "r = models.scara(); J = r.jacobian(r.random_q(8, seed=2024))\n"
            "print(r.n, max(np.linalg.matrix_rank(Jk, tol=1e-9) for Jk in J))  # n, m",
            expect=[str(v) for v in nm["scara"]])
    )
