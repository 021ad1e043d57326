"""The three Jacobians against finite differences of the forward kinematics, and their conversions.

* [J_s θ̇] = Ṫ T⁻¹ (the spatial twist), [J_b θ̇] = T⁻¹ Ṫ (the body twist),
* geometric J: lower block = ṗ (velocity of the tool origin), upper block = ω_s (Ṙ Rᵀ = [ω_s]),
with Ṫ by central differences of fk along θ̇; properties (hypothesis): J_b = Ad_{T⁻¹} J_s, the
conversions invert each other, [ω; v] ↔ [v; ω], symbolic at a random point = numeric.
"""

from __future__ import annotations

import modern_robotics as mr
import numpy as np
import pytest
import sympy as sp
from hypothesis import given
from hypothesis import strategies as st

import kinlib
from helpers import FAST, assert_sym_equal, random_arm, random_thetas
from kinlib import robots

seeds = st.integers(min_value=0, max_value=2**32 - 1)
njoints = st.integers(min_value=1, max_value=7)
H = 1e-6
FD_TOL = 1e-6


def _tdot(fk, th, thdot):
    """Ṫ = d/dt T(θ + t θ̇) at t = 0, by central differences."""
    return (fk(th + H * thdot) - fk(th - H * thdot)) / (2 * H)


def _vee(X):
    """se(3) 4×4 → [ω; v] (written out here, not kinlib's unbracket)."""
    return np.array([X[2, 1], X[0, 2], X[1, 0], X[0, 3], X[1, 3], X[2, 3]])


def _check_fd(fk, Js, Jb, Jg, th, thdot):
    T = fk(th)
    Tdot = _tdot(fk, th, thdot)
    Tinv = np.linalg.inv(T)
    np.testing.assert_allclose(Js @ thdot, _vee(Tdot @ Tinv), atol=FD_TOL, err_msg="[J_s θ̇] = Ṫ T⁻¹")
    np.testing.assert_allclose(Jb @ thdot, _vee(Tinv @ Tdot), atol=FD_TOL, err_msg="[J_b θ̇] = T⁻¹ Ṫ")
    R = T[:3, :3]
    Wdot = Tdot[:3, :3] @ R.T
    omega_s = np.array([Wdot[2, 1], Wdot[0, 2], Wdot[1, 0]])
    np.testing.assert_allclose(Jg[3:] @ thdot, Tdot[:3, 3], atol=FD_TOL, err_msg="geometric J lower block = ṗ")
    np.testing.assert_allclose(Jg[:3] @ thdot, omega_s, atol=FD_TOL, err_msg="geometric J upper block = ω_s")


@pytest.mark.parametrize("n", range(1, 8))
@pytest.mark.parametrize("seed", range(4))
def test_finite_differences_free_functions(seed, n):
    rng = np.random.default_rng(77 * n + seed)
    M, S, kinds = random_arm(rng, n)
    B = mr.Adjoint(mr.TransInv(M)) @ S

    def fk(q):  # modern_robotics' FK: the differences do not depend on kinlib
        return mr.FKinSpace(M, S, q)

    for th in random_thetas(rng, kinds, size=2):
        thdot = rng.normal(size=n)
        _check_fd(
            fk,
            kinlib.jacobian_space(S, th),
            kinlib.jacobian_body(B, th),
            kinlib.geometric_jacobian(M, S, th),
            th,
            thdot,
        )
        # column by column too (θ̇ = e_i)
        for i in range(n):
            _check_fd(
                fk,
                kinlib.jacobian_space(S, th),
                kinlib.jacobian_body(B, th),
                kinlib.geometric_jacobian(M, S, th),
                th,
                np.eye(n)[i],
            )


