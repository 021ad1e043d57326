"""The checker's outputs: ``grades.csv``, one feedback page per submission, and the summary table.

They read the per-submission results :func:`kinlib.course.grade.grade_submission` returns (plain dicts,
``rows`` as dicts), so they can be written again from saved results.
"""

from __future__ import annotations

import csv
import re
from pathlib import Path

__all__ = ["feedback_markdown", "cell_text", "write_outputs", "summary_table"]


def _md(s) -> str:
    return str(s).replace("|", "\\|").replace("\n", " ").replace("<", "&lt;")


def feedback_markdown(res: dict) -> str:
    """The feedback page (Markdown) for one submission's result.

    >>> res = {"submission": "ann.ipynb", "notebook": "02_planar", "rows": [
    ...     {"part": "2.1", "points": 5, "max_points": 5, "status": "pass", "message": ""}]}
    >>> print(feedback_markdown(res).splitlines()[4])
    **Score: 5 / 5 points**
    """
    rows = res["rows"]
    got = sum(r["points"] for r in rows)
    mx = sum(r.get("max_points", 0) for r in rows)
    lines = [
        f"# Feedback: {res.get('title') or res.get('notebook') or 'submission'}",
        "",
        f"Submission `{res['submission']}`" + (f" (notebook `{res['notebook']}`)" if res.get("notebook") else ""),
        "",
        f"**Score: {got:g} / {mx:g} points**",
        "",
        "| Part | Points | Result | Feedback |",
        "|---|---|---|---|",
    ]
    for r in rows:
        lines.append(
            f"| {_md(r['part'])} | {r['points']:g} / {r.get('max_points', 0):g} | {r['status']} | {_md(r['message'])} |"
        )
    bad = [c for c in res.get("cells", []) if c["status"] != "ok"]
    if bad or res.get("restarts"):
        lines += ["", "## Cells that did not run cleanly", ""]
        for c in bad:
            what = cell_text(c)
            part = f" (part {c['part']})" if c.get("part") else ""
            lines.append(f"- code cell {c['index'] + 1}{part}: {_md(what)}")
        if res.get("restarts"):
            lines.append(
                f"- the kernel was restarted {res['restarts']} time(s); the cells that stopped it were skipped"
            )
    if res.get("restored") and isinstance(res["restored"], list):
        names = ", ".join(f"`{n}`" for n in res["restored"][:8]) + (" …" if len(res["restored"]) > 8 else "")
        lines += [
            "",
            f"Your notebook replaced {names}; the checker put the originals back before reading your answers.",
        ]
    if res.get("output_bytes", 0) > 1_000_000:
        lines.append(f"- your notebook printed {res['output_bytes'] / 1e6:.1f} MB of output (not kept)")
    lines += [
        "",
        "How this was checked: your notebook ran top to bottom in a fresh Python kernel; each answer "
        "was evaluated at random joint angles and link lengths and compared with the solution's values "
        "there (matrices entry by entry, subspaces by their span, sets of configurations by their "
        "members, angles modulo 2π, choices as sets). A part passes when every answer in it matches.",
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


def write_outputs(out: Path, results: list) -> None:
    """Write ``out/grades.csv`` and ``out/feedback/<submission>.md``; sets each result's ``feedback`` path.

    >>> import tempfile
    >>> res = {"submission": "ann/hw 2.ipynb", "notebook": "02_planar", "rows": [
    ...     {"submission": "ann/hw 2.ipynb", "notebook": "02_planar", "part": "2.1", "status": "pass",
    ...      "points": 5, "max_points": 5, "message": ""}]}
    >>> with tempfile.TemporaryDirectory() as d:
    ...     write_outputs(Path(d), [res])
    ...     print(sorted(p.relative_to(d).as_posix() for p in Path(d).rglob("*")))
    ...     print((Path(d) / "grades.csv").read_text(), end="")
    ['feedback', 'feedback/ann_hw_2.md', 'grades.csv']
    submission,notebook,part,status,points,message
    ann/hw 2.ipynb,02_planar,2.1,pass,5,
    >>> Path(res["feedback"]).name
    'ann_hw_2.md'
    """
    out.mkdir(parents=True, exist_ok=True)
    fb = out / "feedback"
    fb.mkdir(exist_ok=True)
    with open(out / "grades.csv", "w", newline="") as f:
        w = csv.writer(f, lineterminator="\n")
        w.writerow(["submission", "notebook", "part", "status", "points", "message"])
        for res in results:
            for r in res["rows"]:
                w.writerow([r["submission"], r["notebook"], r["part"], r["status"], f"{r['points']:g}", r["message"]])
    used = set()
    for res in results:
        stem = re.sub(r"[^A-Za-z0-9_.-]+", "_", str(Path(res["submission"]).with_suffix("")))[:120] or "submission"
        name, k = stem, 2
        while name in used:
            name, k = f"{stem}-{k}", k + 1
        used.add(name)
        res["feedback"] = str(fb / f"{name}.md")
        (fb / f"{name}.md").write_text(feedback_markdown(res))


def summary_table(results: list, wall: float, t_ref: float, jobs: int) -> str:
    """The table printed at the end of a batch: one line per submission, pass rates per part, throughput.

    >>> summary_table([], 0.0, 0.0, 2)
    'kinlib grade: no submissions'
    """
    if not results:
        return "kinlib grade: no submissions"
    w = max(10, min(48, max(len(r["submission"]) for r in results)))
    nbw = max(8, min(30, max(len(r["notebook"] or "-") for r in results)))
    lines = [f"{'submission':<{w}}  {'notebook':<{nbw}}  {'score':>9}  pass fail error  seconds"]
    for r in results:
        rows = r["rows"]
        got = sum(x["points"] for x in rows)
        mx = sum(x.get("max_points", 0) for x in rows)
        c = {s: sum(1 for x in rows if x["status"] == s) for s in ("pass", "fail", "error")}
        lines.append(
            f"{r['submission'][:w]:<{w}}  {(r['notebook'] or '-')[:nbw]:<{nbw}}  {got:>4g}/{mx:<4g}  "
            f"{c['pass']:>4} {c['fail']:>4} {c['error']:>5}  {r['seconds']:7.1f}"
        )
    per_part: dict = {}
    for r in results:
        for x in r["rows"]:
            if x["part"] != "-":
                k = (x["notebook"], x["part"])
                per_part.setdefault(k, [0, 0])
                per_part[k][0] += x["status"] == "pass"
                per_part[k][1] += 1
    if per_part:
        lines.append("")
        lines.append(
            "pass rate per part: " + ", ".join(f"{nb[:2]} {p}: {a}/{b}" for (nb, p), (a, b) in sorted(per_part.items()))
        )
    n = len(results)
    graded = wall - t_ref
    lines.append(
        f"{n} submission(s) in {wall:.1f} s ({t_ref:.1f} s for references), --jobs {jobs}: "
        f"{60 * n / max(graded, 1e-9):.1f} submissions/minute"
    )
    return "\n".join(lines)
