"""Velocity kinematics after the Jacobian: inverse velocity, damped least squares, statics, force ellipsoid.

Lynch & Park, *Modern Robotics*, sections 5.3–5.4 and 6.3. For a Jacobian J (m×n: m task rows, n joints)
with V = J θ̇ (twists [ω; v], angular first):

* inverse velocity kinematics  θ̇ = J⁺ V, the Moore–Penrose pseudoinverse: J⁺ = Jᵀ(J Jᵀ)⁻¹ when J has full
  row rank (n ≥ m: the smallest-norm θ̇ that achieves V exactly), J⁺ = (Jᵀ J)⁻¹Jᵀ when it has full column
  rank (n ≤ m: the least-squares θ̇), and in general J⁺ = Σ_{σ_i > tol} v_i u_iᵀ/σ_i from the SVD
  J = Σ σ_i u_i v_iᵀ (:func:`pseudoinverse`, :func:`inverse_velocity`);
* damped least squares  θ̇ = Jᵀ(J Jᵀ + λ²I)⁻¹ V = Σ σ_i/(σ_i² + λ²) v_i u_iᵀ V, bounded near singularities,
  → J⁺V as λ → 0 (:func:`damped_least_squares`);
* statics  τ = Jᵀ F (:func:`joint_torques`), with the wrench F = [m; f] (moment first, like [ω; v]) in the
  frame of the Jacobian: a space Jacobian J_s pairs with the space wrench F_s, a body Jacobian J_b with the
  body wrench F_b, the geometric Jacobian [ω_s; ṗ] with [moment about the tool point, in {s}; force in {s}];
  power balance τᵀθ̇ = Fᵀ V;
* the force ellipsoid {F : ‖Jᵀ F‖ ≤ 1} (:func:`force_ellipsoid`): semi-axes 1/σ_i along the same u_i as the
  velocity ellipsoid {J θ̇ : ‖θ̇‖ ≤ 1} (semi-axes σ_i, :func:`kinlib.manipulability.velocity_ellipsoid`),
  the duality of section 5.4: where the arm moves fast it resists force weakly, and vice versa.

One API, two backends: SymPy J → exact SymPy results (the pseudoinverse needs a constant J: substitute a
configuration first); numbers → NumPy floats, batches (N, m, n) allowed.
"""

from __future__ import annotations

import warnings
from typing import Any, NamedTuple

import numpy as np
import sympy as sp

from .._backend import (
    as_vector,
    check_real_finite,
    exact_jacobian,
    exact_number,
    is_symbolic,
    numeric_jacobian,
    numeric_vectors,
    within_float_range,
)
from ..exact.budget import ExactTimeoutError, OutOfTime, budget_seconds, run
from ..exact.display import readable, readable_ratio
from ..exact.field import decide_zero
from ..exact.linalg import TIME_BUDGET
from .manipulability import velocity_ellipsoid
from .taskspace import task_rows

__all__ = [
    "pseudoinverse",
    "inverse_velocity",
    "damped_least_squares",
    "joint_torques",
    "force_ellipsoid",
    "PinvReport",
    "SingularityWarning",
]

_EPS = np.finfo(float).eps
#: joint-rate amplification 1/σ_min (relative to 1/σ_max) above which a numeric pseudoinverse warns
_WARN_COND = 1e8


class SingularityWarning(UserWarning):
    """J is singular or nearly singular: a pseudoinverse dropped directions, or amplifies V enormously.

    >>> import warnings
    >>> import numpy as np
    >>> with warnings.catch_warnings(record=True) as caught:
    ...     warnings.simplefilter("always")
    ...     P = pseudoinverse(np.array([[1.0, 1.0], [1.0, 1.0]]))   # rank 1 < 2
    >>> [type(w.message).__name__ for w in caught]
    ['SingularityWarning']
    """


