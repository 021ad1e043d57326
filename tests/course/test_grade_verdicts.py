"""Right verdicts from the grader's comparisons (issue 14, item 3), with messages that never give the key away.

Every false pass and false fail reported in the issue is a test here, with the verdict it must get. The answers
are described exactly as the grader describes them (:func:`kinlib.course.answers.describe.describe`, the code a student
kernel runs; the reference side uses the same function) and compared by :func:`kinlib.course.answers.compare.compare`.
Oracles are independent of the comparison: the subspaces are built from known bases and mixings (numpy), the
angle sets from known rational multiples of π, the redesigns' det(J Jᵀ) from modern_robotics' Jacobian.
"""

from __future__ import annotations

import copy
import json
import math
import re
from dataclasses import asdict
from fractions import Fraction
from pathlib import Path

import numpy as np
import pytest
import sympy as sp
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from kinlib import robots
from kinlib.course import schema
from kinlib.course.answers import compare as C
from kinlib.course.answers import describe as probe
from kinlib.course.answers import wire
from kinlib.course.grader.in_kernel.export import export
from kinlib.singularities import task_rows

pi = sp.pi
ROOT = Path(__file__).resolve().parents[2]
TH = [sp.Symbol(f"theta{i}", real=True) for i in (1, 2, 3)]
POINTS = [{"theta1": 0.3, "theta2": -1.1, "theta3": 2.0, "L": 1.3}, {"theta1": -2.0, "theta2": 0.7, "L": 0.8}]


def verdict(kind, student, reference, name="ans", points=POINTS):
    """(ok, message) for the student's value against the reference's, both described as the grader does
    (a JSON round trip, as they cross the kernel boundary)."""
    stu = json.loads(json.dumps(probe.describe(kind, student, points, 0)))
    ref = json.loads(json.dumps(probe.describe(kind, reference, points, 0)))
    return C.compare(kind, stu, ref, name)


def numbers_in(text):
    return {float(x) for x in re.findall(r"(?<![\w.])[-+]?\d+\.\d+(?:e[-+]?\d+)?", text)}


# ----------------------------------------------------------------------------------------- subspaces

CAN_MOVE = sp.Matrix([[1, 0], [0, sp.sqrt(2) / 2], [0, -sp.sqrt(2) / 2]])  # 5.3's range J_s (printed (48))


def test_huge_multiple_of_a_wrong_basis_fails():
    """The issue's false pass: `can_move = 10**12 * (a wrong basis)` passed (rank tolerance ∝ largest σ)."""
    wrong = sp.Matrix([[1, 0], [0, 1], [0, 1]])  # the plane of (1,0,0), (0,1,1): the *cannot* direction in it
    for scale in (10**12, sp.Rational(1, 10**12), 10**30):
        ok, msg = verdict("subspace", scale * wrong, CAN_MOVE, "can_move")
        assert not ok and "not the right one" in msg, (scale, msg)
    ok, msg = verdict("subspace", 10**12 * sp.Matrix([1, 1, 1]), CAN_MOVE, "can_move")
    assert not ok and "1-dimensional" in msg
    assert "2-dimensional" not in msg and "too small" not in msg  # the answer's dimension is not given away


def test_right_span_in_any_basis_and_scale_passes():
    other = sp.Matrix([[2, 10**12], [3, 0], [-3, 0]])  # columns of wildly different lengths, same plane
    assert verdict("subspace", other, CAN_MOVE, "can_move") == (True, "")
    assert verdict("subspace", sp.Matrix([[0, 1, 5], [1, 0, 5], [-1, 0, -5]]) / 10**15, CAN_MOVE)[0]
    assert verdict("subspace", [[0, 0, 0], [1, 0, 0], [0, 1, -1]], CAN_MOVE)[0]  # a zero column, a list


def test_exact_subspaces_are_compared_exactly():
    """Constant exact bases are compared by exact ranks: a column 10⁻³⁰ times another still counts (numerically
    it would be round-off), and an exact near-miss is caught whatever its size."""
    ref = sp.Matrix([[1, 0], [0, 1], [0, 0]])
    stu = sp.Matrix([[1, 0], [0, sp.Rational(1, 10**30)], [0, 0]])
    assert "tree" in probe.describe("subspace", stu, [{}])
    assert verdict("subspace", stu, ref) == (True, "")
    ok, msg = verdict("subspace", sp.Matrix([[1, 0], [0, 1], [0, sp.Rational(1, 10**30)]]), ref)
    assert not ok and "not the right one" in msg
    assert verdict("subspace", [[sp.sqrt(2), 1, 0], [sp.sqrt(6), sp.sqrt(3), 0]], ref)[1] == (
        "ans spans a 1-dimensional space (2 columns, 1 independent), not the right dimension"
    )


