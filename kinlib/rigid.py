"""Rigid-body motions: SO(3), SE(3), the skew map, Rodrigues' formula and the adjoint.

Lynch & Park, *Modern Robotics*, chapter 3. Every function takes SymPy input (exact result, a
SymPy Matrix) or numeric input (a NumPy float array).
"""
from __future__ import annotations

import random

import numpy as np
import sympy as sp
from sympy.core.function import AppliedUndef

from ._backend import as_matrix, as_vector, describe, is_symbolic, is_zero

__all__ = [
    "skew", "unskew", "exp3", "rp_to_trans", "trans_to_rp", "trans_inv", "adjoint",
    "check_so3", "check_se3", "cross",
]

_TOL = 1e-6


def cross(a, b):
    """a × b for two 3-vectors (SymPy columns or float arrays); avoids np.cross' overhead."""
    if isinstance(a, sp.MatrixBase) or isinstance(b, sp.MatrixBase):
        a, b = sp.Matrix(a), sp.Matrix(b)
        return sp.Matrix([a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]])
    return np.array([a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]])


def skew(w):
    """[ω]: the 3×3 skew-symmetric matrix with [ω] x = ω × x."""
    w = as_vector(w, "w", 3)
    rows = [[0, -w[2], w[1]], [w[2], 0, -w[0]], [-w[1], w[0], 0]]
    if isinstance(w, sp.MatrixBase):
        return sp.Matrix(rows)
    return np.array(rows, dtype=float)


def unskew(W):
    """ω from [ω]: the inverse of :func:`skew`. ``W`` must be 3×3 and skew-symmetric."""
    W = as_matrix(W, "W", (3, 3))
    symbolic = isinstance(W, sp.MatrixBase)
    bad = (not all(is_zero(W[i, j] + W[j, i]) for i in range(3) for j in range(i, 3))) if symbolic \
        else not np.allclose(W, -W.T, atol=_TOL)
    if bad:
        raise ValueError(f"W must be skew-symmetric (W = -Wᵀ), got {W.tolist()}")
    v = [W[2, 1], W[0, 2], W[1, 0]]
    return sp.Matrix(v) if symbolic else np.array(v, dtype=float)


def _unit_axis(omega, name: str):
    """Check that ω is a unit vector; return it (SymPy column or float array)."""
    symbolic = isinstance(omega, sp.MatrixBase)
    if symbolic:
        n2 = (omega.T * omega)[0]
        if not is_zero(n2 - 1):
            raise ValueError(f"{name} must be a unit vector (|ω| = 1), got {list(omega)} with |ω|² = {sp.simplify(n2)}")
    else:
        n = float(np.sqrt(omega @ omega))
        if abs(n - 1.0) > _TOL:
            raise ValueError(f"{name} must be a unit vector (|ω| = 1), got {omega.tolist()} with |ω| = {n:.6g}")
    return omega


def exp3(omega, theta):
    """Rodrigues: e^{[ω]θ} = I + sin θ [ω] + (1 − cos θ) [ω]², for a unit axis ω."""
    symbolic = is_symbolic(omega, theta)
    omega = _unit_axis(as_vector(omega, "omega", 3, symbolic), "omega")
    theta = _scalar(theta, "theta", symbolic)
    W = skew(omega)
    if symbolic:
        return sp.eye(3) + sp.sin(theta) * W + (1 - sp.cos(theta)) * W * W
    return np.eye(3) + np.sin(theta) * W + (1.0 - np.cos(theta)) * (W @ W)


def _scalar(x, name: str, symbolic: bool):
    if isinstance(x, (str, bytes)) or isinstance(x, bool):
        raise TypeError(f"{name} must be a number or a SymPy expression, got {describe(x)}")
    if symbolic:
        try:
            e = sp.sympify(x, strict=True)
        except (sp.SympifyError, TypeError):
            raise TypeError(f"{name} must be a number or a SymPy expression, got {describe(x)}") from None
        if not isinstance(e, sp.Expr):
            raise TypeError(f"{name} must be a number or a SymPy expression, got {describe(x)}")
        return e
    try:
        return float(x)
    except (TypeError, ValueError):
        raise TypeError(f"{name} must be a number or a SymPy expression, got {describe(x)}") from None


def rp_to_trans(R, p):
    """T = [[R, p], [0, 1]] from a rotation R and a position p."""
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
    """(R, p) from T = [[R, p], [0, 1]] ∈ SE(3)."""
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
    """R as a matrix after checking RᵀR = I and det R = 1 (numerically at sample points when symbolic)."""
    R = as_matrix(R, name, (3, 3))
    Rn = _numeric_sample(R) if isinstance(R, sp.MatrixBase) else R
    if Rn is None:
        raise ValueError(f"{name} must be a rotation matrix in SO(3); its entries could not be evaluated: {R}")
    if not (np.allclose(Rn.T @ Rn, np.eye(3), atol=_TOL) and abs(np.linalg.det(Rn) - 1) < _TOL):
        raise ValueError(f"{name} must be a rotation matrix in SO(3) (RᵀR = I, det R = 1), got {describe(R)} "
                         f"with RᵀR − I of size {np.abs(Rn.T @ Rn - np.eye(3)).max():.3g} and det R = {np.linalg.det(Rn):.6g}")
    return R


def check_se3(T, name: str = "T"):
    """T as a matrix after checking it is a homogeneous transform [[R, p], [0, 1]] with R ∈ SO(3)."""
    T = as_matrix(T, name, None)
    if T.shape != (4, 4):
        raise ValueError(f"{name} must be a 4×4 homogeneous transform in SE(3), got {describe(T)}")
    bottom = list(T[3, :]) if isinstance(T, sp.MatrixBase) else T[3, :].tolist()
    if isinstance(T, sp.MatrixBase):
        ok = all(is_zero(b - e) for b, e in zip(bottom, (0, 0, 0, 1)))
    else:
        ok = np.allclose(bottom, (0, 0, 0, 1), atol=_TOL)
    if not ok:
        raise ValueError(f"{name} must be a homogeneous transform in SE(3) with last row [0, 0, 0, 1], got last row {bottom}")
    check_so3(T[:3, :3], f"the rotation part of {name}")
    return T


def trans_inv(T):
    """T⁻¹ = [[Rᵀ, −Rᵀp], [0, 1]]."""
    T = check_se3(T, "T")
    R, p = T[:3, :3], T[:3, 3]
    if isinstance(T, sp.MatrixBase):
        return rp_to_trans(R.T, -R.T * p)
    out = np.eye(4)
    out[:3, :3] = R.T
    out[:3, 3] = -R.T @ p
    return out


def adjoint(T):
    """Ad_T = [[R, 0], [[p]R, R]] (6×6), acting on twists [ω; v]."""
    T = check_se3(T, "T")
    R, p = T[:3, :3], T[:3, 3]
    if isinstance(T, sp.MatrixBase):
        return sp.Matrix.vstack(sp.Matrix.hstack(R, sp.zeros(3)), sp.Matrix.hstack(skew(p) * R, R))
    out = np.zeros((6, 6))
    out[:3, :3] = R
    out[3:, 3:] = R
    out[3:, :3] = skew(p) @ R
    return out
