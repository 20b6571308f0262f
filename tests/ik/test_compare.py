"""The IK comparison table (serialkin.ik.compare)."""

from __future__ import annotations

import numpy as np
import pytest

from serialkin import models
from serialkin.errors import InputError
from serialkin.ik import METHODS
from serialkin.ik.compare import COLUMNS, CompareTable, compare

from ._numerical_helpers import well_conditioned_q

FAST = ["lm", "dls", "ccd", "fabrik"]


@pytest.fixture(scope="module")
def planar_table():
    robot = models.planar(3)
    T = robot.fk(well_conditioned_q(robot, 4, seed=1, task="planar"))
    return compare(robot, T[:, :2, 3], methods=FAST + ["bfgs"], tol=1e-6, seed=0)


def test_one_row_per_applicable_method(planar_table):
    """A planar arm with planar targets: every requested method runs and gets one row."""
    assert [r.method for r in planar_table.rows] == FAST + ["bfgs"]
    assert planar_table.skipped == []
    assert planar_table.target_kind == "planar" and planar_table.n_targets == 4


def test_row_contents_are_consistent(planar_table):
    """Rates lie in [0, 1], times are positive, errors finite, solves equal the target count."""
    for r in planar_table:
        assert 0.0 <= r.success_rate <= 1.0
        assert 0.0 <= r.within_limits_rate <= 1.0
        assert r.solves == 4
        assert 0.0 < r.median_time and 0.0 < r.mean_time
        assert r.median_iterations >= 0
        assert np.isfinite([r.median_position_error, r.max_position_error,
                            r.median_orientation_error, r.max_orientation_error]).all()
        assert r.median_position_error <= r.max_position_error
        assert r.family == METHODS[r.method].family
    # on well-conditioned targets every one of these methods succeeds
    assert all(r.success_rate == 1.0 for r in planar_table)
    assert all(r.max_position_error <= 1e-6 for r in planar_table)


def test_renderings(planar_table):
    """to_text, to_html and to_dicts show every row and column."""
    text = planar_table.to_text()
    html = planar_table.to_html()
    for name in FAST:
        assert name in text and f"<td>{name}</td>" in html
    assert all(c in text for c in COLUMNS)
    assert html.count("<tr>") == len(planar_table.rows) + 1
    dicts = planar_table.to_dicts()
    assert len(dicts) == len(planar_table.rows)
    assert set(dicts[0]) >= {"method", "success_rate", "median_time", "mean_time",
                             "median_iterations", "max_position_error"}
    assert planar_table.row("ccd").method == "ccd"
    with pytest.raises(KeyError):
        planar_table.row("powell")


def test_fabrik_is_skipped_on_spatial_robots_with_reason():
    """On UR5 FABRIK gets no row but a skip reason; the other methods run."""
    robot = models.ur5()
    T = robot.fk(well_conditioned_q(robot, 2, seed=2))
    table = compare(robot, T, methods=["lm", "fabrik", "ccd"], tol=1e-6, seed=0,
                    restarts=30)
    assert isinstance(table, CompareTable)
    assert [r.method for r in table.rows] == ["lm", "ccd"]
    assert [m for m, _ in table.skipped] == ["fabrik"]
    assert "parallel" in table.skipped[0][1]
    assert "skipped fabrik" in table.to_text()
    assert table.row("lm").success_rate == 1.0


def test_same_seed_same_table():
    """The same seed gives the same success rates, iterations and errors (not times)."""
    robot = models.puma560()
    T = robot.fk(robot.random_q(3, seed=3))
    a = compare(robot, T[:, :3, 3], methods=["lm", "ccd"], seed=7, tol=1e-6)
    b = compare(robot, T[:, :3, 3], methods=["lm", "ccd"], seed=7, tol=1e-6)
    for ra, rb in zip(a.rows, b.rows):
        assert ra.success_rate == rb.success_rate
        assert ra.median_iterations == rb.median_iterations
        assert ra.max_position_error == rb.max_position_error


def test_initial_guesses_and_method_options():
    """q0 (N, n) and per-method options are passed through to the solves."""
    robot = models.planar(3)
    Q = well_conditioned_q(robot, 2, seed=4, task="planar")
    T = robot.fk(Q)
    table = compare(robot, T[:, :2, 3], methods=["dls"], q0=Q, tol=1e-6,
                    method_options={"dls": {"damping": 0.05}})
    r = table.row("dls")
    assert r.success_rate == 1.0 and r.median_iterations <= 1  # started on the answer


def test_default_methods_exclude_closed_form():
    """Without methods=, every registered numerical method runs (no closed-form ones)."""
    robot = models.planar(2)
    table = compare(robot, [[1.2, 0.4]], tol=1e-6, max_iter=200, restarts=2)
    ran = {r.method for r in table.rows} | {m for m, _ in table.skipped}
    expected = {m for m in METHODS if METHODS[m].family != "analytic"}
    assert ran == expected
    assert all(0.0 <= r.success_rate <= 1.0 for r in table.rows)


@pytest.mark.parametrize("kwargs, match", [
    ({"methods": ["nope"]}, "nope"),
    ({"methods": []}, "methods"),
    ({"tol": -1.0}, "tol"),
    ({"bogus": 1}, "bogus"),
    ({"method_options": {"ccd": {}}, "methods": ["lm"]}, "method_options"),
])
def test_bad_input(kwargs, match):
    """Unknown methods, an empty list, a negative tol or unknown options raise naming them."""
    robot = models.planar(2)
    with pytest.raises((InputError, TypeError), match=match):
        compare(robot, [[1.2, 0.4]], **kwargs)
