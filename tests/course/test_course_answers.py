"""The answer normalisers of kinlib.course.answers' kind modules: one per kind, for the self-checks and the grader alike.

It replaced two (the self-check's coercions and the checker probe's); it accepts the union of the
forms either accepted, and both consumers now accept each of them. The last tests check that: the same
answer, in each form, passes the workbook self-check (fingerprints) and the checker (probe + compare,
run here in-process as the worker process runs them on reference answers).
"""

from __future__ import annotations

import math
from fractions import Fraction

import mpmath
import numpy as np
import pytest
import sympy as sp

from kinlib.course.answers.base import is_bool, is_unanswered
from kinlib.course.answers.choice import choice_value
from kinlib.course.answers.expr import to_sympy
from kinlib.course.answers.sets import looks_like_set, set_conditions, to_set
from kinlib.course.grader.in_kernel.export import exported
from kinlib.course.grader.judge import judge_answer
from kinlib.course.grader.refdata import Reference, reference_answers
from kinlib.course.workbook.selfcheck import fingerprint, verdict

x, th1, th2 = sp.symbols("x theta1 theta2")
COLS = [sp.Matrix([1, 2, 3]), sp.Matrix([4, 5, 6])]
M32 = sp.Matrix([[1, 4], [2, 5], [3, 6]])


# ----------------------------------------------------------------------------------------- to_sympy


@pytest.mark.parametrize(
    "value, expected",
    [
        (M32, M32),
        (sp.ImmutableMatrix(M32), M32),
        (np.array([[1, 4], [2, 5], [3, 6]]), M32),
        (np.array([1, 2, 3]), sp.Matrix([1, 2, 3])),  # a 1-D array is a column
        ([1, 2, 3], sp.Matrix([1, 2, 3])),  # so is a flat list
        (sp.Tuple(1, 2, 3), sp.Matrix([1, 2, 3])),  # (the checker's)
        (COLS, M32),  # a list of column vectors: columns
        ([np.array([1, 2, 3]), np.array([4, 5, 6])], M32),  # (the checker's screw-list convention)
        ([sp.Matrix([[1, 2, 3]]), sp.Matrix([[4, 5, 6]])], M32),
        ([[1, 4], [2, 5], [3, 6]], M32),  # a list of lists: the rows
        ([(1, 4), (2, 5), (3, 6)], M32),
    ],
)
def test_matrix_forms(value, expected):
    tag, obj = to_sympy(value)
    assert tag == "matrix" and obj == expected and isinstance(obj, sp.MutableDenseMatrix)


@pytest.mark.parametrize(
    "value",
    [
        [[1, 2, 3], [4, 5, 6]],
        [(1, 2, 3), (4, 5, 6)],
        COLS,
        [sp.Matrix([[1, 4], [2, 5], [3, 6]])],  # blocks side by side
        [np.array([[1], [2], [3]]), sp.Matrix([4, 5, 6])],
    ],
)
def test_subspace_forms_are_spanning_vectors(value):
    """For subspaces a list of lists is the list of spanning vectors (the self-check's convention)."""
    assert to_sympy(value, vectors=True) == ("matrix", M32)


@pytest.mark.parametrize(
    "value, expected",
    [
        (x**2, x**2),
        (3, sp.Integer(3)),
        (0.5, sp.Float(0.5)),
        (np.float64(0.25), sp.Float(0.25)),
        (np.int64(7), sp.Integer(7)),
        (np.array(2.0), sp.Float(2.0)),
        (Fraction(1, 3), sp.Rational(1, 3)),
        (mpmath.mpf("0.5"), sp.Float(0.5)),  # via sympify (the self-check's)
        (1 + 2j, 1 + 2 * sp.I),
    ],
)
def test_scalar_forms(value, expected):
    tag, obj = to_sympy(value)
    assert tag == "scalar" and sp.simplify(obj - expected) == 0


@pytest.mark.parametrize(
    "value, tag",
    [
        (..., "ellipsis"),
        (None, "none"),
        (True, "bool"),
        (np.bool_(False), "bool"),
        (sp.true, "bool"),
        ([], "empty"),
        ([sp.Matrix([1, 2]), sp.Matrix([1, 2, 3])], "ragged"),
        (np.zeros((2, 2, 2)), "array"),
        ("J", "other"),
        ({"a": 1}, "other"),
        ({1, 2}, "other"),
        (sp.Eq(x, 1), "other"),
        (object(), "other"),
    ],
)
def test_not_a_matrix_or_scalar(value, tag):
    assert to_sympy(value) == (tag, None)


def test_unanswered_and_bool():
    assert is_unanswered(...) and is_unanswered(None) and not is_unanswered(0) and not is_unanswered([])
    assert all(is_bool(v) for v in (True, False, np.bool_(True), sp.true, sp.false))
    assert not any(is_bool(v) for v in (1, 0, "True", sp.Integer(1)))


