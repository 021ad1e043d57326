"""The checker's outputs: ``grades.csv``, ``totals.csv``, one feedback page per submission, the summary table.

They read the per-submission results :func:`kinlib.course.grader.grade.grade_submission` returns (plain dicts,
``rows`` as dicts, scored per answer by :func:`kinlib.course.grader.credit.score_parts`).

The class folder (``--out``) keeps every graded submission's result as ``results/<key>.json`` (key: the
student id and the notebook), and ``grades.csv``, ``totals.csv`` and ``feedback/`` are written from all of
them, so **grading one student again replaces only that student's result**: every other row of the class
files stays byte for byte the same. Files are written atomically (a temporary file, then a rename). The
student id pattern is remembered in ``OUT/class.json`` (a later run without ``--id-pattern`` uses it; a new
pattern re-keys every kept result from its stored path).
Overrides (:mod:`kinlib.course.grader.credit`) are applied each time from ``--overrides`` or, when it is not
given, from ``OUT/overrides.toml`` / ``OUT/overrides.csv`` if present; the stored results stay automatic.

``grades.csv`` columns: student_id, submission, notebook, part, answer (a manual item's label), kind
(auto | manual), status (pass | fail | error for automatic rows; pending | graded for manual ones),
points (empty while pending), max_points, message, comment (the instructor's), student_total,
student_max, student_pending (the student's totals over all their notebooks, and what is still to grade).
"""

from __future__ import annotations

import copy
import csv
import io
import json
import os
import re
import tempfile
import unicodedata
from pathlib import Path

from . import credit
from .intake import file_key, student_id

__all__ = [
    "COLUMNS",
    "feedback_markdown",
    "cell_text",
    "write_outputs",
    "summary_table",
    "load_results",
    "result_key",
    "atomic_write",
    "student_totals",
    "default_overrides",
    "csv_cell",
    "csv_text",
    "md_text",
    "md_code",
    "printable",
]

COLUMNS = [
    "student_id",
    "submission",
    "notebook",
    "part",
    "answer",
    "kind",
    "status",
    "points",
    "max_points",
    "message",
    "comment",
    "student_total",
    "student_max",
    "student_pending",
]


_MD_SPECIAL = re.compile(r"([\\`*_\[\]<>!|~&@])")
_AUTOLINK = re.compile(r"(?i)(?<=\w)(:)(?=//)|(?<=www)(\.)")
_IDENT = re.compile(r"[A-Za-z_][A-Za-z0-9_]{0,79}")


def printable(s) -> str:
    r"""``s`` without anything a terminal would act on: control and format characters (escape sequences,
    carriage returns, bidirectional overrides) are shown as ``\x..``/``\u....`` escapes.

    >>> print(printable("ann\x1b[2J\rbob\u202e"))
    ann\x1b[2J\rbob\u202e
    """
    out = []
    for ch in str(s):
        if unicodedata.category(ch) in ("Cc", "Cf", "Zl", "Zp", "Cs", "Co", "Cn") and ch != " ":
            out.append(repr(ch)[1:-1] if ch.isascii() or ord(ch) < 0x100 else f"\\u{ord(ch):04x}")
        else:
            out.append(ch)
    return "".join(out)


def md_text(s) -> str:
    r"""Student-controlled text as inert Markdown: one line, every character that starts markup, HTML or an
    entity backslash-escaped (no raw HTML, no link, no image), autolinks (``http://``, ``www.``, e-mail)
    broken, control characters shown as escapes.

    >>> print(md_text("<img src=x onerror=alert(1)> [click](javascript:alert(1)) ![](http://evil/p.png) a|b"))
    \<img src=x onerror=alert(1)\> \[click\](javascript:alert(1)) \!\[\](http\://evil/p.png) a\|b
    """
    text = printable(" ".join(str(s).split("\n")))
    return _AUTOLINK.sub(lambda m: "\\" + (m.group(1) or m.group(2)), _MD_SPECIAL.sub(r"\\\1", text))


def md_code(s) -> str:
    r"""A name as inline code when it is a plain identifier, else as :func:`md_text`.

    >>> print(md_code("joint_c"), md_code("`x` <b>"))
    `joint_c` \`x\` \<b\>
    """
    s = str(s)
    return f"`{s}`" if _IDENT.fullmatch(s) else md_text(s)


def _md(s) -> str:
    return md_text(s)


