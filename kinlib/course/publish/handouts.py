"""``kinlib handouts`` (``make handouts``): HTML handouts, student workbooks and an index, from the
executed notebooks.

    kinlib handouts notebooks --out build/handouts [--jobs 2] [--timeout 120] [--no-verify] [--only 05]

(the command line is :mod:`kinlib.course.cli`; the pages and assets are :mod:`kinlib.course.publish.pages`).

For every ``notebooks/NN_*.ipynb`` (executed with nbclient, then exported with nbconvert) it writes

- ``solutions/NN_*.html``: the whole notebook with its outputs;
- ``problems/NN_*.html``: questions, narrative, the student's set-up and figures; left out: ``solution`` and
  ``check`` cells, the set-up's imports and helper functions that only they use (they would give the
  method away: :func:`kinlib.course.publish.analysis.trim_setup`), the untagged markdown inside a worked solution (between a ``question`` and the last
  ``solution``/``check`` cell answering it), cells that read answer variables (and their markdown
  caption just above), any output that repeats an answer cell's output; no prompt numbers; the saved
  widget state pruned to the widgets still shown;
- ``workbooks/NN_*.ipynb``: the student notebook: each ``solution`` code cell becomes a stub
  (``Js = ...  # TODO: ...``, keeping its ``kinlib`` metadata), each solution markdown cell a prompt,
  each ``check`` cell a self-check (:mod:`kinlib.course.workbook.selfcheck`) that compares a fingerprint of the
  student's answer with the reference's made here (a part without a check cell gets one after its
  last solution cell); worked-solution markdown left out as above; the set-up imports only what the
  student starts with (as in the problems); cells that use answer variables run only once those are
  filled in, and say "fix the answer above first" if they fail on a wrong one (``%%needs``,
  :mod:`kinlib.course.workbook.needs`); outputs cleared. Unless ``--no-verify``, each
  workbook is then run top to bottom (the stubs must not crash it);
- the reading aids (``notebooks/README.md``) stay in the problems and the workbooks: objectives, summary,
  ``predict`` questions with their folded ``predict-answer`` (one that gives a graded answer away becomes a
  pointer to the part's self-check), folded ``hint`` steps, ``mistake`` callouts, ``given`` text; the pages fold
  checks, answers and hints in ``<details>`` (:func:`kinlib.course.publish.pages.fold_cells`); under a stub of an
  answer form a student may not know (a set, a choice, a subspace) the workbook shows how to write it;
- ``reference/cheatsheet.html``: the cheat sheet ``notebooks/cheatsheet.md``;
- with ``--audience students`` no solution page, PDF or notebook at all (the folder to publish to students);
- ``index.html`` linking everything, and ``assets/``: MathJax 2 (copied from the installed
  ``jupyter-server-mathjax``), require.js and the ``@jupyter-widgets/html-manager`` embed bundle
  (``npm pack`` from the npm registry into ``build/vendor`` once, then reused), so every page
  renders offline.

Progress goes to stdout; a failing cell stops the job with the notebook and the cell named (exit 1).
"""

from __future__ import annotations

import asyncio
import copy
import json
import re
import shutil
import subprocess
import time
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

import nbformat

from ..schema import (
    ANSWER_TAGS,
    CHECK,
    SELFCHECK,
    SELFCHECK_MODULES,
    SOLUTION,
    Group,
    answer_groups,
    cell_answers,
    cell_meta,
    cell_part,
    cell_reveals,
    cell_tags,
    notebook_sections,
    notebook_title,
    set_source_hidden,
)
from ..workbook.selfcheck import FINGERPRINT_MARK, emit_fingerprints
from .aids import STUDENTS_OUTPUTS, show_students_version, stub, student_reading_aid, students_cell
from .analysis import answer_dependents, loaded_names, trim_setup, worked_narrative
from .execute import notebook_client
from .incremental import Stamps, adopt_sections, build_sections, build_site, code_key, key, print_changed_pdfs
from .pages import CHEATSHEET, HTML_MANAGER, LINKS, REQUIREJS, build_assets, export_html, write_cheatsheet, write_index

__all__ = [
    "build",
    "build_one",
    "execute_notebook",
    "make_problems",
    "make_workbook",
    "prune_widget_state",
    "run_workbook",
    "NotebookFailed",
]


