"""Fit the Panda's and UR5's capsules of serialkin.collision.robots to the vendor meshes.

The numbers of :mod:`serialkin.collision.robots` for the Panda and the UR5 come from this
script (it needs Pinocchio with coal and example-robot-data, the ``bench`` extra, and
trimesh, the ``mesh`` extra):

    PYTHONPATH=src python benchmarks/fit_capsules.py

1. the vendor URDF is loaded by Pinocchio (:class:`serialkin.collision.reference.CoalReference`),
   so that every collision shape coal checks is fitted, the UR5's ``ee_link`` cube and the
   Panda's finger boxes included;
2. each shape's surface is subdivided to edges ≤ 3 mm and moved into the zoo frame of
   its link (same joint values; the fixed transforms are those checked by
   :func:`~serialkin.collision.reference.frame_offsets`); a finger is taken at 21
   openings 0..0.04 m (every 2 mm), so its capsule holds it at any opening;
3. a link's points are cut into ``SLICES`` equal lengths along the axis of its bounding
   capsule and each piece gets its bounding capsule
   (:func:`serialkin.collision.fit.bounding_capsule`):
   the union of the capsules holds every surface point, and a triangle cut between two
   pieces lies within 3 mm / √3 of its corners, so the radii are grown by 1.8 mm, then
   rounded up to 0.1 mm (and 0.1 mm more for the ends rounded to 0.1 mm).

The slice counts were chosen by the false-positive rate against coal (3,000
configurations, ``benchmarks/bench_self_collision.py``): one capsule per link gave 5.6 %
(Panda) and 9.5 % (UR5) at a 5 mm margin, the slices below 3.9 % and 3.8 %.
"""

from __future__ import annotations

import math
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "src"))

from serialkin import models  # noqa: E402
from serialkin.collision.fit import bounding_capsule  # noqa: E402

EDGE = 0.003
SLICES = {"panda": 6, "ur5": 4}


def clouds(name: str) -> dict[str, tuple[np.ndarray, int]]:
    """Surface points of every vendor collision shape in its zoo link frame, per link."""
    import pinocchio as pin
    import trimesh

    from serialkin.collision.reference import CoalReference

    robot, ref = models.get(name), CoalReference(name)
    frame_of = dict(zip(robot.collision.body_names, robot.collision.body_frames, strict=True))
    frame_of.setdefault("ee_link", robot.n)  # the UR5's cube rides on the flange link
    q = np.random.default_rng(1).uniform(-1.0, 1.0, robot.n)
    F = robot.fk_all(q)
    openings = [np.array([[t]]) for t in np.linspace(0.0, 0.04, 21)] if ref.spec.extra else [
        np.zeros((1, 0))]
    surface: dict[str, np.ndarray] = {}
    out: dict[str, list[np.ndarray]] = {}
    for k, extra in enumerate(openings):
        pin.forwardKinematics(ref.model, ref.data, ref.vendor_q(q, extra)[0])
        for go in ref.geom.geometryObjects:
            link = go.name.rpartition("_")[0]
            if k and "finger" not in link:
                continue
            if go.name not in surface:
                g = go.geometry
                m = (trimesh.creation.box(extents=2.0 * np.asarray(g.halfSide))
                     if hasattr(g, "halfSide") else trimesh.load(go.meshPath, force="mesh"))
                v = np.asarray(m.vertices) * (1.0 if hasattr(g, "halfSide")
                                              else np.asarray(go.meshScale))
                surface[go.name] = trimesh.remesh.subdivide_to_size(v, m.faces, EDGE)[0]
            W = ref.spec.T_base_vroot() @ (ref.data.oMi[go.parentJoint] * go.placement).homogeneous
            Z = np.linalg.inv(F[frame_of[link]]) @ W
            out.setdefault(link, []).append(surface[go.name] @ Z[:3, :3].T + Z[:3, 3])
    return {k: (np.vstack(v), int(frame_of[k])) for k, v in out.items()}


def sliced(P: np.ndarray, count: int) -> list[tuple[np.ndarray, np.ndarray, float]]:
    """Bounding capsules of ``count`` equal slices of ``P`` along its bounding capsule's axis."""
    a, b, r = bounding_capsule(P)
    L = float(np.linalg.norm(b - a))
    if count == 1 or L < 1e-9:
        return [(a, b, r)]
    t = (P - a) @ ((b - a) / L)
    edges = np.linspace(t.min(), t.max(), count + 1)
    return [bounding_capsule(P[(t >= lo - 1e-9) & (t <= hi + 1e-9)])
            for lo, hi in zip(edges[:-1], edges[1:], strict=True)]


def main() -> None:
    from serialkin.collision.reference import vendor_files

    for name in ("panda", "ur5"):
        files = vendor_files(name)
        if isinstance(files, str):
            sys.exit(files)
        t = time.perf_counter()
        rows = [(link, f, sliced(P, SLICES[name])) for link, (P, f) in clouds(name).items()]
        print(f"# {name}: fitted in {time.perf_counter() - t:.1f} s; body, frame, a, b, "
              "radius [m]")
        for link, f, caps in rows:
            for a, b, r in caps:
                r_out = math.ceil((r + EDGE / math.sqrt(3.0)) * 1e4) / 1e4 + 1e-4
                print(f'    ("{link}", {f}, {np.round(a, 4).tolist()}, '
                      f"{np.round(b, 4).tolist()}, {r_out:.4f}),")


if __name__ == "__main__":
    main()
