"""The grader's answer key: reference answers computed in the trusted process, kept as signed data.

* **Computed by the instructor's side only.** :func:`build_reference` executes a solution notebook in a
  kernel of the grader's own (instructor code; never a student kernel) and reads each answer as data:
  a SymPy value as a tree of the one wire format (:func:`kinlib.course.answers.wire.dump`, the encoder a
  student's kernel runs), a choice's JSON value, the symbols and their assumptions.
* **Data, never code.** The trees are read back by the parser that reads a student's answer
  (:func:`kinlib.course.answers.wire.load`: a whitelist with caps, nothing is ``eval``-ed), and evaluated at a
  submission's points here, in the grader (:func:`reference_description`).
* **Untrusted until verified.** A cache file whose tag does not verify, or that is not in this format (an
  older version's ``srepr`` text, a tree the parser refuses), is ignored and rebuilt (:func:`read_cache`).
* **Signed.** The cache (``<cache>/<id>-<hash>.json``) holds the reference and an HMAC-SHA256 tag keyed
  by the instructor's secret (:mod:`kinlib.course.grader.secret`); a file whose tag does not verify (edited,
  planted, or made with another secret) is ignored and rebuilt. The cache folder is never visible to a
  sandboxed student kernel (:mod:`kinlib.course.grader.isolation.sandbox`), nor is the notebooks folder.
"""

from __future__ import annotations

import fcntl
import hashlib
import json
import math
import shutil
import tempfile
import time
from dataclasses import asdict, dataclass
from pathlib import Path

from ..answers import describe, wire
from ..answers.expr import to_sympy
from ..answers.subspace import exact_tree
from ..schema import notebook_id, notebook_title, parse_parts, stash_points
from .isolation.kernel import SHIPPED, NotebookRun
from .secret import sign, verify

__all__ = [
    "Reference",
    "GRADE_VERSION",
    "build_reference",
    "load_references",
    "default_notebooks",
    "code_cells",
    "reference_description",
    "reference_value",
    "in_format",
    "read_cache",
    "reference_answers",
]

GRADE_VERSION = "4"  # 3: answers exported as data (in_kernel.export), described in the grader; 4: key as wire trees
_CACHE_PURPOSE = "kinlib-reference-cache"


@dataclass
class Reference:
    """A solution notebook's graded parts and reference answers (as the reference kernel described them).

    :func:`build_reference` makes them (and caches them as signed JSON, read back with ``Reference(**d)``):

    >>> ref = Reference("02_planar", "Planar arms", "notebooks/02_planar.ipynb", "0" * 64,
    ...                 parts=[{"part": "2.1", "points": 5.0, "answers": ["L"], "kinds": {"L": "expr"}}],
    ...                 answers={"L": {"kind": "expr", "tree": ["Symbol", "L", {"positive": True}],
    ...                                "symbols": {"L": {"positive": True}}}})
    >>> ref.error, [p["part"] for p in ref.parts]
    ('', ['2.1'])
    """

    notebook: str
    title: str
    path: str
    sha: str
    parts: list  # [schema.Part as dict]
    answers: dict  # name -> {"kind", "tree"/"choice", "symbols"} or {"error"}
    error: str = ""


def default_notebooks() -> Path:
    """The repository's ``notebooks/`` (next to the kinlib package), else ``notebooks`` in the cwd.

    >>> default_notebooks().name
    'notebooks'
    """
    p = Path(__file__).resolve().parents[3] / "notebooks"
    return p if p.is_dir() else Path("notebooks")


def code_cells(nb: dict) -> list:
    """The code cells of notebook ``nb`` (a dict), in order.

    >>> len(code_cells({"cells": [{"cell_type": "code"}, {"cell_type": "markdown"}, "junk"]}))
    1
    """
    return [c for c in nb.get("cells", []) if isinstance(c, dict) and c.get("cell_type") == "code"]


def _hash(data: bytes) -> str:
    h = hashlib.sha256(data)
    # every module that reads and describes an answer (the answers package: kinds, wire, ...)
    host = [p.read_text() for p in sorted(Path(describe.__file__).parent.glob("*.py"))]
    for s in (*SHIPPED.values(), *host, GRADE_VERSION):
        h.update(s.encode())
    return h.hexdigest()


