"""Singular configurations, rank, and the directions a robot can and cannot move.

A Jacobian J (m×n, any of space / body / geometric: singularities do not depend on the choice) loses
rank where

* det J = 0 (square J),
* det(J Jᵀ) = 0 (m < n, more joints than task dimensions),
* det(Jᵀ J) = 0 (m > n, fewer joints than task dimensions).

``task_rows`` picks a task space's rows first (rows are [ω; v] = wx wy wz vx vy vz; for the geometric
Jacobian the last three are ṗ). ``singular_configurations`` solves det = 0 in closed form, as whole
periodic families; ``rank_at``, ``column_space`` and ``left_null_space`` give exact answers *at* a
configuration (SymPy's ``Matrix.rank()`` on the symbolic J gives only the generic rank and hides the drop).

How the determinant is solved fast: sin θ_i, cos θ_i are replaced by polynomial variables s_i, c_i,
each entry is reduced modulo s_i² + c_i² − 1 (:class:`kinlib.trigpoly.TrigRing`), the determinant is
taken by fraction-free elimination in that polynomial ring and factored, and each factor that involves a
single joint is solved on one period [0, 2π) and written as a family {b + p k : k ∈ ℤ}. Prismatic joint
variables enter polynomially and are solved over ℝ.
"""
from __future__ import annotations

import numbers
from typing import Any, Mapping, Sequence

import numpy as np
import sympy as sp

from ._backend import as_matrix, describe, is_symbolic
from .display import _exact_zero
from .trigpoly import NotTrigPolynomial, TrigRing, angles_in

__all__ = [
    "ROW_NAMES", "task_rows", "singular_configurations", "representatives", "rank_at", "column_space",
    "left_null_space", "evaluate_at", "trig_simplify", "periodic_family", "K",
]

#: Names of the six rows of a Jacobian in the textbook's [ω; v] order (for the geometric J, v is ṗ).
ROW_NAMES = ("wx", "wy", "wz", "vx", "vy", "vz")
_ALIASES = {"px": "vx", "py": "vy", "pz": "vz", "ωx": "wx", "ωy": "wy", "ωz": "wz"}
_PRESETS = {"planar": ("wz", "vx", "vy"), "angular": ("wx", "wy", "wz"), "linear": ("vx", "vy", "vz")}

#: The integer that indexes a periodic family of joint values, {b + p·k : k ∈ ℤ}.
K = sp.Symbol("k", integer=True)

_TWO_PI = 2 * sp.pi


# ----------------------------------------------------------------------------------------------
# input checks
# ----------------------------------------------------------------------------------------------
def _jacobian(J: Any, name: str = "J", symbolic: bool | None = None):
    """J as a 2-D SymPy Matrix (symbolic) or float array; a clear error for anything else."""
    if not isinstance(J, (sp.MatrixBase, np.ndarray, list, tuple)):
        raise TypeError(f"{name} must be a matrix (m×n Jacobian), got {describe(J)}")
    if isinstance(J, np.ndarray) and J.ndim != 2:
        raise ValueError(f"{name} must be a matrix (m×n Jacobian), got {describe(J)}")
    return as_matrix(J, name, None, symbolic)


def _check_thetas(thetas: Any, n: int, name: str = "thetas") -> tuple[sp.Symbol, ...]:
    if isinstance(thetas, sp.Symbol):
        thetas = (thetas,)
    if isinstance(thetas, sp.MatrixBase):
        thetas = list(thetas)
    if isinstance(thetas, (str, bytes)) or not isinstance(thetas, Sequence):
        raise TypeError(f"{name} must be a sequence of {n} SymPy symbols (one per column of J), got {describe(thetas)}")
    thetas = tuple(thetas)
    if not all(isinstance(t, sp.Symbol) for t in thetas):
        raise TypeError(f"{name} must hold SymPy symbols (the joint variables), got {describe(list(thetas))}")
    if len(thetas) != n:
        raise ValueError(f"{name} must hold {n} joint symbols (one per column of J), got {len(thetas)}: "
                         f"{', '.join(map(str, thetas))}")
    if len(set(thetas)) != n:
        raise ValueError(f"{name} must hold distinct symbols, got {', '.join(map(str, thetas))}")
    return thetas


