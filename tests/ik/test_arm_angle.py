"""7-DOF arms: S-R-S arms by their arm angle (closed form, feasible ψ), others by a sweep."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from serialkin import Robot, models
from serialkin.errors import InputError, NoClosedFormError
from serialkin.ik.analytic.arm_angle import _solve as compiled_solve
from serialkin.ik.analytic.arm_angle import (
    arm_angle,
    arm_angle_intervals,
    ik_arm_angle,
    srs_structure,
)
from serialkin.ik.sweep import END_TOL, joint_sweep
from serialkin.model.dh import DHLink

from . import _arm_angle_reference as reference_closed_form


def _wrapped(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    return np.abs((np.asarray(a) - b + np.pi) % (2 * np.pi) - np.pi)


def _reaches(robot: Robot, Q: np.ndarray, T: np.ndarray) -> float:
    F = robot.fk(Q)
    return float(max(np.abs(F[..., :3, 3] - T[:3, 3]).max(),
                     np.abs(F[..., :3, :3] - T[:3, :3]).max()))


def _transform(rng: np.random.Generator) -> np.ndarray:
    A = rng.normal(size=(3, 3))
    R, _ = np.linalg.qr(A)
    T = np.eye(4)
    T[:3, :3] = R * np.sign(np.linalg.det(R))
    T[:3, 3] = rng.uniform(-0.2, 0.2, 3)
    return T


def _random_srs(seed: int, orthogonal: bool = False) -> Robot:
    """A random S-R-S arm: standard DH with a = 0 and d = 0 where the shoulder and wrist meet.

    Axes 1–3 meet when a1 = a2 = d2 = 0, axes 5–7 when a5 = a6 = d6 = 0; the twists
    (±90° when ``orthogonal``, as on the iiwa), the elbow's offsets (a3, a4, d3, d4, d5)
    and base and tool are random. No joint limits.
    """
    rng = np.random.default_rng(seed)

    def twist() -> float:
        size = math.pi / 2 if orthogonal else rng.uniform(0.3, math.pi - 0.3)
        return float(rng.choice([-1, 1]) * size)

    rows = [DHLink(a=0.0, alpha=twist(), d=rng.uniform(0.1, 0.4)),
            DHLink(a=0.0, alpha=twist(), d=0.0),
            DHLink(a=rng.uniform(-0.1, 0.1), alpha=twist(), d=rng.uniform(0.2, 0.5)),
            DHLink(a=rng.uniform(-0.1, 0.1), alpha=twist(), d=rng.uniform(-0.1, 0.1)),
            DHLink(a=0.0, alpha=twist(), d=rng.uniform(0.2, 0.5)),
            DHLink(a=0.0, alpha=twist(), d=0.0),
            DHLink(a=0.0, alpha=0.0, d=rng.uniform(0.05, 0.2))]
    return Robot.from_dh(rows, "standard", base=_transform(rng), tool=_transform(rng),
                         name=f"srs{seed}")


def test_iiwa_generating_configuration_is_among_the_solutions_at_its_arm_angle():
    """iiwa7: ik_arm_angle(fk(q), ψ(q)) contains q; every row reaches T and has arm angle ψ."""
    robot = models.get("iiwa7")
    Q = robot.random_q(100, seed=5)
    for q in Q:
        T = robot.fk(q)
        psi = float(arm_angle(robot, q))
        sols = ik_arm_angle(robot, T, psi)
        assert 1 <= len(sols) <= 8
        assert _wrapped(sols.q, q).max(axis=1).min() < 1e-9
        assert _reaches(robot, sols.q, T) < 1e-10
        assert _wrapped(arm_angle(robot, sols.q), psi).max() < 1e-9
        assert len(set(sols.branch.tolist())) == len(sols)


@settings(max_examples=25, deadline=None)
@given(seed=st.integers(0, 2**31 - 1), qseed=st.integers(0, 2**31 - 1),
       reference=st.sampled_from([None, (1.0, 0.0, 0.0), (0.3, -0.5, 0.8)]))
def test_random_srs_arms_contain_the_generating_configuration(seed, qseed, reference):
    """Random S-R-S arms (random twists, elbow offsets, base, tool), any reference: q found."""
    robot = _random_srs(seed)
    q = np.random.default_rng(qseed).uniform(-math.pi, math.pi, 7)
    T = robot.fk(q)
    psi = float(arm_angle(robot, q, reference))
    sols = ik_arm_angle(robot, T, psi, reference)
    assert _wrapped(sols.q, q).max(axis=1).min() < 1e-8
    assert _reaches(robot, sols.q, T) < 1e-9
    assert _wrapped(arm_angle(robot, sols.q, reference), psi).max() < 1e-8


def test_unlimited_srs_arm_has_eight_distinct_solutions_at_a_generic_pose():
    """Orthogonal twists, no limits: a generic pose has 8 configurations at each ψ.

    (With other twists a spherical shoulder or wrist does not reach every direction, so
    some branches exist only on part of the circle of ψ.)
    """
    robot = _random_srs(11, orthogonal=True)
    T = robot.fk(np.full(7, 0.4))
    for psi in (-2.0, 0.0, 1.3):
        sols = ik_arm_angle(robot, T, psi)
        assert sorted(sols.branch.tolist()) == list(range(8))
        d = _wrapped(sols.q[:, None, :], sols.q[None, :, :]).max(axis=2)
        assert d[~np.eye(8, dtype=bool)].min() > 1e-6


def test_branches_are_continuous_in_the_arm_angle():
    """Following one branch along ψ never jumps: a large step shrinks when ψ's step does."""
    robot = _random_srs(3, orthogonal=True)
    T = robot.fk(np.full(7, 0.7))

    def rows(psi: float) -> dict[int, np.ndarray]:
        sols = ik_arm_angle(robot, T, psi)
        assert len(sols) == 8
        return dict(zip(sols.branch.tolist(), sols.q))

    psis = np.linspace(-1.0, 1.0, 101)
    prev = rows(psis[0])
    for a, b in zip(psis[:-1], psis[1:]):
        cur = rows(b)
        for j in range(8):
            step = _wrapped(cur[j], prev[j]).max()
            if step > 0.05:  # fast motion (near a shoulder or wrist singularity) or a jump?
                fine = [rows(x)[j] for x in np.linspace(a, b, 21)]
                finer = max(_wrapped(u, v).max() for u, v in zip(fine[:-1], fine[1:]))
                assert finer < 0.5 * step, (b, j, step, finer)
        prev = cur


