"""Exact numbers at a configuration: the field K(tan(g/2), parameters) in which "is it zero?" is a proof.

After substituting the joint values, every entry of a Jacobian is a number built from sin a and cos a of the
configuration's angles a, algebraic constants (√2, cos π/7, …) and the positive parameters (link lengths).
Write each angle as a = r + qπ with r, q rational. Let g > 0 be the largest rational with every r an integer
multiple n·g of it, and t = tan(g/2). Then

    cos(n g) + i sin(n g) = (1 + i t)^{2n} / (1 + t²)^n,

and cos(qπ), sin(qπ) are algebraic, so every entry is a rational function of t (and of the parameters) with
coefficients in an algebraic number field K. For g ≠ 0, t is **transcendental** (Lindemann–Weierstrass:
e^{ig} is transcendental for algebraic g ≠ 0), so such a rational function vanishes at t = tan(g/2) *if and
only if* it is identically zero: exact arithmetic in K(t, L1, L2, …) decides every zero test.
:class:`ExactField` does the conversion (numerators over powers of 1 + t², no rational-function gcds);
:class:`NotExact` says when a number is outside this class (an angle √2, a constant π next to a
transcendental angle, angles more than ``MAX_MULTIPLE`` common measures apart).

:func:`mp_value` evaluates such numbers to ``FALLBACK_DIGITS + 40`` digits (shared subexpressions once), for the
certified numerics of :mod:`kinlib.exact`.
"""

from __future__ import annotations

import functools
import itertools
import math
import threading
from fractions import Fraction
from typing import Any

import sympy as sp
from sympy.polys.constructor import construct_domain
from sympy.polys.fields import field as _field
from sympy.polys.matrices import DomainMatrix
from sympy.polys.polyerrors import CoercionFailed
from sympy.polys.rings import ring as _ring

from .trigpoly import NotTrigPolynomial, TrigRing, normal_form_zero

__all__ = [
    "ExactField",
    "PointLift",
    "NotExact",
    "exact_is_zero",
    "decide_zero",
    "mp_value",
    "mp_matrix",
    "mp_context",
    "MAX_MULTIPLE",
    "FALLBACK_DIGITS",
]

#: the largest |n| with every angle's rational part n·g, above which the exact method is not used
MAX_MULTIPLE = 240
#: significant digits of the numeric fallback and of the certified numerics
FALLBACK_DIGITS = 60


class NotExact(ValueError):
    """The exact method does not apply to these numbers (the message says why).

    >>> import sympy as sp
    >>> ExactField([sp.sin(sp.sqrt(2))])   # an angle √2: no exact zero test (a ValueError)
    Traceback (most recent call last):
    ...
    kinlib.exact.field.NotExact: the angle sqrt(2) is not a rational number plus a rational multiple of π
    """


# ----------------------------------------------------------------------------------------------
# the exact field K(t, parameters)
# ----------------------------------------------------------------------------------------------
def _angle_parts(a: sp.Expr) -> tuple:
    """(r, q) with a = r + qπ, both rational; NotExact otherwise."""
    if a.free_symbols:
        raise NotExact(f"the angle {a} depends on the parameters {', '.join(map(str, a.free_symbols))}")
    a = sp.expand(a)
    q = a.coeff(sp.pi)
    r = sp.expand(a - q * sp.pi)
    if not (q.is_Rational and r.is_Rational):
        raise NotExact(f"the angle {a} is not a rational number plus a rational multiple of π")
    return r, q


def _re_im_power(m: int) -> tuple:
    """Integer coefficient lists (low degree first) of Re and Im of (1 + i t)^m, m ≥ 0."""
    re, im = [0] * (m + 1), [0] * (m + 1)
    for k in range(m + 1):
        c = math.comb(m, k)
        if k % 2 == 0:
            re[k] = c if k % 4 == 0 else -c
        else:
            im[k] = c if k % 4 == 1 else -c
    return re, im


@functools.lru_cache(maxsize=4096)
def _field_constant(K, c: sp.Expr):
    """The constant ``c`` as an element of the number field ``K`` (exact; SymPy's ``to_number_field``).

    Cached: finding the element means minimal polynomials and a field isomorphism (milliseconds each), and the
    same few constants (cos and sin of the configuration's multiples of π, √2, …) recur in every field built
    for a notebook. Both K and c are immutable, so the cache cannot change an answer."""
    return K.convert(c) if c.is_Rational else K.from_sympy(c)