class NotebookFailed(RuntimeError):
    """A notebook failed to execute: names the notebook and the cell.

    Raised by :func:`execute_notebook` and :func:`run_workbook` (so by :func:`build`) for the first cell
    that raises, times out or kills the kernel:

    >>> cell = nbformat.v4.new_code_cell("y = x +", metadata={"tags": ["solution"], "kinlib": {"part": "9.9"}})
    >>> print(NotebookFailed("notebooks/07_broken.ipynb", 2, cell, SyntaxError("invalid syntax")))
    07_broken.ipynb: cell 2 failed (code cell, tags: solution, part 9.9):
        | y = x +
      SyntaxError: invalid syntax
    """

    def __init__(self, path, index, cell, error):
        self.path, self.index, self.cell, self.error = Path(path), index, cell, error
        tags = ", ".join(cell_tags(cell)) or "none"
        part = cell_part(cell_meta(cell))
        src = "\n".join("    | " + line for line in cell.source.splitlines()[:6])
        ename = getattr(error, "ename", type(error).__name__)
        evalue = getattr(error, "evalue", str(error))
        super().__init__(
            f"{self.path.name}: cell {index} failed (code cell, tags: {tags}"
            + (f", part {part}" if part else "")
            + f"):\n{src}\n  {ename}: {evalue}"
        )


# ---------------------------------------------------------------------------------------------------
# Execution


def _capture_code(specs: dict) -> str:
    """Kernel code printing the fingerprints of the answers ``specs`` = {name: (kind, part)}."""
    module, function = emit_fingerprints.__module__, emit_fingerprints.__name__
    return f"__import__({module!r}, fromlist=[{function!r}]).{function}({specs!r}, globals())"


def _students_code() -> str:
    """Kernel code displaying the students' version of the picture the cell just run showed (:mod:`.aids`)."""
    module, function = show_students_version.__module__, show_students_version.__name__
    return f"__import__({module!r}, fromlist=[{function!r}]).{function}()"


async def _execute(nb, path: Path, timeout: int, capture_after: dict) -> dict:
    from nbclient.exceptions import CellExecutionError, CellTimeoutError, DeadKernelError

    client = notebook_client(
        nb,
        timeout=timeout,
        kernel_name="python3",
        record_timing=False,
        resources={"metadata": {"path": str(path.parent)}},
    )
    fingerprints: dict = {}
    count = 0
    async with client.async_setup_kernel(stderr=subprocess.DEVNULL):  # quiet: ipykernel's TCP warning
        msg_id = client.kc.kernel_info()
        info = await client.async_wait_for_reply(msg_id)
        if info is not None and "language_info" in info["content"]:
            nb.metadata["language_info"] = info["content"]["language_info"]
        for i, cell in enumerate(nb.cells):
            if cell.cell_type == "code" and cell.source.strip():
                count += 1
            try:
                await client.async_execute_cell(cell, i, execution_count=count)
            except (CellExecutionError, CellTimeoutError, DeadKernelError) as e:
                raise NotebookFailed(path, i, cell, e) from None
            if cell.cell_type == "code" and cell_reveals(cell):  # its picture for the students (make_problems)
                probe = nbformat.v4.new_code_cell(_students_code())
                try:
                    await client.async_execute_cell(probe, i, store_history=False)
                except CellExecutionError as e:
                    raise NotebookFailed(path, i, cell, e) from None
                finally:
                    nb.cells[i] = cell
                shown = [o for o in probe.outputs if o.get("output_type") in ("display_data", "execute_result")]
                cell.metadata[STUDENTS_OUTPUTS] = shown or None
            if i in capture_after:
                probe = nbformat.v4.new_code_cell(_capture_code(capture_after[i]))
                try:
                    await client.async_execute_cell(probe, i, store_history=False)
                except CellExecutionError as e:
                    raise NotebookFailed(path, i, cell, e) from None
                finally:
                    nb.cells[i] = cell  # execute_cell stores the probe at index i: put the cell back
                text = "".join(o.get("text", "") for o in probe.outputs if o.get("output_type") == "stream")
                for line in text.splitlines():
                    if line.startswith(FINGERPRINT_MARK):
                        for name, fp in json.loads(line[len(FINGERPRINT_MARK) :]).items():
                            if "error" in fp:  # the workbook says: no automatic self-check
                                fp = {
                                    "spec": "none||",
                                    "describe": "",
                                    "warning": f"cell {i}: answer {name!r} has no self-check ({fp['error']})",
                                }
                            fingerprints[(i, name)] = fp
        client.set_widgets_metadata()
    return fingerprints


