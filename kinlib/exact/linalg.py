"""Exact linear algebra at a configuration: J(θ₀), rank J(θ₀), range J(θ₀) and null J(θ₀)ᵀ, proved.

SymPy's ``Matrix.rank()`` of the symbolic J gives the *generic* rank and hides the drop at a singular
configuration; and deciding "is this entry zero?" from a float (or by guessing a closed form from one) is
wrong at angles such as θ = 10 or θ = 1/2. Here every zero test is a proof.

**How** (:mod:`kinlib.exact_rank`). Every zero test is made in the field of :mod:`kinlib.exactfield` (the sines
and cosines of the configuration's angles written with t = tan(g/2), which is transcendental, so "zero" there is
a proof). But first a 60-digit SVD (entries to 100 digits) decides every *nonzero*: a singular value above
10⁻²⁰·σ_max is certified nonzero (entries and SVD are accurate to ~10⁻⁵⁵·σ_max, and |σ_i(A) − σ_i(Ã)| ≤
‖A − Ã‖). With symbolic parameters this is done at fixed rational values of them: a minor nonzero there is a
nonzero function of the parameters, so full rank there proves full rank. Only a decision "this is zero" (a rank
drop, a skipped pivot column, a zero entry) is left to exact arithmetic: first minor by minor, by the arm's
structure (:class:`kinlib.exactfield.PointLift`: the configuration's angles written as sums of independent angles,
so that a minor that is 0 for *every* value of them, such as one with the factor sin θ3 at θ3 = π, is proved 0
with no number field; a minor that is not is certified nonzero at 100, 300 or 1000 digits, or decided factor by
factor), which answers the textbook's singular poses at angles such as 2π/7 next to 3π/11 in about a second;
what that leaves undecided goes to fraction-free elimination over K[t, L1, L2, …].
Parameters count as indeterminates: the rank found is the rank for all their positive values except where a
stated expression vanishes (see :class:`Rank`).

The canonical basis entries (rref) are then written with the configuration's own sines and cosines, as ratios
of minors (Cramer's rule) of the evaluated J, each minor computed exactly in the polynomial ring of those sines
and cosines (:class:`kinlib.trigpoly.TrigRing`) and folded for display.

**Where an exact decision is out of reach** (an angle that is not a rational plus a rational multiple of π,
such as √2; a constant such as π or e entering polynomially alongside a transcendental angle; a rank drop at
angles so far apart in units of their common measure g that elimination would take minutes, i.e.
(largest multiple) × min(m, n) > ``EXACT_BUDGET`` = 100, e.g. 1/7 next to 3 on a 6×6 J), the rank is
computed from a singular value decomposition in mpmath with ``FALLBACK_DIGITS`` = 60 significant digits: a singular value above
``10^-FALLBACK_ZERO_DIGITS`` · σ_max (10^-40) is certified nonzero (each entry is accurate to 60 digits and
|σ_i(A) − σ_i(Ã)| ≤ ‖A − Ã‖), one below is reported as numerically zero, *not proven*. The result says so
(``Rank.exact`` is False and ``Rank.note`` states the precision; the bases come with a
:class:`NumericFallbackWarning`).
"""

from __future__ import annotations

import warnings
from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np
import sympy as sp
from sympy.polys.matrices import DomainMatrix

from .._backend import as_matrix, describe, exact_number, is_symbolic, joint_symbols, real_array
from .budget import ExactTimeoutError, OutOfTime, budget_seconds, run
from .display import readable
from .fallback import NumericFallbackWarning, fallback_rank, fallback_rref, fallback_warning
from .field import FALLBACK_DIGITS, MAX_MULTIPLE, NotExact, decide_zero, exact_is_zero
from .rank import RankAnalysis, canonical_rows, rank_conditions

__all__ = [
    "Rank",
    "NumericFallbackWarning",
    "ConditionalResultWarning",
    "evaluate_at",
    "rank_at",
    "column_space",
    "left_null_space",
    "left_null_space_exact",
    "exact_is_zero",
    "exact_det",
    "MAX_MULTIPLE",
    "FALLBACK_DIGITS",
    "TIME_BUDGET",
    "ExactTimeoutError",
]

