"""Jacobian-based IK methods (chapter section 5.3), registered by name.

All of them run in the compiled loop of :mod:`serialkin.ik._kernels` (see its docstring
for each step's formula) and share the skeleton of :mod:`serialkin.ik.solver`: the same
targets, mask, tolerance, restarts and seeding. Joint limits are respected by
projection after every step (2π shift or nearer limit for revolute joints, clamping for
prismatic ones).

=================  =====================================================================
name               step
=================  =====================================================================
``transpose``      Jacobian transpose, ``Δq = α Jᵀe``, Buss/Wolovich step length
``pinv``           Moore-Penrose pseudoinverse, ``Δq = J⁺e`` (eq 40), step capped
``dls``            damped least squares, ``Δq = Jᵀ(JJᵀ + λ²I)⁻¹e`` (eq 46, corrected)
``lm``             Levenberg-Marquardt, damping λE adapted to the error, limit-aware (default)
``lm_wampler``     ``(JᵀJ + λI)Δq = Jᵀe`` (Wampler 1986)
``lm_chan``        ``(JᵀJ + λE·I)Δq = Jᵀe`` (Chan & Lawrence 1988)
``lm_sugihara``    ``(JᵀJ + (E + λ)I)Δq = Jᵀe`` (Sugihara 2011)
``sdls``           selectively damped least squares by SVD (Buss & Kim 2005)
``newton``         Newton-Raphson (eq 41): full ``J⁺e`` step with backtracking
``gauss_newton``   Gauss-Newton on the normal equations, ``(JᵀJ)⁺Jᵀe``
=================  =====================================================================

(``J`` and ``e`` are weighted by the task mask; ``E = ½ eᵀWe``.)

Trade-offs measured by ``benchmarks/bench_ik.py`` (1,000 random full-pose targets on
Panda, UR5 and Puma 560): ``lm`` solves all of them in about 10 iterations (median);
the methods with a constant damping floor (``dls``, ``lm_wampler``, ``lm_sugihara``)
converge only linearly near singular solutions, where they may run out of patience
(about 1 % of targets); the SVD-based ``pinv``, ``newton``, ``gauss_newton`` and
``sdls`` are robust but cost more per iteration; ``transpose`` needs thousands of
iterations and solves only about 3 in 4 full-pose targets within its budget.

Options (keyword arguments of ``robot.ik``; defaults in ``METHODS[name].options``):
``damping`` (λ), ``stall_window`` (iterations within which the cost must halve before
a restart), ``max_step`` (``pinv``: cap on max |Δq_i|; ``sdls``: γ_max), ``rcond``
(relative singular-value cut-off) and, for ``lm``, ``polish``: when every attempt
failed, refine the best one with a monotone Levenberg-Marquardt down to a local
least-squares minimum, so that an unreachable target returns the closest pose found.
"""

from __future__ import annotations

import math

from serialkin.ik import _kernels as K
from serialkin.ik.registry import MethodSpec, register_method

_PROJECTION = (
    "projection after every step: a revolute joint is shifted by 2π when that brings it "
    "inside its range, else set to the nearer limit; a prismatic joint is clamped"
)

register_method(MethodSpec(
    name="transpose", family="jacobian",
    summary="Jacobian transpose with the Buss/Wolovich step length (slow, linear convergence)",
    limits=_PROJECTION, max_iter=5000, restarts=5,
    options={"stall_window": 1000}, kernel_code=K.TRANSPOSE,
))
register_method(MethodSpec(
    name="pinv", family="jacobian",
    summary="Moore-Penrose pseudoinverse step J⁺e (eq 40), steps capped at max_step",
    limits=_PROJECTION, max_iter=100, restarts=50,
    options={"max_step": 0.5, "rcond": 1e-10, "stall_window": 20}, kernel_code=K.PINV,
))
register_method(MethodSpec(
    name="dls", family="jacobian",
    summary="damped least squares Jᵀ(JJᵀ+λ²I)⁻¹e with fixed damping λ (eq 46)",
    limits=_PROJECTION, max_iter=200, restarts=50,
    options={"damping": 0.01, "stall_window": 30}, kernel_code=K.DLS,
))
register_method(MethodSpec(
    name="lm", family="jacobian",
    summary="Levenberg-Marquardt, damping λE adapted to the error, limit-aware (default)",
    limits="limit-aware step: joints at a limit whose step points outward are frozen and "
    "the step recomputed for the others; then " + _PROJECTION,
    max_iter=100, restarts=100,
    options={"damping": 0.03, "stall_window": 5, "polish": True}, kernel_code=K.LM,
))
register_method(MethodSpec(
    name="lm_wampler", family="jacobian",
    summary="Levenberg-Marquardt with constant damping λI (Wampler)",
    limits=_PROJECTION, max_iter=200, restarts=50,
    options={"damping": 1e-4, "stall_window": 30}, kernel_code=K.LM_WAMPLER,
))
register_method(MethodSpec(
    name="lm_chan", family="jacobian",
    summary="Levenberg-Marquardt with error-proportional damping λE (Chan-Lawrence)",
    limits=_PROJECTION, max_iter=200, restarts=50,
    options={"damping": 1.0, "stall_window": 30}, kernel_code=K.LM_CHAN,
))
register_method(MethodSpec(
    name="lm_sugihara", family="jacobian",
    summary="Levenberg-Marquardt with damping E + λ (Sugihara)",
    limits=_PROJECTION, max_iter=200, restarts=50,
    options={"damping": 1e-4, "stall_window": 30}, kernel_code=K.LM_SUGIHARA,
))
register_method(MethodSpec(
    name="sdls", family="jacobian",
    summary="selectively damped least squares by SVD (Buss & Kim)",
    limits=_PROJECTION, max_iter=500, restarts=30,
    options={"max_step": math.pi / 4, "stall_window": 60}, kernel_code=K.SDLS,
))
register_method(MethodSpec(
    name="newton", family="jacobian",
    summary="Newton-Raphson (eq 41): full pseudoinverse step with backtracking line search",
    limits=_PROJECTION, max_iter=100, restarts=50,
    options={"rcond": 1e-10, "stall_window": 20}, kernel_code=K.NEWTON,
))
register_method(MethodSpec(
    name="gauss_newton", family="jacobian",
    summary="Gauss-Newton on the normal equations (JᵀJ)⁺Jᵀe, full step",
    limits=_PROJECTION, max_iter=100, restarts=50,
    options={"rcond": 1e-12, "stall_window": 20}, kernel_code=K.GAUSS_NEWTON,
))
