"""Numerics at the edges (issue 25): log3/log6 on both sides of π and near 0, exp6 at small angles, the
condition number and isotropy without a hidden cut-off; against the 60-digit oracle (tests/exact_oracle.py)."""

from __future__ import annotations

import mpmath
import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

import exact_oracle as oracle
from helpers import FAST
from kinlib import condition_number, exp3, exp6, isotropy, log3, log6

EPS = np.finfo(float).eps
DELTAS = ["1e-16", "1e-15", "1e-14", "1e-12", "1e-8", "1e-4"]


def _unit(v):
    with mpmath.workdps(80):
        v = [mpmath.mpf(x) for x in v]
        n = mpmath.sqrt(sum(x * x for x in v))
        return [x / n for x in v]


def _T(w, v, theta):
    """(the float transform e^{[S]θ} rounded from 60 digits, its 60-digit value) for S = [w; v]."""
    X = oracle.exp6(list(w) + list(v), theta)
    return np.array([[float(X[i, j]) for j in range(4)] for i in range(4)]), X


AXES = [(0, 0, -1), (0, 0, 1), (0, -1, 0), (1, 0, 0), (0.3, -0.5, 0.8), (-1, 2, -2)]


@pytest.mark.parametrize("axis", AXES)
@pytest.mark.parametrize("delta", DELTAS)
@pytest.mark.parametrize("side", [-1, 1])
def test_log3_on_both_sides_of_pi(axis, delta, side):
    """A rotation by π ∓ δ about ω: log3 returns the branch that reproduces R to rounding (the −z branch for
    π − 1e-14 about −z), and when δ is above rounding the exponential coordinates themselves."""
    w = _unit(axis)
    with mpmath.workdps(80):
        theta = mpmath.pi + side * mpmath.mpf(delta)
        R, _ = _T(w, [0, 0, 0], theta)
        R = R[:3, :3]
        # the logarithm in [0, π]: π + δ about ω is π − δ about −ω
        want = [x * theta for x in w] if side < 0 else [-x * (2 * mpmath.pi - theta) for x in w]
    vec = log3(R, "vector")
    ax, th = log3(R, "axis_angle")
    assert np.abs(exp3(ax, th) - R).max() <= 4 * EPS
    if mpmath.mpf(delta) > 1e-14:  # above rounding: the right branch, to a few ulps
        assert np.abs(vec - np.array([float(x) for x in want])).max() <= 8 * EPS * np.pi


@pytest.mark.parametrize("axis", AXES)
@pytest.mark.parametrize("theta", ["1e-300", "1e-16", "1e-12", "1e-8", "1e-4", "0.5"])
def test_log3_near_zero(axis, theta):
    w = _unit(axis)
    R, _ = _T(w, [0, 0, 0], theta)
    vec = log3(R[:3, :3], "vector")
    want = np.array([float(x * mpmath.mpf(theta)) for x in w])
    assert np.abs(vec - want).max() <= 4 * EPS * float(theta)


@pytest.mark.parametrize("axis", AXES[:4])
@pytest.mark.parametrize("theta", ["1e-12", "1e-6", "0.5", "pi-1e-14", "pi-1e-10", "pi+1e-14", "pi+1e-8"])
def test_log6_at_the_edges(axis, theta):
    """log6 of a screw motion (|v| ≈ 1.4 m) near 0 and on both sides of π: exp6(log6 T) = T to rounding."""
    w = _unit(axis)
    with mpmath.workdps(80):
        th = mpmath.pi + mpmath.mpf(theta[2:]) if theta.startswith("pi") else mpmath.mpf(theta)
        q = [mpmath.mpf("0.7"), mpmath.mpf("-1.1"), mpmath.mpf("0.4")]
        v = [-(w[1] * q[2] - w[2] * q[1]), -(w[2] * q[0] - w[0] * q[2]), -(w[0] * q[1] - w[1] * q[0])]
        v = [a + mpmath.mpf("0.1") * b for a, b in zip(v, w)]  # pitch 0.1
    T, _ = _T(w, v, th)
    S, ang = log6(T, "screw_angle")
    back = exp6(S, ang)
    assert np.abs(back - T).max() <= 16 * EPS * (1 + np.abs(T[:3, 3]).max())
    if float(th) < np.pi - 1e-12:  # unique logarithm: the screw itself
        assert np.abs(S - np.array([float(x) for x in list(w) + list(v)])).max() <= 1e-12


def test_exp6_small_angle_large_translation():
    """θ = 1e-8 with a 1.4 m translation (v ≈ 1.4e8): 1 − cos θ and θ − sin θ by their series, not by cancellation."""
    w = _unit([0.2, -0.4, 0.9])
    with mpmath.workdps(80):
        v = [mpmath.mpf("1.4e8") * x for x in _unit([1, 2, -0.5])]
    T, X = _T(w, v, "1e-8")
    got = exp6([float(x) for x in w] + [float(x) for x in v], 1e-8)
    err = max(abs(mpmath.mpf(got[i, j]) - X[i, j]) for i in range(3) for j in range(4))
    assert err <= 4 * EPS * 1.4, float(err)