def execute_notebook(path: Path, timeout: int = 120):
    """Execute ``path``; return (executed notebook, groups, {(cell index, name): fingerprint}).

    It runs the notebook in a Jupyter kernel (seconds; tests/course/test_handouts.py exercises it), hence not run here:

    >>> nb, groups, fps = execute_notebook(Path("notebooks/02_planar_robot_jacobian.ipynb"))  # doctest: +SKIP
    >>> sorted(name for _, name in fps)  # doctest: +SKIP
    ['J', 'Jb', 'Js', 'M', 'S1', 'S2', 'S3', 'T']
    >>> fps[next(k for k in fps if k[1] == "Js")]["spec"][:11]  # doctest: +SKIP
    'matrix|6x3|'
    """
    nb = nbformat.read(path, as_version=4)
    groups = answer_groups(nb)
    capture_after: dict = {}
    for g in groups:
        for part, name, kind, idx in g.answers:
            capture_after.setdefault(idx, {})[name] = (kind, part)
    fps = _run_async(lambda: _execute(nb, Path(path), timeout, capture_after))
    return nb, groups, fps


def _run_async(make_coro):
    """asyncio.run, in a worker thread when this thread already runs an event loop (e.g. under playwright)."""
    try:
        asyncio.get_running_loop()
    except RuntimeError:
        return asyncio.run(make_coro())
    with ThreadPoolExecutor(max_workers=1) as pool:
        return pool.submit(lambda: asyncio.run(make_coro())).result()


# ---------------------------------------------------------------------------------------------------
# Problems: the executed notebook without answers


def _output_texts(output) -> list[str]:
    texts = []
    if output.get("output_type") == "stream":
        texts.append(output.get("text", ""))
    for mime in ("text/plain", "text/latex", "text/markdown", "text/html"):
        v = output.get("data", {}).get(mime)
        if v:
            texts.append(v if isinstance(v, str) else "".join(v))
    return texts


def _leak_signatures(cells) -> tuple[set, set]:
    """Texts (lines of ≥ 12 characters, whole LaTeX outputs) and images shown by answer cells."""
    texts, images = set(), set()
    for c in cells:
        for o in c.get("outputs", []):
            for t in _output_texts(o):
                pieces = [t.strip()]
                if o.get("output_type") == "stream":  # printed lines count one by one
                    pieces += [ln.strip() for ln in t.splitlines()]
                for piece in pieces:
                    if (
                        len(piece) >= 12
                        and sum(ch.isalnum() for ch in piece) >= 4
                        and not piece.startswith("<Figure size")
                    ):
                        texts.add(piece)
            for mime in ("image/png", "image/jpeg"):
                if mime in o.get("data", {}):
                    images.add(o["data"][mime])
    return texts, images


def _leaks(output, texts, images) -> bool:
    data = output.get("data", {})
    if any(data.get(m) in images for m in ("image/png", "image/jpeg") if m in data):
        return True
    for t in _output_texts(output):
        if any(s in t for s in texts):
            return True
    return False


def _widget_ids(obj, found: set):
    if isinstance(obj, str):
        if obj.startswith("IPY_MODEL_"):
            found.add(obj[len("IPY_MODEL_") :])
    elif isinstance(obj, dict):
        for v in obj.values():
            _widget_ids(v, found)
    elif isinstance(obj, list):
        for v in obj:
            _widget_ids(v, found)


