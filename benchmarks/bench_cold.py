"""Cold start: the first call in a fresh Python process, numba cache empty and filled.

Run by hand: ``.venv/bin/python benchmarks/bench_cold.py [--repeats 3] [--cold-repeats 1]
[--rows 1,2,9] [--no-cold] [--timeout 900]``.

Every row is one snippet run in a **fresh process** (``sys.executable -c SNIPPET``, or the
``serialkin`` console script for the CLI row), timed three ways: from process start to
the answer (the snippet prints the clock time of its answer as JSON on stdout; the
figure the goals are judged on), from process start to exit (a process that answered
with kernels still compiling in the background finishes them before it exits), and,
inside the snippet, from the end of its imports to the answer (row 1: the ``import
serialkin`` statement itself). Conditions per serialkin row:

* **cold**: ``NUMBA_CACHE_DIR`` is a new empty directory and ``SERIALKIN_COMPILE`` unset
  (the default: a kernel not yet compiled runs as Python while it compiles on a worker
  thread). The first cold run of a row fills that row's own cache directory; each
  further cold run (``--cold-repeats``) gets another new empty directory.
* **cold-wait** (``--wait-cold``): the same with ``SERIALKIN_COMPILE=wait``, numba
  compiling every kernel before the answer (the behaviour before background compiles).
* **warm**: ``NUMBA_CACHE_DIR`` is the directory that the row's first run filled (the
  same snippet; with ``--no-cold`` that run is made untimed), so numba loads the kernels.

The peers have no numba cache: one condition, "first", in the same run, each after one
untimed run (as serialkin's warm rows, the files they read are then in the OS cache):

* Pinocchio: ``import pinocchio``, the UR5 model from example-robot-data's
  ``ur5_robot.urdf`` (``buildModelFromUrdf``, kinematics only), ``forwardKinematics`` +
  ``updateFramePlacements`` + ``computeFrameJacobian`` of ``tool0`` at q = 0;
* Robotics Toolbox: ``import roboticstoolbox``, ``rtb.models.Panda().ik_LM(T)`` for T
  the FK of its ``qr`` configuration.

Every subprocess runs with the parent's environment, except ``OPENBLAS_NUM_THREADS=1``
and ``MKL_NUM_THREADS=1`` (as every benchmark process, see ``_common.py``) and
``NUMBA_CACHE_DIR`` and ``SERIALKIN_COMPILE``: never inherited, set only as above;
``PYTHONDONTWRITEBYTECODE`` is not inherited either (a user's Python keeps the modules'
bytecode, and an import that compiles every module from source is not what they meet). Figures
are median [min–max] of the runs; ``/pin`` is the ratio of the answer-time median to
Pinocchio's first call in the same run (rows 2–7, when row 9 runs).
The temporary cache directories are deleted at the end. A run past ``--timeout`` seconds
is killed and reported as "timeout"; a failing snippet as "error: ..." (its last line
of stderr). Cold rows cost up to minutes of CPU each (numba compiling the IK kernels).
"""

from __future__ import annotations

import argparse
import json
import os
import shutil
import subprocess
import sys
import tempfile
import time
from dataclasses import dataclass, field
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from _common import Stat, header, record  # noqa: E402
from tests.erd import urdf  # noqa: E402

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent
#: Goal id under which the rows with a goal are recorded for ``run_all.py``'s summary.
GOAL_ID = "27.1"

# ---------------------------------------------------------------------------- snippets
# Each snippet prints one JSON line: {"import_s", "call_s", "ok", "check"} (or "missing").
_HEAD = "import time\n_t0 = time.perf_counter()\nimport json\n"
_TAIL = ("_t2 = time.perf_counter()\n"
         "print(json.dumps({'import_s': _t1 - _t0, 'call_s': _t2 - _t1, 'ok': bool(ok), "
         "'check': check, 'answer_at': time.time()}), flush=True)\n")
_SK = "import numpy as np\nfrom serialkin import models\n_t1 = time.perf_counter()\n"


def _snippet(imports: str, body: str) -> str:
    return _HEAD + imports + body + _TAIL


