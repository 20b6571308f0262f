"""serialkin.jax (issue 35): custom_vjp functions through pure_callback, under jit and vmap."""

from __future__ import annotations

import numpy as np
import pytest

from serialkin import models
from serialkin.errors import InputError, InputTypeError
from tests.autograd._support import gradient_robots, require, well_conditioned_q

jax = require("jax")
jnp = require("jax.numpy")
skj = require("serialkin.jax")
from jax.test_util import check_grads  # noqa: E402

ROBOTS = gradient_robots()
IDS = [name for name, _ in ROBOTS]
ROBOT_LIST = [robot for _, robot in ROBOTS]


@pytest.fixture(autouse=True)
def x64():
    """Run each test with float64 enabled (JAX's default is float32)."""
    jax.config.update("jax_enable_x64", True)
    yield
    jax.config.update("jax_enable_x64", False)


@pytest.mark.parametrize("robot", ROBOT_LIST, ids=IDS)
def test_forward_equals_the_robot_bit_for_bit(robot):
    """In float64 fk and jacobian equal robot.fk and robot.jacobian exactly, batch shape kept."""
    Q = robot.random_q((2, 3), seed=0)
    T, J = skj.fk(robot, jnp.asarray(Q)), skj.jacobian(robot, jnp.asarray(Q))
    assert T.shape == (2, 3, 4, 4) and J.shape == (2, 3, 6, robot.n)
    assert np.array_equal(np.asarray(T), robot.fk(Q))
    assert np.array_equal(np.asarray(J), robot.jacobian(Q))
    assert np.array_equal(np.asarray(jax.jit(lambda q: skj.fk(robot, q))(Q)), robot.fk(Q))


@pytest.mark.parametrize("robot", ROBOT_LIST, ids=IDS)
def test_fk_and_jacobian_pass_check_grads(robot):
    """jax.test_util.check_grads (float64, reverse mode) of fk and jacobian on a (2, n) batch."""
    q = jnp.asarray(robot.random_q(2, seed=1))
    check_grads(lambda x: skj.fk(robot, x), (q,), order=1, modes=["rev"])
    check_grads(lambda x: skj.jacobian(robot, x), (q,), order=1, modes=["rev"])


@pytest.mark.parametrize("robot", ROBOT_LIST[:2], ids=IDS[:2])
def test_jit_and_vmap_agree_with_the_plain_batch(robot):
    """jit(vmap(grad)) per configuration equals grad of the summed batch loss, for fk and J."""
    Q = jnp.asarray(robot.random_q(5, seed=2))

    def loss(q):
        return jnp.sum(skj.fk(robot, q)[..., :3, 3] ** 2) + jnp.sum(skj.jacobian(robot, q) ** 2)

    per_row = jax.jit(jax.vmap(jax.grad(loss)))(Q)
    np.testing.assert_allclose(per_row, jax.grad(loss)(Q), rtol=1e-12, atol=1e-12)
    T = jax.vmap(lambda q: skj.fk(robot, q))(Q.reshape(5, 1, robot.n))
    assert np.array_equal(np.asarray(T)[:, 0], robot.fk(np.asarray(Q)))


def test_jax_and_torch_gradients_agree():
    """The JAX and the PyTorch backward (two implementations of one formula) give one gradient."""
    torch = require("torch")
    skt = require("serialkin.torch")
    robot = models.get("panda")
    Q = robot.random_q(4, seed=3)
    G = np.random.default_rng(4).normal(size=(4, 6, 7))
    gj = jax.grad(lambda q: jnp.sum(skj.jacobian(robot, q) * G))(jnp.asarray(Q))
    qt = torch.tensor(Q, requires_grad=True)
    (skt.jacobian(robot, qt) * torch.as_tensor(G)).sum().backward()
    np.testing.assert_allclose(np.asarray(gj), qt.grad.numpy(), rtol=1e-12, atol=1e-12)


