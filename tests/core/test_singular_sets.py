"""singular_configurations and find_singularities against independent numerics (issue 11, item 2).

Random arms (R and P joints, axes along ±x, ±y, ±z through points with integer and symbolic-length
coordinates): every member of every returned family has σ_min ≈ 0 by a NumPy SVD of modern_robotics'
Jacobian (lengths substituted), random non-members have σ_min clearly > 0, and every singular
configuration found by a numeric search (verified with modern_robotics) lies on a returned condition.
"""

from __future__ import annotations

import functools

import modern_robotics as mr
import numpy as np
import pytest
import sympy as sp
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from kinlib import SerialChain, robots
from kinlib.singular_search import SingularPoints, find_singularities
from kinlib.singularities import (
    IncompleteResultWarning,
    SingularSet,
    periodic_family,
    representatives,
    singular_configurations,
    task_rows,
)
from kinlib.trigpoly import TrigRing
from kinlib.trigsign import proves_nonzero

L = sp.Symbol("L", positive=True)
ROWS = {"wx": 0, "wy": 1, "wz": 2, "vx": 3, "vy": 4, "vz": 5}


# ------------------------------------------------------------------------------------------
# independent numerics: modern_robotics Jacobians, NumPy SVD
# ------------------------------------------------------------------------------------------
def mr_jacobian(S, M, q, kind):
    Js = mr.JacobianSpace(S, q)
    if kind == "space":
        return Js
    p = mr.FKinSpace(M, S, q)[:3, 3]
    return np.vstack([Js[:3], Js[3:] + np.cross(Js[:3].T, p).T])  # [ω_s; ṗ], ṗ = v + ω × p


def sigma_k(J):
    return np.linalg.svd(J, compute_uv=False)[min(J.shape) - 1]


def ang_dist(x, pts, period):
    return min(abs((x - p + period / 2) % period - period / 2) for p in pts)


def satisfies(cond, q, thetas, values, revolute, tol):
    """Whether configuration q satisfies a condition (dict of families, or expression = 0)."""
    if isinstance(cond, dict):
        for j, fam in cond.items():
            i = thetas.index(j)
            if revolute[i]:
                pts = [float(p) for p in representatives(fam)]
                if ang_dist(q[i], pts, 2 * np.pi) > tol:
                    return False
            else:
                if min(abs(q[i] - float(p.subs(values))) for p in fam) > tol:
                    return False
        return True
    f, scale = _numeric_condition(cond, tuple(thetas), tuple(values.items()))
    return abs(f(*q)) < tol * max(scale, 1e-300)  # relative to the expression's typical size


@functools.lru_cache(maxsize=256)
def _numeric_condition(cond, thetas, values):
    f = sp.lambdify(thetas, cond.subs(dict(values)), "numpy")
    rng = np.random.default_rng(99)
    return f, np.median([abs(f(*rng.uniform(-np.pi, np.pi, len(thetas)))) for _ in range(15)])


@st.composite
def arms(draw, max_joints=4):
    n = draw(st.integers(2, max_joints))
    coords = st.sampled_from([0, 0, 1, -1, 2, L, -L])
    screws, kinds = [], []
    for _ in range(n):
        axis = [0, 0, 0]
        axis[draw(st.integers(0, 2))] = draw(st.sampled_from([1, -1]))
        w = sp.Matrix(axis)
        if draw(st.integers(0, 3)) == 0:  # prismatic
            screws.append([0, 0, 0, *axis])
            kinds.append("P")
        else:
            point = sp.Matrix([draw(coords) for _ in range(3)])
            screws.append([*axis, *(-w.cross(point))])
            kinds.append("R")
    home = [draw(coords) for _ in range(3)]
    M = sp.Matrix([[1, 0, 0, home[0]], [0, 1, 0, home[1]], [0, 0, 1, home[2]], [0, 0, 0, 1]])
    kind = draw(st.sampled_from(["space", "geometric", "geometric"]))
    rows = None
    if kind == "geometric":
        rows = draw(st.sampled_from([None, "planar", "linear", ["vx", "vy"], ["wz", "vx", "vy", "vz"]]))
    return SerialChain(M, sp.Matrix(screws).T, name="random"), kind, rows


