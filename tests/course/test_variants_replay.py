"""Replaying a notebook per variant (kinlib.course.variants.replay): which cells re-run, and, in a kernel, that
each variant's answers are those a fresh top-to-bottom run of that variant gives (computed here by hand, or by the
exact engine on the real notebook 05), whatever variant ran before it.
"""

from __future__ import annotations

import time
from pathlib import Path

import nbformat
import pytest
import sympy as sp
from nbformat.v4 import new_code_cell, new_markdown_cell, new_notebook

from kinlib.course.answers import wire
from kinlib.course.variants import spec as specmod
from kinlib.course.variants.replay import Session, plan, replay

ROOT = Path(__file__).resolve().parents[2]

SPEC_META = {
    "params": {
        "a": {"type": "number", "choices": ["1", "2", "3", "5"]},
        "t": {"type": "angle", "choices": ["0", "1/2"]},
    },
    "original": {"a": "1", "t": "0"},
    "parts": ["1.1", "1.3"],
}


def _sol(part, *names, kinds=None):
    meta = {"tags": ["solution"], "kinlib": {"part": part, "answers": list(names)}}
    if kinds:
        meta["kinlib"]["kinds"] = kinds
    return meta


def synthetic(extra_cells=()):
    """A small instructor notebook with variants: an answer that depends on ``a`` through an intermediate name (b),
    one that does not (y), one that depends on a value a dependent cell overwrites (c), a check cell that holds only
    for the instructor's numbers, a widget no answer needs, a printed picture, and a cell that fails for a = 3."""
    spec = specmod.Spec.from_metadata(SPEC_META)
    cells = [
        new_code_cell("import sympy as sp"),
        new_code_cell(specmod.assignment_source(spec, spec.original), metadata={"kinlib": {"variant": True}}),
        new_markdown_cell("**1.1 (2 points).** Find x.", metadata={"tags": ["question"]}),
        new_code_cell("b = a * 2"),  # 3: the intermediate name
        new_code_cell("x = sp.Matrix([[b, 1], [0, sp.cos(t)]])", metadata=_sol("1.1", "x")),  # 4
        new_code_cell("assert b == 2 and x[1, 1] == 1", metadata={"tags": ["check"]}),  # 5: the printed numbers
        new_markdown_cell("**1.2 (2 points).** Find y.", metadata={"tags": ["question"]}),
        new_code_cell("y = sp.Integer(7)", metadata=_sol("1.2", "y")),  # 7: independent
        new_code_cell("c = 10"),  # 8: overwritten below by a dependent cell
        new_markdown_cell("**1.3 (2 points).** Find z.", metadata={"tags": ["question"]}),
        new_code_cell("c = c + a\nz = c", metadata=_sol("1.3", "z")),  # 10: reads the c of cell 8
        new_code_cell("w = 1 / (int(a) - 3)"),  # 11: fails for a = 3
        new_code_cell('print("b is", b)'),  # 12: a picture of the numbers
        new_code_cell("import ipywidgets as widgets\nslider = widgets.IntSlider(value=int(a))\nslider"),  # 13
        *extra_cells,
    ]
    nb = new_notebook(cells=cells)
    nb.metadata["kinlib"] = {"notebook": "01_synthetic", "variants": SPEC_META}
    nb.metadata["kernelspec"] = {"name": "python3", "display_name": "Python 3", "language": "python"}
    return nb, spec


def _value(answer):
    assert "tree" in answer, answer
    return wire.load(answer["tree"])


def _same(got, want) -> bool:
    d = sp.simplify(got - want)
    return d.is_zero_matrix if isinstance(d, sp.MatrixBase) else d == 0


def expected(values):
    """The answers of a fresh run of the synthetic notebook for ``values``, computed by hand."""
    a = sp.Rational(values["a"])
    t = sp.Rational(values["t"]) * sp.pi
    return {"x": sp.Matrix([[2 * a, 1], [0, sp.cos(t)]]), "y": sp.Integer(7), "z": 10 + a}


