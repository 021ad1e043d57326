"""pytest configuration and fixtures. Shared test helpers live in tests/helpers.py (import them from there)."""

import json
import os
import sys
import uuid
from pathlib import Path

import numpy as np
import pytest

ROOT = Path(__file__).resolve().parents[1]

# tests/fixtures holds input notebooks and scripts for the handouts and grading tests, not tests:
# keep `pytest --nbval-lax tests` from collecting them.
collect_ignore = ["fixtures"]


def pytest_configure(config):
    """``KINLIB_COUNT_EXPENSIVE=counts.json``: count the expensive work per test module (tests/expensive_counter.py).
    With nbval on: its items of notebooks/ read the run's handouts execution (tests/nbval_shared.py)."""
    if config.pluginmanager.has_plugin("nbval") and (config.option.nbval or config.option.nbval_lax):
        from kinlib.course.publish.incremental import stamp_dir
        from nbval_shared import PLUGIN, SharedNotebookRuns

        stamps = stamp_dir(ROOT / "build" / "handouts")
        config.pluginmanager.register(SharedNotebookRuns(real_handouts_build, ROOT / "notebooks", stamps), PLUGIN)
    if os.environ.get("KINLIB_COUNT_EXPENSIVE"):
        from expensive_counter import ExpensiveCounter

        counter = ExpensiveCounter(os.environ["KINLIB_COUNT_EXPENSIVE"])
        counter.install()
        config.pluginmanager.register(counter, "kinlib-expensive-counter")


def _run_tmp(tmp_path_factory) -> Path:
    """A temporary folder of this run shared by its pytest-xdist workers (the parent of each worker's basetemp,
    made fresh by the controller for every run); this process's basetemp in a serial run."""
    base = tmp_path_factory.getbasetemp()
    return base.parent if os.environ.get("PYTEST_XDIST_WORKER") else base


@pytest.fixture(autouse=True, scope="session")
def _grader_secret(tmp_path_factory):
    """The grader's secret (kinlib.course.grader.secret) for the whole run, one for all xdist workers (so that
    they share ``grader_reference_cache``): a temporary file, never the tester's ~/.config/kinlib/grader-secret
    (subprocesses inherit it through the environment)."""
    from kinlib.course.grader.secret import load_secret

    old = os.environ.get("KINLIB_GRADER_SECRET")
    path = _run_tmp(tmp_path_factory) / "grader-secret" / "grader-secret"
    load_secret(path)  # made once (atomically: the first worker's), read by the others
    os.environ["KINLIB_GRADER_SECRET"] = str(path)
    yield
    if old is None:
        os.environ.pop("KINLIB_GRADER_SECRET", None)
    else:
        os.environ["KINLIB_GRADER_SECRET"] = old


@pytest.fixture(scope="session")
def grader_reference_cache(tmp_path_factory):
    """One signed reference cache (kinlib.course.grader.refdata) for the run's grading tests: a solution notebook is
    executed for its answer key once per run, not once per module: the xdist workers share the folder (the first
    builds a reference under the cache's own lock, refdata.build_reference; the others read it). Signed with the
    run's secret (``_grader_secret``); a test of the cache itself (poisoned, another secret) uses a folder of its own."""
    path = _run_tmp(tmp_path_factory) / "grader-reference-cache"
    path.mkdir(exist_ok=True)
    return path


@pytest.fixture
def rng():
    """A NumPy generator with a fixed seed (reproducible random configurations)."""
    return np.random.default_rng(1234)


@pytest.fixture(autouse=True)
def _close_figures():
    """Close every matplotlib figure after each test (when a test has imported pyplot)."""
    yield
    if "matplotlib.pyplot" in sys.modules:
        sys.modules["matplotlib.pyplot"].close("all")


# ---------------------------------------------------------------------------------------------------
# Built once per run and shared (issue 24): the real handouts (pages, site, PDFs), the fixture's handouts, and
# one chromium for every browser test.


