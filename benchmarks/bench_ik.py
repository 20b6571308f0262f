"""Numerical IK: success rate, time per solve and iterations per method, beside the peers.

Run by hand: ``.venv/bin/python benchmarks/bench_ik.py [--targets N] [--ikpy-targets M]
[--methods lm,dls,...] [--peers rtb,pinocchio,ikpy] [--no-peers]``.

For Panda, UR5 and Puma 560 (each built from Robotics Toolbox for Python's DH table, tool
and limits, so that every solver works on the same kinematics), N reachable full-pose
targets (FK of seeded random q inside the limits) and N seeded random initial guesses
inside the limits. Every solver gets the same targets and initial guesses, and a solve
counts as a **success only when FK of the returned q is within 1e-6 m and 1e-6 rad of the
target and q is inside the joint limits** (checked here with serialkin's FK, not by the
solver's own flag). Times are wall-clock per call of the public API: median, 10-90 %
spread over the targets, and mean; the goal's rows (serialkin ``lm`` and the toolbox's
``ik_LM``) time every target ``--passes`` times (default 3) and report the median of the
passes' medians and their range ("runs", the run-to-run spread).

Peers, in the same run when the ``bench`` extra is installed:

* Robotics Toolbox's C++ ``ETS.ik_LM`` / ``ik_NR`` / ``ik_GN`` with ``tol=1e-12`` (its
  tolerance is on ½eᵀe; its default 1e-6 accepts millimetre errors), joint limits on,
  its default restarts (``slimit=100``);
* a Pinocchio CLIK loop as in Pinocchio's documentation (damped least squares on the
  frame's log6 error, ``DT=0.1``, ``damp=1e-12``, up to 1000 iterations), with the
  stopping threshold tightened to 1e-10 so that it can reach the accuracy criterion; no
  restarts and no joint-limit handling (as in the documentation);
* ikpy's ``Chain.inverse_kinematics`` with full orientation (``orientation_mode="all"``),
  from the same URDF, on the first M targets (it is slow).

serialkin rows use ``robot.ik(T, method=..., q0=q0, seed=k)`` with each method's default
tolerance (1e-9), iteration budget and restarts. The last column is the ratio of the
median time to Robotics Toolbox's ``ik_LM``. A final line times the batch kernel (all N
targets in one call across the cores): median and spread of 9 runs after one untimed run.

The robots' limits are those the toolbox's IK enforces (``robot.qlim``; for its UR5,
whose DH table has none, ±π).
"""

from __future__ import annotations

import argparse
import os
import sys
import tempfile
import time
import warnings
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "src"))

from _common import Stat, header, record, wall_s  # noqa: E402

from serialkin import Robot  # noqa: E402
from serialkin.model.dh import DHLink  # noqa: E402
from serialkin.spatial.pose import pose_error  # noqa: E402

ACCURACY = 1e-6
DEFAULT_METHODS = ("lm", "lm_chan", "lm_wampler", "lm_sugihara", "dls", "gauss_newton",
                   "newton", "pinv", "sdls", "transpose")


def numba_threads() -> int:
    """Threads the batch kernels use."""
    import numba

    return numba.get_num_threads()


def robot_from_rtb(rtb_robot, name: str) -> Robot:
    """A serialkin robot with the toolbox robot's DH table, limits, base and tool."""
    rows = []
    qlim = np.asarray(rtb_robot.qlim, dtype=float)  # the limits the toolbox's IK enforces
    for j, L in enumerate(rtb_robot.links):
        rows.append(DHLink(a=float(L.a), alpha=float(L.alpha), d=float(L.d),
                           theta=float(L.offset), type="P" if L.isprismatic else "R",
                           qlim=(qlim[0, j], qlim[1, j])))
    convention = "modified" if getattr(rtb_robot, "mdh", False) else "standard"
    return Robot.from_dh(rows, convention, base=np.asarray(rtb_robot.base.A),
                         tool=np.asarray(rtb_robot.tool.A), name=name)


def accurate(robot: Robot, q: np.ndarray, T: np.ndarray) -> bool:
    """FK(q) within 1e-6 m and 1e-6 rad of T, q finite and inside the limits."""
    q = np.asarray(q, dtype=float)
    if q.shape != (robot.n,) or not np.isfinite(q).all() or not robot.within_limits(q):
        return False
    e = pose_error(robot.fk(q), T)
    return bool(np.linalg.norm(e[:3]) <= ACCURACY and np.linalg.norm(e[3:]) <= ACCURACY)


