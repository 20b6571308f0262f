"""Fit one bounding capsule per collision mesh of example-robot-data's Panda and UR5.

The numbers of :mod:`serialkin.collision.robots` come from this script (run it to
reproduce them; it needs the ``example-robot-data`` package of the ``bench`` extra):

    PYTHONPATH=src python benchmarks/fit_capsules.py

For each link with a collision mesh (binary STL, read with numpy):

1. the link's world pose is computed from the URDF (joint origins and axes, fixed joints,
   the Panda's finger joints at 0.04 m, fully open) at three random configurations, and the
   fixed transform from the chosen zoo frame (``serialkin.models`` DH frame) to the link is
   checked to be the same at all three (this proves the frame correspondence; the UR5's
   URDF joint 1 reads q1 + π: its ``base_link`` is turned by π about z from the DH base);
2. the mesh vertices, moved into the zoo frame, get a bounding capsule: axis along the
   principal direction of the vertices, centred in the cross-section's bounding square,
   radius = largest distance of a vertex from the axis, ends pulled in as far as every
   vertex stays inside the capsule (a capsule is convex: it then holds the mesh's hull);
3. two capsules replace it when their summed volume is below 0.8 × its volume: the
   vertices' convex hull is cut across its principal axis (19 cut positions tried), each
   half being the hull of its vertices and of the points where hull edges cross the cut,
   so the two capsules together still contain the whole hull;
4. the fit is reported: mesh volume (divergence theorem on the closed triangle soup),
   summed capsule volume and their ratio (≥ 1: the capsules are conservative).
"""

from __future__ import annotations

import math
import sys
import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np

from serialkin import models
from serialkin.spatial.transforms import make_transform, rotx, roty, rotz

SHARE = Path(sys.prefix) / "lib" / f"python{sys.version_info.major}.{sys.version_info.minor}" \
    / "site-packages" / "cmeel.prefix" / "share" / "example-robot-data" / "robots"


def read_stl(path: Path) -> np.ndarray:
    """Triangles (k, 3, 3) of a binary STL file."""
    data = path.read_bytes()
    k = int(np.frombuffer(data, dtype="<u4", count=1, offset=80)[0])
    rec = np.dtype([("n", "<f4", 3), ("v", "<f4", (3, 3)), ("a", "<u2")])
    return np.frombuffer(data, dtype=rec, count=k, offset=84)["v"].astype(float)


def origin(el) -> np.ndarray:
    o = el.find("origin")
    xyz = [0.0] * 3 if o is None else [float(x) for x in o.get("xyz", "0 0 0").split()]
    rpy = [0.0] * 3 if o is None else [float(x) for x in o.get("rpy", "0 0 0").split()]
    return make_transform(R=rotz(rpy[2]) @ roty(rpy[1]) @ rotx(rpy[0]), p=xyz)


def axis_rot(axis, angle) -> np.ndarray:
    a = np.asarray(axis, float) / np.linalg.norm(axis)
    K = np.array([[0, -a[2], a[1]], [a[2], 0, -a[0]], [-a[1], a[0], 0]])
    return np.eye(3) + math.sin(angle) * K + (1 - math.cos(angle)) * K @ K


def link_poses(urdf: Path, values: dict[str, float]) -> dict[str, np.ndarray]:
    """World pose of every link for joint values by name (missing joints at 0)."""
    root = ET.parse(urdf).getroot()
    by_child = {j.find("child").get("link"): j for j in root.findall("joint")}
    poses: dict[str, np.ndarray] = {}

    def pose(link: str) -> np.ndarray:
        if link in poses:
            return poses[link]
        j = by_child.get(link)
        if j is None:
            T = np.eye(4)
        else:
            T = pose(j.find("parent").get("link")) @ origin(j)
            v = values.get(j.get("name"), 0.0)
            ax = [float(x) for x in (j.find("axis").get("xyz") if j.find("axis") is not None
                                      else "1 0 0").split()]
            M = np.eye(4)
            if j.get("type") in ("revolute", "continuous"):
                M[:3, :3] = axis_rot(ax, v)
            elif j.get("type") == "prismatic":
                M[:3, 3] = np.asarray(ax) * v
            T = T @ M
        poses[link] = T
        return T

    for el in root.findall("link"):
        pose(el.get("name"))
    return poses


def collision_meshes(urdf: Path) -> dict[str, tuple[np.ndarray, float]]:
    """Vertices (link frame) and total volume of each link's collision meshes and boxes."""
    root = ET.parse(urdf).getroot()
    out = {}
    for link in root.findall("link"):
        pts, vol = [], 0.0
        for c in link.findall("collision"):
            T = origin(c)
            m, box = c.find("geometry/mesh"), c.find("geometry/box")
            if m is not None:
                tri = read_stl(SHARE / m.get("filename").split("robots/", 1)[1])
                P = tri.reshape(-1, 3)
                vol += abs(np.einsum("ij,ij->i", tri[:, 0],
                                     np.cross(tri[:, 1], tri[:, 2])).sum()) / 6.0
            elif box is not None:
                size = np.array([float(x) for x in box.get("size").split()])
                P = np.array([[sx, sy, sz] for sx in (-1, 1) for sy in (-1, 1)
                              for sz in (-1, 1)]) * size / 2
                vol += float(np.prod(size))
            else:
                continue
            pts.append(P @ T[:3, :3].T + T[:3, 3])
        if pts:
            out[link.get("name")] = (np.concatenate(pts), vol)
    return out


