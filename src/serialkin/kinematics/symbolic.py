"""Symbolic forward kinematics and Jacobians with sympy (chapter eqs 11-18, 29-38).

:func:`derive` turns any robot (standard or modified DH, or joints in general form,
revolute or prismatic) into sympy matrices: the link matrices ``A_i(q_i)`` (eqs 12-16),
the end-effector transform ``0T_n = base · A_1 ··· A_n · tool`` (eqs 11, 17-18), the
analytical Jacobian of a position or planar task (eqs 29-32) and the geometric Jacobian
(eqs 35-37). Results print as LaTeX or text and compile to numpy functions with
:meth:`SymbolicKinematics.lambdify`; :func:`check_against` evaluates them on random
configurations and compares with the numeric kernels.

Constant DH values are turned into exact numbers where they are simple (0, ±1, small
fractions, multiples of π/12) so that simplification works; with ``params="lengths"`` or
``"all"`` the nonzero constants become symbols (``a_1``, ``d_1``, ``alpha_1``,
``theta_1``; for modified DH the row-i twist and length are named ``a_{i-1}``,
``alpha_{i-1}`` as in Craig) whose numeric values are kept in ``params``.

Example:
    >>> import serialkin as sk
    >>> from serialkin.kinematics.symbolic import derive
    >>> kin = derive(sk.models.two_link(), params="lengths")
    >>> kin.position[0]
    a_1*cos(q_1) + a_2*cos(q_1 + q_2)
"""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field, replace
from fractions import Fraction
from functools import lru_cache
from typing import TYPE_CHECKING, Any

import numpy as np
import sympy as sp

from serialkin._checks import as_generator, check_choice, check_int
from serialkin.errors import InputError, InputTypeError

if TYPE_CHECKING:  # kinematics sits below model: a Robot is read, never imported
    from serialkin.model.dh import DHLink
    from serialkin.model.robot import Robot

PARAM_MODES = ("none", "lengths", "all")
TASKS = ("position", "planar", "planar_pose")


# ---------------------------------------------------------------------------- numbers
def exact(value: float, *, angle: bool = False, tol: float = 1e-12) -> sp.Expr:
    """Turn a float into an exact sympy number when it is simple, else a Float.

    Args:
        value: the number.
        angle: also recognise multiples of π/12 (for α and θ).
        tol: absolute tolerance of the recognition.

    Returns:
        ``0``, an Integer, a Rational with denominator <= 1000, ``k·π/12`` (angles) or a
        ``Float``.
    """
    v = float(value)
    if abs(v) < tol:
        return sp.Integer(0)
    if angle:
        k = v * 12.0 / np.pi
        if abs(k - round(k)) < tol:
            return sp.Rational(round(k), 12) * sp.pi
    fr = Fraction(v).limit_denominator(1000)
    if abs(float(fr) - v) < tol:
        return sp.Rational(fr.numerator, fr.denominator)
    return sp.Float(v, 15)


def exact_matrix(M: np.ndarray) -> sp.Matrix:
    """A numeric matrix with every entry passed through :func:`exact`."""
    a = np.asarray(M, dtype=float)
    return sp.Matrix(a.shape[0], a.shape[1], lambda i, j: exact(a[i, j]))


def _rot(axis: str, t: sp.Expr) -> sp.Matrix:
    c, s = sp.cos(t), sp.sin(t)
    if axis == "x":
        R = sp.Matrix([[1, 0, 0], [0, c, -s], [0, s, c]])
    else:
        R = sp.Matrix([[c, -s, 0], [s, c, 0], [0, 0, 1]])
    T = sp.eye(4)
    T[:3, :3] = R
    return T


def _trans(x: sp.Expr = 0, y: sp.Expr = 0, z: sp.Expr = 0) -> sp.Matrix:
    T = sp.eye(4)
    T[0, 3], T[1, 3], T[2, 3] = x, y, z
    return T


