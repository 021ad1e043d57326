"""Instructor solution checker: grade a class's completed workbooks against the solution notebooks.

    kinlib grade SUBMISSION.ipynb|FOLDER ... --out DIR [--timeout S] [--cell-timeout S] [--jobs N]
                 [--notebooks notebooks] [--cache build/grade-cache] [--quiet] [--secret FILE] [--no-sandbox]
                 [--id-pattern REGEX] [--root DIR] [--memory 2G] [--processes 256] [--disk 512M]
                 [--batch-timeout S]

(the command line is :mod:`kinlib.course.cli`; the outputs are written by :mod:`kinlib.course.grader.report`)

Writes ``DIR/grades.csv`` (submission, notebook, part, status pass|fail|error, points, message),
``DIR/feedback/<submission>.md`` (one page a student can read) and prints a summary table. Exit status 0
when the batch ran (whatever the grades); 1 when a submission could not be graded for an infrastructure
failure (its rows say "not graded: infrastructure", never 0 points silently); 2 for a usage error or
when the sandbox is unavailable (unless ``--no-sandbox``).

How it works
------------
* **Which notebook.** A submission is identified by ``metadata.kinlib.notebook`` (students rename
  files); one whose metadata was lost (solution cells pasted into a new notebook) by its questions
  (:func:`kinlib.course.schema.match_notebook`: the answer names it assigns, the part numbers it mentions),
  with a note in its feedback. A file that is not JSON, not a notebook, or not one of ours gets one
  ``error`` row; so does a link, a FIFO, a file over 50 MB, JSON nested too deep or a notebook of the wrong
  types (:mod:`kinlib.course.grader.intake` reads every file defensively and says what was wrong).
* **The batch** (:func:`grade_batch`): with ``--jobs`` > 1, grading workers started and watched by the grader
  itself (:mod:`kinlib.course.grader.batch`); a worker that dies or stops answering is replaced and its
  submission tried once more, then reported as infrastructure; the outputs are always written for everyone
  graded. Student ids come from each file's path relative to the submissions folder
  (:func:`kinlib.course.grader.intake.student_id`).
* **Reference answers** come from executing the solution notebooks in ``--notebooks`` (never from the
  installed package, which holds no answer key). For each graded part (a ``question`` markdown cell,
  then ``solution`` code cells whose ``kinlib`` metadata lists ``answers`` and optional ``kinds``, as
  :mod:`kinlib.course.schema` reads them) the
  reference kernel (the grader's own, never a student's) exports each answer as data exactly as a student's
  kernel does (below); the grader reads it and keeps it in the same wire format (read back by the same whitelist parser,
  :func:`kinlib.course.answers.wire.load`, never ``eval``); the result is
  cached in ``--cache/<id>-<hash>.json`` with an HMAC tag keyed by the grader secret
  (:mod:`kinlib.course.grader.refdata`), keyed by the notebook's bytes and the checker's version. Points per part:
  ``points`` in the solution cell's ``kinlib`` metadata if present, else "(N points)" parsed from the
  question cell (split evenly when several parts share one question cell).
* **Each submission** runs in its own fresh kernel (:mod:`kinlib.course.grader.isolation.kernel`) in the bubblewrap
  sandbox (:mod:`kinlib.course.grader.isolation.sandbox`) in a scratch copy (a temp dir as cwd), every code cell in
  order with a per-cell and a total time limit. A cell that
  raises is recorded and the next one runs; a cell that kills the kernel (``os._exit``) or ignores the
  time limit is skipped after a restart (at most two), so the other parts are still graded. An answer
  is the value its variable has when its part ends (before the next ``question`` cell; the last part
  at the end of the notebook), so cells a student adds below a stub count and later reuse of the name
  does not. Workbook self-check cells that only call ``kinlib.course.workbook.selfcheck.check`` are not run (they
  cannot change an answer and cost seconds).
* **Answers leave the kernel as data and are judged outside it** (the steps of :mod:`kinlib.course.grader.steps`).
  Before the first student cell the grader starts the only code it ships into a kernel,
  :mod:`kinlib.course.grader.in_kernel` (``guard`` and ``export``, private modules under a random name, from
  their source text), which snapshots SymPy/NumPy/mpmath/builtins. After the last cell it restores those
  namespaces, then asks for each answer *as data*: a JSON tree of the SymPy expression, matrix, set, array,
  list, number or string (:mod:`kinlib.course.answers.wire`), and stops the kernel. Everything else happens in
  the grader's judge process for the submission (:mod:`kinlib.course.grader.judging`: in the sandbox, holding no
  secret, writing nothing; :func:`kinlib.course.grader.judge.judge_answer` per answer with caps, and the process
  killed and replaced when an answer goes past its time limit): the
  tree is rebuilt by a whitelist parser (never ``eval``), evaluated at random points (joint angles in
  (-π, π), positive symbols in (0.5, 2); random per submission, seeded by HMAC(grader secret, submission
  bytes) (:mod:`kinlib.course.grader.secret`): reruns are reproducible, and nobody without the secret can
  compute them from the file), compared with the reference at the same points (shapes first, then values,
  with diagnoses: wrong sign, transposed, columns swapped, [v; ω] rows, degrees, a missing or extra
  variable; non-finite values are wrong), and checked exactly (expand_trig/expand, then simplify), reported
  as advice: it cannot turn a numeric failure into a pass. No point, seed or reference is ever sent to a kernel.
* **Kinds** (``kinds`` beside ``answers``): ``expr`` (default: matrices/expressions as functions of
  the symbols), ``subspace`` (by span, whatever the basis and its scaling: principal angles between
  orthonormal bases), ``set`` (sets of configurations: members compared, angles modulo 2π whatever the
  set is keyed by; a list of {symbol: Set} conditions is their union, [] the empty set), ``choice``
  (ints/tuples compared as sets); ``properties`` beside ``answers`` grade an open-ended answer by the
  property asked (``property:nonsingular``, 5.5: :mod:`kinlib.course.answers.properties`). A default-kind answer
  that is a Set, a {symbol: Set} dict or a list of those is compared as a set; a bool or string as a
  choice; a dict with string keys entry by entry.

Per-student variants (issue 33)
-------------------------------
With ``--variants KEY.json`` (the signed key of :mod:`kinlib.course.variants.key`, verified with the grader secret:
a key whose tag does not verify is refused before anything is graded, :class:`VariantsKeyRefused`), each
submission is judged against its student's own variant: the student id is the submission's identity
(:func:`kinlib.course.grader.intake.student_id`: its path relative to the submissions root, ``--id-pattern``),
never the notebook's metadata or its variant cell (the student controls those). A student not on the key's roster
is not graded (error rows saying so, 0 points). For each answer that varies between variants, a wrong answer is
judged again against the other variants' reference answers (and the instructor's original) that differ from the
student's; one that is right for another variant scores zero and its feedback says "this looks like another
variant's answer" (:data:`kinlib.course.grader.judging.OTHER_VARIANT`), never which variant or its numbers.

Threat model
------------
Each kernel runs in the sandbox: its own user, PID, network and IPC namespaces (no network, no view of
the grader's processes; everything it starts dies with it), a read-only system and Python environment,
the ``kinlib`` package folder but not the repository around it (no notebooks, build folder, reference
cache, secret, output folder or home), and writable only its own scratch folder, a private /tmp and a
small /dev/shm (``/dev`` read-only). Each submission has limits in all (:mod:`kinlib.course.grader.isolation.limits`:
2 GiB of memory and 256 processes in a cgroup of its own, 512 MiB written on one size-limited tmpfs that
holds every folder it can write); a limit reached is a ``limits`` row and the other parts are graded.
grades.csv and the feedback are written after every kernel of the batch, and every process a submission
started, is gone (checked: :func:`kinlib.course.grader.isolation.sandbox.reap_namespaces`). Without bubblewrap the grader
refuses to run unless given ``--no-sandbox``, and then the summary and every feedback page say so.
A kernel that cannot start is retried (:data:`kinlib.course.grader.isolation.kernel.START_ATTEMPTS`), judged by its
process, not by heartbeats. Only the supervisor holds the grader secret: it signs the reference cache and chooses
each submission's points (:func:`plan`); grading workers and judge processes get the points and references, never
the secret, and only the supervisor writes the output folder. The kernel is told nothing secret (no point, seed or reference: only the names of
the answers), and what it reports is only a claim of "this is my answer": a JSON tree read from a size-capped
file by a whitelist parser with caps, never evaluated as code. A submission that replaces or patches the
in-kernel export (it is reachable from ``sys.modules``) can claim any answer, which scores only if it *is*
the answer; it cannot hide a missing answer, a crash or a timeout: those become fail/error rows. The result files the kernel writes are opened without following links, regular
files only, and only known words from the advisory exact check reach the feedback. Redefining
``kinlib.course.workbook.selfcheck.check`` changes nothing (the checker does not
use it); monkeypatching SymPy (``sympy.simplify = ...``, class attributes) or builtins in the kernel is
undone before the answers are exported, and cannot reach the grader's SymPy, which does the evaluating.
"""