def csv_cell(v) -> str:
    r"""One CSV cell: a number as a number (negative ones too), text neutralised by OWASP's rule (a cell that
    starts with ``=``, ``+``, ``-``, ``@``, a tab or a carriage return gets a leading ``'``, so a spreadsheet
    shows it instead of running it; a lone ``-``, the part of a whole-file error row, cannot run and stays).

    >>> [csv_cell(x) for x in (-1.5, 3, "=HYPERLINK(1)", "-2+3", "@SUM(A1)", "\tx", "ann", "")]
    ['-1.5', '3', "'=HYPERLINK(1)", "'-2+3", "'@SUM(A1)", "'\tx", 'ann', '']
    """
    if isinstance(v, (int, float)) and not isinstance(v, bool):
        return f"{float(v):g}"
    s = "" if v is None else str(v)
    return "'" + s if s[:1] in ("=", "+", "-", "@", "\t", "\r") and s != "-" else s


def _g(x) -> str:
    return f"{float(x or 0):g}"


def _label(r: dict) -> str:
    return f"{r['part']} ({r['answer']})" if r.get("answer") else str(r["part"])


def _feedback_parts(rows: list) -> list[str]:
    """The feedback's table of parts, and of points per answer for parts of several answers (Markdown lines)."""
    lines = ["| Part | Points | Result | Feedback |", "|---|---|---|---|"]
    for r in rows:
        pts = "–" if r.get("status") == "pending" else _g(r.get("points"))
        status = _md(r["status"]) + (" (override)" if r.get("override") else "")
        if r.get("kind") == "manual":
            status += ", graded by hand"
        msg = r.get("message", "")
        if r.get("comment"):
            msg = "; ".join(x for x in (msg, f"Instructor: {r['comment']}") if x)
        lines.append(f"| {_md(_label(r))} | {pts} / {_g(r.get('max_points'))} | {status} | {_md(msg)} |")
    multi = [r for r in rows if len(r.get("answers") or []) > 1]
    if multi:
        lines += ["", "## Points per answer", "", "| Part | Answer | Points | Result |", "|---|---|---|---|"]
        for r in multi:
            for a in r["answers"]:
                st = _md(a["status"]) + (" (override)" if a.get("override") else "")
                lines.append(
                    f"| {_md(r['part'])} | {md_code(a['answer'])} | {_g(a['points'])} / {_g(a['max_points'])} | {st} |"
                )
    return lines


def _feedback_cells(res: dict) -> list[str]:
    """The feedback's notes on the student's code: cells that did not run cleanly, restarts, what the checker put
    back, output too large to keep (Markdown lines)."""
    lines: list = []
    bad = [c for c in res.get("cells", []) if c["status"] != "ok"]
    if bad or res.get("restarts"):
        lines += ["", "## Cells that did not run cleanly", ""]
        for c in bad:
            what = cell_text(c)
            part = f" (part {_md(c['part'])})" if c.get("part") else ""
            lines.append(f"- code cell {c['index'] + 1}{part}: {_md(what)}")
        if res.get("restarts"):
            lines.append(
                f"- the kernel was restarted {res['restarts']} time(s); the cells that stopped it were skipped"
            )
    if res.get("restored") and isinstance(res["restored"], list):
        names = ", ".join(md_code(n) for n in res["restored"][:8]) + (" …" if len(res["restored"]) > 8 else "")
        lines += [
            "",
            f"Your notebook replaced {names}; the checker put the originals back before reading your answers.",
        ]
    if res.get("output_bytes", 0) > 1_000_000:
        lines.append(f"- your notebook printed {res['output_bytes'] / 1e6:.1f} MB of output (not kept)")
    if res.get("output_dropped", 0):
        n = res["output_dropped"]
        lines.append(f"- {n} output message(s) of your notebook were over the grader's size cap and were not read")
    return lines


