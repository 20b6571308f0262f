"""The built chapter report in headless Chromium: fonts, typeset maths, images, links, order.

The page embeds its fonts, so these tests run on them, not on the machine's: the
layout tests measure against the text column and each box, and
:func:`test_every_glyph_comes_from_an_embedded_font` checks with Chromium's own report
(DevTools ``CSS.getPlatformFontsForNode``) that no glyph is drawn from a system font.
"""

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
    drv.execute_async_script("const done = arguments[0]; document.fonts.ready.then(done);")
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
    """Every block stays inside the text column; wider content scrolls inside its own box.

    Measured relative to the column and to each box (not to the window), so that it holds
    for any fonts: what a font makes wider must scroll, never push the page wider.
    """
    result = page.execute_script("""
        const body = document.body.getBoundingClientRect();
        const cs = getComputedStyle(document.body);
        const right = body.right - parseFloat(cs.paddingRight);
        const scrolls = el => ['auto', 'scroll'].includes(getComputedStyle(el).overflowX);
        const inScroller = el => { for (let a = el.parentElement; a && a !== document.body;
            a = a.parentElement) { if (scrolls(a)) return true; } return false; };
        const outside = [];
        for (const el of document.querySelectorAll('body *')) {
            if (inScroller(el) || el.closest('math')) continue;
            const r = el.getBoundingClientRect();
            if (r.width > 0 && r.right > right + 1)
                outside.push([el.tagName, el.className, Math.round(r.right - right)]);
        }
        const boxes = Array.from(document.querySelectorAll('.eqbody, .tablewrap, pre')).map(
            b => { const c = b.firstElementChild;
                   return [b.className || b.tagName, b.scrollWidth, b.clientWidth,
                           getComputedStyle(b).overflowX,
                           c ? c.getBoundingClientRect().width : 0]; });
        return [outside, boxes];
    """)
    outside, boxes = result
    assert not outside, outside[:10]
    assert len(boxes) > 50
    for name, scroll_w, client_w, overflow, child_w in boxes:
        assert scroll_w >= child_w - 1, (name, scroll_w, child_w)  # all of it reachable
        assert scroll_w <= client_w + 1 or overflow in ("auto", "scroll"), name


#: Finds, in every text node outside code and mathematics, what must stay on one line:
#: a number with an exponent, a number with its unit, a range a–b, an assignment "q1 = 80.5"
#: (patterns of its own, not the page's, so that what the page forgets to keep together is
#: found); returns [text, node text] of each that the layout breaks across lines.
_BROKEN_NUMBERS_JS = r"""
    const n = String.raw`\d+(?:,\d{3})*(?:\.\d+)?`;
    const patterns = [
        String.raw`[-−+±]?${n}e[-−+]?\d+`,
        String.raw`${n}\s?(?:%|°|×|µs|ms|mm|µm|rad|m|s)(?![\w²])`,
        String.raw`${n}\s?[–-]\s?[-−]?${n}`,
        String.raw`\b[A-Za-zα-ωλ]\w{0,6} = [-−]?${n}`,
    ].map(p => new RegExp(String.raw`(?<![\w.,])` + p, 'g'));
    const skip = 'math, pre, code, style, script, title';
    const walker = document.createTreeWalker(document.body, NodeFilter.SHOW_TEXT);
    const broken = [];
    let checked = 0;
    for (let node = walker.nextNode(); node; node = walker.nextNode()) {
        if (!node.parentElement || node.parentElement.closest(skip)) continue;
        for (const re of patterns) {
            re.lastIndex = 0;
            for (let m = re.exec(node.data); m; m = re.exec(node.data)) {
                const range = document.createRange();
                range.setStart(node, m.index);
                range.setEnd(node, m.index + m[0].length);
                const rects = Array.from(range.getClientRects()).filter(r => r.width > 0);
                checked++;
                if (rects.length < 2) continue;
                const first = rects[0];
                if (rects.some(r => r.top >= first.bottom - 2))
                    broken.push([m[0], node.data.slice(0, 80)]);
            }
        }
    }
    return [checked, broken];"""


def _at_width(page, width: int):
    """Lay the page out at ``width`` CSS pixels (until the returned callable is called)."""
    page.execute_cdp_cmd("Emulation.setDeviceMetricsOverride", {
        "width": width, "height": 800, "deviceScaleFactor": 1, "mobile": False})
    return lambda: page.execute_cdp_cmd("Emulation.clearDeviceMetricsOverride", {})


def test_numbers_never_break_across_lines(page):
    """Every numeric table cell and matrix entry is laid out on one line."""
    broken = page.execute_script("""
        const out = [];
        for (const td of document.querySelectorAll('td.num, table.matrix td')) {
            const range = document.createRange(); range.selectNodeContents(td);
            const tops = new Set(Array.from(range.getClientRects()).map(r => Math.round(r.top)));
            if (tops.size > 1) out.push(td.textContent);
        }
        return out;""")
    assert not broken, broken[:10]


