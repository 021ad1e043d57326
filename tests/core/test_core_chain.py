"""SerialChain: batch = loop, exact symbolic results (no Floats), subs, skeleton, and `import kinlib`."""

from __future__ import annotations

import json
import subprocess
import sys

import modern_robotics as mr
import numpy as np
import pytest
import sympy as sp
from hypothesis import given
from hypothesis import strategies as st

import kinlib
from helpers import FAST, assert_no_floats, assert_sym_equal
from kinlib import robots


def _mr_reference(chain, q):
    """(T, J_s, J_b, geometric J) of a numeric chain at q from modern_robotics (independent of kinlib):
    J_b = JacobianBody(Ad_{M⁻¹} S), J = blockdiag(R, R) J_b."""
    M, S = np.array(chain.M, dtype=float), np.array(chain.screws, dtype=float)
    T = mr.FKinSpace(M, S, q)
    Jb = mr.JacobianBody(mr.Adjoint(mr.TransInv(M)) @ S, q)
    R = T[:3, :3]
    return {
        "fk": T,
        "jacobian_space": mr.JacobianSpace(S, q),
        "jacobian_body": Jb,
        "jacobian_geometric": np.vstack([R @ Jb[:3], R @ Jb[3:]]),
    }


METHODS = ("fk", "jacobian_space", "jacobian_body", "jacobian_geometric", "skeleton")

NUMERIC = {
    "cart_pole": robots.cart_pole(1, sp.Rational(1, 2)),
    "planar_offset_3r": robots.planar_offset_3r(1),
    "spatial_rppr": robots.spatial_rppr(1, 2),
    "planar_3r": robots.planar_3r(1, 1, 1),
    "planar_rpp": robots.planar_rpp(1),
    "ur5": robots.ur5(),
}


# --------------------------------------------------------------------------------------------
# batch = loop
# --------------------------------------------------------------------------------------------
@FAST
@given(st.sampled_from(sorted(NUMERIC)), st.integers(1, 12), st.integers(0, 2**32 - 1))
def test_batch_equals_loop(name, N, seed):
    chain = NUMERIC[name]
    Q = np.random.default_rng(seed).uniform(-np.pi, np.pi, size=(N, chain.n))
    for m in METHODS:
        f = getattr(chain, m)
        batch = f(Q)
        single = np.stack([f(q) for q in Q])
        assert batch.shape == (N, *single.shape[1:]), m
        np.testing.assert_allclose(batch, single, atol=1e-12, rtol=0, err_msg=f"{name}.{m}")


def test_batch_larger_than_a_block_equals_loop():
    """A batch spanning several blocks of the generated code (and a ragged last block)."""
    chain = NUMERIC["ur5"]
    Q = np.random.default_rng(0).uniform(-np.pi, np.pi, size=(9001, 6))
    for m in ("fk", "jacobian_space", "jacobian_geometric"):
        f = getattr(chain, m)
        batch = f(Q)
        idx = [0, 1, 4095, 4096, 4097, 8191, 8192, 9000]
        np.testing.assert_allclose(batch[idx], np.stack([f(Q[i]) for i in idx]), atol=1e-12, rtol=0)
        # and against modern_robotics at the blocks' edges
        for i in idx:
            np.testing.assert_allclose(batch[i], _mr_reference(chain, Q[i])[m], atol=1e-12, rtol=0, err_msg=f"{m}[{i}]")


@pytest.mark.parametrize(
    "q",
    [
        [0.1, 0.2, 0.3],
        (0.1, 0.2, 0.3),
        np.array([0.1, 0.2, 0.3]),
        [0, 1, 2],
        np.array([0, 1, 2]),
        np.array([0.1, 0.2, 0.3], dtype=np.float32),
    ],
)
def test_accepted_numeric_q_forms(q):
    chain = NUMERIC["planar_offset_3r"]
    out = chain.jacobian_space(q)
    assert isinstance(out, np.ndarray) and out.shape == (6, 3) and out.dtype == np.float64
    qa = np.asarray(q, dtype=float)
    # independent: modern_robotics on the screws of problem set eq. (16) typed by hand (L = 1)
    S = np.array([[0, 0, 1, 0, 0, 0], [0, 0, 1, 0, -1, 0], [0, 0, 1, 1, -2, 0]], dtype=float).T
    np.testing.assert_allclose(out, mr.JacobianSpace(S, qa), atol=1e-12)
    assert chain.fk(np.asarray(q, dtype=float)[None, :]).shape == (1, 4, 4)
    assert chain.fk([list(q), list(q)]).shape == (2, 4, 4)


