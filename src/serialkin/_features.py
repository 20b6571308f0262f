"""The warm-up features: groups of kernels compiled together, as the compile notice names them.

``serialkin warmup NAME`` compiles a feature's kernels ahead of time
(:mod:`serialkin.warmup` adds the calls that do it); the first-compile notice of
:mod:`serialkin._background` names the feature of the kernel being compiled and its
expected time. A module of data on its own, outside every kernel's import closure: the
cache stamps of :func:`serialkin._jit.dependency_stamp` follow import statements, so
editing a timing or a summary here recompiles nothing (``_background`` reads this
module through ``importlib``).
"""

from __future__ import annotations

from dataclasses import dataclass

__all__ = ["COMPILE_FEATURES", "CompileFeature", "feature_of_module"]


@dataclass(frozen=True)
class CompileFeature:
    """A group of kernels compiled together (``serialkin warmup NAME``), as the notice names it.

    Attributes:
        name: the name ``serialkin warmup NAME`` takes.
        summary: what a user does that needs these kernels.
        modules: prefixes of the ``serialkin`` modules whose kernels this is (the
            compile notice names the feature of the kernel being compiled); none for
            ``ik-all-near``, whose solvers are ``ik-all``'s classes refined (the notice
            says ``ik-all``) and whose refinement the general 6R solver uses too.
        seconds: the measured cold compile time on a quiet 2-core machine [s] (the
            estimate the notice and the warm-up's progress bar show; docs/compile-time.md).
    """

    name: str
    summary: str
    modules: tuple[str, ...]
    seconds: float


#: The features, in the order ``serialkin warmup --all`` starts them: about longest first,
#: so that the parallel processes finish together, where "longest" is what a feature
#: still compiles after those started before it (they share kernels: ``ik-all`` after
#: ``ik-all-general`` compiles 10 s, alone 27 s; collision before ``ik-all`` ends
#: ``make run``'s warm-up 3 s sooner on 2 cores). Except the two ``make run`` leaves to
#: ``make test`` (the report uses neither), first: ``arm-angle`` and ``ik-all-near``
#: (nearly ideal arms: the refined solvers of ``ik-all``'s classes), which ``make test``'s
#: ``warmup --all`` then compiles one in each process while the extras install, the
#: features ``make run`` compiled loading from the cache after them (started later, they
#: waited for those loads). Their ``seconds``: each feature alone in a fresh process with
#: an empty cache (benchmarks/compile_profile.py, quiet 2-core machine; the first-call
#: notice quotes them), so ``--all`` takes much less than their sum.
#: :data:`serialkin.warmup.FEATURES` adds to each the calls that compile it.
COMPILE_FEATURES: dict[str, CompileFeature] = {f.name: f for f in (
    CompileFeature("arm-angle", "7-DOF arms with a spherical shoulder and wrist by their "
                   "arm angle: robot.ik_arm_angle, robot.arm_angle_intervals",
                   ("serialkin.ik.analytic.arm_angle",), 13.0),
    CompileFeature("ik-all-near", "every solution of nearly ideal (calibrated) arms: "
                   "robot.ik_all", (), 28.0),
    CompileFeature("ik-all-general", "every solution of general 6R arms: robot.ik_all",
                   ("serialkin.ik.analytic.general", "serialkin.ik.analytic.raghavan_roth",
                    "serialkin.ik.analytic.refine"), 42.0),
    CompileFeature("ik-methods", "the numerical IK methods other than the default: "
                   "robot.ik(method=...)",
                   ("serialkin.ik.jacobian_methods", "serialkin.ik.ccd",
                    "serialkin.ik.fabrik", "serialkin.ik.optimize"), 39.0),
    CompileFeature("tracking", "path tracking and redundancy resolution: serialkin track",
                   ("serialkin.tracking", "serialkin.redundancy"), 26.0),
    CompileFeature("collision", "collision-aware IK and clearance queries",
                   ("serialkin.collision", "serialkin.diffik"), 46.0),
    CompileFeature("ik-all", "every closed-form solution: robot.ik_all",
                   ("serialkin.ik.analytic",), 27.0),
    CompileFeature("ik", "numerical IK: robot.ik (default method), one pose and batches",
                   ("serialkin.ik", "serialkin.kinematics.dls", "serialkin.spatial",
                    "serialkin.model.limits"), 22.0),
    CompileFeature("kinematics", "forward kinematics and Jacobians: robot.fk, robot.jacobian",
                   ("serialkin.kinematics",), 13.0),
    CompileFeature("workspace", "workspace sampling: serialkin workspace",
                   ("serialkin.workspace",), 8.0),
)}


def feature_of_module(module: str) -> CompileFeature | None:
    """The feature whose kernels ``module`` holds (longest matching prefix), or None."""
    best, length = None, -1
    for f in COMPILE_FEATURES.values():
        for prefix in f.modules:
            if (module == prefix or module.startswith(prefix + ".")) and len(prefix) > length:
                best, length = f, len(prefix)
    return best
