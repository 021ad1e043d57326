"""Trigonometric polynomials: the normal form modulo sin²θ + cos²θ − 1.

Every product-of-exponentials FK and Jacobian entry is a polynomial in s_i = sin θ_i, c_i = cos θ_i and
other symbols (link lengths, prismatic joint values, θ̇_i ...). Modulo the relations s_i² + c_i² − 1 (one
per angle) each such polynomial has a **unique normal form**, of degree ≤ 1 in every s_i: the relations
involve distinct variables, so they are a Gröbner basis, and the remainder of the division is canonical.

:class:`TrigRing` holds the sparse polynomial ring (no SymPy ``expand`` of large products: this is what
makes it fast) and converts between SymPy expressions and ring elements. It is shared by

* :func:`kinlib.display.is_identically_zero` (normal form = 0 ⇔ identically zero),
* :func:`kinlib.display.simplify_for_display` (normal form, then angle sums folded back),
* :func:`kinlib.singularities.trig_simplify`, the determinant in
  :func:`kinlib.singularities.singular_configurations`, and :func:`kinlib.manipulability.manipulability`.
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Callable, Iterable, Sequence
from typing import Any

import sympy as sp
from sympy.polys.constructor import construct_domain
from sympy.polys.rings import ring as _ring

__all__ = ["TrigRing", "NotTrigPolynomial", "single_angle_form", "angles_in", "is_variable", "normal_form_zero"]


class NotTrigPolynomial(ValueError):
    """The expression is not a polynomial in the sines and cosines of the angles (e.g. √L, 1/sin θ, exp).

    >>> import sympy as sp
    >>> L, t = sp.Symbol("L", positive=True), sp.Symbol("t", real=True)
    >>> TrigRing([sp.sqrt(L) * sp.sin(t)])   # exact mode: √L is not a polynomial generator
    Traceback (most recent call last):
        ...
    kinlib.exact.trigpoly.NotTrigPolynomial: sqrt(L)
    """


def is_variable(x) -> bool:
    """A symbol, a function of time θ(t) or a derivative θ̇(t): an independent variable at one instant.

    >>> import sympy as sp
    >>> t = sp.Symbol("t", real=True)
    >>> q = sp.Function("q")(t)
    >>> is_variable(t), is_variable(q), is_variable(q.diff(t)), is_variable(sp.sin(t))
    (True, True, True, False)
    """
    return isinstance(x, (sp.Symbol, sp.Derivative, sp.core.function.AppliedUndef))


def single_angle_form(e: sp.Expr) -> sp.Expr:
    """Expand sin/cos of sums and integer multiples (sin(θ1 + θ2), cos 2θ) into single-angle functions.

    >>> import sympy as sp
    >>> t1, t2 = sp.symbols("theta1 theta2", real=True)
    >>> single_angle_form(sp.sin(t1 + t2)), single_angle_form(sp.cos(2 * t1))
    (sin(theta1)*cos(theta2) + sin(theta2)*cos(theta1), 2*cos(theta1)**2 - 1)
    """
    compound = [f for f in e.atoms(sp.sin, sp.cos) if not is_variable(f.args[0])]
    return sp.expand_trig(e) if compound else e


def angles_in(exprs: Iterable, candidates: Any = None) -> list[sp.Symbol]:
    """The symbols inside sin/cos (after expanding sums: sin(θ1 + θ2) counts θ1 and θ2), sorted by name;
    only those among ``candidates`` when given.

    >>> import sympy as sp
    >>> t, t1, t2 = sp.symbols("t theta1 theta2", real=True)
    >>> L = sp.Symbol("L", positive=True)
    >>> angles_in([L * sp.cos(t1 + t2), sp.sin(t)]), angles_in([sp.cos(t1 + t2)], candidates=[t2])
    ([t, theta1, theta2], [theta2])
    """
    found: set = set()
    for e in exprs:
        for f in single_angle_form(sp.sympify(e)).atoms(sp.sin, sp.cos):
            found |= {s for s in f.args[0].free_symbols if candidates is None or s in candidates}
    return sorted(found, key=str)


class TrigRing:
    """Polynomials in s_i = sin θ_i, c_i = cos θ_i and other generators, reduced modulo s_i² + c_i² − 1.

    ``TrigRing(exprs, angles=None, opaque=False)`` builds the ring for the expressions ``exprs``
    (brought to single-angle form first):

    * ``angles``: the θ_i whose sin/cos become s_i, c_i; by default every argument of a sin/cos.
    * ``opaque=False`` (exact mode, for zero tests): the expressions must be polynomials in the sines and
      cosines of *variables* (symbols, θ(t), θ̇(t)) and in variables; floats count at their exact binary
      values; anything else raises :class:`NotTrigPolynomial`.
      ``opaque=True`` (display mode): any other subexpression free of the s_i, c_i (√L, 1/L, sin of a
      non-angle) becomes a generator of its own, floats stay floats. ``opaque`` may also be a predicate
      ``atom -> bool`` deciding which such subexpressions are allowed.

    ``ring.normal_form(e)`` is the reduced ring element, ``ring.to_expr(p)`` the SymPy expression again.

    >>> import sympy as sp
    >>> t = sp.Symbol("theta1", real=True)
    >>> ring = TrigRing([sp.sin(t)**3 + sp.sin(t) * sp.cos(t)**2, sp.sin(t)**2])
    >>> ring.to_expr(ring.normal_form(sp.sin(t)**3 + sp.sin(t) * sp.cos(t)**2))   # sin θ (sin²θ + cos²θ)
    sin(theta1)
    >>> ring.to_expr(ring.normal_form(sp.sin(t)**2))   # degree ≤ 1 in sin θ
    1 - cos(theta1)**2
    """

    def __init__(
        self, exprs: Iterable, angles: Sequence | None = None, opaque: bool | Callable[[sp.Expr], bool] = False
    ):
        self.exact = opaque is False
        allow = (lambda a: True) if opaque is True else (opaque or None)
        exprs = [self._prepare(sp.sympify(e)) for e in exprs]
        angle_set = None if angles is None else set(angles)
        trig: dict = {}  # angle -> True (seen)
        variables: dict = {}
        others: dict = {}
        consts: dict = {}
        seen: set = set()

        def is_angle_trig(x) -> bool:
            if not isinstance(x, (sp.sin, sp.cos)):
                return False
            a = x.args[0]
            if angle_set is not None:
                return a in angle_set
            return is_variable(a) or not self.exact

        def scan(x):
            if x in seen:
                return
            seen.add(x)
            if is_angle_trig(x):
                trig[x.args[0]] = True
            elif is_variable(x):
                variables[x] = True
            elif x.is_Number or (x.is_number and not x.has(sp.sin, sp.cos)):
                if not x.is_Rational:
                    consts[x] = True
            elif x.is_Add or x.is_Mul:
                for a in x.args:
                    scan(a)
            elif x.is_Pow and x.exp.is_Integer and x.exp >= 0:
                scan(x.base)
            elif allow is not None and not any(is_angle_trig(f) for f in x.atoms(sp.sin, sp.cos)) and allow(x):
                others[x] = True
            else:
                raise NotTrigPolynomial(x)

        for e in exprs:
            scan(e)
        if angles is None:
            angles = sorted(trig, key=sp.default_sort_key)
        self.angles = tuple(angles)
        #: the angles whose sine or cosine occurs in ``exprs``
        self.found = tuple(a for a in self.angles if a in trig)
        self.variables = tuple(sorted(variables, key=sp.default_sort_key))
        self.others = tuple(sorted(others, key=sp.default_sort_key))
        self.domain = construct_domain(list(consts), extension=True)[0] if consts else sp.QQ
        k = len(self.angles)
        self.s = {a: sp.Dummy(f"s_{a}") for a in self.angles}
        self.c = {a: sp.Dummy(f"c_{a}") for a in self.angles}
        # generators: s_i, c_i (lex order: s before c, so the normal form has degree ≤ 1 in each s_i),
        # then the variables and other atoms (ring symbols: themselves when a Symbol, else a Dummy)
        rest = self.variables + self.others
        syms = (
            [self.s[a] for a in self.angles]
            + [self.c[a] for a in self.angles]
            + [g if isinstance(g, sp.Symbol) else sp.Dummy() for g in rest]
        )
        self.atoms = tuple([sp.sin(a) for a in self.angles] + [sp.cos(a) for a in self.angles] + list(rest))
        #: the SymPy symbol standing for each generator in ``to_expr(p, trig=False)``
        self.symbols = tuple(syms[: 2 * k]) + rest
        if not syms:  # a ring needs a generator: a constant expression
            syms = [sp.Dummy()]
            self.atoms = self.symbols = tuple(syms)
        self.ring, *self.gens = _ring(syms, self.domain)
        self._table = dict(zip(self.atoms, self.gens))
        self._memo: dict = {}
        self._binomials: dict = {}  # h -> the terms (c exponent, coefficient) of (1 − c²)^h
        self.relations = [self.gens[i] ** 2 + self.gens[k + i] ** 2 - 1 for i in range(k)]
        self._owner = {i: self.angles[i % k] for i in range(2 * k)}
        self._owner.update({2 * k + j: g for j, g in enumerate(rest)})
        self._back = {**{self.s[a]: sp.sin(a) for a in self.angles}, **{self.c[a]: sp.cos(a) for a in self.angles}}

    def _prepare(self, e: sp.Expr) -> sp.Expr:
        e = single_angle_form(e)
        if self.exact and e.has(sp.Float):  # a float is taken at its exact binary value
            e = e.xreplace({f: sp.Rational(f) for f in e.atoms(sp.Float)})
        return e

    # ------------------------------------------------------------------------------------------
    def from_expr(self, e: Any):
        """e as a ring element (not yet reduced); :class:`NotTrigPolynomial` if it does not fit the ring."""
        e = self._prepare(sp.sympify(e))
        R, table, memo, domain = self.ring, self._table, self._memo, self.domain

        def conv(x):
            if x in table:
                return table[x]
            if x in memo:
                return memo[x]
            if x.is_Number or (x.is_number and not x.has(sp.sin, sp.cos)):
                try:
                    out = R(domain.from_sympy(x))
                except Exception as err:  # a constant outside the domain, e.g. E**x
                    raise NotTrigPolynomial(x) from err
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
                raise NotTrigPolynomial(x)
            memo[x] = out
            return out

        return conv(e)

    def reduce(self, p):
        """The normal form of the ring element p modulo s_i² + c_i² − 1 (degree ≤ 1 in every s_i).

        Term by term: s_i^(2h+e) = s_i^e (1 − c_i²)^h, expanded by the binomial theorem. The relations are
        a Gröbner basis, so this is the same unique remainder as SymPy's ``p.rem(relations)``, in one pass
        over the terms (``rem`` looks for the leading term again after every step: quadratic in the terms,
        most of the time of a wide Jacobian's singular set). Inexact (float) coefficients go through ``rem``,
        whose order of operations the floats' last bits depend on.
        """
        if not self.relations or not p:
            return p
        if not self.domain.is_Exact:
            return p.rem(self.relations)
        k, dom, table = len(self.angles), self.domain, self._binomials
        acc: dict = {}
        get = acc.get
        for monom, coeff in p.iterterms():
            high = [i for i in range(k) if monom[i] >= 2]
            if not high:
                acc[monom] = get(monom, dom.zero) + coeff
                continue
            base = list(monom)
            parts = []
            for i in high:
                h, base[i] = divmod(monom[i], 2)
                if h not in table:
                    table[h] = [(2 * j, dom.convert((-1) ** j * math.comb(h, j))) for j in range(h + 1)]
                parts.append(table[h])
            for choice in itertools.product(*parts):
                m, c = base[:], coeff
                for i, (e, b) in zip(high, choice):
                    m[k + i] += e
                    c = c * b
                m = tuple(m)
                acc[m] = get(m, dom.zero) + c
        out = self.ring.zero
        for m, c in acc.items():
            if c:
                out[m] = c
        return out

    def normal_form(self, e: Any):
        """The reduced ring element of the expression e."""
        return self.reduce(self.from_expr(e))

    def to_expr(self, p, trig: bool = True, collect: bool = False) -> sp.Expr:
        """The SymPy expression of a ring element: in sin θ_i, cos θ_i, or (``trig=False``) in the
        polynomial variables s_i, c_i (Dummy symbols; :meth:`to_trig` turns them back).

        ``collect=True`` gathers the terms of each product of sines and cosines: (L + θ2) cos θ1
        rather than L cos θ1 + θ2 cos θ1.
        """
        symbols = self.atoms if trig else self.symbols
        if not collect:
            return p.as_expr(*symbols)
        k2 = 2 * len(self.angles)
        groups: dict = {}
        for monom, coeff in p.terms():
            groups.setdefault(monom[:k2], {})[monom[k2:]] = coeff
        to_sympy, rest = self.domain.to_sympy, symbols[k2:]
        terms = []
        for tm, coeffs in groups.items():
            coeff = sp.Add(*[to_sympy(c) * sp.Mul(*[g**e for g, e in zip(rest, m)]) for m, c in coeffs.items()])
            terms.append(coeff * sp.Mul(*[g**e for g, e in zip(symbols[:k2], tm)]))
        return sp.Add(*terms)

    def to_trig(self, e: sp.Expr) -> sp.Expr:
        """s_i → sin θ_i, c_i → cos θ_i in an expression made by ``to_expr(p, trig=False)``."""
        return e.xreplace(self._back)

    def depends_on(self, p) -> set:
        """The angles and the other generators (variables, atoms) that the ring element p involves."""
        if not p:
            return set()
        used = [i for i, d in enumerate(p.degrees()) if d > 0]
        return {self._owner[i] for i in used if i in self._owner}


def normal_form_zero(e: Any) -> bool | None:
    """Whether e ≡ 0, decided by the normal form modulo sin² + cos² − 1 when e (or its numerator) is a
    polynomial in sines, cosines and symbols with exact coefficients; ``None`` when it is of another form
    (√L, exp, a constant SymPy cannot compute with exactly). True and False are both proofs.

    >>> import sympy as sp
    >>> x, L = sp.symbols("x L")
    >>> normal_form_zero(L * (sp.sin(x)**2 + sp.cos(x)**2) - L), normal_form_zero(sp.sin(2*x) - sp.sin(x))
    (True, False)
    >>> normal_form_zero(sp.sqrt(L) - 1) is None, normal_form_zero(sp.sin(6) - 2*sp.sin(3)*sp.cos(3)) is None
    (True, True)
    """
    e = sp.sympify(e)
    if e == 0:
        return True
    if any(not a.args[0].free_symbols for a in single_angle_form(e).atoms(sp.sin, sp.cos, sp.tan)):
        return None  # sin 6 and 2 sin 3 cos 3 would be independent generators: no proof either way
    for f in (e, None):
        if f is None:
            f = sp.fraction(sp.together(e))[0]  # a rational function is 0 exactly where its numerator is
        try:
            ring = TrigRing([f])  # exact mode: NotTrigPolynomial unless a polynomial in sin/cos
            if ring.domain.is_EX:  # constants SymPy cannot do exact arithmetic with
                raise NotTrigPolynomial(f)
            return not ring.normal_form(f)
        except NotTrigPolynomial:
            continue
    return None
