"""MkDocs hooks of the documentation site (mkdocs.yml ``hooks:``).

After the build, the search index is also written as a script,
``search/search_index.js`` (``window.__serialkinSearchIndex = {...}``), which
``docs/assets/offline-search.js`` loads when the site is opened from disk: browsers
refuse the theme's worker and its JSON request on file:// pages.
"""

from __future__ import annotations

from pathlib import Path


def on_post_build(config, **kwargs) -> None:
    """Write ``search/search_index.js`` beside the theme's ``search_index.json``."""
    index = Path(config["site_dir"]) / "search" / "search_index.json"
    if index.is_file():
        text = index.read_text(encoding="utf-8")
        # "</" could close a <script> element if the file were ever inlined: escape it
        script = "window.__serialkinSearchIndex = " + text.replace("</", "<\\/") + ";\n"
        (index.parent / "search_index.js").write_text(script, encoding="utf-8")
