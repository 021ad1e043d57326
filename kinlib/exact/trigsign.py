"""Proofs that a trigonometric polynomial never vanishes (used to drop impossible singular conditions).

A condition found by :func:`kinlib.singularities.singular_configurations` is a polynomial P in
s_i = sin θ_i, c_i = cos θ_i (revolute joints), prismatic joint values and parameters, in the normal form
of :class:`kinlib.trigpoly.TrigRing`. :func:`proves_nonzero` returns True only with a proof that P ≠ 0
for *every* real angle, every real prismatic value, every real parameter and every positive parameter
(symbols declared ``positive=True``); False means "not shown" (P may or may not vanish). The proofs:

* **box bound**: with s_i, c_i ∈ [−1, 1], a term a·m·t (m a monomial in positive parameters, t in the
  s_i, c_i) is ≥ a·m when t = 1, ≥ min(a, 0)·m when every exponent in t is even (t ∈ [0, 1]) and ≥ −|a|·m
  otherwise; terms with a real (unbounded) variable must have even exponents, no odd trig part and a > 0
  (then ≥ 0). If the sum of the bounds has only positive coefficients, P ≥ that sum > 0
  (e.g. 1 + L² sin²θ = 1 + L² − L² cos²θ ≥ 1);
* **one angle**: P = A + B sin θ + C cos θ (A, B, C free of θ) has minimum A − √(B² + C²), so
  A > 0 and A² − B² − C² > 0 prove P > 0;
* **one variable of degree 2**: a x² + b x + c > 0 for every real x when a > 0 and 4ac − b² > 0
  (e.g. 1 + (L + d)² for a prismatic d);

applied recursively to the smaller conditions, and to −P.

>>> import sympy as sp
>>> from kinlib.trigpoly import TrigRing
>>> L, t = sp.Symbol("L", positive=True), sp.Symbol("t", real=True)
>>> ring = TrigRing([L**2 * sp.sin(t)**2 + 1], [t], opaque=True)
>>> proves_nonzero(ring, ring.normal_form(L**2 * sp.sin(t)**2 + 1))
True
>>> proves_nonzero(ring, ring.normal_form(L - sp.cos(t)))   # zero when L ≤ 1
False
"""

from __future__ import annotations

__all__ = ["proves_nonzero", "proves_positive", "generator_kinds"]

_MAX_TERMS = 400
_MAX_DEPTH = 4


def generator_kinds(ring) -> list[str]:
    """For each generator of a :class:`~kinlib.trigpoly.TrigRing`: 's' / 'c' (sine, cosine of an angle),
    'pos' (a positive parameter: a symbol or atom SymPy knows is positive) or 'real' (any other variable).

    >>> import sympy as sp
    >>> from kinlib.trigpoly import TrigRing
    >>> L, d, t = sp.Symbol("L", positive=True), sp.Symbol("d", real=True), sp.Symbol("t", real=True)
    >>> generator_kinds(TrigRing([L * sp.sin(t) + d], [t], opaque=True))   # sin t, cos t, L > 0, d real
    ['s', 'c', 'pos', 'real']
    """
    k = len(ring.angles)
    kinds = ["s"] * k + ["c"] * k
    for g in ring.variables + ring.others:
        kinds.append("pos" if getattr(g, "is_positive", False) else "real")
    return kinds[: ring.ring.ngens]


def _sign(ring, coeff) -> int | None:
    """Exact sign of a coefficient (None when undecided)."""
    v = ring.domain.to_sympy(coeff)
    if v.is_positive:
        return 1
    if v.is_negative:
        return -1
    if v.is_zero:
        return 0
    return None


def _box(ring, p, kinds) -> bool:
    bound: dict = {}
    for monom, coeff in p.terms():
        sgn = _sign(ring, coeff)
        if sgn is None:
            return False
        trig = [e for e, kd in zip(monom, kinds) if kd in ("s", "c") and e]
        real = [e for e, kd in zip(monom, kinds) if kd == "real" and e]
        key = tuple(e if kd == "pos" else 0 for e, kd in zip(monom, kinds))
        if real:
            if sgn < 0 or any(e % 2 for e in real) or any(e % 2 for e in trig):
                return False
            continue  # ≥ 0
        if not trig:
            add = coeff
        elif not any(e % 2 for e in trig):
            if sgn > 0:
                continue  # t ∈ [0, 1]: ≥ 0
            add = coeff
        else:
            add = -coeff if sgn > 0 else coeff  # t ∈ [−1, 1]: ≥ −|a|
        bound[key] = bound.get(key, ring.domain.zero) + add
    bound = {m: c for m, c in bound.items() if c}
    return bool(bound) and all(_sign(ring, c) == 1 for c in bound.values())


