"""Incremental handouts (kinlib.course.publish.incremental): what is reused, what is made again.

The orchestration is tested with a stand-in for the per-notebook step (no kernel: milliseconds); the real
second build of the fixture notebook (it executes nothing and changes no file) is in tests/course/test_handouts.py,
which builds that notebook once for all its tests.
"""

from __future__ import annotations

import json
from pathlib import Path

import nbformat
import pytest

from kinlib.course.publish import handouts, incremental


def _notebook(path: Path, title: str) -> None:
    nb = nbformat.v4.new_notebook()
    nb.cells = [nbformat.v4.new_markdown_cell(f"# {title}")]
    nb.metadata["kinlib"] = {"notebook": path.stem, "title": title, "sections": [path.stem[:2]]}
    nbformat.write(nb, path)


@pytest.fixture
def fake_step(monkeypatch):
    """handouts.build_one replaced by a stand-in that writes the three handouts and records each call."""
    calls = []

    def build_one(path, out, urls, timeout, verify, log=print, links=(), audience="all"):
        calls.append(path.stem)
        nb = nbformat.read(path, as_version=4)
        for kind in ("solutions", "problems") if audience == "all" else ("problems",):
            (out / kind).mkdir(parents=True, exist_ok=True)
            (out / kind / f"{path.stem}.html").write_text(f"<p>{kind} of {nb.cells[0].source}</p>")
        (out / "workbooks").mkdir(parents=True, exist_ok=True)
        nbformat.write(nb, out / "workbooks" / f"{path.stem}.ipynb")
        title = nb.metadata["kinlib"]["title"]
        return {
            "stem": path.stem,
            "title": title,
            "sections": [],
            "executed": nb,
            "problems": nb,
            "workbook": nb,
            "notes": [],
        }

    monkeypatch.setattr(handouts, "build_one", build_one)
    monkeypatch.setattr(handouts, "build_assets", lambda dest, vendor: {})
    return calls


def _build(src, out, log=None, **kw):
    return handouts.build(
        src,
        out,
        **{"site": False, "pdfs": False, "verify": False, "jobs": 1, **kw},
        log=(log if log is not None else []).append,
    )


def test_a_second_build_reuses_every_section_and_one_change_rebuilds_one(tmp_path, fake_step):
    src, out = tmp_path / "nb", tmp_path / "out"
    src.mkdir()
    for stem, title in (("01_a", "A"), ("02_b", "B"), ("03_c", "C")):
        _notebook(src / f"{stem}.ipynb", title)
    _build(src, out)
    assert fake_step == ["01_a", "02_b", "03_c"]

    log: list = []
    entries = _build(src, out, log)
    assert fake_step == ["01_a", "02_b", "03_c"], "nothing changed: nothing is made again"
    assert [e["title"] for e in entries] == ["A", "B", "C"] and all(e.get("reused") for e in entries)
    assert sum("reused" in line for line in log) == 3
    assert entries[1]["workbook"].cells[0].source == "# B"  # the reused entry carries its notebooks

    _notebook(src / "02_b.ipynb", "B, edited")  # one notebook changes
    entries = _build(src, out)
    assert fake_step[3:] == ["02_b"]
    assert [e["title"] for e in entries] == ["A", "B, edited", "C"]

    _build(src, out, fresh=True)  # --fresh: everything again
    assert fake_step[4:] == ["01_a", "02_b", "03_c"]


def test_only_builds_one_section_and_the_index_keeps_the_others(tmp_path, fake_step):
    src, out = tmp_path / "nb", tmp_path / "out"
    src.mkdir()
    for stem, title in (("01_a", "A"), ("02_b", "B")):
        _notebook(src / f"{stem}.ipynb", title)
    _build(src, out)
    _notebook(src / "01_a.ipynb", "A, edited")
    _notebook(src / "02_b.ipynb", "B, edited")
    entries = _build(src, out, only=["02"])
    assert fake_step == ["01_a", "02_b", "02_b"] and [e["stem"] for e in entries] == ["02_b"]
    index = (out / "index.html").read_text()
    assert "problems/02_b.html" in index
    assert "problems/01_a.html" not in index, "01 changed and was not rebuilt: its old pages are not listed"