def test_subspace_in_the_symbols():
    """Span at every point: columns that depend on θ (the right plane at every θ) pass; wrong ones fail."""
    t = TH[0]
    ref = sp.Matrix([[sp.cos(t), 0], [sp.sin(t), 0], [0, 1]])
    assert verdict("subspace", 10**12 * sp.Matrix([[2 * sp.cos(t)], [2 * sp.sin(t)], [5]]).row_join(ref[:, 1]), ref)[0]
    ok, _ = verdict("subspace", 10**12 * sp.Matrix([[sp.cos(t), 0], [0, 0], [0, 1]]), ref)
    assert not ok


def _desc(M):
    """A numeric matrix described as the probe does (one point)."""
    return {
        "tag": "matrix",
        "type": "Matrix",
        "shape": list(M.shape),
        "symbols": [],
        "values": [[[float(np.real(x)), float(np.imag(x))] for x in np.asarray(M).ravel()]],
    }


dims = st.integers(2, 6).flatmap(lambda n: st.tuples(st.just(n), st.integers(1, n - 1)))


@settings(max_examples=60, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(nk=dims, seed=st.integers(0, 2**32 - 1), scale_exp=st.integers(-12, 12), extra=st.integers(0, 2))
def test_subspace_hypothesis(nk, seed, scale_exp, extra):
    """Random bases × random invertible mixing × huge/tiny scales (× dependent extra columns) pass; the same
    basis with one direction tilted out of the subspace fails, whatever the scale."""
    n, k = nk
    rng = np.random.default_rng(seed)
    B = rng.standard_normal((n, k))
    M = rng.standard_normal((k, k))
    while abs(np.linalg.det(M)) < 1e-2 * np.prod(np.linalg.norm(M, axis=0)):
        M = rng.standard_normal((k, k))
    A = B @ M
    if extra:
        A = np.hstack([A, B @ rng.standard_normal((k, extra))])
    A = A * 10.0**scale_exp
    assert C.compare_subspace(_desc(A), _desc(B), "V")[0]
    # tilt: add a component orthogonal to span B to the first column (relative size 1e-3 .. 1)
    Q, _ = np.linalg.qr(B, mode="complete")
    out = Q[:, k:] @ rng.standard_normal(n - k)
    out /= np.linalg.norm(out)
    W = B @ M
    W[:, 0] = W[:, 0] + np.linalg.norm(W[:, 0]) * 10.0 ** rng.uniform(-3, 0) * out
    ok, msg = C.compare_subspace(_desc(W * 10.0**scale_exp), _desc(B), "V")
    assert not ok and "not the right one" in msg


# ----------------------------------------------------------------------------------------- angle sets

# 1.1's `vertical`: det J = L cos θ2 = 0 on one turn of the pole, as the solution notebook computes it: {±π/2}
VERTICAL = sp.solveset(sp.Symbol("L", positive=True) * sp.cos(TH[1]), TH[1], sp.Interval.Ropen(-pi, pi))


@pytest.mark.parametrize(
    "student",
    [
        sp.FiniteSet(pi / 2, 3 * pi / 2),  # the issue's `vertical = {π/2, 3π/2}` (not keyed by θ)
        {pi / 2, 3 * pi / 2},
        {TH[1]: sp.FiniteSet(pi / 2, 3 * pi / 2)},
        {sp.Symbol("q"): sp.FiniteSet(-pi / 2, pi / 2)},  # keyed by another symbol
        sp.ImageSet(sp.Lambda(sp.Symbol("n"), 2 * sp.Symbol("n") * pi + pi / 2), sp.Integers)
        + sp.FiniteSet(-pi / 2 + 20 * pi),
        sp.ImageSet(sp.Lambda(sp.Symbol("n"), sp.Symbol("n") * pi + pi / 2), sp.Integers),
        sp.solveset(sp.cos(TH[1]), TH[1], sp.Reals),  # the solveset(cos θ2, θ2, Reals)
        sp.Union(
            sp.ImageSet(sp.Lambda(sp.Symbol("n"), 2 * sp.Symbol("n") * pi + 1001 * pi / 2), sp.Integers),
            sp.ImageSet(sp.Lambda(sp.Symbol("n"), 2 * sp.Symbol("n") * pi - 997 * pi / 2), sp.Integers),
        ),
        sp.FiniteSet(pi / 2 - 40 * pi, 3 * pi / 2 + 100 * pi),  # outside [0, 2π)
    ],
)
def test_angle_sets_compare_modulo_2pi_whatever_the_key(student):
    assert VERTICAL == sp.FiniteSet(-pi / 2, pi / 2)
    assert verdict("set", student, VERTICAL, "vertical") == (True, "")


def test_typeset_joint_names_are_the_same_joint():
    ref = {TH[1]: sp.FiniteSet(-pi / 4, 3 * pi / 4)}
    for key in ("θ_2", "theta_{2}", r"\theta_2", "theta2"):
        assert verdict("set", {sp.Symbol(key): sp.FiniteSet(3 * pi / 4, 7 * pi / 4)}, ref)[0], key
    assert not verdict("set", {TH[0]: sp.FiniteSet(3 * pi / 4, 7 * pi / 4)}, ref)[0]  # another joint


def test_degrees_are_named_not_called_empty():
    for student in (
        sp.FiniteSet(90, 270),
        {TH[1]: sp.FiniteSet(90, 270)},
        sp.ImageSet(sp.Lambda(sp.Symbol("n"), 180 * sp.Symbol("n") + 90), sp.Integers),
    ):
        ok, msg = verdict("set", student, VERTICAL, "vertical")
        assert not ok and "degrees" in msg and "90, 270" in msg and "empty" not in msg, msg
    ok, msg = verdict("set", sp.FiniteSet(45, 90), VERTICAL, "vertical")  # wrong *and* in degrees
    assert not ok and "degrees (45, 90)" in msg


def test_messages_never_show_internal_none():
    ok, msg = verdict("set", sp.FiniteSet(pi / 2, pi), VERTICAL, "vertical")
    assert not ok and "None" not in msg and "π is not in the set" in msg, msg
    ok, msg = verdict("set", {TH[0]: sp.FiniteSet(0)}, {TH[1]: sp.FiniteSet(0)}, "S")
    assert not ok and "None" not in msg


def test_singular_family_of_5_1_in_every_form():
    """5.1's answer θ2 = −π/4 + kπ, as the solution gives it (a dict of a Union of ImageSets), against the
    forms students write."""
    k = sp.Symbol("k", integer=True)
    ref = {TH[1]: sp.ImageSet(sp.Lambda(k, k * pi - pi / 4), sp.Integers)}
    n = sp.Symbol("n")
    for student in (
        {TH[1]: sp.FiniteSet(3 * pi / 4, 7 * pi / 4)},
        sp.FiniteSet(-pi / 4, 3 * pi / 4),
        sp.solveset(sp.sin(TH[1] + pi / 4), TH[1], sp.Reals),
        {TH[1]: sp.ImageSet(sp.Lambda(n, 2 * n * pi + 3 * pi / 4), sp.Integers) | sp.FiniteSet(-pi / 4 + 8 * pi)},
    ):
        assert verdict("set", student, ref, "singular_theta2") == (True, ""), student
    ok, msg = verdict("set", {TH[1]: sp.FiniteSet(3 * pi / 4)}, ref, "singular_theta2")
    assert not ok and "missing" in msg and "None" not in msg
    assert not verdict("set", {TH[1]: sp.FiniteSet(pi / 4, 3 * pi / 4)}, ref)[0]


def test_prismatic_values_are_not_taken_modulo_2pi():
    """Sets of values that are not angles (not multiples of π, or a prismatic variable) compare as numbers."""
    L = sp.Symbol("L", positive=True)
    d = sp.Symbol("d3", real=True)
    assert not verdict("set", {d: sp.FiniteSet(2 * pi)}, {d: sp.FiniteSet(0)}, "S")[0]
    assert not verdict("set", {TH[2]: sp.FiniteSet(-L + 2 * pi)}, {TH[2]: sp.FiniteSet(-L)}, "S")[0]


angles = st.lists(
    st.tuples(st.integers(-23, 23), st.integers(1, 12)).map(lambda t: Fraction(*t)), min_size=1, max_size=4
)


@settings(max_examples=60, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(fracs=angles, shifts=st.lists(st.integers(-50, 50), min_size=4, max_size=4), form=st.sampled_from("FIU"))
def test_angle_sets_hypothesis(fracs, shifts, form):
    """Rational multiples of π shifted by multiples of 2π, as a FiniteSet, ImageSets or a Union, equal the
    set of their representatives in [0, 2π); changing one value by a non-multiple of 2π fails."""
    reps = sorted({(f % 2) for f in fracs})  # representatives in [0, 2) · π
    ref = sp.FiniteSet(*[sp.Rational(r.numerator, r.denominator) * pi for r in reps])
    n = sp.Symbol("n", integer=True)

    def shifted(vals):
        vals = [sp.Rational(f.numerator, f.denominator) * pi + 2 * pi * shifts[i % 4] for i, f in enumerate(vals)]
        if form == "F":
            return sp.FiniteSet(*vals)
        sets = [sp.ImageSet(sp.Lambda(n, 2 * pi * n + v), sp.Integers) for v in vals]
        return sets[0] if form == "I" and len(sets) == 1 else sp.Union(*sets, evaluate=False)

    assert verdict("set", shifted(fracs), ref, "S") == (True, "")
    wrong = list(fracs)
    wrong[0] = wrong[0] + Fraction(1, 3)  # θ + π/3: a different angle
    if {f % 2 for f in wrong} != set(reps):
        ok, msg = verdict("set", shifted(wrong), ref, "S")
        assert not ok and "None" not in msg


# ----------------------------------------------------------------------------------------- messages keep the key


def test_constant_factor_message_does_not_reveal_the_factor():
    """ "off by a constant factor (0.5 times the answer)" gave the key away (answer = yours / 0.5)."""
    L = sp.Symbol("L", positive=True)
    ref = sp.sqrt(2) * L**2 * sp.sin(TH[1] + pi / 4)
    for k in (sp.Rational(1, 2), 3, sp.Rational(-7, 5), sp.Rational(997, 1000)):
        ok, msg = verdict("expr", k * ref, ref, "detJ")
        assert not ok
        assert "times the answer" not in msg and str(float(k)) not in msg and not numbers_in(msg), msg


@settings(max_examples=40, deadline=None)
@given(
    ref_vals=st.lists(st.floats(-50, 50, allow_nan=False).filter(lambda x: abs(x) > 1e-3), min_size=1, max_size=6),
    factor=st.floats(-20, 20).filter(lambda x: abs(x) > 1e-3 and abs(x - 1) > 1e-6),
)
def test_no_expr_message_prints_a_number_of_the_key(ref_vals, factor):
    ref = {"shape": [len(ref_vals), 1], "symbols": [], "values": [[[x, 0.0] for x in ref_vals]]}
    stu = dict(ref, tag="matrix", values=[[[factor * x, 0.0] for x in ref_vals]])
    ok, msg = C.compare_expr(stu, ref, "v")
    assert not ok
    key_numbers = {round(x, 3) for x in ref_vals} | {round(factor, 3), round(1 / factor, 3)}
    assert not ({round(x, 3) for x in numbers_in(msg)} & key_numbers), msg


def test_set_and_choice_messages_do_not_describe_the_key():
    # 6.1's answer is "no singular configuration": a wrong non-empty answer must not learn that
    ok, msg = verdict("set", {TH[1]: sp.FiniteSet(0)}, [], "singular_set")
    assert not ok and "no such" not in msg and "empty" not in msg
    ok, msg = verdict("set", [{TH[1]: sp.FiniteSet(0)}, {TH[2]: sp.FiniteSet(0)}], [{TH[1]: {0}}], "S")
    assert not ok and "expected" not in msg
    ok, msg = C.compare_choice({"tag": "choice", "value": [1]}, {"value": [1, 2]}, "j")
    assert not ok and "2" not in msg and "partly" not in msg
    ok, msg = C.compare_choice({"tag": "choice", "value": [1, 2, 3]}, {"value": [1, 2]}, "j")
    assert not ok and "more than" not in msg
    assert C.compare_choice({"tag": "choice", "value": [0]}, {"value": [1]}, "j")[1] == "j: joints are numbered from 1"


# ----------------------------------------------------------------------------------------- 5.5 by its property

PROP = "property:nonsingular"


def _rpp_det():
    rpp = robots.planar_rpp()
    Jr = task_rows(rpp.jacobian_space(), "planar")
    return Jr, sp.simplify((Jr * Jr.T).det())


def test_5_5_is_declared_a_property_in_notebook_05():
    nb = json.loads((ROOT / "notebooks" / "05_singularities_planar.ipynb").read_text())
    part = next(p for p in schema.parse_parts(nb) if p.part == "5.5")
    assert [part.kinds[a] for a in part.answers] == [PROP]
    # the self-check judges the same property (schema.answer_groups gives it the grading kind)
    kinds = {(pid, kind) for g in schema.answer_groups(nb) for pid, _name, kind, _i in g.answers if pid == "5.5"}
    assert kinds == {("5.5", PROP)}


def _planar_robot(joints):
    """A planar SerialChain from (kind, x, y) joints at home: 'R' about z through (x, y), 'P' along (x, y);
    screw axes written by hand (S = (ω, −ω × q) for R, (0, v) for P), independent of kinlib's robots."""
    from kinlib.chains import SerialChain

    cols = []
    for kind, x, y in joints:
        cols.append([0, 0, 1, y, -x, 0] if kind == "R" else [0, 0, 0, x, y, 0])
    return SerialChain(sp.eye(4), sp.Matrix(cols).T, name="student_design")


def _gram_det_by_hand(chain):
    """det(J Jᵀ) of the planar task rows from modern_robotics' JacobianSpace at random θ (numbers)."""
    import modern_robotics as mr

    S = np.array(chain.subs(L=1).screws if chain.params else chain.screws, dtype=float)
    rng = np.random.default_rng(3)
    out = []
    for _ in range(200):
        J = mr.JacobianSpace(S, rng.uniform(-np.pi, np.pi, S.shape[1]))[[2, 3, 4]]
        out.append(np.linalg.det(J @ J.T))
    return np.array(out)


def test_5_5_the_students_own_robot_is_judged_by_its_property():
    """Right: the printed R-P-P (as a robot and as its J); other valid designs pass: a P-P-R, an R-P-P with a
    slanted slide (not orthogonal: det(J Jᵀ) = sin²α, never 0 for 0 < α < π), a 4-joint R-R-P-P. The oracle is
    modern_robotics' Jacobian: det(J Jᵀ) on 200 random configurations stays away from 0."""
    Jr, det_rpp = _rpp_det()
    assert det_rpp == 1  # eq. (55)
    valid = {
        "printed R-P-P": robots.planar_rpp(),
        "P-P-R": _planar_robot([("P", 1, 0), ("P", 0, 1), ("R", 2, 1)]),
        "slanted slides": _planar_robot([("R", 0, 0), ("P", 1, 0), ("P", sp.Rational(3, 5), sp.Rational(4, 5))]),
        "R-R-P-P": _planar_robot([("R", 0, 0), ("R", 1, 0), ("P", 1, 0), ("P", 0, 1)]),
    }
    for label, chain in valid.items():
        assert _gram_det_by_hand(chain).min() > 1e-3, label  # the oracle agrees the design is valid
        ok, msg = verdict(PROP, chain, robots.planar_rpp(), "redesign")
        assert ok, (label, msg)
        assert "R-P-P" not in msg and "= 1" not in msg
        # as the grader receives it: exported in the student's kernel, read by the whitelist parser
        crossed = wire.load(json.loads(json.dumps(export(chain))))
        assert verdict(PROP, crossed, robots.planar_rpp(), "redesign")[0], label
    c1, s1 = sp.cos(TH[0]), sp.sin(TH[0])
    J_alt = sp.Matrix([[1, 0, 0], [0, c1 / sp.sqrt(2), -s1], [0, s1 / sp.sqrt(2), c1]])
    for J in (Jr, J_alt, sp.eye(3), 2 * sp.eye(3)):  # a matrix alone (its J, any invertible one) is no robot
        ok, msg = verdict(PROP, J, robots.planar_rpp(), "redesign")
        assert not ok and "SerialChain" in msg and "no robot" in msg, msg


def test_5_5_a_value_with_no_robot_and_singular_designs_fail():
    """`1` (the printed det) with no robot fails, as do 2, L**4, cos(θ1)² + 1: values, not robots. Designs with
    singular configurations fail and the message names where *their* det(J Jᵀ) vanishes, never a design."""
    L = sp.Symbol("L", positive=True)
    original = robots.planar_offset_3r()
    Jt = task_rows(original.jacobian_space(), "planar")
    for value in (1, sp.Integer(1), 2, L**4, sp.cos(TH[0]) ** 2 + 1, sp.Float(0.5)):
        ok, msg = verdict(PROP, value, robots.planar_rpp(), "redesign")
        assert not ok and "robot" in msg, (value, msg)
    cases = {  # answer, a configuration where the oracle (modern_robotics) finds det(J Jᵀ) = 0
        "original robot": (original, [0.4, -np.pi / 4, 1.0]),
        "original J": (Jt, None),
        "two slides only (too few joints)": (_planar_robot([("P", 1, 0), ("P", 0, 1)]), None),
        "R-P-P with parallel slides": (_planar_robot([("R", 0, 0), ("P", 1, 0), ("P", 1, 0)]), [0.3, 0.2, 0.1]),
        "three joints on a line": (_planar_robot([("R", 0, 0), ("R", 1, 0), ("R", 2, 0)]), [0.7, 0.0, 0.0]),
        "spatial": (robots.spatial_rppr(), None),
        "zero": (sp.zeros(3, 3), None),
        "tall": (sp.Matrix([[1, 0], [0, 1], [0, 0]]), None),
    }
    for label, (answer, q_sing) in cases.items():
        if q_sing is not None:
            import modern_robotics as mr

            S = np.array(answer.subs(L=1).screws if answer.params else answer.screws, dtype=float)
            J = mr.JacobianSpace(S, q_sing)[[2, 3, 4]]
            assert abs(np.linalg.det(J @ J.T)) < 1e-12, label
        ok, msg = verdict(PROP, answer, robots.planar_rpp(), "redesign")
        assert not ok, label
        assert "R-P-P" not in msg and "prismatic" not in msg and "= 1" not in msg and "factor" not in msg, msg
    ok, msg = verdict(PROP, original, robots.planar_rpp(), "redesign")
    # never where: the original robot's singular set is 5.1's answer (θ2 = 3π/4, 7π/4), the 4R arm's 7.2's
    assert not ok and "singular configurations" in msg and "pi" not in msg and "theta" not in msg, msg


def test_5_5_hostile_trees_are_rejected_not_evaluated():
    huge = ["Pow", ["Integer", "10"], ["Integer", str(10**9)]]
    col = lambda *xs: ["Matrix", 6, 1, *xs]  # noqa: E731
    zero = ["Integer", "0"]
    for tag in ("scalar", "robot"):
        for tree in (
            huge,
            ["Integer", "9" * 5000],
            ["call", "__import__", "os"],
            {"a": 1},
            col(zero, zero, huge, zero, zero, zero),
            col(zero, zero, ["exp", ["Symbol", "t", {}]], zero, zero, zero),
            col(zero, zero, ["Symbol", "__import__('os')", {}], zero, zero, zero),
        ):
            assert not C.compare(PROP, {"tag": tag, "tree": tree}, {}, "d")[0], tree
    deep = ["Integer", "1"]
    for _ in range(30000):
        deep = ["Add", deep, ["Integer", "1"]]
    ok, msg = C.compare(PROP, {"tag": "scalar", "tree": deep}, {}, "d")
    assert not ok
    ok, msg = C.compare(PROP, {"tag": "matrix", "tree": ["Matrix", 1, 1, deep]}, {}, "d")
    assert not ok and ("could not" in msg or "no robot" in msg)
    ok, msg = C.compare(PROP, {"tag": "robot", "tree": ["Matrix", 6, 1, *[deep] * 6]}, {}, "d")
    assert not ok and "could not" in msg
    big = (sp.sin(TH[0]) + sp.cos(TH[1]) + sp.sin(TH[2]) + 2) ** 12
    ok, msg = verdict(PROP, sp.diag(big, 1, 1), 1, "d")
    assert not ok and "no robot" in msg  # a matrix is refused before it is read
    assert not verdict(PROP, sp.exp(TH[0]), 1, "d")[0]


# ----------------------------------------------------------------------------------------- lost metadata


def _solution_notebooks():
    out = {}
    for f in sorted((ROOT / "notebooks").glob("0*.ipynb")):
        nb = json.loads(f.read_text())
        if schema.notebook_id(nb):
            out[schema.notebook_id(nb)] = nb
    return out


def test_notebook_without_metadata_is_matched_by_its_questions():
    nbs = _solution_notebooks()
    refs = {nid: [asdict(p) for p in schema.parse_parts(nb)] for nid, nb in nbs.items()}
    assert len(refs) >= 6
    for nid, nb in nbs.items():
        pasted = {"cells": [], "metadata": {}, "nbformat": 4, "nbformat_minor": 5}
        for c in nb["cells"]:  # the solution cells pasted into a new notebook: no cell metadata either
            if "solution" in schema.cell_tags(c) and c["cell_type"] == "code":
                pasted["cells"].append({"cell_type": "code", "metadata": {}, "source": c["source"], "outputs": []})
        assert schema.notebook_id(pasted) is None
        assert schema.match_notebook(pasted, refs) == nid
        stubs = copy.deepcopy(pasted)  # an untouched workbook that lost its metadata: `J = ...` stubs
        for c in stubs["cells"]:
            c["source"] = ""
        names = [a for p in refs[nid] for a in p["answers"]]
        stubs["cells"].append({"cell_type": "code", "metadata": {}, "source": "\n".join(f"{a} = ..." for a in names)})
        assert schema.match_notebook(stubs, refs) == nid
    assert schema.match_notebook({"cells": [{"cell_type": "code", "source": "x = 1"}]}, refs) is None
    assert math.isfinite(len(schema.assigned_names({"cells": [{"cell_type": "code", "source": "%%time\nJ ="}]})))


# ----------------------------------------------------------------------------------------- end to end (kernels)

FIX = ROOT / "tests" / "fixtures" / "grade"


def _workbook(overrides: dict) -> dict:
    """The fixture workbook with every stub replaced by the solution's code (or ``overrides[part]``)."""
    ref = json.loads((FIX / "notebooks" / "90_grade_fixture.ipynb").read_text())
    wb = json.loads((FIX / "workbooks" / "90_grade_fixture.ipynb").read_text())
    sources = {
        schema.cell_meta(c)["part"]: schema.cell_source(c)
        for c in ref["cells"]
        if c["cell_type"] == "code" and "solution" in schema.cell_tags(c) and schema.cell_meta(c).get("answers")
    }
    for c in wb["cells"]:
        meta = schema.cell_meta(c)
        if c["cell_type"] == "code" and "solution" in schema.cell_tags(c) and meta.get("answers"):
            c["source"] = overrides.get(meta["part"], sources[meta["part"]])
    return wb


@pytest.mark.slow
def test_end_to_end_verdicts_and_a_notebook_without_metadata(tmp_path, grader_reference_cache):
    from kinlib.course.grader import grade

    subs = tmp_path / "subs"
    subs.mkdir()
    tricky = _workbook(
        {
            "1.3": "moves = 10**12 * sp.Matrix([[1, 0], [0, 1], [0, 1]])   # a wrong plane, scaled up",
            "1.4": "singular = sp.FiniteSet(-sp.pi / 4 + 10 * sp.pi, 3 * sp.pi / 4 - 20 * sp.pi)   # bare, shifted",
        }
    )
    (subs / "tricky.ipynb").write_text(json.dumps(tricky))
    pasted = _workbook({})
    pasted["metadata"] = {}
    for c in pasted["cells"]:
        c["metadata"] = {}
    (subs / "pasted.ipynb").write_text(json.dumps(pasted))
    summary = grade.grade_batch(
        [subs],
        tmp_path / "out",
        jobs=1,
        timeout=120,
        cell_timeout=60,
        notebooks=FIX / "notebooks",
        cache=grader_reference_cache,
        log=None,
    )
    rows = {(Path(r["submission"]).stem, r["part"]): r for r in summary["rows"]}
    assert rows[("tricky", "1.3")]["status"] == "fail" and "not the right one" in rows[("tricky", "1.3")]["message"]
    assert rows[("tricky", "1.4")]["status"] == "pass", rows[("tricky", "1.4")]
    pasted_rows = {p: r for (s, p), r in rows.items() if s == "pasted"}
    assert set(pasted_rows) == {"1.1", "1.2", "1.3", "1.4", "1.5"}, pasted_rows
    assert all(r["status"] == "pass" and r["notebook"] == "90_grade_fixture" for r in pasted_rows.values()), pasted_rows
    res = next(r for r in summary["results"] if Path(r["submission"]).stem == "pasted")
    assert any("recognised as 90_grade_fixture" in n for n in res.get("notes", []))


def test_5_5_the_reference_robot_is_kept_as_data():
    """The solution notebook's answer to 5.5 is a robot: the answer key keeps its screw axes (the reference of a
    property answer is data only; a robot's repr in the key broke every 05 grading once)."""
    from kinlib.course.grader import refdata

    ref = refdata.reference_answers({"redesign": {"tree": export(robots.planar_rpp())}}, {"redesign": PROP})
    assert "error" not in ref["redesign"], ref
    assert ref["redesign"]["kind"] == PROP and ref["redesign"]["tree"][:3] == ["Matrix", 6, 3]


# ----------------------------------------------------------------------------------------- nothing revealed (issue 31)


def _table():
    from answer_table import rows

    return rows()


def test_no_message_states_a_graded_value_of_any_part():
    """Every message both judges give, for every row of the shared table (tests/answer_table.py) given its right
    answer, its typical wrong answers, and every other part's answer, states no graded value of any part that
    the student did not type themselves (their own members may be echoed: "pi/4 is not in the set")."""
    from answer_table import graded_tokens, grader_verdict, home_verdict

    table = _table()
    graded = {row.salt: graded_tokens(row.right) for row in table}
    everything = set().union(*graded.values())
    assert {"3*pi/4", "sqrt(2)*L**2"} <= everything  # the scan looks for the values the issue saw printed
    seen = 0
    for target in table:
        given = [target.right] + [v for v, _ in target.wrong] + [r.right for r in table if r is not target]
        for value in given:
            own = graded_tokens(value)
            forbidden = everything - own
            for msg in (home_verdict(value, target)[1], grader_verdict(value, target, 5)[1]):
                seen += 1
                leaked = sorted(t for t in forbidden if t in msg)
                assert not leaked, (target.salt, value, msg, leaked)
    assert seen > 500


def test_5_5_and_the_4r_arm_never_print_another_parts_singular_set():
    """The original robot given for 5.5 printed 5.1's set ("= 0 where theta2 = 3*pi/4, 7*pi/4 (+ 2πk)"); the 4R
    arm printed 7.2's. Now: "singular configurations", never where, by both judges."""
    from kinlib.course.workbook.selfcheck import fingerprint
    from kinlib.course.workbook.selfcheck import verdict as home

    spec = fingerprint(robots.planar_rpp(), PROP)
    four_r = _planar_robot([("R", 0, 0), ("R", 1, 0), ("R", 2, 0), ("R", 3, 0)])
    for chain in (robots.planar_offset_3r(), four_r):
        ok, msg = verdict(PROP, chain, robots.planar_rpp(), "redesign")
        status, said = home(chain, spec)
        assert not ok and status == "incorrect"
        for m in (msg, said):
            assert "singular configurations" in m and not re.search(r"pi|theta|π/|\d\*", m), m


def test_a_matrix_or_a_number_is_not_a_robot_for_either_judge():
    """`redesign = sp.eye(3)` was "✓ proved": any constant invertible matrix belongs to no robot."""
    from kinlib.course.workbook.selfcheck import fingerprint
    from kinlib.course.workbook.selfcheck import verdict as home

    spec = fingerprint(robots.planar_rpp(), PROP)
    for value in (sp.eye(3), 2 * sp.eye(3), np.eye(3), 1, sp.Integer(1), [[1, 0, 0], [0, 1, 0], [0, 0, 1]]):
        ok, msg = verdict(PROP, value, robots.planar_rpp(), "redesign")
        status, said = home(value, spec)
        assert not ok and status == "incorrect", (value, msg, said)
        assert "SerialChain" in msg and "SerialChain" in said, (msg, said)
    assert home(robots.planar_rpp(), spec)[0] == "correct"
