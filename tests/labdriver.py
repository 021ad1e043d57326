"""Drive JupyterLab in Debian's chromium (playwright) the way a student does, for tests/pictures/test_browser.py and the
browser section of ``make bench`` (bench/bench.py imports this module).

* :func:`jupyterlab` starts JupyterLab on a copy of ``notebooks/`` as ``make lab`` does: the notebooks trusted
  (``jupyter trust``: JupyterLab renders widget outputs only in trusted notebooks) and the project's settings
  (``notebooks/.lab-settings/overrides.json``), with every Jupyter directory (config, data, settings, workspaces) private to
  the run, on a free loopback port.
* :func:`open_notebook` opens a notebook fresh in a new page with the network blocked except loopback;
  :class:`Lab` opens notebook after notebook in one such page (JupyterLab's front end loaded once).
* :func:`run_all` runs every cell (Run → Run All Cells) and returns the seconds until the kernel's last reply.
* :func:`explorers`, :func:`pictures`, :func:`move_slider` find the widget outputs, the pictures in them, and
  time one key press on a slider until the new picture has loaded (all measured in the page's own clock).

Nothing here depends on timing: every wait is for a condition, with generous timeouts.
"""

from __future__ import annotations

import json
import os
import shutil
import signal
import socket
import subprocess
import sys
import time
import urllib.request
from contextlib import contextmanager
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
NOTEBOOKS = ROOT / "notebooks"
LAB_SETTINGS = (
    ROOT / "notebooks" / ".lab-settings"
)  # `make lab` passes --LabApp.app_settings_dir=notebooks/.lab-settings
CHROMIUM = "/usr/bin/chromium"
CHROMIUM_ARGS = [
    "--no-sandbox",
    "--headless",
    "--disable-gpu",
    "--disable-background-networking",
    "--disable-component-update",
    "--disable-sync",
    "--no-first-run",
]
EXPLORER_TEXT = "joint positions"  # the first line of every kinlib.widgets.Explorer


def free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def jupyter_env(work: Path) -> dict:
    """Environment with every Jupyter directory under ``work`` (the user's own are never touched)."""
    return dict(
        os.environ,
        JUPYTER_CONFIG_DIR=str(work / "config"),
        JUPYTER_DATA_DIR=str(work / "data"),
        JUPYTER_RUNTIME_DIR=str(work / "runtime"),
        JUPYTERLAB_SETTINGS_DIR=str(work / "settings"),
        JUPYTERLAB_WORKSPACES_DIR=str(work / "workspaces"),
    )


