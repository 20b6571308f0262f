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
_LIMIT_AWARE = (
    "limit-aware step: joints at a limit whose step points outward are frozen and "
    "the step recomputed for the others; then " + _PROJECTION
)

#: name, kernel code, max_iter, restarts, default options, summary (registration order).
_TABLE = (
    ("transpose", K.TRANSPOSE, 5000, 5, {"stall_window": 1000},
     "Jacobian transpose with the Buss/Wolovich step length (slow, linear convergence)"),
    ("pinv", K.PINV, 100, 50, {"max_step": 0.5, "rcond": 1e-10, "stall_window": 20},
     "Moore-Penrose pseudoinverse step J⁺e (eq 40), steps capped at max_step"),
    ("dls", K.DLS, 200, 50, {"damping": 0.01, "stall_window": 30},
     "damped least squares Jᵀ(JJᵀ+λ²I)⁻¹e with fixed damping λ (eq 46)"),
    ("lm", K.LM, 100, 100, {"damping": 0.03, "stall_window": 5, "polish": True},
     "Levenberg-Marquardt, damping λE adapted to the error, limit-aware (default)"),
    ("lm_wampler", K.LM_WAMPLER, 200, 50, {"damping": 1e-4, "stall_window": 30},
     "Levenberg-Marquardt with constant damping λI (Wampler)"),
    ("lm_chan", K.LM_CHAN, 200, 50, {"damping": 1.0, "stall_window": 30},
     "Levenberg-Marquardt with error-proportional damping λE (Chan-Lawrence)"),
    ("lm_sugihara", K.LM_SUGIHARA, 200, 50, {"damping": 1e-4, "stall_window": 30},
     "Levenberg-Marquardt with damping E + λ (Sugihara)"),
    ("sdls", K.SDLS, 500, 30, {"max_step": math.pi / 4, "stall_window": 60},
     "selectively damped least squares by SVD (Buss & Kim)"),
    ("newton", K.NEWTON, 100, 50, {"rcond": 1e-10, "stall_window": 20},
     "Newton-Raphson (eq 41): full pseudoinverse step with backtracking line search"),
    ("gauss_newton", K.GAUSS_NEWTON, 100, 50, {"rcond": 1e-12, "stall_window": 20},
     "Gauss-Newton on the normal equations (JᵀJ)⁺Jᵀe, full step"),
)



#: Largest robot of the methods whose iteration costs O(n³) (an n×n system, or an SVD
#: over the n columns of J): about a minute for a failing solve at 1000 joints.
MAX_JOINTS_CUBIC = 1000

#: Methods whose iteration cost grows linearly with the number of joints.
_LINEAR = (K.TRANSPOSE, K.DLS)


def _register_all() -> None:
    """Register every method of :data:`_TABLE` (family 'jacobian', compiled kernel)."""
    for name, code, max_iter, restarts, options, summary in _TABLE:
        register_method(MethodSpec(
            name=name, family="jacobian", summary=summary,
            limits=_LIMIT_AWARE if code == K.LM else _PROJECTION,
            max_iter=max_iter, restarts=restarts, options=options, kernel_code=code,
            max_joints=None if code in _LINEAR else MAX_JOINTS_CUBIC,
        ))


_register_all()
