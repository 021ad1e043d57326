"""The reading structure of every notebook and of every workbook made from it (issue 21; the tags are
documented in notebooks/README.md):

* each notebook ``notebooks/NN_*.ipynb`` opens with its ``objectives`` (with a time estimate) and ends with a
  ``summary`` ("Next: ..."); it asks at least one ``predict`` question, each immediately followed by its
  ``predict-answer``, folded (``metadata.jupyter.source_hidden``); its ``check`` and ``hint`` cells are folded; its
  ``mistake`` callouts say "Common mistake";
* each workbook (made here from the notebook with stand-in fingerprints: no kernel runs) keeps the hints, the
  mistakes, the predictions and their answers, folded where they should be; a prediction whose answer is graded
  (``predict-answer`` with ``metadata.kinlib.part``) points to the part's self-check instead of answering; no line
  of a solution or check cell is left;
* the examples of answer forms written under the workbook stubs are accepted by the self-check's comparers;
* ``--audience students`` output (built from the fixture notebook, no site, no PDFs) holds no solution anywhere,
  and the in-browser site is given no solution notebook.
"""

from __future__ import annotations

import re
from pathlib import Path

import nbformat
import pytest
import sympy as sp

from kinlib.course import schema
from kinlib.course.publish import aids, handouts
from kinlib.course.workbook.selfcheck import fingerprint

ROOT = Path(__file__).resolve().parents[2]
NOTEBOOKS = sorted((ROOT / "notebooks").glob("[0-9][0-9]_*.ipynb"))
FIXTURES = ROOT / "tests" / "fixtures" / "handouts"
VENDOR = ROOT / "build" / "vendor"
PARAMS = [pytest.param(p, id=p.stem) for p in NOTEBOOKS]


def _tags(cell) -> set:
    return set(schema.cell_tags(cell))


def _with(nb, tag) -> list:
    return [c for c in nb.cells if tag in _tags(c)]


@pytest.mark.parametrize("path", PARAMS)
def test_notebook_has_the_reading_structure(path):
    nb = nbformat.read(path, as_version=4)
    cells = nb.cells
    objectives = [i for i, c in enumerate(cells) if schema.OBJECTIVES in _tags(c)]
    assert len(objectives) == 1 and objectives[0] <= 2, "one objectives cell, right after the title/introduction"
    text = cells[objectives[0]].source
    assert cells[objectives[0]].cell_type == "markdown" and "By the end of this notebook you can" in text
    assert re.search(r"Time:(?:\*\*)? about \d+ minutes", text), "a time estimate: Time: about N minutes"
    assert 3 <= len(re.findall(r"^\* ", text, re.M)) <= 5, "3 to 5 objectives"

    last = cells[-1]
    assert last.cell_type == "markdown" and schema.SUMMARY in _tags(last), "the last cell is the summary"
    assert 4 <= len(re.findall(r"^\* ", last.source, re.M)) <= 8 and "Next:" in last.source
    assert len(_with(nb, schema.SUMMARY)) == 1

    predicts = [i for i, c in enumerate(cells) if schema.PREDICT in _tags(c)]
    assert predicts, "at least one predict cell"
    for i in predicts:
        assert cells[i].cell_type == "markdown"
        answer = cells[i + 1] if i + 1 < len(cells) else None
        assert answer is not None and schema.PREDICT_ANSWER in _tags(answer), f"cell {i}: predict without its answer"
        assert answer.cell_type == "markdown" and schema.is_source_hidden(answer), f"cell {i + 1}: answer not folded"
    for i, c in enumerate(cells):
        tags = _tags(c)
        if schema.PREDICT_ANSWER in tags:
            assert i > 0 and schema.PREDICT in _tags(cells[i - 1]), f"cell {i}: an answer without its prediction"
        if tags & {schema.CHECK, schema.HINT}:
            assert schema.is_source_hidden(c), f"cell {i} ({', '.join(sorted(tags))}) is not folded"
        if schema.MISTAKE in tags:
            assert c.cell_type == "markdown" and c.source.startswith("**Common mistake"), f"cell {i}"
        aids = {schema.HINT, schema.PREDICT, schema.PREDICT_ANSWER, schema.MISTAKE, schema.GIVEN}
        assert not (tags & aids and tags & schema.ANSWER_TAGS), f"cell {i}: a reading aid is never a solution or check"