@contextmanager
def jupyterlab(
    work: Path, notebooks: Path = NOTEBOOKS, *, trust: bool = True, untrusted: tuple = (), timeout: float = 120
):
    """JupyterLab serving a copy of ``notebooks`` (in ``work/notebooks``); yields its URL.

    ``trust=True`` is what ``make lab`` does (``jupyter trust`` on the notebooks); ``trust=False`` is a notebook
    opened by someone who never ran ``make lab`` (JupyterLab then shows only safe outputs: text, images).
    ``untrusted`` (stems) also serves a copy of each of those notebooks as ``untrusted/<stem>.ipynb`` that nobody
    trusted, in the same server (one start, not two): ``jupyter trust`` signs a notebook's content, so the copy
    carries one more metadata entry (``kinlib_test_copy``) and no signature matches it.
    """
    work = Path(work)
    scratch = work / "notebooks"
    shutil.copytree(notebooks, scratch)
    if untrusted:
        (scratch / "untrusted").mkdir()
        for stem in untrusted:
            nb = json.loads((scratch / f"{stem}.ipynb").read_text(encoding="utf-8"))
            nb["metadata"]["kinlib_test_copy"] = "untrusted: opened without `make lab`"
            (scratch / "untrusted" / f"{stem}.ipynb").write_text(json.dumps(nb, indent=1), encoding="utf-8")
    env = jupyter_env(work)
    bindir = Path(sys.executable).parent
    # no news toast and no update check: notebooks/.lab-settings/overrides.json says so, as for `make lab` (no
    # setting of the test's own: tests/pictures/test_browser.py checks that the project's turns them off)
    if trust:
        nbs = sorted(str(p) for p in scratch.glob("[0-9][0-9]_*.ipynb"))
        subprocess.run([str(bindir / "jupyter"), "trust", *nbs], env=env, check=True, capture_output=True)
    port = free_port()
    log_path = work / "lab.log"
    log = open(log_path, "w")
    proc = subprocess.Popen(
        [
            str(bindir / "jupyter"),
            "lab",
            "--no-browser",
            "--IdentityProvider.token=",
            "--expose-app-in-browser",
            "--allow-root",
            f"--port={port}",
            "--ServerApp.ip=127.0.0.1",
            "--ServerApp.port_retries=0",
            f"--ServerApp.root_dir={scratch}",
            f"--LabApp.app_settings_dir={LAB_SETTINGS}",
        ],
        stdout=log,
        stderr=subprocess.STDOUT,
        env=env,
        start_new_session=True,
    )
    url = f"http://127.0.0.1:{port}"
    try:
        deadline = time.time() + timeout
        while True:
            try:
                urllib.request.urlopen(url + "/api/status", timeout=2)
                break
            except OSError:
                if proc.poll() is not None or time.time() > deadline:
                    raise RuntimeError("JupyterLab did not start:\n" + log_path.read_text()[-3000:]) from None
                time.sleep(0.3)
        yield url
    finally:
        os.killpg(proc.pid, signal.SIGTERM)
        try:
            proc.wait(15)
        except subprocess.TimeoutExpired:
            os.killpg(proc.pid, signal.SIGKILL)
        log.close()


def handouts_are_fresh(out: Path, stems, *, pdf: bool = False) -> bool:
    """``out`` (build/handouts) was written after the last change to any notebook or kinlib module and has the
    problems and solutions page of every notebook in ``stems`` (with ``pdf``, their PDFs too): `make handouts`
    just ran, so a test can look at what it made instead of building again."""
    index = Path(out) / "index.html"
    if not index.exists():
        return False
    sources = list(NOTEBOOKS.glob("[0-9][0-9]_*.ipynb")) + list((ROOT / "kinlib").rglob("*.py"))
    if max(p.stat().st_mtime for p in sources) >= index.stat().st_mtime:
        return False
    kinds = ("problems", "solutions")
    return all((Path(out) / k / f"{s}.html").exists() for s in stems for k in kinds) and (
        not pdf or all((Path(out) / "pdf" / k / f"{s}.pdf").exists() for s in stems for k in kinds)
    )


@contextmanager
def chromium():
    """Debian's chromium through playwright (never a downloaded browser build)."""
    if not Path(CHROMIUM).exists():
        raise FileNotFoundError(f"{CHROMIUM} is missing: `make chromium` installs Debian's chromium")
    from playwright.sync_api import sync_playwright

    with sync_playwright() as p:
        b = p.chromium.launch(executable_path=CHROMIUM, args=CHROMIUM_ARGS)
        try:
            yield b
        finally:
            b.close()


class Watch:
    """What a page asks of the network (anything but ``allow`` is blocked) and what goes wrong on it: blocked
    requests, failed requests, page errors and console errors."""

    def __init__(self, page, allow=("file:", "data:", "blob:", "about:")):
        self.blocked, self.failed, self.errors, self.console = [], [], [], []
        self.allow = tuple(allow)

        def route(r):
            if r.request.url.startswith(self.allow):
                r.continue_()
            else:
                self.blocked.append(r.request.url)
                r.abort()

        page.route("**/*", route)
        page.on("requestfailed", lambda r: self.failed.append(f"{r.url} ({r.failure})"))
        page.on("pageerror", lambda e: self.errors.append(str(e)))
        page.on("console", lambda m: self.console.append(m.text) if m.type == "error" else None)

    def assert_clean(self, what):
        assert not self.blocked, f"{what} tried to reach the network: {self.blocked[:5]}"
        assert not self.failed, f"{what}: failed requests {self.failed[:5]}"
        assert not self.errors, f"{what}: page errors {self.errors[:5]}"
        assert not self.console, f"{what}: console errors {self.console[:5]}"


