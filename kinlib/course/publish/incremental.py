"""Incremental handouts: each output is keyed by a hash of what it is made from, and reused while that holds.

``make handouts`` run twice in a row should not execute six notebooks, rebuild the in-browser site and print
twelve PDFs again. :func:`kinlib.course.publish.handouts.build` asks this module, for each step, whether the
outputs already in ``out/`` were made from the same inputs:

* a **section** (the executed notebook, its problems and solutions pages and its workbook) from the notebook's
  bytes, every source file of the installed kinlib package (:func:`code_key`), the pinned environment
  (``environment.txt``) and the build options that change the pages;
* the **site** (``out/lite``) from the keys of the sections and the solution notebooks it holds;
* each **PDF** from the bytes of the page it prints and :func:`code_key`.

A key is a SHA-256 hex digest. The stamps, and the executed notebooks a reused section needs, live *beside*
``out``, in ``<out's parent>/.kinlib-build/<out's name>/`` (:func:`stamp_dir`), never inside it: ``out`` is what
gets published, and an executed notebook holds the solutions (a students' build must hold none). One JSON file
per output, written only after the output is complete, so a build that stops half way is redone next time;
``--fresh`` removes them. Nothing here looks at modification times: a ``git checkout`` that restores a file restores its key.

>>> import tempfile
>>> with tempfile.TemporaryDirectory() as d:
...     stamps = Stamps(Path(d))
...     before = stamps.current("section-02", "abc", [])
...     stamps.record("section-02", "abc", {"stem": "02"})
...     after = stamps.current("section-02", "abc", [])
...     other = stamps.current("section-02", "abd", [])
>>> before, after, other
(None, {'stem': '02'}, None)
"""

from __future__ import annotations

import hashlib
import json
import shutil
from collections.abc import Iterable
from concurrent.futures import ThreadPoolExecutor
from functools import lru_cache
from pathlib import Path

import nbformat

import kinlib

__all__ = [
    "STAMP_DIR",
    "Stamps",
    "adopt_sections",
    "build_sections",
    "build_site",
    "code_key",
    "key",
    "print_changed_pdfs",
    "stamp_dir",
]

#: the folder beside ``out`` (in its parent) that holds the stamps of every output folder there
STAMP_DIR = ".kinlib-build"


def stamp_dir(out: Path) -> Path:
    """Where the stamps of the output folder ``out`` live: beside it, never inside (``out`` is published).

    >>> stamp_dir(Path("build/handouts-students")).as_posix()
    'build/.kinlib-build/handouts-students'
    """
    out = Path(out)
    return out.parent / STAMP_DIR / out.name


#: the files of the package whose bytes make up :func:`code_key` (code, and the assets the pages embed)
_CODE_SUFFIXES = (".py", ".js", ".css", ".html", ".json", ".txt")


def key(*parts) -> str:
    """SHA-256 of the parts (bytes as they are, anything else as its JSON text, keys sorted).

    >>> key(b"a", {"x": 1}) == key(b"a", {"x": 1}) != key(b"a", {"x": 2})
    True
    """
    h = hashlib.sha256()
    for p in parts:
        data = p if isinstance(p, bytes) else json.dumps(p, sort_keys=True, default=str).encode()
        h.update(len(data).to_bytes(8, "little"))
        h.update(data)
    return h.hexdigest()


@lru_cache(maxsize=1)
def code_key() -> str:
    """One key for the code the handouts are made with: every source file of the kinlib package, by relative
    path and bytes, and the pinned environment (``environment.txt`` beside the package in a checkout; the
    installed package's version otherwise). Computed once per process.

    >>> len(code_key()), code_key() == code_key()
    (64, True)
    """
    pkg = Path(kinlib.__file__).resolve().parent
    files = sorted(
        p for p in pkg.rglob("*") if p.is_file() and p.suffix in _CODE_SUFFIXES and "__pycache__" not in p.parts
    )
    parts: list = [kinlib.__version__]
    for p in files:
        parts += [p.relative_to(pkg).as_posix(), p.read_bytes()]
    env = pkg.parent / "environment.txt"
    parts.append(env.read_bytes() if env.is_file() else b"")
    return key(*parts)


class Stamps:
    """The stamps of one output folder: ``current(name, key, files)`` gives what was recorded for ``name`` when
    it was made with ``key`` and every file in ``files`` still exists, else None; ``record(name, key, data)``
    writes it (call it after the output is complete); ``clear()`` forgets everything (``--fresh``).

    >>> import tempfile
    >>> with tempfile.TemporaryDirectory() as d:
    ...     stamps = Stamps(Path(d))
    ...     stamps.record("site", "k1", {"notebooks": 6})
    ...     kept = stamps.current("site", "k1", []), stamps.current("site", "k1", [Path(d) / "missing.json"])
    ...     stamps.clear()
    ...     gone = stamps.current("site", "k1", [])
    >>> kept, gone
    (({'notebooks': 6}, None), None)
    """

    def __init__(self, out: Path):
        self.dir = stamp_dir(out)

    def _path(self, name: str) -> Path:
        return self.dir / f"{name}.json"

    def current(self, name: str, key: str, files: Iterable[Path]):
        try:
            stamp = json.loads(self._path(name).read_text(encoding="utf-8"))
        except (OSError, ValueError):
            return None
        if not isinstance(stamp, dict) or stamp.get("key") != key:
            return None
        if not all(Path(f).is_file() for f in files):
            return None
        return stamp.get("data")

    def record(self, name: str, key: str, data) -> None:
        self.dir.mkdir(parents=True, exist_ok=True)
        tmp = self._path(name).with_suffix(".tmp")
        tmp.write_text(json.dumps({"key": key, "data": data}, indent=1, sort_keys=True), encoding="utf-8")
        tmp.replace(self._path(name))

    def forget(self, name: str) -> None:
        self._path(name).unlink(missing_ok=True)

    def clear(self) -> None:
        shutil.rmtree(self.dir, ignore_errors=True)