def _row_idx(rows):
    if rows is None:
        return list(range(6))
    names = (
        {"planar": ["wz", "vx", "vy"], "linear": ["vx", "vy", "vz"]}.get(rows, rows) if isinstance(rows, str) else rows
    )
    return [ROWS[r] for r in names]


@settings(deadline=None, derandomize=True, max_examples=30, suppress_health_check=[HealthCheck.too_slow])
@given(arms())
def test_random_arms_members_singular_nonmembers_not_and_nothing_missing(arm):
    chain, kind, rows = arm
    J = chain.jacobian_space() if kind == "space" else chain.jacobian_geometric()
    if rows is not None:
        J = task_rows(J, rows)
    idx = _row_idx(rows)
    rng = np.random.default_rng(7)
    thetas = chain.thetas
    revolute = [t == "R" for t in chain.joint_types]
    try:
        conds = singular_configurations(J, thetas)
    except ValueError as err:  # J never has full rank: check that independently
        assert "never has full rank" in str(err)
        Lv = 1.3
        S, M = (
            (np.array(chain.subs({L: Lv}).screws, dtype=float), np.array(chain.subs({L: Lv}).M, dtype=float))
            if L in chain.params
            else (np.array(chain.screws, dtype=float), np.array(chain.M, dtype=float))
        )
        for _ in range(3):
            q = rng.uniform(-3, 3, chain.n)
            assert sigma_k(mr_jacobian(S, M, q, kind)[idx]) < 1e-9
        return
    assert isinstance(conds, SingularSet)
    if not conds.complete:  # out of reach within the time budget (a loaded machine): a clear note, sound members
        assert "find_singularities" in conds.note
    # a length value off every parameter-only condition
    param_conds = [c for c in conds if not isinstance(c, dict) and not (c.free_symbols & set(thetas))]
    for c in param_conds:  # when it vanishes, every configuration is singular
        for root in sp.solve(c, L):
            if root.is_positive:
                ch = chain.subs({L: root})
                S0, M0 = np.array(ch.screws, dtype=float), np.array(ch.M, dtype=float)
                for _ in range(3):
                    assert sigma_k(mr_jacobian(S0, M0, rng.uniform(-3, 3, chain.n), kind)[idx]) < 1e-9
    Lv = next(
        v
        for v in (sp.Rational(13, 10), sp.Rational(7, 10), sp.Rational(17, 10))
        if all(c.subs(L, v) != 0 for c in param_conds)
    )
    values = {L: Lv}
    num = chain.subs({L: Lv}) if L in chain.params else chain
    S, M = np.array(num.screws, dtype=float), np.array(num.M, dtype=float)

    def smin(q):
        return sigma_k(mr_jacobian(S, M, np.asarray(q, float), kind)[idx])

    joint_conds = [c for c in conds if c not in param_conds]
    # 1. members are singular
    for c in joint_conds:
        for _ in range(4):
            q = rng.uniform(-np.pi, np.pi, chain.n)
            if isinstance(c, dict):
                for j, fam in c.items():
                    i = thetas.index(j)
                    pts = representatives(fam) if revolute[i] else list(fam)
                    q[i] = float(sp.sympify(pts[rng.integers(len(pts))]).subs(values)) + (
                        2 * np.pi * rng.integers(-1, 2) if revolute[i] else 0
                    )
                assert smin(q) < 1e-8, (c, q)
            else:  # an expression: a sign change along one joint, then bisection
                f = sp.lambdify(thetas, c.subs(values), "numpy")
                j = thetas.index(sorted(c.free_symbols & set(thetas), key=str)[0])
                grid = np.linspace(-np.pi, np.pi, 241)
                vals = []
                for x in grid:
                    q[j] = x
                    vals.append(f(*q))
                for a, b, fa, fb in zip(grid[:-1], grid[1:], vals[:-1], vals[1:]):
                    if fa * fb < 0:
                        for _ in range(60):
                            m = (a + b) / 2
                            q[j] = m
                            if f(*q) * fa > 0:
                                a = m
                            else:
                                b = m
                        q[j] = (a + b) / 2
                        assert smin(q) < 1e-6, (c, q)
                        break
    # 2. random non-members are not singular
    for _ in range(8 if conds.complete else 0):
        q = rng.uniform(-np.pi, np.pi, chain.n)
        if not any(satisfies(c, q, thetas, values, revolute, 0.05) for c in joint_conds):
            assert smin(q) > 1e-7, (conds, q)
    # 3. nothing missing: every rank drop a numeric search finds (checked with modern_robotics) is covered
    found = find_singularities(num, rows, samples=40, seed=3, tol=1e-7)
    for q in found.q:
        assert smin(q) < 1e-6
        if not conds.complete:
            continue
        assert any(satisfies(c, q, thetas, values, revolute, 1e-4) for c in joint_conds), (conds, q)


