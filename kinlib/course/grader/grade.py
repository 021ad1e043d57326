"""Instructor solution checker: grade a class's completed workbooks against the solution notebooks.

    kinlib grade SUBMISSION.ipynb|FOLDER ... --out DIR [--timeout S] [--cell-timeout S] [--jobs N]
                 [--notebooks notebooks] [--cache build/grade-cache] [--quiet] [--secret FILE] [--no-sandbox]

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
  ``error`` row.
* **Reference answers** come from executing the solution notebooks in ``--notebooks`` (never from the
  installed package, which holds no answer key). For each graded part (a ``question`` markdown cell,
  then ``solution`` code cells whose ``kinlib`` metadata lists ``answers`` and optional ``kinds``, as
  :mod:`kinlib.course.schema` reads them) the
  reference kernel (the grader's own, never a student's) returns each answer as data (``sympy.srepr``
  text, read back by the strict parser :mod:`kinlib.course.grader.in_kernel.srepr`, never ``eval``); the result is
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
* **Values cross the boundary as JSON numbers only.** Before the first student cell the checker
  starts :mod:`kinlib.course.grader.in_kernel.probe` in the kernel from its source text, with the answer normaliser
  :mod:`kinlib.course.answers.normalise` (private modules under a random name) and snapshots SymPy/NumPy/mpmath/builtins. After the last cell it restores those
  namespaces, then asks for each answer's *values* at checker-chosen random points (joint angles in
  (-π, π), positive symbols in (0.5, 2); random per submission, seeded by HMAC(grader secret,
  submission bytes) (:mod:`kinlib.course.grader.secret`): reruns are reproducible, and nobody without the
  secret can compute them from the file) as [re, im] floats, plus shape, symbol names and type. The
  worker process compares them
  with the reference evaluated at the same points: shapes first, then values, with diagnoses (wrong
  sign, transposed, columns swapped, [v; ω] rows, degrees, a missing or extra variable). Only after
  all values are in does the checker send the reference's srepr into the kernel for an exact check
  (expand_trig/expand, then simplify), reported as advice: it cannot turn a numeric failure into a pass.
* **Kinds** (``kinds`` beside ``answers``): ``expr`` (default: matrices/expressions as functions of
  the symbols), ``subspace`` (by span, whatever the basis and its scaling: principal angles between
  orthonormal bases), ``set`` (sets of configurations: members compared, angles modulo 2π whatever the
  set is keyed by; a list of {symbol: Set} conditions is their union, [] the empty set), ``choice``
  (ints/tuples compared as sets); ``properties`` beside ``answers`` grade an open-ended answer by the
  property asked (``property:nonsingular``, 5.5: :mod:`kinlib.course.answers.properties`). A default-kind answer
  that is a Set, a {symbol: Set} dict or a list of those is compared as a set; a bool or string as a
  choice; a dict with string keys entry by entry.

Threat model
------------
Each kernel runs in the sandbox: its own user, PID, network and IPC namespaces (no network, no view of
the grader's processes; everything it starts dies with it), a read-only system and Python environment,
the ``kinlib`` package folder but not the repository around it (no notebooks, build folder, reference
cache, secret, output folder or home), and writable only its own scratch folder and a private /tmp.
grades.csv and the feedback are written after every kernel of the batch, and every process a submission
started, is gone (checked: :func:`kinlib.course.grader.isolation.sandbox.reap_namespaces`). Without bubblewrap the grader
refuses to run unless given ``--no-sandbox``, and then the summary and every feedback page say so.
A kernel that cannot start is retried (:data:`kinlib.course.grader.isolation.kernel.START_ATTEMPTS`), judged by its
process, not by heartbeats. Within the sandbox, the checker never evaluates student text in its own process
(only JSON numbers and strings come back, read from a size-capped file), compares in its own
process, and records failures from the kernel protocol, so a submission can *lie about the values it
computes* (equivalent to writing those values as its answer) but cannot make the comparison pass
without producing the right values, and cannot hide a missing answer, a crash or a timeout: those
become fail/error rows. The result files the kernel writes are opened without following links, regular
files only, and only known words from the advisory exact check reach the feedback. Redefining
``kinlib.course.workbook.selfcheck.check`` changes nothing (the checker does not
use it); monkeypatching SymPy (``sympy.simplify = ...``, class attributes) or builtins is undone
before the answers are read. The random points are known to the kernel when the values are asked
for, but the reference is not (it is sent only afterwards, for the advisory exact check).
"""

