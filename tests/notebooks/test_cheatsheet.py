"""The cheat sheet (notebooks/cheatsheet.md) states formulas: each one is checked here, numerically, on random
arms (revolute and prismatic joints, fixed seed), against modern_robotics and finite differences, and the
sheet is checked to still state them (so the text and the checks cannot drift apart).
"""

from __future__ import annotations

from pathlib import Path

import modern_robotics as mr
import numpy as np
import pytest
import sympy as sp

import kinlib
from kinlib import manipulability as manip
from kinlib import robots
from kinlib.velocity import damped_least_squares

SHEET = (Path(__file__).resolve().parents[2] / "notebooks" / "cheatsheet.md").read_text(encoding="utf-8")
RNG = np.random.default_rng(2121)


def _random_arm(n=6, revolute_only=False):
    axes = [a / np.linalg.norm(a) for a in RNG.normal(size=(n, 3))]
    S = np.column_stack(
        [
            kinlib.screw_revolute(a, RNG.normal(size=3))
            if revolute_only or RNG.random() < 0.7
            else kinlib.screw_prismatic(a)
            for a in axes
        ]
    )
    M = kinlib.rp_to_trans(kinlib.exp3(axes[0], RNG.normal()), RNG.normal(size=3))
    return M, S, RNG.normal(size=n)


def _bracket3(p):
    return np.array([[0, -p[2], p[1]], [p[2], 0, -p[0]], [-p[1], p[0], 0]])


def _states(*pieces):
    for piece in pieces:
        assert piece in SHEET, f"the cheat sheet no longer states {piece!r}"


@pytest.mark.parametrize("k", range(5))
def test_three_jacobians_relate_as_stated(k):
    _states(
        r"J_b = \mathrm{Ad}_{T^{-1}} J_s",
        r"J = \mathrm{blockdiag}(R, R)\,J_b = [\omega_s; \dot p]",
        r"\dot p = v_s + \omega_s\times p",
        r"J = \begin{bmatrix} I & 0 \\ -[p] & I \end{bmatrix} J_s",
        "**same rank**",
    )
    M, S, q = _random_arm()
    T = mr.FKinSpace(M, S, q)
    R, p = T[:3, :3], T[:3, 3]
    Js = mr.JacobianSpace(S, q)
    Jb = mr.Adjoint(mr.TransInv(T)) @ Js
    B = mr.Adjoint(mr.TransInv(M)) @ S
    assert np.allclose(Jb, mr.JacobianBody(B, q)) and np.allclose(mr.Adjoint(T) @ Jb, Js)
    J = np.block([[R, np.zeros((3, 3))], [np.zeros((3, 3)), R]]) @ Jb
    assert np.allclose(J, kinlib.space_to_geometric(Js, T))
    assert np.allclose(J, np.block([[np.eye(3), np.zeros((3, 3))], [-_bracket3(p), np.eye(3)]]) @ Js)
    # [ω_s; ṗ] by finite differences of the forward kinematics
    eps = 1e-6
    for i in range(len(q)):
        e = np.zeros(len(q))
        e[i] = eps
        Tp, Tm = mr.FKinSpace(M, S, q + e), mr.FKinSpace(M, S, q - e)
        Td = (Tp - Tm) / (2 * eps)
        assert np.allclose(J[3:, i], Td[:3, 3], atol=1e-6)
        assert np.allclose(J[:3, i], mr.so3ToVec(Td[:3, :3] @ R.T), atol=1e-6)
    ranks = {np.linalg.matrix_rank(X, tol=1e-9) for X in (Js, Jb, J)}
    assert len(ranks) == 1


