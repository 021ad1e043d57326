"""The student's path (issue 30): where a student starts, what the students' site and pages do for them.

- ``make lab-students`` opens JupyterLab on the student workbooks (copied once into a folder of the student's own),
  never on the solution notebooks; ``make site AUDIENCE=students`` serves the students' build; JupyterLab started by
  either asks nothing about news (notebooks/.lab-settings).
"""

from __future__ import annotations

import json
import subprocess
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]


def _make_n(*args) -> str:
    return subprocess.run(["make", "-n", *args], cwd=ROOT, capture_output=True, text=True, check=True).stdout


def test_make_lab_students_opens_the_workbooks_not_the_solutions(tmp_path):
    out = _make_n("lab-students", f"WORKBOOKS_DIR={tmp_path}")
    assert f'--notebook-dir="{tmp_path}"' in out and "--notebook-dir=notebooks" not in out, out
    assert "build/handouts-students/workbooks/" in out and "--audience students" in out, out
    assert 'test -e "' in out  # a workbook the student already has is never overwritten
    assert f"--LabApp.app_settings_dir={ROOT / 'notebooks' / '.lab-settings'}" in out
    readme = (ROOT / "README.md").read_text()
    assert "make lab-students   # students start here" in readme
    assert "(students start here)" not in readme.split("make lab        #")[1].splitlines()[0]


def test_make_site_for_students_serves_the_students_build():
    out = _make_n("site", "AUDIENCE=students")
    assert "serve('build/handouts-students'" in out, out
    assert "serve('build/handouts'" in _make_n("site")


def test_jupyterlab_asks_nothing_about_news():
    overrides = json.loads((ROOT / "notebooks" / ".lab-settings" / "overrides.json").read_text())
    note = overrides["@jupyterlab/apputils-extension:notification"]
    assert note["fetchNews"] == "false" and note["checkForUpdates"] is False


# --- in Chromium, on the real handouts (tests/conftest.py ``real_handouts``: built once per run) ------------------
import pytest  # noqa: E402

SHOTS = ROOT / "build" / "screenshots"
_FOCUSED = """() => {const e = document.activeElement;
  return {tag: e.tagName, cls: e.className || '', text: (e.textContent || '').trim().slice(0, 60),
          slider: e.matches('.kinlib-explorer input.kinlib-slider') && e.getAttribute('data-joint') === '1'};}"""


def _page(browser, path, **context):
    ctx = browser.new_context(**context)
    page = ctx.new_page()
    page.route("**/*", lambda r: r.continue_() if r.request.url.startswith("file:") else r.abort())  # offline
    page.goto(path.as_uri())
    page.wait_for_function("() => document.querySelector('.kinlib-explorer input.kinlib-slider')", timeout=120000)
    page.wait_for_function("() => !window.MathJax || !MathJax.Hub || MathJax.Hub.queue.pending === 0", timeout=120000)
    return ctx, page


@pytest.mark.browser
def test_keyboard_reaches_the_05_explorer_in_ten_tabs(real_handouts, shared_browser):
    """From the top of the 05 solutions page, at most 10 Tab presses reach the explorer's first slider: the page's
    first Tab stops are its skip links (each picture, each part); Enter on "Skip to the explorer" and Tab on from
    there (a keyboard user's Enter on a link is not a Tab). MathJax's formulas are no Tab stops."""
    ctx, page = _page(shared_browser, real_handouts / "solutions" / "05_singularities_planar.html")
    try:
        assert page.evaluate("() => MathJax.Hub.config.menuSettings.inTabOrder") is False
        seen = []
        for _ in range(10):
            page.keyboard.press("Tab")
            got = page.evaluate(_FOCUSED)
            seen.append(f"{got['tag']}.{got['cls'][:30]} {got['text'][:30]!r}")
            if got["slider"]:
                break
            if got["tag"] == "A" and got["text"].startswith("Skip to the explorer"):
                page.keyboard.press("Enter")
        else:
            pytest.fail("10 Tab presses did not reach the explorer's first slider:\n" + "\n".join(seen))
        print(f"the explorer's first slider after {len(seen)} Tab presses: {seen}")
        assert page.locator(".kinlib-skip a").first.inner_text().startswith("Skip to the")
    finally:
        ctx.close()


@pytest.mark.browser
def test_phone_shows_the_whole_drawing_with_its_sliders_just_under(real_handouts, shared_browser):
    """A 390 px wide phone on the 05 problems page: the explorer's drawing scales to its container (whole, inside
    the viewport's width, no sideways scrolling), and its sliders sit just under it (the first within 80 px of the
    drawing's bottom)."""
    ctx, page = _page(
        shared_browser,
        real_handouts / "problems" / "05_singularities_planar.html",
        viewport={"width": 390, "height": 844},
        device_scale_factor=2,
        is_mobile=True,
        has_touch=True,
    )
    try:
        got = page.evaluate(
            """() => {const r = document.querySelector('.kinlib-explorer'), s = r.querySelector('svg.kinlib-picture');
               const b = s.getBoundingClientRect(), sl = r.querySelector('input.kinlib-slider').getBoundingClientRect();
               return {vw: document.documentElement.clientWidth, sw: document.documentElement.scrollWidth,
                       svg: [b.left, b.right, b.top, b.bottom], ratio: b.width / b.height, slider: [sl.left, sl.right, sl.top],
                       drawn: +s.getAttribute('width')};}"""
        )
        left, right, top, bottom = got["svg"]
        assert got["vw"] == 390 and got["sw"] <= 390, got  # nothing wider than the phone
        assert 0 <= left < right <= 390 and right - left < got["drawn"], got  # scaled down, whole
        assert abs(got["ratio"] - 1) < 0.01, got  # equal axes kept
        assert bottom <= got["slider"][2] <= bottom + 80 and got["slider"][1] <= 390, got
        SHOTS.mkdir(parents=True, exist_ok=True)
        page.evaluate("y => window.scrollBy(0, y)", top - 10)
        page.screenshot(path=str(SHOTS / "phone-05-problems-explorer.png"))
    finally:
        ctx.close()


@pytest.mark.browser
def test_printed_pages_have_no_slider_legend_nor_skip_links(real_handouts, shared_browser):
    """The PDF prints the page with no sliders: the explorer's "▲ on a slider" legend and the skip links are not
    printed (they are on screen)."""
    ctx, page = _page(shared_browser, real_handouts / "solutions" / "05_singularities_planar.html")
    try:
        shown = "sel => getComputedStyle(document.querySelector(sel)).display"
        assert page.evaluate(shown, ".kinlib-mark-legend") != "none" and page.evaluate(shown, ".kinlib-skip") != "none"
        page.emulate_media(media="print")
        assert page.evaluate(shown, ".kinlib-mark-legend") == "none" and page.evaluate(shown, ".kinlib-skip") == "none"
    finally:
        ctx.close()
