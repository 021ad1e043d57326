"""nbval judging the handouts build's execution instead of running a notebook again (tests/nbval_shared.py).

One pytest run (pytester, in this process) over six three-cell notebooks, with a stand-in "build" that says which
notebooks it executed in this run and keeps their ``executed.ipynb``: nbval's items pass on the same outputs
(streams chunked otherwise, as a kernel may send them), fail on a changed checked output, an error, or a cell that
is not the one executed, start no kernel for those, and run the one notebook the build did not execute in this run
in a kernel of their own (its kept execution, which would fail, is not read).
"""

from __future__ import annotations

import json

import nbformat
import pytest
from nbformat.v4 import new_code_cell, new_notebook, new_output

pytest_plugins = ["pytester"]

CONFTEST = """
import json
from pathlib import Path

import pytest
from nbval_shared import PLUGIN, SharedNotebookRuns

HERE = Path(__file__).parent


def _build():
    return HERE / "out", frozenset(json.loads((HERE / "executed.json").read_text()))


def pytest_configure(config):
    config.pluginmanager.register(SharedNotebookRuns(_build, HERE / "notebooks", HERE / ".stamps"), PLUGIN)


@pytest.fixture
def real_handouts():
    return _build()[0]
"""

USES_THE_BUILD = "def test_uses_the_build(real_handouts):\n    assert real_handouts\n"


def _notebook(printed=("42\n",), shown="42", source0="x = 6 * 7", error=False):
    nb = new_notebook(
        cells=[
            new_code_cell(source0, execution_count=1),
            new_code_cell("# NBVAL_CHECK_OUTPUT\nprint(x)", execution_count=2),
            new_code_cell("x", execution_count=3),
        ]
    )
    nb.cells[1].outputs = [new_output("stream", name="stdout", text=t) for t in printed]
    nb.cells[2].outputs = [new_output("execute_result", {"text/plain": shown}, execution_count=3)]
    if error:
        nb.cells[2].outputs = [new_output("error", ename="NameError", evalue="x", traceback=["NameError: x"])]
    nb.metadata["kernelspec"] = {"name": "python3", "display_name": "Python 3", "language": "python"}
    return nb


CASES = {  # notebook -> (its execution kept by the stand-in build, what nbval must say)
    "01_same": (_notebook(printed=["4", "2\n"]), None),  # the same output, sent in two chunks
    "02_changed": (_notebook(printed=("41\n",)), "Cell 1: Cell outputs differ"),
    "03_unchecked": (_notebook(shown="43"), None),  # a cell without NBVAL_CHECK_OUTPUT: not compared (lax)
    "04_raised": (_notebook(error=True), "Cell 2: Cell execution caused an exception"),
    "05_other": (_notebook(source0="x = 7 * 6"), "Cell 0: the handouts build executed another version"),
    "06_not_executed": (_notebook(printed=("41\n",)), None),  # not executed by the build: nbval runs it
}


def test_nbval_judges_the_builds_execution_and_runs_only_what_it_did_not_execute(pytester, monkeypatch):
    import nbval.kernel

    started = []
    original = nbval.kernel.RunningKernel.__init__

    def counted(self, *a, cwd=None, **k):
        started.append(cwd)
        original(self, *a, cwd=cwd, **k)

    monkeypatch.setattr(nbval.kernel.RunningKernel, "__init__", counted)
    pytester.makeconftest(CONFTEST)
    pytester.makepyfile(test_build=USES_THE_BUILD)
    (pytester.path / "notebooks").mkdir()
    for stem, (executed, _) in CASES.items():
        nbformat.write(_notebook(), pytester.path / "notebooks" / f"{stem}.ipynb")
        (pytester.path / ".stamps" / stem).mkdir(parents=True)
        nbformat.write(executed, pytester.path / ".stamps" / stem / "executed.ipynb")
    (pytester.path / "executed.json").write_text(json.dumps([s for s in CASES if s != "06_not_executed"]))
    result = pytester.runpytest_inprocess("--nbval-lax", "--nbval-current-env", "-p", "no:cacheprovider")
    failed = {r.nodeid: str(r.longrepr) for r in result.reprec.getreports("pytest_runtest_logreport") if r.failed}
    want = {f"notebooks/{stem}.ipynb::{why.split(':')[0]}": why for stem, (_, why) in CASES.items() if why}
    assert set(failed) == set(want), failed
    for nodeid, why in want.items():
        assert why.split(": ", 1)[1] in failed[nodeid]
    result.assert_outcomes(passed=6 * 3 + 1 - len(want), failed=len(want))
    result.stdout.fnmatch_lines(["*5 notebook(s) judged on the handouts build's execution*1 executed by nbval*"])
    assert len(started) == 1 and started[0].endswith("notebooks")  # one kernel: 06's, nbval's own
