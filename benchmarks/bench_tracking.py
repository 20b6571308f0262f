"""Path-tracking benchmark: the chapter's 6-link and 20-link examples.

For each shipped scenario — (a) ``six_link_circle`` (DLS, eq 46), (b) ``twenty_link_free``
and (c) ``twenty_link_obstacles`` (multi-task eq 48) — prints the total time, the time per
path point and the iterations, median of several runs after a warm-up (numba compile).
For (a) it also times the bare compiled DLS loop (without recording the trajectory) and
the same DLS loop written with Pinocchio (frame Jacobian, same λ, tolerance, iteration
budget, start and singularity kick) and with Robotics Toolbox for Python, when installed,
and reports the ratios.

Run: ``.venv/bin/python benchmarks/bench_tracking.py``.
"""

from __future__ import annotations

import statistics
import time

import numpy as np

from serialkin.tracking import load_scenario
from serialkin.tracking.tracker import dls_track

REPEATS = 7


def median_time(fn, repeats: int = REPEATS) -> float:
    """Median wall time [s] of ``repeats`` runs after a warm-up; the spread is kept in SPREAD."""
    fn()
    ts = []
    for _ in range(repeats):
        t0 = time.perf_counter()
        fn()
        ts.append(time.perf_counter() - t0)
    SPREAD[fn] = (min(ts), max(ts))
    return statistics.median(ts)


#: (min, max) run time [s] of the last median_time() of each function.
SPREAD: dict = {}


def spread_us(fn, per: int = 1) -> str:
    """'[min-max] µs' of fn's runs (divided by ``per``)."""
    lo, hi = SPREAD[fn]
    return f"[{lo / per * 1e6:.1f}-{hi / per * 1e6:.1f}]"


def dls_loop_python(jac_pos, targets, q0, lam, tol, max_iter, max_step, kick=1e-3):
    """The chapter's DLS loop (eq 46 corrected) around a peer's Jacobian/position function."""
    q = q0.copy()
    out = np.empty((len(targets), q.size))
    iters = 0
    for k, x_d in enumerate(targets):
        it = 0
        while True:
            J, x = jac_pos(q)
            e = x_d - x
            err = np.linalg.norm(e)
            if err < tol or it >= max_iter:
                break
            dq = J.T @ np.linalg.solve(J @ J.T + lam * lam * np.eye(2), e)
            nrm = np.linalg.norm(dq)
            if nrm > max_step:
                dq *= max_step / nrm
            q = q + dq
            it += 1
            if nrm < 1e-12 * (1.0 + err):
                q = q + kick
        out[k] = q
        iters += it
    return out, iters


def pinocchio_jac_pos(L: float, n: int):
    import pinocchio as pin

    model = pin.Model()
    parent = 0
    placement = pin.SE3.Identity()
    for i in range(n):
        parent = model.addJoint(parent, pin.JointModelRZ(), placement, f"j{i + 1}")
        placement = pin.SE3(np.eye(3), np.array([L, 0.0, 0.0]))
    fid = model.addFrame(pin.Frame("ee", parent, placement, pin.FrameType.OP_FRAME))
    data = model.createData()

    def jac_pos(q):
        J = pin.computeFrameJacobian(model, data, q, fid, pin.LOCAL_WORLD_ALIGNED)
        pin.updateFramePlacement(model, data, fid)
        return J[:2], data.oMf[fid].translation[:2].copy()

    return jac_pos


def rtb_jac_pos(L: float, n: int):
    import roboticstoolbox as rtb

    robot = rtb.DHRobot([rtb.RevoluteDH(a=L) for _ in range(n)])

    def jac_pos(q):
        return robot.jacob0(q)[:2], robot.fkine(q).A[:2, 3]

    return jac_pos


def main() -> None:
    rows = []
    for key, name in (("a", "six_link_circle"), ("b", "twenty_link_free"),
                      ("c", "twenty_link_obstacles")):
        s = load_scenario(name)
        tr = s.run()
        run = s.run
        t = median_time(run)
        rows.append((f"({key}) {name}", len(tr), int(tr.iterations.sum()), t * 1e3,
                     t / len(tr) * 1e6, spread_us(run, len(tr)), tr.max_error * 1e3))
    print(f"median of {REPEATS} runs [min-max]")
    print(f"{'scenario':<28}{'points':>7}{'iters':>7}{'total [ms]':>12}{'per point [µs]':>16}"
          f"{'spread [µs]':>16}{'max err [mm]':>14}")
    for r in rows:
        print(f"{r[0]:<28}{r[1]:>7}{r[2]:>7}{r[3]:>12.3f}{r[4]:>16.1f}{r[5]:>16}{r[6]:>14.3g}")

    # ---------------------------------------------------------------- (a) vs peers
    s = load_scenario("six_link_circle")
    o = s.options
    lam, tol, max_iter, max_step = o["damping"], o["tol"], o["max_iter"], 0.5
    targets = np.ascontiguousarray(s.path.targets)
    rows_ = np.array([0, 1])
    p = len(targets)
    Q = np.zeros((p, 6))
    IT = np.zeros(p, dtype=np.int64)
    ER = np.zeros(p)

    lo = np.ascontiguousarray(s.robot.qlim[:, 0])
    hi = np.ascontiguousarray(s.robot.qlim[:, 1])
    revolute = s.robot.revolute.astype(float)

    def kernel():
        dls_track(s.q0, targets, rows_, s.robot.chain.F, s.robot.chain.meta, lam, tol, max_iter,
                  max_step, s.tolerance, False, 1e-3, lo, hi, revolute, Q, IT, ER)

    t_kernel = median_time(kernel, 21)
    t_track = median_time(s.run)
    print(f"\n(a) serialkin compiled DLS loop only: {t_kernel * 1e6:.1f} µs total "
          f"{spread_us(kernel)} (median of 21 [min-max]), "
          f"{t_kernel / p * 1e6:.2f} µs per point ({int(IT.sum())} iterations); "
          f"track() with recording: {t_track * 1e6:.0f} µs")
    xy = s.path.points
    L = 0.1
    for label, factory in (("Pinocchio", pinocchio_jac_pos), ("Robotics Toolbox", rtb_jac_pos)):
        try:
            jp = factory(L, 6)
        except ImportError:
            print(f"(a) {label}: not installed (pip install -e .[bench])")
            continue
        qs, iters = dls_loop_python(jp, xy, np.zeros(6), lam, tol, max_iter, max_step)
        err = np.max(np.linalg.norm(s.robot.fk(qs)[:, :2, 3] - xy, axis=1))
        t_peer = median_time(lambda jp=jp: dls_loop_python(jp, xy, np.zeros(6), lam, tol,
                                                           max_iter, max_step), 5)
        print(f"(a) {label} DLS loop (Python around the peer's Jacobian): {t_peer * 1e3:.2f} ms "
              f"total, {t_peer / p * 1e6:.1f} µs per point, {iters} iterations, max error "
              f"{err * 1e3:.2g} mm -> serialkin kernel is {t_peer / t_kernel:.0f}x faster, "
              f"track() {t_peer / t_track:.1f}x faster")


if __name__ == "__main__":
    main()
