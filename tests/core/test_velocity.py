"""Matrix logarithms (log3, log6) and the velocity kinematics after the Jacobian (issue 11, item 7).

Oracles are independent of kinlib: modern_robotics' MatrixExp3/MatrixLog3/MatrixExp6/MatrixLog6/JacobianSpace,
numpy.linalg.pinv/lstsq/svd/solve, the four Penrose conditions (which characterise J⁺ uniquely) checked in
exact arithmetic or with 50-digit mpmath, and exact SymPy arithmetic (minimal polynomials) for the exact cases.
"""

from __future__ import annotations

import warnings

import modern_robotics as mr
import mpmath
import numpy as np
import pytest
import sympy as sp
from hypothesis import given, settings
from hypothesis import strategies as st

from helpers import random_arm, random_thetas
from kinlib import (
    SingularityWarning,
    damped_least_squares,
    exp3,
    exp6,
    force_ellipsoid,
    inverse_velocity,
    joint_torques,
    log3,
    log6,
    pseudoinverse,
    velocity_ellipsoid,
)

SETTINGS = settings(deadline=None, derandomize=True, max_examples=40, database=None)
X = sp.Dummy("x")


def _unit(v):
    return v / np.linalg.norm(v)


def _exactly_zero(e) -> bool:
    """e = 0 proved independently of kinlib: literally 0, or its minimal polynomial is x (algebraic e)."""
    e = sp.sympify(e)
    return e == 0 or sp.simplify(e) == 0 or sp.minimal_polynomial(e, X) == X


def _rot(axis: str, a):
    c, s = sp.cos(a), sp.sin(a)
    return {
        "x": sp.Matrix([[1, 0, 0], [0, c, -s], [0, s, c]]),
        "y": sp.Matrix([[c, 0, s], [0, 1, 0], [-s, 0, c]]),
        "z": sp.Matrix([[c, -s, 0], [s, c, 0], [0, 0, 1]]),
    }[axis]


# ----------------------------------------------------------------------------------------------
# log3: numeric, against modern_robotics
# ----------------------------------------------------------------------------------------------
ANGLES = [0.0, 1e-12, 1e-8, 1e-5, 1e-3, 0.3, 1.0, 2.0, 3.0, np.pi - 1e-3, np.pi - 1e-6, np.pi - 1e-9]


def _rodrigues(W):
    """e^{[ω]θ} for W = [ω]θ, in plain NumPy (modern_robotics' MatrixExp3 returns I below θ = 1e-6)."""
    th = np.linalg.norm([W[2, 1], W[0, 2], W[1, 0]])
    if th == 0:
        return np.eye(3)
    K = W / th
    return np.eye(3) + np.sin(th) * K + (1 - np.cos(th)) * (K @ K)


@pytest.mark.parametrize("theta", ANGLES)
def test_log3_inverts_mr_exp3(theta):
    rng = np.random.default_rng(int(theta * 1e6) % 1000)
    for _ in range(5):
        w = _unit(rng.normal(size=3))
        R = _rodrigues(mr.VecToso3(w * theta)) if theta < 1e-5 else mr.MatrixExp3(mr.VecToso3(w * theta))
        L = log3(R)
        assert np.allclose(L, -L.T, atol=0)  # in so(3)
        assert np.abs(_rodrigues(L) - R).max() < 1e-14
        vec = log3(R, form="vector")
        assert np.allclose(vec, w * theta, atol=1e-12)  # the unique log for θ < π
        if 1e-3 <= theta <= 3.0:  # where MR's acos formula is itself accurate
            assert np.allclose(L, mr.MatrixLog3(R), atol=1e-12)
        axis, ang = log3(R, form="axis_angle")
        assert abs(ang - theta) < 1e-12
        if theta > 0:
            assert np.allclose(axis, w, atol=1e-6 if theta < 1e-9 else 1e-10)


