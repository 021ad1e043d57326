"""The course workflow around the grader: points per answer, manual rows, overrides, student ids, class files.

The logic is tested on result dicts directly (no kernel), against hand-computed points; one end-to-end run
grades the tiny ``91_workflow`` fixture (tests/workflow_fixture.py) in real kernels, then re-grades one
student and checks that every other row of the class files is byte for byte unchanged.
"""

from __future__ import annotations

import copy
import csv
import json
from fractions import Fraction
from pathlib import Path

import pytest

import workflow_fixture as wf
from kinlib.course import schema
from kinlib.course.cli import main
from kinlib.course.grader import credit, intake, report

ROOT = Path(__file__).resolve().parents[2]
NOTEBOOKS = sorted((ROOT / "notebooks").glob("[0-9][0-9]_*.ipynb"))


def _parts(nb) -> dict:
    from dataclasses import asdict

    return {p.part: asdict(p) for p in schema.parse_parts(nb)}


def _row(part, status, answers=None, **kw):
    r = {
        "submission": "s.ipynb",
        "notebook": "nb",
        "part": part,
        "status": status,
        "points": 0.0,
        "max_points": 0.0,
        "message": "",
    }
    if answers is not None:
        r["answers"] = [{"answer": n, "status": s, "message": ""} for n, s in answers.items()]
    return r | kw


# ----------------------------------------------------------------------------------------- points per answer


def test_schema_reads_answer_points_and_manual_items():
    parts = _parts(wf.solution())
    assert list(parts) == ["1.1", "1.2", "1.3"]
    assert parts["1.1"]["answer_points"] == {"a": 3.0} and parts["1.1"]["manual"] == {}
    assert parts["1.2"]["answers"] == [] and parts["1.2"]["manual"] == {"drawing": 4.0}  # a part without answers
    assert parts["1.3"]["manual"] == {"explanation": 2.0} and parts["1.3"]["points"] == 5.0
    bad = wf.solution()
    bad["cells"][3]["metadata"]["kinlib"]["answer_points"] = {"a": "3", "b": True, "c": float("nan")}
    assert _parts(bad)["1.1"]["answer_points"] == {}  # not numbers: ignored (even split)


def test_partial_credit_is_the_sum_of_the_passing_answers_points():
    parts = _parts(wf.solution())
    amax = credit.answer_max(parts["1.1"])
    assert amax == {"a": 3, "b": Fraction(3, 2), "c": Fraction(3, 2)}  # declared 3, the other 3 split evenly
    assert credit.answer_max(parts["1.3"]) == {"d": 3}  # 5 - 2 for the explanation
    for verdicts, expected in [
        ({"a": "pass", "b": "pass", "c": "pass"}, 6.0),
        ({"a": "fail", "b": "pass", "c": "pass"}, 3.0),
        ({"a": "pass", "b": "fail", "c": "error"}, 3.0),
        ({"a": "fail", "b": "pass", "c": "fail"}, 1.5),
        ({"a": "fail", "b": "fail", "c": "fail"}, 0.0),
    ]:
        res = {"submission": "s.ipynb", "notebook": wf.NB_ID, "rows": [_row("1.1", "fail", verdicts)]}
        credit.score_parts(res, list(parts.values()))
        r = res["rows"][0]
        assert (r["points"], r["max_points"], r["kind"]) == (expected, 6.0, "auto"), verdicts
        assert sum(a["points"] for a in r["answers"]) == expected


def test_undeclared_points_split_evenly_and_exactly():
    # 4.1 of the problem set: 10 points over 6 answers, nothing declared -> 10/6 each, exactly
    p = {"part": "4.1", "points": 10.0, "answers": ["J", "Jp", "contributions", "joint_a", "joint_b", "joint_c"]}
    amax = credit.answer_max(p)
    assert set(amax.values()) == {Fraction(10, 6)} and sum(amax.values()) == 10
    res = {
        "submission": "s",
        "notebook": "04",
        "rows": [
            _row("4.1", "fail", dict.fromkeys(p["answers"][:3], "pass") | dict.fromkeys(p["answers"][3:], "fail"))
        ],
    }
    assert credit.score_parts(res, [p])["rows"][0]["points"] == 5.0  # 3 × 10/6, not 4.99999


