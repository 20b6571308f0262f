"""Side-by-side comparison of IK methods on the same targets (chapter section 5.3).

The chapter discusses the trade-offs of the numerical families (Jacobian transpose,
pseudoinverse, damped least squares, Newton methods, BFGS/Powell, CCD, FABRIK);
:func:`compare` makes them measurable on any robot: every applicable method solves the
same targets from the same initial guesses with the same tolerance, restarts semantics
and seeds, and a :class:`CompareTable` reports per method the success rate, the median
and mean wall time per solve, the median number of iterations and the final errors.

A method is *applicable* when it accepts the target kind (``MethodSpec.targets``) and
does not reject the robot (e.g. FABRIK on a spatial chain raises
:class:`~serialkin.errors.NotSupportedError`, closed-form methods raise
:class:`~serialkin.errors.NoClosedFormError`); inapplicable methods are listed in
``CompareTable.skipped`` with the reason, and get no row.

Timing: each method first solves the first target once untimed (numba compilation and
caches warm up), then every target is solved one by one and timed with
:func:`time.perf_counter` around the public :func:`serialkin.ik.solve` call.
"""

from __future__ import annotations

import html
import time
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import asdict, dataclass, field
from typing import Any

import numpy as np

from serialkin._checks import as_generator
from serialkin.errors import InputError, InputTypeError, NoClosedFormError, NotSupportedError
from serialkin.ik.registry import METHODS, get_method
from serialkin.ik.solver import DEFAULT_TOL, solve
from serialkin.ik.target import check_q0, check_tol, parse_target
from serialkin.model.robot import Robot, check_robot

#: Column names of :meth:`CompareTable.to_text` / :meth:`CompareTable.to_html`.
COLUMNS = (
    "method", "family", "solves", "success rate", "median time [ms]", "mean time [ms]",
    "median iterations", "median pos. error [m]", "max pos. error [m]",
    "median ori. error [rad]", "max ori. error [rad]", "in limits",
)


@dataclass(frozen=True)
class CompareRow:
    """Statistics of one method over the targets.

    Attributes:
        method: method name.
        family: 'jacobian', 'optimization', 'heuristic' or 'analytic'.
        solves: number of targets solved (attempted).
        success_rate: fraction of successful solves, in [0, 1].
        median_time: median wall time per solve [s].
        mean_time: mean wall time per solve [s].
        median_iterations: median iterations per solve (all attempts counted).
        median_position_error: median final position error [m] over all solves.
        max_position_error: largest final position error [m].
        median_orientation_error: median final orientation error [rad].
        max_orientation_error: largest final orientation error [rad].
        within_limits_rate: fraction of returned q inside the joint limits.
    """

    method: str
    family: str
    solves: int
    success_rate: float
    median_time: float
    mean_time: float
    median_iterations: float
    median_position_error: float
    max_position_error: float
    median_orientation_error: float
    max_orientation_error: float
    within_limits_rate: float

    def cells(self) -> tuple[object, ...]:
        """The row's values in the order of :data:`COLUMNS` (times in ms)."""
        return (
            self.method, self.family, self.solves, self.success_rate,
            1e3 * self.median_time, 1e3 * self.mean_time, self.median_iterations,
            self.median_position_error, self.max_position_error,
            self.median_orientation_error, self.max_orientation_error,
            self.within_limits_rate,
        )


