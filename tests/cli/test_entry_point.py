"""The installed ``serialkin`` console script, run as a real subprocess."""

from __future__ import annotations

import json
import math
import os
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from serialkin import models


def _exe() -> str:
    local = Path(sys.executable).parent / "serialkin"
    found = str(local) if local.exists() else shutil.which("serialkin")
    if not found:
        pytest.skip("the serialkin console script is not installed (pip install -e .)")
    return found


def sk(*args: object, cwd: Path, code: int = 0) -> subprocess.CompletedProcess[str]:
    """Run the console script as a user does: the default compile mode, not the suite's.

    The suite's own processes compile in the foreground (``SERIALKIN_COMPILE=wait``,
    tests/conftest.py); a user's first calls of a one-shot command run as Python
    (``_background.answer_first``), and so do these.
    """
    env = {k: v for k, v in os.environ.items() if k != "SERIALKIN_COMPILE"}
    proc = subprocess.run([_exe(), *map(str, args)], cwd=cwd, capture_output=True, text=True,
                          timeout=300, env=env)
    assert proc.returncode == code, (proc.returncode, proc.stdout[-2000:], proc.stderr[-2000:])
    return proc


def test_models(tmp_path):
    """'serialkin models --json' lists the catalog."""
    data = json.loads(sk("models", "--json", cwd=tmp_path).stdout)
    assert [m["name"] for m in data["models"]] == list(models.names())


def test_fk_and_jacobian(tmp_path):
    """The fk and jacobian JSON equal the library's FK and Jacobian."""
    r = models.get("panda")
    q = r.random_q(seed=1)
    qs = ",".join(repr(float(v)) for v in q)
    fk = json.loads(sk("fk", "panda", "--q", qs, "--json", cwd=tmp_path).stdout)
    np.testing.assert_allclose(fk["results"][0]["T"], r.fk(q), atol=1e-12)
    jac = json.loads(sk("jacobian", "panda", "--q", qs, "--json", cwd=tmp_path).stdout)
    np.testing.assert_allclose(jac["results"][0]["J"], r.jacobian(q), atol=1e-12)


def test_ik_out_of_reach(tmp_path):
    """Out of reach: exit code 1, a stderr line, strict JSON with success false on stdout."""
    proc = sk("ik", "two_link", "--target", "5,0", "--json", cwd=tmp_path, code=1)
    data = json.loads(proc.stdout)
    assert data["success"] is False
    assert "not reached" in proc.stderr


def test_ik_reachable(tmp_path):
    """A reachable planar target is solved and FK of the answer hits it."""
    data = json.loads(sk("ik", "three_link", "--target", "1.0,0.8,0.5", "--json",
                         cwd=tmp_path).stdout)
    q = np.array(data["results"][0]["q"])
    T = models.get("three_link").fk(q)
    np.testing.assert_allclose(T[:2, 3], [1.0, 0.8], atol=1e-8)
    assert math.atan2(T[1, 0], T[0, 0]) == pytest.approx(0.5, abs=1e-8)


def test_workspace_piped_has_no_progress_bar(tmp_path):
    """The workspace subcommand writes its files; piped, it draws no progress bar."""
    proc = sk("workspace", "two_link", "--samples", "100000", "--out", "ws", cwd=tmp_path)
    assert "area" in proc.stdout
    assert "it/s" not in proc.stderr and "q/s" not in proc.stderr and "%|" not in proc.stderr
    summary = json.loads((tmp_path / "ws" / "workspace_reachable.json").read_text())
    assert abs(summary["area"]["value"] - 4 * math.pi) <= summary["area"]["error"]
    assert (tmp_path / "ws" / "workspace_reachable.png").stat().st_size > 1000


def test_track_and_view(tmp_path):
    """The track subcommand writes a trajectory the view subcommand can show."""
    proc = sk("track", "six_link_circle", "--out", "tr", "--no-animation", "--no-figures",
              "--format", "npz", "--json", cwd=tmp_path)
    data = json.loads(proc.stdout)
    assert data["success"] is True
    traj = tmp_path / "tr" / "six_link_circle.npz"
    assert traj.is_file()
    view = json.loads(sk("view", "planar6", "--param", "lengths=[0.1, 0.1, 0.1, 0.1, 0.1, 0.1]",
                         "--trajectory", traj, "--out", "v.html", "--json", cwd=tmp_path).stdout)
    assert view["frames"] == data["computed"]
    assert (tmp_path / "v.html").read_text().lstrip().lower().startswith("<!doctype html")


def test_bad_input_exit_code(tmp_path):
    """Bad input: exit code 2 and one 'Error:' line, no traceback."""
    proc = sk("fk", "pumma560", cwd=tmp_path, code=2)
    assert proc.stderr.startswith("Error:") and "puma560" in proc.stderr
    assert "Traceback" not in proc.stderr


def _run_on_terminal(args: list[str], cwd: Path) -> tuple[int, str]:
    """Run the script with stderr on a pseudo-terminal; return exit code and what it drew."""
    import fcntl
    import os
    import pty
    import struct
    import termios

    master, slave = pty.openpty()
    # a real terminal has a size; tqdm draws nothing on a zero-column one
    fcntl.ioctl(slave, termios.TIOCSWINSZ, struct.pack("HHHH", 24, 100, 0, 0))
    try:
        proc = subprocess.run([_exe(), *args], cwd=cwd, stdout=subprocess.DEVNULL,
                              stderr=slave, timeout=300)
        os.close(slave)
        chunks = []
        while True:
            try:
                data = os.read(master, 65536)
            except OSError:
                break
            if not data:
                break
            chunks.append(data)
    finally:
        os.close(master)
    return proc.returncode, b"".join(chunks).decode("utf-8", "replace")


def test_progress_bar_on_terminal_only_without_quiet(tmp_path):
    """On a terminal a long workspace run draws a progress bar; --quiet draws none."""
    args = ["workspace", "two_link", "--samples", "200000", "--no-plot", "--out", "ws"]
    code, drawn = _run_on_terminal(args, tmp_path)
    assert code == 0 and "workspace" in drawn and "%" in drawn
    code, drawn = _run_on_terminal(args + ["--quiet"], tmp_path)
    assert code == 0 and drawn == ""
