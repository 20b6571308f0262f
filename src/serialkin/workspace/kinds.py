"""The workspace kinds of chapter section 1, computed by sampling.

* **Maximal (reachable) workspace** — positions the tool reaches with at least one
  orientation: :func:`reachable_workspace`.
* **Constant-orientation workspace** — positions reachable with one fixed tool
  orientation: :func:`constant_orientation_workspace`.
* **Inclusive-orientation workspace** — positions reachable with at least one
  orientation within a range (here: within an angle of a centre orientation); the
  maximal workspace is the case of the full range: :func:`inclusive_orientation_workspace`.
* **Total-orientation workspace** — positions reachable with every orientation (sampled):
  :func:`total_orientation_workspace`.
* **Dexterous workspace** — positions reachable with every sampled orientation *and*
  away from singularities (manipulability above a margin): :func:`dexterous_workspace`.

Planar robots (the tool moves in the world xy plane) give 2D workspaces with boundary
polylines and an area; spatial robots give 3D point clouds, planar slices
(:func:`workspace_slice`) and a volume. Every measure comes with its sampling error
(:class:`~serialkin.workspace.grid.MeasureEstimate`). Positions are in metres, in the
world frame (base transform included, tool point = the robot's tool frame origin).
"""

from __future__ import annotations

from collections.abc import Iterable, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from serialkin._budget import check_allocation
from serialkin._checks import (
    as_float_array,
    as_generator,
    check_int,
    check_positive,
    check_rotation,
    short_repr,
)
from serialkin.errors import InputError, InputTypeError
from serialkin.spatial.transforms import rotz
from serialkin.workspace.grid import (
    MeasureEstimate,
    OccupancyGrid,
    grid_bounds,
    occupancy_grid,
)
from serialkin.workspace.sampling import (
    evaluate,
    manipulability_task,
    project_orientation,
    random_rotations,
    sample_configurations,
)

#: Workspace kinds, as named by the CLI and :func:`compute_workspace`.
KINDS = ("reachable", "constant", "inclusive", "total", "dexterous")

#: Default numbers of joint-space samples.
DEFAULT_SAMPLES_2D = 400_000
DEFAULT_SAMPLES_3D = 1_000_000
#: Default number of cells along the largest extent of the workspace.
DEFAULT_RESOLUTION_2D = 200
DEFAULT_RESOLUTION_3D = 50


@dataclass(frozen=True, eq=False)
class Workspace:
    """A sampled workspace.

    Attributes:
        kind: one of :data:`KINDS`.
        robot_name: the robot's name.
        planar: True for a 2D (xy-plane) workspace, False for 3D.
        points: (N, 2) or (N, 3) tool positions of the accepted samples [m].
        q: (N, n) configurations of those samples [rad / m].
        manipulability: (N,) manipulability (eq 43) of each sample, or None.
        grid: the occupancy grid the measure is computed on.
        estimate: area [m²] (planar) or volume [m³] with its error bound.
        samples: number of joint-space samples drawn.
        seed: the seed used (None when fresh entropy).
        params: kind-specific parameters (orientation, angle range, margin ...).
    """

    kind: str
    robot_name: str
    planar: bool
    points: np.ndarray
    q: np.ndarray
    manipulability: np.ndarray | None
    grid: OccupancyGrid
    estimate: MeasureEstimate
    samples: int
    seed: int | None
    params: dict[str, Any] = field(default_factory=dict)

    @property
    def dim(self) -> int:
        """2 (planar) or 3."""
        return 2 if self.planar else 3

    def boundary(self, fill_gaps: bool = True) -> list[np.ndarray]:
        """Boundary polylines (k, 2) [m] of a planar workspace (see OccupancyGrid.boundary).

        Args:
            fill_gaps: give no rim to cells no sample happened to hit (sampling gaps, see
                :func:`~serialkin.workspace.grid.sampling_gaps`); true holes keep theirs.
        """
        return self.grid.boundary(fill_gaps)

    def manipulability_map(self) -> np.ndarray:
        """Per-cell maximum manipulability over the samples in the cell; NaN where empty."""
        if self.manipulability is None:
            raise InputError("this workspace was computed without manipulability=True")
        return self.grid.values_max(self.points, self.manipulability)

    def summary(self) -> dict[str, Any]:
        """JSON-ready summary: kind, sizes, bounding box and the measure with its error."""
        def plain(v: Any) -> Any:
            if isinstance(v, np.ndarray):
                return v.tolist()
            return v

        return {
            "kind": self.kind,
            "robot": self.robot_name,
            "planar": self.planar,
            "samples": self.samples,
            "accepted": int(self.points.shape[0]),
            "seed": self.seed,
            "bbox_min": self.points.min(axis=0).tolist() if len(self.points) else None,
            "bbox_max": self.points.max(axis=0).tolist() if len(self.points) else None,
            ("area" if self.planar else "volume"): self.estimate.as_dict(),
            "params": {k: plain(v) for k, v in self.params.items()},
        }


