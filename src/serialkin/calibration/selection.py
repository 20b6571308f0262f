"""Pose selection: choose K of N candidate configurations that make the fit most precise.

The observability indices of the scaled identification Jacobian ``J_s`` (rows of the K
chosen measurements, columns of the identifiable parameters, each scaled to unit norm
over all candidates), with singular values σ_1 ≥ … ≥ σ_r and L = rows:

* O1 = (σ_1 ··· σ_r)^{1/r} / √L (Borm & Menq 1991): the volume of the uncertainty
  ellipsoid; maximising it is D-optimal design;
* O2 = σ_r / σ_1, the inverse condition number (Driels & Pathre 1990);
* O3 = σ_r, the minimum singular value (Nahvi & Hollerbach 1996);
* O4 = σ_r² / σ_1, the noise amplification index (Nahvi & Hollerbach 1996).

``select_poses`` grows the set greedily (each step adds the candidate that most
increases log det(J_sᵀJ_s + εI), a rank-one-block update), then exchanges members with
candidates while the chosen index improves (at most ``passes`` sweeps).
"""

from __future__ import annotations

import numpy as np

from serialkin._checks import as_generator, check_choice, check_int
from serialkin.calibration.measurements import Measurements
from serialkin.calibration.models import ErrorModel
from serialkin.errors import InputError

#: Observability indices (see the module docstring).
INDICES = ("O1", "O2", "O3", "O4")


def observability(J: np.ndarray, index: str = "O1") -> float:
    """Observability index ``index`` of a scaled identification Jacobian (L, r)."""
    check_choice(index, "index", INDICES)
    s = np.linalg.svd(J, compute_uv=False)
    r = J.shape[1]
    if s.size < r or s[-1] <= 0:
        return 0.0
    if index == "O1":
        return float(np.exp(np.mean(np.log(s))) / np.sqrt(J.shape[0]))
    if index == "O2":
        return float(s[-1] / s[0])
    if index == "O3":
        return float(s[-1])
    return float(s[-1] ** 2 / s[0])


def candidate_jacobians(model: ErrorModel, q: np.ndarray, kind: str) -> np.ndarray:
    """Scaled identification Jacobian blocks (N, k, r) of candidates over the identifiable set."""
    from serialkin.calibration.fit import _generic_measurements
    from serialkin.calibration.identifiability import identifiability
    from serialkin.calibration.jacobian import errors

    meas = _generic_measurements(model, q, kind)
    keep = identifiability(model, meas).identifiable
    _, J = errors(model, meas, jacobian=True)
    if kind == "pose":  # compare metres with radians through the default sigmas
        from serialkin.calibration.measurements import SIGMA_POSITION, SIGMA_ROTATION

        J[:, 3:] *= SIGMA_POSITION / SIGMA_ROTATION
    J = J[:, :, keep]
    norms = np.linalg.norm(J.reshape(-1, J.shape[2]), axis=0) / np.sqrt(len(q))
    return J / norms


def select_poses(model: ErrorModel, candidates: object, count: int, *, kind: str = "position",
                 index: str = "O1", passes: int = 2,
                 seed: None | int | np.random.Generator = None) -> np.ndarray:
    """Indices of ``count`` candidate configurations maximising an observability index.

    Args:
        model: the error model.
        candidates: (N, n) candidate configurations, or an int N for N random ones
            (drawn with ``seed``; then the configurations are ``model.robot.random_q(N,
            seed=seed)``).
        count: K, how many to choose (at least enough rows for the identifiable set).
        kind: the measurement kind planned ('position' or 'pose').
        index: 'O1', 'O2', 'O3' or 'O4' (see the module docstring).
        passes: exchange sweeps after the greedy start.
        seed: for random candidates and the order of exchanges.

    Returns:
        (K,) sorted indices into the candidates.

    Raises:
        InputError: count larger than N, or too small for the identifiable set.
    """
    check_choice(index, "index", INDICES)
    rng = as_generator(seed)
    if isinstance(candidates, (int, np.integer)) and not isinstance(candidates, bool):
        q = model.robot.random_q(check_int(candidates, "candidates", minimum=1), seed=rng)
    else:
        q = model.robot.check_q(candidates).reshape(-1, model.robot.n)
    N = q.shape[0]
    K = check_int(count, "count", minimum=1)
    if K > N:
        raise InputError(f"count must be at most the number of candidates {N}, got {K}")
    passes = check_int(passes, "passes")
    from serialkin.kinematics.parallel import single_threaded_blas

    with single_threaded_blas():
        return _select(model, q, K, kind, index, passes, rng)


def _select(model: ErrorModel, q: np.ndarray, K: int, kind: str, index: str, passes: int,
            rng: np.random.Generator) -> np.ndarray:
    J = candidate_jacobians(model, q, kind)
    k, r = J.shape[1], J.shape[2]
    N = q.shape[0]
    if K * k < r:
        raise InputError(f"count must give at least {r} equations for the {r} identifiable "
                         f"parameters: at least {-(-r // k)} {kind} measurements, got {K}")
    eps = 1e-6
    A = eps * np.eye(r)
    chosen: list[int] = []
    free = np.ones(N, dtype=bool)
    for _ in range(K):
        Ainv = np.linalg.inv(A)
        # log det(A + JᵢᵀJᵢ) − log det A = log det(I + Jᵢ A⁻¹ Jᵢᵀ)
        M = np.eye(k) + J @ Ainv @ np.swapaxes(J, 1, 2)
        gain = np.linalg.slogdet(M)[1]
        gain[~free] = -np.inf
        i = int(np.argmax(gain))
        chosen.append(i)
        free[i] = False
        A = A + J[i].T @ J[i]

    def score(sel: list[int]) -> float:
        return observability(J[sel].reshape(-1, r), index)

    best = score(chosen)
    for _ in range(passes):
        improved = False
        for pos in rng.permutation(K):
            pool = np.flatnonzero(free)
            trial = rng.choice(pool, size=min(len(pool), 64), replace=False) if len(pool) else []
            for c in trial:
                sel = chosen.copy()
                sel[pos] = int(c)
                s = score(sel)
                if s > best:
                    free[chosen[pos]] = True
                    free[c] = False
                    chosen, best, improved = sel, s, True
                    break
        if not improved:
            break
    return np.array(sorted(chosen))


def measurement_observability(model: ErrorModel, measurements: Measurements,
                              index: str = "O1") -> float:
    """Observability index of the configurations of a set of measurements.

    The same scaling as :func:`select_poses`, the measurements being the candidates.
    """
    J = candidate_jacobians(model, np.asarray(measurements.q), measurements.kind)
    return observability(J.reshape(-1, J.shape[2]), index)
