"""Allowed (never checked) body pairs shipped with the zoo robots, and how each was made.

Beyond :func:`~serialkin.collision.acm.default_acm`'s same-frame and adjacent-frame pairs:

* **panda**, **ur5** — the vendor SRDF's ``<disable_collisions>`` (example-robot-data
  6.0: ``panda_description/srdf/panda.srdf``, ``ur_description/srdf/ur5.srdf``), pairs
  naming bodies of the zoo model; the same pairs Pinocchio + coal skip, so that the two
  checks agree (``tests/collision/test_vendor_agreement.py``).
* **puma560**, **stanford**, **iiwa7** — no vendor meshes in example-robot-data: MoveIt's
  sampling rule on the zoo capsules, :func:`~serialkin.collision.queries.sampled_acm`
  with ``samples=20000, seed=0, margin=0, never=True`` (pairs in contact in every
  sample, "always", or in none, "never").

Regenerate: ``python benchmarks/generate_allowed_pairs.py`` (prints the tables below).
"""

from __future__ import annotations

METHOD = {
    "panda": "vendor SRDF (example-robot-data 6.0 panda.srdf)",
    "ur5": "vendor SRDF (example-robot-data 6.0 ur5.srdf)",
    "puma560": "sampled never/always in collision (20,000 configurations, seed 0)",
    "stanford": "sampled never/always in collision (20,000 configurations, seed 0)",
    "iiwa7": "sampled never/always in collision (20,000 configurations, seed 0)",
}

ALLOWED: dict[str, tuple[tuple[str, str], ...]] = {
    "panda": (
        ("panda_hand", "panda_leftfinger"), ("panda_hand", "panda_link3"),
        ("panda_hand", "panda_link4"), ("panda_hand", "panda_link5"),
        ("panda_hand", "panda_link6"), ("panda_hand", "panda_link7"),
        ("panda_hand", "panda_rightfinger"), ("panda_leftfinger", "panda_link3"),
        ("panda_leftfinger", "panda_link4"), ("panda_leftfinger", "panda_link6"),
        ("panda_leftfinger", "panda_link7"), ("panda_leftfinger", "panda_rightfinger"),
        ("panda_link0", "panda_link1"), ("panda_link0", "panda_link2"),
        ("panda_link0", "panda_link3"), ("panda_link0", "panda_link4"),
        ("panda_link1", "panda_link2"), ("panda_link1", "panda_link3"),
        ("panda_link1", "panda_link4"), ("panda_link2", "panda_link3"),
        ("panda_link2", "panda_link4"), ("panda_link3", "panda_link4"),
        ("panda_link3", "panda_link5"), ("panda_link3", "panda_link6"),
        ("panda_link3", "panda_link7"), ("panda_link3", "panda_rightfinger"),
        ("panda_link4", "panda_link5"), ("panda_link4", "panda_link6"),
        ("panda_link4", "panda_link7"), ("panda_link4", "panda_rightfinger"),
        ("panda_link5", "panda_link6"), ("panda_link5", "panda_link7"),
        ("panda_link6", "panda_link7"), ("panda_link6", "panda_rightfinger"),
        ("panda_link7", "panda_rightfinger"),
    ),
    "ur5": (
        ("base_link", "shoulder_link"), ("base_link", "upper_arm_link"),
        ("shoulder_link", "upper_arm_link"), ("upper_arm_link", "forearm_link"),
        ("forearm_link", "wrist_1_link"), ("forearm_link", "wrist_2_link"),
        ("forearm_link", "wrist_3_link"), ("wrist_1_link", "wrist_2_link"),
        ("wrist_1_link", "wrist_3_link"), ("wrist_2_link", "wrist_3_link"),
    ),
    "puma560": (
        ("pedestal", "upper_arm"), ("trunk", "forearm"), ("trunk", "wrist"),
        ("trunk", "flange"), ("upper_arm", "wrist"), ("upper_arm", "flange"),
        ("forearm", "flange"),
    ),
    "stanford": (
        ("base", "guide"), ("column", "boom"), ("column", "wrist"), ("column", "hand"),
        ("guide", "wrist"), ("guide", "hand"), ("boom", "hand"),
    ),
    "iiwa7": (
        ("link0", "link2"), ("link0", "link3"), ("link0", "link4"), ("link1", "link3"),
        ("link1", "link4"), ("link1", "link5"), ("link1", "link6"), ("link1", "link7"),
        ("link2", "link4"), ("link2", "link5"), ("link2", "link6"), ("link2", "link7"),
        ("link3", "link5"), ("link3", "link6"), ("link3", "link7"), ("link4", "link6"),
        ("link4", "link7"),
    ),
}
