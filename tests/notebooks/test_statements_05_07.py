"""The mathematical facts behind the statements of notebooks 05–07 and the cheat sheet (issue 30), each computed
independently of the notebooks' code: modern_robotics' Jacobians, finite differences of its forward kinematics,
plane geometry written out here.

1. Which rows: the (v_x, v_y) rows of J_s of a 2R arm have det ≡ 0; the same rows of J_b and the ṗ rows of the
   geometric J have det = L1 L2 sin θ2. For the full J and the planar triple (ω_z, v_x, v_y) J_s, J_b and J agree.
2. The R-P-P-R arm of 06: the full 6×4 J keeps rank 4 everywhere; its 3×4 ṗ block drops to rank 2 at θ3 = −L2.
3. The J_s column of a planar revolute joint at (x_i, y_i) is (1, y_i, −x_i) in (ω_z, v_x, v_y), not (1, −y_i, x_i).
4. Planar revolute arms: for (ω_z, ṗ_x, ṗ_y) singular ⇔ joint points collinear; for the 2R position task
   singular ⇔ the tool point collinear with the two joints (two joint points are always collinear).
5. The near rule w < 0.1 w_max: w/w_max is unit-free for 05's square J; √det(JᵀJ) of 06's 6×4 J with slides is not,
   while the separate linear measure (Modern Robotics §5.4) is.
6. Damped least squares turns back where σ_min ≈ λ (at δ ≈ 2λ in 05's set-up, not at δ ≈ λ).
8. Yoshikawa's w = √det(J Jᵀ) ≡ 0 for 06's 6×4 J; √det(JᵀJ) = √(1 + (L2 + θ3)²) adds a pure number to a squared length.
9. ‖θ̇‖ = 1 maps onto the boundary of the ellipse of a square J_v and ‖θ̇‖ ≤ 1 fills it; with more joints than rows
   unit rates reach inside (a null-space rate reaches the centre).
10. 06's figure: the roll axis x_b is perpendicular to the old default line of sight (the roll was invisible) and
   29° from the chosen one.
"""

from __future__ import annotations

import json
from pathlib import Path

import modern_robotics as mr
import numpy as np
import pytest

ROOT = Path(__file__).resolve().parents[2]
RNG = np.random.default_rng(30)


def planar_screws(points):
    """Screw axes [ω; v] of revolute joints about z through the given (x, y) points: v = −ω × q."""
    return np.array([np.r_[0, 0, 1, -np.cross([0, 0, 1], [x, y, 0])] for x, y in points]).T


def home(x, y=0.0, z=0.0):
    M = np.eye(4)
    M[:3, 3] = x, y, z
    return M


def geometric(S, M, q):
    Js, p = mr.JacobianSpace(S, q), mr.FKinSpace(M, S, q)[:3, 3]
    return np.vstack([Js[:3], Js[3:] + np.cross(Js[:3].T, p).T])


def fd_position_jacobian(S, M, q, eps=1e-6):
    q = np.asarray(q, dtype=float)
    cols = []
    for i in range(len(q)):
        d = np.zeros(len(q))
        d[i] = eps
        cols.append((mr.FKinSpace(M, S, q + d)[:3, 3] - mr.FKinSpace(M, S, q - d)[:3, 3]) / (2 * eps))
    return np.array(cols).T


# 1 ---------------------------------------------------------------------------------------------------------------


def test_2r_position_rows_of_js_are_singular_everywhere_but_not_those_of_jb_or_the_geometric_j():
    for _ in range(30):
        l1, l2 = RNG.uniform(0.3, 2, 2)
        S, M = planar_screws([(0, 0), (l1, 0)]), home(l1 + l2)
        q = RNG.uniform(-np.pi, np.pi, 2)
        Js, Jb = mr.JacobianSpace(S, q), mr.JacobianBody(mr.Adjoint(mr.TransInv(M)) @ S, q)
        assert abs(np.linalg.det(Js[[3, 4]])) < 1e-12  # v of J_s: the body point at the origin of {s}
        expected = l1 * l2 * np.sin(q[1])
        assert np.isclose(np.linalg.det(Jb[[3, 4]]), expected)
        assert np.isclose(np.linalg.det(geometric(S, M, q)[[3, 4]]), expected)
        assert np.isclose(np.linalg.det(fd_position_jacobian(S, M, q)[:2]), expected, atol=1e-6)


