"""Joint limits: closed intervals ``[lo, hi]`` whose ends may be infinite.

Every use of joint limits in serialkin goes through this module: validation of a
``(lower, upper)`` pair (:func:`check_interval`), membership (:func:`inside`,
:func:`inside_mask`), clamping (:func:`clamp`), moving an angle into the interval by
whole turns (:func:`wrap_into`), projection onto the interval (:func:`project`), the
tidy representative of a final configuration (:func:`normalize`) and the finite box
that random configurations are drawn from (:func:`sampling_box`).

Conventions:

* ``lo = -inf`` and/or ``hi = +inf`` mean an open side; ``lo <= hi`` always; a finite
  end has magnitude at most :data:`MAX_LIMIT` (radians or metres; use an infinite end
  for "no limit").
* A revolute joint's value ``q`` and ``q + 2πk`` give the same pose, so an angle outside
  its interval may be moved into it by whole turns; a prismatic joint's cannot.

The scalar functions are numba-compiled (``cache=True``) so that the compiled IK kernels
and the Python code use the same implementation; they also run from Python.
"""

from __future__ import annotations

import math

import numpy as np

from serialkin._checks import MAX_JOINT_VALUE, short_repr
from serialkin.errors import InputError, RobotDefinitionError

from .._jit import njit

TWO_PI = 2.0 * math.pi

#: Largest |angle| [rad] that :func:`normalize` and the IK's nearest-representative
#: step move by whole turns. ``x + 2πk`` is rounded by about ``ulp(x)/2 + |k|·2.4e-16``
#: rad (the double ``2π`` is not exact): about 1e-12 rad here, but 1e-6 rad at 1e10 rad,
#: enough to break a solution's tolerance. A larger angle is left as it is (its pose is
#: the one the solver measured).
TIDY_MAX = 1e4

#: Largest magnitude of a finite joint limit [rad or m]; beyond it the sampling box and
#: the IK cost overflow. Use an infinite end (``±inf``, ``null`` in files) for no limit.
MAX_LIMIT = MAX_JOINT_VALUE

#: Half-width of the default sampling range of an open side: π rad (revolute), 1 m (prismatic).
DEFAULT_HALF_RANGE = {"R": math.pi, "P": 1.0}


def check_interval(qlim: object, where: str) -> tuple[float, float]:
    """Validate a joint-limit pair and return it as ``(lo, hi)`` floats.

    Accepted: a sequence or array of exactly two real numbers (``None`` for an open side:
    ``None`` as lower means ``-inf``, as upper ``+inf``), ``lo <= hi``, neither NaN, not
    both ends infinite on the same side ((inf, inf) or (-inf, -inf) contain no real
    number), finite ends at most :data:`MAX_LIMIT` in magnitude.

    Raises:
        RobotDefinitionError: anything else (a string, a scalar, None, three values...),
            naming ``where`` and showing what came.
    """
    if isinstance(qlim, np.ndarray):
        seq: object = qlim.tolist() if qlim.ndim == 1 else None
    elif isinstance(qlim, (list, tuple)):
        seq = list(qlim)
    else:
        seq = None
    if not isinstance(seq, list) or len(seq) != 2:
        raise RobotDefinitionError(
            f"{where}: joint limits must be a pair (lower, upper) of numbers (None or ±inf "
            f"for an open side), got {type(qlim).__name__} {short_repr(qlim)}"
        )
    ends = []
    for k, (v, open_end) in enumerate(zip(seq, (-math.inf, math.inf))):
        if v is None:
            ends.append(open_end)
            continue
        if isinstance(v, bool) or not isinstance(v, (int, float, np.integer, np.floating)):
            raise RobotDefinitionError(
                f"{where}: joint limit {('lower', 'upper')[k]} must be a number or None, got "
                f"{type(v).__name__} {short_repr(v)}"
            )
        try:
            x = float(v)
        except OverflowError:  # an integer beyond float range
            raise RobotDefinitionError(
                f"{where}: joint limit {short_repr(v)} is too large; finite limits must be at "
                f"most {MAX_LIMIT:g} in magnitude (use inf or None for an open side)"
            ) from None
        if math.isnan(x):
            raise RobotDefinitionError(f"{where}: joint limits must not be NaN, got "
                                       f"{short_repr(qlim)}")
        if math.isfinite(x) and abs(x) > MAX_LIMIT:
            raise RobotDefinitionError(
                f"{where}: joint limit {x:g} is too large; finite limits must be at most "
                f"{MAX_LIMIT:g} in magnitude (use inf or None for an open side)"
            )
        ends.append(x)
    lo, hi = ends
    if lo > hi:
        raise RobotDefinitionError(
            f"{where}: joint limit lower {lo:g} is greater than upper {hi:g}")
    if lo == hi and math.isinf(lo):
        raise RobotDefinitionError(
            f"{where}: joint limits ({lo:g}, {hi:g}) contain no value; use (-inf, inf) for "
            "an unlimited joint"
        )
    return lo, hi


