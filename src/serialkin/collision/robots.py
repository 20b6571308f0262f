"""Collision models of the built-in robots: capsules and spheres on their DH link frames.

**Panda and UR5** are fitted to example-robot-data's collision meshes (below). **Puma 560,
Stanford arm and iiwa 7** are envelopes built from their published dimensions (the DH
lengths, and link diameters from the manufacturers' drawings, rounded up to 5 mm): one
capsule along each link's body, spheres on wrist housings; every radius is stated in the
table of each function. **Planar arms, the chapter's 2-/3-link arms and the SCARA**
get a capsule along each link (radius 5 % of the link length for planar arms; the SCARA's
radii are given for its default size and scale with ``l1 + l2``). All models are free of
self-collision at q = 0 with the default allowed-collision matrix (adjacent frames and the
shipped allowed pairs of :mod:`serialkin.collision.allowed_pairs`).

Panda and UR5: capsules fitted by ``benchmarks/fit_capsules.py`` to the collision
shapes Pinocchio + coal check in example-robot-data 6.0 (meshes, the Panda's finger boxes,
the UR5's ``ee_link`` cube): each shape's surface, subdivided to 3 mm edges and moved into
the zoo link frame, is cut into equal slices along its axis (6 per Panda link, 4 per UR5
link) and each slice gets its bounding capsule, radius grown by 1.8 mm (a cut triangle
lies within 3 mm/√3 of its corners): every capsule set *contains* its shape. The Panda's
fingers are fitted at 21 openings 0..0.04 m, so they are covered at any opening. The
allowed pairs are the vendor SRDF's (:mod:`serialkin.collision.allowed_pairs`); the
agreement with coal is measured by ``benchmarks/bench_self_collision.py`` and tested by
``tests/collision/test_vendor_agreement.py``.

* Panda (:func:`serialkin.models.panda`, modified DH frames = the URDF's ``panda_link0..7``
  frames): bodies named as in the URDF/SRDF, hand and fingers fixed to frame 7 (the
  fingers' capsules hold them at every opening 0..0.04 m).
* UR5 (:func:`serialkin.models.ur5`, standard DH frames; the URDF's ``base_link`` is turned
  by π about z from the DH base frame 0): bodies named as in ``ur5_robot.urdf``.
"""

from __future__ import annotations

import dataclasses

import numpy as np

from serialkin.collision.allowed_pairs import ALLOWED
from serialkin.model.collision_model import CollisionModel

__all__ = ["iiwa7_collision_model", "panda_collision_model", "planar_collision_model",
           "puma560_collision_model", "scara_collision_model", "stanford_collision_model",
           "ur5_collision_model"]

SOURCE = ("bounding capsules of example-robot-data's collision meshes "
          "(benchmarks/fit_capsules.py)")

