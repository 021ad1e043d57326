"""Browser tests (marked ``browser``): Debian's chromium through the playwright package, never a
downloaded browser, with the network blocked.

1. Every handout page (built once per session by the same code as ``make handouts``, from the real
   notebooks and from the fixture notebook) loads from disk with no request leaving the machine, no
   page error and no failed request, shows typeset math (MathJax output, no raw TeX) and its figures
   (every image decoded), and the saved widgets; a screenshot of each goes to build/screenshots/.
   The animation (5.2) steps and plays, and the picker (4.1) changes configuration, in the static pages.
2. JupyterLab as ``make lab`` starts it (tests/labdriver.py: notebooks trusted, notebooks/.lab-settings/), on a free
   loopback port: every notebook opened fresh shows its widgets' and animation's pictures before running,
   runs all cells (the time is printed, not asserted), and a slider of each explorer (a button of a picker)
   gives a new picture; in notebook 05 the explorer at θ2 = −π/4 says "singular" (``kinlib-status``), shows
   det J = 0 (``kinlib-det``) and a collapsed held-orientation ellipse (``kinlib-held``). Opened untrusted
   (without ``make lab``), notebook 05 still shows static pictures (the display bundles' image/png).
"""

from __future__ import annotations

import json
import math
import os
import re
import subprocess
from pathlib import Path

import pytest

import labdriver

ROOT = Path(__file__).resolve().parents[2]
NOTEBOOKS = ROOT / "notebooks"
FIXTURES = ROOT / "tests" / "fixtures" / "handouts"
VENDOR = ROOT / "build" / "vendor"
SCREENSHOTS = ROOT / "build" / "screenshots"
CHROMIUM = labdriver.CHROMIUM
ARGS = labdriver.CHROMIUM_ARGS

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


@pytest.fixture
def browser(shared_browser):
    """The run's one chromium (tests/conftest.py: one playwright session for every browser module)."""
    return shared_browser


@pytest.fixture(scope="session")
def sites(request, fixture_handouts):
    """The handouts of the real notebooks and of the fixture, each built once per run (tests/conftest.py:
    ``real_handouts``, what `make handouts` does, into build/handouts; ``fixture_handouts``, shared with
    tests/course/test_handouts.py).

    ``KINLIB_HANDOUTS_DIR=build/handouts`` tests an existing build of the real notebooks instead (a quick
    loop after ``make handouts``). A failing real notebook fails its pages' tests, not the fixture's.
    """
    from kinlib.course.publish import handouts

    out = {"fixture": fixture_handouts[0]}
    if REAL:
        try:
            out["handouts"] = request.getfixturevalue("real_handouts")
        except handouts.NotebookFailed as e:
            out["handouts"] = e
    return out


def _site(sites, name):
    site = sites.get(name)
    if site is None:
        pytest.fail(f"no {name} pages were built: notebooks/ has no NN_*.ipynb notebook", pytrace=False)
    if isinstance(site, Exception):
        pytest.fail(f"make handouts fails: {site}", pytrace=False)
    return site


Watch = labdriver.Watch  # blocked/failed requests, page and console errors


def _open(browser, path: Path):
    page = browser.new_page(viewport={"width": 1200, "height": 900})
    watch = Watch(page)
    page.goto(path.as_uri(), wait_until="load")
    return page, watch


#: what the tests after test_handout_page_renders_offline drive on a static page (they go on in its page)
_DRIVEN = ("window.kinlibAnimation(host, S);", "window.kinlibPicker(host, S);")
_DRIVEN_STEMS = ("05_singularities_planar", "06_singularities_spatial")


@pytest.fixture(scope="module")
def static_pages():
    """The static pages test_handout_page_renders_offline loaded and checked that a later test of this module
    drives (animation, picker, the 05 and 06 explorers): kept open, so each is loaded once (a MathJax page costs
    Chromium seconds), not once per test; closed with the module. {path: (page, watch)}"""
    kept: dict = {}
    yield kept
    for page, _watch in kept.values():
        try:
            page.close()
        except Exception:  # the run's chromium may be stopped already (tests/conftest.py)
            pass