# ----------------------------------------------------------------------------------------- sets


@pytest.mark.parametrize(
    "value, expected",
    [
        (sp.FiniteSet(0, sp.pi), sp.FiniteSet(0, sp.pi)),
        ({0, 1}, sp.FiniteSet(0, 1)),
        ([0, 1], sp.FiniteSet(0, 1)),
        ((0, 1), sp.FiniteSet(0, 1)),
        (np.array([0.5, 1.5]), sp.FiniteSet(0.5, 1.5)),
        (sp.pi, sp.FiniteSet(sp.pi)),
        (2, sp.FiniteSet(2)),
        (sp.Interval(0, 1), sp.Interval(0, 1)),
    ],
)
def test_to_set(value, expected):
    assert to_set(value) == expected


@pytest.mark.parametrize("value", ["theta", {th1: 0}, None, True])
def test_to_set_rejects(value):
    with pytest.raises(TypeError):
        to_set(value)


def test_set_conditions_union_of_both_readers():
    S = sp.FiniteSet(0)
    assert set_conditions(S) == [[(None, S)]]
    assert set_conditions([0, 1]) == [[(None, [0, 1])]] and set_conditions({0}) == [[(None, {0})]]
    assert set_conditions(np.array([0.0])) == [[(None, [0.0])]]  # the checker's
    assert set_conditions(sp.pi / 2) == [[(None, sp.FiniteSet(sp.pi / 2))]]  # the self-check's
    assert set_conditions({th1: S, th2: {1}}) == [[(th1, S), (th2, {1})]]
    assert set_conditions(sp.Dict({th1: S})) == [[(th1, S)]]  # the checker's
    assert set_conditions([{th1: S}, {th2: S}]) == [[(th1, S)], [(th2, S)]]  # a union (the checker's)
    assert set_conditions([]) == []  # no configuration
    assert set_conditions("S") is None and set_conditions(None) is None and set_conditions(True) is None


def test_looks_like_set():
    assert looks_like_set(sp.EmptySet) and looks_like_set({th1: sp.FiniteSet(0)}) and looks_like_set([])
    assert looks_like_set([{th1: sp.FiniteSet(0)}, {th2: sp.FiniteSet(1)}])
    assert not looks_like_set({}) and not looks_like_set({"a": 1}) and not looks_like_set([1, 2])
    assert not looks_like_set(sp.Matrix([1]))


# ----------------------------------------------------------------------------------------- choices


@pytest.mark.parametrize(
    "value, expected",
    [
        (3, 3),
        (3.0, 3),
        (sp.Integer(2), 2),
        (np.int64(2), 2),
        (1.5, 1.5),
        (True, True),
        ((3, 1), [3, 1]),
        ({2}, [2]),
        (sp.FiniteSet(1, 2), [1, 2]),
        (np.array([1, 2]), [1, 2]),
        (np.array([[1], [2]]), [1, 2]),  # arrays flattened (the self-check's)
        (sp.Matrix([1, 2]), [1, 2]),  # matrices (the checker's)
        ([(1, 2), 3], [[1, 2], 3]),  # ties nested (the checker's)
        ("  Joint  TWO ", "joint two"),  # case and spaces (the self-check's)
        (x, {"other": "sympy.core.symbol.Symbol"}),
        ([1, "a", None], [1, "a", {"other": "NoneType"}]),
    ],
)
def test_choice_value(value, expected):
    assert choice_value(value) == expected


# ----------------------------------------------------------------------------------------- both consumers accept each form

POINTS = [{"x": 0.7, "theta1": 0.3, "theta2": -1.1}, {"x": -0.4, "theta1": 1.2, "theta2": 2.0}]


def _selfcheck(value, ref, kind):
    return verdict(value, fingerprint(ref, kind, salt="9.9:a"), salt="9.9:a")


def _checker(value, ref, kind):
    """The checker's path: both answers exported as a kernel exports them, the reference read as
    build_reference reads it, the student's judged in the grader (read, described at the points, compared)."""
    entry = reference_answers({"a": exported(ref)}, {"a": kind})
    assert "error" not in entry["a"], entry
    v = judge_answer("a", entry["a"]["kind"], exported(value), Reference("t", "t", "p", "0" * 64, [], entry), POINTS, 1)
    return v.passed, v.message