def _pose(T0, xi):
    """``T(ξ)``: position ``p0 + ξ[:3]``, rotation ``cay([ξ[3:]]×) R0`` (dR = [δθ]× R at 0).

    The Cayley map ``(I − W/2)⁻¹ (I + W/2)`` is a rotation with expm's first derivative
    at 0, and compiles in a fraction of expm's time.
    """
    a, b, c = xi[3], xi[4], xi[5]
    W = jnp.array([[0.0, -c, b], [c, 0.0, -a], [-b, a, 0.0]])
    eye = jnp.eye(3)
    R = jnp.linalg.solve(eye - W / 2, eye + W / 2) @ T0[:3, :3]
    return jnp.eye(4).at[:3, :3].set(R).at[:3, 3].set(T0[:3, 3] + xi[:3])


def test_ik_gradient_matches_finite_differences_of_resolved_ik():
    """For UR5 away from singularities dq*/dξ matches central differences of re-solved IK (1e-6)."""
    robot = models.get("ur5")
    for q_star in well_conditioned_q(robot, 2, seed=5):
        T0 = jnp.asarray(robot.fk(q_star))

        @jax.jit
        def solve(xi, q_star=q_star, T0=T0):
            return skj.ik(robot, _pose(T0, xi), q_star, tol=1e-13, seed=0, restarts=0).q

        analytic = np.asarray(jax.jit(jax.jacrev(solve))(jnp.zeros(6)))
        h, numeric = 1e-6, np.empty((6, 6))
        for k in range(6):
            e = jnp.zeros(6).at[k].set(h)
            numeric[:, k] = (np.asarray(solve(e)) - np.asarray(solve(-e))) / (2 * h)
        np.testing.assert_allclose(analytic, numeric, atol=1e-6)


def test_ik_under_jit_and_vmap_flags_failures():
    """Under jit(vmap(...)) ik solves the batch and flags the unreachable row False."""
    robot = models.get("ur5")
    Q = robot.random_q(3, seed=6)
    T = robot.fk(Q)
    T[2, :3, 3] += 5.0
    run = jax.jit(jax.vmap(lambda T, q0: skj.ik(robot, T, q0, seed=0, restarts=1)))
    q, ok = run(jnp.asarray(T), jnp.asarray(Q + 0.01))
    assert q.shape == (3, 6) and ok.tolist() == [True, True, False]
    np.testing.assert_allclose(robot.fk(np.asarray(q[:2])), T[:2], atol=1e-9)
    g = jax.grad(lambda T: skj.ik(robot, T, Q + 0.01, seed=0, restarts=1).q.sum())(
        jnp.asarray(T))
    assert g.shape == (3, 4, 4) and bool(jnp.all(jnp.isfinite(g)))


def test_float32_without_x64():
    """With x64 off, float32 inputs give float32 poses equal to the float64 ones rounded."""
    jax.config.update("jax_enable_x64", False)
    robot = models.get("panda")
    Q = robot.random_q(3, seed=7).astype(np.float32)
    T = skj.fk(robot, jnp.asarray(Q))
    assert T.dtype == jnp.float32
    assert np.array_equal(np.asarray(T), robot.fk(Q.astype(np.float64)).astype(np.float32))
    g = jax.grad(lambda q: jnp.sum(skj.fk(robot, q)[..., :3, 3]))(jnp.asarray(Q))
    assert g.dtype == jnp.float32 and bool(jnp.all(jnp.isfinite(g)))


def test_bad_arguments_raise_the_librarys_errors_naming_them():
    """Integer arrays, wrong lengths, bad targets and a bad damping are named."""
    robot = models.get("ur5")
    with pytest.raises(InputTypeError, match="q must be a floating-point array"):
        skj.fk(robot, jnp.zeros(6, dtype=jnp.int32))
    with pytest.raises(InputError, match="robot 'UR5' has 6 joints"):
        skj.jacobian(robot, jnp.zeros(5))
    with pytest.raises(InputError, match=r"T must have shape \(\.\.\., 4, 4\)"):
        skj.ik(robot, jnp.zeros((3, 4)), np.zeros(6))
    with pytest.raises(InputError, match="damping"):
        skj.ik(robot, jnp.eye(4), np.zeros(6), damping=-1.0)
