"""Robot collision model, allowed-collision matrix, SRDF and batched clearance queries."""

from __future__ import annotations

import math
import sys
from pathlib import Path

import numpy as np
import pytest

from serialkin import models
from serialkin.collision import (
    AllowedCollisionMatrix,
    CollisionModel,
    acm_from_srdf,
    default_acm,
    in_collision,
    panda_collision_model,
    read_srdf,
    sampled_acm,
    scene_clearance,
    self_clearance,
    ur5_collision_model,
)
from serialkin.collision import kernels as K
from serialkin.errors import InputError, RobotDefinitionError
from serialkin.model.geometry import Box, Capsule, Cylinder, HalfSpace, Sphere

_SHARE = (Path(sys.prefix) / "lib" / f"python{sys.version_info.major}.{sys.version_info.minor}"
          / "site-packages" / "cmeel.prefix" / "share" / "example-robot-data" / "robots")
PANDA_SRDF = _SHARE / "panda_description" / "srdf" / "panda.srdf"
needs_erd = pytest.mark.skipif(not PANDA_SRDF.exists(),
                               reason="example-robot-data (bench extra) is not installed")
FOLDED = np.array([0.0, 0.0, 0.0, -3.0, 0.0, 0.5, 0.0])  # elbow folded, hand down on link 1


@pytest.fixture(scope="module")
def panda():
    return models.panda(), panda_collision_model()


def _brute_self(robot, model, q, acm):
    """Smallest distance over checked shape pairs with the per-pair kernel, in Python."""
    F = robot.fk_all(q)
    best, pair = np.inf, None
    for s in range(len(model.radius)):
        for t in range(s + 1, len(model.radius)):
            i, j = model.shape_body[s], model.shape_body[t]
            if acm.allowed[i, j]:
                continue
            fs, ft = F[model.shape_frame[s]], F[model.shape_frame[t]]
            d = K.capsule_capsule(fs[:3, :3] @ model.a[s] + fs[:3, 3],
                                  fs[:3, :3] @ model.b[s] + fs[:3, 3], model.radius[s],
                                  ft[:3, :3] @ model.a[t] + ft[:3, 3],
                                  ft[:3, :3] @ model.b[t] + ft[:3, 3], model.radius[t])[0]
            if d < best:
                best, pair = d, (min(i, j), max(i, j))
    return best, pair


def test_self_clearance_matches_pairwise_kernel(panda):
    """The batch kernel equals the minimum of the pairwise kernel, with the same body pair."""
    robot, model = panda
    acm = default_acm(model)
    rng = np.random.default_rng(1)
    Q = rng.uniform(robot.qlim[:, 0], robot.qlim[:, 1], (4, 5, 7))
    c = self_clearance(robot, model, Q, acm)
    assert c.distance.shape == (4, 5) and c.pair.shape == (4, 5, 2)
    for idx in np.ndindex(4, 5):
        d, pair = _brute_self(robot, model, Q[idx], acm)
        assert c.distance[idx] == pytest.approx(d, abs=1e-12)
        assert tuple(c.pair[idx]) == pair


@needs_erd
def test_panda_default_state_is_free(panda):
    """The SRDF's 'default' group state of the Panda is free of self-collision."""
    robot, model = panda
    srdf = read_srdf(PANDA_SRDF)
    state = srdf.group_state("default")
    q = np.array([state[f"panda_joint{i}"] for i in range(1, 8)])
    acm = acm_from_srdf(model, srdf)
    c = self_clearance(robot, model, q, acm)
    assert c.distance > 0.0
    assert not in_collision(robot, model, q, acm)


@needs_erd
def test_panda_folded_reports_pair(panda):
    """The folded Panda (elbow −3 rad) collides, and the hand on link 1 is the reported pair."""
    robot, model = panda
    acm = acm_from_srdf(model, PANDA_SRDF)
    c = self_clearance(robot, model, FOLDED, acm)
    assert c.distance < 0.0
    assert c.names(model) == [("panda_link1", "panda_hand")]
    assert in_collision(robot, model, FOLDED, acm)


def test_sampled_acm_contains_adjacent(panda):
    """Pairs on adjacent frames are allowed in the sampled matrix; far pairs stay checked."""
    robot, model = panda
    acm = sampled_acm(robot, model, samples=300, seed=3)
    f = model.body_frames
    for i in range(len(f)):
        for j in range(len(f)):
            if abs(f[i] - f[j]) <= 1:
                assert acm.allowed[i, j]
    assert not acm.is_allowed("panda_link0", "panda_hand")
    again = sampled_acm(robot, model, samples=300, seed=3)
    assert np.array_equal(acm.allowed, again.allowed)


def test_sampled_acm_finds_always_touching_pair(panda):
    """A pair whose shapes overlap in every configuration is found by sampling."""
    robot, model = panda
    d = model.to_dicts()
    d[0]["capsules"].append({"a": [0, 0, 0.0], "b": [0, 0, 0.5], "radius": 0.1})  # base post
    d[2]["capsules"][0]["radius"] = 0.2  # link2 swollen around joint 2 axis
    m = CollisionModel.from_dicts(d)
    plain = AllowedCollisionMatrix(m.body_names, np.eye(len(m.body_names), dtype=bool))
    acm = sampled_acm(robot, m, plain, samples=200, seed=0)
    assert acm.is_allowed("panda_link0", "panda_link2")


