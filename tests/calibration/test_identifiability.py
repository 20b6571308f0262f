"""Identifiability: named redundancies, flagged parameters, Hayati against plain DH."""

from __future__ import annotations

import numpy as np
from hypothesis import example, given, settings
from hypothesis import strategies as st

import serialkin as sk
from serialkin.calibration import error_model, identifiability, make_measurements
from serialkin.calibration.identifiability import analyse
from tests.kinematics._fd import dh_rows, random_transform


def _measure(robot, model, kind, count=40, seed=1):
    q = robot.random_q(count, seed=seed)
    T = model.fk(q)
    return (make_measurements(robot, q, positions=T[:, :3, 3]) if kind == "position"
            else make_measurements(robot, q, poses=T))


def test_ur5_pose_redundancies_are_named():
    """Full poses: d1/base z and theta1/base rz and the last link against the tool."""
    robot = sk.models.ur5()
    model = error_model(robot)
    ident = identifiability(model, _measure(robot, model, "pose"))
    assert ident.rank == 30  # 4 R + 6 for a 6R arm
    assert "d1 and base z cannot be separated from pose measurements" in ident.reasons
    assert "theta1 and base rz cannot be separated from pose measurements" in ident.reasons
    assert set(ident.unidentifiable) == {"theta1", "d1", "theta6", "d6", "a6", "alpha6"}
    assert np.isfinite(ident.condition_number) and ident.condition_number < 100
    assert ident.condition_number_all == np.inf


def test_positions_flag_the_tool_rotations():
    """From positions, the three tool rotations are flagged as having no effect."""
    robot = sk.models.ur5().with_tool(sk.spatial.make_transform(p=[0.05, 0.02, 0.06]))
    model = error_model(robot)
    ident = identifiability(model, _measure(robot, model, "position"))
    assert ident.rank == 27  # 30 - 3 tool orientation
    for name in ("tool rx", "tool ry", "tool rz"):
        assert f"{name} has no effect on position measurements" in ident.reasons
        assert not ident.identifiable[model.names.index(name)]


def test_hayati_is_well_conditioned_where_plain_dh_is_not():
    """Puma 560 joints 2-3 (parallel): plain DH's Jacobian is singular, Hayati's is not."""
    robot = sk.models.puma560()
    plain = error_model(robot, hayati="none", base=False, tool=False)
    hayati = error_model(robot, hayati="auto", base=False, tool=False)
    a = identifiability(plain, _measure(robot, plain, "pose"))
    b = identifiability(hayati, _measure(robot, hayati, "pose"))
    assert plain.size == hayati.size == 24
    assert a.condition_number_all > 1e12  # d2 and d3 slide along the same direction
    assert "d3 and d2 cannot be separated from pose measurements" in a.reasons
    assert b.condition_number_all < 100 and b.rank == 24


def test_plain_dh_degrades_as_axes_approach_parallel():
    """A tilt t of axis 3 makes plain DH's d grow like 1/t and its condition number like 1/t².

    Hayati's model of the same tilted arm stays well conditioned.
    """
    from serialkin.model.dh_extract import to_dh_robot

    robot = sk.models.puma560()
    hay = error_model(robot, base=False, tool=False)
    conds = []
    for tilt in (1e-2, 1e-3):
        p = hay.nominal.copy()
        p[hay.names.index("beta2")] = tilt
        tilted = to_dh_robot(hay.calibrated_robot(p))  # the same arm as a plain DH table
        plain = error_model(tilted, hayati="none", base=False, tool=False)
        assert abs(tilted.dh[1].d) > 0.4 / tilt  # the common normal runs off
        conds.append(identifiability(plain, _measure(tilted, plain, "pose")
                                     ).condition_number_all)
        again = identifiability(hay, _measure(robot, hay, "pose"), p)
        assert again.condition_number < 100
    assert conds[0] > 1e4 and conds[1] > 50 * conds[0]


def test_analyse_finds_a_dependent_column():
    """A column that is a sum of two others is left out and named with both."""
    rng = np.random.default_rng(0)
    J = rng.normal(size=(20, 3))
    J = np.column_stack([J, J[:, 0] + 2 * J[:, 1]])
    ident = analyse(J, ["a", "b", "c", "d"])
    assert ident.identifiable.tolist() == [True, True, True, False]
    assert ident.reasons == ("d cannot be separated from a, b (a combination of them) using "
                             "the measurements",)


