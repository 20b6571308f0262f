"""The one task table: every consumer reads the same rows for the same name."""

from __future__ import annotations

import numpy as np
import pytest

from serialkin import models
from serialkin.errors import InputError
from serialkin.ik.target import KIND_WEIGHTS
from serialkin.model.robot import TASK_ROWS
from serialkin.model.tasks import TARGET_TASKS, TASKS, get_task, task_rows, task_weights
from serialkin.redundancy.objectives import task_rows as redundancy_task_rows
from serialkin.tracking.path import TASKS as PATH_TASKS


def test_consumers_agree_with_the_table():
    """Robot rows, IK kind weights, path point sizes and resolver rows all come from TASKS."""
    for name, task in TASKS.items():
        assert TASK_ROWS[name] == task.rows
        assert redundancy_task_rows(name).tolist() == list(task.rows)
    for kind in TARGET_TASKS:
        w = np.array(KIND_WEIGHTS[kind])
        assert np.flatnonzero(w).tolist() == list(get_task(kind).rows)
        assert PATH_TASKS[kind] == get_task(kind).point_size
    assert TASKS["full"] is TASKS["pose"]
    assert task_weights("planar_pose") == (1.0, 1.0, 0.0, 0.0, 0.0, 1.0)


def test_validation_names_the_choices():
    """Unknown names and bad row lists raise InputError naming what is accepted."""
    with pytest.raises(InputError, match="unknown task 'foo'; expected one of: planar"):
        task_rows("foo")
    with pytest.raises(InputError, match="unknown path task 'orientation'"):
        get_task("orientation", targets_only=True, what="path task")
    for bad in ([0, 0], [], [6], [0.5], 3, [[0, 1]]):
        with pytest.raises(InputError, match="distinct integers in 0..5"):
            task_rows(bad)


def test_manipulability_is_one_implementation():
    """robot.manipulability equals sqrt(det(J Jᵀ)) of the task rows, for every frame."""
    r = models.ur5()
    q = r.random_q(4, seed=1)
    for task in ("pose", "position", "planar"):
        Jt = r.jacobian(q)[:, task_rows(task), :]
        ref = np.sqrt(np.linalg.det(Jt @ np.swapaxes(Jt, -1, -2)))
        np.testing.assert_allclose(r.manipulability(q, task), ref, rtol=1e-9)
    Jl = r.jacobian(q[0], "ee", link=3)[:3]
    np.testing.assert_allclose(r.manipulability(q[0], "position", frame="ee", link=3),
                               np.sqrt(max(np.linalg.det(Jl @ Jl.T), 0.0)), atol=1e-12)


def test_revolute_flags_and_chain_are_public():
    """robot.revolute matches the joint types and the chain's meta column; it is read-only."""
    r = models.stanford()  # RRPRRR
    assert r.revolute.dtype == bool and r.revolute.shape == (r.n,)
    assert r.revolute.tolist() == [t == "R" for t in r.joint_types]
    assert (r.chain.meta[:, 3] == 0.0).tolist() == r.revolute.tolist()
    with pytest.raises(ValueError):
        r.revolute[0] = not r.revolute[0]