def test_revolute_column_is_omega_cross_p_minus_q():
    _states(r"\omega_i\times(p - q_i)")
    M, _, q = _random_arm(4, revolute_only=True)
    ws = [a / np.linalg.norm(a) for a in RNG.normal(size=(4, 3))]
    qs = RNG.normal(size=(4, 3))
    S = np.column_stack([kinlib.screw_revolute(w, qi) for w, qi in zip(ws, qs)])
    T = mr.FKinSpace(M, S, q)
    Js = mr.JacobianSpace(S, q)
    J = np.block([[np.eye(3), np.zeros((3, 3))], [-_bracket3(T[:3, 3]), np.eye(3)]]) @ Js
    for i in range(4):  # the current axis of joint i: moved by the joints before it
        P = mr.FKinSpace(np.eye(4), S[:, :i], q[:i]) if i else np.eye(4)
        w_now, q_now = P[:3, :3] @ ws[i], P[:3, :3] @ qs[i] + P[:3, 3]
        assert np.allclose(J[:3, i], w_now) and np.allclose(J[3:, i], np.cross(w_now, T[:3, 3] - q_now))


def test_planar_3r_det_and_collinear_joint_points():
    _states(r"\det J = L_1 L_2 \sin\theta_2", "**joint points are\n  collinear**")
    arm = robots.planar_3r()
    J = arm.jacobian_geometric().extract([2, 3, 4], [0, 1, 2])
    L1, L2, _ = arm.params
    assert sp.expand(sp.trigsimp(J.det() - L1 * L2 * sp.sin(arm.thetas[1]))) == 0
    for _ in range(20):
        lengths = RNG.uniform(0.3, 2, 3)
        q = RNG.uniform(-np.pi, np.pi, 3)
        if RNG.random() < 0.5:
            q[1] = RNG.choice([0.0, np.pi])
        num = robots.planar_3r(*lengths)
        Jt = num.jacobian_geometric(q)[[2, 3, 4]]
        pts = [np.zeros(2), lengths[0] * np.array([np.cos(q[0]), np.sin(q[0])])]
        pts.append(pts[1] + lengths[1] * np.array([np.cos(q[0] + q[1]), np.sin(q[0] + q[1])]))
        a, b = pts[1] - pts[0], pts[2] - pts[0]
        area = a[0] * b[1] - a[1] * b[0]  # twice the signed area of the joint points' triangle
        assert np.isclose(np.linalg.det(Jt), area, atol=1e-12)  # det = 0 exactly when they are collinear
        assert np.isclose(area, lengths[0] * lengths[1] * np.sin(q[1]), atol=1e-12)
        sigma = np.linalg.svd(Jt, compute_uv=False)
        assert (sigma[-1] < 1e-9) == (abs(area) < 1e-9)  # the ellipse collapses there


def test_ellipse_is_the_svd_and_the_cost_near_a_singularity():
    _states(r"semi-axes $\sigma_i u_i$", r"V^T (J J^T)^{-1} V \le 1", r"\lVert V\rVert/\sigma_{\min}")
    _states(r"\dot\theta = J^T (J J^T + \lambda^2 I)^{-1} V")
    M, S, q = _random_arm(6, revolute_only=True)
    J = mr.JacobianSpace(S, q)
    U, s, Vt = np.linalg.svd(J)
    assert s[-1] > 1e-3 * s[0]  # a regular configuration (fixed seed)
    for i in range(6):
        assert np.allclose(J @ Vt[i], s[i] * U[:, i])
    G_inv = np.linalg.inv(J @ J.T)
    for _ in range(50):  # images of unit joint rates lie on the ellipsoid's surface
        th = RNG.normal(size=6)
        V = J @ (th / np.linalg.norm(th))
        assert np.isclose(V @ G_inv @ V, 1.0)
    V = U[:, -1]
    assert np.isclose(np.linalg.norm(np.linalg.solve(J, V)), 1 / s[-1])
    lam = 0.05
    assert np.allclose(damped_least_squares(J, V, lam), J.T @ np.linalg.solve(J @ J.T + lam**2 * np.eye(6), V))


