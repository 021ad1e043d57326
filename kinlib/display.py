"""Exact zero tests and a fast display form for product-of-exponentials expressions.

``is_identically_zero(M)`` decides whether every entry of M is 0 for *all* values of its symbols
(an identity such as sin²θ + cos²θ − 1, or J_b − Ad_{T⁻¹} J_s), exactly and fast: see its docstring.

``simplify_for_display(M)`` works entry by entry:

1. expand the entry into a polynomial in s_i = sin θ_i, c_i = cos θ_i (and the other symbols);
2. reduce it modulo s_i² + c_i² − 1 (every s_i^k with k ≥ 2 becomes s_i^(k−2)(1 − c_i²)),
   which cancels the terms that only add up to zero;
3. fold sums of products back into sines and cosines of angle sums (``fu.TR10i``:
   cos a cos b − sin a sin b → cos(a + b)), without constant phase shifts (no √2 cos(x + π/4)),
   and pull out common factors (``factor_terms``).

With ``phase_shifts=True`` step 3 keeps TR10i's constant phases (a cos x − a sin x → √2 a cos(x + π/4)),
the form the printed solutions use.

The result is exactly equal to the input (each step is an identity). On the UR5's space Jacobian it
takes about a second, where ``sp.simplify`` of each entry takes minutes and ``trigsimp`` 10–15 s.
Numeric code is generated from the *unsimplified* expression (see :mod:`kinlib.codegen`).
"""
from __future__ import annotations

import numbers
from typing import Any

import numpy as np
import sympy as sp
from sympy.simplify.fu import TR10i

from ._backend import describe

__all__ = ["simplify_for_display", "is_identically_zero"]


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


def _display_entry(e: sp.Expr, phase_shifts: bool = False) -> sp.Expr:
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
    folded = TR10i(R.as_expr().xreplace(back))
    return sp.factor_terms(folded if phase_shifts else _unshift(folded))


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


def simplify_for_display(M: Any, phase_shifts: bool = False):
    """A readable form of a SymPy Matrix or expression in sines and cosines of the joint angles.

    Exactly equal to ``M``; entry-wise Pythagorean reduction (sin² + cos² = 1), angle sums
    (cos θ2 cos θ3 − sin θ2 sin θ3 → cos(θ2 + θ3)) and common factors. ``phase_shifts=True`` also writes
    a cos x − a sin x as √2 a cos(x + π/4), the form of the printed solutions (problem set, eqs. 17–20).
    For display only: the numeric fast path evaluates the unsimplified expression.
    """
    if isinstance(M, sp.MatrixBase):
        return sp.Matrix(M).applyfunc(lambda e: _display_entry(e, phase_shifts))
    if isinstance(M, (str, bytes)) or not isinstance(M, (sp.Basic, int, float)):
        raise TypeError(f"M must be a SymPy Matrix or expression, got {describe(M)}")
    return _display_entry(sp.sympify(M), phase_shifts)


# ----------------------------------------------------------------------------------------------
# exact zero test
# ----------------------------------------------------------------------------------------------
class _NotTrigPolynomial(Exception):
    """The expression is not a polynomial in sines, cosines and symbols (e.g. √L, 1/L, exp)."""


def _is_variable(x) -> bool:
    return isinstance(x, (sp.Symbol, sp.Derivative)) or isinstance(x, sp.core.function.AppliedUndef)


def _single_angle_form(e: sp.Expr) -> sp.Expr:
    """Expand sin/cos of sums and integer multiples (sin(θ1 + θ2), cos 2θ) into single-angle functions."""
    compound = [f for f in e.atoms(sp.sin, sp.cos) if not _is_variable(f.args[0])]
    return sp.expand_trig(e) if compound else e


