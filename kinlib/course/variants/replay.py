"""Replaying the instructor's notebook per variant: run it once in a kernel, then per variant only the cells that
depend on the numbers, and read each variant's answers, self-check fingerprints and pictures.

:class:`Session` executes the notebook top to bottom in one Jupyter kernel (as ``kinlib handouts`` does:
:func:`~kinlib.course.publish.execute.notebook_client`, the working directory the notebook's folder), recording the
original's answers exactly as the grader's reference is read (:func:`kinlib.course.grader.refdata._run_solution`:
each answer kept when its part ends, ``in_kernel.export.export_answer`` to a file, read back with
:func:`~kinlib.course.grader.refdata.reference_answers`) and the self-check fingerprints after each answer cell (the
handouts' ``_capture_code``). :meth:`Session.run` then writes the variant cell for the variant's values
(:func:`~kinlib.course.variants.spec.assignment_source`) and re-runs, in the notebook's order, what :func:`plan` says:

- **dependent** cells: every later code cell that reads a name the variant cell or a dependent cell binds (or
  changes by ``x[i] = ...`` / ``x.a = ...``), transitively; except ``check`` cells (they assert the instructor's
  printed numbers) and widget cells (explorers, animations) that no later re-run cell needs;
- **restoring** cells: a cell that binds a name a dependent cell also binds, when that name is read (by a re-run
  cell, at the end of a part, by the export at the end) where that cell's value, not a variant's, is the one a fresh
  run would see. So every variant starts from the same state whatever ran before it.

A variant whose cell raises gets ``error="cell N: ..."``; a cell that times out or kills the kernel ends that kernel
(a time limit never touches the process it limits: an interrupted SymPy may be left changed) and the next variant
gets a fresh kernel that runs the original again. One kernel per session, stopped by :meth:`Session.close`.

The plan needs no kernel:

>>> import nbformat
>>> from nbformat.v4 import new_code_cell, new_notebook
>>> cells = [new_code_cell("import sympy as sp"), new_code_cell("q = 1", metadata={"kinlib": {"variant": True}}),
...          new_code_cell("J = sp.Matrix([q])"), new_code_cell("R = 3"), new_code_cell("r = J.rank() + R"),
...          new_code_cell("assert q == 1", metadata={"tags": ["check"]})]
>>> p = plan(new_notebook(cells=cells))
>>> p.variant, p.dependent, p.restore, p.skipped
(1, [2, 4], [], {5: 'check'})
"""

from __future__ import annotations

import ast
import asyncio
import copy
import json
import os
import shutil
import subprocess
import tempfile
import threading
import time
from dataclasses import dataclass, field
from pathlib import Path

import nbformat

from ..grader.isolation.kernel import setup_code
from ..grader.refdata import reference_answers
from ..publish.aids import show_students_version
from ..publish.analysis import answer_dependents, cell_names
from ..publish.execute import notebook_client
from ..schema import CHECK, SOLUTION, answer_groups, cell_reveals, cell_tags, parse_parts, stash_points
from ..workbook.selfcheck import FINGERPRINT_MARK, emit_fingerprints
from .spec import Spec, assignment_source, variant_cell_index

__all__ = ["Run", "Plan", "plan", "Session", "replay"]

WIDGET_VIEW = "application/vnd.jupyter.widget-view+json"
_WIDGET_NAMES = frozenset({"widgets", "interact", "interactive", "interact_manual", "explorer"})
_NONCE = "_kinlib_variants_export"


@dataclass
class Run:
    """One run of the notebook for ``values``: its reference answers (``Reference.answers`` format), the
    self-check fingerprints ``{(cell index, name): {"spec", "describe"}}``, the outputs of the cells re-run because
    they depend on the numbers (``{cell index: [outputs]}``: the per-student problem page's figures), the students'
    version of those that state an answer (``students``, as ``kinlib handouts`` makes it), what failed ("" if
    nothing) and the seconds it took.

    >>> Run({"L": "1"}, {}, {}, {}).error
    ''
    """

    values: dict
    answers: dict
    fingerprints: dict
    outputs: dict
    error: str = ""
    seconds: float = 0.0
    students: dict = field(default_factory=dict)


# ---------------------------------------------------------------------------------------------------
# The plan: which cells a variant re-runs (name analysis, no kernel)


@dataclass
class _Cell:
    loads: set | None  # every name read anywhere (None: does not parse, assumed to read everything)
    free: set  # read before bound
    bound: set  # bound at top level (imports too)
    mutated: set  # x of x[...] = / x.a = / del x[...]
    statements: list  # [(loads, bound | mutated, bound)] of each top-level statement but imports
    widget: bool
    check: bool