SNIPPETS = {
    1: _snippet("_t1 = time.perf_counter()\n",
                "import serialkin\nok = True\ncheck = 'imported'\n"),
    2: _snippet(_SK,
                "T = models.get('ur5').fk(np.zeros(6))\n"
                "ok = T.shape == (4, 4)\ncheck = 'T ' + str(T.shape)\n"),
    3: _snippet(_SK,
                "robot = models.get('ur5')\nJ = robot.jacobian(np.zeros(6))\n"
                "ok = J.shape == (6, 6)\ncheck = 'J ' + str(J.shape)\n"),
    4: _snippet(_SK,
                "robot = models.get('panda')\nT = robot.fk(robot.random_q(seed=1))\n"
                "r = robot.ik(T)\nok = bool(r.success)\n"
                "check = 'success' if ok else 'no success: ' + str(r.reason)\n"),
    5: _snippet(_SK,
                "robot = models.get('panda')\nT = robot.fk(robot.random_q(300, seed=1))\n"
                "r = robot.ik(T)\nn_ok = int(np.count_nonzero(r.success))\n"
                "ok = n_ok == len(T)\ncheck = f'success {n_ok}/{len(T)}'\n"),
    6: _snippet(_SK,
                "robot = models.get('ur5')\nT = robot.fk(robot.random_q(seed=1))\n"
                "S = robot.ik_all(T)\nok = len(S) > 0\ncheck = f'{len(S)} solutions'\n"),
    7: _snippet(_SK,
                "robot = models.get('panda')\nT = robot.fk(robot.random_q(seed=1))\n"
                "try:\n"
                "    r = robot.ik(T, self_collision=True)\n"
                "    ok = bool(r.success)\n"
                "    check = 'success' if ok else 'no success: ' + str(r.reason)\n"
                "except Exception as e:\n"
                "    ok = False\n"
                "    check = f'error: {type(e).__name__}: {e}'\n"),
    10: _snippet("try:\n"
                 "    import roboticstoolbox as rtb\n"
                 "except ImportError as e:\n"
                 "    print(json.dumps({'missing': str(e)}))\n"
                 "    raise SystemExit(0)\n"
                 "_t1 = time.perf_counter()\n",
                 "robot = rtb.models.Panda()\nT = robot.fkine(robot.qr)\n"
                 "sol = robot.ik_LM(T)\n"
                 "ok = bool(sol[1]) if isinstance(sol, tuple) else bool(sol.success)\n"
                 "check = 'success' if ok else 'no success'\n"),
}


def pinocchio_snippet(path: Path) -> str:
    """Row 9: Pinocchio's first FK + frame Jacobian of the UR5 URDF at ``path``."""
    return _snippet("try:\n"
                    "    import numpy as np\n"
                    "    import pinocchio as pin\n"
                    "except ImportError as e:\n"
                    "    print(json.dumps({'missing': str(e)}))\n"
                    "    raise SystemExit(0)\n"
                    "_t1 = time.perf_counter()\n",
                    f"model = pin.buildModelFromUrdf({str(path)!r})\n"
                    "data = model.createData()\nq = pin.neutral(model)\n"
                    "pin.forwardKinematics(model, data, q)\n"
                    "pin.updateFramePlacements(model, data)\n"
                    "fid = model.getFrameId('tool0') if model.existFrame('tool0') "
                    "else model.nframes - 1\n"
                    "J = pin.computeFrameJacobian(model, data, q, fid)\n"
                    "ok = J.shape == (6, model.nv)\ncheck = 'J ' + str(J.shape)\n")


def cli_command() -> list[str]:
    """The installed ``serialkin`` console script, or the module that it runs."""
    script = Path(sys.executable).parent / "serialkin"
    base = [str(script)] if script.is_file() else [sys.executable, "-m", "serialkin.cli.main"]
    return [*base, "fk", "ur5", "--q", "0,0,0,0,0,0"]