from __future__ import annotations

import hashlib
import os
import time
from dataclasses import asdict, dataclass, field
from pathlib import Path

from ..schema import cell_meta, cell_part, match_notebook, notebook_id, stash_points
from . import batch, credit, intake
from .isolation.kernel import NotebookRun
from .isolation.limits import Enclosure, Limits, release
from .isolation.sandbox import Sandbox, SandboxUnavailable, check, reap_namespaces
from .judge import N_POINTS
from .judging import JudgeProcess
from .refdata import (
    GRADE_VERSION,
    Reference,
    build_reference,
    code_cells,
    default_notebooks,
    load_references,
)
from .report import summary_table, write_outputs
from .secret import default_secret_path, evaluation_seed, load_secret
from .steps import Grading, Row, run_steps

__all__ = [
    "grade_batch",
    "grade_submission",
    "Job",
    "SUBMISSION_STEPS",
    "build_reference",
    "load_references",
    "find_submissions",
    "default_notebooks",
    "make_points",
    "Reference",
    "Row",
    "GRADE_VERSION",
    "SandboxUnavailable",
    "NO_SANDBOX_NOTE",
    "VariantsKeyRefused",
    "read_variants_key",
    "variant_plan",
]

NO_SANDBOX_NOTE = (
    "graded WITHOUT the sandbox (--no-sandbox): the submission's code ran with the grader's files and network"
)
MAX_SUBMISSION_BYTES = intake.MAX_SUBMISSION_BYTES
MAX_OTHERS = 64  # other variants' reference answers a wrong answer is judged against (each distinct one once)


