"""The 20-link example exercises all three secondary tasks of eq 48: switching any off fails.

The shipped scenario ``twenty_link_obstacles`` is run with all tasks and with the obstacle,
the joint-limit and the singularity task switched off in turn (weight 0); every outcome is
recomputed here from the joint trajectories (clearances, limits, forward kinematics), not
read from the report's text.
"""

from __future__ import annotations

import numpy as np
import pytest

from serialkin.chapter.report import ReportContext
from serialkin.chapter.sections.redundancy import eq48_by_hand, timed_run
from serialkin.redundancy import clearances
from serialkin.tracking import load_scenario
from serialkin.tracking.analysis import ABLATION, ablation, compare_row, task_activity

DEG = np.pi / 180.0


@pytest.fixture(scope="module")
def runs():
    sc = load_scenario("twenty_link_obstacles")
    return sc, {r.label: r for r in ablation(sc)}


def _errors(sc, q):
    """Tracking error of every path point, recomputed with forward kinematics [m]."""
    return np.array([np.linalg.norm(sc.robot.fk(qk)[:2, 3] - p)
                     for qk, p in zip(q, sc.path.points)])


def _worst_clearance(sc, q):
    return min(clearances(sc.robot, qk, sc.obstacles).min() for qk in q)


def _violation(sc, q):
    lim = np.asarray(sc.robot.qlim)
    return float(np.max(np.maximum(q - lim[:, 1], lim[:, 0] - q)))


def test_ablation_runs_every_switch(runs):
    """One run per row of ABLATION, each with exactly its task's weight set to zero."""
    sc, by = runs
    assert list(by) == [label for label, _ in ABLATION]
    res = sc.solver
    assert by["all tasks"].scenario.solver == res
    for label, change in ABLATION[1:]:
        solver = by[label].scenario.solver
        assert solver == res.with_options(**change)
        assert all(getattr(solver, k) == 0.0 for k in change)


def test_all_tasks_track_safely(runs):
    """All tasks on: every point within ±5 mm, no collision, every joint within ±100°."""
    sc, by = runs
    full = by["all tasks"]
    q = full.trajectory.q
    assert len(q) == len(sc.path)
    assert _errors(sc, q).max() <= sc.tolerance
    assert _worst_clearance(sc, q) > 0.0
    assert _violation(sc, q) <= 0.0
    assert full.unreached == 0 and full.limit_violation == 0.0
    assert full.max_joint_difference == 0.0


def test_without_obstacle_task_the_arm_collides(runs):
    """Obstacle task off: some link passes through an obstacle (clearance < 0)."""
    sc, by = runs
    r = by["without the obstacle task"]
    worst = _worst_clearance(sc, r.trajectory.q)
    assert worst < -0.005
    assert r.min_clearance == pytest.approx(worst, abs=1e-9)


def test_without_joint_limit_task_a_joint_leaves_its_range(runs):
    """Joint-limit task off: joint 1 passes its +100° limit by several degrees."""
    sc, by = runs
    r = by["without the joint-limit task"]
    over = _violation(sc, r.trajectory.q)
    assert over > 5.0 * DEG
    assert r.trajectory.q[:, 0].max() > 100.0 * DEG + 5.0 * DEG
    assert r.limit_violation == pytest.approx(over)


def test_without_singularity_task_points_are_lost_near_the_singularity(runs):
    """Singularity task off: points near the stretched (singular) arm miss the ±5 mm band."""
    sc, by = runs
    r = by["without the singularity task"]
    err = _errors(sc, r.trajectory.q)
    lost = np.flatnonzero(err > sc.tolerance)
    assert lost.size >= 2 and r.unreached == lost.size
    # they lie where the arm is nearly stretched: the singularity task acts there
    reach = 20 * 0.01675
    radius = np.linalg.norm(sc.path.points[lost], axis=1)
    assert np.all(radius > 0.99 * reach)
    act = task_activity(sc, by["all tasks"].trajectory)
    assert np.all(act["singularity"][lost] > 0.0)


def test_each_task_is_active_somewhere(runs):
    """Each secondary task has a non-zero weight at some path point of the full run."""
    sc, by = runs
    act = task_activity(sc, by["all tasks"].trajectory)
    for key in ("obstacle", "limit", "singularity"):
        assert (act[key] > 0).sum() >= 5, key
    # joint 1 is the joint that enters its limit buffer in phase 2
    assert 1 in set(act["limit_joint"].tolist())


def test_eq48_by_hand_matches_the_library(runs):
    """Eq 48 assembled from eqs 49-50, 55 and W_s with numpy equals the compiled resolver."""
    sc, by = runs
    tr = by["all tasks"].trajectory
    rng = np.random.default_rng(3)
    for k in (5, 60, 75, len(tr) - 1):
        xdot = rng.normal(scale=0.005, size=2)
        hand = eq48_by_hand(sc, tr.q[k], xdot)["qdot"]
        lib = sc.solver.velocity(sc.robot, tr.q[k], xdot)
        np.testing.assert_allclose(hand, lib, rtol=1e-8, atol=1e-12)


class _SlowFirst:
    """A stand-in scenario whose first run is slow (as a first, compiling call would be).

    It advances a fake clock (``ReportContext.clock``) instead of sleeping: 20 s for the
    first run, 10 ms for every later one.
    """

    def __init__(self) -> None:
        self.calls = 0
        self.now = 0.0

    def clock(self) -> float:
        return self.now

    def run(self):
        self.calls += 1
        self.now += 20.0 if self.calls == 1 else 0.010
        return self.calls


def test_timed_run_reports_warm_runs_only():
    """timed_run: one untimed warm-up call, then `repeat` timed calls; the cold call is out."""
    fake = _SlowFirst()
    ctx = ReportContext(outdir=".", quiet=True, clock=fake.clock)
    result, timing = timed_run(ctx, fake, repeat=4)
    assert fake.calls == 5 and result == 1
    assert timing.warm and timing.n == 4
    # the 20 s first call is not among the timed ones: every timed run took 10 ms
    assert [timing.low, timing.median, timing.high] == pytest.approx([0.010] * 3)
    assert ctx.timings[-1] is timing


def test_twenty_link_timing_is_of_the_warm_kind():
    """The section's timing of the constrained run: warm, and the trajectory is the real one."""
    sc = load_scenario("twenty_link_obstacles")
    ctx = ReportContext(outdir=".", quiet=True)
    tr, timing = timed_run(ctx, sc, repeat=2)
    assert timing.warm and timing.n == 2 and timing.low <= timing.median <= timing.high
    again = sc.run()  # the function the report times, run twice more: the same result
    np.testing.assert_array_equal(tr.q, again.q)


def test_compare_row_summarises_a_trajectory(runs):
    """The library's resolver summary (tracking.analysis.compare_row) reads the trajectory."""
    _, by = runs
    tr = by["all tasks"].trajectory
    row = compare_row("eq 48", tr)
    assert row.seconds is None and row.per_point is None
    assert row.max_error == pytest.approx(tr.max_error)
    assert row.unreached == int((~tr.reached).sum()) == 0
    assert row.min_clearance == pytest.approx(tr.min_clearance)
    assert row.worst_margin == pytest.approx(tr.min_limit_margin) and row.worst_margin > 0
    timed = compare_row("eq 48", tr, seconds=2.0)
    assert timed.per_point == pytest.approx(2.0 / len(tr))