def _open_static(browser, static_pages, path: Path):
    """(page, watch) of the static page ``path``: the one test_handout_page_renders_offline left open (its watch
    goes on collecting), or a fresh one (run alone). Give it back with :func:`_done`."""
    kept = static_pages.get(path)
    if kept is not None and not kept[0].is_closed():
        return kept
    return _open(browser, path)


def _done(static_pages, page) -> None:
    if not any(page is kept for kept, _ in static_pages.values()):
        page.close()


_MATHJAX_DONE = """() => new Promise(resolve => {
  if (!window.MathJax || !MathJax.Hub) { resolve(false); return; }
  MathJax.Hub.Queue(() => resolve(true));
})"""


# ---------------------------------------------------------------------------------------------------
# 1. the static pages


@pytest.mark.parametrize("spec", PAGES, ids=_page_id)
def test_handout_page_renders_offline(sites, browser, static_pages, spec):
    site, kind, stem = spec
    root = _site(sites, site)
    path = root / "index.html" if kind == "index" else root / kind / f"{stem}.html"
    page, watch = _open(browser, path)
    keep = False
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
                page.wait_for_selector(".jupyter-widgets", timeout=60000)
                page.wait_for_timeout(300)
                assert page.locator(".jupyter-widgets").count() > 0
                assert page.get_by_text("Error displaying widget").count() == 0
                assert page.locator(".jupyter-widgets-error-widget").count() == 0
            # the explorers are drawn by their own script (kinlib.widgets: no widget manager, no kernel)
            n_explorers = html.count("window.kinlibExplorer(host, S)")
            if n_explorers:
                page.wait_for_function(
                    "(n) => document.querySelectorAll('.kinlib-explorer svg.kinlib-picture .kinlib-arm').length >= n",
                    arg=n_explorers,
                    timeout=60000,
                )
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
        keep = kind == "solutions" and (
            any(needle in html for needle in _DRIVEN) or (site == "handouts" and stem in _DRIVEN_STEMS)
        )
        if keep:
            static_pages[path] = (page, watch)
    finally:
        if not keep:
            page.close()


def _has_tex(html: str) -> bool:
    """Whether the page's markdown or LaTeX outputs hold TeX (before MathJax)."""
    from bs4 import BeautifulSoup

    soup = BeautifulSoup(html, "html.parser")
    text = "\n".join(e.get_text() for e in soup.select(".jp-RenderedMarkdown, .jp-RenderedLatex"))
    return bool(re.search(r"\$|\\\(|\\\[|\\begin\{", text))


def _pages_with(sites, needle):
    pages = []
    for site, root in sites.items():
        if isinstance(root, Exception):
            continue
        for p in sorted((root / "solutions").glob("*.html")):
            if needle in p.read_text(encoding="utf-8"):
                pages.append((site, p))
    return pages