def prune_widget_state(nb) -> None:
    """Keep only the saved widget models that the notebook's remaining outputs show (and what they use).

    >>> key = "application/vnd.jupyter.widget-state+json"
    >>> view = nbformat.v4.new_output("display_data", {"application/vnd.jupyter.widget-view+json": {"model_id": "s1"}})
    >>> nb = nbformat.v4.new_notebook(cells=[nbformat.v4.new_code_cell("slider", outputs=[view])])
    >>> nb.metadata["widgets"] = {key: {"state": {"s1": {"state": {"layout": "IPY_MODEL_l1"}},
    ...                                           "l1": {"state": {}}, "gone": {"state": {}}}}}
    >>> prune_widget_state(nb)
    >>> sorted(nb.metadata["widgets"][key]["state"])
    ['l1', 's1']
    """
    key = "application/vnd.jupyter.widget-state+json"
    state = nb.metadata.get("widgets", {}).get(key, {}).get("state")
    if state is None:
        return
    todo = set()
    for c in nb.cells:
        for o in c.get("outputs", []):
            view = o.get("data", {}).get("application/vnd.jupyter.widget-view+json")
            if view:
                todo.add(view["model_id"])
    keep = set()
    while todo:
        mid = todo.pop()
        if mid in keep or mid not in state:
            continue
        keep.add(mid)
        found: set = set()
        _widget_ids(state[mid], found)
        todo |= found - keep
    if keep:
        nb.metadata["widgets"][key]["state"] = {k: v for k, v in state.items() if k in keep}
    else:
        del nb.metadata["widgets"]


def _used_names(cells) -> set | None:
    """Every name the code ``cells`` read (None when one of them does not parse: then trim nothing), and every
    name the markdown ``cells`` show as code (`` `rank_at` ``, `` `task_rows(J, "planar")` ``): a function the
    student's text names is imported in the student's set-up (issue 30).

    >>> import nbformat
    >>> sorted(_used_names([nbformat.v4.new_markdown_cell("take the rank (`rank_at`), or `task_rows(J, 2)`")]))
    ['rank_at', 'task_rows']
    """
    used: set = set()
    for c in cells:
        if c.cell_type == "markdown":
            used |= set(re.findall(r"`([A-Za-z_][A-Za-z0-9_]*)\b", c.source))
        if c.cell_type == "code":
            names = loaded_names(c.source)
            if names is None:
                return None
            used |= names
    return used


def _student_setup(cell, used) -> None:
    """Drop from a kept code cell the imports and helpers only the solutions use (see ``trim_setup``)."""
    if used is not None and cell.cell_type == "code":
        cell.source = trim_setup(cell.source, used)


def make_problems(executed) -> tuple:
    """The problem version of an executed notebook, and a list of notes on what was dropped.

    >>> from nbformat.v4 import new_code_cell, new_markdown_cell, new_notebook, new_output
    >>> nb = new_notebook(cells=[
    ...     new_code_cell("a = 6", execution_count=1),
    ...     new_markdown_cell("**1.1 (2 points).** What is 7a?", metadata={"tags": ["question"]}),
    ...     new_code_cell("x = 7 * a", metadata={"tags": ["solution"], "kinlib": {"part": "1.1", "answers": ["x"]}}),
    ...     new_code_cell("print(x + 1)", outputs=[new_output("stream", text="43\\n")])])
    >>> problems, notes = make_problems(nb)
    >>> [c.source for c in problems.cells], problems.cells[0].execution_count
    (['a = 6', '**1.1 (2 points).** What is 7a?'], None)
    >>> notes
    ['problems: left out 1 cell(s) computed from answers (cells 3)']
    """
    nb = copy.deepcopy(executed)
    answer_cells = [c for c in nb.cells if ANSWER_TAGS & set(cell_tags(c))]
    texts, images = _leak_signatures(answer_cells)
    dependents = answer_dependents(nb)
    narrative = worked_narrative(nb)
    notes, cells = [], []
    if narrative:
        notes.append(
            f"problems and workbook: left out {len(narrative)} untagged markdown cell(s) inside worked "
            f"solutions (cells {', '.join(map(str, sorted(narrative)))})"
        )
    dropped = [i for i in dependents if not ANSWER_TAGS & set(cell_tags(nb.cells[i]))]
    if dropped:
        notes.append(
            f"problems: left out {len(dropped)} cell(s) computed from answers "
            f"(cells {', '.join(map(str, sorted(dropped)))})"
        )
    captions = {
        i - 1
        for i in dependents
        if i > 0
        and nb.cells[i - 1].cell_type == "markdown"
        and not cell_tags(nb.cells[i - 1])
        and not nb.cells[i - 1].source.lstrip().startswith("#")
    }

    def dropped_cell(i, c):
        return bool(ANSWER_TAGS & set(cell_tags(c))) or i in narrative or i in dependents or i in captions

    students_outputs = {i: c.metadata.pop(STUDENTS_OUTPUTS, None) for i, c in enumerate(nb.cells)}
    used = _used_names([c for i, c in enumerate(nb.cells) if not dropped_cell(i, c)])
    revealing = []
    for i, c in enumerate(nb.cells):
        if dropped_cell(i, c):
            continue  # answers, worked-solution steps, what is computed from answers and its caption
        if cell_reveals(c):  # a cell that states a graded answer: its students' version, or nothing
            revealing.append(i)
            if c.cell_type == "code":
                shown = students_outputs.get(i)
                if not shown:
                    continue
                c.outputs = [nbformat.from_dict(o) for o in shown]
            elif students_cell(c) is None:
                continue
        student_reading_aid(c)
        if c.cell_type == "code":
            _student_setup(c, used)  # the student's setup: not the imports that give the method away
            kept = [o for o in c.outputs if i in revealing or not _leaks(o, texts, images)]
            if len(kept) != len(c.outputs):
                notes.append(
                    f"problems: cell {i}: dropped {len(c.outputs) - len(kept)} output(s) that repeat an answer"
                )
            for o in kept:
                if "execution_count" in o:
                    o["execution_count"] = None
            c.outputs = kept
            c.execution_count = None
        cells.append(c)
    if revealing:
        notes.append(
            f"problems and workbook: {len(revealing)} cell(s) that state a graded answer shown in their students' "
            f"version or left out (cells {', '.join(map(str, revealing))})"
        )
    nb.cells = cells
    prune_widget_state(nb)
    return nb, notes