def feedback_markdown(res: dict) -> str:
    """The feedback page (Markdown) for one submission's result.

    >>> res = {"submission": "ann.ipynb", "notebook": "02_planar", "rows": [
    ...     {"part": "2.1", "points": 5, "max_points": 5, "status": "pass", "message": ""}]}
    >>> print(feedback_markdown(res).splitlines()[4])
    **Score: 5 / 5 points**
    >>> res["rows"].append({"part": "2.5", "answer": "drawing", "kind": "manual", "status": "pending",
    ...                     "points": 0.0, "max_points": 5, "message": "drawing: graded by hand (pending)"})
    >>> print(feedback_markdown(res).splitlines()[4])
    **Score: 5 / 10 points** (pending: 2.5/drawing, 5 points graded by hand)
    """
    rows = res["rows"]
    tot = credit.result_totals(rows)
    pend = [r for r in rows if r.get("status") == "pending"]
    score = f"**Score: {_g(tot['points'])} / {_g(tot['max_points'])} points**"
    if pend:
        score += (
            f" (pending: {_md(', '.join(tot['pending']))}, {_g(sum(r.get('max_points', 0) for r in pend))} points "
            "graded by hand)"
        )
    lines = [
        f"# Feedback: {_md(res.get('title') or res.get('notebook') or 'submission')}",
        "",
        f"Submission {_md(res['submission'])}" + (f" (notebook {_md(res['notebook'])})" if res.get("notebook") else ""),
        "",
        score,
        "",
    ]
    notes = [str(n) for n in res.get("notes") or []]
    if res.get("sandbox") is False and not any("sandbox" in n for n in notes):
        notes.append("graded without the sandbox (--no-sandbox)")
    lines += [f"*Note: {_md(n)}.*" for n in notes] + ([""] if notes else [])
    lines += _feedback_parts(rows) + _feedback_cells(res)
    lines += [
        "",
        "How this was checked: your notebook ran top to bottom in a fresh Python kernel; each answer "
        "was evaluated at random joint angles and link lengths and compared with the solution's values "
        "there (matrices entry by entry, subspaces by their span, sets of configurations by their "
        "members, angles modulo 2π, choices as sets). Each answer that matches earns its share of its "
        "part's points; work marked *graded by hand* is scored by your instructor.",
        "",
    ]
    return "\n".join(lines)


def cell_text(c: dict) -> str:
    """What happened to a cell (a result's ``cells`` entry), in words.

    >>> cell_text({"status": "error", "ename": "NameError", "evalue": "J"}), cell_text({"status": "timeout"})
    ('raised NameError: J', 'timeout')
    """
    if c["status"] == "error":
        return f"raised {c['ename']}: {c['evalue']}".strip()
    return c.get("note") or c["status"]


# ----------------------------------------------------------------------------------------- class files


def result_key(res: dict) -> str:
    """The name a result is kept under in the class folder: student id and notebook (or the file's stem),
    each in :func:`kinlib.course.grader.intake.file_key`'s collision-free form (plain lower-case ids as they are,
    any other id as a slug plus a hash: ``王伟``, ``josé``/``josè``, ``Ann``/``ann`` never share a file).

    >>> result_key({"student_id": "ann", "notebook": "05_singularities_planar", "submission": "x/hw.ipynb"})
    'ann--05_singularities_planar'
    >>> result_key({"student_id": "bob lee", "notebook": "", "submission": "x/garbage.ipynb"})
    'bob_lee~482bc94ae4--garbage'
    """
    nb = res.get("notebook") or Path(str(res.get("submission", ""))).stem
    return f"{file_key(str(res.get('student_id') or 'unknown'))}--{file_key(nb)}"


def atomic_write(path: Path, text: str) -> bool:
    """Write ``text`` to ``path`` through a temporary file and a rename (readers never see half a file).
    Returns False (and writes nothing) when the file already holds exactly that text.

    >>> import tempfile
    >>> with tempfile.TemporaryDirectory() as d:
    ...     atomic_write(Path(d) / "a.txt", "x"), atomic_write(Path(d) / "a.txt", "x")
    (True, False)
    """
    path = Path(path)
    data = text.encode("utf-8")
    try:
        if path.read_bytes() == data:
            return False
    except OSError:
        pass
    path.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", dir=path.parent)
    try:
        with os.fdopen(fd, "wb") as f:
            f.write(data)
            f.flush()
            os.fsync(f.fileno())
        os.replace(tmp, path)
    except BaseException:
        Path(tmp).unlink(missing_ok=True)
        raise
    return True


def load_results(out: Path) -> list:
    """Every result kept in ``out/results/`` (sorted by key); unreadable files are skipped.

    >>> import tempfile
    >>> with tempfile.TemporaryDirectory() as d:
    ...     load_results(Path(d))
    []
    """
    found = []
    for p in sorted((Path(out) / "results").glob("*.json")):
        try:
            res = json.loads(p.read_text(encoding="utf-8"))
        except (OSError, ValueError):
            continue
        if isinstance(res, dict) and isinstance(res.get("rows"), list):
            found.append(res)
    return found