from __future__ import annotations

import json
import math
import os
import random
import shutil
import tempfile
import time
from concurrent.futures import ProcessPoolExecutor
from dataclasses import asdict, dataclass, field
from pathlib import Path

from ..answers import compare
from ..schema import cell_meta, cell_part, match_notebook, notebook_id, stash_points
from . import credit
from .isolation.kernel import KernelStartError, NotebookRun
from .isolation.sandbox import Sandbox, SandboxUnavailable, check, reap_namespaces
from .refdata import (
    GRADE_VERSION,
    Reference,
    build_reference,
    code_cells,
    default_notebooks,
    load_references,
    reference_description,
)
from .report import summary_table, write_outputs
from .secret import default_secret_path, evaluation_seed, load_secret

__all__ = [
    "grade_batch",
    "grade_submission",
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
]

NO_SANDBOX_NOTE = (
    "graded WITHOUT the sandbox (--no-sandbox): the submission's code ran with the grader's files and network"
)
N_POINTS = 5
N_SET_POINTS = 2
MAX_SUBMISSION_BYTES = 50 * 2**20
PROBE_TIMEOUT = 20.0
EXACT_TIMEOUT = 15.0


@dataclass
class Row:
    """One line of grades.csv: a part of a submission and its result.

    >>> from dataclasses import asdict
    >>> asdict(Row("ann.ipynb", "02_planar", "2.1", "pass", 5.0, "", max_points=5.0))["status"]
    'pass'
    """

    submission: str
    notebook: str
    part: str
    status: str  # pass | fail | error
    points: float  # points earned
    message: str
    max_points: float = 0.0
    answers: list = field(default_factory=list)  # [{answer, status, message}]: credit.score_parts scores them


# ----------------------------------------------------------------------------------------- one submission


def make_points(symbols: dict, seed: int, n: int) -> list[dict]:
    """``n`` random points {symbol name: value}: angles in (-π, π), positive symbols in (0.5, 2).

    The same ``seed`` gives the same points (reruns are reproducible):

    >>> pts = make_points({"theta1": {}, "L1": {"positive": True}}, seed=7, n=2)
    >>> [{k: round(v, 3) for k, v in p.items()} for p in pts]
    [{'L1': 0.986, 'theta1': -2.194}, {'L1': 1.476, 'theta1': -2.686}]
    >>> pts == make_points({"theta1": {}, "L1": {"positive": True}}, seed=7, n=2)
    True
    """
    rng = random.Random(seed)
    pts = []
    for _ in range(n):
        p = {}
        for name in sorted(symbols):
            if symbols[name].get("positive"):
                p[name] = rng.uniform(0.5, 2.0)
            elif name.startswith(("theta", "q", "phi", "alpha", "beta", "gamma")):
                p[name] = rng.uniform(-math.pi, math.pi)
            else:
                p[name] = rng.uniform(-1.5, 1.5)
        pts.append(p)
    return pts


def _error_rows(sub, nid, parts, msg) -> list[Row]:
    if not parts:
        return [Row(sub, nid, "-", "error", 0, msg)]
    return [Row(sub, nid, p["part"], "error", 0, msg, p["points"]) for p in parts]


