"""The closed forms printed in the problem set (sections 1.1, 2, 3 and eq. 33 of section 4) against kinlib.

Every expected matrix below is typed from the problem set (``/work/shared/problem-set-4.md``), and
each was checked by hand from the robot's geometry before it was typed. Transcription typos found
while doing so (the computation wins):

* eq. (4) reads ``p_y = L θ̇2 cos θ2``; it is ṗ_y (the time derivative), as eq. (5) shows.
* eqs. (18), (20), the 2.4 answer and eq. (33) print the first three rows with four entries
  (``0 & 0 & 0 & 0``, ``1 & 1 & 1 & 1``) for a 3-joint robot; the Jacobians are 6×3, with rows
  [0, 0, 0], [0, 0, 0], [1, 1, 1].
* eq. (60) (section 6.2, checked here because it is J of eq. (32) again) prints JᵀJ with (1, 1) entry
  (L2 + θ3)²; it is (L2 + θ3)² + 1, since column 1 of J also has ω_z = 1.
Apart from those, every printed closed form of sections 2 and 3 and eq. (33) agrees with the computation.
"""

from __future__ import annotations

import pytest
import sympy as sp

import kinlib
from helpers import assert_no_floats, assert_sym_equal
from kinlib import robots

sin, cos, sqrt, pi = sp.sin, sp.cos, sp.sqrt, sp.pi


# --------------------------------------------------------------------------------------------
# 1.1 cart-pole
# --------------------------------------------------------------------------------------------
def test_cart_pole_position_jacobian_eq5():
    """Eq. (5) from the hand-written position map of eqs. (1)-(2), through position_jacobian."""
    L, h = sp.symbols("L h", positive=True)
    t1, t2 = sp.symbols("theta1 theta2", real=True)
    p = [t1 + L * cos(t2), h + L * sin(t2)]  # eqs. (1), (2)
    J = kinlib.position_jacobian(p, [t1, t2])
    assert_sym_equal(J, sp.Matrix([[1, -L * sin(t2)], [0, L * cos(t2)]]), "eq. (5)")
    # eqs. (3)-(4): ṗ = J θ̇ (eq. 4 prints p_y where ṗ_y is meant)
    d1, d2 = sp.symbols("thetadot1 thetadot2", real=True)
    pdot = J * sp.Matrix([d1, d2])
    assert_sym_equal(pdot[0], d1 - L * d2 * sin(t2), "eq. (3)")
    assert_sym_equal(pdot[1], L * d2 * cos(t2), "eq. (4), with ṗ_y for the printed p_y")


def test_cart_pole_chain_matches_eq5():
    """The chain's tool position is eqs. (1)-(2), and rows ṗ_x, ṗ_y of its geometric Jacobian are eq. (5)."""
    r = robots.cart_pole()
    L, h = sp.symbols("L h", positive=True)
    t1, t2 = r.thetas
    assert r.joint_types == "PR"
    T = r.fk()
    assert_sym_equal(T[:3, 3], sp.Matrix([t1 + L * cos(t2), h + L * sin(t2), 0]), "cart-pole p(θ)")
    J = r.jacobian_geometric()
    assert_sym_equal(J[3:5, :], sp.Matrix([[1, -L * sin(t2)], [0, L * cos(t2)]]), "cart-pole ṗ_x, ṗ_y rows")
    # the other rows: ω_s = [0, 0, θ̇2], ṗ_z = 0
    assert_sym_equal(J[[0, 1, 2, 5], :], sp.Matrix([[0, 0], [0, 0], [0, 1], [0, 0]]), "cart-pole other rows")
    # and the same through the free function on the cart-pole's M and screws typed by hand (prismatic along x,
    # revolute about z through (0, h)), against eq. (5) and the rows ω_z = θ̇2 (not the chain's own output)
    M = sp.Matrix([[1, 0, 0, L], [0, 1, 0, h], [0, 0, 1, 0], [0, 0, 0, 1]])
    S = sp.Matrix([[0, 0, 0, 1, 0, 0], [0, 0, 1, h, 0, 0]]).T
    J5 = sp.Matrix([[0, 0], [0, 0], [0, 1], [1, -L * sin(t2)], [0, L * cos(t2)], [0, 0]])
    assert_sym_equal(kinlib.geometric_jacobian(M, S, list(r.thetas)), J5, "geometric_jacobian(M, S, θ), eq. (5)")
    # position_jacobian of the chain's own p(θ) equals the geometric rows
    assert_sym_equal(kinlib.position_jacobian(T[:2, 3], list(r.thetas)), J[3:5, :], "∂p/∂θ of the chain")


