"""The report section 5.3 builds and writes Figures 8, 9, 11, 12 and the GIF animations."""

from __future__ import annotations

import pytest

from serialkin.chapter.report import ReportContext


@pytest.mark.slow
def test_redundancy_section_builds_figures(tmp_path):
    """build() returns HTML with the tables and writes every PNG figure and GIF animation."""
    pytest.importorskip("matplotlib")
    from serialkin.chapter.sections import redundancy

    ctx = ReportContext(outdir=tmp_path, quiet=True)
    sec = redundancy.build(ctx)
    assert "5.3" in sec.title and "48" in sec.equations
    names = {p.split("/")[-1] for p in ctx.figures}
    for fig in ("fig08_six_link_motion.png", "fig09_six_link_joints.png",
                "fig11_twenty_link_free.png", "fig12_twenty_link_obstacles.png",
                "fig08_six_link.gif", "fig11_twenty_link_free.gif",
                "fig12_twenty_link_obstacles.gif"):
        assert fig in names
        data = (tmp_path / "figures" / fig).read_bytes()
        assert data[:6] == b"GIF89a" if fig.endswith(".gif") else data[:4] == b"\x89PNG"
    assert "32 / 32" in sec.html  # every point of the circle reached within 5 mm
    assert "largest tracking error" in sec.html