_NOTEBOOK_READY = """(path) => {
  const w = window.jupyterapp && window.jupyterapp.shell.currentWidget;
  const k = w && w.sessionContext && w.sessionContext.session && w.sessionContext.session.kernel;
  const ready = !!k && k.status === 'idle' && !!w.content && w.content.widgets.length > 0 && w.context.path === path;
  if (ready) {  // the current notebook's panel is the one every locator of this module looks in
    document.querySelectorAll('[data-kinlib-current]').forEach(e => { if (e !== w.node) e.removeAttribute('data-kinlib-current'); });
    w.node.setAttribute('data-kinlib-current', '');
  }
  return ready;
}"""

#: the panel of the notebook shown (the last one opened or activated: :func:`open_notebook`, :class:`Lab`)
CURRENT = "[data-kinlib-current]"

_MARK_CURRENT = """() => {
  const w = window.jupyterapp && window.jupyterapp.shell.currentWidget;
  if (!w || !w.node) return false;
  document.querySelectorAll('[data-kinlib-current]').forEach(e => { if (e !== w.node) e.removeAttribute('data-kinlib-current'); });
  w.node.setAttribute('data-kinlib-current', '');
  return true;
}"""


def current(page) -> str:
    """:data:`CURRENT`, after marking the notebook shown now (JupyterLab or JupyterLite: any page that exposes
    ``window.jupyterapp``) as the panel every locator of this module looks in; a page opened by other means
    (JupyterLite's workbook test) is marked here too, so no lookup silently finds nothing."""
    assert page.evaluate(_MARK_CURRENT), "no notebook is shown (window.jupyterapp.shell.currentWidget)"
    return CURRENT


def open_notebook(browser, url: str, name: str, timeout: float = 120):
    """A new page showing notebook ``name`` (e.g. '05_singularities_planar') with its kernel idle.

    Returns (page, watch). The network is blocked except the JupyterLab server on loopback.
    """
    page = browser.new_page(viewport={"width": 1400, "height": 1000})
    host = url.split("//")[1]
    watch = Watch(page, allow=(url, f"ws://{host}", "data:", "blob:", "about:"))
    # a workspace of its own, reset: only this notebook is open (no tab restored from an earlier page)
    page.goto(
        f"{url}/lab/workspaces/kinlib-{name.replace('/', '-')}/tree/{name}.ipynb?reset", wait_until="domcontentloaded"
    )
    page.wait_for_function(_NOTEBOOK_READY, arg=f"{name}.ipynb", timeout=timeout * 1000, polling=200)
    return page, watch


def close_notebook(page) -> None:
    """Shut the notebook's kernel down and close the page."""
    try:
        page.evaluate("() => window.jupyterapp.shell.currentWidget.sessionContext.shutdown()")
    finally:
        page.close()


_OPEN_IN_APP = """async (path) => {
  const app = window.jupyterapp;
  const w = await app.commands.execute('docmanager:open', {path, factory: 'Notebook'});
  app.shell.activateById(w.id);
  return w.id;
}"""

_ACTIVATE = """(id) => {
  window.jupyterapp.shell.activateById(id);
  return window.jupyterapp.shell.currentWidget.id === id;
}"""

_DISPOSE = """async (id) => {
  const w = Array.from(window.jupyterapp.shell.widgets('main')).find(w => w.id === id);
  if (!w) return;
  try { await w.sessionContext.shutdown(); } finally { w.dispose(); }
}"""


