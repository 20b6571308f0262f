"""Joint-space sampling for workspace analysis, on the batched FK/Jacobian kernels.

Configurations are drawn uniformly inside the joint limits (``robot.random_q``, seeded)
and evaluated in chunks by ``robot.fk`` / ``robot.jacobian`` on (N, n) arrays (the
compiled batch kernels). A progress bar (tqdm) is shown on a terminal for long runs.

Orientation-constrained workspaces use :func:`project_orientation`: damped Gauss-Newton
steps on the orientation rows of the geometric Jacobian (eq 36's angular part, the DLS
step of eq 46 corrected by the ERRATA) move each sample onto the set of configurations
whose tool orientation is within ``max_angle`` of a target orientation.
"""

from __future__ import annotations

from collections.abc import Iterator
from dataclasses import dataclass

import numpy as np

from serialkin._budget import check_allocation
from serialkin._checks import as_generator, check_int
from serialkin.kinematics.dls import dls_step_batch
from serialkin.spatial import so3_log, wrap_angle

#: Configurations per chunk (bounds memory: a chunk's Jacobians take chunk·6·n·8 bytes).
CHUNK = 50_000


def progress_bar(total: int, desc: str, progress: bool | None) -> object:
    """A tqdm bar over ``total`` items; ``progress=None`` shows it only on a terminal."""
    from tqdm import tqdm

    disable = None if progress is None else not progress
    return tqdm(total=total, desc=desc, disable=disable, unit="q", unit_scale=True, leave=False)


def chunks(total: int, size: int = CHUNK) -> Iterator[slice]:
    """Slices covering range(total) in pieces of at most ``size``."""
    for start in range(0, total, size):
        yield slice(start, min(start + size, total))


@dataclass(frozen=True, eq=False)
class Samples:
    """Evaluated joint-space samples.

    Attributes:
        q: (N, n) configurations [rad / m].
        position: (N, 3) tool positions in the world frame [m].
        rotation: (N, 3, 3) tool orientations (world from tool).
        manipulability: (N,) manipulability (eq 43) of the chosen task, or None.
    """

    q: np.ndarray
    position: np.ndarray
    rotation: np.ndarray
    manipulability: np.ndarray | None = None


def manipulability_task(robot: object, planar: bool) -> str:
    """The task rows used for the manipulability of workspace maps: planar or spatial."""
    n = robot.n  # type: ignore[attr-defined]
    if planar:
        return "planar_pose" if n >= 3 else "planar"
    return "full" if n >= 6 else "position"


def evaluate(robot: object, Q: np.ndarray, *, manipulability: str | None = None,
             progress: bool | None = None, desc: str = "sampling") -> Samples:
    """FK (and optionally manipulability) of configurations Q (N, n), chunked, with progress."""
    N = Q.shape[0]
    pos = np.empty((N, 3))
    rot = np.empty((N, 3, 3))
    w = np.empty(N) if manipulability else None
    bar = progress_bar(N, desc, progress)
    try:
        for sl in chunks(N):
            T = robot.fk(Q[sl])  # type: ignore[attr-defined]
            pos[sl] = T[:, :3, 3]
            rot[sl] = T[:, :3, :3]
            if w is not None:
                w[sl] = robot.manipulability(Q[sl], task=manipulability)  # type: ignore[attr-defined]
            bar.update(sl.stop - sl.start)  # type: ignore[attr-defined]
    finally:
        bar.close()  # type: ignore[attr-defined]
    return Samples(q=Q, position=pos, rotation=rot, manipulability=w)


def sample_configurations(robot: object, samples: int, seed: None | int | np.random.Generator
                          ) -> np.ndarray:
    """Configurations (samples, n) uniform in the joint limits (see :meth:`Robot.random_q`).

    Raises:
        BudgetError: the samples and their FK results (about ``8·(n + 16)`` bytes each)
            would exceed the memory budget (checked before allocating).
    """
    N = check_int(samples, "samples", minimum=1)
    check_allocation("the workspace samples", (N, robot.n + 16), 8,  # type: ignore[attr-defined]
                     setting="samples (--samples)")
    return robot.random_q(N, seed=as_generator(seed))  # type: ignore[attr-defined]


def orientation_distance(R: np.ndarray, R_target: np.ndarray) -> np.ndarray:
    """Angle [rad] of the rotation between R (..., 3, 3) and R_target (3, 3): ``‖log(R_t Rᵀ)‖``."""
    tr = np.einsum("ij,...ij->...", R_target, R)  # tr(R_t Rᵀ) = sum R_t ∘ R
    return np.arccos(np.clip((tr - 1.0) / 2.0, -1.0, 1.0))


def planar_angle(R: np.ndarray) -> np.ndarray:
    """Orientation angle φ = atan2(R_10, R_00) [rad] of planar tool frames (..., 3, 3)."""
    return np.arctan2(R[..., 1, 0], R[..., 0, 0])


