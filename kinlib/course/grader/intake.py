"""What the grader takes in: submission files found and read defensively, and the student id of each.

A class is never stopped by one file. Every file a batch is given becomes a :class:`Submission`; one that
cannot be graded carries ``refused`` (what was wrong, in words) and becomes an error row, while the rest of
the class is graded:

* **Finding** (:func:`find_submissions`): folders are walked without following symbolic links; a link, a
  FIFO, a socket or a device named ``*.ipynb`` is refused by itself (never the whole batch); hidden folders
  (``.ipynb_checkpoints``) are skipped.
* **Reading** (:func:`read_notebook`): the file is opened with ``O_NOFOLLOW | O_NONBLOCK`` and checked to be
  a regular file *on the open descriptor* (a FIFO never blocks, a link swapped in later is not followed), at
  most :data:`MAX_SUBMISSION_BYTES`; the JSON's nesting depth is measured before it is parsed (at most
  :data:`MAX_JSON_DEPTH`: metadata nested 100,000 lists deep is a row, not a RecursionError); the notebook's
  types are checked (``"nbformat": "4"`` is a string, not version 4; cells are objects whose ``source`` is
  text).
* **Identity** (:func:`student_id`): the id is read from the path *relative to the submissions root* (the
  folder given on the command line, or the root remembered in the class folder), never from the folders
  above it. Without ``--id-pattern`` the id is that relative path without ``.ipynb`` (``ann.ipynb`` →
  ``ann``, ``ann/ps4.ipynb`` → ``ann/ps4``): distinct files, distinct ids. A pattern must match from the
  start of the relative path (``([^/]+)/[^/]+$`` fits ``ann/ps4.ipynb`` but not ``aaron/bob/02.ipynb``: a
  nested folder under a student's folder never becomes student ``bob``); a path that does not fit is named
  explicitly by its relative path, with a warning. Ids are kept exactly as written (Unicode, case).
* **File names** (:func:`file_key`): the names of a student's files in the class folder are derived from the
  id collision-free: an id made only of lower-case ASCII letters, digits, ``_``, ``.`` and single ``-`` (not
  starting with ``.``) is used as it is; any other id becomes a readable ASCII slug plus ``~`` and 10 hex
  digits of its SHA-256 (``王伟`` → ``id~…``, ``Ann`` → ``ann~…``, so ``josé``/``josè`` and ``Ann``/``ann``
  stay apart even on a case-insensitive disk).
"""

from __future__ import annotations

import hashlib
import json
import os
import re
import stat
import unicodedata
from dataclasses import dataclass
from pathlib import Path

import numpy as np

__all__ = [
    "MAX_SUBMISSION_BYTES",
    "MAX_JSON_DEPTH",
    "Submission",
    "find_submissions",
    "read_notebook",
    "json_depth",
    "notebook_problem",
    "student_id",
    "file_key",
]

MAX_SUBMISSION_BYTES = 50 * 2**20  # a notebook larger than this is not graded
MAX_JSON_DEPTH = 64  # nesting of lists/objects; real notebooks use < 12
MAX_CELLS = 5000


@dataclass
class Submission:
    """One file of a batch: where it is, its path relative to the submissions root, and why it is refused
    (empty when it can be graded).

    >>> Submission(Path("/subs/ann/ps4.ipynb"), "ann/ps4.ipynb", "/subs").relpath
    'ann/ps4.ipynb'
    """

    path: Path
    relpath: str  # POSIX, relative to ``root``
    root: str  # the submissions root it was found under (absolute)
    refused: str = ""


# ----------------------------------------------------------------------------------------- finding


def _kind(mode: int) -> str:
    for test, word in (
        (stat.S_ISLNK, "a symbolic link"),
        (stat.S_ISFIFO, "a FIFO (named pipe)"),
        (stat.S_ISSOCK, "a socket"),
        (stat.S_ISCHR, "a character device"),
        (stat.S_ISBLK, "a block device"),
        (stat.S_ISDIR, "a folder"),
    ):
        if test(mode):
            return word
    return "not a regular file"


