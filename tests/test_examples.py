"""Every example script and the README quick start run without error."""

from __future__ import annotations

import re
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
EXAMPLES = sorted((ROOT / "examples").glob("*.py"))


def test_readme_quick_start_runs():
    """The Python block of the README's quick start executes as pasted."""
    text = (ROOT / "README.md").read_text()
    blocks = re.findall(r"```python\n(.*?)```", text, flags=re.S)
    assert blocks, "README has a python quick start"
    namespace: dict[str, object] = {}
    exec(compile(blocks[0], "README.md", "exec"), namespace)  # noqa: S102
    assert namespace["T"].shape == (4, 4)


@pytest.mark.parametrize("script", EXAMPLES, ids=[p.name for p in EXAMPLES])
def test_example_script_runs(script, examples_ran):
    """Each examples/*.py script exits with status 0 (run from a folder of its own)."""
    ran = examples_ran / script.stem
    assert (ran / "returncode").read_text() == "0", \
        (ran / "stderr.txt").read_text(encoding="utf-8")[-3000:]
