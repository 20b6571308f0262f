"""Compiled kernels over the chain representation (numba, ``cache=True``).

Kernel contract: trusts its input; validation happens at the public boundary (the
:class:`~serialkin.model.robot.Robot` methods). Other subpackages call these kernels
with the arrays of ``robot.chain``.

Every robot, whatever convention it was described in (standard DH, modified DH,
general joint axes, URDF), is compiled by :mod:`serialkin.model.chain` into the same
arrays, and these kernels are the only implementation of forward kinematics and
Jacobians in serialkin. IK solvers, redundancy resolution and workspace sampling call
them too.

The chain arrays, for a robot with ``n`` joints:

``F`` (n+1, 4, 4)
    Fixed transforms between joint motions: the end-effector pose is
    ``T = F[0] · M_1(q_1) · F[1] · M_2(q_2) · ... · M_n(q_n) · F[n]`` (eq 11), where
    ``F[0]`` includes the base transform and ``F[n]`` the tool transform.
``L`` (n+1, 4, 4)
    Link-frame offsets: frame 0 is ``L[0]`` (the base), link frame *i* is the pose right
    after ``M_i`` times ``L[i]``. For a standard-DH robot these are the DH frames.
``meta`` (n, 5)
    Per joint: unit axis (x, y, z) in the joint frame — always (0, 0, 1), because
    :func:`~serialkin.model.chain.compile_chain` turns every axis onto z —, type
    (0 revolute, 1 prismatic), offset added to the joint variable.

``M_i(q)`` is a rotation by ``q + offset`` about z (revolute) or a translation by
``q + offset`` along z (prismatic). Kernels trust their input: validation happens in
the Python wrappers. All arrays are float64, C-contiguous.
"""

from __future__ import annotations

import math

import numpy as np

from .._jit import as_readonly, fma, njit

REVOLUTE = 0
PRISMATIC = 1


@njit(cache=True, hot=True, forceinline=True)
def _post_multiply(T, A):
    """T ← T · A for rigid transforms (last rows [0 0 0 1]), in place, no allocation."""
    for r in range(3):
        T[r, 0], T[r, 1], T[r, 2], T[r, 3] = _row_times(T[r, 0], T[r, 1], T[r, 2], T[r, 3], A)


@njit(cache=True, hot=True, forceinline=True)
def _apply_joint(T, meta_i, qi):
    """T ← T · M(q): rotation about / translation along the (compiled) z axis."""
    x = qi + meta_i[4]
    if meta_i[3] == PRISMATIC:
        for r in range(3):
            T[r, 3] = fma(x, T[r, 2], T[r, 3])
        return
    s, c = _sincos_scalar(x)
    for r in range(3):
        t0 = T[r, 0]
        t1 = T[r, 1]
        T[r, 0] = fma(t1, s, t0 * c)
        T[r, 1] = fma(-t0, s, t1 * c)


@njit(cache=True, hot=True, forceinline=True)
def _row_times(t0, t1, t2, t3, A):
    """One row [t0 t1 t2 t3] of a rigid transform times the rigid transform A."""
    return (fma(t2, A[2, 0], fma(t1, A[1, 0], t0 * A[0, 0])),
            fma(t2, A[2, 1], fma(t1, A[1, 1], t0 * A[0, 1])),
            fma(t2, A[2, 2], fma(t1, A[1, 2], t0 * A[0, 2])),
            fma(t2, A[2, 3], fma(t1, A[1, 3], fma(t0, A[0, 3], t3))))


@njit(cache=True, hot=True, forceinline=True)
def _sincos_banks(q, off, SC, i0, i1):
    """(sin, cos) of ``q + off`` for joints ``i0..i1-1`` into the scratch ``SC`` (2-D).

    Joint ``i = i0 + b·w + c`` (w = ``SC.shape[1]``) goes to ``SC[2b, c]`` (sin) and
    ``SC[2b+1, c]`` (cos): for a (6, n) Jacobian rows 0 and 1, for a (4, 4) pose rows 0-1
    then 2-3. ``i1 − i0`` must not exceed the ``(SC.shape[0] // 2)·w`` values SC holds.
    Each bank's loop is contiguous and branch-free, so LLVM vectorises it.
    """
    w = SC.shape[1]
    big = False
    i = i0
    b = 0
    while i < i1:
        m = min(w, i1 - i)
        S = SC[2 * b]
        for c in range(m):
            x = q[i + c] + off[i + c]
            S[c] = x
            big |= abs(x) > 1e5
        i += m
        b += 1
    i = i0
    b = 0
    while i < i1:
        m = min(w, i1 - i)
        S = SC[2 * b]
        C = SC[2 * b + 1]
        if big:
            for c in range(m):
                C[c] = math.cos(S[c])
                S[c] = math.sin(S[c])
        else:
            for c in range(m):
                S[c], C[c] = _sincos(S[c])
        i += m
        b += 1


