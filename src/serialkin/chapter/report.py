"""The chapter report: every worked example of the chapter, recomputed, in one HTML file.

Each section of the report is a module in :mod:`serialkin.chapter.sections` with a
function ``build(ctx: ReportContext) -> Section | list[Section]``. :func:`build_report`
runs them in chapter order and writes ``report.html`` (figures embedded as data URIs, so
the file is self-contained and at most a few MB) plus every figure under ``figures/``,
the fonts the page uses under ``fonts/`` (with their licences), every timed run in
``timings.json`` and what the build depended on in ``build.json`` (:func:`build_provenance`).

What :class:`ReportContext` gives a section:

* ``ctx.eq(latex, number)`` / ``ctx.imath(latex)``: mathematics as MathML (converted from
  LaTeX by ``latex2mathml``; native in Chromium and Firefox, no JavaScript, no network),
  display equations with the chapter's number on the right, scrolling sideways when wide;
* ``ctx.bench()``: a :class:`TimingBench` for a section's warm measurements: each timed
  function is registered (and warmed up), then timed in blocks of rounds that the section
  takes between its other work, so that the runs sample the machine over the section's
  build; a :class:`Timing` is the median of all runs with their 5th-95th percentile as
  its spread, a ratio of two functions is taken per round (``ctx.timing(fn)`` and
  ``ctx.interleaved`` time back to back, with the min..max of the runs);
* ``ctx.reproduce(code, shell)``: the snippet or ``serialkin`` command that reproduces an
  example;
* ``ctx.table`` / ``ctx.matrix`` / ``ctx.figure``: aligned tables without negative zeros,
  bracketed numeric matrices, PNG figures quantised to a 256-colour palette.

These helpers and :class:`Section` are defined in :mod:`serialkin.chapter._context`,
which the section modules import (this module imports the sections, so they never import
it); this module assembles the page and re-exports them.

Sections are numbered as in the chapter: a section's title starts with the chapter's
number ("5.1 Analytical Jacobian"); the page header records the versions, git commit,
date, CPU count and build time.
"""

from __future__ import annotations

import html
import importlib
import os
import time
from collections.abc import Sequence
from pathlib import Path

import numpy as np

from serialkin._checks import check_int
from serialkin._io import write_text_atomic
from serialkin.chapter._context import (
    Html,
    ReportContext,
    Section,
    Timing,
    compact_png,
    format_number,
    format_vector,
    keep_numbers_together,
)
from serialkin.chapter._fonts import FAMILY, embedded_fonts

#: Section modules in chapter order (module name under serialkin.chapter.sections).
SECTION_MODULES: tuple[str, ...] = (
    "workspace",
    "rigid_motion",
    "forward",
    "inverse",
    "jacobian",
    "numerical",
    "redundancy",
)

_CSS = """
body{font-family:@text@;max-width:1100px;margin:2em auto;padding:0 1em;color:#222;
line-height:1.45}
h1{border-bottom:2px solid #345}h2{margin-top:2em;border-bottom:1px solid #ccc}
.eq{color:#555;font-size:90%}table{border-collapse:collapse;margin:0.6em 0}
td,th{border:1px solid #bbb;padding:2px 8px;vertical-align:middle}th{background:#eef}
td.num,th.num{text-align:right;font-variant-numeric:tabular-nums}td.txt,th.txt{text-align:left}
table.matrix{border-left:2px solid #555;border-right:2px solid #555;--k:linear-gradient(#555,#555);
background:var(--k) left top/6px 2px no-repeat,var(--k) left bottom/6px 2px no-repeat,
var(--k) right top/6px 2px no-repeat,var(--k) right bottom/6px 2px no-repeat}
table.matrix td{border:none;text-align:right;font-variant-numeric:tabular-nums;padding:1px 8px}
figure{margin:1em 0}img{max-width:100%}pre{background:#f6f6f6;padding:0.6em;overflow-x:auto}
.eqn{display:flex;align-items:center;margin:0.6em 0}
.eqbody{flex:1 1 auto;min-width:0;overflow-x:auto;overflow-y:hidden;padding:2px 0}
.eqno{flex:none;margin-left:1.5em;color:#333}
math{font-family:@math@}math[display=block]{font-size:1.08em}
pre,code{font-family:@code@;font-size:0.8125em}pre code{font-size:1em}
.repro{border:1px solid #9ab;border-left:4px solid #357;background:#f4f8fb;margin:1em 0;
padding:0.3em 0.8em}.repro pre{background:none;margin:0.3em 0;padding:0}
.repro-label{font-weight:600;font-size:90%;color:#357}
.meta{font-size:90%;color:#444}.meta td,.meta th{border:none;padding:0 1em 0 0;text-align:left}
.meta th{background:none;font-weight:600}
nav ul{list-style:none;padding-left:0}nav li.sub{padding-left:2em}
nav li.part{padding-left:4em}
.err{color:#a00}
td.num,th.num,table.matrix td,.nowrap{white-space:nowrap}
.tablewrap{max-width:100%;overflow-x:auto}
mtd[columnalign=left]{text-align:left}mtd[columnalign=right]{text-align:right}
ol.algorithm{background:#fafafa;border:1px solid #ccc;padding:0.5em 0.8em 0.5em 2.5em}
"""
for _role, _family in FAMILY.items():
    _CSS = _CSS.replace(f"@{_role}@", _family)