SAME = [  # (kind, reference, an equivalent answer in another form)
    ("expr", M32, COLS),  # a list of columns
    ("expr", M32, [np.array([1, 2, 3]), np.array([4, 5, 6])]),
    ("expr", sp.Matrix([x, 1]), [x, 1]),
    ("expr", sp.Matrix([x, 1]), sp.Tuple(x, 1)),
    ("expr", sp.sin(x) ** 2, 1 - sp.cos(x) ** 2),
    ("expr", sp.Rational(1, 2), mpmath.mpf("0.5")),
    ("expr", sp.sqrt(2) / 2, np.float64(math.sqrt(2) / 2)),
    ("subspace", M32, [[1, 2, 3], [4, 5, 6]]),  # spanning vectors as lists
    ("subspace", M32, [sp.Matrix([5, 7, 9]), sp.Matrix([1, 2, 3])]),
    ("set", {th2: sp.FiniteSet(0, sp.pi)}, {th2: [0, sp.pi, 2 * sp.pi]}),
    ("set", sp.FiniteSet(sp.pi / 2), sp.pi / 2),  # a single value
    ("set", sp.FiniteSet(0, 1), np.array([1.0, 0.0])),
    ("set", [{th1: sp.FiniteSet(0)}, {th2: sp.FiniteSet(1)}], [{th2: {1}}, {th1: {0}}]),  # a union
    ("choice", (1, 3), [3, 1]),
    ("choice", (1, 3), sp.Matrix([3, 1])),
    ("choice", (1, 3), np.array([[1, 3]])),
    ("choice", 2, (2.0,)),
    ("choice", "Joint two", "joint   two"),
]


@pytest.mark.parametrize("kind, ref, value", SAME, ids=lambda v: type(v).__name__)
def test_the_selfcheck_and_the_checker_accept_the_same_forms(kind, ref, value):
    assert _selfcheck(value, ref, kind)[0] == "correct", _selfcheck(value, ref, kind)
    ok, message = _checker(value, ref, kind)
    assert ok, message


DIFFERENT = [
    ("expr", M32, M32.T),
    ("expr", M32, [[1, 2, 3], [4, 5, 6]]),  # rows are rows for an expr answer
    ("subspace", M32, [[1, 0, 0]]),
    ("set", sp.FiniteSet(0, 1), [0]),
    ("choice", (1, 3), [1]),
    ("choice", 2, "2"),
]


@pytest.mark.parametrize("kind, ref, value", DIFFERENT, ids=lambda v: type(v).__name__)
def test_the_selfcheck_and_the_checker_reject_the_same_mistakes(kind, ref, value):
    assert _selfcheck(value, ref, kind)[0] == "incorrect"
    assert not _checker(value, ref, kind)[0]


# ----------------------------------------------------------------------------------------- the shared table (issue 31)


def _grader(value, row, seed):
    from answer_table import grader_verdict

    return grader_verdict(value, row, seed)


def _home(value, row):
    from answer_table import home_verdict

    return home_verdict(value, row)


def _table_cases():
    from answer_table import rows

    for row in rows():
        yield pytest.param(row, row.right, True, "", id=f"{row.salt}-right")
        for i, v in enumerate(row.valid):
            yield pytest.param(row, v, True, "", id=f"{row.salt}-valid{i}")
        for i, (v, words) in enumerate(row.wrong):
            yield pytest.param(row, v, False, words, id=f"{row.salt}-wrong{i}")


@pytest.mark.parametrize("row, value, right, words", list(_table_cases()))
def test_the_selfcheck_and_the_grader_agree_on_the_table(row, value, right, words):
    """Every row of the shared table (tests/answer_table.py): the same verdict at home (public points) and in
    the grade (secret points, two seeds), and the mistake named in both."""
    status, home = _home(value, row)
    for seed in (3, 11):
        ok, graded = _grader(value, row, seed)
        assert ok == right, (seed, graded)
    assert (status == "correct") == right, home
    if words:
        assert words in home and words in graded, (home, graded)


def test_every_named_mistake_has_a_case_in_the_table():
    """Each conceptual mistake the course is about (issue 31, item 5) has a wrong answer in the shared table whose
    expected words are that mistake's: the table test above then proves that the self-check and the grader both
    say them (and test_grade_verdicts that no message states a graded value)."""
    from answer_table import rows
    from kinlib.course.answers import mistakes

    said = [words for row in rows() for _, words in row.wrong if words]
    named = {m.name: m.says for m in (*mistakes.CONCEPT_MISTAKES, *mistakes.SYMBOLIC_MISTAKES)}
    named |= {i.name: i.says for i in (*mistakes.FRAME_MISTAKES, *mistakes.SQUARE_MISTAKES)}
    named |= {
        "rank": mistakes.concept_says("rank", True, True),
        "constant": "is a constant",  # the constant's words (symbol notes, or concept_says for a constant answer)
        "rounded": mistakes.ROUNDED.says,
        "variable": mistakes.SET_VARIABLE.says,
        "product-order-shape": mistakes.PRODUCT_ORDER,
    }
    missing = {name: says for name, says in named.items() if not any(w in says for w in said)}
    assert not missing, f"mistakes with no case in tests/answer_table.py: {missing}"
