"""Path tracking through the differential-IK QP: hard limits and clearance (20-link scenario)."""

from __future__ import annotations

import copy
import math

import numpy as np
import pytest

from serialkin.diffik.resolver import QPResolver
from serialkin.errors import InputError
from serialkin.model.geometry import Cylinder
from serialkin.tracking import Path, load_scenario, planar_arm, scenario_from_dict, track


def _circle_clearance(robot, Q, obstacles):
    """Independent clearance: segment-to-centre distances in numpy, minus the radius (p, k)."""
    out = np.empty((len(Q), len(obstacles)))
    for k, q in enumerate(Q):
        P = robot.fk_all(q)[:, :2, 3]
        a, b = P[:-1], P[1:]
        for j, o in enumerate(obstacles):
            d = b - a
            c = o.center[:2]  # a vertical cylinder: its circle in the plane
            t = np.clip(np.einsum("ij,ij->i", c - a, d) / np.einsum("ij,ij->i", d, d),
                        0.0, 1.0)
            closest = a + t[:, None] * d
            out[k, j] = np.linalg.norm(closest - c, axis=1).min() - o.radius
    return out


@pytest.fixture(scope="module")
def scenario():
    return load_scenario("twenty_link_obstacles")


@pytest.fixture(scope="module")
def qp_run(scenario):
    res = QPResolver(task=scenario.path.task, obstacles=scenario.obstacles)
    return track(scenario.robot, scenario.path, res, q0=scenario.q0,
                 tolerance=scenario.tolerance, max_joint_step=0.2)


def test_qp_tracking_never_leaves_a_limit_or_enters_an_obstacle(scenario, qp_run):
    """20-link scenario by QP: every point within the joint limits and outside every obstacle."""
    tr = qp_run
    lim = scenario.robot.qlim
    assert len(tr) == len(scenario.path)
    assert np.all(tr.q >= lim[:, 0]) and np.all(tr.q <= lim[:, 1])
    clear = _circle_clearance(scenario.robot, tr.q, scenario.obstacles)
    assert clear.min() > 0.0
    np.testing.assert_allclose(clear, tr.clearance, atol=1e-9)


def test_compiled_loop_and_daqp_loop_give_the_same_trajectory(scenario, qp_run):
    """The compiled per-target loop (default) and the Python loop around DAQP agree."""
    res = QPResolver(task=scenario.path.task, obstacles=scenario.obstacles, solver="daqp")
    tr = track(scenario.robot, scenario.path, res, q0=scenario.q0,
               tolerance=scenario.tolerance, max_joint_step=0.2)
    assert tr.iterations.tolist() == qp_run.iterations.tolist()
    np.testing.assert_allclose(tr.q, qp_run.q, atol=1e-6)


def test_qp_tracking_reaches_the_path_without_jumps(scenario, qp_run):
    """Every point is reached within the scenario's tolerance and no joint jumps by > 0.2 rad."""
    assert qp_run.complete, qp_run.summary()
    assert qp_run.jumps == []
    step = np.abs(np.diff(np.vstack([scenario.q0, qp_run.q]), axis=0))
    assert step.max() <= 0.2 + 1e-9


def test_weighted_run_needs_its_obstacle_task_the_qp_constraint_holds(scenario, qp_run):
    """Eq 48 without its (soft) obstacle task enters obstacles; the QP's hard rows never do."""
    weak = scenario.solver.with_options(obstacle_weight=0.0)
    soft = track(scenario.robot, scenario.path, weak, q0=scenario.q0,
                 obstacles=scenario.obstacles)
    assert _circle_clearance(scenario.robot, soft.q, scenario.obstacles).min() < 0.0
    assert qp_run.min_clearance > 0.0


def test_joint_jumps_are_reported_never_silent():
    """DLS tracking with a tiny max_joint_step lists every larger move as a JointJump."""
    arm = planar_arm(4, 0.1)
    path = Path.from_points([[0.3, 0.1], [0.1, 0.3], [-0.2, 0.1]])
    tr = track(arm, path, q0=np.full(4, 0.3), max_joint_step=0.05)
    assert tr.jumps and all(abs(j.size) > 0.05 for j in tr.jumps)
    assert "jumped" in tr.summary()
    capped = track(arm, path, "qp", q0=np.full(4, 0.3), max_joint_step=0.05)
    assert capped.jumps == []
    assert np.abs(np.diff(np.vstack([np.full(4, 0.3), capped.q]), axis=0)).max() <= 0.05 + 1e-9
    assert not capped.reached.all()  # the far points cannot be reached within 0.05 rad


