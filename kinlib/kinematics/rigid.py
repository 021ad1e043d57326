"""Rigid-body motions: SO(3), SE(3), the skew map, Rodrigues' formula and the adjoint.

Lynch & Park, *Modern Robotics*, chapter 3. Every function takes SymPy input (exact result, a
SymPy Matrix) or numeric input (a NumPy float array).
"""

from __future__ import annotations

import math
import random

import numpy as np
import sympy as sp
from sympy.core.function import AppliedUndef

from .._backend import (
    as_matrix,
    as_scalar,
    as_vector,
    check_real_finite,
    describe,
    exact_number,
    is_symbolic,
    real_array,
)
from ..exact.field import decide_zero

__all__ = [
    "skew",
    "unskew",
    "exp3",
    "rp_to_trans",
    "trans_to_rp",
    "trans_inv",
    "adjoint",
    "check_so3",
    "check_se3",
    "check_unit_vector",
    "cross",
    "log3",
    "UNIT_ROUNDING",
]

_TOL = 1e-6


def cross(a, b):
    """a × b for two 3-vectors (SymPy columns or float arrays); avoids np.cross' overhead.

    >>> import sympy as sp
    >>> cross(sp.Matrix([1, 0, 0]), sp.Matrix([0, 1, 0])).T
    Matrix([[0, 0, 1]])
    >>> cross([1.0, 0.0, 0.0], [0.0, 1.0, 0.0]).tolist()
    [0.0, 0.0, 1.0]
    """
    if isinstance(a, sp.MatrixBase) or isinstance(b, sp.MatrixBase):
        a, b = sp.Matrix(a), sp.Matrix(b)
        return sp.Matrix([a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]])
    return np.array([a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]])


def skew(w):
    """[ω]: the 3×3 skew-symmetric matrix with [ω] x = ω × x.

    >>> skew([1, 2, 3]).tolist()
    [[0.0, -3.0, 2.0], [3.0, 0.0, -1.0], [-2.0, 1.0, 0.0]]
    >>> import sympy as sp
    >>> a, b, c = sp.symbols("a b c", real=True)
    >>> skew(sp.Matrix([a, b, c]))
    Matrix([
    [ 0, -c,  b],
    [ c,  0, -a],
    [-b,  a,  0]])
    """
    w = as_vector(w, "w", 3)
    rows = [[0, -w[2], w[1]], [w[2], 0, -w[0]], [-w[1], w[0], 0]]
    if isinstance(w, sp.MatrixBase):
        return sp.Matrix(rows)
    return np.array(rows, dtype=float)


def unskew(W):
    """ω from [ω]: the inverse of :func:`skew`. ``W`` must be 3×3 and skew-symmetric.

    >>> import sympy as sp
    >>> unskew(sp.Matrix([[0, -3, 2], [3, 0, -1], [-2, 1, 0]])).T
    Matrix([[1, 2, 3]])
    >>> unskew(skew([4.0, 5.0, 6.0])).tolist()
    [4.0, 5.0, 6.0]
    """
    return skew_vector(W, "W")


def skew_vector(W, name: str):
    """:func:`unskew` with the argument's name for the messages (``unbracket`` passes "the upper-left 3×3 of X")."""
    W = as_matrix(W, name, (3, 3))
    symbolic = isinstance(W, sp.MatrixBase)
    bad = (
        (not all(decide_zero(W[i, j] + W[j, i]) for i in range(3) for j in range(i, 3)))
        if symbolic
        else not np.allclose(W, -W.T, atol=_TOL)
    )
    if bad:
        rel = f"{name} = -{name}ᵀ" if name.isidentifier() else "equal to minus its transpose"
        raise ValueError(f"{name} must be skew-symmetric ({rel}), got {W.tolist()}")
    v = [W[2, 1], W[0, 2], W[1, 0]]
    return sp.Matrix(v) if symbolic else np.array(v, dtype=float)


