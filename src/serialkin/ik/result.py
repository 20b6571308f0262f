"""The one result type every inverse-kinematics method returns.

A failed solve is a result, not an exception: ``success`` is False, ``reason`` says why
and ``q`` holds the best attempt (lowest residual), which is always finite and, with
``respect_limits=True``, inside the joint limits.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from serialkin.errors import InputTypeError

_NEW = object.__new__
_SET = object.__setattr__


@dataclass(frozen=True, eq=False)
class IKResult:
    """Outcome of :func:`serialkin.ik.solve` (and ``robot.ik``).

    For one target the fields are scalars and ``q`` has shape (n,). For a batch of N
    targets every field except ``method`` is an array with leading dimension N
    (``q`` (N, n), ``success`` (N,) bool, ``reason`` (N,) str, ...).

    Attributes:
        q: joint values [rad / m]: the solution, or the best attempt when ``success`` is
            False.
        success: True when the position error and the orientation error (of the task
            coordinates selected by the mask) are both within the tolerance and, with
            ``respect_limits``, q lies inside the joint limits.
        iterations: iterations used in total, over every attempt.
        position_error: ``|p_target − p(q)|`` over the selected position coordinates [m].
        orientation_error: ``|log(R_target R(q)ᵀ)|`` over the selected orientation
            coordinates [rad].
        reason: '' on success, else a sentence saying why the solve failed.
        restarts: how many times the solver restarted from a new random configuration.
        method: name of the method that produced the result.
        clearance: smallest signed distance of the returned q [m] over the checked pairs
            (self pairs not allowed by the collision matrix, robot shapes against the
            scene): negative when shapes overlap; +inf when nothing is checked (no
            ``scene`` nor ``self_collision``). With collision checking a success has
            ``clearance >= margin``.
        closest_pair: the two names realising ``clearance``: two body names, or a body
            name and the scene shape (its name, else ``scene[i]``); ``('', '')`` when
            nothing is checked. A batch holds an (N, 2) str array.
    """

    q: np.ndarray
    success: bool | np.ndarray
    iterations: int | np.ndarray
    position_error: float | np.ndarray
    orientation_error: float | np.ndarray
    reason: str | np.ndarray
    restarts: int | np.ndarray
    method: str
    clearance: float | np.ndarray = np.inf
    closest_pair: tuple[str, str] | np.ndarray = ("", "")

    @classmethod
    def make(cls, q: np.ndarray, success: bool, iterations: int, position_error: float,
             orientation_error: float, reason: str, restarts: int, method: str,
             clearance: float = np.inf, closest_pair: tuple[str, str] = ("", "")) -> IKResult:
        """The result with these fields, built without the frozen ``__init__``'s overhead.

        For the solvers' hot path (about 1 µs less per call); the fields are trusted.
        """
        r = _NEW(cls)
        _SET(r, "__dict__", {
            "q": q, "success": success, "iterations": iterations,
            "position_error": position_error, "orientation_error": orientation_error,
            "reason": reason, "restarts": restarts, "method": method,
            "clearance": clearance, "closest_pair": closest_pair})
        return r

    @classmethod
    def of_rows(cls, batch: bool, method: str, **rows: np.ndarray) -> IKResult:
        """The result of N solves from per-solve arrays, the one way solvers build it.

        ``rows`` holds every field but ``method`` as an array with leading dimension N
        (``q`` (N, n), ``success`` (N,), ..., ``closest_pair`` (N, 2) when given).
        With ``batch`` False (a single target, N = 1) the result is that solve's, with
        scalar fields (:meth:`__getitem__`).
        """
        res = cls(method=method, **rows)
        return res if batch else res[0]

    @property
    def batch(self) -> bool:
        """True when this result holds a batch of solves (``q`` has two dimensions)."""
        return np.ndim(self.q) == 2

    def __len__(self) -> int:
        """Number of solves in a batch result (1 for a single solve)."""
        return int(np.shape(self.q)[0]) if self.batch else 1

    def __getitem__(self, k: int) -> IKResult:
        """The k-th solve of a batch result, as a single result.

        Raises:
            InputTypeError: ``k`` is not an integer (select many solves from the arrays,
                e.g. ``result.q[result.success]``); indexing a single result.
            IndexError: ``k`` out of range.
        """
        if not self.batch:
            raise InputTypeError("a single IKResult cannot be indexed; only batch results can")
        if isinstance(k, (bool, np.bool_)) or not isinstance(k, (int, np.integer)):
            raise InputTypeError(
                f"a batch IKResult is indexed by one integer, got {type(k).__name__}; to "
                "select several solves use its arrays, e.g. result.q[result.success]")
        return IKResult(
            q=np.asarray(self.q)[k].copy(),
            success=bool(np.asarray(self.success)[k]),
            iterations=int(np.asarray(self.iterations)[k]),
            position_error=float(np.asarray(self.position_error)[k]),
            orientation_error=float(np.asarray(self.orientation_error)[k]),
            reason=str(np.asarray(self.reason)[k]),
            restarts=int(np.asarray(self.restarts)[k]),
            method=self.method,
            clearance=float(np.asarray(self.clearance)[k]) if np.ndim(self.clearance)
            else float(self.clearance),
            closest_pair=(tuple(str(x) for x in np.asarray(self.closest_pair)[k])
                          if np.ndim(self.closest_pair) == 2 else tuple(self.closest_pair)),
        )

    def __repr__(self) -> str:
        if self.batch:
            ok = np.asarray(self.success)
            return (
                f"IKResult(method={self.method!r}, batch of {ok.size}: {int(ok.sum())} solved, "
                f"max position error {np.max(self.position_error, initial=0.0):.3g} m, "
                f"max orientation error {np.max(self.orientation_error, initial=0.0):.3g} rad)"
            )
        q = np.array2string(np.asarray(self.q), precision=4, separator=", ")
        tail = "" if self.success else f", reason={self.reason!r}"
        if np.isfinite(self.clearance):
            tail = f", clearance={self.clearance:.3g} m ({self.closest_pair[0]}, " \
                   f"{self.closest_pair[1]}){tail}"
        return (
            f"IKResult(method={self.method!r}, success={bool(self.success)}, q={q}, "
            f"iterations={self.iterations}, restarts={self.restarts}, "
            f"position_error={self.position_error:.3g} m, "
            f"orientation_error={self.orientation_error:.3g} rad{tail})"
        )