# --------------------------------------------------------------------------------------------
# Section 2: planar robot, joints at (0,0), (L,0), (2L,L), tool at (3L,L)
# --------------------------------------------------------------------------------------------
L = sp.Symbol("L", positive=True)


@pytest.fixture(scope="module")
def planar():
    return robots.planar_offset_3r()


def _sec2_printed(t1, t2, t3):
    c1, s1 = cos(t1), sin(t1)
    c123, s123 = cos(t1 + t2 + t3), sin(t1 + t2 + t3)
    a = t1 + t2 + pi / 4
    M = sp.Matrix([[1, 0, 0, 3 * L], [0, 1, 0, L], [0, 0, 1, 0], [0, 0, 0, 1]])  # (14)
    S = sp.Matrix([[0, 0, 1, 0, 0, 0], [0, 0, 1, 0, -L, 0], [0, 0, 1, L, -2 * L, 0]]).T  # (16)
    T = sp.Matrix(
        [  # (17)
            [c123, -s123, 0, L * c123 + L * c1 + L * sqrt(2) * cos(a)],
            [s123, c123, 0, L * s123 + L * s1 + L * sqrt(2) * sin(a)],
            [0, 0, 1, 0],
            [0, 0, 0, 1],
        ]
    )
    Js = sp.Matrix(
        [  # (18), 6×3 (the transcription prints 4 entries in rows 1-3)
            [0, 0, 0],
            [0, 0, 0],
            [1, 1, 1],
            [0, L * s1, L * s1 + L * sqrt(2) * sin(a)],
            [0, -L * c1, -L * c1 - L * sqrt(2) * cos(a)],
            [0, 0, 0],
        ]
    )
    Jb = sp.Matrix(
        [  # (20)
            [0, 0, 0],
            [0, 0, 0],
            [1, 1, 1],
            [L * sin(t2 + t3) - L * sqrt(2) * cos(t3 + pi / 4), -L * sqrt(2) * cos(t3 + pi / 4), 0],
            [L * cos(t2 + t3) + L * sqrt(2) * sin(t3 + pi / 4) + L, L * sqrt(2) * sin(t3 + pi / 4) + L, L],
            [0, 0, 0],
        ]
    )
    J = sp.Matrix(
        [  # 2.4
            [0, 0, 0],
            [0, 0, 0],
            [1, 1, 1],
            [-L * s123 - L * s1 - L * sqrt(2) * sin(a), -L * s123 - L * sqrt(2) * sin(a), -L * s123],
            [L * c123 + L * c1 + L * sqrt(2) * cos(a), L * c123 + L * sqrt(2) * cos(a), L * c123],
            [0, 0, 0],
        ]
    )
    return M, S, T, Js, Jb, J


def test_section2_home_and_screws(planar):
    """Eqs. (14)-(16); the body screws B_i = [ω; −ω × (q_i − p_M)] worked by hand from eq. (15)."""
    M, S, *_ = _sec2_printed(*planar.thetas)
    assert planar.M == M
    assert planar.screws == S
    assert planar.joint_types == "RRR"
    assert planar.params == (L,)
    # the screws from eq. (15)'s ω and q through screw_revolute
    qs = [[0, 0, 0], [L, 0, 0], [2 * L, L, 0]]
    built = sp.Matrix.hstack(*[kinlib.screw_revolute(sp.Matrix([0, 0, 1]), sp.Matrix(q)) for q in qs])
    assert built == S
    B = sp.Matrix([[0, 0, 1, -L, 3 * L, 0], [0, 0, 1, -L, 2 * L, 0], [0, 0, 1, 0, L, 0]]).T
    assert_sym_equal(planar.body_screws, B, "section 2 body screws")