def _browser_module(item) -> bool:
    return item.get_closest_marker("browser") is not None and "shared_browser" in item.fixturenames


@pytest.hookimpl(tryfirst=True)
def pytest_collection_modifyitems(session, config, items):
    """The modules that use the shared chromium run last, one after the other (a stable sort: each module's tests
    keep their order), so that one playwright session serves them all and is stopped after the last one.

    Under pytest-xdist (``make test``: TEST_JOBS=2 by default, ``--dist loadgroup``) every file is a group, run whole by one
    worker (its module fixtures are built once; nbval's cells of one notebook share one kernel, in order), and
    the browser modules are one group together (one chromium, one worker)."""
    browser_modules = {item.module.__name__ for item in items if hasattr(item, "module") and _browser_module(item)}
    _BROWSER_MODULES.update(browser_modules)
    for item in items:
        if hasattr(item, "module") and item.module.__name__ in browser_modules:
            item.add_marker(pytest.mark.xdist_group("browser"))
        else:
            item.add_marker(pytest.mark.xdist_group(item.nodeid.split("::")[0]))
    if getattr(config.option, "loadgroup", False) and hasattr(items[0] if items else None, "_id"):
        # pytest-xdist 3.8 marks a group by appending "@group" to item._nodeid, which pytest 9 no longer reads
        # (Node.nodeid is str(item._id)): done here, as xdist would, so that --dist loadgroup groups
        for item in items:
            group = item.get_closest_marker("xdist_group").args[0]
            if not item.nodeid.endswith(f"@{group}"):
                item._id = type(item._id).parse(f"{item.nodeid}@{group}")
    items.sort(key=lambda item: hasattr(item, "module") and item.module.__name__ in browser_modules)


class _SharedChromium:
    """One playwright session and one chromium (Debian's) for all the browser modules. Playwright's sync API
    allows one session per thread, and while it runs an event loop is running in this thread (asyncio.run fails
    there): so it is started by the first test that asks for it and stopped as soon as the next test does not
    belongs to another module (``pytest_runtest_teardown``), never left running under the other tests."""

    def __init__(self):
        self.playwright = self.browser = None

    def get(self):
        if self.browser is None:
            import labdriver

            if not Path(labdriver.CHROMIUM).exists():
                pytest.fail(f"{labdriver.CHROMIUM} is missing: `make chromium` (apt-get install chromium) installs it")
            from playwright.sync_api import sync_playwright

            self.playwright = sync_playwright().start()
            self.browser = self.playwright.chromium.launch(
                executable_path=labdriver.CHROMIUM, args=labdriver.CHROMIUM_ARGS
            )
        return self.browser

    def stop(self):
        if self.playwright is not None:
            try:
                self.browser.close()
            finally:
                self.playwright.stop()
                self.playwright = self.browser = None


_CHROMIUM = _SharedChromium()


@pytest.fixture
def shared_browser():
    """The run's chromium (playwright ``Browser``): give each test its own page or context, and close it."""
    return _CHROMIUM.get()


_BROWSER_MODULES: set = set()  # the modules that use it (pytest_collection_modifyitems)


def pytest_runtest_teardown(item, nextitem):
    if nextitem is None or getattr(getattr(nextitem, "module", None), "__name__", None) not in _BROWSER_MODULES:
        _CHROMIUM.stop()


def _lock(path: Path):
    """An exclusive lock on ``path`` (a file; fcntl), held until the returned file is closed: two pytest-xdist
    workers never build into one folder at once."""
    import fcntl

    path.parent.mkdir(parents=True, exist_ok=True)
    f = open(path, "a+")
    fcntl.flock(f, fcntl.LOCK_EX)
    return f


