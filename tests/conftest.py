"""Suite-wide test settings.

Hypothesis explores new random examples on every developer run; under CI (``CI`` set in
the environment) it is derandomised so that a landing is judged on a reproducible suite.
Set ``HYPOTHESIS_PROFILE=explore`` to search harder locally.
"""

from __future__ import annotations

import os
import sys
from pathlib import Path

import pytest
from hypothesis import settings

# docs/_build holds helpers the docs build and the tests share (the example runner,
# fresh_python, the API as the docs see it): importable by every test module.
_DOCS_BUILD = str(Path(__file__).resolve().parents[1] / "docs" / "_build")
if _DOCS_BUILD not in sys.path:
    sys.path.insert(0, _DOCS_BUILD)

settings.register_profile("ci", derandomize=True, deadline=None, print_blob=True)
settings.register_profile("explore", max_examples=500, deadline=None)
settings.register_profile("dev", deadline=None)

# Kernels compile in the foreground, as numba does, so that every test sees compiled
# results bit for bit from its first call (the default, "background", runs a kernel as
# Python while it compiles: tests/test_background.py tests that on its own).
os.environ.setdefault("SERIALKIN_COMPILE", "wait")

_default = "ci" if os.environ.get("CI") else "dev"
settings.load_profile(os.environ.get("HYPOTHESIS_PROFILE", _default))


# ------------------------------------------------- the longest files first
#: The test files that take longest (seconds per file in a full run, largest first).
#: ``make test`` distributes whole files (``--dist loadfile``), handing a worker the next
#: file when it is nearly done with its last; pytest-xdist would otherwise send the files
#: with the most tests first (``--no-loadscope-reorder`` turns that off), and a long file
#: with few tests, sent last, kept one worker busy alone for half a minute. Sent first,
#: the long files run beside each other and the many short ones fill in around them.
LONGEST_FIRST = (
    "tests/docs/test_site.py",                   # the strict site build, the examples
    "tests/chapter/test_reproduce.py",           # every Reproduce box in its own process
    "tests/cli/test_readme.py",                  # the README's commands as typed
    "tests/cli/test_entry_point.py",
    "tests/chapter/test_report_browser.py",
    "tests/chapter/test_sections.py",
    "tests/ik/test_raghavan_roth.py",
    "tests/viz/test_viewer_body_browser.py",
    "tests/kinematics/test_symbolic.py",
    "tests/ik/test_arm_angle.py",
    "tests/reach/test_execute.py",
    "tests/viz/test_viewer_browser.py",
    "tests/ik/test_collision_ik.py",
)


def pytest_collection_modifyitems(session, config, items):
    """Run the files of :data:`LONGEST_FIRST` first, in that order (the rest as collected)."""
    rank = {name: k for k, name in enumerate(LONGEST_FIRST)}
    items.sort(key=lambda item: rank.get(item.nodeid.split("::", 1)[0], len(rank)))


# ------------------------------------------------- one compiled specialization per kernel
# Every serialkin kernel is compiled once, for one set of argument types: callers
# normalise dtype, layout and contiguity before calling (issue 27: each extra
# specialization is seconds of someone's first call). At the end of the run, every
# kernel this process compiled or loaded is checked; under pytest-xdist each worker
# writes its counts to a folder the controller reads.
_SPEC_KEY = "serialkin_specializations"


def _specializations() -> dict[str, list[str]]:
    """{kernel: its signatures} for every serialkin kernel with more than one."""
    import gc
    import re
    import sys

    if "numba" not in sys.modules:
        return {}
    from numba.core.dispatcher import Dispatcher

    found: dict[str, list[str]] = {}
    for obj in gc.get_objects():
        if issubclass(type(obj), Dispatcher):  # type(): a dead weak proxy raises on isinstance
            fn = obj.py_func
            if (fn.__module__ or "").startswith("serialkin") and len(obj.signatures) > 1:
                # compile_method's copies carry a hash of their sources: name them without
                name = re.sub(r"_[0-9a-f]{10}[01]?$", "", f"{fn.__module__}.{fn.__qualname__}")
                found[name] = [str(s) for s in obj.signatures]
    return found


def pytest_configure_node(node):  # xdist controller: one folder for the workers' reports
    """Hand every worker the folder its specialization report goes to and the shared one."""
    node.workerinput[_SPEC_KEY] = node.config._serialkin_spec_dir
    node.workerinput[_SHARED_KEY] = node.config._serialkin_shared_dir


def pytest_configure(config):
    """Make the report and shared folders (controller) when pytest-xdist distributes the run."""
    import tempfile

    if not hasattr(config, "workerinput"):
        config._serialkin_spec_dir = tempfile.mkdtemp(prefix="serialkin-spec-")
        config._serialkin_shared_dir = tempfile.mkdtemp(prefix="serialkin-shared-")


def pytest_unconfigure(config):
    """Remove the shared folder at the end of the run (controller)."""
    import shutil

    if not hasattr(config, "workerinput") and hasattr(config, "_serialkin_shared_dir"):
        shutil.rmtree(config._serialkin_shared_dir, ignore_errors=True)


# ------------------------------------------------- work shared by the workers of one run
# Some results are expensive and used by test files that pytest-xdist may send to
# different workers (the chapter report, the example scripts that the docs gallery runs
# too): each is made once per run, by whichever worker asks first, in a folder every
# worker sees; the others wait for it under a file lock and read it.
_SHARED_KEY = "serialkin_shared"


