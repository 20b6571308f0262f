"""Hostile input to every CLI subcommand (issue 10): one ``Error:`` line and exit 2, or a result.

The promise checked here: a run either succeeds (exit 0), reports a target it could not
reach (exit 1, only for ik/ik-compare/track), or refuses its input with exactly one
``Error: ...`` line on stderr and exit 2 — never a traceback, never half-written files.
"""

from __future__ import annotations

import errno
import os
import subprocess
import sys
from pathlib import Path

import pytest
from click.testing import CliRunner
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from serialkin._budget import set_memory_budget
from serialkin.cli.main import cli

SUBCOMMANDS = ("chapter", "models", "fk", "jacobian", "ik", "ik-compare", "track",
               "workspace", "view")


def invoke(*args: object):
    """Run the CLI in-process; return click's result (exceptions are caught and asserted on)."""
    return CliRunner().invoke(cli, [str(a) for a in args])


def assert_refused(result, *, contains: str = "") -> str:
    """Exit 2, exactly one stderr line, starting with 'Error:', no traceback; returns it."""
    assert result.exit_code == 2, (result.exit_code, result.output, result.exception)
    lines = [ln for ln in result.stderr.splitlines() if ln.strip()]
    errors = [ln for ln in lines if ln.startswith("Error:")]
    assert len(errors) == 1, lines
    assert "Traceback" not in result.output
    if contains:
        assert contains in errors[0], errors[0]
    return errors[0]


def assert_promise(result, *, may_fail: bool = False) -> None:
    """The promise: success, or (ik/track) not reached, or one Error line and exit 2."""
    assert "Traceback" not in result.output
    if result.exception is not None and not isinstance(result.exception, SystemExit):
        raise AssertionError(f"uncaught {type(result.exception).__name__}: {result.exception}")
    allowed = (0, 1, 2) if may_fail else (0, 2)
    assert result.exit_code in allowed, (result.exit_code, result.output)
    if result.exit_code == 2:
        errors = [ln for ln in result.stderr.splitlines() if ln.startswith("Error:")]
        assert len(errors) == 1, result.stderr


def files_under(folder: Path) -> list[Path]:
    """Every file below ``folder`` (none when it does not exist)."""
    return sorted(p for p in folder.rglob("*") if p.is_file()) if folder.exists() else []


@pytest.fixture(autouse=True)
def _reset_budget():
    yield
    set_memory_budget(None)


# ---------------------------------------------------------------- input before output
@pytest.mark.parametrize("option", [("--fps", "0"), ("--fps", "nan"), ("--fps", "-3"),
                                    ("--max-frames", "0"), ("--max-frames", "-1"),
                                    ("--max-frames", str(2**63))])
def test_track_bad_animation_options_write_nothing(tmp_path, option):
    """Track with --fps 0 / --max-frames 0 is refused before any file or folder is made."""
    out = tmp_path / "t"
    assert_refused(invoke("track", "six_link_circle", "--out", out, *option))
    assert not out.exists()


@pytest.mark.parametrize("robot, slice_, message", [
    ("two_link", "z=0", "planar"),
    ("ur5", "q=0", "axis must be x, y or z"),
    ("ur5", "z", "expected AXIS=VALUE"),
    ("ur5", "z=abc", "not a number"),
])
def test_workspace_bad_slice_writes_nothing(tmp_path, robot, slice_, message):
    """Bad workspace --slice values are refused before sampling and before any file."""
    out = tmp_path / "w"
    assert_refused(invoke("workspace", robot, "--slice", slice_, "--out", out, "-n", "2000"),
                   contains=message)
    assert files_under(out) == []


@pytest.mark.parametrize("args, setting", [
    (("--cell", "1e-6"), "--cell"),
    (("--resolution", "100000"), "--resolution"),
    (("--samples", str(10**12)), "--samples"),
])
def test_workspace_sizes_beyond_budget(tmp_path, args, setting):
    """Huge grids or sample counts are refused before allocation, naming the setting."""
    out = tmp_path / "w"
    line = assert_refused(invoke("workspace", "two_link", "--out", out, "-n", "2000", *args),
                          contains=setting)
    assert "memory budget" in line and "--memory-budget" in line
    assert not out.exists()


def test_memory_budget_option_lowers_the_budget(tmp_path):
    """--memory-budget (group or subcommand) refuses what the default budget allows."""
    args = ("workspace", "two_link", "--out", tmp_path / "w", "--resolution", "3000",
            "-n", "1000", "--no-plot")
    assert_refused(invoke("--memory-budget", "100M", *args), contains="100 MiB")
    assert_refused(invoke(*args, "--memory-budget", "100M"), contains="100 MiB")
    assert_refused(invoke(*args, "--memory-budget", "lots"), contains="--memory-budget")
    assert invoke(*args).exit_code == 0


