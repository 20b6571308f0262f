"""The one compiled kernel of every closed-form class (numba).

Each class (an integer ``code``) has its own kernel, built by :func:`for_class` on its
first use: ``solve`` solves targets ``start..stop-1`` of a batch with the GIL released,
optionally refining every candidate branch on the true chain (nearly ideal arms, see
:mod:`serialkin.ik.analytic.refine`), on the robot's read-only data packed by
:func:`pack` into three arrays (a call from Python pays for unboxing every array
argument, 50-100 ns each). ``ik_all``'s fast path calls it for one target, its options
path too, and the batch driver (:func:`serialkin.kinematics.parallel.run`) for chunks: one
compiled entry per class, because each compiled level links and re-optimises the whole
solver tree below it (4-5 s of a general 6R's first call per entry).

Why one kernel per class rather than one kernel branching on the code: a kernel
compiles everything it may call, so one entry for all classes compiled every class's
solver (and the general 6R search) at the first ``ik_all`` of any arm: 131 s cold for a
UR5 on a quiet 2-core machine. Per class, a UR5 compiles only the UR solver. The
kernels are copies of the templates below with the class's candidate function bound as a
global (as :func:`serialkin.ik._kernels.compile_method` does for the IK steps), cached
on disk under the class's name. Kernels trust their input.
"""

from __future__ import annotations

import functools
from dataclasses import dataclass

import numpy as np

from serialkin.errors import InputError
from serialkin.ik.analytic.general import MAX_SOLUTIONS as GENERAL_MAX
from serialkin.ik.analytic.general import general_candidates
from serialkin.ik.analytic.planar import solve_planar
from serialkin.ik.analytic.refine import refine_rows
from serialkin.ik.analytic.scara import solve_scara
from serialkin.ik.analytic.spherical_wrist import wrist_candidates
from serialkin.ik.analytic.subproblems import ELBOW_SLACK, finalize, inv_rigid, rigid_error
from serialkin.ik.analytic.ur import ur_candidates

from ..._jit import bind, njit

#: Class codes of :func:`for_class`.
PLANAR, SCARA, WRIST, UR, GENERAL = 0, 1, 2, 3, 4
#: Rows of the output buffer (the most solutions of any class).
MAX_ROWS = GENERAL_MAX