def test_measures_and_their_relations():
    _states(
        r"w = \sqrt{\det(J J^T)} = \sigma_1\sigma_2\cdots\sigma_m",
        r"\sigma_{\min}/\sigma_{\max} \in [0, 1]",
        r"\kappa = \sigma_{\max}/\sigma_{\min} \ge 1",
        r"\mu_1 = \sqrt{\lambda_{\max}/\lambda_{\min}} = \kappa",
        r"\mu_2 = \lambda_{\max}/\lambda_{\min} = \kappa^2",
        r"\mu_3 = \sqrt{\lambda_1\lambda_2\cdots} = \sqrt{\det A} = w",
    )
    M, S, q = _random_arm(7)
    J = mr.JacobianSpace(S, q)[3:]  # 3 rows, 7 joints
    s = np.linalg.svd(J, compute_uv=False)
    lam = np.linalg.eigvalsh(J @ J.T)
    w = np.sqrt(np.linalg.det(J @ J.T))
    assert np.isclose(w, np.prod(s)) and np.isclose(manip.manipulability(J), w)
    kappa = s[0] / s[-1]
    assert np.isclose(manip.condition_number(J), kappa) and np.isclose(manip.isotropy(J), 1 / kappa)
    assert np.isclose(np.sqrt(lam.max() / lam.min()), kappa) and np.isclose(lam.max() / lam.min(), kappa**2)
    assert np.isclose(np.sqrt(np.prod(lam)), w)
    # isotropic: κ = 1 exactly when all σ are equal (a rotation times a scale)
    Q = np.linalg.qr(RNG.normal(size=(3, 3)))[0]
    assert np.isclose(manip.condition_number(2.5 * Q), 1.0)


def test_units_position_rows_and_mixed_rows():
    _states(r"scales by $s^m$", "change when metres become\n  millimetres")
    M, S, q = _random_arm(6, revolute_only=True)
    scale = 1000.0  # metres → millimetres: every length, hence every v = −ω × q and the home position
    S_mm, M_mm = S.copy(), M.copy()
    S_mm[3:] *= scale
    M_mm[:3, 3] *= scale
    J = mr.JacobianSpace(S, q)
    J_mm = mr.JacobianSpace(S_mm, q)
    T, T_mm = mr.FKinSpace(M, S, q), mr.FKinSpace(M_mm, S_mm, q)

    def geometric(Js, T):
        return np.block([[np.eye(3), np.zeros((3, 3))], [-_bracket3(T[:3, 3]), np.eye(3)]]) @ Js

    G, G_mm = geometric(J, T), geometric(J_mm, T_mm)
    pos, pos_mm = G[3:5], G_mm[3:5]  # two position rows: m = 2
    assert np.isclose(manip.manipulability(pos_mm), scale**2 * manip.manipulability(pos))
    assert np.isclose(manip.condition_number(pos_mm), manip.condition_number(pos))
    assert not np.isclose(manip.condition_number(G_mm), manip.condition_number(G), rtol=1e-3)


def test_row_order_swap_elsewhere():
    _states(r"P = \begin{bmatrix} 0 & I \\ I & 0 \end{bmatrix}", "`LOCAL_WORLD_ALIGNED` is $P J$", "`jacob0` is $P J$")
    M, S, q = _random_arm(6)
    J = mr.JacobianSpace(S, q)
    P = np.block([[np.zeros((3, 3)), np.eye(3)], [np.eye(3), np.zeros((3, 3))]])
    assert np.allclose(P @ P, np.eye(6)) and np.allclose(P.T @ P, np.eye(6))
    assert np.allclose(np.linalg.svd(P @ J, compute_uv=False), np.linalg.svd(J, compute_uv=False))
    assert np.allclose((P @ J)[:3], J[3:])  # the linear rows first


# ---------------------------------------------------------------------------------------------------------------
# issue 30: statements relative to the task (rows, Jacobian, units), each checked numerically


def _planar(points):
    return np.column_stack([kinlib.screw_revolute([0, 0, 1], [x, y, 0]) for x, y in points])