def _canonical(d: dict) -> bytes:
    return json.dumps(d, sort_keys=True, separators=(",", ":"), ensure_ascii=True).encode()


def read_cache(cfile: Path, secret: bytes, sha: str) -> Reference | None:
    """The Reference in cache file ``cfile`` if its tag verifies with ``secret`` and it is for ``sha``; else None.

    >>> import tempfile
    >>> with tempfile.TemporaryDirectory() as d:
    ...     _ = (Path(d) / "x.json").write_text('{"reference": {}, "mac": "0"}')
    ...     read_cache(Path(d) / "x.json", b"k" * 32, "0" * 64) is None
    True
    """
    try:
        with open(cfile, "rb") as f:
            d = json.loads(f.read(50 * 2**20))
        ref = d["reference"]
        if not verify(secret, _CACHE_PURPOSE, _canonical(ref), d.get("mac")) or ref.get("sha") != sha:
            return None
        ref = Reference(**ref)
        return ref if in_format(ref) else None
    except (OSError, ValueError, TypeError, KeyError, AttributeError, RecursionError):
        return None


def in_format(ref: Reference) -> bool:
    """Whether every answer of ``ref`` is in this version's format: an error, a choice, or a wire tree that
    :func:`kinlib.course.answers.wire.load` reads (an older cache's ``srepr`` text is not: rebuilt).

    >>> in_format(Reference("n", "t", "p", "0", [], {"a": {"kind": "expr", "srepr": "Integer(1)", "symbols": {}}}))
    False
    """
    if not isinstance(ref.answers, dict):
        return False
    for name, a in ref.answers.items():
        if not isinstance(a, dict) or "srepr" in a:
            return False
        if "error" in a or "choice" in a:
            continue
        if not isinstance(a.get("kind"), str):
            return False
        try:
            reference_value(ref, name)
        except (wire.WireError, RecursionError):
            return False
    return True


def _write_cache(cfile: Path, secret: bytes, ref: Reference) -> None:
    d = asdict(ref)
    cfile.parent.mkdir(parents=True, exist_ok=True, mode=0o700)
    tmp = cfile.with_name(cfile.name + f".{time.monotonic_ns()}.tmp")
    tmp.write_text(json.dumps({"reference": d, "mac": sign(secret, _CACHE_PURPOSE, _canonical(d))}))
    tmp.replace(cfile)


def reference_answers(exported: dict, kinds: dict) -> dict:
    """{name: {"kind", "tree", "symbols"} | {"kind", "choice"} | {"error"}} for the reference answers ``kinds`` =
    {name: kind}, from what the reference kernel exported (``{"tree": ...}`` per name, as
    :func:`kinlib.course.grader.in_kernel.export.export_answer` writes it): each read by the same parser as a
    student's (:func:`kinlib.course.answers.wire.load`) and normalised here (:func:`~kinlib.course.answers.describe.dump_reference`).

    >>> reference_answers({"n": {"tree": ["int", "2"]}, "J": {"missing": True}}, {"n": "choice", "J": "expr"})
    {'n': {'choice': {'tag': 'choice', 'type': 'int', 'value': 2}, 'kind': 'choice'}, 'J': {'error': 'J is not defined after the solution notebook ran'}}
    """
    values, errors = {}, {}
    for name in kinds:
        got = exported.get(name)
        if isinstance(got, dict) and "tree" in got:
            try:
                values[name] = wire.load(got["tree"], max_nodes=10 * wire.MAX_NODES)
            except (wire.WireError, RecursionError) as exc:
                errors[name] = {"error": f"{name}: {exc}"[:500]}
        elif isinstance(got, dict) and not got.get("missing"):
            errors[name] = {"error": f"{name}: {got.get('error') or got.get('too_large') or 'not exported'}"[:500]}
    dumped = describe.dump_reference(values, {n: k for n, k in kinds.items() if n not in errors})
    return {n: errors.get(n) or dumped[n] for n in kinds}