def test_plan_reruns_dependents_restores_overwritten_values_and_skips_checks_and_unneeded_widgets():
    nb, _ = synthetic()
    p = plan(nb)
    assert p.variant == 1
    assert p.dependent == [3, 4, 10, 11, 12]  # b, then x through b; z; the failing cell; the printed picture
    assert p.restore == [8]  # c = 10 before c = c + a, else the next variant would start from the last one's c
    assert p.skipped == {5: "check", 13: "widget"}
    assert 7 not in p.rerun  # y does not depend on the numbers
    assert p.recapture == [4, 10]


def test_plan_needs_a_variant_cell():
    nb, _ = synthetic()
    nb.cells[1].metadata = {}
    with pytest.raises(ValueError, match="no variant cell"):
        plan(nb)


def test_plan_of_a_cell_that_rebinds_from_untainted_names_does_not_spread():
    """A dependent cell's statement that computes a name from untainted names only does not taint it."""
    cells = [
        new_code_cell("q = 1", metadata={"kinlib": {"variant": True}}),
        new_code_cell("J = 5"),
        new_code_cell("qn = float(q)\nJ = 5"),  # depends on q, but J does not
        new_code_cell("w = J + 1"),  # not a dependent
        new_code_cell("v = qn + 1"),
    ]
    p = plan(new_notebook(cells=cells))
    assert p.dependent == [2, 4]


def test_replay_synthetic(tmp_path):
    nb, spec = synthetic()
    path = tmp_path / "01_synthetic.ipynb"
    nbformat.write(nb, path)
    v2 = {"a": "2", "t": "1/2"}
    v5 = {"a": "5", "t": "0"}
    v3 = {"a": "3", "t": "0"}  # cell 11 divides by zero
    with Session(path, spec, timeout=120) as s:
        orig = s.original
        assert orig.error == "", orig.error
        for name, want in expected(spec.original).items():
            assert _same(_value(orig.answers[name]), want)
        runs = [s.run(v) for v in (v2, v5, v3, v2)]
    first, r5, r3, again = runs
    # each variant's answers are those of a fresh run for its numbers (the check cell, false for them, not run)
    for run in (first, r5, again):
        assert run.error == "", run.error
        want = expected(run.values)
        for name in ("x", "y", "z"):
            got = _value(run.answers[name])
            assert _same(got, want[name]), (run.values, name, got)
        assert run.seconds > 0
    # variant 2 does not depend on what ran before it (nothing, or variants 2, 5 and the failing 3)
    assert first.answers == again.answers and first.fingerprints == again.fingerprints
    # the failing variant names the cell and the error; the next one still runs in the same kernel
    assert r3.error.startswith("cell 11: ZeroDivisionError"), r3.error
    # fingerprints: recaptured for the answers that changed, the original's for the one that did not
    assert first.fingerprints[(4, "x")] != orig.fingerprints[(4, "x")]
    assert first.fingerprints[(7, "y")] == orig.fingerprints[(7, "y")]
    assert first.fingerprints[(10, "z")] != r5.fingerprints[(10, "z")]
    assert set(first.fingerprints) == set(orig.fingerprints)
    # outputs of the re-run cells: the printed picture with the variant's numbers; no check, no widget
    text = "".join(o.get("text", "") for o in first.outputs[12])
    assert text == "b is 4\n"
    assert 5 not in first.outputs and 13 not in first.outputs and 7 not in first.outputs


def test_replay_function_and_a_value_outside_the_spec(tmp_path):
    nb, spec = synthetic()
    path = tmp_path / "01_synthetic.ipynb"
    nbformat.write(nb, path)
    orig, runs = replay(path, spec, [{"a": "5", "t": "1/2"}])
    assert orig.error == "" and runs[0].error == ""
    assert _value(runs[0].answers["z"]) == 15
    with Session(path, spec) as s, pytest.raises(ValueError, match="values.a"):
        s.run({"a": "4", "t": "0"})


@pytest.mark.slow
def test_a_cell_that_times_out_ends_the_kernel_and_the_next_variant_gets_a_fresh_one(tmp_path):
    nb, spec = synthetic([new_code_cell("import time\nif a == 5:\n    time.sleep(10**6)\nslept = a")])
    path = tmp_path / "01_synthetic.ipynb"
    nbformat.write(nb, path)
    with Session(path, spec, timeout=20) as s:
        assert s.original.error == ""
        hung = s.run({"a": "5", "t": "0"})
        after = s.run({"a": "2", "t": "0"})
    assert hung.error == "cell 14: timed out after 20 s", hung.error
    assert after.error == "", after.error
    assert _value(after.answers["z"]) == 12


