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
import subprocess
import tarfile
import time
from pathlib import Path

__all__ = ["build_assets", "export_html", "write_index", "HTML_MANAGER", "REQUIREJS", "FONT_AWESOME", "MATHJAX_CONFIG"]

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
    MathMenu: {showLocale: false}
  });
})();
MathJax.Ajax.loadComplete("[MathJax]/config/kinlib.js");
"""


def _npm_pack(name: str, version: str, vendor: Path) -> Path:
    """The unpacked npm package ``name@version`` under ``vendor`` (``npm pack`` from the registry once)."""
    vendor.mkdir(parents=True, exist_ok=True)
    stem = name.lstrip("@").replace("/", "-") + "-" + version
    unpacked = vendor / stem
    if (unpacked / "package" / "package.json").exists():
        return unpacked / "package"
    tgz = vendor / f"{stem}.tgz"
    if not tgz.exists():
        if shutil.which("npm") is None:
            raise RuntimeError(
                f"npm is needed once to fetch {name}@{version} (the offline widget renderer) "
                f"into {vendor}; install node/npm or copy {tgz.name} there"
            )
        r = subprocess.run(
            ["npm", "pack", f"{name}@{version}", "--silent", "--pack-destination", str(vendor)],
            capture_output=True,
            text=True,
        )
        if r.returncode != 0 or not tgz.exists():
            raise RuntimeError(f"npm pack {name}@{version} failed (exit {r.returncode}):\n{r.stderr.strip()[-2000:]}")
    tmp = vendor / (stem + ".tmp")
    shutil.rmtree(tmp, ignore_errors=True)
    with tarfile.open(tgz) as tf:
        tf.extractall(tmp, filter="data")
    shutil.rmtree(unpacked, ignore_errors=True)
    tmp.rename(unpacked)
    return unpacked / "package"


def build_assets(assets: Path, vendor: Path) -> dict:
    """Copy MathJax, require.js and the widget embedder into ``assets``; return their relative URLs
    (the keyword arguments of nbconvert's HTMLExporter used by :func:`export_html`).

    It copies MathJax and may run ``npm pack`` (a download, the first time), hence not run here;
    tests/test_handouts.py exercises it:

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


def export_html(nb, dest: Path, urls: dict, *, title: str, problems: bool) -> None:
    """Write ``nb`` as a page ``dest`` using the offline assets ``urls``; ``problems`` drops prompt numbers.

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
    dest.parent.mkdir(parents=True, exist_ok=True)
    dest.write_text(body, encoding="utf-8")


_INDEX = """<!DOCTYPE html>
<html lang="en"><head><meta charset="utf-8"><title>kinlib handouts</title>
<style>
body {{ font-family: system-ui, sans-serif; max-width: 60rem; margin: 2rem auto; padding: 0 1rem; color: #222; }}
table {{ border-collapse: collapse; width: 100%; }} th, td {{ text-align: left; padding: .5rem; border-bottom: 1px solid #ddd; }}
td.sections {{ color: #666; font-size: .9em; }} a {{ margin-right: .8rem; }}
</style></head><body>
<h1>kinlib: Jacobians, singularities and manipulability</h1>
<p>Problems (no answers), solutions (worked, with outputs) and workbooks (Jupyter notebooks to fill in, with self-checks)
for each notebook. Everything here works offline.</p>
<table><thead><tr><th>#</th><th>Notebook</th><th>Sections</th><th>Handouts</th></tr></thead><tbody>
{rows}
</tbody></table>
<p><small>Built by <code>make handouts</code> ({when}).</small></p>
</body></html>
"""


def write_index(out: Path, entries: list) -> None:
    """Write ``out/index.html`` linking each entry's problems, solutions and workbook.

    >>> import tempfile
    >>> with tempfile.TemporaryDirectory() as d:
    ...     write_index(Path(d), [{"stem": "01_x", "title": "X", "sections": ["1.1"]}])
    ...     'href="problems/01_x.html"' in (Path(d) / "index.html").read_text()
    True
    """
    rows = []
    for e in entries:
        stem = e["stem"]
        rows.append(
            f"<tr><td>{html.escape(stem[:2])}</td><td>{html.escape(e['title'])}</td>"
            f'<td class="sections">{html.escape(", ".join(e["sections"]))}</td>'
            f'<td><a href="problems/{stem}.html">problems</a><a href="solutions/{stem}.html">solutions</a>'
            f'<a href="workbooks/{stem}.ipynb" download>workbook (.ipynb)</a></td></tr>'
        )
    (out / "index.html").write_text(
        _INDEX.format(rows="\n".join(rows), when=time.strftime("%Y-%m-%d")), encoding="utf-8"
    )
