"""The full chapter report builds in the chapter's order, self-contained, with every figure."""

from __future__ import annotations

import re

import pytest

from serialkin.chapter.report import SECTION_MODULES

pytestmark = pytest.mark.slow

#: Sections whose examples this part of the report owns; each ends with a reproduce box.
_WITH_REPRODUCE = ("rigid_motion", "forward", "inverse", "jacobian", "numerical")


def _numbers(html: str) -> list[tuple[int, ...]]:
    heads = re.findall(r"<h2>(\d+(?:\.\d+)*) [^<]*</h2>", html)
    return [tuple(int(x) for x in h.split(".")) for h in heads]


def test_every_section_present(built_report):
    """Each section module appears once as a <section> naming the equations it demonstrates."""
    _, html = built_report
    for name in SECTION_MODULES:
        assert html.count(f'<section id="{name}">') == 1, name
    sections = html.count("<section id=")
    assert html.count('<p class="eq">Demonstrates:') == sections >= len(SECTION_MODULES)


def test_chapter_numbering_once_and_in_order(built_report):
    """Headings carry the chapter's numbers once, strictly increasing: 1, 2, 3, …, 5.3."""
    _, html = built_report
    nums = _numbers(html)
    assert nums == sorted(set(nums)), nums
    for want in [(1,), (2,), (3,), (3, 1), (3, 2), (3, 2, 1), (4,), (4, 1), (5,), (5, 1), (5, 2),
                 (5, 3)]:
        assert want in nums, want
    assert not re.search(r"<h2>\d+(\.\d+)*\.? \d+\.", html)  # no doubled numbers
    toc = re.search(r"<nav>.*?</nav>", html, re.S).group(0)
    assert "<ol" not in toc  # one numbering: the chapter's, not a list's


def test_header_has_build_metadata(built_report):
    """The header names serialkin's version, the commit, the date, versions, CPUs, build time."""
    _, html = built_report
    meta = re.search(r'<table class="meta">(.*?)</table>', html, re.S).group(1)
    for label in ("serialkin", "git commit", "source digest", "built", "Python", "numpy",
                  "numba", "CPUs", "build time"):
        assert f"<th>{label}</th>" in meta, label


def test_build_json_names_the_sources_and_versions(built_report):
    """build.json records these sources' digest (in the header too), sections and versions.

    What a later test run compares before reusing the build.
    """
    import json

    from serialkin.chapter.report import build_provenance, source_digest

    out, html = built_report
    recorded = json.loads((out / "build.json").read_text(encoding="utf-8"))
    assert recorded == build_provenance(SECTION_MODULES)
    digest = source_digest()
    assert re.fullmatch(r"[0-9a-f]{40}", digest) and digest == recorded["source"]
    assert f"<td>{digest[:12]}</td>" in html


def test_examples_end_with_reproduce(built_report):
    """Each of these sections' examples has a Reproduce box (command or snippet)."""
    _, html = built_report
    for name in _WITH_REPRODUCE:
        bodies = re.findall(rf'<section id="{name}(?:-\d+)?">(.*?)</section>', html, re.S)
        with_example = [b for b in bodies if "<table" in b or "<figure" in b]
        assert with_example, name
        for body in with_example:
            assert "Reproduce (" in body, (name, body[:80])
    assert html.count('class="repro"') >= 2 * len(_WITH_REPRODUCE) - 1


def test_no_raw_latex_or_negative_zero(built_report):
    """No LaTeX source outside MathML and no "-0.0000" anywhere in the report's text."""
    _, html = built_report
    text = re.sub(r"<math.*?</math>", "", html, flags=re.S)
    text = re.sub(r"<(style|pre)[^>]*>.*?</\1>", "", text, flags=re.S)
    text = re.sub(r'src="data:[^"]+"', "", text)
    assert not re.search(r"\\(frac|begin|theta|mathbf|left|sqrt|dot)\b", text)
    visible = re.sub(r"<[^>]+>", " ", text)
    negatives = re.findall(r"(?<![\w.])[-−]\d+(?:\.\d*)?(?:e[+-]?\d+)?", visible)
    zeros = [x for x in negatives if float(x.replace("−", "-")) == 0.0]
    assert not zeros, zeros[:5]


def test_every_linked_figure_exists(built_report):
    """Every figure file the report links to was written and is a non-empty PNG or GIF."""
    out, html = built_report
    files = set(re.findall(r'href="(figures/[^"]+)"', html))
    assert len(files) >= 15  # figures 4, 5, 8, 9, 11, 12 and the sections' own
    for rel in files:
        data = (out / rel).read_bytes()
        assert data[:4] in (b"\x89PNG", b"GIF8"), rel
    for fig in ("fig08", "fig09", "fig11", "fig12"):
        assert any(fig in f for f in files), fig
    assert any(f.endswith(".gif") for f in files)


def test_report_is_self_contained_and_small(built_report):
    """Images are data URIs, nothing loads from the network, and the file is at most 5 MB."""
    out, html = built_report
    assert "data:image/png;base64," in html
    assert not re.search(r'<(img|script|link)[^>]+(src|href)="https?://', html)
    assert "<script" not in html  # MathML is native: no JavaScript at all
    assert "Traceback" not in html
    assert (out / "report.html").stat().st_size <= 5_000_000


