"""What a section builder gets: :class:`ReportContext`, :class:`Section` and formatting.

The helpers described in :mod:`serialkin.chapter.report` (mathematics as MathML, warm
timings, "Reproduce" boxes, tables, matrices and palette PNG figures). Section modules
import them from here, never from :mod:`serialkin.chapter.report` (which imports the
sections: the dependency runs one way); the report re-exports every public name of this
module for other callers.
"""

from __future__ import annotations

import base64
import html
import io
import re
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from serialkin._io import write_bytes_atomic
from serialkin.errors import InputError

_NUMBER = re.compile(r"^\s*(\d+(?:\.\d+)*)\.?\s+(.*)$", re.DOTALL)


@dataclass
class Section:
    """One section of the report.

    Attributes:
        title: heading with the chapter's number first, e.g. "3 Forward kinematics" or
            "5.1 Analytical Jacobian" (a trailing dot after the number is accepted). The
            report prints the number once, in the contents and in the heading. A section
            whose number repeats the previous section's (e.g. a second "5.3 ...") continues
            it: it is shown under the same heading with ``part`` as its sub-heading.
        equations: the chapter equation numbers it demonstrates, e.g. "eqs 10-18".
        html: body HTML (use :class:`ReportContext` helpers to make tables and figures).
        anchor: HTML id (default: the module name, then ``<module>-<k>``).
        part: sub-heading when the section continues a previous number (optional).
    """

    title: str
    equations: str
    html: str
    anchor: str = ""
    part: str = ""

    @property
    def number(self) -> str:
        """The chapter's section number, e.g. "5.1" ("" when the title has none)."""
        m = _NUMBER.match(self.title)
        return m.group(1) if m else ""

    @property
    def name(self) -> str:
        """The title without its number."""
        m = _NUMBER.match(self.title)
        return m.group(2).strip() if m else self.title.strip()


@dataclass(frozen=True)
class Timing:
    """A warm wall-clock measurement: median and spread of repeated runs.

    Attributes:
        median: median time of one call [s].
        low: fastest run [s] (the spread is the full range, min..max).
        high: slowest run [s].
        n: number of timed runs.
        warm: True when untimed warm-up calls preceded the timed ones (JIT compiled, caches
            filled).
    """

    median: float
    low: float
    high: float
    n: int
    warm: bool = True

    @property
    def text(self) -> str:
        """E.g. "0.91 ms (median of 7 warm runs, spread 0.85–0.97 ms)"."""
        scale, unit = _time_unit(self.median)
        kind = "warm runs" if self.warm else "runs, first one cold"
        return (f"{_fmt3(self.median * scale)} {unit} (median of {self.n} {kind}, spread "
                f"{_fmt3(self.low * scale)}–{_fmt3(self.high * scale)} {unit})")

    def __str__(self) -> str:
        return self.text


def _time_unit(seconds: float) -> tuple[float, str]:
    """Scale and unit for ``seconds``: s from 1 s, ms from 0.1 ms, else µs."""
    if seconds >= 1.0:
        return 1.0, "s"
    if seconds >= 1e-4:
        return 1e3, "ms"
    return 1e6, "µs"


def _fmt3(value: float) -> str:
    """Three significant digits, no exponent for the ranges :func:`_time_unit` produces."""
    return f"{value:.3g}" if value < 1000 else f"{value:.0f}"


class Html(str):
    """A string of markup that :meth:`ReportContext.table` inserts as it is (not escaped)."""

    __slots__ = ()

    def __html__(self) -> str:
        return str(self)


def _no_negative_zero(text: str) -> str:
    """Drop the sign of a formatted number that rounds to zero ("-0.0000" → "0.0000")."""
    if text.startswith("-"):
        try:
            if float(text) == 0.0:
                return text[1:]
        except ValueError:
            pass
    return text


def format_number(value: float, fmt: str = "{:.6g}") -> str:
    """Format a number with ``fmt``, never printing a negative zero."""
    return _no_negative_zero(fmt.format(value))


def format_vector(values: object, fmt: str = "{:.6g}") -> str:
    """A vector as "(a, b, c)" with :func:`format_number` (no negative zero, no "0.")."""
    flat = np.asarray(values, dtype=float).ravel()
    return "(" + ", ".join(format_number(float(v), fmt) for v in flat) + ")"


_NUMERIC_TEXT = re.compile(
    r"^[+\-−]?(?:\d[\d,\u202f ]*(?:\.\d*)?|\.\d+)(?:[eE][+\-−]?\d+)?"
    r"(?:\s*(?:%|°|s|ms|µs|m|mm|rad|m²|×))?$|^[+\-−]?(?:∞|inf|nan)$"
)


