"""serialkin.torch (issue 35): kernel values, analytic gradients, IK by implicit differentiation."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import serialkin as sk
from serialkin import models
from serialkin.errors import InputError, InputTypeError
from tests.autograd._support import gradient_robots, random_arm, require, well_conditioned_q
from tests.kinematics._fd import dh_rows, random_transform

torch = require("torch")
skt = require("serialkin.torch")

ROBOTS = gradient_robots()
IDS = [name for name, _ in ROBOTS]
ROBOT_LIST = [robot for _, robot in ROBOTS]


def _t(a: np.ndarray, grad: bool = True) -> torch.Tensor:
    return torch.tensor(a, dtype=torch.float64, requires_grad=grad)


def _pose(T0: np.ndarray, xi: torch.Tensor) -> torch.Tensor:
    """``T(ξ)``: position ``p0 + ξ[:3]`` and rotation ``expm([ξ[3:]]×) R0`` (dR = [δθ]× R)."""
    a, b, c = xi[3], xi[4], xi[5]
    z = torch.zeros((), dtype=xi.dtype)
    W = torch.stack([torch.stack([z, -c, b]), torch.stack([c, z, -a]),
                     torch.stack([-b, a, z])])
    T0t = torch.as_tensor(T0)
    top = torch.cat([torch.linalg.matrix_exp(W) @ T0t[:3, :3], (T0t[:3, 3] + xi[:3])[:, None]],
                    dim=1)
    return torch.cat([top, T0t[3:]], dim=0)


# ------------------------------------------------------------------------------ forward
@pytest.mark.parametrize("robot", ROBOT_LIST, ids=IDS)
def test_forward_equals_the_robot_bit_for_bit(robot):
    """In float64 fk and jacobian equal robot.fk and robot.jacobian exactly, batch shape kept."""
    Q = robot.random_q((2, 3), seed=0)
    T = skt.fk(robot, _t(Q, grad=False))
    J = skt.jacobian(robot, _t(Q, grad=False))
    assert T.shape == (2, 3, 4, 4) and J.shape == (2, 3, 6, robot.n)
    assert np.array_equal(T.numpy(), robot.fk(Q))
    assert np.array_equal(J.numpy(), robot.jacobian(Q))
    assert np.array_equal(skt.fk(robot, _t(Q[0, 0], grad=False)).numpy(), robot.fk(Q[0, 0]))


# ------------------------------------------------------------------------------ gradients
@pytest.mark.parametrize("robot", ROBOT_LIST, ids=IDS)
def test_fk_and_jacobian_pass_gradcheck(robot):
    """torch.autograd.gradcheck (float64) of fk and jacobian on a (2, 2, n) batch."""
    q = _t(robot.random_q((2, 2), seed=1))
    assert torch.autograd.gradcheck(lambda x: skt.fk(robot, x), (q,))
    assert torch.autograd.gradcheck(lambda x: skt.jacobian(robot, x), (q,))


@pytest.mark.parametrize("robot", ROBOT_LIST[:3], ids=IDS[:3])
def test_fk_is_twice_differentiable(robot):
    """Second derivatives of fk pass gradgradcheck (its backward runs the jacobian backward)."""
    q = _t(robot.random_q(2, seed=2))
    assert torch.autograd.gradgradcheck(lambda x: skt.fk(robot, x), (q,))


@settings(max_examples=12, deadline=None)
@given(rows=dh_rows(), convention=st.sampled_from(["standard", "modified"]),
       seed=st.integers(0, 2**32 - 1))
def test_random_dh_arms_pass_gradcheck(rows, convention, seed):
    """On random DH tables (R and P joints, both conventions, base and tool) both pass gradcheck."""
    rng = np.random.default_rng(seed)
    robot = sk.Robot.from_dh(rows, convention, base=random_transform(rng),
                             tool=random_transform(rng))
    q = _t(robot.random_q(2, seed=rng))
    assert torch.autograd.gradcheck(lambda x: skt.fk(robot, x), (q,))
    assert torch.autograd.gradcheck(lambda x: skt.jacobian(robot, x), (q,))


@pytest.mark.parametrize("robot", ROBOT_LIST, ids=IDS)
def test_jacobian_backward_is_the_hessian_contraction(robot):
    """The Jacobian's vector-Jacobian product equals Σ Ḡ[r, j] H[r, j, k] with robot.hessian."""
    Q = robot.random_q(5, seed=3)
    G = np.random.default_rng(4).normal(size=(5, 6, robot.n))
    q = _t(Q)
    skt.jacobian(robot, q).backward(torch.as_tensor(G))
    expected = np.einsum("brj,brjk->bk", G, robot.hessian(Q))
    np.testing.assert_allclose(q.grad.numpy(), expected, rtol=1e-12, atol=1e-12)


