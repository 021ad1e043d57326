"""Exact linear algebra at a configuration: J(θ₀), rank J(θ₀), range J(θ₀) and null J(θ₀)ᵀ, proved.

SymPy's ``Matrix.rank()`` of the symbolic J gives the *generic* rank and hides the drop at a singular
configuration; and deciding "is this entry zero?" from a float (or by guessing a closed form from one) is
wrong at angles such as θ = 10 or θ = 1/2. Here every zero test is a proof.

**How.** After substituting the joint values, every entry of J is a number built from sin a and cos a of the
configuration's angles a, algebraic constants (√2, cos π/7, …) and the positive parameters (link lengths).
Write each angle as a = r + qπ with r, q rational. Let g > 0 be the largest rational with every r an integer
multiple n·g of it, and t = tan(g/2). Then

    cos(n g) + i sin(n g) = (1 + i t)^{2n} / (1 + t²)^n,

and cos(qπ), sin(qπ) are algebraic, so every entry is a rational function of t (and of the parameters) with
algebraic coefficients. For g ≠ 0, t is **transcendental** (Lindemann–Weierstrass: e^{ig} is transcendental
for algebraic g ≠ 0), so such a rational function vanishes at t = tan(g/2) *if and only if* it is identically
zero. Rank, pivots and the canonical bases are therefore decided by exact Gaussian elimination in the field
K(t, L1, L2, …) (K the algebraic numbers involved): no numerics at all. Parameters count as indeterminates: the
rank found is the rank for all their values except where a stated minor vanishes (see :class:`Rank`).

The canonical basis entries (rref) are then written with the configuration's own sines and cosines, as ratios
of minors (Cramer's rule) of the evaluated J, each minor computed exactly in the polynomial ring of those sines
and cosines (:class:`kinlib.trigpoly.TrigRing`) and folded for display.

**Where an exact decision is out of reach** (an angle that is not a rational plus a rational multiple of π,
such as √2; angles whose ratio has a numerator or denominator above ``MAX_MULTIPLE``; a constant such as π or e
entering polynomially alongside a transcendental angle), the rank is computed from a singular value
decomposition in mpmath with ``FALLBACK_DIGITS`` = 60 significant digits: a singular value above
``10^-FALLBACK_ZERO_DIGITS`` · σ_max (10^-40) is certified nonzero (each entry is accurate to 60 digits and
|σ_i(A) − σ_i(Ã)| ≤ ‖A − Ã‖), one below is reported as numerically zero, *not proven*. The result says so
(``Rank.exact`` is False and ``Rank.note`` states the precision; the bases come with a
:class:`NumericFallbackWarning`).
"""
from __future__ import annotations

import itertools
import math
import numbers
import warnings
from typing import Any, Mapping, Sequence

import numpy as np
import sympy as sp
from sympy.polys.constructor import construct_domain
from sympy.polys.fields import field as _field
from sympy.polys.matrices import DomainMatrix
from sympy.simplify.fu import TR10i

from ._backend import describe, exact_number, is_symbolic
from .display import simplify_for_display
from .trigpoly import NotTrigPolynomial, TrigRing

__all__ = ["Rank", "NumericFallbackWarning", "ConditionalResultWarning", "evaluate_at", "rank_at",
           "column_space", "left_null_space", "exact_is_zero", "MAX_MULTIPLE", "FALLBACK_DIGITS"]

#: the largest |n| with every angle's rational part n·g, above which the exact method is not used
MAX_MULTIPLE = 240
#: significant digits of the numeric fallback, and the relative size below which σ counts as zero there
FALLBACK_DIGITS = 60
FALLBACK_ZERO_DIGITS = 40


class NumericFallbackWarning(UserWarning):
    """A result was computed numerically (mpmath, 60 digits) because an exact decision was out of reach."""


class ConditionalResultWarning(UserWarning):
    """A result with symbolic parameters holds only where a stated expression in them is nonzero."""


class Rank(int):
    """The rank of J at a configuration: an ``int`` that also says how it was decided.

    * ``exact``: True when proved by exact arithmetic; False for the 60-digit numeric fallback.
    * ``unless``: expressions in the positive parameters (link lengths); the rank is this value for every
      positive value of the parameters at which none of them vanishes (and smaller where one does). Empty
      when the rank holds for all positive values.
    * ``note``: how it was decided, in words.
    """

    exact: bool
    unless: tuple
    note: str

    def __new__(cls, value: int, *, exact: bool = True, unless: Sequence = (), note: str = ""):
        obj = super().__new__(cls, int(value))
        obj.exact, obj.unless, obj.note = exact, tuple(unless), note
        return obj

    def __repr__(self) -> str:
        if self.exact and not self.unless:
            return int.__repr__(self)
        extra = [] if self.exact else [f"numeric, {FALLBACK_DIGITS} digits"]
        extra += [f"assuming {sp.sstr(u)} ≠ 0" for u in self.unless]
        return f"{int(self)} ({'; '.join(extra)})"

    __str__ = __repr__

    def __reduce__(self):
        return (_make_rank, (int(self), self.exact, self.unless, self.note))


def _make_rank(v, exact, unless, note):
    return Rank(v, exact=exact, unless=unless, note=note)


class _NotExact(Exception):
    """The exact method does not apply (the message says why)."""