def _is_algebraic_constant(c) -> bool:
    """Whether the number c is built from rationals, rational powers and sin/cos of rational multiples of π."""
    for f in c.atoms(sp.Function):
        if not (isinstance(f, (sp.sin, sp.cos)) and (f.args[0] / sp.pi).is_Rational):
            return False
    bare = c.xreplace({f: sp.Dummy() for f in c.atoms(sp.sin, sp.cos)})
    return not bare.has(sp.pi, sp.E) and all(
        not p.is_Pow or p.exp.is_Rational for p in sp.preorder_traversal(bare) if isinstance(p, sp.Basic)
    )


def _scan_constants(x, repl: dict, g, consts: set, extra: set) -> None:
    """Collect the constants of the entry part x: algebraic ones into ``consts``, π and e into ``extra`` (only
    when there is no trig angle, ``g`` = 0); anything else raises NotExact. ``repl``: the sines and cosines of
    the angles, which are the field's generator, not constants."""
    if x.is_Rational or x in repl or x.is_Symbol:
        return
    if x is sp.pi or x is sp.E:
        if g != 0:
            raise NotExact(f"the constant {x} appears next to the transcendental sin/cos of {g}")
        extra.add(x)
    elif x.is_Add or x.is_Mul:
        for arg in x.args:
            _scan_constants(arg, repl, g, consts, extra)
    elif x.is_Pow and x.exp.is_Integer:
        _scan_constants(x.base, repl, g, consts, extra)
    elif x.is_number and _is_algebraic_constant(x):
        consts.add(x)
    else:
        raise NotExact(
            f"the entry part {x} is not a rational function of sines and cosines, algebraic numbers and parameters"
        )


