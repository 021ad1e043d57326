"""The workbook self-check names the kind of mistake (kinlib.course.answers.mistakes), never the answer.

Each mistake is made here *forward*, independently of kinlib (a transpose is ``.T``, [v; ω] order is the
two halves of the rows stacked the other way, degrees are the radians times 180/π), on random right
answers (hypothesis), and the self-check's message for the wrong answer must name it; the instructor
checker (kinlib.course.answers.compare) must name the same mistake from the same answer. A wrong answer that is
no known mistake gets the neutral message, and no message holds a number of the right answer. The
picture cell after a wrong answer says "fix the answer above first" (a small workbook run in a kernel).
"""

from __future__ import annotations

import math

import nbformat
import numpy as np
import pytest
import sympy as sp
from hypothesis import HealthCheck, assume, given, settings
from hypothesis import strategies as st

from kinlib.course.answers import compare
from kinlib.course.workbook import needs
from kinlib.course.workbook.selfcheck import fingerprint, verdict

SALT = "9.1:ans"
th1, th2 = sp.symbols("theta1 theta2", real=True)
NEUTRAL = "its values differ from the answer's"
WORDS = {  # the words that name each mistake, in the self-check's and the checker's messages
    "negated": "wrong sign",
    "transposed": "transposed",
    "vw-order": "order",
    "columns": "columns swapped",
    "degrees": "degrees",
}
SETTINGS = settings(max_examples=25, deadline=None, suppress_health_check=[HealthCheck.too_slow])


# ---------------------------------------------------------------------------------------------------
# random right answers and the mistakes made forward


ROWS, COLS = st.sampled_from([1, 2, 3, 6]), st.integers(1, 4)


@st.composite
def matrices(draw, rows=ROWS, cols=COLS):
    """A matrix of large integers (≥ 1000, so its numbers are recognisable in a message), some entries
    depending on θ1, θ2."""
    r, c = draw(rows), draw(cols)
    assume(r * c > 1)
    ints = st.integers(1000, 99_999)
    entries = []
    for _ in range(r * c):
        a, b = draw(ints), draw(ints)
        shape = draw(st.sampled_from(["const", "sin", "cos"]))
        entries.append(a if shape == "const" else a * (sp.sin if shape == "sin" else sp.cos)(th1 - th2) + b)
    return sp.Matrix(r, c, entries)


def _forward(name, M):
    """The wrong answer a student writes when making mistake ``name`` on the right answer M (or None)."""
    r, c = M.shape
    if name == "negated":
        return -M
    if name == "transposed":
        return M.T
    if name == "vw-order":
        if r == 6:
            return M[3:, :].col_join(M[:3, :])
        if r == 3:
            return M[1:, :].col_join(M[:1, :])  # (v_x, v_y, ω_z)
        return None
    if name == "columns":
        return M[:, [1, 0] + list(range(2, c))] if c >= 2 else None
    if name == "degrees":
        return M * 180 / sp.pi
    raise ValueError(name)


def _num(M, k=0):
    vals = {th1: sp.Rational(3, 10) + k, th2: sp.Rational(-7, 10) + 2 * k}
    return np.array(sp.Matrix(M).subs(vals).evalf(20).tolist(), dtype=float)


def _same(A, B):
    A, B = sp.Matrix(A), sp.Matrix(B)
    return A.shape == B.shape and all(np.allclose(_num(A, k), _num(B, k), rtol=1e-12, atol=1e-9) for k in (0, 1))


def _explained_by(M, wrong):
    """The mistakes (made forward) that turn M into ``wrong``."""
    out = set()
    for name in WORDS:
        W = _forward(name, M)
        if W is not None and _same(W, wrong):
            out.add(name)
    return out


def _numbers_of(M) -> set:
    """The numbers of the right answer as they could be printed: its integers and decimals."""
    out = set()
    for e in M:
        for n in sp.sympify(e).atoms(sp.Integer):
            if abs(n) >= 1000:
                out |= {str(n), str(abs(n))}
    for k in range(2):
        out |= {f"{x:.4g}" for x in _num(M, k).ravel() if abs(x) >= 1}
    return out


def _leaks(message, M):
    return [n for n in _numbers_of(M) if n in message]