#: the default ``time_budget`` (seconds) of the exact functions here; past it, the 60-digit fallback answers
#: (no parameters left) or :class:`~kinlib.budget.ExactTimeoutError` says what would work
TIME_BUDGET = 60.0


def exact_det(M: sp.Matrix) -> sp.Expr:
    """det M, exactly: fraction-free elimination over the polynomial domain of M's entries (DomainMatrix), or
    SymPy's Bareiss elimination when the entries hold constants outside that domain (√2, sin 3 …).

    >>> L, t = sp.symbols("L theta")
    >>> exact_det(sp.Matrix([[L, sp.sin(t)], [sp.cos(t), L]]))
    L**2 - sin(theta)*cos(theta)
    """
    try:
        dM = DomainMatrix.from_Matrix(M)
        if dM.domain.is_EX:  # algebraic constants such as √2: plain fraction-free elimination
            raise ValueError
        return dM.domain.to_sympy(dM.det())
    except Exception:
        return sp.expand(M.det(method="bareiss"))


class ConditionalResultWarning(UserWarning):
    """A result with symbolic parameters holds only where a stated expression in them is nonzero.

    >>> import warnings, sympy as sp
    >>> L1, L2 = sp.symbols("L1 L2", positive=True)
    >>> with warnings.catch_warnings(record=True) as caught:
    ...     warnings.simplefilter("always")
    ...     B = column_space(sp.Matrix([[L1, L2], [1, 1]]))   # det = L1 − L2
    >>> caught[0].category.__name__, B.shape
    ('ConditionalResultWarning', (2, 2))
    >>> print(caught[0].message)
    column_space holds for the parameters where L1 - L2 ≠ 0
    """