def _refusal(path: Path) -> str:
    try:
        st = os.lstat(path)
    except OSError as exc:
        return f"cannot read the file: {exc.strerror or exc}"
    if stat.S_ISREG(st.st_mode):
        return ""
    return f"not graded: {_kind(st.st_mode)}, not a regular file (only regular files are read)"


def _walk(root: Path, rel: tuple = ()) -> list:
    """(relative parts, path) of every ``*.ipynb`` entry under ``root``, links not followed, hidden folders skipped."""
    found = []
    try:
        entries = sorted(os.scandir(root.joinpath(*rel)), key=lambda e: e.name)
    except OSError:
        return found
    for e in entries:
        if e.is_dir(follow_symlinks=False):
            if not e.name.startswith("."):
                found += _walk(root, (*rel, e.name))
        elif e.name.endswith(".ipynb"):
            found.append(((*rel, e.name), Path(e.path)))
    return found


def find_submissions(paths, root=None) -> list[Submission]:
    """Every file given, and every ``*.ipynb`` under each folder given, as :class:`Submission` (in order).

    A folder is its files' root; a file given by itself has ``root`` (a folder, or a list: the deepest that
    holds the file) or else its own folder.
    Links and other non-regular files are listed, refused (never followed); a missing path raises
    FileNotFoundError (a usage error).

    >>> import tempfile
    >>> with tempfile.TemporaryDirectory() as d:
    ...     top = Path(d)
    ...     (top / "ann" / ".ipynb_checkpoints").mkdir(parents=True)
    ...     for f in ["ann/hw2.ipynb", "ann/.ipynb_checkpoints/hw2-checkpoint.ipynb", "ann/notes.txt", "bob.ipynb"]:
    ...         _ = (top / f).write_text("{}")
    ...     (top / "eve.ipynb").symlink_to("/etc/passwd")
    ...     [(s.relpath, s.refused[:33]) for s in find_submissions([top])]
    [('ann/hw2.ipynb', ''), ('bob.ipynb', ''), ('eve.ipynb', 'not graded: a symbolic link, not ')]
    """
    found = []
    for p in map(Path, paths):
        if not os.path.lexists(p):
            raise FileNotFoundError(f"no such file or folder: {p}")
        if p.is_dir():  # a folder given on the command line is the instructor's: followed (its contents are not)
            top = Path(os.path.abspath(p))
            for parts, q in _walk(top):
                found.append(Submission(q, "/".join(parts), str(top), _refusal(q)))
            continue
        absp = Path(os.path.abspath(p))
        roots = [root] if isinstance(root, (str, os.PathLike)) else list(root or [])
        holders = [Path(os.path.abspath(r)) for r in roots if absp.is_relative_to(os.path.abspath(r))]
        base = max(holders, key=lambda r: len(r.parts)) if holders else absp.parent
        found.append(Submission(absp, absp.relative_to(base).as_posix(), str(base), _refusal(absp)))
    return found


# ----------------------------------------------------------------------------------------- reading


def _read_regular(path, limit: int) -> bytes:
    """The bytes of a regular file (at most ``limit`` + 1), never following a link nor blocking on a FIFO."""
    fd = os.open(path, os.O_RDONLY | os.O_NOFOLLOW | os.O_NONBLOCK | getattr(os, "O_CLOEXEC", 0))
    with os.fdopen(fd, "rb") as f:
        mode = os.fstat(f.fileno()).st_mode
        if not stat.S_ISREG(mode):
            raise ValueError(f"not graded: {_kind(mode)}, not a regular file (only regular files are read)")
        return f.read(limit + 1)


