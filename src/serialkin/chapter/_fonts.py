"""The report's own fonts: DejaVu and STIX from matplotlib, subset to the page, embedded.

The page must look the same, and lay out the same, on every machine: its layout tests
measure boxes against the text column, and a system font that is wider or missing a glyph
moves them. So the report does not name system fonts: it embeds its own, taken from the
fonts matplotlib ships (``matplotlib/mpl-data/fonts/ttf``, always present where the report
is built since the figures need matplotlib):

* text: DejaVu Sans (regular, bold, oblique), the font of the figures too;
* code: DejaVu Sans Mono;
* mathematics: DejaVu Serif, whose OpenType MATH table gives the browser's MathML layout
  its parameters and stretchy brackets, radicals and sums, and whose italic letters serve
  the single-letter identifiers; the mathematical letters it lacks (bold 𝐉, bold italic 𝝎,
  italic Greek) come from STIX General.

Each font is cut down to the characters the page uses (:func:`page_characters`;
fontTools' subsetter keeps the layout features and the MATH table's variants) and
embedded as a WOFF data URI in the page's ``@font-face`` rules, so the file stays
self-contained; the same files and the fonts' licences are written to ``fonts/`` beside
the page. Licences: DejaVu, the Bitstream Vera licence (a modified font must not be
called "Bitstream" or "Vera"; DejaVu changes are public domain); STIX, the SIL Open Font
License 1.1 with the Reserved Font Names "STIX Fonts" and "TM Math", so the subset of
STIX General is renamed (:data:`FACES`).
"""

from __future__ import annotations

import base64
import hashlib
import html
import io
import json
import re
from collections.abc import Iterable
from dataclasses import dataclass
from pathlib import Path

from serialkin._io import write_bytes_atomic, write_text_atomic

#: Licence files of matplotlib's fonts, copied beside the subset fonts.
LICENCES = ("LICENSE_DEJAVU", "LICENSE_STIX")


@dataclass(frozen=True)
class Face:
    """One embedded font face.

    Attributes:
        family: the CSS family name the page uses.
        source: the file in matplotlib's ``mpl-data/fonts/ttf``.
        role: which characters it is cut down to: "text", "code" or "math".
        weight: CSS font-weight of the face ("normal" or "bold").
        style: CSS font-style of the face ("normal" or "italic").
        rename: the family name written into the subset (None: kept), for a font whose
            licence reserves its name for the unmodified font.
    """

    family: str
    source: str
    role: str
    weight: str = "normal"
    style: str = "normal"
    rename: str | None = None

    @property
    def file(self) -> str:
        """The subset's file name under ``fonts/``, e.g. "DejaVuSans-subset.woff"."""
        return Path(self.source).stem + "-subset.woff"


#: CSS family names of the page's three roles.
TEXT, CODE, MATH, MATH_LETTERS = ("serialkin text", "serialkin code", "serialkin math",
                                  "serialkin math letters")

#: Every face the page embeds.
FACES: tuple[Face, ...] = (
    Face(TEXT, "DejaVuSans.ttf", "text"),
    Face(TEXT, "DejaVuSans-Bold.ttf", "text", weight="bold"),
    Face(TEXT, "DejaVuSans-Oblique.ttf", "text", style="italic"),
    Face(CODE, "DejaVuSansMono.ttf", "code"),
    Face(MATH, "DejaVuSerif.ttf", "math"),
    Face(MATH_LETTERS, "STIXGeneral.ttf", "math", rename="serialkin Math Letters"),
)

#: The CSS font-family lists of the page (nothing after the embedded faces but a generic
#: family, which a test checks is never needed).
FAMILY = {
    "text": f'"{TEXT}", sans-serif',
    "code": f'"{CODE}", monospace',
    "math": f'"{MATH}", "{MATH_LETTERS}", math',
}


