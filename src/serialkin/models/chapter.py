"""The chapter's own example mechanisms: the SCARA of Table 1 and the arms of Figures 5-7.

The chapter gives the SCARA's structure (Table 1, eqs 13-18) but no numbers, and shows
the 2- and 3-link arms (Figures 5-7) without link lengths. The default values below are
illustrative (a small assembly SCARA, unit-length planar links); every one of them is a
parameter.
"""

from __future__ import annotations

import math

from serialkin._checks import check_positive
from serialkin.model.dh import DHLink
from serialkin.model.robot import Robot
from serialkin.models.planar import planar

SCARA_SOURCE = (
    "chapter Table 1 and eqs 13-18 (standard DH, RRPR); default d1, d2, L1, L2 illustrative"
)


def scara(
    d1: float = 0.4,
    d2: float = 0.1,
    l1: float = 0.35,
    l2: float = 0.30,
    *,
    q3_range: tuple[float, float] = (-0.3, 0.0),
) -> Robot:
    """Build the chapter's SCARA robot (RRPR), standard DH as in Table 1.

    ====  =====  ======  ===========  ======
    Link  a_i    α_i     d_i          θ_i
    ====  =====  ======  ===========  ======
    1     L1     0       d1           q1
    2     L2     0       0            q2
    3     0      π       d2 + q3      0
    4     0      0       0            q4
    ====  =====  ======  ===========  ======

    so ``0T4 = 0A1 · 1A2 · 2A3 · 3A4`` (eq 17 as corrected in the ERRATA) with the link
    matrices of eqs 13-16. Joint 3 is prismatic: its variable q3 adds to the constant d2
    along z2 (pointing up; α3 = π turns z3 downwards for the tool).

    Args:
        d1: height of the first link above the base [m].
        d2: constant part of the prismatic offset d3 = d2 + q3 [m].
        l1: length L1 of the first arm link [m].
        l2: length L2 of the second arm link [m].
        q3_range: (lower, upper) stroke of the prismatic joint [m].

    Returns:
        A 4-joint standard-DH :class:`~serialkin.model.robot.Robot` named ``scara``, with
        capsules on its column, arms and quill
        (:func:`~serialkin.collision.robots.scara_collision_model`).

    Raises:
        InputError: a negative length.
    """
    l1 = check_positive(l1, "l1", allow_zero=True)
    l2 = check_positive(l2, "l2", allow_zero=True)
    deg = math.pi / 180.0
    rows = [
        DHLink(a=l1, alpha=0.0, d=float(d1), theta=0.0, type="R",
               qlim=(-150 * deg, 150 * deg), name="q1"),
        DHLink(a=l2, alpha=0.0, d=0.0, theta=0.0, type="R",
               qlim=(-145 * deg, 145 * deg), name="q2"),
        DHLink(a=0.0, alpha=math.pi, d=float(d2), theta=0.0, type="P",
               qlim=tuple(q3_range), name="q3"),
        DHLink(a=0.0, alpha=0.0, d=0.0, theta=0.0, type="R",
               qlim=(-2 * math.pi, 2 * math.pi), name="q4"),
    ]
    from serialkin.collision.robots import scara_collision_model

    robot = Robot.from_dh(rows, "standard", name="scara", source=SCARA_SOURCE)
    return robot.with_collision(scara_collision_model(
        float(d1), float(d2), l1, l2, (float(q3_range[0]), float(q3_range[1]))))


def two_link(l1: float = 1.0, l2: float = 1.0) -> Robot:
    """Build the planar two-link arm of Figures 5 and 7 (eqs 21-27, 37-38), unlimited joints.

    Args:
        l1: length L1 [m].
        l2: length L2 [m].
    """
    return planar(2, [l1, l2], name="two_link")


def three_link(l1: float = 1.0, l2: float = 1.0, l3: float = 1.0) -> Robot:
    """Build the planar three-link arm of Figure 6 (eqs 30-32), unlimited joints.

    Args:
        l1: length L1 [m].
        l2: length L2 [m].
        l3: length L3 [m].
    """
    return planar(3, [l1, l2, l3], name="three_link")