def _run_solution(path: Path, nb: dict, kinds: dict, timeout: float) -> tuple[dict, str]:
    """(answers, error): the solution notebook run in the grader's own kernel, each answer exported as data as a
    student's is, read and described here (:func:`reference_answers`); the error says what failed ("" if none)."""
    tmp = tempfile.mkdtemp(prefix="kinlib-grade-ref-")
    err = ""
    ans: dict = {}
    run = NotebookRun(
        code_cells(nb),
        str(path.parent.resolve()),
        tmp,
        cell_timeout=timeout,
        total_timeout=timeout * 4,
        stash_after=stash_points(nb),
        snapshot=False,
    )
    try:
        run.execute()
        bad = [r for r in run.results.values() if r.status != "ok"]
        if bad:
            err = f"code cell {bad[0].index + 1} of the solution notebook: {bad[0].summary()}"
        exported = {}
        for name in kinds:
            got, e = run.call(f"export_answer(globals(), {name!r}, PATH)", timeout=120)
            exported[name] = got if got is not None else {"error": f"could not read the reference answer: {e}"}
        ans = reference_answers(exported, kinds)
    except RuntimeError as exc:
        err = str(exc)
    finally:
        run.close()
        shutil.rmtree(tmp, ignore_errors=True)
    missing = [f"{n}: {a['error']}" for n, a in ans.items() if "error" in a]
    if missing and not err:
        err = "; ".join(missing)[:1000]
    for n, a in ans.items():  # the key must read back as data now, not fail later at grading time
        if "tree" in a and not err:
            try:
                wire.load(a["tree"], max_nodes=10 * wire.MAX_NODES)
            except (wire.WireError, RecursionError) as exc:
                err = f"{n}: {exc}"
    return ans, err


def build_reference(
    path: Path, cache: Path | None = None, timeout: float = 300.0, log=None, secret: bytes | None = None
) -> Reference:
    """Execute the solution notebook ``path`` and read its answers (cached by content hash when ``cache`` and
    ``secret`` are given; a cache file whose HMAC tag does not verify is rebuilt, never used).

    It runs the notebook in a Jupyter kernel (seconds; tests/course/test_grade.py exercises it), hence not run here:

    >>> ref = build_reference(Path("notebooks/02_planar_robot_jacobian.ipynb"), cache=None)  # doctest: +SKIP
    >>> ref.notebook, ref.error  # doctest: +SKIP
    ('02_planar_robot_jacobian', '')
    """
    path = Path(path)
    data = path.read_bytes()
    sha = _hash(data)
    nb = json.loads(data)
    nid = notebook_id(nb) or path.stem
    cfile = Path(cache) / f"{nid}-{sha[:16]}.json" if cache is not None and secret else None
    if cfile is None:
        return _build(path, nb, nid, sha, None, timeout, log, secret)
    cfile.parent.mkdir(parents=True, exist_ok=True, mode=0o700)
    # graders sharing a cache (two batches at once, a batch's threads) run each solution notebook once: the
    # first builds it under the lock, the others wait and read its cache file
    with open(cfile.parent / f".{cfile.name}.lock", "a") as lock:
        fcntl.flock(lock, fcntl.LOCK_EX)
        if cfile.exists():
            ref = read_cache(cfile, secret, sha)
            if ref is not None:
                return ref
            if log:
                log(f"  reference cache {cfile.name}: signature does not verify; ignored and rebuilt")
        return _build(path, nb, nid, sha, cfile, timeout, log, secret)


def _build(path: Path, nb: dict, nid: str, sha: str, cfile, timeout: float, log, secret) -> Reference:
    """:func:`build_reference`'s kernel run, written to ``cfile`` (signed) when it is not None and it worked."""
    t0 = time.monotonic()
    parts = parse_parts(nb)
    title = notebook_title(nb, nid)
    kinds = {n: k for p in parts for n, k in p.kinds.items()}
    ans, err = _run_solution(path, nb, kinds, timeout)
    ref = Reference(nid, title, str(path), sha, [asdict(p) for p in parts], ans, err)
    if log:
        log(
            f"  reference {nid}: {len(parts)} parts, {len(kinds)} answers "
            f"({time.monotonic() - t0:.1f} s){' ERROR: ' + err if err else ''}"
        )
    if cfile is not None and not err:
        _write_cache(cfile, secret, ref)
    return ref


