"""Gradescope, PrairieLearn and Canvas outputs (kinlib.course.lms.bundles), checked against the platforms' documented fields.

The validators below are written from the platforms' documentation, not from kinlib's output:

* Gradescope, Autograder Specifications (https://gradescope-autograders.readthedocs.io/en/latest/specs/):
  ``results.json`` has ``score`` (required unless every test has one), optional ``execution_time``,
  ``output``, ``output_format``, ``visibility``, ``stdout_visibility``, ``extra_data``, ``tests``; a test
  has optional ``score``, ``max_score``, ``status`` (passed | failed), ``name``, ``number``, ``output``,
  ``tags``, ``visibility``, ``extra_data``; visibility is visible | hidden | after_due_date | after_published.
* PrairieLearn, External Grading (https://prairielearn.readthedocs.io/en/latest/externalGrading/):
  ``/grade/results/results.json``, at most 1 MB; ``gradable`` (bool, default true); when gradable, ``score``
  is required, a number in [0, 1]; when not, ``format_errors`` (a string or a list of strings); tests have
  ``name``, ``description``, ``points``, ``max_points``, ``message``, ``output`` (and ``images``).

The simulations run the real entry points (``run_autograder``, ``run.sh``) inside bubblewrap with a scratch
folder bound at ``/autograder`` or ``/grade``, the rest of the system read-only, a private ``/tmp``. The host's
``/proc`` is bound (not a new one) so that the grader's own sandbox can nest inside the simulated container
(bubblewrap cannot mount a fresh procfs inside another bubblewrap's PID namespace here); the PrairieLearn
simulation grades with the sandbox on, the Gradescope one with a ``--no-sandbox`` bundle.
"""

from __future__ import annotations

import json
import os
import shutil
import subprocess
import sys
import zipfile
from numbers import Real
from pathlib import Path

import pytest

import workflow_fixture as wf
from kinlib.course.grader import credit, report
from kinlib.course.lms import bundles as lms

GS_VIS = {"visible", "hidden", "after_due_date", "after_published"}
GS_TOP = {
    "score",
    "execution_time",
    "output",
    "output_format",
    "test_output_format",
    "test_name_format",
    "visibility",
    "stdout_visibility",
    "extra_data",
    "tests",
    "leaderboard",
}
GS_TEST = {
    "score",
    "max_score",
    "status",
    "name",
    "name_format",
    "number",
    "output",
    "output_format",
    "tags",
    "visibility",
    "extra_data",
}


def _num(x) -> bool:
    return isinstance(x, Real) and not isinstance(x, bool)


def validate_gradescope(d) -> list[str]:
    """Problems with a Gradescope results.json (empty when valid), plus our own requirements: every test
    has name, score, max_score, output and visibility, with 0 ≤ score ≤ max_score."""
    errs = []
    if not isinstance(d, dict):
        return ["results.json is not a JSON object"]
    errs += [f"unknown top-level key {k!r}" for k in d if k not in GS_TOP]
    tests = d.get("tests", [])
    if not isinstance(tests, list):
        return errs + ["tests is not a list"]
    if "score" not in d and not (tests and all("score" in t for t in tests if isinstance(t, dict))):
        errs.append("score is required unless every test has one")
    if "score" in d and not _num(d["score"]):
        errs.append("score is not a number")
    if "execution_time" in d and not _num(d["execution_time"]):
        errs.append("execution_time is not a number")
    for k in ("output",):
        if k in d and not isinstance(d[k], str):
            errs.append(f"{k} is not a string")
    for k in ("visibility", "stdout_visibility"):
        if k in d and d[k] not in GS_VIS:
            errs.append(f"{k} {d[k]!r} is not one of {sorted(GS_VIS)}")
    for i, t in enumerate(tests):
        if not isinstance(t, dict):
            errs.append(f"tests[{i}] is not an object")
            continue
        errs += [f"tests[{i}]: unknown key {k!r}" for k in t if k not in GS_TEST]
        for k in ("name", "score", "max_score", "output", "visibility"):
            if k not in t:
                errs.append(f"tests[{i}]: no {k}")
        for k in ("score", "max_score"):
            if k in t and not _num(t[k]):
                errs.append(f"tests[{i}].{k} is not a number")
        for k in ("name", "number", "output"):
            if k in t and not isinstance(t[k], str):
                errs.append(f"tests[{i}].{k} is not a string")
        if "status" in t and t["status"] not in ("passed", "failed"):
            errs.append(f"tests[{i}].status {t['status']!r}")
        if "visibility" in t and t["visibility"] not in GS_VIS:
            errs.append(f"tests[{i}].visibility {t['visibility']!r}")
        if "tags" in t and not (isinstance(t["tags"], list) and all(isinstance(x, str) for x in t["tags"])):
            errs.append(f"tests[{i}].tags is not a list of strings")
        if _num(t.get("score")) and _num(t.get("max_score")) and not 0 <= t["score"] <= t["max_score"] + 1e-9:
            errs.append(f"tests[{i}]: score {t['score']} outside [0, {t['max_score']}]")
    if _num(d.get("score")) and tests and abs(d["score"] - sum(t.get("score", 0) for t in tests)) > 1e-6:
        errs.append("score is not the sum of the tests' scores")
    return errs


