"""The printed handouts and the course front page (marked ``browser`` and ``slow``): Debian's chromium through
playwright, the network blocked, the PDFs read back with poppler (``make poppler``).

1. Every problems and solutions page of the real notebooks has its PDF (built once per session by the same
   code as ``make handouts``), and nothing in it is clipped: on every page of every PDF no word's box leaves
   the printable width (poppler's ``pdftotext -bbox``), every line of code and of text output on the page is
   in the PDF's text whole (Chromium drops the glyphs it clips, so a cut line would be missing), and in the
   browser under print media emulation no box in the code, output and math areas is wider than it is
   allowed to be (scrollWidth ≤ clientWidth where the overflow is hidden or scrolls, and no box beyond the
   page's right edge).
2. Each PDF page's header names the handout: course, section number and the notebook's title (read from the
   notebook, not from the page) and which handout; the footer numbers the pages.
3. The front page links every section's problems, solutions, workbook, PDFs and "open in the browser", has no
   external URL, and it and one problems and one solutions page pass axe-core's html-has-lang, heading-order,
   image-alt, color-contrast and link-name rules (axe-core ``npm pack``-ed into build/vendor once, then
   offline). Other findings are printed (``-s``), not asserted. Nothing here is timed.

``KINLIB_HANDOUTS_DIR=build/handouts`` tests an existing build (with its pdf/) instead of building.
"""

from __future__ import annotations

import functools
import html
import json
import re
import subprocess
from pathlib import Path

import pytest

from kinlib.course.publish import pages, printing

ROOT = Path(__file__).resolve().parents[2]
NOTEBOOKS = ROOT / "notebooks"
VENDOR = ROOT / "build" / "vendor"
AXE = ("axe-core", "4.10.3")
AXE_RULES = ("html-has-lang", "heading-order", "image-alt", "color-contrast", "link-name")
REAL = sorted(p.stem for p in NOTEBOOKS.glob("[0-9][0-9]_*.ipynb"))
KINDS = ("problems", "solutions")
PAGES = [(k, s) for k in KINDS for s in REAL]
MM = 72 / 25.4  # PDF points per millimetre
TOL = 1.0  # points

pytestmark = [pytest.mark.browser, pytest.mark.slow]


def _id(spec):
    return f"{spec[0]}-{spec[1]}"


# ---------------------------------------------------------------------------------------------------
# fixtures


@pytest.fixture(scope="session")
def built(real_handouts) -> Path:
    """The real handouts with their PDFs: ``make handouts``'s own code (handouts.build prints the PDFs), built once
    per run (tests/conftest.py ``real_handouts``; ``KINLIB_HANDOUTS_DIR`` tests an existing build)."""
    for tool in ("pdftotext", "pdfinfo"):
        if subprocess.run(["which", tool], capture_output=True).returncode:
            pytest.fail(f"{tool} is missing: `make poppler` (apt-get install poppler-utils) installs it")
    if not Path(printing.CHROMIUM).exists():
        pytest.fail(f"{printing.CHROMIUM} is missing: `make chromium` installs Debian's chromium")
    return real_handouts


@pytest.fixture
def browser(shared_browser):
    """The run's one chromium (tests/conftest.py: one playwright session for every browser module)."""
    return shared_browser


@pytest.fixture(scope="session")
def axe_js() -> Path:
    """axe-core's axe.min.js, ``npm pack``-ed into build/vendor once (then offline)."""
    return pages.npm_pack(*AXE, VENDOR) / "axe.min.js"


def _pdf(built: Path, kind: str, stem: str) -> Path:
    pdf = built / "pdf" / kind / f"{stem}.pdf"
    assert pdf.is_file(), f"no PDF {pdf.relative_to(built)}"
    return pdf


def _pdfinfo(pdf: Path) -> dict:
    out = subprocess.run(["pdfinfo", str(pdf)], capture_output=True, text=True, check=True).stdout
    return dict(line.split(":", 1) for line in out.splitlines() if ":" in line)