def _is_numeric(value: object) -> bool:
    """True for numbers and for text that reads as one number (right-aligned in tables)."""
    if isinstance(value, bool):
        return False
    if isinstance(value, (int, float, np.integer, np.floating)):
        return True
    return isinstance(value, str) and not hasattr(value, "__html__") and bool(
        _NUMERIC_TEXT.match(value.strip()))


def _is_blank(value: object) -> bool:
    return isinstance(value, str) and not hasattr(value, "__html__") and not value.strip()


#: First code point of the Unicode mathematical alphanumerics per style, for A, a, Α, α, 0.
_MATH_ALPHA = {
    "bold": (0x1D400, 0x1D41A, 0x1D6A8, 0x1D6C2, 0x1D7CE),
    "bold-italic": (0x1D468, 0x1D482, 0x1D71C, 0x1D736, 0x1D7CE),
}
#: Greek letters after ω in the mathematical alphabets: ∂ ϵ ϑ ϰ ϕ ϱ ϖ.
_GREEK_TAIL = "\u2202\u03f5\u03d1\u03f0\u03d5\u03f1\u03d6"
_VARIANT = re.compile(r'<(mi|mn|mo|mtext)( [^>]*?)? mathvariant="(bold|bold-italic)"([^>]*)>'
                      r"([^<]*)</\1>")


def _styled(char: str, style: str) -> str:
    """``char`` as the Unicode mathematical alphanumeric of ``style`` (unchanged if none)."""
    upper, lower, greek_upper, greek_lower, digit = _MATH_ALPHA[style]
    c = ord(char)
    if 0x41 <= c <= 0x5A:
        return chr(upper + c - 0x41)
    if 0x61 <= c <= 0x7A:
        return chr(lower + c - 0x61)
    if 0x30 <= c <= 0x39:
        return chr(digit + c - 0x30)
    if 0x391 <= c <= 0x3A9:
        return chr(greek_upper + c - 0x391)
    if 0x3B1 <= c <= 0x3C9:
        return chr(greek_lower + c - 0x3B1)
    if char in _GREEK_TAIL:
        return chr(greek_lower + 25 + _GREEK_TAIL.index(char))
    return char


def _bold_as_unicode(mathml: str) -> str:
    r"""Replace ``mathvariant="bold…"`` by Unicode bold letters, which MathML Core renders.

    Chromium implements MathML Core, which ignores ``mathvariant`` other than "normal";
    latex2mathml writes ``\mathbf`` letters as Unicode bold already but ``\boldsymbol``
    and bold digits as a ``mathvariant`` attribute, shown upright and thin.
    """
    def sub(m: re.Match[str]) -> str:
        tag, before, style, after, text = m.groups()
        styled = "".join(_styled(ch, style) for ch in html.unescape(text))
        return f"<{tag}{before or ''}{after}>{html.escape(styled, quote=False)}</{tag}>"

    return _VARIANT.sub(sub, mathml)


def _latex_to_mathml(latex: str, display: str) -> str:
    from latex2mathml.converter import convert

    return _bold_as_unicode(convert(latex, display=display))