def json_depth(data: bytes) -> int:
    """The deepest nesting of ``[``/``{`` in JSON text ``data`` (brackets inside strings not counted), in
    linear time and without recursion.

    >>> json_depth(b'{"a": [1, [2, "[[[["]], "b": {}}'), json_depth(b"[" * 100000 + b"]" * 100000), json_depth(b"7")
    (3, 100000, 0)
    """
    a = np.frombuffer(data, dtype=np.uint8)
    if not a.size:
        return 0
    # escaped characters: in a run of backslashes every second one escapes the next byte (valid JSON has
    # backslashes only in strings)
    quote = a == 34
    bs = np.flatnonzero(a == 92)
    if bs.size:
        start = np.ones(bs.size, dtype=bool)
        start[1:] = bs[1:] != bs[:-1] + 1
        first = np.maximum.accumulate(np.where(start, np.arange(bs.size), 0))
        escaped = bs[(np.arange(bs.size) - first) % 2 == 0] + 1  # the byte after each escaping backslash
        quote[escaped[escaped < a.size]] = False
    quotes = np.flatnonzero(quote)
    opening = np.flatnonzero((a == 91) | (a == 123))
    closing = np.flatnonzero((a == 93) | (a == 125))
    where = np.concatenate([opening, closing])
    step = np.concatenate([np.ones(opening.size, np.int64), -np.ones(closing.size, np.int64)])
    outside = np.searchsorted(quotes, where) % 2 == 0  # an even number of quotes before it: not in a string
    where, step = where[outside], step[outside]
    if not where.size:
        return 0
    return int(max(np.cumsum(step[np.argsort(where, kind="stable")]).max(), 0))


def notebook_problem(nb) -> str:
    """What makes ``nb`` (parsed JSON) not a version-4 notebook the grader can read, or "" when nothing does.

    >>> notebook_problem({"nbformat": 4, "cells": [{"cell_type": "code", "source": ["x = 1"]}]})
    ''
    >>> notebook_problem({"nbformat": "4", "cells": []})
    "nbformat is '4' (a str), not a whole number"
    >>> notebook_problem({"nbformat": 4, "cells": [{"cell_type": "code", "source": [1, 2]}]})
    'cell 1: its source is not text'
    """
    if not isinstance(nb, dict):
        return f"the top level is a JSON {type(nb).__name__}, not an object"
    v = nb.get("nbformat", 4)
    if not isinstance(v, int) or isinstance(v, bool):
        return f"nbformat is {str(v)[:20]!r} (a {type(v).__name__}), not a whole number"
    if v < 4:
        return f"nbformat {v}: only version-4 notebooks are read (save it again with Jupyter)"
    if not isinstance(nb.get("metadata", {}), dict):
        return "its metadata is not an object"
    cells = nb.get("cells")
    if not isinstance(cells, list):
        return "it has no list of cells"
    if len(cells) > MAX_CELLS:
        return f"it has {len(cells)} cells (at most {MAX_CELLS} are read)"
    for i, c in enumerate(cells, 1):
        if not isinstance(c, dict):
            return f"cell {i} is not an object"
        if not isinstance(c.get("cell_type"), str):
            return f"cell {i}: its cell_type is not text"
        src = c.get("source", "")
        if not (isinstance(src, str) or (isinstance(src, list) and all(isinstance(s, str) for s in src))):
            return f"cell {i}: its source is not text"
        if not isinstance(c.get("metadata", {}), dict):
            return f"cell {i}: its metadata is not an object"
    return ""


