"""The instructor checker (``kinlib grade``, kinlib.course.grader.grade) on a fixture notebook and, when present, notebook 02.

One batch of submissions made from ``tests/fixtures/grade`` (the solution notebook, its workbook
filled in right, filled in with mistakes, left untouched, and hostile ones) is graded once, two at a
time; the tests read its rows and feedback.
"""

from __future__ import annotations

import copy
import csv
import json
import shutil
from pathlib import Path

import pytest

from kinlib.course import schema
from kinlib.course.answers import compare as C
from kinlib.course.cli import main
from kinlib.course.grader import grade
from kinlib.course.grader.secret import load_secret

FIX = Path(__file__).resolve().parents[1] / "fixtures" / "grade"
REF = FIX / "notebooks" / "90_grade_fixture.ipynb"
WB = FIX / "workbooks" / "90_grade_fixture.ipynb"
ROOT = Path(__file__).resolve().parents[2]
PARTS = ["1.1", "1.2", "1.3", "1.4", "1.5"]
# every cell of the batch's submissions has this wall-clock limit (the fixture's import cell included): ample for
# its work on a loaded 2-core machine (3 s was not: \`import sympy, kinlib\` takes ~1.5 s idle), while the endless
# cells (a loop, a sleep that ignores SIGINT) still cost only this much, well under the submission's limit
CELL_TIMEOUT = 10
SUBMISSION_TIMEOUT = 150


def _load(p):
    return json.loads(Path(p).read_text())


def _solution_sources(nb) -> dict:
    out = {}
    for c in nb["cells"]:
        meta = c["metadata"].get("kinlib", {})
        if c["cell_type"] == "code" and "solution" in c["metadata"].get("tags", []) and meta.get("answers"):
            out[meta["part"]] = "".join(c["source"])
    return out


def _code(src):
    return {"cell_type": "code", "metadata": {}, "source": src, "outputs": [], "execution_count": None}


def completed(overrides=None, top=(), after=None, end=()) -> dict:
    """The workbook with every stub replaced by the reference's solution (or ``overrides[part]``)."""
    wb, ref = _load(WB), _solution_sources(_load(REF))
    overrides = overrides or {}
    cells = []
    for c in wb["cells"]:
        c = copy.deepcopy(c)
        meta = c["metadata"].get("kinlib", {})
        if c["cell_type"] == "code" and "solution" in c["metadata"].get("tags", []) and meta.get("answers"):
            c["source"] = overrides.get(meta["part"], ref[meta["part"]])
        cells.append(c)
        if after and meta.get("part") == after[0] and "solution" in c["metadata"].get("tags", []):
            cells.append(_code(after[1]))
    first = next(i for i, c in enumerate(cells) if c["cell_type"] == "code")
    for k, src in enumerate(top):
        cells.insert(first + k, _code(src))
    cells += [_code(s) for s in end]
    wb["cells"] = cells
    return wb


RIGHT_FORMS = {  # right answers in other forms than the reference's
    "1.1": "Js = [arm.jacobian_space()[:, i] for i in range(3)]   # a list of columns",
    "1.2": "detJ = arm.jacobian_space().extract([2, 3, 4], [0, 1, 2]).det()   # not simplified",
    "1.3": "moves = sp.Matrix([[2, 1, 3], [L, 0, L], [-L, 0, -L]])   # another basis, plus a dependent column",
    "1.4": "singular = sp.FiniteSet(-sp.pi / 4, 3 * sp.pi / 4)   # principal values, no dict",
    "1.5": "joint_x = [2, 1]\njoint_y = (1,)",
}
MISTAKES_A = {
    "1.1": "Js = kinlib.linear_first(arm.jacobian_space())",
    "1.2": "detJ = sp.simplify(arm.jacobian_space().extract([2, 3, 4], [0, 1, 2]).det()).subs(L, 1)",
    "1.3": "moves = sp.Matrix([[1, 0, 0], [1, L, -L]])",
    "1.4": "singular = {th2: sp.FiniteSet(135, 315)}",
    "1.5": "joint_x = 1\njoint_y = 1",
}
MISTAKES_B = {
    "1.1": "J0 = arm.jacobian_space()\nJs = sp.Matrix.hstack(J0[:, 1], J0[:, 0], J0[:, 2])",
    "1.2": "detJ = -sp.simplify(arm.jacobian_space().extract([2, 3, 4], [0, 1, 2]).det())",
    "1.3": "moves = sp.Matrix([1, 0, 0])",
    "1.4": "singular = {th2: sp.FiniteSet(3 * sp.pi / 4)}",
    "1.5": "joint_x = (0, 1)\njoint_y = 2",
}
CHEAT = (
    "import builtins, kinlib, sympy\n"
    "import kinlib.course.workbook.selfcheck\n"
    "kinlib.course.workbook.selfcheck.check = lambda *a, **k: print('pass')\n"
    "sympy.simplify = lambda *a, **k: sympy.S.Zero\n"
    "sympy.Expr.evalf = lambda self, *a, **k: sympy.Float(0)\n"
    "sympy.MatrixBase.__eq__ = lambda a, b: True\n"
    "builtins.complex = lambda *a, **k: 0j\n"
    "print('all checks pass')"
)


