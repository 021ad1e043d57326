"""kinlib.exact off the problem set: rank, column space and left null space at any configuration of any arm,
against an independent 60-digit oracle (tests/exact_oracle.py: the product of exponentials in mpmath).

Arms are random (revolute and prismatic, 2–6 joints, exact unit axes, numeric or symbolic lengths);
configurations are rationals, integers, rational multiples of π, mixtures, and points on singular families.
"""

from __future__ import annotations

import mpmath
import pytest
import sympy as sp
from hypothesis import HealthCheck, assume, given, settings
from hypothesis import strategies as st

import exact_oracle as O
from kinlib import SerialChain, robots
from kinlib.exact import (
    ConditionalResultWarning,
    NumericFallbackWarning,
    Rank,
    column_space,
    evaluate_at,
    exact_is_zero,
    left_null_space,
    rank_at,
)
from kinlib.singularities import task_rows

R = sp.Rational
pi = sp.pi

# exact unit vectors with small rational entries (so the chains stay exact)
UNITS = [
    (1, 0, 0),
    (0, 1, 0),
    (0, 0, 1),
    (0, 0, -1),
    (R(3, 5), R(4, 5), 0),
    (0, R(3, 5), R(-4, 5)),
    (R(2, 3), R(2, 3), R(1, 3)),
    (R(-4, 5), 0, R(3, 5)),
]
SETTINGS = dict(deadline=None, derandomize=True, suppress_health_check=[HealthCheck.too_slow])


def chain_from(kinds, axes, points, tool):
    cols = []
    for k, w, q in zip(kinds, axes, points):
        w, q = sp.Matrix(w), sp.Matrix(q)
        cols.append(list(w) + list(-w.cross(q)) if k == "R" else [0, 0, 0] + list(w))
    M = sp.eye(4)
    M[:3, 3] = sp.Matrix(tool)
    return SerialChain(M, cols, name="random")


coord = st.integers(-3, 3).map(lambda v: R(v, 2))
point = st.tuples(coord, coord, coord)


@st.composite
def arms(draw, n_min=2, n_max=5):
    n = draw(st.integers(n_min, n_max))
    kinds = "".join(draw(st.lists(st.sampled_from("RRP"), min_size=n, max_size=n)))
    axes = draw(st.lists(st.sampled_from(UNITS), min_size=n, max_size=n))
    points = draw(st.lists(point, min_size=n, max_size=n))
    return chain_from(kinds, axes, points, draw(point))


angle = st.one_of(
    st.integers(-12, 12).map(sp.Integer),  # 10, -3, 0
    st.tuples(st.integers(-9, 9), st.integers(1, 4)).map(lambda a: R(*a)),  # 1/2, -7/3
    st.tuples(st.integers(-8, 8), st.sampled_from([1, 2, 3, 4, 6])).map(lambda a: R(*a) * pi),  # kπ/6
    st.tuples(st.integers(-3, 3), st.integers(-4, 4)).map(lambda a: a[0] + R(a[1], 4) * pi),  # 2 + π/2
    st.sampled_from([sp.Integer(0), pi, -pi, pi / 2]),  # the classic singular values
)
slide = st.tuples(st.integers(-6, 6), st.integers(1, 3)).map(lambda a: R(*a))


def config(draw, chain):
    return [draw(angle) if k == "R" else draw(slide) for k in chain.joint_types]


def oracle_rank(chain, q, rows=None):
    J = O.space_jacobian(chain.screws, q)
    return O.rank(O.rows(J, rows) if rows else J)


@settings(max_examples=40, **SETTINGS)
@given(st.data())
def test_rank_at_equals_60_digit_svd_on_random_arms(data):
    chain = data.draw(arms())
    q = config(data.draw, chain)
    want = oracle_rank(chain, q)
    assume(want is not None)
    got = rank_at(chain.jacobian_space(), q, chain.thetas)
    assert isinstance(got, Rank) and got.exact and not got.unless
    assert got == want, (chain.screws, q)