# ----------------------------------------------------------------------------------------------
# input: J and the configuration
# ----------------------------------------------------------------------------------------------
def _jacobian(J: Any, name: str = "J") -> sp.Matrix:
    if isinstance(J, sp.MatrixBase):
        M = sp.Matrix(J)
    elif isinstance(J, (list, tuple, np.ndarray)):
        try:
            M = sp.Matrix(np.asarray(J, dtype=object).tolist())
        except Exception:
            raise TypeError(f"{name} must be a matrix (m×n Jacobian), got {describe(J)}") from None
        if np.asarray(J, dtype=object).ndim != 2:
            raise ValueError(f"{name} must be a matrix (m×n Jacobian), got {describe(J)}")
    else:
        raise TypeError(f"{name} must be a matrix (m×n Jacobian), got {describe(J)}")
    if M.rows == 0 or M.cols == 0:
        raise ValueError(f"{name} must have at least one row and one column, got {describe(J)}")
    out = []
    for e in M:
        if isinstance(e, (bool, np.bool_)) or not isinstance(e, (sp.Expr, numbers.Number, np.number)):
            raise TypeError(f"{name} must hold numbers or SymPy expressions, got an entry {describe(e)}")
        out.append(exact_number(e, f"an entry of {name}") if not isinstance(e, sp.Expr) else e)
    M = sp.Matrix(M.rows, M.cols, out)
    for e in M:
        if e.has(sp.I, sp.nan, sp.zoo, sp.oo, -sp.oo):
            raise ValueError(f"{name} must hold real, finite entries, got the entry {e}")
    return M


def _joint_symbols(thetas: Any, name: str = "thetas") -> tuple:
    if isinstance(thetas, sp.Symbol):
        thetas = (thetas,)
    if isinstance(thetas, sp.MatrixBase):
        thetas = list(thetas)
    if isinstance(thetas, (str, bytes)) or not isinstance(thetas, (Sequence, np.ndarray)):
        raise TypeError(f"{name} must be a sequence of SymPy symbols (the joint variables), got {describe(thetas)}")
    thetas = tuple(thetas)
    for t in thetas:
        if not isinstance(t, sp.Symbol):
            raise TypeError(f"{name} must hold SymPy symbols (the joint variables), got {describe(t)}")
        if t.is_real is not True:
            raise ValueError(f"{name}: the joint symbol {t} must be declared real (sp.Symbol('{t}', real=True))")
    if len(set(thetas)) != len(thetas):
        raise ValueError(f"{name} must hold distinct symbols, got {', '.join(map(str, thetas))}")
    return thetas


def _table(subs: Any, thetas: Any) -> tuple:
    """({joint: exact value}, numeric?): numeric when any value is a float (Python, NumPy or SymPy Float)."""
    if isinstance(subs, Mapping):
        table = dict(subs)
    elif isinstance(subs, (str, bytes)) or not isinstance(subs, (Sequence, np.ndarray, sp.MatrixBase)):
        raise TypeError(f"subs must be a mapping {{joint symbol: value}} or a sequence of joint values, got {describe(subs)}")
    else:
        vals = list(subs) if not isinstance(subs, np.ndarray) else subs.reshape(-1).tolist()
        if thetas is None:
            raise ValueError("subs is a sequence of joint values: give thetas= (the joint symbols, in order) too")
        thetas = _joint_symbols(thetas)
        if len(vals) != len(thetas):
            raise ValueError(f"subs must hold {len(thetas)} joint values (one per joint "
                             f"{', '.join(map(str, thetas))}), got {len(vals)}")
        table = dict(zip(thetas, vals))
    clean, numeric = {}, False
    for k, v in table.items():
        if not isinstance(k, sp.Symbol):
            raise TypeError(f"subs keys must be SymPy symbols (joints), got {describe(k)}")
        if isinstance(v, (sp.MatrixBase, list, tuple, np.ndarray)):
            raise TypeError(f"subs[{k}] must be a number, got {describe(v)}")
        numeric |= isinstance(v, (float, np.floating, sp.Float))
        v = exact_number(v, f"subs[{k}]")
        bad = sorted((s for s in v.free_symbols if not s.is_positive), key=str)
        if bad:
            raise ValueError(f"subs[{k}] must be a real number (or an expression in positive parameters), got {v}")
        clean[k] = v
    return clean, numeric


def _evaluated(J: Any, subs: Any, thetas: Any) -> tuple:
    """(J at the configuration as an exact SymPy Matrix, numeric?) — numeric when a joint value is a float."""
    if subs is not None and not is_symbolic(J):
        raise TypeError(f"subs only applies to a symbolic J; J is numeric ({describe(J)}): call without subs")
    M = _jacobian(J)
    numeric = False
    if subs is not None:
        table, numeric = _table(subs, thetas)
        M = M.xreplace(table)
    left = sorted((s for s in M.free_symbols if not s.is_positive), key=str)
    if left:
        raise ValueError(f"J still depends on {', '.join(map(str, left))}: this needs J at a configuration; give a "
                         "value for every joint in subs (only positive parameters such as link lengths may stay symbolic)")
    for e in M:   # the values may have brought in I, oo, nan (checked cheaply: entries can be large trees)
        if e.has(sp.I, sp.nan, sp.zoo, sp.oo, -sp.oo):
            raise ValueError(f"J at the configuration must be real and finite, got the entry {e}")
    if numeric and M.free_symbols:
        raise ValueError(f"float joint values select the numeric backend, which needs numbers for the parameters "
                         f"{', '.join(map(str, sorted(M.free_symbols, key=str)))} (substitute them, or give exact "
                         "joint values such as sp.Rational(1, 2) or sp.pi/4)")
    return M, numeric


def _as_float(M: sp.Matrix) -> np.ndarray:
    return np.array([[float(sp.N(M[i, j], 20)) for j in range(M.cols)] for i in range(M.rows)], dtype=float)


# ----------------------------------------------------------------------------------------------
# the exact field K(t, parameters)
# ----------------------------------------------------------------------------------------------
def _angle_parts(a: sp.Expr) -> tuple:
    """(r, q) with a = r + qπ, both rational; _NotExact otherwise."""
    if a.free_symbols:
        raise _NotExact(f"the angle {a} depends on the parameters {', '.join(map(str, a.free_symbols))}")
    a = sp.expand(a)
    q = a.coeff(sp.pi)
    r = sp.expand(a - q * sp.pi)
    if not (q.is_Rational and r.is_Rational):
        raise _NotExact(f"the angle {a} is not a rational number plus a rational multiple of π")
    return r, q