def test_intervals_agree_with_dense_sampling_and_end_on_a_limit():
    """ψ is feasible iff ik_arm_angle finds a row there; each inner interval end is a limit."""
    robot = models.get("iiwa7")
    lo, hi = robot.qlim[:, 0], robot.qlim[:, 1]
    for seed in range(4):
        T = robot.fk(robot.random_q(1, seed=40 + seed)[0])
        iv = arm_angle_intervals(robot, T)
        assert not iv.singular
        rng = np.random.default_rng(seed)
        for psi in rng.uniform(-math.pi, math.pi, 300):
            sols = ik_arm_angle(robot, T, psi)
            near_end = any(min(abs(psi - a), abs(psi - b)) < 1e-7
                           for spans in iv.branches.values() for a, b in spans)
            if near_end:
                continue
            assert iv.contains(psi) == (len(sols) > 0), psi
            for j in range(8):
                assert iv.contains(psi, j) == (j in sols.branch), (psi, j)
        for j, spans in iv.branches.items():
            for a, b in spans:
                for end in (a, b):
                    if abs(abs(end) - math.pi) < 1e-12:
                        continue  # the ±π seam, not a limit
                    sols = ik_arm_angle(robot, T, end)
                    row = sols.q[sols.branch == j]
                    assert len(row) == 1, (j, end)
                    gap = np.minimum(np.abs(row[0] - lo), np.abs(row[0] - hi)).min()
                    assert gap < 1e-7, (j, end, gap)