def font_dir() -> Path:
    """The folder of matplotlib's TrueType fonts (``mpl-data/fonts/ttf``)."""
    import matplotlib

    return Path(matplotlib.get_data_path()) / "fonts" / "ttf"


# --- which characters the page shows --------------------------------------------------------
_MATH = re.compile(r"<math\b.*?</math>", re.S)
_CODE = re.compile(r"<(pre|code)\b[^>]*>(.*?)</\1>", re.S)
_HIDDEN = re.compile(r"<(style|title|head)\b.*?</\1>", re.S)
_TAG = re.compile(r"<[^>]*>")
_SINGLE_MI = re.compile(r"<mi>([^<]+)</mi>")
#: MathML Core's italic mapping of a single-letter <mi> (text-transform: math-auto).
_ITALIC_SPECIAL = {"h": 0x210E, "ı": 0x1D6A4, "ȷ": 0x1D6A5, "ϴ": 0x1D6F3, "∇": 0x1D6FB,
                   "∂": 0x1D715, "ϵ": 0x1D716, "ϑ": 0x1D717, "ϰ": 0x1D718, "ϕ": 0x1D719,
                   "ϱ": 0x1D71A, "ϖ": 0x1D71B}


def math_italic(char: str) -> str:
    """The character a browser shows for a single-letter <mi> (MathML Core's math-auto).

    Latin and Greek letters map to the Unicode mathematical italic letters (U+1D434 …,
    with h → ℎ U+210E); anything else is shown as it is.
    """
    if char in _ITALIC_SPECIAL:
        return chr(_ITALIC_SPECIAL[char])
    c = ord(char)
    if 0x41 <= c <= 0x5A:
        return chr(0x1D434 + c - 0x41)
    if 0x61 <= c <= 0x7A:
        return chr(0x1D44E + c - 0x61)
    if 0x391 <= c <= 0x3A9 and c != 0x3A2:
        return chr(0x1D6E2 + c - 0x391)
    if 0x3B1 <= c <= 0x3C9:
        return chr(0x1D6FC + c - 0x3B1)
    return char


def _text(fragment: str) -> str:
    return html.unescape(_TAG.sub("", fragment))


def page_characters(page: str) -> dict[str, set[str]]:
    """The characters each role shows: {"text", "code", "math"} → set of characters.

    ``text`` is everything outside <math> (code included, so that a fallback to the text
    font is covered too) plus printable ASCII (list numbers, punctuation), ``code`` the
    contents of <pre> and <code>, ``math`` the contents of <math> plus the italic forms
    the browser shows for single-letter identifiers (:func:`math_italic`). Attribute
    values (data URIs, alt texts) and the <head> are not shown and not counted.
    """
    body = _HIDDEN.sub("", page)
    maths = _MATH.findall(body)
    rest = _MATH.sub(" ", body)
    math = set(_text("".join(maths)))
    for m in maths:
        for name in _SINGLE_MI.findall(m):
            letters = html.unescape(name)
            if len(letters) == 1:
                math.add(math_italic(letters))
    code = set(_text("".join(inner for _, inner in _CODE.findall(rest))))
    ascii_ = {chr(c) for c in range(0x20, 0x7F)}
    whitespace = {"\n", "\t", "\r"}
    return {"text": (set(_text(rest)) | ascii_) - whitespace,
            "code": (code | ascii_) - whitespace, "math": math - whitespace}


# --- subsetting ---------------------------------------------------------------------------------
def _rename(font: object, family: str) -> None:
    """Write ``family`` as the font's family, full and PostScript names (name IDs 1-6, 16)."""
    postscript = re.sub(r"[^A-Za-z0-9-]", "", family.title().replace(" ", ""))
    subfamily = "Regular"
    for record in font["name"].names:  # type: ignore[index]
        if record.nameID == 2:
            subfamily = record.toUnicode()
            break
    values = {1: family, 3: f"{postscript};subset", 4: f"{family} {subfamily}".strip(),
              6: f"{postscript}-{subfamily}", 16: family, 17: subfamily}
    table = font["name"]  # type: ignore[index]
    for record in table.names:
        if record.nameID in values:
            record.string = values[record.nameID]