@pytest.mark.slow
@settings(deadline=None, derandomize=True, max_examples=8, suppress_health_check=[HealthCheck.too_slow])
@given(arms(max_joints=6))
def test_random_bigger_arms(arm):
    """The same properties on arms of up to 6 joints (some answers are partial within the time budget)."""
    test_random_arms_members_singular_nonmembers_not_and_nothing_missing.hypothesis.inner_test(arm)


# ------------------------------------------------------------------------------------------
# the reproductions and special cases
# ------------------------------------------------------------------------------------------
def _planar_2r():
    L1, L2 = sp.symbols("L1 L2", positive=True)
    return (
        SerialChain(
            sp.Matrix([[1, 0, 0, L1 + L2], [0, 1, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1]]),
            [[0, 0, 1, 0, 0, 0], [0, 0, 1, 0, -L1, 0]],
            name="2R",
        ),
        L1,
        L2,
    )


def test_planar_2r_full_geometric_jacobian_is_never_singular():
    """The issue: [L2² sin²θ2 + 1] before; ω_z = θ̇1 + θ̇2 and ṗ cannot both vanish: never singular."""
    c, L1, L2 = _planar_2r()
    conds = singular_configurations(c.jacobian_geometric(), c.thetas)
    assert conds == [] and conds.complete
    assert singular_configurations(task_rows(c.jacobian_geometric(), "planar"), c.thetas) == []
    rng = np.random.default_rng(0)
    num = c.subs({L1: 1, L2: sp.Rational(1, 2)})
    S, M = np.array(num.screws, dtype=float), np.array(num.M, dtype=float)
    for t2 in (0.0, np.pi, *rng.uniform(-3, 3, 5)):
        assert sigma_k(mr_jacobian(S, M, [rng.uniform(-3, 3), t2], "geometric")) > 0.3


def test_parameter_condition_is_reported_not_assumed():
    c, L1, L2 = _planar_2r()
    J = task_rows(c.jacobian_geometric(), ["vx", "vy"]) * sp.diag(1, L1 - L2)
    conds = singular_configurations(J, c.thetas)
    assert L1 - L2 in conds or L2 - L1 in conds
    # positive ones are dropped: L1, L1 + L2, L1² + L2²
    J2 = task_rows(c.jacobian_geometric(), ["vx", "vy"]) * sp.diag(L1 + L2, L1**2 + L2**2)
    k = sp.Symbol("k", integer=True)
    assert singular_configurations(J2, c.thetas) == [{c.thetas[1]: sp.ImageSet(sp.Lambda(k, sp.pi * k), sp.Integers)}]
    # and the condition is right: at L1 = L2 every configuration is singular
    f = sp.lambdify(c.thetas, J.subs({L1: 1, L2: 1}), "numpy")
    assert sigma_k(np.array(f(0.3, 1.1), float)) < 1e-12


