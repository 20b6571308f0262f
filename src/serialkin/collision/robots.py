"""Collision models of the built-in robots: capsules and spheres on their DH link frames.

**Panda and UR5** are fitted to example-robot-data's collision meshes (below). **Puma 560,
Stanford arm and iiwa 7** are envelopes built from their published dimensions (the DH
lengths, and link diameters from the manufacturers' drawings, rounded up to 5 mm): one
capsule along each link's body, spheres on wrist housings; every radius is stated in the
table of each function. **Planar arms, the chapter's 2-/3-link arms and the SCARA**
get a capsule along each link (radius 5 % of the link length for planar arms; the SCARA's
radii are given for its default size and scale with ``l1 + l2``). All models are free of
self-collision at q = 0 with the default allowed-collision matrix (adjacent frames allowed).

Panda and UR5: each body is the bounding capsule of its URDF collision geometry (STL
meshes, or boxes for the Panda's fingers), fitted by :mod:`serialkin.collision.fit`
(``merge=True``: one point cloud per link) and moved into the link frame of
:mod:`serialkin.models` (the fixed transform was checked to be the same at several
configurations, which proves the frame correspondence): every capsule *contains* its
mesh. One capsule per link is ×1.4-2.4 the mesh volume (×3.9 for the fingers, ×6.7 for
the UR5's flat base plate); a split into two capsules saved less than the required 20 %
everywhere, so every body has one. Reproduce with ``benchmarks/fit_capsules.py``
(example-robot-data 4.x, the ``bench`` extra; trimesh, the ``mesh`` extra); ends rounded
to 0.1 mm, radii rounded up and grown by 0.1 mm so that the rounded capsule still
contains the mesh.

Volumes [litre], mesh → capsule (largest gap capsule ↔ hull [mm]): Panda link0 3.00 →
7.08 (81), link1 2.98 → 4.64 (27), link2 3.00 → 4.71 (28), link3 2.33 → 3.26 (26), link4
2.37 → 3.31 (29), link5 3.42 → 4.87 (48), link6 1.43 → 2.93 (40), link7 0.45 → 0.92 (27),
hand 0.71 → 1.59 (34), each finger 0.016 → 0.06 (16); UR5 base 0.35 → 2.34 (63),
shoulder 1.55 → 2.64 (26), upper arm 5.36 → 12.18 (35), forearm 2.49 → 6.18 (37), wrists
0.51 → 0.95 (19), 0.51 → 0.95 (19), 0.14 → 0.29 (25).

* Panda (:func:`serialkin.models.panda`, modified DH frames = the URDF's ``panda_link0..7``
  frames): bodies named as in the URDF/SRDF, hand and fingers fixed to frame 7 with the
  fingers fully open (finger joints at 0.04 m).
* UR5 (:func:`serialkin.models.ur5`, standard DH frames; the URDF's ``base_link`` is turned
  by π about z from the DH base frame 0): bodies named as in ``ur5_robot.urdf``.
"""

from __future__ import annotations

import dataclasses

import numpy as np

from serialkin.model.collision_model import CollisionModel

__all__ = ["iiwa7_collision_model", "panda_collision_model", "planar_collision_model",
           "puma560_collision_model", "scara_collision_model", "stanford_collision_model",
           "ur5_collision_model"]

SOURCE = ("bounding capsules of example-robot-data's collision meshes "
          "(benchmarks/fit_capsules.py)")

_PANDA = [  # body, frame, a, b, radius [m]
    ("panda_link0", 0, [0.0, -0.0, 0.0507], [-0.0572, -0.0001, 0.0209], 0.1051),
    ("panda_link1", 1, [0.0, -0.0002, -0.1402], [0.0, -0.0548, 0.0059], 0.0760),
    ("panda_link2", 2, [-0.0003, 0.0078, 0.0556], [0.0001, -0.1424, 0.0002], 0.0759),
    ("panda_link3", 3, [0.0843, 0.0433, 0.0018], [0.0003, 0.0002, -0.0799], 0.0693),
    ("panda_link4", 4, [0.0019, -0.0018, 0.0434], [-0.0809, 0.0844, 0.0004], 0.0694),
    ("panda_link5", 5, [-0.0, 0.0639, 0.003], [0.0002, 0.0104, -0.2438], 0.0674),
    ("panda_link6", 6, [0.0886, 0.0086, -0.0003], [0.0201, 0.0119, 0.0048], 0.0746),
    ("panda_link7", 7, [0.0329, 0.033, 0.0808], [-0.0051, -0.0051, 0.0733], 0.0494),
    ("panda_hand", 7, [0.0433, 0.0434, 0.1383], [-0.0624, -0.0624, 0.1263], 0.0486),
    ("panda_leftfinger", 7, [0.0364, 0.0364, 0.2114], [0.0388, 0.0388, 0.1667], 0.0169),
    ("panda_rightfinger", 7, [-0.0364, -0.0364, 0.2114], [-0.0388, -0.0388, 0.1667], 0.0169),
]

