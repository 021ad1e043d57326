"""PDFs of the handouts: every ``problems/*.html`` and ``solutions/*.html`` page printed by Chromium.

``make handouts`` calls :func:`print_pdfs` after writing the pages; it drives Debian's chromium through
playwright (never a downloaded browser) with every request that is not a local file or loopback URL
aborted, and prints each page only once it is finished: MathJax has typeset (its startup hook, then its
queue), the saved widgets are drawn, every image is decoded and the fonts are loaded. Nothing waits a fixed
time, so a loaded machine makes the same PDF, only later.

The pages carry :data:`PRINT_HEAD` (written by :func:`kinlib.course.publish.pages.export_html`): a print stylesheet
(code and text outputs wrap, figures stay with their captions, sliders give way to their values, the
links bar is hidden) and ``kinlibFitPrint()``, which scales down what is still wider than the paper (the
6×3 SymPy matrices) with CSS ``zoom``. :func:`print_pdfs` calls it at the paper's printable width; a
student printing from the browser gets it through the ``beforeprint`` event.

    build/handouts/pdf/problems/NN_x.pdf, build/handouts/pdf/solutions/NN_x.pdf

Each PDF page has a header naming the handout (``Problem Set 4 · 5 … — solutions``, from the page's
``kinlib-print-header`` meta tag) and a footer with the page number.
"""

from __future__ import annotations

import html
import os
from pathlib import Path
from urllib.parse import urlsplit

__all__ = [
    "print_pdfs",
    "ready_page",
    "launch_args",
    "printable_width_px",
    "PAPER",
    "MARGINS_MM",
    "PRINT_HEAD",
    "CHROMIUM",
    "HEADER_META",
]

CHROMIUM = "/usr/bin/chromium"  # Debian's chromium (`make chromium`)
PAPER = ("A4", 210.0, 297.0)  # format name for page.pdf, width and height in mm
MARGINS_MM = {"top": 16.0, "right": 15.0, "bottom": 14.0, "left": 15.0}
#: the folders of pages printed to out/pdf/<kind>/ (the cheat sheet is in reference/)
PAGE_KINDS = ("problems", "solutions", "reference")
HEADER_META = "kinlib-print-header"
_LOCAL_HOSTS = ("127.0.0.1", "localhost", "::1", "[::1]")
_TIMEOUT_MS = 180_000  # a generous limit for one page to finish (a hung page fails; nothing is timed)

# The print rules, written once and used twice (CSS nesting): under @media print, and under the class
# ``kinlib-print`` that kinlibFitPrint() sets while it measures the page for a print from the browser.
_PRINT_RULES = """
  body, main, .jp-Notebook { padding: 0 !important; margin: 0 !important; width: auto !important; }
  .jp-Notebook { --jp-cell-prompt-width: 5.4em; }
  .jp-InputPrompt, .jp-OutputPrompt { font-size: 7pt; padding-right: 2px; }
  .jp-Cell { padding: 2px 0 !important; }
  .kinlib-links, .kinlib-screen-only { display: none !important; }
  pre, .highlight pre, .jp-RenderedText pre, .cm-editor, .cm-content, .cm-line {
    white-space: break-spaces !important; overflow-wrap: anywhere !important; word-break: normal !important; }
  .jp-CodeMirrorEditor, .jp-InputArea-editor, .jp-OutputArea, .jp-OutputArea-output, .jp-RenderedText,
  .highlight, .jp-RenderedLatex, .jp-RenderedHTMLCommon, .jp-RenderedMarkdown {
    overflow: visible !important; max-width: 100%; }
  img, svg, video, canvas, .widget-image { max-width: 100% !important; height: auto !important; }
  .widget-image { margin: 0 !important; }
  .jp-RenderedImage, .widget-subarea, .animation, table, .MathJax_Display, .jp-RenderedLatex,
  .jp-OutputArea-child:has(img) { break-inside: avoid; }
  h1, h2, h3, h4, h5, h6 { break-after: avoid; break-inside: avoid; }
  .jp-MarkdownCell:has(+ .jp-CodeCell :is(.jp-RenderedImage, .widget-subarea, .animation)) { break-after: avoid; }
  .jp-CodeCell:has(.jp-RenderedImage, .widget-subarea, .animation) .jp-Cell-inputWrapper { break-after: avoid; }
  .widget-slider .slider-container, .widget-button, .widget-toggle-buttons, .widget-play,
  .widget-dropdown select, .anim-controls, .anim-state, .animation input[type=range] { display: none !important; }
  .widget-readout { border: none !important; }
  .widget-hbox { flex-wrap: nowrap !important; }
  .widget-html-content { line-height: 1.25 !important; }
  .widget-hbox > .widget-vbox { flex: 0 0 auto !important; width: auto !important; }
  .widget-slider { width: auto !important; }
  .widget-hbox > .widget-image { flex: 0 1 auto !important; min-width: 0 !important; }
  .jupyter-widgets { font-family: var(--jp-ui-font-family, sans-serif); }
  .widget-slider, .widget-html { height: auto !important; min-height: 0 !important; margin-top: 0 !important;
    margin-bottom: 0 !important; }
  .widget-subarea::after { content: "(interactive in the browser: open the notebook)"; display: block;
    font-size: 8pt; color: #444; }
"""