def _checker_message(wrong, M):
    """The instructor checker's message for ``wrong`` against M, both given as numbers at points."""

    def desc(X):
        X = sp.Matrix(X)
        vals = [[[float(v), 0.0] for v in _num(X, k).ravel()] for k in range(3)]
        return {"tag": "matrix", "shape": list(X.shape), "symbols": ["theta1", "theta2"], "values": vals}

    return compare.compare_expr(desc(wrong), {k: v for k, v in desc(M).items() if k != "tag"}, "A")


# ---------------------------------------------------------------------------------------------------
# matrices


@SETTINGS
@given(M=matrices(), name=st.sampled_from(sorted(WORDS)))
def test_each_mistake_is_named(M, name):
    wrong = _forward(name, M)
    assume(wrong is not None and not _same(wrong, M))
    spec = fingerprint(M, salt=SALT)
    status, message = verdict(wrong, spec, salt=SALT)
    assert status == "incorrect", message
    names = _explained_by(M, wrong)
    assert any(WORDS[n] in message for n in names), (names, message)
    assert not _leaks(message, M), message
    ok, said = _checker_message(wrong, M)  # the checker names the same mistake from the same answer
    assert not ok and any(WORDS[n] in said for n in names), (names, said)
    assert not _leaks(said, M), said


@SETTINGS
@given(M=matrices(), data=st.data())
def test_an_unrelated_wrong_answer_gets_the_neutral_message(M, data):
    other = data.draw(matrices(rows=st.just(M.shape[0]), cols=st.just(M.shape[1])))
    assume(not _same(other, M) and not _explained_by(M, other))
    status, message = verdict(other, fingerprint(M, salt=SALT), salt=SALT)
    assert status == "incorrect"
    # neutral, or the grader's words on its variables (symbol_notes: "uses θ1, which the problem does not")
    assert NEUTRAL in message or "which the problem does not" in message or "constant" in message, message
    assert not _leaks(message, M)


@SETTINGS
@given(M=matrices(rows=st.sampled_from([2, 3, 6]), cols=st.integers(2, 4)))
def test_a_transposed_answer_of_the_wrong_shape_is_named_with_its_shape(M):
    assume(M.shape[0] != M.shape[1])
    status, message = verdict(M.T, fingerprint(M, salt=SALT), salt=SALT)
    assert status == "incorrect" and "transposed" in message
    r, c = M.shape
    assert f"{c}×{r}" in message and f"{r}×{c}" in message  # the shapes: public in the spec anyway
    assert not _leaks(message, M)


def test_two_simple_mistakes_at_once_and_degrees_in_trig():
    M = sp.Matrix([[sp.sin(th1) * 1234, 5678], [sp.cos(th2) + 4321, 8765]])
    status, message = verdict(-M.T, fingerprint(M, salt=SALT), salt=SALT)
    assert "wrong sign" in message and "transposed" in message
    e = sp.sin(th2 + sp.pi / 4)
    status, message = verdict(sp.sin(th2 + 45), fingerprint(e, salt=SALT), salt=SALT)
    assert status == "incorrect" and "degrees inside sin/cos" in message


def test_a_wrong_scalar_reveals_no_factor():
    """The checker no longer prints "0.5 times the answer" (that gives the key away)."""
    ok, said = compare.compare_expr(
        {"tag": "scalar", "shape": [], "symbols": [], "values": [[[1.0, 0.0]]]},
        {"shape": [], "symbols": [], "values": [[[2.0, 0.0]]]},
        "d",
    )
    assert not ok and "constant" in said and "0.5" not in said and "2" not in said, said
    ok, said = compare.compare_expr(  # a function of θ off by a factor: that is named, without the factor
        {"tag": "scalar", "shape": [], "symbols": ["t"], "values": [[[1.0, 0.0]], [[3.0, 0.0]]]},
        {"shape": [], "symbols": ["t"], "values": [[[2.0, 0.0]], [[6.0, 0.0]]]},
        "d",
    )
    assert not ok and "constant factor" in said and "0.5" not in said and "2" not in said, said


# ---------------------------------------------------------------------------------------------------
# sets of angles, subspaces, choices

angles = st.lists(st.integers(-11, 12), min_size=1, max_size=4, unique=True)


