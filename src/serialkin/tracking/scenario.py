"""Tracking scenarios: robot, path, obstacles, limits and solver settings in one file.

A scenario is a YAML or JSON mapping, validated field by field; every error names the
file and the field (e.g. ``scenario 'arm.yaml': field 'path.radius' must be a number > 0,
got 'abc'``). Shipped scenarios (``serialkin/data/scenarios``) reproduce the chapter's
examples: ``six_link_circle`` (Figures 8-9), ``twenty_link_free`` (Figure 11) and
``twenty_link_obstacles`` (Figure 12).

Schema (fields marked * are required)::

    name: str
    description: str
    robot: *                     # exactly one of:
      planar: {links: int, length: float [m]}   # n-link planar arm (standard DH, a = L)
      dh: [{a, alpha, d, theta, type?}]         # standard DH table
      model: str                                # a model of serialkin.models
      urdf: path                                # relative to the scenario file
      joint_limits_deg: [lo, hi] | [[lo, hi], ...]   # optional, degrees
    q0: [..] rad | q0_deg: [..] or one number for every joint   # default zeros
    path: *
      type: circle | points | polyline | wave
      circle:   center [x, y], radius, start (0), stop (2π), step (0.2) [rad]
      points:   points [[x, y] | [x, y, z], ...]
      polyline: waypoints [[...], ...], step [m]
      wave:     start [x, y] | "q0", end [x, y], amplitude [m], periods (1), step (0.02)
                (straight line start→end plus amplitude·sin(2π·periods·s) sideways, s ∈ [0, 1])
      task: planar | position | planar_pose   # optional
    obstacles: [{type: circle|cylinder|sphere|capsule, center|a,b, radius, influence, name}]
    solver:
      method: dls | multitask | <IK method name>          (default dls)
      damping, tol, max_iter, max_step                     (dls / IK)
      weight, obstacle_weight, joint_limit_weight, limit_buffer, singularity_damping,
      manipulability_threshold, repulsive_gain, gain, max_task_step, link_radius (multitask)
    tolerance: float [m]            (default 0.005)
    on_unreachable: continue | stop (default continue)
"""

from __future__ import annotations

import json
import math
import os
from collections.abc import Iterable
from dataclasses import dataclass, field
from importlib import resources
from pathlib import Path as FsPath
from typing import Any

import numpy as np

from serialkin.errors import InputError, InputTypeError, SerialkinError
from serialkin.redundancy.multitask import MultiTaskResolver
from serialkin.redundancy.obstacles import check_obstacles, obstacle_from_dict
from serialkin.tracking.path import Path
from serialkin.tracking.tracker import ON_UNREACHABLE, track
from serialkin.tracking.trajectory import Trajectory

__all__ = [
    "Scenario",
    "ScenarioError",
    "list_scenarios",
    "load_scenario",
    "planar_arm",
    "scenario_from_dict",
]


class ScenarioError(InputError):
    """A scenario file is malformed: the message names the file and the field."""


def planar_arm(links: int, length: float, *, name: str | None = None,
               joint_limits_deg: object = None):
    """An n-link planar arm with equal links (standard DH: a = length, α = d = θ = 0).

    Args:
        links: number of revolute joints.
        length: link length [m].
        name: robot name (default ``'planar<n>'``).
        joint_limits_deg: optional (lo, hi) for every joint or (n, 2) [deg].
    """
    from serialkin.model.robot import Robot

    rows = [{"a": float(length), "alpha": 0.0, "d": 0.0, "theta": 0.0} for _ in range(links)]
    robot = Robot.from_dh(rows, name=name or f"planar{links}",
                          source="equal-link planar arm (chapter section 5.3)")
    if joint_limits_deg is not None:
        lim = np.radians(np.asarray(joint_limits_deg, dtype=float))
        if lim.shape == (2,):
            lim = np.tile(lim, (links, 1))
        robot = robot.with_limits(lim)
    return robot


_ROOT_FIELDS = {"name", "description", "robot", "q0", "q0_deg", "path", "obstacles", "solver",
                "tolerance", "on_unreachable"}
