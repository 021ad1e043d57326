"""Workbooks 05–07 keep their teaching and give no graded answer away (issue 30).

* The velocity-ellipse introduction, "Watch it happen" (where the course's near rule is defined), the DLS set-up and
  its reading stay in workbook 05 (tag ``given``); the "Step" hints of 05 (7) and 06 (3) are kept, folded.
* 07's figure cells belong to their part (no "# Part : your work here."); True/False answers are described as
  "True or False" (with no joint-number example), lists of conditions as a list of dicts; a kinlib function the
  student's text names is imported in the student's set-up.
* What a student reads of these notebooks (the cells kept in the workbook; for a cell with ``kinlib.reveals``, its
  ``students`` version, or nothing for an explorer) holds none of the graded answers of 5.1–5.6, 6.1–6.3 and 7.6 in
  the forms the notebooks write them.

The workbooks are made here with stand-in fingerprints (no kernel runs), as in test_notebook_structure.py.
"""

from __future__ import annotations

import re
from pathlib import Path

import nbformat
import pytest

from kinlib.course import schema
from kinlib.course.publish import aids, handouts
from kinlib.course.workbook.selfcheck import describe_answer

ROOT = Path(__file__).resolve().parents[2]
NB = {
    s: ROOT / "notebooks" / f"{s}.ipynb"
    for s in ("05_singularities_planar", "06_singularities_spatial", "07_going_further")
}


def _workbook(stem):
    nb = nbformat.read(NB[stem], as_version=4)
    groups = schema.answer_groups(nb)
    fps = {(idx, name): {"spec": "none||", "describe": ""} for g in groups for _, name, _, idx in g.answers}
    return nb, handouts.make_workbook(nbformat.read(NB[stem], as_version=4), groups, fps)


def test_workbook_05_keeps_the_ellipse_the_near_rule_and_the_dls_set_up():
    _, wb = _workbook("05_singularities_planar")
    ids = {c.get("id") for c in wb.cells}
    for cid in ("05-ellipse", "05-019", "05-cost", "05-predict-cost", "05-predict-cost-answer", "05-cost-read"):
        assert cid in ids, cid
    # every kept cell that refers to "Watch it happen" (where the near rule is defined) comes after a kept cell that
    # defines it: nothing in the workbook points at a section the student cannot see
    defined = False
    for c in wb.cells:
        if c.cell_type == "markdown" and "Watch it happen" in c.source:
            defined = defined or c.source.lstrip().startswith("#") or "**Watch it happen" in c.source
            assert defined, f"{c.get('id')} refers to 'Watch it happen' before any kept cell defines it"


@pytest.mark.parametrize(
    "stem, steps",
    [
        ("05_singularities_planar", ["05-005", "05-007", "05-009", "05-024", "05-026", "05-035", "05-037"]),
        ("06_singularities_spatial", ["06-005", "06-007", "06-009"]),
        ("07_going_further", ["07-013", "07-015", "07-017"]),
    ],
)
def test_step_hints_are_kept_folded(stem, steps):
    _, wb = _workbook(stem)
    by_id = {c.get("id"): c for c in wb.cells}
    for cid in steps:
        c = by_id.get(cid)
        assert c is not None and "**Step" in c.source and schema.is_source_hidden(c), cid


def test_07_figures_belong_to_their_part():
    nb, wb = _workbook("07_going_further")
    assert not [c for c in wb.cells if "# Part :" in c.source]
    for cid, part in (("07-020", "7.1"), ("07-055", "7.4")):
        assert next(c for c in nb.cells if c.get("id") == cid).metadata["kinlib"]["part"] == part


def test_stub_words_say_the_real_form():
    assert describe_answer(False, "choice") == describe_answer(True, "choice") == "True or False"
    assert describe_answer(2, "choice").startswith("a joint number")
    import sympy as sp

    t = sp.Symbol("theta2", real=True)
    assert describe_answer([{t: sp.FiniteSet(0)}], "set").startswith("a list of dicts")
    assert describe_answer({t: sp.FiniteSet(0)}, "set") == "a dict {symbol: SymPy Set}"
    cell = nbformat.v4.new_code_cell(
        "removes_all = False",
        metadata={
            "tags": ["solution"],
            "kinlib": {"part": "7.2", "answers": ["removes_all"], "kinds": {"removes_all": "choice"}},
        },
    )
    stub = aids.stub(cell, {"removes_all": "True or False"})
    assert "True or False" in stub and "joint number" not in stub
    assert "joint number" in aids.stub(cell, {"removes_all": describe_answer(2, "choice")})


