"""How :mod:`kinlib.exact` decides a rank at a configuration, and the canonical bases and conditions built on it.

The rank of an evaluated J is decided by :class:`RankAnalysis` (certified 60-digit numerics for every
"independent", exact arithmetic for every "dependent"); :func:`canonical_rows` writes rref rows as ratios of
minors (:func:`ring_det`); :func:`rank_conditions` names where positive parameters could lower the rank.

>>> import sympy as sp
>>> L = sp.Symbol("L", positive=True)
>>> an = RankAnalysis(sp.Matrix([[L, 2 * L], [1, 2]]))
>>> an.rank, an.pivots
(1, [0])
"""

from __future__ import annotations

import itertools

import sympy as sp
from sympy.polys.matrices import DomainMatrix

from .display import readable_fold, readable_ratio
from .field import FALLBACK_DIGITS, ExactField, NotExact, PointLift, decide_zero, mp_context, mp_matrix, mp_value
from .trigpoly import NotTrigPolynomial, TrigRing

__all__ = ["EXACT_BUDGET", "MAX_MINORS", "RankAnalysis", "ring_det", "canonical_rows", "rank_conditions"]

#: exact elimination only while (largest multiple n of the common angle measure g) × min(m, n) ≤ this
#: (a 6×6 J: multiples up to 16, a few seconds; beyond, the 60-digit fallback answers, and says so)
EXACT_BUDGET = 100


def ring_det(A: sp.Matrix) -> sp.Expr:
    """det A exactly, computed in the polynomial ring of the sines and cosines in A, folded for display.

    >>> ring_det(sp.Matrix([[sp.cos(3), -sp.sin(3)], [sp.sin(3), sp.cos(3)]]))   # a rotation: sin² + cos² = 1
    1
    """
    if A.rows == 0:
        return sp.S.One
    if A.rows == 1:
        return A[0, 0]
    try:
        ring = TrigRing(list(A), opaque=True)
        if ring.domain.is_EX:
            raise NotTrigPolynomial(A)
        dA = DomainMatrix(
            [[ring.normal_form(A[i, j]) for j in range(A.cols)] for i in range(A.rows)], A.shape, ring.ring.to_domain()
        )
        return ring.to_expr(ring.reduce(dA.det()), collect=True)
    except NotTrigPolynomial:
        return sp.expand(A.det(method="bareiss"))


def _numeric_pivots(X, top) -> tuple:
    """(pivot columns, certain?) of the mpmath matrix X by greedy certified rank tests at 60 digits.

    A column joins when the smallest singular value of the chosen columns plus it exceeds 10⁻²⁰·σ_max(X)
    (certified: the entries and the SVD are accurate to ~10⁻⁵⁵·σ_max, and σ moves by at most that much).
    A column that does not join is a "zero" decision, certain only once the pivots already span every row."""
    mpmath = mp_context()

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


#: the parameter values at which a matrix with parameters is first looked at numerically (distinct, unrelated
#: rationals: a minor nonzero there is a nonzero function of the parameters, so the rank is at least as large)
SPECIAL_VALUES = tuple(sp.Rational(p, q) for p, q in ((97, 61), (113, 73), (131, 89), (151, 67), (167, 103), (181, 79)))


def _certified_pivots(A: sp.Matrix):
    """(pivots, rows, top) when 60-digit numerics certify that A has full rank min(m, n) with the first
    independent columns and rows as pivots, else None. With parameters, A is looked at with the parameters at
    :data:`SPECIAL_VALUES` (cycled): a nonzero minor there is a nonzero rational function of them."""
    mpmath = mp_context()

    if A.free_symbols:
        A = A.xreplace(_special(A.free_symbols))
        if any(e.has(sp.nan, sp.zoo, sp.oo, -sp.oo) for e in A):
            return None
    X = mp_matrix(A)
    with mpmath.workdps(FALLBACK_DIGITS):
        top = max((abs(x) for x in mpmath.svd_r(X, compute_uv=False)), default=mpmath.mpf(0))
    if not top > 0:
        return None
    piv, ok = _numeric_pivots(X, top)
    if not ok:
        return None
    rows, ok = _numeric_pivots(X.T, top)
    return (piv, rows) if ok else None


