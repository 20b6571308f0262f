"""DH extraction from general chains reproduces forward kinematics, in both conventions."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import serialkin as sk
from serialkin.model.dh_extract import common_normal, extract_dh, to_dh_robot
from tests.erd import urdf

angles = st.floats(-np.pi, np.pi)
# extract_dh treats features below model.dh_extract._EPS (1e-9 m) as exactly zero, so a length
# drawn at that scale is ambiguous by construction: lengths are exactly 0 or at least 1 µm.
lengths = st.floats(1e-6, 0.5) | st.floats(-0.5, -1e-6)
special_alpha = st.sampled_from([0.0, np.pi / 2, -np.pi / 2, np.pi])


@st.composite
def dh_tables(draw):
    """Random DH tables with revolute/prismatic joints, including parallel/intersecting axes."""
    n = draw(st.integers(1, 6))
    rows = []
    for _ in range(n):
        rows.append(dict(
            a=draw(st.one_of(st.just(0.0), lengths)),
            alpha=draw(st.one_of(special_alpha, angles)),
            d=draw(st.one_of(st.just(0.0), lengths)),
            theta=draw(st.one_of(st.just(0.0), angles)),
            type=draw(st.sampled_from(["R", "R", "P"])),
        ))
    return rows


@settings(max_examples=40, deadline=None)
@given(dh_tables(), st.sampled_from(["standard", "modified"]),
       st.sampled_from(["standard", "modified"]))
def test_extracted_dh_reproduces_fk(rows, source_conv, target_conv):
    """For random DH robots (any convention), extract_dh in either convention gives the same FK."""
    base = sk.spatial.trotz(0.3) @ sk.spatial.transl(0.1, 0, 0)
    r = sk.Robot.from_dh(rows, source_conv, base=base, tool=sk.spatial.troty(0.2))
    d = to_dh_robot(r, target_conv)
    assert d.convention == target_conv and d.dh is not None
    Q = r.random_q(10, seed=1)
    np.testing.assert_allclose(d.fk(Q), r.fk(Q), atol=1e-9)


def test_general_axes_robot():
    """A robot from general joint axes (skew, not DH-aligned) gets an exact DH table."""
    rng = np.random.default_rng(0)
    joints = []
    for i in range(5):
        axis = rng.normal(size=3)
        R = sk.spatial.rotx(rng.normal()) @ sk.spatial.rotz(rng.normal())
        origin = sk.spatial.make_transform(R, rng.normal(size=3) * 0.2)
        joints.append(sk.Joint(axis=axis, type="P" if i == 2 else "R", origin=origin,
                               offset=rng.normal() * 0.1))
    r = sk.Robot.from_joints(joints)
    for conv in ("standard", "modified"):
        rows, base, tool = extract_dh(r, conv)
        d = sk.Robot.from_dh(rows, conv, base=base, tool=tool)
        Q = r.random_q(10, seed=2)
        np.testing.assert_allclose(d.fk(Q), r.fk(Q), atol=1e-9)


def test_common_normal_cases():
    """Skew, intersecting, parallel and coincident lines give the expected feet and direction."""
    z = np.array([0.0, 0.0, 1.0])
    x = np.array([1.0, 0.0, 0.0])
    c1, c2, n = common_normal(np.zeros(3), z, np.array([0, 1.0, 5.0]), x, np.zeros(3))
    np.testing.assert_allclose(c1, [0, 0, 5])
    np.testing.assert_allclose(c2, [0, 1, 5])
    np.testing.assert_allclose(n, [0, 1, 0])
    c1, c2, n = common_normal(np.zeros(3), z, np.array([0, 0, 2.0]), x, np.zeros(3))
    np.testing.assert_allclose(c1, c2)
    np.testing.assert_allclose(np.abs(n), [0, 1, 0])
    c1, c2, n = common_normal(np.zeros(3), z, np.array([2.0, 0, 7]), z, np.array([0, 0, 3.0]))
    np.testing.assert_allclose(c1, [0, 0, 3])
    np.testing.assert_allclose(c2, [2, 0, 3])
    _, _, n = common_normal(np.zeros(3), z, np.array([0, 0, 7.0]), -z, np.zeros(3))
    assert n is None


@pytest.mark.peer
@pytest.mark.parametrize(("rel", "tip"), [("ur_description/urdf/ur5_robot.urdf", "tool0"),
                                          ("panda_description/urdf/panda.urdf", "panda_hand")])
def test_real_robots_dh(rel, tip):
    """The extracted DH of the real UR5 and Panda URDFs reproduces the URDF's FK."""
    path = urdf(rel)
    if path is None:
        pytest.skip("example-robot-data is not installed (pip install -e '.[bench]')")
    r = sk.Robot.from_urdf(str(path), tip_link=tip)
    for conv in ("standard", "modified"):
        d = to_dh_robot(r, conv)
        Q = r.random_q(50, seed=5)
        np.testing.assert_allclose(d.fk(Q), r.fk(Q), atol=1e-10)
    # UR5: the published standard DH link lengths appear in the extracted table
    if "ur5" in rel:
        a = sorted(abs(row.a) for row in to_dh_robot(r, "standard").dh)
        np.testing.assert_allclose(a[-2:], [0.39225, 0.425], atol=1e-9)