@pytest.mark.parametrize(
    "w", [(1, 0, 0), (0, 1, 0), (0, 0, 1), (1, 1, 0), (1, 1, 1), (1, -1, 0), (0, 1, -1), (-1, 2, 3), (3, -1, -2)]
)
def test_log3_exactly_pi_matches_mr_branches(w):
    """R = 2ω̂ω̂ᵀ − I (θ = π): MR's MatrixLog3 takes its three-branch path; both ±ω̂π are logs, and the
    branch picks MR's sign (first of ω̂_3, ω̂_2, ω̂_1 not ≈ 0 positive)."""
    w = _unit(np.array(w, dtype=float))
    R = 2 * np.outer(w, w) - np.eye(3)
    vec = log3(R, form="vector")
    assert abs(np.linalg.norm(vec) - np.pi) < 1e-12
    assert np.abs(mr.MatrixExp3(mr.VecToso3(vec)) - R).max() < 1e-14
    assert np.allclose(np.abs(vec), np.abs(w * np.pi), atol=1e-12)
    k = next(i for i in (2, 1, 0) if abs(1 + R[i, i]) > 1e-6)
    assert vec[k] > 0
    if (np.trace(R) - 1) / 2 <= -1:  # MR's branch applies exactly
        assert np.allclose(vec, mr.so3ToVec(mr.MatrixLog3(R)), atol=1e-12)


@SETTINGS
@given(st.lists(st.floats(-1, 1), min_size=3, max_size=3), st.floats(0, np.pi))
def test_log3_property_random(wv, theta):
    w = np.array(wv)
    if np.linalg.norm(w) < 1e-3:
        w = np.array([0.0, 0.0, 1.0])
    w = _unit(w)
    R = mr.MatrixExp3(mr.VecToso3(w * theta))
    vec = log3(R, form="vector")
    assert np.linalg.norm(vec) <= np.pi + 1e-12
    assert np.abs(mr.MatrixExp3(mr.VecToso3(vec)) - R).max() < 1e-13


def test_log3_batch_matches_single():
    rng = np.random.default_rng(3)
    Rs = np.stack(
        [mr.MatrixExp3(mr.VecToso3(rng.normal(size=3))) for _ in range(6)] + [np.eye(3), np.diag([1.0, -1, -1])]
    )
    L = log3(Rs)
    assert L.shape == (8, 3, 3)
    for i, R in enumerate(Rs):
        assert np.array_equal(L[i], log3(R))
    axes, ang = log3(Rs, form="axis_angle")
    assert axes.shape == (8, 3) and ang.shape == (8,)
    assert np.array_equal(axes[6], [0, 0, 1]) and ang[6] == 0  # the stated convention at θ = 0


# ----------------------------------------------------------------------------------------------
# log3: exact
# ----------------------------------------------------------------------------------------------
@pytest.mark.parametrize("axis", ["x", "y", "z"])
@pytest.mark.parametrize("k,n", [(1, 2), (1, 3), (1, 4), (3, 4), (1, 6), (5, 6), (2, 7), (1, 8), (1, 12)])
def test_log3_exact_axis_rotations(axis, k, n):
    a = sp.pi * k / n
    R = _rot(axis, a)
    w, theta = log3(R, form="axis_angle")
    assert theta == a  # exactly k π / n
    e = {"x": [1, 0, 0], "y": [0, 1, 0], "z": [0, 0, 1]}[axis]
    assert all(_exactly_zero(wi - ei) for wi, ei in zip(w, e))
    L = log3(R)
    assert not L.atoms(sp.Float)
    assert all(_exactly_zero(x) for x in exp3(w, theta) - R)


@pytest.mark.parametrize("axis", ["x", "y", "z"])
def test_log3_exact_pi_and_identity(axis):
    R = _rot(axis, sp.pi)
    w, theta = log3(R, form="axis_angle")
    assert theta == sp.pi
    assert list(w) == {"x": [1, 0, 0], "y": [0, 1, 0], "z": [0, 0, 1]}[axis]
    assert log3(sp.eye(3)) == sp.zeros(3, 3)
    assert log3(sp.eye(3), form="vector") == sp.zeros(3, 1)


@pytest.mark.parametrize("w", [(1, 1, 0), (1, 1, 1), (1, -1, 0), (0, 1, -1), (1, 2, 2)])
def test_log3_exact_pi_general_axis(w):
    """θ = π about a non-coordinate axis: R = 2ω̂ω̂ᵀ − I exact; MR's branch sign (last nonzero ω̂_k > 0)."""
    w = sp.Matrix(w) / sp.sqrt(sum(x**2 for x in w))
    R = 2 * w * w.T - sp.eye(3)
    got, theta = log3(R, form="axis_angle")
    assert theta == sp.pi
    k = max(i for i in range(3) if w[i] != 0)
    expect = w if w[k] > 0 else -w
    assert all(_exactly_zero(a - b) for a, b in zip(got, expect))