def test_condition_depending_on_lengths_is_kept_as_expression():
    """L1 + L2 cos θ2 vanishes only when L2 ≥ L1: kept as an expression, not dropped, not solved wrongly."""
    _, L1, L2 = _planar_2r()
    t = sp.Symbol("t", real=True)
    assert singular_configurations(sp.Matrix([[L1 + L2 * sp.cos(t)]]), [t]) == [L1 + L2 * sp.cos(t)]
    assert singular_configurations(sp.Matrix([[L1 + L2 + L2 * sp.cos(t)]]), [t]) == []  # ≥ L1 > 0


def test_prismatic_sum_of_squares_dropped():
    d = sp.Symbol("d", real=True)
    t = sp.Symbol("t", real=True)
    assert singular_configurations(sp.Matrix([[1 + (L + d) ** 2, 0], [0, 3 + sp.sin(t) + sp.cos(t)]]), [d, t]) == []


def test_time_budget_gives_a_clear_partial_result():
    r = robots.ur5()
    with pytest.warns(IncompleteResultWarning, match="find_singularities"):
        conds = singular_configurations(r.jacobian_space(), r.thetas, time_budget=0)
    assert isinstance(conds, SingularSet) and not conds.complete
    assert "find_singularities" in conds.note and "time_budget" in conds.note
    with pytest.raises(ValueError, match="time_budget"):
        singular_configurations(r.jacobian_space(), r.thetas, time_budget=-1)


@pytest.mark.parametrize(
    "expr, nonzero",
    [
        (L**2 * sp.sin(sp.Symbol("t", real=True)) ** 2 + 1, True),
        (3 + sp.sin(sp.Symbol("t", real=True)) + sp.cos(sp.Symbol("t", real=True)), True),
        (1 + sp.sin(sp.Symbol("t", real=True)) + sp.cos(sp.Symbol("t", real=True)), False),
        (L - sp.cos(sp.Symbol("t", real=True)), False),
        (L**2 - L + 1, True),
        (1 + (L + sp.Symbol("d", real=True)) ** 2, True),
    ],
)
def test_trigsign_examples(expr, nonzero):
    t = sp.Symbol("t", real=True)
    ring = TrigRing([expr], [t], opaque=True)
    assert proves_nonzero(ring, ring.normal_form(expr)) is nonzero


@settings(deadline=None, derandomize=True, max_examples=60)
@given(st.lists(st.integers(-3, 3), min_size=7, max_size=7))
def test_trigsign_is_sound(c):
    """Whenever a nonvanishing proof is claimed, a dense grid shows no zero (no sign change, |p| > 0)."""
    a, b = sp.symbols("a b", real=True)
    e = (
        c[0]
        + c[1] * sp.sin(a)
        + c[2] * sp.cos(a)
        + c[3] * sp.cos(b)
        + c[4] * sp.sin(a) * sp.cos(b)
        + c[5] * sp.cos(a) ** 2
        + c[6] * L * sp.sin(b)
    )
    ring = TrigRing([e], [a, b], opaque=True)
    if proves_nonzero(ring, ring.normal_form(e)):
        f = sp.lambdify((a, b, L), e, "numpy")
        A, B = np.meshgrid(np.linspace(-np.pi, np.pi, 121), np.linspace(-np.pi, np.pi, 121))
        for Lv in (1e-3, 0.5, 1.0, 3.0, 100.0):
            v = f(A, B, Lv) * np.ones_like(A)
            assert np.all(v > 0) or np.all(v < 0)


