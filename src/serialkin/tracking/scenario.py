"""Tracking scenarios: robot, path, obstacles, limits and solver settings in one file.

A scenario is a YAML or JSON mapping, validated field by field; every error names the
file and the field (e.g. ``scenario 'arm.yaml': field 'path.radius' must be a number > 0,
got 'abc'``). Shipped scenarios (``serialkin/data/scenarios``) reproduce the chapter's
examples: ``six_link_circle`` (Figures 8-9), ``twenty_link_free`` (Figure 11) and
``twenty_link_obstacles`` (Figure 12).

Schema (fields marked * are required)::

    name: str
    description: str
    units: {angle: rad | deg}    # unit of every angle field without _deg (default rad)
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
      method: dls | multitask | qp | <IK method name>     (default dls)
      damping, tol, max_iter, max_step                     (dls / IK)
      max_joint_step [rad]   (dls / IK: report larger joint jumps between points;
                              qp: a hard bound, points beyond it are reported unreached)
      safety [m], collision_gain, self_collision, posture_weight, damping, max_step,
      max_joint_step, tol, max_iter, link_radius,
      backend (compiled | daqp | qpsolvers:<name>)  (qp)
      weight, obstacle_weight, joint_limit_weight, limit_buffer, singularity_damping,
      manipulability_threshold, repulsive_gain, gain, max_task_step, link_radius (multitask)
    tolerance: float [m]            (default 0.005)
    on_unreachable: continue | stop (default continue)
    srdf: path                      # the robot's SRDF (relative to the scenario file): its
                                    # <disable_collisions> pairs are skipped by the QP's
                                    # self-collision check (as `track --srdf`)
    skip_links: [str, ...]          # links of the SRDF without a collision body (needs srdf)

Angles: every angle field (``q0``, ``rpy``, ``angle``, ``max_angle``, a circle's ``start``,
``stop`` and ``step``, DH ``alpha``/``theta``, the φ column of ``planar_pose`` points) is
in the unit of ``units: {angle: ...}``, radians when ``units`` is absent; a ``*_deg`` field
(``q0_deg``, ``rpy_deg``, ``angle_deg``, ``max_angle_deg``) is in degrees whatever
``units`` says. A fixed angle (q0, rpy, DH) read in radians beyond a full turn is refused
with a hint to declare degrees: it is almost surely degrees.
"""

from __future__ import annotations

import math
import os
from dataclasses import dataclass, field
from importlib import resources
from pathlib import Path as FsPath
from typing import Any

import numpy as np

from serialkin._checks import MAX_ITERATIONS, MAX_JOINTS, MAX_LENGTH, beyond_a_turn, short_repr
from serialkin._files import MAX_ITEMS, MISSING, Field, load_document
from serialkin.errors import InputError, InputTypeError, SerialkinError
from serialkin.model.tasks import TARGET_TASKS, get_task
from serialkin.redundancy.multitask import MultiTaskResolver
from serialkin.redundancy.obstacles import check_obstacles, obstacle_from_field
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

#: Most joints of a scenario's robot (planar links or DH rows).
MAX_LINKS = MAX_JOINTS
#: Most points of a scenario's path.
MAX_PATH_POINTS = MAX_ITEMS


class ScenarioError(InputError):
    """A scenario file is malformed: the message names the file and the field."""


def planar_arm(links: int, length: float, *, name: str | None = None,
               joint_limits_deg: object = None):
    """An n-link planar arm with equal links, as the chapter's scenarios use it.

    :func:`serialkin.models.planar` (standard DH: a = length, α = d = θ = 0) with the
    limits given in degrees and no collision model (the scenarios' obstacles are the
    chapter's circles, not the arm's own capsules).

    Args:
        links: number of revolute joints.
        length: link length [m].
        name: robot name (default ``'planar<n>'``).
        joint_limits_deg: optional (lo, hi) for every joint or (n, 2) [deg].
    """
    from serialkin.models import planar

    qlim = None if joint_limits_deg is None else \
        np.radians(np.asarray(joint_limits_deg, dtype=float))
    return planar(links, float(length), qlim, name=name).with_collision(None)