def test_log3_exact_composed_rotation():
    R = _rot("x", sp.pi / 3) * _rot("z", sp.pi / 4)  # an exact rotation with √2, √3 entries
    w, theta = log3(R, form="axis_angle")
    assert not w.atoms(sp.Float) and not theta.atoms(sp.Float)
    assert all(_exactly_zero(x) for x in exp3(w, theta) - R)
    Rn = np.array(R.evalf(), dtype=float)
    assert np.allclose(np.array(log3(R).evalf(), dtype=float), mr.MatrixLog3(Rn), atol=1e-14)


def test_log3_symbolic_closed_form():
    q = sp.Symbol("q", real=True)
    vec = log3(_rot("z", q), form="vector")
    for val in (0.3, 1.7, 3.0, -0.4, -2.9):  # 0 < θ < π: θ = |q|, axis ±ẑ
        got = np.array(vec.subs(q, val).evalf(), dtype=float).ravel()
        assert np.allclose(got, [0, 0, val], atol=1e-12)


def test_log3_exact_refuses_inexact_rotation():
    with pytest.raises(ValueError, match="R must be"):
        log3(sp.Matrix([[sp.Float(0.7071), -sp.Float(0.7071), 0], [sp.Float(0.7071), sp.Float(0.7071), 0], [0, 0, 1]]))
    with pytest.raises(ValueError, match="R"):
        log3(sp.Matrix([[1, 0, 0], [0, 1, 0], [0, 0, 2]]))


# ----------------------------------------------------------------------------------------------
# log6
# ----------------------------------------------------------------------------------------------
@pytest.mark.parametrize("theta", [0.0, 1e-9, 1e-4, 0.5, 2.0, np.pi - 1e-6])
def test_log6_inverts_mr_exp6(theta):
    rng = np.random.default_rng(7)
    for _ in range(5):
        w, v = _unit(rng.normal(size=3)), rng.normal(size=3)
        T = mr.MatrixExp6(mr.VecTose3(np.r_[w * theta, v]))
        X = log6(T)
        assert np.array_equal(X[3], np.zeros(4))
        assert np.abs(mr.MatrixExp6(X) - T).max() < 1e-12
        if theta < 3:  # MR's acos loses ~1e-3 near π
            assert np.allclose(X, mr.MatrixLog6(T), atol=1e-9)
        Sv = log6(T, form="vector")
        if theta > 1e-6:  # MR's MatrixExp6 drops rotations below 1e-6
            assert np.allclose(Sv[:3], w * theta, atol=1e-10)  # angular first
        S, ang = log6(T, form="screw_angle")
        assert np.abs(mr.MatrixExp6(mr.VecTose3(S) * ang) - T).max() < 1e-10


def test_log6_pure_translation_identity_and_pi():
    T = np.eye(4)
    T[:3, 3] = [3.0, 4.0, 0.0]
    assert np.allclose(log6(T), mr.MatrixLog6(T))
    S, ang = log6(T, form="screw_angle")
    assert np.allclose(S, [0, 0, 0, 0.6, 0.8, 0]) and ang == 5.0
    S, ang = log6(np.eye(4), form="screw_angle")
    assert ang == 0 and np.allclose(mr.MatrixExp6(mr.VecTose3(S) * ang), np.eye(4))
    Tpi = np.eye(4)
    Tpi[:3, :3] = np.diag([1.0, -1.0, -1.0])
    Tpi[:3, 3] = [1.0, 2.0, 3.0]
    assert np.abs(mr.MatrixExp6(log6(Tpi)) - Tpi).max() < 1e-14


def test_log6_batch():
    rng = np.random.default_rng(11)
    Ts = np.stack([mr.MatrixExp6(mr.VecTose3(rng.normal(size=6))) for _ in range(7)])
    X = log6(Ts)
    assert X.shape == (7, 4, 4)
    for i in range(7):
        assert np.allclose(X[i], mr.MatrixLog6(Ts[i]), atol=1e-10)
        assert np.allclose(log6(Ts[i]), X[i], atol=0)


@SETTINGS
@given(st.lists(st.floats(-3, 3), min_size=6, max_size=6))
def test_log6_property_random(xi):
    T = mr.MatrixExp6(mr.VecTose3(np.array(xi)))
    assert np.abs(mr.MatrixExp6(log6(T)) - T).max() < 1e-11


