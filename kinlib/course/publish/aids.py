"""The reading aids in the student versions (problems and workbooks) of a notebook: what a ``predict-answer``
that gives a graded answer away becomes, which cells are folded, and the workbook's stubs with examples of the
answer forms a student may not know (a set of angles, a choice, a subspace). Tags: :mod:`kinlib.course.schema`
and ``notebooks/README.md``; used by :mod:`kinlib.course.publish.handouts`.
"""

from __future__ import annotations

import ast

from ..schema import (
    HINT,
    PREDICT_ANSWER,
    answer_kind,
    cell_answers,
    cell_meta,
    cell_part,
    cell_reveals,
    cell_tags,
    set_source_hidden,
    students_markdown,
)

__all__ = [
    "ANSWER_FORM_EXAMPLES",
    "STUDENTS_OUTPUTS",
    "graded_prediction",
    "show_students_version",
    "student_reading_aid",
    "students_cell",
    "students_picture_source",
    "stub",
]

#: the executed cell's metadata key (build-internal, removed from every page) holding the outputs of the students'
#: version of a ``reveals`` picture, made in the kernel by :func:`show_students_version`
STUDENTS_OUTPUTS = "kinlib_students_outputs"
_IMPORT = "from kinlib.widgets import without_answers  # the students' version: it marks no graded answer\n"


def show_students_version(shell=None) -> None:
    """Run in the notebook's kernel by ``kinlib handouts`` right after a code cell with ``"reveals"``: display the
    students' version (:func:`kinlib.widgets.without_answers`) of the picture that cell showed (its result,
    ``Out[n]``), or print a line saying that it showed none (then the students' files leave the cell out).

    >>> class Shell:
    ...     execution_count = 4
    ...     user_ns = {"Out": {3: 42}}
    >>> show_students_version(Shell())
    kinlib-students-version: none (the cell's result is int, not an explorer, animation or picker)
    """
    if shell is None:
        from IPython import get_ipython

        shell = get_ipython()
    out = shell.user_ns.get("Out", {})
    obj = out.get(shell.execution_count - 1) if isinstance(out, dict) else None
    if not callable(getattr(type(obj), "without_answers", None)):
        print(
            f"kinlib-students-version: none (the cell's result is {type(obj).__name__}, "
            "not an explorer, animation or picker)"
        )
        return
    from IPython.display import display

    display(obj.without_answers())


def students_picture_source(source: str) -> str | None:
    """The workbook's source of a picture cell with ``"reveals"``: its last expression wrapped in
    :func:`kinlib.widgets.without_answers` (imported on a first line), or None when the cell does not end with an
    expression (or is not plain Python).

    >>> print(students_picture_source("from kinlib import widgets\\nwidgets.explorer(r, q=[0, 1])   # drag"))
    from kinlib.widgets import without_answers  # the students' version: it marks no graded answer
    from kinlib import widgets
    without_answers(widgets.explorer(r, q=[0, 1]))   # drag
    >>> students_picture_source("x = 1") is None
    True
    """
    try:
        tree = ast.parse(source)
    except SyntaxError:
        return None
    if not tree.body or not isinstance(tree.body[-1], ast.Expr):
        return None
    node = tree.body[-1].value
    lines = source.split("\n")
    first, last = node.lineno - 1, node.end_lineno - 1
    segment = ast.get_source_segment(source, node)
    if segment is None:
        return None
    head = lines[first][: node.col_offset]
    tail = lines[last][node.end_col_offset :]
    new = lines[:first] + (head + "without_answers(" + segment + ")" + tail).split("\n") + lines[last + 1 :]
    return _IMPORT + "\n".join(new)


def students_cell(cell, picture: bool | None = None):
    """The students' version of a cell (problems and workbooks): the cell itself when it ``reveals`` nothing;
    for a markdown cell that does, its ``students`` markdown, or None (left out); for a code cell that does, the
    cell with its picture's students' version (a workbook's source wrapped in ``without_answers``; the problems'
    outputs are replaced by the build), or None when it shows no picture (``picture`` False, or its source does
    not end with an expression). The cell is changed in place.

    >>> md = {"cell_type": "markdown", "source": "det J = 0 at θ2 = −π/4", "metadata": {"kinlib": {"reveals": ["5.1"],
    ...       "students": "Where is det J = 0? That is 5.1."}}}
    >>> students_cell(md)["source"]
    'Where is det J = 0? That is 5.1.'
    >>> students_cell({"cell_type": "markdown", "source": "6.1: none", "metadata": {"kinlib": {"reveals": ["6.1"]}}}) is None
    True
    """
    if not cell_reveals(cell):
        return cell
    if cell.get("cell_type") == "markdown":
        text = students_markdown(cell)
        if text is None:
            return None
        cell["source"] = text
        cell.pop("attachments", None)
        return cell
    if picture is False:
        return None
    src = cell.get("source", "")
    src = "".join(src) if isinstance(src, list) else src
    new = students_picture_source(src)
    if new is None:
        return None
    cell["source"] = new
    return cell


