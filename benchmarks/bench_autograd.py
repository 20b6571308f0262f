"""Differentiable kinematics (issue 35): serialkin.torch and serialkin.jax against their peers.

Rows (median and spread of interleaved repeats, float32 as learning code runs it; 4,096
Panda configurations on the CPU):

* FK + backward: ``serialkin.torch.fk`` then ``backward`` of ``⟨Ḡ, T⟩``, against
  pytorch_kinematics 0.10 (its serial chain built from ``robot.to_urdf()``);
* Jacobian + backward: ``serialkin.torch.jacobian``, the same against
  ``chain.jacobian``;
* JAX ``jit``-ted FK + grad: ``serialkin.jax.fk`` against a pure-JAX FK of the same chain
  (``T = F0·M1(q1)·F1···Mn(qn)·Fn`` of :mod:`serialkin.model.chain`, below), both under
  ``jax.jit(jax.value_and_grad(...))``.

Each peer's values are checked against serialkin's before timing. The torch rows run with
one torch intra-op thread and with one per CPU: on a small machine torch's thread pool
and the kernels' (numba's) compete for the cores, and the loss's own elementwise
operations, the same on both sides, slow down by tens of milliseconds under load; the
ratio compares the best median of each library. Needs the extras
``torch``, ``jax`` and ``autograd-bench`` (``make test-autograd`` installs them); a missing
one leaves its rows "not measured".

Usage: ``python benchmarks/bench_autograd.py`` (``make bench`` runs it).
"""

from __future__ import annotations

import os
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _common import Stat, header, record  # noqa: E402

from serialkin import models  # noqa: E402

N = 4096
REPEAT = 11


def _interleaved_ms(fns: dict, repeat: int = REPEAT) -> dict[str, Stat]:
    """Milliseconds per call of each function, runs interleaved (one warm-up call each)."""
    import time

    for f in fns.values():
        f()
    runs: dict[str, list[float]] = {k: [] for k in fns}
    for _ in range(repeat):
        for k, f in fns.items():
            t0 = time.perf_counter()
            f()
            runs[k].append((time.perf_counter() - t0) * 1e3)
    return {k: Stat(v) for k, v in runs.items()}


def _row(name: str, ms: Stat) -> None:
    print(f"{name:62s} {ms.fmt(3):>26s}")


def torch_rows(robot, Q: np.ndarray) -> None:
    """FK + backward and Jacobian + backward: serialkin.torch vs pytorch_kinematics."""
    try:
        import pytorch_kinematics as pk
        import torch
    except ImportError as exc:
        print(f"torch rows not measured: {exc} (make test-autograd installs the extras)")
        return
    from serialkin import torch as skt

    urdf = robot.to_urdf().encode()
    chain = pk.build_serial_chain_from_urdf(urdf, "tool").to(dtype=torch.float32)
    q = torch.tensor(Q, dtype=torch.float32, requires_grad=True)
    rng = np.random.default_rng(0)
    GT = torch.tensor(rng.normal(size=(N, 4, 4)), dtype=torch.float32)
    GJ = torch.tensor(rng.normal(size=(N, 6, robot.n)), dtype=torch.float32)
    Tp = chain.forward_kinematics(q).get_matrix()
    Jp = chain.jacobian(q)
    dT = float((Tp - skt.fk(robot, q)).abs().max().detach())
    dJ = float((Jp - skt.jacobian(robot, q)).abs().max().detach())
    print(f"pytorch_kinematics {pk.__version__ if hasattr(pk, '__version__') else '0.10'}, "
          f"torch {torch.__version__}: max |ΔT| {dT:.1e}, max |ΔJ| {dJ:.1e} (float32)")
    assert dT < 1e-4 and dJ < 1e-4, "the peer's chain differs from serialkin's"

    def step(f, G):
        def run():
            q.grad = None
            (f(q) * G).sum().backward()
        return run

    default_threads = torch.get_num_threads()
    for what, ours, peer, G in (
            ("FK + backward", lambda x: skt.fk(robot, x),
             lambda x: chain.forward_kinematics(x).get_matrix(), GT),
            ("Jacobian + backward", lambda x: skt.jacobian(robot, x), chain.jacobian, GJ)):
        best: dict[str, Stat] = {}
        for threads in sorted({1, os.cpu_count() or 1}):
            torch.set_num_threads(threads)
            st = _interleaved_ms({"serialkin": step(ours, G), "peer": step(peer, G)})
            for who, name in (("serialkin", "serialkin.torch"), ("peer", "pytorch_kinematics")):
                _row(f"{what}, {N} Panda, {name}, {threads} torch thr. [ms]", st[who])
                if who not in best or st[who].median < best[who].median:
                    best[who] = st[who]
        torch.set_num_threads(default_threads)
        ratio = best["peer"] / best["serialkin"]
        print(f"{'  ratio pytorch_kinematics / serialkin (best of each)':62s} {ratio:>26.1f}")
        record("35.1" if what.startswith("FK") else "35.2",
               f"{what}, {N} Panda float32: pytorch_kinematics / serialkin.torch",
               ratio, "x", ">= 5", ratio >= 5.0)