def test_closed_form_intervals_equal_the_grid_search():
    """iiwa7: the closed-form intervals are the grid search's and bisection's to 1e-9.

    The reference evaluates every branch at 721 values of ψ and bisects each change 40
    times (:func:`_arm_angle_reference.intervals`); on these poses no feasible stretch or
    gap is narrower than its grid step, so both find the same stretches.
    """
    robot = models.get("iiwa7")
    arm = srs_structure(robot)
    for seed in range(40, 46):
        T = robot.fk(robot.random_q(1, seed=seed)[0])
        got = arm_angle_intervals(robot, T).branches
        want = reference_closed_form.intervals(arm, T, np.array([0.0, 0.0, 1.0]))
        assert got.keys() == want.keys()
        for j in got:
            assert len(got[j]) == len(want[j])
            assert np.abs(np.array(got[j]) - np.array(want[j])).max() < 1e-9


def _limited_srs(seed: int, orthogonal: bool) -> Robot:
    """A random S-R-S arm (:func:`_random_srs`) with random limits, some joints unlimited."""
    rng = np.random.default_rng(seed + 7)
    lo, hi = -rng.uniform(0.3, 3.2, 7), rng.uniform(0.3, 3.2, 7)
    free = rng.random(7) < 0.2
    lo[free], hi[free] = -np.inf, np.inf
    return _random_srs(seed, orthogonal).with_limits(np.stack([lo, hi], axis=1))


def _check_intervals(robot: Robot, T: np.ndarray, reference, extra: np.ndarray = None):
    """Every property of arm_angle_intervals(robot, T) against the closed form at given ψ.

    * ψ (2,001 on the circle and ``extra``) farther than 1e-7 from every end is feasible on
      branch j iff the interval list of j contains it (the compiled ``_solve``);
    * each inner end where the branch does not jump (a pivot joint at a singular
      shoulder or wrist) is feasible on its branch (ik_arm_angle has a row there), and
      there a joint is at a limit (to 1e-7) or, just outside, the branch does not exist.
    Returns the intervals.
    """
    arm = srs_structure(robot)
    r = np.array([0.0, 0.0, 1.0] if reference is None else reference, dtype=float)
    r /= np.linalg.norm(r)
    iv = arm_angle_intervals(robot, T, reference)
    psi = np.linspace(-math.pi, math.pi, 2001)
    if extra is not None:
        psi = np.concatenate([psi, extra])
    ok = compiled_solve(arm, T, psi, r)[1]
    ends = np.array([x for spans in iv.branches.values() for s in spans for x in s] + [9.0])
    far = np.abs(psi[:, None] - ends[None, :]).min(axis=1) > 1e-7
    for j in range(8):
        listed = np.array([iv.contains(x, j) for x in psi[far]])
        assert np.array_equal(listed, ok[far, j]), j
    assert np.array_equal(np.array([iv.contains(x) for x in psi[far]]), ok[far].any(axis=1))
    lo, hi = robot.qlim[:, 0], robot.qlim[:, 1]
    for j, spans in iv.branches.items():
        assert all(a < b for a, b in spans)
        assert all(b < c for (_, b), (c, _) in zip(spans[:-1], spans[1:]))
        for a, b in spans:
            for end, out in ((a, -1.0), (b, 1.0)):
                if abs(abs(end) - math.pi) < 1e-12:
                    continue  # the ±π seam
                sides = end + np.array([-1e-6, 1e-6])
                Q, exists = reference_closed_form.solve(arm, T, sides, r, limits=False)
                if exists[:, j].all() and _wrapped(Q[0, j], Q[1, j]).max() > 0.1:
                    continue  # a pivot jumps (singular shoulder or wrist): no limit here
                sols = ik_arm_angle(robot, T, end, reference)
                row = sols.q[sols.branch == j]
                assert len(row) == 1, (j, end)
                with np.errstate(invalid="ignore"):
                    gap = np.nanmin(np.minimum(np.abs(row[0] - lo), np.abs(row[0] - hi)))
                beyond = end + out * np.array([1e-7, 1e-6])
                gone = ~reference_closed_form.solve(arm, T, beyond, r, limits=False)[1][:, j]
                assert gap < 1e-7 or gone.all(), (j, end, gap)
    return iv