def _re_im_power(m: int) -> tuple:
    """Integer coefficient lists (low degree first) of Re and Im of (1 + i t)^m, m ≥ 0."""
    re, im = [0] * (m + 1), [0] * (m + 1)
    for k in range(m + 1):
        c = math.comb(m, k)
        if k % 2 == 0:
            re[k] = c if k % 4 == 0 else -c
        else:
            im[k] = c if k % 4 == 1 else -c
    return re, im


class _Field:
    """The entries of an evaluated matrix as elements of K(t, params) (see the module docstring)."""

    def __init__(self, exprs: list):
        exprs = [e.rewrite(sp.cos, sp.sin) if e.has(sp.tan, sp.cot, sp.sec, sp.csc) else e for e in exprs]
        trig = set()
        for e in exprs:
            trig |= e.atoms(sp.sin, sp.cos)
        parts = {}
        for f in trig:
            parts[f] = _angle_parts(f.args[0])
        rs = [r for r, _ in parts.values() if r != 0]
        if rs:
            g = sp.Rational(math.gcd(*[int(r.p) for r in rs]), math.lcm(*[int(r.q) for r in rs]))
        else:
            g = sp.S.Zero
        self.g = g
        self.multiples = {f: (int(r / g) if r != 0 else 0, q) for f, (r, q) in parts.items()}
        biggest = max((abs(n) for n, _ in self.multiples.values()), default=0)
        if biggest > MAX_MULTIPLE:
            raise _NotExact(f"the angles are {biggest} multiples of their common measure {g} apart "
                            f"(the exact method goes up to {MAX_MULTIPLE})")
        self.params = sorted(set().union(*[e.free_symbols for e in exprs]), key=str) if exprs else []
        # algebraic constants: cos qπ, sin qπ of every angle, and every other constant in the entries
        consts = set()
        for n, q in self.multiples.values():
            consts |= {sp.cos(q * sp.pi), sp.sin(q * sp.pi)}
        repl = {f: sp.Dummy() for f in trig}

        extra = set()

        def algebraic(c) -> bool:
            for f in c.atoms(sp.Function):
                if not (isinstance(f, (sp.sin, sp.cos)) and (f.args[0] / sp.pi).is_Rational):
                    return False
            bare = c.xreplace({f: sp.Dummy() for f in c.atoms(sp.sin, sp.cos)})
            return not bare.has(sp.pi, sp.E) and all(not p.is_Pow or p.exp.is_Rational
                                                     for p in sp.preorder_traversal(bare) if isinstance(p, sp.Basic))

        def scan(x):
            if x.is_Rational or x in repl or x.is_Symbol:
                return
            if x is sp.pi or x is sp.E:
                if g != 0:
                    raise _NotExact(f"the constant {x} appears next to the transcendental sin/cos of {g}")
                extra.add(x)
            elif x.is_Add or x.is_Mul:
                for arg in x.args:
                    scan(arg)
            elif x.is_Pow and x.exp.is_Integer:
                scan(x.base)
            elif x.is_number and algebraic(x):
                consts.add(x)
            else:
                raise _NotExact(f"the entry part {x} is not a rational function of sines and cosines, algebraic "
                                "numbers and parameters")

        for e in exprs:
            scan(e)
        self.extra = sorted(extra, key=str)             # π, e: generators (transcendental; no trig angle then)
        algebraic_consts = sorted((c for c in consts if not c.is_Rational), key=sp.default_sort_key)
        if algebraic_consts:
            K, _ = construct_domain(algebraic_consts, extension=True)
            if K.is_EX:
                raise _NotExact(f"the constants {algebraic_consts} are not algebraic numbers SymPy can do arithmetic with")
        else:
            K = sp.QQ
        self.K = K
        self.t = sp.Dummy("t")
        gens = [self.t] + self.extra + self.params
        self.F, *self.gens = _field(gens, K)
        self.domain = self.F.to_domain()
        self._gen = dict(zip(self.extra + self.params, self.gens[1:]))
        ring = self.F.ring
        self.ring = ring
        tt = ring.gens[0]
        self.one_t2 = 1 + tt ** 2
        self._pow_cache = {0: ring.one}
        self._atom = {}
        cache = {}
        for f, (n, q) in self.multiples.items():
            m = abs(n)
            if m not in cache:
                re, im = _re_im_power(2 * m)
                cache[m] = (sum((c * tt ** k for k, c in enumerate(re) if c), ring.zero),
                            sum((c * tt ** k for k, c in enumerate(im) if c), ring.zero))
            cn, sn = cache[m]
            sn = sn if n >= 0 else -sn
            cq, sq = self._kconst(sp.cos(q * sp.pi)), self._kconst(sp.sin(q * sp.pi))
            num = cn * cq - sn * sq if isinstance(f, sp.cos) else sn * cq + cn * sq
            self._atom[f] = (num, m)          # cos/sin(a) = num / (1 + t²)^m
        self._memo = {}

    def _kconst(self, c):
        return self.ring(self.K.convert(c) if c.is_Rational else self.K.from_sympy(c))

    def _lift(self, pair, e: int):
        num, k = pair
        if e == k:
            return num
        d = e - k
        if d not in self._pow_cache:
            self._pow_cache[d] = self.one_t2 ** d
        return num * self._pow_cache[d]

    def pair(self, e: sp.Expr):
        """e = num / (1 + t²)^k as (num ∈ K[t, params], k); _NotExact for a negative power of a non-constant
        (then :meth:`convert` works in the fraction field)."""
        if e.has(sp.tan, sp.cot, sp.sec, sp.csc):
            e = e.rewrite(sp.cos, sp.sin)
        memo, R = self._memo, self.ring

        def conv(x):
            if x in memo:
                return memo[x]
            if x in self._atom:
                out = self._atom[x]
            elif x in self._gen:
                out = (R(self._gen[x].numer), 0)
            elif x.is_Rational or (x.is_number and not x.has(*self._atom) and not x.has(*self._gen)):
                out = (self._kconst(x), 0)
            elif x.is_Add:
                parts = [conv(a) for a in x.args]
                k = max(p[1] for p in parts)
                out = (sum((self._lift(p, k) for p in parts), R.zero), k)
            elif x.is_Mul:
                num, k = R.one, 0
                for a in x.args:
                    pn, pk = conv(a)
                    num, k = num * pn, k + pk
                out = (num, k)
            elif x.is_Pow and x.exp.is_Integer and x.exp >= 0:
                pn, pk = conv(x.base)
                out = (pn ** int(x.exp), pk * int(x.exp))
            elif x.is_Pow and x.exp.is_Integer and x.base.is_number and not x.base.has(*self._atom):
                out = (self._kconst(x), 0)
            else:
                raise _NotExact(f"{x} is not a polynomial")
            memo[x] = out
            return out

        return conv(e)

    def convert(self, e: sp.Expr):
        """e as an element of the fraction field K(t, params)."""
        try:
            num, k = self.pair(e)
            return self.F(num) / self.F(self.one_t2) ** k if k else self.F(num)
        except _NotExact:
            pass
        if e.has(sp.tan, sp.cot, sp.sec, sp.csc):
            e = e.rewrite(sp.cos, sp.sin)
        if e.is_Add:
            return sum((self.convert(a) for a in e.args), self.F.zero)
        if e.is_Mul:
            out = self.F.one
            for a in e.args:
                out *= self.convert(a)
            return out
        if e.is_Pow and e.exp.is_Integer:
            return self.convert(e.base) ** int(e.exp)
        raise _NotExact(f"cannot convert {e}")  # pragma: no cover - scan() refused it already

    def matrix(self, M: sp.Matrix) -> DomainMatrix:
        """M over the polynomial ring K[t, params]: each row multiplied by the lcm of its denominators (a
        nonzero factor: powers of 1 + t² and of the parameters), which changes neither the rank nor the
        pivots nor the row space."""
        ring = self.ring
        rows = []
        for i in range(M.rows):
            try:
                pairs = [self.pair(M[i, j]) for j in range(M.cols)]
                k = max(p[1] for p in pairs)
                rows.append([self._lift(p, k) for p in pairs])
                continue
            except _NotExact:
                pass
            elems = [self.convert(M[i, j]) for j in range(M.cols)]
            den = ring.one
            for e in elems:
                den = den.lcm(e.denom)
            rows.append([e.numer * den.exquo(e.denom) for e in elems])
        return DomainMatrix(rows, M.shape, ring.to_domain())

    def field_matrix(self, M: sp.Matrix) -> DomainMatrix:
        return DomainMatrix([[self.convert(M[i, j]) for j in range(M.cols)] for i in range(M.rows)],
                            M.shape, self.domain)


