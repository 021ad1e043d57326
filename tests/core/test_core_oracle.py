"""kinlib against the modern_robotics package (Lynch & Park's own code) as an oracle.

Random arms (revolute and prismatic joints, 1–7 joints, random axes, points and home poses) at
random configurations, to 1e-9: exp6, FK (space and body forms), the space and body Jacobians,
both through the free functions and through SerialChain's generated fast path (single and batched),
and the UR5 of Modern Robotics Example 4.5 at the book's pose.
"""

from __future__ import annotations

import modern_robotics as mr
import numpy as np
import pytest
import sympy as sp

import kinlib
from helpers import random_arm, random_thetas
from kinlib import robots

TOL = 1e-9
SEEDS = range(6)
NJOINTS = range(1, 8)


def _arm(seed, n, kinds=None):
    rng = np.random.default_rng(1000 * n + seed)
    M, S, kinds = random_arm(rng, n, kinds)
    return rng, M, S, kinds


def _mr_body(M, S):
    return mr.Adjoint(mr.TransInv(M)) @ S


@pytest.mark.parametrize("seed", range(20))
def test_exp6_matches_mr(seed):
    rng = np.random.default_rng(seed)
    kind = "R" if seed % 3 else "P"
    _, S, _ = random_arm(rng, 1, kind)
    S = S[:, 0]
    theta = rng.uniform(-2 * np.pi, 2 * np.pi)
    expected = mr.MatrixExp6(mr.VecTose3(S * theta))
    np.testing.assert_allclose(kinlib.exp6(S, theta), expected, atol=TOL, rtol=0)
    # exp3 against mr.MatrixExp3 for the rotation part
    if kind == "R":
        np.testing.assert_allclose(
            kinlib.exp3(S[:3], theta), mr.MatrixExp3(mr.VecToso3(S[:3] * theta)), atol=TOL, rtol=0
        )


@pytest.mark.parametrize("n", NJOINTS)
@pytest.mark.parametrize("seed", SEEDS)
def test_free_functions_match_mr(seed, n):
    """fk_space, fk_body, jacobian_space, jacobian_body on a random arm at random configurations."""
    rng, M, S, kinds = _arm(seed, n)
    B = _mr_body(M, S)
    for th in random_thetas(rng, kinds, size=3):
        T = mr.FKinSpace(M, S, th)
        np.testing.assert_allclose(kinlib.fk_space(M, S, th), T, atol=TOL, rtol=0)
        np.testing.assert_allclose(kinlib.fk_body(M, B, th), mr.FKinBody(M, B, th), atol=TOL, rtol=0)
        np.testing.assert_allclose(kinlib.fk_body(M, B, th), T, atol=TOL, rtol=0)
        Js = mr.JacobianSpace(S, th)
        np.testing.assert_allclose(kinlib.jacobian_space(S, th), Js, atol=TOL, rtol=0)
        np.testing.assert_allclose(kinlib.jacobian_body(B, th), mr.JacobianBody(B, th), atol=TOL, rtol=0)
        # the geometric Jacobian from mr's pieces: [ω_s; ṗ] = blockdiag(R, R) J_b
        R = T[:3, :3]
        Jg = np.vstack([R @ mr.JacobianBody(B, th)[:3], R @ mr.JacobianBody(B, th)[3:]])
        np.testing.assert_allclose(kinlib.geometric_jacobian(M, S, th), Jg, atol=TOL, rtol=0)
        # the sequence-of-6-vectors form of Slist gives the same
        np.testing.assert_allclose(kinlib.jacobian_space(list(S.T), list(th)), Js, atol=TOL, rtol=0)


# each chain compiles its own code (dense float arms take ~0.5 s per joint count): fewer seeds for long arms;
# the 7-joint chain is covered by test_all_revolute_and_all_prismatic_arms
@pytest.mark.parametrize("seed, n", [(s, n) for n in range(1, 5) for s in range(2)] + [(0, 5), (0, 6)])
def test_chain_fast_path_matches_mr(seed, n):
    """SerialChain built from float M and screws: generated code, single configurations and a batch."""
    rng, M, S, kinds = _arm(seed, n)
    chain = kinlib.SerialChain(M, S, name=f"random{n}")
    assert chain.joint_types == kinds
    assert chain.params == ()
    B = _mr_body(M, S)
    np.testing.assert_allclose(np.array(chain.body_screws, dtype=float), B, atol=TOL, rtol=0)
    Q = random_thetas(rng, kinds, size=5)
    fk, js, jb, jg = chain.fk(Q), chain.jacobian_space(Q), chain.jacobian_body(Q), chain.jacobian_geometric(Q)
    assert fk.shape == (5, 4, 4) and js.shape == jb.shape == jg.shape == (5, 6, n)
    for k, th in enumerate(Q):
        T = mr.FKinSpace(M, S, th)
        Jb = mr.JacobianBody(B, th)
        Jg = np.vstack([T[:3, :3] @ Jb[:3], T[:3, :3] @ Jb[3:]])
        for got_single, got_batch, want in [
            (chain.fk(th), fk[k], T),
            (chain.jacobian_space(th), js[k], mr.JacobianSpace(S, th)),
            (chain.jacobian_body(th), jb[k], Jb),
            (chain.jacobian_geometric(th), jg[k], Jg),
        ]:
            assert isinstance(got_single, np.ndarray) and got_single.dtype == float
            np.testing.assert_allclose(got_single, want, atol=TOL, rtol=0)
            np.testing.assert_allclose(got_batch, want, atol=TOL, rtol=0)