@settings(max_examples=30, deadline=None)
@given(seed=st.integers(0, 2**31 - 1), orthogonal=st.booleans(),
       reference=st.sampled_from([None, (1.0, 0.0, 0.0), (0.3, -0.5, 0.8)]))
def test_closed_form_intervals_on_random_limited_srs_arms(seed, orthogonal, reference):
    """Random S-R-S arms with random limits: intervals agree with dense evaluation, ends hold.

    Non-orthogonal twists make branches appear and vanish along ψ (subproblem 2 loses
    its solutions): ends there have no joint at a limit, and the branch is gone beyond.
    The generating configuration's arm angle is feasible on its branch.
    """
    robot = _limited_srs(seed, orthogonal)
    rng = np.random.default_rng(seed)
    q = rng.uniform(np.clip(robot.qlim[:, 0], -3, 3), np.clip(robot.qlim[:, 1], -3, 3))
    T = robot.fk(q)
    iv = _check_intervals(robot, T, reference)
    psi = float(arm_angle(robot, q, reference))
    sols = ik_arm_angle(robot, T, psi, reference)
    j = int(sols.branch[np.argmin(_wrapped(sols.q, q).max(axis=1))])
    assert iv.contains(psi, j)


@pytest.mark.parametrize(("joint", "pivot_limits"), [(1, (-1.5, 1.5)), (5, (-2.5, 0.6))])
def test_intervals_across_a_shoulder_or_wrist_singularity(joint, pivot_limits):
    """iiwa7 at a pose whose arm angle ψ₀ has a singular shoulder (q2 = 0) or wrist (q6 = 0).

    Along each branch the pivot joint before it (1 or 5) jumps by π at ψ₀ (from −0.87 to
    2.27 rad, or from −1.57 to 1.57 rad, on branch 0); with that joint limited so that
    one value is inside and the other outside, branch 0 ends at ψ₀ with no joint at a
    limit. The intervals agree with dense evaluation, also within ±1e-3 of ψ₀, and ψ₀
    (the generating configuration's) is feasible.
    """
    base = models.get("iiwa7")
    limits = base.qlim.copy()
    limits[joint - 1] = pivot_limits
    robot = base.with_limits(limits)
    q = np.array([0.5, 0.7, 0.2, -1.2, 0.4, 0.8, 0.1])
    q[joint] = 0.0
    T = robot.fk(q)
    psi0 = float(arm_angle(robot, q))
    iv = _check_intervals(robot, T, None, psi0 + np.linspace(-1e-3, 1e-3, 2001))
    assert iv.contains(psi0)
    assert iv.contains(psi0 - 1e-3, 0) and not iv.contains(psi0 + 1e-3, 0)
    assert min(abs(b - psi0) for _, b in iv.branches[0]) < 1e-6


def test_branch_feasible_everywhere_and_nowhere():
    """No limits, orthogonal twists: every branch on all of [−π, π]; elbow limits: none or half.

    Limiting the elbow to one of its two angles leaves only that elbow's four branches;
    limiting it to neither leaves no interval at all.
    """
    robot = _random_srs(11, orthogonal=True)
    T = robot.fk(np.full(7, 0.4))
    iv = arm_angle_intervals(robot, T)
    assert iv.branches == {j: [(-math.pi, math.pi)] for j in range(8)}
    assert iv.feasible == [(-math.pi, math.pi)]
    q4 = ik_arm_angle(robot, T, 0.0).q[:, 3]
    a, b = q4[0], q4[-1]                          # branch 0's elbow and branch 7's
    limits = np.tile([-np.inf, np.inf], (7, 1))
    limits[3] = [a - 1e-3, a + 1e-3]
    one = arm_angle_intervals(robot.with_limits(limits), T)
    assert set(one.branches) == ({0, 1, 2, 3} if abs(_wrapped(a, b)) > 1e-3 else set(range(8)))
    limits[3] = [0.5 * (a + b) - 1e-4, 0.5 * (a + b) + 1e-4]
    none = arm_angle_intervals(robot.with_limits(limits), T)
    assert none.branches == {} and none.feasible == []


