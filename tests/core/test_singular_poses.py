"""kinlib.exact at the textbook's singular poses (issue 32, item 2): the UR5 and the PUMA 560 at elbow, wrist and
shoulder singularities with mixed rational·π angles (2π/7 next to 3π/11 next to 1/3: a number field of degree in the
hundreds) answer exactly, decided by the arm's structure (exact_rank.PointLift) rather than by elimination.

Oracles, independent of kinlib.exact: the 60-digit product of exponentials and SVD (tests/exact_oracle.py), and the
closed-form singular set (kinlib.singularities.singular_configurations, computed once per arm) whose family the
point lies on, checked exactly (the joint value minus the family's base is an integer multiple of its period; a
condition expression is exactly 0). No assertion depends on time; the seconds are `make bench` (singular-poses).
"""

from __future__ import annotations

import warnings

import mpmath
import pytest
import sympy as sp
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import exact_oracle as O
from kinlib import robots
from kinlib.exact import NumericFallbackWarning, Rank, column_space, exact_is_zero, left_null_space, rank_at
from kinlib.exactfield import decide_zero
from kinlib.singularities import K, singular_configurations

R = sp.Rational
pi = sp.pi
SETTINGS = dict(deadline=None, derandomize=True, suppress_health_check=[HealthCheck.too_slow])

# rational multiples of π whose cosines generate large number fields (never a multiple of π/2), and rationals
pi_angle = (
    st.tuples(st.integers(1, 16), st.sampled_from([7, 9, 11, 13, 17]), st.sampled_from([1, -1]))
    .map(lambda a: R(a[2] * a[0], a[1]) * pi)
    .filter(lambda x: not (2 * x / pi).is_Integer)
)
rational_angle = st.tuples(st.integers(1, 5), st.sampled_from([2, 3, 5]), st.sampled_from([1, -1])).map(
    lambda a: R(a[2] * a[0], a[1])
)


@st.composite
def mixed_pose(draw):
    """Six joint values: rational multiples of π with one plain rational among them (a mixed configuration)."""
    q = [draw(pi_angle) for _ in range(6)]
    q[draw(st.integers(0, 5))] = draw(rational_angle)
    return q


multiple_of_pi = st.integers(-2, 2).map(lambda k: k * pi)


def _arms():
    return {
        "stanford": robots.stanford(),
        "ur5": robots.ur5(),
        "puma560": robots.puma560(),
        "puma_no_offsets": robots.puma560(R(2, 5), 0, 0, R(2, 5)),
    }


ARMS = _arms()


#: the closed-form singular sets, computed once per arm (a few seconds each)
SETS: dict = {}


def _singular_set(cache, name):
    if name not in cache:
        arm = ARMS[name]
        cache[name] = singular_configurations(arm.jacobian_space(), arm.thetas)
        assert cache[name].complete
    return cache[name]


def _in_family(value, family) -> bool:
    """value ∈ {b + p k : k ∈ ℤ} (or a union of such), decided exactly."""
    parts = family.args if isinstance(family, sp.Union) else (family,)
    for s in parts:
        if isinstance(s, sp.FiniteSet):  # a prismatic joint's values
            if any((value - x).is_zero for x in s):
                return True
            continue
        expr = s.lamda.expr
        p, b = expr.coeff(K), expr.subs(K, 0)
        if sp.simplify((value - b) / p).is_Integer:
            return True
    return False


def _closed_form_says_singular(conds, thetas, q) -> bool:
    """Some condition of the closed-form singular set holds exactly at q."""
    point = dict(zip(thetas, q))
    for c in conds:
        if isinstance(c, dict):
            if all(_in_family(point[j], fam) for j, fam in c.items()):
                return True
        elif decide_zero(c.xreplace(point)):  # nonzero: certified numerics; zero: exactly
            return True
    return False


