"""URDF import time, and FK/Jacobian latency of an imported robot vs its DH twin.

Run by hand: ``.venv/bin/python benchmarks/bench_urdf.py``. Needs the bench extra
(example-robot-data) for the Panda URDF. Both robots run the same kernels, so the
latencies should be equal.
"""

from __future__ import annotations

import sys
import timeit
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from tests.erd import urdf  # noqa: E402

import serialkin as sk  # noqa: E402
from serialkin.model.dh_extract import to_dh_robot  # noqa: E402


def best_us(fn, number: int) -> float:
    return min(timeit.repeat(fn, number=number, repeat=5)) / number * 1e6


def main() -> None:
    path = urdf("panda_description/urdf/panda.urdf")
    if path is None:
        sys.exit("example-robot-data is not installed: pip install -e '.[bench]'")
    text = path.read_text()
    t_import = best_us(lambda: sk.Robot.from_urdf(text, tip_link="panda_hand"), 20)
    r_urdf = sk.Robot.from_urdf(text, tip_link="panda_hand")
    r_dh = to_dh_robot(r_urdf, "modified")
    q = r_urdf.random_q(seed=0)
    for r in (r_urdf, r_dh):  # compile / warm up
        r.fk(q), r.jacobian(q)
    rows = [("import Panda URDF (parse + chain)", t_import, float("nan"))]
    for label in ("fk", "jacobian"):
        f_urdf, f_dh = getattr(r_urdf, label), getattr(r_dh, label)
        a = best_us(lambda f=f_urdf: f(q), 20000)
        b = best_us(lambda f=f_dh: f(q), 20000)
        rows.append((f"{label} (URDF model | DH model)", a, b))
    print(f"{'measure':40s} {'URDF [us]':>10s} {'DH [us]':>10s} {'ratio':>7s}")
    for name, a, b in rows:
        ratio = a / b if np.isfinite(b) else float("nan")
        print(f"{name:40s} {a:10.2f} {b:10.2f} {ratio:7.2f}")


if __name__ == "__main__":
    main()