# ---------------------------------------------------------------------------- rows
@dataclass
class Row:
    num: int
    label: str
    cmd: list[str] | None  # None: not runnable (reason in ``missing``)
    peer: bool = False
    goal: tuple[str, float] | None = None  # (condition, seconds)
    cli: bool = False
    missing: str = ""
    runs: dict[str, list[dict]] = field(default_factory=lambda: {"cold": [], "warm": []})
    warm_dir: str | None = None


def make_rows() -> list[Row]:
    py = [sys.executable, "-c"]
    ur5_urdf = urdf("ur_description/urdf/ur5_robot.urdf")
    return [
        Row(1, "import serialkin", py + [SNIPPETS[1]], goal=("cold", 1.0)),
        Row(2, "models.get('ur5').fk(q)", py + [SNIPPETS[2]], goal=("cold", 2.0)),
        Row(3, ".jacobian(q)", py + [SNIPPETS[3]], goal=("cold", 2.0)),
        Row(4, "Panda robot.ik(T)", py + [SNIPPETS[4]], goal=("cold", 4.0)),
        Row(5, "Panda robot.ik of 300 targets", py + [SNIPPETS[5]], goal=("cold", 6.0)),
        Row(6, "UR5 robot.ik_all(T)", py + [SNIPPETS[6]], goal=("cold", 6.0)),
        Row(7, "Panda robot.ik(T, self_collision=True)", py + [SNIPPETS[7]],
            goal=("cold", 8.0)),
        Row(8, "CLI serialkin fk ur5 --q 0,0,0,0,0,0", cli_command(), goal=("warm", 0.7),
            cli=True),
        Row(9, "Pinocchio UR5 URDF: FK + frame Jacobian",
            py + [pinocchio_snippet(ur5_urdf)] if ur5_urdf else None, peer=True,
            missing="" if ur5_urdf else "not installed (example-robot-data)"),
        Row(10, "Robotics Toolbox Panda().ik_LM(T)", py + [SNIPPETS[10]], peer=True),
    ]


def child_env(cache_dir: str | None, mode: str = "") -> dict[str, str]:
    """The parent's environment, one BLAS thread, NUMBA_CACHE_DIR only when given.

    ``SERIALKIN_COMPILE`` is never inherited: ``mode`` when given, else unset (the
    default, a user's first call: kernels compile in the background).
    """
    env = {k: v for k, v in os.environ.items()
           if k not in ("NUMBA_CACHE_DIR", "SERIALKIN_COMPILE", "PYTHONDONTWRITEBYTECODE")}
    if mode:
        env["SERIALKIN_COMPILE"] = mode
    env["OPENBLAS_NUM_THREADS"] = "1"
    env["MKL_NUM_THREADS"] = "1"
    if cache_dir is not None:
        env["NUMBA_CACHE_DIR"] = cache_dir
    return env


def run_once(row: Row, cache_dir: str | None, timeout: float, mode: str = "") -> dict:
    """One fresh process: {'wall', 'answer', 'call_s', 'ok', 'check'} or {'error'|...}.

    ``answer``: from process start to the snippet's answer (the CLI row: to exit), which
    is earlier than ``wall`` when the process then finishes compiling in the background.
    """
    t0 = time.perf_counter()
    start = time.time()
    try:
        p = subprocess.run(row.cmd, cwd=ROOT, env=child_env(cache_dir, mode),
                           capture_output=True, text=True, timeout=timeout, check=False)
    except subprocess.TimeoutExpired:
        return {"error": "timeout", "wall": time.perf_counter() - t0}
    wall = time.perf_counter() - t0
    if p.returncode != 0:
        last = (p.stderr.strip().splitlines() or [f"exit status {p.returncode}"])[-1]
        return {"error": f"error: {last[:120]}", "wall": wall}
    if row.cli:
        ok = "T (world from tool)" in p.stdout
        return {"wall": wall, "answer": wall, "call_s": None, "ok": ok,
                "check": "printed T" if ok else "unexpected output"}
    lines = p.stdout.strip().splitlines()
    try:
        out = json.loads(lines[-1])
    except (IndexError, json.JSONDecodeError):
        return {"error": "error: no JSON on stdout", "wall": wall}
    if "missing" in out:
        return {"missing": f"not installed ({out['missing'][:80]})"}
    answer = min(wall, out["answer_at"] - start) if "answer_at" in out else wall
    return {"wall": wall, "answer": answer, "call_s": out["call_s"], "ok": out["ok"],
            "check": out["check"]}