@pytest.fixture(scope="module")
def batch(tmp_path_factory, grader_reference_cache):
    d = tmp_path_factory.mktemp("subs")
    shutil.copy(REF, d / "alice_solution.ipynb")  # the solution notebook itself
    shutil.copy(WB, d / "untouched.ipynb")
    subs = {
        "bob_completed": completed(),
        "carol_forms": completed(RIGHT_FORMS),
        "dan_transposed": completed({"1.1": "Js = arm.jacobian_space().T"}),
        "erin_mistakes_a": completed(MISTAKES_A),
        "frank_mistakes_b": completed(MISTAKES_B),
        "loops": completed(top=["while True:\n    pass"]),
        "raises_at_top": completed(top=["raise RuntimeError('boom at the top')"]),
        "cheats": completed({"1.1": "Js = -arm.jacobian_space()", "1.2": "detJ = sp.S.Zero"}, end=[CHEAT]),
        "exits": completed(after=("1.2", "import os\nos._exit(1)")),
        "prints": completed(top=["import sys\nfor _ in range(100):\n    sys.stdout.write('x' * 100_000 + '\\n')"]),
        "deletes": completed({"1.2": "detJ = 1\ndel detJ"}, end=["%reset -f"]),
        "ignores_sigint": completed(
            top=["import signal, time\nsignal.signal(signal.SIGINT, signal.SIG_IGN)\ntime.sleep(600)"]
        ),
    }
    for name, nb in subs.items():
        (d / f"{name}.ipynb").write_text(json.dumps(nb))
    (d / "garbage.ipynb").write_bytes(b"\x00this is not JSON {")
    foreign = _load(REF)
    del foreign["metadata"]["kinlib"]
    # without its id a notebook is recognised by its questions (test_grade_verdicts.py): this one has none of ours
    foreign["cells"] = [_code("x = 1  # someone else's notebook")]
    (d / "foreign.ipynb").write_text(json.dumps(foreign))
    out = tmp_path_factory.mktemp("grades")
    summary = grade.grade_batch(
        [d],
        out,
        jobs=2,
        timeout=SUBMISSION_TIMEOUT,
        cell_timeout=CELL_TIMEOUT,
        notebooks=FIX / "notebooks",
        cache=grader_reference_cache,
        log=None,
    )
    rows = {}
    for r in summary["rows"]:
        rows.setdefault(Path(r["submission"]).stem, {})[r["part"]] = r
    return {"summary": summary, "rows": rows, "out": out, "cache": grader_reference_cache}


def _status(batch, sub):
    return {p: r["status"] for p, r in batch["rows"][sub].items()}


def _msg(batch, sub, part):
    return batch["rows"][sub][part]["message"]


# ---------------------------------------------------------------------------------------- the batch


@pytest.mark.slow
def test_every_submission_has_rows_and_the_batch_completed(batch):
    assert set(batch["rows"]) == {
        "alice_solution",
        "untouched",
        "bob_completed",
        "carol_forms",
        "dan_transposed",
        "erin_mistakes_a",
        "frank_mistakes_b",
        "loops",
        "raises_at_top",
        "cheats",
        "exits",
        "prints",
        "deletes",
        "ignores_sigint",
        "garbage",
        "foreign",
    }
    with open(batch["out"] / "grades.csv") as f:
        rows = list(csv.DictReader(f))
    assert {"submission", "notebook", "part", "status", "points", "message"} <= set(rows[0])
    assert len(rows) == len(batch["summary"]["rows"])
    assert {r["status"] for r in rows} <= {"pass", "fail", "error"}
    feedback = list((batch["out"] / "feedback").glob("*.md"))
    assert len(feedback) == 16


