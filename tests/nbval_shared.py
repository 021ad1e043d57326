"""nbval over the course notebooks without a second execution of them (issue 24, item 1).

``make test`` runs nbval over ``notebooks/NN_*.ipynb`` (``--nbval-lax``: every code cell must run without an
error; the cells marked ``# NBVAL_CHECK_OUTPUT`` must give their committed outputs), and the run's real handouts
build (tests/conftest.py ``real_handouts``, what ``make handouts`` builds) executes the same notebooks in a fresh
kernel each (nbclient) to make the pages and workbooks from. Each notebook is executed once: when the run builds
the real handouts, nbval's items of a notebook that build **executed in this run** read that execution
(``build/.kinlib-build/handouts/<stem>/executed.ipynb``, kinlib.course.publish.incremental) instead of starting a
kernel of their own, and judge it by nbval's own rules: its NBVAL_* markers and tags, its stream coalescing, its
sanitize file and its ``compare_outputs`` (the same code, inherited). A cell whose source differs from the one
executed fails (the notebook changed during the run).

nbval runs a notebook itself, as before, when the build did not execute it in this run (a section reused from an
earlier ``make handouts``: that is not a fresh execution), when the build failed (nbval then names the failing
cell itself), when ``KINLIB_HANDOUTS_DIR`` points the tests at an existing build, or when no selected test needs the
real handouts (``pytest --nbval-lax notebooks/05_*.ipynb`` does not build the site and the PDFs).

What the build's execution adds to nbval's: after each answer cell it runs a probe that reads the answers'
fingerprints (kinlib.course.publish.handouts; it prints into a cell of its own, not into the notebook's outputs),
and it follows ``clear_output`` and display updates as JupyterLab and ``make notebooks`` (which made the committed
outputs) do, where nbval's kernel loop ignores them.
"""

from __future__ import annotations

import copy
import os
from pathlib import Path

import nbformat
import pytest
from nbval.plugin import IPyNbCell, IPyNbFile, coalesce_streams

PLUGIN = "kinlib-shared-notebook-runs"


class SharedNotebookRuns:
    """The plugin (registered by tests/conftest.py): ``build()`` → (handouts folder, stems executed in this run),
    the run's real handouts build (built at most once per run)."""

    def __init__(self, build, notebooks: Path, stamps: Path):
        self.build, self.notebooks, self.stamps = build, notebooks.resolve(), stamps
        self.active = False
        self.replayed: list = []
        self.executed_by_nbval: list = []

    def pytest_collection_finish(self, session):
        self.active = not os.environ.get("KINLIB_HANDOUTS_DIR") and any(
            "real_handouts" in getattr(item, "fixturenames", ()) for item in session.items
        )

    @pytest.hookimpl(wrapper=True)
    def pytest_collect_file(self, file_path, parent):
        found = yield
        if Path(file_path).resolve().parent != self.notebooks:
            return found
        return [SharedNotebook.from_parent(parent, path=file_path) if type(f) is IPyNbFile else f for f in found]

    def execution(self, stem: str):
        """The build's execution of notebook ``stem`` in this run, or None (then nbval runs it)."""
        if not self.active:
            return None
        try:
            _out, executed = self.build()
        except Exception:  # the build's own tests report it; nbval names the failing cell itself
            return None
        if stem not in executed:
            return None
        return nbformat.read(self.stamps / stem / "executed.ipynb", as_version=4)

    def pytest_terminal_summary(self, terminalreporter):
        if self.replayed or self.executed_by_nbval:
            terminalreporter.write_line(
                f"nbval: {len(self.replayed)} notebook(s) judged on the handouts build's execution in this run "
                f"(not executed again), {len(self.executed_by_nbval)} executed by nbval (tests/nbval_shared.py)"
            )


class SharedNotebook(IPyNbFile):
    """nbval's notebook collector; its kernel is not started when the run's handouts build executed the notebook."""

    executed = None

    def setup(self):
        plugin = self.config.pluginmanager.get_plugin(PLUGIN)
        self.executed = plugin.execution(self.path.stem)
        if self.executed is None:
            plugin.executed_by_nbval.append(self.path.stem)
            return super().setup()
        plugin.replayed.append(self.path.stem)
        self.setup_sanitize_files()

    def collect(self):
        for item in super().collect():
            yield SharedCell.from_parent(
                self, name=item.name, cell_num=item.cell_num, cell=item.cell, options=item.options
            )


class SharedCell(IPyNbCell):
    """nbval's cell item: on the build's execution, the same checks as ``IPyNbCell.runtest`` after its kernel loop."""

    def runtest(self):
        executed = self.parent.executed
        if executed is None:
            return super().runtest()
        if self.options["skip"]:
            pytest.skip()
        ran = [c for c in executed.cells if c.cell_type == "code"]
        if self.cell_num >= len(ran) or ran[self.cell_num].source != self.cell.source:
            self.raise_cell_error("the handouts build executed another version of this cell (notebook changed?)")
        outs = coalesce_streams([copy.deepcopy(o) for o in ran[self.cell_num].outputs])
        self.test_outputs = outs
        for out in outs:
            if out.output_type == "error" and not self.options["check_exception"]:
                self.raise_cell_error("Cell execution caused an exception", "\n" + "\n".join(out.traceback))
        unrun = self.cell.execution_count is None
        if unrun and self.cell.outputs:
            self.raise_cell_error("Unrun reference cell has outputs")
        if self.options["check"] and not unrun:
            if not self.compare_outputs(outs, coalesce_streams(copy.deepcopy(self.cell.outputs))):
                self.raise_cell_error("Cell outputs differ", "\n".join(self.comparison_traceback))