def _check_exact_and_right(arm, q, singular_expected: bool, cache, name):
    J = O.space_jacobian(arm.screws, q)
    want = O.rank(J)
    assert want is not None
    Js = arm.jacobian_space()
    with warnings.catch_warnings():
        warnings.simplefilter("error", NumericFallbackWarning)  # the exact engine must not give up
        r = rank_at(Js, q, arm.thetas)
        C = column_space(Js, q, arm.thetas)
        N = left_null_space(Js, q, arm.thetas)
    assert isinstance(r, Rank) and r.exact and not r.unless
    assert r == want, (name, q)
    assert (r < 6) == singular_expected == _closed_form_says_singular(_singular_set(cache, name), arm.thetas, q)
    assert C.shape == (6, r) and N.shape == (6, 6 - r)
    assert not any(e.has(sp.Float) for e in C) and not any(e.has(sp.Float) for e in N)
    with mpmath.workdps(60):
        Cm, Nm = O.to_mp(C), O.to_mp(N)
        U, _S, _ = mpmath.svd_r(J)
        Ur = U[:, :r]
        Q, _ = mpmath.qr(Cm)
        Q = Q[:, :r]
        assert O.max_abs(Q * Q.T - Ur * Ur.T) < mpmath.mpf(10) ** -30  # the same range as the oracle's
        if 6 - r:
            assert O.max_abs(J.T * Nm) < mpmath.mpf(10) ** -30 and O.rank(Nm) == 6 - r


@settings(max_examples=4, **SETTINGS)
@given(st.data())
def test_ur5_on_its_elbow_and_wrist_families(data):
    q = data.draw(mixed_pose())
    which = data.draw(st.sampled_from(["elbow", "wrist", "both"]))
    if which in ("elbow", "both"):
        q[2] = data.draw(multiple_of_pi)  # sin θ3 = 0
    if which in ("wrist", "both"):
        q[4] = data.draw(multiple_of_pi)  # sin θ5 = 0
    _check_exact_and_right(ARMS["ur5"], q, True, SETS, "ur5")


@settings(max_examples=2, **SETTINGS)
@given(st.data())
def test_puma_on_its_wrist_family(data):
    q = data.draw(mixed_pose())
    q[4] = data.draw(multiple_of_pi)
    _check_exact_and_right(ARMS["puma560"], q, True, SETS, "puma560")


@settings(max_examples=3, **SETTINGS)
@given(st.data())
def test_puma_without_offsets_on_elbow_wrist_and_shoulder(data):
    """puma560(L, 0, 0, L): elbow θ3 = π/2 + kπ, wrist θ5 = kπ, shoulder sin(θ2 + θ3) = cos θ2 (θ3 = π/2 − 2θ2:
    θ3 is then as "hard" as θ2, and the shoulder factor decides)."""
    q = data.draw(mixed_pose())
    which = data.draw(st.sampled_from(["elbow", "wrist", "shoulder"]))
    if which == "elbow":
        q[2] = pi / 2 + data.draw(multiple_of_pi)
    elif which == "wrist":
        q[4] = data.draw(multiple_of_pi)
    else:
        q[2] = pi / 2 - 2 * q[1]
    _check_exact_and_right(ARMS["puma_no_offsets"], q, True, SETS, "puma_no_offsets")


@settings(max_examples=3, **SETTINGS)
@given(st.data())
def test_stanford_on_its_wrist_family(data):
    q = data.draw(mixed_pose())
    q[2] = data.draw(rational_angle)  # the prismatic joint: a slide
    q[4] = data.draw(multiple_of_pi)
    _check_exact_and_right(ARMS["stanford"], q, True, SETS, "stanford")


def test_the_same_angles_off_the_singular_set_are_full_rank():
    q = [3 * pi / 11, 2 * pi / 7, 5 * pi / 13, 3 * pi / 11, 2 * pi / 7, R(1, 3)]
    _check_exact_and_right(ARMS["ur5"], q, False, SETS, "ur5")


