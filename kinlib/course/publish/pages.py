"""The HTML side of the handouts: pages exported with nbconvert, the index, and the offline assets.

MathJax 2 is copied from the installed ``jupyter-server-mathjax``; require.js, font-awesome and the
``@jupyter-widgets/html-manager`` embed bundle are ``npm pack``-ed from the npm registry into a vendor
folder once, then reused, so every page renders offline.
"""

from __future__ import annotations

import copy
import html
import re
import shutil
import time
from pathlib import Path

from ..schema import CHECK, HINT, MISTAKE, PREDICT, PREDICT_ANSWER, cell_tags
from .lite import lite_link
from .npm import npm_pack

__all__ = [
    "build_assets",
    "npm_pack",
    "export_html",
    "fold_cells",
    "write_index",
    "LINKS",
    "print_header",
    "contrast_ratio",
    "COURSE",
    "HTML_MANAGER",
    "REQUIREJS",
    "FONT_AWESOME",
    "MATHJAX_CONFIG",
]

HTML_MANAGER = ("@jupyter-widgets/html-manager", "1.0.15")  # the embedder for ipywidgets 8.1 (controls 5)
REQUIREJS = ("requirejs", "2.3.8")
FONT_AWESOME = ("font-awesome", "4.7.0")  # the play buttons of matplotlib's to_jshtml() animations
_FA_CDN = re.compile(
    r"https?://(?:maxcdn|stackpath)\.bootstrapcdn\.com/font-awesome/[0-9.]+/css/font-awesome(?:\.min)?\.css"
)
_FA_LOCAL = "../assets/font-awesome/css/font-awesome.min.css"
_REQUIRE_TAG = '<script src="../assets/require.js"></script>'
# The widget bundle finds its icon fonts relative to its AMD module ids: point those at assets/widgets/.
_WIDGET_PATHS = """<script>
window.__jupyter_widgets_assets_path__ = "../assets/widgets/";
if (window.requirejs) {
  requirejs.config({paths: {
    "@jupyter-widgets/html-manager/dist": "../assets/widgets",
    "@jupyter-widgets/base": "../assets/widgets/base", "@jupyter-widgets/controls": "../assets/widgets/controls",
    "@jupyter-widgets/output": "../assets/widgets/output", "@jupyter-widgets/html-manager": "../assets/widgets/hm"}});
}
</script>"""
MATHJAX_CONFIG = "TeX-AMS-MML_HTMLorMML-full,Safe,kinlib"
_MATHJAX_LOCAL_CONFIG = """\
/* kinlib: MathJax 2 from jupyter-server-mathjax ships only the STIX-Web fonts: use them, no image fonts. */
/* No URL that is not there: MathJax_Blank (a font-loading probe) and the TeX web fonts of the hidden
   (assistive) MathML point at local() names instead of about:blank and the missing TeX otf files. */
(function () {
  var none = "local('kinlib-no-such-font')", mml = {};
  for (var i = 1; i <= 6; i++) { mml["@font-face /*" + i + "*/"] = {src: none}; }
  MathJax.Hub.Config({
    "HTML-CSS": {availableFonts: [], preferredFont: null, webFont: "STIX-Web", imageFont: null,
                 styles: {"@font-face": {"font-family": "MathJax_Blank", src: none}}},
    NativeMML: {styles: mml},
    SVG: {font: "STIX-Web"},
    MathMenu: {showLocale: false},
    menuSettings: {inTabOrder: false}  /* formulas are not Tab stops (their menu stays on the right click) */
  });
})();
MathJax.Ajax.loadComplete("[MathJax]/config/kinlib.js");
"""


_npm_pack = npm_pack  # the old private name, used below


LINKS = ("pdf", "lite")  # the other forms a handout links to when they are built (PDF, the in-browser site)