@SETTINGS
@given(ks=angles, keyed=st.booleans())
def test_angle_sets_in_degrees_or_negated_are_named(ks, keyed):
    assume(any(k != 0 for k in ks))  # 0° is 0 rad: no mistake
    right = sp.FiniteSet(*[k * sp.pi / 12 for k in ks])
    degrees = sp.FiniteSet(*[15 * k for k in ks])
    negated = sp.FiniteSet(*[-k * sp.pi / 12 for k in ks])

    def wrap(s):
        return {th2: s} if keyed else s

    spec = fingerprint(wrap(right), "set", salt=SALT)
    status, message = verdict(wrap(degrees), spec, salt=SALT)
    assert status == "incorrect" and "degrees" in message
    mod = {k % 24 for k in ks}
    if {(-k) % 24 for k in ks} != mod:  # not symmetric: minus it is another set, and it is not named (issue 31:
        status, message = verdict(wrap(negated), spec, salt=SALT)  # 5.4's maximisers are 5.1's set negated)
        assert status == "incorrect" and "sign" not in message and "minus" not in message
    assert not any(f"{k}π" in message or f"{k}*pi" in message for k in ks if abs(k) > 1)


@SETTINGS
@given(
    cols=st.lists(st.lists(st.integers(-9, 9), min_size=3, max_size=3), min_size=1, max_size=2),
    mistake=st.sampled_from(["rows", "complement"]),
)
def test_subspace_mistakes_are_named(cols, mistake):
    A = sp.Matrix(cols).T  # 3 × k, columns span the answer
    assume(A.rank() in (1, 2))
    A = sp.Matrix.hstack(*A.columnspace())
    spec = fingerprint(A, "subspace", salt=SALT)
    if mistake == "rows":
        wrong, words = A.T, "as rows"
        assume(A.shape[1] != 3)
    else:
        wrong, words = sp.Matrix.hstack(*A.T.nullspace()), "complement"
    status, message = verdict(wrong, spec, salt=SALT)
    assert status == "incorrect" and words in message, message


def test_zero_based_joint_numbers_are_named():
    status, message = verdict((0, 2), fingerprint((1, 3), "choice", salt=SALT), salt=SALT)
    assert status == "incorrect" and "numbered from 1" in message
    status, message = verdict(2, fingerprint((1, 3), "choice", salt=SALT), salt=SALT)
    assert message == "not right yet: that is not the right choice"


# ---------------------------------------------------------------------------------------------------
# the picture cell after a wrong answer


def test_friendly_error_names_the_answer_and_keeps_the_traceback():
    try:
        np.zeros((2, 1))[1, 1]
    except IndexError as e:
        bundle = needs.friendly_error(["can_move"], type(e), e, e.__traceback__)
    assert "Fix `can_move` above first" in bundle["text/plain"] and "%tb" in bundle["text/plain"]
    assert len(bundle["text/plain"].splitlines()) == 1
    assert "IndexError" in bundle["text/html"] and "<details>" in bundle["text/html"]


def _outputs_text(cell):
    out = []
    for o in cell.outputs:
        if o.output_type == "stream":
            out.append(o.text)
        elif o.output_type == "error":
            out.append("ERROR " + o.ename + ": " + o.evalue)
        else:
            out.append(o.get("data", {}).get("text/plain", ""))
    return "".join(out)


@pytest.mark.slow
def test_a_picture_cell_after_a_wrong_answer_says_fix_the_answer(tmp_path):
    from kinlib.course.publish.execute import notebook_client

    spec = fingerprint(sp.Matrix([[1, 2], [3, 4]]), salt="1.1:J")
    code = nbformat.v4.new_code_cell
    cells = [
        code("%load_ext kinlib.course.workbook.selfcheck\nimport sympy as sp\nimport numpy as np"),
        code("J = sp.Matrix([1, 2])  # a wrong shape"),
        code(f'from kinlib.course.workbook.selfcheck import check\ncheck("1.1", J="{spec}")'),
        code("%%needs J\nnp.array(J.tolist(), dtype=float)[1, 1]  # a 'picture' that indexes the answer"),
        code("%tb"),
        code("np.zeros(2)[5]  # a cell that does not use answers: its error shows as usual"),
        code("J = sp.Matrix([[1, 2], [3, 4]])"),
        code(f'check("1.1", J="{spec}")'),
        code("%%needs J\nJ[7, 7]  # the answer is right: the error is a real one"),
    ]
    nb = nbformat.v4.new_notebook(cells=cells)
    nb.metadata["kernelspec"] = {"name": "python3", "display_name": "Python 3", "language": "python"}
    notebook_client(nb, timeout=120, kernel_name="python3", allow_errors=True).execute(cwd=str(tmp_path))
    texts = [_outputs_text(c) for c in nb.cells]
    assert "✗ wrong form" in texts[2]
    assert "Fix `J` above first" in texts[3] and "ERROR" not in texts[3] and "Traceback" not in texts[3]
    assert "IndexError" in texts[4]  # %tb: the real traceback is still there
    assert texts[5].startswith("ERROR IndexError")  # never swallowed where no answer is used
    assert "✓ correct" in texts[7]
    assert "ERROR IndexError" in texts[8] and "Fix" not in texts[8]


