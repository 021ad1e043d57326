"""Issue 11, item 6: the first numeric call of a student's own arm is quick, and right.

Arms built with ``robots.from_urdf_joints`` from URDF joint placements with realistic float numbers
(an SO-101-like 6R arm with rpy such as 1.5708 and -3.14159 and lengths like 0.0388353; a
Baxter-like 7R arm on a fixed 45° mount with its joints' rpy ±1.57079632679; a 7-joint arm with
prismatic joints and tilted, non-unit axes) are checked against modern_robotics on chains built
independently from the same URDF numbers with NumPy. No test asserts a wall-clock time: the guards
are that a numeric call builds no symbolic matrix, and operation counts of the generated code.
"""

from __future__ import annotations

import ast
import math

import modern_robotics as mr
import mpmath
import numpy as np
import pytest
import sympy as sp
from hypothesis import given, settings
from hypothesis import strategies as st

from kinlib import robots
from kinlib.robots import from_urdf_joints
from kinlib.tape import Tape, TapeValue

SO101 = [
    ("revolute", (0.0388353, -8.97657e-09, 0.0624), (3.14159, 4.18253e-17, -3.14159), (0, 0, 1)),
    ("revolute", (-0.0303992, -0.0182778, -0.0542), (-1.5708, -1.5708, 0), (0, 0, 1)),
    ("revolute", (-0.11257, -0.028, 1.73763e-16), (-3.63608e-16, 8.74301e-16, 1.5708), (0, 0, 1)),
    ("revolute", (-0.1349, 0.0052, 3.62355e-17), (4.02456e-15, 8.67362e-16, -1.5708), (0, 0, 1)),
    ("revolute", (5.55112e-17, -0.0611, 0.0181), (1.5708, 0.0486795, 3.14159), (0, 0, 1)),
    ("revolute", (0.0202, 0.0188, -0.0234), (1.5708, -5.24284e-08, -1.41553e-15), (0, 0, 1)),
]
SO101_TOOL = ((-0.0079, -0.000218121, -0.0981274), (0, 3.14159, 0))
_H = 1.57079632679
BAXTER = [
    ("fixed", (0.024645, 0.219645, 0.118588), (0, 0, 0.7854), None),
    ("revolute", (0.055695, 0, 0.011038), (0, 0, 0), (0, 0, 1)),
    ("revolute", (0.069, 0, 0.27035), (-_H, 0, 0), (0, 0, 1)),
    ("revolute", (0.102, 0, 0), (_H, 0, _H), (0, 0, 1)),
    ("revolute", (0.069, 0, 0.26242), (-_H, -_H, 0), (0, 0, 1)),
    ("revolute", (0.10359, 0, 0), (_H, 0, _H), (0, 0, 1)),
    ("revolute", (0.01, 0, 0.2707), (-_H, -_H, 0), (0, 0, 1)),
    ("revolute", (0.115975, 0, 0), (_H, 0, _H), (0, 0, 1)),
]
BAXTER_TOOL = ((0, 0, 0.27175), (0, 0, 0))
MIXED7 = [
    ("revolute", (0.1, -0.05, 0.3), (0.3, -0.2, 1.1), (0, 0, 1)),
    ("prismatic", (0.0, 0.2, 0.05), (0, 0.4, 0), (1, 2, 2)),
    ("continuous", (0.25, 0, 0.01), (-1.2, 0.5, 0.25), (0.6, 0, 0.8)),
    ("fixed", (0.03, 0.03, 0.0), (0.1, 0.1, 0.1), None),
    ("revolute", (0.0, 0.31, 0.0), (2.5, -0.7, 0.0), (1, 1, 0)),
    ("prismatic", (0.12, 0.0, -0.07), (0, 0, -2.0), (0, 0, 1)),
    ("revolute", (0.07, -0.02, 0.2), (0.9, 1.3, -0.4), (0.48, -0.6, 0.64)),
    ("revolute", (0.0, 0.0, 0.11), (-3.0, 0.0, 0.6), (0, 1, 0)),
]
MIXED7_TOOL = ((0.01, 0.02, 0.15), (0.2, -0.1, 0.05))
ARMS = {"so101": (SO101, SO101_TOOL), "baxter": (BAXTER, BAXTER_TOOL), "mixed7": (MIXED7, MIXED7_TOOL)}