def test_an_animation_and_a_picker_play_without_a_kernel(sites, browser, static_pages):
    """kinlib.widgets' animation (5.2) and configuration picker (4.1) on the static solutions pages (files, no
    kernel, network blocked): the step slider's arrow key and the play button step the arm, a picker button draws
    another configuration (tests/pictures/test_widgets.py checks what is drawn)."""
    pages = _pages_with(sites, "window.kinlibAnimation(host, S);")
    assert any(site == "fixture" for site, _ in pages)
    for _kind, path in pages:
        page, watch = _open_static(browser, static_pages, path)
        try:
            root = page.locator(".kinlib-animation").first
            root.locator(".kinlib-arm").wait_for(timeout=60000)
            root.scroll_into_view_if_needed()
            arm = root.locator(".kinlib-arm")
            first = arm.get_attribute("d")
            root.locator("input.kinlib-step").focus()
            page.keyboard.press("ArrowRight")
            assert root.get_attribute("data-step") == "1" and arm.get_attribute("d") != first, path.name
            root.locator("button.kinlib-play").click()
            page.wait_for_function(
                "(r) => +r.getAttribute('data-step') >= 3", arg=root.element_handle(), timeout=60000, polling=20
            )
            root.locator("button.kinlib-play").click()  # pause
            watch.assert_clean(path.name)
        finally:
            _done(static_pages, page)
    assert "05_singularities_planar" in REAL, "notebooks/05_singularities_planar.ipynb is missing"
    _site(sites, "handouts")
    assert any(site == "handouts" and p.stem.startswith("05") for site, p in pages), (
        "notebook 05's solutions page has no animation: it should show kinlib.widgets.animate_singularity(...)"
    )
    pickers = [p for site, p in _pages_with(sites, "window.kinlibPicker(host, S);") if site == "handouts"]
    assert [p.stem[:2] for p in pickers] == ["04"], pickers
    page, watch = _open_static(browser, static_pages, pickers[0])
    try:
        root = page.locator(".kinlib-picker").first
        root.locator(".kinlib-arm").wait_for(timeout=60000)
        root.scroll_into_view_if_needed()
        before = root.locator(".kinlib-arm").get_attribute("d")
        second = root.locator("button.kinlib-config").nth(1)
        second.focus()
        page.keyboard.press("Enter")
        assert (
            second.get_attribute("aria-pressed") == "true" and root.locator(".kinlib-arm").get_attribute("d") != before
        )
        watch.assert_clean(pickers[0].name)
    finally:
        _done(static_pages, page)


def _explorer_on_static_page(sites, browser, static_pages, stem, index=-1):
    root = _site(sites, "handouts")
    path = root / "solutions" / f"{stem}.html"
    page, watch = _open_static(browser, static_pages, path)
    page.wait_for_function("() => document.querySelectorAll('.kinlib-explorer .kinlib-arm').length > 0", timeout=60000)
    ex = page.locator(".kinlib-explorer").nth(index) if index >= 0 else page.locator(".kinlib-explorer").last
    ex.scroll_into_view_if_needed()
    return page, watch, ex


def test_static_page_05_explorer_goes_singular_without_a_kernel(sites, browser, static_pages):
    """The solutions page of notebook 05 (a file, no kernel, network blocked): θ2 moved to −π/4 with the arrow
    keys shows the singular banner, det J = 0, the collapsed held ellipse and the blocked direction, and the
    aria-live text says so; each key gives a new picture (times printed, `make bench` reports them)."""
    page, watch, ex = _explorer_on_static_page(sites, browser, static_pages, "05_singularities_planar")
    try:
        SCREENSHOTS.mkdir(parents=True, exist_ok=True)
        ex.screenshot(path=str(SCREENSHOTS / "static-05-explorer-before.png"))
        assert ex.locator(".kinlib-status").get_attribute("data-state") != "singular"
        s, handle, readout = labdriver.slider(page.locator(".jp-OutputArea-output").filter(has=ex).last, "θ2")
        handle.focus()
        target, step = -math.pi / 4, math.pi / 180
        times = []
        for _ in range(400):
            value = labdriver.slider_value(readout)
            if abs(value - target) < step / 2:
                break
            area = page.locator(".jp-OutputArea-output").filter(has=ex).last
            times.append(labdriver.move_slider(area, handle, "ArrowLeft" if value > target else "ArrowRight"))
        else:
            pytest.fail(f"the θ2 slider did not reach {target:.3f} (at {readout.inner_text()})")
        assert ex.locator(".kinlib-status").get_attribute("data-state") == "singular"
        assert "SINGULAR" in ex.locator(".kinlib-status").inner_text().upper()
        assert ex.locator(".kinlib-det").inner_text().strip() == "0"
        axes = _numbers(ex.locator(".kinlib-held").inner_text())
        assert len(axes) == 2 and min(axes) == 0 and max(axes) > 0
        assert ex.locator(".kinlib-blocked").count() == 1
        live = ex.locator(".kinlib-live")
        assert live.get_attribute("aria-live") == "polite"
        text = live.inner_text()
        assert "Singular configuration" in text and "cannot move along" in text, text
        ex.screenshot(path=str(SCREENSHOTS / "static-05-explorer-singular.png"))
        # printed (the PDF handouts): the drawing and the values stay, the sliders give way
        page.emulate_media(media="print")
        shown = ex.evaluate(
            "root => ['.kinlib-picture', '.kinlib-arm', '.kinlib-readout', '.kinlib-status', '.kinlib-track']"
            ".map(s => getComputedStyle(root.querySelector(s)).display !== 'none')"
        )
        assert shown == [True, True, True, True, False], shown
        page.emulate_media(media="screen")
        times.sort()
        print(
            f"\nstatic page: key → new picture min {times[0]:.1f} / median {times[len(times) // 2]:.1f} / max {times[-1]:.1f} ms"
        )
        watch.assert_clean("solutions/05")
    finally:
        _done(static_pages, page)


