"""Inverse kinematics: closed-form and numerical solvers behind one interface.

Use ``robot.ik(target, method="lm", ...)`` or :func:`solve`; every method returns an
:class:`IKResult`. :data:`METHODS` maps each method name to its
:class:`~serialkin.ik.registry.MethodSpec`; :func:`available_methods` lists the names;
:func:`compare` runs several methods on the same targets and tabulates the results.

Adding a method family: write a module ``serialkin/ik/<family>.py`` that calls
:func:`~serialkin.ik.registry.register_method` at import, and import it below with the
other families (the registry imports no family: they import it).
"""

# the method families register their methods when imported
from serialkin.ik import heuristic_methods, jacobian_methods, optimization_methods  # noqa: F401
from serialkin.ik.analytic import classify, ik_all
from serialkin.ik.analytic import method as analytic_method  # noqa: F401
from serialkin.ik.analytic.arm_angle import arm_angle, arm_angle_intervals, ik_arm_angle
from serialkin.ik.compare import CompareTable, compare
from serialkin.ik.registry import METHODS, MethodSpec, available_methods, register_method
from serialkin.ik.result import IKResult
from serialkin.ik.solver import DEFAULT_TOL, IKProblem, _fast, solve
from serialkin.model.robot import provide

# Robot.ik and Robot.ik_all call these (the model layer imports nothing above it)
provide("ik", solve)
provide("ik_fast", _fast)
provide("ik_all", ik_all)
provide("arm_angle", arm_angle)
provide("ik_arm_angle", ik_arm_angle)
provide("arm_angle_intervals", arm_angle_intervals)

__all__ = [
    "CompareTable",
    "DEFAULT_TOL",
    "IKProblem",
    "IKResult",
    "METHODS",
    "MethodSpec",
    "available_methods",
    "classify",
    "compare",
    "ik_all",
    "register_method",
    "solve",
]