@pytest.mark.parametrize("stem", sorted(NB))
def test_functions_named_in_the_workbook_are_imported(stem):
    nb, wb = _workbook(stem)
    setup_src = nb.cells[next(i for i, c in enumerate(nb.cells) if c.cell_type == "code")].source
    imported = set(
        re.findall(
            r"\b([a-z_][a-z0-9_]*)\b",
            " ".join(re.findall(r"from kinlib[\w.]* import \(?([^)]*?)\)?\n", setup_src + "\n")),
        )
    )
    wb_setup = next(
        c
        for c in wb.cells
        if c.get("id") == nb.cells[nb.cells.index(next(c for c in nb.cells if c.cell_type == "code"))].get("id")
    )
    text = "\n".join(c.source for c in wb.cells if c.cell_type == "markdown")
    named = set(re.findall(r"`([A-Za-z_][A-Za-z0-9_]*)", text)) & imported
    assert named, "the text names kinlib functions"
    missing = sorted(n for n in named if not re.search(rf"\b{n}\b", wb_setup.source))
    assert not missing, missing


# ---------------------------------------------------------------------------------------------------------------
# nothing graded in what a student reads

ANSWER_FORMS = {  # part: how the notebooks write its answer (LaTeX, and the degrees of the explorer text)
    "5.1": [r"\sin(\theta_2 + \pi/4)", r"\theta_2 = -\pi/4", r"3\pi/4", r"-45^\circ", r"135^\circ", r"-\pi/4 + k\pi"],
    "5.3": [r"(0, 1, 1)", r"45^\circ$ line"],
    "5.4": [r"\sqrt2\,L^2", r"\pi/4 + k\pi", r"\sin 2\theta_2 = 1"],
    "5.6": [r"L^2\cos\theta_2", r"\pi/2 + k\pi", r"\pm\pi/2"],
    "6.1": ["rank 4", r"\mathrm{rank}\,J = 4", "no singular configuration", "keeps rank 4", r"1 + (L_2 + \theta_3)^2"],
    "6.3": [r"(L + \theta_3)^2", r"\theta_3 = -L$", r"\theta_2 = \pi/2"],
    "7.6": [r"L\cos\theta_2", r"\pi/2 + k\pi", r"\pm\pi/2"],
}


def _student_texts(nb, wb):
    kept = {c.get("id") for c in wb.cells}
    for c in nb.cells:
        if c.get("id") not in kept:
            continue
        tags = set(schema.cell_tags(c))
        meta = c.metadata.get("kinlib", {})
        if aids.graded_prediction(c):
            continue  # the workbook points to the self-check instead
        if "reveals" in meta:
            if c.cell_type == "markdown":
                assert "students" in meta, f"{c.get('id')}: a markdown cell that reveals needs its students' version"
                yield c.get("id"), meta["students"]
            continue  # an explorer: the build shows it without its marks
        if tags & schema.ANSWER_TAGS:
            continue
        yield c.get("id"), c.source


@pytest.mark.parametrize("stem", sorted(NB))
def test_what_a_student_reads_states_no_graded_answer(stem):
    nb, wb = _workbook(stem)
    parts = [p for p in schema.notebook_sections(nb) if p in ANSWER_FORMS]
    hits = [
        (cid, part, form)
        for cid, text in _student_texts(nb, wb)
        for part in parts
        for form in ANSWER_FORMS[part]
        if form in text and schema.QUESTION not in schema.cell_tags(next(c for c in nb.cells if c.get("id") == cid))
    ]
    assert not hits, hits


def test_the_cells_that_reveal_are_marked():
    nb = nbformat.read(NB["05_singularities_planar"], as_version=4)
    meta = {c.get("id"): c.metadata.get("kinlib", {}) for c in nb.cells}
    assert meta["05-051"]["reveals"] == ["5.1", "5.4"]  # the explorer marks 5.1's answer on θ2's track
    assert set(meta["05-019"]["reveals"]) == {"5.1", "5.4"} and set(meta["05-cost"]["reveals"]) == {"5.1", "5.3"}
    solution_text = next(c.source for c in nb.cells if c.get("id") == "05-019")
    assert r"\sqrt2\,L^2" in solution_text  # the solutions keep the sentence as it is
    nb6 = nbformat.read(NB["06_singularities_spatial"], as_version=4)
    meta6 = {c.get("id"): c.metadata.get("kinlib", {}) for c in nb6.cells}
    assert meta6["06-mistake-flat"]["reveals"] == ["6.1"] and meta6["06-025"]["reveals"] == ["6.1"]


@pytest.mark.parametrize(
    "stem, cids",
    [
        ("05_singularities_planar", ["05-050", "05-predict-explore"]),
        ("06_singularities_spatial", ["06-024", "06-predict-explore"]),
    ],
)
def test_explorer_texts_have_students_versions_without_readouts(stem, cids):
    """The students' explorer shows no status, det or w readout (INTERFACES.md): the text beside it says none."""
    nb = nbformat.read(NB[stem], as_version=4)
    for c in nb.cells:
        if c.get("id") in cids:
            meta = c.metadata["kinlib"]
            assert meta["reveals"] and meta["students"] != c.source
            for word in ("readout", "status", "reads 0", r"\det J"):
                assert word not in meta["students"], (c.get("id"), word)