def bounding_capsule(P: np.ndarray) -> tuple[np.ndarray, np.ndarray, float]:
    c = P.mean(axis=0)
    _, _, Vt = np.linalg.svd(P - c)
    u = Vt[0]
    e1, e2 = Vt[1], Vt[2]
    x, y = (P - c) @ e1, (P - c) @ e2
    c = c + e1 * (x.max() + x.min()) / 2 + e2 * (y.max() + y.min()) / 2
    t = (P - c) @ u
    rho = np.linalg.norm((P - c) - np.outer(t, u), axis=1)
    r = rho.max()
    h = np.sqrt(np.maximum(r * r - rho * rho, 0.0))
    # vertex (t, rho) lies within r of the axis segment [lo, hi] iff lo <= t + h and hi >= t - h
    lo, hi = (t + h).min(), (t - h).max()
    if lo > hi:
        lo = hi = (lo + hi) / 2
    return c + lo * u, c + hi * u, float(r)


def capsule_volume(a, b, r) -> float:
    return math.pi * r * r * (float(np.linalg.norm(b - a)) + 4.0 * r / 3.0)


def split_fit(P: np.ndarray, cuts: int = 19):
    """Best pair of capsules covering the convex hull of P, cut across its principal axis.

    The hull is cut by a plane normal to the principal axis; each half is the hull of its
    vertices and of the points where hull edges cross the plane, so the two bounding
    capsules together contain the whole hull. Returns (capsules, summed volume).
    """
    from scipy.spatial import ConvexHull

    hull = ConvexHull(P)
    V = P[hull.vertices]
    c = V.mean(axis=0)
    u = np.linalg.svd(V - c)[2][0]
    edges = {tuple(sorted((int(s[i]), int(s[(i + 1) % 3])))) for s in hull.simplices
             for i in range(3)}
    E = np.array(sorted(edges))
    t = (P - c) @ u
    best = None
    for f in np.linspace(0.05, 0.95, cuts):
        cut = t.min() + f * (t.max() - t.min())
        t0, t1 = t[E[:, 0]], t[E[:, 1]]
        crossing = (t0 - cut) * (t1 - cut) < 0
        w = (cut - t0[crossing]) / (t1[crossing] - t0[crossing])
        X = P[E[crossing, 0]] + w[:, None] * (P[E[crossing, 1]] - P[E[crossing, 0]])
        lo = np.vstack([P[hull.vertices][t[hull.vertices] <= cut], X])
        hi = np.vstack([P[hull.vertices][t[hull.vertices] >= cut], X])
        caps = [bounding_capsule(lo), bounding_capsule(hi)]
        vol = sum(capsule_volume(*k) for k in caps)
        if best is None or vol < best[1]:
            best = (caps, vol)
    return best


def fit(robot, urdf: Path, joint_names, attach: dict[str, int], extra=None, offsets=None,
        seed=0, gain=0.8):
    """Capsules per link: one, or two when their summed volume is below ``gain`` × one's."""
    rng = np.random.default_rng(seed)
    meshes = collision_meshes(urdf)
    fixed = {}
    for trial in range(3):
        q = rng.uniform(-1.5, 1.5, robot.n)
        qu = q + (0.0 if offsets is None else np.asarray(offsets))
        values = dict(zip(joint_names, qu, strict=True)) | (extra or {})
        poses = link_poses(urdf, values)
        F = robot.fk_all(q)
        for link, f in attach.items():
            X = np.linalg.inv(F[f]) @ poses[link]
            if trial == 0:
                fixed[link] = X
            else:
                err = np.abs(X - fixed[link]).max()
                assert err < 1e-9, (link, err)
    rows = []
    for link, f in attach.items():
        X = fixed[link]
        P, vol = meshes[link]
        P = P @ X[:3, :3].T + X[:3, 3]
        one = bounding_capsule(P)
        caps, cap = [one], capsule_volume(*one)
        two = split_fit(P)
        if two[1] < gain * cap:
            caps, cap = two
        rows.append((link, f, caps, vol, cap))
    return rows


def main() -> None:
    panda = models.panda()
    pj = [f"panda_joint{i}" for i in range(1, 8)]
    attach = {f"panda_link{i}": i for i in range(8)} | {
        "panda_hand": 7, "panda_leftfinger": 7, "panda_rightfinger": 7}
    res = {"panda": fit(panda, SHARE / "panda_description/urdf/panda.urdf", pj, attach,
                        {"panda_finger_joint1": 0.04, "panda_finger_joint2": 0.04})}
    ur5 = models.ur5()
    uj = ["shoulder_pan_joint", "shoulder_lift_joint", "elbow_joint", "wrist_1_joint",
          "wrist_2_joint", "wrist_3_joint"]
    names = ["base_link", "shoulder_link", "upper_arm_link", "forearm_link", "wrist_1_link",
             "wrist_2_link", "wrist_3_link"]
    res["ur5"] = fit(ur5, SHARE / "ur_description/urdf/ur5_robot.urdf", uj,
                     {n: i for i, n in enumerate(names)}, offsets=[math.pi, 0, 0, 0, 0, 0])
    for robot, rows in res.items():
        print(f"# {robot}: body, frame, capsules [(a, b, radius)]; mesh volume, capsule volume")
        for link, f, caps, vol, cap in rows:
            text = ", ".join(f"({np.round(a, 4).tolist()}, {np.round(b, 4).tolist()}, {r:.4f})"
                             for a, b, r in caps)
            print(f'    ("{link}", {f}, [{text}]),  # {vol * 1e3:.2f} l -> {cap * 1e3:.2f} l, '
                  f"x{cap / vol:.2f}")


if __name__ == "__main__":
    main()
