"""The numeric fallback of kinlib.exact: rank and row-reduced bases computed with 60-digit numbers (mpmath), used
where an exact decision is out of reach (an angle such as √2, a time budget spent), and the warning that says so.

Stated precision: singular values at most 10^-40 σ_max count as zero (:data:`FALLBACK_ZERO_DIGITS`, not proven);
each entry of a returned basis carries the :data:`~kinlib.exactfield.FALLBACK_DIGITS` (60) digits it shows.

>>> import sympy as sp
>>> fallback_rank(sp.Matrix([[1, 2], [2, 4]]))[0]
1
"""

from __future__ import annotations

import warnings

import sympy as sp

from .field import FALLBACK_DIGITS, mp_context, mp_matrix

__all__ = ["FALLBACK_ZERO_DIGITS", "NumericFallbackWarning", "fallback_rank", "fallback_rref", "fallback_warning"]

#: the relative size (10^-40 σ_max) below which the numeric fallback counts a singular value as zero
FALLBACK_ZERO_DIGITS = 40


class NumericFallbackWarning(UserWarning):
    """A result was computed numerically (mpmath, 60 digits) because an exact decision was out of reach.

    >>> import warnings, sympy as sp
    >>> from kinlib.exact import column_space
    >>> from kinlib.robots import planar_2r
    >>> r = planar_2r(1, 2)
    >>> J = r.jacobian_geometric()[[3, 4], :]   # rows ṗ_x, ṗ_y
    >>> with warnings.catch_warnings(record=True) as caught:
    ...     warnings.simplefilter("always")
    ...     B = column_space(J, [sp.sqrt(2), 0], r.thetas)   # θ2 = 0: a rank drop; θ1 = √2: no exact field
    >>> [w.category.__name__ for w in caught], B.shape
    (['NumericFallbackWarning'], (2, 1))
    """


def fallback_rank(A: sp.Matrix) -> tuple:
    """(rank, singular values, descending) of A from a 60-digit SVD; rank counts those above 10^-40 σ_max.

    >>> r, sv = fallback_rank(sp.Matrix([[3, 0], [0, 0]]))
    >>> r, float(sv[0])
    (1, 3.0)
    """
    mpmath = mp_context()  # this thread's own context: never the global precision
    X = mp_matrix(A)
    with mpmath.workdps(FALLBACK_DIGITS):
        s = mpmath.svd_r(X, compute_uv=False)
        sv = sorted((abs(x) for x in s), reverse=True)
        top = sv[0] if sv else mpmath.mpf(0)
        tol = top * mpmath.mpf(10) ** (-FALLBACK_ZERO_DIGITS)
        r = sum(1 for x in sv if x > tol)
    return r, sv


def fallback_rref(A: sp.Matrix) -> sp.Matrix:
    """Nonzero rows of rref(A) as ``FALLBACK_DIGITS``-digit Floats: the rank from the 60-digit SVD, the elimination
    (partial pivoting) with 20 guard digits, so each entry carries the 60 digits it shows (entries of A to ~100).

    >>> R = fallback_rref(sp.Matrix([[2, 4], [1, 2]]))
    >>> R.shape, abs(R[0, 1] - 2) < 1e-59, R[0, 1]._prec >= 199   # one row, 60 decimal digits (199 bits)
    ((1, 2), True, True)
    """
    mpmath = mp_context()  # this thread's own context: never the global precision
    X = mp_matrix(A)
    r, sv = fallback_rank(A)
    with mpmath.workdps(FALLBACK_DIGITS + 20):
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
        rows = [
            [
                sp.Float(mpmath.nstr(X[i, j], FALLBACK_DIGITS), FALLBACK_DIGITS) if abs(X[i, j]) > tol else sp.S.Zero
                for j in range(n)
            ]
            for i in range(row)
        ]
    return sp.Matrix(rows) if rows else sp.zeros(0, n)


def fallback_warning(what: str, why: str):
    """Warn (:class:`NumericFallbackWarning`) that ``what`` was computed numerically, and ``why``.

    >>> import warnings
    >>> with warnings.catch_warnings(record=True) as caught:
    ...     warnings.simplefilter("always")
    ...     fallback_warning("rank_at", "an angle √2")
    >>> caught[0].category.__name__
    'NumericFallbackWarning'
    """
    warnings.warn(
        f"{what}: no exact decision here ({why}); computed with {FALLBACK_DIGITS}-digit numerics "
        f"(singular values below 1e-{FALLBACK_ZERO_DIGITS}·σ_max counted as zero, not proven)",
        NumericFallbackWarning,
        stacklevel=3,
    )