def grade_submission(
    path,
    refs: dict,
    cell_timeout: float = 60.0,
    total_timeout: float = 300.0,
    display_name: str | None = None,
    sandbox=True,
    secret=None,
    user=None,
) -> dict:
    """Grade one file; returns {"rows": [Row], "cells": [...], "seconds": float, ...} (never raises).

    ``sandbox``: a :class:`~kinlib.course.grader.isolation.sandbox.Sandbox`, True (the default one) or False (no sandbox:
    said in the result's ``notes``); ``secret``: the grader secret (bytes) or its file (default
    :func:`~kinlib.course.grader.secret.default_secret_path`), which chooses the evaluation points; ``user``:
    without the sandbox, a :class:`~kinlib.course.grader.isolation.unprivileged.StudentUser` the kernel runs as.

    A file that is not one of the notebooks gets one ``error`` row, without starting a kernel:

    >>> import tempfile
    >>> with tempfile.TemporaryDirectory() as d:
    ...     _ = (Path(d) / "hw2.ipynb").write_text("not json")
    ...     res = grade_submission(Path(d) / "hw2.ipynb", {}, display_name="hw2.ipynb")
    >>> [(r["part"], r["status"], r["message"].split(" (")[0]) for r in res["rows"]]
    [('-', 'error', 'not a notebook: the file is not JSON')]

    A real submission runs in a Jupyter kernel (seconds; tests/test_grade.py exercises it), hence not run here:

    >>> refs = load_references(default_notebooks(), cache=None)  # doctest: +SKIP
    >>> res = grade_submission("ann/02_planar.ipynb", refs)  # doctest: +SKIP
    >>> [(r["part"], r["status"], r["points"]) for r in res["rows"]]  # one row per part  # doctest: +SKIP
    """
    t0 = time.monotonic()
    sub = display_name or str(path)
    out = {"submission": sub, "notebook": "", "title": "", "rows": [], "cells": [], "restarts": 0, "output_bytes": 0}
    out["sandbox"] = sandbox is not False
    out["path"] = str(Path(path).absolute())  # the student id is read from it (credit.student_id)
    if sandbox is False:
        out["notes"] = [
            NO_SANDBOX_NOTE if user is None else f"graded without bubblewrap, as the unprivileged user {user.name}"
        ]
    try:
        data = Path(path).read_bytes()
    except OSError as exc:
        out["rows"] = [Row(sub, "", "-", "error", 0, f"cannot read the file: {exc}")]
        return _done(out, t0)
    if len(data) > MAX_SUBMISSION_BYTES:
        out["rows"] = [
            Row(sub, "", "-", "error", 0, f"not graded: the file is larger than {MAX_SUBMISSION_BYTES // 2**20} MB")
        ]
        return _done(out, t0)
    try:
        nb = json.loads(data.decode("utf-8"))
    except (UnicodeDecodeError, ValueError) as exc:
        out["rows"] = [Row(sub, "", "-", "error", 0, f"not a notebook: the file is not JSON ({str(exc)[:120]})")]
        return _done(out, t0)
    if not isinstance(nb, dict) or not isinstance(nb.get("cells"), list) or nb.get("nbformat", 4) < 4:
        out["rows"] = [Row(sub, "", "-", "error", 0, "not a notebook: JSON, but not a version-4 Jupyter notebook")]
        return _done(out, t0)
    nid = notebook_id(nb)
    if nid is None:  # metadata lost (solution cells pasted into a new notebook): recognised by its questions
        nid = match_notebook(nb, {k: r.parts for k, r in refs.items() if not r.error})
        if nid is not None:
            out.setdefault("notes", []).append(
                f"recognised as {nid} by its answers and questions: the notebook's kinlib metadata was missing"
            )
    if nid is None:
        out["rows"] = [
            Row(
                sub,
                "",
                "-",
                "error",
                0,
                "not one of the kinlib notebooks: its metadata has no "
                "kinlib.notebook (start from the workbook you were given)",
            )
        ]
        return _done(out, t0)
    out["notebook"] = nid
    ref = refs.get(nid)
    if ref is None:
        out["rows"] = [Row(sub, nid, "-", "error", 0, f"unknown notebook {nid!r}: no solution notebook with that id")]
        return _done(out, t0)
    out["title"] = ref.title
    parts = ref.parts
    out["parts"] = parts  # points per answer and manual rows: credit.score_parts, in _done
    if ref.error:
        out["rows"] = _error_rows(sub, nid, parts, f"the reference for {nid} is broken: {ref.error}")
        return _done(out, t0)
    try:
        key = secret if isinstance(secret, bytes) else load_secret(secret)
        if sandbox is True:
            ok, why = check()
            if not ok:
                raise SandboxUnavailable(why)
            sandbox = Sandbox()
    except (OSError, ValueError, SandboxUnavailable) as exc:
        out["infrastructure"] = str(exc)
        out["rows"] = _error_rows(sub, nid, parts, f"not graded: infrastructure: {exc}")
        return _done(out, t0)
    seed = evaluation_seed(key, data)
    symbols: dict = {}
    for a in ref.answers.values():
        symbols.update(a.get("symbols", {}))
    points = make_points(symbols, seed, N_POINTS)

    code = code_cells(nb)
    part_of_cell = {}
    for i, c in enumerate(code):
        part = cell_part(cell_meta(c))
        if part:
            part_of_cell[i] = part
    stash_after = stash_points(nb)

    tmp = tempfile.mkdtemp(prefix="kinlib-grade-")
    run, cpu0 = None, time.process_time()
    try:
        scratch = os.path.join(tmp, "work")
        os.makedirs(scratch)
        with open(os.path.join(scratch, Path(path).name), "wb") as f:
            f.write(data)
        run = NotebookRun(
            code, scratch, tmp, cell_timeout, total_timeout, stash_after=stash_after, sandbox=sandbox or None, user=user
        )
        rows, exact = _grade_in_kernel(run, sub, nid, ref, parts, points, seed, part_of_cell, out)
        out["restarts"] = run.restarts
        out["cells"] = [asdict(r) | {"part": part_of_cell.get(i, "")} for i, r in sorted(run.results.items())]
        out["output_bytes"] = sum(r.output_bytes for r in run.results.values())
    except Exception as exc:  # noqa: BLE001  a checker bug must not stop the batch
        rows, exact = _error_rows(sub, nid, parts, f"internal error in the checker: {type(exc).__name__}: {exc}"), {}
    finally:
        if run is not None:
            run.close()
            out["namespaces"], out["start_failures"] = run.namespaces, run.start_failures
            out["cpu_seconds"] = round(run.cpu_seconds + time.process_time() - cpu0, 3)
        shutil.rmtree(tmp, ignore_errors=True)
    out["rows"] = rows
    out["exact"] = exact
    return _done(out, t0)