# ----------------------------------------------------------------------------------------- per-student variants


class VariantsKeyRefused(ValueError):
    """The variants key cannot be used (missing, damaged, or signed with another secret): nothing is graded.

    >>> read_variants_key("/nonexistent/key.json", b"s" * 32)  # doctest: +ELLIPSIS
    Traceback (most recent call last):
        ...
    kinlib.course.grader.grade.VariantsKeyRefused: ...
    """


def read_variants_key(path, secret: bytes):
    """The :class:`kinlib.course.variants.key.Key` in ``path``, verified with ``secret``; raises
    :class:`VariantsKeyRefused` (saying why) when its tag does not verify or it is not a key.

    >>> read_variants_key("/nonexistent/key.json", b"s" * 32)
    Traceback (most recent call last):
    ...
    kinlib.course.grader.grade.VariantsKeyRefused: the variants key /nonexistent/key.json does not exist: nothing graded
    """
    from ..variants.key import read_key

    p = Path(path)
    if not p.is_file():
        raise VariantsKeyRefused(f"the variants key {p} does not exist: nothing graded")
    key = read_key(p, secret)
    if key is None:
        raise VariantsKeyRefused(
            f"the variants key {p} does not verify with the grader secret (damaged, edited, or built with another "
            "secret): nothing graded; build it again with the secret this grader uses (--secret)"
        )
    return key


def _canon(answer) -> str:
    import json

    return json.dumps(answer, sort_keys=True, separators=(",", ":"), default=str)


def variant_plan(ref: Reference, key, student: str) -> dict | None:
    """What grading needs to judge ``student``'s submission of ``ref``'s notebook against their own variant:
    ``{"student", "variant", "answers": the variant's reference answers, "others": {answer: [the other variants'
    reference answers (and the original's) that differ from the student's]}}``; ``{"student", "refused": why}``
    for a student not on the key's roster; None for a notebook without variants (graded as before).

    >>> from kinlib.course.variants.key import Key, NotebookKey, Variant
    >>> a = lambda n: {"kind": "expr", "tree": ["Integer", str(n)], "symbols": {}}
    >>> ref = Reference("05", "t", "p", "0" * 64, parts=[], answers={"r": a(2), "k": a(7)})
    >>> nk = NotebookKey("05", "0" * 64, {}, {}, variants={"v1": Variant({}, {"r": a(1), "k": a(7)}, {}),
    ...     "v3": Variant({}, {"r": a(3), "k": a(7)}, {})}, students={"ada": "v1", "bob": "v3"})
    >>> p = variant_plan(ref, Key({"05": nk}), "ada")
    >>> p["variant"], p["answers"]["r"]["tree"], [o["tree"] for o in p["others"]["r"]], sorted(p["others"])
    ('v1', ['Integer', '1'], [['Integer', '2'], ['Integer', '3']], ['r'])
    >>> variant_plan(ref, Key({"05": nk}), "eve")["refused"]
    "student 'eve' is not on the roster of the variants key: not graded (the instructor must add them and build the key again)"
    """
    from ..variants.key import reference_for

    nk = key.notebooks.get(ref.notebook)
    if nk is None:
        return None
    try:
        mine, vk = reference_for(ref, key, student)
    except KeyError:
        why = (
            f"student {student!r} is not on the roster of the variants key: not graded (the instructor must add them "
            "and build the key again)"
            if student
            else "no student id for this submission: not graded against a variant (its identity names nobody on the "
            "roster of the variants key)"
        )
        return {"student": student, "refused": why}
    others = {}
    for name, own in mine.answers.items():
        seen, alts = {_canon(own)}, []
        for cand in [ref.answers.get(name)] + [v.answers.get(name) for v in nk.variants.values()]:
            if isinstance(cand, dict) and "error" not in cand and _canon(cand) not in seen:
                seen.add(_canon(cand))
                alts.append(cand)
        if alts:  # only an answer that varies
            others[name] = alts[:MAX_OTHERS]
    return {"student": student, "variant": vk, "answers": dict(mine.answers), "others": others}


# ----------------------------------------------------------------------------------------- one submission


def make_points(symbols: dict, seed: int, n: int) -> list[dict]:
    """``n`` random points {symbol name: value}: angles in (-π, π), positive symbols in (0.5, 2), others in
    (-1.5, 1.5), stratified (one value of each symbol in each n-th of its domain): the rule the self-check's public
    points follow too (:func:`kinlib.course.answers.kinds.draw_points`, issue 31).

    The same ``seed`` gives the same points (reruns are reproducible):

    >>> pts = make_points({"theta1": {}, "L1": {"positive": True}}, seed=7, n=2)
    >>> pts == make_points({"theta1": {}, "L1": {"positive": True}}, seed=7, n=2)
    True
    >>> all(-3.1416 < p["theta1"] < 3.1416 and 0.5 < p["L1"] < 2.0 for p in pts)
    True
    """
    from ..answers.kinds import draw_points

    return draw_points(symbols, seed, n)


def _error_rows(sub, nid, parts, msg) -> list[Row]:
    if not parts:
        return [Row(sub, nid, "-", "error", 0, msg)]
    return [Row(sub, nid, p["part"], "error", 0, msg, p["points"]) for p in parts]


