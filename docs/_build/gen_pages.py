"""Pages generated at build time by mkdocs-gen-files: the API reference and the examples gallery.

* **API reference** — one page per public package: ``serialkin`` and every subpackage whose
  ``__init__`` declares ``__all__`` (found by walking the package, so a package added later
  appears without editing this file). Each page lists exactly the names of ``__all__``,
  rendered by mkdocstrings from their docstrings.
* **Examples gallery** — every ``examples/*.py`` script is run in a fresh folder, several
  at a time (``run_examples.py``; the test suite hands over the folder where it ran them
  already, ``SERIALKIN_EXAMPLES_RAN``); its page shows the script's docstring, the
  figures it wrote, what it printed and its source.

Run by ``mkdocs build`` (``make docs``); the docs test runs the same build.
"""

from __future__ import annotations

import ast
import html
import importlib
import os
import sys
import tempfile
from pathlib import Path

import mkdocs_gen_files

sys.path.insert(0, str(Path(__file__).resolve().parent))
from api import member_block, public_packages  # noqa: E402
from roles import plain_roles  # noqa: E402
from run_examples import EXAMPLES, run_all  # noqa: E402

#: figure types the gallery shows inline; other outputs are linked
IMAGES = (".png", ".gif", ".svg", ".jpg")
LINKED = (".html", ".mp4", ".urdf", ".yaml", ".json", ".tex", ".csv")


def reference_pages() -> None:
    """Write ``reference/<package>.md`` for each public package and an index of them."""
    packages = public_packages()
    index = ["# API reference", "",
             "Every public name of serialkin, package by package, from its docstring "
             "(shapes, units and the equation each function implements). A package's "
             "public names are those of its `__all__`.", "",
             "| package | names | summary |", "|---|---|---|"]
    for name, names in packages:
        mod = importlib.import_module(name)
        summary = plain_roles((mod.__doc__ or "").strip().splitlines()[0]) if mod.__doc__ else ""
        index.append(f"| [`{name}`]({name}.md) | {len(names)} | {summary} |")
        blocks = [f"# `{name}`", "", plain_roles((mod.__doc__ or "").strip()), ""]
        for member in names:
            blocks += [member_block(packages, name, member), ""]
        with mkdocs_gen_files.open(f"reference/{name}.md", "w") as f:
            f.write("\n".join(blocks))
    with mkdocs_gen_files.open("reference/index.md", "w") as f:
        f.write("\n".join(index) + "\n")
    summary = ["* [Overview](index.md)"] + [f"* [{n}]({n}.md)" for n, _ in packages]
    with mkdocs_gen_files.open("reference/SUMMARY.md", "w") as f:
        f.write("\n".join(summary) + "\n")


def _docstring(script: Path) -> str:
    """The module docstring of an example script ('' when it has none)."""
    return ast.get_docstring(ast.parse(script.read_text(encoding="utf-8"))) or ""


def gallery_page(script: Path, ran: Path) -> tuple[str, str]:
    """Write one example's page and outputs from its run in ``ran``; return (page, summary)."""
    stem = script.stem
    code = int((ran / "returncode").read_text())
    if code != 0:
        raise RuntimeError(f"examples/{script.name} failed:\n"
                           f"{(ran / 'stderr.txt').read_text(encoding='utf-8')[-3000:]}")
    tmp = ran / "out"
    outputs = sorted(p for p in tmp.rglob("*") if p.is_file())
    shown, linked = [], []
    for p in outputs:
        rel = p.relative_to(tmp).as_posix()
        if p.suffix.lower() in IMAGES + LINKED:
            with mkdocs_gen_files.open(f"gallery/{stem}/{rel}", "wb") as f:
                f.write(p.read_bytes())
            (shown if p.suffix.lower() in IMAGES else linked).append(rel)
    stdout = (ran / "stdout.txt").read_text(encoding="utf-8")
    doc = _docstring(script)
    lines = [f"# {script.name}", "", doc, ""]
    for rel in shown:
        lines += [f"![{rel}]({stem}/{rel})", ""]
    if linked:
        lines += ["Files it writes: " + ", ".join(f"[`{r}`]({stem}/{r})" for r in linked), ""]
    if stdout.strip():
        out = stdout.strip()
        lines += ["## Output", "", "```text", out[-6000:], "```", ""]
    source = script.read_text(encoding="utf-8")
    lines += ["## Source", "", f"Run it with `python examples/{script.name}`.", "",
              "```python", source.rstrip(), "```", ""]
    with mkdocs_gen_files.open(f"gallery/{stem}.md", "w") as f:
        f.write("\n".join(lines))
    return stem, html.escape(doc.splitlines()[0] if doc else script.name)


def gallery() -> None:
    """Run every example and write ``gallery/index.md`` listing them."""
    ran = os.environ.get("SERIALKIN_EXAMPLES_RAN")
    with tempfile.TemporaryDirectory() as tmp:
        root = Path(ran) if ran else Path(tmp)
        if not ran:
            run_all(root, EXAMPLES)
        rows = [gallery_page(s, root / s.stem) for s in EXAMPLES]
    index = ["# Examples", "",
             "Each script of `examples/` was run when this site was built; its page shows "
             "the figures it made, what it printed and its source. The test suite runs every "
             "script too.", ""]
    index += [f"- [{stem}]({stem}.md): {summary}" for stem, summary in rows]
    with mkdocs_gen_files.open("gallery/index.md", "w") as f:
        f.write("\n".join(index) + "\n")
    summary = ["* [Overview](index.md)"] + [f"* [{stem}]({stem}.md)" for stem, _ in rows]
    with mkdocs_gen_files.open("gallery/SUMMARY.md", "w") as f:
        f.write("\n".join(summary) + "\n")


reference_pages()
gallery()
