"""Count the suite's expensive work per test module (issue 24): ``KINLIB_COUNT_EXPENSIVE=counts.json pytest ...``.

Wall times on a loaded machine are noise; counts are not. Each entry point below is wrapped (in this process
only: work done in a subprocess, e.g. ``kinlib`` run as a command or an LMS bundle's own set-up script, is not
seen) and every call is charged to the test module running at the time (``<session>`` for set-up outside a
test). At the end of the run the counts go to the JSON file named by the variable (with ``-n``, one file per
worker: ``counts.gw0.json``, ...) and a table to the terminal.

Kinds counted:

* ``nbclient kernel``: a Jupyter kernel started by nbclient (handouts, ``kinlib execute``, nbval is separate);
* ``nbval kernel``: a kernel nbval started for a notebook (none for a notebook it judges on the handouts
  build's execution: tests/nbval_shared.py);
* ``handouts.build`` / ``section built`` / ``section reused``: whole builds and, inside them, sections made or reused;
* ``execute_notebook`` / ``run_workbook``: the handouts' notebook executions (each one kernel);
* ``lite site``: a JupyterLite site built (``lite.build_lite``); ``pdf batch``: ``printing.print_pdfs``;
* ``grader kernel``: a kernel of the grader (``kinlib.course.grader.isolation.kernel.Kernel.start``);
* ``grader reference``: a solution notebook executed for the answer key (a cache hit is not counted);
* ``lms bundle``: ``kinlib.course.lms.bundles.build_bundle``;
* ``playwright``: a sync_playwright session started; ``chromium``: a browser launched through playwright;
* ``jupyterlab``: a JupyterLab server started (tests/labdriver.py).
"""

from __future__ import annotations

import functools
import json
import os
from collections import Counter, defaultdict
from pathlib import Path

ENV = "KINLIB_COUNT_EXPENSIVE"


class ExpensiveCounter:
    def __init__(self, path: str):
        self.path = Path(path)
        self.module = "<session>"
        self.counts: dict = defaultdict(Counter)
        self._undo: list = []

    def add(self, kind: str) -> None:
        self.counts[self.module][kind] += 1

    def _wrap(self, owner, name: str, kind: str, *, when=None) -> None:
        original = getattr(owner, name)
        counter = self

        @functools.wraps(original)
        def wrapper(*a, **k):
            result = original(*a, **k)
            if when is None or when(a, k, result):
                counter.add(kind)
            return result

        # count before the call returns for functions that may raise (a failing build still cost its work)
        @functools.wraps(original)
        def wrapper_first(*a, **k):
            counter.add(kind)
            return original(*a, **k)

        setattr(owner, name, wrapper if when is not None else wrapper_first)
        self._undo.append((owner, name, original))

    def install(self) -> None:
        import nbclient.client
        import nbval.kernel
        from playwright.sync_api import _context_manager
        from playwright.sync_api._generated import BrowserType

        import labdriver
        from kinlib.course.grader import refdata
        from kinlib.course.grader.isolation import kernel
        from kinlib.course.lms import bundles
        from kinlib.course.publish import handouts, incremental, lite, printing

        self._wrap(nbclient.client.NotebookClient, "async_start_new_kernel", "nbclient kernel")
        self._wrap(nbval.kernel.RunningKernel, "__init__", "nbval kernel")
        self._wrap(handouts, "build", "handouts.build")
        self._wrap(handouts, "execute_notebook", "execute_notebook")
        self._wrap(handouts, "run_workbook", "run_workbook")
        self._wrap(incremental, "_keep_section", "section built")
        self._wrap(incremental, "_reused_section", "section reused", when=lambda a, k, r: r is not None)
        self._wrap(lite, "build_lite", "lite site")
        self._wrap(printing, "print_pdfs", "pdf batch")
        self._wrap(kernel.Kernel, "start", "grader kernel")
        self._wrap(bundles, "build_bundle", "lms bundle")
        self._wrap(_context_manager.PlaywrightContextManager, "__enter__", "playwright")
        self._wrap(BrowserType, "launch", "chromium")
        self._wrap(labdriver, "jupyterlab", "jupyterlab")
        # refdata's own NotebookRun (a subclass, in refdata's namespace only): a reference executed, not read from
        # the cache; the students' runs (grade.py) are not counted here
        counter, base = self, refdata.NotebookRun

        class CountedRun(base):
            def execute(self, *a, **k):
                counter.add("grader reference")
                return super().execute(*a, **k)

        refdata.NotebookRun = CountedRun
        self._undo.append((refdata, "NotebookRun", base))

    # pytest hooks (registered by tests/conftest.py when the variable is set)

    def pytest_runtest_logstart(self, nodeid, location):
        self.module = nodeid.split("::")[0]

    def pytest_runtest_logfinish(self, nodeid, location):
        pass  # teardown of module fixtures runs before the next logstart: charged to the module that set them up

    def pytest_sessionfinish(self, session):
        for owner, name, original in reversed(self._undo):
            setattr(owner, name, original)
        worker = os.environ.get("PYTEST_XDIST_WORKER")
        path = self.path.with_suffix(f".{worker}.json") if worker else self.path
        counts = {m: {k: v for k, v in c.items() if v} for m, c in self.counts.items()}
        counts = {m: c for m, c in counts.items() if c}
        path.write_text(json.dumps(counts, indent=1, sort_keys=True))

    def pytest_terminal_summary(self, terminalreporter):
        total: Counter = Counter()
        tr = terminalreporter
        tr.section("expensive work per module (tests/expensive_counter.py)")
        for m in sorted(self.counts):
            c = {k: v for k, v in self.counts[m].items() if v}
            if c:
                total.update(c)
                tr.write_line(f"{m}: " + ", ".join(f"{k} {v}" for k, v in sorted(c.items())))
        tr.write_line("TOTAL: " + ", ".join(f"{k} {v}" for k, v in sorted(total.items())))