_FIT_SCRIPT = """
(function () {
  /* kinlib: scale down (CSS zoom) what is wider than the printed page: innermost boxes first. */
  var SEL = ".MathJax_Display, .MathJax_SVG_Display, mjx-container, .jp-RenderedLatex, table, .widget-subarea, "
    + ".jp-RenderedImage, .animation, .jp-RenderedHTMLCommon, .jp-RenderedText, .jp-InputArea-editor, "
    + ".jp-OutputArea-output";
  function fit(width) {
    var root = document.documentElement, n = 0, pass, changed, els, i, e, z;
    document.querySelectorAll("[data-kinlib-zoom]").forEach(function (e) {
      e.style.zoom = ""; e.removeAttribute("data-kinlib-zoom"); });
    if (width) { root.classList.add("kinlib-print"); root.style.width = width + "px"; }
    for (pass = 0; pass < 5; pass++) {
      changed = false;
      els = Array.prototype.slice.call(document.querySelectorAll(SEL)).reverse();
      for (i = 0; i < els.length; i++) {
        e = els[i];
        if (e.clientWidth > 0 && e.scrollWidth > e.clientWidth) {
          z = (parseFloat(e.style.zoom) || 1) * e.clientWidth / e.scrollWidth * 0.995;
          e.style.zoom = String(Math.max(0.2, Math.floor(z * 1000) / 1000));
          e.setAttribute("data-kinlib-zoom", ""); changed = true; n++;
        }
      }
      if (!changed) break;
    }
    if (width) root.style.width = "";
    return n;
  }
  window.kinlibFitPrint = fit;
  /* a print from the browser: measure at a typical printable width (A4 or Letter less margins) */
  window.addEventListener("beforeprint", function () { fit(680); });
  window.addEventListener("afterprint", function () {
    document.documentElement.classList.remove("kinlib-print");
    document.querySelectorAll("[data-kinlib-zoom]").forEach(function (e) {
      e.style.zoom = ""; e.removeAttribute("data-kinlib-zoom"); });
  });
  /* the saved widgets' pictures (drawn by the widget manager) get a text alternative */
  function alts() {
    document.querySelectorAll("img.widget-image:not([alt])").forEach(function (img) {
      img.setAttribute("alt", "Picture drawn by the interactive widget above (its saved state)"); });
    document.querySelectorAll(".widget-slider .noUi-handle:not([aria-label])").forEach(function (h) {
      var box = h.closest(".widget-slider"), label = box && box.querySelector(".widget-label");
      h.setAttribute("aria-label", (label && label.textContent.trim()) || "slider"); });
  }
  new MutationObserver(alts).observe(document.documentElement, {childList: true, subtree: true});
  document.addEventListener("DOMContentLoaded", alts);
})();
"""

PRINT_HEAD = (
    "<style>/* kinlib print stylesheet */\n"
    f"@page {{ size: A4; margin: {MARGINS_MM['top']}mm {MARGINS_MM['right']}mm {MARGINS_MM['bottom']}mm "
    f"{MARGINS_MM['left']}mm; }}\n"
    f"@media print {{ :root {{{_PRINT_RULES}}} }}\n"
    f":root.kinlib-print {{{_PRINT_RULES}}}\n"
    "</style>\n"
    f"<script>{_FIT_SCRIPT}</script>\n"
)


def printable_width_px() -> int:
    """The printable width of the paper in CSS pixels (96 per inch), rounded down: (W − left − right)·96/25.4.

    >>> printable_width_px()  # A4 less 2 × 15 mm
    680
    """
    mm = PAPER[1] - MARGINS_MM["left"] - MARGINS_MM["right"]
    return int(mm * 96 / 25.4)