def validate_prairielearn(d, size: int = 0) -> list[str]:
    """Problems with a PrairieLearn results.json (empty when valid)."""
    errs = []
    if size > 1_000_000:
        errs.append(f"results.json is {size} bytes, over 1 MB")
    if not isinstance(d, dict):
        return errs + ["results.json is not a JSON object"]
    gradable = d.get("gradable", True)
    if not isinstance(gradable, bool):
        errs.append("gradable is not a boolean")
    if gradable:
        if "score" not in d:
            errs.append("a gradable result needs a score")
        elif not (_num(d["score"]) and 0.0 <= d["score"] <= 1.0):
            errs.append(f"score {d['score']!r} is not a number in [0, 1]")
    else:
        fe = d.get("format_errors")
        if fe is not None and not (
            isinstance(fe, str) or (isinstance(fe, list) and all(isinstance(x, str) for x in fe))
        ):
            errs.append("format_errors is neither a string nor a list of strings")
    for k in ("message", "output"):
        if k in d and not isinstance(d[k], str):
            errs.append(f"{k} is not a string")
    for i, t in enumerate(d.get("tests", [])):
        if not isinstance(t, dict):
            errs.append(f"tests[{i}] is not an object")
            continue
        for k in ("name", "description", "message", "output"):
            if k in t and not isinstance(t[k], str):
                errs.append(f"tests[{i}].{k} is not a string")
        for k in ("points", "max_points"):
            if k in t and not _num(t[k]):
                errs.append(f"tests[{i}].{k} is not a number")
        if _num(t.get("points")) and _num(t.get("max_points")) and not 0 <= t["points"] <= t["max_points"] + 1e-9:
            errs.append(f"tests[{i}]: points outside [0, max_points]")
    return errs


def test_the_validators_reject_what_the_specs_forbid():
    assert validate_gradescope({"tests": [{"name": "x", "max_score": 1, "output": "", "visibility": "visible"}]})
    assert validate_gradescope({"score": 1, "tests": [], "stdout_visibility": "public"})
    assert validate_gradescope({"score": "1"})
    assert validate_prairielearn({"gradable": True}) == ["a gradable result needs a score"]
    assert validate_prairielearn({"score": 1.5})
    assert validate_prairielearn({"gradable": False, "format_errors": 3})
    assert not validate_prairielearn({"gradable": False, "format_errors": ["not a notebook"]})


# ----------------------------------------------------------------------------------------- formats, no kernel


def _scored(sid, verdicts):
    from dataclasses import asdict

    from kinlib.course import schema

    parts = [asdict(p) for p in schema.parse_parts(wf.solution())]
    rows = [
        {
            "submission": f"{sid}.ipynb",
            "notebook": wf.NB_ID,
            "part": "1.1",
            "status": "fail",
            "points": 0.0,
            "max_points": 6.0,
            "message": "a: wrong",
            "answers": [{"answer": n, "status": s} for n, s in verdicts.items()],
        },
        {
            "submission": f"{sid}.ipynb",
            "notebook": wf.NB_ID,
            "part": "1.3",
            "status": "pass",
            "points": 5.0,
            "max_points": 5.0,
            "message": "",
        },
    ]
    res = {"submission": f"{sid}.ipynb", "path": f"/c/{sid}.ipynb", "notebook": wf.NB_ID, "title": "W", "rows": rows}
    return credit.score_parts(res, parts)


@pytest.mark.parametrize("visibility", sorted(GS_VIS))
def test_gradescope_results_validate(visibility):
    res = _scored("ann", {"a": "fail", "b": "pass", "c": "pass"})
    g = lms.gradescope_results([res], visibility=visibility, seconds=3.4)
    assert validate_gradescope(g) == []
    assert g["score"] == 3 + 3 and [t["max_score"] for t in g["tests"]] == [6.0, 3.0]  # manual items not included
    assert "1.2 drawing (4 points)" in g["output"] and "1.3 explanation (2 points)" in g["output"]
    assert "✗ a: 0 / 3" in g["tests"][0]["output"]
    assert validate_gradescope(lms.gradescope_results([])) == []
    with pytest.raises(ValueError, match="visibility"):
        lms.gradescope_results([res], visibility="public")