def _stand_in_fingerprints(nb) -> tuple:
    groups = schema.answer_groups(nb)
    fps = {(idx, name): {"spec": "none||", "describe": ""} for g in groups for _, name, _, idx in g.answers}
    return groups, fps


def _answer_lines(nb) -> set:
    """Lines of solution and check cells that would give an answer away (long enough to be specific, and
    not also in a cell the student is given)."""
    lines, given = set(), set()
    for c in nb.cells:
        shortest = 25 if c.cell_type == "code" else 60  # prose repeats short phrases ("no singular configuration")
        for line in c.source.splitlines():
            line = line.strip()
            if len(line) >= shortest and not line.startswith("#"):
                (lines if _tags(c) & schema.ANSWER_TAGS else given).add(line)
    return lines - given


@pytest.mark.parametrize("path", PARAMS)
def test_workbook_keeps_the_help_and_no_solution(path):
    nb = nbformat.read(path, as_version=4)
    groups, fps = _stand_in_fingerprints(nb)
    wb = handouts.make_workbook(nb, groups, fps)
    by_id = {c.get("id"): c for c in wb.cells}
    for c in nb.cells:
        tags = _tags(c)
        aid = tags & {schema.HINT, schema.MISTAKE, schema.PREDICT, schema.PREDICT_ANSWER, schema.GIVEN}
        if not aid or tags & schema.ANSWER_TAGS:
            continue
        kept = by_id.get(c.get("id"))
        assert kept is not None, f"{c.get('id')} ({', '.join(sorted(aid))}) left out of the workbook"
        if tags & {schema.HINT, schema.PREDICT_ANSWER}:
            assert schema.is_source_hidden(kept), f"{c.get('id')}: not folded in the workbook"
        if aids.graded_prediction(c):
            assert "self-check of part" in kept.source and kept.source != c.source
        elif schema.PREDICT_ANSWER in tags or schema.HINT in tags:
            assert kept.source == c.source
    assert _with(wb, schema.PREDICT), "the workbook asks the predictions too"
    text = "\n".join(c.source for c in wb.cells)
    leaked = sorted(line for line in _answer_lines(nb) if line in text)
    assert not leaked, leaked[:5]
    assert not _with(wb, schema.CHECK)
    for c in _with(wb, schema.SELFCHECK) + _with(wb, "workbook-setup"):  # machinery: folded, still run
        assert schema.is_source_hidden(c)


def _examples(lines) -> list:
    """The SymPy expressions written in the examples (``sp.X(...)``, balanced parentheses, no '...')."""
    text = " ".join(lines)
    found, i = [], 0
    while (i := text.find("sp.", i)) >= 0:
        if i > 0 and (text[i - 1].isalnum() or text[i - 1] in "._("):
            i += 3
            continue
        depth, j = 0, i
        while j < len(text):
            if text[j] == "(":
                depth += 1
            elif text[j] == ")":
                depth -= 1
                if depth == 0:
                    break
            elif depth == 0 and not (text[j].isalnum() or text[j] in "._"):
                j -= 1
                break
            j += 1
        expr = text[i : j + 1]
        if "..." not in expr:
            found.append(expr)
        i = j + 1
    return found