@settings(max_examples=25, **SETTINGS)
@given(st.data())
def test_rank_at_planar_rows_of_random_planar_arms(data):
    """Planar arms with task rows (ω_z, v_x, v_y) at rationals, integers and π multiples, and at stretched poses."""
    n = data.draw(st.integers(2, 4))
    kinds = "".join(data.draw(st.lists(st.sampled_from("RRRP"), min_size=n, max_size=n)))
    axes = [
        (0, 0, 1) if k == "R" else data.draw(st.sampled_from([(1, 0, 0), (0, 1, 0), (R(3, 5), R(4, 5), 0)]))
        for k in kinds
    ]
    points = [(data.draw(coord), data.draw(coord), 0) for _ in kinds]
    chain = chain_from(kinds, axes, points, (data.draw(coord), data.draw(coord), 0))
    q = config(data.draw, chain)
    if data.draw(st.booleans()):  # put a revolute joint on a "stretched" value
        i = data.draw(st.integers(0, n - 1))
        if kinds[i] == "R":
            q[i] = data.draw(st.sampled_from([sp.Integer(0), pi]))
    want = oracle_rank(chain, q, [2, 3, 4])
    assume(want is not None)
    J = task_rows(chain.jacobian_space(), "planar")
    assert rank_at(J, q, chain.thetas) == want


def _projector(B):
    """Orthogonal projector onto the span of the columns of the mpmath matrix B."""
    if B.cols == 0:
        return mpmath.zeros(B.rows, B.rows)
    Q, _ = mpmath.qr(B)
    Q = Q[:, : B.cols]
    return Q * Q.T


@settings(max_examples=20, **SETTINGS)
@given(st.data())
def test_column_and_left_null_space_against_the_oracle(data):
    chain = data.draw(arms(2, 4))
    q = config(data.draw, chain)
    J = O.space_jacobian(chain.screws, q)
    r = O.rank(J)
    assume(r is not None)
    Js = chain.jacobian_space()
    C = column_space(Js, q, chain.thetas)
    N = left_null_space(Js, q, chain.thetas)
    assert C.shape == (6, r) and N.shape == (6, 6 - r)
    assert not any(e.has(sp.Float) for e in C) and not any(e.has(sp.Float) for e in N)
    with mpmath.workdps(60):
        Cm, Nm = O.to_mp(C), O.to_mp(N)
        # canonical (rref) form: each basis vector has a leading 1 in its own position
        for Bm in (C, N):
            for k in range(Bm.cols):
                lead = next(i for i in range(Bm.rows) if Bm[i, k] != 0)
                assert Bm[lead, k] == 1
        # same span as the oracle's left singular vectors
        U, S, _ = mpmath.svd_r(J)
        Ur = U[:, :r] if r else mpmath.zeros(6, 0)
        assert O.max_abs(_projector(Cm) - _projector(Ur)) < mpmath.mpf(10) ** -30
        if 6 - r:
            assert O.max_abs(J.T * Nm) < mpmath.mpf(10) ** -30
            assert O.rank(Nm) == 6 - r


def test_issue_reproductions_planar_2r():
    M = sp.Matrix([[1, 0, 0, 2], [0, 1, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1]])
    ch = SerialChain(M, [[0, 0, 1, 0, 0, 0], [0, 0, 1, 0, -1, 0]])
    t1, t2 = ch.thetas
    J = task_rows(ch.jacobian_geometric(), ["vx", "vy"])
    assert rank_at(J, {t1: 10, t2: 0}) == 1  # stretched out at θ1 = 10
    assert rank_at(J, {t1: R(1, 2), t2: R(1, 2)}) == 2  # was truncated to (0, 0)
    from fractions import Fraction

    assert rank_at(J, {t1: Fraction(1, 2), t2: Fraction(1, 2)}) == 2
    # floats select the numeric backend (no truncation either)
    r = rank_at(J, {t1: 0.5, t2: 0.5})
    assert r == 2 and not isinstance(r, Rank)
    N = left_null_space(J, {t1: 3, t2: 0})
    assert N.shape == (2, 1) and N[0] == 1
    assert exact_is_zero(N[1] - sp.sin(3) / sp.cos(3))  # the radial direction (cos 3, sin 3)
    C = column_space(J, {t1: 3, t2: 0})
    assert C.shape == (2, 1) and exact_is_zero(C[1] + sp.cos(3) / sp.sin(3))
    # evaluate_at keeps exact values (no "nice" guesses): sin 3 stays sin 3
    E = evaluate_at(J, {t1: 3, t2: 0})
    assert exact_is_zero(E[0, 1] + sp.sin(3)) and exact_is_zero(E[1, 0] - 2 * sp.cos(3))


