"""Timing of a joint path under velocity, acceleration (toppra) and jerk limits (ruckig).

A joint path q₀ … q_{m−1} is interpolated by a cubic spline q(s) in a path parameter s
(chord length in joint space), and the fastest ``s(t)`` that keeps every joint inside
``|q̇_j| ≤ v_j`` and ``|q̈_j| ≤ a_j`` is found by reachability analysis (TOPP-RA: Pham &
Pham, "A new approach to time-optimal path parameterization based on reachability
analysis", IEEE T-RO 2018), with the ``toppra`` library (the ``paths`` extra), not by
code of our own. An optional Cartesian speed limit v_c on the tool's position becomes
the velocity limits ``|q̇_j| ≤ |q_j'(s)|·v_c / |p'(s)|`` that vary along the path (so
that ṡ ≤ v_c / |p'(s)|).

Jerk limits (:func:`jerk_limited`, the ``ruckig`` library of the same extra): along the
same path ``q̇ = q′ṡ``, ``q̈ = q″ṡ² + q′s̈`` and ``q⃛ = q‴ṡ³ + 3q″ṡs̈ + q′s⃛``, so bounds
``ṡ ≤ V``, ``|s̈| ≤ A``, ``|s⃛| ≤ J`` chosen from the path's largest ``|q_j′|``,
``|q_j″|``, ``|q_j‴|`` keep every joint within its limits, and Ruckig (Berscheid &
Kröger, "Jerk-limited real-time trajectory generation with arbitrary target states", RSS
2021) gives the time-optimal jerk-limited s(t) from rest to rest under them. That is not
time-optimal for the joints: one set of bounds holds for the whole path, so its most
curved part sets the pace everywhere (Ruckig's own waypoint following, which would do
better, needs Ruckig Pro or its cloud service; Ruckig Community plans to one target
state).

When the caller gives no limits, the robot's own are used
(:attr:`~serialkin.model.robot.Robot.velocity_limits`, ``acceleration_limits``: read from
a URDF's ``<limit velocity>``, or the zoo's data sheets).

Units: seconds, radians (or metres for prismatic joints) and their rates.
"""

from __future__ import annotations

import json
import math
from dataclasses import dataclass
from pathlib import Path as FsPath
from typing import Any

import numpy as np

from serialkin._checks import as_float_array, require
from serialkin._io import write_text_atomic
from serialkin.errors import InputError, SerialkinError
from serialkin.model.robot import Robot

__all__ = ["TimedPath", "jerk_limited", "time_optimal"]


def _toppra():
    toppra = require("toppra", "paths", "time_optimal")
    for sub in ("toppra.algorithm", "toppra.constraint"):
        require(sub, "paths", "time_optimal")
    toppra.setup_logging("WARNING")
    return toppra


@dataclass(frozen=True, eq=False)
class TimedPath:
    """A timed joint trajectory (what :func:`time_optimal` and :func:`jerk_limited` return).

    Attributes:
        t: (k,) times [s], from 0 to ``duration``.
        q: (k, n) joint values [rad or m].
        qd: (k, n) joint velocities [rad/s or m/s].
        qdd: (k, n) joint accelerations [rad/s² or m/s²].
        duration: the trajectory's length in time [s].
        velocity: (n,) the velocity limits used; acceleration: (n,) the acceleration limits.
        joint_names: the joints' names (column labels of the CSV file).
        jerk: (n,) the jerk limits used [rad/s³ or m/s³] (:func:`jerk_limited`), else None.
        method: 'toppra' (time-optimal) or 'ruckig' (jerk-limited).
    """

    t: np.ndarray
    q: np.ndarray
    qd: np.ndarray
    qdd: np.ndarray
    duration: float
    velocity: np.ndarray
    acceleration: np.ndarray
    joint_names: tuple[str, ...] = ()
    jerk: np.ndarray | None = None
    method: str = "toppra"

    def names(self) -> list[str]:
        """The column labels: the joints' names, or q1 … qn."""
        n = self.q.shape[1]
        return list(self.joint_names) if len(self.joint_names) == n else [
            f"q{i + 1}" for i in range(n)]

    def to_csv(self, path: str | FsPath) -> FsPath:
        """Write t, q, q̇, q̈ as CSV, one row per time (atomically); columns say their units."""
        names = self.names()
        head = (["t [s]"] + [f"{n} [rad]" for n in names] + [f"{n}_vel [rad/s]" for n in names]
                + [f"{n}_acc [rad/s^2]" for n in names])
        rows = np.column_stack([self.t, self.q, self.qd, self.qdd])
        text = ",".join(head) + "\n" + "\n".join(",".join(repr(float(x)) for x in r)
                                                 for r in rows) + "\n"
        return write_text_atomic(path, text)

    def to_json(self, path: str | FsPath) -> FsPath:
        """Write the trajectory as JSON (atomically): units, names, limits and arrays."""
        data = {"units": {"t": "s", "q": "rad (m for prismatic)", "qd": "per s",
                          "qdd": "per s^2", "jerk_limits": "per s^3"},
                "joint_names": self.names(), "duration": self.duration,
                "velocity_limits": self.velocity.tolist(),
                "acceleration_limits": self.acceleration.tolist(),
                "jerk_limits": None if self.jerk is None else self.jerk.tolist(),
                "method": self.method,
                "t": self.t.tolist(), "q": self.q.tolist(), "qd": self.qd.tolist(),
                "qdd": self.qdd.tolist()}
        return write_text_atomic(path, json.dumps(data))


