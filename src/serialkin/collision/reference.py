"""Self-collision of the zoo robots checked against Pinocchio + coal on the vendor meshes.

The reference is the vendor's own description in example-robot-data: its URDF with the
collision meshes (and the Panda's finger boxes), its SRDF's ``<disable_collisions>``
removed from the pairs (``pinocchio.removeCollisionPairs``), collisions decided by coal.
Optional: needs ``pin`` (Pinocchio ≥ 3 with coal) and ``example-robot-data``
(the ``bench`` extra); :func:`vendor_files` says why a robot cannot be compared.

Configurations map one to one: the zoo model and the vendor URDF take the **same joint
values** (same zero, same sign); their link frames differ by fixed transforms only (the
UR5's DH base is the URDF ``base_link`` turned by π about z, the Panda's hand sits on DH
frame 7 turned by −45°). :func:`frame_offsets` measures those transforms and checks that
they are constant (the comparison refuses to run otherwise). The Panda's fingers, which
are not joints of the zoo chain, get a random opening in [0, 0.04] m: the zoo's finger
capsules hold the finger at every opening.

Agreement over configurations ``q`` drawn uniformly within the zoo robot's limits:

* **false positive** — ours reports a self-collision (clearance < 0) and coal finds every
  pair that ours reports overlapping at least ``margin`` apart on the meshes (pairs are
  compared by link name, so a permanently close pair elsewhere does not hide one);
* **false negative** — coal reports a collision and ours does not (no margin).
"""

from __future__ import annotations

import importlib.metadata
import time
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from serialkin._checks import as_generator

__all__ = ["VENDOR", "Agreement", "CoalReference", "VendorSpec", "compare_with_coal",
           "example_robot_data_share", "frame_offsets", "vendor_files"]


@dataclass(frozen=True)
class VendorSpec:
    """Where a zoo robot's vendor description lives in example-robot-data.

    Attributes:
        urdf: URDF path under ``share/example-robot-data/robots``.
        srdf: SRDF path under the same folder.
        joints: the vendor joint of each zoo joint, in order (same values).
        extra: vendor joints outside the zoo chain, with the range sampled [rad or m].
        base_yaw: the vendor's root link is the zoo base frame turned by this angle about
            z [rad] (``T_base_vroot = Rz(base_yaw)``).
    """

    urdf: str
    srdf: str
    joints: tuple[str, ...]
    extra: dict[str, tuple[float, float]] = field(default_factory=dict)
    base_yaw: float = 0.0

    def T_base_vroot(self) -> np.ndarray:
        """(4, 4) the vendor root link in the zoo base frame."""
        c, s = np.cos(self.base_yaw), np.sin(self.base_yaw)
        T = np.eye(4)
        T[:2, :2] = [[c, -s], [s, c]]
        return T


VENDOR = {
    "panda": VendorSpec("panda_description/urdf/panda.urdf", "panda_description/srdf/panda.srdf",
                        tuple(f"panda_joint{i}" for i in range(1, 8)),
                        {"panda_finger_joint1": (0.0, 0.04)}),
    "ur5": VendorSpec("ur_description/urdf/ur5_robot.urdf", "ur_description/srdf/ur5.srdf",
                      ("shoulder_pan_joint", "shoulder_lift_joint", "elbow_joint",
                       "wrist_1_joint", "wrist_2_joint", "wrist_3_joint"), base_yaw=np.pi),
}

#: Zoo robots with a collision model whose vendor meshes are not in example-robot-data.
NO_VENDOR_MESHES = ("puma560", "stanford", "iiwa7")


def example_robot_data_share() -> Path | None:
    """``.../share`` holding ``example-robot-data/robots`` (the package:// root), or None."""
    try:
        dist = importlib.metadata.distribution("example-robot-data")
    except importlib.metadata.PackageNotFoundError:
        return None
    for f in dist.files or []:
        parts = Path(str(f)).parts
        if "example-robot-data" in parts and parts[-1].endswith(".urdf"):
            full = Path(str(dist.locate_file(f)))
            return Path(*full.parts[: full.parts.index("example-robot-data")])
    return None


def vendor_files(name: str) -> tuple[Path, Path, Path] | str:
    """``(urdf, srdf, package root)`` of zoo robot ``name``, or the reason there are none."""
    spec = VENDOR.get(name)
    if spec is None:
        return (f"{name}: no vendor description in example-robot-data (its allowed pairs "
                "come from never/always-in-collision sampling)")
    try:
        import coal  # noqa: F401
        import pinocchio  # noqa: F401
    except ImportError as exc:
        return f"Pinocchio with coal is not installed ({exc}); pip install pin"
    share = example_robot_data_share()
    if share is None:
        return "example-robot-data is not installed; pip install example-robot-data"
    root = share / "example-robot-data" / "robots"
    urdf, srdf = root / spec.urdf, root / spec.srdf
    for p in (urdf, srdf):
        if not p.is_file():
            return f"{p} is missing from example-robot-data"
    return urdf, srdf, share


