"""Properties of rigid-body motions and screws (kinlib.rigid, kinlib.screws), with hypothesis.

Each property is checked against an independent computation: np.linalg.inv, np.cross, the group
laws of SE(3), the book's identity T[S]T⁻¹ = [Ad_T S] (problem 1.2's hint).
"""

from __future__ import annotations

import modern_robotics as mr
import numpy as np
import pytest
import sympy as sp
from hypothesis import given
from hypothesis import strategies as st

import kinlib
from helpers import FAST, assert_no_floats, assert_sym_equal, random_arm, random_transform

seeds = st.integers(min_value=0, max_value=2**32 - 1)
angles = st.floats(min_value=-10.0, max_value=10.0, allow_nan=False, allow_infinity=False)
TOL = 1e-9


def _screw(seed, kind):
    rng = np.random.default_rng(seed)
    _, S, _ = random_arm(rng, 1, kind)
    return S[:, 0]


def _is_se3(T, tol=TOL):
    R = T[:3, :3]
    return (
        T.shape == (4, 4)
        and np.allclose(R.T @ R, np.eye(3), atol=tol)
        and abs(np.linalg.det(R) - 1) < tol
        and np.array_equal(T[3], [0, 0, 0, 1])
    )


@FAST
@given(seeds, angles, st.sampled_from("RP"))
def test_exp6_lands_in_se3(seed, theta, kind):
    T = kinlib.exp6(_screw(seed, kind), theta)
    assert isinstance(T, np.ndarray) and T.dtype == float
    assert _is_se3(T)


@FAST
@given(seeds, angles, st.floats(-3, 3))
def test_exp6_helical_screw_in_se3_and_moves_along_axis(seed, theta, h):
    rng = np.random.default_rng(seed)
    q, s = rng.normal(size=3), rng.normal(size=3)
    s /= np.linalg.norm(s)
    S = kinlib.screw_axis(q, s, h)
    T = kinlib.exp6(S, theta)
    assert _is_se3(T)
    # a point on the axis moves along the axis by h θ
    np.testing.assert_allclose(T[:3, :3] @ q + T[:3, 3], q + h * theta * s, atol=1e-8)


@FAST
@given(seeds, angles, angles, st.sampled_from("RP"))
def test_exp6_one_parameter_subgroup(seed, a, b, kind):
    """e^{[S]a} e^{[S]b} = e^{[S](a+b)} and e^{[S]·0} = I."""
    S = _screw(seed, kind)
    np.testing.assert_allclose(kinlib.exp6(S, a) @ kinlib.exp6(S, b), kinlib.exp6(S, a + b), atol=1e-8)
    np.testing.assert_allclose(kinlib.exp6(S, 0.0), np.eye(4), atol=0)


@FAST
@given(seeds, angles)
def test_exp6_derivative_is_bracket(seed, theta):
    """d/dθ e^{[S]θ} = [S] e^{[S]θ} (central differences)."""
    S = _screw(seed, "R" if seed % 2 else "P")
    h = 1e-6
    dT = (kinlib.exp6(S, theta + h) - kinlib.exp6(S, theta - h)) / (2 * h)
    np.testing.assert_allclose(dT, kinlib.bracket(S) @ kinlib.exp6(S, theta), atol=1e-7)


@FAST
@given(seeds, angles)
def test_exp3_is_rotation_part_of_exp6(seed, theta):
    S = _screw(seed, "R")
    R = kinlib.exp3(S[:3], theta)
    np.testing.assert_allclose(R, kinlib.exp6(S, theta)[:3, :3], atol=TOL)
    np.testing.assert_allclose(R @ S[:3], S[:3], atol=TOL)  # the axis is fixed
    assert np.allclose(R.T @ R, np.eye(3), atol=TOL) and abs(np.linalg.det(R) - 1) < TOL


@FAST
@given(seeds)
def test_trans_inv(seed):
    T = random_transform(np.random.default_rng(seed))
    Ti = kinlib.trans_inv(T)
    np.testing.assert_allclose(Ti @ T, np.eye(4), atol=TOL)
    np.testing.assert_allclose(T @ Ti, np.eye(4), atol=TOL)
    np.testing.assert_allclose(Ti, np.linalg.inv(T), atol=TOL)


@FAST
@given(seeds)
def test_rp_round_trip(seed):
    T = random_transform(np.random.default_rng(seed))
    R, p = kinlib.trans_to_rp(T)
    np.testing.assert_allclose(kinlib.rp_to_trans(R, p), T, atol=0)


@FAST
@given(seeds)
def test_skew_unskew(seed):
    rng = np.random.default_rng(seed)
    w, x = rng.normal(size=3), rng.normal(size=3)
    W = kinlib.skew(w)
    np.testing.assert_allclose(W @ x, np.cross(w, x), atol=TOL)
    np.testing.assert_allclose(W, -W.T, atol=0)
    np.testing.assert_allclose(kinlib.unskew(W), w, atol=0)
    V = rng.normal(size=6)
    np.testing.assert_allclose(kinlib.unbracket(kinlib.bracket(V)), V, atol=0)


