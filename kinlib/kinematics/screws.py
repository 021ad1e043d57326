"""Screw axes and twists [ω; v] (angular first) and their exponential.

Lynch & Park, *Modern Robotics*, chapter 3.3. A screw axis S = [ω; v] has either |ω| = 1
(revolute or helical, v = −ω × q + h ω) or ω = 0 and |v| = 1 (prismatic).
"""

from __future__ import annotations

import numpy as np
import sympy as sp

from .._backend import as_matrix, as_scalar, as_vector, check_real_finite, describe, exact_number, is_symbolic
from ..exact.display import is_identically_zero
from ..exact.field import decide_zero
from .rigid import check_se3, check_unit_vector, cross, log3, rodrigues_coefficients, skew, skew_vector

__all__ = [
    "screw_revolute",
    "screw_prismatic",
    "screw_axis",
    "bracket",
    "unbracket",
    "exp6",
    "screw_kind",
    "exp6_unchecked",
    "log6",
]


def screw_revolute(omega, q):
    """S = [ω; −ω × q]: a revolute joint about the unit axis ω through the point q.

    >>> import sympy as sp
    >>> screw_revolute(sp.Matrix([0, 0, 1]), sp.Matrix([1, 0, 0])).T
    Matrix([[0, 0, 1, 0, -1, 0]])
    >>> screw_revolute([0, 0, 1], [1, 0, 0]).tolist()
    [0.0, 0.0, 1.0, 0.0, -1.0, 0.0]
    """
    symbolic = is_symbolic(omega, q)
    w = check_unit_vector(as_vector(omega, "omega", 3, symbolic, real_symbols=True), "omega")
    q = as_vector(q, "q", 3, symbolic, real_symbols=True)
    v = -cross(w, q)
    return sp.Matrix.vstack(w, v) if symbolic else np.concatenate([w, v + 0.0])  # + 0.0: no −0.0 entries


def screw_prismatic(v):
    """S = [0; v]: a prismatic joint sliding along the unit direction v.

    >>> screw_prismatic([0, 1, 0]).tolist()
    [0.0, 0.0, 0.0, 0.0, 1.0, 0.0]
    """
    symbolic = is_symbolic(v)
    v = check_unit_vector(as_vector(v, "v", 3, symbolic, real_symbols=True), "v")
    return sp.Matrix.vstack(sp.zeros(3, 1), v) if symbolic else np.concatenate([np.zeros(3), v])


def screw_axis(q, s, h):
    """S = [s; −s × q + h s]: the screw axis through q along the unit direction s with pitch h.

    >>> import sympy as sp
    >>> screw_axis(sp.Matrix([1, 0, 0]), sp.Matrix([0, 0, 1]), sp.Rational(1, 2)).T
    Matrix([[0, 0, 1, 0, -1, 1/2]])
    """
    symbolic = is_symbolic(q, s, h)
    s = check_unit_vector(as_vector(s, "s", 3, symbolic, real_symbols=True), "s")
    q = as_vector(q, "q", 3, symbolic, real_symbols=True)
    h = as_scalar(h, "h", symbolic)
    v = -cross(s, q) + h * s
    return sp.Matrix.vstack(s, v) if symbolic else np.concatenate([s, v + 0.0])


def bracket(V):
    """[V] = [[[ω], v], [0, 0]] ∈ se(3) for a twist V = [ω; v].

    >>> import sympy as sp
    >>> bracket(sp.Matrix([0, 0, 1, 1, 2, 3]))
    Matrix([
    [0, -1, 0, 1],
    [1,  0, 0, 2],
    [0,  0, 0, 3],
    [0,  0, 0, 0]])
    """
    V = as_vector(V, "V", 6)
    if isinstance(V, sp.MatrixBase):
        return sp.Matrix.vstack(sp.Matrix.hstack(skew(V[:3, 0]), V[3:, 0]), sp.zeros(1, 4))
    out = np.zeros((4, 4))
    out[:3, :3] = skew(V[:3])
    out[:3, 3] = V[3:]
    return out