def student_totals(results: list) -> dict:
    """{student id: {"points", "max_points", "pending"}} over all of each student's results.

    >>> student_totals([{"student_id": "ann", "rows": [{"part": "1", "points": 2, "max_points": 5}]},
    ...                 {"student_id": "ann", "rows": [{"part": "2", "points": 1, "max_points": 5}]}])
    {'ann': {'points': 3.0, 'max_points': 10.0, 'pending': []}}
    """
    rows: dict = {}
    for res in results:
        rows.setdefault(res.get("student_id", ""), []).extend(res["rows"])
    return {sid: credit.result_totals(rs) for sid, rs in rows.items()}


def csv_text(rows: list) -> str:
    """CSV text of ``rows``, every cell through :func:`csv_cell` (numbers stay numbers, text is neutralised).

    >>> print(csv_text([["id", "points"], ["=cmd|' /C calc'!A0", -2.0]]), end="")
    id,points
    '=cmd|' /C calc'!A0,-2
    """
    buf = io.StringIO()
    w = csv.writer(buf, lineterminator="\n")
    quoted = csv.writer(buf, lineterminator="\n", quoting=csv.QUOTE_ALL)
    for r in rows:
        cells = [csv_cell(v) for v in r]
        # the csv module quotes a cell with "\n" but not one with a lone "\r", which readers take as a line end
        (quoted if any("\r" in c for c in cells) else w).writerow(cells)
    return buf.getvalue()


_csv = csv_text


def _num(x) -> float:
    return float(x or 0)


def _grades_csv(results: list, totals: dict) -> str:
    out = [COLUMNS]
    for res in results:
        sid = res.get("student_id", "")
        t = totals[sid]
        for r in res["rows"]:
            pending = r.get("status") == "pending"
            out.append(
                [
                    sid,
                    r.get("submission", res.get("submission", "")),
                    r.get("notebook", res.get("notebook", "")),
                    r["part"],
                    r.get("answer", ""),
                    r.get("kind", "auto"),
                    r["status"],
                    "" if pending else _num(r.get("points")),
                    _num(r.get("max_points")),
                    r.get("message", ""),
                    r.get("comment", ""),
                    _num(t["points"]),
                    _num(t["max_points"]),
                    " ".join(t["pending"]),
                ]
            )
    return _csv(out)


def _totals_csv(results: list, totals: dict) -> str:
    nbs: dict = {}
    for res in results:
        nbs.setdefault(res.get("student_id", ""), []).append(res.get("notebook") or res.get("submission", ""))
    out = [["student_id", "points", "max_points", "status", "pending", "notebooks"]]
    for sid in sorted(totals):
        t = totals[sid]
        out.append(
            [
                sid,
                _num(t["points"]),
                _num(t["max_points"]),
                "pending" if t["pending"] else "complete",
                " ".join(t["pending"]),
                " ".join(nbs.get(sid, [])),
            ]
        )
    return _csv(out)


def _key_results(kept: list, new: list, pattern) -> tuple:
    """{key: result}: student ids from the stored paths (so a new pattern re-keys everyone); a new result replaces
    the kept one of the same student and notebook. Results that still share a key (two files of one batch with
    the same id) are all kept, the 2nd, 3rd, ... (by path) with the id suffixed "-2", "-3", and a warning."""
    groups: dict = {}
    warnings = []
    for res in [*kept, *new]:
        if res.get("relpath"):
            res["student_id"], why = student_id(res["relpath"], pattern)
        else:  # kept by an older kinlib: its id as that version read it (the pattern searched in the whole path)
            res["student_id"], why = _legacy_id(str(res.get("path") or res["submission"]), pattern), ""
        if why:
            warnings.append(why)
        for r in res["rows"]:
            r.setdefault("kind", "auto")
            r.setdefault("answer", "")
        groups.setdefault(result_key(res), []).append(res)
    table = {}
    fresh = {id(r) for r in new}
    for key, group in groups.items():
        newer = [r for r in group if id(r) in fresh]
        group = sorted(newer or group, key=lambda r: str(r.get("path") or r["submission"]))
        table[key] = group[0]
        k = 1
        for res in group[1:]:
            sid = res["student_id"]
            while True:  # a suffixed id that no other result has
                k += 1
                res["student_id"] = f"{sid}-{k}"
                if result_key(res) not in groups and result_key(res) not in table:
                    break
            table[result_key(res)] = res
            warnings.append(
                f"{res.get('path') or res['submission']} has the same student id {sid!r} as "
                f"{group[0].get('path') or group[0]['submission']}: kept as {res['student_id']!r}; "
                "give --id-pattern (one folder per student: '([^/]+)/[^/]+$')"
            )
    return table, warnings


