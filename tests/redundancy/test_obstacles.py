"""Obstacles, closest points and obstacle Jacobians (eqs 51-56, corrected)."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from serialkin.errors import InputError, InputTypeError
from serialkin.model.geometry import Capsule, Cylinder, Sphere
from serialkin.redundancy import (
    check_obstacles,
    clearances,
    closest_pairs,
    obstacle_jacobian,
)
from serialkin.redundancy.obstacles import obstacle_from_dict, obstacle_to_dict, robot_segments

from ._robots import six_link, spatial_rp

SEEDS = st.integers(0, 2**31 - 1)


def _brute_clearance(P0, P1, obstacle, samples=4001):
    """Clearance by dense sampling of the segment (independent reference).

    For circles and spheres the distance along the segment is convex in its parameter,
    so the best sample is refined by ternary search between its neighbours (sampling
    alone misses a minimum between samples by up to h²/(8d), above 1e-6 near contact).
    """
    t = np.linspace(0, 1, samples)[:, None]
    pts = P0 + t * (P1 - P0)
    if isinstance(obstacle, (Cylinder, Sphere)):
        k = 2 if isinstance(obstacle, Cylinder) else 3

        def dist(x: float) -> float:
            return float(np.linalg.norm((P0 + x * (P1 - P0))[:k] - obstacle.center[:k]))

        d = np.linalg.norm(pts[:, :k] - obstacle.center[:k], axis=1)
        i = int(np.argmin(d))
        lo, hi = t[max(i - 1, 0), 0], t[min(i + 1, samples - 1), 0]
        for _ in range(100):
            a, b = lo + (hi - lo) / 3, hi - (hi - lo) / 3
            lo, hi = (lo, b) if dist(a) <= dist(b) else (a, hi)
        return min(d.min(), dist(0.5 * (lo + hi))) - obstacle.radius
    else:
        s = np.linspace(0, 1, samples)[:, None]
        core = obstacle.a + s * (obstacle.b - obstacle.a)
        d = np.min(np.linalg.norm(pts[::8, None, :] - core[None, ::8, :], axis=2), axis=1)
    return d.min() - obstacle.radius


def _random_scene(seed):
    """The spatial RP arm at a random q with a random circle, sphere and capsule."""
    rng = np.random.default_rng(seed)
    robot = spatial_rp()
    q = robot.random_q(seed=rng)
    obs = [Cylinder(0.03, math.inf, center=[*rng.uniform(-0.4, 0.4, 2), 0.0]),
           Sphere(0.04, center=rng.uniform(-0.4, 0.4, 3)),
           Capsule(0.02, a=rng.uniform(-0.4, 0.4, 3), b=rng.uniform(-0.4, 0.4, 3))]
    return robot, q, obs


def test_closest_point_is_clamped_to_the_segment():
    """ERRATA (51)-(52): an obstacle beyond a link's end is closest to the end, not the line."""
    robot = six_link()
    q = np.zeros(6)  # links along +x: link 1 from (0,0) to (0.1,0)
    obs = [Cylinder(0.02, math.inf, center=[-0.3, 0.05, 0.0])]  # behind the base, off the line
    pairs = closest_pairs(robot, q, obs)
    p = pairs[0]
    assert p.t == 0.0
    np.testing.assert_allclose(p.point[:2], [0.0, 0.0], atol=1e-15)
    assert p.clearance == pytest.approx(np.hypot(0.3, 0.05) - 0.02)
    # the unclamped projection would give a point at x = -0.3, distance 0.05
    np.testing.assert_allclose(p.u[:2], np.array([0.3, -0.05]) / np.hypot(0.3, 0.05))


@settings(max_examples=25, deadline=None)
@given(seed=SEEDS)
def test_clearances_match_dense_sampling(seed):
    """Clearances of circles, spheres and capsules equal a brute-force sampled minimum."""
    robot, q, obs = _random_scene(seed)
    C = clearances(robot, q, obs)
    P0, P1, _, _ = robot_segments(robot, q)
    assert C.shape == (P0.shape[0], 3)
    for i in range(P0.shape[0]):
        for j, o in enumerate(obs):
            ref = _brute_clearance(P0[i], P1[i], o)
            tol = 2e-3 if isinstance(o, Capsule) else 1e-6
            assert C[i, j] <= ref + 1e-9
            assert C[i, j] == pytest.approx(ref, abs=tol)