def test_static_page_05_slider_marks_are_singular_configurations(sites, browser, static_pages):
    """θ2's track marks exactly the members of singular_configurations' family in the slider's range, computed
    independently here (kinlib.singular_configurations on the exact Jacobian of the same robot)."""
    import sympy as sp

    from kinlib import robots, singular_configurations
    from kinlib.taskspace import task_rows

    r = robots.planar_offset_3r()
    (cond,) = singular_configurations(task_rows(r.jacobian_geometric(), ["wz", "vx", "vy"]), r.thetas)
    members = sorted(float(x) for x in sp.Intersection(cond[r.thetas[1]], sp.Interval(-sp.pi, sp.pi)))
    page, watch, ex = _explorer_on_static_page(sites, browser, static_pages, "05_singularities_planar")
    try:
        for j, want in ((1, []), (2, members), (3, [])):
            got = ex.locator(f"input.kinlib-slider[data-joint='{j}'] ~ div .kinlib-mark").evaluate_all(
                "els => els.map(e => +e.getAttribute('data-value'))"
            )
            assert got == pytest.approx(want, abs=1e-12), (j, got, want)
        watch.assert_clean("solutions/05")
    finally:
        _done(static_pages, page)


def test_static_page_3d_explorer_turns_and_moves(sites, browser, static_pages):
    """Notebook 06's spatial explorer on its solutions page: the view turns from the keyboard (the drawing
    changes, the arm's world coordinates do not) and a joint slider moves the arm."""
    page, watch, ex = _explorer_on_static_page(sites, browser, static_pages, "06_singularities_spatial")
    try:
        SCREENSHOTS.mkdir(parents=True, exist_ok=True)
        ex.screenshot(path=str(SCREENSHOTS / "static-06-explorer-before.png"))
        links = ex.locator(".kinlib-arm")
        before = links.get_attribute("d")
        world = ex.locator(".kinlib-tool").get_attribute("data-x")
        ex.locator("svg.kinlib-picture").focus()
        page.keyboard.press("ArrowRight")
        assert links.get_attribute("d") != before and ex.locator(".kinlib-tool").get_attribute("data-x") == world
        s, handle, readout = labdriver.slider(page.locator(".jp-OutputArea-output").filter(has=ex).last, "θ1")
        handle.focus()
        for _ in range(20):
            page.keyboard.press("ArrowRight")
        assert ex.locator(".kinlib-tool").get_attribute("data-x") != world
        ex.screenshot(path=str(SCREENSHOTS / "static-06-explorer-after.png"))
        watch.assert_clean("solutions/06")
    finally:
        _done(static_pages, page)


# ---------------------------------------------------------------------------------------------------
# 2. JupyterLab, as `make lab` starts it (tests/labdriver.py): every notebook opens with its pictures, runs,
#    and its explorers move; notebook 05's explorer at a singular configuration says so and shows it.
#    Times are printed (run with -s to see them; `make bench` reports them), never asserted.


def _lab_notebooks() -> Path:
    """notebooks/, or ``KINLIB_LAB_NOTEBOOKS`` (e.g. a copy just run by ``kinlib execute``, to test the
    notebooks as `make notebooks` would leave them without touching notebooks/)."""
    return Path(os.environ.get("KINLIB_LAB_NOTEBOOKS") or NOTEBOOKS).resolve()