del _role, _family


def source_digest() -> str:
    """SHA-1 of the installed serialkin package's files (paths and contents), hex.

    Every file under the package folder but compiled caches (``__pycache__``): it names
    the exact sources a report was built from, committed or not.
    """
    import hashlib

    root = Path(__file__).resolve().parents[1]
    h = hashlib.sha1()
    for f in sorted(root.rglob("*")):
        if f.is_file() and "__pycache__" not in f.parts:
            h.update(f.relative_to(root).as_posix().encode() + b"\0")
            h.update(f.read_bytes())
    return h.hexdigest()


def build_provenance(sections: Sequence[str], digest: str | None = None) -> dict[str, object]:
    """What a build depends on: sources, sections and the versions of the libraries it uses.

    Written beside the page as ``build.json``; two builds with equal provenance compute
    the same page (but for its timings and dates). ``digest``: :func:`source_digest`,
    computed here when None.
    """
    import platform
    from importlib.metadata import version

    return {"source": digest or source_digest(), "sections": list(sections),
            "python": platform.python_version(),
            "packages": {p: version(p) for p in ("numpy", "numba", "scipy", "matplotlib",
                                                 "latex2mathml", "pillow")}}


def build_metadata(digest: str | None = None) -> list[tuple[str, str]]:
    """(label, value) pairs describing this build: versions, git commit, date, CPUs.

    ``digest``: :func:`source_digest`, computed here when None.
    """
    import platform
    import subprocess
    from datetime import UTC, datetime

    import numba

    from serialkin._version import __version__

    try:
        from importlib.metadata import version

        sk_version = version("serialkin")
    except Exception:  # noqa: BLE001 - not installed: fall back to the module's attribute
        sk_version = __version__
    commit = "not available (not a git checkout)"
    try:
        here = Path(__file__).resolve().parent
        res = subprocess.run(["git", "rev-parse", "--short=12", "HEAD"], cwd=here,
                             capture_output=True, text=True, timeout=5, check=False)
        if res.returncode == 0 and res.stdout.strip():
            commit = res.stdout.strip()
            dirty = subprocess.run(["git", "status", "--porcelain", "--untracked-files=no"],
                                   cwd=here, capture_output=True, text=True, timeout=5,
                                   check=False)
            if dirty.returncode == 0 and dirty.stdout.strip():
                commit += " (with uncommitted changes)"
    except (OSError, subprocess.SubprocessError):
        pass
    return [
        ("serialkin", sk_version),
        ("git commit", commit),
        ("source digest", (digest or source_digest())[:12]),
        ("built", datetime.now(UTC).strftime("%Y-%m-%d %H:%M UTC")),
        ("Python", platform.python_version()),
        ("numpy", np.__version__),
        ("numba", numba.__version__),
        ("CPUs", str(os.cpu_count())),
    ]


def _sections_of(result: Section | Sequence[Section]) -> list[Section]:
    return [result] if isinstance(result, Section) else list(result)


