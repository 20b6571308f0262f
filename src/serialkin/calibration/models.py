"""Error models: the geometric parameters a calibration may adjust, and their redundancies.

An error model writes the robot as an *extended chain* in which every parameter is the
value of a one-degree-of-freedom motion (a rotation about or a translation along a known
local axis)::

    T(q, p) = B0 · E_base(p) · Π_i [ joint i motions and parameter motions ] · T0 · E_tool(p)

so a parameter enters the chain exactly like a joint variable. The extended chain is an
ordinary :class:`~serialkin.Robot` (its *virtual joints* carry the parameters), and
``∂T/∂p_k`` is the geometric-Jacobian column of that virtual joint: the identification
Jacobian comes from the same compiled kernels as every other Jacobian
(:mod:`serialkin.kinematics.kernels`), exact at any parameter value, not linearised.

Models (:func:`error_model`):

* ``'dh'`` — the robot's own DH table. Standard DH link i:
  ``A_i = Rz(θ_i) · Tz(d_i) · Tx(a_i) · Rx(α_i) [· Ry(β_i)]``; modified (Craig):
  ``A_i = [Ry(β_{i-1}) ·] Rx(α_{i-1}) · Tx(a_{i-1}) · Rz(θ_i) · Tz(d_i)``. θ_i of a revolute
  joint is its joint-offset error. Hayati's β (Hayati & Mirmirani 1985) is added where
  consecutive joint axes are (nearly) parallel: there a tilt of the next axis about y
  moves the common normal far away (d jumps by a/tan(tilt)), so plain DH is singular;
  with β the link is described by θ, a, α, β and the d along the first of the two
  parallel axes (d_i standard, d_{i-1} modified) is left out (fixed at its nominal
  value): it would slide along the same direction as the next d.
* ``'joints'`` — any robot (URDF): each joint's origin gets a translation (x, y, z) and a
  rotation (rz, ry, rx) error, the axis is tilted by the rotations, and the joint offset
  is a parameter: the product-of-exponentials view of joint origin and axis errors.
  Seven parameters per joint where four (revolute) or two (prismatic) are identifiable:
  the analysis chooses a minimal set.
* base and tool — ``B = B0 · Txyz(x, y, z) · Rz · Ry · Rx`` (the robot-file xyz/rpy
  convention, as an error about the nominal B0; likewise the tool). The tool translation
  is the unknown marker offset of position measurements.
* several markers (``markers=K``) — markers 2..K at unknown offsets ``w_k`` (3,) [m] in
  the tool frame: marker k is at ``T(q, p) · w_k`` (marker 1 is the tool origin). These
  3(K−1) parameters are not virtual joints: their Jacobian is the tool rotation, and the
  chain's columns are moved to the marker point (``v + ω × R w_k``).

Non-geometric terms. A parameter's virtual joint moves by ``p_k · g_k(q)``: its
*regressor* ``g_k`` is 1 for a geometric error and the joint value ``q_i`` for an encoder
scale (``scale=True``: joint i turns by ``q_i + s_i q_i``, ``s_i`` the relative scale
error, a virtual joint on the same axis right after the real one), so
``∂T/∂p_k = g_k(q) · (the virtual joint's Jacobian column)``
(:meth:`ErrorModel.regressors`). A joint offset is the geometric θ_i / ``offset``
parameter. **Compliance** is the same construction with another regressor: a joint of
stiffness ``k_i`` under the gravity torque ``τ_i(q)`` deflects by ``c_i τ_i(q)``
(``c_i = 1/k_i`` [rad/(N·m)]), i.e. a parameter on joint i's axis with regressor
``τ_i(q)`` from a dynamic model (link masses and centres, and the payload). To add it:
a builder step like the scale's (:func:`_add_scale`) with ``regressor`` naming the term,
and its column in :meth:`ErrorModel.regressors`; the fit, the identifiability analysis,
the covariance and the pose selection then treat it like any other parameter.

Redundancies (the analysis in :mod:`serialkin.calibration.identifiability` finds them
numerically; typical ones): standard DH — d_1 with base z and θ_1 with base rz (both
along/about joint 1's axis), d_i with d_{i+1} across parallel axes; the last link's
θ_n, d_n, a_n, α_n with the tool; from positions only, the three tool rotations do not
move the measured point at all. A complete, minimal model has 4R + 2P + 6 parameters for
full poses (R revolute, P prismatic joints) and 3 fewer for positions.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from serialkin._checks import as_vector, check_choice, short_repr
from serialkin.errors import InputError, InputTypeError
from serialkin.model.dh import DHLink
from serialkin.model.joint import Joint
from serialkin.model.robot import Robot, check_robot
from serialkin.spatial.transforms import make_transform

#: Error model kinds (see the module docstring).
MODEL_KINDS = ("auto", "dh", "joints")
_AXES = {"x": (1.0, 0.0, 0.0), "y": (0.0, 1.0, 0.0), "z": (0.0, 0.0, 1.0)}
#: Consecutive axes closer to parallel than this angle get Hayati's β (``hayati='auto'``).
HAYATI_ANGLE = np.radians(10.0)


@dataclass(frozen=True)
class Parameter:
    """One calibration parameter.

    Attributes:
        name: its name in the user's terms ('d1', 'beta2', 'base z', 'tool rx',
            'shoulder origin x', 'elbow offset').
        unit: 'm' (a translation), 'rad' (a rotation) or '1' (a relative encoder scale
            error, dimensionless).
        nominal: its value in the nominal robot [m, rad or 1] (0 for base and tool errors
            and scales).
        group: 'base', 'tool', 'marker' or the index (0-based) of the joint it belongs to.
        regressor: the index of the joint whose value multiplies the parameter's motion
            (an encoder scale), or -1 (a constant: geometric errors).
    """

    name: str
    unit: str
    nominal: float
    group: str | int
    regressor: int = -1


@dataclass(frozen=True)
class _Step:
    """A step of the extended chain: a real joint (index) or a parameter (index)."""

    joint: int = -1
    param: int = -1


class ErrorModel:
    """A robot with some of its geometry as free parameters (see the module docstring).

    Build one with :func:`error_model`. It is immutable.

    Attributes:
        robot: the nominal robot.
        kind: 'dh' or 'joints'.
        parameters: tuple of :class:`Parameter`, in chain order (base first, tool last).
        hayati: indices (0-based) of the links that carry Hayati's β.
        extended: the extended chain as a :class:`~serialkin.Robot` (``n + p`` joints).
        joint_index: (n,) positions of the real joints among the extended chain's joints.
        param_index: (c,) positions of the chain parameters (the first c, all but the
            marker offsets) among the extended chain's joints.
        markers: number of markers K (markers 2..K have offset parameters, last).
    """

    def __init__(self, robot: Robot, kind: str, parameters: Sequence[Parameter],
                 steps: Sequence[tuple[_Step, Joint]], tool: np.ndarray,
                 hayati: Sequence[int], markers: int = 1) -> None:
        self.robot = robot
        self.kind = kind
        self.parameters = tuple(parameters)
        self.hayati = tuple(hayati)
        self.markers = int(markers)
        joints = [j for _, j in steps]
        self.extended = Robot.from_joints(joints, base=robot.base, tool=tool,
                                          name=f"{robot.name} (error model)")
        self.joint_index = np.array([k for k, (s, _) in enumerate(steps) if s.joint >= 0])
        self.param_index = np.array([k for k, (s, _) in enumerate(steps) if s.param >= 0])
        self._steps = tuple(steps)
        self._tool_rest = tool

    @property
    def names(self) -> tuple[str, ...]:
        """The parameter names."""
        return tuple(p.name for p in self.parameters)

    @property
    def nominal(self) -> np.ndarray:
        """(p,) nominal parameter values [m or rad]."""
        return np.array([p.nominal for p in self.parameters])

    @property
    def size(self) -> int:
        """Number of parameters p."""
        return len(self.parameters)

    def check_params(self, params: object, name: str = "params") -> np.ndarray:
        """``params`` as a finite float64 (p,) vector, or raise naming it."""
        return as_vector(params, name, self.size)

    @property
    def chain_size(self) -> int:
        """Number c of parameters that are virtual joints of the extended chain."""
        return len(self.param_index)

    @property
    def has_regressors(self) -> bool:
        """Whether some parameter has a regressor other than 1 (e.g. encoder scales)."""
        return any(p.regressor >= 0 for p in self.parameters)

    def regressors(self, q: np.ndarray) -> np.ndarray:
        """(m, c) regressors ``g_k(q)`` of the chain parameters at configurations q (m, n).

        The virtual joint of parameter k moves by ``p_k · g_k(q)`` (module docstring): 1
        for geometric errors, ``q_i`` for the encoder scale of joint i. This is the
        extension point of non-geometric terms: a compliance parameter of joint i would
        return the gravity torque ``τ_i(q)`` [N·m] here (and carry unit 'rad/(N·m)');
        :func:`~serialkin.calibration.jacobian.errors` multiplies the Jacobian column by
        it, so nothing else changes.
        """
        c = self.chain_size
        g = np.ones((q.shape[0], c))
        for k, par in enumerate(self.parameters[:c]):
            if par.regressor >= 0:
                g[:, k] = q[:, par.regressor]
        return g

    def extended_q(self, q: np.ndarray, params: np.ndarray) -> np.ndarray:
        """Joint values (m, n + c) of the extended chain at q (m, n) and params (p,).

        q in the real joints, ``p_k g_k(q)`` in the chain parameters' virtual joints (the
        marker offsets are not in the chain).
        """
        Q = np.empty((q.shape[0], self.extended.n))
        Q[:, self.joint_index] = q
        c = self.chain_size
        if self.has_regressors:
            Q[:, self.param_index] = params[:c] * self.regressors(q)
        else:
            Q[:, self.param_index] = params[:c]
        return Q

    def encoder_scale(self, params: object) -> np.ndarray:
        """(n,) factors ``1 + s_i`` of the joint values at parameters ``params`` (1 without)."""
        p = self.check_params(params)
        out = np.ones(self.robot.n)
        for k, par in enumerate(self.parameters):
            if par.regressor >= 0:
                out[par.regressor] += p[k]
        return out

    def marker_offsets(self, params: object) -> np.ndarray:
        """(K, 3) offsets [m] of the markers in the tool frame (marker 1: the origin, 0)."""
        p = self.check_params(params)
        out = np.zeros((self.markers, 3))
        out[1:] = p[self.chain_size:].reshape(-1, 3)
        return out

    def fk(self, q: object, params: object = None) -> np.ndarray:
        """Tool poses (m, 4, 4) of configurations ``q`` (m, n) with parameters ``params`` (p,).

        ``params`` None means the nominal values.
        """
        qa = self.robot.check_q(q).reshape(-1, self.robot.n)
        p = self.nominal if params is None else self.check_params(params)
        return self.extended.fk(self.extended_q(qa, p))

    def calibrated_robot(self, params: object, name: str | None = None) -> Robot:
        """The robot with parameter values ``params`` (p,), as a :class:`~serialkin.Robot`.

        Encoder scales and marker offsets are not part of a robot
        (:meth:`encoder_scale`, :meth:`marker_offsets`): the robot is the geometry, to be
        driven with the joint values times the scales, its tool at marker 1.
        A DH model without β gives a DH robot (the same convention, base and tool updated),
        which a robot file can hold; otherwise a robot of general joints (each joint's
        origin is the product of the fixed and parameter motions before it), which a URDF
        holds. Joint names and limits are the nominal robot's; the DH robot keeps the
        nominal collision model (its link frames are the same DH frames), a robot of general
        joints has none (its link frames sit on the joint axes).
        """
        p = self.check_params(params)
        nm = self.robot.name if name is None else name
        source = f"calibrated from {self.robot.name}"
        base = self.robot.base @ self._group_product(p, "base")
        tool = self._group_product(p, "tool") @ self._tool_rest
        if self.kind == "dh" and not self.hayati:
            values = dict(zip(self.names, p))
            rows = []
            for i, r in enumerate(self.robot.dh):
                k = i + 1
                rows.append(dataclasses.replace(
                    r, a=float(values[f"a{k}"]), alpha=float(values[f"alpha{k}"]),
                    d=float(values[f"d{k}"]), theta=float(values[f"theta{k}"])))
            out = Robot.from_dh(rows, self.robot.convention, base=base, tool=tool, name=nm,
                                source=source)
            # the DH frames are the nominal ones, moved by the errors: the capsules follow
            return out.with_collision(self.robot.collision)
        joints: list[Joint] = []
        pending = np.eye(4)
        for step, j in self._steps:
            if step.param >= 0 and (self.parameters[step.param].group in ("base", "tool")
                                    or self.parameters[step.param].regressor >= 0):
                continue  # a scale's motion commutes with its joint's: the joint values
            if step.joint >= 0:
                nominal = self.robot.joints[step.joint]
                joints.append(Joint(axis=j.axis, type=j.type, origin=pending @ j.origin,
                                    post=np.eye(4), offset=0.0, qlim=nominal.qlim,
                                    name=self.robot.joint_names[step.joint]))
                pending = j.post.copy()
            else:
                pending = pending @ j.origin @ _motion(j, p[step.param]) @ j.post
        # what follows the last real joint (before the tool errors) joins the tool
        return Robot.from_joints(joints, base=base, tool=pending @ tool, name=nm,
                                 source=source)

    def _group_product(self, p: np.ndarray, group: str) -> np.ndarray:
        """The product of the base (or tool) steps at parameter values ``p`` (4, 4).

        The first tool step carries the fixed transform before the tool errors (the
        nominal tool), so the product is ``T0 · E_tool(p)``; without tool errors the
        nominal tool is in the extended chain's tool instead.
        """
        T = np.eye(4)
        for step, j in self._steps:
            if step.param >= 0 and self.parameters[step.param].group == group:
                T = T @ j.origin @ _motion(j, p[step.param]) @ j.post
        return T

    def __repr__(self) -> str:
        extra = f", hayati={[i + 1 for i in self.hayati]}" if self.hayati else ""
        return f"ErrorModel({self.robot.name!r}, {self.kind}, {self.size} parameters{extra})"


def _motion(j: Joint, value: float) -> np.ndarray:
    """The motion (4, 4) of a parameter's virtual joint by ``value`` about/along its unit axis."""
    from serialkin.spatial.rotations import axis_angle_to_matrix

    if j.type == "P":
        return make_transform(p=j.axis * value)
    return make_transform(axis_angle_to_matrix(j.axis, value))


