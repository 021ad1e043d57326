"""Browser tests (marked ``browser``): Debian's chromium through the playwright package, never a
downloaded browser, with the network blocked.

1. Every handout page (built once per session by the same code as ``make handouts``, from the real
   notebooks and from the fixture notebook) loads from disk with no request leaving the machine, no
   page error and no failed request, shows typeset math (MathJax output, no raw TeX) and its figures
   (every image decoded), and the saved widgets; a screenshot of each goes to build/screenshots/.
   An animation (matplotlib ``to_jshtml``) plays in the static page.
2. JupyterLab on a free loopback port runs notebook 05; its joint slider is moved with the keyboard to
   a singular configuration; the explorer then says so and its picture changes.
"""

from __future__ import annotations

import math
import os
import re
import shutil
import signal
import socket
import subprocess
import sys
import time
import urllib.request
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
NOTEBOOKS = ROOT / "notebooks"
FIXTURES = ROOT / "tests" / "fixtures" / "handouts"
VENDOR = ROOT / "build" / "vendor"
SCREENSHOTS = ROOT / "build" / "screenshots"
CHROMIUM = "/usr/bin/chromium"
ARGS = [
    "--no-sandbox",
    "--headless",
    "--disable-gpu",
    "--disable-background-networking",
    "--disable-component-update",
    "--disable-sync",
    "--no-first-run",
]

pytestmark = [pytest.mark.browser]

REAL = sorted(p.stem for p in NOTEBOOKS.glob("[0-9][0-9]_*.ipynb"))
FIXTURE = sorted(p.stem for p in FIXTURES.glob("[0-9][0-9]_*.ipynb"))
PAGES = (
    [("handouts", "index", None)]
    + [("handouts", k, s) for s in REAL for k in ("problems", "solutions")]
    + [("fixture", "index", None)]
    + [("fixture", k, s) for s in FIXTURE for k in ("problems", "solutions")]
)


def _page_id(p):
    site, kind, stem = p
    return f"{site}-{kind}" + (f"-{stem}" if stem else "")


# ---------------------------------------------------------------------------------------------------
# fixtures


@pytest.fixture(scope="session")
def browser():
    if not Path(CHROMIUM).exists():
        pytest.fail(f"{CHROMIUM} is missing: `make chromium` (or apt-get install chromium) installs Debian's")
    from playwright.sync_api import sync_playwright

    with sync_playwright() as p:
        b = p.chromium.launch(executable_path=CHROMIUM, args=ARGS)
        yield b
        b.close()


@pytest.fixture(scope="session")
def sites(tmp_path_factory):
    """The handouts of the real notebooks and of the fixture, built once (what `make handouts` does).

    ``KINLIB_HANDOUTS_DIR=build/handouts`` tests an existing build of the real notebooks instead (a quick
    loop after ``make handouts``). A failing real notebook fails its pages' tests, not the fixture's.
    """
    from kinlib.course import handouts

    base = tmp_path_factory.mktemp("browser")
    out = {}
    handouts.build(FIXTURES, base / "fixture", vendor=VENDOR, jobs=1, verify=False, log=lambda s: None)
    out["fixture"] = base / "fixture"
    if os.environ.get("KINLIB_HANDOUTS_DIR"):
        out["handouts"] = Path(os.environ["KINLIB_HANDOUTS_DIR"]).resolve()
    elif REAL:
        built = ROOT / "build" / "handouts"
        if _fresh(built):  # `make handouts` just ran: test what it made
            out["handouts"] = built
        else:
            try:
                handouts.build(NOTEBOOKS, built, vendor=VENDOR, jobs=2, verify=False, log=lambda s: None)
                out["handouts"] = built
            except handouts.NotebookFailed as e:
                out["handouts"] = e
    return out


def _fresh(built: Path) -> bool:
    """build/handouts is newer than every notebook and kinlib module, and has every notebook's pages."""
    index = built / "index.html"
    if not index.exists():
        return False
    sources = list(NOTEBOOKS.glob("[0-9][0-9]_*.ipynb")) + list((ROOT / "kinlib").rglob("*.py"))
    if max(p.stat().st_mtime for p in sources) >= index.stat().st_mtime:
        return False
    return all((built / k / f"{s}.html").exists() for s in REAL for k in ("problems", "solutions"))