def _source(cell) -> str:
    s = cell.get("source", "")
    return "".join(s) if isinstance(s, list) else s


def _python(src: str) -> str:
    """Cell source as plain Python (IPython magics and shell escapes transformed, as the name analysis reads it)."""
    from IPython.core.inputtransformer2 import TransformerManager

    return TransformerManager().transform_cell(src)


def _mutated(tree) -> set:
    out = set()
    for n in ast.walk(tree):
        if isinstance(n, (ast.Subscript, ast.Attribute)) and isinstance(n.ctx, (ast.Store, ast.Del)):
            base = n.value
            while isinstance(base, (ast.Subscript, ast.Attribute)):
                base = base.value
            if isinstance(base, ast.Name):
                out.add(base.id)
    return out


def _loads(tree) -> set:
    return {n.id for n in ast.walk(tree) if isinstance(n, ast.Name) and isinstance(n.ctx, ast.Load)}


def _analyse(cell) -> _Cell:
    src = _source(cell)
    check = CHECK in cell_tags(cell)
    try:
        tree = ast.parse(_python(src))
    except SyntaxError:
        return _Cell(None, set(), set(), set(), [], False, check)
    free, bound = cell_names(src)
    statements = []
    for stmt in tree.body:  # what each statement reads and writes: a name is tainted only by what computes it
        if not isinstance(stmt, (ast.Import, ast.ImportFrom)):  # an import binds the same object each time
            names = cell_names(ast.unparse(stmt))[1]
            statements.append((_loads(stmt), names | _mutated(stmt), names))
    loads = _loads(tree)
    widget = bool(loads & _WIDGET_NAMES) or any(WIDGET_VIEW in o.get("data", {}) for o in cell.get("outputs", []))
    return _Cell(loads, free, bound, _mutated(tree), statements, widget, check)


def _taint(c: _Cell, tainted: set, everything: bool = False) -> set:
    """The names cell ``c`` writes from a tainted name (statement by statement, in order); every name it writes
    when ``everything``."""
    local, out = set(tainted), set()
    for loads, writes, names in c.statements:
        if everything or loads & local:
            local |= writes
            out |= writes
        else:  # rebound from untainted names: this cell reads its own value from here on
            local -= names
    return out


@dataclass
class Plan:
    """Which cells a variant re-runs, and what it reads again.

    ``dependent``: cells that depend on the numbers (their outputs are the variant's); ``restore``: cells re-run
    only to put back a value a dependent cell overwrote; ``skipped``: dependent cells not re-run ({cell: "check" |
    "widget"}); ``restash``: {cell: answer names kept again when the part ends there}; ``recapture``: answer cells
    whose fingerprints are taken again; ``needed``: the dependent cells the answers need (the others only draw).

    >>> Plan(2, [4, 5], [1], {6: "check"}, {}, [], needed=[4]).rerun
    [1, 2, 4, 5]
    """

    variant: int
    dependent: list
    restore: list
    skipped: dict
    restash: dict
    recapture: list
    needed: list = field(default_factory=list)

    @property
    def rerun(self) -> list:
        """Every cell a variant runs, in order (the variant cell included)."""
        return sorted({self.variant, *self.dependent, *self.restore})

    @property
    def answers_only(self) -> list:
        """The cells a variant runs for its answers and fingerprints alone (no picture that no answer needs)."""
        return sorted({self.variant, *self.needed, *self.restore})


