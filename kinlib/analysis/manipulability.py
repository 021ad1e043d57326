"""Manipulability: how well the robot can move in every task direction at a configuration.

For J (m×n, the rows of the task space: pick them with :func:`kinlib.taskspace.task_rows`):

* Yoshikawa's manipulability  w = √det(J Jᵀ)  (n ≥ m), or √det(Jᵀ J) when the robot has fewer joints
  than task dimensions (n < m); = σ1 σ2 ⋯ σk, the product of the singular values; 0 exactly at a singularity.
* condition number  κ = σ_max / σ_min ≥ 1 (∞ at a singularity);  isotropy = 1/κ ∈ [0, 1], 1 when the
  velocity ellipsoid is a sphere (a circle in the plane).
* velocity ellipsoid {J θ̇ : ‖θ̇‖ ≤ 1}: semi-axes σ_i along the left singular vectors u_i; with rows held
  at zero (``hold=``, e.g. the orientation ω_z), the ellipsoid of J_r N (N: a basis of null(J_hold)).
* problem 6.2's speed view: V·V = θ̇ᵀ (Jᵀ J) θ̇.

SymPy input gives exact SymPy results (``simplify=True`` for a display form); numbers give floats, and a
batch of Jacobians (N, m, n) gives (N,) results.

**Near a singular configuration**: the course's one rule (used by the explorers, the animation of 5.2 and the
notebooks' text), here beside the measures it is made of (it was kinlib.nearsingular).

>>> import numpy as np
>>> singularity_state(np.diag([1.0, 0.05]), 1.0), singularity_state(np.eye(2), 1.0)
('near', 'regular')
"""

from __future__ import annotations

import warnings
from typing import Any

import numpy as np
import sympy as sp

from .._backend import as_vector, describe, exact_jacobian, is_symbolic, nested_shape, numeric_jacobian, numeric_vectors
from ..exact.budget import ExactTimeoutError, OutOfTime, budget_seconds, report, run
from ..exact.field import FALLBACK_DIGITS, decide_zero, mp_context, mp_matrix, mp_value
from ..exact.linalg import TIME_BUDGET, NumericFallbackWarning, exact_det
from ..exact.trigpoly import TrigRing, angles_in
from .singularities import trig_simplify
from .taskspace import task_row_indices, task_rows

__all__ = [
    "manipulability",
    "condition_number",
    "isotropy",
    "velocity_ellipsoid",
    "twist_speed_form",
    "twist_speed",
    "singular_values",
    "strongest_joints",
    "manipulability_values",
    "MEASURES",
    "measure_label",
    "NEAR_SINGULAR",
    "SINGULAR_RTOL",
    "singularity_state",
    "near_singular",
    "peak_manipulability",
]


def _volume(A: np.ndarray) -> np.ndarray:
    """w = √det(J Jᵀ) (√det(Jᵀ J) with fewer joints than rows) = the product of J's singular values (batched)."""
    return np.prod(np.linalg.svd(A, compute_uv=False), axis=-1)


# ----------------------------------------------------------------------------------------------
# "near a singular configuration": the one rule of the course
# ----------------------------------------------------------------------------------------------
#: A configuration is **near a singular configuration** when its manipulability w = √det(J Jᵀ) of the task
#: rows (√det(Jᵀ J) with fewer joints than rows) is below ``NEAR_SINGULAR`` times w_max, the largest w of the
#: same arm and rows over its joint ranges: w < 0.1 · w_max. The explorers, the animation and the notebooks
#: all use this rule (:func:`singularity_state`); nowhere else in kinlib or the notebooks is "near" decided.
#:
#: Why w / w_max and not σ_min / σ_max: the rows of J mix units (ω in rad/s, ṗ in m/s per rad/s of joint
#: rate), so σ_min / σ_max compares an angular with a linear speed and changes with the unit of length (for the
#: planar 3R of problem 5 with L = 1 it stays ≤ 0.074 on a whole sweep, where w is still 70 % of w_max).
#: Rescaling every length by c scales the v rows by c, i.e. J → D J with D = diag(1, …, c, …) constant, so
#: w → |det D| w at *every* configuration (n ≥ m: det(D J Jᵀ D) = det(D)² det(J Jᵀ)) and the ratio w / w_max
#: does not depend on the unit. (With fewer joints than rows, det(Jᵀ D² J) is not a constant multiple of
#: det(Jᵀ J): there the ratio is unit-free only when the rows have one unit.)
NEAR_SINGULAR = 0.1

#: The rank test: a singular value at most ``SINGULAR_RTOL`` · σ_max counts as 0 (floating-point round-off of a
#: singular configuration computed in double precision is ≈ 10⁻¹⁶ · σ_max).
SINGULAR_RTOL = 1e-6


def singularity_state(J: Any, w_max: float, near: float = NEAR_SINGULAR, rtol: float = SINGULAR_RTOL):
    """'singular', 'near' or 'regular' for numeric task rows J (m×n; a batch (N, m, n) gives an array of N
    states): 'singular' when J loses rank (a singular value ≤ ``rtol`` · σ_max, or J = 0), 'near' when
    w < ``near`` · ``w_max`` (the rule :data:`NEAR_SINGULAR`; w_max: the largest w of the same arm and rows,
    e.g. from :func:`peak_manipulability`), else 'regular'.

    >>> import numpy as np
    >>> J = lambda t: np.array([[1.0, 1.0, 1.0], [0.0, np.sin(1), np.sin(1) + np.sqrt(2) * np.sin(1 + t)],
    ...                         [0.0, -np.cos(1), -np.cos(1) - np.sqrt(2) * np.cos(1 + t)]])
    >>> [str(singularity_state(J(t), np.sqrt(2))) for t in (0.0, np.pi / 4, 0.05, -0.8)]   # w/w_max = |sin t|
    ['singular', 'regular', 'near', 'regular']
    """
    if not (isinstance(w_max, (int, float, np.floating, np.integer)) and np.isfinite(w_max) and w_max > 0):
        raise ValueError(f"w_max must be a positive number (the largest manipulability), got {describe(w_max)}")
    if not (0 < float(near) < 1):
        raise ValueError(f"near must be a number in (0, 1), got {describe(near)}")
    A = numeric_jacobian(J)
    s = np.linalg.svd(A, compute_uv=False)
    singular = s[..., -1] <= rtol * s[..., 0]
    w = _volume(A)
    out = np.where(singular, "singular", np.where(w < float(near) * float(w_max), "near", "regular"))
    return str(out) if out.ndim == 0 else out


