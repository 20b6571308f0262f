"""The IK method registry: method name → :class:`MethodSpec`.

A method is registered once, at import of the module that implements it, with
:func:`register_method`. Every public module of :mod:`serialkin.ik` (a ``.py`` file whose
name does not start with ``_``, other than the skeleton's own modules) is imported the
first time the registry is read, so adding a file that registers its methods is all a new
family needs. The closed-form solvers (:mod:`serialkin.ik.analytic`) are served as the
method ``'analytic'`` when that package provides ``ik_all``.

Two kinds of methods share the same skeleton (:mod:`serialkin.ik.solver`):

* compiled methods (``kernel`` set): a step kernel, written and registered in its
  family's file, inside the one compiled loop of :mod:`serialkin.ik._kernels` that owns
  iterations, restarts, stagnation and limits (:func:`~serialkin.ik._kernels.compile_method`);
* Python methods (``attempt`` set): the method supplies one attempt from a start
  configuration; the shared Python loop in :func:`serialkin.ik.solver.run_attempts` owns
  restarts, seeding, the iteration budget, success test and the result.
"""

from __future__ import annotations

import importlib
import pkgutil
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
        solve: a callable that solves one target entirely on its own (the closed-form
            method, which needs neither restarts nor iterations), or None:
            ``solve(robot, problem, q0, options) -> (q, success, iterations, reason)``
            with ``problem`` an :class:`~serialkin.ik.solver.IKProblem` and ``q0`` (n,)
            or None.

    Raises:
        InputError: not exactly one of ``kernel``, ``attempt``, ``solve`` given.
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

    def __post_init__(self) -> None:
        if (self.kernel is None) + (self.attempt is None) + (self.solve is None) != 2:
            raise InputError(
                f"method {self.name!r} needs exactly one of kernel, attempt, solve"
            )


_REGISTRY: dict[str, MethodSpec] = {}
_DISCOVERED = False


def register_method(spec: MethodSpec) -> MethodSpec:
    """Add a method to the registry (replacing one of the same name) and return it."""
    _REGISTRY[spec.name] = spec
    return spec


#: Modules of the skeleton itself (they register nothing).
_SKELETON = frozenset({"registry", "solver", "target", "result", "compare"})


def _discover() -> None:
    """Import every public ``serialkin.ik`` module once (they register themselves)."""
    global _DISCOVERED
    if _DISCOVERED:
        return
    _DISCOVERED = True
    import serialkin.ik as pkg

    for info in pkgutil.iter_modules(pkg.__path__):
        if not info.ispkg and not info.name.startswith("_") and info.name not in _SKELETON:
            importlib.import_module(f"serialkin.ik.{info.name}")
    if "analytic" not in _REGISTRY:
        from serialkin.ik.analytic.method import register_analytic

        register_analytic()


class _MethodTable(Mapping[str, MethodSpec]):
    """Read-only, lazily populated view of the registry (``serialkin.ik.METHODS``)."""

    def __getitem__(self, name: str) -> MethodSpec:
        _discover()
        return _REGISTRY[name]

    def __iter__(self) -> Iterator[str]:
        _discover()
        return iter(sorted(_REGISTRY))

    def __len__(self) -> int:
        _discover()
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
    if _DISCOVERED and isinstance(name, str):
        spec = _REGISTRY.get(name)
        if spec is not None:
            return spec
    _discover()
    check_choice(name, "method", sorted(_REGISTRY))
    return _REGISTRY[name]  # type: ignore[index]