class PinvReport(NamedTuple):
    """What a pseudoinverse used: the rank kept, the singular values, the cut-off (numeric only).

    >>> import sympy as sp
    >>> pseudoinverse(sp.Matrix([[1, 0], [0, 2], [0, 0]]), full_output=True)[1]   # exact: the rank only
    PinvReport(rank=2, singular_values=None, tol=None)
    >>> import numpy as np
    >>> rep = pseudoinverse(np.diag([3.0, 1.0]), full_output=True)[1]
    >>> rep.rank, rep.singular_values.tolist(), bool(rep.tol < 1e-12)
    (2, [3.0, 1.0], True)
    """

    rank: Any
    singular_values: Any
    tol: Any


# ----------------------------------------------------------------------------------------------
# input checks
# ----------------------------------------------------------------------------------------------
def _apply(M: np.ndarray, x: np.ndarray, name: str) -> np.ndarray:
    """M x for M (…, p, q) and x (…, q), broadcasting the batch axes."""
    if M.ndim == 3 and x.ndim == 2 and M.shape[0] != x.shape[0]:
        raise ValueError(f"{name}: a batch of {x.shape[0]} vectors does not match a batch of {M.shape[0]} Jacobians")
    return np.einsum("...ij,...j->...i", M, x) + 0.0


def _exact_vector(x: Any, name: str, m: int, what: str) -> sp.Matrix:
    v = as_vector(x, name, m, True)
    for e in v:
        check_real_finite(exact_number(e, name), name)
    return v.applyfunc(lambda e: exact_number(e, name))


def _damping(lam: Any) -> sp.Expr:
    """λ as an exact number or expression, checked real, finite and ≥ 0."""
    e = exact_number(lam, "damping")
    if e.is_negative:
        raise ValueError(f"damping must be ≥ 0 (λ in Jᵀ(J Jᵀ + λ²I)⁻¹), got {lam!r}")
    if e.is_nonnegative is not True:
        raise ValueError(
            f"damping must be ≥ 0 (λ in Jᵀ(J Jᵀ + λ²I)⁻¹): could not show {e} ≥ 0; declare its "
            f"symbols positive (sp.Symbol('lam', positive=True)) or give a number"
        )
    return e


# ----------------------------------------------------------------------------------------------
# pseudoinverse
# ----------------------------------------------------------------------------------------------
def _svd_pinv(A: np.ndarray, rtol):
    """(J⁺ batch, rank, σ, tol) for A (N, m, n) via the SVD, cutting σ_i ≤ tol = rtol·σ_max."""
    m, n = A.shape[-2:]
    if rtol is None:
        rtol = max(m, n) * _EPS
    U, s, Vt = np.linalg.svd(A, full_matrices=False)
    tol = rtol * s[..., :1]
    keep = s > tol
    sinv = np.where(keep, 1.0 / np.where(keep, s, 1.0), 0.0)
    P = np.swapaxes(Vt, -1, -2) @ (sinv[..., :, None] * np.swapaxes(U, -1, -2))
    return P, keep.sum(axis=-1), s, tol[..., 0]


def _warn(rank, s, tol, k: int, stacklevel: int = 3):
    rank, s, tol = np.atleast_1d(rank), np.atleast_2d(s), np.atleast_1d(tol)
    deficient = rank < k
    smin_kept = np.where(rank > 0, s[np.arange(len(s)), np.maximum(rank - 1, 0)], 0.0)
    smax = s[:, 0]
    with np.errstate(divide="ignore", invalid="ignore"):
        amp = np.where(smin_kept > 0, smax / smin_kept, np.inf)
    near = ~deficient & (amp > _WARN_COND)
    where = lambda mask: (
        ""
        if len(rank) == 1
        else f" ({int(mask.sum())} of {len(rank)} Jacobians, first at index {int(np.flatnonzero(mask)[0])})"
    )
    if deficient.any():
        i = int(np.flatnonzero(deficient)[0])
        warnings.warn(
            f"J is singular{where(deficient)}: rank {int(rank[i])} < {k}, singular values "
            f"{np.array2string(s[i], precision=3)}; the {k - int(rank[i])} smallest (≤ tol = {tol[i]:.3g}) "
            f"were dropped, so J⁺V has no component along their directions (the minimum-norm "
            f"least-squares θ̇); pass rtol to change the cut-off",
            SingularityWarning,
            stacklevel=stacklevel,
        )
    if near.any():
        i = int(np.flatnonzero(near)[0])
        warnings.warn(
            f"J is nearly singular{where(near)}: σ_max/σ_min = {amp[i]:.3g} > {_WARN_COND:.0e}, so J⁺ "
            f"amplifies V by up to 1/σ_min = {1 / smin_kept[i]:.3g}; consider damped_least_squares",
            SingularityWarning,
            stacklevel=stacklevel,
        )