class ExactField:
    """Exact numbers (and expressions in positive parameters) at a configuration as elements of K(t, params).

    ``ExactField(exprs)`` finds the angles, g, K and the parameters of ``exprs`` (raises :class:`NotExact` when
    they are outside the class of the module docstring); ``convert(e)`` is e in the fraction field (zero exactly
    when e is zero), ``pair(e)`` its numerator over a power of 1 + t², ``matrix(M)`` M over K[t, params] with each
    row's denominators cleared (same rank, pivots and row space).

    >>> import sympy as sp
    >>> f = ExactField([sp.sin(10), sp.cos(sp.Rational(1, 2))])
    >>> f.g, f.multiples[sp.sin(10)]
    (1/2, (20, 0))
    >>> f.convert(sp.sin(10) - 2 * sp.sin(5) * sp.cos(5)) == 0
    True
    """

    def __init__(self, exprs: list):
        exprs = [e.rewrite(sp.cos, sp.sin) if e.has(sp.tan, sp.cot, sp.sec, sp.csc) else e for e in exprs]
        trig = set()
        for e in exprs:
            trig |= e.atoms(sp.sin, sp.cos)
        parts = {}
        for f in trig:
            parts[f] = _angle_parts(f.args[0])
        rs = [r for r, _ in parts.values() if r != 0]
        if rs:
            g = sp.Rational(math.gcd(*[int(r.p) for r in rs]), math.lcm(*[int(r.q) for r in rs]))
        else:
            g = sp.S.Zero
        self.g = g
        self.multiples = {f: (int(r / g) if r != 0 else 0, q) for f, (r, q) in parts.items()}
        biggest = max((abs(n) for n, _ in self.multiples.values()), default=0)
        if biggest > MAX_MULTIPLE:
            raise NotExact(
                f"the angles are {biggest} multiples of their common measure {g} apart "
                f"(the exact method goes up to {MAX_MULTIPLE})"
            )
        self.params = sorted(set().union(*[e.free_symbols for e in exprs]), key=str) if exprs else []
        # algebraic constants: cos qπ, sin qπ of every angle, and every other constant in the entries
        consts = set()
        for _n, q in self.multiples.values():
            consts |= {sp.cos(q * sp.pi), sp.sin(q * sp.pi)}
        repl = {f: sp.Dummy() for f in trig}

        extra = set()
        for e in exprs:
            _scan_constants(e, repl, g, consts, extra)
        self.extra = sorted(extra, key=str)  # π, e: generators (transcendental; no trig angle then)
        algebraic_consts = sorted((c for c in consts if not c.is_Rational), key=sp.default_sort_key)
        self._known: dict = {}
        if algebraic_consts:
            K, elems = construct_domain(algebraic_consts, extension=True)
            # the constants come out of the primitive-element construction already written in K: converting
            # them again (to_number_field: a field isomorphism per constant) took minutes for π/7 next to 3π/5
            self._known = dict(zip(algebraic_consts, elems))
            if K.is_EX:
                raise NotExact(
                    f"the constants {algebraic_consts} are not algebraic numbers SymPy can do arithmetic with"
                )
        else:
            K = sp.QQ
        self.K = K
        self.t = sp.Dummy("t")
        gens = [self.t] + self.extra + self.params
        self.F, *self.gens = _field(gens, K)
        self.domain = self.F.to_domain()
        self._gen = dict(zip(self.extra + self.params, self.gens[1:]))
        ring = self.F.ring
        self.ring = ring
        tt = ring.gens[0]
        self.one_t2 = 1 + tt**2
        self._pow_cache = {0: ring.one}
        self._atom = {}
        self._powers: dict = {}
        for f, (n, q) in self.multiples.items():
            self._atom[f] = self._trig(f, n, q)
        self._memo = {}

    def _trig(self, f, n: int, q) -> tuple:
        """cos/sin(n g + qπ) = num / (1 + t²)^|n| as (num, |n|)."""
        m, tt = abs(n), self.ring.gens[0]
        if m not in self._powers:
            re, im = _re_im_power(2 * m)
            self._powers[m] = (
                sum((c * tt**k for k, c in enumerate(re) if c), self.ring.zero),
                sum((c * tt**k for k, c in enumerate(im) if c), self.ring.zero),
            )
        cn, sn = self._powers[m]
        sn = sn if n >= 0 else -sn
        cq, sq = self._kconst(sp.cos(q * sp.pi)), self._kconst(sp.sin(q * sp.pi))
        return (cn * cq - sn * sq if isinstance(f, sp.cos) else sn * cq + cn * sq), m

    def _new_atom(self, f) -> tuple:
        """A sine or cosine the field was not built from: fine when its angle is a multiple of g (plus qπ with
        cos qπ, sin qπ in K); NotExact otherwise."""
        r, q = _angle_parts(f.args[0])
        n = r / self.g if self.g != 0 else (sp.S.Zero if r == 0 else sp.S.Half)
        if not n.is_Integer or abs(n) > MAX_MULTIPLE:
            raise NotExact(f"{f} is not on the angle lattice of this field (multiples of {self.g})")
        try:
            out = self._trig(f, int(n), q)
        except Exception as err:
            raise NotExact(f"cos/sin of {q}π is outside the constants of this field") from err
        self._atom[f] = out
        return out

    def _kconst(self, c):
        if c in self._known:
            return self.ring(self._known[c])
        try:
            return self.ring(_field_constant(self.K, c))
        except CoercionFailed as err:  # e.g. 1/(1 + π²): not algebraic, so not in any number field K
            raise NotExact(f"{c} is not an algebraic number") from err

    def to_ratio(self, x) -> tuple[sp.Expr, sp.Expr]:
        """A field element back as SymPy (numerator, denominator), polynomials in sin g, cos g, the constants
        and the parameters: t = tan(g/2) written as sin g/(1 + cos g) (an identity, never a guess).
        :func:`kinlib.display.readable_ratio` makes one readable fraction of them."""
        if self.g != 0 and self.K == sp.QQ and not self.extra and not self.params:
            return self._ratio_in_sin_cos(x)
        gens = [self.t] + list(self.extra) + list(self.params)
        num, den = x.numer.as_expr(*gens), x.denom.as_expr(*gens)
        if self.g != 0:
            s, c = sp.sin(self.g), sp.cos(self.g)
            num, den = sp.fraction(
                sp.together(sp.expand(num).subs(self.t, s / (1 + c)) / sp.expand(den).subs(self.t, s / (1 + c)))
            )
        return sp.expand(num), sp.expand(den)

    def _ratio_in_sin_cos(self, x) -> tuple[sp.Expr, sp.Expr]:
        """:meth:`to_ratio` for rational coefficients and no parameters, in polynomial arithmetic over
        QQ[sin g, cos g]: the same pair as SymPy's route (t → sin g/(1 + cos g) in the expanded numerator and
        denominator, ``together``, ``fraction``, ``expand``), which expands every power of 1 + cos g as an
        expression (seconds per entry of a UR5's J⁺). With n(t) = Σ a_k t^k of degree N and lowest degree l,
        n = Σ a_k s^k (1 + c)^(N−k) / (1 + c)^N; ``together`` takes out the content (gcd of the a_k) and s^l,
        and the quotient of the two contents, s^(l_n − l_d) and (1 + c)^(N_d − N_n) go to the side where
        their exponent is positive."""
        s, c = sp.sin(self.g), sp.cos(self.g)
        R, S, C = _ring([s, c], sp.QQ)
        parts = []
        for p in (x.numer, x.denom):
            terms = {m[0]: sp.QQ.to_sympy(co) for m, co in p.terms()}
            top, low = max(terms), min(terms)
            content = sp.Rational(math.gcd(*[q.p for q in terms.values()]), math.lcm(*[q.q for q in terms.values()]))
            powers = {0: R.one}
            for e in range(1, top - low + 1):
                powers[e] = powers[e - 1] * (1 + C)
            poly = R.zero
            for k, q in terms.items():
                poly += R(sp.QQ.from_sympy(q / content)) * S ** (k - low) * powers[top - k]
            parts.append((poly, content, low, top))
        (A, c_num, l_num, n_num), (B, c_den, l_den, n_den) = parts
        ratio, e, f = c_num / c_den, l_num - l_den, n_den - n_num
        num = R(ratio.p) * S ** max(e, 0) * (1 + C) ** max(f, 0) * A
        den = R(ratio.q) * S ** max(-e, 0) * (1 + C) ** max(-f, 0) * B
        return num.as_expr(), den.as_expr()

    def __repr__(self) -> str:
        return f"ExactField(t = tan({self.g}/2), K = {self.K}, parameters {list(self.params)})"

    def _lift(self, pair, e: int):
        num, k = pair
        if e == k:
            return num
        d = e - k
        if d not in self._pow_cache:
            self._pow_cache[d] = self.one_t2**d
        return num * self._pow_cache[d]

    def pair(self, e: sp.Expr):
        """e = num / (1 + t²)^k as (num ∈ K[t, params], k); NotExact for a negative power of a non-constant
        (then :meth:`convert` works in the fraction field)."""
        if e.has(sp.tan, sp.cot, sp.sec, sp.csc):
            e = e.rewrite(sp.cos, sp.sin)
        memo, R = self._memo, self.ring

        def conv(x):
            if x in memo:
                return memo[x]
            if x in self._atom:
                out = self._atom[x]
            elif x in self._gen:
                out = (R(self._gen[x].numer), 0)
            elif isinstance(x, (sp.sin, sp.cos)):
                out = self._new_atom(x)
            elif x.is_Rational or (x.is_number and not x.has(sp.sin, sp.cos) and not x.has(*self._gen)):
                try:
                    out = (self._kconst(x), 0)
                except Exception as err:
                    raise NotExact(f"the constant {x} is outside the constants of this field") from err
            elif x.is_Add:
                parts = [conv(a) for a in x.args]
                k = max(p[1] for p in parts)
                out = (sum((self._lift(p, k) for p in parts), R.zero), k)
            elif x.is_Mul:
                num, k = R.one, 0
                for a in x.args:
                    pn, pk = conv(a)
                    num, k = num * pn, k + pk
                out = (num, k)
            elif x.is_Pow and x.exp.is_Integer and x.exp >= 0:
                pn, pk = conv(x.base)
                out = (pn ** int(x.exp), pk * int(x.exp))
            elif x.is_Pow and x.exp.is_Integer and x.base.is_number and not x.base.has(*self._atom):
                out = (self._kconst(x), 0)
            else:
                raise NotExact(f"{x} is not a polynomial")
            memo[x] = out
            return out

        return conv(e)

    def convert(self, e: sp.Expr):
        """e as an element of the fraction field K(t, params)."""
        try:
            num, k = self.pair(e)
            return self.F(num) / self.F(self.one_t2) ** k if k else self.F(num)
        except NotExact:
            pass
        if e.has(sp.tan, sp.cot, sp.sec, sp.csc):
            e = e.rewrite(sp.cos, sp.sin)
        if e.is_Add:
            return sum((self.convert(a) for a in e.args), self.F.zero)
        if e.is_Mul:
            out = self.F.one
            for a in e.args:
                out *= self.convert(a)
            return out
        if e.is_Pow and e.exp.is_Integer:
            return self.convert(e.base) ** int(e.exp)
        raise NotExact(f"cannot convert {e}")  # pragma: no cover - scan() refused it already

    def matrix(self, M: sp.Matrix) -> DomainMatrix:
        """M over the polynomial ring K[t, params]: each row multiplied by the lcm of its denominators (a
        nonzero factor: powers of 1 + t² and of the parameters), which changes neither the rank nor the
        pivots nor the row space."""
        ring = self.ring
        rows = []
        for i in range(M.rows):
            try:
                pairs = [self.pair(M[i, j]) for j in range(M.cols)]
                k = max(p[1] for p in pairs)
                rows.append([self._lift(p, k) for p in pairs])
                continue
            except NotExact:
                pass
            elems = [self.convert(M[i, j]) for j in range(M.cols)]
            den = ring.one
            for e in elems:
                den = den.lcm(e.denom)
            rows.append([e.numer * den.exquo(e.denom) for e in elems])
        return DomainMatrix(rows, M.shape, ring.to_domain())

    def field_matrix(self, M: sp.Matrix) -> DomainMatrix:
        return DomainMatrix(
            [[self.convert(M[i, j]) for j in range(M.cols)] for i in range(M.rows)], M.shape, self.domain
        )