@pytest.fixture(scope="session")
def shared_once(request):
    """``shared_once(key, make) -> Path``: the folder ``make(folder)`` filled, once per run.

    The first caller of ``key`` (in any worker) runs ``make`` on an empty folder under an
    exclusive lock; later callers wait for the lock and get the same folder. A ``make``
    that raised leaves no result, so the next caller tries again (and fails the same way).
    """
    import fcntl
    import shutil
    from pathlib import Path

    config = request.config
    root = Path(config.workerinput[_SHARED_KEY] if hasattr(config, "workerinput")
                else config._serialkin_shared_dir)

    def once(key, make):
        folder = root / key
        with open(root / f"{key}.lock", "w") as lock:
            fcntl.flock(lock, fcntl.LOCK_EX)
            if not (root / f"{key}.done").exists():
                shutil.rmtree(folder, ignore_errors=True)
                folder.mkdir()
                make(folder)
                (root / f"{key}.done").touch()
        return folder

    return once


def _allowed() -> dict[str, int]:
    """The known exceptions: {kernel: specializations allowed} (tests/kernel_specializations.txt).

    A ratchet: kernels still compiled for several argument types when the check was
    introduced (mostly read-only and writeable views of the same data, and helpers called
    with tuples and with arrays), to be normalised one by one; no other kernel may have
    more than one, and none may exceed its count.
    """
    from pathlib import Path

    allowed = {}
    for line in (Path(__file__).parent / "kernel_specializations.txt").read_text().splitlines():
        line = line.split("#", 1)[0].strip()
        if line:
            name, count = line.rsplit(None, 1)
            allowed[name] = int(count)
    return allowed


def pytest_sessionfinish(session, exitstatus):
    """Fail the run when a kernel was compiled for more signatures than allowed."""
    import json
    import shutil
    from pathlib import Path

    config = session.config
    mine = _specializations()
    if hasattr(config, "workerinput"):  # a worker: report to the controller
        folder = Path(config.workerinput[_SPEC_KEY])
        (folder / f"{config.workerinput['workerid']}.json").write_text(json.dumps(mine))
        return
    folder = Path(config._serialkin_spec_dir)
    for f in folder.glob("*.json"):
        for k, v in json.loads(f.read_text()).items():
            if len(v) > len(mine.get(k, ())):
                mine[k] = v
    shutil.rmtree(folder, ignore_errors=True)
    allowed = _allowed()
    over = {k: v for k, v in mine.items() if len(v) > allowed.get(k, 1)}
    if over:
        lines = [f"{k}: {len(v)} specializations (allowed {allowed.get(k, 1)}): {'; '.join(v)}"
                 for k, v in sorted(over.items())]
        text = ("kernels compiled for more argument types than allowed (normalise their "
                "arguments; tests/kernel_specializations.txt):\n  " + "\n  ".join(lines))
        report = config.pluginmanager.get_plugin("terminalreporter")
        if report:
            report.write_line(text, red=True)
        Path(".pytest_cache").mkdir(exist_ok=True)
        Path(".pytest_cache/specializations.txt").write_text(text + "\n")
        session.exitstatus = 1


@pytest.fixture(scope="session")
def examples_ran(shared_once):
    """The folder where every examples/*.py script ran, once per test run.

    ``<folder>/<stem>`` as docs/_build/run_examples.py leaves it (``returncode``,
    ``stdout.txt``, ``stderr.txt``, ``out/``); the example tests and the docs build's
    gallery (tests/docs/test_site.py) both read it, so each script runs once.
    """
    from run_examples import run_all

    return shared_once("examples", run_all)


# ------------------------------------------------- the chapter report, built once per run
_ROOT = Path(__file__).resolve().parents[1]


@pytest.fixture(scope="session")
def built_report(shared_once):
    """(output folder, report.html text) of one full build of the chapter report.

    Built once per run, also when pytest-xdist sends the files that read it to different
    workers (``shared_once``), by ``serialkin chapter`` in a fresh process, as ``make
    run`` builds it: a build inside a test worker sees what earlier
    tests left in that process (an IK method registered by a test, such as the "gradient"
    of docs/architecture.md's example, adds a row to the numerical section's comparison
    table that its Reproduce box, run in a fresh interpreter, does not print).

    When ``make run`` has built ``out/chapter`` from these very sources with these
    library versions (its ``build.json`` equals :func:`build_provenance` of every
    section), that build is the one tested (copied): the same command on the same inputs.
    """
    import json
    import shutil
    import subprocess

    from serialkin.chapter.report import SECTION_MODULES, build_provenance

    def build(folder: Path) -> None:
        made = _ROOT / "out" / "chapter"
        try:
            recorded = json.loads((made / "build.json").read_text(encoding="utf-8"))
        except (OSError, ValueError):
            recorded = None
        if recorded == build_provenance(SECTION_MODULES):
            shutil.copytree(made, folder, dirs_exist_ok=True)
            return
        env = {**os.environ, "SERIALKIN_COMPILE": "wait"}
        cli = Path(sys.executable).parent / "serialkin"
        res = subprocess.run([str(cli), "chapter", "--out", str(folder), "-q"], env=env,
                             capture_output=True, text=True, timeout=1800, check=False)
        assert res.returncode == 0, res.stderr[-4000:]

    out = shared_once("chapter-report", build)
    return out, (out / "report.html").read_text(encoding="utf-8")


@pytest.fixture(scope="session")
def report_section(built_report):
    """``report_section(sid) -> str``: the built report's section ``sid``, as HTML.

    Its parts (``sid``, ``sid-1``, ``sid-2`` ...) in page order, joined.
    """
    import re

    _, page = built_report
    sections = re.findall(r'<section id="([^"]+)">(.*?)</section>', page, re.S)

    def section(sid: str) -> str:
        found = [body for name, body in sections if name == sid or re.fullmatch(
            re.escape(sid) + r"-\d+", name)]
        assert found, f"no section {sid!r} in the report"
        return "".join(found)

    return section