def test_fk_planar_huge_refused_before_allocation():
    """'fk planar100000000' is refused at once (bounded number of joints)."""
    assert_refused(invoke("fk", "planar100000000"), contains="at most 10000")
    assert_refused(invoke("fk", "planar" + "9" * 5000), contains="at most 10000")


@pytest.mark.parametrize("option", [("--max-iter", str(2**63)), ("--restarts", str(2**64)),
                                    ("--max-iter", "0"), ("--restarts", "-1")])
def test_ik_integer_options_bounded(option):
    """IK with --max-iter 2**63 / --restarts 2**64 is refused (never 0 iterations, exit 1)."""
    assert_refused(invoke("ik", "two_link", "--target", "1.2,0.4", *option))


def test_chapter_out_is_a_file(tmp_path):
    """Chapter --out an existing file (or a path under one): exit 2, file untouched."""
    f = tmp_path / "file.txt"
    f.write_text("keep")
    line = assert_refused(invoke("chapter", "--out", f, "--section", "forward"))
    assert "is a file" in line or "not a folder" in line
    assert_refused(invoke("chapter", "--out", f / "sub", "--section", "forward"))
    assert f.read_text() == "keep"


def test_chapter_unwritable_folder(tmp_path, monkeypatch):
    """Chapter --out a folder the process may not write (per os.access): exit 2."""
    real = os.access
    target = tmp_path / "locked"
    target.mkdir()
    monkeypatch.setattr(os, "access", lambda p, m, **kw: False if Path(p) == target and m & os.W_OK
                        else real(p, m, **kw))
    assert_refused(invoke("chapter", "--out", target, "--section", "forward"),
                   contains="not writable")
    assert files_under(target) == []


def test_chapter_full_disk(tmp_path, monkeypatch):
    """A full disk while the report is written: one Error line, exit 2, no partial file."""
    import serialkin._io as sio

    def full(*args, **kwargs):
        raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))

    monkeypatch.setattr(sio.os, "fdopen", full)
    out = tmp_path / "ch"
    line = assert_refused(invoke("chapter", "--out", out, "--section", "forward"))
    assert "No space left on device" in line
    assert files_under(out) == []  # every write failed: no partial or temporary file


# ---------------------------------------------------------------- every subcommand
HOSTILE = {
    "models": [("nope",), ("planar0",), ("planar-5",), ("x" * 10_000,), ("ur5", "--save",
                                                                         "/dev/null/x.yaml")],
    "fk": [("ur5", "--q", "1,2"), ("ur5", "--q", "nan,0,0,0,0,0"), ("ur5", "--q", "1e400"),
           ("ur5", "--q-file", "/nonexistent.csv"), ("two_link", "--q", "a,b"),
           ("ur5", "--param", "x")],
    "jacobian": [("ur5", "--q", ""), ("ur5", "--frame", "nope"), ("ur5", "--q", "inf,0,0,0,0,0")],
    "ik": [("two_link",), ("two_link", "--target", "nan,0"), ("ur5", "--target", "1,2"),
           ("two_link", "--target", "1,0", "--method", "nope"),
           ("two_link", "--target", "1,0", "--tol", "-1"),
           ("two_link", "--target", "1,0", "--option", "damping=abc")],
    "ik-compare": [("two_link", "--targets", "-1"), ("two_link", "--targets", str(2**70)),
                   ("two_link", "--option", "nope")],
    "track": [("nope",), ("/nonexistent.yaml",), ()],
    "workspace": [("two_link", "--kind", "constant"), ("two_link", "--kind", "inclusive",
                                                       "--orientation", "0"),
                  ("ur5", "--kind", "constant", "--orientation", "1,2", "-n", "300"),
                  ("two_link", "--margin", "nan", "-n", "300", "--no-plot"),
                  ("two_link", "--max-angle", "inf", "-n", "300", "--no-plot")],
    "view": [("two_link", "--q", "1"), ("two_link", "--trajectory", "/nonexistent.csv")],
    "chapter": [("--section", "nope"), ("--section", "x" * 5000)],
}


@pytest.mark.parametrize("command, args", [(c, a) for c, cases in HOSTILE.items()
                                            for a in cases])