def _axis_motion(axis: sp.Matrix, jtype: str, x: sp.Expr) -> sp.Matrix:
    """Rotation by x about / translation by x along a unit axis (Rodrigues), (4, 4)."""
    if jtype == "P":
        return _trans(axis[0] * x, axis[1] * x, axis[2] * x)
    K = sp.Matrix([[0, -axis[2], axis[1]], [axis[2], 0, -axis[0]], [-axis[1], axis[0], 0]])
    R = sp.eye(3) + sp.sin(x) * K + (1 - sp.cos(x)) * K * K
    T = sp.eye(4)
    T[:3, :3] = R
    return T


# ---------------------------------------------------------------------------- result
@dataclass(frozen=True)
class SymbolicLink:
    """One link ``A_i(q_i) = P_i · M_i(q_i) · Q_i`` in symbols.

    Attributes:
        P: fixed part before the joint motion (4, 4).
        M: joint motion, a rotation about / translation along ``axis`` (4, 4).
        Q: fixed part after the motion (4, 4).
        axis: unit joint axis in the frame reached by ``P`` (3, 1).
        type: 'R' or 'P'.
    """

    P: sp.Matrix
    M: sp.Matrix
    Q: sp.Matrix
    axis: sp.Matrix
    type: str

    @property
    def A(self) -> sp.Matrix:
        """The link matrix ``A_i = P · M · Q`` (eq 12), (4, 4)."""
        return self.P * self.M * self.Q