def _legacy_id(path: str, pattern) -> str:
    """The id of a result kept without ``relpath`` (an older kinlib): ``pattern`` searched in its absolute path,
    else the file's stem.

    >>> _legacy_id("/class/ann/ps4.ipynb", r"([^/]+)/[^/]+$"), _legacy_id("/class/ann/ps4.ipynb", None)
    ('ann', 'ps4')
    """
    m = re.search(pattern, path) if pattern else None
    if m:
        got = m.groupdict().get("id") if "id" in m.re.groupindex else (m.group(1) if m.re.groups else m.group(0))
        if got:
            return got
    return Path(path).stem or path


def remembered_root(out: Path) -> list:
    """The submissions roots remembered in ``out/class.json`` (files graded again alone are read relative to
    them), most recent first.

    >>> remembered_root(Path("/nonexistent"))
    []
    """
    roots = _read_settings(out).get("roots")
    return [str(r) for r in roots if isinstance(r, str)] if isinstance(roots, list) else []


def remembered_pattern(out: Path):
    """The ``--id-pattern`` remembered in ``out/class.json`` (None if none).

    >>> remembered_pattern(Path("/nonexistent")) is None
    True
    """
    p = _read_settings(out).get("id_pattern")
    return p if isinstance(p, str) else None


def _read_settings(out: Path) -> dict:
    try:
        d = json.loads((Path(out) / "class.json").read_text())
    except (OSError, ValueError):
        return {}
    return d if isinstance(d, dict) else {}


def default_overrides(out: Path):
    """``out/overrides.toml`` or ``out/overrides.csv`` if present, else None.

    >>> default_overrides(Path("/nonexistent"))
    """
    for name in ("overrides.toml", "overrides.csv"):
        if (out / name).is_file():
            return out / name
    return None


def write_outputs(
    out: Path, results: list, id_pattern=None, overrides=None, merge: bool = True, log=None, roots=()
) -> list:
    """Keep ``results`` in the class folder ``out`` and write ``grades.csv``, ``totals.csv`` and
    ``feedback/<key>.md`` from every result kept there; sets each result's ``student_id`` and ``feedback``.

    ``id_pattern``: :func:`kinlib.course.grader.intake.student_id`'s pattern, matched from the start of the
    submission's path relative to its submissions root (``res["relpath"]``; default: that path without
    ``.ipynb``); ``roots``: the batch's submissions roots (remembered in ``class.json``). ``overrides``: a path
    or a list of :class:`kinlib.course.grader.credit.Override` (default:
    ``out/overrides.toml`` or ``out/overrides.csv`` if present). ``merge=False`` forgets the results kept
    before. Returns the overrides' warnings (a ValueError is raised for a bad override, before writing).

    >>> import tempfile
    >>> res = {"submission": "ann/hw 2.ipynb", "relpath": "ann/hw 2.ipynb", "notebook": "02_planar", "rows": [
    ...     {"submission": "ann/hw 2.ipynb", "notebook": "02_planar", "part": "2.1", "status": "pass",
    ...      "points": 5, "max_points": 5, "message": ""}]}
    >>> with tempfile.TemporaryDirectory() as d:
    ...     write_outputs(Path(d), [res], id_pattern=r"([^/]+)/")
    ...     print(sorted(p.relative_to(d).as_posix() for p in Path(d).rglob("*")))
    ...     print((Path(d) / "grades.csv").read_text(), end="")
    []
    ['class.json', 'feedback', 'feedback/ann--02_planar.md', 'grades.csv', 'results', 'results/ann--02_planar.json', 'totals.csv']
    student_id,submission,notebook,part,answer,kind,status,points,max_points,message,comment,student_total,student_max,student_pending
    ann,ann/hw 2.ipynb,02_planar,2.1,,auto,pass,5,5,,,5,5,
    >>> Path(res["feedback"]).name
    'ann--02_planar.md'
    """
    out = Path(out)
    log = log or (lambda s: None)
    fb = out / "feedback"
    store = out / "results"
    settings = _read_settings(out)
    pattern = id_pattern if id_pattern is not None else settings.get("id_pattern")
    if overrides is None:
        overrides = default_overrides(out)
        if overrides is not None:
            log(f"using the overrides in {overrides}")
    if overrides is not None and not isinstance(overrides, list):
        overrides = credit.load_overrides(overrides)
    kept = load_results(out) if merge else []
    if merge and not kept and (out / "grades.csv").exists():
        log(f"note: {out / 'grades.csv'} has no kept results (written by an older kinlib): it is replaced")
    table, clashes = _key_results(kept, results, pattern)
    final = copy.deepcopy([table[k] for k in sorted(table)])
    warnings = clashes + credit.apply_overrides(final, overrides or [])  # raises for a bad override: nothing written
    for key, res in table.items():  # the raw (automatic) results, not the overridden ones
        atomic_write(store / f"{key}.json", json.dumps(res, sort_keys=True, indent=1) + "\n")
    for p in store.glob("*.json"):
        if p.stem not in table:
            p.unlink()
    known = [getattr(r, "root", r) for r in roots] + remembered_root(out)
    settings = {"id_pattern": pattern, "roots": list(dict.fromkeys(str(r) for r in known))[:20]}
    atomic_write(out / "class.json", json.dumps(settings, indent=1, ensure_ascii=False) + "\n")
    totals = student_totals(final)
    fb.mkdir(parents=True, exist_ok=True)
    for res in final:
        atomic_write(fb / f"{result_key(res)}.md", feedback_markdown(res))
    for p in fb.glob("*--*.md"):  # pages of results no longer kept (another id pattern, --fresh)
        if p.stem not in table:
            p.unlink()
    atomic_write(out / "grades.csv", _grades_csv(final, totals))
    atomic_write(out / "totals.csv", _totals_csv(final, totals))
    for res in results:
        res["feedback"] = str(fb / f"{result_key(res)}.md")
    for w in warnings:
        log(f"warning: {printable(w)}")
    return warnings