class Lab:
    """One JupyterLab page (the application loaded once, as a student keeps one browser tab) in which notebooks
    are opened one after another, each fresh from the server with its own kernel: loading JupyterLab's front end
    costs Chromium as much CPU as running a notebook, so the tests load it once per server, not once per notebook.

    :meth:`open` returns (page, watch) as :func:`open_notebook` does (the watch's lists emptied for each
    notebook); :meth:`close` shuts the notebook's kernel down and disposes of its panel (unsaved changes are
    dropped: the server's copy is never saved); :meth:`activate` shows a notebook still open. Every locator of
    this module looks only in the notebook shown (:data:`CURRENT`).
    """

    def __init__(self, browser, url: str):
        self.browser, self.url = browser, url
        self.page, self.watch, self.ids = None, None, {}

    def open(self, name: str, timeout: float = 120):
        if self.page is None or self.page.is_closed():
            self.page, self.watch = open_notebook(self.browser, self.url, name, timeout)
        else:
            for found in (self.watch.blocked, self.watch.failed, self.watch.errors, self.watch.console):
                found.clear()
            self.page.evaluate(_OPEN_IN_APP, f"{name}.ipynb")
            self.page.wait_for_function(_NOTEBOOK_READY, arg=f"{name}.ipynb", timeout=timeout * 1000, polling=200)
        self.ids[name] = self.page.evaluate("() => window.jupyterapp.shell.currentWidget.id")
        return self.page, self.watch

    def activate(self, name: str, timeout: float = 60):
        assert self.page.evaluate(_ACTIVATE, self.ids[name]), f"{name} is not open"
        self.page.wait_for_function(_NOTEBOOK_READY, arg=f"{name}.ipynb", timeout=timeout * 1000, polling=200)
        return self.page, self.watch

    def close(self, name: str) -> None:
        if self.page is None or self.page.is_closed() or name not in self.ids:
            return
        try:
            self.page.evaluate(_DISPOSE, self.ids.pop(name))
        except Exception:  # a page that broke is not reused: the next notebook loads JupyterLab again
            self.page.close()
            raise

    def quit(self) -> None:
        if self.page is not None and not self.page.is_closed():
            for name in list(self.ids):
                self.close(name)
            self.page.close()


_RUN_ALL = """() => {
  const w = window.jupyterapp.shell.currentWidget;
  const kernel = w.sessionContext.session.kernel;
  const cells = w.content.widgets.filter(c => c.model.type === 'code' && c.model.sharedModel.getSource().trim());
  const state = {expected: cells.length, replies: 0, aborted: 0, t0: performance.now(), t1: null, kernel: 0};
  window.__kinlibRun = state;
  const onMessage = (_, args) => {
    const msg = args.msg;
    if (args.direction === 'recv' && msg.header.msg_type === 'execute_reply') {
      state.replies += 1;
      if (msg.content.status !== 'ok') state.aborted += 1;
      const started = msg.metadata && msg.metadata.started;  // ipykernel: when the kernel began the cell
      if (started) state.kernel += (Date.parse(msg.header.date) - Date.parse(started)) / 1000;
      if (state.replies >= state.expected) { state.t1 = performance.now(); kernel.anyMessage.disconnect(onMessage); }
    }
  };
  kernel.anyMessage.connect(onMessage);
  return window.jupyterapp.commands.execute('notebook:run-all-cells').then(() => state.expected);
}"""


class CellFailed(AssertionError):
    """A cell raised, or did not run to the end (:func:`run_all`): the kernel itself answered."""


def run_all(page, timeout: float = 300, details: bool = False):
    """Run All Cells; wait until the kernel has replied to every non-empty code cell. Returns seconds
    (page clock, from the command to the last reply), or with ``details`` the pair (seconds, seconds the
    kernel spent executing the cells by its own clock). Raises :class:`CellFailed` (an AssertionError) if a
    cell failed."""
    page.evaluate(_RUN_ALL)
    page.wait_for_function("() => window.__kinlibRun.t1 !== null", timeout=timeout * 1000, polling=100)
    run = page.evaluate("() => window.__kinlibRun")
    page.wait_for_function(
        "() => window.jupyterapp.shell.currentWidget.sessionContext.session.kernel.status === 'idle'",
        timeout=timeout * 1000,
        polling=200,
    )
    errors = page.locator(f"{current(page)} .jp-OutputArea-output[data-mime-type='application/vnd.jupyter.error']")
    if errors.count():
        raise CellFailed("a cell raised: " + errors.first.text_content()[:800])
    if run["aborted"]:
        raise CellFailed(f"{run['aborted']} cells did not run to the end")
    wall = (run["t1"] - run["t0"]) / 1000
    return (wall, run["kernel"]) if details else wall


