"""Manipulability: how well the robot can move in every task direction at a configuration.

For J (m×n, the rows of the task space: pick them with :func:`kinlib.singularities.task_rows`):

* Yoshikawa's manipulability  w = √det(J Jᵀ)  (n ≥ m), or √det(Jᵀ J) when the robot has fewer joints
  than task dimensions (n < m); = σ1 σ2 ⋯ σk, the product of the singular values; 0 exactly at a singularity.
* condition number  κ = σ_max / σ_min ≥ 1 (∞ at a singularity);  isotropy = 1/κ ∈ [0, 1], 1 when the
  velocity ellipsoid is a sphere (a circle in the plane).
* velocity ellipsoid {J θ̇ : ‖θ̇‖ ≤ 1}: semi-axes σ_i along the left singular vectors u_i.
* problem 6.2's speed view: V·V = θ̇ᵀ (Jᵀ J) θ̇.

SymPy input gives exact SymPy results (``simplify=True`` for a display form); numbers give floats, and a
batch of Jacobians (N, m, n) gives (N,) results.
"""
from __future__ import annotations

from typing import Any

import numpy as np
import sympy as sp

from ._backend import as_matrix, as_vector, describe, is_symbolic
from .singularities import _det, _is_zero, task_rows, trig_simplify
from .trigpoly import TrigRing, angles_in

__all__ = ["manipulability", "condition_number", "isotropy", "velocity_ellipsoid", "twist_speed_form",
           "twist_speed", "singular_values", "strongest_joints"]


def _numeric(J: Any, name: str = "J") -> np.ndarray:
    """A float array of shape (m, n) or (N, m, n)."""
    if isinstance(J, (str, bytes)) or J is None or np.isscalar(J):
        raise TypeError(f"{name} must be a matrix (m, n) or a batch (N, m, n), got {describe(J)}")
    try:
        A = np.asarray(J, dtype=float)
    except (TypeError, ValueError):
        raise TypeError(f"{name} must hold real numbers, got {describe(J)}") from None
    if A.ndim not in (2, 3) or 0 in A.shape:
        raise ValueError(f"{name} must be a matrix (m, n) or a batch (N, m, n), got {describe(J)}")
    if not np.all(np.isfinite(A)):
        raise ValueError(f"{name} must hold finite numbers (no nan/inf)")
    return A


def _symbolic(J: Any, name: str = "J") -> sp.Matrix:
    M = as_matrix(J, name, None, True)
    if M.rows == 0 or M.cols == 0:
        raise ValueError(f"{name} must have at least one row and one column, got {describe(M)}")
    return M


def _gram(J: sp.Matrix) -> sp.Matrix:
    """J Jᵀ when n ≥ m (more joints than rows), else Jᵀ J: the smaller square Gram matrix."""
    return J * J.T if J.cols >= J.rows else J.T * J


def singular_values(J: Any) -> np.ndarray:
    """σ1 ≥ σ2 ≥ ⋯ ≥ σk (k = min(m, n)) of a numeric J; shape (k,) or (N, k) for a batch."""
    return np.linalg.svd(_numeric(J), compute_uv=False)