def exact_is_zero(e: Any) -> bool:
    """Whether the number (or expression in positive parameters) e is exactly 0, proved.

    e may hold sin and cos of angles r + qπ (r, q rational), algebraic numbers and positive parameters; it is
    written in the field K(tan(g/2), params) of the module docstring, where "zero" is decided exactly.
    Raises ValueError when e is outside that class (then no exact decision is made).

    >>> import sympy as sp
    >>> exact_is_zero(sp.sin(3)**2 + sp.cos(3)**2 - 1), exact_is_zero(sp.sin(10) - 2*sp.sin(5)*sp.cos(5))
    (True, True)
    >>> exact_is_zero(sp.sin(sp.Rational(1, 2)) - sp.Rational(479, 1000))
    False
    """
    e = sp.sympify(e)
    if e == 0:
        return True
    try:
        return not _Field([e]).convert(e)
    except _NotExact as err:
        raise ValueError(f"no exact zero test for {e}: {err}") from None


# ----------------------------------------------------------------------------------------------
# exact rank and canonical bases
# ----------------------------------------------------------------------------------------------
def _ring_det(A: sp.Matrix) -> sp.Expr:
    """det A exactly, computed in the polynomial ring of the sines and cosines in A, folded for display."""
    if A.rows == 0:
        return sp.S.One
    if A.rows == 1:
        return A[0, 0]
    try:
        ring = TrigRing(list(A), opaque=True)
        if ring.domain.is_EX:
            raise NotTrigPolynomial(A)
        dA = DomainMatrix([[ring.normal_form(A[i, j]) for j in range(A.cols)] for i in range(A.rows)],
                          A.shape, ring.ring.to_domain())
        return ring.to_expr(ring.reduce(dA.det()), collect=True)
    except NotTrigPolynomial:
        return sp.expand(A.det(method="bareiss"))


def _display(e: sp.Expr) -> sp.Expr:
    """An exactly equal, readable form of an exact number (or expression in parameters)."""
    if e == 0 or e.is_Rational:
        return e
    num, den = sp.fraction(sp.cancel(sp.together(e))) if not e.has(sp.sin, sp.cos) else sp.fraction(sp.together(e))
    num, den = _fold(num), _fold(den)
    if den == 1:
        return num
    if den.could_extract_minus_sign():
        num, den = -num, -den
    return num / den


def _fold(e: sp.Expr) -> sp.Expr:
    if e.has(sp.sin, sp.cos):
        try:
            return simplify_for_display(e)
        except Exception:  # pragma: no cover - display only
            return sp.factor_terms(TR10i(sp.expand(e)))
    return sp.factor_terms(sp.radsimp(sp.expand(e))) if not e.is_Rational else e


