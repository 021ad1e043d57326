"""The handouts in a second browser engine (marked ``browser``, ``slow``): WebKitGTK (Debian's
``gir1.2-webkit2-4.1``, driven by tests/webkit_run.py under Xvfb; ``make webkit`` installs it), besides
Chromium everywhere else.

1. The static solutions page of notebook 05 (a file: no kernel): its explorer is drawn, and moving θ2 to −π/4
   makes it say singular (det J 0, collapsed held ellipse, blocked direction, the aria-live sentence); the track
   of θ2 is marked at −π/4 and 3π/4.
2. The JupyterLite site (served on loopback): workbook 05 opens, its Pyodide kernel starts, Run All finishes
   with no error and the explorer responds to its slider. Pyodide 0.27.7 runs with run-until-complete, which
   hung other projects' kernels on engines without WebAssembly stack switching (JSPI); the scenario reports
   whether this engine has JSPI (``WebAssembly.Suspending``) and the test passes only if the kernel finished.
   Every URI the page asked for is on loopback (or a ``data:``/``blob:`` URI).

Both run in one WebKit process (one Xvfb, one engine start), one page load after the other.
"""

from __future__ import annotations

import json
import math
import shutil
import subprocess
from pathlib import Path

import pytest
from test_lite import handouts_site  # noqa: F401  (the site of notebook 05, built as make handouts does)

ROOT = Path(__file__).resolve().parents[2]
DRIVER = ROOT / "tests" / "webkit_run.py"
SCREENSHOTS = ROOT / "build" / "screenshots"

pytestmark = [pytest.mark.browser, pytest.mark.slow]


def _webkit_ready() -> str | None:
    if not shutil.which("xvfb-run"):
        return "xvfb-run is missing"
    r = subprocess.run(
        [
            "/usr/bin/python3",
            "-c",
            "import gi; gi.require_version('WebKit2', '4.1'); from gi.repository import WebKit2",
        ],
        capture_output=True,
        text=True,
    )
    return None if r.returncode == 0 else f"WebKitGTK through /usr/bin/python3 is missing: {r.stderr.strip()[-200:]}"


def run_webkit(steps: list, tmp: Path) -> list:
    """Run ``steps`` [(url, scenario JS, timeout s)] one after the other in one WebKit process
    (tests/webkit_run.py under Xvfb: one engine start for all); returns each step's JSON line, in order."""
    cmd = ["xvfb-run", "-a", "/usr/bin/python3", str(DRIVER)]
    for k, (url, scenario, timeout) in enumerate(steps):
        path = tmp / f"scenario-{k}.js"
        path.write_text(scenario)
        cmd += [url, str(path), str(timeout)]
    r = subprocess.run(cmd, capture_output=True, text=True, timeout=sum(t for *_, t in steps) + 60)
    lines = [json.loads(ln) for ln in r.stdout.splitlines() if ln.startswith("{")]
    assert len(lines) == len(steps), (
        f"the WebKit driver printed {len(lines)} of {len(steps)} results (exit {r.returncode}): {r.stderr[-800:]}"
    )
    return lines


@pytest.fixture(scope="module")
def webkit(request, handouts_site, tmp_path_factory):  # noqa: F811
    """{test name: the driver's result of its scenario}: the scenarios of this module's tests that the run
    selected, run in one WebKit process (one Xvfb and one engine start for the module), the static page first."""
    why = _webkit_ready()
    if why:
        pytest.fail(f"{why}: `make webkit` installs Debian's gir1.2-webkit2-4.1, python3-gi and xvfb", pytrace=False)
    from kinlib.course.publish import lite

    wanted = {i.originalname for i in request.session.items if getattr(i, "module", None) is request.module}
    server = lite.serve(handouts_site, 0, block=False)
    base = f"http://127.0.0.1:{server.server_address[1]}/"
    steps = {
        "test_static_page_explorer_in_webkit": (
            (handouts_site / "solutions" / "05_singularities_planar.html").as_uri(), _STATIC, 120),
        "test_jupyterlite_runs_workbook_05_in_webkit": (
            base + lite.lite_link("workbooks/05_singularities_planar.ipynb"), _LITE, 1300),
    }  # fmt: skip
    names = [n for n in steps if n in wanted]
    try:
        out = run_webkit([steps[n] for n in names], tmp_path_factory.mktemp("webkit"))
    finally:
        server.shutdown()
        server.server_close()
    return {"base": base, "site": handouts_site.as_uri() + "/", **dict(zip(names, out))}


