"""The student's path (issue 30): where a student starts, what the students' site and pages do for them.

- ``make lab-students`` opens JupyterLab on the student workbooks (copied once into a folder of the student's own),
  never on the solution notebooks; ``make site AUDIENCE=students`` serves the students' build; JupyterLab started by
  either asks nothing about news (notebooks/.lab-settings).
"""

from __future__ import annotations

import json
import subprocess
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]


def _make_n(*args) -> str:
    return subprocess.run(["make", "-n", *args], cwd=ROOT, capture_output=True, text=True, check=True).stdout


def test_make_lab_students_opens_the_workbooks_not_the_solutions(tmp_path):
    out = _make_n("lab-students", f"WORKBOOKS_DIR={tmp_path}")
    assert f'--notebook-dir="{tmp_path}"' in out and "--notebook-dir=notebooks" not in out, out
    assert "build/handouts-students/workbooks/" in out and "--audience students" in out, out
    assert 'test -e "' in out  # a workbook the student already has is never overwritten
    assert f"--LabApp.app_settings_dir={ROOT / 'notebooks' / '.lab-settings'}" in out
    readme = (ROOT / "README.md").read_text()
    assert "make lab-students   # students start here" in readme
    assert "(students start here)" not in readme.split("make lab        #")[1].splitlines()[0]


def test_make_site_for_students_serves_the_students_build():
    out = _make_n("site", "AUDIENCE=students")
    assert "serve('build/handouts-students'" in out, out
    assert "serve('build/handouts'" in _make_n("site")


def test_jupyterlab_asks_nothing_about_news():
    overrides = json.loads((ROOT / "notebooks" / ".lab-settings" / "overrides.json").read_text())
    note = overrides["@jupyterlab/apputils-extension:notification"]
    assert note["fetchNews"] == "false" and note["checkForUpdates"] is False