# ---------------------------------------------------------------------------------------------------


def _selfcheck_source(answers: list, fps: dict) -> str:
    by_part: dict = {}
    for part, name, _kind, idx in answers:
        by_part.setdefault(part, []).append(f'{name}="{fps[(idx, name)]["spec"]}"')
    lines = [
        "# Self-check: says whether your answers are right, without showing them.",
        f"from {SELFCHECK_MODULES[0]} import check",
        "",
    ]
    lines += [f'check("{part}", {", ".join(args)})' for part, args in by_part.items()]
    return "\n".join(lines) + "\n"


def make_workbook(source_nb, groups: list, fps: dict, pictures: set | None = None):
    """The student workbook made from the (unexecuted) notebook, its groups and the fingerprints.

    A cell with ``"reveals"`` becomes its students' version (:func:`kinlib.course.publish.aids.students_cell`); a
    code one is kept as a picture when its index is in ``pictures`` (the cells whose students' version the kernel
    made; None: every one that ends with an expression), else left out.

    The fingerprints are those :func:`execute_notebook` reads from the kernel; made by hand here:

    >>> from nbformat.v4 import new_code_cell, new_markdown_cell, new_notebook
    >>> from kinlib.course.schema import answer_groups
    >>> from kinlib.course.workbook.selfcheck import fingerprint
    >>> nb = new_notebook(cells=[
    ...     new_markdown_cell("**1.1 (2 points).** What is 6 * 7?", metadata={"tags": ["question"]}),
    ...     new_code_cell("x = 6 * 7", metadata={"tags": ["solution"], "kinlib": {"part": "1.1", "answers": ["x"]}}),
    ...     new_code_cell("assert x == 42", metadata={"tags": ["check"]})])
    >>> fps = {(1, "x"): {"spec": fingerprint(42, salt="1.1:x"), "describe": "a number"}}
    >>> wb = make_workbook(nb, answer_groups(nb), fps)
    >>> [c.metadata["tags"] for c in wb.cells]
    [['question'], ['solution'], ['selfcheck']]
    >>> print(wb.cells[1].source.splitlines()[1])
    x = ...  # TODO: a number (part 1.1)
    >>> print(wb.cells[2].source.splitlines()[-1])
    check("1.1", x="scalar||7253401f7eb9fd2a")
    """
    nb = copy.deepcopy(source_nb)
    nb.metadata.pop("widgets", None)
    describe = {(idx, name): fp.get("describe", "") for (idx, name), fp in fps.items()}
    check_group = {g.check_cell: g for g in groups if g.check_cell is not None}
    after = {g.last_solution: g for g in groups if g.check_cell is None and g.answers}

    needs = answer_dependents(nb)
    narrative = worked_narrative(nb)
    used = _used_names(
        [c for i, c in enumerate(nb.cells) if not (ANSWER_TAGS & set(cell_tags(c))) and i not in narrative]
    )

    cells = []
    part = ""
    for i, cell in enumerate(nb.cells):
        tags = set(cell_tags(cell))
        meta = cell_meta(cell)
        part = cell_part(meta, part)
        if cell.cell_type == "code":
            cell.outputs, cell.execution_count = [], None
        if SOLUTION in tags:
            if cell.cell_type == "code":
                d = {name: describe.get((i, name), "") for name in cell_answers(meta)}
                cell.source = stub(cell, d)
            else:
                cell.source = f"**Your answer (part {part}):** *write it here.*"
                cell.pop("attachments", None)
            cells.append(cell)
        elif CHECK in tags:
            g = check_group.get(i)
            if g is not None and g.answers:
                cells.append(_selfcheck_cell(g, fps, cell))
        elif i in narrative:
            pass
        elif cell_reveals(cell) and students_cell(cell, None if pictures is None else i in pictures) is None:
            pass  # states a graded answer and has no students' version
        else:
            student_reading_aid(cell)
            if i in needs:
                cell.source = f"%%needs {' '.join(needs[i])}\n" + cell.source
            elif not cell_reveals(cell):  # (a students' picture keeps its import of without_answers)
                _student_setup(cell, used)  # imports only what the student starts with
            cells.append(cell)
        if i in after:
            cells.append(_selfcheck_cell(after[i], fps, None))
    if needs:
        setup = nbformat.v4.new_code_cell(
            f"%load_ext {SELFCHECK_MODULES[0]}\n# (cells marked %%needs run once the answers they use are filled in)"
        )
        setup.metadata["tags"] = ["workbook-setup"]
        set_source_hidden(setup)  # machinery, not reading: folded (it still runs)
        first_code = next((k for k, c in enumerate(cells) if c.cell_type == "code"), len(cells))
        cells.insert(first_code, setup)
    nb.cells = cells
    nbformat.validator.normalize(nb)
    return nb