def _ratio(num: sp.Expr, den: sp.Expr) -> sp.Expr:
    """num/den for display, with common polynomial factors (in the sines and cosines) cancelled."""
    if num == 0:
        return sp.S.Zero
    try:
        ring = TrigRing([num, den], opaque=True)
        if ring.domain.is_EX:
            raise NotTrigPolynomial(num)
        pn, pd = ring.normal_form(num), ring.normal_form(den)
        g = pn.gcd(pd)
        pn, pd = pn.exquo(g), pd.exquo(g)
        num, den = ring.to_expr(pn, collect=True), ring.to_expr(pd, collect=True)
    except (NotTrigPolynomial, Exception):
        pass
    return _display(num / den) if den != 1 else _display(num)


def _numeric_pivots(X, top) -> tuple:
    """(pivot columns, certain?) of the mpmath matrix X by greedy certified rank tests at 60 digits.

    A column joins when the smallest singular value of the chosen columns plus it exceeds 10⁻²⁰·σ_max(X)
    (certified: the entries and the SVD are accurate to ~10⁻⁵⁵·σ_max, and σ moves by at most that much).
    A column that does not join is a "zero" decision, certain only once the pivots already span every row."""
    import mpmath
    m, n = X.rows, X.cols
    piv: list = []
    with mpmath.workdps(FALLBACK_DIGITS):
        big = top * mpmath.mpf(10) ** -20
        for j in range(n):
            if len(piv) == m:
                break
            cols = piv + [j]
            sub = mpmath.matrix(m, len(cols))
            for a, c in enumerate(cols):
                for i in range(m):
                    sub[i, a] = X[i, c]
            smin = min(abs(x) for x in mpmath.svd_r(sub, compute_uv=False))
            if smin > big:
                piv.append(j)
            else:
                return piv, False
    return piv, True


class _Analysis:
    """The rank of an evaluated matrix A, its pivot columns (those of rref A) and independent rows.

    Without parameters, first by certified 60-digit numerics (each "independent" decision certified, see
    :func:`_numeric_pivots`); as soon as a decision would be "dependent" (a rank drop, a skipped column), exactly:
    Gaussian elimination in K(t, params) (module docstring)."""

    def __init__(self, A: sp.Matrix):
        self.A = A
        self._fld = None
        if not A.free_symbols:
            X = _mp_matrix(A)
            import mpmath
            with mpmath.workdps(FALLBACK_DIGITS):
                top = max((abs(x) for x in mpmath.svd_r(X, compute_uv=False)), default=mpmath.mpf(0))
            if top > 0:
                piv, ok = _numeric_pivots(X, top)
                if ok:
                    rows, ok = _numeric_pivots(X.T, top)
                    if ok:
                        self.pivots, self.rows, self.rank, self.R = piv, rows, len(piv), None
                        return
        fld = self.fld
        dA = fld.matrix(A).to_field()
        self.R, self.pivots = dA.rref()
        self.R = self.R.to_list()
        self.rank = len(self.pivots)
        _, rows = dA.transpose().rref()       # independent rows: the pivot columns of Aᵀ
        self.rows = list(rows)

    @property
    def fld(self) -> _Field:
        if self._fld is None:
            self._fld = _Field(list(self.A))
        return self._fld

    def entry_is_zero(self, k: int, j: int, expr) -> bool:
        """Whether rref(A)[k, j] is 0; ``expr()`` gives its numerator (a minor) when it must be computed."""
        if self.R is not None:
            return not self.R[k][j]
        return _decide_zero(expr())


def _decide_zero(e: sp.Expr) -> bool:
    """e = 0? A 60-digit value above 1e-30 proves nonzero (SymPy's evalf tracks cancellation); otherwise exactly."""
    if e == 0:
        return True
    if e.is_Rational:
        return False
    if not e.free_symbols:
        import mpmath
        with mpmath.workdps(FALLBACK_DIGITS + 40):
            if abs(_mp_value(e, {})) > mpmath.mpf(10) ** -30:
                return False
    return not _Field([e]).convert(e)


def _canonical_rows(A: sp.Matrix, an: _Analysis) -> sp.Matrix:
    """The nonzero rows of rref(A), exact, entries written as ratios of minors of A (Cramer's rule)."""
    r = an.rank
    if r == 0:
        return sp.zeros(0, A.cols)
    I, P = an.rows, list(an.pivots)
    B = A.extract(I, P)
    D = _ring_det(B)
    out = sp.zeros(r, A.cols)
    for k in range(r):
        for j in range(A.cols):
            if j in P:
                out[k, j] = sp.S.One if P.index(j) == k else sp.S.Zero
                continue
            Bk = B.copy()
            Bk[:, k] = A.extract(I, [j])
            minor = {}

            def numerator():
                minor["d"] = _ring_det(Bk)
                return minor["d"]
            if an.entry_is_zero(k, j, numerator):
                continue
            out[k, j] = _ratio(minor["d"] if "d" in minor else _ring_det(Bk), D)
    return out


