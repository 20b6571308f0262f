"""The report's helpers: MathML equations, warm timings, reproduce boxes, table alignment."""

from __future__ import annotations

import re
import xml.etree.ElementTree as ET

import numpy as np
import pytest

from serialkin.chapter.report import Html, ReportContext, Section, Timing, format_number
from serialkin.errors import InputError

MATHML = "{http://www.w3.org/1998/Math/MathML}"


def _math_elements(fragment: str) -> list[ET.Element]:
    root = ET.fromstring(f"<div>{fragment}</div>")
    return list(root.iter(f"{MATHML}math"))


def test_eq_is_valid_mathml_with_number():
    """eq() gives well-formed XML with one block <math> and the number shown once, on the right."""
    out = ReportContext.eq(r"\dot{\mathbf{q}} = \mathbf{J}^{\dagger}(\mathbf{q}) \dot{\mathbf{x}}",
                           number="40")
    maths = _math_elements(out)
    assert len(maths) == 1
    assert maths[0].get("display") == "block"
    assert out.count("(40)") == 1 and 'class="eqno"' in out
    assert "\\" not in out  # no LaTeX survives


def test_eq_without_number_and_imath_inline():
    """No number → no eqno span; imath() is one inline <math>."""
    assert "eqno" not in ReportContext.eq("x = 1")
    maths = _math_elements(ReportContext.imath(r"\theta_1"))
    assert len(maths) == 1 and maths[0].get("display") == "inline"


def test_eq_escapes_markup_characters():
    """<, > and & in the LaTeX become character references, never raw markup."""
    out = ReportContext.eq(r"a < b \text{ and } c > d")
    maths = _math_elements(out)  # parses, so nothing is left unescaped
    text = "".join(maths[0].itertext())
    assert "<" in text and ">" in text
    assert "<b" not in out.replace("<mrow", "")  # no stray tag from the input
    assert ReportContext.eq("x", number="<1>").count("&lt;1&gt;") == 1


def test_sympy_matrix_converts():
    """The LaTeX of a sympy matrix becomes a MathML <mtable> with the right shape."""
    import sympy as sp

    q = sp.Symbol("q_1", real=True)
    out = ReportContext.eq(sp.latex(sp.Matrix([[sp.cos(q), -sp.sin(q)], [sp.sin(q), sp.cos(q)]])))
    root = _math_elements(out)[0]
    assert len(list(root.iter(f"{MATHML}mtr"))) == 2
    assert len(list(root.iter(f"{MATHML}mtd"))) == 4


class _FakeClock:
    """A clock that advances only when the timed function says so: durations are known."""

    def __init__(self) -> None:
        self.now = 100.0

    def __call__(self) -> float:
        return self.now


def test_timing_warms_up_before_timing(tmp_path):
    """Warm-up calls are untimed; median and min..max come from the timed calls alone."""
    clock = _FakeClock()
    durations = iter([30.0, 0.003, 0.001, 0.002, 0.005, 0.004])  # first: the "compilation"
    calls = []

    def fn():
        clock.now += next(durations)
        calls.append(1)

    ctx = ReportContext(outdir=tmp_path, clock=clock)
    t = ctx.timing(fn, warmup=1, repeat=5)
    assert len(calls) == 6
    assert t.warm and t.n == 5
    assert t.median == pytest.approx(0.003) and t.low == pytest.approx(0.001)
    assert t.high == pytest.approx(0.005)  # the 30 s warm-up call is not among the runs
    assert t.text == "3 ms (median of 5 warm runs, spread 1–5 ms)"
    assert ctx.timings == [t]
    even = ReportContext(outdir=tmp_path, clock=clock)
    steps = iter([0.004, 0.001, 0.002, 0.010])

    def step():
        clock.now += next(steps)

    assert even.timing(step, warmup=0, repeat=4).median == pytest.approx(0.003)  # mean of 2, 4
    cold = ReportContext(outdir=tmp_path).timing(lambda: None, warmup=0, repeat=3)
    assert not cold.warm and cold.n == 3 and 0 <= cold.low <= cold.median <= cold.high
    with pytest.raises(InputError, match="repeat"):
        ctx.timing(fn, repeat=0)