def test_one_joint_chain_accepts_scalar_and_batch():
    S = [[0, 0, 1, 0, 0, 0]]
    M = sp.Matrix([[1, 0, 0, 1], [0, 1, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1]])
    chain = kinlib.SerialChain(M, S, name="pendulum")
    assert chain.n == 1 and chain.joint_types == "R"
    np.testing.assert_allclose(chain.fk([np.pi / 2])[:3, 3], [0, 1, 0], atol=1e-12)
    assert chain.fk(np.zeros((4, 1))).shape == (4, 4, 4)
    assert chain.fk([sp.pi / 2])[:3, 3] == sp.Matrix([0, 1, 0])


# --------------------------------------------------------------------------------------------
# exact results
# --------------------------------------------------------------------------------------------
SYMBOLIC = [
    robots.cart_pole(),
    robots.planar_offset_3r(),
    robots.spatial_rppr(),
    robots.planar_3r(),
    robots.planar_rpp(),
    robots.ur5(),
]


@pytest.mark.parametrize("chain", SYMBOLIC, ids=lambda c: c.name)
def test_symbolic_results_have_no_floats(chain):
    for m in METHODS:
        X = getattr(chain, m)()
        assert isinstance(X, sp.MatrixBase), m
        assert_no_floats(X, f"{chain.name}.{m}()")
        assert X.free_symbols <= set(chain.thetas) | set(chain.params), m
    assert_no_floats(chain.M, "M")
    assert_no_floats(chain.screws, "screws")
    assert_no_floats(chain.body_screws, "body_screws")
    # at an exact configuration
    q = [sp.pi / 4 if t == "R" else sp.Rational(1, 3) for t in chain.joint_types]
    for m in ("fk", "jacobian_space", "jacobian_geometric"):
        X = getattr(chain, m)(q)
        assert_no_floats(X, f"{chain.name}.{m}(q)")
        assert X.free_symbols <= set(chain.params), m


def test_ur5_lengths_are_exact_rationals():
    r = robots.ur5()
    assert r.params == ()
    assert r.M[0, 3] == sp.Rational(817, 1000)  # L1 + L2 = 0.425 + 0.392
    assert robots.ur5(W1=0.109).M == r.M  # a float length becomes the same exact rational
    assert robots.planar_offset_3r(0.5).M[0, 3] == sp.Rational(3, 2)


def test_free_functions_with_exact_input_have_no_floats():
    th = sp.symbols("t1:4", real=True)
    S = sp.Matrix([[0, 0, 1, 0, 0, 0], [0, 1, 0, 0, 0, 1], [0, 0, 0, 0, 0, 1]]).T
    M = sp.Matrix([[1, 0, 0, sp.Rational(1, 2)], [0, 1, 0, 0], [0, 0, 1, 3], [0, 0, 0, 1]])
    for X in (
        kinlib.fk_space(M, S, th),
        kinlib.jacobian_space(S, th),
        kinlib.geometric_jacobian(M, S, th),
        kinlib.jacobian_space(S, [sp.pi / 6, 1, sp.Rational(2, 7)]),
        kinlib.exp6(S[:, 0], sp.pi / 3),
    ):
        assert isinstance(X, sp.MatrixBase)
        assert_no_floats(X)
    # a plain list of ints with symbolic thetas is symbolic too
    assert isinstance(kinlib.jacobian_space([[0, 0, 1, 0, 0, 0]], [th[0]]), sp.MatrixBase)