@pytest.mark.parametrize(
    "chain",
    [
        robots.cart_pole(1, sp.Rational(1, 2)),
        robots.planar_offset_3r(1),
        robots.spatial_rppr(1, 2),
        robots.planar_3r(1, 2, 3),
        robots.planar_rpp(1),
        robots.ur5(),
    ],
    ids=lambda c: c.name,
)
def test_finite_differences_problem_set_robots(chain):
    """The chains' generated code against finite differences of their own generated fk."""
    rng = np.random.default_rng(5)
    for th in random_thetas(rng, chain.joint_types, size=3):
        thdot = rng.normal(size=chain.n)
        _check_fd(chain.fk, chain.jacobian_space(th), chain.jacobian_body(th), chain.jacobian_geometric(th), th, thdot)


def test_cart_pole_pdot_by_finite_differences():
    """Problem 1.1: ṗ = [[1, −L sin θ2], [0, L cos θ2]] θ̇ against differences of p(θ) of eqs. (1)-(2)."""
    L, h = 0.8, 0.3
    r = robots.cart_pole(L, h)

    def p(q):
        return np.array([q[0] + L * np.cos(q[1]), h + L * np.sin(q[1])])

    rng = np.random.default_rng(3)
    for _ in range(5):
        th, thdot = rng.normal(size=2), rng.normal(size=2)
        pdot = (p(th + H * thdot) - p(th - H * thdot)) / (2 * H)
        np.testing.assert_allclose(r.jacobian_geometric(th)[3:5] @ thdot, pdot, atol=FD_TOL)
        np.testing.assert_allclose(r.fk(th)[:2, 3], p(th), atol=1e-12)


# --------------------------------------------------------------------------------------------
# properties
# --------------------------------------------------------------------------------------------
def _arm_at(seed, n):
    rng = np.random.default_rng(seed)
    M, S, kinds = random_arm(rng, n)
    th = random_thetas(rng, kinds)
    return M, S, th, mr.FKinSpace(M, S, th)


@FAST
@given(seeds, njoints)
def test_body_is_adjoint_of_space(seed, n):
    """J_b = Ad_{T⁻¹} J_s (modern_robotics' Adjoint and TransInv), and the body screws are Ad_{M⁻¹} S."""
    M, S, th, T = _arm_at(seed, n)
    Js = kinlib.jacobian_space(S, th)
    B = kinlib.adjoint(kinlib.trans_inv(M)) @ S
    Jb = kinlib.jacobian_body(B, th)
    np.testing.assert_allclose(Jb, mr.Adjoint(mr.TransInv(T)) @ Js, atol=1e-9)
    np.testing.assert_allclose(kinlib.space_to_body(Js, T), Jb, atol=1e-9)
    np.testing.assert_allclose(kinlib.body_to_space(Jb, T), Js, atol=1e-9)


@FAST
@given(seeds, njoints)
def test_conversions_invert_each_other(seed, n):
    M, S, th, T = _arm_at(seed, n)
    R = T[:3, :3]
    Js = kinlib.jacobian_space(S, th)
    Jb = kinlib.space_to_body(Js, T)
    J = kinlib.space_to_geometric(Js, T)
    close = dict(atol=1e-9, rtol=0)
    np.testing.assert_allclose(kinlib.body_to_space(kinlib.space_to_body(Js, T), T), Js, **close)
    np.testing.assert_allclose(kinlib.geometric_to_space(J, T), Js, **close)
    np.testing.assert_allclose(kinlib.geometric_to_body(J, T), Jb, **close)
    np.testing.assert_allclose(kinlib.geometric_to_body(J, R), Jb, **close)  # R alone is enough
    np.testing.assert_allclose(kinlib.body_to_geometric(Jb, T), J, **close)
    np.testing.assert_allclose(kinlib.body_to_geometric(Jb, R), J, **close)
    # geometric_jacobian against modern_robotics: blockdiag(R, R) JacobianBody(Ad_{M⁻¹} S)
    Jb_mr = mr.JacobianBody(mr.Adjoint(mr.TransInv(M)) @ S, th)
    np.testing.assert_allclose(kinlib.geometric_jacobian(M, S, th), np.vstack([R @ Jb_mr[:3], R @ Jb_mr[3:]]), **close)
    # the definitions: J = blockdiag(R, R) J_b; ṗ = v_s + ω_s × p
    np.testing.assert_allclose(J, np.vstack([R @ Jb[:3], R @ Jb[3:]]), **close)
    p = T[:3, 3]
    np.testing.assert_allclose(J[3:], Js[3:] + np.cross(Js[:3].T, p).T, **close)