def _check_params(J: sp.Matrix, thetas, params) -> tuple[sp.Symbol, ...]:
    """Symbols of J other than the joints must be parameters: given in ``params`` or declared positive."""
    extra = J.free_symbols - set(thetas)
    if params is not None:
        if isinstance(params, sp.Symbol):
            params = (params,)
        params = tuple(params)
        if not all(isinstance(p, sp.Symbol) for p in params):
            raise TypeError(f"params must hold SymPy symbols, got {describe(list(params))}")
        extra -= set(params)
        bad = sorted(extra, key=str)
    else:
        bad = sorted((s for s in extra if not s.is_positive), key=str)
    if bad:
        raise ValueError(
            f"J contains the symbol(s) {', '.join(map(str, bad))}, which are not among the joints "
            f"thetas=({', '.join(map(str, thetas))}); parameters must be positive symbols (link lengths) "
            f"or listed in params=")
    return tuple(sorted(J.free_symbols - set(thetas), key=str))


def _row_index(r: Any) -> int:
    if isinstance(r, (bool, np.bool_)):
        raise TypeError(f"rows must be row indices or names among {ROW_NAMES}, got the bool {r!r}")
    if isinstance(r, (numbers.Integral, np.integer)):
        return int(r)
    if isinstance(r, str):
        key = _ALIASES.get(r.lower(), r.lower())
        if key in ROW_NAMES:
            return ROW_NAMES.index(key)
        raise ValueError(f"rows: unknown row name {r!r}; names are {', '.join(ROW_NAMES)} "
                         f"(ṗ aliases px, py, pz) or a preset among {', '.join(_PRESETS)}")
    raise TypeError(f"rows must be row indices or names among {ROW_NAMES}, got {describe(r)}")


# ----------------------------------------------------------------------------------------------
# task rows
# ----------------------------------------------------------------------------------------------
def task_rows(J: Any, rows: Any):
    """The rows of J for a task space: ``task_rows(Js, "planar")`` = rows (ω_z, v_x, v_y).

    ``rows``: a preset ("planar" = wz vx vy, "angular" = wx wy wz, "linear" = vx vy vz), a sequence of
    names among wx wy wz vx vy vz (aliases px py pz for the geometric Jacobian's ṗ rows) or of row
    indices. Names need J with 6 rows ([ω; v] order); indices work for any J. A numeric batch
    (N, 6, n) is accepted and gives (N, k, n).
    """
    if isinstance(rows, str):
        rows = _PRESETS.get(rows.lower(), (rows,))
    if isinstance(rows, (numbers.Integral, np.integer)) and not isinstance(rows, bool):
        rows = (rows,)
    if not isinstance(rows, (Sequence, np.ndarray)) or isinstance(rows, (str, bytes)):
        raise TypeError(f"rows must be a preset name, or a sequence of row names or indices, got {describe(rows)}")
    rows = list(rows)
    if not rows:
        raise ValueError("rows must name at least one row, got an empty sequence")
    named = any(isinstance(r, str) for r in rows)
    idx = [_row_index(r) for r in rows]
    if len(set(idx)) != len(idx):
        raise ValueError(f"rows must not repeat a row, got {rows!r}")
    batch = isinstance(J, np.ndarray) and J.ndim == 3 and not is_symbolic(J)
    if batch:
        m = J.shape[1]
    else:
        J = _jacobian(J)
        m = J.shape[0]
    if named and m != 6:
        raise ValueError(f"row names need a 6-row Jacobian ([ω; v] rows), got J with {m} rows; use indices")
    for i in idx:
        if not -m <= i < m:
            raise ValueError(f"rows: index {i} is out of range for J with {m} rows")
    if batch:
        return np.asarray(J, dtype=float)[:, idx, :]
    if isinstance(J, sp.MatrixBase):
        return J.extract(idx, list(range(J.cols)))
    return J[idx, :]


