"""Display forms of exact results, and the matrix identity test built on kinlib's one zero test.

``is_identically_zero(M)`` decides whether every entry of M is 0 for *all* values of its symbols
(an identity such as sin²θ + cos²θ − 1, or J_b − Ad_{T⁻¹} J_s), exactly and fast, entry by entry through
:func:`kinlib.exactfield.decide_zero`: see its docstring. ``readable``, ``readable_fold`` and
``readable_ratio`` write exact numbers (a configuration's sines and cosines) in a readable, equal form.

``simplify_for_display(M)`` works entry by entry:

1. write the entry as a polynomial in s_i = sin θ_i, c_i = cos θ_i (and the other symbols);
2. take its normal form modulo s_i² + c_i² − 1 (degree ≤ 1 in every s_i; :mod:`kinlib.trigpoly`),
   which cancels the terms that only add up to zero;
3. fold sums of products back into sines and cosines of angle sums (``fu.TR10i``:
   cos a cos b − sin a sin b → cos(a + b)), without constant phase shifts (no √2 cos(x + π/4)),
   and pull out common factors (``factor_terms``).

With ``phase_shifts=True`` step 3 keeps TR10i's constant phases (a cos x − a sin x → √2 a cos(x + π/4)),
the form the printed solutions use.

The result is exactly equal to the input (each step is an identity). On the UR5's space Jacobian it
takes a fraction of a second, where ``sp.simplify`` of each entry takes minutes and ``trigsimp`` 10–15 s.
Numeric code is generated from the *unsimplified* expression (see :mod:`kinlib.codegen`).
"""

from __future__ import annotations

import numbers
from typing import Any

import numpy as np
import sympy as sp
from sympy.simplify.fu import TR10i

from .._backend import check_real_finite, describe
from .field import decide_zero
from .trigpoly import NotTrigPolynomial, TrigRing, single_angle_form

__all__ = ["simplify_for_display", "is_identically_zero", "readable", "readable_fold", "readable_ratio"]


def _display_entry(e: sp.Expr, phase_shifts: bool = False) -> sp.Expr:
    if not e.atoms(sp.sin, sp.cos):
        return sp.factor_terms(sp.expand(e)) if e.free_symbols else e
    try:
        ring = TrigRing([e], opaque=True)  # every sin/cos argument is an angle; √L, 1/L ... as they are
        reduced = ring.to_expr(ring.normal_form(e), collect=True)
    except NotTrigPolynomial:  # e.g. trig functions inside a square root: leave the entry as it is
        return sp.factor_terms(TR10i(sp.expand(single_angle_form(e))))
    folded = TR10i(reduced)
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

    >>> import sympy as sp
    >>> from kinlib.robots import planar_2r
    >>> simplify_for_display(planar_2r().fk()[:2, 3])   # the 2R arm's p(θ), folded from products of sines and cosines
    Matrix([
    [L1*cos(theta1) + L2*cos(theta1 + theta2)],
    [L1*sin(theta1) + L2*sin(theta1 + theta2)]])
    >>> t = sp.Symbol("theta1", real=True)
    >>> simplify_for_display(sp.cos(t) - sp.sin(t)), simplify_for_display(sp.cos(t) - sp.sin(t), phase_shifts=True)
    (-sin(theta1) + cos(theta1), sqrt(2)*cos(theta1 + pi/4))
    """
    if not isinstance(phase_shifts, (bool, np.bool_)):
        raise TypeError(f"phase_shifts must be True or False, got {describe(phase_shifts)}")
    if isinstance(M, sp.MatrixBase):
        for e in M:
            _finite(e, "M")
        return sp.Matrix(M).applyfunc(lambda e: _display_entry(e, phase_shifts))
    if isinstance(M, (str, bytes, bool, np.bool_)) or not isinstance(M, (sp.Expr, int, float)):
        raise TypeError(f"M must be a SymPy Matrix or expression, got {describe(M)}")
    return _display_entry(_finite(sp.sympify(M), "M"), phase_shifts)


def _finite(e: Any, name: str) -> sp.Expr:
    """e if it is a finite, real SymPy expression (symbols declared real); refused otherwise (I, nan, oo, zoo, x)."""
    if not isinstance(e, sp.Expr):
        raise TypeError(f"{name} must hold SymPy expressions or numbers, got an entry {describe(e)}")
    return check_real_finite(e, name)


# ----------------------------------------------------------------------------------------------
# exact zero test
# ----------------------------------------------------------------------------------------------
def _entry_is_zero(e: sp.Expr) -> bool:
    try:
        return decide_zero(e)
    except ValueError:  # documented: False may mean "not shown" for forms outside the exact routes
        return False


def _entries(M: Any, name: str) -> list:
    if isinstance(M, sp.MatrixBase):
        return [_finite(e, name) for e in M]
    if isinstance(M, (str, bytes, bool, np.bool_)) or M is None:
        raise TypeError(f"{name} must be a SymPy expression or Matrix (or numbers), got {describe(M)}")
    if isinstance(M, (complex, np.complexfloating)):
        raise TypeError(f"{name} must be real, got the complex number {M!r}")
    if isinstance(M, (sp.Expr, numbers.Number)):
        return [_finite(sp.sympify(M), name)]
    if isinstance(M, (list, tuple, np.ndarray)):
        if any(
            isinstance(e, (str, bytes, bool, np.bool_, complex, np.complexfloating)) or e is None
            for e in np.asarray(M, dtype=object).flat
        ):
            raise TypeError(
                f"{name} must hold real SymPy expressions or numbers, got {describe(M)} with a "
                f"string, bool, None or complex entry"
            )
        try:
            flat = list(sp.Matrix(M))
        except Exception as err:
            raise TypeError(f"{name} must be a SymPy expression or Matrix (or numbers), got {describe(M)}") from err
        return [_finite(e, name) for e in flat]
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
    Entries without symbols (sin 3, √2 …) and entries in positive lengths only are decided in the exact field
    of :mod:`kinlib.exactfield`. Each entry goes through :func:`kinlib.exactfield.decide_zero`, kinlib's one
    zero test; where it cannot decide (square roots of symbols, exponentials, half angles θ/2 that the
    exponential rewrite does not settle) the answer is False, meaning "not shown".

    Much faster than ``sp.simplify(e) == 0``: no trigsimp, and no SymPy ``expand`` of large products.

    >>> import sympy as sp
    >>> t = sp.Symbol("theta", real=True)
    >>> is_identically_zero(sp.Matrix([sp.sin(t)**2 + sp.cos(t)**2 - 1, sp.sin(2*t) - 2*sp.sin(t)*sp.cos(t)]))
    True
    >>> is_identically_zero(sp.sin(t) - sp.cos(t))
    False
    """
    return all(_entry_is_zero(e) for e in _entries(M, "M"))


