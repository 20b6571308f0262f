"""URDF import time, and FK/Jacobian latency of an imported robot vs its DH twin.

Run by hand: ``.venv/bin/python benchmarks/bench_urdf.py``. Needs the bench extra
(example-robot-data) for the Panda URDF. Both robots run the same kernels, so the
latencies should be equal. Figures are the median [10-90 %] of 15 runs, the two models'
runs interleaved.
"""

from __future__ import annotations

import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from _common import interleaved_us, latency_us  # noqa: E402
from tests.erd import urdf  # noqa: E402

import serialkin as sk  # noqa: E402
from serialkin.model.dh_extract import to_dh_robot  # noqa: E402


def main() -> None:
    path = urdf("panda_description/urdf/panda.urdf")
    if path is None:
        sys.exit("example-robot-data is not installed: pip install -e '.[bench]'")
    text = path.read_text()
    t_import = latency_us(lambda: sk.Robot.from_urdf(text, tip_link="panda_hand"), 5)
    r_urdf = sk.Robot.from_urdf(text, tip_link="panda_hand")
    r_dh = to_dh_robot(r_urdf, "modified")
    q = r_urdf.random_q(seed=0)
    for r in (r_urdf, r_dh):  # compile / warm up
        r.fk(q), r.jacobian(q)
    rows = [("import Panda URDF (parse + chain)", t_import, None)]
    for label in ("fk", "jacobian"):
        f_urdf, f_dh = getattr(r_urdf, label), getattr(r_dh, label)
        t = interleaved_us({"urdf": lambda f=f_urdf: f(q), "dh": lambda f=f_dh: f(q)}, 10000)
        rows.append((f"{label} (URDF model | DH model)", t["urdf"], t["dh"]))
    print(f"{'measure':36s} {'URDF [us]':>22s} {'DH [us]':>22s} {'ratio':>7s}")
    for name, a, b in rows:
        ratio = f"{a / b:7.2f}" if b is not None else f"{'-':>7s}"
        print(f"{name:36s} {a.fmt(2):>22s} {b.fmt(2) if b else '-':>22s} {ratio}")


if __name__ == "__main__":
    main()