def load_references(
    notebooks: Path, cache: Path | None, ids: set | None = None, log=None, jobs: int = 1, secret: bytes | None = None
) -> dict:
    """{notebook id: Reference} for the solution notebooks in ``notebooks`` (only ``ids`` if given).

    Each one is a :func:`build_reference` (a kernel run, or a verified cache file); notebooks without a
    ``kinlib.notebook`` id are not references:

    >>> import tempfile
    >>> with tempfile.TemporaryDirectory() as d:
    ...     _ = (Path(d) / "scratch.ipynb").write_text('{"cells": [], "metadata": {}}')
    ...     load_references(Path(d), cache=None)
    {}
    >>> refs = load_references(default_notebooks(), cache=None, ids={"02_planar_robot_jacobian"})  # doctest: +SKIP
    >>> list(refs)  # doctest: +SKIP
    ['02_planar_robot_jacobian']
    """
    todo = {}
    for p in sorted(Path(notebooks).glob("*.ipynb")):
        try:
            nid = notebook_id(json.loads(p.read_bytes()))
        except (OSError, ValueError):
            continue
        if nid is None or (ids is not None and nid not in ids):
            continue
        todo[nid] = p
    if jobs <= 1 or len(todo) <= 1:
        return {nid: build_reference(p, cache, log=log, secret=secret) for nid, p in todo.items()}
    from concurrent.futures import ThreadPoolExecutor

    with ThreadPoolExecutor(max_workers=jobs) as pool:
        futures = {nid: pool.submit(build_reference, p, cache, log=log, secret=secret) for nid, p in todo.items()}
        return {nid: f.result() for nid, f in futures.items()}


# ----------------------------------------------------------------------------------------- evaluation

_PARSED: dict = {}


def _fast_expr(obj):
    """(template description, f) with f(point) -> values for a reference Matrix/expression, or None."""
    import numpy as np
    import sympy as sp

    tmpl = describe.describe_expr(obj, [], 0)
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


def reference_value(ref: Reference, name: str):
    """The reference answer ``name`` as a SymPy value (or a dict of them): its wire tree read back by
    :func:`kinlib.course.answers.wire.load`, the parser that reads a student's answer (never ``eval``).

    >>> reference_value(Reference("n", "t", "p", "0", [], {"L": {"kind": "expr", "tree": ["Symbol", "L", {}]}}), "L")
    L
    """
    import sympy as sp

    value = wire.load(ref.answers[name]["tree"], max_nodes=10 * wire.MAX_NODES)
    stack = [value]  # SymPy values, in dicts (keyed by name or symbol) and lists: no plain data the key never holds
    while stack:
        v = stack.pop()
        if isinstance(v, dict):
            stack += [k for k in v if not isinstance(k, str)] + list(v.values())
        elif isinstance(v, (list, tuple)):
            stack += list(v)
        elif not isinstance(v, (sp.Basic, sp.MatrixBase)):
            raise wire.WireError(f"a reference answer holds a {type(v).__name__}, not SymPy values")
    return value


def reference_description(ref: Reference, name: str, kind: str, points: list, seed: int) -> dict:
    """The reference answer ``name`` described like a student's, at ``points`` (the same code path as a
    student's, :func:`kinlib.course.answers.describe.describe`; the parsed tree and its lambdified form are cached per process).

    >>> ref = Reference("n", "t", "p", "0" * 64, [], {"x2": {"kind": "expr", "tree": ["Pow", ["Symbol", "x", {}], ["Integer", "2"]],
    ...                                                      "symbols": {"x": {}}}})
    >>> reference_description(ref, "x2", "expr", [{"x": 3.0}], 0)["values"]
    [[[9.0, 0.0]]]
    """
    a = ref.answers[name]
    if "choice" in a:
        return a["choice"]
    key = (name, _canonical({"t": a["tree"]}))  # by the tree itself: a different tree is never served from here
    if key not in _PARSED:
        obj = reference_value(ref, name)
        fast = (
            _fast_expr(obj)
            if kind in ("expr", "subspace") and obj is not None and to_sympy(obj)[0] in ("matrix", "scalar")
            else None
        )
        _PARSED[key] = (obj, fast)
    obj, fast = _PARSED[key]
    if fast is not None:
        try:
            tmpl, values = fast
            out = dict(tmpl, values=[values(p) for p in points])
            if kind == "subspace" and not tmpl.get("symbols") and not tmpl.get("has_float"):
                tree = exact_tree(obj)  # a constant exact span: compared exactly (subspace.compare_subspace)
                if tree is not None:
                    out["tree"] = tree
            return out
        except Exception:  # noqa: BLE001  fall back to SymPy's evaluation
            pass
    return describe.describe(kind, obj, points, seed)