def _never_zero(factor: sp.Expr, fld: _Field) -> bool:
    """True when the factor (an expression in the positive parameters with exact-number coefficients) is nonzero
    for every positive value of the parameters: written as a polynomial in them, all its coefficients (numbers,
    evaluated at the true t with 50 digits) share one strict sign. A nonzero polynomial in the transcendental t is
    nonzero at the true t, so a coefficient that evaluates to below 1e-40 is treated as "sign unknown"."""
    num = fld.convert(factor).numer
    nparam, base = len(fld.params), 1 + len(fld.extra)
    gens_sym = [fld.t] + list(fld.extra)
    grouped: dict = {}
    for monom, coeff in num.terms():
        pm = monom[base:base + nparam]
        val = sp.Mul(fld.K.to_sympy(coeff), *[s ** d for s, d in zip(gens_sym, monom[:base])])
        grouped[pm] = grouped.get(pm, 0) + val
    tval = sp.tan(fld.g / 2) if fld.g != 0 else sp.S.Zero
    signs = set()
    for val in grouped.values():
        v = sp.N(sp.sympify(val).subs(fld.t, tval), 50)
        signs.add(0 if v == 0 or abs(v) < sp.Float("1e-40") else (1 if v > 0 else -1))
    return len(signs) == 1 and 0 not in signs


#: how many r×r minors :func:`_conditions` looks at for one that never vanishes
MAX_MINORS = 60


def _vanishing_factors(D: sp.Expr, an: _Analysis) -> list:
    """The factors of D that involve the parameters and can vanish for positive parameters (sign-normalised)."""
    params = set(an.fld.params)
    _, factors = sp.factor_list(sp.factor_terms(D))
    out = []
    for f, _mult in factors:
        if not (f.free_symbols & params):
            continue
        if f.could_extract_minus_sign():
            f = -f
        if not _never_zero(f, an.fld) and f not in out:
            out.append(f)
    return out


def _conditions(A: sp.Matrix, an: _Analysis) -> tuple:
    """Where the rank r found (over the field of the parameters) could be lower for positive parameters.

    rank A < r exactly where every r×r minor vanishes. The pivot minor and then others (up to ``MAX_MINORS``) are
    examined: one that never vanishes for positive parameters proves the rank for all of them (no condition);
    otherwise the factors shared by all the minors examined (each can vanish) are returned — the rank is r wherever
    none of them vanishes. If the minors share none, the pivot minor's factors are returned (sufficient)."""
    if not A.free_symbols or an.rank == 0:
        return ()
    r = an.rank
    first = (tuple(an.rows), tuple(an.pivots))
    others = itertools.product(itertools.combinations(range(A.rows), r), itertools.combinations(range(A.cols), r))
    common, pivot_factors = None, None
    for I, P in itertools.islice(itertools.chain([first], (c for c in others if c != first)), MAX_MINORS):
        D = _ring_det(A.extract(list(I), list(P)))     # in the sines and cosines of A (the field's atoms)
        if D == 0 or not an.fld.convert(D):
            continue
        facs = _vanishing_factors(D, an)
        if not facs:
            return ()
        if pivot_factors is None:
            pivot_factors = facs
        common = facs if common is None else [f for f in common if f in facs]
    return tuple(_fold(f) for f in (common or pivot_factors or ()))


# ----------------------------------------------------------------------------------------------
# the numeric fallback (stated precision)
# ----------------------------------------------------------------------------------------------
def _mp_value(e: sp.Expr, memo: dict):
    """e to ``FALLBACK_DIGITS + 40`` digits (call inside mpmath.workdps), shared subexpressions evaluated once."""
    import mpmath
    if e in memo:
        return memo[e]
    if e.is_Rational:
        v = mpmath.mpf(e.p) / e.q
    elif e is sp.pi:
        v = +mpmath.pi
    elif e is sp.E:
        v = mpmath.e
    elif e.is_Add:
        v = mpmath.fsum(_mp_value(a, memo) for a in e.args)
    elif e.is_Mul:
        v = mpmath.fprod(_mp_value(a, memo) for a in e.args)
    elif e.is_Pow and e.exp.is_Rational:
        b = _mp_value(e.base, memo)
        v = b ** int(e.exp) if e.exp.is_Integer else b ** (mpmath.mpf(e.exp.p) / e.exp.q)
    elif isinstance(e, sp.sin):
        v = mpmath.sin(_mp_value(e.args[0], memo))
    elif isinstance(e, sp.cos):
        v = mpmath.cos(_mp_value(e.args[0], memo))
    else:
        v = mpmath.mpf(str(sp.N(e, mpmath.mp.dps)))
    memo[e] = v
    return v


def _mp_matrix(A: sp.Matrix):
    """A as an mpmath matrix, entries to ~100 digits (the SVD then runs at ``FALLBACK_DIGITS``)."""
    import mpmath
    if A.free_symbols:
        raise ValueError("no exact decision is possible here and the numeric fallback needs numbers: J still has "
                         f"the parameters {', '.join(map(str, sorted(A.free_symbols, key=str)))}; substitute them")
    memo: dict = {}
    with mpmath.workdps(FALLBACK_DIGITS + 40):
        return mpmath.matrix([[_mp_value(A[i, j], memo) for j in range(A.cols)] for i in range(A.rows)])


def _fallback_rank(A: sp.Matrix) -> tuple:
    import mpmath
    X = _mp_matrix(A)
    with mpmath.workdps(FALLBACK_DIGITS):
        s = mpmath.svd_r(X, compute_uv=False)
        sv = sorted((abs(x) for x in s), reverse=True)
        top = sv[0] if sv else mpmath.mpf(0)
        tol = top * mpmath.mpf(10) ** (-FALLBACK_ZERO_DIGITS)
        r = sum(1 for x in sv if x > tol)
    return r, sv