def _span_text(values: Sequence[int]) -> str:
    """"7" or "3–7" for a sorted list of counts."""
    return f"{values[0]}" if values[0] == values[-1] else f"{values[0]}–{values[-1]}"


def _load_text(load: tuple[float, float, float] | None) -> str:
    """"1.2, 0.9, 0.7 (1, 5, 15 min)" or "not available"."""
    if load is None:
        return "not available on this system"
    return ", ".join(f"{v:.2f}" for v in load) + " (1, 5, 15 min)"


def _loadavg() -> tuple[float, float, float] | None:
    try:
        return os.getloadavg()
    except (OSError, AttributeError):
        return None


def _sections_html(parts: list[tuple[str, Section]]) -> tuple[str, str]:
    """The contents list's items and the sections' HTML, in order: ``(toc, body)``.

    A section with the number of the one before it continues it (a part of the same
    chapter section: an h3 under the same heading); each section's anchor is its own or
    its module's name, numbered from the second section of one module on.
    """
    toc: list[str] = []
    body: list[str] = []
    previous = None
    counts: dict[str, int] = {}
    for module, sec in parts:
        k = counts.get(module, 0)
        counts[module] = k + 1
        anchor = sec.anchor or (module if k == 0 else f"{module}-{k}")
        number = sec.number
        continues = bool(number) and number == previous
        previous = number or previous
        eqs = html.escape(sec.equations)
        if continues:
            heading = sec.part or f"{sec.name} (continued)"
            toc.append(f'<li class="part"><a href="#{anchor}">{html.escape(heading)}</a> '
                       f'<span class="eq">({eqs})</span></li>')
            body.append(f'<section id="{anchor}"><h3 class="part">{html.escape(heading)}</h3>'
                        f'<p class="eq">Demonstrates: {eqs}</p>{sec.html}</section>')
            continue
        label = f"{number} {sec.name}" if number else sec.name
        css = ' class="sub"' if "." in number else ""
        eqs_toc = "" if sec.part else f' <span class="eq">({eqs})</span>'
        toc.append(f'<li{css}><a href="#{anchor}">{html.escape(label)}</a>{eqs_toc}</li>')
        part = ""
        if sec.part:
            part = f'<h3 class="part" id="{anchor}-part">{html.escape(sec.part)}</h3>'
            toc.append(f'<li class="part"><a href="#{anchor}-part">{html.escape(sec.part)}'
                       f'</a> <span class="eq">({eqs})</span></li>')
        body.append(f'<section id="{anchor}"><h2>{html.escape(label)}</h2>{part}'
                    f'<p class="eq">Demonstrates: {eqs}</p>{sec.html}</section>')
    return "".join(toc), "".join(body)


