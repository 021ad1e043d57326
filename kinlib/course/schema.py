"""The notebook schema: the one place that reads cell tags, ``kinlib`` metadata and points.

The solution notebooks in ``notebooks/`` follow one structure, read here for both the handouts
(:mod:`kinlib.course.publish.handouts`) and the checker (:mod:`kinlib.course.grader.grade`):

* **notebook metadata** ``metadata.kinlib``: ``notebook`` (the id a submission is recognised by, students
  rename files), ``title``, ``sections``;
* **cell tags** (``metadata.tags``): ``question`` (a markdown cell opening a graded part; "(N points)" in
  its text gives the points), ``solution`` (code cells computing the answers, markdown cells explaining
  them), ``check`` (cells testing the answers: removed from problems and workbooks), ``selfcheck``
  (the workbook's self-check cells, written by ``kinlib handouts``); the reading aids (kept in problems and
  workbooks; see ``notebooks/README.md``): ``objectives``, ``summary``, ``predict`` and its folded
  ``predict-answer``, ``hint`` (folded), ``mistake`` (a callout) and ``given`` (text a student needs inside a
  worked solution);
* **cell metadata** ``metadata.kinlib`` of a ``solution`` code cell: ``part`` ("2.1"), ``answers``
  (the variable names graded), ``kinds`` ({name: "expr" | "set" | "subspace" | "choice"}; "default"
  is "expr"), ``properties`` ({name: "nonsingular"}: graded by that property, see :func:`grading_kind`),
  ``describe`` ({name: words for the workbook's stub}), ``points`` (overrides the
  question's points for that part), ``answer_points`` ({name: points} of answers within the part, for
  partial credit; answers not listed share the rest evenly) and ``manual`` ({label: points} of work graded
  by hand, e.g. {"drawing": 5}; also allowed on ``solution`` markdown cells). See :mod:`kinlib.course.grader.credit`.

Cells may be nbformat ``NotebookNode`` objects or the plain dicts of ``json.load``; anything malformed
(tags that are not a list, metadata that is not a dict) reads as absent rather than raising.
"""

from __future__ import annotations

import ast
import re
from dataclasses import dataclass, field

__all__ = [
    "QUESTION",
    "SOLUTION",
    "CHECK",
    "SELFCHECK",
    "ANSWER_TAGS",
    "OBJECTIVES",
    "SUMMARY",
    "PREDICT",
    "PREDICT_ANSWER",
    "HINT",
    "MISTAKE",
    "GIVEN",
    "FOLDED_TAGS",
    "is_source_hidden",
    "set_source_hidden",
    "KINDS",
    "SELFCHECK_MODULES",
    "cell_tags",
    "cell_source",
    "cell_meta",
    "cell_part",
    "cell_answers",
    "cell_reveals",
    "students_markdown",
    "answer_kind",
    "grading_kind",
    "PROPERTIES",
    "notebook_meta",
    "notebook_id",
    "notebook_title",
    "notebook_sections",
    "points_in",
    "Group",
    "answer_groups",
    "Part",
    "parse_parts",
    "stash_points",
    "is_plain_selfcheck",
    "assigned_names",
    "match_notebook",
]

QUESTION, SOLUTION, CHECK, SELFCHECK = "question", "solution", "check", "selfcheck"
ANSWER_TAGS = frozenset({SOLUTION, CHECK})
# Reading aids (issue 21): kept in the problems and the workbooks. ``predict-answer``, ``hint`` and ``check``
# cells are folded (source hidden in JupyterLab, inside <details> on the pages).
OBJECTIVES, SUMMARY, PREDICT, PREDICT_ANSWER = "objectives", "summary", "predict", "predict-answer"
HINT, MISTAKE, GIVEN = "hint", "mistake", "given"
FOLDED_TAGS = frozenset({PREDICT_ANSWER, HINT, CHECK})
KINDS = ("default", "expr", "choice", "set", "subspace")
# the module a workbook's self-check cells import ``check`` from: today's, and those of workbooks handed out
# before kinlib.course was laid out in folders (kinlib.course.selfcheck) or existed (kinlib.selfcheck)
SELFCHECK_MODULES = ("kinlib.course.workbook.selfcheck", "kinlib.course.selfcheck", "kinlib.selfcheck")
_POINTS_RE = [re.compile(r"\((\d+(?:\.\d+)?)\s*points?\)", re.I), re.compile(r"(\d+(?:\.\d+)?)\s*points?\b", re.I)]


