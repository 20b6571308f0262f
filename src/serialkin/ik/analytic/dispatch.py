"""The compiled entries of every closed-form class, and their batch range kernels (numba).

Each class (an integer ``code``) has its own three kernels, built by :func:`for_class`
on its first use: ``solve_into`` solves one target, optionally refining every candidate
branch on the true chain (nearly ideal arms, see :mod:`serialkin.ik.analytic.refine`);
``solve_range`` runs it over targets ``start..stop-1`` with the GIL released, for
:func:`serialkin.kinematics.parallel.run`; ``solve_packed`` is the single-call entry of
``ik_all``'s fast path: the same solve with the robot's read-only data packed by
:func:`pack` into three arrays (a call from Python pays for unboxing every array
argument, 50-100 ns each).

Why one set of kernels per class rather than one kernel branching on the code: a kernel
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

#: Class codes of :func:`solve_into`.
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


def _solve_range(arm, prismatic3, Ts, W, P, M, aux, order, revolute, qlim, mid, F, meta,
                 refine, grid, tol_p, tol_r, newton_p, newton_r, out, counts, conv, start,
                 stop):
    """``solve_into`` for targets ``Ts[start:stop]`` (N, 4, 4), GIL released.

    Writes ``out`` (N, 16, n), ``counts`` (N,) and ``conv`` (N, 17); the other arguments
    as for :func:`_solve_into` (rotations always verified).
    """
    for i in range(start, stop):
        counts[i] = solve_into(arm, prismatic3, Ts[i], W, P, M, aux,  # noqa: F821
                               order, revolute, qlim, mid, F, meta, True, refine, grid, tol_p,
                               tol_r, newton_p, newton_r, out[i], conv[i])


#: Header length of the packed integer array (see :func:`pack`).
_HEAD = 8


def pack(code, arm, prismatic3, W, P, M, aux, order, revolute, qlim, mid, F, meta, refine,
         grid, tol_p, tol_r, newton_p, newton_r):
    """The arguments of :func:`solve_into` but the target and outputs, in three arrays.

    Returns read-only ``(I, D, B)``: ``I`` int64 = (code, arm, prismatic3, refine, grid,
    n, rows of aux, length of order) then ``order``; ``D`` float64 = (tol_p, tol_r,
    newton_p, newton_r) then ``W``, ``P``, ``M``, ``aux``, ``qlim``, ``mid``, ``F``,
    ``meta`` flattened; ``B`` = ``revolute`` (bool). :func:`solve_packed` unpacks them as
    views of the same types, so the kernels below it are the ones already compiled.
    Arrays of the structure (aux (k, 3)) and of the chain (F (n+1, 4, 4), meta (n, 5)).
    """
    n = W.shape[0]
    if aux.ndim != 2 or aux.shape[1] != 3 or meta.shape != (n, 5) or F.shape != (n + 1, 4, 4):
        raise InputError(f"pack: aux must be (k, 3), meta ({n}, 5) and F ({n + 1}, 4, 4); got "
                         f"{aux.shape}, {meta.shape}, {F.shape}")  # the layout solve_packed reads
    order = np.asarray(order, dtype=np.int64)
    I = np.concatenate([np.array([code, arm, int(prismatic3), int(refine), grid, n,
                                  aux.shape[0], order.shape[0]], dtype=np.int64), order])
    D = np.concatenate([np.array([tol_p, tol_r, newton_p, newton_r], dtype=float)]
                       + [np.asarray(a, dtype=float).ravel()
                          for a in (W, P, M, aux, qlim, mid, F, meta)])
    B = np.array(revolute, dtype=np.bool_)
    for a in (I, D, B):
        a.setflags(write=False)
    return I, D, B


def _solve_packed(T, I, D, B, out, conv):
    """``solve_into`` on the packed data of :func:`pack` (the fast path's entry).

    One compiled call for the rigidity check and the solve (rotation verified), into
    ``out`` (16, n) and ``conv`` (17,) (as :func:`_solve_into`). Returns the number of
    solutions k >= 0; −1 without solving when T (4, 4) is not a rigid transform to 1e-13
    (the caller then checks it, projects the rotation or raises); ``−2 − k`` when the arm
    is refined (nearly ideal) and its branches are doubtful (:func:`refined_doubtful`;
    the caller then adds the general search's rows).
    """
    if rigid_error(T) > 1e-13:
        return -1
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
    refine = I[3] != 0
    k = solve_into(I[1], I[2] != 0, T, W, P, M, aux, I[_HEAD:_HEAD + I[7]], B,  # noqa: F821
                   qlim, mid, F, meta, True, refine, I[4], D[0], D[1], D[2], D[3], out, conv)
    if refine and refined_doubtful(conv):
        return -2 - k
    return k


@njit(cache=True)
def refined_doubtful(conv):
    """Whether a nearly ideal arm's refined branches may have missed a true solution.

    ``conv`` (17,) as :func:`solve_into` fills it. Doubtful when an odd number of
    branches converged on the true chain (real solutions of a 6R come in pairs: one was
    lost, e.g. near a singularity of the true arm) or none did (the idealised arm may
    have no solution where the true arm has some: measured on random arms with twists
    0.04 rad from parallel). Only the general search can tell, so the caller adds its
    rows. Branches failing in pairs while others converge are usually solutions the
    idealised arm has and the true arm has not (a target near the workspace boundary):
    searching for them would cost the search on most such targets for no miss found.
    """
    good = 0
    for i in range(conv[0]):
        good += conv[1 + i]
    return good % 2 == 1 or good == 0


@dataclass(frozen=True, eq=False)
class ClassKernels:
    """The compiled kernels of one closed-form class (see the module docstring).

    Attributes:
        solve_into: ``solve_into(arm, prismatic3, T, W, P, M, aux, order, revolute, qlim,
            mid, F, meta, check_rot, refine, grid, tol_p, tol_r, newton_p, newton_r, out,
            conv) -> count`` (:func:`_solve_into`).
        solve_range: the same over ``Ts[start:stop]``, GIL released (:func:`_solve_range`).
        solve_packed: ``solve_packed(T, I, D, B, out, conv)`` on :func:`pack`'s arrays.
    """

    solve_into: object
    solve_range: object
    solve_packed: object


_NAMES = {PLANAR: "planar", SCARA: "scara", WRIST: "wrist", UR: "ur", GENERAL: "general"}


@functools.cache
def for_class(code: int, refine: bool = False) -> ClassKernels:
    """The kernels of class ``code`` (:data:`PLANAR` ... :data:`GENERAL`), built once.

    ``refine``: kernels that can refine the candidates of a nearly ideal arm (the
    ``refine`` argument of ``solve_into`` then decides); without it, the refinement is not
    compiled at all (13 s of a UR5's first ``ik_all``) and the argument is ignored.
    Compilation is lazy (each kernel at its first call) and cached on disk; only the
    solver of this class is compiled.
    """
    refine = bool(refine) and code not in (PLANAR, SCARA, GENERAL)
    name = _NAMES[code] + ("_refined" if refine else "")
    if code in (PLANAR, SCARA):
        one = bind(_solve_closed, f"solve_into_{name}",
                   closed=solve_planar if code == PLANAR else solve_scara)
    else:
        cands = {WRIST: _wrist, UR: _ur, GENERAL: _general}[code]
        one = bind(_solve_into, f"solve_into_{name}", candidates=cands, refinable=refine)
    one = njit(cache=True)(one)  # called from Python too: one compiled copy, linked
    return ClassKernels(
        solve_into=one,
        solve_range=njit(cache=True, nogil=True)(bind(_solve_range, f"solve_range_{name}",
                                                      solve_into=one)),
        solve_packed=njit(cache=True)(bind(_solve_packed, f"solve_packed_{name}",
                                           solve_into=one)),
    )


def solve_into(code, *args):
    """One target of class ``code``: ``for_class(code, refine).solve_into(*args)``.

    ``args`` as for :func:`_solve_into` (``refine`` is its 15th).
    """
    return for_class(code, args[14]).solve_into(*args)