_PANDA = [  # body, frame, a, b, radius [m] (benchmarks/fit_capsules.py)
    ("panda_link0", 0, [0.0172, -0.0002, 0.1222], [0.041, 0.0008, 0.0781], 0.0596),
    ("panda_link0", 0, [0.011, -0.0001, 0.0413], [-0.0001, 0.0, 0.0811], 0.0826),
    ("panda_link0", 0, [-0.0065, 0.0559, 0.0749], [-0.0166, -0.0365, 0.0599], 0.0873),
    ("panda_link0", 0, [-0.0439, 0.0882, 0.0598], [-0.0419, -0.0642, 0.0548], 0.0698),
    ("panda_link0", 0, [-0.0833, 0.0681, 0.0386], [-0.0854, -0.0778, 0.0399], 0.0494),
    ("panda_link0", 0, [-0.1288, -0.0624, 0.0158], [-0.1309, 0.0703, 0.0159], 0.0309),
    ("panda_link1", 1, [-0.0003, -0.0333, 0.0245], [0.0002, -0.0829, 0.0062], 0.0551),
    ("panda_link1", 1, [0.0, -0.0181, -0.0016], [0.0, -0.0724, -0.0152], 0.0609),
    ("panda_link1", 1, [0.0, -0.0042, -0.0377], [0.0001, -0.0544, -0.0612], 0.0621),
    ("panda_link1", 1, [0.0068, -0.0246, -0.095], [-0.0017, -0.0213, -0.094], 0.0730),
    ("panda_link1", 1, [0.0001, -0.0074, -0.138], [-0.003, -0.0085, -0.1387], 0.0701),
    ("panda_link1", 1, [0.0002, -0.0036, -0.1779], [-0.0003, 0.0089, -0.1757], 0.0588),
    ("panda_link2", 2, [0.0002, -0.179, 0.0034], [-0.0008, -0.1765, -0.0075], 0.0593),
    ("panda_link2", 2, [0.0001, -0.1479, 0.0198], [-0.0, -0.1348, -0.0037], 0.0618),
    ("panda_link2", 2, [0.0, -0.0935, 0.0217], [-0.0043, -0.0951, 0.024], 0.0730),
    ("panda_link2", 2, [0.0001, -0.0395, 0.0035], [0.0001, -0.0615, 0.0546], 0.0621),
    ("panda_link2", 2, [-0.0001, -0.0024, 0.0171], [-0.0, -0.0161, 0.0732], 0.0608),
    ("panda_link2", 2, [-0.0001, 0.0241, 0.0305], [0.0004, 0.0054, 0.0831], 0.0549),
    ("panda_link3", 3, [0.0891, 0.071, 0.0065], [0.1009, 0.0278, 0.0175], 0.0529),
    ("panda_link3", 3, [0.0809, 0.013, -0.0017], [0.0719, 0.0607, -0.0109], 0.0599),
    ("panda_link3", 3, [0.0547, 0.0243, -0.0274], [0.0552, 0.03, -0.0335], 0.0710),
    ("panda_link3", 3, [0.0155, 0.0166, -0.0448], [0.0389, 0.0206, -0.0722], 0.0643),
    ("panda_link3", 3, [0.0033, 0.0022, -0.0693], [0.0128, 0.0072, -0.1018], 0.0620),
    ("panda_link3", 3, [-0.0034, -0.0547, -0.0938], [-0.0391, 0.0212, -0.0947], 0.0410),
    ("panda_link4", 4, [0.0063, -0.0067, 0.0707], [0.0172, -0.0183, 0.0273], 0.0529),
    ("panda_link4", 4, [-0.0117, 0.0113, 0.0605], [-0.0022, 0.0021, 0.013], 0.0603),
    ("panda_link4", 4, [-0.0278, 0.0281, 0.0214], [-0.0295, 0.037, 0.0311], 0.0702),
    ("panda_link4", 4, [-0.0701, 0.0475, 0.0163], [-0.0435, 0.0709, 0.0201], 0.0646),
    ("panda_link4", 4, [-0.0831, 0.0768, 0.0077], [-0.0775, 0.0824, 0.0008], 0.0692),
    ("panda_link4", 4, [-0.0846, 0.0979, -0.0488], [-0.1296, 0.0971, 0.032], 0.0415),
    ("panda_link5", 5, [0.0, -0.0031, -0.2377], [-0.0001, 0.0126, -0.2384], 0.0609),
    ("panda_link5", 5, [0.0006, 0.0367, -0.195], [-0.0001, 0.0083, -0.1855], 0.0630),
    ("panda_link5", 5, [-0.0001, 0.0509, -0.1396], [0.0, 0.0148, -0.1301], 0.0618),
    ("panda_link5", 5, [-0.0001, 0.0703, -0.0861], [0.0, 0.0226, -0.0746], 0.0609),
    ("panda_link5", 5, [0.0, 0.0846, -0.0309], [0.0001, 0.0328, -0.0199], 0.0606),
    ("panda_link5", 5, [0.0, 0.1022, 0.0007], [-0.0, 0.0376, 0.0087], 0.0529),
    ("panda_link6", 6, [0.1048, -0.0396, -0.0017], [0.0994, 0.0474, -0.0011], 0.0435),
    ("panda_link6", 6, [0.0871, -0.0403, 0.0012], [0.0866, 0.0495, 0.0032], 0.0486),
    ("panda_link6", 6, [0.0593, -0.0386, 0.0053], [0.0556, 0.0467, 0.0095], 0.0507),
    ("panda_link6", 6, [0.0301, -0.0358, 0.0109], [0.0278, 0.036, 0.0122], 0.0484),
    ("panda_link6", 6, [0.0034, -0.0303, 0.0154], [0.004, 0.0257, 0.0142], 0.0452),
    ("panda_link6", 6, [-0.019, -0.0008, 0.0084], [-0.019, -0.0008, 0.0084], 0.0503),
    ("panda_link7", 7, [0.0653, 0.0348, 0.0843], [0.0345, 0.0659, 0.0842], 0.0198),
    ("panda_link7", 7, [0.0464, 0.0184, 0.0798], [0.0173, 0.0474, 0.0799], 0.0282),
    ("panda_link7", 7, [0.0034, 0.0389, 0.0797], [0.034, 0.0043, 0.0785], 0.0332),
    ("panda_link7", 7, [0.0264, -0.017, 0.0794], [-0.019, 0.0269, 0.0794], 0.0337),
    ("panda_link7", 7, [0.011, -0.0324, 0.0777], [-0.0406, 0.0173, 0.0802], 0.0335),
    ("panda_link7", 7, [-0.0201, -0.0202, 0.0705], [-0.0201, -0.0202, 0.0705], 0.0415),
    ("panda_hand", 7, [0.0552, 0.0552, 0.1054], [0.0561, 0.0562, 0.1547], 0.0294),
    ("panda_hand", 7, [0.0361, 0.0358, 0.1052], [0.0322, 0.0353, 0.1508], 0.0347),
    ("panda_hand", 7, [0.0112, 0.0112, 0.1062], [0.0084, 0.0093, 0.1457], 0.0368),
    ("panda_hand", 7, [-0.0089, -0.0089, 0.1099], [-0.016, -0.0158, 0.1473], 0.0358),
    ("panda_hand", 7, [-0.0331, -0.0325, 0.1027], [-0.0382, -0.0391, 0.1557], 0.0318),
    ("panda_hand", 7, [-0.057, -0.0571, 0.1011], [-0.0585, -0.0586, 0.1577], 0.0252),
    ("panda_leftfinger", 7, [0.0462, 0.0462, 0.1721], [0.0182, 0.0182, 0.1677], 0.0143),
    ("panda_leftfinger", 7, [0.0438, 0.0438, 0.183], [0.0054, 0.0054, 0.1683], 0.0143),
    ("panda_leftfinger", 7, [0.0377, 0.0377, 0.1911], [0.0087, 0.0087, 0.1812], 0.0141),
    ("panda_leftfinger", 7, [0.0387, 0.0387, 0.205], [0.0091, 0.0091, 0.1937], 0.0124),
    ("panda_leftfinger", 7, [0.036, 0.036, 0.2159], [0.0037, 0.0037, 0.2036], 0.0124),
    ("panda_leftfinger", 7, [0.0256, 0.0256, 0.2189], [-0.0005, -0.0005, 0.214], 0.0123),
    ("panda_rightfinger", 7, [-0.0182, -0.0182, 0.1677], [-0.0462, -0.0462, 0.1721], 0.0143),
    ("panda_rightfinger", 7, [-0.0054, -0.0054, 0.1683], [-0.0438, -0.0438, 0.1831], 0.0143),
    ("panda_rightfinger", 7, [-0.0087, -0.0087, 0.1812], [-0.0377, -0.0377, 0.1911], 0.0141),
    ("panda_rightfinger", 7, [-0.0091, -0.0091, 0.1937], [-0.0387, -0.0387, 0.205], 0.0124),
    ("panda_rightfinger", 7, [-0.0037, -0.0037, 0.2036], [-0.036, -0.036, 0.2159], 0.0124),
    ("panda_rightfinger", 7, [0.0005, 0.0005, 0.214], [-0.0256, -0.0256, 0.2189], 0.0123),
]