@pytest.mark.parametrize("robot", ROBOT_LIST, ids=IDS)
def test_fk_backward_is_the_jacobian_transpose_of_the_pose_twist(robot):
    """For L = ⟨Ḡ, T⟩ with Ḡ = [[ξ_θ]× R, ξ_p] (a twist's dT), ∂L/∂q = Jᵀ [ξ_p; 2ξ_θ]."""
    Q = robot.random_q(seed=5)
    T, J = robot.fk(Q), robot.jacobian(Q)
    xi = np.random.default_rng(6).normal(size=6)
    a, b, c = xi[3:]
    G = np.zeros((4, 4))
    G[:3, :3] = np.array([[0, -c, b], [c, 0, -a], [-b, a, 0]]) @ T[:3, :3]
    G[:3, 3] = xi[:3]
    q = _t(Q)
    skt.fk(robot, q).backward(torch.as_tensor(G))
    # ⟨[ξ]× R, [ω]× R⟩ = 2 ξ·ω for skew matrices: the angular rows count twice
    np.testing.assert_allclose(q.grad.numpy(), J.T @ np.r_[xi[:3], 2 * xi[3:]], atol=1e-12)


def test_float32_is_computed_in_float64_and_cast_back():
    """A float32 q gives float32 results equal to the float64 ones rounded, and float32 grads."""
    robot = models.get("panda")
    Q = robot.random_q((3, 2), seed=7).astype(np.float32)
    q = torch.tensor(Q, requires_grad=True)
    T = skt.fk(robot, q)
    assert T.dtype == torch.float32
    assert np.array_equal(T.detach().numpy(), robot.fk(Q.astype(np.float64)).astype(np.float32))
    T[..., :3, 3].sum().backward()
    assert q.grad.dtype == torch.float32
    q64 = _t(Q.astype(np.float64))
    skt.fk(robot, q64)[..., :3, 3].sum().backward()
    np.testing.assert_allclose(q.grad.numpy(), q64.grad.numpy(), rtol=1e-5, atol=1e-5)
    J = skt.jacobian(robot, torch.tensor(Q))
    assert J.dtype == torch.float32 and J.shape == (3, 2, 6, 7)


# ------------------------------------------------------------------------------ IK
IK_ROBOTS = [("ur5", models.get("ur5")), ("rrprrr", random_arm(2, "RRPRRR")),
             ("panda", models.get("panda"))]


@pytest.mark.parametrize(("robot", "method"), [(r, "pinv" if r.n > 6 else "lm")
                                               for _, r in IK_ROBOTS],
                         ids=[n for n, _ in IK_ROBOTS])
def test_ik_gradient_matches_finite_differences_of_resolved_ik(robot, method):
    """Away from singularities dq*/dξ matches central differences of re-solved IK to 1e-6.

    ξ is a twist of the target (``p0 + ξ_p``, ``expm([ξ_θ]×) R0``); IK re-solves from the
    solution (for the redundant Panda by 'pinv', whose steps give the minimum-norm change
    the backward documents).
    """
    for q_star in well_conditioned_q(robot, 2, seed=8):
        T0 = robot.fk(q_star)

        def solve(xi, q_star=q_star, T0=T0):
            sol = skt.ik(robot, _pose(T0, xi), q_star, method=method, tol=1e-13, seed=0,
                         restarts=0)
            assert bool(sol.success)
            return sol.q

        xi = torch.zeros(6, dtype=torch.float64, requires_grad=True)
        analytic = torch.autograd.functional.jacobian(solve, xi).numpy()
        h, numeric = 1e-6, np.empty((robot.n, 6))
        for k in range(6):
            e = torch.zeros(6, dtype=torch.float64)
            e[k] = h
            numeric[:, k] = ((solve(e) - solve(-e)) / (2 * h)).numpy()
        np.testing.assert_allclose(analytic, numeric, atol=1e-6)
        assert torch.autograd.gradcheck(solve, (xi,), eps=1e-6, atol=1e-6)