def test_srdf_unknown_link_is_an_error(panda):
    """An SRDF naming a link the model does not have raises, naming the link."""
    _, model = panda
    srdf = ('<robot name="x"><disable_collisions link1="panda_link1" link2="gripper_pad" '
            'reason="Never"/></robot>')
    with pytest.raises(RobotDefinitionError, match="gripper_pad"):
        acm_from_srdf(model, srdf)


def test_negative_radius_is_an_error():
    """A negative radius raises InputError naming the field."""
    with pytest.raises(InputError, match=r"bodies\[0\]\.capsules\[0\]\.radius"):
        CollisionModel.from_dicts([{"name": "a", "frame": 0,
                                    "capsules": [{"a": [0, 0, 0], "b": [1, 0, 0],
                                                  "radius": -0.1}]}])
    with pytest.raises(InputError, match=r"radius\[0\]"):
        CollisionModel(("a",), np.array([0]), np.array([0]), np.zeros((1, 3)),
                       np.zeros((1, 3)), np.array([-1.0]))


def test_dicts_round_trip(panda):
    """from_dicts(to_dicts()) rebuilds the same arrays."""
    _, model = panda
    again = CollisionModel.from_dicts(model.to_dicts())
    for f in ("body_frames", "shape_body", "a", "b", "radius"):
        assert np.array_equal(getattr(model, f), getattr(again, f))
    assert again.body_names == model.body_names


@needs_erd
def test_ur5_model_fits_robot():
    """UR5: a body on every frame; with its SRDF, the upright pose is free, a folded one is not."""
    robot, model = models.ur5(), ur5_collision_model()
    assert sorted(set(model.body_frames.tolist())) == list(range(robot.n + 1))
    acm = acm_from_srdf(model, _SHARE / "ur_description" / "srdf" / "ur5.srdf")
    up = np.array([0.0, -1.57, 1.57, -1.57, -1.57, 0.0])
    assert self_clearance(robot, model, up, acm).distance > 0.0
    folded = np.array([0.0, -1.57, 2.9, 0.0, 0.0, 0.0])  # forearm folded onto the upper arm
    c = self_clearance(robot, model, folded, acm)
    assert c.distance < 0.0
    assert c.names(model) == [("upper_arm_link", "wrist_2_link")]


def test_scene_clearance_table_and_box(panda):
    """Scene clearance equals the per-shape kernels' minimum; a table above the base hits."""
    robot, model = panda
    rng = np.random.default_rng(5)
    Q = rng.uniform(robot.qlim[:, 0], robot.qlim[:, 1], (6, 7))
    box = Box((0.2, 0.4, 0.1), center=[0.5, 0.0, 0.3])
    table = HalfSpace([0, 0, 1], -0.2)
    scene = [box, table, Sphere(0.05, center=[0.3, 0.3, 0.6]),
             Capsule(0.03, a=[0, 0.5, 0], b=[0, 0.5, 1])]
    c = scene_clearance(robot, model, Q, scene)
    for k, q in enumerate(Q):
        F = robot.fk_all(q)
        best = np.inf
        for s in range(len(model.radius)):
            T = F[model.shape_frame[s]]
            a = T[:3, :3] @ model.a[s] + T[:3, 3]
            b = T[:3, :3] @ model.b[s] + T[:3, 3]
            r = model.radius[s]
            best = min(best, K.capsule_box(a, b, r, box.center, box.rotation,
                                           box.half_extents)[0],
                       K.capsule_halfspace(a, b, r, table.normal, table.offset)[0],
                       K.capsule_sphere(a, b, r, scene[2].center, 0.05)[0],
                       K.capsule_capsule(a, b, r, scene[3].a, scene[3].b, 0.03)[0])
        assert c.distance[k] == pytest.approx(best, abs=1e-12)
    high = HalfSpace([0, 0, 1], 0.05)  # a table top cutting the base
    assert in_collision(robot, model, Q, scene=[high], acm=None).all()


def test_scene_z_cylinder_is_planar_distance(panda):
    """An infinite z-cylinder obstacle is measured in the xy plane."""
    robot, model = panda
    q = robot.random_q(3, seed=2)
    post = Cylinder(0.05, math.inf, center=[0.4, -0.2, 0.0])
    c = scene_clearance(robot, model, q, [post])
    for k in range(3):
        F = robot.fk_all(q[k])
        best = np.inf
        for s in range(len(model.radius)):
            T = F[model.shape_frame[s]]
            a = (T[:3, :3] @ model.a[s] + T[:3, 3]) * [1, 1, 0]
            b = (T[:3, :3] @ model.b[s] + T[:3, 3]) * [1, 1, 0]
            best = min(best, K.capsule_sphere(a, b, model.radius[s], np.array([0.4, -0.2, 0.0]),
                                              0.05)[0])
        assert c.distance[k] == pytest.approx(best, abs=1e-12)
        assert c.pair[k, 1] == 0


def test_pairs_follow_the_matrix(panda):
    """Allowing the reported pair removes it: the next query reports another pair or more room."""
    robot, model = panda
    acm = default_acm(model)
    c = self_clearance(robot, model, FOLDED, acm)
    i, j = c.pair
    looser = acm.allow([(model.body_names[i], model.body_names[j])])
    c2 = self_clearance(robot, model, FOLDED, looser)
    assert tuple(c2.pair) != (i, j) and c2.distance >= c.distance
