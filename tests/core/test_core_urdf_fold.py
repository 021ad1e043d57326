"""The generated code of URDF arms (issue 25, item 3): the placements folded into floats give the exact chain's
T, J_s and geometric J to ~1e-12 (60-digit oracle), for random URDF-like arms (random rpy, typed right angles,
xyz, axes, fixed joints, tools); placements that disagree with the chain are refused."""

from __future__ import annotations

import mpmath
import numpy as np
import pytest
import sympy as sp

import exact_oracle as oracle
from kinlib import robots
from kinlib.chains import SerialChain

RIGHT = [0.0, 1.5707963267948966, -1.5707963267948966, 3.141592653589793, 1.57079632679]
AXES = [(0, 0, 1), (0, 1, 0), (1, 0, 0), (0, 0, -1), (0, -1, 0)]


def _random_urdf(rng, n):
    joints = []
    for _ in range(n):
        if rng.random() < 0.25:  # a fixed placement between two joints
            joints.append(("fixed", _xyz(rng), _rpy(rng), None))
        kind = "prismatic" if rng.random() < 0.15 else "revolute"
        axis = AXES[rng.integers(len(AXES))] if rng.random() < 0.8 else tuple(np.round(rng.normal(size=3), 3))
        joints.append((kind, _xyz(rng), _rpy(rng), axis))
    tool = (_xyz(rng), _rpy(rng))
    return joints, tool


def _xyz(rng):
    return tuple(float(x) if rng.random() < 0.6 else 0.0 for x in np.round(rng.uniform(-0.5, 0.5, 3), 4))


def _rpy(rng):
    return tuple(
        RIGHT[rng.integers(len(RIGHT))] if rng.random() < 0.7 else round(float(rng.uniform(-3, 3)), 6) for _ in range(3)
    )


def _mp_array(X):
    return np.array([[float(X[i, j]) for j in range(X.cols)] for i in range(X.rows)])


@pytest.mark.parametrize("seed", range(4))
def test_folded_code_equals_the_exact_chain(seed):
    rng = np.random.default_rng(seed)
    joints, tool = _random_urdf(rng, int(rng.integers(2, 8)))
    chain = robots.from_urdf_joints(joints, tool, name=f"random{seed}")
    n = chain.n
    for _ in range(3):
        q = rng.uniform(-np.pi, np.pi, n)
        T = oracle.fk(chain.screws, chain.M, q)
        Js = oracle.space_jacobian(chain.screws, q)
        with mpmath.workdps(75):
            p = [T[0, 3], T[1, 3], T[2, 3]]
            Jg = Js.copy()
            for j in range(n):
                w = [Js[0, j], Js[1, j], Js[2, j]]
                # ṗ = v + ω × p (the tool origin's velocity from the space twist)
                Jg[3, j] = Js[3, j] + w[1] * p[2] - w[2] * p[1]
                Jg[4, j] = Js[4, j] + w[2] * p[0] - w[0] * p[2]
                Jg[5, j] = Js[5, j] + w[0] * p[1] - w[1] * p[0]
        for got, want in ((chain.fk(q), T), (chain.jacobian_space(q), Js), (chain.jacobian_geometric(q), Jg)):
            want = _mp_array(want)
            assert np.abs(got - want).max() <= 1e-12 * max(1.0, np.abs(want).max())
        batch = chain.jacobian_geometric(np.stack([q, q]))
        assert np.allclose(batch[0], chain.jacobian_geometric(q), atol=1e-13)


def test_placements_that_disagree_are_refused():
    arm = robots.from_urdf_joints(
        [("revolute", (0, 0, 0.1), (0, 0, 0), (0, 0, 1)), ("revolute", (0, 0, 0.2), (sp.pi / 2, 0, 0), (0, 0, 1))],
        tool=((0, 0, 0.3), (0, 0, 0)),
    )
    C, axes = arm._placements
    with pytest.raises(ValueError, match="placements disagree with screws"):
        SerialChain(arm.M, arm.screws, placements=(C, [axes[0], sp.Matrix([1, 0, 0])]))
    with pytest.raises(ValueError, match="placements disagree with M"):
        SerialChain(arm.M, arm.screws, placements=(C[:2] + [sp.eye(4)], axes))
    with pytest.raises(ValueError, match="placements must be"):
        SerialChain(arm.M, arm.screws, placements=(C[:2], axes))
