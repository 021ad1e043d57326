"""kinlib.manipulability against NumPy (det, SVD, cond) and modern_robotics Jacobians."""

from __future__ import annotations

import modern_robotics as mr
import numpy as np
import pytest
import sympy as sp

from helpers import assert_sym_equal
from kinlib import robots
from kinlib.manipulability import (
    condition_number,
    isotropy,
    manipulability,
    singular_values,
    twist_speed,
    twist_speed_form,
    velocity_ellipsoid,
)
from kinlib.singularities import evaluate_at, task_rows

pi = sp.pi


@pytest.mark.parametrize("m, n", [(2, 3), (3, 3), (6, 4), (3, 2), (6, 6), (1, 4)])
def test_numeric_manipulability_is_yoshikawa(rng, m, n):
    for _ in range(5):
        J = rng.normal(size=(m, n))
        G = J @ J.T if n >= m else J.T @ J
        assert np.isclose(manipulability(J), np.sqrt(np.linalg.det(G)), rtol=1e-10)
    batch = rng.normal(size=(7, m, n))
    w = manipulability(batch)
    assert w.shape == (7,)
    G = batch @ np.swapaxes(batch, 1, 2) if n >= m else np.swapaxes(batch, 1, 2) @ batch
    assert np.allclose(w, np.sqrt(np.linalg.det(G)), rtol=1e-10)


def test_numeric_condition_and_isotropy(rng):
    for shape in [(3, 3), (2, 3), (6, 4)]:
        J = rng.normal(size=shape)
        assert np.isclose(condition_number(J), np.linalg.cond(J))
        assert np.isclose(isotropy(J), 1 / np.linalg.cond(J))
    batch = rng.normal(size=(5, 3, 3))
    assert np.allclose(condition_number(batch), np.linalg.cond(batch))
    assert np.allclose(isotropy(batch), 1 / np.linalg.cond(batch))
    sing = np.array([[1.0, 1.0], [1.0, 1.0]])
    assert condition_number(sing) == np.inf and isotropy(sing) == 0.0
    assert isotropy(np.eye(3)) == 1.0 and condition_number(np.eye(3)) == 1.0
    assert isotropy(np.zeros((2, 2))) == 0.0


def test_problem_5_4_symbolic_form(rng):
    """√det(J Jᵀ) of the planar task rows is L²√(sin 2θ2 + 1) (the printed eq. 50), checked numerically."""
    r = robots.planar_offset_3r()
    L = r.params[0]
    th2 = r.thetas[1]
    J = task_rows(r.jacobian_space(), "planar")
    w = manipulability(J, simplify=True)
    assert w == L**2 * sp.sqrt(sp.sin(2 * th2) + 1)
    exact = manipulability(J)
    f = sp.lambdify((L,) + r.thetas, exact, "numpy")
    S = np.array(r.subs(L=1.3).screws, dtype=float)
    for _ in range(5):
        q = rng.uniform(-np.pi, np.pi, 3)
        Jn = mr.JacobianSpace(S, q)[[2, 3, 4]]
        assert np.isclose(f(1.3, *q), np.sqrt(np.linalg.det(Jn @ Jn.T)))
        assert np.isclose(manipulability(Jn), 1.3**2 * np.sqrt(np.sin(2 * q[1]) + 1))
    assert manipulability(evaluate_at(J, [0, -pi / 4, 0], r.thetas)) == 0


def test_rpp_is_isotropic_everywhere():
    """Problem 5.5: det(J Jᵀ) = 1, every singular value 1 (J_s rows ωz, vx, vy)."""
    p = robots.planar_rpp()
    J = task_rows(p.jacobian_space(), "planar")
    assert manipulability(J, simplify=True) == 1
    assert_sym_equal(J * J.T, sp.eye(3), "J Jᵀ")
    assert condition_number(J) == 1 and isotropy(J) == 1
    lengths, U = velocity_ellipsoid(J)
    assert lengths == [1, 1, 1]
    assert_sym_equal(U.T * U, sp.eye(3), "orthonormal axes")