_UR5 = [
    ("base_link", 0, [0.0271, 0.0874, 0.0066], [-0.0296, 0.0856, 0.0047], 0.0259),
    ("base_link", 0, [0.0566, 0.0412, 0.0063], [-0.0616, 0.0393, 0.0083], 0.0281),
    ("base_link", 0, [0.0652, -0.003, 0.009], [-0.065, -0.0065, 0.009], 0.0279),
    ("base_link", 0, [0.0549, -0.0477, 0.0051], [-0.0544, -0.0509, 0.0066], 0.0284),
    ("shoulder_link", 1, [0.0519, 0.0292, 0.036], [-0.0469, 0.0288, 0.0364], 0.0495),
    ("shoulder_link", 1, [0.0, 0.0305, -0.0041], [0.0001, -0.0005, 0.0463], 0.0648),
    ("shoulder_link", 1, [-0.0001, 0.0099, -0.011], [-0.0001, -0.0482, 0.0095], 0.0618),
    ("shoulder_link", 1, [0.0522, -0.0356, -0.0268], [-0.0442, -0.0359, -0.0244], 0.0460),
    ("upper_arm_link", 2, [0.4222, 0.0003, 0.1265], [0.4095, -0.0001, 0.1356], 0.0850),
    ("upper_arm_link", 2, [0.3488, -0.0003, 0.136], [0.2363, -0.0, 0.1359], 0.0577),
    ("upper_arm_link", 2, [0.1871, -0.0005, 0.1362], [0.0761, 0.0001, 0.1358], 0.0580),
    ("upper_arm_link", 2, [0.017, 0.0002, 0.1349], [-0.0004, -0.0001, 0.1284], 0.0843),
    ("forearm_link", 3, [0.3638, -0.0045, 0.027], [0.393, -0.0002, 0.0587], 0.0616),
    ("forearm_link", 3, [0.3321, 0.0001, 0.0161], [0.2198, -0.0, 0.0169], 0.0417),
    ("forearm_link", 3, [0.2029, 0.0, 0.016], [0.086, 0.0, 0.0165], 0.0399),
    ("forearm_link", 3, [0.0341, -0.0002, 0.0116], [-0.0009, 0.0001, 0.0145], 0.0638),
    ("wrist_1_link", 4, [-0.0, 0.0008, -0.041], [-0.0004, -0.0229, -0.0313], 0.0398),
    ("wrist_1_link", 4, [-0.0, 0.0037, -0.0221], [0.0002, -0.0323, -0.0032], 0.0421),
    ("wrist_1_link", 4, [0.0001, 0.0075, 0.0106], [0.0, -0.0291, 0.013], 0.0422),
    ("wrist_1_link", 4, [0.0001, -0.0072, 0.0393], [-0.0002, 0.0032, 0.0358], 0.0408),
    ("wrist_2_link", 5, [0.0003, -0.0039, 0.0361], [-0.0001, 0.0003, 0.039], 0.0406),
    ("wrist_2_link", 5, [-0.0002, -0.0072, 0.0106], [0.0005, 0.0259, 0.0153], 0.0428),
    ("wrist_2_link", 5, [-0.0001, -0.0033, -0.023], [-0.0001, 0.0311, -0.001], 0.0422),
    ("wrist_2_link", 5, [-0.0006, 0.0244, -0.0331], [-0.0001, -0.0006, -0.0415], 0.0398),
    ("wrist_3_link", 6, [0.0358, 0.0205, -0.0176], [-0.0154, 0.0284, -0.0194], 0.0220),
    ("wrist_3_link", 6, [0.0328, 0.0002, -0.0176], [-0.0291, 0.0143, -0.0179], 0.0220),
    ("wrist_3_link", 6, [0.0301, -0.0203, -0.0177], [-0.0335, -0.0047, -0.0178], 0.0221),
    ("wrist_3_link", 6, [0.0129, -0.0301, -0.019], [-0.0318, -0.0239, -0.0179], 0.0207),
    ("ee_link", 6, [-0.0037, -0.005, -0.01], [-0.0038, 0.005, -0.01], 0.0070),
    ("ee_link", 6, [-0.0012, 0.0, -0.01], [-0.0012, 0.0, -0.01], 0.0091),
    ("ee_link", 6, [0.0013, 0.0, -0.01], [0.0013, 0.0, -0.01], 0.0091),
    ("ee_link", 6, [0.0037, -0.005, -0.01], [0.0038, 0.005, -0.01], 0.0070),
]


