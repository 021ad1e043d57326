"""Open chains: product-of-exponentials forward kinematics and :class:`SerialChain`.

Space form:  T(θ) = e^{[S1]θ1} e^{[S2]θ2} ⋯ e^{[Sn]θn} M
Body form:   T(θ) = M e^{[B1]θ1} ⋯ e^{[Bn]θn},  with B_i = Ad_{M⁻¹} S_i.
"""
from __future__ import annotations

from typing import Mapping, Sequence

import numpy as np
import sympy as sp

from ._backend import as_matrix, as_screw_list, as_thetas, describe, is_symbolic
from .codegen import CompiledMatrix
from .jacobians import _prepare, jacobian_body as _jacobian_body, jacobian_space as _jacobian_space
from .rigid import adjoint, check_se3, cross, skew, trans_inv
from .screws import _exp6

__all__ = ["fk_space", "fk_body", "SerialChain"]


def fk_space(M, Slist, thetas):
    """T(θ) = e^{[S1]θ1} ⋯ e^{[Sn]θn} M: the end-effector pose from the space screw axes."""
    symbolic = is_symbolic(M, Slist, thetas)
    M = check_se3(as_matrix(M, "M", None, symbolic), "M")
    S, th, kinds, _ = _prepare(Slist, thetas, "Slist", symbolic)
    T = sp.eye(4) if symbolic else np.eye(4)
    for i in range(S.shape[1]):
        E = _exp6(S[:, i], th[i], kinds[i], symbolic)
        T = T * E if symbolic else T @ E
    return T * M if symbolic else T @ M


def fk_body(M, Blist, thetas):
    """T(θ) = M e^{[B1]θ1} ⋯ e^{[Bn]θn}: the end-effector pose from the body screw axes."""
    symbolic = is_symbolic(M, Blist, thetas)
    M = check_se3(as_matrix(M, "M", None, symbolic), "M")
    B, th, kinds, _ = _prepare(Blist, thetas, "Blist", symbolic)
    T = M
    for i in range(B.shape[1]):
        E = _exp6(B[:, i], th[i], kinds[i], symbolic)
        T = T * E if symbolic else T @ E
    return T


def _joint_symbols(n: int):
    return sp.symbols(f"theta1:{n + 1}", real=True)


