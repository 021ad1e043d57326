"""kinlib.course.schema: the one reader of cell tags, ``kinlib`` metadata and points.

It replaced two readers (the handouts' and the checker's); these tests pin what each accepted:
the handouts read nbformat ``NotebookNode`` cells and grouped answers by ``check`` cells, the checker
read plain JSON dicts defensively (tags not a list, metadata not a dict), parsed points and named parts
without an id after their question.
"""

from __future__ import annotations

import json
from pathlib import Path

import nbformat
import pytest

from kinlib.course import schema
from kinlib.course.schema import (
    answer_groups,
    answer_kind,
    cell_answers,
    cell_meta,
    cell_part,
    cell_source,
    cell_tags,
    is_plain_selfcheck,
    notebook_id,
    notebook_sections,
    notebook_title,
    parse_parts,
    points_in,
    stash_points,
)

ROOT = Path(__file__).resolve().parents[2]
GRADE_REF = ROOT / "tests" / "fixtures" / "grade" / "notebooks" / "90_grade_fixture.ipynb"
HANDOUTS_REF = ROOT / "tests" / "fixtures" / "handouts" / "01_fixture_jacobians.ipynb"


def md(src="", tags=(), **kinlib):
    c = {"cell_type": "markdown", "metadata": {}, "source": src}
    if tags:
        c["metadata"]["tags"] = list(tags)
    if kinlib:
        c["metadata"]["kinlib"] = kinlib
    return c


def code(src="", tags=(), **kinlib):
    c = md(src, tags, **kinlib)
    c.update(cell_type="code", outputs=[], execution_count=None)
    return c


# ----------------------------------------------------------------------------------------- one cell


def test_tags_from_nbformat_cells_and_plain_json():
    node = nbformat.v4.new_code_cell("x = 1")
    node.metadata["tags"] = ["solution"]
    assert cell_tags(node) == ["solution"]  # NotebookNode (the handouts)
    assert cell_tags(code(tags=["check"])) == ["check"]  # json.load dict (the checker)
    assert cell_tags({"metadata": {"tags": ("question",)}}) == ["question"]
    assert cell_tags({"metadata": {"tags": ["solution", 7]}}) == ["solution", "7"]


@pytest.mark.parametrize(
    "cell",
    [
        {},
        {"metadata": None},
        {"metadata": {"tags": None}},
        {"metadata": {"tags": "solution"}},
        {"metadata": "x"},
        "not a cell",
    ],
)
def test_malformed_tags_read_as_none(cell):
    assert cell_tags(cell) == []


def test_source_and_metadata():
    assert cell_source({"source": ["a\n", "b"]}) == "a\nb" and cell_source({"source": "a"}) == "a"
    assert cell_source({}) == ""
    assert cell_meta(code(part="1.1", answers=["J"])) == {"part": "1.1", "answers": ["J"]}
    for bad in ({}, {"metadata": {"kinlib": None}}, {"metadata": {"kinlib": ["x"]}}):
        assert cell_meta(bad) == {}
    meta = cell_meta(code(part="1.1"))
    meta["part"] = "changed"  # a copy: the cell is not edited
    assert cell_meta(code(part="1.1"))["part"] == "1.1"


def test_parts_answers_and_kinds():
    assert cell_part({"part": "2.1"}) == "2.1" and cell_part({"part": 5.2}) == "5.2"
    assert cell_part({}) == "" and cell_part({"part": None}, "q2") == "q2" and cell_part({"part": ""}, "q1") == "q1"
    assert cell_answers({"answers": ["Js", "Jb", "Js"]}) == ["Js", "Jb"]
    assert cell_answers({"answers": ["Js", 3, None]}) == ["Js"]
    assert cell_answers({}) == [] and cell_answers({"answers": "Js"}) == []
    meta = {"kinds": {"S": "set", "V": "subspace", "k": "choice", "J": "default", "x": None, "e": "expr"}}
    assert {n: answer_kind(meta, n) for n in ("S", "V", "k", "J", "x", "e", "missing")} == {
        "S": "set",
        "V": "subspace",
        "k": "choice",
        "J": "expr",
        "x": "expr",
        "e": "expr",
        "missing": "expr",
    }
    assert answer_kind({"kinds": {"J": "matrix"}}, "J") == "matrix"  # unknown kinds are not hidden
    assert answer_kind({"kinds": "set"}, "J") == "expr"


