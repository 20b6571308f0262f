"""Symbolic derivation (sympy) against the numeric kernels and the chapter's formulas."""

from __future__ import annotations

import numpy as np
import pytest
import sympy as sp
from hypothesis import given, settings
from hypothesis import strategies as st

import serialkin as sk
from serialkin import models
from serialkin.errors import InputError, InputTypeError
from serialkin.kinematics.symbolic import check_against, derive, exact
from tests.kinematics._fd import MODEL_IDS, all_models, dh_rows, random_transform

MODELS = all_models()
TOL = 1e-12


def _same(A, B) -> bool:
    """Exact symbolic equality of two matrices (trig expanded to sin/cos of single q)."""
    D = (sp.Matrix(A) - sp.Matrix(B)).applyfunc(lambda e: sp.expand(sp.expand_trig(e)))
    return D == sp.zeros(*D.shape)


@pytest.mark.parametrize("robot", MODELS, ids=MODEL_IDS)
def test_symbolic_matches_kernels_on_every_model(robot):
    """Lambdified symbolic T, geometric and position Jacobians equal fk/jacobian on random q."""
    kin = derive(robot, simplify=False)
    err = check_against(kin, robot, samples=4, seed=20)
    assert max(err.values()) < TOL, err


@pytest.mark.parametrize("name", ["two_link", "scara"])
def test_simplified_and_parametric_forms_match_kernels(name):
    """Simplified results with symbolic lengths, after substitution, equal the kernels."""
    robot = models.get(name)
    for params, simplify in (("lengths", True), ("all", False)):
        kin = derive(robot, params=params, simplify=simplify)
        err = check_against(kin, robot, samples=3, seed=21)
        assert max(err.values()) < TOL, (params, err)


def test_scara_transform_is_eq_18():
    """The simplified SCARA 0T4 has the chapter's position and a z axis pointing down."""
    kin = derive(models.scara(), params="lengths")
    L1, L2, d1, d3 = (sp.Symbol(s, real=True) for s in ("a_1", "a_2", "d_1", "d_3"))
    q1, q2, q3, q4 = kin.q
    kin = kin.subs({d3: sp.Symbol("d_2", real=True)})  # Table 1 calls the constant d2
    d2 = sp.Symbol("d_2", real=True)
    expected_p = sp.Matrix([L1 * sp.cos(q1) + L2 * sp.cos(q1 + q2),
                            L1 * sp.sin(q1) + L2 * sp.sin(q1 + q2), d1 + d2 + q3])
    assert _same(kin.position, expected_p)
    assert kin.T[2, 2] == -1
    assert _same([kin.T[0, 0]], [sp.cos(q1 + q2 - q4)])
    # link matrices are eqs 13-16
    A1, A2, A3, A4 = kin.A
    assert _same(A1[:3, 3], [L1 * sp.cos(q1), L1 * sp.sin(q1), d1])
    assert A3 == sp.Matrix([[1, 0, 0, 0], [0, -1, 0, 0], [0, 0, -1, d2 + q3], [0, 0, 0, 1]])
    assert _same(A4, [[sp.cos(q4), -sp.sin(q4), 0, 0], [sp.sin(q4), sp.cos(q4), 0, 0],
                      [0, 0, 1, 0], [0, 0, 0, 1]])


def test_three_link_analytical_jacobian_is_eq_32():
    """The symbolic ∂(x_E, y_E)/∂q of the 3-link arm is exactly eq 32's element list."""
    kin = derive(models.three_link(), params="lengths")
    L1, L2, L3 = (sp.Symbol(f"a_{i}", real=True) for i in (1, 2, 3))
    q1, q2, q3 = kin.q
    s, c = sp.sin, sp.cos
    eq32 = sp.Matrix([
        [-L1 * s(q1) - L2 * s(q1 + q2) - L3 * s(q1 + q2 + q3),
         -L2 * s(q1 + q2) - L3 * s(q1 + q2 + q3), -L3 * s(q1 + q2 + q3)],
        [L1 * c(q1) + L2 * c(q1 + q2) + L3 * c(q1 + q2 + q3),
         L2 * c(q1 + q2) + L3 * c(q1 + q2 + q3), L3 * c(q1 + q2 + q3)],
    ])
    assert _same(kin.jacobian("planar"), eq32)
    assert _same(kin.jacobian("planar_pose")[2, :], [[1, 1, 1]])