def pure_jax_fk(robot):
    """FK of robot's chain in jax.numpy: ``T = F0·M1(q1)·F1···Mn(qn)·Fn`` (batch (..., n)).

    ``M_i`` is a rotation about z (revolute, meta type 0) or a translation along z
    (prismatic) by ``q_i + offset_i``; a rotation only mixes T's first two columns.
    """
    import jax.numpy as jnp

    F = np.asarray(robot.chain.F)
    kind, offset = np.asarray(robot.chain.meta[:, 3]), np.asarray(robot.chain.meta[:, 4])

    def fk(q):
        T = jnp.broadcast_to(jnp.asarray(F[0], q.dtype), q.shape[:-1] + (4, 4))
        for i in range(robot.n):
            x = q[..., i] + offset[i]
            if kind[i] == 0:
                c, s = jnp.cos(x)[..., None], jnp.sin(x)[..., None]
                a, b = T[..., :, 0], T[..., :, 1]
                T = jnp.stack([c * a + s * b, c * b - s * a, T[..., :, 2], T[..., :, 3]], -1)
            else:
                T = T.at[..., :, 3].add(x[..., None] * T[..., :, 2])
            T = T @ jnp.asarray(F[i + 1], q.dtype)
        return T

    return fk


def jax_rows(robot, Q: np.ndarray) -> None:
    """jit(value_and_grad) of an FK loss: serialkin.jax vs the pure-JAX chain."""
    try:
        import jax
        import jax.numpy as jnp
    except ImportError as exc:
        print(f"JAX rows not measured: {exc} (make test-autograd installs the extras)")
        return
    from serialkin import jax as skj

    G = jnp.asarray(np.random.default_rng(1).normal(size=(N, 4, 4)), jnp.float32)
    q = jnp.asarray(Q, jnp.float32)
    ref = pure_jax_fk(robot)
    dT = float(jnp.abs(ref(q) - skj.fk(robot, q)).max())
    print(f"jax {jax.__version__}: pure-JAX chain vs serialkin.jax max |ΔT| {dT:.1e} (float32)")
    assert dT < 1e-4
    ours = jax.jit(jax.value_and_grad(lambda x: jnp.sum(skj.fk(robot, x) * G)))
    peer = jax.jit(jax.value_and_grad(lambda x: jnp.sum(ref(x) * G)))
    gap = float(jnp.abs(ours(q)[1] - peer(q)[1]).max())
    print(f"  gradients agree to {gap:.1e}")

    def run(f):
        return lambda: jax.block_until_ready(f(q))

    st = _interleaved_ms({"serialkin": run(ours), "peer": run(peer)})
    ratio = st["peer"] / st["serialkin"]
    _row(f"JAX jit FK + grad, {N} Panda, serialkin.jax [ms]", st["serialkin"])
    _row(f"JAX jit FK + grad, {N} Panda, pure-JAX chain [ms]", st["peer"])
    print(f"{'  ratio pure JAX / serialkin':62s} {ratio:>26.2f}")
    record("35.3", f"JAX jit FK + grad, {N} Panda float32: pure JAX / serialkin.jax",
           ratio, "x", ">= 1", ratio >= 1.0)


def main() -> None:
    """Print the table and record the goals' rows."""
    print(header())
    robot = models.get("panda")
    Q = robot.random_q(N, seed=0)
    print(f"{'row':62s} {'median [spread] ms':>26s}")
    torch_rows(robot, Q)
    jax_rows(robot, Q)


if __name__ == "__main__":
    main()
