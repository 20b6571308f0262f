"""Run every benchmark script in this folder, then print one summary table (``make bench``).

Each script prints its own table (medians and spread of repeated runs, peers measured in
the same run when the ``bench`` extra is installed). The figures on which the issues' goals
are judged are collected from the scripts (``SERIALKIN_BENCH_RESULTS``, see
``_common.record``) into the closing table: goal, measured figure, target, met or not.
Benchmarks are run by hand, never as timed assertions in tests.

``--only fk,parallel`` runs a subset of the scripts (by name without ``bench_``).
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile
from pathlib import Path

HERE = Path(__file__).resolve().parent

#: Goal id -> what it asks. Ids are "<issue>.<item>"; a script records its rows under one.
GOALS = {
    "11.1": "single calls no slower than Pinocchio (UR5, Panda)",
    "11.2": "parallel batches never slower than serial; 6-DOF batch FK >= 40 M/s",
    "11.3": "IK lm single <= 8 us at 100 % success; batch <= 4 us per target",
    "12.1": "Panda self_clearance batched on one core <= 2 us per configuration",
    "12.2": "URDF with meshes (Panda, UR5): cold load and capsule fit <= 2 s each",
    "12.5": "viewer with meshes: Panda page <= 5 MB, opens in headless Chromium < 2 s",
    "13.1": "collision-aware IK Panda (table + 2 obstacles) batched <= 100 us at >= 95 %",
    "13.2": "differential-IK QP step <= half of pink's and mink's (Panda, same task set)",
    "13.3": "QP tracking of the 20-link scenario: time per path point (reported)",
    "14.1": "ik_all decomposable arms <= 10 us single, <= 3 us batched; general 6R <= 200 us",
    "15.1": "UR5 2.5 cm x 50-orientation reach map < 1 h on 2 cores; Dask 1->2 workers >= 0.85",
    "16.1": "calibration fit <= 1 s (UR5 60 positions; Panda 200 poses)",
    "27.1": "cold start in a fresh process: import <= 1 s, fk/jacobian <= 2 s, Panda ik "
            "<= 4 s (300 targets <= 6 s, self-collision <= 8 s), UR5 ik_all <= 6 s; CLI "
            "warm <= 0.7 s",
    "30.6": "7-DOF: S-R-S solutions at one arm angle <= 10 us, feasible intervals <= 50 us, "
            "Panda sweep of joint 7 at 1 degree <= 1 ms",
    "31.b": "joint path of 1,000 samples: UR5 <= 20 ms, Panda <= 50 ms; timing <= 50 ms",
    "33.b": "calibration to the noise floor (UR5, joint errors + 8 cm marker, 50 um noise): "
            "80 positions <= 1 s, 1,000 positions <= 5 s",
    "35.1": "serialkin.torch FK + backward, 4,096 Panda: >= 5x faster than pytorch_kinematics",
    "35.2": "serialkin.torch Jacobian + backward, 4,096 Panda: >= 5x pytorch_kinematics",
    "35.3": "serialkin.jax jit FK + grad, 4,096 Panda: at least as fast as a pure-JAX chain",
}


def summary(path: Path) -> str:
    """The closing table from the recorded JSON lines."""
    rows = [json.loads(line) for line in path.read_text(encoding="utf-8").splitlines()
            if line.strip()] if path.exists() else []
    out = ["", "=== summary: goals of the issues ===", ""]
    head = f"{'goal':5s} {'measure':72s} {'measured':>12s} {'target':>14s} {'met':>4s}"
    out += [head, "-" * len(head)]
    for r in rows:
        out.append(f"{r['goal']:5s} {r['measure'][:72]:72s} {r['value']:12.3f} "
                   f"{r['target']:>14s} {'yes' if r['met'] else 'NO':>4s}")
    for goal, text in GOALS.items():
        mine = [r for r in rows if r["goal"] == goal]
        state = ("not measured" if not mine else
                 "met" if all(r["met"] for r in mine) else
                 f"NOT met ({sum(not r['met'] for r in mine)} of {len(mine)} rows)")
        out.append(f"goal {goal} ({text}): {state}")
    if hasattr(os, "getloadavg"):
        load = ", ".join(f"{x:.2f}" for x in os.getloadavg())
        out.append(f"load average at the end (1, 5, 15 min): {load} on {os.cpu_count()} CPUs "
                   "(other processes' load makes the parallel rows meaningless)")
    return "\n".join(out)


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--only", default="", help="comma-separated script names (fk, parallel...)")
    args = ap.parse_args(argv)
    wanted = {w.strip() for w in args.only.split(",") if w.strip()}
    status = 0
    with tempfile.TemporaryDirectory() as tmp:
        results = Path(tmp) / "results.jsonl"
        # one BLAS thread from the start of every script (see _common.py)
        env = dict(os.environ, SERIALKIN_BENCH_RESULTS=str(results), OPENBLAS_NUM_THREADS="1",
                   MKL_NUM_THREADS="1")
        for script in sorted(HERE.glob("bench_*.py")):
            if wanted and script.stem.removeprefix("bench_") not in wanted:
                continue
            print(f"\n=== {script.name} ===", flush=True)
            rc = subprocess.call([sys.executable, str(script)], cwd=HERE.parent, env=env)
            status = status or rc
        print(summary(results), flush=True)
    return status


if __name__ == "__main__":
    sys.exit(main())
