"""Smoke test of the report's rigid-body-motion section (chapter section 2)."""

from __future__ import annotations

import re
from pathlib import Path

from serialkin.chapter.report import ReportContext
from serialkin.chapter.sections import rigid_motion


def test_section_builds_with_small_residuals(tmp_path: Path) -> None:
    """The section renders every part, writes its figure, and all reported errors are tiny."""
    ctx = ReportContext(outdir=tmp_path, quiet=True)
    sec = rigid_motion.build(ctx)
    assert sec.title.startswith("2.") and sec.equations == "eqs 1-9"
    for part in ("eqs 4-6", "eq 7", "Orientation representations", "pose error", "<img"):
        assert part in sec.html
    assert (tmp_path / "figures" / "rigid_motion_frames.png").stat().st_size > 10_000
    # every residual printed as a.be-XX must be below 1e-12
    residuals = [float(x) for x in re.findall(r"\d\.\de[+-]\d\d", sec.html)]
    assert residuals and max(residuals) < 1e-12
