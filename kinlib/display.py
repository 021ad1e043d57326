"""A fast display form for product-of-exponentials expressions (simplify *only* for display).

``simplify_for_display(M)`` works entry by entry:

1. expand the entry into a polynomial in s_i = sin θ_i, c_i = cos θ_i (and the other symbols);
2. reduce it modulo s_i² + c_i² − 1 (every s_i^k with k ≥ 2 becomes s_i^(k−2)(1 − c_i²)),
   which cancels the terms that only add up to zero;
3. fold sums of products back into sines and cosines of angle sums (``fu.TR10i``:
   cos a cos b − sin a sin b → cos(a + b)), without constant phase shifts (no √2 cos(x + π/4)),
   and pull out common factors (``factor_terms``).

The result is exactly equal to the input (each step is an identity). On the UR5's space Jacobian it
takes about a second, where ``sp.simplify`` of each entry takes minutes and ``trigsimp`` 10–15 s.
Numeric code is generated from the *unsimplified* expression (see :mod:`kinlib.codegen`).
"""
from __future__ import annotations

from typing import Any

import sympy as sp
from sympy.simplify.fu import TR10i

from ._backend import describe

__all__ = ["simplify_for_display"]


def _reduce_pythagoras(P: sp.Poly, pairs: list[tuple[int, int]]) -> sp.Poly:
    """The normal form of P modulo s² + c² − 1 for each (index of s, index of c) in ``pairs``."""
    out: dict[tuple, Any] = {}
    stack = list(P.terms())
    while stack:
        m, coeff = stack.pop()
        for i, j in pairs:
            if m[i] >= 2:  # s^k c^l = s^(k-2) c^l - s^(k-2) c^(l+2)
                m1 = list(m)
                m1[i] -= 2
                m2 = list(m1)
                m2[j] += 2
                stack.append((tuple(m1), coeff))
                stack.append((tuple(m2), -coeff))
                break
        else:
            out[m] = out.get(m, 0) + coeff
    terms = {m: c for m, c in out.items() if c != 0}
    if not terms:
        return sp.Poly(0, *P.gens, domain=P.domain)
    return sp.Poly.from_dict(terms, *P.gens, domain=P.domain)


def _display_entry(e: sp.Expr) -> sp.Expr:
    trig = e.atoms(sp.sin, sp.cos)
    if not trig:
        return sp.factor_terms(sp.expand(e)) if e.free_symbols else e
    if any(not f.args[0].is_Symbol for f in trig):
        e = sp.expand_trig(e)  # sin(θ1 + θ2) -> products of single-angle functions
    e = sp.expand(e)
    angles = sorted({f.args[0] for f in e.atoms(sp.sin, sp.cos)}, key=sp.default_sort_key)
    if not angles:
        return sp.factor_terms(e)
    s = {a: sp.Dummy(f"s_{a}") for a in angles}
    c = {a: sp.Dummy(f"c_{a}") for a in angles}
    to_poly = {sp.sin(a): s[a] for a in angles}
    to_poly.update({sp.cos(a): c[a] for a in angles})
    gens = [s[a] for a in angles] + [c[a] for a in angles]
    try:
        P = sp.Poly(e.xreplace(to_poly), *gens)
    except sp.PolynomialError:  # e.g. trig functions inside a square root: leave the entry as it is
        return sp.factor_terms(TR10i(e))
    k = len(angles)
    R = _reduce_pythagoras(P, [(i, k + i) for i in range(k)])
    back = {s[a]: sp.sin(a) for a in angles}
    back.update({c[a]: sp.cos(a) for a in angles})
    return sp.factor_terms(_unshift(TR10i(R.as_expr().xreplace(back))))


def _shifted(f) -> bool:
    return isinstance(f, (sp.sin, sp.cos)) and f.args[0].is_Add and _phase(f.args[0])[0] != 0


def _phase(a: sp.Expr):
    """(constant part, the rest) of an angle: θ1 + θ2 + π/4 -> (π/4, θ1 + θ2)."""
    return a.as_independent(*a.free_symbols, as_Add=True) if a.free_symbols else (a, sp.S.Zero)


def _split(f):
    c, x = _phase(f.args[0])
    if isinstance(f, sp.cos):
        return sp.cos(x) * sp.cos(c) - sp.sin(x) * sp.sin(c)
    return sp.sin(x) * sp.cos(c) + sp.cos(x) * sp.sin(c)


def _unshift(e: sp.Expr) -> sp.Expr:
    """Undo TR10i's a cos x − a sin x → √2 a cos(x + π/4): constant phase shifts are split again."""
    if not any(_shifted(f) for f in e.atoms(sp.sin, sp.cos)):
        return e
    return sp.expand(e.replace(_shifted, _split))


def simplify_for_display(M: Any):
    """A readable form of a SymPy Matrix or expression in sines and cosines of the joint angles.

    Exactly equal to ``M``; entry-wise Pythagorean reduction (sin² + cos² = 1), angle sums
    (cos θ2 cos θ3 − sin θ2 sin θ3 → cos(θ2 + θ3)) and common factors. For display only: the
    numeric fast path evaluates the unsimplified expression.
    """
    if isinstance(M, sp.MatrixBase):
        return sp.Matrix(M).applyfunc(_display_entry)
    if isinstance(M, (str, bytes)) or not isinstance(M, (sp.Basic, int, float)):
        raise TypeError(f"M must be a SymPy Matrix or expression, got {describe(M)}")
    return _display_entry(sp.sympify(M))