# ------------------------------------------------------------------------------------------
# find_singularities
# ------------------------------------------------------------------------------------------
def test_find_singularities_planar_2r():
    c, L1, L2 = _planar_2r()
    num = c.subs({L1: 1, L2: sp.Rational(1, 2)})
    q, sigma = find_singularities(num, ["vx", "vy"], samples=30)
    assert len(q) >= 10 and np.all(sigma < 1e-6)
    assert np.allclose(np.sin(q[:, 1]), 0, atol=1e-5)  # the family sin θ2 = 0
    S, M = np.array(num.screws, dtype=float), np.array(num.M, dtype=float)
    for x in q:
        assert sigma_k(mr_jacobian(S, M, x, "geometric")[[3, 4]]) < 1e-5
    assert np.all(np.abs(q) <= np.pi + 1e-12)


def test_find_singularities_ur5_families_and_reproducible():
    r = robots.ur5()
    res = find_singularities(r, samples=60, seed=1)
    assert isinstance(res, SingularPoints) and res.q.shape[1] == 6 and len(res.q) >= 20
    S = np.array(r.screws, dtype=float)
    L1, L2, H2 = 0.425, 0.392, 0.095  # the UR5's lengths (m)
    kinds = set()
    for q in res.q:
        assert np.linalg.svd(mr.JacobianSpace(S, q), compute_uv=False)[-1] < 1e-5
        shoulder = L1 * np.cos(q[1]) + L2 * np.cos(q[1] + q[2]) - H2 * np.sin(q[1] + q[2] + q[3])
        on = [abs(np.sin(q[2])) < 1e-4, abs(np.sin(q[4])) < 1e-4, abs(shoulder) < 1e-4]
        assert any(on), q
        kinds |= {i for i, v in enumerate(on) if v}
    assert kinds == {0, 1, 2}  # elbow, wrist and shoulder all found
    again = find_singularities(r, samples=60, seed=1)
    assert np.array_equal(again.q, res.q) and np.array_equal(again.sigma, res.sigma)
    other = find_singularities(r, samples=60, seed=2)
    assert not (other.q.shape == res.q.shape and np.allclose(other.q, res.q))
    # sorted, distinct
    assert len({tuple(np.round(x, 6)) for x in res.q}) == len(res.q)


def test_find_singularities_bad_input():
    with pytest.raises(ValueError, match=r"numeric link lengths.*subs"):
        find_singularities(robots.planar_3r())
    with pytest.raises(TypeError, match="SerialChain"):
        find_singularities(np.eye(3))
    r = robots.planar_3r(1, 1, 1)
    with pytest.raises(ValueError, match="tol"):
        find_singularities(r, tol=-1)
    with pytest.raises(TypeError, match="tol"):
        find_singularities(r, tol="small")
    with pytest.raises(ValueError, match="samples"):
        find_singularities(r, samples=0)
    with pytest.raises(TypeError, match="seed"):
        find_singularities(r, seed=1.5)
    with pytest.raises(ValueError, match="limits"):
        find_singularities(r, limits=[(0, 1)])
    with pytest.raises(ValueError, match="unknown row"):
        find_singularities(r, ["vq"])


# ------------------------------------------------------------------------------------------
# a 7-joint arm: a clear answer within the budget, and it agrees with the numeric search
# ------------------------------------------------------------------------------------------
def franka_like() -> SerialChain:
    """A 7R arm with the Franka Panda's layout (lengths in metres, exact rationals)."""
    R = sp.Rational
    d1, d3, d5, a4, a7 = R(333, 1000), R(316, 1000), R(384, 1000), R(825, 10000), R(88, 1000)
    z3, z5 = d1 + d3, d1 + d3 + d5
    axes = [
        ((0, 0, 1), (0, 0, d1)),
        ((0, 1, 0), (0, 0, d1)),
        ((0, 0, 1), (0, 0, z3)),
        ((0, -1, 0), (a4, 0, z3)),
        ((0, 0, 1), (0, 0, z5)),
        ((0, -1, 0), (0, 0, z5)),
        ((0, 0, -1), (a7, 0, z5)),
    ]
    S = []
    for w, q in axes:
        w, q = sp.Matrix(w), sp.Matrix(q)
        S.append([*w, *(-w.cross(q))])
    M = sp.Matrix([[1, 0, 0, a7], [0, -1, 0, 0], [0, 0, -1, z5 - R(107, 1000)], [0, 0, 0, 1]])
    return SerialChain(M, sp.Matrix(S).T, name="franka_like")


