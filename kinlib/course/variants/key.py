"""The roster, each student's proved variant, and the signed key the grader reads.

:func:`build_key` draws each student's variant of every notebook that declares variants
(:func:`~kinlib.course.variants.draw.draw`), proves it (the notebook's own code re-run for it in a kernel,
:mod:`~kinlib.course.variants.replay`; its answers compared with the original's,
:mod:`~kinlib.course.variants.structure`), and redraws a rejected draw (attempt 1, 2, …), recording why.
Each distinct variant is proved once, whoever draws it; a key built before for the same notebook bytes and the
same kinlib code lends its proofs (a second build with the same roster runs no kernel).

The key is JSON signed with the course secret (:func:`write_key`); :func:`read_key` returns None for a file whose
tag does not verify or that is not a key, so a damaged or edited key is refused, never trusted and never a crash.
The pictures of each variant (for its problem page) are kept beside it, unsigned and never read by the grader
(:func:`write_outputs`).

>>> roster = read_roster_text("id,name\\nada,Ada L.\\nbob,\\n")
>>> [(s.id, s.name) for s in roster]
[('ada', 'Ada L.'), ('bob', '')]
"""

from __future__ import annotations

import csv
import io
import json
import re
import time
from concurrent.futures import ThreadPoolExecutor
from dataclasses import asdict, dataclass, field, replace
from pathlib import Path

from ..grader.secret import sign, verify
from ..schema import notebook_id
from .draw import draw, variant_key
from .spec import Spec
from .structure import differences, signature

__all__ = [
    "Student",
    "Variant",
    "NotebookKey",
    "Key",
    "VariantError",
    "read_roster",
    "read_roster_text",
    "build_key",
    "write_key",
    "read_key",
    "reference_for",
    "write_outputs",
    "read_outputs",
    "KEY_VERSION",
]

KEY_VERSION = 1
_PURPOSE = "kinlib-variants-key"
_ID = re.compile(r"[A-Za-z0-9._@+-]{1,64}\Z")
MAX_STUDENTS = 5000


class VariantError(RuntimeError):
    """No well-posed variant could be drawn (or the notebook could not be run): names the notebook and why.

    >>> str(VariantError("05: no well-posed variant for student 'ada' in 50 draws"))[:2]
    '05'
    """


@dataclass(frozen=True)
class Student:
    """One roster row: the id the grader sees (folder or file name for ``kinlib grade``, the platform's id for
    Gradescope/PrairieLearn), and optionally a name and an e-mail address.

    >>> Student("ada", "Ada L.").id
    'ada'
    """

    id: str
    name: str = ""
    email: str = ""


def read_roster_text(text: str, where: str = "roster") -> list[Student]:
    """Students from CSV text with a header (column ``id`` required; ``name``, ``email`` optional). Ids are 1–64
    characters of ``A-Za-z0-9._@+-`` and unique; a bad row raises ValueError naming it.

    >>> read_roster_text("id\\nada\\nada\\n")
    Traceback (most recent call last):
        ...
    ValueError: roster row 3: id 'ada' appears twice
    >>> read_roster_text("name\\nAda\\n")
    Traceback (most recent call last):
        ...
    ValueError: roster: the header has no 'id' column
    """
    rows = list(csv.reader(io.StringIO(text)))
    if not rows:
        raise ValueError(f"{where}: empty")
    header = [h.strip().lower() for h in rows[0]]
    if "id" not in header:
        raise ValueError(f"{where}: the header has no 'id' column")
    col = {h: header.index(h) for h in ("id", "name", "email") if h in header}
    out, seen = [], set()
    for n, row in enumerate(rows[1:], start=2):
        if not any(c.strip() for c in row):
            continue
        get = {h: (row[i].strip() if i < len(row) else "") for h, i in col.items()}
        sid = get["id"]
        if not _ID.match(sid):
            raise ValueError(f"{where} row {n}: id {sid!r} is not 1-64 characters of A-Za-z0-9._@+-")
        if sid in seen:
            raise ValueError(f"{where} row {n}: id {sid!r} appears twice")
        seen.add(sid)
        out.append(Student(sid, get.get("name", "")[:200], get.get("email", "")[:200]))
    if len(out) > MAX_STUDENTS:
        raise ValueError(f"{where}: more than {MAX_STUDENTS} students")
    return out


