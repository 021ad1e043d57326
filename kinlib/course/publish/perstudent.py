"""``kinlib handouts --variants ROSTER.csv``: each student's own problem set (issue 33).

After the sections are built, :func:`build_variants` proves every student's variant
(:func:`kinlib.course.variants.key.build_key`; proofs of unchanged notebooks are reused from the last key) and
writes, for each distinct variant of a notebook (many students may share one):

- ``OUT/variant-pages/NN_x-<variant>.html``: the problems page with that variant's numbers: the question text
  (``variant_markdown``), the variant cell, and the figures re-drawn by the variant's replay;
- ``OUT/variant-workbooks/NN_x-<variant>.ipynb``: the workbook with those numbers and self-checks keyed to the
  variant's own answers (its fingerprints); the JupyterLite site serves them (``files/variants/``);

and for each student ``OUT/students/<token>/index.html``, linking their pages and workbooks (a section without
variants links the shared ones). The token is an HMAC of the student id: a student's link cannot be guessed from
another's. Nothing under OUT states an answer.

The instructor's files go *beside* OUT, never in it (so neither the full nor the students' build publishes them):
``<OUT>/../variants/`` holds ``key.json`` (signed: what ``kinlib grade --variants`` reads), ``report.txt`` (per
notebook: students, variants, draws rejected and why), ``links.csv`` (id, name, token, page) and
``answers/<id>.html`` (each student's numbers and reference answers).
"""

from __future__ import annotations

import copy
import csv
import hashlib
import hmac
import html
import json
import time
from pathlib import Path

import nbformat

from ..answers import wire
from ..schema import answer_groups, cell_reveals
from ..variants import key as keymod
from ..variants.spec import Spec, apply, assignment_source, render_markdown

__all__ = ["build_variants", "student_token", "instructor_dir"]


def student_token(secret: bytes, student_id: str) -> str:
    """The student's folder name under ``OUT/students/``: 16 hex digits of HMAC(secret, id).

    >>> t = student_token(b"s" * 32, "ada"); len(t), t == student_token(b"s" * 32, "ada") != student_token(b"s" * 32, "bob")
    (16, True)
    """
    return hmac.new(secret, b"kinlib-student-folder\0" + student_id.encode(), hashlib.sha256).hexdigest()[:16]


def instructor_dir(out: Path) -> Path:
    """Where the instructor's variant files go: ``variants/`` beside the handouts folder (never inside it).

    >>> instructor_dir(Path("build/handouts")).as_posix()
    'build/variants'
    """
    return Path(out).parent / "variants"


def _variant_problems(problems, executed, spec: Spec, values: dict, outputs: dict):
    """The shared problems page's notebook with a variant's numbers: its question text, its variant cell, and the
    outputs of the cells its replay re-ran (matched by cell id: the problems keep the executed notebook's ids)."""
    nb = copy.deepcopy(problems)
    by_id = {executed.cells[int(i)].get("id"): outs for i, outs in outputs.items() if int(i) < len(executed.cells)}
    code = assignment_source(spec, values)
    for c in nb.cells:
        meta = c.metadata.get("kinlib") or {}
        if c.cell_type == "markdown" and isinstance(meta.get("variant_markdown"), str):
            c.source = render_markdown(meta["variant_markdown"], spec, values)
        elif c.cell_type == "code" and meta.get("variant") is True:
            c.source = code
        elif c.cell_type == "code" and c.get("id") in by_id:
            c.outputs = [nbformat.from_dict(o) for o in by_id[c.get("id")]]
            for o in c.outputs:
                if "execution_count" in o:
                    o["execution_count"] = None
    return nb


def _fingerprints(variant) -> dict:
    out = {}
    for k, fp in variant.fingerprints.items():
        idx, _, name = k.partition("|")
        out[(int(idx), name)] = fp
    return out


