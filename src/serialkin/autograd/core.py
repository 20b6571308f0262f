"""The framework-free side of the differentiable operations: float64 forwards and the IK cotangent.

:mod:`serialkin.torch` and :mod:`serialkin.jax` call these functions on numpy arrays; the
values come from the compiled kernels behind :class:`~serialkin.model.robot.Robot`
(``robot.fk``, ``robot.jacobian``, ``robot.ik``), so a forward equals the robot's own
result bit for bit in float64.

The derivatives the two modules implement, with ``J = [J_v; J_ω]`` (6, n) the geometric
Jacobian in the world frame (rows ``[vx, vy, vz, wx, wy, wz]``, column i ``[z_i × (p −
o_i); z_i]`` revolute, ``[z_i; 0]`` prismatic) and ``T = [R p; 0 1]`` the tool pose:

* **FK** (``T(q)``, (..., n) → (..., 4, 4)): ``∂R/∂q_i = [ω_i]× R`` and ``∂p/∂q_i =
  v_i``, so a cotangent ``Ḡ = ∂L/∂T`` pulls back to ``∂L/∂q = Jᵀ [Ḡ_p; w]`` with
  ``Ḡ_p = Ḡ[:3, 3]`` and ``w = vex-like(R Ḡ_Rᵀ)``: ``w = (M₂₃ − M₃₂, M₃₁ − M₁₃, M₁₂ −
  M₂₁)`` for ``M = R Ḡ_Rᵀ`` (since ``tr(Ḡ_Rᵀ [ω]× R) = ω · w``). The bottom row of T is
  constant and gets no gradient.
* **Jacobian** (``J(q)``, (..., n) → (..., 6, n)): by the kinematic Hessian
  (:meth:`Robot.hessian <serialkin.model.robot.Robot.hessian>`) ``∂J_j/∂q_k = [ω_k × v_j;
  ω_k × ω_j]`` for k < j and ``[ω_j × v_k; 0]`` for k ≥ j; contracted with ``Ḡ = ∂L/∂J``
  it needs no (6, n, n) array::

      ∂L/∂q_k = ω_k · Σ_{j>k} (v_j × Ḡv_j + ω_j × Ḡω_j) + v_k · Σ_{j≤k} (Ḡv_j × ω_j)

  (a suffix and a prefix sum over the columns: O(n) per configuration).
* **IK** (``q*(T)`` with ``fk(q*) = T``): by the implicit function theorem a target change
  ``dT`` with twist ``δx = [dp; δθ]`` (``dR = [δθ]× R``) moves the solution by ``dq =
  J⁺ δx`` (:func:`damped_pinv`: exact ``J⁺`` away from singularities, the minimum-norm
  change for a redundant arm). Its transpose pulls a cotangent ``ḡ = ∂L/∂q*`` back to
  the twist ``y = J⁺ᵀ ḡ = [y_p; y_θ]`` and then to the pose: ``∂L/∂p = y_p``, ``∂L/∂R =
  ½ [y_θ]× R`` (the skew part of ``dR Rᵀ``, so that any ``dT`` on SE(3) gives ``y · δx``).
"""

from __future__ import annotations

from typing import Any

import numpy as np

from serialkin._checks import check_positive
from serialkin.errors import InputError
from serialkin.model.robot import Robot

#: Default of ``damping`` (ε) in :func:`damped_pinv`: singular values of J at or above it
#: are inverted exactly.
DEFAULT_DAMPING = 1e-2


def as_float64(a: Any) -> np.ndarray:
    """``a`` as a C-contiguous float64 array (a copy only when the dtype or layout differs)."""
    return np.ascontiguousarray(a, dtype=np.float64)