_MARK_WIDGET_CELLS = r"""() => {
  const w = window.jupyterapp.shell.currentWidget;
  const found = [];
  w.content.widgets.forEach((c, i) => {
    if (c.model.type !== 'code') return;
    if (c.model.outputs.toJSON().some(o => o.data && (o.data['application/vnd.jupyter.widget-view+json']
        || /window\.kinlib(Explorer|Animation|Picker)\(host, S\)/.test(String(o.data['application/javascript'] || ''))))) {
      c.node.setAttribute('data-kinlib-cell', String(i));
      found.push(i);
    }
  });
  return found;
}"""


def widget_cells(page):
    """The output areas of the code cells whose output is a Jupyter widget or a kinlib explorer, animation or
    picker (its ``application/javascript``), in notebook order."""
    cells = page.evaluate(_MARK_WIDGET_CELLS)
    return [page.locator(f"{current(page)} [data-kinlib-cell='{i}'] .jp-OutputArea").first for i in cells]


_MARK_CELL_WITH = """(needle) => {
  const w = window.jupyterapp.shell.currentWidget;
  const i = w.content.widgets.findIndex(c => c.model.type === 'code' && c.model.sharedModel.getSource().includes(needle));
  if (i >= 0) w.content.widgets[i].node.setAttribute('data-kinlib-cell', String(i));
  return i;
}"""


def output_of(page, needle: str):
    """The output area of the first code cell whose source contains ``needle`` (None if there is none)."""
    i = page.evaluate(_MARK_CELL_WITH, needle)
    return page.locator(f"{current(page)} [data-kinlib-cell='{i}'] .jp-OutputArea").first if i >= 0 else None


def explorers(page, timeout: float = 60):
    """The output areas of the explorers (``kinlib.widgets.explorer``: they have joint sliders), in notebook
    order, each scrolled to and waited for until its widget is rendered."""
    found = []
    for area in widget_cells(page):
        scroll_to(area, timeout)
        area.locator(".jupyter-widgets, .kinlib-ui").first.wait_for(state="attached", timeout=timeout * 1000)
        if EXPLORER_TEXT in area.text_content():
            found.append(area)
    return found


def animations(page):
    """The outputs that hold a kinlib animation (``kinlib.widgets.animate_singularity``)."""
    return page.locator(f"{current(page)} .jp-OutputArea-output").filter(has=page.locator(".kinlib-animation"))


_PICTURE = """(root) => Array.from(root.querySelectorAll('img')).some(
  i => i.complete && i.naturalWidth >= 100 && i.naturalHeight >= 100
       && i.getBoundingClientRect().width >= 100 && i.getBoundingClientRect().height >= 100)
  || Array.from(root.querySelectorAll('svg.kinlib-picture')).some(
  s => !!s.querySelector('.kinlib-arm') && s.getBoundingClientRect().width >= 100
       && s.getBoundingClientRect().height >= 100)"""


def scroll_to(locator, timeout: float = 60) -> None:
    """Scroll ``locator`` to the middle of the notebook (JupyterLab skips rendering cells far out of view)."""
    locator.evaluate("e => e.scrollIntoView({block: 'center'})", timeout=timeout * 1000)


def wait_picture(locator, timeout: float = 60, what: str = "the output") -> None:
    """Scroll ``locator`` into view and wait until it shows a loaded picture of at least 100×100 px; raises
    AssertionError naming ``what`` (and quoting the output's text) if none comes within ``timeout`` s."""
    from playwright.sync_api import TimeoutError as PlaywrightTimeout

    scroll_to(locator, timeout)
    try:
        locator.page.wait_for_function(
            _PICTURE, arg=locator.element_handle(timeout=timeout * 1000), timeout=timeout * 1000, polling=100
        )
    except PlaywrightTimeout:
        text = " ".join((locator.text_content() or "").split())[:200]
        raise AssertionError(
            f"{what} shows no picture (≥ 100×100 px) after {timeout:g} s; its text: {text!r}"
        ) from None