def test_a_part_judged_only_as_a_whole_keeps_all_or_nothing():
    p = {"part": "2.1", "points": 5.0, "answers": ["M", "S1"]}
    ok = credit.score_parts({"submission": "s", "rows": [_row("2.1", "pass")]}, [p])["rows"][0]
    bad = credit.score_parts({"submission": "s", "rows": [_row("2.1", "fail")]}, [p])["rows"][0]
    assert (ok["points"], bad["points"]) == (5.0, 0.0)


def test_score_parts_is_idempotent_and_keeps_error_rows():
    parts = list(_parts(wf.solution()).values())
    res = {
        "submission": "s",
        "notebook": wf.NB_ID,
        "rows": [_row("1.1", "pass", dict.fromkeys("abc", "pass")), _row("1.2", "pass"), _row("1.3", "fail")],
    }
    once = copy.deepcopy(credit.score_parts(res, parts))
    assert credit.score_parts(res, parts) == once
    assert [(r["part"], r.get("answer"), r["kind"], r["status"]) for r in once["rows"]] == [
        ("1.1", "", "auto", "pass"),
        ("1.2", "drawing", "manual", "pending"),  # the grader's spurious "pass" row of 1.2 is replaced
        ("1.3", "", "auto", "fail"),
        ("1.3", "explanation", "manual", "pending"),
    ]
    err = credit.score_parts({"submission": "g", "rows": [_row("-", "error")]}, parts)["rows"]
    assert [(r["part"], r["status"]) for r in err] == [("-", "error")]


@pytest.mark.parametrize("path", NOTEBOOKS, ids=lambda p: p.stem)
def test_the_notebooks_points_add_up(path):
    nb = json.loads(path.read_text())
    parts = _parts(nb)
    for p in parts.values():
        assert credit.check_part_points(p) == [], p
    # every "(N points)" question is graded: automatically, by hand, or both
    questions = [schema.points_in(schema.cell_source(c)) for c in nb["cells"] if "question" in schema.cell_tags(c)]
    assert sum(p["points"] for p in parts.values()) == sum(q for q in questions if q)


def test_section_5_totals_30_with_the_drawing_as_a_manual_row():
    # 5.1–5.5 (25 points) and 5.6, the unseen-robot exercise (5 points; issue 30)
    nb = json.loads((ROOT / "notebooks" / "05_singularities_planar.ipynb").read_text())
    parts = _parts(nb)
    assert parts["5.2"]["answers"] == [] and sum(parts["5.2"]["manual"].values()) == 5
    rows = [_row(p, "pass") for p in parts]
    res = credit.score_parts({"submission": "s", "notebook": "05", "rows": rows}, list(parts.values()))
    t = credit.result_totals(res["rows"])
    assert t["max_points"] == 30 and any(x.startswith("5.2/") for x in t["pending"])


# ----------------------------------------------------------------------------------------- student ids


@pytest.mark.parametrize(
    "relpath, pattern, expected",
    [
        ("ann_lee.ipynb", None, "ann_lee"),  # default: the path relative to the submissions root
        ("ann/ps4.ipynb", None, "ann/ps4"),
        ("ann/ps4.ipynb", r"([^/]+)/[^/]+$", "ann"),  # one folder per student
        ("leeann_LATE_12345_678_ps4-1.ipynb", r"[^/_]+_(?:LATE_|late_)?(?P<id>\d+)_\d+_[^/]*$", "12345"),
        ("leeann_12345_678_ps4.ipynb", r"[^/_]+_(?:LATE_|late_)?(?P<id>\d+)_\d+_[^/]*$", "12345"),
        ("readme.ipynb", r"(?P<id>\d{5})", "readme"),  # no match: named by its path, with a warning
        ("aaron/bob/02.ipynb", r"([^/]+)/[^/]+$", "aaron/bob/02"),  # a nested folder is never student bob
        ("王伟/ps4.ipynb", r"([^/]+)/[^/]+$", "王伟"),  # kept as written
        ("José/ps4.ipynb", r"([^/]+)/[^/]+$", "José"),
    ],
)
def test_student_id_from_the_path(relpath, pattern, expected):
    sid, warning = intake.student_id(relpath, pattern)
    assert sid == expected
    assert bool(warning) == (pattern is not None and expected == relpath[:-6]), warning


# ----------------------------------------------------------------------------------------- overrides


