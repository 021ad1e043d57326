"""kinlib.singularities against independent computation: NumPy SVD of modern_robotics Jacobians,
rank drops checked at members of each claimed family, full rank at random non-members."""

from __future__ import annotations

import modern_robotics as mr
import numpy as np
import pytest
import sympy as sp

from kinlib import SerialChain, robots
from kinlib.singularities import (
    K,
    column_space,
    evaluate_at,
    left_null_space,
    rank_at,
    representatives,
    singular_configurations,
    task_rows,
    trig_simplify,
)

pi = sp.pi


def sigma_min(J):
    return np.linalg.svd(np.asarray(J, dtype=float), compute_uv=False)[-1]


def np_screws(chain):
    return np.array(chain.screws, dtype=float)


# ------------------------------------------------------------------------------------------
# task_rows
# ------------------------------------------------------------------------------------------
def test_task_rows_names_presets_indices():
    J = sp.Matrix(6, 2, lambda i, j: sp.Symbol(f"a{i}{j}", real=True))
    assert task_rows(J, "planar") == J.extract([2, 3, 4], [0, 1])
    assert task_rows(J, ["vx", "vy"]) == J.extract([3, 4], [0, 1])
    assert task_rows(J, ("px", "wz")) == J.extract([3, 2], [0, 1])
    assert task_rows(J, "linear") == J[3:, :]
    assert task_rows(J, "angular") == J[:3, :]
    assert task_rows(J, [0, 5]) == J.extract([0, 5], [0, 1])
    A = np.arange(12.0).reshape(6, 2)
    assert np.array_equal(task_rows(A, "planar"), A[[2, 3, 4]])
    batch = np.arange(36.0).reshape(3, 6, 2)
    assert np.array_equal(task_rows(batch, ["wz", "vy"]), batch[:, [2, 4], :])
    # indices work on any number of rows
    B = sp.Matrix([[1, 2], [3, 4], [5, 6]])
    assert task_rows(B, [2, 0]) == sp.Matrix([[5, 6], [1, 2]])


@pytest.mark.parametrize(
    "rows, exc, words",
    [
        (["vq"], ValueError, "unknown row"),
        (["vx", "vx"], ValueError, "repeat"),
        ([], ValueError, "at least one"),
        ([7], ValueError, "out of range"),
        ([1.5], TypeError, "rows"),
        ([True], TypeError, "bool"),
        (3.5, TypeError, "rows"),
        (None, TypeError, "rows"),
    ],
)
def test_task_rows_bad_rows(rows, exc, words):
    with pytest.raises(exc, match=words):
        task_rows(sp.eye(6), rows)


def test_task_rows_names_need_six_rows_and_a_matrix():
    with pytest.raises(ValueError, match="6.rows?"):
        task_rows(sp.eye(3), "planar")
    with pytest.raises(TypeError, match="J must be a matrix"):
        task_rows("J", "planar")
    with pytest.raises(ValueError, match="J must be a matrix"):
        task_rows(np.zeros(6), [0])


# ------------------------------------------------------------------------------------------
# singular_configurations: the problem set's robots
# ------------------------------------------------------------------------------------------
def test_planar_offset_3r_family_and_rank_drop(rng):
    """Problem 5.1: θ2 = −π/4 + kπ (the printed −π/4 ± 2πi or 3π/4 ± 2πi), for every θ1, θ3."""
    r = robots.planar_offset_3r()
    J = task_rows(r.jacobian_space(), "planar")
    conds = singular_configurations(J, r.thetas)
    th2 = r.thetas[1]
    assert conds == [{th2: sp.ImageSet(sp.Lambda(K, pi * K - pi / 4), sp.Integers)}]
    assert representatives(conds[0][th2]) == [3 * pi / 4, 7 * pi / 4]
    assert representatives(conds[0][th2], -pi, pi) == [-pi / 4, 3 * pi / 4]
    # independent: modern_robotics Jacobian (L = 1) at members and non-members
    S = np_screws(r.subs(L=1))
    for _ in range(10):
        t1, t3 = rng.uniform(-np.pi, np.pi, 2)
        k = int(rng.integers(-3, 4))
        member = [t1, float(-pi / 4 + k * pi), t3]
        assert sigma_min(mr.JacobianSpace(S, member)[[2, 3, 4]]) < 1e-9
        other = [t1, rng.uniform(-np.pi, np.pi), t3]
        if abs(np.sin(other[1]) + np.cos(other[1])) > 1e-2:
            assert sigma_min(mr.JacobianSpace(S, other)[[2, 3, 4]]) > 1e-4


