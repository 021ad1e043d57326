"""``kinlib grade --variants KEY`` (issue 33, item 4): each submission judged against its student's own variant.

A small solution notebook whose numbers vary (``k``: its variant cell) and a key built by hand (the lead's
:mod:`kinlib.course.variants.key` format: each variant's reference answers computed here by SymPy, independently of
the grader, and dumped as the reference kernel would, :func:`kinlib.course.answers.describe.dump_reference`). The
student id is the submission's folder (``--id-pattern``), never the notebook: one submission plants another
student's variant in its metadata and its variant cell, and is graded as its folder says.

One batch (a kernel per submission, two at a time) is graded once; the tests read its rows and feedback.
"""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from kinlib.course.cli import main
from kinlib.course.grader import grade
from kinlib.course.grader.judging import OTHER_VARIANT
from kinlib.course.grader.secret import load_secret
from variants_fixture import FLAG, NID, make_key, notebook


@pytest.fixture(scope="module")
def graded(tmp_path_factory, grader_reference_cache):
    secret = load_secret(None)  # the run's secret (conftest): the key is signed with the grader's secret
    base = tmp_path_factory.mktemp("variants")
    nbs = base / "notebooks"
    nbs.mkdir()
    (nbs / f"{NID}.ipynb").write_text(json.dumps(notebook()))
    key = make_key(secret, base / "key" / "variants-key.json")
    subs = base / "subs"
    bob_planted = notebook(3, r="r = 5 * x**2 + 1", s="s = sp.Matrix([[x, 5], [0, 5 * x]])", values={"k": "3"})
    files = {
        "ada": notebook(3),  # ada's own, right
        "bob": bob_planted,  # right for bob (k=5), with ada's k in its variant cell and metadata
        "cyd": notebook(3),  # ada's right workbook handed in as cyd's (cyd has k=7)
        "dan": notebook(5),  # not on the roster
        "eve": notebook(5, r="r = None  # your answer", s="s = None  # your answer"),  # untouched
        "fay": notebook(2),  # the original's numbers (the solution pages'): fay is not on the roster either
    }
    for sid, nb in files.items():
        (subs / sid).mkdir(parents=True)
        (subs / sid / "ps.ipynb").write_text(json.dumps(nb))
    out = base / "grades"
    summary = grade.grade_batch(
        [subs],
        out,
        jobs=2,
        timeout=240,
        cell_timeout=60,
        notebooks=nbs,
        cache=grader_reference_cache,
        log=None,
        id_pattern=r"(?P<id>[^/]+)/",
        variants=key,
    )
    rows = {}
    for res in summary["results"]:
        rows[res["student_id"]] = {r["part"]: r for r in res["rows"]}
    return {
        "summary": summary,
        "rows": rows,
        "out": out,
        "key": key,
        "subs": subs,
        "nbs": nbs,
        "cache": grader_reference_cache,
    }


def _points(graded, sid):
    return sum(r["points"] for r in graded["rows"][sid].values())


def test_each_students_own_workbook_gets_full_marks(graded):
    for sid in ("ada", "bob"):
        rows = graded["rows"][sid]
        assert {p: r["status"] for p, r in rows.items()} == {"1.1": "pass", "1.2": "pass"}, rows
        assert _points(graded, sid) == 10
        assert FLAG not in json.dumps(rows)


def test_another_students_workbook_scores_zero_and_is_flagged(graded):
    rows = graded["rows"]["cyd"]
    assert _points(graded, "cyd") == 0
    for part in ("1.1", "1.2"):
        assert rows[part]["status"] == "fail"
        assert FLAG in rows[part]["message"], rows[part]
        assert "3" not in rows[part]["message"] and "7" not in rows[part]["message"]  # no variant's number, no id
    fb = Path(
        graded["summary"]["results"][[r["student_id"] for r in graded["summary"]["results"]].index("cyd")]["feedback"]
    )
    assert FLAG in fb.read_text()
    assert OTHER_VARIANT == FLAG


def test_nobody_off_the_roster_is_graded_against_the_original(graded):
    """fay is not on the roster and hands in the original's numbers: not graded (never against the original key)."""
    rows = graded["rows"]["fay"]
    assert _points(graded, "fay") == 0
    assert all("not on the roster" in r["message"] and r["status"] == "error" for r in rows.values()), rows


def test_student_not_on_roster_is_not_graded_with_a_reason(graded):
    rows = graded["rows"]["dan"]
    assert set(rows) == {"1.1", "1.2"}
    for r in rows.values():
        assert r["status"] == "error" and r["points"] == 0
        assert "'dan' is not on the roster of the variants key" in r["message"]
        assert FLAG not in r["message"]
    assert not graded["summary"]["infrastructure_errors"]