def _scored(sid, verdicts=None, nb=wf.NB_ID):
    parts = list(_parts(wf.solution()).values())
    verdicts = verdicts or dict.fromkeys("abc", "pass")
    rows = [_row("1.1", "fail", verdicts), _row("1.2", "pass"), _row("1.3", "pass", {"d": "pass"})]
    for r in rows:
        r["submission"] = f"{sid}.ipynb"
    res = {
        "submission": f"{sid}.ipynb",
        "path": f"/class/{sid}.ipynb",
        "notebook": nb,
        "title": "W",
        "rows": rows,
        "cells": [],
        "seconds": 1.0,
    }
    return credit.score_parts(res, parts)


def test_overrides_csv_and_toml_beat_the_automatic_score_and_show_comments(tmp_path):
    (tmp_path / "o.csv").write_text(
        "student_id,part,score,comment\n"
        "ann,1.2,3.5,two poses; one unlabelled\n"  # the part's only row: its manual item
        "ann,1.1/b,0,copied from the key\n"  # one answer of an automatic part
        "bob,1.3/explanation,,see office hours\n"  # a comment only
    )
    (tmp_path / "o.toml").write_text(
        '[[override]]\nstudent_id = "ann"\npart = "1.3/explanation"\nscore = 2\ncomment = "clear"\n'
    )
    ov = credit.load_overrides(tmp_path / "o.csv") + credit.load_overrides(tmp_path / "o.toml")
    res = [_scored("ann"), _scored("bob")]
    for r in res:
        r["student_id"] = r["submission"][:3]
    assert credit.apply_overrides(res, ov) == []
    ann = {(r["part"], r.get("answer")): r for r in res[0]["rows"]}
    assert (ann["1.2", "drawing"]["status"], ann["1.2", "drawing"]["points"]) == ("graded", 3.5)
    assert ann["1.1", ""]["points"] == 4.5 and ann["1.1", ""]["auto_points"] == 6.0  # 6 - b's 1.5
    assert ann["1.3", "explanation"]["points"] == 2.0
    t = credit.result_totals(res[0]["rows"])
    assert t == {"points": 4.5 + 3.5 + 3 + 2, "max_points": 15.0, "pending": []}
    bob = {(r["part"], r.get("answer")): r for r in res[1]["rows"]}
    assert bob["1.3", "explanation"]["status"] == "pending" and bob["1.3", "explanation"]["comment"]
    fb = report.feedback_markdown(res[0])
    assert "Instructor: copied from the key" in fb and "two poses; one unlabelled" in fb and "(override)" in fb
    assert "**Score: 13 / 15 points**" in fb
    fb_bob = report.feedback_markdown(res[1])
    assert "pending: 1.2/drawing, 1.3/explanation, 6 points graded by hand" in fb_bob


@pytest.mark.parametrize(
    "text, match",
    [
        ("student_id,part,score,comment\nann,1.2,9,too much\n", "above its 4 points"),
        ("student_id,part,score,comment\nann,1.3,1,\n", "several rows"),
        ("student_id,part,score,comment\nann,1.1/b,abc,\n", "must be a number"),
        ("student_id,part,score,comment\nann,1.1/b,-1,\n", "≥ 0"),
        ("student_id,part,score,comment\nann,1.1/b,,\n", "score, a comment or both"),
        ("name,score\nann,1\n", "header must name"),
    ],
)
def test_bad_overrides_are_refused_naming_the_line(tmp_path, text, match):
    f = tmp_path / "o.csv"
    f.write_text(text)
    with pytest.raises(ValueError, match=match):
        res = [_scored("ann") | {"student_id": "ann"}]
        credit.apply_overrides(res, credit.load_overrides(f))


def test_an_override_for_someone_else_is_a_warning():
    res = [_scored("ann") | {"student_id": "ann"}]
    w = credit.apply_overrides(
        res,
        [credit.Override("zed", "1.2", 1.0, source="o.csv:2"), credit.Override("ann", "9.9", 1.0, source="o.csv:3")],
    )
    assert w == [
        "zed 1.2 (o.csv:2): no such student in these results",
        "ann 9.9 (o.csv:3): no such part in their results",
    ]


# ----------------------------------------------------------------------------------------- class files


def _read(p):
    return list(csv.DictReader(open(p, newline="")))