# ---------------------------------------------------------------------------------------------------
# the steps of kinlib.course.publish.handouts.build that reuse what is current


def _section_files(out: Path, stem: str, audience: str = "all") -> list:
    """The files a built section leaves in ``out`` (for students, no solutions page)."""
    kept = stamp_dir(out) / stem
    return [
        *([out / "solutions" / f"{stem}.html"] if audience == "all" else []),
        out / "problems" / f"{stem}.html",
        out / "workbooks" / f"{stem}.ipynb",
        kept / "executed.ipynb",
        kept / "problems.ipynb",
    ]


def _reused_section(path: Path, out: Path, k: str, stamps: Stamps, audience: str = "all") -> dict | None:
    """The index entry of a section whose outputs were made from the same inputs (key ``k``), else None."""
    stem = path.stem
    data = stamps.current(f"section-{stem}", k, _section_files(out, stem, audience))
    if data is None:
        return None
    kept = stamp_dir(out) / stem
    return {
        **data,
        "executed": nbformat.read(kept / "executed.ipynb", as_version=4),
        "problems": nbformat.read(kept / "problems.ipynb", as_version=4),
        "workbook": nbformat.read(out / "workbooks" / f"{stem}.ipynb", as_version=4),
        "reused": True,
    }


def adopt_sections(out: Path, paths, keys: dict, stamps: Stamps, source: Path, source_keys: dict, log=print) -> int:
    """A students' build (``out``) takes from a full build beside it (``source``, audience "all") each section
    that is current there (``source_keys``: its keys for the same notebook, kinlib, pins and options but the
    audience) and not current in ``out``: the problems page and the workbook (the same bytes a students' build
    makes: neither depends on the audience) and the kept executions, never the solutions page; recorded under the
    students' key (``keys``), so :func:`build_sections` reuses it instead of executing the notebook and running
    its workbook again. Returns how many were taken.

    >>> adopt_sections(Path("build/handouts-students"), paths, keys, stamps, Path("build/handouts"), src_keys)  # doctest: +SKIP
    7
    """
    source = Path(source)
    src_stamps, taken = Stamps(source), 0
    for p in paths:
        stem = p.stem
        if stamps.current(f"section-{stem}", keys[p], _section_files(out, stem, "students")) is not None:
            continue
        data = src_stamps.current(f"section-{stem}", source_keys[p], _section_files(source, stem, "all"))
        if data is None:
            continue
        stamps.forget(f"section-{stem}")
        kept, src_kept = stamp_dir(out) / stem, stamp_dir(source) / stem
        for a, b in (
            (source / "problems" / f"{stem}.html", out / "problems" / f"{stem}.html"),
            (source / "workbooks" / f"{stem}.ipynb", out / "workbooks" / f"{stem}.ipynb"),
            (src_kept / "executed.ipynb", kept / "executed.ipynb"),
            (src_kept / "problems.ipynb", kept / "problems.ipynb"),
        ):
            b.parent.mkdir(parents=True, exist_ok=True)
            shutil.copyfile(a, b)
        stamps.record(f"section-{stem}", keys[p], data)
        taken += 1
        log(f"  {stem}: taken from {source} (the same notebook, kinlib, pins and options)")
    return taken