_DLS_FIELDS = {"damping", "tol", "max_iter", "max_step"}
_MT_FIELDS = {"weight", "obstacle_weight", "joint_limit_weight", "limit_buffer", "damping",
              "singularity_damping", "manipulability_threshold", "repulsive_gain", "gain",
              "max_task_step", "max_step", "tol", "max_iter", "link_radius"}


class _Reader:
    """Field access with messages that name the file and the field."""

    def __init__(self, source: str) -> None:
        self.source = source

    def fail(self, where: str, msg: str) -> ScenarioError:
        return ScenarioError(f"scenario {self.source!r}: field {where!r} {msg}")

    def mapping(self, d: object, where: str) -> dict:
        if not isinstance(d, dict):
            raise self.fail(where, f"must be a mapping, got {type(d).__name__} {d!r}"[:200])
        return d

    def get(self, d: dict, key: str, where: str, required: bool = False) -> Any:
        full = f"{where}.{key}" if where else key
        if key not in d or d[key] is None:
            if required:
                raise self.fail(full, "is missing")
            return None
        return d[key]

    def number(self, d: dict, key: str, where: str, *, default: float | None = None,
               positive: bool = False, nonneg: bool = False, required: bool = False) -> float:
        v = self.get(d, key, where, required)
        full = f"{where}.{key}" if where else key
        if v is None:
            return default  # type: ignore[return-value]
        if isinstance(v, bool) or not isinstance(v, (int, float)) or not math.isfinite(v):
            raise self.fail(full, f"must be a finite number, got {v!r}")
        if positive and v <= 0:
            raise self.fail(full, f"must be a number > 0, got {v!r}")
        if nonneg and v < 0:
            raise self.fail(full, f"must be a number >= 0, got {v!r}")
        return float(v)

    def integer(self, d: dict, key: str, where: str, *, minimum: int = 1,
                default: int | None = None, required: bool = False) -> int:
        v = self.get(d, key, where, required)
        full = f"{where}.{key}" if where else key
        if v is None:
            return default  # type: ignore[return-value]
        if isinstance(v, bool) or not isinstance(v, int) or v < minimum:
            raise self.fail(full, f"must be an integer >= {minimum}, got {v!r}")
        return int(v)

    def present(self, d: dict, where: str, numbers: Iterable[str], integers: Iterable[str],
                *, positive: bool = False, nonneg: bool = False) -> dict[str, Any]:
        """The given fields of ``d``: ``numbers`` (see :meth:`number`), then ``integers``.

        Integers must be >= 1; absent or null fields are left out of the result.
        """
        out: dict[str, Any] = {}
        for k in numbers:
            v = self.number(d, k, where, positive=positive, nonneg=nonneg)
            if v is not None:
                out[k] = v
        for k in integers:
            i = self.integer(d, k, where)
            if i is not None:
                out[k] = i
        return out

    def array(self, v: object, where: str, shape_desc: str, ndim: int | None = None,
              cols: tuple[int, ...] | None = None) -> np.ndarray:
        try:
            a = np.asarray(v, dtype=float)
        except (TypeError, ValueError):
            raise self.fail(where, f"must be {shape_desc} of numbers, got {v!r}"[:300]) from None
        if ndim is not None and a.ndim != ndim or cols is not None and a.shape[-1] not in cols:
            raise self.fail(where, f"must be {shape_desc}, got shape {a.shape}")
        if not np.isfinite(a).all():
            bad = tuple(int(i) for i in np.argwhere(~np.isfinite(a))[0])
            raise self.fail(where, f"must be finite; entry {bad} is {a[bad]}")
        return a

    def unknown(self, d: dict, allowed: set[str], where: str) -> None:
        extra = sorted(set(d) - allowed)
        if extra:
            import difflib

            hints = [f"{e!r} (did you mean {m[0]!r}?)" if (m := difflib.get_close_matches(
                e, sorted(allowed), n=1)) else repr(e) for e in extra]
            label = f"{where}." if where else ""
            raise ScenarioError(f"scenario {self.source!r}: unknown field(s) "
                                f"{', '.join(label + h for h in hints)}; allowed: "
                                f"{', '.join(sorted(allowed))}")