# ----------------------------------------------------------------------------------------- one cell


def _metadata(obj) -> dict:
    md = obj.get("metadata") if isinstance(obj, dict) else None
    return md if isinstance(md, dict) else {}


def cell_tags(cell) -> list[str]:
    """The cell's tags as strings (``[]`` when absent or not a list).

    >>> cell_tags({"metadata": {"tags": ["solution", 3]}})
    ['solution', '3']
    >>> cell_tags({"metadata": {"tags": "solution"}}), cell_tags({})
    ([], [])
    """
    tags = _metadata(cell).get("tags") or []
    return [str(t) for t in tags] if isinstance(tags, (list, tuple)) else []


def is_source_hidden(cell) -> bool:
    """Whether JupyterLab shows the cell folded (``metadata.jupyter.source_hidden``).

    >>> is_source_hidden({"metadata": {"jupyter": {"source_hidden": True}}}), is_source_hidden({})
    (True, False)
    """
    jup = _metadata(cell).get("jupyter")
    return isinstance(jup, dict) and jup.get("source_hidden") is True


def set_source_hidden(cell) -> None:
    """Fold the cell in JupyterLab (``metadata.jupyter.source_hidden = True``).

    >>> c = {"metadata": {}}
    >>> set_source_hidden(c); c["metadata"]
    {'jupyter': {'source_hidden': True}}
    """
    md = cell.setdefault("metadata", {})
    jup = md.get("jupyter") if isinstance(md.get("jupyter"), dict) else {}
    jup["source_hidden"] = True
    md["jupyter"] = jup


def cell_source(cell) -> str:
    """The cell's source as one string (nbformat files may store it as a list of lines).

    >>> cell_source({"source": ["x = 1\\n", "y = 2"]})
    'x = 1\\ny = 2'
    """
    s = cell.get("source", "") if isinstance(cell, dict) else ""
    return "".join(s) if isinstance(s, list) else str(s)


def cell_meta(cell) -> dict:
    """The cell's ``kinlib`` metadata (a copy; ``{}`` when absent or not a dict).

    >>> cell_meta({"metadata": {"kinlib": {"part": "1.1", "answers": ["J"]}}})
    {'part': '1.1', 'answers': ['J']}
    >>> cell_meta({"metadata": {"kinlib": None}})
    {}
    """
    meta = _metadata(cell).get("kinlib")
    return dict(meta) if isinstance(meta, dict) else {}


def cell_part(meta: dict, default: str = "") -> str:
    """The part id of a cell's ``kinlib`` metadata as a string, or ``default`` when it has none.

    >>> cell_part({"part": 2.1}), cell_part({}), cell_part({}, "q3")
    ('2.1', '', 'q3')
    """
    part = meta.get("part")
    return str(part) if part is not None and str(part) else default


def cell_reveals(cell) -> list[str]:
    """The graded parts a cell states the answer of (``"kinlib": {"reveals": ["5.1", ...]}``), as strings; [] when
    it states none. Every students' file leaves such a cell out, shows its ``students`` markdown instead, or (a
    picture) shows it without what answers those parts: :mod:`kinlib.course.publish.handouts`, ``notebooks/README.md``.

    >>> cell_reveals({"metadata": {"kinlib": {"reveals": ["5.1", 6.1]}}}), cell_reveals({"metadata": {}})
    (['5.1', '6.1'], [])
    >>> cell_reveals({"metadata": {"kinlib": {"reveals": "5.1"}}})
    ['5.1']
    """
    got = cell_meta(cell).get("reveals")
    if got is None or got == "":
        return []
    items = [got] if isinstance(got, (str, int, float)) else got if isinstance(got, (list, tuple)) else []
    return [str(x) for x in items if str(x)]


def students_markdown(cell) -> str | None:
    """The students' version of a markdown cell that ``reveals`` a graded answer (its ``kinlib.students`` text),
    or None (then the students' files leave the cell out).

    >>> students_markdown({"metadata": {"kinlib": {"reveals": ["1.3"], "students": "Which $n$? See 1.3."}}})
    'Which $n$? See 1.3.'
    >>> students_markdown({"metadata": {"kinlib": {"reveals": ["1.3"]}}}) is None
    True
    """
    text = cell_meta(cell).get("students")
    if isinstance(text, list):
        text = "".join(str(x) for x in text)
    return text if isinstance(text, str) and text.strip() else None