def _exact_pinv(M: sp.Matrix, name: str = "J"):
    """(J⁺, rank) for a constant exact J, every zero test a proof.

    Entries built from sin/cos of angles r + qπ (r, q rational) and algebraic numbers are computed in the field
    K(t), t = tan(g/2) (:class:`kinlib.exactfield.ExactField`: t is transcendental, so field arithmetic decides
    every pivot exactly) and written back with t = tan(g/2); other constants by SymPy elimination with
    :func:`kinlib.exactfield.decide_zero` pivot tests (slow beyond small matrices).
    """
    if M.free_symbols:
        syms = ", ".join(sorted(map(str, M.free_symbols)))
        raise ValueError(
            f"{name} must be constant for an exact pseudoinverse (its form changes where the rank drops), "
            f"got entries in {syms}: substitute a configuration first (J.subs({{...}})), or use "
            f"damped_least_squares with damping > 0, which is exact for every configuration"
        )
    m, n = M.shape
    try:
        from ..exact.field import ExactField, NotExact
    except ImportError:  # pragma: no cover - the exact field is part of kinlib
        ExactField, NotExact = None, ValueError
    if ExactField is not None:
        try:
            fld = ExactField(list(M))
            A = fld.field_matrix(M)
        except NotExact:
            A = None
        if A is not None:
            if fld.K == sp.QQ:  # rational coefficients: field Gauss–Jordan is fastest
                P, r = _pinv_formula(A, A.rank(), m, n, lambda X: X.inv())
            else:  # algebraic coefficients (√2 ...): fraction-free, far faster there
                P, r = _field_pinv(A, m, n)
            return _back(fld, P), r
    iz = lambda e: decide_zero(e, f"an entry in the elimination of {name}")
    if all(iz(e) for e in M):
        return sp.zeros(n, m), 0
    B, C = M.rank_decomposition(iszerofunc=iz)  # M = B C, B: m×r pivot columns, C: r×n (rref rows)
    P, r = _pinv_formula(M, B.cols, m, n, lambda X: X.inv(method="LU", iszerofunc=iz), (B, C))
    return P.applyfunc(readable), r


def _field_pinv(A, m: int, n: int):
    """J⁺ over the exact field K(t, …) (a DomainMatrix): fraction-free inverses in K[t, …] (inv_den), one
    cancellation per entry at the end (field Gauss–Jordan with a gcd at every step is far slower)."""
    R, piv = A.rref()
    r = len(piv)
    if r == 0:
        return A.transpose().mul(A.domain.zero), 0

    def frac(X):  # X = N / d, N over the polynomial ring
        d, N = X.clear_denoms(convert=True)
        return N, getattr(d, "element", d)

    def inv(X):
        N, d = frac(X)
        adj, det = N.inv_den()  # N⁻¹ = adj / det
        return adj.mul(d), det

    def mul(*fs):
        N, d = fs[0]
        for N2, d2 in fs[1:]:
            N, d = N * N2, d * d2
        return N, d

    At = A.transpose()
    if r == m == n:
        N, d = inv(A)
    elif r == m:
        N, d = mul(frac(At), inv(A * At))
    elif r == n:
        N, d = mul(inv(At * A), frac(At))
    else:  # J = B C: B the pivot columns, C the nonzero rref rows
        B, C = A.extract(list(range(m)), list(piv)), R.extract(list(range(r)), list(range(n)))
        Ct, Bt = C.transpose(), B.transpose()
        N, d = mul(frac(Ct), inv(C * Ct), inv(Bt * B), frac(Bt))
    K = A.domain
    dd = K.convert_from(d, N.domain)
    return N.convert_to(K).mul(K.one / dd), r