def test_log6_exact():
    T = sp.Matrix([[1, 0, 0, 0], [0, 0, -1, 0], [0, 1, 0, 3], [0, 0, 0, 1]])
    X = log6(T)
    assert X == sp.Matrix(
        [[0, 0, 0, 0], [0, 0, -sp.pi / 2, 3 * sp.pi / 4], [0, sp.pi / 2, 0, 3 * sp.pi / 4], [0, 0, 0, 0]]
    )  # MR's docstring example, exactly
    S, theta = log6(T, form="screw_angle")
    assert all(_exactly_zero(x) for x in exp6(S, theta) - T)
    # θ = π with a translation, and a pure translation
    Tpi = sp.Matrix([[1, 0, 0, 1], [0, -1, 0, 2], [0, 0, -1, 3], [0, 0, 0, 1]])
    S, theta = log6(Tpi, form="screw_angle")
    assert theta == sp.pi and all(_exactly_zero(x) for x in exp6(S, theta) - Tpi)
    assert np.allclose(np.array(log6(Tpi).evalf(), dtype=float), mr.MatrixLog6(np.array(Tpi, dtype=float)))
    Tt = sp.Matrix([[1, 0, 0, 1], [0, 1, 0, 2], [0, 0, 1, 2], [0, 0, 0, 1]])
    S, theta = log6(Tt, form="screw_angle")
    assert theta == 3 and list(S) == [0, 0, 0, sp.Rational(1, 3), sp.Rational(2, 3), sp.Rational(2, 3)]


def test_log6_exact_general_rotation():
    R = sp.Matrix([[2, -1, 2], [2, 2, -1], [-1, 2, 2]]) / 3  # a rational rotation (θ = π/3 about (1, 1, 1)/√3)
    T = sp.Matrix.vstack(sp.Matrix.hstack(R, sp.Matrix([1, sp.Rational(1, 2), -2])), sp.Matrix([[0, 0, 0, 1]]))
    X = log6(T)
    assert not X.atoms(sp.Float)
    assert np.allclose(np.array(X.evalf(), dtype=float), mr.MatrixLog6(np.array(T.evalf(), dtype=float)), atol=1e-13)
    S, theta = log6(T, form="screw_angle")
    assert theta == sp.pi / 3
    assert all(_exactly_zero(x) for x in exp6(S, theta) - T)


# ----------------------------------------------------------------------------------------------
# pseudoinverse and inverse velocity kinematics
# ----------------------------------------------------------------------------------------------
def _random_matrix(rng, m, n, rank):
    return rng.normal(size=(m, rank)) @ rng.normal(size=(rank, n))


@SETTINGS
@given(st.integers(1, 7), st.integers(1, 7), st.integers(0, 7), st.integers(0, 2**31))
def test_pinv_matches_numpy(m, n, r, seed):
    rng = np.random.default_rng(seed)
    r = min(r, m, n)
    J = _random_matrix(rng, m, n, r)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", SingularityWarning)
        P, rep = pseudoinverse(J, full_output=True)
    assert rep.rank == np.linalg.matrix_rank(J)
    assert np.allclose(P, np.linalg.pinv(J, rcond=max(m, n) * np.finfo(float).eps), atol=1e-8)
    assert np.allclose(J @ P @ J, J, atol=1e-9)  # J J⁺ J = J
    V = rng.normal(size=m)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", SingularityWarning)
        qd = inverse_velocity(J, V)
    assert np.allclose(qd, np.linalg.lstsq(J, V, rcond=None)[0], atol=1e-8)  # the minimum-norm least squares


def test_pinv_formulas_full_rank():
    rng = np.random.default_rng(5)
    J = rng.normal(size=(3, 6))  # full row rank: Jᵀ(JJᵀ)⁻¹, J J⁺ = I
    assert np.allclose(pseudoinverse(J), J.T @ np.linalg.inv(J @ J.T))
    J = rng.normal(size=(6, 2))  # full column rank: (JᵀJ)⁻¹Jᵀ
    assert np.allclose(pseudoinverse(J), np.linalg.inv(J.T @ J) @ J.T)


