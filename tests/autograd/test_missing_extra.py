"""Without its extra, importing serialkin.torch or serialkin.jax says which extra to install."""

from __future__ import annotations

import subprocess
import sys

import pytest


@pytest.mark.parametrize("name", ["torch", "jax"])
def test_import_without_the_extra_names_it(name):
    """With the framework hidden, ``import serialkin.<name>`` raises ImportError with pip's line."""
    code = (f"import sys; sys.modules[{name!r}] = None\n"
            "try:\n"
            f"    import serialkin.{name}\n"
            "except ImportError as exc:\n"
            "    print(exc)\n")
    p = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                       check=False, timeout=300)
    assert p.returncode == 0, p.stderr[-2000:]
    assert f'pip install "serialkin[{name}]"' in p.stdout