def unbracket(X):
    """V = [ω; v] from [V] ∈ se(3).

    >>> import sympy as sp
    >>> unbracket(sp.Matrix([[0, -1, 0, 1], [1, 0, 0, 2], [0, 0, 0, 3], [0, 0, 0, 0]])).T
    Matrix([[0, 0, 1, 1, 2, 3]])
    """
    X = as_matrix(X, "X", (4, 4))
    w = skew_vector(X[:3, :3], "X's upper-left 3×3 block")
    if isinstance(X, sp.MatrixBase):
        if not all(decide_zero(e) for e in X[3, :]):
            raise ValueError(f"X must be in se(3) with last row 0, got last row {list(X[3, :])}")
        return sp.Matrix.vstack(w, X[:3, 3])
    if not np.allclose(X[3], 0):
        raise ValueError(f"X must be in se(3) with last row 0, got last row {X[3].tolist()}")
    return np.concatenate([w, X[:3, 3]])


def screw_kind(S, name: str) -> str:
    """'R' when |ω| = 1, 'P' when ω = 0 and |v| = 1; anything else is not a screw axis.

    >>> import sympy as sp
    >>> screw_kind(sp.Matrix([0, 0, 1, 0, -1, 0]), "S"), screw_kind(sp.Matrix([0, 0, 0, 0, 1, 0]), "S")
    ('R', 'P')
    """
    w, v = S[:3], S[3:]
    if isinstance(S, sp.MatrixBase):
        if all(decide_zero(e) for e in w):
            check_unit_vector(sp.Matrix(v), f"the linear part v of {name} (a prismatic axis, ω = 0)")
            return "P"
        check_unit_vector(sp.Matrix(w), f"the angular part ω of {name}")
        return "R"
    if not np.any(np.abs(w) > 1e-12):
        check_unit_vector(np.asarray(v), f"the linear part v of {name} (a prismatic axis, ω = 0)")
        return "P"
    check_unit_vector(np.asarray(w), f"the angular part ω of {name}")
    return "R"


def exp6(S, theta):
    """e^{[S]θ} ∈ SE(3) for a screw axis S = [ω; v] and a joint value θ.

    |ω| = 1: [[e^{[ω]θ}, (Iθ + (1 − cos θ)[ω] + (θ − sin θ)[ω]²) v], [0, 1]];
    ω = 0:   [[I, v θ], [0, 1]].

    >>> import sympy as sp
    >>> exp6(sp.Matrix([0, 0, 1, 0, -1, 0]), sp.pi / 2)   # a quarter turn about z through (1, 0, 0)
    Matrix([
    [0, -1, 0,  1],
    [1,  0, 0, -1],
    [0,  0, 1,  0],
    [0,  0, 0,  1]])
    >>> exp6([0, 0, 0, 1, 0, 0], 2.0).tolist()   # prismatic: a slide by 2 along x
    [[1.0, 0.0, 0.0, 2.0], [0.0, 1.0, 0.0, 0.0], [0.0, 0.0, 1.0, 0.0], [0.0, 0.0, 0.0, 1.0]]
    """
    symbolic = is_symbolic(S, theta)
    S = as_vector(S, "S", 6, symbolic, real_symbols=True)
    theta = as_scalar(theta, "theta", symbolic)
    kind = screw_kind(S, "S")
    return exp6_unchecked(S, theta, kind, symbolic)


def exp6_unchecked(S, theta, kind: str, symbolic: bool):
    """exp6 without the checks (S already a validated column/array).

    >>> import numpy as np
    >>> (np.round(exp6_unchecked(np.array([0.0, 0, 1, 0, -1, 0]), np.pi / 2, "R", False), 3) + 0.0).tolist()
    [[0.0, -1.0, 0.0, 1.0], [1.0, 0.0, 0.0, -1.0], [0.0, 0.0, 1.0, 0.0], [0.0, 0.0, 0.0, 1.0]]
    """
    if symbolic:
        w, v = S[:3, 0], S[3:, 0]
        if kind == "P":
            R, p = sp.eye(3), v * theta
        else:
            W = skew(w)
            W2 = W * W
            s, c = sp.sin(theta), sp.cos(theta)
            R = sp.eye(3) + s * W + (1 - c) * W2
            p = (sp.eye(3) * theta + (1 - c) * W + (theta - s) * W2) * v
        return sp.Matrix.vstack(sp.Matrix.hstack(R, p), sp.Matrix([[0, 0, 0, 1]]))
    w, v = S[:3], S[3:]
    T = np.eye(4)
    if kind == "P":
        T[:3, 3] = v * theta
        return T
    W = np.array([[0.0, -w[2], w[1]], [w[2], 0.0, -w[0]], [-w[1], w[0], 0.0]])
    W2 = W @ W
    s, one_c, t_s = rodrigues_coefficients(float(theta))
    T[:3, :3] += s * W + one_c * W2
    T[:3, 3] = (theta * v) + one_c * (W @ v) + t_s * (W2 @ v)
    return T