#: Typed decimals (floats made exact, 0.7071067811865476 → 7071067811865476/10¹⁶) that are a unit vector
#: only to rounding are accepted when | |ω|² − 1 | ≤ this: the chain is then exact in the numbers typed.
UNIT_ROUNDING = sp.Rational(1, 10**9)


def check_unit_vector(omega, name: str):
    """Check that ω is a unit vector; return it (SymPy column or float array).

    Numeric: | |ω| − 1 | ≤ 1e-6. Exact: |ω|² = 1 exactly, except for an axis of plain rational numbers
    (typically typed or computed floats made exact: [0.7071067811865476, 0.7071067811865476, 0]) where
    | |ω|² − 1 | ≤ 1e-9 is accepted and the typed decimals are kept as they are (never rounded to a
    "nice" value): results are exact for the numbers typed. Type sp.sqrt(2)/2 for an exactly unit axis.

    >>> import sympy as sp
    >>> check_unit_vector(sp.Matrix([0, sp.sqrt(2) / 2, sp.sqrt(2) / 2]), "omega").T
    Matrix([[0, sqrt(2)/2, sqrt(2)/2]])
    >>> import numpy as np
    >>> check_unit_vector(np.array([1.0, 1.0, 0.0]), "omega")
    Traceback (most recent call last):
        ...
    ValueError: omega must be a unit vector (|ω| = 1), got [1.0, 1.0, 0.0] with |ω| = 1.41421
    """
    symbolic = isinstance(omega, sp.MatrixBase)
    if symbolic:
        n2 = (omega.T * omega)[0]
        if n2 != 1 and not (n2.is_Rational and abs(n2 - 1) <= UNIT_ROUNDING) and not decide_zero(n2 - 1):
            hint = ""
            if n2.is_Rational and abs(n2 - 1) < sp.Rational(1, 1000):
                hint = (
                    f" (|ω|² − 1 = {float(n2 - 1):.3g}; decimals are accepted when |ω|² is 1 to within 1e-9: "
                    f"type more digits, or exact values such as sp.sqrt(2)/2)"
                )
            raise ValueError(
                f"{name} must be a unit vector (|ω| = 1), got {list(omega)} with |ω|² = {sp.simplify(n2)}{hint}"
            )
    else:
        n = float(np.sqrt(omega @ omega))
        if abs(n - 1.0) > _TOL:
            raise ValueError(f"{name} must be a unit vector (|ω| = 1), got {omega.tolist()} with |ω| = {n:.6g}")
    return omega


#: θ − sin θ = θ³/3! − θ⁵/5! + … (Horner, in θ²): the coefficients 1/3!, −1/5!, …, −1/17!; below |θ| = 1
#: the first omitted term is under 1e-16 of the sum
_T_SIN = [(-1) ** k / math.factorial(2 * k + 3) for k in range(8)]


def rodrigues_coefficients(theta: float) -> tuple[float, float, float]:
    """(sin θ, 1 − cos θ, θ − sin θ), each to a few ulps of itself: 1 − cos θ = 2 sin²(θ/2) and, for |θ| < 1,
    θ − sin θ by its series (both differences cancel for small θ: at θ = 1e-8, 1 − cos θ in floats is 0, not
    5e-17, which a screw's large v turns into a visible error).

    >>> [f"{x:.15g}" for x in rodrigues_coefficients(1e-8)[1:]]
    ['5e-17', '1.66666666666667e-25']
    """
    s = math.sin(theta)
    h = math.sin(0.5 * theta)
    if abs(theta) < 1.0:
        t2, acc = theta * theta, 0.0
        for c in reversed(_T_SIN):
            acc = acc * t2 + c
        t_s = acc * t2 * theta
    else:
        t_s = theta - s
    return s, 2.0 * h * h, t_s