def near_singular(J: Any, w_max: float, near: float = NEAR_SINGULAR):
    """True at or near a singular configuration: w < ``near`` · ``w_max`` (:data:`NEAR_SINGULAR`), a singular
    configuration included (w = 0). A batch (N, m, n) gives N booleans.

    >>> import numpy as np
    >>> bool(near_singular(np.diag([1.0, 0.05]), 1.0)), bool(near_singular(np.eye(2), 1.0))
    (True, False)
    """
    state = singularity_state(J, w_max, near)
    return state != "regular" if isinstance(state, str) else np.asarray(state) != "regular"


def peak_manipulability(chain: Any, rows: Any, ranges: Any = None, samples: int = 4000, seed: int = 0, extra=None):
    """w_max: the largest √det(J Jᵀ) of the task ``rows`` of the geometric Jacobian of a numeric ``chain``
    over ``samples`` configurations drawn (fixed ``seed``) from ``ranges`` (a (lo, hi) pair per joint; default
    a turn (−π, π) for every joint), and the configurations ``extra`` (N×n) if given: the reference of the
    "near" rule (:data:`NEAR_SINGULAR`).

    >>> from kinlib.robots import planar_offset_3r
    >>> round(peak_manipulability(planar_offset_3r(1), "planar"), 3)      # √2 L², exactly
    1.414
    """
    n = int(chain.n)
    lo_hi = np.array([(-np.pi, np.pi)] * n if ranges is None else ranges, dtype=float)
    if lo_hi.shape != (n, 2) or not np.all(np.isfinite(lo_hi)):
        raise ValueError(f"ranges must be {n} (lo, hi) pairs of numbers, got {describe(ranges)}")
    if not isinstance(samples, int) or samples < 1:
        raise ValueError(f"samples must be a positive int, got {describe(samples)}")
    rng = np.random.default_rng(seed)
    Q = lo_hi[:, 0] + (lo_hi[:, 1] - lo_hi[:, 0]) * rng.random((samples, n))
    if extra is not None:
        Q = np.vstack([Q, np.asarray(extra, float).reshape(-1, n)])
    return float(np.max(_volume(task_rows(chain.jacobian_geometric(Q), rows))))


def _gram(J: sp.Matrix) -> sp.Matrix:
    """J Jᵀ when n ≥ m (more joints than rows), else Jᵀ J: the smaller square Gram matrix."""
    return J * J.T if J.cols >= J.rows else J.T * J


def singular_values(J: Any) -> np.ndarray:
    """σ1 ≥ σ2 ≥ ⋯ ≥ σk (k = min(m, n)) of a numeric J; shape (k,) or (N, k) for a batch.

    >>> import numpy as np
    >>> from kinlib.robots import planar_2r
    >>> J = planar_2r(1, 1).jacobian_geometric([0.0, np.pi / 2])[[3, 4]]   # rows ṗ_x, ṗ_y: [[-1, -1], [1, 0]]
    >>> s = singular_values(J)
    >>> s.round(3).tolist(), round(float(s.prod()), 3)   # σ1 σ2 = |det J| = L1 L2 |sin θ2|
    ([1.618, 0.618], 1.0)
    """
    return np.linalg.svd(numeric_jacobian(J), compute_uv=False)


def _display_sqrt(G_det: sp.Expr) -> sp.Expr:
    """√D for display: positive factors with even powers come out, the rest is trig-simplified under √."""
    ring = TrigRing([G_det], angles_in([G_det]), opaque=True)
    D = sp.factor(ring.to_expr(ring.normal_form(G_det), trig=False))  # factored as a polynomial in s_i, c_i
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
                inside *= ft**m
    inside = sp.trigsimp(inside) if inside.has(sp.sin, sp.cos) else inside
    return outside * sp.sqrt(inside)


def manipulability(J: Any, simplify: bool = False):
    """Yoshikawa's w = √det(J Jᵀ) (n ≥ m) or √det(Jᵀ J) (n < m): 0 exactly where J loses rank.

    SymPy J: the exact expression (``simplify=True`` gives a display form, e.g. L²√(sin 2θ2 + 1), with
    the square roots of squares of positive parameters taken out). Numeric J (m, n) or a batch (N, m, n):
    the product of the singular values, float or (N,) array.

    >>> import numpy as np
    >>> from kinlib.robots import planar_2r
    >>> J = task_rows(planar_2r().jacobian_geometric(), ["vx", "vy"])   # rows ṗ_x, ṗ_y: det J = L1 L2 sin θ2
    >>> manipulability(J, simplify=True)
    L1*L2*Abs(sin(theta2))
    >>> q = np.array([[0, 0], [0, np.pi / 2], [0, np.pi]])   # stretched out, elbow at a right angle, folded
    >>> (manipulability(planar_2r(1, 1).jacobian_geometric(q)[:, [3, 4]]).round(3) + 0.0).tolist()
    [0.0, 1.0, 0.0]
    """
    if not is_symbolic(J):
        A = numeric_jacobian(J)
        return np.prod(np.linalg.svd(A, compute_uv=False), axis=-1)
    M = exact_jacobian(J)
    D = exact_det(_gram(M))
    if not simplify:
        return sp.sqrt(D)
    return _display_sqrt(D)


def _exact_sign(e: sp.Expr, what: str) -> int:
    """Sign of a constant e, decided exactly (is_zero / is_positive) or by 50-digit evaluation with a clear gap."""
    if e.is_zero or e == 0:
        return 0
    if e.is_positive:
        return 1
    if e.is_negative:
        return -1
    v = sp.N(e, 50)
    if v.is_real and abs(v) > sp.Float("1e-40", 50):
        return 1 if v > 0 else -1
    if decide_zero(e, what):  # a ValueError when it cannot be decided either way
        return 0
    raise ValueError(f"could not decide the sign of {what} = {e} exactly")