def plan(nb) -> Plan:
    """The cells a variant of ``nb`` re-runs (:class:`Plan`); ValueError when it has no variant cell.

    A dependent cell that overwrites a name an earlier cell bound makes that cell re-run when the name is read
    again (here ``J``, read by the part's end and rebound by the dependent cell 3):

    >>> from nbformat.v4 import new_code_cell, new_markdown_cell, new_notebook
    >>> sol = {"tags": ["solution"], "kinlib": {"part": "1.1", "answers": ["J"]}}
    >>> nb = new_notebook(cells=[new_code_cell("q = 1", metadata={"kinlib": {"variant": True}}),
    ...     new_code_cell("J = 2", metadata=sol), new_markdown_cell("**1.2**", metadata={"tags": ["question"]}),
    ...     new_code_cell("J = q * 3")])
    >>> p = plan(nb)
    >>> p.dependent, p.restore, p.restash
    ([3], [1], {1: ['J']})
    """
    v = variant_cell_index(nb)
    if v is None:
        raise ValueError("variants: the notebook has no variant cell (cell metadata kinlib.variant = true)")
    cells = nb["cells"]
    code = [i for i, c in enumerate(cells) if c.get("cell_type") == "code" and _source(c).strip()]
    info = {i: _analyse(cells[i]) for i in code}
    dependent, skipped, tainted = _dependents(nb, info, code, v)
    reads = _Reads(nb, info, code, skipped)
    rerun = {v, *dependent}
    restore: set = set()
    changed = True
    while changed:  # every tainted name read again must be what a fresh run would read there
        changed = False
        events = [(c, x) for c in sorted(rerun | restore) for x in info[c].free & tainted]
        for pos, x in reads.events():
            if x in tainted:
                events.append((pos, x))
        for pos, x in events:
            for w in reads.writers(x, pos):
                if w not in rerun and w not in restore:
                    restore.add(w)
                    changed = True
    ran = rerun | restore

    def fresh(name, pos):
        return any(w in ran for w in reads.writers(name, pos))

    restash = {p: [x for x in names if fresh(x, p + 0.5)] for p, names in reads.stash.items()}
    restash = {p: names for p, names in restash.items() if names}
    recapture = sorted(a for a, names in reads.capture.items() if any(fresh(x, a + 0.5) for x in names))
    # the dependent cells the answers need (the rest only draw): what the answers are read from, and its inputs
    needed: set = set()
    todo = reads.events()
    while todo:
        pos, x = todo.pop()
        for w in reads.writers(x, pos):
            if w in ran and w not in needed:
                needed.add(w)
                todo += [(w, y) for y in info[w].free]
    needed = sorted(needed & set(dependent))
    return Plan(v, dependent, sorted(restore), dict(sorted(skipped.items())), restash, recapture, needed)


def _dependents(nb, info: dict, code: list, v: int) -> tuple[list, dict, set]:
    """(dependent cells, skipped {cell: why}, tainted names) for the variant cell ``v``."""
    tainted = _taint(info[v], set(), everything=True)  # the names it assigns (not its imports)
    dependent, skipped = [], {}
    for i in code:
        if i <= v:
            continue
        c = info[i]
        if c.loads is not None and not (c.free & tainted):  # reads no tainted name before binding it
            continue
        if c.check:
            skipped[i] = "check"
            continue
        dependent.append(i)
        tainted |= _taint(c, tainted)
    # a widget, or a cell no student's page shows (a worked step, a picture of the answers), that no later re-run
    # cell reads and that binds no answer is not re-run: its output is the instructor's only
    cells = nb["cells"]
    answers = {n for p in parse_parts(nb) for n in p.kinds}
    hidden = set(answer_dependents(nbformat.reads(json.dumps(nb), as_version=4))) | {
        i for i in code if {SOLUTION, CHECK} & set(cell_tags(cells[i]))
    }
    for w in reversed(list(dependent)):
        why = "widget" if info[w].widget else "not shown" if w in hidden else None
        if (
            why
            and not (info[w].bound & answers)
            and not any(info[c].loads is None or info[c].loads & info[w].bound for c in dependent if c > w)
        ):
            dependent.remove(w)
            skipped[w] = why
    return dependent, skipped, tainted


class _Reads:
    """Where a notebook's answers are read (a part's end, the fingerprints, the export at the end), and which
    cells a value read at a point comes from."""

    def __init__(self, nb, info: dict, code: list, skipped: dict):
        self.info, self.code, self.skipped, self.end = info, code, skipped, len(nb["cells"])
        code_cells = [i for i, c in enumerate(nb["cells"]) if c.get("cell_type") == "code"]
        self.stash = {code_cells[k]: list(names) for k, names in stash_points(nb).items() if k < len(code_cells)}
        stashed = {n for names in self.stash.values() for n in names}
        self.capture: dict = {}
        for g in answer_groups(nb):
            for _part, name, _kind, idx in g.answers:
                self.capture.setdefault(idx, []).append(name)
        self.final = sorted({n for p in parse_parts(nb) for n in p.kinds} - stashed)

    def events(self) -> list:
        """[(position, name)]: each answer read right after a cell (index + 0.5) or at the end."""
        out = [(p + 0.5, x) for p, names in self.stash.items() for x in names]
        out += [(a + 0.5, x) for a, names in self.capture.items() for x in names]
        return out + [(self.end, x) for x in self.final]

    def writers(self, name: str, before: float) -> list:
        """The cells a fresh run's value of ``name`` just before position ``before`` comes from: the last cell that
        binds it, and those that change it in place after that one."""
        out = []
        for i in reversed([k for k in self.code if k < before and k not in self.skipped]):
            c = self.info[i]
            if name in c.mutated:
                out.append(i)
            if name in c.bound or c.loads is None:
                out.append(i)
                break
        return out