# ----------------------------------------------------------------------------------------- the notebook


def test_notebook_metadata():
    nb = {"metadata": {"kinlib": {"notebook": "02_planar", "title": "Planar", "sections": [2.1, "2.2"]}}}
    assert (notebook_id(nb), notebook_title(nb, "x"), notebook_sections(nb)) == ("02_planar", "Planar", ["2.1", "2.2"])
    for bad in (
        {},
        {"metadata": {}},
        {"metadata": {"kinlib": None}},
        {"metadata": {"kinlib": {"notebook": ""}}},
        {"metadata": {"kinlib": {"notebook": 3}}},
        [],
        "x",
    ):
        assert notebook_id(bad) is None
    # an empty or missing title falls back (the handouts used the stem, the checker the id)
    assert notebook_title({"metadata": {"kinlib": {"title": ""}}}, "02 planar") == "02 planar"
    assert notebook_title({}, "02_planar") == "02_planar"
    assert notebook_sections({}) == []


@pytest.mark.parametrize(
    "text, points",
    [
        ("**1.1 (5 points).** Find J", 5.0),
        ("## 1.2 (2 points)\nWhich joint", 2.0),
        ("(1 point)", 1.0),
        ("(2.5 Points)", 2.5),
        ("worth 10 points in all", 10.0),
        ("3 points here, (4 points) there", 4.0),
        ("no points given", None),
        ("", None),
    ],
)
def test_points_in_question_text(text, points):
    assert points_in(text) == points


# ----------------------------------------------------------------------------------------- answer groups (handouts)


def test_answer_groups_follow_check_cells_and_questions():
    nb = {
        "cells": [
            md("Q1", ["question"]),
            code("J = 1", ["solution"], part="1.1", answers=["J"]),
            code("J = 2\nK = 3", ["solution"], part="1.1", answers=["J", "K"], kinds={"K": "choice"}),
            md("worked", ["solution"], part="1.1"),  # markdown solutions hold no answers
            code("check", ["check"]),
            md("Q2", ["question"]),
            code("work", ["solution"], part="1.2"),  # no answers: still the last solution cell
            code("S = 4", ["solution"], part="1.2", answers=["S"], kinds={"S": "set"}),
            code("", ["solution"], part="1.2"),
            md("Q3", ["question"]),  # closes 1.2's group (no check cell)
            code("c", ["check"]),  # a check cell with nothing to check
        ]
    }
    groups = answer_groups(nb)
    assert [(g.answers, g.check_cell, g.last_solution) for g in groups] == [
        ([("1.1", "J", "expr", 2), ("1.1", "K", "choice", 2)], 4, 2),
        ([("1.2", "S", "set", 7)], None, 8),
        ([], 10, -1),
    ]


def test_answer_groups_reject_a_cell_both_solution_and_check():
    with pytest.raises(ValueError, match="cell 0 is tagged both"):
        answer_groups({"cells": [code("x = 1", ["solution", "check"], answers=["x"])]})


def test_answer_groups_of_an_nbformat_notebook():
    nb = nbformat.read(HANDOUTS_REF, as_version=4)
    assert [[n for _, n, _, _ in g.answers] for g in answer_groups(nb)] == [
        ["Js"],
        ["fastest"],
        ["detJ", "singular"],
        ["span"],
    ]


# ----------------------------------------------------------------------------------------- graded parts (checker)