def progress(text: str) -> None:
    print(text, file=sys.stderr, flush=True)


def measure(rows: list[Row], repeats: int, cold_repeats: int, timeout: float,
            root: str, wait_cold: bool = False) -> None:
    """All the runs, rows interleaved within each round; cold rounds first.

    Cold runs use the default compile mode (a first call runs uncompiled kernels as
    Python while they compile in the background; the process finishes compiling before
    it exits, filling the cache the warm runs use); with ``wait_cold``, each row also
    gets cold runs with ``SERIALKIN_COMPILE=wait`` (numba compiling before answering).
    """
    ours = [r for r in rows if not r.peer and r.cmd is not None]
    peers = [r for r in rows if r.peer and r.cmd is not None]
    modes = [("cold", "")] + ([("cold-wait", "wait")] if wait_cold else [])
    for cond, mode in modes:
        # round 0 of "cold": every serialkin row fills its own cache dir
        for c in range(max(cold_repeats, 1)):
            for row in ours:
                d = tempfile.mkdtemp(prefix=f"row{row.num}-", dir=root)
                res = run_once(row, d, timeout, mode)
                if c == 0 and cond == "cold":
                    row.warm_dir = d
                else:
                    shutil.rmtree(d, ignore_errors=True)
                kind = cond if cold_repeats > 0 else "fill (untimed)"
                progress(f"  {kind} {c + 1}/{max(cold_repeats, 1)}  row {row.num:2d}  "
                         f"answer {res.get('answer', 0.0):7.2f} s  exit "
                         f"{res.get('wall', 0.0):7.2f} s  {res.get('error', '')}")
                if cold_repeats > 0:
                    row.runs.setdefault(cond, []).append(res)
    for row in peers:  # untimed first run: the files it reads into the OS cache
        res = run_once(row, None, timeout)
        if "missing" in res:
            row.missing = res["missing"]
    peers = [r for r in peers if not r.missing]
    for w in range(repeats):
        for row in ours + peers:
            res = run_once(row, None if row.peer else row.warm_dir, timeout)
            row.runs["warm"].append(res)
            kind = "first" if row.peer else "warm"
            progress(f"  {kind} {w + 1}/{repeats}  row {row.num:2d}  "
                     f"{res.get('wall', 0.0):7.2f} s  {res.get('error', '')}")


# ---------------------------------------------------------------------------- report
def stats(runs: list[dict]) -> tuple[Stat | None, Stat | None, Stat | None, str]:
    """(answer Stat, exit Stat, in-process Stat, check text) of the runs that answered."""
    good = [r for r in runs if "error" not in r and "missing" not in r]
    errors = sorted({r["error"] for r in runs if "error" in r})
    checks = sorted({str(r["check"]) for r in good})
    note = "; ".join(errors + checks)
    if not good:
        return None, None, None, note or "-"
    calls = [r["call_s"] for r in good if r["call_s"] is not None]
    return (Stat([r.get("answer", r["wall"]) for r in good]), Stat([r["wall"] for r in good]),
            Stat(calls) if calls else None, note)


def cell(s: Stat | None) -> str:
    return "-" if s is None else s.fmt(2 if s.median >= 0.1 else 3)


def ratio(a: Stat | None, b: Stat | None) -> str:
    return "-" if a is None or b is None or b.median == 0 else f"{a / b:.2f}"