# ---------------------------------------------------------------------------------------------------
# The real notebook 05 with a variant cell for 5.3's configuration (until the notebooks carry theirs)

Q53 = {"type": "angle", "choices": [["1/4", "1/6"], ["-1/4", "3/4", "1/4", "-1/2"], ["1/4", "0"]]}


def notebook_05_with_q53_variant(folder: Path):
    nb = nbformat.read(ROOT / "notebooks" / "05_singularities_planar.ipynb", as_version=4)
    meta = {"params": {"q53": Q53}, "original": {"q53": ["1/4", "-1/4", "1/4"]}, "parts": ["5.3"]}
    spec = specmod.Spec.from_metadata(meta)
    at = next(i for i, c in enumerate(nb.cells) if "q53 = [pi / 4, -pi / 4, pi / 4]\n" in c.source)
    nb.cells[at].source = nb.cells[at].source.replace("q53 = [pi / 4, -pi / 4, pi / 4]\n", "")
    for c in nb.cells:  # the later cells take 5.3's configuration from the variant cell, not hard-coded
        c.source = c.source.replace("q53n = [np.pi / 4, -np.pi / 4, np.pi / 4]", "q53n = [float(t) for t in q53]")
    cell = new_code_cell(specmod.assignment_source(spec, spec.original), metadata={"kinlib": {"variant": True}})
    nb.cells.insert(at, cell)
    nb.metadata["kinlib"]["variants"] = meta
    assert specmod.mismatches(nb, spec) == []
    path = folder / "05_singularities_planar.ipynb"
    nbformat.write(nb, path)
    return path, spec, at


def _rank_by_hand(q):
    """Rank of 05's task rows at q: det J = L²(sin θ2 + cos θ2) (5.1), so 2 on the singular family, else 3."""
    t2 = sp.pi * sp.Rational(q[1])
    return 2 if sp.simplify(sp.sin(t2) + sp.cos(t2)) == 0 else 3


@pytest.mark.slow
def test_replay_05_q53(tmp_path, capsys):
    path, spec, at = notebook_05_with_q53_variant(tmp_path)
    p = plan(nbformat.read(path, as_version=4))
    assert at + 1 in p.dependent and p.restore == []
    singular = {"q53": ["1/6", "3/4", "0"]}
    regular = {"q53": ["1/4", "1/4", "1/4"]}
    other = {"q53": ["1/6", "-1/2", "1/4"]}
    t0 = time.monotonic()
    with Session(path, spec, timeout=300) as s:
        t_orig = time.monotonic() - t0
        orig = s.original
        assert orig.error == "", orig.error
        runs = [s.run(v) for v in (regular, singular, other, regular)]
    for run in runs:
        assert run.error == "", run.error
        rank = _rank_by_hand(run.values["q53"])
        assert _value(run.answers["rank53"]) == rank
        # the subspaces: range J has dimension rank, null Jᵀ the rest (as matrices of spanning columns)
        assert run.answers["can_move"]["kind"] == "subspace"
        # every answer outside 5.3 is the original's
        for name, a in orig.answers.items():
            if name not in ("rank53", "can_move", "cannot_move"):
                assert run.answers[name] == a, name
        # the figure of 5.3 (cell at + 8: the arm and its directions) re-drawn for the variant
        pngs = [o for i, outs in run.outputs.items() for o in outs if "image/png" in o.get("data", {})]
        assert pngs
    assert runs[0].answers == runs[3].answers  # "regular" after "singular" and "other" as before them
    assert _value(orig.answers["rank53"]) == 2 and runs[1].answers["rank53"] == orig.answers["rank53"]
    assert runs[0].answers["can_move"] != orig.answers["can_move"]
    per = [round(r.seconds, 2) for r in runs]
    with capsys.disabled():
        print(f"\n05 replay: original {t_orig:.1f} s, per variant {per} s, cells re-run {p.rerun}")