_ROOT_FIELDS = {"name", "description", "units", "robot", "q0", "q0_deg", "path", "obstacles",
                "solver", "tolerance", "on_unreachable", "srdf", "skip_links"}
#: Angle units of ``units: {angle: ...}`` and their factor to radians.
ANGLE_UNITS = {"rad": 1.0, "deg": math.pi / 180.0}
_DEGREES_HINT = ("are these degrees? write units: {angle: deg} at the top of the file, or "
                 "the field's _deg form")


def _angle_unit(f: Field) -> str:
    """The scenario's angle unit: ``units: {angle: rad|deg}`` (length, if given, 'm')."""
    if not f.present:
        return "rad"
    u = f.mapping({"angle", "length"}, ("angle",),
                  what="a mapping {angle: rad | deg} (lengths are metres)")
    if u["length"].present:
        u["length"].string(choices=("m",))
    return u["angle"].string(choices=tuple(ANGLE_UNITS))
_DLS_FIELDS = {"damping", "tol", "max_iter", "max_step", "max_joint_step"}
_QP_FIELDS = {"safety", "collision_gain", "self_collision", "posture_weight", "damping",
              "max_step", "max_joint_step", "tol", "max_iter", "link_radius", "backend"}
_MT_FIELDS = {"weight", "obstacle_weight", "joint_limit_weight", "limit_buffer", "damping",
              "singularity_damping", "manipulability_threshold", "repulsive_gain", "gain",
              "max_task_step", "max_step", "tol", "max_iter", "link_radius"}
_ROBOT_KINDS = ("planar", "dh", "model", "urdf")
_POSE_STEPS = ("max_step", "max_angle", "max_angle_deg")
_PATH_FIELDS = {"circle": {"center", "radius", "start", "stop", "step"},
                "points": {"points"},
                "polyline": {"waypoints", "step"},
                "wave": {"start", "end", "amplitude", "periods", "step"},
                # pose paths (serialkin.tracking.poses): steps in metres and in radians
                # ('max_angle') or degrees ('max_angle_deg'), never guessed
                "line": {"start", "end", "orientation", *_POSE_STEPS},
                "arc": {"start", "center", "axis", "angle", "angle_deg", "orientation",
                        "end_rotation", *_POSE_STEPS},
                "waypoints": {"poses", "blend", *_POSE_STEPS}}
#: tasks of point paths (the target kinds given as [x, y], [x, y, φ] or [x, y, z])
_TASKS = tuple(name for name in TARGET_TASKS if get_task(name).point_size <= 3)


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
        solver: 'dls', an IK method name, a ``MultiTaskResolver`` or a ``QPResolver``.
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


