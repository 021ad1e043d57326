"""Open chains: product-of-exponentials forward kinematics and :class:`SerialChain`.

Space form:  T(θ) = e^{[S1]θ1} e^{[S2]θ2} ⋯ e^{[Sn]θn} M
Body form:   T(θ) = M e^{[B1]θ1} ⋯ e^{[Bn]θn},  with B_i = Ad_{M⁻¹} S_i.
"""

from __future__ import annotations

import math
import numbers
from collections.abc import Mapping, Sequence

import numpy as np
import sympy as sp

from .._backend import (
    as_matrix,
    as_screw_list,
    as_thetas,
    as_vector,
    describe,
    exact_number,
    is_symbolic,
    joint_symbols,
)
from ..fast.codegen import CompiledMatrix
from ..fast.tape import Tape
from .jacobians import jacobian_body as _jacobian_body
from .jacobians import jacobian_space as _jacobian_space
from .poe import checked_screw_list, fk_body, fk_space
from .rigid import adjoint, check_se3, cross, skew, trans_inv

__all__ = ["fk_space", "fk_body", "SerialChain"]


_F8 = np.dtype(float)


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

    The chain is exact: numbers in ``M`` and ``screws`` (lists, NumPy arrays, Python/NumPy/SymPy floats)
    become the exact decimal typed (0.1 → 1/10, 2.0 → 2; ``kinlib._backend.exact_number``), so a chain
    built from lists equals one built from ``sp.Matrix``. Float axes that are unit only to rounding
    (0.7071067811865476, or axes computed by rotating) are accepted when | |ω|² − 1 | ≤ 1e-9 and kept as
    typed: results are exact for the numbers typed (type ``sp.sqrt(2)/2`` for an exactly unit axis).
    Refused, naming the argument: NaN/inf, complex numbers and ``sp.I``, strings, bools, None, symbols not
    declared real (joint symbols and parameters alike), wrong shapes; q likewise (NaN joint values too).

    ``placements`` (optional; :func:`kinlib.robots.from_urdf_joints` gives them): ``(C, axes)``, the chain as
    URDF writes it, T(θ) = C_1 e^{[â_1]θ1} C_2 ⋯ C_n e^{[â_n]θn} C_{n+1}, with C_i (n + 1 exact 4×4 transforms) the
    constant placement of joint i's frame in the previous one (C_{n+1}: the tool in the last joint's frame) and
    â_i (n unit 3-vectors) the joint axis in joint i's frame; they must agree with ``M`` and ``screws``
    (S_i = Ad_{C_1⋯C_i} [â_i; 0] or [0; â_i], M = C_1⋯C_{n+1}). Only the generated numeric code of ``fk``,
    ``jacobian_space`` and ``jacobian_geometric`` uses them: constant placements folded into floats, rotations
    about axes that are coordinate axes in their own frames, so a URDF arm's code is short (its space screw
    axes, dense in every entry, would not be). Entries of a placement's rotation within 2⁻⁵⁰ of 0 (cos of a
    typed 1.5707963267948966 is 6e-17) are 0 in that code: below the resolution of the typed angles.

    >>> chain = SerialChain([[1, 0, 0, 2.0], [0, 1, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1]],
    ...                     [[0, 0, 1, 0, 0, 0], [0, 0, 1, 0, -1.0, 0]])
    >>> chain.screws.T, chain.params
    (Matrix([
    [0, 0, 1, 0,  0, 0],
    [0, 0, 1, 0, -1, 0]]), ())
    >>> float(chain.fk([0.0, 0.0])[0, 3])
    2.0
    """

    def __init__(
        self,
        M,
        screws,
        *,
        name: str = "chain",
        thetas: Sequence[sp.Symbol] | None = None,
        joint_points=None,
        description: str = "",
        placements=None,
    ):
        for arg, value in (("name", name), ("description", description)):
            if not isinstance(value, str):
                raise TypeError(f"{arg} must be a string, got {describe(value)}")
        # numbers become exact here (0.1 -> 1/10, 2.0 -> 2, sp.Float too); NaN, inf, I, strings, bools,
        # non-real symbols are refused, each naming M or screws[i]
        M = check_se3(as_matrix(M, "M", None, True, real_symbols=True), "M")
        S = as_screw_list(screws, "screws", True)
        n = S.shape[1]
        if thetas is None:
            thetas = _joint_symbols(n)
        thetas = joint_symbols(thetas, n, per="one per screw axis")
        _, _, kinds, _ = checked_screw_list(S, list(thetas), "screws")
        self.name = name
        self.description = description
        self.M = M
        self.screws = S
        self.thetas = thetas
        self.n = n
        self._vec_shape = (n,)  # the shape of one configuration (the fast path compares it)
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
                jp = sp.Matrix.hstack(
                    *[as_vector(p, f"joint_points[{i}]", 3, True, real_symbols=True) for i, p in enumerate(jp)]
                )
            joint_points = as_matrix(jp, "joint_points", (3, n), True, real_symbols=True)
        self.joint_points = joint_points
        syms = set().union(M.free_symbols, S.free_symbols, joint_points.free_symbols)
        self.params = tuple(sorted(syms - set(thetas), key=str))
        self._placements = None if placements is None else _check_placements(placements, M, S, kinds)
        self._sym: dict[str, sp.Matrix] = {}
        self._num: dict[str, CompiledMatrix] = {}
        self._numeric_cache: dict[tuple, SerialChain] = {}

    # --- the book's objects ------------------------------------------------------------------
    @property
    def body_screws(self) -> sp.Matrix:
        """B_i = Ad_{M⁻¹} S_i (6×n, one per column).

        >>> from kinlib.robots import planar_2r
        >>> planar_2r().body_screws.T   # the joint axes seen from the tool frame at home
        Matrix([
        [0, 0, 1, 0, L1 + L2, 0],
        [0, 0, 1, 0,      L2, 0]])
        """
        return adjoint(trans_inv(self.M)) * self.screws

    def subs(self, values: Mapping | None = None, **by_name) -> SerialChain:
        """A copy with parameters replaced: ``chain.subs(L=1)`` or ``chain.subs({L: 1})``.

        Values become exact as typed (``kinlib._backend.exact_number``: 0.1 → 1/10, 2.0 → 2) or are
        real SymPy expressions; keys are the chain's parameters (symbols or their names).

        >>> from kinlib import robots
        >>> robots.planar_offset_3r().subs(L=0.1).M[0, 3]
        3/10
        """
        if values is not None and not isinstance(values, Mapping):
            raise TypeError(f"values must be a mapping {{parameter: value}}, got {describe(values)}")
        names = {str(p): p for p in self.params}
        table = {}
        for k, v in list((values or {}).items()) + list(by_name.items()):
            key = names.get(k) if isinstance(k, str) else k if k in self.params else None
            if key is None:
                raise ValueError(f"{self.name} has no parameter {k!r}; its parameters are {sorted(names)}")
            table[key] = exact_number(v, str(key))
        return SerialChain(
            self.M.subs(table),
            self.screws.subs(table),
            name=self.name,
            thetas=self.thetas,
            joint_points=self.joint_points.subs(table),
            description=self.description,
            placements=None
            if self._placements is None
            else ([C.subs(table) for C in self._placements[0]], [a.subs(table) for a in self._placements[1]]),
        )

    def numeric(self, params: Mapping | None = None) -> SerialChain:
        """The chain with numbers for all its parameters (link lengths), ready to draw or evaluate fast.

        ``params`` maps parameters (symbols or their names) to numbers, as :meth:`subs`; the chain itself when
        it has no parameters left. A ValueError names the parameters still symbolic. Results are cached on the
        chain (so repeated calls with the same numbers, e.g. from a slider, return the same chain).

        >>> from kinlib import robots
        >>> robots.planar_2r().numeric({"L1": 1, "L2": 0.5}).M[0, 3]
        3/2
        >>> robots.planar_2r().numeric({"L1": 1})
        Traceback (most recent call last):
        ...
        ValueError: planar_2r still has the symbolic parameter(s) L2: give numbers for them, e.g. params={'L2': 1}
        """
        if params is not None and not isinstance(params, Mapping):
            raise TypeError(f"params must be a dict of parameter values like {{'L': 1}}, got {describe(params)}")
        chain = self
        if params:
            key = tuple(sorted((str(k), repr(v)) for k, v in params.items()))
            chain = self._numeric_cache.get(key)
            if chain is None:
                for k, v in params.items():
                    if isinstance(v, sp.Basic) and v.free_symbols:
                        raise ValueError(f"params[{str(k)!r}] must be a number, got {describe(v)}")
                chain = self.subs(params)
                self._numeric_cache[key] = chain
        if chain.params:
            left = ", ".join(map(str, chain.params))
            raise ValueError(
                f"{self.name} still has the symbolic parameter(s) {left}: give numbers for them, "
                f"e.g. params={{{str(chain.params[0])!r}: 1}}"
            )
        return chain

    def joint_index(self, joint, name: str = "joint") -> int:
        """0-based index of a joint given as its number 1…n (θ1…θn), its symbol, or its symbol's name.

        >>> from kinlib import robots
        >>> r = robots.planar_2r()
        >>> r.joint_index(2), r.joint_index(r.thetas[0]), r.joint_index("theta2")
        (1, 0, 1)
        """
        if isinstance(joint, sp.Symbol):
            if joint in self.thetas:
                return self.thetas.index(joint)
            raise ValueError(f"{name}: {joint} is not a joint of {self.name} (joints {self.thetas}); got {joint}")
        if isinstance(joint, str):
            for i, t in enumerate(self.thetas):
                if str(t) == joint:
                    return i
            raise ValueError(
                f"{name}: not a joint of {self.name} (joints {tuple(map(str, self.thetas))}); got {joint!r}"
            )
        if isinstance(joint, (numbers.Integral, np.integer)) and not isinstance(joint, (bool, np.bool_)):
            if 1 <= joint <= self.n:
                return int(joint) - 1
            raise ValueError(
                f"{name} must be a joint number 1..{self.n} (as in θ1..θ{self.n}) for {self.name}, got {joint}"
            )
        raise TypeError(f"{name} must be a joint number 1..{self.n}, a joint symbol or its name, got {describe(joint)}")

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
            elif (
                what == "jg"
            ):  # = space_to_geometric(J_s, T) without re-checking T (its SE(3) check costs seconds on big T)
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
        """The same matrix as ``_expr(what)`` (exactly), by the recursions the numeric code is generated
        from (:func:`_poe_rows`: 3×3 and 3-lists, no 4×4 products), which leave few operations.

        With E_i = e^{[S_i]θ_i}, S_i = [ω_i; v_i], R_i = rot(E_1)⋯rot(E_{i−1}) and points carried by
        the E's one at a time (E(x) = rot(E) x + trans(E)) rather than whole 4×4 products:

        * T:   rot(E_1)⋯rot(E_n) rot(M) and position E_1(E_2(⋯E_n(p_M)));
        * J_s: column i = [R_i ω_i; R_i (v_i + ω_i × g_i)] = Ad_{T_{i−1}} S_i, with
          g_i = E_{i−1}⁻¹(⋯E_1⁻¹(0)) the base origin seen from T_{i−1} = E_1⋯E_{i−1};
        * J:   column i = [R_i ω_i; R_i (v_i + ω_i × p_i)] = [ω_s; ṗ] column, p_i = E_i(⋯E_n(p_M));
        * J_b: column i = [Q_iᵀ β_i; Q_iᵀ (ν_i + β_i × u_i)] = Ad_{U_i⁻¹} B_i, with B_i = [β_i; ν_i] and
          (Q_i, u_i) = U_i = e^{[B_{i+1}]θ_{i+1}}⋯e^{[B_n]θ_n};
        * skeleton: the base origin, each joint point carried by E_1⋯E_{i−1}, the tool origin;

        each E_i = (K0 + sin θ K1 + cos θ K2, θ a + b − cos θ b − sin θ d) with constants from S_i
        (Rodrigues' formula, see :func:`_exp_constants`).
        """
        th = self.thetas
        return sp.Matrix(_poe_rows(self, what, lambda x: x, lambda i: (sp.sin(th[i]), sp.cos(th[i]), th[i])))

    def _skeleton_expr(self) -> sp.Matrix:
        """Columns: the base origin, each joint point carried by the links before it, the tool origin."""
        return self._numeric_form("skeleton")

    def _eval(self, what: str, q):
        c = self._num.get(what)
        if c is not None and c._fast is not None and (out := c._fast(q)) is not None:
            return out  # compiled C (kinlib.native) took a plain finite joint vector; None: the paths below
        if type(q) is np.ndarray and q.dtype is _F8:  # fast path: a float64 array, code already generated
            if c is not None:
                if q.shape == self._vec_shape:
                    v = q.tolist()
                    t = sum(v)  # nan/inf anywhere makes t − t nan (≈ 80 ns; np.isfinite(q).all() ≈ 1 µs);
                    if t - t == 0.0:  # the rare finite q whose sum overflows just takes the checked path below
                        return c._single(v)
                elif q.ndim == 2 and q.shape[1] == self.n and np.isfinite(q).all():
                    return c(q)
        elif type(q) is list or type(q) is tuple:  # plain floats (and small ints): no array needed
            if (
                c is not None
                and len(q) == self.n
                and all(isinstance(v, float) and v - v == 0.0 or type(v) is int and -(2**53) <= v <= 2**53 for v in q)
            ):
                return c._single(q)  # floats incl. np.float64; v - v == 0.0 is False for nan and ±inf
        if q is None:
            return self._expr(what)
        if is_symbolic(q):
            expr = self._expr(what)  # numbers need only the generated code, not the whole symbolic matrix
            qs = q if not isinstance(q, sp.MatrixBase) else list(q)
            if isinstance(qs, (sp.Basic,)) and self.n == 1:
                qs = [qs]
            if not isinstance(qs, (list, tuple)) or len(qs) != self.n:
                raise ValueError(f"q must hold {self.n} joint values for {self.name}, got {describe(q)}")
            # exact values (0.5 -> 1/2); I, nan, oo, strings, bools, non-real symbols refused
            vals = list(as_thetas(qs, self.n, "q", True))
            return (
                expr.xreplace(dict(zip(self.thetas, vals)))
                if all(v.is_Atom for v in vals)
                else expr.subs(dict(zip(self.thetas, vals)), simultaneous=True)
            )
        q = self._joint_values(q)  # checked before any code generation (a bad q is named first)
        return self._compiled(what)(q)

    def _joint_values(self, q):
        """q as a float array (n,) or (N, n) of finite real numbers; a clear error for anything else."""
        n = self.n
        want = f"{n} real joint values (or an (N, {n}) batch)"
        if type(q) in (list, tuple) and len(q) == n and all(isinstance(v, float) for v in q):
            arr = np.array(q, dtype=float)  # the common case: plain floats
        elif isinstance(q, np.ndarray) and q.dtype.kind in "fiu":
            arr = q.astype(float, copy=False)
        elif isinstance(q, (list, tuple, np.ndarray)):
            obj = np.asarray(q, dtype=object) if not isinstance(q, np.ndarray) else q
            if obj.ndim not in (1, 2) or obj.shape[-1] != n:
                raise ValueError(f"q must have shape ({n},) or (N, {n}) for this {n}-joint chain, got {describe(q)}")
            for idx in np.ndindex(obj.shape):
                e = obj[idx]
                if isinstance(e, (bool, np.bool_, str, bytes, complex, np.complexfloating)) or not isinstance(
                    e, (numbers.Real, np.integer, np.floating)
                ):
                    raise TypeError(f"q must hold {want}, got {describe(q)} whose entry {list(idx)} is {describe(e)}")
            try:
                arr = np.array(obj.tolist(), dtype=float)
            except OverflowError:
                raise ValueError(
                    f"q must hold {want}, got {describe(q)} with an integer too large for a float"
                ) from None
        else:
            raise TypeError(f"q must hold {want}, got {describe(q)}")
        if arr.ndim not in (1, 2) or arr.shape[-1] != n:
            raise ValueError(f"q must have shape ({n},) or (N, {n}) for this {n}-joint chain, got {describe(q)}")
        if not np.isfinite(arr).all():
            bad = np.argwhere(~np.isfinite(arr))[0]
            raise ValueError(
                f"q must hold {n} finite real joint values, got {describe(q)} whose entry "
                f"{bad.tolist()} is {float(arr[tuple(bad)])!r}"
            )
        return arr

    def _compiled(self, what: str) -> CompiledMatrix:
        """The generated code for ``what`` (fk, js, jb, jg, skeleton), made on first use.

        The recursions of :meth:`_numeric_form` are run once on a :class:`~kinlib.tape.Tape`,
        with the chain's exact constants rounded to floats (exact zeros kept), and ``sympy.cse`` picks
        the temporaries of what was recorded: straight-line code equal to the exact product of
        exponentials to rounding, in 0.1–0.4 s for a dense 7-joint arm whatever the size of the
        chain's exact numbers (no exact SymPy arithmetic on the whole chain; the batched code is
        generated on the first batched call). A chain with ``placements`` (from URDF) also records fk, J_s
        and the geometric J as constant placements times rotations about the joints' own axes
        (:func:`_local_rows`) and compiles whichever recording has fewer operations."""
        if what not in self._num:
            if self.params:
                raise ValueError(
                    f"{self.name} has symbolic parameters {', '.join(map(str, self.params))}: give them numbers "
                    f"first, e.g. chain.subs({str(self.params[0])}=1), or pass SymPy joint values for an exact result"
                )
            tp = Tape(self.n)
            rows = _poe_rows(self, what, _float_constant, lambda i: (tp.sin(i), tp.cos(i), tp.q(i)))
            if self._placements is not None and what in ("fk", "js", "jg"):
                # the URDF's placements usually leave fewer operations (sparse rotations in their own frames);
                # a placement with a rotation entry that is small but not negligible (cos of an 11-digit π/2)
                # may not: record both, compile the shorter
                tl = Tape(self.n)
                local = _local_rows(self, what, lambda i: (tl.sin(i), tl.cos(i), tl.q(i)))
                if tl.operation_count(local) < tp.operation_count(rows):
                    tp, rows = tl, local
            self._num[what] = tp.compile(rows, self.thetas, f"{self.name}.{what}")
        return self._num[what]

    def numeric_code(self, what: str) -> CompiledMatrix:
        """The generated numeric code behind the float path of ``fk`` (``"fk"``), ``jacobian_space`` (``"js"``),
        ``jacobian_body`` (``"jb"``), ``jacobian_geometric`` (``"jg"``) and ``skeleton`` (``"skeleton"``): a
        :class:`~kinlib.codegen.CompiledMatrix` (its ``source``; ``javascript(name)`` prints the same cse'd
        expressions as JavaScript, for :mod:`kinlib.widgets`). Numeric chains only.

        >>> from kinlib.robots import planar_2r
        >>> planar_2r(1, 1).numeric_code("skeleton").shape
        (3, 4)
        """
        if what not in ("fk", "js", "jb", "jg", "skeleton"):
            raise ValueError(f"what must be one of 'fk', 'js', 'jb', 'jg', 'skeleton', got {what!r}")
        return self._compiled(what)

    # --- kinematics ------------------------------------------------------------------------------
    def fk(self, q=None):
        """T(θ) = e^{[S1]θ1} ⋯ e^{[Sn]θn} M (4×4; (N, 4, 4) for a batch).

        >>> import numpy as np, sympy as sp
        >>> from kinlib.robots import planar_2r
        >>> planar_2r().fk([0, sp.pi / 2])   # SymPy values: exact; the elbow bent a right angle, tool at (L1, L2)
        Matrix([
        [0, -1, 0, L1],
        [1,  0, 0, L2],
        [0,  0, 1,  0],
        [0,  0, 0,  1]])
        >>> planar_2r(1, 1).fk(np.zeros((5, 2))).shape   # numbers: a batch of 5 configurations, floats
        (5, 4, 4)
        """
        return self._eval("fk", q)

    def jacobian_space(self, q=None):
        """Space Jacobian J_s(θ), rows [ω; v] (6×n; (N, 6, n) for a batch): V_s = J_s θ̇.

        >>> from kinlib.robots import planar_2r
        >>> planar_2r().jacobian_space().T   # q omitted: exact in θ1, θ2 (J_s never depends on the last joint)
        Matrix([
        [0, 0, 1,              0,               0, 0],
        [0, 0, 1, L1*sin(theta1), -L1*cos(theta1), 0]])
        """
        return self._eval("js", q)

    def jacobian_body(self, q=None):
        """Body Jacobian J_b(θ) = Ad_{T⁻¹} J_s, rows [ω; v]: V_b = J_b θ̇.

        >>> import sympy as sp
        >>> from kinlib.rigid import adjoint, trans_inv
        >>> from kinlib.robots import planar_3r
        >>> r, q = planar_3r(), [0, sp.pi / 2, 0]
        >>> r.jacobian_body(q)[[2, 3, 4], :]   # rows ω_z, v_x, v_y in the tool frame
        Matrix([
        [      1,       1,  1],
        [     L1,       0,  0],
        [L2 + L3, L2 + L3, L3]])
        >>> r.jacobian_body(q) == adjoint(trans_inv(r.fk(q))) * r.jacobian_space(q)
        True
        """
        return self._eval("jb", q)

    def jacobian_geometric(self, q=None):
        """Geometric Jacobian J(θ) = blockdiag(R, R) J_b, rows [ω_s; ṗ]: angular velocity and tool-origin
        velocity in {s}.

        >>> import numpy as np
        >>> from kinlib.robots import planar_2r
        >>> J = planar_2r(1, 1).jacobian_geometric([0.0, np.pi / 2])
        >>> (J[[3, 4]].round(3) + 0.0).tolist()   # rows ṗ_x, ṗ_y
        [[-1.0, -1.0], [1.0, 0.0]]
        >>> round(float(np.linalg.det(J[[3, 4]])), 3)   # L1 L2 sin θ2
        1.0
        """
        return self._eval("jg", q)

    def skeleton(self, q=None):
        """Points to draw the chain (3×(n+2)): base origin, each joint point, tool origin; (N, 3, n+2) for a batch.

        >>> import sympy as sp
        >>> from kinlib.robots import planar_2r
        >>> planar_2r().skeleton([0, sp.pi / 2])   # columns: base origin, joint 1, joint 2, tool origin
        Matrix([
        [0, 0, L1, L1],
        [0, 0,  0, L2],
        [0, 0,  0,  0]])
        """
        return self._eval("skeleton", q)


# --- the recursions behind SerialChain._numeric_form and the generated code (issue 11, item 6) --------
# Written once over plain 3-lists and 3×3 lists with + − ×, so the same lines run in exact SymPy
# (the numeric forms, proved equal to the PoE expressions by tests) and on a tape.Tape (the code:
# constants as floats, a few µs per operation, whatever the size of the chain's exact numbers).
_I3 = ((1, 0, 0), (0, 1, 0), (0, 0, 1))


def _mv(A, x):
    return [A[i][0] * x[0] + A[i][1] * x[1] + A[i][2] * x[2] for i in range(3)]


def _mtv(A, x):  # Aᵀx
    return [A[0][i] * x[0] + A[1][i] * x[1] + A[2][i] * x[2] for i in range(3)]


def _mm(A, B):
    return [[A[i][0] * B[0][j] + A[i][1] * B[1][j] + A[i][2] * B[2][j] for j in range(3)] for i in range(3)]


def _vadd(x, y):
    return [x[0] + y[0], x[1] + y[1], x[2] + y[2]]


def _vcross(a, b):
    return [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]


def _exp_constants(S, kind: str, num):
    """The constants of E(θ) = e^{[S]θ} for S = [ω; v] (exact SymPy in, ``num`` applied to each):

    revolute  rot = K0 + sin θ K1 + cos θ K2 with K0 = I + [ω]², K1 = [ω], K2 = −[ω]² (Rodrigues),
              trans = θ a + b − cos θ b − sin θ d with a = (I + [ω]²) v, b = [ω] v, d = [ω]² v;
    prismatic rot = I, trans = θ v.
    """
    w, v = list(S[:3]), list(S[3:])
    if kind == "P":
        return ("P", [num(x) for x in v])
    W = [[0, -w[2], w[1]], [w[2], 0, -w[0]], [-w[1], w[0], 0]]
    W2 = _mm(W, W)
    K0 = [[_I3[i][j] + W2[i][j] for j in range(3)] for i in range(3)]
    d, b = _mv(W2, v), _mv(W, v)
    a = _vadd(v, d)
    return (
        "R",
        [[num(x) for x in row] for row in K0],
        [[num(x) for x in row] for row in W],
        [[num(-x) for x in row] for row in W2],
        [num(x) for x in a],
        [num(x) for x in b],
        [num(x) for x in d],
    )


def _exp_apply(C, s, c, th, sign: int = 1):
    """(rot, trans) of e^{±[S]θ} from :func:`_exp_constants` and sin θ, cos θ, θ (sign −1: the inverse)."""
    if C[0] == "P":
        return _I3, [x * th * sign for x in C[1]]
    _, K0, K1, K2, a, b, d = C
    ss, tt = s * sign, th * sign
    rot = [[K0[i][j] + ss * K1[i][j] + c * K2[i][j] for j in range(3)] for i in range(3)]
    trans = [tt * a[i] + b[i] - c * b[i] - ss * d[i] for i in range(3)]
    return rot, trans


def _body_screw_columns(M, S):
    """B_i = Ad_{M⁻¹} S_i = [Rᵀω_i; Rᵀ(v_i + ω_i × p)] for M = (R, p), exact, as 6-lists."""
    R = [[M[i, j] for j in range(3)] for i in range(3)]
    p = [M[i, 3] for i in range(3)]
    cols = []
    for k in range(S.shape[1]):
        w, v = list(S[:3, k]), list(S[3:, k])
        cols.append(_mtv(R, w) + _mtv(R, _vadd(v, _vcross(w, p))))
    return cols


def _poe_rows(chain, what: str, num, joint):
    """Rows of T, J_s, J_b, the geometric J or the skeleton of ``chain`` by the recursions of
    :meth:`SerialChain._numeric_form`, in the arithmetic given by ``num`` (an exact constant into it)
    and ``joint(i)`` → (sin θ_i, cos θ_i, θ_i)."""
    if what == "jb":
        return _body_jacobian_rows(chain, num, joint)
    C = [_exp_constants(chain.screws[:, i], chain.joint_types[i], num) for i in range(chain.n)]
    E = [_exp_apply(C[i], *joint(i)) for i in range(chain.n)]
    if what == "skeleton":
        return _skeleton_rows(chain, num, E)
    return _space_rows(chain, what, num, joint, C, E)


def _body_jacobian_rows(chain, num, joint):
    """J_b's rows, from the tool back: column i is Ad of the exponentials after joint i applied to B_i."""
    n, kinds = chain.n, chain.joint_types
    B = _body_screw_columns(chain.M, chain.screws)
    cols, Q, u = [None] * n, _I3, [0, 0, 0]
    for i in reversed(range(n)):
        b, nu = [num(x) for x in B[i][:3]], [num(x) for x in B[i][3:]]
        cols[i] = _mtv(Q, b) + _mtv(Q, _vadd(nu, _vcross(b, u)))
        rot, tr = _exp_apply(_exp_constants(B[i], kinds[i], num), *joint(i))
        Q, u = _mm(rot, Q), _vadd(_mv(rot, u), tr)
    return [[cols[j][r] for j in range(n)] for r in range(6)]


