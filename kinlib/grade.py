"""Instructor solution checker: grade a class's completed workbooks against the solution notebooks.

    python -m kinlib.grade SUBMISSION.ipynb|FOLDER ... --out DIR [--timeout S] [--cell-timeout S] [--jobs N]
                           [--notebooks notebooks] [--cache build/grade-cache]

Writes ``DIR/grades.csv`` (submission, notebook, part, status pass|fail|error, points, message),
``DIR/feedback/<submission>.md`` (one page a student can read) and prints a summary table. Exit status 0
whenever the batch ran (whatever the grades); 2 for a usage error.

How it works
------------
* **Which notebook.** A submission is identified by ``metadata.kinlib.notebook`` (students rename
  files). A file that is not JSON, not a notebook, or not one of ours gets one ``error`` row.
* **Reference answers** come from executing the solution notebooks in ``--notebooks`` (never from the
  installed package, which holds no answer key). For each graded part (a ``question`` markdown cell,
  then ``solution`` code cells whose ``kinlib`` metadata lists ``answers`` and optional ``kinds``) the
  reference kernel returns each answer's ``sympy.srepr``; the result is cached in
  ``--cache/<id>-<hash>.json``, keyed by the notebook's bytes and the checker's version. Points per part:
  ``points`` in the solution cell's ``kinlib`` metadata if present, else "(N points)" parsed from the
  question cell (split evenly when several parts share one question cell).
* **Each submission** runs in its own fresh kernel (:mod:`kinlib._grade_kernel`) in a scratch copy
  (a temp dir as cwd), every code cell in order with a per-cell and a total time limit. A cell that
  raises is recorded and the next one runs; a cell that kills the kernel (``os._exit``) or ignores the
  time limit is skipped after a restart (at most two), so the other parts are still graded. An answer
  is the value its variable has when its part ends (before the next ``question`` cell; the last part
  at the end of the notebook), so cells a student adds below a stub count and later reuse of the name
  does not. Workbook self-check cells that only call ``kinlib.selfcheck.check`` are not run (they
  cannot change an answer and cost seconds).
* **Values cross the boundary as JSON numbers only.** Before the first student cell the checker
  starts :mod:`kinlib._grade_probe` in the kernel from its source text (a private module under a
  random name) and snapshots SymPy/NumPy/mpmath/builtins. After the last cell it restores those
  namespaces, then asks for each answer's *values* at checker-chosen random points (joint angles in
  (-π, π), positive symbols in (0.5, 2); random per submission, seeded by its SHA-256, so reruns are
  reproducible) as [re, im] floats, plus shape, symbol names and type. The worker process compares them
  with the reference evaluated at the same points: shapes first, then values, with diagnoses (wrong
  sign, transposed, columns swapped, [v; ω] rows, degrees, a missing or extra variable). Only after
  all values are in does the checker send the reference's srepr into the kernel for an exact check
  (expand_trig/expand, then simplify), reported as advice: it cannot turn a numeric failure into a pass.
* **Kinds** (``kinds`` beside ``answers``): ``expr`` (default: matrices/expressions as functions of
  the symbols), ``subspace`` (by span: rank [A B] = rank A = rank B), ``set`` (sets of configurations:
  members compared, angles modulo 2π; a list of {symbol: Set} conditions is their union, [] the empty
  set), ``choice`` (ints/tuples compared as sets). A default-kind answer that is a Set, a
  {symbol: Set} dict or a list of those is compared as a set; a bool or string as a choice; a dict with
  string keys entry by entry.

Threat model
------------
The kernel is not a sandbox: a submission runs as the grader's user, with its files and network
(run the batch in a container or as a user that cannot read the solution notebooks or the cache if
students are hostile). Within that, the checker never evaluates student text in its own process
(only JSON numbers and strings come back, read from a size-capped file), compares in its own
process, and records failures from the kernel protocol, so a submission can *lie about the values it
computes* (equivalent to writing those values as its answer) but cannot make the comparison pass
without producing the right values, and cannot hide a missing answer, a crash or a timeout: those
become fail/error rows. Redefining ``kinlib.selfcheck.check`` changes nothing (the checker does not
use it); monkeypatching SymPy (``sympy.simplify = ...``, class attributes) or builtins is undone
before the answers are read. The random points are known to the kernel when the values are asked
for, but the reference is not (it is sent only afterwards, for the advisory exact check).
"""
from __future__ import annotations

import argparse
import csv
import hashlib
import json
import math
import os
import random
import re
import shutil
import sys
import tempfile
import time
from concurrent.futures import ProcessPoolExecutor
from dataclasses import asdict, dataclass, field
from pathlib import Path

from . import _grade_compare as compare
from . import _grade_probe as probe

