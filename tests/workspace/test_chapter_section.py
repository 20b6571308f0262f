"""The chapter report's workspace section (section 1) builds, with its figures and checks."""

from __future__ import annotations

import re

import pytest


@pytest.mark.slow
def test_workspace_section_builds(built_report, report_section):
    """Section 1 computes every table and figure; every closed-form area is within ε."""
    out, _ = built_report
    sec_html = report_section("workspace")
    assert "<h2>1 Degrees of freedom, joint space and workspace</h2>" in sec_html
    assert "eq 43" in sec_html
    names = {"workspace_two_link.png", "workspace_three_link_kinds.png",
             "workspace_puma560.png", "workspace_puma560_slices.png"}
    assert set(re.findall(r"figures/([\w.]+)", sec_html)) == names  # exactly these, this build
    for name in names:
        assert (out / "figures" / name).read_bytes().startswith(b"\x89PNG")
    html = re.sub(r"<(td|th)[^>]*>", r"<\1>", sec_html)  # drop the alignment classes
    cells = re.findall(r"<td>(yes|NO)</td>", html)
    assert len(cells) == 4 + 3  # four 2-link arms, three 3-link kinds with closed forms
    assert set(cells) == {"yes"}
    # the DOF table: SCARA moves in 4 task coordinates, Panda is redundant by one
    assert re.search(r"<td>scara</td><td>4</td><td>RRPR</td>.*?<td>4</td><td>0</td>", html)
    assert re.search(r"<td>panda</td><td>7</td>.*?<td>6</td><td>1</td>", html)
    # dexterous ⊆ total orientation: the printed areas respect the inclusion
    areas = {m.group(1): float(m.group(2)) for m in re.finditer(
        r"<td>(total orientation|dexterous)(?:[^<]|<span[^>]*>[^<]*</span>)*</td>"
        r"<td>([0-9.]+)</td>", html)}
    assert set(areas) == {"total orientation", "dexterous"}
    assert areas["dexterous"] <= areas["total orientation"]
    assert "0 dexterous cells outside the total-orientation set" in html
    assert not re.search(r"-0\.0+(?![0-9])", html)  # no negative zero
    assert html.count('class="repro"') >= 3 and "<math" in html
