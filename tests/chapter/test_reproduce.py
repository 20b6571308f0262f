"""Every "Reproduce" box of the chapter report prints the numbers its section shows.

Each box is run verbatim in a process of its own, in an empty folder: Python boxes as
``python -c`` runs them; shell boxes whose lines are plain ``serialkin`` commands one
command after the other, each as the ``serialkin`` console script runs it (its ``main``
with that command line), stopping at the first that fails as ``bash -e`` does; any other
shell box by ``bash -e -c`` with the venv's ``serialkin`` first on PATH. Its output must
contain the numbers the box declares (``data-expect``), in order, each to the precision
the page prints it with; and the page must show each of those numbers in the box's
section (outside the box). So a reader who copies a box gets what the page shows.
The boxes run with compiled kernels (``SERIALKIN_COMPILE=wait``), as the page says.
"""

from __future__ import annotations

import html
import json
import os
import re
import shlex
import subprocess
import sys
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

import pytest
from fresh_python import run_python  # docs/_build (on sys.path: tests/conftest.py)

from serialkin.chapter.report import SECTION_MODULES

_NUM = re.compile(r"[-−]?(?:\d+(?:\.\d*)?|\.\d+)(?:[eE][-+]?\d+)?")
_BOX = re.compile(r'<div class="repro" data-kind="(\w+)" data-expect="([^"]*)">'
                  r'<span class="repro-label">[^<]*</span><pre><code>(.*?)</code></pre></div>',
                  re.S)
_SOURCES = Path(__file__).resolve().parents[2] / "src" / "serialkin" / "chapter" / "sections"


def _value_and_half_ulp(token: str) -> tuple[float, float]:
    """A printed number and half a unit in its last printed digit ("0.25" → (0.25, 0.005))."""
    t = token.replace("−", "-").replace(",", "")
    mant, _, exp = t.lower().partition("e")
    decimals = len(mant.split(".")[1]) if "." in mant else 0
    scale = 10.0 ** (int(exp) if exp else 0)
    return float(t), 0.5 * 10.0 ** (-decimals) * scale * (1 + 1e-9)


def numbers_in(text: str) -> list[float]:
    """Every number in ``text``, in order (unicode minus accepted)."""
    return [float(m.replace("−", "-")) for m in _NUM.findall(text)]


def match_in_order(expected: list[str], printed: list[float]) -> list[str]:
    """The expected tokens not found, in order, among ``printed`` to their printed precision.

    Greedy earliest matching: finds the in-order match whenever one exists.
    """
    missing = []
    k = 0
    for token in expected:
        value, tol = _value_and_half_ulp(token)
        j = next((i for i in range(k, len(printed)) if abs(printed[i] - value) <= tol), None)
        if j is None:
            missing.append(token)
        else:
            k = j + 1
    return missing


def _visible(fragment: str) -> str:
    text = re.sub(r"<math.*?</math>", " ", fragment, flags=re.S)
    text = re.sub(r'src="data:[^"]+"', "", text)
    return html.unescape(re.sub(r"<[^>]+>", " ", text))


def report_boxes(page: str) -> list[dict]:
    """Every box of the page: section id, kind, code, expected numbers, the section's text."""
    boxes = []
    for sid, body in re.findall(r'<section id="([^"]+)">(.*?)</section>', page, re.S):
        shown = _visible(_BOX.sub(" ", body))
        for kind, expect, code in _BOX.findall(body):
            boxes.append({"section": sid, "kind": kind, "code": html.unescape(code),
                          "expect": json.loads(html.unescape(expect)), "shown": shown})
    return boxes


def run_box(box: dict, cwd: Path) -> subprocess.CompletedProcess:
    """Run a box's exact text in a process of its own in ``cwd``.

    Python boxes as ``python -c`` would run them, and the ``serialkin`` commands of a
    shell box each as the console script would, in children of the fork server of
    docs/_build/fresh_python.py (the imports and numba's set-up done once for every box; no
    serialkin function called before the box's own); any other shell box by ``bash -e -c``.
    """
    env = dict(os.environ)
    env["PATH"] = str(Path(sys.executable).parent) + os.pathsep + env.get("PATH", "")
    # compiled kernels, as when the page was built: while kernels compile in the background
    # the first calls run as Python, whose rounding differs in the last digits, and a long
    # tracking run (the 20-link arm, 6,841 iterations) then follows another path
    env["SERIALKIN_COMPILE"] = "wait"
    if box["kind"] == "python":
        return _python(box["code"], cwd, env, "")
    commands = serialkin_commands(box["code"])
    if not commands:
        return subprocess.run(["bash", "-e", "-c", box["code"]], cwd=cwd, env=env,
                              capture_output=True, text=True, timeout=900, check=False)
    outs, errs = [], []
    for k, argv in enumerate(commands):
        # the console script's own lines (pip's entry-point wrapper), on this command line
        res = _python(f"import sys\nsys.argv = {argv!r}\nfrom serialkin.cli.main import main\n"
                      f"sys.exit(main())\n", cwd, env, f".{k}")
        outs.append(res.stdout)
        errs.append(res.stderr)
        if res.returncode != 0:
            break
    return subprocess.CompletedProcess(["bash", "-e", "-c", box["code"]], res.returncode,
                                       "".join(outs), "".join(errs))