__all__ = ["grade_batch", "grade_submission", "build_reference", "load_references", "find_submissions",
           "Reference", "Row", "main"]

GRADE_VERSION = "1"
N_POINTS = 5
N_SET_POINTS = 2
MAX_SUBMISSION_BYTES = 50 * 2**20
MAX_RESULT_BYTES = 5 * 2**20
PROBE_TIMEOUT = 20.0
EXACT_TIMEOUT = 15.0
MAX_RESTARTS = 2
_PROBE_SOURCE = Path(probe.__file__).read_text()
_POINTS_RE = [re.compile(r"\((\d+(?:\.\d+)?)\s*points?\)", re.I), re.compile(r"(\d+(?:\.\d+)?)\s*points?\b", re.I)]


@dataclass
class Row:
    submission: str
    notebook: str
    part: str
    status: str           # pass | fail | error
    points: float         # points earned
    message: str
    max_points: float = 0.0


@dataclass
class Part:
    part: str
    points: float
    answers: list
    kinds: dict
    cells: list = field(default_factory=list)   # code cell indices of the solution cells


@dataclass
class Reference:
    notebook: str
    title: str
    path: str
    sha: str
    parts: list            # [Part as dict]
    answers: dict          # name -> {"srepr"/"choice", "symbols"} or {"error"}
    error: str = ""


# ----------------------------------------------------------------------------------------- notebooks

def _repo_root() -> Path:
    return Path(__file__).resolve().parent.parent


def default_notebooks() -> Path:
    p = _repo_root() / "notebooks"
    return p if p.is_dir() else Path("notebooks")


def _nb_id(nb: dict) -> str | None:
    meta = nb.get("metadata") if isinstance(nb, dict) else None
    k = meta.get("kinlib") if isinstance(meta, dict) else None
    nid = k.get("notebook") if isinstance(k, dict) else None
    return str(nid) if isinstance(nid, str) and nid else None


def _source(cell) -> str:
    s = cell.get("source", "")
    return "".join(s) if isinstance(s, list) else str(s)


def _tags(cell) -> list:
    md = cell.get("metadata") or {}
    t = md.get("tags") or []
    return [str(x) for x in t] if isinstance(t, list) else []


def _points_in(text: str):
    for rx in _POINTS_RE:
        m = rx.search(text)
        if m:
            return float(m.group(1))
    return None


def parse_parts(nb: dict) -> list[Part]:
    """Graded parts of a solution notebook, in order (see the module docstring)."""
    parts: dict[str, Part] = {}
    question_of: dict[str, int] = {}
    q_idx, q_points = -1, None
    code_idx = -1
    explicit: dict[str, float] = {}
    for cell in nb.get("cells", []):
        tags = _tags(cell)
        if cell.get("cell_type") == "code":
            code_idx += 1
        if cell.get("cell_type") == "markdown" and "question" in tags:
            q_idx += 1
            q_points = _points_in(_source(cell))
            continue
        meta = (cell.get("metadata") or {}).get("kinlib") or {}
        if cell.get("cell_type") != "code" or "solution" not in tags or not meta.get("answers"):
            continue
        pid = str(meta.get("part", "")) or f"q{q_idx + 1}"
        kinds = {str(k): ("expr" if v in ("default", None) else str(v)) for k, v in (meta.get("kinds") or {}).items()}
        p = parts.setdefault(pid, Part(pid, q_points if q_points is not None else 0.0, [], {}))
        for name in meta["answers"]:
            name = str(name)
            if name not in p.answers:
                p.answers.append(name)
            p.kinds[name] = kinds.get(name, "expr")
        p.cells.append(code_idx)
        question_of.setdefault(pid, q_idx)
        if "points" in meta:
            explicit[pid] = float(meta["points"])
    # several parts under one question cell share its points
    shared: dict[int, list] = {}
    for pid, q in question_of.items():
        if pid not in explicit:
            shared.setdefault(q, []).append(pid)
    for pids in shared.values():
        for pid in pids:
            parts[pid].points = round(parts[pid].points / len(pids), 3)
    for pid, pts in explicit.items():
        parts[pid].points = pts
    return list(parts.values())


def stash_points(nb: dict) -> dict:
    """{code cell index: answer names} to keep when a part ends (before the next ``question`` cell).

    An answer is the value its variable has at the end of its part: the solution cell plus any cells
    a student added below it, up to the next question. Later cells that reuse the name (or ``del`` it)
    do not change it. Answers of the last part are read at the end of the notebook.
    """
    out: dict = {}
    pending: list = []
    code_idx = -1
    for cell in nb.get("cells", []):
        if not isinstance(cell, dict):
            continue
        tags = _tags(cell)
        if cell.get("cell_type") == "markdown" and "question" in tags:
            if pending and code_idx >= 0:
                out.setdefault(code_idx, []).extend(n for n in pending if n not in out.get(code_idx, []))
            pending = []
        if cell.get("cell_type") == "code":
            code_idx += 1
            meta = (cell.get("metadata") or {}).get("kinlib") or {}
            if "solution" in tags and isinstance(meta, dict):
                pending += [str(n) for n in (meta.get("answers") or []) if isinstance(n, str)]
    return out


