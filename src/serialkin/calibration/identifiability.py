"""Which parameters the measurements can identify: SVD, condition number, a minimal set.

The identification Jacobian J (m·k, p) is scaled column by column to unit norm,
``J_s = J · D⁻¹`` with ``D = diag(‖J_k‖)`` (so that metres and radians compare). Then:

* the singular values σ of ``J_s`` (descending) and the condition number σ_max/σ_min of
  the identifiable set say how well it is determined (the fit's parameter errors grow
  with 1/σ_min);
* the minimal identifiable set is chosen column by column in a fixed priority order
  (base, tool, then the links from the base out): a column is kept when its part
  orthogonal to the kept columns has norm above ``tol`` (Gram–Schmidt with
  re-orthogonalisation), else it is a combination of kept columns and its parameter
  cannot be told apart from them — it is fixed at its current value, never fitted to
  noise. The combination (``J_s,k ≈ Σ c_j J_s,j``) names the parameters involved:
  "d1 and base z cannot be separated". A column of zero norm does not affect the
  measurements at all (e.g. the tool rotations for positions). Residuals above ``tol``
  one by one do not make the kept set well conditioned (they compound), so while its
  smallest singular value is below ``tol/10`` the latest column of its near-dependency
  is dropped as well.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass

import numpy as np

from serialkin._checks import check_positive
from serialkin.calibration.measurements import Measurements
from serialkin.calibration.models import ErrorModel

#: Relative norm below which a scaled column counts as a combination of the kept ones.
RANK_TOL = 1e-6


def _drop_near_dependent(Js: np.ndarray, keep: np.ndarray, seq: Sequence[int],
                         floor: float) -> np.ndarray:
    """Unkeep columns until the kept scaled columns' smallest singular value is ≥ ``floor``.

    Gram–Schmidt residuals above ``tol`` do not bound the kept set's σ_min: residuals
    compound (7.5e-6 then 5.7e-6 left three columns with σ_min 4e-11, and a 24-column set
    exactly singular, on an arm with a 1e-5 rad twist). While σ_min < ``floor``, of the
    kept columns carrying at least half the largest weight of the last right singular
    vector (the near-dependency), the one latest in the priority order ``seq`` is
    dropped: it lies within σ_min·2√k of the others' span. ``keep`` (p,) is updated.

    Returns:
        the singular values (descending) of the final kept columns (empty when none).
    """
    rank_of = {k: i for i, k in enumerate(seq)}
    while keep.any():
        idx = np.flatnonzero(keep)
        s = np.linalg.svd(Js[:, idx], compute_uv=False)
        if s[-1] >= floor:
            return s
        w = np.abs(np.linalg.svd(Js[:, idx], full_matrices=False)[2][-1])
        heavy = idx[w >= 0.5 * w.max()]
        keep[max(heavy, key=lambda k: rank_of[int(k)])] = False
    return np.zeros(0)


def _readmit(Js: np.ndarray, keep: np.ndarray, seq: Sequence[int], tol: float,
             s: np.ndarray) -> np.ndarray:
    """Keep again, in priority order, dropped columns that the final kept set can take.

    :func:`_drop_near_dependent` drops one column of a near-dependency at a time; a
    column dropped early may no longer depend on the kept columns once a later one of
    the same dependency went too (a prismatic joint with a 6e-5 rad twist: its β lay
    0.97 outside the final kept span). A column comes back when its Gram–Schmidt
    residual against the kept columns is above ``tol`` and the kept set's σ_min stays
    ≥ 0.1·``tol`` with it, so the set is maximal: every column left out either lies
    within ``tol`` of the kept span or would make it nearly singular. ``keep`` (p,) is
    updated; returns the final singular values (``s`` when nothing came back).
    """
    for k in seq:
        if keep[k]:
            continue
        idx = np.flatnonzero(keep)
        c = Js[:, k]
        if idx.size:
            c = c - Js[:, idx] @ np.linalg.lstsq(Js[:, idx], c, rcond=None)[0]
        if np.linalg.norm(c) <= tol:
            continue
        trial = np.linalg.svd(Js[:, np.append(idx, k)], compute_uv=False)
        if trial[-1] >= 0.1 * tol:
            keep[k] = True
            s = trial
    return s


@dataclass(frozen=True, eq=False)
class Identifiability:
    """The identifiability of an error model's parameters from a set of measurements.

    Attributes:
        names: (p,) parameter names.
        identifiable: (p,) bool, True for the minimal identifiable set the fit uses.
        singular_values: the scaled Jacobian's singular values over the identifiable set
            (descending).
        condition_number: σ_max/σ_min over the identifiable set (inf if empty).
        condition_number_all: σ_max/σ_min over every parameter (inf when some cannot be
            identified).
        reasons: one sentence per parameter left out, e.g. 'd1 and base z cannot be
            separated'.
        kind: the measurement kind analysed.
    """

    names: tuple[str, ...]
    identifiable: np.ndarray
    singular_values: np.ndarray
    condition_number: float
    condition_number_all: float
    reasons: tuple[str, ...]
    kind: str

    @property
    def rank(self) -> int:
        """Size of the minimal identifiable set."""
        return int(self.identifiable.sum())

    @property
    def unidentifiable(self) -> tuple[str, ...]:
        """Names of the parameters left out of the fit."""
        return tuple(n for n, ok in zip(self.names, self.identifiable) if not ok)

    def summary(self) -> str:
        """A few lines for people: counts, condition numbers, what is left out and why."""
        lines = [f"{self.rank} of {len(self.names)} parameters identifiable from "
                 f"{self.kind} measurements; condition number {self.condition_number:.4g} "
                 f"(all parameters: {self.condition_number_all:.4g})"]
        lines += [f"  - {r}" for r in self.reasons]
        return "\n".join(lines)


def _condition(s: np.ndarray) -> float:
    if s.size == 0 or s[-1] <= 1e-15 * s[0]:
        return float("inf")
    return float(s[0] / s[-1])


def analyse(J: np.ndarray, names: Sequence[str], *, kind: str = "",
            order: Sequence[int] | None = None, tol: float = RANK_TOL,
            exclude: Mapping[int, str] | None = None) -> Identifiability:
    """Identifiability from an identification Jacobian (see the module docstring).

    Args:
        J: (rows, p) identification Jacobian (whitened or not).
        names: (p,) parameter names.
        kind: measurement kind, for sentences.
        order: priority order of the columns (default 0..p-1).
        tol: relative norm below which a scaled column is dependent.
        exclude: columns left out whatever their rank, each with the sentence that says
            why (e.g. too weakly determined to be fitted).

    Returns:
        :class:`Identifiability`.
    """
    tol = check_positive(tol, "tol")
    J = np.asarray(J, dtype=float)
    p = J.shape[1]
    norms = np.linalg.norm(J, axis=0)
    big = norms.max() if p and norms.max() > 0 else 1.0
    effect = norms > 1e-12 * big
    Js = J / np.where(effect, norms, 1.0)
    seq = list(range(p) if order is None else order)
    exclude = {} if exclude is None else dict(exclude)
    keep = np.zeros(p, dtype=bool)
    basis = np.zeros((J.shape[0], 0))
    for k in seq:
        if not effect[k] or k in exclude:
            continue
        c = Js[:, k]
        r = c - basis @ (basis.T @ c)
        r = r - basis @ (basis.T @ r)
        nr = float(np.linalg.norm(r))
        if nr > tol:
            keep[k] = True
            basis = np.column_stack([basis, r / nr])
    s = _drop_near_dependent(Js, keep, seq, 0.1 * tol)
    s = _readmit(Js, keep, [k for k in seq if effect[k] and k not in exclude], tol, s)
    reasons = []
    what = f"{kind} measurements" if kind else "the measurements"
    idx = np.flatnonzero(keep)
    for k in seq:
        if keep[k]:
            continue
        if k in exclude:
            reasons.append(exclude[k])
            continue
        if not effect[k]:
            reasons.append(f"{names[k]} has no effect on {what}")
            continue
        coef = np.linalg.lstsq(Js[:, idx], Js[:, k], rcond=None)[0]
        big_c = np.abs(coef) > 0.05 * np.abs(coef).max()
        others = [names[idx[i]] for i in np.flatnonzero(big_c)]
        if len(others) == 1:
            reasons.append(f"{names[k]} and {others[0]} cannot be separated from {what}")
        else:
            reasons.append(f"{names[k]} cannot be separated from {', '.join(others)} "
                           f"(a combination of them) using {what}")
    s_all = np.linalg.svd(Js, compute_uv=False) if p else np.zeros(0)
    cond_all = _condition(s_all) if effect.all() else float("inf")
    return Identifiability(tuple(names), keep, s, _condition(s), cond_all, tuple(reasons),
                           kind)


def identifiability(model: ErrorModel, measurements: Measurements, params: object = None,
                    *, tol: float = RANK_TOL) -> Identifiability:
    """Identifiability of ``model``'s parameters from ``measurements`` at ``params``.

    The priority order is base, tool, then the links (a redundant link parameter is
    fixed at its nominal value, so the data-sheet value stays where the data cannot
    tell).
    """
    from serialkin.calibration.jacobian import identification_jacobian
    from serialkin.kinematics.parallel import single_threaded_blas

    J = identification_jacobian(model, measurements, params)
    with single_threaded_blas():
        return analyse(J, model.names, kind=measurements.kind, order=priority_order(model),
                       tol=tol)


def priority_order(model: ErrorModel) -> list[int]:
    """Parameter indices in the analysis' priority: base, tool, markers, the links outwards."""
    groups = [p.group for p in model.parameters]
    return ([i for i, g in enumerate(groups) if g == "base"]
            + [i for i, g in enumerate(groups) if g == "tool"]
            + [i for i, g in enumerate(groups) if g == "marker"]
            + [i for i, g in enumerate(groups) if g not in ("base", "tool", "marker")])
