"""A small notebook whose numbers vary (``k``, its variant cell) and a variants key built by hand for it (issue 33):
shared by tests/course/test_grade_variants.py (kinlib grade) and tests/course/test_grade_lms.py (the bundles).

The key has the lead's :mod:`kinlib.course.variants.key` format; each variant's reference answers are computed here
by SymPy, independently of the grader, and dumped as the reference kernel would
(:func:`kinlib.course.answers.describe.dump_reference`).
"""

from __future__ import annotations

import copy
from pathlib import Path

import sympy as sp

from kinlib.course.answers.describe import dump_reference
from kinlib.course.variants.key import Key, NotebookKey, Variant, write_key

NID = "91_variant_fixture"
FLAG = "this looks like another variant's answer"
KINDS = {"r": "expr", "s": "expr"}
SPEC = {"params": {"k": {"type": "number", "choices": ["2", "3", "5", "7"]}}, "original": {"k": "2"}, "parts": ["1.1"]}
# each student's variant (k), as the key says; dan is not on the roster
STUDENTS = {"ada": 3, "bob": 5, "cyd": 7, "eve": 5}


def _md(src, tags=()):
    return {"cell_type": "markdown", "metadata": {"tags": list(tags)}, "source": src}


def _code(src, meta=None, tags=()):
    md = {"tags": list(tags)} | ({"kinlib": meta} if meta else {})
    return {"cell_type": "code", "metadata": md, "source": src, "outputs": [], "execution_count": None}


def variant_cell(k: int) -> str:
    return f"# The numbers of this problem set: the course's build writes each student's own here.\nfrom sympy import pi, Rational\nk = {k}\n"


def notebook(k: int = 2, r: str = "r = k * x**2 + 1", s: str = "s = sp.Matrix([[x, k], [0, k * x]])", values=None):
    """The solution notebook (k = 2, the original), or a student's workbook (their k, their answers)."""
    meta = {"notebook": NID, "title": "Variants fixture", "sections": ["1.1"]}
    if values is not None:
        meta["variants"] = copy.deepcopy(SPEC) | {"original": values}  # the student controls this: never read
    else:
        meta["variants"] = copy.deepcopy(SPEC)
    return {
        "nbformat": 4,
        "nbformat_minor": 5,
        "metadata": {
            "kernelspec": {"name": "python3", "display_name": "Python 3", "language": "python"},
            "kinlib": meta,
        },
        "cells": [
            _md("# Variants fixture"),
            _code(variant_cell(k), {"variant": True}),
            _code("import sympy as sp\nx = sp.Symbol('x', real=True)"),
            _md("**1.1 (5 points).** Find r(x) = k x² + 1.", ["question"]),
            _code(r, {"answers": ["r"], "part": "1.1"}, ["solution"]),
            _md("**1.2 (5 points).** Find the matrix S(x).", ["question"]),
            _code(s, {"answers": ["s"], "part": "1.2"}, ["solution"]),
        ],
    }


def answers_for(k: int) -> dict:
    """The reference answers of variant k, computed here (not by the grader)."""
    x = sp.Symbol("x", real=True)
    return dump_reference({"r": k * x**2 + 1, "s": sp.Matrix([[x, k], [0, k * x]])}, KINDS)


def make_key(secret: bytes, path: Path) -> Path:
    variants = {f"v{k}": Variant({"k": str(k)}, answers_for(k), {}) for k in sorted(set(STUDENTS.values()))}
    nk = NotebookKey(NID, "0" * 64, SPEC, SPEC["original"], variants, {s: f"v{k}" for s, k in STUDENTS.items()})
    roster = [{"id": s, "name": "", "email": ""} for s in STUDENTS]
    return write_key(path, Key({NID: nk}, roster), secret)