def _allowed(url: str) -> bool:
    """A local file, an inline resource, or a loopback URL (everything else is aborted)."""
    if url.startswith(("file:", "data:", "blob:", "about:")):
        return True
    parts = urlsplit(url)
    return parts.scheme in ("http", "https", "ws") and (parts.hostname or "") in _LOCAL_HOSTS


_MATHJAX_DONE = """() => new Promise(resolve => {
  if (!window.MathJax || !MathJax.Hub || !MathJax.Hub.Register) { resolve(false); return; }
  MathJax.Hub.Register.StartupHook("End", () => resolve(true));
})"""
# MathJax 2's "-full" configuration first typesets every formula with its fast preview (PreviewHTML), then
# again with HTML-CSS. A page opened only to be printed never shows the preview: turn it off before MathJax
# loads (an author configuration, window.MathJax). The final typesetting is the same (measured: the 15 PDFs'
# text and their pages rasterized are identical with and without it), chromium's CPU ~20 % less.
_NO_FAST_PREVIEW = 'window.MathJax = {"fast-preview": {disabled: true}};'
_MATHJAX_QUEUE = "() => new Promise(resolve => MathJax.Hub.Queue(() => resolve(true)))"
# Every saved widget view (a widget-view+json script) is drawn once the embed manager put a
# .widget-subarea (or its error box) next to it.
_WIDGETS_DRAWN = """() => Array.from(document.querySelectorAll(
    'script[type="application/vnd.jupyter.widget-view+json"]')).every(s => s.parentElement &&
    s.parentElement.querySelector('.widget-subarea, .jupyter-widgets-error-widget'))"""
_IMAGES_DECODED = """async () => {
  await document.fonts.ready;
  const imgs = Array.from(document.images);
  await Promise.all(imgs.map(i => i.decode().catch(() => null)));
  return imgs.filter(i => !i.complete || !i.naturalWidth).map(i => (i.currentSrc || i.src || '').slice(0, 60));
}"""
_HEADER = (
    '<div style="font-size:8px;width:100%;margin:0 {l}mm;font-family:sans-serif;color:#333;'
    'display:flex;justify-content:space-between"><span>{text}</span></div>'
)
_FOOTER = (
    '<div style="font-size:8px;width:100%;margin:0 {l}mm;font-family:sans-serif;color:#333;text-align:center">'
    'page <span class="pageNumber"></span> of <span class="totalPages"></span></div>'
)


def ready_page(browser, src: Path, *, media: str = "print"):
    """Open the page ``src`` in ``browser`` (a playwright Browser, or a BrowserContext) as :func:`print_pdfs`
    prints it; return (page, boxes scaled to fit, problems seen: blocked requests, page errors, images that did not load).

    The viewport is :func:`printable_width_px` wide and ``media`` (``"print"``) is emulated; every request but
    local files and loopback is aborted. It returns once MathJax has typeset, the saved widgets are drawn and
    every image is decoded; then, with ``media="print"``, ``kinlibFitPrint()`` has scaled down what is wider
    than the paper. MathJax's fast preview is off (it is never seen here; the final typesetting is the same).
    The caller closes the page. Needs a browser, hence not run here:

    >>> page, scaled, problems = ready_page(browser, Path("build/handouts/solutions/05_x.html"))  # doctest: +SKIP
    >>> problems  # doctest: +SKIP
    []
    """
    width = printable_width_px()
    viewport = {"width": width, "height": 1100}
    if hasattr(browser, "new_context"):  # a Browser: the page in a context of its own
        page = browser.new_page(viewport=viewport)
    else:  # a BrowserContext (print_pdfs: one for all its pages)
        page = browser.new_page()
        page.set_viewport_size(viewport)
    page.set_default_timeout(_TIMEOUT_MS)
    page.add_init_script(_NO_FAST_PREVIEW)
    problems: list = []

    def route(r):
        if _allowed(r.request.url):
            r.continue_()
        else:
            problems.append(f"blocked {r.request.url[:100]}")
            r.abort()

    page.route("**/*", route)
    page.on("pageerror", lambda e: problems.append(f"page error: {e}"))
    scaled = 0
    try:
        page.emulate_media(media=media)
        page.goto(Path(src).resolve().as_uri(), wait_until="load")
        if page.evaluate(_MATHJAX_DONE):
            page.evaluate(_MATHJAX_QUEUE)
        page.wait_for_function(_WIDGETS_DRAWN, polling="raf")
        broken = page.evaluate(_IMAGES_DECODED)
        if broken:
            problems.append(f"images that did not load: {broken}")
        if media == "print":
            scaled = page.evaluate("() => window.kinlibFitPrint ? window.kinlibFitPrint() : 0")
            page.evaluate(_IMAGES_DECODED)
    except BaseException:
        page.close()
        raise
    return page, scaled, problems