def _pinv_formula(A, r: int, m: int, n: int, inv, BC=None):
    """J⁺ from the rank r: J⁻¹, Jᵀ(J Jᵀ)⁻¹ (r = m), (Jᵀ J)⁻¹Jᵀ (r = n), else Cᵀ(C Cᵀ)⁻¹(Bᵀ B)⁻¹Bᵀ for J = B C."""
    T = lambda X: X.transpose() if hasattr(X, "transpose") else X.T
    if r == 0:
        return (A.transpose() if hasattr(A, "to_Matrix") else A.T) * 0, 0
    if r == m == n:
        return inv(A), r
    if r == m:
        return T(A) * inv(A * T(A)), r
    if r == n:
        return inv(T(A) * A) * T(A), r
    if BC is None:  # rank decomposition from the rref: B = pivot columns of A
        R, piv = A.rref()
        B, C = A.extract(list(range(m)), list(piv)), R.extract(list(range(r)), list(range(n)))
    else:
        B, C = BC
    return T(C) * inv(C * T(C)) * inv(T(B) * B) * T(B), r


def _timeout(what: str, seconds, advice: str):
    return ExactTimeoutError(
        f"{what}: the exact computation did not finish within time_budget={seconds} s; {advice}, or give a larger "
        "time_budget (None: no limit)"
    )


def _budgeted_pinv(M: sp.Matrix, seconds, what: str):
    try:
        return run(seconds, what, _exact_pinv, M)
    except OutOfTime:
        raise _timeout(what, seconds, "use float numbers for J (the SVD backend)") from None


def pseudoinverse(J: Any, rtol: Any = None, full_output: bool = False, *, time_budget=TIME_BUDGET):
    """The Moore–Penrose pseudoinverse J⁺ (n×m) of a Jacobian J (m×n).

    J⁺ = Jᵀ(J Jᵀ)⁻¹ for full row rank, (Jᵀ J)⁻¹Jᵀ for full column rank, and in general
    J⁺ = Σ_{σ_i > tol} v_i u_iᵀ / σ_i from the SVD J = Σ σ_i u_i v_iᵀ; J J⁺ J = J, J⁺ J J⁺ = J⁺.

    Numbers (m, n) or a batch (N, m, n): the SVD with the rank cut-off tol = rtol·σ_max, rtol = max(m, n)·ε
    by default (ε = 2.2e-16, NumPy's matrix_rank convention). A :class:`SingularityWarning` is issued when a
    singular value was dropped (rank < min(m, n)) or when the kept ones span more than 1e8 (J⁺ amplifies V
    by 1/σ_min); ``full_output=True`` returns (J⁺, PinvReport(rank, singular values, tol)) as well.
    SymPy J: exact, for a constant (evaluated) J only; the rank is decided with proved zero tests; the report
    holds the exact rank. Entries in sin/cos of rational angles (joint values 1, 1/2, ...) are computed in the
    exact field K(t), t = tan(g/2) (g the angles' common measure, :mod:`kinlib.exactfield`), and come back
    written with sin g and cos g (e.g. −2 sin 10/5); a UR5 at integer angles
    takes ≲ 10 s. (SymPy's own ``Matrix.pinv`` is not used: its zero tests can silently fail on such entries.)
    The exact path gets ``time_budget`` seconds (default 60; None: no limit; :mod:`kinlib.budget`); past it
    :class:`~kinlib.budget.ExactTimeoutError` (a ValueError) is raised.

    >>> import sympy as sp
    >>> pseudoinverse(sp.Matrix([[1, 0], [0, 2], [0, 0]]))
    Matrix([
    [1,   0, 0],
    [0, 1/2, 0]])
    >>> import numpy as np
    >>> import warnings
    >>> with warnings.catch_warnings(record=True) as caught:
    ...     warnings.simplefilter("always")
    ...     P, rep = pseudoinverse(np.array([[1.0, 1.0], [1.0, 1.0]]), full_output=True)
    >>> caught[0].category.__name__                     # rank 1 < 2: the smallest singular value was dropped
    'SingularityWarning'
    >>> P, rep.rank
    (array([[0.25, 0.25],
           [0.25, 0.25]]), 1)
    """
    seconds = budget_seconds(time_budget)
    if is_symbolic(J):
        if rtol is not None:
            raise ValueError(f"rtol applies to numeric J only (the exact rank needs no tolerance), got rtol={rtol!r}")
        P, r = _budgeted_pinv(exact_jacobian(J), seconds, "pseudoinverse")
        return (P, PinvReport(r, None, None)) if full_output else P
    A = numeric_jacobian(J)
    rtol = _rtol(rtol)
    batch = A.ndim == 3
    P, rank, s, tol = _svd_pinv(A if batch else A[None], rtol)
    _warn(rank, s, tol, min(A.shape[-2:]))
    if not batch:
        P, rank, s, tol = P[0], int(rank[0]), s[0], float(tol[0])
    return (P + 0.0, PinvReport(rank, s, tol)) if full_output else P + 0.0