def is_plain_selfcheck(cell) -> bool:
    """A workbook self-check cell as ``make handouts`` wrote it: only ``from kinlib.selfcheck import check``
    and ``check(...)`` calls. It cannot change an answer, so the checker does not spend time running it."""
    import ast
    if "selfcheck" not in _tags(cell):
        return False
    try:
        tree = ast.parse(_source(cell))
    except SyntaxError:
        return False
    for node in tree.body:
        if isinstance(node, ast.ImportFrom) and node.module == "kinlib.selfcheck" and \
                [a.name for a in node.names] == ["check"] and all(a.asname is None for a in node.names):
            continue
        if isinstance(node, ast.Expr) and isinstance(node.value, ast.Call) and \
                isinstance(node.value.func, ast.Name) and node.value.func.id == "check" and \
                all(isinstance(a, ast.Constant) for a in node.value.args) and \
                all(isinstance(k.value, ast.Constant) for k in node.value.keywords):
            continue
        return False
    return True


def _code_cells(nb: dict) -> list:
    return [c for c in nb.get("cells", []) if isinstance(c, dict) and c.get("cell_type") == "code"]


# ----------------------------------------------------------------------------------------- kernel driver

class _Run:
    """A submission (or reference) notebook executed cell by cell in a fresh kernel, with restarts."""

    def __init__(self, cells: list, cwd: str, tmp: str, cell_timeout: float, total_timeout: float,
                 stash_after: dict | None = None, snapshot: bool = True):
        from ._grade_kernel import Kernel
        self.Kernel = Kernel
        self.cells = cells
        self.cwd, self.tmp = cwd, tmp
        self.cell_timeout, self.total = cell_timeout, total_timeout
        self.stash_after = stash_after or {}
        self.snapshot = snapshot
        self.nonce = "_kinlib_grade_" + os.urandom(8).hex()
        self.kernel = None
        self.results: dict = {}
        self.restarts = 0
        self.t0 = time.monotonic()

    def _start(self):
        self.kernel = self.Kernel(cwd=self.cwd, conn_dir=self.tmp)
        self.kernel.start()
        code = (f"def __kg_setup():\n"
                f"    import sys, types\n"
                f"    m = types.ModuleType({self.nonce!r})\n"
                f"    exec(compile({_PROBE_SOURCE!r}, '<kinlib-grade-probe>', 'exec'), m.__dict__)\n"
                f"    sys.modules[{self.nonce!r}] = m\n"
                f"    m.SNAP = m.snapshot() if {self.snapshot!r} else None\n"
                f"__kg_setup(); del __kg_setup\n")
        r = self.kernel.run(code, timeout=60, silent=True)
        if r.status != "ok":
            raise RuntimeError(f"could not start the checker's probe in the kernel: {r.summary()}")

    def _m(self) -> str:
        return f"__import__('sys').modules[{self.nonce!r}]"

    def execute(self):
        """Run all cells; returns self (results: index -> CellResult)."""
        from ._grade_kernel import CellResult
        skip: set = set()
        while True:
            self._start()
            died_at = None
            for i, cell in enumerate(self.cells):
                if i in skip:
                    continue
                left = self.total - (time.monotonic() - self.t0)
                if left <= 0:
                    self.results[i] = CellResult(i, "skipped", note="not run: the total time limit was reached")
                    continue
                src = _source(cell)
                if not src.strip() or is_plain_selfcheck(cell):
                    self.results[i] = CellResult(i, "ok", note="self-check not run by the checker" if src.strip() else "")
                else:
                    r = self.kernel.run(src, timeout=min(self.cell_timeout, left), index=i)
                    self.results[i] = r
                    if r.status in ("died", "timeout") and not self.kernel.alive():
                        died_at = i
                        break
                if i in self.stash_after and self.kernel.alive():
                    self.kernel.run(f"{self._m()}.stash(globals(), {self.stash_after[i]!r})", timeout=10,
                                    silent=True)
            if died_at is None:
                return self
            skip.add(died_at)
            self.kernel.kill()
            if self.restarts >= MAX_RESTARTS or self.total - (time.monotonic() - self.t0) <= 1:
                for j in range(died_at + 1, len(self.cells)):
                    self.results.setdefault(j, CellResult(j, "skipped", note="not run: the kernel had died"))
                self.kernel = None
                return self
            self.restarts += 1
            # rerun from the top in a fresh kernel without the cell(s) that killed it
            for j in list(self.results):
                if j not in skip:
                    del self.results[j]

    def call(self, expr: str, timeout: float) -> tuple[dict | None, str]:
        """Run ``probe.<expr with PATH>`` in the kernel; return (JSON result, error text)."""
        if self.kernel is None or not self.kernel.alive():
            return None, "the kernel was not running"
        path = os.path.join(self.tmp, "r-" + os.urandom(8).hex() + ".json")
        r = self.kernel.run(f"{self._m()}.{expr.replace('PATH', repr(path))}", timeout=timeout, silent=True)
        if r.status != "ok":
            return None, r.summary()
        try:
            with open(path, "rb") as f:
                data = f.read(MAX_RESULT_BYTES + 1)
            if len(data) > MAX_RESULT_BYTES:
                return None, "the answer is too large to read"
            return json.loads(data), ""
        except (OSError, ValueError) as exc:
            return None, f"no readable result ({type(exc).__name__})"

    def close(self):
        if self.kernel is not None:
            self.kernel.kill()
            self.kernel = None