def _site(sites, name):
    site = sites.get(name)
    if site is None:
        pytest.fail(f"no {name} pages were built: notebooks/ has no NN_*.ipynb notebook", pytrace=False)
    if isinstance(site, Exception):
        pytest.fail(f"make handouts fails: {site}", pytrace=False)
    return site


class Watch:
    """Records what a page asks of the network and what goes wrong on it."""

    def __init__(self, page, allow=("file:", "data:", "blob:", "about:")):
        self.blocked, self.failed, self.errors, self.console = [], [], [], []
        self.allow = allow

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
        page.on("response", lambda r: self.failed.append(f"{r.url} (HTTP {r.status})") if r.status >= 400 else None)

    def assert_clean(self, what):
        assert not self.blocked, f"{what} tried to reach the network: {self.blocked[:5]}"
        assert not self.failed, f"{what}: failed requests {self.failed[:5]}"
        assert not self.errors, f"{what}: page errors {self.errors[:5]}"
        assert not self.console, f"{what}: console errors {self.console[:5]}"


def _open(browser, path: Path):
    page = browser.new_page(viewport={"width": 1200, "height": 900})
    watch = Watch(page)
    page.goto(path.as_uri(), wait_until="load")
    return page, watch


_MATHJAX_DONE = """() => new Promise(resolve => {
  if (!window.MathJax || !MathJax.Hub) { resolve(false); return; }
  MathJax.Hub.Queue(() => resolve(true));
})"""


# ---------------------------------------------------------------------------------------------------
# 1. the static pages


@pytest.mark.parametrize("spec", PAGES, ids=_page_id)
def test_handout_page_renders_offline(sites, browser, spec):
    site, kind, stem = spec
    root = _site(sites, site)
    path = root / "index.html" if kind == "index" else root / kind / f"{stem}.html"
    page, watch = _open(browser, path)
    try:
        if kind == "index":
            links = page.eval_on_selector_all("a", "els => els.map(e => e.getAttribute('href'))")
            stems = REAL if site == "handouts" else FIXTURE
            for s in stems:
                for target in (f"problems/{s}.html", f"solutions/{s}.html", f"workbooks/{s}.ipynb"):
                    assert target in links and (root / target).is_file(), target
        else:
            assert page.evaluate(_MATHJAX_DONE), "MathJax did not load"
            html = path.read_text(encoding="utf-8")
            # typeset math, no raw TeX left in the rendered markdown and LaTeX outputs
            n_math = page.locator(".MathJax, .MathJax_Display").count()
            if _has_tex(html):
                assert n_math > 0, "the page has TeX but no typeset math"
            assert page.locator(".MathJax_Error, .noError, merror").count() == 0, "MathJax errors"
            rendered = page.eval_on_selector_all(
                ".jp-RenderedMarkdown, .jp-RenderedLatex", "els => els.map(e => e.innerText).join('\\n')"
            )
            for raw in ("$$", "\\begin{", "\\frac", "\\left[", "\\theta"):
                assert raw not in rendered, f"raw TeX {raw!r} visible"
            # the saved widgets are shown
            if "application/vnd.jupyter.widget-view+json" in html:
                page.wait_for_selector(".jupyter-widgets", timeout=15000)
                page.wait_for_timeout(300)
                assert page.locator(".jupyter-widgets").count() > 0
                assert page.get_by_text("Error displaying widget").count() == 0
                assert page.locator(".jupyter-widgets-error-widget").count() == 0
            # figures: every image decoded; as many as the page embeds
            page.wait_for_function("() => Array.from(document.images).every(i => i.complete)")
            broken = page.evaluate(
                "() => Array.from(document.images).filter(i => !i.naturalWidth).map(i => (i.src || '').slice(0, 60))"
            )
            assert not broken, f"images that did not load: {broken}"
            n_png = len(re.findall(r"<img[^>]*src=\"data:image/", html))
            assert page.locator("img").count() >= n_png
            if kind == "problems":
                assert (
                    page.locator(".jp-InputPrompt").evaluate_all(
                        "els => els.filter(e => /\\d/.test(e.innerText)).length"
                    )
                    == 0
                ), "prompt numbers shown"
            page.wait_for_timeout(200)
        watch.assert_clean(path.name)
        SCREENSHOTS.mkdir(parents=True, exist_ok=True)
        page.screenshot(path=str(SCREENSHOTS / f"{_page_id(spec)}.png"), full_page=True)
    finally:
        page.close()


