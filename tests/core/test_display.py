"""simplify_for_display: exactly equal to its input, shorter, and in the textbook's angle-sum form."""

import random

import numpy as np
import pytest
import sympy as sp

from kinlib import robots
from kinlib.display import is_identically_zero, simplify_for_display


def _num(M, subs):
    """M at the point subs, in floating point (lambdify: exact rational evaluation of the UR5's unsimplified
    geometric Jacobian takes seconds)."""
    syms = sorted(subs, key=str)
    f = sp.lambdify(syms, sp.Matrix(M), "numpy")
    return np.array(f(*[float(subs[k]) for k in syms]), dtype=float)


def _random_subs(chain, seed):
    rng = random.Random(seed)
    subs = {t: sp.Rational(rng.randint(-300, 300), 97) for t in chain.thetas}
    subs.update({p: sp.Rational(rng.randint(1, 200), 61) for p in chain.params})
    return subs


@pytest.mark.parametrize(
    "make",
    [robots.planar_offset_3r, robots.spatial_rppr, robots.cart_pole, robots.planar_3r, robots.planar_rpp, robots.ur5],
)
@pytest.mark.parametrize("what", ["fk", "jacobian_space", "jacobian_body", "jacobian_geometric"])
def test_equal_to_input(make, what):
    chain = make()
    M = getattr(chain, what)()
    D = simplify_for_display(M)
    assert D.shape == M.shape
    for seed in range(3):
        s = _random_subs(chain, seed)
        assert np.allclose(_num(D, s), _num(M, s), atol=1e-12, rtol=0)
    assert sum(sp.count_ops(e) for e in D) <= sum(sp.count_ops(e) for e in M)


def test_exact_identity_planar():
    chain = robots.planar_3r()
    M = chain.fk()
    D = simplify_for_display(M)
    for a, b in zip(D, M):
        assert sp.simplify(sp.expand_trig(a - b)) == 0


def test_textbook_forms():
    L1, L2, L3 = sp.symbols("L1 L2 L3", positive=True)
    t1, t2, t3 = robots.planar_3r().thetas
    D = simplify_for_display(robots.planar_3r().fk())
    assert D[0, 3] == L1 * sp.cos(t1) + L2 * sp.cos(t1 + t2) + L3 * sp.cos(t1 + t2 + t3)
    assert D[0, 0] == sp.cos(t1 + t2 + t3)
    # no sqrt(2) phase shifts in the planar offset arm
    D = simplify_for_display(robots.planar_offset_3r().fk())
    assert not D.has(sp.sqrt(2)) and not D.has(sp.pi)
    # UR5: the three parallel joints appear as one angle sum, and sin^2 + cos^2 terms are gone
    ur5 = robots.ur5()
    t = ur5.thetas
    Js = simplify_for_display(ur5.jacobian_space())
    assert Js[2, 4] == -sp.cos(t[1] + t[2] + t[3])
    assert Js[5, 2] == sp.Rational(17, 40) * sp.cos(t[1])
    assert sp.expand(Js[5, 3] - (425 * sp.cos(t[1]) + 392 * sp.cos(t[1] + t[2])) / 1000) == 0
    assert not Js[5, 3].has(sp.sin)
    assert not any(p.exp >= 2 for p in Js.atoms(sp.Pow) if isinstance(p.base, (sp.sin, sp.cos)))


def test_expression_and_errors():
    x = sp.Symbol("x", real=True)
    assert simplify_for_display(sp.sin(x) ** 2 + sp.cos(x) ** 2) == 1
    # issue 25: symbols not declared real are refused here too (one check for every public function)
    with pytest.raises(ValueError, match=r"M must be real: the symbol\(s\) y are not declared real"):
        simplify_for_display(sp.sin(sp.Symbol("y")))
    assert simplify_for_display(sp.Integer(3)) == 3
    with pytest.raises(TypeError, match="M must be a SymPy Matrix or expression"):
        simplify_for_display("sin(x)")
    with pytest.raises(TypeError, match="M must be"):
        simplify_for_display([1, 2])


# ------------------------------------------------------------------------------------------------
# phase_shifts=True: the printed solutions' √2 cos(x + π/4) form, still exactly equal
# ------------------------------------------------------------------------------------------------
def test_phase_shifts_printed_form():
    chain = robots.planar_offset_3r()
    L = chain.params[0]
    t1, t2, t3 = chain.thetas
    T = chain.fk()
    D = simplify_for_display(T, phase_shifts=True)
    # problem set eq. (17): p_x = L c123 + L c1 + √2 L cos(θ1 + θ2 + π/4)
    assert sp.expand(D[0, 3] - L * (sp.cos(t1 + t2 + t3) + sp.cos(t1) + sp.sqrt(2) * sp.cos(t1 + t2 + sp.pi / 4))) == 0
    assert is_identically_zero(D - T)
    Jb = simplify_for_display(chain.jacobian_body(), phase_shifts=True)
    assert Jb[3, 1] == -sp.sqrt(2) * L * sp.cos(t3 + sp.pi / 4)  # eq. (20)
    for seed in range(2):
        s = _random_subs(chain, seed)
        assert np.allclose(_num(Jb, s), _num(chain.jacobian_body(), s), atol=1e-12, rtol=0)
    assert not simplify_for_display(T).has(sp.sqrt(2))  # default: no phase shifts