class SerialChain:
    """A named open chain: home pose ``M`` and space screw axes ``screws`` (6×n, one per column).

    ``thetas`` are its joint symbols (θ1…θn by default), ``joint_types`` 'R'/'P' per joint,
    ``joint_points`` a point on each joint axis at home (3×n, used to draw the chain), and
    ``params`` the free symbols besides the joints (link lengths).

    Every kinematic method takes ``q``:

    * omitted: the exact SymPy result in ``thetas``;
    * SymPy values: the exact result at ``q`` (substituted);
    * numbers, shape (n,) or a batch (N, n): NumPy floats, from code generated once per chain from
      the unsimplified expression with common-subexpression elimination.
    """

    def __init__(self, M, screws, *, name: str = "chain", thetas: Sequence[sp.Symbol] | None = None,
                 joint_points=None, description: str = ""):
        M = check_se3(as_matrix(M, "M", None, True), "M")
        S = as_screw_list(screws, "screws", True)
        n = S.shape[1]
        if thetas is None:
            thetas = _joint_symbols(n)
        thetas = tuple(thetas)
        if len(thetas) != n or not all(isinstance(t, sp.Symbol) for t in thetas):
            raise ValueError(f"thetas must be {n} SymPy symbols (one per screw axis), got {describe(list(thetas))}")
        _, _, kinds, _ = _prepare(S, list(thetas), "screws")
        self.name = name
        self.description = description
        self.M = M
        self.screws = S
        self.thetas = thetas
        self.n = n
        self.joint_types = "".join(kinds)
        if joint_points is None:
            pts = []
            for i in range(n):
                w, v = S[:3, i], S[3:, i]
                pts.append(cross(w, v) if kinds[i] == "R" else sp.zeros(3, 1))
            joint_points = sp.Matrix.hstack(*pts)
        else:
            jp = joint_points
            if isinstance(jp, (list, tuple)) and len(jp) == n and all(np.size(p) == 3 for p in jp):
                jp = sp.Matrix.hstack(*[sp.Matrix(list(p)) for p in jp])
            joint_points = as_matrix(jp, "joint_points", (3, n), True)
        self.joint_points = joint_points
        syms = set().union(M.free_symbols, S.free_symbols, joint_points.free_symbols)
        self.params = tuple(sorted(syms - set(thetas), key=str))
        self._sym: dict[str, sp.Matrix] = {}
        self._num: dict[str, CompiledMatrix] = {}

    # --- the book's objects ------------------------------------------------------------------
    @property
    def body_screws(self) -> sp.Matrix:
        """B_i = Ad_{M⁻¹} S_i (6×n, one per column)."""
        return adjoint(trans_inv(self.M)) * self.screws

    def subs(self, values: Mapping | None = None, **by_name) -> "SerialChain":
        """A copy with parameters replaced: ``chain.subs(L=1)`` or ``chain.subs({L: 1})``."""
        table = dict(values or {})
        names = {str(p): p for p in self.params}
        for k, v in by_name.items():
            if k not in names:
                raise ValueError(f"{self.name} has no parameter {k!r}; its parameters are {sorted(names)}")
            table[names[k]] = v
        table = {k: sp.nsimplify(v, rational=True) if isinstance(v, float) else sp.sympify(v) for k, v in table.items()}
        return SerialChain(self.M.subs(table), self.screws.subs(table), name=self.name, thetas=self.thetas,
                           joint_points=self.joint_points.subs(table), description=self.description)

    def __repr__(self) -> str:
        params = ", ".join(map(str, self.params)) or "none"
        return f"SerialChain({self.name!r}, joints={self.joint_types!r}, parameters: {params})"

    # --- symbolic expressions (cached, unsimplified) -------------------------------------------
    def _expr(self, what: str) -> sp.Matrix:
        if what not in self._sym:
            th = list(self.thetas)
            if what == "fk":
                e = fk_space(self.M, self.screws, th)
            elif what == "js":
                e = _jacobian_space(self.screws, th)
            elif what == "jb":
                e = _jacobian_body(self.body_screws, th)
            elif what == "jg":  # = space_to_geometric(J_s, T) without re-checking T (its SE(3) check costs seconds on big T)
                js, p = self._expr("js"), self._expr("fk")[:3, 3]
                e = sp.Matrix.vstack(js[:3, :], js[3:, :] - skew(p) * js[:3, :])
            elif what in ("fk_num", "js_num", "jb_num", "jg_num"):
                e = self._numeric_form(what[:2])
            elif what == "skeleton":
                e = self._skeleton_expr()
            else:  # pragma: no cover
                raise KeyError(what)
            self._sym[what] = e
        return self._sym[what]

    def _numeric_form(self, what: str) -> sp.Matrix:
        """The same matrix as ``_expr(what)``, built so that cse leaves few operations (150–190
        instead of 240–300 for the UR5): the form the numeric code is generated from.

        With E_i = e^{[S_i]θ_i}, S_i = [ω_i; v_i], R_i = rot(E_1)⋯rot(E_{i−1}) and points carried by
        the E's one at a time (E(x) = rot(E) x + trans(E)) rather than whole 4×4 products:

        * T:   rot(E_1)⋯rot(E_n) rot(M) and position E_1(E_2(⋯E_n(p_M)));
        * J_s: column i = [R_i ω_i; R_i (v_i + ω_i × g_i)] = Ad_{T_{i−1}} S_i, with
          g_i = E_{i−1}⁻¹(⋯E_1⁻¹(0)) the base origin seen from T_{i−1} = E_1⋯E_{i−1};
        * J:   column i = [R_i ω_i; R_i (v_i + ω_i × p_i)] = [ω_s; ṗ] column, p_i = E_i(⋯E_n(p_M));
        * J_b: column i = [Q_iᵀ β_i; Q_iᵀ (ν_i + β_i × u_i)] = Ad_{U_i⁻¹} B_i, with B_i = [β_i; ν_i] and
          (Q_i, u_i) = U_i = e^{[B_{i+1}]θ_{i+1}}⋯e^{[B_n]θ_n}.
        """
        _, th, kinds, _ = _prepare(self.screws, list(self.thetas), "screws")
        n = self.n
        if what == "jb":
            B = self.body_screws
            cols, Q, u = [None] * n, sp.eye(3), sp.zeros(3, 1)
            for i in reversed(range(n)):
                b, nu = B[:3, i], B[3:, i]
                cols[i] = sp.Matrix.vstack(Q.T * b, Q.T * (nu + cross(b, u)))
                E = _exp6(B[:, i], th[i], kinds[i], True)
                Q, u = E[:3, :3] * Q, E[:3, :3] * u + E[:3, 3]
            return sp.Matrix.hstack(*cols)
        E = [_exp6(self.screws[:, i], th[i], kinds[i], True) for i in range(n)]
        R = [sp.eye(3)]  # R[i] = rot(E_1)⋯rot(E_i)
        for i in range(n):
            R.append(R[-1] * E[i][:3, :3])
        tail = [self.M[:3, 3]]  # tail[k] = E_{n−k+1}(⋯E_n(p_M)): tail[0] = p_M, tail[n] = p(θ)
        for i in reversed(range(n)):
            tail.append(E[i][:3, :3] * tail[-1] + E[i][:3, 3])
        if what == "fk":
            return sp.Matrix.vstack(sp.Matrix.hstack(R[n] * self.M[:3, :3], tail[n]), sp.Matrix([[0, 0, 0, 1]]))
        cols, g = [], sp.zeros(3, 1)
        for i in range(n):
            w, v = self.screws[:3, i], self.screws[3:, i]
            x = g if what == "js" else tail[n - i]
            cols.append(sp.Matrix.vstack(R[i] * w, R[i] * (v + cross(w, x))))
            if what == "js":
                Einv = _exp6(self.screws[:, i], -th[i], kinds[i], True)
                g = Einv[:3, :3] * g + Einv[:3, 3]
        return sp.Matrix.hstack(*cols)

    def _skeleton_expr(self) -> sp.Matrix:
        """Columns: the base origin, each joint point carried by the links before it, the tool origin."""
        cols = [sp.zeros(3, 1)]
        T = sp.eye(4)
        _, th, kinds, _ = _prepare(self.screws, list(self.thetas), "screws")
        for i in range(self.n):
            q = self.joint_points[:, i]
            cols.append(T[:3, :3] * q + T[:3, 3])
            T = T * _exp6(self.screws[:, i], th[i], kinds[i], True)
        cols.append(self._expr("fk")[:3, 3])
        return sp.Matrix.hstack(*cols)

    def _eval(self, what: str, q):
        if type(q) is np.ndarray and q.dtype.kind == "f":  # fast path: a float array, code already generated
            c = self._num.get(what)
            if c is not None:
                return c._single(q.tolist()) if q.shape == (self.n,) else c(q)
        expr = self._expr(what)
        if q is None:
            return expr
        if is_symbolic(q):
            qs = q if not isinstance(q, sp.MatrixBase) else list(q)
            if isinstance(qs, (sp.Basic,)) and self.n == 1:
                qs = [qs]
            if not isinstance(qs, (list, tuple)) or len(qs) != self.n:
                raise ValueError(f"q must hold {self.n} joint values for {self.name}, got {describe(q)}")
            vals = list(as_thetas(qs, self.n, "q", True))  # rejects strings (sympify would make symbols)
            return expr.xreplace(dict(zip(self.thetas, vals))) if all(v.is_Atom for v in vals) \
                else expr.subs(dict(zip(self.thetas, vals)), simultaneous=True)
        return self._compiled(what)(q)

    def _compiled(self, what: str) -> CompiledMatrix:
        if what not in self._num:
            if self.params:
                raise ValueError(
                    f"{self.name} has symbolic parameters {', '.join(map(str, self.params))}: give them numbers "
                    f"first, e.g. chain.subs({str(self.params[0])}=1), or pass SymPy joint values for an exact result")
            expr = self._expr(what + "_num" if what in ("fk", "js", "jb", "jg") else what)
            self._num[what] = CompiledMatrix(expr, self.thetas, f"{self.name}.{what}")
        return self._num[what]

    # --- kinematics ------------------------------------------------------------------------------
    def fk(self, q=None):
        """T(θ) = e^{[S1]θ1} ⋯ e^{[Sn]θn} M (4×4; (N, 4, 4) for a batch)."""
        return self._eval("fk", q)

    def jacobian_space(self, q=None):
        """Space Jacobian J_s(θ), rows [ω; v] (6×n; (N, 6, n) for a batch): V_s = J_s θ̇."""
        return self._eval("js", q)

    def jacobian_body(self, q=None):
        """Body Jacobian J_b(θ) = Ad_{T⁻¹} J_s, rows [ω; v]: V_b = J_b θ̇."""
        return self._eval("jb", q)

    def jacobian_geometric(self, q=None):
        """Geometric Jacobian J(θ) = blockdiag(R, R) J_b, rows [ω_s; ṗ]: angular velocity and tool-origin velocity in {s}."""
        return self._eval("jg", q)

    def skeleton(self, q=None):
        """Points to draw the chain (3×(n+2)): base origin, each joint point, tool origin; (N, 3, n+2) for a batch."""
        return self._eval("skeleton", q)