class CoalReference:
    """The vendor robot in Pinocchio with coal collision pairs minus the SRDF's.

    Args:
        name: zoo robot name (a key of :data:`VENDOR`).

    Raises:
        RuntimeError: the vendor files or Pinocchio/coal are missing (the reason).
    """

    def __init__(self, name: str) -> None:
        import pinocchio as pin

        files = vendor_files(name)
        if isinstance(files, str):
            raise RuntimeError(files)
        urdf, srdf, share = files
        self.spec = VENDOR[name]
        self.model, self.geom, _ = pin.buildModelsFromUrdf(str(urdf), package_dirs=[str(share)],
                                                           mimic=True)
        self.geom.addAllCollisionPairs()
        pin.removeCollisionPairs(self.model, self.geom, str(srdf))
        self.data = self.model.createData()
        self.gdata = self.geom.createData()
        self._pin = pin
        self._idx = [self.model.idx_qs[self.model.getJointId(j)] for j in self.spec.joints]
        self._extra = [(self.model.idx_qs[self.model.getJointId(j)], lo, hi)
                       for j, (lo, hi) in self.spec.extra.items()]
        go = self.geom.geometryObjects
        self.pair_names = [tuple(sorted((_link(go[p.first].name), _link(go[p.second].name))))
                           for p in self.geom.collisionPairs]

    def vendor_q(self, q: np.ndarray, extra: np.ndarray | None = None) -> np.ndarray:
        """(N, nq) vendor configurations from zoo ``q`` (N, n) and the extra joints (N, e)."""
        q = np.atleast_2d(q)
        out = np.tile(self._pin.neutral(self.model), (q.shape[0], 1))
        out[:, self._idx] = q
        for k, (i, _, _) in enumerate(self._extra):
            out[:, i] = extra[:, k]
        return out

    def sample_extra(self, N: int, rng: np.random.Generator) -> np.ndarray:
        """(N, e) values of the extra joints, uniform in their ranges."""
        lo = np.array([x[1] for x in self._extra])
        hi = np.array([x[2] for x in self._extra])
        return lo + (hi - lo) * rng.random((N, len(self._extra)))

    def link_poses(self, qv: np.ndarray, links: list[str]) -> np.ndarray:
        """(len(links), 4, 4) poses of the vendor links in the zoo base frame at ``qv``."""
        pin = self._pin
        pin.framesForwardKinematics(self.model, self.data, qv)
        return self.spec.T_base_vroot() @ np.array(
            [self.data.oMf[self.model.getFrameId(nm)].homogeneous for nm in links])

    def collide(self, qv: np.ndarray) -> bool:
        """True when a checked pair of meshes intersects at vendor configuration ``qv``."""
        return bool(self._pin.computeCollisions(self.model, self.data, self.geom, self.gdata,
                                                qv, True))

    def pair_distances(self, qv: np.ndarray) -> dict[tuple[str, str], float]:
        """Smallest distance [m] of every checked link pair (sorted names) at ``qv``."""
        self._pin.computeDistances(self.model, self.data, self.geom, self.gdata, qv)
        out: dict[tuple[str, str], float] = {}
        for pair, res in zip(self.pair_names, self.gdata.distanceResults, strict=True):
            out[pair] = min(out.get(pair, np.inf), float(res.min_distance))
        return out

    def distance(self, qv: np.ndarray) -> tuple[float, tuple[str, str]]:
        """Smallest distance [m] of the checked pairs at ``qv`` and the pair (link names)."""
        pin = self._pin
        k = pin.computeDistances(self.model, self.data, self.geom, self.gdata, qv)
        return float(self.gdata.distanceResults[k].min_distance), self.pair_names[k]


def _link(geometry_name: str) -> str:
    """``panda_link3_0`` → ``panda_link3`` (Pinocchio numbers a link's collision shapes)."""
    head, _, tail = geometry_name.rpartition("_")
    return head if tail.isdigit() else geometry_name


def frame_offsets(robot, ref: CoalReference, seed: object = 0, samples: int = 5
                  ) -> tuple[dict[str, np.ndarray], float]:
    """Fixed transforms ``X_b = F_zoo[frame_b]⁻¹ · T_vendor_link_b`` of every collision body.

    Measured at ``samples`` random configurations; returns the transforms (at the first)
    and the largest deviation among the configurations (≈ 1e-15 when the frames
    correspond: same joint values, fixed offsets).
    """
    rng = as_generator(seed)
    model = robot.collision
    bodies = list(model.body_names)
    lo, hi = _limits(robot)
    X0, worst = None, 0.0
    for _ in range(samples):
        q = lo + (hi - lo) * rng.random(robot.n)
        F = robot.fk_all(q)[model.body_frames]
        open_ = np.array([[x[2] for x in ref._extra]]).reshape(1, -1)  # extra joints fixed
        T = ref.link_poses(ref.vendor_q(q, open_)[0], bodies)
        X = np.linalg.inv(F) @ T
        if X0 is None:
            X0 = X
        worst = max(worst, float(np.abs(X - X0).max()))
    return dict(zip(bodies, X0, strict=True)), worst