def _selfcheck_cell(group: Group, fps: dict, original):
    cell = nbformat.v4.new_code_cell(_selfcheck_source(group.answers, fps))
    if original is not None and "kinlib" in original.metadata:
        cell.metadata["kinlib"] = copy.deepcopy(original.metadata["kinlib"])
    cell.metadata["tags"] = [SELFCHECK]
    set_source_hidden(cell)  # the student reads its verdict, not its fingerprints and imports
    return cell


def run_workbook(path: Path, timeout: int = 120):
    """Run a workbook top to bottom (it must not raise); return the executed notebook.

    It runs the workbook in a Jupyter kernel (seconds; tests/course/test_handouts.py exercises it), hence not run
    here:

    >>> nb = run_workbook(Path("build/handouts/workbooks/02_planar_robot_jacobian.ipynb"))  # doctest: +SKIP
    >>> any(o.get("output_type") == "error" for c in nb.cells for o in c.get("outputs", []))  # doctest: +SKIP
    False
    """
    from nbclient.exceptions import CellExecutionError

    nb = nbformat.read(path, as_version=4)
    client = notebook_client(
        nb,
        timeout=timeout,
        kernel_name="python3",
        record_timing=False,
        resources={"metadata": {"path": str(Path(path).parent)}},
    )
    try:
        _run_async(lambda: client.async_execute(stderr=subprocess.DEVNULL))
    except CellExecutionError as e:
        idx = next(
            (k for k, c in enumerate(nb.cells) if any(o.get("output_type") == "error" for o in c.get("outputs", []))),
            -1,
        )
        raise NotebookFailed(path, idx, nb.cells[idx] if idx >= 0 else nbformat.v4.new_code_cell(""), e) from None
    return nb


# ---------------------------------------------------------------------------------------------------
# The job


AUDIENCES = ("all", "students")  # all: problems, solutions, workbooks; students: no solution in any form