def test_grades_csv_has_ids_max_points_totals_and_pending(tmp_path):
    other = _scored("ann", nb="92_other")
    other["rows"] = other["rows"][:1]
    report.write_outputs(tmp_path, [_scored("ann"), _scored("bob", {"a": "fail", "b": "pass", "c": "fail"}), other])
    rows = _read(tmp_path / "grades.csv")
    assert list(rows[0]) == report.COLUMNS
    ann = [r for r in rows if r["student_id"] == "ann"]
    assert {r["student_total"] for r in ann} == {f"{6 + 3 + 6:g}"}  # 1.1 + 1.3's d in two notebooks, 1.1 again
    assert {r["student_max"] for r in ann} == {f"{15 + 6:g}"}
    assert ann[0]["student_pending"] == "1.2/drawing 1.3/explanation"
    pending = [r for r in ann if r["status"] == "pending"]
    assert pending and all(r["points"] == "" and r["kind"] == "manual" for r in pending)
    bob = [r for r in rows if r["student_id"] == "bob" and r["part"] == "1.1"][0]
    assert (bob["points"], bob["max_points"], bob["status"]) == ("1.5", "6", "fail")
    totals = _read(tmp_path / "totals.csv")
    assert [(t["student_id"], t["points"], t["max_points"], t["status"]) for t in totals] == [
        ("ann", "15", "21", "pending"),
        ("bob", "4.5", "15", "pending"),
    ]


def test_regrading_one_student_leaves_every_other_row_byte_identical(tmp_path):
    report.write_outputs(tmp_path, [_scored(s) for s in ("ann", "bob", "cyd")])
    before = (tmp_path / "grades.csv").read_text().splitlines()
    fb_before = {p.name: p.read_bytes() for p in (tmp_path / "feedback").iterdir()}
    report.write_outputs(tmp_path, [_scored("bob", {"a": "fail", "b": "fail", "c": "pass"})])  # bob alone, again
    after = (tmp_path / "grades.csv").read_text().splitlines()
    assert len(after) == len(before)
    changed = [i for i, (a, b) in enumerate(zip(before, after)) if a != b]
    assert changed and all(after[i].startswith("bob,") for i in changed)
    assert [b for b in before if not b.startswith("bob,")] == [a for a in after if not a.startswith("bob,")]
    fb_after = {p.name: p.read_bytes() for p in (tmp_path / "feedback").iterdir()}
    assert {k for k in fb_after if fb_after[k] != fb_before.get(k)} == {f"bob--{wf.NB_ID}.md"}
    assert not list(tmp_path.rglob(".*.*"))  # no temporary files left behind
    # --fresh (merge=False) forgets the others
    report.write_outputs(tmp_path, [_scored("bob")], merge=False)
    assert {r["student_id"] for r in _read(tmp_path / "grades.csv")} == {"bob"}


def test_the_id_pattern_is_remembered_and_a_new_one_rekeys_everyone(tmp_path):
    def sub(folder, verdicts=None):
        res = _scored("x", verdicts)
        res["path"], res["relpath"] = f"/class/{folder}/ps.ipynb", f"{folder}/ps.ipynb"
        return res

    report.write_outputs(tmp_path, [sub("ann"), sub("bob")], id_pattern=r"([^/]+)/[^/]+$")
    report.write_outputs(tmp_path, [sub("bob", {"a": "fail", "b": "pass", "c": "pass"})])  # no pattern given
    rows = _read(tmp_path / "grades.csv")
    assert sorted({r["student_id"] for r in rows}) == ["ann", "bob"]
    assert {r["points"] for r in rows if r["student_id"] == "bob" and r["part"] == "1.1"} == {"3"}
    report.write_outputs(tmp_path, [], id_pattern=r"[^/]+/(?P<id>[^/]+)\.ipynb$")  # every file is ps.ipynb
    assert {r["student_id"] for r in _read(tmp_path / "grades.csv")} == {"ps", "ps-2"}  # re-keyed, none lost
    assert sorted(p.name for p in (tmp_path / "results").iterdir()) == [
        f"ps--{wf.NB_ID}.json",
        f"ps-2--{wf.NB_ID}.json",
    ]
    assert sorted(p.name for p in (tmp_path / "feedback").iterdir()) == [f"ps--{wf.NB_ID}.md", f"ps-2--{wf.NB_ID}.md"]


def test_two_files_with_one_student_id_are_both_kept_and_named(tmp_path):
    a, b = _scored("x"), _scored("x", {"a": "fail", "b": "fail", "c": "fail"})
    a["path"], b["path"] = "/class/ann/hw.ipynb", "/class/bob/hw.ipynb"  # default id: the stem, "hw" twice
    w = report.write_outputs(tmp_path, [b, a])
    assert len(w) == 1 and "same student id 'hw'" in w[0] and "--id-pattern" in w[0]
    ids = {r["student_id"]: r["student_total"] for r in _read(tmp_path / "grades.csv")}
    assert ids == {"hw": "9", "hw-2": "3"}  # ann (first by path) keeps "hw"; nothing lost
    report.write_outputs(tmp_path, [])  # a later run keys the kept results the same way
    assert {r["student_id"]: r["student_total"] for r in _read(tmp_path / "grades.csv")} == ids