def build_assets(assets: Path, vendor: Path) -> dict:
    """Copy MathJax, require.js and the widget embedder into ``assets``; return their relative URLs
    (the keyword arguments of nbconvert's HTMLExporter used by :func:`export_html`).

    It copies MathJax and may run ``npm pack`` (a download, the first time), hence not run here;
    tests/course/test_handouts.py exercises it:

    >>> urls = build_assets(Path("build/handouts/assets"), Path("build/vendor"))  # doctest: +SKIP
    >>> urls["require_js_url"]  # doctest: +SKIP
    '../assets/require.js'
    """
    import jupyter_server_mathjax

    assets.mkdir(parents=True, exist_ok=True)
    mj_src = Path(jupyter_server_mathjax.__file__).parent / "static"
    mj = assets / "mathjax"
    if not (mj / "MathJax.js").exists():
        shutil.copytree(mj_src, mj, dirs_exist_ok=True)
    (mj / "config" / "kinlib.js").write_text(_MATHJAX_LOCAL_CONFIG)

    hm = _npm_pack(*HTML_MANAGER, vendor)
    wdst = assets / "widgets"
    wdst.mkdir(exist_ok=True)
    for f in (hm / "dist").iterdir():
        if f.name == "embed-amd.js" or f.suffix in (".woff", ".woff2", ".ttf", ".eot", ".svg"):
            shutil.copy2(f, wdst / f.name)
    rq = _npm_pack(*REQUIREJS, vendor)
    shutil.copy2(rq / "require.js", assets / "require.js")
    fa = _npm_pack(*FONT_AWESOME, vendor)
    for sub in ("css", "fonts"):
        shutil.copytree(fa / sub, assets / "font-awesome" / sub, dirs_exist_ok=True)
    return {
        "mathjax_url": f"../assets/mathjax/MathJax.js?config={MATHJAX_CONFIG}",
        "require_js_url": "../assets/require.js",
        "widget_renderer_url": "../assets/widgets/embed-amd.js",
    }


def export_html(nb, dest: Path, urls: dict, *, title: str, problems: bool, links=LINKS) -> None:
    """Write ``nb`` as a page ``dest`` using the offline assets ``urls``; ``problems`` drops prompt numbers.
    ``links``: which of the other forms the page links to, of ``("pdf", "lite")`` (those that are built).

    The assets need not be there to write the page (``urls`` are only links):

    >>> import nbformat, tempfile
    >>> nb = nbformat.v4.new_notebook(cells=[nbformat.v4.new_markdown_cell("# Planar arms")])
    >>> urls = {"require_js_url": "../assets/require.js", "mathjax_url": "../assets/mathjax/MathJax.js"}
    >>> with tempfile.TemporaryDirectory() as d:
    ...     export_html(nb, Path(d) / "problems" / "02_x.html", urls, title="Planar arms", problems=True)
    ...     page = (Path(d) / "problems" / "02_x.html").read_text()
    >>> "<title>Planar arms</title>" in page, 'src="../assets/require.js"' in page
    (True, True)
    """
    from nbconvert import HTMLExporter

    nb = copy.deepcopy(nb)
    for c in nb.cells:  # matplotlib's to_jshtml() links font-awesome on a CDN
        for o in c.get("outputs", []):
            h = o.get("data", {}).get("text/html")
            if h:
                h = _FA_CDN.sub(_FA_LOCAL, h if isinstance(h, str) else "".join(h))
                h = h.replace('<input id="_anim_slider', '<input aria-label="animation frame" id="_anim_slider')
                if "_anim_img" in h and _FA_LOCAL not in h:  # an animation whose CDN link was dropped
                    h = f'<link rel="stylesheet" href="{_FA_LOCAL}">\n' + h
                o["data"]["text/html"] = h
    exporter = HTMLExporter(
        template_name="lab", embed_images=True, exclude_input_prompt=problems, exclude_output_prompt=problems, **urls
    )
    body, _ = exporter.from_notebook_node(nb, resources={"metadata": {"name": title}})
    if _REQUIRE_TAG not in body:
        raise RuntimeError(f"nbconvert's lab template changed: no {_REQUIRE_TAG} in {dest.name}")
    body = body.replace(_REQUIRE_TAG, _REQUIRE_TAG + "\n" + _WIDGET_PATHS, 1)
    body = _print_and_links(body, nb, dest, title=title, problems=problems, links=links)
    body = fold_cells(body, nb, problems=problems)
    dest.parent.mkdir(parents=True, exist_ok=True)
    dest.write_text(body, encoding="utf-8")


# ---------------------------------------------------------------------------------------------------
# What export_html adds to nbconvert's page: the print stylesheet and header (kinlib.course.publish.printing), a bar
# of links (index, PDF, workbook, "open in the browser"), and a text alternative for every figure.