UNTRUSTED_05 = "untrusted/05_singularities_planar"  # the copy of notebook 05 nobody trusted (labdriver.jupyterlab)


@pytest.fixture(scope="module")
def lab(tmp_path_factory):
    """JupyterLab on a copy of the notebooks, trusted and with notebooks/.lab-settings/ (what `make lab` does), plus
    a copy of notebook 05 that nobody trusted (opened without `make lab`): one server for both."""
    work = tmp_path_factory.mktemp("lab")
    with labdriver.jupyterlab(work, _lab_notebooks(), trust=True, untrusted=(UNTRUSTED_05.split("/")[1],)) as url:
        try:
            yield url
        finally:
            app = _APPS.pop(url, None)
            if app is not None:
                try:
                    app.quit()
                except Exception:  # the run's chromium may be stopped already (tests/conftest.py)
                    pass


#: the JupyterLab page of each server (labdriver.Lab: the front end loaded once, the notebooks opened in turn)
_APPS: dict = {}


def _app(browser, url) -> labdriver.Lab:
    app = _APPS.get(url)
    if app is None or app.browser is not browser:
        app = _APPS[url] = labdriver.Lab(browser, url)
    return app


def test_make_lab_trusts_the_notebooks_and_uses_the_project_settings():
    """`make lab` trusts the notebooks (JupyterLab renders saved widgets only in trusted notebooks) and starts
    JupyterLab with notebooks/.lab-settings/, whose overrides save the widget state with the notebook."""
    out = subprocess.run(["make", "-n", "lab"], cwd=ROOT, capture_output=True, text=True, check=True).stdout
    assert re.search(r"jupyter trust .*notebooks/\d\d_", out), out
    assert f"--LabApp.app_settings_dir={ROOT / 'notebooks' / '.lab-settings'}" in out, out
    overrides = json.loads((labdriver.LAB_SETTINGS / "overrides.json").read_text())
    assert overrides["@jupyter-widgets/jupyterlab-manager:plugin"]["saveState"] is True


_TOASTS = """() => Array.from(document.querySelectorAll('.Toastify__toast')).map(e => e.innerText)"""


def test_make_lab_shows_no_news_and_logs_no_console_error(browser, lab):
    """JupyterLab as `make lab` starts it (notebooks/.lab-settings/, the project's .venv after `make setup`) opens a
    notebook in a new page with no notification over it (no "official Jupyter news?" question: the project's
    overrides turn news and update checks off; labdriver sets nothing of its own) and no console error (the
    JupyterLite kernel's lab extension is not in JupyterLab's path: `make lab-extensions`)."""
    overrides = json.loads((labdriver.LAB_SETTINGS / "overrides.json").read_text())
    notification = overrides["@jupyterlab/apputils-extension:notification"]
    assert notification == {"fetchNews": "false", "checkForUpdates": False}, notification
    page, watch = labdriver.open_notebook(browser, lab, "04_interpreting_the_jacobian")
    try:
        # the news question is asked once the application has started: wait for the notebook's kernel, then
        # for every plugin to be activated (JupyterLab's ``started`` and ``restored``)
        page.evaluate("() => Promise.all([window.jupyterapp.started, window.jupyterapp.restored]).then(() => null)")
        toasts = page.evaluate(_TOASTS)
        center = page.evaluate(
            """() => { const b = document.querySelector('.jp-Notification-Status');
                       return b ? b.innerText.trim() : ''; }"""
        )
        assert not toasts, f"a notification over the notebook: {toasts}"
        assert center in ("", "0"), f"the notification center holds {center} notification(s)"
        assert not watch.console, f"console errors in `make lab`: {[m[:300] for m in watch.console[:3]]}"
        assert not watch.errors, f"page errors in `make lab`: {[m[:300] for m in watch.errors[:3]]}"
        assert not watch.blocked, f"JupyterLab tried to reach the network: {watch.blocked[:5]}"
    finally:
        labdriver.close_notebook(page)