def _robot_limits(robot: Robot | None, value: object, n: int, name: str,
                  caller: str) -> object:
    """``value``, or the robot's own limits of that kind when ``value`` is None."""
    if value is not None:
        return value
    attr = f"{name}_limits"
    if robot is None:
        raise InputError(f"{caller} needs {name} limits: pass {name}=... (one per joint or "
                         f"one for all), or robot=... whose {attr} are stated")
    if robot.n != n:
        raise InputError(f"q has {n} joints but robot {robot.name!r} has {robot.n}")
    own = getattr(robot, attr)
    if own is None:
        where = (" (URDF and MJCF have no acceleration limits: give them, or set them with "
                 "robot.with_rate_limits)" if name == "acceleration" else
                 " (a URDF's <limit velocity>, or robot.with_rate_limits)")
        raise InputError(f"{caller} needs {name} limits: pass {name}=...; robot "
                         f"{robot.name!r} states none{where}")
    missing = [robot.joint_names[j] for j in np.flatnonzero(~np.isfinite(own))]
    if missing:
        raise InputError(f"{caller} needs {name} limits: robot {robot.name!r} states none "
                         f"for joint(s) {', '.join(missing)}; pass {name}=...")
    return own


def _joint_path(q: object) -> tuple[np.ndarray, np.ndarray]:
    """The path (m, n) without consecutive duplicates, and its chord length s (m,) [rad or m]."""
    Q = as_float_array(q, "q", ndim=2)
    if Q.shape[0] < 2:
        raise InputError(f"q must hold at least 2 configurations, got shape {Q.shape}")
    keep = np.concatenate([[True], np.abs(np.diff(Q, axis=0)).max(axis=1) > 1e-12])
    Q = Q[keep]
    if len(Q) < 2:
        raise InputError("q does not move: every configuration is the same")
    s = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(Q, axis=0), axis=1))])
    return Q, s


def _path_and_limits(q: object, robot: Robot | None, velocity: object, acceleration: object,
                     dt: float, caller: str) -> tuple[np.ndarray, ...]:
    """The checked path and limits of ``caller`` (time_optimal, jerk_limited).

    Returns the joint path ``Q`` (k, n), its parameter ``s`` (k,) and the velocity and
    acceleration limits (n,) (given, else the robot's); ``dt`` is checked too.
    """
    Q, s = _joint_path(q)
    n = Q.shape[1]
    v = _limits(_robot_limits(robot, velocity, n, "velocity", caller), n, "velocity")
    a = _limits(_robot_limits(robot, acceleration, n, "acceleration", caller), n,
                "acceleration")
    _check_dt(dt)
    return Q, s, v, a


def _check_dt(dt: float) -> None:
    if not (dt > 0.0 and math.isfinite(dt)):
        raise InputError(f"dt must be a positive time step in seconds, got {dt!r}")


