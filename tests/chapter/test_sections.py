"""Report sections 2-5.3 built one by one: structure, and numbers of the kind they claim."""

from __future__ import annotations

import pytest

from serialkin.chapter.report import ReportContext


@pytest.fixture
def ctx(tmp_path):
    return ReportContext(outdir=tmp_path, quiet=True)


def test_default_solver_timings_are_warm(ctx):
    """Section 5.3's solver timings come from ctx.timing: warm-up first, 7 timed runs each."""
    from serialkin.chapter.sections import numerical

    rows = numerical._default_solver_timings(ctx)
    assert len(rows) == len(ctx.timings) == 3
    for row, t in zip(rows, ctx.timings):
        assert t.warm and t.n == 7 and 0 < t.low <= t.median <= t.high
        assert row[-1] == t.text and "warm runs" in t.text


@pytest.mark.slow
def test_sections_in_chapter_numbering(ctx):
    """Sections 3, 4 and 5 build their numbered parts in the chapter's order."""
    from serialkin.chapter.sections import forward, inverse, jacobian

    numbers = [s.number for mod in (forward, inverse, jacobian) for s in mod.build(ctx)]
    assert numbers == ["3", "3.1", "3.2", "3.2.1", "4", "4.1", "5", "5.1", "5.2"]
