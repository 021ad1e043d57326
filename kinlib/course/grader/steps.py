"""Grading one submission once its notebook is read: a list of named steps (as nbgrader's autograde
preprocessors), each a small function of one :class:`Grading` state.

=========== =============================================================================================
``execute``  run every code cell in the sandboxed kernel (:class:`~.isolation.kernel.NotebookRun`)
``restore``  put back what the notebook replaced in SymPy, NumPy, mpmath, builtins (``in_kernel.guard``)
``export``   ask the kernel for each answer *as data* (``in_kernel.export``): no point, seed or reference
             is ever sent to the kernel
``stop``     stop the kernel: nothing it does from here on can change a grade
``judge``    read, evaluate at the secret points, compare and check exactly, in the submission's judge
             process (:class:`~.judging.JudgeProcess`: killed past the time limit of an answer)
``rows``     one :class:`Row` per part, from the answers' :class:`~.judge.Verdict`
=========== =============================================================================================

:func:`run_steps` runs them in order and records each step's wall time in ``out["timing"]``.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field

from .isolation.kernel import KernelStartError, NotebookRun
from .judge import Verdict

__all__ = ["Grading", "Row", "STEPS", "run_steps", "EXPORT_TIMEOUT"]

EXPORT_TIMEOUT = 20.0  # seconds for the kernel to write one answer's data


@dataclass
class Row:
    """One line of grades.csv: a part of a submission and its result.

    >>> from dataclasses import asdict
    >>> asdict(Row("ann.ipynb", "02_planar", "2.1", "pass", 5.0, "", max_points=5.0))["status"]
    'pass'
    """

    submission: str  # the submission's display name
    notebook: str  # the notebook id (metadata kinlib.notebook)
    part: str  # "2.1", or "-" for a row about the whole file
    status: str  # pass | fail | error
    points: float  # points earned
    message: str  # what is wrong, for the student
    max_points: float = 0.0
    answers: list = field(default_factory=list)  # [Verdict.as_dict()]: credit.score_parts scores them


@dataclass
class Grading:
    """One submission passing through :data:`STEPS` (each step reads and fills its fields).

    A grading whose kernel could not start has only error rows:

    >>> from kinlib.course.grader.isolation.kernel import NotebookRun
    >>> run = NotebookRun([], cwd=".", tmp=".", cell_timeout=5, total_timeout=30)
    >>> g = Grading(run, "ann.ipynb", "02", None, [{"part": "2.1", "points": 5.0, "answers": ["J"]}], [], 0, {}, {},
    ...             fatal="infrastructure: the kernel did not start")
    >>> [(r.part, r.status) for r in run_steps(g, [s for s in STEPS if s[0] != "execute"]).rows]
    [('2.1', 'error')]
    """

    run: NotebookRun  # the kernel run (cells, results, restarts)
    sub: str  # display name
    nid: str  # notebook id
    ref: object  # the refdata.Reference
    parts: list  # the reference's graded parts (schema.Part as dicts)
    points: list  # the secret evaluation points (never sent to the kernel)
    seed: int  # their seed (never sent to the kernel)
    part_of_cell: dict  # code cell index -> part
    out: dict  # the submission's result dict (notes, restored, timing, ...)
    fatal: str = ""  # why no answer can be graded (the kernel died, could not start, ...)
    judge: object = None  # the judge process (judging.JudgeProcess), started before the kernel ran
    exported: dict = field(default_factory=dict)  # answer -> what the kernel exported (or why it could not)
    verdicts: dict = field(default_factory=dict)  # answer -> Verdict
    rows: list = field(default_factory=list)  # [Row]

    def kind(self, name: str, part: dict) -> str:
        return self.ref.answers.get(name, {}).get("kind") or part["kinds"].get(name, "expr")


def _execute(g: Grading) -> None:
    try:  # the answers' result files first: a submission that fills its disk cannot take their space
        g.run.reserve(1 + sum(len(p["answers"]) for p in g.parts))
    except OSError as exc:  # the disk was full before any cell ran: the grader's problem, never the student's
        g.fatal = g.out["infrastructure"] = f"infrastructure: no space for the answers' files ({exc.strerror})"
        return
    try:
        g.run.execute()
    except KernelStartError as exc:
        g.fatal = g.out["infrastructure"] = f"infrastructure: {exc}"
    except RuntimeError as exc:
        g.fatal = str(exc)
    if not g.fatal and g.run.kernel is None:
        g.fatal = "the kernel died and could not be restarted"


def _restore(g: Grading) -> None:
    if g.fatal:
        return
    got, e = g.run.call("restore_saved(PATH)", 30)
    restored = got.get("restored") if isinstance(got, dict) else None
    g.out["restored"] = [str(n)[:100] for n in restored[:50]] if isinstance(restored, list) else f"restore failed: {e}"


def _export(g: Grading) -> None:
    if g.fatal:
        return
    for p in g.parts:
        for name in p["answers"]:
            got, e = g.run.call(f"export_answer(globals(), {name!r}, PATH)", EXPORT_TIMEOUT)
            if got is None:  # the kernel did not write it: its fault only if the kernel is still there
                got = {"kernel_error": e, "kernel_dead": g.run.kernel is None or not g.run.kernel.alive()}
            g.exported[name] = got


def _stop(g: Grading) -> None:
    g.run.close()


def _judge(g: Grading) -> None:
    if g.fatal:
        return
    if g.judge is None:
        from .judging import JudgeProcess

        g.judge = JudgeProcess(g.ref, g.points, g.seed)
    try:
        for p in g.parts:
            for name in p["answers"]:
                got = g.exported.get(name)
                if isinstance(got, dict) and "kernel_error" in got:
                    g.verdicts[name] = _unread(g, name, got)
                    continue
                g.verdicts[name] = g.judge.judge(name, g.kind(name, p), got)
                if g.verdicts[name].message.startswith(f"{name} was not graded: infrastructure"):
                    g.out["infrastructure"] = g.verdicts[name].message
    finally:
        g.judge.close()
        g.out["judge_kills"] = g.judge.kills


def _unread(g: Grading, name: str, got: dict) -> Verdict:
    """The verdict on an answer the kernel did not report: the student's fault (a fail) only if the kernel is
    alive and the grader's disk had room; a full disk (the answer's file could not be written) is flagged."""
    err = str(got.get("kernel_error", ""))
    full = "No space left" in err or "ENOSPC" in err or _disk_full(g.run.tmp)
    if full and getattr(g.run.enclosure, "tmpfs", False):  # its own size-limited disk: it filled it itself
        why = f"{name} could not be written: the submission had used all of its disk space ({err})"
        return Verdict(name, "fail", why[:300])
    if full:  # a disk the grader shares: not the student's fault, and another run may have room
        why = f"{name} was not graded: infrastructure: no space left where the kernel writes its answers ({err})"
        g.out["infrastructure"] = why[:300]
        return Verdict(name, "error", why[:300])
    status = "error" if got.get("kernel_dead") else "fail"
    return Verdict(name, status, f"{name} could not be read: {err}")


def _disk_full(folder) -> bool:
    """Whether the file system of ``folder`` has less than 1 MiB free (a result file would not fit)."""
    import os

    try:
        st = os.statvfs(folder)
    except (OSError, TypeError):
        return False
    return st.f_bavail * st.f_frsize < 2**20


def _rows(g: Grading) -> None:
    for p in g.parts:
        if g.fatal:
            g.rows.append(Row(g.sub, g.nid, p["part"], "error", 0, f"not graded: {g.fatal}", p["points"]))
            continue
        vs = [g.verdicts[n] for n in p["answers"]]
        msgs = [v.message + ("" if v.passed else _cell_hint(p, g)) for v in vs if v.message]
        msgs += [_exact_note(v) for v in vs if v.passed and v.exact not in ("", "equal", "not sympy")]
        ok = all(v.passed for v in vs)
        status = "pass" if ok else ("error" if any(v.status == "error" for v in vs) else "fail")
        answers = [v.as_dict() | ({"message": ""} if v.passed else {}) for v in vs]
        g.rows.append(
            Row(g.sub, g.nid, p["part"], status, p["points"] if ok else 0, "; ".join(msgs), p["points"], answers)
        )
    g.out["exact"] = {n: v.exact for n, v in g.verdicts.items() if v.exact}


def _exact_note(v: Verdict) -> str:
    from .judge import N_POINTS

    why = "timed out" if v.exact == "timed out" else v.exact
    return f"{v.answer}: equal at {N_POINTS} random points, but SymPy did not prove it exactly ({why})"


def _cell_hint(part, g: Grading) -> str:
    results = g.run.results
    bad = [(i, r) for i, r in sorted(results.items()) if g.part_of_cell.get(i) == part["part"] and r.status != "ok"]
    if not bad:
        return ""
    i, r = bad[0]
    return f" (your code cell {i + 1} for this part {r.summary()})"


STEPS = (
    ("execute", _execute),
    ("restore", _restore),
    ("export", _export),
    ("stop", _stop),
    ("judge", _judge),
    ("rows", _rows),
)


def run_steps(g: Grading, steps=STEPS) -> Grading:
    """Run ``steps`` in order on ``g``; each step's wall time goes to ``g.out["timing"][name]``.

    >>> g = Grading(None, "ann.ipynb", "02", None, [], [], 0, {}, {})
    >>> sorted(run_steps(g, [("rows", _rows)]).out["timing"])
    ['rows']
    """
    timing = g.out.setdefault("timing", {})
    for name, step in steps:
        t0 = time.monotonic()
        step(g)
        timing[name] = round(time.monotonic() - t0, 3)
    return g
