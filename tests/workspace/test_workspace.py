"""Workspace kinds by sampling: areas/volumes against closed forms within the stated error."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from serialkin import Robot, models
from serialkin.errors import InputError
from serialkin.spatial import rotz, rpy_to_matrix
from serialkin.workspace import (
    compute_workspace,
    constant_orientation_workspace,
    dexterous_workspace,
    inclusive_orientation_workspace,
    occupancy_grid,
    reachable_workspace,
    total_orientation_workspace,
    workspace_slice,
)
from serialkin.workspace.sampling import orientation_distance, planar_angle, project_orientation


def _annulus(L1: float, L2: float) -> float:
    """Area of the 2-link workspace π((L1+L2)² − (L1−L2)²) (chapter section 1)."""
    return math.pi * ((L1 + L2) ** 2 - (L1 - L2) ** 2)


def _planar(*lengths: float, qlim: float | None = None) -> Robot:
    lim = (-qlim, qlim) if qlim is not None else (-math.inf, math.inf)
    return Robot.from_dh([dict(a=L, alpha=0, d=0, theta=0, qlim=lim) for L in lengths])


@pytest.mark.parametrize(("L1", "L2"), [(1.0, 0.6), (1.0, 1.0), (0.5, 0.9)])
def test_two_link_area_within_stated_error(L1, L2):
    """A 2-link arm's sampled area matches π((L1+L2)² − (L1−L2)²) within the stated error."""
    ws = reachable_workspace(_planar(L1, L2), 300_000, seed=1, progress=False)
    exact = _annulus(L1, L2)
    est = ws.estimate
    assert ws.planar and ws.points.shape == (300_000, 2)
    assert abs(est.value - exact) <= est.error
    assert est.lower <= exact <= est.upper
    assert est.relative_error < 0.06  # the bound is informative, not vacuous


def test_two_link_model_area():
    """The built-in two_link model (L1 = L2 = 1) covers the disc of radius 2."""
    ws = compute_workspace(models.get("two_link"), "reachable", samples=200_000,
                           progress=False)
    assert abs(ws.estimate.value - 4 * math.pi) <= ws.estimate.error


def test_reachable_points_are_fk_of_q():
    """Every sample point is the FK position of its stored configuration."""
    r = _planar(1.0, 0.5, 0.25)
    ws = reachable_workspace(r, 2000, seed=3, progress=False)
    np.testing.assert_allclose(ws.points, r.fk(ws.q)[:, :2, 3], atol=1e-12)
    assert r.within_limits(ws.q).all()


def test_seed_reproducible():
    """The same seed gives the same samples; another seed gives others."""
    r = _planar(1.0, 0.6)
    a = reachable_workspace(r, 5000, seed=7, progress=False)
    b = reachable_workspace(r, 5000, seed=7, progress=False)
    c = reachable_workspace(r, 5000, seed=8, progress=False)
    np.testing.assert_array_equal(a.points, b.points)
    assert not np.array_equal(a.points, c.points)
    assert a.estimate == b.estimate


def test_constant_orientation_three_link():
    """3-link arm with fixed φ: the 2-link annulus about the wrist, every sample at φ."""
    L1, L2, L3, phi = 1.0, 0.8, 0.3, 0.7
    r = _planar(L1, L2, L3)
    ws = constant_orientation_workspace(r, phi, 150_000, seed=2, progress=False)
    assert ws.points.shape[0] > 0.9 * 150_000
    T = r.fk(ws.q)
    dphi = (planar_angle(T[:, :3, :3]) - phi + np.pi) % (2 * np.pi) - np.pi
    assert np.abs(dphi).max() <= 1e-4  # the projection's acceptance tolerance
    assert abs(ws.estimate.value - _annulus(L1, L2)) <= ws.estimate.error
    centre = ws.points - L3 * np.array([math.cos(phi), math.sin(phi)])
    rad = np.linalg.norm(centre, axis=1)
    slack = L3 * 1e-4 + 1e-9  # a 1e-4 rad orientation tolerance moves the wrist point
    assert rad.min() >= abs(L1 - L2) - slack and rad.max() <= L1 + L2 + slack


def test_inclusive_between_constant_and_maximal():
    """Inclusive-orientation area grows from constant (0) to maximal (π), within errors."""
    r = _planar(1.0, 0.8, 0.3)
    kw = dict(seed=4, progress=False)
    const = constant_orientation_workspace(r, 0.0, 100_000, **kw).estimate
    mid = inclusive_orientation_workspace(r, 0.0, 0.6, 100_000, **kw).estimate
    full = inclusive_orientation_workspace(r, 0.0, math.pi, 100_000, **kw).estimate
    maximal = reachable_workspace(r, 100_000, **kw).estimate
    assert const.value - const.error <= mid.value + mid.error
    assert mid.value - mid.error <= full.value + full.error
    assert abs(full.value - maximal.value) <= full.error + maximal.error
    assert abs(maximal.value - math.pi * 2.1 ** 2) <= maximal.error