def _answer_sheet(student, key, tokens) -> str:
    rows = [f"<h1>Answer sheet: {html.escape(student.id)} {html.escape(student.name)}</h1>"]
    for nid, nk in sorted(key.notebooks.items()):
        v = nk.variants[nk.students[student.id]]
        rows.append(f"<h2>{html.escape(nid)}</h2><p>numbers: <code>{html.escape(json.dumps(v.values))}</code></p>")
        rows.append("<table border=1 cellpadding=4><tr><th>answer</th><th>reference</th></tr>")
        for name, a in sorted(v.answers.items()):
            if "choice" in a:
                shown = json.dumps(a["choice"].get("value"))
            elif "tree" in a:
                try:
                    import sympy as sp

                    shown = sp.pretty(wire.load(a["tree"], max_nodes=10 * wire.MAX_NODES), use_unicode=True)
                except (wire.WireError, RecursionError, ValueError) as exc:
                    shown = f"(not shown: {exc})"
            else:
                shown = a.get("error", "")
            rows.append(f"<tr><td>{html.escape(name)}</td><td><pre>{html.escape(shown)}</pre></td></tr>")
        rows.append("</table>")
    return "<!doctype html><meta charset=utf-8><title>answers</title>" + "\n".join(rows)


def _student_index(student, title_of, pages, workbooks, lite: bool) -> str:
    items = []
    for stem, title in title_of.items():
        page, wb = pages[stem], workbooks[stem]
        links = [f'<a href="../../{page}">problems</a>', f'<a href="../../{wb}">workbook (.ipynb)</a>']
        if lite:
            from .lite import lite_link

            site_path = wb.replace("variant-workbooks/", "variants/", 1)
            links.append(f'<a href="../../{lite_link(site_path)}">open in the browser</a>')
        items.append(f"<li>{html.escape(title)}: {' · '.join(links)}</li>")
    return (
        "<!doctype html><meta charset=utf-8><title>Your problem set</title>"
        f"<h1>Your problem set, {html.escape(student.name or student.id)}</h1>"
        "<p>Your numbers were drawn for you (most classmates have others): your answers are graded against your own numbers.</p>"
        f"<ul>{''.join(items)}</ul>"
    )


def _lendable(previous, outputs: dict):
    """The last key's proofs that can be lent, with their pictures: a notebook whose pictures are missing or
    damaged in ``outputs.json`` (untrusted, never a crash) is left out, so its variants are proved and drawn
    again rather than shown with the original's figures.

    >>> nk = keymod.NotebookKey("05", "0" * 64, {}, {}, variants={"v1": keymod.Variant({}, {}, {})})
    >>> sorted(_lendable(keymod.Key({"05": nk}), {"05": {"v1": {"8": []}}}).notebooks)
    ['05']
    >>> [sorted(_lendable(keymod.Key({"05": nk}), bad).notebooks) for bad in ({}, {"05": []}, {"05": {"v2": {}}})]
    [[], [], []]
    """
    if previous is None:
        return None

    def pictured(nid, nk):
        got = outputs.get(nid)
        return isinstance(got, dict) and all(isinstance(got.get(vk), dict) for vk in nk.variants)

    previous.notebooks = {nid: nk for nid, nk in previous.notebooks.items() if pictured(nid, nk)}
    for nid, nk in previous.notebooks.items():
        for vk, v in nk.variants.items():
            v.outputs = outputs[nid][vk]
    return previous