def test_untouched_workbook_scores_zero_without_the_flag(graded):
    rows = graded["rows"]["eve"]
    assert _points(graded, "eve") == 0
    assert all(r["status"] == "fail" and FLAG not in r["message"] for r in rows.values()), rows


def test_the_grade_follows_the_identity_not_the_notebook(graded):
    """bob's workbook says k = 3 (ada's) in its variant cell and metadata; judged as bob (k = 5): full marks.
    The same file copied under ada's folder is ada's variant's wrong answer, and another variant's right one."""
    assert _points(graded, "bob") == 10
    res = next(r for r in graded["summary"]["results"] if r["student_id"] == "bob")
    assert res["variant"] == "v5"


def test_the_original_answers_for_a_student_are_flagged(tmp_path, graded):
    """The instructor's original numbers (k = 2, the solution pages') handed in by a student on the roster: zero,
    flagged; graded alone, in this process (one job: the other path than the batch's workers)."""
    subs = tmp_path / "subs"
    (subs / "ada").mkdir(parents=True)
    (subs / "ada" / "ps.ipynb").write_text(json.dumps(notebook(2)))
    summary = grade.grade_batch(
        [subs],
        tmp_path / "out",
        jobs=1,
        timeout=240,
        cell_timeout=60,
        notebooks=graded["nbs"],
        cache=graded["cache"],
        log=None,
        id_pattern=r"(?P<id>[^/]+)/",
        variants=graded["key"],
    )
    rows = {r["part"]: r for r in summary["rows"]}
    assert sum(r["points"] for r in rows.values()) == 0
    assert all(FLAG in r["message"] for r in rows.values()), rows


def test_a_key_that_does_not_verify_is_refused(tmp_path, graded, capsys):
    bad = tmp_path / "key.json"
    d = json.loads(graded["key"].read_text())
    d["key"]["notebooks"][NID]["students"]["cyd"] = "v3"  # cyd edits the key to get ada's variant
    bad.write_text(json.dumps(d))
    with pytest.raises(grade.VariantsKeyRefused, match="does not verify"):
        grade.grade_batch([graded["subs"]], tmp_path / "o", notebooks=graded["nbs"], log=None, variants=bad)
    other = make_key(b"another secret" * 3, tmp_path / "other.json")
    code = main(
        [
            "grade",
            str(graded["subs"]),
            "--out",
            str(tmp_path / "o2"),
            "--notebooks",
            str(graded["nbs"]),
            "--variants",
            str(other),
        ]
    )
    assert code == 2
    assert "does not verify with the grader secret" in capsys.readouterr().err
    assert not (tmp_path / "o2" / "grades.csv").exists()


def test_a_bundle_refuses_a_key_that_does_not_verify(tmp_path, capsys):
    """kinlib grade gradescope|prairielearn --variants: refused before any notebook runs (exit 2)."""
    nbs = tmp_path / "nbs"
    nbs.mkdir()
    (nbs / f"{NID}.ipynb").write_text(json.dumps(notebook()))
    other = make_key(b"another secret" * 3, tmp_path / "other.json")
    for platform, out in (("gradescope", "ag.zip"), ("prairielearn", "pl")):
        args = ["grade", platform, "--out", str(tmp_path / out), "--notebooks", str(nbs), "--variants", str(other)]
        assert main(args) == 2
        assert "does not verify with the grader secret" in capsys.readouterr().err
        assert not (tmp_path / out).exists() or not any((tmp_path / out).rglob("references.json"))


def test_the_platforms_student_id(tmp_path):
    """Gradescope: users[0]'s sid if on the roster, else its email; PrairieLearn (which names nobody): the
    kinlib_student_id element value, else a submitted file's name on the roster; else none, said so."""
    from kinlib.course.lms.bundles import platform_student

    meta = tmp_path / "submission_metadata.json"
    roster = {"S-1", "bo@x.edu", "ada"}
    meta.write_text(json.dumps({"users": [{"email": "bo@x.edu", "id": 9, "name": "Bo", "sid": "S-1"}, {"sid": "ada"}]}))
    assert platform_student("gradescope", tmp_path, roster)[0] == "S-1"
    meta.write_text(json.dumps({"users": [{"email": "bo@x.edu", "id": 9, "name": "Bo", "sid": "S-9"}]}))
    assert platform_student("gradescope", tmp_path, roster) == ("bo@x.edu", "Gradescope's submitter (email)")
    meta.write_text(json.dumps({"users": [{"email": "zz@x.edu", "sid": "S-9"}]}))
    assert platform_student("gradescope", tmp_path, roster)[0] == "S-9"  # not on the roster: refused later, by name
    meta.write_text("[1, 2")
    assert platform_student("gradescope", tmp_path, roster)[0] == ""
    (tmp_path / "data").mkdir()
    data = tmp_path / "data" / "data.json"
    data.write_text(json.dumps({"params": {"k": 3}, "submitted_answers": {"kinlib_student_id": " ada "}}))
    assert platform_student("prairielearn", tmp_path, roster, [Path("S-1.ipynb")])[0] == "ada"
    data.write_text(json.dumps({"params": {}, "submitted_answers": {}}))
    assert platform_student("prairielearn", tmp_path, roster, [Path("x/S-1.ipynb")])[0] == "S-1"
    sid, why = platform_student("prairielearn", tmp_path, roster, [Path("workbook.ipynb")])
    assert sid == "" and "no student id" in why