COURSE = "Problem Set 4"  # the course name in the PDF page headers
_NO_ALT = 'alt="No description has been provided for this image"'  # what nbconvert puts on every figure
_LINKS_CSS = """<style>/* kinlib: the links bar, and contrast (WCAG AA) for the prompts */
.kinlib-links { font: 14px/1.5 system-ui, sans-serif; margin: 0 0 1rem; padding: .5rem 0; border-bottom: 1px solid #ccc; }
.kinlib-links a { color: #0b4fa8; margin-right: 1.2rem; }
.jp-InputPrompt, .jp-OutputPrompt { opacity: 1 !important; }
.jp-InputPrompt { color: #245e91 !important; } .jp-OutputPrompt { color: #9c3f22 !important; }
</style>
"""


def _luminance(hexcolor: str) -> float:
    h = hexcolor.lstrip("#")
    if len(h) == 3:
        h = "".join(c * 2 for c in h)
    channels = [int(h[i : i + 2], 16) / 255 for i in (0, 2, 4)]
    lin = [c / 12.92 if c <= 0.04045 else ((c + 0.055) / 1.055) ** 2.4 for c in channels]
    return 0.2126 * lin[0] + 0.7152 * lin[1] + 0.0722 * lin[2]


def contrast_ratio(fg: str, bg: str) -> float:
    """WCAG 2 contrast ratio (L1 + 0.05) / (L2 + 0.05) of two ``#rgb``/``#rrggbb`` colours.

    >>> round(contrast_ratio("#408080", "#f5f5f5"), 2), round(contrast_ratio("#000", "#fff"), 1)
    (4.17, 21.0)
    """
    a, b = sorted((_luminance(fg), _luminance(bg)), reverse=True)
    return (a + 0.05) / (b + 0.05)


def _code_colours(body: str, background: str = "#f5f5f5", target: float = 4.6) -> str:
    """CSS overriding the syntax colours of JupyterLab's light theme (``--jp-mirror-editor-*-color``) that
    have less than WCAG AA contrast on the code background: each is darkened until it has ``target``."""
    fixes = {}
    for name, colour in re.findall(r"(--jp-mirror-editor-[\w-]+-color):\s*(#[0-9a-fA-F]{3}(?:[0-9a-fA-F]{3})?);", body):
        h = colour.lstrip("#")
        rgb = [int((h[i] * 2) if len(h) == 3 else h[2 * i : 2 * i + 2], 16) for i in range(3)]
        new = colour
        while contrast_ratio(new, background) < target:
            rgb = [int(c * 0.92) for c in rgb]
            new = "#" + "".join(f"{c:02x}" for c in rgb)
        if new != colour:
            fixes.setdefault(name, new)
    if not fixes:
        return ""
    return (
        "<style>/* kinlib: syntax colours with WCAG AA contrast */ :root { "
        + " ".join(f"{k}: {v};" for k, v in fixes.items())
        + " }</style>\n"
    )


def print_header(stem: str, title: str, problems: bool) -> str:
    """The header of each printed page of a handout: course, section number, title and which handout.

    >>> print_header("05_singularities_planar", "Singularities: the planar robot (solutions)", False)
    'Problem Set 4 · 5 Singularities: the planar robot — solutions'
    >>> print_header("cheatsheet", "Cheat sheet", False)
    'Problem Set 4 · Cheat sheet'
    """
    kind = "problems" if problems else "solutions"
    base = re.sub(r"\s*\((?:problems|solutions)\)\s*$", "", title)
    if not stem[:2].isdigit():  # a reference page (the cheat sheet): neither problems nor solutions
        return f"{COURSE} · {base}"
    return f"{COURSE} · {int(stem[:2])} {base} — {kind}"


def _plain(text: str) -> str:
    """Markdown/TeX to a short plain sentence for alt text."""
    text = re.sub(r"!\[[^\]]*\]\([^)]*\)|<[^>]+>", "", text)
    text = re.sub(r"\[([^\]]*)\]\([^)]*\)", r"\1", text)
    text = re.sub(r"\\(?:bigl|bigr|Bigl|Bigr|left|right|,|;|!)", "", text)
    greek = {"theta": "θ", "pi": "π", "omega": "ω", "sigma": "σ", "mu": "μ", "lambda": "λ", "phi": "φ", "alpha": "α"}
    text = re.sub(r"\\(theta|pi|omega|sigma|mu|lambda|phi|alpha)(?![A-Za-z])", lambda m: greek[m.group(1)], text)
    text = re.sub(r"[*_`#${}]|\\(?:mathrm|text|operatorname|boldsymbol|mathbf)|\\", "", text)
    return " ".join(text.split())