def run(robot, name, solve, targets, q0s, passes=1):
    """Time ``solve(T, q0, k) -> (q, iterations)`` over the targets; return a row dict.

    With ``passes`` > 1 the targets are timed that many times: the median is the median
    of the passes' medians, ``runs`` their range (the run-to-run spread).
    """
    solve(targets[0], q0s[0], 0)  # warm up (compilation, caches)
    times = np.empty((passes, len(targets)))
    iters = np.empty(len(targets))
    ok = np.zeros(len(targets), dtype=bool)
    for p in range(passes):
        for k, (T, q0) in enumerate(zip(targets, q0s)):
            t0 = time.perf_counter()
            q, its = solve(T, q0, k)
            times[p, k] = time.perf_counter() - t0
            if p == 0:
                iters[k] = its
                ok[k] = accurate(robot, q, T)
    p10, p90 = np.percentile(times, [10, 90]) * 1e6
    runs = np.median(times, axis=1) * 1e6
    return {"solver": name, "n": len(targets), "success": ok.mean(),
            "median_us": float(np.median(runs)), "mean_us": times.mean() * 1e6,
            "p10_us": p10, "p90_us": p90, "median_it": np.median(iters),
            "runs": f"{runs.min():.1f}-{runs.max():.1f}"}


def serialkin_solver(robot, method):
    def solve(T, q0, k):
        r = robot.ik(T, method=method, q0=q0, seed=k)
        return r.q, r.iterations
    return solve


def rtb_solver(ets, fn_name):
    fn = getattr(ets, fn_name)

    def solve(T, q0, k):
        sol = fn(T, q0=q0, tol=1e-12, joint_limits=True)
        if isinstance(sol, tuple):  # older toolbox versions return a tuple
            return sol[0], sol[2]
        return sol.q, sol.iterations
    return solve


def pinocchio_solver(robot, urdf_path):
    import pinocchio as pin

    model = pin.buildModelFromUrdf(urdf_path)
    data = model.createData()
    fid = model.getFrameId("tool")
    q_test = robot.random_q(seed=5)
    pin.framesForwardKinematics(model, data, q_test)
    if np.abs(data.oMf[fid].homogeneous - robot.fk(q_test)).max() > 1e-9:
        raise RuntimeError("Pinocchio model from the URDF disagrees with serialkin's FK")
    eye = np.eye(6)

    def solve(T, q0, k, eps=1e-10, it_max=1000, dt=1e-1, damp=1e-12):
        oMdes = pin.SE3(T[:3, :3].copy(), T[:3, 3].copy())
        q = np.array(q0, dtype=float)
        for i in range(it_max):
            pin.framesForwardKinematics(model, data, q)
            iMd = data.oMf[fid].actInv(oMdes)
            err = pin.log(iMd).vector
            if np.linalg.norm(err) < eps:
                return q, i
            J = pin.computeFrameJacobian(model, data, q, fid)
            J = -np.dot(pin.Jlog6(iMd.inverse()), J)
            v = -J.T.dot(np.linalg.solve(J.dot(J.T) + damp * eye, err))
            q = pin.integrate(model, q, v * dt)
        return q, it_max
    return solve


def ikpy_solver(robot, urdf_path):
    from ikpy.chain import Chain

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        chain = Chain.from_urdf_file(urdf_path, base_elements=["base_link"])
        mask = [link.joint_type != "fixed" for link in chain.links]
        chain = Chain.from_urdf_file(urdf_path, base_elements=["base_link"],
                                     active_links_mask=mask)
    idx = np.flatnonzero(mask)
    q_test = robot.random_q(seed=5)
    full = np.zeros(len(chain.links))
    full[idx] = q_test
    if np.abs(chain.forward_kinematics(full) - robot.fk(q_test)).max() > 1e-9:
        raise RuntimeError("ikpy chain from the URDF disagrees with serialkin's FK")

    def solve(T, q0, k):
        start = np.zeros(len(chain.links))
        start[idx] = q0
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            out = chain.inverse_kinematics(target_position=T[:3, 3], target_orientation=T[:3, :3],
                                           orientation_mode="all", initial_position=start)
        return np.asarray(out)[idx], 0
    return solve