def test_velocity_ellipsoid_numeric(rng):
    r = robots.planar_offset_3r(1)
    for _ in range(4):
        q = rng.uniform(-np.pi, np.pi, 3)
        Jg = r.jacobian_geometric(q)
        lengths, U = velocity_ellipsoid(Jg)  # a 6-row J: the linear rows ṗ
        Jp = Jg[3:]
        assert lengths.shape == (3,) and U.shape == (3, 3)
        assert np.allclose(U.T @ U, np.eye(3))
        for k in range(3):
            assert np.allclose(Jp @ Jp.T @ U[:, k], lengths[k] ** 2 * U[:, k], atol=1e-10)
        assert np.isclose(lengths[2], 0.0, atol=1e-12)  # planar: no ṗ_z
        l2, U2 = velocity_ellipsoid(Jg, rows=["vx", "vy"])
        assert np.allclose(l2, np.linalg.svd(Jp[:2], compute_uv=False))
    batch = r.jacobian_geometric(rng.uniform(-3, 3, (5, 3)))
    lb, Ub = velocity_ellipsoid(batch)
    assert lb.shape == (5, 3) and Ub.shape == (5, 3, 3)
    assert np.allclose(np.linalg.svd(batch[:, 3:, :], compute_uv=False), lb)
    assert np.allclose(singular_values(batch[:, 3:, :]), np.linalg.svd(batch[:, 3:, :], compute_uv=False))


def test_twist_speed_form_problem_6_2(rng):
    """Jᵀ J of the RPPR geometric Jacobian is diag(1 + (L2 + θ3)², 1, 1, 1): the printed eq. 60 lacks the 1."""
    r = robots.spatial_rppr()
    L2 = [p for p in r.params if str(p) == "L2"][0]
    th3 = r.thetas[2]
    J = r.jacobian_geometric()
    G = twist_speed_form(J, simplify=True)
    assert_sym_equal(G, sp.diag(1 + (L2 + th3) ** 2, 1, 1, 1), "JᵀJ")
    qd = sp.symbols("thetadot1:5", real=True)
    VV = twist_speed(J, qd)
    r1 = r.subs(L1=1, L2=sp.Rational(1, 2))
    for _ in range(4):
        q = rng.uniform(-2, 2, 4)
        v = rng.normal(size=4)
        Jn = r1.jacobian_geometric(q)
        assert np.isclose(twist_speed(Jn, v), np.dot(Jn @ v, Jn @ v))
        val = VV.subs({**dict(zip(r.thetas, q)), **dict(zip(qd, v)), L2: 0.5, r.params[0]: 1})
        assert np.isclose(float(val), np.dot(Jn @ v, Jn @ v))
        assert np.allclose(twist_speed_form(Jn), Jn.T @ Jn)
    assert twist_speed(np.ones((5, 6, 4)), np.ones(4)).shape == (5,)


def test_symbolic_condition_number_of_a_constant_matrix():
    J = sp.Matrix([[2, 0], [0, 1]])
    assert condition_number(J) == 2 and isotropy(J) == sp.Rational(1, 2)
    assert condition_number(sp.Matrix([[1, 1], [1, 1]])) == sp.oo
    assert isotropy(sp.Matrix([[1, 1], [1, 1]])) == 0


@pytest.mark.parametrize(
    "bad, exc",
    [
        ("J", TypeError),
        (None, TypeError),
        (3.0, TypeError),
        (np.zeros(3), ValueError),
        (np.zeros((2, 0)), ValueError),
        (np.array([[np.nan, 1.0]]), ValueError),
        ([["a", "b"]], TypeError),
        (np.zeros((2, 2, 2, 2)), ValueError),
    ],
)
def test_bad_input(bad, exc):
    for f in (manipulability, condition_number, isotropy):
        with pytest.raises(exc, match="J must"):
            f(bad)


