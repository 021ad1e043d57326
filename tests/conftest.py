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

try:  # no hypothesis test may depend on the machine's speed (CI: a loaded 2-core box): no deadline, no health
    # check about slow data generation, for every test that does not set its own (each @settings inherits these)
    from hypothesis import HealthCheck, settings

    settings.register_profile("kinlib", deadline=None, suppress_health_check=[HealthCheck.too_slow])
    settings.load_profile("kinlib")
except ImportError:  # pragma: no cover
    pass


def pytest_configure(config):
    """Under pytest-xdist the groups are handed out in the order ``pytest_collection_modifyitems`` gives them
    (``--no-loadscope-reorder``: xdist would otherwise sort them by their number of tests).
    ``KINLIB_COUNT_EXPENSIVE=counts.json``: count the expensive work per test module (tests/expensive_counter.py).
    With nbval on: its items of notebooks/ read the run's handouts execution (tests/nbval_shared.py)."""
    if hasattr(config.option, "loadscopereorder"):
        config.option.loadscopereorder = False
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


# The schedule under pytest-xdist (``make test``: ``-n 2 --dist loadgroup``). A work unit is an xdist group: by
# default a test file (its module fixtures are built once; nbval's cells of one notebook share one kernel, in order).
# A few files are split where their parts share nothing expensive, so that both workers can run them at once:
# the part of a file whose item ``_SPLIT[file](item)`` names is the group "file::part".
_SPLIT = {
    # JupyterLab (module fixtures ``lab``/``lab_untrusted``) vs the static pages (the run's handouts build)
    "tests/pictures/test_browser.py": lambda item: "lab" if {"lab", "lab_untrusted"} & set(item.fixturenames) else "",
    # each LMS bundle set up by its own setup.sh and graded in its container (minutes each) apart from each other
    # and from the small tests: both workers run one at once (their references: the run's shared cache)
    "tests/course/test_grade_lms.py": lambda item: (
        item.originalname
        if item.originalname.startswith(("test_gradescope_bundle", "test_prairielearn_bundle"))
        else ""
    ),
    # the two heavy hypothesis properties (no fixtures) apart from each other and from the small tests
    "tests/core/test_singular_sets.py": lambda item: (
        item.originalname if item.originalname.startswith("test_random_") else ""
    ),
}

# Seconds per group on an idle machine (``make test PYTEST_ARGS=--durations=0`` from a fresh clone, summed per group
# with a few lines of code; refreshed after issue 24's second round: the handouts build runs in the
# background, so no group carries it), rounded. Only the order of the groups is read from it: heavy groups first
# (longest processing time first: the two workers end close together), the others after them in collection order.
# Stale numbers cost packing, never correctness; a group not listed counts 1 s. Refresh after a big change.
_SECONDS = {
    # the run3 log of the lead's fresh-clone run (its 30 slowest items, idle machine), less what this round shares:
    # the LMS bundles' references (the run's reference cache) and the students' handouts build (it takes the run's
    # full build's sections and PDFs: tests/course/test_leaks.py)
    "tests/course/test_grade_lms.py::test_gradescope_bundle_set_up_by_its_own_setup_sh": 270,
    "tests/pictures/test_browser.py::lab": 190,
    "tests/course/test_lite.py": 140,
    "tests/course/test_grade_lms.py::test_prairielearn_bundle_in_its_own_image": 125,
    "tests/course/test_second_engine.py": 115,
    "tests/core/test_singular_sets.py::test_random_bigger_arms": 76,
    "tests/pictures/test_browser.py": 70,
    "tests/course/test_grade.py": 60,
    "tests/course/test_leaks.py": 60,
    "tests/course/test_print.py": 56,
    "tests/core/test_velocity.py": 45,
    "tests/course/test_grade_batch.py": 44,
    "tests/core/test_budget.py": 40,
    "tests/course/test_handouts.py": 39,
    "tests/project/test_bench.py": 32,
    "tests/core/test_singular_sets.py::test_random_arms_members_singular_nonmembers_not_and_nothing_missing": 32,
    "tests/course/test_grade_verdicts.py": 30,
    "tests/course/test_grade_judging.py": 30,
    "tests/course/test_grade_sandbox.py": 24,
    "tests/core/test_exact_robustness.py": 23,
    "tests/core/test_exact_rank.py": 20,
    "tests/pictures/test_widgets.py": 16,
    "tests/core/test_conditioning.py": 15,
    "tests/core/test_display.py": 9,
    "tests/course/test_grade_export.py": 8,
    "tests/pictures/test_plotting.py": 8,
    "tests/project/test_doctests.py": 8,
    "tests/core/test_codegen_speed.py": 8,
    "tests/course/test_course_cli.py": 8,
    "tests/pictures/test_figure_layout.py": 8,
    "tests/notebooks/test_going_further.py": 7,
    "tests/course/test_selfcheck.py": 7,
    "tests/core/test_core_oracle.py": 7,
    "tests/core/test_singularities.py": 6,
    "tests/course/test_grade_lms.py": 6,
    "tests/core/test_singular_sets.py": 5,
}
# The groups that need the run's real handouts build (it starts in the background at the start of the run:
# ``_start_handouts_build``) wait until about this much work (seconds, per worker) was handed out before them, so
# that no worker starts by waiting for the build; after that, all groups go longest first.
_BUILD_HEADSTART = 200