def _is_planar(robot: Any, planar: bool | None) -> bool:
    return bool(robot.is_planar) if planar is None else bool(planar)


def _cell_size(points: np.ndarray, cell: float | None, resolution: int | None,
               planar: bool, per_cell: float = 12.0) -> float:
    """Cell edge [m] for a grid of ``points``.

    ``cell`` if given; else the extent / ``resolution``, coarsened when the samples are
    too few for about ``per_cell`` samples per occupied cell (estimated on a coarse
    grid), so Monte-Carlo misses stay small against the resolution error.
    """
    if cell is not None:
        return check_positive(cell, "cell")
    res = check_int(resolution if resolution is not None else
                    (DEFAULT_RESOLUTION_2D if planar else DEFAULT_RESOLUTION_3D),
                    "resolution", minimum=2)
    if points.shape[0] == 0:
        return 1.0
    extent = float((points.max(axis=0) - points.min(axis=0)).max())
    if extent <= 0:
        return 1e-3
    h = extent / res
    if resolution is None:
        d = points.shape[1]
        coarse = occupancy_grid(points, 4 * h)
        measure = coarse.occupied.sum() * (4 * h) ** d
        h = max(h, (measure * per_cell / points.shape[0]) ** (1.0 / d))
    return h


def _seed_value(seed: Any) -> int | None:
    return int(seed) if isinstance(seed, (int, np.integer)) and not isinstance(seed, bool) else None


@dataclass(frozen=True)
class _Sampling:
    """The keyword options every workspace kind shares (see :func:`reachable_workspace`).

    Attributes:
        samples: joint-space samples (None: the kind's default).
        seed: ``None | int | Generator``.
        cell: grid cell edge [m] (None: automatic).
        resolution: cells along the largest extent (None: the default).
        manipulability: also compute each sample's manipulability (eq 43).
        planar: force 2D/3D (None: ``robot.is_planar``).
        progress: progress bar (None: only on a terminal).
    """

    samples: int | None = None
    seed: Any = 0
    cell: float | None = None
    resolution: int | None = None
    manipulability: bool = False
    planar: bool | None = None
    progress: bool | None = None


def _finish(robot: Any, kind: str, planar: bool,
            kept: tuple[np.ndarray, np.ndarray, np.ndarray | None], drawn: int,
            how: _Sampling, params: dict[str, Any],
            grid: OccupancyGrid | None = None) -> Workspace:
    """The :class:`Workspace` of the samples ``kept`` = (q (N, n), points (N, 3), w or None).

    ``drawn`` joint-space samples were drawn with ``how.seed``; the grid is ``grid`` or
    one of ``how.cell`` / ``how.resolution`` over the points (xy only when ``planar``).
    """
    Q, P, w = kept
    pts = P[:, :2] if planar else P
    if grid is None:
        h = _cell_size(pts, how.cell, how.resolution, planar)
        if pts.shape[0]:
            grid = occupancy_grid(pts, h)
        else:
            grid = OccupancyGrid(lower=np.zeros(pts.shape[1]), cell=h,
                                 counts=np.zeros((1,) * pts.shape[1], dtype=np.int64))
    return Workspace(kind=kind, robot_name=robot.name, planar=planar, points=pts, q=Q,
                     manipulability=w, grid=grid, estimate=grid.measure(), samples=drawn,
                     seed=_seed_value(how.seed), params=params)