def test_the_full_j_and_the_planar_triple_agree_for_js_jb_and_the_geometric_j():
    L = 1.0
    S, M = planar_screws([(0, 0), (L, 0), (2 * L, L)]), home(3 * L, L)  # 05's arm
    for _ in range(30):
        q = RNG.uniform(-np.pi, np.pi, 3)
        Js, Jb, Jg = mr.JacobianSpace(S, q), mr.JacobianBody(mr.Adjoint(mr.TransInv(M)) @ S, q), geometric(S, M, q)
        d = [np.linalg.det(J[[2, 3, 4]]) for J in (Js, Jb, Jg)]
        assert np.allclose(d, np.sqrt(2) * L**2 * np.sin(q[1] + np.pi / 4))
        assert len({np.linalg.matrix_rank(J, tol=1e-9) for J in (Js, Jb, Jg)}) == 1


# 2 ---------------------------------------------------------------------------------------------------------------

L1, L2 = 1.0, 0.5


def rppr():
    """06's R-P-P-R arm written from its description: base rotation about z_s, vertical slide, horizontal slide
    along x_s at height L1 + L2, wrist roll about the tool's x axis; tool at (L2, 0, L1 + L2)."""
    q4 = np.array([L2, 0, L1 + L2])
    S = np.array(
        [[0, 0, 1, 0, 0, 0], [0, 0, 0, 0, 0, 1], [0, 0, 0, 1, 0, 0], np.r_[1, 0, 0, -np.cross([1, 0, 0], q4)]]
    ).T
    return S, home(*q4)


def test_rppr_full_j_keeps_rank_4_while_its_position_block_drops_to_rank_2_at_theta3_minus_l2():
    S, M = rppr()
    for _ in range(20):
        q = RNG.uniform(-3, 3, 4)
        on = np.array([q[0], q[1], -L2, q[3]])
        J_on, J_off = geometric(S, M, on), geometric(S, M, q)
        assert np.linalg.matrix_rank(J_on, tol=1e-9) == 4 and np.linalg.matrix_rank(J_off, tol=1e-9) == 4
        assert np.linalg.matrix_rank(fd_position_jacobian(S, M, on), tol=1e-6) == 2
        assert np.linalg.matrix_rank(fd_position_jacobian(S, M, q), tol=1e-6) == 3
        assert np.linalg.matrix_rank(J_on[3:], tol=1e-9) == 2


def test_kinlib_agrees_on_the_rppr_position_block():
    import sympy as sp

    from kinlib import robots
    from kinlib.singularities import rank_at, singular_configurations, task_rows

    r = robots.spatial_rppr()
    _, l2 = r.params
    Jv = task_rows(r.jacobian_geometric(), ("vx", "vy", "vz"))
    for t1, t2, t4 in ((0, 0, 0), (sp.Rational(3, 10), sp.Rational(7, 10), sp.pi / 5)):
        q = [t1, t2, -l2, t4]
        assert rank_at(Jv, q, r.thetas) == 2 and rank_at(r.jacobian_geometric(), q, r.thetas) == 4
        assert rank_at(Jv, [t1, t2, 1 - l2, t4], r.thetas) == 3
    assert singular_configurations(r.jacobian_geometric(), r.thetas) == []
    conds = singular_configurations(Jv, r.thetas)
    assert conds == [{r.thetas[2]: sp.FiniteSet(-l2)}]


# 3 ---------------------------------------------------------------------------------------------------------------


def test_js_column_of_a_planar_revolute_joint_is_1_y_minus_x():
    """From finite differences of FK: [V_s] = Ṫ T⁻¹ for joint i alone, at the joint's current point."""
    for _ in range(20):
        pts = RNG.uniform(-2, 2, (4, 2))
        S, M = planar_screws(pts), home(*RNG.uniform(-2, 2, 2))
        q = RNG.uniform(-np.pi, np.pi, 4)
        for i in range(4):
            d = np.zeros(4)
            d[i] = 1e-6
            Tdot = (mr.FKinSpace(M, S, q + d) - mr.FKinSpace(M, S, q - d)) / 2e-6
            V = mr.se3ToVec(Tdot @ mr.TransInv(mr.FKinSpace(M, S, q)))
            # the joint's current point: the earlier joints move it
            x, y = (mr.FKinSpace(home(*pts[i]), S[:, :i], q[:i]) if i else home(*pts[i]))[:2, 3]
            assert np.allclose(V[[2, 3, 4]], [1, y, -x], atol=1e-6)
            assert not np.allclose(V[[2, 3, 4]], [1, -y, x], atol=1e-3) or abs(x) + abs(y) < 1e-3


# 4 ---------------------------------------------------------------------------------------------------------------


def cross2(a, b):
    return a[0] * b[1] - a[1] * b[0]