def _limits(value: object, n: int, name: str) -> np.ndarray:
    a = np.broadcast_to(as_float_array(value, name), (n,)) if np.ndim(value) == 0 else \
        as_float_array(value, name)
    if a.shape != (n,) or not np.all(np.isfinite(a)) or np.any(a <= 0.0):
        raise InputError(f"{name} must be {n} positive finite limits (or one for every joint), "
                         f"got {np.asarray(value).tolist()!r}")
    return np.array(a, dtype=float)


def time_optimal(q: object, velocity: object = None, acceleration: object = None, *,
                 robot: Robot | None = None, cartesian_speed: float | None = None,
                 dt: float = 0.01, gridpoints: int | None = None) -> TimedPath:
    """The time-optimal timing of joint path ``q`` under velocity and acceleration limits.

    Args:
        q: (m, n) joint path (m ≥ 2), e.g. :attr:`JointPath.q`; consecutive duplicate
            rows are dropped.
        velocity: (n,) or one velocity limit v_j > 0 [rad/s or m/s]; None: the robot's
            ``velocity_limits``.
        acceleration: (n,) or one acceleration limit a_j > 0 [rad/s² or m/s²]; None: the
            robot's ``acceleration_limits``.
        robot: the arm (needed for ``cartesian_speed`` and for limits not given; gives
            the joint names).
        cartesian_speed: the tool position's largest speed [m/s], or None.
        dt: the output's time step [s] (the last sample is at ``duration``).
        gridpoints: toppra's discretisation of the path (default: its own choice from
            the spline's breakpoints, at least 2·m).

    Returns:
        :class:`TimedPath` sampled every ``dt``. toppra enforces the limits at its grid
        points; where its spline exceeds one between them (by about 1e-4 relative), the
        whole timing is slowed by the smallest factor that brings it inside, so every
        limit holds on a fine sampling of the result.

    Raises:
        InputError: bad shapes or limits; a limit neither given nor stated by the robot
            (the message names which, and the joints without one).
        SerialkinError: toppra missing (install the ``paths`` extra), or no timing found
            (toppra's reachability analysis failed: the path cannot be followed with these
            limits, e.g. a cusp where the path reverses).
    """
    ta = _toppra()
    Q, s, v, a = _path_and_limits(q, robot, velocity, acceleration, dt, "time_optimal")
    path = ta.SplineInterpolator(s, Q)
    constraints = [ta.constraint.JointVelocityConstraint(np.column_stack([-v, v])),
                   ta.constraint.JointAccelerationConstraint(np.column_stack([-a, a]))]
    if cartesian_speed is not None:
        constraints.append(_cartesian(ta, path, s, robot, cartesian_speed, v))
    grid = None if gridpoints is None else np.linspace(0.0, s[-1], int(gridpoints))
    if grid is None:
        grid = np.linspace(0.0, s[-1], max(2 * len(s), 100))
    algorithm = ta.algorithm.TOPPRA(constraints, path, gridpoints=grid,
                                    parametrizer="ParametrizeConstAccel")
    traj = algorithm.compute_trajectory(0.0, 0.0)
    if traj is None:
        raise SerialkinError("no timing found: toppra's reachability analysis failed (the "
                             "limits cannot be met along this path, e.g. at a cusp)")
    duration = float(traj.duration)
    # toppra meets the limits at its grid points; between them the spline can exceed
    # them by a little (1e-4 relative seen). Slowing time by k ≥ 1 scales q̇ by 1/k and
    # q̈ by 1/k², so the smallest k that brings every sample inside is applied.
    fine = np.linspace(0.0, duration, max(2000, int(duration / dt) + 1))
    k = max(1.0, float((np.abs(traj(fine, 1)) / v).max()),
            math.sqrt(float((np.abs(traj(fine, 2)) / a).max())))
    u = np.append(np.arange(0.0, duration * k, dt), duration * k) / k
    t = u * k
    names = tuple(robot.joint_names) if robot is not None else ()
    out = [np.asarray(traj(u), dtype=float), np.asarray(traj(u, 1), dtype=float) / k,
           np.asarray(traj(u, 2), dtype=float) / (k * k)]
    duration *= k
    for x in (t, *out):
        x.setflags(write=False)
    return TimedPath(t=t, q=out[0], qd=out[1], qdd=out[2], duration=duration, velocity=v,
                     acceleration=a, joint_names=names)