def _default_samples(samples: int | None, planar: bool) -> int:
    if samples is None:
        return DEFAULT_SAMPLES_2D if planar else DEFAULT_SAMPLES_3D
    return check_int(samples, "samples", minimum=1)


def _target_rotation(orientation: object, planar: bool) -> np.ndarray:
    """(3, 3) rotation from a planar angle φ [rad] or a (3, 3) rotation."""
    a = as_float_array(orientation, "orientation")
    if a.ndim == 0:
        if not planar:
            raise InputError("orientation must be a (3, 3) rotation for a spatial robot, "
                             f"got the scalar {float(a)}")
        return rotz(float(a))
    return check_rotation(a, "orientation")


def reachable_workspace(robot: Any, samples: int | None = None, *, seed: Any = 0,
                        cell: float | None = None, resolution: int | None = None,
                        manipulability: bool = False, planar: bool | None = None,
                        progress: bool | None = None) -> Workspace:
    """Maximal (reachable) workspace: tool positions of uniform joint-space samples.

    Args:
        robot: the robot.
        samples: joint-space samples (default 400,000 planar, 1,000,000 spatial).
        seed: ``None | int | Generator`` (default 0: reproducible).
        cell: grid cell edge [m] (default: the extent / ``resolution``).
        resolution: cells along the largest extent (default 200 planar, 50 spatial).
        manipulability: also compute each sample's manipulability (eq 43) for a map.
        planar: force 2D/3D (default: ``robot.is_planar``).
        progress: progress bar (None: only on a terminal).

    Returns:
        :class:`Workspace` with its area/volume and error bound.
    """
    pl = _is_planar(robot, planar)
    N = _default_samples(samples, pl)
    Q = sample_configurations(robot, N, as_generator(seed) if seed is not None else None)
    task = manipulability_task(robot, pl) if manipulability else None
    S = evaluate(robot, Q, manipulability=task, progress=progress, desc="workspace")
    return _finish(robot, "reachable", pl, (Q, S.position, S.manipulability), N,
                   _Sampling(seed=seed, cell=cell, resolution=resolution),
                   {"manipulability_task": task})


def _oriented_samples(robot: Any, R_t: np.ndarray, max_angle: float, N: int, rng: Any,
                      planar: bool, task: str | None, progress: bool | None, desc: str
                      ) -> tuple[np.ndarray, np.ndarray, np.ndarray | None]:
    Q = sample_configurations(robot, N, rng)
    Q, ok = project_orientation(robot, Q, R_t, max_angle=max_angle, planar=planar)
    Q = Q[ok]
    S = evaluate(robot, Q, manipulability=task, progress=progress, desc=desc)
    return Q, S.position, S.manipulability


def constant_orientation_workspace(robot: Any, orientation: object, samples: int | None = None,
                                   *, seed: Any = 0, cell: float | None = None,
                                   resolution: int | None = None, manipulability: bool = False,
                                   planar: bool | None = None, progress: bool | None = None
                                   ) -> Workspace:
    """Constant-orientation workspace: positions reachable with the tool orientation fixed.

    Each joint-space sample is moved onto the set ``{q : R(q) = R_target}`` by damped
    orientation steps (:func:`~serialkin.workspace.sampling.project_orientation`); the
    samples that reach it (orientation error ≤ 1e-4 rad, inside the limits) are kept.
    For a 3-link planar arm with orientation φ this is the 2-link annulus about the
    wrist, shifted by ``L3 (cos φ, sin φ)``.

    Args:
        robot: the robot.
        orientation: planar angle φ [rad] (planar robots) or a (3, 3) rotation.
        samples: joint-space samples (default as :func:`reachable_workspace`).
        seed: ``None | int | Generator`` (default 0).
        cell: grid cell edge [m] (default: automatic, see :func:`reachable_workspace`).
        resolution: cells along the largest extent.
        manipulability: also compute each sample's manipulability (eq 43).
        planar: force 2D/3D (default: ``robot.is_planar``).
        progress: progress bar (None: only on a terminal).
    """
    return _orientation_range_workspace(
        robot, "constant", orientation, None,
        _Sampling(samples, seed, cell, resolution, manipulability, planar, progress))