def test_complete_minimal_counts():
    """4R + 2P + 6 for full poses: Stanford arm (5R 1P) 28; Puma in modified DH 30, no d2."""
    from serialkin.model.dh import standard_to_modified

    stanford = sk.models.stanford()
    model = error_model(stanford)
    assert identifiability(model, _measure(stanford, model, "pose")).rank == 28
    puma = sk.models.puma560()
    rows, base, tool = standard_to_modified(puma.dh, puma.base, puma.tool)
    modified = sk.Robot.from_dh(rows, "modified", base=base, tool=tool)
    model = error_model(modified)
    assert model.hayati == (2,) and "beta3" in model.names and "d2" not in model.names
    ident = identifiability(model, _measure(modified, model, "pose"))
    assert ident.rank == 30 and ident.condition_number < 100


#: A twist of 1e-5 rad: base z, tool z and theta2 pass the Gram–Schmidt test one by one
#: (residuals 7.5e-6, 5.7e-6) yet the kept set was singular (σ_min 2e-16).
_TINY_TWIST = [{"a": 1.0, "alpha": 0.0, "d": 0.0, "theta": 0.0, "type": "R"},
               {"a": 0.0, "alpha": 0.0, "d": 0.0, "theta": 0.0, "type": "R"},
               {"a": 1.0, "alpha": 1e-05, "d": 0.0, "theta": 0.0, "type": "R"},
               {"a": 0.0, "alpha": 0.0, "d": 0.0, "theta": 0.0, "type": "R"},
               {"a": 0.0, "alpha": 0.0, "d": 0.0, "theta": 0.0, "type": "R"},
               {"a": 0.0, "alpha": 0.0, "d": 0.0, "theta": 0.0, "type": "P"}]
#: A common normal of 1.2e-7 m: the kept set's σ_min is 1.1e-7, just above tol/10.
_TINY_NORMAL = [{"a": 0.0, "alpha": 0.125, "d": 0.0, "theta": 0.0, "type": "R"},
                {"a": 0.0, "alpha": 0.0, "d": 0.5, "theta": 0.0, "type": "R"},
                {"a": 1.192092896e-07, "alpha": 0.0, "d": 0.0, "theta": 0.0, "type": "R"},
                {"a": 0.0, "alpha": 0.0, "d": 0.0, "theta": 0.0, "type": "R"}]


@settings(max_examples=15, deadline=None)
@example(rows=_TINY_TWIST, seed=0, kind="position")
@example(rows=_TINY_NORMAL, seed=0, kind="position")
@given(rows=dh_rows(min_joints=2, max_joints=6), seed=st.integers(0, 2**32 - 1),
       kind=st.sampled_from(["position", "pose"]))
def test_minimal_set_has_full_rank_and_explains_the_rest(rows, seed, kind):
    """The kept columns have full rank, and the set is maximal.

    Each dropped column lies in their span, would make them nearly singular, or has no
    effect.
    """
    from serialkin.calibration.jacobian import identification_jacobian

    rng = np.random.default_rng(seed)
    robot = sk.Robot.from_dh(rows, "standard", base=random_transform(rng))
    model = error_model(robot)
    meas = _measure(robot, model, kind, count=30, seed=rng)
    ident = identifiability(model, meas)
    J = identification_jacobian(model, meas)
    norms = np.linalg.norm(J, axis=0)
    effect = norms > 1e-12 * norms.max()
    Js = J / np.where(effect, norms, 1.0)
    kept = Js[:, ident.identifiable]
    assert np.linalg.matrix_rank(kept, tol=1e-8) == ident.rank
    assert len(ident.reasons) == model.size - ident.rank
    for k in np.flatnonzero(~ident.identifiable & effect):
        resid = Js[:, k] - kept @ np.linalg.lstsq(kept, Js[:, k], rcond=None)[0]
        with_k = np.linalg.svd(np.column_stack([kept, Js[:, k]]), compute_uv=False)
        assert np.linalg.norm(resid) < 1e-5 or with_k[-1] < 1e-6, (k, np.linalg.norm(resid))
    assert ident.rank <= 4 * int(robot.revolute.sum()) + 2 * int((~robot.revolute).sum()) + 6