def test_inclusive_orientations_in_range():
    """Inclusive samples have their planar angle within max_angle of the centre."""
    r = _planar(1.0, 0.8, 0.3)
    ws = inclusive_orientation_workspace(r, 1.0, 0.25, 20_000, seed=5, progress=False)
    phi = planar_angle(r.fk(ws.q)[:, :3, :3])
    d = np.abs((phi - 1.0 + np.pi) % (2 * np.pi) - np.pi)
    assert d.max() <= 0.25 + 1e-4


@pytest.mark.slow
def test_dexterous_three_link_annulus():
    """3-link total-orientation workspace: |p − L3 e_φ| ∈ [d, L1+L2] for every φ (d = |L1−L2|).

    That is ρ = |p| ∈ [d + L3, L1 + L2 − L3], plus the disc ρ ≤ L3 − d when L3 > d.
    """
    L1, L2, L3 = 1.0, 0.8, 0.3
    d = abs(L1 - L2)
    r = _planar(L1, L2, L3)
    exact = math.pi * ((L1 + L2 - L3) ** 2 - (d + L3) ** 2 + max(L3 - d, 0.0) ** 2)
    ws = dexterous_workspace(r, 12, 50_000, seed=6, singularity_margin=0.0, progress=False)
    assert abs(ws.estimate.value - exact) <= ws.estimate.error
    rad = np.linalg.norm(ws.points, axis=1)
    h = ws.grid.cell
    inner = rad <= L3 - d + 2 * h
    assert np.all(rad[~inner] >= d + L3 - 2 * h)
    assert rad.max() <= L1 + L2 - L3 + 2 * h


def test_dexterous_margin_removes_singular_samples():
    """With a singularity margin every kept sample has manipulability ≥ the threshold."""
    r = _planar(1.0, 0.8, 0.3)
    ws = dexterous_workspace(r, 4, 30_000, seed=1, singularity_margin=0.2, progress=False)
    w_min = ws.params["min_manipulability"]
    assert w_min > 0
    assert ws.manipulability.min() >= w_min
    np.testing.assert_allclose(ws.manipulability, r.manipulability(ws.q, task="planar_pose"))


def test_two_link_has_no_dexterous_workspace():
    """A 2-link arm cannot choose its orientation: its total-orientation workspace is empty."""
    ws = total_orientation_workspace(_planar(1.0, 0.6), 6, 20_000, seed=0, progress=False)
    assert ws.estimate.value < 0.02 * _annulus(1.0, 0.6)


def test_manipulability_map_two_link():
    """Per-cell maximum manipulability equals L1·L2·|sin q2| at the cell's radius."""
    L1, L2 = 1.0, 0.6
    ws = reachable_workspace(_planar(L1, L2), 200_000, seed=0, manipulability=True,
                             resolution=60, progress=False)
    W = ws.manipulability_map()
    xs, ys = ws.grid.axes()
    X, Y = np.meshgrid(xs, ys, indexing="ij")
    R = np.hypot(X, Y)
    cos_q2 = np.clip((R**2 - L1**2 - L2**2) / (2 * L1 * L2), -1.0, 1.0)
    sin_q2 = np.sqrt(1 - cos_q2**2)
    inside = ws.grid.interior() & (np.abs(cos_q2) < 0.95)
    expected = L1 * L2 * sin_q2
    # the cell spans radii r ± h/√2 and |dw/dr| = r |cos q2| / sin q2 (from r² = L1² + L2²
    # + 2 L1 L2 cos q2): compare within the variation of w over the cell
    dw = ws.grid.cell / math.sqrt(2) * R * np.abs(cos_q2) / np.maximum(sin_q2, 1e-3)
    assert np.all(np.abs(W[inside] - expected[inside]) <= dw[inside] + 1e-3)
    assert np.nanmax(W) <= L1 * L2 + 1e-12


def _elbow(L1: float, L2: float) -> Robot:
    """Spatial RRR elbow arm (base yaw, shoulder, elbow): shell |L1−L2| ≤ |p| ≤ L1+L2."""
    return Robot.from_dh([dict(a=0, alpha=math.pi / 2, d=0, theta=0),
                          dict(a=L1, alpha=0, d=0, theta=0), dict(a=L2, alpha=0, d=0, theta=0)])