@dataclass(frozen=True)
class SymbolicKinematics:
    """Symbolic forward kinematics of one robot.

    Attributes:
        name: robot name.
        convention: 'standard', 'modified' or None (general joints).
        q: joint symbols ``q_1 … q_n``.
        links: per-link :class:`SymbolicLink`.
        base: (4, 4) base transform (exact numbers).
        tool: (4, 4) tool transform (exact numbers).
        T: end-effector transform ``base · A_1 ··· A_n · tool`` (eq 11), simplified when
            requested.
        params: numeric value of every parameter symbol.
        simplified: whether ``T`` and derived matrices are simplified.
    """

    name: str
    convention: str | None
    q: tuple[sp.Symbol, ...]
    links: tuple[SymbolicLink, ...]
    base: sp.Matrix
    tool: sp.Matrix
    T: sp.Matrix
    params: Mapping[sp.Symbol, float] = field(default_factory=dict)
    simplified: bool = True

    @property
    def n(self) -> int:
        """Number of joints."""
        return len(self.q)

    @property
    def A(self) -> tuple[sp.Matrix, ...]:
        """Link matrices ``A_1 … A_n`` (eqs 12-16), each (4, 4)."""
        return tuple(self._simp(lk.A) for lk in self.links)

    @property
    def position(self) -> sp.Matrix:
        """End-effector position ``0o_n`` (eq 10), (3, 1)."""
        return self.T[:3, 3]

    @property
    def rotation(self) -> sp.Matrix:
        """End-effector rotation ``0R_n`` (eq 10), (3, 3)."""
        return self.T[:3, :3]

    def _simp(self, M: sp.Matrix) -> sp.Matrix:
        return simplify_matrix(M) if self.simplified else M

    def frame(self, i: int) -> sp.Matrix:
        """Frame ``0T_i = base · A_1 ··· A_i`` for i = 0..n (no tool), (4, 4)."""
        i = check_int(i, "i")
        if i > self.n:
            raise InputError(f"i must be in 0..{self.n}, got {i}")
        T = self.base
        for lk in self.links[:i]:
            T = T * lk.A
        return self._simp(T)

    def task(self, task: str = "position") -> sp.Matrix:
        """Task coordinates x(q) (eq 19) as a column matrix.

        'position' gives (x, y, z), 'planar' (x, y) and 'planar_pose' (x, y, φ) with
        φ = atan2(R21, R11) the heading in the xy plane.
        """
        check_choice(task, "task", TASKS)
        p = self.position
        if task == "position":
            return sp.Matrix(p)
        if task == "planar":
            return sp.Matrix(p[:2])
        phi = sp.atan2(self.T[1, 0], self.T[0, 0])
        return sp.Matrix([p[0], p[1], phi])

    def jacobian(self, task: str = "position") -> sp.Matrix:
        """Analytical Jacobian ``J = ∂x/∂q`` (eqs 29, 32) of a task (see :meth:`task`).

        Returns:
            (m, n) sympy matrix, m = 3 ('position', 'planar_pose') or 2 ('planar').
        """
        qv = sp.Matrix(self.q)
        if task != "planar_pose":
            return self._simp(self.task(task).jacobian(qv))
        # dφ/dq of φ = atan2(R21, R11), written as (R11 dR21 − R21 dR11) / (R11² + R21²)
        c, s = self.T[0, 0], self.T[1, 0]
        dphi = ((c * sp.Matrix([s]).jacobian(qv) - s * sp.Matrix([c]).jacobian(qv))
                / (c**2 + s**2))
        return self._simp(sp.Matrix.vstack(self.position[:2, :].jacobian(qv), dphi))

    def geometric_jacobian(self) -> sp.Matrix:
        """Geometric Jacobian (eqs 33-37), rows (vx, vy, vz, wx, wy, wz), (6, n).

        Column i is ``[z_i × (p − o_i); z_i]`` for a revolute joint and ``[z_i; 0]`` for a
        prismatic one.

        ``z_i`` and ``o_i`` are joint i's axis and origin in the world frame (for standard
        DH the chapter's ``z_{i-1}``, ``p_{i-1}``). Returns a (6, n) sympy matrix.
        """
        p = self.position
        cols = []
        W = self.base
        for lk in self.links:
            F = W * lk.P
            z = F[:3, :3] * lk.axis
            o = F[:3, 3]
            if lk.type == "R":
                cols.append(sp.Matrix.vstack(z.cross(p - o), z))
            else:
                cols.append(sp.Matrix.vstack(z, sp.zeros(3, 1)))
            W = W * lk.A
        return self._simp(sp.Matrix.hstack(*cols))

    def subs(self, values: Mapping[Any, Any]) -> SymbolicKinematics:
        """Substitute symbols (e.g. rename ``a_1`` → ``L_1`` or insert numbers).

        Renamed parameters keep their numeric values in ``params``.
        """
        vals = dict(values)

        def s(M: sp.Matrix) -> sp.Matrix:
            return M.subs(vals)

        links = tuple(SymbolicLink(s(lk.P), s(lk.M), s(lk.Q), lk.axis, lk.type)
                      for lk in self.links)
        params: dict[sp.Symbol, float] = {}
        for sym, v in self.params.items():
            new = sp.sympify(vals.get(sym, sym))
            if isinstance(new, sp.Symbol):
                params[new] = v
        q = tuple(vals.get(qi, qi) for qi in self.q)
        if not all(isinstance(qi, sp.Symbol) for qi in q):
            raise InputError("subs may rename joint symbols but not replace them by values")
        return replace(self, q=q, links=links, base=s(self.base), tool=s(self.tool),
                       T=s(self.T), params=params)

    def latex(self, what: str = "T") -> str:
        """LaTeX of one result.

        ``what`` is 'T' (eq 18), 'A' (all link matrices, eqs 13-16, one per line),
        'jacobian' (position task, eq 32) or 'geometric' (eq 37).
        """
        check_choice(what, "what", ("T", "A", "jacobian", "geometric"))
        if what == "A":
            return "\n".join(
                rf"{{}}^{{{i}}}\mathbf{{A}}_{{{i + 1}}} = {sp.latex(A)}"
                for i, A in enumerate(self.A)
            )
        M = {"T": lambda: self.T, "jacobian": self.jacobian,
             "geometric": self.geometric_jacobian}[what]()
        return sp.latex(M)

    def pretty(self, M: sp.Matrix | None = None) -> str:
        """Unicode text rendering of ``M`` (default the end-effector transform)."""
        return sp.pretty(self.T if M is None else M, use_unicode=True, wrap_line=False)

    def lambdify(self, expr: sp.Matrix | None = None) -> Callable[[np.ndarray], np.ndarray]:
        """Compile a matrix expression in q (default ``T``) into ``f(q) -> ndarray``.

        Parameter symbols are replaced by their numeric values first; subexpressions
        shared by the entries (the chain's partial products) are computed once (SymPy's
        ``cse``: an unsimplified 4-joint table with every parameter symbolic compiles
        in about half the time, and evaluates faster).

        Returns:
            A function of one configuration ``q`` (n,) returning a float array of the
            expression's shape.
        """
        # xreplace, not subs: the parameters are plain symbols, replaced by numbers without
        # subs' pattern matching (a 4-joint table with every parameter symbolic: 2.4 s → ms)
        M = (self.T if expr is None else expr).xreplace(
            {sym: sp.Float(v) for sym, v in self.params.items()})
        free = M.free_symbols - set(self.q)
        if free:
            raise InputError(
                f"expression has symbols without numeric values: {sorted(map(str, free))}"
            )
        f = sp.lambdify([self.q], M, modules="numpy", cse=True)
        shape = M.shape

        def evaluate(q: np.ndarray) -> np.ndarray:
            return np.array(f(np.asarray(q, dtype=float)), dtype=float).reshape(shape)

        return evaluate