# ----------------------------------------------------------------------------------------------
# display form (the normal form modulo sin² + cos² = 1 is kinlib.trigpoly's)
# ----------------------------------------------------------------------------------------------
def trig_simplify(e: Any, thetas: Sequence[sp.Symbol] | None = None):
    """A display form: expand the trig functions, reduce with sin² + cos² = 1, then trigsimp and factor.

    Works entry-wise on matrices. Much faster than ``sp.simplify`` on product-of-exponentials output.
    """
    if isinstance(e, sp.MatrixBase):
        return e.applyfunc(lambda x: trig_simplify(x, thetas))
    e = sp.sympify(e)
    if not isinstance(e, sp.Expr):
        raise TypeError(f"e must be a SymPy expression or Matrix, got {describe(e)}")
    angles = angles_in([e], set(thetas) if thetas is not None else None)
    if not angles:
        return sp.factor(e) if e.free_symbols else sp.nsimplify(sp.radsimp(e)) if e.is_number and not e.has(sp.Float) else e
    try:
        ring = TrigRing([e], angles, opaque=True)
        p = ring.to_expr(ring.normal_form(e), trig=False)   # in s_i, c_i: factored as a polynomial
    except NotTrigPolynomial:  # sin/cos under a root or in a denominator: trigsimp alone
        return sp.factor_terms(sp.trigsimp(e))
    return sp.factor_terms(sp.trigsimp(ring.to_trig(sp.factor(p))))


# ----------------------------------------------------------------------------------------------
# singular configurations
# ----------------------------------------------------------------------------------------------
def _rank_det(entries: list, shape: tuple[int, int], ring: TrigRing):
    """det J (square), det(J Jᵀ) (m < n) or det(Jᵀ J) (m > n) of J given as ring elements, row by row:
    fraction-free elimination over the polynomial ring (exact, no expression swell)."""
    from sympy.polys.matrices import DomainMatrix
    m, n = shape
    dJ = DomainMatrix([entries[i * n:(i + 1) * n] for i in range(m)], shape, ring.ring.to_domain())
    G = dJ if m == n else dJ * dJ.transpose() if m < n else dJ.transpose() * dJ
    return G.det()


def _det(M: sp.Matrix) -> sp.Expr:
    try:
        from sympy.polys.matrices import DomainMatrix
        dM = DomainMatrix.from_Matrix(M)
        if dM.domain.is_EX:  # algebraic constants such as √2: plain fraction-free elimination
            raise ValueError
        return dM.domain.to_sympy(dM.det())
    except Exception:
        return sp.expand(M.det(method="bareiss"))


def periodic_family(points: Sequence) -> sp.Set:
    """{b + p k : k ∈ ℤ}: the angles ≡ one of ``points`` (exact, one period [0, 2π)) modulo 2π, written with
    period π when the points come in pairs π apart (sin θ = 0 → {kπ}); bases in (−π/2, π/2] or (−π, π]."""
    points = [sp.sympify(p) for p in points]
    if not points or not all(p.is_number and p.is_real for p in points):
        raise ValueError(f"points must be real numbers, got {points}")
    points = [p - _TWO_PI * sp.floor(p / _TWO_PI) for p in points]
    pts = sorted(set(sp.nsimplify(p) if isinstance(p, sp.Float) else p for p in points), key=lambda x: float(x))
    modpi = all(any(sp.simplify((p + sp.pi) % _TWO_PI - q) == 0 for q in pts) for p in pts)
    if modpi:
        period = sp.pi
        bases = [p for p in pts if float(p) < float(sp.pi) - 1e-12]
        bases = [b - sp.pi if float(b) > float(sp.pi) / 2 + 1e-12 else b for b in bases]
    else:
        period = _TWO_PI
        bases = [p - _TWO_PI if float(p) > float(sp.pi) + 1e-12 else p for p in pts]
    bases = sorted(bases, key=lambda x: float(x))
    sets = [sp.ImageSet(sp.Lambda(K, b + period * K), sp.Integers) for b in bases]
    return sets[0] if len(sets) == 1 else sp.Union(*sets, evaluate=False)


