"""The worked examples of docs/autograd.md run as pasted (they need torch and jax).

The page fences its code as ```py rather than ```python: tests/docs/test_site.py runs the
```python blocks of every guide page in the main suite, which has neither extra; this
test runs the page's blocks under `make test-autograd`, where both are installed.
"""

from __future__ import annotations

import re
from pathlib import Path

import pytest

from tests.autograd._support import require

require("torch")
require("jax")

PAGE = Path(__file__).resolve().parents[2] / "docs" / "autograd.md"
_BLOCK = re.compile(r"^```py\n(.*?)^```", re.S | re.M)


def test_autograd_page_examples_run(monkeypatch, tmp_path):
    """The page's ```py blocks run in order as one session; their own asserts hold."""
    blocks = _BLOCK.findall(PAGE.read_text(encoding="utf-8"))
    assert len(blocks) == 3
    assert "```python" not in PAGE.read_text(encoding="utf-8")
    monkeypatch.chdir(tmp_path)
    namespace = {"__name__": "__main__"}
    for i, block in enumerate(blocks):
        try:
            exec(compile(block, f"autograd.md block {i + 1}", "exec"), namespace)  # noqa: S102
        except Exception as exc:  # noqa: BLE001 - report which block
            pytest.fail(f"autograd.md, py block {i + 1} raised {type(exc).__name__}: {exc}")