def read_roster(path) -> list[Student]:
    """Students from a roster CSV file (:func:`read_roster_text`).

    >>> read_roster("/nonexistent/roster.csv")
    Traceback (most recent call last):
        ...
    FileNotFoundError: roster: no file /nonexistent/roster.csv
    """
    p = Path(path)
    if not p.is_file():
        raise FileNotFoundError(f"roster: no file {p}")
    return read_roster_text(p.read_text(encoding="utf-8-sig"), f"roster {p.name}")


@dataclass
class Variant:
    """A proved variant: its values, its reference answers (``Reference.answers`` format), the self-check
    fingerprints of its answers ({"cell|name": {"spec", "describe"}}), and (not in the key) its pictures.

    >>> Variant({"L": "2"}, {}, {}).outputs
    {}
    """

    values: dict
    answers: dict
    fingerprints: dict
    outputs: dict = field(default_factory=dict)


@dataclass
class NotebookKey:
    """One notebook's variants: the spec it was built from, the proved variants, each student's, the rejections.

    >>> NotebookKey("05", "0" * 64, {}, {}).students
    {}
    """

    notebook: str
    sha: str
    spec: dict
    original: dict
    variants: dict = field(default_factory=dict)  # vkey -> Variant
    students: dict = field(default_factory=dict)  # student id -> vkey
    rejected: dict = field(default_factory=dict)  # vkey -> why (each distinct rejected draw, proved once)
    rejections: list = field(default_factory=list)  # [{"student", "attempt", "variant", "why"}]
    seconds: float = 0.0
    code: str = ""  # the kinlib code and pins the proofs were made with (a proof is lent only to the same code)


@dataclass
class Key:
    """Every notebook's variants (by notebook id) and the roster they were drawn for.

    >>> Key().stats()
    {}
    """

    notebooks: dict = field(default_factory=dict)
    roster: list = field(default_factory=list)  # [Student as dict]
    version: int = KEY_VERSION

    def stats(self) -> dict:
        """{notebook: {"students", "variants", "drawn", "rejected", "reasons": {why: count}, "seconds"}}."""
        out = {}
        for nid, nk in self.notebooks.items():
            reasons: dict = {}
            for r in nk.rejections:
                reasons[r["why"]] = reasons.get(r["why"], 0) + 1
            out[nid] = {
                "students": len(nk.students),
                "variants": len(set(nk.students.values())),
                "drawn": len(nk.students) + len(nk.rejections),
                "rejected": len(nk.rejections),
                "reasons": reasons,
                "seconds": round(nk.seconds, 1),
            }
        return out


# ---------------------------------------------------------------------------------------------------
# Building: draw, prove, redraw


def _variant_from_run(run) -> Variant:
    """The proved variant of a replay run. Its pictures are what students may see: a cell that states a graded
    answer keeps only its students' version (``run.students``), never the instructor's picture."""
    fps = {f"{i}|{name}": fp for (i, name), fp in run.fingerprints.items()}
    students = getattr(run, "students", {}) or {}
    outputs = {i: students[i] if i in students else o for i, o in run.outputs.items()}
    return Variant(dict(run.values), run.answers, fps, outputs)


class _Prover:
    """Proves variants of one notebook on demand, starting its replay kernel only when a proof is needed."""

    def __init__(self, path: Path, spec: Spec, timeout: float):
        self.path, self.spec, self.timeout = path, spec, timeout
        self.session = None
        self.original_sig = None

    def prove(self, values) -> tuple[Variant | None, str]:
        from .replay import Session

        if self.session is None:
            self.session = Session(self.path, self.spec, timeout=self.timeout)
            orig = self.session.original
            if orig.error:
                raise VariantError(f"{self.path.name}: the original does not run: {orig.error}")
            self.original_sig = signature(orig.answers)
        run = self.session.run(values)
        if run.error:
            return None, f"the notebook fails: {run.error}"[:300]
        orig = self.session.original
        why = differences(self.original_sig, signature(run.answers, orig.answers, self.original_sig))
        return (None, "; ".join(why)[:300]) if why else (_variant_from_run(run), "")

    def close(self):
        if self.session is not None:
            self.session.close()