def robot_from_field(f: Field, base_dir: FsPath | None, angle_unit: str = "rad"):
    """The robot of a scenario's ``robot`` field: planar, DH table, zoo model or URDF file.

    ``angle_unit`` ('rad' or 'deg') is the unit of a DH table's ``alpha`` and ``theta``.
    """
    from serialkin.formats.robotfile import dh_rows_from_field
    from serialkin.model.robot import Robot

    r = f.mapping({*_ROBOT_KINDS, "joint_limits_deg", "name"})
    kinds = [k for k in _ROBOT_KINDS if k in r]
    if len(kinds) != 1:
        raise r.fail("must have exactly one of 'planar', 'dh', 'model', 'urdf', "
                     f"got {kinds or 'none'}")
    kind = kinds[0]
    name = r["name"].string(default=None, max_len=1000)
    sub = r[kind]
    if kind == "planar":
        p = sub.mapping({"links", "length"}, ("links", "length"))
        n = p["links"].integer(lo=1, hi=MAX_LINKS)
        L = p["length"].number(lo=0.0, lo_open=True, hi=MAX_LENGTH, unit="m")
        robot = planar_arm(n, L, name=name)
    elif kind == "dh":
        rows = dh_rows_from_field(sub, angle_unit=angle_unit, length_unit="m")
        robot = Robot.from_dh(rows, name=name or "robot")
    else:
        text = sub.string(max_len=4096)
        try:
            if kind == "model":
                from serialkin import models

                robot = models.get(text)
            else:
                p = FsPath(text)
                if not p.is_absolute() and base_dir is not None:
                    p = base_dir / p
                robot = Robot.from_urdf(str(p))
        except SerialkinError as exc:
            raise sub.fail(f"is invalid: {exc}") from exc
        if robot.n > MAX_LINKS:
            raise sub.fail(f"gives a robot of {robot.n} joints, more than {MAX_LINKS}")
    lim_f = r["joint_limits_deg"]
    if lim_f.present:
        a = lim_f.array(what="[lo, hi] or (n, 2) degrees", lo=-1e6, hi=1e6)
        if a.shape == (2,):
            a = np.tile(a, (robot.n, 1))
        if a.shape != (robot.n, 2) or np.any(a[:, 0] >= a[:, 1]):
            raise lim_f.expected(f"[lo, hi] or ({robot.n}, 2) with lo < hi")
        robot = robot.with_limits(np.radians(a))
    return robot


def _count_points(f: Field, length: float, step: float) -> None:
    """Refuse a path whose ``length / step`` exceeds :data:`MAX_PATH_POINTS`."""
    count = length / step
    if not count <= MAX_PATH_POINTS:
        raise f.fail(f"gives about {count:.3g} path points, more than the limit of "
                     f"{MAX_PATH_POINTS}; use a larger step")


def _point(f: Field, what: str = "[x, y]") -> np.ndarray:
    a = f.require().array(what=what, ndim=1, lo=-MAX_LENGTH, hi=MAX_LENGTH)
    if a.shape != (2,):
        raise f.fail(f"must be {what}, got shape {a.shape}")
    return a


def _angle(f: Field, key: str, *, default: Any = None, lo: float = -1e6,
           hi: float = 1e6, angle_unit: str = "rad") -> Any:
    """The angle ``key`` [angle_unit] or ``key_deg`` [deg] (not both), in radians.

    ``lo`` and ``hi`` are in radians; a radian value outside them that is inside them
    as degrees is refused with the hint to declare degrees.
    """
    plain, deg = f[key], f[f"{key}_deg"]
    if plain.present and deg.present:
        raise plain.fail(f"and '{key}_deg' are both given; use one (radians or degrees)")
    if deg.present:
        return math.radians(deg.number(lo=math.degrees(lo), hi=math.degrees(hi), unit="deg"))
    if angle_unit == "deg":
        v = plain.number(lo=math.degrees(lo), hi=math.degrees(hi), unit="deg",
                         default=MISSING if default is MISSING else None)
        return default if v is None else math.radians(v)
    if plain.present and isinstance(plain.value, int | float) and \
            not isinstance(plain.value, bool) and not lo <= plain.value <= hi and \
            lo <= math.radians(plain.value) <= hi:
        raise plain.fail(f"= {plain.value:g} rad is outside [{lo:.4g}, {hi:.4g}] rad; "
                         + _DEGREES_HINT)
    return plain.number(lo=lo, hi=hi, unit="rad", default=default)


