"""The report's embedded fonts: which characters a page needs, the subsets, their licences."""

from __future__ import annotations

import io

import pytest

from serialkin.chapter import _fonts

fontTools = pytest.importorskip("fontTools")


def test_math_italic_follows_mathml_core():
    """Single-letter identifiers map to the Unicode mathematical italic letters (h → ℎ)."""
    assert _fonts.math_italic("x") == "\U0001d465"
    assert _fonts.math_italic("A") == "\U0001d434"
    assert _fonts.math_italic("h") == "\u210e"
    assert _fonts.math_italic("θ") == "\U0001d703"
    assert _fonts.math_italic("Ω") == "\U0001d6fa"
    assert _fonts.math_italic("∂") == "\U0001d715"
    assert _fonts.math_italic("2") == "2" and _fonts.math_italic("+") == "+"


def test_page_characters_by_role():
    """Text outside <math>, code inside <pre>/<code>, maths with italic forms; no attributes."""
    page = ('<html><head><title>Tï</title><style>body{}</style></head><body>'
            '<p title="Ω">a &lt; b <code>q̇</code></p><img alt="Ж" src="data:x">'
            '<math><mi>x</mi><mo>=</mo><mi>cos</mi><mn>2</mn></math></body></html>')
    chars = _fonts.page_characters(page)
    assert {"a", "<", "b", "q", "\u0307"} <= chars["text"]
    assert not {"Ω", "Ж", "ï", "x", "="} & chars["text"] - set(map(chr, range(32, 127)))
    assert {"q", "\u0307"} <= chars["code"]
    assert {"x", "\U0001d465", "=", "c", "o", "s", "2"} <= chars["math"]
    assert "\U0001d450" not in chars["math"]  # "cos" is not one letter: no italic c


def _open(data: bytes):
    from fontTools.ttLib import TTFont

    return TTFont(io.BytesIO(data))


def test_subset_keeps_the_characters_and_is_reproducible():
    """A subset has the asked characters (and not others) and the same bytes twice."""
    source = _fonts.font_dir() / "DejaVuSans.ttf"
    a = _fonts.subset_font(source, "abc−")
    assert a == _fonts.subset_font(source, "abc−")
    cmap = {chr(c) for c in _open(a).getBestCmap()}
    assert {"a", "b", "c", "−"} <= cmap and "z" not in cmap
    assert a[:4] == b"wOFF" and len(a) < (source.stat().st_size) / 10


def test_stix_subset_is_renamed():
    """The STIX subset no longer carries the Reserved Font Name in its names (OFL 1.1)."""
    face = next(f for f in _fonts.FACES if f.source.startswith("STIX"))
    font = _open(_fonts.subset_font(_fonts.font_dir() / face.source, "\U0001d409",
                                    face.rename))
    names = {r.nameID: r.toUnicode() for r in font["name"].names}
    for i in (1, 3, 4, 6):
        assert "STIX" not in names[i], (i, names[i])
    assert names[1] == face.rename
    assert "STI Pub" in names[0] and "STIX" in names[7]  # copyright and trademark stay


def test_graded_delimiters_grow_between_glyph_and_assembly():
    """Parentheses and brackets get size variants, increasing, below the smallest assembly."""
    font = _open(_fonts.subset_font(_fonts.font_dir() / "DejaVuSerif.ttf", "()[]|x",
                                    graded=True))
    variants = font["MATH"].table.MathVariants
    cmap = font.getBestCmap()
    for char in "([":
        glyph = cmap[ord(char)]
        construction = variants.VertGlyphConstruction[
            variants.VertGlyphCoverage.glyphs.index(glyph)]
        records = construction.MathGlyphVariantRecord
        sizes = [r.AdvanceMeasurement for r in records]
        assert records[0].VariantGlyph == glyph and len(records) >= 3, char
        assert sizes == sorted(sizes) and len(set(sizes)) == len(sizes), char
        fixed = [p for p in construction.GlyphAssembly.PartRecords if not p.PartFlags & 1]
        smallest = sum(p.FullAdvance for p in fixed) - variants.MinConnectorOverlap * (
            len(fixed) - 1)
        assert sizes[-1] < smallest, char
        glyf = font["glyf"]
        for r in records[1:]:  # each variant is as tall as it says, about the math axis
            g = glyf[r.VariantGlyph]
            g.recalcBounds(glyf)
            assert abs((g.yMax - g.yMin) - r.AdvanceMeasurement) <= 2, (char, r.VariantGlyph)
