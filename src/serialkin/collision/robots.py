"""Collision models of built-in robots, fitted to example-robot-data's collision meshes.

Each body is one bounding capsule of its URDF collision geometry (STL mesh, or boxes for
the Panda's fingers), moved into the link frame of :mod:`serialkin.models` (the fixed
transform was checked to be the same at several configurations, which proves the frame
correspondence). Axis along the principal direction of the vertices, radius the largest
distance of a vertex from the axis, ends pulled in as far as every vertex stays inside:
every capsule *contains* its mesh. One capsule per mesh is loose, about ×2.2-2.8 the
mesh volume (×7 for the UR5's flat base); the fit script also tries two capsules per mesh
(hull cut across its principal axis) but none saved 20 % of the volume (at best 13 %, on
panda_link1 and link2), so every body has one. Reproduce with
``benchmarks/fit_capsules.py`` (example-robot-data 4.x, the ``bench`` extra); numbers
rounded to 0.1 mm.

Volumes [litre], mesh → capsule: Panda link0 3.00 → 8.46, link1 2.98 → 7.29, link2
3.00 → 7.11, link3 2.33 → 5.21, link4 2.37 → 5.30, link5 3.42 → 7.76, link6 1.43 → 3.34,
link7 0.45 → 0.97, hand 0.71 → 1.68, each finger 0.016 → 0.06 (boxes); UR5 base 0.35 →
2.41, shoulder 1.55 → 2.89, upper arm 5.36 → 13.29, forearm 2.49 → 6.85, wrists 0.51 →
0.95, 0.51 → 0.97, 0.14 → 0.32.

* Panda (:func:`serialkin.models.panda`, modified DH frames = the URDF's ``panda_link0..7``
  frames): bodies named as in the URDF/SRDF, hand and fingers fixed to frame 7 with the
  fingers fully open (finger joints at 0.04 m).
* UR5 (:func:`serialkin.models.ur5`, standard DH frames; the URDF's ``base_link`` is turned
  by π about z from the DH base frame 0): bodies named as in ``ur5_robot.urdf``.
"""

from __future__ import annotations

from serialkin.collision.model import CollisionModel

__all__ = ["panda_collision_model", "ur5_collision_model"]

SOURCE = ("bounding capsules of example-robot-data's collision meshes "
          "(benchmarks/fit_capsules.py)")

_PANDA = [  # body, frame, a, b, radius [m]
    ("panda_link0", 0, [-0.0216, 0.0079, 0.0543], [-0.0529, 0.0086, 0.0384], 0.1182),
    ("panda_link1", 1, [-0.0012, 0.0114, -0.1294], [0.0035, -0.0728, 0.0016], 0.0914),
    ("panda_link2", 2, [-0.001, 0.0031, 0.0721], [0.0003, -0.138, -0.0143], 0.0892),
    ("panda_link3", 3, [0.0843, 0.0517, -0.0147], [0.0135, -0.003, -0.0685], 0.0868),
    ("panda_link4", 4, [0.0023, 0.0142, 0.0526], [-0.0696, 0.0705, -0.0036], 0.0870),
    ("panda_link5", 5, [0.0051, 0.0836, -0.0035], [0.0013, -0.0041, -0.1959], 0.0869),
    ("panda_link6", 6, [0.0215, -0.0107, 0.0144], [0.0881, 0.0127, -0.0005], 0.0778),
    ("panda_link7", 7, [-0.0022, -0.0023, 0.079], [0.0306, 0.0322, 0.081], 0.0516),
    ("panda_hand", 7, [0.0525, 0.0521, 0.1302], [-0.0647, -0.0637, 0.1265], 0.0483),
    ("panda_leftfinger", 7, [0.0389, 0.0389, 0.1668], [0.0361, 0.0361, 0.2108], 0.0168),
    ("panda_rightfinger", 7, [-0.0389, -0.0389, 0.1668], [-0.0361, -0.0361, 0.2108], 0.0168),
]

_UR5 = [
    ("base_link", 0, [-0.0012, -0.0362, 0.0087], [0.0002, 0.0037, 0.009], 0.0744),
    ("shoulder_link", 1, [0.0016, -0.012, 0.0081], [0.0007, 0.0005, 0.0086], 0.0853),
    ("upper_arm_link", 2, [0.4254, -0.001, 0.1359], [-0.0007, 0.0008, 0.1361], 0.0882),
    ("forearm_link", 3, [0.387, 0.0029, 0.0485], [0.008, 0.0023, 0.0137], 0.0680),
    ("wrist_1_link", 4, [-0.0007, -0.0032, -0.0093], [-0.0005, -0.005, 0.0107], 0.0563),
    ("wrist_2_link", 5, [0.0015, 0.0058, 0.0114], [0.001, 0.0032, -0.0091], 0.0566),
    ("wrist_3_link", 6, [-0.0, -0.0023, -0.0183], [-0.0001, 0.0039, -0.0177], 0.0411),
]


def _build(rows, name: str) -> CollisionModel:
    return CollisionModel.from_dicts(
        [{"name": b, "frame": f, "capsules": [{"a": a, "b": e, "radius": r}]}
         for b, f, a, e, r in rows], source=f"{name}: {SOURCE}")


def panda_collision_model() -> CollisionModel:
    """Collision capsules of the Franka Emika Panda (11 bodies on frames 0..7, see module)."""
    return _build(_PANDA, "panda")


def ur5_collision_model() -> CollisionModel:
    """Collision capsules of the Universal Robots UR5 (7 bodies on frames 0..6, see module)."""
    return _build(_UR5, "UR5")