# ----------------------------------------------------------------------------------------- references

def _hash(data: bytes) -> str:
    h = hashlib.sha256(data)
    h.update(_PROBE_SOURCE.encode())
    h.update(GRADE_VERSION.encode())
    return h.hexdigest()


def build_reference(path: Path, cache: Path | None = None, timeout: float = 300.0, log=None) -> Reference:
    """Execute the solution notebook ``path`` and read its answers (cached by content hash)."""
    path = Path(path)
    data = path.read_bytes()
    sha = _hash(data)
    nb = json.loads(data)
    nid = _nb_id(nb) or path.stem
    if cache is not None:
        cfile = Path(cache) / f"{nid}-{sha[:16]}.json"
        if cfile.exists():
            try:
                return Reference(**json.loads(cfile.read_text()))
            except (ValueError, TypeError):
                pass
    t0 = time.monotonic()
    parts = parse_parts(nb)
    title = str((nb.get("metadata", {}).get("kinlib") or {}).get("title", nid))
    answers = {n: k for p in parts for n, k in p.kinds.items()}
    code = _code_cells(nb)
    stash_after = stash_points(nb)
    tmp = tempfile.mkdtemp(prefix="kinlib-grade-ref-")
    err = ""
    ans: dict = {}
    run = _Run(code, str(path.parent.resolve()), tmp, cell_timeout=timeout, total_timeout=timeout * 4,
               stash_after=stash_after, snapshot=False)
    try:
        run.execute()
        bad = [r for r in run.results.values() if r.status != "ok"]
        if bad:
            err = f"code cell {bad[0].index + 1} of the solution notebook: {bad[0].summary()}"
        got, e = run.call(f"probe_reference(globals(), {answers!r}, PATH)", timeout=120)
        if got is None:
            err = err or f"could not read the reference answers: {e}"
        else:
            ans = got
    except RuntimeError as exc:
        err = str(exc)
    finally:
        run.close()
        shutil.rmtree(tmp, ignore_errors=True)
    missing = [f"{n}: {a['error']}" for n, a in ans.items() if "error" in a]
    if missing and not err:
        err = "; ".join(missing)[:1000]
    ref = Reference(nid, title, str(path), sha, [asdict(p) for p in parts], ans, err)
    if log:
        log(f"  reference {nid}: {len(parts)} parts, {len(answers)} answers "
            f"({time.monotonic() - t0:.1f} s){' ERROR: ' + err if err else ''}")
    if cache is not None and not err:
        Path(cache).mkdir(parents=True, exist_ok=True)
        cfile.write_text(json.dumps(asdict(ref)))
    return ref


def load_references(notebooks: Path, cache: Path | None, ids: set | None = None, log=None, jobs: int = 1) -> dict:
    """{notebook id: Reference} for the solution notebooks in ``notebooks`` (only ``ids`` if given)."""
    todo = {}
    for p in sorted(Path(notebooks).glob("*.ipynb")):
        try:
            nid = _nb_id(json.loads(p.read_bytes()))
        except (OSError, ValueError):
            continue
        if nid is None or (ids is not None and nid not in ids):
            continue
        todo[nid] = p
    if jobs <= 1 or len(todo) <= 1:
        return {nid: build_reference(p, cache, log=log) for nid, p in todo.items()}
    from concurrent.futures import ThreadPoolExecutor
    with ThreadPoolExecutor(max_workers=jobs) as pool:
        futures = {nid: pool.submit(build_reference, p, cache, log=log) for nid, p in todo.items()}
        return {nid: f.result() for nid, f in futures.items()}