def _rtol(rtol: Any):
    if rtol is None:
        return None
    r = float(exact_number(rtol, "rtol"))
    if not 0 <= r < 1:
        raise ValueError(f"rtol must be a relative cut-off in [0, 1), got {rtol!r}")
    return r


def inverse_velocity(J: Any, V: Any, rtol: Any = None, full_output: bool = False, *, time_budget=TIME_BUDGET):
    """Inverse velocity kinematics θ̇ = J⁺ V: the joint rates of least norm that best achieve the twist V.

    J⁺ as in :func:`pseudoinverse` (Jᵀ(J Jᵀ)⁻¹ for full row rank: J θ̇ = V exactly; (Jᵀ J)⁻¹Jᵀ for full column
    rank: the least-squares θ̇). Numbers: the SVD with tol = rtol·σ_max (default rtol = max(m, n)·ε), a
    :class:`SingularityWarning` at or near a singularity, ``full_output=True`` → (θ̇, PinvReport). Batches: J
    (N, m, n) and/or V (N, m). SymPy: exact, J constant (V may hold symbols), within ``time_budget`` seconds
    as :func:`pseudoinverse`.

    >>> import sympy as sp
    >>> inverse_velocity(sp.Matrix([[0, 1], [1, 1]]), [1, 2]).T      # planar 2R at θ = (0, π/2), L = 1: ṗ = (1, 2)
    Matrix([[1, 1]])
    """
    seconds = budget_seconds(time_budget)  # checked for numbers too (a garbage budget is never ignored)
    if is_symbolic(J, V):
        if rtol is not None:
            raise ValueError(f"rtol applies to numeric J only (the exact rank needs no tolerance), got rtol={rtol!r}")
        M = exact_jacobian(J)
        v = _exact_vector(V, "V", M.rows, "a twist (the rows of J)")
        P, r = _budgeted_pinv(M, seconds, "inverse_velocity")
        out = (P * v).applyfunc(sp.radsimp)
        return (out, PinvReport(r, None, None)) if full_output else out
    A = numeric_jacobian(J)
    v = numeric_vectors(V, "V", A.shape[-2], "a twist (the rows of J)")
    batch = A.ndim == 3
    P, rank, s, tol = _svd_pinv(A if batch else A[None], _rtol(rtol))
    _warn(rank, s, tol, min(A.shape[-2:]))
    out = _apply(P if batch else P[0], v, "V")
    if not batch:
        rank, s, tol = int(rank[0]), s[0], float(tol[0])
    return (out, PinvReport(rank, s, tol)) if full_output else out