def test_generating_arm_angle_lies_in_the_feasible_intervals():
    """The arm angle of a configuration inside the limits is feasible on its branch's pose."""
    robot = models.get("iiwa7")
    for q in robot.random_q(20, seed=9):
        iv = arm_angle_intervals(robot, robot.fk(q))
        assert iv.contains(float(arm_angle(robot, q)))


def test_out_of_reach_pose_has_no_solution_and_no_interval():
    """A pose beyond the arm's reach: no row at any ψ, no feasible interval."""
    robot = models.get("iiwa7")
    T = np.eye(4)
    T[:3, 3] = [3.0, 0.0, 0.5]
    assert len(ik_arm_angle(robot, T, 0.0)) == 0
    iv = arm_angle_intervals(robot, T)
    assert iv.feasible == [] and iv.branches == {}


def test_stretched_arm_pose_is_singular():
    """The arm straight up (elbow on the line S-W, which is the reference z): ψ undefined."""
    robot = models.get("iiwa7")
    T = robot.fk(np.zeros(7))
    assert arm_angle_intervals(robot, T).singular
    assert float(arm_angle(robot, np.zeros(7))) == 0.0
    sols = ik_arm_angle(robot, T, 0.5)
    assert len(sols) >= 1 and _reaches(robot, sols.q, T) < 1e-10


def test_structure_of_iiwa_and_refusal_of_offset_arms():
    """iiwa7 is S-R-S (shoulder at d1, wrist at d1 + d3 + d5); the Panda is refused, saying why."""
    arm = srs_structure(models.get("iiwa7"))
    assert np.allclose(arm.S, [0, 0, 0.34], atol=1e-12)
    assert np.allclose(arm.W0, [0, 0, 1.14], atol=1e-12)
    with pytest.raises(NoClosedFormError, match="axes 5, 6, 7 do not meet|axes 1, 2, 3"):
        srs_structure(models.get("panda"))
    with pytest.raises(NoClosedFormError, match="7 joints|6 joints"):
        srs_structure(models.get("ur5"))


def test_bad_input_is_named():
    """Bad ψ, pose, reference and resolution raise errors naming the argument."""
    robot = models.get("iiwa7")
    T = robot.fk(np.zeros(7))
    with pytest.raises(InputError, match="psi"):
        ik_arm_angle(robot, T, float("nan"))
    with pytest.raises(InputError, match="reference"):
        ik_arm_angle(robot, T, 0.0, reference=(0.0, 0.0, 0.0))
    with pytest.raises(InputError, match="T"):
        ik_arm_angle(robot, np.eye(3), 0.0)
    with pytest.raises(InputError, match="T must be one"):
        ik_arm_angle(robot, np.stack([T, T]), 0.0)
    with pytest.raises(InputError, match="T must be one"):
        arm_angle_intervals(robot, np.stack([T, T]))
    with pytest.raises(InputError, match="reference"):
        arm_angle_intervals(robot, T, reference=(0.0, 0.0, 0.0))


# ------------------------------------------------- offset 7R arms: a sweep of one joint

def test_panda_sweep_contains_the_generating_configuration_on_one_branch():
    """Panda, joint 7 swept: the generating q lies on a branch; every row reaches T."""
    robot = models.get("panda")
    for seed in range(3):
        q = robot.random_q(1, seed=60 + seed)[0]
        T = robot.fk(q)
        values = np.linspace(q[6] - 0.3, q[6] + 0.3, 31)  # q[6] is the middle value
        sweep = joint_sweep(robot, T, 6, values)
        rows = sweep.q[15][sweep.valid[15]]
        assert _wrapped(rows, q).max(axis=1).min() < 1e-9
        assert _reaches(robot, sweep.q[sweep.valid], T) < 1e-9
        assert np.all(sweep.q[sweep.valid][:, 6] == np.repeat(values, sweep.valid.sum(1)))