# ----------------------------------------------------------------------------------------- one submission

def make_points(symbols: dict, seed: int, n: int) -> list[dict]:
    """``n`` random points {symbol name: value}: angles in (-π, π), positive symbols in (0.5, 2)."""
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


_PARSED: dict = {}


def _fast_expr(obj):
    """(template description, f) with f(point) -> values for a reference Matrix/expression, or None."""
    import numpy as np
    import sympy as sp
    tmpl = probe.describe_expr(obj, [], 0)
    syms = sorted((s for s in obj.free_symbols if isinstance(s, sp.Symbol)), key=lambda s: s.name)
    entries = list(obj) if isinstance(obj, sp.MatrixBase) else [obj]
    try:
        f = sp.lambdify(syms, entries, modules="numpy", cse=True)
    except Exception:  # noqa: BLE001
        return None

    def values(point):
        with np.errstate(all="ignore"):
            out = f(*[np.complex128(point[s.name]) for s in syms])
        row = [[float(np.real(v)), float(np.imag(v))] for v in (complex(x) for x in out)]
        if not all(math.isfinite(x) for v in row for x in v):
            raise ValueError("not finite")
        return row
    return tmpl, values


def _ref_desc(ref: Reference, name: str, kind: str, points: list, seed: int) -> dict:
    """The reference answer described like a student's (same code path; cached lambdified for speed)."""
    a = ref.answers[name]
    if "choice" in a:
        return a["choice"]
    key = (ref.sha, name)
    if key not in _PARSED:
        obj = probe.parse_srepr(a["srepr"])
        fast = _fast_expr(obj) if kind in ("expr", "subspace") and obj is not None and \
            probe.to_sympy(obj)[0] in ("matrix", "scalar") else None
        _PARSED[key] = (obj, fast)
    obj, fast = _PARSED[key]
    if fast is not None:
        try:
            tmpl, values = fast
            return dict(tmpl, values=[values(p) for p in points])
        except Exception:  # noqa: BLE001  fall back to SymPy's evaluation
            pass
    return probe.describe(kind, obj, points, seed)


def _error_rows(sub, nid, parts, msg) -> list[Row]:
    if not parts:
        return [Row(sub, nid, "-", "error", 0, msg)]
    return [Row(sub, nid, p["part"], "error", 0, msg, p["points"]) for p in parts]