@njit(cache=True, hot=True, forceinline=True)
def _chain_walk(q, F, kind, off, J, record, SC):
    """Walk the chain holding the pose's 12 entries in registers; return them as a tuple.

    ``q`` (n,) is a writeable 1-D array typed of any layout (numba's 'A'): the single-call
    entries take any 1-D q, and :func:`fk_into`, :func:`jacobian_into` pass ``q[::1]``,
    the same type, so that the walk compiles once (issue 27). ``F`` (n+1, 4, 4) fixed
    transforms (only their top three rows are read), ``kind`` and ``off`` (n,) each
    joint's type and offset (``meta[:, 3]``, ``meta[:, 4]``, or the same entries of the
    packed chain). ``SC`` is 2-D scratch (the caller's output array,
    overwritten later; at least two rows) for the joints' sin/cos, computed
    (:func:`_sincos_banks`) for as many joints at a time as it holds: a (4, 4) pose holds
    8, so a longer chain refills it on the way. With ``record``, each joint's world axis
    z_i and origin o_i (its frame just before its motion) are stored in ``J[3:, i]`` and
    ``J[:3, i]`` (J (6, n)) on the way; SC may then be J itself, which holds all n joints'
    sin/cos (joint i's are read before column i is written).
    """
    n = kind.shape[0]
    w = SC.shape[1]
    cap = (SC.shape[0] // 2) * w  # joints whose sin/cos SC holds at once
    end = min(n, cap)
    _sincos_banks(q, off, SC, 0, end)
    bank = 0
    col = 0
    A = F[0]
    a0, a1, a2, a3 = A[0, 0], A[0, 1], A[0, 2], A[0, 3]
    b0, b1, b2, b3 = A[1, 0], A[1, 1], A[1, 2], A[1, 3]
    c0, c1, c2, c3 = A[2, 0], A[2, 1], A[2, 2], A[2, 3]
    for i in range(n):
        if i == end:  # only when SC holds fewer than n joints (never with record)
            end = min(n, i + cap)
            _sincos_banks(q, off, SC, i, end)
            bank = 0
            col = 0
        x = q[i] + off[i]
        s = SC[bank, col]
        c = SC[bank + 1, col]
        col += 1
        if col == w:
            col = 0
            bank += 2
        if record:
            J[0, i], J[1, i], J[2, i] = a3, b3, c3
            J[3, i], J[4, i], J[5, i] = a2, b2, c2
        if kind[i] == PRISMATIC:
            a3 = fma(x, a2, a3)
            b3 = fma(x, b2, b3)
            c3 = fma(x, c2, c3)
        else:
            a0, a1 = fma(a1, s, a0 * c), fma(-a0, s, a1 * c)
            b0, b1 = fma(b1, s, b0 * c), fma(-b0, s, b1 * c)
            c0, c1 = fma(c1, s, c0 * c), fma(-c0, s, c1 * c)
        A = F[i + 1]
        a0, a1, a2, a3 = _row_times(a0, a1, a2, a3, A)
        b0, b1, b2, b3 = _row_times(b0, b1, b2, b3, A)
        c0, c1, c2, c3 = _row_times(c0, c1, c2, c3, A)
    return a0, a1, a2, a3, b0, b1, b2, b3, c0, c1, c2, c3


@njit(cache=True, hot=True, forceinline=True)
def _store_pose(t, T):
    for k in range(12):
        T[k // 4, k % 4] = t[k]
    T[3, 0] = 0.0
    T[3, 1] = 0.0
    T[3, 2] = 0.0
    T[3, 3] = 1.0


@njit(cache=True, hot=True, forceinline=True)
def _copy44(src, dst):
    """``dst[:, :] = src`` for (4, 4) arrays, as a loop.

    numba's slice assignment from an array compiles, once per process, the error path of
    a shape mismatch (a message formatted from the shapes: 2.5 s of string kernels).
    """
    for r in range(4):
        for c in range(4):
            dst[r, c] = src[r, c]


@njit(cache=True, hot=True, fastmath=False)
def fk_into(q, F, meta, T):
    """End-effector pose (eq 11) into ``T`` (4, 4) for one configuration ``q`` (n,)."""
    _store_pose(_chain_walk(q[::1], F, meta[:, 3], meta[:, 4], T, False, T), T)


# --- single calls from Python: the packed chain -------------------------------------------
#
# A call from Python pays for every array argument it passes (numba unboxes each one) and
# for every array a kernel allocates. The single-call entries therefore take the packed
# chain ``P`` (n+1, 4, 4) of :attr:`serialkin.model.chain.Chain.packed` — the fixed
# transforms ``F`` whose constant last rows carry each joint's type and offset
# (``P[i, 3, 0]``, ``P[i, 3, 1]``) — and allocate nothing. Allocating nothing, they are
# compiled without numba's reference counting (``_nrt=False``): an argument is then
# unboxed without a reference-counted MemInfo of its own (a malloc and a free per array
# and call), which took ``robot.fk(q)`` from 0.53 to 0.40 µs (UR5, Panda).


@njit(cache=True, hot=True, fastmath=False, _nrt=False)
def fk_one(q, P, T):
    """End-effector pose into ``T`` (4, 4) over the packed chain.

    Returns 0, or (T untouched) 1 when ``q`` has a NaN/inf and 2 when it does not have n
    values: the single-call entry of ``Robot.fk`` checks the length here, in the compiled
    call, rather than in Python.
    """
    n = P.shape[0] - 1
    if q.shape[0] != n:
        return 2
    for i in range(n):
        if not math.isfinite(q[i]):
            return 1
    _store_pose(_chain_walk(q, P, P[:n, 3, 0], P[:n, 3, 1], T, False, T), T)
    return 0


@njit(cache=True, hot=True, _nrt=False)
def jacobian_one(q, P, J):
    """Geometric Jacobian (eqs 33-36) into ``J`` (6, n) over the packed chain.

    Returns 0, or (J untouched) 1 when ``q`` has a NaN/inf and 2 when it does not have n
    values (checked here, as in :func:`fk_one`).
    """
    n = P.shape[0] - 1
    if q.shape[0] != n:
        return 2
    for i in range(n):
        if not math.isfinite(q[i]):
            return 1
    kind = P[:n, 3, 0]
    t = _chain_walk(q, P, kind, P[:n, 3, 1], J, True, J)
    _finish_columns(J, kind, n, t[3], t[7], t[11])
    return 0


# --- sin/cos, and batches: blocks of configurations in structure-of-arrays form -----------
#
# libm's sin/cos are scalar calls (about 10 ns each) and dominate FK. Every kernel here
# evaluates them with a branch-free Taylor polynomial after Cody–Waite reduction by π/2
# (about 3x cheaper), which LLVM also vectorises across a block of configurations. π/2 is
# split into three parts (P1, P2 with 32 significant bits, so k·P1 and k·P2 are exact for
# |k| < 2^20); on |r| ≤ π/4 the truncated series (sin to r^15, cos to r^16) is accurate to
# a few 1e-17; the result agrees with libm to about 2 ulp (tested). Angles beyond
# |x| > 1e5 rad fall back to libm.

_BLOCK = 64
_TWO_OVER_PI = 0.6366197723675814
_P1 = 1.5707963267341256
_P2 = 6.077100506303966e-11
_P3 = 2.0222662487959506e-21


@njit(cache=True, hot=True, forceinline=True)
def _sincos(x):
    """(sin x, cos x) for |x| ≤ 1e5, branch-free so loops over it vectorise (see above)."""
    kf = math.floor(fma(x, _TWO_OVER_PI, 0.5))
    r = fma(-kf, _P3, fma(-kf, _P2, fma(-kf, _P1, x)))
    z = r * r
    # Horner in fused multiply-adds: sin r = r + r·z·ps(z), cos r = 1 + z·pc(z)
    ps = fma(z, -7.647163731819816e-13, 1.6059043836821613e-10)
    ps = fma(z, ps, -2.505210838544172e-08)
    ps = fma(z, ps, 1.0 / 362880.0)
    ps = fma(z, ps, -1.0 / 5040.0)
    ps = fma(z, ps, 1.0 / 120.0)
    ps = fma(z, ps, -1.0 / 6.0)
    sr = fma(r * z, ps, r)
    pc = fma(z, 4.779477332387385e-14, -1.1470745597729725e-11)
    pc = fma(z, pc, 2.08767569878681e-09)
    pc = fma(z, pc, -2.755731922398589e-07)
    pc = fma(z, pc, 2.48015873015873e-05)
    pc = fma(z, pc, -1.0 / 720.0)
    pc = fma(z, pc, 1.0 / 24.0)
    pc = fma(z, pc, -0.5)
    cr = fma(z, pc, 1.0)
    quadrant = kf - 4.0 * math.floor(kf * 0.25)  # 0, 1, 2, 3
    odd = quadrant == 1.0 or quadrant == 3.0
    sv = cr if odd else sr
    cv = sr if odd else cr
    sv = -sv if quadrant >= 2.0 else sv
    cv = -cv if (quadrant == 1.0 or quadrant == 2.0) else cv
    return sv, cv


@njit(cache=True, hot=True, forceinline=True)
def _sincos_scalar(x):
    """(sin x, cos x): :func:`_sincos`, or libm beyond |x| > 1e5 rad."""
    if abs(x) > 1e5:
        return math.sin(x), math.cos(x)
    return _sincos(x)


@njit(cache=True, hot=True, fastmath=False)
def _fk_block(Q, F, meta, out, k0, B, T, X, c, s):
    """Poses of configurations ``Q[k0:k0+B]`` into ``out``; True if a q was NaN or ±inf.

    Scratch: T (12, _BLOCK) the poses' top rows, X (n, _BLOCK) the block's joint values
    joint-major (so every per-joint loop reads contiguous memory), c, s (_BLOCK,).
    The finiteness test rides on the read of every q: ``z = Σ 0·q`` is 0 for finite
    values and NaN as soon as one is NaN or infinite (one multiply-add per value).
    """
    n = meta.shape[0]
    z = 0.0
    for b in range(B):
        for i in range(n):
            v = Q[k0 + b, i]
            z += 0.0 * v
            X[i, b] = v + meta[i, 4]
    for j in range(12):
        v = F[0, j // 4, j % 4]
        for b in range(B):
            T[j, b] = v
    for i in range(n):
        x = X[i]
        A = F[i + 1]
        a00, a01, a02, a03 = A[0, 0], A[0, 1], A[0, 2], A[0, 3]
        a10, a11, a12, a13 = A[1, 0], A[1, 1], A[1, 2], A[1, 3]
        a20, a21, a22, a23 = A[2, 0], A[2, 1], A[2, 2], A[2, 3]
        # one pass over T per joint: its motion M_i and then F[i+1] (the same operations
        # in the same order as two passes, so the same bits, with half the T traffic)
        if meta[i, 3] == PRISMATIC:
            for r in range(3):
                for b in range(B):
                    t0 = T[4 * r, b]
                    t1 = T[4 * r + 1, b]
                    t2 = T[4 * r + 2, b]
                    t3 = fma(x[b], t2, T[4 * r + 3, b])
                    T[4 * r, b] = fma(t2, a20, fma(t1, a10, t0 * a00))
                    T[4 * r + 1, b] = fma(t2, a21, fma(t1, a11, t0 * a01))
                    T[4 * r + 2, b] = fma(t2, a22, fma(t1, a12, t0 * a02))
                    T[4 * r + 3, b] = fma(t2, a23, fma(t1, a13, fma(t0, a03, t3)))
        else:
            big = False
            for b in range(B):
                s[b], c[b] = _sincos(x[b])
                big |= abs(x[b]) > 1e5
            if big:
                for b in range(B):
                    s[b] = math.sin(x[b])
                    c[b] = math.cos(x[b])
            for r in range(3):
                for b in range(B):
                    t0 = T[4 * r, b]
                    t1 = T[4 * r + 1, b]
                    t2 = T[4 * r + 2, b]
                    u0 = fma(t1, s[b], t0 * c[b])
                    u1 = fma(-t0, s[b], t1 * c[b])
                    T[4 * r, b] = fma(t2, a20, fma(u1, a10, u0 * a00))
                    T[4 * r + 1, b] = fma(t2, a21, fma(u1, a11, u0 * a01))
                    T[4 * r + 2, b] = fma(t2, a22, fma(u1, a12, u0 * a02))
                    T[4 * r + 3, b] = fma(t2, a23, fma(u1, a13, fma(u0, a03, T[4 * r + 3, b])))
    for b in range(B):
        o = out[k0 + b]
        for j in range(12):
            o[j // 4, j % 4] = T[j, b]
        o[3, 0] = 0.0
        o[3, 1] = 0.0
        o[3, 2] = 0.0
        o[3, 3] = 1.0
    return z != z


@njit(cache=True, hot=True, forceinline=True)
def _fk_blocks(Q, F, meta, out, start, stop):
    """Poses of ``Q[start:stop]`` into ``out`` block by block; True if a q was not finite."""
    T = np.empty((12, _BLOCK))
    X = np.empty((meta.shape[0], _BLOCK))
    c = np.empty(_BLOCK)
    s = np.empty(_BLOCK)
    bad = False
    k0 = start
    while k0 < stop:
        B = min(_BLOCK, stop - k0)
        bad |= _fk_block(Q, F, meta, out, k0, B, T, X, c, s)
        k0 += B
    return bad


# --- batches: range kernels ----------------------------------------------------------------
#
# Every batch kernel processes items ``start..stop-1`` with the GIL released; the
# scheduler in :mod:`serialkin.kinematics.parallel` hands chunks of the range to the
# cores (dynamic scheduling: see there why not ``prange``).


@njit(cache=True, hot=True, nogil=True)
def fk_range(Q, F, meta, out, start, stop):
    """End-effector poses of ``Q[start:stop]`` (Q (N, n)) into ``out`` (N, 4, 4).

    Walks the range in blocks of ``_BLOCK`` configurations (structure of arrays, see
    :func:`_sincos`). Trusts that every q is finite; :func:`fk_checked_range` checks.
    """
    _fk_blocks(Q, F, meta, out, start, stop)


@njit(cache=True, hot=True, nogil=True)
def fk_checked_range(Q, F, meta, out, bad, start, stop):
    """:func:`fk_range`, setting ``bad[0] = 1`` (bad: int64 (1,)) if a q is not finite.

    The batch path of ``Robot.fk`` validates its input this way: the kernel reads every
    q anyway, so the finiteness test costs one multiply-add per value instead of a
    separate pass over the batch (``np.isfinite(Q).all()``, 10 % of a 100,000-pose call).
    Poses of non-finite configurations are not finite; the caller raises.
    """
    if _fk_blocks(Q, F, meta, out, start, stop):
        bad[0] = 1


@njit(cache=True, hot=True, forceinline=True)
def finite_row(q):
    """True when every entry of ``q`` (n,) is finite: the batch kernels' input check.

    A batch kernel reads every q anyway; testing it there costs a compare per value,
    where ``np.isfinite(Q).all()`` before the call is a separate pass over the batch.
    """
    for i in range(q.shape[0]):
        if not math.isfinite(q[i]):
            return False
    return True


@njit(cache=True, hot=True)
def fk_all_into(q, F, L, meta, out):
    """Every link frame 0..n (base to last link, without the tool) into ``out`` (n+1, 4, 4)."""
    n = meta.shape[0]
    T = F[0].copy()
    _copy44(L[0], out[0])
    for i in range(n):
        _apply_joint(T, meta[i], q[i])
        _copy44(T, out[i + 1])
        _post_multiply(out[i + 1], L[i + 1])
        _post_multiply(T, F[i + 1])


@njit(cache=True, hot=True, nogil=True)
def fk_all_range(Q, F, L, meta, out, bad, start, stop):
    """Link frames of ``Q[start:stop]`` (Q (N, n)) into ``out`` (N, n+1, 4, 4).

    A configuration with a NaN/inf sets ``bad[0] = 1`` (bad: int64 (1,)) and its frames
    are NaN; the caller raises (:func:`finite_row`).
    """
    for k in range(start, stop):
        if finite_row(Q[k]):
            fk_all_into(Q[k], F, L, meta, out[k])
        else:
            bad[0] = 1
            out[k] = math.nan


@njit(cache=True, hot=True, forceinline=True)
def _record_joint(J, j, T, meta_j):
    """Store joint j's world axis z_j in J[3:, j] and origin o_j in J[:3, j] (T: its frame)."""
    for r in range(3):
        J[3 + r, j] = T[r, 2]  # the joint axis is the frame's z axis
        J[r, j] = T[r, 3]


@njit(cache=True, hot=True, forceinline=True)
def _finish_columns(J, kind, m, px, py, pz):
    """Turn the recorded (o_j, z_j) of the first m joints into Jacobian columns (eqs 35-36).

    Revolute: ``[z × (p − o); z]``; prismatic: ``[z; 0]``.
    """
    for j in range(m):
        zx = J[3, j]
        zy = J[4, j]
        zz = J[5, j]
        if kind[j] == PRISMATIC:
            J[0, j] = zx
            J[1, j] = zy
            J[2, j] = zz
            J[3, j] = 0.0
            J[4, j] = 0.0
            J[5, j] = 0.0
        else:
            dx = px - J[0, j]
            dy = py - J[1, j]
            dz = pz - J[2, j]
            J[0, j] = zy * dz - zz * dy
            J[1, j] = zz * dx - zx * dz
            J[2, j] = zx * dy - zy * dx


@njit(cache=True, hot=True)
def jacobian_into(q, F, meta, J, T):
    """Geometric Jacobian at the end-effector, base frame (eqs 33-36).

    Writes ``J`` (6, n), rows (vx, vy, vz, wx, wy, wz), and the end-effector pose ``T``
    (4, 4). Joint *i*'s axis and origin are those of its frame just before its motion
    (for standard DH, frame i-1: the chapter's z_{i-1}, p_{i-1}).
    """
    t = _chain_walk(q[::1], F, meta[:, 3], meta[:, 4], J, True, J)
    _store_pose(t, T)
    _finish_columns(J, meta[:, 3], meta.shape[0], t[3], t[7], t[11])


@njit(cache=True, hot=True)
def joint_axes_into(q, F, meta, P, W):
    """World origin ``P[i]`` (3,) and unit axis ``W[i]`` (3,) of every joint i at ``q``.

    These are the lines the joints turn about / slide along (the o_i, z_i of eqs 35-36),
    used by DH extraction and by closed-form structure recognition.
    """
    T = F[0].copy()
    for i in range(meta.shape[0]):
        for r in range(3):
            P[i, r] = T[r, 3]
            W[i, r] = T[r, 2]
        _apply_joint(T, meta[i], q[i])
        _post_multiply(T, F[i + 1])


@njit(cache=True, hot=True, nogil=True)
def jacobian_range(Q, F, meta, J, T, bad, start, stop):
    """Geometric Jacobians (N, 6, n) and poses (N, 4, 4) of ``Q[start:stop]`` (Q (N, n)).

    Non-finite configurations set ``bad[0] = 1`` and get NaN (:func:`fk_all_range`).
    """
    for k in range(start, stop):
        if finite_row(Q[k]):
            jacobian_into(Q[k], F, meta, J[k], T[k])
        else:
            bad[0] = 1
            J[k] = math.nan
            T[k] = math.nan


@njit(cache=True, hot=True)
def point_jacobian_into(q, F, L, meta, link, point, J, p_out):
    """Jacobian of a point fixed to link frame ``link`` (0..n), base frame.

    ``point`` (3,) is given in the link frame's coordinates. Columns of joints beyond
    ``link`` are zero (they do not move the point). Writes ``J`` (6, n) and the point's
    position in the base frame into ``p_out`` (3,). This is eq 56, J_s = ∂s/∂q, with the
    angular rows of the link.
    """
    J[:, :] = 0.0
    T = F[0].copy()
    W = L[0].copy()
    for i in range(link):
        _record_joint(J, i, T, meta[i])
        _apply_joint(T, meta[i], q[i])
        if i == link - 1:
            _copy44(T, W)
            _post_multiply(W, L[i + 1])
        _post_multiply(T, F[i + 1])
    for r in range(3):
        p_out[r] = W[r, 0] * point[0] + W[r, 1] * point[1] + W[r, 2] * point[2] + W[r, 3]
    _finish_columns(J, meta[:, 3], link, p_out[0], p_out[1], p_out[2])


@njit(cache=True, hot=True, nogil=True)
def point_jacobian_range(Q, F, L, meta, link, point, J, P, bad, start, stop):
    """Point Jacobians (N, 6, n) and point positions (N, 3) of ``Q[start:stop]``.

    Non-finite configurations set ``bad[0] = 1`` and get NaN (:func:`fk_all_range`).
    """
    for k in range(start, stop):
        if finite_row(Q[k]):
            point_jacobian_into(Q[k], F, L, meta, link, point, J[k], P[k])
        else:
            bad[0] = 1
            J[k] = math.nan
            P[k] = math.nan


# --- second order: Hessian and time derivative of the geometric Jacobian ------------------
#
# With J's columns J_j = [v_j; w_j] (w_j = z_j for a revolute joint, 0 for a prismatic one),
# a joint k before j turns column j rigidly and a joint k at or after j moves only the
# reference point, so (Haviland & Corke 2022, "Manipulator differential kinematics II",
# in the [v; ω] row order):
#
#     ∂J_j/∂q_k = [w_k × v_j; w_k × w_j]   for k < j,
#     ∂J_j/∂q_k = [w_j × v_k; 0]           for k ≥ j,
#
# and J̇ = Σ_k (∂J/∂q_k) q̇_k, i.e. column j of J̇ is
#
#     J̇_j = [ω_{<j} × v_j + w_j × v_{≥j};  ω_{<j} × w_j],
#
# with ω_{<j} = Σ_{k<j} w_k q̇_k and v_{≥j} = Σ_{k≥j} v_k q̇_k: O(n) once J is known.
# Both hold for any point Jacobian (columns beyond the link are zero). In the tool frame
# (J_ee = blockdiag(Rᵀ, Rᵀ) J, Ṙ = [ω]× R) each block gains a term: ∂J_ee/∂q_k =
# blockdiag(Rᵀ, Rᵀ)(∂J/∂q_k − [w_k]× J) and J̇_ee = blockdiag(Rᵀ, Rᵀ)(J̇ − [ω]× J) with
# ω = Σ_k w_k q̇_k.


@njit(cache=True, hot=True, forceinline=True)
def _cross_into(ax, ay, az, bx, by, bz, out, r, j, k, sign):
    """out[r:r+3, j, k] = sign · (a × b)."""
    out[r, j, k] = sign * (ay * bz - az * by)
    out[r + 1, j, k] = sign * (az * bx - ax * bz)
    out[r + 2, j, k] = sign * (ax * by - ay * bx)


@njit(cache=True, hot=True)
def hessian_into(J, R, ee, H):
    """Hessian ``H`` (6, n, n), ``H[:, j, k] = ∂J[:, j]/∂q_k``, of a base-frame Jacobian J (6, n).

    With ``ee`` the Hessian of ``blockdiag(Rᵀ, Rᵀ) J`` (R (3, 3) the frame's rotation) is
    written instead. Formulas in the section comment above.
    """
    n = J.shape[1]
    for j in range(n):
        for k in range(n):
            if k < j:
                wx, wy, wz = J[3, k], J[4, k], J[5, k]
                _cross_into(wx, wy, wz, J[0, j], J[1, j], J[2, j], H, 0, j, k, 1.0)
                _cross_into(wx, wy, wz, J[3, j], J[4, j], J[5, j], H, 3, j, k, 1.0)
            else:
                _cross_into(J[3, j], J[4, j], J[5, j], J[0, k], J[1, k], J[2, k], H, 0, j, k,
                            1.0)
                H[3, j, k] = 0.0
                H[4, j, k] = 0.0
                H[5, j, k] = 0.0
    if ee:
        for j in range(n):
            for k in range(n):
                wx, wy, wz = J[3, k], J[4, k], J[5, k]
                for r in (0, 3):
                    vx, vy, vz = J[r, j], J[r + 1, j], J[r + 2, j]
                    hx = H[r, j, k] - (wy * vz - wz * vy)
                    hy = H[r + 1, j, k] - (wz * vx - wx * vz)
                    hz = H[r + 2, j, k] - (wx * vy - wy * vx)
                    for c in range(3):
                        H[r + c, j, k] = R[0, c] * hx + R[1, c] * hy + R[2, c] * hz


@njit(cache=True, hot=True)
def jacobian_dot_into(J, qd, R, ee, Jd):
    """Time derivative ``Jd`` (6, n) of a base-frame Jacobian J (6, n) at joint rates qd (n,).

    ``J̇ = Σ_k (∂J/∂q_k) q̇_k`` in O(n) (see the section comment); with ``ee`` that of
    ``blockdiag(Rᵀ, Rᵀ) J`` (R (3, 3) the frame's rotation).
    """
    n = J.shape[1]
    vx = vy = vz = 0.0  # v_{≥j}, accumulated from the last column backwards
    for j in range(n - 1, -1, -1):
        vx += J[0, j] * qd[j]
        vy += J[1, j] * qd[j]
        vz += J[2, j] * qd[j]
        Jd[0, j] = J[4, j] * vz - J[5, j] * vy
        Jd[1, j] = J[5, j] * vx - J[3, j] * vz
        Jd[2, j] = J[3, j] * vy - J[4, j] * vx
    ox = oy = oz = 0.0  # ω_{<j}
    for j in range(n):
        for r in (0, 3):
            ax, ay, az = J[r, j], J[r + 1, j], J[r + 2, j]
            cx, cy, cz = oy * az - oz * ay, oz * ax - ox * az, ox * ay - oy * ax
            if r == 0:
                Jd[0, j] += cx
                Jd[1, j] += cy
                Jd[2, j] += cz
            else:
                Jd[3, j] = cx
                Jd[4, j] = cy
                Jd[5, j] = cz
        ox += J[3, j] * qd[j]
        oy += J[4, j] * qd[j]
        oz += J[5, j] * qd[j]
    if ee:  # ω is now the frame's angular velocity
        for j in range(n):
            for r in (0, 3):
                ax, ay, az = J[r, j], J[r + 1, j], J[r + 2, j]
                hx = Jd[r, j] - (oy * az - oz * ay)
                hy = Jd[r + 1, j] - (oz * ax - ox * az)
                hz = Jd[r + 2, j] - (ox * ay - oy * ax)
                for c in range(3):
                    Jd[r + c, j] = R[0, c] * hx + R[1, c] * hy + R[2, c] * hz


@njit(cache=True, hot=True, forceinline=True)
def _tool_jacobian(q, P):
    """Tool Jacobian (6, n) and rotation (3, 3) over the packed chain (single calls)."""
    n = P.shape[0] - 1
    kind = P[:n, 3, 0]
    J = np.empty((6, n))
    t = _chain_walk(q, P, kind, P[:n, 3, 1], J, True, J)
    _finish_columns(J, kind, n, t[3], t[7], t[11])
    R = np.empty((3, 3))
    for r in range(3):
        for c in range(3):
            R[r, c] = t[4 * r + c]
    return J, R


@njit(cache=True, hot=True)
def hessian_one(q, P, ee, H):
    """:func:`hessian_into` of the tool Jacobian at one ``q`` (packed chain); False on NaN q."""
    for i in range(q.shape[0]):
        if not math.isfinite(q[i]):
            return False
    J, R = _tool_jacobian(q, P)
    hessian_into(J, R, ee, H)
    return True


@njit(cache=True, hot=True)
def jacobian_dot_one(q, P, qd, ee, Jd):
    """:func:`jacobian_dot_into` of the tool Jacobian at one ``q`` (packed chain); False on NaN."""
    for i in range(q.shape[0]):
        if not (math.isfinite(q[i]) and math.isfinite(qd[i])):
            return False
    J, R = _tool_jacobian(q, P)
    jacobian_dot_into(J, as_readonly(qd), R, ee, Jd)  # qd only read: as the batch passes it
    return True


@njit(cache=True, hot=True, nogil=True)
def hessian_range(J, R, ee, H, start, stop):
    """:func:`hessian_into` for items ``start..stop-1`` of J (N, 6, n), R (N, 3, 3) into H."""
    for k in range(start, stop):
        hessian_into(J[k], R[k], ee, H[k])


@njit(cache=True, hot=True, nogil=True)
def jacobian_dot_range(J, Qd, R, ee, Jd, start, stop):
    """:func:`jacobian_dot_into` for items ``start..stop-1`` of J (N, 6, n), Qd (N, n).

    ``Qd`` read-only; each row is passed as ``Qd[k][::1]`` (typed of any layout), the
    type :func:`jacobian_dot_one` passes, so that jacobian_dot_into compiles once.
    """
    for k in range(start, stop):
        jacobian_dot_into(J[k], Qd[k][::1], R[k], ee, Jd[k])