def test_r07_elbow_a_hair_off_pi_is_full_rank_exactly():
    """UR5 at θ3 = π + 10⁻⁷⁰ with mixed angles: σ_min/σ_max ≈ 3e-72, which a 60-digit SVD calls rank 5. The true
    rank is 6: sin θ3 = −sin 10⁻⁷⁰ ≠ 0 (the elbow factor of the closed-form set, decided exactly), and no other
    factor vanishes there."""
    arm = ARMS["ur5"]
    q = [R(1, 2), 2 * pi / 7, pi + R(1, 10**70), 3, 3 * pi / 11, 1]
    with warnings.catch_warnings():
        warnings.simplefilter("error", NumericFallbackWarning)
        r = rank_at(arm.jacobian_space(), q, arm.thetas)
        N = left_null_space(arm.jacobian_space(), q, arm.thetas)
    assert r == 6 and r.exact and N.shape == (6, 0)
    assert not exact_is_zero(sp.sin(q[2]))  # the elbow factor, exactly nonzero
    with mpmath.workdps(200):  # the oracle at 200 digits sees the small, nonzero singular value
        J = O.space_jacobian(arm.screws, q)
        s = sorted(abs(x) for x in mpmath.svd_r(J, compute_uv=False))
        assert mpmath.mpf(10) ** -75 < s[0] / s[-1] < mpmath.mpf(10) ** -70
    # the same point exactly on the elbow: rank 5, also exact
    q[2] = pi
    r5 = rank_at(arm.jacobian_space(), q, arm.thetas)
    assert r5 == 5 and r5.exact


def test_planar_2r_at_a_large_denominator_with_symbolic_lengths():
    """The 2R arm stretched out (θ2 = π) at θ1 = 12345π/98767, lengths symbolic: rank 1 for all lengths."""
    L1, L2 = sp.symbols("L1 L2", positive=True)
    arm = robots.planar_2r(L1, L2)
    J = arm.jacobian_geometric()[[3, 4], :]
    q = [R(12345, 98767) * pi, pi]
    r = rank_at(J, q, arm.thetas)
    assert r == 1 and r.exact
    N = left_null_space(J, q, arm.thetas)
    assert N.shape == (2, 1)
    Jq = J.xreplace(dict(zip(arm.thetas, q)))
    assert all(decide_zero(e) for e in (N.T * Jq))  # yᵀ J = 0 exactly, for all L1, L2


def test_rank_at_fallback_warns():
    """Out of the exact method's reach (an angle √2), rank_at's 60-digit answer comes with a warning, as the
    bases' do (README: every numeric fallback warns)."""
    arm = robots.planar_2r(1, 2)
    J = arm.jacobian_geometric()[[3, 4], :]
    with pytest.warns(NumericFallbackWarning, match="rank_at"):
        r = rank_at(J, [sp.sqrt(2), 0], arm.thetas)
    assert r == 1 and not r.exact


def test_puma_with_a_symbolic_length_at_elbow_and_shoulder():
    """puma560(L, 0, 0, L) at θ3 = π/2 (elbow and shoulder at once) with mixed angles: rank 4 for every L > 0,
    exact; the oracle agrees at L = 2/5."""
    L = sp.Symbol("L", positive=True)
    arm = robots.puma560(L, 0, 0, L)
    q = [3 * pi / 11, 2 * pi / 7, pi / 2, 5 * pi / 13, 3 * pi / 11, R(1, 3)]
    with warnings.catch_warnings():
        warnings.simplefilter("error", NumericFallbackWarning)
        r = rank_at(arm.jacobian_space(), q, arm.thetas)
        N = left_null_space(arm.jacobian_space(), q, arm.thetas)
    assert r == 4 and r.exact and not r.unless and N.shape == (6, 2)
    assert O.rank(O.space_jacobian(ARMS["puma_no_offsets"].screws, q)) == 4
    Jq = arm.jacobian_space().xreplace(dict(zip(arm.thetas, q)))
    assert all(decide_zero(e) for e in (N.T * Jq))  # yᵀ J = 0 exactly, for all L


# ---------------------------------------------------------------------------------------------------------
# velocity_ellipsoid / force_ellipsoid at singular poses (issue 32: each spent its whole 60 s budget)
# ---------------------------------------------------------------------------------------------------------
def _mp_svd(M):
    """Independent oracle: singular values and left singular vectors of M from a 60-digit mpmath SVD of sp.N
    values (no kinlib code)."""
    ctx = mpmath.mp.clone()
    ctx.dps = 60
    X = ctx.matrix([[ctx.mpf(str(sp.N(e, 70))) for e in M.row(i)] for i in range(M.rows)])
    U, S, _ = ctx.svd_r(X)
    return [S[i] for i in range(min(M.shape))], U, ctx