def grade_submission(path, refs: dict, cell_timeout: float = 60.0, total_timeout: float = 300.0,
                     display_name: str | None = None) -> dict:
    """Grade one file; returns {"rows": [Row], "cells": [...], "seconds": float, ...} (never raises)."""
    t0 = time.monotonic()
    sub = display_name or str(path)
    out = {"submission": sub, "notebook": "", "title": "", "rows": [], "cells": [], "restarts": 0,
           "output_bytes": 0}
    try:
        data = Path(path).read_bytes()
    except OSError as exc:
        out["rows"] = [Row(sub, "", "-", "error", 0, f"cannot read the file: {exc}")]
        return _done(out, t0)
    if len(data) > MAX_SUBMISSION_BYTES:
        out["rows"] = [Row(sub, "", "-", "error", 0, f"not graded: the file is larger than "
                                                      f"{MAX_SUBMISSION_BYTES // 2**20} MB")]
        return _done(out, t0)
    try:
        nb = json.loads(data.decode("utf-8"))
    except (UnicodeDecodeError, ValueError) as exc:
        out["rows"] = [Row(sub, "", "-", "error", 0, f"not a notebook: the file is not JSON ({str(exc)[:120]})")]
        return _done(out, t0)
    if not isinstance(nb, dict) or not isinstance(nb.get("cells"), list) or nb.get("nbformat", 4) < 4:
        out["rows"] = [Row(sub, "", "-", "error", 0, "not a notebook: JSON, but not a version-4 Jupyter notebook")]
        return _done(out, t0)
    nid = _nb_id(nb)
    if nid is None:
        out["rows"] = [Row(sub, "", "-", "error", 0, "not one of the kinlib notebooks: its metadata has no "
                                                      "kinlib.notebook (start from the workbook you were given)")]
        return _done(out, t0)
    out["notebook"] = nid
    ref = refs.get(nid)
    if ref is None:
        out["rows"] = [Row(sub, nid, "-", "error", 0, f"unknown notebook {nid!r}: no solution notebook with "
                                                       "that id")]
        return _done(out, t0)
    out["title"] = ref.title
    parts = ref.parts
    if ref.error:
        out["rows"] = _error_rows(sub, nid, parts, f"the reference for {nid} is broken: {ref.error}")
        return _done(out, t0)
    seed = int(hashlib.sha256(data).hexdigest()[:15], 16)
    symbols: dict = {}
    for a in ref.answers.values():
        symbols.update(a.get("symbols", {}))
    points = make_points(symbols, seed, N_POINTS)

    code = _code_cells(nb)
    part_of_cell = {}
    for i, c in enumerate(code):
        meta = (c.get("metadata") or {}).get("kinlib") or {}
        if isinstance(meta, dict) and meta.get("part") is not None:
            part_of_cell[i] = str(meta.get("part"))
    stash_after = stash_points(nb)

    tmp = tempfile.mkdtemp(prefix="kinlib-grade-")
    run = None
    try:
        scratch = os.path.join(tmp, "work")
        os.makedirs(scratch)
        with open(os.path.join(scratch, Path(path).name), "wb") as f:
            f.write(data)
        run = _Run(code, scratch, tmp, cell_timeout, total_timeout, stash_after=stash_after)
        rows, exact = _grade_in_kernel(run, sub, nid, ref, parts, points, seed, part_of_cell, out)
        out["restarts"] = run.restarts
        out["cells"] = [asdict(r) | {"part": part_of_cell.get(i, "")} for i, r in sorted(run.results.items())]
        out["output_bytes"] = sum(r.output_bytes for r in run.results.values())
    except Exception as exc:  # noqa: BLE001  a checker bug must not stop the batch
        rows, exact = _error_rows(sub, nid, parts, f"internal error in the checker: {type(exc).__name__}: {exc}"), {}
    finally:
        if run is not None:
            run.close()
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
                got, e = run.call(f"probe_answer(globals(), {name!r}, {kind!r}, {points[:n]!r}, {seed}, PATH)",
                                  PROBE_TIMEOUT)
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
        msgs, ok_all, err = [], True, False
        for name in p["answers"]:
            kind = ref.answers.get(name, {}).get("kind") or p["kinds"].get(name, "expr")
            ra = ref.answers.get(name, {})
            stu = results.get(name) or {"tag": "probe-error", "error": "no result"}
            if not isinstance(stu, dict):
                stu = {"tag": "probe-error", "error": "malformed result"}
            if stu.get("tag") == "probe-error" and stu.get("kernel"):
                err, ok_all = True, False
                msgs.append(f"{name} could not be read: {stu.get('error')}")
                continue
            n = N_SET_POINTS if kind == "set" else (0 if kind == "choice" else N_POINTS)
            try:
                rd = _ref_desc(ref, name, kind, points[:n], seed)
            except Exception as exc:  # noqa: BLE001
                err, ok_all = True, False
                msgs.append(f"{name}: the reference could not be evaluated ({exc})")
                continue
            ok, msg = compare.compare(kind, stu, rd, name)
            if ok and kind == "expr" and stu.get("tag") in ("matrix", "scalar") and "srepr" in ra:
                pending_exact.append((p["part"], name, ra["srepr"]))
            if not ok:
                ok_all = False
                msgs.append(msg + _cell_hint(p, run.results, part_of_cell))
            elif msg:
                msgs.append(f"{name}: {msg}")
        status = "pass" if ok_all else ("error" if err else "fail")
        rows.append(Row(sub, nid, p["part"], status, p["points"] if ok_all else 0, "; ".join(msgs), p["points"]))
    timing["compare"] = round(time.monotonic() - t2, 3)
    t3 = time.monotonic()
    # the advisory exact check, only now that every value is in
    if not fatal and run.kernel is not None and run.kernel.alive():
        for part, name, text in pending_exact:
            got, e = run.call(f"probe_exact(globals(), {name!r}, {text!r}, PATH)", EXACT_TIMEOUT)
            exact[name] = (got or {}).get("exact", "not checked") if isinstance(got, dict) else "not checked"
            if exact[name] != "equal":
                for r in rows:
                    if r.part == part and r.status == "pass":
                        note = (f"{name}: equal at {N_POINTS} random points, but SymPy did not prove it exactly "
                                f"({'timed out' if got is None else exact[name]})")
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
    return out


# ----------------------------------------------------------------------------------------- batch

def find_submissions(paths) -> list[Path]:
    """Files given, plus every .ipynb under folders given (hidden folders such as .ipynb_checkpoints
    skipped), in order."""
    found = []
    for p in map(Path, paths):
        if p.is_dir():
            found += sorted(q for q in p.rglob("*.ipynb")
                            if not any(part.startswith(".") for part in q.relative_to(p).parts[:-1]))
        elif p.exists():
            found.append(p)
        else:
            raise FileNotFoundError(f"no such file or folder: {p}")
    return found


def _peek_id(path: Path):
    try:
        with open(path, "rb") as f:
            data = f.read(MAX_SUBMISSION_BYTES + 1)
        return _nb_id(json.loads(data))
    except (OSError, ValueError, UnicodeDecodeError, AttributeError):
        return None