@dataclass
class Scenario:
    """A validated tracking scenario.

    Attributes:
        name: scenario name.
        description: free text.
        robot: the :class:`~serialkin.model.robot.Robot` (with the scenario's limits).
        path: the :class:`~serialkin.tracking.path.Path`.
        q0: (n,) start configuration [rad / m].
        obstacles: obstacles.
        solver: 'dls', an IK method name, or a ``MultiTaskResolver``.
        options: keyword options for :func:`~serialkin.tracking.tracker.track`.
        tolerance: acceptance tolerance [m].
        on_unreachable: 'continue' or 'stop'.
        link_radius: link capsule radius for clearances [m].
        source: the file it came from.
        data: the raw mapping.
    """

    name: str
    description: str
    robot: Any
    path: Path
    q0: np.ndarray
    obstacles: tuple
    solver: Any
    options: dict = field(default_factory=dict)
    tolerance: float = 5e-3
    on_unreachable: str = "continue"
    link_radius: float = 0.0
    source: str = ""
    data: dict = field(default_factory=dict)

    def run(self) -> Trajectory:
        """Track the path; returns the :class:`Trajectory`."""
        return track(self.robot, self.path, self.solver, q0=self.q0, obstacles=self.obstacles,
                     link_radius=self.link_radius, tolerance=self.tolerance,
                     on_unreachable=self.on_unreachable, **self.options)


def _robot(rd: _Reader, d: dict, base_dir: FsPath | None):
    from serialkin.model.robot import Robot

    r = rd.mapping(d, "robot")
    kinds = [k for k in ("planar", "dh", "model", "urdf") if k in r]
    rd.unknown(r, {"planar", "dh", "model", "urdf", "joint_limits_deg", "name"}, "robot")
    if len(kinds) != 1:
        raise rd.fail("robot", "must have exactly one of 'planar', 'dh', 'model', 'urdf', "
                      f"got {kinds or 'none'}")
    kind = kinds[0]
    name = r.get("name")
    try:
        if kind == "planar":
            p = rd.mapping(r["planar"], "robot.planar")
            rd.unknown(p, {"links", "length"}, "robot.planar")
            n = rd.integer(p, "links", "robot.planar", required=True)
            L = rd.number(p, "length", "robot.planar", positive=True, required=True)
            robot = planar_arm(n, L, name=name)
        elif kind == "dh":
            rows = r["dh"]
            if not isinstance(rows, list) or not rows:
                raise rd.fail("robot.dh", "must be a non-empty list of rows")
            robot = Robot.from_dh(rows, name=name or "robot")
        elif kind == "model":
            import serialkin.models as models

            fn = getattr(models, str(r["model"]), None)
            if not callable(fn):
                raise rd.fail("robot.model", f"names no model of serialkin.models: {r['model']!r}")
            robot = fn()
        else:
            p = FsPath(str(r["urdf"]))
            if not p.is_absolute() and base_dir is not None:
                p = base_dir / p
            robot = Robot.from_urdf(str(p))
    except ScenarioError:
        raise
    except (SerialkinError, ValueError, TypeError) as exc:
        raise rd.fail(f"robot.{kind}", f"is invalid: {exc}") from exc
    lim = r.get("joint_limits_deg")
    if lim is not None:
        a = rd.array(lim, "robot.joint_limits_deg", "[lo, hi] or (n, 2) degrees")
        if a.shape == (2,):
            a = np.tile(a, (robot.n, 1))
        if a.shape != (robot.n, 2) or np.any(a[:, 0] >= a[:, 1]):
            raise rd.fail("robot.joint_limits_deg",
                          f"must be [lo, hi] or ({robot.n}, 2) with lo < hi, got {lim!r}")
        robot = robot.with_limits(np.radians(a))
    return robot


