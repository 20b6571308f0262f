"""The documentation site: strict build, complete API reference, working links and snippets.

The site is built once per test session with ``mkdocs build --strict`` (a warning of MkDocs,
mkdocstrings or griffe fails the build), exactly as ``make docs`` does, into a temporary folder.
Python blocks fenced as ```` ```python ```` on the hand-written guide pages are run, page by
page in one namespace (as a reader pastes them one after the other); fragments
that are not meant to run (excerpts of the library's source) are fenced as ```` ```py ````.
Blocks fenced ```` ```python exec="on" ... ```` are also run by the build itself
(markdown-exec), which shows what they print under them: the output a page shows is real.
"""

from __future__ import annotations

import importlib
import inspect
import os
import re
import subprocess
import sys
from html.parser import HTMLParser
from pathlib import Path
from urllib.parse import unquote, urlsplit

import pytest

ROOT = Path(__file__).resolve().parents[2]
DOCS = ROOT / "docs"
import api  # noqa: E402  (docs/_build/api.py, on sys.path by tests/conftest.py)

pytest.importorskip("mkdocs", reason="the docs extra is not installed (pip install -e '.[docs]')")
pytest.importorskip("mkdocstrings_handlers.python")


@pytest.fixture(scope="module")
def site(tmp_path_factory, examples_ran):
    """The site built in strict mode; the build's output is in the failure message.

    Its gallery reads the examples' runs of this test run (``examples_ran``) rather than
    running every script a second time.
    """
    out = tmp_path_factory.mktemp("site")
    env = dict(os.environ, DISABLE_MKDOCS_2_WARNING="true", NO_MKDOCS_2_WARNING="1",
               PYTHONPATH=str(ROOT / "src"), SERIALKIN_EXAMPLES_RAN=str(examples_ran))
    proc = subprocess.run([sys.executable, "-m", "mkdocs", "build", "--strict", "-d", str(out)],
                          cwd=ROOT, env=env, capture_output=True, text=True, timeout=1200)
    warnings = [ln for ln in (proc.stdout + proc.stderr).splitlines()
                if "WARNING" in ln or "Error" in ln or "error" in ln]
    assert proc.returncode == 0, "docs build failed:\n" + "\n".join(warnings[-40:] or [
        proc.stderr[-3000:]])
    return out


class _Links(HTMLParser):
    """Collects the href/src of every element and the ids of a page."""

    def __init__(self) -> None:
        super().__init__()
        self.refs: list[tuple[str, str, str]] = []
        self.ids: set[str] = set()

    def handle_starttag(self, tag: str, attrs: list[tuple[str, str | None]]) -> None:
        for key, value in attrs:
            if key in ("href", "src") and value:
                self.refs.append((tag, key, value))
            if key == "id" and value:
                self.ids.add(value)


def _parse(path: Path) -> _Links:
    parser = _Links()
    parser.feed(path.read_text(encoding="utf-8"))
    return parser


def _pages(site: Path) -> list[Path]:
    """The site's pages; not 404.html, whose root-absolute links serve a web server's errors."""
    return sorted(p for p in site.rglob("*.html") if p.name != "404.html")


def test_site_builds_strict_with_every_section(site):
    """The strict build writes the home page, the guide, gallery, CLI and API reference pages."""
    for page in ("index.html", "getting-started.html", "which-ik-method.html",
                 "coming-from.html", "chapter-report.html", "cli.html",
                 "gallery/index.html", "reference/index.html"):
        assert (site / page).is_file(), page


def test_every_public_name_has_a_docstring():
    """Each name in a public package's __all__ (functions, classes, modules) has a docstring."""
    missing = []
    for package, names in api.public_packages():
        mod = importlib.import_module(package)
        for name in names:
            obj = getattr(mod, name)
            if (inspect.isfunction(obj) or inspect.isclass(obj) or inspect.ismodule(obj)) and \
                    not (inspect.getdoc(obj) or "").strip():
                missing.append(f"{package}.{name}")
    assert not missing, f"public names without a docstring: {', '.join(missing)}"