def test_symbolic_q_equals_substitution():
    """Exact values and symbols as q give the closed forms of the problem set at q (typed by hand)."""
    r = robots.planar_offset_3r()
    (L,) = r.params
    sqrt2 = sp.sqrt(2)
    q = [sp.pi / 3, -sp.pi / 4, sp.pi / 6]
    # eq. (18) at q: column i = [0, 0, 1, y_i, −x_i, 0] with (x_i, y_i) the joint point after the joints before it
    t1, a = q[0], q[0] + q[1] + sp.pi / 4
    j2 = (L * sp.cos(t1), L * sp.sin(t1))
    j3 = (j2[0] + sqrt2 * L * sp.cos(a), j2[1] + sqrt2 * L * sp.sin(a))
    expected = sp.Matrix([[0, 0, 0], [0, 0, 0], [1, 1, 1], [0, j2[1], j3[1]], [0, -j2[0], -j3[0]], [0, 0, 0]])
    Js = r.jacobian_space(q)
    assert_no_floats(Js, "J_s(q)")
    assert_sym_equal(Js, expected, "J_s(q), eq. (18) at q")
    # and numerically against modern_robotics at L = 1.3
    S = np.array([[0, 0, 1, 0, 0, 0], [0, 0, 1, 0, -1.3, 0], [0, 0, 1, 1.3, -2.6, 0]]).T
    np.testing.assert_allclose(
        np.array(Js.subs(L, sp.Rational(13, 10)).evalf(), dtype=float),
        mr.JacobianSpace(S, [float(v) for v in q]),
        atol=1e-12,
    )
    # symbols as q: eq. (17) with θ1 = a, θ2 = b, θ3 = 0
    a, b = sp.symbols("a b", real=True)
    c, s = sp.cos(a + b), sp.sin(a + b)
    T17 = sp.Matrix(
        [
            [c, -s, 0, L * c + L * sp.cos(a) + sqrt2 * L * sp.cos(a + b + sp.pi / 4)],
            [s, c, 0, L * s + L * sp.sin(a) + sqrt2 * L * sp.sin(a + b + sp.pi / 4)],
            [0, 0, 1, 0],
            [0, 0, 0, 1],
        ]
    )
    assert_sym_equal(r.fk([a, b, 0]), T17, "fk at symbols, eq. (17)")


def test_numeric_chain_matches_symbolic_chain():
    """The generated code for planar_offset_3r(L=7/5) equals the exact chain at random points."""
    sym = robots.planar_offset_3r()
    num = robots.planar_offset_3r(sp.Rational(7, 5))
    L = sym.params[0]
    rng = np.random.default_rng(11)
    for q in rng.uniform(-3, 3, size=(5, 3)):
        point = {L: sp.Rational(7, 5), **dict(zip(sym.thetas, q))}
        for m in METHODS:
            np.testing.assert_allclose(
                getattr(num, m)(q), np.array(getattr(sym, m)().subs(point), dtype=float), atol=1e-12, err_msg=m
            )


# --------------------------------------------------------------------------------------------
# attributes, subs, skeleton
# --------------------------------------------------------------------------------------------
def test_attributes_and_subs():
    r = robots.spatial_rppr()
    L1, L2 = sp.symbols("L1 L2", positive=True)
    assert r.n == 4 and len(r.thetas) == 4 and r.joint_types == "RPPR"
    assert all(isinstance(t, sp.Symbol) and t.is_real for t in r.thetas)
    assert [str(t) for t in r.thetas] == ["theta1", "theta2", "theta3", "theta4"]
    assert r.screws.shape == (6, 4) and r.joint_points.shape == (3, 4)
    r1 = r.subs(L1=1)
    assert r1.params == (L2,)
    r2 = r.subs({L1: 1, L2: 2})
    assert r2.params == () and r2.M[2, 3] == 3 and r2.thetas == r.thetas
    assert r.params == (L1, L2)  # subs returns a copy
    with pytest.raises(ValueError, match=r"no parameter 'L3'.*\['L1', 'L2'\]"):
        r.subs(L3=1)
    assert "spatial_rppr" in repr(r)