class _Builder:
    """Accumulates the extended chain: fixed transforms, real joints, parameter motions."""

    def __init__(self) -> None:
        self.steps: list[tuple[_Step, Joint]] = []
        self.params: list[Parameter] = []
        self.pending = np.eye(4)

    def fixed(self, T: np.ndarray) -> None:
        self.pending = self.pending @ T

    def param(self, name: str, axis: str | np.ndarray, kind: str, nominal: float,
              group: str | int, regressor: int = -1) -> None:
        ax = np.array(_AXES[axis]) if isinstance(axis, str) else axis
        unit = "1" if regressor >= 0 else "m" if kind == "P" else "rad"
        self.params.append(Parameter(name=name, unit=unit, nominal=float(nominal), group=group,
                                     regressor=regressor))
        self.steps.append((_Step(param=len(self.params) - 1),
                           Joint(axis=ax, type=kind, origin=self.pending, name=name)))
        self.pending = np.eye(4)

    def joint(self, index: int, axis: np.ndarray, kind: str, name: str) -> None:
        self.steps.append((_Step(joint=index),
                           Joint(axis=axis, type=kind, origin=self.pending, name=name)))
        self.pending = np.eye(4)

    def pose_errors(self, group: str) -> None:
        for name, axis, kind in (("x", "x", "P"), ("y", "y", "P"), ("z", "z", "P"),
                                 ("rz", "z", "R"), ("ry", "y", "R"), ("rx", "x", "R")):
            self.param(f"{group} {name}", axis, kind, 0.0, group)