@pytest.mark.slow
def test_seven_joint_arm_answers_and_covers_numeric_search():
    arm = franka_like()
    conds = singular_configurations(arm.jacobian_space(), arm.thetas, time_budget=40)
    assert isinstance(conds, SingularSet)
    S = np.array(arm.screws, dtype=float)
    found = find_singularities(arm, samples=40)
    assert len(found.q) >= 5
    for q in found.q:
        assert sigma_k(mr.JacobianSpace(S, q)) < 1e-5
    if conds.complete:  # every condition is an exact expression or family: check both directions
        revolute = [True] * 7
        for q in found.q:
            assert any(satisfies(c, q, arm.thetas, {}, revolute, 1e-4) for c in conds)
        rng = np.random.default_rng(0)
        for _ in range(20):
            q = rng.uniform(-np.pi, np.pi, 7)
            if not any(satisfies(c, q, arm.thetas, {}, revolute, 1e-3) for c in conds):
                assert sigma_k(mr.JacobianSpace(S, q)) > 1e-8
    else:
        assert "find_singularities" in conds.note


def test_an_incomplete_singular_set_equals_no_list():
    """issue 32: a SingularSet that gave up is not the empty answer (nor any other list), so `== []` in a test or a
    caller cannot mistake giving up for "no singular configuration"; a complete one compares as a list."""
    r = robots.planar_2r()
    J = task_rows(r.jacobian_geometric(), ["vx", "vy"])
    with pytest.warns(IncompleteResultWarning):
        gave_up = singular_configurations(J, r.thetas, time_budget=0)
    assert not gave_up.complete and list(gave_up) == []
    assert gave_up != [] and not (gave_up == []) and gave_up != gave_up
    assert SingularSet([], complete=True) == [] and SingularSet([1], complete=False) != [1]
    done = singular_configurations(J, r.thetas)
    assert done.complete and done == [{r.thetas[1]: periodic_family([0, sp.pi])}]


def test_puma_elbow_factor_is_the_one_its_docstring_states():
    """robots.puma560's docstring: elbow a3 sin θ3 + d4 cos θ3 = 0. Checked independently: at θ3 with
    tan θ3 = −d4/a3 the upper arm and the line from the elbow to the wrist centre are parallel (their cross product
    vanishes), and the 6×6 geometric J is singular there (60-digit determinant)."""
    import mpmath

    r = robots.puma560()
    a3, d4 = sp.Rational("0.0203"), sp.Rational("0.4318")
    th3 = sp.atan2(-d4, a3)  # a3 sin θ3 + d4 cos θ3 = 0
    assert sp.simplify(a3 * sp.sin(th3) + d4 * sp.cos(th3)) == 0
    q = [sp.Rational(1, 3), sp.Rational(-2, 7), th3, sp.Rational(1, 5), sp.Rational(3, 4), sp.Rational(1, 2)]
    f = sp.lambdify(r.thetas, r.jacobian_geometric(), "mpmath")  # J(θ) evaluated in mpmath at 60 digits

    def det60(q):
        with mpmath.workdps(60):
            vals = [
                mpmath.atan2(-mpmath.mpf(4318) / 10000, mpmath.mpf(203) / 10000)
                if x == th3
                else mpmath.mpf(x.p) / x.q
                if x.is_Rational
                else mpmath.mpf(str(sp.N(x, 70)))
                for x in q
            ]
            return mpmath.det(mpmath.matrix(f(*vals)))

    assert abs(det60(q)) < mpmath.mpf(10) ** -50
    q[2] = th3 + sp.Rational(1, 10)  # off the factor: regular
    assert abs(det60(q)) > 1e-6