def exp3(omega, theta):
    """Rodrigues: e^{[ω]θ} = I + sin θ [ω] + (1 − cos θ) [ω]², for a unit axis ω.

    >>> import sympy as sp
    >>> exp3(sp.Matrix([0, 0, 1]), sp.pi / 2)
    Matrix([
    [0, -1, 0],
    [1,  0, 0],
    [0,  0, 1]])
    >>> import numpy as np
    >>> (np.round(exp3([1, 0, 0], np.pi / 2), 3) + 0.0).tolist()
    [[1.0, 0.0, 0.0], [0.0, 0.0, -1.0], [0.0, 1.0, 0.0]]
    """
    symbolic = is_symbolic(omega, theta)
    omega = check_unit_vector(as_vector(omega, "omega", 3, symbolic), "omega")
    theta = as_scalar(theta, "theta", symbolic)
    W = skew(omega)
    if symbolic:
        return sp.eye(3) + sp.sin(theta) * W + (1 - sp.cos(theta)) * W * W
    s, one_c, _ = rodrigues_coefficients(theta)
    return np.eye(3) + s * W + one_c * (W @ W)


def rp_to_trans(R, p):
    """T = [[R, p], [0, 1]] from a rotation R and a position p.

    >>> import sympy as sp
    >>> rp_to_trans(sp.eye(3), sp.Matrix([1, 2, 3]))
    Matrix([
    [1, 0, 0, 1],
    [0, 1, 0, 2],
    [0, 0, 1, 3],
    [0, 0, 0, 1]])
    """
    symbolic = is_symbolic(R, p)
    R = as_matrix(R, "R", (3, 3), symbolic)
    p = as_vector(p, "p", 3, symbolic)
    if symbolic:
        return sp.Matrix.vstack(sp.Matrix.hstack(R, p), sp.Matrix([[0, 0, 0, 1]]))
    T = np.eye(4)
    T[:3, :3] = R
    T[:3, 3] = p
    return T


def trans_to_rp(T):
    """(R, p) from T = [[R, p], [0, 1]] ∈ SE(3).

    >>> import sympy as sp
    >>> R, p = trans_to_rp(sp.Matrix([[0, -1, 0, 1], [1, 0, 0, 2], [0, 0, 1, 3], [0, 0, 0, 1]]))
    >>> R, p.T
    (Matrix([
    [0, -1, 0],
    [1,  0, 0],
    [0,  0, 1]]), Matrix([[1, 2, 3]]))
    """
    T = check_se3(T, "T")
    if isinstance(T, sp.MatrixBase):
        return T[:3, :3], T[:3, 3]
    return T[:3, :3].copy(), T[:3, 3].copy()


def _numeric_sample(M):
    """M with every free symbol replaced by a fixed pseudo-random value (for cheap property checks)."""
    syms = sorted(M.free_symbols, key=str)
    rng = random.Random(12345)
    vals = {s: sp.Float(rng.uniform(0.3, 1.7)) for s in syms}
    # joint angles written as functions of time, θ_i(t) (problem 1.2), are sampled like symbols
    vals.update({f: sp.Float(rng.uniform(0.3, 1.7)) for f in sorted(M.atoms(AppliedUndef), key=str)})
    try:
        return np.array(M.xreplace(vals).evalf(), dtype=float)
    except (TypeError, ValueError):
        return None


def check_so3(R, name: str = "R"):
    """R as a matrix after checking RᵀR = I and det R = 1 (numerically at sample points when symbolic).

    >>> import sympy as sp
    >>> check_so3(sp.Matrix([[0, -1, 0], [1, 0, 0], [0, 0, 1]])).det()
    1
    >>> import numpy as np
    >>> check_so3(np.diag([2.0, 1.0, 1.0]))  # doctest: +ELLIPSIS
    Traceback (most recent call last):
        ...
    ValueError: R must be a rotation matrix in SO(3) (RᵀR = I, det R = 1), got an array of shape (3, 3) ...
    """
    R = as_matrix(R, name, (3, 3))
    Rn = _numeric_sample(R) if isinstance(R, sp.MatrixBase) else R
    if Rn is None:
        raise ValueError(f"{name} must be a rotation matrix in SO(3); its entries could not be evaluated: {R}")
    if not (np.allclose(Rn.T @ Rn, np.eye(3), atol=_TOL) and abs(np.linalg.det(Rn) - 1) < _TOL):
        raise ValueError(
            f"{name} must be a rotation matrix in SO(3) (RᵀR = I, det R = 1), got {describe(R)} "
            f"with RᵀR − I of size {np.abs(Rn.T @ Rn - np.eye(3)).max():.3g} and det R = {np.linalg.det(Rn):.6g}"
        )
    return R