def _skeleton_rows(chain, num, E):
    """The skeleton's rows (x, y, z of the base, each joint's point and the tool), from the exponentials E."""
    pM = [num(chain.M[i, 3]) for i in range(3)]
    cols, R, p = [[0, 0, 0]], _I3, [0, 0, 0]
    for i in range(chain.n):
        cols.append(_vadd(_mv(R, [num(x) for x in chain.joint_points[:, i]]), p))
        p, R = _vadd(_mv(R, E[i][1]), p), _mm(R, E[i][0])
    cols.append(_vadd(_mv(R, pM), p))
    return [[col[r] for col in cols] for r in range(3)]


def _space_rows(chain, what: str, num, joint, C, E):
    """Rows of T ("fk"), J_s ("js") or the geometric J ("jg") from the exponentials' constants C and values E."""
    n, M = chain.n, chain.M
    pM = [num(M[i, 3]) for i in range(3)]
    R = [_I3]  # R[i] = rot(E_1)⋯rot(E_i)
    for i in range(n if what == "fk" else n - 1):
        R.append(_mm(R[-1], E[i][0]))
    tail = [pM]  # tail[k] = E_{n−k+1}(⋯E_n(p_M)): tail[0] = p_M, tail[n] = p(θ)
    if what in ("fk", "jg"):
        for i in reversed(range(n)):
            tail.append(_vadd(_mv(E[i][0], tail[-1]), E[i][1]))
    if what == "fk":
        RM = _mm(R[n], [[num(M[i, j]) for j in range(3)] for i in range(3)])
        return [RM[r] + [tail[n][r]] for r in range(3)] + [[0, 0, 0, 1]]
    cols, g = [], [0, 0, 0]
    for i in range(n):
        w, v = [num(x) for x in chain.screws[:3, i]], [num(x) for x in chain.screws[3:, i]]
        x = g if what == "js" else tail[n - i]
        cols.append(_mv(R[i], w) + _mv(R[i], _vadd(v, _vcross(w, x))))
        if what == "js" and i < n - 1:
            rot, tr = _exp_apply(C[i], *joint(i), sign=-1)
            g = _vadd(_mv(rot, g), tr)
    return [[cols[j][r] for j in range(n)] for r in range(6)]