def _path(rd: _Reader, d: object, robot, q0: np.ndarray) -> Path:
    p = rd.mapping(d, "path")
    kind = rd.get(p, "type", "path", required=True)
    allowed = {"circle": {"center", "radius", "start", "stop", "step"},
               "points": {"points"},
               "polyline": {"waypoints", "step"},
               "wave": {"start", "end", "amplitude", "periods", "step"}}
    if kind not in allowed:
        raise rd.fail("path.type", f"must be one of {', '.join(allowed)}, got {kind!r}")
    rd.unknown(p, allowed[kind] | {"type", "task"}, "path")
    task = p.get("task")
    if task is not None and task not in ("planar", "position", "planar_pose"):
        raise rd.fail("path.task", f"must be planar, position or planar_pose, got {task!r}")
    try:
        if kind == "circle":
            c = rd.array(rd.get(p, "center", "path", True), "path.center", "[x, y]", 1, (2,))
            return Path.circle(c, rd.number(p, "radius", "path", positive=True, required=True),
                               start=rd.number(p, "start", "path", default=0.0),
                               stop=rd.number(p, "stop", "path", default=2 * math.pi),
                               step=rd.number(p, "step", "path", default=0.2, positive=True))
        if kind == "points":
            pts = rd.array(rd.get(p, "points", "path", True), "path.points",
                           "a list of [x, y] or [x, y, z] points", 2, (2, 3))
            return Path.from_points(pts, task=task)
        if kind == "polyline":
            w = rd.array(rd.get(p, "waypoints", "path", True), "path.waypoints",
                         "a list of [x, y] or [x, y, z] points", 2, (2, 3))
            return Path.polyline(w, rd.number(p, "step", "path", positive=True, required=True),
                                 task=task)
        start = rd.get(p, "start", "path", True)
        if start == "q0":
            a = robot.fk(q0)[:2, 3]
        else:
            a = rd.array(start, "path.start", "[x, y] or 'q0'", 1, (2,))
        b = rd.array(rd.get(p, "end", "path", True), "path.end", "[x, y]", 1, (2,))
        amp = rd.number(p, "amplitude", "path", default=0.0)
        periods = rd.number(p, "periods", "path", default=1.0)
        step = rd.number(p, "step", "path", default=0.02, positive=True)
        if step > 1:
            raise rd.fail("path.step", f"must be in (0, 1] for a wave, got {step!r}")
        dvec = b - a
        nrm = np.array([-dvec[1], dvec[0]]) / max(np.linalg.norm(dvec), 1e-12)
        return Path.from_function(
            lambda s: a + dvec * s + amp * math.sin(2 * math.pi * periods * s) * nrm,
            0.0, 1.0, step, task="planar")
    except ScenarioError:
        raise
    except (InputError, InputTypeError) as exc:
        raise rd.fail("path", f"is invalid: {exc}") from exc