def check_se3(T, name: str = "T"):
    """T as a matrix after checking it is a homogeneous transform [[R, p], [0, 1]] with R ∈ SO(3).

    >>> import numpy as np
    >>> check_se3(np.eye(4)).shape
    (4, 4)
    >>> check_se3(np.diag([1.0, 1.0, 1.0, 2.0]))
    Traceback (most recent call last):
        ...
    ValueError: T must be a homogeneous transform in SE(3) with last row [0, 0, 0, 1], got last row [0.0, 0.0, 0.0, 2.0]
    """
    T = as_matrix(T, name, None)
    if T.shape != (4, 4):
        raise ValueError(f"{name} must be a 4×4 homogeneous transform in SE(3), got {describe(T)}")
    bottom = list(T[3, :]) if isinstance(T, sp.MatrixBase) else T[3, :].tolist()
    if isinstance(T, sp.MatrixBase):
        ok = all(decide_zero(b - e) for b, e in zip(bottom, (0, 0, 0, 1)))
    else:
        ok = np.allclose(bottom, (0, 0, 0, 1), atol=_TOL)
    if not ok:
        raise ValueError(
            f"{name} must be a homogeneous transform in SE(3) with last row [0, 0, 0, 1], got last row {bottom}"
        )
    check_so3(T[:3, :3], f"the rotation part of {name}")
    return T


def trans_inv(T):
    """T⁻¹ = [[Rᵀ, −Rᵀp], [0, 1]].

    >>> import sympy as sp
    >>> trans_inv(sp.Matrix([[0, -1, 0, 1], [1, 0, 0, 2], [0, 0, 1, 3], [0, 0, 0, 1]]))
    Matrix([
    [ 0, 1, 0, -2],
    [-1, 0, 0,  1],
    [ 0, 0, 1, -3],
    [ 0, 0, 0,  1]])
    """
    T = check_se3(T, "T")
    R, p = T[:3, :3], T[:3, 3]
    if isinstance(T, sp.MatrixBase):
        return rp_to_trans(R.T, -R.T * p)
    out = np.eye(4)
    out[:3, :3] = R.T
    out[:3, 3] = -R.T @ p
    return out


def adjoint(T):
    """Ad_T = [[R, 0], [[p]R, R]] (6×6), acting on twists [ω; v].

    >>> import sympy as sp
    >>> T = sp.Matrix([[1, 0, 0, 1], [0, 1, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1]])   # a shift by 1 along x
    >>> adjoint(T)
    Matrix([
    [1, 0,  0, 0, 0, 0],
    [0, 1,  0, 0, 0, 0],
    [0, 0,  1, 0, 0, 0],
    [0, 0,  0, 1, 0, 0],
    [0, 0, -1, 0, 1, 0],
    [0, 1,  0, 0, 0, 1]])
    >>> (adjoint(T) * sp.Matrix([0, 0, 1, 0, 0, 0])).T   # spin about z_b seen from {s}: v = −ω × p
    Matrix([[0, 0, 1, 0, -1, 0]])
    """
    T = check_se3(T, "T")
    R, p = T[:3, :3], T[:3, 3]
    if isinstance(T, sp.MatrixBase):
        return sp.Matrix.vstack(sp.Matrix.hstack(R, sp.zeros(3)), sp.Matrix.hstack(skew(p) * R, R))
    out = np.zeros((6, 6))
    out[:3, :3] = R
    out[3:, 3:] = R
    out[3:, :3] = skew(p) @ R
    return out


