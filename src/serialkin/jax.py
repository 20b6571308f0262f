"""Forward kinematics, Jacobians and IK as differentiable JAX functions (extra ``[jax]``).

``fk``, ``jacobian`` and ``ik`` are :func:`jax.custom_vjp` functions whose forward is a
:func:`jax.pure_callback` into the robot's compiled kernels, so they work under
:func:`jax.jit`, :func:`jax.grad` and :func:`jax.vmap` (the callbacks take any leading
batch shape: ``vmap_method="expand_dims"`` for ``fk``/``jacobian``, ``"broadcast_all"``
for ``ik``). Values are computed in float64 and returned in the input's dtype: in float64
(``jax.config.update("jax_enable_x64", True)``) ``fk(robot, q)`` equals ``robot.fk(q)``
bit for bit; without x64 JAX arrays are float32.

Backward passes (equations in :mod:`serialkin.autograd.core`): ``fk`` by the geometric
Jacobian (computed in the same callback as the pose and kept as the residual), ``jacobian``
by the kinematic Hessian contracted as a prefix and a suffix sum over the columns (both
in ``jax.numpy``, fused by XLA), ``ik`` by the implicit function theorem with the
singular-value-damped pseudo-inverse (a second callback). Reverse mode only, first order
(a ``custom_vjp`` has no forward mode, and the callbacks are not differentiated again).

Example::

    import jax, jax.numpy as jnp, serialkin as sk
    from serialkin import jax as skj
    robot = sk.models.get("panda")
    loss = lambda q: jnp.sum(skj.fk(robot, q)[..., :3, 3] ** 2)
    g = jax.jit(jax.grad(loss))(jnp.zeros((32, 7)))   # (32, 7)
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any, NamedTuple

import numpy as np

try:
    import jax
    import jax.numpy as jnp
except ImportError as exc:  # pragma: no cover - exercised in a subprocess by the tests
    raise ImportError('serialkin.jax needs JAX, which the extra installs: '
                      'pip install "serialkin[jax]"') from exc

from serialkin._memo import PerObject
from serialkin.autograd import core
from serialkin.errors import InputError, InputTypeError
from serialkin.model.robot import Robot, check_robot

__all__ = ["IKSolution", "fk", "ik", "jacobian"]


class IKSolution(NamedTuple):
    """What :func:`ik` returns: the solutions and a convergence flag per target.

    Attributes:
        q: (..., n) joint values [rad / m] in the target's dtype; rows that did not
            converge hold the solver's best attempt.
        success: (...) bool array, False on every row that failed to converge (its
            gradient is then that of an attempt, not of a solution: mask it out).
    """

    q: jax.Array
    success: jax.Array


def _check_array(x: object, name: str) -> jax.Array:
    """``x`` as a JAX array of a real floating dtype; else InputTypeError naming ``name``."""
    try:
        a = jnp.asarray(x)
    except TypeError:
        raise InputTypeError(f"{name} must be an array of real numbers, got "
                             f"{type(x).__name__}") from None
    if not jnp.issubdtype(a.dtype, jnp.floating):
        raise InputTypeError(f"{name} must be a floating-point array (float32 or float64), "
                             f"got dtype {a.dtype}")
    return a


def _check_q(robot: Robot, q: jax.Array) -> None:
    """InputError when q's last axis is not of the robot's length (checked while tracing)."""
    if q.ndim == 0 or q.shape[-1] != robot.n:
        raise InputError(f"q has shape {q.shape} but robot {robot.name!r} has {robot.n} "
                         f"joints (expected shape (..., {robot.n}))")


def _fk_vjp(T: jax.Array, J: jax.Array, G: jax.Array) -> jax.Array:
    """``∂L/∂q = Jᵀ [Ḡ_p; w]`` (..., n) from T (..., 4, 4), J (..., 6, n), Ḡ (..., 4, 4)."""
    M = T[..., :3, :3] @ jnp.swapaxes(G[..., :3, :3], -1, -2)  # R Ḡ_Rᵀ
    w = jnp.stack([M[..., 1, 2] - M[..., 2, 1], M[..., 2, 0] - M[..., 0, 2],
                   M[..., 0, 1] - M[..., 1, 0]], axis=-1)
    g6 = jnp.concatenate([G[..., :3, 3], w], axis=-1)
    return jnp.einsum("...in,...i->...n", J, g6)


def _jacobian_vjp(J: jax.Array, G: jax.Array) -> jax.Array:
    """``∂L/∂q_k = ω_k·Σ_{j>k}(v_j×Ḡv_j + ω_j×Ḡω_j) + v_k·Σ_{j≤k}(Ḡv_j×ω_j)``, (..., n)."""
    v, w = jnp.swapaxes(J[..., :3, :], -1, -2), jnp.swapaxes(J[..., 3:, :], -1, -2)
    Gv, Gw = jnp.swapaxes(G[..., :3, :], -1, -2), jnp.swapaxes(G[..., 3:, :], -1, -2)
    a = jnp.cross(v, Gv) + jnp.cross(w, Gw)
    b = jnp.cross(Gv, w)
    after = jnp.flip(jnp.cumsum(jnp.flip(a, -2), -2), -2) - a  # Σ_{j>k}
    return (w * after).sum(-1) + (v * jnp.cumsum(b, -2)).sum(-1)


def _callback(f: Callable[..., Any], shapes: Any, *args: Any, vmap_method: str) -> Any:
    """``jax.pure_callback(f, shapes, *args)`` with the given ``vmap_method``."""
    return jax.pure_callback(f, shapes, *args, vmap_method=vmap_method)


class _Ops(NamedTuple):
    """The custom_vjp functions ``fk(q)`` and ``jacobian(q)`` of one robot."""

    fk: Callable[[jax.Array], jax.Array]
    jacobian: Callable[[jax.Array], jax.Array]


_OPS: PerObject[_Ops] = PerObject()


def _make_ops(robot: Robot) -> _Ops:
    """Build the custom_vjp ``fk`` and ``jacobian`` of ``robot`` (kept per robot in _OPS)."""
    n = robot.n

    def pose_shape(q: Any) -> jax.ShapeDtypeStruct:
        return jax.ShapeDtypeStruct(q.shape[:-1] + (4, 4), q.dtype)

    def jac_shape(q: Any) -> jax.ShapeDtypeStruct:
        return jax.ShapeDtypeStruct(q.shape[:-1] + (6, n), q.dtype)

    def fk_host(q: Any) -> np.ndarray:
        return robot.fk(core.as_float64(q)).astype(q.dtype)

    def fk_jac_host(q: Any) -> tuple[np.ndarray, np.ndarray]:
        T, J = core.fk_and_jacobian(robot, core.as_float64(q))
        return T.astype(q.dtype), J.astype(q.dtype)

    def jac_host(q: Any) -> np.ndarray:
        return robot.jacobian(core.as_float64(q)).astype(q.dtype)

    @jax.custom_vjp
    def fk(q: jax.Array) -> jax.Array:
        return _callback(fk_host, pose_shape(q), q, vmap_method="expand_dims")

    def fk_fwd(q: jax.Array) -> tuple[jax.Array, tuple[jax.Array, jax.Array]]:
        T, J = _callback(fk_jac_host, (pose_shape(q), jac_shape(q)), q,
                         vmap_method="expand_dims")
        return T, (T, J)

    def fk_bwd(res: tuple[jax.Array, jax.Array], G: jax.Array) -> tuple[jax.Array]:
        T, J = res
        return (_fk_vjp(T, J, G),)

    fk.defvjp(fk_fwd, fk_bwd)

    @jax.custom_vjp
    def jacobian(q: jax.Array) -> jax.Array:
        return _callback(jac_host, jac_shape(q), q, vmap_method="expand_dims")

    def jac_fwd(q: jax.Array) -> tuple[jax.Array, jax.Array]:
        J = jacobian(q)
        return J, J

    def jac_bwd(J: jax.Array, G: jax.Array) -> tuple[jax.Array]:
        return (_jacobian_vjp(J, G),)

    jacobian.defvjp(jac_fwd, jac_bwd)
    return _Ops(fk, jacobian)


def _ops(robot: object) -> _Ops:
    """The custom_vjp functions of ``robot`` (built once per robot)."""
    robot = check_robot(robot)
    return _OPS.setdefault(robot, lambda: _make_ops(robot))


def fk(robot: Robot, q: object) -> jax.Array:
    """Tool pose ``T = base · A_1(q_1) ··· A_n(q_n) · tool`` (eqs 10-11), differentiable in q.

    Args:
        robot: the robot.
        q: (..., n) floating-point array of joint values [rad / m].

    Returns:
        (..., 4, 4) homogeneous transforms ``T_world_ee`` in q's dtype; in float64 equal
        to ``robot.fk(q)``. Reverse-mode derivative: ``∂L/∂q = Jᵀ [Ḡ_p; w]``.

    Raises:
        InputTypeError: robot not a Robot, q not a floating-point array.
        InputError: q of the wrong length (non-finite values raise inside the callback,
            outside jit only).
    """
    ops = _ops(robot)
    a = _check_array(q, "q")
    _check_q(robot, a)
    return ops.fk(a)


def jacobian(robot: Robot, q: object) -> jax.Array:
    """World-frame geometric Jacobian (eqs 33-36), rows ``[v; ω]``, differentiable in q.

    Args:
        robot: the robot.
        q: (..., n) floating-point array of joint values [rad / m].

    Returns:
        (..., 6, n) in q's dtype; in float64 equal to ``robot.jacobian(q)``. Reverse-mode
        derivative: the contraction with the kinematic Hessian.

    Raises:
        InputTypeError: robot not a Robot, q not a floating-point array.
        InputError: q of the wrong length.
    """
    ops = _ops(robot)
    a = _check_array(q, "q")
    _check_q(robot, a)
    return ops.jacobian(a)


def ik(robot: Robot, T: object, q0: object, *, method: str = "lm",
       damping: float = core.DEFAULT_DAMPING, seed: Any = None, **options: Any) -> IKSolution:
    """Inverse kinematics ``q*`` with ``fk(q*) = T``, differentiable in the target T.

    As :func:`serialkin.torch.ik`: the forward is ``robot.ik(T, method, q0=q0, seed=seed,
    **options)`` on every target (one batch, in a callback); the reverse-mode derivative
    is the implicit function theorem ``dq = J^# δx`` with ``J^# = Σ_i f(σ_i) v_i u_iᵀ``,
    ``f(σ) = 1/σ`` for ``σ ≥ damping`` and ``σ/damping²`` below
    (:func:`serialkin.autograd.core.damped_pinv`): exact away from singularities (for a
    redundant arm the minimum-norm change, which the 'pinv' method makes when re-solving
    from q*), finite near one. The derivative with
    respect to q0 is zero.

    Args:
        robot: the robot.
        T: (..., 4, 4) floating-point array of target poses ``T_world_ee``.
        q0: (n,) or (..., n) initial guesses, leading shape broadcast against T's.
        method: an IK method name (default 'lm').
        damping: ε of the damped pseudo-inverse, > 0 [units of J] (default 1e-2).
        seed: seed of the solver's random restarts (None or int; a fixed seed keeps the
            function pure, as ``pure_callback`` assumes).
        **options: further options of :func:`serialkin.ik.solve` (``tol``, ``max_iter``,
            ``restarts``, ``respect_limits`` ...).

    Returns:
        :class:`IKSolution` ``(q, success)``: q (..., n) in T's dtype, success (...) bool.

    Raises:
        InputTypeError: robot not a Robot, T not a floating-point array.
        InputError: T not (..., 4, 4), q0 of the wrong shape, a bad damping. Errors of
            the solve itself (q0 outside the limits, an unknown option) raise inside the
            callback.
    """
    robot = check_robot(robot)
    d = core.check_damping(damping)
    Ta, q0a = _check_ik_arrays(robot, T, q0)
    solve = _ik_function(robot, method, seed, dict(options), d, Ta.dtype)
    q, ok = solve(Ta, q0a)
    return IKSolution(q, ok)


def _check_ik_arrays(robot: Robot, T: object, q0: object) -> tuple[jax.Array, jax.Array]:
    """The targets (..., 4, 4) and the starts (..., n) of :func:`ik`, in T's dtype.

    Raises:
        InputTypeError: T not a floating-point array.
        InputError: T not (..., 4, 4), q0 not (..., n) or not broadcast against T.
    """
    Ta = _check_array(T, "T")
    if Ta.ndim < 2 or Ta.shape[-2:] != (4, 4):
        raise InputError(f"T must have shape (..., 4, 4), got {Ta.shape}")
    q0a = jnp.asarray(q0, dtype=Ta.dtype)
    if q0a.ndim == 0 or q0a.shape[-1] != robot.n:
        raise InputError(f"q0 must have shape (..., {robot.n}) for robot {robot.name!r}, "
                         f"got {q0a.shape}")
    try:
        np.broadcast_shapes(Ta.shape[:-2], q0a.shape[:-1])
    except ValueError:
        raise InputError(f"q0's leading shape {q0a.shape[:-1]} does not broadcast against "
                         f"T's {Ta.shape[:-2]}") from None
    return Ta, q0a


def _sum_to_shape(G: jax.Array, T: jax.Array) -> jax.Array:
    """``G`` summed over the dimensions that broadcasting added to ``T`` or stretched in it.

    The cotangent of a broadcast input: leading extra axes summed away, axes where T has
    length 1 summed with ``keepdims``.
    """
    extra = G.ndim - T.ndim
    G = G.sum(axis=tuple(range(extra))) if extra else G
    ones = tuple(i for i, (m, k) in enumerate(zip(G.shape, T.shape)) if k == 1 and m != 1)
    return G.sum(axis=ones, keepdims=True) if ones else G


def _ik_function(robot: Robot, method: str, seed: Any, options: dict[str, Any], d: float,
                 dtype: Any) -> Callable[[jax.Array, jax.Array], tuple[jax.Array, jax.Array]]:
    """The custom_vjp ``solve(T, q0) -> (q, success)`` of :func:`ik`, results in ``dtype``.

    Forward: ``core.solve_ik`` in a callback; reverse: the target cotangent of
    ``core.ik_target_cotangent`` with damping ``d``, zero for q0.
    """

    def solve_host(T: Any, q0: Any) -> tuple[np.ndarray, np.ndarray]:
        q, ok = core.solve_ik(robot, core.as_float64(T), core.as_float64(q0), method, seed,
                              options)
        return q.astype(dtype), ok

    def cotangent_host(T: Any, q: Any, g: Any) -> np.ndarray:
        G = core.ik_target_cotangent(robot, core.as_float64(T), core.as_float64(q),
                                     core.as_float64(g), d)
        return G.astype(dtype)

    def shapes(lead: tuple[int, ...]) -> tuple[jax.ShapeDtypeStruct, jax.ShapeDtypeStruct]:
        return (jax.ShapeDtypeStruct(lead + (robot.n,), dtype),
                jax.ShapeDtypeStruct(lead, jnp.bool_))

    @jax.custom_vjp
    def solve(T: jax.Array, q0: jax.Array) -> tuple[jax.Array, jax.Array]:
        lead = np.broadcast_shapes(T.shape[:-2], q0.shape[:-1])
        return _callback(solve_host, shapes(lead), T, q0, vmap_method="broadcast_all")

    def solve_fwd(T: jax.Array, q0: jax.Array) -> tuple[Any, Any]:
        q, ok = solve(T, q0)
        return (q, ok), (T, q0, q)

    def solve_bwd(res: Any, cotangents: Any) -> tuple[jax.Array, jax.Array]:
        T, q0, q = res
        gq = cotangents[0]
        G = _callback(cotangent_host, jax.ShapeDtypeStruct(q.shape[:-1] + (4, 4), dtype),
                      T, q, gq, vmap_method="broadcast_all")
        return _sum_to_shape(G, T), jnp.zeros_like(q0)

    solve.defvjp(solve_fwd, solve_bwd)
    return solve
