"""Fit the Panda's and UR5's capsules of serialkin.collision.robots with the library's fit.

The numbers of :mod:`serialkin.collision.robots` for the Panda and the UR5 come from this
script (it needs example-robot-data, the ``bench`` extra, and trimesh, the ``mesh`` extra):

    PYTHONPATH=src python benchmarks/fit_capsules.py

1. the URDF is loaded with its meshes resolved (``Robot.from_urdf(..., resolve_meshes=True)``)
   and capsules are fitted to every link's collision geometry
   (:func:`serialkin.collision.fit.collision_model_from_geometry` with ``merge=True``:
   a bounding capsule of all of a link's shapes, a second one when it saves 20 % of the
   volume);
2. the Panda's fingers hang on prismatic joints, outside the arm's chain: a second robot
   ending at each finger is fitted the same way and its finger frame is fixed to frame 7
   with the finger joint at 0.04 m (fully open);
3. each URDF chain frame is mapped to the zoo model's frame (:mod:`serialkin.models`, DH
   frames) by the transform ``X_f = F_zoo[f]⁻¹ · F_urdf[f]``, checked to be the same at
   three random configurations (the UR5's URDF joint 1 reads q1 + π);
4. the fit is reported: per body the mesh volume, the capsules' volume and the ratio, the
   largest gap (Hausdorff distance capsule ↔ hull), and the fit time.
"""

from __future__ import annotations

import math
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from tests.erd import robots_dir, urdf  # noqa: E402

from serialkin import Robot, models  # noqa: E402
from serialkin.collision.fit import collision_model_from_geometry  # noqa: E402
from serialkin.formats.mesh import clear_mesh_cache  # noqa: E402


def load(rel: str, tip: str) -> Robot:
    """The URDF robot ending at ``tip``, mesh paths resolved.

    The right finger's ``<mimic>`` (not supported: serialkin chains have independent
    joints) is dropped: the finger is placed at 0.04 m by hand anyway.
    """
    text = urdf(rel).read_text().replace('<mimic joint="panda_finger_joint1"/>', "")
    return Robot.from_urdf(text, tip_link=tip, resolve_meshes=True,
                           package_map={"example-robot-data": robots_dir().parent})


def frame_map(zoo: Robot, robot: Robot, offsets=None, extra=(), seed: int = 0) -> np.ndarray:
    """(n+1, 4, 4): X_f with F_zoo[f] · X_f = F_urdf[f], checked at three configurations.

    ``extra`` are the values of the URDF chain's joints beyond the zoo's n (a finger).
    """
    rng = np.random.default_rng(seed)
    X = None
    for _ in range(3):
        q = rng.uniform(-1.5, 1.5, zoo.n)
        qu = np.concatenate([q + (0.0 if offsets is None else np.asarray(offsets)), extra])
        Xi = np.linalg.inv(zoo.fk_all(q)) @ robot.fk_all(qu)[: zoo.n + 1]
        if X is not None and np.abs(Xi - X).max() > 1e-9:
            raise RuntimeError(f"frames of {zoo.name} and its URDF do not correspond")
        X = Xi
    return X


def rows_of(model, report, X: np.ndarray, frame_of=None):
    """(body, zoo frame, [(a, b, r)], shape volume, capsule volume, gap) per body."""
    out = []
    for i, body in enumerate(model.body_names):
        f = int(model.body_frames[i]) if frame_of is None else frame_of
        T = X[int(model.body_frames[i])]
        caps = [(T[:3, :3] @ model.a[s] + T[:3, 3], T[:3, :3] @ model.b[s] + T[:3, 3],
                 float(model.radius[s])) for s in np.flatnonzero(model.shape_body == i)]
        fits = [fit for fit in report.fits if fit.link_name == body]
        out.append((body, f, caps, sum(fit.shape_volume for fit in fits),
                    sum(fit.capsule_volume for fit in fits), max(fit.max_gap for fit in fits)))
    return out


def panda_rows():
    """Capsules of the Panda's arm, hand and both fingers in the zoo's frames."""
    zoo, arm = models.panda(), load("panda_description/urdf/panda.urdf", "panda_hand")
    model, report = collision_model_from_geometry(arm, merge=True)
    rows = rows_of(model, report, frame_map(zoo, arm))
    for finger in ("panda_leftfinger", "panda_rightfinger"):
        r = load("panda_description/urdf/panda.urdf", finger)
        m, rep = collision_model_from_geometry(r, links=[finger], merge=True)
        q = np.zeros(r.n)
        q[-1] = 0.04  # fully open
        F = r.fk_all(q)
        X = frame_map(zoo, r, extra=[0.04])
        X8 = X[7] @ np.linalg.inv(F[7]) @ F[8]  # finger frame in zoo frame 7
        rows += rows_of(m, rep, np.array([X8] * (r.n + 1)), frame_of=7)
    return rows


def ur5_rows():
    """Capsules of the UR5's links in the zoo's frames."""
    zoo, robot = models.ur5(), load("ur_description/urdf/ur5_robot.urdf", "tool0")
    links = [lg.link_name for lg in robot.geometry
             if lg.collision and lg.link_name != "ee_link"]  # ee_link: a 1 cm marker cube
    model, report = collision_model_from_geometry(robot, links=links, merge=True)
    return rows_of(model, report, frame_map(zoo, robot, offsets=[np.pi, 0, 0, 0, 0, 0]))


def main() -> None:
    if urdf("panda_description/urdf/panda.urdf") is None:
        sys.exit("example-robot-data is not installed: pip install -e '.[bench]'")
    for name, fn in (("panda", panda_rows), ("ur5", ur5_rows)):
        clear_mesh_cache()
        t = time.perf_counter()
        rows = fn()
        dt = time.perf_counter() - t
        print(f"# {name}: fitted in {dt:.2f} s (meshes loaded cold); body, frame, a, b, radius "
              "[m]; mesh volume -> capsule volume [l], ratio, largest gap [mm]")
        for body, f, caps, vol, cap, gap in rows:
            for a, b, r in caps:
                # ends rounded to 0.1 mm move by at most 0.09 mm: the radius is rounded
                # up and grown by 0.1 mm so that the printed capsule still holds the mesh
                r_out = math.ceil(r * 1e4) / 1e4 + 1e-4
                print(f'    ("{body}", {f}, {np.round(a, 4).tolist()}, '
                      f"{np.round(b, 4).tolist()}, {r_out:.4f}),")
            print(f"    # {vol * 1e3:.2f} l -> {cap * 1e3:.2f} l, x{cap / vol:.2f}, "
                  f"gap {gap * 1e3:.0f} mm")


if __name__ == "__main__":
    main()