def test_bad_qdot_and_rows():
    with pytest.raises(ValueError, match=r"qdot must .*\b4\b"):
        twist_speed(np.ones((6, 4)), np.ones(3))
    with pytest.raises(ValueError, match="qdot must be a vector of length 4"):
        twist_speed(sp.ones(6, 4), sp.symbols("a b c"))
    with pytest.raises(ValueError, match="unknown row"):
        velocity_ellipsoid(np.ones((6, 3)), rows=["vw"])


# --- velocity_ellipsoid(J, rows, hold): the ellipse with some task rows held at zero (issue 13, item 3) ------
def _null_basis_qr(H: np.ndarray) -> np.ndarray:
    """An orthonormal basis of null(H) by a complete QR of Hᵀ (independent of the SVD used by kinlib)."""
    r = np.linalg.matrix_rank(H)
    Q, _ = np.linalg.qr(H.T, mode="complete")
    return Q[:, r:]


def _support(lengths, U, d):
    """Support function of the ellipse with semi-axes lengths along the columns of U, in direction d."""
    return float(np.sqrt(np.sum((np.asarray(lengths) * (U.T @ d)) ** 2)))


def _geometric_J_mr(chain, q):
    """[ω_s; ṗ] from modern_robotics: ṗ = v_s + ω_s × p (p the tool origin)."""
    S, M = np.array(chain.screws, float), np.array(chain.M, float)
    Js = mr.JacobianSpace(S, np.asarray(q, float))
    p = mr.FKinSpace(M, S, np.asarray(q, float))[:3, 3]
    return np.vstack([Js[:3], Js[3:] - np.cross(p, Js[:3].T).T])


@pytest.mark.parametrize("n, rows, hold", [(3, ("vx", "vy"), ("wz",)), (6, "linear", "angular"), (5, [3, 4], [0, 2])])
def test_held_ellipsoid_support_function_and_extreme_points(rng, n, rows, hold):
    from kinlib.taskspace import task_row_indices

    r, h = list(task_row_indices(rows)), list(task_row_indices(hold))
    for _ in range(6):
        J = rng.normal(size=(6, n))
        lengths, U = velocity_ellipsoid(J, rows=rows, hold=hold)
        N = _null_basis_qr(J[h])
        A = J[r]
        assert np.allclose(U.T @ U, np.eye(U.shape[1]), atol=1e-10)
        for _ in range(10):  # support function: max over the unit ball of null(J_h) of d·(A θ̇) = ‖Nᵀ Aᵀ d‖
            d = rng.normal(size=len(r))
            assert _support(lengths, U, d) == pytest.approx(np.linalg.norm(N.T @ A.T @ d), rel=1e-9, abs=1e-12)
        # extreme points: sampled θ̇ = N z, ‖z‖ = 1 never leave the ellipse, and reach its largest semi-axis
        z = rng.normal(size=(N.shape[1], 400))
        pts = A @ N @ (z / np.linalg.norm(z, axis=0))
        big = np.max(np.abs(U[:, 0] @ pts))
        assert big <= lengths[0] * (1 + 1e-12) and big >= 0.9 * lengths[0]


def test_held_ellipse_semi_axes_by_mpmath(rng):
    import mpmath

    J = rng.normal(size=(6, 4))
    lengths, _ = velocity_ellipsoid(J, rows=("vx", "vy", "vz"), hold=("wz",))
    N = _null_basis_qr(J[[2]])
    s = mpmath.svd_r(mpmath.matrix((J[[3, 4, 5]] @ N).tolist()), compute_uv=False)
    assert sorted(lengths, reverse=True) == pytest.approx(sorted([float(x) for x in s], reverse=True), rel=1e-12)