def test_two_link_geometric_jacobian_is_eq_38():
    """The symbolic geometric Jacobian of the 2-link arm (eq 37) simplifies to eq 38."""
    kin = derive(models.two_link(), params="lengths")
    L1, L2 = sp.Symbol("a_1", real=True), sp.Symbol("a_2", real=True)
    q1, q2 = kin.q
    eq38 = sp.Matrix([
        [-L1 * sp.sin(q1) - L2 * sp.sin(q1 + q2), -L2 * sp.sin(q1 + q2)],
        [L1 * sp.cos(q1) + L2 * sp.cos(q1 + q2), L2 * sp.cos(q1 + q2)],
        [0, 0], [0, 0], [0, 0], [1, 1],
    ])
    assert _same(kin.geometric_jacobian(), eq38)


@pytest.mark.slow
@settings(max_examples=6, deadline=None)
@given(rows=dh_rows(max_joints=4), convention=st.sampled_from(["standard", "modified"]),
       seed=st.integers(0, 2**32 - 1))
def test_random_dh_tables_symbolic_equals_numeric(rows, convention, seed):
    """Random DH tables (both conventions, R/P, random base and tool): symbolic == numeric."""
    rng = np.random.default_rng(seed)
    robot = sk.Robot.from_dh(rows, convention, base=random_transform(rng),
                             tool=random_transform(rng))
    kin = derive(robot, params="all", simplify=False)
    err = check_against(kin, robot, samples=2, seed=rng)
    assert max(err.values()) < 1e-11, err


def test_general_joint_robot():
    """A robot given as general joints (no DH table) derives to the same numeric pose."""
    panda = models.panda()
    robot = sk.Robot.from_joints(panda.joints, tool=panda.tool, name="panda-joints")
    kin = derive(robot, simplify=False)
    assert kin.convention is None
    err = check_against(kin, robot, samples=3, seed=22)
    assert max(err.values()) < TOL
    with pytest.raises(InputError, match="params"):
        derive(robot, params="lengths")


def test_printing():
    """LaTeX and text renderings contain the joint symbols and trigonometric functions."""
    kin = derive(models.two_link(), params="lengths")
    tex = kin.latex("T")
    assert r"\cos" in tex and "q_{1}" in tex
    assert r"\mathbf{A}_{2}" in kin.latex("A")
    assert "a_{2}" in kin.latex("jacobian")
    assert "cos" in kin.pretty()
    with pytest.raises(InputError, match="what"):
        kin.latex("nope")


def test_exact_numbers():
    """Simple constants become exact sympy numbers; others stay floats."""
    assert exact(np.pi / 2, angle=True) == sp.pi / 2
    assert exact(-np.pi, angle=True) == -sp.pi
    assert exact(0.5) == sp.Rational(1, 2)
    assert exact(1e-17) == 0
    assert isinstance(exact(0.4318), sp.Rational | sp.Float)
    assert float(exact(0.089159)) == pytest.approx(0.089159, abs=1e-15)


def test_bad_arguments():
    """The derive and lambdify functions name the bad argument."""
    with pytest.raises(InputTypeError, match="robot"):
        derive("ur5")
    with pytest.raises(InputError, match="params"):
        derive(models.two_link(), params="some")
    kin = derive(models.two_link(), params="lengths")
    with pytest.raises(InputError, match="task"):
        kin.jacobian("orientation")
    with pytest.raises(InputError, match="without numeric values"):
        kin.lambdify(sp.Matrix([sp.Symbol("zeta")]))