def simplify_matrix(M: sp.Matrix) -> sp.Matrix:
    """Simplify every entry of a matrix.

    Trigonometric entries go through sympy's ``fu`` (the Fu-Zhong-Zeng rule sequence,
    which folds ``cos a cos b − sin a sin b`` into ``cos(a + b)`` and is several times
    faster than ``trigsimp`` + ``simplify`` on kinematic chains); other entries through
    ``simplify``. Entries are memoised, so repeated entries and repeated calls are free.
    """
    return M.applyfunc(_simplify_entry)


@lru_cache(maxsize=4096)
def _simplify_entry(e: sp.Expr) -> sp.Expr:
    if e.is_Atom:
        return e
    if e.has(sp.sin, sp.cos):
        return sp.fu(e)
    return sp.simplify(e)


# ---------------------------------------------------------------------------- derive
def _param(value: float, name: str, angle: bool, use_symbol: bool,
           params: dict[sp.Symbol, float]) -> sp.Expr:
    e = exact(value, angle=angle)
    if use_symbol and e != 0:
        sym = sp.Symbol(name, real=True)
        params[sym] = float(value)
        return sym
    return e


def dh_link(row: DHLink, q: sp.Symbol, convention: str, index: int, params: str = "none",
            values: dict[sp.Symbol, float] | None = None) -> SymbolicLink:
    """Symbolic link ``A_i`` of one DH row (standard Rz·Tz·Tx·Rx, modified Rx·Tx·Rz·Tz).

    Args:
        row: the DH row.
        q: the joint symbol.
        convention: 'standard' or 'modified'.
        index: 1-based row index (names the parameter symbols).
        params: 'none', 'lengths' (a, d symbolic) or 'all' (also α, θ).
        values: dict collecting the numeric values of created symbols.
    """
    check_choice(convention, "convention", ("standard", "modified"))
    check_choice(params, "params", PARAM_MODES)
    values = {} if values is None else values
    lengths, angles = params in ("lengths", "all"), params == "all"
    k = index if convention == "standard" else index - 1
    a = _param(row.a, f"a_{k}", False, lengths, values)
    alpha = _param(row.alpha, f"alpha_{k}", True, angles, values)
    d = _param(row.d, f"d_{index}", False, lengths, values)
    theta = _param(row.theta, f"theta_{index}", True, angles, values)
    z = sp.Matrix([0, 0, 1])
    if row.type == "R":
        M = _rot("z", theta + q)
        fixed_z = _trans(z=d)
    else:
        M = _trans(z=d + q)
        fixed_z = _rot("z", theta)
    if convention == "standard":
        if row.type == "R":
            return SymbolicLink(sp.eye(4), M, fixed_z * _trans(x=a) * _rot("x", alpha), z, "R")
        return SymbolicLink(fixed_z, M, _trans(x=a) * _rot("x", alpha), z, "P")
    P = _rot("x", alpha) * _trans(x=a)
    if row.type == "R":
        return SymbolicLink(P, M, fixed_z, z, "R")
    return SymbolicLink(P * fixed_z, M, sp.eye(4), z, "P")