def test_hostile_arguments_every_subcommand(tmp_path, command, args):
    """Hand-written hostile arguments to each subcommand keep the promise (no traceback)."""
    assert set(HOSTILE) == set(SUBCOMMANDS)
    out_args = () if command in ("models", "fk", "jacobian", "ik", "ik-compare") else (
        "--out", tmp_path / "o")
    if command == "view":
        out_args = ("--out", tmp_path / "o" / "v.html")
    result = invoke(command, *args, *out_args)
    assert_promise(result, may_fail=command in ("ik", "ik-compare", "track"))
    assert result.exit_code != 0 or command in ("models",), result.output


def test_view_corrupt_trajectories(tmp_path):
    """View --trajectory with corrupt files: one Error line, exit 2, no page written."""
    cases = {
        "bad.json": b"{not json",
        "text.csv": b"q1,q2\nfoo,bar\n",
        "notzip.npz": b"this is not a zip file",
        "bin.csv": bytes(range(256)) * 4,
    }
    for name, data in cases.items():
        p = tmp_path / name
        p.write_bytes(data)
        out = tmp_path / f"{name}.html"
        result = invoke("view", "two_link", "--trajectory", p, "--out", out)
        assert_promise(result)
        assert result.exit_code == 2, (name, result.output)
        assert not out.exists()


def test_one_line_for_multi_line_messages(tmp_path):
    """A library message holding line breaks (from a hostile name) is printed on one line."""
    robot = tmp_path / "r.yaml"
    robot.write_text('name: "arm\\nsecond line"\ndh:\n  - {a: 1, alpha: 0, d: 0, theta: 0}\n')
    result = invoke("fk", robot, "--q", "1,2")
    assert_refused(result)
    assert "second line" in result.stderr.splitlines()[-1] or "second" not in result.stderr


# ---------------------------------------------------------------- fuzzing
_TEXT = st.text(alphabet=st.characters(blacklist_categories=("Cs",)), max_size=30)
_NUMBERISH = st.one_of(
    _TEXT,
    st.lists(st.one_of(st.floats(allow_nan=True, allow_infinity=True),
                       st.integers(-10**30, 10**30)), max_size=8)
    .map(lambda v: ",".join(str(x) for x in v)),
)


@settings(max_examples=40, deadline=None, suppress_health_check=[HealthCheck.too_slow,
                                                                   HealthCheck.function_scoped_fixture])
@given(command=st.sampled_from(["fk", "jacobian", "ik"]), value=_NUMBERISH,
       robot=st.sampled_from(["two_link", "ur5", "planar3"]))
def test_fuzz_numeric_arguments(command, value, robot):
    """Random text as --q / --target keeps the promise for fk, jacobian and ik."""
    opt = "--target" if command == "ik" else "--q"
    result = invoke(command, robot, opt, value, "--max-iter" if command == "ik" else "--json",
                    *(("50",) if command == "ik" else ()))
    assert_promise(result, may_fail=command == "ik")


@settings(max_examples=25, deadline=None, suppress_health_check=[HealthCheck.too_slow,
                                                                   HealthCheck.function_scoped_fixture])
@given(option=st.sampled_from(["--cell", "--resolution", "--samples", "--seed", "--margin",
                               "--orientations", "--max-angle"]),
       value=st.one_of(_TEXT, st.integers(-5, 40).map(str),
                       st.integers(10**12, 10**25).map(str), st.floats().map(repr)))
def test_fuzz_workspace_options(tmp_path_factory, option, value):
    """Random workspace option values: a result, or one Error line, never a traceback."""
    out = tmp_path_factory.mktemp("ws")
    result = invoke("--memory-budget", "200M", "workspace", "two_link", "-n", "500",
                    "--no-plot", "--no-points",
                    "--kind", "dexterous" if option in ("--margin", "--orientations")
                    else "reachable", option, value, "--out", out, "-q")
    assert_promise(result)


# ---------------------------------------------------------------- real processes
def _exe() -> list[str]:
    return [sys.executable, "-m", "serialkin.cli.main"]


@pytest.mark.parametrize("args", [
    ["fk", "planar100000000"],
    ["track", "six_link_circle", "--fps", "0"],
    ["workspace", "two_link", "--cell", "1e-6"],
    ["ik", "two_link", "--target", "1,0", "--max-iter", str(2**63)],
])
def test_subprocess_one_error_line(tmp_path, args):
    """As a real process: exit 2, exactly one stderr line 'Error: ...', nothing written."""
    env = {**os.environ, "PYTHONPATH": str(Path(__file__).resolve().parents[2] / "src")}
    proc = subprocess.run([*_exe(), *args], cwd=tmp_path, capture_output=True, text=True,
                          timeout=600, env=env)
    assert proc.returncode == 2, (proc.returncode, proc.stderr[-2000:])
    lines = proc.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("Error: "), lines
    assert list(tmp_path.iterdir()) == []
