"""The chapter's simulations reproduced: 6-link circle (Figs 8-9), 20-link arm (Figs 11-12)."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from serialkin.redundancy import clearances
from serialkin.tracking import load_scenario


@pytest.fixture(scope="module")
def six():
    s = load_scenario("six_link_circle")
    return s, s.run()


@pytest.fixture(scope="module")
def free():
    s = load_scenario("twenty_link_free")
    return s, s.run()


@pytest.fixture(scope="module")
def constrained():
    s = load_scenario("twenty_link_obstacles")
    return s, s.run()


def test_six_link_scenario_is_the_chapter_example(six):
    """Shipped (a): L = 0.1 m, circle (−2.5L, 0) radius L, φ = 0..2π step 0.2, q0 = 0."""
    s, _ = six
    assert s.robot.n == 6
    np.testing.assert_allclose([d.a for d in s.robot.dh], 0.1)
    phi = np.arange(32) * 0.2
    np.testing.assert_allclose(s.path.parameter, phi)
    np.testing.assert_allclose(s.path.points[:, 0], -0.25 + 0.1 * np.cos(phi))
    np.testing.assert_allclose(s.path.points[:, 1], 0.1 * np.sin(phi))
    assert np.all(s.q0 == 0.0)
    assert s.solver == "dls" and s.tolerance == 0.005


def test_six_link_every_point_within_5mm(six):
    """(a): every path point is reached within ±5 mm; the largest error is far below it."""
    s, tr = six
    assert len(tr) == 32 and tr.complete
    errs = np.linalg.norm(tr.positions[:, :2] - s.path.points, axis=1)
    print(f"six-link circle: largest tracking error {errs.max() * 1e3:.3g} mm")
    assert errs.max() <= 0.005
    assert errs.max() < 1e-5
    np.testing.assert_allclose(errs, tr.errors, atol=1e-12)


def test_free_twenty_link_tracks_path(free):
    """(b): the free 20-link arm follows the path within the tolerance, no limits used."""
    s, tr = free
    assert s.robot.n == 20 and not s.obstacles
    assert np.all(np.isinf(s.robot.qlim))
    assert tr.complete and tr.max_error <= s.tolerance


def test_constrained_twenty_link_avoids_obstacles_and_limits(constrained):
    """(c): path within tolerance, positive clearance of every link at every step, |q| ≤ 100°."""
    s, tr = constrained
    assert len(s.obstacles) == 4
    assert tr.complete and tr.max_error <= s.tolerance
    np.testing.assert_allclose(s.robot.qlim, np.radians([[-100, 100]] * 20))
    assert np.all(np.abs(tr.q) <= np.radians(100.0))
    assert tr.min_limit_margin > 0
    for q in tr.q:  # recompute: every link segment against every obstacle
        assert clearances(s.robot, q, s.obstacles).min() > 0
    # independent check: dense points along the arm stay outside every circle
    for q in tr.q[::5]:
        F = s.robot.fk_all(q)[:, :2, 3]
        t = np.linspace(0, 1, 50)[:, None, None]
        pts = (F[:-1] + t * (F[1:] - F[:-1])).reshape(-1, 2)
        for o in s.obstacles:
            assert np.min(np.linalg.norm(pts - o.center[:2], axis=1)) > o.radius


def test_self_motion_differs_while_task_path_agrees(free, constrained):
    """(b) vs (c): the same end-effector path, different joint trajectories (self-motion)."""
    sb, tb = free
    sc, tc = constrained
    np.testing.assert_allclose(sb.path.points, sc.path.points)
    np.testing.assert_allclose(sb.q0, sc.q0)
    assert np.max(np.linalg.norm(tb.positions - tc.positions, axis=1)) <= 2 * sc.tolerance
    assert np.degrees(np.max(np.abs(tb.q - tc.q))) > 20.0


def test_obstacles_are_tight_without_the_obstacle_task(constrained):
    """The designed obstacles matter: without the obstacle task the arm passes through some."""
    sc, _ = constrained
    bare = dataclasses.replace(sc, solver=sc.solver.with_options(obstacle_weight=0.0))
    tr = bare.run()
    worst = np.array([clearances(sc.robot, q, sc.obstacles).min(axis=0) for q in tr.q]).min(axis=0)
    assert np.sum(worst < 0) >= 2