def _build(rows, name: str, source: str = SOURCE, allowed=None) -> CollisionModel:
    bodies: dict[str, dict] = {}
    for b, f, a, e, r in rows:  # a body may have several rows (capsules)
        bodies.setdefault(b, {"name": b, "frame": f, "capsules": []})["capsules"].append(
            {"a": a, "b": e, "radius": r})
    model = CollisionModel.from_dicts(list(bodies.values()), source=f"{name}: {source}")
    pairs = ALLOWED.get(name, ()) if allowed is None else allowed
    return dataclasses.replace(model, allowed=tuple(pairs))


def panda_collision_model() -> CollisionModel:
    """Collision capsules of the Franka Emika Panda (11 bodies on frames 0..7, see module).

    Allowed pairs: the vendor SRDF's (:mod:`serialkin.collision.allowed_pairs`).
    """
    return _build(_PANDA, "panda")


def ur5_collision_model() -> CollisionModel:
    """Collision capsules of the Universal Robots UR5 (8 bodies on frames 0..6, see module).

    ``ee_link`` is the URDF's 1 cm cube at the flange, which coal checks against the
    forearm; allowed pairs: the vendor SRDF's (:mod:`serialkin.collision.allowed_pairs`).
    """
    return _build(_UR5, "ur5")


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