def _float_constant(x) -> float:
    """An exact constant of the chain as the float the generated code uses (exact zeros stay 0.0); a constant
    beyond the float range (an M or a screw with 10**400 in it) is refused, never turned into inf or 0.

    >>> _float_constant(sp.Integer(10) ** 400)
    Traceback (most recent call last):
    ...
    ValueError: the chain's constant 1.0E+400 is beyond the float range (|x| < 1.8e308): its numeric code cannot represent it; pass SymPy joint values for an exact result
    """
    if x == 0:
        return 0.0
    v = float(x)
    if not math.isfinite(v):
        raise ValueError(
            f"the chain's constant {sp.N(x, 2)} is beyond the float range (|x| < 1.8e308): its numeric code cannot "
            "represent it; pass SymPy joint values for an exact result"
        )
    return v


# --- URDF-style chains: constant placements and rotations about the joints' own axes (issue 25) -------------
def _check_placements(placements, M, S, kinds):
    """``(C, axes)`` as exact matrices after checking they describe the chain (M, S) (to 1e-9, in floats)."""
    n = S.shape[1]
    if not isinstance(placements, (list, tuple)) or len(placements) != 2:
        raise ValueError(
            f"placements must be (C, axes) with n + 1 = {n + 1} transforms and {n} axes, got {describe(placements)}"
        )
    C, axes = placements
    if not isinstance(C, (list, tuple)) or len(C) != n + 1 or not isinstance(axes, (list, tuple)) or len(axes) != n:
        raise ValueError(
            f"placements must be (C, axes) with n + 1 = {n + 1} transforms and {n} axes, got {describe(placements)}"
        )
    C = [
        check_se3(as_matrix(c, f"placements C[{i}]", (4, 4), True, real_symbols=True), f"placements C[{i}]")
        for i, c in enumerate(C)
    ]
    axes = [as_vector(a, f"placements axes[{i}]", 3, True, real_symbols=True) for i, a in enumerate(axes)]
    if not (M.free_symbols or S.free_symbols or any(c.free_symbols for c in C)):
        F = np.eye(4)
        for i in range(n):
            F = F @ np.array(C[i], dtype=float)
            u = np.array(axes[i], dtype=float).ravel()
            w = F[:3, :3] @ u
            want = np.concatenate([w, np.cross(F[:3, 3], w)]) if kinds[i] == "R" else np.concatenate([np.zeros(3), w])
            if not np.allclose(want, np.array(S[:, i], dtype=float).ravel(), atol=1e-9):
                raise ValueError(
                    f"placements disagree with screws[{i}]: C_1⋯C_{i + 1} and axes[{i}] give {want.tolist()}"
                )
        if not np.allclose(F @ np.array(C[n], dtype=float), np.array(M, dtype=float), atol=1e-9):
            raise ValueError("placements disagree with M: C_1⋯C_{n+1} ≠ M")
    return C, axes