def fk_and_jacobian(robot: Robot, q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The tool pose (..., 4, 4) and the world-frame Jacobian (..., 6, n) at q (..., n)."""
    return robot.fk(q), robot.jacobian(q)


#: Configurations per block of the numpy backward passes: their temporaries then stay
#: below glibc's mmap threshold (128 kB) and are reused, not mapped and faulted in afresh
#: (which made the Jacobian backward of 4,096 Panda configurations 4-9 ms instead of 1-2).
_BLOCK_BYTES = 96 * 1024


def _blockwise(f: Any, lead: tuple[int, ...], n: int, *arrays: np.ndarray) -> np.ndarray:
    """``f`` over blocks of the flattened leading axis of ``arrays``; result (*lead, n)."""
    flat = [a.reshape((-1,) + a.shape[len(lead):]) for a in arrays]
    N = flat[0].shape[0]
    out = np.empty((N, n))
    step = max(1, _BLOCK_BYTES // (8 * 3 * max(n, 3)))
    for start in range(0, N, step):
        out[start:start + step] = f(*(a[start:start + step] for a in flat))
    return out.reshape(lead + (n,))


def _fk_vjp_block(T: np.ndarray, J: np.ndarray, G: np.ndarray) -> np.ndarray:
    M = T[:, :3, :3] @ np.swapaxes(G[:, :3, :3], -1, -2)
    g6 = np.empty((G.shape[0], 6))
    g6[:, :3] = G[:, :3, 3]
    g6[:, 3] = M[:, 1, 2] - M[:, 2, 1]
    g6[:, 4] = M[:, 2, 0] - M[:, 0, 2]
    g6[:, 5] = M[:, 0, 1] - M[:, 1, 0]
    return np.einsum("bin,bi->bn", J, g6)


def fk_vjp(T: np.ndarray, J: np.ndarray, G: np.ndarray) -> np.ndarray:
    """``∂L/∂q = Jᵀ [Ḡ_p; w]`` (..., n) from T (..., 4, 4), J (..., 6, n) and Ḡ (..., 4, 4).

    ``w = (M₂₃ − M₃₂, M₃₁ − M₁₃, M₁₂ − M₂₁)`` with ``M = R Ḡ_Rᵀ`` (module docstring).
    """
    return _blockwise(_fk_vjp_block, T.shape[:-2], J.shape[-1], T, J, G)


def _cross(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Cross products of (3, ...) arrays (axis 0 holds x, y, z)."""
    return np.stack([a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2],
                     a[0] * b[1] - a[1] * b[0]])


def _jacobian_vjp_block(J: np.ndarray, G: np.ndarray) -> np.ndarray:
    Jt = np.ascontiguousarray(np.moveaxis(J, 0, -1))  # (6, n, N): long inner loops
    Gt = np.ascontiguousarray(np.moveaxis(G, 0, -1))
    v, w, Gv, Gw = Jt[:3], Jt[3:], Gt[:3], Gt[3:]
    a = _cross(v, Gv) + _cross(w, Gw)  # (3, n, N)
    after = np.cumsum(a[:, ::-1], axis=1)[:, ::-1] - a  # Σ_{j>k}
    upto = np.cumsum(_cross(Gv, w), axis=1)  # Σ_{j≤k}
    return ((w * after).sum(0) + (v * upto).sum(0)).T  # (N, n)


def jacobian_vjp(J: np.ndarray, G: np.ndarray) -> np.ndarray:
    """``∂L/∂q`` (..., n) of ``L(J(q))`` from J (..., 6, n) and ``Ḡ = ∂L/∂J`` (..., 6, n).

    ``∂L/∂q_k = ω_k · Σ_{j>k} (v_j × Ḡv_j + ω_j × Ḡω_j) + v_k · Σ_{j≤k} (Ḡv_j × ω_j)``,
    the kinematic Hessian contracted with Ḡ (module docstring).
    """
    return _blockwise(_jacobian_vjp_block, J.shape[:-2], J.shape[-1], J, G)


def check_damping(damping: object) -> float:
    """``damping`` as a float in (0, 1e9], or InputError/InputTypeError naming it."""
    return check_positive(damping, "damping")


def damped_pinv(J: np.ndarray, damping: float) -> np.ndarray:
    """Singular-value-damped pseudo-inverse ``J^# = Σ_i f(σ_i) v_i u_iᵀ`` of J (..., 6, n).

    ``f(σ) = 1/σ`` for ``σ ≥ ε`` (the Moore-Penrose inverse: exact, and the minimum-norm
    solution for a redundant arm) and ``f(σ) = σ/ε²`` below — the damped least-squares
    gain ``σ/(σ² + λ²)`` with the variable damping ``λ² = ε² − σ²`` (Nakamura & Hanafusa
    1986 make λ grow as σ falls; this choice makes f continuous at ε, zero at a
    singularity and never above ``1/ε``). ``ε = damping`` is in J's units (m per rad for
    the linear rows of a revolute column, 1 for the angular ones).

    Returns:
        (..., n, 6), finite for any finite J.
    """
    U, s, Vt = np.linalg.svd(J, full_matrices=False)
    eps2 = damping * damping
    with np.errstate(divide="ignore"):
        f = np.where(s >= damping, 1.0 / np.where(s > 0, s, 1.0), s / eps2)
    return np.swapaxes(Vt, -1, -2) @ (f[..., :, None] * np.swapaxes(U, -1, -2))