def elbow_3r(L1, L2, H):
    """A spatial elbow arm: waist about z, shoulder and elbow about y; upper arm L1, forearm L2, shoulder height H."""
    S = [[0, 0, 1, 0, 0, 0], [0, 1, 0, -H, 0, 0], [0, 1, 0, -H, 0, L1]]
    M = sp.eye(4)
    M[:3, 3] = sp.Matrix([L1 + L2, 0, H])
    return SerialChain(M, S, name="elbow")


def test_issue_reproduction_elbow_with_symbolic_lengths():
    L1, L2, H = sp.symbols("L1 L2 H", positive=True)
    ch = elbow_3r(L1, L2, H)
    Jp = task_rows(ch.jacobian_geometric(), "linear")
    r = rank_at(Jp, (2, 1, 0), ch.thetas)  # elbow stretched: rank 2 for all lengths
    assert r == 2 and r.exact and not r.unless
    r3 = rank_at(Jp, (2, 1, 1), ch.thetas)
    assert r3 == 3
    # against the oracle at several positive lengths
    for vals in [(1, 1, 1), (R(3, 2), R(1, 3), 2), (2, 5, R(1, 7))]:
        num = elbow_3r(*vals)
        assert O.rank(O.rows(_geometric_mp(num, (2, 1, 0)), [3, 4, 5])) == 2
        assert O.rank(O.rows(_geometric_mp(num, (2, 1, 1)), [3, 4, 5])) == 3


def _geometric_mp(chain, q):
    """[ω_s; ṗ] = [[I, 0], [−[p], I]] J_s with p the tool position, in mpmath (oracle side)."""
    Js = O.space_jacobian(chain.screws, q)
    with mpmath.workdps(75):
        T = mpmath.eye(4)
        for i in range(chain.n):
            T = T * O._exp6([O._mp(x) for x in chain.screws[:, i]], O._mp(q[i]))
        T = T * O.to_mp(chain.M)
        p = [T[0, 3], T[1, 3], T[2, 3]]
        J = Js.copy()
        for j in range(chain.n):
            w = [Js[0, j], Js[1, j], Js[2, j]]
            pxw = [p[1] * w[2] - p[2] * w[1], p[2] * w[0] - p[0] * w[2], p[0] * w[1] - p[1] * w[0]]
            for k in range(3):
                J[3 + k, j] = Js[3 + k, j] - pxw[k]
        return J


def test_symbolic_lengths_conditions_are_stated():
    L1, L2 = sp.symbols("L1 L2", positive=True)
    t1, t2 = sp.symbols("theta1 theta2", real=True)
    J = sp.Matrix(
        [
            [-L1 * sp.sin(t1) - L2 * sp.sin(t1 + t2), -L2 * sp.sin(t1 + t2)],
            [L1 * sp.cos(t1) + L2 * sp.cos(t1 + t2), L2 * sp.cos(t1 + t2)],
        ]
    )
    assert rank_at(J, {t1: 2, t2: 1}).unless == ()  # L1 L2 sin 1 ≠ 0 for all positive lengths
    folded = rank_at(J, {t1: 2, t2: pi})  # folded back: rank 1 for all lengths (column 2)
    assert folded == 1 and folded.unless == ()
    # a rank that does depend on the lengths: J = [[L1 − L2, L1 − L2]] (and the tool of a folded 2R, ṗ_x row only)
    D = sp.Matrix([[L1 - L2, 2 * (L1 - L2)], [0, 0]])
    r = rank_at(D)
    assert r == 1 and len(r.unless) == 1 and sp.expand(r.unless[0] ** 2 - (L1 - L2) ** 2) == 0
    assert "assuming" in repr(r)
    assert rank_at(D.subs({L1: 1, L2: 1})) == 0  # and at L1 = L2 it is lower indeed
    Jx = sp.Matrix([[J[0, 0]]])  # ṗ_x of the first joint alone at θ = (2, π)
    rx = rank_at(Jx, {t1: 2, t2: pi})
    assert rx == 1 and rx.unless and rank_at(Jx.subs({L1: 1, L2: 1}), {t1: 2, t2: pi}) == 0
    with pytest.warns(ConditionalResultWarning):
        column_space(Jx, {t1: 2, t2: pi})