def test_section2_closed_forms(planar):
    """T(θ) (17), J_s (18), J_b (20) and J (2.4) through the chain."""
    _, _, T, Js, Jb, J = _sec2_printed(*planar.thetas)
    assert_sym_equal(planar.fk(), T, "T(θ), eq. (17)")
    assert_sym_equal(planar.jacobian_space(), Js, "J_s, eq. (18)")
    assert_sym_equal(planar.jacobian_body(), Jb, "J_b, eq. (20)")
    assert_sym_equal(planar.jacobian_geometric(), J, "J, 2.4")


def test_section2_free_functions(planar):
    """The same closed forms through the free functions and the conversions of eqs. (19) and (21)."""
    M, S, T, Js, Jb, J = _sec2_printed(*planar.thetas)
    th = list(planar.thetas)
    Tk = kinlib.fk_space(M, S, th)
    assert_sym_equal(Tk, T, "fk_space")
    assert_sym_equal(kinlib.fk_body(M, planar.body_screws, th), T, "fk_body")
    Jsk = kinlib.jacobian_space(S, th)
    assert_sym_equal(Jsk, Js, "jacobian_space")
    assert_sym_equal(kinlib.jacobian_body(planar.body_screws, th), Jb, "jacobian_body")
    assert_sym_equal(kinlib.space_to_body(Jsk, Tk), Jb, "J_b = Ad_{T⁻¹} J_s, eq. (19)")
    assert_sym_equal(kinlib.body_to_geometric(Jb, T), J, "J = blockdiag(R, R) J_b, eq. (21)")
    assert_sym_equal(kinlib.geometric_jacobian(M, S, th), J, "geometric_jacobian")
    # a list of 6-vectors works as well as a 6×n matrix
    assert_sym_equal(kinlib.jacobian_space([list(S[:, i]) for i in range(3)], th), Js, "Slist as a sequence")


def test_section2_at_problem_5_3_configuration(planar):
    """Eq. (47): J_s at θ = (π/4, −π/4, π/4), exactly (rows ω_z, v_x, v_y)."""
    Js = planar.jacobian_space([pi / 4, -pi / 4, pi / 4])
    expected = sp.Matrix(
        [[1, 1, 1], [0, sqrt(2) * L / 2, L * (sqrt(2) + 2) / 2], [0, -sqrt(2) * L / 2, -L * (sqrt(2) + 2) / 2]]
    )
    assert_sym_equal(Js[[2, 3, 4], :], expected, "eq. (47)")
    assert_no_floats(Js, "J_s at an exact configuration")


# --------------------------------------------------------------------------------------------
# Section 3: spatial RPPR
# --------------------------------------------------------------------------------------------
L1, L2 = sp.symbols("L1 L2", positive=True)


@pytest.fixture(scope="module")
def rppr():
    return robots.spatial_rppr()


def _sec3_printed(t1, t2, t3, t4):
    c1, s1, c4, s4 = cos(t1), sin(t1), cos(t4), sin(t4)
    H = L1 + L2
    M = sp.Matrix([[1, 0, 0, L2], [0, 1, 0, 0], [0, 0, 1, H], [0, 0, 0, 1]])  # (22)
    S = sp.Matrix([[0, 0, 1, 0, 0, 0], [0, 0, 0, 0, 0, 1], [0, 0, 0, 1, 0, 0], [1, 0, 0, 0, H, 0]]).T  # (23)-(26)
    T = sp.Matrix(
        [  # (27)
            [c1, -c4 * s1, s1 * s4, (L2 + t3) * c1],
            [s1, c1 * c4, -c1 * s4, (L2 + t3) * s1],
            [0, s4, c4, H + t2],
            [0, 0, 0, 1],
        ]
    )
    Js = sp.Matrix(
        [  # (28)
            [0, 0, 0, c1],
            [0, 0, 0, s1],
            [1, 0, 0, 0],
            [0, 0, c1, -(H + t2) * s1],
            [0, 0, s1, (H + t2) * c1],
            [0, 1, 0, 0],
        ]
    )
    Jb = sp.Matrix(
        [  # (30)
            [0, 0, 0, 1],
            [s4, 0, 0, 0],
            [c4, 0, 0, 0],
            [0, 0, 1, 0],
            [(L2 + t3) * c4, s4, 0, 0],
            [-(L2 + t3) * s4, c4, 0, 0],
        ]
    )
    J = sp.Matrix(
        [  # (32)
            [0, 0, 0, c1],
            [0, 0, 0, s1],
            [1, 0, 0, 0],
            [-(L2 + t3) * s1, 0, c1, 0],
            [(L2 + t3) * c1, 0, s1, 0],
            [0, 1, 0, 0],
        ]
    )
    return M, S, T, Js, Jb, J