@dataclass
class Job:
    """One submission passing through :data:`SUBMISSION_STEPS` (each step reads and fills its fields; a step
    that returns False ends the grading with the rows it wrote).

    >>> job = Job(Path("ann.ipynb"), {}, {"submission": "ann.ipynb"})
    >>> job.sub, job.nid, job.points
    ('ann.ipynb', '', [])
    """

    path: Path  # the file
    refs: dict  # notebook id -> refdata.Reference
    out: dict  # the result (rows, notes, timing, ...): what grade_submission returns
    cell_timeout: float = 60.0
    total_timeout: float = 300.0
    sandbox: object = True  # a Sandbox, True (the default one) or False
    secret: object = None  # the grader secret (bytes) or its file
    limits: Limits | None = None
    user: object = None  # without the sandbox: the unprivileged StudentUser the kernel runs as
    data: bytes = b""  # the file's bytes (the evaluation seed is derived from them)
    nb: dict = field(default_factory=dict)  # the notebook
    nid: str = ""  # its notebook id
    ref: Reference | None = None
    points: list = field(default_factory=list)  # the secret evaluation points (never sent to the kernel)
    seed: int = 0
    plan: dict | None = None  # the points chosen by a batch's supervisor (:func:`plan`); then no secret here
    variant: dict | None = None  # the student's variant (:func:`variant_plan`), per-student variants only
    vkey: object = None  # the variants Key (the student's variant is chosen from it by ``student``)
    student: str = ""  # the submission's student id (its identity: intake.student_id), for the variants key
    others: dict = field(default_factory=dict)  # answer -> the other variants' reference answers

    @property
    def sub(self) -> str:
        return self.out["submission"]

    def stop(self, rows: list) -> bool:
        """End the grading with ``rows`` (returns False, what a step returns then)."""
        self.out["rows"] = rows
        return False


def _read(job: Job) -> bool:
    """The file's bytes and notebook, read defensively (:func:`kinlib.course.grader.intake.read_notebook`)."""
    data, nb, problem = intake.read_notebook(job.path)  # never raises, never blocks, never recurses deeply
    if problem:
        return job.stop([Row(job.sub, "", "-", "error", 0, problem)])
    job.data, job.nb = data, nb
    return True


def _identify(job: Job) -> bool:
    """Which notebook it is (its metadata, or its questions when the metadata was lost) and its reference."""
    nid = notebook_id(job.nb)
    if nid is None:  # metadata lost (solution cells pasted into a new notebook): recognised by its questions
        nid = match_notebook(job.nb, {k: r.parts for k, r in job.refs.items() if not r.error})
        if nid is not None:
            job.out.setdefault("notes", []).append(
                f"recognised as {nid} by its answers and questions: the notebook's kinlib metadata was missing"
            )
    if nid is None:
        why = (
            "not one of the kinlib notebooks: its metadata has no kinlib.notebook (start from the workbook you "
            "were given)"
        )
        return job.stop([Row(job.sub, "", "-", "error", 0, why)])
    job.nid = job.out["notebook"] = nid
    job.ref = job.refs.get(nid)
    if job.ref is None:
        why = f"unknown notebook {nid!r}: no solution notebook with that id"
        return job.stop([Row(job.sub, nid, "-", "error", 0, why)])
    job.out["title"] = job.ref.title
    job.out["parts"] = job.ref.parts  # points per answer and manual rows: credit.score_parts, in _done
    if job.ref.error:
        why = f"the reference for {nid} is broken: {job.ref.error}"
        return job.stop(_error_rows(job.sub, nid, job.ref.parts, why))
    return _own_variant(job)


def _own_variant(job: Job) -> bool:
    """Per-student variants: the student's own reference (:func:`variant_plan`, chosen from the submission's
    identity, never from the notebook), or error rows for a student not on the key's roster."""
    if job.variant is None and job.vkey is not None:
        job.variant = variant_plan(job.ref, job.vkey, job.student)
    v = job.variant
    if v is None:
        return True
    if v.get("refused"):
        job.out["variant"] = ""
        return job.stop(_error_rows(job.sub, job.nid, job.ref.parts, v["refused"]))
    from dataclasses import replace

    job.ref = replace(job.ref, answers={**job.ref.answers, **v["answers"]})
    job.others = v.get("others") or {}
    job.out["variant"], job.out["student"] = v.get("variant") or "", v.get("student", "")
    return True


def _prepare(job: Job) -> bool:
    """The sandbox, and the submission's secret evaluation points: given (a batch's supervisor chose them,
    :func:`plan`), else seeded here by HMAC(secret, bytes)."""
    try:
        key = None
        if job.plan is None:
            key = job.secret if isinstance(job.secret, bytes) else load_secret(job.secret)
        elif job.plan.get("sha") != hashlib.sha256(job.data).hexdigest():
            raise ValueError("the file changed while the batch was grading it")
        if job.sandbox is True:
            ok, why = check()
            if not ok:
                raise SandboxUnavailable(why)
            job.sandbox = Sandbox()
    except (OSError, ValueError, SandboxUnavailable) as exc:
        job.out["infrastructure"] = str(exc)
        return job.stop(_error_rows(job.sub, job.nid, job.ref.parts, f"not graded: infrastructure: {exc}"))
    if job.plan is not None:
        job.seed, job.points = int(job.plan["seed"]), job.plan["points"]
    else:
        job.seed, job.points = _points(job.ref, key, job.data)
    return True


