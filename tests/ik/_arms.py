"""Hypothesis strategies and DH tables of arms with a spherical wrist, shared by the IK tests."""

from __future__ import annotations

import math

from hypothesis import strategies as st

from serialkin.model.dh import DHLink

H = 0.5 * math.pi


def zero_or_away(low: float, high: float) -> st.SearchStrategy[float]:
    """Exactly 0 (a special structure) or well away from it (a well-conditioned one)."""
    return st.one_of(st.just(0.0), st.floats(low, high), st.floats(-high, -low))


#: ``@given(**WRIST_ARM, ...)``: DH a, α of the three arm joints and d of the arm and wrist.
WRIST_ARM = {
    "a": st.lists(zero_or_away(0.05, 0.5), min_size=3, max_size=3),
    "alpha": st.lists(zero_or_away(0.2, 2.9), min_size=3, max_size=3),
    "d": st.lists(zero_or_away(0.05, 0.5), min_size=4, max_size=4),
}


def wrist_arm_rows(a, alpha, d) -> list[DHLink]:
    """Standard DH rows of an R R R arm (a, alpha, d[:3]) then a spherical wrist (d[3])."""
    rows = [DHLink(a=a[i], alpha=alpha[i], d=d[i]) for i in range(3)]
    return rows + [DHLink(a=0.0, alpha=-H, d=d[3]), DHLink(a=0.0, alpha=H, d=0.0),
                   DHLink(a=0.0, alpha=0.0, d=0.1)]