def test_section3_home_and_screws(rppr):
    M, S, *_ = _sec3_printed(*rppr.thetas)
    assert rppr.M == M
    assert rppr.screws == S
    assert rppr.joint_types == "RPPR"
    assert set(rppr.params) == {L1, L2}
    # S4 from its axis (x) and a point on it (0, 0, L1 + L2); S2, S3 from their directions
    assert kinlib.screw_revolute(sp.Matrix([1, 0, 0]), sp.Matrix([0, 0, L1 + L2])) == S[:, 3]
    assert kinlib.screw_prismatic(sp.Matrix([0, 0, 1])) == S[:, 1]
    assert kinlib.screw_prismatic(sp.Matrix([1, 0, 0])) == S[:, 2]
    B = sp.Matrix([[0, 0, 1, 0, L2, 0], [0, 0, 0, 0, 0, 1], [0, 0, 0, 1, 0, 0], [1, 0, 0, 0, 0, 0]]).T
    assert_sym_equal(rppr.body_screws, B, "section 3 body screws")


def test_section3_closed_forms(rppr):
    """T(θ) (27), J_s (28), J_b (30), J (32) through the chain."""
    _, _, T, Js, Jb, J = _sec3_printed(*rppr.thetas)
    assert_sym_equal(rppr.fk(), T, "T(θ), eq. (27)")
    assert_sym_equal(rppr.jacobian_space(), Js, "J_s, eq. (28)")
    assert_sym_equal(rppr.jacobian_body(), Jb, "J_b, eq. (30)")
    assert_sym_equal(rppr.jacobian_geometric(), J, "J, eq. (32)")


def test_section3_free_functions(rppr):
    M, S, T, Js, Jb, J = _sec3_printed(*rppr.thetas)
    th = list(rppr.thetas)
    Tk = kinlib.fk_space(M, S, th)
    assert_sym_equal(Tk, T, "fk_space")
    assert_sym_equal(kinlib.fk_body(M, rppr.body_screws, th), T, "fk_body")
    Jsk = kinlib.jacobian_space(S, th)
    assert_sym_equal(Jsk, Js, "jacobian_space")
    assert_sym_equal(kinlib.jacobian_body(rppr.body_screws, th), Jb, "jacobian_body")
    assert_sym_equal(kinlib.space_to_body(Jsk, Tk), Jb, "eq. (29)")
    assert_sym_equal(kinlib.body_to_geometric(Jb, T), J, "eq. (31)")
    assert_sym_equal(kinlib.geometric_jacobian(M, S, th), J, "geometric_jacobian")
    # 6.2's JᵀJ. DISCREPANCY: eq. (60) prints diag((L2 + θ3)², 1, 1, 1), but column 1 of J (eq. 32)
    # is [0, 0, 1, −(L2 + θ3) s1, (L2 + θ3) c1, 0]: its squared length is (L2 + θ3)² + 1 (the ω_z = 1
    # entry counts too). The computation wins; eq. (61)'s conclusion (θ3 → ±∞) is unchanged.
    t3 = th[2]
    assert_sym_equal(J.T * J, sp.diag((L2 + t3) ** 2 + 1, 1, 1, 1), "JᵀJ (eq. 60 corrected)")
    assert not _equal_as_printed(J.T * J, sp.diag((L2 + t3) ** 2, 1, 1, 1))


def _equal_as_printed(A, B):
    return all(sp.simplify(e) == 0 for e in (A - B))


