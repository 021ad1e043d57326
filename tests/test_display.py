"""simplify_for_display: exactly equal to its input, shorter, and in the textbook's angle-sum form."""
import random

import numpy as np
import pytest
import sympy as sp

from kinlib import robots
from kinlib.display import simplify_for_display


def _num(M, subs):
    return np.array(M.xreplace(subs).evalf(30), dtype=float)


def _random_subs(chain, seed):
    rng = random.Random(seed)
    subs = {t: sp.Rational(rng.randint(-300, 300), 97) for t in chain.thetas}
    subs.update({p: sp.Rational(rng.randint(1, 200), 61) for p in chain.params})
    return subs


@pytest.mark.parametrize("make", [robots.planar_offset_3r, robots.spatial_rppr, robots.cart_pole,
                                  robots.planar_3r, robots.planar_rpp, robots.ur5])
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
    x = sp.Symbol("x")
    assert simplify_for_display(sp.sin(x) ** 2 + sp.cos(x) ** 2) == 1
    assert simplify_for_display(sp.Integer(3)) == 3
    with pytest.raises(TypeError, match="M must be a SymPy Matrix or expression"):
        simplify_for_display("sin(x)")
    with pytest.raises(TypeError, match="M must be"):
        simplify_for_display([1, 2])
