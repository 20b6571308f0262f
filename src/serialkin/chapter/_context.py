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
from dataclasses import dataclass, field, replace
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
    """A warm wall-clock measurement (or a ratio of two): median and spread of repeated runs.

    Two kinds of spread, told apart by ``blocks``:

    * ``blocks == 1`` (:meth:`ReportContext.timing`, :meth:`ReportContext.interleaved`):
      the runs were taken back to back and the spread is their full range, min..max;
    * ``blocks > 1`` (:class:`TimingBench`): the runs were taken in ``blocks`` blocks
      spread over a section's build, and the spread is the 5th to the 95th percentile of
      all of them (numpy's linear interpolation; for 21 runs, the second fastest and the
      second slowest), so that one stray run at either end does not set it.

    Attributes:
        median: median of all timed runs [s] (for a ratio: of the per-round ratios [1]).
        low: lower end of the spread [s or 1].
        high: upper end of the spread [s or 1].
        n: number of timed runs (for a ratio: of rounds).
        warm: True when untimed warm-up calls preceded the timed ones (JIT compiled, caches
            filled).
        blocks: number of blocks the runs were taken in (1: back to back).
        unit: "s" for times, "×" for ratios.
        label: what was timed (the name given to :meth:`TimingBench.add`), "" if unnamed.
        runs: every timed run in the order taken [s or 1], shape (n,).
    """

    median: float
    low: float
    high: float
    n: int
    warm: bool = True
    blocks: int = 1
    unit: str = "s"
    label: str = ""
    runs: tuple[float, ...] = field(default=(), repr=False, compare=False)

    @property
    def text(self) -> str:
        """The timing as printed, e.g. "0.91 ms (median of 7 warm runs, spread 0.85–0.97 ms)".

        Taken in blocks: "7.55 ms (median of 21 warm runs in 7 blocks, 5th–95th
        percentile 7.47–7.62 ms)"; a ratio: "5.2× (median of 21 rounds in 7 blocks, 5th–95th
        percentile 5.1–5.4×)".
        """
        if self.unit == "×":
            value = f"{format_ratio(self.median)}×"
            low, high, unit = format_ratio(self.low), format_ratio(self.high), "×"
            kind = "rounds"
        else:
            scale, unit = _time_unit(self.median)
            value = f"{_fmt3(self.median * scale)} {unit}"
            low, high, unit = _fmt3(self.low * scale), _fmt3(self.high * scale), f" {unit}"
            kind = "warm runs" if self.warm else "runs, first one cold"
        if self.blocks > 1:
            return (f"{value} (median of {self.n} {kind} in {self.blocks} blocks, 5th–95th "
                    f"percentile {low}–{high}{unit})")
        return f"{value} (median of {self.n} {kind}, spread {low}–{high}{unit})"

    def __str__(self) -> str:
        return self.text

    def scaled(self, factor: float, label: str) -> Timing:
        """Every run times ``factor`` [1], with the median and spread taken of those runs.

        For a quantity proportional to the timed one in every run, e.g. a per-iteration
        ratio from a whole-path ratio when each run makes the same iterations.
        """
        runs = np.asarray(self.runs, dtype=float) * factor
        if not runs.size:
            return replace(self, median=self.median * factor, low=self.low * factor,
                           high=self.high * factor, label=label)
        low, high = (np.percentile(runs, [5.0, 95.0]) if self.blocks > 1
                     else (runs.min(), runs.max()))
        return replace(self, median=float(np.median(runs)), low=float(low), high=float(high),
                       runs=tuple(float(r) for r in runs), label=label)


