"""Symbolic condition number and isotropy (issue 11, item 5) against NumPy's SVD at random points."""

from __future__ import annotations

import numpy as np
import pytest
import sympy as sp
from hypothesis import given, settings
from hypothesis import strategies as st

from kinlib import SerialChain, robots
from kinlib.manipulability import condition_number, isotropy
from kinlib.singularities import task_rows

L1, L2 = sp.symbols("L1 L2", positive=True)


def planar_2r():
    return SerialChain(
        sp.Matrix([[1, 0, 0, L1 + L2], [0, 1, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1]]),
        [[0, 0, 1, 0, 0, 0], [0, 0, 1, 0, -L1, 0]],
        name="2R",
    )


def np_cond(J):
    s = np.linalg.svd(np.asarray(J, dtype=float), compute_uv=False)
    return s[0] / s[-1]


CASES = [
    ("2R (vx, vy)", lambda: (planar_2r(), ["vx", "vy"])),
    ("2R planar rows", lambda: (planar_2r(), "planar")),
    ("2R all rows", lambda: (planar_2r(), None)),
    ("3R (vx, vy)", lambda: (robots.planar_3r(), ["vx", "vy"])),
    ("offset 3R (vx, vy)", lambda: (robots.planar_offset_3r(), ["vx", "vy"])),
]


@pytest.mark.parametrize("name, make", CASES, ids=[c[0] for c in CASES])
def test_symbolic_condition_number_and_isotropy_match_numpy_svd(name, make):
    chain, rows = make()
    J = chain.jacobian_geometric()
    if rows is not None:
        J = task_rows(J, rows)
    kappa, iso = condition_number(J), isotropy(J)
    assert not kappa.has(sp.Max, sp.Min) and not iso.has(sp.Max, sp.Min)
    syms = list(chain.thetas) + list(chain.params)
    fk, fi, fJ = (sp.lambdify(syms, e, "numpy") for e in (kappa, iso, J))
    rng = np.random.default_rng(3)
    for _ in range(12):
        vals = list(rng.uniform(-np.pi, np.pi, chain.n)) + list(rng.uniform(0.3, 2.0, len(chain.params)))
        ref = np_cond(fJ(*vals))
        assert np.isclose(float(fk(*vals)), ref, rtol=1e-8)
        assert np.isclose(float(fi(*vals)), 1 / ref, rtol=1e-8)
    # exact at a singular configuration: the isotropy is exactly 0 there, κ infinite
    if rows == ["vx", "vy"] and chain.name in ("2R", "planar_3r"):
        at = {chain.thetas[1]: 0, **({chain.thetas[2]: 0} if chain.n == 3 else {})}
        assert sp.simplify(iso.subs(at)) == 0
        assert kappa.subs(at) in (sp.zoo, sp.oo)


@settings(deadline=None, derandomize=True, max_examples=40)
@given(st.lists(st.integers(-4, 4), min_size=4, max_size=4), st.integers(-3, 3))
def test_constant_matrices_exact(entries, shift):
    """No free symbols: exact eigenvalues of the constant Gram matrix, compared with NumPy."""
    J = sp.Matrix(2, 2, entries) + sp.Matrix([[0, shift], [0, 0]]) * sp.sqrt(2)
    A = np.array(J.evalf(), dtype=float)
    s = np.linalg.svd(A, compute_uv=False)
    k, i = condition_number(J), isotropy(J)
    if s[-1] < 1e-12 * max(s[0], 1):
        assert k == sp.oo and i == 0
    else:
        assert k.is_number and np.isclose(float(k), s[0] / s[-1], rtol=1e-10)
        assert np.isclose(float(i), s[-1] / s[0], rtol=1e-10)
        assert not k.has(sp.Float)


def test_special_values():
    D = sp.Matrix([[2, 0], [0, 1]])
    assert condition_number(D) == 2 and isotropy(D) == sp.Rational(1, 2)
    assert condition_number(sp.Matrix([[1, 1], [1, 1]])) == sp.oo and isotropy(sp.Matrix([[1, 1], [1, 1]])) == 0
    t = sp.Symbol("t", real=True)
    R = sp.Matrix([[1, 0, 0], [0, sp.cos(t), -sp.sin(t)], [0, sp.sin(t), sp.cos(t)]])  # J Jᵀ = I for every t
    assert condition_number(R) == 1 and isotropy(R) == 1
    assert condition_number(sp.Matrix([[sp.cos(t), sp.sin(t)]])) == 1  # k = 1
    # k = 2 with a circle everywhere: κ = 1 exactly
    assert condition_number(sp.Matrix([[sp.cos(t), -sp.sin(t)], [sp.sin(t), sp.cos(t)]])) == 1


def test_three_singular_values_with_free_joints_is_refused_with_the_numeric_alternative():
    J = task_rows(robots.planar_3r().jacobian_geometric(), "planar")
    for f in (condition_number, isotropy):
        with pytest.raises(ValueError, match=r"k = min\(m, n\) = 3.*jacobian_geometric\(q\)"):
            f(J)
    # ... but at a configuration (no free joint symbols, numeric lengths) it is exact
    Jc = task_rows(robots.planar_3r(1, 1, 1).jacobian_geometric([0, sp.pi / 2, sp.pi / 2]), "planar")
    A = np.array(Jc.evalf(), dtype=float)
    assert np.isclose(float(condition_number(Jc)), np.linalg.cond(A), rtol=1e-10)


@pytest.mark.parametrize(
    "bad, exc",
    [
        (np.array([[1.0, np.nan], [0.0, 1.0]]), ValueError),
        (np.array([[1.0, np.inf], [0.0, 1.0]]), ValueError),
        (np.array([[1.0, 1j], [0.0, 1.0]]), TypeError),
        ([[1.0, "2"], [0.0, 1.0]], TypeError),
        ([[True, False], [False, True]], TypeError),
    ],
)
def test_numeric_bad_input_refused(bad, exc):
    for f in (condition_number, isotropy):
        with pytest.raises(exc, match="J"):
            f(bad)