# ----------------------------------------------------------------------------------------------
# singular poses: zero through independent angles (no number field)
# ----------------------------------------------------------------------------------------------
#: the nice parts ν of an angle Σ n_i φ_i + ν: multiples of π/12 (sin ν, cos ν in Q(√2, √3))
_NICE = 12
#: at most this many independent angles φ_i (3^k sign patterns are tried for each new angle)
MAX_LIFT_ANGLES = 9


class PointLift:
    """Zero tests at a configuration through angles taken as independent: what a singular pose needs.

    At a singular pose a minor vanishes because of the arm's structure (sin θ3 = 0 at θ3 = π, whatever the
    other joints are), not because of a coincidence between 2π/7 and 3π/11. Each sine or cosine in the matrix
    is sin/cos of an angle a = r + qπ (r, q rational); the angles are written as a = Σ n_i φ_i + ν with
    n_i ∈ {−1, 0, 1} (or ±2 on at most two φ_i), ν a multiple of π/12 and φ_i the matrix's own angles (smallest first: the joint values
    before their sums), checked exactly (r and q compared as rationals). ``lifted(e)`` replaces every sine and
    cosine by the polynomial in sin φ_i, cos φ_i (and sin ν, cos ν) it equals at the configuration. A
    polynomial that is 0 for *every* φ (its normal form modulo sin² + cos² − 1 is 0,
    :class:`kinlib.trigpoly.TrigRing`) is 0 at the configuration: a proof of "zero" that needs no number field
    (Q(cos 2π/7, cos 3π/11, …) has degree in the hundreds). It proves nothing about "nonzero" (certified
    numerics do that), and a zero by coincidence is left to the other exact routes.

    >>> import sympy as sp
    >>> a, b = 2 * sp.pi / 7, 3 * sp.pi / 11
    >>> e = sp.sin(a + b) - sp.sin(a) * sp.cos(b) - sp.cos(a) * sp.sin(b)   # 0: sin(a + b) is sin(34π/77)
    >>> lift = PointLift([e])
    >>> lift.values   # 34π/77 = π − 2π/7 − 3π/11
    [2*pi/7, 3*pi/11]
    >>> lift.is_zero(e)
    True
    """

    def __init__(self, exprs: list):

        atoms: set = set()
        for e in exprs:
            atoms |= e.atoms(sp.sin, sp.cos)
        if any(e.has(sp.tan, sp.cot, sp.sec, sp.csc) for e in exprs):
            raise NotExact("tan/cot/sec/csc: not lifted")
        parts = {}
        for f in atoms:
            r, q = _angle_parts(f.args[0])  # NotExact for √2, or an angle with parameters
            parts[f] = (Fraction(int(r.p), int(r.q)), Fraction(int(q.p), int(q.q)))
        order = sorted(
            set(parts.values()),
            key=lambda a: (max(abs(a[0].numerator), a[0].denominator) * max(abs(a[1].numerator), a[1].denominator), a),
        )
        basis: list = []
        combo: dict = {}  # angle -> (coefficients, nu)
        for a in order:
            found = self._express(a, basis)
            if found is None:
                if len(basis) >= MAX_LIFT_ANGLES:
                    raise NotExact(f"more than {MAX_LIFT_ANGLES} independent angles")
                basis.append(a)
                found = (tuple([0] * (len(basis) - 1) + [1]), Fraction(0))
            combo[a] = found
        self.values = [
            sp.Rational(r.numerator, r.denominator) + sp.Rational(q.numerator, q.denominator) * sp.pi for r, q in basis
        ]
        self.angles = [sp.Dummy(f"phi{i}", real=True) for i in range(len(basis))]
        self.table = {}
        for f, a in parts.items():
            coeffs, nu = combo[a]
            arg = sum((n * p for n, p in zip(coeffs, self.angles) if n), sp.S.Zero)
            arg += sp.Rational(nu.numerator, nu.denominator) * sp.pi
            self.table[f] = sp.expand_trig(type(f)(arg))
        self._back = {}
        for p, v in zip(self.angles, self.values):
            self._back[sp.sin(p)], self._back[sp.cos(p)] = sp.sin(v), sp.cos(v)

    @staticmethod
    def _express(a, basis):
        """(coefficients, ν) with a = Σ n_i b_i + νπ, ν a multiple of 1/12: n_i ∈ {−1, 0, 1} (sums of joint
        values), then n_i ∈ {±1, ±2} on at most two angles (θ3 = π/2 − 2θ2); None when neither fits."""
        r, q = a
        k = len(basis)
        tries = [(size, (1, -1)) for size in range(1, k + 1)] + [(size, (2, -2, 1, -1)) for size in (1, 2)]
        for size, choices in tries:
            for support in itertools.combinations(range(k), size):
                for signs in itertools.product(choices, repeat=size):
                    if len(choices) == 4 and all(abs(s) == 1 for s in signs):
                        continue  # tried already
                    rr, qq = r, q
                    for i, s in zip(support, signs):
                        rr -= s * basis[i][0]
                        qq -= s * basis[i][1]
                    if rr == 0 and (qq * _NICE).denominator == 1:
                        coeffs = [0] * k
                        for i, s in zip(support, signs):
                            coeffs[i] = s
                        return tuple(coeffs), qq
        return None

    def lifted(self, e: sp.Expr) -> sp.Expr:
        """e with every sine and cosine written in the independent angles (equal at the configuration)."""
        return e.xreplace(self.table)

    def ring(self, exprs: list) -> TrigRing:
        """The exact :class:`TrigRing` of lifted expressions (the angles φ_i; parameters as variables)."""
        ring = TrigRing(exprs, self.angles)
        if ring.domain.is_EX:
            raise NotExact("constants outside SymPy's exact domains")
        return ring

    def is_zero(self, e: sp.Expr) -> bool:
        """True when e is 0 for every value of the independent angles (so 0 here); False: not shown. A quotient
        is 0 where its numerator is (its denominator is the lift of e's own denominators, nonzero here)."""
        try:
            x = self.lifted(e)
            if any(p.exp.is_negative for p in x.atoms(sp.Pow)):
                x = sp.fraction(sp.together(x))[0]
            return not self.ring([x]).normal_form(x)
        except (NotTrigPolynomial, NotExact):
            return False

    def at_point(self, e: sp.Expr) -> sp.Expr:
        """A lifted expression (in sin φ_i, cos φ_i) at the configuration again."""
        return e.xreplace(self._back)


