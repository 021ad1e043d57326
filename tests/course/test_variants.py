"""Per-student variants (issue 33): the spec, the draw, the structure proof and the key, without a kernel.

The kernel side (replay, build_key on the real notebooks) is in tests/course/test_variants_build.py.
"""

from __future__ import annotations

import json
import sys
from fractions import Fraction

import numpy as np
import pytest
import sympy as sp
from hypothesis import given, settings
from hypothesis import strategies as st

from kinlib.course.answers import wire
from kinlib.course.answers.choice import describe_choice
from kinlib.course.variants import draw as drawmod
from kinlib.course.variants import key as keymod
from kinlib.course.variants import spec as specmod
from kinlib.course.variants import structure
from kinlib.manipulability import strongest_joints
from kinlib.singularities import evaluate_at, rank_at

SECRET = b"k" * 32

fractions = st.fractions(min_value=-4, max_value=4, max_denominator=12)


def _text(f: Fraction) -> str:
    return str(f.numerator) if f.denominator == 1 else f"{f.numerator}/{f.denominator}"


@st.composite
def specs(draw):
    """A random valid spec: 1-3 parameters, scalars or vectors, angles or numbers."""
    n = draw(st.integers(1, 3))
    params, original = {}, {}
    for i in range(n):
        kind = draw(st.sampled_from(specmod.TYPES))
        width = draw(st.integers(0, 3))  # 0: a scalar
        elems = [
            sorted({_text(f) for f in draw(st.lists(fractions, min_size=1, max_size=5))}) for _ in range(max(width, 1))
        ]
        name = f"p{i}"
        params[name] = {"type": kind, "choices": elems if width else elems[0]}
        original[name] = [e[0] for e in elems] if width else elems[0][0]
    return specmod.Spec.from_metadata({"params": params, "original": original})


@given(specs(), st.text(min_size=1, max_size=20).filter(lambda s: "\0" not in s), st.integers(0, 30))
@settings(max_examples=150)
def test_a_draw_is_a_point_of_the_domain_and_reproducible(spec, student, attempt):
    values = drawmod.draw(SECRET, student, "05_x", spec, attempt)
    specmod.check_values(spec, values)
    assert values == drawmod.draw(SECRET, student, "05_x", spec, attempt)
    # the variant cell and the markdown are written from these values, and read back as them
    src = specmod.assignment_source(spec, values)
    ns: dict = {}
    exec(compile(src, "<variant cell>", "exec"), ns)  # the instructor's generated code, not a student's
    for p in spec.params:
        want = specmod.value(p, values[p.name])
        got = ns[p.name]
        assert (list(map(sp.sympify, got)) if p.vector else sp.sympify(got)) == want


def test_the_draw_depends_on_secret_student_notebook_and_attempt_and_covers_the_choices():
    spec = specmod.Spec.from_metadata(
        {
            "params": {"q": {"type": "angle", "choices": [[str(k) + "/12" for k in range(-11, 13)], ["-1/4", "3/4"]]}},
            "original": {"q": ["3/12", "-1/4"]},
        }
    )
    seen = {drawmod.variant_key(drawmod.draw(SECRET, f"s{i}", "05", spec)) for i in range(400)}
    assert len(seen) > 40  # 48 variants: nearly all drawn by 400 students
    # each input changes the draw for most students (one student may coincide by chance: test several)
    for vary in range(4):
        same = 0
        for i in range(30):
            args = [SECRET, f"t{i}", "05", spec, 0]
            other = list(args)
            other[[0, 1, 2, 4][vary]] = [b"j" * 32, f"u{i}", "04", 1][vary]
            same += drawmod.draw(*args[:4], attempt=args[4]) == drawmod.draw(*other[:4], attempt=other[4])
        assert same < 8, vary


