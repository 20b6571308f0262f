"""Fitting capsules to link geometry: bounding capsules of meshes and primitives, with errors.

A capsule ``(a, b, r)`` is the set of points within ``r`` of the segment ``ab``; it is
convex, so a capsule that contains every vertex of a mesh contains the mesh's convex hull.

**One bounding capsule** (:func:`bounding_capsule`) of a point set ``P`` (the hull
vertices): for an axis direction ``u`` the points are projected on the plane normal to
``u`` and the axis is put through the centre of the smallest enclosing circle of the
projection (Welzl's algorithm); the radius is the largest distance ``ρ_i`` of a point
from the axis, and the ends ``t_lo ≤ t_hi`` along the axis are pulled in as far as every
point stays inside: point ``(t_i, ρ_i)`` is within ``r`` of ``[t_lo, t_hi]`` iff
``t_lo ≤ t_i + h_i`` and ``t_hi ≥ t_i − h_i`` with ``h_i = √(r² − ρ_i²)``. Every
direction so gives a bounding capsule of volume ``V(u) = π r² (|b − a| + 4r/3)``; the
three principal directions of ``P`` (eigenvectors of the covariance) are tried, then
``V(u)`` is minimised over directions near the best one (Nelder–Mead, scipy).

**A few capsules** when one is loose (:func:`fit_points`): while the capsules' volume is
above ``loose`` × the hull's volume and fewer than ``max_capsules`` are used, the
loosest piece's hull is cut by a plane normal to its principal axis (19 positions tried);
each half is the hull of its vertices and of the points where hull edges cross the plane,
so the two capsules still contain the whole hull. The split is kept when it saves at
least ``1 − gain`` of the volume (default 20 %).

**Fitting error** (:class:`ShapeFit`): the volume ratio (capsules / shape, ≥ 1 when the
shape is closed) and the largest gap, the Hausdorff distance between each capsule ``C`` and
the convex piece ``K ⊆ C`` it covers. For convex ``K ⊆ C`` that distance is
``max_u (h_C(u) − h_K(u))`` over unit directions ``u`` with support functions
``h_C(u) = max(u·a, u·b) + r`` and ``h_K(u) = max_i u·p_i``; it is evaluated on
:data:`GAP_DIRECTIONS` quasi-uniform directions (a lower bound that converges to it).

**Primitives** are used as they are: a sphere is a sphere (``a = b``), a capsule a
capsule; a box is bounded through its 8 corners, a cylinder through two regular 64-gons
circumscribing its end circles (so the polygonal prism contains the cylinder).

Meshes are loaded with :func:`serialkin.formats.mesh.load_mesh` (the ``serialkin[mesh]``
extra); convex hulls come from :class:`scipy.spatial.ConvexHull` (Qhull).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from serialkin._checks import check_choice, check_int, check_real
from serialkin.errors import InputError, InputTypeError, RobotDefinitionError
from serialkin.model.collision_model import CollisionModel

__all__ = ["GAP_DIRECTIONS", "FitReport", "ShapeFit", "bounding_capsule", "capsule_volume",
           "collision_model_from_geometry", "fit_points", "fit_shape", "max_gap"]

#: Number of directions on which the gap (a Hausdorff distance) is evaluated.
GAP_DIRECTIONS = 2000

Capsule3 = tuple[np.ndarray, np.ndarray, float]


def capsule_volume(a: np.ndarray, b: np.ndarray, r: float) -> float:
    """Volume of a capsule [m³]: ``π r² (|b − a| + 4r/3)`` (cylinder plus two half-balls)."""
    return math.pi * r * r * (float(np.linalg.norm(np.subtract(b, a))) + 4.0 * r / 3.0)


def _directions(count: int) -> np.ndarray:
    """(count, 3) quasi-uniform unit vectors (Fibonacci sphere)."""
    k = np.arange(count) + 0.5
    z = 1.0 - 2.0 * k / count
    phi = math.pi * (3.0 - math.sqrt(5.0)) * k
    s = np.sqrt(1.0 - z * z)
    return np.stack([s * np.cos(phi), s * np.sin(phi), z], axis=1)


_DIRS = _directions(GAP_DIRECTIONS)


def _principal_axes(P: np.ndarray) -> np.ndarray:
    """(3, 3): unit principal directions of the points (rows), largest variance first."""
    Q = P - P.mean(axis=0)
    _, vecs = np.linalg.eigh(Q.T @ Q)
    return vecs.T[::-1].copy()


def _circle_of(p: tuple, q: tuple, r: tuple | None = None) -> tuple[float, float, float]:
    """(cx, cy, radius²) of the circle on diameter pq, or through p, q, r."""
    if r is None:
        cx, cy = (p[0] + q[0]) / 2.0, (p[1] + q[1]) / 2.0
        return cx, cy, (p[0] - cx) ** 2 + (p[1] - cy) ** 2
    bx, by, qx, qy = q[0] - p[0], q[1] - p[1], r[0] - p[0], r[1] - p[1]
    d = 2.0 * (bx * qy - by * qx)
    if abs(d) < 1e-300:  # collinear (only by rounding): the widest pair's circle
        return max((_circle_of(u, v) for u, v in ((p, q), (p, r), (q, r))),
                   key=lambda c: c[2])
    b2, c2 = bx * bx + by * by, qx * qx + qy * qy
    ux, uy = (qy * b2 - by * c2) / d, (bx * c2 - qx * b2) / d
    return p[0] + ux, p[1] + uy, ux * ux + uy * uy


def _enclosing_circle(xy: np.ndarray) -> np.ndarray:
    """Centre (2,) of the smallest circle holding the points ``xy`` (k, 2).

    Welzl's randomised incremental algorithm (expected O(k)) on the points' 2-D hull, in a
    fixed shuffled order (seed 0: the result does not depend on chance).
    """
    from scipy.spatial import ConvexHull, QhullError

    try:
        xy = xy[ConvexHull(xy).vertices]
    except (QhullError, ValueError):
        pass  # collinear or too few points: use them all
    pts = [tuple(p) for p in xy[np.random.default_rng(0).permutation(len(xy))].tolist()]

    def outside(c: tuple[float, float, float], p: tuple) -> bool:
        return (p[0] - c[0]) ** 2 + (p[1] - c[1]) ** 2 > c[2] * (1.0 + 1e-12) + 1e-30

    c = (pts[0][0], pts[0][1], 0.0)
    for i in range(1, len(pts)):
        if outside(c, pts[i]):
            c = (pts[i][0], pts[i][1], 0.0)
            for j in range(i):
                if outside(c, pts[j]):
                    c = _circle_of(pts[i], pts[j])
                    for m in range(j):
                        if outside(c, pts[m]):
                            c = _circle_of(pts[i], pts[j], pts[m])
    return np.array([c[0], c[1]])


def _capsule_along(P: np.ndarray, u: np.ndarray) -> Capsule3:
    """The bounding capsule of ``P`` (k, 3) with axis direction ``u`` (unit)."""
    e1 = np.cross(u, [1.0, 0.0, 0.0] if abs(u[0]) < 0.9 else [0.0, 1.0, 0.0])
    e1 /= np.linalg.norm(e1)
    e2 = np.cross(u, e1)
    m = P.mean(axis=0)
    Q = P - m
    cx, cy = _enclosing_circle(np.stack([Q @ e1, Q @ e2], axis=1))
    c = m + cx * e1 + cy * e2
    t = (P - c) @ u
    rho = np.linalg.norm((P - c) - np.outer(t, u), axis=1)
    r = float(rho.max())
    h = np.sqrt(np.maximum(r * r - rho * rho, 0.0))
    lo, hi = float((t + h).min()), float((t - h).max())
    if lo > hi:  # the points fit in a sphere of radius r on the axis
        lo = hi = (lo + hi) / 2.0
    # grow r by a relative 1e-12 so rounding never leaves a vertex outside
    return c + lo * u, c + hi * u, r * (1.0 + 1e-12) + 1e-15


def _refine_axis(P: np.ndarray, u0: np.ndarray) -> Capsule3:
    """The capsule along the axis direction near ``u0`` of least volume (Nelder–Mead).

    The direction is ``u0 + x e1 + y e2`` normalised (``e1, e2`` ⟂ ``u0``); the
    objective is the volume of :func:`_capsule_along`, a bounding capsule for every
    direction, so any result contains the points.
    """
    from scipy.optimize import minimize

    e1 = np.cross(u0, [1.0, 0.0, 0.0] if abs(u0[0]) < 0.9 else [0.0, 1.0, 0.0])
    e1 /= np.linalg.norm(e1)
    e2 = np.cross(u0, e1)

    def along(x: np.ndarray) -> Capsule3:
        u = u0 + x[0] * e1 + x[1] * e2
        return _capsule_along(P, u / np.linalg.norm(u))

    res = minimize(lambda x: capsule_volume(*along(x)), np.zeros(2), method="Nelder-Mead",
                   options={"xatol": 1e-3, "fatol": 1e-9, "maxfev": 200,
                            "initial_simplex": [[0.0, 0.0], [0.3, 0.0], [0.0, 0.3]]})
    return along(res.x)


def bounding_capsule(points: object, *, refine: bool = True) -> Capsule3:
    """A capsule ``(a, b, r)`` containing every point, of small volume (module docstring).

    Args:
        points: (k, 3) points [m], k >= 1.
        refine: also search the axis direction near the best principal direction
            (Nelder–Mead on the volume, about 100 evaluations); without it only the
            principal directions are tried (faster, up to ×1.6 larger on elbow-shaped
            links).

    Returns:
        ``a`` (3,), ``b`` (3,) axis ends [m] and radius ``r`` [m]; every point is within
        ``r`` of segment ``ab``.
    """
    P = np.asarray(points, dtype=float).reshape(-1, 3)
    if P.shape[0] == 0 or not np.isfinite(P).all():
        raise InputError(f"points must be a non-empty finite (k, 3) array, got {P.shape}")
    if P.shape[0] == 1 or np.ptp(P, axis=0).max() == 0.0:
        return P[0].copy(), P[0].copy(), 0.0
    Vt = _principal_axes(P)
    along = [_capsule_along(P, u / np.linalg.norm(u)) for u in Vt]
    candidates = [_quick_capsule(P), *along]
    if refine:
        vols = [capsule_volume(*c) for c in along]
        candidates.append(_refine_axis(P, Vt[int(np.argmin(vols))]))
    return min(candidates, key=lambda c: capsule_volume(*c))


def max_gap(capsule: Capsule3, points: np.ndarray) -> float:
    """Hausdorff distance between a capsule and the convex hull of ``points`` inside it [m].

    ``max_u (max(u·a, u·b) + r − max_i u·p_i)`` over :data:`GAP_DIRECTIONS` directions
    (module docstring); 0 for a capsule fitting a primitive capsule or sphere exactly.
    """
    a, b, r = capsule
    h_c = np.maximum(_DIRS @ a, _DIRS @ b) + r
    h_k = (_DIRS @ np.asarray(points, dtype=float).T).max(axis=1)
    return float(max((h_c - h_k).max(), 0.0))


def _hull(P: np.ndarray):
    """Qhull hull of P, or None when P is degenerate (flat, a line, a point)."""
    from scipy.spatial import ConvexHull, QhullError

    if P.shape[0] < 4:
        return None
    try:
        return ConvexHull(P)
    except (QhullError, ValueError):
        return None


def _quick_capsule(P: np.ndarray) -> Capsule3:
    """A cheap bounding capsule (principal axis, bounding-square centre) to rank cuts."""
    m = P.mean(axis=0)
    Vt = _principal_axes(P)
    u, e1, e2 = Vt[0], Vt[1], Vt[2]
    x, y = (P - m) @ e1, (P - m) @ e2
    c = m + e1 * (x.max() + x.min()) / 2 + e2 * (y.max() + y.min()) / 2
    t = (P - c) @ u
    rho = np.linalg.norm((P - c) - np.outer(t, u), axis=1)
    r = float(rho.max())
    h = np.sqrt(np.maximum(r * r - rho * rho, 0.0))
    lo, hi = float((t + h).min()), float((t - h).max())
    lo, hi = (lo, hi) if lo <= hi else ((lo + hi) / 2, (lo + hi) / 2)
    return c + lo * u, c + hi * u, r * (1.0 + 1e-12) + 1e-15


def _split(P: np.ndarray, hull, cuts: int = 19):
    """Best cut of the hull of P normal to its principal axis (module docstring).

    Returns ``(volume, [lo, hi])``: the two point sets whose hulls cover the hull of P,
    ranked by the summed volume of their quick capsules; None if no cut is possible.
    """
    V = P[hull.vertices]
    c = V.mean(axis=0)
    u = _principal_axes(V)[0]
    s = hull.simplices
    E = np.unique(np.sort(np.concatenate([s[:, [0, 1]], s[:, [1, 2]], s[:, [2, 0]]]), axis=1),
                  axis=0)
    t = (P - c) @ u
    tv = t[hull.vertices]
    best = None
    for f in np.linspace(0.05, 0.95, cuts):
        cut = tv.min() + f * (tv.max() - tv.min())
        t0, t1 = t[E[:, 0]], t[E[:, 1]]
        crossing = (t0 - cut) * (t1 - cut) < 0
        w = (cut - t0[crossing]) / (t1[crossing] - t0[crossing])
        X = P[E[crossing, 0]] + w[:, None] * (P[E[crossing, 1]] - P[E[crossing, 0]])
        lo = np.vstack([V[tv <= cut], X])
        hi = np.vstack([V[tv >= cut], X])
        if lo.shape[0] == 0 or hi.shape[0] == 0:
            continue
        vol = capsule_volume(*_quick_capsule(lo)) + capsule_volume(*_quick_capsule(hi))
        if best is None or vol < best[0]:
            best = (vol, [lo, hi])
    return best


def _piece(P: np.ndarray):
    """(hull vertices, their hull or None, bounding capsule, hull volume) of a point set."""
    h = _hull(P)
    if h is not None:
        P = P[h.vertices]
        h = _hull(P)  # indexed on the vertices alone
    return P, h, bounding_capsule(P, refine=False), (0.0 if h is None else float(h.volume))


def fit_points(points: object, *, max_capsules: int = 3, loose: float = 1.5,
               gain: float = 0.8) -> tuple[list[Capsule3], list[np.ndarray], float]:
    """Capsules containing the convex hull of ``points``: one, or a few when one is loose.

    Args:
        points: (k, 3) points [m].
        max_capsules: most capsules (>= 1).
        loose: split while the capsules' volume exceeds ``loose`` × the hull volume.
        gain: keep a split only if the two capsules' volume is below ``gain`` × the
            volume of the capsule they replace.

    Returns:
        ``(capsules, pieces, hull_volume)``: the capsules ``(a, b, r)``, the points whose
        hull each one covers (for :func:`max_gap`), and the hull volume [m³] (0 if flat).
    """
    P = np.asarray(points, dtype=float).reshape(-1, 3)
    first = _piece(P)
    pieces = [first]
    target = loose * first[3]
    tried: set[int] = set()
    while len(pieces) < max_capsules:
        if sum(capsule_volume(*k[2]) for k in pieces) <= target:
            break
        # try to split the piece whose capsule wastes the most volume
        order = sorted((i for i in range(len(pieces))
                        if pieces[i][1] is not None and id(pieces[i][0]) not in tried),
                       key=lambda i: pieces[i][3] - capsule_volume(*pieces[i][2]))
        if not order:
            break
        i = order[0]
        Pi, hi, cap, _ = pieces[i]
        best = _split(Pi, hi)
        new = [_piece(part) for part in best[1]] if best is not None else []
        if new and sum(capsule_volume(*k[2]) for k in new) < gain * capsule_volume(*cap):
            pieces[i:i + 1] = new
        else:
            tried.add(id(Pi))
    # the split decisions use principal-axis capsules; the final ones are refined
    return [bounding_capsule(p[0]) for p in pieces], [p[0] for p in pieces], first[3]


@dataclass(frozen=True)
class ShapeFit:
    """The capsules fitted to one shape of one link, and how tight they are.

    Attributes:
        link_name: the link (body) the shape belongs to.
        frame: chain frame 0..n of the link.
        shape: what was fitted (``'mesh <file>'``, ``'box'``, ``'cylinder'``, ...).
        capsules: ``(a, b, r)`` in frame ``frame`` [m]; ``a = b`` for a sphere.
        shape_volume: the shape's volume [m³] (a mesh's enclosed volume; 0 if open or
            flat).
        capsule_volume: the capsules' summed volume [m³].
        max_gap: largest Hausdorff distance between a capsule and the convex part of the
            shape it covers [m] (0 for a primitive sphere or capsule).
    """

    link_name: str
    frame: int
    shape: str
    capsules: tuple[Capsule3, ...]
    shape_volume: float
    capsule_volume: float
    max_gap: float

    @property
    def volume_ratio(self) -> float:
        """Capsule volume / shape volume (≥ 1 for a closed shape; inf if the shape is flat)."""
        return self.capsule_volume / self.shape_volume if self.shape_volume > 0 else math.inf


@dataclass(frozen=True)
class FitReport:
    """The fits of every shape of a robot (:func:`collision_model_from_geometry`)."""

    fits: tuple[ShapeFit, ...]

    @property
    def capsule_count(self) -> int:
        """Total number of capsules and spheres."""
        return sum(len(f.capsules) for f in self.fits)

    @property
    def max_gap(self) -> float:
        """The largest gap over all shapes [m] (0 when there is none)."""
        return max((f.max_gap for f in self.fits), default=0.0)

    def table(self) -> str:
        """A plain-text table: link, shape, capsules, volumes [litre], ratio, gap [mm]."""
        rows = [f"{'link':24s} {'shape':28s} {'caps':>4s} {'shape l':>8s} {'caps l':>8s} "
                f"{'ratio':>6s} {'gap mm':>7s}"]
        for f in self.fits:
            shape = f.shape if len(f.shape) <= 28 else "…" + f.shape[-27:]
            rows.append(f"{f.link_name[:24]:24s} {shape:28s} {len(f.capsules):4d} "
                        f"{f.shape_volume * 1e3:8.3f} {f.capsule_volume * 1e3:8.3f} "
                        f"{f.volume_ratio:6.2f} {f.max_gap * 1e3:7.1f}")
        return "\n".join(rows)


def _shape_points(geometry: object) -> tuple[str, np.ndarray, float]:
    """Points whose hull contains a box or cylinder, its name and exact volume."""
    from serialkin.model.geometry import Box, Cylinder

    if isinstance(geometry, Box):
        s = np.asarray(geometry.size) / 2.0
        corners = np.array([[x, y, z] for x in (-1, 1) for y in (-1, 1) for z in (-1, 1)])
        return "box", corners * s, float(np.prod(geometry.size))
    if not isinstance(geometry, Cylinder):
        raise InputTypeError(f"expected a Box or Cylinder, got {type(geometry).__name__}")
    n = 64
    ang = 2 * math.pi * np.arange(n) / n
    R = geometry.radius / math.cos(math.pi / n)
    ring = np.stack([R * np.cos(ang), R * np.sin(ang)], axis=1)
    h = geometry.length / 2.0
    pts = np.vstack([np.column_stack([ring, np.full(n, -h)]),
                     np.column_stack([ring, np.full(n, h)])])
    return "cylinder", pts, math.pi * geometry.radius ** 2 * geometry.length


def _exact_fit(shape: object, link_name: str, frame: int) -> ShapeFit | None:
    """A sphere or capsule shape as itself (gap 0), or None for other shapes."""
    from serialkin.model.geometry import Capsule, Sphere

    g, T = shape.geometry, shape.origin
    R, p = T[:3, :3], T[:3, 3]
    if isinstance(g, Sphere):
        vol = 4.0 / 3.0 * math.pi * g.radius ** 3
        return ShapeFit(link_name, frame, "sphere", ((p.copy(), p.copy(), g.radius),), vol,
                        vol, 0.0)
    if isinstance(g, Capsule):
        half = R[:, 2] * g.length / 2.0
        cap = (p - half, p + half, g.radius)
        vol = capsule_volume(*cap)
        return ShapeFit(link_name, frame, "capsule", (cap,), vol, vol, 0.0)
    return None


def _posed_points(shape: object, link_name: str) -> tuple[str, np.ndarray, float]:
    """Name, points (in the chain frame) whose hull holds the shape, and its volume."""
    from serialkin.formats.mesh import load_mesh
    from serialkin.model.geometry import Mesh

    g, T = shape.geometry, shape.origin
    if isinstance(g, Mesh):
        try:
            m = load_mesh(g.filename, g.scale)
        except RobotDefinitionError as exc:
            raise RobotDefinitionError(f"link {link_name!r} collision mesh: {exc}") from None
        name, P, vol = f"mesh {g.filename}", m.vertices, m.volume
    else:
        name, P, vol = _shape_points(g)
    return name, P @ T[:3, :3].T + T[:3, 3], vol


def _fit_cloud(name: str, P: np.ndarray, vol: float, link_name: str, frame: int,
               options: dict) -> ShapeFit:
    """Capsules of a point cloud and their fitting error (BLAS on one thread: small products)."""
    from serialkin.kinematics.parallel import single_threaded_blas

    with single_threaded_blas():
        caps, pieces, hull_vol = fit_points(P, **options)
        gap = max(max_gap(c, piece) for c, piece in zip(caps, pieces, strict=True))
    if vol <= 0.0:
        vol = hull_vol
    return ShapeFit(link_name, frame, name, tuple(caps), vol,
                    sum(capsule_volume(*c) for c in caps), gap)


def fit_shape(shape: object, link_name: str = "", frame: int = 0, *,
              max_capsules: int = 3, loose: float = 1.5, gain: float = 0.8) -> ShapeFit:
    """Fit capsules to one posed :class:`~serialkin.model.geometry.Shape`.

    Spheres and capsules are taken as they are; boxes, cylinders and meshes get bounding
    capsules (:func:`fit_points` on their points moved by the shape's origin). Results are
    in the shape's chain frame.

    Raises:
        RobotDefinitionError: a mesh file is missing or corrupt (the message names the link).
        NotSupportedError: a mesh needs trimesh (``serialkin[mesh]``) and it is missing.
    """
    from serialkin.model.geometry import Shape

    if not isinstance(shape, Shape):
        raise InputTypeError(f"shape must be a Shape, got {type(shape).__name__}")
    exact = _exact_fit(shape, link_name, frame)
    if exact is not None:
        return exact
    name, P, vol = _posed_points(shape, link_name)
    return _fit_cloud(name, P, vol, link_name, frame,
                      {"max_capsules": max_capsules, "loose": loose, "gain": gain})


def _fit_link(shapes: Sequence, link_name: str, frame: int, merge: bool,
              options: dict) -> list[ShapeFit]:
    """The fits of one link's shapes: each on its own, or the non-exact ones merged."""
    if not merge:
        return [fit_shape(s, link_name, frame, **options) for s in shapes]
    fits, clouds = [], []
    for s in shapes:
        exact = _exact_fit(s, link_name, frame)
        if exact is not None:
            fits.append(exact)
        else:
            clouds.append(_posed_points(s, link_name))
    if len(clouds) == 1:
        fits.append(_fit_cloud(*clouds[0], link_name, frame, options))
    elif clouds:
        P = np.vstack([c[1] for c in clouds])
        vol = sum(c[2] for c in clouds)
        fits.append(_fit_cloud(f"{len(clouds)} shapes merged", P, vol, link_name, frame,
                               options))
    return fits


def collision_model_from_geometry(robot: object, kind: str = "collision", *,
                                  max_capsules: int = 3, loose: float = 1.5,
                                  gain: float = 0.8,
                                  links: Sequence[str] | None = None,
                                  merge: bool = False,
                                  ) -> tuple[CollisionModel, FitReport]:
    """Fit a capsule collision model to a robot's link geometry.

    One body per link of ``robot.geometry`` that has shapes of kind ``kind`` (named as
    the link, on its chain frame), holding the capsules of all its shapes
    (:func:`fit_shape`).

    Args:
        robot: a :class:`~serialkin.Robot` with geometry (e.g. from a URDF loaded with
            ``resolve_meshes=True``).
        kind: ``'collision'`` or ``'visual'`` shapes.
        max_capsules: most capsules per shape (>= 1).
        loose: split a shape's capsule while capsule volume > ``loose`` × hull volume.
        gain: keep a split only if it saves at least ``1 − gain`` of the volume.
        links: only these links (default: all).
        merge: fit the boxes, cylinders and meshes of a link together (one cloud, fewer
            capsules) instead of each on its own; spheres and capsules stay as they are.

    Returns:
        ``(model, report)``: the :class:`CollisionModel` and the :class:`FitReport` with
        each shape's volume ratio and largest gap.

    Raises:
        InputError: the robot has no geometry of that kind; an unknown link in ``links``.
        RobotDefinitionError: a mesh file is missing or corrupt (names the link and file).
        NotSupportedError: meshes need ``serialkin[mesh]`` and trimesh is missing.
    """
    kind = check_choice(kind, "kind", ("collision", "visual"))
    max_capsules = check_int(max_capsules, "max_capsules", minimum=1, maximum=64)
    loose = check_real(loose, "loose")
    gain = check_real(gain, "gain")
    if loose < 1.0 or not 0.0 < gain <= 1.0:
        raise InputError(f"loose must be >= 1 and gain in (0, 1], got loose={loose}, "
                         f"gain={gain}")
    geometry = tuple(getattr(robot, "geometry", ()))
    if links is not None:
        known = {lg.link_name for lg in geometry}
        for name in links:
            if name not in known:
                raise InputError(f"links: unknown link {name!r}; links with geometry: "
                                 f"{', '.join(sorted(known)) or '(none)'}")
        geometry = tuple(lg for lg in geometry if lg.link_name in set(links))
    bodies, fits = [], []
    for lg in geometry:
        shapes = getattr(lg, kind)
        if not shapes:
            continue
        body = {"name": lg.link_name, "frame": lg.frame, "capsules": [], "spheres": []}
        options = {"max_capsules": max_capsules, "loose": loose, "gain": gain}
        for f in _fit_link(shapes, lg.link_name, lg.frame, bool(merge), options):
            fits.append(f)
            for a, b, r in f.capsules:
                if np.array_equal(a, b):
                    body["spheres"].append({"center": a, "radius": r})
                else:
                    body["capsules"].append({"a": a, "b": b, "radius": r})
        bodies.append(body)
    if not bodies:
        raise InputError(f"robot {getattr(robot, 'name', '')!r} has no {kind} geometry to "
                         "fit (load a URDF with <" + kind + "> elements, or give shapes in "
                         "the robot file)")
    model = CollisionModel.from_dicts(
        bodies, source=f"capsules fitted to the {kind} geometry of "
                       f"{getattr(robot, 'name', 'robot')!r} (serialkin.collision.fit)")
    return model, FitReport(tuple(fits))