def test_target_inside_an_obstacle_is_not_reached_and_not_entered():
    """A path point inside an obstacle is reported unreached; the arm stops outside it."""
    arm = planar_arm(6, 0.1)
    obs = Cylinder(0.05, math.inf, center=[0.3, 0.25, 0.0], influence=0.03)
    path = Path.from_points([[0.35, 0.1], [0.3, 0.25]])
    tr = track(arm, path, "qp", q0=np.full(6, 0.2), obstacles=(obs,))
    assert tr.reached.tolist() == [True, False]
    assert tr.min_clearance > 0.0
    assert tr.errors[1] >= 0.05 - 0.003  # stays at least the radius (minus safety) away


def test_scenario_file_selects_the_qp(scenario):
    """A scenario with solver: {method: qp, ...} tracks through the QP with its settings."""
    data = copy.deepcopy(scenario.data)
    data["solver"] = {"method": "qp", "safety": 0.003, "max_joint_step": 0.2, "max_iter": 100}
    data["path"]["waypoints"] = data["path"]["waypoints"][:3]
    sc = scenario_from_dict(data)
    assert isinstance(sc.solver, QPResolver) and sc.solver.safety == 0.003
    tr = sc.run()
    assert tr.complete and "QP" in tr.solver
    data["solver"] = {"method": "qp", "backend": "qpsolvers:nonexistent"}
    with pytest.raises(InputError, match="nonexistent"):
        scenario_from_dict(data)
    data["solver"] = {"method": "qp", "weight": 1.0}
    with pytest.raises(InputError, match="weight"):
        scenario_from_dict(data)


@pytest.mark.parametrize("suffix", [".csv", ".npz"])
def test_jumps_survive_a_file_round_trip(tmp_path, suffix):
    """Reported joint jumps are saved with the trajectory and read back unchanged."""
    arm = planar_arm(4, 0.1)
    path = Path.from_points([[0.3, 0.1], [0.1, 0.3]])
    tr = track(arm, path, q0=np.full(4, 0.3), max_joint_step=0.05)
    assert tr.jumps
    back = type(tr).load(tr.save(tmp_path / f"t{suffix}"))
    assert back.jumps == tr.jumps


def test_chapter_side_by_side_reports_both_runs(tmp_path, scenario, qp_run):
    """The report's comparison: eq 48 and QP rows with their numbers, a table and a figure."""
    pytest.importorskip("matplotlib")
    from serialkin.chapter.report import ReportContext
    from serialkin.chapter.sections import redundancy

    ctx = ReportContext(outdir=tmp_path, quiet=True)
    weighted, wt = redundancy.timed_run(ctx, scenario, repeat=1)
    rows = redundancy.side_by_side(ctx, scenario, weighted, wt, repeat=1)
    (w, _), (q, _) = rows
    assert q.min_clearance == pytest.approx(qp_run.min_clearance)
    assert q.worst_margin >= 0.0 and q.min_clearance > 0.0 and q.unreached == 0
    assert w.min_clearance == pytest.approx(weighted.min_clearance)
    assert q.per_point > 0 and w.per_point > 0
    sec = redundancy._qp_part(ctx, scenario, rows)
    assert "QP with hard constraints" in sec.html and "<table" in sec.html
    assert (tmp_path / "figures" / "twenty_link_qp_vs_eq48.png").read_bytes()[:4] == b"\x89PNG"


def test_cli_track_with_the_qp(tmp_path):
    """`serialkin track --solver qp` runs the QP; --max-joint-step bounds it (exit 1, reported)."""
    import json

    from click.testing import CliRunner

    from serialkin.cli.main import cli

    args = ["track", "six_link_circle", "--solver", "qp", "--no-figures", "--no-animation",
            "--json", "--out", str(tmp_path)]
    r = CliRunner().invoke(cli, args)
    assert r.exit_code == 0, r.output
    out = json.loads(r.stdout)
    assert "QP" in out["solver"] and out["success"] and out["jumps"] == []
    capped = CliRunner().invoke(cli, [*args, "--max-joint-step", "0.05"])
    assert capped.exit_code == 1  # the first points need larger moves from q0 = 0
    out = json.loads(capped.stdout[:capped.stdout.rindex("}") + 1])
    assert out["jumps"] == [] and out["failures"] and out["failures"][0]["index"] == 0
    bad = CliRunner().invoke(cli, ["track", "six_link_circle", "--max-joint-step", "-1",
                                   "--out", str(tmp_path)])
    assert bad.exit_code == 2 and "max-joint-step" in bad.output