_UR5 = [
    ("base_link", 0, [-0.0, 0.001, 0.006], [0.001, -0.0363, 0.0064], 0.0742),
    ("shoulder_link", 1, [0.0007, -0.0111, 0.0034], [-0.0, -0.0, 0.0123], 0.0824),
    ("upper_arm_link", 2, [0.4252, 0.0003, 0.131], [-0.0106, -0.0003, 0.1317], 0.0843),
    ("forearm_link", 3, [0.3994, -0.0006, 0.0445], [0.0031, -0.0019, 0.0152], 0.0640),
    ("wrist_1_link", 4, [-0.0011, -0.0037, -0.0102], [-0.0002, -0.0054, 0.0116], 0.0561),
    ("wrist_2_link", 5, [0.0011, 0.0053, 0.0112], [0.0005, 0.0035, -0.0091], 0.0565),
    ("wrist_3_link", 6, [-0.0001, 0.0004, -0.0212], [0.0006, -0.0033, -0.0212], 0.0401),
]


def _build(rows, name: str, source: str = SOURCE, allowed=()) -> CollisionModel:
    model = CollisionModel.from_dicts(
        [{"name": b, "frame": f, "capsules": [{"a": a, "b": e, "radius": r}]}
         for b, f, a, e, r in rows], source=f"{name}: {source}")
    return dataclasses.replace(model, allowed=tuple(allowed))


def panda_collision_model() -> CollisionModel:
    """Collision capsules of the Franka Emika Panda (11 bodies on frames 0..7, see module)."""
    return _build(_PANDA, "panda")


def ur5_collision_model() -> CollisionModel:
    """Collision capsules of the Universal Robots UR5 (7 bodies on frames 0..6, see module).

    ``base_link`` and ``upper_arm_link`` are an allowed pair: their capsules overlap at the
    shoulder in every one of 5,000 sampled configurations (``sampled_acm``, seed 0), as
    MoveIt's setup assistant would disable an "always in collision" pair.
    """
    return _build(_UR5, "UR5", allowed=[("base_link", "upper_arm_link")])


ENVELOPE = "envelope from published dimensions (serialkin.collision.robots)"

# Puma 560 (standard DH, frames of serialkin.models.puma560): frame 1 at the shoulder with
# y1 up, frame 2 at the elbow (upper arm along -x2), forearm along z3 (0.4318 m to the wrist
# centre, offset 0.15005 m along the shoulder axis), frames 4-6 at the wrist centre.
_PUMA560 = [
    ("pedestal", 0, [0, 0, 0.0], [0, 0, 0.38], 0.12),
    ("trunk", 1, [0, -0.20, 0], [0, 0, 0], 0.11),
    ("upper_arm", 2, [-0.4318, 0, 0], [0, 0, 0], 0.08),
    ("forearm", 3, [0, 0, -0.05], [0, 0, 0.33], 0.055),
    ("wrist", 5, [0, 0, 0], [0, 0, 0], 0.05),
    ("flange", 6, [0, 0, 0.02], [0, 0, 0.056], 0.035),
]

# Stanford arm (standard DH): frame 1 at the shoulder (up is -y1), frame 2 on the boom's
# guide 0.154 m aside, the boom slides along z3 and ends at the wrist centre (frame 3
# origin; stroke 0.305-1.27 m, the boom is 0.6 m long), the hand reaches 0.263 m along z6.
_STANFORD = [
    ("base", 0, [0, 0, 0], [0, 0, 0.12], 0.15),
    ("column", 1, [0, 0.22, 0], [0, 0, 0], 0.08),
    ("guide", 2, [0, 0, -0.06], [0, 0, 0.06], 0.09),
    ("boom", 3, [0, 0, -0.60], [0, 0, -0.06], 0.045),
    ("wrist", 5, [0, 0, 0], [0, 0, 0], 0.055),
    ("hand", 6, [0, 0, -0.19], [0, 0, -0.03], 0.045),
]

# KUKA LBR iiwa 7 R800 (standard DH, Faria et al. frames): shoulder frames 1-2 at 0.34 m
# (down is +y1), elbow frames 3-4 0.4 m further (shoulder towards -y3), wrist frames 5-6
# 0.4 m further (elbow towards +y5), flange frame 7 0.126 m along z6. Link diameters about
# 0.12-0.14 m (KUKA data sheet drawing).
_IIWA7 = [
    ("link0", 0, [0, 0, 0.0], [0, 0, 0.10], 0.10),
    ("link1", 1, [0, 0.12, 0], [0, 0, 0], 0.075),
    ("link2", 2, [0, 0, 0], [0, 0, 0.18], 0.07),
    ("link3", 3, [0, -0.20, 0], [0, 0, 0], 0.07),
    ("link4", 4, [0, 0, 0], [0, 0, 0.19], 0.065),
    ("link5", 5, [0, 0.21, 0], [0, 0.09, 0], 0.065),
    ("link6", 6, [0, 0, -0.01], [0, 0, 0.05], 0.07),
    ("link7", 7, [0, 0, -0.045], [0, 0, -0.015], 0.045),
]