def _solve_single(g: sp.Expr, joint: sp.Symbol, revolute: bool) -> sp.Set | None:
    """The real zeros of g(joint) as a Set, or None when they have no closed form."""
    try:
        if revolute:
            sol = sp.solveset(g, joint, sp.Interval.Ropen(0, _TWO_PI))
            if sol is sp.S.EmptySet:
                return sol
            if isinstance(sol, sp.FiniteSet) and all(p.is_real and p.is_number for p in sol):
                return periodic_family(list(sol))
            return None
        sol = sp.solveset(g, joint, sp.S.Reals)
        if sol is sp.S.EmptySet or isinstance(sol, sp.FiniteSet):
            return sol
        return None
    except (NotImplementedError, ValueError, TypeError):
        return None


def _normalize_expr(e: sp.Expr) -> sp.Expr:
    """A condition 'e = 0' written with a positive leading coefficient and no constant factor."""
    e = sp.factor_terms(e)
    c, rest = e.as_coeff_Mul()
    if c.is_number and c != 0:
        e = rest
    if e.could_extract_minus_sign():
        e = -e
    return e


def singular_configurations(J: Any, thetas: Sequence[sp.Symbol], params: Sequence[sp.Symbol] | None = None) -> list:
    """Where J(θ) loses rank, in closed form: a list of conditions (empty when there is none).

    The rank test is det J = 0 (square), det(J Jᵀ) = 0 (more joints than rows) or det(Jᵀ J) = 0 (fewer).
    Each condition is either

    * ``{θ_i: S}``: joint i in the SymPy Set S, the whole periodic family, e.g.
      ``{theta2: ImageSet(Lambda(k, pi*k - pi/4), Integers)}`` (θ2 = −π/4 + kπ); for a prismatic
      joint a FiniteSet of values; or
    * an expression that must vanish, where a factor involves several joints (the UR5's shoulder
      singularity), written back in sin/cos and trig-simplified.

    ``thetas``: the n joint symbols, one per column of J. A joint need not appear in J (a space Jacobian
    never depends on the last joint). Every other symbol in J is a parameter: it must be declared
    positive (the link lengths of :mod:`kinlib.robots` are) or be listed in ``params``; parameter-only
    factors are taken to be nonzero (generic link lengths).
    """
    if not is_symbolic(J):
        raise TypeError(f"J must be a symbolic Jacobian (a SymPy Matrix in the joint symbols), got {describe(J)}")
    J = _jacobian(J, "J", True)
    thetas = _check_thetas(thetas, J.cols)
    _check_params(J, thetas, params)
    if J.rows == 0 or J.cols == 0:
        raise ValueError(f"J must have at least one row and one column, got {describe(J)}")

    joint_set = set(thetas)

    def parameter_atom(a: sp.Expr) -> bool:  # √L, 1/L: allowed; anything else with a joint or a trig function: not
        return not (a.free_symbols & joint_set) and not a.has(sp.sin, sp.cos, sp.tan)

    def bad_entry(e):
        return ValueError("J must be polynomial in sin θ_i, cos θ_i of the revolute joints and in the "
                          f"prismatic joint values; got the entry {e}")

    try:
        ring = TrigRing(list(J), thetas, opaque=parameter_atom)   # s_i = sin θ_i, c_i = cos θ_i, θ_j, L, ...
    except NotTrigPolynomial:
        for e in J:
            try:
                TrigRing([e], thetas, opaque=parameter_atom)
            except NotTrigPolynomial:
                raise bad_entry(e) from None
        raise
    revolute = set(ring.found)                   # joints inside sin/cos; the others enter polynomially
    mixed = revolute & set(ring.variables)       # θ sin θ is not a trigonometric polynomial
    if mixed:
        raise bad_entry(next(e for e in J if mixed & set(TrigRing([e], thetas, opaque=parameter_atom).variables)))
    Jp = [ring.normal_form(e) for e in J]
    D = _rank_det(Jp, J.shape, ring)
    conditions: list = []

    def add(cond):
        if cond not in conditions:
            conditions.append(cond)

    if not D:
        raise ValueError("J never has full rank (its rank-test determinant is identically zero): "
                         "every configuration is singular")
    _, factors = D.factor_list()
    for f, _mult in factors:
        if not ring.depends_on(f) & joint_set:
            continue
        _, sub = ring.reduce(f).factor_list()
        for g, _m in sub:
            joints = ring.depends_on(g) & joint_set
            if not joints:
                continue
            if len(joints) == 1:
                (j,) = joints
                sol = _solve_single(ring.to_expr(g), j, j in revolute)
                if sol is sp.S.EmptySet:
                    continue
                if sol is not None:
                    add({j: sol})
                    continue
            expr = ring.to_expr(g)
            if sp.count_ops(expr) < 400:
                expr = sp.trigsimp(expr)
            add(_normalize_expr(expr))

    def key(c):
        if isinstance(c, dict):
            (j,) = c
            return (0, thetas.index(j), str(c[j]))
        return (1, 0, str(c))
    return sorted(conditions, key=key)