def test_pinv_warns_at_and_near_singularity():
    J = np.array([[1.0, 1.0], [1.0, 1.0]])
    with pytest.warns(SingularityWarning, match="rank 1 < 2"):
        P, rep = pseudoinverse(J, full_output=True)
    assert rep.rank == 1 and np.all(np.isfinite(P))
    J = np.diag([1.0, 1e-10])
    with pytest.warns(SingularityWarning, match="nearly singular"):
        qd = inverse_velocity(J, [0.0, 1.0])
    assert np.isclose(qd[1], 1e10)  # the true J⁺V, with the warning
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        inverse_velocity(np.eye(3), [1.0, 2.0, 3.0])  # a regular J does not warn
    with pytest.warns(SingularityWarning, match="rank"):  # a caller's cut-off is honoured
        _, rep = pseudoinverse(J, rtol=1e-6, full_output=True)
    assert rep.rank == 1


def test_inverse_velocity_batches():
    rng = np.random.default_rng(2)
    Js, V = rng.normal(size=(5, 3, 4)), rng.normal(size=(5, 3))
    qd = inverse_velocity(Js, V)
    assert qd.shape == (5, 4)
    for i in range(5):
        assert np.allclose(qd[i], np.linalg.pinv(Js[i]) @ V[i])
    assert inverse_velocity(Js[0], V).shape == (5, 4)  # one J, many twists
    with pytest.raises(ValueError, match="V"):
        inverse_velocity(Js, V[:3])


@SETTINGS
@given(st.integers(2, 7), st.integers(0, 2**31))
def test_inverse_velocity_on_random_arms(n, seed):
    rng = np.random.default_rng(seed)
    M, S, kinds = random_arm(rng, n)
    J = mr.JacobianSpace(S, random_thetas(rng, kinds))
    V = J @ rng.normal(size=n)  # a reachable twist
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", SingularityWarning)
        qd = inverse_velocity(J, V)
    assert np.allclose(J @ qd, V, atol=1e-8)  # J J⁺ V = V on the column space
    assert np.allclose(qd, np.linalg.pinv(J) @ V, atol=1e-8)


def _penrose_exact(J, P):
    """The four Penrose conditions, to 50 digits (mpmath), for exact J and P."""
    with mpmath.workdps(60):
        A = mpmath.matrix([[mpmath.mpf(str(sp.N(e, 60))) for e in J.row(i)] for i in range(J.rows)])
        B = mpmath.matrix([[mpmath.mpf(str(sp.N(e, 60))) for e in P.row(i)] for i in range(P.rows)])
        return max(
            mpmath.mnorm(A * B * A - A, 1),
            mpmath.mnorm(B * A * B - B, 1),
            mpmath.mnorm((A * B).T - A * B, 1),
            mpmath.mnorm((B * A).T - B * A, 1),
        )


@SETTINGS
@given(st.integers(1, 4), st.integers(1, 4), st.integers(0, 4), st.integers(0, 2**31))
def test_exact_pinv_rational_penrose(m, n, r, seed):
    """Exact J⁺ of integer matrices of any rank: the four Penrose conditions hold exactly."""
    rng = np.random.default_rng(seed)
    r = min(r, m, n)
    J = (
        sp.Matrix(rng.integers(-3, 4, size=(m, r)).tolist()) * sp.Matrix(rng.integers(-3, 4, size=(r, n)).tolist())
        if r
        else sp.zeros(m, n)
    )
    P, rep = pseudoinverse(J, full_output=True)
    assert rep.rank == np.linalg.matrix_rank(np.array(J, dtype=float))
    assert not P.atoms(sp.Float)
    for C in (J * P * J - J, P * J * P - P, (J * P).T - J * P, (P * J).T - P * J):
        assert C == sp.zeros(*C.shape)


def _planar_2r_p():
    t1, t2 = sp.symbols("theta1 theta2", real=True)
    return sp.Matrix(
        [[-sp.sin(t1) - sp.sin(t1 + t2), -sp.sin(t1 + t2)], [sp.cos(t1) + sp.cos(t1 + t2), sp.cos(t1 + t2)]]
    ), (t1, t2)


@pytest.mark.parametrize(
    "cfg,rank",
    [
        ((10, 0), 1),
        ((sp.Rational(1, 2), sp.Rational(1, 2)), 2),
        ((3, sp.pi), 1),
        ((sp.pi / 8, sp.pi / 3), 2),
        ((1, 2), 2),
    ],
)
def test_exact_pinv_planar_2r(cfg, rank):
    """The issue's configurations: rank decided exactly (10, 0 is singular; 1/2, 1/2 is not)."""
    J, th = _planar_2r_p()
    Jc = J.subs(dict(zip(th, cfg)))
    P, rep = pseudoinverse(Jc, full_output=True)
    assert rep.rank == rank
    assert _penrose_exact(Jc, P) < 1e-45
    assert np.allclose(np.array(P.evalf(), dtype=float), np.linalg.pinv(np.array(Jc.evalf(), dtype=float)), atol=1e-12)