def _parallel_links(robot: Robot, angle: float) -> list[int]:
    """DH links i whose axes z_{i-1}, z_i are within ``angle`` of parallel (0-based i)."""
    out = []
    for i, r in enumerate(robot.dh):
        if robot.convention == "standard":
            alpha = r.alpha
        else:
            if i == 0:
                continue
            alpha = r.alpha  # α_{i-1} between axes i-1 and i
        if abs(np.sin(alpha)) < np.sin(angle):
            if robot.convention == "standard" and i == robot.n - 1:
                continue  # the last frame's x is free: the tool errors cover it
            out.append(i)
    return out


def _hayati_links(robot: Robot, hayati: object) -> list[int]:
    if isinstance(hayati, str):
        check_choice(hayati, "hayati", ("auto", "none"))
        return _parallel_links(robot, HAYATI_ANGLE) if hayati == "auto" else []
    if isinstance(hayati, bool):
        return _parallel_links(robot, HAYATI_ANGLE) if hayati else []
    try:
        links = sorted({int(k) for k in hayati})  # type: ignore[union-attr]
    except (TypeError, ValueError):
        raise InputTypeError(f"hayati must be 'auto', 'none' or a list of link numbers "
                             f"(1..n), got {short_repr(hayati)}") from None
    bad = [k for k in links if not 1 <= k <= robot.n]
    if bad:
        raise InputError(f"hayati has link number(s) {bad} outside 1..{robot.n}")
    return [k - 1 for k in links]