@FAST
@given(seeds, seeds)
def test_adjoint_properties(seed1, seed2):
    """T[V]T⁻¹ = [Ad_T V]; Ad_{T1 T2} = Ad_{T1} Ad_{T2}; Ad_{T⁻¹} = (Ad_T)⁻¹."""
    rng = np.random.default_rng(seed1)
    T1, T2 = random_transform(rng), random_transform(np.random.default_rng(seed2))
    V = rng.normal(size=6)
    A = kinlib.adjoint(T1)
    np.testing.assert_allclose(kinlib.bracket(A @ V), T1 @ kinlib.bracket(V) @ np.linalg.inv(T1), atol=1e-8)
    np.testing.assert_allclose(kinlib.adjoint(T1 @ T2), A @ kinlib.adjoint(T2), atol=1e-8)
    np.testing.assert_allclose(kinlib.adjoint(kinlib.trans_inv(T1)), np.linalg.inv(A), atol=1e-8)


@FAST
@given(seeds)
def test_screw_constructors(seed):
    rng = np.random.default_rng(seed)
    w = rng.normal(size=3)
    w /= np.linalg.norm(w)
    q = rng.normal(size=3)
    S = kinlib.screw_revolute(w, q)
    np.testing.assert_allclose(S, np.concatenate([w, -np.cross(w, q)]), atol=TOL)
    # any point on the axis gives the same screw
    np.testing.assert_allclose(kinlib.screw_revolute(w, q + 2.5 * w), S, atol=1e-9)
    np.testing.assert_allclose(kinlib.screw_axis(q, w, 0.0), S, atol=TOL)
    np.testing.assert_allclose(kinlib.screw_prismatic(w), np.concatenate([np.zeros(3), w]), atol=0)


# --------------------------------------------------------------------------------------------
# the symbolic backend: exact, and equal to the numeric one
# --------------------------------------------------------------------------------------------
def test_exp6_symbolic_is_exact_and_matches_rodrigues():
    th = sp.Symbol("theta", real=True)
    w = sp.Matrix([sp.Rational(2, 3), sp.Rational(1, 3), sp.Rational(2, 3)])  # a rational unit vector
    q = sp.Matrix([1, sp.Rational(-1, 2), 3])
    S = kinlib.screw_revolute(w, q)
    T = kinlib.exp6(S, th)
    assert_no_floats(T, "exp6")
    # independent: R = e^{[ω]θ} by SymPy's matrix exponential; p = (I − R) q for a pure rotation about q
    W = sp.Matrix([[0, -w[2], w[1]], [w[2], 0, -w[0]], [-w[1], w[0], 0]])
    R = sp.simplify((W * th).exp())
    assert_sym_equal(T[:3, :3], R, "exp6 rotation vs Matrix.exp")
    assert_sym_equal(T[:3, 3], (sp.eye(3) - R) * q, "exp6 translation")
    # at a number it equals modern_robotics' MatrixExp6 of the screw typed from ω and q
    S_typed = np.concatenate(
        [
            np.array(w, dtype=float).ravel(),
            -np.cross(np.array(w, dtype=float).ravel(), np.array(q, dtype=float).ravel()),
        ]
    )
    np.testing.assert_allclose(
        np.array(T.subs(th, 0.7), dtype=float), mr.MatrixExp6(mr.VecTose3(S_typed * 0.7)), atol=1e-12
    )


def test_symbolic_rigid_functions_exact():
    a = sp.Symbol("a", real=True)
    T = kinlib.exp6(sp.Matrix([0, 0, 1, 0, -1, 0]), a)
    for name, X in [
        ("trans_inv", kinlib.trans_inv(T)),
        ("adjoint", kinlib.adjoint(T)),
        ("exp3", kinlib.exp3(sp.Matrix([0, 1, 0]), sp.pi / 3)),
        ("skew", kinlib.skew(sp.Matrix([1, a, 2]))),
    ]:
        assert isinstance(X, sp.MatrixBase), name
        assert_no_floats(X, name)
    assert_sym_equal(kinlib.trans_inv(T) * T, sp.eye(4), "trans_inv(T) T = I, symbolic")
    assert_sym_equal(
        kinlib.exp3(sp.Matrix([0, 1, 0]), sp.pi / 3),
        sp.Matrix([[sp.Rational(1, 2), 0, sp.sqrt(3) / 2], [0, 1, 0], [-sp.sqrt(3) / 2, 0, sp.Rational(1, 2)]]),
        "exp3 about y by π/3",
    )


def test_numeric_inputs_give_float_arrays():
    T = kinlib.exp6([0, 0, 1, 0, 0, 0], 1)  # ints in, floats out
    assert isinstance(T, np.ndarray) and T.dtype == np.float64
    assert isinstance(kinlib.skew([1, 2, 3]), np.ndarray)
    assert isinstance(kinlib.adjoint(np.eye(4)), np.ndarray)


@pytest.mark.parametrize("theta", [0.0, 1e-12, np.pi, -np.pi, 2 * np.pi])
def test_exp6_edge_angles(theta):
    S = np.array([0, 0, 1, 0, -1, 0.0])
    T = kinlib.exp6(S, theta)
    assert _is_se3(T)
    # rotation about z through (1, 0, 0): the origin goes to (1 − cos θ, −sin θ, 0)
    np.testing.assert_allclose(T[:3, 3], [1 - np.cos(theta), -np.sin(theta), 0], atol=1e-12)
