"""Which cells of a notebook depend on its answers: name analysis of code cells, and worked solutions.

Used by :mod:`kinlib.course.publish.handouts` to leave answers out of the problem pages and the workbooks: cells
that read answer variables (computed by ``solution`` cells), the untagged markdown of worked
solutions, and the imports and helper functions only the solutions use (:func:`trim_setup`).
"""

from __future__ import annotations

import ast

from ..schema import ANSWER_TAGS, CHECK, QUESTION, SOLUTION, cell_tags

__all__ = ["cell_names", "loaded_names", "trim_setup", "worked_narrative", "answer_dependents"]


def _python_source(src: str) -> str:
    """Cell source as plain Python (IPython magics and shell escapes transformed)."""
    from IPython.core.inputtransformer2 import TransformerManager

    return TransformerManager().transform_cell(src)


class _Names(ast.NodeVisitor):
    """Names a cell reads before binding them (free names), and names it binds, in evaluation order."""

    def __init__(self):
        self.free, self.bound = set(), set()

    def visit_Name(self, node):
        if isinstance(node.ctx, ast.Load):
            if node.id not in self.bound:
                self.free.add(node.id)
        else:
            self.bound.add(node.id)

    def visit_Assign(self, node):
        self.visit(node.value)
        for t in node.targets:
            self.visit(t)

    def visit_AnnAssign(self, node):
        if node.value is not None:
            self.visit(node.value)
        self.visit(node.target)

    def visit_AugAssign(self, node):
        self.visit(node.value)
        if isinstance(node.target, ast.Name):
            if node.target.id not in self.bound:
                self.free.add(node.target.id)
            self.bound.add(node.target.id)
        else:
            self.visit(node.target)

    def visit_NamedExpr(self, node):
        self.visit(node.value)
        self.visit(node.target)

    def visit_For(self, node):
        self.visit(node.iter)
        self.visit(node.target)
        for n in node.body + node.orelse:
            self.visit(n)

    def _comprehension(self, node, elts):
        outer = set(self.bound)
        for g in node.generators:
            self.visit(g.iter)
            self.visit(g.target)
            for cond in g.ifs:
                self.visit(cond)
        for e in elts:
            self.visit(e)
        self.bound = outer  # comprehension variables do not leak

    def visit_ListComp(self, node):
        self._comprehension(node, [node.elt])

    visit_SetComp = visit_GeneratorExp = visit_ListComp

    def visit_DictComp(self, node):
        self._comprehension(node, [node.key, node.value])

    def _function(self, node, body):
        for d in getattr(node, "decorator_list", []):
            self.visit(d)
        for d in node.args.defaults + [d for d in node.args.kw_defaults if d is not None]:
            self.visit(d)
        if not isinstance(node, ast.Lambda):
            self.bound.add(node.name)
        outer = set(self.bound)
        a = node.args
        self.bound |= {x.arg for x in a.posonlyargs + a.args + a.kwonlyargs}
        self.bound |= {x.arg for x in (a.vararg, a.kwarg) if x is not None}
        for n in body:
            self.visit(n)
        self.bound = outer | ({node.name} if not isinstance(node, ast.Lambda) else set())

    def visit_FunctionDef(self, node):
        self._function(node, node.body)

    visit_AsyncFunctionDef = visit_FunctionDef

    def visit_Lambda(self, node):
        self._function(node, [node.body])

    def visit_ClassDef(self, node):
        for n in node.bases + node.decorator_list:
            self.visit(n)
        self.bound.add(node.name)

    def visit_Import(self, node):
        for a in node.names:
            self.bound.add((a.asname or a.name).split(".")[0])

    visit_ImportFrom = visit_Import


def cell_names(src: str) -> tuple[set, set]:
    """(names read before being bound, names bound) by a code cell; empty sets if it does not parse.

    >>> free, bound = cell_names("for k in ks:\\n    J = J + k\\n%matplotlib inline")
    >>> sorted(free), sorted(bound)
    (['J', 'get_ipython', 'ks'], ['J', 'k'])
    """
    try:
        tree = ast.parse(_python_source(src))
    except SyntaxError:
        return set(), set()
    v = _Names()
    for stmt in tree.body:
        v.visit(stmt)
    return v.free, v.bound