def test_collinear_rule_holds_for_the_planar_triple_and_the_tool_point_rule_for_the_2r_position_task():
    for _ in range(30):
        pts = RNG.uniform(-2, 2, (3, 2))
        S, M = planar_screws(pts), home(*RNG.uniform(-2, 2, 2))
        q = RNG.uniform(-np.pi, np.pi, 3)
        cur = [(mr.FKinSpace(home(*pts[i]), S[:, :i], q[:i]) if i else home(*pts[i]))[:2, 3] for i in range(3)]
        det = np.linalg.det(geometric(S, M, q)[[2, 3, 4]])
        assert np.isclose(det, cross2(cur[1] - cur[0], cur[2] - cur[0]))  # 0 ⇔ the joint points collinear
    for _ in range(30):
        l1, l2 = RNG.uniform(0.3, 2, 2)
        S, M = planar_screws([(0, 0), (l1, 0)]), home(l1 + l2)
        q = RNG.uniform(-np.pi, np.pi, 2)
        q2 = np.array([l1 * np.cos(q[0]), l1 * np.sin(q[0])])
        p = mr.FKinSpace(M, S, q)[:2, 3]
        det = np.linalg.det(geometric(S, M, q)[[3, 4]])
        assert np.isclose(det, cross2(p, p - q2))  # 0 ⇔ the tool point on the line of the two joints


# 5, 8 ------------------------------------------------------------------------------------------------------------


def test_near_rule_is_unit_free_for_a_square_j_but_not_for_the_6x4_rppr():
    def w_planar(scale, q):
        S, M = planar_screws([(0, 0), (scale, 0), (2 * scale, scale)]), home(3 * scale, scale)
        J = geometric(S, M, q)[[2, 3, 4]]
        return np.sqrt(np.linalg.det(J @ J.T))

    qa, qb = [0.3, 0.9, -0.2], [0.1, np.pi / 4, 1.0]  # any two configurations: the ratio is what the rule uses
    for s in (1.0, 1000.0):
        assert np.isclose(w_planar(s, qa) / w_planar(s, qb), w_planar(1.0, qa) / w_planar(1.0, qb))

    def rppr_measures(scale, q):
        q4 = np.array([L2, 0, L1 + L2]) * scale
        S = np.array(
            [[0, 0, 1, 0, 0, 0], [0, 0, 0, 0, 0, 1], [0, 0, 0, 1, 0, 0], np.r_[1, 0, 0, -np.cross([1, 0, 0], q4)]]
        ).T
        qs = np.array([q[0], q[1] * scale, q[2] * scale, q[3]])  # slides in the new unit too
        J = geometric(S, home(*q4), qs)
        gram = np.sqrt(np.linalg.det(J.T @ J))
        Jv = J[3:]
        return gram, np.sqrt(np.linalg.det(Jv @ Jv.T)), np.linalg.det(J @ J.T)

    qa, qb = [0.2, 0.3, 0.0, 0.4], [0.2, 0.3, 2.0, 0.4]  # L2 + θ3 = 0.5 and 2.5 (metres)
    gm_a, v_a, yosh = rppr_measures(1.0, qa)
    gm_b, v_b, _ = rppr_measures(1.0, qb)
    gmm_a, vm_a, _ = rppr_measures(1000.0, qa)  # millimetres
    gmm_b, vm_b, _ = rppr_measures(1000.0, qb)
    assert np.isclose(gm_a, np.sqrt(1 + 0.5**2)) and np.isclose(gm_b, np.sqrt(1 + 2.5**2))  # 8: 1 + (L2 + θ3)²
    assert abs(gm_a / gm_b - gmm_a / gmm_b) > 0.2  # √det(JᵀJ): the ratio depends on the unit of length
    assert np.isclose(v_a / v_b, vm_a / vm_b)  # the linear part alone (MR §5.4): unit-free
    assert abs(yosh) < 1e-9  # 8: Yoshikawa's det(J Jᵀ) is 0 for 6 rows and 4 joints


# 6 ---------------------------------------------------------------------------------------------------------------


def test_dls_turns_back_where_sigma_min_is_lambda_not_where_delta_is_lambda():
    L, lam = 1.0, 0.05
    S, M = planar_screws([(0, 0), (L, 0), (2 * L, L)]), home(3 * L, L)
    V = np.array([0, 0.1 / np.sqrt(2), 0.1 / np.sqrt(2)])
    deltas = np.logspace(-3, 0, 601)
    rates, smin = [], []
    for d in deltas:
        J = geometric(S, M, [np.pi / 4, -np.pi / 4 + d, np.pi / 4])[[2, 3, 4]]
        rates.append(np.linalg.norm(J.T @ np.linalg.solve(J @ J.T + lam**2 * np.eye(3), V)))
        smin.append(np.linalg.svd(J, compute_uv=False)[-1])
    k = int(np.argmax(rates))
    assert abs(smin[k] / lam - 1) < 0.05  # the turn: σ_min ≈ λ
    assert deltas[k] / lam > 1.8  # ... at δ ≈ 2λ here, not δ ≈ λ (an angle is not a singular value)
    assert np.isclose(smin[k] / deltas[k], 0.475, atol=0.01)  # σ_min ≈ 0.47 δ, as the notebook says