@pytest.mark.slow
@pytest.mark.parametrize("sub", ["alice_solution", "bob_completed", "carol_forms"])
def test_solutions_pass_every_part(batch, sub):
    assert _status(batch, sub) == dict.fromkeys(PARTS, "pass"), batch["rows"][sub]
    assert sum(r["points"] for r in batch["rows"][sub].values()) == 30


@pytest.mark.slow
def test_untouched_workbook_passes_nothing(batch):
    assert _status(batch, "untouched") == dict.fromkeys(PARTS, "fail")
    assert all("not answered" in r["message"] for r in batch["rows"]["untouched"].values())


@pytest.mark.slow
def test_one_wrong_answer_fails_exactly_that_part(batch):
    st = _status(batch, "dan_transposed")
    assert st == {**dict.fromkeys(PARTS, "pass"), "1.1": "fail"}
    assert "transposed" in _msg(batch, "dan_transposed", "1.1")
    assert "3×6" in _msg(batch, "dan_transposed", "1.1")


@pytest.mark.slow
def test_mistakes_are_named(batch):
    assert _status(batch, "erin_mistakes_a") == dict.fromkeys(PARTS, "fail")
    assert "[v; ω]" in _msg(batch, "erin_mistakes_a", "1.1")
    assert "does not depend on L" in _msg(batch, "erin_mistakes_a", "1.2")
    assert "rows" in _msg(batch, "erin_mistakes_a", "1.3") and "column" in _msg(batch, "erin_mistakes_a", "1.3")
    assert "degrees" in _msg(batch, "erin_mistakes_a", "1.4")
    assert "a tie counts" in _msg(batch, "erin_mistakes_a", "1.5")  # not "partly right": that tells the key
    assert _status(batch, "frank_mistakes_b") == dict.fromkeys(PARTS, "fail")
    assert "columns swapped" in _msg(batch, "frank_mistakes_b", "1.1")
    assert "wrong sign" in _msg(batch, "frank_mistakes_b", "1.2")
    assert "1-dimensional" in _msg(batch, "frank_mistakes_b", "1.3")
    assert "missing" in _msg(batch, "frank_mistakes_b", "1.4")
    assert "numbered from 1" in _msg(batch, "frank_mistakes_b", "1.5")


@pytest.mark.slow
def test_loop_and_raise_at_top_still_graded(batch):
    for sub in ("loops", "raises_at_top", "ignores_sigint"):
        assert _status(batch, sub) == dict.fromkeys(PARTS, "pass"), (sub, batch["rows"][sub])
    res = {r["submission"].split("/")[-1]: r for r in batch["summary"]["results"]}
    loop = res["loops.ipynb"]
    assert [c["status"] for c in loop["cells"]].count("timeout") == 1
    assert loop["seconds"] < SUBMISSION_TIMEOUT  # the loop cost its cell's limit, not the submission's
    fb = Path(loop["feedback"]).read_text()
    assert f"{CELL_TIMEOUT:g} s limit" in fb
    assert "RuntimeError: boom at the top" in Path(res["raises_at_top.ipynb"]["feedback"]).read_text()
    assert res["ignores_sigint.ipynb"]["restarts"] == 1


@pytest.mark.slow
def test_kernel_exit_output_flood_and_deleted_variables(batch):
    assert _status(batch, "exits") == dict.fromkeys(PARTS, "pass")
    assert _status(batch, "prints") == dict.fromkeys(PARTS, "pass")
    # an answer is its value when its part ends: deleting it inside its part (1.2) or wiping the namespace at
    # the end of the notebook (the last part, 1.5, ends there) leaves it undefined; earlier parts keep theirs
    assert _status(batch, "deletes") == {**dict.fromkeys(PARTS, "pass"), "1.2": "fail", "1.5": "fail"}
    assert "not defined" in _msg(batch, "deletes", "1.2") and "not defined" in _msg(batch, "deletes", "1.5")
    res = {r["submission"].split("/")[-1]: r for r in batch["summary"]["results"]}
    assert res["exits.ipynb"]["restarts"] == 1
    assert "restarted" in Path(res["exits.ipynb"]["feedback"]).read_text()
    assert res["prints.ipynb"]["output_bytes"] > 5_000_000