# ----------------------------------------------------------------------------------------------
# The matrix logarithm of SO(3) (issue 11, item 7), and two helpers it shares with
# kinlib.screws.log6 and kinlib.velocity (public names so those modules may import them).
# ----------------------------------------------------------------------------------------------
def _log3_numeric(A: np.ndarray):
    """(vector ω̂θ, axis ω̂, angle θ) for a batch (N, 3, 3) of rotation matrices."""
    ax = 0.5 * np.stack([A[:, 2, 1] - A[:, 1, 2], A[:, 0, 2] - A[:, 2, 0], A[:, 1, 0] - A[:, 0, 1]], axis=-1)
    s = np.linalg.norm(ax, axis=-1)  # = sin θ
    c = np.clip((np.trace(A, axis1=1, axis2=2) - 1.0) / 2.0, -1.0, 1.0)  # = cos θ
    theta = np.arctan2(s, c)  # θ ∈ [0, π], accurate near 0 and π
    vec = ax / np.sinc(theta / np.pi)[:, None]  # sin θ ω̂ · θ / sin θ  (θ ≤ π/2 branch)
    big = c < 0  # θ > π/2: the axis from the symmetric part
    if np.any(big):
        Ab = A[big]
        B = 0.5 * (Ab + np.swapaxes(Ab, 1, 2)) - c[big][:, None, None] * np.eye(3)  # (1 − cos θ) ω̂ω̂ᵀ
        k = np.argmax(np.diagonal(B, axis1=1, axis2=2), axis=-1)
        col = B[np.arange(len(k)), :, k]
        w = col / np.linalg.norm(col, axis=-1)[:, None]  # ω̂ up to sign, ω̂_k > 0
        d = np.einsum("ij,ij->i", w, ax[big])  # = sin θ (ω̂·ω̂) with the right sign
        # d's rounding error is below eps (each entry of A within eps/2 of the rotation's): its sign is
        # the branch whenever |d| > 2 eps (so π − 1e-15 about −z gives −z). Below that, θ = π to rounding and
        # either sign is a logarithm (|e^{[ω̂]θ} − R| ≤ 2|d|): Modern Robotics' choice, the first of
        # ω̂_3, ω̂_2, ω̂_1 with 1 + r_kk = 2ω̂_k² not near 0 (|·| ≥ 1e-6, its NearZero) is positive
        diag1 = 1.0 + np.diagonal(Ab, axis1=1, axis2=2)
        kk = np.where(diag1[:, 2] >= 1e-6, 2, np.where(diag1[:, 1] >= 1e-6, 1, 0))
        mr_sign = np.sign(w[np.arange(len(kk)), kk])
        tiny = 2 * np.finfo(float).eps
        sign = np.where(d > tiny, 1.0, np.where(d < -tiny, -1.0, np.where(mr_sign == 0, 1.0, mr_sign)))
        vec[big] = (sign * theta[big])[:, None] * w
    axis = np.where((theta > 0)[:, None], vec / np.where(theta > 0, theta, 1.0)[:, None], [0.0, 0.0, 1.0])
    return vec, axis, theta


