"""The IK method registry: method name → :class:`MethodSpec`.

A method is registered once, at import of the module that implements it, with
:func:`register_method`. The built-in families are imported by name in
``serialkin/ik/__init__.py`` (:mod:`~serialkin.ik.jacobian_methods`,
:mod:`~serialkin.ik.heuristic_methods`, :mod:`~serialkin.ik.optimization_methods` and
the closed-form :mod:`serialkin.ik.analytic.method`), so every import of serialkin
registers them before any solve; a new family is a module that calls
:func:`register_method` at import and one import line there. This module imports
none of them: the dependency runs one way, from the families to the registry.

Two kinds of methods share the same skeleton (:mod:`serialkin.ik.solver`):

* compiled methods (``kernel`` set): a step kernel, written and registered in its
  family's file, inside the one compiled loop of :mod:`serialkin.ik._kernels` that owns
  iterations, restarts, stagnation and limits (:func:`~serialkin.ik._kernels.compile_method`);
* Python methods (``attempt`` set): the method supplies one attempt from a start
  configuration; the shared Python loop in :func:`serialkin.ik.solver.run_attempts` owns
  restarts, seeding, the iteration budget, success test and the result.
"""

from __future__ import annotations

from collections.abc import Callable, Iterator, Mapping
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

from serialkin._checks import check_choice
from serialkin.errors import InputError

if TYPE_CHECKING:
    import numpy as np

    from serialkin.ik._kernels import CompiledMethod
    from serialkin.ik.solver import IKProblem

#: Signature of a Python method's attempt: ``attempt(problem, q_start, max_iter, options)``
#: returns ``(q, iterations)``. ``q`` (n,) must be finite and, when
#: ``problem.respect_limits``, inside the limits (use ``problem.project``); the attempt
#: should stop early when it converges (``problem.converged``) or stagnates.
AttemptFn = Callable[["IKProblem", "np.ndarray", int, Mapping[str, Any]], tuple["np.ndarray", int]]


@dataclass(frozen=True)
class MethodSpec:
    """Description of one IK method.

    Attributes:
        name: the method name users pass as ``method=``.
        family: 'jacobian', 'optimization', 'heuristic' or 'analytic'.
        summary: one line for listings (``serialkin ik --list``, ``compare``).
        limits: how the method respects joint limits (one sentence).
        targets: the target kinds it accepts ('pose', 'position', 'planar',
            'planar_pose').
        max_iter: default iteration budget per attempt.
        restarts: default number of restarts from random configurations.
        options: method-specific keyword options and their defaults.
        kernel: the compiled method (a step kernel in the shared loop, built by
            :func:`serialkin.ik._kernels.compile_method`), or None for a Python method.
        attempt: the Python attempt function (see :data:`AttemptFn`), or None.
        max_joints: the largest robot (number of joints) the method accepts, or None for
            any: methods whose iteration costs O(n³) (an n×n system or an SVD over n
            columns) or O(n²) function evaluations would run for hours on the longest
            chains serialkin allows; those robots are refused with the names of the
            methods that scale.
        solve: a callable that solves every target at once entirely on its own (the
            closed-form method, which needs neither restarts nor iterations), or None:
            ``solve(robot, T, kind, q0, options) -> (q, found, reason)`` with ``T``
            (N, 4, 4) the targets, ``kind`` their target kind, ``q0`` (N, n) or None;
            ``q`` (N, n) the answers, ``found`` (N,) bool and ``reason`` the sentence
            of a target not found. The solver measures the errors and decides success.
        solve_pose: with ``solve``, optionally the same solve for the common single call
            (one (4, 4) pose, the method's default options), cheaper than ``solve`` on
            a batch of one: ``solve_pose(robot, T, q0) -> (q, found, reason)`` with
            ``T`` a checked C-contiguous float64 (4, 4) pose, ``q0`` a checked (n,)
            guess or None; ``q`` (n,), ``found`` a bool. Its answer must be ``solve``'s
            for that target, bit for bit: :func:`serialkin.ik.solver.solve` calls it
            on its fast path in place of ``solve``.

    Raises:
        InputError: not exactly one of ``kernel``, ``attempt``, ``solve`` given, or
            ``solve_pose`` without ``solve``.
    """

    name: str
    family: str
    summary: str
    limits: str
    targets: tuple[str, ...] = ("pose", "position", "planar", "planar_pose")
    max_iter: int = 100
    restarts: int = 50
    options: Mapping[str, Any] = field(default_factory=dict)
    kernel: CompiledMethod | None = None
    attempt: AttemptFn | None = None
    solve: Callable[..., Any] | None = None
    max_joints: int | None = None
    solve_pose: Callable[..., Any] | None = None

    def __post_init__(self) -> None:
        if (self.kernel is None) + (self.attempt is None) + (self.solve is None) != 2:
            raise InputError(
                f"method {self.name!r} needs exactly one of kernel, attempt, solve"
            )
        if self.solve_pose is not None and self.solve is None:
            raise InputError(f"method {self.name!r}: solve_pose goes with solve")


_REGISTRY: dict[str, MethodSpec] = {}


def register_method(spec: MethodSpec) -> MethodSpec:
    """Add a method to the registry (replacing one of the same name) and return it."""
    _REGISTRY[spec.name] = spec
    return spec


class _MethodTable(Mapping[str, MethodSpec]):
    """Read-only view of the registry, in name order (``serialkin.ik.METHODS``)."""

    def __getitem__(self, name: str) -> MethodSpec:
        return _REGISTRY[name]

    def __iter__(self) -> Iterator[str]:
        return iter(sorted(_REGISTRY))

    def __len__(self) -> int:
        return len(_REGISTRY)

    def __repr__(self) -> str:
        return f"METHODS({', '.join(self)})"


#: All registered methods, name → :class:`MethodSpec` (read-only mapping).
METHODS: Mapping[str, MethodSpec] = _MethodTable()


def available_methods() -> tuple[str, ...]:
    """Names of every registered IK method, sorted."""
    return tuple(METHODS)


def get_method(name: object) -> MethodSpec:
    """The :class:`MethodSpec` registered as ``name``.

    Raises:
        InputError: unknown name; the message lists the available methods.
    """
    if isinstance(name, str):
        spec = _REGISTRY.get(name)
        if spec is not None:
            return spec
    check_choice(name, "method", sorted(_REGISTRY))
    return _REGISTRY[name]  # type: ignore[index]