def error_model(robot: Robot, kind: str = "auto", *, hayati: object = "auto",
                base: bool = True, tool: bool = True, scale: bool = False,
                markers: int = 1) -> ErrorModel:
    """The error model of ``robot`` (see the module docstring for the equations).

    Args:
        robot: the nominal robot.
        kind: 'dh' (the robot's DH table, standard or modified), 'joints' (joint origin,
            axis and offset errors; any robot) or 'auto' ('dh' when the robot has a DH
            table, else 'joints').
        hayati: for 'dh': 'auto' (β on links whose consecutive axes are within
            :data:`HAYATI_ANGLE` of parallel), 'none', or a list of link numbers (1..n).
        base: include the six base-pose errors.
        tool: include the six tool-pose errors (the tool translation is the marker offset
            of position measurements).
        scale: include each joint's encoder scale error ``s_i`` (joint i moves by
            ``(1 + s_i) q_i``; module docstring).
        markers: number K of markers measured (``Measurements.markers`` says which); the
            offsets of markers 2..K from the tool origin are parameters (3 each).

    Returns:
        :class:`ErrorModel`.

    Raises:
        InputError: unknown kind; 'dh' for a robot without a DH table; a bad hayati list.
    """
    from serialkin._checks import check_int

    check_robot(robot)
    check_choice(kind, "kind", MODEL_KINDS)
    markers = check_int(markers, "markers", minimum=1)
    if kind == "auto":
        kind = "dh" if robot.dh is not None else "joints"
    if kind == "dh" and robot.dh is None:
        raise InputError(f"kind='dh' needs a robot with a DH table; robot {robot.name!r} "
                         "has general joints (use kind='joints')")
    b = _Builder()
    if base:
        b.pose_errors("base")
    links: list[int] = []
    if kind == "dh":
        links = _hayati_links(robot, hayati)
        _dh_chain(b, robot, links, scale)
    else:
        _joint_chain(b, robot, scale)
    b.fixed(robot.tool)
    if tool:
        b.pose_errors("tool")
    for k in range(2, markers + 1):  # not virtual joints: after the chain's parameters
        for axis in "xyz":
            b.params.append(Parameter(name=f"marker {k} {axis}", unit="m", nominal=0.0,
                                      group="marker"))
    return ErrorModel(robot, kind, b.params, b.steps, b.pending, links, markers)


