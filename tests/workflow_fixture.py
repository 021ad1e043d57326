"""A tiny solution notebook for the grading workflow tests (partial credit, manual work, platforms).

``91_workflow`` has three parts, 15 points:

* 1.1 (6 points): answers ``a`` (declared 3 points), ``b`` and ``c`` (undeclared: the 3 left, 1.5 each);
* 1.2 (4 points): a drawing, graded by hand (``manual`` on a solution markdown cell), no answers;
* 1.3 (5 points): answer ``d`` (the 3 left after) an explanation graded by hand (2 points).

It needs nothing but SymPy, so a kernel runs it in about a second.
"""

from __future__ import annotations

import copy
import json
from pathlib import Path

NB_ID = "91_workflow"
RIGHT = {
    "1.1": "a = th1**2\nb = sp.sin(th1)\nc = sp.Matrix([1, th1])",
    "1.3": "d = 2 * th1",
}


def _md(text, tags=(), kinlib=None):
    c = {"cell_type": "markdown", "metadata": {}, "source": text}
    if tags:
        c["metadata"]["tags"] = list(tags)
    if kinlib:
        c["metadata"]["kinlib"] = kinlib
    return c


def _code(src, tags=(), kinlib=None):
    c = {"cell_type": "code", "metadata": {}, "source": src, "outputs": [], "execution_count": None}
    if tags:
        c["metadata"]["tags"] = list(tags)
    if kinlib:
        c["metadata"]["kinlib"] = kinlib
    return c


def solution(sources=None) -> dict:
    """The solution notebook (``sources``: {part: code} replaces a part's solution code, for submissions)."""
    src = dict(RIGHT, **(sources or {}))
    cells = [
        _md("# Workflow fixture"),
        _code('import sympy as sp\nth1 = sp.Symbol("theta1")'),
        _md("**1.1 (6 points).** Three answers.", ["question"]),
        _code(
            src["1.1"],
            ["solution"],
            {"part": "1.1", "answers": ["a", "b", "c"], "answer_points": {"a": 3}},
        ),
        _md("**1.2 (4 points).** Draw the arm.", ["question"]),
        _code("# the drawing (a figure in the solution)", ["solution"], {"part": "1.2", "answers": []}),
        _md("A drawing of the arm.", ["solution"], {"part": "1.2", "manual": {"drawing": 4}}),
        _md("**1.3 (5 points).** One answer, and say why.", ["question"]),
        _code(src["1.3"], ["solution"], {"part": "1.3", "answers": ["d"]}),
        _md("Because.", ["solution"], {"part": "1.3", "manual": {"explanation": 2}}),
    ]
    return {
        "cells": cells,
        "metadata": {
            "kinlib": {"notebook": NB_ID, "title": "Workflow fixture", "sections": ["1.1", "1.2", "1.3"]},
            "kernelspec": {"name": "python3", "display_name": "Python 3", "language": "python"},
        },
        "nbformat": 4,
        "nbformat_minor": 5,
    }


def write_solution(folder: Path) -> Path:
    folder.mkdir(parents=True, exist_ok=True)
    p = folder / f"{NB_ID}.ipynb"
    p.write_text(json.dumps(solution(), indent=1) + "\n")
    return p


def write_submission(path: Path, sources=None) -> Path:
    nb = copy.deepcopy(solution(sources))
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(json.dumps(nb, indent=1) + "\n")
    return path