def _kappa_parts(J: Any, what: str):
    """Symbolic κ from the k×k Gram matrix G (k = min(m, n)): ('one',) when κ = 1, ('singular',) when κ = ∞
    everywhere, or ('ratio', top, bottom) with κ = top/bottom, both ≥ 0 (bottom = 0 at singular points).

    k = 2: λ± = (t ± √(t² − 4d))/2 (t = trace G, d = det G, t² − 4d = (a − c)² + 4b² ≥ 0), so
    κ = √(λ₊/λ₋) = (t + √(t² − 4d)) / (2√d). A constant G: its exact eigenvalues.
    """
    M = exact_jacobian(J)
    k = min(M.shape)
    if k == 1:
        return ("one",)
    # G as normal forms modulo sin² + cos² = 1 (canonical and fast; no trigsimp of big expressions)
    ring = TrigRing(list(M), angles_in(list(M)), opaque=True)
    E = [[ring.normal_form(M[i, j]) for j in range(M.cols)] for i in range(M.rows)]
    A = E if M.rows <= M.cols else [list(col) for col in zip(*E)]  # k×N
    R = ring.ring
    G = [[ring.reduce(sum((x * y for x, y in zip(A[i], A[j])), R.zero)) for j in range(k)] for i in range(k)]
    if all(not g or g.is_ground for row in G for g in row):
        Gc = sp.Matrix(k, k, lambda i, j: ring.to_expr(G[i][j]) if G[i][j] else sp.S.Zero)
        ev = [sp.radsimp(e) for e in Gc.eigenvals(multiple=True)]
        if any(_exact_sign(e, "an eigenvalue of the Gram matrix") == 0 for e in ev):
            return ("singular",)
        top = bottom = ev[0]
        for e in ev[1:]:
            if _exact_sign(e - top, "a difference of eigenvalues") > 0:
                top = e
            if _exact_sign(e - bottom, "a difference of eigenvalues") < 0:
                bottom = e
        if _exact_sign(top - bottom, "a difference of eigenvalues") == 0:
            return ("one",)
        return ("ratio", sp.radsimp(sp.sqrt(top)), sp.radsimp(sp.sqrt(bottom)))
    if k > 2 and not M.free_symbols:
        # a constant J with sines of numbers (sin 1, …): singular exactly when det G = 0 (decided exactly); else the
        # eigenvalues are roots of a cubic or worse with transcendental coefficients: κ from a 60-digit SVD, flagged
        from ..exact.fallback import fallback_rank, fallback_warning

        Gc = M * M.T if M.rows <= M.cols else M.T * M
        if decide_zero(exact_det(Gc)):
            return ("singular",)
        _, sv = fallback_rank(M)
        fallback_warning(what, "the eigenvalues of a constant 3×3 (or larger) Gram matrix with sines of numbers")
        return ("ratio", sp.Float(sv[0], FALLBACK_DIGITS), sp.Float(sv[k - 1], FALLBACK_DIGITS))
    if k > 2:
        raise ValueError(
            f"{what} of a symbolic J with k = min(m, n) = {k} ≥ 3 has no readable closed form (the Gram "
            "eigenvalues are roots of a cubic or worse): evaluate it numerically, e.g. "
            f"{what}(chain.subs(L=1).jacobian_geometric(q)) with float joint values q, or pick 2 task rows "
            "with task_rows(J, [...]) (a 2-row J has a closed form), or give J at a configuration "
            "(no free symbols) for the exact value"
        )
    t = G[0][0] + G[1][1]
    d = ring.reduce(G[0][0] * G[1][1] - G[0][1] * G[0][1])
    disc = ring.reduce(t * t - 4 * d)
    if not disc:
        return ("one",)
    if not d:
        return ("singular",)
    return ("ratio", _show(ring, t) + _sqrt_form(ring, disc), 2 * _sqrt_form(ring, d))


def _show(ring, p, limit: int = 120) -> sp.Expr:
    """A ring element in sin/cos: factored as a polynomial, angle sums folded when small."""
    e = ring.to_trig(sp.factor(ring.to_expr(p, trig=False)))
    return sp.trigsimp(e) if sp.count_ops(e) < limit else e