def test_every_mistake_message_is_free_of_numbers_of_a_key():
    """The fixed words of every named mistake hold no digit but column/row numbers and 45° (the example)."""
    from kinlib.course.answers import mistakes

    named = mistakes.MATRIX_MISTAKES + mistakes.SUBSPACE_MISTAKES + mistakes.SET_MISTAKES + mistakes.CONCEPT_MISTAKES
    named += (mistakes.SET_VARIABLE, mistakes.ROUNDED, mistakes.DECIMALS) + mistakes.SYMBOLIC_MISTAKES
    for m in named:
        words = m.message("") if isinstance(m, mistakes.Mistake) else m.says
        for tok in "".join(ch if ch.isdigit() else " " for ch in words).split():
            assert tok in {"45", "4", "1", "2", "3", "6", "180"}, (m.name, words)  # 1, 2: L1, L2 and 1/σ
    assert "pi/4" not in " ".join(m.message("") if isinstance(m, mistakes.Mistake) else m.says for m in named)
    assert math.isclose(float(sp.pi / 180), math.pi / 180)


# ---------------------------------------------------------------------------------------------------
# 5.5: the self-check judges the property of the student's own redesign (as the grader does)


def _planar_chain(joints):
    """A planar SerialChain from (kind, x, y) at home, screw axes written by hand: R about z through (x, y)
    is (0, 0, 1, y, −x, 0), a slide along (x, y) is (0, 0, 0, x, y, 0)."""
    from kinlib.chains import SerialChain

    cols = [[0, 0, 1, y, -x, 0] if k == "R" else [0, 0, 0, x, y, 0] for k, x, y in joints]
    return SerialChain(sp.eye(4), sp.Matrix(cols).T, name="my_arm")


def test_5_5_selfcheck_judges_the_students_robot():
    from kinlib import robots
    from kinlib.course.workbook import selfcheck

    spec = fingerprint(robots.planar_rpp(), "property:nonsingular", salt="5.5:redesign")
    assert spec == "property|nonsingular|-"  # the spec holds nothing of the printed design
    right = [robots.planar_rpp(), _planar_chain([("P", 1, 0), ("P", 0, 1), ("R", 2, 1)])]  # printed; another valid
    for arm in right:
        status, msg = verdict(arm, spec, salt="5.5:redesign")
        assert status == "correct", msg
    wrong = {
        "1 with no robot": 1,
        "2": sp.Integer(2),
        "cos²+1": sp.cos(th1) ** 2 + 1,
        "the original arm": robots.planar_offset_3r(),
        "joints on a line": _planar_chain([("R", 0, 0), ("R", 1, 0), ("R", 2, 0)]),
    }
    for label, value in wrong.items():
        status, msg = verdict(value, spec, salt="5.5:redesign")
        assert status == "incorrect", (label, msg)
        assert "R-P-P" not in msg and "prismatic" not in msg, msg
    assert "robot" in verdict(1, spec)[1]
    assert verdict(..., spec)[0] == "unanswered"
    with pytest.raises(ValueError, match="fails its property"):  # a solution notebook whose answer is not valid
        fingerprint(robots.planar_offset_3r(), "property:nonsingular")
    assert "SerialChain" in selfcheck.describe_answer(robots.planar_rpp(), "property:nonsingular")


# ---------------------------------------------------------------------------------------------------
# the public sample points cover the grader's domains (issue 31, item 3)