def exact_is_zero(e: Any) -> bool:
    """Whether the number (or expression in positive parameters) e is exactly 0, proved.

    e may hold sin and cos of angles r + qπ (r, q rational), algebraic numbers and positive parameters; it is
    written in the field K(tan(g/2), params) of the module docstring, where "zero" is decided exactly.
    Raises ValueError when e is outside that class (then no exact decision is made).

    >>> import sympy as sp
    >>> exact_is_zero(sp.sin(3)**2 + sp.cos(3)**2 - 1), exact_is_zero(sp.sin(10) - 2*sp.sin(5)*sp.cos(5))
    (True, True)
    >>> exact_is_zero(sp.sin(sp.Rational(1, 2)) - sp.Rational(479, 1000))
    False
    """
    e = sp.sympify(e)
    if e == 0:
        return True
    try:
        return not ExactField([e]).convert(e)
    except NotExact as err:
        raise ValueError(f"no exact zero test for {e}: {err}") from None


def decide_zero(e: Any, what: str = "an entry") -> bool:
    """Decide e = 0 with a proof, never a guess: kinlib's one zero test, for numbers and for expressions.

    e is a number (a configuration's sines and cosines, algebraic constants), an expression in positive
    parameters (link lengths; "zero" then means zero for all of them), or an expression in other symbols
    (joint variables: "zero" means identically zero).

    * nonzero number: a value above 10⁻³⁰ at ``FALLBACK_DIGITS + 40`` digits (:func:`mp_value`);
    * exact arithmetic in K(tan(g/2), params) (:class:`ExactField`) for sines and cosines of angles r + qπ
      (r, q rational), algebraic numbers and parameters;
    * the normal form modulo sin² + cos² − 1 (:func:`kinlib.trigpoly.normal_form_zero`) for polynomials and
      rational functions in the sines and cosines of symbols: True and False are both proofs;
    * zero only: sin and cos written with exponentials and expanded, the minimal polynomial x of an
      algebraic number, or ``sp.simplify(e) == 0``.

    Anything else raises ``ValueError`` (an honest "cannot decide"), never a silent answer.

    >>> decide_zero(sp.sin(3)**2 + sp.cos(3)**2 - 1), decide_zero(sp.sqrt(2)/2 - sp.Rational(7, 10))
    (True, False)
    >>> x = sp.Symbol("x")
    >>> decide_zero(sp.sin(2*x) - 2*sp.sin(x)*sp.cos(x)), decide_zero(sp.sin(x) - sp.cos(x))
    (True, False)
    """
    e = sp.sympify(e)
    if e == 0:
        return True
    if e.is_Rational:
        return False
    if not e.free_symbols:
        mpmath = mp_context()
        try:
            with mpmath.workdps(FALLBACK_DIGITS + 40):
                if abs(mp_value(e, {}, mpmath)) > mpmath.mpf(10) ** -30:
                    return False
        except (TypeError, ValueError):  # e.g. a complex intermediate: the exact routes below decide
            pass
    if e.has(sp.sin, sp.cos):  # zero for every value of the angles taken independently: zero (no number field)
        try:
            if PointLift([e]).is_zero(e):
                return True
        except NotExact:
            pass
    try:
        return not ExactField([e]).convert(e)
    except NotExact:
        pass
    identity = normal_form_zero(e)
    if identity is not None:
        return identity
    try:
        if sp.expand(sp.expand_trig(e).rewrite(sp.exp)) == 0:
            return True
    except Exception:  # pragma: no cover - a route that fails is just not a proof
        pass
    if not e.free_symbols:
        x = sp.Dummy("x")
        try:
            if sp.minimal_polynomial(e, x) == x:
                return True
        except Exception:  # not algebraic (sin 3 ...), or too hard
            pass
    if sp.simplify(e) == 0:
        return True
    raise ValueError(
        f"could not decide exactly whether {what} = {e} is zero (no exact identity was found"
        + ("" if e.free_symbols else f" and its value is below 1e-30 at {FALLBACK_DIGITS + 40} digits")
        + "); evaluate numerically instead"
    )