def _fallback_rref(A: sp.Matrix) -> sp.Matrix:
    """Nonzero rows of rref(A), 60-digit arithmetic with partial pivoting, entries as 30-digit Floats."""
    import mpmath
    X = _mp_matrix(A)
    r, sv = _fallback_rank(A)
    with mpmath.workdps(FALLBACK_DIGITS):
        m, n = X.rows, X.cols
        X = X.copy()
        tol = (sv[0] if sv else 0) * mpmath.mpf(10) ** (-FALLBACK_ZERO_DIGITS)
        row, piv = 0, []
        for j in range(n):
            if row == m:
                break
            k = max(range(row, m), key=lambda i: abs(X[i, j]))
            if abs(X[k, j]) <= tol:
                continue
            X[row, :], X[k, :] = X[k, :], X[row, :]
            X[row, :] = X[row, :] / X[row, j]
            for i in range(m):
                if i != row and X[i, j] != 0:
                    X[i, :] = X[i, :] - X[i, j] * X[row, :]
            piv.append(j)
            row += 1
        rows = [[sp.Float(mpmath.nstr(X[i, j], 30), 30) if abs(X[i, j]) > tol else sp.S.Zero for j in range(n)]
                for i in range(row)]
    return sp.Matrix(rows) if rows else sp.zeros(0, n)


def _fallback_warning(what: str, why: str):
    warnings.warn(f"{what}: no exact decision here ({why}); computed with {FALLBACK_DIGITS}-digit numerics "
                  f"(singular values below 1e-{FALLBACK_ZERO_DIGITS}·σ_max counted as zero, not proven)",
                  NumericFallbackWarning, stacklevel=3)


# ----------------------------------------------------------------------------------------------
# public functions
# ----------------------------------------------------------------------------------------------
def _numeric_J(J: Any, name: str = "J") -> np.ndarray:
    """A numeric Jacobian as a finite float array (m, n); bools, strings, complex numbers, NaN/inf refused."""
    if isinstance(J, (str, bytes)) or J is None or isinstance(J, (numbers.Number, np.generic)):
        raise TypeError(f"{name} must be a matrix (m×n Jacobian), got {describe(J)}")
    if isinstance(J, np.ndarray) and J.dtype.kind in "iuf":
        A = J
    else:
        try:
            obj = np.asarray(J, dtype=object)
        except Exception:
            raise TypeError(f"{name} must be a matrix (m×n Jacobian), got {describe(J)}") from None
        for e in obj.flat:
            if isinstance(e, (bool, np.bool_)):
                raise TypeError(f"{name} must hold numbers, got the bool {e!r} ({describe(J)})")
            if isinstance(e, (complex, np.complexfloating)):
                raise TypeError(f"{name} must hold real numbers, got the complex number {e!r} ({describe(J)})")
            if not isinstance(e, (numbers.Real, np.integer, np.floating)):
                raise TypeError(f"{name} must hold real numbers, got an entry {describe(e)}")
        A = obj
    if A.ndim != 2:
        raise ValueError(f"{name} must be a matrix (m×n Jacobian), got {describe(J)}")
    A = np.asarray(A, dtype=float)
    if 0 in A.shape:
        raise ValueError(f"{name} must have at least one row and one column, got {describe(J)}")
    if not np.isfinite(A).all():
        raise ValueError(f"{name} must hold finite numbers, got NaN or inf in {describe(J)}")
    return A


def _numeric_rank_tol(s: np.ndarray, shape) -> float:
    return max(shape) * np.finfo(float).eps * (s[0] if s.size else 0.0) * 100


def _is_numeric_input(J: Any, subs: Any) -> bool:
    return subs is None and not is_symbolic(J) and not (
        isinstance(J, (list, tuple)) and any(isinstance(e, (sp.Basic,)) for e in np.asarray(J, dtype=object).flat))


def evaluate_at(J: Any, subs: Any = None, thetas: Sequence[sp.Symbol] | None = None):
    """J(θ₀): the Jacobian at a configuration, exact, with every zero entry proved zero.

    ``subs``: a mapping {joint symbol: value} or a sequence of values matched to ``thetas``. Values are exact
    numbers (π/4, 1/2, 10, ``Fraction(1, 2)``) or expressions in positive parameters (θ3 = −L2); a float
    (Python, NumPy or SymPy) says the configuration is approximate and selects the numeric backend (a float array,
    and for :func:`rank_at` and the bases a float SVD). The result may still contain positive parameters, never a joint. Entries are written
    readably (sin² + cos² = 1 applied, angle sums folded); an entry is 0 exactly when it is 0 (decided exactly,
    see the module docstring). A numeric J (an array, no subs) comes back as a float array.

    >>> import sympy as sp
    >>> t1, t2 = sp.symbols("theta1 theta2", real=True)
    >>> J = sp.Matrix([[-sp.sin(t1) - sp.sin(t1 + t2), -sp.sin(t1 + t2)], [sp.cos(t1) + sp.cos(t1 + t2), sp.cos(t1 + t2)]])
    >>> evaluate_at(J, {t1: 10, t2: 0})
    Matrix([
    [-2*sin(10), -sin(10)],
    [ 2*cos(10),  cos(10)]])
    """
    if _is_numeric_input(J, subs):
        return _numeric_J(J)
    M, numeric = _evaluated(J, subs, thetas)
    if numeric:
        return _as_float(M)
    try:
        zero = [_decide_zero(e) for e in M]
    except _NotExact:
        zero = [e == 0 for e in M]
    return sp.Matrix(M.rows, M.cols, [sp.S.Zero if z else _display(e) for e, z in zip(M, zero)])


def _analyse(M: sp.Matrix, what: str):
    """(_Analysis or None, reason): the exact analysis, or None with the reason it is out of reach."""
    try:
        return _Analysis(M), ""
    except _NotExact as err:
        return None, str(err)


