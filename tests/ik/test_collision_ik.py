"""Collision-aware IK (issue 13 item 1) and solutions nearest the seed (issue 13 item 4)."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from serialkin import models
from serialkin.collision import default_acm, scene_clearance, self_clearance
from serialkin.collision.queries import checked_shape_pairs
from serialkin.errors import InputError, InputTypeError
from serialkin.ik import _kernels as K
from serialkin.ik import solver
from serialkin.model.geometry import Box, HalfSpace, Sphere

from .conftest import ACCURACY

#: Table top 10 cm below the Panda's base frame: the fitted base capsule reaches 8 cm down.
TABLE = HalfSpace([0.0, 0.0, 1.0], -0.10, name="table")
BALL = Sphere(0.10, center=[0.45, 0.25, 0.45], name="ball")
CRATE = Box((0.12, 0.12, 0.12), center=[0.40, -0.35, 0.25], name="crate")
SCENE = [TABLE, BALL, CRATE]


@pytest.fixture(scope="module")
def panda():
    """The zoo Panda with its fitted capsules."""
    return models.panda()


def free_configurations(robot, count, seed, margin=0.0):
    """``count`` seeded configurations inside the limits, collision-free with ``margin``."""
    rng = np.random.default_rng(seed)
    lim = robot.sampling_limits()
    out = []
    while sum(len(x) for x in out) < count:
        Q = rng.uniform(lim[:, 0], lim[:, 1], (4 * count, robot.n))
        ok = self_clearance(robot, robot.collision, Q).distance >= margin
        ok &= scene_clearance(robot, robot.collision, Q, SCENE).distance >= margin
        out.append(Q[ok])
    return np.concatenate(out)[:count]


def coal_clearance(robot, Q, scene):
    """Smallest distance over the checked pairs, recomputed with coal (independent peer)."""
    coal = pytest.importorskip("coal")
    model = robot.collision
    pa, pb = checked_shape_pairs(model, default_acm(model))
    geoms = []
    for a, b, r in zip(model.a, model.b, model.radius, strict=True):
        length = float(np.linalg.norm(b - a))
        geoms.append(coal.Capsule(float(r), length) if length > 0 else coal.Sphere(float(r)))
    obstacles = []
    for s in scene:
        if isinstance(s, HalfSpace):
            obstacles.append((coal.Halfspace(s.normal, s.offset), coal.Transform3s()))
        elif isinstance(s, Sphere):
            obstacles.append((coal.Sphere(float(s.radius)),
                              coal.Transform3s(np.eye(3), np.asarray(s.center, float))))
        else:
            obstacles.append((coal.Box(*(2.0 * s.half_extents)),
                              coal.Transform3s(s.rotation, s.center)))
    req = coal.DistanceRequest()
    res = coal.DistanceResult()
    out = np.empty(len(Q))
    for k, q in enumerate(Q):
        frames = robot.fk_all(q)
        poses = []
        for s in range(len(model.radius)):
            Fm = frames[model.shape_frame[s]]
            a = Fm[:3, :3] @ model.a[s] + Fm[:3, 3]
            b = Fm[:3, :3] @ model.b[s] + Fm[:3, 3]
            u = b - a
            n = np.linalg.norm(u)
            R = np.eye(3)
            if n > 0:
                z = u / n
                x = np.cross(z, [1.0, 0.0, 0.0] if abs(z[0]) < 0.9 else [0.0, 1.0, 0.0])
                x /= np.linalg.norm(x)
                R = np.column_stack([x, np.cross(z, x), z])
            poses.append(coal.Transform3s(R, 0.5 * (a + b)))
        best = np.inf
        for i, j in zip(pa, pb, strict=True):
            res.clear()
            best = min(best, coal.distance(geoms[i], poses[i], geoms[j], poses[j], req, res))
        for s in range(len(geoms)):
            for geom, pose in obstacles:
                res.clear()
                best = min(best, coal.distance(geoms[s], poses[s], geom, pose, req, res))
        out[k] = best
    return out


def test_panda_scene_acceptance(panda):
    """10,000 targets from collision-free configurations: ≥ 95 % solved, no success collides.

    Every success is inside the limits, reaches its target to 1e-6, and is collision-free
    by the solver's clearance and by coal's distances on the same capsules.
    """
    Q = free_configurations(panda, 10_000, seed=2024)
    targets = panda.fk(Q)
    res = panda.ik(targets, scene=SCENE, self_collision=True, seed=7)
    ok = res.success
    assert ok.mean() >= 0.95
    assert panda.within_limits(res.q[ok], 1e-12).all()
    T = panda.fk(res.q[ok])
    assert np.abs(T[:, :3, 3] - targets[ok][:, :3, 3]).max() <= ACCURACY
    assert (res.clearance[ok] >= 0.0).all()
    ours = np.minimum(self_clearance(panda, panda.collision, res.q[ok]).distance,
                      scene_clearance(panda, panda.collision, res.q[ok], SCENE).distance)
    np.testing.assert_allclose(res.clearance[ok], ours, atol=1e-12)
    sample = np.flatnonzero(ok)[:1500]
    peer = coal_clearance(panda, res.q[sample], SCENE)
    assert (peer >= -1e-9).all()
    np.testing.assert_allclose(peer, res.clearance[sample], atol=1e-6)


def test_batch_equals_single(panda):
    """Each batch entry equals the single collision-aware solve with the same seed."""
    Q = free_configurations(panda, 6, seed=5)
    targets = panda.fk(Q)
    batch = panda.ik(targets, scene=SCENE, self_collision=True, margin=0.01, seed=3)
    for k in range(6):
        one = panda.ik(targets[k], scene=SCENE, self_collision=True, margin=0.01, seed=3)
        assert np.array_equal(one.q, batch.q[k])
        assert one.success == batch.success[k]
        assert one.clearance == batch.clearance[k]
        assert one.closest_pair == tuple(batch.closest_pair[k])
        assert batch[k].closest_pair == one.closest_pair


def test_margin_is_kept(panda):
    """With a margin, every success keeps at least that clearance (scene only)."""
    Q = free_configurations(panda, 40, seed=11, margin=0.0)
    res = panda.ik(panda.fk(Q), scene=SCENE, margin=0.015, seed=1)
    assert res.success.mean() >= 0.8
    d = scene_clearance(panda, panda.collision, res.q[res.success], SCENE).distance
    assert (d >= 0.015 - 1e-12).all()
    assert set(res.closest_pair[res.success][:, 1]) <= {"table", "ball", "crate"}


def test_clearance_reports_closest_pair(panda):
    """Clearance and closest_pair are the minimum over self and scene pairs at q."""
    q = free_configurations(panda, 1, seed=3)[0]
    res = panda.ik(panda.fk(q), q0=q, scene=SCENE, self_collision=True, seed=0)
    assert res.success
    s = self_clearance(panda, panda.collision, res.q)
    c = scene_clearance(panda, panda.collision, res.q, SCENE)
    names = panda.collision.body_names
    if s.distance <= c.distance:
        assert res.closest_pair == (names[s.pair[0]], names[s.pair[1]])
    else:
        assert res.closest_pair == (names[c.pair[0]], SCENE[c.pair[1]].name)
    assert res.clearance == pytest.approx(min(float(s.distance), float(c.distance)), abs=1e-12)


def test_nothing_checked_gives_inf(panda):
    """Without scene or self_collision: clearance +inf and an empty closest pair."""
    q = free_configurations(panda, 1, seed=4)[0]
    res = panda.ik(panda.fk(q), seed=0)
    assert res.clearance == np.inf
    assert res.closest_pair == ("", "")
    batch = panda.ik(panda.fk(q[None]), seed=0)
    assert np.isinf(batch.clearance).all()


def test_target_inside_obstacle_fails_with_reason(panda):
    """A target inside an obstacle: failure, naming the obstacle, with a finite best attempt."""
    q = free_configurations(panda, 1, seed=8)[0]
    T = panda.fk(q)
    ball = Sphere(0.05, center=T[:3, 3], name="blob")
    res = panda.ik(T, scene=[ball], restarts=3, seed=0)
    assert not res.success
    assert "inside obstacle 'blob'" in res.reason
    assert np.isfinite(res.q).all()
    assert res.clearance < 0
    assert res.closest_pair[1] == "blob"


def test_margin_larger_than_free_space_fails(panda):
    """A margin no configuration can keep: failure with a reason, within the budget."""
    q = free_configurations(panda, 1, seed=9)[0]
    res = panda.ik(panda.fk(q), scene=SCENE, margin=2.0, restarts=3, seed=0)
    assert not res.success
    assert "collided" in res.reason and "margin" in res.reason
    assert res.iterations <= 4 * 100 * (solver.PUSHES + 1) + 100


def test_another_jacobian_method(panda):
    """Another Jacobian-family method (dls, single calls) also returns free solutions only.

    Every compiled method runs the same collision-aware loop around its step kernel; one
    more besides lm is compiled here (compilation takes seconds per method).
    """
    Q = free_configurations(panda, 8, seed=13)
    results = [panda.ik(T, method="dls", scene=SCENE, self_collision=True, seed=2)
               for T in panda.fk(Q)]
    assert np.mean([r.success for r in results]) >= 0.75
    assert all(r.clearance >= 0 for r in results if r.success)


def test_bad_collision_input(panda):
    """Negative margin, wrong types, no collision model, non-Jacobian method: clear errors."""
    T = panda.fk(free_configurations(panda, 1, seed=1)[0])
    with pytest.raises(InputError, match="margin must be >= 0"):
        panda.ik(T, scene=SCENE, margin=-0.01)
    with pytest.raises(InputError, match="margin"):
        panda.ik(T, scene=SCENE, margin=float("nan"))
    with pytest.raises(InputTypeError, match="scene"):
        panda.ik(T, scene=["table"])
    with pytest.raises(InputTypeError, match="self_collision"):
        panda.ik(T, self_collision="yes")
    with pytest.raises(InputTypeError, match="acm"):
        panda.ik(T, self_collision=True, acm="none")
    with pytest.raises(InputError, match="self_collision=True"):
        panda.ik(T, scene=SCENE, acm=default_acm(panda.collision))
    with pytest.raises(InputTypeError, match="margin"):
        panda.ik(T, scene=SCENE, margin=np.array([0.1, 0.2]))
    bare = panda.with_collision(None)
    with pytest.raises(InputError, match="with_collision"):
        bare.ik(T, scene=SCENE)
    with pytest.raises(InputError, match="Jacobian-family"):
        panda.ik(T, method="ccd", scene=SCENE)


def test_nearest_representative_single_and_batch():
    """UR5 (±2π ranges): revolute angles come back in the 2π-shift nearest q0, in range."""
    ur5 = models.ur5()
    rng = np.random.default_rng(21)
    qs = rng.uniform(-np.pi, np.pi, (8, 6))
    shift = rng.choice([-1.0, 1.0], size=(8, 6)) * 2 * np.pi
    q0 = np.clip(qs + shift + rng.normal(0, 0.05, (8, 6)), -2 * np.pi, 2 * np.pi)
    targets = ur5.fk(qs)
    for method in ("lm", "dls"):
        batch = ur5.ik(targets, q0=q0, method=method, seed=0)
        assert batch.success.mean() >= 0.75
        for k in range(8):
            one = ur5.ik(targets[k], q0=q0[k], method=method, seed=0)
            for q in (one.q, batch.q[k]):
                assert ur5.within_limits(q, 1e-12)
                # no other 2π-representative inside the limits is nearer to q0
                for sgn in (-1.0, 1.0):
                    other = q + sgn * 2 * np.pi
                    inside = (other >= -2 * np.pi) & (other <= 2 * np.pi)
                    assert not np.any(inside & (np.abs(other - q0[k]) < np.abs(q - q0[k])))


@settings(max_examples=200, deadline=None)
@given(q=st.floats(-2 * np.pi, 2 * np.pi), ref=st.floats(-20.0, 20.0),
       lo=st.floats(-9.0, 0.0), width=st.floats(0.0, 18.0))
def test_nearest_into_property(q, ref, lo, width):
    """nearest_into keeps the angle mod 2π and inside [lo, hi], and no in-range shift is nearer."""
    hi = lo + width
    q = min(max(q, lo), hi)
    out = np.array([q])
    box = np.array([[lo], [hi], [1.0]])  # read-only rows, as the solver's limit box
    box.setflags(write=False)
    K.nearest_into(out, np.array([ref]), box[0], box[1], box[2], True)
    x = out[0]
    assert lo <= x <= hi
    k = (x - q) / (2 * np.pi)
    assert abs(k - round(k)) < 1e-9
    for j in range(-4, 5):
        other = q + 2 * np.pi * j
        if lo <= other <= hi:
            assert abs(x - ref) <= abs(other - ref) + 1e-9


def test_batch_failure_reason_names_bodies_as_plain_text():
    """A failed collision-aware batch solve names its closest pair as plain names (no np.str_)."""
    from serialkin.model.geometry import Sphere

    robot = models.get("panda")
    T = robot.fk(np.array([0.0, 0.3, 0.0, -2.0, 0.0, 2.0, 0.8]))
    # a ball around the target point: the flange cannot reach it without touching the ball
    scene = [Sphere(0.12, center=T[:3, 3])]
    res = robot.ik(np.stack([T, T]), scene=scene, seed=0, restarts=1)
    assert not res.success.any()
    assert "np.str_" not in res[0].reason and "panda_" in res[0].reason