def _self_distance(arm, Q):
    """Smallest distance between link segments two or more apart, minus two radii of 1 cm."""
    from serialkin.spatial.segments import closest_segment_segment

    worst = np.inf
    for q in Q:
        P = arm.fk_all(q)[:, :3, 3]
        for a in range(arm.n):
            for b in range(a + 2, arm.n):
                # points as tuples, as the library passes them
                s, t = closest_segment_segment(tuple(P[a]), tuple(P[a + 1]), tuple(P[b]),
                                               tuple(P[b + 1]))
                d = np.linalg.norm(P[a] + s * (P[a + 1] - P[a]) - P[b] - t * (P[b + 1] - P[b]))
                worst = min(worst, d - 0.02)
    return worst


def test_self_collision_tracking_keeps_links_apart_in_both_loops():
    """Folding a 6-link arm to its base: links cross without self-collision rows, never with."""
    arm = planar_arm(6, 0.1)
    path = Path.polyline([[0.5, 0.1], [0.05, 0.0], [0.0, 0.0]], 0.02)
    free = track(arm, path, QPResolver(task="planar", link_radius=0.01), q0=np.full(6, 0.1))
    assert _self_distance(arm, free.q) < 0.0
    runs = []
    for solver in ("compiled", "daqp"):
        res = QPResolver(task="planar", self_collision=True, link_radius=0.01, safety=0.005,
                         solver=solver)
        runs.append(track(arm, path, res, q0=np.full(6, 0.1)))
        assert _self_distance(arm, runs[-1].q) > 0.0
    np.testing.assert_allclose(runs[0].q, runs[1].q, atol=1e-6)


def test_margin_larger_than_the_free_space_is_reported(tmp_path):
    """A safety distance no configuration can keep: infeasible QPs are named, never silent."""
    arm = planar_arm(6, 0.1)
    obs = Cylinder(0.05, math.inf, center=[0.3, 0.2, 0.0], influence=0.05)
    path = Path.from_points([arm.fk(np.full(6, 0.2))[:2, 3], [0.45, 0.1]])
    res = QPResolver(task="planar", obstacles=(obs,), safety=0.5, max_step=0.01)
    tr = track(arm, path, res, q0=np.full(6, 0.2))
    text = tr.summary()
    assert "infeasible" in text
    assert tr.notes or any("infeasible" in f.reason for f in tr.failures)
    back = type(tr).load(tr.save(tmp_path / "t.npz"))
    assert back.notes == tr.notes and back.failures == tr.failures


def test_panda_tracking_with_its_capsule_model_and_a_scene():
    """A Panda path over a box on a table: no capsule enters the scene or another body."""
    import serialkin as sk
    from serialkin.collision import scene_clearance, self_clearance
    from serialkin.model.geometry import Box, HalfSpace

    panda = sk.models.get("panda")
    box = Box((0.2, 0.3, 0.2), center=[0.5, 0.0, 0.1])
    scene = (box, HalfSpace([0, 0, 1], -0.12))
    q0 = np.array([0.0, -0.3, 0.0, -2.2, 0.0, 2.0, 0.8])
    start = panda.fk(q0)[:3, 3]
    path = Path.polyline([start, [0.5, 0.0, 0.22], [0.5, 0.2, 0.3]], 0.01)
    res = QPResolver(task="position", scene=scene, self_collision=True, safety=0.005,
                     max_step=0.02, max_iter=100)
    tr = track(panda, path, res, q0=q0)
    sc = scene_clearance(panda, panda.collision, tr.q, scene).distance
    sf = self_clearance(panda, panda.collision, tr.q).distance
    assert sc.min() > 0.0 and sf.min() > 0.0
    lim = panda.qlim
    assert np.all(tr.q >= lim[:, 0]) and np.all(tr.q <= lim[:, 1])
    assert tr.reached[0] and tr.reached[-1]
