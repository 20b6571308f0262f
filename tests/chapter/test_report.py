"""The full chapter report builds, contains every section and every figure it links to."""

from __future__ import annotations

import re

import pytest

from serialkin.chapter.report import SECTION_MODULES, build_report

pytestmark = pytest.mark.slow


@pytest.fixture(scope="module")
def report(tmp_path_factory):
    out = tmp_path_factory.mktemp("chapter")
    path = build_report(out, quiet=True)
    return out, path.read_text(encoding="utf-8")


def test_every_section_present(report):
    """Each section module appears once as a <section> with the equations it implements."""
    _, html = report
    for name in SECTION_MODULES:
        assert html.count(f'<section id="{name}">') == 1, name
    assert html.count('<p class="eq">Implements:') == len(SECTION_MODULES)


def test_every_linked_figure_exists(report):
    """Every figure file the report links to was written and is a non-empty PNG or GIF."""
    out, html = report
    files = set(re.findall(r'href="(figures/[^"]+)"', html))
    assert len(files) >= 15  # figures 4, 5, 8, 9, 11, 12 and the sections' own
    for rel in files:
        data = (out / rel).read_bytes()
        assert data[:4] in (b"\x89PNG", b"GIF8"), rel
    for fig in ("fig08", "fig09", "fig11", "fig12"):
        assert any(fig in f for f in files), fig
    assert any(f.endswith(".gif") for f in files)


def test_report_is_self_contained(report):
    """Images are embedded as data URIs and nothing is loaded from the network."""
    _, html = report
    assert "data:image/png;base64," in html
    assert not re.search(r'<(img|script|link)[^>]+(src|href)="https?://', html)
    assert "Traceback" not in html
