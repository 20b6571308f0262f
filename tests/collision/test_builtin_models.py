"""Capsules of every built-in model: present, on the right frames, sensible self-collision."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from serialkin import models
from serialkin.collision import CollisionModel, default_acm, self_clearance
from serialkin.collision.robots import PLANAR_RADIUS, scara_collision_model

# a configuration within the limits that the real robot can take without self-contact
HOME = {
    "planar": None, "two_link": None, "three_link": None, "scara": [0, 0, -0.1, 0],
    "puma560": [0, 0, 0, 0, 0, 0], "stanford": [0, 0, 0.8, 0, 0, 0], "ur5": None,
    "panda": [0, -0.785, 0, -2.356, 0, 1.571, 0.785], "iiwa7": [0, 0, 0, 0, 0, 0, 0],
}


def _robot(name: str):
    return models.planar(6) if name == "planar" else models.get(name)


@pytest.mark.parametrize("name", models.names())
def test_every_model_carries_capsules_on_its_frames(name: str) -> None:
    """Each built-in model has a collision model whose bodies sit on frames 0..n."""
    robot = _robot(name)
    model = robot.collision
    assert isinstance(model, CollisionModel) and len(model.body_names) >= 2
    assert model.body_frames.max() <= robot.n and (model.radius > 0).all()


@pytest.mark.parametrize("name", [n for n, q in HOME.items() if q is not None])
def test_home_configuration_is_free_and_few_samples_collide(name: str) -> None:
    """At a home pose no checked pair touches; most random in-limit poses are free."""
    robot = _robot(name)
    model = robot.collision
    acm = default_acm(model)
    assert self_clearance(robot, model, np.array(HOME[name], float), acm).distance > 0
    if name == "panda":
        return  # the Panda's fitted capsules need its SRDF (tests/collision/test_robot.py)
    rng = np.random.default_rng(0)
    q = rng.uniform(robot.qlim[:, 0], robot.qlim[:, 1], (2000, robot.n))
    assert (self_clearance(robot, model, q, acm).distance < 0).mean() < 0.25


def test_folded_planar_arm_reports_the_overlapping_links() -> None:
    """A 3-link arm folded back on itself (q2 = π) makes link 3 overlap link 1."""
    robot = models.three_link()
    c = self_clearance(robot, robot.collision, np.array([0.0, np.pi, 0.0]),
                       default_acm(robot.collision))
    assert c.distance < 0 and c.names(robot.collision) == [("link1", "link3")]


@settings(max_examples=25, deadline=None)
@given(lengths=st.lists(st.floats(0.0, 2.0), min_size=1, max_size=6),
       seed=st.integers(0, 2**31))
def test_planar_capsules_join_the_joints(lengths: list[float], seed: int) -> None:
    """Capsule i runs from joint i to joint i+1 (the link frames' origins), radius 5 % L_i."""
    robot = models.planar(len(lengths), lengths)
    model = robot.collision
    q = np.random.default_rng(seed).uniform(-np.pi, np.pi, robot.n)
    F = robot.fk_all(q)
    for s in range(robot.n):
        T = F[model.shape_frame[s]]
        np.testing.assert_allclose(T[:3, :3] @ model.a[s] + T[:3, 3], F[s][:3, 3], atol=1e-12)
        np.testing.assert_allclose(T[:3, :3] @ model.b[s] + T[:3, 3], F[s + 1][:3, 3],
                                   atol=1e-12)
    np.testing.assert_allclose(model.radius, PLANAR_RADIUS * np.asarray(lengths))


def test_scara_capsules_follow_its_size() -> None:
    """The SCARA's capsules scale with l1 + l2 and its quill with the stroke."""
    small = models.scara(l1=0.175, l2=0.15, q3_range=(-0.2, 0.0)).collision
    big = scara_collision_model()
    np.testing.assert_allclose(small.radius, big.radius / 2)
    quill = small.body_index("quill")
    assert np.linalg.norm(small.b[quill] - small.a[quill]) == pytest.approx(0.2)


def test_bodyless_frames_do_not_separate_neighbours() -> None:
    """Puma: forearm (frame 3) and wrist (frame 5) are adjacent, frame 4 carrying nothing."""
    import dataclasses

    model = dataclasses.replace(models.puma560().collision, allowed=())  # adjacency only
    acm = default_acm(model)
    assert acm.is_allowed("forearm", "wrist") and acm.is_allowed("wrist", "flange")
    assert not acm.is_allowed("forearm", "flange")
    assert not acm.is_allowed("pedestal", "upper_arm")


@pytest.mark.parametrize(("name", "rel", "tip", "base_yaw"), [
    ("panda", "panda_description/urdf/panda.urdf", "panda_hand", 0.0),
    ("ur5", "ur_description/urdf/ur5_robot.urdf", "tool0", np.pi),  # base_link = Rz(π)·DH base
])
def test_shipped_capsules_contain_the_collision_meshes(name, rel, tip, base_yaw) -> None:
    """Every collision-mesh vertex of the Panda and UR5 lies inside its body's capsules."""
    from tests.erd import robots_dir, urdf

    pytest.importorskip("trimesh")
    from serialkin import Robot
    from serialkin.formats.mesh import link_meshes

    path = urdf(rel)
    if path is None:
        pytest.skip("example-robot-data (bench extra) is not installed")
    zoo = models.get(name)
    src = Robot.from_urdf(str(path), tip_link=tip, resolve_meshes=True,
                          package_map={"example-robot-data": robots_dir().parent})
    q = np.random.default_rng(0).uniform(-1, 1, zoo.n)
    c, s = np.cos(base_yaw), np.sin(base_yaw)
    Rz = np.array([[c, -s, 0, 0], [s, c, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1]])
    X = np.linalg.inv(zoo.fk_all(q)) @ Rz @ src.fk_all(q)  # zoo ← URDF, same joint values
    model, checked = zoo.collision, 0
    for lm in link_meshes(src, "collision"):
        if lm.link_name not in model.body_names:
            continue
        T = X[lm.frame]
        P = lm.mesh.vertices @ T[:3, :3].T + T[:3, 3]
        i = model.body_index(lm.link_name)
        inside = np.zeros(len(P), bool)
        for s in np.flatnonzero(model.shape_body == i):
            a, b, r = model.a[s], model.b[s], model.radius[s]
            d = b - a
            t = np.clip((P - a) @ d / max(d @ d, 1e-30), 0, 1)
            inside |= np.linalg.norm(P - a - t[:, None] * d, axis=1) <= r
        assert inside.all(), lm.link_name
        checked += 1
    assert checked == (9 if name == "panda" else 7)


def test_ur5_self_collision_works_out_of_the_box():
    """The zoo UR5 ships the vendor SRDF's allowed pairs: random q mostly free."""
    import dataclasses

    from serialkin.collision import AllowedCollisionMatrix, default_acm, sampled_acm, self_clearance

    robot = models.get("ur5")
    sampled = sampled_acm(robot, robot.collision, samples=2000, seed=1)
    assert default_acm(robot.collision).checked_pairs() == sampled.checked_pairs()
    Q = robot.random_q(500, seed=2)  # joints over ±2π: the wrist often folds into the arm
    free = (self_clearance(robot, robot.collision, Q).distance > 0).mean()
    strict = AllowedCollisionMatrix(robot.collision.body_names,
                                    default_acm(dataclasses.replace(robot.collision,
                                                                    allowed=())).allowed)
    free_strict = (self_clearance(robot, robot.collision, Q, acm=strict).distance > 0).mean()
    assert free > 0.7 and free_strict < 0.1


def test_allowed_pairs_round_trip_through_dicts_and_robot_files(tmp_path):
    """A model's allowed pairs survive to_dicts/from_dicts and a robot file; unknown names fail."""
    from serialkin.errors import InputError
    from serialkin.formats.robotfile import load_robot_file, save_robot_file
    from serialkin.model.collision_model import CollisionModel

    robot = models.get("ur5")
    model = robot.collision
    assert ("base_link", "upper_arm_link") in model.allowed
    assert CollisionModel.from_dicts(model.to_dicts()).allowed == model.allowed
    path = tmp_path / "ur5.yaml"
    save_robot_file(robot, path)
    assert load_robot_file(path).collision.allowed == model.allowed
    bad = model.to_dicts()
    bad[0]["allowed"] = ["no_such_body"]
    with pytest.raises(InputError, match="no_such_body"):
        CollisionModel.from_dicts(bad)