def test_a_stopped_build_or_a_removed_output_is_made_again(tmp_path, fake_step):
    src, out = tmp_path / "nb", tmp_path / "out"
    src.mkdir()
    _notebook(src / "01_a.ipynb", "A")
    _build(src, out)
    (out / "problems" / "01_a.html").unlink()  # an output went missing
    _build(src, out)
    assert fake_step == ["01_a", "01_a"]
    stamp = incremental.stamp_dir(out) / "section-01_a.json"
    assert not any(p.name == incremental.STAMP_DIR for p in out.rglob("*")), "nothing of the build's own inside out"
    stamp.write_text("{not json")  # a stamp cut short
    _build(src, out)
    assert fake_step == ["01_a", "01_a", "01_a"]
    assert json.loads(stamp.read_text())["data"]["title"] == "A"


def test_the_key_covers_the_notebook_the_code_and_the_options(tmp_path):
    k = incremental.key
    assert k(b"nb", {"verify": True}) != k(b"nb", {"verify": False})
    assert k(b"nb", "code-1") != k(b"nb", "code-2")
    assert k(b"a", b"bc") != k(b"ab", b"c")  # parts are length-prefixed
    code = incremental.code_key()
    assert len(code) == 64 and code == incremental.code_key()


def test_a_students_build_takes_the_full_builds_current_sections_and_pdfs_never_a_solution(
    tmp_path, fake_step, monkeypatch
):
    """``reuse_from`` (``make handouts AUDIENCE=students`` after ``make handouts``): the sections made from the same
    notebook, code and options are copied (problems page, workbook), not made again; a changed notebook is made; no
    solution page or PDF comes along; a PDF is copied only for a page of the same bytes."""
    from kinlib.course.publish import printing

    printed: list = []

    def print_pdfs(out, pages, log=print):
        for p in pages:
            pdf = out / "pdf" / p.parent.name / f"{p.stem}.pdf"
            pdf.parent.mkdir(parents=True, exist_ok=True)
            pdf.write_bytes(b"%PDF " + p.read_bytes())
            printed.append(f"{out.name}/{p.parent.name}/{p.stem}")

    monkeypatch.setattr(printing, "print_pdfs", print_pdfs)
    src, full, students = tmp_path / "nb", tmp_path / "full", tmp_path / "students"
    src.mkdir()
    for stem, title in (("01_a", "A"), ("02_b", "B")):
        _notebook(src / f"{stem}.ipynb", title)
    _build(src, full, pdfs=True)
    assert fake_step == ["01_a", "02_b"]
    assert sorted(printed) == ["full/problems/01_a", "full/problems/02_b", "full/solutions/01_a", "full/solutions/02_b"]
    _notebook(src / "02_b.ipynb", "B, edited")  # changed since the full build: made for the students
    log: list = []
    entries = _build(src, students, log, pdfs=True, audience="students", reuse_from=full)
    assert fake_step == ["01_a", "02_b", "02_b"], "01 is taken from the full build, 02 (changed) is made"
    assert [e["title"] for e in entries] == ["A", "B, edited"] and entries[0].get("reused")
    assert any("01_a: taken from" in line for line in log)
    for kind, ext in (("problems", "html"), ("workbooks", "ipynb")):
        assert (students / kind / f"01_a.{ext}").read_bytes() == (full / kind / f"01_a.{ext}").read_bytes()
    assert not (students / "solutions").exists() and not (students / "pdf" / "solutions").exists()
    # 01's page has the full build's bytes: its PDF is copied; 02's is printed (its page changed)
    assert printed[4:] == ["students/problems/02_b"]
    assert (students / "pdf" / "problems" / "01_a.pdf").read_bytes() == (
        full / "pdf" / "problems" / "01_a.pdf"
    ).read_bytes()
    # a second students' build reuses its own sections: nothing made, nothing printed
    _build(src, students, pdfs=True, audience="students", reuse_from=full)
    assert fake_step == ["01_a", "02_b", "02_b"] and len(printed) == 5