def summary_table(results: list, wall: float, t_ref: float, jobs: int) -> str:
    """The table printed at the end of a batch: one line per submission, pass rates per part, throughput.

    >>> summary_table([], 0.0, 0.0, 2)
    'kinlib grade: no submissions'
    """
    if not results:
        return "kinlib grade: no submissions"
    names = {id(r): (printable(r["submission"]), printable(r["notebook"] or "-")) for r in results}
    w = max(10, min(48, max(len(n[0]) for n in names.values())))
    nbw = max(8, min(30, max(len(n[1]) for n in names.values())))
    lines = [f"{'submission':<{w}}  {'notebook':<{nbw}}  {'score':>9}  pass fail error pending  seconds"]
    for r in results:
        rows = r["rows"]
        t = credit.result_totals(rows)
        c = {s: sum(1 for x in rows if x["status"] == s) for s in ("pass", "fail", "error", "pending")}
        lines.append(
            f"{names[id(r)][0][:w]:<{w}}  {names[id(r)][1][:nbw]:<{nbw}}  "
            f"{t['points']:>4g}/{t['max_points']:<4g}  "
            f"{c['pass']:>4} {c['fail']:>4} {c['error']:>5} {c['pending']:>7}  {r.get('seconds', 0.0):7.1f}"
        )
    per_part: dict = {}
    for r in results:
        for x in r["rows"]:
            if x["part"] != "-" and x.get("kind", "auto") == "auto":
                k = (x["notebook"], x["part"])
                per_part.setdefault(k, [0, 0])
                per_part[k][0] += x["status"] == "pass"
                per_part[k][1] += 1
    if per_part:
        lines.append("")
        lines.append(
            "pass rate per part: " + ", ".join(f"{nb[:2]} {p}: {a}/{b}" for (nb, p), (a, b) in sorted(per_part.items()))
        )
    if any(r.get("sandbox") is False for r in results):
        lines.append("graded WITHOUT the sandbox (--no-sandbox)")
    n = len(results)
    graded = wall - t_ref
    lines.append(
        f"{n} submission(s) in {wall:.1f} s ({t_ref:.1f} s for references), --jobs {jobs}: "
        f"{60 * n / max(graded, 1e-9):.1f} submissions/minute"
    )
    return "\n".join(printable(line) for line in lines)