_PUMA0 = robots.puma560(R(2, 5), 0, 0, R(2, 5))


@settings(max_examples=3, **SETTINGS)
@given(
    st.sampled_from(["ur5_elbow", "ur5_wrist", "puma0_elbow"]),
    # denominators whose sines SymPy keeps as sin(kπ/q) (π/5, π/12 ... become radicals: not this path, see below)
    st.lists(st.tuples(st.integers(1, 12), st.sampled_from([7, 9, 11, 13])), min_size=5, max_size=5),
)
def test_velocity_ellipsoid_at_singular_poses(family, frac):
    """Random rational·π angles on UR5/PUMA singular families: semi-axes right to 40 digits against a 60-digit
    mpmath SVD, directions spanning the same lines, zero axes exactly 0 where the rank drops; exact (no Float, no
    warning) when the linear rows have rank ≤ 1, else 60-digit Floats with a NumericFallbackWarning."""
    from kinlib.manipulability import velocity_ellipsoid
    from kinlib.taskspace import task_rows
    from kinlib.velocity import force_ellipsoid

    a = [R(p, q) * sp.pi for p, q in frac]
    chain, q = {
        "ur5_elbow": (robots.ur5(), [a[0], a[1], sp.pi, a[2], a[3], a[4]]),
        "ur5_wrist": (robots.ur5(), [a[0], a[1], a[2], a[3], 0, a[4]]),
        "puma0_elbow": (_PUMA0, [a[0], a[1], sp.pi / 2, a[2], a[3], a[4]]),
    }[family]
    J = chain.jacobian_space().subs(dict(zip(chain.thetas, q)))
    M = task_rows(J, "linear")
    s, U, ctx = _mp_svd(M)
    rank = sum(1 for x in s if x > ctx.mpf(10) ** -40 * s[0])
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        lengths, D = velocity_ellipsoid(J, time_budget=30)
        flengths, _ = force_ellipsoid(J, time_budget=30)
    fell_back = any(issubclass(w.category, NumericFallbackWarning) for w in caught)
    exact = not fell_back and not any(e.has(sp.Float) for e in [*lengths, *D])
    if rank <= 1:
        assert exact
    else:
        assert fell_back  # no closed form in reach: stated precision, said so
    assert all(x == 0 for x in lengths[rank:]) and all(x == sp.oo for x in flengths[rank:])
    with ctx.workdps(60):
        for i in range(rank):
            got = ctx.mpf(str(sp.N(lengths[i], 60)))
            assert abs(got - s[i]) < ctx.mpf(10) ** -40 * s[0]
            assert abs(ctx.mpf(str(sp.N(flengths[i], 60))) * s[i] - 1) < ctx.mpf(10) ** -35
            u = [ctx.mpf(str(sp.N(D[r, i], 60))) for r in range(3)]
            dot = ctx.fsum(u[r] * U[r, i] for r in range(3))
            assert abs(abs(dot) - 1) < ctx.mpf(10) ** -30  # the same line (signs are free)


def test_rank_of_a_zero_column_computed_as_noise():
    """issue 32: the PUMA (no offsets) at its elbow singularity: its linear rows have rank 1 (a 60-digit SVD: 0.4,
    then values below 1e-100); a minor of a column that is 0 exactly, computed as 1e-102, was certified nonzero
    against a bound made of that column's own noise (rank 3)."""
    from kinlib.taskspace import task_rows

    h = [3 * sp.pi / 11, 2 * sp.pi / 7, 5 * sp.pi / 13, 3 * sp.pi / 11, 2 * sp.pi / 7]
    J = _PUMA0.jacobian_space().subs(dict(zip(_PUMA0.thetas, [h[0], h[1], sp.pi / 2, h[2], h[3], h[4]])))
    M = task_rows(J, "linear")
    s, _, ctx = _mp_svd(M)
    assert s[0] > 0.1 and all(x < ctx.mpf(10) ** -50 for x in s[1:])
    r = rank_at(M)
    assert int(r) == 1 and r.exact
