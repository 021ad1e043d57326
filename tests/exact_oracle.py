"""An independent 60-digit oracle for tests: the space Jacobian of a chain by the product of exponentials,
written here in mpmath from the screw axes alone (no kinlib code), and its singular values."""

from __future__ import annotations

import mpmath

DIGITS = 60


def _mp(x):
    import sympy as sp

    return mpmath.mpf(str(sp.N(sp.sympify(x), DIGITS + 15)))


def _skew(w):
    return mpmath.matrix([[0, -w[2], w[1]], [w[2], 0, -w[0]], [-w[1], w[0], 0]])


def _exp6(S, th):
    """e^{[S]θ} (4×4) by Rodrigues; S = [ω; v] with |ω| = 1 or ω = 0."""
    w = [S[0], S[1], S[2]]
    v = mpmath.matrix([S[3], S[4], S[5]])
    T = mpmath.eye(4)
    if all(x == 0 for x in w):
        for i in range(3):
            T[i, 3] = v[i] * th
        return T
    W = _skew(w)
    W2 = W * W
    R = mpmath.eye(3) + mpmath.sin(th) * W + (1 - mpmath.cos(th)) * W2
    p = (mpmath.eye(3) * th + (1 - mpmath.cos(th)) * W + (th - mpmath.sin(th)) * W2) * v
    for i in range(3):
        for j in range(3):
            T[i, j] = R[i, j]
        T[i, 3] = p[i]
    return T


def space_jacobian(screws, q):
    """J_s (6×n) at q: column i = Ad_{e^{[S1]q1}⋯e^{[S_{i-1}]q_{i-1}}} S_i. screws: 6×n exact (SymPy), q exact."""
    with mpmath.workdps(DIGITS + 15):
        n = screws.shape[1]
        S = [[_mp(screws[r, i]) for r in range(6)] for i in range(n)]
        Q = [_mp(x) for x in q]
        T = mpmath.eye(4)
        J = mpmath.matrix(6, n)
        for i in range(n):
            R = T[0:3, 0:3]
            p = [T[0, 3], T[1, 3], T[2, 3]]
            w = R * mpmath.matrix(S[i][:3])
            v = R * mpmath.matrix(S[i][3:])
            pw = _skew(p) * w
            for r in range(3):
                J[r, i] = w[r]
                J[3 + r, i] = pw[r] + v[r]
            T = T * _exp6(S[i], Q[i])
        return J


def singular_values(J):
    with mpmath.workdps(DIGITS):
        return sorted((abs(s) for s in mpmath.svd_r(J, compute_uv=False)), reverse=True)


def rank(J, zero=mpmath.mpf(10) ** -45, nonzero=mpmath.mpf(10) ** -20):
    """The rank of J, or None when a singular value lies between 1e-45 and 1e-20 (too close to call)."""
    s = singular_values(J)
    top = max(s[0], 1) if s else 1
    r = 0
    for x in s:
        if x > nonzero * top:
            r += 1
        elif x > zero * top:
            return None
    return r


def rows(J, idx):
    out = mpmath.matrix(len(idx), J.cols)
    for a, i in enumerate(idx):
        for j in range(J.cols):
            out[a, j] = J[i, j]
    return out


def to_mp(M):
    """A SymPy Matrix of exact numbers as a 60-digit mpmath matrix."""
    with mpmath.workdps(DIGITS + 15):
        return mpmath.matrix([[_mp(M[i, j]) for j in range(M.cols)] for i in range(M.rows)])


def max_abs(X):
    return max((abs(x) for x in X), default=mpmath.mpf(0))


def exp6(S, th):
    """e^{[S]θ} (4×4) at 60 digits for a screw S = [ω; v] (|ω| = 1 or ω = 0) of mpmath numbers or strings and θ
    (an mpmath number or a string, e.g. "3.14159…" or mpmath.pi − δ), by Rodrigues' formula."""
    with mpmath.workdps(DIGITS + 15):
        return _exp6([mpmath.mpf(x) for x in S], mpmath.mpf(th))


def fk(screws, M, q):
    """T(θ) = e^{[S1]θ1}⋯e^{[Sn]θn} M at 60 digits (screws 6×n and M exact SymPy, q exact or floats)."""
    with mpmath.workdps(DIGITS + 15):
        n = screws.shape[1]
        T = mpmath.eye(4)
        for i in range(n):
            T = T * _exp6([_mp(screws[r, i]) for r in range(6)], _mp(q[i]))
        return T * to_mp(M)


def geometric_jacobian(screws, M, q):
    """The geometric Jacobian [ω_s; ṗ] (6×n) at q, 60 digits: ṗ = v_s + ω_s × p = v_s − [p] ω_s with p the tool
    origin (from :func:`fk`), so it rests on :func:`space_jacobian` and :func:`fk` only."""
    with mpmath.workdps(DIGITS + 15):
        Js = space_jacobian(screws, q)
        T = fk(screws, M, q)
        P = _skew([T[0, 3], T[1, 3], T[2, 3]])
        J = Js.copy()
        for r in range(3):
            for j in range(Js.cols):
                J[3 + r, j] = Js[3 + r, j] - sum(P[r, k] * Js[k, j] for k in range(3))
        return J