def _no_text_reprs(page):
    """No widget or animation shown as its text repr (`Explorer(children=…`, `<…Animation object…>`)."""
    text = page.locator(f"{labdriver.CURRENT} .jp-OutputArea-output[data-mime-type='text/plain']").evaluate_all(
        "els => els.map(e => e.textContent).join('\\n')"
    )
    for bad in ("Explorer(children", "ConfigPicker(children", "VBox(children", "Animation object"):
        assert bad not in text, f"a widget is shown as text: {bad}…"
    assert page.locator(labdriver.CURRENT).get_by_text("Error displaying widget").count() == 0


#: notebook 05 left open (and run) by its test below, per server: the next test goes on in it (one run-all, not two)
_RUN_05: set = set()


@pytest.mark.parametrize("stem", REAL)
def test_lab_notebook_opens_with_pictures_runs_and_its_explorers_move(browser, lab, stem):
    app = _app(browser, lab)
    page, watch = app.open(stem)
    keep = False
    try:
        # 1. opened fresh, not run: every widget and animation shows its saved picture
        widgets = labdriver.widget_cells(page)
        for area in widgets:
            labdriver.wait_picture(area, what="a widget output on open (saved widget state)")
        anims = labdriver.animations(page)
        for k in range(anims.count()):
            labdriver.wait_picture(anims.nth(k), what="the animation on open")
        _no_text_reprs(page)
        if stem.startswith("05"):
            assert widgets and anims.count(), "notebook 05 has an explorer and an animation"
        SCREENSHOTS.mkdir(parents=True, exist_ok=True)
        if widgets:
            labdriver.scroll_to(widgets[0])
            widgets[0].screenshot(path=str(SCREENSHOTS / f"lab-{stem}-on-open.png"))

        # 2. run all (time reported, not asserted)
        seconds, kernel = labdriver.run_all(page, details=True)
        print(f"\n{stem}: run-all {seconds:.1f} s in JupyterLab (kernel busy {kernel:.1f} s)")
        for k in range(anims.count()):  # the player shows frame 0 after run-all, not a blank
            labdriver.wait_picture(anims.nth(k), what="the animation after run-all")
        _no_text_reprs(page)

        # 3. each explorer: one key press on θ1 gives a new picture; a picker: another button, a new picture
        for area in labdriver.widget_cells(page):
            labdriver.wait_picture(area)
            if labdriver.EXPLORER_TEXT in area.text_content():
                _slider, handle, readout = labdriver.slider(area, "θ1")
                before = readout.inner_text()
                handle.focus()
                ms = labdriver.move_slider(area, handle, "ArrowRight")
                assert readout.inner_text() != before, "the slider did not move"
                print(f"{stem}: slider move → new picture {ms:.0f} ms")
            else:
                buttons = area.locator("button:not(.mod-active)")
                assert buttons.count() > 0, "a widget that is neither an explorer nor a picker"
                ms = labdriver.click_and_wait(area, buttons.first)
                print(f"{stem}: picker button → new picture {ms:.0f} ms")
        assert not watch.blocked, f"JupyterLab tried to reach the network: {watch.blocked[:5]}"
        assert not watch.errors, f"page errors: {[e[-300:] for e in watch.errors[:3]]}"
        keep = stem == "05_singularities_planar"
        if keep:
            _RUN_05.add(lab)
    finally:
        if not keep:
            app.close(stem)


def _numbers(text: str) -> list[float]:
    return [float(x) for x in re.findall(r"[-+]?\d+(?:\.\d+)?(?:e[-+]?\d+)?", text.replace("\u2212", "-"))]