# --- the same arms with NumPy floats, independently of kinlib ------------------------------------------
def _rpy(r, p, y):
    cr, sr, cp, sp_, cy, sy = np.cos(r), np.sin(r), np.cos(p), np.sin(p), np.cos(y), np.sin(y)
    Rz = np.array([[cy, -sy, 0], [sy, cy, 0], [0, 0, 1]])
    Ry = np.array([[cp, 0, sp_], [0, 1, 0], [-sp_, 0, cp]])
    Rx = np.array([[1, 0, 0], [0, cr, -sr], [0, sr, cr]])
    return Rz @ Ry @ Rx


def _mr_arm(joints, tool):
    """(M, S, kinds, joint points at home) from URDF placements, in floats."""
    R, p, S, kinds, pts = np.eye(3), np.zeros(3), [], "", []
    for kind, xyz, rpy, axis in list(joints) + [("fixed", *tool, None)]:
        p = p + R @ np.array(xyz, float)
        R = R @ _rpy(*rpy)
        if kind == "fixed":
            continue
        w = R @ (np.array(axis, float) / np.linalg.norm(axis))
        prismatic = kind == "prismatic"
        S.append(np.concatenate([np.zeros(3), w]) if prismatic else np.concatenate([w, -np.cross(w, p)]))
        kinds += "P" if prismatic else "R"
        pts.append(p.copy())
    M = np.eye(4)
    M[:3, :3], M[:3, 3] = R, p
    return M, np.column_stack(S), kinds, pts


def _configs(kinds, size, seed):
    rng = np.random.default_rng(seed)
    q = rng.uniform(-math.pi, math.pi, size=(size, len(kinds)))
    q[:, [k == "P" for k in kinds]] = rng.uniform(-0.5, 0.5, size=(size, kinds.count("P")))
    return q


def _geometric(T, Jb):
    R = T[:3, :3]
    return np.vstack([R @ Jb[:3], R @ Jb[3:]])


@pytest.mark.parametrize("arm", sorted(ARMS))
def test_urdf_arm_matches_modern_robotics(arm):
    """T, J_s, J_b and J = blockdiag(R, R) J_b of a fresh chain (first call = code generation),
    one configuration at a time and batched, against modern_robotics on the float chain."""
    joints, tool = ARMS[arm]
    chain = from_urdf_joints(joints, tool, name=arm)
    M, S, kinds, _ = _mr_arm(joints, tool)
    assert chain.joint_types == kinds
    B = mr.Adjoint(mr.TransInv(M)) @ S
    Q = _configs(kinds, 6, seed=len(arm))
    want = {"fk": [], "jacobian_space": [], "jacobian_body": [], "jacobian_geometric": []}
    for q in Q:
        T, Jb = mr.FKinSpace(M, S, q), mr.JacobianBody(B, q)
        for method, w in (
            ("fk", T),
            ("jacobian_space", mr.JacobianSpace(S, q)),
            ("jacobian_body", Jb),
            ("jacobian_geometric", _geometric(T, Jb)),
        ):
            np.testing.assert_allclose(getattr(chain, method)(q), w, atol=1e-12, rtol=0, err_msg=f"{arm} {method}")
            want[method].append(w)
    for method, w in want.items():  # the batched code, made on the first batched call
        np.testing.assert_allclose(getattr(chain, method)(Q), np.stack(w), atol=1e-12, rtol=0)


def test_skeleton_matches_modern_robotics():
    """Column i + 1 of the skeleton is joint i's origin at home carried by the joints before it."""
    joints, tool = ARMS["mixed7"]
    chain = from_urdf_joints(joints, tool)
    M, S, kinds, pts = _mr_arm(joints, tool)
    jp = np.column_stack(pts)  # the joint frames' origins at home
    np.testing.assert_allclose(np.array(chain.joint_points, dtype=float), jp, atol=1e-15)
    for q in _configs(kinds, 4, seed=3):
        sk = chain.skeleton(q)
        np.testing.assert_allclose(sk[:, 0], 0, atol=1e-15)
        for i in range(chain.n):
            P = np.eye(4)
            P[:3, 3] = jp[:, i]
            want = mr.FKinSpace(P, S[:, :i], q[:i])[:3, 3] if i else jp[:, i]
            np.testing.assert_allclose(sk[:, i + 1], want, atol=1e-12, rtol=0)
        np.testing.assert_allclose(sk[:, -1], mr.FKinSpace(M, S, q)[:3, 3], atol=1e-12, rtol=0)