def test_answer_form_examples_are_accepted():
    """What the stubs show is what the self-check compares as meant: a periodic family is the same set of
    angles as its members in one turn, a tie is a tuple in any order, a subspace any basis of the span."""
    env = {"sp": sp, "n": sp.Symbol("n", integer=True)}
    sets = [eval(e, env) for e in _examples(aids.ANSWER_FORM_EXAMPLES["set"])]  # noqa: S307 (our own text)
    assert any(isinstance(s, sp.ImageSet) for s in sets) and any(isinstance(s, sp.FiniteSet) for s in sets)
    family = next(s for s in sets if isinstance(s, sp.ImageSet))
    assert fingerprint(family, "set") == fingerprint(sp.FiniteSet(sp.pi / 4, -3 * sp.pi / 4), "set")
    finite = next(s for s in sets if isinstance(s, sp.FiniteSet))
    assert fingerprint(finite, "set") == fingerprint(sp.FiniteSet(3 * sp.pi / 2, sp.pi / 2), "set")
    choice = " ".join(aids.ANSWER_FORM_EXAMPLES["choice"])
    assert "(1, 2)" in choice and fingerprint((1, 2), "choice") == fingerprint((2, 1), "choice")
    assert fingerprint(2, "choice") != fingerprint((1, 2), "choice")
    (basis,) = [eval(e, env) for e in _examples(aids.ANSWER_FORM_EXAMPLES["subspace"])]  # noqa: S307
    other = sp.Matrix([[1, 1], [1, -1], [0, 0]])
    assert fingerprint(basis, "subspace") == fingerprint(other, "subspace")


def test_stubs_show_the_examples():
    cell = nbformat.v4.new_code_cell(
        "x = 1", metadata={"tags": ["solution"], "kinlib": {"part": "5.1", "answers": ["x"], "kinds": {"x": "set"}}}
    )
    stub = aids.stub(cell, {})
    assert "sp.ImageSet(sp.Lambda(n, sp.pi / 4 + n * sp.pi), sp.Integers)" in stub
    assert "x = ...  # TODO" in stub and "x = 1" not in stub


# ---------------------------------------------------------------------------------------------------
# --audience students: no solution in any form


@pytest.fixture(scope="module")
def students(tmp_path_factory, monkeypatch_module):
    from kinlib.course.publish import lite

    out = tmp_path_factory.mktemp("students") / "handouts"
    (out / "solutions").mkdir(parents=True)
    (out / "solutions" / "01_fixture_jacobians.html").write_text("left by an earlier full build")
    seen = {}

    def fake_build_lite(out_, notebooks, log=print):  # the site itself is tests/course/test_lite.py's business
        seen["solutions"] = list(notebooks)
        seen["workbooks"] = sorted(p.name for p in (Path(out_) / "workbooks").glob("*.ipynb"))

    monkeypatch_module.setattr(lite, "build_lite", fake_build_lite)
    handouts.build(
        FIXTURES,
        out,
        vendor=VENDOR,
        jobs=1,
        verify=False,
        site=True,
        pdfs=False,
        audience="students",
        log=lambda s: None,
    )
    return out, seen


@pytest.fixture(scope="module")
def monkeypatch_module():
    mp = pytest.MonkeyPatch()
    yield mp
    mp.undo()


def test_students_output_has_no_solution(students):
    out, seen = students
    source = nbformat.read(FIXTURES / "01_fixture_jacobians.ipynb", as_version=4)
    secrets = _answer_lines(source)
    secrets |= {  # the check cells' printed lines (the ✓ lines) and the solution markdown
        line.strip()
        for c in source.cells
        if _tags(c) & schema.ANSWER_TAGS
        for o in c.get("outputs", [])
        for line in o.get("text", "").splitlines()
        if len(line.strip()) >= 20
    }
    assert secrets
    assert not (out / "solutions").exists() and not (out / "pdf" / "solutions").exists()
    files = [p for p in out.rglob("*") if p.is_file() and "assets" not in p.relative_to(out).parts]
    assert files
    for p in files:
        text = p.read_text(encoding="utf-8", errors="replace")
        if p.suffix == ".pdf":
            import subprocess

            text = subprocess.run(["pdftotext", str(p), "-"], capture_output=True, text=True, check=True).stdout
        found = [s for s in secrets if s in text]
        assert not found, (p.relative_to(out), found[:3])
        assert "solutions/" not in text, (p.relative_to(out), "links to a solution")
    index = (out / "index.html").read_text()
    assert 'href="problems/01_fixture_jacobians.html"' in index and "Solutions" not in index
    # the in-browser site gets the workbooks and no solution notebook
    assert seen == {"solutions": [], "workbooks": ["01_fixture_jacobians.ipynb"]}


def test_audience_is_checked(tmp_path):
    with pytest.raises(ValueError, match="audience"):
        handouts.build(FIXTURES, tmp_path / "out", audience="teachers", log=lambda s: None)