def _figure_alts(nb, section_default: str) -> dict:
    """{cell id: alt text} for the code cells with figures: "Figure k of <section>: <caption>", the caption
    being the figure's ``title="…"`` in the cell's code, else the first sentence of the markdown just above; a
    cell's ``metadata.kinlib.alt`` (a string) wins."""
    alts, heading, k, prev_md = {}, section_default, 0, ""
    for c in nb.cells:
        if c.cell_type == "markdown":
            m = re.search(r"^#{1,3}\s+(.+)$", c.source, re.M)
            if m:
                heading, k = _plain(m.group(1)), 0
            prev_md = _plain(re.sub(r"^#{1,6}\s+.*$", "", c.source, flags=re.M))
            continue
        n_img = sum(
            1
            for o in c.get("outputs", [])
            if {"image/png", "image/jpeg"} & set(o.get("data", {})) or "_anim_img" in str(o.get("data", {}))
        )
        if n_img and c.get("id"):
            k += 1
            given = c.get("metadata", {}).get("kinlib", {}).get("alt")
            title = re.search(r"""\btitle\s*=\s*f?(["'])(.+?)\1""", c.source)
            sentence = re.sub(r"^\d+(?:\.\d+)*\s*\(\d+ points?\)\.?\s*", "", prev_md).split(". ")[0]
            if title and "{" not in title.group(2):  # the figure's own title (an f-string's varies: not that)
                caption = _plain(title.group(2))
            else:
                caption = sentence[:160] if len(sentence) >= 20 else ""
            alts[c["id"]] = (
                given
                if isinstance(given, str) and given.strip()
                else f"Figure {k} of “{heading}”" + (f": {caption}" if caption else "")
            )
        prev_md = ""
    return alts


_PICTURES = {
    "window.kinlibExplorer(": "explorer",
    "window.kinlibAnimation(": "animation",
    "window.kinlibPicker(": "picker",
}
_PART = re.compile(r"^\s*(?:#+\s*)?\**\s*(\d+\.\d+)")
_SKIP_CSS = (
    "<style>/* kinlib: skip links, the first Tab stops of a page */\n"
    ".kinlib-skip { font: 13px/1.6 system-ui, sans-serif; margin: 0 0 .3rem; }\n"
    ".kinlib-skip a { color: #0b4fa8; margin-right: .9rem; } .kinlib-skip a:focus { outline: 2px solid #0b4fa8; }\n"
    "@media print { .kinlib-skip { display: none; } }\n</style>\n"
)


def skip_links(nb) -> str:
    """The page's first Tab stops (issue 30, keyboard): a link to each explorer, animation and picker, then to each
    graded part's question, by the cells' ids (``#cell-id=…``, nbconvert's). Following one and pressing Tab lands
    on that picture's first control. "" when the page has neither.

    >>> import nbformat
    >>> q = nbformat.v4.new_markdown_cell("**5.1 (5 points).** Where?", id="q51")
    >>> q.metadata["tags"] = ["question"]
    >>> ex = nbformat.v4.new_code_cell("ex", id="ex1", outputs=[nbformat.v4.new_output("display_data",
    ...     {"application/javascript": "window.kinlibExplorer(host, S);", "text/plain": "explorer of planar_2r at θ = (0, 0)"})])
    >>> print(skip_links(nbformat.v4.new_notebook(cells=[q, ex])))  # doctest: +NORMALIZE_WHITESPACE
    <style>...
    <nav class="kinlib-skip" aria-label="Skip to"><a href="#cell-id=ex1">Skip to the explorer (planar_2r)</a><a href="#cell-id=q51">Part 5.1</a></nav>
    """
    pictures, parts = [], []
    for c in nb.cells:
        cid = c.get("id")
        if not cid:
            continue
        if c.get("cell_type") == "code":
            for o in c.get("outputs", []):
                js = o.get("data", {}).get("application/javascript", "")
                js = "".join(js) if isinstance(js, list) else js
                kind = next((k for marker, k in _PICTURES.items() if marker in js), None)
                if kind:
                    text = o.get("data", {}).get("text/plain", "")
                    text = "".join(text) if isinstance(text, list) else text
                    m = re.search(r"(?:of|for) (\S+)", text)
                    pictures.append((cid, f"Skip to the {kind}" + (f" ({m.group(1)})" if m else "")))
                    break
        elif "question" in cell_tags(c):
            src = c.get("source", "")
            m = _PART.match("".join(src) if isinstance(src, list) else src)
            if m:
                parts.append((cid, f"Part {m.group(1)}"))
    if not pictures and not parts:
        return ""
    links = "".join(f'<a href="#cell-id={html.escape(cid)}">{html.escape(t)}</a>' for cid, t in pictures + parts)
    return _SKIP_CSS + f'<nav class="kinlib-skip" aria-label="Skip to">{links}</nav>\n'