def serialkin_commands(script: str) -> list[list[str]] | None:
    """The command lines of a shell script made only of plain ``serialkin`` commands.

    None when a line does anything else (another program, a pipe, a redirection, a
    variable, a substitution, a line continuation): such a script runs in bash.
    """
    commands = []
    for line in script.splitlines():
        if any(c in line for c in "|&;<>$`\\(){}*?[]~!") or re.search(r"\S#", line):
            return None  # (a # inside a word, or quoted, is not a comment to bash)
        try:
            words = shlex.split(line, comments=True)
        except ValueError:  # a quote left open: bash decides
            return None
        if words and words[0] != "serialkin":
            return None
        if words:
            commands.append(words)
    return commands


def _python(code: str, cwd: Path, env: dict[str, str], tag: str) -> subprocess.CompletedProcess:
    """``python -c code`` in a child of docs/_build/fresh_python.py's fork server."""
    streams = cwd.parent / f"{cwd.name}{tag}.stdout", cwd.parent / f"{cwd.name}{tag}.stderr"
    status = run_python(code=code, cwd=cwd, env=env, stdout=streams[0], stderr=streams[1],
                        timeout=900)
    out, err = (s.read_text(encoding="utf-8") for s in streams)
    return subprocess.CompletedProcess(["python", "-c", code], status, out, err)


def test_only_plain_serialkin_commands_skip_bash():
    """Plain ``serialkin`` lines (comments, quoting) are split; anything else goes to bash."""
    assert serialkin_commands('serialkin fk ur5 --q "0, 0"   # a comment\n\nserialkin models') \
        == [["serialkin", "fk", "ur5", "--q", "0, 0"], ["serialkin", "models"]]
    for script in ("serialkin fk ur5 | head", "ls", "serialkin fk $ROBOT", "serialkin a; ls",
                   "serialkin fk ur5 > out.txt", "serialkin fk \\\n ur5", "cd x && serialkin",
                   'serialkin x "#" | head', "serialkin a#b", 'serialkin "open', "serialkin ~/x"):
        assert serialkin_commands(script) is None, script


def test_match_in_order_uses_the_printed_precision():
    """0.25 matches 0.2512 (two decimals) but not 0.256; order matters; e-notation scales."""
    assert match_in_order(["0.25", "1.3e-07"], numbers_in("x 0.2512 y 1.34e-07")) == []
    assert match_in_order(["0.25"], numbers_in("0.256")) == ["0.25"]
    assert match_in_order(["2", "1"], numbers_in("1 2")) == ["1"]
    assert match_in_order(["−0.0701"], numbers_in("[-0.07013991]")) == []


@pytest.mark.slow
def test_every_box_is_collected(built_report):
    """The page has one box per ``ctx.reproduce`` call of the sections, each declaring numbers."""
    _, page = built_report
    boxes = report_boxes(page)
    calls = sum(p.read_text(encoding="utf-8").count("ctx.reproduce(")
                for p in _SOURCES.rglob("*.py"))
    assert len(boxes) == calls == page.count('class="repro"'), (len(boxes), calls)
    assert {b["section"].split("-")[0] for b in boxes} >= set(SECTION_MODULES)
    empty = [b["code"][:60] for b in boxes if not b["expect"]]
    assert not empty, empty


@pytest.mark.slow
def test_page_shows_every_number_a_box_declares(built_report):
    """Each number a box declares appears, as printed, in the text of the box's section."""
    _, page = built_report
    absent = [(b["section"], t) for b in report_boxes(page) for t in b["expect"]
              if t not in b["shown"].replace("−", "-")]
    assert not absent, absent[:10]


@pytest.mark.slow
def test_every_box_reproduces_the_page(built_report, tmp_path):
    """Run verbatim in a fresh process, every box prints the numbers its section shows."""
    _, page = built_report
    boxes = report_boxes(page)

    def check(item: tuple[int, dict]) -> str | None:
        k, box = item
        folder = tmp_path / f"box{k}"
        folder.mkdir()
        res = run_box(box, folder)
        if res.returncode != 0:
            return f"box {k} ({box['section']}) failed:\n{box['code']}\n{res.stderr[-1500:]}"
        missing = match_in_order(box["expect"], numbers_in(res.stdout))
        if missing:
            return (f"box {k} ({box['section']}) does not print {missing}:\n{box['code']}\n"
                    f"--- output:\n{res.stdout[-8000:]}")
        return None

    with ThreadPoolExecutor(max_workers=2) as pool:
        failures = [f for f in pool.map(check, enumerate(boxes)) if f]
    assert not failures, "\n\n".join(failures)