def _split(ring, p, idx: int) -> dict:
    """p as {exponent of generator idx: coefficient polynomial}."""
    R = ring.ring
    out: dict = {}
    for monom, coeff in p.terms():
        e = monom[idx]
        m = list(monom)
        m[idx] = 0
        out[e] = out.get(e, R.zero) + R({tuple(m): coeff})
    return out


def proves_positive(ring, p, kinds: list[str] | None = None, depth: int = 0) -> bool:
    """True only when p > 0 is proved for all admissible values (see the module docstring).

    >>> import sympy as sp
    >>> from kinlib.trigpoly import TrigRing
    >>> L, d, t = sp.Symbol("L", positive=True), sp.Symbol("d", real=True), sp.Symbol("t", real=True)
    >>> ring = TrigRing([1 + (L + d)**2, 2 + sp.cos(t)], opaque=True)
    >>> proves_positive(ring, ring.normal_form(1 + (L + d)**2)), proves_positive(ring, ring.normal_form(2 + sp.cos(t)))
    (True, True)
    >>> proves_positive(ring, ring.normal_form(-2 - sp.cos(t)))   # negative everywhere: not positive
    False
    """
    if kinds is None:
        kinds = generator_kinds(ring)
    if not p:
        return False
    if p.is_ground:
        return _sign(ring, p.LC) == 1
    if len(p.terms()) > _MAX_TERMS:
        return False
    if _box(ring, p, kinds):
        return True
    if depth >= _MAX_DEPTH:
        return False
    degs = p.degrees()
    k = len(ring.angles)
    # one angle at a time: A + B s + C c
    for i in range(k):
        ds, dc = degs[i], degs[k + i]
        if ds == 0 and dc == 0 or ds > 1 or dc > 1:
            continue
        parts = _split(ring, p, i)
        A_B = {e: _split(ring, q, k + i) for e, q in parts.items()}
        if 1 in A_B and 1 in A_B[1]:  # a sin·cos term
            continue
        A = A_B.get(0, {}).get(0, ring.ring.zero)
        C = A_B.get(0, {}).get(1, ring.ring.zero)
        B = A_B.get(1, {}).get(0, ring.ring.zero)
        if proves_positive(ring, A, kinds, depth + 1) and proves_positive(
            ring, ring.reduce(A * A - B * B - C * C), kinds, depth + 1
        ):
            return True
    # one real (then positive) variable of degree exactly 2
    for want in ("real", "pos"):
        for idx, kd in enumerate(kinds):
            if kd != want or degs[idx] != 2:
                continue
            parts = _split(ring, p, idx)
            a, b, c = (parts.get(e, ring.ring.zero) for e in (2, 1, 0))
            if proves_positive(ring, a, kinds, depth + 1) and proves_positive(
                ring, ring.reduce(4 * a * c - b * b), kinds, depth + 1
            ):
                return True
    return False


def proves_nonzero(ring, p, kinds: list[str] | None = None) -> bool:
    """True only when p ≠ 0 is proved for every real angle, real variable and positive parameter
    (p > 0 or p < 0 everywhere); False when not shown.

    >>> import sympy as sp
    >>> from kinlib.trigpoly import TrigRing
    >>> L, t = sp.Symbol("L", positive=True), sp.Symbol("t", real=True)
    >>> ring = TrigRing([-2 - sp.cos(t), L - sp.cos(t)], opaque=True)
    >>> proves_nonzero(ring, ring.normal_form(-2 - sp.cos(t)))   # −2 − cos t ≤ −1
    True
    >>> proves_nonzero(ring, ring.normal_form(L - sp.cos(t)))    # vanishes for L ≤ 1: not shown
    False
    """
    if kinds is None:
        kinds = generator_kinds(ring)
    return proves_positive(ring, p, kinds) or proves_positive(ring, -p, kinds)