@pytest.mark.parametrize("width", [None, 420])
def test_numbers_in_text_and_prose_never_break(page, width):
    """In prose and text cells, a number stays on one line with its unit, range and exponent.

    At the page's width and in a narrow window (420 px), where nearly every line breaks.
    """
    restore = _at_width(page, width) if width else (lambda: None)
    try:
        checked, broken = page.execute_script(_BROKEN_NUMBERS_JS)
    finally:
        restore()
    assert checked > 500
    assert not broken, broken[:10]


def test_display_equations_fit_their_box(page):
    """At the page's width every display equation fits its box; narrower, it scrolls inside it.

    Measured relative to the box: the equation's own width against the box's, so that it
    holds for any fonts.
    """
    script = """
        return Array.from(document.querySelectorAll('.eqbody')).map(b => {
            // a display <math> is a block as wide as its box: measure what it holds
            const m = b.querySelector('math');
            const width = Math.max(...Array.from(m.children).map(
                c => c.getBoundingClientRect().width));
            return [width, b.clientWidth, b.scrollWidth,
                    getComputedStyle(b).overflowX,
                    b.parentElement.querySelector('.eqno')?.textContent || ''];
        });"""
    boxes = page.execute_script(script)
    assert len(boxes) > 40
    wide = [(no, round(w), client) for w, client, _, _, no in boxes if w > client + 1]
    assert not wide, wide
    restore = _at_width(page, 420)
    try:
        narrow = page.execute_script(script)
    finally:
        restore()
    scrolled = [b for b in narrow if b[0] > b[1] + 1]
    assert scrolled  # some equations are wider than a 420 px column ...
    for w, _client, scroll_w, overflow, no in scrolled:  # ... and scroll inside their box
        assert overflow in ("auto", "scroll") and scroll_w >= w - 1, no


def test_embedded_fonts_load_and_style_the_page(page):
    """Every @font-face of the page is loaded; text, code and maths name them first."""
    from serialkin.chapter._fonts import CODE, FACES, MATH, MATH_LETTERS, TEXT

    faces = page.execute_script(
        "return Array.from(document.fonts).map(f => [f.family, f.weight, f.style, f.status])")
    assert sorted(faces) == sorted([f.family, f.weight, f.style, "loaded"] for f in FACES)
    families = page.execute_script(
        "const f = s => getComputedStyle(document.querySelector(s)).fontFamily;"
        "return [f('body'), f('td'), f('pre'), f('code'), f('math'), f('mi')];")
    want = [TEXT, TEXT, CODE, CODE, MATH, MATH]
    for got, first in zip(families, want):
        assert got.startswith(f'"{first}"'), (got, first)
    assert f'"{MATH_LETTERS}"' in families[4]


def test_every_glyph_comes_from_an_embedded_font(page):
    """Chromium draws every glyph of the page from the embedded fonts, none from the system.

    One element per distinct (tag, own text, font family, weight, style) is asked through
    the DevTools protocol which platform fonts rendered its text.
    """
    probes = page.execute_script("""
        const seen = new Set(); let n = 0;
        for (const el of document.body.querySelectorAll('*')) {
            const own = Array.from(el.childNodes).filter(c => c.nodeType === 3)
                .map(c => c.data).join('').trim();
            if (!own) continue;
            const cs = getComputedStyle(el);
            const key = [el.tagName, own, cs.fontFamily, cs.fontWeight, cs.fontStyle].join('|');
            if (seen.has(key)) continue;
            seen.add(key); el.setAttribute('data-fontprobe', ''); n++;
        }
        return n;""")
    page.execute_cdp_cmd("DOM.enable", {})
    page.execute_cdp_cmd("CSS.enable", {})
    root = page.execute_cdp_cmd("DOM.getDocument", {"depth": -1})["root"]
    ids = page.execute_cdp_cmd("DOM.querySelectorAll", {
        "nodeId": root["nodeId"], "selector": "[data-fontprobe]"})["nodeIds"]
    assert len(ids) == probes > 500
    glyphs: dict[tuple[str, bool], int] = {}
    for node in ids:
        for font in page.execute_cdp_cmd("CSS.getPlatformFontsForNode",
                                         {"nodeId": node})["fonts"]:
            key = (font["familyName"], font["isCustomFont"])
            glyphs[key] = glyphs.get(key, 0) + font["glyphCount"]
    system = {k: v for k, v in glyphs.items() if not k[1]}
    assert not system, system
    assert {name for name, _ in glyphs} == {"DejaVu Sans", "DejaVu Sans Mono",
                                             "DejaVu Serif", "serialkin Math Letters"}