def inclusive_orientation_workspace(robot: Any, orientation: object, max_angle: float,
                                    samples: int | None = None, *, seed: Any = 0,
                                    cell: float | None = None, resolution: int | None = None,
                                    manipulability: bool = False, planar: bool | None = None,
                                    progress: bool | None = None) -> Workspace:
    """Inclusive-orientation workspace: reachable with some orientation in a range.

    Positions reachable with at least one orientation within ``max_angle`` [rad] of
    ``orientation``.

    The range of orientations is the cone ``{R : angle(R_target Rᵀ) ≤ max_angle}`` (for a
    planar robot, φ ∈ [φ_t − max_angle, φ_t + max_angle]). ``max_angle = 0`` gives the
    constant-orientation workspace, ``max_angle = π`` the maximal workspace.

    Args:
        robot: the robot.
        orientation: centre orientation: planar angle φ [rad] or a (3, 3) rotation.
        max_angle: half-width of the orientation range [rad], 0..π.
        samples: joint-space samples (default as :func:`reachable_workspace`).
        seed: ``None | int | Generator`` (default 0).
        cell: grid cell edge [m] (default: automatic, see :func:`reachable_workspace`).
        resolution: cells along the largest extent.
        manipulability: also compute each sample's manipulability (eq 43).
        planar: force 2D/3D (default: ``robot.is_planar``).
        progress: progress bar (None: only on a terminal).
    """
    return _orientation_range_workspace(
        robot, "inclusive", orientation, max_angle,
        _Sampling(samples, seed, cell, resolution, manipulability, planar, progress))


def _orientation_range_workspace(robot: Any, kind: str, orientation: object,
                                 max_angle: float | None, how: _Sampling) -> Workspace:
    """Body of the constant- (``max_angle`` None, i.e. 0) and inclusive-orientation kinds.

    Keeps the samples projected onto ``{q : angle(R_target R(q)ᵀ) ≤ max_angle}``.
    """
    pl = _is_planar(robot, how.planar)
    R_t = _target_rotation(orientation, pl)
    params: dict[str, Any] = {"orientation": R_t}
    ma = 0.0
    if max_angle is not None:
        ma = check_positive(max_angle, "max_angle", allow_zero=True)
        if ma > np.pi:
            raise InputError(f"max_angle must be in [0, π] rad, got {max_angle!r}")
        params["max_angle"] = ma
    N = _default_samples(how.samples, pl)
    task = manipulability_task(robot, pl) if how.manipulability else None
    kept = _oriented_samples(robot, R_t, ma, N, as_generator(how.seed), pl, task,
                             how.progress, f"{kind} orientation")
    params["manipulability_task"] = task
    if pl:
        params["phi"] = float(np.arctan2(R_t[1, 0], R_t[0, 0]))
    return _finish(robot, kind, pl, kept, N, how, params)


def _orientation_set(orientations: int | Sequence[object], planar: bool, rng: Any
                     ) -> list[np.ndarray]:
    if isinstance(orientations, (int, np.integer)) and not isinstance(orientations, bool):
        k = check_int(orientations, "orientations", minimum=1)
        check_allocation("the orientation set", (k, 3, 3), 8, setting="orientations")
        if planar:
            return [rotz(phi) for phi in -np.pi + 2 * np.pi * np.arange(k) / k]
        return list(random_rotations(k, rng))
    if isinstance(orientations, (str, bytes)) or not isinstance(orientations, Iterable):
        raise InputTypeError("orientations must be a count or a list of orientations, got "
                             f"{type(orientations).__name__} {short_repr(orientations)}")
    out = [_target_rotation(o, planar) for o in orientations]
    if not out:
        raise InputError("orientations is empty; give a count or at least one orientation")
    return out