def test_every_timing_is_warm(built_report):
    """Every timing the page prints is a median of warm runs in blocks, with the block spread."""
    _, html = built_report
    times = re.findall(r"median of \d+ warm runs in (\d+) blocks, 5th–95th percentile", html)
    ratios = re.findall(r"× \(median of \d+ rounds in (\d+) blocks, 5th–95th percentile", html)
    # (c)/(b) for the whole path and per iteration, QP / eq 48, and BFGS / lm and
    # Powell / lm on each of three robots
    assert len(times) >= 14 and len(ratios) == 9, (times, ratios)
    assert {int(b) for b in times + ratios} == {7}
    assert not re.search(r"median of \d+ (warm runs|interleaved pairs)[^,]*, spread", html)


def test_timings_json_holds_every_run(built_report):
    """timings.json: each timing's median and 5th-95th percentile follow from its runs."""
    import json

    import numpy as np

    out, html = built_report
    data = json.loads((out / "timings.json").read_text(encoding="utf-8"))
    # numerical: lm, BFGS and Powell on three robots and 6 ratios; redundancy: 4 runs and 3
    # ratios ((c)/(b) for the whole path and per iteration, QP / eq 48)
    assert len(data) == 22 and {d["section"] for d in data} == {"numerical", "redundancy"}
    for d in data:
        runs = np.array(d["runs"])
        assert d["n"] == runs.size == 21 and d["blocks"] == 7, d["label"]
        assert d["median"] == np.median(runs)
        assert (d["low"], d["high"]) == tuple(np.percentile(runs, [5, 95]))
        assert d["low"] <= d["median"] <= d["high"]
    labels = {d["label"] for d in data}
    assert {"(b) free", "(c) constrained", "(c) by the QP", "six-link circle"} <= labels
    assert "(c) by the QP / (c) constrained" in labels
    assert "(c) constrained / (b) free per iteration" in labels


def test_every_character_is_in_a_bundled_font(built_report):
    """Each character the page shows is in the embedded font of its role: no system font."""
    from fontTools.ttLib import TTFont

    from serialkin.chapter._fonts import FACES, LICENCES, page_characters

    out, html = built_report
    fonts = out / "fonts"
    for name in LICENCES:
        assert (fonts / name).read_text(encoding="utf-8").strip()
    cover: dict[str, set[str]] = {}
    for face in FACES:
        data = (fonts / face.file).read_bytes()
        assert data[:4] == b"wOFF", face.file
        assert html.count("data:font/woff;base64,") == len(FACES)
        cmap = {chr(c) for c in TTFont(fonts / face.file).getBestCmap()}
        if face.weight == "normal" and face.style == "normal":
            cover.setdefault(face.role, set()).update(cmap)
        else:  # bold and italic text faces cover what the regular one does
            assert page_characters(html)["text"] <= cmap, face.file
    for role, chars in page_characters(html).items():
        missing = sorted(chars - cover[role])
        assert not missing, (role, missing[:20])


def test_bold_symbols_are_unicode_bold(built_report):
    """No MathML relies on mathvariant="bold…" (MathML Core ignores it): bold is Unicode bold."""
    _, html = built_report
    assert "\\boldsymbol" not in html
    assert not re.search(r'mathvariant="bold', html)
    assert "\U0001d74e" in html or "\U0001d7ce" in html  # bold-italic ω or bold 0


def test_equation_numbers_follow_the_chapter(built_report):
    """Numbered equations appear in the chapter's order, each number at most once (eq 2 too)."""
    _, html = built_report
    numbers = re.findall(r'<span class="eqno">\((\d+)(?:[^)]*)\)</span>', html)
    values = [int(n) for n in numbers]
    assert 2 in values and values == sorted(values), values
    assert len(set(values)) == len(values), values


#: The equations the ERRATA corrects (its table: 17; 23/26 with the pairing of 27; 44; 46;
#: 51-52, the clamped projection; 54). Eq 48 is printed right: the ERRATA corrects step 6
#: of the 20-link algorithm to it.
CORRECTED = {17, 23, 26, 27, 44, 46, 51, 52, 54}


def test_each_equation_has_its_own_number_and_corrections_are_marked(built_report):
    """Every label is one chapter number ("(30)", never "(30-31)"); the ERRATA's are marked."""
    _, html = built_report
    labels = re.findall(r'<span class="eqno">\(([^)]*)\)</span>', html)
    assert labels and all(re.fullmatch(r"\d+(, corrected)?", n) for n in labels), labels
    numbers = {int(n.split(",")[0]) for n in labels}
    assert {30, 31, 32} <= numbers
    marked = {int(n.split(",")[0]) for n in labels if n.endswith(", corrected")}
    assert marked == CORRECTED & numbers == CORRECTED, marked


def test_angles_in_the_half_open_interval(built_report):
    """Angles printed in degrees in the IK tables lie in (−180°, 180°]."""
    _, html = built_report
    section = re.search(r'<section id="inverse">(.*?)</section>', html, re.S).group(1)
    cells = re.findall(r'<td class="num">(-?\d+\.\d)</td>', section)
    assert cells
    assert all(-180.0 < float(c) <= 180.0 for c in cells)