def test_numeric_calls_build_no_symbolic_matrix():
    """The expensive step the first call used to take: numbers need only the generated code,
    never the chain's whole symbolic matrix (seconds for a 7-joint arm with long exact numbers)."""
    chain = from_urdf_joints(*ARMS["baxter"])
    q = np.zeros(chain.n)
    for method in ("fk", "jacobian_space", "jacobian_body", "jacobian_geometric", "skeleton"):
        getattr(chain, method)(q)
        getattr(chain, method)(q.tolist())
    assert chain._sym == {}
    assert set(chain._num) == {"fk", "js", "jb", "jg", "skeleton"}
    assert all(c._batch_source is None for c in chain._num.values())  # batched code: on the first batch only
    chain.fk(np.zeros((3, chain.n)))
    assert chain._num["fk"]._batch_source is not None


def _operations(source: str) -> int:
    """Arithmetic operations in the one-configuration code (binary and unary operators)."""
    tree = ast.parse(source.split("def _batch")[0])
    return sum(isinstance(n, (ast.BinOp, ast.UnaryOp)) for n in ast.walk(tree))


def test_operation_counts_do_not_grow():
    """Steady-state speed: the UR5's generated code has no more operations than before the change
    (T 120, J_s 152, J_b 143, J 135: what cse left from the SymPy numeric forms), and the dense
    7-joint Baxter-like arm (no zero in its rotations: 1.57079632679 is not π/2) stays near 1,000."""
    ur5 = robots.ur5()
    for what, most in (("fk", 120), ("js", 152), ("jb", 143), ("jg", 135), ("skeleton", 264)):
        assert _operations(ur5._compiled(what).source) <= most, what
    baxter = from_urdf_joints(*ARMS["baxter"])
    for what in ("fk", "js", "jb", "jg"):
        assert _operations(baxter._compiled(what).source) <= 1200, what


# --- from_urdf_joints: exact numbers -----------------------------------------------------------------
ANGLES = [1.5708, -3.14159, 0.0486795, 4.18253e-17, -5.24284e-08, 0.7854, 1.57079632679, 10.0, -7.5, 3.0]


@pytest.mark.parametrize("a", ANGLES)
def test_rpy_rotation_is_exact_and_within_1e18_of_the_typed_angle(a):
    """The rotation is exactly orthogonal and rational, its angle within 1e-18 rad of the decimal typed
    (checked with mpmath at 40 digits)."""
    chain = from_urdf_joints([("revolute", (0, 0, 0), (0, 0, 0), (0, 0, 1))], tool=((0, 0, 0), (a, 0, 0)))
    R = chain.M[:3, :3]
    assert all(e.is_Rational for e in R)
    assert R.T * R == sp.eye(3) and R.det() == 1
    with mpmath.workdps(40):
        x = mpmath.mpf(repr(a))
        assert abs(mpmath.mpf(R[1, 1].p) / R[1, 1].q - mpmath.cos(x)) <= 1e-18
        assert abs(mpmath.mpf(R[2, 1].p) / R[2, 1].q - mpmath.sin(x)) <= 1e-18


def test_urdf_numbers_are_exact():
    chain = from_urdf_joints(SO101, SO101_TOOL)
    assert chain.M[:3, :3].T * chain.M[:3, :3] == sp.eye(3)
    for i in range(chain.n):
        w = chain.screws[:3, i]
        assert (w.T * w)[0] == 1  # exactly a unit vector
    one = from_urdf_joints([("revolute", (0.0388353, -8.97657e-09, 0.0624), (0, 0, 0), (0, 0, 1))])
    assert list(one.M[:3, 3]) == [sp.Rational("0.0388353"), sp.Rational("-8.97657e-09"), sp.Rational("0.0624")]
    exact = from_urdf_joints([("revolute", (0, 0, 0), (sp.pi / 2, 0, 0), (0, 0, 1))])  # SymPy angle: exact
    assert exact.M[:3, :3] == sp.Matrix([[1, 0, 0], [0, 0, -1], [0, 1, 0]])
    tilted = from_urdf_joints(
        [("revolute", (0, 0, 0), (0, 0, 0), (1, 1, 0)), ("prismatic", (0, 0, 0), (0, 0, 0), (0, 2, 0))]
    )
    assert list(tilted.screws[:, 0]) == [sp.sqrt(2) / 2, sp.sqrt(2) / 2, 0, 0, 0, 0]
    assert list(tilted.screws[:, 1]) == [0, 0, 0, 0, 1, 0]
    assert tilted.joint_types == "RP"
    L = sp.Symbol("L", positive=True)
    symbolic = from_urdf_joints([("revolute", (0, 0, 0), (0, 0, 0), (0, 0, 1))], tool=((L, 0, 0), (0, 0, 0)))
    assert symbolic.params == (L,)


