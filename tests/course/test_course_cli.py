"""The ``kinlib`` command (kinlib.course.cli): subcommands, --help, --version, exit statuses.

The console script is declared as ``kinlib = "kinlib.course.cli:main"``; ``python -m kinlib.course``
runs the same ``main``.
"""

from __future__ import annotations

import csv
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

import kinlib
from kinlib.course.cli import main

ROOT = Path(__file__).resolve().parents[2]
HANDOUTS_FIXTURES = ROOT / "tests" / "fixtures" / "handouts"
GRADE_FIXTURES = ROOT / "tests" / "fixtures" / "grade"
VENDOR = ROOT / "build" / "vendor"


def _exit(argv, capsys):
    with pytest.raises(SystemExit) as e:
        main(argv)
    out, err = capsys.readouterr()
    return e.value.code, out, err


def test_help_lists_the_subcommands(capsys):
    code, out, _ = _exit(["--help"], capsys)
    assert code == 0 and "usage: kinlib" in out
    assert "handouts" in out and "grade" in out and "--version" in out


@pytest.mark.parametrize(
    "command, options",
    [
        (
            "handouts",
            [
                "--out",
                "--vendor",
                "--jobs",
                "--timeout",
                "--no-verify",
                "--only",
                "--no-site",
                "--no-pdf",
                "--reuse-from",
                "--serve",
            ],
        ),
        ("grade", ["--out", "--timeout", "--cell-timeout", "--jobs", "--notebooks", "--cache", "--quiet"]),
    ],
)
def test_each_subcommand_has_help(command, options, capsys):
    code, out, _ = _exit([command, "--help"], capsys)
    assert code == 0 and f"usage: kinlib {command}" in out
    assert all(o in out for o in options)


def test_version(capsys):
    code, out, _ = _exit(["--version"], capsys)
    assert code == 0 and out.strip() == f"kinlib {kinlib.__version__}"