def test_same_family_from_body_and_geometric_jacobians():
    """Each of the three Jacobians gives the printed family θ2 = −π/4 + kπ (eqs. 44-45), written out here."""
    r = robots.planar_offset_3r()
    printed = [{r.thetas[1]: sp.ImageSet(sp.Lambda(K, pi * K - pi / 4), sp.Integers)}]
    for J in (r.jacobian_space(), r.jacobian_body(), r.jacobian_geometric()):
        assert singular_configurations(task_rows(J, "planar"), r.thetas) == printed


def test_printed_jacobian_with_shifted_angles_gives_the_same_family():
    """The problem set's hand-written J_s (eq. 43) with sin(θ1 + θ2 + π/4) terms."""
    L = sp.Symbol("L", positive=True)
    t1, t2, t3 = sp.symbols("theta1:4", real=True)
    a = t1 + t2 + pi / 4
    J = sp.Matrix(
        [
            [1, 1, 1],
            [0, L * sp.sin(t1), L * sp.sin(t1) + L * sp.sqrt(2) * sp.sin(a)],
            [0, -L * sp.cos(t1), -L * sp.cos(t1) - L * sp.sqrt(2) * sp.cos(a)],
        ]
    )
    assert singular_configurations(J, (t1, t2, t3)) == [{t2: sp.ImageSet(sp.Lambda(K, pi * K - pi / 4), sp.Integers)}]


def test_ur5_three_families(rng):
    """Elbow sin θ3 = 0, wrist sin θ5 = 0, and the shoulder condition, checked with modern_robotics."""
    r = robots.ur5()
    th = r.thetas
    conds = singular_configurations(r.jacobian_space(), th)
    fam = sp.ImageSet(sp.Lambda(K, pi * K), sp.Integers)
    assert conds[:2] == [{th[2]: fam}, {th[4]: fam}]
    assert len(conds) == 3
    shoulder = conds[2]
    assert isinstance(shoulder, sp.Expr) and shoulder.free_symbols == {th[1], th[2], th[3]}
    f = sp.lambdify(th, shoulder, "numpy")
    S = np_screws(r)
    L1, L2, H2 = 0.425, 0.392, 0.095
    # det J_s / (sin θ3 sin θ5 · shoulder) is one constant: the conditions are all of det's zeros
    ratios = []
    for _ in range(6):
        q = rng.uniform(-np.pi, np.pi, 6)
        ratios.append(np.linalg.det(mr.JacobianSpace(S, q)) / (np.sin(q[2]) * np.sin(q[4]) * f(*q)))
    assert np.allclose(ratios, ratios[0], rtol=1e-8)
    # rank drops at members of each family, full rank off them
    found = 0
    while found < 4:
        q = rng.uniform(-np.pi, np.pi, 6)
        for j, k in ((2, int(rng.integers(-2, 3))), (4, int(rng.integers(-2, 3)))):
            qq = q.copy()
            qq[j] = k * np.pi
            assert sigma_min(mr.JacobianSpace(S, qq)) < 1e-9
        x = L1 * np.cos(q[1]) + L2 * np.cos(q[1] + q[2])
        if abs(x) < H2:  # a shoulder singularity: choose θ4 so the expression vanishes
            qq = q.copy()
            qq[3] = np.arcsin(x / H2) - q[1] - q[2]
            assert abs(f(*qq)) < 1e-12
            assert sigma_min(mr.JacobianSpace(S, qq)) < 1e-9
            found += 1
        assert sigma_min(mr.JacobianSpace(S, q)) > 1e-6