def cell_answers(meta: dict) -> list[str]:
    """The answer variable names of a ``solution`` cell's ``kinlib`` metadata, in order, without
    repeats (names that are not strings are ignored: they cannot be variables).

    >>> cell_answers({"answers": ["J", "detJ", "J", 3]})
    ['J', 'detJ']
    """
    names = meta.get("answers") or []
    out: list[str] = []
    for n in names if isinstance(names, (list, tuple)) else []:
        if isinstance(n, str) and n not in out:
            out.append(n)
    return out


def answer_kind(meta: dict, name: str) -> str:
    """The kind of answer ``name``: ``kinds[name]`` of the cell's ``kinlib`` metadata, with "default",
    ``None`` and a missing entry all read as "expr". Other values are returned as given (the self-check
    then says it cannot check them; the checker compares them as expressions).

    >>> answer_kind({"kinds": {"S": "set", "J": "default"}}, "S"), answer_kind({"kinds": {"J": "default"}}, "J")
    ('set', 'expr')
    >>> answer_kind({}, "J")
    'expr'
    """
    kinds = meta.get("kinds")
    kind = kinds.get(name) if isinstance(kinds, dict) else None
    return "expr" if kind in (None, "default") else str(kind)


PROPERTIES = ("nonsingular",)


def grading_kind(meta: dict, name: str) -> str:
    """How the grader compares answer ``name``: "property:<p>" when the cell's ``kinlib`` metadata declares
    ``properties`` {name: p} (an open-ended answer graded by the property asked, e.g. "nonsingular":
    det(J Jᵀ) ≠ 0 for every θ of the student's own robot, never by one design's value), else :func:`answer_kind`.
    The self-check judges a property answer by the same judge (:mod:`kinlib.course.answers.properties`).

    >>> grading_kind({"properties": {"d": "nonsingular"}}, "d"), grading_kind({"kinds": {"S": "set"}}, "S")
    ('property:nonsingular', 'set')
    """
    props = meta.get("properties")
    prop = props.get(name) if isinstance(props, dict) else None
    if isinstance(prop, str) and prop:
        return f"property:{prop}"
    return answer_kind(meta, name)


# ----------------------------------------------------------------------------------------- the notebook


def notebook_meta(nb) -> dict:
    """The notebook's ``kinlib`` metadata (``{}`` when absent or not a dict).

    >>> notebook_meta({"metadata": {"kinlib": {"notebook": "02_planar"}}})
    {'notebook': '02_planar'}
    """
    meta = _metadata(nb).get("kinlib")
    return dict(meta) if isinstance(meta, dict) else {}


def notebook_id(nb) -> str | None:
    """``metadata.kinlib.notebook``, the id a submission is recognised by; ``None`` if missing or empty.

    >>> notebook_id({"metadata": {"kinlib": {"notebook": "02_planar"}}}), notebook_id({"cells": []})
    ('02_planar', None)
    """
    nid = notebook_meta(nb).get("notebook")
    return nid if isinstance(nid, str) and nid else None


def notebook_title(nb, default: str) -> str:
    """``metadata.kinlib.title``, or ``default`` when it is missing or empty.

    >>> notebook_title({"metadata": {"kinlib": {"title": "Singularities"}}}, "x"), notebook_title({}, "05 sing")
    ('Singularities', '05 sing')
    """
    title = notebook_meta(nb).get("title")
    return str(title) if title else default


def notebook_sections(nb) -> list[str]:
    """``metadata.kinlib.sections`` as strings.

    >>> notebook_sections({"metadata": {"kinlib": {"sections": [5.1, "5.2"]}}})
    ['5.1', '5.2']
    """
    sections = notebook_meta(nb).get("sections") or []
    return [str(s) for s in sections] if isinstance(sections, (list, tuple)) else []


def points_in(text: str) -> float | None:
    """The points a question cell's text announces: "(N points)" first, else "N points"; ``None`` if none.

    >>> points_in("**1.5 (10 points).** Which joint ..."), points_in("worth 2.5 point"), points_in("no score")
    (10.0, 2.5, None)
    """
    for rx in _POINTS_RE:
        m = rx.search(text)
        if m:
            return float(m.group(1))
    return None