def representatives(family: sp.Set, lo=0, hi=2 * sp.pi) -> list:
    """The members of a family of joint values in [lo, hi) (sorted, exact): e.g. θ2 = −π/4 + kπ → [3π/4, 7π/4]."""
    lo, hi = sp.sympify(lo), sp.sympify(hi)
    if not isinstance(family, sp.Set):
        raise TypeError(f"family must be a SymPy Set, got {describe(family)}")
    if not (lo.is_number and hi.is_number and float(lo) < float(hi)):
        raise ValueError(f"need numbers lo < hi, got lo={lo}, hi={hi}")
    out = []
    parts = family.args if isinstance(family, sp.Union) else (family,)
    for part in parts:
        if isinstance(part, sp.FiniteSet):
            out += [p for p in part if p.is_number and float(lo) <= float(p) < float(hi)]
        elif isinstance(part, sp.ImageSet) and part.base_sets == (sp.S.Integers,):
            lam = part.lamda
            (k,) = lam.variables
            expr = lam.expr
            b, p = expr.subs(k, 0), sp.expand(expr - expr.subs(k, 0)).coeff(k)
            if not (b.is_number and p.is_number and p != 0) or sp.expand(b + p * k - expr) != 0:
                raise ValueError(f"family must be {{b + p k}} with numbers b, p; got {part}")
            k0 = int(np.floor(float((lo - b) / p))) - 1
            k1 = int(np.ceil(float((hi - b) / p))) + 1
            for kk in range(min(k0, k1), max(k0, k1) + 1):
                v = b + p * kk
                if float(lo) - 1e-12 <= float(v) < float(hi) - 1e-12:
                    out.append(v)
        elif part is sp.S.EmptySet:
            continue
        else:
            raise ValueError(f"family must be a FiniteSet, an ImageSet over the integers or a Union of them; got {part}")
    return sorted(set(out), key=lambda v: float(v))


# ----------------------------------------------------------------------------------------------
# exact values at a configuration
# ----------------------------------------------------------------------------------------------
def _is_number_like(v: Any) -> bool:
    return isinstance(v, (numbers.Real, np.integer, np.floating)) and not isinstance(v, (bool, np.bool_))