def _print_and_links(body: str, nb, dest: Path, *, title: str, problems: bool, links=LINKS) -> str:
    from .printing import HEADER_META, PRINT_HEAD

    stem, kind = dest.stem, dest.parent.name
    header = print_header(stem, title, problems)
    head = f'<meta name="{HEADER_META}" content="{html.escape(header)}">\n{_LINKS_CSS}{_code_colours(body)}{PRINT_HEAD}'
    if "</head>" not in body:
        raise RuntimeError(f"nbconvert's lab template changed: no </head> in {dest.name}")
    body = body.replace("</head>", head + "</head>", 1)
    notebook = f"{'workbooks' if problems else 'solutions'}/{stem}.ipynb"
    which = "the workbook" if problems else "this notebook"
    bar_links = [("../index.html", "All handouts (course index)")]
    if "pdf" in links:
        bar_links.append((f"../pdf/{kind}/{stem}.pdf", f"PDF of this page ({kind})"))
    if "lite" in links:
        bar_links.append(
            ("../" + lite_link(notebook), f"Open {which} in the browser (JupyterLite, nothing to install)")
        )
    if problems:
        bar_links.append((f"../workbooks/{stem}.ipynb", "Download the workbook (.ipynb)"))
    bar = '<nav class="kinlib-links" aria-label="This handout">' + "".join(
        f'<a href="{html.escape(href)}">{html.escape(text)}</a>' for href, text in bar_links
    )
    bar += "</nav>\n"
    m = re.search(r"<main>", body)
    if m is None:
        raise RuntimeError(f"nbconvert's lab template changed: no <main> in {dest.name}")
    body = body[: m.end()] + "\n" + skip_links(nb) + bar + body[m.end() :]
    body = body.replace("<head>", '<head>\n<meta name="viewport" content="width=device-width, initial-scale=1">', 1)
    alts = _figure_alts(nb, html.unescape(header))
    pieces = re.split(r'(id="cell-id=[^"]*")', body)
    for i in range(1, len(pieces), 2):
        alt = alts.get(pieces[i][len('id="cell-id=') : -1])
        if alt:
            pieces[i + 1] = pieces[i + 1].replace(_NO_ALT, f'alt="{html.escape(alt)}"')
    return "".join(pieces).replace(_NO_ALT, f'alt="{html.escape("Figure in " + header)}"')


# ---------------------------------------------------------------------------------------------------
# The reading aids on the pages (notebooks/README.md): checks, predict-answers and hints folded in <details>,
# common mistakes as a callout box.