def _points(ref: Reference, key: bytes, data: bytes) -> tuple[int, list]:
    """(seed, points) of a submission with bytes ``data`` of the notebook ``ref``: HMAC(secret, bytes)."""
    seed = evaluation_seed(key, data)
    symbols: dict = {}
    for a in ref.answers.values():
        symbols.update(a.get("symbols", {}))
    return seed, make_points(symbols, seed, N_POINTS)


def plan(path, refs: dict, key: bytes, variants=None, student: str = "") -> dict | None:
    """What a grading worker needs from the secret to grade the file ``path``, chosen by the supervisor (which
    alone holds the secret): {"seed", "points", "sha"} (sha: of the bytes the points are for), or None when the
    file is not gradable (the worker's own steps then say why). ``variants`` (a variants Key) and ``student``: the
    plan also carries the student's variant (:func:`variant_plan`).

    >>> plan("no-such-file.ipynb", {}, b"k" * 32) is None
    True
    """
    job = Job(Path(path), refs, {"submission": str(path)}, vkey=variants, student=student)
    if not (_read(job) and _identify(job)):
        if job.variant and job.variant.get("refused"):  # not on the roster: the worker writes the rows saying so
            return {"seed": 0, "points": [], "sha": hashlib.sha256(job.data).hexdigest(), "variant": job.variant}
        return None
    seed, points = _points(job.ref, key, job.data)
    out = {"seed": seed, "points": points, "sha": hashlib.sha256(job.data).hexdigest()}
    if job.variant is not None:
        out["variant"] = job.variant
    return out


def _grade(job: Job) -> bool:
    """Run the notebook in a fresh kernel inside the submission's enclosure (its cgroup and size-limited tmpfs)
    and grade it by the steps of :mod:`kinlib.course.grader.steps`; a limit reached adds a ``limits`` row."""
    out = job.out
    enc = Enclosure(job.limits or Limits(), tag=out["relpath"])
    out["limits"] = enc.describe()
    try:
        rows = _run_and_judge(job, enc)
    finally:
        reached = enc.reached()
        enc.close()  # every process of the submission killed, its tmpfs gone
    if reached:  # a row that says which limit stopped what (the parts' rows say what it cost)
        out["limits_reached"] = reached
        rows.append(Row(job.sub, job.nid, "limits", "error", 0, "limit reached: " + "; ".join(reached), 0.0))
    out["rows"] = rows
    return True


def _run_and_judge(job: Job, enc: Enclosure) -> list:
    """The kernel run of :func:`_grade` (a checker bug becomes error rows, never a stopped batch)."""
    out, parts = job.out, job.ref.parts
    code = code_cells(job.nb)
    part_of_cell = {i: part for i, c in enumerate(code) if (part := cell_part(cell_meta(c)))}
    run, cpu0 = None, time.process_time()
    # the judge of this submission's answers: its own process (judging.JudgeProcess), in the sandbox started now,
    # so that it imports SymPy while the kernel runs; as the student's user (no sandbox) only once every process
    # of that user is gone (the kernel's could reach a process of their own user)
    judge = JudgeProcess(job.ref, job.points, job.seed, sandbox=job.sandbox or None, user=job.user, others=job.others)
    try:
        if job.user is None:
            judge.start()
        scratch = os.path.join(enc.folder, "work")
        os.makedirs(scratch)
        with open(os.path.join(scratch, job.path.name), "wb") as f:
            f.write(job.data)
        run = NotebookRun(
            code,
            scratch,
            enc.folder,
            job.cell_timeout,
            job.total_timeout,
            stash_after=stash_points(job.nb),
            sandbox=job.sandbox or None,
            enclosure=enc,
            user=job.user,
        )
        g = Grading(run, job.sub, job.nid, job.ref, parts, job.points, job.seed, part_of_cell, out, judge=judge)
        g = run_steps(g)
        out["restarts"] = run.restarts
        out["cells"] = [asdict(r) | {"part": part_of_cell.get(i, "")} for i, r in sorted(run.results.items())]
        out["output_bytes"] = sum(r.output_bytes for r in run.results.values())
        out["output_dropped"] = sum(r.dropped for r in run.results.values())  # messages over the size cap
        out.setdefault("exact", {})
        return g.rows
    except Exception as exc:  # noqa: BLE001  a checker bug must not stop the batch, nor pass as a grade
        out["exact"] = {}
        why = f"internal error in the checker: {type(exc).__name__}: {exc}"[:300]
        out["infrastructure"] = why  # flagged (exit status 1, the summary counts it): run it again
        return _error_rows(job.sub, job.nid, parts, f"not graded: infrastructure: {why}")
    finally:
        judge.close()
        if run is not None:
            run.close()
            out["namespaces"], out["start_failures"] = run.namespaces, run.start_failures
            out["cpu_seconds"] = round(run.cpu_seconds + time.process_time() - cpu0, 3)


#: grading one file, as named steps (as nbgrader's autograde converters); each takes the :class:`Job`
#: and returns False when it has written the submission's final rows (a file that is not gradable)
SUBMISSION_STEPS = (
    ("read", _read),
    ("identify", _identify),
    ("prepare", _prepare),
    ("grade", _grade),
)