def _group(item) -> str:
    path = item.nodeid.split("::")[0]
    part = _SPLIT[path](item) if path in _SPLIT and hasattr(item, "originalname") else ""
    return f"{path}::{part}" if part else path


def _needs_build(item) -> bool:
    return "real_handouts" in getattr(item, "fixturenames", ()) or type(item).__name__ == "SharedCell"


def _schedule(groups: list, needs_build: set, workers: int) -> list:
    """The groups (in collection order) in the order to hand them out: longest first (``_SECONDS``), except that
    the groups in ``needs_build`` come only after ``_BUILD_HEADSTART`` seconds per worker of the others.

    >>> lite, velocity = "tests/course/test_lite.py", "tests/core/test_velocity.py"
    >>> lms = "tests/course/test_grade_lms.py::test_gradescope_bundle_set_up_by_its_own_setup_sh"
    >>> _schedule(["a", lite, velocity, lms], {lite}, 1) == [lms, lite, velocity, "a"]  # lite waits for 200 s only
    True
    >>> _schedule(["a", lite, velocity, lms], {lite}, 2) == [lms, velocity, "a", lite]  # two: 2 × 200 s of others
    True
    """
    by_time = sorted(groups, key=lambda g: -_SECONDS.get(g, 1))  # stable: collection order among equals
    free = [g for g in by_time if g not in needs_build]
    held = [g for g in by_time if g in needs_build]
    out, ahead = [], 0
    while free or held:
        released = ahead >= _BUILD_HEADSTART * workers or not free
        if held and released and (not free or _SECONDS.get(held[0], 1) >= _SECONDS.get(free[0], 1)):
            out.append(held.pop(0))
        else:
            g = free.pop(0)
            out.append(g)
            ahead += _SECONDS.get(g, 1)
    return out


