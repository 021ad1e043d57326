"""Screw axes and twists [ω; v] (angular first) and their exponential.

Lynch & Park, *Modern Robotics*, chapter 3.3. A screw axis S = [ω; v] has either |ω| = 1
(revolute or helical, v = −ω × q + h ω) or ω = 0 and |v| = 1 (prismatic).
"""
from __future__ import annotations

import numpy as np
import sympy as sp

from ._backend import as_matrix, as_vector, is_symbolic, is_zero
from .rigid import _scalar, _unit_axis, cross, skew

__all__ = ["screw_revolute", "screw_prismatic", "screw_axis", "bracket", "unbracket", "exp6"]


def screw_revolute(omega, q):
    """S = [ω; −ω × q]: a revolute joint about the unit axis ω through the point q."""
    symbolic = is_symbolic(omega, q)
    w = _unit_axis(as_vector(omega, "omega", 3, symbolic), "omega")
    q = as_vector(q, "q", 3, symbolic)
    v = -cross(w, q)
    return sp.Matrix.vstack(w, v) if symbolic else np.concatenate([w, v + 0.0])  # + 0.0: no −0.0 entries


def screw_prismatic(v):
    """S = [0; v]: a prismatic joint sliding along the unit direction v."""
    symbolic = is_symbolic(v)
    v = _unit_axis(as_vector(v, "v", 3, symbolic), "v")
    return sp.Matrix.vstack(sp.zeros(3, 1), v) if symbolic else np.concatenate([np.zeros(3), v])


def screw_axis(q, s, h):
    """S = [s; −s × q + h s]: the screw axis through q along the unit direction s with pitch h."""
    symbolic = is_symbolic(q, s, h)
    s = _unit_axis(as_vector(s, "s", 3, symbolic), "s")
    q = as_vector(q, "q", 3, symbolic)
    h = _scalar(h, "h", symbolic)
    v = -cross(s, q) + h * s
    return sp.Matrix.vstack(s, v) if symbolic else np.concatenate([s, v + 0.0])


def bracket(V):
    """[V] = [[[ω], v], [0, 0]] ∈ se(3) for a twist V = [ω; v]."""
    V = as_vector(V, "V", 6)
    if isinstance(V, sp.MatrixBase):
        return sp.Matrix.vstack(sp.Matrix.hstack(skew(V[:3, 0]), V[3:, 0]), sp.zeros(1, 4))
    out = np.zeros((4, 4))
    out[:3, :3] = skew(V[:3])
    out[:3, 3] = V[3:]
    return out


def unbracket(X):
    """V = [ω; v] from [V] ∈ se(3)."""
    X = as_matrix(X, "X", (4, 4))
    from .rigid import unskew  # local: keeps the import graph flat
    w = unskew(X[:3, :3])
    if isinstance(X, sp.MatrixBase):
        if not all(is_zero(e) for e in X[3, :]):
            raise ValueError(f"X must be in se(3) with last row 0, got last row {list(X[3, :])}")
        return sp.Matrix.vstack(w, X[:3, 3])
    if not np.allclose(X[3], 0):
        raise ValueError(f"X must be in se(3) with last row 0, got last row {X[3].tolist()}")
    return np.concatenate([w, X[:3, 3]])


def _screw_kind(S, name: str) -> str:
    """'R' when |ω| = 1, 'P' when ω = 0 and |v| = 1; anything else is not a screw axis."""
    w, v = S[:3], S[3:]
    if isinstance(S, sp.MatrixBase):
        if all(is_zero(e) for e in w):
            _unit_axis(sp.Matrix(v), f"the linear part v of {name} (a prismatic axis, ω = 0)")
            return "P"
        _unit_axis(sp.Matrix(w), f"the angular part ω of {name}")
        return "R"
    if not np.any(np.abs(w) > 1e-12):
        _unit_axis(np.asarray(v), f"the linear part v of {name} (a prismatic axis, ω = 0)")
        return "P"
    _unit_axis(np.asarray(w), f"the angular part ω of {name}")
    return "R"


def exp6(S, theta):
    """e^{[S]θ} ∈ SE(3) for a screw axis S = [ω; v] and a joint value θ.

    |ω| = 1: [[e^{[ω]θ}, (Iθ + (1 − cos θ)[ω] + (θ − sin θ)[ω]²) v], [0, 1]];
    ω = 0:   [[I, v θ], [0, 1]].
    """
    symbolic = is_symbolic(S, theta)
    S = as_vector(S, "S", 6, symbolic)
    theta = _scalar(theta, "theta", symbolic)
    kind = _screw_kind(S, "S")
    return _exp6(S, theta, kind, symbolic)


def _exp6(S, theta, kind: str, symbolic: bool):
    """exp6 without the checks (S already a validated column/array)."""
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
    s, c = np.sin(theta), np.cos(theta)
    T[:3, :3] += s * W + (1.0 - c) * W2
    T[:3, 3] = (theta * v) + (1.0 - c) * (W @ v) + (theta - s) * (W2 @ v)
    return T