def read_notebook(path) -> tuple[bytes, dict | None, str]:
    """(bytes, notebook, "") for a readable notebook, or (bytes or b"", None, what was wrong): never raises for
    what the file holds or is.

    >>> import tempfile
    >>> with tempfile.TemporaryDirectory() as d:
    ...     p = Path(d) / "deep.ipynb"
    ...     _ = p.write_text('{"metadata": {"x": ' + "[" * 100000 + "]" * 100000 + '}, "cells": []}')
    ...     os.mkfifo(Path(d) / "fifo.ipynb")
    ...     print(read_notebook(p)[2]); print(read_notebook(Path(d) / "fifo.ipynb")[2])
    not a notebook: its JSON is nested 100002 levels deep (at most 64 are read)
    not graded: a FIFO (named pipe), not a regular file (only regular files are read)
    """
    try:
        data = _read_regular(path, MAX_SUBMISSION_BYTES)
    except ValueError as exc:
        return b"", None, str(exc)
    except OSError as exc:
        if exc.errno == getattr(os, "ELOOP", 40):
            return b"", None, "not graded: a symbolic link, not a regular file (only regular files are read)"
        return b"", None, f"cannot read the file: {exc.strerror or exc}"
    if len(data) > MAX_SUBMISSION_BYTES:
        return b"", None, f"not graded: the file is larger than {MAX_SUBMISSION_BYTES // 2**20} MB"
    depth = json_depth(data)
    if depth > MAX_JSON_DEPTH:
        return data, None, f"not a notebook: its JSON is nested {depth} levels deep (at most {MAX_JSON_DEPTH} are read)"
    try:
        nb = json.loads(data.decode("utf-8"))
    except (UnicodeDecodeError, ValueError, RecursionError) as exc:
        return data, None, f"not a notebook: the file is not JSON ({str(exc)[:120]})"
    problem = notebook_problem(nb)
    if problem:
        return data, None, f"not a notebook: JSON, but not a version-4 Jupyter notebook: {problem}"
    return data, nb, ""


# ----------------------------------------------------------------------------------------- identity


def student_id(relpath: str, pattern: str | None = None) -> tuple[str, str]:
    """(student id, warning) of a submission at ``relpath`` (POSIX, relative to the submissions root).

    No pattern: the relative path without ``.ipynb``. A pattern is matched from the start of ``relpath``
    (group ``id``, else group 1, else the whole match); a path it does not fit keeps its relative path as
    its id, and the warning says so.

    >>> student_id("ann.ipynb"), student_id("ann/ps4.ipynb", r"([^/]+)/[^/]+$")
    (('ann', ''), ('ann', ''))
    >>> student_id("aaron/bob/02.ipynb", r"([^/]+)/[^/]+$")[0]
    'aaron/bob/02'
    >>> student_id("王伟/ps4.ipynb", r"([^/]+)/[^/]+$"), student_id("José.ipynb")
    (('王伟', ''), ('José', ''))
    """
    whole = relpath[:-6] if relpath.endswith(".ipynb") else relpath
    if not pattern:
        return whole, ""
    m = re.match(pattern, relpath)
    if m:
        got = m.groupdict().get("id") if "id" in m.re.groupindex else (m.group(1) if m.re.groups else m.group(0))
        if got:
            return got, ""
    return whole, (
        f"{relpath} does not fit --id-pattern {pattern!r} (matched from the start of the path relative to the "
        f"submissions root): kept as student {whole!r}"
    )


_SAFE = re.compile(r"[a-z0-9_](?:[a-z0-9_.]|-(?!-))*")


def file_key(text: str, limit: int = 80) -> str:
    """A file-name-safe, collision-free form of ``text`` (a student id or a notebook id).

    >>> file_key("ann"), file_key("ps4_v2.1")
    ('ann', 'ps4_v2.1')
    >>> file_key("Ann"), file_key("王伟")[:3], file_key("王伟") != file_key("李娜"), file_key("josé") != file_key("josè")
    ('ann~17239b6e25', 'id~', True, True)
    >>> file_key("../etc"), file_key("a--b")
    ('etc~f7f9121fdb', 'a-b~90827a2e56')
    """
    if len(text) <= limit and _SAFE.fullmatch(text):
        return text
    ascii_ = unicodedata.normalize("NFKD", text).encode("ascii", "ignore").decode().lower()
    slug = re.sub(r"-{2,}", "-", re.sub(r"[^a-z0-9_.-]+", "_", ascii_)).strip("._-")[:40] or "id"
    return f"{slug}~{hashlib.sha256(text.encode('utf-8', 'surrogatepass')).hexdigest()[:10]}"