def build_one(
    path: Path, out: Path, urls: dict, timeout: int, verify: bool, log=print, links=LINKS, audience: str = "all"
) -> dict:
    """Execute one notebook and write its three handouts; return its index entry.

    It runs the notebook (and, with ``verify``, the workbook) in a Jupyter kernel (seconds;
    tests/course/test_handouts.py exercises it through :func:`build`), hence not run here:

    >>> out = Path("build/handouts")
    >>> urls = build_assets(out / "assets", Path("build/vendor"))  # doctest: +SKIP
    >>> entry = build_one(Path("notebooks/02_planar_robot_jacobian.ipynb"), out, urls, 120, True)  # doctest: +SKIP
    >>> entry["stem"], entry["title"]  # doctest: +SKIP
    ('02_planar_robot_jacobian', 'Jacobian of a planar robot')
    """
    t0 = time.perf_counter()
    stem = path.stem
    source = nbformat.read(path, as_version=4)
    executed, groups, fps = execute_notebook(path, timeout)
    t_exec = time.perf_counter() - t0
    title = notebook_title(executed, stem.replace("_", " "))
    pictures = {i for i, c in enumerate(executed.cells) if c.metadata.get(STUDENTS_OUTPUTS)}
    problems, notes = make_problems(executed)
    for c in executed.cells:  # build-internal: not in the solutions page nor the kept execution
        c.metadata.pop(STUDENTS_OUTPUTS, None)
    if audience == "all":
        export_html(
            executed,
            out / "solutions" / f"{stem}.html",
            urls,
            title=f"{title} (solutions)",
            problems=False,
            links=links,
        )
    export_html(
        problems, out / "problems" / f"{stem}.html", urls, title=f"{title} (problems)", problems=True, links=links
    )
    wb = make_workbook(source, groups, fps, pictures)
    wpath = out / "workbooks" / f"{stem}.ipynb"
    wpath.parent.mkdir(parents=True, exist_ok=True)
    nbformat.write(wb, wpath)
    extra = ""
    if verify:
        t1 = time.perf_counter()
        run_workbook(wpath, timeout)
        extra = f", workbook runs ({time.perf_counter() - t1:.1f} s)"
    notes = notes + [fp["warning"] for fp in fps.values() if "warning" in fp]
    for n in notes:
        log(f"    {stem}: {n}")
    n_answers = sum(len(g.answers) for g in groups)
    log(
        f"  {stem}: done in {time.perf_counter() - t0:.1f} s (executed in {t_exec:.1f} s, "
        f"{n_answers} self-checked answers{extra})"
    )
    return {
        "stem": stem,
        "title": title,
        "sections": notebook_sections(executed),
        "executed": executed,
        "problems": problems,
        "workbook": wb,
        "notes": notes,
    }