def project_orientation(robot: object, Q: np.ndarray, R_target: np.ndarray, *,
                        max_angle: float = 0.0, planar: bool = False, tol: float = 1e-4,
                        iterations: int = 40, damping: float = 1e-2
                        ) -> tuple[np.ndarray, np.ndarray]:
    """Move configurations until the tool orientation is within ``max_angle`` of ``R_target``.

    Each iteration takes the damped least-squares step (eq 46, corrected)
    ``Δq = J_ωᵀ (J_ω J_ωᵀ + λ² I)⁻¹ e`` on the angular rows ``J_ω`` of the geometric
    Jacobian (rows wx, wy, wz; only wz for planar robots), where ``e`` is the rotation
    vector ``log(R_target Rᵀ)`` shortened so the step stops on the cone of half-angle
    ``max_angle``. Joints that a step would push through a limit are frozen and the step
    recomputed (active set); revolute joints with a full-turn range wrap around. Positions follow
    the orientation freely, so the result samples the constant-orientation
    (``max_angle = 0``) or inclusive-orientation workspace.

    Args:
        robot: the robot.
        Q: (N, n) start configurations (not modified).
        R_target: (3, 3) target orientation (world from tool).
        max_angle: accepted orientation distance [rad].
        planar: planar robot: only the z rotation counts (φ = atan2(R_10, R_00)).
        tol: extra angle tolerance [rad] for acceptance.
        iterations: maximum number of steps.
        damping: λ of the DLS step.

    Returns:
        (Q_new (N, n), accepted (N,) bool): configurations within ``max_angle + tol``.
    """
    Q = np.array(Q, dtype=float, copy=True)
    lo, hi = robot.sampling_limits().T  # type: ignore[attr-defined]
    phi_t = float(planar_angle(R_target))
    # revolute joints whose range spans a full turn wrap around instead of stopping
    wrap = robot.revolute & (hi - lo >= 2 * np.pi - 1e-12)  # type: ignore[attr-defined]
    lam2 = damping * damping
    for sl in chunks(Q.shape[0]):
        Qc = Q[sl]
        active = np.arange(Qc.shape[0])
        for _ in range(iterations):
            T = robot.fk(Qc[active])  # type: ignore[attr-defined]
            if planar:
                err = wrap_angle(phi_t - planar_angle(T[:, :3, :3]))[:, None]
                ang = np.abs(err[:, 0])
            else:
                err = so3_log(R_target @ np.swapaxes(T[:, :3, :3], -1, -2), check=False)
                ang = np.linalg.norm(err, axis=1)
            todo = ang > max_angle + 0.5 * tol
            if not np.any(todo):
                break
            active, err, ang = active[todo], err[todo], ang[todo]
            err = err * (1.0 - max_angle / ang)[:, None]
            J = robot.jacobian(Qc[active])  # type: ignore[attr-defined]
            Jw = J[:, 5:6, :] if planar else J[:, 3:6, :]
            qa = Qc[active]
            dq = _dls_step(Jw, err, lam2)
            # active set: joints the step pushes through a limit are frozen, step recomputed
            blocked = ~wrap & (((qa + dq) < lo) | ((qa + dq) > hi))
            if np.any(blocked):
                dq = _dls_step(Jw * ~blocked[:, None, :], err, lam2)
            qn = qa + dq
            qn = np.where(wrap, lo + np.mod(qn - lo, 2 * np.pi), np.clip(qn, lo, hi))
            Qc[active] = qn
        Q[sl] = Qc
    R = robot.fk(Q)[:, :3, :3]  # type: ignore[attr-defined]
    if planar:
        ang = np.abs(wrap_angle(phi_t - planar_angle(R)))
    else:
        ang = orientation_distance(R, R_target)
    return Q, ang <= max_angle + tol


def _dls_step(Jw: np.ndarray, err: np.ndarray, lam2: float) -> np.ndarray:
    """Batched DLS step ``Jᵀ (J Jᵀ + λ² I)⁻¹ e`` for J (N, m, n), e (N, m) → (N, n)."""
    dq = np.empty((Jw.shape[0], Jw.shape[2]))
    dls_step_batch(np.ascontiguousarray(Jw, dtype=float), np.ascontiguousarray(err, dtype=float),
                   lam2, 0.0, dq)
    return dq


def random_rotations(count: int, seed: None | int | np.random.Generator) -> np.ndarray:
    """``count`` rotations uniform on SO(3) (normalised Gaussian quaternions), (count, 3, 3)."""
    rng = as_generator(seed)
    qv = rng.standard_normal((count, 4))
    qv /= np.linalg.norm(qv, axis=1, keepdims=True)
    w, x, y, z = qv.T
    return np.stack([
        np.stack([1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)], -1),
        np.stack([2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)], -1),
        np.stack([2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)], -1),
    ], axis=-2)