def scenario_from_dict(data: object, source: str = "<dict>",
                       base_dir: str | os.PathLike[str] | None = None) -> Scenario:
    """Validate a scenario mapping and build a :class:`Scenario`.

    Args:
        data: the mapping (as read from YAML/JSON).
        source: file name used in error messages.
        base_dir: folder for relative paths (URDF).

    Raises:
        ScenarioError: a missing, unknown or mistyped field (the message names the file
            and the field), negative weights, obstacles overlapping the base.
    """
    rd = _Reader(source)
    d = rd.mapping(data, "(root)")
    rd.unknown(d, _ROOT_FIELDS, "")
    robot = _robot(rd, rd.get(d, "robot", "", required=True),
                   FsPath(base_dir) if base_dir is not None else None)
    n = robot.n
    if "q0" in d and "q0_deg" in d:
        raise rd.fail("q0", "and 'q0_deg' are both given; use one")
    q0 = np.zeros(n)
    for key, scale in (("q0", 1.0), ("q0_deg", math.pi / 180)):
        if d.get(key) is not None:
            a = rd.array(d[key], key, f"one number or a list of {n} numbers")
            if a.ndim == 0:
                a = np.full(n, float(a))
            if a.shape != (n,):
                raise rd.fail(key, f"must have {n} values (one per joint), got shape {a.shape}")
            q0 = a * scale
    path = _path(rd, rd.get(d, "path", "", required=True), robot, q0)
    obs_list = d.get("obstacles") or []
    if not isinstance(obs_list, list):
        raise rd.fail("obstacles", f"must be a list, got {type(obs_list).__name__}")
    obstacles = []
    for i, o in enumerate(obs_list):
        try:
            obstacles.append(obstacle_from_dict(o, where=f"obstacles[{i}]"))
        except (InputError, InputTypeError) as exc:
            raise ScenarioError(f"scenario {source!r}: {exc}") from exc
    obstacles = tuple(obstacles)
    solver_d = rd.mapping(d.get("solver") or {}, "solver")
    method = solver_d.get("method", "dls")
    if not isinstance(method, str):
        raise rd.fail("solver.method", f"must be a string, got {method!r}")
    tolerance = rd.number(d, "tolerance", "", default=5e-3, positive=True)
    on_unreach = d.get("on_unreachable", "continue")
    if on_unreach not in ON_UNREACHABLE:
        raise rd.fail("on_unreachable", f"must be one of {', '.join(ON_UNREACHABLE)}, "
                      f"got {on_unreach!r}")
    options: dict[str, Any] = {}
    link_radius = 0.0
    if method == "multitask":
        rd.unknown(solver_d, _MT_FIELDS | {"method"}, "solver")
        kw = rd.present(solver_d, "solver", sorted(_MT_FIELDS - {"max_iter"}), ["max_iter"],
                        nonneg=True)
        link_radius = kw.get("link_radius", 0.0)
        try:
            solver: Any = MultiTaskResolver(task=path.task, obstacles=obstacles, **kw)
        except (InputError, InputTypeError) as exc:
            raise rd.fail("solver", f"is invalid: {exc}") from exc
    else:
        rd.unknown(solver_d, _DLS_FIELDS | {"method", "options"}, "solver")
        options.update(rd.present(solver_d, "solver", ("damping", "tol", "max_step"),
                                  ["max_iter"], positive=True))
        if method != "dls":
            extra = solver_d.get("options") or {}
            options["ik_options"] = rd.mapping(extra, "solver.options")
        solver = method
    try:
        check_obstacles(robot, obstacles, link_radius=link_radius)
    except InputError as exc:
        raise ScenarioError(f"scenario {source!r}: field 'obstacles': {exc}") from exc
    name = d.get("name", FsPath(source).stem)
    return Scenario(name=str(name), description=str(d.get("description", "")), robot=robot,
                    path=path, q0=q0, obstacles=obstacles, solver=solver, options=options,
                    tolerance=tolerance, on_unreachable=on_unreach, link_radius=link_radius,
                    source=source, data=dict(d))


def _shipped_dir():
    return resources.files("serialkin") / "data" / "scenarios"


def list_scenarios() -> list[str]:
    """Names of the shipped scenarios."""
    return sorted(p.name.rsplit(".", 1)[0] for p in _shipped_dir().iterdir()
                  if p.name.endswith((".yaml", ".yml", ".json")))


def load_scenario(path_or_name: str | os.PathLike[str]) -> Scenario:
    """Load and validate a scenario from a YAML/JSON file, or a shipped one by name.

    Raises:
        ScenarioError: unreadable or malformed file (the message names the file and field).
        InputError: no such file and no shipped scenario of that name.
    """
    import yaml

    p = FsPath(path_or_name)
    if not p.exists():
        names = list_scenarios()
        if str(path_or_name) in names:
            for ext in (".yaml", ".yml", ".json"):
                res = _shipped_dir() / f"{path_or_name}{ext}"
                if res.is_file():
                    with resources.as_file(res) as real:
                        return load_scenario(real)
        raise InputError(f"no scenario file {str(path_or_name)!r}; shipped scenarios: "
                         f"{', '.join(names)}")
    text = p.read_text(encoding="utf-8")
    try:
        if p.suffix.lower() == ".json":
            data = json.loads(text)
        else:
            data = yaml.safe_load(text)
    except (json.JSONDecodeError, yaml.YAMLError) as exc:
        raise ScenarioError(f"scenario {p.name!r}: cannot be parsed: {exc}") from exc
    return scenario_from_dict(data, source=p.name, base_dir=p.parent)