def test_spatial_shell_volume_and_slice():
    """A spatial elbow arm's volume is the spherical shell's; its z = 0 slice an annulus."""
    L1, L2 = 1.0, 0.5
    ws = reachable_workspace(_elbow(L1, L2), 400_000, seed=2, progress=False)
    assert not ws.planar and ws.points.shape[1] == 3
    exact = 4 / 3 * math.pi * ((L1 + L2) ** 3 - (L1 - L2) ** 3)
    assert abs(ws.estimate.value - exact) <= ws.estimate.error
    assert ws.estimate.unit == "m^3"
    sl = workspace_slice(ws, "z", 0.0)
    assert sl.axes == ("x", "y")
    assert abs(sl.estimate.value - _annulus(L1, L2)) <= sl.estimate.error
    rad = np.linalg.norm(sl.points, axis=1)
    assert rad.max() <= L1 + L2 + 1e-9


def test_spatial_constant_orientation_matches_target():
    """Constant-orientation samples of a 6R arm have the target orientation."""
    r = models.get("puma560")
    R_t = rpy_to_matrix([0.0, math.pi / 2, 0.3])
    ws = constant_orientation_workspace(r, R_t, 3000, seed=1, progress=False)
    assert ws.points.shape[0] > 1000
    ang = orientation_distance(r.fk(ws.q)[:, :3, :3], R_t)
    assert ang.max() <= 1e-4 + 1e-9
    assert r.within_limits(ws.q, tol=1e-12).all()


@settings(max_examples=25, deadline=None)
@given(st.floats(-math.pi, math.pi), st.floats(0.0, 0.8))
def test_project_orientation_reaches_cone(phi, max_angle):
    """Projection puts planar samples within max_angle of φ (3-link, unlimited joints)."""
    r = _planar(1.0, 0.7, 0.4)
    Q0 = r.random_q(200, seed=1)
    Q, ok = project_orientation(r, Q0, rotz(phi), max_angle=max_angle, planar=True)
    assert ok.all()
    d = np.abs((planar_angle(r.fk(Q)[:, :3, :3]) - phi + np.pi) % (2 * np.pi) - np.pi)
    assert d.max() <= max_angle + 1e-4


def test_bad_input():
    """Bad arguments raise InputError naming them."""
    r = _planar(1.0, 0.6)
    with pytest.raises(InputError, match="kind"):
        compute_workspace(r, "dexterity")
    with pytest.raises(InputError, match="max_angle"):
        inclusive_orientation_workspace(r, 0.0, 4.0, 100)
    with pytest.raises(InputError, match="orientation"):
        constant_orientation_workspace(r, np.ones((3, 3)), 100)
    with pytest.raises(InputError, match="samples"):
        reachable_workspace(r, 0)
    with pytest.raises(InputError, match="orientation"):
        constant_orientation_workspace(models.get("puma560"), 0.3, 100)
    with pytest.raises(InputError, match="spatial"):
        workspace_slice(reachable_workspace(r, 100, progress=False))
    with pytest.raises(InputError, match="needs orientation"):
        compute_workspace(r, "constant")


def test_progress_bar_only_when_asked(capsys):
    """progress=False prints nothing; progress=True draws a bar on stderr."""
    r = _planar(1.0, 0.6)
    reachable_workspace(r, 1000, progress=False)
    assert capsys.readouterr().err == ""
    reachable_workspace(r, 1000, progress=True)
    assert "workspace" in capsys.readouterr().err


def test_occupancy_grid_square():
    """Uniform points in a unit square: area 1 within the error; interior/boundary counts."""
    rng = np.random.default_rng(0)
    pts = rng.random((200_000, 2))
    g = occupancy_grid(pts, 0.02)
    est = g.measure()
    assert abs(est.value - 1.0) <= est.error
    assert est.n_interior + est.n_boundary == int(g.occupied.sum())
    assert est.unseen < 1.0
    lines = g.boundary()
    assert len(lines) == 1
    assert np.all(lines[0].min(axis=0) > -0.05) and np.all(lines[0].max(axis=0) < 1.05)


def test_planar_boundary_has_outer_and_inner_rims():
    """The annulus boundary has two closed curves near the radii L1+L2 and L1−L2."""
    ws = reachable_workspace(_planar(1.0, 0.6), 200_000, seed=0, progress=False)
    lines = ws.boundary()
    assert len(lines) == 2
    radii = sorted(float(np.linalg.norm(line, axis=1).mean()) for line in lines)
    h = ws.grid.cell
    assert abs(radii[0] - 0.4) < 2 * h and abs(radii[1] - 1.6) < 2 * h


@settings(max_examples=12, deadline=None)
@given(st.floats(0.1, 2.0), st.floats(0.1, 2.0), st.integers(0, 2**31 - 1),
       st.sampled_from([100_000, 250_000]))
def test_two_link_bound_holds_for_random_arms(L1, L2, seed, samples):
    """For random lengths, seeds and sample counts the stated bound contains the true area."""
    ws = reachable_workspace(_planar(L1, L2), samples, seed=seed, progress=False)
    assert abs(ws.estimate.value - _annulus(L1, L2)) <= ws.estimate.error