def jerk_limited(q: object, jerk: object, velocity: object = None,
                 acceleration: object = None, *, robot: Robot | None = None,
                 dt: float = 0.01) -> TimedPath:
    """A timing of joint path ``q`` under velocity, acceleration and jerk limits (Ruckig).

    The path is a cubic spline q(s) through ``q`` (chord length s in joint space, as in
    :func:`time_optimal`), followed exactly; s(t) is Ruckig's time-optimal rest-to-rest
    profile under constant bounds V, A, J on ṡ, |s̈|, |s⃛| (module docstring):

        V = min_j min(v_j / D1_j, √(a_j / (2·D2_j)), ∛(j_j / (3·D3_j))),
        A = min_j min((a_j − D2_j·V²) / D1_j, j_j / (9·D2_j·V)),
        J = min_j (j_j − 3·D2_j·V·A − D3_j·V³) / D1_j,

    where D1_j, D2_j, D3_j are the largest |q_j′|, |q_j″|, |q_j‴| along the spline; then
    |q̇_j| ≤ v_j, |q̈_j| ≤ a_j and |q⃛_j| ≤ j_j everywhere. The bounds are conservative:
    the duration is longer than :func:`time_optimal`'s (which has no jerk limit), the
    more so the less uniform the path's curvature. As in :func:`time_optimal`, a fine
    sampling of the result is checked (jerk by differences of q̈) and time is slowed by
    the smallest factor that keeps every limit.

    Args:
        q: (m, n) joint path (m ≥ 2); consecutive duplicate rows are dropped.
        jerk: (n,) or one jerk limit j_j > 0 [rad/s³ or m/s³].
        velocity: (n,) or one velocity limit [rad/s or m/s]; None: the robot's.
        acceleration: (n,) or one acceleration limit [rad/s² or m/s²]; None: the robot's.
        robot: the arm (for limits not given; gives the joint names).
        dt: the output's time step [s] (the last sample is at ``duration``).

    Returns:
        :class:`TimedPath` with ``method='ruckig'`` and ``jerk`` set, sampled every ``dt``.

    Raises:
        InputError: bad shapes or limits; a limit neither given nor stated by the robot.
        SerialkinError: ruckig missing (install the ``paths`` extra) or its calculation
            failed.
    """
    from scipy.interpolate import CubicSpline

    rk = require("ruckig", "paths", "jerk_limited")
    Q, s, v, a = _path_and_limits(q, robot, velocity, acceleration, dt, "jerk_limited")
    n = Q.shape[1]
    jk = _limits(jerk, n, "jerk")
    spline = CubicSpline(s, Q)
    V, A, J = _path_bounds(spline, s, v, a, jk)
    traj = _ruckig_profile(rk, float(s[-1]), V, A, J)
    base = float(traj.duration)

    def states(times: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        return _joint_states(traj, spline, float(s[-1]), times)

    fine = np.linspace(0.0, base, max(4000, int(base / dt) + 1))
    _, fqd, fqdd = states(fine)
    fjerk = np.diff(fqdd, axis=0) / np.diff(fine)[:, None]
    k = max(1.0, float((np.abs(fqd) / v).max()), math.sqrt(float((np.abs(fqdd) / a).max())),
            float((np.abs(fjerk) / jk).max()) ** (1.0 / 3.0))
    t = np.append(np.arange(0.0, base * k, dt), base * k)
    qs, qd, qdd = states(t / k)
    out = (t, qs, qd / k, qdd / (k * k))
    for x in out:
        x.setflags(write=False)
    names = tuple(robot.joint_names) if robot is not None else ()
    return TimedPath(t=out[0], q=out[1], qd=out[2], qdd=out[3], duration=base * k,
                     velocity=v, acceleration=a, joint_names=names, jerk=jk, method="ruckig")


def _path_bounds(spline: Any, s: np.ndarray, v: np.ndarray, a: np.ndarray,
                 jk: np.ndarray) -> tuple[float, float, float]:
    """The bounds V, A, J on ṡ, |s̈|, |s⃛| that keep every joint inside v, a, jk.

    The formulas of :func:`jerk_limited` with D1, D2, D3 the largest |q′|, |q″|, |q‴| of
    ``spline`` (a cubic spline over the knots ``s`` (m,)): q′ and q″ are polynomials of
    degree 2 and 1 on each knot interval, q‴ a constant, so their largest values are
    taken from 8 points an interval (the final check of the timing covers the rest).
    """
    grid = (s[:-1, None] + np.diff(s)[:, None] * np.linspace(0.0, 1.0, 8)).ravel()
    D1, D2, D3 = (np.abs(spline(grid, k)).max(axis=0) for k in (1, 2, 3))
    V = min(_ratio(v, D1), _ratio(a, 2.0 * D2, 0.5), _ratio(jk, 3.0 * D3, 1.0 / 3.0))
    A = min(_ratio(a - D2 * V * V, D1), _ratio(jk, 9.0 * D2 * V))
    J = _ratio(jk - 3.0 * D2 * V * A - D3 * V ** 3, D1)
    return V, A, J


def _ruckig_profile(rk: Any, length: float, V: float, A: float, J: float) -> Any:
    """Ruckig's time-optimal rest-to-rest trajectory of s from 0 to ``length``.

    Raises:
        SerialkinError: ruckig found none.
    """
    inp = rk.InputParameter(1)
    inp.current_position, inp.target_position = [0.0], [length]
    inp.max_velocity, inp.max_acceleration, inp.max_jerk = [V], [A], [J]
    traj = rk.Trajectory(1)
    result = rk.Ruckig(1).calculate(inp, traj)
    if result not in (rk.Result.Working, rk.Result.Finished):
        raise SerialkinError(f"ruckig found no trajectory ({result}) along a path of length "
                             f"{length:.4g} with bounds ṡ ≤ {V:.4g}, |s̈| ≤ {A:.4g}, "
                             f"|s⃛| ≤ {J:.4g}")
    return traj


def _joint_states(traj: Any, spline: Any, length: float, times: np.ndarray,
                  ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """q, q̇, q̈ (k, n) at ``times`` (k,) [s] of the profile s(t) ``traj`` along ``spline``.

    ``q̇ = q′ ṡ`` and ``q̈ = q″ ṡ² + q′ s̈``, s clipped to [0, ``length``].
    """
    x = np.array([traj.at_time(float(t)) for t in times])[:, :, 0]   # (k, 3): s, ṡ, s̈
    d1 = spline(np.clip(x[:, 0], 0.0, length), 1)
    return (spline(np.clip(x[:, 0], 0.0, length)), d1 * x[:, 1:2],
            spline(np.clip(x[:, 0], 0.0, length), 2) * x[:, 1:2] ** 2 + d1 * x[:, 2:3])


def _ratio(num: np.ndarray, den: np.ndarray, power: float = 1.0) -> float:
    """min_j (num_j / den_j)^power over the joints with den_j > 0 (inf when none)."""
    ok = den > 0.0
    return float(np.min((num[ok] / den[ok]) ** power)) if ok.any() else math.inf


def _cartesian(ta, path, s, robot, speed, v):
    """Velocity limits varying along s that cap the tool position's speed at ``speed``."""
    if robot is None:
        raise InputError("cartesian_speed needs the robot (robot=...) to compute positions")
    if not (speed > 0.0 and math.isfinite(speed)):
        raise InputError(f"cartesian_speed must be a positive speed in m/s, got {speed!r}")

    def limits(x: float) -> np.ndarray:  # toppra asks for one s at a time: (n, 2)
        dq = path(np.array([x]), 1)[0]                       # q'(s), (n,)
        J = robot.jacobian(path(np.array([x]))[0])[:3]       # position rows, (3, n)
        dp = float(np.linalg.norm(J @ dq))
        lim = np.minimum(v, np.maximum(np.abs(dq) * speed / max(dp, 1e-12), 1e-9))
        return np.column_stack([-lim, lim])

    return ta.constraint.JointVelocityConstraintVarying(limits)