@FAST
@given(seeds, njoints)
def test_linear_first_angular_first(seed, n):
    """[ω; v] → [v; ω] (Pinocchio/RTB order) and back, for a Jacobian and a twist."""
    _, S, th, _ = _arm_at(seed, n)
    J = kinlib.jacobian_space(S, th)
    Jl = kinlib.linear_first(J)
    np.testing.assert_array_equal(Jl, J[[3, 4, 5, 0, 1, 2]])
    np.testing.assert_array_equal(Jl[:3], J[3:])
    np.testing.assert_array_equal(kinlib.angular_first(Jl), J)
    np.testing.assert_array_equal(kinlib.linear_first(kinlib.angular_first(J)), J)
    V = J[:, 0]
    assert kinlib.linear_first(V).shape == (6,)
    np.testing.assert_array_equal(kinlib.linear_first(V), np.concatenate([V[3:], V[:3]]))
    np.testing.assert_array_equal(kinlib.angular_first(kinlib.linear_first(V)), V)


def test_linear_first_symbolic():
    r = robots.planar_offset_3r()
    J = r.jacobian_geometric()
    Jl = kinlib.linear_first(J)
    assert isinstance(Jl, sp.MatrixBase) and Jl == sp.Matrix.vstack(J[3:, :], J[:3, :])
    assert kinlib.angular_first(Jl) == J
    assert kinlib.linear_first(sp.Matrix([1, 2, 3, 4, 5, 6])) == sp.Matrix([4, 5, 6, 1, 2, 3])


_SYMBOLIC = {name: getattr(robots, name)() for name in ("cart_pole", "planar_offset_3r", "spatial_rppr", "planar_3r")}
positive = st.floats(min_value=0.1, max_value=3.0)
joint = st.floats(min_value=-3.0, max_value=3.0)


# modern_robotics' MatrixExp6 takes a rotation by |θ| < 1e-6 (its NearZero) as no rotation at all: keep the
# oracle's joint values at 0 or clear of that threshold
mr_joint = joint.filter(lambda x: x == 0 or abs(x) > 1e-5)


@FAST
@given(
    st.sampled_from(sorted(_SYMBOLIC)),
    st.lists(positive, min_size=3, max_size=3),
    st.lists(mr_joint, min_size=4, max_size=4),
)
def test_symbolic_at_random_point_equals_numeric(name, lengths, qs):
    """The exact chain, substituted at a random point, equals modern_robotics there."""
    chain = _SYMBOLIC[name]
    params = dict(zip(chain.params, lengths))
    q = qs[: chain.n]
    point = {**params, **dict(zip(chain.thetas, q))}
    M = np.array(chain.M.subs(params), dtype=float)
    S = np.array(chain.screws.subs(params), dtype=float)
    T = mr.FKinSpace(M, S, q)
    Jb = mr.JacobianBody(mr.Adjoint(mr.TransInv(M)) @ S, q)
    R = T[:3, :3]
    for label, sym, num in [
        ("T", chain.fk(), T),
        ("J_s", chain.jacobian_space(), mr.JacobianSpace(S, q)),
        ("J_b", chain.jacobian_body(), Jb),
        ("J", chain.jacobian_geometric(), np.vstack([R @ Jb[:3], R @ Jb[3:]])),
    ]:
        np.testing.assert_allclose(np.array(sym.subs(point), dtype=float), num, atol=1e-9, err_msg=label)