_REFS: dict = {}


def _init_worker(refs_json):
    global _REFS
    _REFS = {k: Reference(**v) for k, v in refs_json.items()}


def _work(args):
    path, name, cell_timeout, total_timeout = args
    return grade_submission(path, _REFS, cell_timeout, total_timeout, display_name=name)


def grade_batch(paths, out, jobs: int = 2, timeout: float = 300.0, cell_timeout: float = 60.0,
                notebooks=None, cache="default", log=print) -> dict:
    """Grade every submission in ``paths`` (files or folders) into ``out``; returns a summary dict.

    ``summary = {"results": [per-submission dict], "rows": [...], "seconds": wall time,
    "per_minute": submissions per minute, "reference_seconds": ...}``. Never raises for a bad submission.
    """
    t0 = time.monotonic()
    log = log or (lambda *a, **k: None)
    out = Path(out)
    subs = find_submissions(paths)
    notebooks = Path(notebooks) if notebooks else default_notebooks()
    if cache == "default":
        cache = notebooks.resolve().parent / "build" / "grade-cache"
    ids = {i for i in (_peek_id(p) for p in subs) if i}
    refs = load_references(notebooks, Path(cache) if cache else None, ids, log=log, jobs=max(1, int(jobs)))
    t_ref = time.monotonic() - t0
    names = _display_names(subs)
    jobs = max(1, int(jobs))
    work = [(str(p), n, cell_timeout, timeout) for p, n in zip(subs, names)]
    results = []
    if jobs == 1 or len(work) <= 1:
        for k, w in enumerate(work, 1):
            results.append(grade_submission(w[0], refs, cell_timeout, timeout, display_name=w[1]))
            _progress(log, k, len(work), results[-1])
    else:
        import multiprocessing as mp
        refs_json = {k: asdict(v) for k, v in refs.items()}
        with ProcessPoolExecutor(max_workers=min(jobs, len(work)), mp_context=mp.get_context("spawn"),
                                 initializer=_init_worker, initargs=(refs_json,)) as pool:
            for k, r in enumerate(pool.map(_work, work), 1):
                results.append(r)
                _progress(log, k, len(work), r)
    wall = time.monotonic() - t0
    write_outputs(out, results, refs)
    summary = {"results": results, "rows": [r for res in results for r in res["rows"]], "seconds": wall,
               "reference_seconds": t_ref, "n": len(results),
               "per_minute": 60 * len(results) / max(wall - t_ref, 1e-9) if results else 0.0}
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


# ----------------------------------------------------------------------------------------- outputs

def _md(s) -> str:
    return str(s).replace("|", "\\|").replace("\n", " ").replace("<", "&lt;")


def feedback_markdown(res: dict) -> str:
    rows = res["rows"]
    got = sum(r["points"] for r in rows)
    mx = sum(r.get("max_points", 0) for r in rows)
    lines = [f"# Feedback: {res.get('title') or res.get('notebook') or 'submission'}", "",
             f"Submission `{res['submission']}`" + (f" (notebook `{res['notebook']}`)" if res.get("notebook") else ""),
             "", f"**Score: {got:g} / {mx:g} points**", "",
             "| Part | Points | Result | Feedback |", "|---|---|---|---|"]
    for r in rows:
        lines.append(f"| {_md(r['part'])} | {r['points']:g} / {r.get('max_points', 0):g} | {r['status']} | "
                     f"{_md(r['message'])} |")
    bad = [c for c in res.get("cells", []) if c["status"] != "ok"]
    if bad or res.get("restarts"):
        lines += ["", "## Cells that did not run cleanly", ""]
        for c in bad:
            what = CellSummary.text(c)
            part = f" (part {c['part']})" if c.get("part") else ""
            lines.append(f"- code cell {c['index'] + 1}{part}: {_md(what)}")
        if res.get("restarts"):
            lines.append(f"- the kernel was restarted {res['restarts']} time(s); the cells that stopped it were "
                         "skipped")
    if res.get("restored") and isinstance(res["restored"], list):
        names = ", ".join(f"`{n}`" for n in res["restored"][:8]) + (" …" if len(res["restored"]) > 8 else "")
        lines += ["", f"Your notebook replaced {names}; the checker put the originals back before reading "
                      "your answers."]
    if res.get("output_bytes", 0) > 1_000_000:
        lines.append(f"- your notebook printed {res['output_bytes'] / 1e6:.1f} MB of output (not kept)")
    lines += ["", "How this was checked: your notebook ran top to bottom in a fresh Python kernel; each answer "
              "was evaluated at random joint angles and link lengths and compared with the solution's values "
              "there (matrices entry by entry, subspaces by their span, sets of configurations by their "
              "members, angles modulo 2π, choices as sets). A part passes when every answer in it matches.", ""]
    return "\n".join(lines)