_STATIC = """
const sleep = ms => new Promise(r => setTimeout(r, ms));
for (let i = 0; i < 100 && !document.querySelector('.kinlib-explorer .kinlib-arm'); i++) await sleep(100);
const all = document.querySelectorAll('.kinlib-explorer');
if (!all.length) return {drawn: false};
const ex = all[all.length - 1], X = ex.kinlib, S = X.S;
const inp = ex.querySelector("input.kinlib-slider[data-joint='2']");
const before = ex.querySelector('.kinlib-arm').getAttribute('d');
const k = Math.round((-Math.PI / 4 - S.ranges[1][0]) / (S.ranges[1][1] - S.ranges[1][0]) * S.ticks[1]);
inp.value = String(k);
inp.dispatchEvent(new Event('input', {bubbles: true}));
return {drawn: true, moved: ex.querySelector('.kinlib-arm').getAttribute('d') !== before, q2: X.q[1],
        state: ex.querySelector('.kinlib-status').getAttribute('data-state'),
        det: ex.querySelector('.kinlib-det').textContent, held: ex.querySelector('.kinlib-held').textContent,
        blocked: ex.querySelectorAll('.kinlib-blocked').length, live: ex.querySelector('.kinlib-live').textContent,
        marks: Array.from(inp.parentNode.querySelectorAll('.kinlib-mark')).map(m => +m.getAttribute('data-value'))};
"""


def test_static_page_explorer_in_webkit(webkit):
    out = webkit["test_static_page_explorer_in_webkit"]
    assert out["error"] is None, out["error"]
    r = out["result"]
    assert r["drawn"], "no explorer drawn on the static page"
    assert r["moved"] and abs(r["q2"] + math.pi / 4) < 1e-12
    assert r["state"] == "singular" and r["det"] == "0", r
    held = [float(x) for x in r["held"].split(",")]
    assert min(held) == 0 and max(held) > 0
    assert r["blocked"] == 1 and "Singular configuration" in r["live"] and "cannot move along" in r["live"]
    assert r["marks"] == pytest.approx([-math.pi / 4, 3 * math.pi / 4], abs=1e-12)
    outside = [u for u in out["requests"] if not u.startswith(("file:", "data:", "blob:", "about:"))]
    assert not outside, outside
    print(f"\n{out['engine']}: static page 05, explorer singular at θ2 = −π/4")


_LITE = """
const sleep = ms => new Promise(r => setTimeout(r, ms));
const t0 = performance.now(), res = {jspi: typeof WebAssembly.Suspending === 'function'};
const app = () => window.jupyterapp, nb = () => app() && app().shell.currentWidget;
const kernel = () => { const w = nb(); return w && w.sessionContext && w.sessionContext.session
  && w.sessionContext.session.kernel; };
while (!(kernel() && kernel().status === 'idle' && nb().content.widgets.length)) {
  if (performance.now() - t0 > 600000) { res.stage = 'kernel never idle'; return res; }
  await sleep(250);
}
res.ready_s = (performance.now() - t0) / 1000;
const w = nb();
const code = w.content.widgets.filter(c => c.model.type === 'code' && c.model.sharedModel.getSource().trim());
const t1 = performance.now();
app().commands.execute('notebook:run-all-cells');
while (!(code.every(c => c.model.executionCount) && kernel().status === 'idle')) {
  if (performance.now() - t1 > 600000) {
    res.stage = 'run-all did not finish'; res.done = code.filter(c => c.model.executionCount).length;
    res.cells = code.length; return res;
  }
  await sleep(250);
}
res.run_s = (performance.now() - t1) / 1000;
res.errors = code.filter(c => c.model.outputs.toJSON().some(o => o.output_type === 'error'))
  .map(c => c.model.sharedModel.getSource().slice(0, 60));
const i = w.content.widgets.findIndex(c => c.model.type === 'code'
  && c.model.outputs.toJSON().some(o => String((o.data || {})['application/javascript'] || '').includes('kinlibExplorer')));
res.explorer_cell = i;
if (i < 0) { res.stage = 'no explorer output'; return res; }
await w.content.scrollToItem(i, 'start');
for (let k = 0; k < 100 && !w.content.widgets[i].node.querySelector('.kinlib-explorer .kinlib-arm'); k++) await sleep(100);
const ex = w.content.widgets[i].node.querySelector('.kinlib-explorer');
if (!ex) { res.stage = 'explorer not drawn'; return res; }
const inp = ex.querySelector("input.kinlib-slider[data-joint='1']");
const before = ex.querySelector('.kinlib-arm').getAttribute('d');
inp.value = String(+inp.value + 10);
inp.dispatchEvent(new Event('input', {bubbles: true}));
res.moved = ex.querySelector('.kinlib-arm').getAttribute('d') !== before;
res.stage = 'done';
return res;
"""


def test_jupyterlite_runs_workbook_05_in_webkit(webkit):
    out, base = webkit["test_jupyterlite_runs_workbook_05_in_webkit"], webkit["base"]
    r = out["result"] or {}
    print(f"\n{out['engine']}: JSPI {r.get('jspi')}; kernel ready {r.get('ready_s')} s, run-all {r.get('run_s')} s")
    assert out["error"] is None, (out["error"], r)
    assert r.get("stage") == "done", r
    assert not r["errors"], r["errors"]
    assert r["moved"], "the explorer did not respond to its slider"
    # the site, or the handouts' own files: the static page ran first in the same WebView, and its MathJax may
    # still load an extension from the folder (file:) while this step runs; nothing else may be asked for
    local = (base, webkit["site"], "data:", "blob:", "about:")
    outside = [u for u in out["requests"] if not u.startswith(local)]
    assert not outside, outside[:5]