#: Size steps of the graded delimiters :func:`add_size_variants` draws (× the base glyph).
SIZE_STEPS = (1.15, 1.32, 1.52, 1.75, 2.0, 2.3)


def add_size_variants(font: object) -> int:
    """Give each stretchy delimiter of the MATH table graded sizes between glyph and assembly.

    DejaVu's MATH table stretches parentheses, brackets, braces and bars only by glyph
    assembly, whose smallest size is about 2.4 em (two 1.2 em pieces), while the glyph is
    about 0.9 em: content a subscript taller than the glyph (cos(q₁)) gets
    2.4 em parentheses. This adds, per delimiter that has an assembly and no size
    variants, the glyph drawn taller by each of :data:`SIZE_STEPS` smaller than the
    assembly (scaled vertically about the math axis, eq. y' = a + s (y − a) with a the
    AxisHeight, so the stroke widths stay), listed as its size variants in increasing
    height, the glyph itself first.

    Args:
        font: a ``fontTools.ttLib.TTFont`` with a TrueType ``glyf`` and a ``MATH`` table.

    Returns:
        the number of glyphs added.
    """
    from fontTools.pens.transformPen import TransformPen
    from fontTools.pens.ttGlyphPen import TTGlyphPen
    from fontTools.ttLib.tables import otTables

    if "MATH" not in font or "glyf" not in font:  # type: ignore[operator]
        return 0
    math = font["MATH"].table  # type: ignore[index]
    variants = math.MathVariants
    if variants is None or variants.VertGlyphCoverage is None:
        return 0
    axis = math.MathConstants.AxisHeight.Value
    glyf, hmtx = font["glyf"], font["hmtx"]  # type: ignore[index]
    glyphs = font.getGlyphSet()  # type: ignore[attr-defined]
    order = list(font.getGlyphOrder())  # type: ignore[attr-defined]
    added = 0
    for name, construction in zip(variants.VertGlyphCoverage.glyphs,
                                  variants.VertGlyphConstruction):
        assembly = construction.GlyphAssembly
        if construction.MathGlyphVariantRecord or assembly is None:
            continue
        base = glyf[name]
        base.recalcBounds(glyf)
        height = base.yMax - base.yMin
        if height <= 0:
            continue
        fixed = [p for p in assembly.PartRecords if not p.PartFlags & 1]
        smallest = sum(p.FullAdvance for p in fixed) - variants.MinConnectorOverlap * (
            len(fixed) - 1)
        records = []
        for size in (1.0, *SIZE_STEPS):
            if size * height >= smallest:
                break
            glyph_name = name
            if size != 1.0:
                glyph_name = f"{name}.size{len(records)}"
                pen = TTGlyphPen(glyphs)
                glyphs[name].draw(TransformPen(pen, (1, 0, 0, size, 0, axis * (1 - size))))
                glyph = pen.glyph()
                glyph.recalcBounds(glyf)
                glyf[glyph_name] = glyph
                hmtx[glyph_name] = (hmtx[name][0], glyph.xMin if glyph.numberOfContours
                                    else 0)
                order.append(glyph_name)
                added += 1
            record = otTables.MathGlyphVariantRecord()
            record.VariantGlyph = glyph_name
            record.AdvanceMeasurement = round(size * height)
            records.append(record)
        construction.MathGlyphVariantRecord = records
        construction.VariantCount = len(records)
    font.setGlyphOrder(order)  # type: ignore[attr-defined]
    return added


