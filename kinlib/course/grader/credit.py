"""Course credit: points per answer (partial credit), manual rows, instructor overrides, student ids, totals.

The grader (:func:`kinlib.course.grader.grade.grade_submission`) judges each answer pass/fail/error; this module
turns those verdicts into points, the way the solution notebook's ``kinlib`` cell metadata declares them
(read by :func:`kinlib.course.schema.parse_parts`):

* **Points per answer.** A part is worth its question's "(N points)" (or the cell's ``points``). Work graded
  by hand, ``manual`` ({label: points}, e.g. ``{"drawing": 5}``), takes its points off the top; the rest is
  shared by the part's answers: ``answer_points`` ({name: points}) where declared, and what remains split
  **evenly** between the answers not declared (the default when nothing is declared: N / number of answers).
  A part's score is the sum of the points of the answers that pass. Example: 4.1 is 10 points over 6 answers.
* **Manual rows.** Each manual item is its own row (``kind`` "manual", status ``pending``, 0 points, its
  maximum), so a section's maximum adds up (section 5: 25 points, 5.2's drawing included) and the total says
  what is still pending. An override gives it a score (status ``graded``).
* **Overrides** (``--overrides FILE``, CSV or TOML): ``student_id, part, score, comment`` (``notebook``
  optional). ``part`` is "5.2" (the part's only row), "4.1/joint_c" (one answer of an automatic part: its
  points are replaced and the part's score recomputed) or "5.2/drawing" (a manual item). An override beats
  the automatic score; its comment is shown in the feedback; an empty score only adds the comment.
* **Student ids** come from the submission's path relative to the submissions root
  (:func:`kinlib.course.grader.intake.student_id`): by default that path without ``.ipynb``; with ``--id-pattern``,
  the regular expression matched from the start of it (the group named ``id``, else group 1, else the whole
  match). Examples: Canvas downloads ``doejane_12345_678_ps4.ipynb`` (12345: the Canvas user id,
  the ``ID`` column of a Canvas gradebook) → ``[^/_]+_(?:LATE_|late_)?(?P<id>\\d+)_\\d+_[^/]*$``; one folder per
  student ``ann/ps4.ipynb`` → ``([^/]+)/[^/]+$``.
"""

from __future__ import annotations

import csv
from dataclasses import dataclass
from fractions import Fraction
from pathlib import Path

__all__ = [
    "answer_max",
    "manual_items",
    "check_part_points",
    "score_parts",
    "Override",
    "load_overrides",
    "apply_overrides",
    "result_totals",
]


def _frac(x) -> Fraction:
    return Fraction(str(float(x))) if not isinstance(x, Fraction) else x


def _num(x: Fraction) -> float:
    return round(float(x), 6)


def manual_items(part: dict) -> dict:
    """{label: points} of a part's work graded by hand (``manual`` of its metadata), as Fractions.

    >>> manual_items({"part": "5.2", "points": 5.0, "answers": [], "manual": {"drawing": 5.0}})
    {'drawing': Fraction(5, 1)}
    >>> manual_items({"part": "2.1", "points": 5.0, "answers": ["M"]})
    {}
    """
    return {str(k): _frac(v) for k, v in (part.get("manual") or {}).items()}


def answer_max(part: dict) -> dict:
    """{answer: points} within a part: declared ``answer_points``, the rest of the part's points (after its
    manual items) split evenly between the other answers. Exact (Fractions), so the points add up.

    Score_part = Σ over passing answers of answer_max; with nothing declared each answer is worth N/k:

    >>> p = {"part": "4.1", "points": 10.0, "answers": ["J", "Jp", "c", "a", "b", "c3"]}
    >>> sum(answer_max(p).values()), answer_max(p)["J"]
    (Fraction(10, 1), Fraction(5, 3))
    >>> p = {"part": "5.5", "points": 5.0, "answers": ["d", "e"], "answer_points": {"d": 2}, "manual": {"proof": 2}}
    >>> {k: float(v) for k, v in answer_max(p).items()}   # 5 - 2 (proof) - 2 (d) = 1 left for e
    {'d': 2.0, 'e': 1.0}
    """
    names = list(part.get("answers") or [])
    declared = {n: _frac(v) for n, v in (part.get("answer_points") or {}).items() if n in names}
    pool = _frac(part.get("points") or 0) - sum(manual_items(part).values(), Fraction(0))
    rest = [n for n in names if n not in declared]
    left = max(pool - sum(declared.values(), Fraction(0)), Fraction(0))
    share = left / len(rest) if rest else Fraction(0)
    return {n: declared.get(n, share) for n in names}