@pytest.mark.parametrize("kinds", ["RRRRRRR", "PPP", "RPRPRP", "P", "R"])
def test_all_revolute_and_all_prismatic_arms(kinds):
    rng, M, S, kinds = _arm(7, len(kinds), kinds)
    chain = kinlib.SerialChain(M, S)
    for th in random_thetas(rng, kinds, size=2):
        np.testing.assert_allclose(kinlib.fk_space(M, S, th), mr.FKinSpace(M, S, th), atol=TOL, rtol=0)
        np.testing.assert_allclose(kinlib.jacobian_space(S, th), mr.JacobianSpace(S, th), atol=TOL, rtol=0)
        np.testing.assert_allclose(chain.jacobian_space(th), mr.JacobianSpace(S, th), atol=TOL, rtol=0)
        np.testing.assert_allclose(chain.jacobian_body(th), mr.JacobianBody(_mr_body(M, S), th), atol=TOL, rtol=0)


@pytest.mark.parametrize("seed", range(8))
def test_adjoint_trans_inv_match_mr(seed):
    rng = np.random.default_rng(seed)
    M, S, _ = random_arm(rng, 1, "R")
    np.testing.assert_allclose(kinlib.adjoint(M), mr.Adjoint(M), atol=TOL, rtol=0)
    np.testing.assert_allclose(kinlib.trans_inv(M), mr.TransInv(M), atol=TOL, rtol=0)
    R, p = kinlib.trans_to_rp(M)
    Rm, pm = mr.TransToRp(M)
    np.testing.assert_allclose(R, Rm, atol=TOL, rtol=0)
    np.testing.assert_allclose(p, pm, atol=TOL, rtol=0)
    np.testing.assert_allclose(kinlib.rp_to_trans(R, p), mr.RpToTrans(Rm, pm), atol=TOL, rtol=0)
    np.testing.assert_allclose(kinlib.skew(S[:3, 0]), mr.VecToso3(S[:3, 0]), atol=TOL, rtol=0)
    np.testing.assert_allclose(kinlib.bracket(S[:, 0]), mr.VecTose3(S[:, 0]), atol=TOL, rtol=0)
    np.testing.assert_allclose(kinlib.unbracket(mr.VecTose3(S[:, 0])), S[:, 0], atol=TOL, rtol=0)
    # screw_axis (pitch h) against mr.ScrewToAxis
    q, s, h = rng.normal(size=3), S[:3, 0], rng.normal()
    np.testing.assert_allclose(kinlib.screw_axis(q, s, h), mr.ScrewToAxis(q, s, h), atol=TOL, rtol=0)
    np.testing.assert_allclose(kinlib.screw_revolute(s, q), mr.ScrewToAxis(q, s, 0), atol=TOL, rtol=0)


# --------------------------------------------------------------------------------------------
# UR5, Modern Robotics Example 4.5
# --------------------------------------------------------------------------------------------
W1, W2, L1, L2, H1, H2 = 0.109, 0.082, 0.425, 0.392, 0.089, 0.095
UR5_M = np.array([[-1, 0, 0, L1 + L2], [0, 0, 1, W1 + W2], [0, 1, 0, H1 - H2], [0, 0, 0, 1]], dtype=float)
UR5_S = np.array(
    [
        [0, 0, 1, 0, 0, 0],
        [0, 1, 0, -H1, 0, 0],
        [0, 1, 0, -H1, 0, L1],
        [0, 1, 0, -H1, 0, L1 + L2],
        [0, 0, -1, -W1, L1 + L2, 0],
        [0, 1, 0, H2 - H1, 0, L1 + L2],
    ],
    dtype=float,
).T
BOOK_POSE = [0, -np.pi / 2, 0, 0, np.pi / 2, 0]  # Example 4.5: θ2 = −π/2, θ5 = π/2, others 0
BOOK_T = np.array([[0, -1, 0, 0.095], [1, 0, 0, 0.109], [0, 0, 1, 0.988], [0, 0, 0, 1]])