@pytest.mark.parametrize(
    "meta, field",
    [
        (None, "variants"),
        ({"params": {}}, "variants"),
        (
            {"params": {"class": {"type": "angle", "choices": ["1"]}}, "original": {"class": "1"}},
            "variants.params.class",
        ),
        ({"params": {"q": {"type": "length", "choices": ["1"]}}, "original": {"q": "1"}}, "variants.params.q.type"),
        ({"params": {"q": {"type": "angle", "choices": []}}, "original": {"q": "1"}}, "variants.params.q.choices"),
        (
            {"params": {"q": {"type": "angle", "choices": ["1", "1"]}}, "original": {"q": "1"}},
            "variants.params.q.choices",
        ),
        ({"params": {"q": {"type": "angle", "choices": ["__import__('os')"]}}, "original": {"q": "1"}}, "choices[0]"),
        ({"params": {"q": {"type": "angle", "choices": ["1/0"]}}, "original": {"q": "1"}}, "choices[0]"),
        ({"params": {"q": {"type": "angle", "choices": ["1"]}}, "original": {}}, "variants.original"),
        ({"params": {"q": {"type": "angle", "choices": ["1"]}}, "original": {"q": "2"}}, "variants.original.q"),
    ],
)
def test_a_malformed_spec_is_refused_naming_the_field(meta, field):
    with pytest.raises(ValueError, match=field.replace("[", r"\[").replace("]", r"\]")):
        specmod.Spec.from_metadata(meta)


@given(st.text(max_size=200))
@settings(max_examples=200)
def test_markdown_templates_substitute_placeholders_and_evaluate_nothing(text):
    """Whatever the template holds (it is instructor data, but still: no code runs), only {{name}} and
    {{name[i]}} are replaced; an unknown name is a ValueError, never evaluated."""
    spec = specmod.Spec.from_metadata(
        {"params": {"q": {"type": "angle", "choices": [["1/4"], ["-1/2"]]}}, "original": {"q": ["1/4", "-1/2"]}}
    )
    events = []

    def hook(event, args):
        if event in ("exec", "compile", "import"):
            events.append(event)

    sys.addaudithook(hook)  # audit hooks cannot be removed: it only records
    start = len(events)
    try:
        out = specmod.render_markdown(text + " {{q}} {{q[1]}}", spec, spec.original)
    except ValueError as exc:
        assert "variant_markdown" in str(exc)
    else:
        assert out.endswith(r" (\pi/4, -\pi/2) -\pi/2")
    assert events[start:] == []


# ---------------------------------------------------------------------------------------------------
# The structure proof, against independent computation


def _expr(value, kind="expr"):
    return {"kind": kind, "tree": wire.dump(value), "symbols": {}}


def _choice(value):
    return {"kind": "choice", "choice": describe_choice(value)}


def _planar_jacobian(lengths):
    """The task rows (ω_z, v_x, v_y) of J_s for a planar RRR arm with links along x at home (independent: by hand)."""
    th = sp.symbols("theta1:4", real=True)
    pts, angle, x, y = [], 0, 0, 0
    for i in range(3):
        pts.append((x, y))
        angle += th[i]
        x, y = x + lengths[i] * sp.cos(angle), y + lengths[i] * sp.sin(angle)
    cols = [[1, py, -px] for px, py in pts]
    return sp.Matrix(cols).T, th


angle = st.integers(-11, 12).map(lambda k: sp.Rational(k, 12) * sp.pi)


@given(st.tuples(angle, angle), st.sampled_from([0, sp.pi]), st.tuples(angle, angle, angle))
@settings(max_examples=25, deadline=None)
def test_rank_structure_matches_numpy_at_singular_and_regular_points(free, on_family, other):
    """5.3's structure (the rank at the asked θ): a point on the singular family θ2 ∈ {0, π} keeps the original's
    rank 2 (the variant is kept); a point off it has rank 3 and is rejected, with the reason saying so. The exact
    rank is checked against NumPy's SVD rank of the same matrix in floats."""
    J, th = _planar_jacobian([1, 1, 1])
    q_orig = [sp.pi / 4, 0, sp.pi / 4]
    q_var = [free[0], on_family, free[1]]
    sig = {}
    for name, q in (("orig", q_orig), ("var", q_var), ("other", list(other))):
        r = rank_at(J, q, th)
        num = np.linalg.matrix_rank(np.array(evaluate_at(J, q, th), dtype=float), tol=1e-9)
        assert r == num
        sig[name] = structure.signature({"rank53": _expr(sp.Integer(r))})
    assert structure.differences(sig["orig"], sig["var"]) == []
    diff = structure.differences(sig["orig"], sig["other"])
    if sp.sin(other[1]) != 0:
        assert diff == [f"rank53: 2 in the original, {3} here"]
    else:
        assert diff == []