def _new_result(path, display_name, sandbox, relpath, root, user) -> dict:
    """The result dict of a submission before any step ran."""
    p = Path(path)
    out = {"submission": display_name or str(path), "notebook": "", "title": "", "rows": [], "cells": []}
    out.update(restarts=0, output_bytes=0, sandbox=sandbox is not False, path=str(p.absolute()))
    out["relpath"] = relpath or p.name  # the student id is read from it (intake.student_id)
    out["root"] = root or str(p.absolute().parent)
    if sandbox is False:
        out["notes"] = [
            NO_SANDBOX_NOTE if user is None else f"graded without bubblewrap, as the unprivileged user {user.name}"
        ]
    return out


def grade_submission(
    path,
    refs: dict,
    cell_timeout: float = 60.0,
    total_timeout: float = 300.0,
    display_name: str | None = None,
    sandbox=True,
    secret=None,
    relpath: str | None = None,
    root: str | None = None,
    limits: Limits | None = None,
    user=None,
    plan: dict | None = None,
    variants=None,
    student: str = "",
) -> dict:
    """Grade one file; returns {"rows": [Row], "cells": [...], "seconds": float, ...} (never raises), by the
    named steps of :data:`SUBMISSION_STEPS` (read, identify, prepare, grade: the last runs
    :data:`kinlib.course.grader.steps.STEPS` in the kernel's enclosure).

    ``sandbox``: a :class:`~kinlib.course.grader.isolation.sandbox.Sandbox`, True (the default one) or False (no sandbox:
    said in the result's ``notes``); ``secret``: the grader secret (bytes) or its file (default
    :func:`~kinlib.course.grader.secret.default_secret_path`), which chooses the evaluation points; ``user``:
    without the sandbox, a :class:`~kinlib.course.grader.isolation.unprivileged.StudentUser` the kernel runs as;
    ``plan``: the points a batch's supervisor chose (:func:`plan`; then ``secret`` is not used, and the plan
    carries the student's variant); ``variants``: the per-student variants Key and ``student`` the submission's
    student id (its identity, never the notebook's metadata): judged against that student's variant.

    A file that is not one of the notebooks gets one ``error`` row, without starting a kernel:

    >>> import tempfile
    >>> with tempfile.TemporaryDirectory() as d:
    ...     _ = (Path(d) / "hw2.ipynb").write_text("not json")
    ...     res = grade_submission(Path(d) / "hw2.ipynb", {}, display_name="hw2.ipynb")
    >>> [(r["part"], r["status"], r["message"].split(" (")[0]) for r in res["rows"]]
    [('-', 'error', 'not a notebook: the file is not JSON')]

    A real submission runs in a Jupyter kernel (seconds; tests/course/test_grade.py exercises it), hence not run here:

    >>> refs = load_references(default_notebooks(), cache=None)  # doctest: +SKIP
    >>> res = grade_submission("ann/02_planar.ipynb", refs)  # doctest: +SKIP
    >>> [(r["part"], r["status"], r["points"]) for r in res["rows"]]  # one row per part  # doctest: +SKIP
    """
    t0 = time.monotonic()
    out = _new_result(path, display_name, sandbox, relpath, root, user)
    job = Job(Path(path), refs, out, cell_timeout, total_timeout, sandbox, secret, limits, user)
    job.plan, job.vkey, job.student = plan, variants, student
    job.variant = (plan or {}).get("variant")
    for _, step in SUBMISSION_STEPS:
        if not step(job):
            break
    return _done(out, t0)


def _done(out, t0):
    out["seconds"] = round(time.monotonic() - t0, 3)
    out["rows"] = [asdict(r) if isinstance(r, Row) else r for r in out["rows"]]
    return credit.score_parts(out, out.pop("parts", None) or [])


# ----------------------------------------------------------------------------------------- batch


def find_submissions(paths) -> list[Path]:
    """Files given, plus every .ipynb under folders given (hidden folders such as .ipynb_checkpoints
    skipped, links not followed: :func:`kinlib.course.grader.intake.find_submissions`), in order.

    >>> import tempfile
    >>> with tempfile.TemporaryDirectory() as d:
    ...     root = Path(d)
    ...     (root / "ann" / ".ipynb_checkpoints").mkdir(parents=True)
    ...     for f in ["ann/hw2.ipynb", "ann/.ipynb_checkpoints/hw2-checkpoint.ipynb", "ann/notes.txt", "bob.ipynb"]:
    ...         _ = (root / f).write_text("{}")
    ...     [p.relative_to(root).as_posix() for p in find_submissions([root / "ann", root / "bob.ipynb"])]
    ['ann/hw2.ipynb', 'bob.ipynb']
    """
    return [s.path for s in intake.find_submissions(paths)]


def _peek_id(path: Path, unmatched: bool = False):
    """The notebook id of a submission (None if none); ``unmatched``: whether it is a notebook without one."""
    _, nb, problem = intake.read_notebook(path)
    if problem:
        return None if not unmatched else False
    return notebook_id(nb) is None if unmatched else notebook_id(nb)


def worker_handler(init: dict):
    """The function a grading worker (:mod:`kinlib.course.grader.batch`) applies to each task: ``init`` holds the
    references (as dicts), the sandbox and the time limits, never the secret; a task names one submission and
    carries its evaluation points (:func:`plan`, chosen by the supervisor)."""
    refs = {k: Reference(**v) for k, v in init["refs"].items()}

    def handle(task: dict) -> dict:
        return grade_submission(
            task["path"],
            refs,
            init["cell_timeout"],
            init["timeout"],
            display_name=task["name"],
            sandbox=init["sandbox"],
            relpath=task["relpath"],
            root=task["root"],
            limits=init.get("limits"),
            plan=task.get("plan") or {"seed": 0, "points": [], "sha": ""},
        )

    return handle