def test_held_ellipse_collapses_at_theta2_minus_pi_over_4_on_the_section_5_robot():
    """Notebook 05's explorer at θ2 = −π/4: the held ellipse is a segment, the free ṗ ellipse stays fat."""
    chain = robots.planar_offset_3r(1)
    q = [np.pi / 6, -np.pi / 4, -np.pi / 3]
    J = _geometric_J_mr(chain, q)
    held, U = velocity_ellipsoid(J, rows=("vx", "vy"), hold=("wz",))
    free, _ = velocity_ellipsoid(J, rows=("vx", "vy"))
    assert held[1] < 1e-12 and held[0] > 1.0
    assert free == pytest.approx([2.79, 1.03], abs=0.01)
    # the exact values at the exact configuration: the zero is an exact 0
    Je = robots.planar_offset_3r(1).jacobian_geometric([pi / 6, -pi / 4, -pi / 3])
    exact, Ue = velocity_ellipsoid(Je, rows=("vx", "vy"), hold=("wz",))
    assert exact[1] == 0 and float(exact[0]) == pytest.approx(held[0], rel=1e-12)
    assert all(isinstance(x, sp.Basic) for x in exact) and not any(e.has(sp.Float) for e in exact)
    assert np.allclose(np.abs(np.array(Ue, float)), np.abs(U), atol=1e-12)


def test_held_ellipse_is_flat_exactly_on_the_singular_set(rng):
    """|det [J_ω; J_ṗ]| = ‖J_ω‖ · σ1 σ2 of the held map (an identity for one held row): the smallest held
    semi-axis is 0 exactly where the task rows (ω_z, ṗ_x, ṗ_y) lose rank — on the family θ2 = −π/4, 3π/4."""
    chain = robots.planar_offset_3r(1)
    for _ in range(20):
        q = rng.uniform(-np.pi, np.pi, 3)
        J = _geometric_J_mr(chain, q)
        held, _ = velocity_ellipsoid(J, rows=("vx", "vy"), hold=("wz",))
        T = J[[2, 3, 4]]
        assert np.sqrt(3) * np.prod(held) == pytest.approx(abs(np.linalg.det(T)), abs=1e-12)
    for theta2 in (-np.pi / 4, 3 * np.pi / 4):
        for _ in range(10):
            q = [rng.uniform(-np.pi, np.pi), theta2, rng.uniform(-np.pi, np.pi)]
            J = _geometric_J_mr(chain, q)
            held, _ = velocity_ellipsoid(J, rows=("vx", "vy"), hold=("wz",))
            assert held[-1] < 1e-12 * held[0]
            assert np.linalg.matrix_rank(J[[2, 3, 4]], tol=1e-9) == 2


@pytest.mark.parametrize(
    "kwargs, exc, words",
    [
        (dict(rows=("vx", "vy"), hold=("vx",)), ValueError, ["rows", "hold", "share"]),
        (dict(rows=("vx", "vy"), hold=("spin",)), ValueError, ["hold", "unknown"]),
        (dict(rows=None, hold=("wz",)), ValueError, ["rows"]),
        (dict(rows=("vx", "vy"), hold=True), TypeError, ["hold"]),
        (dict(rows=("vx", "vy"), hold=[]), ValueError, ["hold"]),
    ],
)
def test_held_ellipse_refuses_bad_arguments(kwargs, exc, words):
    J = np.arange(18.0).reshape(6, 3)
    with pytest.raises(exc) as e:
        velocity_ellipsoid(J, **kwargs)
    assert all(w in str(e.value) for w in words), str(e.value)


@pytest.mark.parametrize(
    "J, exc",
    [
        (np.full((6, 3), np.nan), ValueError),
        (np.zeros((4, 6, 3)), ValueError),
        ("J", TypeError),
        (np.zeros((2, 3)), ValueError),  # names need 6 rows
    ],
)
def test_held_ellipse_refuses_bad_J(J, exc):
    with pytest.raises(exc, match="J|rows"):
        velocity_ellipsoid(J, rows=("vx", "vy"), hold=("wz",))
