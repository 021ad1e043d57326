"""The reading aids in the student versions (problems and workbooks) of a notebook: what a ``predict-answer``
that gives a graded answer away becomes, which cells are folded, and the workbook's stubs with examples of the
answer forms a student may not know (a set of angles, a choice, a subspace). Tags: :mod:`kinlib.course.schema`
and ``notebooks/README.md``; used by :mod:`kinlib.course.publish.handouts`.
"""

from __future__ import annotations

from ..schema import (
    HINT,
    PREDICT_ANSWER,
    answer_kind,
    cell_answers,
    cell_meta,
    cell_part,
    cell_tags,
    set_source_hidden,
)

__all__ = ["ANSWER_FORM_EXAMPLES", "graded_prediction", "student_reading_aid", "stub"]


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