def test_ur5_symbolic_lengths_shoulder_expression():
    W1, W2, L1, L2, H1, H2 = sp.symbols("W1 W2 L1 L2 H1 H2", positive=True)
    r = robots.ur5(W1, W2, L1, L2, H1, H2)
    t = r.thetas
    conds = singular_configurations(r.jacobian_body(), t)
    expected = L1 * sp.cos(t[1]) + L2 * sp.cos(t[1] + t[2]) - H2 * sp.sin(t[1] + t[2] + t[3])
    assert sp.expand(sp.expand_trig(conds[2] - expected)) == 0 or sp.expand(sp.expand_trig(conds[2] + expected)) == 0


def test_spatial_rppr_and_rpp_have_none():
    r = robots.spatial_rppr()
    assert singular_configurations(r.jacobian_geometric(), r.thetas) == []
    assert singular_configurations(r.jacobian_space(), r.thetas) == []
    p = robots.planar_rpp()
    assert singular_configurations(task_rows(p.jacobian_space(), "planar"), p.thetas) == []


def test_prismatic_factor_is_solved_over_the_reals(rng):
    """R about z then P along the rotated x: ṗ rows give det = L + θ2, singular only at θ2 = −L."""
    L = sp.Symbol("L", positive=True)
    chain = SerialChain(
        sp.Matrix([[1, 0, 0, L], [0, 1, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1]]),
        [[0, 0, 1, 0, 0, 0], [0, 0, 0, 1, 0, 0]],
        name="rp",
    )
    J = task_rows(chain.jacobian_geometric(), ["vx", "vy"])
    t1, t2 = chain.thetas
    assert singular_configurations(J, chain.thetas) == [{t2: sp.FiniteSet(-L)}]
    Jn = sp.lambdify(chain.thetas, J.subs(L, 1), "numpy")
    assert sigma_min(Jn(rng.uniform(-3, 3), -1.0)) < 1e-12
    assert sigma_min(Jn(rng.uniform(-3, 3), 0.5)) > 0.1


def test_more_joints_than_rows_gives_a_joint_condition(rng):
    """planar_3r's (ṗx, ṗy) rows: all 2×2 minors vanish iff sin θ2 = sin θ3 = 0, one condition on two joints
    (it was a sum of squares of the minors before issue 11)."""
    r = robots.planar_3r(1, 1, 1)
    J = task_rows(r.jacobian_geometric(), ["vx", "vy"])
    conds = singular_configurations(J, r.thetas)
    fam = sp.ImageSet(sp.Lambda(K, pi * K), sp.Integers)
    assert conds == [{r.thetas[1]: fam, r.thetas[2]: fam}] and conds.complete
    S = np_screws(r)
    for _ in range(5):
        q = rng.uniform(-3, 3, 3)
        assert sigma_min(_geo_rows(S, r, q)) > 1e-6 or min(abs(np.sin(q[1])), abs(np.sin(q[2]))) < 1e-2
        q[1], q[2] = np.pi * rng.integers(-2, 3), np.pi * rng.integers(-2, 3)
        assert sigma_min(_geo_rows(S, r, q)) < 1e-9


def _geo_rows(S, chain, q):
    """(ṗx, ṗy) rows of the geometric Jacobian from modern_robotics: ṗ = v_s + ω_s × p."""
    Js = mr.JacobianSpace(S, q)
    p = mr.FKinSpace(np.array(chain.M, dtype=float), S, q)[:3, 3]
    return (Js[3:] + np.cross(Js[:3].T, p).T)[:2]


