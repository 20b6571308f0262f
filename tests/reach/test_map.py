"""Reachability maps against closed-form workspaces and brute-force IK."""

from __future__ import annotations

import math
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from serialkin import models
from serialkin.models.planar import planar
from serialkin.reach import reachability_map, super_fibonacci
from serialkin.reach.orientations import approach_orientations, fibonacci_sphere

L1, L2, L3 = 1.0, 0.6, 0.3
SRC = str(Path(__file__).resolve().parents[2] / "src")


def _radii(m) -> np.ndarray:
    return np.linalg.norm(m.centres()[:, :2], axis=1)


def test_two_link_reachable_voxels_are_the_annulus():
    """2-link arm: a voxel is reached iff its centre lies in |L1−L2| ≤ ρ ≤ L1+L2."""
    m = reachability_map(planar(2, [L1, L2]), 0.05, progress=False)
    rho = _radii(m)
    inside = (rho >= abs(L1 - L2)) & (rho <= L1 + L2)
    clear = np.minimum(np.abs(rho - abs(L1 - L2)), np.abs(rho - (L1 + L2))) > 1e-9
    reached = m.reachable.reshape(-1)
    assert np.array_equal(reached[clear], inside[clear])
    # a position task has one "orientation": reached means fully reached
    assert np.array_equal(m.fully_reachable, m.reachable)
    assert m.orientations == 1 and inside.sum() > 500


def test_two_link_has_no_fully_reachable_voxel_with_headings():
    """2-link arm with heading targets: no voxel reaches every heading (no dexterous set)."""
    m = reachability_map(planar(2, [L1, L2]), 0.1, 8, task="planar_pose", progress=False)
    assert not m.fully_reachable.any()
    assert m.reached.max() <= 2  # at most the two elbow branches


@pytest.mark.parametrize("lengths", [(1.0, 0.8, 0.3), (1.0, 0.6, 0.5)])
def test_three_link_reachable_and_dexterous_sets(lengths):
    """3-link arm: reached voxels = the reachable annulus, fully reached = the dexterous set.

    Reachable: ρ ∈ [max(0, d − L3), L1+L2+L3], d = |L1−L2|; dexterous (every heading):
    ρ ∈ [d + L3, L1+L2−L3], plus the disc ρ ≤ L3 − d when L3 > d. Compared at voxels whose
    centre is farther than a voxel's half-diagonal from every boundary circle.
    """
    a, b, c = lengths
    d = abs(a - b)
    h = 0.08
    R = a + b + c + h  # one quadrant is enough: the sets are discs and annuli about 0
    m = reachability_map(planar(3, list(lengths)), h, 24, bounds=[[0, R], [0, R], [-1, 1]],
                         progress=False)
    rho = _radii(m)
    reach_in = (rho >= max(0.0, d - c)) & (rho <= a + b + c)
    dex = ((rho >= d + c) & (rho <= a + b - c)) | (rho <= c - d)
    circles = [max(0.0, d - c), a + b + c, d + c, a + b - c] + ([c - d] if c > d else [])
    clear = np.min(np.abs(rho[:, None] - np.array(circles)[None]), axis=1) > h * math.sqrt(0.5)
    assert np.array_equal(m.reachable.reshape(-1)[clear], reach_in[clear])
    assert np.array_equal(m.fully_reachable.reshape(-1)[clear], dex[clear])
    assert dex[clear].sum() > 10 and (reach_in & ~dex)[clear].sum() > 10


def test_three_link_numerical_solver_matches_closed_form():
    """The numerical batch IK reaches exactly the (voxel, heading) pairs ik_all reaches."""
    r = planar(3, [1.0, 0.8, 0.3])
    cf = reachability_map(r, 0.2, 12, solver="closed_form", progress=False)
    nu = reachability_map(r, 0.2, 12, solver="numerical", restarts=8, progress=False)
    assert np.array_equal(cf.reached, nu.reached)
    # one solution per reached heading numerically, up to two in closed form
    assert np.all(nu.solutions == nu.reached)
    assert np.all(cf.solutions >= cf.reached) and np.all(cf.solutions <= 2 * cf.reached)
    # the numerical solution is one of the closed-form ones (to its tolerance 1e-6)
    assert np.all(nu.manipulability_max <= cf.manipulability_max + 1e-5)