def test_timing_text_units():
    """Timing.text picks µs, ms or s and prints the spread in the same unit."""
    assert Timing(9.1e-4, 8.5e-4, 9.7e-4, 7).text == (
        "0.91 ms (median of 7 warm runs, spread 0.85–0.97 ms)")
    assert Timing(2.5e-6, 2e-6, 3e-6, 3).text.startswith("2.5 µs")
    assert Timing(1.5, 1.2, 2.0, 3).text.startswith("1.5 s")


def test_reproduce_escapes_code():
    """The reproduce box shows the code escaped inside <pre><code>, labelled by kind."""
    out = ReportContext.reproduce("serialkin fk scara --q '1 < 2'", shell=True)
    assert "Reproduce (shell)" in out and "1 &lt; 2" in out and "<pre><code>" in out
    assert "Reproduce (Python)" in ReportContext.reproduce("import serialkin")


def _cells(table: str) -> list[tuple[str, str]]:
    return re.findall(r'<t[dh] class="(num|txt)">(.*?)</t[dh]>', table)


def test_table_alignment():
    """Numbers (also numeric strings) are right-aligned, text left-aligned, header follows."""
    out = ReportContext.table([("a", 1.5, "2.0e-05", "98 %"), ("b", 2, "∞", "7 ms")],
                              ["name", "x", "y", "z"])
    cells = _cells(out)
    assert cells[:4] == [("txt", "name"), ("num", "x"), ("num", "y"), ("num", "z")]
    assert cells[4:8] == [("txt", "a"), ("num", "1.5"), ("num", "2.0e-05"), ("num", "98 %")]


def test_no_negative_zero():
    """Values that round to zero never print with a minus sign, in tables and matrices."""
    assert format_number(-1e-9, "{:.4f}") == "0.0000"
    assert format_number(-0.0) == "0"
    assert format_number(-0.5, "{:.1f}") == "-0.5"
    out = ReportContext.table([(-1e-7, "-0.0000")], fmt="{:.4f}")
    assert "-0.0000" not in out and out.count("0.0000") == 2
    m = ReportContext.matrix(np.array([[-1e-9, -0.25], [-0.0, 1.0]]))
    assert "-0.0000" not in m and "-0.2500" in m
    assert isinstance(m, Html)


def test_html_cells_not_escaped():
    """Html cells (a matrix, MathML) are inserted as markup."""
    out = ReportContext.table([("R", ReportContext.matrix(np.eye(2)))])
    assert '<table class="matrix">' in out


def test_section_number_parsing():
    """The chapter number is parsed from the title with or without a trailing dot."""
    assert Section("5.1 Analytical Jacobian", "", "").number == "5.1"
    assert Section("3. Forward kinematics", "", "").number == "3"
    assert Section("3. Forward kinematics", "", "").name == "Forward kinematics"
    assert Section("Appendix", "", "").number == ""


def test_table_alignment_is_per_column():
    """A column mixing text and numbers is a text column: every cell left-aligned."""
    out = ReportContext.table([("23 (corrected)", 1.0), ("24", 2.0), ("", 3.0)], ["eq", "v"])
    cells = _cells(out)
    assert [c for c, _ in cells] == ["txt", "num", "txt", "num", "txt", "num", "txt", "num"]
    out = ReportContext.table([("1.5", ""), ("2", 0.5)], [Html("<i>x</i>"), "y"])
    assert '<th class="num"><i>x</i></th>' in out and _cells(out)[3] == ("num", "")


def test_compact_png_keeps_white_and_shrinks(tmp_path):
    """A matplotlib PNG re-encoded with a palette stays a PNG, keeps white white, shrinks."""
    import io

    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from PIL import Image

    from serialkin.chapter.report import compact_png

    fig, ax = plt.subplots()
    x = np.linspace(0, 6, 400)
    for k in range(6):
        ax.plot(x, np.sin(x + k), label=f"curve {k}")
    ax.legend()
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=110)
    plt.close(fig)
    out = compact_png(buf.getvalue())
    assert out[:4] == b"\x89PNG" and len(out) < len(buf.getvalue())
    with Image.open(io.BytesIO(out)) as im:
        assert im.mode == "P"
        assert im.convert("RGB").getpixel((2, 2)) == (255, 255, 255)