def _add_scale(b: _Builder, i: int, axis: np.ndarray, kind: str, name: str) -> None:
    """Joint i's encoder scale: a virtual joint on its axis right after it, moving ``s q_i``."""
    b.param(name, axis, kind, 0.0, i, regressor=i)


def _joint_and_offset(b: _Builder, i: int, r: DHLink, name: str, scale: bool) -> None:
    """Joint i about z (its scale) and its θ offset, in the order the chain applies them.

    A revolute joint turns by ``q + s q + θ``: the joint, its scale, then the offset θ_i;
    a prismatic one turns by θ_i first, then slides (and slides by its scale).
    """
    z = np.array(_AXES["z"])
    if r.type == "R":
        b.joint(i, z, "R", name)
        if scale:
            _add_scale(b, i, z, "R", f"scale{i + 1}")
        b.param(f"theta{i + 1}", "z", "R", r.theta, i)
    else:
        b.param(f"theta{i + 1}", "z", "R", r.theta, i)
        b.joint(i, z, "P", name)
        if scale:
            _add_scale(b, i, z, "P", f"scale{i + 1}")


def _dh_chain(b: _Builder, robot: Robot, hayati: Sequence[int], scale: bool) -> None:
    for i, r in enumerate(robot.dh):
        k, name = i + 1, robot.joint_names[i]
        if robot.convention == "standard":
            _joint_and_offset(b, i, r, name, scale)
            if i in hayati:  # d_i slides along an axis parallel to the next: fixed
                b.fixed(make_transform(p=[0.0, 0.0, r.d]))
            else:
                b.param(f"d{k}", "z", "P", r.d, i)
            b.param(f"a{k}", "x", "P", r.a, i)
            b.param(f"alpha{k}", "x", "R", r.alpha, i)
            if i in hayati:
                b.param(f"beta{k}", "y", "R", 0.0, i)
        else:
            if i in hayati:
                b.param(f"beta{k}", "y", "R", 0.0, i)
            b.param(f"alpha{k}", "x", "R", r.alpha, i)
            b.param(f"a{k}", "x", "P", r.a, i)
            _joint_and_offset(b, i, r, name, scale)
            if i + 1 in hayati:  # joint i+1 is parallel to this one: d_i is fixed
                b.fixed(make_transform(p=[0.0, 0.0, r.d]))
            else:
                b.param(f"d{k}", "z", "P", r.d, i)


def _joint_chain(b: _Builder, robot: Robot, scale: bool) -> None:
    for i, j in enumerate(robot.joints):
        name = robot.joint_names[i]
        b.fixed(j.origin)
        for label, axis, kind in (("x", "x", "P"), ("y", "y", "P"), ("z", "z", "P"),
                                  ("rz", "z", "R"), ("ry", "y", "R"), ("rx", "x", "R")):
            b.param(f"{name} origin {label}", axis, kind, 0.0, i)
        b.joint(i, j.axis, j.type, name)
        if scale:
            _add_scale(b, i, j.axis.copy(), j.type, f"{name} scale")
        b.param(f"{name} offset", j.axis.copy(), j.type, j.offset, i)
        b.fixed(j.post)