def test_single_joint_robot_and_cart_pole():
    t = sp.Symbol("t", real=True)
    assert singular_configurations(sp.Matrix([[sp.cos(t)]]), [t]) == [
        {t: sp.ImageSet(sp.Lambda(K, pi * K + pi / 2), sp.Integers)}
    ]
    assert singular_configurations(sp.Matrix([[sp.sin(t) - 1]]), [t]) == [
        {t: sp.ImageSet(sp.Lambda(K, 2 * pi * K + pi / 2), sp.Integers)}
    ]
    assert singular_configurations(sp.Matrix([[sp.sin(t) + 2]]), [t]) == []
    cp = robots.cart_pole()
    th2 = cp.thetas[1]
    assert singular_configurations(task_rows(cp.jacobian_geometric(), ["vx", "vy"]), cp.thetas) == [
        {th2: sp.ImageSet(sp.Lambda(K, pi * K + pi / 2), sp.Integers)}
    ]


# ------------------------------------------------------------------------------------------
# singular_configurations: bad input
# ------------------------------------------------------------------------------------------
def test_bad_input_singular_configurations():
    r = robots.planar_offset_3r()
    J = task_rows(r.jacobian_space(), "planar")
    with pytest.raises(TypeError, match="symbolic Jacobian"):
        singular_configurations(np.eye(3), r.thetas)
    with pytest.raises(TypeError, match="J must be a matrix"):
        singular_configurations(sp.Symbol("x"), r.thetas)
    with pytest.raises(ValueError, match="3 SymPy symbols"):
        singular_configurations(J, r.thetas[:2])
    with pytest.raises(TypeError, match="SymPy symbols"):
        singular_configurations(J, ["theta1", "theta2", "theta3"])
    with pytest.raises(TypeError, match="sequence"):
        singular_configurations(J, 3)
    with pytest.raises(ValueError, match="distinct"):
        singular_configurations(J, (r.thetas[0],) * 3)
    x = sp.Symbol("x", real=True)  # not a joint, not positive: not a parameter either
    with pytest.raises(ValueError, match="x.*not among the joints"):
        singular_configurations(J + sp.Matrix(3, 3, lambda i, j: x if i == j == 0 else 0), r.thetas)
    # ... unless declared a parameter (any real: x = 0 makes every configuration singular, so it is reported)
    assert singular_configurations(J.subs(sp.Symbol("L", positive=True), x), r.thetas, params=[x]) == [
        {r.thetas[1]: sp.ImageSet(sp.Lambda(K, pi * K - pi / 4), sp.Integers)},
        x,
    ]
    with pytest.raises(ValueError, match="identically zero"):
        singular_configurations(
            sp.Matrix([[sp.sin(x), sp.sin(x)], [sp.cos(x), sp.cos(x)]]), [x, sp.Symbol("y", real=True)]
        )
    with pytest.raises(ValueError, match="polynomial in sin"):
        singular_configurations(sp.Matrix([[sp.sin(x / 2)]]), [x])
    with pytest.raises(ValueError, match=r"polynomial in sin.*entry x\*sin\(x\)"):
        singular_configurations(sp.Matrix([[1, 0], [x * sp.sin(x), sp.cos(x)]]), [x, sp.Symbol("y", real=True)])


# ------------------------------------------------------------------------------------------
# rank, column space, left null space at a configuration
# ------------------------------------------------------------------------------------------
Q53 = [pi / 4, -pi / 4, pi / 4]


def planar_J():
    r = robots.planar_offset_3r()
    return r, task_rows(r.jacobian_space(), "planar")


def test_rank_at_sees_the_drop_that_generic_rank_hides():
    r, J = planar_J()
    assert J.rank() == 3  # SymPy's generic rank
    assert rank_at(J, dict(zip(r.thetas, Q53))) == 2
    assert rank_at(J, Q53, thetas=r.thetas) == 2
    assert rank_at(J, [0, 0, 0], thetas=r.thetas) == 3
    # numeric paths
    assert rank_at(J.subs(sp.Symbol("L", positive=True), 1), [np.pi / 4, -np.pi / 4, np.pi / 4], r.thetas) == 2
    assert rank_at(np.array(evaluate_at(J, Q53, r.thetas).subs(sp.Symbol("L", positive=True), 2), dtype=float)) == 2


