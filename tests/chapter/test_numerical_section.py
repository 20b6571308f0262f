"""Section 5.3's comparison shows only what reproduces, and its ratios come from the bench.

A method that runs thousands of iterations (the Jacobian transpose) gets an iteration
count and final errors that depend on how the kernels were compiled: the page gives those
as a bound or as "varies", never as a measured value, and its Reproduce box checks the
rest. The prose's time ratios are the per-round ratios of the section's bench
(timings.json), not ratios of single-run medians.
"""

from __future__ import annotations

import html
import json
import re

import pytest

from serialkin.chapter._context import VARIES, ReportContext, format_ratio
from serialkin.chapter.sections.numerical.comparison import (
    CHAOTIC_ITERATIONS,
    _iterations,
    compare_box,
    row_cells,
)
from serialkin.ik.compare import COLUMNS, CompareRow


def _row(iterations: float, success: float = 0.7) -> CompareRow:
    return CompareRow(method="transpose", family="jacobian", solves=10,
                      success_rate=success, median_time=2e-3, mean_time=4e-3,
                      median_iterations=iterations, median_position_error=9.97e-7,
                      max_position_error=6.39e-5, median_orientation_error=2.56e-7,
                      max_orientation_error=4.55e-6, within_limits_rate=1.0)


def test_a_chaotic_row_shows_only_what_reproduces():
    """Over 1,000 iterations: "> 1,000", the tolerance as the median errors' bound, "varies"."""
    cells = dict(zip(COLUMNS, row_cells(_row(4904.0), 1e-6)))
    assert cells["median iterations"] == f"> {CHAOTIC_ITERATIONS:,}"
    assert cells["median pos. error [m]"] == cells["median ori. error [rad]"] == "< 1e-06"
    assert cells["max pos. error [m]"] == cells["max ori. error [rad]"] == VARIES
    assert cells["success rate"] == 0.7
    half = dict(zip(COLUMNS, row_cells(_row(4904.0, success=0.5), 1e-6)))
    assert half["median pos. error [m]"] == VARIES  # the median may be a failed solve's
    assert row_cells(_row(33.0), 1e-6) == _row(33.0).cells()


def test_chaotic_cells_keep_the_column_numeric():
    """A bound and "varies" leave the column right-aligned like the numbers around them."""
    out = ReportContext.table([(33.0, 9.97e-7), ("> 1,000", VARIES), (8.0, "< 1e-06")],
                              ["iterations", "error"])
    assert out.count('class="num"') == 8 and 'class="txt"' not in out


def test_iteration_ranges_never_quote_a_chaotic_count():
    """A range of median iterations names counts beyond 1,000 only as "more than 1,000"."""
    assert _iterations([33.0, 4904.0]) == "33 to more than 1,000"
    assert _iterations([4904.0, 2200.5]) == "more than 1,000"
    assert _iterations([5.5, 94.0]) == "5.5–94"


def test_the_box_checks_a_chaotic_row_by_its_success_rate_only():
    """The box declares every row's numbers, a chaotic row's success rate only."""
    from serialkin.ik.compare import CompareTable

    table = CompareTable(robot="puma560", target_kind="pose", n_targets=10, tol=1e-6,
                         rows=[_row(8.0, success=1.0), _row(4904.0)])
    box = compare_box(ReportContext, table)
    expect = json.loads(html.unescape(re.search(r'data-expect="([^"]*)"', box).group(1)))
    assert expect == ["1", "8", "9.97e-07", "6.39e-05", "0.7"]


def _section(page: str, sid: str) -> str:
    return re.search(rf'<section id="{sid}">(.*?)</section>', page, re.S).group(1)


@pytest.mark.slow
def test_the_page_prints_no_chaotic_count(built_report):
    """No iteration count above 1,000 is printed in the comparison tables or the prose."""
    _, page = built_report
    body = _section(page, "numerical")
    col = COLUMNS.index("median iterations")
    for table in re.findall(r"<table><caption>IK methods.*?</table>", body, re.S):
        for row in re.findall(r"<tr>(.*?)</tr>", table.split("<tbody>")[1], re.S):
            cell = html.unescape(re.findall(r"<td[^>]*>(.*?)</td>", row)[col])
            cell = re.sub(r"<[^>]+>", "", cell)
            assert cell == f"> {CHAOTIC_ITERATIONS:,}" or float(cell) <= CHAOTIC_ITERATIONS
    prose = re.sub(r"<[^>]+>", "", re.search(r"<p>Reading the tables.*?</p>", body, re.S)[0])
    counts = re.findall(r"median ([\d.,]+)(?:–([\d.,]+))? (?:to more than [\d,]+ )?"
                        r"iterations", prose)
    assert counts
    assert all(float(v.replace(",", "")) <= CHAOTIC_ITERATIONS for c in counts for v in c if v)


@pytest.mark.slow
def test_the_prose_ratios_are_the_benchs_per_round_ratios(built_report):
    """BFGS / lm and Powell / lm in the prose span the per-round ratio medians of timings.json."""
    out, page = built_report
    data = json.loads((out / "timings.json").read_text(encoding="utf-8"))
    prose = html.unescape(re.sub(r"<[^>]+>", "", re.search(
        r"<p>Reading the tables.*?</p>", _section(page, "numerical"), re.S)[0]))
    spans = []
    for method in ("bfgs", "powell"):
        ratios = [d for d in data if d["unit"] == "×" and d["label"].startswith(f"{method}, ")]
        assert len(ratios) == 3 and all(d["n"] == 21 and d["blocks"] == 7 for d in ratios)
        for d in ratios:  # "bfgs, UR5 / lm, UR5": both solves of one robot, per round
            robot = d["label"].split(" / ")[0].split(", ")[1]
            assert d["label"] == f"{method}, {robot} / lm, {robot}"
        lo, hi = (format_ratio(f(d["median"] for d in ratios)) for f in (min, max))
        spans.append(lo if lo == hi else f"{lo}–{hi}")
    assert f"they took {spans[0]}× and {spans[1]}× lm's time per solve" in prose