def _cells(nb) -> list:
    cells = nb.get("cells") if isinstance(nb, dict) else None
    return [c for c in cells if isinstance(c, dict)] if isinstance(cells, list) else []


def _is(cell, cell_type: str) -> bool:
    return cell.get("cell_type") == cell_type


# ----------------------------------------------------------------------------------------- answer groups (handouts)


@dataclass
class Group:
    """The answers checked together: solution cells up to a check cell (or the next question).

    :func:`answer_groups` makes them; each answer is (part, name, kind, cell index):

    >>> Group()
    Group(answers=[], check_cell=None, last_solution=-1)
    >>> Group(answers=[("1.1", "J", "expr", 1)], check_cell=2, last_solution=1).answers[0][1]
    'J'
    """

    answers: list = field(default_factory=list)  # (part, name, kind, cell index)
    check_cell: int | None = None  # index of the check cell, if any
    last_solution: int = -1


def answer_groups(nb) -> list[Group]:
    """Group the answer variables of ``solution`` code cells by the ``check`` cell that follows them
    (a ``question`` cell closes a group too). Raises ValueError for a cell tagged both solution and check.

    >>> nb = {"cells": [{"cell_type": "markdown", "metadata": {"tags": ["question"]}},
    ...                 {"cell_type": "code", "metadata": {"tags": ["solution"],
    ...                  "kinlib": {"part": "1.1", "answers": ["J"], "kinds": {"J": "default"}}}},
    ...                 {"cell_type": "code", "metadata": {"tags": ["check"]}}]}
    >>> [(g.answers, g.check_cell, g.last_solution) for g in answer_groups(nb)]
    [([('1.1', 'J', 'expr', 1)], 2, 1)]
    """
    groups, pending = [], Group()

    def close(check=None):
        nonlocal pending
        if pending.answers or check is not None:
            pending.check_cell = check
            groups.append(pending)
        pending = Group()

    for i, cell in enumerate(_cells(nb)):
        tags = cell_tags(cell)
        if SOLUTION in tags and CHECK in tags:
            raise ValueError(f"cell {i} is tagged both 'solution' and 'check'")
        if QUESTION in tags:
            close()
        if SOLUTION in tags and _is(cell, "code"):
            meta = cell_meta(cell)
            for name in cell_answers(meta):
                pending.answers = [a for a in pending.answers if a[1] != name]
                pending.answers.append((cell_part(meta), name, grading_kind(meta, name), i))
            pending.last_solution = i
        if CHECK in tags:
            close(check=i)
    close()
    return groups


# ----------------------------------------------------------------------------------------- graded parts (checker)


@dataclass
class Part:
    """A graded part: its id, points, answer names and kinds, and its solution cells (code cell indices).

    :func:`parse_parts` makes them from a solution notebook:

    >>> Part("2.1", 5.0, ["J"], {"J": "expr"})
    Part(part='2.1', points=5.0, answers=['J'], kinds={'J': 'expr'}, cells=[], answer_points={}, manual={})
    """

    part: str
    points: float
    answers: list
    kinds: dict
    cells: list = field(default_factory=list)
    answer_points: dict = field(default_factory=dict)  # {answer name: points} declared for partial credit
    manual: dict = field(default_factory=dict)  # {label: points} of work graded by hand