# ---------------------------------------------------------------------------------------------------
# The kernel


def _kernel_call(function, *args, namespace: bool = False) -> str:
    """Kernel code calling the kinlib ``function`` (by its module and name) with ``args`` written as literals: the
    probes ``kinlib handouts`` runs after a cell (its fingerprints, the students' version of its picture).

    >>> _kernel_call(emit_fingerprints, {"J": ("expr", "1.1")}, namespace=True)
    "__import__('kinlib.course.workbook.selfcheck', fromlist=['emit_fingerprints']).emit_fingerprints({'J': ('expr', '1.1')}, globals())"
    """
    module, name = function.__module__, function.__name__
    args_text = ", ".join([repr(a) for a in args] + (["globals()"] if namespace else []))
    return f"__import__({module!r}, fromlist=[{name!r}]).{name}({args_text})"


class _Failed(Exception):
    def __init__(self, index: int, why: str, dead: bool = False):
        super().__init__(f"cell {index}: {why}"[:500])
        self.dead = dead


def _plain(outputs) -> list:
    """Outputs as plain JSON (nbformat nodes copied), for the key's pictures."""
    return json.loads(json.dumps(outputs))


def _error_text(exc) -> str:
    ename = getattr(exc, "ename", None) or type(exc).__name__
    evalue = getattr(exc, "evalue", None)
    if evalue is None:
        evalue = str(exc).strip().splitlines()[-1] if str(exc).strip() else ""
    return f"{ename}: {evalue}"


#: serialises the name analysis: concurrent ast.parse in 3.11 raises "AST constructor recursion depth mismatch"
_PARSE_LOCK = threading.Lock()