def test_every_public_name_is_in_the_api_reference(site):
    """Every name of every public __all__ has its anchor on its package's reference page."""
    packages = api.public_packages()
    ids = {}
    missing = []
    for package, names in packages:
        for name in names:
            page, anchor = api.documented_at(packages, package, name)
            if page not in ids:
                path = site / "reference" / f"{page}.html"
                assert path.is_file(), f"no reference page for {page}"
                ids[page] = _parse(path).ids
            if anchor is None:  # documented with its home package: its name must be there
                obj = getattr(importlib.import_module(package), name)
                anchor = obj.__name__ if inspect.ismodule(obj) else \
                    f"{obj.__module__}.{obj.__qualname__}"
                if inspect.ismodule(obj):
                    continue  # a public package: its own page exists (checked above)
            if anchor not in ids[page]:
                missing.append(f"{package}.{name} (#{anchor} on reference/{page}.html)")
    assert not missing, "public names missing from the API reference: " + ", ".join(missing)


def test_every_internal_link_resolves(site):
    """Every relative href/src of every page points to a file of the site (and anchor)."""
    broken = []
    ids_of: dict[Path, set[str]] = {}
    for page in _pages(site):
        for tag, key, ref in _parse(page).refs:
            parts = urlsplit(ref)
            if parts.scheme or ref.startswith(("//", "mailto:", "data:", "javascript:")):
                continue
            target = page if not parts.path else (page.parent / unquote(parts.path)).resolve()
            if target.is_dir():
                target = target / "index.html"
            if not target.exists():
                broken.append(f"{page.relative_to(site)}: <{tag} {key}={ref!r}>")
                continue
            if parts.fragment and target.suffix == ".html" and tag == "a":
                if target not in ids_of:
                    ids_of[target] = _parse(target).ids
                if unquote(parts.fragment) not in ids_of[target]:
                    broken.append(f"{page.relative_to(site)}: <a href={ref!r}> (no such anchor)")
    assert not broken, "broken links:\n" + "\n".join(broken[:50])


def test_site_reads_offline(site):
    """No page loads a script, stylesheet, font or image from the network."""
    remote = []
    for page in _pages(site):
        for tag, key, ref in _parse(page).refs:
            if urlsplit(ref).scheme in ("http", "https") or ref.startswith("//"):
                if tag in ("script", "img", "iframe") or (tag == "link" and key == "href"):
                    remote.append(f"{page.relative_to(site)}: <{tag} {key}={ref!r}>")
    assert not remote, "network resources:\n" + "\n".join(remote[:20])


def test_cli_reference_lists_every_command(site):
    """The command-line page has a section for every `serialkin` subcommand."""
    from serialkin.cli.main import cli

    text = (site / "cli.html").read_text(encoding="utf-8")
    missing = [name for name in cli.commands if f"serialkin {name}" not in text]
    assert not missing, f"commands missing from cli.html: {missing}"


def test_gallery_shows_every_example_with_its_figures(site):
    """Each examples/*.py has a gallery page; the figures the scripts write are shown."""
    scripts = sorted((ROOT / "examples").glob("*.py"))
    for script in scripts:
        page = site / "gallery" / f"{script.stem}.html"
        assert page.is_file(), f"no gallery page for examples/{script.name}"
    images = [ref for p in _pages(site / "gallery") for tag, _, ref in _parse(p).refs
              if tag == "img" and ref.endswith((".png", ".gif", ".svg"))]
    assert len(images) >= len(scripts) // 2, images


GUIDE_PAGES = sorted(p for p in DOCS.glob("*.md"))
_BLOCK = re.compile(r"^```python(?: [^\n]*)?\n(.*?)^```", re.S | re.M)


@pytest.mark.parametrize("page", GUIDE_PAGES, ids=[p.name for p in GUIDE_PAGES])
def test_guide_snippets_run(page, tmp_path, monkeypatch):
    """The ```python blocks of a guide page run as pasted, in order, as one session."""
    blocks = _BLOCK.findall(page.read_text(encoding="utf-8"))
    if not blocks:
        assert "```python" not in page.read_text(encoding="utf-8")
        return
    import matplotlib

    matplotlib.use("Agg")
    (tmp_path / "examples").symlink_to(ROOT / "examples")  # pages quote examples/ paths
    monkeypatch.chdir(tmp_path)
    namespace = {"__name__": "__main__"}  # later blocks may use earlier blocks' names
    # a page may register an IK method (architecture.md's "gradient"): it is taken out
    # again, or every later compare() in this worker (the report's table) would list it
    from serialkin.ik import registry

    methods = dict(registry._REGISTRY)
    try:
        for i, block in enumerate(blocks):
            try:
                exec(compile(block, f"{page.name} block {i + 1}", "exec"),  # noqa: S102
                     namespace)
            except Exception as exc:  # noqa: BLE001 - report which block of which page
                pytest.fail(f"{page.name}, python block {i + 1} raised "
                            f"{type(exc).__name__}: {exc}")
    finally:
        registry._REGISTRY.clear()
        registry._REGISTRY.update(methods)


