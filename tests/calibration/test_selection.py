"""Pose selection by observability indices."""

from __future__ import annotations

import numpy as np
import pytest

import serialkin as sk
from serialkin.calibration import error_model, observability, select_poses
from serialkin.calibration.selection import candidate_jacobians
from serialkin.errors import InputError


def test_observability_indices_of_a_known_matrix():
    """O1..O4 of diag(4, 1) stacked with zeros: geometric mean/√L, 1/4, 1, 1/4."""
    J = np.array([[4.0, 0.0], [0.0, 1.0], [0.0, 0.0], [0.0, 0.0]])
    assert observability(J, "O1") == pytest.approx(2.0 / 2.0)
    assert observability(J, "O2") == pytest.approx(0.25)
    assert observability(J, "O3") == pytest.approx(1.0)
    assert observability(J, "O4") == pytest.approx(0.25)


@pytest.mark.parametrize("index", ["O1", "O3"])
def test_selected_poses_beat_random_subsets(index):
    """K selected of 300 candidates score higher than every one of 20 random K-subsets."""
    robot = sk.models.ur5().with_tool(sk.spatial.make_transform(p=[0.05, 0.02, 0.06]))
    model = error_model(robot)
    cand = robot.random_q(300, seed=1)
    K = 15
    chosen = select_poses(model, cand, K, index=index, seed=0)
    assert len(set(chosen.tolist())) == K
    J = candidate_jacobians(model, cand, "position")
    r = J.shape[2]
    best = observability(J[chosen].reshape(-1, r), index)
    rng = np.random.default_rng(2)
    randoms = [observability(J[rng.choice(300, K, replace=False)].reshape(-1, r), index)
               for _ in range(20)]
    assert best > max(randoms)


def test_selection_bad_count():
    """Too many or too few poses raise InputError with the needed count."""
    model = error_model(sk.models.ur5())
    with pytest.raises(InputError, match="at most the number of candidates 10"):
        select_poses(model, 10, 11, seed=0)
    with pytest.raises(InputError, match="at least 9 position measurements"):
        select_poses(model, 50, 3, seed=0)