def test_public_points_cover_the_domains_of_the_grader_secret_points():
    """The grader draws a symbol's values from kinds.symbol_domain (angles over (-π, π), lengths in (0.5, 2), other
    signed symbols across 0); the self-check samples the same domains, one sample in each fifth, so that every
    sign change of a sinusoid in θ (a half-turn wide) holds a sample."""
    from kinlib.course.answers.kinds import symbol_domain
    from kinlib.course.grader.grade import make_points
    from kinlib.course.workbook.selfcheck import SAMPLE_POINTS, sample_value

    symbols = {"theta2": {}, "L": {"positive": True}, "F_x": {}, "thetadot1": {}, "L1": {"positive": True}}
    for seed in range(20):
        for p in make_points(symbols, seed, 5):
            for name, x in p.items():
                lo, hi = symbol_domain(name, bool(symbols[name].get("positive")))[1]
                assert lo <= x <= hi, (name, x)
    for name, signed in (("theta2", False), ("thetadot1", False), ("L", False), ("F_x", True), ("q3", False)):
        key, (lo, hi) = symbol_domain(name, positive=not signed and not name.startswith(("theta", "q")))
        xs = [float(sample_value(name, k, signed)) for k in range(SAMPLE_POINTS)]
        width = (hi - lo) / SAMPLE_POINTS
        assert sorted(int((x - lo) // width) for x in xs) == list(range(SAMPLE_POINTS)), (name, xs)
    # a half-turn wide window anywhere holds a sample of every angle: |sin(θ + a)| and sin(θ + a) differ there
    for a in np.linspace(-np.pi, np.pi, 37):
        for name in ("theta1", "theta2", "theta3", "q1"):
            assert any(np.sin(float(sample_value(name, k)) + a) < -0.05 for k in range(SAMPLE_POINTS)), (name, a)


def test_abs_det_and_signed_manipulability_fail_at_home_as_in_the_grade():
    """The issue's two examples: |det J| for det J and a signed w for w = √det(J Jᵀ) were ✓ in the workbook."""
    L = sp.Symbol("L", positive=True)
    det = sp.sqrt(2) * L**2 * sp.sin(th2 + sp.pi / 4)
    for right, wrong in ((det, sp.Abs(det)), (sp.Abs(det), det)):
        spec = fingerprint(right, salt="5.4:w")
        status, message = verdict(wrong, spec, salt="5.4:w")
        assert status == "incorrect" and "wrong sign at some configurations" in message, message
        assert verdict(right, spec, salt="5.4:w")[0] == "correct"


def test_decimals_get_a_word_about_rounding():
    """8 significant digits pass (the grader's tolerance) with a note; 3 fail, saying they are rounded."""
    L = sp.Symbol("L", positive=True)
    right = sp.sqrt(2) * L**2
    spec = fingerprint(right, salt="5.4:w_max")
    status, message = verdict(sp.Float("1.4142136") * L**2, spec, salt="5.4:w_max")
    assert status == "correct" and "decimals" in message
    status, message = verdict(sp.Float("1.41") * L**2, spec, salt="5.4:w_max")
    assert status == "incorrect" and "rounded" in message
    status, message = verdict(sp.Float("1.2") * L**2, spec, salt="5.4:w_max")
    assert status == "incorrect" and "decimals" in message


def test_yes_no_as_0_or_1_and_an_empty_set_for_a_dict():
    spec = fingerprint(False, "choice", salt="7.2:removes_all")
    assert verdict(0, spec, salt="7.2:removes_all")[0] == "correct"
    assert verdict(1, spec, salt="7.2:removes_all")[0] == "incorrect"
    spec = fingerprint({th2: sp.FiniteSet(0, sp.pi)}, "set", salt="7.2:singular_4r")
    for empty in (sp.EmptySet, [], set()):
        status, message = verdict(empty, spec, salt="7.2:singular_4r")
        assert status == "incorrect" and "form" not in message and "dict" not in message, message
    spec = fingerprint(sp.EmptySet, "set", salt="6.1:singular_set")
    for empty in (sp.EmptySet, [], set(), {th2: sp.EmptySet}):
        assert verdict(empty, spec, salt="6.1:singular_set")[0] == "correct", empty