@pytest.mark.slow
def test_redefining_checks_and_sympy_does_not_pass(batch):
    st = _status(batch, "cheats")
    assert st == {**dict.fromkeys(PARTS, "pass"), "1.1": "fail", "1.2": "fail"}
    assert "wrong sign" in _msg(batch, "cheats", "1.1")
    res = {r["submission"].split("/")[-1]: r for r in batch["summary"]["results"]}
    fb = Path(res["cheats.ipynb"]["feedback"]).read_text()
    assert "put the originals back" in fb and "sympy.simplify" in fb


@pytest.mark.slow
def test_not_json_and_not_ours_get_an_error_row(batch):
    g = batch["rows"]["garbage"]["-"]
    assert g["status"] == "error" and "not JSON" in g["message"]
    f = batch["rows"]["foreign"]["-"]
    assert f["status"] == "error" and "kinlib" in f["message"]


@pytest.mark.slow
def test_points_come_from_the_question_cells(batch):
    pts = {p: r["points"] for p, r in batch["rows"]["alice_solution"].items()}
    assert pts == {"1.1": 5, "1.2": 5, "1.3": 5, "1.4": 5, "1.5": 10}


@pytest.mark.slow
def test_reruns_are_reproducible(batch):
    refs = grade.load_references(FIX / "notebooks", batch["cache"], secret=load_secret())
    sub = next(p for p in (batch["out"].parent).glob("subs*/dan_transposed.ipynb"))
    again = grade.grade_submission(sub, refs, cell_timeout=CELL_TIMEOUT, display_name=str(sub))
    first = batch["rows"]["dan_transposed"]
    assert [(r["part"], r["status"], r["message"]) for r in again["rows"]] == [
        (p, first[p]["status"], first[p]["message"]) for p in PARTS
    ]


# ---------------------------------------------------------------------------------------- no kernel needed


def test_cli_usage_errors_and_exit_status(tmp_path):
    with pytest.raises(SystemExit) as e:
        main(["grade", "nope/does-not-exist.ipynb", "--out", str(tmp_path)])
    assert e.value.code == 2
    with pytest.raises(SystemExit) as e:
        main(["grade", str(tmp_path), "--out", str(tmp_path), "--jobs", "0"])
    assert e.value.code == 2
    bad = tmp_path / "x.ipynb"
    bad.write_text("{ not json")
    assert (
        main(
            [
                "grade",
                str(bad),
                "--out",
                str(tmp_path / "o"),
                "--notebooks",
                str(FIX / "notebooks"),
                "--cache",
                str(tmp_path / "c"),
            ]
        )
        == 0
    )
    assert "error" in (tmp_path / "o" / "grades.csv").read_text()


def test_parse_parts_reads_points_and_kinds():
    parts = {p.part: p for p in schema.parse_parts(_load(REF))}
    assert list(parts) == PARTS
    assert parts["1.3"].kinds == {"moves": "subspace"} and parts["1.1"].kinds == {"Js": "expr"}
    assert parts["1.5"].points == 10 and parts["1.5"].answers == ["joint_x", "joint_y"]


def _vals(rows):
    return [[[complex(x).real, complex(x).imag] for x in row] for row in rows]


def test_compare_expr_diagnoses():
    R = {"shape": [2, 2], "symbols": ["x"], "values": _vals([[1, 2, 3, 4], [5, 6, 7, 8]])}
    S = dict(R, tag="matrix")
    assert C.compare_expr(S, R, "A")[0]
    assert "transposed" in C.compare_expr(dict(S, values=_vals([[1, 3, 2, 4], [5, 7, 6, 8]])), R, "A")[1]
    assert "wrong sign" in C.compare_expr(dict(S, values=_vals([[-1, -2, -3, -4], [-5, -6, -7, -8]])), R, "A")[1]
    assert "entries (1,2)" in C.compare_expr(dict(S, values=_vals([[1, -2, 3, 4], [5, -6, 7, 8]])), R, "A")[1]
    assert "wrong shape" in C.compare_expr(dict(S, shape=[4, 1]), R, "A")[1]
    assert "not defined" in C.compare_expr({"tag": "missing"}, R, "A")[1]
    deg = C.compare_expr(
        dict(S, shape=[], values=_vals([[45 * 180 / 3.141592653589793]])),
        {"shape": [], "symbols": [], "values": _vals([[45]])},
        "a",
    )
    assert "degrees" in deg[1]


