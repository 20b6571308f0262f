"""The chapter report: every worked example of the chapter, recomputed, in one HTML file.

Each section of the report is a module in :mod:`serialkin.chapter.sections` with a
function ``build(ctx: ReportContext) -> Section``. :func:`build_report` runs them in
chapter order and writes ``report.html`` (figures embedded as data URIs, so the file is
self-contained) plus every figure as a file under ``figures/``.
"""

from __future__ import annotations

import base64
import html
import importlib
import io
import os
import time
from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from serialkin._io import write_bytes_atomic, write_text_atomic

#: Section modules in chapter order (module name under serialkin.chapter.sections).
SECTION_MODULES: tuple[str, ...] = (
    "workspace",
    "rigid_motion",
    "forward",
    "jacobian",
    "inverse",
    "redundancy",
)


@dataclass
class Section:
    """One section of the report.

    Attributes:
        title: heading, e.g. "3. Forward kinematics".
        equations: the chapter equation numbers it implements, e.g. "eqs 10-18".
        html: body HTML (use :class:`ReportContext` helpers to make tables and figures).
        anchor: HTML id.
    """

    title: str
    equations: str
    html: str
    anchor: str = ""


@dataclass
class ReportContext:
    """What a section builder gets: the output folder and helpers for figures and tables."""

    outdir: Path
    quiet: bool = False
    figures: list[str] = field(default_factory=list)

    def figure(self, fig: object, name: str, caption: str = "") -> str:
        """Save a matplotlib figure as ``figures/<name>.png``; return an <img> block (inline)."""
        import matplotlib.pyplot as plt

        buf = io.BytesIO()
        fig.savefig(buf, format="png", dpi=110, bbox_inches="tight")  # type: ignore[attr-defined]
        plt.close(fig)  # type: ignore[arg-type]
        return self.file_figure(buf.getvalue(), f"{name}.png", caption)

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

    @staticmethod
    def table(rows: Sequence[Sequence[object]], header: Sequence[str] | None = None,
              fmt: str = "{:.6g}") -> str:
        """An HTML table; floats formatted with ``fmt``."""

        def cell(v: object) -> str:
            if isinstance(v, (float, np.floating)):
                return fmt.format(v)
            return html.escape(str(v))

        head = ""
        if header:
            head = "<tr>" + "".join(f"<th>{html.escape(h)}</th>" for h in header) + "</tr>"
        body = "".join("<tr>" + "".join(f"<td>{cell(v)}</td>" for v in r) + "</tr>" for r in rows)
        return f"<table>{head}{body}</table>"

    @staticmethod
    def matrix(M: object, fmt: str = "{:.4f}") -> str:
        """A numeric matrix as a bordered HTML table."""
        a = np.atleast_2d(np.asarray(M, dtype=float))
        body = "".join(
            "<tr>" + "".join(f"<td>{fmt.format(0.0 if abs(v) < 5e-13 else v)}</td>" for v in r)
            + "</tr>" for r in a
        )
        return f'<table class="matrix">{body}</table>'

    @staticmethod
    def code(text: str) -> str:
        """Preformatted text (e.g. LaTeX or printed sympy)."""
        return f"<pre>{html.escape(text)}</pre>"


_CSS = """
body{font-family:system-ui,sans-serif;max-width:1100px;margin:2em auto;padding:0 1em;color:#222}
h1{border-bottom:2px solid #345}h2{margin-top:2em;border-bottom:1px solid #ccc}
.eq{color:#555;font-size:90%}table{border-collapse:collapse;margin:0.6em 0}
td,th{border:1px solid #bbb;padding:2px 8px;text-align:right}th{background:#eef}
table.matrix td{border:none;border-left:1px solid #999;border-right:1px solid #999}
figure{margin:1em 0}img{max-width:100%}pre{background:#f6f6f6;padding:0.6em;overflow-x:auto}
.err{color:#a00}
"""


def build_report(outdir: str | os.PathLike[str], *, quiet: bool = False,
                 sections: Sequence[str] | None = None) -> Path:
    """Run every section builder and write ``<outdir>/report.html``; return its path.

    Args:
        outdir: output folder (created when missing).
        quiet: no progress output.
        sections: subset of :data:`SECTION_MODULES` to build (default: all).
    """
    from tqdm import tqdm

    out = Path(outdir)
    out.mkdir(parents=True, exist_ok=True)
    ctx = ReportContext(outdir=out, quiet=quiet)
    names = list(sections) if sections else list(SECTION_MODULES)
    parts: list[Section] = []
    bar = tqdm(names, desc="chapter", disable=quiet or None, unit="section")
    for name in bar:
        bar.set_postfix_str(name)
        t0 = time.perf_counter()
        module = importlib.import_module(f"serialkin.chapter.sections.{name}")
        sec = module.build(ctx)
        sec.anchor = sec.anchor or name
        sec.html += f'<p class="eq">Computed in {time.perf_counter() - t0:.2f} s.</p>'
        parts.append(sec)
    toc = "".join(
        f'<li><a href="#{s.anchor}">{html.escape(s.title)}</a> '
        f'<span class="eq">({html.escape(s.equations)})</span></li>' for s in parts
    )
    body = "".join(
        f'<section id="{s.anchor}"><h2>{html.escape(s.title)}</h2>'
        f'<p class="eq">Implements: {html.escape(s.equations)}</p>{s.html}</section>'
        for s in parts
    )
    page = (
        "<!DOCTYPE html><html><head><meta charset='utf-8'>"
        "<title>Kinematics of Serial Manipulators — reproduced by serialkin</title>"
        f"<style>{_CSS}</style></head><body>"
        "<h1>Kinematics of Serial Manipulators — reproduced by serialkin</h1>"
        "<p>Every number and figure below is computed by serialkin when this report is "
        "built (<code>serialkin chapter</code>); the corrected equations of the ERRATA "
        "are used.</p>"
        f"<ol>{toc}</ol>{body}</body></html>"
    )
    path = out / "report.html"
    write_text_atomic(path, page)
    return path