# ----------------------------------------------------------------------------------------------
# readable forms of exact numbers (identities only: never a guess)
# ----------------------------------------------------------------------------------------------
def readable(e: sp.Expr) -> sp.Expr:
    """An exactly equal, readable form of an exact number (or expression in parameters).

    >>> import sympy as sp
    >>> readable((sp.sqrt(2) + 2) / sp.sqrt(2)), readable(sp.sin(3) / -sp.cos(3))
    (1 + sqrt(2), -sin(3)/cos(3))
    """
    if e == 0 or e.is_Rational:
        return e
    num, den = sp.fraction(sp.cancel(sp.together(e))) if not e.has(sp.sin, sp.cos) else sp.fraction(sp.together(e))
    num, den = readable_fold(num), readable_fold(den)
    if den == 1:
        return num
    if den.could_extract_minus_sign():
        num, den = -num, -den
    return num / den


def readable_fold(e: sp.Expr) -> sp.Expr:
    """e (a polynomial in sines, cosines, constants and parameters) reduced by sin² + cos² = 1 and folded.

    >>> import sympy as sp
    >>> readable_fold(sp.cos(1) * sp.cos(2) - sp.sin(1) * sp.sin(2)), readable_fold((sp.sqrt(2) + 1) ** 2)
    (cos(3), 2*sqrt(2) + 3)
    """
    if e.has(sp.sin, sp.cos):
        try:
            return simplify_for_display(e)
        except Exception:  # pragma: no cover - display only
            return sp.factor_terms(TR10i(sp.expand(e)))
    if e.is_Rational:
        return e
    return sp.expand(sp.radsimp(e)) if e.is_number else sp.factor_terms(sp.radsimp(sp.expand(e)))


def readable_ratio(num: sp.Expr, den: sp.Expr) -> sp.Expr:
    """num/den for display, with common polynomial factors (in the sines and cosines) cancelled.

    >>> import sympy as sp
    >>> t = sp.Symbol("theta1", real=True)
    >>> readable_ratio(sp.sin(2 * t), sp.sin(t)), readable_ratio(sp.sin(3) * sp.cos(3), sp.cos(3) ** 2)
    (2*cos(theta1), sin(3)/cos(3))
    """
    if num == 0:
        return sp.S.Zero
    try:
        ring = TrigRing([num, den], opaque=True)
        if ring.domain.is_EX:
            raise NotTrigPolynomial(num)
        pn, pd = ring.normal_form(num), ring.normal_form(den)
        g = pn.gcd(pd)
        pn, pd = pn.exquo(g), pd.exquo(g)
        num, den = ring.to_expr(pn, collect=True), ring.to_expr(pd, collect=True)
    except (NotTrigPolynomial, Exception):
        pass
    return readable(num / den) if den != 1 else readable(num)
