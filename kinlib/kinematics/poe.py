"""The product-of-exponentials formula (Lynch & Park, *Modern Robotics*, chapter 4).

Space form:  T(θ) = e^{[S1]θ1} e^{[S2]θ2} ⋯ e^{[Sn]θn} M
Body form:   T(θ) = M e^{[B1]θ1} ⋯ e^{[Bn]θn},  with B_i = Ad_{M⁻¹} S_i.

Screw lists are 6×n with one axis [ω; v] per column, or a sequence of n 6-vectors. SymPy in → exact SymPy
out; numbers in → NumPy floats.
"""

from __future__ import annotations

import numpy as np
import sympy as sp

from .._backend import as_matrix, as_screw_list, as_thetas, is_symbolic
from .rigid import check_se3
from .screws import exp6_unchecked, screw_kind

__all__ = ["fk_space", "fk_body", "checked_screw_list"]


def checked_screw_list(Slist, thetas, name: str = "Slist", symbolic: bool | None = None):
    """(S 6×n, θ, joint kinds 'R'/'P', symbolic?) after checking a screw list and its joint values.

    Every column must be a screw axis: |ω| = 1 (revolute), or ω = 0 and |v| = 1 (prismatic).

    >>> S, th, kinds, symbolic = checked_screw_list([[0, 0, 1, 0, 0, 0], [0, 0, 0, 1, 0, 0]], [0.5, 2.0])
    >>> S.shape, kinds, symbolic
    ((6, 2), ['R', 'P'], False)
    """
    if symbolic is None:
        symbolic = is_symbolic(Slist, thetas)
    S = as_screw_list(Slist, name, symbolic)
    n = S.shape[1]
    th = as_thetas(thetas, n, "thetas", symbolic)
    kinds = [screw_kind(S[:, i], f"{name} column {i + 1}") for i in range(n)]
    return S, th, kinds, symbolic


def fk_space(M, Slist, thetas):
    """T(θ) = e^{[S1]θ1} ⋯ e^{[Sn]θn} M: the end-effector pose from the space screw axes.

    >>> import sympy as sp
    >>> from kinlib.robots import planar_2r
    >>> r = planar_2r()
    >>> fk_space(r.M, r.screws, [sp.pi / 2, -sp.pi / 2])   # shoulder up, elbow back: tool at (L2, L1)
    Matrix([
    [1, 0, 0, L2],
    [0, 1, 0, L1],
    [0, 0, 1,  0],
    [0, 0, 0,  1]])
    """
    symbolic = is_symbolic(M, Slist, thetas)
    M = check_se3(as_matrix(M, "M", None, symbolic, real_symbols=True), "M")
    S, th, kinds, _ = checked_screw_list(Slist, thetas, "Slist", symbolic)
    T = sp.eye(4) if symbolic else np.eye(4)
    for i in range(S.shape[1]):
        E = exp6_unchecked(S[:, i], th[i], kinds[i], symbolic)
        T = T * E if symbolic else T @ E
    return T * M if symbolic else T @ M


def fk_body(M, Blist, thetas):
    """T(θ) = M e^{[B1]θ1} ⋯ e^{[Bn]θn}: the end-effector pose from the body screw axes.

    >>> import numpy as np, sympy as sp
    >>> from kinlib.robots import planar_2r
    >>> r, q = planar_2r(), [sp.pi / 2, -sp.pi / 2]
    >>> r.body_screws.T   # B_i = Ad_{M⁻¹} S_i
    Matrix([
    [0, 0, 1, 0, L1 + L2, 0],
    [0, 0, 1, 0,      L2, 0]])
    >>> fk_body(r.M, r.body_screws, q) == fk_space(r.M, r.screws, q)   # the body and space forms agree
    True
    >>> r1 = planar_2r(1, 1)
    >>> M, B = np.array(r1.M, dtype=float), np.array(r1.body_screws, dtype=float)   # numbers in, floats out
    >>> (np.round(fk_body(M, B, [np.pi / 2, -np.pi / 2])[:3, 3], 3) + 0.0).tolist()
    [1.0, 1.0, 0.0]
    """
    symbolic = is_symbolic(M, Blist, thetas)
    M = check_se3(as_matrix(M, "M", None, symbolic, real_symbols=True), "M")
    B, th, kinds, _ = checked_screw_list(Blist, thetas, "Blist", symbolic)
    T = M
    for i in range(B.shape[1]):
        E = exp6_unchecked(B[:, i], th[i], kinds[i], symbolic)
        T = T * E if symbolic else T @ E
    return T