def _has_tex(html: str) -> bool:
    """Whether the page's markdown or LaTeX outputs hold TeX (before MathJax)."""
    from bs4 import BeautifulSoup

    soup = BeautifulSoup(html, "html.parser")
    text = "\n".join(e.get_text() for e in soup.select(".jp-RenderedMarkdown, .jp-RenderedLatex"))
    return bool(re.search(r"\$|\\\(|\\\[|\\begin\{", text))


def _animation_pages(sites):
    pages = []
    for site, root in sites.items():
        if isinstance(root, Exception):
            continue
        for p in sorted((root / "solutions").glob("*.html")):
            if "anim_step_forward" in p.read_text(encoding="utf-8") or "_anim_img" in p.read_text(encoding="utf-8"):
                pages.append((site, p))
    return pages


def test_an_animation_plays_without_a_kernel(sites, browser):
    pages = _animation_pages(sites)
    assert any(site == "fixture" for site, _ in pages)
    for _kind, path in pages:
        page, watch = _open(browser, path)
        try:
            img = page.locator("img[id^='_anim_img']").first
            img.scroll_into_view_if_needed()
            first = img.get_attribute("src")
            # the "next frame" button, then play: the frame changes with no kernel and no network
            page.locator("button[onclick*='next_frame']").first.click()
            page.wait_for_timeout(150)
            second = img.get_attribute("src")
            assert second != first, f"{path.name}: the animation did not step"
            page.locator("button[onclick*='play_animation']").first.click()
            seen = set()
            for _ in range(12):
                page.wait_for_timeout(40)
                seen.add(img.get_attribute("src"))
            assert len(seen) >= 2, f"{path.name}: the animation did not play"
            watch.assert_clean(path.name)
        finally:
            page.close()
    assert "05_singularities_planar" in REAL, "notebooks/05_singularities_planar.ipynb is missing"
    _site(sites, "handouts")
    assert any(site == "handouts" for site, _ in pages), (
        "no real handout carries an animation: notebook 05 should show "
        "kinlib.plotting.animate_singularity(...) as HTML(anim.to_jshtml())"
    )


# ---------------------------------------------------------------------------------------------------
# 2. JupyterLab: notebook 05's explorer reaches a singular configuration


def _free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


@pytest.fixture(scope="module")
def lab(tmp_path_factory):
    nb05 = NOTEBOOKS / "05_singularities_planar.ipynb"
    assert nb05.exists(), "notebooks/05_singularities_planar.ipynb is missing"
    work = tmp_path_factory.mktemp("lab")
    scratch = work / "notebooks"
    shutil.copytree(NOTEBOOKS, scratch)
    port = _free_port()
    jupyter = Path(sys.executable).parent / "jupyter"
    env = dict(
        os.environ,
        JUPYTER_CONFIG_DIR=str(work / "config"),
        JUPYTERLAB_SETTINGS_DIR=str(work / "settings"),
        JUPYTERLAB_WORKSPACES_DIR=str(work / "workspaces"),
    )
    notif = work / "settings" / "@jupyterlab" / "apputils-extension" / "notification.jupyterlab-settings"
    notif.parent.mkdir(parents=True)
    notif.write_text('{"fetchNews": "false", "checkForUpdates": false}')  # no news toast
    log = open(work / "lab.log", "w")
    proc = subprocess.Popen(
        [
            str(jupyter),
            "lab",
            "--no-browser",
            "--IdentityProvider.token=",
            "--expose-app-in-browser",
            "--allow-root",
            f"--port={port}",
            "--ServerApp.ip=127.0.0.1",
            "--ServerApp.port_retries=0",
            f"--ServerApp.root_dir={scratch}",
            "--LabApp.news_url=None",
            "--LabApp.check_for_updates_class=jupyterlab.NeverCheckForUpdate",
        ],
        stdout=log,
        stderr=subprocess.STDOUT,
        env=env,
        start_new_session=True,
    )
    url = f"http://127.0.0.1:{port}"
    try:
        deadline = time.time() + 60
        while True:
            try:
                urllib.request.urlopen(url + "/api/status", timeout=2)
                break
            except OSError:
                if proc.poll() is not None or time.time() > deadline:
                    raise RuntimeError("JupyterLab did not start:\n" + (work / "lab.log").read_text()[-3000:]) from None
                time.sleep(0.3)
        yield url
    finally:
        os.killpg(proc.pid, signal.SIGTERM)
        try:
            proc.wait(15)
        except subprocess.TimeoutExpired:
            os.killpg(proc.pid, signal.SIGKILL)
        log.close()


