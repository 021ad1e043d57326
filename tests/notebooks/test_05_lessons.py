"""Notebook 05 is four lessons of one sitting each (issue 30, "practice that transfers"), and 06's 6.3 figure labels
each joint beside it (issue 30, statement 10).

One notebook (and one workbook) per problem-set section; inside 05 the lessons are the ``## Lesson 5X · …`` headings:

* the contents table after the objectives links every lesson heading (by the id JupyterLab and nbconvert give it);
* each lesson holds the graded parts it names (5A: 5.1, 5.2; 5B: 5.3; 5C: 5.4; 5D: 5.5, 5.6), opens with what the
  student will be able to do and about how many minutes (at most 25; the lessons add up to the objectives' time), has
  at most 32 cells, asks at least one prediction before it shows the answer, and ends with its "Before you stop"
  recap (5D's just before the notebook's summary);
* the workbook keeps every lesson heading, set-up cell and recap;
* each lesson runs from its start in a fresh kernel: the notebook's set-up cell, then the lesson's cells (its own
  set-up cell rebuilds what earlier lessons made). Slow (the whole notebook once, four kernels).
"""

from __future__ import annotations

import re
from pathlib import Path

import nbformat
import numpy as np
import pytest

from kinlib.course import schema
from kinlib.course.publish import handouts

ROOT = Path(__file__).resolve().parents[2]
NB05 = ROOT / "notebooks" / "05_singularities_planar.ipynb"
PARTS = {"A": ["5.1", "5.2"], "B": ["5.3"], "C": ["5.4"], "D": ["5.5", "5.6"]}
HEAD = re.compile(r"^## Lesson 5([A-D]) · (.+)$", re.M)


def _lessons(nb):
    """{letter: (title, [cells])}: from each lesson heading to the next (the last one to the summary)."""
    starts = [
        (i, *HEAD.match(c.source).groups())
        for i, c in enumerate(nb.cells)
        if c.cell_type == "markdown" and HEAD.match(c.source)
    ]
    end = next(i for i, c in enumerate(nb.cells) if "summary" in schema.cell_tags(c))
    bounds = [s[0] for s in starts[1:]] + [end]
    return {k: (title, nb.cells[i:j]) for (i, k, title), j in zip(starts, bounds)}


def _questions(cells):
    return [re.match(r"\*\*(\d\.\d) \(", c.source).group(1) for c in cells if "question" in schema.cell_tags(c)]


def test_lessons_hold_their_parts_in_order():
    nb = nbformat.read(NB05, as_version=4)
    lessons = _lessons(nb)
    assert list(lessons) == list(PARTS)
    for k, (_, cells) in lessons.items():
        assert _questions(cells) == PARTS[k], k
    # nothing graded outside a lesson, and the part numbers are the problem set's, in order
    assert sum(PARTS.values(), []) == schema.notebook_sections(nb)
    first = next(i for i, c in enumerate(nb.cells) if HEAD.match(c.source))
    assert not [c for c in nb.cells[:first] if schema.cell_part(schema.cell_meta(c))]


def test_each_lesson_opens_with_its_goal_and_time_and_ends_with_a_recap():
    nb = nbformat.read(NB05, as_version=4)
    lessons = _lessons(nb)
    total = 0
    for k, (_, cells) in lessons.items():
        opening = cells[0].source
        assert "After this lesson you can" in opening, k
        m = re.search(r"about (\d+) minutes", opening)
        assert m and int(m.group(1)) <= 25, k
        total += int(m.group(1))
        assert ", ".join(PARTS[k]).replace(", ", " and ") in opening, k
        assert len(cells) <= 32, (k, len(cells))
        # the student predicts before being shown: a predict cell, its folded answer right after it
        predicts = [i for i, c in enumerate(cells) if "predict" in schema.cell_tags(c)]
        assert predicts, k
        for i in predicts:
            assert "predict-answer" in schema.cell_tags(cells[i + 1]) and schema.is_source_hidden(cells[i + 1]), k
        assert cells[-1].cell_type == "markdown" and cells[-1].source.startswith(
            f"**Before you stop (Lesson 5{k}).**"
        ), k
        # a recap is read by students: it states no graded result, so it carries no reveals and is no answer
        assert not schema.cell_reveals(cells[-1]) and not set(schema.cell_tags(cells[-1])) & schema.ANSWER_TAGS
    objectives = next(c for c in nb.cells if "objectives" in schema.cell_tags(c)).source
    assert f"Time: about {total} minutes" in objectives