# ------------------------------------------------------------------------------------------------
# is_identically_zero: exact identity test
# ------------------------------------------------------------------------------------------------
x, y, z = sp.symbols("x y z", real=True)


@pytest.mark.parametrize(
    "expr",
    [
        sp.sin(x) ** 2 + sp.cos(x) ** 2 - 1,
        sp.sin(x + y) - sp.sin(x) * sp.cos(y) - sp.cos(x) * sp.sin(y),
        sp.cos(2 * x) - sp.cos(x) ** 4 + sp.sin(x) ** 4,
        sp.sin(x) ** 2 - sp.sin(x) ** 4 - sp.sin(x) ** 2 * sp.cos(x) ** 2,
        sp.sqrt(2) * sp.cos(x + sp.pi / 4) - sp.cos(x) + sp.sin(x),
        1 / (z * (z + 1)) - 1 / z + 1 / (z + 1),
        sp.tan(x) - sp.sin(x) / sp.cos(x),
        sp.Integer(0),
    ],
)
def test_identities_are_zero(expr):
    assert is_identically_zero(expr) is True


@pytest.mark.parametrize(
    "expr",
    [
        sp.sin(x),
        sp.sin(x) ** 2 + sp.cos(x) ** 2 - 1 + sp.Rational(1, 10**12),  # numerically ~0, exactly not
        sp.sin(x + y) - sp.sin(x) * sp.cos(y) + sp.cos(x) * sp.sin(y),
        sp.sqrt(2) * sp.cos(x + sp.pi / 4) - sp.cos(x) - sp.sin(x),
        z * sp.sin(x) ** 2 + z * sp.cos(x) ** 2,
        sp.Integer(3),
    ],
)
def test_nonzero_is_not_zero(expr):
    assert is_identically_zero(expr) is False
    # independent: the expression is nonzero at some point (exact rational evaluation, 50 digits)
    vals = [
        sp.N(expr.subs({x: sp.Rational(a, 7), y: sp.Rational(b, 5), z: sp.Rational(3, 2)}), 50)
        for a, b in [(1, 2), (3, -4), (-5, 1), (2, 9)]
    ]
    assert any(abs(v) > 1e-40 for v in vals)


def test_body_jacobian_is_adjoint_of_space_jacobian():
    """J_b = Ad_{T⁻¹} J_s exactly, for the symbolic robots (the difference is a large trig polynomial)."""
    import kinlib

    for chain in (robots.planar_offset_3r(), robots.spatial_rppr(), robots.ur5()):
        Js, Jb, T = chain.jacobian_space(), chain.jacobian_body(), chain.fk()
        gap = Jb - kinlib.adjoint(kinlib.trans_inv(T)) * Js
        assert not all(e == 0 for e in gap)  # not trivially zero as written
        assert is_identically_zero(gap)
        assert not is_identically_zero(Jb - Js)  # J_b ≠ J_s: the test does not say yes to everything


def test_time_functions_and_derivatives():
    """The 1.2 derivation: θ_i(t) and θ̇_i are variables too (chain rule for e^{[S]θ(t)})."""
    import kinlib

    t = sp.Symbol("t", real=True)
    q = sp.Function("theta1", real=True)(t)
    S = kinlib.screw_revolute(sp.Matrix([0, 1, 0]), sp.Matrix([1, 0, 2]))
    E = kinlib.exp6(S, q)
    assert is_identically_zero(E.diff(t) - kinlib.bracket(S) * q.diff(t) * E)
    assert not is_identically_zero(E.diff(t) - kinlib.bracket(S) * E)


def test_agrees_with_simplify_on_random_trig_polynomials():
    rng = random.Random(7)
    atoms = [sp.sin(x), sp.cos(x), sp.sin(y), sp.cos(y), z]
    for _ in range(25):
        e = sum(rng.randint(-2, 2) * sp.Mul(*rng.choices(atoms, k=rng.randint(0, 3))) for _ in range(4))
        ident = e * (sp.sin(x) ** 2 + sp.cos(x) ** 2) - e  # ≡ 0
        assert is_identically_zero(ident)
        assert is_identically_zero(e) == (sp.simplify(e) == 0)