_ROT_ZERO = 2.0**-50


def _local_rows(chain, what: str, joint):
    """Rows of T, J_s or the geometric J from the placements (on a tape: floats, sparse where the URDF is).

    Frame i at θ: F_i = F_{i−1} C_i e^{[â_i]θ_i}; joint i's axis ω_i = rot(F_{i−1} C_i) â_i through the origin p_i
    of F_{i−1} C_i. J_s column [ω_i; p_i × ω_i], the geometric J's [ω_i; ω_i × (p − p_i)] ([0; ω_i] prismatic)."""
    C, axes = chain._placements
    scale = max([abs(float(x)) for c in C for x in c[:3, 3]] + [1e-300])

    def rot(A):
        return [[0.0 if abs(float(A[r, k])) <= _ROT_ZERO else float(A[r, k]) for k in range(3)] for r in range(3)]

    def pos(A):
        return [0.0 if abs(float(A[r, 3])) <= _ROT_ZERO * scale else float(A[r, 3]) for r in range(3)]

    R, p, cols = _I3, [0, 0, 0], []
    for i, kind in enumerate(chain.joint_types):
        p = _vadd(_mv(R, pos(C[i])), p)
        G = _mm(R, rot(C[i]))
        u = [0.0 if abs(float(x)) <= _ROT_ZERO else float(x) for x in axes[i]]
        w = _mv(G, u)
        s, c, th = joint(i)
        if kind == "R":
            K = _exp_constants(
                sp.Matrix(list(axes[i]) + [0, 0, 0]), "R", lambda x: 0.0 if abs(float(x)) <= _ROT_ZERO else float(x)
            )
            R = _mm(G, _exp_apply(K, s, c, th)[0])
            cols.append((w, p))
        else:
            R = G
            cols.append((None, w))
            p = _vadd(p, [x * th for x in w])
    pe = _vadd(_mv(R, pos(C[-1])), p)
    if what == "fk":
        RM = _mm(R, rot(C[-1]))
        return [RM[r] + [pe[r]] for r in range(3)] + [[0, 0, 0, 1]]
    out = []
    for w, x in cols:
        if w is None:
            out.append([0.0, 0.0, 0.0] + x)
        elif what == "js":
            out.append(w + _vcross(x, w))
        else:
            out.append(w + _vcross(w, [pe[0] - x[0], pe[1] - x[1], pe[2] - x[2]]))
    return [[col[r] for col in out] for r in range(6)]