@pytest.mark.parametrize(
    "joints, tool, word",
    [
        ("revolute", None, "joints"),
        ([("revolute", (0, 0), (0, 0, 0), (0, 0, 1))], None, "xyz"),
        ([("ball", (0, 0, 0), (0, 0, 0), (0, 0, 1))], None, "type"),
        ([("revolute", (0, 0, 0), (0, 0, 0), (0, 0, 0))], None, "axis"),
        ([("revolute", (0, 0, 0), (0, 0, float("nan")), (0, 0, 1))], None, "rpy"),
        ([("revolute", (0, 0, "1"), (0, 0, 0), (0, 0, 1))], None, "xyz"),
        ([("revolute", (0, 0, 0), (0, 0, 0))], None, r"joints\[0\] must be \(type, xyz, rpy, axis\)"),
        ([("fixed", (0, 0, 0), (0, 0, 0), None)], None, "at least one"),
        ([("revolute", (0, 0, 0), (0, 0, 0), (0, 0, 1))], ((0, 0, 0),), "tool"),
        ([("revolute", (0, 0, 0), (0, 0, 0), (0, 0, 1))], 5, "tool"),
        ([("revolute", (0, 0, 0), (0, 0, 0), (0, 0, 1))], ((0, 0, 0), (0, 0)), "tool rpy"),
        ([("revolute", (0, 0, 0), (0, 0, 0), (0, 0, 1j))], None, "axis"),
    ],
)
def test_from_urdf_joints_refuses_bad_input(joints, tool, word):
    with pytest.raises((TypeError, ValueError), match=word):
        from_urdf_joints(joints, tool)


# --- the tape ---------------------------------------------------------------------------------------------
def test_tape_folds_constants():
    tp = Tape(2)
    x, s = tp.q(0), tp.sin(1)
    assert 0 * x == 0.0 and type(x * 0.0) is float
    assert x - x == 0.0 and (x + s) - s is not None and ((x + s) - s).terms == x.terms
    assert 1 * x is x and (2 * x + 3 * x).terms == (5 * x).terms
    assert (x * s) is not (s * x) and (x * s).terms == (s * x).terms  # one product node
    assert tp.operation_count([[x * s + 2.0]]) == 2


_LEAVES = st.sampled_from(["q0", "q1", "s0", "c0", "s1", "c1"]) | st.floats(-3, 3, allow_nan=False).map(
    lambda v: round(v, 3)
)
_EXPRS = st.recursive(_LEAVES, lambda kids: st.tuples(st.sampled_from("+-*"), kids, kids), max_leaves=12)


def _run(e, env):
    if isinstance(e, tuple):
        op, a, b = e
        a, b = _run(a, env), _run(b, env)
        return a + b if op == "+" else a - b if op == "-" else a * b
    return env[e] if isinstance(e, str) else e


@settings(deadline=None, derandomize=True, max_examples=60, database=None)
@given(st.lists(_EXPRS, min_size=1, max_size=4), st.lists(st.floats(-4, 4), min_size=2, max_size=2))
def test_tape_code_equals_direct_evaluation(exprs, q):
    """Whatever is recorded, the generated code (with and without cse) computes it (floats to rounding)."""
    tp = Tape(2)
    env = {"q0": tp.q(0), "q1": tp.q(1), "s0": tp.sin(0), "c0": tp.cos(0), "s1": tp.sin(1), "c1": tp.cos(1)}
    direct = {
        "q0": q[0],
        "q1": q[1],
        "s0": math.sin(q[0]),
        "c0": math.cos(q[0]),
        "s1": math.sin(q[1]),
        "c1": math.cos(q[1]),
    }
    rows = [[_run(e, env) for e in exprs]]
    want = np.array([[_run(e, direct) for e in exprs]])
    scale = 1 + np.abs(want)
    for cse in (True, False):
        f = tp.compile(rows, sp.symbols("a b", real=True), cse=cse)
        assert np.all(np.abs(f(q) - want) <= 1e-9 * scale)
        assert np.all(np.abs(f(np.array([q, q]))[1] - want) <= 1e-9 * scale)
    assert all(type(v) in (float, TapeValue) for v in rows[0])