@pytest.fixture(autouse=True, scope="session")
def _vendor_once(tmp_path_factory):
    """Under pytest-xdist: the npm packages of the pages (build/vendor, fetched once: kinlib.course.publish.npm)
    are fetched and unpacked by one worker at a time, before any test, so that two workers never unpack into one
    folder. (A serial run needs nothing: the first build fetches them.)"""
    if os.environ.get("PYTEST_XDIST_WORKER"):
        from kinlib.course.publish.pages import build_assets

        with _lock(ROOT / "build" / ".vendor.lock"):
            build_assets(tmp_path_factory.mktemp("assets"), ROOT / "build" / "vendor")


# one id per run, shared by the xdist workers (each worker process has its own _RUN otherwise: a serial run)
_RUN = os.environ.get("PYTEST_XDIST_TESTRUNUID") or uuid.uuid4().hex
_REAL_HANDOUTS: dict = {}


def real_handouts_build() -> tuple[Path, frozenset]:
    """The run's real handouts build (``real_handouts``), made at most once per run: (folder, the stems of the
    notebooks it executed in this run: the others were reused from an earlier build). A failure is raised again
    to every later caller, not retried."""
    if "result" not in _REAL_HANDOUTS:
        try:
            _REAL_HANDOUTS["result"] = _build_real_handouts()
        except Exception as exc:
            _REAL_HANDOUTS["result"] = exc
    if isinstance(_REAL_HANDOUTS["result"], Exception):
        raise _REAL_HANDOUTS["result"]
    return _REAL_HANDOUTS["result"]


def _build_real_handouts() -> tuple[Path, frozenset]:
    if os.environ.get("KINLIB_HANDOUTS_DIR"):
        return Path(os.environ["KINLIB_HANDOUTS_DIR"]).resolve(), frozenset()
    from kinlib.course.publish import handouts

    out = ROOT / "build" / "handouts"
    done = out.parent / ".handouts-built-by"  # {"run": the run's id, "executed": stems} once built in this run
    with _lock(out.parent / ".handouts.lock"):
        try:
            mark = json.loads(done.read_text())
        except (OSError, ValueError):
            mark = {}
        if not isinstance(mark, dict) or mark.get("run") != _RUN:
            done.unlink(missing_ok=True)
            entries = handouts.build(
                ROOT / "notebooks", out, vendor=ROOT / "build" / "vendor", jobs=2, log=lambda s: None
            )
            mark = {"run": _RUN, "executed": [e["stem"] for e in entries if not e.get("reused")]}
            done.write_text(json.dumps(mark))
    return out, frozenset(mark["executed"])


@pytest.fixture(scope="session")
def real_handouts() -> Path:
    """The handouts of notebooks/ with the in-browser site and the PDFs, built once per run into build/handouts by
    ``make handouts``'s own code and options (so a ``make handouts`` just before is reused, section by section:
    kinlib.course.publish.incremental; and what the tests built is what ``make handouts`` would publish). With
    ``verify`` on, as ``make handouts``: every workbook is run top to bottom too. Under pytest-xdist the first
    worker builds (a file lock) and the others read that build. nbval reads the notebooks' executions of this
    build (tests/nbval_shared.py). ``KINLIB_HANDOUTS_DIR`` tests an existing build instead. Raises the build's
    error (NotebookFailed names the notebook and cell)."""
    return real_handouts_build()[0]


@pytest.fixture(scope="session")
def fixture_handouts(tmp_path_factory):
    """The handouts of tests/fixtures/handouts (no site, no PDFs, workbooks not run), built once per run (per
    xdist worker): (folder, the notebook's index entry, the build's log lines)."""
    from kinlib.course.publish import handouts

    out = tmp_path_factory.mktemp("fixture-handouts") / "handouts"
    log: list = []
    entries = handouts.build(
        ROOT / "tests" / "fixtures" / "handouts",
        out,
        vendor=ROOT / "build" / "vendor",
        jobs=1,
        verify=False,
        site=False,
        pdfs=False,
        log=log.append,
    )
    return out, entries[0], log