def print_rows(rows, ref_median):
    print(f"  {'solver':24s} {'targets':>7s} {'success':>8s} {'median us':>10s} "
          f"{'runs us':>11s} {'p10-p90 us':>14s} {'mean us':>10s} {'median it':>9s} "
          f"{'median / ik_LM':>14s}")
    for r in rows:
        ratio = f"{r['median_us'] / ref_median:14.2f}" if ref_median else f"{'':>14s}"
        spread = f"{r['p10_us']:.1f}-{r['p90_us']:.1f}"
        print(f"  {r['solver']:24s} {r['n']:7d} {r['success']:8.1%} {r['median_us']:10.1f} "
              f"{r['runs']:>11s} {spread:>14s} {r['mean_us']:10.1f} {r['median_it']:9.0f} "
              f"{ratio}", flush=True)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--targets", type=int, default=1000)
    parser.add_argument("--ikpy-targets", type=int, default=100)
    parser.add_argument("--passes", type=int, default=3,
                        help="timed passes over the targets for rtb ik_LM and serialkin lm "
                             "(median of the pass medians; the others get one pass)")
    parser.add_argument("--methods", default=",".join(DEFAULT_METHODS),
                        help="comma-separated serialkin methods")
    parser.add_argument("--robots", default="Panda,UR5,Puma560")
    parser.add_argument("--no-peers", action="store_true")
    parser.add_argument("--peers", default="rtb,pinocchio,ikpy",
                        help="comma-separated peers to run: rtb, pinocchio, ikpy")
    args = parser.parse_args()
    import roboticstoolbox as rtb  # the robots are defined by the toolbox's DH tables

    methods = [m for m in args.methods.split(",") if m]
    peers = set() if args.no_peers else {p for p in args.peers.split(",") if p}
    print(f"IK benchmark: {args.targets} reachable full-pose targets per robot, success = FK "
          f"within {ACCURACY:g} m and {ACCURACY:g} rad and q inside the limits")
    print(header())
    for rname in args.robots.split(","):
        rtb_robot = getattr(rtb.models.DH, rname)()
        robot = robot_from_rtb(rtb_robot, rname)
        Q = robot.random_q(args.targets, seed=1)
        targets = np.ascontiguousarray(robot.fk(Q))
        q0s = robot.random_q(args.targets, seed=2)
        print(f"\n{rname} ({robot.n} joints, {robot.convention} DH; load average "
              f"{os.getloadavg()[0]:.2f} on {os.cpu_count()} CPUs)")
        rows = []
        ref = None
        if "rtb" in peers:
            ets = rtb_robot.ets()
            for fn in ("ik_LM", "ik_NR", "ik_GN"):
                row = run(robot, f"rtb {fn} (C++)", rtb_solver(ets, fn), targets, q0s,
                          args.passes if fn == "ik_LM" else 1)
                rows.append(row)
                if fn == "ik_LM":
                    ref = row["median_us"]
        for m in methods:
            rows.append(run(robot, f"serialkin {m}", serialkin_solver(robot, m), targets, q0s,
                            args.passes if m == "lm" else 1))
        if peers & {"pinocchio", "ikpy"}:
            fd, path = tempfile.mkstemp(suffix=".urdf")
            with os.fdopen(fd, "w") as f:
                f.write(robot.to_urdf())
            try:
                for key, label, make, count in (
                    ("pinocchio", "pinocchio CLIK (python)", pinocchio_solver, args.targets),
                    ("ikpy", "ikpy", ikpy_solver, args.ikpy_targets),
                ):
                    if key not in peers:
                        continue
                    try:
                        solver = make(robot, path)
                    except Exception as exc:  # a peer that cannot load this robot
                        print(f"  {label}: skipped ({exc})")
                        continue
                    rows.append(run(robot, label, solver, targets[:count], q0s[:count]))
            finally:
                os.unlink(path)
        print_rows(rows, ref)
        for r in rows:
            if r["solver"] == "serialkin lm":
                met = r["median_us"] <= 8.0 and r["success"] == 1.0
                record("11.3", f"IK lm single, {rname}: median [us] at {r['success']:.1%} success",
                       r["median_us"], "us", "<= 8 at 100 %", met)
        res = robot.ik(targets, q0=q0s, seed=0)
        per = Stat(wall_s(lambda r=robot, t=targets, q=q0s: r.ik(t, q0=q, seed=0),
                          repeat=9).values / args.targets * 1e6)
        ok = np.mean([accurate(robot, q, T) for q, T in zip(res.q, targets)])
        print(f"  batch kernel (lm, {args.targets} targets in one call, {numba_threads()} "
              f"threads): {per.fmt(2)} us per target (median [spread] of 9 runs), "
              f"success {ok:.1%}")
        record("11.3", f"IK lm batch, {rname}, {numba_threads()} threads: us per target "
               f"at {ok:.1%} success", per.median, "us", "<= 4", per.median <= 4.0)


if __name__ == "__main__":
    main()