class CellSummary:
    @staticmethod
    def text(c: dict) -> str:
        if c["status"] == "error":
            return f"raised {c['ename']}: {c['evalue']}".strip()
        return c.get("note") or c["status"]


def write_outputs(out: Path, results: list, refs: dict) -> None:
    out.mkdir(parents=True, exist_ok=True)
    fb = out / "feedback"
    fb.mkdir(exist_ok=True)
    with open(out / "grades.csv", "w", newline="") as f:
        w = csv.writer(f, lineterminator="\n")
        w.writerow(["submission", "notebook", "part", "status", "points", "message"])
        for res in results:
            for r in res["rows"]:
                w.writerow([r["submission"], r["notebook"], r["part"], r["status"], f"{r['points']:g}",
                            r["message"]])
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
    if not results:
        return "kinlib.grade: no submissions"
    w = max(10, min(48, max(len(r["submission"]) for r in results)))
    nbw = max(8, min(30, max(len(r["notebook"] or "-") for r in results)))
    lines = [f"{'submission':<{w}}  {'notebook':<{nbw}}  {'score':>9}  pass fail error  seconds"]
    for r in results:
        rows = r["rows"]
        got = sum(x["points"] for x in rows)
        mx = sum(x.get("max_points", 0) for x in rows)
        c = {s: sum(1 for x in rows if x["status"] == s) for s in ("pass", "fail", "error")}
        lines.append(f"{r['submission'][:w]:<{w}}  {(r['notebook'] or '-')[:nbw]:<{nbw}}  {got:>4g}/{mx:<4g}  "
                     f"{c['pass']:>4} {c['fail']:>4} {c['error']:>5}  {r['seconds']:7.1f}")
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
        lines.append("pass rate per part: " + ", ".join(f"{nb[:2]} {p}: {a}/{b}" for (nb, p), (a, b) in
                                                       sorted(per_part.items())))
    n = len(results)
    graded = wall - t_ref
    lines.append(f"{n} submission(s) in {wall:.1f} s ({t_ref:.1f} s for references), --jobs {jobs}: "
                 f"{60 * n / max(graded, 1e-9):.1f} submissions/minute")
    return "\n".join(lines)


# ----------------------------------------------------------------------------------------- CLI

def main(argv=None) -> int:
    ap = argparse.ArgumentParser(prog="python -m kinlib.grade",
                                 description="Grade completed kinlib workbooks against the solution notebooks.")
    ap.add_argument("submissions", nargs="+", help="submission notebooks, or folders (every .ipynb inside)")
    ap.add_argument("--out", required=True, type=Path, help="output folder (grades.csv, feedback/)")
    ap.add_argument("--timeout", type=float, default=300.0, help="seconds allowed per submission (default 300)")
    ap.add_argument("--cell-timeout", type=float, default=60.0, help="seconds allowed per cell (default 60)")
    ap.add_argument("--jobs", type=int, default=min(2, os.cpu_count() or 1),
                    help="submissions graded at once (default: 2 or the number of cores)")
    ap.add_argument("--notebooks", type=Path, default=None,
                    help="folder of solution notebooks (default: the repository's notebooks/)")
    ap.add_argument("--cache", type=Path, default=None,
                    help="reference cache folder (default: build/grade-cache next to the notebooks folder)")
    ap.add_argument("--quiet", action="store_true", help="print only the summary table")
    args = ap.parse_args(argv)
    if args.jobs < 1 or args.timeout <= 0 or args.cell_timeout <= 0:
        ap.error("--jobs, --timeout and --cell-timeout must be positive")
    try:
        subs = find_submissions(args.submissions)
    except FileNotFoundError as exc:
        ap.error(str(exc))
    if args.notebooks is not None and not args.notebooks.is_dir():
        ap.error(f"--notebooks {args.notebooks} is not a folder")
    if not subs:
        print("kinlib.grade: no .ipynb submissions found", file=sys.stderr)
    quiet = args.quiet
    log = (lambda s: None) if quiet else (lambda s: print(s, flush=True))
    summary = grade_batch(subs, args.out, jobs=args.jobs, timeout=args.timeout, cell_timeout=args.cell_timeout,
                          notebooks=args.notebooks, cache=args.cache if args.cache else "default", log=log)
    if quiet:
        print(summary_table(summary["results"], summary["seconds"], summary["reference_seconds"], args.jobs))
    print(f"wrote {args.out / 'grades.csv'} and {len(summary['results'])} feedback file(s) in {args.out / 'feedback'}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