def test_format_vector_has_no_negative_zero():
    """format_vector prints "(a, b)" with the number format and never "-0"."""
    from serialkin.chapter.report import format_vector

    assert format_vector([-0.0, 0.5, -2.0]) == "(0, 0.5, -2)"
    assert format_vector([-1e-12, 0.25], "{:.3f}") == "(0.000, 0.250)"
    assert format_vector(np.array([[-0.0, 1.23456]]), "{:.2f}") == "(0.00, 1.23)"


def test_interleaved_alternates_and_gives_the_ratio(tmp_path):
    """interleaved: warm-ups untimed, pairs in alternating order, ratio second/first per pair."""
    clock = _FakeClock()
    order = []

    def make(name, seconds):
        def fn():
            order.append(name)
            clock.now += seconds
        return fn

    ctx = ReportContext(outdir=tmp_path, clock=clock)
    ta, tb, ratio = ctx.interleaved(make("a", 0.002), make("b", 0.006), warmup=1, repeat=4)
    assert order == ["a", "b", "a", "b", "b", "a", "a", "b", "b", "a"]
    assert ta.median == pytest.approx(0.002) and tb.median == pytest.approx(0.006)
    assert ratio.median == pytest.approx(3.0) and ratio.n == 4
    assert ctx.timings == [ta, tb]


def _bench_with(durations, rounds=2):
    """A bench on a fake clock; ``durations[name]`` yields that function's run times."""
    clock = _FakeClock()
    calls = []

    def make(name):
        def fn():
            calls.append(name)
            clock.now += next(durations[name])
            return name.upper()
        return fn

    ctx = ReportContext(outdir=".", clock=clock)
    return ctx, ctx.bench(rounds=rounds), make, calls


def test_bench_rotates_the_order_and_warms_up_untimed():
    """add() calls fn once untimed and returns its result; rounds rotate the order."""
    from itertools import chain, repeat

    durations = {name: chain([first], repeat(each)) for name, first, each in
                 (("a", 50.0, 0.001), ("b", 60.0, 0.002), ("c", 70.0, 0.003))}
    ctx, bench, make, calls = _bench_with(durations, rounds=2)
    assert [bench.add(n, make(n)) for n in "abc"] == ["A", "B", "C"]
    assert calls == ["a", "b", "c"]  # the warm-ups
    bench.block()
    bench.block()
    assert calls[3:] == list("abc" "bca" "cab" "abc")  # round k starts at function k mod 3
    assert bench.blocks == 2 and bench.names == ["a", "b", "c"]
    t = bench.timing("b")
    assert t.n == 4 and t.blocks == 2 and t.median == pytest.approx(0.002)  # no 60 s warm-up
    assert ctx.timings == [t] and bench.timing("b") is t  # recorded once


def test_bench_spread_is_the_5th_to_95th_percentile():
    """Median over all runs of all blocks; spread = their 5th-95th percentile (not min..max)."""
    runs = iter([1.0, 0.010, 0.012, 0.050, 0.020, 0.021, 0.022])  # warm-up, then 2 blocks of 3
    ctx, bench, make, _ = _bench_with({"a": runs}, rounds=3)
    bench.add("a", make("a"))
    bench.block()
    bench.block()
    t = bench.timing("a")
    assert t.median == pytest.approx(np.median([0.010, 0.011, 0.050, 0.020, 0.021, 0.022]))
    # sorted 10, 12, 20, 21, 22, 50 ms: the 5th percentile is at rank 0.25, the 95th at 4.75
    assert (t.low, t.high) == (pytest.approx(0.0105), pytest.approx(0.0430))
    assert t.runs == pytest.approx((0.010, 0.012, 0.050, 0.020, 0.021, 0.022))
    assert t.text == ("20.5 ms (median of 6 warm runs in 2 blocks, 5th–95th percentile "
                      "10.5–43 ms)")


def test_bench_ratio_is_taken_per_round():
    """ratio(a, b): the time of a over the time of b in the same round, median and spread."""
    durations = {"a": iter([9.0, 0.004, 0.006, 0.009, 0.0115]),
                 "b": iter([9.0, 0.002, 0.002, 0.002, 0.004])}
    ctx, bench, make, _ = _bench_with(durations, rounds=2)
    bench.add("a", make("a"))
    bench.add("b", make("b"))
    bench.block()
    bench.block()
    r = bench.ratio("a", "b")
    assert r.runs == pytest.approx((2.0, 3.0, 4.5, 2.875))
    # sorted 2, 2.875, 3, 4.5: the percentiles at ranks 0.15 and 2.85
    assert r.median == pytest.approx(2.9375)
    assert (r.low, r.high) == pytest.approx((2.13125, 4.275))
    assert r.unit == "×" and r.label == "a / b"
    assert r.text == "2.9× (median of 4 rounds in 2 blocks, 5th–95th percentile 2.1–4.3×)"