def test_custom_thetas():
    a, b = sp.symbols("a b", real=True)
    c = kinlib.SerialChain(sp.eye(4), [[0, 0, 1, 0, 0, 0], [0, 0, 0, 1, 0, 0]], thetas=(a, b))
    assert c.thetas == (a, b) and c.joint_types == "RP"
    assert c.fk().free_symbols == {a, b}


def test_skeleton_planar_offset_3r():
    """Base origin, the three joint points carried by the links, the tool origin (by hand)."""
    r = robots.planar_offset_3r(1)
    q = np.array([0.3, -0.7, 1.1])
    c1, s1 = np.cos(q[0]), np.sin(q[0])
    a = q[0] + q[1]
    j2 = np.array([c1, s1, 0])
    j3 = j2 + np.sqrt(2) * np.array([np.cos(a + np.pi / 4), np.sin(a + np.pi / 4), 0])
    tool = j3 + np.array([np.cos(q.sum()), np.sin(q.sum()), 0])
    expected = np.column_stack([np.zeros(3), np.zeros(3), j2, j3, tool])
    np.testing.assert_allclose(r.skeleton(q), expected, atol=1e-12)
    np.testing.assert_allclose(r.skeleton(q)[:, -1], r.fk(q)[:3, 3], atol=1e-12)
    assert r.skeleton(np.zeros((3, 3))).shape == (3, 3, 5)


@pytest.mark.parametrize("name", sorted(NUMERIC))
def test_skeleton_ends_at_tool_and_joint_points_on_axes(name):
    chain = NUMERIC[name]
    q = np.random.default_rng(2).uniform(-1, 1, size=chain.n)
    sk, T = chain.skeleton(q), chain.fk(q)
    assert sk.shape == (3, chain.n + 2)
    np.testing.assert_allclose(sk[:, 0], 0, atol=0)
    np.testing.assert_allclose(sk[:, -1], T[:3, 3], atol=1e-12)
    Js = chain.jacobian_space(q)
    for i, kind in enumerate(chain.joint_types):
        if kind == "R":  # the drawn joint point lies on the current joint axis: v = −ω × q
            w, v = Js[:3, i], Js[3:, i]
            np.testing.assert_allclose(-np.cross(w, sk[:, i + 1]), v, atol=1e-9, err_msg=f"joint {i + 1}")


# --------------------------------------------------------------------------------------------
# import kinlib
# --------------------------------------------------------------------------------------------
def test_import_kinlib_is_light():
    # what it loads, not how long it takes (a loaded machine varies; make bench times the import)
    code = (
        "import sys, json; import kinlib; "
        "print(json.dumps({'mods': [m for m in ('matplotlib', 'ipywidgets', 'IPython', "
        "'modern_robotics') if m in sys.modules]}))"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True, timeout=60)
    info = json.loads(out.stdout.strip().splitlines()[-1])
    assert info["mods"] == [], f"import kinlib pulled in {info['mods']}"


def test_chain_from_float_screws_is_accepted():
    """Regression: float unit axes (|ω|² − 1 ≈ 1e-16) were rejected by the exact unit-vector test."""
    w = np.array([1.0, 2.0, 3.0]) / np.sqrt(14.0)
    S = np.concatenate([w, -np.cross(w, [0.3, 0.1, 0.2])])
    M = np.eye(4)
    M[:3, 3] = [1.0, 0.5, 0.25]
    chain = kinlib.SerialChain(M, [S, [0, 0, 0, 0.6, 0.8, 0]])
    assert chain.joint_types == "RP"
    q = [0.4, -0.2]
    np.testing.assert_allclose(
        chain.jacobian_space(q), mr.JacobianSpace(np.column_stack([S, [0, 0, 0, 0.6, 0.8, 0]]), q), atol=1e-12
    )
    # but a float axis that is really not a unit vector is still refused
    with pytest.raises(ValueError, match="must be a unit vector"):
        kinlib.SerialChain(M, [[0, 0, 1.001, 0, 0, 0]])