def test_docs_open_in_chromium(site):
    """The home page and an API page render in headless Chromium from file:// without errors."""
    from tests._browser import start_chromium

    driver, profile = start_chromium()
    try:
        for page in ("index.html", "reference/serialkin.ik.html"):
            driver.get((site / page).as_uri())
            title = driver.title
            assert "serialkin" in title, title
            body = driver.find_element("tag name", "body").text
            assert len(body) > 200, body[:200]
            severe = [e for e in driver.get_log("browser") if e["level"] == "SEVERE"
                      and "favicon" not in e["message"]]
            assert not severe, severe
    finally:
        driver.quit()
        import shutil

        shutil.rmtree(profile, ignore_errors=True)


def _chromium_page(site: Path, page: str):
    """A headless Chromium (1100 × 760) showing ``page`` of ``site`` from file://."""
    from tests._browser import start_chromium

    driver, profile = start_chromium()
    driver.get((site / page).as_uri())
    return driver, profile


def _close(driver, profile) -> None:
    import shutil

    driver.quit()
    shutil.rmtree(profile, ignore_errors=True)


def test_search_answers_from_disk(site):
    """Opened from file://, typing in the search box lists sections that link to real pages."""
    import time

    driver, profile = _chromium_page(site, "ik.html")
    try:
        box = driver.find_element("css selector", "[data-md-component=search-query]")
        box.click()
        box.send_keys("jacobian")
        deadline = time.monotonic() + 20
        links: list[str] = []
        while time.monotonic() < deadline and not links:
            time.sleep(0.2)
            links = [a.get_attribute("href") for a in
                     driver.find_elements("css selector", ".md-search-result__list li a")]
        assert links, "no search results for 'jacobian' on the site opened from disk"
        for href in links:
            target = Path(unquote(urlsplit(href).path))
            assert target.is_file() and site in target.parents, href
        first = driver.find_element("css selector", ".md-search-result__list li a")
        assert first.is_displayed(), "the results are listed but not shown"
        titles = [h.text for h in driver.find_elements("css selector",
                                                        ".md-search-result__list h1")]
        assert any("acobian" in t for t in titles), titles
    finally:
        _close(driver, profile)


#: Tokens of inline code inside table cells whose characters lie on two lines (JavaScript):
#: a token is a run without white space, cut after each hyphen (a break after a hyphen is
#: the usual typographic one).
_BROKEN_TOKENS = """
var bad = [];
document.querySelectorAll('.md-typeset table code').forEach(function (c) {
  c.childNodes.forEach(function (t) {
    if (t.nodeType !== 3) return;
    var re = /[^\\s-]+-?/g, m;
    while ((m = re.exec(t.data))) {
      var r = document.createRange();
      r.setStart(t, m.index); r.setEnd(t, m.index + m[0].length);
      var tops = new Set(Array.from(r.getClientRects()).filter(function (x) {
        return x.width > 0; }).map(function (x) { return Math.round(x.top); }));
      if (tops.size > 1) bad.push(m[0]);
    }
  });
});
return bad;
"""


@pytest.mark.parametrize("page", ["coming-from.html", "ik.html", "cli.html"])
def test_code_in_tables_never_breaks_inside_a_token(site, page):
    """Inline code in table cells wraps only between words, never inside an identifier."""
    driver, profile = _chromium_page(site, page)
    try:
        broken = driver.execute_script(_BROKEN_TOKENS)
        assert not broken, f"{page}: code broken across lines: {broken[:10]}"
    finally:
        _close(driver, profile)
