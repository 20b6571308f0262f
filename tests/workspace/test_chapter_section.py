"""The chapter report's workspace section (section 1) builds, with its figures and checks."""

from __future__ import annotations

import re

import pytest

from serialkin.chapter.report import ReportContext


@pytest.mark.slow
def test_workspace_section_builds(tmp_path):
    """Section 1 computes every table and figure; every closed-form area is within ε."""
    from serialkin.chapter.sections import workspace

    ctx = ReportContext(outdir=tmp_path, quiet=True)
    sec = workspace.build(ctx)
    assert sec.title.startswith("1.")
    assert "section 1" in sec.equations and "eq 43" in sec.equations
    names = {"workspace_two_link.png", "workspace_three_link_kinds.png",
             "workspace_puma560.png", "workspace_puma560_slices.png"}
    assert {f.split("/")[-1] for f in ctx.figures} == names
    for f in ctx.figures:
        assert (tmp_path / f).read_bytes().startswith(b"\x89PNG")
    html = re.sub(r"<(td|th)[^>]*>", r"<\1>", sec.html)  # drop the alignment classes
    cells = re.findall(r"<td>(yes|NO)</td>", html)
    assert len(cells) == 4 + 3  # four 2-link arms, three 3-link kinds with closed forms
    assert set(cells) == {"yes"}
    # the DOF table: SCARA moves in 4 task coordinates, Panda is redundant by one
    assert re.search(r"<td>scara</td><td>4</td><td>RRPR</td>.*?<td>4</td><td>0</td>", html)
    assert re.search(r"<td>panda</td><td>7</td>.*?<td>6</td><td>1</td>", html)
    # dexterous ⊆ total orientation: the printed areas respect the inclusion
    areas = {m.group(1): float(m.group(2)) for m in re.finditer(
        r"<td>(total orientation|dexterous)[^<]*</td><td>([0-9.]+)</td>", html)}
    assert set(areas) == {"total orientation", "dexterous"}
    assert areas["dexterous"] <= areas["total orientation"]
    assert "0 dexterous cells outside the total-orientation set" in html
    assert not re.search(r"-0\.0+(?![0-9])", html)  # no negative zero
    assert html.count('class="repro"') >= 3 and "<math" in html