_WORD = re.compile(r'<word xMin="([-\d.]+)" yMin="([-\d.]+)" xMax="([-\d.]+)" yMax="([-\d.]+)">([^<]*)</word>')


@functools.cache
def _words(pdf: Path) -> list[tuple[float, float, list]]:
    """[(page width, page height, [(xMin, yMin, xMax, yMax, word)])] for every page (pdftotext -bbox; read once
    per PDF and run: two tests read it). Callers do not change it."""
    xml = subprocess.run(["pdftotext", "-bbox", str(pdf), "-"], capture_output=True, text=True, check=True).stdout
    result = []
    for chunk in xml.split("<page ")[1:]:
        w = float(re.search(r'width="([\d.]+)"', chunk).group(1))
        h = float(re.search(r'height="([\d.]+)"', chunk).group(1))
        words = [(*map(float, m.groups()[:4]), html.unescape(m.group(5))) for m in _WORD.finditer(chunk)]
        result.append((w, h, words))
    return result


# ---------------------------------------------------------------------------------------------------
# 1. nothing clipped


def test_every_page_has_a_pdf_of_a4_pages(built):
    counts = {}
    for kind, stem in PAGES:
        info = _pdfinfo(_pdf(built, kind, stem))
        w, h = map(float, re.findall(r"[\d.]+", info["Page size"])[:2])
        assert abs(w - 210 * MM) < 2 and abs(h - 297 * MM) < 2, info["Page size"]
        counts[f"{kind}/{stem}"] = int(info["Pages"])
        assert counts[f"{kind}/{stem}"] >= 1
    print("\nPDF page counts: " + ", ".join(f"{k} {n}" for k, n in counts.items()))


@pytest.mark.parametrize("spec", PAGES, ids=_id)
def test_no_word_beyond_the_printable_width(built, spec):
    pdf = _pdf(built, *spec)
    left, right = printing.MARGINS_MM["left"] * MM, printing.MARGINS_MM["right"] * MM
    pages = _words(pdf)
    assert pages, f"{pdf.name}: no pages"
    outside = []
    for n, (w, _h, words) in enumerate(pages, 1):
        assert words, f"{pdf.name} page {n}: no text at all"
        for x0, _y0, x1, _y1, word in words:
            if x0 < left - TOL or x1 > w - right + TOL:
                outside.append(
                    f"page {n}: {word!r} at x = {x0:.1f}..{x1:.1f} pt (printable {left:.1f}..{w - right:.1f})"
                )
    assert not outside, f"{pdf.name}: {len(outside)} word(s) beyond the printable width: {outside[:5]}"


def _squeeze(text: str) -> str:
    return re.sub(r"\s+", "", text)


def _page_lines(html_path: Path) -> list[str]:
    """The lines of code and of text output on a page (what a cut line would lose)."""
    from bs4 import BeautifulSoup

    soup = BeautifulSoup(html_path.read_text(encoding="utf-8"), "html.parser")
    lines = []
    for el in soup.select(".jp-InputArea-editor pre, .jp-RenderedText pre"):
        lines += [ln for ln in el.get_text().splitlines() if ln.strip()]
    return lines


def _body_text(pdf: Path) -> str:
    """The PDF's text without whitespace, in reading order: each page's words between the header and the footer,
    line by line (words whose top edges are within 2 pt), left to right. Words taller than 24 pt are MathJax's
    glyphs (their boxes have the font's whole height) and are left out, so that they do not split a line."""
    top, bottom = printing.MARGINS_MM["top"] * MM, printing.MARGINS_MM["bottom"] * MM
    out = []
    for _w, h, words in _words(pdf):
        body = sorted(
            (y0, x0, word)
            for x0, y0, _x1, y1, word in words
            if y0 >= top - TOL and y1 <= h - bottom + TOL and y1 - y0 <= 24
        )
        lines: list = []
        for y0, x0, word in body:
            if lines and y0 - lines[-1][0] <= 2:
                lines[-1][1].append((x0, word))
            else:
                lines.append((y0, [(x0, word)]))
        out += [w for _y, ws in lines for _x, w in sorted(ws)]
    return "".join(out)


