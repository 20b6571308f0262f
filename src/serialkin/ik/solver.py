"""The shared IK skeleton: one entry point, one loop, one result.

:func:`solve` (what ``robot.ik`` calls) validates the arguments, looks the method up in
the registry and runs it:

* compiled methods (the Jacobian family) run entirely in their ``solve_chunk`` (one
  target: a chunk of one), the shared loop of :mod:`serialkin.ik._kernels` around the
  method's step kernel; a batch runs it on every core (GIL released, chunks handed out by
  :func:`serialkin.kinematics.parallel.run`);
* Python methods supply one attempt and :func:`run_attempts` owns the rest.

Both follow the same semantics:

* **attempts** — the first attempt starts from ``q0`` (or, without one, from a random
  configuration); when an attempt fails to converge or stagnates, the solver restarts
  from a configuration drawn uniformly inside the joint limits (unlimited revolute joints:
  [-π, π]; unlimited prismatic joints: [-1, 1] m), at most ``restarts`` times;
* **budget** — at most ``max_iter`` iterations per attempt, so at most
  ``(restarts + 1)·max_iter`` in total (plus ``max_iter`` for the final polish of the
  ``lm`` method): a solve always ends;
* **tolerance** — success when the position error [m] and the orientation error [rad]
  of the selected task coordinates are both ≤ ``tol`` (default :data:`DEFAULT_TOL`), and
  q is inside the limits when ``respect_limits``;
* **randomness** — one splitmix64 stream per target seeded from ``seed``: the same seed
  gives the same answer, and a batch returns exactly what the single solves return;
* **failure** — ``success=False``, a ``reason``, and the best attempt's q (lowest cost),
  always finite.
"""

from __future__ import annotations

import math
import os
from collections.abc import Mapping
from dataclasses import dataclass, replace
from typing import Any

import numpy as np

from serialkin._budget import check_allocation
from serialkin._checks import MAX_ITERATIONS, ROTATION_TOL, check_int, readonly, short_repr
from serialkin._memo import PerObject
from serialkin.errors import InputError, InputTypeError
from serialkin.ik import _kernels as K
from serialkin.ik.registry import _REGISTRY, MethodSpec, available_methods, get_method
from serialkin.ik.result import IKResult
from serialkin.ik.target import (
    DEFAULT_WEIGHTS,
    Target,
    check_q0,
    check_tol,
    parse_target,
    robot_arrays,
)
from serialkin.ik.turns import nearest_turn, wide_joints
from serialkin.kinematics import kernels as FK
from serialkin.kinematics import parallel
from serialkin.model.robot import Robot, check_robot
from serialkin.spatial import kernels as SK

#: Default tolerance on the position [m] and orientation [rad] errors.
DEFAULT_TOL = 1e-9

#: Largest number of restarts a solve accepts (``max_iter`` is bounded by
#: :data:`serialkin._checks.MAX_ITERATIONS`).
MAX_RESTARTS = 100_000

_MASK64 = (1 << 64) - 1

#: Hot-path caches: kernel configuration vectors and parameter tails for default options.
_CONFIGS: dict[tuple, np.ndarray] = {}
_PARAMS: dict[str, tuple[MethodSpec, np.ndarray]] = {}