# --------------------------------------------------------------------------------------------
# Section 4: planar 3R, eq. (33)
# --------------------------------------------------------------------------------------------
def test_section4_geometric_jacobian_eq33():
    r = robots.planar_3r()
    l1, l2, l3 = sp.symbols("L1 L2 L3", positive=True)
    t1, t2, t3 = r.thetas
    s1, c1 = sin(t1), cos(t1)
    s12, c12 = sin(t1 + t2), cos(t1 + t2)
    s123, c123 = sin(t1 + t2 + t3), cos(t1 + t2 + t3)
    J33 = sp.Matrix(
        [
            [0, 0, 0],
            [0, 0, 0],
            [1, 1, 1],
            [-l3 * s123 - l2 * s12 - l1 * s1, -l3 * s123 - l2 * s12, -l3 * s123],
            [l3 * c123 + l2 * c12 + l1 * c1, l3 * c123 + l2 * c12, l3 * c123],
            [0, 0, 0],
        ]
    )
    assert_sym_equal(r.jacobian_geometric(), J33, "eq. (33)")
    assert_sym_equal(kinlib.geometric_jacobian(r.M, r.screws, [t1, t2, t3]), J33, "eq. (33), free function")
    # and the tool position it differentiates
    p = sp.Matrix([l1 * c1 + l2 * c12 + l3 * c123, l1 * s1 + l2 * s12 + l3 * s123, 0])
    assert_sym_equal(r.fk()[:3, 3], p, "planar 3R p(θ)")


@pytest.mark.parametrize(
    "theta, row, coeffs",
    [
        # eqs. (39)-(41) with L1 = L2 = L3 = 1, the printed two-to-three-digit values
        ([-pi / 8, pi / 4, pi / 8], 3, [-0.707, -1.09, -0.707]),
        ([3 * pi / 4, -pi / 4, 0], 3, [-2.707, -2, -1]),
        ([pi / 2, -pi / 8, -pi / 2], 4, [1.31, 1.31, 0.92]),
    ],
)
def test_section4_rates_eqs_39_41(theta, row, coeffs):
    J = robots.planar_3r(1, 1, 1).jacobian_geometric(theta)
    got = [float(v) for v in J[row, :]]
    assert got == pytest.approx(coeffs, abs=6e-3)


def test_planar_rpp_eq54():
    """5.5's redesign: rows ω_z, ṗ_x... of J_s are eq. (54) and J_s J_sᵀ on them is I (eq. 55)."""
    r = robots.planar_rpp()
    t1 = r.thetas[0]
    Js = r.jacobian_space()[[2, 3, 4], :]
    assert_sym_equal(Js, sp.Matrix([[1, 0, 0], [0, cos(t1), -sin(t1)], [0, sin(t1), cos(t1)]]), "eq. (54)")
    assert_sym_equal(Js * Js.T, sp.eye(3), "eq. (55)")


# --------------------------------------------------------------------------------------------
# the equality helper itself: it must prove true identities and reject false ones
# --------------------------------------------------------------------------------------------
def test_assert_sym_equal_helper():
    from helpers import _is_zero_exact

    a, b = sp.symbols("a b", real=True)
    assert _is_zero_exact(sin(a + b) - sin(a) * cos(b) - cos(a) * sin(b))
    assert _is_zero_exact(sin(a) ** 2 + cos(a) ** 2 - 1)
    assert _is_zero_exact(sqrt(2) * cos(a + pi / 4) - cos(a) + sin(a))
    assert _is_zero_exact(L * (sin(a) ** 2 * cos(b) + cos(a) ** 2 * cos(b)) - L * cos(b))
    assert not _is_zero_exact(sin(a) - cos(a))
    assert not _is_zero_exact(sin(a) ** 2 - cos(a) ** 2)
    with pytest.raises(AssertionError, match="entry"):
        assert_sym_equal(sp.Matrix([[sin(a) ** 2]]), sp.Matrix([[1 - cos(a) ** 2 + 1e-6]]), "tiny difference")
    with pytest.raises(AssertionError, match="shapes differ"):
        assert_sym_equal(sp.zeros(2, 3), sp.zeros(3, 2))
    assert_sym_equal(sp.Matrix([[sin(2 * a)]]), sp.Matrix([[2 * sin(a) * cos(a)]]), "double angle")