@njit(cache=True)
def _unreverse(cand, k):
    """Rows ``cand[:k]`` of a reversed chain's solutions as the robot's: columns reversed.

    The reversed chain's joint j is the robot's joint n + 1 − j with the same angle
    (:func:`serialkin.ik.analytic.structure.reversed_lines`). Returns k.
    """
    n = cand.shape[1]
    for i in range(k):
        for j in range(n // 2):
            t = cand[i, j]
            cand[i, j] = cand[i, n - 1 - j]
            cand[i, n - 1 - j] = t
    return k


@njit(cache=True, inline="always")
def _wrist(T, W, P, M, aux, arm, prismatic3, order, grid, F, meta, newton_p, newton_r, slack,
           cand):
    """Candidates of a spherical-wrist arm (:func:`wrist_candidates`); returns the count.

    ``order`` is ``[1]`` when W, P, M are the reversed chain's (the wrist at the base):
    it solves ``T⁻¹`` and the rows are reversed back.
    """
    if order.shape[0] > 0 and order[0] == 1:
        k = wrist_candidates(inv_rigid(T), W, P, M, aux, arm, prismatic3, slack, cand)
        return _unreverse(cand, k)
    return wrist_candidates(T, W, P, M, aux, arm, prismatic3, slack, cand)


@njit(cache=True, inline="always")
def _ur(T, W, P, M, aux, arm, prismatic3, order, grid, F, meta, newton_p, newton_r, slack,
        cand):
    """Candidates of a UR-class arm (:func:`ur_candidates`); returns the count.

    ``order`` as for :func:`_wrist` (``[1]``: parallel axes 3, 4, 5 and intersecting
    axes 1, 2, solved on the reversed chain).
    """
    if order.shape[0] > 0 and order[0] == 1:
        return _unreverse(cand, ur_candidates(inv_rigid(T), W, P, M, aux, slack, cand))
    return ur_candidates(T, W, P, M, aux, slack, cand)


@njit(cache=True, inline="always")
def _general(T, W, P, M, aux, arm, prismatic3, order, grid, F, meta, newton_p, newton_r, slack,
             cand):
    """Candidates of a general 6R (:func:`general_candidates`); returns the count.

    ``order`` is (arm code, searched chain reversed, elimination starts on the reversed
    chain) (:func:`~serialkin.ik.analytic.structure.general_structure`). Real solutions
    of a 6R come in even numbers: an odd count searches once more on a grid twice as fine.
    """
    reverse = order[1] == 1
    rr_other = order.shape[0] > 2 and (order[2] == 1) != reverse
    k = general_candidates(T, W, P, M, aux, arm, reverse, rr_other, grid, F, meta, newton_p,
                           newton_r, cand)
    if k % 2 == 1:
        k = general_candidates(T, W, P, M, aux, arm, reverse, rr_other, 2 * grid, F, meta,
                               newton_p, newton_r, cand)
    return k


# The templates below are copied by for_class with the class's functions bound as globals
# (``candidates`` and ``refinable``, or ``closed``; then ``solve_into``), then compiled.
def _solve_into(arm, prismatic3, T, W, P, M, aux, order, revolute, qlim, mid, F, meta,
                check_rot, refine, grid, tol_p, tol_r, newton_p, newton_r, out, conv):
    """Every solution of one target into ``out`` (16, n); returns their count.

    Args:
        arm: arm code of the spherical-wrist / general classes.
        prismatic3: joint 3 slides (Stanford classes).
        T: (4, 4) target pose (world).
        W: (n, 3) joint directions at q = 0 (the structure's data, as P, M, aux, order).
        P: (n, 3) joint points [m].
        M: (4, 4) tool pose at q = 0.
        aux: class data.
        order: class joint indices; ``[1]`` for a spherical-wrist or UR arm recognised on
            its reversed chain (W, P, M then that chain's; see :func:`_wrist`).
        revolute: (n,) joint kinds.
        qlim: (n, 2) joint limits.
        mid: (n,) wrapping centres.
        F: (n+1, 4, 4) chain transforms (verification and refinement).
        meta: (n, 5) chain joint data.
        check_rot: verify the rotation too.
        refine: Newton-refine every candidate branch on the chain (nearly ideal arms;
            not the general class, whose candidates are refined already).
        grid: search grid of the general class.
        tol_p: verification tolerance [m].
        tol_r: verification tolerance of the rotation entries.
        newton_p: refinement tolerance [m].
        newton_r: refinement tolerance [rad].
        out: (16, n) output rows.
        conv: (17,) int: ``conv[0]`` the number of candidate branches B, ``conv[1:B+1]``
            1 when branch i converged (or needed no refinement), else 0.

    Returns:
        the number of solutions inside the limits (rows sorted lexicographically).
    """
    n = W.shape[0]
    cand = np.zeros((MAX_ROWS, n))
    slack = ELBOW_SLACK if refine else 0.0  # idealised arm: elbow seeds beyond its reach
    k = candidates(T, W, P, M, aux, arm, prismatic3, order, grid, F, meta,  # noqa: F821
                   newton_p, newton_r, slack, cand)
    conv[0] = k
    if refinable and refine:  # noqa: F821 (bound by for_class)
        ok = np.zeros(k, dtype=np.bool_)
        refine_rows(cand, k, T, F, meta, newton_p, newton_r, ok)
        for i in range(k):
            conv[1 + i] = 1 if ok[i] else 0
    else:
        for i in range(k):
            conv[1 + i] = 1
    return finalize(cand, k, revolute, qlim, mid, F, meta, T, True, tol_p, tol_r, out)


def _solve_closed(arm, prismatic3, T, W, P, M, aux, order, revolute, qlim, mid, F, meta,
                  check_rot, refine, grid, tol_p, tol_r, newton_p, newton_r, out, conv):
    """:func:`_solve_into` of a planar or SCARA arm (solved and finalised by ``closed``)."""
    conv[0] = 0
    return closed(T, W, P, M, order, aux[0].copy(), aux[1].copy(),  # noqa: F821
                  revolute, qlim, mid, F, meta, check_rot, tol_p, tol_r, out)


#: Header length of the packed integer array (see :func:`pack`).
_HEAD = 9


def pack(code, arm, prismatic3, W, P, M, aux, order, revolute, qlim, mid, F, meta, check_rot,
         refine, grid, tol_p, tol_r, newton_p, newton_r):
    """The arguments of :func:`_solve_into` but the target and outputs, in three arrays.

    Returns read-only ``(I, D, B)``: ``I`` int64 = (code, arm, prismatic3, refine, grid,
    n, rows of aux, length of order, check_rot) then ``order``; ``D`` float64 = (tol_p,
    tol_r, newton_p, newton_r) then ``W``, ``P``, ``M``, ``aux``, ``qlim``, ``mid``, ``F``,
    ``meta`` flattened; ``B`` = ``revolute`` (bool). The class kernel (:func:`_solve`)
    unpacks them as views. Arrays of the structure (aux (k, 3)) and of the chain (F
    (n+1, 4, 4), meta (n, 5)).
    """
    n = W.shape[0]
    if aux.ndim != 2 or aux.shape[1] != 3 or meta.shape != (n, 5) or F.shape != (n + 1, 4, 4):
        raise InputError(f"pack: aux must be (k, 3), meta ({n}, 5) and F ({n + 1}, 4, 4); got "
                         f"{aux.shape}, {meta.shape}, {F.shape}")  # the layout _solve reads
    order = np.asarray(order, dtype=np.int64)
    I = np.concatenate([np.array([code, arm, int(prismatic3), int(refine), grid, n,
                                  aux.shape[0], order.shape[0], int(check_rot)],
                                 dtype=np.int64), order])
    D = np.concatenate([np.array([tol_p, tol_r, newton_p, newton_r], dtype=float)]
                       + [np.asarray(a, dtype=float).ravel()
                          for a in (W, P, M, aux, qlim, mid, F, meta)])
    B = np.array(revolute, dtype=np.bool_)
    for a in (I, D, B):
        a.setflags(write=False)
    return I, D, B


def _solve(Ts, I, D, B, out, counts, conv, start, stop):
    """Every solution of targets ``start..stop-1`` on :func:`pack`'s arrays; the last count.

    The class's one compiled kernel (GIL released): the single call of ``ik_all``'s fast
    path (``start, stop = 0, 1``), its ordinary path and the batch driver's chunks
    (:func:`serialkin.kinematics.parallel.run`) all call it, so the class's solver tree
    compiles once. The buffers are flat so that one pose needs no reshaping: ``Ts`` (4N,
    4) the targets stacked (target i is ``Ts[4i:4i+4]``), ``out`` (16N, n) the rows
    (target i's are ``out[16i:16i+16]``), ``conv`` (17N,) the convergence records, each as
    :func:`_solve_into` writes them, and ``counts`` (N,) the solutions per target: −1,
    without solving, when the rotation is verified (``check_rot``) and the target is not a
    rigid transform to 1e-13 (the caller then checks it, projects the rotation or raises).
    Returns ``counts[stop − 1]`` (0 for an empty range).
    """
    n = I[5]
    na = I[6]
    o = 4
    W = D[o:o + 3 * n].reshape((n, 3))
    o += 3 * n
    P = D[o:o + 3 * n].reshape((n, 3))
    o += 3 * n
    M = D[o:o + 16].reshape((4, 4))
    o += 16
    aux = D[o:o + 3 * na].reshape((na, 3))
    o += 3 * na
    qlim = D[o:o + 2 * n].reshape((n, 2))
    o += 2 * n
    mid = D[o:o + n]
    o += n
    F = D[o:o + 16 * (n + 1)].reshape((n + 1, 4, 4))
    o += 16 * (n + 1)
    meta = D[o:o + 5 * n].reshape((n, 5))
    check_rot = I[8] != 0
    order = I[_HEAD:_HEAD + I[7]]
    k = 0
    for i in range(start, stop):
        T = Ts[4 * i:4 * i + 4]
        if check_rot and rigid_error(T) > 1e-13:
            k = -1
        else:
            k = solve_into(I[1], I[2] != 0, T, W, P, M, aux, order, B, qlim, mid,  # noqa: F821
                           F, meta, check_rot, I[3] != 0, I[4], D[0], D[1], D[2], D[3],
                           out[MAX_ROWS * i:MAX_ROWS * i + MAX_ROWS],
                           conv[(MAX_ROWS + 1) * i:(MAX_ROWS + 1) * (i + 1)])
        counts[i] = k
    return k


@dataclass(frozen=True, eq=False)
class ClassKernels:
    """The compiled kernel of one closed-form class (see the module docstring).

    Attributes:
        solve: ``solve(Ts, I, D, B, out, counts, conv, start, stop) -> last count`` on
            :func:`pack`'s arrays and flat buffers (:func:`_solve`).
    """

    solve: object


_NAMES = {PLANAR: "planar", SCARA: "scara", WRIST: "wrist", UR: "ur", GENERAL: "general"}


@functools.cache
def for_class(code: int, refine: bool = False) -> ClassKernels:
    """The kernel of class ``code`` (:data:`PLANAR` ... :data:`GENERAL`), built once.

    ``refine``: a kernel that can refine the candidates of a nearly ideal arm (the
    ``refine`` field of :func:`pack` then decides); without it, the refinement is not
    compiled at all (13 s of a UR5's first ``ik_all``) and the field is ignored.
    Compilation is lazy (at the first call) and cached on disk; only the solver of this
    class is compiled, once: the per-target template is inlined in numba's IR into the
    one range kernel (each compiled level links and re-optimises everything below it).
    """
    refine = bool(refine) and code not in (PLANAR, SCARA, GENERAL)
    name = _NAMES[code] + ("_refined" if refine else "")
    if code in (PLANAR, SCARA):
        one = bind(_solve_closed, f"solve_into_{name}",
                   closed=solve_planar if code == PLANAR else solve_scara)
    else:
        cands = {WRIST: _wrist, UR: _ur, GENERAL: _general}[code]
        one = bind(_solve_into, f"solve_into_{name}", candidates=cands, refinable=refine)
    one = njit(cache=True, inline="always")(one)
    return ClassKernels(solve=njit(cache=True, nogil=True)(
        bind(_solve, f"solve_{name}", solve_into=one)))


def solve(code: int, T: np.ndarray, packed: tuple, grain: int = 0) -> tuple:
    """Solve targets ``T`` (N, 4, 4) of class ``code`` on :func:`pack`'s arrays.

    ``T`` must be C-contiguous, writeable float64 (the kernel's one specialisation);
    ``grain`` > 0 spreads the targets over every core in chunks of at least ``grain``
    (:func:`serialkin.kinematics.parallel.run`). Returns ``(out, counts, conv)``: (N, 16,
    n) rows (zero beyond each count), (N,) counts (−1: not rigid, see :func:`_solve`) and
    (N, 17) convergence records.
    """
    from serialkin.kinematics.parallel import run

    I, D, B = packed
    N = T.shape[0]
    out = np.zeros((N, MAX_ROWS, int(I[5])))
    counts = np.zeros(N, dtype=np.int64)
    conv = np.zeros((N, MAX_ROWS + 1), dtype=np.int64)
    kernel = for_class(code, bool(I[3])).solve
    args = (T.reshape(4 * N, 4), I, D, B, out.reshape(MAX_ROWS * N, -1), counts,
            conv.reshape(-1))
    if grain > 0:
        run(kernel, args, N, grain)
    else:
        kernel(*args, 0, N)
    return out, counts, conv