def parse_parts(nb) -> list[Part]:
    """Graded parts of a solution notebook, in order.

    A part is made of the ``solution`` code cells with ``answers`` of one ``part`` id (a cell without one
    belongs to "q<N>", its question's number). Points: ``points`` of the cell's metadata if given, else
    the "(N points)" of the question cell above, split evenly between the parts sharing that question.
    A ``solution`` cell (code or markdown) whose metadata has ``manual`` ({label: points}) makes a part too,
    even without answers (5.2's drawing); ``answer_points`` and ``manual`` are collected per part.

    >>> q = {"cell_type": "markdown", "metadata": {"tags": ["question"]}, "source": "**1 (6 points).**"}
    >>> def sol(part, *names):
    ...     return {"cell_type": "code", "metadata": {"tags": ["solution"],
    ...             "kinlib": {"part": part, "answers": list(names)}}}
    >>> [(p.part, p.points, p.answers, p.cells) for p in parse_parts({"cells": [q, sol("1a", "x"), sol("1b", "y")]})]
    [('1a', 3.0, ['x'], [0]), ('1b', 3.0, ['y'], [1])]
    """
    parts: dict[str, Part] = {}
    question_of: dict[str, int] = {}
    q_idx, q_points = -1, None
    code_idx = -1
    explicit: dict[str, float] = {}
    for cell in _cells(nb):
        tags = cell_tags(cell)
        if _is(cell, "code"):
            code_idx += 1
        if _is(cell, "markdown") and QUESTION in tags:
            q_idx += 1
            q_points = points_in(cell_source(cell))
            continue
        meta = cell_meta(cell)
        names = cell_answers(meta) if _is(cell, "code") else []
        manual = _points_map(meta.get("manual"))
        if SOLUTION not in tags or not (names or manual):
            continue
        pid = cell_part(meta, f"q{q_idx + 1}")
        p = parts.setdefault(pid, Part(pid, q_points if q_points is not None else 0.0, [], {}))
        for name in names:
            if name not in p.answers:
                p.answers.append(name)
            p.kinds[name] = grading_kind(meta, name)
        p.answer_points.update(_points_map(meta.get("answer_points")))
        p.manual.update(manual)
        if _is(cell, "code"):
            p.cells.append(code_idx)
        question_of.setdefault(pid, q_idx)
        if "points" in meta:
            explicit[pid] = float(meta["points"])
    # several parts under one question cell share its points
    shared: dict[int, list] = {}
    for pid, q in question_of.items():
        if pid not in explicit:
            shared.setdefault(q, []).append(pid)
    for pids in shared.values():
        for pid in pids:
            parts[pid].points = round(parts[pid].points / len(pids), 3)
    for pid, pts in explicit.items():
        parts[pid].points = pts
    return list(parts.values())


def _points_map(obj) -> dict:
    """{str: float} of a metadata mapping of points, keeping only finite numbers ≥ 0 (not bools)."""
    out = {}
    for k, v in obj.items() if isinstance(obj, dict) else ():
        if isinstance(v, (int, float)) and not isinstance(v, bool) and v == v and 0 <= v < float("inf"):
            out[str(k)] = float(v)
    return out


def stash_points(nb) -> dict:
    """{code cell index: answer names} to keep when a part ends (before the next ``question`` cell).

    An answer is the value its variable has at the end of its part: the solution cell plus any cells
    a student added below it, up to the next question. Later cells that reuse the name (or ``del`` it)
    do not change it. Answers of the last part are read at the end of the notebook (not listed here).

    >>> cells = [{"cell_type": "code", "metadata": {"tags": ["solution"], "kinlib": {"answers": ["J"]}}},
    ...          {"cell_type": "code", "metadata": {}},
    ...          {"cell_type": "markdown", "metadata": {"tags": ["question"]}}]
    >>> stash_points({"cells": cells})
    {1: ['J']}
    """
    out: dict = {}
    pending: list = []
    code_idx = -1
    for cell in _cells(nb):
        if _is(cell, "markdown") and QUESTION in cell_tags(cell):
            if pending and code_idx >= 0:
                out.setdefault(code_idx, []).extend(n for n in pending if n not in out.get(code_idx, []))
            pending = []
        if _is(cell, "code"):
            code_idx += 1
            if SOLUTION in cell_tags(cell):
                pending += cell_answers(cell_meta(cell))
    return out


def is_plain_selfcheck(cell) -> bool:
    """A workbook self-check cell as ``kinlib handouts`` writes it: tagged ``selfcheck``, holding only
    ``from kinlib.course.workbook.selfcheck import check`` (or an older workbook's ``kinlib.course.selfcheck`` or ``kinlib.selfcheck``) and
    ``check(...)`` calls with constant arguments. It cannot change an answer.

    >>> src = 'from kinlib.course.workbook.selfcheck import check\\ncheck("1.1", J="matrix|6x3|0123456789abcdef")'
    >>> is_plain_selfcheck({"metadata": {"tags": ["selfcheck"]}, "source": src})
    True
    >>> is_plain_selfcheck({"metadata": {"tags": ["selfcheck"]}, "source": src + "\\nJ = 0"})
    False
    """
    if SELFCHECK not in cell_tags(cell):
        return False
    try:
        tree = ast.parse(cell_source(cell))
    except SyntaxError:
        return False
    for node in tree.body:
        if (
            isinstance(node, ast.ImportFrom)
            and node.module in SELFCHECK_MODULES
            and [a.name for a in node.names] == ["check"]
            and all(a.asname is None for a in node.names)
        ):
            continue
        if (
            isinstance(node, ast.Expr)
            and isinstance(node.value, ast.Call)
            and isinstance(node.value.func, ast.Name)
            and node.value.func.id == "check"
            and all(isinstance(a, ast.Constant) for a in node.value.args)
            and all(isinstance(k.value, ast.Constant) for k in node.value.keywords)
        ):
            continue
        return False
    return True