@pytest.mark.parametrize(
    "argv",
    [
        [],
        ["frobnicate"],
        ["--nope"],
        ["grade"],
        ["grade", "x.ipynb"],
        ["grade", "x.ipynb", "--out", "o", "--jobs", "0"],
        ["grade", "x.ipynb", "--out", "o", "--timeout", "-1"],
        ["grade", "x.ipynb", "--out", "o", "--cell-timeout", "s"],
        ["grade", "no/such/file.ipynb", "--out", "o"],
        ["handouts"],
        ["handouts", "nb", "--jobs", "two"],
    ],
)
def test_usage_errors_exit_2_with_one_line(argv, capsys, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    (tmp_path / "x.ipynb").write_text("{}")
    code, out, err = _exit(argv, capsys)
    assert code == 2 and out == ""
    assert len(err.strip().splitlines()) == 1 and err.startswith("kinlib") and "error:" in err, err


def test_grade_notebooks_must_be_a_folder(capsys, tmp_path):
    (tmp_path / "x.ipynb").write_text("{}")
    code, _, err = _exit(
        ["grade", str(tmp_path / "x.ipynb"), "--out", str(tmp_path / "o"), "--notebooks", str(tmp_path / "missing")],
        capsys,
    )
    assert code == 2 and "--notebooks" in err and len(err.strip().splitlines()) == 1


def test_handouts_without_notebooks_is_an_error(capsys, tmp_path):
    assert main(["handouts", str(tmp_path), "--out", str(tmp_path / "out")]) == 2
    err = capsys.readouterr().err
    assert err.startswith("kinlib handouts: error: no notebooks named NN_*.ipynb") and err.count("\n") == 1


def test_handouts_on_a_folder(capsys, tmp_path):
    nbs = tmp_path / "notebooks"
    nbs.mkdir()
    shutil.copy(HANDOUTS_FIXTURES / "01_fixture_jacobians.ipynb", nbs)
    out = tmp_path / "handouts"
    assert (
        main(
            [
                "handouts",
                str(nbs),
                "--out",
                str(out),
                "--vendor",
                str(VENDOR),
                "--jobs",
                "1",
                "--no-verify",
                "--no-site",
                "--no-pdf",
            ]
        )
        == 0
    )
    for rel in (
        "index.html",
        "problems/01_fixture_jacobians.html",
        "solutions/01_fixture_jacobians.html",
        "workbooks/01_fixture_jacobians.ipynb",
    ):
        assert (out / rel).is_file(), rel
    workbook = (out / "workbooks" / "01_fixture_jacobians.ipynb").read_text()
    assert (
        "from kinlib.course.workbook.selfcheck import check" in workbook
        and "%load_ext kinlib.course.workbook.selfcheck" in workbook
    )
    assert "kinlib handouts: wrote" in capsys.readouterr().out


def test_grade_a_small_batch(capsys, tmp_path, grader_reference_cache):
    subs = tmp_path / "subs"
    subs.mkdir()
    shutil.copy(GRADE_FIXTURES / "notebooks" / "90_grade_fixture.ipynb", subs / "solution.ipynb")
    shutil.copy(GRADE_FIXTURES / "workbooks" / "90_grade_fixture.ipynb", subs / "untouched.ipynb")
    out = tmp_path / "grades"
    assert (
        main(
            [
                "grade",
                str(subs),
                "--out",
                str(out),
                "--notebooks",
                str(GRADE_FIXTURES / "notebooks"),
                "--cache",
                str(grader_reference_cache),  # the run's answer key (signed with its secret), not built again
                "--jobs",
                "2",
                "--quiet",
            ]
        )
        == 0
    )
    stdout = capsys.readouterr().out
    assert "submission" in stdout and "wrote" in stdout and "[1/2]" not in stdout  # --quiet: the table only
    with open(out / "grades.csv") as f:
        rows = list(csv.DictReader(f))
    status = {(Path(r["submission"]).stem, r["part"]): r["status"] for r in rows}
    assert {p: s for (sub, p), s in status.items() if sub == "solution"} == dict.fromkeys(
        ["1.1", "1.2", "1.3", "1.4", "1.5"], "pass"
    )
    assert {s for (sub, _), s in status.items() if sub == "untouched"} == {"fail"}
    assert len(list((out / "feedback").glob("*.md"))) == 2


def test_python_dash_m_kinlib_course():
    r = subprocess.run(
        [sys.executable, "-m", "kinlib.course", "--version"], capture_output=True, text=True, cwd=ROOT, timeout=120
    )
    assert r.returncode == 0 and r.stdout.strip() == f"kinlib {kinlib.__version__}"
    r = subprocess.run(
        [sys.executable, "-m", "kinlib.course", "grade"], capture_output=True, text=True, cwd=ROOT, timeout=120
    )
    assert r.returncode == 2 and len(r.stderr.strip().splitlines()) == 1


@pytest.mark.parametrize("command", [["handouts", "notebooks"], ["grade", "subs", "--out", "o"]])
def test_without_the_course_extra_the_command_says_what_to_install(command, capsys, monkeypatch):
    """`pip install kinlib` (no [course]) still installs the console script: it must say what is missing."""
    import builtins

    real_import = builtins.__import__

    def no_nbformat(name, *args, **kwargs):
        if name.split(".")[0] in ("nbformat", "nbclient", "nbconvert", "jupyter_client") or (
            name in ("publish.handouts", "grader.grade")
            and args
            and (args[0] or {}).get("__package__") == "kinlib.course"
        ):
            raise ModuleNotFoundError(f"No module named {name!r}", name="nbformat")
        return real_import(name, *args, **kwargs)

    for mod in ("kinlib.course.publish.handouts", "kinlib.course.grader.grade"):
        monkeypatch.delitem(sys.modules, mod, raising=False)
    monkeypatch.setattr(builtins, "__import__", no_nbformat)
    assert main(command) == 2
    err = capsys.readouterr().err
    assert "missing nbformat" in err and "pip install 'kinlib[course]'" in err and err.count("\n") == 1