def _sqrt_form(ring, p) -> sp.Expr:
    """√p for display (p ≥ 0): squared factors taken out (|f| unless f ≥ 0 is known), the rest under the root."""
    coeff, factors = sp.factor_list(ring.to_expr(p, trig=False))
    outside, inside = sp.S.One, coeff
    for f, m in factors:
        ft = ring.to_trig(f)
        if m >= 2:
            ft_out = _show(ring, ring.from_expr(ft)) if ft.has(sp.sin, sp.cos) else ft
            outside *= (ft_out if ft.is_nonnegative else sp.Abs(ft_out)) ** (m // 2)
        if m % 2:
            inside *= ft
    if inside.has(sp.sin, sp.cos):
        inside = _show(ring, ring.reduce(ring.from_expr(inside)))
    return outside * sp.sqrt(inside)


def _extreme_singular_values(A: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(σ_max, σ_min) of a float J or batch, with σ_min = 0 exactly when, and only when, J is exactly singular.

    LAPACK's σ_min of a rank-deficient J is rounding noise (≈ 1e-17 σ_max for [[1, 1], [1, 1]]), and a
    nonsingular J may be ill-conditioned (diag(1e300, 1)): where σ_min ≤ k·eps·σ_max (numerically singular),
    J's rank is decided exactly on its floats as the exact binary fractions they are (fraction-free
    elimination): rank-deficient → σ_min = 0; otherwise LAPACK's σ_min stands (so κ agrees with
    ``numpy.linalg.cond`` for every J that is not exactly singular; no hidden cut-off).
    """
    s = np.linalg.svd(A, compute_uv=False)
    smax, smin = s[..., 0].copy(), s[..., -1].copy()
    k = s.shape[-1]
    suspect = np.flatnonzero(np.reshape(smin <= 4 * k * np.finfo(float).eps * smax, -1))
    if suspect.size:
        flat_min = smin.reshape(-1)
        mats = A.reshape((-1,) + A.shape[-2:])
        for i in suspect:
            if _exact_rank(mats[i]) < k:
                flat_min[i] = 0.0
        smin = flat_min.reshape(smin.shape)
    return smax, smin


def _exact_rank(A: np.ndarray) -> int:
    """The exact rank of a float matrix (its entries as exact binary fractions), by integer elimination."""
    from fractions import Fraction

    rows = [[Fraction(float(x)) for x in row] for row in A]
    if not rows or not rows[0]:
        return 0
    scale = 1
    for row in rows:
        for x in row:
            scale = max(scale, x.denominator)  # powers of two: the largest is a common denominator
    M = [[int(x * scale) for x in row] for row in rows]
    rank, ncols = 0, len(M[0])
    for c in range(ncols):
        piv = next((r for r in range(rank, len(M)) if M[r][c]), None)
        if piv is None:
            continue
        M[rank], M[piv] = M[piv], M[rank]
        p = M[rank]
        for r in range(rank + 1, len(M)):
            f = M[r][c]
            if f:
                M[r] = [p[c] * a - f * b for a, b in zip(M[r], p)]
        rank += 1
    return rank


def condition_number(J: Any):
    """κ = σ_max / σ_min (≥ 1; ∞ at a singular configuration), over the k = min(m, n) singular values.

    Numeric J (or a batch): floats, σ_max/σ_min as ``numpy.linalg.cond`` with no cut-off (diag(1, 1e-12) →
    1e12, diag(1e300, 1) → 1e300); ∞ exactly when J is exactly singular, i.e. its floats (as the exact binary
    fractions they are) have rank < k ([[1, 1], [1, 1]], a zero column). A configuration singular only up to
    rounding (θ2 = np.pi, where sin θ2 is 1.2e-16) gives a large finite κ (≈ 1e16), as NumPy does. SymPy J: exact, from the k×k Gram matrix G = J Jᵀ (or Jᵀ J) with
    eigenvalues λ = σ²: for k = 2, κ = √(λ₊/λ₋) = (t + √(t² − 4d)) / (2√d) with t = trace G, d = det G
    (trig-simplified; d = 0 exactly at the singular configurations, where κ = ∞ — SymPy gives zoo);
    k = 1 gives 1; with no free symbols the exact eigenvalues of the constant G; k ≥ 3 with free joint
    symbols is refused (ValueError) with the numeric alternative named.

    >>> import sympy as sp
    >>> condition_number(sp.Matrix([[2, 0], [0, 1]]))
    2
    >>> t = sp.Symbol("t", real=True)
    >>> condition_number(sp.Matrix([[1, sp.cos(t)], [0, sp.sin(t)]]))
    (Abs(cos(t)) + 1)/Abs(sin(t))
    """
    if not is_symbolic(J):
        smax, smin = _extreme_singular_values(numeric_jacobian(J))
        with np.errstate(divide="ignore", over="ignore"):
            out = np.where(smin > 0, smax / np.where(smin > 0, smin, 1.0), np.inf)
        return float(out) if np.ndim(out) == 0 else out
    parts = _kappa_parts(J, "condition_number")
    if parts[0] == "one":
        return sp.S.One
    if parts[0] == "singular":
        return sp.oo
    return sp.factor_terms(parts[1] / parts[2])


def isotropy(J: Any):
    """1/κ = σ_min / σ_max ∈ [0, 1]: 1 when the velocity ellipsoid is a sphere (circle), 0 at a singularity.

    Numeric J: σ_min/σ_max with no cut-off (diag(1, 1e-12) → 1e-12, diag(1e300, 1) → 1e-300); 0 exactly when J
    is exactly singular (see :func:`condition_number`).

    SymPy J as for :func:`condition_number`: for k = 2, 2√d / (t + √(t² − 4d)) (0 where d = det G = 0).

    >>> import sympy as sp
    >>> isotropy(sp.Matrix([[2, 0], [0, 1]]))
    1/2
    """
    if not is_symbolic(J):
        smax, smin = _extreme_singular_values(numeric_jacobian(J))
        with np.errstate(under="ignore"):
            out = np.where(smin > 0, smin / np.where(smax > 0, smax, 1.0), 0.0)
        return float(out) if np.ndim(out) == 0 else out
    parts = _kappa_parts(J, "isotropy")
    if parts[0] == "one":
        return sp.S.One
    if parts[0] == "singular":
        return sp.S.Zero
    return sp.factor_terms(parts[2] / parts[1])


def velocity_ellipsoid(J: Any, rows: Any = None, hold: Any = None, *, time_budget=TIME_BUDGET):
    """The velocity ellipsoid {J_r θ̇ : ‖θ̇‖ ≤ 1}: (semi-axis lengths σ_i, unit directions u_i as columns).

    ``rows``: pick task rows first (see :func:`~kinlib.taskspace.task_rows`); by default a 6-row J
    uses its linear rows ("linear" = vx vy vz, the tool velocity ṗ for the geometric Jacobian), any other J
    all of its rows. Numeric J: lengths (k,) sorted descending and directions (m, k), k = min(m, n) (a
    batch gives (N, k), (N, m, k)). SymPy J: exact eigen-decomposition of J Jᵀ (lengths √λ, orthonormal
    directions), for small or evaluated J. An eigenvalue that is a root of an irreducible polynomial of degree
    ≥ 3 with rational coefficients is written as ``CRootOf`` (exact; its direction as polynomials in that
    root); with other coefficients (sin 1, …) there is no closed form and, as past ``time_budget`` seconds
    (default 60; None: no limit; :mod:`kinlib.budget`), a constant J gets the eigen-decomposition in
    ``FALLBACK_DIGITS`` = 60-digit Floats with a :class:`~kinlib.exact.NumericFallbackWarning`; a J with free
    symbols is refused (a ValueError saying to substitute numbers).

    ``hold``: task rows kept at zero (e.g. ``("wz",)``: the tool's orientation held). The ellipsoid is then
    {J_r θ̇ : J_h θ̇ = 0, ‖θ̇‖ ≤ 1} = {J_r N z : ‖z‖ ≤ 1} with N an orthonormal basis of null(J_h) (d columns):
    semi-axes the singular values of J_r N, directions its left singular vectors, k = min(m, d). Since
    rank [J_h; J_r] = rank J_h + rank(J_r N), a semi-axis is 0 (the ellipse collapses to a segment) exactly
    where the rows [J_h; J_r] lose rank while J_h keeps its rank. ``rows`` must be named with ``hold``
    and the two must not share a row. Numeric: N from the SVD of J_h (its rank: singular values above
    max(shape)·ε·σ_max, NumPy's matrix_rank rule); one J at a time (no batch). SymPy: exact, from the
    Gram matrix J_r P J_rᵀ with P = B (Bᵀ B)⁻¹ Bᵀ the projector onto null(J_h) (B = SymPy's nullspace
    basis, so no square roots enter before the eigenvalues); with free symbols the null space is the
    generic one (valid where J_h keeps its generic rank).

    >>> import numpy as np, sympy as sp
    >>> from kinlib.robots import planar_2r, planar_offset_3r
    >>> lengths, dirs = velocity_ellipsoid(planar_2r(1, 1).jacobian_geometric([0.0, np.pi / 2]))   # rows vx vy vz
    >>> lengths.round(3).tolist(), dirs.shape   # σ1, σ2; u1, u2 as columns
    ([1.618, 0.618], (3, 2))
    >>> velocity_ellipsoid(sp.Matrix([[2, 0], [0, 1]]))   # exact: semi-axes 2 along x, 1 along y
    ([2, 1], Matrix([
    [1, 0],
    [0, 1]]))
    >>> J = planar_offset_3r(1).jacobian_geometric([np.pi / 6, -np.pi / 4, -np.pi / 3])   # θ2 = −π/4: singular
    >>> velocity_ellipsoid(J, rows=("vx", "vy"))[0].round(2).tolist()   # ṗ with all three joints: still fat
    [2.79, 1.03]
    >>> (velocity_ellipsoid(J, rows=("vx", "vy"), hold=("wz",))[0].round(2) + 0.0).tolist()   # ω_z held: a segment
    [1.72, 0.0]
    >>> velocity_ellipsoid(sp.Matrix([[1, 1, 1], [0, 0, 1], [0, -1, 0]]), rows=[1, 2], hold=[0])[0]   # exact
    [1, sqrt(3)/3]
    """
    seconds = budget_seconds(time_budget)
    if hold is not None:
        return _held_ellipsoid(J, rows, hold, seconds)
    if rows is None:
        shape = J.shape if hasattr(J, "shape") else np.shape(np.asarray(J, dtype=object))
        rows = "linear" if len(shape) >= 2 and shape[-2] == 6 else None
    if rows is not None:
        J = task_rows(J, rows)
    if not is_symbolic(J):
        A = numeric_jacobian(J)
        U, s, _ = np.linalg.svd(A, full_matrices=False)
        return s, U
    M = exact_jacobian(J)
    if _at_a_pose(M):
        got = _pose_axes(M, seconds)
        if got is not None:
            return got
    return budgeted_axes(lambda: M * M.T, min(M.rows, M.cols), seconds, "velocity_ellipsoid", M.free_symbols)


def _at_a_pose(M: sp.Matrix) -> bool:
    """M is an evaluated J of three or more rows, none of them zero, with sines and cosines that did not evaluate
    (angles such as 2π/7, 1/3): the Gram matrix's eigenvalues are then roots of a polynomial whose coefficients
    lie in a number field of high degree, where SymPy's generic eigen-decomposition spent the whole budget."""
    return (
        not M.free_symbols
        and M.rows >= 3
        and M.has(sp.sin, sp.cos)
        and all(any(e != 0 for e in M.row(i)) for i in range(M.rows))
    )


def _pose_rank_axes(M: sp.Matrix):
    """In the budget's process: ("exact", lengths, U) when the rank r of M (proved by
    :class:`~kinlib.exact_rank.RankAnalysis`, the structure at singular poses) is 0 or 1, else ("rank", r).
    Rank 1: J Jᵀ = ‖·‖² c cᵀ for a pivot column c, so σ₁ = √(tr J Jᵀ) along c/‖c‖; the other axes have length 0
    along an orthonormal basis of the left null space of M."""
    from ..exact.linalg import left_null_space_exact
    from ..exact.rank import RankAnalysis

    r = RankAnalysis(M).rank
    if r > 1:
        return ("rank", r)
    m, k = M.rows, min(M.rows, M.cols)
    if r == 0:
        return ("exact", [sp.S.Zero] * k, sp.eye(m)[:, :k])
    c = next(M.col(j) for j in range(M.cols) if any(decide_zero(e) is False for e in M.col(j)))
    lam = sum((e**2 for e in M), sp.S.Zero)
    u = c / sp.sqrt(sum((e**2 for e in c), sp.S.Zero))
    N, why = left_null_space_exact(M, m)
    if N is None:
        return ("rank", r)
    zeros = sp.GramSchmidt([N.col(j) for j in range(N.cols)], orthonormal=True)[: k - 1]
    return ("exact", [sp.sqrt(lam)] + [sp.S.Zero] * (k - 1), sp.Matrix.hstack(u, *zeros))


def _pose_axes(M: sp.Matrix, seconds):
    """velocity_ellipsoid at an evaluated pose (:func:`_at_a_pose`): exact for rank ≤ 1 (:func:`_pose_rank_axes`);
    otherwise the eigen-decomposition of J Jᵀ in 60-digit numerics with a NumericFallbackWarning, its zero axes
    (rank proved exactly) exactly 0. None when the rank itself is out of reach (then the generic path)."""
    try:
        got = run(seconds, "velocity_ellipsoid", _pose_rank_axes, M)
    except (OutOfTime, ValueError):
        return None
    if got[0] == "exact":
        return got[1], got[2]
    r, k = got[1], min(M.rows, M.cols)
    lengths, U = _numeric_axes(M * M.T, k)
    if sum(1 for x in lengths if x != 0) != r:  # a nonzero axis below the 60-digit resolution: look closer
        lengths, U = _numeric_axes(M * M.T, k, digits=4 * FALLBACK_DIGITS)
    lengths = [x if i < r else sp.S.Zero for i, x in enumerate(lengths)]
    warnings.warn(
        f"velocity_ellipsoid: J has rank {r} here (proved exactly), so {k - r} semi-axes are exactly 0; the "
        f"{r} nonzero ones are roots of a degree-{r} polynomial with coefficients in a number field of high degree "
        f"(no closed form in reach): computed with {FALLBACK_DIGITS}-digit numerics",
        NumericFallbackWarning,
        stacklevel=3,
    )
    return lengths, U


class _NoClosedForm(Exception):
    pass


def budgeted_axes(gram, k: int, seconds, what: str, symbols=()):
    """:func:`_exact_axes` of ``gram()`` within ``seconds``; the 60-digit fallback for a constant Gram matrix
    (with a NumericFallbackWarning), a clear ValueError for a symbolic one (``symbols``: J's free symbols)."""
    why, grams = "", []

    def axes():  # G is reported: the caller keeps it for the fallback even when the budget then runs out
        report(G := gram())
        return _exact_axes(G, k)

    try:
        return run(seconds, what, axes, progress=grams.append)
    except OutOfTime:
        why = f"the exact eigen-decomposition did not finish within time_budget={seconds} s"
    except _NoClosedForm as err:
        why = str(err)
    G = grams[-1] if grams else None if symbols else gram()  # (G not formed in time: constant matrices' product)
    if G is None or G.free_symbols:
        syms = ", ".join(sorted(map(str, G.free_symbols if G is not None else symbols), key=str))
        raise ExactTimeoutError(
            f"{what}: {why}; J has the free symbols {syms}: substitute numbers for them (floats: the fast numeric "
            "backend; exact values: this exact path), or give a larger time_budget (None: no limit)"
        )
    warnings.warn(
        f"{what}: no exact eigen-decomposition here ({why}); computed with {FALLBACK_DIGITS}-digit numerics "
        f"(eigenvalues below 1e-40·λ_max counted as zero, not proven)",
        NumericFallbackWarning,
        stacklevel=3,
    )
    return _numeric_axes(G, k)


def _numeric_axes(G: sp.Matrix, k: int, digits: int = FALLBACK_DIGITS):
    """(lengths, directions) of the k largest eigenvalues of the symmetric constant G, as 60-digit Floats
    (``digits``: the working precision, more for tiny eigenvalues)."""
    mpmath = mp_context()  # this thread's own context: never the global precision
    if digits > FALLBACK_DIGITS:
        memo: dict = {}
        with mpmath.workdps(digits + 40):
            X = mpmath.matrix([[mp_value(G[i, j], memo, mpmath) for j in range(G.cols)] for i in range(G.rows)])
    else:
        X = mp_matrix(G)
    with mpmath.workdps(digits + 20):
        X = (X + X.T) / 2
        E, Q = mpmath.eigsy(X)
        order = sorted(range(len(E)), key=lambda i: -E[i])[:k]
        top = max((abs(e) for e in E), default=mpmath.mpf(0))
        tol = top * mpmath.mpf(10) ** -(digits - 20)

        def fl(x):
            return sp.Float(mpmath.nstr(x, FALLBACK_DIGITS), FALLBACK_DIGITS) if abs(x) > tol else sp.S.Zero

        lengths = [fl(mpmath.sqrt(E[i])) if E[i] > tol else sp.S.Zero for i in order]
        vecs = [[fl(Q[r, i]) for i in order] for r in range(G.rows)]
    return lengths, sp.Matrix(vecs) if order else sp.zeros(G.rows, 0)


def _charpoly_factors(G: sp.Matrix):
    """The factors (f, multiplicity) of det(x I − G) in the Dummy x, and x."""
    x = sp.Dummy("x")
    p = G.charpoly(x).as_expr(x)  # (a PurePoly keeps a generator of its own)
    _, facs = sp.factor_list(p, x)
    return [(f, m) for f, m in facs if f.has(x)], x


def _root_axes(G: sp.Matrix, f: sp.Expr, x: sp.Symbol) -> list:
    """(λ, unit eigenvector) for each root λ = CRootOf(f, i) of an irreducible rational f of degree ≥ 3 that is
    a simple factor of the characteristic polynomial: the eigenvector is a nonzero column of adj(G − λI), written
    as polynomials in λ reduced modulo f (a reduced polynomial that is not 0 cannot vanish at a root of the
    irreducible f: a proof that the column is nonzero)."""
    n = G.rows
    f, x = f.subs(x, sp.Symbol("x")), sp.Symbol("x")  # G is constant here: x only names CRootOf's polynomial
    P = sp.Poly(f, x)
    adj = (G - x * sp.eye(n)).adjugate(method="berkowitz")
    for j in range(n):
        col = [sp.Poly(adj[i, j], x).rem(P) for i in range(n)]
        if any(not c.is_zero for c in col):
            break
    else:  # pragma: no cover - a simple root has a rank-(n−1) G − λI, so adj ≠ 0
        raise _NoClosedForm("an eigenvector could not be found exactly")
    n2 = sum((c * c for c in col), sp.Poly(0, x)).rem(P)
    out = []
    for i in range(P.degree()):
        lam = sp.CRootOf(P, i)
        norm = sp.sqrt(n2.as_expr().subs(x, lam))
        out.append((lam, sp.Matrix([c.as_expr().subs(x, lam) / norm for c in col])))
    return out


def _exact_axes(G: sp.Matrix, k: int):
    """Exact (lengths √λ, orthonormal directions) of the k largest eigenvalues of the Gram matrix G."""
    G = trig_simplify(G) if angles_in(list(G)) else G.applyfunc(sp.simplify)
    pairs = []
    facs, x = _charpoly_factors(G) if G.rows >= 3 else ([], None)
    high = [(f, m) for f, m in facs if sp.degree(f, x) >= 3]
    if high:
        if G.free_symbols:
            raise _NoClosedForm(
                f"the eigenvalues of the {G.rows}×{G.rows} Gram matrix include roots of an irreducible polynomial of "
                f"degree {max(sp.degree(f, x) for f, _ in high)} in them: no closed form"
            )
        if any(m > 1 or not sp.Poly(f, x).domain.is_QQ and not sp.Poly(f, x).domain.is_ZZ for f, m in high):
            raise _NoClosedForm(
                "the eigenvalues include roots of an irreducible polynomial of degree ≥ 3 whose coefficients are "
                "not rational: no closed form"
            )
        for f, _m in high:
            pairs += _root_axes(G, f, x)
        low = [(f, m) for f, m in facs if sp.degree(f, x) <= 2]
        eig = []
        for f, _m in low:
            for lam in sp.roots(sp.Poly(f, x)):
                eig.append((lam, None, (G - lam * sp.eye(G.rows)).nullspace(simplify=True)))
    else:
        try:
            eig = G.eigenvects(simplify=True)
        except NotImplementedError:
            raise ValueError(
                "J: SymPy cannot find exact eigenvectors of this Gram matrix (J with free joint symbols is too "
                "big): give J at a configuration (exact values, no free joint symbols) or numbers"
            ) from None
    for lam, _mult, vecs in eig:
        lam = sp.simplify(lam)
        ortho = sp.GramSchmidt(vecs, orthonormal=True)
        for v in ortho:
            pairs.append((lam, v.applyfunc(lambda e: sp.radsimp(sp.simplify(e)))))

    def key(p):
        try:
            return -float(p[0].subs(dict.fromkeys(p[0].free_symbols, 1)))
        except TypeError:
            return 0.0

    pairs.sort(key=key)
    pairs = pairs[:k]
    lengths = [sp.sqrt(lam) for lam, _ in pairs]
    if not pairs:
        return lengths, sp.zeros(G.rows, 0)
    return lengths, sp.Matrix.hstack(*[v for _, v in pairs])


def _held_ellipsoid(J: Any, rows: Any, hold: Any, seconds):
    """velocity_ellipsoid(J, rows, hold): the ellipsoid of J_r θ̇ over θ̇ ∈ null(J_h), ‖θ̇‖ ≤ 1."""
    if rows is None:
        raise ValueError("rows must name the task rows drawn (e.g. rows=('vx', 'vy')) when hold is given, got None")
    if isinstance(J, np.ndarray) and J.ndim == 3:
        raise ValueError(f"J must be one Jacobian (m×n) when hold is given (loop over a batch), got {describe(J)}")
    symbolic = is_symbolic(J)
    M = exact_jacobian(J) if symbolic else numeric_jacobian(J)
    if M.shape[0] == 0 or len(M.shape) != 2:
        raise ValueError(f"J must be a matrix (m×n Jacobian), got {describe(J)}")
    m = M.shape[0]
    r_idx = task_row_indices(rows, None, m)
    try:
        h_idx = task_row_indices(hold, None, m)
    except (TypeError, ValueError) as e:
        raise type(e)(f"hold: {e}") from None
    both = sorted(set(r_idx) & set(h_idx))
    if both:
        raise ValueError(
            f"rows and hold must not share a row (a held row is zero), got rows={describe(rows)}, "
            f"hold={describe(hold)} (both name rows {both})"
        )
    if symbolic:
        A, H = M.extract(list(r_idx), list(range(M.cols))), M.extract(list(h_idx), list(range(M.cols)))
        try:
            B = run(seconds, "velocity_ellipsoid", H.nullspace, simplify=True)
        except OutOfTime:
            raise ExactTimeoutError(
                f"velocity_ellipsoid: the null space of the held rows did not finish within time_budget={seconds} "
                "s; give J at a configuration, numbers, or a larger time_budget (None: no limit)"
            ) from None
        if not B:
            return [], sp.zeros(A.rows, 0)
        B = sp.Matrix.hstack(*B)
        d = B.cols
        P, syms = lambda: A * (B * (B.T * B).inv() * B.T) * A.T, M.free_symbols
        return budgeted_axes(P, min(A.rows, d), seconds, "velocity_ellipsoid", syms)
    A, H = M[list(r_idx)], M[list(h_idx)]
    _, s, Vt = np.linalg.svd(H)
    rank = int(np.sum(s > max(H.shape) * np.finfo(float).eps * (s[0] if s.size else 0.0))) if s[0] > 0 else 0
    N = Vt[rank:].T  # n × d, orthonormal basis of null(J_h)
    if N.shape[1] == 0:
        return np.zeros(0), np.zeros((A.shape[0], 0))
    U, s2, _ = np.linalg.svd(A @ N, full_matrices=False)
    return s2, U


def twist_speed_form(J: Any, simplify: bool = False):
    """Jᵀ J, the matrix of problem 6.2's quadratic form V·V = θ̇ᵀ (Jᵀ J) θ̇ (n×n).

    Exact for SymPy J (``simplify=True``: trig-simplified for display); floats, or (N, n, n), for numbers.

    >>> from kinlib.robots import planar_2r
    >>> twist_speed_form(task_rows(planar_2r().jacobian_geometric(), ["vx", "vy"]), simplify=True)   # ṗ·ṗ
    Matrix([
    [L1**2 + 2*L1*L2*cos(theta2) + L2**2, L2*(L1*cos(theta2) + L2)],
    [           L2*(L1*cos(theta2) + L2),                    L2**2]])
    """
    if not is_symbolic(J):
        A = numeric_jacobian(J)
        return np.swapaxes(A, -1, -2) @ A
    M = exact_jacobian(J)
    G = M.T * M
    return trig_simplify(G) if simplify else G


def twist_speed(J: Any, qdot: Any, simplify: bool = False):
    """V·V = θ̇ᵀ (Jᵀ J) θ̇ = ‖J θ̇‖², the squared size of the twist V = J θ̇ (problem 6.2).

    >>> import numpy as np
    >>> from kinlib.robots import planar_2r
    >>> J = task_rows(planar_2r().jacobian_geometric(), ["vx", "vy"])
    >>> twist_speed(J, [1, 0], simplify=True)   # joint 1 alone: |ṗ|² = |p|², the law of cosines
    L1**2 + 2*L1*L2*cos(theta2) + L2**2
    >>> float(twist_speed(planar_2r(1, 1).jacobian_space([0.0, np.pi / 2]), [1.0, 1.0]))   # V_s = (0, 0, 2, 0, -1, 0)
    5.0
    """
    if not is_symbolic(J, qdot):
        A = numeric_jacobian(J)
        q = numeric_vectors(qdot, "qdot", A.shape[-1], "joint rates θ̇")
        if q.shape[-1:] != (A.shape[-1],):
            raise ValueError(f"qdot must hold {A.shape[-1]} joint rates, got {describe(qdot)}")
        V = np.einsum("...ij,...j->...i", A, q)
        return np.sum(V * V, axis=-1)
    M = exact_jacobian(J)
    q = as_vector(qdot, "qdot", M.cols, True)
    e = (q.T * (M.T * M) * q)[0, 0]
    return trig_simplify(sp.expand(e)) if simplify else e


def strongest_joints(row: Any, tol: float = 1e-9):
    """The joint(s) (1-based) whose column contributes the most to one task row: argmax_i |J[row, i]|.

    ``row``: the n entries of that row at a configuration (problem 4.1: the ṗ_x row). One joint gives an
    int; a tie gives a tuple of ints, e.g. (1, 2). SymPy entries are compared exactly (|a| − |b|
    simplified to 0); numbers within ``tol`` (relative) tie.

    >>> import sympy as sp
    >>> from kinlib.robots import planar_3r
    >>> row = planar_3r(1, 1, 1).jacobian_geometric([sp.pi / 2, 0, 0])[3, :]   # the ṗ_x row, arm along y_s
    >>> row, strongest_joints(row)
    (Matrix([[-3, -2, -1]]), 1)
    >>> strongest_joints([0.5, -0.5, 0.1])   # a tie
    (1, 2)
    """
    if isinstance(row, sp.MatrixBase):
        vals = list(row)
    elif isinstance(row, (str, bytes)) or not hasattr(row, "__len__"):
        raise TypeError(f"row must be the n entries of one row of J, got {describe(row)}")
    else:
        nested_shape(row, "row")  # a ragged list is named as such
        arr = np.asarray(row, dtype=object)
        if arr.ndim == 0 or arr.ndim > 2 or (arr.ndim == 2 and 1 not in arr.shape):
            raise ValueError(f"row must be the n entries of one row of J, got {describe(row)}")
        vals = list(arr.reshape(-1))
    if not vals:
        raise ValueError(f"row must hold at least one entry, got {describe(row)}")
    if is_symbolic(vals):
        vals = [sp.sympify(v) for v in vals]
        if any(not v.is_number or not v.is_real for v in vals):
            raise ValueError(f"row must hold real numbers (evaluate J at a configuration first), got {vals}")
        mags = [sp.Abs(v) for v in vals]
        top = max(mags, key=lambda m: float(m))
        best = [i + 1 for i, m in enumerate(mags) if decide_zero(m - top)]
    else:
        a = np.abs(as_vector(vals, "row", None, False))
        top = float(a.max())
        best = [i + 1 for i, m in enumerate(a) if abs(m - top) <= tol * max(top, 1e-300)]
    return best[0] if len(best) == 1 else tuple(best)


# ----------------------------------------------------------------------------------------------
# measures over many configurations (numbers; the pictures plot these)
# ----------------------------------------------------------------------------------------------
#: The measures :func:`manipulability_values` knows, and their plain-text labels.
MEASURES = {
    "yoshikawa": "√det(J Jᵀ)",
    "det": "det J",
    "inverse_condition": "σ_min / σ_max",
    "min_singular_value": "σ_min",
}


def manipulability_values(J: Any, measure: Any = "yoshikawa") -> np.ndarray:
    """A manipulability measure of numeric task Jacobians J (m×n, or a batch (N, m, n) → N values):

    * ``'yoshikawa'``: w = √det(J Jᵀ) (√det(Jᵀ J) when n < m) = σ1 ⋯ σk, as :func:`manipulability`;
    * ``'det'``: det J (square J only; signed, so its zero contour is the singular set);
    * ``'inverse_condition'``: σ_min/σ_max = :func:`isotropy` (1 = isotropic, 0 = singular);
    * ``'min_singular_value'``: σ_min;
    * a callable taking the batch (N, m, n) and returning N values.

    >>> import numpy as np
    >>> J = np.array([[[2.0, 0.0], [0.0, 0.5]], [[1.0, 1.0], [1.0, 1.0]]])
    >>> manipulability_values(J).round(12).tolist(), manipulability_values(J, "inverse_condition").round(12).tolist()
    ([1.0, 0.0], [0.25, 0.0])
    """
    if callable(measure):
        A = numeric_jacobian(J)
        return np.asarray(measure(A), dtype=float)
    if not isinstance(measure, str) or measure not in MEASURES:
        raise ValueError(f"measure must be one of {', '.join(MEASURES)} or a callable, got {describe(measure)}")
    A = numeric_jacobian(J)
    if measure == "yoshikawa":
        return manipulability(A)
    if measure == "det":
        if A.shape[-1] != A.shape[-2]:
            raise ValueError(
                f"measure='det' needs a square task Jacobian, got rows×joints = {A.shape[-2:]}; "
                f"use measure='yoshikawa' or choose as many rows as joints"
            )
        return np.linalg.det(A)
    s = np.linalg.svd(A, compute_uv=False)
    if measure == "min_singular_value":
        return s[..., -1]
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.where(s[..., 0] > 0, s[..., -1] / s[..., 0], 0.0)


def measure_label(measure: Any, m: int, n: int) -> str:
    """The plain-text name of a measure for an m-row, n-joint task Jacobian (axis labels, legends).

    >>> measure_label("yoshikawa", 2, 3), measure_label("yoshikawa", 3, 2), measure_label("det", 2, 2)
    ('√det(J Jᵀ)', '√det(Jᵀ J)', 'det J')
    """
    if measure == "yoshikawa" and n < m:
        return "√det(Jᵀ J)"
    if isinstance(measure, str):
        return MEASURES.get(measure, measure)
    return getattr(measure, "__name__", "measure")