class Session:
    """The instructor's notebook ``path`` run once in a kernel (:attr:`original`, a :class:`Run` of the spec's
    original values, ready when the constructor returns), then :meth:`run` per variant in the same kernel;
    :meth:`close` stops it (also a context manager). ``timeout``: seconds per cell.

    It runs a Jupyter kernel (tests/course/test_variants_replay.py exercises it), hence not run here:

    >>> with Session(Path("notebooks/05_singularities_planar.ipynb"), spec) as s:  # doctest: +SKIP
    ...     run = s.run({"q53": ["1/4", "-3/4", "1/4"]})
    >>> run.error, run.answers["rank53"]  # doctest: +SKIP
    """

    def __init__(self, path, spec: Spec, timeout: float = 120):
        if not isinstance(spec, Spec):
            raise TypeError(f"spec: expected a variants Spec, got {type(spec).__name__}")
        if isinstance(timeout, bool) or not isinstance(timeout, (int, float)) or not 0 < timeout <= 86400:
            raise ValueError(f"timeout: expected seconds per cell in (0, 86400], got {timeout!r}")
        if not Path(path).is_file():
            raise FileNotFoundError(f"path: no notebook {path}")
        self.path = Path(path)
        self.spec = spec
        self.timeout = timeout
        self.nb = nbformat.read(self.path, as_version=4)
        with _PARSE_LOCK:  # CPython 3.11's ast.parse is not thread-safe (build_key proves notebooks in threads)
            self.plan = plan(self.nb)
        self.kinds = {n: k for p in parse_parts(self.nb) for n, k in p.kinds.items()}
        self.capture: dict = {}
        for g in answer_groups(self.nb):
            for part, name, kind, idx in g.answers:
                self.capture.setdefault(idx, {})[name] = (kind, part)
        code_cells = [i for i, c in enumerate(self.nb.cells) if c.cell_type == "code"]
        self.stash = {code_cells[k]: list(v) for k, v in stash_points(self.nb).items() if k < len(code_cells)}
        self.tmp = tempfile.mkdtemp(prefix="kinlib-variants-")
        self.client = None
        self._setup = None
        self._count = 0
        self._loop = asyncio.new_event_loop()
        self._thread = threading.Thread(target=self._loop.run_forever, name="kinlib-replay", daemon=True)
        self._thread.start()
        self.original = Run(dict(spec.original), {}, {}, {})
        try:
            self.original = self._call(self._original())
        except BaseException:
            self.close()
            raise

    # -- plumbing

    def _call(self, coro):
        return asyncio.run_coroutine_threadsafe(coro, self._loop).result()

    async def _start(self):
        nb = copy.deepcopy(self.nb)
        self.client = notebook_client(
            nb,
            timeout=self.timeout,
            kernel_name="python3",
            record_timing=False,
            shutdown_kernel="immediate",
            resources={"metadata": {"path": str(self.path.parent)}},
        )
        env = {**os.environ, "PYTHONHASHSEED": "0"}  # set order in printed outputs (as kinlib execute)
        self._setup = self.client.async_setup_kernel(stderr=subprocess.DEVNULL, env=env)
        await self._setup.__aenter__()
        self._count = 0
        await self._exec(setup_code(_NONCE, snapshot=False), -1, quiet=True)

    async def _stop(self):
        if self._setup is not None:
            setup, self._setup, self.client = self._setup, None, None
            try:
                await setup.__aexit__(None, None, None)
            except Exception:  # noqa: BLE001  (a kernel that is already gone)
                pass

    async def _exec(self, source: str, index: int, quiet: bool = False):
        """Run ``source`` as cell ``index``; return the cell (its outputs). Raises _Failed naming the cell."""
        from nbclient.exceptions import CellExecutionError, CellTimeoutError, DeadKernelError

        cell = nbformat.v4.new_code_cell(source)
        slot = max(index, 0)
        nb = self.client.nb
        keep = nb.cells[slot] if slot < len(nb.cells) else None
        if not quiet:
            self._count += 1
        try:
            await self.client.async_execute_cell(
                cell, slot, execution_count=None if quiet else self._count, store_history=not quiet
            )
        except CellTimeoutError:
            raise _Failed(index, f"timed out after {self.timeout:g} s", dead=True) from None
        except DeadKernelError:
            raise _Failed(index, "the kernel died", dead=True) from None
        except CellExecutionError as e:
            raise _Failed(index, _error_text(e)) from None
        finally:
            if keep is not None:
                nb.cells[slot] = keep
        return cell

    async def _fingerprints(self, index: int, fps: dict):
        cell = await self._exec(_kernel_call(emit_fingerprints, self.capture[index], namespace=True), index, quiet=True)
        text = "".join(o.get("text", "") for o in cell.outputs if o.get("output_type") == "stream")
        for line in text.splitlines():
            if line.startswith(FINGERPRINT_MARK):
                for name, fp in json.loads(line[len(FINGERPRINT_MARK) :]).items():
                    if "error" in fp:  # as the handouts: the workbook says there is no automatic self-check
                        fp = {
                            "spec": "none||",
                            "describe": "",
                            "warning": f"cell {index}: answer {name!r} has no self-check ({fp['error']})",
                        }
                    fps[(index, name)] = fp

    async def _stash(self, index: int, names: list):
        await self._exec(f"__import__('sys').modules[{_NONCE!r}].stash(globals(), {names!r})", index, quiet=True)

    async def _answers(self) -> dict:
        files = {n: os.path.join(self.tmp, f"a{k}.json") for k, n in enumerate(self.kinds)}
        for p in files.values():
            if os.path.exists(p):
                os.remove(p)
        code = (
            f"for __n, __p in {list(files.items())!r}:\n"
            f"    __import__('sys').modules[{_NONCE!r}].export_answer(globals(), __n, __p)\n"
            "del __n, __p"
        )
        await self._exec(code, -1, quiet=True)
        exported = {}
        for n, p in files.items():
            try:
                exported[n] = json.loads(Path(p).read_text())
            except (OSError, ValueError) as e:
                exported[n] = {"error": f"could not read the reference answer: {e}"}
        return reference_answers(exported, self.kinds)

    @staticmethod
    def _missing(answers: dict) -> str:
        missing = [f"{n}: {a['error']}" for n, a in answers.items() if "error" in a]
        return "; ".join(missing)[:1000]

    # -- the runs

    async def _original(self) -> Run:
        t0 = time.monotonic()
        values = dict(self.spec.original)
        await self._start()
        fps: dict = {}
        try:
            for i, cell in enumerate(self.nb.cells):
                if cell.cell_type != "code" or not cell.source.strip():
                    continue
                await self._exec(cell.source, i)  # the variant cell as the notebook has it
                if i in self.capture:
                    await self._fingerprints(i, fps)
                if i in self.stash:
                    await self._stash(i, self.stash[i])
            answers = await self._answers()
        except _Failed as e:
            if e.dead:
                await self._stop()
            return Run(values, {}, fps, {}, str(e), time.monotonic() - t0)
        return Run(values, answers, fps, {}, self._missing(answers), time.monotonic() - t0)

    async def _variant(self, values: dict, pictures: bool = True) -> Run:
        t0 = time.monotonic()
        if self.client is None:  # the last variant ended the kernel: start again from the original
            orig = await self._original()
            if orig.error:
                return Run(values, {}, {}, {}, f"the original does not run: {orig.error}", time.monotonic() - t0)
        p = self.plan
        fps = dict(self.original.fingerprints)
        outputs, students = {}, {}
        rerun = set(p.rerun if pictures else p.answers_only)
        try:
            source = assignment_source(self.spec, values)
            for i in range(min(rerun), len(self.nb.cells)):
                if i in rerun:
                    cell = await self._exec(source if i == p.variant else self.nb.cells[i].source, i)
                    if i in p.dependent:
                        outputs[i] = _plain(cell.outputs)
                        if cell_reveals(self.nb.cells[i]):
                            probe = await self._exec(_kernel_call(show_students_version), i, quiet=True)
                            shown = [
                                o for o in probe.outputs if o.get("output_type") in ("display_data", "execute_result")
                            ]
                            students[i] = _plain(shown)
                if i in p.recapture:
                    await self._fingerprints(i, fps)
                if i in p.restash:
                    await self._stash(i, p.restash[i])
            answers = await self._answers()
        except _Failed as e:
            if e.dead:
                await self._stop()
            return Run(values, {}, {}, outputs, str(e), time.monotonic() - t0, students)
        return Run(values, answers, fps, outputs, self._missing(answers), time.monotonic() - t0, students)

    def run(self, values: dict, pictures: bool = True) -> Run:
        """The notebook's answers, fingerprints and re-run outputs for ``values`` (a :class:`Run`; its ``error``
        says what failed). Raises ValueError when ``values`` are not one of the spec's draws. Without ``pictures``
        only the cells the answers need run (:attr:`Plan.answers_only`; the outputs are theirs): a proof that
        needs no figure."""
        assignment_source(self.spec, values)  # ValueError naming the parameter
        if self.original.error:
            return Run(dict(values), {}, {}, {}, f"the original does not run: {self.original.error}")
        run = self._call(self._variant(dict(values), pictures))
        run.values = dict(values)
        return run

    def close(self):
        """Stop the kernel and the session's thread (idempotent)."""
        if self._loop.is_closed():
            return
        try:
            self._call(self._stop())
        finally:
            self._loop.call_soon_threadsafe(self._loop.stop)
            self._thread.join(timeout=30)
            self._loop.close()
            shutil.rmtree(self.tmp, ignore_errors=True)

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()