@pytest.mark.parametrize("spec", PAGES, ids=_id)
def test_every_code_and_output_line_is_printed_whole(built, spec):
    kind, stem = spec
    pdf = _pdf(built, kind, stem)
    flat = _body_text(pdf)
    lines = _page_lines(built / kind / f"{stem}.html")
    assert lines, "no code on the page"
    missing = [ln for ln in lines if _squeeze(ln) not in flat]
    assert not missing, f"{pdf.name}: {len(missing)} of {len(lines)} line(s) not printed whole: {missing[:4]}"


# In print media, in the areas that overflowed before (code, outputs, math): no box clips or scrolls its
# content, and no box reaches beyond the page's right edge. MathJax's assistive MathML is clipped on purpose
# (for screen readers): left out.
_OVERFLOWS = """() => {
  const root = document.documentElement, W = root.clientWidth, bad = [];
  const areas = document.querySelectorAll(
    '.jp-InputArea-editor, .jp-OutputArea-output, .jp-RenderedMarkdown, .MathJax_Display');
  const seen = new Set();
  for (const area of areas) {
    for (const e of [area, ...area.querySelectorAll('*')]) {
      if (seen.has(e) || e.closest('.MJX_Assistive_MathML')) continue;
      seen.add(e);
      const r = e.getBoundingClientRect();
      if (!r.width || !r.height) continue;
      const ox = getComputedStyle(e).overflowX;
      const name = e.tagName + '.' + String(e.className).split(' ')[0];
      if (ox !== 'visible' && e.clientWidth > 0 && e.scrollWidth > e.clientWidth + 1)
        bad.push(`${name} clips: scrollWidth ${e.scrollWidth} > clientWidth ${e.clientWidth}`);
      if (r.right > W + 1 || r.left < -1)
        bad.push(`${name} beyond the page: ${r.left.toFixed(0)}..${r.right.toFixed(0)} of ${W}`);
    }
  }
  if (root.scrollWidth > W + 1) bad.push(`the page scrolls sideways: ${root.scrollWidth} > ${W}`);
  return bad;
}"""


@pytest.mark.parametrize("spec", PAGES, ids=_id)
def test_nothing_overflows_in_print_media(built, browser, spec):
    kind, stem = spec
    page, _scaled, problems = printing.ready_page(browser, built / kind / f"{stem}.html")
    try:
        assert page.evaluate("() => matchMedia('print').matches")
        assert page.evaluate("() => document.documentElement.clientWidth") == printing.printable_width_px()
        assert not problems, problems
        bad = page.evaluate(_OVERFLOWS)
        assert not bad, f"{kind}/{stem}: {len(bad)} overflowing box(es): {bad[:6]}"
    finally:
        page.close()


# ---------------------------------------------------------------------------------------------------
# 2. the header names the section


@pytest.mark.parametrize("spec", PAGES, ids=_id)
def test_every_pdf_page_has_a_header_naming_the_handout(built, spec):
    kind, stem = spec
    title = json.loads((NOTEBOOKS / f"{stem}.ipynb").read_text(encoding="utf-8"))["metadata"]["kinlib"]["title"]
    expected = f"Problem Set 4 · {int(stem[:2])} {title} — {kind}"
    pdf = _pdf(built, kind, stem)
    n = int(_pdfinfo(pdf)["Pages"])
    # one pdftotext for the whole PDF: it ends every page with a form feed
    texts = subprocess.run(["pdftotext", "-layout", str(pdf), "-"], capture_output=True, text=True, check=True).stdout
    texts = texts.split("\f")
    assert len(texts) == n + 1 and not texts[-1].strip(), f"{len(texts) - 1} pages of text for {n} pages"
    for k, text in enumerate(texts[:n], 1):
        lines = [ln.strip() for ln in text.splitlines() if ln.strip()]
        assert lines and " ".join(lines[0].split()) == expected, f"page {k}: header {lines[:1]}, not {expected!r}"
        assert " ".join(lines[-1].split()) == f"page {k} of {n}", f"page {k}: footer {lines[-1:]}"