def graded_prediction(cell) -> str:
    """The part a ``predict-answer`` cell gives the answer of (its ``metadata.kinlib.part``), or "".

    Such an answer is shown in the solutions only; the problems and the workbook keep the folded cell with a
    pointer to the part's self-check instead (:func:`student_reading_aid`).

    >>> graded_prediction({"metadata": {"tags": ["predict-answer"], "kinlib": {"part": "4.1"}}})
    '4.1'
    >>> graded_prediction({"metadata": {"tags": ["predict-answer"]}})
    ''
    """
    return cell_part(cell_meta(cell)) if PREDICT_ANSWER in cell_tags(cell) else ""


def student_reading_aid(cell) -> None:
    """In the problems and the workbook: hints and predict-answers folded; a graded prediction's answer
    replaced by a pointer to the self-check of its part.

    >>> cell = {"source": "Joint 2.", "metadata": {"tags": ["predict-answer"], "kinlib": {"part": "4.1"}}}
    >>> student_reading_aid(cell)
    >>> cell["source"][:60], cell["metadata"]["jupyter"]
    ('**Check your prediction** with the self-check of part 4.1 in', {'source_hidden': True})
    """
    tags = set(cell_tags(cell))
    part = graded_prediction(cell)
    if part:
        cell["source"] = (
            f"**Check your prediction** with the self-check of part {part} in the workbook: it says whether your "
            "answer is right without showing it. The reasoning is in the solutions."
        )
        cell.pop("attachments", None)
    if tags & {HINT, PREDICT_ANSWER}:
        set_source_hidden(cell)


# How to write the answer forms a student may not have met (shown under the stubs of those answers);
# tests/notebooks/test_notebook_structure.py checks that each example is accepted by the self-check's comparers.
ANSWER_FORM_EXAMPLES = {
    "set": (
        "How to write a set of angles (SymPy sets; n is an integer symbol):",
        "  a few values:       sp.FiniteSet(-sp.pi / 2, sp.pi / 2)",
        "  a periodic family:  n = sp.Symbol('n', integer=True)",
        "                      sp.ImageSet(sp.Lambda(n, sp.pi / 4 + n * sp.pi), sp.Integers)",
        "  several families:   sp.Union(sp.ImageSet(...), sp.ImageSet(...));  none at all: sp.EmptySet",
    ),
    "choice": (
        "How to write a choice: a joint number, 1-based (e.g. 2); if joints tie, a tuple of all of them (e.g. (1, 2)).",
    ),
    "subspace": (
        "How to write a subspace: a Matrix whose columns span it, e.g. sp.Matrix([[1, 0], [0, 1], [0, 0]]) for the",
        "x-y plane (any basis of the same span is right).",
    ),
}


def stub(cell, describe: dict) -> str:
    """The workbook's stub for a ``solution`` code cell: a line ``name = ...  # TODO: ...`` per answer (with the
    ``describe`` words), and under an answer form a student may not know, how to write it.

    >>> import nbformat
    >>> cell = nbformat.v4.new_code_cell("joint = 2", metadata={"tags": ["solution"],
    ...     "kinlib": {"part": "4.1", "answers": ["joint"], "kinds": {"joint": "choice"}}})
    >>> print(stub(cell, {"joint": "a joint number"}))  # doctest: +NORMALIZE_WHITESPACE
    # Part 4.1: your answer. Replace each ... below; the self-check further down says whether it is right.
    joint = ...  # TODO: a joint number (part 4.1)
    #   How to write a choice: a joint number, 1-based (e.g. 2); if joints tie, a tuple of all of them (e.g. (1, 2)).
    <BLANKLINE>
    """
    meta = cell_meta(cell)
    part = cell_part(meta)
    answers = cell_answers(meta)
    words = meta.get("describe") if isinstance(meta.get("describe"), dict) else {}
    lines = [
        f"# Part {part}: your answer. Replace each ... below; the self-check further down says whether it is right."
        if answers
        else f"# Part {part}: your work here."
    ]
    for name in answers:
        what = ", ".join(x for x in (words.get(name), describe.get(name)) if x)
        lines.append(f"{name} = ...  # TODO: {what or 'your answer'} (part {part})")
    # a True/False answer of kind "choice" needs no joint-number example
    examples = [
        answer_kind(meta, name)
        for name in answers
        if not (answer_kind(meta, name) == "choice" and describe.get(name) == "True or False")
    ]
    for kind in dict.fromkeys(examples):
        lines += [f"#   {line}" for line in ANSWER_FORM_EXAMPLES.get(kind, ())]
    return "\n".join(lines) + "\n"
