"""Calibration fit time (issue 16): UR5 from 60 positions, Panda (7R) from 200 poses.

Run by hand: ``.venv/bin/python benchmarks/bench_calibration.py [--repeat N]``. No other
library identifies kinematic parameters (Robotics Toolbox, Pinocchio, ikpy, mink), so the
baseline in the same run is the same fit with scipy's finite-difference Jacobian
(``jac='2-point'``) instead of the kernels' identification Jacobian: the ratio is what the
analytic Jacobian buys. Figures are the median [10–90 %] wall time of repeated fits
(after one untimed run), the two variants' runs interleaved, both with single-threaded
BLAS (as ``calibrate`` runs it: next to numba's thread pool a multi-threaded BLAS made
the Panda fit's SVDs 10-40x slower); the calibrated model's validation error over 1,000
configurations is printed with them. The kernels' time includes the identifiability
analysis (two SVD-based passes); the 2-point variant is given the fitted set.

Issue 33: the staged fit on truth robots made without the error models (every joint origin
moved ≤ 1 mm and tilted ≤ 0.3°, an 8 cm marker; ``perturb_joints``), UR5 from 80 positions
with 50 µm noise and from 1,000: time (median [10–90 %] of the repeats) and validation RMS
(no baseline: one stage of the old kind does not reach the truth); goal 33.b in
``run_all.py``.
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from _common import Stat, header, record  # noqa: E402

import serialkin as sk  # noqa: E402
from serialkin.calibration import (  # noqa: E402
    calibrate,
    error_model,
    perturb,
    perturb_joints,
    simulate_measurements,
)
from serialkin.calibration.jacobian import whitened  # noqa: E402
from serialkin.kinematics.parallel import single_threaded_blas  # noqa: E402

TARGET_S = 1.0  # a fit should take at most a second
TARGET_LARGE_S = 5.0  # ... and 1,000 measurements at most five


def _fd_fit(model, meas, keep):
    """The same least-squares problem with scipy's finite-difference Jacobian."""
    from scipy.optimize import least_squares

    p0 = model.nominal
    fit = np.flatnonzero(keep)

    def fun(x):
        p = p0.copy()
        p[fit] = x
        return whitened(model, meas, p)[0]

    with single_threaded_blas():  # as calibrate() does
        sol = least_squares(fun, p0[fit], jac="2-point", method="trf", x_scale="jac",
                            ftol=1e-12, xtol=1e-12, gtol=1e-12, max_nfev=200 * len(fit))
    p = p0.copy()
    p[fit] = sol.x
    return p


def _case(label, robot, count, kind, noise_rotation, repeat):
    model = error_model(robot)
    real = model.calibrated_robot(perturb(model, seed=3))
    meas = simulate_measurements(real, count, kind=kind, noise_position=5e-5,
                                 noise_rotation=noise_rotation, seed=4)
    res = calibrate(model, meas)
    keep = res.identifiability.identifiable
    _fd_fit(model, meas, keep)  # warm up
    times: dict[str, list[float]] = {"kernels": [], "2-point": []}
    for _ in range(repeat):
        t0 = time.perf_counter()
        calibrate(model, meas)
        times["kernels"].append(time.perf_counter() - t0)
        t0 = time.perf_counter()
        p_fd = _fd_fit(model, meas, keep)
        times["2-point"].append(time.perf_counter() - t0)
    q = robot.random_q(1000, seed=9)
    err = np.linalg.norm(res.robot.fk(q)[:, :3, 3] - real.fk(q)[:, :3, 3], axis=1)
    same = float(np.abs(p_fd - res.params).max())
    a, b = Stat(times["kernels"]), Stat(times["2-point"])
    print(f"{label:44s} {a.fmt(4):>26s} {b.fmt(4):>26s} {b / a:7.1f}   "
          f"{np.sqrt(np.mean(err**2)) * 1e3:.4f} mm  ({res.identifiability.rank} params, "
          f"|Δp| FD vs kernels {same:.1e})")
    record("16.1", f"calibration fit {label} [s]", a.median, "s", f"<= {TARGET_S:g} s",
           a.median <= TARGET_S)


def _staged(label, robot, count, repeat):
    """Time of the staged fit (issue 33) on a joint-origin truth with an 8 cm marker."""
    truth = perturb_joints(robot, marker=0.08, seed=1)
    meas = simulate_measurements(truth, count, noise_position=5e-5, seed=2)
    res = calibrate(robot, meas)
    times = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        calibrate(robot, meas)
        times.append(time.perf_counter() - t0)
    q = robot.random_q(1000, seed=9)
    err = np.linalg.norm(res.robot.fk(q)[:, :3, 3] - truth.fk(q)[:, :3, 3], axis=1)
    a = Stat(times)
    print(f"{label:44s} {a.fmt(4):>26s} {'':>26s} {'':>7s}   "
          f"{np.sqrt(np.mean(err**2)) * 1e3:.4f} mm  ({res.identifiability.rank} params, "
          f"{res.iterations} evaluations, success {res.success})")
    target = TARGET_S if count <= 100 else TARGET_LARGE_S
    record("33.b", f"time to calibrate {label} [s]", a.median, "s", f"<= {target:g} s",
           a.median <= target)


def main(argv: list[str] | None = None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeat", type=int, default=10)
    args = ap.parse_args(argv)
    print(header())
    print("timings on a shared machine: other processes disturb them")
    print(f"{'case':44s} {'kernels Jacobian [s]':>26s} {'scipy 2-point [s]':>26s} "
          f"{'ratio':>7s}   validation RMS")
    marker = sk.spatial.make_transform(p=[0.05, 0.02, 0.06])
    _case("UR5, 60 positions (0.05 mm noise)", sk.models.ur5().with_tool(marker), 60,
          "position", 0.0, args.repeat)
    _case("Panda 7R, 200 poses (0.05 mm, 0.1 mrad)", sk.models.panda(), 200, "pose", 1e-4,
          args.repeat)
    for count in (80, 1000):
        _staged(f"UR5 joint errors + 8 cm marker, {count} positions", sk.models.ur5(), count,
                args.repeat)


if __name__ == "__main__":
    main()
