"""Forward kinematics, Jacobians and IK as differentiable PyTorch operations (extra ``[torch]``).

``fk``, ``jacobian`` and ``ik`` are :class:`torch.autograd.Function` objects over tensors of any
leading batch shape ``(...)``. The forward runs the compiled kernels of the robot in
float64 (a float32 input is computed in float64 and the result cast back), so in float64
``fk(robot, q)`` equals ``robot.fk(q)`` bit for bit. The backward passes are analytic
(equations in :mod:`serialkin.autograd.core`):

* ``fk``: the vector-Jacobian product ``∂L/∂q = Jᵀ [Ḡ_p; w]`` with the geometric Jacobian;
* ``jacobian``: the contraction of ``∂L/∂J`` with the kinematic Hessian, as a prefix and
  a suffix sum over the columns (no (6, n, n) array);
* ``ik``: the implicit function theorem, ``dq = J^# δx`` with the singular-value-damped
  pseudo-inverse J^# (exact where every singular value of J is at least ``damping``,
  the minimum-norm change for a redundant arm, bounded near a singularity).

A first-order backward runs in numpy (float64, the formulas of
:func:`serialkin.autograd.core.fk_vjp` and :func:`~serialkin.autograd.core.jacobian_vjp`).
With ``create_graph=True`` the backward of ``fk`` and ``jacobian`` runs the same formulas
in torch operations instead, so they can be differentiated again (a Hessian-vector
product through ``fk`` runs the ``jacobian`` backward); ``ik``'s backward is first order
only. Computation is on the CPU; a tensor on another device is copied to the CPU and
the result copied back.

Example::

    import torch, serialkin as sk
    from serialkin import torch as skt
    robot = sk.models.get("panda")
    q = torch.zeros(32, 7, dtype=torch.float64, requires_grad=True)
    T = skt.fk(robot, q)                      # (32, 4, 4)
    T[..., :3, 3].square().sum().backward()   # q.grad (32, 7)
"""

from __future__ import annotations

from typing import Any, NamedTuple

import numpy as np

try:
    import torch
    from torch.autograd.function import once_differentiable
except ImportError as exc:  # pragma: no cover - exercised in a subprocess by the tests
    raise ImportError('serialkin.torch needs PyTorch, which the extra installs: '
                      'pip install "serialkin[torch]"') from exc

from serialkin._checks import as_float_array
from serialkin.autograd import core
from serialkin.errors import InputTypeError
from serialkin.model.robot import Robot, check_robot

__all__ = ["IKSolution", "fk", "ik", "jacobian"]


class IKSolution(NamedTuple):
    """What :func:`ik` returns: the solutions and a convergence flag per target.

    Attributes:
        q: (..., n) joint values [rad / m], the dtype and device of the target; rows that
            did not converge hold the solver's best attempt.
        success: (...) bool tensor, False on every row that failed to converge (its
            gradient is then that of an attempt, not of a solution: mask it out).
    """

    q: torch.Tensor
    success: torch.Tensor


def _check_tensor(x: object, name: str) -> torch.Tensor:
    """``x`` if it is a real floating-point tensor; else InputTypeError naming ``name``."""
    if not isinstance(x, torch.Tensor):
        raise InputTypeError(f"{name} must be a torch.Tensor, got {type(x).__name__} "
                             "(torch.as_tensor converts arrays)")
    if not x.is_floating_point():
        raise InputTypeError(f"{name} must be a floating-point tensor (float32 or float64), "
                             f"got dtype {x.dtype}")
    return x


def _numpy64(x: torch.Tensor) -> np.ndarray:
    """A detached CPU float64 numpy copy (or view) of ``x``."""
    x = x.detach().cpu()
    return core.as_float64((x if _numpy_dtype(x.dtype) else x.double()).numpy())


def _numpy_dtype(dtype: torch.dtype) -> Any:
    """The numpy dtype of a torch dtype (None for one numpy lacks, e.g. bfloat16)."""
    return {torch.float64: np.float64, torch.float32: np.float32,
            torch.float16: np.float16}.get(dtype)


def _like(a: np.ndarray, x: torch.Tensor) -> torch.Tensor:
    """``a`` as a tensor with the dtype and device of ``x``.

    The cast is numpy's where it can be: a torch operation on a large tensor starts
    torch's intra-op threads, which then compete with the kernels' threads for the cores
    (on 2 cores one such cast cost ~20 ms instead of 0.1 ms).
    """
    np_dtype = _numpy_dtype(x.dtype)
    t = torch.from_numpy(a.astype(np_dtype, copy=False) if np_dtype is not None else a)
    return t if t.dtype == x.dtype and x.device.type == "cpu" else t.to(x.dtype).to(x.device)