@dataclass(frozen=True)
class CompareTable:
    """Result of :func:`compare`: one row per applicable method, plus the skipped ones.

    Attributes:
        robot: robot name.
        target_kind: 'pose', 'position', 'planar' or 'planar_pose'.
        n_targets: number of targets.
        tol: tolerance used [m, rad].
        rows: one :class:`CompareRow` per method that ran, in the order requested.
        skipped: (method, reason) for every requested method that was not applicable.
    """

    robot: str
    target_kind: str
    n_targets: int
    tol: float
    rows: list[CompareRow] = field(default_factory=list)
    skipped: list[tuple[str, str]] = field(default_factory=list)

    def __len__(self) -> int:
        """Number of rows (methods that ran)."""
        return len(self.rows)

    def __iter__(self) -> Iterable[CompareRow]:  # type: ignore[override]
        """Iterate over the rows."""
        return iter(self.rows)

    def row(self, method: str) -> CompareRow:
        """The row of ``method``; raises KeyError when it did not run."""
        for r in self.rows:
            if r.method == method:
                return r
        raise KeyError(f"no row for method {method!r}; rows: {[r.method for r in self.rows]}")

    def to_dicts(self) -> list[dict[str, Any]]:
        """Rows as plain dicts (times in seconds), e.g. for ``json`` or a DataFrame."""
        return [asdict(r) for r in self.rows]

    @staticmethod
    def _fmt(v: object) -> str:
        if isinstance(v, float):
            if v == 0.0:
                return "0"
            if 1e-3 <= abs(v) < 1e4:
                return f"{v:.3f}".rstrip("0").rstrip(".") if abs(v) < 1 else f"{v:.4g}"
            return f"{v:.2e}"
        return str(v)

    def _title(self) -> str:
        return (f"IK methods on {self.robot}: {self.n_targets} {self.target_kind} targets, "
                f"tol {self.tol:g}")

    def to_text(self) -> str:
        """A plain-text table (fixed-width columns), with skipped methods listed below."""
        cells = [list(COLUMNS)] + [[self._fmt(v) for v in r.cells()] for r in self.rows]
        widths = [max(len(c[i]) for c in cells) for i in range(len(COLUMNS))]
        lines = [self._title()]
        for k, c in enumerate(cells):
            lines.append("  ".join(
                s.ljust(widths[i]) if i < 2 else s.rjust(widths[i]) for i, s in enumerate(c)
            ))
            if k == 0:
                lines.append("  ".join("-" * w for w in widths))
        for name, reason in self.skipped:
            lines.append(f"skipped {name}: {reason}")
        return "\n".join(lines)

    def to_html(self) -> str:
        """An HTML <table> (with a caption) and a list of skipped methods."""
        head = "<tr>" + "".join(f"<th>{html.escape(c)}</th>" for c in COLUMNS) + "</tr>"
        body = "".join(
            "<tr>" + "".join(f"<td>{html.escape(self._fmt(v))}</td>" for v in r.cells()) + "</tr>"
            for r in self.rows
        )
        out = (f"<table><caption>{html.escape(self._title())}</caption>{head}{body}</table>")
        if self.skipped:
            items = "".join(f"<li><b>{html.escape(m)}</b>: {html.escape(r)}</li>"
                            for m, r in self.skipped)
            out += f"<ul class=\"skipped\">{items}</ul>"
        return out

    def __str__(self) -> str:
        return self.to_text()


def _method_names(methods: object) -> list[str]:
    if methods is None:
        return [m for m in METHODS if METHODS[m].family != "analytic"]
    if isinstance(methods, str):
        methods = [methods]
    if not isinstance(methods, Sequence) or not methods:
        raise InputTypeError(
            f"methods must be None, a method name or a nonempty list of names, got {methods!r}"
        )
    names = []
    for m in methods:
        get_method(m)  # raises listing the available ones
        if m not in names:
            names.append(m)
    return names


