"""The one internal chain representation that feeds every kernel.

:func:`compile_chain` turns joints in general form (:class:`~serialkin.model.joint.Joint`)
plus base and tool transforms into the arrays documented in
:mod:`serialkin.kinematics.kernels`. Standard DH, modified DH, general axes and URDF
all end here, so every algorithm serves every robot.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from serialkin.model.joint import JOINT_TYPES, Joint


@dataclass(frozen=True, eq=False)
class Chain:
    """Compiled chain arrays (read-only).

    Attributes:
        F: (n+1, 4, 4) fixed transforms between joint motions, base and tool included.
        L: (n+1, 4, 4) link-frame offsets (L[0] is the base).
        meta: (n, 5) axis x, y, z (always 0, 0, 1 after compilation), type (0 R, 1 P),
            offset.
        packed: (n+1, 4, 4) ``F`` with each joint's type and offset in the last row,
            ``packed[i, 3, :2] = (type_i, offset_i)`` (zeros for i = n): the one array the
            single-call kernels take.
    """

    F: np.ndarray
    L: np.ndarray
    meta: np.ndarray
    packed: np.ndarray

    @property
    def n(self) -> int:
        """Number of joints."""
        return self.meta.shape[0]

    def __setstate__(self, state: dict[str, np.ndarray]) -> None:
        """Unpickling keeps the arrays read-only (numpy's pickles restore them writeable)."""
        self.__dict__.update(state)
        for a in state.values():
            if isinstance(a, np.ndarray):
                a.setflags(write=False)


def z_alignment(axis: np.ndarray) -> np.ndarray:
    """A rotation ``R`` (3, 3) with ``R · e_z = axis`` (unit axis), the identity for +z.

    A motion about/along ``axis`` is then ``R · M_z(q) · Rᵀ``.
    """
    c = float(axis[2])
    if c < 0.0:  # through a half turn about x, keeping 1 + c away from 0
        H = np.diag([1.0, -1.0, -1.0])
        return H @ z_alignment(H @ axis)
    v = np.array([-axis[1], axis[0], 0.0])  # e_z × axis
    K = np.array([[0.0, -v[2], v[1]], [v[2], 0.0, -v[0]], [-v[1], v[0], 0.0]])
    return np.eye(3) + K + K @ K / (1.0 + c)


def compile_chain(joints: Sequence[Joint], base: np.ndarray, tool: np.ndarray) -> Chain:
    """Compile joints ``A_i = P_i·M_i·Q_i`` with base and tool into kernel arrays.

    ``T = base · Π_i (P_i · M_i(q_i) · Q_i) · tool`` (eq 11) is regrouped as
    ``F[0]·M_1·F[1]···M_n·F[n]`` with ``F[0] = base·P_1``, ``F[i] = Q_i·P_{i+1}`` and
    ``F[n] = Q_n·tool``. Every joint axis is then turned onto +z: with ``R_i`` from
    :func:`z_alignment`, ``M_i = R_i·M_z(q_i)·R_iᵀ``, so ``F[i-1]`` absorbs ``R_i`` on the
    right, ``F[i]`` and ``L[i]`` absorb ``R_iᵀ`` on the left, and every compiled axis is
    (0, 0, 1). The kernels therefore only rotate about / slide along z.
    """
    n = len(joints)
    F = np.empty((n + 1, 4, 4))
    L = np.empty((n + 1, 4, 4))
    meta = np.empty((n, 5))
    L[0] = base
    if n == 0:
        F[0] = base @ tool
    else:
        F[0] = base @ joints[0].origin
    for i, j in enumerate(joints):
        meta[i, :3] = j.axis
        meta[i, 3] = JOINT_TYPES[j.type]
        meta[i, 4] = j.offset
        L[i + 1] = j.post
        nxt = joints[i + 1].origin if i + 1 < n else tool
        F[i + 1] = j.post @ nxt
    for i, j in enumerate(joints):
        R = np.eye(4)
        R[:3, :3] = z_alignment(j.axis)
        F[i] = F[i] @ R
        F[i + 1] = R.T @ F[i + 1]
        L[i + 1] = R.T @ L[i + 1]
        meta[i, :3] = (0.0, 0.0, 1.0)
    packed = F.copy()
    packed[:, 3, :] = 0.0
    packed[:n, 3, 0] = meta[:, 3]
    packed[:n, 3, 1] = meta[:, 4]
    for a in (F, L, meta, packed):
        a.setflags(write=False)
    return Chain(F=F, L=L, meta=meta, packed=packed)