def pose_from_field(f: Field, robot=None, q0: np.ndarray | None = None,
                    angle_unit: str = "rad") -> np.ndarray:
    """A (4, 4) pose from ``{position: [x, y, z], rpy: [...]}`` (or ``rpy_deg``), or 'q0'.

    ``position`` in metres; the rotation as roll-pitch-yaw angles in ``angle_unit``
    (``rpy``; 'rad' or 'deg') or degrees (``rpy_deg``), absent for no rotation; ``'q0'``
    is the tool pose at the scenario's start configuration. ``rpy`` in radians beyond a
    full turn is refused (most likely degrees).
    """
    from serialkin.spatial.rotations import rpy_to_matrix

    if f.value == "q0" and robot is not None:
        return robot.fk(q0)
    m = f.mapping({"position", "rpy", "rpy_deg"}, ("position",),
                  what="a pose {position: [x, y, z], rpy: [..] or rpy_deg: [..]} or 'q0'")
    T = np.eye(4)
    T[:3, 3] = m["position"].vector(3, lo=-MAX_LENGTH, hi=MAX_LENGTH)
    if m["rpy"].present and m["rpy_deg"].present:
        raise m["rpy"].fail("and 'rpy_deg' are both given; use one (radians or degrees)")
    if m["rpy_deg"].present:
        T[:3, :3] = rpy_to_matrix(np.radians(m["rpy_deg"].vector(3, lo=-1e4, hi=1e4)))
    elif m["rpy"].present and angle_unit == "deg":
        T[:3, :3] = rpy_to_matrix(np.radians(m["rpy"].vector(3, lo=-1e4, hi=1e4, unit="deg")))
    elif m["rpy"].present:
        rpy = m["rpy"].vector(3, lo=-1e4, hi=1e4, unit="rad")
        if beyond_a_turn(rpy).any():
            raise m["rpy"].fail(f"= {[float(x) for x in rpy]} rad has an angle beyond a full "
                                f"turn (2π); " + _DEGREES_HINT + " (rpy_deg)")
        T[:3, :3] = rpy_to_matrix(rpy)
    return T


def _pose_path(p: Field, kind: str, robot, q0: np.ndarray, unit: str = "rad") -> Path:
    """A line, arc or waypoint path of poses (serialkin.tracking.poses) from its fields."""
    from serialkin.tracking import poses

    steps = {"max_step": p["max_step"].number(lo=0.0, lo_open=True, hi=MAX_LENGTH,
                                              default=0.005, unit="m"),
             "max_angle": _angle(p, "max_angle", default=math.radians(1.0), lo=1e-9,
                                 hi=math.pi, angle_unit=unit)}
    if kind == "line":
        return poses.line(pose_from_field(p["start"].require(), robot, q0, unit),
                          pose_from_field(p["end"].require(), robot, q0, unit),
                          orientation=p["orientation"].string(choices=("slerp", "fixed"),
                                                              default="slerp"), **steps)
    if kind == "arc":
        end = p["end_rotation"]
        return poses.arc(pose_from_field(p["start"].require(), robot, q0, unit),
                         p["center"].require().vector(3, lo=-MAX_LENGTH, hi=MAX_LENGTH),
                         p["axis"].require().vector(3, lo=-1e6, hi=1e6),
                         _angle(p, "angle", default=MISSING, lo=-2 * math.pi, hi=2 * math.pi,
                                angle_unit=unit),
                         end_rotation=(pose_from_field(end, angle_unit=unit)[:3, :3]
                                       if end.present else None),
                         orientation=p["orientation"].string(
                             choices=("follow", "fixed", "slerp"), default="follow"),
                         **steps)
    ws = np.stack([pose_from_field(w, robot, q0, unit) for w in
                   p["poses"].require().items(min_len=2, max_len=MAX_ITEMS)])
    blend = p["blend"].number(lo=0.0, hi=MAX_LENGTH, default=0.0, unit="m")
    return poses.waypoints(ws, blend=blend, **steps)