def slider(explorer, label: str = "θ1"):
    """(slider, the element that takes the keys, its readout) of the joint slider ``label`` (θ1, θ2, ...) of
    ``explorer``: a kinlib explorer's range input, or an ipywidgets slider's handle."""
    if explorer.locator(".kinlib-explorer").count():
        j = int(label.lstrip("θ"))
        s = explorer.locator(f"input.kinlib-slider[data-joint='{j}']").first
        value = explorer.locator(f"label:has(+ .kinlib-track input.kinlib-slider[data-joint='{j}']) .kinlib-value")
        return s, s, value.first
    s = explorer.locator(".widget-slider, .widget-hslider").filter(has_text=label).first
    return s, s.locator(".noUi-handle").first, s.locator(".widget-readout").first


def slider_value(readout) -> float:
    return float(readout.inner_text().replace("\u2212", "-"))


_ARM_CHANGE = """(root, events) => {
  const imgs = Array.from(root.querySelectorAll('img')).filter(i => i.naturalWidth > 0);
  const img = imgs.sort((a, b) => b.naturalWidth * b.naturalHeight - a.naturalWidth * a.naturalHeight)[0];
  const before = img.src;
  const change = {t0: null, ms: null};
  window.__kinlibChange = change;
  for (const ev of events)
    root.addEventListener(ev, () => { if (change.t0 === null) change.t0 = performance.now(); }, {capture: true});
  const done = () => {
    if (img.src !== before && img.complete && img.naturalWidth > 0 && change.t0 !== null && change.ms === null) {
      change.ms = performance.now() - change.t0;
      img.removeEventListener('load', done);
    }
  };
  img.addEventListener('load', done);
}"""


_SCENE_CHANGE = """(root, events) => {
  const scene = root.querySelector('.kinlib-scene');
  const change = {t0: null, ms: null};
  window.__kinlibChange = change;
  for (const ev of events)
    root.addEventListener(ev, () => { if (change.t0 === null) change.t0 = performance.now(); }, {capture: true});
  const obs = new MutationObserver(() => {
    if (change.t0 === null || change.ms !== null) return;
    obs.disconnect();
    requestAnimationFrame(() => { change.ms = performance.now() - change.t0; });  // the frame that shows it
  });
  obs.observe(scene, {childList: true});
}"""


def _timed_change(area, action, events, timeout: float) -> float:
    """Run ``action``; wait until the picture in ``area`` is new: a kinlib explorer's redrawn SVG scene (to the
    next animation frame, the one that paints it), or the largest image's new source, loaded. Returns the
    milliseconds from the first of ``events`` (captured in the page) to then."""
    script = _SCENE_CHANGE if area.locator(".kinlib-scene").count() else _ARM_CHANGE
    area.evaluate(script, list(events))
    action()
    area.page.wait_for_function("() => window.__kinlibChange.ms !== null", timeout=timeout * 1000, polling="raf")
    return float(area.page.evaluate("() => window.__kinlibChange.ms"))


def move_slider(area, handle, key: str = "ArrowRight", timeout: float = 60) -> float:
    """Press ``key`` on the (focused) slider ``handle`` of the explorer in ``area``; wait until the explorer's
    picture has a new source that has loaded. Returns the milliseconds from the key press to the image's load
    event, in the page's clock (so the test process's own latency is not counted)."""
    return _timed_change(area, lambda: handle.press(key), ("keydown",), timeout)


def click_and_wait(area, target, timeout: float = 60) -> float:
    """Click ``target`` (a button of the widget in ``area``) and wait for a new picture, as :func:`move_slider`."""
    return _timed_change(area, lambda: target.click(), ("mousedown", "pointerdown"), timeout)