def _log3_exact(R: sp.Matrix):
    """(ω̂, θ, exactly_zero) for an exact SymPy rotation matrix; see :func:`log3`."""
    from ..exact.display import is_identically_zero, simplify_for_display

    for e in R:
        check_real_finite(e, "R")
    if not R.free_symbols:
        R = R.applyfunc(lambda e: exact_number(e, "R"))
        D = R.T * R - sp.eye(3)
        for i in range(3):
            for j in range(i, 3):
                if not decide_zero(D[i, j], f"(RᵀR − I)[{i}, {j}]"):
                    raise ValueError(
                        f"R must be exactly a rotation matrix (RᵀR = I) for an exact logarithm, got "
                        f"{R.tolist()} with (RᵀR − I)[{i}, {j}] = {D[i, j]} ≠ 0; "
                        f"give exact entries (sp.sqrt(2)/2, not 0.7071) or a NumPy array for a numeric log"
                    )
        if not decide_zero(R.det() - 1, "det R − 1"):
            raise ValueError(f"R must be a rotation matrix with det R = 1, got det R = {sp.simplify(R.det())}")
        simp = sp.radsimp
        c = simp(sp.expand((R.trace() - 1) / 2))
        if decide_zero(c - 1, "cos θ − 1"):
            return sp.Matrix([0, 0, 1]), sp.S.Zero, True
        if decide_zero(c + 1, "cos θ + 1"):
            # θ = π, Modern Robotics' three branches: ω̂ = (r_k + e_k)/√(2(1 + r_kk)) for the first k = 3, 2, 1
            # with 1 + r_kk ≠ 0 (r_k the k-th column of R)
            for k in (2, 1, 0):
                d = 1 + R[k, k]
                if not decide_zero(d, f"1 + r{k + 1}{k + 1}"):
                    w = (R[:, k] + sp.eye(3)[:, k]) / sp.sqrt(2 * d)
                    return w.applyfunc(lambda e: sp.radsimp(sp.simplify(e))), sp.pi, False
            raise AssertionError("unreachable: a rotation by π has some 1 + r_kk = 2ω̂_k² ≠ 0")  # pragma: no cover
        theta = _acos_exact(c)
        s = sp.sqrt(simp(1 - c**2))  # sin θ > 0 for 0 < θ < π
        w = sp.Matrix([R[2, 1] - R[1, 2], R[0, 2] - R[2, 0], R[1, 0] - R[0, 1]]) / (2 * s)
        return w.applyfunc(lambda e: sp.radsimp(sp.simplify(e))), theta, False
    # free symbols: the closed form valid for 0 < θ < π (sin θ ≠ 0)
    if is_identically_zero(R - sp.eye(3)):
        return sp.Matrix([0, 0, 1]), sp.S.Zero, True
    c = simplify_for_display((R.trace() - 1) / 2)
    s = sp.sqrt(simplify_for_display(1 - c**2))
    w = simplify_for_display(sp.Matrix([R[2, 1] - R[1, 2], R[0, 2] - R[2, 0], R[1, 0] - R[0, 1]]) / 2) / s
    return w, sp.acos(c), False


def _acos_exact(c: sp.Expr) -> sp.Expr:
    """acos c for a constant c, as a rational multiple of π when it is one (π/12 for (√2 + √6)/4).

    The candidate p/q (q ≤ 360, from the continued fraction of acos(c)/π at 40 digits) is accepted only after
    cos(pπ/q) − c = 0 is *proved* (:func:`decide_zero`); otherwise acos(c) stays as it is. Exact either way.
    """
    import fractions

    theta = sp.acos(c)
    if not isinstance(theta, sp.acos):
        return theta
    try:
        x = fractions.Fraction(str(sp.N(theta / sp.pi, 40))).limit_denominator(360)
        cand = sp.Rational(x.numerator, x.denominator)
        if 0 < cand < 1 and decide_zero(sp.cos(cand * sp.pi) - c, "cos θ − c"):
            return cand * sp.pi
    except (ValueError, TypeError):
        pass
    return theta


_LOG3_FORMS = ("matrix", "vector", "axis_angle")


def _check_form(form, forms, name="form"):
    if not isinstance(form, str) or form not in forms:
        raise ValueError(f"{name} must be one of {', '.join(map(repr, forms))}, got {describe(form)}")