def test_prairielearn_results_validate_and_score_in_0_1():
    res = _scored("ann", {"a": "fail", "b": "pass", "c": "pass"})
    p = lms.prairielearn_results([res])
    assert validate_prairielearn(p) == [] and p["gradable"] is True
    assert p["score"] == pytest.approx(6 / 9)
    bad = {
        "submission": "x.ipynb",
        "notebook": "",
        "rows": [{"part": "-", "status": "error", "points": 0, "max_points": 0, "message": "not a notebook: not JSON"}],
    }
    q = lms.prairielearn_results([bad])
    assert (
        validate_prairielearn(q) == [] and q["gradable"] is False and q["format_errors"] == ["not a notebook: not JSON"]
    )


def test_canvas_csv_points_possible_pending_and_roster(tmp_path):
    out = tmp_path / "class"
    report.write_outputs(out, [_scored(s, dict.fromkeys("abc", "pass")) for s in ("111", "222")])
    (out / "overrides.csv").write_text("student_id,part,score,comment\n111,1.2,4,\n111,1.3/explanation,1,\n")
    w = lms.canvas_csv(out, "PS4 (1234)", tmp_path / "c.csv")
    lines = (tmp_path / "c.csv").read_text().splitlines()
    assert lines[0] == "Student,ID,SIS User ID,SIS Login ID,Section,PS4 (1234)"
    assert lines[1] == "Points Possible,,,,,15"
    assert lines[2] == ",111,,,,14"  # 6 + 3 automatic, 4 + 1 by override
    assert lines[3] == ",222,,,," and any("222" in x and "pending" in x for x in w)  # pending: blank
    lms.canvas_csv(out, "PS4", tmp_path / "c2.csv", include_pending=True)
    assert (tmp_path / "c2.csv").read_text().splitlines()[3] == ",222,,,,9"
    roster = tmp_path / "export.csv"
    roster.write_text(
        "Student,ID,SIS User ID,SIS Login ID,Section,PS4\n"
        "    Points Possible,,,,,15\n"
        '"Lee, Ann",111,S-111,alee,Sec 1,\n'
    )
    w = lms.canvas_csv(out, "PS4", tmp_path / "c3.csv", roster=roster)
    assert (tmp_path / "c3.csv").read_text().splitlines()[2] == '"Lee, Ann",111,S-111,alee,Sec 1,14'
    assert any("222: not in the roster" in x for x in w)


# ----------------------------------------------------------------------------------------- simulations


def _bwrap_works() -> bool:
    if not shutil.which("bwrap"):
        return False
    r = subprocess.run(["bwrap", *_system_binds(), "--dev", "/dev", "--proc", "/proc", "true"], capture_output=True)
    return r.returncode == 0


def _system_binds() -> list[str]:
    """Every top-level folder read-only (as a container image would be), except those the sandbox makes."""
    opts = []
    for d in sorted(os.listdir("/")):
        p = "/" + d
        if d in ("proc", "dev", "tmp", "sys", "autograder", "grade") or not os.path.exists(p):
            continue
        opts += ["--symlink", os.readlink(p), p] if os.path.islink(p) else ["--ro-bind", p, p]
    return opts


def _simulate(mount: str, scratch: Path, entry: str) -> subprocess.CompletedProcess:
    cmd = [
        "bwrap", *_system_binds(),
        "--dev", "/dev", "--bind", "/proc", "/proc", "--tmpfs", "/tmp",
        # the Python environment (the platform's image has its packages installed): bound after the private
        # /tmp, so a checkout in a mktemp folder (CI's fresh clone) stays visible
        "--ro-bind", os.path.realpath(sys.prefix), os.path.realpath(sys.prefix),
        "--bind", str(scratch), mount,
        "--die-with-parent",
        "--setenv", "HOME", "/tmp", "--setenv", "KINLIB_PYTHON", sys.executable,
        "--chdir", mount,
        entry,
    ]  # fmt: skip
    return subprocess.run(cmd, capture_output=True, text=True, timeout=600)


needs_bwrap = pytest.mark.skipif(not _bwrap_works(), reason="bubblewrap cannot run here")


@pytest.fixture(scope="module")
def fixture_notebooks(tmp_path_factory):
    d = tmp_path_factory.mktemp("nbs")
    wf.write_solution(d)
    return d


def _sandbox_ok() -> bool:
    try:
        from kinlib.course.grader.isolation import sandbox

        sandbox.check()
        return True
    except Exception:  # noqa: BLE001
        return False