def derive(robot: Robot, *, params: str = "none", simplify: bool = True,
           q_name: str = "q") -> SymbolicKinematics:
    """Derive a robot's forward kinematics symbolically (eqs 11-18).

    DH robots use their table (standard or modified, with optional parameter symbols);
    other robots use their joints in general form ``A = origin · M(q + offset) · post``
    with exact numbers for the constant transforms.

    Args:
        robot: the robot.
        params: 'none' (numbers), 'lengths' (nonzero a, d as symbols) or 'all' (also α, θ);
            DH robots only.
        simplify: simplify ``T`` and every derived matrix (slow beyond ~6 joints: seconds
            to minutes; use False for large robots and numeric checks).
        q_name: base name of the joint symbols (``q_1 … q_n``).

    Returns:
        A :class:`SymbolicKinematics`.

    Raises:
        InputTypeError: ``robot`` is not a Robot.
        InputError: unknown ``params`` mode, or ``params`` on a robot without DH table.
    """
    if not all(hasattr(robot, a) for a in ("n", "joints", "dh", "convention", "chain")):
        raise InputTypeError(f"robot must be a serialkin Robot, got {type(robot).__name__}")
    check_choice(params, "params", PARAM_MODES)
    q = tuple(sp.Symbol(f"{q_name}_{i + 1}", real=True) for i in range(robot.n))
    values: dict[sp.Symbol, float] = {}
    links: list[SymbolicLink] = []
    if robot.dh is not None:
        for i, row in enumerate(robot.dh):
            links.append(dh_link(row, q[i], robot.convention or "standard", i + 1, params,
                                 values))
    else:
        if params != "none":
            raise InputError(
                f"params={params!r} needs a DH robot; robot {robot.name!r} has general joints"
            )
        for i, j in enumerate(robot.joints):
            axis = sp.Matrix([exact(v) for v in j.axis])
            x = q[i] + exact(j.offset, angle=j.type == "R")
            links.append(SymbolicLink(exact_matrix(j.origin), _axis_motion(axis, j.type, x),
                                      exact_matrix(j.post), axis, j.type))
    base, tool = exact_matrix(robot.base), exact_matrix(robot.tool)
    T = base
    for lk in links:
        T = T * lk.A
    T = T * tool
    if simplify:
        T = simplify_matrix(T)
    return SymbolicKinematics(name=robot.name, convention=robot.convention, q=q,
                              links=tuple(links), base=base, tool=tool, T=T,
                              params=values, simplified=simplify)


def check_against(kin: SymbolicKinematics, robot: Robot, samples: int = 5,
                  seed: None | int | np.random.Generator = None,
                  q: Sequence[np.ndarray] | None = None) -> dict[str, float]:
    """Evaluate the symbolic results on random q and compare with the numeric kernels.

    Args:
        kin: the symbolic kinematics of ``robot``.
        robot: the robot.
        samples: number of random configurations (inside the sampling limits).
        seed: random seed.
        q: explicit configurations instead of random ones, each (n,).

    Returns:
        ``{"fk": max |T_sym − robot.fk|, "geometric": max |J_sym − robot.jacobian|,
        "position_jacobian": max |∂p/∂q − J_v|}`` over the samples.
    """
    Q = list(q) if q is not None else list(robot.random_q(samples, seed=as_generator(seed)))
    fT = kin.lambdify()
    fJ = kin.lambdify(kin.geometric_jacobian())
    fP = kin.lambdify(kin.jacobian("position"))
    err = {"fk": 0.0, "geometric": 0.0, "position_jacobian": 0.0}
    for qi in Q:
        J = robot.jacobian(qi)
        err["fk"] = max(err["fk"], float(np.abs(fT(qi) - robot.fk(qi)).max()))
        err["geometric"] = max(err["geometric"], float(np.abs(fJ(qi) - J).max()))
        err["position_jacobian"] = max(err["position_jacobian"],
                                       float(np.abs(fP(qi) - J[:3]).max()))
    return err


__all__ = [
    "PARAM_MODES",
    "TASKS",
    "SymbolicKinematics",
    "SymbolicLink",
    "check_against",
    "derive",
    "dh_link",
    "exact",
    "exact_matrix",
    "simplify_matrix",
]