def test_overrides_in_the_class_folder_apply_without_regrading(tmp_path):
    report.write_outputs(tmp_path, [_scored("ann"), _scored("bob")])
    (tmp_path / "overrides.csv").write_text("student_id,part,score,comment\nann,1.2/drawing,4,\n")
    assert main(["grade", "--out", str(tmp_path)]) == 0  # no submissions: only the class files are rewritten
    ann = [r for r in _read(tmp_path / "grades.csv") if r["student_id"] == "ann"]
    assert {r["student_total"] for r in ann} == {"13"}
    kept = json.loads((tmp_path / "results" / f"ann--{wf.NB_ID}.json").read_text())
    assert all(not r.get("override") for r in kept["rows"])  # the kept results stay automatic


def test_atomic_write_keeps_the_old_file_when_writing_fails(tmp_path, monkeypatch):
    f = tmp_path / "grades.csv"
    f.write_text("old\n")

    def boom(*a):
        raise OSError("disk full")

    monkeypatch.setattr("kinlib.course.grader.report.os.replace", boom)
    with pytest.raises(OSError):
        report.atomic_write(f, "new\n")
    assert f.read_text() == "old\n" and [p.name for p in tmp_path.iterdir()] == ["grades.csv"]


# ----------------------------------------------------------------------------------------- end to end


@pytest.mark.slow
def test_end_to_end_partial_manual_override_and_single_regrade(tmp_path):
    from kinlib.course.grader import grade

    nbs = tmp_path / "notebooks"
    wf.write_solution(nbs)
    subs = tmp_path / "subs"
    wf.write_submission(subs / "ann" / "w.ipynb")
    wf.write_submission(subs / "bob" / "w.ipynb", {"1.1": "a = th1**3\nb = sp.sin(th1)\nc = sp.Matrix([1, 2])"})
    out = tmp_path / "grades"
    kw = dict(
        jobs=2,
        timeout=120,
        cell_timeout=30,
        notebooks=nbs,
        cache=tmp_path / "cache",
        log=None,
        secret=tmp_path / "secret",
        id_pattern=r"([^/]+)/[^/]+$",
    )
    s = grade.grade_batch([subs], out, **kw)
    rows = {(r["student_id"], r["part"], r["answer"]): r for r in _read(out / "grades.csv")}
    assert {k[0] for k in rows} == {"ann", "bob"}
    assert rows["ann", "1.1", ""]["points"] == "6" and rows["bob", "1.1", ""]["points"] == "1.5"  # b only
    assert rows["ann", "1.2", "drawing"]["status"] == "pending" and rows["ann", "1.2", "drawing"]["points"] == ""
    assert rows["ann", "1.1", ""]["student_total"] == "9" and rows["ann", "1.1", ""]["student_max"] == "15"
    res = {r["student_id"]: r for r in s["results"]}
    fb = Path(res["bob"]["feedback"]).read_text()
    assert "## Points per answer" in fb and "| 1.1 | `b` | 1.5 / 1.5 | pass |" in fb
    # bob fixes his answers and is graded again, alone; an override arrives for ann
    before = [ln for ln in (out / "grades.csv").read_text().splitlines() if ln.startswith("ann,")]
    wf.write_submission(subs / "bob" / "w.ipynb")
    grade.grade_batch([subs / "bob" / "w.ipynb"], out, **kw)
    after = (out / "grades.csv").read_text().splitlines()
    assert [ln for ln in after if ln.startswith("ann,")] == before
    assert {r["points"] for r in _read(out / "grades.csv") if r["student_id"] == "bob" and r["part"] == "1.1"} == {"6"}
    (out / "overrides.toml").write_text('[[override]]\nstudent_id = "ann"\npart = "1.2"\nscore = 4\ncomment = "ok"\n')
    assert main(["grade", "--out", str(out)]) == 0
    ann = {(r["part"], r["answer"]): r for r in _read(out / "grades.csv") if r["student_id"] == "ann"}
    assert ann["1.2", "drawing"]["status"] == "graded" and ann["1.1", ""]["student_total"] == "13"
    assert ann["1.1", ""]["student_pending"] == "1.3/explanation"