def test_fallback_is_stated_and_agrees_with_the_oracle():
    ch = robots.planar_3r(1, 1, 1)
    J = task_rows(ch.jacobian_space(), "planar")
    r = rank_at(J, (sp.sqrt(2), 0, 1), ch.thetas)
    assert r == 2 and not r.exact and "60-digit" in r.note
    assert oracle_rank(ch, (sp.sqrt(2), 0, 1), [2, 3, 4]) == 2
    with pytest.warns(NumericFallbackWarning, match="60-digit"):
        N = left_null_space(J, (sp.sqrt(2), 0, 1), ch.thetas)
    assert N.shape == (3, 1)
    with mpmath.workdps(60):
        Jm = O.rows(O.space_jacobian(ch.screws, (sp.sqrt(2), 0, 1)), [2, 3, 4])
        assert O.max_abs(Jm.T * O.to_mp(N)) < mpmath.mpf(10) ** -25
    # symbolic lengths cannot go numeric: a clear error
    with pytest.raises(ValueError, match="substitute them"):
        rank_at(task_rows(robots.planar_3r().jacobian_space(), "planar"), (sp.sqrt(2), 0, 1), robots.planar_3r().thetas)


def test_far_apart_angles_on_a_6_joint_arm_are_exact_at_the_elbow():
    """1/7 next to 3 on the UR5 with the elbow stretched: elimination in K(t) would take minutes (multiples of 1/21
    up to 21, and it used to fall back to the 60-digit SVD); the elbow's structure (sin θ3 = 0 whatever the other
    joints are: exact_rank.PointLift) decides it exactly, in agreement with the oracle; full rank is exact too."""
    u = robots.ur5()
    q = (R(1, 7), 3, 0, 1, 2, 2)
    r = rank_at(u.jacobian_space(), q, u.thetas)
    assert r == 5 == O.rank(O.space_jacobian(u.screws, q)) and r.exact
    q2 = (R(1, 7), 3, 1, 1, 2, 2)
    r2 = rank_at(u.jacobian_space(), q2, u.thetas)
    assert r2 == 6 and r2.exact


@pytest.mark.parametrize("q", [(1, 2, 3, 4, 5, 6), (1, 2, R(1, 3), 4, 0, 6), (2, -1, 3, 1, pi / 2, 10)])
def test_six_joint_arms_at_integer_angles(q):
    """The Stanford-like RRPRRR arm (was > 4 minutes) and the UR5 (elbow stretched), against the oracle."""
    for chain in (robots.stanford(), robots.ur5()):
        Js = chain.jacobian_space()
        want = O.rank(O.space_jacobian(chain.screws, q))
        assert rank_at(Js, q, chain.thetas) == want
        assert left_null_space(Js, q, chain.thetas).shape == (6, 6 - want)
    u = robots.ur5()
    assert rank_at(u.jacobian_geometric(), (R(1, 2), 10, 0, 1, 3, 2), u.thetas) == 5  # elbow: θ3 = 0


def test_exact_is_zero_identities_and_refusals():
    assert exact_is_zero(sp.sin(10) - 2 * sp.sin(5) * sp.cos(5))
    assert exact_is_zero(sp.cos(R(1, 3)) ** 2 + sp.sin(R(1, 3)) ** 2 - 1)
    assert exact_is_zero(sp.sin(3 + pi / 2) - sp.cos(3))
    assert exact_is_zero(sp.sin(pi / 7) - sp.cos(5 * pi / 14))
    assert not exact_is_zero(sp.sin(1) - R(841470984807896507, 10**18))  # agrees to 18 digits, not equal
    assert not exact_is_zero(sp.sin(R(1, 2)) * sp.sin(10) - sp.sin(R(21, 2)) + 10**-30)
    with pytest.raises(ValueError, match="no exact zero test"):
        exact_is_zero(sp.sin(sp.sqrt(2)))