class TimingBench:
    """Warm timings of several functions, their runs taken in blocks spread over a build.

    Runs of one function taken back to back see one state of the machine; a rebuild sees
    another (what the other worker process or other programs do, the clock frequency, the
    memory layout of the process), so two builds' medians can differ by more than the
    min..max of back-to-back runs. A bench therefore takes the runs of every registered
    function in blocks: a block is ``rounds`` rounds, a round runs each function once
    (their order rotated from round to round, so that none always runs first or after the
    same one), and the section calls :meth:`block` between its other work, so that the
    blocks sample the machine over the section's whole build. A :class:`Timing` is the
    median of all runs with their 5th to 95th percentile as its spread: the run-to-run
    variation over the whole build, which a rebuild's median falls into where the
    min..max of back-to-back runs was too narrow (docs/chapter-report.md). A ratio of two
    functions is taken per round (both ran in the same round of one process, under one
    machine state), its median and spread likewise.

    Made by :meth:`ReportContext.bench`; the timings it gives are added to the
    context's ``timings`` once each.
    """

    def __init__(self, clock: Callable[[], float], record: list[Timing], rounds: int = 3
                 ) -> None:
        from serialkin._checks import check_int

        self._clock = clock
        self._record = record
        self._rounds = check_int(rounds, "rounds", minimum=1)
        self._fns: dict[str, Callable[[], object]] = {}
        self._runs: dict[str, list[list[float]]] = {}
        self._round = 0
        self._given: dict[str, Timing] = {}

    @property
    def names(self) -> list[str]:
        """The registered functions' names, in the order added."""
        return list(self._fns)

    @property
    def blocks(self) -> int:
        """Blocks taken so far."""
        return len(next(iter(self._runs.values()), []))

    def add(self, name: str, fn: Callable[[], object], warmup: int = 1) -> object:
        """Register ``fn`` under ``name`` and call it ``warmup`` times, untimed.

        Returns:
            what the last warm-up call returned (e.g. the trajectory of a tracking run,
            so that the section need not run it again).

        Raises:
            InputError: ``name`` already registered, a block already taken (every
                function must run in every block), or ``warmup`` below 1.
        """
        from serialkin._checks import check_int

        warmup = check_int(warmup, "warmup", minimum=1)
        if name in self._fns:
            raise InputError(f"name must be new to the bench, got {name!r} which is "
                             f"registered already (names: {', '.join(self._fns)})")
        if self.blocks:
            raise InputError(f"add({name!r}, ...) must come before the first block: every "
                             f"function runs in every block, and {self.blocks} were taken")
        result: object = None
        for _ in range(warmup):
            result = fn()
        self._fns[name] = fn
        self._runs[name] = []
        return result

    def block(self) -> None:
        """Take one block: ``rounds`` rounds, each running every function once, timed.

        Raises:
            InputError: no function registered yet.
        """
        if not self._fns:
            raise InputError("block() needs a function to time: call add(name, fn) first")
        if self._given:
            raise InputError("block() after timing() or ratio(): the timings already given "
                             f"({', '.join(self._given)}) would not include it")
        names = list(self._fns)
        taken: dict[str, list[float]] = {name: [] for name in names}
        clock = self._clock
        for _ in range(self._rounds):
            k = self._round % len(names)
            for name in names[k:] + names[:k]:
                t0 = clock()
                self._fns[name]()
                taken[name].append(clock() - t0)
            self._round += 1
        for name in names:
            self._runs[name].append(taken[name])

    def _blocks_of(self, name: str) -> list[list[float]]:
        if name not in self._runs:
            raise InputError(f"name must be a registered function, got {name!r} (registered: "
                             f"{', '.join(self._runs) or 'none'})")
        blocks = self._runs[name]
        if not blocks:
            raise InputError(f"no block taken yet: call block() before asking for {name!r}")
        return blocks

    @staticmethod
    def _summary(blocks: list[list[float]], unit: str, label: str) -> Timing:
        flat = [t for b in blocks for t in b]
        if len(blocks) > 1:
            low, high = (float(v) for v in np.percentile(flat, [5.0, 95.0]))
        else:
            low, high = min(flat), max(flat)
        return Timing(median=float(np.median(flat)), low=low, high=high, n=len(flat),
                      warm=True, blocks=len(blocks), unit=unit, label=label,
                      runs=tuple(flat))

    def timing(self, name: str) -> Timing:
        """The :class:`Timing` of ``name`` over every block taken (added to the context once)."""
        if name not in self._given:
            t = self._summary(self._blocks_of(name), "s", name)
            self._given[name] = t
            self._record.append(t)
        return self._given[name]

    def ratio(self, numerator: str, denominator: str) -> Timing:
        """Time of ``numerator`` / time of ``denominator`` per round, as a :class:`Timing` [1].

        Both ran in the same round (one process, one machine state): the ratio of each
        round, the median over all rounds and their 5th to 95th percentile.
        """
        label = f"{numerator} / {denominator}"
        if label not in self._given:
            a, b = self._blocks_of(numerator), self._blocks_of(denominator)
            ratios = [[x / y for x, y in zip(ba, bb)] for ba, bb in zip(a, b)]
            t = self._summary(ratios, "×", label)
            self._given[label] = t
            self._record.append(t)
        return self._given[label]


def _time_unit(seconds: float) -> tuple[float, str]:
    """Scale and unit for ``seconds``: s from 1 s, ms from 0.1 ms, else µs."""
    if seconds >= 1.0:
        return 1.0, "s"
    if seconds >= 1e-4:
        return 1e3, "ms"
    return 1e6, "µs"


def format_ratio(value: float) -> str:
    """A ratio to two significant digits, from 100 up as a whole number ("3,100", not "3.1e+03")."""
    if value >= 100:
        return f"{float(f'{value:.2g}'):,.0f}"
    return f"{value:.2g}"


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
    r"^(?:[<>≤≥]\s*)?[+\-−]?(?:\d[\d,\u202f ]*(?:\.\d*)?|\.\d+)(?:[eE][+\-−]?\d+)?"
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