def test_ur5_coarse_map_matches_brute_force_ik_all():
    """UR5: per voxel, reached count, solutions and manipulability equal an ik_all loop."""
    r = models.get("ur5")
    N = 6
    m = reachability_map(r, 0.3, N, progress=False)
    assert m.settings["solver"] == "closed_form"
    R = super_fibonacci(N)
    P = m.centres()
    reached = np.zeros(len(P), dtype=int)
    sols = np.zeros(len(P), dtype=int)
    wmax = np.zeros(len(P))
    for i, p in enumerate(P):
        for k in range(N):
            T = np.eye(4)
            T[:3, :3], T[:3, 3] = R[k], p
            Q = r.ik_all(T)
            if len(Q):
                reached[i] += 1
                sols[i] += len(Q)
                wmax[i] = max(wmax[i], float(np.max(r.manipulability(Q))))
    assert np.array_equal(m.reached.reshape(-1), reached)
    assert np.array_equal(m.solutions.reshape(-1), sols)
    np.testing.assert_allclose(m.manipulability_max.reshape(-1), wmax, rtol=1e-12, atol=0)
    np.testing.assert_array_equal(m.index.reshape(-1), reached / N)
    assert 0 < reached.sum() < N * len(P)


def test_super_fibonacci_rotations_are_uniform():
    """Super-Fibonacci rotations are proper and their mean tends to the Haar mean 0."""
    R = super_fibonacci(2000)
    np.testing.assert_allclose(R @ R.transpose(0, 2, 1), np.broadcast_to(np.eye(3), R.shape),
                               atol=1e-12)
    np.testing.assert_allclose(np.linalg.det(R), 1.0, atol=1e-12)
    assert np.abs(R.mean(axis=0)).max() < 0.01
    # second moment of a Haar rotation: E[R_ij²] = 1/3
    np.testing.assert_allclose((R**2).mean(axis=0), np.full((3, 3), 1 / 3), atol=0.01)


def test_approach_orientations_point_along_the_directions():
    """Each approach rotation's z axis is its direction; rolls are evenly spaced about it."""
    D, K = 10, 4
    R = approach_orientations(D, K).reshape(D, K, 3, 3)
    z = fibonacci_sphere(D)
    np.testing.assert_allclose(R[:, :, :, 2], np.broadcast_to(z[:, None], (D, K, 3)),
                               atol=1e-12)
    cos = np.einsum("dki,dki->dk", R[:, 1:, :, 0], R[:, :-1, :, 0])
    np.testing.assert_allclose(cos, 0.0, atol=1e-12)  # 4 rolls: 90° apart
    np.testing.assert_allclose(np.linalg.det(R), 1.0, atol=1e-12)


@settings(max_examples=25, deadline=None)
@given(n=st.integers(1, 300), d=st.integers(1, 40), k=st.integers(1, 12))
def test_orientation_sets_are_rotations(n, d, k):
    """Any count gives proper rotations; approach sets have d·k distinct rotations."""
    for R in (super_fibonacci(n), approach_orientations(d, k)):
        np.testing.assert_allclose(R @ R.transpose(0, 2, 1),
                                   np.broadcast_to(np.eye(3), R.shape), atol=1e-12)
        np.testing.assert_allclose(np.linalg.det(R), 1.0, atol=1e-12)
    A = approach_orientations(d, k).reshape(d * k, 9)
    assert len(np.unique(np.round(A, 9), axis=0)) == d * k


def test_importing_reach_loads_neither_dask_nor_matplotlib():
    """`import serialkin.reach` imports no optional extra (Dask, matplotlib)."""
    code = ("import sys, serialkin, serialkin.reach; "
            "print(any(m.split('.')[0] in ('dask', 'distributed', 'matplotlib') "
            "for m in sys.modules))")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         env=dict(os.environ, PYTHONPATH=SRC), timeout=120)
    assert out.stdout.strip() == "False", out.stderr


def test_load_map_reads_an_output_folder(tmp_path):
    """load_map accepts the folder a run wrote as well as its map.npz."""
    from serialkin.reach import load_map, reachability_map

    arm = models.get("two_link")
    m = reachability_map(arm, 0.25, orientations=1, out=tmp_path / "run")
    for path in (tmp_path / "run", tmp_path / "run" / "map.npz"):
        assert np.array_equal(load_map(path).index, m.index)