@given(st.tuples(angle, angle, angle), st.sampled_from([0, 1]))
@settings(max_examples=40, deadline=None)
def test_a_winner_stays_a_winner_and_a_tie_a_tie(q, row):
    """4.1's structure: the exact winner (strongest_joints) against NumPy's |entries| (a tie when two are within
    1e-12); the proof keeps a variant exactly when both agree with the original's form."""
    th = sp.symbols("theta1:4", real=True)
    # ṗ_x, ṗ_y of the tool of the planar arm, links of length 1: the derivatives of its position
    p = sp.Matrix([sum(sp.cos(sum(th[: i + 1])) for i in range(3)), sum(sp.sin(sum(th[: i + 1])) for i in range(3))])
    Jp = p.jacobian(th)
    r = evaluate_at(Jp, list(q), th)[row, :]
    winner = strongest_joints(r)
    mags = np.abs(np.array(r, dtype=float)).ravel()
    best = np.flatnonzero(mags >= mags.max() - 1e-12) + 1
    assert (winner if isinstance(winner, tuple) else (winner,)) == tuple(int(b) for b in best)
    orig = structure.signature({"joint_a": _choice(2)})
    got = structure.signature({"joint_a": _choice(winner)})
    assert (structure.differences(orig, got) == []) == (len(best) == 1)


def test_families_count_and_variables_decide_the_set_structure():
    th2, th3 = sp.symbols("theta2 theta3", real=True)
    k = sp.Symbol("k", integer=True)
    fam = lambda a: sp.ImageSet(sp.Lambda(k, a + sp.pi * k), sp.Integers)  # noqa: E731
    one = structure.signature({"s": _expr({th2: fam(-sp.pi / 4)}, "set")})
    moved = structure.signature({"s": _expr({th2: fam(sp.pi / 3)}, "set")})
    two = structure.signature({"s": _expr({th2: sp.Union(fam(0), fam(sp.pi / 3))}, "set")})
    other_var = structure.signature({"s": _expr({th3: fam(0)}, "set")})
    assert structure.differences(one, moved) == []
    assert "2 singular families" in structure.differences(one, two)[0]
    assert structure.differences(one, other_var)


def test_a_zero_in_symbols_changes_the_structure_a_zero_number_does_not():
    th = sp.Symbol("theta2", real=True)
    a = structure.signature({"c": _expr(sp.Matrix([[sp.sqrt(2) / 2, 1, -1]]))})
    b = structure.signature({"c": _expr(sp.Matrix([[sp.cos(sp.pi / 5), 0, sp.sqrt(2) - 2 * sp.cos(sp.pi / 4)]]))})
    assert structure.differences(a, b) == []  # a joint that does not move the tool: still a row of 3 numbers
    s1 = structure.signature({"J": _expr(sp.Matrix([[sp.sin(th), 1]]))})
    s0 = structure.signature({"J": _expr(sp.Matrix([[sp.sin(th) ** 2 + sp.cos(th) ** 2 - 1, 1]]))})
    assert structure.differences(s1, s0) == [
        "J: a 1×2 matrix with 0 zero entries in the original, a 1×2 matrix with 1 zero entry here"
    ]
    n1 = structure.signature({"w": _expr(sp.sqrt(2) - 2 * sp.cos(sp.pi / 4) + 1)})
    n0 = structure.signature({"w": _expr(sp.sqrt(2) - 2 * sp.cos(sp.pi / 4))})
    assert structure.differences(n1, n0)  # the answer itself becoming 0 is a different answer


# ---------------------------------------------------------------------------------------------------
# The key: signed, refused when damaged, the student's own reference