def build(
    notebooks: Path,
    out: Path,
    *,
    vendor: Path | None = None,
    jobs: int = 1,
    timeout: int = 120,
    verify: bool = True,
    only: list | None = None,
    site: bool = True,
    pdfs: bool = True,
    fresh: bool = False,
    audience: str = "all",
    reuse_from: Path | None = None,
    variants: Path | None = None,
    secret: Path | None = None,
    log=print,
) -> list:
    """The whole job; raises NotebookFailed naming the notebook and cell when one fails. Writes ``out/``:
    ``index.html``, ``problems/`` and ``solutions/`` (HTML), ``workbooks/`` (.ipynb), and unless switched off
    ``lite/`` (``site``: the JupyterLite site, :func:`kinlib.course.publish.lite.build_lite`) and ``pdf/`` (``pdfs``:
    every page printed by Chromium, :func:`kinlib.course.publish.printing.print_pdfs`); the pages link only what is built.
    ``reference/cheatsheet.html`` (and its PDF) is the one-page cheat sheet (``notebooks/cheatsheet.md``).

    ``audience="students"`` leaves out every solution: no ``solutions/`` pages or PDFs, no solution notebooks
    in the in-browser site, no link to them in the index (what a course publishes to its students; a
    ``solutions/`` folder left in ``out`` by an earlier build is removed first). With ``reuse_from`` (a full
    build of the same notebooks, e.g. build/handouts) it takes from there each section made from the same
    notebook, kinlib, pins and options (its problems page and workbook: the same bytes; never a solution), and
    each PDF of a page with the same bytes, instead of executing, verifying and printing them again
    (:func:`kinlib.course.publish.incremental.adopt_sections`).

    ``variants`` (a roster CSV) gives every student their own numbers (issue 33,
    :mod:`kinlib.course.publish.perstudent`): each student's variant of every notebook that declares variants is
    drawn with the course secret (``secret``: a file; default kinlib grade's), proved well-posed, and written as
    their own pages and workbooks under ``out/students/``; the signed key the grader reads, the report, the links
    and the answer sheets go to ``out/../variants/``.

    Incremental (:mod:`kinlib.course.publish.incremental`): a section whose notebook, kinlib code, pins and options
    are those of the outputs already in ``out/`` is reused, not executed again (the log says "reused"); the site
    and each PDF likewise. ``fresh`` forgets what was built and makes everything again. With ``only``, the other
    sections already built and still current stay on the index.

    A folder without ``NN_*.ipynb`` notebooks is refused before anything is written:

    >>> import tempfile
    >>> with tempfile.TemporaryDirectory() as d:
    ...     build(Path(d), Path(d) / "out")  # doctest: +ELLIPSIS
    Traceback (most recent call last):
        ...
    FileNotFoundError: no notebooks named NN_*.ipynb in ...

    A real build executes every notebook in a Jupyter kernel (minutes; tests/course/test_handouts.py exercises
    it), hence not run here:

    >>> entries = build(Path("notebooks"), Path("build/handouts"), jobs=2, only=["02"])  # doctest: +SKIP
    >>> [e["stem"] for e in entries]  # doctest: +SKIP
    ['02_planar_robot_jacobian']
    """
    t0 = time.perf_counter()
    if audience not in AUDIENCES:
        raise ValueError(f"audience: expected one of {', '.join(AUDIENCES)}, got {audience!r}")
    notebooks, out = Path(notebooks), Path(out)
    links = tuple(k for k, on in (("pdf", pdfs), ("lite", site)) if on)
    all_paths = sorted(p for p in notebooks.glob("[0-9][0-9]_*.ipynb"))
    paths = all_paths
    if only:
        paths = [p for p in all_paths if any(p.stem.startswith(o) for o in only)]
    if not paths:
        raise FileNotFoundError(f"no notebooks named NN_*.ipynb in {notebooks}")
    vendor = Path(vendor) if vendor else out.parent / "vendor"
    log(f"kinlib handouts: {len(paths)} notebook(s) from {notebooks} -> {out} (for {audience})")
    if audience == "students":  # nothing of an earlier full build may stay behind
        for stale in (out / "solutions", out / "pdf" / "solutions"):
            shutil.rmtree(stale, ignore_errors=True)
    urls = build_assets(out / "assets", vendor)
    log(
        f"  assets: MathJax (jupyter-server-mathjax), require.js {REQUIREJS[1]}, "
        f"{HTML_MANAGER[0]} {HTML_MANAGER[1]} ({time.perf_counter() - t0:.1f} s)"
    )
    stamps = Stamps(out)
    if fresh:
        stamps.clear()
    options = {"verify": verify, "links": list(links), "urls": urls, "audience": audience}
    keys = {p: key(code_key(), p.read_bytes(), options) for p in all_paths}
    source = Path(reuse_from) if reuse_from is not None and audience == "students" else None
    if source is not None:
        full = {**options, "audience": "all"}
        adopt_sections(out, paths, keys, stamps, source, {p: key(code_key(), p.read_bytes(), full) for p in paths}, log)
    entries, listed = build_sections(
        out,
        all_paths,
        paths,
        keys,
        stamps,
        lambda p: build_one(p, out, urls, timeout, verify, log, links, audience),
        jobs=jobs,
        audience=audience,
        log=log,
    )
    if variants is not None:
        from ..grader.secret import load_secret
        from .perstudent import build_variants

        build_variants(
            notebooks,
            out,
            variants,
            load_secret(secret),
            entries,
            urls,
            lite=site,
            make_workbook=make_workbook,
            fresh=fresh,
            log=log,
        )
    sheet = notebooks / CHEATSHEET
    if sheet.exists():
        write_cheatsheet(sheet, out / "reference" / "cheatsheet.html", urls, links=links)
    write_index(out, listed, links, audience=audience, cheatsheet=sheet.exists())
    if site:
        build_site(out, paths if audience == "all" else [], [keys[p] for p in paths], stamps, log)
    if pdfs:
        print_changed_pdfs(out, stamps, log, source)
    log(
        f"kinlib handouts: wrote {out / 'index.html'} and {(3 if audience == 'all' else 2) * len(paths)} handouts "
        f"in {time.perf_counter() - t0:.1f} s"
    )
    return entries
