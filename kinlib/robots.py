"""Every robot of the problem set as a :class:`~kinlib.chains.SerialChain`.

Link lengths are arguments: numbers or SymPy symbols, defaulting to positive SymPy symbols of the
same names (so ``planar_offset_3r()`` is the problem set's robot in L, and
``planar_offset_3r(1)`` a numeric one for the fast path). Python floats are turned into exact
rationals (0.425 → 17/40), so symbolic work stays exact.
"""
from __future__ import annotations

import sympy as sp

from .chains import SerialChain

__all__ = ["cart_pole", "planar_offset_3r", "spatial_rppr", "planar_3r", "planar_rpp", "ur5", "length"]


def length(value, name: str):
    """A link length: a positive symbol named ``name`` when ``value`` is None, else ``value`` made exact."""
    if value is None:
        return sp.Symbol(name, positive=True)
    if isinstance(value, (str, bytes)) or isinstance(value, bool):
        raise TypeError(f"{name} must be a number or a SymPy expression, got {value!r}")
    if isinstance(value, float):
        return sp.nsimplify(value, rational=True)
    try:
        return sp.sympify(value, strict=True)
    except (sp.SympifyError, TypeError):
        raise TypeError(f"{name} must be a number or a SymPy expression, got {value!r}") from None


def _T(p, R=None):
    R = sp.eye(3) if R is None else sp.Matrix(R)
    return sp.Matrix.vstack(sp.Matrix.hstack(R, sp.Matrix(p)), sp.Matrix([[0, 0, 0, 1]]))


def _cols(*vs):
    return sp.Matrix.hstack(*[sp.Matrix(v) for v in vs])


def cart_pole(L=None, h=None) -> SerialChain:
    """Problem 1.1: a cart sliding along x_s (θ1) carrying a pole of length L hinged at height h (θ2 from x_s).

    End effector: the tip of the pole, p = (θ1 + L cos θ2, h + L sin θ2, 0).
    """
    L, h = length(L, "L"), length(h, "h")
    S = _cols([0, 0, 0, 1, 0, 0], [0, 0, 1, h, 0, 0])
    return SerialChain(_T([L, h, 0]), S, name="cart_pole", joint_points=_cols([0, 0, 0], [0, h, 0]),
                       description="cart (prismatic along x_s) + pole (revolute about z_s at height h)")


def planar_offset_3r(L=None) -> SerialChain:
    """Sections 2 and 5: three revolute joints about z_s at (0, 0), (L, 0), (2L, L); tool frame at (3L, L)."""
    L = length(L, "L")
    S = _cols([0, 0, 1, 0, 0, 0], [0, 0, 1, 0, -L, 0], [0, 0, 1, L, -2 * L, 0])
    return SerialChain(_T([3 * L, L, 0]), S, name="planar_offset_3r",
                       joint_points=_cols([0, 0, 0], [L, 0, 0], [2 * L, L, 0]),
                       description="planar RRR with joints at (0,0), (L,0), (2L,L) and the tool at (3L,L)")


def spatial_rppr(L1=None, L2=None) -> SerialChain:
    """Sections 3 and 6: R about z_s, P along z_s, P along x, R about x through (0, 0, L1 + L2); tool at (L2, 0, L1 + L2)."""
    L1, L2 = length(L1, "L1"), length(L2, "L2")
    H = L1 + L2
    S = _cols([0, 0, 1, 0, 0, 0], [0, 0, 0, 0, 0, 1], [0, 0, 0, 1, 0, 0], [1, 0, 0, 0, H, 0])
    return SerialChain(_T([L2, 0, H]), S, name="spatial_rppr",
                       joint_points=_cols([0, 0, 0], [0, 0, L1], [0, 0, H], [L2, 0, H]),
                       description="spatial RPPR: base rotation, vertical slide, horizontal slide, wrist roll")


def planar_3r(L1=None, L2=None, L3=None) -> SerialChain:
    """Section 4: planar RRR with links L1, L2, L3 along x_s at home; tool at (L1 + L2 + L3, 0)."""
    L1, L2, L3 = length(L1, "L1"), length(L2, "L2"), length(L3, "L3")
    S = _cols([0, 0, 1, 0, 0, 0], [0, 0, 1, 0, -L1, 0], [0, 0, 1, 0, -(L1 + L2), 0])
    return SerialChain(_T([L1 + L2 + L3, 0, 0]), S, name="planar_3r",
                       joint_points=_cols([0, 0, 0], [L1, 0, 0], [L1 + L2, 0, 0]),
                       description="planar RRR, links L1, L2, L3")


def planar_rpp(L=None) -> SerialChain:
    """Problem 5.5's redesign: R about z_s, then P along x_s and P along y_s (as seen at home); tool offset L along x."""
    L = length(L, "L")
    S = _cols([0, 0, 1, 0, 0, 0], [0, 0, 0, 1, 0, 0], [0, 0, 0, 0, 1, 0])
    return SerialChain(_T([L, 0, 0]), S, name="planar_rpp",
                       joint_points=_cols([0, 0, 0], [0, 0, 0], [0, 0, 0]),
                       description="planar RPP: a base rotation followed by x and y slides")


_UR5 = {"W1": "0.109", "W2": "0.082", "L1": "0.425", "L2": "0.392", "H1": "0.089", "H2": "0.095"}


def ur5(W1=None, W2=None, L1=None, L2=None, H1=None, H2=None) -> SerialChain:
    """The UR5 of Modern Robotics Example 4.5 (6R); defaults are the book's lengths in metres, as exact rationals.

    Pass SymPy symbols (e.g. ``ur5(*sp.symbols('W1 W2 L1 L2 H1 H2', positive=True))``) for the symbolic arm.
    """
    given = dict(W1=W1, W2=W2, L1=L1, L2=L2, H1=H1, H2=H2)
    v = {k: (sp.Rational(_UR5[k]) if x is None else length(x, k)) for k, x in given.items()}
    W1, W2, L1, L2, H1, H2 = (v[k] for k in ("W1", "W2", "L1", "L2", "H1", "H2"))
    M = _T([L1 + L2, W1 + W2, H1 - H2], [[-1, 0, 0], [0, 0, 1], [0, 1, 0]])
    S = _cols([0, 0, 1, 0, 0, 0], [0, 1, 0, -H1, 0, 0], [0, 1, 0, -H1, 0, L1],
              [0, 1, 0, -H1, 0, L1 + L2], [0, 0, -1, -W1, L1 + L2, 0], [0, 1, 0, H2 - H1, 0, L1 + L2])
    pts = _cols([0, 0, 0], [0, 0, H1], [L1, 0, H1], [L1 + L2, 0, H1], [L1 + L2, W1, H1], [L1 + L2, W1, H1 - H2])
    return SerialChain(M, S, name="ur5", joint_points=pts, description="UR5 (Modern Robotics Example 4.5)")