# ----------------------------------------------------------------------------------------------
# The matrix logarithm of SE(3) (issue 11, item 7)
# ----------------------------------------------------------------------------------------------
_LOG6_FORMS = ("matrix", "vector", "screw_angle")


def _log6_exact(T: sp.Matrix):
    """(ω̂, θ_rot, vθ, p) for an exact SymPy transform; θ_rot = 0 exactly when R = I."""
    for e in T:
        check_real_finite(e, "T")
    if not T.free_symbols:
        T = T.applyfunc(lambda e: exact_number(e, "T"))
        for j, want in enumerate((0, 0, 0, 1)):
            if not decide_zero(T[3, j] - want, f"T[3, {j}] − {want}"):
                raise ValueError(
                    f"T must be a homogeneous transform with last row [0, 0, 0, 1], got last row {list(T[3, :])}"
                )
    else:
        T = check_se3(T, "T")
    R, p = T[:3, :3], T[:3, 3]
    try:
        w, theta = log3(R, form="axis_angle")
    except ValueError as err:
        raise ValueError(f"the rotation part of T: {err}") from None
    if theta == 0:
        return w, theta, p, p
    W = skew(w)
    c, s = sp.cos(theta), sp.sin(theta)  # cos(acos x) = x and sin(acos x) = √(1 − x²): exact
    k = 1 - theta / 2 * s / (1 - c)  # 1 − (θ/2) cot(θ/2); cot(θ/2) = sin θ/(1 − cos θ), 0 at θ = π
    vt = (sp.eye(3) - theta / 2 * W + k * W * W) * p
    simp = (lambda e: sp.radsimp(sp.simplify(e))) if not T.free_symbols else sp.factor_terms
    return w, theta, vt.applyfunc(simp), p


def _pure_translation_zero(p) -> bool:
    if isinstance(p, sp.MatrixBase):
        return is_identically_zero(p)
    return not np.any(p)