@dataclass
class ReportContext:
    """What a section builder gets: the output folder and helpers for figures and tables.

    Attributes:
        outdir: the report's folder (figures go to ``figures/`` below it).
        quiet: no progress output.
        figures: the figure files written so far, relative to ``outdir``.
        timings: the :class:`Timing` of every :meth:`timing` call so far.
        clock: the clock :meth:`timing` reads [s] (default ``time.perf_counter``; a test
            passes a fake one to check the arithmetic without measuring anything).
    """

    outdir: Path
    quiet: bool = False
    figures: list[str] = field(default_factory=list)
    timings: list[Timing] = field(default_factory=list)
    clock: Callable[[], float] = field(default=time.perf_counter, repr=False, compare=False)

    # --- mathematics -------------------------------------------------------------------------
    @staticmethod
    def eq(latex: str, number: str | None = None) -> str:
        """A display equation: LaTeX rendered as MathML, the chapter's number on the right.

        Args:
            latex: the equation in LaTeX (amsmath subset understood by latex2mathml; sympy's
                ``sp.latex`` output works).
            number: the chapter's equation number, e.g. "49" (shown as "(49)"), or None.

        Returns:
            HTML: a block whose equation scrolls sideways when wider than the page.
        """
        math = _latex_to_mathml(latex, "block")
        num = (f'<span class="eqno">({html.escape(str(number))})</span>'
               if number is not None else "")
        return f'<div class="eqn"><div class="eqbody">{math}</div>{num}</div>'

    @staticmethod
    def imath(latex: str) -> str:
        """Inline mathematics: LaTeX rendered as MathML inside the running text."""
        return _latex_to_mathml(latex, "inline")

    # --- timings -------------------------------------------------------------------------------
    def timing(self, fn: Callable[[], object], *, warmup: int = 1, repeat: int = 7) -> Timing:
        """Time ``fn()`` by :attr:`clock`: ``warmup`` untimed calls, then ``repeat`` timed ones.

        Returns:
            :class:`Timing` with the median and the full range (min..max) of the timed
            calls [s]; ``warm`` is True when ``warmup >= 1``.
        """
        if repeat < 1:
            raise InputError(f"repeat must be at least 1, got {repeat}")
        for _ in range(max(0, warmup)):
            fn()
        runs = []
        clock = self.clock
        for _ in range(repeat):
            t0 = clock()
            fn()
            runs.append(clock() - t0)
        t = Timing(median=float(np.median(runs)), low=float(min(runs)),
                   high=float(max(runs)), n=repeat, warm=warmup >= 1)
        self.timings.append(t)
        return t

    def interleaved(self, first: Callable[[], object], second: Callable[[], object], *,
                    warmup: int = 1, repeat: int = 9) -> tuple[Timing, Timing, Timing]:
        """Time two functions in alternation, for a ratio that one machine state affects alike.

        ``warmup`` untimed calls of each, then ``repeat`` pairs, the order inside a pair
        alternating (first-second, second-first, …) so that neither always runs on a
        cache or clock warmed by the other.

        Returns:
            (timing of ``first``, timing of ``second``, the ratio second / first of each pair
            as a :class:`Timing` whose numbers are ratios, not seconds). The two timings
            are added to :attr:`timings`.
        """
        if repeat < 1:
            raise InputError(f"repeat must be at least 1, got {repeat}")
        for _ in range(max(0, warmup)):
            first()
            second()
        clock = self.clock
        a_runs, b_runs = [], []
        for k in range(repeat):
            pair = (first, second) if k % 2 == 0 else (second, first)
            times = []
            for fn in pair:
                t0 = clock()
                fn()
                times.append(clock() - t0)
            ta, tb = times if k % 2 == 0 else times[::-1]
            a_runs.append(ta)
            b_runs.append(tb)

        def summary(runs: list[float]) -> Timing:
            return Timing(median=float(np.median(runs)), low=float(min(runs)),
                          high=float(max(runs)), n=repeat, warm=warmup >= 1)

        ratios = [b / a for a, b in zip(a_runs, b_runs)]
        ta, tb = summary(a_runs), summary(b_runs)
        self.timings.extend([ta, tb])
        return ta, tb, summary(ratios)

    # --- reproduction --------------------------------------------------------------------------
    @staticmethod
    def reproduce(code: str, shell: bool = False, expect: Sequence[object] = ()) -> str:
        """A "Reproduce" box with the Python snippet or ``serialkin ...`` command.

        Args:
            code: the exact text a reader copies: Python run by ``python -c`` in a fresh
                interpreter, or shell lines with the installed ``serialkin`` on PATH.
            shell: True for shell lines.
            expect: the numbers the box prints, in the order it prints them, each formatted
                exactly as the page shows it (pass the page's own formatted strings, so the
                box and the page come from one computation in the same units).
                tests/chapter/test_reproduce.py runs every box and checks that its output
                contains these numbers, in order, to their printed precision, and that the
                page shows each of them in the box's section.

        Returns:
            HTML: the box, with the expected numbers in its ``data-expect`` attribute (JSON).
        """
        import json

        kind = "shell" if shell else "Python"
        tokens = [str(e).replace("\u2212", "-") for e in expect]
        data = html.escape(json.dumps(tokens), quote=True)
        return (f'<div class="repro" data-kind="{kind.lower()}" data-expect="{data}">'
                f'<span class="repro-label">Reproduce ({kind})</span>'
                f'<pre><code>{html.escape(code.strip())}</code></pre></div>')

    # --- figures -------------------------------------------------------------------------------
    def figure(self, fig: object, name: str, caption: str = "") -> str:
        """Save a matplotlib figure as ``figures/<name>.png``; return an <img> block (inline)."""
        import matplotlib.pyplot as plt

        buf = io.BytesIO()
        fig.savefig(buf, format="png", dpi=110, bbox_inches="tight")  # type: ignore[attr-defined]
        plt.close(fig)  # type: ignore[arg-type]
        return self.file_figure(compact_png(buf.getvalue()), f"{name}.png", caption)

    def file_figure(self, data: bytes, filename: str, caption: str = "") -> str:
        """Store image bytes (PNG or GIF) under ``figures/``; return an inline <figure> block."""
        path = self.outdir / "figures" / filename
        write_bytes_atomic(path, data)
        rel = f"figures/{filename}"
        self.figures.append(rel)
        mime = "image/gif" if filename.endswith(".gif") else "image/png"
        b64 = base64.b64encode(data).decode()
        cap = html.escape(caption)
        return (
            f'<figure><img src="data:{mime};base64,{b64}" alt="{cap}" data-file="{rel}">'
            f'<figcaption>{cap} <a href="{rel}">({filename})</a></figcaption></figure>'
        )

    # --- tables --------------------------------------------------------------------------------
    @staticmethod
    def table(rows: Sequence[Sequence[object]], header: Sequence[object] | None = None,
              fmt: str = "{:.6g}") -> str:
        """An HTML table: numeric columns right-aligned, text columns left-aligned.

        A column is numeric when every non-empty cell is a number or a string that reads as
        one (e.g. "1.2e-05", "98 %"). Floats are formatted with ``fmt``, never as a negative
        zero; :class:`Html` cells and header cells (e.g. MathML, a matrix) are inserted
        unescaped. A header cell is aligned like its column.
        """

        def cell(v: object) -> str:
            if hasattr(v, "__html__"):
                return v.__html__()  # type: ignore[attr-defined]
            if isinstance(v, (float, np.floating)):
                return format_number(float(v), fmt)
            if isinstance(v, str):
                return html.escape(_no_negative_zero(v))
            return html.escape(str(v))

        ncol = max([len(r) for r in rows] + [len(header or ())])
        numeric = [any(j < len(r) for r in rows) and all(
            _is_numeric(r[j]) for r in rows if j < len(r) and not _is_blank(r[j]))
            for j in range(ncol)]
        cls = ["num" if x else "txt" for x in numeric]

        def head_cell(h: object) -> str:
            return h.__html__() if hasattr(h, "__html__") else html.escape(str(h))  # type: ignore[attr-defined]

        head = ""
        if header:
            head = "<thead><tr>" + "".join(
                f'<th class="{cls[j]}">{head_cell(h)}</th>' for j, h in enumerate(header)
            ) + "</tr></thead>"
        body = "".join("<tr>" + "".join(f'<td class="{cls[j]}">{cell(v)}</td>'
                                        for j, v in enumerate(r)) + "</tr>" for r in rows)
        return f'<div class="tablewrap"><table>{head}<tbody>{body}</tbody></table></div>'

    @staticmethod
    def matrix(M: object, fmt: str = "{:.4f}") -> str:
        """A numeric matrix as a bracketed HTML table (right-aligned, no negative zero)."""
        a = np.atleast_2d(np.asarray(M, dtype=float))
        body = "".join(
            "<tr>" + "".join(
                f"<td>{format_number(0.0 if abs(v) < 5e-13 else float(v), fmt)}</td>"
                for v in r) + "</tr>" for r in a
        )
        return Html(f'<table class="matrix">{body}</table>')

    @staticmethod
    def algorithm(title: str, steps: Sequence[tuple[int, str]], note: str = "") -> str:
        """An algorithm box of the chapter as numbered steps.

        Args:
            title: the algorithm's name, as the chapter prints it.
            steps: (indent level, step HTML) in order; numbered 1, 2, … as in the chapter.
            note: HTML after the steps (e.g. which steps the ERRATA corrects).
        """
        items = "".join(f'<li style="margin-left:{1.6 * level:g}em">{text}</li>'
                        for level, text in steps)
        return (f'<div class="algobox"><p><b>Algorithm:</b> {html.escape(title)}</p>'
                f'<ol class="algorithm">{items}</ol>{note}</div>')

    @staticmethod
    def code(text: str) -> str:
        """Preformatted text (program output; never mathematics: use :meth:`eq`)."""
        return f"<pre>{html.escape(text)}</pre>"


def compact_png(data: bytes) -> bytes:
    """Re-encode a PNG with a 256-colour palette (about 3× smaller for line plots).

    Pillow's fast octree quantiser; palette entries within 6 levels of white are snapped
    to pure white so backgrounds stay white.
    """
    from PIL import Image

    with Image.open(io.BytesIO(data)) as im:
        rgb = im.convert("RGB")
    q = rgb.quantize(colors=256, method=Image.Quantize.FASTOCTREE, dither=Image.Dither.NONE)
    pal = q.getpalette() or []
    for k in range(0, len(pal) - 2, 3):
        if min(pal[k:k + 3]) >= 249:
            pal[k:k + 3] = [255, 255, 255]
    q.putpalette(pal)
    out = io.BytesIO()
    q.save(out, format="PNG")
    return out.getvalue()


__all__ = [
    "Html",
    "ReportContext",
    "Section",
    "Timing",
    "compact_png",
    "format_number",
    "format_vector",
]