def _path(f: Field, robot, q0: np.ndarray, unit: str = "rad") -> Path:
    p = f.mapping()
    ang = ANGLE_UNITS[unit]
    kind = p["type"].string(choices=_PATH_FIELDS)
    p.mapping(_PATH_FIELDS[kind] | {"type", "task"})
    if kind in ("line", "arc", "waypoints"):
        try:
            return _pose_path(p, kind, robot, q0, unit)
        except (InputError, InputTypeError) as exc:
            if isinstance(exc, ScenarioError):
                raise
            raise f.fail(f"is invalid: {exc}") from exc
    task = p["task"].string(choices=_TASKS, default=None)
    try:
        if kind == "circle":
            c = _point(p["center"])
            radius = p["radius"].number(lo=0.0, lo_open=True, hi=MAX_LENGTH, unit="m")
            start = p["start"].number(default=0.0, unit=unit) * ang
            stop = p["stop"].number(default=2 * math.pi / ang, unit=unit) * ang
            step = p["step"].number(lo=0.0, lo_open=True, default=0.2 / ang, unit=unit) * ang
            _count_points(p["step"], abs(stop - start), step)
            return Path.circle(c, radius, start=start, stop=stop, step=step)
        if kind == "points":
            pts = p["points"].require().array(
                what="a list of [x, y] or [x, y, z] points", ndim=2, cols=(2, 3),
                max_items=3 * MAX_PATH_POINTS, lo=-MAX_LENGTH, hi=MAX_LENGTH)
            if task == "planar_pose" and pts.shape[1] == 3:  # (x, y, φ): φ in the unit
                pts = pts.copy()
                pts[:, 2] *= ang
            return Path.from_points(pts, task=task)
        if kind == "polyline":
            w = p["waypoints"].require().array(
                what="a list of [x, y] or [x, y, z] points", ndim=2, cols=(2, 3),
                lo=-MAX_LENGTH, hi=MAX_LENGTH)
            step = p["step"].number(lo=0.0, lo_open=True, hi=MAX_LENGTH, unit="m")
            _count_points(p["step"], float(np.linalg.norm(np.diff(w, axis=0), axis=1).sum()),
                          step)
            return Path.polyline(w, step, task=task)
        sf = p["start"].require()
        a = robot.fk(q0)[:2, 3] if sf.value == "q0" else _point(sf, "[x, y] or 'q0'")
        b = _point(p["end"])
        amp = p["amplitude"].number(lo=-MAX_LENGTH, hi=MAX_LENGTH, default=0.0, unit="m")
        periods = p["periods"].number(default=1.0)
        step = p["step"].number(lo=0.0, lo_open=True, hi=1.0, default=0.02)
        _count_points(p["step"], 1.0, step)
        dvec = b - a
        nrm = np.array([-dvec[1], dvec[0]]) / max(np.linalg.norm(dvec), 1e-12)
        return Path.from_function(
            lambda s: a + dvec * s + amp * math.sin(2 * math.pi * periods * s) * nrm,
            0.0, 1.0, step, task="planar")
    except (InputError, InputTypeError) as exc:
        if isinstance(exc, ScenarioError):
            raise
        raise f.fail(f"is invalid: {exc}") from exc


def _ik_options(f: Field, method: str) -> dict[str, Any]:
    """The ``solver.options`` of an IK method: known names, plain values of the right type."""
    from serialkin.ik.registry import get_method

    spec = get_method(method)
    defaults: dict[str, Any] = {"restarts": 0, "seed": 0, "respect_limits": True}
    defaults.update(spec.options)
    f.mapping(set(defaults), what="a mapping of option names to values")
    out: dict[str, Any] = {}
    for key in f.keys():
        v, default = f[key], defaults[key]
        if isinstance(default, bool):
            if not isinstance(v.value, bool):
                raise v.expected("true or false")
            out[key] = v.value
        elif key == "seed":
            out[key] = v.integer(lo=0, hi=2**63 - 1)
        elif isinstance(default, int):
            out[key] = v.integer(lo=0, hi=MAX_ITERATIONS)
        elif isinstance(default, str):
            out[key] = v.string(max_len=100)
        else:
            out[key] = v.number()
    return out


