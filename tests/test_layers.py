"""The layer contract (issue 28): a module imports only from its layer and the layers below.

The layers are listed in pyproject.toml (``[tool.importlinter]``) and drawn in
docs/architecture.md; import-linter checks every import, deferred ones inside functions
included. Every package and module of serialkin must be placed in a layer, so that a new
one cannot sit outside the contract.
"""

from __future__ import annotations

import subprocess
import sys
import tomllib
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]


def _layers() -> list[str]:
    config = tomllib.loads((ROOT / "pyproject.toml").read_text())["tool"]["importlinter"]
    (contract,) = config["contracts"]
    return [name.strip() for layer in contract["layers"] for name in layer.split("|")]


def test_every_package_and_module_has_a_layer():
    here = ROOT / "src" / "serialkin"
    found = {f"serialkin.{p.stem}" for p in here.iterdir()
             if (p.suffix == ".py" and p.stem != "__init__")
             or (p.is_dir() and (p / "__init__.py").exists())}
    assert found - set(_layers()) == set(), "place these in a layer of pyproject.toml"
    assert set(_layers()) - found == set(), "layers name modules that do not exist"


def test_the_layer_contract_is_kept():
    linter = Path(sys.executable).parent / "lint-imports"
    if not linter.exists():
        pytest.skip("import-linter is not installed (the dev extra installs it)")
    p = subprocess.run([str(linter), str(ROOT / "pyproject.toml")], cwd=ROOT,
                       capture_output=True, text=True, check=False)
    assert p.returncode == 0, p.stdout[-4000:] + p.stderr[-2000:]
    assert "1 kept, 0 broken" in p.stdout