def test_ik_near_a_singularity_stays_finite_and_follows_the_damping():
    """At UR5's wrist singularity dq*/dξ is finite and equals Σ f(σ_i) v_i u_iᵀ, f ≤ 1/ε."""
    robot = models.get("ur5")
    q_star = np.array([0.3, -1.2, 1.4, -0.6, 1.1, 1e-4])  # q5 = 0: wrist axes 4 and 6 align
    q_star[4] = 1e-4
    T0 = robot.fk(q_star)
    for damping in (1e-2, 1e-1):
        def solve(xi, damping=damping):
            return skt.ik(robot, _pose(T0, xi), q_star, damping=damping, seed=0,
                          restarts=0).q

        D = torch.autograd.functional.jacobian(solve, torch.zeros(6, dtype=torch.float64))
        D = D.numpy()
        q_sol = solve(torch.zeros(6, dtype=torch.float64)).numpy()
        U, s, Vt = np.linalg.svd(robot.jacobian(q_sol))
        assert s.min() < damping  # the damped regime is exercised
        f = np.where(s >= damping, 1 / s, s / damping**2)
        assert np.all(np.isfinite(D))
        np.testing.assert_allclose(D, Vt.T @ np.diag(f) @ U.T, atol=1e-9)
        assert np.linalg.norm(D, 2) <= 1 / damping * (1 + 1e-9)


def test_ik_flags_rows_that_did_not_converge_and_keeps_batch_shapes():
    """A (2, 3) batch gives q (2, 3, n) and success (2, 3); the unreachable row is False."""
    robot = models.get("ur5")
    Q = robot.random_q((2, 3), seed=9)
    T = robot.fk(Q)
    T[1, 2, :3, 3] += 5.0  # far out of reach
    sol = skt.ik(robot, _t(T), Q + 0.01, seed=0, restarts=1)
    assert sol.q.shape == (2, 3, 6) and sol.success.shape == (2, 3)
    assert sol.success.dtype == torch.bool
    assert sol.success.tolist() == [[True, True, True], [True, True, False]]
    sol.q.sum().backward()  # the failed row still gets a finite (attempt) gradient


def test_ik_gradient_broadcasts_q0_and_sums_back_to_the_target_shape():
    """One (4, 4) target with a (3, n) batch of guesses: T.grad is (4, 4), the sum of the rows."""
    robot = models.get("ur5")
    q_star = well_conditioned_q(robot, 1, seed=10)[0]
    T = _t(robot.fk(q_star))
    sol = skt.ik(robot, T, np.stack([q_star] * 3) + 1e-3, seed=0)
    assert sol.q.shape == (3, 6)
    sol.q[:, 0].sum().backward()
    T1 = _t(robot.fk(q_star))
    skt.ik(robot, T1, q_star + 1e-3, seed=0).q[0].backward()
    np.testing.assert_allclose(T.grad.numpy(), 3 * T1.grad.numpy(), atol=1e-9)


# ------------------------------------------------------------------------------ errors
def test_bad_arguments_raise_the_librarys_errors_naming_them():
    """Non-tensors, integer tensors, wrong lengths, bad targets and damping are named."""
    robot = models.get("ur5")
    with pytest.raises(InputTypeError, match="q must be a torch.Tensor"):
        skt.fk(robot, np.zeros(6))
    with pytest.raises(InputTypeError, match="q must be a floating-point tensor"):
        skt.jacobian(robot, torch.zeros(6, dtype=torch.int64))
    with pytest.raises(InputError, match="q has 5 values"):
        skt.fk(robot, torch.zeros(5))
    with pytest.raises(InputTypeError, match="robot must be a serialkin Robot"):
        skt.fk("ur5", torch.zeros(6))
    with pytest.raises(InputError, match=r"T must have shape \(\.\.\., 4, 4\)"):
        skt.ik(robot, torch.zeros(3, 4), np.zeros(6))
    with pytest.raises(InputError, match="damping"):
        skt.ik(robot, torch.eye(4), np.zeros(6), damping=0.0)
    with pytest.raises(InputError, match="q0 must have shape"):
        skt.ik(robot, torch.eye(4), np.zeros(5))
