"""Collision rows from the robot's capsule model and a scene: gradients, distances, safety."""

from __future__ import annotations

import math

import numpy as np
import pytest

import serialkin as sk
from serialkin.collision import scene_clearance, self_clearance
from serialkin.diffik import DiffIK, FrameTask, PositionLimit, PostureTask, VelocityLimit
from serialkin.diffik.model_collision import ModelCollisionAvoidance
from serialkin.diffik.tasks import Workspace
from serialkin.errors import InputError
from serialkin.model.geometry import Box, Capsule, Cylinder, HalfSpace, Sphere


@pytest.fixture(scope="module")
def panda():
    return sk.models.get("panda")


def _scene():
    return [HalfSpace([0, 0, 1], -0.12), Box((0.2, 0.4, 0.1), center=[0.5, 0.0, 0.3]),
            Sphere(0.05, center=[0.3, 0.3, 0.5]),
            Cylinder(0.05, math.inf, center=[0.4, -0.4, 0.0]),
            Capsule(0.03, a=[0.6, -0.2, 0.2], b=[0.6, 0.2, 0.6])]


@pytest.mark.parametrize("seed", [3, 4])
def test_rows_are_minus_the_distance_gradients(panda, seed):
    """Every row (scene and self pairs, separated or overlapping) is −∇d by central differences."""
    con = ModelCollisionAvoidance(_scene(), safety=0.0, influence=10.0)
    q = panda.random_q(seed=seed)
    ws = Workspace(panda)
    ws.update(q)
    G, h = con.rows(ws, q)
    who = con._state(panda)[-1]
    D = con.distances(panda, q)
    assert G.shape[0] > 50
    fd = np.empty((D.shape[0], panda.n))  # every distance's central difference, per joint
    for j in range(panda.n):
        e = np.zeros(panda.n)
        e[j] = 1e-6
        fd[:, j] = (con.distances(panda, q + e) - con.distances(panda, q - e)) / 2e-6
    for r in range(G.shape[0]):
        i = who[r]
        if i < 0:  # an end sphere's row: checked through the closest-pair rows' code path
            continue
        np.testing.assert_allclose(-G[r], fd[i], atol=1e-6)
        assert h[r] == pytest.approx(0.5 * D[i])


def test_distances_agree_with_the_collision_queries(panda):
    """The smallest scene and self distances equal scene_clearance and self_clearance."""
    scene = _scene()
    con = ModelCollisionAvoidance(scene, influence=10.0)
    for seed in range(5):
        q = panda.random_q(seed=seed)
        D = con.distances(panda, q)
        k = panda.collision.a.shape[0] * len(scene)
        assert D[:k].min() == pytest.approx(
            float(scene_clearance(panda, panda.collision, q, scene).distance), abs=1e-12)
        assert D[k:].min() == pytest.approx(
            float(self_clearance(panda, panda.collision, q).distance), abs=1e-12)


def test_pulled_into_a_box_the_arm_stops_at_the_safety_distance(panda):
    """A target inside a box: small steps never bring any capsule into the box or the table."""
    box = Box((0.16, 0.16, 0.16), center=[0.55, 0.0, 0.25])
    scene = [box, HalfSpace([0, 0, 1], -0.12)]
    q = np.array([0.0, -0.3, 0.0, -2.2, 0.0, 2.0, 0.8])
    target = panda.fk(q)
    target[:3, 3] = box.center
    ik = DiffIK(panda, [FrameTask(target, task="position"), PostureTask(q, weight=1e-3)],
                [PositionLimit(), VelocityLimit(0.01),
                 ModelCollisionAvoidance(scene, safety=0.005, influence=0.05)])
    for _ in range(250):
        res = ik.step(q)
        assert res.success, res.reason
        q = q + res.dq
        assert float(scene_clearance(panda, panda.collision, q, scene).distance) > 0.0
        assert float(self_clearance(panda, panda.collision, q).distance) > 0.0
    gap = float(scene_clearance(panda, panda.collision, q, [box]).distance)
    assert gap == pytest.approx(0.005, abs=3e-3)  # parked at d_s


def test_scene_overlapping_the_fixed_base_is_an_input_error(panda):
    """A table through the base (e.g. a scene in the wrong frame) is refused, naming the body."""
    con = ModelCollisionAvoidance([HalfSpace([0, 0, 1], 0.0)])
    ws = Workspace(panda)
    q = np.zeros(panda.n)
    ws.update(q)
    with pytest.raises(InputError, match="fixed to the base"):
        con.rows(ws, q)
    with pytest.raises(InputError, match="influence"):
        ModelCollisionAvoidance([], safety=0.05, influence=0.01)