def test_accepts_scalars_matrices_and_lists():
    assert is_identically_zero(0) and is_identically_zero(0.0) and not is_identically_zero(1)
    assert is_identically_zero(sp.zeros(2, 3))
    assert is_identically_zero(sp.Matrix([[sp.sin(x) ** 2 + sp.cos(x) ** 2 - 1, 0]]))
    assert not is_identically_zero(sp.Matrix([[0, 0], [0, sp.cos(x)]]))
    assert is_identically_zero([[sp.cos(x) ** 2 - 1 + sp.sin(x) ** 2], [0]])
    assert is_identically_zero(np.zeros((2, 2)))


@pytest.mark.parametrize("bad", ["sin(x)**2 + cos(x)**2 - 1", None, {"a": 1}, ["x", 0], True, sp.Eq(x, x)])
def test_bad_input(bad):
    with pytest.raises(TypeError, match="M must"):
        is_identically_zero(bad)


# ------------------------------------------------------------------------------------------------
# the shared normal form modulo sin² + cos² − 1 (kinlib.trigpoly), behind both functions above and
# kinlib.singularities / kinlib.manipulability
# ------------------------------------------------------------------------------------------------
def _values_at(e, seed):
    rng = random.Random(seed)
    pt = {s: sp.Rational(rng.randint(-300, 300), 97) for s in sorted(e.free_symbols, key=str)}
    return sp.N(e.subs(pt), 30)


def test_normal_form_is_canonical_reduced_and_equal_to_the_input():
    from kinlib.trigpoly import TrigRing

    a = sp.sin(x) ** 3 * sp.cos(y) + z * sp.cos(x + y) + sp.cos(2 * x)
    b = (
        sp.sin(x) * (1 - sp.cos(x) ** 2) * sp.cos(y)
        + z * (sp.cos(x) * sp.cos(y) - sp.sin(x) * sp.sin(y))
        + 2 * sp.cos(x) ** 2
        - 1
    )  # the same function, written differently
    R = TrigRing([a, b])
    assert R.normal_form(a) == R.normal_form(b)  # canonical
    e = R.to_expr(R.normal_form(a))
    assert sp.Poly(e, sp.sin(x), sp.sin(y)).degree_list() <= (1, 1)  # degree ≤ 1 in every sine
    for seed in range(3):  # independent: exact rational points
        assert abs(_values_at(e - a, seed)) < 1e-25


def test_normal_form_collects_and_has_two_modes():
    from kinlib.trigpoly import NotTrigPolynomial, TrigRing

    L = sp.Symbol("L", positive=True)
    e = L * sp.cos(x) + y * sp.cos(x) - z * sp.sin(x) ** 3 - z * sp.sin(x) * sp.cos(x) ** 2
    R = TrigRing([e])
    assert R.to_expr(R.normal_form(e), collect=True) == (L + y) * sp.cos(x) - z * sp.sin(x)
    # exact mode (zero tests): only polynomials in sin/cos and symbols; floats at their binary value
    with pytest.raises(NotTrigPolynomial):
        TrigRing([sp.sqrt(L) * sp.sin(x)])
    R = TrigRing([0.5 * sp.sin(x)])
    assert R.to_expr(R.normal_form(0.5 * sp.sin(x))) == sp.sin(x) / 2
    # display mode: other subexpressions (√L) are generators of their own, floats stay floats
    f = sp.sqrt(L) * (sp.sin(x) ** 2 + sp.cos(x) ** 2) + 0.5 * sp.sin(x)
    R = TrigRing([f], opaque=True)
    out = R.to_expr(R.normal_form(f))
    assert out.has(sp.Float) and sp.nsimplify(out) == sp.sqrt(L) + sp.sin(x) / 2
    with pytest.raises(NotTrigPolynomial):  # sin inside a root: not a polynomial
        TrigRing([sp.sqrt(sp.sin(x))], opaque=True)


def test_one_pass_reduction_is_the_division_remainder():
    """TrigRing.reduce (s_i^2 → 1 − c_i^2 term by term) against SymPy's own division by the relations (an
    independent computation of the unique remainder), with rational and algebraic coefficients, high powers
    and other generators; and degree ≤ 1 in every sine."""
    from kinlib.trigpoly import TrigRing

    L, d = sp.Symbol("L", positive=True), sp.Symbol("d")
    angles = sp.symbols("t1:4", real=True)
    atoms = [*map(sp.sin, angles), *map(sp.cos, angles), L, d]
    rng = random.Random(5)
    for unit in (1, sp.sqrt(2)):
        exprs = [
            sp.Add(
                *[
                    rng.randint(-5, 5)
                    * unit ** rng.randint(0, 1)
                    * sp.Mul(*[rng.choice(atoms) ** rng.randint(0, 5) for _ in range(4)])
                    for _ in range(12)
                ]
            )
            for _ in range(25)
        ]
        ring = TrigRing(exprs, angles)
        for e in exprs:
            p = ring.from_expr(e)
            r = ring.reduce(p)
            assert r == p.rem(ring.relations)
            assert all(m[i] <= 1 for m in r.monoms() for i in range(len(angles)))
