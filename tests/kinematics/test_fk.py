"""Forward kinematics (chapter section 3): the SCARA example, frames, batches and peers."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import serialkin as sk
from serialkin import models
from serialkin.model.dh import link_transform, parse_dh_rows
from tests.kinematics._fd import MODEL_IDS, all_models, dh_rows, random_transform

MODELS = all_models()


def _Rz(t):
    c, s = np.cos(t), np.sin(t)
    return np.array([[c, -s, 0, 0], [s, c, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1.0]])


def _T(x=0.0, y=0.0, z=0.0):
    T = np.eye(4)
    T[:3, 3] = [x, y, z]
    return T


def _chapter_scara_transforms(d1, d2, L1, L2, q):
    """The SCARA link matrices exactly as printed in eqs 13-16 (multiplied-out forms)."""
    q1, q2, q3, q4 = q
    c1, s1, c2, s2 = np.cos(q1), np.sin(q1), np.cos(q2), np.sin(q2)
    A1 = np.array([[c1, -s1, 0, L1 * c1], [s1, c1, 0, L1 * s1], [0, 0, 1, d1], [0, 0, 0, 1]])
    A2 = np.array([[c2, -s2, 0, L2 * c2], [s2, c2, 0, L2 * s2], [0, 0, 1, 0], [0, 0, 0, 1]])
    A3 = np.array([[1, 0, 0, 0], [0, np.cos(np.pi), -np.sin(np.pi), 0],
                   [0, np.sin(np.pi), np.cos(np.pi), d2 + q3], [0, 0, 0, 1]])
    A4 = _Rz(q4)
    return A1, A2, A3, A4


_len = st.floats(0.05, 1.0)


@settings(max_examples=40, deadline=None)
@given(d1=_len, d2=st.floats(-0.5, 0.5), L1=_len, L2=_len, seed=st.integers(0, 2**32 - 1))
def test_scara_matches_chapter_eqs_13_to_18(d1, d2, L1, L2, seed):
    """SCARA fk equals 0A1·1A2·2A3·3A4 of eqs 13-16 (eq 17 as corrected in the ERRATA)."""
    robot = models.scara(d1=d1, d2=d2, l1=L1, l2=L2, q3_range=(-1.0, 1.0))
    q = robot.random_q(seed=seed)
    A1, A2, A3, A4 = _chapter_scara_transforms(d1, d2, L1, L2, q)
    np.testing.assert_allclose(A1, _T(z=d1) @ _Rz(q[0]) @ _T(x=L1), atol=1e-14)  # eq 13
    np.testing.assert_allclose(A2, _Rz(q[1]) @ _T(x=L2), atol=1e-14)  # eqs 14-15
    T = A1 @ A2 @ A3 @ A4  # eq 17 (corrected)
    np.testing.assert_allclose(robot.fk(q), T, atol=1e-12)
    # eq 18: position of the end-effector
    p = [L1 * np.cos(q[0]) + L2 * np.cos(q[0] + q[1]),
         L1 * np.sin(q[0]) + L2 * np.sin(q[0] + q[1]), d1 + d2 + q[2]]
    np.testing.assert_allclose(robot.fk(q)[:3, 3], p, atol=1e-12)
    # every link matrix is the DH formula of its Table 1 row
    for A, row, qi in zip((A1, A2, A3, A4), robot.dh, q):
        np.testing.assert_allclose(link_transform(row, qi), A, atol=1e-12)


def test_scara_misprinted_eq_17_differs():
    """The printed eq 17 (0A2 in place of 0A1) is not the SCARA pose: the ERRATA matters."""
    robot = models.scara()
    q = np.array([0.3, -0.7, -0.1, 0.4])
    A1, A2, A3, A4 = _chapter_scara_transforms(0.4, 0.1, 0.35, 0.30, q)
    misprint = (A1 @ A2) @ A2 @ A3 @ A4
    assert not np.allclose(robot.fk(q), misprint, atol=1e-6)
    np.testing.assert_allclose(robot.fk(q), A1 @ A2 @ A3 @ A4, atol=1e-12)


@settings(max_examples=30, deadline=None)
@given(lengths=st.lists(st.floats(0.01, 2.0), min_size=2, max_size=3),
       seed=st.integers(0, 2**32 - 1))
def test_planar_closed_form_eqs_21_22_30_31(lengths, seed):
    """Planar 2- and 3-link tool positions equal eqs 21-22 and 30-31, z = 0, heading Σq."""
    robot = models.planar(len(lengths), lengths)
    q = robot.random_q(seed=seed)
    cum = np.cumsum(q)
    x = sum(L * np.cos(c) for L, c in zip(lengths, cum))
    y = sum(L * np.sin(c) for L, c in zip(lengths, cum))
    T = robot.fk(q)
    np.testing.assert_allclose(T[:3, 3], [x, y, 0.0], atol=1e-12)
    np.testing.assert_allclose(T[:3, :3], _Rz(cum[-1])[:3, :3], atol=1e-12)


@pytest.mark.parametrize("robot", MODELS, ids=MODEL_IDS)
def test_rotation_is_orthonormal_eq_7(robot):
    """Every tool and link rotation satisfies RᵀR = I and det R = 1 (eq 7)."""
    q = robot.random_q(64, seed=1)
    R = robot.fk(q)[:, :3, :3]
    np.testing.assert_allclose(np.swapaxes(R, -1, -2) @ R, np.broadcast_to(np.eye(3), R.shape),
                               atol=1e-12)
    np.testing.assert_allclose(np.linalg.det(R), 1.0, atol=1e-12)
    F = robot.fk_all(q)
    np.testing.assert_allclose(np.linalg.det(F[..., :3, :3]), 1.0, atol=1e-12)
    np.testing.assert_array_equal(robot.fk(q)[:, 3], np.broadcast_to([0, 0, 0, 1.0], (64, 4)))


@pytest.mark.parametrize("robot", MODELS, ids=MODEL_IDS)
def test_fk_all_is_product_of_link_transforms(robot):
    """fk_all frame i is base · A_1 ··· A_i with A from the DH formula (eq 11); fk adds the tool."""
    for q in robot.random_q(5, seed=2):
        frames = robot.fk_all(q)
        T = robot.base.copy()
        np.testing.assert_allclose(frames[0], T, atol=1e-14)
        for i, row in enumerate(robot.dh):
            T = T @ link_transform(row, q[i], robot.convention)
            np.testing.assert_allclose(frames[i + 1], T, atol=1e-12)
        np.testing.assert_allclose(robot.fk(q), T @ robot.tool, atol=1e-12)


@settings(max_examples=40, deadline=None)
@given(rows=dh_rows(), convention=st.sampled_from(["standard", "modified"]),
       seed=st.integers(0, 2**32 - 1))
def test_random_dh_fk_is_product_of_link_transforms(rows, convention, seed):
    """On random DH tables (both conventions, R and P joints, base and tool) fk is eq 11."""
    rng = np.random.default_rng(seed)
    base, tool = random_transform(rng), random_transform(rng)
    robot = sk.Robot.from_dh(rows, convention, base=base, tool=tool)
    q = robot.random_q(seed=rng)
    T = base.copy()
    frames = robot.fk_all(q)
    for i, row in enumerate(parse_dh_rows(rows)):
        T = T @ link_transform(row, q[i], convention)
        np.testing.assert_allclose(frames[i + 1], T, atol=1e-12)
    np.testing.assert_allclose(robot.fk(q), T @ tool, atol=1e-12)


@pytest.mark.parametrize("robot", MODELS, ids=MODEL_IDS)
def test_batch_equals_single(robot):
    """The fk and fk_all results on a (3, 4, n) batch equal the single calls, element by element."""
    Q = robot.random_q((3, 4), seed=3)
    T = robot.fk(Q)
    F = robot.fk_all(Q)
    assert T.shape == (3, 4, 4, 4)
    assert F.shape == (3, 4, robot.n + 1, 4, 4)
    for idx in np.ndindex(3, 4):
        np.testing.assert_array_equal(T[idx], robot.fk(Q[idx]))
        np.testing.assert_allclose(F[idx], robot.fk_all(Q[idx]), atol=1e-15)
    np.testing.assert_array_equal(robot.fk(list(Q[0, 0])), T[0, 0])
    assert robot.fk(Q[0, :0]).shape == (0, 4, 4)


def test_base_and_tool_compose():
    """with_base/with_tool give base · fk · tool for any rigid base and tool."""
    rng = np.random.default_rng(4)
    robot = models.ur5()
    B, E = random_transform(rng), random_transform(rng)
    moved = robot.with_base(B).with_tool(E)
    for q in robot.random_q(5, seed=rng):
        np.testing.assert_allclose(moved.fk(q), B @ robot.fk(q) @ E, atol=1e-12)


@pytest.mark.parametrize(
    ("name", "q", "expected"),
    [
        # Values read off the published tables at q = 0.
        ("puma560", np.zeros(6), [0.4318 + 0.0203, -0.15005, 26.45 * 0.0254 + 0.4318]),
        ("ur5", np.zeros(6), [-0.425 - 0.39225, -0.10915 - 0.0823, 0.089159 - 0.09465]),
        ("iiwa7", np.zeros(7), [0.0, 0.0, 0.340 + 0.400 + 0.400 + 0.126]),
        ("panda", np.zeros(7), [0.088, 0.0, 0.333 + 0.316 + 0.384 - 0.107]),
        ("stanford", np.array([0, 0, 0.5, 0, 0, 0]), [0.0, 0.154 - 0.0203, 0.412 + 0.5 + 0.263]),
    ],
)
def test_reference_positions(name, q, expected):
    """Tool positions at simple configurations equal the sums read from the DH tables."""
    np.testing.assert_allclose(models.get(name).fk(q)[:3, 3], expected, atol=1e-12)


# ---------------------------------------------------------------------------- peers
def _rtb_models():
    rtb = pytest.importorskip("roboticstoolbox")
    from spatialmath import SE3

    panda = rtb.models.DH.Panda()
    panda.tool = SE3()  # compare at the flange: serialkin's panda() ends there
    ur5 = rtb.models.DH.UR5()
    ur5.links[0].d = 0.089159  # UR's published d1 (the toolbox has 0.089459)
    stanford = rtb.models.DH.Stanford()
    stanford.links[5].d = 0.263  # flange offset of the MATLAB toolbox and Paul (1981)
    return {"puma560": rtb.models.DH.Puma560(), "panda": panda, "ur5": ur5,
            "stanford": stanford}


@pytest.mark.peer
@pytest.mark.parametrize("name", ["puma560", "panda", "ur5", "stanford"])
def test_fk_matches_robotics_toolbox(name):
    """The tool pose equals Robotics Toolbox's DH model fkine on random configurations."""
    peer = _rtb_models()[name]
    robot = models.get(name)
    for q in robot.random_q(10, seed=5):
        np.testing.assert_allclose(robot.fk(q), peer.fkine(q).A, atol=1e-12)


@pytest.mark.peer
def test_panda_and_ur5_match_manufacturer_urdfs_in_pinocchio():
    """Panda fk equals panda_link8 (flange) and UR5 fk equals Rz(π)·tool0 of the URDFs."""
    pin = pytest.importorskip("pinocchio")
    from tests.erd import urdf

    cases = [("panda", "panda_description/urdf/panda.urdf", "panda_link8", np.eye(4)),
             ("ur5", "ur_description/urdf/ur5_robot.urdf", "tool0", np.diag([-1, -1, 1, 1.0]))]
    for name, rel, frame, world_from_urdf in cases:
        path = urdf(rel)
        if path is None:
            pytest.skip(f"example-robot-data does not ship {rel}")
        model = pin.buildModelFromUrdf(str(path))
        data = model.createData()
        fid = model.getFrameId(frame)
        robot = models.get(name)
        for q in robot.random_q(10, seed=6):
            qq = np.concatenate([q, np.zeros(model.nq - robot.n)])  # Panda: finger joints
            pin.framesForwardKinematics(model, data, qq)
            T = world_from_urdf @ data.oMf[fid].homogeneous
            np.testing.assert_allclose(robot.fk(q), T, atol=1e-9)