#: A table cell in place of a number that is not reproducible from build to build (the
#: page says why); like an empty cell, it does not decide its column's alignment.
VARIES = "varies"


def _is_blank(value: object) -> bool:
    """Empty text or :data:`VARIES`: a cell that leaves its column's alignment to the others."""
    return isinstance(value, str) and not hasattr(value, "__html__") and (
        not value.strip() or value.strip() == VARIES)


#: A number as the page prints it, kept on one line with what belongs to it: an optional
#: name and "=" ("q1 = 80.5°"), a comparison ("&gt; 1,000", escaped), a sign, an exponent
#: ("2.2e-16"), a unit ("0.098 ms") and a second number of a range ("0.285–0.438 ms").
_NUMBER_PART = r"[+\-−±]?(?:\d+(?:,\d{3})*(?:\.\d+)?|\.\d+)(?:e[+\-−]?\d+)?"
_UNIT = r"(?:\s?(?:%|°|×|µs|ms|ns|mm|µm|m²|m³|m/rad|mrad|µrad|rad|deg|m|s|R)(?![\w²³]))?"
NUMBER_RUN = re.compile(
    r"(?<![\w.,#&;+\-−±])"
    r"(?:[A-Za-zα-ωΑ-Ω][\w]{0,6} ?= ?)?"
    r"(?:(?:&lt;|&gt;|[<>≤≥~≈]) ?)?"
    + _NUMBER_PART + _UNIT
    + r"(?:\s?[–\-]\s?" + _NUMBER_PART + _UNIT + r")?"
    r"(?!\w|\.\d)")
#: Where a browser may break a line inside a :data:`NUMBER_RUN` match.
_BREAKABLE = re.compile(r"[\s–/]|(?<=.)[-−]")
#: Elements whose text is left as it is: code, mathematics, and cells already on one line.
_VERBATIM = ("math", "pre", "code", "style", "script", "title")
_TAG = re.compile(r"(<[^>]*>)")
_TAG_PARTS = re.compile(r"<(/?)([A-Za-z][\w-]*)([^>]*)>")


def _keeps_verbatim(name: str, attrs: str) -> bool:
    return (name in _VERBATIM or (name == "td" and 'class="num"' in attrs)
            or (name == "table" and 'class="matrix"' in attrs))


def keep_numbers_together(markup: str) -> str:
    """Wrap each number of the text that a line could break inside in ``<span class="nowrap">``.

    A number with its unit ("0.098 ms"), a range ("0.285–0.438 ms", "1.04-18.6 ms"), an
    exponent ("2.2e-16"), a bound ("&gt; 1,000") or an assignment ("q1 = 80.5°"): the
    matches of :data:`NUMBER_RUN` that hold a break opportunity (a space, a dash, a
    slash). Only text is changed, never a tag, an attribute or an entity; the text of
    ``math``, ``pre``, ``code``, numeric cells and matrices (one line already) is left
    alone.
    """
    def wrap(m: re.Match[str]) -> str:
        text = m.group(0)
        return f'<span class="nowrap">{text}</span>' if _BREAKABLE.search(text) else text

    out = []
    verbatim: list[str] = []
    for part in _TAG.split(markup):
        if part.startswith("<"):
            tag = _TAG_PARTS.match(part)
            if tag:
                closing, name, attrs = tag.group(1), tag.group(2).lower(), tag.group(3)
                if not closing and _keeps_verbatim(name, attrs) and not attrs.endswith("/"):
                    verbatim.append(name)
                elif closing and verbatim and verbatim[-1] == name:
                    verbatim.pop()
            out.append(part)
        else:
            out.append(part if verbatim else NUMBER_RUN.sub(wrap, part))
    return "".join(out)


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
                   high=float(max(runs)), n=repeat, warm=warmup >= 1, runs=tuple(runs))
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

        def summary(runs: list[float], unit: str = "s") -> Timing:
            return Timing(median=float(np.median(runs)), low=float(min(runs)),
                          high=float(max(runs)), n=repeat, warm=warmup >= 1, unit=unit,
                          runs=tuple(runs))

        ratios = [b / a for a, b in zip(a_runs, b_runs)]
        ta, tb = summary(a_runs), summary(b_runs)
        self.timings.extend([ta, tb])
        return ta, tb, summary(ratios, "×")

    def bench(self, rounds: int = 3) -> TimingBench:
        """A :class:`TimingBench` on this context's clock.

        Register the functions to time, then take blocks of ``rounds`` rounds between the
        section's other work; its timings (and ratios) are added to :attr:`timings` when
        asked for.
        """
        return TimingBench(self.clock, self.timings, rounds)

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
    "TimingBench",
    "VARIES",
    "compact_png",
    "format_number",
    "format_ratio",
    "format_vector",
    "keep_numbers_together",
]