def replay(path, spec: Spec, variants: list, timeout: float = 120, jobs: int = 1) -> tuple[Run, list]:
    """(the original's :class:`Run`, one Run per variant in ``variants``, in order): the notebook ``path`` executed
    once in a kernel, then per variant the cells that depend on the numbers (:class:`Session`). With ``jobs`` > 1
    the variants are shared out round-robin between that many kernels (each runs the original once first).

    >>> replay("nb.ipynb", None, [], jobs=0)
    Traceback (most recent call last):
        ...
    ValueError: jobs: expected a whole number of kernels >= 1, got 0

    It runs a Jupyter kernel (tests/course/test_variants_replay.py exercises it), hence not run here:

    >>> original, runs = replay(Path("notebooks/05_singularities_planar.ipynb"), spec, [values])  # doctest: +SKIP
    """
    if isinstance(jobs, bool) or not isinstance(jobs, int) or jobs < 1:
        raise ValueError(f"jobs: expected a whole number of kernels >= 1, got {jobs!r}")
    variants = list(variants)
    jobs = min(jobs, max(len(variants), 1))

    def work(share):
        with Session(path, spec, timeout=timeout) as s:
            return s.original, [s.run(v) for v in share]

    if jobs == 1:
        return work(variants)
    from concurrent.futures import ThreadPoolExecutor

    with ThreadPoolExecutor(max_workers=jobs) as pool:
        results = list(pool.map(work, [variants[k::jobs] for k in range(jobs)]))
    runs: list = [None] * len(variants)
    for k, (_orig, share) in enumerate(results):
        runs[k::jobs] = share
    return results[0][0], runs
