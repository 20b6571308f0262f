"""Compile the kernels ahead of time, in parallel, into numba's on-disk cache.

serialkin's kernels are compiled by numba the first time a feature is used and then
loaded from the on-disk cache (``cache=True``) by every later process: a first call
that has to compile takes seconds to minutes (see docs/compile-time.md), a later one
milliseconds. :func:`warmup` pays that once, visibly: each feature's kernels are
compiled by calling the feature's public functions in a process of their own, as many
processes at a time as there are cores, with a progress bar and the time left. The
command ``serialkin warmup`` calls it; ``make run`` and ``make test`` run it first.

A first call that must compile prints one line to stderr, once per feature and process
(:func:`serialkin._background.install_notice`, installed when serialkin loads numba,
without this module), unless ``SERIALKIN_QUIET_COMPILE`` is set to a non-empty value
other than ``0``. The features' names, modules and estimated times are
:data:`serialkin._features.COMPILE_FEATURES` (the notice needs them); this module adds
the calls that compile each one.

Every feature calls only public API with the argument types users pass (one pose and
batches, C- and Fortran-ordered arrays), so what it compiles is exactly what a user's
first call would compile, and nothing else.
"""

from __future__ import annotations

import os
import time
from collections.abc import Callable, Iterable
from dataclasses import dataclass

import numpy as np

from serialkin._background import install_notice
from serialkin._checks import check_choice
from serialkin._features import COMPILE_FEATURES, CompileFeature
from serialkin._features import feature_of_module as _feature_of_module

__all__ = ["FEATURES", "Feature", "feature_of_module", "install_notice", "warmup"]


@dataclass(frozen=True)
class Feature(CompileFeature):
    """A :class:`~serialkin._features.CompileFeature` with what compiles it, in one process.

    Attributes:
        run: calls the feature's public functions (compiling what they need); the other
            attributes are :class:`~serialkin._features.CompileFeature`'s.
    """

    run: Callable[[], object]


def _kinematics() -> None:
    import serialkin as sk

    for name in ("ur5", "panda"):
        r = sk.models.get(name)
        Q = r.random_q(300, seed=0)
        for q in (Q[0], Q[:1].T[:, 0]):  # a contiguous and a strided configuration
            r.fk(q)
            r.jacobian(q)
            r.jacobian(q, frame="ee")
            r.hessian(q)
            r.jacobian_dot(q, qd=np.ones(r.n))
            r.manipulability(q)
            r.fk_all(q)
        T = r.fk(Q)
        r.fk(np.asfortranarray(Q))
        r.jacobian(Q)
        r.jacobian(Q, link=2, point=[0.0, 0.0, 0.1])
        r.hessian(Q)
        r.jacobian_dot(Q, qd=np.ones_like(Q))
        r.manipulability(Q)
        sk.spatial.pose_error(T, T[::-1])
        sk.spatial.so3_log(T[:, :3, :3])


def _ik() -> None:
    import serialkin as sk

    for name in ("panda", "ur5", "two_link"):
        r = sk.models.get(name)
        Q = r.random_q(300, seed=0)
        T = r.fk(Q)
        if r.n == 2:
            r.ik(T[0, :2, 3])
            r.ik(T[:, :2, 3])
        else:
            r.ik(T[0])
            r.ik(np.asfortranarray(T[0]))
            r.ik(T[0], q0=Q[1])
            r.ik(T)
            r.ik(T, q0=Q[::-1].copy())


def _ik_all() -> None:
    import serialkin as sk

    for name in ("ur5", "puma560", "stanford", "scara", "three_link"):
        r = sk.models.get(name)
        T = r.fk(r.random_q(4, seed=0))
        r.ik_all(T[0])
        r.ik_all(T)


def _arm_angle() -> None:
    import serialkin as sk
    from serialkin.ik.analytic.arm_angle import ik_arm_angle_path

    iiwa = sk.models.get("iiwa7")  # S-R-S arms by the arm angle: one pose, a path, ψ intervals
    T = iiwa.fk(iiwa.random_q(4, seed=0))
    iiwa.ik_arm_angle(T[0], 0.3)
    ik_arm_angle_path(iiwa, T, 0.3)
    iiwa.arm_angle_intervals(T[0])


def _ik_methods() -> None:
    import serialkin as sk
    from serialkin.ik import METHODS

    panda = sk.models.get("panda")
    planar = sk.models.get("three_link")  # FABRIK: chains with parallel axes
    for name, spec in METHODS.items():
        if name in ("lm", "analytic"):  # the ik and ik-all features
            continue
        r = planar if name == "fabrik" else panda
        Q = r.random_q(3, seed=0)
        T = r.fk(Q)
        if r is planar:
            T = T[:, :2, 3]  # position targets in the plane
        r.ik(T[0], method=name, max_iter=5)
        r.ik(T[0], method=name, q0=Q[1], max_iter=5)
        r.ik(T[0], method=name, q0=Q[0])  # default options: the one-target fast path
        if spec.kernel is not None:  # the compiled batch loop
            r.ik(T, method=name, max_iter=5)


def _ik_all_general() -> None:
    import serialkin as sk
    from serialkin.model.dh import DHLink

    rng = np.random.default_rng(0)
    general = sk.Robot.from_dh([DHLink(a=rng.uniform(0.05, 0.5), alpha=rng.uniform(-3, 3),
                                       d=rng.uniform(-0.3, 0.3)) for _ in range(6)])
    T = general.fk(general.random_q(2, seed=0))
    general.ik_all(T[0])
    general.ik_all(T)