def puma560_collision_model() -> CollisionModel:
    """Capsules of the Unimation PUMA 560 (6 bodies on frames 0..6, envelope, see module).

    ==========  =====  ==========================  ==========
    body        frame  axis (frame coordinates)    radius [m]
    ==========  =====  ==========================  ==========
    pedestal    0      z 0 .. 0.38                 0.12
    trunk       1      y -0.20 .. 0                0.11
    upper_arm   2      x -0.4318 .. 0              0.08
    forearm     3      z -0.05 .. 0.33             0.055
    wrist       5      sphere at the origin        0.05
    flange      6      z 0.02 .. 0.056             0.035
    ==========  =====  ==========================  ==========
    """
    return _build(_PUMA560, "puma560", ENVELOPE)


def stanford_collision_model() -> CollisionModel:
    """Capsules of the Stanford arm (6 bodies, envelope; the boom moves with q3).

    ======  =====  ==========================  ==========
    body    frame  axis (frame coordinates)    radius [m]
    ======  =====  ==========================  ==========
    base    0      z 0 .. 0.12                 0.15
    column  1      y 0.22 .. 0                 0.08
    guide   2      z -0.06 .. 0.06             0.09
    boom    3      z -0.60 .. -0.06            0.045
    wrist   5      sphere at the origin        0.055
    hand    6      z -0.19 .. -0.03            0.045
    ======  =====  ==========================  ==========
    """
    return _build(_STANFORD, "stanford", ENVELOPE)


def iiwa7_collision_model() -> CollisionModel:
    """Capsules of the KUKA LBR iiwa 7 R800 (8 bodies on frames 0..7, envelope).

    =====  =====  ==========================  ==========
    body   frame  axis (frame coordinates)    radius [m]
    =====  =====  ==========================  ==========
    link0  0      z 0 .. 0.10                 0.10
    link1  1      y 0.12 .. 0                 0.075
    link2  2      z 0 .. 0.18                 0.07
    link3  3      y -0.20 .. 0                0.07
    link4  4      z 0 .. 0.19                 0.065
    link5  5      y 0.21 .. 0.09              0.065
    link6  6      z -0.01 .. 0.05             0.07
    link7  7      z -0.045 .. -0.015          0.045
    =====  =====  ==========================  ==========
    """
    return _build(_IIWA7, "iiwa7", ENVELOPE)


#: Radius of a planar arm's link capsule as a fraction of the link length.
PLANAR_RADIUS = 0.05


def planar_collision_model(lengths: object) -> CollisionModel:
    """One capsule per link of a planar arm (standard DH rows ``(L_i, 0, 0, q_i)``).

    Link ``i`` runs from the origin of frame ``i−1`` to that of frame ``i``: in frame ``i``
    the segment ``(−L_i, 0, 0) .. (0, 0, 0)``, radius ``0.05 L_i``
    (:data:`PLANAR_RADIUS`); bodies ``link1 .. linkn`` on frames 1..n.
    """
    L = np.asarray(lengths, dtype=float).reshape(-1)
    n = L.shape[0]
    a = np.zeros((n, 3))
    a[:, 0] = -L
    return CollisionModel(tuple(f"link{i + 1}" for i in range(n)),
                          np.arange(1, n + 1, dtype=np.int64), np.arange(n, dtype=np.int64),
                          a, np.zeros((n, 3)), PLANAR_RADIUS * L,
                          source=f"planar arm: capsules along the links, radius "
                                 f"{PLANAR_RADIUS:g} x length")


def scara_collision_model(d1: float = 0.4, d2: float = 0.1, l1: float = 0.35,
                          l2: float = 0.30, q3_range: tuple[float, float] = (-0.3, 0.0)
                          ) -> CollisionModel:
    """Capsules of the chapter's SCARA (:func:`serialkin.models.scara`, standard DH).

    Radii for the default size (l1 + l2 = 0.65 m), scaled by ``(l1 + l2) / 0.65``:

    =======  =====  ======================================  ==========
    body     frame  axis (frame coordinates)                radius [m]
    =======  =====  ======================================  ==========
    column   0      z 0 .. d1 − 0.1                         0.08
    arm1     1      x −l1 .. 0                              0.04
    arm2     2      x −l2 .. 0                              0.03
    quill    3      z 0 .. −stroke (z3 points down)         0.015
    =======  =====  ======================================  ==========
    """
    s = (l1 + l2) / 0.65
    stroke = float(q3_range[1] - q3_range[0])
    rows = [("column", 0, [0, 0, 0], [0, 0, max(d1 - 0.1 * s, 0.0)], 0.08 * s),
            ("arm1", 1, [-l1, 0, 0], [0, 0, 0], 0.04 * s),
            ("arm2", 2, [-l2, 0, 0], [0, 0, 0], 0.03 * s),
            ("quill", 3, [0, 0, 0], [0, 0, -stroke], 0.015 * s)]
    return _build(rows, "scara", ENVELOPE)