def test_rows_without_omega_depend_on_the_jacobian():
    _states(
        r"rows of $J_s$ have $\det \equiv 0$ in every pose", r"$L_1 L_2\sin\theta_2$", "never the $v$ rows of $J_s$"
    )
    for _ in range(10):
        l1, l2 = RNG.uniform(0.3, 2, 2)
        S, M = _planar([(0, 0), (l1, 0)]), np.eye(4)
        M[0, 3] = l1 + l2
        q = RNG.uniform(-np.pi, np.pi, 2)
        T = mr.FKinSpace(M, S, q)
        Js = mr.JacobianSpace(S, q)
        Jb = mr.Adjoint(mr.TransInv(T)) @ Js
        Jg = np.vstack([Js[:3], Js[3:] + np.cross(Js[:3].T, T[:3, 3]).T])
        assert abs(np.linalg.det(Js[[3, 4]])) < 1e-12
        assert np.allclose([np.linalg.det(Jb[[3, 4]]), np.linalg.det(Jg[[3, 4]])], l1 * l2 * np.sin(q[1]))


def test_planar_columns_of_js():
    _states("$(1, y_i, -x_i)$", "$(0, u_x, u_y)$")
    for _ in range(10):
        x, y = RNG.normal(size=2)
        u = RNG.normal(size=2)
        u /= np.linalg.norm(u)
        S = np.column_stack([kinlib.screw_revolute([0, 0, 1], [x, y, 0]), kinlib.screw_prismatic([u[0], u[1], 0])])
        J = mr.JacobianSpace(S, [0.0, 0.0])  # joint 1 first: its point is where it was placed
        assert np.allclose(J[[2, 3, 4], 0], [1, y, -x]) and np.allclose(J[[2, 3, 4], 1], [0, u[0], u[1]])


def test_dls_rates_peak_where_sigma_min_is_lambda():
    _states(r"its rates are largest where", r"$\sigma_{\min} \approx \lambda$")
    lam = 0.05
    U = np.linalg.qr(RNG.normal(size=(3, 3)))[0]
    V = U[:, 2]  # along the direction being lost
    sig = np.logspace(-3, 0, 601)
    rates = [np.linalg.norm(damped_least_squares(U @ np.diag([2.0, 1.0, s]) @ U.T, V, lam)) for s in sig]
    assert abs(sig[int(np.argmax(rates))] / lam - 1) < 0.03
    assert max(rates) <= 1 / (2 * lam) + 1e-9


def test_yoshikawa_is_for_m_le_n():
    _states(r"for $m \le n$", r"With $m \gt n$ it is 0 everywhere")
    M, S, q = _random_arm(4)
    J = mr.JacobianSpace(S, q)
    assert abs(np.linalg.det(J @ J.T)) < 1e-9 and np.linalg.det(J.T @ J) > 1e-6


def test_near_rule_is_a_convention_unit_free_only_sometimes():
    _states("is a convention, not a standard", "unit-free when $J$ is square")

    def ratio(scale, gram):  # w(qa)/w(qb) of a 3-row, 2-joint arm: one revolute, one slide
        S = np.column_stack([kinlib.screw_revolute([0, 0, 1], [0, 0, 0]), kinlib.screw_prismatic([1, 0, 0])])
        M = np.eye(4)
        M[0, 3] = scale
        out = []
        for slide in (0.5, 2.0):
            T = mr.FKinSpace(M, S, [0.3, slide * scale])
            Js = mr.JacobianSpace(S, [0.3, slide * scale])
            Jg = np.vstack([Js[:3], Js[3:] + np.cross(Js[:3].T, T[:3, 3]).T])[[2, 3, 4]]
            out.append(np.sqrt(np.linalg.det(Jg.T @ Jg)) if gram else abs(np.linalg.det(Jg[1:])))
        return out[0] / out[1]

    assert abs(ratio(1.0, True) - ratio(1000.0, True)) > 0.05  # m > n, mixed joint types: depends on the unit
    assert np.isclose(ratio(1.0, False), ratio(1000.0, False))  # the square ṗ block: unit-free