# 9 ---------------------------------------------------------------------------------------------------------------


def test_unit_rates_map_onto_the_boundary_of_a_square_jv_and_inside_for_a_redundant_one():
    S, M = planar_screws([(0, 0), (1, 0)]), home(2)
    Jv = geometric(S, M, [0.3, 1.1])[[3, 4]]
    Ainv = np.linalg.inv(Jv @ Jv.T)
    ang = np.linspace(0, 2 * np.pi, 50)
    on = Jv @ np.array([np.cos(ang), np.sin(ang)])
    assert np.allclose(np.einsum("ij,ik,kj->j", on, Ainv, on), 1)  # ‖θ̇‖ = 1: the boundary only
    inner = 0.5 * on
    pre = np.linalg.solve(Jv, inner)
    assert np.all(np.linalg.norm(pre, axis=0) <= 1)  # interior points need ‖θ̇‖ < 1: ‖θ̇‖ ≤ 1 fills it
    S3, M3 = planar_screws([(0, 0), (1, 0), (2, 0)]), home(3)
    Jv3 = geometric(S3, M3, [0.3, 1.1, -0.4])[[3, 4]]
    null = np.linalg.svd(Jv3)[2][-1]
    assert np.isclose(np.linalg.norm(null), 1) and np.allclose(Jv3 @ null, 0, atol=1e-12)  # a unit rate at the centre


# 10 --------------------------------------------------------------------------------------------------------------


def _line_of_sight(elev, azim):
    e, a = np.radians(elev), np.radians(azim)
    return np.array([np.cos(e) * np.cos(a), np.cos(e) * np.sin(a), np.sin(e)])


def test_06_figure_is_seen_along_the_roll_axis():
    x_b = np.array([np.cos(np.pi / 6), np.sin(np.pi / 6), 0])  # the tool's x axis at θ1 = π/6 (the roll axis)
    assert abs(_line_of_sight(30, -60) @ x_b) < 1e-12  # matplotlib's default view: the roll axis across the sight
    assert abs(_line_of_sight(15, 235) @ x_b) > np.cos(np.radians(30))  # the view chosen in 06
    nb = json.loads((ROOT / "notebooks" / "06_singularities_spatial.ipynb").read_text())
    src = next("".join(c["source"]) for c in nb["cells"] if c.get("id") == "06-002")
    assert "view_init(elev=15, azim=235)" in src


@pytest.mark.parametrize(
    "stem, wrong",
    [
        (
            "05_singularities_planar",
            ["misses the drop at $\\theta_2 = -\\pi/4$", "turns back at $\\delta \\approx \\lambda$"],
        ),
        ("06_singularities_spatial", ["must use $\\sqrt{\\det(J^T J)}$ instead"]),
        ("07_going_further", ["$(1, -y_i, x_i)$"]),
    ],
)
def test_the_old_sentences_are_gone(stem, wrong):
    nb = json.loads((ROOT / "notebooks" / f"{stem}.ipynb").read_text())
    text = "\n".join("".join(c["source"]) for c in nb["cells"] if c["cell_type"] == "markdown")
    for s in wrong:
        assert s not in text


def test_07_labels_sit_at_their_joints():
    """07's 3-D picture of your own arm: the labels are placed at the joints' current points (chain.skeleton), not
    where the default placement puts them (the edges of the 3-D box)."""
    nb = json.loads((ROOT / "notebooks" / "07_going_further.ipynb").read_text())
    src = next("".join(c["source"]) for c in nb["cells"] if c.get("id") == "07-067")
    assert "labels=False" in src and "my_arm.skeleton(q_my)" in src and "art.ax.text(x + 0.03, y, z + 0.06" in src
    from kinlib import robots

    arm = robots.from_urdf_joints(
        [
            ("revolute", (0, 0, 0.4), (0, 0, 0), (0, 0, 1)),
            ("revolute", (0.35, 0, 0), (0, 0, 0), (0, 0, 1)),
            ("prismatic", (0.3, 0, 0), (0, 0, 0), (0, 0, -1)),
            ("revolute", (0, 0, 0), (0, 0, 0), (0, 0, 1)),
        ],
        tool=((0, 0, -0.1), (0, 0, 0)),
    )
    q = [0.3, 1.2, 0.1, 0.0]
    pts = np.asarray(arm.skeleton(q), dtype=float)[:3]
    # column i + 1 is joint i + 1's point: joint 2 at 0.35 m from joint 1, joint 4 below joint 3 by the slide's 0.1 m
    assert np.isclose(np.linalg.norm(pts[:2, 2] - pts[:2, 1]), 0.35)
    assert np.allclose(pts[:2, 4], pts[:2, 3]) and np.isclose(pts[2, 3] - pts[2, 4], 0.1)