def _limits(robot) -> tuple[np.ndarray, np.ndarray]:
    lo, hi = robot.qlim[:, 0].copy(), robot.qlim[:, 1].copy()
    lo[~np.isfinite(lo)] = -np.pi
    hi[~np.isfinite(hi)] = np.pi
    return lo, hi


@dataclass(frozen=True)
class Agreement:
    """Our self-collision check against coal's on the same configurations.

    Attributes:
        robot: zoo name.
        samples: configurations compared.
        margin: margin of the false positives [m].
        ours: fraction of configurations where ours reports a self-collision.
        coal: fraction where coal does.
        false_positive: fraction where ours collides and coal finds each of our
            overlapping pairs ≥ ``margin`` apart.
        false_negative: fraction where coal collides and ours does not (no margin).
        fp_pairs: ``{(body, body): count}`` of our closest pair in the false positives.
        fn_pairs: ``{(link, link): count}`` of coal's closest pair in the false negatives.
        frame_error: largest deviation of the zoo ↔ vendor link transforms [m or 1].
        ours_us: time per configuration of our check [µs] (batch).
        coal_us: time per configuration of coal's (``computeCollisions``, first hit) [µs].
    """

    robot: str
    samples: int
    margin: float
    ours: float
    coal: float
    false_positive: float
    false_negative: float
    fp_pairs: dict
    fn_pairs: dict
    frame_error: float
    ours_us: float
    coal_us: float


def compare_with_coal(robot, name: str, samples: int = 10_000, *, seed: object = 0,
                      margin: float = 0.005, acm=None) -> Agreement:
    """Compare ``robot``'s self-collision check with coal's on the vendor meshes.

    Args:
        robot: the zoo robot (with its collision model).
        name: its key in :data:`VENDOR`.
        samples: configurations, uniform within the robot's limits (seeded).
        seed: None, int or Generator.
        margin: false-positive margin [m].
        acm: allowed-collision matrix of ours (default: the model's own allowed pairs).

    Raises:
        RuntimeError: the frames do not correspond (deviation > 1e-9) or the vendor
            files are missing.
    """
    from serialkin.collision.acm import default_acm
    from serialkin.collision.queries import body_pair_distances, self_clearance

    ref = CoalReference(name)
    rng = as_generator(seed)
    _, err = frame_offsets(robot, ref, rng)
    if err > 1e-9:
        raise RuntimeError(f"{name}: zoo and vendor link frames differ by a varying transform "
                           f"({err:.3g}); the joint values do not map one to one")
    model = robot.collision
    acm = default_acm(model) if acm is None else acm
    lo, hi = _limits(robot)
    q = lo + (hi - lo) * rng.random((samples, robot.n))
    qv = ref.vendor_q(q, ref.sample_extra(samples, rng))
    self_clearance(robot, model, q[:2], acm)  # compile / warm
    t = time.perf_counter()
    ours = self_clearance(robot, model, q, acm).distance < 0.0
    ours_us = (time.perf_counter() - t) / samples * 1e6
    t = time.perf_counter()
    hit = np.array([ref.collide(x) for x in qv])
    coal_us = (time.perf_counter() - t) / samples * 1e6
    pairs, d = body_pair_distances(robot, model, q[ours], acm)
    names = [tuple(sorted((model.body_names[i], model.body_names[j]))) for i, j in pairs]
    fp = np.zeros(samples, dtype=bool)
    fp_pairs: dict = {}
    for row, k in enumerate(np.flatnonzero(ours)):
        coal_d = ref.pair_distances(qv[k])
        near = [coal_d.get(names[c], np.inf) < margin for c in np.flatnonzero(d[row] < 0.0)]
        if not any(near):
            fp[k] = True
            pair = names[int(np.argmin(d[row]))]
            fp_pairs[pair] = fp_pairs.get(pair, 0) + 1
    fn = hit & ~ours
    fn_pairs: dict = {}
    for k in np.flatnonzero(fn):
        _, pair = ref.distance(qv[k])
        fn_pairs[pair] = fn_pairs.get(pair, 0) + 1
    return Agreement(name, samples, margin, float(ours.mean()), float(hit.mean()),
                     float(fp.mean()), float(fn.mean()), fp_pairs, fn_pairs, err, ours_us,
                     coal_us)