# ----------------------------------------------------------------------------------------------
# damped least squares
# ----------------------------------------------------------------------------------------------
def damped_least_squares(J: Any, V: Any, damping: Any, *, time_budget=TIME_BUDGET):
    """Damped least squares θ̇ = Jᵀ(J Jᵀ + λ²I)⁻¹ V = (Jᵀ J + λ²I)⁻¹ Jᵀ V = Σ σ_i/(σ_i² + λ²) v_i u_iᵀ V.

    The θ̇ minimising ‖J θ̇ − V‖² + λ²‖θ̇‖²: bounded by ‖V‖/(2λ) at every configuration (no blow-up at a
    singularity), → J⁺V as λ → 0. ``damping`` λ ≥ 0 (real, finite; chosen by the caller, e.g. 0.01–0.1 of
    the typical σ). λ = 0 is exactly :func:`inverse_velocity` (same rank cut-off and warnings).

    Numbers: the SVD form (stable), J (m, n) or (N, m, n), V (m,) or (N, m). SymPy: exact; with λ > 0 the
    matrix J Jᵀ + λ²I is positive definite, so the result holds for every configuration and J may keep its
    symbols (small arms: the closed form grows fast); λ = 0 needs a constant J. The exact path gets
    ``time_budget`` seconds (default 60; None: no limit; :mod:`kinlib.budget`); past it
    :class:`~kinlib.budget.ExactTimeoutError` (a ValueError) says what would work.

    >>> import sympy as sp
    >>> damped_least_squares(sp.Matrix([[1, 0], [0, 0]]), [1, 1], 1).T    # singular J: the 2nd direction is dropped
    Matrix([[1/2, 0]])
    """
    seconds = budget_seconds(time_budget)
    if is_symbolic(J, V, damping):
        lam = _damping(damping)
        M = exact_jacobian(J)
        v = _exact_vector(V, "V", M.rows, "a twist (the rows of J)")
        if lam == 0:
            return inverse_velocity(M, v, time_budget=time_budget)
        try:
            return run(seconds, "damped_least_squares", _exact_dls, M, lam, v)
        except OutOfTime:
            raise _timeout(
                "damped_least_squares",
                seconds,
                "the closed form in the joint symbols grows fast: give J at a configuration (exact values) or floats",
            ) from None
    lam = within_float_range(_damping(damping), "damping")
    A = numeric_jacobian(J)
    v = numeric_vectors(V, "V", A.shape[-2], "a twist (the rows of J)")
    if lam == 0:
        return inverse_velocity(A, v)
    U, s, Vt = np.linalg.svd(A, full_matrices=False)
    g = s / (s * s + lam * lam)
    P = np.swapaxes(Vt, -1, -2) @ (g[..., :, None] * np.swapaxes(U, -1, -2))
    return _apply(P, v, "V")


def _exact_dls(M: sp.Matrix, lam: sp.Expr, v: sp.Matrix):
    m, n = M.shape
    const = not (M.free_symbols or lam.free_symbols)
    fast = _field_dls(M, lam, v) if const else None
    if fast is not None:
        return fast if not v.free_symbols else (fast * v).applyfunc(sp.radsimp)
    if not const:  # in the joint symbols: G = J Jᵀ + λ²I is positive definite, G⁻¹ = adj G / det G, each
        # simplified modulo sin² + cos² = 1 (LUsolve + cancel on the raw entries took > 900 s for the 2R arm)
        from .singularities import trig_simplify

        G = trig_simplify(M * M.T if m <= n else M.T * M) + lam**2 * sp.eye(min(m, n))
        det = trig_simplify(G.det(method="berkowitz"))
        num = M.T * (G.adjugate(method="berkowitz") * v) if m <= n else G.adjugate(method="berkowitz") * (M.T * v)
        return num.applyfunc(lambda e: trig_simplify(e) / det)
    kw = {"iszerofunc": lambda e: decide_zero(e, "a pivot")}
    if m <= n:
        out = M.T * (M * M.T + lam**2 * sp.eye(m)).LUsolve(v, **kw)
    else:
        out = (M.T * M + lam**2 * sp.eye(n)).LUsolve(M.T * v, **kw)
    return out.applyfunc(lambda e: sp.radsimp(sp.simplify(e)) if const and not e.has(sp.sin, sp.cos) else sp.cancel(e))