@dataclass(frozen=True, eq=False)
class IKProblem:
    """One target for one robot, as Python methods see it.

    Attributes:
        robot: the robot.
        T_target: (4, 4) target pose (world frame).
        weights: (6,) task-coordinate weights ``w`` of ``[vx, vy, vz, wx, wy, wz]``.
        kind: target kind ('pose', 'position', 'planar', 'planar_pose').
        tol: tolerance on the position [m] and orientation [rad] errors.
        respect_limits: whether q must stay inside the joint limits.
        lower, upper: (n,) projection bounds (the joint limits, or ±inf when
            ``respect_limits`` is False).
        revolute: (n,) bool, True for revolute joints.
    """

    robot: Robot
    T_target: np.ndarray
    weights: np.ndarray
    kind: str
    tol: float
    respect_limits: bool
    lower: np.ndarray
    upper: np.ndarray
    revolute: np.ndarray

    @property
    def n(self) -> int:
        """Number of joints."""
        return self.robot.n

    @property
    def selected(self) -> np.ndarray:
        """(6,) booleans: task coordinates that count."""
        return self.weights > 0.0

    def pose(self, q: np.ndarray) -> np.ndarray:
        """Tool pose (4, 4) at ``q`` (n,) (trusted, finite float64)."""
        T = np.empty((4, 4))
        FK.fk_into(np.ascontiguousarray(q, dtype=np.float64), self.robot.chain.F,
                   self.robot.chain.meta, T)
        return T

    def error(self, q: np.ndarray) -> np.ndarray:
        """Unweighted pose error ``e = [p_t − p; log(R_t Rᵀ)^∨]`` (6,) at ``q`` [m; rad]."""
        e = np.empty(6)
        SK.pose_error_into(self.pose(q), self.T_target, e)
        return e

    def jacobian(self, q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Geometric Jacobian (6, n) and pose (4, 4) at ``q``."""
        J = np.empty((6, self.n))
        T = np.empty((4, 4))
        FK.jacobian_into(np.ascontiguousarray(q, dtype=np.float64), self.robot.chain.F,
                         self.robot.chain.meta, J, T)
        return J, T

    def cost(self, q: np.ndarray) -> float:
        """Cost ``E = ½ Σ w_i e_i²`` at ``q``."""
        e = self.error(q)
        return 0.5 * float(np.dot(self.weights, e * e))

    def errors(self, q: np.ndarray) -> tuple[float, float]:
        """(position error [m], orientation error [rad]) over the selected coordinates."""
        e = self.error(q)
        sel = self.selected
        return (float(np.linalg.norm(e[:3][sel[:3]])), float(np.linalg.norm(e[3:][sel[3:]])))

    def converged(self, q: np.ndarray) -> bool:
        """True when both errors are within ``tol``."""
        p, o = self.errors(q)
        return p <= self.tol and o <= self.tol

    def project(self, q: np.ndarray) -> np.ndarray:
        """A copy of q projected onto the joint ranges (unchanged without limits).

        Revolute joints are shifted by 2π when that brings them inside, else set to the
        nearer limit; prismatic joints are clamped.
        """
        out = np.array(q, dtype=np.float64)
        if self.respect_limits:
            # the joint types as the kernels' (5, n) box holds them (read-only float64
            # 1.0 / 0.0), the one type project_into compiles for
            box = robot_arrays(self.robot).box
            K.project_into(out, self.lower, self.upper, box[K.B_REVOLUTE])
        return out


def _stream_seed(seed: object) -> int:
    """A uint64 stream seed from ``seed`` (None: fresh OS entropy; int; Generator)."""
    if type(seed) is int:
        return seed & _MASK64
    if seed is None:
        return int.from_bytes(os.urandom(8), "little")
    if isinstance(seed, np.random.Generator):
        return int(seed.integers(0, 2**63, dtype=np.int64))
    if isinstance(seed, (int, np.integer)) and not isinstance(seed, bool):
        return int(seed) & _MASK64
    raise InputTypeError(
        f"seed must be None, an int or a numpy Generator, got {type(seed).__name__} {seed!r}"
    )


def _options(spec: MethodSpec, options: Mapping[str, Any]) -> Mapping[str, Any]:
    """Method options merged over the method's defaults; unknown names raise."""
    if not options:
        return spec.options
    unknown = sorted(set(options) - set(spec.options))
    if unknown:
        accepted = ", ".join(sorted(spec.options)) or "none"
        raise InputError(
            f"unknown option(s) {unknown} for method {spec.name!r}; its options are: {accepted} "
            "(common ones: q0, mask, tol, max_iter, restarts, seed, respect_limits)"
        )
    return {**spec.options, **options}


def _limits(robot: Robot, respect_limits: bool) -> tuple[np.ndarray, ...]:
    a = robot_arrays(robot)
    return a.lo, a.hi, a.slo, a.shi, a.revolute


def reach_bound(robot: Robot) -> float:
    """An upper bound on the distance of the tool from joint 1's origin [m].

    By the triangle inequality over the chain ``T = F0·M1·F1···Mn·Fn`` (eq 11), the tool
    is at most ``Σ_i |t(F_i)| + Σ_prismatic max|q_i + offset_i|`` from the origin of
    ``F0`` (prismatic ranges from the sampling limits).
    """
    F, meta = robot.chain.F, robot.chain.meta
    r = float(np.linalg.norm(F[1:, :3, 3], axis=1).sum())
    lim = robot.sampling_limits()
    for i in range(robot.n):
        if meta[i, 3] == FK.PRISMATIC:
            r += float(np.max(np.abs(lim[i] + meta[i, 4])))
    return r


def failure_hint(robot: Robot, q: np.ndarray, weights: np.ndarray, respect_limits: bool,
                 T_target: np.ndarray | None = None) -> str:
    """Why the best attempt ``q`` may have stopped short of the target.

    A position target farther from joint 1 than :func:`reach_bound` is out of reach,
    certainly. Otherwise, at a stationary point of the cost that is not a solution (where
    the ``lm`` polish ends), either a joint limit is active or the task Jacobian is
    singular (its rows cannot move the tool along the remaining error): the hint names
    the joints at a limit, or the singularity (typically the arm stretched towards an
    out-of-reach target), or else falls back to the general causes.
    """
    q = np.asarray(q, dtype=np.float64)
    if T_target is not None and np.all(np.asarray(weights)[:3] > 0):
        bound = reach_bound(robot)
        dist = float(np.linalg.norm(T_target[:3, 3] - robot.chain.F[0][:3, 3]))
        if dist > bound:
            return (f"the target is out of reach: it is {dist:.3g} m from joint 1 but no "
                    f"configuration puts the tool farther than {bound:.3g} m from it")
    if respect_limits:
        lo, hi = robot.qlim[:, 0], robot.qlim[:, 1]
        span = np.where(np.isfinite(hi - lo), hi - lo, 1.0)
        at = np.flatnonzero((np.abs(q - lo) <= 1e-9 * (1 + span))
                            | (np.abs(q - hi) <= 1e-9 * (1 + span)))
        if at.size:
            names = ", ".join(repr(robot.joint_names[i]) for i in at)
            return (f"the best attempt has joint(s) {names} at a limit: the target may be "
                    "reachable only outside the joint limits")
    J = robot.jacobian(q)[np.asarray(weights) > 0]
    sv = np.linalg.svd(J, compute_uv=False)
    if sv.size and (sv.size > robot.n or sv[-1] <= 1e-5 * sv[0]):
        return ("the best attempt is at a singular configuration (e.g. the arm stretched): "
                "the target looks out of reach")
    return ("the target may be out of reach, reachable only outside the joint limits, or "
            "need more restarts / iterations")


def failure_reason(pos_err: float, ori_err: float, tol: float, attempts: int,
                   iterations: int, kind: str, hint: str = "") -> str:
    """The sentence reported when a solve fails (``hint``: see :func:`failure_hint`)."""
    what = f"position error {pos_err:.3g} m"
    if kind in ("pose", "planar_pose"):
        what += f", orientation error {ori_err:.3g} rad"
    hint = hint or ("the target may be out of reach, reachable only outside the joint "
                    "limits, or need more restarts / iterations")
    return (
        f"no configuration within tol={tol:g} found in {attempts} attempt(s) and {iterations} "
        f"iterations (best: {what}); {hint}"
    )


def run_attempts(spec: MethodSpec, problem: IKProblem, q0: np.ndarray | None, max_iter: int,
                 restarts: int, seed: int, options: Mapping[str, Any]) -> tuple:
    """The shared loop for Python methods: attempts from q0 / seeded random starts.

    The same semantics as the compiled loop (:func:`serialkin.ik._kernels._restarts`:
    the same random stream, starts, best-attempt rule), in Python because its attempts
    are Python (scipy's optimisers, CCD, FABRIK): a compiled loop cannot call them.

    Returns ``(q, success, iterations, position_error, orientation_error, reason,
    restarts_used)`` for one target.
    """
    robot = problem.robot
    arrays = robot_arrays(robot)
    slo, shi = arrays.slo, arrays.shi
    state = np.array([seed], dtype=np.uint64)
    best_q = None
    best_cost = np.inf
    total = 0
    used = 0
    success = False
    for attempt in range(restarts + 1):
        used = attempt
        if attempt == 0 and q0 is not None:
            start = q0.copy()
        else:
            start = np.empty(robot.n)
            K.random_q_into(state, slo, shi, start)
        start = problem.project(start)
        if best_q is None:
            best_q, best_cost = start, problem.cost(start)
        q, its = spec.attempt(problem, start, max_iter, options)
        q = np.asarray(q, dtype=np.float64)
        total += min(int(its), max_iter)
        if q.shape != (robot.n,) or not np.isfinite(q).all():
            continue
        if problem.respect_limits:
            q = problem.project(q)
        cost = problem.cost(q)
        ok = problem.converged(q)
        if ok or cost < best_cost:
            best_q, best_cost = q, cost
        if ok:
            success = True
            break
    q = np.array(best_q, dtype=np.float64)
    K.normalize_into(q, arrays.lo, arrays.hi, arrays.box[K.B_REVOLUTE])  # the kernels' types
    success = honest_success(robot, q, success, problem.respect_limits)
    pe, oe = problem.errors(q)
    reason = "" if success else failure_reason(
        pe, oe, problem.tol, used + 1, total, problem.kind,
        failure_hint(robot, q, problem.weights, problem.respect_limits, problem.T_target))
    return q, success, total, pe, oe, reason, used


def _same_options(a: Mapping[str, Any], b: Mapping[str, Any]) -> bool:
    """True when two option mappings hold the same plain values (arrays never compare)."""
    plain = (bool, int, float, str)
    return a.keys() == b.keys() and all(
        type(a[k]) is type(b[k]) and isinstance(a[k], plain) and a[k] == b[k] for k in a)


def _method_params(spec: MethodSpec, opts: Mapping[str, Any]) -> np.ndarray:
    """The tail ``cfg[C_WINDOW:]`` of the kernel configuration.

    The loop's stagnation window, polish flag and stall ratio, then, for a member of a
    family of methods, its number (``spec.kernel.code``), then the method's own
    parameters (``spec.kernel.params``, in order).
    """
    from serialkin._checks import check_positive

    default = opts is spec.options or _same_options(opts, spec.options)
    if default:
        cached = _PARAMS.get(spec.name)
        if cached is not None and cached[0] is spec:
            return cached[1]
    names = spec.kernel.params
    base = K.C_WINDOW
    code = spec.kernel.code  # a family member: its number first (compile_family)
    lead = 0 if code is None else 1
    p = np.zeros(K.N_LOOP - base + lead + len(names))
    if lead:
        p[K.N_LOOP - base] = code
    polish = opts.get("polish", False)
    if not isinstance(polish, (bool, np.bool_)):
        raise InputTypeError(f"polish must be True or False, got {polish!r}")
    p[K.C_POLISH - base] = 1.0 if polish else 0.0
    p[K.C_WINDOW - base] = check_int(opts.get("stall_window", 20), "stall_window", minimum=1,
                                     maximum=MAX_ITERATIONS)
    ratio = check_positive(opts.get("stall_ratio", 0.0), "stall_ratio", allow_zero=True)
    if ratio >= 1.0:
        raise InputError(f"stall_ratio must be in [0, 1) (0 turns the rule off), got "
                         f"{ratio!r}")
    p[K.C_STALL_RATIO - base] = ratio
    for i, (name, zero_ok) in enumerate(names):
        p[K.N_LOOP - base + lead + i] = check_positive(opts[name], name,
                                                       allow_zero=zero_ok)
    if default:
        p.setflags(write=False)
        _PARAMS[spec.name] = (spec, p)
    return p


def solve(
    robot: Robot,
    target: object,
    method: str = "lm",
    *,
    q0: object = None,
    mask: object = None,
    tol: float | None = None,
    max_iter: int | None = None,
    restarts: int | None = None,
    seed: None | int | np.random.Generator = None,
    respect_limits: bool = True,
    scene: object = None,
    self_collision: bool = False,
    margin: float = 0.0,
    acm: object = None,
    **options: Any,
) -> IKResult:
    """Inverse kinematics of ``robot`` for ``target`` by ``method``.

    Args:
        robot: the robot.
        target: (4, 4) pose, 3-vector position, planar (x, y) / (x, y, φ) for planar
            robots, or a batch of these ((N, 4, 4), (N, 3), (N, 2)); see
            :mod:`serialkin.ik.target`.
        method: a name from :func:`serialkin.ik.available_methods` (default 'lm').
        q0: initial guess (n,), or for a batch (n,) or (N, n); default a random
            configuration from the seeded stream.
        mask: 6 booleans / weights for ``[vx, vy, vz, wx, wy, wz]`` (default: those the
            target defines).
        tol: tolerance on position [m] and orientation [rad] errors, > 0
            (default :data:`DEFAULT_TOL`).
        max_iter: iterations per attempt (default per method), 1 to
            :data:`~serialkin._checks.MAX_ITERATIONS` (10⁶).
        restarts: restarts from random configurations allowed (default per method), 0 to
            :data:`MAX_RESTARTS` (10⁵).
        seed: None, int or numpy Generator for the random starts.
        respect_limits: keep q inside the joint limits (each method documents how).
        scene: obstacles in the world frame — one or a sequence of shapes of
            :mod:`serialkin.model.geometry` (``Sphere``, ``Capsule``, ``Box``,
            ``HalfSpace``, the infinite ``Cylinder`` along z) — that a solution must clear
            by ``margin`` (needs ``robot.collision``; Jacobian-family methods).
        self_collision: also ask for a self-collision-free solution (the robot's shape
            pairs not allowed by ``acm``).
        margin: clearance a solution must keep [m], ≥ 0 (0: touching is allowed).
        acm: :class:`~serialkin.collision.acm.AllowedCollisionMatrix` of body pairs never
            checked (default :func:`~serialkin.collision.acm.default_acm` of the model).
        **options: method-specific options (see ``METHODS[name].options``).

    Returns:
        :class:`IKResult`; for a batch target, with arrays. With ``scene`` or
        ``self_collision``, a success also has ``clearance >= margin``, and the solver
        keeps searching (push-out steps along the clearance gradient, restarts) until it
        finds one or its budget ends (see :func:`serialkin.ik._kernels._solve_one_collision`).

    Raises:
        InputError: a malformed target, mask, tolerance or q0, an unknown method (the
            message lists the available ones) or an unknown option; a negative margin, a
            scene or collision check on a robot without a collision model, or on a method
            outside the Jacobian family. A failed solve is not an error: it returns
            ``success=False`` with a ``reason``.
    """
    if (type(target) is np.ndarray and type(method) is str and not options and mask is None
            and tol is None and max_iter is None and restarts is None and respect_limits is True
            and scene is None and self_collision is False and acm is None
            and type(margin) is float and margin == 0.0):
        if isinstance(robot, Robot):
            res = _fast(robot, target, method, q0, seed)
            if res is not None:
                return res
    return _solve_checked(robot, target, method, _Request(
        q0=q0, mask=mask, tol=tol, max_iter=max_iter, restarts=restarts, seed=seed,
        respect_limits=respect_limits, scene=scene, self_collision=self_collision,
        margin=margin, acm=acm, options=options))


@dataclass(frozen=True, eq=False)
class _Request:
    """The keyword arguments of one :func:`solve` call, as given (same names, unchecked)."""

    q0: object
    mask: object
    tol: float | None
    max_iter: int | None
    restarts: int | None
    seed: None | int | np.random.Generator
    respect_limits: object
    scene: object
    self_collision: object
    margin: object
    acm: object
    options: Mapping[str, Any]


def _check_joint_count(robot: Robot, spec: MethodSpec) -> None:
    """Raise InputError when ``robot`` has more joints than ``spec`` takes (naming others)."""
    if spec.max_joints is not None and robot.n > spec.max_joints:
        scalable = [m for m in available_methods() if get_method(m).max_joints is None
                    and get_method(m).family != "analytic"]
        raise InputError(
            f"method {spec.name!r} takes robots of at most {spec.max_joints} joints (its "
            f"cost per iteration grows faster than the number of joints); robot "
            f"{short_repr(robot.name)} has {robot.n}: use one of {', '.join(scalable)}"
        )


def _check_batch_size(robot: Robot, target: object) -> None:
    """Refuse a batch target whose copies and results exceed the memory budget."""
    shape = getattr(target, "shape", None)
    if shape is not None and len(shape) >= 2:  # before parse_target copies a batch
        # per target: its copy (16), q (n) and the kernel's info: refused before allocation
        count = math.prod(shape[:-1]) // (4 if shape[-2:] == (4, 4) else 1)
        check_allocation("the IK batch (targets and results)",
                         (count, robot.n + K.N_INFO + 16), 8, setting="target")


def _solve_checked(robot: object, target: object, method: str, req: _Request) -> IKResult:
    """:func:`solve` past its fast path: check every argument, then run the method."""
    check_robot(robot)
    spec = get_method(method)
    _check_joint_count(robot, spec)
    _check_batch_size(robot, target)
    tgt = parse_target(robot, target, req.mask)
    if tgt.kind not in spec.targets:
        raise InputError(
            f"method {spec.name!r} does not accept {tgt.kind} targets; it accepts "
            f"{', '.join(spec.targets)}"
        )
    tol_v = DEFAULT_TOL if req.tol is None else check_tol(req.tol)
    iters = spec.max_iter if req.max_iter is None else check_int(
        req.max_iter, "max_iter", minimum=1, maximum=MAX_ITERATIONS)
    nrest = spec.restarts if req.restarts is None else check_int(
        req.restarts, "restarts", minimum=0, maximum=MAX_RESTARTS)
    if not isinstance(req.respect_limits, (bool, np.bool_)):
        raise InputTypeError(f"respect_limits must be True or False, got {req.respect_limits!r}")
    respect = bool(req.respect_limits)
    opts = _options(spec, req.options)
    coll = None
    if (req.scene is not None or req.self_collision is not False or req.acm is not None
            or not (type(req.margin) is float and req.margin == 0.0)):
        coll = _collision_setup(robot, spec, req.scene, req.self_collision, req.margin, req.acm)
    n_targets = tgt.T.shape[0] if tgt.batch else None
    q0a = None if req.q0 is None else check_q0(robot, req.q0, n_targets, respect)
    stream = _stream_seed(req.seed)
    if coll is not None and coll.active:
        res = _solve_collision(robot, tgt, spec, q0a, tol_v, iters, nrest, stream, respect,
                               opts, coll)
    elif spec.kernel is not None:
        res = _solve_compiled(robot, tgt, spec, q0a, tol_v, iters, nrest, stream, respect,
                              opts)
    else:
        res = _solve_python(robot, tgt, spec, q0a, tol_v, iters, nrest, stream, respect, opts)
    return with_nearest_turns(robot, res, q0a)


#: Per robot: the (n,) mask of joints wider than a turn, or False when there is none.
_WIDE: PerObject[Any] = PerObject()


def _wide(robot: Robot) -> Any:
    """The (n,) mask of ``robot``'s joints wider than a turn, or False (cached, ``_WIDE``)."""
    wide = _WIDE.get(robot)
    if wide is None:
        mask = wide_joints(robot.qlim[:, 0], robot.qlim[:, 1], robot.revolute)
        wide = _WIDE.set(robot, mask if mask.any() else False)
    return wide


def with_nearest_turns(robot: Robot, res: IKResult, q0: np.ndarray | None) -> IKResult:
    """``res`` with q moved by whole turns to the representative nearest ``q0`` (or zero).

    Only revolute joints whose range exceeds 2π move, and only inside their limits
    (:func:`serialkin.ik.turns.nearest_turn`); ``res`` itself when nothing moves. The
    errors and the flags stay those of the solve: the pose is the same to rounding.

    Args:
        robot: the robot solved for.
        res: the solver's result (single or batch).
        q0: the initial guess, (n,) or (N, n), or None (the reference is then zero).
    """
    wide = _wide(robot)
    if wide is False:
        return res
    q = nearest_turn(res.q, robot.qlim[:, 0], robot.qlim[:, 1], wide, q0)
    if np.array_equal(q, res.q):
        return res
    if not np.asarray(res.q).flags.writeable:
        q.setflags(write=False)
    return replace(res, q=q)


def _fast_entry(robot: object, method: str) -> tuple | None:
    """The prepared arrays of the fast path for ``robot`` and ``method`` (None: not eligible).

    ``(spec, entry point of solve_fast, S, zeros (n,), the strides (8,) of a contiguous q0,
    method name)`` (for a method with ``solve_pose``: no entry point nor ``S``, None),
    kept in ``_FAST_ENTRIES`` per robot and method: ``S`` the packed constants
    (:func:`~serialkin.ik._kernels.pack_fast`) and the compiled entry point of the
    method's ``solve_fast`` for a read-only ``S``, C (4, 4) target, C (n,) q0 and q, an
    int64 seed and a bool. Calling the entry point skips numba's per-call type dispatch
    (about 0.2 µs for six arguments); it does not check dtypes, layouts or shapes, so
    :func:`_fast` does.
    """
    from serialkin._jit import entry_point

    if not isinstance(robot, Robot) or method not in _REGISTRY:
        return None
    spec = get_method(method)
    if (spec.solve_pose is not None and "pose" in spec.targets
            and (spec.max_joints is None or robot.n <= spec.max_joints)):
        # a method that solves one pose by itself: no compiled entry, and in place of S
        # the limits _fast_pose reads (_fast_pose)
        a = robot_arrays(robot)
        limits = (a.lo, a.hi, robot.qlim[:, 0], robot.qlim[:, 1], _wide(robot))
        entry = (spec, None, limits, np.zeros(robot.n), (8,), spec.name)
        _FAST_ENTRIES.setdefault(robot, dict)[method] = entry
        return entry
    if (spec.kernel is None or spec.kernel.solve_fast is None or "pose" not in spec.targets
            or (spec.max_joints is not None and robot.n > spec.max_joints)):
        return None
    a = robot_arrays(robot)
    tgt = Target(np.eye(4), DEFAULT_WEIGHTS["pose"], "pose")
    cfgs = [_kernel_config(spec, tgt, DEFAULT_TOL, spec.max_iter, spec.restarts, True,
                           use, spec.options) for use in (False, True)]
    S = K.pack_fast(robot.chain.F, robot.chain.meta, a.box, cfgs[0], cfgs[1], ROTATION_TOL)

    def sig() -> tuple:  # numba's types, imported only when the kernel is loaded
        import numba

        f64, Array = numba.float64, numba.types.Array
        vec = Array(f64, 1, "C")
        return (Array(f64, 1, "C", readonly=True), Array(f64, 2, "C"), vec, numba.int64,
                numba.types.boolean, vec)

    function, final = entry_point(spec.kernel.solve_fast, sig)
    entry = (spec, function, S, np.zeros(robot.n), (8,), spec.name)
    if final:  # else its Python function while it compiles: ask again next call
        _FAST_ENTRIES.setdefault(robot, dict)[method] = entry
    return entry


#: The fast path's prepared entries, per robot: {method: entry} (:func:`_fast_entry`).
_FAST_ENTRIES: PerObject[dict[str, tuple]] = PerObject()
_NO_ENTRIES: dict[str, tuple] = {}
_NEW = object.__new__
_SIGN = 1 << 63
_F64 = np.dtype(np.float64)
_NDARRAY = np.ndarray
#: Strides of a C-contiguous float64 (4, 4) array.
_C44 = (32, 8)
#: The fields of a fast-path success that do not vary (copied into the new result's
#: ``__dict__``, then filled: cheaper than building the dictionary).
_SUCCESS = {"q": None, "success": True, "iterations": 0, "position_error": 0.0,
            "orientation_error": 0.0, "reason": "", "restarts": 0, "method": "",
            "clearance": np.inf, "closest_pair": ("", "")}


def _fast(robot: Robot, target: np.ndarray, method: str, q0: object,
          seed: object) -> IKResult | None:
    """:func:`solve` for the common call, or None when the call is not that one.

    The common call: one floating-point (4, 4) pose (copied to C-contiguous float64 when
    it is not), ``q0`` None or a C-contiguous float64 (n,) array, ``seed`` None or an
    int, every other argument at its default, a compiled method (or one with
    ``solve_pose``: :func:`_fast_pose`, which takes any q0). The checks of the ordinary
    path run inside the one compiled call (``solve_fast``,
    :func:`~serialkin.ik._kernels.pose_and_q0_valid`); when they fail, None, and the
    ordinary path raises its precise error. The answer is the ordinary
    path's, bit for bit (same kernel, configuration and seed). Read-only arrays are
    fine: the call only reads them.
    """
    if target.dtype is not _F64 or target.strides != _C44 or target.shape != (4, 4):
        # a pose in another layout or float type (Fortran order, as the Robotics Toolbox
        # returns it, a transposed or float32 array): copied, 0.3 µs, where the ordinary
        # path took twice as long as the fast one
        if target.shape != (4, 4) or target.dtype.kind != "f":
            return None
        target = np.ascontiguousarray(target, dtype=np.float64)
    ent = _FAST_ENTRIES.get(robot, _NO_ENTRIES).get(method)
    # the method's spec, looked up directly: a re-registered method gets a new entry
    if ent is None or ent[0] is not _REGISTRY.get(method):
        ent = _fast_entry(robot, method)
        if ent is None:
            return None
    _, solve_fast, S, zeros, strides, name = ent
    if solve_fast is None:
        return _fast_pose(robot, ent[0], S, target, q0, seed)
    if q0 is None:
        q0k = zeros
    elif (type(q0) is _NDARRAY and q0.dtype is _F64 and q0.nbytes == zeros.nbytes
          and q0.strides == strides):
        q0k = q0  # strides (8,): one dimension, contiguous; nbytes: n values
    else:
        return None
    if type(seed) is int and 0 <= seed < _SIGN:
        s = seed  # the common case: the uint64 seed's bits as an int64
    elif type(seed) is int:
        s = seed & _MASK64
        s -= (s & _SIGN) * 2
    elif seed is None:
        s = int.from_bytes(os.urandom(8), "little", signed=True)
    else:
        return None
    q = np.empty(zeros.shape[0])
    status, its, pe, oe, used = solve_fast(S, target, q0k, s, q0 is not None, q)
    if status == 1:  # IKResult.make, inlined
        r = _NEW(IKResult)
        d = r.__dict__
        d.update(_SUCCESS)
        d["q"] = q
        d["iterations"] = its
        d["position_error"] = pe
        d["orientation_error"] = oe
        d["restarts"] = used
        d["method"] = name
        return r  # turned nearest q0 (or zero) by the kernel: with_nearest_turns' rule
    if status < 0:
        return None
    reason = failure_reason(pe, oe, DEFAULT_TOL, used + 1, its, "pose",
                            failure_hint(robot, q, DEFAULT_WEIGHTS["pose"], True, target))
    return IKResult.make(q, False, its, pe, oe, reason, used, name)  # turned by the kernel


#: The flag fk_checked_range raises for a non-finite q (never, for a solver's answer).
_UNUSED = np.zeros(1, dtype=np.int64)


def _fast_pose(robot: Robot, spec: MethodSpec, limits: tuple, target: np.ndarray,
               q0: object, seed: object) -> IKResult | None:
    """:func:`_fast` for a method with ``solve_pose``: the ordinary path's answer, in scalars.

    The ordinary path's checks, in its order, for the common call: the target's compiled
    rigidity check (failing: None, and the ordinary path names the fault), then
    :func:`check_q0` (raising the ordinary path's errors); a seed other than None or an
    int takes the ordinary path (which draws from a Generator). Then
    :func:`_solve_whole`'s judgement of one answer, with the same kernels (FK of a
    (1, n) batch, ``pose_error_batch``) and the same arithmetic (the norms of three
    values summed left to right, as numpy's reduction sums them), and
    :func:`with_nearest_turns`' shift. ``limits`` is ``(lo, hi, lower, upper, wide)``:
    the kernels' read-only limits, ``robot.qlim``'s columns and :func:`_wide`.
    """
    if seed is not None and type(seed) is not int:
        return None
    T1 = readonly(target.reshape(1, 4, 4))
    if not SK.transforms_valid(T1, ROTATION_TOL):
        return None
    q0a = None if q0 is None else check_q0(robot, q0, None, True)
    q, found, why = spec.solve_pose(robot, target, q0a)
    # robot.fk of the (1, n) batch, its kernel called directly (q is finite)
    Tq, E = np.empty((1, 4, 4)), np.empty((1, 6))
    FK.fk_checked_range(q.reshape(1, -1), robot.chain.F, robot.chain.meta, Tq, _UNUSED, 0, 1)
    Tq.flags.writeable = False  # pose_error's read-only input
    SK.pose_error_batch(Tq, T1, E)
    e0, e1, e2, e3, e4, e5 = E[0].tolist()
    pe = math.sqrt(e0 * e0 + e1 * e1 + e2 * e2)
    oe = math.sqrt(e3 * e3 + e4 * e4 + e5 * e5)
    lo, hi, lower, upper, wide = limits
    inside = K.inside_limits(readonly(q), lo, hi, LIMIT_TOL)
    ok = found and pe <= DEFAULT_TOL and oe <= DEFAULT_TOL and inside
    reason = ("" if ok else why if not found else _NOT_REPRODUCED if inside else _OUTSIDE)
    if wide is not False:
        q = nearest_turn(q, lower, upper, wide, q0a)
    return IKResult.make(q, bool(ok), int(found), pe, oe, reason, 0, spec.name)


def _solve_compiled(robot: Robot, tgt: Target, spec: MethodSpec, q0: np.ndarray | None,
                    tol: float, max_iter: int, restarts: int, seed: int, respect: bool,
                    opts: Mapping[str, Any]) -> IKResult:
    box = robot_arrays(robot).box
    cfg = _kernel_config(spec, tgt, tol, max_iter, restarts, respect, q0 is not None, opts)
    F, meta = robot.chain.F, robot.chain.meta
    n = robot.n
    seed64 = np.uint64(seed)
    # the kernels are compiled for writable target / q0 arrays: copy read-only ones
    Tt = tgt.T if tgt.T.flags.writeable else tgt.T.copy()
    if not tgt.batch:
        q = np.empty(n)
        info = np.empty(K.N_INFO)
        q0k = q0 if q0 is not None and q0.flags.writeable else (
            np.zeros(n) if q0 is None else q0.copy())
        spec.kernel.solve_chunk(F, meta, Tt[None], box, q0k[None], cfg, seed64, q[None],
                                info[None], 0, 1)
        return _from_info(robot, tgt, spec, q, info, tol, respect)
    N = Tt.shape[0]
    Q = np.empty((N, n))
    info = np.empty((N, K.N_INFO))
    Q0 = np.zeros((N, n)) if q0 is None else np.array(q0, dtype=np.float64, order="C")
    _run_chunks(spec.kernel.solve_chunk, F, meta, Tt, box, Q0, cfg, seed64, Q, info)
    return _from_info(robot, tgt, spec, Q, info, tol, respect)


@dataclass(frozen=True, eq=False)
class _Collision:
    """The collision check of one solve: the model's flat arrays, pairs, scene, names."""

    active: bool
    arrays: tuple = ()
    ccfg: np.ndarray | None = None
    body_names: tuple[str, ...] = ()
    scene_names: tuple[str, ...] = ()
    scene: np.ndarray | None = None
    margin: float = 0.0


#: Push-out steps per attempt that reaches the target in collision.
PUSHES = 2


def _collision_setup(robot: Robot, spec: MethodSpec, scene: object, self_collision: object,
                     margin: object, acm: object) -> _Collision:
    """Validate the collision arguments of :func:`solve` and pack them for the kernels."""
    from serialkin._checks import check_real
    from serialkin.collision.acm import check_acm
    from serialkin.collision.queries import checked_shape_pairs
    from serialkin.collision.shapes import encode_scene

    if not isinstance(self_collision, (bool, np.bool_)):
        raise InputTypeError(f"self_collision must be True or False, got {self_collision!r}")
    margin_v = check_real(margin, "margin", unit="m")
    if margin_v < 0.0:
        raise InputError(f"margin must be >= 0 m (the clearance a solution keeps), got "
                         f"{margin_v!r}")
    if check_acm(acm) is not None and not self_collision:
        raise InputError("acm lists the body pairs a self-collision check skips; it needs "
                         "self_collision=True")
    if scene is not None and not isinstance(scene, (list, tuple)):
        scene = [scene]
    enc = np.zeros((0, 16)) if scene is None else encode_scene(scene)
    if not (self_collision or enc.shape[0]):
        return _Collision(active=False)
    model = robot.collision
    if model is None:
        raise InputError(
            f"robot {short_repr(robot.name)} has no collision model, so scene / "
            "self_collision cannot be checked; attach one with robot.with_collision(model) "
            "(e.g. serialkin.collision.panda_collision_model() for a Panda, or a "
            "CollisionModel.from_dicts(...) of your capsules)")
    if spec.kernel is None:
        compiled = [m for m in available_methods() if get_method(m).kernel is not None]
        raise InputError(
            f"collision-aware IK (scene / self_collision) runs in the compiled loop of the "
            f"Jacobian-family methods; method {spec.name!r} is not one of them: use one of "
            f"{', '.join(compiled)}")
    if self_collision:
        pa, pb = checked_shape_pairs(model, acm)
    else:  # read-only as the pairs are: a scene-only solve compiles no second loop
        pa = pb = readonly(np.zeros(0, dtype=np.int64))
    arrays = (np.ascontiguousarray(model.shape_frame), model.a, model.b, model.radius,
              model.shape_body, pa, pb, enc)
    names = tuple((getattr(s, "name", "") or f"scene[{i}]") for i, s in enumerate(scene or ()))
    ccfg = np.empty(K.N_CCFG)
    ccfg[K.K_MARGIN] = margin_v
    ccfg[K.K_PUSHES] = PUSHES
    return _Collision(active=True, arrays=arrays, ccfg=ccfg, body_names=model.body_names,
                      scene_names=names, scene=enc, margin=margin_v)


def _pair_names(coll: _Collision, info: np.ndarray) -> tuple[str, str]:
    """The closest pair of ``info`` (N_INFO,) as names."""
    from serialkin.collision.queries import PAIR_SCENE, PAIR_SELF

    kind, i, j = int(info[K.I_PAIR]), int(info[K.I_PAIR + 1]), int(info[K.I_PAIR + 2])
    if kind == PAIR_SELF:
        return str(coll.body_names[i]), str(coll.body_names[j])
    if kind == PAIR_SCENE:
        return str(coll.body_names[i]), str(coll.scene_names[j])
    return "", ""


def _collision_reason(robot: Robot, coll: _Collision, tgt_T: np.ndarray, q: np.ndarray,
                      info: np.ndarray, pair: tuple[str, str], tol: float, kind: str,
                      respect: bool, weights: np.ndarray) -> str:
    """Why a collision-aware solve failed (the sentence of ``IKResult.reason``)."""
    from serialkin.collision.queries import scene_point_distance

    pe, oe = float(info[K.I_POS_ERR]), float(info[K.I_ORI_ERR])
    its, used = int(info[K.I_ITERATIONS]), int(info[K.I_RESTARTS])
    d = float(info[K.I_CLEARANCE])
    if not (pe <= tol and oe <= tol):
        return failure_reason(pe, oe, tol, used + 1, its, kind,
                              failure_hint(robot, q, weights, respect, tgt_T))
    where = ""
    if coll.scene is not None and coll.scene.shape[0] and weights[:3].all():
        p = np.ascontiguousarray(tgt_T[:3, 3], dtype=np.float64)
        for o in range(coll.scene.shape[0]):
            if scene_point_distance(p, coll.scene, o) < 0.0:
                name = str(coll.scene_names[o])
                where = (f"; the target position lies inside obstacle {name!r}, "
                         "so no collision-free solution exists")
                break
    where = where or ("; the margin may be larger than the free space around the target, or "
                      "more restarts are needed")
    return (f"every attempt that reached the target collided ({used + 1} attempt(s), "
            f"{its} iterations): best clearance {d:.3g} m < margin {coll.margin:g} m, "
            f"closest pair {str(pair[0])!r}–{str(pair[1])!r}{where}")


def _solve_collision(robot: Robot, tgt: Target, spec: MethodSpec, q0: np.ndarray | None,
                     tol: float, max_iter: int, restarts: int, seed: int, respect: bool,
                     opts: Mapping[str, Any], coll: _Collision) -> IKResult:
    """The compiled collision-aware solve (single target or batch on every core)."""
    box = robot_arrays(robot).box
    cfg = _kernel_config(spec, tgt, tol, max_iter, restarts, respect, q0 is not None, opts)
    F, L, meta = robot.chain.F, robot.chain.L, robot.chain.meta
    n = robot.n
    seed64 = np.uint64(seed)
    Tt = np.array(tgt.T, dtype=np.float64, order="C")
    if not tgt.batch:
        q = np.empty(n)
        info = np.empty(K.N_INFO)
        q0k = np.zeros(n) if q0 is None else np.array(q0, dtype=np.float64)
        spec.kernel.solve_chunk_collision(F, L, meta, Tt[None], box, q0k[None], cfg, seed64,
                                          *coll.arrays, coll.ccfg, q[None], info[None], 0, 1)
        return _from_info(robot, tgt, spec, q, info, tol, respect, coll)
    N = Tt.shape[0]
    Q = np.empty((N, n))
    info = np.empty((N, K.N_INFO))
    Q0 = np.zeros((N, n)) if q0 is None else np.array(q0, dtype=np.float64, order="C")
    parallel.run(spec.kernel.solve_chunk_collision,
                 (F, L, meta, Tt, box, Q0, cfg, seed64, *coll.arrays, coll.ccfg, Q, info),
                 N, grain=4)
    return _from_info(robot, tgt, spec, Q, info, tol, respect, coll)


def _run_chunks(solve_chunk: Any, F: np.ndarray, meta: np.ndarray, Tt: np.ndarray, box: np.ndarray,
                Q0: np.ndarray, cfg: np.ndarray, seed64: np.uint64, Q: np.ndarray,
                info: np.ndarray) -> None:
    """Solve a batch with the method's ``solve_chunk`` on every core.

    Scheduled by :func:`serialkin.kinematics.parallel.run` (guided chunks of at least 8
    targets claimed dynamically, so a few slow targets or a busy core do not leave the
    batch waiting); fewer than :data:`PARALLEL_MIN_TARGETS` targets run on the calling
    thread.
    """
    parallel.run(solve_chunk, (F, meta, Tt, box, Q0, cfg, seed64, Q, info), Tt.shape[0],
                 grain=8, min_items=PARALLEL_MIN_TARGETS)


#: Batches of fewer targets are solved on the calling thread: waking a second thread
#: costs more than it saves (UR5 ``lm``, 2 cores: 16, 40, 100 targets took 2.2×, 1.5×,
#: 1.0× as long on two threads as on one; 400 targets 0.74×).
PARALLEL_MIN_TARGETS = 128


def _kernel_config(spec: MethodSpec, tgt: Target, tol: float, max_iter: int, restarts: int,
                   respect: bool, use_q0: bool, opts: Mapping[str, Any]) -> np.ndarray:
    """The kernel configuration vector ``cfg`` (see :mod:`serialkin.ik._kernels`).

    With default weights and options the vector is cached (the kernels never write it).
    """
    key = None
    if opts is spec.options and tgt.weights is DEFAULT_WEIGHTS.get(tgt.kind):
        key = (spec.name, id(spec), tgt.kind, tol, max_iter, restarts, respect, use_q0)
        cfg = _CONFIGS.get(key)
        if cfg is not None:
            return cfg
    tail = _method_params(spec, opts)
    cfg = np.empty(K.C_WINDOW + tail.shape[0])
    cfg[K.C_WEIGHTS:K.C_WEIGHTS + 6] = tgt.weights
    cfg[K.C_TOL] = tol
    cfg[K.C_MAX_ITER] = max_iter
    cfg[K.C_RESTARTS] = restarts
    cfg[K.C_RESPECT] = 1.0 if respect else 0.0
    cfg[K.C_USE_Q0] = 1.0 if use_q0 else 0.0
    cfg[K.C_WINDOW:] = tail
    # read-only, as the fast path's packed copy is: the kernels see one array type
    # whichever path called them, and compile once
    cfg.setflags(write=False)
    if key is not None:
        if len(_CONFIGS) > 256:
            _CONFIGS.clear()
        _CONFIGS[key] = cfg
    return cfg


#: Tolerance of the final "q inside the joint limits" test of a success [rad or m].
LIMIT_TOL = K.LIMIT_TOL

_OUTSIDE = ("the configuration found lies outside the joint limits; the target may be "
            "reachable only outside them")


def honest_success(robot: Robot, q: np.ndarray, ok: bool, respect: bool) -> bool:
    """The final guard of every method: a success with ``respect`` has q inside the limits.

    Limits are intervals with possibly infinite ends (:mod:`serialkin.model.limits`).
    """
    if not ok or not respect:
        return ok
    a = robot_arrays(robot)
    return bool(K.inside_limits(readonly(np.ascontiguousarray(q, dtype=np.float64)), a.lo, a.hi,
                                LIMIT_TOL))


def _from_info(robot: Robot, tgt: Target, spec: MethodSpec, Q: np.ndarray, info: np.ndarray,
               tol: float, respect: bool, coll: _Collision | None = None) -> IKResult:
    """The one builder of a compiled solve's :class:`IKResult`, from the kernels' records.

    ``Q`` (n,) or (N, n) holds the configurations and ``info`` (N_INFO,) or (N, N_INFO)
    the kernels' records (the ``I_*`` indices of :mod:`serialkin.ik._kernels`), one per
    target: a single result for one target, arrays for a batch. A success needs the
    kernel's success flag and, with ``respect``, q inside the limits (the final guard of
    :func:`honest_success`, evaluated by the kernel). Each failure gets its sentence
    (:func:`failure_reason`, or with the collision check ``coll`` the closest pair's);
    with ``coll`` the clearance and closest pair are filled too.
    """
    single = info.ndim == 1
    rec = info.reshape(-1, K.N_INFO)
    Qs = Q.reshape(-1, Q.shape[-1])
    Ts = tgt.T.reshape(-1, 4, 4)
    ok = rec[:, K.I_SUCCESS] > 0.5
    if respect:
        ok &= rec[:, K.I_INSIDE] > 0.5
    its = rec[:, K.I_ITERATIONS].astype(np.int64)
    used = rec[:, K.I_RESTARTS].astype(np.int64)
    pe, oe = rec[:, K.I_POS_ERR].copy(), rec[:, K.I_ORI_ERR].copy()
    pairs = None if coll is None else [_pair_names(coll, rec[k]) for k in range(len(rec))]

    def reason(k: int) -> str:
        if coll is not None:
            return _collision_reason(robot, coll, Ts[k], Qs[k], rec[k], pairs[k], tol,
                                     tgt.kind, respect, tgt.weights)
        return failure_reason(pe[k], oe[k], tol, used[k] + 1, its[k], tgt.kind,
                              failure_hint(robot, Qs[k], tgt.weights, respect, Ts[k]))

    failed = np.flatnonzero(~ok)
    said = [reason(int(k)) for k in failed]  # a sentence for each failure only
    extra = {} if coll is None else {"clearance": rec[:, K.I_CLEARANCE].copy(),
                                     "closest_pair": np.array(pairs, dtype=str).reshape(-1, 2)}
    # the str array np.array(list of N str) makes, without building it from N objects
    reasons = np.zeros(Qs.shape[0], dtype=f"<U{max(map(len, said), default=1) or 1}")
    reasons[failed] = said
    return IKResult.of_rows(not single, spec.name, q=Qs, success=ok, iterations=its,
                            position_error=pe, orientation_error=oe, reason=reasons,
                            restarts=used, **extra)


def _problem(robot: Robot, T: np.ndarray, tgt: Target, tol: float, respect: bool) -> IKProblem:
    lo, hi, _, _, revolute = _limits(robot, respect)
    if not respect:
        lo = readonly(np.full(robot.n, -np.inf))
        hi = readonly(np.full(robot.n, np.inf))
    # read-only, as the cached limits are: the methods' kernels compile once
    return IKProblem(robot=robot, T_target=readonly(np.ascontiguousarray(T)), weights=tgt.weights,
                     kind=tgt.kind, tol=tol, respect_limits=respect, lower=lo, upper=hi,
                     revolute=revolute)


def _solve_python(robot: Robot, tgt: Target, spec: MethodSpec, q0: np.ndarray | None,
                  tol: float, max_iter: int, restarts: int, seed: int, respect: bool,
                  opts: Mapping[str, Any]) -> IKResult:
    """A Python method's solve, for one target or a batch.

    The shared attempt loop per target, or the method's own ``solve`` over every target
    at once (then errors and success are measured here, :func:`_solve_whole`).
    """
    Ts = tgt.T[None] if not tgt.batch else tgt.T
    if spec.solve is not None:
        return _solve_whole(robot, tgt, spec, Ts, q0, tol, respect, opts)
    rows = []
    for k in range(Ts.shape[0]):
        problem = _problem(robot, Ts[k], tgt, tol, respect)
        qk = None if q0 is None else (q0 if q0.ndim == 1 else q0[k])
        rows.append(run_attempts(spec, problem, qk, max_iter, restarts, seed, opts))
    q, ok, its, pe, oe, reason, used = zip(*rows, strict=True)
    return IKResult.of_rows(
        tgt.batch, spec.name, q=np.array(q), success=np.array(ok, dtype=bool),
        iterations=np.array(its, dtype=np.int64), position_error=np.array(pe),
        orientation_error=np.array(oe), reason=np.array(reason, dtype=object).astype(str),
        restarts=np.array(used, dtype=np.int64))


#: Why a closed-form answer that does not reproduce its target failed.
_NOT_REPRODUCED = "the closed-form solution does not reproduce the target within tol"


def _solve_whole(robot: Robot, tgt: Target, spec: MethodSpec, Ts: np.ndarray,
                 q0: np.ndarray | None, tol: float, respect: bool,
                 opts: Mapping[str, Any]) -> IKResult:
    """Run ``spec.solve`` on every target ``Ts`` (N, 4, 4) at once; measure and judge.

    Errors are those of :meth:`IKProblem.errors` (the selected coordinates of
    ``[p_t − p; log(R_t Rᵀ)^∨]``), for all answers at once; a found answer succeeds when
    both errors are within ``tol`` and, with ``respect``, it lies inside the limits.
    """
    from serialkin.spatial.pose import pose_error

    N = Ts.shape[0]
    q0s = None if q0 is None else np.broadcast_to(q0, (N, robot.n))
    Q, found, why = spec.solve(robot, Ts, tgt.kind, q0s, opts)
    Q = np.ascontiguousarray(Q, dtype=np.float64)
    E = pose_error(robot.fk(Q), Ts, check=False)  # (N, 6)
    sel = tgt.weights > 0.0
    pe = np.linalg.norm(E[:, :3] * sel[:3], axis=1)
    oe = np.linalg.norm(E[:, 3:] * sel[3:], axis=1)
    ok = found & (pe <= tol) & (oe <= tol)
    reasons = np.where(found, _NOT_REPRODUCED, why)
    if respect:
        inside = np.asarray(robot.within_limits(Q, LIMIT_TOL))
        reasons = np.where(found & ~inside, _OUTSIDE, reasons)
        ok &= inside
    reasons = np.where(ok, "", reasons)
    return IKResult.of_rows(tgt.batch, spec.name, q=Q, success=ok,
                            iterations=found.astype(np.int64), position_error=pe,
                            orientation_error=oe, reason=reasons.astype(str),
                            restarts=np.zeros(N, dtype=np.int64))
