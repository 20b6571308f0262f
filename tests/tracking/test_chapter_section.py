"""The chapter report's redundancy parts of section 5.3, as the built report shows them."""

from __future__ import annotations

import pytest


@pytest.mark.slow
def test_redundancy_section_builds_figures(built_report, report_section):
    """5.3's redundancy parts: typeset equations, every figure and GIF, warm timings."""
    out, page = built_report
    html = report_section("redundancy")
    for n in ("eq 42", "eq 46", "eq 48", "eq 49", "51-56"):
        assert n in html
    for title in ("Example: the six-link arm (Figures 8 and 9)",
                  "Example: the 20-link arm (Figures 11 and 12)"):
        assert title in html
    for fig in ("fig08_six_link_motion.png", "fig09_six_link_joints.png",
                "fig10_link_obstacle.png", "eq49_joint_limit_weight.png",
                "fig11_twenty_link_free.png", "fig12_twenty_link_obstacles.png",
                "twenty_link_task_activity.png", "twenty_link_ablation.png",
                "fig08_six_link.gif", "fig12_twenty_link_obstacles.gif"):
        assert f"figures/{fig}" in html  # this build's figure, not one left from another
        data = (out / "figures" / fig).read_bytes()
        assert data[:6] == b"GIF89a" if fig.endswith(".gif") else data[:4] == b"\x89PNG"
    assert "32 / 32" in html  # every point of the circle reached within 5 mm
    assert "largest tracking error" in html
    parts = page.count('<section id="redundancy')
    assert parts >= 5 and html.count('class="repro"') >= parts  # each part: how to reproduce
    assert "<math" in html and "\\frac" not in html and "\\mathbf" not in html
    # timings come from warm runs (ctx.timing with a warm-up call)
    assert html.count("warm runs in 7 blocks") >= 3