def test_parse_parts_points_from_questions_split_and_explicit():
    nb = {
        "cells": [
            code("setup"),
            md("**1 (6 points).**", ["question"]),
            code("a = 1", ["solution"], part="1a", answers=["a"]),
            code("b = 1", ["solution"], part="1b", answers=["b"], kinds={"b": "default"}),
            md("**2 (4 points).**", ["question"]),
            code("c = 1", ["solution"], part="2", answers=["c"], points=1.5, kinds={"c": "set"}),
            md("**3.** no points", ["question"]),
            code("d = 1", ["solution"], answers=["d"]),  # no part id: named after its question
            code("x = 1", ["solution"], part="4"),  # no answers: not graded
            code("e = 1", ["solution"], part="1a", answers=["e", "a"]),  # a part continued further down
        ]
    }
    parts = {p.part: p for p in parse_parts(nb)}
    assert list(parts) == ["1a", "1b", "2", "q3"]
    assert parts["1a"].points == 3.0 and parts["1b"].points == 3.0  # 6 points, two parts
    assert parts["2"].points == 1.5 and parts["q3"].points == 0.0
    assert parts["1a"].answers == ["a", "e"] and parts["1a"].cells == [1, 6]
    assert parts["1b"].kinds == {"b": "expr"} and parts["2"].kinds == {"c": "set"}


def test_parse_parts_of_the_grading_fixture():
    parts = parse_parts(json.loads(GRADE_REF.read_text()))
    assert [(p.part, p.points) for p in parts] == [("1.1", 5), ("1.2", 5), ("1.3", 5), ("1.4", 5), ("1.5", 10)]


@pytest.mark.parametrize(
    "path", [GRADE_REF, HANDOUTS_REF, *sorted((ROOT / "notebooks").glob("[0-9][0-9]_*.ipynb"))], ids=lambda p: p.stem
)
def test_handouts_and_checker_read_the_same_answers(path):
    """The groups the self-checks are made from and the parts the checker grades hold the same answers."""
    nb = json.loads(path.read_text())
    from_groups = {(part, name, kind) for g in answer_groups(nb) for part, name, kind, _ in g.answers}
    parts = parse_parts(nb)
    # an answer graded by a property ("property:nonsingular", see schema.grading_kind) is judged by the same
    # property in the self-check (kinlib.course.properties.judge)
    from_parts = {(p.part, name, p.kinds[name]) for p in parts for name in p.answers}
    assert from_groups == from_parts
    graded = [p.kinds[n] for p in parts for n in p.answers]
    assert all(k in schema.KINDS or k.partition(":")[2] in schema.PROPERTIES for k in graded)


def test_stash_points_at_the_end_of_each_part():
    nb = {
        "cells": [
            md("Q1", ["question"]),
            code("J = 1", ["solution"], answers=["J"]),
            code("student's extra cell"),
            md("Q2", ["question"]),  # part 1 ends after code cell 1
            code("K = 1", ["solution"], answers=["K", 3]),
            md("text"),
            code("later"),  # the last part ends at the end of the notebook
            "not a cell",
        ]
    }
    assert stash_points(nb) == {1: ["J"]}
    nb["cells"].append(md("Q3", ["question"]))
    assert stash_points(nb) == {1: ["J"], 3: ["K"]}


# ----------------------------------------------------------------------------------------- self-check cells


@pytest.mark.parametrize("module", schema.SELFCHECK_MODULES)
def test_plain_selfcheck_cells_of_new_and_old_workbooks(module):
    src = f'# Self-check\nfrom {module} import check\n\ncheck("1.1", Js="matrix|6x3|0123456789abcdef")\n'
    assert is_plain_selfcheck(code(src, ["selfcheck"]))
    assert not is_plain_selfcheck(code(src))  # not tagged
    assert not is_plain_selfcheck(code(src + "Js = 0\n", ["selfcheck"]))  # changes an answer
    assert not is_plain_selfcheck(code(src.replace("import check", "import check as c"), ["selfcheck"]))
    assert not is_plain_selfcheck(code(src + "check('1.1', Js=Js)\n", ["selfcheck"]))  # not a constant
    assert not is_plain_selfcheck(code("check(", ["selfcheck"]))


def test_the_workbooks_selfcheck_cells_are_plain():
    wb = json.loads((ROOT / "tests" / "fixtures" / "grade" / "workbooks" / "90_grade_fixture.ipynb").read_text())
    cells = [c for c in wb["cells"] if "selfcheck" in cell_tags(c)]
    assert len(cells) == 5 and all(is_plain_selfcheck(c) for c in cells)
    assert all(f"from {schema.SELFCHECK_MODULES[0]} import check" in cell_source(c) for c in cells)