def _grade_in_kernel(run, sub, nid, ref, parts, points, seed, part_of_cell, out):
    """Execute the submission, read every answer's values, compare; then the advisory exact check."""
    results: dict = {}
    exact: dict = {}
    fatal = ""
    t0 = time.monotonic()
    timing = out.setdefault("timing", {})
    try:
        run.execute()
    except KernelStartError as exc:
        fatal = out["infrastructure"] = f"infrastructure: {exc}"
    except RuntimeError as exc:
        fatal = str(exc)
    if not fatal and run.kernel is None:
        fatal = "the kernel died and could not be restarted"
    timing["execute"] = round(time.monotonic() - t0, 3)
    t1 = time.monotonic()
    if not fatal:
        got, e = run.call("restore_saved(PATH)", 30)
        out["restored"] = (got or {}).get("restored", 0) if got else f"restore failed: {e}"
        for p in parts:
            for name in p["answers"]:
                kind = ref.answers.get(name, {}).get("kind") or p["kinds"].get(name, "expr")
                n = N_SET_POINTS if kind == "set" else (0 if kind == "choice" else N_POINTS)
                got, e = run.call(
                    f"probe_answer(globals(), {name!r}, {kind!r}, {points[:n]!r}, {seed}, PATH)", PROBE_TIMEOUT
                )
                if got is None:
                    got = {"tag": "probe-error", "error": e, "kernel": run.kernel is None or not run.kernel.alive()}
                results[name] = got
    timing["probe"] = round(time.monotonic() - t1, 3)
    t2 = time.monotonic()
    rows = []
    pending_exact = []
    for p in parts:
        if fatal:
            rows.append(Row(sub, nid, p["part"], "error", 0, f"not graded: {fatal}", p["points"]))
            continue
        msgs, ok_all, err, verdicts = [], True, False, []
        for name in p["answers"]:
            kind = ref.answers.get(name, {}).get("kind") or p["kinds"].get(name, "expr")
            ra = ref.answers.get(name, {})
            stu = results.get(name) or {"tag": "probe-error", "error": "no result"}
            if not isinstance(stu, dict):
                stu = {"tag": "probe-error", "error": "malformed result"}
            if stu.get("tag") == "probe-error" and stu.get("kernel"):
                err, ok_all = True, False
                msgs.append(f"{name} could not be read: {stu.get('error')}")
                verdicts.append({"answer": name, "status": "error", "message": msgs[-1]})
                continue
            n = N_SET_POINTS if kind == "set" else (0 if kind == "choice" else N_POINTS)
            try:
                rd = reference_description(ref, name, kind, points[:n], seed)
            except Exception as exc:  # noqa: BLE001
                err, ok_all = True, False
                msgs.append(f"{name}: the reference could not be evaluated ({exc})")
                verdicts.append({"answer": name, "status": "error", "message": msgs[-1]})
                continue
            ok, msg = compare.compare(kind, stu, rd, name)
            verdicts.append({"answer": name, "status": "pass" if ok else "fail", "message": "" if ok else msg})
            if ok and kind == "expr" and stu.get("tag") in ("matrix", "scalar") and "srepr" in ra:
                pending_exact.append((p["part"], name, ra["srepr"]))
            if not ok:
                ok_all = False
                msgs.append(msg + _cell_hint(p, run.results, part_of_cell))
            elif msg:
                msgs.append(f"{name}: {msg}")
        status = "pass" if ok_all else ("error" if err else "fail")
        rows.append(
            Row(sub, nid, p["part"], status, p["points"] if ok_all else 0, "; ".join(msgs), p["points"], verdicts)
        )
    timing["compare"] = round(time.monotonic() - t2, 3)
    t3 = time.monotonic()
    # the advisory exact check, only now that every value is in
    if not fatal and run.kernel is not None and run.kernel.alive():
        for part, name, text in pending_exact:
            got, e = run.call(f"probe_exact(globals(), {name!r}, {text!r}, PATH)", EXACT_TIMEOUT)
            exact[name] = (got or {}).get("exact", "not checked") if isinstance(got, dict) else "not checked"
            if exact[name] not in ("equal", "not proved", "not sympy", "missing", "error"):
                exact[name] = "not checked"  # the kernel wrote the file: only known words reach the feedback
            if exact[name] != "equal":
                for r in rows:
                    if r.part == part and r.status == "pass":
                        note = (
                            f"{name}: equal at {N_POINTS} random points, but SymPy did not prove it exactly "
                            f"({'timed out' if got is None else exact[name]})"
                        )
                        r.message = "; ".join(x for x in (r.message, note) if x)
    timing["exact"] = round(time.monotonic() - t3, 3)
    return rows, exact