_FOLD_CSS = """<style>/* kinlib: folded cells (checks, answers to predictions, hints) and callouts */
details.kinlib-fold { margin: .4rem 0 .6rem; border-left: 3px solid #8a8a8a; padding: .1rem 0 .1rem .6rem; }
details.kinlib-fold > summary { cursor: pointer; font: 600 14px/1.6 system-ui, sans-serif; color: #1f4f7a; }
details.kinlib-predict-answer { border-left-color: #2e7d32; } details.kinlib-hint { border-left-color: #b26a00; }
.kinlib-predict .jp-RenderedMarkdown { background: #eef6ee; border-radius: 4px; padding: .2rem .6rem; }
.kinlib-mistake { border: 2px solid #b3261e; border-radius: 6px; background: #fdf1f0; margin: .5rem 0;
  padding: .2rem .6rem; }
</style>
<script>
/* Open every folded cell for printing (and when printed from the browser); typeset the maths of a folded
   cell again when it is opened (MathJax 2 cannot measure what is hidden). */
(function () {
  function openAll() { document.querySelectorAll("details.kinlib-fold").forEach(function (d) { d.open = true; }); }
  document.addEventListener("DOMContentLoaded", function () {
    if (window.matchMedia && window.matchMedia("print").matches) { openAll(); }
  });
  window.addEventListener("beforeprint", openAll);
  document.addEventListener("click", function (e) {  /* a reader's click (or Enter) on a summary, not the parser */
    var s = e.target && e.target.closest ? e.target.closest("details.kinlib-fold > summary") : null;
    if (!s) { return; }
    setTimeout(function () {
      var d = s.parentNode;
      if (d.open && window.MathJax && MathJax.Hub) { MathJax.Hub.Queue(["Rerender", MathJax.Hub, d]); }
    }, 0);
  });
})();
</script>
"""
_CELL_START = re.compile(r'<div class="jp-Cell [^"]*" id="cell-id=([^"]*)">')
_SUMMARIES = {
    CHECK: "How we know this is right",
    PREDICT_ANSWER: "Show the answer",
    HINT: "Hint",
}


def fold_cells(body: str, nb, *, problems: bool) -> str:
    """The page ``body`` with its reading aids laid out (cells found by their ``cell-id``): ``check`` cells
    folded in ``<details><summary>How we know this is right</summary>``, ``predict-answer`` cells in
    "Show the answer", ``hint`` cells in "Hint" (folded on problem pages, open on solution pages),
    ``mistake`` cells in a "Common mistake" callout box, ``predict`` cells highlighted.

    >>> import nbformat
    >>> from nbconvert import HTMLExporter
    >>> a = nbformat.v4.new_markdown_cell("It is $x$.", id="a")
    >>> a.metadata["tags"] = ["predict-answer"]
    >>> nb = nbformat.v4.new_notebook(cells=[nbformat.v4.new_markdown_cell("Guess?", id="q"), a])
    >>> page = fold_cells(HTMLExporter(template_name="lab").from_notebook_node(nb)[0], nb, problems=True)
    >>> "<summary>Show the answer</summary>" in page, page.index("Guess?") < page.index("<details") < page.index("It is")
    (True, True)
    """
    kinds, titles = {}, {}
    for c in nb.cells:
        tags = set(cell_tags(c))
        for tag in (CHECK, PREDICT_ANSWER, HINT, MISTAKE, PREDICT):
            if tag in tags and c.get("id"):
                kinds[c["id"]] = tag
                bold = re.match(r"\s*\*\*(.+?)\*\*", c.get("source", "")) if c.get("cell_type") == "markdown" else None
                if tag == HINT and bold:  # "Hint: Step 1: the screw axes", from the cell's bold lead
                    titles[c["id"]] = "Hint: " + html.escape(bold.group(1).strip().rstrip(".:"))
                break
    if not kinds:
        return body
    main_end = body.rfind("</main>")
    if main_end < 0:
        raise RuntimeError("nbconvert's lab template changed: no </main>")
    starts = [(m.start(), m.group(1)) for m in _CELL_START.finditer(body, 0, main_end)]
    out, pos = [], 0
    for k, (start, cid) in enumerate(starts):
        end = starts[k + 1][0] if k + 1 < len(starts) else main_end
        kind = kinds.get(html.unescape(cid))
        if kind is None:
            continue
        cell = body[start:end].rstrip()
        out.append(body[pos:start])
        if kind in _SUMMARIES:
            opened = " open" if kind == HINT and not problems else ""
            out.append(
                f'<details class="kinlib-fold kinlib-{kind}"{opened}>'
                f"<summary>{titles.get(html.unescape(cid), _SUMMARIES[kind])}</summary>\n"
                f"{cell}\n</details>\n"
            )
        else:
            out.append(f'<div class="kinlib-{kind}" role="note">\n{cell}\n</div>\n')
        pos = end
    out.append(body[pos:])
    body = "".join(out)
    return body.replace("</head>", _FOLD_CSS + "</head>", 1)


