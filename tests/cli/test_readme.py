"""The README's command-line examples and workspace snippet run as documented."""

from __future__ import annotations

import re
import shlex
from pathlib import Path

import numpy as np
import pytest
from click.testing import CliRunner

from serialkin import models
from serialkin.cli.main import cli

README = Path(__file__).resolve().parents[2] / "README.md"


def _section(title: str) -> str:
    text = README.read_text(encoding="utf-8")
    start = text.index(title)
    end = text.find("\n## ", start + len(title))
    return text[start:end if end > 0 else len(text)]


def _commands() -> list[list[str]]:
    block = re.findall(r"```bash\n(.*?)```", _section("## Command line"), flags=re.S)[0]
    cmds = []
    for line in block.splitlines():
        line = line.split("  #")[0].strip()
        if line:
            cmds.append(shlex.split(line))
    return cmds


COMMANDS = _commands()


@pytest.mark.slow
@pytest.mark.parametrize("argv", COMMANDS, ids=[" ".join(c[1:3]) for c in COMMANDS])
def test_readme_command_runs(argv, tmp_path, monkeypatch):
    """Each command of the README's Command line block exits with status 0."""
    assert argv[0] == "serialkin"
    args = argv[1:]
    if args[0] == "chapter":  # the full report is built by tests/chapter; one section here
        args += ["--section", "rigid_motion", "--quiet"]
    if args[0] == "workspace":
        args += ["--samples", "20000"]  # the documented command, with fewer samples
    if args[0] == "track":
        args += ["--max-frames", "3"]
    if args[0] == "reach":  # the documented command on a coarser grid (1/8 of the cells)
        args[args.index("--resolution") + 1] = "0.2"
    monkeypatch.chdir(tmp_path)
    if args[0] == "base-placement":  # the task poses the command reads
        Path("tasks.yaml").write_text("tasks:\n  - [0.4, 0.1, 0.3, 3.1416, 0, 0]\n"
                                      "  - [0.4, -0.2, 0.2, 3.1416, 0, 0]\n")
    if args[0] == "calibrate" and "--simulate" not in args:  # measurements to fit
        sim = ["calibrate", "ur5", "--simulate", "60", "--measurements", "meas.csv"]
        assert CliRunner().invoke(cli, sim, catch_exceptions=False).exit_code == 0
    monkeypatch.setattr("webbrowser.open", lambda url: True)
    r = models.get("ur5")
    T = r.fk(r.random_q(3, seed=0))
    Path("targets.csv").write_text("".join(",".join(repr(float(v)) for v in t.ravel()) + "\n"
                                           for t in T))
    result = CliRunner().invoke(cli, args, catch_exceptions=False)
    assert result.exit_code == 0, result.output


@pytest.mark.slow
def test_readme_workspace_snippet(monkeypatch, tmp_path):
    """The README's workspace snippet runs and its area agrees with the closed form."""
    monkeypatch.chdir(tmp_path)
    code = re.findall(r"```python\n(.*?)```", _section("### Workspace analysis in Python"),
                      flags=re.S)[0]
    ns: dict[str, object] = {}
    exec(compile(code, "README.md", "exec"), ns)  # noqa: S102
    est = ns["ws"].estimate
    assert abs(est.value - np.pi * (1.6**2 - 0.4**2)) <= est.error
    assert ns["dex"].estimate.value > 0