def check_part_points(part: dict) -> list[str]:
    """Problems with a part's declared points (an empty list when they add up to the part's points).

    >>> check_part_points({"part": "4.1", "points": 10.0, "answers": ["a", "b"], "answer_points": {"a": 4, "b": 4}})
    ['4.1: the answers and manual items add up to 8, the part is worth 10']
    >>> check_part_points({"part": "4.1", "points": 10.0, "answers": ["a"], "answer_points": {"z": 1}})
    ["4.1: answer_points names z, which is not one of the part's answers ['a']"]
    """
    pid = part.get("part", "?")
    out = []
    names = list(part.get("answers") or [])
    for n in part.get("answer_points") or {}:
        if n not in names:
            out.append(f"{pid}: answer_points names {n}, which is not one of the part's answers {names}")
    total = sum(answer_max(part).values(), Fraction(0)) + sum(manual_items(part).values(), Fraction(0))
    if total != _frac(part.get("points") or 0) and not out:
        out.append(
            f"{pid}: the answers and manual items add up to {float(total):g}, "
            f"the part is worth {float(part.get('points') or 0):g}"
        )
    return out


def _verdicts(row: dict, names: list) -> dict:
    """{answer: (status, message)} from the grader's per-answer list, or from the part's status."""
    got = {a.get("answer"): a for a in row.get("answers") or [] if isinstance(a, dict)}
    out = {}
    for n in names:
        a = got.get(n)
        if a is not None:
            out[n] = (str(a.get("status", "fail")), str(a.get("message", "")))
        else:  # the grader said only pass/fail/error for the whole part
            out[n] = (row["status"], "")
    return out


def score_parts(result: dict, parts: list) -> dict:
    """Points per answer and manual rows for one graded submission (in place; returns it; idempotent).

    Each automatic row gets ``kind`` "auto", ``answers`` [{answer, status, points, max_points, message}],
    ``points`` = Σ points of its passing answers and ``max_points`` = the part's points less its manual
    items; each manual item becomes a row (``kind`` "manual", status "pending", ``answer`` its label):

    >>> parts = [{"part": "5.1", "points": 5.0, "answers": ["d", "s"], "answer_points": {"d": 2}},
    ...          {"part": "5.2", "points": 5.0, "answers": [], "manual": {"drawing": 5}}]
    >>> res = {"submission": "ann.ipynb", "notebook": "05", "rows": [
    ...     {"submission": "ann.ipynb", "notebook": "05", "part": "5.1", "status": "fail", "points": 0,
    ...      "max_points": 5, "message": "s: wrong", "answers": [{"answer": "d", "status": "pass"},
    ...                                                      {"answer": "s", "status": "fail"}]},
    ...     {"submission": "ann.ipynb", "notebook": "05", "part": "5.2", "status": "pass", "points": 5,
    ...      "max_points": 5, "message": ""}]}
    >>> [(r["part"], r["kind"], r["status"], r["points"], r["max_points"]) for r in score_parts(res, parts)["rows"]]
    [('5.1', 'auto', 'fail', 2.0, 5.0), ('5.2', 'manual', 'pending', 0.0, 5.0)]
    """
    if result.get("credit") == "scored":
        return result
    by_id = {str(p.get("part")): p for p in parts or []}
    graded = [r for r in result.get("rows", []) if str(r.get("part")) in by_id]
    if not graded:  # not one of this reference's submissions (not a notebook, unknown id): as it is
        for r in result.get("rows", []):
            r.setdefault("kind", "auto")
            r.setdefault("answer", "")
        result["credit"] = "scored"
        return result
    rows = []
    for r in result.get("rows", []):
        if str(r.get("part")) not in by_id:
            r.setdefault("kind", "auto")
            r.setdefault("answer", "")
            rows.append(r)
    like = graded[0]
    for pid, p in by_id.items():
        names = list(p.get("answers") or [])
        for r in (x for x in graded if str(x.get("part")) == pid) if names else ():
            amax = answer_max(p)
            verdicts = _verdicts(r, names)
            per = []
            for n in names:
                st, msg = verdicts[n]
                per.append(
                    {
                        "answer": n,
                        "status": st,
                        "points": _num(amax[n] if st == "pass" else 0),
                        "max_points": _num(amax[n]),
                        "message": msg,
                    }
                )
            got = sum((amax[n] for n in names if verdicts[n][0] == "pass"), Fraction(0))
            r.update(
                kind="auto",
                answer=r.get("answer", ""),
                answers=per,
                points=_num(got),
                max_points=_num(sum(amax.values(), Fraction(0))),
            )
            rows.append(r)
        for label, pts in manual_items(p).items():
            rows.append(_manual_row(like, pid, label, pts))
    result["rows"] = rows
    result["credit"] = "scored"
    return result