def log6(T, form: str = "matrix"):
    """The matrix logarithm of SE(3): [S]θ ∈ se(3) with e^{[S]θ} = T (Modern Robotics' MatrixLog6).

    Lynch & Park, Algorithm 3.2 (section 3.3.3.2), for T = [[R, p], [0, 1]]:

    * R = I:  ω = 0, v = p/|p|, θ = |p| (a pure translation; T = I gives θ = 0);
    * else:   [ω̂]θ = log3(R) (θ ∈ (0, π]) and
              vθ = G⁻¹(θ) p θ = (I − ½[ω̂]θ + (1 − (θ/2) cot(θ/2)) [ω̂]²) p,
              i.e. G⁻¹(θ) = I/θ − [ω̂]/2 + (1/θ − ½ cot(θ/2)) [ω̂]².

    ``form``: "matrix" → [S]θ = [[[ω̂]θ, vθ], [0, 0]] (4×4); "vector" → Sθ = [ω̂θ; vθ] (angular first);
    "screw_angle" → (S, θ) with S = [ω̂; v] (|ω̂| = 1) or [0; v] (|v| = 1), θ ≥ 0 (T = I: the convention
    S = [0, 0, 1, 0, 0, 0], θ = 0). The inverse of :func:`exp6`: ``exp6(*log6(T, "screw_angle")) == T``.

    Exact for SymPy T (R's logarithm as in :func:`kinlib.rigid.log3`, cot(θ/2) = sin θ/(1 − cos θ) exact); with
    free symbols the closed form holds where 0 < θ < π. Numbers: floats, (4, 4) or a batch (N, 4, 4)
    (1 − (θ/2)cot(θ/2) by its series θ²/12 + θ⁴/720 + θ⁶/30240 below θ = 0.01).

    >>> import sympy as sp
    >>> T = sp.Matrix([[1, 0, 0, 0], [0, 0, -1, 0], [0, 1, 0, 3], [0, 0, 0, 1]])
    >>> log6(T)
    Matrix([
    [0,    0,     0,      0],
    [0,    0, -pi/2, 3*pi/4],
    [0, pi/2,     0, 3*pi/4],
    [0,    0,     0,      0]])
    >>> log6(sp.Matrix([[1, 0, 0, 3], [0, 1, 0, 4], [0, 0, 1, 0], [0, 0, 0, 1]]), form="screw_angle")[1]
    5
    """
    from .._backend import real_array
    from .rigid import log3

    if not isinstance(form, str) or form not in _LOG6_FORMS:
        raise ValueError(f"form must be one of {', '.join(map(repr, _LOG6_FORMS))}, got {describe(form)}")
    if is_symbolic(T):
        Tm = as_matrix(T, "T", (4, 4), True)
        w, theta, vt, p = _log6_exact(Tm)
        if form == "screw_angle":
            if theta != 0:
                return sp.Matrix.vstack(
                    w, (vt / theta).applyfunc(sp.radsimp if not Tm.free_symbols else sp.factor_terms)
                ), theta
            if _pure_translation_zero(p):
                return sp.Matrix([0, 0, 1, 0, 0, 0]), sp.S.Zero
            d = sp.sqrt(sp.expand((p.T * p)[0, 0]))
            return sp.Matrix.vstack(sp.zeros(3, 1), p / d), d
        wt = w * theta if theta != 0 else sp.zeros(3, 1)
        if form == "vector":
            return sp.Matrix.vstack(wt, vt)
        return sp.Matrix.vstack(sp.Matrix.hstack(skew(wt), vt), sp.zeros(1, 4))
    A = real_array(T, "T", "a 4×4 transform or a batch (N, 4, 4) of them")
    if A.shape[-2:] != (4, 4) or A.ndim not in (2, 3):
        raise ValueError(f"T must be a 4×4 homogeneous transform or a batch (N, 4, 4) of them, got {describe(A)}")
    single = A.ndim == 2
    B = A[None] if single else A
    bot = np.abs(B[:, 3, :] - [0.0, 0.0, 0.0, 1.0]).max(axis=-1) if len(B) else np.zeros(0)
    if np.any(bot > 1e-6):
        i = int(np.flatnonzero(bot > 1e-6)[0])
        raise ValueError(
            f"T{'' if single else f'[{i}]'} must be a homogeneous transform with last row [0, 0, 0, 1], "
            f"got last row {B[i, 3].tolist()}"
        )
    try:
        w, theta = log3(B[:, :3, :3], form="axis_angle")
    except ValueError as err:
        raise ValueError(f"the rotation part of T: {err}") from None
    p = B[:, :3, 3]
    with np.errstate(divide="ignore", invalid="ignore"):
        half = theta / 2
        k = np.where(
            theta < 1e-2,
            theta**2 / 12 + theta**4 / 720 + theta**6 / 30240,
            1.0 - half / np.tan(np.where(theta < 1e-2, 1.0, half)),
        )
    wp = np.cross(w, p)
    vt = p - (half[:, None] * wp) + k[:, None] * np.cross(w, wp)
    wt = w * theta[:, None]
    if form == "screw_angle":
        pn = np.linalg.norm(p, axis=-1)
        rot = theta > 0
        tr = ~rot & (pn > 0)
        S = np.zeros((len(B), 6))
        S[:, 2] = 1.0
        S[rot, :3] = w[rot]
        S[rot, 3:] = vt[rot] / theta[rot][:, None]
        S[tr, 2] = 0.0
        S[tr, 3:] = p[tr] / pn[tr][:, None]
        ang = np.where(rot, theta, pn)
        return (S[0] + 0.0, float(ang[0])) if single else (S + 0.0, ang)
    V = np.concatenate([wt, vt], axis=-1) + 0.0
    if form == "vector":
        return V[0] if single else V
    X = np.zeros((len(B), 4, 4))
    X[:, 0, 1], X[:, 0, 2], X[:, 1, 2] = -wt[:, 2], wt[:, 1], -wt[:, 0]
    X[:, 1, 0], X[:, 2, 0], X[:, 2, 1] = wt[:, 2], -wt[:, 1], wt[:, 0]
    X[:, :3, 3] = vt
    return (X[0] if single else X) + 0.0
