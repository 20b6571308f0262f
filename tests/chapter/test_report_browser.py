"""The built chapter report in headless Chromium: typeset maths, images, links, order."""

from __future__ import annotations

import re

import pytest

from tests._browser import start_chromium

pytestmark = [pytest.mark.browser, pytest.mark.slow]

#: LaTeX control words that must never reach the reader.
_LATEX = re.compile(r"\\(frac|begin|end|theta|vartheta|mathbf|boldsymbol|left|right|dot|"
                    r"sqrt|cdot|alpha|beta|gamma|omega|pi|sum|prod|operatorname|text|quad|"
                    r"dagger|partial|mathrm|circ)\b")


@pytest.fixture(scope="module")
def page(built_report):
    """Chromium showing the report (loaded once for this module)."""
    out, _ = built_report
    drv, profile = start_chromium()
    drv.get((out / "report.html").resolve().as_uri())
    yield drv
    drv.quit()
    import shutil

    shutil.rmtree(profile, ignore_errors=True)


def test_no_raw_latex_visible(page):
    r"""The visible text contains no LaTeX control word (\frac, \begin, \theta, …)."""
    text = page.execute_script("return document.body.innerText")
    assert len(text) > 10_000
    found = _LATEX.findall(text)
    assert not found, found[:10]


def test_every_math_element_has_size(page):
    """Every <math> element is rendered with a non-zero width and height."""
    sizes = page.execute_script(
        "return Array.from(document.querySelectorAll('math')).map(m => {"
        "const r = m.getBoundingClientRect(); return [r.width, r.height, m.textContent]; })")
    assert len(sizes) > 50
    empty = [s for s in sizes if not (s[0] > 0 and s[1] > 0)]
    assert not empty, empty[:5]


def test_every_image_loads(page):
    """Every <img> decodes (naturalWidth > 0)."""
    imgs = page.execute_script(
        "return Array.from(document.images).map(i => [i.complete, i.naturalWidth, i.alt]);")
    assert len(imgs) >= 15
    bad = [i for i in imgs if not (i[0] and i[1] > 0)]
    assert not bad, bad


def test_contents_links_resolve_to_headings(page):
    """Each contents link targets an element whose first heading has the link's text."""
    pairs = page.execute_script(
        "return Array.from(document.querySelectorAll('nav a')).map(a => {"
        "const id = a.getAttribute('href').slice(1); const el = document.getElementById(id);"
        "const h = !el ? null : el.matches('h2, h3') ? el : el.querySelector('h2, h3');"
        "return [id, a.textContent, h ? h.textContent : null]; })")
    assert len(pairs) >= 12
    for anchor, label, heading in pairs:
        assert heading is not None, anchor
        assert heading.strip() == label.strip(), (anchor, label, heading)


def test_headings_in_chapter_order(page):
    """The numbered headings, read top to bottom, follow the chapter: 1, 2, 3, 3.2, …, 5.3."""
    heads = page.execute_script(
        "return Array.from(document.querySelectorAll('section > h2')).map(h => h.textContent)")
    nums = [tuple(int(x) for x in re.match(r"(\d+(?:\.\d+)*) ", h).group(1).split("."))
            for h in heads]
    assert nums == sorted(nums) and len(set(nums)) == len(nums), heads
    assert nums[0] == (1,) and nums[-1] == (5, 3)


def test_wide_content_scrolls_inside_its_box(page):
    """Nothing widens the page: wide equations scroll inside their own box, never cut off."""
    page_width, view = page.execute_script(
        "return [document.documentElement.scrollWidth, window.innerWidth]")
    assert page_width <= view, (page_width, view)
    boxes = page.execute_script(
        "return Array.from(document.querySelectorAll('.eqbody')).map(b => ["
        "b.scrollWidth, b.clientWidth, getComputedStyle(b).overflowX,"
        "b.querySelector('math').getBoundingClientRect().width])")
    assert boxes
    for scroll_w, client_w, overflow, math_w in boxes:
        assert scroll_w >= math_w - 1  # the whole equation is reachable
        assert scroll_w <= client_w or overflow == "auto"