def _cell_hint(part, results, part_of_cell) -> str:
    bad = [(i, r) for i, r in sorted(results.items()) if part_of_cell.get(i) == part["part"] and r.status != "ok"]
    if not bad:
        return ""
    i, r = bad[0]
    return f" (your code cell {i + 1} for this part {r.summary()})"


def _done(out, t0):
    out["seconds"] = round(time.monotonic() - t0, 3)
    out["rows"] = [asdict(r) if isinstance(r, Row) else r for r in out["rows"]]
    return credit.score_parts(out, out.pop("parts", None) or [])


# ----------------------------------------------------------------------------------------- batch


def find_submissions(paths) -> list[Path]:
    """Files given, plus every .ipynb under folders given (hidden folders such as .ipynb_checkpoints
    skipped), in order.

    >>> import tempfile
    >>> with tempfile.TemporaryDirectory() as d:
    ...     root = Path(d)
    ...     (root / "ann" / ".ipynb_checkpoints").mkdir(parents=True)
    ...     for f in ["ann/hw2.ipynb", "ann/.ipynb_checkpoints/hw2-checkpoint.ipynb", "ann/notes.txt", "bob.ipynb"]:
    ...         _ = (root / f).write_text("{}")
    ...     [p.relative_to(root).as_posix() for p in find_submissions([root / "ann", root / "bob.ipynb"])]
    ['ann/hw2.ipynb', 'bob.ipynb']
    """
    found = []
    for p in map(Path, paths):
        if p.is_dir():
            found += sorted(
                q for q in p.rglob("*.ipynb") if not any(part.startswith(".") for part in q.relative_to(p).parts[:-1])
            )
        elif p.exists():
            found.append(p)
        else:
            raise FileNotFoundError(f"no such file or folder: {p}")
    return found