def not_graded(sub: intake.Submission, refs: dict, why: str, name: str | None = None) -> dict:
    """The result of a submission the batch could not grade (an infrastructure failure: a worker that died
    twice, none that could start, the batch's time limit): one error row per part of its notebook."""
    t0 = time.monotonic()
    name = name or sub.relpath
    out = {"submission": name, "notebook": "", "title": "", "rows": [], "cells": [], "restarts": 0}
    out.update(path=str(sub.path), relpath=sub.relpath, root=sub.root, infrastructure=why, output_bytes=0)
    nid = _peek_id(sub.path)
    ref = refs.get(nid) if nid else None
    msg = f"not graded: infrastructure: {why}"
    if ref is None:
        out["rows"] = [Row(name, nid or "", "-", "error", 0, msg)]
    else:
        out.update(notebook=nid, title=ref.title, parts=ref.parts)
        out["rows"] = _error_rows(name, nid, ref.parts, msg)
    return _done(out, t0)


def _variants_of(variants, key: bytes, subs: list, id_pattern, out: Path, log):
    """(the verified variants key or None, {submission path: student id}) for :func:`grade_batch`."""
    if variants is None:
        return None, {}
    from .report import remembered_pattern

    vkey = read_variants_key(variants, key)
    pattern = id_pattern if id_pattern is not None else remembered_pattern(out)
    students = {s.path: intake.student_id(s.relpath, pattern)[0] for s in subs}
    log(
        f"variants: {variants} ({', '.join(sorted(vkey.notebooks)) or 'no notebook'}): each submission judged "
        "against its student's own variant"
    )
    return vkey, students


def grade_batch(
    paths,
    out,
    jobs: int = 2,
    timeout: float = 300.0,
    cell_timeout: float = 60.0,
    notebooks=None,
    cache="default",
    log=print,
    sandbox: bool = True,
    secret=None,
    id_pattern=None,
    overrides=None,
    merge: bool = True,
    batch_timeout: float | None = None,
    on_event=None,
    root=None,
    limits: Limits | None = None,
    variants=None,
) -> dict:
    """Grade every submission in ``paths`` (files or folders) into ``out``; returns a summary dict.

    ``summary = {"results": [per-submission dict], "rows": [...], "seconds": wall time,
    "per_minute": submissions per minute, "reference_seconds": ..., "infrastructure_errors": n,
    "sandbox": bool}``. Never raises for a bad submission (a link, a FIFO, deep or mistyped JSON: an error
    row each). Each student kernel runs in the bubblewrap sandbox (:mod:`kinlib.course.grader.isolation.sandbox`);
    without it (bwrap missing) this raises SandboxUnavailable unless ``sandbox=False`` (``--no-sandbox``), and
    then every feedback page and the summary say so. ``secret``: the grader secret's file (default
    :func:`~kinlib.course.grader.secret.default_secret_path`, created on first use) or bytes.

    With ``jobs`` > 1 the submissions are graded by supervised worker processes
    (:mod:`kinlib.course.grader.batch`): a worker that dies or hangs is replaced and its submission retried
    once, then reported as infrastructure; ``batch_timeout`` (seconds) bounds the whole batch. ``limits``: what
    each submission may use in all (:class:`kinlib.course.grader.isolation.limits.Limits`: 2 GiB, 256
    processes, 512 MiB written). ``root``: the folder student ids are read relative to, for files given by
    themselves (default: the one remembered in ``out/class.json``). grades.csv, totals.csv and the feedback are
    written for everyone graded, even when the batch is interrupted, and only after every kernel of the batch
    (and every process a submission started) is gone. ``variants``: the per-student variants key's file (verified
    with the secret; :class:`VariantsKeyRefused` before anything runs when it does not verify): each submission is
    judged against the variant of its student id (``id_pattern``, else the one remembered in ``out``).

    It runs the solution notebooks and every submission in Jupyter kernels (seconds to minutes;
    tests/course/test_grade.py exercises it), hence not run here:

    >>> summary = grade_batch(["submissions/"], "build/grades", jobs=2, log=None)  # doctest: +SKIP
    >>> summary["n"], sorted({r["status"] for r in summary["rows"]})  # submissions, statuses seen  # doctest: +SKIP
    >>> sorted(p.name for p in Path("build/grades").iterdir())  # doctest: +SKIP
    ['class.json', 'feedback', 'grades.csv', 'results', 'totals.csv']
    """
    from .report import remembered_root

    t0 = time.monotonic()
    log = log or (lambda *a, **k: None)
    out = Path(out)
    subs = intake.find_submissions(paths, root=root or remembered_root(out))
    notebooks = Path(notebooks) if notebooks else default_notebooks()
    if cache == "default":
        cache = notebooks.resolve().parent / "build" / "grade-cache"
    key = secret if isinstance(secret, bytes) else load_secret(secret)
    vkey, students = _variants_of(variants, key, subs, id_pattern, out, log)
    hidden = [notebooks, out, cache or "", "" if isinstance(secret, bytes) else secret or default_secret_path()]
    if variants is not None:
        hidden.append(variants)
    sb = _batch_sandbox(hidden, subs) if sandbox else None
    if sb is None:
        log(f"WARNING: {NO_SANDBOX_NOTE}")
    jobs = max(1, int(jobs))
    refs = load_references(notebooks, Path(cache) if cache else None, _needed_ids(subs), log=log, jobs=jobs, secret=key)
    t_ref = time.monotonic() - t0
    results: list = []  # filled as submissions are graded: an interrupted batch still writes what it graded
    try:
        opts = dict(timeout=timeout, cell_timeout=cell_timeout, sandbox=sb or False, secret=key, limits=limits)
        if vkey is not None:
            opts["variants"], opts["students"] = vkey, students
        _grade_all(results, subs, refs, jobs, opts, batch_timeout, on_event, log)
    finally:
        # every kernel is stopped by now; make sure no process of any sandbox survives before writing results
        survivors = reap_namespaces([n for r in results for n in r.get("namespaces", [])])
        if survivors:
            raise RuntimeError(
                f"processes {survivors} of the batch's sandboxes could not be killed: no results written"
            )
        write_outputs(out, results, id_pattern=id_pattern, overrides=overrides, merge=merge, log=log, roots=subs)
    wall = time.monotonic() - t0
    log(summary_table(results, wall, t_ref, jobs))  # control characters already escaped
    return _summary(results, wall, t_ref, sb is not None)