def _tiny_key():
    nk = keymod.NotebookKey(
        "05_x",
        "0" * 64,
        {"params": {"L": {"type": "number", "choices": ["1", "2"]}}, "original": {"L": "1"}},
        {"L": "1"},
        variants={
            "v2": keymod.Variant({"L": "2"}, {"r": _expr(sp.Integer(2))}, {"3|r": {"spec": "x", "describe": ""}})
        },
        students={"ada": "v2"},
    )
    return keymod.Key({"05_x": nk}, [{"id": "ada", "name": "", "email": ""}])


def test_a_damaged_or_edited_key_is_refused_not_trusted(tmp_path):
    p = keymod.write_key(tmp_path / "key.json", _tiny_key(), SECRET)
    assert keymod.read_key(p, SECRET).notebooks["05_x"].students == {"ada": "v2"}
    d = json.loads(p.read_text())
    d["key"]["notebooks"]["05_x"]["students"]["ada"] = "v9"
    (tmp_path / "edited.json").write_text(json.dumps(d))
    assert keymod.read_key(tmp_path / "edited.json", SECRET) is None
    raw = p.read_bytes()
    for cut in (0, 1, len(raw) // 2, len(raw) - 1):
        (tmp_path / "cut.json").write_bytes(raw[:cut])
        assert keymod.read_key(tmp_path / "cut.json", SECRET) is None
    (tmp_path / "junk.json").write_text('{"key": [], "tag": 3}')
    assert keymod.read_key(tmp_path / "junk.json", SECRET) is None
    assert keymod.read_key(p, b"z" * 32) is None


@pytest.mark.parametrize(
    "text, match",
    [
        ("id\n../etc\n", "row 2"),
        ("id\n" + "a" * 65 + "\n", "row 2"),
        ("id,name\nada,A\nbob,B\nada,C\n", "row 4: id 'ada' appears twice"),
        ("", "empty"),
        ("student\nada\n", "no 'id' column"),
    ],
)
def test_a_bad_roster_row_is_named(text, match):
    with pytest.raises(ValueError, match=match):
        keymod.read_roster_text(text)


def test_a_variants_pictures_of_a_cell_that_states_an_answer_are_only_its_students_version():
    """A re-run cell marked "reveals" (its picture states a graded answer) keeps, in the proved variant the
    per-student pages are made from, only the students' version the replay probed, never the full picture."""
    from kinlib.course.variants.key import _variant_from_run
    from kinlib.course.variants.replay import Run

    run = Run(
        {"q": "1"}, {}, {(3, "x"): {"spec": "s"}}, {5: ["marked singular"], 6: ["arm"]}, "", 0.0, {5: ["arm only"]}
    )
    v = _variant_from_run(run)
    assert v.outputs == {5: ["arm only"], 6: ["arm"]} and v.fingerprints == {"3|x": {"spec": "s"}}


@given(st.integers(-11, 12))
@settings(max_examples=24, deadline=None)
def test_a_subspace_that_lines_up_with_the_axes_is_another_form(k):
    """5.3's range J at θ1 = kπ/12 (a rotation of the original's tilted plane, θ1 = π/4): the same structure
    unless the lost direction (−sin, cos) lines up with an axis (θ1 a multiple of π/2), which NumPy sees as a
    zero component of it."""
    t = sp.pi * k / 12
    lost = sp.Matrix([0, -sp.sin(t + sp.pi / 4), sp.cos(t + sp.pi / 4)])  # the original's (0, 1, 1) direction turned
    rng = sp.Matrix.hstack(sp.Matrix([1, 0, 0]), sp.Matrix([0, lost[2], -lost[1]]))
    orig = structure.signature({"c": _expr(sp.Matrix([[1, 0], [0, 1], [0, -1]]), "subspace")})
    got = structure.signature({"c": _expr(rng, "subspace")})
    numeric = np.array(lost[1:, 0].evalf(30), dtype=float).ravel()
    aligned = bool(np.any(np.abs(numeric) < 1e-12))
    assert (structure.differences(orig, got) != []) == aligned