def _manual_row(like: dict, part: str, label: str, pts: Fraction) -> dict:
    return {
        "submission": like.get("submission", ""),
        "notebook": like.get("notebook", ""),
        "part": part,
        "answer": label,
        "kind": "manual",
        "status": "pending",
        "points": 0.0,
        "max_points": _num(pts),
        "message": f"{label}: graded by hand (pending)",
    }


# ----------------------------------------------------------------------------------------- overrides


@dataclass
class Override:
    """One line of an instructor's overrides file.

    >>> Override("ann", "5.2/drawing", 4.0, "neat", source="overrides.csv:2").item
    'drawing'
    """

    student_id: str
    part: str  # "5.2", "4.1/joint_c" or "5.2/drawing"
    score: float | None
    comment: str = ""
    notebook: str = ""
    source: str = ""

    @property
    def part_id(self) -> str:
        return self.part.split("/", 1)[0].strip()

    @property
    def item(self) -> str:
        return self.part.split("/", 1)[1].strip() if "/" in self.part else ""


def _score(value, where: str):
    if value is None or (isinstance(value, str) and not value.strip()):
        return None
    if isinstance(value, bool):
        raise ValueError(f"{where}: score must be a number, got {value!r}")
    try:
        x = float(value)
    except (TypeError, ValueError):
        raise ValueError(f"{where}: score must be a number, got {value!r}") from None
    if not (x == x and abs(x) != float("inf")) or x < 0:
        raise ValueError(f"{where}: score must be a finite number ≥ 0, got {value!r}")
    return x


def load_overrides(path) -> list[Override]:
    """Read an overrides file: CSV (header ``student_id,part,score,comment[,notebook]``; ``student`` is accepted
    for ``student_id``) or TOML (``[[override]]`` tables with the same keys). Raises ValueError naming the
    file and line for a bad row.

    >>> import tempfile, os
    >>> with tempfile.TemporaryDirectory() as d:
    ...     f = Path(d) / "o.csv"
    ...     _ = f.write_text("student_id,part,score,comment\\nann,5.2/drawing,4,two poses; one mislabelled\\n")
    ...     [(o.student_id, o.part_id, o.item, o.score, o.comment) for o in load_overrides(f)]
    [('ann', '5.2', 'drawing', 4.0, 'two poses; one mislabelled')]
    """
    path = Path(path)
    rows: list = []
    if path.suffix.lower() == ".toml":
        import tomllib

        try:
            data = tomllib.loads(path.read_text(encoding="utf-8"))
        except tomllib.TOMLDecodeError as exc:
            raise ValueError(f"{path}: not valid TOML ({exc})") from None
        items = data.get("override", data.get("overrides", []))
        if not isinstance(items, list):
            raise ValueError(f"{path}: expected [[override]] tables")
        rows = [(f"{path}:override #{k}", d) for k, d in enumerate(items, 1)]
    else:
        with open(path, newline="", encoding="utf-8-sig") as f:
            reader = csv.DictReader(f)
            fields = {(h or "").strip().lower() for h in reader.fieldnames or []}
            if not ({"student_id", "student"} & fields and "part" in fields):
                raise ValueError(
                    f"{path}: the header must name student_id, part, score, comment (got {sorted(fields)})"
                )
            rows = [
                (f"{path}:{k}", {(a or "").strip().lower(): (b or "").strip() for a, b in d.items() if a})
                for k, d in enumerate(reader, 2)
            ]
    out = []
    for where, d in rows:
        if not isinstance(d, dict):
            raise ValueError(f"{where}: expected a table of student_id, part, score, comment")
        sid = str(d.get("student_id", d.get("student", "")) or "").strip()
        part = str(d.get("part", "") or "").strip()
        if not sid or not part:
            raise ValueError(f"{where}: student_id and part are required, got {sid!r} and {part!r}")
        score = _score(d.get("score"), where)
        comment = str(d.get("comment", "") or "").strip()
        if score is None and not comment:
            raise ValueError(f"{where}: give a score, a comment or both")
        out.append(Override(sid, part, score, comment, str(d.get("notebook", "") or "").strip(), where))
    return out