def _fk_vjp(T: torch.Tensor, J: torch.Tensor, G: torch.Tensor) -> torch.Tensor:
    """``∂L/∂q = Jᵀ [Ḡ_p; w]`` (..., n) from T (..., 4, 4), J (..., 6, n), Ḡ (..., 4, 4)."""
    M = T[..., :3, :3] @ G[..., :3, :3].transpose(-1, -2)  # R Ḡ_Rᵀ
    w = torch.stack([M[..., 1, 2] - M[..., 2, 1], M[..., 2, 0] - M[..., 0, 2],
                     M[..., 0, 1] - M[..., 1, 0]], dim=-1)
    g6 = torch.cat([G[..., :3, 3], w], dim=-1)
    return (J * g6[..., :, None]).sum(-2)


def _jacobian_vjp(J: torch.Tensor, G: torch.Tensor) -> torch.Tensor:
    """``∂L/∂q_k = ω_k·Σ_{j>k}(v_j×Ḡv_j + ω_j×Ḡω_j) + v_k·Σ_{j≤k}(Ḡv_j×ω_j)``, (..., n)."""
    v, w = J[..., :3, :].transpose(-1, -2), J[..., 3:, :].transpose(-1, -2)  # (..., n, 3)
    Gv, Gw = G[..., :3, :].transpose(-1, -2), G[..., 3:, :].transpose(-1, -2)
    a = torch.linalg.cross(v, Gv, dim=-1) + torch.linalg.cross(w, Gw, dim=-1)
    b = torch.linalg.cross(Gv, w, dim=-1)
    after = torch.flip(torch.cumsum(torch.flip(a, (-2,)), -2), (-2,)) - a  # Σ_{j>k}
    upto = torch.cumsum(b, -2)  # Σ_{j≤k}
    return (w * after).sum(-1) + (v * upto).sum(-1)


class _FK(torch.autograd.Function):
    """T(q) by ``robot.fk``; backward by the geometric Jacobian."""

    @staticmethod
    def forward(ctx: Any, robot: Robot, q: torch.Tensor) -> torch.Tensor:
        q64 = _numpy64(q)
        T64 = robot.fk(q64)
        T = _like(T64, q)
        ctx.robot, ctx.q64, ctx.T64 = robot, q64, T64
        ctx.save_for_backward(q, T)
        return T

    @staticmethod
    def backward(ctx: Any, G: torch.Tensor) -> tuple[None, torch.Tensor | None]:
        if not ctx.needs_input_grad[1]:
            return None, None
        q, T = ctx.saved_tensors
        if torch.is_grad_enabled():  # create_graph: stay differentiable (J by _Jacobian)
            return None, _fk_vjp(T, _Jacobian.apply(ctx.robot, q), G)
        # first order: in numpy (float64), away from torch's thread pool (see _like)
        return None, _like(core.fk_vjp(ctx.T64, ctx.robot.jacobian(ctx.q64), _numpy64(G)), q)


class _Jacobian(torch.autograd.Function):
    """J(q) by ``robot.jacobian``; backward by the kinematic Hessian."""

    @staticmethod
    def forward(ctx: Any, robot: Robot, q: torch.Tensor) -> torch.Tensor:
        J64 = robot.jacobian(_numpy64(q))
        J = _like(J64, q)
        ctx.J64 = J64
        ctx.save_for_backward(J)
        return J

    @staticmethod
    def backward(ctx: Any, G: torch.Tensor) -> tuple[None, torch.Tensor | None]:
        if not ctx.needs_input_grad[1]:
            return None, None
        (J,) = ctx.saved_tensors
        if torch.is_grad_enabled():
            return None, _jacobian_vjp(J, G)
        return None, _like(core.jacobian_vjp(ctx.J64, _numpy64(G)), J)


class _IK(torch.autograd.Function):
    """q*(T) by ``robot.ik``; backward by the implicit function theorem."""

    @staticmethod
    def forward(ctx: Any, robot: Robot, T: torch.Tensor, q0: np.ndarray, method: str,
                seed: Any, damping: float, options: dict[str, Any]
                ) -> tuple[torch.Tensor, torch.Tensor]:
        T64 = _numpy64(T)
        q64, success = core.solve_ik(robot, T64, q0, method, seed, options)
        ctx.robot, ctx.T64, ctx.q64, ctx.damping = robot, T64, q64, damping
        ctx.shape, ctx.like = T.shape, torch.empty(0, dtype=T.dtype, device=T.device)
        ok = torch.from_numpy(success).to(T.device)
        ctx.mark_non_differentiable(ok)
        return _like(q64, T), ok

    @staticmethod
    @once_differentiable
    def backward(ctx: Any, gq: torch.Tensor, _gok: Any) -> tuple[Any, ...]:
        G = core.ik_target_cotangent(ctx.robot, ctx.T64, ctx.q64, _numpy64(gq), ctx.damping)
        G = np.ascontiguousarray(core.sum_to_shape(G, tuple(ctx.shape)))
        return (None, _like(G, ctx.like), None, None, None, None, None)