@pytest.fixture(scope="module")
def ur5():
    return robots.ur5()


def test_ur5_is_the_books_arm(ur5):
    np.testing.assert_allclose(np.array(ur5.M, dtype=float), UR5_M, atol=1e-15)
    np.testing.assert_allclose(np.array(ur5.screws, dtype=float), UR5_S, atol=1e-15)
    assert ur5.joint_types == "RRRRRR"


def test_ur5_book_pose(ur5):
    """Example 4.5's printed T(θ), against mr and kinlib (numeric, fast path and exact)."""
    np.testing.assert_allclose(mr.FKinSpace(UR5_M, UR5_S, BOOK_POSE), BOOK_T, atol=1e-12)
    np.testing.assert_allclose(ur5.fk(BOOK_POSE), BOOK_T, atol=1e-12)
    np.testing.assert_allclose(kinlib.fk_space(UR5_M, UR5_S, BOOK_POSE), BOOK_T, atol=1e-12)
    exact = ur5.fk([0, -sp.pi / 2, 0, 0, sp.pi / 2, 0])
    assert exact == sp.Matrix(
        [
            [0, -1, 0, sp.Rational("0.095")],
            [1, 0, 0, sp.Rational("0.109")],
            [0, 0, 1, sp.Rational("0.988")],
            [0, 0, 0, 1],
        ]
    )


@pytest.mark.parametrize("pose", [BOOK_POSE, [0.3, -1.1, 0.7, 0.2, 1.4, -0.5], [0.0] * 6])
def test_ur5_jacobians_match_mr(ur5, pose):
    B = _mr_body(UR5_M, UR5_S)
    Js, Jb = mr.JacobianSpace(UR5_S, pose), mr.JacobianBody(B, pose)
    T = mr.FKinSpace(UR5_M, UR5_S, pose)
    Jg = np.vstack([T[:3, :3] @ Jb[:3], T[:3, :3] @ Jb[3:]])
    np.testing.assert_allclose(ur5.jacobian_space(pose), Js, atol=TOL, rtol=0)
    np.testing.assert_allclose(ur5.jacobian_body(pose), Jb, atol=TOL, rtol=0)
    np.testing.assert_allclose(ur5.jacobian_geometric(pose), Jg, atol=TOL, rtol=0)
    np.testing.assert_allclose(kinlib.jacobian_space(UR5_S, pose), Js, atol=TOL, rtol=0)
    np.testing.assert_allclose(kinlib.jacobian_body(B, pose), Jb, atol=TOL, rtol=0)
    # batched, the same pose three times among others
    Q = np.array([pose, BOOK_POSE, pose])
    np.testing.assert_allclose(ur5.jacobian_space(Q)[[0, 2]], np.stack([Js, Js]), atol=TOL, rtol=0)
    np.testing.assert_allclose(ur5.fk(Q)[1], BOOK_T, atol=1e-12)


def test_ur5_exact_jacobian_at_book_pose_matches_mr(ur5):
    q = [0, -sp.pi / 2, 0, 0, sp.pi / 2, 0]
    Js = ur5.jacobian_space(q)
    assert isinstance(Js, sp.MatrixBase) and not Js.atoms(sp.Float)
    np.testing.assert_allclose(
        np.array(Js.evalf(), dtype=float), mr.JacobianSpace(UR5_S, BOOK_POSE), atol=1e-12, rtol=0
    )


def test_ur5_symbolic_lengths_screws_from_axes():
    """ur5 with symbolic lengths: each S_i = [ω_i; −ω_i × q_i] from the book's joint axes and points."""
    w1, w2, l1, l2, h1, h2 = syms = sp.symbols("W1 W2 L1 L2 H1 H2", positive=True)
    r = robots.ur5(*syms)
    axes = [(0, 0, 1), (0, 1, 0), (0, 1, 0), (0, 1, 0), (0, 0, -1), (0, 1, 0)]
    points = [(0, 0, 0), (0, 0, h1), (l1, 0, h1), (l1 + l2, 0, h1), (l1 + l2, w1, 0), (l1 + l2, 0, h1 - h2)]
    for i, (w, q) in enumerate(zip(axes, points)):
        w, q = sp.Matrix(w), sp.Matrix(q)
        assert sp.expand(r.screws[:, i] - sp.Matrix.vstack(w, -w.cross(q))) == sp.zeros(6, 1), f"S{i + 1}"
    assert r.M == sp.Matrix([[-1, 0, 0, l1 + l2], [0, 0, 1, w1 + w2], [0, 1, 0, h1 - h2], [0, 0, 0, 1]])