def _rref(dA: DomainMatrix, fld: ExactField) -> tuple:
    """(rows of a matrix with rref(dA)'s zero pattern, as lists; pivot columns), exactly. In K(t) or K(t, L)
    SymPy's elimination over the fraction field is fastest; with more generators its gcds explode (11.6 s
    against 2.4 s on a PUMA 560 with two symbolic lengths) and fraction-free elimination over K[t, …] is used."""
    if len(fld.params) + len(fld.extra) <= 1:
        R, pivots = dA.to_field().rref()
    else:
        R, _den, pivots = dA.rref_den()  # den · rref: the same zero pattern
    return R.to_list(), list(pivots)


def _independent_rows(A: sp.Matrix, pivots: list):
    """r = len(pivots) rows I with A[I, pivots] nonsingular, certified by 60-digit numerics (parameters at
    :data:`SPECIAL_VALUES`: nonsingular there is nonsingular), or None. Any such rows serve Cramer's rule."""
    mpmath = mp_context()

    r = len(pivots)
    if r == 0:
        return []
    X = mp_matrix(A.extract(list(range(A.rows)), pivots).xreplace(_special(A.free_symbols)))
    rows: list = []
    with mpmath.workdps(FALLBACK_DIGITS):
        top = max((abs(x) for x in mpmath.svd_r(X, compute_uv=False)), default=mpmath.mpf(0))
        for i in range(A.rows):
            sub = mpmath.matrix([[X[k, j] for j in range(r)] for k in rows + [i]])
            if min(abs(x) for x in mpmath.svd_r(sub, compute_uv=False)) > top * mpmath.mpf(10) ** -20:
                rows.append(i)
                if len(rows) == r:
                    return rows
    return None