# ---------------------------------------------------------------------------------------------------
# 3. the front page


def test_front_page_links_everything_and_nothing_outside(built):
    page = (built / "index.html").read_text(encoding="utf-8")
    assert not re.search(r"(?i)\b(?:https?|ftp|wss?):|(?:src|href)\s*=\s*[\"']//", page), "an external URL"
    hrefs = re.findall(r'href="([^"]+)"', page)
    for stem in REAL:
        for rel in (
            f"problems/{stem}.html",
            f"solutions/{stem}.html",
            f"pdf/problems/{stem}.pdf",
            f"pdf/solutions/{stem}.pdf",
            f"workbooks/{stem}.ipynb",
        ):
            assert rel in hrefs and (built / rel).is_file(), rel
        for nb in (f"workbooks/{stem}.ipynb", f"solutions/{stem}.ipynb"):
            assert any(h.startswith("lite/") and h.endswith(f"path={nb}") for h in hrefs), f"open {nb} in the browser"
    for handout in [built / k / f"{s}.html" for k, s in PAGES]:
        text = handout.read_text(encoding="utf-8")
        kind, stem = handout.parent.name, handout.stem
        assert f'href="../pdf/{kind}/{stem}.pdf"' in text, f"{kind}/{stem}: no PDF link"
        nb = f"{'workbooks' if kind == 'problems' else 'solutions'}/{stem}.ipynb"
        assert re.search(rf'href="\.\./lite/[^"]*path={re.escape(nb)}"', text), f"{kind}/{stem}: no browser link"


def test_every_figure_has_a_meaningful_alt_text(built):
    from bs4 import BeautifulSoup

    for kind, stem in PAGES:
        soup = BeautifulSoup((built / kind / f"{stem}.html").read_text(encoding="utf-8"), "html.parser")
        assert soup.html.get("lang") == "en"
        for img in soup.find_all("img"):
            alt = (img.get("alt") or "").strip()
            assert alt and "No description" not in alt, f"{kind}/{stem}: an image without a text alternative"


def _axe(browser, path: Path, axe_js: Path, *, handout: bool):
    if handout:  # rendered as on screen, after MathJax and the widgets
        page, _, problems = printing.ready_page(browser, path, media="screen")
        page.set_viewport_size({"width": 1200, "height": 900})
    else:
        page = browser.new_page(viewport={"width": 1200, "height": 900})
        problems = []
        page.route("**/*", lambda r: r.continue_() if r.request.url.startswith("file:") else r.abort())
        page.goto(path.as_uri(), wait_until="load")
    try:
        page.add_script_tag(path=str(axe_js))
        # resultTypes: only the violations are read, so axe details no passing node (a documented speed option)
        result = page.evaluate(
            "async () => JSON.parse(JSON.stringify((await axe.run(document, {resultTypes: ['violations']})).violations))"
        )
    finally:
        page.close()
    return result, problems


@pytest.mark.parametrize(
    "rel", ["index.html", "problems/05_singularities_planar.html", "solutions/05_singularities_planar.html"]
)
def test_accessibility_axe(built, browser, axe_js, rel):
    violations, problems = _axe(browser, built / rel, axe_js, handout=rel != "index.html")
    assert not problems, problems
    summary = {v["id"]: [n["target"] for n in v["nodes"]][:4] for v in violations}
    others = {k: v for k, v in summary.items() if k not in AXE_RULES}
    if others:
        print(f"\n{rel}: other axe findings (not asserted): {json.dumps(others)[:1500]}")
    failed = {k: v for k, v in summary.items() if k in AXE_RULES}
    assert not failed, f"{rel}: axe violations {failed}"