class Rank(int):
    """The rank of J at a configuration: an ``int`` that also says how it was decided.

    * ``exact``: True when proved by exact arithmetic; False for the 60-digit numeric fallback.
    * ``unless``: expressions in the positive parameters (link lengths); the rank is this value for every
      positive value of the parameters at which none of them vanishes. Where one vanishes the rank *may* be
      smaller: the factors come from one nonzero minor, a sufficient condition, not always a necessary one
      (for [[L1 − L2, 0], [0, 1], [L1 − 2 L2, 0]] the rank is 2 even at L1 = L2). Empty when the rank holds
      for all positive values.
    * ``note``: how it was decided, in words.

    >>> import sympy as sp
    >>> from kinlib.robots import planar_2r
    >>> r = planar_2r(1, 2)
    >>> J = r.jacobian_geometric()[[3, 4], :]   # rows ṗ_x, ṗ_y; det = L1 L2 sin θ2
    >>> R = rank_at(J, [1, 0], r.thetas)   # stretched out (θ2 = 0): proved
    >>> R, R.exact, R.unless, R.note
    (1, True, (), 'exact elimination in K(tan(g/2), parameters)')
    >>> R = rank_at(J, [sp.sqrt(2), 0], r.thetas)   # θ1 = √2 is outside the exact method
    >>> R, R.exact
    (1 (numeric, 60 digits), False)
    >>> L1, L2 = sp.symbols("L1 L2", positive=True)
    >>> R = rank_at(sp.Matrix([[L1, L2], [1, 1]]))
    >>> R, R.unless, R + 0   # an int: 2 for all positive L1, L2 with L1 ≠ L2
    (2 (assuming L1 - L2 ≠ 0), (L1 - L2,), 2)
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


# ----------------------------------------------------------------------------------------------
# input: J and the configuration
# ----------------------------------------------------------------------------------------------
def _jacobian(J: Any, name: str = "J") -> sp.Matrix:
    """J as an exact SymPy Matrix (numbers made exact, I/nan/oo refused: ``_backend.as_matrix``), not empty."""
    if not isinstance(J, (sp.MatrixBase, list, tuple, np.ndarray)):
        raise TypeError(f"{name} must be a matrix (m×n Jacobian), got {describe(J)}")
    M = as_matrix(J, name, None, True)
    if M.rows == 0 or M.cols == 0:
        raise ValueError(f"{name} must have at least one row and one column, got {describe(J)}")
    return M


def _table(subs: Any, thetas: Any) -> tuple:
    """({joint: exact value}, numeric?): numeric when any value is a float (Python, NumPy or SymPy Float)."""
    if isinstance(subs, Mapping):
        table = dict(subs)
    elif isinstance(subs, (str, bytes)) or not isinstance(subs, (Sequence, np.ndarray, sp.MatrixBase)):
        raise TypeError(
            f"subs must be a mapping {{joint symbol: value}} or a sequence of joint values, got {describe(subs)}"
        )
    else:
        vals = list(subs) if not isinstance(subs, np.ndarray) else subs.reshape(-1).tolist()
        if thetas is None:
            raise ValueError(
                f"subs is a sequence of joint values (got {describe(subs)}): give thetas= (the joint "
                "symbols, in order) too, or a mapping {joint symbol: value}"
            )
        thetas = joint_symbols(thetas)
        if len(vals) != len(thetas):
            raise ValueError(
                f"subs must hold {len(thetas)} joint values (one per joint "
                f"{', '.join(map(str, thetas))}), got {len(vals)}"
            )
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
    if not isinstance(J, (sp.MatrixBase, list, tuple, np.ndarray)):
        raise TypeError(f"J must be a matrix (m×n Jacobian), got {describe(J)}")
    if subs is not None and not is_symbolic(J):
        raise TypeError(
            f"subs only applies to a symbolic J (SymPy expressions in the joint symbols); got a "
            f"numeric J ({describe(J)}): call without subs"
        )
    M = _jacobian(J)
    numeric = False
    if subs is not None:
        table, numeric = _table(subs, thetas)
        M = M.xreplace(table)
    left = sorted((s for s in M.free_symbols if not s.is_positive), key=str)
    if left:
        raise ValueError(
            f"J must be taken at a configuration: it still depends on {', '.join(map(str, left))} (got "
            f"{describe(J)}{' and subs ' + sp.sstr(subs) if subs is not None else ', no subs'}); give a "
            "value for every joint in subs (only positive parameters such as link lengths may stay symbolic)"
        )
    for e in M:  # the values may have brought in I, oo, nan (checked cheaply: entries can be large trees)
        if e.has(sp.I, sp.nan, sp.zoo, sp.oo, -sp.oo):
            raise ValueError(f"J at the configuration must be real and finite, got the entry {e}")
    if numeric and M.free_symbols:
        raise ValueError(
            f"float joint values select the numeric backend, which needs numbers for the parameters "
            f"{', '.join(map(str, sorted(M.free_symbols, key=str)))} (substitute them, or give exact "
            "joint values such as sp.Rational(1, 2) or sp.pi/4)"
        )
    return M, numeric


def _as_float(M: sp.Matrix) -> np.ndarray:
    return np.array([[float(sp.N(M[i, j], 20)) for j in range(M.cols)] for i in range(M.rows)], dtype=float)


# ----------------------------------------------------------------------------------------------
# public functions
# ----------------------------------------------------------------------------------------------
def _numeric_J(J: Any, name: str = "J") -> np.ndarray:
    """A numeric Jacobian as a finite float array (m, n); bools, strings, complex numbers, NaN/inf refused."""
    A = real_array(J, name, "a matrix (m×n Jacobian)")
    if A.ndim != 2:
        raise ValueError(f"{name} must be a matrix (m×n Jacobian), got {describe(J)}")
    if 0 in A.shape:
        raise ValueError(f"{name} must have at least one row and one column, got {describe(J)}")
    return A


def _numeric_rank_tol(s: np.ndarray, shape) -> float:
    return max(shape) * np.finfo(float).eps * (s[0] if s.size else 0.0) * 100


def _is_numeric_input(J: Any, subs: Any) -> bool:
    return (
        subs is None
        and not is_symbolic(J)
        and not (
            isinstance(J, (list, tuple)) and any(isinstance(e, (sp.Basic,)) for e in np.asarray(J, dtype=object).flat)
        )
    )


def evaluate_at(J: Any, subs: Any = None, thetas: Sequence[sp.Symbol] | None = None, *, time_budget=TIME_BUDGET):
    """J(θ₀): the Jacobian at a configuration, exact, with every zero entry proved zero.

    ``subs``: a mapping {joint symbol: value} or a sequence of values matched to ``thetas``. Values are exact
    numbers (π/4, 1/2, 10, ``Fraction(1, 2)``) or expressions in positive parameters (θ3 = −L2); a float
    (Python, NumPy or SymPy) says the configuration is approximate and selects the numeric backend (a float array,
    and for :func:`rank_at` and the bases a float SVD). The result may still contain positive parameters, never a joint. Entries are written
    readably (sin² + cos² = 1 applied, angle sums folded); an entry is 0 exactly when it is 0 (decided exactly,
    see the module docstring). A numeric J (an array, no subs) comes back as a float array. The zero tests get
    ``time_budget`` seconds (None: no limit); past it :class:`~kinlib.budget.ExactTimeoutError` is raised.

    >>> import sympy as sp
    >>> t1, t2 = sp.symbols("theta1 theta2", real=True)
    >>> J = sp.Matrix([[-sp.sin(t1) - sp.sin(t1 + t2), -sp.sin(t1 + t2)], [sp.cos(t1) + sp.cos(t1 + t2), sp.cos(t1 + t2)]])
    >>> evaluate_at(J, {t1: 10, t2: 0})
    Matrix([
    [-2*sin(10), -sin(10)],
    [ 2*cos(10),  cos(10)]])
    """
    seconds = budget_seconds(time_budget)
    if _is_numeric_input(J, subs):
        return _numeric_J(J)
    M, numeric = _evaluated(J, subs, thetas)
    if numeric:
        return _as_float(M)
    try:
        zero = run(seconds, "evaluate_at", _zero_entries, M)
    except OutOfTime:
        raise ExactTimeoutError(
            f"evaluate_at: {_late(seconds)} (deciding which entries are zero); give a larger time_budget "
            "(None: no limit), or float joint values for a numeric J"
        ) from None
    return sp.Matrix(M.rows, M.cols, [sp.S.Zero if z else readable(e) for e, z in zip(M, zero)])


def _zero_entries(M: sp.Matrix) -> list:
    """Which entries of M are zero, decided exactly (in a budget's process: kinlib.budget.run)."""
    try:
        return [decide_zero(e) for e in M]
    except NotExact:
        return [e == 0 for e in M]


def _rank_exact(M: sp.Matrix):
    """(Rank, "") proved exactly, or (None, why not)."""
    an, why = _analyse(M, "rank_at")
    if an is None:
        return None, why
    unless = rank_conditions(M, an)
    return Rank(an.rank, unless=unless, note="exact elimination in K(tan(g/2), parameters)"), ""


def _column_space_exact(A: sp.Matrix):
    """(canonical basis of range Aᵀ as columns, "") proved exactly, or (None, why not)."""
    an, why = _analyse(A, "column_space")
    if an is None:
        return None, why
    unless = rank_conditions(A, an)
    out = canonical_rows(A, an).T
    _warn_conditions("column_space", unless)
    return out, ""


def left_null_space_exact(A: sp.Matrix, m: int):
    """The left null space of the ``m``-row matrix ``A`` (the rows of a Jacobian already evaluated at a pose), with
    no time budget of its own (the caller runs it inside one, :func:`kinlib.exact.budget.run`): (canonical basis of
    null Aᵀ as columns, "") proved exactly, or (None, why not). :func:`left_null_space` is the user's function.

    >>> left_null_space_exact(sp.Matrix([[1, 2], [2, 4]]), 2)  # rows 2 = 2 × row 1: y = (1, -1/2) has yᵀA = 0
    (Matrix([
    [   1],
    [-1/2]]), '')
    """
    an, why = _analyse(A, "left_null_space")
    if an is None:
        return None, why
    unless = rank_conditions(A, an)
    if an.rank == m:
        out = sp.zeros(m, 0)
    else:
        N = _null_from_rref(canonical_rows(A, an), m)
        out = canonical_rows(N, RankAnalysis(N)).T if N.rows else sp.zeros(m, 0)
    _warn_conditions("left_null_space", unless)
    return out, ""


def _analyse(M: sp.Matrix, what: str):
    """(RankAnalysis or None, reason): the exact analysis, or None with the reason it is out of reach."""
    try:
        return RankAnalysis(M), ""
    except NotExact as err:
        return None, str(err)


def _late(seconds) -> str:
    return f"the exact computation did not finish within time_budget={seconds} s"


def _numbers_only(M: sp.Matrix, what: str, why: str, seconds) -> sp.Matrix:
    """M for the 60-digit fallback: refused with a clear error when parameters are left (no numbers to use)."""
    if M.free_symbols and why.startswith("the exact computation did not finish"):
        params = ", ".join(map(str, sorted(M.free_symbols, key=str)))
        raise ExactTimeoutError(
            f"{what}: {why}, and the {FALLBACK_DIGITS}-digit fallback needs numbers for the parameters {params}: "
            "substitute them (J.subs({...})), or give a larger time_budget (None: no limit)"
        )
    return M


def rank_at(J: Any, subs: Any = None, thetas: Sequence[sp.Symbol] | None = None, *, time_budget=TIME_BUDGET) -> int:
    """rank J(θ₀) at a configuration, proved exactly (see the module docstring); a :class:`Rank` (an int).

    ``subs`` as in :func:`evaluate_at` (float values: a float SVD, and a plain int). With symbolic link lengths the rank holds for all their positive values,
    or ``Rank.unless`` names the minor whose vanishing would lower it. Out of reach of the exact method (e.g. an
    angle √2) or past ``time_budget`` seconds (default :data:`TIME_BUDGET`; None: no limit; see
    :mod:`kinlib.budget` for how it is enforced), a 60-digit SVD decides and ``Rank.exact`` is False; with
    parameters left there are no numbers for it, and :class:`~kinlib.budget.ExactTimeoutError` (a ValueError)
    says so. A numeric J (float array, no subs) or float joint values: the float SVD with tolerance
    100·max(m, n)·ε·σ_max, a plain int.

    >>> import sympy as sp
    >>> t1, t2 = sp.symbols("theta1 theta2", real=True)
    >>> J = sp.Matrix([[-sp.sin(t1) - sp.sin(t1 + t2), -sp.sin(t1 + t2)], [sp.cos(t1) + sp.cos(t1 + t2), sp.cos(t1 + t2)]])
    >>> rank_at(J, {t1: 10, t2: 0}), rank_at(J, {t1: sp.Rational(1, 2), t2: sp.Rational(1, 2)})
    (1, 2)
    """
    seconds = budget_seconds(time_budget)
    if _is_numeric_input(J, subs):
        A = _numeric_J(J)
        s = np.linalg.svd(A, compute_uv=False)
        return int(np.sum(s > _numeric_rank_tol(s, A.shape)))  # numbers in, a number out
    M, numeric = _evaluated(J, subs, thetas)
    if numeric:
        return rank_at(_as_float(M))
    got, why = _exact_or_why(seconds, "rank_at", _rank_exact, M)
    if got is not None:
        return got
    r, _ = fallback_rank(_numbers_only(M, "rank_at", why, seconds))
    fallback_warning("rank_at", why)
    return Rank(r, exact=False, note=f"{FALLBACK_DIGITS}-digit SVD ({why})")


def _exact_or_why(seconds, what: str, work, *args):
    """``work(*args)`` (which returns (answer or None, why not)) run within ``seconds`` of CPU in a killable child
    (:func:`kinlib.exact.budget.run`): its (answer, why), or (None, why) past the budget, for the caller's fallback."""
    try:
        return run(seconds, what, work, *args)
    except OutOfTime:
        return None, _late(seconds)


def _warn_conditions(what: str, unless: tuple):
    if unless:
        warnings.warn(
            f"{what} holds for the parameters where {', '.join(map(sp.sstr, unless))} ≠ 0",
            ConditionalResultWarning,
            stacklevel=3,
        )


def column_space(J: Any, subs: Any = None, thetas: Sequence[sp.Symbol] | None = None, *, time_budget=TIME_BUDGET):
    """A basis of range J(θ₀) (the twists/velocities the robot can produce there), as columns (m×r).

    Exact J: the canonical basis, the nonzero rows of rref(Jᵀ) (leading entries 1), so equal subspaces give
    equal matrices; proved exactly as in :func:`rank_at`, entries written with the configuration's sines and
    cosines. Out of reach of the exact method or past ``time_budget`` seconds (as in :func:`rank_at`): the same
    basis in 60-digit Floats, with a :class:`NumericFallbackWarning` (parameters left: ExactTimeoutError).
    Numeric J: an orthonormal basis from the SVD.

    >>> import sympy as sp
    >>> t1, t2 = sp.symbols("theta1 theta2", real=True)
    >>> J = sp.Matrix([[-sp.sin(t1) - sp.sin(t1 + t2), -sp.sin(t1 + t2)], [sp.cos(t1) + sp.cos(t1 + t2), sp.cos(t1 + t2)]])
    >>> column_space(J, {t1: 3, t2: 0}).T
    Matrix([[1, -cos(3)/sin(3)]])
    """
    seconds = budget_seconds(time_budget)
    if _is_numeric_input(J, subs):
        A = _numeric_J(J)
        U, s, _ = np.linalg.svd(A)
        return U[:, : int(np.sum(s > _numeric_rank_tol(s, A.shape)))]
    M, numeric = _evaluated(J, subs, thetas)
    if numeric:
        return column_space(_as_float(M))
    A = M.T
    out, why = _exact_or_why(seconds, "column_space", _column_space_exact, A)
    if out is not None:
        return out
    A = _numbers_only(A, "column_space", why, seconds)
    fallback_warning("column_space", why)
    return fallback_rref(A).T


def left_null_space(J: Any, subs: Any = None, thetas: Sequence[sp.Symbol] | None = None, *, time_budget=TIME_BUDGET):
    """A basis of null J(θ₀)ᵀ (the directions y the robot cannot move along: yᵀJ = 0), as columns (m×(m − r)).

    Exact J: the canonical (rref) basis, proved exactly as in :func:`rank_at`; empty (m×0) at full row rank.
    Out of reach of the exact method or past ``time_budget`` seconds: 60-digit Floats with a
    :class:`NumericFallbackWarning`, as :func:`column_space`. Numeric J: orthonormal, from the SVD.

    >>> import sympy as sp
    >>> t1, t2 = sp.symbols("theta1 theta2", real=True)
    >>> J = sp.Matrix([[-sp.sin(t1) - sp.sin(t1 + t2), -sp.sin(t1 + t2)], [sp.cos(t1) + sp.cos(t1 + t2), sp.cos(t1 + t2)]])
    >>> left_null_space(J, {t1: 3, t2: 0}).T
    Matrix([[1, sin(3)/cos(3)]])
    """
    seconds = budget_seconds(time_budget)
    if _is_numeric_input(J, subs):
        A = _numeric_J(J)
        U, s, _ = np.linalg.svd(A)
        return U[:, int(np.sum(s > _numeric_rank_tol(s, A.shape))) :]
    M, numeric = _evaluated(J, subs, thetas)
    if numeric:
        return left_null_space(_as_float(M))
    A = M.T  # null(Mᵀ) = null(A)
    m = A.cols
    out, why = _exact_or_why(seconds, "left_null_space", left_null_space_exact, A, m)
    if out is not None:
        return out
    A = _numbers_only(A, "left_null_space", why, seconds)
    fallback_warning("left_null_space", why)
    return _null_from_rref(fallback_rref(A), m, fallback=True)


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
