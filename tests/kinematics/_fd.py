"""Finite-difference references and random DH tables shared by the kinematics tests."""

from __future__ import annotations

import numpy as np
from hypothesis import strategies as st

import serialkin as sk
from serialkin import models


def vee(W: np.ndarray) -> np.ndarray:
    """Axial vector of the skew-symmetric part of a 3x3 matrix."""
    S = 0.5 * (W - W.T)
    return np.array([S[2, 1], S[0, 2], S[1, 0]])


def fd_jacobian(pose_fn, q: np.ndarray, frame: str = "base", h: float = 1e-6) -> np.ndarray:
    """Central finite-difference Jacobian of a pose function q -> (4, 4).

    Linear rows: dp/dq. Angular rows: vee(dR/dq · Rᵀ) (frame 'base') or
    vee(Rᵀ · dR/dq) with the linear part rotated by Rᵀ (frame 'ee').
    """
    q = np.asarray(q, dtype=float)
    T = pose_fn(q)
    R = T[:3, :3]
    J = np.empty((6, q.size))
    for i in range(q.size):
        e = np.zeros(q.size)
        e[i] = h
        dT = (pose_fn(q + e) - pose_fn(q - e)) / (2 * h)
        if frame == "base":
            J[:3, i] = dT[:3, 3]
            J[3:, i] = vee(dT[:3, :3] @ R.T)
        else:
            J[:3, i] = R.T @ dT[:3, 3]
            J[3:, i] = vee(R.T @ dT[:3, :3])
    return J


def all_models() -> list[sk.Robot]:
    """Every built-in model (planar with 5 uneven links for the parametric entry)."""
    out = []
    for name in models.names():
        out.append(models.planar(5, [0.3, 0.5, 0.2, 0.4, 0.1]) if name == "planar"
                   else models.get(name))
    return out


MODEL_IDS = [m if m != "planar" else "planar5" for m in models.names()]

_length = st.floats(-1.0, 1.0, allow_nan=False)
_angle = st.floats(-np.pi, np.pi, allow_nan=False)


@st.composite
def dh_rows(draw, min_joints: int = 1, max_joints: int = 7) -> list[dict]:
    """Random DH tables: a, d in [-1, 1] m, α, θ in [-π, π], revolute or prismatic."""
    n = draw(st.integers(min_joints, max_joints))
    return [
        {"a": draw(_length), "alpha": draw(_angle), "d": draw(_length),
         "theta": draw(_angle), "type": draw(st.sampled_from(["R", "P"]))}
        for _ in range(n)
    ]


def random_transform(rng: np.random.Generator) -> np.ndarray:
    """A random rigid transform (rotation from a QR decomposition, translation in [-1, 1])."""
    Q, Rr = np.linalg.qr(rng.normal(size=(3, 3)))
    Q = Q * np.sign(np.diag(Rr))
    if np.linalg.det(Q) < 0:
        Q[:, 0] = -Q[:, 0]
    T = np.eye(4)
    T[:3, :3] = Q
    T[:3, 3] = rng.uniform(-1, 1, 3)
    return T