def test_sweep_branches_never_jump_and_match_a_fine_sweep():
    """Along each branch neighbouring rows differ by at most max_jump; a finer grid agrees."""
    robot = models.get("panda")
    q = robot.random_q(1, seed=71)[0]
    T = robot.fk(q)
    sweep = joint_sweep(robot, T, 6, resolution=math.radians(3.0))
    assert sweep.branches >= 1
    for k in range(sweep.branches):
        v, rows = sweep.branch(k)
        assert np.all(np.diff(np.flatnonzero(sweep.valid[:, k])) == 1)  # one run
        if len(rows) > 1:
            assert _wrapped(rows[1:], rows[:-1]).max() <= sweep.max_jump
    # the generating value is feasible, and feasibility agrees with fresh solves
    assert any(a <= q[6] <= b for a, b in sweep.feasible)
    for a, b in sweep.feasible:
        if a > sweep.values[0]:
            assert len(robot.ik_all(T, free={6: a - 1e-6})) == 0
            assert len(robot.ik_all(T, free={6: a + 1e-7})) > 0
        if b < sweep.values[-1]:
            assert len(robot.ik_all(T, free={6: b + 1e-6})) == 0
            assert len(robot.ik_all(T, free={6: b - 1e-7})) > 0


def test_sweep_ends_are_refined_to_end_tol():
    """Joint 7 swept (one batch per refinement round): ends within END_TOL.

    Each inner end has solutions and 2·END_TOL outside it none (fresh locked solves,
    with the limits).
    """
    robot = models.get("panda")
    checked = 0
    for q in [np.array([0.2, -0.3, 0.1, -2.0, 0.1, 1.8, 0.6])] + list(robot.random_q(4, seed=5)):
        T = robot.fk(q)
        sweep = joint_sweep(robot, T, 6)
        for a, b in sweep.feasible:
            for end, out in ((a, -1.0), (b, 1.0)):
                if sweep.values[0] < end < sweep.values[-1]:
                    assert len(robot.ik_all(T, free={6: end})) > 0
                    assert len(robot.ik_all(T, free={6: end + out * 2 * END_TOL})) == 0
                    checked += 1
    assert checked >= 4


def test_sweep_of_a_middle_joint_has_refined_ends():
    """Joint 4 (a locked solve per value): the feasible ends are found and refined.

    Regression: an end whose neighbouring grid samples were not all feasible raised
    IndexError (a masked sample was looked up past the end of the samples' array).
    """
    robot = models.get("panda")
    T = robot.fk(np.array([0.2, -0.3, 0.1, -2.0, 0.1, 1.8, 0.6]))
    sweep = joint_sweep(robot, T, 3, resolution=math.radians(10.0))
    assert sweep.feasible
    for a, b in sweep.feasible:
        for end, out in ((a, -1.0), (b, 1.0)):
            if sweep.values[0] < end < sweep.values[-1]:
                assert len(robot.ik_all(T, free={3: end + out * 1e-6})) == 0
                assert len(robot.ik_all(T, free={3: end - out * 1e-7})) > 0


def test_sweep_bad_input_is_named():
    """A bad joint index, unsorted values or a non-positive jump name their argument."""
    robot = models.get("panda")
    T = robot.fk(np.zeros(7))
    with pytest.raises(InputError, match="joint"):
        joint_sweep(robot, T, 7)
    with pytest.raises(InputError, match="values"):
        joint_sweep(robot, T, 6, [0.2, 0.1])
    with pytest.raises(InputError, match="max_jump"):
        joint_sweep(robot, T, 6, max_jump=0.0)