def test_contents_link_every_lesson():
    nb = nbformat.read(NB05, as_version=4)
    toc = next(c for c in nb.cells if c.get("id") == "05-contents")
    assert nb.cells.index(toc) < next(i for i, c in enumerate(nb.cells) if c.cell_type == "code")
    links = re.findall(r"\[([^\]]+)\]\(#([^)]+)\)", toc.source)
    titles = [f"Lesson 5{k} · {t}" for k, (t, _) in _lessons(nb).items()]
    assert [text for text, _ in links] == titles
    # JupyterLab and nbconvert give a heading the id of its text with spaces as '-'
    assert [target for _, target in links] == [t.replace(" ", "-") for t in titles]


def test_workbook_keeps_every_lesson_cell():
    nb = nbformat.read(NB05, as_version=4)
    groups = schema.answer_groups(nb)
    fps = {(idx, name): {"spec": "none||", "describe": ""} for g in groups for _, name, _, idx in g.answers}
    wb = handouts.make_workbook(nbformat.read(NB05, as_version=4), groups, fps)
    kept = {c.get("id") for c in wb.cells}
    lesson_cells = ["05-contents"] + [
        c.get("id")
        for _, cells in _lessons(nb).values()
        for c in (cells[0], cells[-1], *[c for c in cells[1:3] if c.get("id", "").startswith("05-setup")])
    ]
    assert len(lesson_cells) == 1 + 4 * 2 + 2
    assert not [cid for cid in lesson_cells if cid not in kept]


@pytest.mark.slow
def test_each_lesson_runs_from_its_start_in_a_fresh_kernel():
    """One kernel, its namespace emptied (``%reset -f``) at each lesson's start: the notebook's set-up cell, then the
    lesson's code cells (a name only an earlier lesson binds is a NameError). The whole notebook runs once."""
    from kinlib.course.publish.execute import notebook_client

    nb = nbformat.read(NB05, as_version=4)
    setup = next(c for c in nb.cells if c.cell_type == "code")
    run, starts = nbformat.v4.new_notebook(metadata=nb.metadata), {}
    for letter, (_, cells) in _lessons(nb).items():
        starts[len(run.cells)] = letter
        run.cells.append(nbformat.v4.new_code_cell("%reset -f\nimport matplotlib\nmatplotlib.use('Agg')"))
        run.cells += [nbformat.v4.new_code_cell(c.source) for c in [setup, *cells] if c.cell_type == "code"]
    client = notebook_client(run, timeout=600, kernel_name="python3", cwd=str(ROOT / "notebooks"), allow_errors=True)
    client.execute()
    lesson, failed = None, []
    for i, c in enumerate(run.cells):
        lesson = starts.get(i, lesson)
        failed += [(lesson, o["ename"], o["evalue"]) for o in c.outputs if o.get("output_type") == "error"]
    assert not failed, failed


def test_06_polar_arm_labels_sit_next_to_their_joints():
    """Each θi label of 6.3's drawing is within 0.4 (data units, reach about 2) of its joint."""
    import matplotlib.pyplot as plt
    import sympy as sp

    from kinlib import plotting, robots

    nb = nbformat.read(ROOT / "notebooks" / "06_singularities_spatial.ipynb", as_version=4)
    src = next(c for c in nb.cells if c.get("id") == "06-63-given").source.replace("plt.show()", "")
    ns = {"np": np, "sp": sp, "plt": plt, "robots": robots, "plotting": plotting}
    exec(compile(src, "06:06-63-given", "exec"), ns)
    art, sk = ns["art"], ns["sk"]
    assert [t.get_text() for t in art.labels] == [r"$\theta_{1}$", r"$\theta_{2}$", r"$\theta_{3}$"]
    for i, t in enumerate(art.labels):
        assert np.linalg.norm(np.array(t.get_position_3d(), dtype=float) - sk[:, i + 1]) < 0.4, i
    plt.close("all")