def _solver(f: Field, path: Path, obstacles: tuple) -> tuple[Any, dict[str, Any], float]:
    """The solver (name or resolver), the tracker's options and the link radius."""
    from serialkin.ik.registry import available_methods

    s = f.mapping() if f.present else Field({}, f.path, f.origin, f.error)
    others = [m for m in available_methods() if m not in ("dls", "multitask", "qp")]
    method = s["method"].string(choices=("dls", "multitask", "qp", *others),
                                default="dls")
    if method == "qp":
        return _qp_solver(s, path, obstacles)
    if method == "multitask":
        s.mapping(_MT_FIELDS | {"method"})
        kw: dict[str, Any] = {k: s[k].number(lo=0.0) for k in sorted(_MT_FIELDS - {"max_iter"})
                              if s[k].present}
        if s["max_iter"].present:
            kw["max_iter"] = s["max_iter"].integer(lo=1, hi=MAX_ITERATIONS)
        try:
            resolver = MultiTaskResolver(task=path.task, obstacles=obstacles, **kw)
        except (InputError, InputTypeError) as exc:
            raise s.fail(f"is invalid: {exc}") from exc
        return resolver, {}, kw.get("link_radius", 0.0)
    s.mapping(_DLS_FIELDS | {"method", "options"})
    options: dict[str, Any] = {k: s[k].number(lo=0.0, lo_open=True)
                               for k in ("damping", "tol", "max_step", "max_joint_step")
                               if s[k].present}
    if s["max_iter"].present:
        options["max_iter"] = s["max_iter"].integer(lo=1, hi=MAX_ITERATIONS)
    if method != "dls":
        options["ik_options"] = _ik_options(s["options"], method) if s["options"].present \
            else {}
    elif s["options"].present:
        raise s["options"].fail("is for IK methods; the 'dls' tracker has no options")
    return method, options, 0.0


def _qp_solver(s: Field, path: Path, obstacles: tuple) -> tuple[Any, dict[str, Any], float]:
    """The ``solver`` mapping of ``method: qp``: a :class:`~serialkin.diffik.QPResolver`."""
    from serialkin.diffik.resolver import QPResolver

    s.mapping(_QP_FIELDS | {"method"})
    kw: dict[str, Any] = {k: s[k].number(lo=0.0) for k in sorted(
        _QP_FIELDS - {"max_iter", "self_collision", "backend"}) if s[k].present}
    if s["max_iter"].present:
        kw["max_iter"] = s["max_iter"].integer(lo=1, hi=MAX_ITERATIONS)
    if s["self_collision"].present:
        if not isinstance(s["self_collision"].value, bool):
            raise s["self_collision"].expected("true or false")
        kw["self_collision"] = s["self_collision"].value
    if s["backend"].present:
        kw["solver"] = s["backend"].string(max_len=100)
    try:
        resolver = QPResolver(task=path.task, obstacles=obstacles, **kw)
    except (InputError, InputTypeError) as exc:
        raise s.fail(f"is invalid: {exc}") from exc
    return resolver, {}, kw.get("link_radius", 0.0)