def _ik_all_near() -> None:
    import serialkin as sk
    from serialkin.model.dh import DHLink

    for name in ("ur5", "puma560"):  # nearly ideal arms (a calibrated robot): refined
        dh = sk.models.get(name).dh
        r = sk.Robot.from_dh([DHLink(a=row.a + 1e-4, alpha=row.alpha + 1e-3, d=row.d,
                                     theta=row.theta) for row in dh], "standard")
        T = r.fk(r.random_q(2, seed=0))
        r.ik_all(T[0])
        r.ik_all(T)


def _collision() -> None:
    import serialkin as sk
    from serialkin.collision import (
        default_acm,
        panda_collision_model,
        scene_clearance,
        self_clearance,
    )
    from serialkin.collision.queries import body_pair_distances
    from serialkin.model.geometry import Box, HalfSpace

    r = sk.models.get("panda")
    Q = r.random_q(2, seed=0)
    T = r.fk(Q)
    r.ik(T[0], self_collision=True)
    r.ik(T, self_collision=True)
    r.ik(T[0], method="dls", self_collision=True)  # the loop the other Jacobian methods share
    model = panda_collision_model()
    acm = default_acm(model)
    self_clearance(r, model, Q, acm)
    body_pair_distances(r, model, Q, acm)
    scene = [Box((0.2, 0.2, 0.2), center=[0.5, 0.0, 0.3]), HalfSpace([0.0, 0.0, 1.0])]
    scene_clearance(r, model, Q, scene)


def _workspace() -> None:
    import serialkin as sk
    from serialkin.workspace import dexterous_workspace, reachable_workspace

    reachable_workspace(sk.models.two_link(1.0, 0.6), 2_000, seed=0, progress=False)
    reachable_workspace(sk.models.get("puma560"), 2_000, seed=0, progress=False)
    dexterous_workspace(sk.models.three_link(1.0, 0.8, 0.3), orientations=4, samples=2_000,
                        seed=0)


def _tracking() -> None:
    from serialkin.redundancy.nullspace import dls_inverse
    from serialkin.tracking import load_scenario, track
    from serialkin.tracking.analysis import qp_resolver

    load_scenario("six_link_circle").run()
    sc = load_scenario("twenty_link_obstacles")  # weighted tasks with obstacles (eq 48)
    sc.run()
    track(sc.robot, sc.path, qp_resolver(sc), q0=sc.q0)  # the QP with hard constraints
    dls_inverse(sc.robot.jacobian(sc.q0), 0.1)


_RUNS: dict[str, Callable[[], object]] = {
    "ik-all-general": _ik_all_general, "ik-all-near": _ik_all_near, "ik-all": _ik_all,
    "arm-angle": _arm_angle,
    "ik-methods": _ik_methods,
    "tracking": _tracking, "collision": _collision, "ik": _ik, "kinematics": _kinematics,
    "workspace": _workspace,
}

#: The features of :data:`serialkin._features.COMPILE_FEATURES` (in its order, the one
#: that ends the parallel processes together; the reasons are there), each with the
#: calls that compile it.
FEATURES: dict[str, Feature] = {
    name: Feature(f.name, f.summary, f.modules, f.seconds, _RUNS[name])
    for name, f in COMPILE_FEATURES.items()}


def feature_of_module(module: str) -> Feature | None:
    """The feature whose kernels ``module`` holds (longest matching prefix), or None."""
    f = _feature_of_module(module)
    return None if f is None else FEATURES[f.name]


def _run_one(name: str) -> float:
    """Run feature ``name`` in this process (a worker); returns its wall time [s]."""
    os.environ["SERIALKIN_QUIET_COMPILE"] = "1"
    os.environ["SERIALKIN_COMPILE"] = "wait"  # compile here, not run as Python meanwhile
    t0 = time.perf_counter()
    FEATURES[name].run()
    return time.perf_counter() - t0


def warmup(features: Iterable[str] | None = None, *, jobs: int | None = None,
           progress: bool | None = None) -> dict[str, float]:
    """Compile the kernels of ``features`` (default: all) into numba's on-disk cache.

    Each feature runs in a fresh process (``spawn``), ``jobs`` at a time (default: the
    CPUs this process may use), in the order of ``COMPILE_FEATURES``; features already
    compiled load from the cache in about a second. ``progress`` (default: when stderr
    is a terminal) shows a bar weighted by each feature's expected compile time, with
    the time left.

    Returns:
        the wall time [s] of each feature's process, by name.

    Raises:
        InputError: an unknown feature name (the message lists the valid ones).
    """
    import sys
    from concurrent.futures import ProcessPoolExecutor, as_completed
    from multiprocessing import get_context

    from tqdm.auto import tqdm

    from serialkin.errors import InputError

    names = list(FEATURES) if features is None else list(features)
    for n in names:
        check_choice(n, "feature", FEATURES)
    if not names:
        raise InputError("features must name at least one feature, got none")
    names.sort(key=lambda n: list(FEATURES).index(n))
    cpus = len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else os.cpu_count()
    jobs = max(1, min(len(names), jobs or cpus or 1))
    show = sys.stderr.isatty() if progress is None else progress
    total = sum(FEATURES[n].seconds for n in names) / jobs
    times: dict[str, float] = {}
    with tqdm(total=round(total), unit="s", desc="compiling", disable=not show,
              bar_format="{desc}: {percentage:3.0f}%|{bar}| {postfix} [{elapsed}<{remaining}]",
              file=sys.stderr) as bar, \
            ProcessPoolExecutor(max_workers=jobs, mp_context=get_context("spawn")) as pool:
        futures = {pool.submit(_run_one, n): n for n in names}
        for fut in as_completed(futures):
            n = futures[fut]
            times[n] = fut.result()
            bar.set_postfix_str(f"{n} {times[n]:.0f} s", refresh=False)
            bar.update(min(bar.total - bar.n, round(FEATURES[n].seconds / jobs)))
        bar.update(bar.total - bar.n)
    return times