def fk(robot: Robot, q: torch.Tensor) -> torch.Tensor:
    """Tool pose ``T = base · A_1(q_1) ··· A_n(q_n) · tool`` (eqs 10-11), differentiable in q.

    Args:
        robot: the robot.
        q: (..., n) floating-point tensor of joint values [rad / m].

    Returns:
        (..., 4, 4) homogeneous transforms ``T_world_ee``, q's dtype and device; in
        float64 equal to ``robot.fk(q)``. Backward: ``∂L/∂q = Jᵀ [Ḡ_p; w]``
        (:mod:`serialkin.autograd.core`).

    Raises:
        InputTypeError: robot not a Robot, q not a floating-point tensor.
        InputError: q of the wrong length or not finite.
    """
    return _FK.apply(check_robot(robot), _check_tensor(q, "q"))


def jacobian(robot: Robot, q: torch.Tensor) -> torch.Tensor:
    """World-frame geometric Jacobian (eqs 33-36), rows ``[v; ω]``, differentiable in q.

    Args:
        robot: the robot.
        q: (..., n) floating-point tensor of joint values [rad / m].

    Returns:
        (..., 6, n), q's dtype and device; in float64 equal to ``robot.jacobian(q)``.
        Backward: the contraction with the kinematic Hessian ``∂J/∂q``.

    Raises:
        InputTypeError: robot not a Robot, q not a floating-point tensor.
        InputError: q of the wrong length or not finite.
    """
    return _Jacobian.apply(check_robot(robot), _check_tensor(q, "q"))


def ik(robot: Robot, T: torch.Tensor, q0: object, *, method: str = "lm",
       damping: float = core.DEFAULT_DAMPING, seed: Any = None, **options: Any) -> IKSolution:
    """Inverse kinematics ``q*`` with ``fk(q*) = T``, differentiable in the target T.

    The forward is ``robot.ik(T, method, q0=q0, seed=seed, **options)`` on every target
    (one batch). The backward is the implicit function theorem: a target change ``dT`` with
    twist ``δx = [dp; δθ]`` (``dR = [δθ]× R``) moves the solution by ``dq = J^# δx``, J the
    world-frame Jacobian at q*, ``J^# = Σ_i f(σ_i) v_i u_iᵀ`` with ``f(σ) = 1/σ`` for
    ``σ ≥ damping`` and ``σ/damping²`` below (:func:`serialkin.autograd.core.damped_pinv`).
    So away from singularities the gradient is exact; for a redundant arm it is the
    minimum-norm solution change (the one the 'pinv' method makes when re-solving from
    q*; another solver may drift differently in the null space). Near a singularity it
    stays finite: the gain on a direction is at most 1/damping. The gradient with respect
    to q0 is zero.

    Args:
        robot: the robot.
        T: (..., 4, 4) floating-point tensor of target poses ``T_world_ee``.
        q0: (n,) or (..., n) initial guesses (tensor or array-like; not differentiated).
        method: an IK method name (default 'lm'; see :func:`serialkin.ik.available_methods`).
        damping: ε of the damped pseudo-inverse, > 0 [units of J] (default 1e-2).
        seed: seed of the solver's random restarts (None, int or numpy Generator).
        **options: further options of :func:`serialkin.ik.solve` (``tol``, ``max_iter``,
            ``restarts``, ``mask``, ``respect_limits`` ...).

    Returns:
        :class:`IKSolution` ``(q, success)``: q (..., n) with T's dtype and device,
        success (...) bool.

    Raises:
        InputTypeError: robot not a Robot, T not a floating-point tensor.
        InputError: T not (..., 4, 4), q0 of the wrong shape or outside the limits, a bad
            damping or option (as :func:`serialkin.ik.solve` raises).
    """
    robot = check_robot(robot)
    _check_tensor(T, "T")
    d = core.check_damping(damping)
    q0a = _numpy64(q0) if isinstance(q0, torch.Tensor) else core.as_float64(
        as_float_array(q0, "q0"))
    q, ok = _IK.apply(robot, T, q0a, method, seed, d, dict(options))
    return IKSolution(q, ok)