def _span_projector(B):
    B = np.asarray(B, dtype=float)
    if B.shape[1] == 0:
        return np.zeros((B.shape[0], B.shape[0]))
    Q, _ = np.linalg.qr(B)
    return Q @ Q.T


def test_problem_5_3_directions():
    r, J = planar_J()
    C = column_space(J, Q53, r.thetas)
    N = left_null_space(J, Q53, r.thetas)
    assert C == sp.Matrix([[1, 0], [0, 1], [0, -1]])
    assert N == sp.Matrix([0, 1, 1])  # the printed null(Js') = [0, 1, 1]ᵀ
    printed = sp.Matrix([[1, 0], [0, sp.sqrt(2) / 2], [0, -sp.sqrt(2) / 2]])
    assert (printed.row_join(C)).rank() == 2


@pytest.mark.parametrize("seed", range(4))
def test_column_and_left_null_space_against_svd(seed):
    """At members of the planar family: spans equal NumPy's SVD range; left null ⟂ columns."""
    rng = np.random.default_rng(seed)
    r, J = planar_J()
    L = sp.Symbol("L", positive=True)
    q = [
        sp.Rational(int(rng.integers(-8, 8)), 4) * pi,
        -pi / 4 + int(rng.integers(-2, 3)) * pi,
        sp.Rational(int(rng.integers(-8, 8)), 3) * pi,
    ]
    C = column_space(J, q, r.thetas)
    N = left_null_space(J, q, r.thetas)
    Lval = 1.7
    Jn = np.array(evaluate_at(J, q, r.thetas).subs(L, Lval), dtype=float)
    U, s, _ = np.linalg.svd(Jn)
    rank = int(np.sum(s > 1e-9))
    assert C.shape == (3, rank) and N.shape == (3, 3 - rank)
    Cn = np.array(C.subs(L, Lval), dtype=float)
    Nn = np.array(N.subs(L, Lval), dtype=float)
    assert np.all(np.isfinite(Cn)) and np.all(np.isfinite(Nn))
    assert np.allclose(_span_projector(Cn), _span_projector(U[:, :rank]), atol=1e-9)
    assert np.allclose(Nn.T @ Jn, 0, atol=1e-9)
    # the numeric backend against the SVD too: range U[:, :rank], left null space U[:, rank:]
    assert np.allclose(_span_projector(column_space(Jn)), _span_projector(U[:, :rank]), atol=1e-9)
    assert np.allclose(_span_projector(left_null_space(Jn)), _span_projector(U[:, rank:]), atol=1e-9)


def test_basis_defined_where_generic_nullspace_is_not():
    """SymPy's nullspace of the symbolic matrix has 1/tan-like entries; at θ = 0 ours are plain numbers."""
    t = sp.Symbol("t", real=True)
    J = sp.Matrix([sp.cos(t), sp.sin(t)])
    generic = J.T.nullspace()[0]
    assert any(sp.denom(sp.together(e)).has(sp.cos) for e in generic)  # −sin t / cos t: undefined at π/2
    assert left_null_space(J, {t: pi / 2}) == sp.Matrix([1, 0])
    assert column_space(J, {t: pi / 2}) == sp.Matrix([0, 1])
    assert left_null_space(J, {t: pi / 3}) == sp.Matrix([1, -sp.sqrt(3) / 3])
    J2 = sp.Matrix([[sp.sin(t), sp.cos(t)], [sp.sin(t), sp.cos(t)]])
    assert rank_at(J2, {t: pi / 2}) == 1
    assert left_null_space(J2, {t: 0}) == sp.Matrix([1, -1])


def test_ur5_elbow_singular_config_exact():
    r = robots.ur5()
    q = [0, pi / 4, 0, pi / 3, pi / 2, pi / 6]
    J = r.jacobian_space()
    assert rank_at(J, q, r.thetas) == 5
    N = left_null_space(J, q, r.thetas)
    Jn = mr.JacobianSpace(np_screws(r), np.array([float(v) for v in q]))
    assert N.shape == (6, 1)
    assert np.allclose(np.array(N, dtype=float).T @ Jn, 0, atol=1e-12)