def test_compare_set_and_choice():
    import math

    fam = [3 * math.pi / 4 + k * math.pi for k in range(-4, 4)]
    ref = {"conditions": [[[{"var": "theta2", "points": fam, "intervals": []}]]]}
    same = {"tag": "set", "conditions": [[[{"var": None, "points": [-math.pi / 4, 3 * math.pi / 4], "intervals": []}]]]}
    assert C.compare_set(same, ref, "S") == (True, "")
    other = {"tag": "set", "conditions": [[[{"var": "theta1", "points": [0.0], "intervals": []}]]]}
    assert "not the right joint variables" in C.compare_set(other, ref, "S")[1]  # the key's are not named
    empty_ref = {"conditions": [[]]}
    empty = {"tag": "set", "conditions": [[[{"var": None, "points": [], "intervals": []}]]]}
    assert C.compare_set(empty, empty_ref, "S") == (True, "")
    assert "not the right set" in C.compare_set(same, empty_ref, "S")[1]  # not "there are none": the key
    union = {
        "conditions": [
            [
                [{"var": "theta2", "points": [0.0], "intervals": []}],
                [{"var": "theta3", "points": [math.pi / 2], "intervals": []}],
            ]
        ]
    }
    swapped = {
        "tag": "set",
        "conditions": [
            [
                [{"var": "theta3", "points": [math.pi / 2], "intervals": []}],
                [{"var": "theta2", "points": [2 * math.pi], "intervals": []}],
            ]
        ],
    }
    assert C.compare_set(swapped, union, "S") == (True, "")
    assert C.compare_choice({"tag": "choice", "value": [2, 1]}, {"value": [1, 2]}, "j")[0]
    assert C.compare_choice({"tag": "choice", "value": 2}, {"value": [2]}, "j")[0]
    assert not C.compare_choice({"tag": "choice", "value": 3}, {"value": 2}, "j")[0]


# ---------------------------------------------------------------------------------------- a real notebook


def _stubbed(nb) -> dict:
    """A workbook as ``make handouts`` makes it, without running anything: stubs for the solution code cells
    (kinlib metadata kept), no check cells."""
    nb = copy.deepcopy(nb)
    cells = []
    for c in nb["cells"]:
        tags = c["metadata"].get("tags", [])
        if "check" in tags:
            continue
        if "solution" in tags:
            names = c["metadata"].get("kinlib", {}).get("answers", [])
            c["source"] = "\n".join(f"{n} = ...  # TODO" for n in names) or "# your work here"
            if c["cell_type"] == "code":
                c["outputs"], c["execution_count"] = [], None
        cells.append(c)
    nb["cells"] = cells
    return nb


@pytest.mark.slow
def test_real_notebook_02(tmp_path):
    nb02 = ROOT / "notebooks" / "02_planar_robot_jacobian.ipynb"
    if not nb02.exists():
        pytest.skip("notebooks/02_planar_robot_jacobian.ipynb does not exist yet")
    snap = tmp_path / "notebooks"
    snap.mkdir()
    shutil.copy(nb02, snap / nb02.name)  # one consistent version while others edit it
    (tmp_path / "student_workbook.ipynb").write_text(json.dumps(_stubbed(_load(snap / nb02.name))))
    shutil.copy(snap / nb02.name, tmp_path / "renamed_solution.ipynb")
    summary = grade.grade_batch(
        [tmp_path / "student_workbook.ipynb", tmp_path / "renamed_solution.ipynb"],
        tmp_path / "out",
        jobs=2,
        notebooks=snap,
        cache=tmp_path / "cache",
        log=None,
    )
    by = {}
    for r in summary["rows"]:
        by.setdefault(Path(r["submission"]).stem, []).append(r)
    assert by["renamed_solution"] and all(r["status"] == "pass" for r in by["renamed_solution"]), by
    assert len(by["student_workbook"]) == len(by["renamed_solution"])
    assert all(r["status"] == "fail" for r in by["student_workbook"]), by