def apply_overrides(results: list, overrides: list) -> list[str]:
    """Merge overrides into graded results (in place): scores replace points (the automatic score is kept in
    ``auto_points``), comments go to the row's ``comment``. Returns warnings for overrides that match no row
    of these results' students. Raises ValueError for a score above the row's (or answer's) maximum, or a
    part with several rows addressed without ``/item``.

    >>> res = [{"student_id": "ann", "notebook": "05", "rows": [
    ...     {"part": "5.2", "answer": "drawing", "kind": "manual", "status": "pending", "points": 0.0,
    ...      "max_points": 5.0, "message": "drawing: graded by hand (pending)"}]}]
    >>> apply_overrides(res, [Override("ann", "5.2", 4, "neat"), Override("bob", "5.1", 1)])
    ['bob 5.1 (): no such student in these results']
    >>> r = res[0]["rows"][0]; (r["status"], r["points"], r["comment"])
    ('graded', 4.0, 'neat')
    """
    warnings = []
    by_student: dict = {}
    for res in results:
        by_student.setdefault(res.get("student_id", ""), []).append(res)
    for o in overrides:
        cands = [res for res in by_student.get(o.student_id, []) if not o.notebook or res.get("notebook") == o.notebook]
        if not cands:
            warnings.append(f"{o.student_id} {o.part} ({o.source}): no such student in these results")
            continue
        hits = []
        for res in cands:
            rows = [r for r in res["rows"] if str(r.get("part")) == o.part_id]
            if o.item:
                exact = [r for r in rows if r.get("answer") == o.item]
                inner = [r for r in rows if any(a.get("answer") == o.item for a in r.get("answers") or [])]
                rows = exact or inner
            hits += [(res, r) for r in rows]
        if not hits:
            warnings.append(f"{o.student_id} {o.part} ({o.source}): no such part in their results")
            continue
        if len(hits) > 1:
            labels = sorted({f"{r['part']}/{r.get('answer') or '…'}" for _, r in hits})
            raise ValueError(
                f"{o.source}: {o.student_id} {o.part} matches several rows ({', '.join(labels)}): "
                "name one (part/answer) or give the notebook"
            )
        _apply(hits[0][1], o)
    return warnings


def _apply(row: dict, o: Override) -> None:
    if o.comment:
        row["comment"] = "; ".join(x for x in (row.get("comment", ""), o.comment) if x)
    if o.score is None:
        return
    inner = [
        a for a in row.get("answers") or [] if o.item and a.get("answer") == o.item and row.get("answer") != o.item
    ]
    if inner:
        a = inner[0]
        if o.score > a["max_points"] + 1e-9:
            raise ValueError(f"{o.source}: {o.part} score {o.score:g} is above its {a['max_points']:g} points")
        row.setdefault("auto_points", row["points"])
        a["points"], a["override"] = o.score, True
        row["points"] = _num(sum((_frac(x["points"]) for x in row["answers"]), Fraction(0)))
    else:
        if o.score > row.get("max_points", 0) + 1e-9:
            raise ValueError(f"{o.source}: {o.part} score {o.score:g} is above its {row.get('max_points', 0):g} points")
        row.setdefault("auto_points", row["points"])
        row["points"] = float(o.score)
    row["override"] = True
    if row.get("kind") == "manual":
        row["status"] = "graded"
        row["message"] = f"{row.get('answer') or row['part']}: graded by hand"


def result_totals(rows: list) -> dict:
    """{"points", "max_points", "pending": [labels of manual rows without a score]} of some rows.

    >>> result_totals([{"part": "5.1", "points": 2.0, "max_points": 5.0, "status": "fail"},
    ...                {"part": "5.2", "answer": "drawing", "points": 0.0, "max_points": 5.0, "status": "pending"}])
    {'points': 2.0, 'max_points': 10.0, 'pending': ['5.2/drawing']}
    """
    pts = sum((_frac(r.get("points") or 0) for r in rows), Fraction(0))
    mx = sum((_frac(r.get("max_points") or 0) for r in rows), Fraction(0))
    pending = [
        f"{r['part']}/{r.get('answer')}" if r.get("answer") else str(r["part"])
        for r in rows
        if r.get("status") == "pending"
    ]
    return {"points": _num(pts), "max_points": _num(mx), "pending": pending}