def test_lab_05_explorer_at_a_singular_configuration(browser, lab):
    """θ2 = −π/4 (det J ∝ sin(θ2 + π/4)): the banner says singular, det J shows 0 and the ṗ ellipse with the
    orientation held is collapsed (a zero semi-axis); the picture changes on the way there. Goes on in the page
    the test above opened and ran (run alone, it opens and runs the notebook itself)."""
    stem = "05_singularities_planar"
    assert stem in REAL, "notebooks/05_singularities_planar.ipynb is missing"
    app = _app(browser, lab)
    if lab in _RUN_05 and stem in app.ids:
        _RUN_05.discard(lab)
        page, watch = app.activate(stem)
    else:
        page, watch = app.open(stem)
        labdriver.run_all(page)
    try:
        explorers = labdriver.explorers(page)
        assert explorers, "notebook 05 has no explorer"
        ex = explorers[-1]
        labdriver.wait_picture(ex)
        status, det, held = ex.locator(".kinlib-status"), ex.locator(".kinlib-det"), ex.locator(".kinlib-held")
        for name, loc in (("kinlib-status", status), ("kinlib-det", det), ("kinlib-held", held)):
            assert loc.count() == 1, f"the explorer has no element of class {name} (kinlib.widgets)"
        _slider, handle, readout = labdriver.slider(ex, "θ2")
        handle.focus()
        target, step = -math.pi / 4, math.pi / 180
        for _ in range(400):
            value = labdriver.slider_value(readout)
            if abs(value - target) < step / 2:
                break
            handle.press("ArrowLeft" if value > target else "ArrowRight")
        else:
            pytest.fail(f"the θ2 slider did not reach {target:.3f} (at {readout.inner_text()})")
        # the HTML widgets replace their content on every update: query the explorer afresh each time
        page.wait_for_function(
            "(root) => { const s = root.querySelector('.kinlib-status'); "
            "return !!s && s.getAttribute('data-state') === 'singular'; }",
            arg=ex.element_handle(),
            timeout=60000,
            polling=100,
        )
        assert "SINGULAR" in status.inner_text().upper()
        assert det.inner_text().strip() == "0", f"det J shows {det.inner_text()!r} at a singular configuration"
        axes = _numbers(held.inner_text())
        assert len(axes) == 2 and min(axes) == 0 and max(axes) > 0, f"held-orientation ellipse: {held.inner_text()}"
        assert ex.locator(".kinlib-blocked").count() == 1, "no blocked direction drawn at the singular configuration"
        assert "Singular configuration" in ex.locator(".kinlib-live").inner_text()
        SCREENSHOTS.mkdir(parents=True, exist_ok=True)
        ex.screenshot(path=str(SCREENSHOTS / "lab-05-explorer-singular.png"))
        assert not watch.blocked, f"JupyterLab tried to reach the network: {watch.blocked[:5]}"
        assert not watch.errors, f"page errors: {[e[-300:] for e in watch.errors[:3]]}"
    finally:
        app.close(stem)


_ANY_CODE_CELL_TRUSTED = """() => {
  const cells = window.jupyterapp.shell.currentWidget.content.model.cells;
  let n = 0, trusted = false;
  for (let i = 0; i < cells.length; i++)
    if (cells.get(i).type === 'code') { n += 1; trusted = trusted || !!cells.get(i).trusted; }
  return n ? trusted : null;
}"""


def test_untrusted_notebook_shows_static_pictures(browser, lab):
    """Opened without `make lab` (not trusted: a copy of notebook 05 nobody signed), JupyterLab cannot draw widgets;
    the explorer's and the animation's display bundles carry a static image/png, which it shows instead of the
    text repr."""
    stem = "05_singularities_planar"
    assert stem in REAL, "notebooks/05_singularities_planar.ipynb is missing"
    app = _app(browser, lab)
    page, watch = app.open(UNTRUSTED_05)
    trusted = page.evaluate(_ANY_CODE_CELL_TRUSTED)
    assert trusted is False, "the copy of notebook 05 is trusted"
    try:
        areas = labdriver.widget_cells(page)
        assert areas, "notebook 05 has no widget output"
        for area in areas:
            labdriver.wait_picture(area, what="an untrusted widget output (its static image/png)")
            assert area.locator("[data-mime-type='image/png'] img").count() == 1, "no static image/png"
        anim = labdriver.output_of(page, "animate_singularity(")
        assert anim is not None, "notebook 05 has no animation"
        labdriver.wait_picture(anim, what="the untrusted animation (frame 0 without scripts)")
        _no_text_reprs(page)
        assert not watch.blocked, f"JupyterLab tried to reach the network: {watch.blocked[:5]}"
    finally:
        app.close(UNTRUSTED_05)
