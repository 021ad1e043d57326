"""A full disk never spoils a row silently (issue 31, item 6): the answers' result files are allocated before any
cell of the submission runs (kinlib.course.grader.isolation.kernel.NotebookRun.reserve), so a submission that fills
its disk still has its answers read and graded; a disk already full when grading starts is flagged as
infrastructure (the batch retries it), never an "internal error" or a student's fail."""

from __future__ import annotations

import errno
import json
import os
from pathlib import Path

import pytest

from kinlib.course.grader import grade
from kinlib.course.grader.isolation.limits import Enclosure, Limits

FIX = Path(__file__).resolve().parents[1] / "fixtures" / "grade"
SOLUTION = FIX / "notebooks" / "90_grade_fixture.ipynb"
# fill every byte the submission may write (its own tmpfs: the working folder, /tmp, and the answers' files)
FILL = (
    "import os\n"
    "_n, _errs = 0, set()\n"
    "for _d in ('/tmp', '.'):\n"
    "    try:\n"
    "        while True:\n"
    "            with open(os.path.join(_d, f'fill{_n}'), 'wb') as _f:\n"
    "                _n += 1\n"
    "                for _ in range(8):\n"
    "                    _f.write(b'0' * 2**20)\n"
    "    except OSError as _e:\n"
    "        _errs.add(_e.errno)\n"
    "print(_n, _errs)\n"
)


def _filler() -> dict:
    nb = json.loads(SOLUTION.read_text())
    nb["cells"].append({"cell_type": "code", "metadata": {}, "source": FILL, "outputs": [], "execution_count": None})
    return nb


def _tmpfs_available() -> bool:
    with Enclosure(Limits(disk_bytes=8 * 2**20), "probe") as enc:
        return bool(enc.tmpfs)


@pytest.mark.slow
def test_a_submission_that_fills_its_disk_still_has_its_answers_graded(tmp_path, grader_reference_cache):
    if not _tmpfs_available():
        pytest.skip("a size-limited tmpfs needs root")
    sub = tmp_path / "filler.ipynb"
    sub.write_text(json.dumps(_filler()))
    refs = grade.load_references(FIX / "notebooks", grader_reference_cache, secret=grade.load_secret())
    res = grade.grade_submission(sub, refs, cell_timeout=300, total_timeout=900, limits=Limits(disk_bytes=48 * 2**20))
    parts = [r for r in res["rows"] if r["part"] != "limits"]
    assert [r["status"] for r in parts] == ["pass"] * 5, [(r["part"], r["message"][:200]) for r in parts]
    # the disk really was full: the fill cell ran into ENOSPC (or its per-file cap) on the submission's tmpfs
    fill = res["cells"][-1]
    assert fill["status"] == "ok", fill
    assert any("disk" in x or "written" in x for x in res.get("limits_reached", [])), res.get("limits_reached")
    assert not res.get("infrastructure"), res.get("infrastructure")


def test_a_disk_full_before_the_submission_runs_is_flagged_not_an_internal_error(
    tmp_path, monkeypatch, grader_reference_cache
):
    """ENOSPC when the grader allocates the answers' files (simulated: posix_fallocate fails): every row says
    'not graded: infrastructure' (the batch retries such a submission), never 0 points or an internal error."""
    refs = grade.load_references(FIX / "notebooks", grader_reference_cache, secret=grade.load_secret())
    sub = tmp_path / "solution.ipynb"
    sub.write_bytes(SOLUTION.read_bytes())

    def full(fd, offset, length):
        raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))

    monkeypatch.setattr(os, "posix_fallocate", full)
    res = grade.grade_submission(sub, refs, cell_timeout=120, total_timeout=600)
    rows = res["rows"]
    assert rows and all(r["status"] == "error" for r in rows), rows
    assert all(r["message"].startswith("not graded: infrastructure: no space") for r in rows), rows
    assert "internal error" not in json.dumps(rows)
    assert res["infrastructure"]