def _trig_remainder(e: sp.Expr):
    """The normal form of e modulo sin²θ + cos²θ − 1 (one relation per angle θ), as a ring element.

    e must be a polynomial in sin θ_i, cos θ_i (θ_i symbols or functions of time) and other symbols;
    the arithmetic is done in a sparse polynomial ring (no SymPy expand), which is what makes it fast.
    """
    e = _single_angle_form(e)
    if e.has(sp.Float):  # a float is taken at its exact binary value
        e = e.xreplace({f: sp.Rational(f) for f in e.atoms(sp.Float)})
    trig = e.atoms(sp.sin, sp.cos)
    if any(not _is_variable(f.args[0]) for f in trig):
        raise _NotTrigPolynomial
    angles = sorted({f.args[0] for f in trig}, key=sp.default_sort_key)
    variables = sorted(e.atoms(sp.Symbol, sp.Derivative, sp.core.function.AppliedUndef), key=sp.default_sort_key)
    consts = [c for c in e.atoms(sp.Number, sp.NumberSymbol) if not isinstance(c, sp.Rational)]
    consts += [p for p in e.atoms(sp.Pow) if p.is_number and not p.is_Rational]
    if consts:
        domain = sp.polys.constructor.construct_domain(consts, extension=True)[0]
    else:
        domain = sp.QQ
    k = len(angles)
    gens = [sp.sin(a) for a in angles] + [sp.cos(a) for a in angles] + variables
    if not gens:
        gens = [sp.Dummy()]
    R, *G = sp.polys.rings.ring([sp.Dummy() for _ in gens], domain)
    table = dict(zip(gens, G))
    memo: dict = {}

    def conv(x):
        if x in table:
            return table[x]
        if x in memo:
            return memo[x]
        if x.is_number and (x.is_Rational or domain != sp.QQ):
            try:
                out = R(domain.from_sympy(x))
            except Exception as err:  # a constant outside the domain, e.g. E**x
                raise _NotTrigPolynomial from err
        elif x.is_Add:
            out = R.zero
            for a in x.args:
                out += conv(a)
        elif x.is_Mul:
            out = R.one
            for a in x.args:
                out *= conv(a)
        elif x.is_Pow and x.exp.is_Integer and x.exp >= 0:
            out = conv(x.base) ** int(x.exp)
        else:
            raise _NotTrigPolynomial
        memo[x] = out
        return out

    p = conv(e)
    if k == 0 or p == 0:
        return p
    return p.rem([G[i] ** 2 + G[k + i] ** 2 - 1 for i in range(k)])


def _entry_is_zero(e: sp.Expr) -> bool:
    if e == 0:
        return True
    try:
        return _trig_remainder(e) == 0
    except _NotTrigPolynomial:
        pass
    num = sp.fraction(sp.together(e))[0]   # a rational function is 0 exactly where its numerator is
    try:
        return _trig_remainder(num) == 0
    except _NotTrigPolynomial:
        return sp.expand(sp.expand_trig(e).rewrite(sp.exp)) == 0


def _entries(M: Any, name: str) -> list:
    if isinstance(M, sp.MatrixBase):
        return list(M)
    if isinstance(M, (str, bytes)) or isinstance(M, bool):
        raise TypeError(f"{name} must be a SymPy expression or Matrix (or numbers), got {describe(M)}")
    if isinstance(M, (sp.Expr, numbers.Number)):
        return [sp.sympify(M)]
    if isinstance(M, (list, tuple, np.ndarray)):
        if any(isinstance(e, (str, bytes, bool)) for e in np.asarray(M, dtype=object).flat):
            raise TypeError(f"{name} must hold SymPy expressions or numbers, got {describe(M)} with a string or bool")
        try:
            flat = list(sp.Matrix(M))
        except Exception as err:
            raise TypeError(f"{name} must be a SymPy expression or Matrix (or numbers), got {describe(M)}") from err
        for e in flat:
            if not isinstance(e, sp.Expr):
                raise TypeError(f"{name} must hold SymPy expressions or numbers, got an entry {describe(e)}")
        return flat
    raise TypeError(f"{name} must be a SymPy expression or Matrix (or numbers), got {describe(M)}")


def is_identically_zero(M: Any) -> bool:
    """True when every entry of M is 0 for *all* values of its symbols: M ≡ 0, e.g. sin²θ + cos²θ − 1.

    M is a SymPy expression or Matrix (or nested lists of them). The test is exact, never numeric:

    1. sines and cosines of sums and multiples are expanded into single angles (sin(θ1 + θ2) →
       sin θ1 cos θ2 + cos θ1 sin θ2), so each entry becomes a polynomial in s_i = sin θ_i, c_i = cos θ_i
       and the other symbols (lengths L, prismatic joint values, time derivatives θ̇_i ...);
    2. the polynomial is reduced modulo s_i² + c_i² − 1 (one relation per angle) in a sparse polynomial
       ring; the entry is identically zero exactly when the remainder is 0.

    Why exact: the relations s_i² + c_i² − 1 involve distinct variables, so they form a Gröbner basis and the
    remainder is the *unique* normal form, of degree ≤ 1 in each s_i; the functions cosᵏθ and sin θ cosᵏθ are
    linearly independent, so a nonzero normal form is a nonzero function of the angles. Hence, for
    polynomials in sines and cosines (every product-of-exponentials FK and Jacobian entry, and any
    difference of two of them) the answer is True if and only if the entry is identically zero
    (θ_i(t) and θ̇_i count as independent variables, as they are at any one instant).
    Floats count at their exact binary values. Rational functions are tested through their numerator.
    Other forms (square roots of symbols, exponentials, half angles θ/2) fall back to writing sin and cos
    with exponentials and expanding: there True is still a proof, but False may mean "not shown".

    Much faster than ``sp.simplify(e) == 0``: no trigsimp, and no SymPy ``expand`` of large products.
    """
    return all(_entry_is_zero(e) for e in _entries(M, "M"))