def limits_table(qlim: object, n: int, where: str = "qlim") -> np.ndarray:
    """Joint limits of ``n`` joints as an (n, 2) float array [rad or m], each row checked.

    Accepted: one (lower, upper) pair for every joint, or an (n, 2) table; ±inf for an
    open side. Each row then passes :func:`check_interval`.

    Raises:
        InputError: a string, non-numbers, or another shape (naming ``where``).
        RobotDefinitionError: a row that is not a valid interval.
    """
    expected = f"{where} must be a pair (lower, upper) or have shape ({n}, 2)"
    if isinstance(qlim, (str, bytes)):
        raise InputError(f"{expected}, got {short_repr(qlim)}")
    try:
        lim = np.asarray(qlim, dtype=float)
    except (TypeError, ValueError, OverflowError) as exc:
        raise InputError(f"{expected}, got {short_repr(qlim)}") from exc
    if lim.shape == (2,):
        lim = np.tile(lim, (n, 1))
    if lim.shape != (n, 2):
        raise InputError(f"{expected}, got shape {lim.shape}")
    rows = [check_interval(lim[i], f"{where}[{i}]") for i in range(n)]
    return np.array(rows, dtype=float).reshape(n, 2)


def rate_limits(value: object, n: int, where: str) -> np.ndarray | None:
    """Per-joint limits on a rate (velocity, acceleration) as a read-only (n,) array, or None.

    Accepted: None (no limit stated), one number for every joint, or ``n`` numbers; each
    positive, ``inf`` for a joint whose limit is not stated. Units: rad/s or m/s
    (velocity), rad/s² or m/s² (acceleration), per joint type.

    Raises:
        RobotDefinitionError: another shape, NaN, zero or a negative value (naming
            ``where`` and showing what came).
    """
    if value is None:
        return None
    expected = f"{where} must be one positive number or {n} of them (inf where not stated)"
    if isinstance(value, (str, bytes)):
        raise RobotDefinitionError(f"{expected}, got {short_repr(value)}")
    try:
        a = np.array(value, dtype=float)
    except (TypeError, ValueError, OverflowError):
        raise RobotDefinitionError(f"{expected}, got {short_repr(value)}") from None
    if a.ndim == 0:
        a = np.full(n, float(a))
    if a.shape != (n,):
        raise RobotDefinitionError(f"{expected}, got shape {a.shape}")
    if np.isnan(a).any() or (a <= 0.0).any():
        raise RobotDefinitionError(f"{expected}, got {short_repr(a.tolist())}")
    a.setflags(write=False)
    return a


@njit(cache=True)
def inside(x, lo, hi, tol):
    """True when ``x`` is finite and ``lo − tol <= x <= hi + tol`` (ends may be infinite)."""
    return math.isfinite(x) and x >= lo - tol and x <= hi + tol


def inside_mask(q: np.ndarray, lo: np.ndarray, hi: np.ndarray, tol: float = 0.0) -> np.ndarray:
    """Elementwise :func:`inside` for arrays broadcasting against (..., n) (numpy)."""
    q = np.asarray(q, dtype=np.float64)
    return np.isfinite(q) & (q >= lo - tol) & (q <= hi + tol)


@njit(cache=True)
def clamp(x, lo, hi):
    """The point of ``[lo, hi]`` nearest to ``x`` (prismatic projection)."""
    if x < lo:
        return lo
    if x > hi:
        return hi
    return x