@FAST
@given(
    seed=st.integers(0, 2**32 - 1),
    logtheta=st.floats(min_value=-12.0, max_value=0.5),
    sign=st.sampled_from([-1, 1]),
    scale=st.floats(min_value=0.0, max_value=9.0),
)
def test_exp6_matches_60_digits_at_small_angles(seed, logtheta, sign, scale):
    """Random screws with |v| up to 1e9 at angles 1e-12 … 3: every entry within a few ulps of the 60-digit value."""
    rng = np.random.default_rng(seed)
    w = rng.normal(size=3)
    w /= np.linalg.norm(w)
    v = rng.normal(size=3) * 10.0**scale
    theta = sign * 10.0**logtheta
    got = exp6(np.concatenate([w, v]), theta)
    X = oracle.exp6([repr(float(x)) for x in w] + [repr(float(x)) for x in v], repr(float(theta)))
    p_scale = max(abs(theta) * np.linalg.norm(v), 1.0)
    err_R = max(abs(mpmath.mpf(got[i, j]) - X[i, j]) for i in range(3) for j in range(3))
    err_p = max(abs(mpmath.mpf(got[i, 3]) - X[i, 3]) for i in range(3))
    assert err_R <= 8 * EPS and err_p <= 16 * EPS * p_scale, (float(err_R), float(err_p))


@FAST
@given(seed=st.integers(0, 2**32 - 1), delta=st.floats(min_value=-1e-9, max_value=1e-9))
def test_log3_random_rotations_near_pi(seed, delta):
    rng = np.random.default_rng(seed)
    w = rng.normal(size=3)
    w /= np.linalg.norm(w)
    R, _ = _T([repr(float(x)) for x in w], [0, 0, 0], mpmath.pi + mpmath.mpf(repr(delta)))
    ax, th = log3(R[:3, :3], "axis_angle")
    assert 0 <= th <= np.pi and np.abs(exp3(ax, th) - R[:3, :3]).max() <= 8 * EPS


# --- condition number and isotropy: no hidden cut-off ------------------------------------------------
def test_condition_number_without_cut_off():
    for J in (
        np.diag([1.0, 1e-12]),
        np.diag([1e300, 1.0]),
        np.diag([1.0, 1e-200]),
        np.array([[1.0, 1.0], [1.0, 1 + 2**-52]]),
    ):
        assert condition_number(J) == pytest.approx(
            np.linalg.svd(J, compute_uv=False)[0] / np.linalg.svd(J, compute_uv=False)[-1]
        )
        assert isotropy(J) == pytest.approx(1 / condition_number(J))
    assert condition_number(np.diag([1.0, 1e-12])) == pytest.approx(1e12) == np.linalg.cond(np.diag([1.0, 1e-12]))
    assert condition_number(np.diag([1e300, 1.0])) == pytest.approx(1e300)
    assert isotropy(np.diag([1e300, 1.0])) == pytest.approx(1e-300)


def test_condition_number_is_infinite_exactly_at_exact_singularity(rng):
    """Integer matrices of rank r < k (B·C): exactly singular → ∞ and 0; of rank k − 1 nudged by one ulp: finite."""
    for m, n, r in [(2, 2, 1), (3, 3, 2), (6, 7, 5), (3, 6, 1)]:
        A = rng.integers(-5, 6, (m, r)).astype(float) @ rng.integers(-5, 6, (r, n)).astype(float)
        assert condition_number(A) == np.inf and isotropy(A) == 0.0
        batch = np.stack([A, np.eye(m, n)])
        assert condition_number(batch).tolist() == [np.inf, 1.0]
        if r < min(m, n) - 1:
            continue  # one nudged entry raises the rank by one at most
        B = A.copy()
        B[0, 0] = np.nextafter(B[0, 0], np.inf) if B[0, 0] else 2**-40
        assert np.isfinite(condition_number(B)) and isotropy(B) > 0
    assert condition_number(np.zeros((2, 3))) == np.inf and isotropy(np.zeros((2, 3))) == 0.0


def test_condition_number_at_a_float_singularity_agrees_with_numpy():
    """θ2 = np.pi is singular only up to rounding (sin θ2 = 1.2e-16): a large finite κ, as numpy.linalg.cond."""
    from kinlib import robots

    J = robots.planar_2r(1, 1).jacobian_geometric([0.3, np.pi])[[3, 4]]
    assert condition_number(J) == pytest.approx(np.linalg.cond(J)) and condition_number(J) > 1e14