_KERNEL_IDLE = """() => {
  const w = window.jupyterapp && window.jupyterapp.shell.currentWidget;
  const k = w && w.sessionContext && w.sessionContext.session && w.sessionContext.session.kernel;
  return !!k && k.status === 'idle' && w.content && w.content.widgets && w.content.widgets.length > 0;
}"""

_RUN_ALL_DONE = """() => {
  const w = window.jupyterapp.shell.currentWidget;
  const k = w.sessionContext.session.kernel;
  return k.status === 'idle' && w.content.widgets.every(c => c.model.type !== 'code' || !c.promptNode
           || !c.promptNode.textContent.includes('*'));
}"""


def test_lab_explorer_reaches_a_singular_configuration(browser, lab):
    page = browser.new_page(viewport={"width": 1400, "height": 1000})
    host = lab.split("//")[1]
    watch = Watch(page, allow=(lab, f"ws://{host}", "data:", "blob:", "about:"))
    try:
        t0 = time.time()
        page.goto(f"{lab}/lab/tree/05_singularities_planar.ipynb", wait_until="domcontentloaded")
        page.wait_for_function(_KERNEL_IDLE, timeout=60000)
        page.evaluate("() => window.jupyterapp.commands.execute('notebook:run-all-cells')")
        page.wait_for_timeout(500)
        page.wait_for_function(_RUN_ALL_DONE, timeout=90000, polling=250)
        assert (
            page.locator(
                ".jp-OutputArea-output[data-mime-type='application/vnd.jupyter.stderr'] :text('Traceback')"
            ).count()
            == 0
        )
        errors = page.locator(".jp-OutputArea-output[data-mime-type='application/vnd.jupyter.error']")
        assert errors.count() == 0, "a cell raised: " + errors.first.inner_text()[:500]

        ex = page.locator(".jp-OutputArea-output").filter(has_text="joint positions").first
        ex.scroll_into_view_if_needed()
        status = ex.locator(".widget-html").filter(has_text="configuration").last
        page.wait_for_function("(el) => el.innerText.length > 0", arg=status.element_handle(), timeout=20000)
        assert "SINGULAR" not in status.inner_text(), "the explorer should start at a regular configuration"
        picture = ex.locator("img").first
        before = picture.screenshot()

        # θ2's slider: move it with the keyboard to the singular θ2 = -π/4 (det J ∝ sin(θ2 + π/4))
        slider = ex.locator(".widget-slider, .widget-hslider").filter(has_text="θ2").first
        handle = slider.locator(".noUi-handle").first
        readout = slider.locator(".widget-readout").first
        handle.focus()
        target, step = -math.pi / 4, math.pi / 180
        for _ in range(200):
            value = float(readout.inner_text().replace("\u2212", "-"))
            if abs(value - target) < step / 2:
                break
            handle.press("ArrowLeft" if value > target else "ArrowRight")
        else:
            pytest.fail(f"the θ2 slider did not reach {target:.3f} (at {readout.inner_text()})")
        page.wait_for_function("(el) => el.innerText.includes('SINGULAR')", arg=status.element_handle(), timeout=20000)
        page.wait_for_timeout(500)  # the last picture
        after = picture.screenshot()
        assert after != before, "the explorer's picture did not change"
        SCREENSHOTS.mkdir(parents=True, exist_ok=True)
        (SCREENSHOTS / "lab-05-explorer-before.png").write_bytes(before)
        (SCREENSHOTS / "lab-05-explorer-singular.png").write_bytes(after)
        ex.screenshot(path=str(SCREENSHOTS / "lab-05-explorer.png"))
        assert time.time() - t0 < 120
        assert not watch.blocked, f"JupyterLab tried to reach the network: {watch.blocked[:5]}"
        assert not watch.errors, f"page errors: {watch.errors[:5]}"
    finally:
        page.close()