def _print_one(browser, src: Path, dest: Path) -> tuple[int, list]:
    """Print ``src`` to ``dest``; return (boxes scaled to fit, problems seen)."""
    page, scaled, problems = ready_page(browser, src)
    try:
        header = page.evaluate(
            f"() => (document.querySelector('meta[name=\"{HEADER_META}\"]') || {{}}).content || document.title"
        )
        left = MARGINS_MM["left"]
        dest.parent.mkdir(parents=True, exist_ok=True)
        page.pdf(
            path=str(dest),
            format=PAPER[0],
            margin={k: f"{v}mm" for k, v in MARGINS_MM.items()},
            print_background=True,
            display_header_footer=True,
            header_template=_HEADER.format(l=left, text=html.escape(header)),
            footer_template=_FOOTER.format(l=left),
        )
    finally:
        page.close()
    return scaled, problems


def launch_args() -> list:
    """chromium's command line for printing: headless, no background traffic; ``--no-sandbox`` as root.

    >>> "--headless" in launch_args()
    True
    """
    args = ["--headless", "--disable-gpu", "--disable-background-networking", "--disable-component-update"]
    if hasattr(os, "geteuid") and os.geteuid() == 0:
        args.insert(0, "--no-sandbox")  # chromium's sandbox refuses to run as root
    return args


def _print_all(jobs: list, log) -> list[Path]:
    from playwright.sync_api import sync_playwright

    done = []
    with sync_playwright() as p:
        browser = p.chromium.launch(executable_path=CHROMIUM, args=launch_args())
        try:
            # one context for every page (not one per page): chromium's CPU ~10 % less, the same PDFs (measured:
            # text and rasterized pages identical); the pages store nothing (no cookie, no storage) to share
            context = browser.new_context(viewport={"width": printable_width_px(), "height": 1100})
            for src, dest in jobs:
                scaled, problems = _print_one(context, src, dest)
                note = f", {scaled} wide box(es) scaled to fit" if scaled else ""
                log(f"  pdf: {dest.parent.name}/{dest.name}{note}")
                for msg in problems:
                    log(f"    {src.parent.name}/{src.name}: {msg}")
                done.append(dest)
        finally:
            browser.close()
    return done


def print_pdfs(out: Path, *, pages=None, log=print) -> list[Path]:
    """Print every ``out/problems/*.html``, ``out/solutions/*.html`` and ``out/reference/*.html`` (the cheat
    sheet), or only ``pages`` (a list of those files), to ``out/pdf/<kind>/<stem>.pdf``
    (A4, margins :data:`MARGINS_MM`, content :func:`printable_width_px` CSS pixels wide); return the PDFs.

    One chromium (Debian's, :data:`CHROMIUM`), one browser context, prints them all, offline. A folder with no
    pages gives no PDFs and starts no browser:

    >>> import tempfile
    >>> with tempfile.TemporaryDirectory() as d:
    ...     print_pdfs(Path(d), log=lambda s: None)
    []

    Printing real pages takes seconds each (tests/course/test_print.py does it), hence not run here:

    >>> pdfs = print_pdfs(Path("build/handouts"))  # doctest: +SKIP
    >>> pdfs[0].relative_to("build/handouts").as_posix()  # doctest: +SKIP
    'pdf/problems/01_properties_of_jacobians.pdf'
    """
    out = Path(out)
    if pages is None:
        pages = [src for kind in PAGE_KINDS for src in sorted((out / kind).glob("*.html"))]
    jobs = [(Path(src), out / "pdf" / Path(src).parent.name / f"{Path(src).stem}.pdf") for src in pages]
    if not jobs:
        return []
    if not Path(CHROMIUM).exists():
        raise FileNotFoundError(f"{CHROMIUM} is missing: `make chromium` installs Debian's chromium (for the PDFs)")
    try:  # playwright's sync API refuses to run inside an event loop (e.g. a notebook): use a thread then
        import asyncio

        asyncio.get_running_loop()
    except RuntimeError:
        return _print_all(jobs, log)
    from concurrent.futures import ThreadPoolExecutor

    with ThreadPoolExecutor(max_workers=1) as pool:
        return pool.submit(_print_all, jobs, log).result()
