"""The :class:`Robot`: a serial chain of revolute and prismatic joints (section 3).

A robot is immutable. However it was described (standard or modified DH table, general
joint axes, URDF), it holds one compiled :class:`~serialkin.model.chain.Chain` that the
kernels of :mod:`serialkin.kinematics` evaluate.

Conventions: joint vectors ``q`` have shape (..., n) [rad for revolute, m for prismatic];
poses are 4x4 homogeneous transforms of the end-effector (tool) in the world frame
(``T_world_ee``, base transform included); twists and Jacobian rows are ordered
``[vx, vy, vz, wx, wy, wz]``.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Mapping, Sequence
from typing import TYPE_CHECKING, Any

import numpy as np

from serialkin._budget import check_allocation
from serialkin._checks import (
    MAX_JOINTS,
    as_float_array,
    as_generator,
    check_choice,
    check_int,
    check_positive,
    readonly,
    short_repr,
)
from serialkin._memo import PerObject
from serialkin.errors import InputError, InputTypeError, RobotDefinitionError
from serialkin.kinematics import kernels as K
from serialkin.kinematics import parallel
from serialkin.kinematics.dls import manipulability_batch
from serialkin.model.chain import compile_chain
from serialkin.model.dh import CONVENTIONS, DHLink, dh_to_joints, parse_dh_rows
from serialkin.model.joint import Joint, check_fixed_transform
from serialkin.model.limits import (
    DEFAULT_HALF_RANGE,
    inside_mask,
    limits_table,
    rate_limits,
    sampling_box,
)
from serialkin.model.tasks import TASKS, task_rows

if TYPE_CHECKING:
    from serialkin.ik.analytic import AllSolutions
    from serialkin.ik.result import IKResult
    from serialkin.model.geometry import LinkGeometry

_F64 = np.dtype(np.float64)
_NDARRAY = np.ndarray
_EMPTY = np.empty
#: Entry points of the single-call kernels, each resolved on first use by :func:`_resolve`.
_FK1: Any = None
_JAC1: Any = None
_HESS1: Any = None
_JDOT1: Any = None


def _resolve(name: str) -> Any:
    """The single-call kernel ``name``, compiled (or loaded from numba's cache) on first use.

    ``name`` is one of ``_FK1`` (``fk_one``), ``_JAC1`` (``jacobian_one``), ``_HESS1``
    (``hessian_one``), ``_JDOT1`` (``jacobian_dot_one``); the entry point is stored in that
    module global and returned. Each is resolved on its own, so a first ``fk`` compiles
    only ``fk_one``. Calling an entry point skips numba's per-call type dispatch
    (0.2-2 µs). They are compiled for ``q`` (and ``qd``) 1-D float64 arrays of any layout,
    ``P`` the read-only packed chain, a bool frame flag and a C-contiguous float64 output.
    An entry point does NOT check the dtype or the number of dimensions of an array (an
    int64 q would be read as float64): the fast paths check both before calling.
    ``fk_one``/``jacobian_one`` check the length and finiteness themselves and return a
    nonzero code: the fast paths then take the general one, which raises the library's
    error.
    """
    from serialkin._jit import entry_point

    def sig() -> tuple:  # numba's types, imported only when the kernel is loaded
        import numba

        f64, Array = numba.float64, numba.types.Array
        vec, P = Array(f64, 1, "A"), Array(f64, 3, "C", readonly=True)
        flag = numba.types.boolean
        return {
            "_FK1": (vec, P, Array(f64, 2, "C")),
            "_JAC1": (vec, P, Array(f64, 2, "C")),
            "_HESS1": (vec, P, flag, Array(f64, 3, "C")),
            "_JDOT1": (vec, P, vec, flag, Array(f64, 2, "C")),
        }[name]

    dispatcher = {"_FK1": K.fk_one, "_JAC1": K.jacobian_one, "_HESS1": K.hessian_one,
                  "_JDOT1": K.jacobian_dot_one}[name]
    found, final = entry_point(dispatcher, sig)
    if final:  # else the Python function while it compiles: ask again next call
        globals()[name] = found
    return found


_SOLVE: Any = None
_FAST_IK: Any = None


_PROVIDED: dict[str, Any] = {}


def provide(name: str, function: Any) -> None:
    """Register ``function`` as what :class:`Robot`'s method ``name`` calls.

    ``Robot.ik``, ``ik_all``, ``fit_collision``, ``from_urdf``, ``from_mjcf``,
    ``from_xacro`` and ``to_urdf`` are conveniences over functions of the layers above
    ``model`` (``ik``, ``collision``, ``formats``). The model layer imports nothing above
    it: each of those packages registers its functions here when it is imported
    (``serialkin/ik/__init__.py``, ``serialkin/collision/__init__.py``,
    ``serialkin/formats/__init__.py``), and importing any ``serialkin`` module imports
    them all. Names: ``"ik"`` (:func:`serialkin.ik.solve`), ``"ik_fast"`` (its fast
    path), ``"ik_all"``, ``"fit_collision"``, ``"from_urdf"``, ``"from_mjcf"``,
    ``"from_xacro"``, ``"to_urdf"`` (the readers and the writer of
    :mod:`serialkin.formats`).
    """
    global _SOLVE, _FAST_IK
    _PROVIDED[name] = function
    if name == "ik":
        _SOLVE = function
    elif name == "ik_fast":
        _FAST_IK = function


def _provided(name: str) -> Any:
    """The function registered for ``name`` (:func:`provide`)."""
    function = _PROVIDED.get(name)
    if function is None:  # only while serialkin itself is still being imported
        raise RuntimeError(f"Robot.{name.removesuffix('_fast')} is provided by a serialkin "
                           "package not imported yet: import serialkin first")
    return function


def _immutable(name: str, action: str) -> str:
    """The message of an attempt to change a built robot's attribute ``name``."""
    return (f"Robot is immutable: cannot {action} {name!r}; make a changed copy instead "
            "(with_tool, with_base, with_limits, with_collision, or Robot(...) with the "
            "changed parts)")


#: Robot.is_planar per robot (computed once, kept beside the robot, not written onto it).
_PLANAR: PerObject[bool] = PerObject()


def _out_array(out: object, shape: tuple[int, ...]) -> np.ndarray:
    """``out`` when it is a writeable C-contiguous float64 array of ``shape``, else raise."""
    if not (type(out) is np.ndarray and out.dtype is _F64 and out.shape == shape
            and out.flags.c_contiguous and out.flags.writeable):
        got = (f"{type(out).__name__}" if not isinstance(out, np.ndarray) else
               f"{out.dtype} array of shape {out.shape}"
               f"{'' if out.flags.c_contiguous else ', not C-contiguous'}"
               f"{'' if out.flags.writeable else ', read-only'}")
        raise InputError(f"out must be a writeable C-contiguous float64 array of shape "
                         f"{shape}, got {got}")
    return out


#: Named task-row selections for manipulability and condition number, by name and alias
#: (a view of :data:`serialkin.model.tasks.TASKS`, the one task table).
TASK_ROWS: dict[str, tuple[int, ...]] = {name: t.rows for name, t in TASKS.items()}


class Robot:
    """A serial manipulator with ``n`` joints.

    Build one with :meth:`from_dh`, :meth:`from_joints`, :meth:`from_urdf` or take one
    from :mod:`serialkin.models`.

    Attributes:
        name: the robot's name.
        n: number of joints (degrees of freedom).
        joints: tuple of :class:`~serialkin.model.joint.Joint` in general form.
        dh: tuple of :class:`~serialkin.model.dh.DHLink` when built from a DH table, else None.
        convention: 'standard' or 'modified' for DH robots, else None.
        base: (4, 4) world-from-base transform.
        tool: (4, 4) last-link-from-tool transform.
        qlim: (n, 2) joint limits [rad or m], ±inf where unlimited.
        velocity_limits: (n,) read-only largest joint speeds [rad/s or m/s] (``inf`` for a
            joint whose limit is not stated), or None when the description states none.
            URDF ``<limit velocity>`` fills it; set with :meth:`with_rate_limits`.
        acceleration_limits: (n,) largest joint accelerations [rad/s² or m/s²] likewise,
            or None. URDF and MJCF have no standard place for them (MoveIt keeps them in
            ``joint_limits.yaml``): they come from the zoo's data sheets or
            :meth:`with_rate_limits`.
        revolute: (n,) read-only bool array, True for a revolute joint, False for a
            prismatic one (``joint_types`` holds the same as 'R'/'P').
        chain: the compiled chain arrays (:class:`~serialkin.model.chain.Chain`: ``F``,
            ``L``, ``meta``, ``packed``) that compiled kernels of other subpackages take.
        collision: the robot's :class:`~serialkin.model.collision_model.CollisionModel`
            (capsules and spheres per link frame) or None; set with :meth:`with_collision`.
    """

    def __init__(
        self,
        joints: Sequence[Joint],
        *,
        base: object = None,
        tool: object = None,
        name: str = "robot",
        dh: Sequence[DHLink] | None = None,
        convention: str | None = None,
        source: str = "",
        link_names: Sequence[str] | None = None,
        geometry: Sequence[LinkGeometry] = (),
        collision: object = None,
        velocity_limits: object = None,
        acceleration_limits: object = None,
    ) -> None:
        if isinstance(joints, (str, bytes, Mapping)) or not isinstance(joints, Sequence):
            raise RobotDefinitionError(
                f"joints must be a list of Joint, got {type(joints).__name__} "
                f"{short_repr(joints)}")
        if len(joints) == 0:
            raise RobotDefinitionError("a robot needs at least one joint")
        if len(joints) > MAX_JOINTS:
            raise RobotDefinitionError(
                f"a robot has at most {MAX_JOINTS} joints, got {len(joints)}")
        for i, j in enumerate(joints):
            if not isinstance(j, Joint):
                raise RobotDefinitionError(f"joints[{i}] must be a Joint, got {type(j).__name__}")
        if not isinstance(name, str):
            raise RobotDefinitionError(
                f"robot name must be a string, got {type(name).__name__} {short_repr(name)}")
        self.name = name
        self.joints = tuple(joints)
        self.n = len(joints)
        self.base = np.eye(4) if base is None else check_fixed_transform(base, "base")
        self.tool = np.eye(4) if tool is None else check_fixed_transform(tool, "tool")
        self.dh = tuple(dh) if dh is not None else None
        self.convention = convention
        self.source = source
        #: link names (base..tip) when known, e.g. from a URDF; else None.
        self.link_names: tuple[str, ...] | None = \
            None if link_names is None else tuple(link_names)
        #: visual and collision shapes per link (:mod:`serialkin.model.geometry`)
        self.geometry: tuple[LinkGeometry, ...] = tuple(geometry)
        #: capsule/sphere collision model (:mod:`serialkin.collision`), or None
        self.collision: Any = None if collision is None else self._checked_collision(collision)
        self.qlim = np.array([j.qlim for j in joints], dtype=float)
        self.velocity_limits = rate_limits(velocity_limits, self.n, "velocity_limits")
        self.acceleration_limits = rate_limits(acceleration_limits, self.n,
                                               "acceleration_limits")
        self.joint_types = tuple(j.type for j in joints)
        self.revolute = np.array([t == "R" for t in self.joint_types], dtype=bool)
        self.joint_names = tuple(j.name or f"joint{i + 1}" for i, j in enumerate(joints))
        if len(set(self.joint_names)) != self.n:
            raise RobotDefinitionError(f"joint names must be unique, got {self.joint_names}")
        for a in (self.base, self.tool, self.qlim, self.revolute):
            a.setflags(write=False)
        self.chain = compile_chain(self.joints, self.base, self.tool)
        self._F, self._L, self._meta = self.chain.F, self.chain.L, self.chain.meta
        self._P = self.chain.packed
        self._qshape = (self.n,)
        self._jshape = (6, self.n)
        self._frozen = True

    def __setattr__(self, name: str, value: Any) -> None:
        """A built robot is immutable: setting an attribute raises AttributeError.

        Everything is given to the constructor (``link_names``, ``geometry``,
        ``collision`` included) or changed by a copy (:meth:`with_tool`,
        :meth:`with_base`, :meth:`with_limits`, :meth:`with_rate_limits`,
        :meth:`with_collision`).
        """
        if getattr(self, "_frozen", False):
            raise AttributeError(_immutable(name, "set"))
        object.__setattr__(self, name, value)

    def __delattr__(self, name: str) -> None:
        """A built robot is immutable: deleting an attribute raises AttributeError."""
        if getattr(self, "_frozen", False):
            raise AttributeError(_immutable(name, "delete"))
        object.__delattr__(self, name)

    def __setstate__(self, state: dict[str, Any]) -> None:
        """Unpickling restores a built (immutable) robot, its arrays read-only again.

        numpy's pickles restore arrays writeable; read-only ones keep the kernels compiled
        for one argument type (the chain's arrays are restored by ``Chain``).
        """
        self.__dict__.update(state)
        state.setdefault("velocity_limits", None)      # pickled before the rate limits
        state.setdefault("acceleration_limits", None)
        for key in ("base", "tool", "qlim", "revolute", "velocity_limits",
                    "acceleration_limits"):
            a = state.get(key)
            if isinstance(a, np.ndarray):
                a.setflags(write=False)

    # ------------------------------------------------------------------ constructors
    @classmethod
    def from_dh(
        cls,
        links: Sequence[DHLink | Mapping[str, Any]],
        convention: str = "standard",
        *,
        base: object = None,
        tool: object = None,
        name: str = "robot",
        source: str = "",
    ) -> Robot:
        """Build a robot from a DH table (section 3.2).

        Args:
            links: rows as :class:`DHLink` or mappings with fields ``a, alpha, d, theta``
                and optional ``type`` ('R'/'P'), ``qlim`` (lower, upper), ``name``.
            convention: 'standard' (A = Rz(θ)Tz(d)Tx(a)Rx(α), the chapter's) or
                'modified' (Craig: A = Rx(α)Tx(a)Rz(θ)Tz(d)).
            base: (4, 4) world-from-base transform.
            tool: (4, 4) transform from the last DH frame to the tool.
            name: robot name.
            source: where the parameters come from (shown by ``serialkin models``).

        Raises:
            RobotDefinitionError: missing/unknown field, unknown joint type, lower > upper.
            InputError: unknown convention, base/tool not rigid transforms.
        """
        check_choice(convention, "convention", CONVENTIONS)
        rows = parse_dh_rows(links)
        joints = dh_to_joints(rows, convention)
        return cls(joints, base=base, tool=tool, name=name, dh=rows, convention=convention,
                   source=source)

    @classmethod
    def from_joints(
        cls,
        joints: Sequence[Joint],
        *,
        base: object = None,
        tool: object = None,
        name: str = "robot",
        source: str = "",
    ) -> Robot:
        """Build a robot from joints in general form (fixed transform + axis), as URDF does."""
        return cls(joints, base=base, tool=tool, name=name, source=source)

    @classmethod
    def from_urdf(cls, path_or_string: str, base_link: str | None = None,
                  tip_link: str | None = None, *, package_map: Any = None,
                  search_path: Any = (), resolve_meshes: bool = False) -> Robot:
        """Build a robot from a URDF file or string (see :mod:`serialkin.formats.urdf`).

        ``package_map``, ``search_path`` and ``resolve_meshes`` locate the mesh files of
        the links' geometry, as in :func:`~serialkin.formats.urdf.robot_from_urdf`.
        """
        return _provided("from_urdf")(
            path_or_string, base_link=base_link, tip_link=tip_link, package_map=package_map,
            search_path=search_path, resolve_meshes=resolve_meshes)

    @classmethod
    def from_mjcf(cls, path_or_string: str, base_body: str | None = None,
                  end_body: str | None = None, *, tool_site: str | None = None,
                  resolve_meshes: bool = False) -> Robot:
        """Build a robot from a MuJoCo MJCF file or string (see :mod:`serialkin.formats.mjcf`).

        The chain runs from ``base_body`` (default: the world) to ``end_body`` (default:
        the end of the unbranched chain); ``tool_site`` names a site used as the tool.
        ``q`` is MuJoCo's ``qpos`` of the chain's hinge and slide joints.
        """
        return _provided("from_mjcf")(
            path_or_string, base_body=base_body, end_body=end_body, tool_site=tool_site,
            resolve_meshes=resolve_meshes)

    @classmethod
    def from_xacro(cls, path: str, base_link: str | None = None, tip_link: str | None = None,
                   *, mappings: Mapping[str, str] | None = None, package_map: Any = None,
                   search_path: Any = (), resolve_meshes: bool = False) -> Robot:
        """Build a robot from a xacro file (needs ``pip install "serialkin[xacro]"``).

        The file is expanded by the ROS ``xacro`` processor with ``mappings`` as its
        ``<xacro:arg>`` values, ``$(find pkg)`` resolved through ``package_map`` and
        ``search_path``, then read as URDF (see :mod:`serialkin.formats.xacro`).
        """
        return _provided("from_xacro")(
            path, base_link=base_link, tip_link=tip_link, mappings=mappings,
            package_map=package_map, search_path=search_path, resolve_meshes=resolve_meshes)

    def to_urdf(self) -> str:
        """Return the robot's kinematics as a URDF string (see :mod:`serialkin.formats.urdf`)."""
        return _provided("to_urdf")(self)

    def _copy(self, **changes: Any) -> Robot:
        """A new robot with some constructor arguments changed (the others kept)."""
        args: dict[str, Any] = dict(joints=self.joints, base=self.base, tool=self.tool,
                                    name=self.name, dh=self.dh, convention=self.convention,
                                    source=self.source)
        args.update(link_names=self.link_names, geometry=self.geometry,
                    collision=self.collision, velocity_limits=self.velocity_limits,
                    acceleration_limits=self.acceleration_limits)
        args.update(changes)
        return Robot(args.pop("joints"), **args)

    def with_collision(self, model: object) -> Robot:
        """A copy of this robot carrying ``model`` as its collision model (None removes it).

        Args:
            model: a :class:`~serialkin.model.collision_model.CollisionModel` whose body
                frames are frames of this robot (0..n), or None.

        Raises:
            InputTypeError: ``model`` is neither a CollisionModel nor None.
            InputError: a body is fixed to a frame this robot does not have.
        """
        return self._copy(collision=model)

    def _checked_collision(self, model: object) -> Any:
        """``model`` if it is a CollisionModel on this robot's frames (see with_collision)."""
        from serialkin.model.collision_model import CollisionModel

        if not isinstance(model, CollisionModel):
            raise InputTypeError(f"model must be a CollisionModel or None, got "
                                 f"{type(model).__name__} {short_repr(model)}")
        frames = np.asarray(model.body_frames)
        if frames.size and int(frames.max()) > self.n:
            i = int(np.argmax(frames > self.n))
            raise InputError(f"model body {model.body_names[i]!r} is fixed to frame "
                             f"{int(frames[i])} but robot {self.name!r} has frames 0..{self.n}")
        return model

    def fit_collision(self, kind: str = "collision", *, max_capsules: int = 3,
                      loose: float = 1.5, gain: float = 0.8,
                      merge: bool = False) -> tuple[Robot, Any]:
        """A copy carrying capsules fitted to its link geometry, and the fit report.

        Bounding capsules of each link's ``kind`` shapes (meshes, boxes, cylinders;
        spheres and capsules as they are), see
        :func:`~serialkin.collision.fit.collision_model_from_geometry`; meshes need the
        ``serialkin[mesh]`` extra. ``merge=True`` fits one cloud per link instead of
        one per shape.

        Returns:
            ``(robot, report)``: the robot with its :attr:`collision` model set, and the
            :class:`~serialkin.collision.fit.FitReport` (volume ratio and largest gap of
            every shape).

        Raises:
            InputError: the robot has no geometry of that kind.
            RobotDefinitionError: a mesh file is missing or corrupt.
        """
        model, report = _provided("fit_collision")(
            self, kind, max_capsules=max_capsules, loose=loose, gain=gain, merge=merge)
        return self.with_collision(model), report

    def clearance(self, q: object, scene: object = None, **options: Any) -> Any:
        """Smallest signed distance [m] to itself and to ``scene``, with the pair named.

        Uses :attr:`collision`; ``options``: ``acm``, ``srdf`` (its disabled pairs are
        added), ``skip_links``, ``self_collision`` — see
        :func:`serialkin.collision.checks.clearance`, which returns a
        :class:`~serialkin.collision.checks.NamedClearance` of shape (...,) for
        ``q`` (..., n).

        Raises:
            InputError: the robot has no collision model.
        """
        return _provided("clearance")(self, q, scene, **options)

    def in_collision(self, q: object, scene: object = None, **options: Any) -> Any:
        """(...,) bool: :meth:`clearance` below ``margin`` (default 0 m: shapes overlap).

        ``options`` as for :meth:`clearance`, and ``margin`` [m].
        """
        return _provided("in_collision")(self, q, scene, **options)

    def with_tool(self, tool: object) -> Robot:
        """A copy of this robot with another tool transform (4, 4)."""
        return self._copy(tool=tool)

    def with_base(self, base: object) -> Robot:
        """A copy of this robot with another base transform (4, 4)."""
        return self._copy(base=base)

    def with_limits(self, qlim: object) -> Robot:
        """A copy of this robot with other joint limits [rad or m], ±inf for an open side.

        Args:
            qlim: an (n, 2) table, or one (lower, upper) pair for every joint.
        """
        lim = limits_table(qlim, self.n)
        rows = [(float(lo), float(hi)) for lo, hi in lim]
        joints = [dataclasses.replace(j, qlim=rows[i]) for i, j in enumerate(self.joints)]
        dh = None if self.dh is None else [
            dataclasses.replace(r, qlim=rows[i]) for i, r in enumerate(self.dh)]
        return self._copy(joints=joints, dh=dh)

    def with_rate_limits(self, velocity: object = None,
                         acceleration: object = None) -> Robot:
        """A copy of this robot with joint velocity and acceleration limits.

        Args:
            velocity: (n,) or one largest joint speed [rad/s or m/s], ``inf`` where not
                stated; None removes them.
            acceleration: (n,) or one largest joint acceleration [rad/s² or m/s²]
                likewise; None removes them.

        Raises:
            RobotDefinitionError: a limit that is not positive, or the wrong count.
        """
        return self._copy(velocity_limits=velocity, acceleration_limits=acceleration)

    # ------------------------------------------------------------------ validation
    def check_q(self, q: object, name: str = "q", *, finite: bool = True) -> np.ndarray:
        """Return ``q`` as a finite float64 array of shape (..., n), or raise naming it.

        ``finite=False`` skips the finiteness test, for a caller whose kernel tests
        while it reads (the FK batch); it calls ``check_q`` again to raise.
        """
        a = as_float_array(q, name, finite=finite)
        if a.ndim == 0 or a.shape[-1] != self.n:
            got = f"{a.shape[-1]} values" if a.ndim else "a scalar"
            raise InputError(
                f"{name} has {got} but robot {self.name!r} has {self.n} joints "
                f"(expected shape (..., {self.n}), got {a.shape})"
            )
        return a

    def _nonfinite(self, q: np.ndarray, name: str = "q") -> InputError:
        return InputError(f"{name} must be finite, got {short_repr(q.tolist())}")

    @property
    def is_planar(self) -> bool:
        """True when the tool moves in the world xy plane only (rows vz, wx, wy of J vanish).

        Computed once per robot (robots are immutable) and kept beside it, not on it
        (:class:`serialkin._memo.PerObject`); every IK call reads it.
        """
        planar = _PLANAR.get(self)
        if planar is None:
            J = self.jacobian(self.random_q(3, seed=0))
            planar = _PLANAR.set(self, bool(np.allclose(J[:, [2, 3, 4]], 0.0, atol=1e-9)))
        return planar

    # ------------------------------------------------------------------ kinematics
    def fk(self, q: object, *, out: np.ndarray | None = None) -> np.ndarray:
        """Forward kinematics: the tool pose in the world frame (eqs 10-11).

        ``T = base · A_1(q_1) ··· A_n(q_n) · tool``.

        Args:
            q: joint values, shape (n,) or (..., n) [rad / m].
            out: optional writeable C-contiguous float64 array of shape (..., 4, 4) to
                write the result into (and return), for callers that reuse buffers (it
                pays off for batches; for one pose checking it costs what allocating does).

        Returns:
            (4, 4) or (..., 4, 4) homogeneous transforms.

        Raises:
            InputError: q of the wrong shape or not finite (a batch's ``out`` may then
                have been written); out of the wrong kind.
        """
        if type(q) is _NDARRAY and q.dtype is _F64 and q.ndim == 1:
            # one configuration: one compiled call, which checks the length and finiteness
            # (an entry point does not check dtype or ndim: they are checked here, and
            # out's; anything else takes the general path below)
            if out is None:
                T = _EMPTY((4, 4))
            elif type(out) is _NDARRAY and out.dtype is _F64 and out.shape == (4, 4) \
                    and out.flags.carray:
                T = out
            else:
                T = None
            if T is not None and (_FK1 or _resolve("_FK1"))(q, self._P, T) == 0:
                return T
        a = self.check_q(q, finite=False)  # the batch kernel tests finiteness as it reads
        if a.ndim == 1:
            a = self.check_q(a)
        shape = a.shape[:-1] + (4, 4)
        check_allocation("the FK batch", shape, 8, setting="the batch size")
        T = np.empty(shape) if out is None else _out_array(out, shape)
        if a.ndim == 1:
            K.fk_into(_kernel_q(a), self._F, self._meta, T)
            return T
        flat = _kernel_q(a.reshape(-1, self.n))
        bad = np.zeros(1, dtype=np.int64)
        parallel.run(K.fk_checked_range, (flat, self._F, self._meta, T.reshape(-1, 4, 4), bad),
                     flat.shape[0], grain=max(256, 12288 // self.n))
        if bad[0]:
            self.check_q(a)  # raises the error naming the first non-finite entry
        return T

    def fk_all(self, q: object) -> np.ndarray:
        """Every link frame ``world_T_i`` for i = 0..n (frame 0 is the base; no tool), eq 11.

        Args:
            q: joint values, shape (..., n).

        Returns:
            (..., n+1, 4, 4). For a standard-DH robot these are the DH frames 0..n.
        """
        a = self.check_q(q, finite=False)  # the kernel tests finiteness as it reads
        flat = _kernel_q(a.reshape(-1, self.n))
        check_allocation("the link frames", (flat.shape[0], self.n + 1, 4, 4), 8,
                         setting="the batch size")
        out = np.empty((flat.shape[0], self.n + 1, 4, 4))
        bad = np.zeros(1, dtype=np.int64)
        parallel.run(K.fk_all_range, (flat, self._F, self._L, self._meta, out, bad),
                     flat.shape[0], grain=max(32, 1536 // self.n))
        if bad[0]:
            self.check_q(a)  # raises the error naming the first non-finite entry
        return out.reshape(a.shape[:-1] + (self.n + 1, 4, 4))

    def jacobian(
        self,
        q: object,
        frame: str = "base",
        *,
        link: int | None = None,
        point: object = None,
        out: np.ndarray | None = None,
    ) -> np.ndarray:
        """Geometric Jacobian (eqs 33-36), rows (vx, vy, vz, wx, wy, wz).

        Column i is ``[z_i × (p − o_i); z_i]`` for a revolute joint and ``[z_i; 0]`` for a
        prismatic one, where ``z_i``, ``o_i`` are joint i's axis and origin in the world
        frame and ``p`` the reference point.

        Args:
            q: joint values, shape (..., n).
            frame: 'base' (world coordinates) or 'ee' (both blocks rotated into the tool
                frame, ``blockdiag(Rᵀ, Rᵀ) J``).
            link: None for the tool point; else a link frame index 0..n, and the Jacobian
                is that of ``point`` fixed on that link (joints beyond it give zero columns).
            point: (3,) point in the link frame's coordinates [m] (default its origin).
            out: optional writeable C-contiguous float64 array of shape (..., 6, n) to
                write the result into (and return), for callers that reuse buffers (it
                pays off for batches in the base frame, where it is written in place).

        Returns:
            (6, n) or (..., 6, n).

        Raises:
            InputError: q of the wrong shape or not finite (a batch's ``out`` may then
                have been written), unknown frame, link outside 0..n, point without
                link, out of the wrong kind.
        """
        if type(q) is _NDARRAY and q.dtype is _F64 and q.ndim == 1 and link is None \
                and point is None and type(frame) is str and frame == "base":
            if out is None:  # one compiled call, as in fk
                J = _EMPTY(self._jshape)
            elif type(out) is _NDARRAY and out.dtype is _F64 and out.shape == self._jshape \
                    and out.flags.carray:
                J = out
            else:
                J = None
            if J is not None and (_JAC1 or _resolve("_JAC1"))(q, self._P, J) == 0:
                return J
        in_place = out is not None and link is None and frame == "base"
        a, J, T = self._jacobians(q, frame, link, point, out if in_place else None)
        if in_place:
            return out
        shape = a.shape[:-1] + (6, self.n)
        if out is None:
            return J.reshape(shape)
        _out_array(out, shape)[...] = J.reshape(shape)
        return out

    def _jacobians(self, q: object, frame: str, link: int | None, point: object,
                   out: object = None) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Validated q (..., n), Jacobians (N, 6, n) in ``frame`` and the frames' poses (N, 4, 4).

        The poses are the tool's (``link`` None) or link ``link``'s frame (not the point's).
        With ``out`` (the caller's (..., 6, n) buffer; only for the tool's Jacobian in the
        base frame) the Jacobians are written straight into it (J is then a view of out).
        """
        check_choice(frame, "frame", ("base", "ee"))
        a = self.check_q(q, finite=False)  # the kernels test finiteness as they read
        flat = _kernel_q(a.reshape(-1, self.n))
        N = flat.shape[0]
        check_allocation("the Jacobian batch", (N, 6 * self.n + 16), 8, setting="the batch size")
        grain = max(16, 3072 // self.n)
        bad = np.zeros(1, dtype=np.int64)
        if link is None:
            if point is not None:
                raise InputError("point is given without link; pass link=k (0..n) as well")
            if out is not None:
                J = _out_array(out, a.shape[:-1] + (6, self.n)).reshape(N, 6, self.n)
            else:
                J = np.empty((N, 6, self.n))
            T = np.empty((N, 4, 4))
            parallel.run(K.jacobian_range, (flat, self._F, self._meta, J, T, bad), N, grain)
            if bad[0]:
                self.check_q(a)  # raises the error naming the first non-finite entry
        else:
            k = check_int(link, "link")
            if k > self.n:
                raise InputError(f"link must be in 0..{self.n}, got {k}")
            p = np.zeros(3) if point is None else as_float_array(point, "point", ndim=1)
            if p.shape != (3,):
                raise InputError(f"point must have 3 values, got shape {p.shape}")
            P = np.empty((N, 3))
            J = np.empty((N, 6, self.n))
            parallel.run(K.point_jacobian_range,
                         (flat, self._F, self._L, self._meta, k, np.ascontiguousarray(p), J, P,
                          bad), N, grain)
            if bad[0]:
                self.check_q(a)  # raises the error naming the first non-finite entry
            T = self.fk_all(flat)[:, k]
        if frame == "ee":
            Rt = np.swapaxes(T[:, :3, :3], -1, -2)
            J = np.concatenate([Rt @ J[:, :3], Rt @ J[:, 3:]], axis=1)
        return a, J, T

    def hessian(self, q: object, frame: str = "base", *, link: int | None = None,
                point: object = None) -> np.ndarray:
        """Hessian of the geometric Jacobian, ``H[..., :, j, k] = ∂J[..., :, j]/∂q_k``.

        With J's columns ``J_j = [v_j; w_j]`` (``w_j = z_j`` revolute, 0 prismatic), in the
        base frame (Haviland & Corke 2022; Pinocchio's kinematic Hessian)::

            ∂J_j/∂q_k = [w_k × v_j;  w_k × w_j]   k < j
            ∂J_j/∂q_k = [w_j × v_k;  0        ]   k ≥ j

        and in the 'ee' frame ``∂(blockdiag(Rᵀ, Rᵀ) J)/∂q_k = blockdiag(Rᵀ, Rᵀ)(∂J/∂q_k −
        [w_k]× J)``. The linear block is symmetric in (j, k) (it is the Hessian of the
        point's position). It gives the task acceleration ``ẍ = J q̈ + Σ_k H[:, :, k] q̇_k q̇``
        and :meth:`jacobian_dot` ``J̇ = Σ_k H[:, :, k] q̇_k``.

        Args:
            q: joint values, shape (..., n) [rad / m].
            frame: 'base' or 'ee', as for :meth:`jacobian`.
            link: None (tool) or a link frame 0..n, as for :meth:`jacobian`.
            point: (3,) point on that link [m], as for :meth:`jacobian`.

        Returns:
            (6, n, n) or (..., 6, n, n): units of J per rad (revolute q_k) or per m
            (prismatic q_k), i.e. [m/rad²], [1/rad] ... as the columns combine.

        Raises:
            InputError: as :meth:`jacobian`.
        """
        if type(q) is _NDARRAY and q.dtype is _F64 and q.ndim == 1 and len(q) == self.n \
                and link is None and point is None and (frame == "base" or frame == "ee"):
            H = _EMPTY((6, self.n, self.n))
            if (_HESS1 or _resolve("_HESS1"))(q, self._P, frame == "ee", H):
                return H
            raise self._nonfinite(q)
        check_choice(frame, "frame", ("base", "ee"))
        a, J, T = self._jacobians(q, "base", link, point)
        N = J.shape[0]
        H = np.empty((N, 6, self.n, self.n))
        R = np.ascontiguousarray(T[:, :3, :3])
        parallel.run(K.hessian_range, (J, R, frame == "ee", H), N,
                     grain=max(8, 1024 // (self.n * self.n)))
        return H.reshape(a.shape[:-1] + (6, self.n, self.n))

    def jacobian_dot(self, q: object, qd: object, frame: str = "base", *,
                     link: int | None = None, point: object = None) -> np.ndarray:
        """Time derivative J̇ of the geometric Jacobian at joint rates ``qd``.

        The task acceleration is ``ẍ = J q̈ + J̇ q̇`` (ẍ = [a; α], the linear acceleration
        of the reference point and the angular acceleration, in ``frame``), with

            ``J̇ = Σ_k (∂J/∂q_k) q̇_k``  (see :meth:`hessian`),

        evaluated in O(n) per configuration without forming the Hessian: column j is
        ``[ω_{<j} × v_j + w_j × v_{≥j};  ω_{<j} × w_j]`` with ``ω_{<j} = Σ_{k<j} w_k q̇_k``
        and ``v_{≥j} = Σ_{k≥j} v_k q̇_k``; in the 'ee' frame ``blockdiag(Rᵀ, Rᵀ)(J̇ − [ω]× J)``
        with ω the frame's angular velocity. Pinocchio's ``getFrameJacobianTimeVariation``
        computes the same matrix (LOCAL_WORLD_ALIGNED for 'base', LOCAL for 'ee').

        Args:
            q: joint values, shape (..., n) [rad / m].
            qd: joint rates, shape broadcastable to q's [rad/s / m/s].
            frame: 'base' or 'ee', as for :meth:`jacobian`.
            link: None (tool) or a link frame 0..n, as for :meth:`jacobian`.
            point: (3,) point on that link [m], as for :meth:`jacobian`.

        Returns:
            (6, n) or (..., 6, n) [J's units per s].

        Raises:
            InputError: as :meth:`jacobian`; qd not finite or not broadcastable to q.
        """
        n = self.n
        if type(q) is _NDARRAY and type(qd) is _NDARRAY and q.dtype is _F64 \
                and qd.dtype is _F64 and q.ndim == 1 and qd.ndim == 1 and len(q) == n \
                and len(qd) == n and link is None and point is None \
                and (frame == "base" or frame == "ee") and qd.flags.c_contiguous:
            # (a strided qd takes the batch path, which copies it: one compiled layout)
            Jd = _EMPTY((6, n))
            if (_JDOT1 or _resolve("_JDOT1"))(q, self._P, qd, frame == "ee", Jd):
                return Jd
            self.check_q(qd, "qd")  # names the non-finite argument
            raise self._nonfinite(q)
        check_choice(frame, "frame", ("base", "ee"))
        a, J, T = self._jacobians(q, "base", link, point)
        v = self.check_q(qd, "qd")
        try:
            v = np.broadcast_to(v, a.shape)
        except ValueError:
            raise InputError(f"qd has shape {v.shape}, which does not broadcast to q's "
                             f"shape {a.shape}") from None
        N = J.shape[0]
        Jd = np.empty((N, 6, self.n))
        R = np.ascontiguousarray(T[:, :3, :3])
        parallel.run(K.jacobian_dot_range,
                     (J, readonly(np.ascontiguousarray(v.reshape(-1, self.n))), R, frame == "ee",
                      Jd),
                     N, grain=max(16, 3072 // self.n))
        return Jd.reshape(a.shape[:-1] + (6, self.n))

    def joint_axes(self, q: object = None) -> tuple[np.ndarray, np.ndarray]:
        """Joint lines in the world frame: origins (n, 3) [m] and unit axes (n, 3) at ``q``.

        Joint i turns about (slides along) the line through ``origins[i]`` with direction
        ``axes[i]`` — the o_i and z_i of eqs 35-36. ``q`` defaults to zeros.
        """
        a = np.zeros(self.n) if q is None else self.check_q(q)
        if a.ndim != 1:
            raise InputError(f"q must have shape ({self.n},), got {a.shape}")
        P, W = np.empty((self.n, 3)), np.empty((self.n, 3))
        K.joint_axes_into(_kernel_q(a), self._F, self._meta, P, W)
        return P, W

    def jacobian_planar(self, q: object, orientation: bool = False) -> np.ndarray:
        """Planar task Jacobian (eqs 30-32 and 38): rows (vx, vy) or (vx, vy, wz), (..., 2|3, n)."""
        rows = [0, 1, 5] if orientation else [0, 1]
        return self.jacobian(q)[..., rows, :]

    def jacobian_analytic(self, q: object, rep: str = "rpy") -> np.ndarray:
        """Analytical Jacobian (eq 29) for an orientation representation.

        See :func:`serialkin.kinematics.analytic.jacobian_analytic`.
        """
        from serialkin.kinematics.analytic import jacobian_analytic

        return jacobian_analytic(self, q, rep)

    def _task_jacobian(self, q: object, task: str | Sequence[int]) -> np.ndarray:
        return self.jacobian(q)[..., task_rows(task), :]

    def manipulability(self, q: object, task: str | Sequence[int] = "full", *,
                       frame: str = "base", link: int | None = None,
                       point: object = None) -> np.ndarray | float:
        """Yoshikawa manipulability ``w = sqrt(det(J Jᵀ))`` (eq 43) of the task Jacobian.

        Args:
            q: joint values, shape (..., n).
            task: rows of J that form the task: a name of :data:`serialkin.model.tasks.TASKS`
                ('full'/'pose', 'position', 'orientation', 'planar' (vx, vy),
                'planar_pose' (vx, vy, wz)) or a list of row indices.
            frame: frame of the Jacobian, as in :meth:`jacobian` ('base' or 'ee').
            link: Jacobian of a point on this link frame, as in :meth:`jacobian`.
            point: that point, as in :meth:`jacobian`.

        Returns:
            float or (...) array; 0 at singular configurations (and when n < m). Computed
            as the product of J's singular values, which equals sqrt(det(J Jᵀ)) and is
            exactly representable near singularities
            (:func:`serialkin.kinematics.dls.manipulability_of`).
        """
        rows = task_rows(task)
        J = np.ascontiguousarray(self.jacobian(q, frame, link=link, point=point)[..., rows, :])
        flat = J.reshape((-1,) + J.shape[-2:])
        w = np.empty(flat.shape[0])
        manipulability_batch(flat, w)
        w = w.reshape(J.shape[:-2])
        return float(w) if w.ndim == 0 else w

    def condition_number(self, q: object, task: str | Sequence[int] = "full") -> np.ndarray | float:
        """Condition number σ_max/σ_min of the task Jacobian (inf at singularities)."""
        J = self._task_jacobian(q, task)
        s = np.linalg.svd(J, compute_uv=False)
        with np.errstate(divide="ignore"):
            c = np.where(s[..., -1] > 1e-15 * s[..., 0], s[..., 0] / s[..., -1], np.inf)
        return float(c) if c.ndim == 0 else c

    # ------------------------------------------------------------------ joint space
    def random_q(self, size: int | tuple[int, ...] | None = None,
                 seed: None | int | np.random.Generator = None) -> np.ndarray:
        """Uniform random configurations inside the joint limits, shape (n,) or (*size, n).

        Draws from :meth:`sampling_limits` (the limits; an open side is replaced as
        :func:`serialkin.model.limits.sampling_box` documents: unlimited revolute joints
        sample [-π, π], unlimited prismatic joints [-1, 1] m).

        Args:
            size: None for one configuration, an int or a tuple of ints (each >= 0).
            seed: None, int or numpy Generator.

        Raises:
            InputError / InputTypeError: a negative or non-integer size; a size beyond
                the memory budget (:mod:`serialkin._budget`).
        """
        rng = as_generator(seed)
        lo, hi = self.sampling_limits().T
        if size is None:
            shape: tuple[int, ...] = ()
        elif isinstance(size, (tuple, list)):
            shape = tuple(check_int(s, "size") for s in size)
        else:
            shape = (check_int(size, "size"),)
        check_allocation("random_q size", (*shape, self.n), 8, setting="size")
        return lo + (hi - lo) * rng.random(shape + (self.n,))

    def sampling_limits(self) -> np.ndarray:
        """The finite box random configurations are drawn from, (n, 2) [rad or m].

        The joint limits, each open side replaced as
        :func:`serialkin.model.limits.sampling_box` documents (default half-range π for
        revolute joints, 1 m for prismatic ones).
        """
        d = np.array([DEFAULT_HALF_RANGE[t] for t in self.joint_types])
        return sampling_box(self.qlim[:, 0], self.qlim[:, 1], d)

    def within_limits(self, q: object, tol: float = 0.0) -> np.ndarray | bool:
        """True where ``q`` (..., n) lies inside the joint limits (with tolerance ``tol``)."""
        a = self.check_q(q)
        tol = check_positive(tol, "tol", allow_zero=True)
        ok = np.all(inside_mask(a, self.qlim[:, 0], self.qlim[:, 1], tol), axis=-1)
        return bool(ok) if ok.ndim == 0 else ok

    # ------------------------------------------------------------------ inverse kinematics
    def ik(self, target: object, method: str = "lm", *, q0: object = None,
           seed: object = None, **options: Any) -> IKResult:
        """Inverse kinematics by any method (see :func:`serialkin.ik.solve`).

        ``scene=[...]``, ``self_collision=True`` and ``margin`` (m) ask for a solution
        that is also collision-free (needs :attr:`collision`; see docs/ik.md).
        """
        if not options and type(target) is _NDARRAY and type(method) is str:
            res = (_FAST_IK or _provided("ik_fast"))(self, target, method, q0, seed)
            if res is not None:  # the common call, answered as solve would (same bits)
                return res
        return (_SOLVE or _provided("ik"))(self, target, method, q0=q0, seed=seed, **options)

    def ik_all(self, target: object, **options: Any) -> AllSolutions:
        """Every IK solution inside the limits (see :func:`serialkin.ik.analytic.ik_all`).

        Always an :class:`~serialkin.ik.analytic.AllSolutions`. For one (4, 4) target it
        is also the (k, n) array of its rows (``len``, indexing, iteration and
        ``np.asarray`` give them); for a batch (..., 4, 4) it holds padded rows
        (..., k_max, n) and a count per target. Options: ``tol``, ``all_turns``,
        ``free``, ``near_tol``, ``grid``, ``reference``, ``weights``, ``norm``, ``report``.
        """
        return _provided("ik_all")(self, target, **options)

    def arm_angle(self, q: object, reference: object = None) -> np.ndarray:
        """The arm angle ψ [rad] of configurations (..., 7) of a 7R S-R-S arm (iiwa-like).

        See :func:`serialkin.ik.analytic.arm_angle.arm_angle` (the conventional SEW angle
        about the shoulder-wrist line, measured from ``reference``, default base z).
        """
        return _provided("arm_angle")(self, q, reference)

    def ik_arm_angle(self, target: object, psi: float, reference: object = None,
                     **options: Any) -> Any:
        """Every configuration of a 7R S-R-S arm reaching ``target`` at arm angle ψ [rad].

        Closed form, up to 8 rows with their branches
        (:func:`serialkin.ik.analytic.arm_angle.ik_arm_angle`).
        """
        return _provided("ik_arm_angle")(self, target, psi, reference, **options)

    def arm_angle_intervals(self, target: object, reference: object = None,
                            **options: Any) -> Any:
        """The arm angles [rad] at which each branch reaches ``target`` inside the limits.

        See :func:`serialkin.ik.analytic.arm_angle.arm_angle_intervals`.
        """
        return _provided("arm_angle_intervals")(self, target, reference, **options)

    # ------------------------------------------------------------------ display
    def __repr__(self) -> str:
        types = "".join(self.joint_types)
        conv = f", {self.convention} DH" if self.convention else ""
        return f"Robot({self.name!r}, n={self.n}, joints={types}{conv})"


def _kernel_q(a: np.ndarray) -> np.ndarray:
    """Joint values as the batch kernels take them: C-ordered and writeable (one signature).

    A read-only array (a path's joint values, a frozen result) is copied, as is one that
    is not C-contiguous; others pass as they are (issue 27: a kernel compiled once).
    """
    c = np.ascontiguousarray(a)
    return c if c.flags.writeable else c.copy()


def robot_scale(robot: Robot) -> float:
    """Return a length scale of the robot [m]: an upper bound on its reach from the base.

    The tool lies within ``Σ_{i>=1} |t(F[i])|`` plus the prismatic travel of the first
    joint's frame (eq 11: ``T = F[0]·M_1·F[1]···M_n·F[n]``), where ``t`` is the
    translation; a prismatic joint adds its largest finite limit (1 m when unlimited).
    At least 1e-3. Used to size frame triads, markers and views, and to judge a calibration's
    parameter changes and residuals.
    """
    F = robot.chain.F
    total = float(np.linalg.norm(F[1:, :3, 3], axis=-1).sum())
    for i, revolute in enumerate(robot.revolute):
        if not revolute:
            lim = np.abs(robot.qlim[i])
            finite = lim[np.isfinite(lim)]
            total += float(finite.max()) if finite.size else 1.0
    return max(total, 1e-3)


def check_robot(robot: object, name: str = "robot") -> Robot:
    """``robot`` if it is a :class:`Robot`; else InputTypeError naming ``name``.

    A string gets a hint: it looks like a model name, which ``serialkin.models.get``
    turns into a robot.

    Raises:
        InputTypeError: ``robot`` is not a Robot.
    """
    if isinstance(robot, Robot):
        return robot
    hint = (f" (a model name: serialkin.models.get({short_repr(robot, 40)}) builds it)"
            if isinstance(robot, str) else "")
    raise InputTypeError(f"{name} must be a serialkin Robot, got {type(robot).__name__} "
                         f"{short_repr(robot, 40)}{hint}")
