"""The generated numeric code: the numeric forms are the same matrices, and the batched sin/cos
(computed from tan(a/2)) agree with math.sin/math.cos to rounding, at awkward angles too."""

from __future__ import annotations

import math

import modern_robotics as mr
import numpy as np
import pytest
import sympy as sp

import kinlib
from helpers import random_arm
from kinlib import robots
from kinlib.codegen import CompiledMatrix
from kinlib.display import is_identically_zero

CHAINS = {
    "ur5": robots.ur5(),
    "spatial_rppr": robots.spatial_rppr(),  # with its symbolic lengths
    "planar_offset_3r": robots.planar_offset_3r(),
    "cart_pole": robots.cart_pole(),
    "planar_rpp": robots.planar_rpp(),
}


@pytest.mark.parametrize("what", ["fk", "js", "jb", "jg"])
@pytest.mark.parametrize("name", sorted(CHAINS))
def test_numeric_form_is_the_same_matrix(name, what):
    """The shorter expression the code is generated from equals the PoE expression exactly."""
    chain = CHAINS[name]
    short, full = chain._expr(what + "_num"), chain._expr(what)
    assert short.shape == full.shape
    assert is_identically_zero(short - full), f"{name}.{what}"


@pytest.mark.parametrize("kinds", ["RPR", "PRRP"])
def test_numeric_form_of_random_arms_matches_modern_robotics(kinds):
    """Random axes with exact (rational) entries: the generated code against modern_robotics
    (FKinSpace, JacobianSpace, JacobianBody on Ad_{M⁻¹} S, and J = blockdiag(R, R) J_b)."""
    rng = np.random.default_rng(7)
    M, S, kinds = random_arm(rng, len(kinds), kinds)
    chain = kinlib.SerialChain(M, S)
    q = rng.uniform(-np.pi, np.pi, size=(5, chain.n))
    Mf, Sf = np.array(chain.M, dtype=float), np.array(chain.screws, dtype=float)
    Bf = mr.Adjoint(mr.TransInv(Mf)) @ Sf
    for qi in q:
        T = mr.FKinSpace(Mf, Sf, qi)
        Jb = mr.JacobianBody(Bf, qi)
        R = T[:3, :3]
        np.testing.assert_allclose(chain.fk(qi), T, atol=1e-12)
        np.testing.assert_allclose(chain.jacobian_space(qi), mr.JacobianSpace(Sf, qi), atol=1e-12)
        np.testing.assert_allclose(chain.jacobian_body(qi), Jb, atol=1e-12)
        np.testing.assert_allclose(chain.jacobian_geometric(qi), np.vstack([R @ Jb[:3], R @ Jb[3:]]), atol=1e-12)


AWKWARD = [
    0.0,
    -0.0,
    math.pi / 2,
    -math.pi / 2,
    math.pi,
    -math.pi,
    2 * math.pi,
    3 * math.pi / 2,
    1e-300,
    5e-324,
    1e-8,
    math.pi - 1e-12,
    1e3,
    -1e6,
    12345.678,
    math.nextafter(math.pi, 0),
]


def test_batched_sin_cos_agree_with_math_at_awkward_angles():
    x = sp.Symbol("x")
    c = CompiledMatrix(sp.Matrix([[sp.sin(x), sp.cos(x)]]), [x])
    got = c(np.array(AWKWARD)[:, None])[:, 0, :]
    want = np.array([[math.sin(a), math.cos(a)] for a in AWKWARD])
    np.testing.assert_allclose(got, want, atol=4.5e-16, rtol=0)
    with np.errstate(invalid="ignore"):  # NumPy warns, as np.sin(inf) does
        assert np.isnan(c(np.array([[np.nan], [np.inf]]))).all()  # not finite in, not a number out


def test_batched_trig_forms():
    """Only sin, only cos, compound and nested arguments, powers, and several blocks."""
    a, b = sp.symbols("a b", real=True)
    M = sp.Matrix(
        [
            [sp.sin(a), sp.cos(b) ** 2, sp.sin(a + b) * sp.cos(a - 2 * b)],
            [sp.sin(sp.sin(a)), sp.cos(a) * sp.sin(b) - 1, sp.tan(a / 3) + sp.cos(a + b)],
        ]
    )
    c = CompiledMatrix(M, [a, b])
    Q = np.random.default_rng(1).uniform(-10, 10, size=(20000, 2))
    f = sp.lambdify([a, b], list(M), "math")
    want = np.array([f(*q) for q in Q[::97]], dtype=float).reshape(-1, 2, 3)
    np.testing.assert_allclose(c(Q)[::97], want, atol=1e-14, rtol=0)
    np.testing.assert_allclose(np.stack([c(q) for q in Q[::97]]), want, atol=1e-14, rtol=0)


def test_product_of_exponentials_batch_calls_tan_not_sin_cos():
    """Where the time went (np.sin/np.cos on float64 are not vectorized; np.tan is): the batched
    code of the UR5 calls tan once per joint it depends on (T on all six; J_s and the geometric J
    not on θ6, J_b not on θ1) and sin/cos never; the single code keeps math.sin/cos."""
    chain = CHAINS["ur5"]
    for what in ("fk", "js", "jb", "jg"):
        src = chain._compiled(what).source
        single, batch = src.split("def _batch")
        joints = len(chain._expr(what + "_num").free_symbols)
        assert joints == (6 if what == "fk" else 5)
        assert batch.count("tan(") == joints and "sin(" not in batch and "cos(" not in batch, what
        assert "sin(" in single and "tan(" not in single, what