@pytest.hookimpl(tryfirst=True)
def pytest_collection_modifyitems(session, config, items):
    """Groups the items for pytest-xdist and orders them (see ``_SPLIT``, ``_SECONDS``, ``_schedule``).

    Under pytest-xdist (``make test``: TEST_JOBS=2 by default, ``--dist loadgroup``) each group is run whole by one
    worker, the groups handed out in the order of the items (xdist's own reordering, by number of tests, is off:
    ``pytest_configure``). Each browser module is a group of its own: a worker starts its own chromium for it
    (``shared_browser``), kept while its next test is in a browser module too, stopped before any other test.
    Without xdist the same order is kept."""
    browser_modules = {item.module.__name__ for item in items if hasattr(item, "module") and _browser_module(item)}
    _BROWSER_MODULES.update(browser_modules)
    group_of = {item: _group(item) for item in items}
    for item in items:
        item.add_marker(pytest.mark.xdist_group(group_of[item]))
    if getattr(config.option, "loadgroup", False) and hasattr(items[0] if items else None, "_id"):
        # pytest-xdist 3.8 marks a group by appending "@group" to item._nodeid, which pytest 9 no longer reads
        # (Node.nodeid is str(item._id)): done here, as xdist would, so that --dist loadgroup groups
        for item in items:
            group = item.get_closest_marker("xdist_group").args[0]
            if not item.nodeid.endswith(f"@{group}"):
                item._id = type(item._id).parse(f"{item.nodeid}@{group}")
    groups = list(dict.fromkeys(group_of.values()))
    needs_build = {group_of[item] for item in items if _needs_build(item)}
    if "tests/pictures/test_browser.py" in groups:  # its static pages read the build (``sites``: getfixturevalue)
        needs_build.add("tests/pictures/test_browser.py")
    workers = int(os.environ.get("PYTEST_XDIST_WORKER_COUNT", "1"))
    rank = {g: i for i, g in enumerate(_schedule(groups, needs_build, workers))}
    items.sort(key=lambda item: rank[group_of[item]])


def pytest_collection_finish(session):
    """The selected tests (after -k/-m) need the real handouts build: it starts now (``_start_handouts_build``)."""
    if any(_needs_build(item) for item in session.items) and not session.config.option.collectonly:
        _start_handouts_build(session.config)


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
    folder, nor into the folder the background handouts build (``_start_handouts_build``) unpacks them into. (A
    serial run without the background build needs nothing: the first build fetches them.)"""
    if os.environ.get("PYTEST_XDIST_WORKER") or _BACKGROUND:
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


_BACKGROUND: list = []  # the background build's process (``_start_handouts_build``)


def _start_handouts_build(config) -> None:
    """Starts the run's real handouts build at once, in a process of its own (``python tests/conftest.py``:
    ``_background_build``), so that it runs while both workers run the tests that do not need it: started by
    one process per run (the first xdist worker, or a run without xdist). It takes the same lock and writes the
    same mark as ``_build_real_handouts``: whoever asks for the build afterwards waits for it and reads it, and a
    build the background process did not finish (failed, killed) is made by the next one who asks, with its
    error. Ended at the end of the run if still running."""
    if os.environ.get("KINLIB_HANDOUTS_DIR") or os.environ.get("PYTEST_XDIST_WORKER", "gw0") != "gw0" or _BACKGROUND:
        return
    import subprocess

    log = ROOT / "build" / ".handouts-background.log"
    log.parent.mkdir(parents=True, exist_ok=True)
    with open(log, "w") as out:
        _BACKGROUND.append(
            subprocess.Popen(
                [sys.executable, str(Path(__file__)), _RUN],
                cwd=ROOT,
                stdin=subprocess.DEVNULL,
                stdout=out,
                stderr=subprocess.STDOUT,
                start_new_session=True,  # its kernels and children end with it (``pytest_unconfigure``)
            )
        )


def pytest_unconfigure(config):
    for proc in _BACKGROUND:
        if proc.poll() is None:
            import signal

            os.killpg(proc.pid, signal.SIGTERM)
            try:
                proc.wait(30)
            except Exception:
                os.killpg(proc.pid, signal.SIGKILL)
                proc.wait()


def _background_build() -> None:
    """The background build (``_start_handouts_build``): the pages' npm packages first, under their lock
    (``_vendor_once``), then the real handouts build under its lock."""
    import tempfile

    from kinlib.course.publish.pages import build_assets

    with _lock(ROOT / "build" / ".vendor.lock"), tempfile.TemporaryDirectory() as tmp:
        build_assets(Path(tmp) / "assets", ROOT / "build" / "vendor")
    _build_real_handouts()


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


if __name__ == "__main__":  # the background build: python tests/conftest.py RUN-ID
    _RUN = sys.argv[1]
    _background_build()