def _peek_id(path: Path, unmatched: bool = False):
    """The notebook id of a submission (None if none); ``unmatched``: whether it is a notebook without one."""
    try:
        with open(path, "rb") as f:
            data = f.read(MAX_SUBMISSION_BYTES + 1)
        nb = json.loads(data)
        if unmatched:
            return isinstance(nb, dict) and isinstance(nb.get("cells"), list) and notebook_id(nb) is None
        return notebook_id(nb)
    except (OSError, ValueError, UnicodeDecodeError, AttributeError):
        return None


_REFS: dict = {}
_CTX: dict = {}


def _init_worker(refs_json, sandbox, secret):
    global _REFS
    _REFS = {k: Reference(**v) for k, v in refs_json.items()}
    _CTX.update(sandbox=sandbox, secret=secret)


def _work(args):
    path, name, cell_timeout, total_timeout = args
    return grade_submission(path, _REFS, cell_timeout, total_timeout, display_name=name, **_CTX)


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
) -> dict:
    """Grade every submission in ``paths`` (files or folders) into ``out``; returns a summary dict.

    ``summary = {"results": [per-submission dict], "rows": [...], "seconds": wall time,
    "per_minute": submissions per minute, "reference_seconds": ..., "infrastructure_errors": n,
    "sandbox": bool}``. Never raises for a bad submission. Each student kernel runs in the bubblewrap
    sandbox (:mod:`kinlib.course.grader.isolation.sandbox`); without it (bwrap missing) this raises SandboxUnavailable
    unless ``sandbox=False`` (``--no-sandbox``), and then every feedback page and the summary say so.
    ``secret``: the grader secret's file (default :func:`~kinlib.course.grader.secret.default_secret_path`,
    created on first use) or bytes. grades.csv and the feedback are written only after every kernel of
    the batch (and every process a submission started) is gone.

    It runs the solution notebooks and every submission in Jupyter kernels (seconds to minutes;
    tests/test_grade.py exercises it), hence not run here:

    >>> summary = grade_batch(["submissions/"], "build/grades", jobs=2, log=None)  # doctest: +SKIP
    >>> summary["n"], sorted({r["status"] for r in summary["rows"]})  # submissions, statuses seen  # doctest: +SKIP
    >>> sorted(p.name for p in Path("build/grades").iterdir())  # doctest: +SKIP
    ['feedback', 'grades.csv']
    """
    t0 = time.monotonic()
    log = log or (lambda *a, **k: None)
    out = Path(out)
    subs = find_submissions(paths)
    notebooks = Path(notebooks) if notebooks else default_notebooks()
    if cache == "default":
        cache = notebooks.resolve().parent / "build" / "grade-cache"
    key = secret if isinstance(secret, bytes) else load_secret(secret)
    sb = None
    if sandbox:
        ok, why = check()
        if not ok:
            raise SandboxUnavailable(f"{why}; to grade without the sandbox pass --no-sandbox")
        hidden = [notebooks, out, cache or "", "" if isinstance(secret, bytes) else secret or default_secret_path()]
        sb = Sandbox(hidden=[str(Path(h).resolve()) for h in hidden if h] + [str(p.resolve().parent) for p in subs])
        sb.command(["true"], cwd="/tmp", rw=[], env={})  # refuses now if a bind would expose a hidden folder
    else:
        log(f"WARNING: {NO_SANDBOX_NOTE}")
    ids = {i for i in (_peek_id(p) for p in subs) if i}
    if any(_peek_id(p, unmatched=True) for p in subs):
        ids = None  # a notebook without its id is matched against every assignment's questions
    refs = load_references(notebooks, Path(cache) if cache else None, ids, log=log, jobs=max(1, int(jobs)), secret=key)
    t_ref = time.monotonic() - t0
    names = _display_names(subs)
    jobs = max(1, int(jobs))
    work = [(str(p), n, cell_timeout, timeout) for p, n in zip(subs, names)]
    results = []
    if jobs == 1 or len(work) <= 1:
        for k, w in enumerate(work, 1):
            results.append(
                grade_submission(w[0], refs, cell_timeout, timeout, display_name=w[1], sandbox=sb or False, secret=key)
            )
            _progress(log, k, len(work), results[-1])
    else:
        import multiprocessing as mp

        refs_json = {k: asdict(v) for k, v in refs.items()}
        with ProcessPoolExecutor(
            max_workers=min(jobs, len(work)),
            mp_context=mp.get_context("spawn"),
            initializer=_init_worker,
            initargs=(refs_json, sb or False, key),
        ) as pool:
            for k, r in enumerate(pool.map(_work, work), 1):
                results.append(r)
                _progress(log, k, len(work), r)
    # every kernel is stopped by now; make sure no process of any sandbox survives before writing results
    survivors = reap_namespaces([n for r in results for n in r.get("namespaces", [])])
    if survivors:
        raise RuntimeError(f"processes {survivors} of the batch's sandboxes could not be killed: no results written")
    wall = time.monotonic() - t0
    write_outputs(out, results, id_pattern=id_pattern, overrides=overrides, merge=merge, log=log)
    summary = {
        "results": results,
        "rows": [r for res in results for r in res["rows"]],
        "seconds": wall,
        "reference_seconds": t_ref,
        "n": len(results),
        "per_minute": 60 * len(results) / max(wall - t_ref, 1e-9) if results else 0.0,
        "infrastructure_errors": sum(1 for r in results if r.get("infrastructure")),
        "sandbox": sb is not None,
    }
    log(summary_table(results, wall, t_ref, jobs))
    return summary


def _progress(log, k, n, r):
    tot = sum(x["points"] for x in r["rows"])
    mx = sum(x.get("max_points", 0) for x in r["rows"])
    log(f"[{k}/{n}] {r['submission']}: {tot:g}/{mx:g} ({r['seconds']:.1f} s)")


def _display_names(subs) -> list[str]:
    names = []
    try:
        common = Path(os.path.commonpath([str(p.resolve().parent) for p in subs])) if subs else None
    except ValueError:
        common = None
    for p in subs:
        try:
            names.append(str(p.resolve().relative_to(common)) if common else str(p))
        except ValueError:
            names.append(str(p))
    return names