def test_exact_pinv_ur5():
    from kinlib import robots

    ur = robots.ur5()
    J0 = ur.jacobian_space()
    for vals, rank in (([1, 2, 3, 4, 5, 6], 6), ([0, 0, 0, 0, 0, 0], 5)):
        J = J0.subs(dict(zip(ur.thetas, vals)))
        P, rep = pseudoinverse(J, full_output=True)
        assert rep.rank == rank
        assert _penrose_exact(J, P) < 1e-40


def test_exact_pinv_refuses_symbols():
    J, _ = _planar_2r_p()
    with pytest.raises(ValueError, match="constant"):
        pseudoinverse(J)
    with pytest.raises(ValueError, match="rtol"):
        pseudoinverse(sp.eye(2), rtol=1e-3)


# ----------------------------------------------------------------------------------------------
# damped least squares
# ----------------------------------------------------------------------------------------------
@SETTINGS
@given(st.integers(1, 7), st.integers(1, 7), st.floats(1e-3, 10), st.integers(0, 2**31))
def test_dls_matches_formula(m, n, lam, seed):
    rng = np.random.default_rng(seed)
    J, V = rng.normal(size=(m, n)), rng.normal(size=m)
    want = J.T @ np.linalg.solve(J @ J.T + lam**2 * np.eye(m), V)
    assert np.allclose(damped_least_squares(J, V, lam), want, atol=1e-10)


@SETTINGS
@given(st.integers(2, 7), st.integers(0, 2**31))
def test_dls_tends_to_pinv_at_regular_configurations(n, seed):
    rng = np.random.default_rng(seed)
    M, S, kinds = random_arm(rng, n)
    J = mr.JacobianSpace(S, random_thetas(rng, kinds))
    s = np.linalg.svd(J, compute_uv=False)
    if s[-1] < 1e-3 * s[0]:
        return  # (near) singular: not a regular configuration
    V = rng.normal(size=6)
    ref = np.linalg.pinv(J) @ V
    errs = [np.linalg.norm(damped_least_squares(J, V, lam) - ref) for lam in (1e-2, 1e-4, 1e-6)]
    assert errs[2] < 1e-6 * (1 + np.linalg.norm(ref)) and errs[0] >= errs[1] >= errs[2]


def test_dls_bounded_at_singularity():
    J = np.array([[1.0, 1.0], [1.0, 1.0]])
    V = np.array([1.0, -1.0])  # entirely in the lost direction
    for lam in (1.0, 0.1, 0.01):
        assert np.linalg.norm(damped_least_squares(J, V, lam)) <= np.linalg.norm(V) / (2 * lam) + 1e-12
    with pytest.warns(SingularityWarning):  # λ = 0 is the pseudoinverse, with its warning
        assert np.allclose(damped_least_squares(J, V, 0), 0)


def test_dls_exact():
    J, th = _planar_2r_p()
    lam = sp.Rational(1, 10)
    qd = damped_least_squares(J, [1, 0], lam)  # symbolic J: valid at every configuration
    for cfg in ((0.3, 0.0), (1.0, 2.0), (2.0, np.pi)):
        Jn = np.array(J.subs(dict(zip(th, cfg))).evalf(), dtype=float)
        want = Jn.T @ np.linalg.solve(Jn @ Jn.T + 0.01 * np.eye(2), [1.0, 0.0])
        assert np.allclose(np.array(qd.subs(dict(zip(th, cfg))).evalf(), dtype=float).ravel(), want)
    assert damped_least_squares(sp.Matrix([[1, 0], [0, 0]]), [1, 1], 1) == sp.Matrix([sp.Rational(1, 2), 0])
    Jc = J.subs({th[0]: 10, th[1]: 0})
    qd = damped_least_squares(Jc, [1, 2], sp.Rational(1, 2))
    Jn = np.array(Jc.evalf(), dtype=float)
    assert np.allclose(
        np.array(qd.evalf(), dtype=float).ravel(), Jn.T @ np.linalg.solve(Jn @ Jn.T + 0.25 * np.eye(2), [1, 2])
    )
    assert damped_least_squares(sp.Matrix([[2, 0], [0, 1]]), [2, 1], 0) == sp.Matrix([1, 1])  # λ = 0: J⁺V