_mp_local = threading.local()


def mp_context():
    """This thread's own mpmath context (``mpmath.MPContext``), created on first use: kinlib sets precision only
    there (``with ctx.workdps(n):``), never on the global ``mpmath.mp``, so threads never share a precision
    (two threads in ``mpmath.workdps(60)`` and ``workdps(100)`` saw each other's) and the user's is never changed.

    >>> import mpmath
    >>> ctx = mp_context()
    >>> with ctx.workdps(60):
    ...     print(ctx.nstr(ctx.pi, 40), mpmath.mp.dps)
    3.141592653589793238462643383279502884197 15
    >>> ctx is mp_context()   # the same one for this thread
    True
    """
    ctx = getattr(_mp_local, "ctx", None)
    if ctx is None:
        import mpmath

        ctx = _mp_local.ctx = mpmath.MPContext()
    return ctx


def mp_value(e: sp.Expr, memo: dict, ctx=None):
    """e to ``FALLBACK_DIGITS + 40`` digits (call inside ``ctx.workdps``), shared subexpressions evaluated once.
    ``ctx``: the mpmath context (:func:`mp_context`; None: the global ``mpmath.mp``).

    >>> import mpmath, sympy as sp
    >>> memo, ctx = {}, mp_context()
    >>> with ctx.workdps(FALLBACK_DIGITS + 40):
    ...     v = mp_value(sp.sin(10) - 2 * sp.sin(5) * sp.cos(5), memo, ctx)   # sin 2a − 2 sin a cos a = 0
    ...     w = mp_value(sp.sqrt(2), memo, ctx)
    >>> abs(v) < ctx.mpf(10) ** -80, sp.sin(5) in memo, ctx.nstr(w, 20)
    (True, True, '1.4142135623730950488')
    """
    if ctx is None:
        import mpmath

        ctx = mpmath.mp
    mpmath = ctx
    if e in memo:
        return memo[e]
    if e.is_Rational:
        v = mpmath.mpf(e.p) / e.q
    elif e is sp.pi:
        v = +mpmath.pi
    elif e is sp.E:
        v = mpmath.e
    elif e.is_Add:
        v = mpmath.fsum(mp_value(a, memo, ctx) for a in e.args)
    elif e.is_Mul:
        v = mpmath.fprod(mp_value(a, memo, ctx) for a in e.args)
    elif e.is_Pow and e.exp.is_Rational:
        b = mp_value(e.base, memo, ctx)
        v = b ** int(e.exp) if e.exp.is_Integer else b ** (mpmath.mpf(e.exp.p) / e.exp.q)
    elif isinstance(e, sp.sin):
        v = mpmath.sin(mp_value(e.args[0], memo, ctx))
    elif isinstance(e, sp.cos):
        v = mpmath.cos(mp_value(e.args[0], memo, ctx))
    else:
        v = mpmath.mpf(str(sp.N(e, mpmath.dps)))
    memo[e] = v
    return v


def mp_matrix(A: sp.Matrix, ctx=None):
    """A as an mpmath matrix of ``ctx`` (default: this thread's :func:`mp_context`), entries to ~100 digits
    (the SVD then runs at ``FALLBACK_DIGITS``).

    >>> import sympy as sp
    >>> ctx = mp_context()
    >>> X = mp_matrix(sp.Matrix([[sp.cos(1), -sp.sin(1)], [sp.sin(1), sp.cos(1)]]))   # a rotation: det = 1
    >>> with ctx.workdps(FALLBACK_DIGITS):
    ...     print(X.rows, X.cols, ctx.nstr(ctx.det(X), 50))
    2 2 1.0
    """
    mpmath = mp_context() if ctx is None else ctx
    if A.free_symbols:
        raise ValueError(
            "no exact decision is possible here and the numeric fallback needs numbers: J still has "
            f"the parameters {', '.join(map(str, sorted(A.free_symbols, key=str)))}; substitute them"
        )
    memo: dict = {}
    with mpmath.workdps(FALLBACK_DIGITS + 40):
        return mpmath.matrix([[mp_value(A[i, j], memo, mpmath) for j in range(A.cols)] for i in range(A.rows)])