def evaluate_at(J: Any, subs: Any = None, thetas: Sequence[sp.Symbol] | None = None):
    """J at a configuration, exact when J and the values are exact.

    ``subs``: a mapping {joint symbol: value}, or a sequence of values matched to ``thetas``. Values are
    numbers (SymPy numbers such as π/4, ints) or expressions in positive parameters (θ3 = −L2). Any
    Python float selects the numeric backend (a float array). After substitution J may still contain
    positive parameters (link lengths), never a joint. Entries are simplified, so a zero is a zero.
    """
    if subs is None:
        if is_symbolic(J):
            M = _jacobian(J, "J", True)
            return _clean(M)
        return _jacobian(J, "J", False)
    if not is_symbolic(J):
        raise TypeError(f"subs only applies to a symbolic J; J is numeric ({describe(J)}): call without subs")
    M = _jacobian(J, "J", True)
    if isinstance(subs, Mapping):
        table = dict(subs)
    elif isinstance(subs, (str, bytes)) or not isinstance(subs, (Sequence, np.ndarray, sp.MatrixBase)):
        raise TypeError(f"subs must be a mapping {{joint symbol: value}} or a sequence of joint values, got {describe(subs)}")
    else:
        vals = list(subs)
        if thetas is None:
            raise ValueError("subs is a sequence of joint values: give thetas= (the joint symbols, in order) too")
        thetas = _check_thetas(thetas, len(thetas) if not isinstance(thetas, sp.Symbol) else 1)
        if len(vals) != len(thetas):
            raise ValueError(f"subs must hold {len(thetas)} joint values (one per joint "
                             f"{', '.join(map(str, thetas))}), got {len(vals)}")
        table = dict(zip(thetas, vals))
    numeric = False
    clean = {}
    for k, v in table.items():
        if not isinstance(k, sp.Symbol):
            raise TypeError(f"subs keys must be SymPy symbols (joints), got {describe(k)}")
        if isinstance(v, (float, np.floating)):
            numeric = True
        if _is_number_like(v):
            clean[k] = sp.Float(float(v)) if isinstance(v, (float, np.floating)) else sp.Integer(int(v))
        elif isinstance(v, sp.Expr) and not isinstance(v, sp.MatrixBase):
            bad = [s for s in v.free_symbols if not s.is_positive]
            if bad or v.has(sp.I) or v.is_real is False:
                raise ValueError(f"subs[{k}] must be a real number (or an expression in positive parameters), got {v}")
            clean[k] = v
        else:
            raise TypeError(f"subs[{k}] must be a number, got {describe(v)}")
    M = M.xreplace(clean)
    left = sorted((s for s in M.free_symbols if not s.is_positive), key=str)
    if left:
        raise ValueError(f"J still depends on {', '.join(map(str, left))} after the substitution: give a value for "
                         "every joint (only positive parameters such as link lengths may stay symbolic)")
    if numeric:
        if M.free_symbols:
            raise ValueError(f"float joint values need a numeric J; J has parameters "
                             f"{', '.join(map(str, sorted(M.free_symbols, key=str)))}")
        return np.array(M.evalf(), dtype=float)
    return _clean(M)


def _clean_entry(e: sp.Expr) -> sp.Expr:
    if e.is_number:
        if e.has(sp.Float):
            return e
        e = sp.nsimplify(sp.radsimp(sp.expand_trig(e)), [sp.pi]) if e.has(sp.sin, sp.cos) else sp.radsimp(e)
        return sp.simplify(e) if sp.count_ops(e) > 8 else e
    if e.has(sp.sin, sp.cos):
        return trig_simplify(e)
    return sp.factor(sp.radsimp(e))


def _clean(M: sp.Matrix) -> sp.Matrix:
    return M.applyfunc(_clean_entry)


def _is_zero(e: Any):
    """Exact zero test that never mistakes a configuration's zero for a nonzero.

    Polynomials in sines, cosines and symbols (and rational functions of them) are decided exactly by
    :func:`kinlib.display.is_identically_zero`'s normal form; other forms (square roots ...) numerically
    first (a nonzero value proves nonzero), then by ``sp.simplify``.
    """
    e = sp.sympify(e)
    if e == 0:
        return True
    if e.is_zero is not None:
        return e.is_zero
    if e.is_number:
        v = complex(sp.N(e, 40))
        if abs(v) > 1e-30:
            return False
        exact = _exact_zero(e)
        if exact is not None:
            return exact
        return bool(sp.simplify(e) == 0 or e.equals(0))
    exact = _exact_zero(e)
    if exact is not None:
        return exact
    # other expressions in positive parameters: a random positive point proves nonzero
    rng = np.random.default_rng(0)
    syms = sorted(e.free_symbols, key=str)
    for _ in range(3):
        pt = {s: sp.Rational(int(rng.integers(2, 97)), int(rng.integers(2, 97))) for s in syms}
        if abs(complex(sp.N(e.subs(pt), 40))) > 1e-30:
            return False
    return bool(sp.simplify(e) == 0)