_INTRO_TAIL = """the <strong>workbook</strong>, a Jupyter notebook to fill
in with self-checks, to download or to <strong>open in the browser</strong> (JupyterLite: Python runs in the
browser tab, nothing to install; it needs this folder served over http, for example by <code>make site</code>
or any static web host, and its first start takes a while).</p>"""
_INTRO_ALL = (
    """<p>For each notebook of the course: the <strong>problems</strong> (questions, no answers) and the worked
<strong>solutions</strong>, as web pages and as PDFs; """
    + _INTRO_TAIL
)
_INTRO_STUDENTS = (
    """<p>For each notebook of the course: the <strong>problems</strong> (questions, no answers), as a web page
and as a PDF; """
    + _INTRO_TAIL
)

_INDEX = """<!DOCTYPE html>
<html lang="en"><head><meta charset="utf-8">
<meta name="viewport" content="width=device-width, initial-scale=1">
<title>{course} handouts: Jacobians, singularities and manipulability</title>
<style>
body {{ font: 16px/1.5 system-ui, sans-serif; max-width: 52rem; margin: 2rem auto; padding: 0 1rem;
  color: #1f1f1f; background: #fff; }}
a {{ color: #0b4fa8; }} a:visited {{ color: #5b2a86; }} a:focus {{ outline: 2px solid #0b4fa8; outline-offset: 2px; }}
section {{ border-top: 1px solid #ccc; padding: .2rem 0 .6rem; }}
h2 {{ font-size: 1.25rem; margin: .8rem 0 .2rem; }}
.sections, footer {{ color: #595959; font-size: .9em; margin: 0 0 .3rem; }}
ul.links {{ margin: .2rem 0; padding-left: 1.2rem; }} ul.links li {{ margin: .15rem 0; }}
.sep {{ color: #595959; padding: 0 .4rem; }}
</style></head><body>
<header>
<h1>{course}: Jacobians, singularities and manipulability</h1>
{intro}
<p>These pages load nothing from the internet: every script, font and picture is in this folder.</p>
</header>
<main>
{rows}
</main>
<footer><p>Built by <code>make handouts</code> ({when}).</p></footer>
</body></html>
"""


CHEATSHEET = "cheatsheet.md"  # in the notebooks folder: the one-page cheat sheet, built to reference/cheatsheet.html


def write_cheatsheet(src: Path, dest: Path, urls: dict, *, links=LINKS) -> None:
    """The cheat sheet ``src`` (markdown with LaTeX maths) as a page ``dest`` (``reference/cheatsheet.html``),
    with the same assets, print header and links bar as the handouts (its PDF: ``pdf/reference/``).

    >>> import tempfile
    >>> with tempfile.TemporaryDirectory() as d:
    ...     _ = (Path(d) / "c.md").write_text("# Cheat sheet\\n\\n$J_b = J_s$")
    ...     write_cheatsheet(Path(d) / "c.md", Path(d) / "reference" / "cheatsheet.html", {}, links=("pdf",))
    ...     page = (Path(d) / "reference" / "cheatsheet.html").read_text()
    >>> "<title>Cheat sheet</title>" in page, "../pdf/reference/cheatsheet.pdf" in page
    (True, True)
    """
    import nbformat

    text = Path(src).read_text(encoding="utf-8")
    m = re.search(r"^#\s+(.+)$", text, re.M)
    title = m.group(1).strip() if m else "Cheat sheet"
    nb = nbformat.v4.new_notebook(cells=[nbformat.v4.new_markdown_cell(text, id="cheatsheet")])
    urls = {"require_js_url": "../assets/require.js", **urls}
    export_html(nb, dest, urls, title=title, problems=False, links=tuple(k for k in links if k == "pdf"))
    page = dest.read_text(encoding="utf-8")
    dest.write_text(page.replace("</head>", _CHEATSHEET_PRINT + "</head>", 1), encoding="utf-8")