def scenario_from_dict(data: object, source: str = "<dict>",
                       base_dir: str | os.PathLike[str] | None = None) -> Scenario:
    """Validate a scenario mapping and build a :class:`Scenario`.

    Every field is read with :class:`serialkin._files.Field` (type and range checked
    before use; the robot has at most :data:`MAX_LINKS` joints, the path at most
    :data:`MAX_PATH_POINTS` points, iteration budgets at most :data:`MAX_ITERATIONS`).

    Args:
        data: the mapping (as read from YAML/JSON).
        source: file name used in error messages.
        base_dir: folder for relative paths (URDF).

    Raises:
        ScenarioError: a missing, unknown or mistyped field (the message names the file
            and the field), negative weights, obstacles overlapping the base.
    """
    doc = Field(data, "", f"scenario {source!r}", ScenarioError)
    doc.mapping(_ROOT_FIELDS, ("robot", "path"))
    unit = _angle_unit(doc["units"])
    robot = robot_from_field(doc["robot"], FsPath(base_dir) if base_dir is not None else None,
                             unit)
    n = robot.n
    if doc["q0"].present and doc["q0_deg"].present:
        raise doc["q0"].fail("and 'q0_deg' are both given; use one")
    q0 = np.zeros(n)
    for key, scale in (("q0", ANGLE_UNITS[unit]), ("q0_deg", math.pi / 180)):
        qf = doc[key]
        if qf.present:
            a = qf.array(what=f"one number or a list of {n} numbers", scalar_ok=True,
                         lo=-1e6, hi=1e6)
            if a.ndim == 0:
                a = np.full(n, float(a))
            if a.shape != (n,):
                raise qf.fail(f"must have {n} values (one per joint), got shape {a.shape}")
            if key == "q0" and unit == "rad" and beyond_a_turn(a[robot.revolute]).any():
                raise qf.fail("has a revolute joint value beyond a full turn; q0 is in "
                              "radians (for degrees write q0_deg, or units: {angle: deg})")
            q0 = np.where(robot.revolute, a * scale, a)
    path = _path(doc["path"], robot, q0, unit)
    obs_f = doc["obstacles"]
    obstacles = tuple(obstacle_from_field(o) for o in obs_f.items(max_len=10_000)) \
        if obs_f.present else ()
    solver, options, link_radius = _solver(doc["solver"], path, obstacles)
    options = {**options, **_srdf_options(doc, base_dir)}
    tolerance = doc["tolerance"].number(lo=0.0, lo_open=True, default=5e-3, unit="m")
    on_unreach = doc["on_unreachable"].string(choices=ON_UNREACHABLE, default="continue")
    try:
        check_obstacles(robot, obstacles, link_radius=link_radius)
    except InputError as exc:
        raise ScenarioError(f"scenario {source!r}: field 'obstacles': {exc}") from exc
    name = doc["name"].string(default=FsPath(source).stem or "scenario", max_len=1000)
    description = doc["description"].string(default="", nonempty=False)
    return Scenario(name=name, description=description, robot=robot,
                    path=path, q0=q0, obstacles=obstacles, solver=solver, options=options,
                    tolerance=tolerance, on_unreachable=on_unreach, link_radius=link_radius,
                    source=source, data=dict(doc.value))


def _srdf_options(doc: Field, base_dir: str | os.PathLike[str] | None) -> dict[str, Any]:
    """``track``'s ``srdf`` and ``skip_links`` from the scenario's fields ({} when absent).

    ``srdf`` is a file path relative to the scenario's folder; it must exist (the file is
    read when the scenario is tracked, where a solver that checks no self-collision is
    refused). ``skip_links`` needs ``srdf``.
    """
    out: dict[str, Any] = {}
    sf, kf = doc["srdf"], doc["skip_links"]
    if sf.present:
        rel = FsPath(sf.string(max_len=4096))
        path = rel if rel.is_absolute() or base_dir is None else FsPath(base_dir) / rel
        if not path.is_file():
            raise sf.fail(f"must name an SRDF file (relative to the scenario's folder), got "
                          f"{short_repr(str(rel))}: {short_repr(str(path))} is not a file")
        out["srdf"] = str(path)
    if kf.present:
        if not sf.present:
            raise kf.fail("names links of an SRDF: give srdf too")
        out["skip_links"] = tuple(f.string(max_len=1000) for f in kf.items(max_len=10_000))
    return out


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
    if not isinstance(path_or_name, (str, os.PathLike)):
        raise InputTypeError("path_or_name must be a file path or a shipped scenario name, "
                             f"got {type(path_or_name).__name__} {short_repr(path_or_name)}")
    p = FsPath(path_or_name)
    if not p.exists():
        names = list_scenarios()
        if str(path_or_name) in names:
            for ext in (".yaml", ".yml", ".json"):
                res = _shipped_dir() / f"{path_or_name}{ext}"
                if res.is_file():
                    with resources.as_file(res) as real:
                        return load_scenario(real)
        raise InputError(f"no scenario file {short_repr(str(path_or_name))}; shipped scenarios: "
                         f"{', '.join(names)}")
    data = load_document(p, what="scenario", error=ScenarioError)
    return scenario_from_dict(data, source=p.name, base_dir=p.parent)