def log3(R, form: str = "matrix"):
    """The matrix logarithm of SO(3): [ω̂]θ ∈ so(3) with e^{[ω̂]θ} = R, θ ∈ [0, π] (Modern Robotics' MatrixLog3).

    Lynch & Park, Algorithm 3.1 (section 3.2.3.3):

    * R = I:          θ = 0 (ω̂ undefined; ``form="axis_angle"`` returns the convention ω̂ = ẑ = (0, 0, 1));
    * tr R = −1:      θ = π, ω̂ = (r_k + e_k)/√(2(1 + r_kk)) for the first k = 3, 2, 1 with 1 + r_kk ≠ 0
                      (−ω̂ is as good a logarithm: this is the book's choice);
    * otherwise:      θ = arccos((tr R − 1)/2) ∈ (0, π),  [ω̂] = (R − Rᵀ)/(2 sin θ).

    ``form``: "matrix" → [ω̂]θ (3×3); "vector" → ω̂θ (the exponential coordinates, a 3-vector);
    "axis_angle" → (ω̂, θ). The inverse of :func:`exp3`: ``exp3(*log3(R, "axis_angle")) == R``.

    Exact (SymPy R without symbols): RᵀR = I and det R = 1 are proved first (else ValueError); θ = 0 and θ = π
    are decided exactly; θ = acos(…) stays exact (π/4 for √2/2 entries, 2π/7 for cos(2π/7) ...).
    SymPy R with free symbols: the closed form θ = acos((tr R − 1)/2), [ω̂]θ = θ (R − Rᵀ)/(2 sin θ), valid where
    0 < θ < π (substitute values first for θ = 0 or π); R = I identically is recognised.
    Numbers: floats, (3, 3) or a batch (N, 3, 3) (→ (N, 3, 3), (N, 3), or ((N, 3), (N,))); θ = atan2(|axial|, cos θ)
    (accurate near 0 and π); for θ > π/2 the axis comes from the symmetric part (R + Rᵀ)/2 − cos θ I = (1 − cos θ)ω̂ω̂ᵀ.
    R must be orthogonal with det 1 to 1e-6 (else ValueError).

    >>> import sympy as sp
    >>> h = sp.sqrt(2) / 2
    >>> log3(sp.Matrix([[h, -h, 0], [h, h, 0], [0, 0, 1]]))
    Matrix([
    [   0, -pi/4, 0],
    [pi/4,     0, 0],
    [   0,     0, 0]])
    >>> log3(sp.diag(1, -1, -1), form="axis_angle")
    (Matrix([
    [1],
    [0],
    [0]]), pi)
    >>> import numpy as np
    >>> np.round(log3(np.diag([1.0, -1.0, -1.0]), form="vector"), 6)
    array([3.141593, 0.      , 0.      ])
    """
    _check_form(form, _LOG3_FORMS)
    if is_symbolic(R):
        Rm = check_so3(R, "R")
        w, theta, zero = _log3_exact(Rm)
        if form == "axis_angle":
            return w, theta
        vec = sp.zeros(3, 1) if zero else w * theta
        return vec if form == "vector" else skew(vec)
    A = real_array(R, "R", "a 3×3 rotation matrix or a batch (N, 3, 3) of them")
    if A.shape[-2:] != (3, 3) or A.ndim not in (2, 3):
        raise ValueError(f"R must be a 3×3 rotation matrix or a batch (N, 3, 3) of them, got {describe(A)}")
    single = A.ndim == 2
    B = A[None] if single else A
    err = np.abs(np.swapaxes(B, 1, 2) @ B - np.eye(3)).max(axis=(1, 2)) if len(B) else np.zeros(0)
    det = np.linalg.det(B) if len(B) else np.zeros(0)
    bad = np.flatnonzero((err > _TOL) | (np.abs(det - 1) > _TOL))
    if bad.size:
        i = bad[0]
        where = "" if single else f"[{i}]"
        raise ValueError(
            f"R{where} must be a rotation matrix in SO(3) (RᵀR = I, det R = 1 to {_TOL:g}), got RᵀR − I "
            f"of size {err[i]:.3g} and det R = {det[i]:.6g}"
        )
    vec, axis, theta = _log3_numeric(B)
    if single:
        vec, axis, theta = vec[0], axis[0], float(theta[0])
    if form == "axis_angle":
        return axis, theta
    if form == "vector":
        return vec + 0.0
    W = np.zeros(vec.shape[:-1] + (3, 3))
    W[..., 0, 1], W[..., 0, 2], W[..., 1, 2] = -vec[..., 2], vec[..., 1], -vec[..., 0]
    W[..., 1, 0], W[..., 2, 0], W[..., 2, 1] = vec[..., 2], -vec[..., 1], vec[..., 0]
    return W + 0.0