def worked_narrative(nb) -> set:
    """Untagged markdown cells inside a worked solution: after a ``question`` cell and before the last
    ``solution``/``check`` cell answering it (its steps and explanations). Problems and workbooks drop them.

    >>> import nbformat
    >>> q, step, sol = (nbformat.v4.new_markdown_cell(t) for t in ("Q", "step 1", "answer"))
    >>> q.metadata["tags"], sol.metadata["tags"] = ["question"], ["solution"]
    >>> worked_narrative(nbformat.v4.new_notebook(cells=[q, step, sol]))
    {1}
    """
    out: set = set()
    cells = nb.cells
    questions = [i for i, c in enumerate(cells) if QUESTION in cell_tags(c)]
    for k, q in enumerate(questions):
        stop = questions[k + 1] if k + 1 < len(questions) else len(cells)
        answers = [i for i in range(q + 1, stop) if ANSWER_TAGS & set(cell_tags(cells[i]))]
        if answers:
            out |= {
                i for i in range(q + 1, answers[-1]) if cells[i].cell_type == "markdown" and not cell_tags(cells[i])
            }
    return out


def answer_dependents(nb) -> dict:
    """{cell index: names it reads that come from solution cells} for the other code cells.

    Names bound by ``solution`` cells, and by cells that use them, exist only once the student has
    answered; a cell that reads one of them (before any non-answer cell bound it) depends on answers.

    >>> import nbformat
    >>> cells = [nbformat.v4.new_code_cell(s) for s in ("J = 1", "print(J.shape)", "x = 2")]
    >>> cells[0].metadata["tags"] = ["solution"]
    >>> answer_dependents(nbformat.v4.new_notebook(cells=cells))
    {1: ['J']}
    """
    answer_names: set = set()
    defined: set = set()
    needs: dict = {}
    for i, cell in enumerate(nb.cells):
        if cell.cell_type != "code":
            continue
        loads, binds = cell_names(cell.source)
        tags = set(cell_tags(cell))
        if SOLUTION in tags:
            answer_names |= binds
            continue
        if CHECK in tags:
            continue
        used = sorted((loads & answer_names) - defined)
        if used:
            needs[i] = used
            answer_names |= binds
        else:
            defined |= binds - answer_names
    return needs


def loaded_names(src: str) -> set:
    """Every name a code cell reads anywhere (bound before or not; a conservative "uses"), or None when
    it does not parse.

    >>> sorted(loaded_names("from m import f\\nx = f(y)\\n%matplotlib inline"))
    ['f', 'get_ipython', 'y']
    """
    try:
        tree = ast.parse(_python_source(src))
    except SyntaxError:
        return None
    return {n.id for n in ast.walk(tree) if isinstance(n, ast.Name) and isinstance(n.ctx, ast.Load)}


def trim_setup(src: str, used: set) -> str:
    """``src`` without the ``from M import`` names and top-level functions that no name in ``used`` reads
    (what only the solutions need: the workbook and the problems show the student's setup). Other
    statements, ``import M`` lines and comments stay; a cell that does not parse as plain Python is kept.

    >>> print(trim_setup("import numpy as np\\nfrom kinlib.singularities import (task_rows,\\n"
    ...                  "    column_space)\\n\\n\\ndef fd(x):\\n    return x\\n\\nr = 1", {"task_rows", "np"}))
    import numpy as np
    from kinlib.singularities import task_rows
    <BLANKLINE>
    r = 1
    """
    try:
        tree = ast.parse(src)
    except SyntaxError:
        return src
    lines = src.splitlines()
    edits = []  # (first line, last line, replacement lines), 0-based inclusive
    for node in tree.body:
        first = min([node.lineno] + [d.lineno for d in getattr(node, "decorator_list", [])]) - 1
        last = node.end_lineno - 1
        if isinstance(node, ast.ImportFrom) and node.module and node.level == 0:
            keep = [a for a in node.names if a.name == "*" or (a.asname or a.name) in used]
            if len(keep) == len(node.names):
                continue
            names = ", ".join(a.name + (f" as {a.asname}" if a.asname else "") for a in keep)
            text = f"from {node.module} import {names}"
            if len(text) > 110:
                text = f"from {node.module} import (\n    {names},\n)"
            edits.append((first, last, text.splitlines() if keep else []))
        elif isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)) and node.name not in used:
            edits.append((first, last, []))
    if not edits:
        return src
    for first, last, new in sorted(edits, reverse=True):
        lines[first : last + 1] = new
    out: list = []
    for line in lines:  # no runs of blank lines left where statements went
        if not line.strip() and (not out or not out[-1].strip()):
            continue
        out.append(line)
    while out and not out[-1].strip():
        out.pop()
    return "\n".join(out) + ("\n" if src.endswith("\n") else "")