def _key_for_notebook(path, nb, spec, roster, secret, previous, max_attempts, timeout, log) -> NotebookKey:
    import hashlib

    t0 = time.monotonic()
    nid = notebook_id(nb) or path.stem
    sha = hashlib.sha256(path.read_bytes()).hexdigest()
    nk = NotebookKey(nid, sha, nb["metadata"]["kinlib"]["variants"], dict(spec.original))
    from ..publish.incremental import code_key

    nk.code = code_key()
    old = previous.notebooks.get(nid) if previous is not None else None
    if old is not None and old.sha == sha and old.code == nk.code:  # same notebook, same engine: the proofs hold
        nk.variants, nk.rejected = dict(old.variants), dict(old.rejected)
    prover = _Prover(path, spec, timeout)
    try:
        pending = {s.id: 0 for s in roster}
        while pending:
            nxt = {}
            for sid, attempt in pending.items():
                values = draw(secret, sid, nid, spec, attempt)
                vk = variant_key(values)
                if vk not in nk.variants and vk not in nk.rejected:
                    variant, why = prover.prove(values)
                    if variant is None:
                        nk.rejected[vk] = why
                    else:
                        nk.variants[vk] = variant
                if vk in nk.variants:
                    nk.students[sid] = vk
                    continue
                nk.rejections.append({"student": sid, "attempt": attempt, "variant": vk, "why": nk.rejected[vk]})
                if attempt + 1 >= max_attempts:
                    raise VariantError(
                        f"{nid}: no well-posed variant for student {sid!r} in {max_attempts} draws "
                        f"(the last: {nk.rejected[vk]}); widen the notebook's choices"
                    )
                nxt[sid] = attempt + 1
            pending = nxt
    finally:
        prover.close()
    used = set(nk.students.values())
    nk.variants = {k: v for k, v in nk.variants.items() if k in used}
    nk.seconds = time.monotonic() - t0
    return nk


def build_key(
    notebooks,
    roster: list,
    secret: bytes,
    *,
    only=None,
    max_attempts: int = 50,
    timeout: float = 120.0,
    previous: Key | None = None,
    jobs: int = 2,
    log=print,
) -> Key:
    """Each student's proved variant of every notebook (``NN_*.ipynb`` in ``notebooks``) that declares variants.

    ``previous`` (a key read back with :func:`read_key`) lends the proofs of notebooks whose bytes are unchanged,
    made with the same kinlib code and pins (a change to the engine or to the proof's rules proves them again).
    ``jobs`` notebooks are proved at once (each in its own kernel).
    Raises VariantError when a student gets no well-posed variant in ``max_attempts`` draws.

    It runs notebooks in a Jupyter kernel (tests/course/test_variants.py exercises it), hence not run here:

    >>> key = build_key(Path("notebooks"), read_roster("roster.csv"), b"s" * 32)  # doctest: +SKIP
    >>> key.stats()["05_singularities_planar"]["rejected"]  # doctest: +SKIP
    0
    """
    if not roster:
        raise ValueError("roster: no students")
    key = Key(roster=[asdict(s) for s in roster])
    paths = sorted(Path(notebooks).glob("[0-9][0-9]_*.ipynb"))
    if only:
        paths = [p for p in paths if any(p.stem.startswith(o) for o in only)]
    todo = []
    for path in paths:
        nb = json.loads(path.read_bytes())
        spec = Spec.from_notebook(nb)
        if spec is not None:
            todo.append((path, nb, spec))

    def one(item):
        path, nb, spec = item
        return _key_for_notebook(path, nb, spec, roster, secret, previous, max_attempts, timeout, log)

    with ThreadPoolExecutor(max_workers=max(1, min(jobs, len(todo) or 1))) as pool:  # a kernel per notebook
        done = list(pool.map(one, todo))
    for nk in done:
        key.notebooks[nk.notebook] = nk
        st = key.stats()[nk.notebook]
        log(
            f"  variants {nk.notebook}: {st['students']} students, {st['variants']} variants proved well-posed, "
            f"{st['rejected']} of {st['drawn']} draws rejected ({nk.seconds:.1f} s)"
        )
        for why, n in sorted(st["reasons"].items(), key=lambda kv: -kv[1]):
            log(f"    rejected {n}x: {why}")
    return key


# ---------------------------------------------------------------------------------------------------
# The signed file