def _timing_text(timings: Sequence[Timing]) -> str:
    """The header's line on how the page's timings were taken (counts, repeats, blocks)."""
    if not timings:
        return "none measured"
    times = [t for t in timings if t.unit != "×"]
    repeats = sorted({t.n for t in timings})
    blocks = sorted({t.blocks for t in timings})
    rounds = sorted({t.n // t.blocks for t in timings})
    return (
        f"{len(times)} times and {len(timings) - len(times)} ratios, each the median of "
        f"{_span_text(repeats)} warm runs after an untimed warm-up"
        + (f", taken in {_span_text(blocks)} blocks spread over their section's build "
           f"(a block: {_span_text(rounds)} rounds, each running every timed function of "
           "the section once, the order rotating); the spread printed with each is the "
           "5th to 95th percentile of its runs" if blocks[-1] > 1 else
           ", with their full range")
        + "; a ratio between two methods is taken per round, in one process; every run "
        "is in timings.json beside this page")


def _meta_html(seconds: float, cpu: float, workers: str,
               load: tuple[tuple[float, float, float] | None, ...],
               timings: Sequence[Timing], digest: str | None = None) -> str:
    """The header's table: versions, commit, build time, load, timings, fonts."""
    import matplotlib

    meta = build_metadata(digest) + [
        ("build time", f"{seconds:.1f} s wall clock ({workers}); the sections took "
                       f"{cpu:.1f} s CPU in all"),
        ("load average", f"at the start {_load_text(load[0])}; at the end "
                         f"{_load_text(load[-1])} on {os.cpu_count()} CPUs: with a load "
                         "above the CPU count other processes shared the cores and the "
                         "times below are slower and more spread than on a quiet machine"),
        ("timings", _timing_text(timings)),
        ("fonts", f"DejaVu Sans (text, and the figures), DejaVu Sans Mono (code), DejaVu "
                  "Serif with STIX General's mathematical letters (mathematics), from "
                  f"matplotlib {matplotlib.__version__}, cut down to the characters of this "
                  "page and embedded in it, so that it looks the same on every machine; the "
                  "files and their licences are in fonts/ beside it")]
    return ('<table class="meta">' + "".join(
        f"<tr><th>{html.escape(k)}</th><td>{html.escape(v)}</td></tr>" for k, v in meta)
        + "</table>")


def _render(parts: list[tuple[str, Section]], seconds: float, cpu: float,
            workers: str, load: tuple[tuple[float, float, float] | None, ...] = (None, None),
            timings: Sequence[Timing] = (), digest: str | None = None) -> str:
    """The whole page: header with build metadata, contents, sections.

    Numbers are kept on one line with their units, ranges and exponents
    (:func:`~serialkin.chapter._context.keep_numbers_together`).
    """
    toc, body = _sections_html(parts)
    return keep_numbers_together(
        "<!DOCTYPE html><html lang='en'><head><meta charset='utf-8'>"
        "<title>Kinematics of Serial Manipulators — reproduced by serialkin</title>"
        f"<style>{_CSS}</style></head><body>"
        "<h1>Kinematics of Serial Manipulators — reproduced by serialkin</h1>"
        "<p>Every number and figure below is computed by serialkin when this report is "
        "built (<code>serialkin chapter</code>); equations carry the chapter's numbers and "
        "the corrected forms of the ERRATA are used. Times are wall-clock medians of warm "
        "runs (after an untimed warm-up call), measured while the report was built and "
        "taken in blocks spread over the build, between its other work; the spread printed "
        "with each is the 5th to 95th percentile of its runs, the run-to-run variation over "
        "the build. They depend on the machine and its load, stated below. Each Reproduce "
        "box prints the numbers its section shows; run "
        "<code>serialkin warmup</code> once first (or set <code>SERIALKIN_COMPILE=wait</code>"
        "): until the compiled kernels are ready the first calls run as Python, whose "
        "rounding differs in the last digits, and a long tracking run (the 20-link arm) then "
        "takes a slightly different path.</p>"
        f"{_meta_html(seconds, cpu, workers, load, timings, digest)}"
        f"<nav><h2 id='contents'>Contents</h2><ul>{toc}</ul></nav>{body}</body></html>"
    )


#: matplotlib settings of every figure: the page's text font (whatever a matplotlibrc says).
FIGURE_FONTS = {"font.family": "sans-serif", "font.sans-serif": ["DejaVu Sans"],
                "mathtext.fontset": "dejavusans"}

#: Relative cost of the section modules (the heaviest are started first when several
#: worker processes build the report).
_COST_HINT = {"workspace": 3, "redundancy": 3, "numerical": 2}


def _build_module(name: str, outdir: str, quiet: bool
                  ) -> tuple[list[Section], list[str], list[Timing], float, float]:
    """Build one section module: (sections, figure files, timings, wall s, CPU s)."""
    import matplotlib

    ctx = ReportContext(outdir=Path(outdir), quiet=quiet)
    t0, c0 = time.perf_counter(), time.process_time()
    module = importlib.import_module(f"serialkin.chapter.sections.{name}")
    with matplotlib.rc_context(FIGURE_FONTS):
        built = _sections_of(module.build(ctx))
    wall, cpu = time.perf_counter() - t0, time.process_time() - c0
    built[-1].html += (f'<p class="eq">Section built in {wall:.2f} s wall clock, {cpu:.2f} s '
                       "CPU (this machine).</p>")
    return built, ctx.figures, ctx.timings, wall, cpu


def _worker_init() -> None:
    """One compute thread per worker process: the workers already share the cores."""
    import numba

    numba.set_num_threads(1)


def build_report(outdir: str | os.PathLike[str], *, quiet: bool = False,
                 sections: Sequence[str] | None = None, jobs: int | None = None) -> Path:
    """Run every section builder and write ``<outdir>/report.html``; return its path.

    Each module of :data:`SECTION_MODULES` has ``build(ctx) -> Section | list[Section]``;
    sections are shown in the chapter's order with the chapter's numbers.

    Args:
        outdir: output folder (created when missing).
        quiet: no progress output.
        sections: subset of :data:`SECTION_MODULES` to build (default: all), shown in
            the chapter's order.
        jobs: worker processes building section modules side by side, each with one
            compute thread; 1 builds everything in this process. None (default): the
            cores that other processes leave free now
            (:func:`serialkin.kinematics.parallel.free_cores`), at most one per section.
            Measured on 2 cores: quiet, 2 workers take a first build from 92 s to 60 s
            and a warm one from 9.6 s to 6.4 s; with the other core busy they did not
            pay (both import everything and compile the shared kernels), which is why
            the default counts free cores.

    Raises:
        InputError: ``jobs`` below 1 (InputTypeError: not an integer).
    """
    from tqdm import tqdm

    start = time.perf_counter()
    load_start = _loadavg()
    out = Path(outdir)
    out.mkdir(parents=True, exist_ok=True)
    (out / "build.json").unlink(missing_ok=True)  # rewritten when the page is complete
    digest = source_digest()  # of the sources this build runs (header and build.json)
    names = list(SECTION_MODULES) if not sections else sorted(
        dict.fromkeys(sections), key=lambda n: (SECTION_MODULES + (n,)).index(n))
    if jobs is None:
        from serialkin.kinematics.parallel import free_cores

        n_jobs = max(1, min(free_cores(), len(names)))
    else:
        n_jobs = check_int(jobs, "jobs", minimum=1)
    results: dict[str, tuple] = {}
    bar = tqdm(total=len(names), desc="chapter", disable=quiet or None, unit="section")
    if n_jobs > 1:
        import multiprocessing
        from concurrent.futures import ProcessPoolExecutor, as_completed

        order = sorted(names, key=lambda n: -_COST_HINT.get(n, 1))
        with ProcessPoolExecutor(max_workers=n_jobs, initializer=_worker_init,
                                 mp_context=multiprocessing.get_context("spawn")) as pool:
            futures = {pool.submit(_build_module, n, str(out), True): n for n in order}
            for fut in as_completed(futures):
                results[futures[fut]] = fut.result()
                bar.set_postfix_str(futures[fut])
                bar.update()
    else:
        for name in names:
            bar.set_postfix_str(name)
            results[name] = _build_module(name, str(out), quiet)
            bar.update()
    bar.close()
    parts = [(name, sec) for name in names for sec in results[name][0]]
    cpu = sum(results[name][4] for name in names)
    workers = (f"{n_jobs} worker processes, one compute thread each" if n_jobs > 1
               else "one process")
    timings = [t for name in names for t in results[name][2]]
    page = _render(parts, time.perf_counter() - start, cpu, workers,
                   (load_start, _loadavg()), timings, digest)
    page = page.replace("<style>", "<style>" + embedded_fonts(page, out), 1)
    path = out / "report.html"
    write_text_atomic(path, page)
    write_text_atomic(out / "timings.json", _timings_json(
        [(name, t) for name in names for t in results[name][2]]))
    import json

    write_text_atomic(out / "build.json", json.dumps(build_provenance(names, digest),
                                                     indent=1))
    return path


def _timings_json(timings: Sequence[tuple[str, Timing]]) -> str:
    """Every timing of the page with all its runs, as JSON (times in seconds).

    One object per timing: section module, label, unit ("s" or "×" for a ratio), median,
    low and high (the printed spread), runs n, blocks and the runs in the order taken.
    """
    import json

    return json.dumps([
        {"section": module, "label": t.label, "unit": t.unit, "median": t.median,
         "low": t.low, "high": t.high, "n": t.n, "blocks": t.blocks, "runs": list(t.runs)}
        for module, t in timings], indent=1, ensure_ascii=False) + "\n"


__all__ = [
    "SECTION_MODULES",
    "Html",
    "ReportContext",
    "Section",
    "Timing",
    "build_metadata",
    "build_report",
    "compact_png",
    "format_number",
    "format_vector",
]