def test_robot_methods_are_the_module_functions():
    """robot.arm_angle / ik_arm_angle / arm_angle_intervals give the functions' results."""
    robot = models.get("iiwa7")
    q = np.array([0.3, 0.6, -0.2, -1.2, 0.4, 0.8, 0.1])
    T = robot.fk(q)
    psi = robot.arm_angle(q)
    assert psi == arm_angle(robot, q)
    assert np.array_equal(robot.ik_arm_angle(T, psi).q, ik_arm_angle(robot, T, psi).q)
    assert robot.arm_angle_intervals(T).feasible == arm_angle_intervals(robot, T).feasible


@pytest.mark.parametrize("seed", [None, 3, 8, 21])
def test_compiled_closed_form_equals_the_numpy_reference(seed):
    """The compiled kernel gives the numpy closed form's flags and angles to 1e-12.

    iiwa7 (with limits) and random S-R-S arms (no limits), random poses and arm angles.
    """
    robot = models.get("iiwa7") if seed is None else _random_srs(seed)
    arm = srs_structure(robot)
    rng = np.random.default_rng(0 if seed is None else seed)
    r = np.array([0.3, -0.5, 0.8]) / np.linalg.norm([0.3, -0.5, 0.8])
    for T in robot.fk(robot.random_q(20, seed=1)):
        psi = rng.uniform(-math.pi, math.pi, 16)
        Q_ref, ok_ref = reference_closed_form.solve(arm, T, psi, r)
        Q, ok = compiled_solve(arm, T, psi, r)
        assert np.array_equal(ok, ok_ref)
        assert ok.any()
        assert np.abs(Q - Q_ref)[ok].max() < 1e-12


def test_one_pose_fast_path_equals_the_checked_path():
    """A C-ordered float64 pose (compiled checks) and a Fortran-ordered one give the same rows."""
    robot = models.get("iiwa7")
    rng = np.random.default_rng(4)
    for T in robot.fk(robot.random_q(30, seed=2)):
        psi = float(rng.uniform(-math.pi, math.pi))
        fast = ik_arm_angle(robot, T, psi)
        checked = ik_arm_angle(robot, np.asfortranarray(T), psi)
        assert np.array_equal(fast.branch, checked.branch)
        assert fast.branch.dtype == checked.branch.dtype == np.int64
        assert np.abs(fast.q - checked.q).max(initial=0.0) < 1e-12
        if len(fast):
            assert _reaches(robot, fast.q, T) < 1e-10


def test_sweep_of_the_last_joint_has_the_locked_solves_rows():
    """A sweep of joint 7 (one batch solve) has, at each value, the rows of ik_all(free=...)."""
    robot = models.get("panda")
    T = robot.fk(np.array([0.2, -0.3, 0.1, -2.0, 0.1, 1.8, 0.6]))
    sw = joint_sweep(robot, T, 6, resolution=math.radians(5.0))
    assert sw.valid.any()
    for i, v in enumerate(sw.values):
        rows = np.asarray(robot.ik_all(T, free={6: float(v)}).q)
        got = sw.q[i, sw.valid[i]]
        assert got.shape == rows.shape
        for row in rows:
            assert np.abs(got - row).max(axis=1).min() < 1e-9


def test_a_sweep_pickles_and_reads_the_same_intervals_after():
    """A sweep pickles before and after its feasible intervals are read (computed lazily).

    The copy computes the same intervals as the original (to Dask workers, say).
    """
    import pickle

    robot = models.get("panda")
    T = robot.fk(np.array([0.2, -0.3, 0.1, -2.0, 0.1, 1.8, 0.6]))
    sw = joint_sweep(robot, T, 6, resolution=math.radians(5.0))
    copy = pickle.loads(pickle.dumps(sw))
    assert copy.feasible == sw.feasible and sw.feasible
    again = pickle.loads(pickle.dumps(sw))  # after the read: the cached list travels
    assert again.feasible == sw.feasible
    np.testing.assert_array_equal(again.q, sw.q)