def dexterous_workspace(robot: Any, orientations: int | Sequence[object] | None = None,
                        samples: int | None = None, *, singularity_margin: float = 0.05,
                        min_manipulability: float | None = None, seed: Any = 0,
                        cell: float | None = None, resolution: int | None = None,
                        planar: bool | None = None, progress: bool | None = None,
                        kind: str = "dexterous", grid: OccupancyGrid | None = None
                        ) -> Workspace:
    """Dexterous workspace: every sampled orientation, away from singularities.

    For each orientation ``R_k`` the constant-orientation samples are computed and those
    with manipulability ``w < w_min`` dropped; a cell belongs to the dexterous workspace
    when it is occupied for every ``k`` (intersection of the occupancy grids on one
    common grid). ``w_min = min_manipulability`` or, by default,
    ``singularity_margin · max w`` over all samples. With ``singularity_margin = 0`` this
    is the total-orientation workspace of the sampled orientations.

    Sampling caveats: (1) the result is the dexterous set for the *sampled* orientations,
    a superset of the set for every orientation; use enough orientations (its excess
    shrinks like the spacing² of the orientations). (2) A cell missed for one
    orientation drops out of the intersection; the error bound adds each orientation's
    Chao1 estimate of missed cells.

    Args:
        robot: the robot.
        orientations: a count (planar: evenly spaced φ over 2π; spatial: uniform random
            rotations, seeded; default 12 planar, 8 spatial) or a list of orientations.
        samples: joint-space samples per orientation (default: the defaults of
            :func:`reachable_workspace` divided by the number of orientations, at
            least 100,000).
        singularity_margin: relative manipulability margin (0..1).
        min_manipulability: absolute threshold instead of the margin.
        seed: ``None | int | Generator`` (default 0); also draws spatial orientations.
        cell: grid cell edge [m] (default: automatic, coarse enough for the sparsest
            orientation's samples).
        resolution: cells along the largest extent.
        planar: force 2D/3D (default: ``robot.is_planar``).
        progress: progress bar (None: only on a terminal).
        kind: 'dexterous' or 'total' (label only).
        grid: count on this grid (its cell, lower corner and shape) instead of one sized
            for these samples. With the total-orientation workspace's grid and the same
            seed, orientations and samples, the dexterous cells are a subset of the
            total-orientation cells by construction (the samples are a subset), so the
            dexterous area never exceeds the total-orientation area.
    """
    pl = _is_planar(robot, planar)
    margin = check_positive(singularity_margin, "singularity_margin", allow_zero=True)
    sampled = _orientation_samples(robot, orientations, samples, seed, pl, progress)
    return _intersect_orientations(robot, sampled, margin, min_manipulability, seed, cell,
                                   resolution, pl, kind, grid)