@pytest.mark.slow
@needs_bwrap
def test_gradescope_autograder_zip_in_a_simulated_container(tmp_path, fixture_notebooks):
    zpath = lms.gradescope_zip(
        tmp_path / "autograder.zip", notebooks=fixture_notebooks, cache=None, secret=tmp_path / "secret",
        sandbox=False, visibility="after_published", timeout=120, cell_timeout=30,
    )  # fmt: skip
    names = zipfile.ZipFile(zpath).namelist()
    assert {"setup.sh", "run_autograder", "config.json", "references.json", "grader-secret"} <= set(names)
    assert "kinlib-src/kinlib/course/grader/grade.py" in names and not any("__pycache__" in n for n in names)
    assert (tmp_path / "secret").read_bytes().strip() not in zipfile.ZipFile(zpath).read("grader-secret")
    scratch = tmp_path / "ag"
    zipfile.ZipFile(zpath).extractall(scratch / "source")
    for f in ("run_autograder", "setup.sh"):
        (scratch / "source" / f).chmod(0o755)
    shutil.copy(scratch / "source" / "run_autograder", scratch / "run_autograder")
    wf.write_submission(scratch / "submission" / "my work.ipynb", {"1.1": "a = th1\nb = sp.sin(th1)\nc = 0"})
    r = _simulate("/autograder", scratch, "/autograder/run_autograder")
    assert r.returncode == 0, r.stderr[-3000:]
    assert "from /autograder/source/kinlib-src/kinlib" in r.stdout  # the zip's own copy of kinlib ran
    path = scratch / "results" / "results.json"
    d = json.loads(path.read_text())
    assert validate_gradescope(d) == [], d
    assert d["score"] == 1.5 + 3  # b of 1.1, d of 1.3
    assert [(t["name"], t["score"], t["max_score"], t["visibility"]) for t in d["tests"]] == [
        ("1.1", 1.5, 6.0, "after_published"),
        ("1.3", 3.0, 3.0, "after_published"),
    ]
    assert "without the sandbox" in d["output"] and "1.2 drawing" in d["output"]
    # no notebook in the submission: still a valid results file, score 0
    shutil.rmtree(scratch / "submission")
    (scratch / "submission").mkdir()
    r = _simulate("/autograder", scratch, "/autograder/run_autograder")
    d = json.loads(path.read_text())
    assert r.returncode == 0 and validate_gradescope(d) == [] and d["score"] == 0 and "No .ipynb" in d["output"]


@pytest.mark.slow
@needs_bwrap
def test_prairielearn_external_grader_in_a_simulated_container(tmp_path, fixture_notebooks):
    out = lms.prairielearn_dir(
        tmp_path / "pl", notebooks=fixture_notebooks, cache=None, secret=tmp_path / "secret",
        sandbox=_sandbox_ok(), timeout=120, cell_timeout=30,
    )  # fmt: skip
    opts = json.loads((out / "info-externalGradingOptions.json").read_text())["externalGradingOptions"]
    assert opts["entrypoint"] == "/grade/serverFilesCourse/kinlib_grader/run.sh" and opts["timeout"] <= 600
    scratch = tmp_path / "grade"
    shutil.copytree(out / "serverFilesCourse", scratch / "serverFilesCourse")
    wf.write_submission(scratch / "student" / "w.ipynb")
    r = _simulate("/grade", scratch, "/grade/serverFilesCourse/kinlib_grader/run.sh")
    assert r.returncode == 0, r.stderr[-3000:]
    path = scratch / "results" / "results.json"
    d = json.loads(path.read_text())
    assert validate_prairielearn(d, path.stat().st_size) == [], d
    assert d["gradable"] is True and d["score"] == 1.0 and [t["points"] for t in d["tests"]] == [6.0, 3.0]
    # a file that is not a notebook: not gradable, with a format error
    (scratch / "student" / "w.ipynb").write_text("print('hello')")
    r = _simulate("/grade", scratch, "/grade/serverFilesCourse/kinlib_grader/run.sh")
    d = json.loads(path.read_text())
    assert r.returncode == 0 and validate_prairielearn(d) == [] and d["gradable"] is False
    assert "not JSON" in d["format_errors"][0]


def test_the_platform_commands(tmp_path, capsys):
    from kinlib.course.cli import main

    out = tmp_path / "class"
    report.write_outputs(out, [_scored("111", dict.fromkeys("abc", "pass"))])
    assert main(["grade", "canvas", str(out), "--assignment", "PS4", "--out", str(tmp_path / "c.csv")]) == 0
    assert "111 pending" in capsys.readouterr().err.replace(":", "")
    assert (tmp_path / "c.csv").read_text().splitlines()[2] == ",111,,,,"
    assert main(["grade", "canvas", str(tmp_path / "empty"), "--assignment", "PS4", "--out", "x.csv"]) == 2
    for bad in (["grade", "gradescope", "--out", "a.zip", "--visibility", "public"], ["grade", "canvas", str(out)]):
        with pytest.raises(SystemExit) as e:
            main(bad)
        assert e.value.code == 2
    args = ["--notebooks", str(tmp_path), "--secret", str(tmp_path / "s")]
    assert main(["grade", "prairielearn", "--out", str(tmp_path / "pl"), *args]) == 2
    assert "no solution notebooks" in capsys.readouterr().err