def solve_ik(robot: Robot, T: np.ndarray, q0: np.ndarray, method: str, seed: Any,
             options: dict[str, Any]) -> tuple[np.ndarray, np.ndarray]:
    """Solutions (..., n) and success flags (...) of ``robot.ik`` for targets T (..., 4, 4).

    ``q0`` (n,) is the initial guess of every target, (..., n) one per target (its leading
    shape broadcast against T's). Rows are solved as one batch by ``robot.ik(T, method,
    q0=..., seed=seed, **options)``; a failed row keeps the solver's best attempt.

    Raises:
        InputError: T not of shape (..., 4, 4), q0 of the wrong length or not broadcastable,
            and whatever ``robot.ik`` raises for its arguments.
    """
    if T.ndim < 2 or T.shape[-2:] != (4, 4):
        raise InputError(f"T must have shape (..., 4, 4), got {T.shape}")
    if q0.ndim == 0 or q0.shape[-1] != robot.n:
        raise InputError(f"q0 must have shape (..., {robot.n}) for robot {robot.name!r}, "
                         f"got {q0.shape}")
    try:
        lead = np.broadcast_shapes(T.shape[:-2], q0.shape[:-1])
    except ValueError:
        raise InputError(f"q0's leading shape {q0.shape[:-1]} does not broadcast against "
                         f"T's {T.shape[:-2]}") from None
    Tb = as_float64(np.broadcast_to(T, lead + (4, 4))).reshape(-1, 4, 4)
    Qb = as_float64(np.broadcast_to(q0, lead + (robot.n,))).reshape(-1, robot.n)
    result = robot.ik(Tb, method, q0=Qb, seed=seed, **options)
    q = np.asarray(result.q, dtype=np.float64).reshape(lead + (robot.n,))
    success = np.asarray(result.success, dtype=bool).reshape(lead)
    return q, success


def ik_target_cotangent(robot: Robot, T: np.ndarray, q: np.ndarray, g: np.ndarray,
                        damping: float) -> np.ndarray:
    """``∂L/∂T`` (..., 4, 4) of an IK solution q (..., n) for targets T, given ``ḡ = ∂L/∂q``.

    The implicit-function-theorem pullback of the module docstring: ``y = J^#ᵀ ḡ`` with
    ``J^#`` = :func:`damped_pinv` of the world-frame Jacobian at the solution, then
    ``∂L/∂p = y_p`` and ``∂L/∂R = ½ [y_θ]× R`` with R the target's rotation. The result
    has q's leading shape (:func:`sum_to_shape` reduces it to T's).
    """
    J = robot.jacobian(q)
    y = np.einsum("...ji,...j->...i", damped_pinv(J, damping), g)  # (..., 6): J^#ᵀ ḡ
    yp, (a, b, c) = y[..., :3], np.moveaxis(y[..., 3:], -1, 0)
    zero = np.zeros_like(a)
    Y = np.stack([np.stack([zero, -c, b], -1), np.stack([c, zero, -a], -1),
                  np.stack([-b, a, zero], -1)], -2)  # [y_θ]×
    out = np.zeros(q.shape[:-1] + (4, 4))  # T's leading shape broadcast against q0's
    out[..., :3, :3] = 0.5 * (Y @ T[..., :3, :3])
    out[..., :3, 3] = yp
    return out


def sum_to_shape(a: np.ndarray, shape: tuple[int, ...]) -> np.ndarray:
    """``a`` summed over the leading axes that broadcasting added to ``shape`` (a cotangent)."""
    extra = a.ndim - len(shape)
    if extra:
        a = a.sum(axis=tuple(range(extra)))
    axes = tuple(i for i, (m, k) in enumerate(zip(a.shape, shape)) if k == 1 and m != 1)
    return a.sum(axis=axes, keepdims=True) if axes else a
