"""The report section 5.3 (redundancy) builds Figures 8-12, eq 49, activity and ablation."""

from __future__ import annotations

import pytest

from serialkin.chapter.report import ReportContext


@pytest.mark.slow
def test_redundancy_section_builds_figures(tmp_path):
    """build() returns the parts of 5.3 with typeset equations, every figure and GIF."""
    pytest.importorskip("matplotlib")
    from serialkin.chapter.sections import redundancy

    ctx = ReportContext(outdir=tmp_path, quiet=True)
    parts = redundancy.build(ctx)
    assert all(p.title.startswith("5.3 ") and p.part for p in parts)
    html = "".join(p.html for p in parts)
    eqs = " ".join(p.equations for p in parts)
    for n in ("42", "46", "48", "49", "51-56"):
        assert n in eqs
    names = {p.split("/")[-1] for p in ctx.figures}
    for fig in ("fig08_six_link_motion.png", "fig09_six_link_joints.png",
                "fig10_link_obstacle.png", "eq49_joint_limit_weight.png",
                "fig11_twenty_link_free.png", "fig12_twenty_link_obstacles.png",
                "twenty_link_task_activity.png", "twenty_link_ablation.png",
                "fig08_six_link.gif", "fig12_twenty_link_obstacles.gif"):
        assert fig in names
        data = (tmp_path / "figures" / fig).read_bytes()
        assert data[:6] == b"GIF89a" if fig.endswith(".gif") else data[:4] == b"\x89PNG"
    assert "32 / 32" in html  # every point of the circle reached within 5 mm
    assert "largest tracking error" in html
    assert html.count('class="repro"') >= len(parts)  # every part says how to reproduce it
    assert "<math" in html and "\\frac" not in html and "\\mathbf" not in html
    # timings come from warm runs (ctx.timing with a warm-up call)
    assert len(ctx.timings) >= 3 and all(t.warm for t in ctx.timings)
