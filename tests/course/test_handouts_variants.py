"""``kinlib handouts --variants ROSTER.csv`` (issue 33): each student's pages and workbooks carry their own numbers
and self-checks, the instructor's key and answer sheets stay out of the published folder, and the screenshots of
two students' 05 pages differ where their numbers do.

Slow: 04 and 05 are executed and their students' variants proved (about two minutes).
"""

from __future__ import annotations

import csv
import json
import re
from pathlib import Path

import pytest

from kinlib.course.answers import wire
from kinlib.course.publish import handouts
from kinlib.course.variants import draw as drawmod
from kinlib.course.variants import key as keymod
from kinlib.course.variants.spec import Spec, assignment_source, render_markdown
from kinlib.course.workbook import selfcheck

ROOT = Path(__file__).resolve().parents[2]
NOTEBOOKS = ROOT / "notebooks"
VENDOR = ROOT / "build" / "vendor"
ROSTER = "id,name\nada,Ada Lovelace\nbob,Bob Bell\ncyd,\n"
N05 = "05_singularities_planar"

pytestmark = pytest.mark.slow


@pytest.fixture(scope="module")
def built(tmp_path_factory):
    root = tmp_path_factory.mktemp("variants-handouts")
    (root / "roster.csv").write_text(ROSTER)
    secret_file = root / "secret"
    secret_file.write_text("ab" * 32)
    secret_file.chmod(0o600)
    out = root / "handouts"
    logs: list = []
    handouts.build(
        NOTEBOOKS,
        out,
        vendor=VENDOR,
        jobs=2,
        only=["04", "05"],
        site=False,
        pdfs=False,
        verify=False,
        variants=root / "roster.csv",
        secret=secret_file,
        log=logs.append,
    )
    from kinlib.course.grader.secret import load_secret

    secret = load_secret(secret_file)
    return out, root / "variants", secret, logs


def _links(inst: Path) -> dict:
    with open(inst / "links.csv") as f:
        return {row["id"]: row for row in csv.DictReader(f)}


def _student_files(out: Path, index: str) -> dict:
    page = (out / index).read_text()
    return {m.split("/")[0]: m for m in re.findall(r'href="\.\./\.\./([^"]+)"', page)}


def test_each_student_gets_their_own_numbers_in_the_question_the_variant_cell_and_the_page(built):
    out, inst, secret, _ = built
    key = keymod.read_key(inst / "key.json", secret)
    assert key is not None
    spec = Spec.from_notebook(json.loads((NOTEBOOKS / f"{N05}.ipynb").read_bytes()))
    links = _links(inst)
    assert set(links) == {"ada", "bob", "cyd"}
    seen = {}
    for sid, row in links.items():
        nk = key.notebooks[N05]
        values = nk.variants[nk.students[sid]].values
        attempt = sum(r["student"] == sid for r in nk.rejections)
        assert values == drawmod.draw(secret, sid, N05, spec, attempt)
        files = [f for f in re.findall(r'href="\.\./\.\./([^"]+)"', (out / row["index"]).read_text()) if N05 in f]
        wb_path = next(out / f for f in files if f.endswith(".ipynb"))
        page = next(out / f for f in files if f.endswith(".html")).read_text()
        wb = json.loads(wb_path.read_text())
        text = "\n".join("".join(c["source"]) for c in wb["cells"])
        cell_line = next(line for line in text.splitlines() if line.startswith("q53 = "))
        seen[sid] = cell_line
        assert cell_line == assignment_source(spec, values).splitlines()[-1]
        assert "variants" not in wb["metadata"].get("kinlib", {})  # the domain is not the student's
        question = next("".join(c["source"]) for c in wb["cells"] if "**5.3 (" in "".join(c["source"]))
        theta = render_markdown("{{q53}}", spec, values)
        assert f"$\\theta = {theta}$" in question
        assert theta in page  # the problems page states the same numbers
    assert len(set(seen.values())) > 1  # three students: not all the same numbers


def test_the_self_check_accepts_the_students_own_answer_and_not_a_classmates(built):
    out, inst, secret, _ = built
    key = keymod.read_key(inst / "key.json", secret)
    nk = key.notebooks[N05]
    links = _links(inst)
    variants = {sid: nk.students[sid] for sid in links}
    distinct = sorted(set(variants.values()))
    if len(distinct) < 2:
        pytest.skip("the three students share one variant of 05")
    a, b = distinct[:2]
    wb_a = json.loads((out / f"variant-workbooks/{N05}-{a}.ipynb").read_text())
    checks = [c for c in wb_a["cells"] if 'check("5.3"' in "".join(c["source"])]
    assert checks
    specs = dict(re.findall(r'(\w+)="([^"]+)"', "".join(checks[0]["source"])))
    for name in ("can_move", "cannot_move"):
        mine = wire.load(nk.variants[a].answers[name]["tree"], max_nodes=10 * wire.MAX_NODES)
        theirs = wire.load(nk.variants[b].answers[name]["tree"], max_nodes=10 * wire.MAX_NODES)
        assert selfcheck.verdict(mine, specs[name], salt=f"5.3:{name}")[0] == "correct", name
        same_space = mine.row_join(theirs).rank() == mine.rank()
        if not same_space:  # a classmate's directions are not this student's
            assert selfcheck.verdict(theirs, specs[name], salt=f"5.3:{name}")[0] == "incorrect", name


def test_the_instructors_files_are_beside_the_published_folder_never_in_it(built):
    out, inst, _secret, logs = built
    published = [p for p in out.rglob("*") if p.is_file()]
    names = {p.name for p in published}
    assert "key.json" not in names and "links.csv" not in names and "report.txt" not in names
    assert not any(p.parent.name == "answers" for p in published)
    for sid in ("ada", "bob", "cyd"):
        assert (inst / "answers" / f"{sid}.html").is_file()
    report = (inst / "report.txt").read_text()
    assert "04_interpreting_the_jacobian: 3 students" in report and "05_singularities_planar: 3 students" in report
    assert "every one proved well-posed" in report and "draws rejected" in report
    tokens = {row["token"] for row in _links(inst).values()}
    assert {p.name for p in (out / "students").iterdir()} == tokens
    # a token is not the id, and cannot be made without the secret
    assert not tokens & {"ada", "bob", "cyd"}


def test_no_variant_page_or_workbook_states_its_own_graded_answers(built):
    """test_leaks' search (every form of every graded answer), run on each variant's own page and workbook with
    that variant's own answers: a student's page gives none of *their* answers away."""
    from test_leaks import allowed, find_hits, forms, students_files

    from kinlib.course.schema import parse_parts

    out, inst, secret, _ = built
    key = keymod.read_key(inst / "key.json", secret)
    stems = sorted(p.stem for p in NOTEBOOKS.glob("[0-9][0-9]_*.ipynb"))
    files = students_files(out)
    searched = 0
    for nid, nk in key.notebooks.items():
        part_of = {
            n: p.part for p in parse_parts(json.loads((NOTEBOOKS / f"{nid}.ipynb").read_bytes())) for n in p.kinds
        }
        for vk, v in nk.variants.items():
            mine = {rel: text for rel, text in files.items() if f"{nid}-{vk}" in rel}
            assert len(mine) == 2, sorted(mine)  # its page and its workbook
            all_forms = [f for name, ans in v.answers.items() for f in forms(nid, part_of[name], name, ans)]
            searched += len(all_forms)
            hits = [h for h in find_hits(all_forms, mine, stems) if not allowed(h)]
            assert not hits, [(h.form.part, h.form.name, h.form.label, h.file, h.context) for h in hits]
    assert searched > 50