def build_variants(
    notebooks: Path,
    out: Path,
    roster_path,
    secret: bytes,
    entries: list,
    urls: dict,
    *,
    lite: bool,
    make_workbook,
    fresh: bool = False,
    log=print,
) -> keymod.Key:
    """Prove each student's variants and write their pages, workbooks and links (see the module docstring).

    It runs the notebooks' variants in kernels (tests/course/test_handouts_variants.py exercises it through
    :func:`kinlib.course.publish.handouts.build`, which passes its ``make_workbook``), hence not run here:

    >>> key = build_variants(Path("notebooks"), Path("build/handouts"), "roster.csv", secret, entries, urls,
    ...                      lite=True, make_workbook=make_workbook)  # doctest: +SKIP
    >>> sorted(key.notebooks)  # doctest: +SKIP
    ['04_interpreting_the_jacobian', '05_singularities_planar']
    """
    from .pages import export_html

    t0 = time.perf_counter()
    out, notebooks = Path(out), Path(notebooks)
    roster = keymod.read_roster(roster_path)
    inst = instructor_dir(out)
    previous = None if fresh else keymod.read_key(inst / "key.json", secret)
    outputs = keymod.read_outputs(inst / "outputs.json")
    previous = _lendable(previous, outputs)
    stems = [e["stem"] for e in entries]
    key = keymod.build_key(notebooks, roster, secret, previous=previous, log=log, only=stems)
    keymod.write_key(inst / "key.json", key, secret)
    keymod.write_outputs(inst / "outputs.json", key)
    by_stem = {e["stem"]: e for e in entries}
    pages = {s: f"problems/{s}.html" for s in stems}
    workbooks = {s: f"workbooks/{s}.ipynb" for s in stems}
    per_student: dict = {s.id: (dict(pages), dict(workbooks)) for s in roster}
    keep: set = set()
    for stem in stems:
        path = notebooks / f"{stem}.ipynb"
        source = nbformat.read(path, as_version=4)
        spec = Spec.from_notebook(source)
        nid = next((n for n, nk in key.notebooks.items() if stem.startswith(n) or n == stem), None)
        if spec is None or nid is None:
            continue
        nk = key.notebooks[nid]
        executed, problems_nb = by_stem[stem]["executed"], by_stem[stem]["problems"]
        groups = answer_groups(source)
        shared = {c.get("id") for c in by_stem[stem]["workbook"].cells}
        pictures = {i for i, c in enumerate(source.cells) if cell_reveals(c) and c.get("id") in shared}
        title = by_stem[stem]["title"]
        old = previous.notebooks.get(nid) if previous is not None else None
        lent = old is not None and old.sha == nk.sha and by_stem[stem].get("reused", False)
        for vk, v in nk.variants.items():
            page, wb = f"variant-pages/{stem}-{vk}.html", f"variant-workbooks/{stem}-{vk}.ipynb"
            keep.update({page, wb})
            if not lent or not (out / page).exists() or not (out / wb).exists():
                problems = _variant_problems(problems_nb, executed, spec, v.values, v.outputs)
                export_html(problems, out / page, urls, title=f"{title} (problems)", problems=True, links=())
                workbook = make_workbook(apply(source, spec, v.values), groups, _fingerprints(v), pictures)
                (out / wb).parent.mkdir(parents=True, exist_ok=True)
                nbformat.write(workbook, out / wb)
        for sid, vk in nk.students.items():
            per_student[sid][0][stem] = f"variant-pages/{stem}-{vk}.html"
            per_student[sid][1][stem] = f"variant-workbooks/{stem}-{vk}.ipynb"
    for folder in ("variant-pages", "variant-workbooks"):  # variants no student has any more
        for f in (out / folder).glob("*") if (out / folder).is_dir() else []:
            if f"{folder}/{f.name}" not in keep and any(f.name.startswith(s + "-") for s in stems):
                f.unlink()
    titles = {e["stem"]: e["title"] for e in entries}
    (inst / "answers").mkdir(parents=True, exist_ok=True)
    with open(inst / "links.csv", "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["id", "name", "token", "index"])
        for s in roster:
            token = student_token(secret, s.id)
            d = out / "students" / token
            d.mkdir(parents=True, exist_ok=True)
            p, wbs = per_student[s.id]
            (d / "index.html").write_text(_student_index(s, titles, p, wbs, lite))
            w.writerow([s.id, s.name, token, f"students/{token}/index.html"])
            (inst / "answers" / f"{s.id}.html").write_text(_answer_sheet(s, key, None))
    report = [f"kinlib handouts --variants {Path(roster_path).name}: {len(roster)} students"]
    for nid, st in key.stats().items():
        report.append(
            f"{nid}: {st['students']} students, {st['variants']} distinct variants, every one proved well-posed; "
            f"{st['rejected']} of {st['drawn']} draws rejected ({st['seconds']} s)"
        )
        report += [f"  rejected {n}x: {why}" for why, n in sorted(st["reasons"].items(), key=lambda kv: -kv[1])]
    (inst / "report.txt").write_text("\n".join(report) + "\n")
    log(
        f"  variants: {len(roster)} students' pages and workbooks in {time.perf_counter() - t0:.1f} s "
        f"(key, report, links and answer sheets in {inst})"
    )
    return key
