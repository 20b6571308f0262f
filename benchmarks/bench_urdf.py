"""URDF import time, FK/Jacobian latency of an imported robot vs its DH twin, and meshes.

Run by hand: ``.venv/bin/python benchmarks/bench_urdf.py``. Needs the bench extra
(example-robot-data) for the Panda URDF. Both robots run the same kernels, so the
latencies should be equal. Figures are the median [10-90 %] of 15 runs, the two models'
runs interleaved.

URDF with meshes (issue 12, needs the ``mesh`` extra): the Panda and the UR5 loaded with
every visual and collision mesh (``Robot.from_urdf(resolve_meshes=True)`` then
``link_meshes`` for both kinds, the mesh cache cleared before each run: a cold load),
against Pinocchio's ``buildModelsFromUrdf`` (kinematics plus visual and collision
geometry models, meshes loaded by coal/assimp) in the same run; then the capsule fit
(``collision_model_from_geometry(merge=True)``) with the meshes cached. Pinocchio also
loads the Panda's fingers (not in serialkin's chain), so its load does a little more
work. Figures are the median [min-max] of 5 runs.
"""

from __future__ import annotations

import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from _common import Stat, interleaved_us, latency_us, record, wall_s  # noqa: E402
from tests.erd import robots_dir, urdf  # noqa: E402

import serialkin as sk  # noqa: E402
from serialkin.model.dh_extract import to_dh_robot  # noqa: E402


def main() -> None:
    path = urdf("panda_description/urdf/panda.urdf")
    if path is None:
        sys.exit("example-robot-data is not installed: pip install -e '.[bench]'")
    text = path.read_text()
    t_import = latency_us(lambda: sk.Robot.from_urdf(text, tip_link="panda_hand"), 5)
    r_urdf = sk.Robot.from_urdf(text, tip_link="panda_hand")
    r_dh = to_dh_robot(r_urdf, "modified")
    q = r_urdf.random_q(seed=0)
    for r in (r_urdf, r_dh):  # compile / warm up
        r.fk(q), r.jacobian(q)
    rows = [("import Panda URDF (parse + chain)", t_import, None)]
    for label in ("fk", "jacobian"):
        f_urdf, f_dh = getattr(r_urdf, label), getattr(r_dh, label)
        t = interleaved_us({"urdf": lambda f=f_urdf: f(q), "dh": lambda f=f_dh: f(q)}, 10000)
        rows.append((f"{label} (URDF model | DH model)", t["urdf"], t["dh"]))
    print(f"{'measure':36s} {'URDF [us]':>22s} {'DH [us]':>22s} {'ratio':>7s}")
    for name, a, b in rows:
        ratio = f"{a / b:7.2f}" if b is not None else f"{'-':>7s}"
        print(f"{name:36s} {a.fmt(2):>22s} {b.fmt(2) if b else '-':>22s} {ratio}")


MESH_ROBOTS = (("Panda", "panda_description/urdf/panda.urdf", "panda_hand"),
               ("UR5", "ur_description/urdf/ur5_robot.urdf", "tool0"))

#: Goal 12.2: a robot with its meshes loads in at most this time, cold [s].
LOAD_TARGET_S = 2.0


def meshes(repeat: int = 5) -> None:
    """Cold URDF-with-meshes load (serialkin vs Pinocchio) and capsule fit time."""
    try:
        import trimesh  # noqa: F401
    except ImportError:
        print("meshes: skipped (pip install -e '.[mesh]')")
        return
    from serialkin.collision.fit import collision_model_from_geometry
    from serialkin.formats.mesh import clear_mesh_cache, link_meshes

    pkg = {"example-robot-data": robots_dir().parent}
    print(f"\n{'URDF with meshes (cold) [s]':36s} {'serialkin':>22s} {'Pinocchio':>22s} "
          f"{'ratio':>7s} {'faces':>9s}")
    for name, rel, tip in MESH_ROBOTS:
        path = str(urdf(rel))

        def load(path=path, tip=tip):
            clear_mesh_cache()
            r = sk.Robot.from_urdf(path, tip_link=tip, resolve_meshes=True, package_map=pkg)
            return r, [m for kind in ("visual", "collision") for m in link_meshes(r, kind)]

        ours = wall_s(load, repeat)
        try:
            import pinocchio as pin

            folder = [str(robots_dir().parent.parent)]
            peer: Stat | None = wall_s(
                lambda p=path, f=folder: pin.buildModelsFromUrdf(p, f), repeat)
        except ImportError:
            peer = None
        robot, loaded = load()
        faces = sum(m.mesh.faces.shape[0] for m in loaded)
        ratio = f"{ours / peer:7.2f}" if peer else f"{'-':>7s}"
        print(f"{name + ' load':36s} {ours.fmt(3):>22s} {peer.fmt(3) if peer else '-':>22s} "
              f"{ratio} {faces:9d}")
        record("12.2", f"{name} URDF + {len(loaded)} meshes, cold load (median)", ours.median,
               "s", f"<= {LOAD_TARGET_S:g} s", ours.median <= LOAD_TARGET_S)
        fit = wall_s(lambda r=robot: collision_model_from_geometry(r, merge=True), repeat)
        _, report = collision_model_from_geometry(robot, merge=True)
        print(f"{name + ' capsule fit (meshes cached)':36s} {fit.fmt(3):>22s} "
              f"{'':>22s} {'':>7s} {report.capsule_count:6d} caps")
        record("12.2", f"{name} capsule fit, {report.capsule_count} capsules (median)",
               fit.median, "s", f"<= {LOAD_TARGET_S:g} s", fit.median <= LOAD_TARGET_S)


if __name__ == "__main__":
    main()
    meshes()