def _vee_sym(X):
    """se(3) or so(3) matrix → its vector ([ω; v] or ω), written out here, not kinlib's unbracket."""
    w = sp.Matrix([X[2, 1], X[0, 2], X[1, 0]])
    return sp.Matrix.vstack(w, X[:3, 3]) if X.shape == (4, 4) else w


def test_symbolic_free_functions_equal_chain_methods():
    """The free functions and the chain's methods, exact, against the derivatives of the problem set's T(θ)
    (eq. (27), typed by hand): column i of J_s is (∂T/∂θ_i) T⁻¹, of J_b T⁻¹ (∂T/∂θ_i), of J [ω_s; ∂p/∂θ_i]."""
    r = robots.spatial_rppr()
    th = list(r.thetas)
    L1, L2 = sp.symbols("L1 L2", positive=True)
    t1, t2, t3, t4 = th
    c1, s1, c4, s4 = sp.cos(t1), sp.sin(t1), sp.cos(t4), sp.sin(t4)
    T = sp.Matrix(
        [
            [c1, -c4 * s1, s1 * s4, (L2 + t3) * c1],
            [s1, c1 * c4, -c1 * s4, (L2 + t3) * s1],
            [0, s4, c4, L1 + L2 + t2],
            [0, 0, 0, 1],
        ]
    )  # eq. (27)
    R = T[:3, :3]
    Tinv = sp.Matrix.vstack(sp.Matrix.hstack(R.T, -R.T * T[:3, 3]), sp.Matrix([[0, 0, 0, 1]]))
    dT = [T.diff(t) for t in th]
    Js = sp.Matrix.hstack(*[_vee_sym(sp.simplify(d * Tinv)) for d in dT])
    Jb = sp.Matrix.hstack(*[_vee_sym(sp.simplify(Tinv * d)) for d in dT])
    J = sp.Matrix.hstack(*[sp.Matrix.vstack(_vee_sym(sp.simplify(d[:3, :3] * R.T)), d[:3, 3]) for d in dT])
    assert_sym_equal(kinlib.jacobian_space(r.screws, th), Js, "J_s (free function) = Ṫ T⁻¹")
    assert_sym_equal(r.jacobian_space(), Js, "J_s (chain) = Ṫ T⁻¹")
    assert_sym_equal(kinlib.jacobian_body(r.body_screws, th), Jb, "J_b (free function) = T⁻¹ Ṫ")
    assert_sym_equal(r.jacobian_body(), Jb, "J_b (chain) = T⁻¹ Ṫ")
    assert_sym_equal(kinlib.space_to_geometric(r.jacobian_space(), r.fk()), J, "J (space_to_geometric) = [ω_s; ṗ]")
    assert_sym_equal(r.jacobian_geometric(), J, "J (chain) = [ω_s; ṗ]")
    assert_sym_equal(kinlib.geometric_jacobian(r.M, r.screws, th), J, "J (geometric_jacobian) = [ω_s; ṗ]")
    # the conversions, on the derivatives: inputs and expected results both independent of kinlib
    assert_sym_equal(kinlib.geometric_to_space(J, T), Js, "J → J_s")
    assert_sym_equal(kinlib.geometric_to_body(J, T), Jb, "J → J_b")
    assert_sym_equal(kinlib.body_to_space(Jb, T), Js, "J_b → J_s")
    assert_sym_equal(kinlib.space_to_body(Js, T), Jb, "J_s → J_b")


def test_position_jacobian_matches_geometric_rows_planar_3r():
    r = robots.planar_3r()
    p = r.fk()[:2, 3]
    assert_sym_equal(kinlib.position_jacobian(p, list(r.thetas)), r.jacobian_geometric()[3:5, :], "∂p/∂θ")
    t = sp.Symbol("t", real=True)
    assert kinlib.position_jacobian([t**2, sp.sin(t)], t) == sp.Matrix([[2 * t], [sp.cos(t)]])