def _special(params) -> dict:
    ordered = sorted(params, key=str)
    n = len(SPECIAL_VALUES)
    return {p: SPECIAL_VALUES[i % n] + i // n for i, p in enumerate(ordered)}


class RankAnalysis:
    """The rank of an evaluated matrix A, its pivot columns (those of rref A) and independent rows.

    First by certified 60-digit numerics (each "independent" decision certified, see :func:`_numeric_pivots`;
    with parameters, at :data:`SPECIAL_VALUES` of them: the rank over the field of the parameters is at least the
    rank there, so full rank there is full rank, proved); as soon as a decision would be "dependent" (a rank drop,
    a skipped column), exactly: fraction-free Gaussian elimination over K[t, params] (module docstring).

    >>> import sympy as sp
    >>> L = sp.Symbol("L", positive=True)
    >>> an = RankAnalysis(sp.Matrix([[L, 1], [1, L]]))   # det = L² − 1: full rank over the field of L
    >>> an.rank, an.pivots, an.rows, an.certified
    (2, [0, 1], [0, 1], True)
    """

    def __init__(self, A: sp.Matrix):
        self.A = A
        self._fld = None
        self.certified = False
        self.pose = None
        got = _certified_pivots(A)
        if got is not None:
            self.pivots, self.rows = got
            self.rank, self.R, self.certified = len(self.pivots), None, True
            return
        got = _singular_pose(A)
        if got is not None:
            self.pose, (self.pivots, self.rows) = got
            self.rank, self.R = len(self.pivots), None
            return
        fld = self.fld
        size = max((abs(n) for n, _ in fld.multiples.values()), default=0) * min(A.shape)
        if size > EXACT_BUDGET:
            raise NotExact(
                f"exact elimination with angles up to {size // min(A.shape)} multiples of their common "
                f"measure {fld.g} on a {A.rows}×{A.cols} matrix is out of reach in seconds"
            )
        dA = fld.matrix(A)
        self.R, self.pivots = _rref(dA, fld)
        self.rank = len(self.pivots)
        self.rows = _independent_rows(A, self.pivots)
        if self.rows is None:  # the pivot columns of Aᵀ, exactly
            self.rows = _rref(dA.transpose(), fld)[1]

    def is_zero(self, e: sp.Expr, minor: tuple | None = None) -> bool:
        """Whether e (a number or expression in the parameters, built from A's sines and cosines) is 0, proved:
        nonzero when its value (parameters at :data:`SPECIAL_VALUES`) is above 10⁻³⁰ at 100 digits, else exactly.
        ``minor``: (rows, columns) when e is that minor of A (decided as at a singular pose, when A is one)."""
        mpmath = mp_context()

        if self.pose is not None and minor is not None:
            z = self.pose.minor_zero(*minor)
            if z is not None:
                return z

        try:
            with mpmath.workdps(FALLBACK_DIGITS + 40):
                if abs(mp_value(e.xreplace(_special(e.free_symbols)), {}, mpmath)) > mpmath.mpf(10) ** -30:
                    return False
        except (TypeError, ValueError, ZeroDivisionError):
            pass
        return not self.fld.convert(e)

    @property
    def fld(self) -> ExactField:
        if self._fld is None:
            self._fld = ExactField(list(self.A))
        return self._fld

    def entry_is_zero(self, k: int, j: int, expr, minor: tuple | None = None) -> bool:
        """Whether rref(A)[k, j] is 0; ``expr()`` gives its numerator (a minor) when it must be computed;
        ``minor``: its (rows, columns) in A."""
        if self.R is not None:
            return not self.R[k][j]
        if self.pose is not None and minor is not None:
            z = self.pose.minor_zero(*minor)
            if z is not None:
                return z
        return decide_zero(expr())


def canonical_rows(A: sp.Matrix, an: RankAnalysis) -> sp.Matrix:
    """The nonzero rows of rref(A), exact, entries written as ratios of minors of A (Cramer's rule).

    >>> A = sp.Matrix([[sp.sin(1), 2 * sp.sin(1)], [sp.cos(1), 2 * sp.cos(1)]])
    >>> canonical_rows(A, RankAnalysis(A))
    Matrix([[1, 2]])
    """
    r = an.rank
    if r == 0:
        return sp.zeros(0, A.cols)
    I, P = an.rows, list(an.pivots)
    B = A.extract(I, P)
    D = ring_det(B)
    out = sp.zeros(r, A.cols)
    for k in range(r):
        for j in range(A.cols):
            if j in P:
                out[k, j] = sp.S.One if P.index(j) == k else sp.S.Zero
                continue
            Bk = B.copy()
            Bk[:, k] = A.extract(I, [j])
            minor = {}

            def numerator(Bk=Bk, minor=minor):
                minor["d"] = ring_det(Bk)
                return minor["d"]

            if an.entry_is_zero(k, j, numerator, (I, P[:k] + [j] + P[k + 1 :])):
                continue
            out[k, j] = readable_ratio(minor["d"] if "d" in minor else ring_det(Bk), D)
    return out


def _never_zero(factor: sp.Expr, params: list) -> bool:
    """True when the factor (an expression in the positive parameters with exact-number coefficients) is nonzero
    for every positive value of the parameters: written as a polynomial in them, all its coefficients share one
    strict sign. A coefficient's sign is read from its value at ``FALLBACK_DIGITS + 40`` digits when that is above
    10⁻³⁰ (certified, as in :func:`kinlib.exactfield.decide_zero`); a smaller one is decided exactly: zero (left
    out) or "sign unknown" (the factor may vanish)."""
    mpmath = mp_context()

    try:
        terms = sp.Poly(factor, *params, domain="EX").terms()
    except sp.PolynomialError:  # not a polynomial in the parameters (√L …): it may vanish, as far as we know
        return False
    signs, memo = set(), {}
    for _monom, coeff in terms:
        c = sp.sympify(getattr(coeff, "ex", coeff))
        try:
            with mpmath.workdps(FALLBACK_DIGITS + 40):
                v = mp_value(c, memo, mpmath)
            big = abs(v) > mpmath.mpf(10) ** -30
        except (TypeError, ValueError):
            big = False
        if big:
            signs.add(1 if v > 0 else -1)
            continue
        try:
            if decide_zero(c, "a coefficient"):
                continue
        except ValueError:
            pass
        return False
    return len(signs) == 1


#: how many r×r minors :func:`rank_conditions` looks at for one that never vanishes
MAX_MINORS = 60


def _vanishing_factors(D: sp.Expr, an: RankAnalysis) -> list:
    """The factors of D that involve the parameters and can vanish for positive parameters (sign-normalised)."""
    ordered = sorted(an.A.free_symbols, key=str)
    params = set(ordered)
    try:  # factored in the parameters, the configuration's constants as coefficients (nested radicals such
        # as √(5 + √5) make SymPy's factor_list over all atoms fail: "Cannot construct a polynomial from 1")
        _, factors = sp.factor_list(sp.factor_terms(D), *sorted(params, key=str))
    except sp.PolynomialError:
        factors = [(sp.expand(D), 1)]  # one factor: a sufficient condition all the same
    out = []
    for f, _mult in factors:
        if not (f.free_symbols & params):
            continue
        if f.could_extract_minus_sign():
            f = -f
        if not _never_zero(f, ordered) and f not in out:
            out.append(f)
    return out


def rank_conditions(A: sp.Matrix, an: RankAnalysis) -> tuple:
    """Where the rank r found (over the field of the parameters) could be lower for positive parameters.

    rank A < r exactly where every r×r minor vanishes. The pivot minor and then others (up to ``MAX_MINORS``) are
    examined: one that never vanishes for positive parameters proves the rank for all of them (no condition);
    otherwise the factors shared by all the minors examined (each can vanish) are returned — the rank is r wherever
    none of them vanishes. If the minors share none, the pivot minor's factors are returned (sufficient).

    >>> L1, L2 = sp.symbols("L1 L2", positive=True)
    >>> A = sp.Matrix([[L1, L2], [1, 1]])
    >>> rank_conditions(A, RankAnalysis(A))   # rank 2 unless L1 = L2
    (L1 - L2,)
    """
    if not A.free_symbols or an.rank == 0:
        return ()
    r = an.rank
    first = (tuple(an.rows), tuple(an.pivots))
    others = itertools.product(itertools.combinations(range(A.rows), r), itertools.combinations(range(A.cols), r))
    common, pivot_factors = None, None
    for I, P in itertools.islice(itertools.chain([first], (c for c in others if c != first)), MAX_MINORS):
        D = ring_det(A.extract(list(I), list(P)))  # in the sines and cosines of A (the field's atoms)
        if D == 0 or ((I, P) != first or not an.certified) and an.is_zero(D, (list(I), list(P))):
            continue
        facs = _vanishing_factors(D, an)
        if not facs:
            return ()
        if pivot_factors is None:
            pivot_factors = facs
        common = facs if common is None else [f for f in common if f in facs]
    return tuple(readable_fold(f) for f in (common or pivot_factors or ()))


# ----------------------------------------------------------------------------------------------
# singular poses: zero tests through independent angles (no number field)
# ----------------------------------------------------------------------------------------------
#: the precisions (digits) at which a minor that is not 0 for all φ is looked at again: nonzero when above
#: 10^(70 − digits) times Hadamard's bound (the margin of :func:`_numeric_pivots`, 70 digits)
_ESCALATE = (100, 300, 1000)
#: minors are factored only over QQ and with at most this many terms (SymPy's multivariate factoring, slow over
#: an algebraic extension: 25 s a minor); otherwise the minor's value is decided whole
_MAX_FACTOR_TERMS = 400


def _mp_det(rows: list):
    """det of a small square mpmath matrix (lists) by elimination with partial pivoting (call inside workdps);
    mpmath.det fails on an exactly singular one."""
    A = [list(r) for r in rows]
    n, d = len(A), 1
    for j in range(n):
        k = max(range(j, n), key=lambda i: abs(A[i][j]))
        if not A[k][j]:
            return 0 * d
        if k != j:
            A[j], A[k] = A[k], A[j]
            d = -d
        d *= A[j][j]
        for i in range(j + 1, n):
            f = A[i][j] / A[j][j]
            if f:
                A[i] = [a - f * b for a, b in zip(A[i], A[j])]
    return d


def _has_division(e: sp.Expr) -> bool:
    return any(p.exp.is_negative for p in e.atoms(sp.Pow))


def _hadamard_small(d, X, rows, cols, digits: int) -> bool:
    """Whether |d| (a minor X[rows, cols] computed at ``digits`` digits) is below the certification line
    10^(70 − digits) · Π max(‖column‖, s) (Hadamard's bound on the minor; s = the largest entry of X):
    "not certified nonzero". The floor s: an entry's error is absolute, on the scale of the matrix, so a column
    that is 0 exactly but computed as 10⁻¹⁰² must not make its own noise look certified (a PUMA's linear rows at
    its elbow singularity, rank 1, were given rank 3; issue 32)."""
    mpmath = mp_context()

    s = max((abs(X[i, j]) for i in range(X.rows) for j in range(X.cols)), default=mpmath.mpf(0))
    h = mpmath.mpf(1)
    for j in cols:
        h *= max(mpmath.sqrt(mpmath.fsum(abs(X[i, j]) ** 2 for i in rows)), s)
    return not abs(d) > h * mpmath.mpf(10) ** (70 - digits)


class _SingularPose:
    """The rank, pivots and independent rows of an evaluated matrix A decided minor by minor: each minor
    nonzero by certified numerics (escalated to 300 and 1000 digits), zero by :class:`PointLift` (0 for every
    value of the independent angles), or, for a minor that is neither, by its factors one by one (nonzero
    numerically, or decided exactly by :func:`~kinlib.exactfield.decide_zero` on that factor alone). A
    minor none of these decides makes the whole analysis give way (None) to elimination in K(t)."""

    def __init__(self, A: sp.Matrix):
        self.A = A
        self.lift = PointLift(list(A))
        self.special = _special(A.free_symbols)
        self._X: dict = {}
        self._rows = None
        self._ring = None
        self._memo: dict = {}

    def X(self, digits: int):
        mpmath = mp_context()

        if digits not in self._X:
            B = self.A.xreplace(self.special) if self.special else self.A
            memo: dict = {}
            with mpmath.workdps(digits):
                self._X[digits] = mpmath.matrix(
                    [[mp_value(B[i, j], memo, mpmath) for j in range(B.cols)] for i in range(B.rows)]
                )
        return self._X[digits]

    def _lifted_rows(self):
        """Each row of A lifted and multiplied by the product of its entries' denominators (nonzero at the
        configuration: they are the entries' own denominators there), as ring elements."""
        if self._rows is None:
            fr = [
                [sp.fraction(sp.together(e)) if _has_division(e) else (e, sp.S.One) for e in row]
                for row in self.A.tolist()
            ]
            exprs = [self.lift.lifted(x) for row in fr for pair in row for x in pair]
            ring = self.lift.ring(exprs)
            it = iter(exprs)
            rows = []
            for row in fr:
                nums, dens = [], []
                for _ in row:
                    nums.append(ring.normal_form(next(it)))
                    dens.append(ring.normal_form(next(it)))
                distinct = []
                for d in dens:
                    if d != ring.ring.one and d not in distinct:
                        distinct.append(d)
                out = []
                for n, d in zip(nums, dens):
                    x = n
                    for o in distinct:
                        if o != d:
                            x = x * o
                    out.append(x)
                rows.append(out)
            self._rows, self._ring = rows, ring
        return self._rows

    def _numeric(self, rows, cols, digits: int):
        """The minor at ``digits`` digits: (nonzero certified?, value)."""
        mpmath = mp_context()

        X = self.X(digits)
        with mpmath.workdps(digits):
            d = _mp_det([[X[i, j] for j in cols] for i in rows])
            return not _hadamard_small(d, X, rows, cols, digits), d

    def minor_zero(self, rows, cols) -> bool | None:
        """Whether det A[rows, cols] = 0 (True / False, proved), None when undecided."""
        key = (tuple(sorted(rows)), tuple(sorted(cols)))
        if key in self._memo:
            return self._memo[key]
        self._memo[key] = out = self._decide(list(rows), list(cols))
        return out

    def _decide(self, rows, cols):
        if self._numeric(rows, cols, _ESCALATE[0])[0]:
            return False
        try:
            L = self._lifted_rows()
        except (NotTrigPolynomial, NotExact):
            return None
        ring = self._ring
        D = DomainMatrix([[L[i][j] for j in cols] for i in rows], (len(rows), len(cols)), ring.ring.to_domain())
        p = ring.reduce(D.det())
        if not p:
            return True
        for digits in _ESCALATE[1:]:
            if self._numeric(rows, cols, digits)[0]:
                return False
        return self._by_factors(ring, p)

    def _by_factors(self, ring, p):
        """p ≠ 0 as a polynomial, numerically 0 here: zero exactly when one of its factors is."""
        factors = [(p, 1)]
        if ring.domain.is_QQ and len(p.terms()) <= _MAX_FACTOR_TERMS:
            try:
                factors = p.factor_list()[1]
            except Exception:  # pragma: no cover - then p is decided whole
                pass
        env = dict(zip(self.lift.angles, self.lift.values))
        for f, _m in factors:
            e = ring.to_expr(f).xreplace(env)
            try:
                if decide_zero(e, "a factor of a minor"):
                    return True
            except ValueError:
                return None
        return False

    def greedy(self, m: int, n: int, zero):
        """(pivot columns, their rows) of an m×n matrix whose minors' zero tests are ``zero(rows, cols)``:
        column j joins when some bordered minor [I + i, P + j] is nonzero (then A[I, P] stays nonsingular;
        otherwise every bordered minor is 0 and column j lies in the span of the pivots)."""
        P: list = []
        I: list = []
        for j in range(n):
            if len(P) == m:
                break
            free = [i for i in range(m) if i not in I]
            pick = None
            for i in free:  # numerics first: any certified nonzero bordered minor will do
                if zero(I + [i], P + [j], numeric=True) is False:
                    pick = i
                    break
            if pick is None:
                for i in free:
                    z = zero(I + [i], P + [j])
                    if z is None:
                        return None
                    if z is False:
                        pick = i
                        break
            if pick is not None:
                P.append(j)
                I.append(pick)
        return P, I

    def analyse(self):
        """(pivots, rows) of A as :class:`RankAnalysis` has them (rows: the first independent rows of
        A[:, pivots]), or None when a minor is undecided."""
        A = self.A

        def zero(rows, cols, numeric=False):
            if numeric:
                return False if self._numeric(rows, cols, _ESCALATE[0])[0] else None
            return self.minor_zero(rows, cols)

        got = self.greedy(A.rows, A.cols, zero)
        if got is None:
            return None
        P, _ = got
        rows = _independent_rows(A, P)
        if rows is None:  # the first independent rows of A[:, P], decided the same way (transposed)

            def zero_t(rows_t, cols_t, numeric=False):
                return zero(cols_t, [P[k] for k in rows_t], numeric)

            got_t = self.greedy(len(P), A.rows, zero_t)
            if got_t is None:
                return None
            rows = got_t[0]
        return P, rows


def _singular_pose(A: sp.Matrix):
    """(the :class:`_SingularPose` analysis, (pivots, rows)) of A, or None when it does not apply (no sines and
    cosines; an angle outside r + qπ; a minor it cannot decide): then elimination in K(t) decides."""
    if not A.has(sp.sin, sp.cos):
        return None
    try:
        pose = _SingularPose(A)
        got = pose.analyse()
    except (NotExact, NotTrigPolynomial):
        return None
    return None if got is None else (pose, got)