def subset_font(source: Path, characters: Iterable[str], rename: str | None = None,
                graded: bool = False) -> bytes:
    """``source`` cut down to ``characters`` as WOFF bytes (deterministic).

    Keeps every OpenType layout feature (kerning, tabular figures), the MATH table with
    the variants and assemblies of the kept glyphs, the hinting and every name record
    (copyright and licence included); the timestamp is not rewritten, so the same input
    gives the same bytes.

    Args:
        source: a TrueType font file.
        characters: the characters to keep (missing ones are skipped).
        rename: new family name (None: keep the font's).
        graded: add graded delimiter sizes to its MATH table (:func:`add_size_variants`).
    """
    import logging

    from fontTools import subset
    from fontTools.ttLib import TTFont

    options = subset.Options()
    options.layout_features = ["*"]
    options.name_IDs = ["*"]
    options.name_languages = ["*"]
    options.name_legacy = True
    options.notdef_outline = True
    options.drop_tables = [*options.drop_tables, "FFTM"]
    options.flavor = "woff"
    previous = logging.getLogger("fontTools").level
    logging.getLogger("fontTools").setLevel(logging.ERROR)
    try:
        font = TTFont(source, recalcTimestamp=False)
        subsetter = subset.Subsetter(options)
        subsetter.populate(unicodes=sorted({ord(c) for c in characters}))
        subsetter.subset(font)
        if graded:
            add_size_variants(font)
        if rename:
            _rename(font, rename)
        font.flavor = "woff"
        buf = io.BytesIO()
        font.save(buf)
    finally:
        logging.getLogger("fontTools").setLevel(previous)
    return buf.getvalue()


def coverage(source: Path) -> set[str]:
    """The characters ``source`` has a glyph for."""
    from fontTools.ttLib import TTFont

    return {chr(c) for c in TTFont(source, lazy=True).getBestCmap()}


def embedded_fonts(page: str, outdir: Path) -> str:
    """Subset :data:`FACES` to ``page``, write them and the licences to ``outdir/fonts``.

    A subset already in ``outdir/fonts`` for the same source and characters (recorded in
    ``fonts.json``) is reused, so a rebuild into the same folder does not subset again.

    Returns:
        the CSS ``@font-face`` rules, each font embedded as a WOFF data URI.
    """
    chars = page_characters(page)
    folder = outdir / "fonts"
    folder.mkdir(parents=True, exist_ok=True)
    manifest_path = folder / "fonts.json"
    try:
        manifest = json.loads(manifest_path.read_text(encoding="utf-8"))
    except (OSError, ValueError):
        manifest = {}
    source_dir = font_dir()
    rules = []
    math_done: set[str] = set()
    for face in FACES:
        source = source_dir / face.source
        wanted = chars[face.role]
        if face.family == MATH_LETTERS:  # only what the first math font lacks
            wanted = wanted - math_done
        stat = source.stat()
        key = hashlib.sha256(
            f"{face.source} {stat.st_size} {face.rename} {face.role} {SIZE_STEPS} "
            f"{''.join(sorted(wanted))}".encode()).hexdigest()
        target = folder / face.file
        data = target.read_bytes() if (manifest.get(face.file) == key
                                       and target.is_file()) else b""
        if not data:
            data = subset_font(source, wanted, face.rename, graded=face.role == "math")
            write_bytes_atomic(target, data)
            manifest[face.file] = key
        if face.family == MATH:
            math_done = wanted & coverage(source)
        uri = "data:font/woff;base64," + base64.b64encode(data).decode()
        rules.append(f'@font-face{{font-family:"{face.family}";src:url({uri}) '
                     f'format("woff");font-weight:{face.weight};font-style:{face.style};'
                     "font-display:block}")
    for name in LICENCES:
        licence = (source_dir / name).read_bytes()
        if not (folder / name).is_file() or (folder / name).read_bytes() != licence:
            write_bytes_atomic(folder / name, licence)
    write_text_atomic(manifest_path, json.dumps(manifest, indent=1, sort_keys=True) + "\n")
    return "".join(rules)


__all__ = ["FACES", "FAMILY", "Face", "embedded_fonts", "font_dir", "math_italic",
           "page_characters", "subset_font"]
