"""Replaying a notebook per variant (kinlib.course.variants.replay): which cells re-run, and, in a kernel, that
each variant's answers are those a fresh top-to-bottom run of that variant gives (computed here by hand, or by the
exact engine on the real notebook 05), whatever variant ran before it.
"""

from __future__ import annotations

import time
from pathlib import Path

import modern_robotics as mr
import nbformat
import numpy as np
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
    assert p.needed == [3, 4, 10]  # the failing cell and the picture are not needed for an answer
    assert p.answers_only == [1, 3, 4, 8, 10]


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


def test_session_arguments_are_checked_before_any_kernel(tmp_path):
    nb, spec = synthetic()
    path = tmp_path / "01_synthetic.ipynb"
    nbformat.write(nb, path)
    with pytest.raises(TypeError, match="spec"):
        Session(path, SPEC_META)
    with pytest.raises(ValueError, match="timeout"):
        Session(path, spec, timeout=0)
    with pytest.raises(FileNotFoundError, match="path"):
        Session(tmp_path / "missing.ipynb", spec)
    nb.cells[1].metadata = {}
    nbformat.write(nb, path)
    with pytest.raises(ValueError, match="no variant cell"):
        Session(path, spec)


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


def test_answers_only_gives_the_answers_of_a_full_run(tmp_path):
    nb, spec = synthetic()
    path = tmp_path / "01_synthetic.ipynb"
    nbformat.write(nb, path)
    v2, v3 = {"a": "2", "t": "1/2"}, {"a": "3", "t": "1/2"}
    with Session(path, spec) as s:
        lean = s.run(v2, pictures=False)
        full = s.run(v3)
        lean3 = s.run(v3, pictures=False)  # cell 11 (1 / 0 for a = 3) is not needed for an answer
        full2 = s.run(v2)
    assert lean.error == "" and lean3.error == "" and full.error.startswith("cell 11: ZeroDivisionError")
    assert lean.answers == full2.answers and lean.fingerprints == full2.fingerprints
    assert _value(lean3.answers["z"]) == 13
    assert 12 in full2.outputs and 12 not in lean.outputs


def test_replay_function_and_a_value_outside_the_spec(tmp_path):
    nb, spec = synthetic()
    path = tmp_path / "01_synthetic.ipynb"
    nbformat.write(nb, path)
    draws = [{"a": "5", "t": "1/2"}, {"a": "2", "t": "0"}, {"a": "3", "t": "1/2"}]
    orig, runs = replay(path, spec, draws, jobs=2)  # two kernels, the draws shared out between them
    assert orig.error == "" and runs[0].error == "" and runs[1].error == ""
    assert [r.values for r in runs] == draws
    assert [_value(r.answers["z"]) for r in runs[:2]] == [15, 12]
    assert runs[2].error.startswith("cell 11: ZeroDivisionError")
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
# The real notebook 05: 5.3's configuration comes from its variant cell (metadata.kinlib.variants)

Q53 = {"type": "angle", "choices": [["1/4", "1/6"], ["-1/4", "3/4", "1/4", "-1/2"], ["1/4", "0"]]}


def notebook_05_with_q53_variant(folder: Path):
    """05 as the instructor wrote it, its 5.3 domain widened (the test's draws include points off the singular
    family, which the build's proof would reject)."""
    nb = nbformat.read(ROOT / "notebooks" / "05_singularities_planar.ipynb", as_version=4)
    meta = nb.metadata["kinlib"]["variants"]
    meta["params"]["q53"] = Q53
    spec = specmod.Spec.from_metadata(meta)
    assert specmod.mismatches(nb, spec) == []
    path = folder / "05_singularities_planar.ipynb"
    nbformat.write(nb, path)
    return path, spec, specmod.variant_cell_index(nb)


def _subspace_numeric(answer):
    """A subspace answer's spanning columns as floats (L = 1, as 05's pictures)."""
    m = _value(answer)
    m = m.subs({s: 1 for s in m.free_symbols if s.name == "L"})
    return np.array(m, dtype=float)


def _task_svd(values):
    """Independent oracle: NumPy's SVD of modern_robotics' space Jacobian of 05's arm (L = 1), task rows."""
    q = [float(sp.pi * sp.Rational(t)) for t in values["q53"]]
    # 05's planar offset 3R arm (L = 1): joints about z_s through (0, 0), (1, 0), (2, 1); S_i = [ω; −ω × q_i]
    z = np.array([0.0, 0.0, 1.0])
    screws = np.array([np.r_[z, -np.cross(z, q_i)] for q_i in ([0, 0, 0], [1, 0, 0], [2, 1, 0])]).T
    return np.linalg.svd(mr.JacobianSpace(screws, q)[[2, 3, 4]])


@pytest.mark.slow
def test_replay_05_q53(tmp_path, capsys):
    path, spec, at = notebook_05_with_q53_variant(tmp_path)
    p = plan(nbformat.read(path, as_version=4))
    assert p.dependent and min(p.dependent) > at and p.restore == [] and p.needed
    # on the singular family (rank 2) and off it (rank 3: a draw the build's proof would reject)
    draws = [{"q53": ["1/6", "3/4", "0"]}, {"q53": ["1/4", "1/4", "1/4"]}, {"q53": ["1/6", "-1/2", "1/4"]}]
    t0 = time.monotonic()
    with Session(path, spec, timeout=300) as s:
        t_orig = time.monotonic() - t0
        orig = s.original
        assert orig.error == "", orig.error
        runs = [s.run(v) for v in (*draws, draws[0])]
        lean = [s.run(v, pictures=False) for v in draws[1:]]
    assert runs[0].answers == runs[3].answers  # the first draw after the others as before them
    assert [r.answers for r in lean] == [r.answers for r in runs[1:3]]
    changed = set()
    for run in runs:
        assert run.error == "", run.error
        U, sv, _ = _task_svd(run.values)
        rank = int(np.sum(sv > 1e-9))
        assert _value(run.answers["rank53"]) == rank
        C = _subspace_numeric(run.answers["can_move"])
        assert C.shape == (3, rank) and np.allclose(U[:, :rank] @ U[:, :rank].T @ C, C)
        if rank < 3:
            N = _subspace_numeric(run.answers["cannot_move"])
            assert N.shape == (3, 3 - rank) and np.allclose(U[:, :rank].T @ N, 0)  # null Jᵀ ⟂ range J
        changed |= {n for n, a in orig.answers.items() if run.answers[n] != a}
        # the figure of 5.3 shows its answers (the directions): no student's page shows it, so it is not re-run
        assert set(run.outputs) <= set(p.dependent)
    assert [_value(r.answers["rank53"]) for r in runs] == [2, 3, 3, 2]
    assert changed <= {"rank53", "can_move", "cannot_move"} and "can_move" in changed
    per = [round(r.seconds, 2) for r in runs]
    per_lean = [round(r.seconds, 2) for r in lean]
    with capsys.disabled():
        print(
            f"\n05 replay: original {t_orig:.1f} s, per variant {per} s (cells {p.rerun}), "
            f"answers only {per_lean} s (cells {p.answers_only})"
        )