def report(rows: list[Row], no_cold: bool) -> None:
    pin_row = next((r for r in rows if r.num == 9), None)
    pin = stats(pin_row.runs["warm"])[0] if pin_row is not None else None
    head = (f"{'#':>2s} {'row':40s} {'cond':9s} {'answer [s]':>20s} {'exit [s]':>20s} "
            f"{'after imports [s]':>20s} {'goal':>7s} {'met':>4s} {'/pin':>5s}  check")
    print(head)
    print("-" * (len(head) + 12))
    for row in rows:
        if row.cmd is None or row.missing:
            print(f"{row.num:2d} {row.label:40s} {'':9s} {row.missing or 'not installed'}")
            continue
        conds = ["warm"] if row.peer or no_cold else \
            [c for c in ("cold", "cold-wait", "warm") if row.runs.get(c)]
        for i, name in enumerate(conds):
            answer, wall, call, note = stats(row.runs[name])
            goal = met = ""
            shown = "first" if row.peer else name
            if row.goal is not None and row.goal[0] == name:
                goal = f"<={row.goal[1]:.1f} s"
                if answer is not None:
                    ok = all(r.get("ok") for r in row.runs[name] if "error" not in r)
                    m = answer.median <= row.goal[1] and ok
                    met = "yes" if m else "NO"
                    record(GOAL_ID, f"{row.label} ({name}, fresh process, to the answer)",
                           answer.median, "s", f"<= {row.goal[1]:.1f} s", m)
            rat = ratio(answer, pin) if 2 <= row.num <= 7 else "-"
            label = row.label if i == 0 else ""
            num = f"{row.num:2d}" if i == 0 else "  "
            print(f"{num} {label:40s} {shown:9s} {cell(answer):>20s} {cell(wall):>20s} "
                  f"{cell(call):>20s} {goal:>7s} {met:>4s} {rat:>5s}  {note}", flush=True)


def parse_rows(text: str) -> set[int]:
    """'1,2,9' or '2-7,9' -> row numbers."""
    out: set[int] = set()
    for part in text.split(","):
        part = part.strip()
        if not part:
            continue
        lo, _, hi = part.partition("-")
        out.update(range(int(lo), int(hi or lo) + 1))
    return out


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeats", type=int, default=3,
                    help="timed runs of each warm row and of each peer (default 3)")
    ap.add_argument("--cold-repeats", type=int, default=1,
                    help="timed cold runs of each serialkin row, each with a new empty "
                         "cache (default 1: a cold row costs up to minutes)")
    ap.add_argument("--rows", default="", help="row numbers, e.g. 1,2,9 or 2-7 (default all)")
    ap.add_argument("--no-cold", action="store_true", help="skip the cold condition")
    ap.add_argument("--wait-cold", action="store_true",
                    help="also cold runs with SERIALKIN_COMPILE=wait (compile, then answer)")
    ap.add_argument("--timeout", type=float, default=900.0,
                    help="seconds before a subprocess is killed and reported 'timeout' "
                         "(default 900)")
    args = ap.parse_args(argv)
    rows = make_rows()
    if args.rows:
        wanted = parse_rows(args.rows)
        unknown = wanted - {r.num for r in rows}
        if unknown:
            ap.error(f"unknown rows {sorted(unknown)}; rows are 1-{len(rows)}")
        rows = [r for r in rows if r.num in wanted]
    cold_repeats = 0 if args.no_cold else args.cold_repeats
    print(header())
    print("Fresh process per run (answer: process start to the answer; exit: to the process's "
          "end, after it finished compiling in the background; after imports: in the "
          "snippet, end of its imports to the answer). cold: empty NUMBA_CACHE_DIR, default "
          "mode (kernels compile in the background, run as Python meanwhile); cold-wait: "
          "the same with SERIALKIN_COMPILE=wait; warm: the cache a previous run of the same "
          "snippet filled; first: peers (no numba cache).")
    print(f"median [min–max] of {cold_repeats} cold / {args.repeats} warm and peer runs; "
          "/pin: answer median / Pinocchio's first call (row 9) in this run; goals on the "
          "answer median.\n", flush=True)
    with tempfile.TemporaryDirectory(prefix="serialkin-cold-") as root:
        measure(rows, args.repeats, cold_repeats, args.timeout, root, args.wait_cold)
    report(rows, args.no_cold)
    return 0


if __name__ == "__main__":
    sys.exit(main())