def _body(key: Key) -> dict:
    nbs = {}
    for nid, nk in key.notebooks.items():
        d = asdict(nk)
        for v in d["variants"].values():
            v.pop("outputs", None)
        nbs[nid] = d
    return {"version": key.version, "roster": key.roster, "notebooks": nbs}


def _data(body: dict) -> bytes:
    return json.dumps(body, sort_keys=True, separators=(",", ":")).encode()


def write_key(path, key: Key, secret: bytes) -> Path:
    """Write ``key`` signed with ``secret`` (without the pictures: :func:`write_outputs`).

    >>> import tempfile, os
    >>> p = write_key(os.path.join(tempfile.mkdtemp(), "key.json"), Key(), b"s" * 32)
    >>> read_key(p, b"s" * 32).notebooks, read_key(p, b"t" * 32)
    ({}, None)
    """
    body = _body(key)
    p = Path(path)
    p.parent.mkdir(parents=True, exist_ok=True)
    tmp = p.with_name(p.name + ".tmp")
    tmp.write_text(json.dumps({"key": body, "tag": sign(secret, _PURPOSE, _data(body))}))
    tmp.replace(p)
    return p


def read_key(path, secret: bytes) -> Key | None:
    """The key in ``path``, or None when it is missing, damaged, not a key, or its tag does not verify.

    >>> read_key("/nonexistent/key.json", b"s" * 32) is None
    True
    """
    try:
        d = json.loads(Path(path).read_bytes())
        body = d["key"]
        if not verify(secret, _PURPOSE, _data(body), d["tag"]) or body.get("version") != KEY_VERSION:
            return None
        nbs = {}
        for nid, n in body["notebooks"].items():
            variants = {k: Variant(**v) for k, v in n.pop("variants").items()}
            nbs[nid] = NotebookKey(**n, variants=variants)
        return Key(nbs, list(body["roster"]), body["version"])
    except (OSError, ValueError, KeyError, TypeError, AttributeError):
        return None


def write_outputs(path, key: Key) -> Path:
    """The pictures of every variant ({notebook: {variant: {cell: outputs}}}), for the per-student pages.

    >>> import tempfile, os
    >>> p = write_outputs(os.path.join(tempfile.mkdtemp(), "outputs.json"), Key())
    >>> read_outputs(p)
    {}
    """
    data = {nid: {vk: v.outputs for vk, v in nk.variants.items()} for nid, nk in key.notebooks.items()}
    p = Path(path)
    p.parent.mkdir(parents=True, exist_ok=True)
    p.write_text(json.dumps(data))
    return p


def read_outputs(path) -> dict:
    """What :func:`write_outputs` wrote, or {} when it is missing or damaged (the build then re-runs the variants).

    >>> read_outputs("/nonexistent/outputs.json")
    {}
    """
    try:
        d = json.loads(Path(path).read_bytes())
        return d if isinstance(d, dict) else {}
    except (OSError, ValueError):
        return {}


# ---------------------------------------------------------------------------------------------------
# Grading


def reference_for(ref, key: Key, student_id: str):
    """(the student's own reference, its variant key) for the notebook of ``ref``: ``ref`` itself with the
    answers of the student's variant. A notebook without variants gives ``(ref, None)``; a student who is not on
    the key's roster raises KeyError.

    >>> from kinlib.course.grader.refdata import Reference
    >>> ref = Reference("05", "t", "p", "0" * 64, parts=[], answers={"r": {"kind": "expr", "tree": ["Integer", "2"]}})
    >>> nk = NotebookKey("05", "0" * 64, {}, {}, variants={"v1": Variant({}, {"r": {"kind": "expr",
    ...     "tree": ["Integer", "1"]}}, {})}, students={"ada": "v1"})
    >>> mine, vk = reference_for(ref, Key({"05": nk}), "ada")
    >>> vk, mine.answers["r"]["tree"], ref.answers["r"]["tree"]
    ('v1', ['Integer', '1'], ['Integer', '2'])
    """
    nk = key.notebooks.get(ref.notebook)
    if nk is None:
        return ref, None
    vk = nk.students.get(student_id)
    if vk is None:
        raise KeyError(f"student {student_id!r} is not on the roster of the variants key")
    return replace(ref, answers={**ref.answers, **nk.variants[vk].answers}), vk
