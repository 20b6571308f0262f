"""Section 1 (workspace): closed-form areas of planar 2R and 3R workspaces.

The sampled areas of the section are checked against these (unlimited joints).
"""

from __future__ import annotations

import math


def annulus_area(L1: float, L2: float) -> float:
    """π((L1+L2)² − (L1−L2)²) = 4π L1 L2: the area of the 2-link workspace."""
    return math.pi * ((L1 + L2) ** 2 - (L1 - L2) ** 2)


def three_link_reachable_area(L: tuple[float, float, float]) -> float:
    """Maximal workspace of a planar 3R arm: the annulus r_min ≤ |p| ≤ L1+L2+L3."""
    r_max = sum(L)
    r_min = max(0.0, 2 * max(L) - r_max)
    return math.pi * (r_max**2 - r_min**2)


def three_link_total_area(L: tuple[float, float, float]) -> float:
    """Total-orientation workspace of a planar 3R arm (unlimited joints).

    Every heading φ is reachable at p when the wrist p − L3 e_φ is in the 2-link annulus
    [d, L1+L2], d = |L1−L2|, for every φ: its distance to p ranges over [|L3 − |p||,
    |p| + L3], so |p| ≤ L1 + L2 − L3 and either |p| ≥ d + L3 (the ring) or |p| ≤ L3 − d
    (the disc, when L3 > d): the ring plus the disc of radius min(L3 − d, L1 + L2 − L3).
    """
    L1, L2, L3 = L
    d = abs(L1 - L2)
    outer = max(L1 + L2 - L3, 0.0)
    ring = math.pi * max(outer**2 - (d + L3) ** 2, 0.0) if outer > d + L3 else 0.0
    return ring + math.pi * max(min(L3 - d, outer), 0.0) ** 2