def test_no_student_id_is_refused_with_a_reason():
    import tempfile

    import variants_fixture as vf
    from kinlib.course.grader.refdata import Reference
    from kinlib.course.variants.key import read_key

    with tempfile.TemporaryDirectory() as d:
        key = read_key(make_key(b"s" * 32, Path(d) / "k.json"), b"s" * 32)
    ref = Reference(NID, "t", "p", "0" * 64, [], vf.answers_for(2))
    assert "no student id" in grade.variant_plan(ref, key, "")["refused"]
    plan = grade.variant_plan(ref, key, "ada")
    assert plan["variant"] == "v3" and set(plan["others"]) == {"r", "s"}
    assert len(plan["others"]["r"]) == 3  # the original (k=2) and the other variants (5, 7), not ada's own


@pytest.mark.slow
def test_notebook_04_graded_against_each_students_own_key(tmp_path, grader_reference_cache):
    """The real 04 with its declared variants, its key built by the variants build (draw, replay, proof): two
    students with different variants each get full marks for their own solution notebook (the instructor's with
    their numbers, spec.apply); the first's handed in as the second's: every answer that differs between their
    variants scores zero and is flagged; the others (the same for every variant) still pass."""
    import shutil

    from kinlib.course.variants import key as K
    from kinlib.course.variants import spec as S

    src = sorted((Path(__file__).resolve().parents[2] / "notebooks").glob("04_*.ipynb"))
    if not src or S.Spec.from_notebook(json.loads(src[0].read_text())) is None:
        pytest.skip("notebook 04 declares no variants here")
    nbs = tmp_path / "notebooks"
    nbs.mkdir()
    shutil.copy(src[0], nbs / src[0].name)
    nb = json.loads(src[0].read_text())
    spec = S.Spec.from_notebook(nb)
    secret = load_secret(None)
    roster = [K.Student(f"s{i}") for i in range(6)]
    key = K.build_key(nbs, roster, secret, log=lambda *a: None)
    nid = next(iter(key.notebooks))
    nk = key.notebooks[nid]
    by_variant = {}
    for sid, vk in nk.students.items():
        by_variant.setdefault(vk, sid)
    assert len(by_variant) >= 2, "six students drew one variant"
    (va, a), (vb, b) = sorted(by_variant.items())[:2]
    keyfile = K.write_key(tmp_path / "key.json", key, secret)
    subs = tmp_path / "subs"
    files = {f"{a}/own": (a, va), f"{b}/own": (b, vb), f"{b}/copy": (a, va)}
    for rel, (_, vk) in files.items():
        (subs / rel).parent.mkdir(parents=True, exist_ok=True)
        (subs / f"{rel}.ipynb").write_text(json.dumps(S.apply(nb, spec, nk.variants[vk].values)))
    summary = grade.grade_batch(
        [subs],
        tmp_path / "out",
        jobs=2,
        timeout=600,
        cell_timeout=300,
        notebooks=nbs,
        cache=grader_reference_cache,
        log=None,
        id_pattern=r"(?P<id>[^/]+)/",
        variants=keyfile,
    )
    res = {r["relpath"][: -len(".ipynb")]: r for r in summary["results"]}
    for rel in (f"{a}/own", f"{b}/own"):
        auto = [r for r in res[rel]["rows"] if r.get("kind") != "manual"]
        assert auto and all(r["status"] == "pass" for r in auto), [r for r in auto if r["status"] != "pass"]
    differ = {
        n
        for n, x in nk.variants[va].answers.items()
        if json.dumps(x, sort_keys=True) != json.dumps(nk.variants[vb].answers.get(n), sort_keys=True)
    }
    assert differ, "the two variants have the same answers"
    seen = {}
    for r in res[f"{b}/copy"]["rows"]:
        for v in r.get("answers") or []:
            seen[v["answer"]] = v
    assert differ <= set(seen)
    for n in differ:
        assert seen[n]["status"] == "fail" and FLAG in seen[n]["message"], seen[n]
    assert all(v["status"] == "pass" for n, v in seen.items() if n not in differ), seen