# ----------------------------------------------------------------------------------------- a notebook without metadata

_PART_RE = re.compile(r"(?<![\d.])(\d+\.\d+)(?![\d.])")


def assigned_names(nb) -> set:
    """Names assigned at the top level of the notebook's code cells (``x = …``, ``a, b = …``, ``x += …``,
    ``x: T = …``); cells that do not parse (magics, syntax errors) are read line by line.

    >>> sorted(assigned_names({"cells": [{"cell_type": "code", "source": "J, d = f()\\n%time x = 1\\ny += 2"}]}))
    ['J', 'd', 'x', 'y']
    """

    def targets(node):
        if isinstance(node, ast.Name):
            yield node.id
        elif isinstance(node, (ast.Tuple, ast.List)):
            for e in node.elts:
                yield from targets(e)
        elif isinstance(node, ast.Starred):
            yield from targets(node.value)

    def scan(src):
        tree = ast.parse(src)
        for node in tree.body:
            if isinstance(node, ast.Assign):
                for t in node.targets:
                    out.update(targets(t))
            elif isinstance(node, (ast.AugAssign, ast.AnnAssign)):
                out.update(targets(node.target))

    out: set = set()
    for cell in _cells(nb):
        if not _is(cell, "code"):
            continue
        src = cell_source(cell)
        try:
            scan(src)
        except (SyntaxError, ValueError):
            for line in src.splitlines():
                line = line.lstrip("%! ").split(" ", 1)[-1] if line.lstrip().startswith(("%", "!")) else line
                try:
                    scan(line.strip())
                except (SyntaxError, ValueError):
                    continue
    return out


def match_notebook(nb, references: dict) -> str | None:
    """The id of the assignment a notebook without ``metadata.kinlib.notebook`` answers (solution cells pasted
    into a new notebook), recognised by its questions: the answer names its code cells assign and the part
    numbers ("5.1") its markdown mentions, against ``references`` = {id: [parts as dicts with "part" and
    "answers"]}. ``None`` unless one assignment fits clearly (at least half of its answers assigned, or half
    of its parts mentioned and some answer assigned) and better than every other.

    >>> refs = {"02": [{"part": "2.1", "answers": ["M", "S1"]}, {"part": "2.2", "answers": ["Js"]}],
    ...         "05": [{"part": "5.1", "answers": ["detJ", "singular_theta2"]}]}
    >>> cell = {"cell_type": "code", "source": "detJ = Jt.det()\\nsingular_theta2 = {th2: S}"}
    >>> match_notebook({"cells": [cell]}, refs), match_notebook({"cells": []}, refs)
    ('05', None)
    """
    assigned = assigned_names(nb)
    text = "\n".join(cell_source(c) for c in _cells(nb) if _is(c, "markdown"))
    mentioned = set(_PART_RE.findall(text))
    scored = []
    for nid, parts in (references or {}).items():
        parts = [p for p in parts or [] if isinstance(p, dict)]
        answers = {a for p in parts for a in (p.get("answers") or []) if isinstance(a, str)}
        ids = {str(p.get("part")) for p in parts if p.get("part") is not None}
        if not answers and not ids:
            continue
        hit = len(answers & assigned)
        cover = hit / len(answers) if answers else 0.0
        said = len(ids & mentioned) / len(ids) if ids else 0.0
        if cover >= 0.5 or (said >= 0.5 and hit > 0):
            scored.append(((round(cover + said, 9), hit), nid))
    scored.sort(key=lambda t: t[0], reverse=True)
    if not scored or (len(scored) > 1 and scored[0][0] == scored[1][0]):
        return None
    return scored[0][1]