@pytest.mark.parametrize(
    "bad,exc",
    [
        (-0.1, ValueError),
        (float("nan"), ValueError),
        (float("inf"), ValueError),
        (1j, TypeError),
        ("0.1", TypeError),
        (True, TypeError),
        (None, TypeError),
        (sp.I, ValueError),
        (sp.Symbol("lam"), ValueError),
        (-sp.Rational(1, 2), ValueError),
    ],
)
def test_dls_refuses_bad_damping(bad, exc):
    with pytest.raises(exc, match="damping"):
        damped_least_squares(np.eye(2), [1.0, 1.0], bad)


# ----------------------------------------------------------------------------------------------
# statics
# ----------------------------------------------------------------------------------------------
@SETTINGS
@given(st.integers(1, 7), st.integers(1, 7), st.integers(0, 2**31))
def test_power_balance(m, n, seed):
    """τ·θ̇ = F·V with V = J θ̇ and τ = Jᵀ F."""
    rng = np.random.default_rng(seed)
    J, F, qd = rng.normal(size=(m, n)), rng.normal(size=m), rng.normal(size=n)
    tau = joint_torques(J, F)
    assert np.isclose(tau @ qd, F @ (J @ qd))
    assert np.allclose(tau, J.T @ F)


def test_statics_frames_space_and_body():
    """A space Jacobian with the space wrench gives the same τ as the body Jacobian with the body wrench
    F_b = Ad_{T_sb}ᵀ F_s (modern_robotics' JacobianSpace/JacobianBody/Adjoint)."""
    rng = np.random.default_rng(9)
    M, S, kinds = random_arm(rng, 5)
    th = random_thetas(rng, kinds)
    B = mr.Adjoint(mr.TransInv(M)) @ S
    T = mr.FKinSpace(M, S, th)
    Fs = rng.normal(size=6)
    Fb = mr.Adjoint(T).T @ Fs
    assert np.allclose(joint_torques(mr.JacobianSpace(S, th), Fs), joint_torques(mr.JacobianBody(B, th), Fb))


def test_statics_batches_and_exact():
    rng = np.random.default_rng(4)
    Js, F = rng.normal(size=(4, 6, 3)), rng.normal(size=(4, 6))
    assert np.allclose(joint_torques(Js, F), np.einsum("kij,ki->kj", Js, F))
    J, th = _planar_2r_p()
    f = sp.symbols("f_x f_y", real=True)
    qd = sp.symbols("qd1 qd2", real=True)
    tau = joint_torques(J, list(f))
    assert sp.expand((tau.T * sp.Matrix(qd))[0] - (sp.Matrix(f).T * J * sp.Matrix(qd))[0]) == 0


# ----------------------------------------------------------------------------------------------
# force ellipsoid
# ----------------------------------------------------------------------------------------------
@SETTINGS
@given(st.integers(1, 6), st.integers(1, 7), st.integers(0, 2**31))
def test_force_ellipsoid_dual_to_velocity(m, n, seed):
    rng = np.random.default_rng(seed)
    J = rng.normal(size=(m, n))
    lengths, U = force_ellipsoid(J, rows=list(range(m)))
    s = np.linalg.svd(J, compute_uv=False)
    vl, vU = velocity_ellipsoid(J, rows=list(range(m)))
    assert np.allclose(lengths, 1 / s)
    assert np.allclose(np.abs(U), np.abs(vU))  # the same axes
    for i in range(len(s)):  # the semi-axis tip lies on ‖Jᵀ F‖ = 1
        assert np.isclose(np.linalg.norm(J.T @ (U[:, i] * lengths[i])), 1.0)


def test_force_ellipsoid_singular_is_inf_not_nan():
    J = np.array([[1.0, 1.0], [1.0, 1.0]])
    lengths, U = force_ellipsoid(J)
    assert np.isinf(lengths[1]) and np.isclose(lengths[0], 0.5) and not np.isnan(lengths).any()
    assert np.allclose(J.T @ U[:, 1], 0, atol=1e-12)
    lengths, _ = force_ellipsoid(np.zeros((2, 3)))
    assert np.all(np.isinf(lengths))
    Ls, Us = force_ellipsoid(np.stack([J, np.eye(2)]))
    assert Ls.shape == (2, 2) and Us.shape == (2, 2, 2) and np.isinf(Ls[0, 1]) and np.allclose(Ls[1], 1)