def _field_dls(M: sp.Matrix, lam: sp.Expr, v: sp.Matrix):
    """For a constant J and λ > 0, in the exact field K(tan(g/2)): θ̇ = Jᵀ(J Jᵀ + λ²I)⁻¹V when V is constant too
    (one linear solve), else the matrix Jᵀ(J Jᵀ + λ²I)⁻¹; None when the field does not apply."""
    const_v = not v.free_symbols
    try:
        from ..exact.field import ExactField

        fld = ExactField(list(M) + [lam] + (list(v) if const_v else []))
        A = fld.field_matrix(M)
        l2 = fld.convert(lam**2)
        b = fld.field_matrix(v) if const_v else None
    except (ImportError, ValueError):
        return None
    m, n = M.shape
    K = A.domain
    At = A.transpose()
    G = A * At + A.eye(m, K).mul(l2) if m <= n else At * A + A.eye(n, K).mul(l2)
    if const_v:
        x = At * G.lu_solve(b) if m <= n else G.lu_solve(At * b)
        return _back(fld, x)
    d, N = G.clear_denoms(convert=True)  # fraction-free: G⁻¹ = d · adj(N)/det(N)
    adj, det = N.inv_den()
    Gi = adj.convert_to(K).mul(K.convert_from(getattr(d, "element", d), N.domain) / K.convert_from(det, N.domain))
    X = At * Gi if m <= n else Gi * At
    return _back(fld, X)


#: an entry of an exact result is folded for reading (:func:`~kinlib.display.readable_ratio`: trig identities,
#: common factors) only while its numerator and denominator in t = tan(g/2) have at most this many terms together;
#: larger ones come back as one fraction of polynomials in sin g, cos g, exactly equal, unfolded (folding a UR5's
#: J⁺ at integer angles was 93 % of its 21.7 s; issue 32)
READABLE_TERMS = 24


def _back(fld, X) -> sp.Matrix:
    """A matrix over the exact field written back in the configuration's sines and cosines (small entries folded
    readably, large ones as a fraction of polynomials: :data:`READABLE_TERMS`)."""
    rows, cols = X.shape
    L = X.to_list()

    def entry(x):
        if not x:
            return sp.S.Zero
        x = fld.F(x)
        num, den = fld.to_ratio(x)
        if _terms(x) <= READABLE_TERMS:  # (no sines: algebraic numbers, radsimp'd without a trig ring's field
            # isomorphisms, 16 s → under a second for the planar 2R at (π/8, π/3))
            return (
                readable_ratio(num, den) if num.has(sp.sin, sp.cos) or den.has(sp.sin, sp.cos) else readable(num / den)
            )
        return num if den == 1 else num / den

    return sp.Matrix(rows, cols, [entry(L[i][j]) for i in range(rows) for j in range(cols)])


def _terms(x) -> int:
    """Terms of a field element's numerator and denominator (polynomials in t and the parameters)."""
    return sum(len(p.terms()) if hasattr(p, "terms") else 1 for p in (x.numer, x.denom))


