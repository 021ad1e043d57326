"""The computed answers of problem set sections 4-6 (notebooks 04-06), pinned.

Where the printed solution disagrees with computation, the computed result is pinned here and the
notebook shows both: 6.2's Jᵀ J (eq. 60) and V·V (eq. 61) miss a +1 in the (1, 1) entry. 5.1's printed
"θ2 = 0.5 sin⁻¹(−1)" (eq. 44) is one branch of the family pinned below.
"""

from __future__ import annotations

import numpy as np
import sympy as sp

from kinlib import robots
from kinlib.manipulability import manipulability, strongest_joints, twist_speed, twist_speed_form
from kinlib.singularities import (
    K,
    column_space,
    evaluate_at,
    left_null_space,
    rank_at,
    representatives,
    singular_configurations,
    task_rows,
)

pi = sp.pi


def test_4_1_contributions_and_choices():
    arm = robots.planar_3r()
    L1, L2, L3 = arm.params
    L = sp.Symbol("L", positive=True)
    Jp = task_rows(arm.jacobian_geometric(), ["vx", "vy"]).subs({L1: L, L2: L, L3: L}) / L
    cases = {
        "a": ([-pi / 8, pi / 4, pi / 8], 0, [-0.70711, -1.08979, -0.70711], 2),
        "b": ([3 * pi / 4, -pi / 4, 0], 0, [-2.70711, -2.0, -1.0], 1),
        "c": ([pi / 2, -pi / 8, -pi / 2], 1, [1.30656, 1.30656, 0.92388], (1, 2)),
    }
    for q, row, numbers, choice in cases.values():
        vals = evaluate_at(Jp, q, arm.thetas)[row, :]
        assert np.allclose([float(v) for v in vals], numbers, atol=1e-5)
        assert strongest_joints(vals) == choice
    # the tie is exact: the columns differ by L1 cos θ1
    Jfull = task_rows(arm.jacobian_geometric(), ["vy"])
    assert sp.simplify(Jfull[0, 0] - Jfull[0, 1] - L1 * sp.cos(arm.thetas[0])) == 0


def test_strongest_joints_numeric_and_bad_input():
    assert strongest_joints([0.1, -0.5, 0.3]) == 2
    assert strongest_joints(np.array([1.0, -1.0, 0.2])) == (1, 2)
    assert strongest_joints(sp.Matrix([[sp.sqrt(2), -sp.sqrt(2), 1]])) == (1, 2)
    import pytest

    with pytest.raises(ValueError, match="real numbers"):
        strongest_joints(sp.Matrix([[sp.Symbol("x"), 1]]))
    with pytest.raises(TypeError, match="row must be"):
        strongest_joints("123")


def test_5_1_singular_family():
    r = robots.planar_offset_3r()
    conds = singular_configurations(task_rows(r.jacobian_space(), "planar"), r.thetas)
    th2 = r.thetas[1]
    assert conds == [{th2: sp.ImageSet(sp.Lambda(K, pi * K - pi / 4), sp.Integers)}]
    assert representatives(conds[0][th2], -pi, pi) == [-pi / 4, 3 * pi / 4]


def test_5_3_rank_and_directions():
    r = robots.planar_offset_3r()
    J = task_rows(r.jacobian_space(), "planar")
    q = [pi / 4, -pi / 4, pi / 4]
    assert rank_at(J, q, r.thetas) == 2
    assert column_space(J, q, r.thetas) == sp.Matrix([[1, 0], [0, 1], [0, -1]])
    assert left_null_space(J, q, r.thetas) == sp.Matrix([0, 1, 1])


def test_5_4_manipulability_and_maximizers():
    r = robots.planar_offset_3r()
    (L,) = r.params
    th2 = r.thetas[1]
    w = manipulability(task_rows(r.jacobian_space(), "planar"), simplify=True)
    assert w == L**2 * sp.sqrt(sp.sin(2 * th2) + 1)
    assert sp.solveset(sp.sin(2 * th2) - 1, th2, sp.Interval.Ropen(0, 2 * pi)) == sp.FiniteSet(pi / 4, 5 * pi / 4)


def test_5_5_rpp_has_identity_gram():
    p = robots.planar_rpp()
    J = task_rows(p.jacobian_space(), "planar")
    assert (J * J.T).applyfunc(sp.trigsimp) == sp.eye(3)
    assert singular_configurations(J, p.thetas) == []


def test_6_1_and_6_2_computed_not_printed():
    r = robots.spatial_rppr()
    L1, L2 = r.params
    th3 = r.thetas[2]
    J = r.jacobian_geometric()
    assert singular_configurations(J, r.thetas) == []
    G = twist_speed_form(J, simplify=True)
    assert (G - sp.diag(1 + (L2 + th3) ** 2, 1, 1, 1)).applyfunc(sp.expand).is_zero_matrix
    printed_60 = sp.diag((L2 + th3) ** 2, 1, 1, 1)
    assert not (G - printed_60).applyfunc(sp.expand).is_zero_matrix
    qd = sp.symbols("thetadot1:5", real=True)
    VV = twist_speed(J, qd, simplify=True)
    assert sp.expand(VV - ((1 + (L2 + th3) ** 2) * qd[0] ** 2 + qd[1] ** 2 + qd[2] ** 2 + qd[3] ** 2)) == 0