def test_force_ellipsoid_exact():
    lengths, U = force_ellipsoid(sp.Matrix([[2, 0], [0, 0]]))
    assert lengths == [sp.Rational(1, 2), sp.oo]
    J, th = _planar_2r_p()
    lengths, U = force_ellipsoid(J.subs({th[0]: 0, th[1]: 0}))  # stretched: no force along the arm needs torque
    assert sp.oo in lengths
    lengths, U = force_ellipsoid(J.subs({th[0]: 0, th[1]: sp.pi / 2}))
    s = np.linalg.svd(np.array(J.subs({th[0]: 0, th[1]: sp.pi / 2}).evalf(), dtype=float), compute_uv=False)
    assert np.allclose(sorted(float(x) for x in lengths), sorted(1 / s))


# ----------------------------------------------------------------------------------------------
# bad input
# ----------------------------------------------------------------------------------------------
BAD_MATRICES = [
    ("nan", np.array([[np.nan, 0.0], [0.0, 1.0]]), ValueError),
    ("inf", np.array([[np.inf, 0.0], [0.0, 1.0]]), ValueError),
    ("complex", np.array([[1j, 0], [0, 1]]), TypeError),
    ("str", "eye", TypeError),
    ("bool", [[True, False], [False, True]], TypeError),
    ("None", None, TypeError),
    ("1-D", np.array([1.0, 2.0]), ValueError),
    ("4-D", np.zeros((1, 1, 2, 2)), ValueError),
    ("sp.I", sp.Matrix([[sp.I, 0], [0, 1]]), ValueError),
    ("nan entry", [[1.0, None], [0.0, 1.0]], TypeError),
]


@pytest.mark.parametrize("label,bad,exc", BAD_MATRICES, ids=[b[0] for b in BAD_MATRICES])
@pytest.mark.parametrize(
    "fn",
    [
        lambda J: pseudoinverse(J),
        lambda J: inverse_velocity(J, [1.0, 1.0]),
        lambda J: damped_least_squares(J, [1.0, 1.0], 0.1),
        lambda J: joint_torques(J, [1.0, 1.0]),
        lambda J: force_ellipsoid(J),
    ],
    ids=["pseudoinverse", "inverse_velocity", "damped_least_squares", "joint_torques", "force_ellipsoid"],
)
def test_bad_jacobians_refused(fn, label, bad, exc):
    with pytest.raises((ValueError, TypeError)) as info:
        fn(bad)
    assert isinstance(info.value, exc) or label in ("sp.I", "nan entry", "bool")
    assert "J" in str(info.value)


@pytest.mark.parametrize(
    "bad", [np.array([np.nan, 1.0]), [1j, 1.0], "ab", [True, False], None, [1.0, 2.0, 3.0], [sp.I, 1]]
)
def test_bad_twists_and_wrenches_refused(bad):
    for fn, name in ((inverse_velocity, "V"), (joint_torques, "F")):
        with pytest.raises((ValueError, TypeError), match=name):
            fn(np.eye(2), bad)


@pytest.mark.parametrize(
    "bad",
    [
        np.full((3, 3), np.nan),
        np.eye(3) * 2,
        np.zeros((2, 2)),
        "R",
        None,
        True,
        np.eye(3) + 0j,
        [[1, 0, 0], [0, 1, 0], [0, 0, None]],
        np.diag([1.0, 1.0, -1.0]),
        sp.Matrix([[sp.I, 0, 0], [0, 1, 0], [0, 0, 1]]),
    ],
)
def test_log3_refuses(bad):
    with pytest.raises((ValueError, TypeError), match="R"):
        log3(bad)


@pytest.mark.parametrize(
    "bad",
    [
        np.full((4, 4), np.inf),
        np.eye(3),
        "T",
        None,
        np.eye(4) * 1j,
        np.array([[1, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, 0], [1, 0, 0, 1.0]]),
        np.diag([2.0, 1, 1, 1]),
    ],
)
def test_log6_refuses(bad):
    with pytest.raises((ValueError, TypeError), match="T"):
        log6(bad)


def test_bad_form_refused():
    with pytest.raises(ValueError, match="form"):
        log3(np.eye(3), form="quaternion")
    with pytest.raises(ValueError, match="form"):
        log6(np.eye(4), form=None)