def _display_sqrt(G_det: sp.Expr) -> sp.Expr:
    """√D for display: positive factors with even powers come out, the rest is trig-simplified under √."""
    ring = TrigRing([G_det], angles_in([G_det]), opaque=True)
    D = sp.factor(ring.to_expr(ring.normal_form(G_det), trig=False))   # factored as a polynomial in s_i, c_i
    coeff, factors = sp.factor_list(D)
    outside, inside = sp.sqrt(coeff) if coeff >= 0 else sp.S.One, sp.S.One if coeff >= 0 else coeff
    for f, m in factors:
        ft = ring.to_trig(f)
        if m % 2 == 0:
            outside *= (ft if ft.is_nonnegative else sp.Abs(sp.trigsimp(ft))) ** (m // 2)
        else:
            if ft.is_nonnegative:
                outside *= ft ** (m // 2)
                inside *= ft
            else:
                inside *= ft ** m
    inside = sp.trigsimp(inside) if inside.has(sp.sin, sp.cos) else inside
    return outside * sp.sqrt(inside)


def manipulability(J: Any, simplify: bool = False):
    """Yoshikawa's w = √det(J Jᵀ) (n ≥ m) or √det(Jᵀ J) (n < m): 0 exactly where J loses rank.

    SymPy J: the exact expression (``simplify=True`` gives a display form, e.g. L²√(sin 2θ2 + 1), with
    the square roots of squares of positive parameters taken out). Numeric J (m, n) or a batch (N, m, n):
    the product of the singular values, float or (N,) array.
    """
    if not is_symbolic(J):
        A = _numeric(J)
        return np.prod(np.linalg.svd(A, compute_uv=False), axis=-1)
    M = _symbolic(J)
    D = _det(_gram(M))
    if not simplify:
        return sp.sqrt(D)
    return _display_sqrt(D)


def _gram_eigenvalues(M: sp.Matrix) -> list:
    G = _gram(M)
    if G.free_symbols and angles_in(list(G)):
        G = trig_simplify(G)
    else:
        G = G.applyfunc(sp.simplify)
    ev = G.eigenvals(multiple=True, simplify=True)
    return [sp.simplify(e) for e in ev]


def condition_number(J: Any):
    """κ = σ_max / σ_min (≥ 1; ∞ at a singular configuration), over the k = min(m, n) singular values.

    Numeric J (or a batch): floats. SymPy J: √(λ_max/λ_min) of the Gram matrix, exact (with Max/Min left
    unevaluated where the eigenvalues cannot be ordered).
    """
    if not is_symbolic(J):
        s = np.linalg.svd(_numeric(J), compute_uv=False)
        smax, smin = s[..., 0], s[..., -1]
        with np.errstate(divide="ignore", invalid="ignore"):
            out = np.where(smin > 1e-12 * np.maximum(smax, 1e-300), smax / np.where(smin > 0, smin, 1), np.inf)
        return float(out) if np.ndim(out) == 0 else out
    ev = _gram_eigenvalues(_symbolic(J))
    if any(_is_zero(e) for e in ev):
        return sp.oo
    if len(set(ev)) == 1:
        return sp.S.One
    return sp.sqrt(sp.Max(*ev) / sp.Min(*ev))


def isotropy(J: Any):
    """1/κ = σ_min / σ_max ∈ [0, 1]: 1 when the velocity ellipsoid is a sphere (circle), 0 at a singularity."""
    if not is_symbolic(J):
        s = np.linalg.svd(_numeric(J), compute_uv=False)
        smax, smin = s[..., 0], s[..., -1]
        with np.errstate(divide="ignore", invalid="ignore"):
            ratio = smin / np.where(smax > 0, smax, 1)
            out = np.where((smax > 0) & (ratio > 1e-12), ratio, 0.0)
        return float(out) if np.ndim(out) == 0 else out
    ev = _gram_eigenvalues(_symbolic(J))
    if any(_is_zero(e) for e in ev):
        return sp.S.Zero
    if len(set(ev)) == 1:
        return sp.S.One
    return sp.sqrt(sp.Min(*ev) / sp.Max(*ev))


def velocity_ellipsoid(J: Any, rows: Any = None):
    """The velocity ellipsoid {J θ̇ : ‖θ̇‖ ≤ 1}: (semi-axis lengths σ_i, unit directions u_i as columns).

    ``rows``: pick task rows first (see :func:`~kinlib.singularities.task_rows`); by default a 6-row J
    uses its linear rows ("linear" = vx vy vz, the tool velocity ṗ for the geometric Jacobian), any other J
    all of its rows. Numeric J: lengths (k,) sorted descending and directions (m, k), k = min(m, n) (a
    batch gives (N, k), (N, m, k)). SymPy J: exact eigen-decomposition of J Jᵀ (lengths √λ, orthonormal
    directions), for small or evaluated J.
    """
    if rows is None:
        shape = J.shape if hasattr(J, "shape") else np.shape(np.asarray(J, dtype=object))
        rows = "linear" if len(shape) >= 2 and shape[-2] == 6 else None
    if rows is not None:
        J = task_rows(J, rows)
    if not is_symbolic(J):
        A = _numeric(J)
        U, s, _ = np.linalg.svd(A, full_matrices=False)
        return s, U
    M = _symbolic(J)
    G = M * M.T
    G = trig_simplify(G) if angles_in(list(G)) else G.applyfunc(sp.simplify)
    pairs = []
    for lam, mult, vecs in G.eigenvects(simplify=True):
        lam = sp.simplify(lam)
        ortho = sp.GramSchmidt(vecs, orthonormal=True)
        for v in ortho:
            pairs.append((lam, v.applyfunc(lambda e: sp.radsimp(sp.simplify(e)))))

    def key(p):
        try:
            return -float(p[0].subs({s: 1 for s in p[0].free_symbols}))
        except TypeError:
            return 0.0
    pairs.sort(key=key)
    k = min(M.rows, M.cols)
    pairs = pairs[:k] if M.cols < M.rows else pairs
    lengths = [sp.sqrt(lam) for lam, _ in pairs]
    return lengths, sp.Matrix.hstack(*[v for _, v in pairs])


def twist_speed_form(J: Any, simplify: bool = False):
    """Jᵀ J, the matrix of problem 6.2's quadratic form V·V = θ̇ᵀ (Jᵀ J) θ̇ (n×n).

    Exact for SymPy J (``simplify=True``: trig-simplified for display); floats, or (N, n, n), for numbers.
    """
    if not is_symbolic(J):
        A = _numeric(J)
        return np.swapaxes(A, -1, -2) @ A
    M = _symbolic(J)
    G = M.T * M
    return trig_simplify(G) if simplify else G


def twist_speed(J: Any, qdot: Any, simplify: bool = False):
    """V·V = θ̇ᵀ (Jᵀ J) θ̇ = ‖J θ̇‖², the squared size of the twist V = J θ̇ (problem 6.2)."""
    if not is_symbolic(J, qdot):
        A = _numeric(J)
        q = np.asarray(qdot, dtype=float) if not isinstance(qdot, (str, bytes)) else None
        if q is None or q.shape[-1:] != (A.shape[-1],):
            raise ValueError(f"qdot must hold {A.shape[-1]} joint rates, got {describe(qdot)}")
        V = np.einsum("...ij,...j->...i", A, q)
        return np.sum(V * V, axis=-1)
    M = _symbolic(J)
    q = as_vector(qdot, "qdot", M.cols, True)
    e = (q.T * (M.T * M) * q)[0, 0]
    return trig_simplify(sp.expand(e)) if simplify else e


def strongest_joints(row: Any, tol: float = 1e-9):
    """The joint(s) (1-based) whose column contributes the most to one task row: argmax_i |J[row, i]|.

    ``row``: the n entries of that row at a configuration (problem 4.1: the ṗ_x row). One joint gives an
    int; a tie gives a tuple of ints, e.g. (1, 2). SymPy entries are compared exactly (|a| − |b|
    simplified to 0); numbers within ``tol`` (relative) tie.
    """
    if isinstance(row, sp.MatrixBase):
        vals = list(row)
    elif isinstance(row, (str, bytes)) or not hasattr(row, "__len__"):
        raise TypeError(f"row must be the n entries of one row of J, got {describe(row)}")
    else:
        vals = list(np.asarray(row, dtype=object).reshape(-1))
    if not vals:
        raise ValueError("row must hold at least one entry")
    if is_symbolic(vals):
        vals = [sp.sympify(v) for v in vals]
        if any(not v.is_number or not v.is_real for v in vals):
            raise ValueError(f"row must hold real numbers (evaluate J at a configuration first), got {vals}")
        mags = [sp.Abs(v) for v in vals]
        top = max(mags, key=lambda m: float(m))
        best = [i + 1 for i, m in enumerate(mags) if _is_zero(m - top)]
    else:
        a = np.abs(as_vector(vals, "row", None, False))
        top = float(a.max())
        best = [i + 1 for i, m in enumerate(a) if abs(m - top) <= tol * max(top, 1e-300)]
    return best[0] if len(best) == 1 else tuple(best)