# The cheat sheet prints on one A4 page: smaller type and tighter headings than a handout.
_CHEATSHEET_PRINT = """<style>/* kinlib: the cheat sheet on one printed page */
@media print {
  .jp-RenderedHTMLCommon { font-size: 10.5px !important; line-height: 1.32 !important; }
  .jp-RenderedHTMLCommon h1 { font-size: 17px !important; margin: 0 0 4px !important; }
  .jp-RenderedHTMLCommon h2 { font-size: 13.5px !important; margin: 8px 0 3px !important; }
  .jp-RenderedHTMLCommon p, .jp-RenderedHTMLCommon ul { margin-top: 2px !important; margin-bottom: 3px !important; }
  .jp-RenderedHTMLCommon li { margin: 1px 0 !important; }
}
</style>
"""


def write_index(out: Path, entries: list, links=LINKS, *, audience: str = "all", cheatsheet: bool = False) -> None:
    """Write ``out/index.html``, the course front page: for each entry (a section of the course) its
    problems and solutions (web page and PDF), its workbook (download, and "open in the browser" with
    JupyterLite) and its solution notebook in the browser (``links``: which of ``("pdf", "lite")`` were built; the
    others are left out). Offline (no external URL), ``lang="en"``, one h1
    then an h2 per section, link texts that name the section and the target. ``audience="students"``: no
    solution links (the solutions are not built); ``cheatsheet``: a link to ``reference/cheatsheet.html``.

    >>> import tempfile
    >>> with tempfile.TemporaryDirectory() as d:
    ...     write_index(Path(d), [{"stem": "01_x", "title": "X", "sections": ["1.1"]}])
    ...     page = (Path(d) / "index.html").read_text()
    >>> 'href="problems/01_x.html"' in page, 'href="pdf/solutions/01_x.pdf"' in page, "://" in page
    (True, True, False)
    """
    rows = []
    pdf, lite = "pdf" in links, "lite" in links
    solutions = audience != "students"
    if cheatsheet:
        rows.append(
            '<section aria-labelledby="sref"><h2 id="sref">Cheat sheet</h2>\n<ul class="links">\n'
            '<li><a href="reference/cheatsheet.html">Cheat sheet: J_s, J_b and J; singularities; manipulability '
            "(web page)</a>"
            + (
                '<span class="sep" aria-hidden="true">·</span><a href="pdf/reference/cheatsheet.pdf">Cheat sheet (PDF)</a>'
                if pdf
                else ""
            )
            + "</li>\n</ul></section>"
        )
    for e in entries:
        stem = e["stem"]
        num = str(int(stem[:2])) if stem[:2].isdigit() else stem
        title = html.escape(e["title"])
        sections = ", ".join(e.get("sections") or [])

        def a(href, text, extra=""):
            return f'<a href="{html.escape(href)}"{extra}>{html.escape(text)}</a>'

        sep = '<span class="sep" aria-hidden="true">·</span>'
        rows.append(
            f'<section aria-labelledby="s{stem}"><h2 id="s{stem}">{html.escape(num)} · {title}</h2>\n'
            + (f'<p class="sections">Problem set sections {html.escape(sections)}</p>\n' if sections else "")
            + '<ul class="links">\n'
            + f"<li>{a(f'problems/{stem}.html', f'Problems {num} (web page)')}"
            + (f"{sep}{a(f'pdf/problems/{stem}.pdf', f'Problems {num} (PDF)')}" if pdf else "")
            + "</li>\n"
            + (
                f"<li>{a(f'solutions/{stem}.html', f'Solutions {num} (web page)')}"
                + (f"{sep}{a(f'pdf/solutions/{stem}.pdf', f'Solutions {num} (PDF)')}" if pdf else "")
                + (
                    f"{sep}{a(lite_link(f'solutions/{stem}.ipynb'), f'Solutions {num}: open the notebook in the browser')}"
                    if lite
                    else ""
                )
                + "</li>\n"
                if solutions
                else ""
            )
            + f"<li>{a(f'workbooks/{stem}.ipynb', f'Workbook {num} (download .ipynb)', ' download')}"
            + (
                f"{sep}{a(lite_link(f'workbooks/{stem}.ipynb'), f'Workbook {num}: open in the browser')}"
                if lite
                else ""
            )
            + "</li>\n"
            "</ul></section>"
        )
    intro = _INTRO_ALL if solutions else _INTRO_STUDENTS
    (out / "index.html").write_text(
        _INDEX.format(rows="\n".join(rows), when=time.strftime("%Y-%m-%d"), course=html.escape(COURSE), intro=intro),
        encoding="utf-8",
    )