def test_bench_refuses_what_would_skew_it():
    """Late add(), block() before add() or after timing(), unknown names: InputError."""
    from itertools import repeat

    ctx, bench, make, _ = _bench_with({"a": repeat(0.001), "b": repeat(0.001)})
    with pytest.raises(InputError, match="add"):
        bench.block()
    with pytest.raises(InputError, match="warmup"):
        bench.add("a", make("a"), warmup=0)
    bench.add("a", make("a"))
    with pytest.raises(InputError, match="block"):
        bench.timing("a")
    with pytest.raises(InputError, match="registered already"):
        bench.add("a", make("a"))
    bench.block()
    with pytest.raises(InputError, match="before the first block"):
        bench.add("b", make("b"))
    with pytest.raises(InputError, match="registered: a"):
        bench.timing("nope")
    bench.timing("a")
    with pytest.raises(InputError, match="after timing"):
        bench.block()


def test_reproduce_box_carries_the_expected_numbers():
    """A Reproduce box stores the page's numbers as JSON (unicode minus as ASCII)."""
    import html
    import json

    box = ReportContext.reproduce("print(1)", expect=["−0.25", "3"])
    data = re.search(r'data-expect="([^"]*)"', box).group(1)
    assert json.loads(html.unescape(data)) == ["-0.25", "3"]
    assert 'data-kind="python"' in box and "Reproduce (Python)" in box


def test_bold_mathml_becomes_unicode_bold():
    r"""\boldsymbol and bold digits come out as Unicode bold letters, with no mathvariant."""
    out = ReportContext.imath(r"\boldsymbol{\omega} + \mathbf{0} + \boldsymbol{x}")
    assert "mathvariant" not in out
    assert "\U0001d74e" in out and "\U0001d7ce" in out and "\U0001d499" in out


def test_algorithm_box_numbers_its_steps():
    """An algorithm box is an ordered list: one numbered item per step, indented by level."""
    box = ReportContext.algorithm("demo", [(0, "first"), (1, "second")])
    assert box.count("<li") == 2 and "<ol" in box and "margin-left:1.6em" in box


def test_numbers_are_kept_together_in_text():
    """A number with its unit, range, exponent or name is wrapped so no line breaks inside it."""
    from serialkin.chapter._context import keep_numbers_together

    def kept(text: str) -> list[str]:
        return re.findall(r'<span class="nowrap">(.*?)</span>', keep_numbers_together(text))

    assert kept("100 %, 1.04-18.6 ms") == ["100 %", "1.04-18.6 ms"]
    assert kept("spread 0.105-0.3 ms, 0.098 ms") == ["0.105-0.3 ms", "0.098 ms"]
    assert kept("percentile 0.285–0.438 ms") == ["0.285–0.438 ms"]
    assert kept("W_L1 = 0.15 (q1 = 80.5°)") == ["W_L1 = 0.15", "q1 = 80.5°"]
    assert kept("rounding (2.2e-16).") == ["2.2e-16"]
    assert kept("&gt; 1,000 iterations") == ["&gt; 1,000"]
    # nothing that cannot break, nothing in code, maths, numeric cells, tags or entities
    for text in ("5.2× (median of 21 rounds", "5th–95th", "&#39;x&#39;", "<code>1 - 2 ms</code>",
                 '<td class="num">1.2e-05</td>', '<img alt="3 mm">',
                 '<math><mn>2</mn><mo>-</mo><mn>3</mn></math>'):
        assert keep_numbers_together(text) == text


def test_large_ratios_print_without_exponent():
    """A ratio of 1,100 prints as "1,100×", never "1.1e+03×"; small ones keep two digits."""
    t = Timing(median=1113.0, low=720.0, high=1234.0, n=21, blocks=7, unit="×")
    assert t.text.startswith("1,100× (median of 21 rounds in 7 blocks")
    assert "percentile 720–1,200×" in t.text
    assert Timing(median=5.24, low=3.5, high=6.0, n=21, blocks=7, unit="×").text.startswith(
        "5.2×")