def rank_at(J: Any, subs: Any = None, thetas: Sequence[sp.Symbol] | None = None) -> int:
    """rank J(θ₀) at a configuration, proved exactly (see the module docstring); a :class:`Rank` (an int).

    ``subs`` as in :func:`evaluate_at` (float values: a float SVD, ``Rank.exact`` False). With symbolic link lengths the rank holds for all their positive values,
    or ``Rank.unless`` names the minor whose vanishing would lower it. Out of reach of the exact method (e.g. an
    angle √2), a 60-digit SVD decides and ``Rank.exact`` is False. A numeric J (float array, no subs): the
    SVD with tolerance 100·max(m, n)·ε·σ_max.

    >>> import sympy as sp
    >>> t1, t2 = sp.symbols("theta1 theta2", real=True)
    >>> J = sp.Matrix([[-sp.sin(t1) - sp.sin(t1 + t2), -sp.sin(t1 + t2)], [sp.cos(t1) + sp.cos(t1 + t2), sp.cos(t1 + t2)]])
    >>> rank_at(J, {t1: 10, t2: 0}), rank_at(J, {t1: sp.Rational(1, 2), t2: sp.Rational(1, 2)})
    (1, 2)
    """
    if _is_numeric_input(J, subs):
        A = _numeric_J(J)
        s = np.linalg.svd(A, compute_uv=False)
        return Rank(int(np.sum(s > _numeric_rank_tol(s, A.shape))), exact=False,
                    note="float SVD, tolerance 100·max(m, n)·ε·σ_max")
    M, numeric = _evaluated(J, subs, thetas)
    if numeric:
        return rank_at(_as_float(M))
    an, why = _analyse(M, "rank_at")
    if an is None:
        r, _ = _fallback_rank(M)
        return Rank(r, exact=False, note=f"{FALLBACK_DIGITS}-digit SVD ({why})")
    unless = _conditions(M, an)
    return Rank(an.rank, unless=unless, note="exact elimination in K(tan(g/2), parameters)")


def _warn_conditions(what: str, unless: tuple):
    if unless:
        warnings.warn(f"{what} holds for the parameters where {', '.join(map(sp.sstr, unless))} ≠ 0",
                      ConditionalResultWarning, stacklevel=3)


def column_space(J: Any, subs: Any = None, thetas: Sequence[sp.Symbol] | None = None):
    """A basis of range J(θ₀) (the twists/velocities the robot can produce there), as columns (m×r).

    Exact J: the canonical basis, the nonzero rows of rref(Jᵀ) (leading entries 1), so equal subspaces give
    equal matrices; proved exactly as in :func:`rank_at`, entries written with the configuration's sines and
    cosines. Numeric J: an orthonormal basis from the SVD.

    >>> import sympy as sp
    >>> t1, t2 = sp.symbols("theta1 theta2", real=True)
    >>> J = sp.Matrix([[-sp.sin(t1) - sp.sin(t1 + t2), -sp.sin(t1 + t2)], [sp.cos(t1) + sp.cos(t1 + t2), sp.cos(t1 + t2)]])
    >>> column_space(J, {t1: 3, t2: 0}).T
    Matrix([[1, -cos(3)/sin(3)]])
    """
    if _is_numeric_input(J, subs):
        A = _numeric_J(J)
        U, s, _ = np.linalg.svd(A)
        return U[:, : int(np.sum(s > _numeric_rank_tol(s, A.shape)))]
    M, numeric = _evaluated(J, subs, thetas)
    if numeric:
        return column_space(_as_float(M))
    A = M.T
    an, why = _analyse(A, "column_space")
    if an is None:
        _fallback_warning("column_space", why)
        return _fallback_rref(A).T
    _warn_conditions("column_space", _conditions(A, an))
    return _canonical_rows(A, an).T


def left_null_space(J: Any, subs: Any = None, thetas: Sequence[sp.Symbol] | None = None):
    """A basis of null J(θ₀)ᵀ (the directions y the robot cannot move along: yᵀJ = 0), as columns (m×(m − r)).

    Exact J: the canonical (rref) basis, proved exactly as in :func:`rank_at`; empty (m×0) at full row rank.
    Numeric J: orthonormal, from the SVD.

    >>> import sympy as sp
    >>> t1, t2 = sp.symbols("theta1 theta2", real=True)
    >>> J = sp.Matrix([[-sp.sin(t1) - sp.sin(t1 + t2), -sp.sin(t1 + t2)], [sp.cos(t1) + sp.cos(t1 + t2), sp.cos(t1 + t2)]])
    >>> left_null_space(J, {t1: 3, t2: 0}).T
    Matrix([[1, sin(3)/cos(3)]])
    """
    if _is_numeric_input(J, subs):
        A = _numeric_J(J)
        U, s, _ = np.linalg.svd(A)
        return U[:, int(np.sum(s > _numeric_rank_tol(s, A.shape))):]
    M, numeric = _evaluated(J, subs, thetas)
    if numeric:
        return left_null_space(_as_float(M))
    A = M.T                                   # null(Mᵀ) = null(A)
    m = A.cols
    an, why = _analyse(A, "left_null_space")
    if an is None:
        _fallback_warning("left_null_space", why)
        R = _fallback_rref(A)
        return _null_from_rref(R, m, fallback=True)
    _warn_conditions("left_null_space", _conditions(A, an))
    if an.rank == m:
        return sp.zeros(m, 0)
    R = _canonical_rows(A, an)
    N = _null_from_rref(R, m)
    return _canonical_rows(N, _Analysis(N)).T if N.rows else sp.zeros(m, 0)


def _null_from_rref(R: sp.Matrix, m: int, fallback: bool = False) -> sp.Matrix:
    """Rows spanning null(R) for R in rref: x_f = 1 for a free column f, x_P = −R[:, f]."""
    piv = []
    for k in range(R.rows):
        j = next(j for j in range(m) if R[k, j] != 0)
        piv.append(j)
    free = [j for j in range(m) if j not in piv]
    rows = []
    for f in free:
        x = [sp.S.Zero] * m
        x[f] = sp.S.One
        for k, p in enumerate(piv):
            x[p] = -R[k, f]
        rows.append(x)
    N = sp.Matrix(rows) if rows else sp.zeros(0, m)
    if fallback:
        return N.T
    return N