@njit(cache=True)
def turn_mod(t):
    """``t mod 2π`` in [0, 2π] (a tiny negative t rounds up to 2π), bit for bit ``t % (2π)``.

    Within one turn of 0, the common case after an IK step, that is ``t`` or ``t + 2π``
    (Python's float modulo is fmod, exact here, then + 2π when the signs differ), with
    no call to fmod (about 14 ns, against 4 for the test).
    """
    if t > 0.0 and t < TWO_PI:
        return t
    if t < 0.0 and t > -TWO_PI:
        return t + TWO_PI
    return t % TWO_PI


@njit(cache=True)
def wrap_into(x, lo, hi):
    """An angle ``x + 2πk`` inside ``[lo, hi]``, or NaN when the interval holds none.

    ``x`` itself when it is inside; else the smallest such angle when ``lo`` is finite,
    the largest when only ``hi`` is finite (an interval open on one side holds every
    angle modulo 2π).
    """
    if x >= lo and x <= hi:
        return x
    if math.isfinite(lo):
        y = lo + turn_mod(x - lo)
        return y if y <= hi else math.nan
    if math.isfinite(hi):
        return hi - turn_mod(hi - x)
    return x


@njit(cache=True)
def project(x, lo, hi, revolute):
    """Projection of joint value ``x`` onto ``[lo, hi]``.

    A revolute joint is first moved by whole turns (:func:`wrap_into`, same pose); when
    no turn brings it inside, it is set to the end nearer on the circle. A prismatic joint
    is clamped.
    """
    if x >= lo and x <= hi:
        return x
    if revolute:
        y = wrap_into(x, lo, hi)
        if not math.isnan(y):
            return y
        y = lo + turn_mod(x - lo)  # lo and hi are finite here: y in (hi, lo + 2π)
        return hi if y - hi <= lo + TWO_PI - y else lo
    return clamp(x, lo, hi)


@njit(cache=True)
def normalize(x, lo, hi, revolute):
    """The tidy representative of a final joint value (same pose).

    Prismatic joints are unchanged. A revolute joint outside its interval is moved in by
    whole turns when possible. Inside: with both ends infinite it is wrapped into
    [-π, π); with one open side, the representative in [-π, π) is taken when it is
    inside, else the one nearest the finite end; with both ends finite it is unchanged.
    An angle beyond :data:`TIDY_MAX` in magnitude is never moved (rounding would change
    its pose).
    """
    if not revolute or not abs(x) <= TIDY_MAX:
        return x
    if not (x >= lo and x <= hi):
        y = wrap_into(x, lo, hi)
        return x if math.isnan(y) else y
    if math.isfinite(lo) and math.isfinite(hi):
        return x
    r = turn_mod(x + math.pi) - math.pi
    if r >= lo and r <= hi:
        return r
    if math.isfinite(lo):
        return lo + turn_mod(x - lo)
    return hi - turn_mod(hi - x)


def sampling_box(lo: np.ndarray, hi: np.ndarray, half_range: np.ndarray) -> np.ndarray:
    """The finite box random configurations are drawn from, (n, 2).

    A finite end is kept. With ``d`` the joint's default half-range
    (:data:`DEFAULT_HALF_RANGE`: π for revolute, 1 m for prismatic), an infinite lower
    end becomes ``min(−d, hi − 2d)`` and an infinite upper end ``max(d, lo + 2d)``: an
    unlimited joint samples ``[−d, d]``, a joint open on one side a range at least
    ``2d`` wide next to its finite end (for a revolute joint every angle modulo 2π).

    Args:
        lo: (n,) lower ends (-inf allowed).
        hi: (n,) upper ends (+inf allowed).
        half_range: (n,) default half-ranges d [rad or m].
    """
    lo = np.asarray(lo, dtype=np.float64)
    hi = np.asarray(hi, dtype=np.float64)
    d = np.asarray(half_range, dtype=np.float64)
    with np.errstate(invalid="ignore"):
        slo = np.where(np.isfinite(lo), lo, np.minimum(-d, hi - 2 * d))
        shi = np.where(np.isfinite(hi), hi, np.maximum(d, lo + 2 * d))
    return np.stack([slo, shi], axis=-1)


def __getattr__(name: str):
    """``wrap_angle``: the old name of :func:`wrap_into` (warns; removed next release)."""
    if name == "wrap_angle":
        import warnings

        warnings.warn("serialkin.model.limits.wrap_angle is renamed wrap_into (wrapping to "
                      "(-pi, pi] is serialkin.spatial.wrap_angle)", DeprecationWarning,
                      stacklevel=2)
        return wrap_into
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