# ----------------------------------------------------------------------------------------------
# statics and the force ellipsoid
# ----------------------------------------------------------------------------------------------
def joint_torques(J: Any, F: Any):
    """Statics τ = Jᵀ F: the joint torques/forces that hold the wrench F at the end-effector (gravity aside).

    F = [m; f] (moment first, matching twists [ω; v]) expressed like J: the space Jacobian J_s with the
    space wrench F_s, the body Jacobian J_b with the body wrench F_b, the geometric Jacobian [ω_s; ṗ] with
    [moment about the tool point, in {s}; force, in {s}]; task rows of J pair with the same rows of F.
    Power balance: τᵀθ̇ = Fᵀ(J θ̇) = Fᵀ V. Numbers: J (m, n) or (N, m, n), F (m,) or (N, m). SymPy: exact.

    >>> import sympy as sp
    >>> t1, t2 = sp.symbols("theta1 theta2", real=True)
    >>> s1, c1, s12, c12 = sp.sin(t1), sp.cos(t1), sp.sin(t1 + t2), sp.cos(t1 + t2)
    >>> J = sp.Matrix([[-s1 - s12, -s12], [c1 + c12, c12]])   # planar 2R, unit links: rows ṗx, ṗy
    >>> joint_torques(J, [0, 1]).T                             # hold the force f_y = 1 at the tip
    Matrix([[cos(theta1) + cos(theta1 + theta2), cos(theta1 + theta2)]])
    """
    if is_symbolic(J, F):
        M = exact_jacobian(J)
        f = _exact_vector(F, "F", M.rows, "a wrench (the rows of J)")
        return M.T * f
    A = numeric_jacobian(J)
    f = numeric_vectors(F, "F", A.shape[-2], "a wrench (the rows of J)")
    return _apply(np.swapaxes(A, -1, -2), f, "F")


def force_ellipsoid(J: Any, rows: Any = None, *, time_budget=TIME_BUDGET):
    """The force ellipsoid {F : ‖Jᵀ F‖ ≤ 1}: (semi-axis lengths 1/σ_i, unit directions u_i as columns).

    Dual to the velocity ellipsoid {J θ̇ : ‖θ̇‖ ≤ 1} (:func:`kinlib.manipulability.velocity_ellipsoid`, lengths
    σ_i, directions u_i): the same principal directions, reciprocal lengths (Jᵀ u_i = σ_i v_i, so
    ‖Jᵀ(u_i/σ_i)‖ = 1). Same conventions as velocity_ellipsoid: ``rows`` picks task rows (default: a 6-row J
    uses "linear", i.e. forces f for the geometric Jacobian), k = min(m, n) axes, columns in the order of
    the σ_i (descending), so lengths ascend. At a singularity σ_i = 0: the length is ``inf`` (numbers; σ_i ≤
    max(m, n)·ε·σ_max counts as 0) or ``sp.oo`` (exact): the structure resists that force with no torque.
    When m > n the ellipsoid is also unbounded along the m − n directions of the left null space of J (not
    among the k returned, as the velocity ellipsoid's flat directions are not).
    Numbers: lengths (k,) and directions (m, k); a batch (N, m, n) gives (N, k), (N, m, k). SymPy: exact, with
    velocity_ellipsoid's ``time_budget`` and fallback (60-digit Floats with a NumericFallbackWarning for a
    constant J; a ValueError for a J with free symbols).

    >>> import sympy as sp
    >>> force_ellipsoid(sp.Matrix([[2, 0], [0, 0]]))
    ([1/2, oo], Matrix([
    [1, 0],
    [0, 1]]))
    """
    budget_seconds(time_budget)  # checked for numbers too (a garbage budget is never ignored)
    if is_symbolic(J):
        lengths, U = velocity_ellipsoid(J, rows, time_budget=time_budget)
        out = []
        for s in lengths:
            try:
                zero = decide_zero(s, "a singular value")
            except ValueError:
                if not s.free_symbols:
                    raise
                zero = False  # not identically zero: 1/s is exact wherever s ≠ 0
            plain = s.has(sp.CRootOf) or s.is_Float or sp.count_ops(s) > 60  # (radsimp of a long root: minutes)
            out.append(sp.oo if zero else (1 / s if plain else sp.radsimp(1 / s)))
        return out, U
    A = numeric_jacobian(J)
    if rows is None and A.shape[-2] == 6:
        rows = "linear"
    if rows is not None:
        A = task_rows(A, rows)
    U, s, _ = np.linalg.svd(A, full_matrices=False)
    m, n = A.shape[-2:]
    tol = max(m, n) * _EPS * s[..., :1]
    with np.errstate(divide="ignore"):
        lengths = np.where(s > tol, 1.0 / np.where(s > tol, s, 1.0), np.inf)
    return lengths, U