def _numeric_rank_tol(s: np.ndarray, shape) -> float:
    return max(shape) * np.finfo(float).eps * (s[0] if s.size else 0.0) * 100


def rank_at(J: Any, subs: Any = None, thetas: Sequence[sp.Symbol] | None = None) -> int:
    """rank J at a configuration: exact (entries simplified before any zero test) for SymPy J and values.

    ``subs`` as in :func:`evaluate_at` ({θ_i: value} or values with ``thetas``). A numeric J (or float
    values) uses the SVD with a relative tolerance.
    """
    M = evaluate_at(J, subs, thetas)
    if isinstance(M, np.ndarray):
        s = np.linalg.svd(M, compute_uv=False)
        return int(np.sum(s > _numeric_rank_tol(s, M.shape)))
    _require_constant(M, "rank_at")
    return int(M.rank(iszerofunc=_is_zero, simplify=True))


def _require_constant(M: sp.Matrix, what: str):
    left = sorted((s for s in M.free_symbols if not s.is_positive), key=str)
    if left:
        raise ValueError(f"{what} needs J at a configuration: J depends on {', '.join(map(str, left))} "
                         "(give subs=...; a basis of the symbolic J can be undefined at special configurations)")


def _rref_rows(A: sp.Matrix) -> sp.Matrix:
    """The nonzero rows of rref(A), entries cleaned: the canonical basis of A's row space."""
    R, piv = A.rref(iszerofunc=_is_zero, simplify=True)
    rows = R[: len(piv), :]
    return rows.applyfunc(lambda e: sp.radsimp(sp.simplify(e)) if e != 0 else e)


def column_space(J: Any, subs: Any = None, thetas: Sequence[sp.Symbol] | None = None):
    """A basis of range J (the twists/velocities the robot can produce) at a configuration, as columns.

    Exact J: the canonical basis, the nonzero rows of rref(Jᵀ) (leading entries 1), so equal subspaces give
    equal matrices; always defined because J is evaluated (and simplified) first. Numeric J: an
    orthonormal basis from the SVD. The result is m×r (r = rank).
    """
    M = evaluate_at(J, subs, thetas)
    if isinstance(M, np.ndarray):
        U, s, _ = np.linalg.svd(M)
        r = int(np.sum(s > _numeric_rank_tol(s, M.shape)))
        return U[:, :r]
    _require_constant(M, "column_space")
    if M.is_zero_matrix:
        return sp.zeros(M.rows, 0)
    return _rref_rows(M.T).T


def left_null_space(J: Any, subs: Any = None, thetas: Sequence[sp.Symbol] | None = None):
    """A basis of null Jᵀ (directions the robot cannot move: yᵀ J = 0) at a configuration, as columns.

    Exact J: canonical (rref) basis; numeric J: orthonormal from the SVD. m×(m − r), empty when full rank.
    """
    M = evaluate_at(J, subs, thetas)
    if isinstance(M, np.ndarray):
        U, s, _ = np.linalg.svd(M)
        r = int(np.sum(s > _numeric_rank_tol(s, M.shape)))
        return U[:, r:]
    _require_constant(M, "left_null_space")
    vecs = M.T.nullspace(iszerofunc=_is_zero, simplify=True)
    if not vecs:
        return sp.zeros(M.rows, 0)
    return _rref_rows(sp.Matrix.hstack(*vecs).T).T