@pytest.mark.parametrize(
    "bad, exc, words",
    [
        ({"theta1": 0}, TypeError, "keys must be SymPy symbols"),
        (3, TypeError, "mapping"),
        ({0: 1}, TypeError, "keys must be SymPy symbols"),
    ],
)
def test_bad_subs(bad, exc, words):
    t1 = sp.Symbol("theta1", real=True)
    with pytest.raises(exc, match=words):
        rank_at(sp.Matrix([[sp.sin(t1)]]), bad)


@pytest.mark.parametrize(
    "value, exc, words",
    [
        (1j, TypeError, "complex"),
        (sp.I, ValueError, "real and finite"),
        ("1.5", TypeError, "string"),
        (True, TypeError, "bool"),
        (None, TypeError, "None"),
        (float("nan"), ValueError, "finite"),
        (float("inf"), ValueError, "finite"),
        (sp.oo, ValueError, "finite"),
        (sp.Symbol("z"), ValueError, "real"),
    ],
)
def test_bad_joint_values(value, exc, words):
    t1 = sp.Symbol("theta1", real=True)
    J = sp.Matrix([[sp.sin(t1), 1]])
    for f in (rank_at, evaluate_at, column_space, left_null_space):
        with pytest.raises(exc, match=words):
            f(J, {t1: value})


@pytest.mark.parametrize(
    "J, exc, words",
    [
        ([[1, float("nan")]], ValueError, "finite"),
        ([[1, 1j]], TypeError, "complex"),
        ("J", TypeError, "J must be a matrix"),
        ([[True, 1]], TypeError, "bool"),
        ([1, 2], ValueError, "matrix"),
        (sp.Matrix([[sp.nan]]), ValueError, "finite"),
    ],
)
def test_bad_jacobians(J, exc, words):
    with pytest.raises(exc, match=words):
        rank_at(J)


def test_non_real_joint_symbol_refused():
    z = sp.Symbol("z")
    with pytest.raises(ValueError, match="declared real"):
        rank_at(sp.Matrix([[sp.sin(z)]]), [1], thetas=[z])


@settings(max_examples=30, **SETTINGS)
@given(st.lists(st.integers(-40, 40), min_size=1, max_size=14), st.lists(st.integers(-40, 40), min_size=1, max_size=14))
def test_exact_field_ratio_in_sin_cos_is_sympys_and_equal(a, b):
    """ExactField.to_ratio (polynomial arithmetic over QQ[sin g, cos g]) gives the very pair SymPy's route gives
    (t → sin g/(1 + cos g), together, fraction, expand: what the display was made from), and its value is the
    field element's at t = tan(g/2) (60 digits)."""
    from kinlib.exactfield import ExactField

    assume(any(a) and any(b))
    fld = ExactField([sp.sin(sp.Rational(1, 2)), sp.cos(3)])
    tt = fld.ring.gens[0]
    num = sum((sp.QQ(c, 1 + i % 3) * tt**i for i, c in enumerate(a)), fld.ring.zero)
    den = sum((sp.QQ(c, 1 + i % 5) * tt**i for i, c in enumerate(b)), fld.ring.zero)
    x = fld.F(num) / fld.F(den)
    got = fld.to_ratio(x)
    s, c = sp.sin(fld.g), sp.cos(fld.g)
    n, dd = (p.as_expr(fld.t) for p in (x.numer, x.denom))
    want = sp.fraction(sp.together(sp.expand(n).subs(fld.t, s / (1 + c)) / sp.expand(dd).subs(fld.t, s / (1 + c))))
    assert got == tuple(sp.expand(w) for w in want)
    value = (n / dd).subs(fld.t, sp.tan(fld.g / 2))
    assert abs(sp.N(got[0] / got[1] - value, 60)) < 1e-50