def _batch_sandbox(hidden: list, subs: list) -> Sandbox:
    """The batch's sandbox, hiding the notebooks, outputs, cache, secret and submission folders from every kernel;
    raises SandboxUnavailable without bubblewrap, or if a bind would expose a hidden folder."""
    ok, why = check()
    if not ok:
        raise SandboxUnavailable(f"{why}; to grade without the sandbox pass --no-sandbox")
    sb = Sandbox(hidden=[str(Path(h).resolve()) for h in hidden if h] + sorted({s.root for s in subs}))
    sb.command(["true"], cwd="/tmp", rw=[], env={})  # refuses now if a bind would expose a hidden folder
    return sb


def _needed_ids(subs: list):
    """The notebook ids the readable submissions name (None: every assignment's, when one lost its id and is
    matched against every assignment's questions)."""
    readable = [s.path for s in subs if not s.refused]
    if any(_peek_id(p, unmatched=True) for p in readable):
        return None
    return {i for i in (_peek_id(p) for p in readable) if i}


def _summary(results: list, wall: float, t_ref: float, sandboxed: bool) -> dict:
    """What :func:`grade_batch` returns."""
    return {
        "results": results,
        "rows": [r for res in results for r in res["rows"]],
        "seconds": wall,
        "reference_seconds": t_ref,
        "n": len(results),
        "per_minute": 60 * len(results) / max(wall - t_ref, 1e-9) if results else 0.0,
        "infrastructure_errors": sum(1 for r in results if r.get("infrastructure")),
        "sandbox": sandboxed,
    }


def _grade_all(done, subs, refs, jobs, opts, batch_timeout, on_event, log) -> None:
    """Append one result per submission to ``done``: in this process (one job, or one submission), else by
    supervised workers (in the submissions' order once all are in)."""
    n = len(subs)
    if jobs == 1 or n <= 1:
        try:
            for k, s in enumerate(subs, 1):
                o = opts
                args = (o["cell_timeout"], o["timeout"], s.relpath, o["sandbox"], o["secret"], s.relpath, s.root)
                vk, sid = o.get("variants"), o.get("students", {}).get(s.path, "")
                done.append(grade_submission(s.path, refs, *args, limits=o["limits"], variants=vk, student=sid))
                _progress(log, k, n, done[-1])
        except KeyboardInterrupt:
            log(f"interrupted: writing the {len(done)} result(s) graded so far")
            raise
        return
    # the supervisor alone holds the secret: it chooses each submission's points; a worker gets only those
    tasks = [
        {"i": k, "path": str(s.path), "name": s.relpath, "relpath": s.relpath, "root": s.root}
        | {"plan": plan(s.path, refs, opts["secret"], opts.get("variants"), opts.get("students", {}).get(s.path, ""))}
        for k, s in enumerate(subs)
    ]
    init = {"handler": f"{__name__}:worker_handler", "refs": {k: asdict(v) for k, v in refs.items()}}
    init.update({k: v for k, v in opts.items() if k not in ("secret", "variants", "students")})

    def event(kind, pid, i):
        if kind in ("died", "stuck", "retry", "gave-up") and i is not None:
            log(f"grading worker {pid} {kind} while grading {subs[i].relpath}")
        if on_event is not None:
            on_event(kind, pid, i)

    def result(i, res):
        done.append(res)
        _progress(log, len(done), n, res)

    task_limit = 2 * opts["timeout"] + 600.0  # the kernel's own limits end a submission long before this
    results = batch.run(
        tasks,
        jobs,
        init,
        lambda task, why: not_graded(subs[task["i"]], refs, why),
        task_limit,
        batch_timeout=batch_timeout,
        on_event=event,
        on_result=result,
        cleanup=release,
    )
    done[:] = results


def _progress(log, k, n, r):
    from .report import printable

    tot = sum(x["points"] for x in r["rows"])
    mx = sum(x.get("max_points", 0) for x in r["rows"])
    log(printable(f"[{k}/{n}] {r['submission']}: {tot:g}/{mx:g} ({r['seconds']:.1f} s)"))