def compare(
    robot: Robot,
    targets: object,
    methods: str | Sequence[str] | None = None,
    q0: object = None,
    seed: None | int | np.random.Generator = 0,
    tol: float = DEFAULT_TOL,
    *,
    method_options: Mapping[str, Mapping[str, Any]] | None = None,
    **options: Any,
) -> CompareTable:
    """Solve the same targets with several IK methods and tabulate the outcome.

    Args:
        robot: the robot.
        targets: a batch of targets as :func:`serialkin.ik.solve` accepts them:
            (N, 4, 4) poses, (N, 3) positions, or (N, 2) / (N, 3) planar targets (one
            target is accepted too).
        methods: method names (default: every registered numerical method, i.e. all but
            the closed-form family).
        q0: initial guesses, (n,) or (N, n) (default: each method draws its start from
            the same seeded stream).
        seed: None, int or Generator; target k is solved by every method with the same
            derived seed, so the comparison is reproducible.
        tol: tolerance on position [m] and orientation [rad] errors (the success test).
        method_options: per-method options, e.g. ``{"dls": {"damping": 0.05}}``.
        **options: common keywords passed to every solve (``mask``, ``max_iter``,
            ``restarts``, ``respect_limits``).

    Returns:
        A :class:`CompareTable`.

    Raises:
        InputError / InputTypeError: bad robot, targets, q0, tol, method names, or an
            option that a method does not accept.
    """
    check_robot(robot)
    _check_common_options(options)
    tol_v = check_tol(tol)
    tgt = parse_target(robot, targets, options.get("mask"))
    Ts = tgt.T if tgt.batch else tgt.T[None]
    N = Ts.shape[0]
    if N == 0:
        raise InputError("targets is empty; give at least one target")
    raw = np.asarray(targets, dtype=float)
    respect = bool(options.get("respect_limits", True))
    runs = _Runs(robot=robot, targets=raw if tgt.batch else raw[None],
                 q0=None if q0 is None else check_q0(robot, q0, N, respect),
                 seeds=as_generator(seed).integers(0, 2**62, size=N), tol=tol_v)
    names = _method_names(methods)
    mopts = dict(method_options or {})
    for m in mopts:
        if m not in names:
            raise InputError(f"method_options names {m!r}, which is not among methods {names}")
    table = CompareTable(robot=robot.name, target_kind=tgt.kind, n_targets=N, tol=tol_v)
    for name in names:
        spec = get_method(name)
        if tgt.kind not in spec.targets:
            table.skipped.append((name, f"does not accept {tgt.kind} targets (accepts "
                                        f"{', '.join(spec.targets)})"))
            continue
        kw = {**options, **mopts.get(name, {})}
        try:
            runs.solve(0, name, kw)  # warm-up (compilation), untimed
        except (NotSupportedError, NoClosedFormError) as exc:
            table.skipped.append((name, str(exc)))
            continue
        table.rows.append(_method_row(runs, name, spec.family, kw))
    return table


def _check_common_options(options: Mapping[str, Any]) -> None:
    """Raise InputError for a ``**options`` name of :func:`compare` not common to all methods."""
    allowed = {"mask", "max_iter", "restarts", "respect_limits"}
    unknown = sorted(set(options) - allowed)
    if unknown:
        raise InputError(
            f"unknown option(s) {unknown} for compare; common options are "
            f"{sorted(allowed)}, method-specific ones go in method_options={{name: {{...}}}}"
        )


@dataclass(frozen=True, eq=False)
class _Runs:
    """What every method of :func:`compare` solves: the same targets, guesses and seeds.

    Attributes:
        robot: the robot.
        targets: (N, ...) the targets as given, one per row.
        q0: (N, n) checked initial guesses, or None (each solve draws its start).
        seeds: (N,) the derived seed of each target.
        tol: tolerance on position [m] and orientation [rad] errors.
    """

    robot: Robot
    targets: np.ndarray
    q0: np.ndarray | None
    seeds: np.ndarray
    tol: float

    @property
    def count(self) -> int:
        """Number of targets N."""
        return self.seeds.shape[0]

    def solve(self, k: int, method: str, kw: Mapping[str, Any]) -> Any:
        """Solve target ``k`` with ``method`` and the keywords ``kw``; the IKResult."""
        return solve(self.robot, self.targets[k], method,
                     q0=None if self.q0 is None else self.q0[k], tol=self.tol,
                     seed=int(self.seeds[k]), **kw)


def _method_row(runs: _Runs, method: str, family: str, kw: Mapping[str, Any]) -> CompareRow:
    """Solve every target of ``runs`` with ``method``, timing each solve; its statistics."""
    N = runs.count
    times = np.empty(N)
    ok = np.empty(N, dtype=bool)
    its = np.empty(N)
    pe = np.empty(N)
    oe = np.empty(N)
    inside = np.empty(N, dtype=bool)
    for k in range(N):
        t0 = time.perf_counter()
        res = runs.solve(k, method, kw)
        times[k] = time.perf_counter() - t0
        ok[k] = bool(res.success)
        its[k] = res.iterations
        pe[k] = res.position_error
        oe[k] = res.orientation_error
        inside[k] = bool(runs.robot.within_limits(res.q, 1e-12))
    return CompareRow(
        method=method, family=family, solves=N, success_rate=float(ok.mean()),
        median_time=float(np.median(times)), mean_time=float(times.mean()),
        median_iterations=float(np.median(its)),
        median_position_error=float(np.median(pe)), max_position_error=float(pe.max()),
        median_orientation_error=float(np.median(oe)),
        max_orientation_error=float(oe.max()),
        within_limits_rate=float(inside.mean()),
    )
