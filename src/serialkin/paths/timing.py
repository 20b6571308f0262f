"""Time-optimal timing of a joint path under velocity and acceleration limits (toppra).

A joint path q₀ … q_{m−1} is interpolated by a cubic spline q(s) in a path parameter s
(chord length in joint space), and the fastest ``s(t)`` that keeps every joint inside
``|q̇_j| ≤ v_j`` and ``|q̈_j| ≤ a_j`` is found by reachability analysis (TOPP-RA: Pham &
Pham, "A new approach to time-optimal path parameterization based on reachability
analysis", IEEE T-RO 2018), with the ``toppra`` library (the ``paths`` extra), not by
code of our own. An optional Cartesian speed limit v_c on the tool's position becomes
the velocity limits ``|q̇_j| ≤ |q_j'(s)|·v_c / |p'(s)|`` that vary along the path (so
that ṡ ≤ v_c / |p'(s)|).

Units: seconds, radians (or metres for prismatic joints) and their rates.
"""

from __future__ import annotations

import json
import math
from dataclasses import dataclass
from pathlib import Path as FsPath

import numpy as np

from serialkin._checks import as_float_array
from serialkin._io import write_text_atomic
from serialkin.errors import InputError, SerialkinError
from serialkin.model.robot import Robot

__all__ = ["TimedPath", "time_optimal"]


def _toppra():
    try:
        import toppra
        import toppra.algorithm
        import toppra.constraint
    except ImportError as exc:  # pragma: no cover - the extra is installed in the tests
        raise SerialkinError(
            "time_optimal needs the toppra library: pip install 'serialkin[paths]'") from exc
    toppra.setup_logging("WARNING")
    return toppra


@dataclass(frozen=True, eq=False)
class TimedPath:
    """A timed joint trajectory (what :func:`time_optimal` returns).

    Attributes:
        t: (k,) times [s], from 0 to ``duration``.
        q: (k, n) joint values [rad or m].
        qd: (k, n) joint velocities [rad/s or m/s].
        qdd: (k, n) joint accelerations [rad/s² or m/s²].
        duration: the trajectory's length in time [s].
        velocity: (n,) the velocity limits used; acceleration: (n,) the acceleration limits.
        joint_names: the joints' names (column labels of the CSV file).
    """

    t: np.ndarray
    q: np.ndarray
    qd: np.ndarray
    qdd: np.ndarray
    duration: float
    velocity: np.ndarray
    acceleration: np.ndarray
    joint_names: tuple[str, ...] = ()

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
                          "qdd": "per s^2"},
                "joint_names": self.names(), "duration": self.duration,
                "velocity_limits": self.velocity.tolist(),
                "acceleration_limits": self.acceleration.tolist(),
                "t": self.t.tolist(), "q": self.q.tolist(), "qd": self.qd.tolist(),
                "qdd": self.qdd.tolist()}
        return write_text_atomic(path, json.dumps(data))


def _limits(value: object, n: int, name: str) -> np.ndarray:
    a = np.broadcast_to(as_float_array(value, name), (n,)) if np.ndim(value) == 0 else \
        as_float_array(value, name)
    if a.shape != (n,) or not np.all(np.isfinite(a)) or np.any(a <= 0.0):
        raise InputError(f"{name} must be {n} positive finite limits (or one for every joint), "
                         f"got {np.asarray(value).tolist()!r}")
    return np.array(a, dtype=float)


def time_optimal(q: object, velocity: object, acceleration: object, *,
                 robot: Robot | None = None, cartesian_speed: float | None = None,
                 dt: float = 0.01, gridpoints: int | None = None) -> TimedPath:
    """The time-optimal timing of joint path ``q`` under velocity and acceleration limits.

    Args:
        q: (m, n) joint path (m ≥ 2), e.g. :attr:`JointPath.q`; consecutive duplicate
            rows are dropped.
        velocity: (n,) or one velocity limit v_j > 0 [rad/s or m/s].
        acceleration: (n,) or one acceleration limit a_j > 0 [rad/s² or m/s²].
        robot: the arm (needed for ``cartesian_speed``; gives the joint names).
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
        InputError: bad shapes or limits.
        SerialkinError: toppra missing (install the ``paths`` extra), or no timing found
            (toppra's reachability analysis failed: the path cannot be followed with these
            limits, e.g. a cusp where the path reverses).
    """
    ta = _toppra()
    Q = as_float_array(q, "q", ndim=2)
    if Q.shape[0] < 2:
        raise InputError(f"q must hold at least 2 configurations, got shape {Q.shape}")
    keep = np.concatenate([[True], np.abs(np.diff(Q, axis=0)).max(axis=1) > 1e-12])
    Q = Q[keep]
    if len(Q) < 2:
        raise InputError("q does not move: every configuration is the same")
    n = Q.shape[1]
    v = _limits(velocity, n, "velocity")
    a = _limits(acceleration, n, "acceleration")
    if not (dt > 0.0 and math.isfinite(dt)):
        raise InputError(f"dt must be a positive time step in seconds, got {dt!r}")
    s = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(Q, axis=0), axis=1))])
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