def build_sections(out: Path, all_paths, paths, keys: dict, stamps: Stamps, make, *, jobs=1, audience="all", log=print):
    """Reuse each section of ``paths`` that is current (its key in ``keys``), make the others with
    ``make(path) -> entry`` (``jobs`` at a time) and record them; return the entries of ``paths``, in order, and
    the index entries of every section of ``all_paths`` that is current (with ``--only``, the others built before).

    :func:`kinlib.course.publish.handouts.build` passes its per-notebook step as ``make``; a second call with the same
    keys makes nothing (tests/course/test_handouts_incremental.py runs both with a stand-in step):

    >>> entries, listed = build_sections(Path("build/handouts"), paths, paths, keys, Stamps(out), make)  # doctest: +SKIP
    """
    entries: dict = {}
    todo = []
    for p in paths:
        entries[p] = _reused_section(p, out, keys[p], stamps, audience)
        if entries[p] is None:
            todo.append(p)
        else:
            log(f"  {p.stem}: reused (notebook, kinlib and pins unchanged since it was built)")

    def make_and_keep(p):
        stamps.forget(f"section-{p.stem}")
        entry = make(p)
        _keep_section(entry, out, keys[p], stamps)
        return entry

    if jobs <= 1 or len(todo) <= 1:
        for k, p in enumerate(todo, 1):
            log(f"[{k}/{len(todo)}] {p.name} ...")
            entries[p] = make_and_keep(p)
    else:
        with ThreadPoolExecutor(max_workers=jobs) as pool:
            futures = {p: pool.submit(make_and_keep, p) for p in todo}
            log(f"  running {len(todo)} notebooks, {jobs} at a time")
            try:
                for p, f in futures.items():
                    entries[p] = f.result()
            except BaseException:
                for f in futures.values():
                    f.cancel()
                raise
    listed = []
    for p in all_paths:
        current = entries.get(p) or stamps.current(f"section-{p.stem}", keys[p], _section_files(out, p.stem, audience))
        if current is not None:
            listed.append(current)
    if len(listed) > len(paths):
        log(f"  index: {len(listed) - len(paths)} other section(s) kept from earlier builds")
    return [entries[p] for p in paths], listed


def _keep_section(entry: dict, out: Path, k: str, stamps: Stamps) -> None:
    kept = stamp_dir(out) / entry["stem"]
    kept.mkdir(parents=True, exist_ok=True)
    nbformat.write(entry["executed"], kept / "executed.ipynb")
    nbformat.write(entry["problems"], kept / "problems.ipynb")
    stamps.record(f"section-{entry['stem']}", k, {n: entry[n] for n in ("stem", "title", "sections", "notes")})


def build_site(out: Path, paths: list, section_keys: list, stamps: Stamps, log) -> None:
    """The JupyterLite site, rebuilt only when a workbook, a solution notebook or kinlib changed.

    >>> build_site(Path("build/handouts"), paths, section_keys, Stamps(out), print)  # doctest: +SKIP
      lite: reused (no workbook, solution notebook or kinlib file changed)
    """
    from .lite import build_lite  # the notebooks in the browser (JupyterLite, offline): out/lite/

    workbooks = sorted((out / "workbooks").glob("[0-9][0-9]_*.ipynb"))
    workbooks += sorted((out / "variant-workbooks").glob("[0-9][0-9]_*.ipynb"))  # each student's (issue 33)
    k = key(code_key(), section_keys, [(p.name, p.read_bytes()) for p in (*workbooks, *paths)])
    if stamps.current("site", k, [out / "lite" / "jupyter-lite.json"]) is not None:
        log("  lite: reused (no workbook, solution notebook or kinlib file changed)")
        return
    stamps.forget("site")
    build_lite(out, paths, log=log)
    stamps.record("site", k, {"notebooks": [p.name for p in paths]})


def print_changed_pdfs(out: Path, stamps: Stamps, log, source: Path | None = None) -> None:
    """The PDFs of the pages, each printed again only when its page (or kinlib) changed. With ``source`` (another
    build: :func:`adopt_sections`), a page whose PDF is current there for the same bytes is copied, not printed.

    >>> print_changed_pdfs(Path("build/handouts"), Stamps(Path("build/handouts")), print)  # doctest: +SKIP
      pdf: 13 of 13 reused (their pages did not change)
    """
    from .printing import PAGE_KINDS, print_pdfs  # the PDFs of the pages (chromium, offline): out/pdf/

    pages = [p for kind in PAGE_KINDS for p in sorted((out / kind).glob("*.html"))]
    keys = {p: key(code_key(), p.read_bytes()) for p in pages}
    pdf = {p: out / "pdf" / p.parent.name / f"{p.stem}.pdf" for p in pages}
    name = {p: f"pdf-{p.parent.name}-{p.stem}" for p in pages}
    todo = [p for p in pages if stamps.current(name[p], keys[p], [pdf[p]]) is None]
    if len(todo) < len(pages):
        log(f"  pdf: {len(pages) - len(todo)} of {len(pages)} reused (their pages did not change)")
    if source is not None and todo:
        src_stamps, copied = Stamps(Path(source)), []
        for p in todo:
            src_pdf = Path(source) / "pdf" / p.parent.name / f"{p.stem}.pdf"
            if src_stamps.current(name[p], keys[p], [src_pdf]) is not None:  # the key holds the page's bytes
                stamps.forget(name[p])
                pdf[p].parent.mkdir(parents=True, exist_ok=True)
                shutil.copyfile(src_pdf, pdf[p])
                stamps.record(name[p], keys[p], {"page": f"{p.parent.name}/{p.name}"})
                copied.append(p)
        if copied:
            log(f"  pdf: {len(copied)} of {len(pages)} taken from {source} (the same pages)")
        todo = [p for p in todo if p not in copied]
    if not todo:
        return
    for p in todo:
        stamps.forget(name[p])
    print_pdfs(out, pages=todo, log=log)
    for p in todo:
        stamps.record(name[p], keys[p], {"page": f"{p.parent.name}/{p.name}"})