@settings(max_examples=25, deadline=None)
@given(seed=SEEDS)
def test_obstacle_jacobian_rows_match_finite_differences(seed):
    """Eq 55: J_ci q̇ is the approach rate, i.e. J_ci = −∂c_i/∂q (finite differences)."""
    robot, q, obs = _random_scene(seed)
    pairs = closest_pairs(robot, q, obs, with_jacobian=True)
    h = 1e-7
    for p in pairs:
        if p.distance < 1e-6:
            continue
        fd = np.empty(robot.n)
        for k in range(robot.n):
            d = np.zeros(robot.n)
            d[k] = h
            cp = clearances(robot, q + d, obs)[p.segment, p.obstacle]
            cm = clearances(robot, q - d, obs)[p.segment, p.obstacle]
            fd[k] = (cp - cm) / (2 * h)
        np.testing.assert_allclose(p.jacobian_row, -fd, atol=1e-5)


def test_obstacle_jacobian_keeps_only_pairs_within_influence():
    """Only link/obstacle pairs closer than the influence distance give rows."""
    robot = six_link()
    q = np.zeros(6)
    # 20 mm from links 1-2
    near = Cylinder(0.03, math.inf, center=[0.15, 0.05, 0.0], influence=0.05)
    far = Cylinder(0.03, math.inf, center=[0.15, 0.5, 0.0], influence=0.05)
    Jc, c, pairs = obstacle_jacobian(robot, q, [near, far])
    assert Jc.shape[1] == 6 and Jc.shape[0] == len(pairs) == len(c) > 0
    assert all(j == 0 for _, j in pairs)
    assert np.all(c < 0.05)
    Jc2, _, _ = obstacle_jacobian(robot, q, [far])
    assert Jc2.shape == (0, 6)


def test_obstacle_overlapping_base_is_rejected():
    """An obstacle that covers the robot's base raises InputError naming it."""
    robot = six_link()
    with pytest.raises(InputError, match="overlaps the robot base"):
        check_obstacles(robot, [Cylinder(0.05, math.inf, center=[0.01, 0.0, 0.0], name="pillar")])
    check_obstacles(robot, [Cylinder(0.05, math.inf, center=[0.2, 0.0, 0.0])])


def test_obstacle_construction_errors():
    """Bad radii, centres and dictionaries raise clear errors."""
    with pytest.raises(InputError, match="radius"):
        Cylinder(-1.0, math.inf, center=[0, 0, 0])
    with pytest.raises(InputError, match="center"):
        Sphere(1.0, center=[0, 0])
    with pytest.raises(InputError, match="finite"):
        Cylinder(1.0, math.inf, center=[np.nan, 0, 0])
    with pytest.raises(InputError, match="influence"):
        Cylinder(1.0, math.inf, center=[0, 0, 0], influence=-0.1)
    with pytest.raises(InputError, match="obstacle.type"):
        obstacle_from_dict({"type": "cube"})
    with pytest.raises(InputError, match="'obstacle.radius' is missing"):
        obstacle_from_dict({"type": "circle", "center": [0, 0]})
    with pytest.raises(InputError, match="unknown field"):
        obstacle_from_dict({"type": "circle", "center": [0, 0], "radius": 1, "colour": "r"})
    with pytest.raises(InputTypeError):
        clearances(six_link(), np.zeros(6), ["not an obstacle"])
    o = obstacle_from_dict({"type": "capsule", "a": [0, 0, 0], "b": [1, 0, 0], "radius": 0.1})
    back = obstacle_from_dict(obstacle_to_dict(o))
    assert isinstance(back, Capsule) and np.allclose(back.b, o.b) and back.radius == o.radius