def test_rank_at_bad_input():
    r, J = planar_J()
    with pytest.raises(ValueError, match="3 joint values"):
        rank_at(J, [0, 0], thetas=r.thetas)
    with pytest.raises(ValueError, match="give thetas"):
        rank_at(J, [0, 0, 0])
    with pytest.raises(TypeError, match=r"subs\[theta1\] must be a real number .* got the string 'pi'"):
        rank_at(J, {r.thetas[0]: "pi", r.thetas[1]: 0})
    with pytest.raises(ValueError, match="real number"):
        rank_at(J, {r.thetas[0]: r.thetas[2], r.thetas[1]: 0})
    with pytest.raises(ValueError, match=r"subs\[theta1\] must be real and finite, got I"):
        rank_at(J, {r.thetas[0]: sp.I, r.thetas[1]: 0})
    with pytest.raises(ValueError, match="still depends on theta2"):
        rank_at(J, {r.thetas[0]: 0})
    with pytest.raises(TypeError, match="keys must be SymPy symbols"):
        rank_at(J, {"theta1": 0})
    with pytest.raises(TypeError, match="mapping"):
        rank_at(J, 3)
    with pytest.raises(TypeError, match="subs only applies"):
        rank_at(np.eye(3), {r.thetas[0]: 0})
    with pytest.raises(ValueError, match="J must be taken at a configuration: it still depends on theta1, theta2"):
        column_space(J)
    with pytest.raises(ValueError, match="J must be taken at a configuration: it still depends on theta1, theta2"):
        left_null_space(J)
    with pytest.raises(TypeError, match="J must be a matrix"):
        rank_at("J")


def test_representatives_and_trig_simplify():
    fam = sp.Union(
        sp.ImageSet(sp.Lambda(K, 2 * pi * K + pi / 3), sp.Integers), sp.FiniteSet(sp.Rational(1, 2)), evaluate=False
    )
    assert representatives(fam, 0, 4 * pi) == [sp.Rational(1, 2), pi / 3, 7 * pi / 3]
    with pytest.raises(TypeError, match="SymPy Set"):
        representatives([1, 2])
    with pytest.raises(ValueError, match="lo < hi"):
        representatives(fam, 1, 0)
    t1, t2 = sp.symbols("theta1 theta2", real=True)
    e = sp.sin(t1) ** 2 * sp.sin(t2) + sp.cos(t1) ** 2 * sp.sin(t2) + 1
    assert trig_simplify(e) == sp.sin(t2) + 1
    assert trig_simplify(sp.Matrix([e])) == sp.Matrix([sp.sin(t2) + 1])


def test_trig_simplify_outside_trig_polynomials_and_exact_zero_test():
    from kinlib.exactfield import decide_zero as _is_zero  # kinlib's one exact zero test (rank, rref)

    t1 = sp.Symbol("theta1", real=True)
    L1, L2 = sp.symbols("L1 L2", positive=True)
    # sin/cos under a root or in a denominator: no polynomial normal form, trigsimp alone
    assert trig_simplify(sp.sqrt(L1 * sp.sin(t1) ** 2 + L1 * sp.cos(t1) ** 2)) == sp.sqrt(L1)
    assert trig_simplify(sp.sin(t1) / (sp.sin(t1) ** 2 + sp.cos(t1) ** 2)) == sp.sin(t1)
    # the zero test behind rank/rref: exact for polynomials in the parameters and algebraic numbers
    assert _is_zero(sp.expand((L1 + L2) ** 7) - (L1 + L2) ** 7)
    assert not _is_zero(sp.expand((L1 + L2) ** 7) - (L1 + L2) ** 7 + L1 * sp.Rational(1, 10**30))
    assert _is_zero(sp.sqrt(2) / 2 - 1 / sp.sqrt(2)) and not _is_zero(sp.sqrt(2) * L1 - L1)
    assert _is_zero(sp.sqrt(6) * sp.sqrt(3) - 3 * sp.sqrt(2))