def _orientation_samples(robot: Any, orientations: int | Sequence[object] | None,
                         samples: int | None, seed: Any, pl: bool, progress: bool | None
                         ) -> dict[str, Any]:
    """Constant-orientation samples for every orientation of the set (see dexterous_workspace)."""
    rng = as_generator(seed) if seed is not None else as_generator(None)
    if orientations is None:
        orientations = 12 if pl else 8
    Rs = _orientation_set(orientations, pl, rng)
    K = len(Rs)
    if samples is None:
        per = max(100_000, _default_samples(None, pl) // K)
    else:
        per = check_int(samples, "samples", minimum=1)
    check_allocation("the workspace samples", (K * per, robot.n + 16), 8,
                     setting="samples × orientations")
    task = manipulability_task(robot, pl)
    parts = []
    for k, R_t in enumerate(Rs):
        parts.append(_oriented_samples(robot, R_t, 0.0, per, rng, pl, task, progress,
                                       f"orientation {k + 1}/{K}"))
    return {"Rs": Rs, "per": per, "task": task, "parts": parts}


def _intersect_orientations(robot: Any, sampled: dict[str, Any], margin: float,
                            min_manipulability: float | None, seed: Any, cell: float | None,
                            resolution: int | None, pl: bool, kind: str,
                            grid: OccupancyGrid | None) -> Workspace:
    """The cells occupied for every orientation by samples with w ≥ w_min (one grid)."""
    Rs, per, task, parts = sampled["Rs"], sampled["per"], sampled["task"], sampled["parts"]
    K = len(Rs)
    w_all = np.concatenate([p[2] for p in parts]) if parts else np.zeros(0)
    w_max = float(w_all.max()) if w_all.size else 0.0
    w_min = (check_positive(min_manipulability, "min_manipulability", allow_zero=True)
             if min_manipulability is not None else margin * w_max)
    kept = [(Q[w >= w_min], P[w >= w_min], w[w >= w_min]) for Q, P, w in parts]
    dim = 2 if pl else 3
    all_pts = np.concatenate([P[:, :dim] for _, P, _ in kept]) if kept else np.zeros((0, dim))
    params = {"orientations": np.array(Rs), "min_manipulability": w_min,
              "singularity_margin": margin if min_manipulability is None else None,
              "samples_per_orientation": per, "manipulability_task": task}
    how = _Sampling(seed=seed, cell=cell, resolution=resolution)
    if all_pts.shape[0] == 0:
        return _finish(robot, kind, pl, (np.zeros((0, robot.n)), np.zeros((0, 3)), np.zeros(0)),
                       per * K, how, params)
    if grid is not None:
        if grid.dim != dim:
            raise InputError(f"grid must be {dim}-dimensional for this robot, got {grid.dim}D")
        h, lower, shape = grid.cell, grid.lower, grid.shape
    else:  # one common grid, coarse enough for the sparsest orientation's samples
        h = max(_cell_size(P[:, :dim], cell, resolution, pl) for _, P, _ in kept if len(P))
        lower, shape = grid_bounds(all_pts, h)
    counts = None
    unseen = 0.0
    for _, P, _ in kept:
        g = occupancy_grid(P[:, :dim], h, lower=lower, shape=shape)
        unseen += g.measure().unseen
        counts = g.counts if counts is None else np.minimum(counts, g.counts)
    grid = OccupancyGrid(lower=lower, cell=h, counts=counts)
    # keep the samples that fall in the intersection
    Qa = np.concatenate([Q for Q, _, _ in kept])
    Pa = np.concatenate([P for _, P, _ in kept])
    wa = np.concatenate([w for _, _, w in kept])
    idx, inside = grid.index(Pa[:, :dim])
    keep = inside.copy()
    keep[inside] = grid.occupied[tuple(idx[inside].T)]
    ws = _finish(robot, kind, pl, (Qa[keep], Pa[keep], wa[keep]), per * K, how, params,
                 grid=grid)
    # the intersection's own Chao1 count does not see misses of single orientations
    est = ws.estimate
    vol = h ** dim
    extra = max(unseen - est.unseen, 0.0)
    est = MeasureEstimate(value=est.value, error=est.error + vol * extra, lower=est.lower,
                          upper=est.upper + vol * extra, cell=h, n_interior=est.n_interior,
                          n_boundary=est.n_boundary, unseen=est.unseen + extra, dim=dim)
    return Workspace(kind=ws.kind, robot_name=ws.robot_name, planar=pl, points=ws.points,
                     q=ws.q, manipulability=ws.manipulability, grid=grid, estimate=est,
                     samples=ws.samples, seed=ws.seed, params=params)


def total_orientation_workspace(robot: Any, orientations: int | Sequence[object] | None = None,
                                samples: int | None = None, **options: Any) -> Workspace:
    """Total-orientation workspace: every sampled orientation, singularities allowed.

    :func:`dexterous_workspace` with ``singularity_margin = 0``.
    """
    options.setdefault("singularity_margin", 0.0)
    return dexterous_workspace(robot, orientations, samples, kind="total", **options)


def total_and_dexterous_workspaces(robot: Any,
                                   orientations: int | Sequence[object] | None = None,
                                   samples: int | None = None, *,
                                   singularity_margin: float = 0.05,
                                   min_manipulability: float | None = None, seed: Any = 0,
                                   cell: float | None = None, resolution: int | None = None,
                                   planar: bool | None = None, progress: bool | None = None
                                   ) -> tuple[Workspace, Workspace]:
    """The total-orientation and the dexterous workspace from one set of samples, one grid.

    The constant-orientation samples of every orientation are drawn once (as in
    :func:`dexterous_workspace`); the total-orientation workspace keeps all of them, the
    dexterous one those with ``w ≥ w_min``, counted on the total-orientation grid. So the
    dexterous cells are a subset of the total-orientation cells by construction (and its
    area estimate never exceeds the total-orientation one), at the cost of one sampling.

    Args: as :func:`dexterous_workspace`.

    Returns:
        (total-orientation workspace, dexterous workspace).
    """
    pl = _is_planar(robot, planar)
    margin = check_positive(singularity_margin, "singularity_margin", allow_zero=True)
    sampled = _orientation_samples(robot, orientations, samples, seed, pl, progress)
    total = _intersect_orientations(robot, sampled, 0.0, None, seed, cell, resolution, pl,
                                    "total", None)
    dext = _intersect_orientations(robot, sampled, margin, min_manipulability, seed, cell,
                                   resolution, pl, "dexterous", total.grid)
    return total, dext


def compute_workspace(robot: Any, kind: str = "reachable", **options: Any) -> Workspace:
    """Compute a workspace of the given kind (one of :data:`KINDS`) with keyword options.

    ``constant`` and ``inclusive`` need ``orientation`` (and ``max_angle`` for inclusive).
    """
    from serialkin._checks import check_choice

    check_choice(kind, "kind", KINDS)
    if kind == "reachable":
        return reachable_workspace(robot, **options)
    if kind == "constant":
        if "orientation" not in options:
            raise InputError("the constant-orientation workspace needs orientation=")
        return constant_orientation_workspace(robot, **options)
    if kind == "inclusive":
        if "orientation" not in options or "max_angle" not in options:
            raise InputError("the inclusive-orientation workspace needs orientation= and "
                             "max_angle=")
        return inclusive_orientation_workspace(robot, **options)
    if kind == "total":
        return total_orientation_workspace(robot, **options)
    return dexterous_workspace(robot, **options)


@dataclass(frozen=True, eq=False)
class WorkspaceSlice:
    """A planar slice of a 3D workspace.

    Attributes:
        axis: the slicing axis 'x', 'y' or 'z'.
        value: the slice plane's coordinate [m].
        thickness: slab thickness [m].
        axes: names of the two in-plane coordinates, e.g. ('x', 'y').
        points: (M, 2) in-plane coordinates of the samples within the slab [m].
        grid: 2D occupancy grid of those points.
        estimate: cross-section area [m²] with its error bound.
    """

    axis: str
    value: float
    thickness: float
    axes: tuple[str, str]
    points: np.ndarray
    grid: OccupancyGrid
    estimate: MeasureEstimate

    def boundary(self, fill_gaps: bool = True) -> list[np.ndarray]:
        """Boundary polylines (k, 2) of the cross-section [m] (gaps as in Workspace.boundary)."""
        return self.grid.boundary(fill_gaps)


def workspace_slice(ws: Workspace, axis: str = "z", value: float = 0.0,
                    thickness: float | None = None) -> WorkspaceSlice:
    """The samples of a 3D workspace in the slab ``|x_axis − value| ≤ thickness/2``.

    Args:
        ws: a spatial workspace.
        axis: 'x', 'y' or 'z'.
        value: plane coordinate [m].
        thickness: slab thickness [m] (default: the workspace grid's cell).
    """
    from serialkin._checks import check_choice

    if ws.planar:
        raise InputError("workspace_slice needs a spatial (3D) workspace; this one is planar")
    check_choice(axis, "axis", ("x", "y", "z"))
    k = "xyz".index(axis)
    t = ws.grid.cell if thickness is None else check_positive(thickness, "thickness")
    v = float(value)
    sel = np.abs(ws.points[:, k] - v) <= t / 2
    keep = [i for i in range(3) if i != k]
    pts = ws.points[sel][:, keep]
    if pts.shape[0]:
        grid = occupancy_grid(pts, ws.grid.cell)
    else:
        grid = OccupancyGrid(lower=np.zeros(2), cell=ws.grid.cell,
                             counts=np.zeros((1, 1), dtype=np.int64))
    names = ("x", "y", "z")
    return WorkspaceSlice(axis=axis, value=v, thickness=t, axes=(names[keep[0]], names[keep[1]]),
                          points=pts, grid=grid, estimate=grid.measure())
